-- records in ports (input and output), record field access
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.p_pkg.all;

entity p_record_port is
  port (clk : in std_logic; i : in pix_rec; o : out pix_rec);
end entity;

architecture rtl of p_record_port is
begin
  process (clk)
  begin
    if rising_edge(clk) then
      o       <= i;
      o.data  <= i.data + 1;
      o.xy    <= i.xy / 2;
    end if;
  end process;
end architecture;
