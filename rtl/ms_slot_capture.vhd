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
-- (mstrack.fixed.blocks_v2.ms_slot_capture).
--
-- Descriptor (dec_log2, reg_*), taken on `load`; one load, one capture:
--   * load_now = '0', or any load between frames: for the next frame (taken at its frame_start; a
--     second load before it replaces the first);
--   * load_now = '1' during a frame: for this frame, from the next pixel on.  If a pixel of the
--     region's first full-resolution row (reg_y * D) or a later row has already arrived (in the load
--     clock included), nothing is captured and `late` pulses: the deadline of the target's job was
--     missed (the capacity rule of mstrack.fixed.multi_capacity makes that impossible).
--   A frame without a load for it captures nothing.  A load_now while a capture is armed replaces
--   it (that capture ends without a release).
-- `released` pulses once per captured frame when the region is complete in the slot: on the first
-- pixel below its last full-resolution row ((reg_y + reg_h - 1) * D), else at frame_end; every
-- write of the region has reached the port at least one clock before (a read issued in the
-- released clock or later sees them all, as ms_region_capture's done).  The release comes at most
-- D + 1 input lines after the region's last row has streamed in (the capacity rule's
-- `release_line`).  frame_error disarms without a release.
-- dec_log2 above LOG2_D_MAX gives D = 1 (as ms_decimate).
-- Latency: ip_valid -> we 3 clocks; the release 3 clocks after its pixel, 4 after frame_end.
-- Throughput: 1 pixel per clock, no handshake.
-- Python model: mstrack.fixed.blocks_v2.ms_slot_capture (the slot's words) and
-- mstrack.fixed.multi_capacity.TargetDemand.release_line (the bound on the release).
-- Reset: synchronous, active high: nothing armed, nothing pending.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_capture is
  generic (
    LANES      : natural := 4;                 -- RAM banks (power of two)
    COORD_W    : natural := 12;                -- width of x, y and of the region
    REGION_MAX : natural := 256;               -- largest region extent (reg_w, reg_h <= REGION_MAX)
    STRIDE     : natural := 64;                -- words per region row per bank (>= REGION_MAX / LANES)
    ADDR_W     : natural := 14;                -- slot address width
    DATA_W     : natural := 9;                 -- bits per pixel (colour bin 9; joint: + orientation 4)
    LOG2_D_MAX : natural range 0 to 7 := 4     -- largest log2 D
  );
  port (
    clk         : in  std_logic;                                -- clock
    rst         : in  std_logic;                                -- synchronous reset, active high
    -- full-resolution interior pixels (ms_frontend, PPC 1)
    frame_start : in  std_logic;                                -- a frame started
    frame_end   : in  std_logic;                                -- good frame complete (after its last pixel)
    frame_error : in  std_logic;                                -- frame abandoned
    ip_valid    : in  std_logic;                                -- interior pixel
    ip_x        : in  unsigned(COORD_W - 1 downto 0);           -- its column
    ip_y        : in  unsigned(COORD_W - 1 downto 0);           -- its row
    ip_data     : in  std_logic_vector(DATA_W - 1 downto 0);    -- its bins
    -- descriptor
    load        : in  std_logic;                                -- take dec_log2, reg_*
    load_now    : in  std_logic;                                -- '1': for the frame streaming now
    dec_log2    : in  unsigned(2 downto 0);                     -- log2 D
    reg_x       : in  unsigned(COORD_W - 1 downto 0);           -- region first column (decimated px)
    reg_y       : in  unsigned(COORD_W - 1 downto 0);           -- region first row
    reg_w       : in  unsigned(COORD_W - 1 downto 0);           -- region width (1 .. REGION_MAX)
    reg_h       : in  unsigned(COORD_W - 1 downto 0);           -- region height (1 .. REGION_MAX)
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
  function log2_lanes(n : natural) return natural is
  begin
    if n <= 1 then
      return 0;
    end if;
    return clog2(n);
  end function;
  constant LOG2L  : natural := log2_lanes(LANES);
  constant BANK_W : natural := clog2(LANES);
  constant LW     : natural := LOG2_D_MAX + 1;          -- low bits of the grid test
  constant YW     : natural := COORD_W + LOG2_D_MAX;    -- a decimated row back at full resolution

  type desc_t is record
    k            : unsigned(2 downto 0);                -- log2 D (0 .. LOG2_D_MAX)
    x0, y0       : unsigned(COORD_W - 1 downto 0);      -- region origin (decimated)
    x1, y1       : unsigned(COORD_W downto 0);          -- region end, exclusive (decimated)
    first, last  : unsigned(YW - 1 downto 0);           -- its first and last full-resolution rows
  end record;

  -- the descriptor of a load, its log2 D clamped as ms_decimate's
  function to_desc(l2 : unsigned(2 downto 0); x, y, w, h : unsigned(COORD_W - 1 downto 0)) return desc_t is
    variable d : desc_t;
  begin
    d.k := (others => '0');
    for i in 1 to LOG2_D_MAX loop
      if l2 = i then
        d.k := to_unsigned(i, 3);
      end if;
    end loop;
    d.x0 := x;
    d.y0 := y;
    d.x1 := resize(x, COORD_W + 1) + w;
    d.y1 := resize(y, COORD_W + 1) + h;
    d.first := shift_left(resize(y, YW), to_integer(d.k));
    d.last := shift_left(resize(d.y1 - 1, YW), to_integer(d.k));
    return d;
  end function;

  function mask_of(k : unsigned(2 downto 0)) return unsigned is
  begin
    return resize(shift_left(to_unsigned(1, LW + 1), to_integer(k)) - 1, LW);
  end function;

  signal cur, nxt   : desc_t;
  signal cap_on     : std_logic := '0';   -- capturing in this frame (armed, not released)
  signal nxt_valid  : std_logic := '0';
  signal in_frame   : std_logic := '0';   -- between frame_start and frame_end / frame_error
  signal seen_any   : std_logic := '0';   -- a pixel of this frame has arrived
  signal seen_y     : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- the row of the last one
  signal row_y      : unsigned(COORD_W - 1 downto 0);  -- decimated row of row_base
  signal row_base   : unsigned(ADDR_W - 1 downto 0);   -- (row_y - y0) * STRIDE
  -- stage 1
  signal g1, rel1, end1 : std_logic := '0';
  signal xd1, yd1   : unsigned(COORD_W - 1 downto 0);
  signal d1         : std_logic_vector(DATA_W - 1 downto 0);
  -- stage 2
  signal v2, rel2   : std_logic := '0';
  signal rx2        : unsigned(COORD_W - 1 downto 0);
  signal base2      : unsigned(ADDR_W - 1 downto 0);
  signal d2         : std_logic_vector(DATA_W - 1 downto 0);
begin
  assert 2 ** LOG2L = LANES report "ms_slot_capture: LANES must be a power of two" severity failure;
  assert STRIDE * LANES >= REGION_MAX report "ms_slot_capture: STRIDE < REGION_MAX / LANES" severity failure;
  assert LOG2_D_MAX < COORD_W report "ms_slot_capture: LOG2_D_MAX >= COORD_W" severity failure;
  assert 2 ** ADDR_W >= REGION_MAX * STRIDE report "ms_slot_capture: ADDR_W too small for REGION_MAX * STRIDE"
    severity failure;

  p_cap : process (clk)
    variable on_grid, inside, is_late, trig : boolean;
    variable base : unsigned(ADDR_W - 1 downto 0);
    variable dsc  : desc_t;
    variable fr_open : std_logic;                 -- the frame streaming now (frame_start clock included)
    variable any_seen : std_logic;
    variable last_seen : unsigned(COORD_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      -- stage 1: grid test and decimated position (cur's D), the release trigger
      on_grid := (resize(ip_x, LW) and mask_of(cur.k)) = 0 and (resize(ip_y, LW) and mask_of(cur.k)) = 0;
      g1   <= '1' when cap_on = '1' and ip_valid = '1' and on_grid else '0';
      xd1  <= shift_right(ip_x, to_integer(cur.k));
      yd1  <= shift_right(ip_y, to_integer(cur.k));
      d1   <= ip_data;
      trig := cap_on = '1' and ip_valid = '1' and resize(ip_y, YW) > cur.last;
      rel1 <= '1' when trig else '0';
      end1 <= cap_on and frame_end;
      -- stage 2: inside the region, row base
      inside := g1 = '1' and xd1 >= cur.x0 and resize(xd1, COORD_W + 1) < cur.x1
                and yd1 >= cur.y0 and resize(yd1, COORD_W + 1) < cur.y1;
      base := row_base;
      if inside and yd1 /= row_y then
        base := row_base + STRIDE;
        row_base <= base;
        row_y    <= yd1;
      end if;
      v2    <= '1' when inside else '0';
      rx2   <= xd1 - cur.x0;
      base2 <= base;
      d2    <= d1;
      rel2  <= rel1 or end1;
      -- stage 3: the slot's write port
      we       <= v2;
      wbank    <= resize(rx2, BANK_W);
      waddr    <= base2 + resize(shift_right(rx2, LOG2L), ADDR_W);
      wdata    <= d2;
      released <= rel2;
      late     <= '0';

      -- control
      if trig then
        cap_on <= '0';                            -- one release per captured frame
      end if;
      -- pixels seen in this frame (the late test of a load_now)
      fr_open := in_frame;
      any_seen := seen_any;
      last_seen := seen_y;
      if frame_start = '1' then
        fr_open := '1';
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
        in_frame  <= '1';
        cap_on    <= nxt_valid;
        cur       <= nxt;
        nxt_valid <= '0';
        row_y     <= nxt.y0;
        row_base  <= (others => '0');
      end if;
      if load = '1' then
        dsc := to_desc(dec_log2, reg_x, reg_y, reg_w, reg_h);
        if load_now = '1' and fr_open = '1' then
          is_late := any_seen = '1' and resize(last_seen, YW) >= dsc.first;
          if is_late then
            late   <= '1';
            cap_on <= '0';
          else
            cap_on   <= '1';
            cur      <= dsc;
            row_y    <= dsc.y0;
            row_base <= (others => '0');
            g1       <= '0';               -- the load clock's pixel was tested with the old descriptor
            rel1     <= '0';               -- (it lies above the new region's first row)
            end1     <= '0';
          end if;
        else
          nxt       <= dsc;
          nxt_valid <= '1';
        end if;
      end if;
      if rst = '1' then
        cap_on    <= '0';
        nxt_valid <= '0';
        in_frame  <= '0';
        seen_any  <= '0';
        g1        <= '0';
        rel1      <= '0';
        end1      <= '0';
        v2        <= '0';
        rel2      <= '0';
        we        <= '0';
        released  <= '0';
        late      <= '0';
      end if;
    end if;
  end process;
  armed   <= cap_on;
  pending <= nxt_valid;
end architecture;
