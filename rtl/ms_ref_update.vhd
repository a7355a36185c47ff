-- ms_ref_update: running reference of tracker v2, ref_next = ref_in + ((x - ref_in) >> K_SHIFT) (floor)
-- on unsigned W-bit values.  (The port is ref_in, not ref: `ref` is a SystemVerilog keyword and breaks
-- the GHDL -> Verilog -> Verilator flow, docs/hdl_flow.md.)
--
-- Used for rho_ref and share_ref (unsigned Q1.16, 0 .. 2**16, W = 17) on frames whose state is OK;
-- K_SHIFT = log2(1 / ref_rate) (default 6).  ref_next lies between ref_in and x, so it fits W unsigned
-- bits.  The arithmetic is ms_loss_filter's (same formula) on W + 1 bit two's complement operands.
-- Model: mstrack.fixed.blocks_v2.ms_ref_update(ref, x, k) with k = K_SHIFT, bit for bit (every ref_in, x).
--
-- Latency    : 1 clock: if edge t samples start = 1, edge t + 1 samples done = 1 with ref_next.
-- Throughput : one result per clock (busy is always 0).
-- Handshake  : start qualifies ref_in, x; done is start delayed by one clock; ref_next is registered
--              and held until the next start.
-- Cost       : ms_loss_filter with W + 1 bits (two W + 2 bit adders, W + 2 flip-flops).
-- Reset      : synchronous, active high: done only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_ref_update is
  generic (
    W       : positive := 17;  -- ref_in, x, ref_next bits (unsigned)
    K_SHIFT : natural  := 6    -- k = log2(1 / ref_rate), 0 .. W + 1 (0: ref_next = x)
  );
  port (
    clk      : in  std_logic;                  -- clock
    rst      : in  std_logic;                  -- synchronous reset
    start    : in  std_logic;                  -- ref_in, x valid
    ref_in   : in  unsigned(W - 1 downto 0);   -- reference
    x        : in  unsigned(W - 1 downto 0);   -- this frame's value
    busy     : out std_logic;                  -- always 0 (one result per clock)
    done     : out std_logic;                  -- pulse: ref_next valid (one clock after start)
    ref_next : out unsigned(W - 1 downto 0)    -- ref_in + ((x - ref_in) >> K_SHIFT), floor
  );
end entity;

architecture rtl of ms_ref_update is
  signal rs, xs, y : signed(W downto 0);
begin
  rs <= signed(resize(ref_in, W + 1));
  xs <= signed(resize(x, W + 1));

  u_filt : entity work.ms_loss_filter
    generic map (W => W + 1, K_SHIFT => K_SHIFT)
    port map (clk => clk, rst => rst, start => start, s => rs, x => xs, busy => busy, done => done, s_next => y);

  ref_next <= unsigned(y(W - 1 downto 0));             -- >= 0 and < 2**W: between ref_in and x
end architecture;
