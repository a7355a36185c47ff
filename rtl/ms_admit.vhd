-- ms_admit: the capacity rule of the shared-engine multi-target core, in integers: which of a
-- frame's jobs run (mstrack.fixed.multi_capacity.plan_frame) and whether an add is taken
-- (check_add).
--
-- Computes: for the frame's jobs offered in priority order (the live targets oldest first, then
-- the adds of that frame), with each job's worst-case clocks c, release line r and next line n:
--   slack = max((FRAME_LINES - r + n - 1) * LINE_CLOCKS, BLANK_CLOCKS)    (TargetDemand.slack)
--   fits  = sum + c <= min(min_slack, slack)                             (sum, min_slack: the jobs taken so far)
--   a live target's job (o_add = '0'): taken if fits and fewer than MAX_TARGETS are taken, else held
--     (plan_frame: a held job does not stop a later, smaller one);
--   an add's init job (o_add = '1'): ADD_FULL (1) if o_full (MAX_TARGETS targets live: the top
--     counts them, held ones included), else ADD_CYCLES (2) if not fits, else ADD_OK (0) (check_add).
-- A taken job (a live one taken, an add OK) adds c to sum and its slack to min_slack.  `clear`
-- starts a frame (sum 0, min_slack all ones, none taken).  sum and min_slack are outputs (plan.clocks,
-- plan.budget once every job is offered; min_slack all ones when none was taken).
-- The timing comes in as ports (frame_lines, line_clocks, blank_clocks = (frame lines - active lines)
-- line clocks), so one core serves any video mode; the product is a shift-and-add over LC_W clocks.
-- Latency: offer -> done LC_W + 3 clocks (16 at LC_W 13).  Throughput: one offer per LC_W + 4 clocks
-- (`ready`).
-- Handshake: an offer is taken when ready = '1'; done pulses with taken / code; clear when ready.
-- Python model: mstrack.fixed.multi_capacity.plan_frame / check_add (tb/test_ms_admit.py).
-- Reset: synchronous, active high: ready, none taken.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_admit is
  generic (
    MAX_TARGETS : positive := 16;   -- jobs a frame can take (the core's MAX_TARGETS)
    CLK_W       : positive := 24;   -- a job's clocks
    LINE_W      : positive := 12;   -- frame lines, release and next lines
    LC_W        : positive := 13;   -- clocks per line
    SUM_W       : positive := 28    -- sum of clocks, slacks (>= LINE_W + 1 + LC_W)
  );
  port (
    clk          : in  std_logic;                             -- clock
    rst          : in  std_logic;                             -- synchronous reset, active high
    frame_lines  : in  unsigned(LINE_W - 1 downto 0);         -- lines per frame, blanking included (1125)
    line_clocks  : in  unsigned(LC_W - 1 downto 0);           -- clocks per line (2200)
    blank_clocks : in  unsigned(SUM_W - 1 downto 0);          -- vertical blanking in clocks (99,000)
    clear        : in  std_logic;                             -- start a frame's plan
    offer        : in  std_logic;                             -- a job: o_*
    o_add        : in  std_logic;                             -- '1': an add's init job
    o_full       : in  std_logic;                             -- (adds) MAX_TARGETS targets are live
    o_clocks     : in  unsigned(CLK_W - 1 downto 0);          -- its worst-case clocks
    o_release    : in  unsigned(LINE_W - 1 downto 0);         -- its release line
    o_next       : in  unsigned(LINE_W - 1 downto 0);         -- its next line
    ready        : out std_logic;                             -- an offer or a clear can be taken
    done         : out std_logic;                             -- pulse: the verdict of the last offer
    taken        : out std_logic;                             -- a live job taken / an add ok
    code         : out unsigned(1 downto 0);                  -- adds: 0 ok, 1 full, 2 cycles; live: 0 taken, 2 held
    sum          : out unsigned(SUM_W - 1 downto 0);          -- clocks of the jobs taken
    min_slack    : out unsigned(SUM_W - 1 downto 0)           -- smallest slack among them
  );
end entity;

architecture rtl of ms_admit is
  type state_t is (S_IDLE, S_MUL, S_CMP, S_MIN, S_DONE);
  signal state     : state_t := S_IDLE;
  signal n_taken   : natural range 0 to MAX_TARGETS := 0;
  signal acc       : unsigned(SUM_W - 1 downto 0);       -- lines * line_clocks, built bit by bit
  signal mcand     : unsigned(SUM_W - 1 downto 0);       -- lines, shifted left each step
  signal mplier    : unsigned(LC_W - 1 downto 0);        -- line_clocks, shifted right each step
  signal step      : natural range 0 to LC_W := 0;
  signal j_add, j_full : std_logic;
  signal j_clocks  : unsigned(SUM_W - 1 downto 0);
  signal slack_r, total_r, budget_r : unsigned(SUM_W - 1 downto 0);
  signal sum_r, min_r : unsigned(SUM_W - 1 downto 0);
begin
  assert SUM_W >= LINE_W + 1 + LC_W and SUM_W > CLK_W report "ms_admit: SUM_W too small" severity failure;

  p_admit : process (clk)
    variable fits : boolean;
  begin
    if rising_edge(clk) then
      done <= '0';
      case state is
        when S_IDLE =>
          if clear = '1' then
            sum_r   <= (others => '0');
            min_r   <= (others => '1');
            n_taken <= 0;
          elsif offer = '1' then
            -- lines from the end of this region to the start of the next one (release <= frame lines)
            mcand    <= resize(frame_lines - o_release - 1, SUM_W) + o_next;
            mplier   <= line_clocks;
            acc      <= (others => '0');
            step     <= 0;
            j_add    <= o_add;
            j_full   <= o_full;
            j_clocks <= resize(o_clocks, SUM_W);
            state    <= S_MUL;
          end if;
        when S_MUL =>                                  -- one bit of line_clocks per clock
          if mplier(0) = '1' then
            acc <= acc + mcand;
          end if;
          mcand  <= shift_left(mcand, 1);
          mplier <= shift_right(mplier, 1);
          step   <= step + 1;
          if step = LC_W - 1 then
            state <= S_CMP;
          end if;
        when S_CMP =>                                  -- one carry chain per clock from here
          if acc > blank_clocks then
            slack_r <= acc;
          else
            slack_r <= blank_clocks;
          end if;
          total_r <= sum_r + j_clocks;
          state <= S_MIN;
        when S_MIN =>
          if slack_r < min_r then
            budget_r <= slack_r;
          else
            budget_r <= min_r;
          end if;
          state <= S_DONE;
        when S_DONE =>
          fits := total_r <= budget_r;
          done <= '1';
          if j_add = '1' then
            if j_full = '1' then
              code <= to_unsigned(1, 2);
              fits := false;
            elsif fits then
              code <= to_unsigned(0, 2);
            else
              code <= to_unsigned(2, 2);
            end if;
          else
            fits := fits and n_taken < MAX_TARGETS;
            code <= to_unsigned(0, 2) when fits else to_unsigned(2, 2);
          end if;
          taken <= '1' when fits else '0';
          if fits then
            sum_r <= total_r;
            min_r <= budget_r;
            if n_taken < MAX_TARGETS then
              n_taken <= n_taken + 1;
            end if;
          end if;
          state <= S_IDLE;
      end case;
      if rst = '1' then
        state   <= S_IDLE;
        done    <= '0';
        sum_r   <= (others => '0');
        min_r   <= (others => '1');
        n_taken <= 0;
      end if;
    end if;
  end process;
  ready     <= '1' when state = S_IDLE else '0';
  sum       <= sum_r;
  min_slack <= min_r;
end architecture;
