-- ms_divider: pipelined restoring division with saturation.
--
-- Computes q = min(floor(n / d), 2**Q_W - 1) for an unsigned dividend n (N_W bits) and an
-- unsigned divisor d (D_W bits), bit-exact with mstrack.fixed.primitives.ms_divider_reference
-- (and the vectorised ms_divider).  Stage 0 registers the operands and flags saturation
-- (n >= d << Q_W); stage k = 1..Q_W decides quotient bit i = Q_W - k by comparing the partial
-- remainder with d << i and subtracting it when it is >= (restoring division).  Unless the
-- result saturates, the remainder entering stage k is < d << (i + 1), so only its bits
-- i + D_W .. i take part: one (D_W + 2)-bit subtraction per stage, its borrow selecting
-- (remainder bits no later stage reads are dropped by synthesis).
-- d = 0: the saturation test n >= 0 is always true, so q = 2**Q_W - 1 (all ones); callers
-- must avoid d = 0 (the model raises on it).
--
-- Latency    : LATENCY = Q_W + 1 clocks from in_valid to out_valid (constant LATENCY below).
-- Throughput : one division per clock, no back-pressure: the pipeline always flows.
-- Handshake  : in_valid qualifies in_n/in_d/in_tag; out_valid qualifies out_q/out_tag
--              (one out_valid pulse per in_valid, in order, LATENCY clocks later).
-- Cost       : Q_W subtractors of D_W + 2 bits and as many pipeline registers for the
--              remainder, divisor and tag.
-- Reset      : synchronous, active high; clears the valid pipeline only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_divider is
  generic (
    N_W   : natural := 22;  -- dividend bits (1..)
    D_W   : natural := 14;  -- divisor bits (1..)
    Q_W   : natural := 16;  -- quotient bits (1..); each adds one pipeline stage
    TAG_W : natural := 1    -- user tag bits passed alongside (1..; tie unused tags to '0')
  );
  port (
    clk       : in  std_logic;                             -- clock
    rst       : in  std_logic;                             -- synchronous reset, active high
    in_valid  : in  std_logic;                             -- input operands valid
    in_n      : in  unsigned(N_W - 1 downto 0);            -- dividend
    in_d      : in  unsigned(D_W - 1 downto 0);            -- divisor (> 0; 0 gives all ones)
    in_tag    : in  std_logic_vector(TAG_W - 1 downto 0);  -- user tag
    out_valid : out std_logic;                             -- result valid (LATENCY clocks after in_valid)
    out_q     : out unsigned(Q_W - 1 downto 0);            -- min(floor(n / d), 2**Q_W - 1)
    out_tag   : out std_logic_vector(TAG_W - 1 downto 0)   -- tag of this result
  );
end entity;

architecture rtl of ms_divider is
  constant LATENCY : natural := Q_W + 1;                   -- clocks from in_valid to out_valid
  -- remainder/compare width: holds n and d << (Q_W - 1) and d << Q_W for the saturation test
  function maxn(a, b : natural) return natural is
  begin
    if a > b then return a; end if;
    return b;
  end function;
  constant CW : natural := maxn(N_W, D_W + Q_W) + 1;

  type rem_arr_t is array (0 to Q_W) of unsigned(CW - 1 downto 0);
  type d_arr_t is array (0 to Q_W) of unsigned(D_W - 1 downto 0);
  type q_arr_t is array (0 to Q_W) of unsigned(Q_W - 1 downto 0);
  type tag_arr_t is array (0 to Q_W) of std_logic_vector(TAG_W - 1 downto 0);

  signal v_r   : std_logic_vector(0 to Q_W) := (others => '0');
  signal sat_r : std_logic_vector(0 to Q_W);
  signal rem_r : rem_arr_t;
  signal d_r   : d_arr_t;
  signal q_r   : q_arr_t;
  signal tag_r : tag_arr_t;
begin
  assert N_W >= 1 and D_W >= 1 and Q_W >= 1 and TAG_W >= 1
    report "ms_divider: widths must be >= 1" severity failure;

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        v_r <= (others => '0');
      else
        v_r <= in_valid & v_r(0 to Q_W - 1);
      end if;
    end if;
  end process;

  p_data : process (clk)
    variable hi   : unsigned(D_W downto 0);         -- remainder bits i + D_W .. i
    variable diff : unsigned(D_W + 1 downto 0);     -- hi - d, top bit = borrow
    variable i    : natural;
  begin
    if rising_edge(clk) then
      -- stage 0: register operands, saturation test n >= d << Q_W  <=>  (n >> Q_W) >= d
      rem_r(0) <= resize(in_n, CW);
      d_r(0)   <= in_d;
      q_r(0)   <= (others => '0');
      tag_r(0) <= in_tag;
      if shift_right(resize(in_n, CW), Q_W) >= resize(in_d, CW) then
        sat_r(0) <= '1';
      else
        sat_r(0) <= '0';
      end if;
      -- stage k: quotient bit i = Q_W - k.  Unless saturated, rem < d << (i + 1), so
      -- rem >= d << i  <=>  hi = rem(i + D_W .. i) >= d, and rem - (d << i) only changes those
      -- bits: one D_W + 2 bit subtractor whose borrow selects (saturated: q is forced anyway)
      for k in 1 to Q_W loop
        i := Q_W - k;
        hi   := rem_r(k - 1)(i + D_W downto i);
        diff := resize(hi, D_W + 2) - resize(d_r(k - 1), D_W + 2);
        d_r(k)   <= d_r(k - 1);
        tag_r(k) <= tag_r(k - 1);
        sat_r(k) <= sat_r(k - 1);
        rem_r(k) <= rem_r(k - 1);
        q_r(k)   <= q_r(k - 1);
        if diff(D_W + 1) = '0' then
          rem_r(k)(i + D_W downto i) <= diff(D_W downto 0);
          q_r(k)(i) <= '1';
        end if;
      end loop;
      -- saturation folded into the last stage so that out_q is a plain register
      if sat_r(Q_W - 1) = '1' then
        q_r(Q_W) <= (others => '1');
      end if;
    end if;
  end process;

  out_valid <= v_r(Q_W);
  out_q     <= q_r(Q_W);
  out_tag   <= tag_r(Q_W);
end architecture;
