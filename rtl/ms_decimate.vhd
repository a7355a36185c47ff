-- ms_decimate: decimated interior-pixel stream of tracker v2 (between ms_frontend and
-- ms_region_capture / the init model counters).
--
-- Computes: on frame_start it latches log2 D (dec_log2, D = 1 .. 2**LOG2_D_MAX) for the frame;
-- each interior pixel (ip_x, ip_y) of the front end with ip_x mod D = 0 and ip_y mod D = 0
-- is passed on as pixel (ip_x / D, ip_y / D) of the decimated frame frame[::D, ::D], with its
-- colour and edge bins; the others are dropped.  The frame events are passed on with the same
-- delay, so they keep their order with the pixels (frame_end still comes 1 clock after the
-- frame's last pixel, as ms_region_capture needs for its `done`).
-- Every pixel of the decimated interior (1 .. Wd - 2, Wd = ceil(W / D) = ((W - 1) >> log2 D) + 1)
-- is a frame interior pixel (D <= x D <= (Wd - 2) D <= W - 1 - D), so the decimated interior
-- comes out complete and in raster order: ms_region_capture fed with this stream and a region
-- of the decimated frame (mstrack.fixed.blocks.ms_region on the decimated size) writes
-- exactly tracker_v2._capture(frame[::D, ::D], region) into the colour RAM.
-- The edge bin passed on is the full-resolution one of pixel (x D, y D) (v2 tracks on colour
-- only: the edge RAM is unused there).
-- D = 1 (dec_log2 = 0) passes every pixel unchanged, 1 clock later.
-- Latency: 1 clock (pixels and events).  Throughput: 1 pixel per clock, no handshake.
-- Cost: two COORD_W-bit barrel shifters (x, y), the low-bit test, 2 COORD_W + bins + 8 FF
-- (docs/blocks/ms_decimate.md: 80 LUT4, 47 FF for the v2 defaults).
-- dec_log2 above LOG2_D_MAX gives D = 1.
-- Python model: frame[::D, ::D] (mstrack.fixed.tracker_v2.FixedTrackerV2._bins / _capture).
-- Reset: synchronous, active high; valid and event flags, dec_log2 latch back to D = 1.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_decimate is
  generic (
    COORD_W        : natural := 12;              -- width of x, y
    LOG2_D_MAX     : natural range 0 to 7 := 4;  -- largest log2 D (4: D = 16, lost at D = 8)
    COLOUR_BITS    : natural range 1 to 8 := 3;  -- colour bin = 3 * COLOUR_BITS bits
    EDGE_BINS_LOG2 : natural range 1 to 8 := 4   -- edge bin width
  );
  port (
    clk          : in  std_logic;                                       -- clock
    rst          : in  std_logic;                                       -- synchronous reset, active high
    dec_log2     : in  unsigned(2 downto 0);                            -- log2 D of the next frame (sampled on frame_start)
    -- from ms_frontend
    frame_start  : in  std_logic;                                       -- a frame started: latch dec_log2
    frame_end    : in  std_logic;                                       -- good frame complete (after its last pixel)
    frame_error  : in  std_logic;                                       -- frame abandoned
    ip_valid     : in  std_logic;                                       -- interior pixel
    ip_x         : in  unsigned(COORD_W - 1 downto 0);                  -- its column
    ip_y         : in  unsigned(COORD_W - 1 downto 0);                  -- its row
    ip_cbin      : in  std_logic_vector(3 * COLOUR_BITS - 1 downto 0);  -- its colour bin
    ip_ebin      : in  std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);   -- its edge bin
    -- decimated stream (to ms_region_capture)
    dp_start     : out std_logic;                                       -- frame_start, 1 clock later
    dp_end       : out std_logic;                                       -- frame_end, 1 clock later
    dp_error     : out std_logic;                                       -- frame_error, 1 clock later
    dp_valid     : out std_logic;                                       -- decimated pixel
    dp_x         : out unsigned(COORD_W - 1 downto 0);                  -- its column ip_x / D
    dp_y         : out unsigned(COORD_W - 1 downto 0);                  -- its row ip_y / D
    dp_cbin      : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0);  -- its colour bin
    dp_ebin      : out std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);   -- its edge bin (full resolution)
    dec_q        : out unsigned(2 downto 0)                             -- log2 D of the current frame
  );
end entity;

architecture rtl of ms_decimate is
  constant LW : natural := LOG2_D_MAX + 1;  -- low bits tested (mask width, at least 1)
  signal k     : unsigned(2 downto 0) := (others => '0');           -- log2 D of the frame
  signal mask  : unsigned(LW - 1 downto 0) := (others => '0');      -- D - 1
begin
  assert LOG2_D_MAX < COORD_W report "ms_decimate: LOG2_D_MAX >= COORD_W" severity failure;

  p_dec : process (clk)
    variable on_grid : boolean;
    variable xs, ys  : unsigned(COORD_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      on_grid := (resize(ip_x, LW) and mask) = 0 and (resize(ip_y, LW) and mask) = 0;
      xs := shift_right(ip_x, to_integer(k));  -- k <= LOG2_D_MAX (latched below)
      ys := shift_right(ip_y, to_integer(k));
      dp_valid <= '1' when ip_valid = '1' and on_grid else '0';
      dp_x     <= xs;
      dp_y     <= ys;
      dp_cbin  <= ip_cbin;
      dp_ebin  <= ip_ebin;
      dp_start <= frame_start;
      dp_end   <= frame_end;
      dp_error <= frame_error;
      if frame_start = '1' then
        k <= (others => '0');
        mask <= (others => '0');
        for i in 1 to LOG2_D_MAX loop
          if dec_log2 = i then
            k    <= to_unsigned(i, 3);
            mask <= to_unsigned(2 ** i - 1, LW);
          end if;
        end loop;
      end if;
      if rst = '1' then
        dp_valid <= '0';
        dp_start <= '0';
        dp_end   <= '0';
        dp_error <= '0';
        k        <= (others => '0');
        mask     <= (others => '0');
      end if;
    end if;
  end process;
  dec_q <= k;
end architecture;
