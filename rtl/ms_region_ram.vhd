-- ms_region_ram: banked search-region RAM (bins of the captured region).
--
-- LANES banks (LANES a power of two), each DEPTH words of DATA_W bits, one
-- simple dual-port block RAM (ms_ram_sdp) per bank, initialised to zero.
-- Write port (shared): we, wbank, waddr, wdata -> bank wbank, word waddr.
-- Read port per bank: raddr(b) -> rdata(b), exactly RD_LAT clocks of latency
-- (1: the RAM's read register only; 3: what ms_ram_sdp's ecp5 architecture
-- needs to use the DP16KD output register and register its depth multiplexer;
-- ms_tracker uses 3; 4: that multiplexer in two registered levels, ms_tracker_v2 uses 4).  A read of an address >= DEPTH keeps the previous data.
-- WR_LAT = 1 registers the write port (on ECP5 after the bank / row decode: the
-- DP16KD write enables, addresses and data come from flip-flops); ms_tracker uses
-- 1.  Reads of a word in the clock it is written are undefined on ECP5 (the
-- tracker reads a region only after its capture has ended).
-- Throughput: 1 write + LANES reads per clock.  No reset (RAM contents only).
-- Python model: the arrays returned by mstrack.fixed.blocks.ms_region_capture,
-- region pixel (rx, ry) at bank rx mod LANES, address ry * STRIDE + rx / LANES.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_region_ram is
  generic (
    LANES  : natural := 2;    -- banks (power of two); one read port each
    DEPTH  : natural := 18336; -- words per bank (REGION_MAX * STRIDE = 191 * 96 by default)
    DATA_W : natural := 9;    -- word width (bin index)
    ADDR_W : natural := 15;   -- address width, 2**ADDR_W >= DEPTH
    RD_LAT : positive := 1;   -- read latency in clocks (each clock above 1 costs LANES * DATA_W FF)
    WR_LAT : natural  := 0    -- 0 or 1: a write reaches the RAM WR_LAT clocks after the port (1: registered)
  );
  port (
    clk   : in  std_logic;                                      -- clock
    we    : in  std_logic;                                      -- write enable
    wbank : in  unsigned(clog2(LANES) - 1 downto 0);            -- bank to write (ignored when LANES = 1)
    waddr : in  unsigned(ADDR_W - 1 downto 0);                  -- word to write
    wdata : in  std_logic_vector(DATA_W - 1 downto 0);          -- data to write
    raddr : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);  -- read address of bank b at (b+1)*ADDR_W-1 downto b*ADDR_W
    rdata : out std_logic_vector(LANES * DATA_W - 1 downto 0)   -- read data of bank b, RD_LAT clocks after raddr
  );
end entity;

architecture rtl of ms_region_ram is
begin
  assert LANES >= 1 and 2 ** clog2(LANES) = LANES or LANES = 1
    report "ms_region_ram: LANES must be a power of two" severity failure;
  assert 2 ** ADDR_W >= DEPTH report "ms_region_ram: ADDR_W too small for DEPTH" severity failure;

  g_bank : for b in 0 to LANES - 1 generate
    signal bank_we : std_logic;
  begin
    bank_we <= we when LANES = 1 or wbank = to_unsigned(b, wbank'length) else '0';

    u_bank : entity work.ms_ram_sdp
      generic map (DEPTH => DEPTH, DATA_W => DATA_W, ADDR_W => ADDR_W, RD_LAT => RD_LAT, WR_LAT => WR_LAT)
      port map (clk => clk, we => bank_we, waddr => waddr, wdata => wdata,
                raddr => unsigned(raddr((b + 1) * ADDR_W - 1 downto b * ADDR_W)),
                rdata => rdata((b + 1) * DATA_W - 1 downto b * DATA_W));
  end generate;
end architecture;
