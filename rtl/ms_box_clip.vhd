-- ms_box_clip: clip an integer init box to the frame interior and to the largest window.
--
-- Computes (model: mstrack.fixed.blocks.ms_box_clip and init_centre), per axis with
-- a = box start, n = box size, S = frame size:
--   lo = max(a, 1); hi = min(a + n, S - 1); len = hi - lo
--   len < 3                 -> rejected (also covers boxes entirely outside)
--   len > 2*MAX_HALF + 1    -> lo += (len - (2*MAX_HALF+1)) / 2; len = 2*MAX_HALF + 1
-- and then the half extents e = (len - 1) / 2 and the init centre in Q.CF:
--   c = (2*lo + len - 1) << (CF - 1).
-- Latency: 2 clocks from in_valid to out_valid.  Throughput: 1 box per clock.
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

  signal v1              : std_logic := '0';
  signal lo_x, lo_y      : s_t;
  signal len_x, len_y    : s_t;
  signal same_x, same_y  : std_logic;
begin
  -- stage 1: clip to the interior
  p_clip : process(clk)
    variable a, n, s, lo, hi : s_t;
  begin
    if rising_edge(clk) then
      -- x axis
      a := resize(box_x, SW);
      n := signed(resize(box_w, SW));
      s := signed(resize(frame_w, SW));
      lo := a;
      if lo < 1 then lo := to_signed(1, SW); end if;
      hi := a + n;
      if hi > s - 1 then hi := s - 1; end if;
      lo_x <= lo;
      len_x <= hi - lo;
      same_x <= '1' when lo = a and hi = a + n else '0';
      -- y axis
      a := resize(box_y, SW);
      n := signed(resize(box_h, SW));
      s := signed(resize(frame_h, SW));
      lo := a;
      if lo < 1 then lo := to_signed(1, SW); end if;
      hi := a + n;
      if hi > s - 1 then hi := s - 1; end if;
      lo_y <= lo;
      len_y <= hi - lo;
      same_y <= '1' when lo = a and hi = a + n else '0';
      v1 <= in_valid;
      if rst = '1' then
        v1 <= '0';
      end if;
    end if;
  end process;

  -- stage 2: reject / shrink to the largest window, half extents, centre
  p_fit : process(clk)
    variable lo, ln   : s_t;
    variable shrunk   : boolean;
    variable rej      : boolean;
    variable cxv, cyv : unsigned(COORD_W + CF - 1 downto 0);
  begin
    if rising_edge(clk) then
      rej := len_x < 3 or len_y < 3;
      shrunk := false;
      -- x
      lo := lo_x; ln := len_x;
      if ln > WIN_MAX then
        lo := lo + shift_right(ln - WIN_MAX, 1);
        ln := to_signed(WIN_MAX, SW);
        shrunk := true;
      end if;
      clip_x <= unsigned(lo(COORD_W - 1 downto 0));
      clip_w <= unsigned(ln(COORD_W - 1 downto 0));
      ex <= resize(unsigned(shift_right(ln - 1, 1)), HALF_W);
      cxv := shift_left(resize(unsigned(shift_left(lo, 1) + ln - 1), COORD_W + CF), CF - 1);
      -- y
      lo := lo_y; ln := len_y;
      if ln > WIN_MAX then
        lo := lo + shift_right(ln - WIN_MAX, 1);
        ln := to_signed(WIN_MAX, SW);
        shrunk := true;
      end if;
      clip_y <= unsigned(lo(COORD_W - 1 downto 0));
      clip_h <= unsigned(ln(COORD_W - 1 downto 0));
      ey <= resize(unsigned(shift_right(ln - 1, 1)), HALF_W);
      cyv := shift_left(resize(unsigned(shift_left(lo, 1) + ln - 1), COORD_W + CF), CF - 1);
      cx <= cxv;
      cy <= cyv;
      rejected <= '1' when rej else '0';
      clipped <= '1' when rej or shrunk or same_x = '0' or same_y = '0' else '0';
      out_valid <= v1;
      if rst = '1' then
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
