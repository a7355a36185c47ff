-- ms_tracker_shared: the shared-engine multi-target core (docs/multi_target_core.md): MAX_TARGETS
-- targets on one ms_engine, each with its own slot (ms_slot_pool), model and record, behind the ports of
-- ms_tracker_multi.  Executable specification: mstrack.hw.cosim_multi.CoreModelMulti with the capacity
-- rule (capacity = MultiCoreConfig(MAX_TARGETS, VideoTiming(ACTIVE_LINES, FRAME_LINES, LINE_CLOCKS))).
--
-- Schedule (this version): the live targets are planned, oldest first, by ms_frame_plan (each tracked
-- or held) as soon as the previous frame is closed, in the blanking, with the frame size of the ports
-- then; a remove, a stream fault's words or another frame size at the start of frame plan them again
-- when the start of frame comes, and the input waits for it.  Once the plan holds, the inits pending
-- after a fault and each add taken are checked against it in the blanking (the engine's init geometry,
-- the init job's clocks from ms_job_clocks, check_add in ms_frame_plan: taken, or refused with
-- CMD_CYCLES); the verdicts are tentative until the start of frame, which reports and frees the refused
-- adds (a clock or two each) and goes in; adds taken too late to be checked, or a plan made again (a
-- remove, a fault's words, another frame size), are checked at the start of frame while the input
-- waits.  A frame with nothing left to check goes in at once.  A frame size on the ports other than the
-- plan's, in the blanking, plans again there (and undoes the checks).  Each target with a job has its
-- slot's capture loaded (the region, or the init rectangle).  The frame then streams in,
-- every slot capturing its own region, and the jobs run as their slots are released (ms_job_queue, in
-- release order; an init: ms_init_job learns the model from the slot first).  A job's word goes to
-- ms_result_order, its new state waits beside the committed one.  When the frame has ended and its
-- last job has ended, every job's state is committed, and the slots are walked in id order (two clocks a
-- slot: its flags are read into registers, then decided on): the top's words are written (held: err_code 6; a frame of another size than the target's); then the frame is
-- closed and its words leave in ascending id.  A stream fault (or a start of frame that cuts the frame)
-- stops the frame's jobs: the running one ends, the queued ones are dropped, the pending states are
-- dropped, and every live target gets an error word from its committed state.  No live target: slot
-- 0's word alone.  The input waits at the next start of frame for the frame's last job, so the jobs
-- get the rest of their frame and the blanking, not yet the raster slack of docs/multi_target_core.md
-- (jobs running while the next frame streams); the plan's verdicts are the rule's.
-- Handshake: AXI4-Stream video in, commands valid / ready (taken between frames), cmd_done reports,
-- AXI4-Stream results (tlast on a frame's last word).
-- Not yet: overflow (a second fault before the first one's words), a frame size per target in the plan
-- (the plan takes frame_width / frame_height), an init pending after a fault counted without its check.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_stream_pkg.all;

entity ms_tracker_shared is
  generic (
    MAX_TARGETS    : positive range 1 to 16 := 2;   -- target slots
    MAX_FRAME_W    : natural := 2048;     -- widest frame
    RGB_PACKING    : natural := 0;        -- s_axis_tdata layout (as ms_tracker)
    LANES          : natural := 4;        -- pixels per clock of a pixel pass
    COLOUR_BITS    : natural := 3;        -- bits per channel of the colour bin
    EDGE_BINS_LOG2 : natural := 4;        -- (front end; unused by v2)
    EDGE_SHIFT     : natural := 5;        -- (front end; unused by v2)
    FEATURES       : natural := 1;        -- must be 1 (colour)
    KERNEL_EPAN    : natural := 0;        -- must be 0 (flat)
    KERNEL_BITS    : natural := 8;        -- KA/KB scale of the target statistics
    MAX_HALF       : natural := 63;       -- largest window half extent (max_window = 2 MAX_HALF + 1)
    MARGIN         : natural := 32;       -- search margin (decimated px)
    COORD_W        : natural := 12;       -- frame coordinate bits
    CF             : natural := 8;        -- centre fraction bits
    WI             : natural := 4;
    WF             : natural := 4;
    RF             : natural := 6;
    AF             : natural := 8;
    RHO_OUT_FRAC   : natural := 16;
    MAX_ITER       : natural := 20;
    EPS2           : natural := 65536;
    HALF_W         : natural := 6;
    REGION_MAX     : natural := 256;
    REGION_W       : natural := 9;
    STRIDE         : natural := 64;
    ADDR_W         : natural := 14;
    KVAL_W         : natural := 1;
    HIST_W         : natural := 14;
    COUNT_W        : natural := 14;
    POSSUM_W       : natural := 21;
    KD_W           : natural := 29;
    SQRT_IN_W      : natural := 40;
    RHO_SUM_W      : natural := 21;
    RATIO_Q_W      : natural := 16;
    WEIGHT_W       : natural := 8;
    SW_W           : natural := 22;
    SWX_W          : natural := 29;
    SHIFT_Q_W      : natural := 14;
    CENTRE_W       : natural := 17;
    CENTRE_ABS_W   : natural := 20;
    ITER_W         : natural := 5;
    RHO_OUT_W      : natural := 17;
    ALPHA_W        : natural := 9;
    WIN_W          : natural := 7;
    RESULT_W       : natural := 160;
    -- v2 (mstrack.hw.cosim.CoreConfigV2.generics)
    PAD16          : natural := 4;        -- pad in 1/16
    RING16         : natural := 10;       -- bg_ring in 1/16
    MAX_WINDOW     : natural := 127;      -- largest window diameter (decimated px)
    KT_W           : natural := 9;        -- KA/KB width (KERNEL_BITS + 1)
    ST2_W          : natural := 23;
    SHARE_W        : natural := 17;
    SPREAD_W       : natural := 25;
    SIZE_W         : natural := 20;       -- w8, h8 bits (COORD_W + 8)
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
    CONF_LOST      : natural := 26214;    -- round(conf_lost 2**16)
    CONF_UNCERTAIN : natural := 32768;
    CONF_REACQUIRE : natural := 32768;
    SPREAD_DEFAULT : natural := 5368709;  -- spread_ref when the init spread is 0: (128 << (KB + 16)) / (16 + PAD16)**2
    BG_Q_W         : natural := 14;
    BG_O_W         : natural := 17;
    SEARCH_ITER    : natural := 5;        -- iterations per start point while lost
    STEP16         : natural := 16;       -- search_step in 1/16 (start points +- step x window)
    MARGIN_MAX     : natural := 255;      -- largest region margin (MARGIN + the search offset)
    -- the gated scale test (mstrack.fixed.tracker_v2 _scale_verdict, scale_test with scale_test_gate):
    -- d256 = round(256 scale_test), 13 = tracker v2's default 0.05; 0 = off (mstrack-v2-colour).
    -- Costs a 9-bit constant multiply per axis, a 2-input mux on the window-size inputs, the fit
    -- compares, 2 x 17-bit rho compares and one SPREAD_W compare (the gate); buys rho-checked scale
    -- updates at 2 x (tables + Qw load + one pass + rho) clocks more per tracking frame
    SCALE_TEST_D256 : natural range 0 to 255 := 13;
    -- the joint colour x gradient-orientation bins (FixedTrackerV2 with orient_T = ORIENT_T, the
    -- default tracker v2's 64): -1 = off (colour bins alone: mstrack-v2-colour, bit for bit);
    -- >= 0: a pixel's bin is 9 colour + ms_orient_bin(grey, ORIENT_T) (4,608 bins: N_ORIENT 9 banks of
    -- the histogram, the bin pass, the model and T; a 4-bit orientation region RAM beside the colour one)
    ORIENT_T        : integer range -1 to 2047 := 64;
    -- the slots (ms_slot_pool): RAM read latency (the pool's read port adds its multiplexer)
    RD_LAT          : positive := 3;
    -- the capacity rule (mstrack.fixed.multi_capacity.MultiCoreConfig: VideoTiming and PassCosts)
    FRAME_LINES     : natural := 1125;    -- lines per frame, blanking included
    ACTIVE_LINES    : natural := 1080;
    LINE_CLOCKS     : natural := 2200;    -- clocks per line
    LC_W            : positive := 13;     -- bits of LINE_CLOCKS
    SUM_W           : positive := 28;     -- sums of clocks, slacks
    CLK_W           : natural := 24;      -- a job's clocks
    PLAN_REGION_W   : natural := 10;      -- ms_job_demand's region widths (mstrack.hw.multi_core.job_demand_generics)
    GROW_Q16        : natural := 6554;
    PASS_LAT        : natural := 10;
    M_TRACK         : natural := 21;
    C_TRACK         : natural := 13170;
    M_LOST          : natural := 54;
    C_LOST          : natural := 32375;
    C_INIT          : natural := 3534;
    SCALE_PERMILLE  : natural := 50;
    C_SCALE         : natural := 2862
  );
  port (
    clk                  : in  std_logic;                                   -- clock
    rst                  : in  std_logic;                                   -- synchronous reset, active high
    frame_width          : in  unsigned(COORD_W - 1 downto 0);              -- as ms_tracker_v2
    frame_height         : in  unsigned(COORD_W - 1 downto 0);
    -- commands: op 0 add (box x, y, w, h as ms_tracker_v2's s_init), 1 remove (target id)
    s_cmd_tvalid         : in  std_logic;
    s_cmd_tready         : out std_logic;
    s_cmd_op             : in  std_logic;
    s_cmd_id             : in  unsigned(3 downto 0);
    s_cmd_x              : in  signed(COORD_W + 1 downto 0);
    s_cmd_y              : in  signed(COORD_W + 1 downto 0);
    s_cmd_w              : in  unsigned(COORD_W downto 0);
    s_cmd_h              : in  unsigned(COORD_W downto 0);
    cmd_done             : out std_logic;                                   -- one clock: an outcome
    cmd_code             : out unsigned(1 downto 0);                        -- 0 ok, 1 full / not live, 3 box rejected
    cmd_id               : out unsigned(3 downto 0);                        -- the slot concerned
    -- video in
    s_axis_tdata         : in  std_logic_vector(23 downto 0);
    s_axis_tvalid        : in  std_logic;
    s_axis_tready        : out std_logic;
    s_axis_tlast         : in  std_logic;
    s_axis_tuser         : in  std_logic;
    -- results: result word v2 + the 4-bit id
    m_axis_result_tdata  : out std_logic_vector(RESULT_W + 3 downto 0);
    m_axis_result_tvalid : out std_logic;
    m_axis_result_tready : in  std_logic;
    m_axis_result_tlast  : out std_logic;
    live                 : out std_logic_vector(MAX_TARGETS - 1 downto 0);  -- slots holding a target (or its add)
    busy                 : out std_logic                                    -- an engine's mean shift is running
  );
end entity;

architecture rtl of ms_tracker_shared is
  constant NT      : positive := MAX_TARGETS;
  constant SW      : natural := bits_for(NT - 1);
  constant TS_W    : natural := v2_state_w(CENTRE_ABS_W, SIZE_W, COORD_W, SHARE_W, CON_W, SPREAD_W);
  constant BIN_W   : natural := 3 * COLOUR_BITS;
  constant OR_ON   : boolean := ORIENT_T >= 0;
  constant N_OR    : natural := 8 * boolean'pos(OR_ON) + 1;
  constant DATA_W  : natural := BIN_W + 4 * boolean'pos(OR_ON);
  -- the slot pool's read latency is RD_LAT + 2 (address copy, RAMs, multiplexer): the init job's; the
  -- engine gives its address a clock early (ram_addr_next) and sees RAM_LAT = RD_LAT + 1
  constant POOL_LAT : positive := RD_LAT + 2;
  constant RAM_LAT : positive := RD_LAT + 1;
  constant ST_OK    : unsigned(2 downto 0) := "000";
  constant ST_ERROR : unsigned(2 downto 0) := "110";
  constant ERR_CAPACITY : std_logic_vector(2 downto 0) := "110";
  constant F_REJ   : natural := 4;
  constant F_NOT   : natural := 5;
  constant V_FL    : natural := 2 * CENTRE_ABS_W + 2 * SIZE_W + RHO_OUT_W + 17 + 3 + ITER_W + 2 + 3 + 4;

  subtype slot_t is unsigned(3 downto 0);
  type slot_arr is array (0 to NT - 1) of slot_t;
  type rec_arr is array (0 to NT - 1) of std_logic_vector(TS_W - 1 downto 0);
  type cen_arr is array (0 to NT - 1) of unsigned(CENTRE_ABS_W - 1 downto 0);
  type size_arr is array (0 to NT - 1) of unsigned(SIZE_W - 1 downto 0);
  type crd_arr is array (0 to NT - 1) of unsigned(COORD_W - 1 downto 0);
  type bxy_arr is array (0 to NT - 1) of signed(COORD_W + 1 downto 0);
  type bwh_arr is array (0 to NT - 1) of unsigned(COORD_W downto 0);
  type l2d_arr is array (0 to NT - 1) of unsigned(2 downto 0);

  -- per slot: the model's CoreModelMulti / CoreModelV2 state
  signal alloc, pend, waiting, pinit, valid, rejd, held, job : std_logic_vector(NT - 1 downto 0) :=
    (others => '0');
  signal recs    : rec_arr := (others => (others => '0'));     -- the target's record (valid)
  signal c8x_a, c8y_a : cen_arr := (others => (others => '0')); -- centre and size for the words of the top
  signal w8_a, h8_a : size_arr := (others => (others => '0'));
  signal fw_a, fh_a : crd_arr := (others => (others => '0'));   -- the target's frame size
  signal bx_a, by_a : bxy_arr := (others => (others => '0'));   -- an add's box
  signal bw_a, bh_a : bwh_arr := (others => (others => '0'));
  signal hold_l2d : l2d_arr := (others => (others => '0'));
  -- a job's outcome, pending until its frame's words are sent (committed then, dropped on a fault)
  signal runm, jdone : std_logic_vector(NT - 1 downto 0) := (others => '0');
  -- registered per-slot write enables: a job's outcome into its pending registers (the clock after
  -- J_END), the frame's commit (S_J_CMT), an add's box (S_CMD), a remove's clears (S_CMD), an add
  -- accepted: its centre and size (the clock after S_A_CODE's verdict)
  signal pw_m, cmt_m, cm_add, cm_rm, ac_m : std_logic_vector(NT - 1 downto 0) := (others => '0');
  signal cm_kk   : unsigned(3 downto 0) := (others => '0');     -- the add's slot (the lowest free one)
  signal cm_full : std_logic := '0';                             -- no free slot
  signal j_oh    : std_logic_vector(NT - 1 downto 0) := (others => '0');  -- the job's slot, one-hot
  signal j_ld    : std_logic_vector(NT - 1 downto 0) := (others => '0');  -- j_oh, not an init pending
  signal p_recs  : rec_arr := (others => (others => '0'));
  signal p_c8x, p_c8y : cen_arr := (others => (others => '0'));
  signal p_w8, p_h8 : size_arr := (others => (others => '0'));
  signal p_fw, p_fh : crd_arr := (others => (others => '0'));
  signal ord     : slot_arr := (others => (others => '0'));     -- slots in the order of their adds
  signal n_ord   : natural range 0 to NT := 0;
  signal lst     : slot_arr := (others => (others => '0'));     -- the plan's live targets, oldest first
  signal n_live  : natural range 0 to NT := 0;
  signal n_cnt   : natural range 0 to NT + 1 := 0;               -- check_add's n_live
  signal rej_flag : std_logic := '0';
  -- a command taken in S_IDLE, carried out in S_CMD (its slot's registers written from registers)
  signal cm_op   : std_logic := '0';
  signal cm_id   : unsigned(3 downto 0) := (others => '0');
  signal cm_x, cm_y : signed(COORD_W + 1 downto 0) := (others => '0');
  signal cm_w, cm_h : unsigned(COORD_W downto 0) := (others => '0');
  signal cm_fw, cm_fh : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal fcount  : unsigned(15 downto 0) := (others => '0');

  type state_t is (S_IDLE, S_CMD, S_LIST, S_PLAN, S_ADDS, S_A_DROP, S_A_LOAD, S_A_INIT, S_A_CLK, S_A_OFFER, S_A_CODE,
                   S_OPEN, S_STREAM, S_J_WAIT, S_J_CMT, S_J_SZ, S_J_NEXT, S_COMMIT, S_SIDE, S_E_NEXT, S_SINGLE);
  signal fsm     : state_t := S_IDLE;
  -- the jobs: run as their regions are released, while the frame streams
  type jstate_t is (J_IDLE, J_SEL, J_LOAD, J_INIT, J_IJ, J_WORD, J_END);
  signal jfsm    : jstate_t := J_IDLE;
  signal j_slot  : slot_t := (others => '0');
  signal jrun    : std_logic := '0';                            -- the frame's jobs may start
  signal arm_req : std_logic := '0';                            -- a frame opened: set its masks, then jrun
  signal cut_pend : std_logic := '0';                           -- a cut frame's fault is still to come
  -- the plan in the blanking: the live targets' plan runs as soon as the previous frame is closed; it
  -- holds (plan_ok) until a remove, a stream fault's words or the start of frame; pl_fw / pl_fh: the
  -- frame size it planned with (a start of frame with another size is planned again)
  signal plan_ok, early : std_logic := '0';
  signal pl_fw, pl_fh : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal direct : std_logic;                                    -- a start of frame can go in at once
  -- the adds checked in the blanking: once the plan holds, the inits pending and each add taken are
  -- checked against it at once (chk_early), their verdicts tentative until the start of frame: eacc an
  -- add taken (or a box the engine refused), eref an add refused, reported and freed at the start of
  -- frame; chk_ok: the inits pending are checked.  A new plan (S_LIST) or a stream fault's words undo them
  -- (the adds wait again), so the verdicts are those of the check at the start of frame
  signal eacc, eref : std_logic_vector(NT - 1 downto 0) := (others => '0');
  signal chk_ok, chk_early : std_logic := '0';
  signal q_flush : std_logic := '0';
  signal q_valid, q_ready : std_logic;
  signal q_slot  : unsigned(3 downto 0);
  signal q_rel   : std_logic_vector(NT - 1 downto 0);
  signal j       : natural range 0 to NT := 0;                   -- list / slot index
  signal pass_b  : std_logic := '0';                            -- the adds' second pass (the waiting ones)
  signal k_cur   : slot_t := (others => '0');
  signal a_rd    : std_logic := '0';                            -- S_LIST / S_ADDS: k_cur holds entry j's slot
  signal out_mask : std_logic_vector(NT - 1 downto 0) := (others => '0');
  signal om_any  : std_logic := '0';                            -- out_mask has a slot (registered with it)
  signal first_w : std_logic := '0';
  signal rej_any : std_logic := '0';
  signal is_err  : std_logic := '0';                            -- the merged frame is a stream fault's
  signal err_r   : std_logic_vector(2 downto 0) := (others => '0');
  signal side_w  : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');
  signal side_push : std_logic := '0';                          -- S_SIDE: push side_w (else only bookkeeping)
  signal side_nt : std_logic := '0';                            -- the slot's word has no_target
  -- the word to ms_result_order, loaded every clock: side_w in the walk (wsel: the state of the clock
  -- before was one of the walk's), else the engine's word; ro_valid says when it is taken
  signal wsel    : std_logic := '0';
  signal sg_ok   : std_logic := '0';                            -- S_SINGLE: side_w holds its word
  signal sgl     : std_logic := '0';                            -- the sequencer is in S_SINGLE
  -- the slot walk (S_J_NEXT, S_E_NEXT) decides on registers: slot j's flags and word fields are read
  -- in one clock (pf_ok '0'), used in the next (pf_ok '1')
  signal pf_ok, pf_alloc, pf_valid, pf_pinit, pf_held, pf_rejd, pf_size : std_logic := '0';
  signal pf_c8x, pf_c8y : unsigned(CENTRE_ABS_W - 1 downto 0) := (others => '0');
  signal pf_w8, pf_h8 : unsigned(SIZE_W - 1 downto 0) := (others => '0');
  signal pf_l2d : unsigned(2 downto 0) := (others => '0');
  -- per slot: the frame's size is not the target's (registered every clock from fr_w / fr_h and the
  -- slot's fw_a / fh_a; the walk reads it a clock after the commit's, S_J_SZ)
  signal sz_m   : std_logic_vector(NT - 1 downto 0) := (others => '0');

  -- input
  signal open_in, in_frame : std_logic := '0';
  signal line_cnt : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal fr_w, fr_h : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal beat, s_ready, size_ok : std_logic;
  signal ev_end, ev_err : std_logic := '0';
  signal ev_code : std_logic_vector(2 downto 0) := (others => '0');
  -- a frame in the front end: started at the input and its frame_start not out yet, or started and
  -- not ended (frame_end or frame_error)
  signal inflight : natural range 0 to 3 := 0;
  signal fe_open, fe_busy : std_logic := '0';

  -- front end and slots
  signal fe_start, fe_end, fe_error, ad_end, ip_valid, ad_valid : std_logic;
  signal fe_code  : std_logic_vector(2 downto 0);
  signal ip_x, ip_y, ad_x, ad_y : unsigned(COORD_W - 1 downto 0);
  signal ip_obin  : std_logic_vector(3 downto 0);
  signal ad_cbin  : std_logic_vector(BIN_W - 1 downto 0);
  signal cap_load : std_logic := '0';
  signal cap_slot : unsigned(SW - 1 downto 0) := (others => '0');
  signal cap_l2d  : unsigned(2 downto 0) := (others => '0');
  signal cap_x0, cap_y0, cap_x1, cap_y1 : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal released : std_logic_vector(NT - 1 downto 0);
  signal rd_slot  : unsigned(SW - 1 downto 0) := (others => '0');
  signal raddr, e_raddr, e_raddr_next, j_raddr : std_logic_vector(LANES * ADDR_W - 1 downto 0);
  signal p_cbin   : std_logic_vector(LANES * BIN_W - 1 downto 0);
  signal p_obin   : std_logic_vector(LANES * 4 - 1 downto 0);
  signal j_rdata  : std_logic_vector(LANES * DATA_W - 1 downto 0);

  -- engine and init job
  signal cmd_go, cmd_init, cmd_load, ij_start : std_logic := '0';
  signal c_init_x, c_init_y : signed(COORD_W + 1 downto 0) := (others => '0');
  signal c_init_w, c_init_h : unsigned(COORD_W downto 0) := (others => '0');
  signal c_init_fw, c_init_fh : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal ini_slot : slot_t := (others => '0');                   -- the slot c_init_* are loaded from
  signal c_state  : std_logic_vector(TS_W - 1 downto 0) := (others => '0');
  signal c_model  : unsigned(clog2(NT) - 1 downto 0) := (others => '0');
  signal e_idle, e_geo_done, e_init_rej, e_res_valid, e_res_ready, e_busy : std_logic;
  signal e_rec    : std_logic_vector(TS_W - 1 downto 0);
  signal e_valid, e_init : std_logic;
  signal e_c8x, e_c8y : unsigned(CENTRE_ABS_W - 1 downto 0);
  signal e_w8, e_h8 : unsigned(SIZE_W - 1 downto 0);
  signal e_fw, e_fh : unsigned(COORD_W - 1 downto 0);
  signal e_res    : std_logic_vector(RESULT_W - 1 downto 0);
  signal e_word_rej : std_logic := '0';
  signal l2d      : unsigned(2 downto 0);
  signal reg_x, reg_y, reg_w, reg_h, wb, hb, bg_cx, bg_cy : unsigned(COORD_W - 1 downto 0);
  signal rect_x, rect_y, rect_w, rect_h, last_x, last_y : unsigned(COORD_W - 1 downto 0);
  signal geo_wd, geo_hd : unsigned(WIN_W - 1 downto 0);
  signal m_sel    : unsigned(clog2(NT) - 1 downto 0);
  signal m_rd_addr : unsigned(BIN_W - 1 downto 0);
  signal m_qn     : unsigned(16 downto 0);
  signal m_t      : std_logic;
  signal m_qn_all : std_logic_vector(N_OR * 17 - 1 downto 0);
  signal m_t_all  : std_logic_vector(N_OR - 1 downto 0);
  signal j_busy, ij_done : std_logic;

  -- the plan
  signal pl_start, pl_busy, st_req, st_valid, p_valid, p_taken, plan_done : std_logic;
  signal st_index, p_slot : unsigned(3 downto 0);
  signal st_slot  : unsigned(3 downto 0) := (others => '0');
  signal st_w8, st_h8 : unsigned(COORD_W + 7 downto 0) := (others => '0');
  signal st_c8x, st_c8y : unsigned(COORD_W + CF - 1 downto 0) := (others => '0');
  signal st_lost, st_valid_r, st_pend : std_logic := '0';
  signal p_l2d    : unsigned(2 downto 0);
  signal p_reg_x, p_reg_y : unsigned(COORD_W - 1 downto 0);
  signal p_reg_w, p_reg_h : unsigned(PLAN_REGION_W - 1 downto 0);
  signal a_ready, a_offer, a_full, a_done : std_logic := '0';
  signal a_code   : unsigned(1 downto 0);
  signal a_clocks : unsigned(CLK_W - 1 downto 0) := (others => '0');
  signal a_release, a_next : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal g_x0, g_y0, g_x1, g_y1, g_next : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal g_rel : unsigned(COORD_W downto 0) := (others => '0');
  signal jc_start, jc_done : std_logic := '0';
  signal jc_clocks : unsigned(CLK_W - 1 downto 0);

  -- results
  signal ro_valid, ro_close, ro_close_ready : std_logic := '0';
  signal ro_id    : unsigned(3 downto 0) := (others => '0');
  signal ro_word  : std_logic_vector(RESULT_W - 1 downto 0) := (others => '0');
  signal ro_mask  : std_logic_vector(NT - 1 downto 0) := (others => '0');
  signal done_r   : std_logic := '0';
  signal code_r   : unsigned(1 downto 0) := (others => '0');
  signal id_r     : unsigned(3 downto 0) := (others => '0');

  function idx(v : unsigned) return natural is
  begin
    return to_integer(v);
  end function;

  -- a word of the top: centre and size, no statistics
  function top_word(cx, cy, bw, bh : unsigned; st : unsigned; dl : unsigned; flags, err : std_logic_vector;
                    fc : unsigned) return std_logic_vector is
  begin
    return v2_word(RESULT_W, CENTRE_ABS_W, SIZE_W, RHO_OUT_W, ITER_W, cx, cy, bw, bh, to_unsigned(0, 17),
                   to_unsigned(0, 17), st, to_unsigned(0, ITER_W), "00", dl, to_unsigned(0, 4), flags, err, fc);
  end function;

  -- the number of set bits of v
  function ones(v : std_logic_vector) return natural is
    variable n : natural := 0;
  begin
    for i in v'range loop
      if v(i) = '1' then
        n := n + 1;
      end if;
    end loop;
    return n;
  end function;

  -- the lowest set bit of v, or -1
  function lowest(v : std_logic_vector) return integer is
  begin
    for i in 0 to v'length - 1 loop
      if v(v'low + i) = '1' then
        return i;
      end if;
    end loop;
    return -1;
  end function;
begin
  assert FEATURES = 1 and KERNEL_EPAN = 0
    report "ms_tracker_shared: tracker v2 is colour only with the flat kernel (FEATURES 1, KERNEL_EPAN 0)"
    severity failure;

  ---------------------------------------------------------------------------- video input
  size_ok <= '1' when frame_width >= 3 and frame_height >= 3 and frame_width <= MAX_FRAME_W else '0';
  -- a start of frame waits for the frame's plan (S_OPEN takes it); other beats flow while a frame is
  -- open, and between frames in S_IDLE (a beat without a start of frame: ms_stream_check reports it)
  -- a planned frame without adds to check goes in from S_IDLE at once (no stall at its start)
  direct <= '1' when fsm = S_IDLE and plan_ok = '1' and waiting = (waiting'range => '0')
                     and eref = (eref'range => '0') and (pinit = (pinit'range => '0') or chk_ok = '1')
                     and open_in = '0' and ev_end = '0' and ev_err = '0'
                     and s_cmd_tvalid = '0' and frame_width = pl_fw and frame_height = pl_fh else '0';
  s_ready <= '1' when rst = '0' and ((fsm = S_OPEN and s_axis_tuser = '1')
                                      or (direct = '1' and s_axis_tuser = '1')
                                      or (fsm = S_STREAM and open_in = '1' and s_axis_tuser = '0')
                                      or (fsm = S_IDLE and open_in = '0' and s_axis_tuser = '0'
                                          and s_cmd_tvalid = '0' and ev_end = '0' and ev_err = '0'))
             else '0';
  s_axis_tready <= s_ready;
  beat <= s_axis_tvalid and s_ready;

  fe_busy <= '1' when inflight /= 0 or fe_open = '1' else '0';

  p_gate : process(clk)
    variable f : natural range 0 to 3;
  begin
    if rising_edge(clk) then
      f := inflight;
      if beat = '1' and s_axis_tuser = '1' and size_ok = '1' and f < 3 then
        f := f + 1;
      end if;
      if fe_start = '1' and f > 0 then
        f := f - 1;
      end if;
      inflight <= f;
      if fe_end = '1' or fe_error = '1' then
        fe_open <= '0';
      end if;
      if fe_start = '1' then
        fe_open <= '1';
      end if;
      if beat = '1' then
        if s_axis_tuser = '1' then
          in_frame <= size_ok;
          open_in <= size_ok;
          fr_w <= frame_width;
          fr_h <= frame_height;
          line_cnt <= (others => '0');
        elsif in_frame = '1' and s_axis_tlast = '1' then
          line_cnt <= line_cnt + 1;
          if line_cnt = fr_h - 1 then
            in_frame <= '0';
            open_in <= '0';
          end if;
        end if;
      end if;
      if rst = '1' then
        in_frame <= '0';
        open_in <= '0';
        inflight <= 0;
        fe_open <= '0';
      end if;
    end if;
  end process;

  u_fe : entity work.ms_frontend
    generic map (COORD_W => COORD_W, MAX_FRAME_W => MAX_FRAME_W, COLOUR_BITS => COLOUR_BITS,
                 EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, RGB_PACKING => RGB_PACKING,
                 ORIENT_T => maximum(ORIENT_T, 0))
    port map (clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
              in_valid => beat, in_data => s_axis_tdata, in_sof => s_axis_tuser, in_eol => s_axis_tlast,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              frame_start => fe_start, frame_end => fe_end, frame_error => fe_error, err_code => fe_code,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => ad_end);

  u_pool : entity work.ms_slot_pool
    generic map (N_SLOTS => NT, LANES => LANES, COORD_W => COORD_W, REGION_MAX => REGION_MAX, STRIDE => STRIDE,
                 ADDR_W => ADDR_W, COLOUR_W => BIN_W, ORIENT => OR_ON, LOG2_D_MAX => 4, RD_LAT => RD_LAT,
                 WR_LAT => 1)
    port map (clk => clk, rst => rst, frame_start => fe_start, frame_error => fe_error,
              ad_valid => ad_valid, ad_x => ad_x, ad_y => ad_y, ad_cbin => ad_cbin, ad_end => ad_end,
              ip_valid => ip_valid, ip_x => ip_x, ip_y => ip_y, ip_obin => ip_obin,
              load => cap_load, load_slot => cap_slot, load_now => '0', dec_log2 => cap_l2d,
              fx0 => cap_x0, fy0 => cap_y0, fx1 => cap_x1, fy1 => cap_y1, armed => open, pending => open,
              released => released, late => open, rd_slot => rd_slot, raddr => raddr, rdata => p_cbin,
              robin => p_obin);
  -- the init job and the engine never read in the same clocks: the engine's passes start after the
  -- init job's done, and the job's reads end before it
  raddr <= j_raddr when j_busy = '1' else e_raddr_next;
  g_lane : for b in 0 to LANES - 1 generate
    j_rdata(b * DATA_W + BIN_W - 1 downto b * DATA_W) <= p_cbin((b + 1) * BIN_W - 1 downto b * BIN_W);
    g_or : if OR_ON generate
      j_rdata(b * DATA_W + BIN_W + 3 downto b * DATA_W + BIN_W) <= p_obin(b * 4 + 3 downto b * 4);
    end generate;
  end generate;

  -- the released regions of the frame's jobs, in release order
  q_rel <= released and runm;
  q_ready <= '1' when jfsm = J_IDLE and jrun = '1' and rst = '0' else '0';
  u_queue : entity work.ms_job_queue
    generic map (N_SLOTS => NT)
    port map (clk => clk, rst => rst, flush => q_flush, rel => q_rel, q_valid => q_valid, q_ready => q_ready,
              q_slot => q_slot, merged => open);

  ---------------------------------------------------------------------------- the engine
  u_job : entity work.ms_init_job
    generic map (LANES => LANES, STRIDE => STRIDE, ADDR_W => ADDR_W, REGION_W => REGION_W, COORD_W => COORD_W,
                 RD_LAT => POOL_LAT, BIN_W => BIN_W, N_ORIENT => N_OR, HALF_W => HALF_W, RING_W => 5,
                 Q_W => BG_Q_W, O_W => BG_O_W, KD_W => KD_W, MODELS => NT)
    port map (clk => clk, rst => rst, start => ij_start, rect_w => resize(rect_w, REGION_W),
              rect_h => resize(rect_h, REGION_W), cx => resize(bg_cx - rect_x, REGION_W),
              cy => resize(bg_cy - rect_y, REGION_W), wb => resize(wb, HALF_W + 1), hb => resize(hb, HALF_W + 1),
              ring16 => to_unsigned(RING16, 5), model => m_sel, org_x => rect_x, org_y => rect_y,
              last_x => last_x, last_y => last_y, busy => j_busy, done => ij_done,
              raddr => j_raddr, rdata => j_rdata, m_rd_addr => m_rd_addr, m_rd_obin => (others => '0'),
              m_rd_sel => m_sel, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all, m_t_all => m_t_all);

  u_eng : entity work.ms_engine
    generic map (MAX_FRAME_W => MAX_FRAME_W, LANES => LANES, COLOUR_BITS => COLOUR_BITS, KERNEL_BITS => KERNEL_BITS,
                 MAX_HALF => MAX_HALF, MARGIN => MARGIN, COORD_W => COORD_W, CF => CF, WI => WI, WF => WF, RF => RF,
                 AF => AF, RHO_OUT_FRAC => RHO_OUT_FRAC, MAX_ITER => MAX_ITER, EPS2 => EPS2, HALF_W => HALF_W,
                 REGION_W => REGION_W, STRIDE => STRIDE, ADDR_W => ADDR_W, KVAL_W => KVAL_W, HIST_W => HIST_W,
                 COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, KD_W => KD_W, SQRT_IN_W => SQRT_IN_W,
                 RHO_SUM_W => RHO_SUM_W, RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, SW_W => SW_W,
                 SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W, CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W,
                 ITER_W => ITER_W, RHO_OUT_W => RHO_OUT_W, ALPHA_W => ALPHA_W, WIN_W => WIN_W,
                 RESULT_W => RESULT_W, PAD16 => PAD16, RING16 => RING16, MAX_WINDOW => MAX_WINDOW, KT_W => KT_W,
                 ST2_W => ST2_W, SHARE_W => SHARE_W, SPREAD_W => SPREAD_W, SIZE_W => SIZE_W, SCALE_W => SCALE_W,
                 SCALE_GAIN => SCALE_GAIN, SCALE_REG => SCALE_REG, SCALE_STEP => SCALE_STEP,
                 SCALE_RATIO_Q_W => SCALE_RATIO_Q_W, WR_Q_W => WR_Q_W, CON_W => CON_W, LOSS_K => LOSS_K,
                 REF_K => REF_K, LOSS_RHO => LOSS_RHO, LOSS_CONTRAST => LOSS_CONTRAST, CONF_LOST => CONF_LOST,
                 CONF_UNCERTAIN => CONF_UNCERTAIN, CONF_REACQUIRE => CONF_REACQUIRE,
                 SPREAD_DEFAULT => SPREAD_DEFAULT, BG_Q_W => BG_Q_W, BG_O_W => BG_O_W, SEARCH_ITER => SEARCH_ITER,
                 STEP16 => STEP16, MARGIN_MAX => MARGIN_MAX, SCALE_TEST_D256 => SCALE_TEST_D256,
                 ORIENT_T => ORIENT_T, MODELS => NT, RAM_LAT => RAM_LAT, SLOT_INIT => true)
    port map (clk => clk, rst => rst, idle => e_idle, geo_done => e_geo_done, go => cmd_go, rearm => '0',
              init_take => cmd_init, init_x => c_init_x, init_y => c_init_y, init_w => c_init_w,
              init_h => c_init_h, init_fw => c_init_fw, init_fh => c_init_fh, init_rejected => e_init_rej,
              load_take => cmd_load, load_state => c_state, load_model => c_model,
              rec => e_rec, rec_valid => e_valid, rec_init => e_init, rec_c8x => e_c8x, rec_c8y => e_c8y,
              rec_w8 => e_w8, rec_h8 => e_h8, rec_fw => e_fw, rec_fh => e_fh,
              geo_l2d => l2d, geo_reg_x => reg_x, geo_reg_y => reg_y, geo_reg_w => reg_w, geo_reg_h => reg_h,
              geo_wb => wb, geo_hb => hb, geo_bg_cx => bg_cx, geo_bg_cy => bg_cy,
              geo_rect_x => rect_x, geo_rect_y => rect_y, geo_rect_w => rect_w, geo_rect_h => rect_h,
              geo_wd => geo_wd, geo_hd => geo_hd, geo_last_x => last_x, geo_last_y => last_y,
              m_sel => m_sel, m_rd_addr => m_rd_addr, m_qn => m_qn, m_t => m_t, m_qn_all => m_qn_all,
              m_t_all => m_t_all, ram_addr => e_raddr, ram_addr_next => e_raddr_next, ram_data => p_cbin, ram_obin => p_obin,
              res_valid => e_res_valid, res_ready => e_res_ready, res_data => e_res,
              word_fcount => fcount, word_rejected => e_word_rej, word_overflow => '0', busy => e_busy);
  busy <= e_busy;

  ---------------------------------------------------------------------------- the plan
  u_plan : entity work.ms_frame_plan
    generic map (MAX_TARGETS => NT, COORD_W => COORD_W, CF => CF, PAD16 => PAD16, MAX_WINDOW => MAX_WINDOW,
                 HALF_W => HALF_W, REGION_W => PLAN_REGION_W, MARGIN => MARGIN, MARGIN_MAX => MARGIN_MAX,
                 STEP16 => STEP16, GROW_Q16 => GROW_Q16, LANES => LANES, PASS_LAT => PASS_LAT, CLK_W => CLK_W,
                 M_TRACK => M_TRACK, C_TRACK => C_TRACK, M_LOST => M_LOST, C_LOST => C_LOST, C_INIT => C_INIT,
                 SCALE_PERMILLE => SCALE_PERMILLE, C_SCALE => C_SCALE, LC_W => LC_W, SUM_W => SUM_W)
    port map (clk => clk, rst => rst, frame_lines => to_unsigned(FRAME_LINES, COORD_W),
              line_clocks => to_unsigned(LINE_CLOCKS, LC_W),
              blank_clocks => to_unsigned((FRAME_LINES - ACTIVE_LINES) * LINE_CLOCKS, SUM_W),
              start => pl_start, n_live => to_unsigned(n_live, 5), frame_w => pl_fw,
              frame_h => pl_fh, busy => pl_busy, st_req => st_req, st_index => st_index,
              st_valid => st_valid_r, st_slot => st_slot, st_w8 => st_w8, st_h8 => st_h8, st_c8x => st_c8x,
              st_c8y => st_c8y, st_lost => st_lost, p_valid => p_valid, p_slot => p_slot, p_taken => p_taken,
              p_log2_d => p_l2d, p_reg_x => p_reg_x, p_reg_y => p_reg_y, p_reg_w => p_reg_w, p_reg_h => p_reg_h,
              p_clocks => open, p_first_line => open, p_release => open, p_next_line => open,
              plan_done => plan_done, plan_clocks => open, plan_budget => open,
              a_ready => a_ready, a_offer => a_offer, a_full => a_full, a_clocks => a_clocks,
              a_release => a_release, a_next => a_next, a_done => a_done, a_code => a_code);

  -- an add's init job clocks (init_demand)
  u_jc : entity work.ms_job_clocks
    generic map (LANES => LANES, HALF_W => HALF_W, PASS_LAT => PASS_LAT, COORD_W => COORD_W, CLK_W => CLK_W,
                 M_TRACK => M_TRACK, C_TRACK => C_TRACK, M_LOST => M_LOST, C_LOST => C_LOST, C_INIT => C_INIT,
                 SCALE_PERMILLE => SCALE_PERMILLE, C_SCALE => C_SCALE)
    port map (clk => clk, rst => rst, start => jc_start, kind => "10", wd => resize(geo_wd, HALF_W + 1),
              hd => resize(geo_hd, HALF_W + 1), lim => resize(geo_wd, HALF_W + 1), ring_rows => rect_h,
              ring_cols => rect_w, busy => open, done => jc_done, clocks => jc_clocks);

  ---------------------------------------------------------------------------- results
  -- the frame's words (the engine's as its jobs end, the top's in the pass after the frame) leave in
  -- ascending id when the frame is closed
  e_res_ready <= '1' when jfsm = J_WORD else '0';
  u_order : entity work.ms_result_order
    generic map (N_SLOTS => NT, WORD_W => RESULT_W)
    port map (clk => clk, rst => rst, s_valid => ro_valid, s_ready => open, s_id => ro_id, s_word => ro_word,
              close => ro_close, close_mask => ro_mask, close_ready => ro_close_ready,
              m_valid => m_axis_result_tvalid, m_ready => m_axis_result_tready, m_data => m_axis_result_tdata,
              m_last => m_axis_result_tlast, missing => open);
  cmd_done <= done_r;
  cmd_code <= code_r;
  cmd_id   <= id_r;
  live     <= alloc;
  s_cmd_tready <= '1' when fsm = S_IDLE and open_in = '0' and ev_end = '0' and ev_err = '0' and rst = '0'
                  else '0';

  ---------------------------------------------------------------------------- the sequencer
  p_seq : process(clk)
    variable k : natural range 0 to NT - 1;
    variable kj : natural range 0 to NT - 1;                -- the job runner's slot
    variable kk : integer;
    variable fl : std_logic_vector(7 downto 0);
    variable refd : std_logic;                             -- S_ADDS: the add was refused in the blanking
    variable m : std_logic_vector(NT - 1 downto 0);
    variable r : std_logic_vector(TS_W - 1 downto 0);

    -- slot s leaves the age order (a remove, a refused add, a box the engine refused): the entries after
    -- it move up one place (a slot is in the order at most once)
    procedure drop_ord(s : slot_t) is
      variable gone : std_logic;
    begin
      gone := '0';
      for q in 0 to NT - 1 loop
        if q < n_ord and ord(q) = s then
          gone := '1';
        end if;
        if gone = '1' and q < NT - 1 then
          ord(q) <= ord(q + 1);
        end if;
      end loop;
      if gone = '1' then
        n_ord <= n_ord - 1;
      end if;
    end procedure;

    -- the adds checked in the blanking wait again (their plan is gone)
    procedure undo_checks is
    begin
      for i in 0 to NT - 1 loop
        if eacc(i) = '1' then
          waiting(i) <= '1'; pinit(i) <= '0'; rejd(i) <= '0';
        end if;
        if eref(i) = '1' then
          waiting(i) <= '1';
        end if;
      end loop;
      eacc <= (others => '0');
      eref <= (others => '0');
      chk_ok <= '0';
    end procedure;
  begin
    if rising_edge(clk) then
      done_r <= '0';
      cmd_go <= '0';
      cmd_init <= '0';
      cmd_load <= '0';
      ij_start <= '0';
      cap_load <= '0';
      pl_start <= '0';
      jc_start <= '0';
      a_offer <= '0';
      st_valid_r <= '0';
      ro_valid <= '0';
      ro_close <= '0';
      wsel <= '1' when fsm = S_J_CMT or fsm = S_J_SZ or fsm = S_J_NEXT or fsm = S_COMMIT or fsm = S_SIDE
                       or fsm = S_E_NEXT or fsm = S_SINGLE else '0';
      if wsel = '1' then
        ro_word <= side_w;
        ro_id <= k_cur;
      else
        ro_word <= e_res;
        ro_id <= j_slot;
      end if;
      -- the close mask every clock (ms_result_order takes it with ro_close): the frame's slots, or slot 0
      -- alone in S_SINGLE (sg_ok: out_mask is empty there)
      ro_mask <= out_mask;
      ro_mask(0) <= out_mask(0) or sg_ok;
      -- the job's record every clock, an AND-OR under j_ld (set from J_IDLE to J_SEL, else empty): the
      -- engine takes it with cmd_load, the clock after J_SEL or S_ADDS (an add's empty record)
      r := (others => '0');
      for i in 0 to NT - 1 loop
        if j_ld(i) = '1' then
          r := r or recs(i);
        end if;
      end loop;
      c_state <= r;
      -- the walk's word every clock (no decode of the sequencer's state in its enable): S_SINGLE's (sgl),
      -- else S_E_NEXT's (is_err) or S_J_NEXT's from slot j's registered reads; ro_word takes it in the
      -- clock after the state that decides (wsel)
      if sgl = '1' then                                  -- no live target: slot 0's word alone
        if is_err = '1' then
          fl := v2_flags('0', '0', '0', '1', rej_any or rejd(0), '1', '0');
          side_w <= top_word(c8x_a(0), c8y_a(0), w8_a(0), h8_a(0), ST_ERROR, to_unsigned(0, 3), fl, err_r,
                             fcount);
        elsif pinit(0) = '1' and alloc(0) = '1' and (fr_w /= fw_a(0) or fr_h /= fh_a(0)) then
          fl := v2_flags('0', '0', '0', '1', rej_any, '1', '0');
          side_w <= top_word(c8x_a(0), c8y_a(0), w8_a(0), h8_a(0), ST_ERROR, to_unsigned(0, 3), fl,
                             ERR_SIZE_CHANGED, fcount);
        else
          fl := v2_flags('0', '0', '0', '0', rej_any, '1', '0');
          side_w <= top_word(c8x_a(0), c8y_a(0), w8_a(0), h8_a(0), ST_OK, to_unsigned(0, 3), fl, "000", fcount);
        end if;
      else
        fl := v2_flags('0', '0', '0', '1', pf_rejd or (first_w and rej_any), not pf_valid, '0');
        if is_err = '1' then                             -- a stream fault's word
          side_w <= top_word(pf_c8x, pf_c8y, pf_w8, pf_h8, ST_ERROR, to_unsigned(0, 3), fl, err_r, fcount);
        elsif (pf_valid = '1' or pf_pinit = '1') and pf_size = '1' then  -- the frame size's
          side_w <= top_word(pf_c8x, pf_c8y, pf_w8, pf_h8, ST_ERROR, to_unsigned(0, 3), fl, ERR_SIZE_CHANGED,
                             fcount);
        else                                             -- the capacity's
          side_w <= top_word(pf_c8x, pf_c8y, pf_w8, pf_h8, ST_ERROR, pf_l2d, fl, ERR_CAPACITY, fcount);
        end if;
      end if;
      sg_ok <= '0';
      q_flush <= '0';
      -- an add's init rectangle in frame px, its release and next line (the engine's geometry holds from
      -- geo_done until the check's verdict, hundreds of clocks later: registered here every clock)
      g_x0 <= shift_left(rect_x, idx(l2d));
      g_y0 <= shift_left(rect_y, idx(l2d));
      g_x1 <= shift_left(rect_x + rect_w, idx(l2d));
      g_y1 <= shift_left(rect_y + rect_h, idx(l2d));
      g_rel <= shift_left(resize(rect_y + rect_h, COORD_W + 1), idx(l2d)) + 1;
      g_next <= shift_left(reg_y, idx(l2d));
      -- the init box and frame size for the engine, loaded every clock from the slot that a register
      -- selects (ini_slot: the job's slot from J_SEL, the add's from its S_A_LOAD), so no decode of
      -- either state machine reaches these registers; the engine takes them with cmd_init
      c_init_x <= bx_a(idx(ini_slot)); c_init_y <= by_a(idx(ini_slot));
      c_init_w <= bw_a(idx(ini_slot)); c_init_h <= bh_a(idx(ini_slot));
      c_init_fw <= fw_a(idx(ini_slot)); c_init_fh <= fh_a(idx(ini_slot));
      -- the per-slot writes, each under its own registered enable (no decode of the sequencer's state
      -- in a clock enable that fans out to a slot's whole record)
      for i in 0 to NT - 1 loop
        if pw_m(i) = '1' then                            -- a job's outcome, pending (the engine holds it)
          p_recs(i) <= e_rec;
          p_c8x(i) <= e_c8x; p_c8y(i) <= e_c8y; p_w8(i) <= e_w8; p_h8(i) <= e_h8;
          p_fw(i) <= e_fw; p_fh(i) <= e_fh;
        end if;
        if cmt_m(i) = '1' then                           -- the frame ended good: its jobs' states commit
          recs(i) <= p_recs(i);
          c8x_a(i) <= p_c8x(i); c8y_a(i) <= p_c8y(i); w8_a(i) <= p_w8(i); h8_a(i) <= p_h8(i);
          fw_a(i) <= p_fw(i); fh_a(i) <= p_fh(i);
        end if;
        if cm_add(i) = '1' then                          -- an add's box
          bx_a(i) <= cm_x; by_a(i) <= cm_y; bw_a(i) <= cm_w; bh_a(i) <= cm_h;
          fw_a(i) <= cm_fw; fh_a(i) <= cm_fh;
        end if;
        if ac_m(i) = '1' then                            -- an add accepted (the engine holds its geometry)
          c8x_a(i) <= e_c8x; c8y_a(i) <= e_c8y; w8_a(i) <= e_w8; h8_a(i) <= e_h8;
        end if;
        if cm_rm(i) = '1' then                           -- a remove's clears
          c8x_a(i) <= (others => '0'); c8y_a(i) <= (others => '0');
          w8_a(i) <= (others => '0'); h8_a(i) <= (others => '0');
        end if;
      end loop;
      pw_m <= (others => '0');
      cmt_m <= (others => '0');
      cm_add <= (others => '0');
      cm_rm <= (others => '0');
      ac_m <= (others => '0');
      -- slot j's reads for the walk (j = NT: nothing to read)
      pf_ok <= '0';
      if j < NT then
        k := j;
        pf_alloc <= alloc(k); pf_valid <= valid(k); pf_pinit <= pinit(k); pf_held <= held(k);
        pf_rejd <= rejd(k);
        pf_size <= sz_m(k);
        pf_c8x <= c8x_a(k); pf_c8y <= c8y_a(k); pf_w8 <= w8_a(k); pf_h8 <= h8_a(k);
        pf_l2d <= hold_l2d(k);
      end if;
      for i in 0 to NT - 1 loop
        sz_m(i) <= '1' when fr_w /= fw_a(i) or fr_h /= fh_a(i) else '0';
      end loop;
      -- frame events of the front end (the last one of each kind is kept: one frame at a time)
      if fe_end = '1' then
        ev_end <= '1';
      end if;
      if fe_error = '1' then
        ev_err <= '1';
        ev_code <= fe_code;
        if cut_pend = '0' then                           -- the open frame failed: no more of its jobs
          jrun <= '0';
          arm_req <= '0';
        end if;
      end if;

      -- a frame opened (and a cut frame's fault reported): the frame's jobs, masks and first word
      if arm_req = '1' and cut_pend = '0' and fe_error = '0' and (fsm = S_STREAM or fsm = S_J_WAIT) then
        arm_req <= '0';
        jrun <= '1';
        jdone <= (others => '0');
        m := (others => '0');
        for i in 0 to NT - 1 loop
          if alloc(i) = '1' and (valid(i) = '1' or (pinit(i) = '1' and fr_w = fw_a(i) and fr_h = fh_a(i))) then
            m(i) := '1';
          end if;
          runm(i) <= job(i) and not held(i) and m(i);
        end loop;
        out_mask <= m;
        om_any <= '1' when m /= (m'range => '0') else '0';
        rej_any <= rej_flag;
        if rejd /= (rejd'range => '0') then
          rej_any <= '1';
        end if;
      end if;

      -- the job runner: a released region's job on the engine; its word to the result order, its new
      -- state pending until the frame's words are sent
      case jfsm is
        when J_IDLE =>
          if q_valid = '1' and q_ready = '1' then
            kj := idx(q_slot);
            j_slot <= q_slot;
            for i in 0 to NT - 1 loop
              j_oh(i) <= '1' when i = kj else '0';
              j_ld(i) <= '1' when i = kj and pinit(i) = '0' else '0';
            end loop;
            rd_slot <= resize(q_slot, SW);
            e_word_rej <= '1' when rej_any = '1' and lowest(out_mask) = kj else '0';
            jfsm <= J_SEL;
          end if;
        when J_SEL =>                                    -- the record selected from the registered slot
          cmd_load <= '1';                               -- (c_state, above: an AND-OR under the one-hot
          j_ld <= (others => '0');                       -- slot; an init pending loads an empty record)
          c_model <= resize(j_slot, clog2(NT));
          ini_slot <= j_slot;
          jfsm <= J_LOAD;
        when J_LOAD =>                                   -- (the init's box: c_init_*, above; the engine
          kj := idx(j_slot);                             -- takes it with cmd_init)
          if e_geo_done = '1' then
            if pinit(kj) = '1' then
              cmd_init <= '1';
              jfsm <= J_INIT;
            else
              cmd_go <= '1';
              jfsm <= J_WORD;
            end if;
          end if;
        when J_INIT =>
          if e_geo_done = '1' then
            ij_start <= '1';
            jfsm <= J_IJ;
          end if;
        when J_IJ =>
          if ij_done = '1' then
            cmd_go <= '1';
            jfsm <= J_WORD;
          end if;
        when J_WORD =>
          if e_res_valid = '1' then                      -- (ro_word, ro_id: the engine's, above)
            ro_valid <= '1';
            jfsm <= J_END;
          end if;
        when J_END =>
          if e_idle = '1' then                           -- its outcome pending the next clock (pw_m)
            pw_m <= j_oh;
            for i in 0 to NT - 1 loop
              if j_oh(i) = '1' then
                jdone(i) <= '1';
              end if;
            end loop;
            jfsm <= J_IDLE;
          end if;
      end case;
      -- the plan asks for the k-th oldest live target's state
      -- (two clocks: the slot, then its state)
      if st_req = '1' then
        st_slot <= lst(idx(st_index));
        st_pend <= '1';
      end if;
      if st_pend = '1' then
        k := idx(st_slot);
        st_w8 <= resize(w8_a(k), COORD_W + 8);
        st_h8 <= resize(h8_a(k), COORD_W + 8);
        st_c8x <= resize(c8x_a(k), COORD_W + CF);
        st_c8y <= resize(c8y_a(k), COORD_W + CF);
        st_lost <= recs(k)(1);
        st_valid_r <= '1';
        st_pend <= '0';
      end if;

      case fsm is
        ------------------------------------------------------------ between frames
        when S_IDLE =>
          if s_cmd_tvalid = '1' and open_in = '0' and ev_end = '0' and ev_err = '0' then
            cm_op <= s_cmd_op; cm_id <= s_cmd_id;        -- taken; carried out in the next clock
            cm_x <= s_cmd_x; cm_y <= s_cmd_y; cm_w <= s_cmd_w; cm_h <= s_cmd_h;
            cm_fw <= frame_width; cm_fh <= frame_height;
            kk := -1;                                    -- an add's slot: the lowest free one
            for i in NT - 1 downto 0 loop
              if alloc(i) = '0' then
                kk := i;
              end if;
            end loop;
            cm_full <= '1';
            cm_kk <= (others => '0');
            if kk >= 0 then
              cm_full <= '0';
              cm_kk <= to_unsigned(kk, 4);
            end if;
            for i in 0 to NT - 1 loop
              cm_add(i) <= '1' when s_cmd_op = '0' and i = kk else '0';
              cm_rm(i) <= '1' when s_cmd_op = '1' and to_integer(s_cmd_id) = i and alloc(i) = '1' else '0';
            end loop;
            fsm <= S_CMD;
          elsif ev_err = '1' then
            if jfsm = J_IDLE and jrun = '0' then         -- the failed frame's last job has ended
              ev_err <= '0';
              plan_ok <= '0';
              undo_checks;
              is_err <= '1';
              err_r <= ev_code;
              j <= 0;
              first_w <= '1';
              m := alloc and valid;
              out_mask <= m;
              om_any <= '1' when m /= (m'range => '0') else '0';
              rej_any <= rej_flag;
              if (rejd and not eacc) /= (rejd'range => '0') then
                rej_any <= '1';
              end if;
              fsm <= S_E_NEXT;
            end if;
          elsif ev_end = '1' then
            ev_end <= '0';
            fsm <= S_J_WAIT;
          elsif beat = '1' and s_axis_tuser = '1' then  -- planned, adds checked: the start of frame goes in
            arm_req <= '1';
            q_flush <= '1';
            plan_ok <= '0';
            eacc <= (others => '0');                     -- the verdicts hold
            chk_ok <= '0';
            fsm <= S_STREAM;
          elsif s_axis_tvalid = '1' and s_axis_tuser = '1' and fe_busy = '0' and jfsm = J_IDLE then
            if plan_ok = '1' and frame_width = pl_fw and frame_height = pl_fh then
              n_cnt <= n_ord - ones(waiting) - ones(eref);  -- planned: the adds left to check, the refusals
              j <= 0;
              pass_b <= chk_ok;
              chk_early <= '0';
              fsm <= S_ADDS;
            else
              j <= 0;
              n_live <= 0;
              early <= '0';
              pl_fw <= frame_width;
              pl_fh <= frame_height;
              fsm <= S_LIST;
            end if;
          elsif plan_ok = '0' and open_in = '0' and fe_busy = '0' and jfsm = J_IDLE then
            j <= 0;                                      -- the next frame's plan, in the blanking
            n_live <= 0;
            early <= '1';
            pl_fw <= frame_width;
            pl_fh <= frame_height;
            fsm <= S_LIST;
          elsif plan_ok = '1' and (frame_width /= pl_fw or frame_height /= pl_fh) then
            plan_ok <= '0';                              -- the frame size changed since the plan: plan again
          elsif plan_ok = '1' and (waiting /= (waiting'range => '0')
                                   or (pinit /= (pinit'range => '0') and chk_ok = '0'))
                and open_in = '0' and fe_busy = '0' and jfsm = J_IDLE then
            n_cnt <= n_ord - ones(waiting) - ones(eref);  -- the adds taken, checked in the blanking
            j <= 0;
            pass_b <= chk_ok;
            chk_early <= '1';
            fsm <= S_ADDS;
          end if;

        when S_CMD =>                                    -- the command taken in S_IDLE: its slot's registers
          done_r <= '1';
          fsm <= S_IDLE;
          if cm_op = '1' then                            -- remove
            id_r <= cm_id;
            code_r <= "01";
            plan_ok <= '0';                            -- the live targets change: plan again
            for i in 0 to NT - 1 loop                    -- (the record's clears: cm_rm, above)
              if cm_rm(i) = '1' then
                alloc(i) <= '0'; pend(i) <= '0'; waiting(i) <= '0'; pinit(i) <= '0'; valid(i) <= '0';
                rejd(i) <= '0'; held(i) <= '0'; eacc(i) <= '0'; eref(i) <= '0';
              end if;
            end loop;
            if cm_rm /= (cm_rm'range => '0') then
              code_r <= "00";
              drop_ord(cm_id);
            end if;
          else                                         -- add: the lowest free slot (its box: cm_add, above)
            if cm_full = '1' then
              code_r <= "01";
              id_r <= (others => '0');
              rej_flag <= '1';
            else
              for i in 0 to NT - 1 loop
                if cm_add(i) = '1' then
                  alloc(i) <= '1'; pend(i) <= '1'; waiting(i) <= '1';
                end if;
              end loop;
              ord(n_ord) <= cm_kk;
              n_ord <= n_ord + 1;
              code_r <= "00";
              id_r <= cm_kk;
            end if;
          end if;

        ------------------------------------------------------------ the frame's plan
        when S_LIST =>                                   -- the live targets in age order
          if j < n_ord and a_rd = '0' then               -- (two clocks an entry: its slot, then its flags)
            k_cur <= ord(j);
            a_rd <= '1';
          elsif j < n_ord then
            a_rd <= '0';
            k := idx(k_cur);
            if valid(k) = '1' and pinit(k) = '0' then
              lst(n_live) <= k_cur;
              n_live <= n_live + 1;
            end if;
            j <= j + 1;
          elsif pl_busy = '0' then
            held <= (others => '0');
            job <= (others => '0');
            undo_checks;
            pl_start <= '1';
            fsm <= S_PLAN;
          end if;

        when S_PLAN =>
          cap_slot <= resize(p_slot, SW);                -- the descriptor every clock, taken with cap_load
          cap_l2d <= p_l2d;                              -- (its enable is the state alone)
          cap_x0 <= shift_left(p_reg_x, idx(p_l2d));
          cap_y0 <= shift_left(p_reg_y, idx(p_l2d));
          cap_x1 <= shift_left(p_reg_x + resize(p_reg_w, COORD_W), idx(p_l2d));
          cap_y1 <= shift_left(p_reg_y + resize(p_reg_h, COORD_W), idx(p_l2d));
          if p_valid = '1' then
            k := idx(p_slot);
            if p_taken = '1' then
              job(k) <= '1';
              cap_load <= '1';
            else
              held(k) <= '1';
              hold_l2d(k) <= p_l2d;
            end if;
          end if;
          if plan_done = '1' and early = '1' then        -- planned in the blanking: wait for the frame
            early <= '0';
            plan_ok <= '1';
            fsm <= S_IDLE;
          elsif plan_done = '1' then
            n_cnt <= n_ord - ones(waiting);
            j <= 0;
            pass_b <= '0';
            chk_early <= '0';
            fsm <= S_ADDS;
          end if;

        when S_ADDS =>                                   -- the inits pending, then the adds waiting
          if j < n_ord and a_rd = '0' then               -- (two clocks an entry: its slot, then its flags)
            k_cur <= ord(j);
            a_rd <= '1';
          elsif j < n_ord then
            a_rd <= '0';
            k := idx(k_cur);
            refd := '0';                                 -- eref(k) (a loop: GHDL 2.0's synthesis failed on
            for i in 0 to NT - 1 loop                    -- the indexed read)
              if i = k and eref(i) = '1' then
                refd := '1';
              end if;
            end loop;
            if pass_b = '1' and refd = '1' and chk_early = '0' then
              fsm <= S_A_DROP;                           -- refused in the blanking: reported and freed now
            else
              if (pass_b = '0' and pinit(k) = '1') or (pass_b = '1' and waiting(k) = '1') then
                cmd_load <= '1';                           -- an empty record (j_ld is clear: c_state),
                c_model <= resize(k_cur, clog2(NT));       -- the target's model
                ini_slot <= k_cur;
                fsm <= S_A_LOAD;
              end if;
              j <= j + 1;
            end if;
          elsif pass_b = '0' then
            pass_b <= '1';
            j <= 0;
          elsif chk_early = '1' then                     -- checked in the blanking: wait for the frame
            chk_early <= '0';
            chk_ok <= '1';
            fsm <= S_IDLE;
          else
            fsm <= S_OPEN;
          end if;

        when S_A_DROP =>                                 -- an add refused in the blanking
          k := idx(k_cur);
          alloc(k) <= '0'; pend(k) <= '0';
          eref(k) <= '0';
          rej_flag <= '1';
          done_r <= '1';
          code_r <= "10";
          id_r <= k_cur;
          drop_ord(k_cur);                               -- the next entry moves into place j
          fsm <= S_ADDS;

        when S_A_LOAD =>                                 -- (the add's box: c_init_*, above)
          if e_geo_done = '1' then
            cmd_init <= '1';
            fsm <= S_A_INIT;
          end if;

        when S_A_INIT =>
          k := idx(k_cur);
          if e_init_rej = '1' then                       -- the engine refuses the box: reported by its word
            rejd(k) <= '1';
            waiting(k) <= '0';
            eacc(k) <= chk_early and pass_b;
            n_cnt <= n_cnt + 1;
            fsm <= S_ADDS;
          elsif e_geo_done = '1' then
            jc_start <= '1';
            fsm <= S_A_CLK;
          end if;

        when S_A_CLK =>
          if jc_done = '1' then
            a_clocks <= jc_clocks;
            if g_rel > resize(fh_a(idx(k_cur)), COORD_W + 1) then
              a_release <= fh_a(idx(k_cur));
            else
              a_release <= resize(g_rel, COORD_W);
            end if;
            a_next <= g_next;
            a_full <= '1' when n_cnt >= NT else '0';
            fsm <= S_A_OFFER;
          end if;

        when S_A_OFFER =>
          if a_ready = '1' then
            a_offer <= '1';
            fsm <= S_A_CODE;
          end if;

        when S_A_CODE =>
          cap_slot <= resize(k_cur, SW);                 -- the descriptor every clock, taken with cap_load
          cap_l2d <= l2d;
          cap_x0 <= g_x0; cap_y0 <= g_y0; cap_x1 <= g_x1; cap_y1 <= g_y1;
          if a_done = '1' then
            k := idx(k_cur);
            if a_code = "00" or pass_b = '0' then        -- accepted (an init pending keeps its verdict)
              pinit(k) <= '1';
              waiting(k) <= '0';
              job(k) <= '1';
              eacc(k) <= chk_early and pass_b;
              for i in 0 to NT - 1 loop                  -- its centre and size the next clock (ac_m)
                ac_m(i) <= '1' when i = k else '0';
              end loop;
              if pass_b = '1' then
                n_cnt <= n_cnt + 1;
              end if;
              cap_load <= '1';
            elsif chk_early = '1' then                   -- refused in the blanking: at the start of frame
              eref(k) <= '1';
              waiting(k) <= '0';
            else                                         -- refused: the slot is free again
              alloc(k) <= '0'; pend(k) <= '0'; waiting(k) <= '0';
              rej_flag <= '1';
              done_r <= '1';
              code_r <= "10";
              id_r <= k_cur;
              drop_ord(k_cur);
              j <= j - 1;                                -- the next entry moved into this place
            end if;
            fsm <= S_ADDS;
          end if;

        when S_OPEN =>                                   -- the start of frame goes in
          if beat = '1' then
            plan_ok <= '0';
            eacc <= (others => '0');                     -- the verdicts hold
            chk_ok <= '0';
            arm_req <= '1';
            q_flush <= '1';                              -- a cut frame's jobs not started are dropped
            fsm <= S_STREAM;
          end if;

        ------------------------------------------------------------ the frame
        when S_STREAM =>
          if ev_err = '1' then                           -- a stream fault: its error words (S_IDLE)
            fsm <= S_IDLE;
          elsif ev_end = '1' then
            ev_end <= '0';
            fsm <= S_J_WAIT;
          elsif open_in = '1' and s_axis_tvalid = '1' and s_axis_tuser = '1' then
            jrun <= '0';                                 -- a start of frame cuts this one: its jobs stop,
            arm_req <= '0';                              -- their outcomes are dropped (its fault comes)
            if jrun = '0' and jfsm = J_IDLE then
              cut_pend <= fe_busy;
              j <= 0;                                    -- the next frame's plan
              n_live <= 0;
              early <= '0';
              plan_ok <= '0';
              pl_fw <= frame_width;
              pl_fh <= frame_height;
              fsm <= S_LIST;
            end if;
          elsif open_in = '0' and fe_busy = '0' then     -- the frame was abandoned, its fault reported
            fsm <= S_IDLE;
          end if;

        when S_J_WAIT =>                                 -- every job of the frame has ended
          if arm_req = '0' and (runm and not jdone) = (runm'range => '0') and jfsm = J_IDLE then
            cmt_m <= jdone;                              -- the frame ended good: its jobs' states commit
            jrun <= '0';                                 -- in S_J_CMT (cmt_m, above)
            is_err <= '0';
            first_w <= '1';
            j <= 0;
            fsm <= S_J_CMT;
          end if;

        when S_J_CMT =>                                  -- the commit's clock
          fsm <= S_J_SZ;

        when S_J_SZ =>                                   -- the size flags of the committed sizes (sz_m):
          fsm <= S_J_NEXT;                               -- the walk reads after it

        when S_J_NEXT =>                                 -- slot j's word of the frame (side_w, above)
          if j = NT then
            if om_any = '0' then
              sgl <= '1';
              fsm <= S_SINGLE;
            elsif ro_close_ready = '1' then
              ro_close <= '1';                           -- (ro_mask: out_mask, above)
              fcount <= fcount + 1;
              rej_flag <= '0';
              fsm <= S_IDLE;
            end if;
          elsif pf_ok = '0' then
            pf_ok <= '1';                                -- slot j's reads
          else
            k_cur <= to_unsigned(j, 4);
            if pf_alloc = '0' then
              j <= j + 1;
            elsif (pf_valid = '1' or pf_pinit = '1') and pf_size = '1' then
              side_push <= pf_valid;                     -- side_w: the frame size's error word
              side_nt <= not pf_valid;
              fsm <= S_SIDE;
            elsif pf_held = '1' and pf_valid = '1' then  -- side_w: the capacity's error word
              side_push <= '1';
              side_nt <= '0';
              fsm <= S_SIDE;
            elsif pf_pinit = '1' or pf_valid = '1' then    -- the job's word and state are in
              fsm <= S_COMMIT;
            else                                         -- no target (a box the engine refused)
              side_push <= '0';
              side_nt <= '1';
              fsm <= S_SIDE;
            end if;
          end if;

        when S_COMMIT =>                                 -- a job's slot: tracking (a state of its own: GHDL
          k := idx(k_cur);                               -- 2.0's synthesis failed on writes under S_J_NEXT's
          valid(k) <= '1';                               -- elsif chain)
          pinit(k) <= '0';
          pend(k) <= '0';
          rejd(k) <= '0';
          first_w <= '0';
          j <= j + 1;
          fsm <= S_J_NEXT;

        when S_SIDE =>                                   -- a word of the top, and the slot's bookkeeping
          k := idx(k_cur);
          if side_push = '1' then                        -- (ro_word, ro_id: side_w and k_cur, above)
            ro_valid <= '1';
            first_w <= '0';
          end if;
          if pend(k) = '1' then
            if rejd(k) = '1' then                      -- the box was refused by the engine
              alloc(k) <= '0'; pend(k) <= '0';
              done_r <= '1';
              code_r <= "11";
              id_r <= k_cur;
              drop_ord(k_cur);
            elsif side_nt = '0' then
              pend(k) <= '0';
            end if;
          end if;
          rejd(k) <= '0';
          j <= j + 1;
          if is_err = '1' then
            fsm <= S_E_NEXT;
          else
            fsm <= S_J_NEXT;
          end if;

        ------------------------------------------------------------ a stream fault: one error word per live target
        when S_E_NEXT =>                                 -- (side_w, above)
          if j = NT then
            if om_any = '0' then
              sgl <= '1';
              fsm <= S_SINGLE;
            elsif ro_close_ready = '1' then
              ro_close <= '1';                           -- (ro_mask: out_mask, above)
              fcount <= fcount + 1;
              rej_flag <= '0';
              cut_pend <= '0';                           -- a cut frame's words are out: the next one's jobs
              if open_in = '1' or fe_busy = '1' then
                fsm <= S_STREAM;                         -- a frame streams (it cut the failed one)
              else
                fsm <= S_IDLE;
              end if;
            end if;
          elsif pf_ok = '0' then
            pf_ok <= '1';                                -- slot j's reads
          else
            k_cur <= to_unsigned(j, 4);
            side_push <= pf_alloc and pf_valid;
            side_nt <= not pf_valid;
            if pf_alloc = '0' then
              j <= j + 1;
            else
              fsm <= S_SIDE;
            end if;
          end if;

        when S_SINGLE =>                                 -- no live target: slot 0's word alone (side_w,
          k_cur <= (others => '0');                      -- above: sent from the second clock on)
          sg_ok <= '1';
          if ro_close_ready = '1' and sg_ok = '1' then
            if is_err = '1' then
              cut_pend <= '0';
            end if;
            sg_ok <= '0';
            sgl <= '0';
            ro_valid <= '1';
            ro_close <= '1';                             -- (ro_mask: slot 0, above)
            fcount <= fcount + 1;
            rej_flag <= '0';
            if is_err = '1' and (open_in = '1' or fe_busy = '1') then
              fsm <= S_STREAM;
            else
              fsm <= S_IDLE;
            end if;
          end if;
      end case;

      if rst = '1' then
        fsm <= S_IDLE;
        sgl <= '0';
        alloc <= (others => '0'); pend <= (others => '0'); waiting <= (others => '0');
        pinit <= (others => '0'); valid <= (others => '0'); rejd <= (others => '0');
        held <= (others => '0'); job <= (others => '0');
        j_ld <= (others => '0');
        c8x_a <= (others => (others => '0')); c8y_a <= (others => (others => '0'));
        w8_a <= (others => (others => '0')); h8_a <= (others => (others => '0'));
        n_ord <= 0;
        rej_flag <= '0';
        fcount <= (others => '0');
        ev_end <= '0';
        ev_err <= '0';
        jfsm <= J_IDLE;
        jrun <= '0';
        arm_req <= '0';
        cut_pend <= '0';
        plan_ok <= '0';
        early <= '0';
        eacc <= (others => '0');
        eref <= (others => '0');
        chk_ok <= '0';
        chk_early <= '0';
        a_rd <= '0';
        st_pend <= '0';
        runm <= (others => '0');
      end if;
    end if;
  end process;
end architecture;
