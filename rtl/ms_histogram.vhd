-- ms_histogram: per-bin accumulators of a pixel pass, LANES pixels per clock.
--
-- For every valid lane pixel (the caller sets in_valid(l) only for pixels
-- inside the kernel) with bin u, kernel value k, offsets dx, dy:
--   H[u] += k, N[u] += 1, SX[u] += dx, SY[u] += dy.
-- Each lane owns a bank: a simple dual-port RAM of N_BINS words (one read and
-- one write per clock) holding {H, N, SX, SY} (only N when KERNEL_EPAN = 0:
-- then H = N).  Read-modify-write pipeline, per lane:
--   stage 0 (input cycle): the RAM is read at the pixel's bin (registered read);
--   stage 1: old = RAM word, or the word written at the previous edge when it
--            was the same bin (forwarding: the only write the read can miss),
--            new = old + increment, written at the end of stage 1.
-- So any sequence of bins, including runs of one bin, accumulates exactly.
--
-- Read-and-clear port (used only when no pixels are in flight): bin_rd_en with
-- bin_rd_addr goes down the same pipeline, writes 0 into every bank and
-- returns the sums over the lanes of H, N, SX, SY with bin_rd_valid exactly
-- BIN_RD_LAT = 3 clocks later (edge sampling bin_rd_en = edge n -> outputs
-- valid after edge n + 2; the lane sum has its own register stage).  One bin
-- per clock.  Pixel inputs have priority; do not mix both in one cycle.
--
-- After reset the block writes 0 into every entry (N_BINS clocks, ready = '0'
-- meanwhile; inputs are ignored), so it never depends on RAM power-up values.
-- in_last marks the final beat of a pass: last_done pulses once that beat's
-- updates are written (HIST_ACC_LAT = 2 clocks after in_last is sampled).
-- Model: mstrack.fixed.blocks.ms_histogram (Hist H, N, SX, SY).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_histogram is
  generic (
    LANES       : natural := 2;   -- pixels per clock: LANES RAM banks and LANES adders of each field
    BIN_W       : natural := 9;   -- bin index width; N_BINS = 2**BIN_W entries per bank
    D_W         : natural := 9;   -- width of the signed dx, dy inputs
    KERNEL_EPAN : natural := 0;   -- 1: store H (HIST_W) besides N; 0: H = N, saves HIST_W RAM bits per entry
    KVAL_W      : natural := 1;   -- width of k
    HIST_W      : natural := 14;  -- width of H
    COUNT_W     : natural := 14;  -- width of N
    POSSUM_W    : natural := 21;  -- width of the signed SX, SY
    BIN_RD_LAT  : natural := 3    -- read port latency: fixed at 3 (documented constant, checked)
  );
  port (
    clk          : in  std_logic;                                   -- clock
    rst          : in  std_logic;                                   -- synchronous reset; starts the RAM clear
    ready        : out std_logic;                                   -- '0' while the RAMs are cleared after reset
    -- pixels
    in_valid     : in  std_logic_vector(LANES - 1 downto 0);        -- per lane: accumulate this pixel
    in_bin       : in  std_logic_vector(LANES * BIN_W - 1 downto 0);  -- per lane bin (lane l at l*BIN_W)
    in_k         : in  std_logic_vector(LANES * KVAL_W - 1 downto 0); -- per lane kernel value
    in_dx        : in  std_logic_vector(LANES * D_W - 1 downto 0);  -- per lane signed dx
    in_dy        : in  signed(D_W - 1 downto 0);                    -- dy (same row for all lanes)
    in_last      : in  std_logic;                                   -- final beat of the pass
    last_done    : out std_logic;                                   -- pulse: final beat written
    -- bin read-and-clear port
    bin_rd_en    : in  std_logic;                                   -- read and clear bin bin_rd_addr
    bin_rd_addr  : in  unsigned(BIN_W - 1 downto 0);                -- bin to read
    bin_rd_valid : out std_logic;                                   -- sums valid (BIN_RD_LAT after bin_rd_en)
    bin_h        : out unsigned(HIST_W - 1 downto 0);               -- sum over lanes of H
    bin_n        : out unsigned(COUNT_W - 1 downto 0);              -- sum over lanes of N
    bin_sx       : out signed(POSSUM_W - 1 downto 0);               -- sum over lanes of SX
    bin_sy       : out signed(POSSUM_W - 1 downto 0)                -- sum over lanes of SY
  );
end entity;

architecture rtl of ms_histogram is
  constant N_BINS : natural := 2 ** BIN_W;
  constant H_W    : natural := HIST_W * KERNEL_EPAN;            -- stored H bits (0 when flat)
  constant E_W    : natural := H_W + COUNT_W + 2 * POSSUM_W;    -- RAM word
  -- word layout: [SY | SX | N | H]
  constant N_LO   : natural := H_W;
  constant SX_LO  : natural := H_W + COUNT_W;
  constant SY_LO  : natural := SX_LO + POSSUM_W;

  subtype word_t is std_logic_vector(E_W - 1 downto 0);
  type word_arr_t is array (0 to LANES - 1) of word_t;

  -- per-lane sums for the read port
  type h_arr_t is array (0 to LANES - 1) of unsigned(HIST_W - 1 downto 0);
  type n_arr_t is array (0 to LANES - 1) of unsigned(COUNT_W - 1 downto 0);
  type s_arr_t is array (0 to LANES - 1) of signed(POSSUM_W - 1 downto 0);

  signal rd_word  : word_arr_t;                         -- registered RAM read, per lane
  signal fw_word  : word_arr_t;                         -- word written at the previous edge, per lane
  signal fw_bin   : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal fw_valid : std_logic_vector(LANES - 1 downto 0) := (others => '0');

  -- stage 1 control
  signal s1_acc   : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- accumulate
  signal s1_clr   : std_logic := '0';                                         -- read-and-clear
  signal s1_bin   : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal s1_k     : std_logic_vector(LANES * KVAL_W - 1 downto 0) := (others => '0');
  signal s1_dx    : std_logic_vector(LANES * D_W - 1 downto 0) := (others => '0');
  signal s1_dy    : signed(D_W - 1 downto 0) := (others => '0');
  signal s1_last  : std_logic := '0';

  -- read-port lane values (stage 2) and sums (stage 3)
  signal s2_valid : std_logic := '0';
  signal s2_h     : h_arr_t;
  signal s2_n     : n_arr_t;
  signal s2_sx    : s_arr_t;
  signal s2_sy    : s_arr_t;
  signal s3_valid : std_logic := '0';
  signal s3_h     : unsigned(HIST_W - 1 downto 0) := (others => '0');
  signal s3_n     : unsigned(COUNT_W - 1 downto 0) := (others => '0');
  signal s3_sx    : signed(POSSUM_W - 1 downto 0) := (others => '0');
  signal s3_sy    : signed(POSSUM_W - 1 downto 0) := (others => '0');
  signal done_r   : std_logic := '0';

  -- reset clear
  signal clearing  : std_logic := '1';
  signal clr_addr  : unsigned(BIN_W - 1 downto 0) := (others => '0');

  -- old word of lane l in stage 1 (RAM or forwarded)
  function sel_old(rd, fw : word_t; fv : std_logic; fb, b : std_logic_vector) return word_t is
  begin
    if fv = '1' and fb = b then
      return fw;
    end if;
    return rd;
  end function;
begin
  assert BIN_RD_LAT = 3 report "ms_histogram: BIN_RD_LAT is fixed at 3" severity failure;
  assert KERNEL_EPAN = 1 or HIST_W = COUNT_W
    report "ms_histogram: flat kernel needs HIST_W = COUNT_W (H = N)" severity failure;

  -- reset clear of the RAMs: N_BINS cycles after reset
  p_clear : process (clk)
  begin
    if rising_edge(clk) then
      if clearing = '1' then
        clr_addr <= clr_addr + 1;
        if clr_addr = N_BINS - 1 then
          clearing <= '0';
        end if;
      end if;
      if rst = '1' then
        clearing <= '1';
        clr_addr <= (others => '0');
      end if;
    end if;
  end process;
  ready <= not clearing;

  -- stage 0 -> 1 control
  p_s1 : process (clk)
  begin
    if rising_edge(clk) then
      if clearing = '0' and unsigned(in_valid) /= 0 then
        s1_acc <= in_valid;
        s1_clr <= '0';
      elsif clearing = '0' and bin_rd_en = '1' then
        s1_acc <= (others => '0');
        s1_clr <= '1';
      else
        s1_acc <= (others => '0');
        s1_clr <= '0';
      end if;
      s1_last <= in_last and not clearing;
      if bin_rd_en = '1' and unsigned(in_valid) = 0 then
        for l in 0 to LANES - 1 loop
          s1_bin((l + 1) * BIN_W - 1 downto l * BIN_W) <= std_logic_vector(bin_rd_addr);
        end loop;
      else
        s1_bin <= in_bin;
      end if;
      s1_k  <= in_k;
      s1_dx <= in_dx;
      s1_dy <= in_dy;
      if rst = '1' then
        s1_acc  <= (others => '0');
        s1_clr  <= '0';
        s1_last <= '0';
      end if;
    end if;
  end process;

  g_lane : for l in 0 to LANES - 1 generate
    type ram_t is array (0 to N_BINS - 1) of word_t;
    signal ram     : ram_t := (others => (others => '0'));
    signal rd_addr : unsigned(BIN_W - 1 downto 0);
    signal old_w   : word_t;
    signal new_w   : word_t;
    signal we      : std_logic;
    signal wr_addr : unsigned(BIN_W - 1 downto 0);
    signal wr_data : word_t;
  begin
    -- read address: pixel bin, else read-port address
    rd_addr <= bin_rd_addr when (bin_rd_en = '1' and unsigned(in_valid) = 0)
               else unsigned(in_bin((l + 1) * BIN_W - 1 downto l * BIN_W));

    old_w <= sel_old(rd_word(l), fw_word(l), fw_valid(l), fw_bin((l + 1) * BIN_W - 1 downto l * BIN_W),
                     s1_bin((l + 1) * BIN_W - 1 downto l * BIN_W));

    p_add : process (all)
      variable w    : word_t;
      variable kinc : unsigned(HIST_W - 1 downto 0);
    begin
      w := old_w;
      if s1_clr = '1' then
        w := (others => '0');
      else
        if KERNEL_EPAN = 1 then
          kinc := resize(unsigned(s1_k((l + 1) * KVAL_W - 1 downto l * KVAL_W)), HIST_W);
          w(H_W - 1 downto 0) := std_logic_vector(unsigned(old_w(H_W - 1 downto 0)) + kinc);
        end if;
        w(SX_LO - 1 downto N_LO) := std_logic_vector(unsigned(old_w(SX_LO - 1 downto N_LO)) + 1);
        w(SY_LO - 1 downto SX_LO) := std_logic_vector(signed(old_w(SY_LO - 1 downto SX_LO))
                                     + resize(signed(s1_dx((l + 1) * D_W - 1 downto l * D_W)), POSSUM_W));
        w(E_W - 1 downto SY_LO) := std_logic_vector(signed(old_w(E_W - 1 downto SY_LO))
                                   + resize(s1_dy, POSSUM_W));
      end if;
      new_w <= w;
    end process;

    -- write port: reset clear, else stage-1 result
    we      <= '1' when clearing = '1' or s1_acc(l) = '1' or s1_clr = '1' else '0';
    wr_addr <= clr_addr when clearing = '1' else unsigned(s1_bin((l + 1) * BIN_W - 1 downto l * BIN_W));
    wr_data <= (others => '0') when clearing = '1' else new_w;

    p_ram : process (clk)
    begin
      if rising_edge(clk) then
        if we = '1' then
          ram(to_integer(wr_addr)) <= wr_data;
        end if;
        rd_word(l) <= ram(to_integer(rd_addr));
      end if;
    end process;

    p_fw : process (clk)
    begin
      if rising_edge(clk) then
        fw_word(l) <= wr_data;
        fw_bin((l + 1) * BIN_W - 1 downto l * BIN_W) <= std_logic_vector(wr_addr);
        fw_valid(l) <= we;
      end if;
    end process;

    -- read port, stage 2: lane values of the cleared entry
    p_s2 : process (clk)
    begin
      if rising_edge(clk) then
        if KERNEL_EPAN = 1 then
          s2_h(l) <= unsigned(old_w(H_W - 1 downto 0));
        else
          s2_h(l) <= resize(unsigned(old_w(SX_LO - 1 downto N_LO)), HIST_W);
        end if;
        s2_n(l)  <= unsigned(old_w(SX_LO - 1 downto N_LO));
        s2_sx(l) <= signed(old_w(SY_LO - 1 downto SX_LO));
        s2_sy(l) <= signed(old_w(E_W - 1 downto SY_LO));
      end if;
    end process;
  end generate;

  -- read port, stage 3: sums over the lanes; pass done
  p_s3 : process (clk)
    variable h  : unsigned(HIST_W - 1 downto 0);
    variable n  : unsigned(COUNT_W - 1 downto 0);
    variable sx : signed(POSSUM_W - 1 downto 0);
    variable sy : signed(POSSUM_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      s2_valid <= s1_clr;
      h := (others => '0');
      n := (others => '0');
      sx := (others => '0');
      sy := (others => '0');
      for l in 0 to LANES - 1 loop
        h  := h + s2_h(l);
        n  := n + s2_n(l);
        sx := sx + s2_sx(l);
        sy := sy + s2_sy(l);
      end loop;
      s3_h     <= h;
      s3_n     <= n;
      s3_sx    <= sx;
      s3_sy    <= sy;
      s3_valid <= s2_valid;
      done_r   <= s1_last;
      if rst = '1' then
        s2_valid <= '0';
        s3_valid <= '0';
        done_r   <= '0';
      end if;
    end if;
  end process;

  last_done    <= done_r;
  bin_rd_valid <= s3_valid;
  bin_h        <= s3_h;
  bin_n        <= s3_n;
  bin_sx       <= s3_sx;
  bin_sy       <= s3_sy;
end architecture;
