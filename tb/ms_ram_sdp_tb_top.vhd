-- Test wrapper: ms_ram_sdp with its architecture chosen explicitly (ARCH_ECP5 = 1: `ecp5` on the
-- DP16KD model of tb/vhdl/dp16kd_sim.vhd; 0: `inferred`), so that the test does not depend on
-- which architecture GHDL's incremental analysis saw last.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_ram_sdp_tb_top is
  generic (
    DEPTH     : positive := 1024;  -- as ms_ram_sdp
    DATA_W    : positive := 9;     -- as ms_ram_sdp
    ADDR_W    : positive := 10;    -- as ms_ram_sdp
    RD_LAT    : positive := 1;     -- as ms_ram_sdp
    WR_LAT    : natural  := 0;     -- as ms_ram_sdp
    ARCH_ECP5 : natural  := 0      -- 1: architecture ecp5, 0: inferred
  );
  port (
    clk   : in  std_logic;                              -- clock
    we    : in  std_logic;                              -- write enable
    waddr : in  unsigned(ADDR_W - 1 downto 0);          -- write address
    wdata : in  std_logic_vector(DATA_W - 1 downto 0);  -- write data
    raddr : in  unsigned(ADDR_W - 1 downto 0);          -- read address
    rdata : out std_logic_vector(DATA_W - 1 downto 0)   -- read data
  );
end entity;

architecture tb of ms_ram_sdp_tb_top is
begin
  g_ecp5 : if ARCH_ECP5 = 1 generate
    u_ram : entity work.ms_ram_sdp(ecp5)
      generic map (DEPTH => DEPTH, DATA_W => DATA_W, ADDR_W => ADDR_W, RD_LAT => RD_LAT, WR_LAT => WR_LAT)
      port map (clk => clk, we => we, waddr => waddr, wdata => wdata, raddr => raddr, rdata => rdata);
  end generate;
  g_inferred : if ARCH_ECP5 = 0 generate
    u_ram : entity work.ms_ram_sdp(inferred)
      generic map (DEPTH => DEPTH, DATA_W => DATA_W, ADDR_W => ADDR_W, RD_LAT => RD_LAT, WR_LAT => WR_LAT)
      port map (clk => clk, we => we, waddr => waddr, wdata => wdata, raddr => raddr, rdata => rdata);
  end generate;
end architecture;
