-- VHDL-2008 selected signal assignment inside a process
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity p_2008_sel is
  port (s : in std_logic_vector(2 downto 0); a, b : in unsigned(7 downto 0); y2 : out unsigned(7 downto 0));
end entity;

architecture rtl of p_2008_sel is
begin
  process (all)
  begin
    with s select y2 <= a when "000", b when "001", a + b when others;
  end process;
end architecture;
