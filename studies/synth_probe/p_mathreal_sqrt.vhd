-- ieee.math_real sqrt in a constant expression
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.math_real.all;

entity p_mathreal_sqrt is
  port (a : in unsigned(7 downto 0); y : out unsigned(16 downto 0));
end entity;

architecture rtl of p_mathreal_sqrt is
  constant SCALE : integer := integer(round(256.0 * sqrt(2.0)));
begin
  y <= a * to_unsigned(SCALE, 9);
end architecture;
