-- ms_divider_iter: iterative (one quotient bit per clock) restoring division with saturation.
--
-- Computes q = min(floor(n / d), 2**Q_W - 1) for an unsigned dividend n (N_W bits) and an
-- unsigned divisor d (D_W bits), bit-exact with ms_divider (pipelined) and
-- mstrack.fixed.primitives.ms_divider_reference; d = 0 gives all ones (saturation).
-- The operands are registered with the saturation flag (n >= d << Q_W  <=>  (n >> Q_W) >= d);
-- then Q_W steps decide quotient bits Q_W - 1 .. 0.  Unless saturated, the remainder before
-- the step of bit i is < d << (i + 1) and its bits below i are n's, so only the window
-- R = rem >> i (D_W + 1 bits) is held: each step subtracts d from R (its borrow selecting)
-- and shifts the next dividend bit in, one (D_W + 2)-bit subtractor in all.  A saturated
-- result is forced to all ones in the last step.
-- Use: a division unit used a few times per frame / iteration, where the pipelined
-- ms_divider (Q_W stages of remainder, divisor and tag registers) costs far more flip-flops.
--
-- Latency    : LATENCY = Q_W + 1 clocks from in_valid to out_valid (as ms_divider).
-- Throughput : one division per Q_W + 1 clocks: in_valid is accepted when busy = 0 (busy is
--              low again in the out_valid cycle, so divisions can follow back to back).
-- Handshake  : in_valid qualifies in_n/in_d (ignored while busy = 1); out_valid is a one-clock
--              pulse; out_q is registered, valid from out_valid until the next accepted in_valid.
-- Cost       : one D_W + 2 bit subtractor; D_W + 1 + Q_W + D_W + Q_W + a few flip-flops.
-- Reset      : synchronous, active high; control state only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_divider_iter is
  generic (
    N_W : natural := 22;  -- dividend bits (1..)
    D_W : natural := 14;  -- divisor bits (1..)
    Q_W : natural := 16   -- quotient bits (1..); one clock each
  );
  port (
    clk       : in  std_logic;                   -- clock
    rst       : in  std_logic;                   -- synchronous reset, active high
    in_valid  : in  std_logic;                   -- start a division (when busy = 0)
    in_n      : in  unsigned(N_W - 1 downto 0);  -- dividend
    in_d      : in  unsigned(D_W - 1 downto 0);  -- divisor (> 0; 0 gives all ones)
    busy      : out std_logic;                   -- dividing (in_valid ignored)
    out_valid : out std_logic;                   -- pulse: out_q valid (LATENCY clocks after in_valid)
    out_q     : out unsigned(Q_W - 1 downto 0)   -- min(floor(n / d), 2**Q_W - 1)
  );
end entity;

architecture rtl of ms_divider_iter is
  function maxn(a, b : natural) return natural is
  begin
    if a > b then return a; end if;
    return b;
  end function;
  constant LATENCY : natural := Q_W + 1;                 -- in_valid -> out_valid
  constant XW      : natural := maxn(N_W, D_W + Q_W) + 1; -- dividend extended

  signal busy_r : std_logic := '0';
  signal ov_r   : std_logic := '0';
  signal cnt    : natural range 0 to Q_W - 1;
  signal r_r    : unsigned(D_W downto 0);                -- remainder window rem >> i
  signal nl_r   : unsigned(Q_W - 1 downto 0);            -- dividend bits below the window, MSB first
  signal d_r    : unsigned(D_W - 1 downto 0);
  signal sat_r  : std_logic;
  signal q_r    : unsigned(Q_W - 1 downto 0);
begin
  assert N_W >= 1 and D_W >= 1 and Q_W >= 1
    report "ms_divider_iter: widths must be >= 1" severity failure;

  p_div : process (clk)
    variable x    : unsigned(XW - 1 downto 0);
    variable diff : unsigned(D_W + 1 downto 0);          -- R - d, top bit = borrow
    variable rr   : unsigned(D_W downto 0);
    variable q    : unsigned(Q_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      ov_r <= '0';
      if busy_r = '0' then
        if in_valid = '1' then
          x      := resize(in_n, XW);
          r_r    <= x(Q_W - 1 + D_W downto Q_W - 1);
          nl_r   <= shift_left(resize(x(Q_W - 1 downto 0), Q_W), 1);  -- bits Q_W-2 .. 0, then 0
          d_r    <= in_d;
          if shift_right(x, Q_W) >= resize(in_d, XW) then
            sat_r <= '1';
          else
            sat_r <= '0';
          end if;
          cnt    <= Q_W - 1;
          busy_r <= '1';
        end if;
      else
        diff := resize(r_r, D_W + 2) - resize(d_r, D_W + 2);
        if diff(D_W + 1) = '0' then
          rr := diff(D_W downto 0);
        else
          rr := r_r;
        end if;
        q := shift_left(q_r, 1);
        q(0) := not diff(D_W + 1);
        r_r  <= rr(D_W - 1 downto 0) & nl_r(Q_W - 1);
        nl_r <= shift_left(nl_r, 1);
        if cnt = 0 then
          busy_r <= '0';
          ov_r   <= '1';
          if sat_r = '1' then
            q_r <= (others => '1');
          else
            q_r <= q;
          end if;
        else
          q_r <= q;
          cnt <= cnt - 1;
        end if;
      end if;
      if rst = '1' then
        busy_r <= '0';
        ov_r   <= '0';
      end if;
    end if;
  end process;

  busy      <= busy_r;
  out_valid <= ov_r;
  out_q     <= q_r;
end architecture;
