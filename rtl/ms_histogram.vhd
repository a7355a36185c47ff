-- ms_histogram: per-bin accumulators of a pixel pass, LANES pixels per clock,
-- optionally banked by orientation (N_ORIENT banks per lane).
--
-- For every valid lane pixel (the caller sets in_valid(l) only for pixels
-- inside the kernel) with bin u, orientation o, kernel value k, offsets dx, dy:
--   H[o][u] += k, N[o][u] += 1, SX[o][u] += dx, SY[o][u] += dy.
-- N_ORIENT = 1 (default): one bank, in_obin is ignored, o = 0 (the plain
-- histogram).  N_ORIENT = 9 (tracker v2's joint colour x orientation bins,
-- joint bin = 9 u + o): bank o at address u holds joint bin 9 u + o, so the
-- read port returns, per colour address, the 9 orientation bins at once.
-- Each lane owns N_ORIENT banks: simple dual-port RAMs of N_BINS words (one
-- read and one write per clock) holding {H, N, SX, SY} (only N when
-- KERNEL_EPAN = 0: then H = N).  A lane pixel reads address u in all of its
-- banks and writes only bank o.  Read-modify-write pipeline, per lane (one
-- adder per lane, whatever N_ORIENT):
--   stage 0 (input cycle): the RAMs are read at the pixel's bin (registered
--            read); its tag (bin, orientation) is compared with the tags of the
--            three RAM writes the read misses (the one at the read edge, wq now;
--            the next edge's, stage 2 now; the one after, stage 1 now), the hits
--            are registered.  A hit needs the same bin and the same orientation
--            (or a write to all banks: a clear);
--   stage 1: the read data is registered once more, with no logic between (no
--            RAM clock-to-out in the add); the newest missed write to the same
--            tag, if any, is selected and registered (forwarding);
--   stage 2: old = forwarded word, else bank o's RAM word (an N_ORIENT:1
--            multiplexer when N_ORIENT > 1), new = old + increment, registered
--            (wq, with a one-hot bank write enable) at the end of stage 2 and
--            written into bank o at the next edge (no logic between the
--            registers and the RAM inputs).
-- So any sequence of (bin, orientation), including runs of one joint bin and
-- one bin with changing orientations, accumulates exactly.
--
-- Read-and-clear port (used only between passes: from the cycle in which
-- last_done is high on, and after ready): bin_rd_en with bin_rd_addr goes down
-- the same pipeline, writes 0 into that address of every bank and returns, per
-- orientation bank o, the sums over the lanes of H, N, SX, SY (bin_*_all, bank o
-- at bits o*W; bin_h, bin_n, bin_sx, bin_sy = bank 0) with bin_rd_valid exactly
-- BIN_RD_LAT = 3 clocks later (edge sampling bin_rd_en = edge n -> outputs valid
-- after edge n + 2; the lane sums of the RAM words are added in stage 2, without
-- forwarding: a bin must not be read again within 3 clocks; a simulation
-- assertion checks that no write to the bin is in flight).  One address (N_ORIENT
-- bins) per clock.  Do not use both in one cycle (the read port would win).
--
-- After reset the block writes 0 into every entry of every bank (N_BINS clocks,
-- the banks in parallel; ready = '0' meanwhile; inputs are ignored), so it never
-- depends on RAM power-up values.  in_last marks the final beat of a pass:
-- last_done pulses once that beat's updates are written into the RAMs
-- (HIST_ACC_LAT = 4 clocks after in_last is sampled).
-- Model: mstrack.fixed.blocks.ms_histogram (Hist H, N, SX, SY); with N_ORIENT > 1
-- the histogram of the joint bins N_ORIENT u + o seen through
-- mstrack.fixed.blocks.ms_histogram_banks (arrays [u][o]).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_histogram is
  generic (
    LANES       : natural := 2;   -- pixels per clock: LANES x N_ORIENT RAM banks and LANES adders of each field
    BIN_W       : natural := 9;   -- bin index width; N_BINS = 2**BIN_W entries per bank
    N_ORIENT    : natural range 1 to 16 := 1;  -- banks per lane (orientation bins); each costs a RAM of
                                  -- N_BINS words, its lane-sum adders on the read port and a wider
                                  -- stage-2 multiplexer; 1 = the plain histogram (in_obin ignored)
    ORIENT_W    : natural := 4;   -- width of an orientation bin in in_obin (2**ORIENT_W >= N_ORIENT)
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
    in_obin      : in  std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
                                                                    -- per lane orientation bank 0 .. N_ORIENT - 1
                                                                    -- (lane l at l*ORIENT_W); ignored if N_ORIENT = 1
    in_k         : in  std_logic_vector(LANES * KVAL_W - 1 downto 0); -- per lane kernel value
    in_dx        : in  std_logic_vector(LANES * D_W - 1 downto 0);  -- per lane signed dx
    in_dy        : in  signed(D_W - 1 downto 0);                    -- dy (same row for all lanes)
    in_last      : in  std_logic;                                   -- final beat of the pass
    last_done    : out std_logic;                                   -- pulse: final beat written
    -- bin read-and-clear port
    bin_rd_en    : in  std_logic;                                   -- read and clear bin bin_rd_addr (all banks)
    bin_rd_addr  : in  unsigned(BIN_W - 1 downto 0);                -- bin to read
    bin_rd_valid : out std_logic;                                   -- sums valid (BIN_RD_LAT after bin_rd_en)
    bin_h        : out unsigned(HIST_W - 1 downto 0);               -- bank 0: sum over lanes of H
    bin_n        : out unsigned(COUNT_W - 1 downto 0);              -- bank 0: sum over lanes of N
    bin_sx       : out signed(POSSUM_W - 1 downto 0);               -- bank 0: sum over lanes of SX
    bin_sy       : out signed(POSSUM_W - 1 downto 0);               -- bank 0: sum over lanes of SY
    bin_h_all    : out std_logic_vector(N_ORIENT * HIST_W - 1 downto 0);   -- bank o at o*HIST_W: unsigned H sum
    bin_n_all    : out std_logic_vector(N_ORIENT * COUNT_W - 1 downto 0);  -- bank o at o*COUNT_W: unsigned N sum
    bin_sx_all   : out std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0); -- bank o at o*POSSUM_W: signed SX sum
    bin_sy_all   : out std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0)  -- bank o at o*POSSUM_W: signed SY sum
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
  type bank_arr_t is array (0 to N_ORIENT - 1) of word_t;       -- one word per bank of a lane
  type lane_bank_arr_t is array (0 to LANES - 1) of bank_arr_t;
  subtype bank_mask_t is std_logic_vector(N_ORIENT - 1 downto 0);
  type bank_mask_arr_t is array (0 to LANES - 1) of bank_mask_t;

  signal rd_raw   : lane_bank_arr_t;                    -- registered RAM read (stage 1), per lane and bank
  signal rd_word  : lane_bank_arr_t;                    -- read data registered again (stage 2)
  -- RAM write registers (stage 3: written at the next edge) and the write of the previous edge
  signal wq_word, wq2_word   : word_arr_t;
  signal wq_bin, wq2_bin     : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal wq_obin             : std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
  signal wq_we, wq2_we       : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal wq_bwe              : bank_mask_arr_t := (others => (others => '0'));  -- per lane: banks written
  signal wq_all              : std_logic := '0';        -- wq is a clear (all banks)
  signal fwd_word : word_arr_t;                         -- stage 2: the newest write to its tag the RAM read missed
  signal fwd_hit  : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- stage 2: use fwd_word

  -- stage 1 control
  signal s1_acc   : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- accumulate
  signal s1_clr   : std_logic := '0';                                         -- read-and-clear
  signal s1_bin   : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal s1_obin  : std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
  signal s1_k     : std_logic_vector(LANES * KVAL_W - 1 downto 0) := (others => '0');
  signal s1_dx    : std_logic_vector(LANES * D_W - 1 downto 0) := (others => '0');
  signal s1_dy    : signed(D_W - 1 downto 0) := (others => '0');
  signal s1_last  : std_logic := '0';
  -- stage 2 control
  signal s2_acc   : std_logic_vector(LANES - 1 downto 0) := (others => '0');
  signal s2_clr   : std_logic := '0';
  signal s2_bin   : std_logic_vector(LANES * BIN_W - 1 downto 0) := (others => '0');
  signal s2_obin  : std_logic_vector(LANES * ORIENT_W - 1 downto 0) := (others => '0');
  signal s2_k     : std_logic_vector(LANES * KVAL_W - 1 downto 0) := (others => '0');
  signal s2_dx    : std_logic_vector(LANES * D_W - 1 downto 0) := (others => '0');
  signal s2_dy    : signed(D_W - 1 downto 0) := (others => '0');
  signal s2_last  : std_logic := '0';

  -- read-port sums (stage 3 = outputs), bank o at o*W
  signal s3_valid : std_logic := '0';
  signal s3_h     : std_logic_vector(N_ORIENT * HIST_W - 1 downto 0) := (others => '0');
  signal s3_n     : std_logic_vector(N_ORIENT * COUNT_W - 1 downto 0) := (others => '0');
  signal s3_sx    : std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0) := (others => '0');
  signal s3_sy    : std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0) := (others => '0');
  signal s3_last, done_r : std_logic := '0';

  -- reset clear
  signal clearing  : std_logic := '1';
  signal clr_addr  : unsigned(BIN_W - 1 downto 0) := (others => '0');

  function to_sl(b : boolean) return std_logic is
  begin
    if b then
      return '1';
    end if;
    return '0';
  end function;

  -- same bank: equal orientations, or either write/read covers all banks (a clear); always with one bank
  function same_bank(oa, ob : std_logic_vector; all_a, all_b : std_logic) return boolean is
  begin
    if N_ORIENT = 1 then
      return true;
    end if;
    return all_a = '1' or all_b = '1' or oa = ob;
  end function;
begin
  assert BIN_RD_LAT = 3 report "ms_histogram: BIN_RD_LAT is fixed at 3" severity failure;
  assert KERNEL_EPAN = 1 or HIST_W = COUNT_W
    report "ms_histogram: flat kernel needs HIST_W = COUNT_W (H = N)" severity failure;
  assert 2 ** ORIENT_W >= N_ORIENT report "ms_histogram: ORIENT_W too narrow for N_ORIENT" severity failure;

  -- reset clear of the RAMs: N_BINS cycles after reset (all banks in parallel)
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

  -- stage 0 -> 1 control (the read port wins when both are used in one cycle: do not)
  p_s1 : process (clk)
  begin
    if rising_edge(clk) then
      if clearing = '0' and bin_rd_en = '1' then
        s1_acc <= (others => '0');
        s1_clr <= '1';
      elsif clearing = '0' then
        s1_acc <= in_valid;
        s1_clr <= '0';
      else
        s1_acc <= (others => '0');
        s1_clr <= '0';
      end if;
      s1_last <= in_last and not clearing;
      s1_k  <= in_k;
      s1_dx <= in_dx;
      s1_dy <= in_dy;
      -- stage 1 -> 2
      s2_acc  <= s1_acc;
      s2_clr  <= s1_clr;
      s2_last <= s1_last;
      s2_bin  <= s1_bin;
      s2_obin <= s1_obin;
      s2_k    <= s1_k;
      s2_dx   <= s1_dx;
      s2_dy   <= s1_dy;
      -- the write register holds a clear of all banks (reset clear or read port)
      wq_all  <= clearing or s2_clr;
      if rst = '1' then
        s1_acc  <= (others => '0');
        s1_clr  <= '0';
        s1_last <= '0';
        s2_acc  <= (others => '0');
        s2_clr  <= '0';
        s2_last <= '0';
      end if;
    end if;
  end process;

  g_lane : for l in 0 to LANES - 1 generate
    signal rd_addr : std_logic_vector(BIN_W - 1 downto 0);   -- stage 0 bin = RAM read address
    signal rd_obin : std_logic_vector(ORIENT_W - 1 downto 0);  -- stage 0 orientation (0 when N_ORIENT = 1)
    signal rd_sel  : word_t;                                 -- stage 2: bank s2_o's RAM word
    signal old_w   : word_t;
    signal new_w   : word_t;                                 -- stage 2 result (0 for read-and-clear)
    signal we      : std_logic;                              -- stage 2 writes new_w at s2_b
    signal h1, h2, h3 : std_logic := '0';                    -- stage 1: tag of stage 2 / wq / wq2 is ours
    alias s1_b     : std_logic_vector(BIN_W - 1 downto 0) is s1_bin((l + 1) * BIN_W - 1 downto l * BIN_W);
    alias s2_b     : std_logic_vector(BIN_W - 1 downto 0) is s2_bin((l + 1) * BIN_W - 1 downto l * BIN_W);
    alias wq_b     : std_logic_vector(BIN_W - 1 downto 0) is wq_bin((l + 1) * BIN_W - 1 downto l * BIN_W);
    alias wq2_b    : std_logic_vector(BIN_W - 1 downto 0) is wq2_bin((l + 1) * BIN_W - 1 downto l * BIN_W);
    alias s1_o     : std_logic_vector(ORIENT_W - 1 downto 0) is s1_obin((l + 1) * ORIENT_W - 1 downto l * ORIENT_W);
    alias s2_o     : std_logic_vector(ORIENT_W - 1 downto 0) is s2_obin((l + 1) * ORIENT_W - 1 downto l * ORIENT_W);
    alias wq_o     : std_logic_vector(ORIENT_W - 1 downto 0) is wq_obin((l + 1) * ORIENT_W - 1 downto l * ORIENT_W);
  begin
    -- read address: read-port address, else pixel bin
    rd_addr <= std_logic_vector(bin_rd_addr) when bin_rd_en = '1'
               else in_bin((l + 1) * BIN_W - 1 downto l * BIN_W);
    rd_obin <= in_obin((l + 1) * ORIENT_W - 1 downto l * ORIENT_W) when N_ORIENT > 1
               else (others => '0');
    assert not (rising_edge(clk) and N_ORIENT > 1 and clearing = '0' and bin_rd_en = '0' and in_valid(l) = '1'
                and unsigned(rd_obin) >= N_ORIENT)
      report "ms_histogram: in_obin of a valid pixel >= N_ORIENT (the pixel is dropped)" severity error;

    -- stage 2 old word: the newest missed write to the tag (resolved in stage 1), else bank s2_o's word
    p_sel : process (all)
      variable w : word_t;
    begin
      w := rd_word(l)(0);
      for o in 1 to N_ORIENT - 1 loop
        if unsigned(s2_o) = o then
          w := rd_word(l)(o);
        end if;
      end loop;
      rd_sel <= w;
    end process;
    old_w <= fwd_word(l) when fwd_hit(l) = '1' else rd_sel;
    -- the read port needs no forwarding (nothing in flight to its bin, see the header)
    assert not (rising_edge(clk) and s2_clr = '1' and fwd_hit(l) = '1')
      report "ms_histogram: bin read while a write to that bin is in flight" severity error;

    p_add : process (all)
      variable w    : word_t;
      variable kinc : unsigned(HIST_W - 1 downto 0);
    begin
      w := old_w;
      if s2_clr = '1' then
        w := (others => '0');
      else
        if KERNEL_EPAN = 1 then
          kinc := resize(unsigned(s2_k((l + 1) * KVAL_W - 1 downto l * KVAL_W)), HIST_W);
          w(H_W - 1 downto 0) := std_logic_vector(unsigned(old_w(H_W - 1 downto 0)) + kinc);
        end if;
        w(SX_LO - 1 downto N_LO) := std_logic_vector(unsigned(old_w(SX_LO - 1 downto N_LO)) + 1);
        w(SY_LO - 1 downto SX_LO) := std_logic_vector(signed(old_w(SY_LO - 1 downto SX_LO))
                                     + resize(signed(s2_dx((l + 1) * D_W - 1 downto l * D_W)), POSSUM_W));
        w(E_W - 1 downto SY_LO) := std_logic_vector(signed(old_w(E_W - 1 downto SY_LO))
                                   + resize(s2_dy, POSSUM_W));
      end if;
      new_w <= w;
    end process;
    we <= s2_acc(l) or s2_clr;

    g_bank : for o in 0 to N_ORIENT - 1 generate
      type ram_t is array (0 to N_BINS - 1) of word_t;
      signal ram     : ram_t := (others => (others => '0'));
      signal bank_we : std_logic;                            -- write bank o (one bank: wq_we itself)
    begin
      bank_we <= wq_we(l) when N_ORIENT = 1 else wq_bwe(l)(o);
      p_ram : process (clk)
      begin
        if rising_edge(clk) then
          if bank_we = '1' then
            ram(to_integer(unsigned(wq_b))) <= wq_word(l);
          end if;
          -- the read data of a read/write collision is never used (stage 2 forwards that write,
          -- h3): 'X' lets synthesis map the RAM without emulating read-before-write across
          -- ports, which block RAM does not have
          if bank_we = '1' and wq_b = rd_addr then
            rd_raw(l)(o) <= (others => 'X');
          else
            rd_raw(l)(o) <= ram(to_integer(unsigned(rd_addr)));
          end if;
          rd_word(l)(o) <= rd_raw(l)(o);    -- no logic between: the RAM's output register
        end if;
      end process;
    end generate;

    p_fw : process (clk)
    begin
      if rising_edge(clk) then
        s1_b <= rd_addr;
        s1_o <= rd_obin;
        -- RAM write registers: the reset clear (all banks), else the stage 2 result (bank s2_o;
        -- all banks for a read-and-clear)
        if clearing = '1' then
          wq_we(l)   <= '1';
          wq_bwe(l)  <= (others => '1');
          wq_b       <= std_logic_vector(clr_addr);
          wq_word(l) <= (others => '0');
        else
          wq_we(l)   <= we;
          for o in 0 to N_ORIENT - 1 loop
            wq_bwe(l)(o) <= s2_clr or (s2_acc(l) and to_sl(N_ORIENT = 1 or unsigned(s2_o) = o));
          end loop;
          wq_b       <= s2_b;
          wq_word(l) <= new_w;
        end if;
        wq_o        <= s2_o;
        wq2_we(l)   <= wq_we(l);
        wq2_b       <= wq_b;
        wq2_word(l) <= wq_word(l);
        -- stage 0 -> 1: its read (at this edge) misses the RAM writes of this edge (wq now,
        -- wq2 in stage 1), of the next edge (stage 2 now, wq in stage 1) and of the one after
        -- (stage 1 now, stage 2 in stage 1); a hit needs the same bin and bank.  (A clear write
        -- can only be in wq: pixels and reads are ignored while clearing.)
        h1 <= (s1_acc(l) or s1_clr) and to_sl(s1_b = rd_addr and same_bank(s1_o, rd_obin, s1_clr, bin_rd_en));
        h2 <= we and to_sl(s2_b = rd_addr and same_bank(s2_o, rd_obin, s2_clr, bin_rd_en));
        h3 <= wq_we(l) and to_sl(wq_b = rd_addr and same_bank(wq_o, rd_obin, wq_all, bin_rd_en));
        -- stage 1 -> 2: the newest missed write to the tag, if any
        fwd_hit(l) <= h1 or h2 or h3;
        if h1 = '1' then
          fwd_word(l) <= new_w;
        elsif h2 = '1' then
          fwd_word(l) <= wq_word(l);
        else
          fwd_word(l) <= wq2_word(l);
        end if;
      end if;
    end process;
  end generate;

  -- read port, stage 2: per bank, sums over the lanes of the RAM words of the cleared entry
  -- (registered = outputs); pass done one clock after the last write register (then it is in the RAM)
  p_s3 : process (clk)
    variable h  : unsigned(HIST_W - 1 downto 0);
    variable n  : unsigned(COUNT_W - 1 downto 0);
    variable sx : signed(POSSUM_W - 1 downto 0);
    variable sy : signed(POSSUM_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      for o in 0 to N_ORIENT - 1 loop
        h := (others => '0');
        n := (others => '0');
        sx := (others => '0');
        sy := (others => '0');
        for l in 0 to LANES - 1 loop
          if KERNEL_EPAN = 1 then
            h := h + unsigned(rd_word(l)(o)(H_W - 1 downto 0));
          else
            h := h + resize(unsigned(rd_word(l)(o)(SX_LO - 1 downto N_LO)), HIST_W);
          end if;
          n  := n + unsigned(rd_word(l)(o)(SX_LO - 1 downto N_LO));
          sx := sx + signed(rd_word(l)(o)(SY_LO - 1 downto SX_LO));
          sy := sy + signed(rd_word(l)(o)(E_W - 1 downto SY_LO));
        end loop;
        s3_h((o + 1) * HIST_W - 1 downto o * HIST_W)     <= std_logic_vector(h);
        s3_n((o + 1) * COUNT_W - 1 downto o * COUNT_W)   <= std_logic_vector(n);
        s3_sx((o + 1) * POSSUM_W - 1 downto o * POSSUM_W) <= std_logic_vector(sx);
        s3_sy((o + 1) * POSSUM_W - 1 downto o * POSSUM_W) <= std_logic_vector(sy);
      end loop;
      s3_valid <= s2_clr;
      s3_last  <= s2_last;
      done_r   <= s3_last;
      if rst = '1' then
        s3_valid <= '0';
        s3_last  <= '0';
        done_r   <= '0';
      end if;
    end if;
  end process;

  last_done    <= done_r;
  bin_rd_valid <= s3_valid;
  bin_h        <= unsigned(s3_h(HIST_W - 1 downto 0));
  bin_n        <= unsigned(s3_n(COUNT_W - 1 downto 0));
  bin_sx       <= signed(s3_sx(POSSUM_W - 1 downto 0));
  bin_sy       <= signed(s3_sy(POSSUM_W - 1 downto 0));
  bin_h_all    <= s3_h;
  bin_n_all    <= s3_n;
  bin_sx_all   <= s3_sx;
  bin_sy_all   <= s3_sy;
end architecture;
