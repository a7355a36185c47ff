-- ms_init_merge: the init-frame pixel stream of tracker v2 with joint bins (colour x orientation):
-- merges the frame-border pixels of ms_frontend's all-pixel stream (av_*, orientation 8) with the
-- frame-interior pixels of ms_decimate (dp_*, their orientation from ms_sobel, one line later)
-- into the one count port of ms_bg_model (N_ORIENT 9).
--
-- Computes: every pixel (x / D, y / D) of the decimated frame frame[::D, ::D] exactly once, with its
-- colour bin and its orientation bin ms_orient_bin(ms_grey(frame), T)[::D, ::D] (the model's
-- FixedTrackerV2(orient_T = T)._bins): an interior pixel (1 <= x <= W - 2, 1 <= y <= H - 2) as
-- ms_decimate passes it (dp_obin = ms_sobel's ip_obin), a border pixel (x = 0, y = 0, x = W - 1 or
-- y = H - 1, x mod D = y mod D = 0) from av_* with obin 8; then one beat with px_last.  Border pixels
-- outside the rectangle ms_bg_model counts (|x/D - cx| <= ex + gx, |y/D - cy| <= ey + gy, its box
-- and ring, from the same start, cx, cy, wb, hb, ring16) are dropped: ms_bg_model ignores them, and
-- the FIFO below is sized for the rectangle, not for the frame width.
-- Alignment: av_* leads the Sobel by one line: av is delayed by AV_DELAY clocks (a 16-word LUT RAM)
-- so that in each clock the merge sees, for one input beat b = (x, y): b's own av pixel, the interior
-- pixel dp (x - 1, y - 1) that b completes, and b's frame events (dp_start with the sof beat, dp_end
-- with the frame's last beat, dp_error); so a frame's pixels and events are in order with the next
-- frame's (an error cut included).  A simulation assertion checks it (dp_start with av (0, 0)).
-- Merge: dp pixels go straight to the output; border pixels (and px_last, on the frame's last
-- border pixel or alone, coordinates all ones = outside any box) go through a FIFO whose words
-- leave in every clock without a dp pixel.  The FIFO memory is an ms_ram_sdp (RD_LAT 3: on ECP5
-- the DP16KD output register) followed by a 5-word prefetch ring (flip-flops / LUT RAM); a word is
-- read when the ring has room for it whatever the pops, so the dp pixel's priority reaches neither
-- the RAM nor the ring's inputs.  dp_error empties FIFO and ring (the caller resets ms_bg_model).
-- px_* hold their values while px_valid is low (see docs/blocks/ms_init_merge.md: a chain netlist
-- under Verilator went wrong when they did not).
-- FIFO depth (worst case): in one clock b's border pixel and dp (x - 1, y - 1) are both decimated
-- pixels only if x = x - 1 mod D, i.e. D = 1; at D >= 2 at most one pixel per clock arrives and
-- the FIFO (memory + reads in flight + ring) holds at most 7 words (its 6-clock path to the output,
-- px_last beside the frame's last dp).  At D = 1 the two arrive together on the right column
-- (x = W - 1, y >= 2: one word, paid back at (1, y + 1), which brings neither) and on the bottom
-- row (x >= 2, y = H - 1: no free clock until the frame ends), so it holds at most
-- min(W - 1, 2 RX + 1) + 7 words, RX = ex + gx: the bottom row's pixels inside the rectangle.
-- FIFO_DEPTH = 2**clog2(min(MAX_FRAME_W - 1, 2 RX_MAX + 1) + 8) (the memory's share of that),
-- RX_MAX = 2**HALF_W - 1 + (RING16_MAX (2**(HALF_W + 1) - 1)) / 16 (core v2: HALF_W 6, ring16 10:
-- RX_MAX 142, 512 words x 34 b).  A full FIFO drops the pixel and raises `overflow` (sticky; a
-- simulation assertion too).  The FIFO drains after dp_end in at most min(W - 1, 2 RX + 1) + 8
-- clocks, before the next frame's first dp pixel (2 W + 2 beats after its sof beat; rows 0 and 1
-- bring border pixels only, which queue behind px_last), so px_last always precedes the next
-- frame's pixels (simulation assertion).
-- Latency (counted from the RTL): av pixel -> px_* 16 clocks when the FIFO is empty and no dp pixel
-- comes (delay 8, 2 stages, write, RAM read 3, ring, output register); dp_* -> px_* 4 clocks;
-- dp_end -> px_last: 8 clocks + the FIFO's backlog.  Throughput: 1 pixel per clock out, no
-- handshake (ms_bg_model never stalls); the backlog is absorbed by the FIFO.
-- Cost (ECP5, RING16_MAX 10, yosys synth_ecp5 + nextpnr, block alone; docs/blocks/ms_init_merge.md):
-- about 340 LUT4, 555 FF, 2 DP16KD, 18 TRELLIS_DPR16X4, no MULT18X18D.
-- Python model: the pixel set of mstrack.fixed.tracker_v2.FixedTrackerV2._bins(frame, D) (orient_T
-- > 0), which ms_bg_model counts; the order is free.
-- Reset: synchronous, active high: control state (FIFO empty, no pixel out, overflow cleared).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_init_merge is
  generic (
    COORD_W     : natural := 12;             -- x, y and frame size bits
    BIN_W       : natural := 9;              -- colour bin bits (3 colour_bits)
    HALF_W      : natural := 6;              -- ms_bg_model's HALF_W: wb, hb have HALF_W + 1 bits
    RING_W      : natural := 5;              -- ring16 bits
    RING16_MAX  : natural := 31;             -- largest ring16 used (FIFO depth; core v2: RING16 = 10)
    MAX_FRAME_W : natural := 2048;           -- widest frame (FIFO depth at D = 1)
    LOG2_D_MAX  : natural range 0 to 7 := 4  -- largest log2 D (ms_decimate's)
  );
  port (
    clk          : in  std_logic;                                -- clock
    rst          : in  std_logic;                                -- synchronous reset, active high
    -- the box (as given to ms_bg_model, decimated px), sampled on start
    start        : in  std_logic;                                -- pulse: take cx, cy, wb, hb, ring16
    cx, cy       : in  unsigned(COORD_W - 1 downto 0);           -- box centre
    wb, hb       : in  unsigned(HALF_W downto 0);                -- box diameters
    ring16       : in  unsigned(RING_W - 1 downto 0);            -- ring width per side in 1/16 of the box
    -- frame size (as given to ms_frontend), sampled with the frame's first av pixel (0, 0)
    frame_width  : in  unsigned(COORD_W - 1 downto 0);           -- W
    frame_height : in  unsigned(COORD_W - 1 downto 0);           -- H
    -- ms_frontend's all-pixel stream
    av_valid     : in  std_logic;                                -- a frame pixel
    av_x, av_y   : in  unsigned(COORD_W - 1 downto 0);           -- its column, row (full resolution)
    av_cbin      : in  std_logic_vector(BIN_W - 1 downto 0);     -- its colour bin
    -- ms_decimate (its ip_ebin fed with ms_frontend's ip_obin)
    dec_q        : in  unsigned(2 downto 0);                     -- log2 D of the current frame
    dp_start     : in  std_logic;                                -- frame events
    dp_end       : in  std_logic;                                --   "
    dp_error     : in  std_logic;                                --   "
    dp_valid     : in  std_logic;                                -- decimated interior pixel
    dp_x, dp_y   : in  unsigned(COORD_W - 1 downto 0);           -- its position (decimated px)
    dp_cbin      : in  std_logic_vector(BIN_W - 1 downto 0);     -- its colour bin
    dp_obin      : in  std_logic_vector(3 downto 0);             -- its orientation bin (0 .. 8)
    -- to ms_bg_model's count port
    px_valid     : out std_logic;                                -- a pixel
    px_bin       : out unsigned(BIN_W - 1 downto 0);             -- colour bin
    px_obin      : out unsigned(3 downto 0);                     -- orientation bin (8 on the frame border)
    px_x, px_y   : out unsigned(COORD_W - 1 downto 0);           -- decimated px
    px_last      : out std_logic;                                -- the frame's last beat
    overflow     : out std_logic                                 -- sticky: a border pixel was lost (FIFO full)
  );
end entity;

architecture rtl of ms_init_merge is
  constant AV_DELAY : natural := 8;                     -- av -> av1 clocks (av1 aligned with dp_start)
  constant RX_MAX   : natural := 2 ** HALF_W - 1 + (RING16_MAX * (2 ** (HALF_W + 1) - 1)) / 16;
  constant FIFO_AW  : natural := clog2(minimum(MAX_FRAME_W - 1, 2 * RX_MAX + 1) + 8);
  constant R_W      : natural := RING_W + HALF_W + 2;   -- rx, ry bits (ex + (ring16 wb) >> 4)
  constant S_W      : natural := maximum(COORD_W, R_W) + 2;  -- signed bounds cx -+ rx
  constant AV_W     : natural := 1 + 2 * COORD_W + BIN_W;   -- {border, x, y, cbin}
  constant E_W      : natural := 1 + 2 * COORD_W + BIN_W;   -- FIFO word {last, x, y, cbin}
  constant LW       : natural := LOG2_D_MAX + 1;
  constant RD_LAT   : natural := 3;                     -- FIFO memory read latency (ms_ram_sdp: ECP5 OUTREG)
  constant NQ       : natural := RD_LAT + 2;            -- prefetch buffer words (a read per clock; the
                                                        -- read decision does not wait for the pop)

  -- box rectangle
  signal wb_r, hb_r   : unsigned(HALF_W downto 0) := (others => '0');
  signal ring_r       : unsigned(RING_W - 1 downto 0) := (others => '0');
  signal rcx, rcy     : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal rx, ry       : unsigned(R_W - 1 downto 0) := (others => '0');
  signal gxa, gya     : unsigned(R_W - 1 downto 0) := (others => '0');  -- ring16 wb, ring16 hb (serial)
  signal x_lo, x_hi, y_lo, y_hi : signed(S_W - 1 downto 0) := (others => '0');  -- cx -+ rx, cy -+ ry
  signal gcnt         : natural range 0 to RING_W := 0;                  -- bits still to add
  -- frame size of the av stream
  signal wl, hl       : unsigned(COORD_W - 1 downto 0) := (others => '1');  -- W - 1, H - 1
  -- av delay line (LUT RAM ring)
  type dl_t is array (0 to 15) of std_logic_vector(AV_W - 1 downto 0);
  signal dl           : dl_t;
  signal dl_wp        : unsigned(3 downto 0) := (others => '0');
  signal av0          : std_logic_vector(AV_W - 1 downto 0) := (others => '0');  -- border test registered
  signal av1          : std_logic_vector(AV_W - 1 downto 0) := (others => '0');  -- delay-line output
  signal dv           : std_logic_vector(1 to AV_DELAY) := (others => '0');     -- its valid (border) bits
  -- stage 1: aligned (av1, dp registered once, events as they come)
  signal i1_v         : std_logic := '0';
  signal i1_x, i1_y   : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal i1_c         : std_logic_vector(BIN_W - 1 downto 0) := (others => '0');
  signal i1_o         : std_logic_vector(3 downto 0) := (others => '0');
  -- stage 2: decimated border pixel
  signal b2_v, i2_v, s2, e2, r2 : std_logic := '0';
  signal b2_x, b2_y, i2_x, i2_y : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal b2_c, i2_c   : std_logic_vector(BIN_W - 1 downto 0) := (others => '0');
  signal i2_o         : std_logic_vector(3 downto 0) := (others => '0');
  -- stage 3: rectangle test
  signal b3_v, i3_v, e3, r3 : std_logic := '0';
  signal b3_x, b3_y, i3_x, i3_y : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal b3_c, i3_c   : std_logic_vector(BIN_W - 1 downto 0) := (others => '0');
  signal i3_o         : std_logic_vector(3 downto 0) := (others => '0');
  -- FIFO of border pixels and px_last markers
  signal f_we         : std_logic;
  signal f_wdata, f_rdata : std_logic_vector(E_W - 1 downto 0);
  type q_t is array (0 to NQ - 1) of std_logic_vector(E_W - 1 downto 0);
  signal q            : q_t := (others => (others => '0'));          -- prefetch buffer (a ring)
  signal qh, qt       : natural range 0 to NQ - 1 := 0;              -- its head, its next free word
  signal qn           : natural range 0 to NQ := 0;                  -- its words
  signal fcnt         : unsigned(FIFO_AW downto 0) := (others => '0');  -- words in the FIFO memory (wp - rp)
  signal f_ne, f_full : std_logic := '0';                            -- fcnt /= 0, fcnt = 2**FIFO_AW (registered)
  signal rv           : std_logic_vector(1 to RD_LAT) := (others => '0');  -- reads in flight
  signal wp, rp       : unsigned(FIFO_AW downto 0) := (others => '0');
  signal ovf          : std_logic := '0';
  signal lasts        : unsigned(1 downto 0) := (others => '0');  -- px_last markers not yet out
begin
  assert FIFO_AW <= 16 report "ms_init_merge: FIFO too deep" severity failure;
  assert RING_W + 3 < 3 * (HALF_W + 1) + 7
    report "ms_init_merge: the rectangle would not be ready before ms_bg_model counts" severity failure;

  -- the box's rectangle, as ms_bg_model's set-up computes it: rx = ex + gx = (wb - 1) / 2 + (ring16 wb) >> 4;
  -- ring16 wb, ring16 hb by shift-and-add, MSB first (RING_W clocks after start; no multiplier, so no
  -- DSP block), then rx, ry, then the bounds: valid RING_W + 3 clocks after start, long before
  -- ms_bg_model counts (its set-up takes at least 3 (HALF_W + 1) + 7 clocks)
  p_box : process (clk)
  begin
    if rising_edge(clk) then
      if start = '1' then
        rcx <= cx;
        rcy <= cy;
        wb_r <= wb;
        hb_r <= hb;
        ring_r <= ring16;
        gxa <= (others => '0');
        gya <= (others => '0');
        gcnt <= RING_W;
        assert ring16 <= RING16_MAX report "ms_init_merge: ring16 > RING16_MAX (FIFO sized too small)"
          severity error;
      elsif gcnt > 0 then
        gxa <= shift_left(gxa, 1);
        gya <= shift_left(gya, 1);
        if ring_r(gcnt - 1) = '1' then
          gxa <= shift_left(gxa, 1) + resize(wb_r, R_W);
          gya <= shift_left(gya, 1) + resize(hb_r, R_W);
        end if;
        gcnt <= gcnt - 1;
      end if;
      rx <= resize(shift_right(wb_r - 1, 1), R_W) + shift_right(gxa, 4);
      ry <= resize(shift_right(hb_r - 1, 1), R_W) + shift_right(gya, 4);
      -- the rectangle's bounds (signed: they may leave the frame), so that the per-pixel test is
      -- four compares in parallel (one carry chain deep)
      x_lo <= signed(resize(rcx, S_W)) - signed(resize(rx, S_W));
      x_hi <= signed(resize(rcx, S_W)) + signed(resize(rx, S_W));
      y_lo <= signed(resize(rcy, S_W)) - signed(resize(ry, S_W));
      y_hi <= signed(resize(rcy, S_W)) + signed(resize(ry, S_W));
    end if;
  end process;

  -- av: border test (frame size taken with pixel (0, 0)), then the delay line
  p_av : process (clk)
    variable w1, h1 : unsigned(COORD_W - 1 downto 0);
    variable brd    : std_logic;
  begin
    if rising_edge(clk) then
      w1 := wl;
      h1 := hl;
      if av_valid = '1' and av_x = 0 and av_y = 0 then
        w1 := frame_width - 1;
        h1 := frame_height - 1;
        wl <= w1;
        hl <= h1;
      end if;
      brd := '0';
      if av_valid = '1' and (av_x = 0 or av_y = 0 or av_x = w1 or av_y = h1) then
        brd := '1';
      end if;
      -- data through the LUT RAM, the border (valid) bit through flip-flops (cleared by reset)
      dv <= brd & dv(1 to AV_DELAY - 1);
      av0 <= '0' & std_logic_vector(av_x) & std_logic_vector(av_y) & av_cbin;
      dl(to_integer(dl_wp)) <= av0;
      av1 <= dv(AV_DELAY - 1) & dl(to_integer(dl_wp - (AV_DELAY - 2)))(AV_W - 2 downto 0);
      dl_wp <= dl_wp + 1;
      if rst = '1' then
        dv <= (others => '0');
        av1(AV_W - 1) <= '0';
      end if;
    end if;
  end process;

  -- stages 1 .. 3: dp registered once (then beat b's av pixel, its dp pixel and its events share a
  -- clock), decimation of the border pixel (dec_q is the frame's from dp_start on), rectangle test
  p_pipe : process (clk)
    variable m      : unsigned(LW - 1 downto 0);
    variable k      : natural range 0 to 7;
    variable ax, ay : unsigned(COORD_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      i1_v <= dp_valid;
      i1_x <= dp_x;
      i1_y <= dp_y;
      i1_c <= dp_cbin;
      i1_o <= dp_obin;
      -- stage 2
      k := 0;                                           -- as ms_decimate: above LOG2_D_MAX, D = 1
      m := (others => '0');
      for i in 1 to LOG2_D_MAX loop
        if dec_q = i then
          k := i;
          m := to_unsigned(2 ** i - 1, LW);
        end if;
      end loop;
      ax := unsigned(av1(AV_W - 2 downto AV_W - 1 - COORD_W));
      ay := unsigned(av1(AV_W - 2 - COORD_W downto BIN_W));
      b2_v <= '0';
      if av1(AV_W - 1) = '1' and (resize(ax, LW) and m) = 0 and (resize(ay, LW) and m) = 0 then
        b2_v <= '1';
      end if;
      b2_x <= shift_right(ax, k);
      b2_y <= shift_right(ay, k);
      b2_c <= av1(BIN_W - 1 downto 0);
      i2_v <= i1_v;
      i2_x <= i1_x;
      i2_y <= i1_y;
      i2_c <= i1_c;
      i2_o <= i1_o;
      s2 <= dp_start;
      e2 <= dp_end;
      r2 <= dp_error;
      -- stage 3
      b3_v <= '0';
      if b2_v = '1' and signed(resize(b2_x, S_W)) >= x_lo and signed(resize(b2_x, S_W)) <= x_hi
         and signed(resize(b2_y, S_W)) >= y_lo and signed(resize(b2_y, S_W)) <= y_hi then
        b3_v <= '1';
      end if;
      b3_x <= b2_x;
      b3_y <= b2_y;
      b3_c <= b2_c;
      i3_v <= i2_v;
      i3_x <= i2_x;
      i3_y <= i2_y;
      i3_c <= i2_c;
      i3_o <= i2_o;
      e3 <= e2;
      r3 <= r2;
      if rst = '1' then
        i1_v <= '0';
        b2_v <= '0';
        i2_v <= '0';
        s2 <= '0';
        e2 <= '0';
        r2 <= '0';
        b3_v <= '0';
        i3_v <= '0';
        e3 <= '0';
        r3 <= '0';
      end if;
    end if;
  end process;

  -- simulation only: the alignment (dp_start with the sof beat's av pixel (0, 0))
  p_check : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '0' and s2 = '1' then
        assert b2_v = '1' and b2_x = 0 and b2_y = 0
          report "ms_init_merge: dp_start not with the av pixel (0, 0): alignment broken" severity failure;
      end if;
    end if;
  end process;

  -- FIFO memory: ms_ram_sdp (block RAM; on ECP5 its DP16KD output register, RD_LAT clocks)
  u_fifo : entity work.ms_ram_sdp
    generic map (DEPTH => 2 ** FIFO_AW, DATA_W => E_W, ADDR_W => FIFO_AW, RD_LAT => RD_LAT, WR_LAT => 0)
    port map (clk => clk, we => f_we, waddr => wp(FIFO_AW - 1 downto 0), wdata => f_wdata,
              raddr => rp(FIFO_AW - 1 downto 0), rdata => f_rdata);

  -- merge: dp pixel out at once; else the head of the prefetch buffer (the words read from the FIFO
  -- memory, a ring of NQ = RD_LAT + 2 flip-flop words: one read per clock while words are popped; the
  -- read is decided on the buffer's words and the reads in flight, not on this clock's pop, and the
  -- word read goes to the ring's tail, so that the dp pixel's priority reaches no RAM or ring input)
  p_merge : process (clk)
    variable push, pop, rd, full : boolean;
    variable lasts_n : unsigned(1 downto 0);
    variable qn_n, inflight : natural range 0 to NQ + RD_LAT;
    variable rd_bit : std_logic;
    variable fc : unsigned(FIFO_AW downto 0);
  begin
    if rising_edge(clk) then
      push := b3_v = '1' or e3 = '1';
      pop := qn > 0 and i3_v = '0' and r3 = '0';         -- (dp_error: the buffer is dropped)
      inflight := 0;
      for i in 1 to RD_LAT loop
        if rv(i) = '1' then
          inflight := inflight + 1;
        end if;
      end loop;
      -- read when the word will find room when it arrives (pops only add room)
      rd := f_ne = '1' and qn + inflight < NQ and r3 = '0';
      full := f_full = '1' and r3 = '0';                 -- (dp_error empties it)
      -- output
      -- (the data registers load every clock, a 2:1 multiplexer: no clock enable from i3_v)
      px_valid <= '1' when i3_v = '1' or pop else '0';
      px_last <= '0';
      if i3_v = '1' then
        px_x <= i3_x;
        px_y <= i3_y;
        px_bin <= unsigned(i3_c);
        px_obin <= unsigned(i3_o);
        assert lasts = 0 or r3 = '1'
          report "ms_init_merge: a pixel of the next frame before px_last (FIFO backlog)" severity failure;
      elsif pop then
        px_last <= q(qh)(E_W - 1);
        px_x <= unsigned(q(qh)(E_W - 2 downto E_W - 1 - COORD_W));
        px_y <= unsigned(q(qh)(E_W - 2 - COORD_W downto BIN_W));
        px_bin <= unsigned(q(qh)(BIN_W - 1 downto 0));
        px_obin <= to_unsigned(8, 4);
      end if;
      lasts_n := lasts;
      if pop and q(qh)(E_W - 1) = '1' then
        lasts_n := lasts_n - 1;
      end if;
      -- prefetch ring
      qn_n := qn;
      if pop then
        qh <= (qh + 1) mod NQ;
        qn_n := qn_n - 1;
      end if;
      if rv(RD_LAT) = '1' then
        q(qt) <= f_rdata;                                -- (room was reserved at the read)
        qt <= (qt + 1) mod NQ;
        qn_n := qn_n + 1;
      end if;
      qn <= qn_n;
      rd_bit := '1' when rd else '0';
      rv <= rd_bit & rv(1 to RD_LAT - 1);               -- rv(RD_LAT): the word in f_rdata now
      if rd then
        rp <= rp + 1;
      end if;
      -- FIFO write (f_we, f_wdata below: the memory writes at this edge)
      if push then
        if full then
          ovf <= '1';
          assert false report "ms_init_merge: FIFO full, border pixel lost" severity error;
        else
          wp <= wp + 1;
          if e3 = '1' then
            lasts_n := lasts_n + 1;
          end if;
        end if;
      end if;
      lasts <= lasts_n;
      -- words in the memory, and its flags for the next clock (registered: no wp / rp compare in
      -- front of the read and write decisions)
      fc := fcnt;
      if r3 = '1' then
        fc := (others => '0');
      elsif rd then
        fc := fc - 1;
      end if;
      if push and not full then
        fc := fc + 1;
      end if;
      fcnt <= fc;
      f_ne <= '1' when fc /= 0 else '0';
      f_full <= '1' when fc = 2 ** FIFO_AW else '0';
      if r3 = '1' then                                   -- abandoned frame: drop its border pixels
        rp <= wp;                                        -- (a push of this clock, the pixel (0, 0) of
        qn <= 0;                                         -- the frame that cut it, stays: wp + 1)
        qh <= 0;
        qt <= 0;
        rv <= (others => '0');
        lasts <= (others => '0');
      end if;
      if rst = '1' then
        px_valid <= '0';
        px_last <= '0';
        wp <= (others => '0');
        rp <= (others => '0');
        qn <= 0;
        qh <= 0;
        qt <= 0;
        rv <= (others => '0');
        fcnt <= (others => '0');
        f_ne <= '0';
        f_full <= '0';
        ovf <= '0';
        lasts <= (others => '0');
      end if;
    end if;
  end process;
  f_we <= '1' when (b3_v = '1' or e3 = '1') and not (f_full = '1' and r3 = '0') else '0';
  f_wdata <= e3 & std_logic_vector(b3_x) & std_logic_vector(b3_y) & b3_c when b3_v = '1' else
             e3 & (2 * COORD_W - 1 downto 0 => '1') & b3_c;  -- px_last alone: coordinates all ones
  overflow <= ovf;
end architecture;
