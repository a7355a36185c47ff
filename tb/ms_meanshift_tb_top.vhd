-- Test wrapper: one ms_meanshift engine reading a ms_region_ram whose write port the test drives.
-- N_ORIENT > 1: a second ms_region_ram (4-bit orientation bins, written with the colour bins from
-- wodata at the same address) feeds ram_obin; the Q load ports and max_it are passed through.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_meanshift_tb_top is
  generic (
    LANES : natural := 2; BIN_W : natural := 6; HALF_W : natural := 3; REGION_W : natural := 5;
    REGION_MAX : natural := 23; STRIDE : natural := 12; ADDR_W : natural := 9; COORD_W : natural := 12;
    KERNEL_EPAN : natural := 0; KERNEL_BITS : natural := 8; KVAL_W : natural := 1; KD_W : natural := 17;
    HIST_W : natural := 8; COUNT_W : natural := 8; POSSUM_W : natural := 11; SQRT_IN_W : natural := 28;
    RHO_SUM_W : natural := 15; RATIO_Q_W : natural := 16; WEIGHT_W : natural := 8; WF : natural := 4;
    RF : natural := 6; SW_W : natural := 16; SWX_W : natural := 19; SHIFT_Q_W : natural := 11;
    CF : natural := 8; CENTRE_W : natural := 13; CENTRE_ABS_W : natural := 20; MAX_ITER : natural := 20;
    ITER_W : natural := 5; EPS2 : natural := 65536; N_ORIENT : natural := 1;
    LO_IN : natural := 0                     -- 1: ms_meanshift's LO_IN (the clamp's lower bound from lo_x_in / lo_y_in)
  );
  port (
    clk : in std_logic; rst : in std_logic;
    we : in std_logic; wbank : in unsigned(clog2(LANES) - 1 downto 0); waddr : in unsigned(ADDR_W - 1 downto 0);
    wdata : in std_logic_vector(BIN_W - 1 downto 0);
    wodata : in std_logic_vector(3 downto 0) := (others => '0');
    kt_we : in std_logic; kt_addr : in unsigned(HALF_W - 1 downto 0); kt_ta : in unsigned(KD_W - 1 downto 0);
    kt_tb : in unsigned(KD_W - 1 downto 0); kt_ka : in unsigned(KVAL_W - 1 downto 0);
    kt_kb : in unsigned(KVAL_W - 1 downto 0); kt_xr : in unsigned(HALF_W - 1 downto 0);
    kd_d : in unsigned(KD_W - 1 downto 0);
    ex : in unsigned(HALF_W - 1 downto 0); ey : in unsigned(HALF_W - 1 downto 0);
    reg_x : in unsigned(COORD_W - 1 downto 0); reg_y : in unsigned(COORD_W - 1 downto 0);
    hi_x : in unsigned(REGION_W - 1 downto 0); hi_y : in unsigned(REGION_W - 1 downto 0);
    lo_x_in : in unsigned(REGION_W - 1 downto 0) := (others => '0');
    lo_y_in : in unsigned(REGION_W - 1 downto 0) := (others => '0');
    start : in std_logic; learn : in std_logic;
    start_cx : in unsigned(CENTRE_ABS_W - 1 downto 0); start_cy : in unsigned(CENTRE_ABS_W - 1 downto 0);
    busy : out std_logic; done : out std_logic;
    res_cx : out unsigned(CENTRE_ABS_W - 1 downto 0); res_cy : out unsigned(CENTRE_ABS_W - 1 downto 0);
    res_s : out unsigned(RHO_SUM_W - 1 downto 0); res_iter : out unsigned(ITER_W - 1 downto 0);
    res_stop : out std_logic_vector(1 downto 0); res_k : out unsigned(HIST_W - 1 downto 0);
    max_it : in unsigned(ITER_W - 1 downto 0) := to_unsigned(MAX_ITER, ITER_W);
    q_ext_we : in std_logic := '0'; q_ext_addr : in unsigned(BIN_W - 1 downto 0) := (others => '0');
    q_ext_data : in unsigned(HIST_W - 1 downto 0) := (others => '0');
    q_ext_bank : in unsigned(3 downto 0) := (others => '0');
    q_ext_all_we : in std_logic := '0';
    q_ext_all_data : in std_logic_vector(N_ORIENT * HIST_W - 1 downto 0) := (others => '0')
  );
end entity;

architecture tb of ms_meanshift_tb_top is
  signal raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal rdata : std_logic_vector(LANES * BIN_W - 1 downto 0);
  signal odata : std_logic_vector(LANES * 4 - 1 downto 0) := (others => '0');
begin
  g_oram : if N_ORIENT > 1 generate
    u_oram : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => 4, ADDR_W => ADDR_W)
      port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wodata, raddr => raddr,
                rdata => odata);
  end generate;
  u_ram : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => REGION_MAX * STRIDE, DATA_W => BIN_W, ADDR_W => ADDR_W)
    port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wdata, raddr => raddr, rdata => rdata);
  u_eng : entity work.ms_meanshift
    generic map (LANES => LANES, BIN_W => BIN_W, HALF_W => HALF_W, REGION_W => REGION_W, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COORD_W => COORD_W, KERNEL_EPAN => KERNEL_EPAN, KERNEL_BITS => KERNEL_BITS,
                 KVAL_W => KVAL_W, KD_W => KD_W, HIST_W => HIST_W, COUNT_W => COUNT_W, POSSUM_W => POSSUM_W,
                 SQRT_IN_W => SQRT_IN_W, RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W,
                 WF => WF, RF => RF, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CF => CF,
                 CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, MAX_ITER => MAX_ITER, ITER_W => ITER_W,
                 EPS2 => EPS2, N_ORIENT => N_ORIENT, LO_IN => LO_IN = 1)
    port map (clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta, kt_tb => kt_tb,
              kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr, kd_d => kd_d, ex => ex, ey => ey,
              reg_x => reg_x, reg_y => reg_y,
              hi_x => hi_x, hi_y => hi_y, lo_x_in => lo_x_in, lo_y_in => lo_y_in, start => start, learn => learn, start_cx => start_cx,
              start_cy => start_cy, busy => busy, done => done, res_cx => res_cx, res_cy => res_cy,
              res_s => res_s, res_iter => res_iter, res_stop => res_stop, res_k => res_k,
              ram_addr => raddr, ram_data => rdata, ram_obin => odata, max_it => max_it,
              q_ext_we => q_ext_we, q_ext_addr => q_ext_addr, q_ext_data => q_ext_data, q_ext_bank => q_ext_bank,
              q_ext_all_we => q_ext_all_we, q_ext_all_data => q_ext_all_data);
end architecture;
