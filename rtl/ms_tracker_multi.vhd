-- ms_tracker_multi: MAX_TARGETS targets in one core: one ms_tracker_v2 engine per target slot, the
-- video broadcast to all, add / remove commands, and a merger that sends one result word per live
-- target per frame with the target's id (mstrack.fixed.vhdl_pkg.result_layout_multi).  Executable
-- specification: mstrack.hw.cosim_multi.CoreModelMulti (docs/multi_target_core.md, "Ports and result
-- stream"); block page docs/blocks/ms_tracker_multi.md.
--
-- Computes: each slot k is a complete core v2 (ms_tracker_v2), so a target is tracked bit for bit as a
-- single tracker v2.  A video beat goes into one register and is offered to every engine until each
-- has taken it (the next beat enters in the clock the last one takes it), so all engines see the same
-- beats, each at its own pace.  Commands (s_cmd_*) are taken between frames,
-- when every engine is idle and the previous frame's words are merged: an add gives its box to the
-- lowest free slot's engine (as core v2's init box: applied on the next good frame of its size; a box
-- that does not clip is rejected by that engine, which frees the slot when its next word shows it);
-- with no free slot it is refused (code 1, flag `rejected` on the next frame's first word).  A remove
-- resets the slot's engine (code 0; an id that is not live: code 1, nothing changes).  Each command
-- reports its outcome on cmd_done / cmd_code / cmd_id (add: 0 ok, 1 full; a rejected box later reports
-- code 3 with its id when the engine's word shows the rejection; several in one frame: one per clock,
-- lowest slot first).
-- Results: when every engine has its word of a frame, the merger takes them all in one clock and sends,
-- in ascending slot order, the words without the flag no_target (live targets), each with its id at
-- bits RESULT_W + 3 .. RESULT_W and frame_count replaced by the frames merged since reset; a frame with
-- none sends slot 0's word alone.  The flag `rejected` of any engine's word and of a refused add is set
-- on the frame's first word.  tlast on a frame's last word.
-- Latency: an engine's (core v2) + 3 clocks to the first word, then one word per clock without
-- back-pressure.  Throughput: 1 pixel per clock while a frame streams (the slowest engine sets the
-- pace); a command holds the video for 2 clocks (remove) or until its engine takes the box (add).
-- Handshake: AXI4-Stream in (s_axis), commands valid / ready (s_cmd), results AXI4-Stream out
-- (m_axis_result, one word per live target per frame, tlast on the last).
-- Resources: MAX_TARGETS x core v2 + the merger's MAX_TARGETS x RESULT_W register bank.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_tracker_multi is
  generic (
    MAX_TARGETS    : positive range 1 to 16 := 2;   -- target slots (engines)
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
    ORIENT_T        : integer range -1 to 2047 := 64
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

architecture rtl of ms_tracker_multi is
  constant N      : positive := MAX_TARGETS;
  constant CONF_W : natural := 17;
  -- result word v2 fields (mstrack.fixed.vhdl_pkg.result_layout_v2), as ms_tracker_axi
  constant V_FL   : natural := 2 * CENTRE_ABS_W + 2 * SIZE_W + RHO_OUT_W + CONF_W + 3 + ITER_W + 2 + 3 + 4;
  constant V_EC   : natural := V_FL + 8;
  constant V_FC   : natural := V_EC + 3;
  constant F_REJ  : natural := 4;                      -- RESULT_FLAGS indices
  constant F_NOT  : natural := 5;

  type words_t is array (0 to N - 1) of std_logic_vector(RESULT_W - 1 downto 0);
  signal e_init_v, e_init_r, e_ready, e_rvalid, e_rst, e_busy : std_logic_vector(N - 1 downto 0) := (others => '0');
  signal e_word   : words_t;
  signal w_reg    : words_t := (others => (others => '0'));
  signal all_idle, all_rvalid, any_rvalid, v_open, cmd_take, m_take : std_logic;
  -- video broadcast: one registered beat, offered to every engine until each has taken it
  signal b_valid  : std_logic := '0';
  signal b_data   : std_logic_vector(23 downto 0) := (others => '0');
  signal b_user, b_last : std_logic := '0';
  signal b_pend   : std_logic_vector(N - 1 downto 0) := (others => '0');   -- engine k has not taken it
  signal e_valid  : std_logic_vector(N - 1 downto 0);
  signal b_free, s_ready : std_logic;
  signal cmd_busy : std_logic := '0';
  signal c_op     : std_logic := '0';
  signal c_x, c_y : signed(COORD_W + 1 downto 0) := (others => '0');
  signal c_w, c_h : unsigned(COORD_W downto 0) := (others => '0');
  signal alloc, pend : std_logic_vector(N - 1 downto 0) := (others => '0');
  signal rej_flag : std_logic := '0';
  signal box_rep  : std_logic_vector(N - 1 downto 0) := (others => '0');   -- rejected boxes still to report
  -- merger
  signal m_busy   : std_logic := '0';                  -- words latched, being sent
  signal m_emit   : std_logic_vector(N - 1 downto 0) := (others => '0');
  signal m_idx    : natural range 0 to N := 0;
  signal m_first  : std_logic := '0';
  signal m_rej    : std_logic := '0';
  signal m_single : std_logic := '0';                  -- no live target: slot 0's word alone
  signal o_valid  : std_logic := '0';
  signal o_last   : std_logic := '0';
  signal o_data   : std_logic_vector(RESULT_W + 3 downto 0) := (others => '0');
  signal fcount   : unsigned(15 downto 0) := (others => '0');
  signal done_r   : std_logic := '0';
  signal code_r   : unsigned(1 downto 0) := (others => '0');
  signal id_r     : unsigned(3 downto 0) := (others => '0');

  function lowest(v : std_logic_vector) return natural is   -- index of the lowest '0', or v'length
  begin
    for i in 0 to v'length - 1 loop
      if v(v'low + i) = '0' then
        return i;
      end if;
    end loop;
    return v'length;
  end function;

  function next_set(v : std_logic_vector; from : natural) return natural is   -- lowest '1' at from or above
  begin
    for i in 0 to v'length - 1 loop
      if i >= from and v(v'low + i) = '1' then
        return i;
      end if;
    end loop;
    return v'length;
  end function;
begin
  assert RESULT_W >= V_FC + 16 report "ms_tracker_multi: RESULT_W and the result layout v2 disagree" severity failure;

  g_eng : for k in 0 to N - 1 generate
    u_eng : entity work.ms_tracker_v2
      generic map (
        MAX_FRAME_W     => MAX_FRAME_W,
        RGB_PACKING     => RGB_PACKING,
        LANES           => LANES,
        COLOUR_BITS     => COLOUR_BITS,
        EDGE_BINS_LOG2  => EDGE_BINS_LOG2,
        EDGE_SHIFT      => EDGE_SHIFT,
        FEATURES        => FEATURES,
        KERNEL_EPAN     => KERNEL_EPAN,
        KERNEL_BITS     => KERNEL_BITS,
        MAX_HALF        => MAX_HALF,
        MARGIN          => MARGIN,
        COORD_W         => COORD_W,
        CF              => CF,
        WI              => WI,
        WF              => WF,
        RF              => RF,
        AF              => AF,
        RHO_OUT_FRAC    => RHO_OUT_FRAC,
        MAX_ITER        => MAX_ITER,
        EPS2            => EPS2,
        HALF_W          => HALF_W,
        REGION_MAX      => REGION_MAX,
        REGION_W        => REGION_W,
        STRIDE          => STRIDE,
        ADDR_W          => ADDR_W,
        KVAL_W          => KVAL_W,
        HIST_W          => HIST_W,
        COUNT_W         => COUNT_W,
        POSSUM_W        => POSSUM_W,
        KD_W            => KD_W,
        SQRT_IN_W       => SQRT_IN_W,
        RHO_SUM_W       => RHO_SUM_W,
        RATIO_Q_W       => RATIO_Q_W,
        WEIGHT_W        => WEIGHT_W,
        SW_W            => SW_W,
        SWX_W           => SWX_W,
        SHIFT_Q_W       => SHIFT_Q_W,
        CENTRE_W        => CENTRE_W,
        CENTRE_ABS_W    => CENTRE_ABS_W,
        ITER_W          => ITER_W,
        RHO_OUT_W       => RHO_OUT_W,
        ALPHA_W         => ALPHA_W,
        WIN_W           => WIN_W,
        RESULT_W        => RESULT_W,
        PAD16           => PAD16,
        RING16          => RING16,
        MAX_WINDOW      => MAX_WINDOW,
        KT_W            => KT_W,
        ST2_W           => ST2_W,
        SHARE_W         => SHARE_W,
        SPREAD_W        => SPREAD_W,
        SIZE_W          => SIZE_W,
        SCALE_W         => SCALE_W,
        SCALE_GAIN      => SCALE_GAIN,
        SCALE_REG       => SCALE_REG,
        SCALE_STEP      => SCALE_STEP,
        SCALE_RATIO_Q_W => SCALE_RATIO_Q_W,
        WR_Q_W          => WR_Q_W,
        CON_W           => CON_W,
        LOSS_K          => LOSS_K,
        REF_K           => REF_K,
        LOSS_RHO        => LOSS_RHO,
        LOSS_CONTRAST   => LOSS_CONTRAST,
        CONF_LOST       => CONF_LOST,
        CONF_UNCERTAIN  => CONF_UNCERTAIN,
        CONF_REACQUIRE  => CONF_REACQUIRE,
        SPREAD_DEFAULT  => SPREAD_DEFAULT,
        BG_Q_W          => BG_Q_W,
        BG_O_W          => BG_O_W,
        SEARCH_ITER     => SEARCH_ITER,
        STEP16          => STEP16,
        MARGIN_MAX      => MARGIN_MAX,
        SCALE_TEST_D256 => SCALE_TEST_D256,
        ORIENT_T        => ORIENT_T
      )
      port map (
        clk => clk, rst => e_rst(k), frame_width => frame_width, frame_height => frame_height,
        s_init_tvalid => e_init_v(k), s_init_tready => e_init_r(k),
        s_init_x => c_x, s_init_y => c_y, s_init_w => c_w, s_init_h => c_h,
        s_axis_tdata => b_data, s_axis_tvalid => e_valid(k), s_axis_tready => e_ready(k),
        s_axis_tlast => b_last, s_axis_tuser => b_user,
        m_axis_result_tdata => e_word(k), m_axis_result_tvalid => e_rvalid(k),
        m_axis_result_tready => m_take, m_axis_result_tlast => open, busy => e_busy(k));
  end generate;

  -- the beat register is free when empty or when every engine that has not taken its beat takes it now;
  -- an engine that is not ready still sees the beat (core v2 looks at a start of frame it does not take
  -- yet: the re-arm of its background model after a bad init frame)
  e_valid <= b_pend when b_valid = '1' else (others => '0');
  b_free  <= '1' when b_valid = '0' or (b_pend and not e_ready) = (b_pend'range => '0') else '0';
  all_idle   <= '1' when e_init_r = (e_init_r'range => '1') else '0';
  all_rvalid <= '1' when e_rvalid = (e_rvalid'range => '1') else '0';
  any_rvalid <= '0' when e_rvalid = (e_rvalid'range => '0') else '1';
  -- a command is taken between frames: every engine idle (no frame in progress, its word taken), the
  -- merger done with the previous frame's words (so a refusal's flag goes to the next frame)
  cmd_take <= s_cmd_tvalid and not cmd_busy and all_idle and not any_rvalid and not m_busy and not b_valid
              and not rst when box_rep = (box_rep'range => '0') else '0';
  s_cmd_tready <= cmd_take;
  -- no beat while a command is taken or carried out
  v_open  <= not cmd_take and not cmd_busy;
  s_ready <= b_free and v_open and not rst;
  s_axis_tready <= s_ready;

  p_video : process(clk)
  begin
    if rising_edge(clk) then
      if b_valid = '1' then
        b_pend <= b_pend and not e_ready;              -- the engines that take it now are done
        if b_free = '1' then
          b_valid <= '0';
        end if;
      end if;
      if s_axis_tvalid = '1' and s_ready = '1' then
        b_valid <= '1';
        b_data <= s_axis_tdata;
        b_user <= s_axis_tuser;
        b_last <= s_axis_tlast;
        b_pend <= (others => '1');
      end if;
      if rst = '1' then
        b_valid <= '0';
        b_pend <= (others => '0');
      end if;
    end if;
  end process;
  m_take  <= all_rvalid and not m_busy and not rst;

  p_ctl : process(clk)
    variable k : natural range 0 to 16;
    variable wsel : std_logic_vector(RESULT_W - 1 downto 0);
    variable fl : std_logic_vector(7 downto 0);
    variable emit : std_logic_vector(N - 1 downto 0);
    variable rj : std_logic;
  begin
    if rising_edge(clk) then
      done_r <= '0';
      e_rst <= (others => rst);
      -- commands
      if cmd_take = '1' then
        c_op <= s_cmd_op;
        c_x <= s_cmd_x; c_y <= s_cmd_y; c_w <= s_cmd_w; c_h <= s_cmd_h;
        if s_cmd_op = '1' then                         -- remove
          done_r <= '1';
          id_r <= s_cmd_id;
          code_r <= "01";
          for i in 0 to N - 1 loop                     -- (loops, not variable indices: GHDL's Verilog
            if to_integer(s_cmd_id) = i and alloc(i) = '1' then   -- writer breaks those at N = 1)
              e_rst(i) <= '1';
              alloc(i) <= '0';
              pend(i) <= '0';
              code_r <= "00";
              cmd_busy <= '1';                         -- the reset clock: no beat
            end if;
          end loop;
        else                                           -- add
          k := lowest(alloc);
          if k = N then
            done_r <= '1';
            code_r <= "01";
            id_r <= (others => '0');
            rej_flag <= '1';
          else
            for i in 0 to N - 1 loop
              if i = k then
                alloc(i) <= '1';
                pend(i) <= '1';
                e_init_v(i) <= '1';
              end if;
            end loop;
            id_r <= to_unsigned(k, 4);
            cmd_busy <= '1';
          end if;
        end if;
      elsif cmd_busy = '1' then
        if c_op = '1' then
          cmd_busy <= '0';                             -- the engine was reset in this clock
        elsif (e_init_v and e_init_r) /= (e_init_v'range => '0') then
          e_init_v <= (others => '0');                 -- the engine took the box
          cmd_busy <= '0';
          done_r <= '1';
          code_r <= "00";
        end if;
      end if;

      -- the rejected boxes of the last merged frame, lowest slot first, one report per clock
      if box_rep /= (box_rep'range => '0') then
        k := next_set(box_rep, 0);
        done_r <= '1';
        code_r <= "11";
        id_r <= to_unsigned(k, 4);
        for i in 0 to N - 1 loop
          if i = k then
            box_rep(i) <= '0';
          end if;
        end loop;
      end if;

      -- merger: latch every engine's word of the frame, then send the live ones
      if m_take = '1' then
        w_reg <= e_word;
        emit := (others => '0');
        rj := rej_flag;
        for i in 0 to N - 1 loop
          fl := e_word(i)(V_FL + 7 downto V_FL);
          emit(i) := not fl(F_NOT);
          rj := rj or fl(F_REJ);
          if pend(i) = '1' and cmd_take = '0' then     -- an add waiting for its engine's first word
            if fl(F_REJ) = '1' then                    -- the box was rejected: the slot is free again
              alloc(i) <= '0';
              pend(i) <= '0';
              box_rep(i) <= '1';                       -- reported below, one slot per clock
            elsif fl(F_NOT) = '0' then
              pend(i) <= '0';                          -- the target exists
            end if;
          end if;
        end loop;
        rej_flag <= '0';
        m_rej <= rj;
        m_emit <= emit;
        m_single <= '1' when emit = (emit'range => '0') else '0';
        m_idx <= 0;
        m_first <= '1';
        m_busy <= '1';
      end if;
      if m_busy = '1' and (o_valid = '0' or m_axis_result_tready = '1') then
        if m_single = '1' or next_set(m_emit, m_idx) < N then
          if m_single = '1' then
            k := 0;
          else
            k := next_set(m_emit, m_idx);
          end if;
          wsel := w_reg(0);
          for i in 1 to N - 1 loop
            if i = k then
              wsel := w_reg(i);
            end if;
          end loop;
          o_data <= (others => '0');
          o_data(RESULT_W - 1 downto 0) <= wsel;
          o_data(V_FC + 15 downto V_FC) <= std_logic_vector(fcount);
          o_data(V_FL + F_REJ) <= wsel(V_FL + F_REJ) or (m_rej and m_first);
          o_data(RESULT_W + 3 downto RESULT_W) <= std_logic_vector(to_unsigned(k, 4));
          o_valid <= '1';
          m_first <= '0';
          if m_single = '1' or next_set(m_emit, k + 1) = N then
            o_last <= '1';
            m_busy <= '0';
            fcount <= fcount + 1;
          else
            o_last <= '0';
          end if;
          m_idx <= k + 1;
          m_single <= '0';
        end if;
      elsif o_valid = '1' and m_axis_result_tready = '1' then
        o_valid <= '0';
      end if;

      if rst = '1' then
        cmd_busy <= '0';
        e_init_v <= (others => '0');
        alloc <= (others => '0');
        pend <= (others => '0');
        box_rep <= (others => '0');
        rej_flag <= '0';
        m_busy <= '0';
        o_valid <= '0';
        o_last <= '0';
        fcount <= (others => '0');
        done_r <= '0';
      end if;
    end if;
  end process;

  m_axis_result_tdata  <= o_data;
  m_axis_result_tvalid <= o_valid;
  m_axis_result_tlast  <= o_last;
  cmd_done <= done_r;
  cmd_code <= code_r;
  cmd_id   <= id_r;
  live     <= alloc;
  busy     <= '0' when e_busy = (e_busy'range => '0') else '1';
end architecture;
