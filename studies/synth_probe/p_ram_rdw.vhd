-- inferred RAMs: simple dual port read-first (signal), write-first (variable),
-- and a ROM initialised by a package function (constant array)
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.p_pkg.all;

entity p_ram_rdw is
  generic (AW : natural := 10; DW : natural := 16);
  port (clk : in std_logic; we : in std_logic;
        wa, ra : in unsigned(AW - 1 downto 0); d : in std_logic_vector(DW - 1 downto 0);
        q_rf : out std_logic_vector(DW - 1 downto 0);
        q_wf : out std_logic_vector(DW - 1 downto 0);
        q_rom : out unsigned(7 downto 0));
end entity;

architecture rtl of p_ram_rdw is
  type ram_t is array (0 to 2 ** AW - 1) of std_logic_vector(DW - 1 downto 0);
  signal ram1 : ram_t;
  constant ROM : u8_arr(0 to 2 ** AW - 1) := kernel_rom(2 ** AW);
begin
  -- read-first, same address port (read old data on write)
  process (clk)
  begin
    if rising_edge(clk) then
      if we = '1' then
        ram1(to_integer(wa)) <= d;
      end if;
      q_rf <= ram1(to_integer(wa));
    end if;
  end process;

  -- write-first (new data) with a shared variable-free idiom: variable RAM
  process (clk)
    variable ram2 : ram_t;
  begin
    if rising_edge(clk) then
      if we = '1' then
        ram2(to_integer(wa)) := d;
      end if;
      q_wf <= ram2(to_integer(ra));
    end if;
  end process;

  process (clk)
  begin
    if rising_edge(clk) then
      q_rom <= ROM(to_integer(ra));
    end if;
  end process;
end architecture;
