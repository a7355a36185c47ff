-- ms_job_demand: one live target's job on its next frame, from its state record, for the capacity
-- rule (ms_admit) and the target's capture (ms_slot_capture) of the shared-engine multi-target core
-- (model: mstrack.fixed.multi_capacity.ms_job_demand; docs/multi_target_core.md, "Capacity rule").
--
-- Computes, from the size w8, h8 (Q.8 px), the centre c8 (Q.CF px), lost and the frame size, in
-- three geometry passes on one ms_decimation, two ms_window_size and one ms_region_v2 (the blocks
-- core v2 uses before a frame, so the numbers are core v2's):
--   A  this frame: log2 D = ms_decimation(w8, h8) (+ 1 while lost), the decimated frame
--      ((S - 1) >> log2 D) + 1, the windows wd, hd (limit min(MAX_WINDOW, S_d - 2)), the search
--      offsets (STEP16 wd) >> 4, (STEP16 hd) >> 4 and the region around c8 >> log2 D with its margin;
--      from it, the job's worst clocks (ms_job_clocks: kind lost or track, the window limit
--      min(MAX_WINDOW, dw - 2, dh - 2)), first_line = reg_y D, the release line
--      min((reg_y + reg_h) D + 1, frame_h) and lo = (reg_y + ey) D (the highest window centre);
--   B  the next frame tracked with the size grown by scale_step: w8g = min((w8 G) >> 16, frame_w 256),
--      G = 2**16 + GROW_Q16 (h8g alike), not lost;
--   C  the next frame searched: (w8, h8) lost (2 x the base D);
--   next_line = max(0, lo - max over B, C of (e_y + margin + 1) D), the earliest line the next
--   region can start on.
-- The products w8 G are shift-and-add, one bit of G per clock (no multiplier block); at most one carry
-- chain after a barrel shift per clock.
-- Latency: about 3 x 18 clocks of geometry + 18 of the grown sizes, beside ms_job_clocks (at most
-- 453 clocks at LANES 4 with the scale test): `done` when both are in.
-- Throughput: one job per run; `start` is taken when busy = '0'.
-- Handshake: start with the inputs (sampled on that clock), busy while running, done pulses one
-- clock with the outputs (held until the next done).
-- Reset: synchronous, active high.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_job_demand is
  generic (
    COORD_W        : natural := 12;     -- frame coordinate bits
    CF             : natural := 8;      -- centre fraction bits
    PAD16          : natural := 4;      -- window padding in 1/16
    MAX_WINDOW     : natural := 127;    -- largest window (decimated px)
    HALF_W         : natural := 6;      -- window half extent bits (MAX_WINDOW <= 2**(HALF_W + 1) - 1)
    REGION_W       : natural := 9;      -- region size bits
    MARGIN         : natural := 32;     -- search margin
    MARGIN_MAX     : natural := 255;    -- largest margin while lost
    STEP16         : natural := 16;     -- search_step in 1/16
    GROW_Q16       : natural := 6554;   -- scale_step in Q.16 (the next frame's size at most x (1 + scale_step))
    -- ms_job_clocks (mstrack.hw.multi_core.job_clocks_generics)
    LANES          : positive := 4;
    PASS_LAT       : natural := 10;
    CLK_W          : natural := 24;
    M_TRACK        : natural := 21;
    C_TRACK        : natural := 13254;
    M_LOST         : natural := 54;
    C_LOST         : natural := 32591;
    C_INIT         : natural := 15826;
    SCALE_PERMILLE : natural := 50;
    C_SCALE        : natural := 2870
  );
  port (
    clk        : in  std_logic;
    rst        : in  std_logic;
    start      : in  std_logic;                               -- a target's state: the inputs below
    w8, h8     : in  unsigned(COORD_W + 7 downto 0);          -- size, Q.8 px
    c8x, c8y   : in  unsigned(COORD_W + CF - 1 downto 0);     -- centre, Q.CF px
    lost       : in  std_logic;                               -- searching
    frame_w    : in  unsigned(COORD_W - 1 downto 0);
    frame_h    : in  unsigned(COORD_W - 1 downto 0);
    busy       : out std_logic;
    done       : out std_logic;                               -- pulse: the outputs below are valid
    log2_d     : out unsigned(2 downto 0);                    -- the job's D
    wd, hd     : out unsigned(HALF_W downto 0);               -- its window
    reg_x      : out unsigned(COORD_W - 1 downto 0);          -- its region (decimated px)
    reg_y      : out unsigned(COORD_W - 1 downto 0);
    reg_w      : out unsigned(REGION_W - 1 downto 0);
    reg_h      : out unsigned(REGION_W - 1 downto 0);
    clocks     : out unsigned(CLK_W - 1 downto 0);            -- worst-case job clocks
    first_line : out unsigned(COORD_W - 1 downto 0);          -- reg_y D
    release_line : out unsigned(COORD_W - 1 downto 0);          -- the region has streamed in after this line
    next_line  : out unsigned(COORD_W - 1 downto 0)           -- the next region starts on or below it
  );
end entity;

architecture rtl of ms_job_demand is
  constant S8_W  : natural := COORD_W + 8;
  constant WIN_W : natural := HALF_W + 1;
  constant G     : natural := 2 ** 16 + GROW_Q16;
  constant G_W   : natural := bits_for(G);
  constant LW    : natural := COORD_W + 6;                   -- lines x D, spans x D
  type state_t is (S_IDLE, S_GROW, S_DEC, S_DEC_WAIT, S_DIM, S_DIM2, S_WS, S_WS_WAIT, S_RG, S_RG_WAIT, S_SPAN,
                   S_SPAN2, S_NEXT,
                   S_CLK_WAIT, S_DONE);
  signal state : state_t := S_IDLE;
  signal pass  : natural range 0 to 2 := 0;                  -- A, B, C
  -- the inputs
  signal w8_r, h8_r, w8g, h8g : unsigned(S8_W - 1 downto 0);
  signal cx_r, cy_r : unsigned(COORD_W + CF - 1 downto 0);
  signal lost_r     : std_logic;
  signal fw_r, fh_r : unsigned(COORD_W - 1 downto 0);
  signal fw_m1, fh_m1 : unsigned(COORD_W - 1 downto 0);      -- frame size - 1
  -- the grown sizes, shift-and-add over the bits of G
  signal gb         : natural range 0 to G_W := 0;
  signal g_sh       : unsigned(G_W - 1 downto 0);            -- G, shifted right one bit per clock
  signal acc_w, acc_h, mc_w, mc_h : unsigned(S8_W + G_W - 1 downto 0);
  -- one geometry pass
  signal p_lost     : std_logic;
  signal dec_in, dec_out : std_logic := '0';
  signal dec_l2     : unsigned(1 downto 0);
  signal s8w, s8h   : unsigned(S8_W - 1 downto 0);
  signal l2d        : unsigned(2 downto 0);
  signal dw, dh     : unsigned(COORD_W - 1 downto 0);
  signal dw2, dh2   : unsigned(COORD_W - 1 downto 0);        -- dw - 2, dh - 2
  signal lim_w, lim_h : unsigned(WIN_W - 1 downto 0);
  signal ws_in, ws_w_valid, ws_h_valid : std_logic := '0';
  signal ws_w, ws_h : unsigned(WIN_W - 1 downto 0);
  signal wd_r, hd_r : unsigned(WIN_W - 1 downto 0);
  signal ex, ey     : unsigned(HALF_W - 1 downto 0);
  signal ox, oy     : unsigned(COORD_W - 1 downto 0);
  signal cxd, cyd   : unsigned(COORD_W + CF - 1 downto 0);
  signal rv_in, rv_out : std_logic := '0';
  signal rv_x, rv_y : unsigned(COORD_W - 1 downto 0);
  signal rv_w, rv_h, rv_hx, rv_hy : unsigned(REGION_W - 1 downto 0);
  signal rv_m       : unsigned(COORD_W - 1 downto 0);
  -- pass A's results and the spans
  signal lo_line    : unsigned(LW - 1 downto 0);
  signal sum_a, sum_lo, sum_sp : unsigned(LW - 1 downto 0);  -- reg_y + reg_h, reg_y + e_y, e_y + margin + 1
  signal lines_r, span_r : unsigned(LW - 1 downto 0);          -- sum_a D, sum_sp D
  signal half_max   : unsigned(LW - 1 downto 0);
  -- ms_job_clocks
  signal jc_start, jc_busy, jc_done : std_logic := '0';
  signal jc_kind    : unsigned(1 downto 0);
  signal jc_lim     : unsigned(WIN_W - 1 downto 0);
  signal jc_clocks  : unsigned(CLK_W - 1 downto 0);
  signal jc_have    : std_logic := '0';

  function umin(a, b : unsigned) return unsigned is
  begin
    if a < b then return a; else return b; end if;
  end function;
begin
  assert MAX_WINDOW <= 2 ** WIN_W - 1 report "ms_job_demand: MAX_WINDOW needs HALF_W + 1 bits" severity failure;

  u_dec : entity work.ms_decimation
    generic map (S8_W => S8_W, PAD16 => PAD16, MAX_WINDOW => MAX_WINDOW)
    port map (clk => clk, rst => rst, in_valid => dec_in, w8 => s8w, h8 => s8h, out_valid => dec_out,
              log2_d => dec_l2);
  u_wsw : entity work.ms_window_size
    generic map (S8_W => S8_W, PAD16 => PAD16, N_W => WIN_W)
    port map (clk => clk, rst => rst, in_valid => ws_in, s8 => s8w, log2_d => l2d, limit => lim_w,
              out_valid => ws_w_valid, n => ws_w);
  u_wsh : entity work.ms_window_size
    generic map (S8_W => S8_W, PAD16 => PAD16, N_W => WIN_W)
    port map (clk => clk, rst => rst, in_valid => ws_in, s8 => s8h, log2_d => l2d, limit => lim_h,
              out_valid => ws_h_valid, n => ws_h);
  u_region : entity work.ms_region_v2
    generic map (COORD_W => COORD_W, CF => CF, HALF_W => HALF_W, REGION_W => REGION_W, MARGIN => MARGIN,
                 MARGIN_MAX => MARGIN_MAX)
    port map (clk => clk, rst => rst, in_valid => rv_in, cx => cxd, cy => cyd, ex => ex, ey => ey,
              ox => ox, oy => oy, lost => p_lost, frame_w => dw, frame_h => dh, out_valid => rv_out,
              reg_x => rv_x, reg_y => rv_y, reg_w => rv_w, reg_h => rv_h, hi_x => rv_hx, hi_y => rv_hy,
              region_margin => rv_m);
  u_clocks : entity work.ms_job_clocks
    generic map (LANES => LANES, HALF_W => HALF_W, PASS_LAT => PASS_LAT, COORD_W => COORD_W, CLK_W => CLK_W,
                 M_TRACK => M_TRACK, C_TRACK => C_TRACK, M_LOST => M_LOST, C_LOST => C_LOST, C_INIT => C_INIT,
                 SCALE_PERMILLE => SCALE_PERMILLE, C_SCALE => C_SCALE)
    port map (clk => clk, rst => rst, start => jc_start, kind => jc_kind, wd => wd_r, hd => hd_r, lim => jc_lim,
              ring_rows => to_unsigned(3, COORD_W), ring_cols => to_unsigned(3, COORD_W), busy => jc_busy,
              done => jc_done, clocks => jc_clocks);

  p_main : process (clk)
  begin
    if rising_edge(clk) then
      done     <= '0';
      dec_in   <= '0';
      ws_in    <= '0';
      rv_in    <= '0';
      jc_start <= '0';
      if jc_done = '1' then
        clocks  <= jc_clocks;
        jc_have <= '1';
      end if;
      case state is
        when S_IDLE =>                         -- the inputs every clock (their enable is the state
          w8_r <= w8; h8_r <= h8; cx_r <= c8x; cy_r <= c8y; lost_r <= lost; fw_r <= frame_w; fh_r <= frame_h;
          fw_m1 <= frame_w - 1; fh_m1 <= frame_h - 1;  -- alone): held from start's clock on
          acc_w <= (others => '0'); acc_h <= (others => '0'); gb <= 0;
          mc_w <= resize(w8, S8_W + G_W); mc_h <= resize(h8, S8_W + G_W);
          g_sh <= to_unsigned(G, G_W);
          half_max <= (others => '0');
          pass <= 0;
          if start = '1' then
            jc_have <= '0';
            state <= S_GROW;
          end if;

        when S_GROW =>                         -- w8 G, h8 G: one bit of G per clock
          if gb = G_W then
            w8g <= resize(umin(shift_right(acc_w, 16), resize(fw_r & x"00", S8_W + G_W)), S8_W);
            h8g <= resize(umin(shift_right(acc_h, 16), resize(fh_r & x"00", S8_W + G_W)), S8_W);
            state <= S_DEC;
          else
            if g_sh(0) = '1' then
              acc_w <= acc_w + mc_w;
              acc_h <= acc_h + mc_h;
            end if;
            mc_w <= shift_left(mc_w, 1);
            mc_h <= shift_left(mc_h, 1);
            g_sh <= shift_right(g_sh, 1);
            gb <= gb + 1;
          end if;

        when S_DEC =>                          -- the pass's size and search state
          if pass = 1 then
            s8w <= w8g; s8h <= h8g; p_lost <= '0';
          else
            s8w <= w8_r; s8h <= h8_r;
            if pass = 0 then p_lost <= lost_r; else p_lost <= '1'; end if;
          end if;
          dec_in <= '1';
          state <= S_DEC_WAIT;

        when S_DEC_WAIT =>
          if dec_out = '1' then
            if p_lost = '1' then l2d <= resize(dec_l2, 3) + 1; else l2d <= resize(dec_l2, 3); end if;
            state <= S_DIM;
          end if;

        when S_DIM =>                          -- the decimated frame, the centre
          dw <= shift_right(fw_m1, to_integer(l2d)) + 1;
          dh <= shift_right(fh_m1, to_integer(l2d)) + 1;
          cxd <= shift_right(cx_r, to_integer(l2d));
          cyd <= shift_right(cy_r, to_integer(l2d));
          state <= S_DIM2;

        when S_DIM2 =>
          dw2 <= dw - 2;
          dh2 <= dh - 2;
          state <= S_WS;

        when S_WS =>                           -- the window limits min(MAX_WINDOW, S_d - 2)
          lim_w <= resize(umin(dw2, to_unsigned(MAX_WINDOW, COORD_W)), WIN_W);
          lim_h <= resize(umin(dh2, to_unsigned(MAX_WINDOW, COORD_W)), WIN_W);
          ws_in <= '1';                        -- ms_window_size takes the limits the next clock
          state <= S_WS_WAIT;

        when S_WS_WAIT =>
          if ws_w_valid = '1' then
            wd_r <= ws_w;
            hd_r <= ws_h;
            ex <= resize(shift_right(ws_w - 1, 1), HALF_W);
            ey <= resize(shift_right(ws_h - 1, 1), HALF_W);
            ox <= resize(shift_right(resize(ws_w, COORD_W + 6) * STEP16, 4), COORD_W);
            oy <= resize(shift_right(resize(ws_h, COORD_W + 6) * STEP16, 4), COORD_W);
            state <= S_RG;
          end if;

        when S_RG =>
          rv_in <= '1';
          if pass = 0 then                     -- the job's clocks, beside the rest
            jc_start <= '1';
            if lost_r = '1' then jc_kind <= "01"; else jc_kind <= "00"; end if;
            jc_lim <= umin(lim_w, lim_h);
          end if;
          state <= S_RG_WAIT;

        when S_RG_WAIT =>
          if rv_out = '1' then
            if pass = 0 then
              log2_d <= l2d;
              wd <= wd_r; hd <= hd_r;
              reg_x <= rv_x; reg_y <= rv_y; reg_w <= rv_w; reg_h <= rv_h;
              first_line <= resize(shift_left(resize(rv_y, LW), to_integer(l2d)), COORD_W);
            end if;
            sum_a  <= resize(rv_y, LW) + resize(rv_h, LW);
            sum_lo <= resize(rv_y, LW) + resize(ey, LW);
            sum_sp <= resize(ey, LW) + resize(rv_m, LW) + 1;
            state <= S_SPAN;
          end if;

        when S_SPAN =>                         -- x D
          lines_r <= shift_left(sum_a, to_integer(l2d));
          span_r  <= shift_left(sum_sp, to_integer(l2d));
          if pass = 0 then
            lo_line <= shift_left(sum_lo, to_integer(l2d));
          end if;
          state <= S_SPAN2;

        when S_SPAN2 =>                        -- A: the release line; B, C: the span (e_y + margin + 1) D
          if pass = 0 then
            if lines_r >= resize(fh_r, LW) then  -- release = min(lines + 1, frame_h)
              release_line <= fh_r;
            else
              release_line <= resize(lines_r + 1, COORD_W);
            end if;
          elsif span_r > half_max then
            half_max <= span_r;
          end if;
          if pass = 2 then
            state <= S_NEXT;
          else
            pass <= pass + 1;
            state <= S_DEC;
          end if;

        when S_NEXT =>
          if lo_line > half_max then
            next_line <= resize(lo_line - half_max, COORD_W);
          else
            next_line <= (others => '0');
          end if;
          state <= S_CLK_WAIT;

        when S_CLK_WAIT =>
          if jc_have = '1' or jc_done = '1' then
            state <= S_DONE;
          end if;

        when S_DONE =>
          done  <= '1';
          state <= S_IDLE;
      end case;
      if rst = '1' then
        state   <= S_IDLE;
        done    <= '0';
        dec_in  <= '0';
        ws_in   <= '0';
        rv_in   <= '0';
        jc_start <= '0';
        jc_have <= '0';
      end if;
    end if;
  end process;
  busy <= '0' when state = S_IDLE else '1';
end architecture;
