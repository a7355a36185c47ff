-- ms_job_clocks: the worst-case clocks of one target's job on the shared engine of the
-- multi-target core (mstrack.fixed.multi_capacity.job_clocks), what ms_admit checks against the
-- frame's slack.
--
-- Computes, with pp(w, h) the worst pixel pass of a w x h window (ms_pass_clocks, instantiated here):
--   track: C_TRACK + M_TRACK pp(wd, hd) + scale
--   lost : C_LOST  + M_LOST  pp(wd, hd) + scale
--   init : C_INIT  +         pp(wd, hd) + ring_rows ring_cols
--   scale = C_SCALE + 2 pp(up(wd), up(hd)) when SCALE_PERMILLE > 0 (the gated scale test's larger
--           window), up(s) = min(lim, ceil(s (1000 + SCALE_PERMILLE) / 1000)); 0 otherwise.
-- The constants come from mstrack.hw.multi_core.job_clocks_generics(tp, costs) (the engine's step
-- clocks: bin pass, centre, Qw load, v2 per-frame work, state record in and out).
-- Handshake: `start` with kind, wd, hd, lim, ring_rows, ring_cols, taken when busy = '0'; `done`
-- pulses with `clocks` (held until the next done).
-- Latency: one or two ms_pass_clocks runs + a few clocks (at most 453 clocks at LANES 4 with the
-- scale test, 234 without; the products pp x M and the ring, shift-and-add, run beside them).
-- Python model: mstrack.fixed.multi_capacity.job_clocks (tb/test_ms_job_clocks.py).
-- Reset: synchronous, active high.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_job_clocks is
  generic (
    LANES          : positive := 4;
    HALF_W         : natural := 6;       -- windows up to 2**(HALF_W + 1) - 1 px
    PASS_LAT       : natural := 10;
    COORD_W        : natural := 12;      -- ring rows and columns
    CLK_W          : natural := 24;      -- width of clocks
    M_TRACK        : natural := 21;      -- passes of a tracking job (max_iter + 1)
    C_TRACK        : natural := 13254;
    M_LOST         : natural := 54;      -- passes of a lost job (9 start points x (search_iter + 1))
    C_LOST         : natural := 32591;
    C_INIT         : natural := 15826;
    SCALE_PERMILLE : natural := 50;      -- round(1000 scale_test); 0: no scale test
    C_SCALE        : natural := 2870
  );
  port (
    clk       : in  std_logic;
    rst       : in  std_logic;
    start     : in  std_logic;                          -- pulse: a job
    kind      : in  unsigned(1 downto 0);               -- 0 track, 1 lost, 2 init
    wd, hd    : in  unsigned(HALF_W downto 0);          -- its window (decimated px)
    lim       : in  unsigned(HALF_W downto 0);          -- the window limit min(max_window, dw - 2, dh - 2)
    ring_rows : in  unsigned(COORD_W - 1 downto 0);     -- init: the box and ring rectangle
    ring_cols : in  unsigned(COORD_W - 1 downto 0);
    busy      : out std_logic;
    done      : out std_logic;                          -- pulse: clocks valid
    clocks    : out unsigned(CLK_W - 1 downto 0)
  );
end entity;

architecture rtl of ms_job_clocks is
  constant SW : natural := HALF_W + 1;
  type up_t is array (0 to 2 ** SW - 1) of natural;
  function up_table return up_t is
    variable t : up_t;
  begin
    for s in t'range loop
      t(s) := (s * (1000 + SCALE_PERMILLE) + 999) / 1000;   -- ceil(s (1000 + st) / 1000)
    end loop;
    return t;
  end function;
  constant UP : up_t := up_table;

  type state_t is (S_IDLE, S_PP1, S_PP2, S_MUL, S_SUM, S_OUT);
  signal state  : state_t := S_IDLE;
  signal pc_start, pc_busy, pc_done : std_logic;
  signal pc_w, pc_h : unsigned(SW - 1 downto 0);
  signal pc_clocks  : unsigned(15 downto 0);
  signal k_r        : unsigned(1 downto 0);
  signal lim_r      : unsigned(SW - 1 downto 0);
  signal wd_r, hd_r : unsigned(SW - 1 downto 0);
  signal pp1, pp2   : unsigned(15 downto 0);
  -- ring product, shift-and-add
  signal r_acc, r_mc : unsigned(2 * COORD_W - 1 downto 0);
  signal r_mp       : unsigned(COORD_W - 1 downto 0);
  signal base_r, var_r : unsigned(CLK_W - 1 downto 0);
  -- pp1 x M (M_TRACK, M_LOST or 1 by kind), shift-and-add: no multiplier block between registers
  constant MW : natural := bits_for(maximum(M_TRACK, M_LOST));
  signal p_acc, p_mc : unsigned(CLK_W - 1 downto 0);
  signal p_mp       : unsigned(MW - 1 downto 0);

  function upl(s, l : unsigned) return unsigned is
    variable u : natural := UP(to_integer(s));
  begin
    if u > to_integer(l) then
      u := to_integer(l);
    end if;
    return to_unsigned(u, SW);
  end function;
begin
  u_pc : entity work.ms_pass_clocks
    generic map (LANES => LANES, HALF_W => HALF_W, PASS_LAT => PASS_LAT, KD_W => 29, OUT_W => 16)
    port map (clk => clk, rst => rst, start => pc_start, w => pc_w, h => pc_h, busy => pc_busy,
              done => pc_done, clocks => pc_clocks);

  p_job : process (clk)
  begin
    if rising_edge(clk) then
      done     <= '0';
      pc_start <= '0';
      -- the ring product runs beside the passes (one bit of ring_cols per clock)
      if r_mp /= 0 then
        if r_mp(0) = '1' then
          r_acc <= r_acc + r_mc;
        end if;
        r_mc <= shift_left(r_mc, 1);
        r_mp <= shift_right(r_mp, 1);
      end if;
      if state /= S_IDLE and state /= S_PP1 and p_mp /= 0 then
        if p_mp(0) = '1' then
          p_acc <= p_acc + p_mc;
        end if;
        p_mc <= shift_left(p_mc, 1);
        p_mp <= shift_right(p_mp, 1);
      end if;
      case state is
        when S_IDLE =>
          if start = '1' then
            k_r      <= kind;
            lim_r    <= lim;
            wd_r     <= wd;
            hd_r     <= hd;
            pc_w     <= wd;
            pc_h     <= hd;
            pc_start <= '1';
            r_acc    <= (others => '0');
            r_mc     <= resize(ring_rows, 2 * COORD_W);
            if kind = 2 then
              r_mp <= ring_cols;
            else
              r_mp <= (others => '0');
            end if;
            state <= S_PP1;
          end if;
        when S_PP1 =>
          if pc_done = '1' then
            pp1 <= pc_clocks;
            pp2 <= (others => '0');
            p_acc <= (others => '0');
            p_mc  <= resize(pc_clocks, CLK_W);
            case to_integer(k_r) is
              when 0 => p_mp <= to_unsigned(M_TRACK, MW);
              when 1 => p_mp <= to_unsigned(M_LOST, MW);
              when others => p_mp <= to_unsigned(1, MW);
            end case;
            if SCALE_PERMILLE > 0 and k_r /= 2 then
              pc_w     <= upl(wd_r, lim_r);
              pc_h     <= upl(hd_r, lim_r);
              pc_start <= '1';
              state    <= S_PP2;
            else
              state <= S_MUL;
            end if;
          end if;
        when S_PP2 =>
          if pc_done = '1' then
            pp2   <= pc_clocks;
            state <= S_MUL;
          end if;
        when S_MUL =>                              -- pp1 x M runs from S_PP1 on (beside the second pass)
          if p_mp = 0 and r_mp = 0 then            -- both products done
            state <= S_SUM;
          end if;
        when S_SUM =>                              -- the constant and the window's term
          case to_integer(k_r) is
            when 0 => base_r <= to_unsigned(C_TRACK, CLK_W) + p_acc;
            when 1 => base_r <= to_unsigned(C_LOST, CLK_W) + p_acc;
            when others => base_r <= to_unsigned(C_INIT, CLK_W) + p_acc;
          end case;
          if k_r = 2 then
            var_r <= resize(r_acc, CLK_W);
          elsif SCALE_PERMILLE > 0 then
            var_r <= to_unsigned(C_SCALE, CLK_W) + shift_left(resize(pp2, CLK_W), 1);
          else
            var_r <= (others => '0');
          end if;
          state <= S_OUT;
        when S_OUT =>
          clocks <= base_r + var_r;
          done   <= '1';
          state  <= S_IDLE;
      end case;
      if rst = '1' then
        state    <= S_IDLE;
        done     <= '0';
        pc_start <= '0';
        r_mp     <= (others => '0');
        p_mp     <= (others => '0');
      end if;
    end if;
  end process;
  busy <= '0' when state = S_IDLE else '1';
end architecture;
