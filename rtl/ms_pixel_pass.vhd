-- ms_pixel_pass: one pixel pass of the mean-shift engine (scan -> region RAM -> kernel -> histogram).
--
-- On `start` it scans the window centred at (win_x, win_y) (region-relative px,
-- half extents ex, ey) LANES pixels per clock (ms_window_scan: in each row only the
-- LANES-aligned groups that reach the kernel ellipse, |dx| <= XR[|dy|], with a
-- per-lane mask of the pixels inside it), reads the bins from the external region
-- RAM (LANES banks, data RAM_LAT clocks after the address), evaluates the kernel value of
-- each lane (LANES x ms_kernel, private KA/KB copies written through the kt_* port;
-- the scan keeps the XR table) and accumulates H, N, SX, SY of the inside pixels
-- into the per-bin accumulators (ms_histogram).
-- Inside test: the scan's row-extent mask |dx| <= XR[|dy|] (|dy| <= ey) is exactly
-- the model's TA[|dx|] + TB[|dy|] < D (TA grows with |dx|, dx = 0 is inside every
-- row), so kt_ta, kt_tb and kd_d are not used (kept so that the interface and
-- ms_kernel_tables stay as they are; synthesis removes them).  `done` pulses when
-- the last pixel has been accumulated; the accumulators are then read and cleared
-- through the bin_rd_* port (BIN_RD_LAT = 3 clocks, one bin per clock).
--
-- Cycle count: if rising edge s samples start = '1', done = '1' is sampled by
-- edge s + C (done is high during the cycle before that edge), with
--   C = sum over dy = -ey .. ey of G(dy) + PASS_LAT, PASS_LAT = 10
--   (scan row pipeline 2, kernel 4 (the RAM read, RAM_LAT <= 4 clocks, overlaps it), histogram 4:
--   see docs/blocks/ms_pixel_pass.md; PASS_LAT does not depend on RAM_LAT),
--   G(dy) = floor((win_x + XR[|dy|]) / LANES) - floor((win_x - XR[|dy|]) / LANES) + 1.
-- Throughput: LANES pixels per clock, no stall.  Handshake: `start` is a pulse,
-- accepted only when idle (after `done` of the previous pass) and ready = '1';
-- the bin read port is used only between passes (from the cycle of `done` on), a
-- bin at most once in 3 clocks (ms_histogram).  ex, ey and the kernel tables must
-- be stable during a pass.
-- Scan tap (px_*): the scan's beat (valid, lane mask, lane-0 dx, dy, last) in the cycle its
-- ram_addr is out, for ms_target_stats (v2), which reads the same beat's bins from ram_data one
-- clock later (so with RAM_LAT = 1 only; ms_tracker_v2 delays the tap RAM_LAT - 1 clocks); wires from the
-- scan's registers, the pass itself is unchanged.
-- ram_addr_next: what ram_addr holds at the next clock (ms_window_scan's out_addr_next), for a read
-- port that registers the address once more in front of its RAMs (ms_slot_pool): such a port reads
-- ram_addr_next with one clock more of latency and returns the data when a RAM_LAT port behind
-- ram_addr would.
-- N_ORIENT > 1 (tracker v2's joint colour x orientation bins, joint bin = N_ORIENT u + o): ram_obin
-- carries each lane's orientation bin o (0 .. N_ORIENT - 1, 4 bits per lane) from an orientation
-- region RAM read at the same address with the same latency as ram_data; it travels beside the
-- colour bin u through the same delay stages to ms_histogram's in_obin (bank o), and the read
-- port returns, per colour address u, the N_ORIENT banks on bin_*_all (bank o at bits o*width;
-- bin_h .. bin_sy = bank 0).  Cycle count, PASS_LAT and BIN_RD_LAT are unchanged.  N_ORIENT = 1:
-- ram_obin is ignored (no delay stages for it), bin_*_all = bin_h .. bin_sy.
-- Model: mstrack.fixed.blocks.ms_histogram(bins, region, win, ms_kernel(w, h, ...), n_bins); with
-- N_ORIENT > 1 on the joint bins N_ORIENT u + o, n_bins = N_ORIENT 2**BIN_W, read out as
-- mstrack.fixed.blocks.ms_histogram_banks.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_pixel_pass is
  generic (
    LANES       : natural := 2;   -- pixels per clock (power of 2): LANES kernels, LANES histogram banks
    BIN_W       : natural := 9;   -- bin width; N_BINS = 2**BIN_W histogram entries per bank
    HALF_W      : natural := 6;   -- width of ex, ey, kernel table address
    REGION_W    : natural := 8;   -- width of region-relative coordinates
    STRIDE      : natural := 96;  -- region RAM words per row (ceil(REGION_MAX / LANES))
    ADDR_W      : natural := 15;  -- region RAM address width per bank
    KERNEL_EPAN : natural := 0;   -- 0 flat, 1 Epanechnikov (KA/KB tables, H stored apart from N)
    KERNEL_BITS : natural := 8;   -- Epanechnikov k = 2**KERNEL_BITS - KA - KB
    KVAL_W      : natural := 1;   -- width of k, KA, KB
    KD_W        : natural := 29;  -- width of TA, TB, D (unused ports)
    HIST_W      : natural := 14;  -- width of H
    COUNT_W     : natural := 14;  -- width of N
    POSSUM_W    : natural := 21;  -- width of the signed SX, SY
    RAM_LAT     : positive := 1;  -- region RAM read latency, 1 .. 4 (3 / 4: ms_ram_sdp on ECP5): no clock more, RAM_LAT - 1 bin delay stages fewer
    N_ORIENT    : natural range 1 to 16 := 1  -- orientation banks of the histogram (joint bins; 1 = colour bins only,
                                  -- ram_obin ignored)
  );
  port (
    clk          : in  std_logic;                                    -- clock
    rst          : in  std_logic;                                    -- synchronous reset (control; starts the histogram clear)
    ready        : out std_logic;                                    -- '0' while the histogram clears after reset (2**BIN_W clocks)
    -- pass control
    start        : in  std_logic;                                    -- pulse: scan the window at (win_x, win_y)
    win_x        : in  unsigned(REGION_W - 1 downto 0);              -- window centre column (region-relative)
    win_y        : in  unsigned(REGION_W - 1 downto 0);              -- window centre row (region-relative)
    ex           : in  unsigned(HALF_W - 1 downto 0);                -- half extent x (stable)
    ey           : in  unsigned(HALF_W - 1 downto 0);                -- half extent y (stable)
    done         : out std_logic;                                    -- pulse: all pixels accumulated
    -- kernel table write port (from ms_kernel_tables)
    kt_we        : in  std_logic;                                    -- write entry kt_addr
    kt_addr      : in  unsigned(HALF_W - 1 downto 0);                -- entry index i
    kt_ta        : in  unsigned(KD_W - 1 downto 0);                  -- TA[i] = 4 i^2 h^2 (unused: row-extent mask)
    kt_tb        : in  unsigned(KD_W - 1 downto 0);                  -- TB[i] = 4 i^2 w^2 (unused: row-extent mask)
    kt_ka        : in  unsigned(KVAL_W - 1 downto 0);                -- KA[i]
    kt_kb        : in  unsigned(KVAL_W - 1 downto 0);                -- KB[i]
    kt_xr        : in  unsigned(HALF_W - 1 downto 0);                -- XR[i]: largest |dx| inside in row |dy| = i
    kd_d         : in  unsigned(KD_W - 1 downto 0);                  -- D = w^2 h^2 (unused: row-extent mask)
    -- region RAM read port (bank l at l*ADDR_W / l*BIN_W)
    ram_addr     : out std_logic_vector(LANES * ADDR_W - 1 downto 0);  -- per bank word address
    ram_addr_next : out std_logic_vector(LANES * ADDR_W - 1 downto 0); -- ram_addr of the next clock (combinational)
    ram_data     : in  std_logic_vector(LANES * BIN_W - 1 downto 0);   -- per bank bin, RAM_LAT clocks after ram_addr
    ram_obin     : in  std_logic_vector(LANES * 4 - 1 downto 0) := (others => '0');  -- N_ORIENT > 1: per bank
                                                                     -- orientation bin (lane l at l*4), as ram_data
    -- scan tap (ms_target_stats sits beside the pass on it; the bins of a beat are ram_data one clock later)
    px_valid     : out std_logic;                                    -- beat valid (the beat whose ram_addr is out now)
    px_mask      : out std_logic_vector(LANES - 1 downto 0);          -- lane l inside the kernel ellipse
    px_dx        : out signed(REGION_W downto 0);                    -- dx of lane 0 (lane l: px_dx + l)
    px_dy        : out signed(REGION_W downto 0);                    -- dy of the beat's row
    px_last      : out std_logic;                                    -- final beat of the pass
    -- bin read-and-clear port
    bin_rd_en    : in  std_logic;                                    -- read and clear bin bin_rd_addr
    bin_rd_addr  : in  unsigned(BIN_W - 1 downto 0);                 -- bin
    bin_rd_valid : out std_logic;                                    -- BIN_RD_LAT = 3 clocks after bin_rd_en
    bin_h        : out unsigned(HIST_W - 1 downto 0);                -- H of the bin (sum over lanes)
    bin_n        : out unsigned(COUNT_W - 1 downto 0);               -- N of the bin
    bin_sx       : out signed(POSSUM_W - 1 downto 0);                -- SX of the bin
    bin_sy       : out signed(POSSUM_W - 1 downto 0);                -- SY of the bin (bank 0)
    -- N_ORIENT banks of the bin (bank o at bits o*width, ms_histogram's bin_*_all; with bin_rd_valid)
    bin_h_all    : out std_logic_vector(N_ORIENT * HIST_W - 1 downto 0);
    bin_n_all    : out std_logic_vector(N_ORIENT * COUNT_W - 1 downto 0);
    bin_sx_all   : out std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0);
    bin_sy_all   : out std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0)
  );
end entity;

architecture rtl of ms_pixel_pass is
  constant D_W        : natural := REGION_W + 1;
  constant KERNEL_LAT : natural := 4;   -- ms_kernel

  -- scan outputs (cycle t)
  signal sc_valid, sc_last : std_logic;
  signal sc_addr           : unsigned(ADDR_W - 1 downto 0);
  signal sc_addr_next      : unsigned(ADDR_W - 1 downto 0);
  signal sc_dx, sc_dy      : signed(D_W - 1 downto 0);
  signal sc_mask           : std_logic_vector(LANES - 1 downto 0);

  -- delays to the histogram input (cycle t + KERNEL_LAT); index i = value of cycle t + i
  type d_arr_t is array (1 to KERNEL_LAT) of signed(D_W - 1 downto 0);
  signal hist_bin          : std_logic_vector(LANES * BIN_W - 1 downto 0);  -- the bins at cycle t + KERNEL_LAT
  signal hist_obin         : std_logic_vector(LANES * 4 - 1 downto 0);      -- their orientation bins (N_ORIENT > 1)
  signal last_d            : std_logic_vector(1 to KERNEL_LAT) := (others => '0');
  signal dx_d, dy_d        : d_arr_t := (others => (others => '0'));

  -- kernel outputs (cycle t + KERNEL_LAT)
  signal k_valid, k_inside : std_logic_vector(LANES - 1 downto 0);
  signal k_val             : std_logic_vector(LANES * KVAL_W - 1 downto 0);
  signal h_valid           : std_logic_vector(LANES - 1 downto 0);
  signal h_dx              : std_logic_vector(LANES * D_W - 1 downto 0);
begin
  assert RAM_LAT <= KERNEL_LAT report "ms_pixel_pass: RAM_LAT must not exceed the kernel latency (4)" severity failure;

  u_scan : entity work.ms_window_scan
    generic map (LANES => LANES, HALF_W => HALF_W, REGION_W => REGION_W, STRIDE => STRIDE, ADDR_W => ADDR_W)
    port map (
      clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_xr => kt_xr,
      start => start, win_x => win_x, win_y => win_y, ex => ex, ey => ey,
      busy => open, out_valid => sc_valid, out_addr => sc_addr, out_addr_next => sc_addr_next, out_dx => sc_dx, out_dy => sc_dy,
      out_mask => sc_mask, out_last => sc_last);

  -- scan tap: the scan's registered outputs, unchanged (no logic added to the pass)
  px_valid <= sc_valid;
  px_mask  <= sc_mask;
  px_dx    <= sc_dx;
  px_dy    <= sc_dy;
  px_last  <= sc_last;

  g_addr : for l in 0 to LANES - 1 generate
    ram_addr((l + 1) * ADDR_W - 1 downto l * ADDR_W) <= std_logic_vector(sc_addr);
    ram_addr_next((l + 1) * ADDR_W - 1 downto l * ADDR_W) <= std_logic_vector(sc_addr_next);
  end generate;

  g_kernel : for l in 0 to LANES - 1 generate
    signal dx_l : signed(D_W - 1 downto 0);
    signal k_l  : unsigned(KVAL_W - 1 downto 0);
  begin
    dx_l <= sc_dx + l;
    u_kernel : entity work.ms_kernel
      generic map (HALF_W => HALF_W, D_W => D_W, KERNEL_EPAN => KERNEL_EPAN, KERNEL_BITS => KERNEL_BITS,
                   KVAL_W => KVAL_W)
      port map (
        clk => clk, rst => rst, kt_we => kt_we, kt_addr => kt_addr, kt_ka => kt_ka, kt_kb => kt_kb,
        in_valid => sc_valid, in_inside => sc_mask(l), in_dx => dx_l, in_dy => sc_dy,
        out_valid => k_valid(l), out_inside => k_inside(l), out_k => k_l);
    k_val((l + 1) * KVAL_W - 1 downto l * KVAL_W) <= std_logic_vector(k_l);
    h_valid(l) <= k_valid(l) and k_inside(l);
    h_dx((l + 1) * D_W - 1 downto l * D_W) <= std_logic_vector(dx_d(KERNEL_LAT) + l);
  end generate;

  p_delay : process (clk)
  begin
    if rising_edge(clk) then
      dx_d(1) <= sc_dx;
      dy_d(1) <= sc_dy;
      last_d(1) <= sc_last and sc_valid;
      for i in 2 to KERNEL_LAT loop
        dx_d(i)   <= dx_d(i - 1);
        dy_d(i)   <= dy_d(i - 1);
        last_d(i) <= last_d(i - 1);
      end loop;
      if rst = '1' then
        last_d <= (others => '0');
      end if;
    end if;
  end process;

  -- the bins: RAM_LAT = KERNEL_LAT: the RAM's (registered) read data itself; else delayed to t + KERNEL_LAT
  g_bin0 : if RAM_LAT = KERNEL_LAT generate
    hist_bin <= ram_data;
  end generate;
  g_bin : if RAM_LAT < KERNEL_LAT generate
    type bin_arr_t is array (RAM_LAT + 1 to KERNEL_LAT) of std_logic_vector(LANES * BIN_W - 1 downto 0);
    signal bin_d : bin_arr_t := (others => (others => '0'));
  begin
    p_bin : process (clk)
    begin
      if rising_edge(clk) then
        bin_d(RAM_LAT + 1) <= ram_data;
        for i in RAM_LAT + 2 to KERNEL_LAT loop
          bin_d(i) <= bin_d(i - 1);
        end loop;
      end if;
    end process;
    hist_bin <= bin_d(KERNEL_LAT);
  end generate;

  -- the orientation bins: the same delay as the colour bins (N_ORIENT > 1 only)
  g_obin1 : if N_ORIENT = 1 generate
    hist_obin <= (others => '0');
  end generate;
  g_obin0 : if N_ORIENT > 1 and RAM_LAT = KERNEL_LAT generate
    hist_obin <= ram_obin;
  end generate;
  g_obin : if N_ORIENT > 1 and RAM_LAT < KERNEL_LAT generate
    type obin_arr_t is array (RAM_LAT + 1 to KERNEL_LAT) of std_logic_vector(LANES * 4 - 1 downto 0);
    signal obin_d : obin_arr_t := (others => (others => '0'));
  begin
    p_obin : process (clk)
    begin
      if rising_edge(clk) then
        obin_d(RAM_LAT + 1) <= ram_obin;
        for i in RAM_LAT + 2 to KERNEL_LAT loop
          obin_d(i) <= obin_d(i - 1);
        end loop;
      end if;
    end process;
    hist_obin <= obin_d(KERNEL_LAT);
  end generate;

  u_hist : entity work.ms_histogram
    generic map (LANES => LANES, BIN_W => BIN_W, N_ORIENT => N_ORIENT, ORIENT_W => 4, D_W => D_W,
                 KERNEL_EPAN => KERNEL_EPAN, KVAL_W => KVAL_W,
                 HIST_W => HIST_W, COUNT_W => COUNT_W, POSSUM_W => POSSUM_W, BIN_RD_LAT => 3)
    port map (
      clk => clk, rst => rst, ready => ready,
      in_valid => h_valid, in_bin => hist_bin, in_obin => hist_obin, in_k => k_val, in_dx => h_dx, in_dy => dy_d(KERNEL_LAT),
      in_last => last_d(KERNEL_LAT), last_done => done,
      bin_rd_en => bin_rd_en, bin_rd_addr => bin_rd_addr, bin_rd_valid => bin_rd_valid,
      bin_h => bin_h, bin_n => bin_n, bin_sx => bin_sx, bin_sy => bin_sy,
      bin_h_all => bin_h_all, bin_n_all => bin_n_all, bin_sx_all => bin_sx_all, bin_sy_all => bin_sy_all);
end architecture;
