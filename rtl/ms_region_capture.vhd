-- ms_region_capture: writes the bins of the search region's pixels into the
-- colour and edge region RAMs (two ms_region_ram, instantiated by the top).
--
-- Computes: on frame_start it latches the region (reg_x, reg_y, reg_w, reg_h;
-- computed by the top, inside the frame interior) and arms; for each interior
-- pixel (ip_x, ip_y) of the front end inside the region, with rx = ip_x - reg_x,
-- ry = ip_y - reg_y, it writes
--   bank  = rx mod LANES                (low bits of rx)
--   waddr = ry * STRIDE + rx / LANES    (row base counter + shift, no multiplier)
--   wdata_colour = ip_cbin, wdata_edge = ip_ebin.
-- The row base counts STRIDE per new region row (the front end delivers every
-- interior row in order).  frame_end or frame_error disarms; done pulses 2
-- clocks after frame_end, once the frame's last write is in the RAMs (a read
-- issued in the done clock or later sees all of them).
-- Latency: ip_valid -> we 2 clocks; frame_end -> done 2 clocks.
-- Throughput: 1 pixel/clock, no handshake.
-- Pixels per clock (PPC = 2 or 4, the front end's ip_* of PPC lanes, lane k = column ip_x + k):
-- the PPC pixels of a beat are consecutive columns of one row, so they fall into PPC different
-- banks (rx mod LANES) when PPC <= LANES; each bank then gets at most one write per clock, on the
-- per-bank write port bwe(b), bwaddr(b), bwdata_colour(b), bwdata_edge(b) (flat vectors, bank b
-- at slice b; same layout, same latency), which the top wires to LANES one-bank ms_region_ram.
-- The shared port (we, wbank, ...) is used only with PPC = 1 (it stays '0' otherwise), the
-- per-bank port only with PPC > 1 (it stays '0' with PPC = 1).  PPC > LANES is refused (generic
-- assertion): two pixels of a beat would need the same bank.  Lanes outside the interior (the
-- first beat of a line, ip_x + k < 1) are outside the region anyway (reg_x >= 1).
-- Python model: mstrack.fixed.blocks.ms_region_capture (region pixel (rx, ry)
-- holds colour[ry, rx], edge[ry, rx]).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_region_capture is
  generic (
    LANES          : natural := 2;    -- RAM banks (power of two)
    COORD_W        : natural := 12;   -- width of x, y and of the region
    REGION_MAX     : natural := 191;  -- largest region extent (reg_w, reg_h <= REGION_MAX)
    STRIDE         : natural := 96;   -- words per region row per bank = ceil(REGION_MAX / LANES)
    ADDR_W         : natural := 15;   -- RAM address width (bits_for(REGION_MAX * STRIDE - 1))
    COLOUR_BITS    : natural range 1 to 8 := 3;  -- colour bin = 3 * COLOUR_BITS bits
    EDGE_BINS_LOG2 : natural range 1 to 8 := 4;  -- edge bin width
    PPC            : positive := 1               -- pixels per clock of ip_*: 1, 2 or 4 (<= LANES)
  );
  port (
    clk          : in  std_logic;                                          -- clock
    rst          : in  std_logic;                                          -- synchronous reset, active high
    frame_start  : in  std_logic;                                          -- from ms_frontend: latch the region, arm
    frame_end    : in  std_logic;                                          -- from ms_frontend: good frame complete
    frame_error  : in  std_logic;                                          -- from ms_frontend: frame abandoned (disarm)
    reg_x        : in  unsigned(COORD_W - 1 downto 0);                     -- region first column (sampled on frame_start)
    reg_y        : in  unsigned(COORD_W - 1 downto 0);                     -- region first row
    reg_w        : in  unsigned(COORD_W - 1 downto 0);                     -- region width (1 .. REGION_MAX)
    reg_h        : in  unsigned(COORD_W - 1 downto 0);                     -- region height (1 .. REGION_MAX)
    ip_valid     : in  std_logic;                                          -- interior pixel(s) (ms_frontend)
    ip_x         : in  unsigned(COORD_W - 1 downto 0);                     -- column of lane 0
    ip_y         : in  unsigned(COORD_W - 1 downto 0);                     -- its row
    ip_cbin      : in  std_logic_vector(PPC * 3 * COLOUR_BITS - 1 downto 0);  -- colour bin per lane
    ip_ebin      : in  std_logic_vector(PPC * EDGE_BINS_LOG2 - 1 downto 0);   -- edge bin per lane
    we           : out std_logic;                                          -- RAM write enable (both RAMs)
    wbank        : out unsigned(clog2(LANES) - 1 downto 0);                -- RAM bank
    waddr        : out unsigned(ADDR_W - 1 downto 0);                      -- RAM word address
    wdata_colour : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0);     -- colour RAM data
    wdata_edge   : out std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);      -- edge RAM data
    done         : out std_logic;                                          -- pulse: region of a good frame captured
    -- per-bank write port (PPC > 1 only): bank b at slice b
    bwe           : out std_logic_vector(LANES - 1 downto 0);                         -- write enable of bank b
    bwaddr        : out std_logic_vector(LANES * ADDR_W - 1 downto 0);                -- its word address
    bwdata_colour : out std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);       -- its colour data
    bwdata_edge   : out std_logic_vector(LANES * EDGE_BINS_LOG2 - 1 downto 0)         -- its edge data
  );
end entity;

architecture rtl of ms_region_capture is
  constant LOG2L  : natural := log2_lanes(LANES);  -- log2(LANES), 0 for 1 lane
  constant BANK_W : natural := clog2(LANES);

  signal armed    : std_logic := '0';
  signal x0, y0   : unsigned(COORD_W - 1 downto 0);  -- region origin
  signal x1, y1   : unsigned(COORD_W downto 0);      -- region end (exclusive)
  signal row_y    : unsigned(COORD_W - 1 downto 0);  -- row of row_base
  signal row_base : unsigned(ADDR_W - 1 downto 0);   -- ry * STRIDE of row_y
  -- stage 1
  signal v1       : std_logic := '0';
  signal base1    : unsigned(ADDR_W - 1 downto 0);
  signal rx1      : unsigned(COORD_W - 1 downto 0);
  signal c1       : std_logic_vector(3 * COLOUR_BITS - 1 downto 0);
  signal e1       : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal end1     : std_logic := '0';
begin
  assert 2 ** LOG2L = LANES report "ms_region_capture: LANES must be a power of two" severity failure;
  assert STRIDE * LANES >= REGION_MAX report "ms_region_capture: STRIDE < REGION_MAX / LANES" severity failure;

  assert PPC = 1 or PPC = 2 or PPC = 4 report "ms_region_capture: PPC must be 1, 2 or 4" severity failure;
  assert PPC <= LANES report "ms_region_capture: PPC > LANES is not supported (two pixels of a beat in one bank)"
    severity failure;

  ---------------------------------------------------------------------------- one pixel per clock
  g_ppc1 : if PPC = 1 generate
    p_capture : process (clk)
      variable inside : boolean;
      variable base   : unsigned(ADDR_W - 1 downto 0);
    begin
      if rising_edge(clk) then
        -- stage 1: inside test, row base
        inside := armed = '1' and ip_valid = '1'
                  and ip_x >= x0 and resize(ip_x, COORD_W + 1) < x1
                  and ip_y >= y0 and resize(ip_y, COORD_W + 1) < y1;
        base := row_base;
        if inside and ip_y /= row_y then
          base := row_base + STRIDE;
          row_base <= base;
          row_y    <= ip_y;
        end if;
        v1    <= '1' when inside else '0';
        base1 <= base;
        rx1   <= ip_x - x0;
        c1    <= ip_cbin;
        e1    <= ip_ebin;
        end1  <= frame_end and armed;
        -- stage 2: RAM write
        we           <= v1;
        wbank        <= resize(rx1, BANK_W);
        waddr        <= base1 + resize(shift_right(rx1, LOG2L), ADDR_W);
        wdata_colour <= c1;
        wdata_edge   <= e1;
        done         <= end1;
        -- control
        if frame_end = '1' or frame_error = '1' then
          armed <= '0';
        end if;
        if frame_start = '1' then
          armed    <= '1';
          x0       <= reg_x;
          y0       <= reg_y;
          x1       <= resize(reg_x, COORD_W + 1) + reg_w;
          y1       <= resize(reg_y, COORD_W + 1) + reg_h;
          row_y    <= reg_y;
          row_base <= (others => '0');
        end if;
        if rst = '1' then
          armed <= '0';
          v1    <= '0';
          end1  <= '0';
          we    <= '0';
          done  <= '0';
        end if;
      end if;
    end process;
    bwe <= (others => '0');
    bwaddr <= (others => '0');
    bwdata_colour <= (others => '0');
    bwdata_edge <= (others => '0');
  end generate;

  ---------------------------------------------------------------------------- PPC pixels per clock
  g_ppcn : if PPC > 1 generate
    constant CB_W : natural := 3 * COLOUR_BITS;
    constant EB_W : natural := EDGE_BINS_LOG2;
    type rx_arr is array (0 to PPC - 1) of unsigned(COORD_W - 1 downto 0);
    signal vl1 : std_logic_vector(PPC - 1 downto 0) := (others => '0');  -- lane k inside the region
    signal rxl : rx_arr;                                                  -- its region column
    signal cl1 : std_logic_vector(PPC * CB_W - 1 downto 0);
    signal el1 : std_logic_vector(PPC * EB_W - 1 downto 0);
  begin
    we <= '0';
    wbank <= (others => '0');
    waddr <= (others => '0');
    wdata_colour <= (others => '0');
    wdata_edge <= (others => '0');

    p_capture_n : process (clk)
      variable inside, any : boolean;
      variable col    : unsigned(COORD_W - 1 downto 0);
      variable base   : unsigned(ADDR_W - 1 downto 0);
      variable row_in : boolean;
    begin
      if rising_edge(clk) then
        -- stage 1: inside test per lane (all lanes share the row), row base
        row_in := armed = '1' and ip_valid = '1' and ip_y >= y0 and resize(ip_y, COORD_W + 1) < y1;
        any := false;
        for k in 0 to PPC - 1 loop
          col := ip_x + k;
          inside := row_in and col >= x0 and resize(col, COORD_W + 1) < x1;
          vl1(k) <= '1' when inside else '0';
          rxl(k) <= col - x0;
          any := any or inside;
        end loop;
        base := row_base;
        if any and ip_y /= row_y then
          base := row_base + STRIDE;
          row_base <= base;
          row_y    <= ip_y;
        end if;
        base1 <= base;
        cl1   <= ip_cbin;
        el1   <= ip_ebin;
        end1  <= frame_end and armed;
        -- stage 2: lane k -> bank rx mod LANES (PPC consecutive columns: PPC different banks)
        for bk in 0 to LANES - 1 loop
          bwe(bk) <= '0';
          for k in 0 to PPC - 1 loop
            if vl1(k) = '1' and resize(rxl(k), BANK_W) = to_unsigned(bk, BANK_W) then
              bwe(bk) <= '1';
              bwaddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk) <=
                std_logic_vector(base1 + resize(shift_right(rxl(k), LOG2L), ADDR_W));
              bwdata_colour(CB_W * (bk + 1) - 1 downto CB_W * bk) <= cl1(CB_W * (k + 1) - 1 downto CB_W * k);
              bwdata_edge(EB_W * (bk + 1) - 1 downto EB_W * bk) <= el1(EB_W * (k + 1) - 1 downto EB_W * k);
            end if;
          end loop;
        end loop;
        done <= end1;
        -- control
        if frame_end = '1' or frame_error = '1' then
          armed <= '0';
        end if;
        if frame_start = '1' then
          armed    <= '1';
          x0       <= reg_x;
          y0       <= reg_y;
          x1       <= resize(reg_x, COORD_W + 1) + reg_w;
          y1       <= resize(reg_y, COORD_W + 1) + reg_h;
          row_y    <= reg_y;
          row_base <= (others => '0');
        end if;
        if rst = '1' then
          armed <= '0';
          vl1   <= (others => '0');
          end1  <= '0';
          bwe   <= (others => '0');
          done  <= '0';
        end if;
      end if;
    end process;
  end generate;
end architecture;
