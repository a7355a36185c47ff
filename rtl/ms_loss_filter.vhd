-- ms_loss_filter: one step of the loss flag's smoothing, s_next = s + ((x - s) >> K_SHIFT), where >> is
-- an arithmetic shift (floor), on W-bit two's complement values.
--
-- Tracker v2 runs it twice per frame: on rho (unsigned Q1.16, 0 .. 2**16) and on the contrast
-- share - ring_share (signed Q1.16, -2**16 .. 2**16); K_SHIFT = log2(1 / loss_smooth) (default 1).
-- s_next lies between s and x, so it keeps their range: W = 18 holds both.  The difference has W + 1
-- bits; the floor shift is a slice diff(W downto K_SHIFT), sign-extended (not shift_right of a
-- signed: GHDL 2.0 writes that as a logical Verilog shift, docs/hdl_flow.md).  ms_ref_update is the
-- same arithmetic on unsigned values (it instantiates this entity).
-- Model: mstrack.fixed.blocks_v2.ms_loss_filter(s, x, k) with k = K_SHIFT, bit for bit (every s, x).
--
-- Latency    : 1 clock: if edge t samples start = 1, edge t + 1 samples done = 1 with s_next.
-- Throughput : one result per clock (busy is always 0).
-- Handshake  : start qualifies s, x; done is start delayed by one clock; s_next is registered and
--              held until the next start.
-- Cost       : two W + 1 bit adders, W + 1 flip-flops.
-- Reset      : synchronous, active high: done only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_loss_filter is
  generic (
    W       : positive := 18;  -- s, x, s_next bits (two's complement)
    K_SHIFT : natural  := 1    -- k = log2(1 / smoothing), 0 .. W (0: s_next = x)
  );
  port (
    clk    : in  std_logic;                  -- clock
    rst    : in  std_logic;                  -- synchronous reset
    start  : in  std_logic;                  -- s, x valid
    s      : in  signed(W - 1 downto 0);     -- filter state
    x      : in  signed(W - 1 downto 0);     -- new value
    busy   : out std_logic;                  -- always 0 (one result per clock)
    done   : out std_logic;                  -- pulse: s_next valid (one clock after start)
    s_next : out signed(W - 1 downto 0)      -- s + ((x - s) >> K_SHIFT), floor
  );
end entity;

architecture rtl of ms_loss_filter is
  signal y_r    : signed(W - 1 downto 0) := (others => '0');
  signal done_r : std_logic := '0';
begin
  assert K_SHIFT <= W report "ms_loss_filter: K_SHIFT must be <= W" severity failure;

  p_step : process (clk)
    variable diff, step, y : signed(W downto 0);
  begin
    if rising_edge(clk) then
      diff := resize(x, W + 1) - resize(s, W + 1);
      step := resize(diff(W downto K_SHIFT), W + 1);     -- floor(diff / 2**K_SHIFT)
      y    := resize(s, W + 1) + step;                   -- between s and x: fits W bits
      if start = '1' then
        y_r <= y(W - 1 downto 0);
      end if;
      done_r <= start;
      if rst = '1' then
        done_r <= '0';
      end if;
    end if;
  end process;

  busy   <= '0';
  done   <= done_r;
  s_next <= y_r;
end architecture;
