-- ms_fusion: fusion weights, fused centre and reported rho values
-- (model: mstrack.fixed.blocks.ms_fusion and ms_rho_out).
--
--   tot     = S_c + S_e
--   alpha_c = FEATURES 1 (colour): 2**AF;  FEATURES 2 (edge): 0;
--             fused: tot = 0 ? 2**(AF-1) : floor(((S_c << AF) + (tot >> 1)) / tot)
--   alpha_e = 2**AF - alpha_c
--   c       = (alpha_c * c_c + alpha_e * c_e + 2**(AF-1)) >> AF        (x and y)
--   rho_f   = floor((S_f << (RHO_OUT_FRAC - RF)) / K)   (0 for an unused feature)
-- The three divisions run in three iterative dividers (ms_divider_iter, one quotient bit per
-- clock, issued on consecutive clocks; each is used once per frame).  The
-- blend needs no multiplier: alpha_c c_c and alpha_e c_e are built by shift-and-add, one bit
-- of alpha per clock, MSB first (acc = 2 acc + bit c), then summed and rounded in two more
-- clocks, so every clock has at most one adder between registers (no MULT18X18D, which yosys
-- maps without its registers on ECP5: the blend in one clock was a 63-76 MHz path).
-- Latency: start in cycle c, done in cycle c + Q_W + 9 + ALPHA_W when the alpha division is
-- issued (fused, S_c + S_e > 0), c + Q_W + 8 + ALPHA_W otherwise (Q_W = RHO_OUT_FRAC + 1):
-- 3 issue clocks, the divider (Q_W + 1), S_WAIT, S_BLEND, ALPHA_W x S_MAC, S_SUM, S_ROUND,
-- S_DONE; one fusion per frame.  Handshake: start pulse (while idle) -> done pulse; outputs held.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_fusion is
  generic (
    FEATURES     : natural := 0;   -- 0 fused, 1 colour only, 2 edge only
    RHO_SUM_W    : natural := 21;  -- bits of S (Bhattacharyya sum, RF fraction bits)
    HIST_W       : natural := 14;  -- bits of K (sum of kernel values)
    CENTRE_ABS_W : natural := 20;  -- bits of an absolute Q.CF centre
    AF           : natural := 8;   -- alpha fraction bits
    ALPHA_W      : natural := 9;   -- alpha bits (0 .. 2**AF)
    RF           : natural := 6;   -- fraction bits of S
    RHO_OUT_FRAC : natural := 16;  -- fraction bits of the reported rho
    RHO_OUT_W    : natural := 17   -- reported rho bits (0 .. 2**RHO_OUT_FRAC)
  );
  port (
    clk     : in  std_logic;                                 -- clock
    rst     : in  std_logic;                                 -- synchronous reset
    start   : in  std_logic;                                 -- pulse: inputs valid
    s_c     : in  unsigned(RHO_SUM_W - 1 downto 0);          -- colour S
    s_e     : in  unsigned(RHO_SUM_W - 1 downto 0);          -- edge S
    c_cx    : in  unsigned(CENTRE_ABS_W - 1 downto 0);       -- colour centre x (Q.CF)
    c_cy    : in  unsigned(CENTRE_ABS_W - 1 downto 0);       -- colour centre y
    e_cx    : in  unsigned(CENTRE_ABS_W - 1 downto 0);       -- edge centre x
    e_cy    : in  unsigned(CENTRE_ABS_W - 1 downto 0);       -- edge centre y
    k_sum   : in  unsigned(HIST_W - 1 downto 0);             -- K (> 0)
    done    : out std_logic;                                 -- pulse: outputs valid (held)
    cx      : out unsigned(CENTRE_ABS_W - 1 downto 0);       -- fused centre x (Q.CF)
    cy      : out unsigned(CENTRE_ABS_W - 1 downto 0);       -- fused centre y
    alpha_c : out unsigned(ALPHA_W - 1 downto 0);            -- colour weight (Q0.AF, 0 .. 2**AF)
    rho_c   : out unsigned(RHO_OUT_W - 1 downto 0);          -- colour rho (Q.RHO_OUT_FRAC)
    rho_e   : out unsigned(RHO_OUT_W - 1 downto 0)           -- edge rho
  );
end entity;

architecture rtl of ms_fusion is
  constant Q_W : natural := RHO_OUT_FRAC + 1;
  constant N_W : natural := max(RHO_SUM_W + 1 + AF, RHO_SUM_W + RHO_OUT_FRAC - RF);
  constant D_W : natural := max(RHO_SUM_W + 1, HIST_W);
  constant ONE : natural := 2 ** AF;

  constant PW  : natural := CENTRE_ABS_W + ALPHA_W;        -- one product alpha * c

  type state_t is (S_IDLE, S_ISSUE1, S_ISSUE2, S_WAIT, S_BLEND, S_MAC, S_SUM, S_ROUND, S_DONE);
  signal state : state_t := S_IDLE;

  signal sc_r, se_r     : unsigned(RHO_SUM_W - 1 downto 0);
  signal tot_r          : unsigned(RHO_SUM_W downto 0);
  signal k_r            : unsigned(HIST_W - 1 downto 0);
  signal ccx_r, ccy_r, ecx_r, ecy_r : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal dv_rc, dv_re, dv_a : std_logic := '0';  -- issue rho_c / rho_e / alpha division
  signal div_n          : unsigned(N_W - 1 downto 0);
  signal div_d          : unsigned(D_W - 1 downto 0);
  signal qv_rc, qv_re, qv_a : std_logic;         -- results (one-clock pulses)
  signal q_rc, q_re, q_a : unsigned(Q_W - 1 downto 0);
  signal n_results      : unsigned(1 downto 0);
  signal a_c            : unsigned(ALPHA_W - 1 downto 0);
  -- blend: multiplier bits (shifted out MSB first), products, sums
  signal m_c, m_e       : unsigned(ALPHA_W - 1 downto 0);
  signal p_cx, p_cy, p_ex, p_ey : unsigned(PW - 1 downto 0);
  signal sum_x, sum_y   : unsigned(PW downto 0);
  signal nbit           : natural range 0 to ALPHA_W - 1;
begin
  assert Q_W >= AF + 1 report "ms_fusion: RHO_OUT_FRAC must be >= AF" severity failure;
  assert RHO_OUT_FRAC >= RF report "ms_fusion: RHO_OUT_FRAC must be >= RF" severity failure;

  -- one iterative divider per division (each used once per frame: far fewer flip-flops than a
  -- pipeline); issued on consecutive clocks, so the results come back on consecutive clocks,
  -- each straight into its own register
  u_div_rc : entity work.ms_divider_iter
    generic map (N_W => N_W, D_W => D_W, Q_W => Q_W)
    port map (clk => clk, rst => rst, in_valid => dv_rc, in_n => div_n, in_d => div_d,
              busy => open, out_valid => qv_rc, out_q => q_rc);
  u_div_re : entity work.ms_divider_iter
    generic map (N_W => N_W, D_W => D_W, Q_W => Q_W)
    port map (clk => clk, rst => rst, in_valid => dv_re, in_n => div_n, in_d => div_d,
              busy => open, out_valid => qv_re, out_q => q_re);
  u_div_a : entity work.ms_divider_iter
    generic map (N_W => N_W, D_W => D_W, Q_W => Q_W)
    port map (clk => clk, rst => rst, in_valid => dv_a, in_n => div_n, in_d => div_d,
              busy => open, out_valid => qv_a, out_q => q_a);

  p_fsm : process(clk)
  begin
    if rising_edge(clk) then
      dv_rc <= '0';
      dv_re <= '0';
      dv_a  <= '0';
      done <= '0';
      case state is
        when S_IDLE =>
          if start = '1' then
            sc_r <= s_c; se_r <= s_e; k_r <= k_sum;
            tot_r <= resize(s_c, RHO_SUM_W + 1) + s_e;
            ccx_r <= c_cx; ccy_r <= c_cy; ecx_r <= e_cx; ecy_r <= e_cy;
            n_results <= (others => '0');
            -- rho_c division: (S_c << (RHO_OUT_FRAC - RF)) / K
            dv_rc <= '1';
            div_n <= shift_left(resize(s_c, N_W), RHO_OUT_FRAC - RF);
            div_d <= resize(k_sum, D_W);
            state <= S_ISSUE1;
          end if;
        when S_ISSUE1 =>
          dv_re <= '1';
          div_n <= shift_left(resize(se_r, N_W), RHO_OUT_FRAC - RF);
          div_d <= resize(k_r, D_W);
          state <= S_ISSUE2;
        when S_ISSUE2 =>
          -- alpha division (fused mode with tot > 0); otherwise a constant
          if FEATURES = 1 then
            a_c <= to_unsigned(ONE, ALPHA_W);
          elsif FEATURES = 2 then
            a_c <= (others => '0');
          elsif tot_r = 0 then
            a_c <= to_unsigned(ONE / 2, ALPHA_W);
          else
            dv_a  <= '1';
            div_n <= shift_left(resize(sc_r, N_W), AF) + shift_right(resize(tot_r, N_W), 1);
            div_d <= resize(tot_r, D_W);
          end if;
          state <= S_WAIT;
        when S_WAIT =>
          if (qv_rc or qv_re or qv_a) = '1' then  -- results captured below
            n_results <= n_results + 1;
            -- the last expected result: 3 if the alpha division was issued, else 2
            if (n_results = 2) or (n_results = 1 and (FEATURES /= 0 or tot_r = 0)) then
              state <= S_BLEND;
            end if;
          end if;
        when S_BLEND =>                   -- set up alpha_c c_c and alpha_e c_e (x and y)
          m_c <= a_c;
          m_e <= to_unsigned(ONE, ALPHA_W) - a_c;
          p_cx <= (others => '0');
          p_cy <= (others => '0');
          p_ex <= (others => '0');
          p_ey <= (others => '0');
          nbit <= ALPHA_W - 1;
          state <= S_MAC;
        when S_MAC =>                     -- p = 2 p + (alpha bit) c, MSB first
          if m_c(ALPHA_W - 1) = '1' then
            p_cx <= shift_left(p_cx, 1) + resize(ccx_r, PW);
            p_cy <= shift_left(p_cy, 1) + resize(ccy_r, PW);
          else
            p_cx <= shift_left(p_cx, 1);
            p_cy <= shift_left(p_cy, 1);
          end if;
          if m_e(ALPHA_W - 1) = '1' then
            p_ex <= shift_left(p_ex, 1) + resize(ecx_r, PW);
            p_ey <= shift_left(p_ey, 1) + resize(ecy_r, PW);
          else
            p_ex <= shift_left(p_ex, 1);
            p_ey <= shift_left(p_ey, 1);
          end if;
          m_c <= shift_left(m_c, 1);
          m_e <= shift_left(m_e, 1);
          if nbit = 0 then
            state <= S_SUM;
          else
            nbit <= nbit - 1;
          end if;
        when S_SUM =>
          sum_x <= resize(p_cx, PW + 1) + p_ex;
          sum_y <= resize(p_cy, PW + 1) + p_ey;
          state <= S_ROUND;
        when S_ROUND =>                   -- (alpha_c c_c + alpha_e c_e + 2**(AF-1)) >> AF
          cx <= resize(shift_right(sum_x + ONE / 2, AF), CENTRE_ABS_W);
          cy <= resize(shift_right(sum_y + ONE / 2, AF), CENTRE_ABS_W);
          alpha_c <= a_c;
          state <= S_DONE;
        when S_DONE =>
          done <= '1';
          state <= S_IDLE;
      end case;
      -- division results (they only come back in S_WAIT): straight into their registers, enabled
      -- by the divider's out_valid alone
      if qv_rc = '1' then
        rho_c <= (others => '0');
        if FEATURES /= 2 then rho_c <= resize(q_rc, RHO_OUT_W); end if;
      end if;
      if qv_re = '1' then
        rho_e <= (others => '0');
        if FEATURES /= 1 then rho_e <= resize(q_re, RHO_OUT_W); end if;
      end if;
      if qv_a = '1' then
        a_c <= resize(q_a, ALPHA_W);
      end if;
      if rst = '1' then
        state <= S_IDLE;
        dv_rc <= '0';
        dv_re <= '0';
        dv_a  <= '0';
        done <= '0';
      end if;
    end if;
  end process;
end architecture;
