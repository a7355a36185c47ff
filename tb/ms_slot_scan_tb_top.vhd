-- Test wrapper: ms_slot_scan reading a slot of ms_region_ram (the RAM the slot pool gives each slot),
-- whose write port the bench drives to fill the slot.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_scan_tb_top is
  generic (
    LANES    : natural := 4;      -- as ms_slot_scan
    STRIDE   : natural := 64;
    ADDR_W   : natural := 14;
    DATA_W   : natural := 13;
    REGION_W : natural := 9;
    DEPTH    : positive := 16384; -- slot words per bank (ms_region_ram)
    RD_LAT   : positive := 4      -- ms_region_ram's read latency
  );
  port (
    clk      : in  std_logic;
    rst      : in  std_logic;
    we       : in  std_logic;                                   -- the slot's write port
    wbank    : in  unsigned(clog2(LANES) - 1 downto 0);
    waddr    : in  unsigned(ADDR_W - 1 downto 0);
    wdata    : in  std_logic_vector(DATA_W - 1 downto 0);
    start    : in  std_logic;                                   -- ms_slot_scan
    rect_w   : in  unsigned(REGION_W - 1 downto 0);
    rect_h   : in  unsigned(REGION_W - 1 downto 0);
    busy     : out std_logic;
    px_valid : out std_logic;
    px_x     : out unsigned(REGION_W - 1 downto 0);
    px_y     : out unsigned(REGION_W - 1 downto 0);
    px_data  : out std_logic_vector(DATA_W - 1 downto 0);
    px_last  : out std_logic
  );
end entity;

architecture rtl of ms_slot_scan_tb_top is
  signal raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal rdata : std_logic_vector(LANES * DATA_W - 1 downto 0);
begin
  u_ram : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => DATA_W, ADDR_W => ADDR_W, RD_LAT => RD_LAT,
                 WR_LAT => 0)
    port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wdata, raddr => raddr,
              rdata => rdata);
  u_scan : entity work.ms_slot_scan
    generic map (LANES => LANES, STRIDE => STRIDE, ADDR_W => ADDR_W, DATA_W => DATA_W, REGION_W => REGION_W,
                 RD_LAT => RD_LAT)
    port map (clk => clk, rst => rst, start => start, rect_w => rect_w, rect_h => rect_h, busy => busy,
              raddr => raddr, rdata => rdata, px_valid => px_valid, px_x => px_x, px_y => px_y,
              px_data => px_data, px_last => px_last);
end architecture;
