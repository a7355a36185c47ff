-- unconstrained port on the TOP entity (no instance to size it)
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity p_unconstrained_top is
  port (a : in std_logic_vector; y : out std_logic_vector);
end entity;

architecture rtl of p_unconstrained_top is
begin
  y <= not a;
end architecture;
