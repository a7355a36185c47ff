-- ms_target_stats: target-coloured pixel statistics of one window pass (tracker v2), beside ms_pixel_pass.
--
-- Over the pixels of a pass (the kernel ellipse of the window: ms_pixel_pass's scan, LANES pixels
-- per clock) it accumulates, with d2q = KA[|dx|] + KB[|dy|] (the pixel's normalised d^2, Q.KERNEL_BITS)
-- and t = T[bin] (1 for target-coloured bins):
--   nt    = sum t                   st2   = sum t d2q
--   n_in  = sum in                  nt_in = sum t in,   in = d2q (16 + PAD16)^2 < 2**(KERNEL_BITS + 8)
-- (in: the pixel lies in the box inside the padded window).  The inner test is a compare with the
-- constant IN_LIM = ceil(2**(KERNEL_BITS + 8) / (16 + PAD16)^2): d2q c < L <=> d2q < ceil(L / c).
-- Model: mstrack.fixed.blocks_v2.ms_target_stats(bins, T, win, ms_kernel(w, h, "flat", KB), KB, pad16).
-- Joint bins (N_ORIENT > 1, tracker v2's colour x orientation, N_ORIENT 9): a pixel's bin is the pair
-- (colour on ram_data, orientation on ram_obin), the model's N_ORIENT colour + obin (ms_joint_bin), and
-- t = T[(colour, obin)]: each lane's T table holds 2**BIN_W words of N_ORIENT bits, word = colour,
-- bit o = T[(colour, o)] (ms_bg_model's m_t_all layout), written one colour address per clock through
-- (t_addr, t_data_all): a whole T load is 2**BIN_W clocks, as the Qw load beside it; the lookup reads
-- the word of the pixel's colour and selects bit obin after the RAM's output register.  N_ORIENT = 1:
-- the colour bin only (ram_obin, t_data_all ignored; t_data; the block as before).
--
-- Attachment: it sits on ms_pixel_pass's scan tap (px_valid, px_mask, px_dx, px_dy, px_last: the beat
-- whose ram_addr is out in cycle t) and on the region RAM's read data (ram_data, the beat's bins in
-- cycle t + 1, the same wires as ms_pixel_pass's ram_data); ms_pixel_pass is not changed otherwise.
-- Tables: T (2**BIN_W x N_ORIENT b, written through t_* at init: ms_bg_model's T) and the kernel tables
-- KA (one copy per lane) and KB (one copy: dy is the same for all lanes of a beat), written through
-- the kt_* port of ms_kernel_tables run with KERNEL_EPAN = 1, KVAL_W = KERNEL_BITS + 1 (the flat
-- pixel pass ignores KA/KB).  Entries used: |dx| <= ex, |dy| <= ey (exact there, < 2**KERNEL_BITS).
--
-- Pipeline (edge s samples the beat): s: |dx + l|, |dy|, mask -> s+1: bins registered, KA/KB read
-- -> s+2: T read (ms_ram_sdp, RD_LAT 2), d2q = KA + KB -> s+3: T read data out of the RAM's output register
-- -> s+4: per-lane terms (t = bit obin of the T word, t d2q, in, t in) -> s+5 .. s+4+log2(LANES): adder tree over the lanes
-- (one level per clock) -> s+5+log2(LANES): accumulators; on the last beat the sums go to the
-- outputs and the accumulators restart from 0 (the next pass needs no clear).
-- Latency    : STATS_LAT = 6 + log2(LANES) clocks: if edge s samples px_valid = px_last = 1, edge
--              s + STATS_LAT samples done = 1 (tb/test_ms_target_stats.py asserts it).  Attached to
--              ms_pixel_pass (PASS_LAT = 10), done comes log2(LANES) - 2 clocks after the pass's done
--              (LANES = 4: in the same clock), long before the bin pass that follows has ended; in
--              ms_tracker_v2 (region RAM latency 4) the tap is delayed 3 clocks, done 3 clocks later.
-- Throughput : LANES pixels per clock (one beat per clock, no stall, no back-pressure).
-- Handshake  : none on the input (the tap is a stream); done is a one-clock pulse, nt/st2/n_in/nt_in
--              are registered and held until the next pass's done.  Tables must not be written
--              during a pass.
-- Cost       : LANES KA tables (2**HALF_W x KT_W), one KB table, LANES T tables (2**BIN_W x N_ORIENT b:
--              one DP16KD each (512 x 36 mode) up to 9 bits at BIN_W 9, so N_ORIENT 9 adds no block RAM;
--              N_ORIENT > 1: an N_ORIENT:1 bit select per lane and 2 ORIENT_W-bit delay registers),
--              LANES (KT_W + 1)-bit adders, a compare per lane, an adder tree and 4 accumulators.
-- Reset      : synchronous, active high: the pipeline valid/last flags and the accumulators.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_target_stats is
  generic (
    LANES       : natural := 4;   -- pixels per clock (power of 2), as ms_pixel_pass; one KA and T copy each
    BIN_W       : natural := 9;   -- bin width: T has 2**BIN_W entries
    HALF_W      : natural := 6;   -- kernel table address width (|dx|, |dy| <= 2**HALF_W - 1)
    REGION_W    : natural := 8;   -- region coordinate bits (px_dx, px_dy are REGION_W + 1 signed)
    KERNEL_BITS : natural := 8;   -- KB: d2q is Q.KB (2**KB = 1)
    KT_W        : natural := 9;   -- KA, KB entry width (ms_kernel_tables KVAL_W; >= KERNEL_BITS)
    PAD16       : natural := 4;   -- pad in sixteenths (TrackerParams.pad = 0.25 -> 4): the inner test
    COUNT_W     : natural := 14;  -- nt, n_in, nt_in bits (pixels of the largest window)
    ST2_W       : natural := 23;  -- st2 bits (largest window x largest d2q)
    N_ORIENT    : natural range 1 to 16 := 1;  -- orientation bins: T has 2**BIN_W words of N_ORIENT bits per
                                  -- lane, looked up at the joint bin (colour, obin); 1 = colour only (obins ignored)
    ORIENT_W    : natural := 4    -- width of an orientation bin in t_obin, ram_obin (2**ORIENT_W >= N_ORIENT)
  );
  port (
    clk      : in  std_logic;                                    -- clock
    rst      : in  std_logic;                                    -- synchronous reset (pipeline flags, accumulators)
    -- T table write port (at init, between passes)
    t_we     : in  std_logic;                                    -- write T[t_addr] (N_ORIENT > 1: the word t_addr)
    t_addr   : in  unsigned(BIN_W - 1 downto 0);                 -- bin (colour bin when N_ORIENT > 1)
    t_data   : in  std_logic;                                    -- N_ORIENT = 1: T[bin], 1 target-coloured
    t_data_all : in std_logic_vector(N_ORIENT - 1 downto 0) := (others => '0');
                                                                 -- N_ORIENT > 1: bit o = T[(t_addr, o)]
    -- kernel table write port (ms_kernel_tables kt_*, KERNEL_EPAN = 1)
    kt_we    : in  std_logic;                                    -- write entry kt_addr
    kt_addr  : in  unsigned(HALF_W - 1 downto 0);                -- entry index i
    kt_ka    : in  unsigned(KT_W - 1 downto 0);                  -- KA[i] = floor((4 i^2 << KB) / w^2)
    kt_kb    : in  unsigned(KT_W - 1 downto 0);                  -- KB[i] = floor((4 i^2 << KB) / h^2)
    -- ms_pixel_pass scan tap (cycle t) and region RAM data (cycle t + 1)
    px_valid : in  std_logic;                                    -- beat valid
    px_mask  : in  std_logic_vector(LANES - 1 downto 0);         -- lane l inside the ellipse
    px_dx    : in  signed(REGION_W downto 0);                    -- dx of lane 0 (lane l: px_dx + l)
    px_dy    : in  signed(REGION_W downto 0);                    -- dy of the beat
    px_last  : in  std_logic;                                    -- last beat of the pass
    ram_data : in  std_logic_vector(LANES * BIN_W - 1 downto 0); -- the beat's bins (lane l at l*BIN_W), cycle t + 1
    ram_obin : in  std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
                                                                 -- their orientation bins (lane l at l*ORIENT_W),
                                                                 -- cycle t + 1 (ignored if N_ORIENT = 1)
    -- results of the last pass (held)
    done     : out std_logic;                                    -- pulse: results of the pass just ended
    nt       : out unsigned(COUNT_W - 1 downto 0);               -- target-coloured pixels
    st2      : out unsigned(ST2_W - 1 downto 0);                 -- their sum of d2q
    n_in     : out unsigned(COUNT_W - 1 downto 0);               -- pixels of the inner box
    nt_in    : out unsigned(COUNT_W - 1 downto 0)                -- target-coloured pixels of the inner box
  );
end entity;

architecture rtl of ms_target_stats is
  constant D_W     : natural := REGION_W + 1;
  constant D2Q_W   : natural := KT_W + 1;                        -- KA + KB
  constant TL      : natural := clog2(LANES) * boolean'pos(LANES > 1);  -- adder tree levels
  constant STATS_LAT : natural := 6 + TL;
  constant C_SQ    : natural := (16 + PAD16) * (16 + PAD16);
  constant IN_LIM  : natural := (2 ** (KERNEL_BITS + 8) + C_SQ - 1) / C_SQ;  -- d2q < IN_LIM: inner
  constant TS_W    : natural := D2Q_W + TL;                      -- tree: sum of t d2q
  constant TC_W    : natural := TL + 1;                          -- tree: counts (<= LANES)

  type ka_ram_t is array (0 to 2 ** HALF_W - 1) of unsigned(KT_W - 1 downto 0);
  type a_arr_t is array (0 to LANES - 1) of unsigned(HALF_W - 1 downto 0);
  type k_arr_t is array (0 to LANES - 1) of unsigned(KT_W - 1 downto 0);
  type q_arr_t is array (0 to LANES - 1) of unsigned(D2Q_W - 1 downto 0);
  -- adder tree: level k (0 .. TL) has LANES / 2**k entries, stored flat at [k * LANES + i]
  type ts_arr_t is array (0 to (TL + 1) * LANES - 1) of unsigned(TS_W - 1 downto 0);
  type tc_arr_t is array (0 to (TL + 1) * LANES - 1) of unsigned(TC_W - 1 downto 0);

  signal kb_ram : ka_ram_t := (others => (others => '0'));

  -- stage 1 (edge s)
  signal last1 : std_logic := '0';
  signal m1        : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal adx1      : a_arr_t := (others => (others => '0'));
  signal ady1      : unsigned(HALF_W - 1 downto 0) := (others => '0');
  -- stage 2 (edge s + 1)
  signal last2     : std_logic := '0';
  signal m2        : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal bin2      : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal obin2     : std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
  signal obin3, obin4 : std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
  signal ka2       : k_arr_t := (others => (others => '0'));
  signal kb2       : unsigned(KT_W - 1 downto 0) := (others => '0');
  -- stage 3 (edge s + 2): T read (u_t), d2q; stage 4 (edge s + 3): T read data out of u_t
  signal last3, last4 : std_logic := '0';
  signal m3        : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal m4, t4    : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal d3, d4    : q_arr_t := (others => (others => '0'));
  -- stage 5 and the tree (edges s + 4 .. s + 4 + TL)
  signal last_t    : std_logic_vector(0 to TL) := (others => '0');
  signal tr_st     : ts_arr_t := (others => (others => '0'));
  signal tr_nt, tr_ni, tr_nti : tc_arr_t := (others => (others => '0'));
  -- accumulators and results (edge s + 5 + TL)
  signal a_nt, a_ni, a_nti : unsigned(COUNT_W - 1 downto 0) := (others => '0');
  signal a_st      : unsigned(ST2_W - 1 downto 0) := (others => '0');
  signal done_r    : std_logic := '0';
  signal r_nt, r_ni, r_nti : unsigned(COUNT_W - 1 downto 0) := (others => '0');
  signal r_st      : unsigned(ST2_W - 1 downto 0) := (others => '0');
  signal t_wd      : std_logic_vector(N_ORIENT - 1 downto 0);
begin
  assert N_ORIENT = 1 or 2 ** ORIENT_W >= N_ORIENT
    report "ms_target_stats: ORIENT_W too narrow for N_ORIENT" severity failure;
  assert LANES = 1 or 2 ** clog2(LANES) = LANES
    report "ms_target_stats: LANES must be a power of 2" severity failure;
  assert KT_W >= KERNEL_BITS
    report "ms_target_stats: KT_W must hold KA, KB < 2**KERNEL_BITS" severity failure;

  -- stage 1: |dx + l|, |dy| (explicit negation: GHDL 2.0's Verilog writer has no abs); only the
  -- HALF_W low bits matter (|dx| <= ex, |dy| <= ey for every pixel inside the ellipse)
  p_s1 : process (clk)
    variable dxl, a : signed(D_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      last1 <= px_valid and px_last;
      for l in 0 to LANES - 1 loop
        m1(l) <= px_valid and px_mask(l);
        dxl := px_dx + l;
        if dxl(D_W - 1) = '1' then
          a := -dxl;
        else
          a := dxl;
        end if;
        adx1(l) <= unsigned(a(HALF_W - 1 downto 0));
      end loop;
      if px_dy(D_W - 1) = '1' then
        a := -px_dy;
      else
        a := px_dy;
      end if;
      ady1 <= unsigned(a(HALF_W - 1 downto 0));
      if rst = '1' then
        last1 <= '0';
        m1    <= (others => '0');
      end if;
    end if;
  end process;

  -- KB table (one copy) and its registered read
  p_kb : process (clk)
  begin
    if rising_edge(clk) then
      if kt_we = '1' then
        kb_ram(to_integer(kt_addr)) <= kt_kb;
      end if;
      kb2 <= kb_ram(to_integer(ady1));
    end if;
  end process;

  t_wd <= t_data_all when N_ORIENT > 1 else (others => t_data);

  -- per lane: KA table (stage 2 read) and T table (stage 3 read, address = the registered bin)
  g_lane : for l in 0 to LANES - 1 generate
    signal ka_ram : ka_ram_t := (others => (others => '0'));
    signal t_rd   : std_logic_vector(N_ORIENT - 1 downto 0);
  begin
    p_ka : process (clk)
    begin
      if rising_edge(clk) then
        if kt_we = '1' then
          ka_ram(to_integer(kt_addr)) <= kt_ka;
        end if;
        ka2(l) <= ka_ram(to_integer(adx1(l)));
      end if;
    end process;

    -- T: ms_ram_sdp, read latency 2 (on ECP5 one DP16KD with its output register: the table's
    -- ~5.8 ns clock-to-out no longer reaches the fabric; the inferred architecture: a read
    -- register and one more), address = the registered bin (edge s + 2), data after edge s + 3;
    -- the write port registered (WR_LAT 1: written at init only, one clock later is harmless)
    u_t : entity work.ms_ram_sdp
      generic map (DEPTH => 2 ** BIN_W, DATA_W => N_ORIENT, ADDR_W => BIN_W, RD_LAT => 2, WR_LAT => 1)
      port map (clk => clk, we => t_we, waddr => t_addr, wdata => t_wd,
                raddr => unsigned(bin2((l + 1) * BIN_W - 1 downto l * BIN_W)), rdata => t_rd);
    -- the lane's orientation selects its bit of the word (after the RAM's output register; an
    -- orientation >= N_ORIENT, only on masked lanes, reads 0)
    p_tsel : process (t_rd, obin4)
      variable ob : natural;
    begin
      if N_ORIENT = 1 then
        t4(l) <= t_rd(0);
      else
        ob := to_integer(unsigned(obin4((l + 1) * ORIENT_W - 1 downto l * ORIENT_W)));
        t4(l) <= '0';
        for o in 0 to N_ORIENT - 1 loop
          if ob = o then
            t4(l) <= t_rd(o);
          end if;
        end loop;
      end if;
    end process;

    p_d2q : process (clk)
    begin
      if rising_edge(clk) then
        d3(l) <= resize(ka2(l), D2Q_W) + resize(kb2, D2Q_W);
        d4(l) <= d3(l);
      end if;
    end process;
  end generate;

  -- stages 2 .. 4: flags; the bins registered once after the region RAM
  p_s23 : process (clk)
  begin
    if rising_edge(clk) then
      bin2  <= ram_data;
      obin2 <= ram_obin;
      obin3 <= obin2;
      obin4 <= obin3;
      m2    <= m1;
      last2 <= last1;
      m3    <= m2;
      last3 <= last2;
      m4    <= m3;
      last4 <= last3;
      if rst = '1' then
        m2    <= (others => '0');
        last2 <= '0';
        m3    <= (others => '0');
        last3 <= '0';
        m4    <= (others => '0');
        last4 <= '0';
      end if;
    end if;
  end process;

  -- stage 5: per-lane terms (tree level 0), then one tree level per clock
  p_tree : process (clk)
    variable tv, inn : std_logic;
    variable n       : natural;
  begin
    if rising_edge(clk) then
      for l in 0 to LANES - 1 loop
        tv  := t4(l) and m4(l);
        inn := '0';
        if d4(l) < IN_LIM then
          inn := m4(l);
        end if;
        tr_nt(l)  <= (0 => tv, others => '0');
        tr_ni(l)  <= (0 => inn, others => '0');
        tr_nti(l) <= (0 => tv and inn, others => '0');
        if tv = '1' then
          tr_st(l) <= resize(d4(l), TS_W);
        else
          tr_st(l) <= (others => '0');
        end if;
      end loop;
      last_t(0) <= last4;
      for k in 1 to TL loop
        n := LANES / 2 ** k;
        for i in 0 to n - 1 loop
          tr_st(k * LANES + i)  <= tr_st((k - 1) * LANES + 2 * i) + tr_st((k - 1) * LANES + 2 * i + 1);
          tr_nt(k * LANES + i)  <= tr_nt((k - 1) * LANES + 2 * i) + tr_nt((k - 1) * LANES + 2 * i + 1);
          tr_ni(k * LANES + i)  <= tr_ni((k - 1) * LANES + 2 * i) + tr_ni((k - 1) * LANES + 2 * i + 1);
          tr_nti(k * LANES + i) <= tr_nti((k - 1) * LANES + 2 * i) + tr_nti((k - 1) * LANES + 2 * i + 1);
        end loop;
        last_t(k) <= last_t(k - 1);
      end loop;
      if rst = '1' then
        last_t <= (others => '0');
      end if;
    end if;
  end process;

  -- accumulators: the last beat of a pass writes the results and restarts them from 0
  p_acc : process (clk)
    variable s_st  : unsigned(ST2_W - 1 downto 0);
    variable s_nt, s_ni, s_nti : unsigned(COUNT_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      s_st  := a_st + resize(tr_st(TL * LANES), ST2_W);
      s_nt  := a_nt + resize(tr_nt(TL * LANES), COUNT_W);
      s_ni  := a_ni + resize(tr_ni(TL * LANES), COUNT_W);
      s_nti := a_nti + resize(tr_nti(TL * LANES), COUNT_W);
      done_r <= last_t(TL);
      if last_t(TL) = '1' then
        r_st  <= s_st;
        r_nt  <= s_nt;
        r_ni  <= s_ni;
        r_nti <= s_nti;
        a_st  <= (others => '0');
        a_nt  <= (others => '0');
        a_ni  <= (others => '0');
        a_nti <= (others => '0');
      else
        a_st  <= s_st;
        a_nt  <= s_nt;
        a_ni  <= s_ni;
        a_nti <= s_nti;
      end if;
      if rst = '1' then
        done_r <= '0';
        a_st   <= (others => '0');
        a_nt   <= (others => '0');
        a_ni   <= (others => '0');
        a_nti  <= (others => '0');
      end if;
    end if;
  end process;

  done  <= done_r;
  nt    <= r_nt;
  st2   <= r_st;
  n_in  <= r_ni;
  nt_in <= r_nti;
end architecture;
