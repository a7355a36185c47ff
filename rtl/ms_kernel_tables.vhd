-- ms_kernel_tables: kernel tables of a w x h target (paper core: once per target, at init;
-- tracker v2: once per frame, for that frame's window wd x hd from ms_window_size, any size
-- 3 .. 2 MAX_HALF + 1, with KERNEL_EPAN = 1 since v2's target statistics need KA/KB with the flat
-- kernel; tb/test_ms_kernel_tables.py checks every such size, docs/blocks/ms_kernel_tables.md).
--
-- On `start` with the integer target size (w, h), 3 <= w, h <= 2 MAX_HALF + 1:
--   ex = (w - 1) / 2, ey = (h - 1) / 2, kd_d = D = w^2 h^2        (held until the next start)
-- and, for i = 0 .. max(ex, ey), one write on the table port:
--   kt_addr = i, kt_ta = TA[i] = 4 i^2 h^2, kt_tb = TB[i] = 4 i^2 w^2,
--   kt_ka = KA[i] = floor((4 i^2 << KERNEL_BITS) / w^2),
--   kt_kb = KB[i] = floor((4 i^2 << KERNEL_BITS) / h^2)   (KERNEL_EPAN = 1; 0 when flat),
--   kt_xr = XR[i] = the largest dx in 0 .. ex with TA[dx] + TB[i] < D, 0 if there is none
--           (row extent of the ellipse: XR[0] = ex, non-increasing; i <= ey always has dx = 0
--           inside; i > ey has none and gives 0).
-- Entries i > ex (TA, KA) or i > ey (TB, KB) are never used by ms_kernel (it tests
-- |dx| <= ex, |dy| <= ey): TA/TB are still exact there, KA/KB saturate at
-- 2**KVAL_W - 1 in the divider.  Then `done` pulses.
-- TA, TB are built by additions (TA[i+1] = TA[i] + 4 h^2 (2 i + 1)); KA, KB come from
-- one pipelined ms_divider shared by both (KA[i] issued, then KB[i]: 2 clocks per entry).
-- XR comes from a sequential walk with no multiplier and no comparator on a residual
-- R = D - 1 - TA[dx] - TB[i] (dx is outside row i when R < 0, its sign bit): a set-up
-- walk takes dx from 0 up to ex by additions (ex clocks), then, before entry i is issued,
-- dx walks down from XR[i-1] (one clock per step: TA[dx] - TA[dx-1] = 4 h^2 (2 dx - 1))
-- while dx > 0 and R < 0.  The down walk takes ex - XR[max(ex, ey)] steps in all.
--
-- w^2, h^2 and D = w^2 h^2 come from shift-and-add multiplications (no multiplier block:
-- a MULT18X18D between two registers limits Fmax to ~144 MHz): w^2 and h^2 together in
-- HALF_W + 1 clocks, D in 2 (HALF_W + 1) clocks.
--
-- Latency (start -> done), n = max(ex, ey), X = 2 ex - XR[n] (walk clocks), S = 3 (HALF_W + 1) + 3
-- (set-up: S_SETUP1, w^2 and h^2, S_DINIT, D, S_SETUP2):
-- flat n + S + 2 + X clocks; Epanechnikov 2 (n + 1) + KVAL_W + S + 2 + X clocks (issue 1 or 2
-- per entry, divider KVAL_W + 1, write register 1).  At most 215 (flat) / 289 (Epanechnikov,
-- KVAL_W 9) clocks for HALF_W = 6.  Speed is irrelevant (once per target).
-- Handshake: `start` pulse, ignored while busy; `done` pulse.
-- Model: mstrack.fixed.blocks.ms_kernel(w, h, kernel, KERNEL_BITS): .ex .ey .D .TA .TB .KA .KB
-- (XR[i] = max dx with ms_kernel.inside in row |dy| = i).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_kernel_tables is
  generic (
    HALF_W      : natural := 6;   -- width of ex, ey, table address; w, h have HALF_W + 1 bits
    KERNEL_EPAN : natural := 0;   -- 1: KA/KB through a KVAL_W-stage divider; 0: no divider, KA = KB = 0
    KERNEL_BITS : natural := 8;   -- KA, KB scale: 2**KERNEL_BITS
    KVAL_W      : natural := 1;   -- width of KA, KB (divider quotient bits)
    KD_W        : natural := 29   -- width of TA, TB, D
  );
  port (
    clk     : in  std_logic;                          -- clock
    rst     : in  std_logic;                          -- synchronous reset (control state)
    start   : in  std_logic;                          -- pulse: compute the tables of a w x h target
    w       : in  unsigned(HALF_W downto 0);          -- target width in px (3 .. 2 MAX_HALF + 1)
    h       : in  unsigned(HALF_W downto 0);          -- target height in px (3 .. 2 MAX_HALF + 1)
    busy    : out std_logic;                          -- computing
    done    : out std_logic;                          -- pulse: all entries written, ex/ey/kd_d valid
    ex      : out unsigned(HALF_W - 1 downto 0);      -- (w - 1) / 2
    ey      : out unsigned(HALF_W - 1 downto 0);      -- (h - 1) / 2
    kd_d    : out unsigned(KD_W - 1 downto 0);        -- D = w^2 h^2
    kt_we   : out std_logic;                          -- table write strobe
    kt_addr : out unsigned(HALF_W - 1 downto 0);      -- entry i
    kt_ta   : out unsigned(KD_W - 1 downto 0);        -- TA[i] = 4 i^2 h^2
    kt_tb   : out unsigned(KD_W - 1 downto 0);        -- TB[i] = 4 i^2 w^2
    kt_ka   : out unsigned(KVAL_W - 1 downto 0);      -- KA[i] (0 when flat)
    kt_kb   : out unsigned(KVAL_W - 1 downto 0);      -- KB[i] (0 when flat)
    kt_xr   : out unsigned(HALF_W - 1 downto 0)       -- XR[i]: last dx inside in row |dy| = i
  );
end entity;

architecture rtl of ms_kernel_tables is
  constant WW   : natural := HALF_W + 1;              -- w, h
  constant SQ_W : natural := 2 * WW;                  -- w^2, h^2
  constant T_W  : natural := KD_W + 2;                -- TA/TB accumulators and steps (headroom)
  constant N_W  : natural := 2 * HALF_W + 2 + KERNEL_BITS;  -- (4 i^2) << KERNEL_BITS
  constant TAG_W : natural := 2 * HALF_W + 1;         -- [sel | XR[i] | i], sel = 0 KA, 1 KB

  type state_t is (S_IDLE, S_SETUP1, S_SQ, S_DINIT, S_DMUL, S_SETUP2, S_XUP, S_ISSUE, S_WAIT);
  signal state : state_t := S_IDLE;

  signal wl, hl         : unsigned(WW - 1 downto 0) := (others => '0');
  signal w2, h2         : unsigned(SQ_W - 1 downto 0) := (others => '0');
  signal ex_r, ey_r     : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal n_last         : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal d_r            : unsigned(KD_W - 1 downto 0) := (others => '0');
  -- shift-and-add multiplications: w^2, h^2 (multiplicands mcw, mch, multipliers mpw, mph),
  -- then D = w^2 h^2 (multiplicand mcd = w^2 << j, multiplier mpd = h^2 >> j)
  signal mcw, mch       : unsigned(SQ_W - 1 downto 0) := (others => '0');
  signal mpw, mph       : unsigned(WW - 1 downto 0) := (others => '0');
  signal mcd            : unsigned(KD_W - 1 downto 0) := (others => '0');
  signal mpd            : unsigned(SQ_W - 1 downto 0) := (others => '0');
  signal cnt            : natural range 0 to SQ_W := 0;
  -- issue side
  signal i_iss          : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal sel            : std_logic := '0';
  signal sq4, sq4_step  : unsigned(N_W - 1 downto 0) := (others => '0');  -- 4 i^2, 8 i + 4
  -- write side
  signal ta_acc, tb_acc : unsigned(T_W - 1 downto 0) := (others => '0');
  signal ta_stp, tb_stp : unsigned(T_W - 1 downto 0) := (others => '0');
  signal ka_hold        : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  -- XR walk: xr = dx, xres = D - 1 - TA[xr] - TB[i_iss] (signed), xstp = TA[xr+1] - TA[xr]
  -- (S_XUP) / TA[xr] - TA[xr-1] (S_ISSUE), tbw_stp = TB[i_iss+1] - TB[i_iss]
  signal xr             : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal xr_nz          : std_logic := '0';           -- xr /= 0 (registered with xr)
  signal xup_last       : std_logic := '0';           -- S_XUP: this step is the last (xr + 1 = ex)
  signal xres           : signed(T_W downto 0) := (others => '0');
  signal xstp, tbw_stp  : unsigned(T_W - 1 downto 0) := (others => '0');
  signal walk           : std_logic;                  -- dx = xr is outside row i_iss: step down
  signal xr_r           : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal we_r, done_r   : std_logic := '0';
  signal addr_r         : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal ta_r, tb_r     : unsigned(KD_W - 1 downto 0) := (others => '0');
  signal ka_r, kb_r     : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  -- divider
  signal dv_in_valid    : std_logic;
  signal dv_in_n        : unsigned(N_W - 1 downto 0);
  signal dv_in_d        : unsigned(SQ_W - 1 downto 0);
  signal dv_in_tag      : std_logic_vector(TAG_W - 1 downto 0);
  signal dv_out_valid   : std_logic := '0';
  signal dv_out_q       : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  signal dv_out_tag     : std_logic_vector(TAG_W - 1 downto 0) := (others => '0');
begin
  -- walk only before KA of an entry is issued (sel = 0); at sel = 1 the test is already false
  walk <= xr_nz and xres(T_W);

  dv_in_valid <= '1' when state = S_ISSUE and walk = '0' and KERNEL_EPAN = 1 else '0';
  dv_in_n     <= shift_left(sq4, KERNEL_BITS);
  dv_in_d     <= h2 when sel = '1' else w2;
  dv_in_tag   <= sel & std_logic_vector(xr) & std_logic_vector(i_iss);

  g_div : if KERNEL_EPAN = 1 generate
    u_div : entity work.ms_divider
      generic map (N_W => N_W, D_W => SQ_W, Q_W => KVAL_W, TAG_W => TAG_W)
      port map (
        clk => clk, rst => rst, in_valid => dv_in_valid, in_n => dv_in_n, in_d => dv_in_d,
        in_tag => dv_in_tag, out_valid => dv_out_valid, out_q => dv_out_q, out_tag => dv_out_tag);
  end generate;

  p_ctrl : process (clk)
    variable wr   : boolean;
    variable wr_i : unsigned(HALF_W - 1 downto 0);
    variable wr_x : unsigned(HALF_W - 1 downto 0);
    variable e_x, e_y : unsigned(HALF_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      we_r   <= '0';
      done_r <= '0';
      wr     := false;
      wr_i   := i_iss;
      wr_x   := xr;
      e_x    := (others => '0');
      e_y    := (others => '0');
      -- if/elsif instead of case: GHDL 2.0's Verilog output of a full enum case has no default
      if state = S_IDLE then
        if start = '1' then
          wl    <= w;
          hl    <= h;
          state <= S_SETUP1;
        end if;

      elsif state = S_SETUP1 then
        w2   <= (others => '0');
        h2   <= (others => '0');
        mcw  <= resize(wl, SQ_W);
        mch  <= resize(hl, SQ_W);
        mpw  <= wl;
        mph  <= hl;
        cnt  <= 0;
        e_x  := resize(shift_right(wl - 1, 1), HALF_W);
        e_y  := resize(shift_right(hl - 1, 1), HALF_W);
        ex_r <= e_x;
        ey_r <= e_y;
        if e_x > e_y then
          n_last <= e_x;
        else
          n_last <= e_y;
        end if;
        state <= S_SQ;

      elsif state = S_SQ then            -- w^2, h^2: WW shift-and-add steps
        if mpw(0) = '1' then
          w2 <= w2 + mcw;
        end if;
        if mph(0) = '1' then
          h2 <= h2 + mch;
        end if;
        mcw <= shift_left(mcw, 1);
        mch <= shift_left(mch, 1);
        mpw <= shift_right(mpw, 1);
        mph <= shift_right(mph, 1);
        if cnt = WW - 1 then
          state <= S_DINIT;
        else
          cnt <= cnt + 1;
        end if;

      elsif state = S_DINIT then
        d_r   <= (others => '0');
        mcd   <= resize(w2, KD_W);
        mpd   <= h2;
        cnt   <= 0;
        state <= S_DMUL;

      elsif state = S_DMUL then          -- D = w^2 h^2: SQ_W shift-and-add steps (mod 2**KD_W, D < 2**KD_W)
        if mpd(0) = '1' then
          d_r <= d_r + mcd;
        end if;
        mcd <= shift_left(mcd, 1);
        mpd <= shift_right(mpd, 1);
        if cnt = SQ_W - 1 then
          state <= S_SETUP2;
        else
          cnt <= cnt + 1;
        end if;

      elsif state = S_SETUP2 then
        ta_acc   <= (others => '0');
        tb_acc   <= (others => '0');
        ta_stp   <= resize(shift_left(resize(h2, T_W), 2), T_W);
        tb_stp   <= resize(shift_left(resize(w2, T_W), 2), T_W);
        i_iss    <= (others => '0');
        sel      <= '0';
        sq4      <= (others => '0');
        sq4_step <= to_unsigned(4, N_W);
        xr       <= (others => '0');
        xr_nz    <= '0';
        if ex_r = 1 then
          xup_last <= '1';
        else
          xup_last <= '0';
        end if;
        xstp     <= resize(shift_left(resize(h2, T_W), 2), T_W);
        tbw_stp  <= resize(shift_left(resize(w2, T_W), 2), T_W);
        xres     <= signed(resize(d_r, T_W + 1)) - 1;
        if ex_r = 0 then
          state <= S_ISSUE;
        else
          state <= S_XUP;
        end if;

      elsif state = S_XUP then           -- xr = 0 .. ex by additions
        xres <= xres - signed(resize(xstp, T_W + 1));
        xr   <= xr + 1;
        xr_nz <= '1';
        if resize(xr, HALF_W + 1) + 2 = resize(ex_r, HALF_W + 1) then
          xup_last <= '1';
        else
          xup_last <= '0';
        end if;
        if xup_last = '1' then
          state <= S_ISSUE;               -- xstp stays TA[ex] - TA[ex-1]: the down step
        else
          xstp <= xstp + shift_left(resize(h2, T_W), 3);
        end if;

      elsif state = S_ISSUE then
        if walk = '1' then                -- TA[xr] + TB[i] >= D: dx = xr is outside, step down
          xres <= xres + signed(resize(xstp, T_W + 1));
          xstp <= xstp - shift_left(resize(h2, T_W), 3);
          xr   <= xr - 1;
          if xr = 1 then
            xr_nz <= '0';
          end if;
        elsif KERNEL_EPAN = 1 then
          sel <= not sel;
          if sel = '1' then
            i_iss    <= i_iss + 1;
            sq4      <= sq4 + sq4_step;
            sq4_step <= sq4_step + 8;
            xres     <= xres - signed(resize(tbw_stp, T_W + 1));
            tbw_stp  <= tbw_stp + shift_left(resize(w2, T_W), 3);
            if i_iss = n_last then
              state <= S_WAIT;
            end if;
          end if;
        else
          wr      := true;
          wr_i    := i_iss;
          wr_x    := xr;
          i_iss   <= i_iss + 1;
          xres    <= xres - signed(resize(tbw_stp, T_W + 1));
          tbw_stp <= tbw_stp + shift_left(resize(w2, T_W), 3);
          if i_iss = n_last then
            state <= S_WAIT;
          end if;
        end if;

      end if;

      -- write side (Epanechnikov: divider results, KA of entry i then KB of entry i)
      if KERNEL_EPAN = 1 and dv_out_valid = '1' then
        if dv_out_tag(TAG_W - 1) = '0' then
          ka_hold <= dv_out_q;
        else
          wr   := true;
          wr_i := unsigned(dv_out_tag(HALF_W - 1 downto 0));
          wr_x := unsigned(dv_out_tag(2 * HALF_W - 1 downto HALF_W));
          ka_r <= ka_hold;
          kb_r <= dv_out_q;
        end if;
      end if;
      if wr then
        we_r   <= '1';
        addr_r <= wr_i;
        ta_r   <= resize(ta_acc, KD_W);
        tb_r   <= resize(tb_acc, KD_W);
        xr_r   <= wr_x;
        ta_acc <= ta_acc + ta_stp;
        tb_acc <= tb_acc + tb_stp;
        ta_stp <= ta_stp + shift_left(resize(h2, T_W), 3);
        tb_stp <= tb_stp + shift_left(resize(w2, T_W), 3);
        if wr_i = n_last then
          done_r <= '1';
          state  <= S_IDLE;
        end if;
      end if;

      if rst = '1' then
        state  <= S_IDLE;
        we_r   <= '0';
        done_r <= '0';
        sel    <= '0';
      end if;
    end if;
  end process;

  busy    <= '0' when state = S_IDLE else '1';
  done    <= done_r;
  ex      <= ex_r;
  ey      <= ey_r;
  kd_d    <= d_r;
  kt_we   <= we_r;
  kt_addr <= addr_r;
  kt_ta   <= ta_r;
  kt_tb   <= tb_r;
  kt_ka   <= ka_r;
  kt_kb   <= kb_r;
  kt_xr   <= xr_r;
end architecture;
