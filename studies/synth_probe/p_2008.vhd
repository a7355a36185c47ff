-- VHDL-2008: process(all), conditional and selected assignments inside processes,
-- generate if/elsif/else and case-generate, ?= operators, reduction operators
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity p_2008 is
  generic (MODE : natural := 1);
  port (clk : in std_logic; s : in std_logic_vector(2 downto 0);
        a, b : in unsigned(7 downto 0);
        y1, y2, y3 : out unsigned(7 downto 0); r : out std_logic; g : out unsigned(7 downto 0));
end entity;

architecture rtl of p_2008 is
begin
  process (all)
  begin
    y1 <= a when s(0) = '1' else b;        -- conditional assignment in a process
    y2 <= a when s = "000" else b when s = "001" else a + b;  -- (sequential `with .. select` is rejected by GHDL 2.0, see p_2008_sel.vhd)
    case s is                                -- (matching case? is mis-synthesised, see p_2008_casem.vhd)
      when "100" | "101" | "110" | "111" => y3 <= a and b;
      when "010" | "011" => y3 <= a or b;
      when others => y3 <= (others => '0');
    end case;
    r <= xor s;                              -- reduction operator
  end process;

  gen : if MODE = 0 generate
    g <= a;
  elsif MODE = 1 generate
    process (clk)
    begin
      if rising_edge(clk) then
        g <= a - b when (s ?= "111") = '1' else a + b;
      end if;
    end process;
  else generate
    g <= b;
  end generate;
end architecture;
