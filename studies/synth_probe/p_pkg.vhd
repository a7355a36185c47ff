-- shared package for the GHDL --synth construct probes (studies/synth_probe)
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

package p_pkg is
  type pix_rec is record
    data  : unsigned(7 downto 0);
    valid : std_logic;
    xy    : integer range 0 to 1023;
  end record;
  type u8_arr is array (natural range <>) of unsigned(7 downto 0);
  type u_arr is array (natural range <>) of unsigned;  -- VHDL-2008 fully unconstrained
  function clog2(n : positive) return natural;
  function sat_add(a, b : unsigned) return unsigned;
  function kernel_rom(n : positive) return u8_arr;
end package;

package body p_pkg is
  function clog2(n : positive) return natural is
    variable r : natural := 0;
  begin
    while 2 ** r < n loop
      r := r + 1;
    end loop;
    return r;
  end function;

  function sat_add(a, b : unsigned) return unsigned is
    variable s : unsigned(a'length downto 0);
  begin
    s := resize(a, a'length + 1) + resize(b, a'length + 1);
    if s(s'high) = '1' then
      return (a'length - 1 downto 0 => '1');
    end if;
    return s(a'length - 1 downto 0);
  end function;

  function kernel_rom(n : positive) return u8_arr is
    variable r : u8_arr(0 to n - 1);
  begin
    for i in 0 to n - 1 loop
      r(i) := to_unsigned(255 - (255 * i * i) / (n * n), 8);  -- Epanechnikov-like profile
    end loop;
    return r;
  end function;
end package body;
