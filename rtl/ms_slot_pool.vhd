-- ms_slot_pool: the region slots of the shared-engine multi-target core: N_SLOTS ms_slot_capture,
-- each writing its own ms_region_ram (a slot of whole block RAM tiles), and the engine's read port,
-- which reads the banks of one slot at a time.
--
-- Computes: slot s holds mstrack.fixed.blocks_v2.ms_slot_capture(bins, D_s, region_s) of the last
-- region captured into it (layout slot_words: region pixel (rx, ry) at bank rx mod LANES, word
-- ry * STRIDE + rx / LANES); the read port returns, RD_LAT + 1 clocks after (rd_slot, raddr), the
-- words at raddr(b) of every bank b of slot rd_slot.
-- Descriptors: one shared bus, taken by slot load_slot on `load` (ms_slot_capture's rules: between
-- frames or with load_now = '0' for the next frame, in a frame_start clock for that frame,
-- load_now = '1' for this frame); armed, pending, released and late per slot.
-- Every slot sees every pixel: a pixel inside k regions is written k times, each slot through its
-- own RAM's write port, so nothing waits.
-- Latency: ip_valid -> the slot RAM's write port 3 clocks (ms_slot_capture), + WR_LAT into the RAM;
-- read: RD_LAT clocks in the slot RAMs + 1 registered multiplexer stage.  A read issued in a slot's
-- released clock or later sees its region (WR_LAT 0; with WR_LAT 1 a clock later).
-- Throughput: 1 pixel per clock in; LANES words per clock out.
-- Cost: N_SLOTS x (ms_slot_capture + ms_region_ram of REGION_MAX x STRIDE words per bank) + the
-- N_SLOTS-way read multiplexer (docs/blocks/ms_slot_pool.md).
-- Reset: synchronous, active high (the captures; the RAMs keep their contents).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_pool is
  generic (
    N_SLOTS    : positive := 2;                -- slots (targets)
    LANES      : natural := 4;                 -- RAM banks (power of two)
    COORD_W    : natural := 12;                -- width of x, y and of the bounds
    REGION_MAX : natural := 256;               -- largest region extent (decimated px)
    STRIDE     : natural := 64;                -- words per region row per bank
    ADDR_W     : natural := 14;                -- slot address width
    DATA_W     : natural := 9;                 -- bits per pixel
    LOG2_D_MAX : natural range 0 to 7 := 4;    -- largest log2 D
    RD_LAT     : positive := 3;                -- slot RAM read latency (ms_region_ram)
    WR_LAT     : natural := 1                  -- slot RAM write latency (ms_region_ram)
  );
  port (
    clk         : in  std_logic;                                        -- clock
    rst         : in  std_logic;                                        -- synchronous reset, active high
    frame_start : in  std_logic;                                        -- ms_frontend's frame events
    frame_end   : in  std_logic;
    frame_error : in  std_logic;
    ip_valid    : in  std_logic;                                        -- ms_frontend's interior pixels
    ip_x        : in  unsigned(COORD_W - 1 downto 0);
    ip_y        : in  unsigned(COORD_W - 1 downto 0);
    ip_data     : in  std_logic_vector(DATA_W - 1 downto 0);
    -- descriptor bus
    load        : in  std_logic;                                        -- slot load_slot takes the descriptor
    load_slot   : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);
    load_now    : in  std_logic;
    dec_log2    : in  unsigned(2 downto 0);
    fx0, fy0    : in  unsigned(COORD_W - 1 downto 0);                   -- the region at full resolution
    fx1, fy1    : in  unsigned(COORD_W - 1 downto 0);
    -- per slot
    armed       : out std_logic_vector(N_SLOTS - 1 downto 0);
    pending     : out std_logic_vector(N_SLOTS - 1 downto 0);
    released    : out std_logic_vector(N_SLOTS - 1 downto 0);
    late        : out std_logic_vector(N_SLOTS - 1 downto 0);
    -- the engine's read port
    rd_slot     : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);     -- slot to read
    raddr       : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);    -- word of bank b at slice b
    rdata       : out std_logic_vector(LANES * DATA_W - 1 downto 0)     -- RD_LAT + 1 clocks later
  );
end entity;

architecture rtl of ms_slot_pool is
  constant SEL_W : natural := bits_for(N_SLOTS - 1);
  type data_arr is array (0 to N_SLOTS - 1) of std_logic_vector(LANES * DATA_W - 1 downto 0);
  type sel_arr is array (1 to RD_LAT) of unsigned(SEL_W - 1 downto 0);
  signal slot_data : data_arr;
  signal sel_d     : sel_arr;
begin
  g_slot : for s in 0 to N_SLOTS - 1 generate
    signal s_load : std_logic;
    signal we     : std_logic;
    signal wbank  : unsigned(clog2(LANES) - 1 downto 0);
    signal waddr  : unsigned(ADDR_W - 1 downto 0);
    signal wdata  : std_logic_vector(DATA_W - 1 downto 0);
  begin
    s_load <= load when load_slot = to_unsigned(s, SEL_W) else '0';

    u_cap : entity work.ms_slot_capture
      generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                   ADDR_W => ADDR_W, DATA_W => DATA_W, LOG2_D_MAX => LOG2_D_MAX)
      port map (clk => clk, rst => rst, frame_start => frame_start, frame_end => frame_end,
                frame_error => frame_error, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y,
                ip_data => ip_data, load => s_load, load_now => load_now, dec_log2 => dec_log2,
                fx0 => fx0, fy0 => fy0, fx1 => fx1, fy1 => fy1, armed => armed(s), pending => pending(s),
                released => released(s), late => late(s), we => we, wbank => wbank, waddr => waddr,
                wdata => wdata);

    u_ram : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => DATA_W, ADDR_W => ADDR_W,
                   RD_LAT => RD_LAT, WR_LAT => WR_LAT)
      port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wdata, raddr => raddr,
                rdata => slot_data(s));
  end generate;

  -- the read multiplexer: rd_slot delayed with the RAMs' read, then one registered selection
  p_rd : process (clk)
  begin
    if rising_edge(clk) then
      sel_d(1) <= rd_slot;
      for i in 2 to RD_LAT loop
        sel_d(i) <= sel_d(i - 1);
      end loop;
      rdata <= (others => '0');
      for s in 0 to N_SLOTS - 1 loop
        if sel_d(RD_LAT) = to_unsigned(s, SEL_W) then
          rdata <= slot_data(s);
        end if;
      end loop;
    end if;
  end process;
end architecture;
