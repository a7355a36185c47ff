-- ms_meanshift: one feature's mean-shift engine: pixel pass, bin pass, centre, iteration control
-- (model: mstrack.fixed.blocks.ms_meanshift; learn mode: the Q histogram of ms_tracker init).
--
-- Track mode (learn = 0), all coordinates region-relative inside, absolute at the ports:
--   c0 = clamp(start - region origin);  pass at round(c0) -> S0, sums
--   for it = 1 .. MAX_ITER:
--     Sw = 0                     -> stop LOST      (result c0, S0)
--     c1 = ms_centre(sums, round(c0));  pass at round(c1) -> S1, sums
--     S1 < S0                    -> stop RHO       (result c0, S0)
--     shift2 = |c1 - c0|^2 (Q.2CF); c0 = c1; S0 = S1
--     shift2 < EPS2              -> stop SHIFT
--   -> stop MAX_ITER
-- Learn mode (learn = 1): one pixel pass at round(clamp(start)); the bin pass stores H as
-- the model histogram Q and returns K = sum H.
-- A "pass" = ms_pixel_pass (window bounding box, LANES px/clock) then ms_bin_pass (one bin
-- per clock; ITER_BINS = 1: iterative arithmetic, one bin per ~23 clocks, see its header).
-- Cycles per iteration: the pixel pass (sum over the window rows of the LANES
-- groups of each row's ellipse extent, + 6) + the bin pass (N_BINS + ~35) + ms_centre
-- (SHIFT_Q_W + 6) + 6 of control; docs/realtime.md, docs/performance.md.
-- Clamp: the window centre stays in [lo, hi] per axis, region-relative: hi = hi_x / hi_y; lo = ex / ey,
-- or lo_x_in / lo_y_in with LO_IN (the region a pass may use starts after the RAM's origin).
-- Handshake: `start` pulse while `busy` = 0; `done` pulse with the results (held).
-- N_ORIENT > 1 (tracker v2's joint colour x orientation bins, joint bin = N_ORIENT u + o, u the
-- colour bin on ram_data, o the orientation bin on ram_obin from an orientation region RAM read at
-- the same address and latency): ms_pixel_pass accumulates into N_ORIENT banks per lane and
-- ms_bin_pass reads the N_ORIENT banks of a colour address per clock (bin_*_all), so a pass still
-- walks N_BINS addresses (bin pass + TL = ceil(log2 N_ORIENT) clocks: 4 at N_ORIENT 9, per pass).
-- Q (N_ORIENT banks) is learnt as before or loaded while idle, one word per clock (q_ext_we,
-- q_ext_bank: N_ORIENT N_BINS clocks for all of Q) or one colour address of every bank per clock
-- (q_ext_all_we, q_ext_all_data: N_BINS clocks).  Model: ms_meanshift on the joint bins with
-- n_bins = N_ORIENT 2**BIN_W.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_meanshift is
  generic (
    LANES        : natural := 2;      -- pixels per clock of the pixel pass
    BIN_W        : natural := 9;      -- bin index bits (N_BINS = 2**BIN_W)
    HALF_W       : natural := 6;      -- half extent bits
    REGION_W     : natural := 8;      -- region coordinate bits
    STRIDE       : natural := 96;     -- region RAM words per row per bank
    ADDR_W       : natural := 15;     -- region RAM address bits
    COORD_W      : natural := 12;     -- frame coordinate bits
    KERNEL_EPAN  : natural := 0;      -- 0 flat, 1 Epanechnikov
    KERNEL_BITS  : natural := 8;      -- Epanechnikov kernel bits
    KVAL_W       : natural := 1;      -- kernel value bits
    KD_W         : natural := 29;     -- kernel compare term bits
    HIST_W       : natural := 14;     -- H bits
    COUNT_W      : natural := 14;     -- N bits
    POSSUM_W     : natural := 21;     -- SX/SY bits (signed)
    SQRT_IN_W    : natural := 40;     -- Bhattacharyya isqrt input bits
    RHO_SUM_W    : natural := 21;     -- S bits
    RATIO_Q_W    : natural := 16;     -- weight ratio quotient bits
    WEIGHT_W     : natural := 8;      -- weight bits (WI + WF)
    WF           : natural := 4;      -- weight fraction bits
    RF           : natural := 6;      -- Bhattacharyya term fraction bits
    SW_W         : natural := 22;     -- Sw bits
    SWX_W        : natural := 29;     -- Swx/Swy bits (signed)
    SHIFT_Q_W    : natural := 14;     -- shift division quotient bits
    CF           : natural := 8;      -- centre fraction bits
    CENTRE_W     : natural := 16;     -- region-relative centre bits (REGION_W + CF)
    CENTRE_ABS_W : natural := 20;     -- absolute centre bits (COORD_W + CF)
    MAX_ITER     : natural := 20;     -- iteration limit
    ITER_W       : natural := 5;      -- iteration counter bits
    EPS2         : natural := 65536;  -- shift stop threshold, Q.2CF px^2
    RAM_LAT      : positive := 1;     -- region RAM read latency (ms_pixel_pass, 1 .. 4; cycles do not change)
    ITER_BINS    : natural := 0;      -- ms_bin_pass ITERATIVE: 1 = iterative arithmetic (few bins; slower pass)
    N_ORIENT     : natural range 1 to 16 := 1;  -- orientation banks (joint bins N_ORIENT u + o, ITER_BINS = 0 only);
                                      -- 1 = colour bins only (ram_obin, q_ext_bank ignored)
    LO_IN        : boolean := false   -- true: the lowest window centre is lo_x / lo_y (an init job's reference
                                      -- pass, whose slot rectangle starts before its region); false: ex / ey
  );
  port (
    clk       : in  std_logic;                                    -- clock
    rst       : in  std_logic;                                    -- synchronous reset
    -- kernel tables (written by the top at init, broadcast to both engines)
    kt_we     : in  std_logic;                                    -- table write enable
    kt_addr   : in  unsigned(HALF_W - 1 downto 0);                -- table index i
    kt_ta     : in  unsigned(KD_W - 1 downto 0);                  -- 4 i^2 h^2
    kt_tb     : in  unsigned(KD_W - 1 downto 0);                  -- 4 i^2 w^2
    kt_ka     : in  unsigned(KVAL_W - 1 downto 0);                -- Epanechnikov x term
    kt_kb     : in  unsigned(KVAL_W - 1 downto 0);                -- Epanechnikov y term
    kt_xr     : in  unsigned(HALF_W - 1 downto 0);                -- row extent XR[i] (window scan)
    kd_d      : in  unsigned(KD_W - 1 downto 0);                  -- D = w^2 h^2
    ex        : in  unsigned(HALF_W - 1 downto 0);                -- window half extent x
    ey        : in  unsigned(HALF_W - 1 downto 0);                -- window half extent y
    -- region of this frame
    reg_x     : in  unsigned(COORD_W - 1 downto 0);               -- region origin x (absolute)
    reg_y     : in  unsigned(COORD_W - 1 downto 0);               -- region origin y
    hi_x      : in  unsigned(REGION_W - 1 downto 0);              -- largest window centre x (rel.)
    hi_y      : in  unsigned(REGION_W - 1 downto 0);              -- largest window centre y (rel.)
    lo_x_in   : in  unsigned(REGION_W - 1 downto 0) := (others => '0');  -- LO_IN: lowest window centre x (rel.)
    lo_y_in   : in  unsigned(REGION_W - 1 downto 0) := (others => '0');  -- LO_IN: lowest window centre y (rel.)
    -- control
    start     : in  std_logic;                                    -- pulse: run (while busy = 0)
    learn     : in  std_logic;                                    -- with start: learn Q
    start_cx  : in  unsigned(CENTRE_ABS_W - 1 downto 0);          -- start centre x, Q.CF absolute
    start_cy  : in  unsigned(CENTRE_ABS_W - 1 downto 0);          -- start centre y
    busy      : out std_logic;                                    -- running
    done      : out std_logic;                                    -- pulse: results valid (held)
    res_cx    : out unsigned(CENTRE_ABS_W - 1 downto 0);          -- result centre x, Q.CF absolute
    res_cy    : out unsigned(CENTRE_ABS_W - 1 downto 0);          -- result centre y
    res_s     : out unsigned(RHO_SUM_W - 1 downto 0);             -- S at the result centre
    res_iter  : out unsigned(ITER_W - 1 downto 0);                -- iterations run
    res_stop  : out std_logic_vector(1 downto 0);                 -- stop code (ms_pkg STOP_*)
    res_k     : out unsigned(HIST_W - 1 downto 0);                -- K (learn mode)
    -- region RAM read port (one address per bank, data 1 clock later)
    ram_addr  : out std_logic_vector(LANES * ADDR_W - 1 downto 0);
    ram_addr_next : out std_logic_vector(LANES * ADDR_W - 1 downto 0);  -- ram_addr of the next clock (ms_pixel_pass)
    ram_data  : in  std_logic_vector(LANES * BIN_W - 1 downto 0);
    ram_obin  : in  std_logic_vector(LANES * 4 - 1 downto 0) := (others => '0');  -- N_ORIENT > 1: orientation
                                                                  -- bin per bank (lane l at l*4), as ram_data
    -- core v2 (all optional; the paper core leaves them at their defaults / open):
    single    : in  std_logic := '0';                             -- with start: one track pass, no iteration (iter 0)
    max_it    : in  unsigned(ITER_W - 1 downto 0) := to_unsigned(MAX_ITER, ITER_W);  -- iteration limit (1 .. MAX_ITER)
    q_ext_we  : in  std_logic := '0';                             -- write Q[q_ext_addr] (while idle)
    q_ext_addr: in  unsigned(BIN_W - 1 downto 0) := (others => '0');
    q_ext_data: in  unsigned(HIST_W - 1 downto 0) := (others => '0');
    q_ext_bank: in  unsigned(3 downto 0) := (others => '0');      -- N_ORIENT > 1: bank of the q_ext_we write
    q_ext_all_we   : in std_logic := '0';                         -- write every bank at q_ext_addr (while idle)
    q_ext_all_data : in std_logic_vector(N_ORIENT * HIST_W - 1 downto 0) := (others => '0');  -- bank o at o*HIST_W
    px_valid  : out std_logic;                                    -- pixel-pass scan tap (ms_pixel_pass)
    px_mask   : out std_logic_vector(LANES - 1 downto 0);
    px_dx     : out signed(REGION_W downto 0);
    px_dy     : out signed(REGION_W downto 0);
    px_last   : out std_logic
  );
end entity;

architecture rtl of ms_meanshift is
  constant SCW : natural := CENTRE_W + 2;                         -- signed centre work width
  subtype sc_t is signed(SCW - 1 downto 0);

  type state_t is (S_IDLE, S_CLAMP, S_PASS, S_PASS_WAIT, S_BIN_WAIT, S_CENTRE_WAIT,
                   S_DIFF, S_DECIDE, S_FINISH);
  signal state : state_t := S_IDLE;

  signal learn_r          : std_logic;
  signal single_r         : std_logic := '0';
  signal max_it_r         : unsigned(ITER_W - 1 downto 0);
  signal c_in_x, c_in_y   : sc_t;
  signal c0x, c0y         : unsigned(CENTRE_W - 1 downto 0);
  signal c1x, c1y         : unsigned(CENTRE_W - 1 downto 0);
  signal win_x, win_y     : unsigned(REGION_W - 1 downto 0);
  signal win0_x, win0_y   : unsigned(REGION_W - 1 downto 0);
  signal s0               : unsigned(RHO_SUM_W - 1 downto 0);
  signal first            : std_logic;
  signal it               : unsigned(ITER_W - 1 downto 0);
  signal dxs, dys         : sc_t := (others => '0');
  -- stop test on |dxs|, |dys| saturated to SQ_W bits (p_shift): the smallest width whose largest
  -- value squared is >= EPS2, at most CENTRE_W (|dxs| < 2**CENTRE_W: no saturation then) and 16
  -- (65535**2 > any natural EPS2), so each square is one unsigned <= 16 x 16 product
  function sq_width(eps2, max_w : natural) return natural is
    variable w : natural := 1;
  begin
    while w < max_w and 2 ** w - 1 < 46341 and (2 ** w - 1) * (2 ** w - 1) < eps2 loop
      w := w + 1;
    end loop;
    return w;
  end function;
  constant SQ_W : natural := sq_width(EPS2, CENTRE_W);
  signal dxa, dya         : unsigned(SQ_W - 1 downto 0) := (others => '0');
  signal sqx, sqy         : unsigned(2 * SQ_W - 1 downto 0) := (others => '0');
  signal shift2           : unsigned(2 * SQ_W downto 0);
  signal shift_small      : std_logic;
  signal rho_fell         : std_logic;

  -- sub-block handshakes
  constant BIN_RD_LAT : natural := 3;                             -- ms_pixel_pass bin read latency
  signal pp_ready          : std_logic;
  signal pp_start, pp_done : std_logic;
  signal bp_start, bp_done : std_logic;
  signal ce_start, ce_done, ce_lost : std_logic;
  signal ce_cx, ce_cy      : unsigned(CENTRE_W - 1 downto 0);
  signal bp_s              : unsigned(RHO_SUM_W - 1 downto 0);
  signal bp_sw             : unsigned(SW_W - 1 downto 0);
  signal bp_swx, bp_swy    : signed(SWX_W - 1 downto 0);
  signal bp_k              : unsigned(HIST_W - 1 downto 0);
  signal bin_rd_en         : std_logic;
  signal bin_rd_addr       : unsigned(BIN_W - 1 downto 0);
  signal bin_rd_valid      : std_logic;
  signal bin_h             : unsigned(HIST_W - 1 downto 0);
  signal bin_n             : unsigned(COUNT_W - 1 downto 0);
  signal bin_sx, bin_sy    : signed(POSSUM_W - 1 downto 0);
  signal bin_h_all         : std_logic_vector(N_ORIENT * HIST_W - 1 downto 0);
  signal bin_n_all         : std_logic_vector(N_ORIENT * COUNT_W - 1 downto 0);
  signal bin_sx_all        : std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0);
  signal bin_sy_all        : std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0);
  signal lo_x, lo_y        : unsigned(REGION_W - 1 downto 0);

  function round_c(c : unsigned) return unsigned is
  begin
    return resize(shift_right(resize(c, CENTRE_W + 1) + 2 ** (CF - 1), CF), REGION_W);
  end function;
begin
  lo_x <= lo_x_in when LO_IN else resize(ex, REGION_W);
  lo_y <= lo_y_in when LO_IN else resize(ey, REGION_W);

  u_pass : entity work.ms_pixel_pass
    generic map (LANES => LANES, BIN_W => BIN_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, KERNEL_EPAN => KERNEL_EPAN,
                 KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W, KD_W => KD_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, RAM_LAT => RAM_LAT, N_ORIENT => N_ORIENT)
    port map (clk => clk, rst => rst, ready => pp_ready, start => pp_start, win_x => win_x, win_y => win_y,
              ex => ex, ey => ey, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr, kd_d => kd_d,
              ram_addr => ram_addr, ram_addr_next => ram_addr_next, ram_data => ram_data, ram_obin => ram_obin,
              done => pp_done,
              bin_rd_en => bin_rd_en, bin_rd_addr => bin_rd_addr, bin_rd_valid => bin_rd_valid,
              bin_h => bin_h, bin_n => bin_n, bin_sx => bin_sx, bin_sy => bin_sy,
              bin_h_all => bin_h_all, bin_n_all => bin_n_all, bin_sx_all => bin_sx_all, bin_sy_all => bin_sy_all,
              px_valid => px_valid, px_mask => px_mask, px_dx => px_dx, px_dy => px_dy, px_last => px_last);

  u_bins : entity work.ms_bin_pass
    generic map (BIN_W => BIN_W, HIST_W => HIST_W, COUNT_W => COUNT_W, POSSUM_W => POSSUM_W,
                 SQRT_IN_W => SQRT_IN_W, RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W,
                 WEIGHT_W => WEIGHT_W, WF => WF, RF => RF, SW_W => SW_W, SWX_W => SWX_W,
                 BIN_RD_LAT => BIN_RD_LAT, ITERATIVE => ITER_BINS, N_ORIENT => N_ORIENT)
    port map (clk => clk, rst => rst, start => bp_start, learn => learn_r, busy => open,
              bin_rd_en => bin_rd_en, bin_rd_addr => bin_rd_addr, bin_rd_valid => bin_rd_valid,
              bin_h => bin_h, bin_n => bin_n, bin_sx => bin_sx, bin_sy => bin_sy,
              bin_h_all => bin_h_all, bin_n_all => bin_n_all, bin_sx_all => bin_sx_all, bin_sy_all => bin_sy_all,
              done => bp_done, s_sum => bp_s, sw => bp_sw, swx => bp_swx, swy => bp_swy,
              k_sum => bp_k, q_ext_we => q_ext_we, q_ext_addr => q_ext_addr, q_ext_data => q_ext_data,
              q_ext_bank => q_ext_bank, q_ext_all_we => q_ext_all_we, q_ext_all_data => q_ext_all_data);

  u_centre : entity work.ms_centre
    generic map (SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CF => CF,
                 REGION_W => REGION_W, CENTRE_W => CENTRE_W)
    port map (clk => clk, rst => rst, start => ce_start, sw => bp_sw, swx => bp_swx, swy => bp_swy,
              win_x => win0_x, win_y => win0_y, lo_x => lo_x, hi_x => hi_x, lo_y => lo_y,
              hi_y => hi_y, done => ce_done, cx => ce_cx, cy => ce_cy, lost => ce_lost);

  busy <= '0' when state = S_IDLE else '1';

  -- shift2 = dxs^2 + dys^2 < EPS2, free running in four register stages (|d| saturated |
  -- square | sum | compare): dxs / dys are written in S_CENTRE_WAIT and read back in S_DECIDE
  -- after a whole pixel pass and bin pass (>= N_BINS clocks), so shift_small has long settled
  -- by then.  Saturation keeps the result: let M = 2**SQ_W - 1, a = min(|dxs|, M),
  -- b = min(|dys|, M).  If |dxs| <= M and |dys| <= M, a^2 + b^2 = dxs^2 + dys^2.  Otherwise
  -- one of them, say |dxs| > M, so dxs^2 > M^2 and a^2 = M^2; with M^2 >= EPS2 (sq_width) both
  -- dxs^2 + dys^2 and a^2 + b^2 are >= EPS2: "not small" either way.  (When SQ_W = CENTRE_W,
  -- M >= |d| always and nothing saturates.)
  p_shift : process(clk)
    -- |d| saturated to SQ_W bits (|d| < 2**CENTRE_W: the negation does not overflow; not abs:
    -- GHDL 2.0 writes it as VHDL into the Verilog)
    function sat_mag(d : sc_t) return unsigned is
      variable ad : unsigned(SCW - 1 downto 0);
    begin
      if d < 0 then
        ad := unsigned(-d);
      else
        ad := unsigned(d);
      end if;
      if shift_right(ad, SQ_W) /= 0 then
        return to_unsigned(2 ** SQ_W - 1, SQ_W);
      end if;
      return ad(SQ_W - 1 downto 0);
    end function;
  begin
    if rising_edge(clk) then
      dxa <= sat_mag(dxs);
      dya <= sat_mag(dys);
      sqx <= dxa * dxa;
      sqy <= dya * dya;
      shift2 <= resize(sqx, 2 * SQ_W + 1) + sqy;
      if shift2 < EPS2 then
        shift_small <= '1';
      else
        shift_small <= '0';
      end if;
    end if;
  end process;

  p_ctrl : process(clk)
    variable cx, cy   : sc_t;
    variable lo, hi   : sc_t;
    variable stop_now : boolean;
  begin
    if rising_edge(clk) then
      pp_start <= '0';
      bp_start <= '0';
      ce_start <= '0';
      done <= '0';
      case state is
        when S_IDLE =>
          if start = '1' then
            learn_r <= learn;
            single_r <= single and not learn;
            max_it_r <= max_it;
            c_in_x <= signed(resize(start_cx, SCW)) - signed(resize(shift_left(resize(reg_x, CENTRE_ABS_W), CF), SCW));
            c_in_y <= signed(resize(start_cy, SCW)) - signed(resize(shift_left(resize(reg_y, CENTRE_ABS_W), CF), SCW));
            first <= '1';
            it <= to_unsigned(1, ITER_W);
            state <= S_CLAMP;
          end if;

        when S_CLAMP =>                       -- c0 = clamp(start), window at round(c0)
          -- the two bound compares and round(c_in) side by side (one carry chain deep), then
          -- a select: round(lo) = ex / ey and round(hi) = hi_x / hi_y exactly (integer bounds)
          lo := signed(resize(shift_left(resize(lo_x, CENTRE_W), CF), SCW));
          hi := signed(resize(shift_left(resize(hi_x, CENTRE_W), CF), SCW));
          if c_in_x < lo and not (lo_x > hi_x) then                   -- clamped to lo
            c0x <= unsigned(lo(CENTRE_W - 1 downto 0));
            win_x <= lo_x;
          elsif c_in_x < lo or c_in_x > hi then                       -- clamped to hi
            c0x <= unsigned(hi(CENTRE_W - 1 downto 0));
            win_x <= hi_x;
          else
            c0x <= unsigned(c_in_x(CENTRE_W - 1 downto 0));
            win_x <= round_c(unsigned(c_in_x(CENTRE_W - 1 downto 0)));
          end if;
          lo := signed(resize(shift_left(resize(lo_y, CENTRE_W), CF), SCW));
          hi := signed(resize(shift_left(resize(hi_y, CENTRE_W), CF), SCW));
          if c_in_y < lo and not (lo_y > hi_y) then
            c0y <= unsigned(lo(CENTRE_W - 1 downto 0));
            win_y <= lo_y;
          elsif c_in_y < lo or c_in_y > hi then
            c0y <= unsigned(hi(CENTRE_W - 1 downto 0));
            win_y <= hi_y;
          else
            c0y <= unsigned(c_in_y(CENTRE_W - 1 downto 0));
            win_y <= round_c(unsigned(c_in_y(CENTRE_W - 1 downto 0)));
          end if;
          state <= S_PASS;

        when S_PASS =>                        -- (the histogram clears itself after reset)
          if pp_ready = '1' then
            pp_start <= '1';
            state <= S_PASS_WAIT;
          end if;

        when S_PASS_WAIT =>
          if pp_done = '1' then
            bp_start <= '1';
            state <= S_BIN_WAIT;
          end if;

        when S_BIN_WAIT =>
          if bp_done = '1' then
            if learn_r = '1' or single_r = '1' then
              res_k <= bp_k;
              s0 <= bp_s;
              it <= (others => '0');
              res_stop <= STOP_SHIFT;
              state <= S_FINISH;
            elsif first = '1' then
              first <= '0';
              s0 <= bp_s;
              win0_x <= win_x;
              win0_y <= win_y;
              ce_start <= '1';
              state <= S_CENTRE_WAIT;
            else
              state <= S_DIFF;
            end if;
          end if;

        when S_CENTRE_WAIT =>
          if ce_done = '1' then
            if ce_lost = '1' then
              res_stop <= STOP_LOST;
              state <= S_FINISH;
            else
              c1x <= ce_cx;
              c1y <= ce_cy;
              -- shift components now (c0 is stable), squared and compared during the pass
              -- (p_shift); S_DIFF registers the rho compare for S_DECIDE
              dxs <= signed(resize(ce_cx, SCW)) - signed(resize(c0x, SCW));
              dys <= signed(resize(ce_cy, SCW)) - signed(resize(c0y, SCW));
              win_x <= round_c(ce_cx);
              win_y <= round_c(ce_cy);
              state <= S_PASS;
            end if;
          end if;

        when S_DIFF =>                        -- (shift_small settles during the pass)
          rho_fell <= '1' when bp_s < s0 else '0';
          state <= S_DECIDE;

        when S_DECIDE =>
          if rho_fell = '1' then              -- S1 < S0: keep c0, S0
            res_stop <= STOP_RHO;
            state <= S_FINISH;
          else
            c0x <= c1x;
            c0y <= c1y;
            s0 <= bp_s;
            win0_x <= win_x;
            win0_y <= win_y;
            stop_now := true;
            if shift_small = '1' then
              res_stop <= STOP_SHIFT;
            elsif it = max_it_r then
              res_stop <= STOP_MAX_ITER;
            else
              stop_now := false;
            end if;
            if stop_now then
              state <= S_FINISH;
            else
              it <= it + 1;
              ce_start <= '1';
              state <= S_CENTRE_WAIT;
            end if;
          end if;

        when S_FINISH =>                      -- back to absolute coordinates
          res_cx <= resize(c0x, CENTRE_ABS_W) + shift_left(resize(reg_x, CENTRE_ABS_W), CF);
          res_cy <= resize(c0y, CENTRE_ABS_W) + shift_left(resize(reg_y, CENTRE_ABS_W), CF);
          res_s <= s0;
          res_iter <= it;
          done <= '1';
          state <= S_IDLE;
      end case;
      if rst = '1' then
        state <= S_IDLE;
        pp_start <= '0';
        bp_start <= '0';
        ce_start <= '0';
        done <= '0';
      end if;
    end if;
  end process;
end architecture;
