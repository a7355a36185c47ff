-- ms_box_clip: clip an integer init box to the frame interior and to the largest window.
--
-- Computes (model: mstrack.fixed.blocks.ms_box_clip and init_centre), per axis with
-- a = box start, n = box size, S = frame size:
--   lo = max(a, 1); hi = min(a + n, S - 1); len = hi - lo
--   len < 3                 -> rejected (also covers boxes entirely outside)
--   len > 2*MAX_HALF + 1    -> lo += (len - (2*MAX_HALF+1)) / 2; len = 2*MAX_HALF + 1
-- and then the half extents e = (len - 1) / 2 and the init centre in Q.CF:
--   c = (2*lo + len - 1) << (CF - 1).
-- Pipeline (at most one carry chain plus selection per clock): 1 lo = max(a, 1),
-- lo + WIN_MAX, a + n, S - 1; 2 len = hi - lo and len - WIN_MAX (both candidates of hi,
-- selected by the compare a + n > S - 1); 3 reject test, shrink (lo += (len - WIN_MAX)/2),
-- len - 1; 4 half extent and centre 2 lo + len - 1.
-- Latency: 4 clocks from in_valid to out_valid.  Throughput: 1 box per clock.
-- Handshake: valid only (no back-pressure); used once per init request.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_box_clip is
  generic (
    COORD_W  : natural := 12;   -- frame coordinate bits (frames < 2**COORD_W px)
    HALF_W   : natural := 6;    -- bits of a half extent (0 .. MAX_HALF)
    MAX_HALF : natural := 63;   -- largest half extent; windows up to 2*MAX_HALF+1 px
    CF       : natural := 8     -- centre fraction bits
  );
  port (
    clk       : in  std_logic;                               -- clock
    rst       : in  std_logic;                               -- synchronous reset (valid only)
    in_valid  : in  std_logic;                               -- box valid
    box_x     : in  signed(COORD_W + 1 downto 0);            -- left column (may be negative)
    box_y     : in  signed(COORD_W + 1 downto 0);            -- top row (may be negative)
    box_w     : in  unsigned(COORD_W downto 0);              -- width  (px)
    box_h     : in  unsigned(COORD_W downto 0);              -- height (px)
    frame_w   : in  unsigned(COORD_W - 1 downto 0);          -- frame width  (px)
    frame_h   : in  unsigned(COORD_W - 1 downto 0);          -- frame height (px)
    out_valid : out std_logic;                               -- result valid (one clock)
    rejected  : out std_logic;                               -- box rejected (< 3 px inside)
    clipped   : out std_logic;                               -- box changed by clipping
    clip_x    : out unsigned(COORD_W - 1 downto 0);          -- clipped left column
    clip_y    : out unsigned(COORD_W - 1 downto 0);          -- clipped top row
    clip_w    : out unsigned(COORD_W - 1 downto 0);          -- clipped width
    clip_h    : out unsigned(COORD_W - 1 downto 0);          -- clipped height
    ex        : out unsigned(HALF_W - 1 downto 0);           -- half extent x = (w-1)/2
    ey        : out unsigned(HALF_W - 1 downto 0);           -- half extent y = (h-1)/2
    cx        : out unsigned(COORD_W + CF - 1 downto 0);     -- init centre x, Q.CF
    cy        : out unsigned(COORD_W + CF - 1 downto 0)      -- init centre y, Q.CF
  );
end entity;

architecture rtl of ms_box_clip is
  constant SW      : natural := COORD_W + 3;                 -- signed working width
  constant WIN_MAX : integer := 2 * MAX_HALF + 1;
  subtype s_t is signed(SW - 1 downto 0);

  -- per axis, stage 1
  type s1_t is record
    lo    : s_t;        -- max(a, 1)
    lo_w  : s_t;        -- lo + WIN_MAX
    hi_a  : s_t;        -- a + n (box end, exclusive)
    hi_b  : s_t;        -- S - 1 (interior end, exclusive)
    a_in  : std_logic;  -- a >= 1 (lo = a)
  end record;
  -- stage 2
  type s2_t is record
    lo    : s_t;
    len   : s_t;        -- min(a + n, S - 1) - lo
    dw    : s_t;        -- len - WIN_MAX
    same  : std_logic;  -- lo = a and hi = a + n
  end record;
  -- stage 3
  type s3_t is record
    lo    : s_t;        -- start after shrinking
    len   : s_t;        -- size after shrinking
    lm1   : s_t;        -- len - 1
    rej   : std_logic;  -- len < 3 (before shrinking)
    shr   : std_logic;  -- shrunk to WIN_MAX
    same  : std_logic;
  end record;

  function stage1(box_a : signed; box_n : unsigned; size : unsigned) return s1_t is
    variable r : s1_t;
    variable a : s_t;
  begin
    a := resize(box_a, SW);
    if a < 1 then
      r.lo := to_signed(1, SW);
      r.lo_w := to_signed(1 + WIN_MAX, SW);
      r.a_in := '0';
    else
      r.lo := a;
      r.lo_w := a + WIN_MAX;
      r.a_in := '1';
    end if;
    r.hi_a := a + signed(resize(box_n, SW));
    r.hi_b := signed(resize(size, SW)) - 1;
    return r;
  end function;

  function stage2(p : s1_t) return s2_t is
    variable r : s2_t;
  begin
    r.lo := p.lo;
    if p.hi_a > p.hi_b then
      r.len := p.hi_b - p.lo;
      r.dw := p.hi_b - p.lo_w;
      r.same := '0';
    else
      r.len := p.hi_a - p.lo;
      r.dw := p.hi_a - p.lo_w;
      r.same := p.a_in;
    end if;
    return r;
  end function;

  function stage3(p : s2_t) return s3_t is
    variable r : s3_t;
  begin
    r.rej := '1' when p.len < 3 else '0';
    r.same := p.same;
    if p.dw > 0 then            -- len > WIN_MAX: shrink about the centre
      r.lo := p.lo + shift_right(p.dw, 1);
      r.len := to_signed(WIN_MAX, SW);
      r.lm1 := to_signed(WIN_MAX - 1, SW);
      r.shr := '1';
    else
      r.lo := p.lo;
      r.len := p.len;
      r.lm1 := p.len - 1;
      r.shr := '0';
    end if;
    return r;
  end function;

  function centre(p : s3_t) return unsigned is
  begin
    return shift_left(resize(unsigned(shift_left(p.lo, 1) + p.lm1), COORD_W + CF), CF - 1);
  end function;

  signal v1, v2, v3 : std_logic := '0';
  signal x1, y1     : s1_t;
  signal x2, y2     : s2_t;
  signal x3, y3     : s3_t;
begin
  p_pipe : process(clk)
  begin
    if rising_edge(clk) then
      -- stage 1: clip the start to the interior
      x1 <= stage1(box_x, box_w, frame_w);
      y1 <= stage1(box_y, box_h, frame_h);
      -- stage 2: clip the end, length
      x2 <= stage2(x1);
      y2 <= stage2(y1);
      -- stage 3: reject / shrink to the largest window
      x3 <= stage3(x2);
      y3 <= stage3(y2);
      -- stage 4: outputs, half extents, centre
      clip_x <= unsigned(x3.lo(COORD_W - 1 downto 0));
      clip_w <= unsigned(x3.len(COORD_W - 1 downto 0));
      ex <= resize(unsigned(shift_right(x3.lm1, 1)), HALF_W);
      cx <= centre(x3);
      clip_y <= unsigned(y3.lo(COORD_W - 1 downto 0));
      clip_h <= unsigned(y3.len(COORD_W - 1 downto 0));
      ey <= resize(unsigned(shift_right(y3.lm1, 1)), HALF_W);
      cy <= centre(y3);
      rejected <= x3.rej or y3.rej;
      clipped <= x3.rej or y3.rej or x3.shr or y3.shr or not x3.same or not y3.same;
      v1 <= in_valid;
      v2 <= v1;
      v3 <= v2;
      out_valid <= v3;
      if rst = '1' then
        v1 <= '0';
        v2 <= '0';
        v3 <= '0';
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
