-- Test wrapper: the shared-engine multi-target core's datapath, its sequencer played by the bench
-- (tb/test_ms_engine_pool.py): ms_frontend -> ms_slot_pool (N_SLOTS slots: colour RAMs from the
-- all-pixel stream, orientation RAMs from the interior stream) -> one read port, shared by ms_init_job
-- (while it is busy) and ms_engine with SLOT_INIT (one model per target).  The bench loads each slot's
-- capture with the engine's geometry, streams the frame, then runs every target's job from its slot
-- (rd_slot).  The pool's read port has RD_LAT + 2 clocks of latency: the init job's RD_LAT; the
-- engine reads its ram_addr_next, a clock early, and sees RAM_LAT = RD_LAT + 1.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_engine_pool_tb_top is
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
    -- the slots: the pool's RAMs' read latency (its read port has one more: the multiplexer)
    N_SLOTS         : positive := 2;
    RD_LAT          : positive := 3;
    REGION_MAX      : natural := 256;
    EDGE_BINS_LOG2  : natural := 4;       -- (front end)
    EDGE_SHIFT      : natural := 5
  );
  port (
    clk           : in  std_logic;
    rst           : in  std_logic;
    frame_width   : in  unsigned(COORD_W - 1 downto 0);             -- video in (ms_frontend)
    frame_height  : in  unsigned(COORD_W - 1 downto 0);
    in_valid      : in  std_logic;
    in_data       : in  std_logic_vector(23 downto 0);
    in_sof        : in  std_logic;
    in_eol        : in  std_logic;
    frame_start   : out std_logic;                                  -- its frame events
    frame_error   : out std_logic;
    ad_end        : out std_logic;
    cap_load      : in  std_logic;                                  -- ms_slot_pool's descriptor bus
    cap_slot      : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);
    cap_now       : in  std_logic;
    cap_l2d       : in  unsigned(2 downto 0);
    cap_x0, cap_y0, cap_x1, cap_y1 : in unsigned(COORD_W - 1 downto 0);
    released      : out std_logic_vector(N_SLOTS - 1 downto 0);
    late          : out std_logic_vector(N_SLOTS - 1 downto 0);
    rd_slot       : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);  -- the slot the jobs read
    ij_start      : in  std_logic;                                  -- ms_init_job on the engine's init geometry
    ij_busy       : out std_logic;
    ij_done       : out std_logic;
    idle          : out std_logic;                                  -- ms_engine
    geo_done      : out std_logic;
    go            : in  std_logic;
    rearm         : in  std_logic;
    init_take     : in  std_logic;
    init_x        : in  signed(COORD_W + 1 downto 0);
    init_y        : in  signed(COORD_W + 1 downto 0);
    init_w        : in  unsigned(COORD_W downto 0);
    init_h        : in  unsigned(COORD_W downto 0);
    init_fw       : in  unsigned(COORD_W - 1 downto 0);
    init_fh       : in  unsigned(COORD_W - 1 downto 0);
    init_rejected : out std_logic;
    load_take     : in  std_logic;
    load_state    : in  std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                    SPREAD_W) - 1 downto 0);
    load_model    : in  unsigned(clog2(MODELS) - 1 downto 0);
    rec           : out std_logic_vector(v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W,
                                                    SPREAD_W) - 1 downto 0);
    rec_init      : out std_logic;
    geo_l2d       : out unsigned(2 downto 0);
    geo_reg_x     : out unsigned(COORD_W - 1 downto 0);
    geo_reg_y     : out unsigned(COORD_W - 1 downto 0);
    geo_reg_w     : out unsigned(COORD_W - 1 downto 0);
    geo_reg_h     : out unsigned(COORD_W - 1 downto 0);
    geo_bg_cx     : out unsigned(COORD_W - 1 downto 0);
    geo_bg_cy     : out unsigned(COORD_W - 1 downto 0);
    geo_wd        : out unsigned(WIN_W - 1 downto 0);
    geo_hd        : out unsigned(WIN_W - 1 downto 0);
    geo_rect_x    : out unsigned(COORD_W - 1 downto 0);
    geo_rect_y    : out unsigned(COORD_W - 1 downto 0);
    geo_rect_w    : out unsigned(COORD_W - 1 downto 0);
    geo_rect_h    : out unsigned(COORD_W - 1 downto 0);
    res_valid     : out std_logic;
    res_ready     : in  std_logic;
    res_data      : out std_logic_vector(RESULT_W - 1 downto 0);
    word_fcount   : in  unsigned(15 downto 0)
  );
end entity;

architecture rtl of ms_engine_pool_tb_top is
  constant BIN_W  : natural := 3 * COLOUR_BITS;
  constant OR_ON  : boolean := ORIENT_T >= 0;
  constant N_OR   : natural := 8 * boolean'pos(OR_ON) + 1;
  constant DATA_W : natural := BIN_W + 4 * boolean'pos(OR_ON);
  -- the slot pool's read latency is RD_LAT + 2 (address copy, RAMs, multiplexer): the init job's; the
  -- engine gives its address a clock early (ram_addr_next) and sees RAM_LAT = RD_LAT + 1
  constant POOL_LAT : positive := RD_LAT + 2;
  constant RAM_LAT : positive := RD_LAT + 1;
  signal raddr, e_raddr, e_raddr_next, j_raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal rdata    : std_logic_vector(LANES * DATA_W - 1 downto 0);
  signal e_cbin   : std_logic_vector(LANES * BIN_W - 1 downto 0);
  signal e_obin   : std_logic_vector(LANES * 4 - 1 downto 0);
  signal j_busy   : std_logic;
  signal m_sel    : unsigned(clog2(MODELS) - 1 downto 0);
  signal m_rd_addr : unsigned(BIN_W - 1 downto 0);
  signal m_qn     : unsigned(16 downto 0);
  signal m_t      : std_logic;
  signal m_qn_all : std_logic_vector(N_OR * 17 - 1 downto 0);
  signal m_t_all  : std_logic_vector(N_OR - 1 downto 0);
  signal wb, hb, bg_cx, bg_cy, rect_x, rect_y, rect_w, rect_h, last_x, last_y : unsigned(COORD_W - 1 downto 0);
  signal fs, ferr, aend, ip_valid, ad_valid : std_logic;
  signal ip_x, ip_y, ad_x, ad_y : unsigned(COORD_W - 1 downto 0);
  signal ip_obin  : std_logic_vector(3 downto 0);
  signal ad_cbin  : std_logic_vector(BIN_W - 1 downto 0);
begin
  frame_start <= fs;
  frame_error <= ferr;
  ad_end <= aend;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, ORIENT_T => maximum(ORIENT_T, 0))
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => in_valid, in_data => in_data, in_sof => in_sof, in_eol => in_eol,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              frame_start => fs, frame_error => ferr,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => aend);

  u_pool : entity work.ms_slot_pool
    generic map (N_SLOTS => N_SLOTS, LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, COLOUR_W => BIN_W, ORIENT => OR_ON,
                 LOG2_D_MAX => 4, RD_LAT => RD_LAT, WR_LAT => 1)
    port map (clk => clk, rst => rst, frame_start => fs, frame_error => ferr,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => aend,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              load => cap_load, load_slot => cap_slot, load_now => cap_now, dec_log2 => cap_l2d,
              fx0 => cap_x0, fy0 => cap_y0, fx1 => cap_x1, fy1 => cap_y1, armed => open, pending => open,
              released => released, late => late, rd_slot => rd_slot, raddr => raddr, rdata => e_cbin,
              robin => e_obin);
  -- the init job and the engine never read in the same clocks: the engine's passes start after the
  -- init job's done, and the job's reads end before it
  raddr <= j_raddr when j_busy = '1' else e_raddr_next;
  -- ms_init_job takes a pixel as {orientation, colour bin} per lane
  g_lane : for b in 0 to LANES - 1 generate
    rdata(b * DATA_W + BIN_W - 1 downto b * DATA_W) <= e_cbin((b + 1) * BIN_W - 1 downto b * BIN_W);
    g_or : if OR_ON generate
      rdata(b * DATA_W + BIN_W + 3 downto b * DATA_W + BIN_W) <= e_obin(b * 4 + 3 downto b * 4);
    end generate;
  end generate;

  u_job : entity work.ms_init_job
    generic map (LANES => LANES, STRIDE => STRIDE, ADDR_W => ADDR_W, REGION_W => REGION_W, COORD_W => COORD_W,
                 RD_LAT => POOL_LAT,
                 BIN_W => BIN_W, N_ORIENT => N_OR, HALF_W => HALF_W, RING_W => 5, Q_W => BG_Q_W,
                 O_W => BG_O_W, KD_W => KD_W, MODELS => MODELS)
    port map (clk => clk, rst => rst, start => ij_start, rect_w => resize(rect_w, REGION_W),
              rect_h => resize(rect_h, REGION_W), cx => resize(bg_cx - rect_x, REGION_W),
              cy => resize(bg_cy - rect_y, REGION_W), wb => resize(wb, HALF_W + 1), hb => resize(hb, HALF_W + 1),
              ring16 => to_unsigned(RING16, 5), model => m_sel, org_x => rect_x, org_y => rect_y,
              last_x => last_x, last_y => last_y, busy => j_busy, done => ij_done,
              raddr => j_raddr, rdata => rdata, m_rd_addr => m_rd_addr, m_rd_obin => (others => '0'),
              m_rd_sel => m_sel, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all, m_t_all => m_t_all);
  ij_busy <= j_busy;

  u_eng : entity work.ms_engine
    generic map (
                 MAX_FRAME_W => MAX_FRAME_W, LANES => LANES, COLOUR_BITS => COLOUR_BITS, KERNEL_BITS
                 => KERNEL_BITS, MAX_HALF => MAX_HALF, MARGIN => MARGIN, COORD_W => COORD_W, CF =>
                 CF, WI => WI, WF => WF, RF => RF, AF => AF, RHO_OUT_FRAC => RHO_OUT_FRAC, MAX_ITER
                 => MAX_ITER, EPS2 => EPS2, HALF_W => HALF_W, REGION_W => REGION_W, STRIDE =>
                 STRIDE, ADDR_W => ADDR_W, KVAL_W => KVAL_W, HIST_W => HIST_W, COUNT_W => COUNT_W,
                 POSSUM_W => POSSUM_W, KD_W => KD_W, SQRT_IN_W => SQRT_IN_W, RHO_SUM_W => RHO_SUM_W,
                 RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, SW_W => SW_W, SWX_W => SWX_W,
                 SHIFT_Q_W => SHIFT_Q_W, CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, ITER_W
                 => ITER_W, RHO_OUT_W => RHO_OUT_W, ALPHA_W => ALPHA_W, WIN_W => WIN_W, RESULT_W =>
                 RESULT_W, PAD16 => PAD16, RING16 => RING16, MAX_WINDOW => MAX_WINDOW, KT_W => KT_W,
                 ST2_W => ST2_W, SHARE_W => SHARE_W, SPREAD_W => SPREAD_W, SIZE_W => SIZE_W, SCALE_W
                 => SCALE_W, SCALE_GAIN => SCALE_GAIN, SCALE_REG => SCALE_REG, SCALE_STEP =>
                 SCALE_STEP, SCALE_RATIO_Q_W => SCALE_RATIO_Q_W, WR_Q_W => WR_Q_W, CON_W => CON_W,
                 LOSS_K => LOSS_K, REF_K => REF_K, LOSS_RHO => LOSS_RHO, LOSS_CONTRAST =>
                 LOSS_CONTRAST, CONF_LOST => CONF_LOST, CONF_UNCERTAIN => CONF_UNCERTAIN,
                 CONF_REACQUIRE => CONF_REACQUIRE, SPREAD_DEFAULT => SPREAD_DEFAULT, BG_Q_W =>
                 BG_Q_W, BG_O_W => BG_O_W, SEARCH_ITER => SEARCH_ITER, STEP16 => STEP16, MARGIN_MAX
                 => MARGIN_MAX, SCALE_TEST_D256 => SCALE_TEST_D256, ORIENT_T => ORIENT_T, MODELS =>
                 MODELS, RAM_LAT => RAM_LAT,
                 SLOT_INIT => true)
    port map (clk => clk, rst => rst, idle => idle, geo_done => geo_done, go => go, rearm => rearm,
              init_take => init_take, init_x => init_x, init_y => init_y, init_w => init_w, init_h => init_h,
              init_fw => init_fw, init_fh => init_fh, init_rejected => init_rejected,
              load_take => load_take, load_state => load_state, load_model => load_model,
              rec => rec, rec_valid => open, rec_init => rec_init, rec_c8x => open, rec_c8y => open,
              rec_w8 => open, rec_h8 => open, rec_fw => open, rec_fh => open,
              geo_l2d => geo_l2d, geo_reg_x => geo_reg_x, geo_reg_y => geo_reg_y, geo_reg_w => geo_reg_w,
              geo_reg_h => geo_reg_h, geo_wb => wb, geo_hb => hb, geo_bg_cx => bg_cx, geo_bg_cy => bg_cy,
              geo_rect_x => rect_x, geo_rect_y => rect_y, geo_rect_w => rect_w, geo_rect_h => rect_h,
              geo_last_x => last_x, geo_last_y => last_y, geo_wd => geo_wd, geo_hd => geo_hd,
              m_sel => m_sel, m_rd_addr => m_rd_addr, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all,
              m_t_all => m_t_all, ram_addr => e_raddr, ram_addr_next => e_raddr_next, ram_data => e_cbin, ram_obin => e_obin,
              res_valid => res_valid, res_ready => res_ready, res_data => res_data,
              word_fcount => word_fcount, word_rejected => '0', word_overflow => '0', busy => open);
  geo_bg_cx <= bg_cx;
  geo_bg_cy <= bg_cy;
  geo_rect_x <= rect_x;
  geo_rect_y <= rect_y;
  geo_rect_w <= rect_w;
  geo_rect_h <= rect_h;
end architecture;
