-- ms_tracker_v2: core v2: tracker v2 (mstrack.fixed.tracker_v2.FixedTrackerV2) bit for bit, on the ports
-- and stream behaviour of ms_tracker, with result word v2.  Integrators instantiate ms_tracker with
-- PRESET 1, which passes every port and generic here.  The block page, docs/blocks/ms_tracker_v2.md,
-- gives each step, the joint bins, the gated scale test, the stream faults, the measured latencies and
-- the tests.
--
-- Structure: the stream side (this entity) around ms_engine, the sequencer of one target's job
-- (docs/blocks/ms_engine.md).  The stream side holds the stream check and gate, the front end,
-- ms_decimate, the region capture and RAM, ms_bg_model (counted on the init frame's stream), the
-- stream faults and the result FIFO; the engine the target's record, the geometry and the work after
-- the frame.
-- Computes, per video frame:
--   before the frame (input closed): the engine's geometry: log2 D = ms_decimation(w8, h8) (+ 1 while
--   lost), the decimated frame size, the window diameters (ms_window_size), the search offsets (STEP16)
--   and the region (ms_region_v2) around c8 >> log2 D (margin MARGIN, + the offset while lost, at most
--   MARGIN_MAX); on an init frame the box (ms_box_size), then ms_bg_model reset and started here;
--   during the frame: ms_frontend -> ms_decimate -> ms_region_capture (colour region RAM, + the 4-bit
--   orientation RAM with ORIENT_T >= 0); on the init frame ms_bg_model counts the decimated frame;
--   after the frame (the engine's job, started once the region is in and on an init frame the model
--   learnt): ms_kernel_tables + K, the Qw load (ms_model_scale into the engine's Q RAM, T into
--   ms_target_stats), ms_meanshift from c8 >> log2 D (init frame: one pass, `single`), ms_target_stats,
--   rho (ms_fusion), ms_share, ms_confidence; while lost 8 more start points x SEARCH_ITER iterations,
--   the best confidence wins; for the winner ms_spread, ms_ring_share, ms_loss_filter x 2,
--   ms_loss_flag, the search state and status, ms_ref_update x 2, with SCALE_TEST_D256 > 0 the gated
--   scale test (x(1 - d), x(1 + d): tables, Qw load, one pass, rho each; ms_scale_test, ms_scale_gate),
--   ms_scale and ms_resize x 2.
-- Result word v2 (mstrack.fixed.vhdl_pkg.result_layout_v2): cx, cy, w8, h8, rho, confidence,
-- status, iter, stop, decim_log2, searched, flags, err_code, frame_count.  Init box and stream faults:
-- as ms_tracker (error result with status 6; state unchanged; a fault on the init frame re-arms
-- ms_bg_model, and a start of frame that cuts the init frame is held until then).
--
-- Latency: between frames about 25 clocks (+ ms_bg_model's reset and set-up before an init frame);
-- last pixel -> result: 1 clock (the registered go), the kernel tables (<= 289 clocks), the Qw load (N_BINS + 6), the mean shift
-- (docs/realtime.md), ~60 clocks of statistics and about 230 of confidence, loss flag, scale and
-- resize; while lost 8 more mean shifts with their confidence; on the init frame ms_bg_model's
-- 3 N_BINS + 65 clocks first; the gated scale test adds about 2 x (tables + Qw load + one pass) on a
-- frame that scales.  Measured per sequence: docs/blocks/ms_tracker_v2.md (studies/v2_latency.py).
-- Throughput: 1 pixel per clock while a frame streams; the input is closed from a frame's last pixel
-- until its result is in the FIFO (as ms_tracker).
-- Handshake: AXI4-Stream in (s_axis) and out (m_axis_result, one word per frame, tlast = 1), s_init
-- valid / ready (taken between frames), busy = the engine is running; tgt_load valid / ready (another
-- target's state record and model, taken between frames after any s_init; MODELS > 1).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_tracker_v2 is
  generic (
    MAX_FRAME_W    : natural := 2048;     -- widest frame
    RGB_PACKING    : natural := 0;        -- s_axis_tdata layout (as ms_tracker)
    LANES          : natural := 4;        -- pixels per clock of a pixel pass
    COLOUR_BITS    : natural := 3;        -- bits per channel of the colour bin
    EDGE_BINS_LOG2 : natural := 4;        -- (front end; unused by v2)
    EDGE_SHIFT     : natural := 5;        -- (front end; unused by v2)
    FEATURES       : natural := 1;        -- must be 1 (colour)
    KERNEL_EPAN    : natural := 0;        -- must be 0 (flat)
    KERNEL_BITS    : natural := 8;        -- KA/KB scale of the target statistics
    MAX_HALF       : natural := 63;       -- largest window half extent (max_window = 2 MAX_HALF + 1)
    MARGIN         : natural := 32;       -- search margin (decimated px)
    COORD_W        : natural := 12;       -- frame coordinate bits
    CF             : natural := 8;        -- centre fraction bits
    WI             : natural := 4;
    WF             : natural := 4;
    RF             : natural := 6;
    AF             : natural := 8;
    RHO_OUT_FRAC   : natural := 16;
    MAX_ITER       : natural := 20;
    EPS2           : natural := 65536;
    HALF_W         : natural := 6;
    REGION_MAX     : natural := 256;
    REGION_W       : natural := 9;
    STRIDE         : natural := 64;
    ADDR_W         : natural := 14;
    KVAL_W         : natural := 1;
    HIST_W         : natural := 14;
    COUNT_W        : natural := 14;
    POSSUM_W       : natural := 21;
    KD_W           : natural := 29;
    SQRT_IN_W      : natural := 40;
    RHO_SUM_W      : natural := 21;
    RATIO_Q_W      : natural := 16;
    WEIGHT_W       : natural := 8;
    SW_W           : natural := 22;
    SWX_W          : natural := 29;
    SHIFT_Q_W      : natural := 14;
    CENTRE_W       : natural := 17;
    CENTRE_ABS_W   : natural := 20;
    ITER_W         : natural := 5;
    RHO_OUT_W      : natural := 17;
    ALPHA_W        : natural := 9;
    WIN_W          : natural := 7;
    RESULT_W       : natural := 160;
    -- v2 (mstrack.hw.cosim.CoreConfigV2.generics)
    PAD16          : natural := 4;        -- pad in 1/16
    RING16         : natural := 10;       -- bg_ring in 1/16
    MAX_WINDOW     : natural := 127;      -- largest window diameter (decimated px)
    KT_W           : natural := 9;        -- KA/KB width (KERNEL_BITS + 1)
    ST2_W          : natural := 23;
    SHARE_W        : natural := 17;
    SPREAD_W       : natural := 25;
    SIZE_W         : natural := 20;       -- w8, h8 bits (COORD_W + 8)
    SCALE_W        : natural := 17;
    SCALE_GAIN     : natural := 19661;
    SCALE_REG      : natural := 6554;
    SCALE_STEP     : natural := 6554;
    SCALE_RATIO_Q_W: natural := 17;
    WR_Q_W         : natural := 27;
    CON_W          : natural := 18;
    LOSS_K         : natural := 1;
    REF_K          : natural := 6;
    LOSS_RHO       : natural := 45220;
    LOSS_CONTRAST  : integer := 16384;
    CONF_LOST      : natural := 26214;    -- round(conf_lost 2**16)
    CONF_UNCERTAIN : natural := 32768;
    CONF_REACQUIRE : natural := 32768;
    SPREAD_DEFAULT : natural := 5368709;  -- spread_ref when the init spread is 0: (128 << (KB + 16)) / (16 + PAD16)**2
    BG_Q_W         : natural := 14;
    BG_O_W         : natural := 17;
    SEARCH_ITER    : natural := 5;        -- iterations per start point while lost
    STEP16         : natural := 16;       -- search_step in 1/16 (start points +- step x window)
    MARGIN_MAX     : natural := 255;      -- largest region margin (MARGIN + the search offset)
    -- the gated scale test (mstrack.fixed.tracker_v2 _scale_verdict, scale_test with scale_test_gate):
    -- d256 = round(256 scale_test), 13 = tracker v2's default 0.05; 0 = off (mstrack-v2-colour).
    -- Costs a 9-bit constant multiply per axis, a 2-input mux on the window-size inputs, the fit
    -- compares, 2 x 17-bit rho compares and one SPREAD_W compare (the gate); buys rho-checked scale
    -- updates at 2 x (tables + Qw load + one pass + rho) clocks more per tracking frame
    SCALE_TEST_D256 : natural range 0 to 255 := 13;
    -- the joint colour x gradient-orientation bins (FixedTrackerV2 with orient_T = ORIENT_T, the
    -- default tracker v2's 64): -1 = off (colour bins alone: mstrack-v2-colour, bit for bit);
    -- >= 0: a pixel's bin is 9 colour + ms_orient_bin(grey, ORIENT_T) (4,608 bins: N_ORIENT 9 banks of
    -- the histogram, the bin pass, the model and T; a 4-bit orientation region RAM beside the colour one)
    ORIENT_T        : integer range -1 to 2047 := 64;
    -- target models held (one per target when one engine serves several: the tgt_* ports); 1 = core v2
    MODELS          : positive := 1
  );
  port (
    clk                  : in  std_logic;
    rst                  : in  std_logic;
    frame_width          : in  unsigned(COORD_W - 1 downto 0);
    frame_height         : in  unsigned(COORD_W - 1 downto 0);
    s_init_tvalid        : in  std_logic;
    s_init_tready        : out std_logic;
    s_init_x             : in  signed(COORD_W + 1 downto 0);
    s_init_y             : in  signed(COORD_W + 1 downto 0);
    s_init_w             : in  unsigned(COORD_W downto 0);
    s_init_h             : in  unsigned(COORD_W downto 0);
    s_axis_tdata         : in  std_logic_vector(23 downto 0);
    s_axis_tvalid        : in  std_logic;
    s_axis_tready        : out std_logic;
    s_axis_tlast         : in  std_logic;
    s_axis_tuser         : in  std_logic;
    m_axis_result_tdata  : out std_logic_vector(RESULT_W - 1 downto 0);
    m_axis_result_tvalid : out std_logic;
    m_axis_result_tready : in  std_logic;
    m_axis_result_tlast  : out std_logic;
    busy                 : out std_logic;
    -- the target this engine works for (several targets on one engine; docs/blocks/ms_tracker_v2.md,
    -- "Target state"): its state record (mstrack.fixed.vhdl_pkg.target_state_layout_v2), valid
    -- while tgt_load_ready = 1; a load, taken between frames like s_init, replaces the record and
    -- selects the target's model in ms_bg_model (an init learns into it, a frame reads it)
    tgt_state            : out std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                           SPREAD_W) - 1 downto 0);
    tgt_load_valid       : in  std_logic := '0';
    tgt_load_ready       : out std_logic;
    tgt_load_state       : in  std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                           SPREAD_W) - 1 downto 0) := (others => '0');
    tgt_load_model       : in  unsigned(clog2(MODELS) - 1 downto 0) := (others => '0')
  );
end entity;

architecture rtl of ms_tracker_v2 is
  constant BIN_C_W   : natural := 3 * COLOUR_BITS;
  constant OR_ON     : boolean := ORIENT_T >= 0;
  constant N_OR      : natural := 9 * boolean'pos(OR_ON) + boolean'pos(not OR_ON);   -- orientation banks
  constant DEPTH     : natural := REGION_MAX * STRIDE;
  constant REGION_RD_LAT : positive := 4;  -- ms_ram_sdp ecp5: 25 rows per bank, the row multiplexer in two registered levels
  constant REGION_WR_LAT : natural := 1;
  constant DRAIN     : natural := 63;
  constant FCOUNT_W  : natural := 16;
  constant TS_W      : natural := v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W, SPREAD_W);
  constant ST_OK     : unsigned(2 downto 0) := "000";
  constant ST_ERROR  : unsigned(2 downto 0) := "110";

  -- the stream side's steps around the engine: S_IDLE (the engine idle too: a frame streams, a command
  -- is taken), S_ARM1..3 (ms_bg_model reset and armed for an init frame), S_BG (the init frame's model
  -- is being learnt), S_RUN (the engine's job, until its word is in the FIFO), S_PUSH (a word of the
  -- stream side: a stream fault's, a changed frame size's, no target's)
  type sstate_t is (S_IDLE, S_ARM1, S_ARM2, S_ARM3, S_BG, S_RUN, S_PUSH);
  signal tstate : sstate_t := S_IDLE;
  signal ctl_idle, err_push : std_logic;
  -- the engine's commands, registered (with the init box and the record they carry): the engine takes
  -- them one clock after the stream side decides, which keeps the stream side's conditions off the
  -- engine's paths; the stream side waits that clock (cmd_pending)
  signal c_go, c_rearm, c_init, c_load, cmd_pending : std_logic := '0';
  signal c_init_x, c_init_y : signed(COORD_W + 1 downto 0) := (others => '0');
  signal c_init_w, c_init_h : unsigned(COORD_W downto 0) := (others => '0');
  signal c_init_fw, c_init_fh : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal c_load_state : std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W, SPREAD_W) - 1
                                         downto 0) := (others => '0');
  signal c_load_model : unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
  signal rejected_pending : std_logic := '0';
  signal tgt_ready_i, tgt_take : std_logic;

  -- the engine
  signal e_idle, e_geo_done, e_go, e_rearm, e_init_rej, e_res_valid, e_busy : std_logic;
  signal e_valid, e_init : std_logic;
  signal e_res_data   : std_logic_vector(RESULT_W - 1 downto 0);
  signal e_c8x, e_c8y : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal e_w8, e_h8   : unsigned(SIZE_W - 1 downto 0);
  signal e_fw, e_fh   : unsigned(COORD_W - 1 downto 0);
  signal l2d          : unsigned(2 downto 0);
  signal reg_x, reg_y, reg_w_c, reg_h_c, wb, hb : unsigned(COORD_W - 1 downto 0);
  signal m_sel        : unsigned(clog2(MODELS) - 1 downto 0);

  -- stream gate (as ms_tracker)
  signal accept, beat : std_logic;
  signal gate_closed, in_frame, err_hold : std_logic := '0';
  signal line_cnt     : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal drain_cnt    : natural range 0 to DRAIN := 0;
  signal fr_w, fr_h   : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal size_ok, init_take, fe_err_now, init_ready : std_logic;
  -- init pending: ms_bg_model armed and no beat since (bg_clean); a start of frame otherwise waits for a
  -- re-arm (bg_rearm)
  signal bg_clean, bg_rearm : std_logic := '0';

  -- front end, decimation, capture, RAM
  signal ip_valid     : std_logic;
  signal ip_x, ip_y   : unsigned(COORD_W - 1 downto 0);
  signal ip_cbin      : std_logic_vector(BIN_C_W - 1 downto 0);
  signal ip_ebin      : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal fe_start, fe_end, fe_error : std_logic;
  signal fe_code      : std_logic_vector(ERR_CODE_W - 1 downto 0);
  signal dp_start, dp_end, dp_error, dp_valid : std_logic;
  signal dp_x, dp_y   : unsigned(COORD_W - 1 downto 0);
  signal dp_cbin      : std_logic_vector(BIN_C_W - 1 downto 0);
  signal dp_ebin      : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal cap_we       : std_logic;
  signal cap_bank     : unsigned(clog2(LANES) - 1 downto 0);
  signal cap_addr     : unsigned(ADDR_W - 1 downto 0);
  signal cap_c        : std_logic_vector(BIN_C_W - 1 downto 0);
  signal cap_done     : std_logic;
  signal ram_addr     : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal ram_data     : std_logic_vector(LANES * BIN_C_W - 1 downto 0);
  signal ip_obin      : std_logic_vector(3 downto 0);
  signal ip_edge      : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal cap_e        : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal ram_obin     : std_logic_vector(LANES * 4 - 1 downto 0) := (others => '0');   -- orientation RAM data

  -- background model
  signal bg_rst, bg_rst_p, bg_start, bg_busy, bg_counting, bg_done : std_logic := '0';
  signal bg_got       : std_logic := '0';
  signal bg_cx, bg_cy : unsigned(COORD_W - 1 downto 0);
  signal bg_px_valid, bg_px_last : std_logic := '0';
  signal bg_px_bin    : std_logic_vector(BIN_C_W - 1 downto 0);
  signal bg_px_obin   : unsigned(3 downto 0) := (others => '0');
  signal bg_px_bin_u  : unsigned(BIN_C_W - 1 downto 0);
  signal dec_q        : unsigned(2 downto 0);
  signal av_valid     : std_logic;
  signal av_x, av_y   : unsigned(COORD_W - 1 downto 0);
  signal av_cbin      : std_logic_vector(BIN_C_W - 1 downto 0);
  signal bg_px_x, bg_px_y : unsigned(COORD_W - 1 downto 0);
  signal m_rd_addr    : unsigned(BIN_C_W - 1 downto 0);
  signal m_qn         : unsigned(16 downto 0);
  signal m_t          : std_logic;
  signal m_qn_all     : std_logic_vector(N_OR * 17 - 1 downto 0);   -- ORIENT_T >= 0: the 9 banks of m_rd_addr
  signal m_t_all      : std_logic_vector(N_OR - 1 downto 0);

  -- results
  signal top_word, fifo_data : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');
  signal fifo_valid, fifo_ready : std_logic;
  signal frame_count  : unsigned(FCOUNT_W - 1 downto 0) := (others => '0');
  signal err_pending, overflow : std_logic := '0';
  signal err_code_r   : std_logic_vector(ERR_CODE_W - 1 downto 0);

  -- a word of the stream side: the target's centre and size, no statistics
  function side_word(cx, cy, bw, bh : unsigned; st : unsigned; flags, err : std_logic_vector;
                     fc : unsigned) return std_logic_vector is
  begin
    return v2_word(RESULT_W, CENTRE_ABS_W, SIZE_W, RHO_OUT_W, ITER_W, cx, cy, bw, bh, to_unsigned(0, 17),
                   to_unsigned(0, 17), st, to_unsigned(0, ITER_W), "00", to_unsigned(0, 3), to_unsigned(0, 4),
                   flags, err, fc);
  end function;
begin
  assert FEATURES = 1 and KERNEL_EPAN = 0
    report "ms_tracker_v2: tracker v2 is colour only with the flat kernel (FEATURES 1, KERNEL_EPAN 0)"
    severity failure;
  -- the tracking region must fit the region RAM (the lost-state bound, 255 at the defaults, is
  -- mstrack.hw.cosim.region_max_v2: it follows from the decimation rule, not from the generics alone)
  assert (REGION_MAX >= MAX_WINDOW + 2 * MARGIN or REGION_MAX >= MAX_FRAME_W - 2) and MARGIN_MAX >= MARGIN
    report "ms_tracker_v2: REGION_MAX must be >= min(MAX_WINDOW + 2 MARGIN, MAX_FRAME_W - 2), MARGIN_MAX >= MARGIN"
    severity failure;

  ---------------------------------------------------------------------------- video input gate
  size_ok <= '1' when frame_width >= 3 and frame_height >= 3 and frame_width <= MAX_FRAME_W else '0';
  bg_rearm <= s_axis_tuser and e_init and not bg_clean;
  accept <= '1' when ctl_idle = '1' and gate_closed = '0' and err_hold = '0'
                     and fe_err_now = '0' and init_take = '0' and tgt_take = '0' and bg_rearm = '0' else '0';
  s_axis_tready <= accept;
  beat <= s_axis_tvalid and accept;

  p_gate : process(clk)
  begin
    if rising_edge(clk) then
      if beat = '1' then
        if s_axis_tuser = '1' then
          in_frame <= size_ok;
          fr_w <= frame_width;
          fr_h <= frame_height;
          line_cnt <= (others => '0');
        elsif in_frame = '1' and s_axis_tlast = '1' then
          line_cnt <= line_cnt + 1;
        end if;
        if in_frame = '1' and s_axis_tuser = '0' and s_axis_tlast = '1' and line_cnt = fr_h - 1 then
          gate_closed <= '1';
          in_frame <= '0';
        end if;
      end if;
      if gate_closed = '1' and ctl_idle = '1' then
        if drain_cnt = DRAIN then
          gate_closed <= '0';
          drain_cnt <= 0;
        else
          drain_cnt <= drain_cnt + 1;
        end if;
      else
        drain_cnt <= 0;
      end if;
      if fifo_ready = '1' and (tstate = S_PUSH or (tstate = S_RUN and e_res_valid = '1')) then
        gate_closed <= '0';
      end if;
      if rst = '1' then
        gate_closed <= '0';
        in_frame <= '0';
        drain_cnt <= 0;
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- front end, decimation, capture
  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, RGB_PACKING => RGB_PACKING,
                 ORIENT_T => maximum(ORIENT_T, 0))
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => beat, in_data => s_axis_tdata, in_sof => s_axis_tuser, in_eol => s_axis_tlast,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_edge,
              ip_obin => ip_obin,
              frame_start => fe_start, frame_end => fe_end, frame_error => fe_error,
              error_now => fe_err_now, err_code => fe_code,
              av_valid => av_valid, av_x => av_x, av_y => av_y, av_cbin => av_cbin);

  -- the edge-bin path of the capture carries the orientation bin (ORIENT_T >= 0); off, the edge
  -- bin as before (captured into no RAM: core v2 tracks colour)
  ip_ebin <= ip_obin when OR_ON else ip_edge;
  assert not OR_ON or EDGE_BINS_LOG2 = 4
    report "ms_tracker_v2: ORIENT_T >= 0 carries the orientation bin on the 4-bit edge path: EDGE_BINS_LOG2 must be 4"
    severity failure;

  u_dec : entity work.ms_decimate
    generic map (COORD_W => COORD_W, LOG2_D_MAX => 4, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => EDGE_BINS_LOG2)
    port map (clk => clk, rst => rst, dec_log2 => l2d, frame_start => fe_start, frame_end => fe_end,
              frame_error => fe_error, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin,
              ip_ebin => ip_ebin, dp_start => dp_start, dp_end => dp_end, dp_error => dp_error,
              dp_valid => dp_valid, dp_x => dp_x, dp_y => dp_y, dp_cbin => dp_cbin, dp_ebin => dp_ebin,
              dec_q => dec_q);

  u_cap : entity work.ms_region_capture
    generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => EDGE_BINS_LOG2)
    port map (clk => clk, rst => rst, frame_start => dp_start, frame_end => dp_end,
              frame_error => dp_error, reg_x => reg_x, reg_y => reg_y, reg_w => reg_w_c,
              reg_h => reg_h_c, ip_valid => dp_valid, ip_x => dp_x, ip_y => dp_y, ip_cbin => dp_cbin,
              ip_ebin => dp_ebin, we => cap_we, wbank => cap_bank, waddr => cap_addr,
              wdata_colour => cap_c, wdata_edge => cap_e, done => cap_done);

  u_ram : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => BIN_C_W, ADDR_W => ADDR_W,
                 RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
    port map (clk => clk, we => cap_we, wbank => cap_bank, waddr => cap_addr, wdata => cap_c,
              raddr => ram_addr, rdata => ram_data);

  -- the orientation region RAM (ORIENT_T >= 0): 4 bits per pixel, same addresses and latency
  g_oram : if OR_ON generate
    u_oram : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => 4, ADDR_W => ADDR_W,
                   RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
      port map (clk => clk, we => cap_we, wbank => cap_bank, waddr => cap_addr, wdata => cap_e,
                raddr => ram_addr, rdata => ram_obin);
  end generate;

  ---------------------------------------------------------------------------- background model
  -- every pixel (x, y) of the decimated frame frame[::D, ::D] (x mod D = 0, y mod D = 0, border
  -- included: the front end's av_* stream), at (x / D, y / D); one extra beat at dp_end, after the
  -- frame's last pixel (coordinates all ones: outside the box and its ring), carries px_last
  g_bg_colour : if not OR_ON generate
    p_bgpx : process(clk)
      variable m : unsigned(COORD_W - 1 downto 0);
    begin
      if rising_edge(clk) then
        m := shift_left(to_unsigned(1, COORD_W), to_integer(l2d)) - 1;
        if dp_end = '1' then
          bg_px_valid <= '1';
          bg_px_last <= '1';
          bg_px_x <= (others => '1');
          bg_px_y <= (others => '1');
        else
          bg_px_valid <= '0';
          if av_valid = '1' and (av_x and m) = 0 and (av_y and m) = 0 then
            bg_px_valid <= '1';
          end if;
          bg_px_last <= '0';
          bg_px_x <= shift_right(av_x, to_integer(l2d));
          bg_px_y <= shift_right(av_y, to_integer(l2d));
        end if;
        bg_px_bin <= av_cbin;
        if rst = '1' then
          bg_px_valid <= '0';
          bg_px_last <= '0';
        end if;
      end if;
    end process;
  end generate;

  -- ORIENT_T >= 0: the joint bins need each pixel's orientation: frame-interior pixels come from the
  -- Sobel (ms_decimate's dp_*, one line later), frame-border pixels (orientation 8) from av_*;
  -- ms_init_merge merges the two into ms_bg_model's one count port (docs/blocks/ms_init_merge.md)
  g_bg_joint : if OR_ON generate
    u_merge : entity work.ms_init_merge
      generic map (COORD_W => COORD_W, BIN_W => BIN_C_W, HALF_W => HALF_W, RING_W => 5, RING16_MAX => RING16,
                   MAX_FRAME_W => MAX_FRAME_W, LOG2_D_MAX => 4)
      port map (clk => clk, rst => bg_rst, start => bg_start, cx => bg_cx, cy => bg_cy,
                wb => resize(wb, HALF_W + 1), hb => resize(hb, HALF_W + 1), ring16 => to_unsigned(RING16, 5),
                frame_width => frame_width, frame_height => frame_height,
                av_valid => av_valid, av_x => av_x, av_y => av_y, av_cbin => av_cbin,
                dec_q => dec_q, dp_start => dp_start, dp_end => dp_end, dp_error => dp_error,
                dp_valid => dp_valid, dp_x => dp_x, dp_y => dp_y, dp_cbin => dp_cbin, dp_obin => dp_ebin,
                px_valid => bg_px_valid, px_bin => bg_px_bin_u, px_obin => bg_px_obin,
                px_x => bg_px_x, px_y => bg_px_y, px_last => bg_px_last, overflow => open);
    bg_px_bin <= std_logic_vector(bg_px_bin_u);
  end generate;

  bg_rst      <= rst or bg_rst_p;

  u_bg : entity work.ms_bg_model
    generic map (BIN_W => BIN_C_W, HALF_W => HALF_W, COORD_W => COORD_W, RING_W => 5, Q_W => BG_Q_W,
                 O_W => BG_O_W, KD_W => KD_W, N_ORIENT => N_OR, MODELS => MODELS)
    port map (clk => clk, rst => bg_rst, start => bg_start, cx => bg_cx, cy => bg_cy, m_wr_sel => m_sel,
              m_rd_sel => m_sel,
              wb => resize(wb, HALF_W + 1), hb => resize(hb, HALF_W + 1), ring16 => to_unsigned(RING16, 5),
              busy => bg_busy, counting => bg_counting, done => bg_done,
              px_valid => bg_px_valid, px_bin => unsigned(bg_px_bin), px_obin => bg_px_obin,
              px_x => bg_px_x, px_y => bg_px_y,
              px_last => bg_px_last, n_box => open, n_ring => open, o_min => open, qv_sum => open,
              m_rd_addr => m_rd_addr, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all, m_t_all => m_t_all);

  ---------------------------------------------------------------------------- the engine
  u_eng : entity work.ms_engine
    generic map (MAX_FRAME_W => MAX_FRAME_W, LANES => LANES, COLOUR_BITS => COLOUR_BITS, KERNEL_BITS => KERNEL_BITS,
                 MAX_HALF => MAX_HALF, MARGIN => MARGIN, COORD_W => COORD_W, CF => CF, WI => WI, WF => WF, RF => RF,
                 AF => AF, RHO_OUT_FRAC => RHO_OUT_FRAC, MAX_ITER => MAX_ITER, EPS2 => EPS2, HALF_W => HALF_W,
                 REGION_W => REGION_W, STRIDE => STRIDE, ADDR_W => ADDR_W, KVAL_W => KVAL_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, KD_W => KD_W, SQRT_IN_W => SQRT_IN_W,
                 RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, SW_W => SW_W,
                 SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W,
                 ITER_W => ITER_W, RHO_OUT_W => RHO_OUT_W, ALPHA_W => ALPHA_W, WIN_W => WIN_W,
                 RESULT_W => RESULT_W, PAD16 => PAD16, RING16 => RING16, MAX_WINDOW => MAX_WINDOW, KT_W => KT_W,
                 ST2_W => ST2_W, SHARE_W => SHARE_W, SPREAD_W => SPREAD_W, SIZE_W => SIZE_W, SCALE_W => SCALE_W,
                 SCALE_GAIN => SCALE_GAIN, SCALE_REG => SCALE_REG, SCALE_STEP => SCALE_STEP,
                 SCALE_RATIO_Q_W => SCALE_RATIO_Q_W, WR_Q_W => WR_Q_W, CON_W => CON_W, LOSS_K => LOSS_K,
                 REF_K => REF_K, LOSS_RHO => LOSS_RHO, LOSS_CONTRAST => LOSS_CONTRAST, CONF_LOST => CONF_LOST,
                 CONF_UNCERTAIN => CONF_UNCERTAIN, CONF_REACQUIRE => CONF_REACQUIRE,
                 SPREAD_DEFAULT => SPREAD_DEFAULT, BG_Q_W => BG_Q_W, BG_O_W => BG_O_W, SEARCH_ITER => SEARCH_ITER,
                 STEP16 => STEP16, MARGIN_MAX => MARGIN_MAX, SCALE_TEST_D256 => SCALE_TEST_D256,
                 ORIENT_T => ORIENT_T, MODELS => MODELS, RAM_LAT => REGION_RD_LAT)
    port map (clk => clk, rst => rst, idle => e_idle, geo_done => e_geo_done, go => c_go, rearm => c_rearm,
              init_take => c_init, init_x => c_init_x, init_y => c_init_y, init_w => c_init_w,
              init_h => c_init_h, init_fw => c_init_fw, init_fh => c_init_fh, init_rejected => e_init_rej,
              load_take => c_load, load_state => c_load_state, load_model => c_load_model,
              rec => tgt_state, rec_valid => e_valid, rec_init => e_init, rec_c8x => e_c8x, rec_c8y => e_c8y,
              rec_w8 => e_w8, rec_h8 => e_h8, rec_fw => e_fw, rec_fh => e_fh,
              geo_l2d => l2d, geo_reg_x => reg_x, geo_reg_y => reg_y, geo_reg_w => reg_w_c, geo_reg_h => reg_h_c,
              geo_wb => wb, geo_hb => hb, geo_bg_cx => bg_cx, geo_bg_cy => bg_cy,
              m_sel => m_sel, m_rd_addr => m_rd_addr, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all,
              m_t_all => m_t_all, ram_addr => ram_addr, ram_data => ram_data, ram_obin => ram_obin,
              res_valid => e_res_valid, res_ready => fifo_ready, res_data => e_res_data,
              word_fcount => frame_count, word_rejected => rejected_pending, word_overflow => overflow,
              busy => e_busy);
  busy <= e_busy;

  ---------------------------------------------------------------------------- results
  u_fifo : entity work.ms_fifo
    generic map (WIDTH => RESULT_W, DEPTH => 4)
    port map (clk => clk, rst => rst, s_valid => fifo_valid, s_ready => fifo_ready, s_data => fifo_data,
              m_valid => m_axis_result_tvalid, m_ready => m_axis_result_tready, m_data => m_axis_result_tdata);
  m_axis_result_tlast <= '1';

  ---------------------------------------------------------------------------- control
  -- the stream side takes a frame or a command while it and the engine are idle, and not on the
  -- clock an init's geometry arrives (ms_bg_model is armed first)
  ctl_idle <= '1' when tstate = S_IDLE and e_idle = '1' and cmd_pending = '0'
                      and not (e_geo_done = '1' and e_init = '1') else '0';
  cmd_pending <= c_go or c_rearm or c_init or c_load;
  err_push <= ctl_idle and not cap_done and err_pending and fifo_ready;
  -- the engine's commands: a job once the region is in (an init's once its model is learnt); the
  -- geometry again after a word of the stream side, after a fault on an init frame (not a cut), and
  -- before a start of frame that would reach an ms_bg_model no longer clean
  e_go <= '1' when (ctl_idle = '1' and cap_done = '1' and e_init = '0' and e_valid = '1'
                    and fr_w = e_fw and fr_h = e_fh)
                   or (tstate = S_BG and bg_got = '1') else '0';
  e_rearm <= '1' when (err_push = '1' and fe_error = '0' and e_init = '1' and err_code_r /= ERR_CUT)
                      or (ctl_idle = '1' and cap_done = '0' and not (err_pending = '1' and fifo_ready = '1')
                          and init_take = '0' and tgt_take = '0' and s_axis_tvalid = '1' and bg_rearm = '1'
                          and gate_closed = '0' and err_hold = '0' and fe_err_now = '0')
                      or (tstate = S_PUSH and fifo_ready = '1') else '0';

  p_cmd : process(clk)
  begin
    if rising_edge(clk) then
      c_go <= e_go;
      c_rearm <= e_rearm;
      c_init <= init_take;
      c_load <= tgt_take;
      if init_take = '1' then
        c_init_x <= s_init_x; c_init_y <= s_init_y; c_init_w <= s_init_w; c_init_h <= s_init_h;
        c_init_fw <= frame_width; c_init_fh <= frame_height;
      end if;
      if tgt_take = '1' then
        c_load_state <= tgt_load_state;
        c_load_model <= tgt_load_model;
      end if;
      if rst = '1' then
        c_go <= '0';
        c_rearm <= '0';
        c_init <= '0';
        c_load <= '0';
      end if;
    end if;
  end process;

  p_ctrl : process(clk)
  begin
    if rising_edge(clk) then
      fifo_valid <= '0';
      bg_start <= '0';
      bg_rst_p <= '0';
      if fe_err_now = '1' then
        err_hold <= '1';
      end if;
      if fe_error = '1' then
        if err_pending = '1' then
          overflow <= '1';
        end if;
        err_pending <= '1';
        err_code_r <= fe_code;
      end if;
      if bg_done = '1' then
        bg_got <= '1';
      end if;
      if beat = '1' then
        bg_clean <= '0';
      end if;
      if e_init_rej = '1' then
        rejected_pending <= '1';
      end if;

      case tstate is
        when S_IDLE =>
          if e_geo_done = '1' and e_init = '1' then      -- an init's region: arm ms_bg_model first
            bg_rst_p <= '1';
            tstate <= S_ARM1;
          elsif ctl_idle = '1' and cap_done = '1' then
            if (e_init = '1' or e_valid = '1') and (fr_w /= e_fw or fr_h /= e_fh) then
              top_word <= side_word(e_c8x, e_c8y, e_w8, e_h8, ST_ERROR,
                                    v2_flags('0', '0', '0', '1', rejected_pending, not e_valid, overflow),
                                    ERR_SIZE_CHANGED, frame_count);
              tstate <= S_PUSH;
            elsif e_init = '1' then
              tstate <= S_BG;
            elsif e_valid = '1' then
              tstate <= S_RUN;                           -- e_go
            else
              top_word <= side_word(e_c8x, e_c8y, e_w8, e_h8, ST_OK,
                                    v2_flags('0', '0', '0', '0', rejected_pending, '1', overflow),
                                    "000", frame_count);
              tstate <= S_PUSH;
            end if;
          elsif err_push = '1' then
            fifo_data <= side_word(e_c8x, e_c8y, e_w8, e_h8, ST_ERROR,
                                   v2_flags('0', '0', '0', '1', rejected_pending, not e_valid, overflow),
                                   err_code_r, frame_count);
            fifo_valid <= '1';
            frame_count <= frame_count + 1;
            overflow <= '0';
            rejected_pending <= '0';
            if fe_error = '0' then
              err_pending <= '0';
              if fe_err_now = '0' then
                err_hold <= '0';
              end if;
            end if;
          end if;

        when S_ARM1 =>                                   -- (bg_rst_p high this clock)
          tstate <= S_ARM2;

        when S_ARM2 =>
          if bg_busy = '0' then
            bg_start <= '1';
            tstate <= S_ARM3;
          end if;

        when S_ARM3 =>
          if bg_counting = '1' then
            bg_got <= '0';
            bg_clean <= '1';
            tstate <= S_IDLE;
          end if;

        when S_BG =>                                     -- e_go once the model is learnt
          if bg_got = '1' then
            tstate <= S_RUN;
          end if;

        when S_RUN =>
          if e_res_valid = '1' and fifo_ready = '1' then
            fifo_data <= e_res_data;
            fifo_valid <= '1';
            frame_count <= frame_count + 1;
            overflow <= '0';
            rejected_pending <= '0';
            tstate <= S_IDLE;
          end if;

        when S_PUSH =>                                   -- e_rearm with the push
          if fifo_ready = '1' then
            fifo_data <= top_word;
            fifo_valid <= '1';
            frame_count <= frame_count + 1;
            overflow <= '0';
            rejected_pending <= '0';
            tstate <= S_IDLE;
          end if;
      end case;

      if rst = '1' then
        tstate <= S_IDLE;
        rejected_pending <= '0';
        err_pending <= '0';
        err_hold <= '0';
        overflow <= '0';
        frame_count <= (others => '0');
        bg_clean <= '0';
      end if;
    end if;
  end process;

  init_ready <= '1' when ctl_idle = '1' and cap_done = '0' and err_pending = '0' and in_frame = '0'
                         and gate_closed = '0' and err_hold = '0' and fe_err_now = '0' else '0';
  init_take <= s_init_tvalid and init_ready;
  s_init_tready <= init_ready;
  -- a target load: between frames like an init (which goes first), not while an init frame is pending
  tgt_ready_i <= init_ready and not e_init and not s_init_tvalid;
  tgt_take <= tgt_load_valid and tgt_ready_i;
  tgt_load_ready <= tgt_ready_i;
end architecture;
