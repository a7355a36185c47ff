-- ieee.math_real in constant expressions (log2/ceil/round) and an assert
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.math_real.all;

entity p_mathreal is
  generic (DEPTH : positive := 600);
  port (clk : in std_logic; a : in unsigned(natural(ceil(log2(real(DEPTH)))) - 1 downto 0);
        y : out unsigned(natural(ceil(log2(real(DEPTH)))) - 1 downto 0));
end entity;

architecture rtl of p_mathreal is
  constant AW : natural := natural(ceil(log2(real(DEPTH))));
  constant SCALE : integer := integer(round(256.0 * 1.41421356));
begin
  assert AW = 10 report "AW wrong" severity failure;
  process (clk)
  begin
    if rising_edge(clk) then
      y <= resize(a * to_unsigned(SCALE, 9) / 256, AW);
    end if;
  end process;
end architecture;
