-- ieee.fixed_pkg (sfixed/ufixed) arithmetic
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.fixed_pkg.all;

entity p_fixed is
  port (clk : in std_logic; a : in sfixed(3 downto -8); b : in ufixed(1 downto -10);
        y : out sfixed(6 downto -18); z : out sfixed(3 downto -8));
end entity;

architecture rtl of p_fixed is
begin
  process (clk)
  begin
    if rising_edge(clk) then
      y <= a * to_sfixed(b);
      z <= resize(a * a, 3, -8);
    end if;
  end process;
end architecture;
