-- ms_slot_pool_tb_top: test wrapper (not part of the core) for tb/test_ms_slot_pool.py: ms_frontend
-- -> ms_slot_pool, as the shared-engine multi-target core joins them: the colour RAMs from the
-- all-pixel stream delayed to the frame events (ad_*), the orientation RAMs from the interior stream
-- (ip_obin), both captures on frame_start, frame_error and ad_end.  The pool's ports are exposed,
-- with the front end's frame events for the bench.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_slot_pool_tb_top is
  generic (
    N_SLOTS     : positive := 3;     -- slots
    LANES       : natural := 4;      -- RAM banks
    COORD_W     : natural := 12;     -- coordinate width
    MAX_FRAME_W : natural := 64;     -- line buffer depth
    REGION_MAX  : natural := 24;     -- largest region extent
    STRIDE      : natural := 6;      -- words per region row per bank
    ADDR_W      : natural := 8;      -- slot address width
    COLOUR_BITS : natural := 3;      -- colour bits per channel
    ORIENT      : boolean := true;   -- orientation RAMs
    ORIENT_T    : natural := 64;     -- orientation threshold
    LOG2_D_MAX  : natural := 4;      -- largest log2 D
    RD_LAT      : positive := 3;     -- slot RAM read latency
    WR_LAT      : natural := 1       -- slot RAM write latency
  );
  port (
    clk          : in  std_logic;                                          -- clock
    rst          : in  std_logic;                                          -- reset
    frame_width  : in  unsigned(COORD_W - 1 downto 0);                     -- W
    frame_height : in  unsigned(COORD_W - 1 downto 0);                     -- H
    in_valid     : in  std_logic;                                          -- beat
    in_data      : in  std_logic_vector(23 downto 0);                      -- RGB
    in_sof       : in  std_logic;                                          -- start of frame
    in_eol       : in  std_logic;                                          -- end of line
    frame_start  : out std_logic;                                          -- front end events
    frame_error  : out std_logic;
    ad_end       : out std_logic;
    load         : in  std_logic;                                          -- descriptor bus
    load_slot    : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);
    load_now     : in  std_logic;
    dec_log2     : in  unsigned(2 downto 0);
    fx0, fy0     : in  unsigned(COORD_W - 1 downto 0);
    fx1, fy1     : in  unsigned(COORD_W - 1 downto 0);
    armed        : out std_logic_vector(N_SLOTS - 1 downto 0);             -- per slot
    pending      : out std_logic_vector(N_SLOTS - 1 downto 0);
    released     : out std_logic_vector(N_SLOTS - 1 downto 0);
    late         : out std_logic_vector(N_SLOTS - 1 downto 0);
    rd_slot      : in  unsigned(bits_for(N_SLOTS - 1) - 1 downto 0);       -- read port
    raddr        : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);
    rdata        : out std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);
    robin        : out std_logic_vector(LANES * 4 - 1 downto 0)
  );
end entity;

architecture tb of ms_slot_pool_tb_top is
  constant CB_W : natural := 3 * COLOUR_BITS;
  signal fs, ferr, aend : std_logic;
  signal ip_valid, ad_valid : std_logic;
  signal ip_x, ip_y, ad_x, ad_y : unsigned(COORD_W - 1 downto 0);
  signal ip_obin : std_logic_vector(3 downto 0);
  signal ad_cbin : std_logic_vector(CB_W - 1 downto 0);
begin
  frame_start <= fs;
  frame_error <= ferr;
  ad_end <= aend;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS, ORIENT_T => ORIENT_T)
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => in_valid, in_data => in_data, in_sof => in_sof, in_eol => in_eol,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              frame_start => fs, frame_error => ferr,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => aend);

  u_pool : entity work.ms_slot_pool
    generic map (N_SLOTS => N_SLOTS, LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, COLOUR_W => CB_W, ORIENT => ORIENT,
                 LOG2_D_MAX => LOG2_D_MAX, RD_LAT => RD_LAT, WR_LAT => WR_LAT)
    port map (clk => clk, rst => rst, frame_start => fs, frame_error => ferr,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => aend,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              load => load, load_slot => load_slot, load_now => load_now, dec_log2 => dec_log2,
              fx0 => fx0, fy0 => fy0, fx1 => fx1, fy1 => fy1, armed => armed, pending => pending,
              released => released, late => late, rd_slot => rd_slot, raddr => raddr, rdata => rdata,
              robin => robin);
end architecture;
