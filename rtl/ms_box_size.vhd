-- ms_box_size: box diameter of tracker v2 along one axis, in decimated px (init model box).
--
-- Computes (model: mstrack.fixed.blocks_v2.ms_box_size(s8, D, limit))
--   n = round(s / D) = (s8 + 2**(7 + log2 D)) >> (8 + log2 D)  (half up), n = max(3, min(n, limit))
-- with s8 the target size in Q.8 px; limit = the decimated frame size - 2 (tracker_v2.init).
-- This is ms_window_size with PAD16 = 0 ((16 s8 + 2**(11 + k)) >> (12 + k) is the same value):
-- the x16 is wiring, so the multiply stage is a plain register.
-- Latency: 3 clocks from in_valid to out_valid.  Throughput: 1 per clock.
-- Handshake: valid only (no back-pressure); used at init.
-- Cost: a barrel shifter, one incrementer, two compares; about 2 S8_W + 2 N_W FF
-- (docs/blocks/ms_box_size.md: 56 LUT4, 69 FF, 27 CCU2C for the defaults).
-- Reset: synchronous, active high; valid flags only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_box_size is
  generic (
    S8_W       : natural range 9 to 30 := 20;  -- width of s8 (Q(COORD_W).8: COORD_W + 8)
    N_W        : natural range 2 to 16 := 12   -- width of limit and n (COORD_W: decimated frame - 2)
  );
  port (
    clk       : in  std_logic;                          -- clock
    rst       : in  std_logic;                          -- synchronous reset (valid flags only)
    in_valid  : in  std_logic;                          -- inputs valid
    s8        : in  unsigned(S8_W - 1 downto 0);        -- target size along this axis, Q.8 px
    log2_d    : in  unsigned(2 downto 0);               -- log2 D, 0 .. 7 (v2 init: 0 .. 3)
    limit     : in  unsigned(N_W - 1 downto 0);         -- largest n (values below 3 give 3)
    out_valid : out std_logic;                          -- n valid (in_valid delayed 3 clocks)
    n         : out unsigned(N_W - 1 downto 0)          -- diameter in decimated px, 3 .. max(3, limit)
  );
end entity;

architecture rtl of ms_box_size is
begin
  u_size : entity work.ms_window_size
    generic map (S8_W => S8_W, PAD16 => 0, N_W => N_W)
    port map (clk => clk, rst => rst, in_valid => in_valid, s8 => s8, log2_d => log2_d, limit => limit,
              out_valid => out_valid, n => n);
end architecture;
