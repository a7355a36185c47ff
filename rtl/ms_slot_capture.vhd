-- ms_slot_capture: one target's region capture for the shared-engine multi-target core: its own
-- decimation, its own region, its own slot (the write port of one ms_region_ram), armed between
-- frames or during a frame.
--
-- Computes: from the full-resolution interior pixel stream of ms_frontend (PPC 1), the pixels of
-- the decimated frame frame[::D, ::D] (ip_x mod D = 0, ip_y mod D = 0, as ms_decimate) whose
-- decimated position (ip_x / D, ip_y / D) is inside the region (reg_x, reg_y, reg_w, reg_h, in
-- decimated px), written as ms_region_capture writes them: rx = ip_x / D - reg_x,
-- ry = ip_y / D - reg_y,
--   wbank = rx mod LANES, waddr = ry * STRIDE + rx / LANES, wdata = ip_data.
-- So the slot holds FixedTrackerV2._capture(frame[::D, ::D], region)
-- (mstrack.fixed.blocks_v2.ms_slot_capture).  A region that reaches the frame's border (an init
-- rectangle, docs/multi_target_core.md "Border pixels") gets the pixels the stream brings: with
-- INTERIOR_ONLY (the Sobel's stream) none on the border, and rows start at region column 1 when the
-- region starts at the frame's column 0 (the top row needs nothing: a row is counted when it arrives);
-- without it (the all-pixel stream av_*) every pixel.
-- The region comes at full resolution (fx0 = reg_x D, fy0 = reg_y D, fx1 = (reg_x + reg_w) D,
-- fy1 = (reg_y + reg_h) D: one shifter in the engine serves every slot), so a slot needs no
-- shifter: the inside test compares ip_x, ip_y with the bounds, and rx, ry are counters (every
-- decimated pixel of the region arrives, in raster order: the decimated interior is complete, see
-- ms_decimate).
--
-- Descriptor (dec_log2, fx0, fy0, fx1, fy1), taken on `load`; one load, one capture:
--   * between frames, or load_now = '0' during a frame: for the next frame (armed at its frame_start;
--     a second load before it replaces the first);
--   * in a frame_start clock: for the frame that starts;
--   * load_now = '1' during a frame: for this frame, from the next pixel on.  If a pixel of the
--     region's first full-resolution row (fy0) or a later row has already arrived (in the load clock
--     included), nothing is captured and `late` pulses: the deadline of the target's job was missed
--     (the capacity rule of mstrack.fixed.multi_capacity makes that impossible).
--   A frame without a load for it captures nothing.  A load while a capture is armed (not released)
--   replaces it, which ends that capture without a release (the shared engine loads a slot only
--   after its release, or between frames).
-- `released` pulses once per captured frame when the region is complete in the slot: on the first
-- pixel below its last full-resolution row (fy1 - D), else at frame_end; every
-- write of the region has reached the port at least one clock before (a read issued in the
-- released clock or later sees them all, as ms_region_capture's done).  The release comes at most
-- D + 1 input lines after the region's last row has streamed in (the capacity rule's
-- `release_line`).  frame_error disarms without a release.
-- dec_log2 above LOG2_D_MAX gives D = 1 (as ms_decimate).
-- frame_end may come in the clock of the frame's last pixel (the all-pixel stream's av_end does).
-- Latency: ip_valid -> we 3 clocks; the release 3 clocks after its pixel, 5 after frame_end.
-- Cost (docs/blocks/ms_slot_capture.md): the grid mask, seven COORD_W-bit comparators, two
-- counters, one descriptor register; no shifter, no multiplier.
-- Throughput: 1 pixel per clock, no handshake.
-- Python model: mstrack.fixed.blocks_v2.ms_slot_capture (the slot's words) and
-- mstrack.fixed.multi_capacity.release_line (the bound on the release).
-- Reset: synchronous, active high: nothing armed, nothing pending.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_capture is
  generic (
    LANES      : natural := 4;                 -- RAM banks (power of two)
    COORD_W    : natural := 12;                -- width of x, y and of the bounds
    REGION_MAX : natural := 256;               -- largest region extent (reg_w, reg_h <= REGION_MAX)
    STRIDE     : natural := 64;                -- words per region row per bank (>= REGION_MAX / LANES)
    ADDR_W     : natural := 14;                -- slot address width
    DATA_W     : natural := 9;                 -- bits per pixel (colour bin 9; joint: + orientation 4)
    LOG2_D_MAX : natural range 0 to 7 := 4;    -- largest log2 D
    -- true: the pixel stream is the Sobel's interior stream, which has no pixel in the frame's column 0,
    -- so a region that starts there (an init rectangle's orientation) writes each row from region column
    -- 1 on; false: a stream with every pixel (the front end's av_*, an init rectangle's colour)
    INTERIOR_ONLY : boolean := true
  );
  port (
    clk         : in  std_logic;                                -- clock
    rst         : in  std_logic;                                -- synchronous reset, active high
    -- full-resolution interior pixels (ms_frontend, PPC 1)
    frame_start : in  std_logic;                                -- a frame started
    frame_end   : in  std_logic;                                -- good frame complete (with or after its last pixel)
    frame_error : in  std_logic;                                -- frame abandoned
    ip_valid    : in  std_logic;                                -- interior pixel
    ip_x        : in  unsigned(COORD_W - 1 downto 0);           -- its column
    ip_y        : in  unsigned(COORD_W - 1 downto 0);           -- its row
    ip_data     : in  std_logic_vector(DATA_W - 1 downto 0);    -- its bins
    -- descriptor (the region at full resolution)
    load        : in  std_logic;                                -- take dec_log2, fx0 .. fy1
    load_now    : in  std_logic;                                -- '1': for the frame streaming now
    dec_log2    : in  unsigned(2 downto 0);                     -- log2 D
    fx0         : in  unsigned(COORD_W - 1 downto 0);           -- reg_x D: first column
    fy0         : in  unsigned(COORD_W - 1 downto 0);           -- reg_y D: first row
    fx1         : in  unsigned(COORD_W - 1 downto 0);           -- (reg_x + reg_w) D: column after the last
    fy1         : in  unsigned(COORD_W - 1 downto 0);           -- (reg_y + reg_h) D: row after the last
    -- status
    armed       : out std_logic;                                -- capturing this frame, not released yet
    pending     : out std_logic;                                -- a descriptor waits for the next frame
    released    : out std_logic;                                -- pulse: the region is in the slot
    late        : out std_logic;                                -- pulse: load_now after the region's first row
    -- the slot's write port (ms_region_ram)
    we          : out std_logic;                                -- write enable
    wbank       : out unsigned(clog2(LANES) - 1 downto 0);      -- bank
    waddr       : out unsigned(ADDR_W - 1 downto 0);            -- word address in the slot
    wdata       : out std_logic_vector(DATA_W - 1 downto 0)     -- data
  );
end entity;

architecture rtl of ms_slot_capture is
  constant LOG2L  : natural := log2_lanes(LANES);
  constant BANK_W : natural := clog2(LANES);
  constant LW     : natural := LOG2_D_MAX + 1;          -- low bits of the grid test
  constant CNT_W  : natural := bits_for(REGION_MAX);    -- region column counter

  -- the descriptor: grid mask (D - 1), bounds, the region's last full-resolution row
  signal mask       : unsigned(LW - 1 downto 0);
  signal x0, y0, x1, y1, last : unsigned(COORD_W - 1 downto 0);
  signal cap_on     : std_logic := '0';   -- capturing in this frame (armed, not released)
  signal wait_start : std_logic := '0';   -- armed for the next frame
  signal in_frame   : std_logic := '0';   -- between frame_start and frame_end / frame_error
  signal seen_any   : std_logic := '0';   -- a pixel of this frame has arrived
  signal seen_y     : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- the row of the last one
  signal row_y      : unsigned(COORD_W - 1 downto 0);  -- full-resolution row of the region row being written
  -- stage 1
  signal v1, nr1, rel1, end1 : std_logic := '0';
  signal end2       : std_logic := '0';   -- frame_end's release, one stage behind the pixels
  signal d1         : std_logic_vector(DATA_W - 1 downto 0);
  -- stage 2: region row base and column
  signal row_base   : unsigned(ADDR_W - 1 downto 0);
  signal col_next   : unsigned(CNT_W - 1 downto 0);
  signal col0       : unsigned(CNT_W - 1 downto 0) := (others => '0');   -- a row's first column written
  signal v2, rel2   : std_logic := '0';
  signal base2      : unsigned(ADDR_W - 1 downto 0);
  signal col2       : unsigned(CNT_W - 1 downto 0);
  signal d2         : std_logic_vector(DATA_W - 1 downto 0);
begin
  assert 2 ** LOG2L = LANES report "ms_slot_capture: LANES must be a power of two" severity failure;
  assert STRIDE * LANES >= REGION_MAX report "ms_slot_capture: STRIDE < REGION_MAX / LANES" severity failure;
  assert LOG2_D_MAX < COORD_W report "ms_slot_capture: LOG2_D_MAX >= COORD_W" severity failure;
  assert 2 ** ADDR_W >= REGION_MAX * STRIDE report "ms_slot_capture: ADDR_W too small for REGION_MAX * STRIDE"
    severity failure;

  p_cap : process (clk)
    variable inside, trig, is_late, arm_now : boolean;
    variable m  : unsigned(LW - 1 downto 0);
    variable dv : unsigned(COORD_W - 1 downto 0);
    variable base : unsigned(ADDR_W - 1 downto 0);
    variable col  : unsigned(CNT_W - 1 downto 0);
    variable any_seen : std_logic;
    variable last_seen : unsigned(COORD_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      -- stage 1: grid and inside tests at full resolution, the region row, the release trigger
      inside := cap_on = '1' and ip_valid = '1'
                and (resize(ip_x, LW) and mask) = 0 and (resize(ip_y, LW) and mask) = 0
                and ip_x >= x0 and ip_x < x1 and ip_y >= y0 and ip_y < y1;
      v1  <= '1' when inside else '0';
      nr1 <= '1' when ip_y /= row_y else '0';
      if inside then
        row_y <= ip_y;
      end if;
      d1   <= ip_data;
      trig := cap_on = '1' and ip_valid = '1' and ip_y > last;
      rel1 <= '1' when trig else '0';
      end1 <= cap_on and frame_end;
      -- stage 2: row base (STRIDE per region row) and column (counted along the row)
      base := row_base;
      col := col_next;
      if v1 = '1' and nr1 = '1' then
        base := row_base + STRIDE;
        col := col0;
      end if;
      if v1 = '1' then
        row_base <= base;
        col_next <= col + 1;
      end if;
      v2    <= v1;
      base2 <= base;
      col2  <= col;
      d2    <= d1;
      end2  <= end1;
      rel2  <= rel1 or end2;
      -- stage 3: the slot's write port
      we       <= v2;
      wbank    <= resize(col2, BANK_W);
      waddr    <= base2 + resize(shift_right(col2, LOG2L), ADDR_W);
      wdata    <= d2;
      released <= rel2;
      late     <= '0';

      -- control
      if trig then
        cap_on <= '0';                            -- one release per captured frame
      end if;
      any_seen := seen_any;                       -- pixels of this frame, the load clock's included
      last_seen := seen_y;
      if frame_start = '1' then
        any_seen := '0';
      end if;
      if ip_valid = '1' then
        any_seen := '1';
        last_seen := ip_y;
      end if;
      seen_any <= any_seen;
      seen_y   <= last_seen;
      if frame_end = '1' or frame_error = '1' then
        cap_on   <= '0';
        in_frame <= '0';
      end if;
      if frame_start = '1' then
        in_frame   <= '1';
        cap_on     <= wait_start;
        wait_start <= '0';
      end if;
      arm_now := false;
      if load = '1' then
        m  := (others => '0');                  -- D - 1 and D (dec_log2 above LOG2_D_MAX: D = 1)
        dv := to_unsigned(1, COORD_W);
        for i in 1 to LOG2_D_MAX loop
          if dec_log2 = i then
            m  := to_unsigned(2 ** i - 1, LW);
            dv := to_unsigned(2 ** i, COORD_W);
          end if;
        end loop;
        mask <= m;
        col0 <= (others => '0');
        if INTERIOR_ONLY and fx0 = 0 then         -- column 0 never arrives: rows start at region column 1
          col0 <= to_unsigned(1, CNT_W);
        end if;
        x0   <= fx0;
        y0   <= fy0;
        x1   <= fx1;
        y1   <= fy1;
        last <= fy1 - dv;
        is_late := false;
        if frame_start = '1' then                 -- the frame starting now
          arm_now := true;
        elsif load_now = '1' and in_frame = '1' then
          is_late := any_seen = '1' and last_seen >= fy0;
          arm_now := not is_late;
        end if;
        cap_on     <= '1' when arm_now else '0';
        wait_start <= '0' when arm_now or is_late else '1';
        late       <= '1' when is_late else '0';
      end if;
      -- a new capture: its first region row is row 0
      if arm_now or (frame_start = '1' and wait_start = '1' and load = '0') then
        row_y    <= fy0 when arm_now else y0;
        row_base <= (others => '0');
        if arm_now then
          col_next <= (others => '0');
          if INTERIOR_ONLY and fx0 = 0 then
            col_next <= to_unsigned(1, CNT_W);
          end if;
        else
          col_next <= col0;
        end if;
      end if;
      if arm_now then
        v1   <= '0';                              -- pixels in flight belong to the old descriptor (the
        v2   <= '0';                              -- load clock's lies above the new region's first row)
        rel1 <= '0';
        end1 <= '0';
      end if;
      if rst = '1' then
        cap_on     <= '0';
        wait_start <= '0';
        in_frame   <= '0';
        seen_any   <= '0';
        v1         <= '0';
        rel1       <= '0';
        end1       <= '0';
        end2       <= '0';
        v2         <= '0';
        rel2       <= '0';
        we         <= '0';
        released   <= '0';
        late       <= '0';
      end if;
    end if;
  end process;
  armed   <= cap_on;
  pending <= wait_start;
end architecture;
