-- ms_sobel: 3x3 Sobel magnitude and edge bin of the frame interior, with the
-- interior pixel's colour bin.
--
-- Computes: for each input pixel (x, y) with x >= 2 and y >= 2 it emits the
-- interior pixel (x-1, y-1) with
--   ip_cbin = colour bin of (x-1, y-1) (from the line buffer)
--   ip_ebin = min(2**EDGE_BINS_LOG2 - 1, (|Gx| + |Gy|) >> EDGE_SHIFT)
--   Gx = right column - left column, Gy = bottom row - top row (weights 1 2 1)
-- of the 3x3 grey neighbourhood centred on (x-1, y-1).
-- Storage: a simple dual-port line buffer of MAX_FRAME_W words holding, per
-- column, rows y-1 (grey + colour bin) and y-2 (grey): 16 + 3*COLOUR_BITS
-- bits, as three ms_ram_sdp (grey y-2, grey y-1, colour bin y-1; <= 9 bits
-- each, so one DP16KD of 2048 x 9 each by default and no depth multiplexer)
-- with a read latency of 2 (on ECP5 the DP16KD output register).  Read at x
-- when the pixel's position arrives (in_valid, in_x, in_y: ONE CLOCK BEFORE
-- its grey and colour bin, in_grey / in_cbin), the word (rq) there 2 clocks
-- later, and written back 2 clocks after the read, once rq, the grey and the
-- colour bin are registered (read-modify-write of the same column; columns
-- x+1 and x+2 are read meanwhile, never the same address).  A 3x3 window of
-- registers shifts on each pixel.
-- The input pixels must arrive in raster order, x counting 0 .. W-1 within a
-- line with no pixel missing (as ms_stream_check delivers them), W <= MAX_FRAME_W.
-- Pipeline: 0 position registered + line buffer read, 1 grey / colour bin and
-- the read word registered, 2 window shift, 3 the four weighted 1-2-1 sums
-- (right / left column, bottom / top row; two adder levels), 4 |Gx| and |Gy|
-- (both differences in parallel, chosen by sign), 5 |Gx| + |Gy|, shift and
-- saturation.
-- Latency: 6 clocks from in_valid (position) of pixel (x+1, y+1) to ip_valid
-- of (x, y), i.e. 5 clocks from its in_grey; independent of input gaps.
-- Throughput: 1 pixel/clock, no stalls.
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
    in_valid : in  std_logic;                                            -- pixel present (its position)
    in_x     : in  unsigned(COORD_W - 1 downto 0);                       -- its column
    in_y     : in  unsigned(COORD_W - 1 downto 0);                       -- its row
    in_grey  : in  unsigned(7 downto 0);                                 -- its grey level (ms_grey), 1 clock after in_valid
    in_cbin  : in  std_logic_vector(3 * COLOUR_BITS - 1 downto 0);       -- its colour bin (ms_colour_bin), with in_grey
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
  constant SUM_W : natural := 10;                 -- a 1-2-1 sum of greys <= 1020
  constant MAG_W : natural := SUM_W + 1;          -- |Gx| + |Gy| <= 2040

  -- the word is kept in three RAMs of <= 9 bits (one DP16KD of 2048 x 9 each by default),
  -- so that no RAM is split in depth (no output multiplexer between RAM and register)
  signal rq    : std_logic_vector(LB_W - 1 downto 0);  -- the line buffer word, 2 clocks after the read
  signal ra    : unsigned(LA_W - 1 downto 0);          -- read address (the column of in_x)

  -- stage 0: position registered, line buffer read
  signal v0, e0   : std_logic := '0';
  signal x0, y0   : unsigned(COORD_W - 1 downto 0);
  signal wa0      : unsigned(LA_W - 1 downto 0);
  -- stage 1: grey and colour bin registered, line buffer word of the same column in rq
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
  -- stage 3: weighted 1-2-1 sums of the right (xp) / left (xn) column, bottom (yp) / top (yn) row
  signal v3       : std_logic := '0';
  signal x3, y3   : unsigned(COORD_W - 1 downto 0);
  signal c3       : std_logic_vector(CB_W - 1 downto 0);
  signal sxp, sxn, syp, syn : unsigned(SUM_W - 1 downto 0);  -- 0 .. 1020
  -- stage 4: |Gx|, |Gy|
  signal v4       : std_logic := '0';
  signal x4, y4   : unsigned(COORD_W - 1 downto 0);
  signal c4       : std_logic_vector(CB_W - 1 downto 0);
  signal agx, agy : unsigned(SUM_W - 1 downto 0);         -- 0 .. 1020
begin
  assert MAX_FRAME_W >= 3 report "ms_sobel: MAX_FRAME_W must be >= 3" severity failure;
  assert 2 ** LA_W <= 2 ** COORD_W report "ms_sobel: COORD_W too small for MAX_FRAME_W" severity failure;

  -- line buffer: three simple dual-port RAMs, read latency 2 (read in stage 0, data in rq when
  -- stage 1's registers are out; written back at the edge after stage 1)
  ra <= in_x(LA_W - 1 downto 0);

  u_lbuf_t : entity work.ms_ram_sdp   -- grey y-2
    generic map (DEPTH => MAX_FRAME_W, DATA_W => 8, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => rq(LB_W - 9 downto CB_W),
              raddr => ra, rdata => rq(LB_W - 1 downto LB_W - 8));
  u_lbuf_m : entity work.ms_ram_sdp   -- grey y-1
    generic map (DEPTH => MAX_FRAME_W, DATA_W => 8, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => std_logic_vector(g1),
              raddr => ra, rdata => rq(LB_W - 9 downto CB_W));
  u_lbuf_c : entity work.ms_ram_sdp   -- colour bin y-1
    generic map (DEPTH => MAX_FRAME_W, DATA_W => CB_W, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => c1,
              raddr => ra, rdata => rq(CB_W - 1 downto 0));

  p_pipe : process (clk)
    variable dxp, dxn, dyp, dyn : unsigned(MAG_W - 1 downto 0);  -- differences, bit SUM_W = borrow
    variable mag    : unsigned(MAG_W - 1 downto 0);
    variable sh     : unsigned(MAG_W - 1 downto 0);

    -- a + 2 m + b of three greys
    function sum121(a, m, b : g_t) return unsigned is
    begin
      return (resize(a, SUM_W) + resize(b, SUM_W)) + shift_left(resize(m, SUM_W), 1);
    end function;
  begin
    if rising_edge(clk) then
      -- stage 0
      v0  <= in_valid;
      e0  <= '0';
      if in_x >= 2 and in_y >= 2 then
        e0 <= in_valid;
      end if;
      x0  <= in_x - 1;
      y0  <= in_y - 1;
      wa0 <= in_x(LA_W - 1 downto 0);
      -- stage 1
      v1  <= v0;
      e1  <= e0;
      x1  <= x0;
      y1  <= y0;
      g1  <= in_grey;
      c1  <= in_cbin;
      wa1 <= wa0;
      -- stage 2: shift the window by one column on each pixel
      if v1 = '1' then
        t0 <= t1; t1 <= t2; t2 <= unsigned(rq(LB_W - 1 downto LB_W - 8));
        m0 <= m1; m1 <= m2; m2 <= unsigned(rq(LB_W - 9 downto CB_W));
        b0 <= b1; b1 <= b2; b2 <= g1;
        cm1 <= cm2; cm2 <= rq(CB_W - 1 downto 0);
      end if;
      v2 <= e1;
      x2 <= x1;
      y2 <= y1;
      -- stage 3: Gx = sxp - sxn, Gy = syp - syn
      sxp <= sum121(t2, m2, b2);
      sxn <= sum121(t0, m0, b0);
      syp <= sum121(b0, b1, b2);
      syn <= sum121(t0, t1, t2);
      v3  <= v2;
      x3  <= x2;
      y3  <= y2;
      c3  <= cm1;
      -- stage 4: |Gx|, |Gy|: both differences, the one without borrow
      dxp := resize(sxp, MAG_W) - resize(sxn, MAG_W);
      dxn := resize(sxn, MAG_W) - resize(sxp, MAG_W);
      dyp := resize(syp, MAG_W) - resize(syn, MAG_W);
      dyn := resize(syn, MAG_W) - resize(syp, MAG_W);
      if dxp(SUM_W) = '1' then agx <= dxn(SUM_W - 1 downto 0); else agx <= dxp(SUM_W - 1 downto 0); end if;
      if dyp(SUM_W) = '1' then agy <= dyn(SUM_W - 1 downto 0); else agy <= dyp(SUM_W - 1 downto 0); end if;
      v4  <= v3;
      x4  <= x3;
      y4  <= y3;
      c4  <= c3;
      -- stage 5
      mag := resize(agx, MAG_W) + resize(agy, MAG_W);
      sh  := shift_right(mag, EDGE_SHIFT);
      if sh > 2 ** EDGE_BINS_LOG2 - 1 then
        ip_ebin <= (others => '1');
      else
        ip_ebin <= std_logic_vector(sh(EDGE_BINS_LOG2 - 1 downto 0));
      end if;
      ip_valid <= v4;
      ip_x     <= x4;
      ip_y     <= y4;
      ip_cbin  <= c4;
      if rst = '1' then
        v0 <= '0';
        e0 <= '0';
        v1 <= '0';
        e1 <= '0';
        v2 <= '0';
        v3 <= '0';
        v4 <= '0';
        ip_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
