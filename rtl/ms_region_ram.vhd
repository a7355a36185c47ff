-- ms_region_ram: banked search-region RAM (bins of the captured region).
--
-- LANES banks (LANES a power of two), each DEPTH words of DATA_W bits, one
-- inferred simple dual-port block RAM per bank, initialised to zero.
-- Write port (shared): we, wbank, waddr, wdata -> bank wbank, word waddr.
-- Read port per bank: raddr(b) -> rdata(b) registered, exactly 1 clock of
-- latency; a read of the address written in the same clock returns the OLD
-- word (read-before-write).
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
    ADDR_W : natural := 15    -- address width, 2**ADDR_W >= DEPTH
  );
  port (
    clk   : in  std_logic;                                      -- clock
    we    : in  std_logic;                                      -- write enable
    wbank : in  unsigned(clog2(LANES) - 1 downto 0);            -- bank to write (ignored when LANES = 1)
    waddr : in  unsigned(ADDR_W - 1 downto 0);                  -- word to write
    wdata : in  std_logic_vector(DATA_W - 1 downto 0);          -- data to write
    raddr : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);  -- read address of bank b at (b+1)*ADDR_W-1 downto b*ADDR_W
    rdata : out std_logic_vector(LANES * DATA_W - 1 downto 0)   -- read data of bank b, 1 clock after raddr
  );
end entity;

architecture rtl of ms_region_ram is
begin
  assert LANES >= 1 and 2 ** clog2(LANES) = LANES or LANES = 1
    report "ms_region_ram: LANES must be a power of two" severity failure;
  assert 2 ** ADDR_W >= DEPTH report "ms_region_ram: ADDR_W too small for DEPTH" severity failure;

  g_bank : for b in 0 to LANES - 1 generate
    type ram_t is array (0 to DEPTH - 1) of std_logic_vector(DATA_W - 1 downto 0);
    signal ram : ram_t := (others => (others => '0'));
    signal bank_we : std_logic;
  begin
    bank_we <= we when LANES = 1 or wbank = to_unsigned(b, wbank'length) else '0';

    p_bank : process (clk)
    begin
      if rising_edge(clk) then
        -- out-of-range addresses (>= DEPTH) read nothing (the register keeps its value)
        if unsigned(raddr((b + 1) * ADDR_W - 1 downto b * ADDR_W)) < DEPTH then
          rdata((b + 1) * DATA_W - 1 downto b * DATA_W) <=
            ram(to_integer(unsigned(raddr((b + 1) * ADDR_W - 1 downto b * ADDR_W))));
        end if;
        if bank_we = '1' and waddr < DEPTH then
          ram(to_integer(waddr)) <= wdata;
        end if;
      end if;
    end process;
  end generate;
end architecture;
