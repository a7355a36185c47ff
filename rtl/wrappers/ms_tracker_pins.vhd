-- ms_tracker_pins: ms_tracker (either preset) with few pins, for place-and-route (Fmax) runs only.
--
-- Computes nothing of its own: the core's ~260 ports are more than the LFE5U-85F CABGA381 has user
-- I/Os, so the video stream ports stay as they are, frame_width, frame_height and the init box come
-- from a serial configuration chain (cfg_shift / cfg_din, 6 x (COORD_W + 2) register bits, LSB
-- first: frame_width, frame_height, init x, y, w, h) and each result word (RESULT_W bits: 144 for
-- PRESET 0, 160 for PRESET 1) is shifted out one bit per clock, LSB first, on res_dout while
-- res_valid is high.  Every result bit stays observable, so synthesis removes nothing of the core.
-- Latency / throughput / handshake: those of ms_tracker, plus RESULT_W clocks to shift a result word
-- out (the core's result is taken when the shifter is empty; its result FIFO holds the next ones).
-- Cost over the core and the flow that places it: docs/performance.md, mstrack/hw/synth.py.
-- Generics: exactly those of ms_tracker, passed through (the same names and defaults).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_formats_pkg.all;

entity ms_tracker_pins is
  generic (
    PRESET         : natural := 0;               -- 0 the paper core, 1 core v2 (ms_tracker_v2)
    MAX_FRAME_W    : natural := 2048;            -- widest frame (line buffer depth); 3 .. 2**COORD_W - 1
    RGB_PACKING    : natural := 0;               -- s_axis_tdata layout: 0 R 23:16 G 15:8 B 7:0; 1 AMD UG934 (R B G)
    PPC            : natural := 1;               -- pixels per clock (s_axis beat): 1, 2 or 4 (<= LANES)
    LANES          : natural := D_LANES;         -- pixels per clock of a pixel pass
    COLOUR_BITS    : natural := D_COLOUR_BITS;   -- bits per channel of the colour bin
    EDGE_BINS_LOG2 : natural := D_EDGE_BINS_LOG2;-- log2 edge bins
    EDGE_SHIFT     : natural := D_EDGE_SHIFT;    -- edge bin = min(E-1, |G| >> EDGE_SHIFT)
    FEATURES       : natural := D_FEATURES;      -- 0 fused, 1 colour only, 2 edge only
    KERNEL_EPAN    : natural := D_KERNEL_EPAN;   -- 0 flat, 1 Epanechnikov
    KERNEL_BITS    : natural := D_KERNEL_BITS;   -- Epanechnikov kernel bits
    MAX_HALF       : natural := D_MAX_HALF;      -- largest window half extent
    MARGIN         : natural := D_MARGIN;        -- search margin (px)
    COORD_W        : natural := D_COORD_W;       -- frame coordinate bits
    CF             : natural := D_CF;            -- centre fraction bits
    WI             : natural := D_WI;            -- weight integer bits
    WF             : natural := D_WF;            -- weight fraction bits
    RF             : natural := D_RF;            -- Bhattacharyya term fraction bits
    AF             : natural := D_AF;            -- alpha fraction bits
    RHO_OUT_FRAC   : natural := D_RHO_OUT_FRAC;  -- reported rho fraction bits
    MAX_ITER       : natural := D_MAX_ITER;      -- iteration limit per feature
    EPS2           : natural := D_EPS2;          -- shift stop threshold (Q.2CF px^2)
    HALF_W         : natural := D_HALF_W;        -- derived widths: see mstrack.fixed.vhdl_pkg
    REGION_MAX     : natural := D_REGION_MAX;
    REGION_W       : natural := D_REGION_W;
    STRIDE         : natural := D_STRIDE;
    ADDR_W         : natural := D_ADDR_W;
    KVAL_W         : natural := D_KVAL_W;
    HIST_W         : natural := D_HIST_W;
    COUNT_W        : natural := D_COUNT_W;
    POSSUM_W       : natural := D_POSSUM_W;
    KD_W           : natural := D_KD_W;
    SQRT_IN_W      : natural := D_SQRT_IN_W;
    RHO_SUM_W      : natural := D_RHO_SUM_W;
    RATIO_Q_W      : natural := D_RATIO_Q_W;
    WEIGHT_W       : natural := D_WEIGHT_W;
    SW_W           : natural := D_SW_W;
    SWX_W          : natural := D_SWX_W;
    SHIFT_Q_W      : natural := D_SHIFT_Q_W;
    CENTRE_W       : natural := D_CENTRE_W;
    CENTRE_ABS_W   : natural := D_CENTRE_ABS_W;
    ITER_W         : natural := D_ITER_W;
    RHO_OUT_W      : natural := D_RHO_OUT_W;
    ALPHA_W        : natural := D_ALPHA_W;
    WIN_W          : natural := D_WIN_W;
    RESULT_W       : natural := D_RESULT_W;       -- PRESET 0: 144 (result word), 1: 160 (result word v2)
    -- core v2 only (PRESET 1; ms_tracker_v2's defaults; mstrack.hw.cosim.CoreConfigV2.generics)
    PAD16          : natural := 4;               -- pad in 1/16
    RING16         : natural := 10;              -- bg_ring in 1/16
    MAX_WINDOW     : natural := 127;             -- largest window diameter (decimated px)
    KT_W           : natural := 9;               -- KA/KB width (KERNEL_BITS + 1)
    ST2_W          : natural := 23;
    SHARE_W        : natural := 17;
    SPREAD_W       : natural := 25;
    SIZE_W         : natural := 20;              -- w8, h8 bits (COORD_W + 8)
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
    CONF_LOST      : natural := 26214;           -- round(conf_lost 2**16)
    CONF_UNCERTAIN : natural := 32768;
    CONF_REACQUIRE : natural := 32768;
    SPREAD_DEFAULT : natural := 5368709;         -- spread_ref when the init spread is 0
    BG_Q_W         : natural := 14;
    BG_O_W         : natural := 17;
    SEARCH_ITER    : natural := 5;               -- iterations per start point while lost
    STEP16         : natural := 16;              -- search_step in 1/16
    MARGIN_MAX     : natural := 255;             -- largest region margin (MARGIN + the search offset)
    SCALE_TEST_D256: natural range 0 to 255 := 13; -- PRESET 1: the gated scale test: round(256 scale_test); 0 = off (mstrack-v2-colour)
    ORIENT_T       : integer range -1 to 2047 := 64 -- PRESET 1: the joint colour x orientation bins: orient_T; -1 = off (mstrack-v2-colour)
  );
  port (
    clk           : in  std_logic;                      -- core clock
    rst           : in  std_logic;                      -- synchronous reset
    cfg_shift     : in  std_logic;                      -- shift the configuration chain
    cfg_din       : in  std_logic;                      -- configuration bit in
    s_init_tvalid : in  std_logic;                      -- init box (from the chain) valid
    s_init_tready : out std_logic;                      -- init box accepted
    s_axis_tdata  : in  std_logic_vector(24 * PPC - 1 downto 0);  -- video in (as ms_tracker)
    s_axis_tvalid : in  std_logic;
    s_axis_tready : out std_logic;
    s_axis_tlast  : in  std_logic;
    s_axis_tuser  : in  std_logic;
    res_valid     : out std_logic;                      -- result word being shifted out
    res_dout      : out std_logic;                      -- result bit, LSB first
    busy          : out std_logic                       -- mean shift running
  );
end entity;

architecture rtl of ms_tracker_pins is
  constant F_W   : natural := COORD_W + 2;
  constant CFG_W : natural := 6 * F_W;
  signal cfg      : std_logic_vector(CFG_W - 1 downto 0) := (others => '0');
  signal r_data   : std_logic_vector(RESULT_W - 1 downto 0);
  signal r_valid, r_ready : std_logic;
  signal sh       : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');
  signal sh_cnt   : natural range 0 to RESULT_W := 0;

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

  u_core : entity work.ms_tracker
    generic map (
      PRESET          => PRESET,
      MAX_FRAME_W     => MAX_FRAME_W,
      RGB_PACKING     => RGB_PACKING,
      PPC             => PPC,
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
      s_init_tvalid => s_init_tvalid, s_init_tready => s_init_tready,
      s_init_x => signed(fld(cfg, 2, COORD_W + 2)), s_init_y => signed(fld(cfg, 3, COORD_W + 2)),
      s_init_w => unsigned(fld(cfg, 4, COORD_W + 1)), s_init_h => unsigned(fld(cfg, 5, COORD_W + 1)),
      s_axis_tdata => s_axis_tdata, s_axis_tvalid => s_axis_tvalid, s_axis_tready => s_axis_tready,
      s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
      m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
      m_axis_result_tready => r_ready, m_axis_result_tlast => open,
      busy => busy);

  r_ready <= '1' when sh_cnt = 0 else '0';

  p_ser : process(clk)
  begin
    if rising_edge(clk) then
      if sh_cnt = 0 then
        if r_valid = '1' then
          sh <= r_data;
          sh_cnt <= RESULT_W;
        end if;
      else
        sh <= '0' & sh(RESULT_W - 1 downto 1);
        sh_cnt <= sh_cnt - 1;
      end if;
      if rst = '1' then
        sh_cnt <= 0;
      end if;
    end if;
  end process;
  res_dout <= sh(0);
  res_valid <= '1' when sh_cnt /= 0 else '0';
end architecture;
