-- unconstrained array ports on a sub-entity (sized by the instance), 2008 array of unsigned
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.p_pkg.all;

entity p_uc_sub is
  port (a : in std_logic_vector; b : in u8_arr; y : out unsigned);
end entity;

architecture rtl of p_uc_sub is
begin
  process (all)
    variable acc : unsigned(y'range);
  begin
    acc := resize(unsigned(a), y'length);
    for k in b'range loop
      acc := acc + b(k);
    end loop;
    y <= acc;
  end process;
end architecture;

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.p_pkg.all;

entity p_unconstrained is
  generic (N : natural := 4);
  port (a : in std_logic_vector(11 downto 0); b : in u8_arr(0 to N - 1);
        c : in u_arr(0 to 1)(5 downto 0); y : out unsigned(15 downto 0); z : out unsigned(5 downto 0));
end entity;

architecture rtl of p_unconstrained is
begin
  u0 : entity work.p_uc_sub port map (a => a, b => b, y => y);
  z <= c(0) + c(1);
end architecture;
