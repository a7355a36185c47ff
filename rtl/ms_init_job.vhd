-- ms_init_job: the init job of the shared-engine multi-target core: the target model learnt from the
-- rectangle captured into the target's slot on the frame it was added (docs/multi_target_core.md,
-- "The init job").
--
-- Computes: model `model` of ms_bg_model = mstrack.fixed.blocks_v2.ms_bg_model(rect, cx, cy, wb, hb, ring16)
-- of the rectangle's bins (ms_slot_scan: every pixel of the rect_w x rect_h rectangle, coordinates
-- relative to it), which is the model FixedTrackerV2.init learns from the whole decimated frame when
-- the rectangle is mstrack.fixed.multi_capacity.init_capture's and (cx, cy) its centre cd moved by the
-- rectangle's origin.  A slot pixel is {orientation bin (4 bits, N_ORIENT > 1), colour bin (BIN_W)}.
-- A pixel on the frame's border (decimated x = 0, y = 0, or the last column / row when it is a
-- border pixel at full resolution: last_x, last_y) is counted with orientation 8 whatever the slot
-- holds there: the slot's orientation comes from the Sobel's interior stream, which has no border
-- pixels (docs/multi_target_core.md, "The init job").  org_x, org_y: the rectangle's origin in the
-- decimated frame; last_x, last_y all ones: no such column / row (the defaults: no substitution).
-- Steps: ms_bg_model's start (the kernel-table set-up of the box), then ms_slot_scan streams the
-- rectangle into its count port, one pixel per clock, then its three passes write the model.
-- Latency: `done` comes SETUP + RD_LAT + rect_w rect_h + LAT_DONE + 7 clocks after the edge that takes
-- `start`: SETUP is ms_bg_model's set-up of the box (its header: at most 215 clocks at HALF_W 6),
-- LAT_DONE its px_last -> done (3 N + 65 at the default widths, N = N_ORIENT 2**BIN_W); 7 = 2 to start
-- it, 2 to start the scan, the scan's 2 registers and 1 to see its done (tb/test_ms_init_job.py checks it).
-- Throughput: one job at a time (busy).
-- Handshake: `start` with its inputs is taken when busy = 0; `done` is a one-clock pulse.  The model
-- read port (m_rd_*) is ms_bg_model's and may be used at any time (during a job model `model` shows
-- a mix of the old and the new model).
-- Reset: synchronous, active high; ms_bg_model then clears its count RAM (busy meanwhile); the models
-- keep their contents.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_init_job is
  generic (
    LANES    : natural := 4;        -- slot RAM banks
    STRIDE   : natural := 64;       -- words per slot row per bank
    ADDR_W   : natural := 14;       -- slot word address width
    REGION_W : natural := 9;        -- rectangle sizes and coordinates
    COORD_W  : natural := 12;       -- decimated frame coordinates (org_*, last_*)
    RD_LAT   : positive := 5;       -- the slot read port's latency
    BIN_W    : natural := 9;        -- colour bin bits
    N_ORIENT : natural range 1 to 16 := 9;   -- orientation banks (1: colour bins only)
    HALF_W   : natural := 6;        -- ms_bg_model's box widths
    RING_W   : natural := 5;
    Q_W      : natural := 14;
    O_W      : natural := 17;
    KD_W     : natural := 29;
    MODELS   : positive := 2        -- models held (one per target)
  );
  port (
    clk       : in  std_logic;
    rst       : in  std_logic;
    -- the job
    start     : in  std_logic;                                  -- taken when busy = 0
    rect_w    : in  unsigned(REGION_W - 1 downto 0);            -- the captured rectangle
    rect_h    : in  unsigned(REGION_W - 1 downto 0);
    cx        : in  unsigned(REGION_W - 1 downto 0);            -- box centre, relative to the rectangle
    cy        : in  unsigned(REGION_W - 1 downto 0);
    wb        : in  unsigned(HALF_W downto 0);                  -- box diameters
    hb        : in  unsigned(HALF_W downto 0);
    ring16    : in  unsigned(RING_W - 1 downto 0);
    model     : in  unsigned(clog2(MODELS) - 1 downto 0);       -- the target's model
    org_x     : in  unsigned(COORD_W - 1 downto 0) := (others => '1');   -- the rectangle's origin
    org_y     : in  unsigned(COORD_W - 1 downto 0) := (others => '1');
    last_x    : in  unsigned(COORD_W - 1 downto 0) := (others => '1');   -- the frame's last border column
    last_y    : in  unsigned(COORD_W - 1 downto 0) := (others => '1');   -- and row (all ones: none)
    busy      : out std_logic;
    done      : out std_logic;                                  -- pulse: the model is written
    -- the slot's read port
    raddr     : out std_logic_vector(LANES * ADDR_W - 1 downto 0);
    rdata     : in  std_logic_vector(LANES * (BIN_W + 4 * boolean'pos(N_ORIENT > 1)) - 1 downto 0);
    -- the models' read port (ms_bg_model's)
    m_rd_addr : in  unsigned(BIN_W - 1 downto 0);
    m_rd_obin : in  unsigned(3 downto 0) := (others => '0');
    m_rd_sel  : in  unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
    m_qn      : out unsigned(16 downto 0);
    m_t       : out std_logic;
    m_qn_all  : out std_logic_vector(N_ORIENT * 17 - 1 downto 0);
    m_t_all   : out std_logic_vector(N_ORIENT - 1 downto 0)
  );
end entity;

architecture rtl of ms_init_job is
  constant OR_ON  : boolean := N_ORIENT > 1;
  constant DATA_W : natural := BIN_W + 4 * boolean'pos(OR_ON);
  type state_t is (S_IDLE, S_BG_START, S_SETUP, S_SCAN, S_PASSES);
  signal state    : state_t := S_IDLE;
  signal bg_start, bg_busy, bg_counting, bg_done : std_logic := '0';
  signal sc_start, sc_busy : std_logic := '0';
  signal px_valid, px_last : std_logic;
  signal px_x, px_y : unsigned(REGION_W - 1 downto 0);
  signal px_data  : std_logic_vector(DATA_W - 1 downto 0);
  signal px_obin  : unsigned(3 downto 0);
  signal w_r, h_r, cx_r, cy_r : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal wb_r, hb_r : unsigned(HALF_W downto 0) := (others => '0');
  signal ring_r   : unsigned(RING_W - 1 downto 0) := (others => '0');
  signal model_r  : unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
  signal done_r   : std_logic := '0';
  -- the frame's border inside the rectangle (rectangle-relative), taken with start
  signal bl_x, bl_y, br_x, br_y : std_logic := '0';          -- left / top border, right / bottom border in it
  signal rel_x, rel_y : unsigned(REGION_W - 1 downto 0) := (others => '0');
begin
  u_scan : entity work.ms_slot_scan
    generic map (LANES => LANES, STRIDE => STRIDE, ADDR_W => ADDR_W, DATA_W => DATA_W, REGION_W => REGION_W,
                 RD_LAT => RD_LAT)
    port map (clk => clk, rst => rst, start => sc_start, rect_w => w_r, rect_h => h_r, busy => sc_busy,
              raddr => raddr, rdata => rdata, px_valid => px_valid, px_x => px_x, px_y => px_y,
              px_data => px_data, px_last => px_last);

  -- (two generates, not one conditional: the colour bins' px_data has no orientation slice, and GHDL
  -- refuses to synthesise the null slice even in a branch that is never taken)
  g_ob_colour : if not OR_ON generate
    px_obin <= (others => '0');
  end generate;
  g_ob_joint : if OR_ON generate
    px_obin <= to_unsigned(8, 4) when (bl_x = '1' and px_x = 0) or (bl_y = '1' and px_y = 0)
                                      or (br_x = '1' and px_x = rel_x) or (br_y = '1' and px_y = rel_y) else
               unsigned(px_data(DATA_W - 1 downto BIN_W));
  end generate;

  u_bg : entity work.ms_bg_model
    generic map (BIN_W => BIN_W, HALF_W => HALF_W, COORD_W => REGION_W, RING_W => RING_W, Q_W => Q_W, O_W => O_W,
                 KD_W => KD_W, N_ORIENT => N_ORIENT, ORIENT_W => 4, MODELS => MODELS)
    port map (clk => clk, rst => rst, start => bg_start, cx => cx_r, cy => cy_r, wb => wb_r, hb => hb_r,
              ring16 => ring_r, m_wr_sel => model_r, busy => bg_busy, counting => bg_counting, done => bg_done,
              px_valid => px_valid, px_bin => unsigned(px_data(BIN_W - 1 downto 0)), px_obin => px_obin,
              px_x => px_x, px_y => px_y, px_last => px_last, n_box => open, n_ring => open, o_min => open,
              qv_sum => open, m_rd_addr => m_rd_addr, m_rd_obin => m_rd_obin, m_rd_sel => m_rd_sel,
              m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all, m_t_all => m_t_all);

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      bg_start <= '0';
      sc_start <= '0';
      done_r <= '0';
      case state is
        when S_IDLE =>
          if start = '1' and bg_busy = '0' then
            w_r <= rect_w; h_r <= rect_h; cx_r <= cx; cy_r <= cy;
            wb_r <= wb; hb_r <= hb; ring_r <= ring16; model_r <= model;
            bl_x <= to_sl(org_x = 0);
            bl_y <= to_sl(org_y = 0);
            br_x <= to_sl(last_x /= 2 ** COORD_W - 1 and last_x >= org_x and last_x - org_x < rect_w);
            br_y <= to_sl(last_y /= 2 ** COORD_W - 1 and last_y >= org_y and last_y - org_y < rect_h);
            rel_x <= resize(last_x - org_x, REGION_W);
            rel_y <= resize(last_y - org_y, REGION_W);
            state <= S_BG_START;
          end if;
        when S_BG_START =>                     -- ms_bg_model takes the box (its inputs registered above)
          bg_start <= '1';
          state <= S_SETUP;
        when S_SETUP =>                        -- its kernel-table set-up, then it counts
          if bg_counting = '1' and bg_start = '0' then
            sc_start <= '1';
            state <= S_SCAN;
          end if;
        when S_SCAN =>                         -- the rectangle into the count port
          if sc_start = '0' and sc_busy = '0' then
            state <= S_PASSES;
          end if;
        when S_PASSES =>                       -- the three passes write the model
          if bg_done = '1' then
            done_r <= '1';
            state <= S_IDLE;
          end if;
      end case;
      if rst = '1' then
        state <= S_IDLE;
        bg_start <= '0';
        sc_start <= '0';
        done_r <= '0';
      end if;
    end if;
  end process;

  busy <= '1' when state /= S_IDLE or bg_busy = '1' else '0';
  done <= done_r;
end architecture;
