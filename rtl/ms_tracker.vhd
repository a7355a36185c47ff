-- ms_tracker: mean-shift tracking core (top level): the paper core or core v2 (generic PRESET).
--
-- PRESET selects the tracker (TrackerParams.preset); ports and handshakes are the same for both, only
-- the result word differs:
--   0 (default) the paper core: colour + edge fusion, mstrack.fixed.FixedTracker bit for bit, result
--     word of RESULT_W = 144 bits with the default generics; described below.
--   1 core v2: tracker v2 (mstrack.fixed.tracker_v2.FixedTrackerV2) bit for bit, colour only, result word
--     v2 of RESULT_W = 160 bits (mstrack.fixed.vhdl_pkg.result_layout_v2); the engine ms_tracker_v2
--     (rtl/ms_tracker_v2.vhd: its header gives the latency) with every port and generic passed through;
--     one pixel per clock (PPC = 1); the generics after RESULT_W are core v2's own.
-- Each preset ignores the other's own generics.  `mstrack hdl config --preset paper|v2` writes every
-- generic; RESULT_W and the derived widths are checked against the preset at elaboration.
--
-- PRESET 0 computes, per video frame, the tracking result of mstrack.fixed.FixedTracker bit for bit
-- (docs/architecture.md, docs/fixed_point.md).  Video in as AXI4-Stream, PPC pixels per clock
-- (generic PPC = 1, 2 or 4; AXI4-Stream video convention): pixel k of a beat in s_axis_tdata bits
-- 24k+23 .. 24k, the leftmost pixel in the low bits, each R(23:16) G(15:8) B(7:0) (RGB_PACKING = 0)
-- or AMD UG934's R(23:16) B(15:8) G(7:0) (RGB_PACKING = 1); tuser = start of frame (first beat),
-- tlast = last beat of each line.  PPC = 1 is the one-pixel core (ports as before); with PPC > 1
-- a frame whose frame_width is not a multiple of PPC is refused (error result, code 4 `size`),
-- and PPC <= LANES is required (generic assertion; the region capture writes the PPC pixels of a
-- beat into PPC different banks).  The results do not depend on PPC (bit-exact with the model).
-- One result word per frame out on m_axis_result
-- (fields: mstrack.fixed.vhdl_pkg.result_layout, LSB first: cx, cy, rho_c, rho_e, alpha_c,
-- iter_c, iter_e, stop_c, stop_e, flags, err_code, box_w, box_h, frame_count).
--
-- Target init: a box on s_init (accepted between frames) takes effect on the next frame:
-- it is clipped (ms_box_clip: to the frame interior and to 2*MAX_HALF+1 px, for the frame
-- size present when it is taken); a box with less than 3x3 px inside, or taken while the
-- frame size is out of range, is rejected (flag `rejected` in the next result; a previous
-- target stays).  The next good frame of that size learns the model histograms (flag `init`).
-- Frames before any init give results with flag `no_target`.
--
-- Protocol errors (short/long line, missing start of frame, frame cut by a new start of
-- frame, frame size out of range at a start of frame) and a good frame of another size than
-- the target's init frame give a result with flag `error` and an error code
-- (rtl/ms_stream_pkg.vhd); that frame is not tracked, the target state is unchanged, and the
-- next good frame is tracked normally.  No error result is ever lost: the input is closed
-- from the clock after the bad beat until its error result is in the FIFO.  Results are never
-- dropped: a full result FIFO back-pressures the video input.  docs/architecture.md lists
-- every fault and its behaviour.
--
-- Throughput: PPC pixels per clock while a frame streams in.  After the last pixel of a
-- frame, s_axis_tready stays low until that frame's result is computed (both features'
-- mean-shift loops in parallel, then fusion); see docs/performance.md for cycle counts.
-- Result path: the 144-bit result word is loaded in the clock after the branch that decides it,
-- from held registers (centre in c8x / c8y, the fusion's and engines' outputs, the branch's flags
-- and error code registered with it), so its load enable is one flip-flop; a tracked or learnt
-- result still leaves T_PUSH in the next clock (the frame's latency is unchanged), an error result
-- goes to the FIFO one clock after its word (the input stays closed until then).
-- The input is back-pressured while a frame is streaming only after a protocol error (until
-- the error result is written), when the result FIFO is full, and for one clock when an init
-- box is taken.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_formats_pkg.all;
use work.ms_stream_pkg.all;

entity ms_tracker is
  generic (
    PRESET         : natural := 0;               -- 0 the paper core (below), 1 core v2 (ms_tracker_v2)
    MAX_FRAME_W    : natural := 2048;            -- widest frame (line buffer depth); 3 .. 2**COORD_W - 1
    RGB_PACKING    : natural := 0;               -- s_axis_tdata layout: 0 R 23:16 G 15:8 B 7:0; 1 AMD UG934 (R B G)
    PPC            : natural := 1;               -- pixels per clock (s_axis beat): 1, 2 or 4 (<= LANES)
    LANES          : natural := D_LANES;         -- pixels per clock of a pixel pass
    COLOUR_BITS    : natural := D_COLOUR_BITS;   -- bits per channel of the colour bin
    EDGE_BINS_LOG2 : natural := D_EDGE_BINS_LOG2;-- log2 edge bins
    EDGE_SHIFT     : natural := D_EDGE_SHIFT;    -- edge bin = min(E-1, |G| >> EDGE_SHIFT)
    FEATURES       : natural := D_FEATURES;      -- 0 fused, 1 colour only, 2 edge only
    KERNEL_EPAN    : natural := D_KERNEL_EPAN;   -- 0 flat, 1 Epanechnikov
    KERNEL_BITS    : natural := D_KERNEL_BITS;   -- Epanechnikov kernel bits
    MAX_HALF       : natural := D_MAX_HALF;      -- largest window half extent
    MARGIN         : natural := D_MARGIN;        -- search margin (px)
    COORD_W        : natural := D_COORD_W;       -- frame coordinate bits
    CF             : natural := D_CF;            -- centre fraction bits
    WI             : natural := D_WI;            -- weight integer bits
    WF             : natural := D_WF;            -- weight fraction bits
    RF             : natural := D_RF;            -- Bhattacharyya term fraction bits
    AF             : natural := D_AF;            -- alpha fraction bits
    RHO_OUT_FRAC   : natural := D_RHO_OUT_FRAC;  -- reported rho fraction bits
    MAX_ITER       : natural := D_MAX_ITER;      -- iteration limit per feature
    EPS2           : natural := D_EPS2;          -- shift stop threshold (Q.2CF px^2)
    HALF_W         : natural := D_HALF_W;        -- derived widths: see mstrack.fixed.vhdl_pkg
    REGION_MAX     : natural := D_REGION_MAX;
    REGION_W       : natural := D_REGION_W;
    STRIDE         : natural := D_STRIDE;
    ADDR_W         : natural := D_ADDR_W;
    KVAL_W         : natural := D_KVAL_W;
    HIST_W         : natural := D_HIST_W;
    COUNT_W        : natural := D_COUNT_W;
    POSSUM_W       : natural := D_POSSUM_W;
    KD_W           : natural := D_KD_W;
    SQRT_IN_W      : natural := D_SQRT_IN_W;
    RHO_SUM_W      : natural := D_RHO_SUM_W;
    RATIO_Q_W      : natural := D_RATIO_Q_W;
    WEIGHT_W       : natural := D_WEIGHT_W;
    SW_W           : natural := D_SW_W;
    SWX_W          : natural := D_SWX_W;
    SHIFT_Q_W      : natural := D_SHIFT_Q_W;
    CENTRE_W       : natural := D_CENTRE_W;
    CENTRE_ABS_W   : natural := D_CENTRE_ABS_W;
    ITER_W         : natural := D_ITER_W;
    RHO_OUT_W      : natural := D_RHO_OUT_W;
    ALPHA_W        : natural := D_ALPHA_W;
    WIN_W          : natural := D_WIN_W;
    RESULT_W       : natural := D_RESULT_W;       -- PRESET 0: 144 (result word), 1: 160 (result word v2)
    -- core v2 only (PRESET 1; ms_tracker_v2's defaults; mstrack.hw.cosim.CoreConfigV2.generics)
    PAD16          : natural := 4;               -- pad in 1/16
    RING16         : natural := 10;              -- bg_ring in 1/16
    MAX_WINDOW     : natural := 127;             -- largest window diameter (decimated px)
    KT_W           : natural := 9;               -- KA/KB width (KERNEL_BITS + 1)
    ST2_W          : natural := 23;
    SHARE_W        : natural := 17;
    SPREAD_W       : natural := 25;
    SIZE_W         : natural := 20;              -- w8, h8 bits (COORD_W + 8)
    SCALE_W        : natural := 17;
    SCALE_GAIN     : natural := 19661;
    SCALE_REG      : natural := 6554;
    SCALE_STEP     : natural := 6554;
    SCALE_RATIO_Q_W: natural := 17;
    WR_Q_W         : natural := 27;
    CON_W          : natural := 18;
    LOSS_K         : natural := 1;
    REF_K          : natural := 6;
    LOSS_RHO       : natural := 45220;
    LOSS_CONTRAST  : integer := 16384;
    CONF_LOST      : natural := 26214;           -- round(conf_lost 2**16)
    CONF_UNCERTAIN : natural := 32768;
    CONF_REACQUIRE : natural := 32768;
    SPREAD_DEFAULT : natural := 5368709;         -- spread_ref when the init spread is 0
    BG_Q_W         : natural := 14;
    BG_O_W         : natural := 17;
    SEARCH_ITER    : natural := 5;               -- iterations per start point while lost
    STEP16         : natural := 16;              -- search_step in 1/16
    MARGIN_MAX     : natural := 255;             -- largest region margin (MARGIN + the search offset)
    SCALE_TEST_D256: natural range 0 to 255 := 13; -- PRESET 1: the gated scale test: round(256 scale_test); 0 = off (mstrack-v2-colour)
    ORIENT_T       : integer range -1 to 2047 := 64 -- PRESET 1: the joint colour x orientation bins: orient_T; -1 = off (mstrack-v2-colour)
  );
  port (
    clk                  : in  std_logic;                                -- core and pixel clock
    rst                  : in  std_logic;                                -- synchronous reset
    frame_width          : in  unsigned(COORD_W - 1 downto 0);           -- W, sampled at each start of frame
    frame_height         : in  unsigned(COORD_W - 1 downto 0);           -- H
    -- target init (accepted between frames)
    s_init_tvalid        : in  std_logic;                                -- init box valid
    s_init_tready        : out std_logic;                                -- init box accepted
    s_init_x             : in  signed(COORD_W + 1 downto 0);             -- box left column
    s_init_y             : in  signed(COORD_W + 1 downto 0);             -- box top row
    s_init_w             : in  unsigned(COORD_W downto 0);               -- box width
    s_init_h             : in  unsigned(COORD_W downto 0);               -- box height
    -- video in
    s_axis_tdata         : in  std_logic_vector(24 * PPC - 1 downto 0);  -- PPC pixels, pixel k at 24k+23 .. 24k: R, G, B (RGB_PACKING 1: R, B, G)
    s_axis_tvalid        : in  std_logic;                                -- pixel valid
    s_axis_tready        : out std_logic;                                -- pixel accepted
    s_axis_tlast         : in  std_logic;                                -- last beat of a line
    s_axis_tuser         : in  std_logic;                                -- first beat of a frame
    -- results
    m_axis_result_tdata  : out std_logic_vector(RESULT_W - 1 downto 0);  -- result word
    m_axis_result_tvalid : out std_logic;                                -- result valid
    m_axis_result_tready : in  std_logic;                                -- result taken
    m_axis_result_tlast  : out std_logic;                                -- always 1 (one word per frame)
    -- status
    busy                 : out std_logic                                 -- mean shift running
  );
end entity;

architecture rtl of ms_tracker is
  constant BIN_C_W     : natural := 3 * COLOUR_BITS;
  constant BIN_E_W     : natural := EDGE_BINS_LOG2;
  constant DEPTH       : natural := REGION_MAX * STRIDE;
  -- region RAM read latency: 3 lets ms_ram_sdp's ecp5 architecture use the DP16KD output register
  -- and register its depth multiplexer; the pixel pass hides it (no cycle more, results unchanged)
  constant REGION_RD_LAT : positive := 3;
  -- region RAM write port registered (bank / row decode off the DP16KD write-enable path); the
  -- engines read a region only well after its capture's last write
  constant REGION_WR_LAT : natural := 1;
  constant DRAIN       : natural := 63;           -- clocks the front end needs to drain a frame
  constant A_ONE       : natural := 2 ** AF;
  constant FLAGS_W     : natural := 8;
  constant ERR_W       : natural := 3;
  constant FCOUNT_W    : natural := 16;
  constant RHO_ONE     : natural := 2 ** RHO_OUT_FRAC;

  type tstate_t is (T_REGION, T_REGION_WAIT, T_IDLE, T_CLIP, T_TABLES, T_RUN, T_FUSE, T_PUSH);
  signal state : tstate_t := T_REGION;

  -- target state
  signal target_valid, init_pending, init_clipped, rejected_pending : std_logic := '0';
  signal c8x, c8y       : unsigned(CENTRE_ABS_W - 1 downto 0) := (others => '0');
  signal ex_r, ey_r     : unsigned(HALF_W - 1 downto 0) := to_unsigned(1, HALF_W);
  signal box_w, box_h   : unsigned(WIN_W - 1 downto 0) := (others => '0');
  signal k_r            : unsigned(HIST_W - 1 downto 0);
  signal learn_run      : std_logic;
  -- region of the next / current frame
  signal region_ok      : std_logic := '0';
  signal rg_valid_in, rg_valid : std_logic;
  signal rg_x, rg_y     : unsigned(COORD_W - 1 downto 0);
  signal rg_w, rg_h     : unsigned(REGION_W - 1 downto 0);
  signal rg_hi_x, rg_hi_y : unsigned(REGION_W - 1 downto 0);
  signal reg_x, reg_y   : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal reg_w, reg_h   : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal hi_x, hi_y     : unsigned(REGION_W - 1 downto 0) := (others => '0');
  -- stream gate
  signal accept         : std_logic;
  signal beat           : std_logic;
  signal gate_closed    : std_logic := '0';
  signal in_frame       : std_logic := '0';
  signal line_cnt       : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal drain_cnt      : natural range 0 to DRAIN := 0;
  signal fr_w, fr_h     : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- size of the frame in progress
  signal size_mis       : std_logic := '0';  -- registered (fr_w, fr_h) /= (tgt_w, tgt_h): both settle long before cap_done
  signal size_ok        : std_logic;                      -- frame_width / frame_height in range
  signal err_hold       : std_logic := '0';               -- an error is on its way to the FIFO: input closed
  signal init_take      : std_logic;                      -- the init box is taken this clock
  signal fe_err_now     : std_logic;
  -- frame size the target was initialised for (the region is computed for it)
  signal tgt_w, tgt_h   : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);
  signal in_fw, in_fh   : unsigned(COORD_W - 1 downto 0) := to_unsigned(3, COORD_W);
  -- front end
  signal ip_valid       : std_logic;
  signal ip_x, ip_y     : unsigned(COORD_W - 1 downto 0);
  signal ip_cbin        : std_logic_vector(PPC * BIN_C_W - 1 downto 0);
  signal ip_ebin        : std_logic_vector(PPC * BIN_E_W - 1 downto 0);
  signal cap_bwe        : std_logic_vector(LANES - 1 downto 0);          -- per-bank write port (PPC > 1)
  signal cap_bwaddr     : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal cap_bwc        : std_logic_vector(LANES * BIN_C_W - 1 downto 0);
  signal cap_bwe_d      : std_logic_vector(LANES * BIN_E_W - 1 downto 0);
  signal fe_start, fe_end, fe_error : std_logic;
  signal fe_code        : std_logic_vector(ERR_CODE_W - 1 downto 0);
  signal cap_we         : std_logic;
  signal cap_bank       : unsigned(clog2(LANES) - 1 downto 0);
  signal cap_addr       : unsigned(ADDR_W - 1 downto 0);
  signal cap_c          : std_logic_vector(BIN_C_W - 1 downto 0);
  signal cap_e          : std_logic_vector(BIN_E_W - 1 downto 0);
  signal cap_done       : std_logic;
  signal reg_w_c, reg_h_c : unsigned(COORD_W - 1 downto 0);
  -- RAM read ports
  signal ram_c_addr, ram_e_addr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal ram_c_data     : std_logic_vector(LANES * BIN_C_W - 1 downto 0);
  signal ram_e_data     : std_logic_vector(LANES * BIN_E_W - 1 downto 0);
  -- init path
  signal bc_valid, bc_out_valid, bc_rejected, bc_clipped : std_logic;
  signal bc_x, bc_y, bc_w, bc_h : unsigned(COORD_W - 1 downto 0);
  signal bc_ex, bc_ey   : unsigned(HALF_W - 1 downto 0);
  signal bc_cx, bc_cy   : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal in_x, in_y     : signed(COORD_W + 1 downto 0);
  signal in_w, in_h     : unsigned(COORD_W downto 0);
  signal kt_start, kt_done : std_logic;
  signal kt_we          : std_logic;
  signal kt_addr        : unsigned(HALF_W - 1 downto 0);
  signal kt_ta, kt_tb, kd_d : unsigned(KD_W - 1 downto 0);
  signal kt_ka, kt_kb   : unsigned(KVAL_W - 1 downto 0);
  signal kt_ex, kt_ey   : unsigned(HALF_W - 1 downto 0);
  signal kt_xr          : unsigned(HALF_W - 1 downto 0);
  signal tab_w, tab_h   : unsigned(WIN_W - 1 downto 0);
  -- engines
  signal eng_start      : std_logic := '0';
  signal c_busy, e_busy, c_done, e_done : std_logic;
  signal c_got, e_got   : std_logic := '0';
  signal c_cx, c_cy, e_cx, e_cy : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal c_s, e_s       : unsigned(RHO_SUM_W - 1 downto 0);
  signal c_iter, e_iter : unsigned(ITER_W - 1 downto 0);
  signal c_stop, e_stop : std_logic_vector(1 downto 0);
  signal c_k, e_k       : unsigned(HIST_W - 1 downto 0);
  -- fusion
  signal fu_start, fu_done : std_logic := '0';
  signal fu_cx, fu_cy   : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal fu_alpha       : unsigned(ALPHA_W - 1 downto 0);
  signal fu_rho_c, fu_rho_e : unsigned(RHO_OUT_W - 1 downto 0);
  -- results
  signal res_word       : std_logic_vector(RESULT_W - 1 downto 0);
  -- the result word is loaded one clock after the branch that decides it (res_ld), from held
  -- registers selected by registered flags (rs_learn / rs_fuse): no deep load enable on its
  -- 144 flip-flops; the branch keeps its flags and error code in res_flags / res_err
  signal res_ld, rs_learn, rs_fuse : std_logic := '0';
  signal res_flags      : std_logic_vector(FLAGS_W - 1 downto 0) := (others => '0');
  signal res_err        : std_logic_vector(ERR_W - 1 downto 0) := (others => '0');
  signal err_push       : std_logic := '0';           -- an error result goes to the FIFO next clock
  signal push_now       : std_logic;                  -- T_PUSH writes its word this clock
  signal fifo_valid, fifo_ready : std_logic;
  signal fifo_data      : std_logic_vector(RESULT_W - 1 downto 0);
  signal frame_count    : unsigned(FCOUNT_W - 1 downto 0) := (others => '0');
  signal err_pending    : std_logic := '0';
  signal err_code_r     : std_logic_vector(ERR_CODE_W - 1 downto 0);
  signal overflow       : std_logic := '0';
  signal init_ready     : std_logic;
  signal io_idle        : std_logic;                         -- both inputs may open (registered terms)
  signal init_free      : std_logic;                         -- init_ready's own registered terms

  function pack(cx, cy : unsigned; rho_c, rho_e : unsigned; alpha : unsigned;
                iter_c, iter_e : unsigned; stop_c, stop_e : std_logic_vector;
                flags : std_logic_vector; err : std_logic_vector; bw, bh : unsigned;
                fc : unsigned) return std_logic_vector is
    variable v : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');
    variable o : natural := 0;
  begin
    v(o + CENTRE_ABS_W - 1 downto o) := std_logic_vector(cx); o := o + CENTRE_ABS_W;
    v(o + CENTRE_ABS_W - 1 downto o) := std_logic_vector(cy); o := o + CENTRE_ABS_W;
    v(o + RHO_OUT_W - 1 downto o) := std_logic_vector(rho_c); o := o + RHO_OUT_W;
    v(o + RHO_OUT_W - 1 downto o) := std_logic_vector(rho_e); o := o + RHO_OUT_W;
    v(o + ALPHA_W - 1 downto o) := std_logic_vector(alpha); o := o + ALPHA_W;
    v(o + ITER_W - 1 downto o) := std_logic_vector(iter_c); o := o + ITER_W;
    v(o + ITER_W - 1 downto o) := std_logic_vector(iter_e); o := o + ITER_W;
    v(o + 1 downto o) := stop_c; o := o + 2;
    v(o + 1 downto o) := stop_e; o := o + 2;
    v(o + FLAGS_W - 1 downto o) := flags; o := o + FLAGS_W;
    v(o + ERR_W - 1 downto o) := err; o := o + ERR_W;
    v(o + WIN_W - 1 downto o) := std_logic_vector(bw); o := o + WIN_W;
    v(o + WIN_W - 1 downto o) := std_logic_vector(bh); o := o + WIN_W;
    v(o + FCOUNT_W - 1 downto o) := std_logic_vector(fc);
    return v;
  end function;

  -- flags (ms_pkg.v2_flags, the same byte in both result words): 0 init, 1 clipped, 2 lost, 3 error,
  -- 4 rejected, 5 no_target, 6 overflow

  ------------------------------------------------------------------------------ generic checks
  -- The derived widths are generics (computed by mstrack.fixed.vhdl_pkg.core_generics; `mstrack hdl
  -- config` writes them all).  The relations below are the ones the RTL is built on; each is
  -- checked at elaboration (severity failure), with the formula of mstrack.fixed.formats.widths.
  -- Products are formed on 128-bit unsigned values, so no integer overflows for any MAX_HALF.
  subtype big_t is unsigned(127 downto 0);
  function big(n : natural) return big_t is
  begin
    return to_unsigned(n, 128);
  end function;
  function mul(a, b : big_t) return big_t is
  begin
    return resize(a * b, 128);
  end function;
  function bits_of(v : big_t) return natural is     -- bits to hold 0 .. v (at least 1)
  begin
    for i in 127 downto 1 loop
      if v(i) = '1' then
        return i + 1;
      end if;
    end loop;
    return 1;
  end function;
  function img(n : natural) return string is
  begin
    return integer'image(n);
  end function;
  procedure check(name : string; got, want : natural; formula : string) is
  begin
    assert got = want
      report "ms_tracker: " & name & " = " & img(got) & ", expected " & formula & " = " & img(want)
             & " (derive every width with mstrack hdl config)"
      severity failure;
  end procedure;

  constant X_WIN     : natural := 2 * MAX_HALF + 1;
  constant X_PIX     : big_t := mul(big(X_WIN), big(X_WIN));
  function kmax return big_t is                     -- largest kernel value: 1 flat, 2**KERNEL_BITS Epanechnikov
  begin
    if KERNEL_EPAN = 0 then
      return big(1);
    end if;
    return shift_left(big(1), KERNEL_BITS);
  end function;
  constant X_KMAX    : big_t := kmax;
  constant X_HISTMAX : big_t := mul(X_PIX, X_KMAX);
  constant X_WMAX    : big_t := shift_left(big(1), WI + WF) - 1;
  constant X_REGION  : natural := X_WIN + 2 * MARGIN;
  constant X_STRIDE  : natural := (X_REGION + LANES - 1) / max(LANES, 1);
  constant X_SQRT_IN : natural := bits_of(shift_left(mul(X_HISTMAX, X_HISTMAX), 2 * RF));
  constant X_RESULT  : natural := 2 * CENTRE_ABS_W + 2 * RHO_OUT_W + ALPHA_W + 2 * ITER_W + 4 + FLAGS_W
                                  + ERR_W + 2 * WIN_W + FCOUNT_W;
  -- result word v2 (PRESET 1, mstrack.fixed.vhdl_pkg.result_layout_v2): cx, cy, w8, h8, rho, confidence (17),
  -- status (3), iter, stop (2), decim_log2 (3), searched (4), flags, err_code, frame_count
  constant X_RESULT_V2 : natural := 2 * CENTRE_ABS_W + 2 * (COORD_W + 8) + RHO_OUT_W + 17 + 3 + ITER_W + 2 + 3 + 4
                                    + FLAGS_W + ERR_W + FCOUNT_W;

  -- frame width accepted with PPC pixels per beat: a multiple of PPC (PPC a power of two)
  function width_ppc_ok(w : unsigned) return boolean is
  begin
    for i in 0 to 1 loop
      if 2 ** (i + 1) <= PPC and w(i) = '1' then
        return false;
      end if;
    end loop;
    return true;
  end function;

  -- evaluated once at elaboration; returns true so that it can initialise a constant
  function checks return boolean is
  begin
    assert PRESET <= 1 report "ms_tracker: PRESET = " & img(PRESET) & " (0 the paper core, 1 core v2)"
      severity failure;
    if PRESET = 1 then
      -- core v2: ms_tracker_v2 checks its own generics
      assert RESULT_W = 8 * ((X_RESULT_V2 + 7) / 8)
        report "ms_tracker: RESULT_W = " & img(RESULT_W) & " but PRESET 1 (core v2) has a result word v2 of "
               & img(8 * ((X_RESULT_V2 + 7) / 8)) & " bits (mstrack hdl config --preset v2 sets every generic)"
        severity failure;
      assert PPC = 1 report "ms_tracker: PPC = " & img(PPC) & ": PRESET 1 (core v2) takes one pixel per clock"
        severity failure;
      return true;
    end if;
    assert LANES = 1 or (LANES >= 1 and 2 ** clog2(LANES) = LANES)
      report "ms_tracker: LANES = " & img(LANES) & " is not a power of two" severity failure;
    assert FEATURES <= 2 report "ms_tracker: FEATURES = " & img(FEATURES) & " (0 fused, 1 colour, 2 edge)"
      severity failure;
    assert KERNEL_EPAN <= 1 report "ms_tracker: KERNEL_EPAN = " & img(KERNEL_EPAN) & " (0 flat, 1 Epanechnikov)"
      severity failure;
    assert RGB_PACKING <= 1 report "ms_tracker: RGB_PACKING = " & img(RGB_PACKING) & " (0 mstrack, 1 UG934)"
      severity failure;
    assert PPC = 1 or PPC = 2 or PPC = 4 report "ms_tracker: PPC = " & img(PPC) & " (1, 2 or 4)" severity failure;
    assert PPC <= LANES report "ms_tracker: PPC = " & img(PPC) & " > LANES = " & img(LANES)
      & " is not supported (the region capture writes the PPC pixels of a beat into PPC different banks)"
      severity failure;
    assert MAX_HALF >= 1 report "ms_tracker: MAX_HALF must be >= 1" severity failure;
    assert MAX_FRAME_W >= 3 and MAX_FRAME_W <= 2 ** COORD_W - 1
      report "ms_tracker: MAX_FRAME_W = " & img(MAX_FRAME_W) & " out of 3 .. 2**COORD_W - 1 = "
             & img(2 ** COORD_W - 1) severity failure;
    check("HALF_W", HALF_W, bits_of(big(MAX_HALF)), "bits_for(MAX_HALF)");
    check("WIN_W", WIN_W, bits_of(big(X_WIN)), "bits_for(2 MAX_HALF + 1)");
    check("REGION_MAX", REGION_MAX, X_REGION, "2 MAX_HALF + 1 + 2 MARGIN");
    check("REGION_W", REGION_W, bits_of(big(REGION_MAX)), "bits_for(REGION_MAX)");
    check("STRIDE", STRIDE, X_STRIDE, "ceil(REGION_MAX / LANES)");
    check("ADDR_W", ADDR_W, bits_of(big(REGION_MAX * STRIDE - 1)), "bits_for(REGION_MAX STRIDE - 1)");
    check("KVAL_W", KVAL_W, bits_of(X_KMAX), "bits_for(kernel maximum)");
    check("HIST_W", HIST_W, bits_of(X_HISTMAX), "bits_for(window pixels x kernel maximum)");
    check("COUNT_W", COUNT_W, bits_of(X_PIX), "bits_for((2 MAX_HALF + 1)**2)");
    check("POSSUM_W", POSSUM_W, bits_of(mul(X_PIX, big(MAX_HALF))) + 1, "bits_for(pixels MAX_HALF) + 1");
    check("KD_W", KD_W, bits_of(mul(big(4), mul(mul(big(MAX_HALF), big(MAX_HALF)), X_PIX)) + mul(X_PIX, X_PIX)),
          "bits_for(4 MAX_HALF**2 win**2 + win**4)");
    check("SQRT_IN_W", SQRT_IN_W, X_SQRT_IN + X_SQRT_IN mod 2, "even(bits_for(HIST_MAX**2 2**(2 RF)))");
    check("RHO_SUM_W", RHO_SUM_W, bits_of(shift_left(X_HISTMAX, RF)) + 1, "bits_for(HIST_MAX 2**RF) + 1");
    check("WEIGHT_W", WEIGHT_W, WI + WF, "WI + WF");
    check("RATIO_Q_W", RATIO_Q_W, 2 * (WI + WF), "2 (WI + WF)");
    check("SW_W", SW_W, bits_of(mul(X_WMAX, X_PIX)), "bits_for((2**WEIGHT_W - 1) pixels)");
    check("SWX_W", SWX_W, bits_of(mul(X_WMAX, mul(X_PIX, big(MAX_HALF)))) + 1,
          "bits_for((2**WEIGHT_W - 1) pixels MAX_HALF) + 1");
    check("SHIFT_Q_W", SHIFT_Q_W, bits_of(shift_left(big(MAX_HALF), CF)), "bits_for(MAX_HALF 2**CF)");
    check("CENTRE_W", CENTRE_W, REGION_W + CF, "REGION_W + CF");
    check("CENTRE_ABS_W", CENTRE_ABS_W, COORD_W + CF, "COORD_W + CF");
    check("ITER_W", ITER_W, bits_of(big(MAX_ITER)), "bits_for(MAX_ITER)");
    check("RHO_OUT_W", RHO_OUT_W, RHO_OUT_FRAC + 1, "RHO_OUT_FRAC + 1");
    check("ALPHA_W", ALPHA_W, AF + 1, "AF + 1");
    check("RESULT_W", RESULT_W, 8 * ((X_RESULT + 7) / 8),
          "PRESET 0 (the paper core): the result fields rounded up to 8 bits");
    return true;
  end function;
  constant GENERICS_OK : boolean := checks;
begin

  ---------------------------------------------------------------------------- PRESET 1: core v2
  -- the v2 engine with every port and generic passed through (PPC = 1: s_axis_tdata is one pixel)
  g_v2 : if PRESET = 1 generate
    u_v2 : entity work.ms_tracker_v2
      generic map (
        MAX_FRAME_W => MAX_FRAME_W, RGB_PACKING => RGB_PACKING, LANES => LANES, COLOUR_BITS => COLOUR_BITS,
        EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, FEATURES => FEATURES,
        KERNEL_EPAN => KERNEL_EPAN, KERNEL_BITS => KERNEL_BITS, MAX_HALF => MAX_HALF, MARGIN => MARGIN,
        COORD_W => COORD_W, CF => CF, WI => WI, WF => WF, RF => RF, AF => AF, RHO_OUT_FRAC => RHO_OUT_FRAC,
        MAX_ITER => MAX_ITER, EPS2 => EPS2, HALF_W => HALF_W, REGION_MAX => REGION_MAX, REGION_W => REGION_W,
        STRIDE => STRIDE, ADDR_W => ADDR_W, KVAL_W => KVAL_W, HIST_W => HIST_W, COUNT_W => COUNT_W,
        POSSUM_W => POSSUM_W, KD_W => KD_W, SQRT_IN_W => SQRT_IN_W, RHO_SUM_W => RHO_SUM_W,
        RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W,
        CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, ITER_W => ITER_W, RHO_OUT_W => RHO_OUT_W,
        ALPHA_W => ALPHA_W, WIN_W => WIN_W, RESULT_W => RESULT_W,
        PAD16 => PAD16, RING16 => RING16, MAX_WINDOW => MAX_WINDOW, KT_W => KT_W, ST2_W => ST2_W,
        SHARE_W => SHARE_W, SPREAD_W => SPREAD_W, SIZE_W => SIZE_W, SCALE_W => SCALE_W,
        SCALE_GAIN => SCALE_GAIN, SCALE_REG => SCALE_REG, SCALE_STEP => SCALE_STEP,
        SCALE_RATIO_Q_W => SCALE_RATIO_Q_W, WR_Q_W => WR_Q_W, CON_W => CON_W, LOSS_K => LOSS_K, REF_K => REF_K,
        LOSS_RHO => LOSS_RHO, LOSS_CONTRAST => LOSS_CONTRAST, CONF_LOST => CONF_LOST,
        CONF_UNCERTAIN => CONF_UNCERTAIN, CONF_REACQUIRE => CONF_REACQUIRE, SPREAD_DEFAULT => SPREAD_DEFAULT,
        BG_Q_W => BG_Q_W, BG_O_W => BG_O_W, SEARCH_ITER => SEARCH_ITER, STEP16 => STEP16,
        MARGIN_MAX => MARGIN_MAX, SCALE_TEST_D256 => SCALE_TEST_D256, ORIENT_T => ORIENT_T)
      port map (
        clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
        s_init_tvalid => s_init_tvalid, s_init_tready => s_init_tready, s_init_x => s_init_x,
        s_init_y => s_init_y, s_init_w => s_init_w, s_init_h => s_init_h,
        s_axis_tdata => s_axis_tdata(23 downto 0), s_axis_tvalid => s_axis_tvalid,
        s_axis_tready => s_axis_tready, s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
        m_axis_result_tdata => m_axis_result_tdata, m_axis_result_tvalid => m_axis_result_tvalid,
        m_axis_result_tready => m_axis_result_tready, m_axis_result_tlast => m_axis_result_tlast,
        busy => busy);
  end generate g_v2;

  ---------------------------------------------------------------------------- PRESET 0: the paper core
  -- (the statements of this generate are not indented one level more, to keep the paper core's history)
  g_paper : if PRESET = 0 generate

  ---------------------------------------------------------------------------- video input gate
  -- closed: outside T_IDLE, after a frame's last beat until its result, while an error result is
  -- on its way to the FIFO (so that no second error can come before it: none is ever lost), and
  -- in the clock an init box is taken (the box applies to the frame after that clock)
  size_ok <= '1' when frame_width >= 3 and frame_height >= 3 and frame_width <= MAX_FRAME_W
                     and width_ppc_ok(frame_width) else '0';
  -- (err_push: the error word is loaded, the FIFO takes it at the end of the next clock)
  -- written so that s_init_tvalid enters accept in one AND with registered terms (init_free), not
  -- through init_ready and init_take: the same function (accept needs io_idle, which init_ready
  -- has too), a shorter ready chain s_init_tvalid / state -> s_axis_tready -> the stream check
  io_idle <= '1' when state = T_IDLE and gate_closed = '0' and err_hold = '0' and err_push = '0'
                      and fe_err_now = '0' else '0';
  init_free <= '1' when cap_done = '0' and err_pending = '0' and in_frame = '0' else '0';
  accept <= io_idle and region_ok and not (s_init_tvalid and init_free);
  s_axis_tready <= accept;
  beat <= s_axis_tvalid and accept;

  p_gate : process(clk)
  begin
    if rising_edge(clk) then
      if beat = '1' then
        if s_axis_tuser = '1' then
          -- a frame size out of range: ms_stream_check drops the frame (ERR_SIZE)
          in_frame <= size_ok;
          fr_w <= frame_width;
          fr_h <= frame_height;
          line_cnt <= (others => '0');
        elsif in_frame = '1' and s_axis_tlast = '1' then
          line_cnt <= line_cnt + 1;
        end if;
        -- the frame's last beat (as far as the line count says): close until its result
        if in_frame = '1' and s_axis_tuser = '0' and s_axis_tlast = '1' and line_cnt = fr_h - 1 then
          gate_closed <= '1';
          in_frame <= '0';
        end if;
      end if;
      -- fr_w / fr_h change at a start of frame, tgt_w / tgt_h in T_TABLES: both at least a
      -- frame's beats and the front end's delay before the cap_done that reads size_mis
      size_mis <= '1' when fr_w /= tgt_w or fr_h /= tgt_h else '0';
      if gate_closed = '1' and state = T_IDLE then
        -- a frame that ended badly has no frame_end: reopen once the front end has drained
        if drain_cnt = DRAIN then
          gate_closed <= '0';
          drain_cnt <= 0;
        else
          drain_cnt <= drain_cnt + 1;
        end if;
      else
        drain_cnt <= 0;
      end if;
      if push_now = '1' then
        gate_closed <= '0';
      end if;
      if rst = '1' then
        gate_closed <= '0';
        in_frame <= '0';
        drain_cnt <= 0;
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- front end, capture, RAMs
  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, RGB_PACKING => RGB_PACKING,
                 PPC => PPC)
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => beat, in_data => s_axis_tdata, in_sof => s_axis_tuser, in_eol => s_axis_tlast,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin, ip_ebin => ip_ebin,
              frame_start => fe_start, frame_end => fe_end, frame_error => fe_error,
              error_now => fe_err_now, err_code => fe_code);

  reg_w_c <= resize(reg_w, COORD_W);
  reg_h_c <= resize(reg_h, COORD_W);

  u_cap : entity work.ms_region_capture
    generic map (LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COLOUR_BITS => COLOUR_BITS, EDGE_BINS_LOG2 => EDGE_BINS_LOG2,
                 PPC => PPC)
    port map (clk => clk, rst => rst, frame_start => fe_start, frame_end => fe_end,
              frame_error => fe_error, reg_x => reg_x, reg_y => reg_y, reg_w => reg_w_c,
              reg_h => reg_h_c, ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_cbin => ip_cbin,
              ip_ebin => ip_ebin, we => cap_we, wbank => cap_bank, waddr => cap_addr,
              wdata_colour => cap_c, wdata_edge => cap_e, done => cap_done,
              bwe => cap_bwe, bwaddr => cap_bwaddr, bwdata_colour => cap_bwc, bwdata_edge => cap_bwe_d);

  -- PPC = 1: one write per clock into the LANES-banked RAMs (shared write port)
  g_ram1 : if PPC = 1 generate
    u_ram_c : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => BIN_C_W, ADDR_W => ADDR_W,
                   RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
      port map (clk => clk, we => cap_we, wbank => cap_bank, waddr => cap_addr, wdata => cap_c,
                raddr => ram_c_addr, rdata => ram_c_data);

    u_ram_e : entity work.ms_region_ram
      generic map (LANES => LANES, DEPTH => DEPTH, DATA_W => BIN_E_W, ADDR_W => ADDR_W,
                   RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
      port map (clk => clk, we => cap_we, wbank => cap_bank, waddr => cap_addr, wdata => cap_e,
                raddr => ram_e_addr, rdata => ram_e_data);
  end generate;

  -- PPC > 1: up to PPC writes per clock, one per bank: one single-bank ms_region_ram per bank
  -- (the same banks, layout and latencies as the LANES-banked RAM above)
  g_ramn : if PPC > 1 generate
    g_bank : for bk in 0 to LANES - 1 generate
      u_ram_c : entity work.ms_region_ram
        generic map (LANES => 1, DEPTH => DEPTH, DATA_W => BIN_C_W, ADDR_W => ADDR_W,
                     RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
        port map (clk => clk, we => cap_bwe(bk), wbank => "0",
                  waddr => unsigned(cap_bwaddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk)),
                  wdata => cap_bwc(BIN_C_W * (bk + 1) - 1 downto BIN_C_W * bk),
                  raddr => ram_c_addr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk),
                  rdata => ram_c_data(BIN_C_W * (bk + 1) - 1 downto BIN_C_W * bk));

      u_ram_e : entity work.ms_region_ram
        generic map (LANES => 1, DEPTH => DEPTH, DATA_W => BIN_E_W, ADDR_W => ADDR_W,
                     RD_LAT => REGION_RD_LAT, WR_LAT => REGION_WR_LAT)
        port map (clk => clk, we => cap_bwe(bk), wbank => "0",
                  waddr => unsigned(cap_bwaddr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk)),
                  wdata => cap_bwe_d(BIN_E_W * (bk + 1) - 1 downto BIN_E_W * bk),
                  raddr => ram_e_addr(ADDR_W * (bk + 1) - 1 downto ADDR_W * bk),
                  rdata => ram_e_data(BIN_E_W * (bk + 1) - 1 downto BIN_E_W * bk));
    end generate;
  end generate;

  ---------------------------------------------------------------------------- init path
  u_clip : entity work.ms_box_clip
    generic map (COORD_W => COORD_W, HALF_W => HALF_W, MAX_HALF => MAX_HALF, CF => CF)
    port map (clk => clk, rst => rst, in_valid => bc_valid, box_x => in_x, box_y => in_y,
              box_w => in_w, box_h => in_h, frame_w => in_fw, frame_h => in_fh,
              out_valid => bc_out_valid, rejected => bc_rejected, clipped => bc_clipped,
              clip_x => bc_x, clip_y => bc_y, clip_w => bc_w, clip_h => bc_h, ex => bc_ex,
              ey => bc_ey, cx => bc_cx, cy => bc_cy);

  u_tables : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KD_W => KD_W, KERNEL_EPAN => KERNEL_EPAN,
                 KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W)
    port map (clk => clk, rst => rst, start => kt_start, w => tab_w, h => tab_h, busy => open,
              done => kt_done,
              ex => kt_ex, ey => kt_ey, kd_d => kd_d, kt_we => kt_we, kt_addr => kt_addr,
              kt_ta => kt_ta, kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr);

  u_region : entity work.ms_region
    generic map (COORD_W => COORD_W, HALF_W => HALF_W, REGION_W => REGION_W, MARGIN => MARGIN, CF => CF)
    port map (clk => clk, rst => rst, in_valid => rg_valid_in, cx => c8x, cy => c8y, ex => ex_r,
              ey => ey_r, frame_w => tgt_w, frame_h => tgt_h, out_valid => rg_valid,
              reg_x => rg_x, reg_y => rg_y, reg_w => rg_w, reg_h => rg_h, hi_x => rg_hi_x,
              hi_y => rg_hi_y);

  ---------------------------------------------------------------------------- engines
  u_colour : entity work.ms_meanshift
    generic map (LANES => LANES, BIN_W => BIN_C_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, COORD_W => COORD_W, KERNEL_EPAN => KERNEL_EPAN,
                 KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W, KD_W => KD_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, SQRT_IN_W => SQRT_IN_W,
                 RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, WF => WF,
                 RF => RF, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CF => CF,
                 CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, MAX_ITER => MAX_ITER,
                 ITER_W => ITER_W, EPS2 => EPS2, RAM_LAT => REGION_RD_LAT)
    port map (clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr, kd_d => kd_d, ex => ex_r, ey => ey_r,
              reg_x => reg_x, reg_y => reg_y, hi_x => hi_x, hi_y => hi_y, start => eng_start,
              learn => learn_run, start_cx => c8x, start_cy => c8y, busy => c_busy, done => c_done,
              res_cx => c_cx, res_cy => c_cy, res_s => c_s, res_iter => c_iter, res_stop => c_stop,
              res_k => c_k, ram_addr => ram_c_addr, ram_data => ram_c_data);

  u_edge : entity work.ms_meanshift
    generic map (LANES => LANES, BIN_W => BIN_E_W, HALF_W => HALF_W, REGION_W => REGION_W,
                 STRIDE => STRIDE, ADDR_W => ADDR_W, COORD_W => COORD_W, KERNEL_EPAN => KERNEL_EPAN,
                 KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W, KD_W => KD_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, SQRT_IN_W => SQRT_IN_W,
                 RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, WF => WF,
                 RF => RF, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CF => CF,
                 CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, MAX_ITER => MAX_ITER,
                 ITER_W => ITER_W, EPS2 => EPS2, RAM_LAT => REGION_RD_LAT, ITER_BINS => 1)
    port map (clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_ta => kt_ta,
              kt_tb => kt_tb, kt_ka => kt_ka, kt_kb => kt_kb, kt_xr => kt_xr, kd_d => kd_d, ex => ex_r, ey => ey_r,
              reg_x => reg_x, reg_y => reg_y, hi_x => hi_x, hi_y => hi_y, start => eng_start,
              learn => learn_run, start_cx => c8x, start_cy => c8y, busy => e_busy, done => e_done,
              res_cx => e_cx, res_cy => e_cy, res_s => e_s, res_iter => e_iter, res_stop => e_stop,
              res_k => e_k, ram_addr => ram_e_addr, ram_data => ram_e_data);

  u_fusion : entity work.ms_fusion
    generic map (FEATURES => FEATURES, RHO_SUM_W => RHO_SUM_W, HIST_W => HIST_W,
                 CENTRE_ABS_W => CENTRE_ABS_W, AF => AF, ALPHA_W => ALPHA_W, RF => RF,
                 RHO_OUT_FRAC => RHO_OUT_FRAC, RHO_OUT_W => RHO_OUT_W)
    port map (clk => clk, rst => rst, start => fu_start, s_c => c_s, s_e => e_s, c_cx => c_cx,
              c_cy => c_cy, e_cx => e_cx, e_cy => e_cy, k_sum => k_r, done => fu_done, cx => fu_cx,
              cy => fu_cy, alpha_c => fu_alpha, rho_c => fu_rho_c, rho_e => fu_rho_e);

  busy <= c_busy or e_busy;

  ---------------------------------------------------------------------------- results
  u_fifo : entity work.ms_fifo
    generic map (WIDTH => RESULT_W, DEPTH => 4)
    port map (clk => clk, rst => rst, s_valid => fifo_valid, s_ready => fifo_ready, s_data => res_word,
              m_valid => m_axis_result_tvalid, m_ready => m_axis_result_tready, m_data => fifo_data);
  m_axis_result_tdata <= fifo_data;
  m_axis_result_tlast <= '1';

  ---------------------------------------------------------------------------- control
  p_ctrl : process(clk)
    variable lost    : std_logic;
    variable a_init  : unsigned(ALPHA_W - 1 downto 0);
    variable zero_s2 : std_logic_vector(1 downto 0);
    variable ic, ie  : unsigned(ITER_W - 1 downto 0);
    variable sc, se  : std_logic_vector(1 downto 0);
  begin
    if rising_edge(clk) then
      bc_valid <= '0';
      kt_start <= '0';
      eng_start <= '0';
      fu_start <= '0';
      rg_valid_in <= '0';
      fifo_valid <= '0';
      res_ld <= '0';
      zero_s2 := "00";

      -- the result word of the branch decided a clock ago (below): c8x / c8y already hold its
      -- centre (the learn and fuse branches load them in the same clock)
      if res_ld = '1' then
        if FEATURES = 1 then a_init := to_unsigned(A_ONE, ALPHA_W);
        elsif FEATURES = 2 then a_init := (others => '0');
        else a_init := to_unsigned(A_ONE / 2, ALPHA_W);
        end if;
        ic := c_iter; sc := c_stop; ie := e_iter; se := e_stop;
        if FEATURES = 2 then ic := (others => '0'); sc := "00"; end if;
        if FEATURES = 1 then ie := (others => '0'); se := "00"; end if;
        if rs_fuse = '1' then
          res_word <= pack(c8x, c8y, fu_rho_c, fu_rho_e, fu_alpha, ic, ie, sc, se, res_flags, res_err,
                           box_w, box_h, frame_count);
        elsif rs_learn = '1' then
          res_word <= pack(c8x, c8y, to_unsigned(RHO_ONE, RHO_OUT_W), to_unsigned(RHO_ONE, RHO_OUT_W),
                           a_init, to_unsigned(0, ITER_W), to_unsigned(0, ITER_W), zero_s2, zero_s2,
                           res_flags, res_err, box_w, box_h, frame_count);
        else
          res_word <= pack(c8x, c8y, to_unsigned(0, RHO_OUT_W), to_unsigned(0, RHO_OUT_W),
                           to_unsigned(0, ALPHA_W), to_unsigned(0, ITER_W), to_unsigned(0, ITER_W),
                           zero_s2, zero_s2, res_flags, res_err, box_w, box_h, frame_count);
        end if;
      end if;
      -- an error result: its word is loaded in this clock, the FIFO takes it in the next
      err_push <= '0';
      if err_push = '1' then
        fifo_valid <= '1';
        frame_count <= frame_count + 1;
      end if;

      -- protocol errors: one error result each (pushed when the FIFO has room)
      if fe_err_now = '1' then
        err_hold <= '1';
      end if;
      if fe_error = '1' then
        if err_pending = '1' then
          overflow <= '1';
        end if;
        err_pending <= '1';
        err_code_r <= fe_code;
      end if;

      case state is
        when T_REGION =>
          rg_valid_in <= '1';
          region_ok <= '0';
          state <= T_REGION_WAIT;

        when T_REGION_WAIT =>
          if rg_valid = '1' then
            reg_x <= rg_x; reg_y <= rg_y; reg_w <= rg_w; reg_h <= rg_h;
            hi_x <= rg_hi_x; hi_y <= rg_hi_y;
            region_ok <= '1';
            state <= T_IDLE;
          end if;

        when T_IDLE =>
          if cap_done = '1' then                     -- a good frame is in the region RAMs
            if (init_pending = '1' or target_valid = '1') and size_mis = '1' then
              -- not the size the target was initialised for: not tracked, state unchanged
              res_ld <= '1'; rs_learn <= '0'; rs_fuse <= '0';
              res_flags <= v2_flags('0', '0', '0', '1', rejected_pending, not target_valid, overflow);
              res_err <= ERR_SIZE_CHANGED;
              state <= T_PUSH;
            elsif init_pending = '1' or target_valid = '1' then
              learn_run <= init_pending;
              eng_start <= '1';
              c_got <= '0';
              e_got <= '0';
              state <= T_RUN;
            else
              res_ld <= '1'; rs_learn <= '0'; rs_fuse <= '0';
              res_flags <= v2_flags('0', '0', '0', '0', rejected_pending, '1', overflow);
              res_err <= "000";
              state <= T_PUSH;
            end if;
          elsif err_pending = '1' and fifo_ready = '1' and err_push = '0' and fifo_valid = '0' then
            -- (no write on its way: fifo_ready counts every word already written)
            res_ld <= '1'; rs_learn <= '0'; rs_fuse <= '0';
            res_flags <= v2_flags('0', '0', '0', '1', rejected_pending, not target_valid, overflow);
            res_err <= err_code_r;
            err_push <= '1';
            overflow <= '0';
            rejected_pending <= '0';
            if fe_error = '0' then
              err_pending <= '0';
              if fe_err_now = '0' then
                err_hold <= '0';
              end if;
            end if;
          elsif init_take = '1' then
            in_x <= s_init_x; in_y <= s_init_y; in_w <= s_init_w; in_h <= s_init_h;
            in_fw <= frame_width; in_fh <= frame_height;
            bc_valid <= '1';
            state <= T_CLIP;
          end if;

        when T_CLIP =>
          if bc_out_valid = '1' then
            -- a frame size out of range when the box came: rejected too
            if bc_rejected = '1' or in_fw < 3 or in_fh < 3 or in_fw > MAX_FRAME_W or not width_ppc_ok(in_fw) then
              rejected_pending <= '1';
              state <= T_IDLE;
            else
              tab_w <= resize(bc_w, WIN_W);
              tab_h <= resize(bc_h, WIN_W);
              kt_start <= '1';
              state <= T_TABLES;
            end if;
          end if;

        when T_TABLES =>
          if kt_done = '1' then
            ex_r <= bc_ex;
            ey_r <= bc_ey;
            box_w <= tab_w;
            box_h <= tab_h;
            c8x <= bc_cx;
            c8y <= bc_cy;
            tgt_w <= in_fw;
            tgt_h <= in_fh;
            init_pending <= '1';
            init_clipped <= bc_clipped;
            target_valid <= '0';
            state <= T_REGION;
          end if;

        when T_RUN =>
          if c_done = '1' then c_got <= '1'; end if;
          if e_done = '1' then e_got <= '1'; end if;
          if (c_got = '1' or c_done = '1') and (e_got = '1' or e_done = '1') then
            if learn_run = '1' then
              k_r <= c_k;
              c8x <= c_cx;
              c8y <= c_cy;
              target_valid <= '1';
              init_pending <= '0';
              res_ld <= '1'; rs_learn <= '1'; rs_fuse <= '0';
              res_flags <= v2_flags('1', init_clipped, '0', '0', rejected_pending, '0', overflow);
              res_err <= "000";
              state <= T_PUSH;
            else
              fu_start <= '1';
              state <= T_FUSE;
            end if;
          end if;

        when T_FUSE =>
          if fu_done = '1' then
            if FEATURES = 1 then
              lost := '1' when c_stop = STOP_LOST else '0';
            elsif FEATURES = 2 then
              lost := '1' when e_stop = STOP_LOST else '0';
            else
              lost := '1' when c_stop = STOP_LOST and e_stop = STOP_LOST else '0';
            end if;
            c8x <= fu_cx;
            c8y <= fu_cy;
            -- the word a clock later (above); an unused feature reports 0 iterations and stop
            -- code 0 (as the model)
            res_ld <= '1'; rs_learn <= '0'; rs_fuse <= '1';
            res_flags <= v2_flags('0', '0', lost, '0', rejected_pending, '0', overflow);
            res_err <= "000";
            state <= T_PUSH;
          end if;

        when T_PUSH =>              -- its word was loaded in the clock after the branch
          if push_now = '1' then
            fifo_valid <= '1';
            frame_count <= frame_count + 1;
            overflow <= '0';
            rejected_pending <= '0';
            state <= T_REGION;
          end if;
      end case;

      if rst = '1' then
        state <= T_REGION;
        region_ok <= '0';
        target_valid <= '0';
        init_pending <= '0';
        rejected_pending <= '0';
        err_pending <= '0';
        err_hold <= '0';
        err_push <= '0';
        res_ld <= '0';
        overflow <= '0';
        frame_count <= (others => '0');
        box_w <= (others => '0');
        box_h <= (others => '0');
        tgt_w <= to_unsigned(3, COORD_W);
        tgt_h <= to_unsigned(3, COORD_W);
        c8x <= (others => '0');
        c8y <= (others => '0');
        ex_r <= to_unsigned(1, HALF_W);
        ey_r <= to_unsigned(1, HALF_W);
      end if;
    end if;
  end process;

  -- T_PUSH writes when the FIFO has room and no error word is on its way (fifo_valid: written
  -- at the next edge, not yet counted by fifo_ready)
  push_now <= '1' when state = T_PUSH and fifo_ready = '1' and fifo_valid = '0' else '0';

  init_ready <= io_idle and init_free;
  init_take <= s_init_tvalid and init_ready;
  s_init_tready <= init_ready;
  end generate g_paper;
end architecture;
