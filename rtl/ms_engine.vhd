-- ms_engine: one target's job on one frame of tracker v2 (mstrack.fixed.tracker_v2.FixedTrackerV2), bit
-- for bit: the sequencer of core v2 without its stream side.  It holds one target's state record (the
-- record of mstrack.fixed.vhdl_pkg.target_state_layout_v2), computes that target's region for the next
-- frame, and, once the region is in the memory behind ram_addr / ram_data (and on an init frame the
-- model has been learnt into ms_bg_model), runs the frame's work and gives the result word and the new
-- record.  ms_tracker_v2 (core v2) is ms_engine behind the stream side; docs/blocks/ms_engine.md.
--
-- Computes:
--   geometry (after reset, a load, an init box, a result, or rearm): log2 D = ms_decimation(w8, h8)
--   (+ 1 while lost), the decimated frame size, the window diameters (ms_window_size), the box
--   (ms_box_size), the search offsets (STEP16) and the region (ms_region_v2) around c8 >> log2 D; with
--   an init pending, the box centre in the decimated interior for ms_bg_model (bg_cx, bg_cy);
--   a job (go): ms_kernel_tables + K, the Qw load (ms_model_scale of the model read through m_*, into
--   the Q RAM of ms_meanshift; T into ms_target_stats), ms_meanshift from c8 >> log2 D (init: one pass,
--   `single`), ms_target_stats, rho (ms_fusion), ms_share, ms_confidence; while lost 8 more start
--   points x SEARCH_ITER iterations, the best confidence wins; for the winner ms_spread,
--   ms_ring_share, ms_loss_filter x 2, ms_loss_flag, the search state and status, ms_ref_update x 2,
--   with SCALE_TEST_D256 > 0 the gated scale test, ms_scale and ms_resize x 2; the result word v2
--   (frame_count, rejected and overflow from the ports) and the new record.
-- Commands, taken while idle = 1, at most one per clock: go (run the job), init_take (an init box:
--   ms_box_clip, its verdict acted on a clock after the clip's out_valid; a box it rejects gives
--   init_rejected, otherwise the record becomes an init pending),
--   load_take (another target's record and model; an init pending is dropped: it was the previous
--   target's, and the record does not hold one; load_state is sampled with load_take and written into
--   the record the next clock), rearm (compute the geometry again).
-- Latency: init_take -> init_rejected or the record: 6 clocks; geometry about 25 clocks (+ 3 with an
--   init pending, + 4 more with SLOT_INIT, + 1 after a load); go -> res_valid: the kernel tables
--   (<= 289 clocks), the Qw load (N_BINS + 6), the mean shift (docs/realtime.md), ~60 clocks of
--   statistics and about 230 of confidence, loss flag, scale and resize; while lost 8 more mean
--   shifts with their confidence; the gated scale test adds about 2 x (tables + Qw load + one pass)
--   on a frame that scales.  Measured per sequence:
--   docs/blocks/ms_tracker_v2.md (studies/v2_latency.py).
-- Throughput: one job at a time; the region memory is read LANES pixels per clock (RAM_LAT clocks of
--   read latency).
-- The record's registers are written under registers set a clock before (rec_ld, clip_ok, lf_take,
--   t_res), and the spread and ring share under their blocks' done, not under the state's decode,
--   where their sources allow; the final statistics (st_fin) under run_ms and fin_best; the region's
--   last column and row and the scale test's fit verdict are registered a state before the compares and
--   decisions that use them (T_RECT2, T_ST_FIT).
-- Handshake: the command pulses above; res_valid / res_ready for the word (the record shows the new
--   state from then on; after the handshake the geometry of the next frame follows).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_engine is
  generic (
    MAX_FRAME_W    : natural := 2048;     -- widest frame
    LANES          : natural := 4;        -- pixels per clock of a pixel pass
    COLOUR_BITS    : natural := 3;        -- bits per channel of the colour bin
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
    -- target models held (one per target when one engine serves several: load_model); 1 = core v2
    MODELS          : positive := 1;
    -- read latency of the region memory behind ram_addr / ram_data (ms_region_ram's RD_LAT)
    RAM_LAT         : positive := 4;
    -- the init job from a slot (the multi-target core): false = core v2 (the init frame's region is in
    -- the memory, the model counted on the stream); true = the memory holds init_capture's rectangle
    -- (geo_rect_*: the box's ring and the region), the model is counted from it (ms_init_job) and the
    -- reference pass addresses from the rectangle's origin with the region's clamp (ms_meanshift LO_IN)
    SLOT_INIT       : boolean := false
  );
  port (
    clk            : in  std_logic;
    rst            : in  std_logic;
    idle           : out std_logic;        -- waiting for a command; the geometry below is the next job's
    geo_done       : out std_logic := '0'; -- one clock, with idle: the geometry has just been computed
    go             : in  std_logic;        -- run the job (its region is in the memory; an init's model is learnt)
    rearm          : in  std_logic;        -- compute the geometry again
    init_take      : in  std_logic;        -- an init box and its frame size
    init_x         : in  signed(COORD_W + 1 downto 0);
    init_y         : in  signed(COORD_W + 1 downto 0);
    init_w         : in  unsigned(COORD_W downto 0);
    init_h         : in  unsigned(COORD_W downto 0);
    init_fw        : in  unsigned(COORD_W - 1 downto 0);
    init_fh        : in  unsigned(COORD_W - 1 downto 0);
    init_rejected  : out std_logic := '0'; -- one clock: the box was rejected (the record is unchanged)
    load_take      : in  std_logic;        -- another target's record and model
    load_state     : in  std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                     SPREAD_W) - 1 downto 0);
    load_model     : in  unsigned(clog2(MODELS) - 1 downto 0);
    -- the record (target_state_layout_v2) and the fields the stream side reads from it
    rec            : out std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                     SPREAD_W) - 1 downto 0);
    rec_valid      : out std_logic;        -- a target is tracked
    rec_init       : out std_logic;        -- an init is pending (the next job learns)
    rec_c8x        : out unsigned(CENTRE_ABS_W - 1 downto 0);
    rec_c8y        : out unsigned(CENTRE_ABS_W - 1 downto 0);
    rec_w8         : out unsigned(SIZE_W - 1 downto 0);
    rec_h8         : out unsigned(SIZE_W - 1 downto 0);
    rec_fw         : out unsigned(COORD_W - 1 downto 0);   -- the target's frame size
    rec_fh         : out unsigned(COORD_W - 1 downto 0);
    -- the next job's geometry (valid while idle): decimation, region, box and its centre
    geo_l2d        : out unsigned(2 downto 0);
    geo_reg_x      : out unsigned(COORD_W - 1 downto 0);
    geo_reg_y      : out unsigned(COORD_W - 1 downto 0);
    geo_reg_w      : out unsigned(COORD_W - 1 downto 0);
    geo_reg_h      : out unsigned(COORD_W - 1 downto 0);
    geo_wb         : out unsigned(COORD_W - 1 downto 0);
    geo_hb         : out unsigned(COORD_W - 1 downto 0);
    geo_bg_cx      : out unsigned(COORD_W - 1 downto 0);
    geo_bg_cy      : out unsigned(COORD_W - 1 downto 0);
    -- SLOT_INIT, an init pending: the rectangle to capture (mstrack.fixed.multi_capacity.init_capture)
    geo_rect_x     : out unsigned(COORD_W - 1 downto 0);
    geo_rect_y     : out unsigned(COORD_W - 1 downto 0);
    geo_rect_w     : out unsigned(COORD_W - 1 downto 0);
    geo_rect_h     : out unsigned(COORD_W - 1 downto 0);
    -- the frame's last column / row in decimated px when it is a border pixel at full resolution
    -- the window diameters (decimated px) of the next job (an init's: init_capture's wd, hd)
    geo_wd         : out unsigned(WIN_W - 1 downto 0);
    geo_hd         : out unsigned(WIN_W - 1 downto 0);
    -- ((W - 1) mod D = 0), else all ones (ms_init_job counts border pixels with orientation 8)
    geo_last_x     : out unsigned(COORD_W - 1 downto 0);
    geo_last_y     : out unsigned(COORD_W - 1 downto 0);
    -- the target's model (ms_bg_model): m_sel selects it, m_rd_addr -> m_qn, m_t one clock later
    m_sel          : out unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
    m_rd_addr      : out unsigned(3 * COLOUR_BITS - 1 downto 0) := (others => '0');
    m_qn           : in  unsigned(16 downto 0);
    m_t            : in  std_logic;
    m_qn_all       : in  std_logic_vector((8 * boolean'pos(ORIENT_T >= 0) + 1) * 17 - 1 downto 0);
    m_t_all        : in  std_logic_vector(8 * boolean'pos(ORIENT_T >= 0) downto 0);
    -- the region memory (colour bins; orientation bins with ORIENT_T >= 0), RAM_LAT clocks
    ram_addr       : out std_logic_vector(LANES * ADDR_W - 1 downto 0);
    -- ram_addr of the next clock (combinational, ms_pixel_pass): for a memory that registers the
    -- address once more in front of its RAMs (ms_slot_pool), RAM_LAT + 1 clocks from ram_addr_next
    ram_addr_next  : out std_logic_vector(LANES * ADDR_W - 1 downto 0);
    ram_data       : in  std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);
    ram_obin       : in  std_logic_vector(LANES * 4 - 1 downto 0);
    -- the result word (result word v2; its frame_count, rejected and overflow from these inputs)
    res_valid      : out std_logic;
    res_ready      : in  std_logic;
    res_data       : out std_logic_vector(RESULT_W - 1 downto 0);
    word_fcount    : in  unsigned(15 downto 0);
    word_rejected  : in  std_logic;
    word_overflow  : in  std_logic;
    busy           : out std_logic         -- the mean shift is running
  );
end entity;

architecture rtl of ms_engine is
  constant BIN_C_W   : natural := 3 * COLOUR_BITS;
  constant OR_ON     : boolean := ORIENT_T >= 0;
  constant N_OR      : natural := 9 * boolean'pos(OR_ON) + boolean'pos(not OR_ON);   -- orientation banks
  constant N_BINS    : natural := 2 ** BIN_C_W;
  constant ONE16     : natural := 65536;
  constant BOX_HALF_W : natural := COORD_W - 1;     -- ms_box_clip without shrink: MAX_HALF 2**(COORD_W-1) - 1
  -- status codes (mstrack.fixed.vhdl_pkg.STATUS_V2)
  constant ST_OK     : unsigned(2 downto 0) := "000";
  constant ST_UNC    : unsigned(2 downto 0) := "001";
  constant ST_LOST   : unsigned(2 downto 0) := "010";
  constant ST_REACQ  : unsigned(2 downto 0) := "011";
  constant ST_INIT   : unsigned(2 downto 0) := "100";
  constant ST_CLIP   : unsigned(2 downto 0) := "101";

  type tstate_t is (T_PREP, T_DEC, T_DEC_WAIT, T_SIZE, T_SIZE_WAIT, T_BOX, T_BOX1, T_BOX2, T_RECT0, T_RECT1,
                    T_RECT2, T_RECT3,
                    T_REGION_WAIT, T_IDLE, T_LOAD, T_CLIP, T_TABLES, T_QLOAD, T_RUN, T_C0, T_C1, T_C2,
                    T_CNEXT, T_STATS0, T_STATS, T_CONF,
                    T_DECIDE, T_ST_SIZE, T_ST_WS, T_ST_WS_WAIT, T_ST_FIT, T_ST_RUN, T_ST_RHO, T_ST_NEXT,
                    T_ST_GATE, T_SCALE, T_RESIZE, T_RESULT, T_PUSH);
  signal fsm : tstate_t := T_PREP;
  -- load_state registered every clock: T_LOAD writes the record from it (the clock after load_take), so
  -- the record's enable is T_LOAD's decode, not T_IDLE's command priority
  signal ld_st : std_logic_vector(load_state'range) := (others => '0');
  -- '1' in T_RESULT's clock, set with the transition: the word and the init's references are written
  -- under it (a register, not the state's decode, in their clock enables)
  signal t_res : std_logic := '0';
  -- the init box's verdict, registered every clock from ms_box_clip's registered outputs and the frame
  -- size: T_CLIP acts on it a clock after out_valid, so the record's clock enable is a register and
  -- T_CLIP's decode, not the compares
  signal in_bad, clip_v, clip_rej, clip_ok : std_logic := '0';
  -- '1' in T_LOAD's clock, set with the transition: the loaded record is written under it
  signal rec_ld : std_logic := '0';
  -- ms_loss_filter's done, registered: the smoothed rho and contrast (held by the filter) are written
  -- under it, not under T_CONF's decode
  signal lf_take : std_logic := '0';

  -- target state (one record per target)
  signal target_valid, init_pending, init_clipped : std_logic := '0';
  signal c8x, c8y     : unsigned(CENTRE_ABS_W - 1 downto 0) := (others => '0');
  signal w8, h8, w0_8 : unsigned(SIZE_W - 1 downto 0) := (others => '0');
  signal rho_ref, share_ref, rho0 : unsigned(SHARE_W - 1 downto 0) := (others => '0');
  signal rho_s, con_s : signed(CON_W - 1 downto 0) := (others => '0');
  signal spread_ref   : unsigned(SPREAD_W - 1 downto 0) := (others => '0');
  signal lost_st, reported_lost : std_logic := '0';
  signal lost_st_frame : std_logic := '0';             -- lost_st of the frame being finished
  -- the target state record (tgt_state): field offsets from bit 0 (target_state_layout_v2)
  constant TS_W      : natural := v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W, SPREAD_W);
  constant TS_C8X    : natural := 3;
  constant TS_C8Y    : natural := TS_C8X + CENTRE_ABS_W;
  constant TS_W8     : natural := TS_C8Y + CENTRE_ABS_W;
  constant TS_H8     : natural := TS_W8 + SIZE_W;
  constant TS_W0     : natural := TS_H8 + SIZE_W;
  constant TS_FW     : natural := TS_W0 + SIZE_W;
  constant TS_FH     : natural := TS_FW + COORD_W;
  constant TS_RREF   : natural := TS_FH + COORD_W;
  constant TS_SREF   : natural := TS_RREF + SHARE_W;
  constant TS_RHO0   : natural := TS_SREF + SHARE_W;
  constant TS_RHOS   : natural := TS_RHO0 + SHARE_W;
  constant TS_CONS   : natural := TS_RHOS + CON_W;
  constant TS_SPREF  : natural := TS_CONS + CON_W;
  signal tgt_w, tgt_h : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);
  signal in_fw, in_fh : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);

  -- per-frame geometry
  signal l2d          : unsigned(2 downto 0) := (others => '0');
  signal dw, dh       : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);   -- decimated frame size
  signal wd, hd       : unsigned(WIN_W - 1 downto 0) := to_unsigned(3, WIN_W);
  signal wb, hb       : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);
  signal ex_r, ey_r   : unsigned(HALF_W - 1 downto 0) := to_unsigned(1, HALF_W);
  signal s8x, s8y     : unsigned(CENTRE_ABS_W - 1 downto 0) := (others => '0');      -- start centre (decimated)
  signal k_acc        : unsigned(HIST_W - 1 downto 0) := (others => '0');
  signal ox_r, oy_r   : unsigned(COORD_W - 1 downto 0) := (others => '0');                -- search offsets (decimated px)
  -- start points: 0 the last centre, 1 .. 8 (while lost) the centre +- (ox, oy)
  signal cand         : unsigned(3 downto 0) := (others => '0');
  signal eng_cx, eng_cy : unsigned(CENTRE_ABS_W - 1 downto 0) := (others => '0');
  signal eng_max_it   : unsigned(ITER_W - 1 downto 0) := to_unsigned(MAX_ITER, ITER_W);
  signal best_cx, best_cy : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal best_s       : unsigned(RHO_SUM_W - 1 downto 0);
  signal best_conf    : unsigned(16 downto 0);
  signal best_take    : std_logic := '0';            -- T_C2 found a better start point (copy next clock)
  signal reg_x, reg_y : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal reg_w, reg_h : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal hi_x, hi_y   : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal reg_w_c, reg_h_c : unsigned(COORD_W - 1 downto 0);
  -- the region's last column and row (reg_x + reg_w - 1, reg_y + reg_h - 1, mod 2**COORD_W), registered with
  -- the region, so that T_RECT2 compares registers
  signal reg_x1, reg_y1 : unsigned(COORD_W - 1 downto 0) := (others => '0');
  -- the region (ms_region_v2, started when the window sizes are known); S - 2 per axis for the init box
  type rg_pair_t is array (0 to 1) of signed(COORD_W + 2 downto 0);
  signal rg_s2        : rg_pair_t;
  signal rv_in_valid, rv_out_valid : std_logic := '0';
  signal rv_cx, rv_cy : unsigned(COORD_W + CF - 1 downto 0);
  signal rv_reg_x, rv_reg_y : unsigned(COORD_W - 1 downto 0);
  signal rv_reg_w, rv_reg_h, rv_hi_x, rv_hi_y : unsigned(REGION_W - 1 downto 0);
  -- init box centre (T_BOX .. T_BOX2): round(c), half size, interior limits [hx + 1, S - 2 - hx]
  signal bx_c, by_c, bx_h, by_h, bx_lo, by_lo, bx_hi, by_hi : unsigned(COORD_W - 1 downto 0) := (others => '0');
  -- ms_region per axis: n = min(2e + 2m + 1, S - 2), start = clamp(round(c) - e - m, 1, S - 1 - n),
  -- hi (region-relative) = n - 1 - e
  function rg_s(u : unsigned) return signed is
  begin
    return signed(resize(u, COORD_W + 3));
  end function;
  function rg_round(c : unsigned) return signed is
  begin
    return signed(resize(shift_right(c + to_unsigned(2 ** (CF - 1), c'length), CF), COORD_W + 3));
  end function;
  -- init box: c := lo if c < lo; then c := hi if c > hi (unsigned), written with the compares side by side
  function box_clamp(c, lo, hi : unsigned) return unsigned is
  begin
    if c < lo then
      if lo > hi then return hi; else return lo; end if;
    else
      if c > hi then return hi; else return c; end if;
    end if;
  end function;
  signal lim_w, lim_h : unsigned(COORD_W - 1 downto 0);
  -- SLOT_INIT: the init rectangle = bbox(the box's ring clipped to the frame, the region) (T_RECT0 ..
  -- T_RECT3), and the pass's origin and clamp (the region's, or on an init job the rectangle's origin
  -- with the region's clamp moved by po = region origin - rectangle origin)
  signal ring_gx, ring_gy : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal rc_x0, rc_y0, rc_x1, rc_y1 : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal rect_x, rect_y, rect_w, rect_h : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal po_x, po_y   : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal last_x, last_y : unsigned(COORD_W - 1 downto 0) := (others => '1');
  signal ms_reg_x, ms_reg_y : unsigned(COORD_W - 1 downto 0);
  signal ms_hi_x, ms_hi_y, ms_lo_x, ms_lo_y : unsigned(REGION_W - 1 downto 0);
  signal lim_wn, lim_hn : unsigned(WIN_W - 1 downto 0);

  -- geometry blocks
  signal dec_in_valid, dec_out_valid : std_logic := '0';
  signal dec_l2       : unsigned(1 downto 0);
  signal ws_in_valid, ws_w_valid, ws_h_valid : std_logic := '0';
  signal ws_w, ws_h   : unsigned(WIN_W - 1 downto 0);
  signal ws_ex, ws_ey : unsigned(HALF_W - 1 downto 0);  -- (ws_w - 1) >> 1, (ws_h - 1) >> 1 as ex_r, ey_r take them
  signal st_fit       : std_logic := '0';               -- the scale test's window fits the region (T_ST_FIT)
  -- st_fin's two writes under registers: run_ms (fsm = T_RUN, as a flip-flop) with c_done, and fin_best
  -- (set in T_C2: high in T_CNEXT when the search ends and the last start point is not the best)
  signal run_ms, fin_best : std_logic := '0';
  signal bs_w_valid, bs_h_valid : std_logic;
  signal bs_w, bs_h   : unsigned(COORD_W - 1 downto 0);

  -- init path
  signal bc_valid, bc_out_valid, bc_rejected, bc_clipped : std_logic := '0';
  signal bc_x, bc_y, bc_w, bc_h : unsigned(COORD_W - 1 downto 0);
  signal bc_cx, bc_cy : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal in_x, in_y   : signed(COORD_W + 1 downto 0);
  signal in_w, in_h   : unsigned(COORD_W downto 0);

  -- background model
  signal bg_cx, bg_cy : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal q_we_one, q_we_all : std_logic;
  signal ms_out_qw_all : std_logic_vector(N_OR * HIST_W - 1 downto 0) := (others => '0');  -- Qw of the 9 banks

  -- kernel tables
  signal kt_start, kt_done, kt_we : std_logic := '0';
  signal kt_addr, kt_xr, kt_ex, kt_ey : unsigned(HALF_W - 1 downto 0);
  signal kt_ta, kt_tb, kd_d : unsigned(KD_W - 1 downto 0);
  signal kt_ka, kt_kb : unsigned(KT_W - 1 downto 0);

  -- Qw load
  signal ql_cnt       : unsigned(BIN_C_W downto 0) := (others => '0');
  signal ql_issue, ql_v1 : std_logic := '0';
  signal ql_bin1      : unsigned(BIN_C_W - 1 downto 0) := (others => '0');
  -- Qn registered once more before ms_model_scale (timing: model RAM read -> the multiplier's 3 Qn chain)
  signal ql_v2        : std_logic := '0';
  signal ql_bin2      : unsigned(BIN_C_W - 1 downto 0) := (others => '0');
  signal m_qn_r       : unsigned(16 downto 0) := (others => '0');
  signal ms_out_valid : std_logic;
  signal ms_out_qw    : unsigned(HIST_W - 1 downto 0);
  signal ms_out_tag   : std_logic_vector(BIN_C_W - 1 downto 0);
  signal ms_in_tag    : std_logic_vector(BIN_C_W - 1 downto 0);
  signal ql_seen      : unsigned(BIN_C_W downto 0) := (others => '0');

  -- engine
  signal eng_start, eng_single : std_logic := '0';
  signal c_busy, c_done : std_logic;
  signal c_cx, c_cy   : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal c_s          : unsigned(RHO_SUM_W - 1 downto 0);
  signal c_iter       : unsigned(ITER_W - 1 downto 0);
  signal c_stop       : std_logic_vector(1 downto 0);
  signal c_k          : unsigned(HIST_W - 1 downto 0);
  signal px_valid, px_last : std_logic;
  signal px_mask      : std_logic_vector(LANES - 1 downto 0);
  signal px_dx, px_dy : signed(REGION_W downto 0);
  type tap_t is record
    v, l : std_logic;
    m    : std_logic_vector(LANES - 1 downto 0);
    dx, dy : signed(REGION_W downto 0);
  end record;
  type tap_arr_t is array (1 to RAM_LAT - 1) of tap_t;
  signal tap          : tap_arr_t;
  signal t_we         : std_logic := '0';
  signal t_addr       : unsigned(BIN_C_W - 1 downto 0) := (others => '0');
  signal t_data       : std_logic := '0';

  -- statistics of the last two passes
  signal st_done      : std_logic;
  signal st_nt, st_n_in, st_nt_in : unsigned(COUNT_W - 1 downto 0);
  signal st_st2       : unsigned(ST2_W - 1 downto 0);
  type stats_t is record
    nt, n_in, nt_in : unsigned(COUNT_W - 1 downto 0);
    st2 : unsigned(ST2_W - 1 downto 0);
  end record;
  signal st_cur, st_prev, st_fin, best_st : stats_t;

  -- per-frame results
  signal r_cx, r_cy   : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal r_iter       : unsigned(ITER_W - 1 downto 0);
  signal r_stop       : std_logic_vector(1 downto 0);
  signal r_s          : unsigned(RHO_SUM_W - 1 downto 0);
  signal rho, share, ring : unsigned(SHARE_W - 1 downto 0) := (others => '0');
  signal spread       : unsigned(SPREAD_W - 1 downto 0) := (others => '0');
  signal conf         : unsigned(16 downto 0) := (others => '0');
  signal lflag        : std_logic := '0';
  signal rho_s_n, con_s_n : signed(CON_W - 1 downto 0);
  signal scale_s      : unsigned(SCALE_W - 1 downto 0);
  signal w8_n, h8_n   : unsigned(SIZE_W - 1 downto 0);
  signal rr_rho, rr_share : unsigned(SHARE_W - 1 downto 0);
  signal status_r     : unsigned(2 downto 0) := (others => '0');
  signal got          : std_logic_vector(3 downto 0) := (others => '0');

  -- block handshakes
  signal fu_start, fu_done, sh_start, sh_done, sp_start, sp_done, rs_start, rs_done : std_logic := '0';
  signal cf_start, cf_done, lf_start, lf_done, fl_start, fl_done : std_logic := '0';
  signal ru_d         : std_logic := '0';
  signal ru_start, sc_start, sc_done, rz_start, rzw_done, rzh_done : std_logic := '0';
  signal fu_rho       : unsigned(RHO_OUT_W - 1 downto 0);
  signal sh_share, rs_ring : unsigned(SHARE_W - 1 downto 0);
  signal sp_spread    : unsigned(SPREAD_W - 1 downto 0);
  signal con_x        : signed(CON_W - 1 downto 0);

  -- the gated scale test (SCALE_TEST_D256 > 0; T_ST_SIZE .. T_ST_GATE): the windows x(1 - d), x(1 + d)
  -- at the final centre, one after the other through the frame's own blocks (window size, kernel
  -- tables + K, Qw load, one pass of the engine without moving, ms_fusion's rho)
  constant ST_ON      : boolean := SCALE_TEST_D256 > 0;
  signal st_sel       : std_logic := '0';             -- the window-size inputs are the test sizes
  signal st_up        : std_logic := '0';             -- 0: x(1 - d), 1: x(1 + d)
  signal st_w8, st_h8 : unsigned(SIZE_W - 1 downto 0) := (others => '0');   -- ms_scale_test_size
  signal st_rx, st_ry : signed(COORD_W + 2 downto 0) := (others => '0');    -- round(final centre) - region origin
  signal st_best      : unsigned(SHARE_W - 1 downto 0) := (others => '0');  -- largest rho so far
  signal st_v         : signed(1 downto 0) := (others => '0');              -- verdict -1 / 0 / +1
  signal sp_gate      : unsigned(SPREAD_W - 1 downto 0) := (others => '0'); -- ms_scale_gate
  signal ws_s8w, ws_s8h : unsigned(SIZE_W - 1 downto 0);
  signal sc_spread    : unsigned(SPREAD_W - 1 downto 0);                    -- ms_scale's spread
  -- ms_scale_test_size(s8, d256, up) = (s8 (256 -+ d256) + 128) >> 8, saturated to SIZE_W bits (exact:
  -- a size of 2**SIZE_W - 1 already gives a window above MAX_WINDOW at D <= 16, asserted below)
  -- in two registered steps (p_st_size): the product s8 f, f = 256 -+ d256, then the rounding and
  -- saturation (st_round), so no multiplier output reaches a register through an adder in one clock
  signal st_pw_lo, st_pw_hi, st_ph_lo, st_ph_hi : unsigned(SIZE_W + 9 downto 0) := (others => '0');
  signal st_w8_lo, st_w8_hi, st_h8_lo, st_h8_hi : unsigned(SIZE_W - 1 downto 0) := (others => '0');
  constant ST_F_LO : natural := 256 - SCALE_TEST_D256;
  constant ST_F_HI : natural := 256 + SCALE_TEST_D256;
  function st_round(prod : unsigned) return unsigned is
    variable p : unsigned(SIZE_W + 9 downto 0);
  begin
    p := prod + 128;
    p := shift_right(p, 8);
    if p(SIZE_W + 9 downto SIZE_W) /= 0 then
      return to_unsigned(2 ** SIZE_W - 1, SIZE_W);
    end if;
    return p(SIZE_W - 1 downto 0);
  end function;

  -- results
  signal res_word     : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');

  function pack(cx, cy, bw, bh : unsigned; rh, cn : unsigned; st : unsigned; it : unsigned;
                sp : std_logic_vector; dl : unsigned; srch : unsigned; flags : std_logic_vector;
                err : std_logic_vector; fc : unsigned) return std_logic_vector is
  begin
    return v2_word(RESULT_W, CENTRE_ABS_W, SIZE_W, RHO_OUT_W, ITER_W, cx, cy, bw, bh, rh, cn, st, it, sp, dl,
                   srch, flags, err, fc);
  end function;

  function umin(a, b : unsigned) return unsigned is
  begin
    if a < b then return a; else return b; end if;
  end function;
begin
  assert RESULT_W = 160 report "ms_engine: RESULT_W must be 160 (result word v2)" severity failure;
  -- the scale test's size saturates at 2**SIZE_W - 1: exact while that size's window at D = 16 is >= MAX_WINDOW
  assert SCALE_TEST_D256 = 0 or (16 + PAD16) * (2 ** (SIZE_W - 16)) >= MAX_WINDOW
    report "ms_engine: SIZE_W too small for the scale test's saturated size" severity failure;

  ---------------------------------------------------------------------------- geometry
  u_decim : entity work.ms_decimation
    generic map (S8_W => SIZE_W, PAD16 => PAD16, MAX_WINDOW => MAX_WINDOW)
    port map (clk => clk, rst => rst, in_valid => dec_in_valid, w8 => w8, h8 => h8,
              out_valid => dec_out_valid, log2_d => dec_l2);

  -- the window-size inputs: the target size, or during the scale test the test window's size
  ws_s8w <= st_w8 when ST_ON and st_sel = '1' else w8;
  ws_s8h <= st_h8 when ST_ON and st_sel = '1' else h8;
  u_wsw : entity work.ms_window_size
    generic map (S8_W => SIZE_W, PAD16 => PAD16, N_W => WIN_W)
    port map (clk => clk, rst => rst, in_valid => ws_in_valid, s8 => ws_s8w, log2_d => l2d, limit => lim_wn,
              out_valid => ws_w_valid, n => ws_w);
  u_wsh : entity work.ms_window_size
    generic map (S8_W => SIZE_W, PAD16 => PAD16, N_W => WIN_W)
    port map (clk => clk, rst => rst, in_valid => ws_in_valid, s8 => ws_s8h, log2_d => l2d, limit => lim_hn,
              out_valid => ws_h_valid, n => ws_h);
  u_bsw : entity work.ms_box_size
    generic map (S8_W => SIZE_W, N_W => COORD_W)
    port map (clk => clk, rst => rst, in_valid => ws_in_valid, s8 => w8, log2_d => l2d, limit => lim_w,
              out_valid => bs_w_valid, n => bs_w);
  u_bsh : entity work.ms_box_size
    generic map (S8_W => SIZE_W, N_W => COORD_W)
    port map (clk => clk, rst => rst, in_valid => ws_in_valid, s8 => h8, log2_d => l2d, limit => lim_h,
              out_valid => bs_h_valid, n => bs_h);

  rv_cx <= resize(s8x, COORD_W + CF);
  rv_cy <= resize(s8y, COORD_W + CF);
  u_region : entity work.ms_region_v2
    generic map (COORD_W => COORD_W, CF => CF, HALF_W => HALF_W, REGION_W => REGION_W, MARGIN => MARGIN,
                 MARGIN_MAX => MARGIN_MAX)
    port map (clk => clk, rst => rst, in_valid => rv_in_valid, cx => rv_cx, cy => rv_cy, ex => ex_r, ey => ey_r,
              ox => ox_r, oy => oy_r, lost => lost_st, frame_w => dw, frame_h => dh, out_valid => rv_out_valid,
              reg_x => rv_reg_x, reg_y => rv_reg_y, reg_w => rv_reg_w, reg_h => rv_reg_h, hi_x => rv_hi_x,
              hi_y => rv_hi_y, region_margin => open);

  u_clip : entity work.ms_box_clip
    generic map (COORD_W => COORD_W, HALF_W => BOX_HALF_W, MAX_HALF => 2 ** BOX_HALF_W - 1, CF => CF)
    port map (clk => clk, rst => rst, in_valid => bc_valid, box_x => in_x, box_y => in_y,
              box_w => in_w, box_h => in_h, frame_w => in_fw, frame_h => in_fh,
              out_valid => bc_out_valid, rejected => bc_rejected, clipped => bc_clipped,
              clip_x => bc_x, clip_y => bc_y, clip_w => bc_w, clip_h => bc_h, ex => open,
              ey => open, cx => bc_cx, cy => bc_cy);

  u_tables : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KERNEL_EPAN => 1, KERNEL_BITS => KERNEL_BITS, KVAL_W => KT_W, KD_W => KD_W)
    port map (clk => clk, rst => rst, start => kt_start, w => resize(wd, HALF_W + 1),
              h => resize(hd, HALF_W + 1), busy => open, done => kt_done,
              ex => kt_ex, ey => kt_ey, kd_d => kd_d, kt_we => kt_we, kt_addr => kt_addr,
              kt_ta => kt_ta, kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr);

  ---------------------------------------------------------------------------- Qw = ms_model_scale(Qn, K)
  -- one register stage between the model RAM's read data and the multiplier: T_QLOAD counts the
  -- results (ql_seen = N_BINS), so it takes one clock more per frame, nothing else changes
  -- ms_scale_test_size of both test sizes, computed in every clock from w8, h8: the product registered,
  -- then rounded and saturated (2 clocks).  w8, h8 change only between frames (init) and in T_RESIZE,
  -- after the test, so at T_ST_SIZE these registers hold the sizes of this frame's w8, h8.
  g_st_size : if ST_ON generate
    p_st_size : process (clk)
    begin
      if rising_edge(clk) then
        st_pw_lo <= resize(w8 * to_unsigned(ST_F_LO, 10), SIZE_W + 10);
        st_pw_hi <= resize(w8 * to_unsigned(ST_F_HI, 10), SIZE_W + 10);
        st_ph_lo <= resize(h8 * to_unsigned(ST_F_LO, 10), SIZE_W + 10);
        st_ph_hi <= resize(h8 * to_unsigned(ST_F_HI, 10), SIZE_W + 10);
        st_w8_lo <= st_round(st_pw_lo);
        st_w8_hi <= st_round(st_pw_hi);
        st_h8_lo <= st_round(st_ph_lo);
        st_h8_hi <= st_round(st_ph_hi);
      end if;
    end process;
  end generate;

  p_qn_r : process (clk)
  begin
    if rising_edge(clk) then
      m_qn_r <= m_qn;
      ql_bin2 <= ql_bin1;
      ql_v2 <= ql_v1 and not rst;
    end if;
  end process;
  ms_in_tag <= std_logic_vector(ql_bin2);
  u_mscale : entity work.ms_model_scale
    generic map (HIST_W => HIST_W, QN_FRAC => 16, TAG_W => BIN_C_W)
    port map (clk => clk, rst => rst, in_valid => ql_v2, in_qn => m_qn_r, in_k => k_acc, in_tag => ms_in_tag,
              out_valid => ms_out_valid, out_qw => ms_out_qw, out_tag => ms_out_tag);

  -- ORIENT_T >= 0: the 9 banks of one colour address per clock (ms_bg_model's m_qn_all), 8 more
  -- ms_model_scale in lockstep with u_mscale (bank 0 is u_mscale's, m_qn = bank m_rd_obin = 0),
  -- into the engine's parallel Q load; the walk stays N_BINS colour addresses
  g_mscale : if OR_ON generate
    ms_out_qw_all(HIST_W - 1 downto 0) <= std_logic_vector(ms_out_qw);
    g_bank : for o in 1 to N_OR - 1 generate
      signal qn_r : unsigned(16 downto 0);
      signal qw   : unsigned(HIST_W - 1 downto 0);
    begin
      p_r : process (clk)
      begin
        if rising_edge(clk) then
          qn_r <= unsigned(m_qn_all(o * 17 + 16 downto o * 17));
        end if;
      end process;
      u_ms : entity work.ms_model_scale
        generic map (HIST_W => HIST_W, QN_FRAC => 16, TAG_W => 1)
        port map (clk => clk, rst => rst, in_valid => ql_v2, in_qn => qn_r, in_k => k_acc, in_tag => "0",
                  out_valid => open, out_qw => qw, out_tag => open);
      ms_out_qw_all((o + 1) * HIST_W - 1 downto o * HIST_W) <= std_logic_vector(qw);
    end generate;
  end generate;

  ---------------------------------------------------------------------------- engine + statistics
  -- the Qw load: one bin per clock (colour bins), or every bank of a colour address (ORIENT_T >= 0)
  q_we_one <= ms_out_valid when not OR_ON else '0';
  q_we_all <= ms_out_valid when OR_ON else '0';
  u_colour : entity work.ms_meanshift
    generic map (LANES => LANES, BIN_W => BIN_C_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, COORD_W => COORD_W, KERNEL_EPAN => 0,
                 KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W, KD_W => KD_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, SQRT_IN_W => SQRT_IN_W,
                 RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, WF => WF,
                 RF => RF, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CF => CF,
                 CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, MAX_ITER => MAX_ITER,
                 ITER_W => ITER_W, EPS2 => EPS2, RAM_LAT => RAM_LAT, N_ORIENT => N_OR,
                 LO_IN => SLOT_INIT)
    port map (clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka(KVAL_W - 1 downto 0), kt_kb => kt_kb(KVAL_W - 1 downto 0),
              kt_xr => kt_xr, kd_d => kd_d, ex => ex_r, ey => ey_r,
              reg_x => ms_reg_x, reg_y => ms_reg_y, hi_x => ms_hi_x, hi_y => ms_hi_y,
              lo_x_in => ms_lo_x, lo_y_in => ms_lo_y, start => eng_start,
              learn => '0', start_cx => eng_cx, start_cy => eng_cy, busy => c_busy, done => c_done,
              res_cx => c_cx, res_cy => c_cy, res_s => c_s, res_iter => c_iter, res_stop => c_stop,
              res_k => c_k, ram_addr => ram_addr, ram_addr_next => ram_addr_next, ram_data => ram_data,
              ram_obin => ram_obin,
              single => eng_single, max_it => eng_max_it,
              q_ext_we => q_we_one, q_ext_addr => unsigned(ms_out_tag), q_ext_data => ms_out_qw,
              q_ext_all_we => q_we_all, q_ext_all_data => ms_out_qw_all,
              px_valid => px_valid, px_mask => px_mask, px_dx => px_dx, px_dy => px_dy, px_last => px_last);

  -- the tap is aligned with ram_addr; ms_target_stats wants the bins one clock after it
  p_tap : process(clk)
  begin
    if rising_edge(clk) then
      tap(1) <= (v => px_valid, l => px_last, m => px_mask, dx => px_dx, dy => px_dy);
      for i in 2 to RAM_LAT - 1 loop
        tap(i) <= tap(i - 1);
      end loop;
      if rst = '1' then
        for i in 1 to RAM_LAT - 1 loop
          tap(i).v <= '0';
          tap(i).l <= '0';
        end loop;
      end if;
    end if;
  end process;

  u_stats : entity work.ms_target_stats
    generic map (LANES => LANES, BIN_W => BIN_C_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 KERNEL_BITS => KERNEL_BITS, KT_W => KT_W, PAD16 => PAD16, COUNT_W => COUNT_W, ST2_W => ST2_W,
                 N_ORIENT => N_OR)
    port map (clk => clk, rst => rst, t_we => t_we, t_addr => t_addr, t_data => t_data, t_data_all => m_t_all,
              kt_we => kt_we, kt_addr => kt_addr, kt_ka => kt_ka, kt_kb => kt_kb,
              px_valid => tap(RAM_LAT - 1).v, px_mask => tap(RAM_LAT - 1).m,
              px_dx => tap(RAM_LAT - 1).dx, px_dy => tap(RAM_LAT - 1).dy,
              px_last => tap(RAM_LAT - 1).l,
              ram_data => ram_data, ram_obin => ram_obin, done => st_done, nt => st_nt, st2 => st_st2, n_in => st_n_in,
              nt_in => st_nt_in);


  ---------------------------------------------------------------------------- per-frame arithmetic
  u_rho : entity work.ms_fusion
    generic map (FEATURES => 1, RHO_SUM_W => RHO_SUM_W, HIST_W => HIST_W,
                 CENTRE_ABS_W => CENTRE_ABS_W, AF => AF, ALPHA_W => ALPHA_W, RF => RF,
                 RHO_OUT_FRAC => RHO_OUT_FRAC, RHO_OUT_W => RHO_OUT_W)
    port map (clk => clk, rst => rst, start => fu_start, s_c => r_s, s_e => (others => '0'), c_cx => r_cx,
              c_cy => r_cy, e_cx => r_cx, e_cy => r_cy, k_sum => k_acc, done => fu_done, cx => open,
              cy => open, alpha_c => open, rho_c => fu_rho, rho_e => open);

  u_share : entity work.ms_share
    generic map (COUNT_W => COUNT_W, SHARE_W => SHARE_W)
    port map (clk => clk, rst => rst, start => sh_start, nt_in => st_fin.nt_in, n_in => st_fin.n_in,
              busy => open, done => sh_done, share => sh_share);

  u_spread : entity work.ms_spread
    generic map (COUNT_W => COUNT_W, ST2_W => ST2_W, SPREAD_W => SPREAD_W)
    port map (clk => clk, rst => rst, start => sp_start, st2 => st_fin.st2, nt => st_fin.nt,
              busy => open, done => sp_done, spread => sp_spread);

  u_ring : entity work.ms_ring_share
    generic map (COUNT_W => COUNT_W, SHARE_W => SHARE_W)
    port map (clk => clk, rst => rst, start => rs_start, nt => st_fin.nt, nt_in => st_fin.nt_in,
              n_in => st_fin.n_in, k => resize(k_acc, COUNT_W), busy => open, done => rs_done,
              ring_share => rs_ring);

  u_conf : entity work.ms_confidence
    generic map (W => SHARE_W)
    port map (clk => clk, rst => rst, start => cf_start, rho => rho, share => share, rho_ref => rho_ref,
              share_ref => share_ref, busy => open, done => cf_done, conf => conf);

  con_x <= signed(resize(share, CON_W)) - signed(resize(ring, CON_W));
  u_lf_rho : entity work.ms_loss_filter
    generic map (W => CON_W, K_SHIFT => LOSS_K)
    port map (clk => clk, rst => rst, start => lf_start, s => rho_s, x => signed(resize(rho, CON_W)),
              busy => open, done => lf_done, s_next => rho_s_n);
  u_lf_con : entity work.ms_loss_filter
    generic map (W => CON_W, K_SHIFT => LOSS_K)
    port map (clk => clk, rst => rst, start => lf_start, s => con_s, x => con_x,
              busy => open, done => open, s_next => con_s_n);

  u_flag : entity work.ms_loss_flag
    generic map (RHO_W => SHARE_W, CON_W => CON_W, LOSS_RHO => LOSS_RHO, LOSS_CONTRAST => LOSS_CONTRAST)
    port map (clk => clk, rst => rst, start => fl_start, rho_s => unsigned(rho_s(SHARE_W - 1 downto 0)),
              rho0 => rho0, con_s => con_s, share => share, busy => open, done => fl_done, lost => lflag);

  u_ref_rho : entity work.ms_ref_update
    generic map (W => SHARE_W, K_SHIFT => REF_K)
    port map (clk => clk, rst => rst, start => ru_start, ref_in => rho_ref, x => rho, busy => open,
              done => open, ref_next => rr_rho);
  u_ref_share : entity work.ms_ref_update
    generic map (W => SHARE_W, K_SHIFT => REF_K)
    port map (clk => clk, rst => rst, start => ru_start, ref_in => share_ref, x => share, busy => open,
              done => open, ref_next => rr_share);

  sc_spread <= sp_gate when ST_ON else spread;        -- the gated spread (ms_scale_gate) with the scale test
  u_scale : entity work.ms_scale
    generic map (SPREAD_W => SPREAD_W, SIZE_W => SIZE_W, SCALE_W => SCALE_W, SCALE_GAIN => SCALE_GAIN,
                 SCALE_REG => SCALE_REG, SCALE_STEP => SCALE_STEP, RATIO_Q_W => SCALE_RATIO_Q_W,
                 WR_Q_W => WR_Q_W)
    port map (clk => clk, rst => rst, start => sc_start, spread => sc_spread, spread_ref => spread_ref,
              w8 => w8, w0_8 => w0_8, busy => open, done => sc_done, s => scale_s);

  u_rz_w : entity work.ms_resize
    generic map (SIZE_W => SIZE_W, SCALE_W => SCALE_W, COORD_W => COORD_W)
    port map (clk => clk, rst => rst, start => rz_start, s8 => w8, s => scale_s, frame_size => tgt_w,
              busy => open, done => rzw_done, s8_out => w8_n);
  u_rz_h : entity work.ms_resize
    generic map (SIZE_W => SIZE_W, SCALE_W => SCALE_W, COORD_W => COORD_W)
    port map (clk => clk, rst => rst, start => rz_start, s8 => h8, s => scale_s, frame_size => tgt_h,
              busy => open, done => rzh_done, s8_out => h8_n);

  -- the pass's origin and clamp: the region's; with SLOT_INIT on an init job the rectangle's origin and
  -- the region's clamp moved into it (registered: they change between jobs, long before a pass)
  g_pass_region : if not SLOT_INIT generate
    ms_reg_x <= reg_x;
    ms_reg_y <= reg_y;
    ms_hi_x <= hi_x;
    ms_hi_y <= hi_y;
    ms_lo_x <= (others => '0');
    ms_lo_y <= (others => '0');
  end generate;
  g_pass_slot : if SLOT_INIT generate
    p_pass : process (clk)
    begin
      if rising_edge(clk) then
        if init_pending = '1' then
          ms_reg_x <= rect_x;
          ms_reg_y <= rect_y;
          ms_hi_x <= hi_x + po_x;
          ms_hi_y <= hi_y + po_y;
          ms_lo_x <= resize(ex_r, REGION_W) + po_x;
          ms_lo_y <= resize(ey_r, REGION_W) + po_y;
        else
          ms_reg_x <= reg_x;
          ms_reg_y <= reg_y;
          ms_hi_x <= hi_x;
          ms_hi_y <= hi_y;
          ms_lo_x <= resize(ex_r, REGION_W);
          ms_lo_y <= resize(ey_r, REGION_W);
        end if;
      end if;
    end process;
  end generate;

  reg_w_c <= resize(reg_w, COORD_W);
  ws_ex <= resize(shift_right(ws_w - 1, 1), HALF_W);
  ws_ey <= resize(shift_right(ws_h - 1, 1), HALF_W);
  reg_h_c <= resize(reg_h, COORD_W);

  -- window-size limits: min(MAX_WINDOW, decimated size - 2)
  lim_w  <= umin(dw - 2, to_unsigned(MAX_WINDOW, COORD_W));
  lim_h  <= umin(dh - 2, to_unsigned(MAX_WINDOW, COORD_W));
  lim_wn <= resize(lim_w, WIN_W);
  lim_hn <= resize(lim_h, WIN_W);
  ---------------------------------------------------------------------------- control
  p_ctrl : process(clk)
    variable k_add : unsigned(HIST_W - 1 downto 0);
    variable srch  : unsigned(2 downto 0);
    variable stat  : unsigned(2 downto 0);
    variable lost_now : std_logic;
    variable srch4    : unsigned(3 downto 0);
    variable sxo, syo : signed(CENTRE_ABS_W + 1 downto 0);
  begin
    if rising_edge(clk) then
      bc_valid <= '0';
      kt_start <= '0';
      eng_start <= '0';
      dec_in_valid <= '0';
      ws_in_valid <= '0';
      rv_in_valid <= '0';
      fu_start <= '0'; sh_start <= '0'; sp_start <= '0'; rs_start <= '0';
      cf_start <= '0'; lf_start <= '0'; fl_start <= '0'; ru_start <= '0';
      sc_start <= '0'; rz_start <= '0';
      ql_v1 <= '0';
      init_rejected <= '0';
      geo_done <= '0';
      ld_st <= load_state;
      t_res <= '0';
      in_bad <= '1' when in_fw < 3 or in_fh < 3 or in_fw > MAX_FRAME_W else '0';
      clip_v <= bc_out_valid;
      clip_rej <= bc_rejected or in_bad;
      clip_ok <= bc_out_valid and not (bc_rejected or in_bad);
      rec_ld <= '0';
      lf_take <= lf_done;
      -- the best start point so far (wide search): taken the clock after T_C2 decided it
      best_take <= '0';
      fin_best <= '0';
      if best_take = '1' then
        best_cx <= r_cx; best_cy <= r_cy; best_s <= r_s; best_st <= st_fin; best_conf <= conf;
      end if;

      -- the final statistics: the run's (its last or, at a rho stop, the pass before) or the best start point's
      if run_ms = '1' and c_done = '1' then
        if c_stop = STOP_RHO then
          st_fin <= st_prev;
        else
          st_fin <= st_cur;
        end if;
      end if;
      if fin_best = '1' then
        st_fin <= best_st;
      end if;

      -- statistics of the last two passes
      if st_done = '1' then
        st_prev <= st_cur;
        st_cur <= (nt => st_nt, n_in => st_n_in, nt_in => st_nt_in, st2 => st_st2);
      end if;

      case fsm is
        ------------------------------------------------------------ before a frame: geometry
        when T_PREP =>
          if init_pending = '1' or target_valid = '1' then
            dec_in_valid <= '1';
            fsm <= T_DEC_WAIT;
          else
            l2d <= (others => '0');
            geo_done <= '1';
            fsm <= T_IDLE;
          end if;

        when T_DEC_WAIT =>
          if dec_out_valid = '1' then
            if lost_st = '1' then                -- while lost: D x 2
              l2d <= resize(dec_l2, 3) + 1;
            else
              l2d <= resize(dec_l2, 3);
            end if;
            fsm <= T_DEC;
          end if;

        when T_DEC =>
          dw <= shift_right(tgt_w - 1, to_integer(l2d)) + 1;
          dh <= shift_right(tgt_h - 1, to_integer(l2d)) + 1;
          s8x <= shift_right(c8x, to_integer(l2d));
          s8y <= shift_right(c8y, to_integer(l2d));
          fsm <= T_SIZE;

        when T_SIZE =>                         -- lim_* follow dw, dh (registered in T_DEC)
          last_x <= (others => '1');
          last_y <= (others => '1');
          if ((tgt_w - 1) and (shift_left(to_unsigned(1, COORD_W), to_integer(l2d)) - 1)) = 0 then
            last_x <= dw - 1;
          end if;
          if ((tgt_h - 1) and (shift_left(to_unsigned(1, COORD_W), to_integer(l2d)) - 1)) = 0 then
            last_y <= dh - 1;
          end if;
          ws_in_valid <= '1';
          bx_c <= resize(shift_right(s8x + 2 ** (CF - 1), CF), COORD_W);   -- init box: round(c)
          by_c <= resize(shift_right(s8y + 2 ** (CF - 1), CF), COORD_W);
          fsm <= T_SIZE_WAIT;

        when T_SIZE_WAIT =>
          if ws_w_valid = '1' then
            wd <= ws_w;
            hd <= ws_h;
            ex_r <= resize(shift_right(ws_w - 1, 1), HALF_W);
            ey_r <= resize(shift_right(ws_h - 1, 1), HALF_W);
            wb <= bs_w;
            hb <= bs_h;
            -- search offsets ox, oy = (step16 wd) >> 4, (step16 hd) >> 4; the region margin grows by
            -- max(ox, oy) while lost (at most MARGIN_MAX)
            ox_r <= resize(shift_right(resize(ws_w, COORD_W + 6) * STEP16, 4), COORD_W);
            oy_r <= resize(shift_right(resize(ws_h, COORD_W + 6) * STEP16, 4), COORD_W);
            rv_in_valid <= '1';                -- ms_region_v2 takes ex_r .. oy_r the next clock
            rg_s2(0) <= rg_s(dw) - 2;
            rg_s2(1) <= rg_s(dh) - 2;
            fsm <= T_REGION_WAIT;
          end if;

        when T_REGION_WAIT =>                  -- the region of this frame (ms_region_v2)
          if rv_out_valid = '1' then
            reg_x <= rv_reg_x; reg_w <= rv_reg_w; hi_x <= rv_hi_x;
            reg_y <= rv_reg_y; reg_h <= rv_reg_h; hi_y <= rv_hi_y;
            reg_x1 <= rv_reg_x + resize(rv_reg_w, COORD_W) - 1;
            reg_y1 <= rv_reg_y + resize(rv_reg_h, COORD_W) - 1;
            if init_pending = '1' then
              fsm <= T_BOX;
            else
              geo_done <= '1';
              fsm <= T_IDLE;
            end if;
          end if;

        when T_BOX =>                          -- init box centre in the decimated interior: half sizes
          bx_h <= shift_right(resize(wb, COORD_W) - 1, 1);
          by_h <= shift_right(resize(hb, COORD_W) - 1, 1);
          fsm <= T_BOX1;

        when T_BOX1 =>                         -- limits hx + 1, S - 2 - hx (S - 2 from the region)
          bx_lo <= bx_h + 1;
          by_lo <= by_h + 1;
          bx_hi <= unsigned(rg_s2(0)(COORD_W - 1 downto 0)) - bx_h;
          by_hi <= unsigned(rg_s2(1)(COORD_W - 1 downto 0)) - by_h;
          fsm <= T_BOX2;

        when T_BOX2 =>                         -- c := max(c, lo); c := min(c, hi) (compares side by side)
          bg_cx <= box_clamp(bx_c, bx_lo, bx_hi);
          bg_cy <= box_clamp(by_c, by_lo, by_hi);
          if SLOT_INIT then
            fsm <= T_RECT0;
          else
            geo_done <= '1';
            fsm <= T_IDLE;
          end if;

        -- SLOT_INIT: init_capture's rectangle, from the box centre (bg_cx, bg_cy), its half sizes and the region
        when T_RECT0 =>                        -- the ring's width: (ring16 wb) >> 4
          ring_gx <= resize(shift_right(resize(wb, COORD_W + 5) * to_unsigned(RING16, 5), 4), COORD_W);
          ring_gy <= resize(shift_right(resize(hb, COORD_W + 5) * to_unsigned(RING16, 5), 4), COORD_W);
          fsm <= T_RECT1;

        when T_RECT1 =>                        -- the ring clipped to the frame:
                                               -- [max(0, c - h - g), min(S - 1, c + h + g)]
          if resize(bx_h, COORD_W + 1) + ring_gx > bg_cx then
            rc_x0 <= (others => '0');
          else
            rc_x0 <= bg_cx - bx_h - ring_gx;
          end if;
          if resize(by_h, COORD_W + 1) + ring_gy > bg_cy then
            rc_y0 <= (others => '0');
          else
            rc_y0 <= bg_cy - by_h - ring_gy;
          end if;
          rc_x1 <= umin(bg_cx + bx_h + ring_gx, dw - 1);
          rc_y1 <= umin(bg_cy + by_h + ring_gy, dh - 1);
          fsm <= T_RECT2;

        when T_RECT2 =>                        -- with the region: the smallest rectangle holding both
          rect_x <= umin(rc_x0, reg_x);
          rect_y <= umin(rc_y0, reg_y);
          if rc_x1 < reg_x1 then rc_x1 <= reg_x1; end if;
          if rc_y1 < reg_y1 then rc_y1 <= reg_y1; end if;
          fsm <= T_RECT3;

        when T_RECT3 =>
          rect_w <= rc_x1 - rect_x + 1;
          rect_h <= rc_y1 - rect_y + 1;
          po_x <= resize(reg_x - rect_x, REGION_W);
          po_y <= resize(reg_y - rect_y, REGION_W);
          geo_done <= '1';
          fsm <= T_IDLE;

        ------------------------------------------------------------ waiting for a frame / init
        when T_IDLE =>
          if go = '1' then
            kt_start <= '1';
            k_acc <= (others => '0');
            fsm <= T_TABLES;
          elsif init_take = '1' then
            in_x <= init_x; in_y <= init_y; in_w <= init_w; in_h <= init_h;
            in_fw <= init_fw; in_fh <= init_fh;
            bc_valid <= '1';
            fsm <= T_CLIP;
          elsif load_take = '1' then           -- another target: its model now, its state next clock
            m_sel <= load_model;
            init_pending <= '0';               -- an init pending was the previous target's
            init_clipped <= '0';
            rec_ld <= '1';
            fsm <= T_LOAD;
          elsif rearm = '1' then
            fsm <= T_PREP;
          end if;

        when T_LOAD =>                         -- the record taken with load_take (ld_st; rec_ld, below)
          fsm <= T_PREP;                       -- its region for the next frame

        when T_CLIP =>                         -- the verdict a clock after ms_box_clip's out_valid
          if clip_v = '1' then                 -- the accepted box's record: clip_ok, below
            if clip_rej = '1' then
              init_rejected <= '1';
              fsm <= T_IDLE;
            else
              fsm <= T_PREP;
            end if;
          end if;

        ------------------------------------------------------------ after a frame
        when T_TABLES =>                       -- K = sum over rows |dy| <= ey of (2 XR + 1)
          if kt_we = '1' and kt_addr <= ey_r then
            k_add := resize(shift_left(resize(kt_xr, HIST_W), 1) + 1, HIST_W);
            if kt_addr = 0 then
              k_acc <= k_acc + k_add;
            else
              k_acc <= k_acc + shift_left(k_add, 1);
            end if;
          end if;
          if kt_done = '1' then
            ql_cnt <= (others => '0');
            ql_seen <= (others => '0');
            fsm <= T_QLOAD;
          end if;

        when T_QLOAD =>                        -- Qn, T read -> ms_model_scale -> Q RAM; T -> stats
          if ql_cnt(BIN_C_W) = '0' then
            m_rd_addr <= ql_cnt(BIN_C_W - 1 downto 0);
            ql_cnt <= ql_cnt + 1;
            ql_issue <= '1';
          else
            ql_issue <= '0';
          end if;
          ql_v1 <= ql_issue;                   -- m_qn / m_t of m_rd_addr (1 clock)
          ql_bin1 <= m_rd_addr;
          if ms_out_valid = '1' then
            ql_seen <= ql_seen + 1;
          end if;
          if ql_seen = N_BINS and ST_ON and st_sel = '1' then
            -- scale test: one pass without moving at the final centre (clamped: the window fits,
            -- so round(clamp(c)) = round(c))
            eng_single <= '1';
            eng_cx <= r_cx;
            eng_cy <= r_cy;
            eng_start <= '1';
            fsm <= T_ST_RUN;
          elsif ql_seen = N_BINS then
            eng_single <= init_pending;
            eng_cx <= s8x;
            eng_cy <= s8y;
            if lost_st = '1' then
              eng_max_it <= to_unsigned(SEARCH_ITER, ITER_W);
            else
              eng_max_it <= to_unsigned(MAX_ITER, ITER_W);
            end if;
            cand <= (others => '0');
            eng_start <= '1';
            run_ms <= '1';
            fsm <= T_RUN;
          end if;

        when T_RUN =>
          if c_done = '1' then
            r_cx <= c_cx; r_cy <= c_cy; r_s <= c_s;
            if cand = 0 then                     -- iterations and stop of the centre's run
              r_iter <= c_iter; r_stop <= c_stop;
            end if;
            run_ms <= '0';                     -- st_fin: above, under run_ms and c_done
            fsm <= T_C0;
          end if;

        -- confidence of this start point's result; the best (the centre, then strictly better) wins
        when T_C0 =>
          got <= (others => '0');
          fu_start <= '1'; sh_start <= '1';
          fsm <= T_C1;

        when T_C1 =>
          if fu_done = '1' then got(0) <= '1'; rho <= fu_rho; end if;
          if sh_done = '1' then got(1) <= '1'; share <= sh_share; end if;
          if got(1 downto 0) = "11" then
            cf_start <= '1';
            fsm <= T_C2;
          end if;

        when T_C2 =>
          if cf_done = '1' then
            -- the decision only is registered here; the copy into best_* follows a clock later
            -- (in T_CNEXT, from r_*, st_fin and conf, which hold there), so the 17-bit compare
            -- drives one flip-flop and not the enables of the whole best_* record
            if cand = 0 or conf > best_conf then
              best_take <= '1';
            elsif not (lost_st = '1' and init_pending = '0' and cand /= 8) then
              fin_best <= '1';                 -- T_CNEXT ends the search on a start point that is not the best
            end if;
            fsm <= T_CNEXT;
          end if;

        when T_CNEXT =>
          if lost_st = '1' and init_pending = '0' and cand /= 8 then
            -- next start point (sx, sy) in (-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)
            sxo := signed(resize(s8x, CENTRE_ABS_W + 2));
            syo := signed(resize(s8y, CENTRE_ABS_W + 2));
            case to_integer(cand) is
              when 0 | 3 | 5 => sxo := sxo - signed(resize(shift_left(resize(ox_r, CENTRE_ABS_W), CF), CENTRE_ABS_W + 2));
              when 2 | 4 | 7 => sxo := sxo + signed(resize(shift_left(resize(ox_r, CENTRE_ABS_W), CF), CENTRE_ABS_W + 2));
              when others => null;
            end case;
            case to_integer(cand) is
              when 0 | 1 | 2 => syo := syo - signed(resize(shift_left(resize(oy_r, CENTRE_ABS_W), CF), CENTRE_ABS_W + 2));
              when 5 | 6 | 7 => syo := syo + signed(resize(shift_left(resize(oy_r, CENTRE_ABS_W), CF), CENTRE_ABS_W + 2));
              when others => null;
            end case;
            if sxo < 0 then sxo := (others => '0'); end if;
            if syo < 0 then syo := (others => '0'); end if;
            eng_cx <= unsigned(sxo(CENTRE_ABS_W - 1 downto 0));
            eng_cy <= unsigned(syo(CENTRE_ABS_W - 1 downto 0));
            cand <= cand + 1;
            eng_start <= '1';
            run_ms <= '1';
            fsm <= T_RUN;
          else
            if best_take = '0' then            -- else this start point is the best: r_*, st_fin hold it
              r_cx <= best_cx; r_cy <= best_cy; r_s <= best_s;   -- st_fin: above, under fin_best
            end if;
            fsm <= T_STATS0;
          end if;

        when T_STATS0 =>                       -- rho, share, spread, ring share side by side
          got <= (others => '0');
          fu_start <= '1'; sh_start <= '1'; sp_start <= '1'; rs_start <= '1';
          fsm <= T_STATS;

        when T_STATS =>
          if fu_done = '1' then got(0) <= '1'; rho <= fu_rho; end if;
          if sh_done = '1' then got(1) <= '1'; share <= sh_share; end if;
          if sp_done = '1' then got(2) <= '1'; end if;   -- (spread, ring: sp_done, rs_done, below)
          if rs_done = '1' then got(3) <= '1'; end if;
          if got = "1111" then
            if init_pending = '1' then
              t_res <= '1';
              fsm <= T_RESULT;
            else
              cf_start <= '1';
              lf_start <= '1';
              got <= (others => '0');
              fsm <= T_CONF;
            end if;
          end if;

        when T_CONF =>                         -- the smoothed rho and contrast: lf_take, below
          if lf_take = '1' then
            got(1) <= '1';
          end if;
          if cf_done = '1' then
            got(0) <= '1';
          end if;
          if got(1) = '1' and got(2) = '0' then
            fl_start <= '1';
            got(2) <= '1';
          end if;
          if fl_done = '1' then
            got(3) <= '1';
          end if;
          if got(0) = '1' and got(3) = '1' then
            fsm <= T_DECIDE;
          end if;

        when T_DECIDE =>
          -- search state from the confidence
          if (lost_st = '1' and conf < CONF_REACQUIRE) or (lost_st = '0' and conf < CONF_LOST) then
            lost_now := '1';
            srch := ST_LOST;
          elsif lost_st = '1' then
            lost_now := '0';
            srch := ST_REACQ;
          elsif conf < CONF_UNCERTAIN then
            lost_now := '0';
            srch := ST_UNC;
          else
            lost_now := '0';
            srch := ST_OK;
          end if;
          -- reported status from the loss flag
          if lflag = '1' then
            if lost_now = '1' then stat := ST_LOST; else stat := ST_UNC; end if;
          else
            if reported_lost = '1' then stat := ST_REACQ; else stat := ST_OK; end if;
          end if;
          status_r <= stat;
          lost_st_frame <= lost_st;
          lost_st <= lost_now;
          if stat = ST_LOST or (stat = ST_UNC and reported_lost = '1') then
            reported_lost <= '1';
          else
            reported_lost <= '0';
          end if;
          c8x <= shift_left(r_cx, to_integer(l2d));
          c8y <= shift_left(r_cy, to_integer(l2d));
          if srch = ST_OK then
            ru_start <= '1';
          end if;
          if SCALE_GAIN > 0 and st_fin.nt /= 0 and ST_ON then
            -- the scale test (mstrack.fixed.tracker_v2 _scale_verdict): rho of the main run is the
            -- first candidate; the main run's tables, K and Q RAM are no longer needed this frame
            -- (rho, share, spread, ring share, confidence and loss flag are registered)
            st_sel <= '1';
            st_up <= '0';
            st_best <= rho;
            st_v <= "00";
            fsm <= T_ST_SIZE;
          elsif SCALE_GAIN > 0 and st_fin.nt /= 0 then
            sc_start <= '1';
            fsm <= T_SCALE;
          else
            t_res <= '1';
            fsm <= T_RESULT;
          end if;

        ------------------------------------------------------------ the gated scale test (ST_ON)
        when T_ST_SIZE =>                      -- ms_scale_test_size x 2; the final centre's window, region-relative
          if ST_ON then                        -- (no multiplier in the netlist without the test)
            if st_up = '1' then
              st_w8 <= st_w8_hi;
              st_h8 <= st_h8_hi;
            else
              st_w8 <= st_w8_lo;
              st_h8 <= st_h8_lo;
            end if;
            st_rx <= rg_round(r_cx) - rg_s(reg_x);
            st_ry <= rg_round(r_cy) - rg_s(reg_y);
          end if;
          fsm <= T_ST_WS;

        when T_ST_WS =>                        -- ms_window_size of the test sizes (ws_s8w, ws_s8h)
          ws_in_valid <= '1';
          fsm <= T_ST_WS_WAIT;

        when T_ST_WS_WAIT =>
          if ws_w_valid = '1' then
            wd <= ws_w;
            hd <= ws_h;
            ex_r <= ws_ex;
            ey_r <= ws_ey;
            -- the fit verdict registered here, so that T_ST_FIT decides on a flip-flop
            st_fit <= '1' when st_rx >= rg_s(resize(ws_ex, COORD_W)) and st_ry >= rg_s(resize(ws_ey, COORD_W))
                               and st_rx + rg_s(resize(ws_ex, COORD_W)) < rg_s(reg_w_c)
                               and st_ry + rg_s(resize(ws_ey, COORD_W)) < rg_s(reg_h_c) else '0';
            fsm <= T_ST_FIT;
          end if;

        when T_ST_FIT =>                       -- a window that leaves the captured region does not count
          if st_fit = '1' then                 -- (registered in T_ST_WS_WAIT)
            hi_x <= reg_w - 1 - resize(ex_r, REGION_W);
            hi_y <= reg_h - 1 - resize(ey_r, REGION_W);
            kt_start <= '1';
            k_acc <= (others => '0');
            fsm <= T_TABLES;                 -- -> T_QLOAD -> T_ST_RUN
          else
            fsm <= T_ST_NEXT;
          end if;

        when T_ST_RUN =>
          if c_done = '1' then
            r_s <= c_s;                        -- (the main run's S is no longer needed: rho is registered)
            fu_start <= '1';
            fsm <= T_ST_RHO;
          end if;

        when T_ST_RHO =>                       -- ms_scale_test: the largest rho, ties to the earlier window
          if fu_done = '1' then
            if fu_rho > st_best then
              st_best <= fu_rho;
              if st_up = '1' then st_v <= "01"; else st_v <= "11"; end if;
            end if;
            fsm <= T_ST_NEXT;
          end if;

        when T_ST_NEXT =>
          if st_up = '0' then
            st_up <= '1';
            fsm <= T_ST_SIZE;
          else
            fsm <= T_ST_GATE;
          end if;

        when T_ST_GATE =>                      -- ms_scale_gate: spread if the rho test moves the same way
          if (spread > spread_ref and st_v = "01") or (spread < spread_ref and st_v = "11") then
            sp_gate <= spread;
          else
            sp_gate <= spread_ref;
          end if;
          st_sel <= '0';
          sc_start <= '1';
          fsm <= T_SCALE;

        when T_SCALE =>
          if sc_done = '1' then
            rz_start <= '1';
            fsm <= T_RESIZE;
          end if;

        when T_RESIZE =>
          if rzw_done = '1' then
            w8 <= w8_n;
            h8 <= h8_n;
            t_res <= '1';
            fsm <= T_RESULT;
          end if;

        when T_RESULT =>                       -- the word and the init's references (t_res, below)
          fsm <= T_PUSH;

        when T_PUSH =>                         -- the word is out on res_data
          if res_ready = '1' then
            fsm <= T_PREP;
          end if;
      end case;

      -- T_LOAD: the record taken with load_take
      if rec_ld = '1' then
        target_valid  <= ld_st(0);
        lost_st       <= ld_st(1);
        reported_lost <= ld_st(2);
        c8x        <= unsigned(ld_st(TS_C8Y - 1 downto TS_C8X));
        c8y        <= unsigned(ld_st(TS_W8 - 1 downto TS_C8Y));
        w8         <= unsigned(ld_st(TS_H8 - 1 downto TS_W8));
        h8         <= unsigned(ld_st(TS_W0 - 1 downto TS_H8));
        w0_8       <= unsigned(ld_st(TS_FW - 1 downto TS_W0));
        tgt_w      <= unsigned(ld_st(TS_FH - 1 downto TS_FW));
        tgt_h      <= unsigned(ld_st(TS_RREF - 1 downto TS_FH));
        rho_ref    <= unsigned(ld_st(TS_SREF - 1 downto TS_RREF));
        share_ref  <= unsigned(ld_st(TS_RHO0 - 1 downto TS_SREF));
        rho0       <= unsigned(ld_st(TS_RHOS - 1 downto TS_RHO0));
        rho_s      <= signed(ld_st(TS_CONS - 1 downto TS_RHOS));
        con_s      <= signed(ld_st(TS_SPREF - 1 downto TS_CONS));
        spread_ref <= unsigned(ld_st(TS_W - 1 downto TS_SPREF));
      end if;
      -- T_CLIP: an accepted init box (only T_CLIP waits for ms_box_clip, so clip_ok needs no decode)
      if clip_ok = '1' then
        c8x <= bc_cx;
        c8y <= bc_cy;
        w8 <= shift_left(resize(bc_w, SIZE_W), 8);
        h8 <= shift_left(resize(bc_h, SIZE_W), 8);
        w0_8 <= shift_left(resize(bc_w, SIZE_W), 8);
        tgt_w <= in_fw;
        tgt_h <= in_fh;
        init_pending <= '1';
        init_clipped <= bc_clipped;
        target_valid <= '0';
        lost_st <= '0';
        reported_lost <= '0';
      end if;
      -- T_STATS: the spread and the ring share (only T_STATS0 starts ms_spread and ms_ring_share)
      if sp_done = '1' then
        spread <= sp_spread;
      end if;
      if rs_done = '1' then
        ring <= rs_ring;
      end if;
      -- T_CONF: the loss filters' smoothed rho and contrast (only T_CONF starts them)
      if lf_take = '1' then
        rho_s <= rho_s_n;
        con_s <= con_s_n;
      end if;
      -- T_RESULT: the word, and an init's references
      if t_res = '1' then
        if init_pending = '1' then
          rho_ref <= rho;
          share_ref <= share;
          rho0 <= rho;
          rho_s <= signed(resize(rho, CON_W));
          con_s <= con_x;
          if spread /= 0 then
            spread_ref <= spread;
          else
            spread_ref <= to_unsigned(SPREAD_DEFAULT, SPREAD_W);
          end if;
          target_valid <= '1';
          init_pending <= '0';
          if init_clipped = '1' then stat := ST_CLIP; else stat := ST_INIT; end if;
          res_word <= pack(c8x, c8y, w8, h8, rho, to_unsigned(ONE16, 17), stat, to_unsigned(0, ITER_W),
                           "00", l2d, to_unsigned(0, 4),
                           v2_flags(not init_clipped, init_clipped, '0', '0', word_rejected, '0', word_overflow),
                           "000", word_fcount);
        else
          if status_r = ST_LOST then lost_now := '1'; else lost_now := '0'; end if;
          if lost_st_frame = '1' then
            srch := "000"; srch4 := to_unsigned(8, 4);
          else
            srch4 := to_unsigned(0, 4);
          end if;
          res_word <= pack(c8x, c8y, w8, h8, rho, conf, status_r, r_iter, r_stop, l2d, srch4,
                           v2_flags('0', '0', lost_now, '0', word_rejected, '0', word_overflow),
                           "000", word_fcount);
        end if;
      end if;

      -- the references follow OK frames (ms_ref_update: one clock after ru_start)
      ru_d <= ru_start;
      if ru_d = '1' then
        rho_ref <= rr_rho;
        share_ref <= rr_share;
      end if;

      if rst = '1' then
        fsm <= T_PREP;
        target_valid <= '0';
        init_pending <= '0';
        w8 <= (others => '0');
        h8 <= (others => '0');
        tgt_w <= to_unsigned(3, COORD_W);
        tgt_h <= to_unsigned(3, COORD_W);
        c8x <= (others => '0');
        c8y <= (others => '0');
        lost_st <= '0';
        reported_lost <= '0';
        m_sel <= (others => '0');
        init_rejected <= '0';
        geo_done <= '0';
        t_res <= '0';
        clip_v <= '0';
        clip_ok <= '0';
        rec_ld <= '0';
        lf_take <= '0';
        run_ms <= '0';
        fin_best <= '0';
        ql_issue <= '0';
        st_sel <= '0';
      end if;
    end if;
  end process;

  idle      <= '1' when fsm = T_IDLE else '0';
  res_valid <= '1' when fsm = T_PUSH else '0';
  res_data  <= res_word;
  busy      <= c_busy;
  rec <= std_logic_vector(spread_ref) & std_logic_vector(con_s) & std_logic_vector(rho_s)
         & std_logic_vector(rho0) & std_logic_vector(share_ref) & std_logic_vector(rho_ref)
         & std_logic_vector(tgt_h) & std_logic_vector(tgt_w) & std_logic_vector(w0_8)
         & std_logic_vector(h8) & std_logic_vector(w8) & std_logic_vector(c8y) & std_logic_vector(c8x)
         & reported_lost & lost_st & target_valid;
  rec_valid <= target_valid;
  rec_init  <= init_pending;
  rec_c8x   <= c8x;
  rec_c8y   <= c8y;
  rec_w8    <= w8;
  rec_h8    <= h8;
  rec_fw    <= tgt_w;
  rec_fh    <= tgt_h;
  geo_l2d   <= l2d;
  geo_reg_x <= reg_x;
  geo_reg_y <= reg_y;
  geo_reg_w <= reg_w_c;
  geo_reg_h <= reg_h_c;
  geo_wb    <= wb;
  geo_hb    <= hb;
  geo_bg_cx <= bg_cx;
  geo_bg_cy <= bg_cy;
  geo_rect_x <= rect_x;
  geo_rect_y <= rect_y;
  geo_rect_w <= rect_w;
  geo_rect_h <= rect_h;
  geo_wd <= wd;
  geo_hd <= hd;
  geo_last_x <= last_x;
  geo_last_y <= last_y;

  -- T table of ms_target_stats: written with the Qw load (T of the bin read the clock before)
  t_we   <= ql_v1;
  t_addr <= ql_bin1;
  t_data <= m_t;
end architecture;
