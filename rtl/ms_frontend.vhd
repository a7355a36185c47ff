-- ms_frontend: streaming front end of the tracker: ms_stream_check ->
-- (ms_colour_bin | ms_grey) -> ms_sobel.
--
-- Computes: the (x, y, colour bin, edge bin, orientation bin) of every interior pixel
-- (1 <= x <= W-2, 1 <= y <= H-2) of each frame, in raster order, PPC pixels
-- per clock (PPC = 1, 2 or 4; lane k = column ip_x + k, valid where
-- ip_mask(k) = 1; see ms_sobel: a line's first beat has lanes 0 .. 1 off), plus the
-- frame events of ms_stream_check re-timed so that they keep their order with
-- the pixels: every event is delayed by EVT_DELAY = 8 clocks, so that
--   * frame_end comes 1 clock AFTER the frame's last interior pixel (ip_valid),
--     i.e. 9 clocks after the frame's last input beat was accepted;
--   * frame_error (any code, also ERR_CUT) comes after all the ip_* pixels of
--     the abandoned frame;
--   * frame_start comes 9 clocks after the sof beat, before the first interior
--     pixel of that frame (which needs >= 2 W + 3 beats).
-- ad_* is the all-pixel stream av_* delayed to the frame events, for a capture on it (the
-- multi-target core's colour slots, ms_slot_capture without INTERIOR_ONLY): frame_start and
-- frame_error come 1 clock before the first ad pixel of the frame they start, ad_end (the stream's
-- frame_end) in the clock of the frame's last ad pixel, 1 clock after frame_end; frame_error in or
-- after the clock of an abandoned frame's last ad pixel.  So a frame's ad pixels and its interior
-- pixels lie between the same frame_start and frame_end / frame_error (+ 1 clock on ad_end), and a
-- descriptor loaded outside that clock reaches captures on both streams for the same frame.
-- Latency: input beat of pixel (x+1, y+1) -> ip_valid of (x, y): 8 clocks
-- (check 1, grey 2, sobel 5 after the grey; ms_sobel reads its line buffer
-- with the position, which it gets one clock before the grey); the same for every PPC.
-- Throughput: 1 beat of PPC pixels/clock; never stalls (no ready): the top must
-- back-pressure upstream itself if it needs to.
-- Pixels per clock: in_data carries PPC pixels per beat (AXI4-Stream video: pixel k in bits
-- 24k+23 .. 24k, the leftmost pixel in the low bits; in_sof on the frame's first beat, in_eol on
-- the line's last beat); one ms_colour_bin and one ms_grey per pixel, ms_sobel PPC wide.  A
-- frame_width that is not a multiple of PPC is refused like a size out of range (ERR_SIZE).
-- PPC = 1 keeps every port as in the one-pixel core (ip_mask = ip_valid).
-- Pixel layout (RGB_PACKING): 0 = R 23:16, G 15:8, B 7:0 (default); 1 = AMD UG934's RGB
-- order (video format code 2: R 23:16, B 15:8, G 7:0), so that AMD video IP connects directly.
-- Frame size: 3 <= frame_width <= MAX_FRAME_W, 3 <= frame_height, frame_width a multiple of
-- PPC; ms_stream_check drops a frame out of that range (frame_error, ERR_SIZE).
-- Python model: mstrack.fixed.blocks ms_colour_bin and
-- ms_edge_bin(ms_sobel(ms_grey(frame)), 2**EDGE_BINS_LOG2, EDGE_SHIFT);
-- ip_obin: mstrack.fixed.blocks_v2 ms_orient_bin(ms_grey(frame), ORIENT_T).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_stream_pkg.all;

entity ms_frontend is
  generic (
    COORD_W        : natural := 12;              -- width of x, y, frame size
    MAX_FRAME_W    : natural := 2048;            -- widest frame (line buffer depth)
    COLOUR_BITS    : natural range 1 to 8 := 3;  -- bits per channel of the colour bin
    EDGE_BINS_LOG2 : natural range 1 to 8 := 4;  -- edge bin width
    EDGE_SHIFT     : natural range 0 to 11 := 5; -- edge bin = min(E-1, |G| >> EDGE_SHIFT)
    ORIENT_T       : natural range 0 to 2047 := 64; -- orientation bin: flat (8) where |Gx| + |Gy| < ORIENT_T
    RGB_PACKING    : natural range 0 to 1 := 0;  -- pixel layout: 0 R 23:16 G 15:8 B 7:0 (mstrack);
                                                 -- 1 R 23:16 B 15:8 G 7:0 (AMD UG934, RGB video); wiring only
    PPC            : positive := 1               -- pixels per clock (beat): 1, 2 or 4
  );
  port (
    clk          : in  std_logic;                                       -- clock
    rst          : in  std_logic;                                       -- synchronous reset, active high
    frame_width  : in  unsigned(COORD_W - 1 downto 0);                  -- W, sampled on sof
    frame_height : in  unsigned(COORD_W - 1 downto 0);                  -- H, sampled on sof
    in_valid     : in  std_logic;                                       -- beat present (AXI tvalid; tready = 1)
    in_data      : in  std_logic_vector(24 * PPC - 1 downto 0);         -- PPC RGB pixels, pixel k at 24k+23 .. 24k (RGB_PACKING)
    in_sof       : in  std_logic;                                       -- start of frame (AXI tuser)
    in_eol       : in  std_logic;                                       -- end of line (AXI tlast)
    ip_valid     : out std_logic;                                       -- interior pixel(s) out (ip_mask /= 0)
    ip_mask      : out std_logic_vector(PPC - 1 downto 0);              -- lane k holds an interior pixel
    ip_x         : out unsigned(COORD_W - 1 downto 0);                  -- column of lane 0 (1 .. W-2 when ip_mask(0))
    ip_y         : out unsigned(COORD_W - 1 downto 0);                  -- its row (1 .. H-2)
    ip_cbin      : out std_logic_vector(PPC * 3 * COLOUR_BITS - 1 downto 0);  -- colour bin of lane k at lane k
    ip_ebin      : out std_logic_vector(PPC * EDGE_BINS_LOG2 - 1 downto 0);   -- edge bin of lane k at lane k
    ip_obin      : out std_logic_vector(PPC * 4 - 1 downto 0);          -- orientation bin (0 .. 8) of lane k at 4k+3 .. 4k
    frame_start  : out std_logic;                                       -- pulse: a frame started (delayed)
    frame_end    : out std_logic;                                       -- pulse: good frame complete, after its last ip_valid
    frame_error  : out std_logic;                                       -- pulse: protocol error (delayed), no frame_end for that frame
    error_now    : out std_logic;                                       -- pulse: the same error, undelayed (1 clock after the bad beat)
    err_code     : out std_logic_vector(ERR_CODE_W - 1 downto 0);       -- ERR_* (ms_stream_pkg), with frame_error
    -- every pixel of the frame (border included), colour bin only, 1 clock after ms_stream_check
    -- (core v2: ms_bg_model counts the ring up to the frame border; the paper core leaves it open)
    av_valid     : out std_logic;                                       -- a pixel of the frame
    av_x         : out unsigned(COORD_W - 1 downto 0);                  -- its column (0 .. W-1)
    av_y         : out unsigned(COORD_W - 1 downto 0);                  -- its row (0 .. H-1)
    av_cbin      : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0);  -- its colour bin (all-pixel stream: PPC = 1 only)
    -- the same stream delayed to the frame events (ad_valid of pixel (x, y) 9 clocks after its input beat)
    ad_valid     : out std_logic;                                       -- a pixel of the frame
    ad_x         : out unsigned(COORD_W - 1 downto 0);                  -- its column (0 .. W-1)
    ad_y         : out unsigned(COORD_W - 1 downto 0);                  -- its row (0 .. H-1)
    ad_cbin      : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0);  -- its colour bin
    ad_end       : out std_logic                                        -- pulse: good frame complete, with its last ad pixel
  );
end entity;

architecture rtl of ms_frontend is
  constant EVT_DELAY : natural := 8;  -- = pixel path after ms_stream_check (grey 2 + sobel 5) + 1
  constant CB_W : natural := 3 * COLOUR_BITS;

  signal rgb      : std_logic_vector(24 * PPC - 1 downto 0);  -- in_data as R 23:16, G 15:8, B 7:0 per pixel
  signal px_valid : std_logic;
  signal px_data  : std_logic_vector(24 * PPC - 1 downto 0);
  signal px_x, px_y : unsigned(COORD_W - 1 downto 0);
  signal c_start, c_end, c_err : std_logic;
  signal c_code   : std_logic_vector(ERR_CODE_W - 1 downto 0);

  signal cb_valid : std_logic_vector(PPC - 1 downto 0);
  signal cb_bin, cb_bin_d : std_logic_vector(PPC * CB_W - 1 downto 0);
  signal g_valid  : std_logic_vector(PPC - 1 downto 0);
  signal g_grey   : unsigned(8 * PPC - 1 downto 0);
  signal pv1      : std_logic := '0';              -- px_valid delayed 1 clock
  signal x1, y1   : unsigned(COORD_W - 1 downto 0);  -- px_x, px_y delayed 1 clock

  constant EV_W : natural := 3 + ERR_CODE_W;
  type ev_pipe_t is array (1 to EVT_DELAY) of std_logic_vector(EV_W - 1 downto 0);
  signal ev : ev_pipe_t := (others => (others => '0'));
  -- ad_*: av_* delayed by EVT_DELAY clocks
  constant AD_W : natural := 1 + 2 * COORD_W + CB_W;
  type ad_pipe_t is array (1 to EVT_DELAY) of std_logic_vector(AD_W - 1 downto 0);
  signal ad : ad_pipe_t := (others => (others => '0'));
  signal ad_end_r : std_logic := '0';
begin
  -- pixel layout of the input (no logic: a permutation of wires)
  g_rgb : for k in 0 to PPC - 1 generate
    rgb(24 * k + 23 downto 24 * k) <= in_data(24 * k + 23 downto 24 * k) when RGB_PACKING = 0 else
                                      in_data(24 * k + 23 downto 24 * k + 16) & in_data(24 * k + 7 downto 24 * k)
                                      & in_data(24 * k + 15 downto 24 * k + 8);
  end generate;

  u_check : entity work.ms_stream_check
    generic map (COORD_W => COORD_W, DATA_W => 24, MIN_SIZE => 3, MAX_W => MAX_FRAME_W, PPC => PPC)
    port map (
      clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
      in_valid => in_valid, in_data => rgb, in_sof => in_sof, in_eol => in_eol,
      px_valid => px_valid, px_data => px_data, px_x => px_x, px_y => px_y,
      frame_start => c_start, frame_end => c_end, frame_error => c_err, err_code => c_code);

  -- one colour bin and one grey per pixel of the beat
  g_pix : for k in 0 to PPC - 1 generate
    u_colour : entity work.ms_colour_bin
      generic map (COLOUR_BITS => COLOUR_BITS)
      port map (clk => clk, rst => rst, in_valid => px_valid, in_data => px_data(24 * k + 23 downto 24 * k),
                out_valid => cb_valid(k), out_bin => cb_bin(CB_W * (k + 1) - 1 downto CB_W * k));

    u_grey : entity work.ms_grey
      port map (clk => clk, rst => rst, in_valid => px_valid, in_data => px_data(24 * k + 23 downto 24 * k),
                out_valid => g_valid(k), out_grey => g_grey(8 * k + 7 downto 8 * k));
  end generate;

  -- align the colour bin (latency 1) with the grey (latency 2); ms_sobel takes the
  -- position (valid, x, y) one clock before the grey
  p_align : process (clk)
  begin
    if rising_edge(clk) then
      cb_bin_d <= cb_bin;
      pv1 <= px_valid;
      x1  <= px_x;
      y1  <= px_y;
      if rst = '1' then
        pv1 <= '0';
      end if;
    end if;
  end process;

  av_valid <= pv1;
  av_x     <= x1;
  av_y     <= y1;
  av_cbin  <= cb_bin(CB_W - 1 downto 0);   -- PPC > 1: the beat's first pixel (core v2 runs at PPC = 1)

  u_sobel : entity work.ms_sobel
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, ORIENT_T => ORIENT_T, PPC => PPC)
    port map (clk => clk, rst => rst, in_valid => pv1, in_x => x1, in_y => y1,
              in_grey => g_grey, in_cbin => cb_bin_d,
              ip_valid => ip_valid, ip_mask => ip_mask, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_ebin,
              ip_obin => ip_obin);

  -- event delay line
  p_events : process (clk)
  begin
    if rising_edge(clk) then
      ev(1) <= c_start & c_end & c_err & c_code;
      for i in 2 to EVT_DELAY loop
        ev(i) <= ev(i - 1);
      end loop;
      if rst = '1' then
        for i in 1 to EVT_DELAY loop
          ev(i)(EV_W - 1 downto ERR_CODE_W) <= (others => '0');
        end loop;
      end if;
    end if;
  end process;
  error_now   <= c_err;

  -- the all-pixel stream delayed to the frame events
  p_ad : process (clk)
  begin
    if rising_edge(clk) then
      ad(1) <= pv1 & std_logic_vector(x1) & std_logic_vector(y1) & cb_bin(CB_W - 1 downto 0);
      for i in 2 to EVT_DELAY loop
        ad(i) <= ad(i - 1);
      end loop;
      ad_end_r <= ev(EVT_DELAY)(EV_W - 2);
      if rst = '1' then
        ad <= (others => (others => '0'));
        ad_end_r <= '0';
      end if;
    end if;
  end process;
  ad_valid <= ad(EVT_DELAY)(AD_W - 1);
  ad_x     <= unsigned(ad(EVT_DELAY)(AD_W - 2 downto AD_W - 1 - COORD_W));
  ad_y     <= unsigned(ad(EVT_DELAY)(CB_W + COORD_W - 1 downto CB_W));
  ad_cbin  <= ad(EVT_DELAY)(CB_W - 1 downto 0);
  ad_end   <= ad_end_r;
  frame_start <= ev(EVT_DELAY)(EV_W - 1);
  frame_end   <= ev(EVT_DELAY)(EV_W - 2);
  frame_error <= ev(EVT_DELAY)(EV_W - 3);
  err_code    <= ev(EVT_DELAY)(ERR_CODE_W - 1 downto 0);
end architecture;
