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
  -- result word v2 (mstrack.fixed.vhdl_pkg.result_layout_v2), from bit 0: cx, cy (centre_abs_w each),
  -- w8, h8 (size_w each), rho (rho_w), confidence 17, status 3, iter (iter_w), stop 2, decim_log2 3,
  -- searched 4, flags 8, err_code 3, frame_count 16; result_w bits (the rest 0)
  function v2_word(result_w, centre_abs_w, size_w, rho_w, iter_w : natural;
                   cx, cy, bw, bh, rh, cn, st, it : unsigned; sp : std_logic_vector; dl, srch : unsigned;
                   flags, err : std_logic_vector; fc : unsigned) return std_logic_vector;
  -- result word v2's flags: 0 init, 1 clipped, 2 lost, 3 error, 4 rejected, 5 no_target, 6 overflow
  function v2_flags(init, clipped, lost, err, rej, notgt, ovf : std_logic) return std_logic_vector;
  -- stop codes of a mean-shift loop (mstrack.fixed.blocks.STOP_CODES)
  constant STOP_SHIFT    : std_logic_vector(1 downto 0) := "00";
  constant STOP_RHO      : std_logic_vector(1 downto 0) := "01";
  constant STOP_MAX_ITER : std_logic_vector(1 downto 0) := "10";
  constant STOP_LOST     : std_logic_vector(1 downto 0) := "11";
end package;

package body ms_pkg is
  function v2_word(result_w, centre_abs_w, size_w, rho_w, iter_w : natural;
                   cx, cy, bw, bh, rh, cn, st, it : unsigned; sp : std_logic_vector; dl, srch : unsigned;
                   flags, err : std_logic_vector; fc : unsigned) return std_logic_vector is
    variable v : std_logic_vector(result_w - 1 downto 0) := (others => '0');
    variable o : natural := 0;
  begin
    v(o + centre_abs_w - 1 downto o) := std_logic_vector(resize(cx, centre_abs_w)); o := o + centre_abs_w;
    v(o + centre_abs_w - 1 downto o) := std_logic_vector(resize(cy, centre_abs_w)); o := o + centre_abs_w;
    v(o + size_w - 1 downto o) := std_logic_vector(resize(bw, size_w)); o := o + size_w;
    v(o + size_w - 1 downto o) := std_logic_vector(resize(bh, size_w)); o := o + size_w;
    v(o + rho_w - 1 downto o) := std_logic_vector(resize(rh, rho_w)); o := o + rho_w;
    v(o + 16 downto o) := std_logic_vector(resize(cn, 17)); o := o + 17;
    v(o + 2 downto o) := std_logic_vector(resize(st, 3)); o := o + 3;
    v(o + iter_w - 1 downto o) := std_logic_vector(resize(it, iter_w)); o := o + iter_w;
    v(o + 1 downto o) := sp; o := o + 2;
    v(o + 2 downto o) := std_logic_vector(resize(dl, 3)); o := o + 3;
    v(o + 3 downto o) := std_logic_vector(resize(srch, 4)); o := o + 4;
    v(o + 7 downto o) := flags; o := o + 8;
    v(o + 2 downto o) := err; o := o + 3;
    v(o + 15 downto o) := std_logic_vector(resize(fc, 16));
    return v;
  end function;

  function v2_flags(init, clipped, lost, err, rej, notgt, ovf : std_logic) return std_logic_vector is
    -- bit by bit, not a concatenation: GHDL's synthesis cannot fold a concatenation of constant bits
    variable f : std_logic_vector(7 downto 0) := (others => '0');
  begin
    f(0) := init; f(1) := clipped; f(2) := lost; f(3) := err; f(4) := rej; f(5) := notgt; f(6) := ovf;
    return f;
  end function;

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
