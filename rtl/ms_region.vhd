-- ms_region: search-region geometry around a centre (model: mstrack.fixed.blocks.ms_region).
--
-- Per axis, with c the window position round(centre) = (centre + 2**(CF-1)) >> CF,
-- e the half extent and S the frame size:
--   n     = min(2e + 2*MARGIN + 1, S - 2)
--   start = min(max(c - e - MARGIN, 1), S - 1 - n)
-- The region is columns start .. start + n - 1 (inside the frame interior).  It also
-- gives the region-relative limits of the window centre: lo = e, hi = n - 1 - e.
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
  signal v1           : std_logic := '0';
  signal n_x, n_y     : s_t;
  signal st_x, st_y   : s_t;
  signal ex1, ey1     : s_t;
  signal smax_x, smax_y : s_t;

  function round_pos(c : unsigned) return s_t is
  begin
    return resize(signed('0' & shift_right(c + to_unsigned(2 ** (CF - 1), c'length), CF)), SW);
  end function;
begin
  -- stage 1: region size and the unclamped start
  p_size : process(clk)
    variable e, n, s : s_t;
  begin
    if rising_edge(clk) then
      e := signed(resize(ex, SW));
      s := signed(resize(frame_w, SW));
      n := shift_left(e, 1) + (2 * MARGIN + 1);
      if n > s - 2 then n := s - 2; end if;
      n_x <= n;
      st_x <= round_pos(cx) - e - MARGIN;
      smax_x <= s - 1 - n;
      ex1 <= e;
      e := signed(resize(ey, SW));
      s := signed(resize(frame_h, SW));
      n := shift_left(e, 1) + (2 * MARGIN + 1);
      if n > s - 2 then n := s - 2; end if;
      n_y <= n;
      st_y <= round_pos(cy) - e - MARGIN;
      smax_y <= s - 1 - n;
      ey1 <= e;
      v1 <= in_valid;
      if rst = '1' then
        v1 <= '0';
      end if;
    end if;
  end process;

  -- stage 2: clamp the start into the interior, limits of the window centre
  p_clamp : process(clk)
    variable st : s_t;
  begin
    if rising_edge(clk) then
      st := st_x;
      if st < 1 then st := to_signed(1, SW); end if;
      if st > smax_x then st := smax_x; end if;
      reg_x <= unsigned(st(COORD_W - 1 downto 0));
      reg_w <= unsigned(n_x(REGION_W - 1 downto 0));
      hi_x <= unsigned(resize(n_x - 1 - ex1, REGION_W));
      st := st_y;
      if st < 1 then st := to_signed(1, SW); end if;
      if st > smax_y then st := smax_y; end if;
      reg_y <= unsigned(st(COORD_W - 1 downto 0));
      reg_h <= unsigned(n_y(REGION_W - 1 downto 0));
      hi_y <= unsigned(resize(n_y - 1 - ey1, REGION_W));
      out_valid <= v1;
      if rst = '1' then
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
