-- ms_frame_plan: the plan of a frame of the shared-engine multi-target core: each live target's job
-- (ms_job_demand) and the capacity rule's verdict on it (ms_admit), oldest target first; then the
-- frame's adds, offered to the same rule (model: mstrack.fixed.multi_capacity.plan_frame over
-- ms_job_demand, then check_add; docs/multi_target_core.md, "Capacity rule").
--
-- Computes: on `start`, for k = 0 .. n_live - 1 (the live targets in age order, oldest first), it
-- asks the state record of the k-th (st_req with st_index; the top answers st_valid with the slot and
-- its state: w8, h8, c8, lost), runs ms_job_demand on it and offers the job to ms_admit; p_valid then
-- gives the slot, the verdict (p_taken: tracked on this frame, or held) and the job (D, region, clocks,
-- first, release and next line: what the slot's capture is loaded with).  plan_done gives the sum of
-- the taken jobs' clocks and their smallest slack (plan.clocks, plan.budget).  Then, until the next
-- start, each add's init job (a_offer: its clocks, release and next line, and a_full when MAX_TARGETS
-- targets are live) gets its code on a_done (0 ok, 1 full, 2 cycles), checked against the jobs taken
-- and the adds taken before it (check_add).
-- Latency: per live target the state read, ms_job_demand (at most 485 clocks for tracker v2) and
-- ms_admit (LC_W + 3); 16 targets take under 8,500 clocks.  An add: LC_W + 4 clocks.
-- Throughput: one plan at a time (`busy`); adds one at a time (`a_ready`).
-- Handshake: start when busy = '0' (sampled with n_live, frame_w, frame_h); st_req pulses, st_valid
-- answers at any later clock; p_valid, plan_done and a_done pulse one clock with their outputs, which
-- hold until the next pulse; a_offer is taken when a_ready = '1'.
-- Reset: synchronous, active high.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_frame_plan is
  generic (
    MAX_TARGETS    : positive range 1 to 16 := 16;
    -- ms_job_demand (mstrack.hw.multi_core.job_demand_generics)
    COORD_W        : natural := 12;
    CF             : natural := 8;
    PAD16          : natural := 4;
    MAX_WINDOW     : natural := 127;
    HALF_W         : natural := 6;
    REGION_W       : natural := 10;
    MARGIN         : natural := 32;
    MARGIN_MAX     : natural := 255;
    STEP16         : natural := 16;
    GROW_Q16       : natural := 6554;
    LANES          : positive := 4;
    PASS_LAT       : natural := 10;
    CLK_W          : natural := 24;
    M_TRACK        : natural := 21;
    C_TRACK        : natural := 13254;
    M_LOST         : natural := 54;
    C_LOST         : natural := 32591;
    C_INIT         : natural := 15826;
    SCALE_PERMILLE : natural := 50;
    C_SCALE        : natural := 2870;
    -- ms_admit
    LC_W           : positive := 13;    -- clocks per line
    SUM_W          : positive := 28     -- sums of clocks, slacks
  );
  port (
    clk          : in  std_logic;
    rst          : in  std_logic;
    frame_lines  : in  unsigned(COORD_W - 1 downto 0);            -- video timing (ms_admit)
    line_clocks  : in  unsigned(LC_W - 1 downto 0);
    blank_clocks : in  unsigned(SUM_W - 1 downto 0);
    start        : in  std_logic;                                 -- plan a frame
    n_live       : in  unsigned(4 downto 0);                      -- live targets (0 .. MAX_TARGETS)
    frame_w      : in  unsigned(COORD_W - 1 downto 0);
    frame_h      : in  unsigned(COORD_W - 1 downto 0);
    busy         : out std_logic;
    -- the state records, in age order
    st_req       : out std_logic;                                 -- pulse: the k-th oldest target's state
    st_index     : out unsigned(3 downto 0);                      -- k
    st_valid     : in  std_logic;                                 -- its slot and state
    st_slot      : in  unsigned(3 downto 0);
    st_w8, st_h8 : in  unsigned(COORD_W + 7 downto 0);
    st_c8x       : in  unsigned(COORD_W + CF - 1 downto 0);
    st_c8y       : in  unsigned(COORD_W + CF - 1 downto 0);
    st_lost      : in  std_logic;
    -- one per live target, oldest first
    p_valid      : out std_logic;
    p_slot       : out unsigned(3 downto 0);
    p_taken      : out std_logic;                                 -- '1' tracked, '0' held (err_code 6)
    p_log2_d     : out unsigned(2 downto 0);
    p_reg_x      : out unsigned(COORD_W - 1 downto 0);            -- region, decimated px
    p_reg_y      : out unsigned(COORD_W - 1 downto 0);
    p_reg_w      : out unsigned(REGION_W - 1 downto 0);
    p_reg_h      : out unsigned(REGION_W - 1 downto 0);
    p_clocks     : out unsigned(CLK_W - 1 downto 0);
    p_first_line : out unsigned(COORD_W - 1 downto 0);
    p_release    : out unsigned(COORD_W - 1 downto 0);
    p_next_line  : out unsigned(COORD_W - 1 downto 0);
    -- the plan
    plan_done    : out std_logic;
    plan_clocks  : out unsigned(SUM_W - 1 downto 0);              -- sum of the taken jobs' clocks
    plan_budget  : out unsigned(SUM_W - 1 downto 0);              -- their smallest slack (all ones: none)
    -- the frame's adds
    a_ready      : out std_logic;
    a_offer      : in  std_logic;
    a_full       : in  std_logic;                                 -- MAX_TARGETS targets live
    a_clocks     : in  unsigned(CLK_W - 1 downto 0);
    a_release    : in  unsigned(COORD_W - 1 downto 0);
    a_next       : in  unsigned(COORD_W - 1 downto 0);
    a_done       : out std_logic;
    a_code       : out unsigned(1 downto 0)                       -- 0 ok, 1 full, 2 cycles
  );
end entity;

architecture rtl of ms_frame_plan is
  type state_t is (S_IDLE, S_CLEAR, S_CLEARED, S_REQ, S_STATE, S_DEMAND, S_DEM_WAIT, S_OFFER, S_ADMIT, S_DONE, S_ADDS,
                   S_ADD_WAIT);
  signal state  : state_t := S_IDLE;
  signal k      : unsigned(4 downto 0);
  signal n_r    : unsigned(4 downto 0);
  signal fw_r, fh_r : unsigned(COORD_W - 1 downto 0);
  -- the state being planned
  signal slot_r : unsigned(3 downto 0);
  signal w8_r, h8_r : unsigned(COORD_W + 7 downto 0);
  signal cx_r, cy_r : unsigned(COORD_W + CF - 1 downto 0);
  signal lost_r : std_logic;
  -- ms_job_demand
  signal jd_start, jd_busy, jd_done : std_logic := '0';
  signal jd_l2d : unsigned(2 downto 0);
  signal jd_wd, jd_hd : unsigned(HALF_W downto 0);
  signal jd_x, jd_y : unsigned(COORD_W - 1 downto 0);
  signal jd_w, jd_h : unsigned(REGION_W - 1 downto 0);
  signal jd_clocks : unsigned(CLK_W - 1 downto 0);
  signal jd_first, jd_release, jd_next : unsigned(COORD_W - 1 downto 0);
  -- ms_admit
  signal ad_clear, ad_offer, ad_add, ad_full, ad_ready, ad_done, ad_taken : std_logic := '0';
  signal ad_clocks : unsigned(CLK_W - 1 downto 0);
  signal ad_release, ad_next : unsigned(COORD_W - 1 downto 0);
  signal ad_code : unsigned(1 downto 0);
  signal ad_sum, ad_min : unsigned(SUM_W - 1 downto 0);
begin
  u_demand : entity work.ms_job_demand
    generic map (COORD_W => COORD_W, CF => CF, PAD16 => PAD16, MAX_WINDOW => MAX_WINDOW, HALF_W => HALF_W,
                 REGION_W => REGION_W, MARGIN => MARGIN, MARGIN_MAX => MARGIN_MAX, STEP16 => STEP16,
                 GROW_Q16 => GROW_Q16, LANES => LANES, PASS_LAT => PASS_LAT, CLK_W => CLK_W, M_TRACK => M_TRACK,
                 C_TRACK => C_TRACK, M_LOST => M_LOST, C_LOST => C_LOST, C_INIT => C_INIT,
                 SCALE_PERMILLE => SCALE_PERMILLE, C_SCALE => C_SCALE)
    port map (clk => clk, rst => rst, start => jd_start, w8 => w8_r, h8 => h8_r, c8x => cx_r, c8y => cy_r,
              lost => lost_r, frame_w => fw_r, frame_h => fh_r, busy => jd_busy, done => jd_done,
              log2_d => jd_l2d, wd => jd_wd, hd => jd_hd, reg_x => jd_x, reg_y => jd_y, reg_w => jd_w,
              reg_h => jd_h, clocks => jd_clocks, first_line => jd_first, release_line => jd_release,
              next_line => jd_next);
  u_admit : entity work.ms_admit
    generic map (MAX_TARGETS => MAX_TARGETS, CLK_W => CLK_W, LINE_W => COORD_W, LC_W => LC_W, SUM_W => SUM_W)
    port map (clk => clk, rst => rst, frame_lines => frame_lines, line_clocks => line_clocks,
              blank_clocks => blank_clocks, clear => ad_clear, offer => ad_offer, o_add => ad_add,
              o_full => ad_full, o_clocks => ad_clocks, o_release => ad_release, o_next => ad_next,
              ready => ad_ready, done => ad_done, taken => ad_taken, code => ad_code, sum => ad_sum,
              min_slack => ad_min);

  p_plan : process (clk)
  begin
    if rising_edge(clk) then
      st_req    <= '0';
      jd_start  <= '0';
      ad_clear  <= '0';
      ad_offer  <= '0';
      p_valid   <= '0';
      plan_done <= '0';
      a_done    <= '0';
      case state is
        when S_IDLE | S_ADDS =>
          if start = '1' then
            n_r  <= n_live;
            fw_r <= frame_w;
            fh_r <= frame_h;
            k    <= (others => '0');
            state <= S_CLEAR;
          elsif state = S_ADDS and a_offer = '1' and ad_ready = '1' then
            ad_offer   <= '1';
            ad_add     <= '1';
            ad_full    <= a_full;
            ad_clocks  <= a_clocks;
            ad_release <= a_release;
            ad_next    <= a_next;
            state <= S_ADD_WAIT;
          end if;

        when S_CLEAR =>                        -- (ms_admit is ready: nothing runs between plans)
          ad_clear <= '1';
          state <= S_CLEARED;

        when S_CLEARED =>                      -- ms_admit takes the clear on this clock's edge
          if n_r = 0 then
            state <= S_DONE;
          else
            state <= S_REQ;
          end if;

        when S_REQ =>
          st_req   <= '1';
          st_index <= k(3 downto 0);
          state <= S_STATE;

        when S_STATE =>
          if st_valid = '1' then
            slot_r <= st_slot;
            w8_r <= st_w8; h8_r <= st_h8; cx_r <= st_c8x; cy_r <= st_c8y; lost_r <= st_lost;
            state <= S_DEMAND;
          end if;

        when S_DEMAND =>                       -- ms_job_demand takes the registered state
          jd_start <= '1';
          state <= S_DEM_WAIT;

        when S_DEM_WAIT =>
          if jd_done = '1' then
            state <= S_OFFER;
          end if;

        when S_OFFER =>
          if ad_ready = '1' then
            ad_offer   <= '1';
            ad_add     <= '0';
            ad_full    <= '0';
            ad_clocks  <= jd_clocks;
            ad_release <= jd_release;
            ad_next    <= jd_next;
            state <= S_ADMIT;
          end if;

        when S_ADMIT =>
          if ad_done = '1' then
            p_valid      <= '1';
            p_slot       <= slot_r;
            p_taken      <= ad_taken;
            p_log2_d     <= jd_l2d;
            p_reg_x      <= jd_x;
            p_reg_y      <= jd_y;
            p_reg_w      <= jd_w;
            p_reg_h      <= jd_h;
            p_clocks     <= jd_clocks;
            p_first_line <= jd_first;
            p_release    <= jd_release;
            p_next_line  <= jd_next;
            if k + 1 = n_r then
              state <= S_DONE;
            else
              k <= k + 1;
              state <= S_REQ;
            end if;
          end if;

        when S_DONE =>                         -- ms_admit's sum and min_slack hold the last verdict's
          plan_done   <= '1';
          plan_clocks <= ad_sum;
          plan_budget <= ad_min;
          state <= S_ADDS;

        when S_ADD_WAIT =>
          if ad_done = '1' then
            a_done <= '1';
            a_code <= ad_code;
            state <= S_ADDS;
          end if;
      end case;
      if rst = '1' then
        state     <= S_IDLE;
        st_req    <= '0';
        jd_start  <= '0';
        ad_clear  <= '0';
        ad_offer  <= '0';
        p_valid   <= '0';
        plan_done <= '0';
        a_done    <= '0';
      end if;
    end if;
  end process;
  busy    <= '0' when state = S_IDLE or state = S_ADDS else '1';
  a_ready <= '1' when state = S_ADDS and ad_ready = '1' else '0';
end architecture;
