-- ms_bg_model: background-weighted (CBWH) target model of tracker v2, learnt at init.
--
-- Computes mstrack.fixed.blocks_v2.ms_bg_model(bins, cx, cy, wb, hb, ring16, N_ORIENT N_BINS) bit for
-- bit, from the pixel stream of the (decimated) init frame.  N_ORIENT = 1 (default): u = px_bin, the
-- colour bin (px_obin, m_rd_obin ignored).  N_ORIENT > 1 (tracker v2's joint bins, N_ORIENT 9):
-- u = the joint bin (colour px_bin, orientation px_obin), the model's N_ORIENT colour + obin
-- (ms_joint_bin); it lives at address {obin, colour} = obin 2**BIN_W + colour, so each orientation is
-- a bank of 2**BIN_W colour words (the model RAM is N_ORIENT such banks, read all at once through
-- m_qn_all / m_t_all).  The passes below walk all N = N_ORIENT N_BINS joint bins in address order;
-- min, sums and per-bin functions do not depend on the order, and the totals are the same pixels'
-- (Q_W, O_W, the divider's widths unchanged).
--   box  : pixels with |dx| <= ex, |dy| <= ey and |dx| <= XR[|dy|] (dx = x - cx, dy = y - cy,
--          ex = (wb - 1) / 2, ey = (hb - 1) / 2, XR = the row extents of ms_kernel_tables: the
--          exact flat-ellipse test TA[|dx|] + TB[|dy|] < D of ms_kernel)   -> Q[u] += 1
--   ring : pixels with |dx| <= ex + gx, |dy| <= ey + gy, not (|dx| <= ex and |dy| <= ey),
--          gx = (ring16 wb) >> 4, gy = (ring16 hb) >> 4                     -> O[u] += 1
--          (the clipping of the ring to the image is implicit: only image pixels stream in);
-- then, after the frame, three passes over the bins (one bin per clock each):
--   pass 1: o* = the smallest non-zero O[u];
--   pass 2: T[u] = (Q[u] no > O[u] nq) (nq = sum Q, no = sum O; without ring pixels, no = 0:
--           T[u] = (Q[u] > 0)); v[u] = min(floor(o* 2**8 / O[u]), 2**8) (O[u] = 0: the
--           divider's d = 0 saturates to all ones, min gives 2**8, as the model);
--           qv[u] = Q[u] v[u], tot = sum qv; {T, qv} written back over {Q, O};
--   pass 3: Qn[u] = floor(qv[u] 2**16 / tot) (0 when qv[u] = 0); {T, Qn} written into the
--           model RAM; the count word cleared (ready for the next init).
-- One pipelined ms_divider serves passes 2 and 3; the products are ms_mult_r4 LUT multipliers.
--
-- Pixel input: any order (each pixel carries its coordinates), at most one per clock, gaps
-- allowed; px_last marks the frame's last pixel.  The caller streams every pixel of the image
-- the model sees (the decimated frame frame[::D, ::D], coordinates in decimated px) exactly once.
-- Counting: stage A registers |dx|, |dy|; stage B the XR look-up (registered) and the rectangle
-- tests; stage C the box / ring flags; then a read-modify-write of the count RAM word
-- {T | Q | O} at the pixel's bin (read latency 3, written one clock after the increment) with
-- forwarding from the 4 pixels before (any sequence of bins, runs of one bin included, counts
-- exactly).
--
-- Memories: count RAM N_ORIENT N_BINS x (1 + Q_W + O_W) (ms_ram_sdp, RD_LAT 3), model RAM N_ORIENT
-- banks of MODELS N_BINS x 18 {T | Qn} (MODELS > 1: one model per target, learnt into model m_wr_sel
-- (taken with start), read from model m_rd_sel; the others keep theirs; m_wr_sel, m_rd_sel < MODELS), XR table and Q delay memory (LUT RAM); the ECP5 mapping, cost and
-- Fmax: docs/blocks/ms_bg_model.md.
--
-- Latency (tb/test_ms_bg_model.py measures both):
--   start -> counting : the kernel-table set-up of (wb, hb) (flat ms_kernel_tables: at most
--                       215 clocks at HALF_W = 6) + 2 clocks, exactly; pixels before `counting` are
--                       ignored (the top starts the block when the init box is taken, between
--                       frames, so this costs nothing on the stream).
--   px_last -> done   : LAT_DONE = 3 N + 65 clocks at the default widths, N = N_ORIENT N_BINS:
--                       drain 7, pass 1 N + 4, pass 2 N + 31 (read 3, T products M(Q_W) = 4, T 1,
--                       divider 18, v Q M(9) = 4, end 1), pass 3 N + 23 (read 3, divider 18,
--                       end, done 2); M(a) = 1 + max(1, ceil(log2(ceil(a / 2)))) is the
--                       ms_mult_r4 latency (constant LAT_DONE).  1,601 clocks at N = 512; 13,889 at
--                       N_ORIENT 9 (N = 4,608), on the init frame only (the v2 budget:
--                       docs/blocks/ms_bg_model.md).
-- Throughput: one pixel per clock while counting; one model per init.
-- Handshake : `start` (with cx, cy, wb, hb, ring16) is taken when busy = 0; busy stays high
--             until `done` (one-clock pulse); n_box, n_ring, o_min, qv_sum are stable from done
--             until the next start.  The model RAM read port (m_rd_addr, m_rd_obin -> m_qn, m_t
--             one clock later: bank m_rd_obin; m_qn_all, m_t_all: every bank at m_rd_addr, from
--             the banks' read registers) may be used at any time; during a model computation it
--             shows a mix of the old and the new model.
--             One count port: with joint bins the top merges the Sobel's interior pixels and
--             the border pixels into one stream (ms_init_merge).
-- Reset     : synchronous, active high; control state; then N clocks clear the count RAM
--             (busy = 1 meanwhile; 4,608 at N_ORIENT 9).  The model RAM keeps its contents.  To
--             abandon an init frame (stream error), reset the block.
-- Model     : mstrack.fixed.blocks_v2.ms_bg_model (ModelV2 Qn, T; sums of Q, O).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_bg_model is
  generic (
    BIN_W   : natural := 9;   -- bin index bits, N_BINS = 2**BIN_W (RAM depth, clocks per pass)
    HALF_W  : natural := 6;   -- ex, ey bits; wb, hb have HALF_W + 1 bits (3 .. 2**(HALF_W+1) - 1)
    COORD_W : natural := 12;  -- pixel coordinate bits (decimated px)
    RING_W  : natural := 5;   -- ring16 bits (bg_ring = ring16 / 16)
    Q_W     : natural := 14;  -- Q[u] and sum Q bits: must hold (2 ex + 1)(2 ey + 1)
    O_W     : natural := 17;  -- O[u] and sum O bits: must hold the ring area (>= 8)
    KD_W    : natural := 29;  -- kernel-table width (ms_kernel_tables: holds w^2 h^2)
    N_ORIENT : natural range 1 to 16 := 1;  -- orientation banks: the joint bin (px_bin, px_obin) has
                              -- N_ORIENT 2**BIN_W values (RAM depths, clocks per pass); 1 = colour only
    ORIENT_W : natural := 4;  -- width of px_obin, m_rd_obin (2**ORIENT_W >= N_ORIENT)
    MODELS   : positive := 1  -- models held (one per target): model RAM depth MODELS N_BINS per bank
  );
  port (
    clk       : in  std_logic;                             -- clock
    rst       : in  std_logic;                             -- synchronous reset, active high
    -- control
    start     : in  std_logic;                             -- pulse: learn a model (taken when busy = 0)
    cx        : in  unsigned(COORD_W - 1 downto 0);        -- box centre column (decimated px)
    cy        : in  unsigned(COORD_W - 1 downto 0);        -- box centre row
    wb        : in  unsigned(HALF_W downto 0);             -- box diameter x (3 ..)
    hb        : in  unsigned(HALF_W downto 0);             -- box diameter y (3 ..)
    ring16    : in  unsigned(RING_W - 1 downto 0);         -- ring width per side, 1/16 of the box size
    m_wr_sel  : in  unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
                                                           -- the model this start learns (MODELS > 1)
    busy      : out std_logic;                             -- from start (or reset) until done
    counting  : out std_logic;                             -- pixels are counted
    done      : out std_logic;                             -- pulse: model written
    -- pixels of the init frame
    px_valid  : in  std_logic;                             -- a pixel (ignored unless counting)
    px_bin    : in  unsigned(BIN_W - 1 downto 0);          -- its bin (colour bin when N_ORIENT > 1)
    px_obin   : in  unsigned(ORIENT_W - 1 downto 0) := (others => '0');  -- its orientation bin
                                                           -- 0 .. N_ORIENT - 1 (ignored if N_ORIENT = 1)
    px_x      : in  unsigned(COORD_W - 1 downto 0);        -- its column
    px_y      : in  unsigned(COORD_W - 1 downto 0);        -- its row
    px_last   : in  std_logic;                             -- with px_valid: the frame's last pixel
    -- results (stable from done)
    n_box     : out unsigned(Q_W - 1 downto 0);            -- nq = sum Q
    n_ring    : out unsigned(O_W - 1 downto 0);            -- no = sum O
    o_min     : out unsigned(O_W - 1 downto 0);            -- o* (all ones when no = 0)
    qv_sum    : out unsigned(Q_W + 7 downto 0);            -- tot = sum Q v
    -- model read port
    m_rd_addr : in  unsigned(BIN_W - 1 downto 0);          -- bin (colour bin when N_ORIENT > 1)
    m_rd_obin : in  unsigned(ORIENT_W - 1 downto 0) := (others => '0');  -- orientation bank (N_ORIENT > 1)
    m_rd_sel  : in  unsigned(clog2(MODELS) - 1 downto 0) := (others => '0');
                                                           -- the model read (MODELS > 1)
    m_qn      : out unsigned(16 downto 0);                 -- Qn[bin] (Q0.16, <= 2**16), 1 clock later
    m_t       : out std_logic;                             -- T[bin], 1 clock later
    m_qn_all  : out std_logic_vector(N_ORIENT * 17 - 1 downto 0);  -- Qn of bank o at o*17, 1 clock later
    m_t_all   : out std_logic_vector(N_ORIENT - 1 downto 0)        -- T of bank o at bit o, 1 clock later
  );
end entity;

architecture rtl of ms_bg_model is
  constant N_BINS  : natural := 2 ** BIN_W;                   -- colour bins (words per model bank)
  constant OB_W    : natural := clog2(N_ORIENT) * boolean'pos(N_ORIENT > 1);  -- bank bits of an address
  constant AW      : natural := BIN_W + OB_W;                -- joint address {obin, colour}
  constant NJ      : natural := N_ORIENT * N_BINS;           -- joint bins: count RAM depth, clocks per pass
  constant BG_FRAC : natural := 8;                 -- v in Q.8 (blocks_v2.BG_FRAC)
  constant QN_FRAC : natural := 16;                -- Qn in Q.16 (blocks_v2.QN_BITS)
  constant QN_W    : natural := QN_FRAC + 1;       -- Qn bits (<= 2**16)
  constant V_W     : natural := BG_FRAC + 1;       -- v bits (<= 2**8)
  constant QV_W    : natural := Q_W + BG_FRAC;     -- Q v (Q <= 2**Q_W - 1, v <= 2**8)
  constant TOT_W   : natural := Q_W + BG_FRAC;     -- sum Q v <= nq 2**8
  constant CW      : natural := 1 + Q_W + O_W;     -- count word [T | Q | O], later [T | qv]
  constant MW      : natural := 1 + QN_W;          -- model word [T | Qn]
  constant DN_W    : natural := max(QV_W + QN_FRAC, O_W + BG_FRAC);   -- divider dividend
  constant DD_W    : natural := max(TOT_W, O_W);                      -- divider divisor
  constant G_W     : natural := max(COORD_W, RING_W + HALF_W + 1) + 1; -- ring extents
  constant P_W     : natural := Q_W + O_W;         -- T products
  constant RD_LAT  : natural := 3;                 -- count RAM read latency (ms_ram_sdp: ECP5 OUTREG)
  constant DRAIN   : natural := RD_LAT + 4;        -- px_last -> S_P1 (the last count is in the RAM)
  constant DVT_W  : natural := 3;                 -- divider tag [last | qz | T]
  constant QD_W   : natural := clog2(QN_W + 2);   -- Q delay memory address (holds > divider latency)
  constant MTT_W  : natural := Q_W + O_W + 1;    -- T product tag [last | O | Q]
  constant MVT_W  : natural := AW + 2;            -- v Q product tag [last | T | u]
  -- ms_mult_r4 latency for an A_W-bit digit operand: 1 + max(1, ceil(log2(ceil(A_W / 2))))
  function mult_lat(a_w : natural) return natural is
  begin
    return 1 + max(1, clog2((a_w + 1) / 2));
  end function;
  -- px_last -> done (documentation; the test measures it): drain, pass 1, pass 2, pass 3
  constant LAT_DONE : natural := DRAIN + (NJ + RD_LAT + 1)
                                 + (NJ + RD_LAT + mult_lat(Q_W) + 1 + (QN_W + 1) + mult_lat(V_W) + 1)
                                 + (NJ + RD_LAT + (QN_W + 1) + 2);

  type state_t is (S_CLEAR, S_IDLE, S_SETUP, S_COUNT, S_DRAIN, S_P1, S_P2, S_P3, S_DONE);
  signal state : state_t := S_CLEAR;

  -- parameters
  signal cx_r, cy_r     : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal wb_r, hb_r     : unsigned(HALF_W downto 0) := (others => '0');
  signal ring_r         : unsigned(RING_W - 1 downto 0) := (others => '0');
  signal ex_r, ey_r     : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal gx, gy         : unsigned(G_W - 1 downto 0) := (others => '0');   -- (ring16 n) << 0, then >> 4
  signal rx, ry         : unsigned(G_W - 1 downto 0) := (others => '0');   -- ex + gx, ey + gy
  signal mul_cnt        : natural range 0 to RING_W := 0;
  signal mul_done       : std_logic := '0';
  signal kt_start, kt_done, kt_we : std_logic;
  signal kt_ex, kt_ey, kt_addr, kt_xr : unsigned(HALF_W - 1 downto 0);
  signal kt_seen        : std_logic := '0';
  type xr_ram_t is array (0 to 2 ** HALF_W - 1) of unsigned(HALF_W - 1 downto 0);
  signal xr_ram         : xr_ram_t := (others => (others => '0'));

  -- reset clear
  signal clr_addr       : unsigned(AW - 1 downto 0) := (others => '0');
  signal drain_cnt      : natural range 0 to DRAIN := 0;

  -- pixel stages A (|dx|, |dy|), B (XR, rectangles), C (b_*: box / ring flags)
  signal a_v            : std_logic := '0';
  signal a_bin          : unsigned(AW - 1 downto 0) := (others => '0');
  signal a_adx, a_ady   : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal xb_v, xb_in, xb_ring : std_logic := '0';
  signal xb_xr, xb_adx  : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal xb_bin         : unsigned(AW - 1 downto 0) := (others => '0');
  signal b_acc, b_box   : std_logic := '0';
  signal b_bin          : unsigned(AW - 1 downto 0) := (others => '0');
  signal nq_r           : unsigned(Q_W - 1 downto 0) := (others => '0');
  signal no_r           : unsigned(O_W - 1 downto 0) := (others => '0');

  -- count RAM and its read-modify-write pipeline (ms_histogram's scheme, one lane)
  signal rd_addr        : unsigned(AW - 1 downto 0);
  signal rd_word        : std_logic_vector(CW - 1 downto 0);     -- RAM read data, RD_LAT clocks after rd_addr
  signal s1_acc, s1_box, s2_acc, s2_box, s3_acc, s3_box : std_logic := '0';
  signal s1_b, s2_b, s3_b : unsigned(AW - 1 downto 0) := (others => '0');
  signal old_w, new_w   : std_logic_vector(CW - 1 downto 0);
  signal wq_we, wq2_we  : std_logic := '0';
  signal wq_b, wq2_b    : unsigned(AW - 1 downto 0) := (others => '0');
  signal wq_word, wq2_word, wq3_word, fwd_word : std_logic_vector(CW - 1 downto 0) := (others => '0');
  signal h1, h2, h3, h4, fwd_hit : std_logic := '0';

  -- passes: issue side and read stages
  signal iss_en         : std_logic := '0';
  signal iss_addr       : unsigned(AW - 1 downto 0) := (others => '0');
  signal r1_v, r2_v, r3_v, r1_last, r2_last, r3_last : std_logic := '0';
  signal r1_u, r2_u, r3_u : unsigned(AW - 1 downto 0) := (others => '0');
  signal pass_we        : std_logic;                        -- count RAM write of a pass
  signal pass_wa        : unsigned(AW - 1 downto 0);
  signal pass_wd        : std_logic_vector(CW - 1 downto 0);
  signal omin           : unsigned(O_W - 1 downto 0) := (others => '1');
  signal tot            : unsigned(TOT_W - 1 downto 0) := (others => '0');
  signal pass_end       : std_logic := '0';                 -- the pass's last bin is finished

  -- pass 2: T products, divider, v Q product
  signal w_q            : unsigned(Q_W - 1 downto 0);
  signal w_o            : unsigned(O_W - 1 downto 0);
  signal m1_v, m2_v     : std_logic;
  signal m1_p, m2_p     : std_logic_vector(P_W - 1 downto 0);
  signal m1_tag, m2_tag : std_logic_vector(MTT_W - 1 downto 0);
  signal mt_in_v        : std_logic;
  signal mt_tag_in      : std_logic_vector(MTT_W - 1 downto 0);
  signal t_v, t_t, t_last : std_logic := '0';
  signal t_q            : unsigned(Q_W - 1 downto 0) := (others => '0');
  signal t_o            : unsigned(O_W - 1 downto 0) := (others => '0');
  signal dv_in_v, dv_out_v : std_logic;
  signal dv_n           : unsigned(DN_W - 1 downto 0);
  signal dv_d           : unsigned(DD_W - 1 downto 0);
  signal dv_tag_in, dv_tag : std_logic_vector(DVT_W - 1 downto 0);
  signal dv_q           : unsigned(QN_W - 1 downto 0);
  signal dv_cnt         : unsigned(AW - 1 downto 0) := (others => '0');  -- results out of the divider
  signal qd_wp, qd_rp   : unsigned(QD_W - 1 downto 0) := (others => '0');   -- Q delay memory pointers
  type qd_ram_t is array (0 to 2 ** QD_W - 1) of std_logic_vector(Q_W - 1 downto 0);
  signal qd_ram         : qd_ram_t;                  -- Q beside the divider (pass 2), LUT RAM
  signal mv_in_v, mv_v  : std_logic;
  signal mv_a           : unsigned(V_W - 1 downto 0);
  signal mv_b           : std_logic_vector(Q_W - 1 downto 0);
  signal mv_tag_in, mv_tag : std_logic_vector(MVT_W - 1 downto 0);
  signal mv_p           : std_logic_vector(QV_W - 1 downto 0);

  -- model RAM: N_ORIENT banks of MODELS N_BINS words (bank = the address's obin; model m at words
  -- m N_BINS ..: the address {model, colour bin})
  constant SEL_W  : natural := clog2(MODELS);              -- m_wr_sel / m_rd_sel width (model bits of an
                                                            -- address when MODELS > 1)
  type m_ram_t is array (0 to MODELS * N_BINS - 1) of std_logic_vector(MW - 1 downto 0);
  signal m_sel_r        : unsigned(SEL_W - 1 downto 0) := (others => '0');   -- m_wr_sel taken with start
  function m_index(sel : unsigned; bin : unsigned) return natural is
  begin
    if MODELS = 1 then
      return to_integer(bin);
    end if;
    return to_integer(sel & bin);
  end function;
  type m_rd_arr_t is array (0 to N_ORIENT - 1) of std_logic_vector(MW - 1 downto 0);
  signal m_rd_all       : m_rd_arr_t := (others => (others => '0'));
  signal m_obin_r       : unsigned(ORIENT_W - 1 downto 0) := (others => '0');
  signal m_we           : std_logic := '0';
  signal m_wa           : unsigned(AW - 1 downto 0) := (others => '0');
  signal m_wd           : std_logic_vector(MW - 1 downto 0) := (others => '0');
  signal m_rd           : std_logic_vector(MW - 1 downto 0);

  signal done_r         : std_logic := '0';

  -- joint address {obin, colour} = obin 2**BIN_W + colour (N_ORIENT = 1: the colour bin)
  function jaddr(ob : unsigned(ORIENT_W - 1 downto 0); c : unsigned(BIN_W - 1 downto 0)) return unsigned is
  begin
    return shift_left(resize(ob, AW), BIN_W) or resize(c, AW);
  end function;
begin
  assert N_ORIENT = 1 or 2 ** ORIENT_W >= N_ORIENT
    report "ms_bg_model: ORIENT_W too narrow for N_ORIENT" severity failure;
  assert O_W >= BG_FRAC report "ms_bg_model: O_W must be >= 8 (count word holds [T | qv])" severity failure;
  assert HALF_W >= 2 and BIN_W >= 1 report "ms_bg_model: HALF_W >= 2, BIN_W >= 1" severity failure;

  busy     <= '0' when state = S_IDLE else '1';
  counting <= '1' when state = S_COUNT else '0';
  done     <= done_r;

  ---------------------------------------------------------------------------- set-up
  u_tables : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KERNEL_EPAN => 0, KERNEL_BITS => 8, KVAL_W => 1, KD_W => KD_W)
    port map (clk => clk, rst => rst, start => kt_start, w => wb_r, h => hb_r, busy => open,
              done => kt_done, ex => kt_ex, ey => kt_ey, kd_d => open, kt_we => kt_we,
              kt_addr => kt_addr, kt_ta => open, kt_tb => open, kt_ka => open, kt_kb => open,
              kt_xr => kt_xr);

  p_xr : process (clk)
  begin
    if rising_edge(clk) then
      if kt_we = '1' then
        xr_ram(to_integer(kt_addr)) <= kt_xr;
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- control
  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      kt_start <= '0';
      done_r   <= '0';
      case state is
        when S_CLEAR =>                                  -- reset clear of the count RAM
          clr_addr <= clr_addr + 1;
          if clr_addr = NJ - 1 then
            state <= S_IDLE;
          end if;
        when S_IDLE =>
          if start = '1' then
            m_sel_r <= m_wr_sel;
            cx_r <= cx;
            cy_r <= cy;
            wb_r <= wb;
            hb_r <= hb;
            ring_r <= ring16;
            gx <= (others => '0');
            gy <= (others => '0');
            mul_cnt <= 0;
            mul_done <= '0';
            kt_seen <= '0';
            kt_start <= '1';
            state <= S_SETUP;
          end if;
        when S_SETUP =>
          -- gx, gy = ring16 wb, ring16 hb by shift-and-add (MSB first), then >> 4, ex + gx, ey + gy
          if mul_cnt < RING_W then
            gx <= shift_left(gx, 1);
            gy <= shift_left(gy, 1);
            if ring_r(RING_W - 1 - mul_cnt) = '1' then
              gx <= shift_left(gx, 1) + resize(wb_r, G_W);
              gy <= shift_left(gy, 1) + resize(hb_r, G_W);
            end if;
            mul_cnt <= mul_cnt + 1;
          elsif mul_done = '0' then
            gx <= shift_right(gx, 4);
            gy <= shift_right(gy, 4);
            mul_done <= '1';
          end if;
          if kt_done = '1' then
            kt_seen <= '1';
            ex_r <= kt_ex;
            ey_r <= kt_ey;
          end if;
          if kt_seen = '1' and mul_done = '1' then
            rx <= gx + resize(ex_r, G_W);
            ry <= gy + resize(ey_r, G_W);
            state <= S_COUNT;
          end if;
        when S_COUNT =>
          if px_valid = '1' and px_last = '1' then
            drain_cnt <= 0;
            state <= S_DRAIN;
          end if;
        when S_DRAIN =>                                  -- the last pixel's count is written
          if drain_cnt = DRAIN - 1 then
            state <= S_P1;
          else
            drain_cnt <= drain_cnt + 1;
          end if;
        when S_P1 | S_P2 | S_P3 =>
          if pass_end = '1' then
            if state = S_P1 then
              state <= S_P2;
            elsif state = S_P2 then
              state <= S_P3;
            else
              state <= S_DONE;
            end if;
          end if;
        when S_DONE =>
          done_r <= '1';
          state <= S_IDLE;
      end case;
      if rst = '1' then
        state <= S_CLEAR;
        clr_addr <= (others => '0');
        kt_start <= '0';
        done_r <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- pixel flags
  p_pix : process (clk)
    variable dx, dy : signed(COORD_W downto 0);
    variable in_ex, in_ey, box, ring : boolean;
  begin
    if rising_edge(clk) then
      -- stage A: |dx|, |dy|
      dx := signed('0' & px_x) - signed('0' & cx_r);
      dy := signed('0' & px_y) - signed('0' & cy_r);
      -- |dx|, |dy| by negation, not `abs` (GHDL 2.0's Verilog writer prints `abs` as VHDL)
      if dx < 0 then
        dx := -dx;
      end if;
      if dy < 0 then
        dy := -dy;
      end if;
      a_adx <= resize(unsigned(dx), COORD_W);
      a_ady <= resize(unsigned(dy), COORD_W);
      a_bin <= jaddr(px_obin, px_bin);
      assert not (px_valid = '1' and state = S_COUNT and N_ORIENT > 1 and px_obin >= N_ORIENT)
        report "ms_bg_model: px_obin >= N_ORIENT" severity error;
      a_v   <= px_valid and to_sl(state = S_COUNT);
      -- stage B: XR[|dy|] registered (LUT RAM read), the rectangle tests
      in_ex := a_adx <= resize(ex_r, COORD_W);
      in_ey := a_ady <= resize(ey_r, COORD_W);
      ring  := resize(a_adx, G_W) <= rx and resize(a_ady, G_W) <= ry and not (in_ex and in_ey);
      xb_xr   <= xr_ram(to_integer(a_ady(HALF_W - 1 downto 0)));
      xb_adx  <= a_adx(HALF_W - 1 downto 0);
      xb_in   <= to_sl(in_ex and in_ey);
      xb_ring <= to_sl(ring);
      xb_v    <= a_v;
      xb_bin  <= a_bin;
      -- stage C: box = inside the rectangle and |dx| <= XR[|dy|] (XR <= ex < 2**HALF_W, so the
      -- low HALF_W bits of |dx| suffice once |dx| <= ex)
      box   := xb_in = '1' and xb_adx <= xb_xr;
      b_acc <= xb_v and to_sl(box or xb_ring = '1');
      b_box <= to_sl(box);
      b_bin <= xb_bin;
      -- totals from the registered flags
      if state = S_SETUP then
        nq_r <= (others => '0');
        no_r <= (others => '0');
      elsif b_acc = '1' and b_box = '1' then
        nq_r <= nq_r + 1;
        -- the widths are the caller's (Q_W, O_W): the totals must not wrap
        assert nq_r /= 2 ** Q_W - 1 report "ms_bg_model: sum Q overflows Q_W" severity error;
      elsif b_acc = '1' then
        no_r <= no_r + 1;
        assert no_r /= 2 ** O_W - 1 report "ms_bg_model: sum O overflows O_W" severity error;
      end if;
      if rst = '1' then
        a_v   <= '0';
        xb_v  <= '0';
        b_acc <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- count RAM
  rd_addr <= iss_addr when iss_en = '1' else b_bin;

  old_w <= fwd_word when fwd_hit = '1' else rd_word;
  p_add : process (all)
    variable w : std_logic_vector(CW - 1 downto 0);
  begin
    w := old_w;
    if s3_box = '1' then
      w(O_W + Q_W - 1 downto O_W) := std_logic_vector(unsigned(old_w(O_W + Q_W - 1 downto O_W)) + 1);
    else
      w(O_W - 1 downto 0) := std_logic_vector(unsigned(old_w(O_W - 1 downto 0)) + 1);
    end if;
    new_w <= w;
  end process;

  -- the count RAM: ms_ram_sdp, read latency RD_LAT (on ECP5 DP16KD with its output register and
  -- a registered row multiplexer); written from the write register wq (write at the next edge).
  -- A read of the word written at the same edge (DP16KD collision: undefined; `inferred`: the old
  -- word) or of a junk address >= NJ (idle pixel slot: the output holds) is never used (h4).
  u_cram : entity work.ms_ram_sdp
    generic map (DEPTH => NJ, DATA_W => CW, ADDR_W => AW, RD_LAT => RD_LAT, WR_LAT => 0)
    port map (clk => clk, we => wq_we, waddr => wq_b, wdata => wq_word, raddr => rd_addr,
              rdata => rd_word);

  p_fw : process (clk)
  begin
    if rising_edge(clk) then
      s1_acc <= b_acc;
      s1_box <= b_box;
      s1_b   <= rd_addr;
      s2_acc <= s1_acc;
      s2_box <= s1_box;
      s2_b   <= s1_b;
      s3_acc <= s2_acc;
      s3_box <= s2_box;
      s3_b   <= s2_b;
      -- RAM write register: reset clear, else a pass write, else the count
      if state = S_CLEAR then
        wq_we   <= '1';
        wq_b    <= clr_addr;
        wq_word <= (others => '0');
      elsif pass_we = '1' then
        wq_we   <= '1';
        wq_b    <= pass_wa;
        wq_word <= pass_wd;
      else
        wq_we   <= s3_acc;
        wq_b    <= s3_b;
        wq_word <= new_w;
      end if;
      wq2_we   <= wq_we;
      wq2_b    <= wq_b;
      wq2_word <= wq_word;
      wq3_word <= wq2_word;
      -- a read at edge e (rd_word in stage 3, after edge e + RD_LAT - 1) misses the writes of
      -- the 4 pixels read at e - 1 .. e - 4 (their writes at e + 3 .. e, the RAM written from wq
      -- one edge after the word leaves stage 3): at edge e + 1 (the read's bin in s1_b) compare
      -- with them (s2, s3, wq, wq2), at edge e + 2 forward the newest one's word into stage 3
      -- (then new_w, wq_word, wq2_word, wq3_word)
      h1 <= s2_acc and to_sl(s2_b = s1_b);
      h2 <= s3_acc and to_sl(s3_b = s1_b);
      h3 <= wq_we and to_sl(wq_b = s1_b);
      h4 <= wq2_we and to_sl(wq2_b = s1_b);
      fwd_hit <= h1 or h2 or h3 or h4;
      if h1 = '1' then
        fwd_word <= new_w;
      elsif h2 = '1' then
        fwd_word <= wq_word;
      elsif h3 = '1' then
        fwd_word <= wq2_word;
      else
        fwd_word <= wq3_word;
      end if;
      if rst = '1' then
        s1_acc <= '0';
        s2_acc <= '0';
        s3_acc <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- bin passes
  -- issue: joint addresses 0 .. NJ - 1 ({obin, colour}), one per clock, at the start of each pass
  p_issue : process (clk)
    variable first : boolean;
  begin
    if rising_edge(clk) then
      first := (state = S_DRAIN and drain_cnt = DRAIN - 1)
               or ((state = S_P1 or state = S_P2) and pass_end = '1');
      if first then
        iss_en   <= '1';
        iss_addr <= (others => '0');
      elsif iss_en = '1' then
        if iss_addr = NJ - 1 then
          iss_en <= '0';
        else
          iss_addr <= iss_addr + 1;
        end if;
      end if;
      -- read stages r1 .. r3 (RD_LAT = 3): r3 beside rd_word
      r1_v    <= iss_en;
      r1_u    <= iss_addr;
      r1_last <= iss_en and to_sl(iss_addr = NJ - 1);
      r2_v    <= r1_v;
      r2_u    <= r1_u;
      r2_last <= r1_last;
      r3_v    <= r2_v;
      r3_u    <= r2_u;
      r3_last <= r2_last;
      if rst = '1' then
        iss_en <= '0';
        r1_v   <= '0';
        r2_v   <= '0';
        r3_v   <= '0';
      end if;
    end if;
  end process;

  w_q <= unsigned(rd_word(O_W + Q_W - 1 downto O_W));
  w_o <= unsigned(rd_word(O_W - 1 downto 0));

  -- pass 1: o* (also restarts tot)
  p_p1 : process (clk)
  begin
    if rising_edge(clk) then
      if state = S_DRAIN then
        omin <= (others => '1');
        tot  <= (others => '0');
      elsif state = S_P1 and r3_v = '1' then
        if w_o /= 0 and w_o < omin then
          omin <= w_o;
        end if;
      end if;
      if state = S_P2 and mv_v = '1' then
        tot <= tot + resize(unsigned(mv_p), TOT_W);
      end if;
    end if;
  end process;

  -- pass 2 stage 1: T products Q no and nq O
  mt_in_v   <= r3_v when state = S_P2 else '0';
  mt_tag_in <= r3_last & std_logic_vector(w_o) & std_logic_vector(w_q);
  u_mt1 : entity work.ms_mult_r4
    generic map (A_W => Q_W, B_W => O_W, B_SIGNED => false, P_W => P_W, TAG_W => MTT_W)
    port map (clk => clk, rst => rst, in_valid => mt_in_v, in_a => w_q, in_b => std_logic_vector(no_r),
              in_tag => mt_tag_in, out_valid => m1_v, out_p => m1_p, out_tag => m1_tag);
  u_mt2 : entity work.ms_mult_r4
    generic map (A_W => Q_W, B_W => O_W, B_SIGNED => false, P_W => P_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => mt_in_v, in_a => nq_r, in_b => std_logic_vector(w_o),
              in_tag => "0", out_valid => m2_v, out_p => m2_p, out_tag => open);

  -- pass 2 stage 2: T registered with its bin, Q, O
  p_t : process (clk)
    variable q : unsigned(Q_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      q := unsigned(m1_tag(Q_W - 1 downto 0));
      t_v    <= m1_v;
      t_q    <= q;
      t_o    <= unsigned(m1_tag(Q_W + O_W - 1 downto Q_W));
      t_last <= m1_tag(MTT_W - 1);
      if no_r = 0 then
        t_t <= to_sl(q /= 0);
      else
        t_t <= to_sl(unsigned(m1_p) > unsigned(m2_p));
      end if;
      if rst = '1' then
        t_v <= '0';
      end if;
    end if;
  end process;

  -- the divider: pass 2 floor(o* 2**8 / O), pass 3 floor(qv 2**16 / tot)
  dv_in_v   <= t_v when state = S_P2 else r3_v when state = S_P3 else '0';
  dv_n      <= shift_left(resize(omin, DN_W), BG_FRAC) when state = S_P2
               else shift_left(resize(unsigned(rd_word(QV_W - 1 downto 0)), DN_W), QN_FRAC);
  dv_d      <= resize(t_o, DD_W) when state = S_P2 else resize(tot, DD_W);
  dv_tag_in <= (t_last & '0' & t_t) when state = S_P2
               else (r3_last & to_sl(unsigned(rd_word(QV_W - 1 downto 0)) = 0) & rd_word(CW - 1));

  -- results leave the divider in bin order: counters give their bin; in pass 2 Q waits beside
  -- the divider in a small delay memory (written at the divider input, read at its output)
  p_dcnt : process (clk)
  begin
    if rising_edge(clk) then
      if state = S_P1 or pass_end = '1' then
        qd_wp  <= (others => '0');
        qd_rp  <= (others => '0');
        dv_cnt <= (others => '0');
      else
        if dv_in_v = '1' then
          qd_wp <= qd_wp + 1;
        end if;
        if dv_out_v = '1' then
          qd_rp  <= qd_rp + 1;
          dv_cnt <= dv_cnt + 1;
        end if;
      end if;
      if state = S_P2 and t_v = '1' then
        qd_ram(to_integer(qd_wp)) <= std_logic_vector(t_q);
      end if;
    end if;
  end process;
  u_div : entity work.ms_divider
    generic map (N_W => DN_W, D_W => DD_W, Q_W => QN_W, TAG_W => DVT_W)
    port map (clk => clk, rst => rst, in_valid => dv_in_v, in_n => dv_n, in_d => dv_d,
              in_tag => dv_tag_in, out_valid => dv_out_v, out_q => dv_q, out_tag => dv_tag);

  -- pass 2 stage 3: v = min(q, 2**8), qv = v Q
  mv_in_v   <= dv_out_v when state = S_P2 else '0';
  mv_a      <= to_unsigned(2 ** BG_FRAC, V_W) when dv_q >= 2 ** BG_FRAC else resize(dv_q, V_W);
  mv_b      <= qd_ram(to_integer(qd_rp));
  mv_tag_in <= dv_tag(2) & dv_tag(0) & std_logic_vector(dv_cnt);
  u_mv : entity work.ms_mult_r4
    generic map (A_W => V_W, B_W => Q_W, B_SIGNED => false, P_W => QV_W, TAG_W => MVT_W)
    port map (clk => clk, rst => rst, in_valid => mv_in_v, in_a => mv_a, in_b => mv_b,
              in_tag => mv_tag_in, out_valid => mv_v, out_p => mv_p, out_tag => mv_tag);

  -- count RAM writes of the passes: pass 2 {T, qv}; pass 3 clears the word it has read
  p_pw : process (all)
  begin
    pass_we <= '0';
    pass_wa <= r3_u;
    pass_wd <= (others => '0');
    if state = S_P2 and mv_v = '1' then
      pass_we <= '1';
      pass_wa <= unsigned(mv_tag(AW - 1 downto 0));
      pass_wd(CW - 1) <= mv_tag(AW);
      pass_wd(QV_W - 1 downto 0) <= mv_p;
    elsif state = S_P3 and r3_v = '1' then
      pass_we <= '1';
    end if;
  end process;

  -- pass end: pass 1 at its last read, pass 2 at its last write, pass 3 at its last model write
  p_end : process (clk)
  begin
    if rising_edge(clk) then
      pass_end <= '0';
      if state = S_P1 and r3_v = '1' and r3_last = '1' then
        pass_end <= '1';
      elsif state = S_P2 and mv_v = '1' and mv_tag(MVT_W - 1) = '1' then
        pass_end <= '1';
      elsif state = S_P3 and dv_out_v = '1' and dv_tag(DVT_W - 1) = '1' then
        pass_end <= '1';
      end if;
      if pass_end = '1' then
        pass_end <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- model RAM
  p_mw : process (clk)
  begin
    if rising_edge(clk) then
      m_we <= '0';
      if state = S_P3 and dv_out_v = '1' then
        m_we <= '1';
        m_wa <= dv_cnt;
        m_wd(MW - 1) <= dv_tag(0);
        if dv_tag(1) = '1' then            -- qv = 0: Qn = 0 (also when tot = 0)
          m_wd(QN_W - 1 downto 0) <= (others => '0');
        else
          m_wd(QN_W - 1 downto 0) <= std_logic_vector(dv_q);
        end if;
      end if;
      m_obin_r <= m_rd_obin;
      if rst = '1' then
        m_we <= '0';
      end if;
    end if;
  end process;

  -- the banks: bank o holds the joint bins (colour, o), written at m_wa = {o, colour}, all read at
  -- m_rd_addr (one clock); m_qn / m_t select bank m_rd_obin (after the read registers)
  g_mbank : for o in 0 to N_ORIENT - 1 generate
    signal mram : m_ram_t := (others => (others => '0'));
  begin
    p_mb : process (clk)
    begin
      if rising_edge(clk) then
        if m_we = '1' and shift_right(m_wa, BIN_W) = o then
          mram(m_index(m_sel_r, m_wa(BIN_W - 1 downto 0))) <= m_wd;
        end if;
        m_rd_all(o) <= mram(m_index(m_rd_sel, m_rd_addr));
      end if;
    end process;
    m_qn_all((o + 1) * QN_W - 1 downto o * QN_W) <= m_rd_all(o)(QN_W - 1 downto 0);
    m_t_all(o) <= m_rd_all(o)(MW - 1);
  end generate;
  p_msel : process (all)
  begin
    m_rd <= m_rd_all(0);
    for o in 1 to N_ORIENT - 1 loop
      if m_obin_r = o then
        m_rd <= m_rd_all(o);
      end if;
    end loop;
  end process;
  m_qn <= unsigned(m_rd(QN_W - 1 downto 0));
  m_t  <= m_rd(MW - 1);

  n_box  <= nq_r;
  n_ring <= no_r;
  o_min  <= omin;
  qv_sum <= tot;
end architecture;
