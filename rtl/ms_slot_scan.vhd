-- ms_slot_scan: the init job's pixel stream: every pixel of the rectangle captured in a slot, one per
-- clock in raster order, with its coordinates relative to the rectangle, for ms_bg_model
-- (docs/multi_target_core.md, "The init job").
--
-- Computes: mstrack.fixed.blocks_v2.ms_slot_scan(region): pixel (rx, ry) of the slot for ry = 0 ..
-- rect_h - 1, rx = 0 .. rect_w - 1, read from bank rx mod LANES, word ry STRIDE + rx / LANES (the
-- layout ms_slot_capture writes, blocks_v2.slot_words).  Every clock one read: the word of the
-- pixel it issues on every bank (raddr), the pixel's lane taken from rdata RD_LAT clocks later.
-- Latency: `start` -> the first pixel RD_LAT + 2 clocks (the issue register, the read, the lane
-- register); then one pixel per clock, rect_w x rect_h in all, `px_last` with the last; `busy` from
-- `start` to the clock after `px_last`.
-- Throughput: one pixel per clock (the count RAM of ms_bg_model takes one per clock).
-- Handshake: `start` with rect_w, rect_h (>= 1, rect_w <= LANES STRIDE) is taken when busy = 0; no
-- back-pressure.
-- Reset: synchronous, active high: idle.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_scan is
  generic (
    LANES    : natural := 4;        -- slot RAM banks (power of two)
    STRIDE   : natural := 64;       -- words per rectangle row per bank
    ADDR_W   : natural := 14;       -- slot word address width
    DATA_W   : natural := 13;       -- bits per pixel (colour bin, + orientation bin)
    REGION_W : natural := 9;        -- rect_w, rect_h, px_x, px_y bits
    RD_LAT   : positive := 4        -- read latency of the slot's read port (raddr -> rdata)
  );
  port (
    clk      : in  std_logic;
    rst      : in  std_logic;
    start    : in  std_logic;                                     -- scan a rectangle (when busy = 0)
    rect_w   : in  unsigned(REGION_W - 1 downto 0);               -- its size (pixels)
    rect_h   : in  unsigned(REGION_W - 1 downto 0);
    busy     : out std_logic;
    -- the slot's read port
    raddr    : out std_logic_vector(LANES * ADDR_W - 1 downto 0); -- word of bank b at slice b
    rdata    : in  std_logic_vector(LANES * DATA_W - 1 downto 0); -- RD_LAT clocks after raddr
    -- the pixels
    px_valid : out std_logic;
    px_x     : out unsigned(REGION_W - 1 downto 0);               -- relative to the rectangle
    px_y     : out unsigned(REGION_W - 1 downto 0);
    px_data  : out std_logic_vector(DATA_W - 1 downto 0);
    px_last  : out std_logic                                      -- with the last pixel
  );
end entity;

architecture rtl of ms_slot_scan is
  constant LANE_W : natural := log2_lanes(LANES);
  type tag_t is record
    v, l : std_logic;
    x, y : unsigned(REGION_W - 1 downto 0);
  end record;
  type tag_arr is array (0 to RD_LAT) of tag_t;
  constant NO_TAG : tag_t := (v => '0', l => '0', x => (others => '0'), y => (others => '0'));
  signal tags       : tag_arr := (others => NO_TAG);              -- tags(0): the read being issued
  signal run        : std_logic := '0';
  signal cx, cy     : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal w_r, h_r   : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal row_base   : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal word       : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal o_valid, o_last : std_logic := '0';
  signal o_x, o_y   : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal o_data     : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
  signal busy_i     : std_logic;
begin
  -- every bank reads the same word: the rectangle starts at the slot's column 0
  g_addr : for b in 0 to LANES - 1 generate
    raddr((b + 1) * ADDR_W - 1 downto b * ADDR_W) <= std_logic_vector(word);
  end generate;

  p_scan : process (clk)
    variable t    : tag_t;
    variable lane : natural range 0 to LANES - 1;
  begin
    if rising_edge(clk) then
      -- issue: the pixel (cx, cy) of the word row_base + cx / LANES
      t := NO_TAG;
      if run = '1' then
        t := (v => '1', l => '0', x => cx, y => cy);
        word <= row_base + resize(shift_right(cx, LANE_W), ADDR_W);
        if cx = w_r - 1 then
          cx <= (others => '0');
          row_base <= row_base + STRIDE;
          if cy = h_r - 1 then
            t.l := '1';
            run <= '0';
          else
            cy <= cy + 1;
          end if;
        else
          cx <= cx + 1;
        end if;
      end if;
      tags(0) <= t;
      for i in 1 to RD_LAT loop
        tags(i) <= tags(i - 1);
      end loop;
      -- the pixel's lane of the word read RD_LAT clocks after its issue
      lane := 0;
      if LANES > 1 then
        lane := to_integer(tags(RD_LAT).x(LANE_W - 1 downto 0));
      end if;
      o_valid <= tags(RD_LAT).v;
      o_last <= tags(RD_LAT).l;
      o_x <= tags(RD_LAT).x;
      o_y <= tags(RD_LAT).y;
      o_data <= rdata((lane + 1) * DATA_W - 1 downto lane * DATA_W);
      if start = '1' and busy_i = '0' then
        run <= '1';
        cx <= (others => '0');
        cy <= (others => '0');
        w_r <= rect_w;
        h_r <= rect_h;
        row_base <= (others => '0');
      end if;
      if rst = '1' then
        run <= '0';
        tags <= (others => NO_TAG);
        o_valid <= '0';
        o_last <= '0';
      end if;
    end if;
  end process;

  p_busy : process (all)
    variable b : std_logic;
  begin
    b := run or o_valid;
    for i in 0 to RD_LAT loop
      b := b or tags(i).v;
    end loop;
    busy_i <= b;
  end process;
  busy     <= busy_i;
  px_valid <= o_valid;
  px_last  <= o_last;
  px_x     <= o_x;
  px_y     <= o_y;
  px_data  <= o_data;
end architecture;
