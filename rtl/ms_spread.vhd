-- ms_spread: mean d2q of the target-coloured pixels, spread = floor(st2 2**16 / nt) (Q.(KB + 16)),
-- 0 when nt = 0.
--
-- One ms_divider_iter (N_W = ST2_W + 16, D_W = COUNT_W, Q_W = SPREAD_W).  nt = 0 divides 0 by 1 (the
-- operands are chosen in front of the divider's input registers), so the quotient register is the
-- output.  The model divides with 40 quotient bits (ms_divider(st2 << 16, nt, 40)); SPREAD_W bits
-- (v2_scale_generics: bits_for((2**(KB + 1) - 1) 2**16) = 25) give the same quotient for every
-- st2 < 2**(SPREAD_W - 16) nt, i.e. every mean d2q the kernel tables can give (d2q < 2**(KB + 1));
-- beyond that the quotient saturates at 2**SPREAD_W - 1.
-- Model: mstrack.fixed.blocks_v2.ms_spread (on a TargetStats).
--
-- Latency    : SPREAD_W + 1 clocks: if edge s samples start = 1 (busy = 0), edge s + SPREAD_W + 1
--              samples done = 1 (tb/test_ms_spread.py asserts it).
-- Throughput : one spread per SPREAD_W + 1 clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; spread is registered
--              and held until the next start.
-- Cost       : one ms_divider_iter (a COUNT_W + 2 bit subtractor, ~2 COUNT_W + 2 SPREAD_W
--              flip-flops) and a COUNT_W-bit zero test.
-- Reset      : synchronous, active high (the divider's control state).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_spread is
  generic (
    COUNT_W  : natural := 14;  -- nt bits
    ST2_W    : natural := 23;  -- st2 bits
    SPREAD_W : natural := 25   -- spread bits, Q(KB + 1).16
  );
  port (
    clk    : in  std_logic;                             -- clock
    rst    : in  std_logic;                             -- synchronous reset
    start  : in  std_logic;                             -- pulse: st2, nt valid (while busy = 0)
    st2    : in  unsigned(ST2_W - 1 downto 0);          -- sum of d2q over the target-coloured pixels
    nt     : in  unsigned(COUNT_W - 1 downto 0);        -- target-coloured pixels
    busy   : out std_logic;                             -- dividing
    done   : out std_logic;                             -- pulse: spread valid
    spread : out unsigned(SPREAD_W - 1 downto 0)        -- floor(st2 2**16 / nt), 0 if nt = 0
  );
end entity;

architecture rtl of ms_spread is
  signal dv_n : unsigned(ST2_W + 15 downto 0);
  signal dv_d : unsigned(COUNT_W - 1 downto 0);
begin
  dv_n <= (others => '0') when nt = 0 else shift_left(resize(st2, ST2_W + 16), 16);
  dv_d <= to_unsigned(1, COUNT_W) when nt = 0 else nt;

  u_div : entity work.ms_divider_iter
    generic map (N_W => ST2_W + 16, D_W => COUNT_W, Q_W => SPREAD_W)
    port map (clk => clk, rst => rst, in_valid => start, in_n => dv_n, in_d => dv_d, busy => busy,
              out_valid => done, out_q => spread);
end architecture;
