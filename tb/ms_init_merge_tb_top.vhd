-- ms_init_merge_tb_top: test wrapper (not part of the core) for tb/test_ms_init_merge.py: the joint
-- core's init path ms_frontend (ip_obin, av_*) -> ms_decimate (its edge input fed with ip_obin) ->
-- ms_init_merge -> ms_bg_model (N_ORIENT 9); the model RAM read port and the totals are exposed.
-- One reset for all (core v2 resets ms_bg_model and this merge together on an abandoned init frame).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_init_merge_tb_top is
  generic (
    COORD_W     : natural := 12;   -- coordinate width
    MAX_FRAME_W : natural := 128;  -- line buffer depth, widest frame
    COLOUR_BITS : natural := 3;    -- colour bits per channel (BIN_W = 3 COLOUR_BITS)
    HALF_W      : natural := 6;    -- ms_bg_model HALF_W
    RING_W      : natural := 5;    -- ring16 bits
    RING16_MAX  : natural := 31;   -- largest ring16 (FIFO depth)
    Q_W         : natural := 14;   -- ms_bg_model Q_W
    O_W         : natural := 17;   -- ms_bg_model O_W
    KD_W        : natural := 29;   -- ms_bg_model KD_W
    LOG2_D_MAX  : natural := 4;    -- largest log2 D
    ORIENT_T    : natural := 64;   -- orientation threshold (the candidate's 64)
    N_ORIENT    : natural := 9     -- orientation banks
  );
  port (
    clk          : in  std_logic;                                    -- clock
    rst          : in  std_logic;                                    -- reset (all blocks)
    frame_width  : in  unsigned(COORD_W - 1 downto 0);               -- W
    frame_height : in  unsigned(COORD_W - 1 downto 0);               -- H
    in_valid     : in  std_logic;                                    -- beat
    in_data      : in  std_logic_vector(23 downto 0);                -- RGB
    in_sof       : in  std_logic;                                    -- start of frame
    in_eol       : in  std_logic;                                    -- end of line
    dec_log2     : in  unsigned(2 downto 0);                         -- log2 D (sampled at frame start)
    frame_start  : out std_logic;                                    -- front end event
    frame_end    : out std_logic;                                    -- front end event
    frame_error  : out std_logic;                                    -- front end event
    start        : in  std_logic;                                    -- ms_bg_model / merge start
    cx, cy       : in  unsigned(COORD_W - 1 downto 0);               -- box centre (decimated px)
    wb, hb       : in  unsigned(HALF_W downto 0);                    -- box diameters
    ring16       : in  unsigned(RING_W - 1 downto 0);                -- ring in 1/16
    busy         : out std_logic;                                    -- ms_bg_model
    counting     : out std_logic;                                    -- ms_bg_model
    done         : out std_logic;                                    -- ms_bg_model
    overflow     : out std_logic;                                    -- merge FIFO overflow (sticky)
    px_valid     : out std_logic;                                    -- merge output (observed)
    px_last      : out std_logic;                                    -- merge output (observed)
    px_x, px_y   : out unsigned(COORD_W - 1 downto 0);               -- merge output (observed)
    px_bin       : out unsigned(3 * COLOUR_BITS - 1 downto 0);       -- merge output (observed)
    px_obin      : out unsigned(3 downto 0);                         -- merge output (observed)
    n_box        : out unsigned(Q_W - 1 downto 0);                   -- sum Q
    n_ring       : out unsigned(O_W - 1 downto 0);                   -- sum O
    m_rd_addr    : in  unsigned(3 * COLOUR_BITS - 1 downto 0);       -- model read: colour bin
    m_rd_obin    : in  unsigned(3 downto 0);                         -- model read: orientation bank
    m_qn         : out unsigned(16 downto 0);                        -- Qn
    m_t          : out std_logic                                     -- T
  );
end entity;

architecture tb of ms_init_merge_tb_top is
  constant CB_W : natural := 3 * COLOUR_BITS;
  signal ip_valid, dp_valid, av_valid : std_logic;
  signal ip_x, ip_y, dp_x, dp_y, av_x, av_y : unsigned(COORD_W - 1 downto 0);
  signal ip_cbin, dp_cbin, av_cbin : std_logic_vector(CB_W - 1 downto 0);
  signal ip_obin, dp_obin : std_logic_vector(3 downto 0);
  signal fs, fe, ferr, ds, de, derr : std_logic;
  signal dq : unsigned(2 downto 0);
  signal m_valid, m_last : std_logic;
  signal m_bin : unsigned(CB_W - 1 downto 0);
  signal m_obin : unsigned(3 downto 0);
  signal m_x, m_y : unsigned(COORD_W - 1 downto 0);
begin
  frame_start <= fs;
  frame_end <= fe;
  frame_error <= ferr;
  px_valid <= m_valid;
  px_last <= m_last;
  px_x <= m_x;
  px_y <= m_y;
  px_bin <= m_bin;
  px_obin <= m_obin;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 ORIENT_T => ORIENT_T)
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => in_valid, in_data => in_data, in_sof => in_sof, in_eol => in_eol,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => open,
              ip_obin => ip_obin, frame_start => fs, frame_end => fe, frame_error => ferr,
              av_valid => av_valid, av_x => av_x, av_y => av_y, av_cbin => av_cbin);

  u_dec : entity work.ms_decimate
    generic map (COORD_W => COORD_W, LOG2_D_MAX => LOG2_D_MAX, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => 4)
    port map (clk => clk, rst => rst, dec_log2 => dec_log2, frame_start => fs, frame_end => fe,
              frame_error => ferr, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin,
              ip_ebin => ip_obin, dp_start => ds, dp_end => de, dp_error => derr, dp_valid => dp_valid,
              dp_x => dp_x, dp_y => dp_y, dp_cbin => dp_cbin, dp_ebin => dp_obin, dec_q => dq);

  u_merge : entity work.ms_init_merge
    generic map (COORD_W => COORD_W, BIN_W => CB_W, HALF_W => HALF_W, RING_W => RING_W,
                 RING16_MAX => RING16_MAX, MAX_FRAME_W => MAX_FRAME_W, LOG2_D_MAX => LOG2_D_MAX)
    port map (clk => clk, rst => rst, start => start, cx => cx, cy => cy, wb => wb, hb => hb,
              ring16 => ring16, frame_width => frame_width, frame_height => frame_height,
              av_valid => av_valid, av_x => av_x, av_y => av_y, av_cbin => av_cbin, dec_q => dq,
              dp_start => ds, dp_end => de, dp_error => derr, dp_valid => dp_valid, dp_x => dp_x,
              dp_y => dp_y, dp_cbin => dp_cbin, dp_obin => dp_obin,
              px_valid => m_valid, px_bin => m_bin, px_obin => m_obin, px_x => m_x, px_y => m_y,
              px_last => m_last, overflow => overflow);

  u_bg : entity work.ms_bg_model
    generic map (BIN_W => CB_W, HALF_W => HALF_W, COORD_W => COORD_W, RING_W => RING_W, Q_W => Q_W,
                 O_W => O_W, KD_W => KD_W, N_ORIENT => N_ORIENT, ORIENT_W => 4)
    port map (clk => clk, rst => rst, start => start, cx => cx, cy => cy, wb => wb, hb => hb,
              ring16 => ring16, busy => busy, counting => counting, done => done,
              px_valid => m_valid, px_bin => m_bin, px_obin => m_obin, px_x => m_x, px_y => m_y,
              px_last => m_last, n_box => n_box, n_ring => n_ring, o_min => open, qv_sum => open,
              m_rd_addr => m_rd_addr, m_rd_obin => m_rd_obin, m_qn => m_qn, m_t => m_t,
              m_qn_all => open, m_t_all => open);
end architecture;
