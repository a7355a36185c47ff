-- ms_ring_share: target share of the window's ring around the box (tracker v2 loss flag),
-- ring_share = floor((nt - nt_in) 2**16 / (K - n_in)) (Q1.16), 0 when K <= n_in.
--
-- The ring is the K - n_in window pixels outside the inner box (flat kernel: K is the window's pixel
-- count); nt - nt_in of them are target-coloured.  Two COUNT_W-bit subtractors in front of one
-- ms_share (its divider's input registers take the differences, so ms_share's quotient register is
-- the output): ms_share(nt_in => nt - nt_in, n_in => K - n_in, or 0 when K <= n_in, which gives 0).
-- Domain: nt >= nt_in (ms_target_stats counts the inner box's target pixels among the window's);
-- nt - nt_in > K - n_in (not reachable) saturates at 2**SHARE_W - 1 exactly as the model's
-- ms_divider((nt - nt_in) << 16, K - n_in, 17) with SHARE_W = 17.
-- Model: mstrack.fixed.blocks_v2.ms_ring_share(st, K) (on a TargetStats), bit for bit.
--
-- Latency    : SHARE_W + 1 clocks (18): if edge s samples start = 1 (busy = 0), edge s + SHARE_W + 1
--              samples done = 1 (tb/test_ms_ring_share.py asserts it).
-- Throughput : one ring share per SHARE_W + 1 clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; ring_share is
--              registered and held until the next start.
-- Cost       : ms_share (one ms_divider_iter) plus a COUNT_W and a COUNT_W + 1 bit subtractor.
-- Reset      : synchronous, active high (the divider's control state).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_ring_share is
  generic (
    COUNT_W : natural := 14;  -- nt, nt_in, n_in, k bits (pixels of the largest window)
    SHARE_W : natural := 17   -- ring_share bits: Q1.16 (0 .. 2**16); the model's divider has 17
  );
  port (
    clk        : in  std_logic;                          -- clock
    rst        : in  std_logic;                          -- synchronous reset
    start      : in  std_logic;                          -- pulse: inputs valid (while busy = 0)
    nt         : in  unsigned(COUNT_W - 1 downto 0);     -- target-coloured pixels of the window
    nt_in      : in  unsigned(COUNT_W - 1 downto 0);     -- target-coloured pixels of the inner box (<= nt)
    n_in       : in  unsigned(COUNT_W - 1 downto 0);     -- pixels of the inner box
    k          : in  unsigned(COUNT_W - 1 downto 0);     -- pixels of the window (K)
    busy       : out std_logic;                          -- dividing
    done       : out std_logic;                          -- pulse: ring_share valid
    ring_share : out unsigned(SHARE_W - 1 downto 0)      -- floor((nt - nt_in) 2**16 / (K - n_in)), 0 if K <= n_in
  );
end entity;

architecture rtl of ms_ring_share is
  signal den  : unsigned(COUNT_W downto 0);              -- K - n_in with its borrow
  signal num  : unsigned(COUNT_W - 1 downto 0);          -- nt - nt_in
  signal den0 : unsigned(COUNT_W - 1 downto 0);          -- K - n_in, 0 when K <= n_in
begin
  num  <= nt - nt_in;
  den  <= resize(k, COUNT_W + 1) - resize(n_in, COUNT_W + 1);
  den0 <= (others => '0') when den(COUNT_W) = '1' else den(COUNT_W - 1 downto 0);

  u_share : entity work.ms_share
    generic map (COUNT_W => COUNT_W, SHARE_W => SHARE_W)
    port map (clk => clk, rst => rst, start => start, nt_in => num, n_in => den0, busy => busy,
              done => done, share => ring_share);
end architecture;
