-- ms_sobel: 3x3 Sobel magnitude and edge bin of the frame interior, with the
-- interior pixel's colour bin.
--
-- Computes: for each input pixel (x, y) with x >= 2 and y >= 2 it emits the
-- interior pixel (x-1, y-1) with
--   ip_cbin = colour bin of (x-1, y-1) (from the line buffer)
--   ip_ebin = min(2**EDGE_BINS_LOG2 - 1, (|Gx| + |Gy|) >> EDGE_SHIFT)
--   Gx = right column - left column, Gy = bottom row - top row (weights 1 2 1)
-- of the 3x3 grey neighbourhood centred on (x-1, y-1).
-- Storage: one inferred simple dual-port RAM of MAX_FRAME_W words holding,
-- per column, rows y-1 (grey + colour bin) and y-2 (grey): 16 + 3*COLOUR_BITS
-- bits.  Read at x when the pixel arrives, written one clock later
-- (read-modify-write of the same column, never the same address in one clock
-- for lines of >= 2 pixels).  A 3x3 window of registers shifts on each pixel.
-- The input pixels must arrive in raster order, x counting 0 .. W-1 within a
-- line with no pixel missing (as ms_stream_check delivers them), W <= MAX_FRAME_W.
-- Latency: 4 clocks from in_valid of pixel (x+1, y+1) to ip_valid of (x, y),
-- independent of input gaps.  Throughput: 1 pixel/clock, no stalls.
-- Python model: ms_edge_bin(ms_sobel(ms_grey(frame))) and ms_colour_bin of
-- mstrack.fixed.blocks (interior (H-2) x (W-2) pixels).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_sobel is
  generic (
    COORD_W        : natural := 12;    -- width of x, y
    MAX_FRAME_W    : natural := 2048;  -- line buffer depth (widest frame); costs RAM (16 + 3*COLOUR_BITS) bits/px
    COLOUR_BITS    : natural range 1 to 8 := 3;  -- colour bin width / 3
    EDGE_BINS_LOG2 : natural range 1 to 8 := 4;  -- edge bin width
    EDGE_SHIFT     : natural range 0 to 11 := 5  -- |G| >> EDGE_SHIFT before saturation
  );
  port (
    clk      : in  std_logic;                                            -- clock
    rst      : in  std_logic;                                            -- synchronous reset (valid bits only)
    in_valid : in  std_logic;                                            -- pixel present
    in_x     : in  unsigned(COORD_W - 1 downto 0);                       -- its column
    in_y     : in  unsigned(COORD_W - 1 downto 0);                       -- its row
    in_grey  : in  unsigned(7 downto 0);                                 -- its grey level (ms_grey)
    in_cbin  : in  std_logic_vector(3 * COLOUR_BITS - 1 downto 0);       -- its colour bin (ms_colour_bin)
    ip_valid : out std_logic;                                            -- interior pixel out
    ip_x     : out unsigned(COORD_W - 1 downto 0);                       -- its column (1 .. W-2)
    ip_y     : out unsigned(COORD_W - 1 downto 0);                       -- its row (1 .. H-2)
    ip_cbin  : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0);       -- its colour bin
    ip_ebin  : out std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0)         -- its edge bin
  );
end entity;

architecture rtl of ms_sobel is
  constant CB_W : natural := 3 * COLOUR_BITS;
  constant LB_W : natural := 16 + CB_W;           -- {grey y-2, grey y-1, cbin y-1}
  constant LA_W : natural := clog2(MAX_FRAME_W);  -- line buffer address width
  constant MAG_W : natural := 11;                 -- |Gx| + |Gy| <= 2040

  type ram_t is array (0 to MAX_FRAME_W - 1) of std_logic_vector(LB_W - 1 downto 0);
  signal lbuf : ram_t := (others => (others => '0'));
  signal rdata : std_logic_vector(LB_W - 1 downto 0);

  -- stage 1: input registered, line buffer word of the same column read
  signal v1, e1   : std_logic := '0';  -- valid, emits an interior pixel
  signal x1, y1   : unsigned(COORD_W - 1 downto 0);
  signal g1       : unsigned(7 downto 0);
  signal c1       : std_logic_vector(CB_W - 1 downto 0);
  signal wa1      : unsigned(LA_W - 1 downto 0);
  -- stage 2: 3x3 window (t = top row y-2, m = middle y-1, b = bottom y; 0 = column x-2, 2 = x)
  subtype g_t is unsigned(7 downto 0);
  signal t0, t1, t2, m0, m1, m2, b0, b1, b2 : g_t := (others => '0');
  signal cm1, cm2 : std_logic_vector(CB_W - 1 downto 0);  -- colour bins of m1, m2
  signal v2       : std_logic := '0';
  signal x2, y2   : unsigned(COORD_W - 1 downto 0);
  -- stage 3: |Gx|, |Gy|
  signal v3       : std_logic := '0';
  signal x3, y3   : unsigned(COORD_W - 1 downto 0);
  signal c3       : std_logic_vector(CB_W - 1 downto 0);
  signal agx, agy : unsigned(MAG_W - 2 downto 0);         -- 0 .. 1020
begin
  assert MAX_FRAME_W >= 3 report "ms_sobel: MAX_FRAME_W must be >= 3" severity failure;
  assert 2 ** LA_W <= 2 ** COORD_W report "ms_sobel: COORD_W too small for MAX_FRAME_W" severity failure;

  -- line buffer: simple dual port, registered read (read before the write of stage 1)
  p_lbuf : process (clk)
  begin
    if rising_edge(clk) then
      rdata <= lbuf(to_integer(in_x(LA_W - 1 downto 0)));
      if v1 = '1' then
        lbuf(to_integer(wa1)) <= rdata(LB_W - 9 downto CB_W) & std_logic_vector(g1) & c1;
      end if;
    end if;
  end process;

  p_pipe : process (clk)
    variable gx, gy : signed(MAG_W downto 0);  -- -1020 .. 1020 (12 bits)
    variable mag    : unsigned(MAG_W - 1 downto 0);
    variable sh     : unsigned(MAG_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      -- stage 1
      v1  <= in_valid;
      e1  <= '0';
      if in_x >= 2 and in_y >= 2 then
        e1 <= in_valid;
      end if;
      x1  <= in_x - 1;
      y1  <= in_y - 1;
      g1  <= in_grey;
      c1  <= in_cbin;
      wa1 <= in_x(LA_W - 1 downto 0);
      -- stage 2: shift the window by one column on each pixel
      if v1 = '1' then
        t0 <= t1; t1 <= t2; t2 <= unsigned(rdata(LB_W - 1 downto LB_W - 8));
        m0 <= m1; m1 <= m2; m2 <= unsigned(rdata(LB_W - 9 downto CB_W));
        b0 <= b1; b1 <= b2; b2 <= g1;
        cm1 <= cm2; cm2 <= rdata(CB_W - 1 downto 0);
      end if;
      v2 <= e1;
      x2 <= x1;
      y2 <= y1;
      -- stage 3
      gx := signed(resize(t2, MAG_W + 1) + shift_left(resize(m2, MAG_W + 1), 1) + resize(b2, MAG_W + 1))
          - signed(resize(t0, MAG_W + 1) + shift_left(resize(m0, MAG_W + 1), 1) + resize(b0, MAG_W + 1));
      gy := signed(resize(b0, MAG_W + 1) + shift_left(resize(b1, MAG_W + 1), 1) + resize(b2, MAG_W + 1))
          - signed(resize(t0, MAG_W + 1) + shift_left(resize(t1, MAG_W + 1), 1) + resize(t2, MAG_W + 1));
      -- |g| written out: GHDL 2.0's Verilog writer emits invalid code for `abs`
      if gx < 0 then agx <= resize(unsigned(-gx), MAG_W - 1); else agx <= resize(unsigned(gx), MAG_W - 1); end if;
      if gy < 0 then agy <= resize(unsigned(-gy), MAG_W - 1); else agy <= resize(unsigned(gy), MAG_W - 1); end if;
      v3  <= v2;
      x3  <= x2;
      y3  <= y2;
      c3  <= cm1;
      -- stage 4
      mag := resize(agx, MAG_W) + resize(agy, MAG_W);
      sh  := shift_right(mag, EDGE_SHIFT);
      if sh > 2 ** EDGE_BINS_LOG2 - 1 then
        ip_ebin <= (others => '1');
      else
        ip_ebin <= std_logic_vector(sh(EDGE_BINS_LOG2 - 1 downto 0));
      end if;
      ip_valid <= v3;
      ip_x     <= x3;
      ip_y     <= y3;
      ip_cbin  <= c3;
      if rst = '1' then
        v1 <= '0';
        e1 <= '0';
        v2 <= '0';
        v3 <= '0';
        ip_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
