-- Test wrapper: ms_target_stats attached to ms_pixel_pass as in core v2.  ms_kernel_tables
-- (KERNEL_EPAN = 1, KVAL_W = KT_W: it computes KA/KB) writes the kernel tables of the flat pixel pass
-- (XR) and of ms_target_stats (KA/KB); the region RAM is a model in the test (ram_addr / ram_data,
-- data 1 clock after the address, both blocks read the same data); the histogram is not read.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_target_stats_tb_top is
  generic (
    LANES : natural := 4; BIN_W : natural := 9; HALF_W : natural := 6; REGION_W : natural := 8;
    STRIDE : natural := 48; ADDR_W : natural := 14; KERNEL_BITS : natural := 8; KT_W : natural := 9;
    KD_W : natural := 29; HIST_W : natural := 14; COUNT_W : natural := 14; POSSUM_W : natural := 21;
    PAD16 : natural := 4; ST2_W : natural := 23
  );
  port (
    clk : in std_logic; rst : in std_logic;
    -- kernel tables of a w x h window
    kt_start : in std_logic; w : in unsigned(HALF_W downto 0); h : in unsigned(HALF_W downto 0);
    kt_done : out std_logic;
    -- T table
    t_we : in std_logic; t_addr : in unsigned(BIN_W - 1 downto 0); t_data : in std_logic;
    -- pass
    ready : out std_logic; start : in std_logic;
    win_x : in unsigned(REGION_W - 1 downto 0); win_y : in unsigned(REGION_W - 1 downto 0);
    done : out std_logic;
    ram_addr : out std_logic_vector(LANES * ADDR_W - 1 downto 0);
    ram_data : in std_logic_vector(LANES * BIN_W - 1 downto 0);
    -- statistics
    st_done : out std_logic;
    nt : out unsigned(COUNT_W - 1 downto 0); st2 : out unsigned(ST2_W - 1 downto 0);
    n_in : out unsigned(COUNT_W - 1 downto 0); nt_in : out unsigned(COUNT_W - 1 downto 0)
  );
end entity;

architecture tb of ms_target_stats_tb_top is
  signal ex, ey : unsigned(HALF_W - 1 downto 0);
  signal kd_d, kt_ta, kt_tb : unsigned(KD_W - 1 downto 0);
  signal kt_we : std_logic;
  signal kt_addr, kt_xr : unsigned(HALF_W - 1 downto 0);
  signal kt_ka, kt_kb : unsigned(KT_W - 1 downto 0);
  signal px_valid, px_last : std_logic;
  signal px_mask : std_logic_vector(LANES - 1 downto 0);
  signal px_dx, px_dy : signed(REGION_W downto 0);
begin
  u_tables : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KERNEL_EPAN => 1, KERNEL_BITS => KERNEL_BITS, KVAL_W => KT_W, KD_W => KD_W)
    port map (clk => clk, rst => rst, start => kt_start, w => w, h => h, busy => open, done => kt_done,
              ex => ex, ey => ey, kd_d => kd_d, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr);

  u_pass : entity work.ms_pixel_pass
    generic map (LANES => LANES, BIN_W => BIN_W, HALF_W => HALF_W, REGION_W => REGION_W, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, KERNEL_EPAN => 0, KERNEL_BITS => KERNEL_BITS, KVAL_W => 1, KD_W => KD_W,
                 HIST_W => HIST_W, COUNT_W => COUNT_W, POSSUM_W => POSSUM_W)
    port map (clk => clk, rst => rst, ready => ready, start => start, win_x => win_x, win_y => win_y,
              ex => ex, ey => ey, done => done, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka(0 downto 0), kt_kb => kt_kb(0 downto 0), kt_xr => kt_xr,
              kd_d => kd_d, ram_addr => ram_addr, ram_data => ram_data,
              px_valid => px_valid, px_mask => px_mask, px_dx => px_dx, px_dy => px_dy, px_last => px_last,
              bin_rd_en => '0', bin_rd_addr => (others => '0'), bin_rd_valid => open,
              bin_h => open, bin_n => open, bin_sx => open, bin_sy => open);

  u_stats : entity work.ms_target_stats
    generic map (LANES => LANES, BIN_W => BIN_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 KERNEL_BITS => KERNEL_BITS, KT_W => KT_W, PAD16 => PAD16, COUNT_W => COUNT_W, ST2_W => ST2_W)
    port map (clk => clk, rst => rst, t_we => t_we, t_addr => t_addr, t_data => t_data,
              kt_we => kt_we, kt_addr => kt_addr, kt_ka => kt_ka, kt_kb => kt_kb,
              px_valid => px_valid, px_mask => px_mask, px_dx => px_dx, px_dy => px_dy, px_last => px_last,
              ram_data => ram_data, done => st_done, nt => nt, st2 => st2, n_in => n_in, nt_in => nt_in);
end architecture;
