-- ms_centre: new window centre from the weighted position sums of a bin pass.
--
-- Computes, per axis (x shown, y the same with swy, win_y, lo_y, hi_y):
--   cx = clamp((win_x << CF) + sgn(swx) * min(floor(((|swx| << CF) + (sw >> 1)) / sw), 2**SHIFT_Q_W - 1),
--              lo_x << CF, hi_x << CF)          (clamp = min(max(c, lo), hi))
--   lost = (sw = 0)  (cx, cy are then don't-care)
-- i.e. mstrack.fixed.blocks.ms_centre (round_div_signed + clamp_centre) on region-relative
-- coordinates.  Two ms_divider_iter (N_W = max(SWX_W + CF, SW_W - 1) + 1, D_W = SW_W,
-- Q_W = SHIFT_Q_W), one per axis: x is issued two clocks after start, y the clock after that.
--
-- The clamp thresholds (bounds relative to the window centre, chosen by the sign of the sum)
-- are computed while the division runs, one axis at a time (x after start, y when the x
-- quotient is taken).  The divider operands are registered (x the clock after start, y the
-- clock after that); each axis has an iterative divider (ms_divider_iter, one quotient bit per
-- clock); the quotient of either axis then takes two clocks: S = select, base +- q and two
-- comparisons q < T in parallel; R = the clamp select into cx / cy.
-- Latency    : done SHIFT_Q_W + 6 clocks after start (start in cycle c, done in c + SHIFT_Q_W + 6).
-- Throughput : one centre per SHIFT_Q_W + 6 clocks; a start is accepted when busy = 0
--              (busy is already low in the done cycle, so starts can follow back to back).
-- Handshake  : start samples sw, swx, swy, win_*, lo_*, hi_* (latched); done is a one-clock
--              pulse; cx, cy, lost are registered and stable until the next result.
-- Reset      : synchronous, active high; control state only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_centre is
  generic (
    SW_W      : natural := 22;  -- sw bits (unsigned)
    SWX_W     : natural := 29;  -- swx, swy bits (signed)
    SHIFT_Q_W : natural := 14;  -- quotient bits of the shift division (saturates at 2**SHIFT_Q_W - 1)
    CF        : natural := 8;   -- centre fraction bits
    REGION_W  : natural := 8;   -- region coordinate bits (win, lo, hi)
    CENTRE_W  : natural := 16   -- centre bits (= REGION_W + CF)
  );
  port (
    clk   : in  std_logic;                             -- clock
    rst   : in  std_logic;                             -- synchronous reset, active high
    start : in  std_logic;                             -- pulse: compute a centre (when busy = 0)
    sw    : in  unsigned(SW_W - 1 downto 0);           -- sum w N
    swx   : in  signed(SWX_W - 1 downto 0);            -- sum w SX
    swy   : in  signed(SWX_W - 1 downto 0);            -- sum w SY
    win_x : in  unsigned(REGION_W - 1 downto 0);       -- window centre column (region-relative px)
    win_y : in  unsigned(REGION_W - 1 downto 0);       -- window centre row (region-relative px)
    lo_x  : in  unsigned(REGION_W - 1 downto 0);       -- lowest allowed centre column (px)
    hi_x  : in  unsigned(REGION_W - 1 downto 0);       -- highest allowed centre column (px)
    lo_y  : in  unsigned(REGION_W - 1 downto 0);       -- lowest allowed centre row (px)
    hi_y  : in  unsigned(REGION_W - 1 downto 0);       -- highest allowed centre row (px)
    busy  : out std_logic;                             -- computing (start ignored)
    done  : out std_logic;                             -- pulse: cx, cy, lost valid
    cx    : out unsigned(CENTRE_W - 1 downto 0);       -- new centre column, Q.CF region-relative
    cy    : out unsigned(CENTRE_W - 1 downto 0);       -- new centre row, Q.CF region-relative
    lost  : out std_logic                              -- sw = 0: target lost (cx, cy don't-care)
  );
end entity;

architecture rtl of ms_centre is
  function maxn(a, b : natural) return natural is
  begin
    if a > b then return a; end if;
    return b;
  end function;
  function bool_sl(b : boolean) return std_logic is
  begin
    if b then return '1'; end if;
    return '0';
  end function;
  constant LATENCY : natural := SHIFT_Q_W + 6;                    -- start -> done
  constant N_W     : natural := maxn(SWX_W + CF, SW_W - 1) + 1;   -- divider dividend bits
  constant CW      : natural := maxn(CENTRE_W, SHIFT_Q_W) + 2;    -- signed centre arithmetic bits

  signal busy_r : std_logic := '0';
  signal ph_x   : std_logic := '0';   -- issue x this clock
  signal ph_y   : std_logic := '0';   -- issue y this clock
  signal sw_r   : unsigned(SW_W - 1 downto 0);
  signal swh_r  : unsigned(SW_W - 2 downto 0);   -- sw >> 1
  signal swh1_r : unsigned(N_W - 1 downto 0);    -- (sw >> 1) + 2**CF  (the + 1 of -s, shifted)
  signal swx_r  : signed(SWX_W - 1 downto 0);
  signal swy_r  : signed(SWX_W - 1 downto 0);
  signal win_x_r, win_y_r, lo_x_r, hi_x_r, lo_y_r, hi_y_r : unsigned(REGION_W - 1 downto 0);
  signal lost_r : std_logic;

  signal d_valid : std_logic := '0';               -- divider operands registered
  signal d_n     : unsigned(N_W - 1 downto 0);
  signal d_tag   : std_logic_vector(1 downto 0);  -- (1) = y, (0) = negative
  signal dx_valid, dy_valid : std_logic;          -- x / y operands to their divider
  signal qx_valid, qy_valid : std_logic;
  signal qx, qy  : unsigned(SHIFT_Q_W - 1 downto 0);
  -- stage S: one axis' unclamped centre and bound tests
  signal s_valid : std_logic := '0';
  signal s_y     : std_logic;                     -- the y axis
  signal s_sum, s_lo, s_hi : signed(CW - 1 downto 0);
  signal s_lt, s_gt : std_logic;                  -- c < lo, c > hi

  -- clamp of the axis whose quotient comes next: base = win << CF, lo (hi if lo > hi), hi
  -- (<< CF), thresholds of the two bound tests, sign of the axis' sum
  signal ax_base, ax_lo, ax_hi, ax_tlt, ax_tgt : signed(CW - 1 downto 0);
  signal ax_neg : std_logic;

  signal cx_r, cy_r : unsigned(CENTRE_W - 1 downto 0);
  signal done_r     : std_logic := '0';
  signal lost_o     : std_logic := '0';
begin
  assert CENTRE_W = REGION_W + CF
    report "ms_centre: CENTRE_W must be REGION_W + CF" severity failure;

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        busy_r <= '0';
        ph_x   <= '0';
        ph_y   <= '0';
        done_r <= '0';
      else
        ph_x   <= '0';
        ph_y   <= ph_x;
        done_r <= '0';
        if busy_r = '0' and start = '1' then
          busy_r <= '1';
          ph_x   <= '1';
        end if;
        if s_valid = '1' and s_y = '1' then       -- y result: done
          done_r <= '1';
          busy_r <= '0';
        end if;
      end if;
    end if;
  end process;

  p_latch : process (clk)
  begin
    if rising_edge(clk) then
      if busy_r = '0' and start = '1' then
        sw_r    <= sw;
        swh_r   <= shift_right(sw, 1)(SW_W - 2 downto 0);
        swh1_r  <= resize(shift_right(sw, 1), N_W) + to_unsigned(2 ** CF, N_W);
        swx_r   <= swx;
        swy_r   <= swy;
        win_x_r <= win_x;
        win_y_r <= win_y;
        lo_x_r  <= lo_x;
        hi_x_r  <= hi_x;
        lo_y_r  <= lo_y;
        hi_y_r  <= hi_y;
        if sw = 0 then
          lost_r <= '1';
        else
          lost_r <= '0';
        end if;
      end if;
    end if;
  end process;

  -- divider operands, registered: (|s| << CF) + (sw >> 1), s = swx in the x phase, swy in the
  -- y phase.  For s < 0, |s| = not s + 1 (as SWX_W-bit unsigned, also for s = -2**(SWX_W-1)),
  -- so the operand is (not s << CF) + ((sw >> 1) + 2**CF): one adder after a select.
  p_operands : process (clk)
    variable s   : signed(SWX_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      if ph_x = '1' then
        s := swx_r;
      else
        s := swy_r;
      end if;
      if s < 0 then
        d_n      <= shift_left(resize(unsigned(not s), N_W), CF) + swh1_r;
        d_tag(0) <= '1';
      else
        d_n      <= shift_left(resize(unsigned(s), N_W), CF) + resize(swh_r, N_W);
        d_tag(0) <= '0';
      end if;
      d_tag(1) <= ph_y;
      if rst = '1' then
        d_valid <= '0';
      else
        d_valid <= ph_x or ph_y;
      end if;
    end if;
  end process;

  -- one iterative divider per axis (used once per iteration each: far fewer flip-flops than a
  -- pipeline); x issued the clock before y, so the quotients come back on consecutive clocks
  -- into the shared stage S (select, add, bound tests), then stage R (clamp select)
  u_div_x : entity work.ms_divider_iter
    generic map (N_W => N_W, D_W => SW_W, Q_W => SHIFT_Q_W)
    port map (clk => clk, rst => rst, in_valid => dx_valid, in_n => d_n, in_d => sw_r,
              busy => open, out_valid => qx_valid, out_q => qx);

  u_div_y : entity work.ms_divider_iter
    generic map (N_W => N_W, D_W => SW_W, Q_W => SHIFT_Q_W)
    port map (clk => clk, rst => rst, in_valid => dy_valid, in_n => d_n, in_d => sw_r,
              busy => open, out_valid => qy_valid, out_q => qy);

  dx_valid <= d_valid and not d_tag(1);
  dy_valid <= d_valid and d_tag(1);

  -- clamp bounds of the axis whose quotient comes next (x after start, y when the x quotient is
  -- taken), with the sign of its sum s: c = base + d, d = +q (s >= 0) or -q (s < 0), and
  --   c < lo <=> d < lo - base  <=>  s >= 0: q < lo - base       s < 0: not q < base - lo + 1
  --   c > hi <=> d > hi - base  <=>  s >= 0: not q < hi - base + 1   s < 0: q < base - hi
  -- so each test is one comparison q < T (T precomputed here) and an xor with the sign
  p_axis : process (clk)
    variable w, lo, hi : unsigned(REGION_W - 1 downto 0);
    variable b, l, h   : signed(CW - 1 downto 0);
    variable b1, h1    : signed(CW - 1 downto 0);   -- b + 1, h + 1
    variable neg       : std_logic;
  begin
    if rising_edge(clk) then
      if ph_x = '1' or qx_valid = '1' then
        if ph_x = '1' then                        -- operands latched: x comes first
          w := win_x_r; lo := lo_x_r; hi := hi_x_r; neg := swx_r(SWX_W - 1);
        else                                      -- x taken now: y is next
          w := win_y_r; lo := lo_y_r; hi := hi_y_r; neg := swy_r(SWX_W - 1);
        end if;
        b := signed(shift_left(resize(w, CW), CF));
        l := signed(shift_left(resize(lo, CW), CF));
        h := signed(shift_left(resize(hi, CW), CF));
        if CF > 0 then                            -- low CF bits are 0: + 1 sets bit 0
          b1 := b; b1(0) := '1';
          h1 := h; h1(0) := '1';
        else
          b1 := b + 1;
          h1 := h + 1;
        end if;
        ax_neg  <= neg;
        ax_base <= b;
        ax_hi   <= h;
        if lo > hi then                           -- clamp = min(max(c, lo), hi): hi if lo > hi
          ax_lo <= h;
        else
          ax_lo <= l;
        end if;
        if neg = '1' then
          ax_tlt <= b1 - l;
          ax_tgt <= b - h;
        else
          ax_tlt <= l - b;
          ax_tgt <= h1 - b;
        end if;
      end if;
    end if;
  end process;

  -- stage S (the clock a quotient comes back): c = base +- q and the two bound tests
  p_sel : process (clk)
    variable q : signed(CW - 1 downto 0);
  begin
    if rising_edge(clk) then
      if qy_valid = '1' then
        q := signed(resize(qy, CW));
      else
        q := signed(resize(qx, CW));
      end if;
      if ax_neg = '1' then
        s_sum <= ax_base - q;
      else
        s_sum <= ax_base + q;
      end if;
      s_lt <= ax_neg xor bool_sl(q < ax_tlt);
      s_gt <= (not ax_neg) xor bool_sl(q < ax_tgt);
      s_lo <= ax_lo;
      s_hi <= ax_hi;
      s_y  <= qy_valid;
      if rst = '1' then
        s_valid <= '0';
      else
        s_valid <= qx_valid or qy_valid;
      end if;
    end if;
  end process;

  -- stage R: clamp = lo if c < lo, else hi if c > hi, else c (as the model)
  p_result : process (clk)
    variable c : signed(CW - 1 downto 0);
  begin
    if rising_edge(clk) then
      if s_lt = '1' then
        c := s_lo;
      elsif s_gt = '1' then
        c := s_hi;
      else
        c := s_sum;
      end if;
      if s_valid = '1' then
        if s_y = '1' then
          cy_r   <= resize(unsigned(c), CENTRE_W);
          lost_o <= lost_r;
        else
          cx_r <= resize(unsigned(c), CENTRE_W);
        end if;
      end if;
    end if;
  end process;

  busy <= busy_r;
  done <= done_r;
  cx   <= cx_r;
  cy   <= cy_r;
  lost <= lost_o;
end architecture;
