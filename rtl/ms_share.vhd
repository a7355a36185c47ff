-- ms_share: target share of the inner box, share = floor(nt_in 2**16 / n_in) (Q.16), 0 when n_in = 0.
--
-- One ms_divider_iter (N_W = COUNT_W + 16, D_W = COUNT_W, Q_W = SHARE_W).  n_in = 0 divides 0 by 1
-- (the operands are chosen in front of the divider's input registers), so the quotient register is
-- the output.  With SHARE_W = 17 the quotient saturates at 2**17 - 1 exactly as the model's
-- ms_divider(nt_in << 16, n_in, 17) (never reached by ms_target_stats: nt_in <= n_in, share <= 2**16).
-- Model: mstrack.fixed.blocks_v2.ms_share (on a TargetStats).
--
-- Latency    : SHARE_W + 1 clocks: if edge s samples start = 1 (busy = 0), edge s + SHARE_W + 1
--              samples done = 1 (tb/test_ms_share.py asserts it).
-- Throughput : one share per SHARE_W + 1 clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; share is registered
--              and held until the next start.
-- Cost       : one ms_divider_iter (a COUNT_W + 2 bit subtractor, ~2 COUNT_W + 2 SHARE_W flip-flops)
--              and a COUNT_W-bit zero test.
-- Reset      : synchronous, active high (the divider's control state).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_share is
  generic (
    COUNT_W : natural := 14;  -- nt_in, n_in bits (pixels of the largest window)
    SHARE_W : natural := 17   -- share bits: Q1.16 (0 .. 2**16); the model's divider has 17
  );
  port (
    clk   : in  std_logic;                              -- clock
    rst   : in  std_logic;                              -- synchronous reset
    start : in  std_logic;                              -- pulse: nt_in, n_in valid (while busy = 0)
    nt_in : in  unsigned(COUNT_W - 1 downto 0);         -- target-coloured pixels of the inner box
    n_in  : in  unsigned(COUNT_W - 1 downto 0);         -- pixels of the inner box
    busy  : out std_logic;                              -- dividing
    done  : out std_logic;                              -- pulse: share valid
    share : out unsigned(SHARE_W - 1 downto 0)          -- floor(nt_in 2**16 / n_in), 0 if n_in = 0
  );
end entity;

architecture rtl of ms_share is
  signal dv_n : unsigned(COUNT_W + 15 downto 0);
  signal dv_d : unsigned(COUNT_W - 1 downto 0);
begin
  dv_n <= (others => '0') when n_in = 0 else shift_left(resize(nt_in, COUNT_W + 16), 16);
  dv_d <= to_unsigned(1, COUNT_W) when n_in = 0 else n_in;

  u_div : entity work.ms_divider_iter
    generic map (N_W => COUNT_W + 16, D_W => COUNT_W, Q_W => SHARE_W)
    port map (clk => clk, rst => rst, in_valid => start, in_n => dv_n, in_d => dv_d, busy => busy,
              out_valid => done, out_q => share);
end architecture;
