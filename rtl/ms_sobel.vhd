-- ms_sobel: 3x3 Sobel magnitude and edge bin, and gradient orientation bin, of the
-- frame interior, with the interior pixel's colour bin; PPC pixels per clock.
--
-- Computes: for each input beat of PPC pixels (x .. x+PPC-1, y) (x a multiple
-- of PPC) it emits, with y >= 2, the PPC interior candidates (x-1+k, y-1),
-- k = 0 .. PPC-1 (lane k), each with
--   ip_cbin = colour bin of (x-1+k, y-1) (from the line buffer)
--   ip_ebin = min(2**EDGE_BINS_LOG2 - 1, (|Gx| + |Gy|) >> EDGE_SHIFT)
--   ip_obin = 4 [Gx < 0] + 2 [Gy < 0] + [|Gy| > |Gx|] if |Gx| + |Gy| >= ORIENT_T,
--             else 8 (the octant of the gradient, 8 = flat; tracker v2's joint bins)
--   Gx = right column - left column, Gy = bottom row - top row (weights 1 2 1)
-- of the 3x3 grey neighbourhood centred there; ip_mask(k) = 1 for the lanes
-- inside the interior (x-1+k >= 1; x-1+k <= W-2 always holds), ip_valid = 1
-- if any lane is.  ip_x is the column of lane 0 (x-1, modulo 2**COORD_W:
-- all ones for the line's first beat, a lane that ip_mask excludes).
-- PPC = 1: one pixel per beat, ip_mask = ip_valid, ip_x = the interior column.
-- Storage: a simple dual-port line buffer of ceil(MAX_FRAME_W / PPC) words
-- holding, per column group x / PPC, rows y-1 (grey + colour bin) and y-2
-- (grey) of its PPC pixels: PPC (16 + 3*COLOUR_BITS) bits, as three ms_ram_sdp
-- (grey y-2, grey y-1, colour bin y-1; PPC x 8, PPC x 8, PPC x 3*COLOUR_BITS
-- bits; at PPC = 1 one DP16KD of 2048 x 9 each by default and no depth
-- multiplexer) with a read latency of 2 (on ECP5 the DP16KD output register).
-- Read at x / PPC when the beat's position arrives (in_valid, in_x, in_y: ONE
-- CLOCK BEFORE its greys and colour bins, in_grey / in_cbin), the word (rq)
-- there 2 clocks later, and written back 2 clocks after the read, once rq, the
-- greys and the colour bins are registered (read-modify-write of the same word;
-- the next two words are read meanwhile, never the same address).  A window of
-- registers, 3 rows x (PPC + 2) columns (the last two columns of the previous
-- beat, then the beat's PPC columns), shifts by PPC columns on each beat.
-- The input beats must arrive in raster order, x counting 0, PPC, .. W-PPC
-- within a line with no beat missing (as ms_stream_check delivers them),
-- W <= MAX_FRAME_W, W a multiple of PPC.
-- Pipeline: 0 position registered + line buffer read, 1 greys / colour bins and
-- the read word registered, 2 window shift, 3 the four weighted 1-2-1 sums per
-- lane (right / left column, bottom / top row; two adder levels), 4 |Gx| and
-- |Gy| (both differences in parallel, chosen by sign), 5 |Gx| + |Gy|, shift
-- and saturation.
-- Latency: 6 clocks from in_valid (position) of the beat at (x+1, y+1) to
-- ip_valid of (x, y) (5 clocks from its in_grey); independent of input gaps.
-- Throughput: 1 beat (PPC pixels)/clock, no stalls.
-- Python model: ms_edge_bin(ms_sobel(ms_grey(frame))) and ms_colour_bin of
-- mstrack.fixed.blocks, ms_orient_bin(ms_grey(frame), ORIENT_T) of
-- mstrack.fixed.blocks_v2 (interior (H-2) x (W-2) pixels).  ip_obin unused: no logic.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_sobel is
  generic (
    COORD_W        : natural := 12;    -- width of x, y
    MAX_FRAME_W    : natural := 2048;  -- widest frame; line buffer of ceil(MAX_FRAME_W / PPC) words of PPC (16 + 3*COLOUR_BITS) bits
    COLOUR_BITS    : natural range 1 to 8 := 3;  -- colour bin width / 3
    EDGE_BINS_LOG2 : natural range 1 to 8 := 4;  -- edge bin width
    EDGE_SHIFT     : natural range 0 to 11 := 5; -- |G| >> EDGE_SHIFT before saturation
    ORIENT_T       : natural range 0 to 2047 := 64; -- |Gx| + |Gy| >= ORIENT_T: an orientation, else flat (8)
    PPC            : positive := 1               -- pixels per clock: 1, 2 or 4
  );
  port (
    clk      : in  std_logic;                                            -- clock
    rst      : in  std_logic;                                            -- synchronous reset (valid bits only)
    in_valid : in  std_logic;                                            -- beat present (its position)
    in_x     : in  unsigned(COORD_W - 1 downto 0);                       -- column of its first pixel (multiple of PPC)
    in_y     : in  unsigned(COORD_W - 1 downto 0);                       -- its row
    in_grey  : in  unsigned(8 * PPC - 1 downto 0);                       -- grey of pixel k at 8k+7 .. 8k (ms_grey), 1 clock after in_valid
    in_cbin  : in  std_logic_vector(PPC * 3 * COLOUR_BITS - 1 downto 0); -- colour bin of pixel k at lane k (ms_colour_bin), with in_grey
    ip_valid : out std_logic;                                            -- interior pixel(s) out: ip_mask /= 0
    ip_mask  : out std_logic_vector(PPC - 1 downto 0);                   -- lane k holds an interior pixel
    ip_x     : out unsigned(COORD_W - 1 downto 0);                       -- column of lane 0 (1 .. W-2 when ip_mask(0))
    ip_y     : out unsigned(COORD_W - 1 downto 0);                       -- its row (1 .. H-2)
    ip_cbin  : out std_logic_vector(PPC * 3 * COLOUR_BITS - 1 downto 0); -- colour bin of lane k at lane k
    ip_ebin  : out std_logic_vector(PPC * EDGE_BINS_LOG2 - 1 downto 0);  -- edge bin of lane k at lane k
    ip_obin  : out std_logic_vector(PPC * 4 - 1 downto 0)                -- orientation bin (0 .. 8) of lane k at 4k+3 .. 4k
  );
end entity;

architecture rtl of ms_sobel is
  constant CB_W  : natural := 3 * COLOUR_BITS;
  constant EB_W  : natural := EDGE_BINS_LOG2;
  constant LB_W  : natural := 16 + CB_W;                       -- {grey y-2, grey y-1, cbin y-1} per pixel
  constant LOG2P : natural := 0 * boolean'pos(PPC = 1) + 1 * boolean'pos(PPC = 2) + 2 * boolean'pos(PPC = 4);
  constant WORDS : natural := (MAX_FRAME_W + PPC - 1) / PPC;  -- line buffer depth
  constant LA_W  : natural := clog2(WORDS);                    -- line buffer address width
  constant SUM_W : natural := 10;                              -- a 1-2-1 sum of greys <= 1020
  constant MAG_W : natural := SUM_W + 1;                       -- |Gx| + |Gy| <= 2040
  constant NW    : natural := PPC + 2;                         -- window columns

  subtype g_t is unsigned(7 downto 0);
  subtype c_t is std_logic_vector(CB_W - 1 downto 0);
  subtype s_t is unsigned(SUM_W - 1 downto 0);
  type g_arr is array (natural range <>) of g_t;
  type c_arr is array (natural range <>) of c_t;
  type s_arr is array (natural range <>) of s_t;

  -- the line buffer word (PPC pixels), in three RAMs: at PPC = 1 <= 9 bits each (one DP16KD of
  -- 2048 x 9 each by default), so that no RAM is split in depth (no output multiplexer)
  signal rq_t  : std_logic_vector(8 * PPC - 1 downto 0);     -- greys y-2, 2 clocks after the read
  signal rq_m  : std_logic_vector(8 * PPC - 1 downto 0);     -- greys y-1
  signal rq_c  : std_logic_vector(CB_W * PPC - 1 downto 0);  -- colour bins y-1
  signal ra    : unsigned(LA_W - 1 downto 0);                -- read address (the word of in_x)

  -- stage 0: position registered, line buffer read
  signal v0       : std_logic := '0';
  signal e0       : std_logic_vector(PPC - 1 downto 0) := (others => '0');
  signal x0, y0   : unsigned(COORD_W - 1 downto 0);
  signal wa0      : unsigned(LA_W - 1 downto 0);
  -- stage 1: greys and colour bins registered, line buffer word of the same column group in rq_*
  signal v1       : std_logic := '0';                                         -- valid
  signal e1       : std_logic_vector(PPC - 1 downto 0) := (others => '0');    -- lanes emitting an interior pixel
  signal x1, y1   : unsigned(COORD_W - 1 downto 0);
  signal g1       : std_logic_vector(8 * PPC - 1 downto 0);
  signal c1       : std_logic_vector(CB_W * PPC - 1 downto 0);
  signal wa1      : unsigned(LA_W - 1 downto 0);
  -- stage 2: window (t = top row y-2, m = middle y-1, b = bottom y; column 0 = x-2, NW-1 = x+PPC-1)
  signal t, m, b  : g_arr(0 to NW - 1) := (others => (others => '0'));
  signal cm       : c_arr(0 to NW - 1);                                       -- colour bins of row m
  signal v2       : std_logic_vector(PPC - 1 downto 0) := (others => '0');
  signal x2, y2   : unsigned(COORD_W - 1 downto 0);
  -- stage 3: weighted 1-2-1 sums of the right (xp) / left (xn) column, bottom (yp) / top (yn) row
  signal v3       : std_logic_vector(PPC - 1 downto 0) := (others => '0');
  signal x3, y3   : unsigned(COORD_W - 1 downto 0);
  signal c3       : c_arr(0 to PPC - 1);
  signal sxp, sxn, syp, syn : s_arr(0 to PPC - 1);                            -- 0 .. 1020
  -- stage 4: |Gx|, |Gy|
  signal v4       : std_logic_vector(PPC - 1 downto 0) := (others => '0');
  signal x4, y4   : unsigned(COORD_W - 1 downto 0);
  signal c4       : c_arr(0 to PPC - 1);
  signal agx, agy : s_arr(0 to PPC - 1);                                      -- 0 .. 1020
  signal ngx, ngy : std_logic_vector(PPC - 1 downto 0);                       -- Gx < 0, Gy < 0
  signal mask_o   : std_logic_vector(PPC - 1 downto 0) := (others => '0');
begin
  assert MAX_FRAME_W >= 3 report "ms_sobel: MAX_FRAME_W must be >= 3" severity failure;
  assert PPC = 1 or PPC = 2 or PPC = 4 report "ms_sobel: PPC must be 1, 2 or 4" severity failure;
  assert 2 ** (LA_W + LOG2P) <= 2 ** COORD_W report "ms_sobel: COORD_W too small for MAX_FRAME_W" severity failure;

  -- line buffer: three simple dual-port RAMs, read latency 2 (read in stage 0, data in rq_* when
  -- stage 1's registers are out; written back at the edge after stage 1)
  ra <= resize(shift_right(in_x, LOG2P), LA_W);

  u_lbuf_t : entity work.ms_ram_sdp   -- greys y-2
    generic map (DEPTH => WORDS, DATA_W => 8 * PPC, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => rq_m, raddr => ra, rdata => rq_t);
  u_lbuf_m : entity work.ms_ram_sdp   -- greys y-1
    generic map (DEPTH => WORDS, DATA_W => 8 * PPC, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => g1, raddr => ra, rdata => rq_m);
  u_lbuf_c : entity work.ms_ram_sdp   -- colour bins y-1
    generic map (DEPTH => WORDS, DATA_W => CB_W * PPC, ADDR_W => LA_W, RD_LAT => 2)
    port map (clk => clk, we => v1, waddr => wa1, wdata => c1, raddr => ra, rdata => rq_c);

  p_pipe : process (clk)
    variable dxp, dxn, dyp, dyn : unsigned(MAG_W - 1 downto 0);  -- differences, bit SUM_W = borrow
    variable mag    : unsigned(MAG_W - 1 downto 0);
    variable sh     : unsigned(MAG_W - 1 downto 0);
    variable any    : std_logic;

    -- p + 2 q + r of three greys
    function sum121(p, q, r : g_t) return unsigned is
    begin
      return (resize(p, SUM_W) + resize(r, SUM_W)) + shift_left(resize(q, SUM_W), 1);
    end function;
  begin
    if rising_edge(clk) then
      -- stage 0: lane k is interior if its column x-1+k >= 1 and the row y-1 >= 1
      v0  <= in_valid;
      for k in 0 to PPC - 1 loop
        e0(k) <= '0';
        if in_x + k >= 2 and in_y >= 2 then
          e0(k) <= in_valid;
        end if;
      end loop;
      x0  <= in_x - 1;
      y0  <= in_y - 1;
      wa0 <= ra;
      -- stage 1
      v1  <= v0;
      e1  <= e0;
      x1  <= x0;
      y1  <= y0;
      g1  <= std_logic_vector(in_grey);
      c1  <= in_cbin;
      wa1 <= wa0;
      -- stage 2: shift the window by PPC columns on each beat
      if v1 = '1' then
        for j in 0 to 1 loop
          t(j) <= t(j + PPC); m(j) <= m(j + PPC); b(j) <= b(j + PPC); cm(j) <= cm(j + PPC);
        end loop;
        for k in 0 to PPC - 1 loop
          t(k + 2)  <= unsigned(rq_t(8 * k + 7 downto 8 * k));
          m(k + 2)  <= unsigned(rq_m(8 * k + 7 downto 8 * k));
          b(k + 2)  <= unsigned(g1(8 * k + 7 downto 8 * k));
          cm(k + 2) <= rq_c(CB_W * (k + 1) - 1 downto CB_W * k);
        end loop;
      end if;
      v2 <= e1;
      x2 <= x1;
      y2 <= y1;
      -- stage 3: lane k centred on window column k + 1: Gx = sxp - sxn, Gy = syp - syn
      for k in 0 to PPC - 1 loop
        sxp(k) <= sum121(t(k + 2), m(k + 2), b(k + 2));
        sxn(k) <= sum121(t(k), m(k), b(k));
        syp(k) <= sum121(b(k), b(k + 1), b(k + 2));
        syn(k) <= sum121(t(k), t(k + 1), t(k + 2));
        c3(k)  <= cm(k + 1);
      end loop;
      v3  <= v2;
      x3  <= x2;
      y3  <= y2;
      -- stage 4: |Gx|, |Gy|: both differences, the one without borrow
      for k in 0 to PPC - 1 loop
        dxp := resize(sxp(k), MAG_W) - resize(sxn(k), MAG_W);
        dxn := resize(sxn(k), MAG_W) - resize(sxp(k), MAG_W);
        dyp := resize(syp(k), MAG_W) - resize(syn(k), MAG_W);
        dyn := resize(syn(k), MAG_W) - resize(syp(k), MAG_W);
        if dxp(SUM_W) = '1' then agx(k) <= dxn(SUM_W - 1 downto 0); else agx(k) <= dxp(SUM_W - 1 downto 0); end if;
        if dyp(SUM_W) = '1' then agy(k) <= dyn(SUM_W - 1 downto 0); else agy(k) <= dyp(SUM_W - 1 downto 0); end if;
        ngx(k) <= dxp(SUM_W);  -- borrow: right < left, Gx < 0
        ngy(k) <= dyp(SUM_W);  -- bottom < top, Gy < 0
      end loop;
      v4  <= v3;
      x4  <= x3;
      y4  <= y3;
      c4  <= c3;
      -- stage 5
      any := '0';
      for k in 0 to PPC - 1 loop
        mag := resize(agx(k), MAG_W) + resize(agy(k), MAG_W);
        sh  := shift_right(mag, EDGE_SHIFT);
        if sh > 2 ** EDGE_BINS_LOG2 - 1 then
          ip_ebin(EB_W * (k + 1) - 1 downto EB_W * k) <= (others => '1');
        else
          ip_ebin(EB_W * (k + 1) - 1 downto EB_W * k) <= std_logic_vector(sh(EB_W - 1 downto 0));
        end if;
        if mag >= ORIENT_T then
          ip_obin(4 * k + 3) <= '0';
          ip_obin(4 * k + 2) <= ngx(k);
          ip_obin(4 * k + 1) <= ngy(k);
          if agy(k) > agx(k) then ip_obin(4 * k) <= '1'; else ip_obin(4 * k) <= '0'; end if;
        else
          ip_obin(4 * k + 3 downto 4 * k) <= "1000";
        end if;
        ip_cbin(CB_W * (k + 1) - 1 downto CB_W * k) <= c4(k);
        any := any or v4(k);
      end loop;
      mask_o   <= v4;
      ip_valid <= any;
      ip_x     <= x4;
      ip_y     <= y4;
      if rst = '1' then
        v0 <= '0';
        e0 <= (others => '0');
        v1 <= '0';
        e1 <= (others => '0');
        v2 <= (others => '0');
        v3 <= (others => '0');
        v4 <= (others => '0');
        mask_o <= (others => '0');
        ip_valid <= '0';
      end if;
    end if;
  end process;
  ip_mask <= mask_o;
end architecture;
