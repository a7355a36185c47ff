-- Test wrapper: ms_init_job reading a slot of ms_region_ram (the RAM the slot pool gives each slot),
-- whose write port the bench drives to fill the slot.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_init_job_tb_top is
  generic (
    LANES    : natural := 4;      -- as ms_init_job
    STRIDE   : natural := 64;
    ADDR_W   : natural := 14;
    REGION_W : natural := 9;
    BIN_W    : natural := 9;
    N_ORIENT : natural := 1;
    HALF_W   : natural := 6;
    RING_W   : natural := 5;
    Q_W      : natural := 14;
    O_W      : natural := 17;
    KD_W     : natural := 29;
    MODELS   : positive := 3;
    DEPTH    : positive := 16384; -- slot words per bank (ms_region_ram)
    RD_LAT   : positive := 4      -- ms_region_ram's read latency
  );
  port (
    clk       : in  std_logic;
    rst       : in  std_logic;
    we        : in  std_logic;                                  -- the slot's write port
    wbank     : in  unsigned(clog2(LANES) - 1 downto 0);
    waddr     : in  unsigned(ADDR_W - 1 downto 0);
    wdata     : in  std_logic_vector(BIN_W + 4 * boolean'pos(N_ORIENT > 1) - 1 downto 0);
    start     : in  std_logic;                                  -- ms_init_job
    rect_w    : in  unsigned(REGION_W - 1 downto 0);
    rect_h    : in  unsigned(REGION_W - 1 downto 0);
    cx        : in  unsigned(REGION_W - 1 downto 0);
    cy        : in  unsigned(REGION_W - 1 downto 0);
    wb        : in  unsigned(HALF_W downto 0);
    hb        : in  unsigned(HALF_W downto 0);
    ring16    : in  unsigned(RING_W - 1 downto 0);
    model     : in  unsigned(clog2(MODELS) - 1 downto 0);
    org_x     : in  unsigned(11 downto 0);                      -- the rectangle's origin, the frame's last
    org_y     : in  unsigned(11 downto 0);                      -- border column / row (ms_init_job)
    last_x    : in  unsigned(11 downto 0);
    last_y    : in  unsigned(11 downto 0);
    busy      : out std_logic;
    done      : out std_logic;
    m_rd_addr : in  unsigned(BIN_W - 1 downto 0);
    m_rd_obin : in  unsigned(3 downto 0);
    m_rd_sel  : in  unsigned(clog2(MODELS) - 1 downto 0);
    m_qn      : out unsigned(16 downto 0);
    m_t       : out std_logic
  );
end entity;

architecture rtl of ms_init_job_tb_top is
  constant DATA_W : natural := BIN_W + 4 * boolean'pos(N_ORIENT > 1);
  signal raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal rdata : std_logic_vector(LANES * DATA_W - 1 downto 0);
begin
  u_ram : entity work.ms_region_ram
    generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => DATA_W, ADDR_W => ADDR_W, RD_LAT => RD_LAT,
                 WR_LAT => 0)
    port map (clk => clk, we => we, wbank => wbank, waddr => waddr, wdata => wdata, raddr => raddr,
              rdata => rdata);
  u_job : entity work.ms_init_job
    generic map (LANES => LANES, STRIDE => STRIDE, ADDR_W => ADDR_W, REGION_W => REGION_W, RD_LAT => RD_LAT,
                 BIN_W => BIN_W, N_ORIENT => N_ORIENT, HALF_W => HALF_W, RING_W => RING_W, Q_W => Q_W,
                 O_W => O_W, KD_W => KD_W, MODELS => MODELS)
    port map (clk => clk, rst => rst, start => start, rect_w => rect_w, rect_h => rect_h, cx => cx, cy => cy,
              wb => wb, hb => hb, ring16 => ring16, model => model, org_x => org_x, org_y => org_y,
              last_x => last_x, last_y => last_y, busy => busy, done => done,
              raddr => raddr, rdata => rdata, m_rd_addr => m_rd_addr, m_rd_obin => m_rd_obin,
              m_rd_sel => m_rd_sel, m_qn => m_qn, m_t => m_t, m_qn_all => open, m_t_all => open);
end architecture;
