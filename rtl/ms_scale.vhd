-- ms_scale: scale factor s (Q.16) of one frame, tracker v2.
--
--   r   = floor(spread 2**16 / spread_ref)                 (ratio of the spreads, Q.16)
--   est = clamp(isqrt(r 2**16), LO, HI)                    (sqrt of the ratio, Q.16, floored)
--   wr  = floor(w8 2**16 / w0_8)                           (size / init size, Q.16)
--   s   = clamp(ONE + ((GAIN (est - ONE)) >> 16) - ((REG (wr - ONE)) >> 16), LO, HI)
-- with ONE = 2**16, LO = ONE - STEP, HI = ONE + STEP, >> arithmetic (floor); GAIN, REG, STEP are the
-- generics SCALE_GAIN, SCALE_REG, SCALE_STEP = round(x 2**16) of TrackerParams scale_gain, scale_reg,
-- scale_step (mstrack.fixed.vhdl_pkg.v2_scale_generics).
-- Model: mstrack.fixed.blocks_v2.ms_scale(spread, spread_ref, w8, w0_8, tp), bit for bit.
--
-- The model divides with 40 quotient bits.  Here both divisions share one ms_divider_iter of
-- Q_W = max(RATIO_Q_W, WR_Q_W) quotient bits, which is exact: r is used as min(r, 2**RATIO_Q_W - 1)
-- (every larger r gives isqrt(r 2**16) >= HI, clamped to HI all the same: RATIO_Q_W is the smallest
-- width for which that holds, v2_scale_generics), and wr < 2**WR_Q_W for every w8 < 2**SIZE_W,
-- w0_8 >= 3 2**8 (the sizes ms_resize and the init box can give).  spread_ref must be > 0 (the
-- tracker's reference always is; 0 gives est = HI).  The square root is digit-by-digit (the algorithm
-- of ms_isqrt / ms_isqrt_reference), one root bit per clock on ISQ_W = RATIO_Q_W + 16 (even) input
-- bits, and runs during the second division.  The two constant multiplications are shift-and-add,
-- one constant bit per clock, MSB first (17 clocks, no multiplier block), both at once.
--
-- Latency    : SCALE_LAT = 2 Q_W + 25 clocks (Q_W = max(RATIO_Q_W, WR_Q_W); 79 with the defaults): if
--              edge s samples start = 1 (busy = 0), edge s + SCALE_LAT samples done = 1 (asserted by
--              tb/test_ms_scale.py).  Once per frame.
-- Throughput : one s per SCALE_LAT clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; s is registered and
--              held until the next done.
-- Cost       : one ms_divider_iter (max(SPREAD_W, SIZE_W) + 2 bit subtractor), an ISQ_W / 2 + 2 bit
--              subtractor (root), two adders for the products (~36 and WR_Q_W + 19 bits), the clamps.
-- Reset      : synchronous, active high: control state.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_scale is
  generic (
    SPREAD_W   : natural := 25;     -- spread, spread_ref bits
    SIZE_W     : natural := 20;     -- w8, w0_8 bits (Q.8 px, COORD_W + 8)
    SCALE_W    : natural := 17;     -- s bits (s <= ONE + SCALE_STEP)
    SCALE_GAIN : natural := 19661;  -- round(scale_gain 2**16), 0 .. 2**16
    SCALE_REG  : natural := 6554;   -- round(scale_reg 2**16), 0 .. 2**16
    SCALE_STEP : natural := 6554;   -- round(scale_step 2**16), 0 .. 2**15
    RATIO_Q_W  : natural := 17;     -- bits of the ratio r kept (saturating; see above)
    WR_Q_W     : natural := 27      -- bits of the size ratio wr (never saturates in the domain)
  );
  port (
    clk        : in  std_logic;                            -- clock
    rst        : in  std_logic;                            -- synchronous reset
    start      : in  std_logic;                            -- pulse: inputs valid (while busy = 0)
    spread     : in  unsigned(SPREAD_W - 1 downto 0);      -- spread of this frame (ms_spread)
    spread_ref : in  unsigned(SPREAD_W - 1 downto 0);      -- spread at init (> 0)
    w8         : in  unsigned(SIZE_W - 1 downto 0);        -- box width now, Q.8 px (< 2**SIZE_W)
    w0_8       : in  unsigned(SIZE_W - 1 downto 0);        -- box width at init, Q.8 px (>= 3 px)
    busy       : out std_logic;                            -- computing
    done       : out std_logic;                            -- pulse: s valid
    s          : out unsigned(SCALE_W - 1 downto 0)        -- scale factor, Q.16, in [LO, HI]
  );
end entity;

architecture rtl of ms_scale is
  constant ONE   : natural := 2 ** 16;
  constant LO    : natural := ONE - SCALE_STEP;
  constant HI    : natural := ONE + SCALE_STEP;
  constant M_W   : natural := 17;                                  -- GAIN, REG bits (<= 2**16)
  constant OP_W  : natural := max(SPREAD_W, SIZE_W);
  constant Q_W   : natural := max(RATIO_Q_W, WR_Q_W);
  constant ISQ_W : natural := RATIO_Q_W + 16 + (RATIO_Q_W mod 2); -- isqrt input bits (even)
  constant RT_W  : natural := ISQ_W / 2;                           -- root bits
  constant RM_W  : natural := RT_W + 3;                            -- remainder / trial bits (rem <= 2 root)
  constant A_W   : natural := RT_W + 2;                            -- est - ONE (signed)
  constant B_W   : natural := Q_W + 2;                             -- wr - ONE (signed)
  constant PA_W  : natural := A_W + M_W + 1;                       -- GAIN (est - ONE)
  constant PB_W  : natural := B_W + M_W + 1;                       -- REG (wr - ONE)
  constant S_W   : natural := max(PA_W, PB_W) - 16 + 3;            -- ONE + pa - pb before the clamp
  constant GAIN_V : unsigned(M_W - 1 downto 0) := to_unsigned(SCALE_GAIN, M_W);
  constant REG_V  : unsigned(M_W - 1 downto 0) := to_unsigned(SCALE_REG, M_W);

  type state_t is (S_IDLE, S_DIV1, S_DIV2, S_CLAMP, S_MUL, S_SUM, S_OUT);
  signal state : state_t := S_IDLE;

  signal wn_r, wd_r     : unsigned(SIZE_W - 1 downto 0);
  signal dv_valid       : std_logic := '0';
  signal dv_n           : unsigned(OP_W + 15 downto 0);
  signal dv_d           : unsigned(OP_W - 1 downto 0);
  signal dv_busy, dv_ov : std_logic;
  signal dv_q           : unsigned(Q_W - 1 downto 0);
  -- isqrt (digit by digit)
  signal sq_x           : unsigned(ISQ_W - 1 downto 0);
  signal sq_rem         : unsigned(RM_W - 1 downto 0);
  signal sq_root        : unsigned(RT_W - 1 downto 0);
  signal sq_cnt         : natural range 0 to RT_W;          -- root bits still to decide
  signal wr_r           : unsigned(Q_W - 1 downto 0);
  -- products
  signal ax             : signed(A_W - 1 downto 0);
  signal bx             : signed(B_W - 1 downto 0);
  signal pa             : signed(PA_W - 1 downto 0);
  signal pb             : signed(PB_W - 1 downto 0);
  signal k              : natural range 0 to M_W - 1;
  signal sum_r          : signed(S_W - 1 downto 0);
  signal s_r            : unsigned(SCALE_W - 1 downto 0) := (others => '0');
  signal done_r         : std_logic := '0';
begin
  assert SCALE_STEP <= 2 ** 15 and SCALE_GAIN <= 2 ** 16 and SCALE_REG <= 2 ** 16
    report "ms_scale: SCALE_STEP <= 0.5, SCALE_GAIN, SCALE_REG <= 1 (Q.16)" severity failure;
  assert 2 ** SCALE_W > HI report "ms_scale: SCALE_W must hold 1 + step" severity failure;
  assert RT_W <= Q_W + 1 report "ms_scale: the root must be done within the second division" severity failure;

  u_div : entity work.ms_divider_iter
    generic map (N_W => OP_W + 16, D_W => OP_W, Q_W => Q_W)
    port map (clk => clk, rst => rst, in_valid => dv_valid, in_n => dv_n, in_d => dv_d, busy => dv_busy,
              out_valid => dv_ov, out_q => dv_q);

  -- digit-by-digit square root: one root bit per clock while sq_cnt > 0 (ms_isqrt_reference)
  p_isqrt : process (clk)
    variable rm, tr : unsigned(RM_W - 1 downto 0);
    variable diff   : unsigned(RM_W downto 0);
  begin
    if rising_edge(clk) then
      if sq_cnt /= 0 then
        rm := shift_left(sq_rem, 2);
        rm(1 downto 0) := sq_x(ISQ_W - 1 downto ISQ_W - 2);
        tr := shift_left(resize(sq_root, RM_W), 2);
        tr(0) := '1';
        diff := resize(rm, RM_W + 1) - resize(tr, RM_W + 1);
        if diff(RM_W) = '0' then
          sq_rem  <= diff(RM_W - 1 downto 0);
          sq_root <= shift_left(sq_root, 1) or to_unsigned(1, RT_W);
        else
          sq_rem  <= rm;
          sq_root <= shift_left(sq_root, 1);
        end if;
        sq_x   <= shift_left(sq_x, 2);
        sq_cnt <= sq_cnt - 1;
      end if;
      if state = S_DIV1 and dv_ov = '1' then          -- load: x = min(r, 2**RATIO_Q_W - 1) << 16
        if dv_q >= 2 ** RATIO_Q_W - 1 then
          sq_x <= shift_left(resize(to_unsigned(2 ** RATIO_Q_W - 1, RATIO_Q_W), ISQ_W), 16);
        else
          sq_x <= shift_left(resize(dv_q(RATIO_Q_W - 1 downto 0), ISQ_W), 16);
        end if;
        sq_rem  <= (others => '0');
        sq_root <= (others => '0');
        sq_cnt  <= RT_W;
      end if;
      if rst = '1' then
        sq_cnt <= 0;
      end if;
    end if;
  end process;

  p_ctrl : process (clk)
    variable est : unsigned(RT_W - 1 downto 0);
    variable v   : signed(S_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      dv_valid <= '0';
      done_r   <= '0';
      case state is
        when S_IDLE =>
          if start = '1' then                                  -- division 1: spread 2**16 / spread_ref
            dv_n     <= shift_left(resize(spread, OP_W + 16), 16);
            dv_d     <= resize(spread_ref, OP_W);
            dv_valid <= '1';
            wn_r     <= w8;
            wd_r     <= w0_8;
            state    <= S_DIV1;
          end if;

        when S_DIV1 =>
          if dv_ov = '1' then                                  -- division 2: w8 2**16 / w0_8 (isqrt starts)
            dv_n     <= shift_left(resize(wn_r, OP_W + 16), 16);
            dv_d     <= resize(wd_r, OP_W);
            dv_valid <= '1';
            state    <= S_DIV2;
          end if;

        when S_DIV2 =>                                         -- (the root is done long before)
          if dv_ov = '1' then
            wr_r  <= dv_q;
            state <= S_CLAMP;
          end if;

        when S_CLAMP =>                                        -- est = clamp(root); the two factors
          est := sq_root;
          if est < LO then
            est := to_unsigned(LO, RT_W);
          elsif est > HI then
            est := to_unsigned(HI, RT_W);
          end if;
          ax <= signed(resize(est, A_W)) - ONE;
          bx <= signed(resize(wr_r, B_W)) - ONE;
          pa <= (others => '0');
          pb <= (others => '0');
          k  <= M_W - 1;
          state <= S_MUL;

        when S_MUL =>                                          -- MSB first: p = 2 p + bit_k x
          if GAIN_V(k) = '1' then
            pa <= shift_left(pa, 1) + ax;
          else
            pa <= shift_left(pa, 1);
          end if;
          if REG_V(k) = '1' then
            pb <= shift_left(pb, 1) + bx;
          else
            pb <= shift_left(pb, 1);
          end if;
          if k = 0 then
            state <= S_SUM;
          else
            k <= k - 1;
          end if;

        when S_SUM =>                                          -- ONE + (pa >> 16) - (pb >> 16), floor
          -- (>> 16 as a slice: GHDL 2.0 writes shift_right of a signed as Verilog `>>`, a logical shift)
          sum_r <= to_signed(ONE, S_W) + resize(pa(PA_W - 1 downto 16), S_W) - resize(pb(PB_W - 1 downto 16), S_W);
          state <= S_OUT;

        when S_OUT =>                                          -- clamp to [LO, HI]
          v := sum_r;
          if v < LO then
            s_r <= to_unsigned(LO, SCALE_W);
          elsif v > HI then
            s_r <= to_unsigned(HI, SCALE_W);
          else
            s_r <= unsigned(v(SCALE_W - 1 downto 0));
          end if;
          done_r <= '1';
          state  <= S_IDLE;
      end case;
      if rst = '1' then
        state    <= S_IDLE;
        dv_valid <= '0';
        done_r   <= '0';
      end if;
    end if;
  end process;

  busy <= '0' when state = S_IDLE else '1';
  done <= done_r;
  s    <= s_r;
end architecture;
