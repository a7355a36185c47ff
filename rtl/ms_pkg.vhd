-- ms_pkg: shared helper functions and types of the mstrack core.
-- Number formats are NOT defined here: they come from the Python model
-- (mstrack.fixed.formats) as generics; rtl/ms_formats_pkg.vhd holds the
-- generated defaults.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

package ms_pkg is
  -- ceil(log2(n)), at least 1
  function clog2(n : natural) return natural;
  -- bits to hold 0 .. n
  function bits_for(n : natural) return natural;
  -- log2 of a power of two, 0 for 1 (bank / lane index bits)
  function log2_lanes(n : natural) return natural;
  -- '1' for true
  function to_sl(b : boolean) return std_logic;
  function max(a, b : integer) return integer;
  function min(a, b : integer) return integer;
  -- bits of core v2's target state record (ms_tracker_v2 tgt_state: mstrack.fixed.vhdl_pkg.target_state_layout_v2)
  function v2_state_w(centre_abs_w, size_w, coord_w, share_w, con_w, spread_w : natural) return natural;
  -- stop codes of a mean-shift loop (mstrack.fixed.blocks.STOP_CODES)
  constant STOP_SHIFT    : std_logic_vector(1 downto 0) := "00";
  constant STOP_RHO      : std_logic_vector(1 downto 0) := "01";
  constant STOP_MAX_ITER : std_logic_vector(1 downto 0) := "10";
  constant STOP_LOST     : std_logic_vector(1 downto 0) := "11";
end package;

package body ms_pkg is
  function v2_state_w(centre_abs_w, size_w, coord_w, share_w, con_w, spread_w : natural) return natural is
  begin
    return 3 + 2 * centre_abs_w + 3 * size_w + 2 * coord_w + 3 * share_w + 2 * con_w + spread_w;
  end function;

  function clog2(n : natural) return natural is
    variable r : natural := 0;
    variable v : natural := 1;
  begin
    while v < n loop
      v := v * 2;
      r := r + 1;
    end loop;
    if r = 0 then
      return 1;
    end if;
    return r;
  end function;

  function bits_for(n : natural) return natural is
    variable r : natural := 1;
    variable v : natural := n / 2;
  begin
    while v > 0 loop
      v := v / 2;
      r := r + 1;
    end loop;
    return r;
  end function;

  function log2_lanes(n : natural) return natural is
  begin
    if n <= 1 then
      return 0;
    end if;
    return clog2(n);
  end function;

  function to_sl(b : boolean) return std_logic is
  begin
    if b then
      return '1';
    end if;
    return '0';
  end function;

  function max(a, b : integer) return integer is
  begin
    if a > b then return a; end if;
    return b;
  end function;

  function min(a, b : integer) return integer is
  begin
    if a < b then return a; end if;
    return b;
  end function;
end package body;
