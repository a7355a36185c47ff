-- ms_slot_pool: the region slots of the shared-engine multi-target core: per slot a colour RAM and,
-- with ORIENT, an orientation RAM, each written by its own ms_slot_capture (a slot of whole block RAM
-- tiles per memory), and the engine's read port, which reads the banks of one slot at a time.
--
-- Computes: slot s holds mstrack.fixed.blocks_v2.ms_slot_capture(bins, D_s, region_s) of the last
-- region captured into it, for bins = the colour bins and (ORIENT) the orientation bins (layout
-- slot_words: region pixel (rx, ry) at bank rx mod LANES, word ry * STRIDE + rx / LANES); the read
-- port returns, RD_LAT + 2 clocks after (rd_slot, raddr), the words at raddr(b) of every bank b of
-- slot rd_slot, colour on rdata and orientation on robin.
-- Read address: each slot registers raddr in its own copy, loaded only in the clocks rd_slot selects
-- it, in front of its RAMs.  The copies are what the placer spreads over the die beside their block
-- RAMs: the shared read address no longer drives every slot RAM's address and enable pins itself.
-- A reader that has its address a clock early (ms_engine's ram_addr_next) sees RD_LAT + 1.
-- Streams (docs/multi_target_core.md, "Border pixels"): the colour RAM is captured from ms_frontend's
-- all-pixel stream delayed to the frame events (ad_*, every pixel, the frame's border included), the
-- orientation RAM from its interior stream (ip_*, no border pixel: INTERIOR_ONLY).  Both captures take
-- the same frame events: frame_start, frame_error and ad_end (1 clock after frame_end; on the
-- interior stream it comes 2 clocks after the last pixel).  So a descriptor reaches both captures for
-- the same frame.  A border pixel's orientation is not written: ms_init_job counts it with
-- orientation 8 and never reads it.
-- Descriptors: one shared bus, taken by slot load_slot on `load` for both captures (ms_slot_capture's
-- rules: between frames or with load_now = '0' for the next frame, in a frame_start clock for that
-- frame, load_now = '1' for this frame); armed, pending, released and late per slot.
--   * released: the orientation capture's release (ORIENT), else the colour capture's.  The colour
--     capture never releases later: the ad stream brings row y about one input line before the
--     interior stream brings it, and a region with no pixel below it on either stream is released
--     by both at ad_end.  So the slot is complete in both RAMs when `released` pulses;
--   * late: either capture's (the colour one's deadline is the earlier: its stream leads by a line);
--   * armed, pending: either capture's.
-- Every slot sees every pixel: a pixel inside k regions is written k times, each slot through its
-- own RAMs' write ports, so nothing waits.
-- Latency: a pixel -> its slot RAM's write port 3 clocks (ms_slot_capture), + WR_LAT into the RAM;
-- read: 1 address register per slot + RD_LAT clocks in the slot RAMs + 1 registered multiplexer
-- stage.  A read issued in a slot's released clock or later sees its region (WR_LAT 0; with WR_LAT 1
-- a clock later).
-- Throughput: 1 pixel per clock on each stream; LANES words of each RAM per clock out.
-- Cost: N_SLOTS x (one or two ms_slot_capture + their ms_region_ram of REGION_MAX x STRIDE words per
-- bank + LANES x ADDR_W address flip-flops) + the N_SLOTS-way read multiplexer
-- (docs/blocks/ms_slot_pool.md).
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
    COLOUR_W   : natural := 9;                 -- bits of a colour bin
    ORIENT     : boolean := true;              -- an orientation RAM per slot (the joint core)
    LOG2_D_MAX : natural range 0 to 7 := 4;    -- largest log2 D
    RD_LAT     : positive := 3;                -- slot RAM read latency (ms_region_ram)
    WR_LAT     : natural := 1                  -- slot RAM write latency (ms_region_ram)
  );
  port (
    clk         : in  std_logic;                                        -- clock
    rst         : in  std_logic;                                        -- synchronous reset, active high
    frame_start : in  std_logic;                                        -- ms_frontend's frame events
    frame_error : in  std_logic;
    -- ms_frontend's all-pixel stream delayed to the frame events: the colour RAMs
    ad_valid    : in  std_logic;
    ad_x        : in  unsigned(COORD_W - 1 downto 0);
    ad_y        : in  unsigned(COORD_W - 1 downto 0);
    ad_cbin     : in  std_logic_vector(COLOUR_W - 1 downto 0);
    ad_end      : in  std_logic;                                        -- its frame_end: both captures' frame end
    -- ms_frontend's interior stream: the orientation RAMs (ORIENT)
    ip_valid    : in  std_logic;
    ip_x        : in  unsigned(COORD_W - 1 downto 0);
    ip_y        : in  unsigned(COORD_W - 1 downto 0);
    ip_obin     : in  std_logic_vector(3 downto 0);
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
    rdata       : out std_logic_vector(LANES * COLOUR_W - 1 downto 0);  -- colour, RD_LAT + 2 clocks later
    robin       : out std_logic_vector(LANES * 4 - 1 downto 0)          -- orientation (ORIENT; else 0)
  );
end entity;

architecture rtl of ms_slot_pool is
  constant SEL_W : natural := bits_for(N_SLOTS - 1);
  type cdata_arr is array (0 to N_SLOTS - 1) of std_logic_vector(LANES * COLOUR_W - 1 downto 0);
  type odata_arr is array (0 to N_SLOTS - 1) of std_logic_vector(LANES * 4 - 1 downto 0);
  type sel_arr is array (1 to RD_LAT + 1) of unsigned(SEL_W - 1 downto 0);
  signal slot_c : cdata_arr;
  signal slot_o : odata_arr := (others => (others => '0'));
  signal sel_d  : sel_arr;
begin
  g_slot : for s in 0 to N_SLOTS - 1 generate
    signal s_load : std_logic;
    signal c_armed, c_pending, c_rel, c_late : std_logic;
    signal o_armed, o_pending, o_rel, o_late : std_logic := '0';
    signal c_we, o_we : std_logic;
    signal c_wbank, o_wbank : unsigned(clog2(LANES) - 1 downto 0);
    signal c_waddr, o_waddr : unsigned(ADDR_W - 1 downto 0);
    signal c_wdata : std_logic_vector(COLOUR_W - 1 downto 0);
    signal o_wdata : std_logic_vector(3 downto 0);
    signal s_raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0) := (others => '0');
  begin
    s_load <= load when load_slot = to_unsigned(s, SEL_W) else '0';

    -- this slot's copy of the read address (loaded while rd_slot selects it, so the copies differ
    -- and synthesis keeps one per slot)
    p_raddr : process (clk)
    begin
      if rising_edge(clk) then
        if rd_slot = to_unsigned(s, SEL_W) then
          s_raddr <= raddr;
        end if;
      end if;
    end process;

    u_cap_c : entity work.ms_slot_capture
      generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                   ADDR_W => ADDR_W, DATA_W => COLOUR_W, LOG2_D_MAX => LOG2_D_MAX, INTERIOR_ONLY => false)
      port map (clk => clk, rst => rst, frame_start => frame_start, frame_end => ad_end,
                frame_error => frame_error, ip_valid => ad_valid, ip_x => ad_x, ip_y => ad_y,
                ip_data => ad_cbin, load => s_load, load_now => load_now, dec_log2 => dec_log2,
                fx0 => fx0, fy0 => fy0, fx1 => fx1, fy1 => fy1, armed => c_armed, pending => c_pending,
                released => c_rel, late => c_late, we => c_we, wbank => c_wbank, waddr => c_waddr,
                wdata => c_wdata);

    u_ram_c : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => COLOUR_W, ADDR_W => ADDR_W,
                   RD_LAT => RD_LAT, WR_LAT => WR_LAT)
      port map (clk => clk, we => c_we, wbank => c_wbank, waddr => c_waddr, wdata => c_wdata, raddr => s_raddr,
                rdata => slot_c(s));

    g_orient : if ORIENT generate
      u_cap_o : entity work.ms_slot_capture
        generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                     ADDR_W => ADDR_W, DATA_W => 4, LOG2_D_MAX => LOG2_D_MAX, INTERIOR_ONLY => true)
        port map (clk => clk, rst => rst, frame_start => frame_start, frame_end => ad_end,
                  frame_error => frame_error, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y,
                  ip_data => ip_obin, load => s_load, load_now => load_now, dec_log2 => dec_log2,
                  fx0 => fx0, fy0 => fy0, fx1 => fx1, fy1 => fy1, armed => o_armed, pending => o_pending,
                  released => o_rel, late => o_late, we => o_we, wbank => o_wbank, waddr => o_waddr,
                  wdata => o_wdata);

      u_ram_o : entity work.ms_region_ram
        generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => 4, ADDR_W => ADDR_W,
                     RD_LAT => RD_LAT, WR_LAT => WR_LAT)
        port map (clk => clk, we => o_we, wbank => o_wbank, waddr => o_waddr, wdata => o_wdata, raddr => s_raddr,
                  rdata => slot_o(s));
    end generate;

    armed(s)    <= c_armed or o_armed;
    pending(s)  <= c_pending or o_pending;
    released(s) <= o_rel when ORIENT else c_rel;
    late(s)     <= c_late or o_late;
  end generate;

  -- the read multiplexer: rd_slot delayed with the address copy and the RAMs' read, then one
  -- registered selection
  p_rd : process (clk)
  begin
    if rising_edge(clk) then
      sel_d(1) <= rd_slot;
      for i in 2 to RD_LAT + 1 loop
        sel_d(i) <= sel_d(i - 1);
      end loop;
      rdata <= (others => '0');
      robin <= (others => '0');
      for s in 0 to N_SLOTS - 1 loop
        if sel_d(RD_LAT + 1) = to_unsigned(s, SEL_W) then
          rdata <= slot_c(s);
          if ORIENT then
            robin <= slot_o(s);
          end if;
        end if;
      end loop;
    end if;
  end process;
end architecture;
