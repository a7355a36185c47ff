-- ms_capture_tb_top: test wrapper (not part of the core) for
-- tb/test_ms_region_capture.py: ms_frontend -> ms_region_capture -> two
-- ms_region_ram (colour, edge); the RAM read ports are exposed.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_capture_tb_top is
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
    PPC            : natural := 1      -- pixels per clock (<= LANES)
  );
  port (
    clk          : in  std_logic;                                                 -- clock
    rst          : in  std_logic;                                                 -- reset
    frame_width  : in  unsigned(COORD_W - 1 downto 0);                            -- W
    frame_height : in  unsigned(COORD_W - 1 downto 0);                            -- H
    in_valid     : in  std_logic;                                                 -- beat
    in_data      : in  std_logic_vector(24 * PPC - 1 downto 0);                   -- PPC RGB pixels
    in_sof       : in  std_logic;                                                 -- start of frame
    in_eol       : in  std_logic;                                                 -- end of line
    reg_x        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    reg_y        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    reg_w        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    reg_h        : in  unsigned(COORD_W - 1 downto 0);                            -- region
    frame_start  : out std_logic;                                                 -- front end event
    frame_end    : out std_logic;                                                 -- front end event
    frame_error  : out std_logic;                                                 -- front end event
    err_code     : out std_logic_vector(ERR_CODE_W - 1 downto 0);                 -- front end error code
    done         : out std_logic;                                                 -- capture done
    raddr        : in  std_logic_vector(LANES * ADDR_W - 1 downto 0);             -- read address per bank
    rdata_colour : out std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);    -- colour RAM data per bank
    rdata_edge   : out std_logic_vector(LANES * EDGE_BINS_LOG2 - 1 downto 0)      -- edge RAM data per bank
  );
end entity;

architecture tb of ms_capture_tb_top is
  signal ip_valid : std_logic;
  signal ip_x, ip_y : unsigned(COORD_W - 1 downto 0);
  signal wd_c : std_logic_vector(3 * COLOUR_BITS - 1 downto 0);
  signal wd_e : std_logic_vector(EDGE_BINS_LOG2 - 1 downto 0);
  signal ip_cbin : std_logic_vector(PPC * 3 * COLOUR_BITS - 1 downto 0);
  signal ip_ebin : std_logic_vector(PPC * EDGE_BINS_LOG2 - 1 downto 0);
  signal bwe : std_logic_vector(LANES - 1 downto 0);
  signal bwaddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal bwd_c : std_logic_vector(LANES * 3 * COLOUR_BITS - 1 downto 0);
  signal bwd_e : std_logic_vector(LANES * EDGE_BINS_LOG2 - 1 downto 0);
  constant CB_W : natural := 3 * COLOUR_BITS;
  constant EB_W : natural := EDGE_BINS_LOG2;
  signal fs, fe, ferr : std_logic;
  signal we : std_logic;
  signal wbank : unsigned(clog2(LANES) - 1 downto 0);
  signal waddr : unsigned(ADDR_W - 1 downto 0);
begin
  frame_start <= fs;
  frame_end <= fe;
  frame_error <= ferr;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, PPC => PPC)
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => in_valid, in_data => in_data, in_sof => in_sof, in_eol => in_eol,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_ebin,
              frame_start => fs, frame_end => fe, frame_error => ferr, err_code => err_code);

  u_cap : entity work.ms_region_capture
    generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => EDGE_BINS_LOG2, PPC => PPC)
    port map (clk => clk, rst => rst, frame_start => fs, frame_end => fe, frame_error => ferr,
              reg_x => reg_x, reg_y => reg_y, reg_w => reg_w, reg_h => reg_h,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_ebin,
              we => we, wbank => wbank, waddr => waddr, wdata_colour => wd_c, wdata_edge => wd_e,
              done => done, bwe => bwe, bwaddr => bwaddr, bwdata_colour => bwd_c, bwdata_edge => bwd_e);

  g_ram1 : if PPC = 1 generate
    u_ram_c : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => 3 * COLOUR_BITS, ADDR_W => ADDR_W)
      port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wd_c,
                raddr => raddr, rdata => rdata_colour);

    u_ram_e : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => EDGE_BINS_LOG2, ADDR_W => ADDR_W)
      port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wd_e,
                raddr => raddr, rdata => rdata_edge);
  end generate;

  g_ramn : if PPC > 1 generate
    g_bank : for bk in 0 to LANES - 1 generate
      u_ram_c : entity work.ms_region_ram
        generic map (LANES => 1, DEPTH => REGION_MAX * STRIDE, DATA_W => CB_W, ADDR_W => ADDR_W)
        port map (clk => clk, we => bwe(bk), wbank => "0",
                  waddr => unsigned(bwaddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk)),
                  wdata => bwd_c(CB_W * (bk + 1) - 1 downto CB_W * bk),
                  raddr => raddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk),
                  rdata => rdata_colour(CB_W * (bk + 1) - 1 downto CB_W * bk));

      u_ram_e : entity work.ms_region_ram
        generic map (LANES => 1, DEPTH => REGION_MAX * STRIDE, DATA_W => EB_W, ADDR_W => ADDR_W)
        port map (clk => clk, we => bwe(bk), wbank => "0",
                  waddr => unsigned(bwaddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk)),
                  wdata => bwd_e(EB_W * (bk + 1) - 1 downto EB_W * bk),
                  raddr => raddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk),
                  rdata => rdata_edge(EB_W * (bk + 1) - 1 downto EB_W * bk));
    end generate;
  end generate;
end architecture;
