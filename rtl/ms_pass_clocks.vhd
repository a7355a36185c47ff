-- ms_pass_clocks: the worst-case clocks of one pixel pass over a w x h window (flat kernel) at the
-- worst LANES alignment: the job-clock term of the capacity rule that depends on the window
-- (mstrack.fixed.multi_capacity.pixel_pass_clocks), for the shared-engine multi-target core.
--
-- Computes: with ex = (w - 1) / 2, ey = (h - 1) / 2 and XR[i] the kernel ellipse's row extent
-- (ms_kernel_tables, instantiated here: the largest |dx| inside row |dy| = i, 0 when none),
--   groups_a(i) = (ex + a + XR[i]) / LANES - (ex + a - XR[i]) / LANES + 1      (a = 0 .. LANES - 1)
--   clocks = max over a of sum over dy = -ey .. ey of groups_a(|dy|), + PASS_LAT
-- i.e. the LANES groups ms_window_scan visits per row, summed over the rows, with the window's left
-- edge at each alignment; the worst one, plus the pass latency (ms_pixel_pass's PASS_LAT).
-- Handshake: `start` with (w, h), 3 <= w, h <= 2**(HALF_W + 1) - 1, taken when busy = '0'; `done`
-- pulses with `clocks` (held until the next done).
-- Latency: ms_kernel_tables' flat latency (at most 215 clocks at HALF_W 6) + LANES + 5 clocks (a
-- 3-stage sum, then the worst alignment one accumulator per clock).
-- Throughput: one window per start -> done.
-- Cost: ms_kernel_tables (flat: no divider) + LANES accumulators.
-- Python model: mstrack.fixed.multi_capacity.pixel_pass_clocks(w, h, LANES, PASS_LAT).
-- Reset: synchronous, active high.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_pass_clocks is
  generic (
    LANES    : positive := 4;     -- pixels per clock of the pass (power of two)
    HALF_W   : natural := 6;      -- width of ex, ey; w, h have HALF_W + 1 bits
    PASS_LAT : natural := 10;     -- ms_pixel_pass' latency after the last row group
    KD_W     : natural := 29;     -- ms_kernel_tables' TA / TB / D width
    OUT_W    : natural := 16      -- width of clocks
  );
  port (
    clk    : in  std_logic;                          -- clock
    rst    : in  std_logic;                          -- synchronous reset, active high
    start  : in  std_logic;                          -- pulse: a w x h window
    w      : in  unsigned(HALF_W downto 0);          -- window width in px (odd, 3 ..)
    h      : in  unsigned(HALF_W downto 0);          -- window height in px
    busy   : out std_logic;                          -- computing
    done   : out std_logic;                          -- pulse: clocks valid
    clocks : out unsigned(OUT_W - 1 downto 0)        -- worst-case pixel pass clocks
  );
end entity;

architecture rtl of ms_pass_clocks is
  constant LOG2L : natural := log2_lanes(LANES);
  type acc_arr is array (0 to LANES - 1) of unsigned(OUT_W - 1 downto 0);
  signal acc     : acc_arr;
  signal kt_we   : std_logic;
  signal kt_addr : unsigned(HALF_W - 1 downto 0);
  signal kt_xr   : unsigned(HALF_W - 1 downto 0);
  signal kt_done, kt_busy : std_logic;
  signal run     : std_logic := '0';
  signal fin     : std_logic_vector(3 downto 0) := (others => '0');  -- done, delayed past the pipeline
  type grp_arr is array (0 to LANES - 1) of unsigned(HALF_W + 1 downto 0);
  signal hi1, lo1, g2 : grp_arr;
  signal v1, v2, dbl1, dbl2 : std_logic := '0';
  signal best_r  : unsigned(OUT_W - 1 downto 0);
  signal idx     : natural range 0 to LANES := 0;
  signal pick    : std_logic := '0';

  signal ex_r, ey_r : unsigned(HALF_W - 1 downto 0);
  signal t_start : std_logic;
begin
  assert LANES = 2 ** LOG2L report "ms_pass_clocks: LANES must be a power of two" severity failure;

  u_tables : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KERNEL_EPAN => 0, KERNEL_BITS => 8, KVAL_W => 1, KD_W => KD_W)
    port map (clk => clk, rst => rst, start => t_start, w => w, h => h, busy => kt_busy,
              done => kt_done, ex => open, ey => open, kd_d => open, kt_we => kt_we, kt_addr => kt_addr,
              kt_ta => open, kt_tb => open, kt_ka => open, kt_kb => open, kt_xr => kt_xr);

  t_start <= start and not run;

  p_sum : process (clk)
  begin
    if rising_edge(clk) then
      done <= '0';
      fin  <= fin(fin'high - 1 downto 0) & '0';
      if start = '1' and run = '0' then
        run <= '1';
        for a in 0 to LANES - 1 loop
          acc(a) <= (others => '0');
        end loop;
        ex_r <= resize(shift_right(w - 1, 1), HALF_W);   -- (w - 1) / 2, (h - 1) / 2, as the tables'
        ey_r <= resize(shift_right(h - 1, 1), HALF_W);
      end if;
      -- stage 1: a table entry (rows dy = +-i, i <= ey; once for i = 0): the group ends per alignment
      v1   <= run and kt_we and to_sl(kt_addr <= ey_r);
      dbl1 <= to_sl(kt_addr /= 0);
      for a in 0 to LANES - 1 loop
        hi1(a) <= resize(ex_r, HALF_W + 2) + a + kt_xr;
        lo1(a) <= resize(ex_r, HALF_W + 2) + a - kt_xr;
      end loop;
      -- stage 2: the groups of the row
      v2   <= v1;
      dbl2 <= dbl1;
      for a in 0 to LANES - 1 loop
        g2(a) <= shift_right(hi1(a), LOG2L) - shift_right(lo1(a), LOG2L) + 1;
      end loop;
      -- stage 3: accumulate (twice for i > 0)
      if v2 = '1' then
        for a in 0 to LANES - 1 loop
          if dbl2 = '1' then
            acc(a) <= acc(a) + shift_left(resize(g2(a), OUT_W), 1);
          else
            acc(a) <= acc(a) + g2(a);
          end if;
        end loop;
      end if;
      if run = '1' and kt_done = '1' then
        fin(0) <= '1';                            -- the last entry was written before done
      end if;
      -- the worst alignment, one accumulator per clock, then + PASS_LAT
      if fin(fin'high) = '1' then                 -- the sum is in acc
        best_r <= acc(0);
        idx    <= 1;
        pick   <= '1';
      elsif pick = '1' then
        if idx < LANES then
          if acc(idx) > best_r then
            best_r <= acc(idx);
          end if;
          idx <= idx + 1;
        else
          clocks <= best_r + PASS_LAT;
          done   <= '1';
          run    <= '0';
          pick   <= '0';
        end if;
      end if;
      if rst = '1' then
        run  <= '0';
        done <= '0';
        v1   <= '0';
        v2   <= '0';
        fin  <= (others => '0');
        pick <= '0';
      end if;
    end if;
  end process;
  busy <= run;
end architecture;
