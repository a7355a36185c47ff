-- ms_tracker_multi_pins: a multi-target core with few pins, for place-and-route (Fmax) runs only:
-- ms_tracker_multi, or with SHARED_ENGINE ms_tracker_shared (the two cores have the same ports).
--
-- Computes nothing of its own, as rtl/wrappers/ms_tracker_pins.vhd for the single-target core: the video
-- stream ports stay as they are; frame_width, frame_height and the command come from a serial
-- configuration chain (cfg_shift / cfg_din, 6 x (COORD_W + 2) + 5 register bits, LSB first:
-- frame_width, frame_height, box x, y, w, h, op, id), a command is given with cmd_valid / cmd_ready;
-- its outcome (cmd_done, cmd_code, cmd_id), the live slots and busy are pins; each result word
-- (RESULT_W + 4 bits: result word v2 and the id) is shifted out one bit per clock, LSB first, on
-- res_dout while res_valid is high, with its tlast on res_last.  Every result bit stays observable, so
-- synthesis removes nothing of the core.
-- Latency / throughput / handshake: those of the core, plus RESULT_W + 4 clocks to shift a
-- result word out (the core's word is taken when the shifter is empty; the core holds the next ones).
-- Generics: exactly those of ms_tracker_multi, then SHARED_ENGINE and ms_tracker_shared's own (RD_LAT ..
-- C_SCALE), passed through (the same names and defaults).
-- Flow: mstrack/hw/synth.py (configurations multi<N>-colour, shared<N>-colour), docs/performance.md.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_tracker_multi_pins is
  generic (
    MAX_TARGETS    : positive range 1 to 16 := 2;   -- target slots
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
    SHARED_ENGINE   : boolean := false;   -- false ms_tracker_multi (an engine per slot), true ms_tracker_shared
    -- SHARED_ENGINE only (ms_tracker_shared's own generics):
    -- the slots (ms_slot_pool): RAM read latency (the pool's read port adds its multiplexer)
    RD_LAT          : positive := 3;
    -- the capacity rule (mstrack.fixed.multi_capacity.MultiCoreConfig: VideoTiming and PassCosts)
    FRAME_LINES     : natural := 1125;    -- lines per frame, blanking included
    ACTIVE_LINES    : natural := 1080;
    LINE_CLOCKS     : natural := 2200;    -- clocks per line
    LC_W            : positive := 13;     -- bits of LINE_CLOCKS
    SUM_W           : positive := 28;     -- sums of clocks, slacks
    CLK_W           : natural := 24;      -- a job's clocks
    PLAN_REGION_W   : natural := 10;      -- ms_job_demand's region widths (mstrack.hw.multi_core.job_demand_generics)
    GROW_Q16        : natural := 6554;
    PASS_LAT        : natural := 10;
    M_TRACK         : natural := 21;
    C_TRACK         : natural := 13170;
    M_LOST          : natural := 54;
    C_LOST          : natural := 32375;
    C_INIT          : natural := 3534;
    SCALE_PERMILLE  : natural := 50;
    C_SCALE         : natural := 2862
  );
  port (
    clk           : in  std_logic;                      -- core clock
    rst           : in  std_logic;                      -- synchronous reset
    cfg_shift     : in  std_logic;                      -- shift the configuration chain
    cfg_din       : in  std_logic;                      -- configuration bit in
    cmd_valid     : in  std_logic;                      -- command (from the chain) valid
    cmd_ready     : out std_logic;                      -- command taken
    cmd_done      : out std_logic;                      -- an outcome (as the core)
    cmd_code      : out std_logic_vector(1 downto 0);
    cmd_id        : out std_logic_vector(3 downto 0);
    s_axis_tdata  : in  std_logic_vector(23 downto 0);  -- video in (as the core)
    s_axis_tvalid : in  std_logic;
    s_axis_tready : out std_logic;
    s_axis_tlast  : in  std_logic;
    s_axis_tuser  : in  std_logic;
    res_valid     : out std_logic;                      -- result word being shifted out
    res_dout      : out std_logic;                      -- result bit, LSB first
    res_last      : out std_logic;                      -- the word's tlast (the frame's last word)
    live          : out std_logic_vector(MAX_TARGETS - 1 downto 0);  -- slots holding a target
    busy          : out std_logic                       -- an engine's mean shift is running
  );
end entity;

architecture rtl of ms_tracker_multi_pins is
  constant F_W   : natural := COORD_W + 2;
  constant CFG_W : natural := 6 * F_W + 5;
  constant WORD_W : natural := RESULT_W + 4;
  signal cfg      : std_logic_vector(CFG_W - 1 downto 0) := (others => '0');
  signal r_data   : std_logic_vector(WORD_W - 1 downto 0);
  signal r_valid, r_ready, r_last : std_logic;
  signal sh       : std_logic_vector(WORD_W - 1 downto 0) := (others => '0');
  signal sh_last  : std_logic := '0';
  signal sh_cnt   : natural range 0 to WORD_W := 0;
  signal code     : unsigned(1 downto 0);
  signal id       : unsigned(3 downto 0);

  function fld(v : std_logic_vector; i, w : natural) return std_logic_vector is
  begin
    return v(i * F_W + w - 1 downto i * F_W);
  end function;
begin
  p_cfg : process(clk)
  begin
    if rising_edge(clk) then
      if cfg_shift = '1' then
        cfg <= cfg_din & cfg(CFG_W - 1 downto 1);
      end if;
    end if;
  end process;

  g_multi : if not SHARED_ENGINE generate
    u_core : entity work.ms_tracker_multi
      generic map (
        MAX_TARGETS     => MAX_TARGETS,
        MAX_FRAME_W     => MAX_FRAME_W,
        RGB_PACKING     => RGB_PACKING,
        LANES           => LANES,
        COLOUR_BITS     => COLOUR_BITS,
        EDGE_BINS_LOG2  => EDGE_BINS_LOG2,
        EDGE_SHIFT      => EDGE_SHIFT,
        FEATURES        => FEATURES,
        KERNEL_EPAN     => KERNEL_EPAN,
        KERNEL_BITS     => KERNEL_BITS,
        MAX_HALF        => MAX_HALF,
        MARGIN          => MARGIN,
        COORD_W         => COORD_W,
        CF              => CF,
        WI              => WI,
        WF              => WF,
        RF              => RF,
        AF              => AF,
        RHO_OUT_FRAC    => RHO_OUT_FRAC,
        MAX_ITER        => MAX_ITER,
        EPS2            => EPS2,
        HALF_W          => HALF_W,
        REGION_MAX      => REGION_MAX,
        REGION_W        => REGION_W,
        STRIDE          => STRIDE,
        ADDR_W          => ADDR_W,
        KVAL_W          => KVAL_W,
        HIST_W          => HIST_W,
        COUNT_W         => COUNT_W,
        POSSUM_W        => POSSUM_W,
        KD_W            => KD_W,
        SQRT_IN_W       => SQRT_IN_W,
        RHO_SUM_W       => RHO_SUM_W,
        RATIO_Q_W       => RATIO_Q_W,
        WEIGHT_W        => WEIGHT_W,
        SW_W            => SW_W,
        SWX_W           => SWX_W,
        SHIFT_Q_W       => SHIFT_Q_W,
        CENTRE_W        => CENTRE_W,
        CENTRE_ABS_W    => CENTRE_ABS_W,
        ITER_W          => ITER_W,
        RHO_OUT_W       => RHO_OUT_W,
        ALPHA_W         => ALPHA_W,
        WIN_W           => WIN_W,
        RESULT_W        => RESULT_W,
        PAD16           => PAD16,
        RING16          => RING16,
        MAX_WINDOW      => MAX_WINDOW,
        KT_W            => KT_W,
        ST2_W           => ST2_W,
        SHARE_W         => SHARE_W,
        SPREAD_W        => SPREAD_W,
        SIZE_W          => SIZE_W,
        SCALE_W         => SCALE_W,
        SCALE_GAIN      => SCALE_GAIN,
        SCALE_REG       => SCALE_REG,
        SCALE_STEP      => SCALE_STEP,
        SCALE_RATIO_Q_W => SCALE_RATIO_Q_W,
        WR_Q_W          => WR_Q_W,
        CON_W           => CON_W,
        LOSS_K          => LOSS_K,
        REF_K           => REF_K,
        LOSS_RHO        => LOSS_RHO,
        LOSS_CONTRAST   => LOSS_CONTRAST,
        CONF_LOST       => CONF_LOST,
        CONF_UNCERTAIN  => CONF_UNCERTAIN,
        CONF_REACQUIRE  => CONF_REACQUIRE,
        SPREAD_DEFAULT  => SPREAD_DEFAULT,
        BG_Q_W          => BG_Q_W,
        BG_O_W          => BG_O_W,
        SEARCH_ITER     => SEARCH_ITER,
        STEP16          => STEP16,
        MARGIN_MAX      => MARGIN_MAX,
        SCALE_TEST_D256 => SCALE_TEST_D256,
        ORIENT_T        => ORIENT_T
      )
      port map (
        clk => clk, rst => rst,
        frame_width  => unsigned(fld(cfg, 0, COORD_W)),
        frame_height => unsigned(fld(cfg, 1, COORD_W)),
        s_cmd_tvalid => cmd_valid, s_cmd_tready => cmd_ready,
        s_cmd_op => cfg(6 * F_W), s_cmd_id => unsigned(cfg(6 * F_W + 4 downto 6 * F_W + 1)),
        s_cmd_x => signed(fld(cfg, 2, COORD_W + 2)), s_cmd_y => signed(fld(cfg, 3, COORD_W + 2)),
        s_cmd_w => unsigned(fld(cfg, 4, COORD_W + 1)), s_cmd_h => unsigned(fld(cfg, 5, COORD_W + 1)),
        cmd_done => cmd_done, cmd_code => code, cmd_id => id,
        s_axis_tdata => s_axis_tdata, s_axis_tvalid => s_axis_tvalid, s_axis_tready => s_axis_tready,
        s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
        m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
        m_axis_result_tready => r_ready, m_axis_result_tlast => r_last,
        live => live, busy => busy);
  end generate;
  g_shared : if SHARED_ENGINE generate
    u_core : entity work.ms_tracker_shared
      generic map (
        MAX_TARGETS     => MAX_TARGETS,
        MAX_FRAME_W     => MAX_FRAME_W,
        RGB_PACKING     => RGB_PACKING,
        LANES           => LANES,
        COLOUR_BITS     => COLOUR_BITS,
        EDGE_BINS_LOG2  => EDGE_BINS_LOG2,
        EDGE_SHIFT      => EDGE_SHIFT,
        FEATURES        => FEATURES,
        KERNEL_EPAN     => KERNEL_EPAN,
        KERNEL_BITS     => KERNEL_BITS,
        MAX_HALF        => MAX_HALF,
        MARGIN          => MARGIN,
        COORD_W         => COORD_W,
        CF              => CF,
        WI              => WI,
        WF              => WF,
        RF              => RF,
        AF              => AF,
        RHO_OUT_FRAC    => RHO_OUT_FRAC,
        MAX_ITER        => MAX_ITER,
        EPS2            => EPS2,
        HALF_W          => HALF_W,
        REGION_MAX      => REGION_MAX,
        REGION_W        => REGION_W,
        STRIDE          => STRIDE,
        ADDR_W          => ADDR_W,
        KVAL_W          => KVAL_W,
        HIST_W          => HIST_W,
        COUNT_W         => COUNT_W,
        POSSUM_W        => POSSUM_W,
        KD_W            => KD_W,
        SQRT_IN_W       => SQRT_IN_W,
        RHO_SUM_W       => RHO_SUM_W,
        RATIO_Q_W       => RATIO_Q_W,
        WEIGHT_W        => WEIGHT_W,
        SW_W            => SW_W,
        SWX_W           => SWX_W,
        SHIFT_Q_W       => SHIFT_Q_W,
        CENTRE_W        => CENTRE_W,
        CENTRE_ABS_W    => CENTRE_ABS_W,
        ITER_W          => ITER_W,
        RHO_OUT_W       => RHO_OUT_W,
        ALPHA_W         => ALPHA_W,
        WIN_W           => WIN_W,
        RESULT_W        => RESULT_W,
        PAD16           => PAD16,
        RING16          => RING16,
        MAX_WINDOW      => MAX_WINDOW,
        KT_W            => KT_W,
        ST2_W           => ST2_W,
        SHARE_W         => SHARE_W,
        SPREAD_W        => SPREAD_W,
        SIZE_W          => SIZE_W,
        SCALE_W         => SCALE_W,
        SCALE_GAIN      => SCALE_GAIN,
        SCALE_REG       => SCALE_REG,
        SCALE_STEP      => SCALE_STEP,
        SCALE_RATIO_Q_W => SCALE_RATIO_Q_W,
        WR_Q_W          => WR_Q_W,
        CON_W           => CON_W,
        LOSS_K          => LOSS_K,
        REF_K           => REF_K,
        LOSS_RHO        => LOSS_RHO,
        LOSS_CONTRAST   => LOSS_CONTRAST,
        CONF_LOST       => CONF_LOST,
        CONF_UNCERTAIN  => CONF_UNCERTAIN,
        CONF_REACQUIRE  => CONF_REACQUIRE,
        SPREAD_DEFAULT  => SPREAD_DEFAULT,
        BG_Q_W          => BG_Q_W,
        BG_O_W          => BG_O_W,
        SEARCH_ITER     => SEARCH_ITER,
        STEP16          => STEP16,
        MARGIN_MAX      => MARGIN_MAX,
        SCALE_TEST_D256 => SCALE_TEST_D256,
        ORIENT_T        => ORIENT_T,
        RD_LAT          => RD_LAT,
        FRAME_LINES     => FRAME_LINES,
        ACTIVE_LINES    => ACTIVE_LINES,
        LINE_CLOCKS     => LINE_CLOCKS,
        LC_W            => LC_W,
        SUM_W           => SUM_W,
        CLK_W           => CLK_W,
        PLAN_REGION_W   => PLAN_REGION_W,
        GROW_Q16        => GROW_Q16,
        PASS_LAT        => PASS_LAT,
        M_TRACK         => M_TRACK,
        C_TRACK         => C_TRACK,
        M_LOST          => M_LOST,
        C_LOST          => C_LOST,
        C_INIT          => C_INIT,
        SCALE_PERMILLE  => SCALE_PERMILLE,
        C_SCALE         => C_SCALE
      )
      port map (
        clk => clk, rst => rst,
        frame_width  => unsigned(fld(cfg, 0, COORD_W)),
        frame_height => unsigned(fld(cfg, 1, COORD_W)),
        s_cmd_tvalid => cmd_valid, s_cmd_tready => cmd_ready,
        s_cmd_op => cfg(6 * F_W), s_cmd_id => unsigned(cfg(6 * F_W + 4 downto 6 * F_W + 1)),
        s_cmd_x => signed(fld(cfg, 2, COORD_W + 2)), s_cmd_y => signed(fld(cfg, 3, COORD_W + 2)),
        s_cmd_w => unsigned(fld(cfg, 4, COORD_W + 1)), s_cmd_h => unsigned(fld(cfg, 5, COORD_W + 1)),
        cmd_done => cmd_done, cmd_code => code, cmd_id => id,
        s_axis_tdata => s_axis_tdata, s_axis_tvalid => s_axis_tvalid, s_axis_tready => s_axis_tready,
        s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
        m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
        m_axis_result_tready => r_ready, m_axis_result_tlast => r_last,
        live => live, busy => busy);
  end generate;
  cmd_code <= std_logic_vector(code);
  cmd_id <= std_logic_vector(id);

  r_ready <= '1' when sh_cnt = 0 else '0';

  p_ser : process(clk)
  begin
    if rising_edge(clk) then
      if sh_cnt = 0 then
        if r_valid = '1' then
          sh <= r_data;
          sh_last <= r_last;
          sh_cnt <= WORD_W;
        end if;
      else
        sh <= '0' & sh(WORD_W - 1 downto 1);
        sh_cnt <= sh_cnt - 1;
      end if;
      if rst = '1' then
        sh_cnt <= 0;
      end if;
    end if;
  end process;
  res_dout <= sh(0);
  res_last <= sh_last;
  res_valid <= '1' when sh_cnt /= 0 else '0';
end architecture;
