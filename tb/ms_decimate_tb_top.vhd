-- ms_decimate_tb_top: test wrapper (not part of the core) for tb/test_ms_decimate.py:
-- ms_frontend -> ms_decimate -> ms_region_capture -> two ms_region_ram (colour, edge);
-- the RAM read ports are exposed.  This is the v2 capture path (region in decimated px).
-- ORIENT_T >= 0: the edge RAM captures ms_sobel's orientation bin instead of the edge bin
-- (step 1 of the joint core: colour and orientation region RAMs, docs/results_v2_mean.md).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_decimate_tb_top is
  generic (
    LANES          : natural := 2;     -- RAM banks
    COORD_W        : natural := 12;    -- coordinate width
    MAX_FRAME_W    : natural := 64;    -- line buffer depth
    REGION_MAX     : natural := 11;    -- largest region extent
    STRIDE         : natural := 6;     -- ceil(REGION_MAX / LANES)
    ADDR_W         : natural := 7;     -- bits_for(REGION_MAX * STRIDE - 1)
    COLOUR_BITS    : natural := 3;     -- colour bits per channel
    EDGE_BINS_LOG2 : natural := 4;     -- edge bin width
    EDGE_SHIFT     : natural := 5;     -- edge shift
    LOG2_D_MAX     : natural := 4;     -- largest log2 D
    ORIENT_T       : integer range -1 to 2047 := -1  -- -1: the edge RAM gets the edge bins; >= 0: the
                                                     -- orientation bins of this threshold (EDGE_BINS_LOG2 = 4)
  );
  port (
    clk          : in  std_logic;                                                 -- clock
    rst          : in  std_logic;                                                 -- reset
    frame_width  : in  unsigned(COORD_W - 1 downto 0);                            -- W
    frame_height : in  unsigned(COORD_W - 1 downto 0);                            -- H
    in_valid     : in  std_logic;                                                 -- beat
    in_data      : in  std_logic_vector(23 downto 0);                             -- RGB
    in_sof       : in  std_logic;                                                 -- start of frame
    in_eol       : in  std_logic;                                                 -- end of line
    dec_log2     : in  unsigned(2 downto 0);                                      -- log2 D (sampled at frame start)
    reg_x        : in  unsigned(COORD_W - 1 downto 0);                            -- region (decimated px)
    reg_y        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    reg_w        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    reg_h        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    frame_start  : out std_logic;                                                 -- front end event
    frame_end    : out std_logic;                                                 -- front end event
    frame_error  : out std_logic;                                                 -- front end event
    err_code     : out std_logic_vector(ERR_CODE_W - 1 downto 0);                 -- front end error code
    dec_q        : out unsigned(2 downto 0);                                      -- latched log2 D
    done         : out std_logic;                                                 -- capture done
    raddr        : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);             -- read address per bank
    rdata_colour : out std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);    -- colour RAM data per bank
    rdata_edge   : out std_logic_vector(LANES * EDGE_BINS_LOG2 - 1 downto 0)      -- edge RAM data per bank
  );
end entity;

architecture tb of ms_decimate_tb_top is
  signal ip_valid, dp_valid : std_logic;
  signal ip_x, ip_y, dp_x, dp_y : unsigned(COORD_W - 1 downto 0);
  signal ip_cbin, dp_cbin, wd_c : std_logic_vector(3 * COLOUR_BITS - 1 downto 0);
  signal ip_ebin, dp_ebin, wd_e : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal ip_edge : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal ip_obin : std_logic_vector(3 downto 0);
  signal fs, fe, ferr, ds, de, derr : std_logic;
  signal we : std_logic;
  signal wbank : unsigned(clog2(LANES) - 1 downto 0);
  signal waddr : unsigned(ADDR_W - 1 downto 0);
begin
  frame_start <= fs;
  frame_end <= fe;
  frame_error <= ferr;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT,
                 ORIENT_T => maximum(ORIENT_T, 0))
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => in_valid, in_data => in_data, in_sof => in_sof, in_eol => in_eol,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_edge,
              ip_obin => ip_obin,
              frame_start => fs, frame_end => fe, frame_error => ferr, err_code => err_code);
  assert ORIENT_T < 0 or EDGE_BINS_LOG2 = 4 report "ms_decimate_tb_top: ORIENT_T needs EDGE_BINS_LOG2 = 4"
    severity failure;
  g_edge : if ORIENT_T < 0 generate
    ip_ebin <= ip_edge;
  end generate;
  g_orient : if ORIENT_T >= 0 generate
    ip_ebin <= ip_obin;
  end generate;

  u_dec : entity work.ms_decimate
    generic map (COORD_W => COORD_W, LOG2_D_MAX => LOG2_D_MAX, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2)
    port map (clk => clk, rst => rst, dec_log2 => dec_log2, frame_start => fs, frame_end => fe,
              frame_error => ferr, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin,
              ip_ebin => ip_ebin, dp_start => ds, dp_end => de, dp_error => derr, dp_valid => dp_valid,
              dp_x => dp_x, dp_y => dp_y, dp_cbin => dp_cbin, dp_ebin => dp_ebin, dec_q => dec_q);

  u_cap : entity work.ms_region_capture
    generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => EDGE_BINS_LOG2)
    port map (clk => clk, rst => rst, frame_start => ds, frame_end => de, frame_error => derr,
              reg_x => reg_x, reg_y => reg_y, reg_w => reg_w, reg_h => reg_h,
              ip_valid => dp_valid, ip_x => dp_x, ip_y => dp_y, ip_cbin => dp_cbin, ip_ebin => dp_ebin,
              we => we, wbank => wbank, waddr => waddr, wdata_colour => wd_c, wdata_edge => wd_e,
              done => done);

  u_ram_c : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => 3 * COLOUR_BITS, ADDR_W => ADDR_W)
    port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wd_c,
              raddr => raddr, rdata => rdata_colour);

  u_ram_e : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => EDGE_BINS_LOG2, ADDR_W => ADDR_W)
    port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wd_e,
              raddr => raddr, rdata => rdata_edge);
end architecture;
