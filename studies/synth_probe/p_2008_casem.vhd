-- VHDL-2008 matching case statement (case?) with don't-care choices
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity p_2008_casem is
  port (s : in std_logic_vector(2 downto 0); a, b : in unsigned(7 downto 0); y3 : out unsigned(7 downto 0));
end entity;

architecture rtl of p_2008_casem is
begin
  process (all)
  begin
    case? s is
      when "1--"  => y3 <= a and b;
      when "01-"  => y3 <= a or b;
      when others => y3 <= (others => '0');
    end case?;
  end process;
end architecture;
