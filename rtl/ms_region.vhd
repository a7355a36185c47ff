-- ms_region: search-region geometry around a centre (model: mstrack.fixed.blocks.ms_region).
--
-- Per axis, with c the window position round(centre) = (centre + 2**(CF-1)) >> CF,
-- e the half extent and S the frame size:
--   n     = min(2e + 2*MARGIN + 1, S - 2)
--   start = min(max(c - e - MARGIN, 1), S - 1 - n)
-- The region is columns start .. start + n - 1 (inside the frame interior).  It also
-- gives the region-relative limits of the window centre: lo = e, hi = n - 1 - e.
-- Timing: stage 1 computes, per axis, the unclamped start round(c) - (e + MARGIN),
-- t = S - 1 - (2e + 2*MARGIN + 1) (the upper start limit when the region is not cut
-- by the frame) and both candidates of n and hi; stage 2 only compares (t < 1: n = S - 2
-- and start = 1; else start = min(max(start, 1), t)) and selects: at most two carry
-- chains in a clock.
-- Latency: 2 clocks from in_valid to out_valid.  Throughput: 1 per clock.
-- Handshake: valid only; used once per frame.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_region is
  generic (
    COORD_W  : natural := 12;   -- frame coordinate bits
    HALF_W   : natural := 6;    -- half extent bits
    REGION_W : natural := 8;    -- bits of a region size / region-relative coordinate
    MARGIN   : natural := 32;   -- search margin (px) on each side of the window box
    CF       : natural := 8     -- centre fraction bits
  );
  port (
    clk       : in  std_logic;                           -- clock
    rst       : in  std_logic;                           -- synchronous reset (valid only)
    in_valid  : in  std_logic;                           -- inputs valid
    cx        : in  unsigned(COORD_W + CF - 1 downto 0); -- centre x, Q.CF (absolute)
    cy        : in  unsigned(COORD_W + CF - 1 downto 0); -- centre y, Q.CF (absolute)
    ex        : in  unsigned(HALF_W - 1 downto 0);       -- window half extent x
    ey        : in  unsigned(HALF_W - 1 downto 0);       -- window half extent y
    frame_w   : in  unsigned(COORD_W - 1 downto 0);      -- frame width
    frame_h   : in  unsigned(COORD_W - 1 downto 0);      -- frame height
    out_valid : out std_logic;                           -- outputs valid (one clock, then held)
    reg_x     : out unsigned(COORD_W - 1 downto 0);      -- region left column (absolute)
    reg_y     : out unsigned(COORD_W - 1 downto 0);      -- region top row (absolute)
    reg_w     : out unsigned(REGION_W - 1 downto 0);     -- region width
    reg_h     : out unsigned(REGION_W - 1 downto 0);     -- region height
    hi_x      : out unsigned(REGION_W - 1 downto 0);     -- largest window centre x, region-relative
    hi_y      : out unsigned(REGION_W - 1 downto 0)      -- largest window centre y, region-relative
  );
end entity;

architecture rtl of ms_region is
  constant SW : natural := COORD_W + 3;
  subtype s_t is signed(SW - 1 downto 0);
  type axis_t is record
    st   : s_t;  -- round(c) - e - MARGIN (unclamped start)
    t    : s_t;  -- S - 1 - (2e + 2 MARGIN + 1): start limit if the box + margins fit
    n_a  : s_t;  -- 2e + 2 MARGIN + 1 (n if it fits)
    n_b  : s_t;  -- S - 2 (n otherwise)
    hi_a : s_t;  -- e + 2 MARGIN (= n_a - 1 - e)
    hi_b : s_t;  -- S - 3 - e (= n_b - 1 - e)
  end record;
  signal v1   : std_logic := '0';
  signal ax, ay : axis_t;

  function round_pos(c : unsigned) return s_t is
  begin
    return resize(signed('0' & shift_right(c + to_unsigned(2 ** (CF - 1), c'length), CF)), SW);
  end function;

  -- stage 1 of one axis
  function prepare(c : unsigned; ev : unsigned; sv : unsigned) return axis_t is
    variable a    : axis_t;
    variable e, s : s_t;
  begin
    e := signed(resize(ev, SW));
    s := signed(resize(sv, SW));
    a.st   := round_pos(c) - (e + MARGIN);
    a.t    := (s - (2 * MARGIN + 2)) - shift_left(e, 1);
    a.n_a  := shift_left(e, 1) + (2 * MARGIN + 1);
    a.n_b  := s - 2;
    a.hi_a := e + 2 * MARGIN;
    a.hi_b := (s - 3) - e;
    return a;
  end function;

  -- stage 2 of one axis: clamped start, n, hi
  type res_t is record
    st, n, hi : s_t;
  end record;
  function finish(a : axis_t) return res_t is
    variable r : res_t;
  begin
    if a.t < 1 then             -- region cut to the frame interior: n = S - 2, start = 1
      r.st := to_signed(1, SW);
      r.n  := a.n_b;
      r.hi := a.hi_b;
    else
      if a.st > a.t then
        r.st := a.t;
      elsif a.st < 1 then
        r.st := to_signed(1, SW);
      else
        r.st := a.st;
      end if;
      r.n  := a.n_a;
      r.hi := a.hi_a;
    end if;
    return r;
  end function;
begin
  -- stage 1: unclamped start, start limit, candidates of n and hi
  p_size : process(clk)
  begin
    if rising_edge(clk) then
      ax <= prepare(cx, ex, frame_w);
      ay <= prepare(cy, ey, frame_h);
      v1 <= in_valid;
      if rst = '1' then
        v1 <= '0';
      end if;
    end if;
  end process;

  -- stage 2: clamp the start into the interior, select n and the window centre limit
  p_clamp : process(clk)
    variable rx, ry : res_t;
  begin
    if rising_edge(clk) then
      rx := finish(ax);
      ry := finish(ay);
      reg_x <= unsigned(rx.st(COORD_W - 1 downto 0));
      reg_w <= unsigned(rx.n(REGION_W - 1 downto 0));
      hi_x  <= unsigned(resize(rx.hi, REGION_W));
      reg_y <= unsigned(ry.st(COORD_W - 1 downto 0));
      reg_h <= unsigned(ry.n(REGION_W - 1 downto 0));
      hi_y  <= unsigned(resize(ry.hi, REGION_W));
      out_valid <= v1;
      if rst = '1' then
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
