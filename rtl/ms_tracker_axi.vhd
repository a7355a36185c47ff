-- ms_tracker_axi: ms_tracker with an AXI4-Lite register interface and an interrupt (system top).
--
-- Wraps rtl/ms_tracker.vhd (unchanged) for a camera pipeline with a CPU beside it, either core:
-- generic PRESET 0 (default) the paper core, result word v1 (mstrack.fixed.vhdl_pkg.result_layout);
-- PRESET 1 core v2, result word v2 (result_layout_v2, 160 bits; PPC 1).  Every generic of ms_tracker
-- is passed through under the same name (`mstrack hdl config` writes them; RESULT_STREAM is this
-- entity's own); VERSION.result_version (1 or 2) and CONFIG.preset tell software which word it reads.
--   * video AXI4-Stream in (s_axis_*: PPC 24-bit RGB pixels per beat, pixel k at 24k+23 .. 24k
--     (generic PPC, passed to the core), tuser = start of frame, tlast = end of line),
--     passed to the core frame by frame: CTRL.enable is looked at on each start-of-frame beat; a
--     frame that starts while enable = 0 is consumed (tready = 1) and dropped whole (DROP_COUNT),
--     so the core never sees a partial frame; beats before the first start of frame are dropped;
--   * AXI4-Lite slave (s_axil_*, 32-bit data, 12-bit byte address = 4 KiB window): the register
--     block rtl/ms_tracker_regs.vhd, GENERATED from regs/ms_tracker_regs.rdl (docs/registers.md);
--     an unmapped address or a write to a read-only register answers SLVERR (bresp/rresp = "10"),
--     and the write changes nothing;
--   * frame size, init box (CMD.init: the box is copied at the write and offered on the core's
--     init port until taken, STATUS.init_pending), enable, status, counters (results, lost, error,
--     rejected, dropped frames; CMD.clear_counters), the last result and interrupts;
--   * the last result: latched whole in one clock when the core produces it (L); reading RES_HEAD
--     returns L's head and copies all of L into the snapshot S that RES_CX .. RES_RAW4 show, in the
--     same clock, so one frame's fields are read one by one without tearing (docs/integration.md);
--     the fields of the preset's word are decoded (v1: RES_CX .. RES_BOX; v2: RES_CX, RES_CY, rho in
--     RES_RHO_C, RES_W8, RES_H8, RES_CONF, RES_STATE), the other preset's registers read 0;
--   * STATUS.tracking and the lost / reacquired events: v1 from the flags (tracking: none of
--     no_target, lost, error); v2 from the status field (tracking: status ok, reacquired, init or
--     clipped, and neither no_target nor error, i.e. the box is trusted; lost: status lost, which is
--     exactly when the core sets flag lost; reacquired: status reacquired, v2 only);
--   * irq: high while an INT_STATUS bit (result / lost / error / reacquired; W1C) is set and enabled;
--   * m_axis_result_* (RESULT_STREAM = true): the core's result words as an AXI4-Stream (one beat
--     per frame, tlast = 1); its back-pressure reaches the video input through the core's result
--     FIFO.  RESULT_STREAM = false: tvalid = 0, tready ignored, results only through registers.
-- Latency    : the core's (docs/performance.md) + 1 clock to L; a register read answers in 2 clocks
--              after the address (PeakRDL regblock + AXI4-Lite adapter), 2 transactions in flight.
-- Throughput : the core's: PPC pixels per clock while a frame streams in.
-- Reset      : rst synchronous, active high (core and registers; every register to its reset value).
-- Cost       : over the core, logic only (no RAM, no multiplier): docs/blocks/ms_tracker_axi.md, Resources.
-- Multi-target cores (MAX_TARGETS >= 1; PRESET 1, PPC 1): ms_tracker_multi with MAX_TARGETS slots in place
-- of ms_tracker (docs/blocks/ms_tracker_multi.md): CMD.add (box INIT_POS / INIT_SIZE; CMD.init does the
-- same) and CMD.remove (TARGET.id) are copied at the write and offered to the core's command port until
-- taken (between frames); CMD_STATUS shows pending and the last report (code, id), INT_STATUS.command
-- fires on each report; MULTI shows MAX_TARGETS and the live slots.  The words of a frame (one per live
-- target, id at RESULT_W + 3 .. RESULT_W on m_axis_result) are latched by id as they come into a
-- collecting bank and copied, in the clock the frame's last word (tlast) comes, into the bank the registers
-- show (2 x MAX_TARGETS x 160 flip-flops), with RES_MASK (the ids with a word without flag no_target) and
-- its frame_count: RES_SEL.id chooses the target whose word RES_HEAD returns and snapshots, so every
-- target's word of one frame is read without tearing while the next frame's words come.
-- INT_STATUS.result fires once per frame (its last word); lost / error / reacquired are set in the same
-- clock when any word of that frame has them (one interrupt per frame tells the whole frame);
-- RESULT_COUNT counts frames, LOST / ERROR / REJECT_COUNT words.
-- SHARED_ENGINE = true: ms_tracker_shared in place of ms_tracker_multi (one engine runs every target's job,
-- docs/blocks/ms_tracker_shared.md), with the same ports and registers; MULTI.shared_engine reads 1, an add
-- can be refused at its frame by the capacity rule (a CMD_STATUS report with code 2, after the add's code 0),
-- and a live target can be held on a frame (its word's err_code 6).
-- Generics: those of ms_tracker (passed through; the derived widths come from
-- mstrack.fixed.vhdl_pkg.core_generics, core v2's from mstrack.hw.cosim.CoreConfigV2.tracker_generics)
-- MAX_TARGETS (0: single target), SHARED_ENGINE with ms_tracker_shared's own (RD_LAT .. C_SCALE) and RESULT_STREAM.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;
use work.ms_formats_pkg.all;
use work.ms_tracker_regs_pkg.all;

entity ms_tracker_axi is
  generic (
    PRESET         : natural := 0;               -- 0 the paper core (result word v1), 1 core v2 (result word v2)
    MAX_FRAME_W    : natural := 2048;            -- widest frame (line buffer depth)
    RGB_PACKING    : natural := 0;               -- s_axis_tdata layout (ms_tracker): 0 R G B, 1 AMD UG934 (R B G)
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
    ORIENT_T       : integer range -1 to 2047 := 64; -- PRESET 1: the joint colour x orientation bins: orient_T; -1 = off (mstrack-v2-colour)
    MAX_TARGETS    : natural range 0 to 16 := 0;  -- 0: one target (ms_tracker); 1 .. 16: the multi-target core's slots (PRESET 1)
    SHARED_ENGINE  : boolean := false;            -- MAX_TARGETS >= 1: false ms_tracker_multi (an engine per slot),
                                                  -- true ms_tracker_shared (one engine for every slot)
    -- SHARED_ENGINE only (ms_tracker_shared's; mstrack.hw.multi_core.shared_core_generics): the slot pool's
    -- read latency, the capacity rule's video timing and the plan's job-demand constants
    RD_LAT         : positive := 3;
    FRAME_LINES    : natural := 1125;            -- lines per frame, blanking included
    ACTIVE_LINES   : natural := 1080;
    LINE_CLOCKS    : natural := 2200;            -- clocks per line
    LC_W           : positive := 13;             -- bits of LINE_CLOCKS
    SUM_W          : positive := 28;
    CLK_W          : natural := 24;
    PLAN_REGION_W  : natural := 10;
    GROW_Q16       : natural := 6554;
    PASS_LAT       : natural := 10;
    M_TRACK        : natural := 21;
    C_TRACK        : natural := 13170;
    M_LOST         : natural := 54;
    C_LOST         : natural := 32375;
    C_INIT         : natural := 3534;
    SCALE_PERMILLE : natural := 50;
    C_SCALE        : natural := 2862;
    RESULT_STREAM  : boolean := true              -- true: m_axis_result_* carries each result word
  );
  port (
    clk                  : in  std_logic;                                -- core, register and pixel clock
    rst                  : in  std_logic;                                -- synchronous reset, active high
    -- AXI4-Lite slave (registers: docs/registers.md)
    s_axil_awvalid       : in  std_logic;                                -- write address valid
    s_axil_awready       : out std_logic;                                -- write address ready
    s_axil_awaddr        : in  std_logic_vector(11 downto 0);            -- write byte address
    s_axil_awprot        : in  std_logic_vector(2 downto 0);             -- ignored
    s_axil_wvalid        : in  std_logic;                                -- write data valid
    s_axil_wready        : out std_logic;                                -- write data ready
    s_axil_wdata         : in  std_logic_vector(31 downto 0);            -- write data
    s_axil_wstrb         : in  std_logic_vector(3 downto 0);             -- byte enables
    s_axil_bvalid        : out std_logic;                                -- write response valid
    s_axil_bready        : in  std_logic;                                -- write response ready
    s_axil_bresp         : out std_logic_vector(1 downto 0);             -- OKAY "00" / SLVERR "10"
    s_axil_arvalid       : in  std_logic;                                -- read address valid
    s_axil_arready       : out std_logic;                                -- read address ready
    s_axil_araddr        : in  std_logic_vector(11 downto 0);            -- read byte address
    s_axil_arprot        : in  std_logic_vector(2 downto 0);             -- ignored
    s_axil_rvalid        : out std_logic;                                -- read data valid
    s_axil_rready        : in  std_logic;                                -- read data ready
    s_axil_rdata         : out std_logic_vector(31 downto 0);            -- read data
    s_axil_rresp         : out std_logic_vector(1 downto 0);             -- OKAY "00" / SLVERR "10"
    -- video in
    s_axis_tdata         : in  std_logic_vector(24 * PPC - 1 downto 0);  -- PPC pixels, pixel k: R 24k+23:24k+16, G, B
    s_axis_tvalid        : in  std_logic;                                -- pixel valid
    s_axis_tready        : out std_logic;                                -- pixel accepted
    s_axis_tlast         : in  std_logic;                                -- last pixel of a line
    s_axis_tuser         : in  std_logic;                                -- first pixel of a frame
    -- result stream (RESULT_STREAM = true)
    m_axis_result_tdata  : out std_logic_vector(RESULT_W + 4 * minimum(MAX_TARGETS, 1) - 1 downto 0);  -- result word
                                                                         -- (result_layout / _v2; MAX_TARGETS >= 1: _multi)
    m_axis_result_tvalid : out std_logic;                                -- result valid
    m_axis_result_tready : in  std_logic;                                -- result taken
    m_axis_result_tlast  : out std_logic;                                -- 1 on a frame's last word (single target: always)
    -- interrupt
    irq                  : out std_logic                                 -- level, active high
  );
end entity;

architecture rtl of ms_tracker_axi is
  constant RAW_W  : natural := 160;                    -- raw result window RES_RAW0..4
  -- result word v1 fields (mstrack.fixed.vhdl_pkg.result_layout), LSB first
  constant O_CX   : natural := 0;
  constant O_CY   : natural := O_CX + CENTRE_ABS_W;
  constant O_RC   : natural := O_CY + CENTRE_ABS_W;
  constant O_RE   : natural := O_RC + RHO_OUT_W;
  constant O_AL   : natural := O_RE + RHO_OUT_W;
  constant O_IC   : natural := O_AL + ALPHA_W;
  constant O_IE   : natural := O_IC + ITER_W;
  constant O_SC   : natural := O_IE + ITER_W;
  constant O_SE   : natural := O_SC + 2;
  constant O_FL   : natural := O_SE + 2;
  constant O_EC   : natural := O_FL + 8;
  constant O_BW   : natural := O_EC + 3;
  constant O_BH   : natural := O_BW + WIN_W;
  constant O_FC   : natural := O_BH + WIN_W;
  constant F_LOST : natural := 2;                      -- RESULT_FLAGS indices
  constant F_ERR  : natural := 3;
  constant F_REJ  : natural := 4;
  constant F_NOT  : natural := 5;
  constant W_MAX  : natural := 2 ** COORD_W - 1;
  -- result word v2 fields (mstrack.fixed.vhdl_pkg.result_layout_v2), LSB first (PRESET 1)
  constant CONF_W : natural := 17;                     -- Q1.16 (vhdl_pkg.CONF_W)
  constant V_CX   : natural := 0;
  constant V_CY   : natural := V_CX + CENTRE_ABS_W;
  constant V_W8   : natural := V_CY + CENTRE_ABS_W;
  constant V_H8   : natural := V_W8 + SIZE_W;
  constant V_RHO  : natural := V_H8 + SIZE_W;
  constant V_CONF : natural := V_RHO + RHO_OUT_W;
  constant V_ST   : natural := V_CONF + CONF_W;
  constant V_IT   : natural := V_ST + 3;
  constant V_SP   : natural := V_IT + ITER_W;
  constant V_DL   : natural := V_SP + 2;
  constant V_SR   : natural := V_DL + 3;
  constant V_FL   : natural := V_SR + 4;
  constant V_EC   : natural := V_FL + 8;
  constant V_FC   : natural := V_EC + 3;
  -- status codes of result word v2 (vhdl_pkg.STATUS_V2)
  constant ST_OK    : natural := 0;
  constant ST_UNC   : natural := 1;
  constant ST_LOST  : natural := 2;
  constant ST_REACQ : natural := 3;
  constant ST_INIT  : natural := 4;
  constant ST_CLIP  : natural := 5;

  signal hw_in    : ms_tracker_regs_in_t;
  signal hw_out   : ms_tracker_regs_out_t;
  -- video gate
  signal pass_r   : std_logic := '0';                  -- the frame in progress goes to the core
  signal sof_held : std_logic := '0';                  -- a start-of-frame beat waits; its route is fixed
  signal sof_rt   : std_logic := '0';
  signal route    : std_logic;                         -- where the current beat goes (1: core)
  signal c_tvalid, c_tready : std_logic;
  signal drop_sof : std_logic;
  -- init
  signal init_v   : std_logic := '0';
  signal init_rdy : std_logic;
  signal ib_x, ib_y : signed(COORD_W + 1 downto 0) := (others => '0');
  signal ib_w, ib_h : unsigned(COORD_W downto 0) := (others => '0');
  -- results
  constant MULTI_W : natural := RESULT_W + 4 * minimum(MAX_TARGETS, 1);
  signal r_data   : std_logic_vector(MULTI_W - 1 downto 0);                   -- the core's word (multi: with id)
  signal r_valid, r_ready, r_take, r_last : std_logic;
  signal r_id     : natural range 0 to 15;                                     -- target id of r_data (multi)
  signal r_word   : std_logic_vector(RAW_W - 1 downto 0);                      -- r_data, zero-extended
  signal w_lost, w_err, w_rej, w_reacq : std_logic;                           -- events of r_word
  signal lat      : std_logic_vector(RAW_W - 1 downto 0) := (others => '0');   -- L (multi: RES_SEL's word)
  signal snap     : std_logic_vector(RAW_W - 1 downto 0) := (others => '0');   -- S
  signal lat_ok   : std_logic := '0';
  signal head_id  : std_logic_vector(3 downto 0);                              -- target id of L (multi)
  -- commands (multi)
  signal cmd_v    : std_logic := '0';                  -- a command offered to the core
  signal cmd_wait : std_logic := '0';                  -- taken, its report not yet come
  signal cmd_op   : std_logic := '0';                  -- 0 add, 1 remove
  signal cmd_tid  : unsigned(3 downto 0) := (others => '0');
  signal cmd_rdy, cmd_done : std_logic;
  signal cmd_code : unsigned(1 downto 0);
  signal cmd_rid  : unsigned(3 downto 0);
  signal ev_cmd   : std_logic := '0';
  signal st_code  : std_logic_vector(1 downto 0) := (others => '0');
  signal st_id    : std_logic_vector(3 downto 0) := (others => '0');
  signal st_count : unsigned(15 downto 0) := (others => '0');
  signal live     : std_logic_vector(15 downto 0) := (others => '0');
  signal vis_mask : std_logic_vector(15 downto 0) := (others => '0');
  signal vis_fc   : std_logic_vector(15 downto 0) := (others => '0');
  signal ev_res, ev_lost, ev_err, ev_rej, ev_reacq : std_logic := '0';    -- per word (ev_res: per frame)
  signal acc_lost, acc_err, acc_reacq : std_logic := '0';                   -- events of the frame's earlier words
  signal fr_lost, fr_err, fr_reacq : std_logic := '0';                      -- events of the frame, with ev_res
  signal busy     : std_logic;
  signal fw, fh   : unsigned(COORD_W - 1 downto 0);

  function sat_u(v : std_logic_vector; w : natural) return unsigned is
  begin
    if unsigned(v) > 2 ** w - 1 then
      return to_unsigned(2 ** w - 1, w);
    end if;
    return resize(unsigned(v), w);
  end function;

  function sat_s(v : std_logic_vector; w : natural) return signed is
    variable s : integer := to_integer(signed(v));
  begin
    if s > 2 ** (w - 1) - 1 then
      return to_signed(2 ** (w - 1) - 1, w);
    elsif s < -(2 ** (w - 1)) then
      return to_signed(-(2 ** (w - 1)), w);
    end if;
    return to_signed(s, w);
  end function;

  function fld(v : std_logic_vector; off, w, n : natural) return std_logic_vector is
  begin
    return std_logic_vector(resize(unsigned(v(off + w - 1 downto off)), n));
  end function;
begin
  assert RESULT_W <= RAW_W report "ms_tracker_axi: RESULT_W > 160 does not fit RES_RAW0..4" severity failure;
  assert CENTRE_ABS_W <= 32 and RHO_OUT_W <= 32 and ALPHA_W <= 32 and ITER_W <= 8 and WIN_W <= 16
    report "ms_tracker_axi: a result field is wider than its register field" severity failure;
  assert PRESET /= 0 or O_FC + 16 <= RESULT_W report "ms_tracker_axi: result layout and RESULT_W disagree" severity failure;
  assert PRESET = 0 or (V_FC + 16 <= RESULT_W and SIZE_W <= 32)
    report "ms_tracker_axi: result layout v2 and RESULT_W disagree" severity failure;
  assert COORD_W + 2 <= 16 report "ms_tracker_axi: init box registers are 16 bits" severity failure;
  assert MAX_TARGETS = 0 or (PRESET = 1 and PPC = 1)
    report "ms_tracker_axi: MAX_TARGETS >= 1 (ms_tracker_multi, ms_tracker_shared) needs PRESET 1 and PPC 1" severity failure;

  ---------------------------------------------------------------------------- registers
  u_regs : entity work.ms_tracker_regs
    port map (
      clk => clk, rst => rst,
      s_axil_awready => s_axil_awready, s_axil_awvalid => s_axil_awvalid, s_axil_awaddr => s_axil_awaddr,
      s_axil_awprot => s_axil_awprot, s_axil_wready => s_axil_wready, s_axil_wvalid => s_axil_wvalid,
      s_axil_wdata => s_axil_wdata, s_axil_wstrb => s_axil_wstrb, s_axil_bready => s_axil_bready,
      s_axil_bvalid => s_axil_bvalid, s_axil_bresp => s_axil_bresp, s_axil_arready => s_axil_arready,
      s_axil_arvalid => s_axil_arvalid, s_axil_araddr => s_axil_araddr, s_axil_arprot => s_axil_arprot,
      s_axil_rready => s_axil_rready, s_axil_rvalid => s_axil_rvalid, s_axil_rdata => s_axil_rdata,
      s_axil_rresp => s_axil_rresp, hwif_in => hw_in, hwif_out => hw_out);

  -- identification and build-time configuration
  hw_in.VERSION.result_version.next_q <= x"1" when PRESET = 0 else x"2";
  hw_in.VERSION.result_width.next_q   <= std_logic_vector(to_unsigned(RESULT_W, 8));
  hw_in.CONFIG.features.next_q        <= std_logic_vector(to_unsigned(FEATURES, 2));
  hw_in.CONFIG.kernel_epan.next_q     <= '1' when KERNEL_EPAN /= 0 else '0';
  hw_in.CONFIG.result_stream.next_q   <= '1' when RESULT_STREAM else '0';
  hw_in.CONFIG.preset.next_q          <= std_logic_vector(to_unsigned(PRESET, 2));
  hw_in.CONFIG.lanes.next_q           <= std_logic_vector(to_unsigned(LANES, 8));
  hw_in.CONFIG.max_half.next_q        <= std_logic_vector(to_unsigned(MAX_HALF, 16));
  -- core v2's tracker variant (map minor 2): PRESET 0 has neither the joint bins nor the scale test
  hw_in.CONFIG_V2.orient_on.next_q    <= '1' when PRESET /= 0 and ORIENT_T >= 0 else '0';
  hw_in.CONFIG_V2.orient_t.next_q     <= std_logic_vector(to_unsigned(maximum(ORIENT_T, 0), 11))
                                         when PRESET /= 0 and ORIENT_T >= 0 else (others => '0');
  hw_in.CONFIG_V2.scale_test_d256.next_q <= std_logic_vector(to_unsigned(SCALE_TEST_D256, 8))
                                            when PRESET /= 0 else (others => '0');
  hw_in.FORMAT.max_frame_w.next_q     <= std_logic_vector(to_unsigned(MAX_FRAME_W, 16));
  hw_in.FORMAT.centre_frac.next_q     <= std_logic_vector(to_unsigned(CF, 4));
  hw_in.FORMAT.rho_frac.next_q        <= std_logic_vector(to_unsigned(RHO_OUT_FRAC, 5));
  hw_in.FORMAT.alpha_frac.next_q      <= std_logic_vector(to_unsigned(AF, 5));

  -- status
  hw_in.STATUS.init_pending.next_q <= init_v;
  hw_in.STATUS.busy.next_q         <= busy;
  hw_in.STATUS.gate_open.next_q    <= pass_r;
  hw_in.STATUS.result_valid.next_q <= lat_ok;

  -- interrupts (level inputs of sticky intr fields: a one-clock pulse sets the bit) and counters
  -- (lost / error / reacquired with the frame's result: the events of all its words, set in the clock
  -- the result bit is set, so one interrupt tells the whole frame; the counters count words)
  hw_in.INT_STATUS.result.next_q <= ev_res;
  hw_in.INT_STATUS.lost.next_q   <= ev_res and fr_lost;
  hw_in.INT_STATUS.error.next_q  <= ev_res and fr_err;
  hw_in.INT_STATUS.reacquired.next_q <= ev_res and fr_reacq;
  hw_in.INT_STATUS.command.next_q <= ev_cmd;
  irq <= hw_out.INT_STATUS.intr;
  hw_in.RESULT_COUNT.count.incr <= ev_res;
  hw_in.LOST_COUNT.count.incr   <= ev_lost;
  hw_in.ERROR_COUNT.count.incr  <= ev_err;
  hw_in.REJECT_COUNT.count.incr <= ev_rej;
  hw_in.DROP_COUNT.count.incr   <= drop_sof;

  -- last result: head from L, the rest from the snapshot S; the fields of the preset's word
  g_v1 : if PRESET = 0 generate
    -- tracking: the last result has none of the flags no_target, lost, error
    hw_in.STATUS.tracking.next_q      <= lat_ok and not (lat(O_FL + F_NOT) or lat(O_FL + F_LOST) or lat(O_FL + F_ERR));
    w_lost  <= r_word(O_FL + F_LOST);
    w_err   <= r_word(O_FL + F_ERR);
    w_rej   <= r_word(O_FL + F_REJ);
    w_reacq <= '0';
    hw_in.RES_HEAD.frame_count.next_q <= fld(lat, O_FC, 16, 16);
    hw_in.RES_HEAD.flags.next_q       <= fld(lat, O_FL, 8, 8);
    hw_in.RES_HEAD.err_code.next_q    <= fld(lat, O_EC, 3, 3);
    hw_in.RES_CX.value.next_q         <= fld(snap, O_CX, CENTRE_ABS_W, 32);
    hw_in.RES_CY.value.next_q         <= fld(snap, O_CY, CENTRE_ABS_W, 32);
    hw_in.RES_RHO_C.value.next_q      <= fld(snap, O_RC, RHO_OUT_W, 32);
    hw_in.RES_RHO_E.value.next_q      <= fld(snap, O_RE, RHO_OUT_W, 32);
    hw_in.RES_ALPHA.value.next_q      <= fld(snap, O_AL, ALPHA_W, 32);
    hw_in.RES_ITER.iter_c.next_q      <= fld(snap, O_IC, ITER_W, 8);
    hw_in.RES_ITER.iter_e.next_q      <= fld(snap, O_IE, ITER_W, 8);
    hw_in.RES_ITER.stop_c.next_q      <= fld(snap, O_SC, 2, 2);
    hw_in.RES_ITER.stop_e.next_q      <= fld(snap, O_SE, 2, 2);
    hw_in.RES_BOX.box_w.next_q        <= fld(snap, O_BW, WIN_W, 16);
    hw_in.RES_BOX.box_h.next_q        <= fld(snap, O_BH, WIN_W, 16);
    hw_in.RES_W8.value.next_q         <= (others => '0');
    hw_in.RES_H8.value.next_q         <= (others => '0');
    hw_in.RES_CONF.value.next_q       <= (others => '0');
    hw_in.RES_STATE.status.next_q     <= (others => '0');
    hw_in.RES_STATE.iter.next_q       <= (others => '0');
    hw_in.RES_STATE.stop.next_q       <= (others => '0');
    hw_in.RES_STATE.decim_log2.next_q <= (others => '0');
    hw_in.RES_STATE.searched.next_q   <= (others => '0');
  end generate;

  g_v2 : if PRESET /= 0 generate
    signal st_lat, st_new : natural range 0 to 7;
  begin
    -- result word v2: the status says what the frame is (STATUS_V2); the core sets flag lost exactly
    -- for status lost, flag error with status error, no_target (status 0) before any init.
    -- tracking: the box of the last result is trusted (TrackResult.ok): status ok, reacquired, init or
    -- clipped, and neither no_target nor error; uncertain (the loss flag is up, search state not lost)
    -- and lost are not tracking
    st_lat <= to_integer(unsigned(lat(V_ST + 2 downto V_ST)));
    st_new <= to_integer(unsigned(r_word(V_ST + 2 downto V_ST)));
    hw_in.STATUS.tracking.next_q <= lat_ok and not (lat(V_FL + F_NOT) or lat(V_FL + F_ERR))
                                    when st_lat = ST_OK or st_lat = ST_REACQ or st_lat = ST_INIT or st_lat = ST_CLIP
                                    else '0';
    w_lost  <= '1' when st_new = ST_LOST else '0';
    w_reacq <= '1' when st_new = ST_REACQ else '0';
    w_err   <= r_word(V_FL + F_ERR);
    w_rej   <= r_word(V_FL + F_REJ);
    hw_in.RES_HEAD.frame_count.next_q <= fld(lat, V_FC, 16, 16);
    hw_in.RES_HEAD.flags.next_q       <= fld(lat, V_FL, 8, 8);
    hw_in.RES_HEAD.err_code.next_q    <= fld(lat, V_EC, 3, 3);
    hw_in.RES_CX.value.next_q         <= fld(snap, V_CX, CENTRE_ABS_W, 32);
    hw_in.RES_CY.value.next_q         <= fld(snap, V_CY, CENTRE_ABS_W, 32);
    hw_in.RES_RHO_C.value.next_q      <= fld(snap, V_RHO, RHO_OUT_W, 32);
    hw_in.RES_RHO_E.value.next_q      <= (others => '0');
    hw_in.RES_ALPHA.value.next_q      <= (others => '0');
    hw_in.RES_ITER.iter_c.next_q      <= (others => '0');
    hw_in.RES_ITER.iter_e.next_q      <= (others => '0');
    hw_in.RES_ITER.stop_c.next_q      <= (others => '0');
    hw_in.RES_ITER.stop_e.next_q      <= (others => '0');
    hw_in.RES_BOX.box_w.next_q        <= (others => '0');
    hw_in.RES_BOX.box_h.next_q        <= (others => '0');
    hw_in.RES_W8.value.next_q         <= fld(snap, V_W8, SIZE_W, 32);
    hw_in.RES_H8.value.next_q         <= fld(snap, V_H8, SIZE_W, 32);
    hw_in.RES_CONF.value.next_q       <= fld(snap, V_CONF, CONF_W, 32);
    hw_in.RES_STATE.status.next_q     <= fld(snap, V_ST, 3, 3);
    hw_in.RES_STATE.iter.next_q       <= fld(snap, V_IT, ITER_W, 8);
    hw_in.RES_STATE.stop.next_q       <= fld(snap, V_SP, 2, 2);
    hw_in.RES_STATE.decim_log2.next_q <= fld(snap, V_DL, 3, 3);
    hw_in.RES_STATE.searched.next_q   <= fld(snap, V_SR, 4, 4);
  end generate;
  hw_in.RES_HEAD.valid.next_q       <= lat_ok;
  hw_in.RES_HEAD.target_id.next_q   <= head_id;
  -- multi-target registers (single target: 0)
  hw_in.MULTI.max_targets.next_q    <= std_logic_vector(to_unsigned(MAX_TARGETS, 5));
  hw_in.MULTI.shared_engine.next_q  <= '1' when SHARED_ENGINE and MAX_TARGETS > 0 else '0';
  hw_in.MULTI.live.next_q           <= live;
  hw_in.CMD_STATUS.pending.next_q   <= cmd_v or cmd_wait;
  hw_in.CMD_STATUS.code.next_q      <= st_code;
  hw_in.CMD_STATUS.id.next_q        <= st_id;
  hw_in.CMD_STATUS.reports.next_q   <= std_logic_vector(st_count);
  hw_in.RES_MASK.mask.next_q        <= vis_mask;
  hw_in.RES_MASK.frame_count.next_q <= vis_fc;
  hw_in.RES_RAW0.value.next_q       <= snap(31 downto 0);
  hw_in.RES_RAW1.value.next_q       <= snap(63 downto 32);
  hw_in.RES_RAW2.value.next_q       <= snap(95 downto 64);
  hw_in.RES_RAW3.value.next_q       <= snap(127 downto 96);
  hw_in.RES_RAW4.value.next_q       <= snap(159 downto 128);

  ---------------------------------------------------------------------------- video gate
  -- route of the current beat: a start-of-frame beat takes CTRL.enable (fixed once it waits),
  -- any other beat follows its frame
  route <= pass_r when s_axis_tuser = '0' else
           sof_rt when sof_held = '1' else
           hw_out.CTRL.enable.value;
  c_tvalid <= s_axis_tvalid and route;
  s_axis_tready <= c_tready when route = '1' else '1';
  drop_sof <= s_axis_tvalid and s_axis_tuser and not route;

  p_gate : process(clk)
  begin
    if rising_edge(clk) then
      if s_axis_tvalid = '1' and s_axis_tuser = '1' then
        if route = '0' or c_tready = '1' then        -- the start-of-frame beat is taken
          pass_r   <= route;
          sof_held <= '0';
        else
          sof_held <= '1';
          sof_rt   <= route;
        end if;
      end if;
      if rst = '1' then
        pass_r   <= '0';
        sof_held <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- frame size, init
  fw <= sat_u(hw_out.FRAME_SIZE.width.value, COORD_W);
  fh <= sat_u(hw_out.FRAME_SIZE.height.value, COORD_W);

  p_init : process(clk)
  begin
    if rising_edge(clk) then
      if init_v = '1' and init_rdy = '1' then
        init_v <= '0';
      end if;
      -- copy the box; the latest command wins (multi-target: CMD.add too)
      if hw_out.CMD.init.value = '1' or (MAX_TARGETS > 0 and hw_out.CMD.add.value = '1') then
        ib_x   <= sat_s(hw_out.INIT_POS.x.value, COORD_W + 2);
        ib_y   <= sat_s(hw_out.INIT_POS.y.value, COORD_W + 2);
        ib_w   <= sat_u(hw_out.INIT_SIZE.width.value, COORD_W + 1);
        ib_h   <= sat_u(hw_out.INIT_SIZE.height.value, COORD_W + 1);
        init_v <= '1' when MAX_TARGETS = 0 else '0';
      end if;
      if rst = '1' then
        init_v <= '0';
      end if;
    end if;
  end process;

  ---------------------------------------------------------------------------- core
  g_core1 : if MAX_TARGETS = 0 generate
    u_core : entity work.ms_tracker
      generic map (
        PRESET         => PRESET,
        MAX_FRAME_W    => MAX_FRAME_W,
        RGB_PACKING    => RGB_PACKING,
        PPC            => PPC,
        LANES          => LANES,
        COLOUR_BITS    => COLOUR_BITS,
        EDGE_BINS_LOG2 => EDGE_BINS_LOG2,
        EDGE_SHIFT     => EDGE_SHIFT,
        FEATURES       => FEATURES,
        KERNEL_EPAN    => KERNEL_EPAN,
        KERNEL_BITS    => KERNEL_BITS,
        MAX_HALF       => MAX_HALF,
        MARGIN         => MARGIN,
        COORD_W        => COORD_W,
        CF             => CF,
        WI             => WI,
        WF             => WF,
        RF             => RF,
        AF             => AF,
        RHO_OUT_FRAC   => RHO_OUT_FRAC,
        MAX_ITER       => MAX_ITER,
        EPS2           => EPS2,
        HALF_W         => HALF_W,
        REGION_MAX     => REGION_MAX,
        REGION_W       => REGION_W,
        STRIDE         => STRIDE,
        ADDR_W         => ADDR_W,
        KVAL_W         => KVAL_W,
        HIST_W         => HIST_W,
        COUNT_W        => COUNT_W,
        POSSUM_W       => POSSUM_W,
        KD_W           => KD_W,
        SQRT_IN_W      => SQRT_IN_W,
        RHO_SUM_W      => RHO_SUM_W,
        RATIO_Q_W      => RATIO_Q_W,
        WEIGHT_W       => WEIGHT_W,
        SW_W           => SW_W,
        SWX_W          => SWX_W,
        SHIFT_Q_W      => SHIFT_Q_W,
        CENTRE_W       => CENTRE_W,
        CENTRE_ABS_W   => CENTRE_ABS_W,
        ITER_W         => ITER_W,
        RHO_OUT_W      => RHO_OUT_W,
        ALPHA_W        => ALPHA_W,
        WIN_W          => WIN_W,
        RESULT_W       => RESULT_W,
        PAD16          => PAD16,
        RING16         => RING16,
        MAX_WINDOW     => MAX_WINDOW,
        KT_W           => KT_W,
        ST2_W          => ST2_W,
        SHARE_W        => SHARE_W,
        SPREAD_W       => SPREAD_W,
        SIZE_W         => SIZE_W,
        SCALE_W        => SCALE_W,
        SCALE_GAIN     => SCALE_GAIN,
        SCALE_REG      => SCALE_REG,
        SCALE_STEP     => SCALE_STEP,
        SCALE_RATIO_Q_W=> SCALE_RATIO_Q_W,
        WR_Q_W         => WR_Q_W,
        CON_W          => CON_W,
        LOSS_K         => LOSS_K,
        REF_K          => REF_K,
        LOSS_RHO       => LOSS_RHO,
        LOSS_CONTRAST  => LOSS_CONTRAST,
        CONF_LOST      => CONF_LOST,
        CONF_UNCERTAIN => CONF_UNCERTAIN,
        CONF_REACQUIRE => CONF_REACQUIRE,
        SPREAD_DEFAULT => SPREAD_DEFAULT,
        BG_Q_W         => BG_Q_W,
        BG_O_W         => BG_O_W,
        SEARCH_ITER    => SEARCH_ITER,
        STEP16         => STEP16,
        MARGIN_MAX     => MARGIN_MAX,
        SCALE_TEST_D256=> SCALE_TEST_D256,
        ORIENT_T       => ORIENT_T
      )
      port map (
        clk => clk, rst => rst, frame_width => fw, frame_height => fh,
        s_init_tvalid => init_v, s_init_tready => init_rdy,
        s_init_x => ib_x, s_init_y => ib_y, s_init_w => ib_w, s_init_h => ib_h,
        s_axis_tdata => s_axis_tdata, s_axis_tvalid => c_tvalid, s_axis_tready => c_tready,
        s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
        m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
        m_axis_result_tready => r_ready, m_axis_result_tlast => open,
        busy => busy);
    r_id   <= 0;
    r_last <= '1';
    cmd_rdy  <= '0';
    cmd_done <= '0';
    cmd_code <= (others => '0');
    cmd_rid  <= (others => '0');
    cmd_v    <= '0';
    cmd_wait <= '0';
    cmd_op   <= '0';
    cmd_tid  <= (others => '0');
    ev_cmd   <= '0';
    st_code  <= (others => '0');
    st_id    <= (others => '0');
    st_count <= (others => '0');
    live     <= (others => '0');
    vis_mask <= (others => '0');
    vis_fc   <= (others => '0');
    head_id  <= (others => '0');

    p_lat : process(clk)
    begin
      if rising_edge(clk) then
        if r_take = '1' then                         -- L: the whole word in one clock
          lat    <= r_word;
          lat_ok <= '1';
        end if;
        if rst = '1' then
          lat    <= (others => '0');
          lat_ok <= '0';
        end if;
      end if;
    end process;
  end generate;

  g_coreN : if MAX_TARGETS > 0 generate
    type bank_t is array (0 to MAX_TARGETS - 1) of std_logic_vector(RAW_W - 1 downto 0);
    signal coll, vis : bank_t := (others => (others => '0'));   -- the frame's words as they come / shown
    signal coll_m    : std_logic_vector(MAX_TARGETS - 1 downto 0) := (others => '0');
    signal vis_ok    : std_logic := '0';                         -- a frame has completed since reset
    signal live_n    : std_logic_vector(MAX_TARGETS - 1 downto 0);
    signal sel       : natural range 0 to 15;
  begin
    g_multi : if not SHARED_ENGINE generate
      u_core : entity work.ms_tracker_multi
        generic map (
          MAX_TARGETS    => MAX_TARGETS,
          MAX_FRAME_W    => MAX_FRAME_W,
          RGB_PACKING    => RGB_PACKING,
          LANES          => LANES,
          COLOUR_BITS    => COLOUR_BITS,
          EDGE_BINS_LOG2 => EDGE_BINS_LOG2,
          EDGE_SHIFT     => EDGE_SHIFT,
          FEATURES       => FEATURES,
          KERNEL_EPAN    => KERNEL_EPAN,
          KERNEL_BITS    => KERNEL_BITS,
          MAX_HALF       => MAX_HALF,
          MARGIN         => MARGIN,
          COORD_W        => COORD_W,
          CF             => CF,
          WI             => WI,
          WF             => WF,
          RF             => RF,
          AF             => AF,
          RHO_OUT_FRAC   => RHO_OUT_FRAC,
          MAX_ITER       => MAX_ITER,
          EPS2           => EPS2,
          HALF_W         => HALF_W,
          REGION_MAX     => REGION_MAX,
          REGION_W       => REGION_W,
          STRIDE         => STRIDE,
          ADDR_W         => ADDR_W,
          KVAL_W         => KVAL_W,
          HIST_W         => HIST_W,
          COUNT_W        => COUNT_W,
          POSSUM_W       => POSSUM_W,
          KD_W           => KD_W,
          SQRT_IN_W      => SQRT_IN_W,
          RHO_SUM_W      => RHO_SUM_W,
          RATIO_Q_W      => RATIO_Q_W,
          WEIGHT_W       => WEIGHT_W,
          SW_W           => SW_W,
          SWX_W          => SWX_W,
          SHIFT_Q_W      => SHIFT_Q_W,
          CENTRE_W       => CENTRE_W,
          CENTRE_ABS_W   => CENTRE_ABS_W,
          ITER_W         => ITER_W,
          RHO_OUT_W      => RHO_OUT_W,
          ALPHA_W        => ALPHA_W,
          WIN_W          => WIN_W,
          RESULT_W       => RESULT_W,
          PAD16          => PAD16,
          RING16         => RING16,
          MAX_WINDOW     => MAX_WINDOW,
          KT_W           => KT_W,
          ST2_W          => ST2_W,
          SHARE_W        => SHARE_W,
          SPREAD_W       => SPREAD_W,
          SIZE_W         => SIZE_W,
          SCALE_W        => SCALE_W,
          SCALE_GAIN     => SCALE_GAIN,
          SCALE_REG      => SCALE_REG,
          SCALE_STEP     => SCALE_STEP,
          SCALE_RATIO_Q_W=> SCALE_RATIO_Q_W,
          WR_Q_W         => WR_Q_W,
          CON_W          => CON_W,
          LOSS_K         => LOSS_K,
          REF_K          => REF_K,
          LOSS_RHO       => LOSS_RHO,
          LOSS_CONTRAST  => LOSS_CONTRAST,
          CONF_LOST      => CONF_LOST,
          CONF_UNCERTAIN => CONF_UNCERTAIN,
          CONF_REACQUIRE => CONF_REACQUIRE,
          SPREAD_DEFAULT => SPREAD_DEFAULT,
          BG_Q_W         => BG_Q_W,
          BG_O_W         => BG_O_W,
          SEARCH_ITER    => SEARCH_ITER,
          STEP16         => STEP16,
          MARGIN_MAX     => MARGIN_MAX,
          SCALE_TEST_D256=> SCALE_TEST_D256,
          ORIENT_T       => ORIENT_T
        )
        port map (
          clk => clk, rst => rst, frame_width => fw, frame_height => fh,
          s_cmd_tvalid => cmd_v, s_cmd_tready => cmd_rdy, s_cmd_op => cmd_op, s_cmd_id => cmd_tid,
          s_cmd_x => ib_x, s_cmd_y => ib_y, s_cmd_w => ib_w, s_cmd_h => ib_h,
          cmd_done => cmd_done, cmd_code => cmd_code, cmd_id => cmd_rid,
          s_axis_tdata => s_axis_tdata, s_axis_tvalid => c_tvalid, s_axis_tready => c_tready,
          s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
          m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
          m_axis_result_tready => r_ready, m_axis_result_tlast => r_last,
          live => live_n, busy => busy);
    end generate;
    g_shared : if SHARED_ENGINE generate
      u_core : entity work.ms_tracker_shared
        generic map (
          MAX_TARGETS    => MAX_TARGETS,
          MAX_FRAME_W    => MAX_FRAME_W,
          RGB_PACKING    => RGB_PACKING,
          LANES          => LANES,
          COLOUR_BITS    => COLOUR_BITS,
          EDGE_BINS_LOG2 => EDGE_BINS_LOG2,
          EDGE_SHIFT     => EDGE_SHIFT,
          FEATURES       => FEATURES,
          KERNEL_EPAN    => KERNEL_EPAN,
          KERNEL_BITS    => KERNEL_BITS,
          MAX_HALF       => MAX_HALF,
          MARGIN         => MARGIN,
          COORD_W        => COORD_W,
          CF             => CF,
          WI             => WI,
          WF             => WF,
          RF             => RF,
          AF             => AF,
          RHO_OUT_FRAC   => RHO_OUT_FRAC,
          MAX_ITER       => MAX_ITER,
          EPS2           => EPS2,
          HALF_W         => HALF_W,
          REGION_MAX     => REGION_MAX,
          REGION_W       => REGION_W,
          STRIDE         => STRIDE,
          ADDR_W         => ADDR_W,
          KVAL_W         => KVAL_W,
          HIST_W         => HIST_W,
          COUNT_W        => COUNT_W,
          POSSUM_W       => POSSUM_W,
          KD_W           => KD_W,
          SQRT_IN_W      => SQRT_IN_W,
          RHO_SUM_W      => RHO_SUM_W,
          RATIO_Q_W      => RATIO_Q_W,
          WEIGHT_W       => WEIGHT_W,
          SW_W           => SW_W,
          SWX_W          => SWX_W,
          SHIFT_Q_W      => SHIFT_Q_W,
          CENTRE_W       => CENTRE_W,
          CENTRE_ABS_W   => CENTRE_ABS_W,
          ITER_W         => ITER_W,
          RHO_OUT_W      => RHO_OUT_W,
          ALPHA_W        => ALPHA_W,
          WIN_W          => WIN_W,
          RESULT_W       => RESULT_W,
          PAD16          => PAD16,
          RING16         => RING16,
          MAX_WINDOW     => MAX_WINDOW,
          KT_W           => KT_W,
          ST2_W          => ST2_W,
          SHARE_W        => SHARE_W,
          SPREAD_W       => SPREAD_W,
          SIZE_W         => SIZE_W,
          SCALE_W        => SCALE_W,
          SCALE_GAIN     => SCALE_GAIN,
          SCALE_REG      => SCALE_REG,
          SCALE_STEP     => SCALE_STEP,
          SCALE_RATIO_Q_W=> SCALE_RATIO_Q_W,
          WR_Q_W         => WR_Q_W,
          CON_W          => CON_W,
          LOSS_K         => LOSS_K,
          REF_K          => REF_K,
          LOSS_RHO       => LOSS_RHO,
          LOSS_CONTRAST  => LOSS_CONTRAST,
          CONF_LOST      => CONF_LOST,
          CONF_UNCERTAIN => CONF_UNCERTAIN,
          CONF_REACQUIRE => CONF_REACQUIRE,
          SPREAD_DEFAULT => SPREAD_DEFAULT,
          BG_Q_W         => BG_Q_W,
          BG_O_W         => BG_O_W,
          SEARCH_ITER    => SEARCH_ITER,
          STEP16         => STEP16,
          MARGIN_MAX     => MARGIN_MAX,
          SCALE_TEST_D256=> SCALE_TEST_D256,
          ORIENT_T       => ORIENT_T,
          RD_LAT         => RD_LAT,
          FRAME_LINES    => FRAME_LINES,
          ACTIVE_LINES   => ACTIVE_LINES,
          LINE_CLOCKS    => LINE_CLOCKS,
          LC_W           => LC_W,
          SUM_W          => SUM_W,
          CLK_W          => CLK_W,
          PLAN_REGION_W  => PLAN_REGION_W,
          GROW_Q16       => GROW_Q16,
          PASS_LAT       => PASS_LAT,
          M_TRACK        => M_TRACK,
          C_TRACK        => C_TRACK,
          M_LOST         => M_LOST,
          C_LOST         => C_LOST,
          C_INIT         => C_INIT,
          SCALE_PERMILLE => SCALE_PERMILLE,
          C_SCALE        => C_SCALE
        )
        port map (
          clk => clk, rst => rst, frame_width => fw, frame_height => fh,
          s_cmd_tvalid => cmd_v, s_cmd_tready => cmd_rdy, s_cmd_op => cmd_op, s_cmd_id => cmd_tid,
          s_cmd_x => ib_x, s_cmd_y => ib_y, s_cmd_w => ib_w, s_cmd_h => ib_h,
          cmd_done => cmd_done, cmd_code => cmd_code, cmd_id => cmd_rid,
          s_axis_tdata => s_axis_tdata, s_axis_tvalid => c_tvalid, s_axis_tready => c_tready,
          s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
          m_axis_result_tdata => r_data, m_axis_result_tvalid => r_valid,
          m_axis_result_tready => r_ready, m_axis_result_tlast => r_last,
          live => live_n, busy => busy);
    end generate;
    r_id <= to_integer(unsigned(r_data(MULTI_W - 1 downto RESULT_W)));
    init_rdy <= '1';                                   -- (CMD.init is an add here: init_v stays 0)
    live <= std_logic_vector(resize(unsigned(live_n), 16));

    -- commands: copied at the write of CMD (add / init: the box of p_init; remove: TARGET.id), offered
    -- until the core takes it; the latest write wins while not taken
    p_cmd : process(clk)
    begin
      if rising_edge(clk) then
        ev_cmd <= cmd_done;
        if cmd_v = '1' and cmd_rdy = '1' then
          cmd_v    <= '0';
          cmd_wait <= '1';
        end if;
        if cmd_done = '1' then
          cmd_wait <= '0';
          st_code  <= std_logic_vector(cmd_code);
          st_id    <= std_logic_vector(cmd_rid);
          st_count <= st_count + 1;
        end if;
        if hw_out.CMD.remove.value = '1' then
          cmd_v   <= '1';
          cmd_op  <= '1';
          cmd_tid <= unsigned(hw_out.TARGET.id.value);
        elsif hw_out.CMD.add.value = '1' or hw_out.CMD.init.value = '1' then
          cmd_v  <= '1';
          cmd_op <= '0';
        end if;
        if rst = '1' then
          cmd_v    <= '0';
          cmd_wait <= '0';
          ev_cmd   <= '0';
          st_code  <= (others => '0');
          st_id    <= (others => '0');
          st_count <= (others => '0');
        end if;
      end if;
    end process;

    -- the frame's words by id into coll; at its last word coll (with that word) is shown in vis
    p_bank : process(clk)
      variable m : std_logic_vector(MAX_TARGETS - 1 downto 0);
    begin
      if rising_edge(clk) then
        if r_take = '1' then
          m := coll_m;
          for i in 0 to MAX_TARGETS - 1 loop           -- loops, not variable indices (docs/hdl_flow.md)
            if r_id = i then
              coll(i) <= r_word;
              m(i) := not r_word(V_FL + F_NOT);
            end if;
            if r_last = '1' then
              vis(i) <= r_word when r_id = i else coll(i);
            end if;
          end loop;
          if r_last = '1' then
            vis_mask <= std_logic_vector(resize(unsigned(m), 16));
            vis_fc   <= r_word(V_FC + 15 downto V_FC);
            vis_ok   <= '1';
            coll_m   <= (others => '0');
          else
            coll_m   <= m;
          end if;
        end if;
        if rst = '1' then
          coll_m   <= (others => '0');
          vis_mask <= (others => '0');
          vis_fc   <= (others => '0');
          vis_ok   <= '0';
        end if;
      end if;
    end process;

    -- L: the word of target RES_SEL.id (an id >= MAX_TARGETS reads as no result)
    sel <= to_integer(unsigned(hw_out.RES_SEL.id.value));
    p_sel : process(all)
    begin
      lat    <= (others => '0');
      lat_ok <= '0';
      for i in 0 to MAX_TARGETS - 1 loop
        if sel = i then
          lat    <= vis(i);
          lat_ok <= vis_ok;
        end if;
      end loop;
    end process;
    head_id <= hw_out.RES_SEL.id.value when sel < MAX_TARGETS else (others => '0');
  end generate;

  ---------------------------------------------------------------------------- results
  r_ready <= m_axis_result_tready when RESULT_STREAM else '1';
  r_take  <= r_valid and r_ready;
  m_axis_result_tdata  <= r_data;
  m_axis_result_tvalid <= r_valid when RESULT_STREAM else '0';
  m_axis_result_tlast  <= r_last;
  r_word <= std_logic_vector(resize(unsigned(r_data(RESULT_W - 1 downto 0)), RAW_W));

  p_result : process(clk)
  begin
    if rising_edge(clk) then
      ev_res  <= r_take and r_last;                  -- once per frame
      ev_lost <= r_take and w_lost;
      ev_err  <= r_take and w_err;
      ev_rej  <= r_take and w_rej;
      ev_reacq <= r_take and w_reacq;
      fr_lost  <= acc_lost or w_lost;
      fr_err   <= acc_err or w_err or w_rej;
      fr_reacq <= acc_reacq or w_reacq;
      if r_take = '1' then                           -- collect over the frame's words; clear at its last
        acc_lost  <= (acc_lost or w_lost) and not r_last;
        acc_err   <= (acc_err or w_err or w_rej) and not r_last;
        acc_reacq <= (acc_reacq or w_reacq) and not r_last;
      end if;
      if hw_out.RES_HEAD.frame_count.swacc = '1' then  -- read of RES_HEAD: S <= L, same clock
        snap <= lat;
      end if;
      if rst = '1' then
        snap   <= (others => '0');
        ev_res <= '0';
        ev_lost <= '0';
        ev_err <= '0';
        ev_rej <= '0';
        ev_reacq <= '0';
        acc_lost <= '0';
        acc_err <= '0';
        acc_reacq <= '0';
      end if;
    end if;
  end process;
end architecture;
