-- ms_bin_pass: one pass over the histogram bins (learn the model, or Bhattacharyya sum + weights).
--
-- Owns the model histogram RAM Q (N_BINS = 2**BIN_W words of HIST_W bits).  A `start` pulse
-- (ignored while busy = 1) reads the pixel-pass accumulators bin by bin, 0 .. N_BINS-1, one per
-- clock, through the histogram's read-and-clear port (bin_rd_en/bin_rd_addr -> bin_rd_valid,
-- bin_h, bin_n, bin_sx, bin_sy; results are only assumed to come back in order, the return
-- side counts them, so any latency works; BIN_RD_LAT is documentation / checking only).
--   learn = 1 : Q[u] <= H[u]; k_sum = sum H  (fits in HIST_W: sum H = K).
--   learn = 0 : per bin t = isqrt((H Q) << 2RF)                    (ms_isqrt, SQRT_IN_W)
--               w = 0 if H = 0 else isqrt(min(floor((Q << 2WF) / H), 2**RATIO_Q_W - 1))
--                                     (ms_divider Q_W = RATIO_Q_W, then ms_isqrt IN_W = RATIO_Q_W)
--               s_sum = sum t, sw = sum w N, swx = sum w SX, swy = sum w SY; k_sum = sum H too.
-- Must match mstrack.fixed.blocks.ms_bin_pass / ms_weight (and sum(H) for k_sum).
-- The product H Q is kept in SQRT_IN_W - 2RF bits (the model sizes SQRT_IN_W for H, Q <= the
-- largest possible histogram value, so it never truncates in use).
-- The products are pipelined radix-4 LUT multipliers (ms_mult_r4, latency M(a) = 1 + max(1,
-- ceil(log2(ceil(a/2)))) for an a of a bits); timing and resource notes: docs/blocks/ms_bin_pass.md.
--
-- ITERATIVE = 1 (for few bins, e.g. the 16 edge bins): same results, ports and handshake, with
-- iterative arithmetic: one bin at a time is requested (the next when the previous leaves stage
-- 1; learn passes still read one bin per clock).  Stage 1: one ms_divider_iter (one quotient bit
-- per clock) and H Q by shift-and-add; stage 2 (overlapping stage 1 of the next bin): the rho
-- and weight roots digit by digit (one root bit per clock each, as ms_scale), w N, w SX, w SY
-- added into the accumulators bit by bit of w.  No ms_divider, ms_isqrt, ms_mult_r4, no delay
-- memory: stage A's registers hold the bin until it leaves stage 1.
--
-- N_ORIENT > 1 (tracker v2's joint colour x orientation bins, joint bin = N_ORIENT u + o; ITERATIVE
-- = 0 only, ITERATIVE = 1 is refused by an assertion at elaboration): the read port returns, per
-- colour address u = 0 .. N_BINS - 1, the N_ORIENT banks on bin_h_all .. bin_sy_all (bank o at bits
-- o*width, as ms_histogram's bin_*_all; bin_h .. bin_sy are then ignored).  N_ORIENT Q RAM banks
-- (N_BINS x HIST_W each, address u, bank o = joint bin N_ORIENT u + o; learn: Q_o[u] <= H_o[u]),
-- N_ORIENT copies of the datapath above (H Q product, rho isqrt, divider, weight isqrt, delay
-- memory, w N / w SX / w SY products) in lockstep, and a registered adder tree of TL =
-- ceil(log2(N_ORIENT)) levels (TL = 0 with one bank) adding the N_ORIENT terms of each clock
-- (H, t, w N, w SX, w SY) before the accumulators.  A pass still walks N_BINS addresses.  Integer
-- sums: s_sum, sw, swx, swy, k_sum equal ms_bin_pass / sum H over the N_ORIENT N_BINS joint bins
-- exactly, in any order, with the same generics (the width bounds count no bins:
-- docs/blocks/ms_bin_pass.md).  External Q load, two ports (both only while idle, not in the same
-- clock): one word per clock, q_ext_bank selects the bank (joint bin N_ORIENT q_ext_addr + q_ext_bank; a
-- full load takes N_ORIENT N_BINS clocks), or all N_ORIENT banks of address q_ext_addr in one
-- clock (q_ext_all_we, q_ext_all_data: bank o at bits o*HIST_W; a full load takes N_BINS clocks).
-- With N_ORIENT = 1 the parallel port writes Q[q_ext_addr] as the word port does.
--
-- Latency    : learn (both): done 2 + N_BINS + BIN_RD_LAT + TL clocks after start (TL above;
--              N_ORIENT = 1: TL = 0; N_ORIENT 9: TL = 4; every track latency below is + TL too);
--              track, ITERATIVE = 0: done 3 + N_BINS + BIN_RD_LAT + max(SQRT_IN_W/2 + 1 + M(HIST_W),
--              RATIO_Q_W + RATIO_Q_W/2 + 2 + M(WEIGHT_W)) clocks after start (rho path: product +
--              isqrt; weight path: divider + isqrt + multiply; core flat: 3 + N_BINS + BIN_RD_LAT + 29);
--              track, ITERATIVE = 1: done T1 + (N_BINS - 1) P + S2 + 2 clocks after start, with
--              T1 = BIN_RD_LAT + max(RATIO_Q_W + 4, HIST_W + 3) (request -> the bin leaves stage 1),
--              S2 = max(SQRT_IN_W/2 + 1, RATIO_Q_W) (stage 2 clocks), P = max(T1, S2 + 1) (clocks
--              per bin); core flat, edge engine (16 bins, BIN_RD_LAT 3): 23 + 15 * 23 + 23 = 391
--              (start in cycle c, done high in cycle c + latency; tb/test_ms_bin_pass.py asserts it).
-- Throughput : ITERATIVE = 0: one bin address (N_ORIENT bins) per clock; a pass takes N_BINS +
--              pipeline latency clocks.
--              ITERATIVE = 1: one bin per P clocks in track passes (whatever the read latency: one
--              request outstanding, the histogram's later answers only delay the pass).
-- Handshake  : start/learn sampled when busy = 0; done is a one-clock pulse; s_sum, sw, swx,
--              swy, k_sum are stable from done until the next accepted start.
-- Reset      : synchronous, active high; control state only (the Q RAM keeps its contents).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_bin_pass is
  generic (
    BIN_W      : natural := 9;   -- bin index bits, N_BINS = 2**BIN_W (Q RAM depth, clocks per pass)
    HIST_W     : natural := 14;  -- H and Q bits (Q RAM width)
    COUNT_W    : natural := 14;  -- N (pixel count per bin) bits
    POSSUM_W   : natural := 21;  -- SX, SY (signed position sums per bin) bits
    SQRT_IN_W  : natural := 40;  -- Bhattacharyya isqrt input bits (even, >= 2 RF + 2)
    RHO_SUM_W  : natural := 21;  -- s_sum bits
    RATIO_Q_W  : natural := 16;  -- quotient bits of (Q << 2WF) / H (even; divider stages)
    WEIGHT_W   : natural := 8;   -- weight bits (= RATIO_Q_W / 2)
    WF         : natural := 4;   -- weight fraction bits
    RF         : natural := 6;   -- rho fraction bits
    SW_W       : natural := 22;  -- sw bits (unsigned sum w N)
    SWX_W      : natural := 29;  -- swx, swy bits (signed sums w SX, w SY)
    BIN_RD_LAT : natural := 2;   -- latency of the histogram read port (checking only, >= 1)
    ITERATIVE  : natural := 0;   -- 0: one bin per clock (pipelined); 1: iterative arithmetic (see above)
    N_ORIENT   : natural range 1 to 16 := 1  -- orientation banks (joint bin = N_ORIENT u + o; see above);
                                 -- 1 = the plain block (bin_h .. bin_sy; bin_*_all, q_ext_bank ignored)
  );
  port (
    clk          : in  std_logic;                             -- clock
    rst          : in  std_logic;                             -- synchronous reset, active high
    -- control
    start        : in  std_logic;                             -- pulse: start a pass (when busy = 0)
    learn        : in  std_logic;                             -- with start: 1 = store H into Q, 0 = track
    busy         : out std_logic;                             -- pass in progress
    -- histogram read-and-clear port
    bin_rd_en    : out std_logic;                             -- read bin bin_rd_addr
    bin_rd_addr  : out unsigned(BIN_W - 1 downto 0);          -- bin index, 0 .. N_BINS-1 in order
    bin_rd_valid : in  std_logic;                             -- read data valid (in request order)
    bin_h        : in  unsigned(HIST_W - 1 downto 0);         -- H[u] = sum of kernel values
    bin_n        : in  unsigned(COUNT_W - 1 downto 0);        -- N[u] = pixel count
    bin_sx       : in  signed(POSSUM_W - 1 downto 0);         -- SX[u] = sum of dx
    bin_sy       : in  signed(POSSUM_W - 1 downto 0);         -- SY[u] = sum of dy
    -- N_ORIENT > 1: the N_ORIENT banks of address u (bank o at bits o*width; ms_histogram's bin_*_all);
    -- then bin_h, bin_n, bin_sx, bin_sy are ignored
    bin_h_all    : in  std_logic_vector(N_ORIENT * HIST_W - 1 downto 0) := (others => '0');   -- unsigned H
    bin_n_all    : in  std_logic_vector(N_ORIENT * COUNT_W - 1 downto 0) := (others => '0');  -- unsigned N
    bin_sx_all   : in  std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0) := (others => '0'); -- signed SX
    bin_sy_all   : in  std_logic_vector(N_ORIENT * POSSUM_W - 1 downto 0) := (others => '0'); -- signed SY
    -- results
    done         : out std_logic;                             -- pulse: pass finished, results valid
    s_sum        : out unsigned(RHO_SUM_W - 1 downto 0);      -- S = sum isqrt(H Q 2**2RF) (track)
    sw           : out unsigned(SW_W - 1 downto 0);           -- sum w N (track)
    swx          : out signed(SWX_W - 1 downto 0);            -- sum w SX (track)
    swy          : out signed(SWX_W - 1 downto 0);            -- sum w SY (track)
    k_sum        : out unsigned(HIST_W - 1 downto 0);         -- sum H (K in learn mode)
    -- external Q write port (core v2 loads Qw = ms_model_scale(Qn, K) per frame; only while idle)
    q_ext_we     : in  std_logic := '0';                      -- write Q[q_ext_addr]
    q_ext_addr   : in  unsigned(BIN_W - 1 downto 0) := (others => '0');
    q_ext_data   : in  unsigned(HIST_W - 1 downto 0) := (others => '0');
    q_ext_bank   : in  unsigned(3 downto 0) := (others => '0'); -- N_ORIENT > 1: bank written (joint bin
                                                                 -- N_ORIENT q_ext_addr + q_ext_bank)
    -- parallel external Q write: every bank at q_ext_addr in one clock (not with q_ext_we; only while idle)
    q_ext_all_we   : in  std_logic := '0';                      -- write Q_o[q_ext_addr], o = 0 .. N_ORIENT - 1
    q_ext_all_data : in  std_logic_vector(N_ORIENT * HIST_W - 1 downto 0) := (others => '0')  -- bank o at o*HIST_W
  );
end entity;

architecture rtl of ms_bin_pass is
  constant N_BINS : natural := 2 ** BIN_W;
  constant PW     : natural := SQRT_IN_W - 2 * RF;            -- H Q product bits
  constant DN_W   : natural := HIST_W + 2 * WF;               -- divider dividend bits
  -- N, SX, SY of a bin wait beside the divider and the weight isqrt in a delay memory (not
  -- in every pipeline stage): DLY_W bits, DLY clocks from stage A to the isqrt output
  constant DLY_W  : natural := COUNT_W + 2 * POSSUM_W;
  constant DLY    : natural := (RATIO_Q_W + 1) + (RATIO_Q_W / 2 + 1);  -- ms_divider + ms_isqrt
  constant DP_W   : natural := clog2(DLY);                     -- delay memory address bits
  type dly_ram_t is array (0 to 2 ** DP_W - 1) of std_logic_vector(DLY_W - 1 downto 0);

  type ram_t is array (0 to N_BINS - 1) of std_logic_vector(HIST_W - 1 downto 0);
  -- per orientation bank (index o): port inputs, Q RAM read registers, stage A
  type hb_arr_t is array (0 to N_ORIENT - 1) of unsigned(HIST_W - 1 downto 0);
  type nb_arr_t is array (0 to N_ORIENT - 1) of unsigned(COUNT_W - 1 downto 0);
  type pb_arr_t is array (0 to N_ORIENT - 1) of signed(POSSUM_W - 1 downto 0);
  type qb_arr_t is array (0 to N_ORIENT - 1) of std_logic_vector(HIST_W - 1 downto 0);
  signal h_in      : hb_arr_t;                                 -- bank o of the read port
  signal n_in      : nb_arr_t;
  signal sx_in     : pb_arr_t;
  signal sy_in     : pb_arr_t;

  -- issue side
  signal busy_r    : std_logic := '0';
  signal learn_r   : std_logic := '0';
  signal rd_en_r   : std_logic := '0';
  signal rd_addr_r : unsigned(BIN_W - 1 downto 0) := (others => '0');
  -- return side
  signal ret_cnt   : unsigned(BIN_W - 1 downto 0) := (others => '0');
  signal q_rd      : qb_arr_t;                                 -- Q RAM read registers (per bank)
  signal ret_nx    : unsigned(BIN_W - 1 downto 0) := to_unsigned(1, BIN_W);  -- ret_cnt + 1
  signal q_addr_p  : unsigned(BIN_W - 1 downto 0);             -- Q RAM address (write or read), all banks
  signal h_ab      : hb_arr_t;                                 -- stage A, per bank
  signal q_ab      : hb_arr_t;
  signal n_ab      : nb_arr_t;
  signal sx_ab     : pb_arr_t;
  signal sy_ab     : pb_arr_t;
  signal q_a       : unsigned(HIST_W - 1 downto 0);            -- Q of the bin in stage A (bank 0)
  signal va        : std_logic := '0';                        -- stage A valid (track bins)
  signal last_a    : std_logic;
  signal h_a       : unsigned(HIST_W - 1 downto 0);            -- stage A, bank 0 (ITERATIVE)
  signal n_a       : unsigned(COUNT_W - 1 downto 0);
  signal sx_a      : signed(POSSUM_W - 1 downto 0);
  signal sy_a      : signed(POSSUM_W - 1 downto 0);
  signal div_n     : unsigned(DN_W - 1 downto 0);             -- ITERATIVE: dividend (bank 0)
  -- accumulator inputs (from either arithmetic path, or the bank adder tree)
  signal add_k_en  : std_logic;                                -- k_acc += add_k
  signal add_k     : unsigned(HIST_W - 1 downto 0);
  signal fin_k     : std_logic;                                -- last bin's H added
  signal k_last    : std_logic;                                -- the last bin returns (read port)
  signal add_s_en  : std_logic;                                -- s_acc += add_s
  signal add_s     : unsigned(RHO_SUM_W - 1 downto 0);
  signal add_w_en  : std_logic;                                -- sw/swx/swy_acc += add_wn/wsx/wsy
  signal add_wn    : unsigned(SW_W - 1 downto 0);
  signal add_wsx   : signed(SWX_W - 1 downto 0);
  signal add_wsy   : signed(SWX_W - 1 downto 0);
  signal fin_s     : std_logic;                                -- last bin's term added (rho)
  signal fin_w     : std_logic;                                -- last bin's terms added (weights)
  signal it_take   : std_logic;                                -- ITERATIVE: a bin leaves stage 1
  -- accumulators and completion
  signal s_acc     : unsigned(RHO_SUM_W - 1 downto 0);
  signal sw_acc    : unsigned(SW_W - 1 downto 0);
  signal swx_acc   : signed(SWX_W - 1 downto 0);
  signal swy_acc   : signed(SWX_W - 1 downto 0);
  signal k_acc     : unsigned(HIST_W - 1 downto 0);
  signal k_fin     : std_logic := '0';
  signal s_fin     : std_logic := '0';
  signal w_fin     : std_logic := '0';
  signal done_r    : std_logic := '0';
begin
  assert WEIGHT_W = RATIO_Q_W / 2 and RATIO_Q_W mod 2 = 0 and SQRT_IN_W mod 2 = 0
    report "ms_bin_pass: need WEIGHT_W = RATIO_Q_W / 2, RATIO_Q_W and SQRT_IN_W even" severity failure;
  assert PW >= 1 and BIN_RD_LAT >= 1
    report "ms_bin_pass: need SQRT_IN_W > 2 RF and BIN_RD_LAT >= 1" severity failure;
  assert ITERATIVE = 0 or N_ORIENT = 1
    report "ms_bin_pass: ITERATIVE = 1 has no orientation banks (need N_ORIENT = 1)" severity failure;

  ---------------------------------------------------------------- read port, per bank
  g_in : for o in 0 to N_ORIENT - 1 generate
    g_one : if N_ORIENT = 1 generate
      h_in(o)  <= bin_h;
      n_in(o)  <= bin_n;
      sx_in(o) <= bin_sx;
      sy_in(o) <= bin_sy;
    end generate;
    g_all : if N_ORIENT > 1 generate
      h_in(o)  <= unsigned(bin_h_all((o + 1) * HIST_W - 1 downto o * HIST_W));
      n_in(o)  <= unsigned(bin_n_all((o + 1) * COUNT_W - 1 downto o * COUNT_W));
      sx_in(o) <= signed(bin_sx_all((o + 1) * POSSUM_W - 1 downto o * POSSUM_W));
      sy_in(o) <= signed(bin_sy_all((o + 1) * POSSUM_W - 1 downto o * POSSUM_W));
    end generate;
  end generate;

  ---------------------------------------------------------------- issue side: bins 0 .. N_BINS-1
  p_issue : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        busy_r  <= '0';
        rd_en_r <= '0';
        learn_r <= '0';
      else
        if busy_r = '0' and start = '1' then
          busy_r    <= '1';
          learn_r   <= learn;
          rd_en_r   <= '1';
          rd_addr_r <= (others => '0');
        elsif ITERATIVE = 0 or learn_r = '1' then
          if rd_en_r = '1' then
            if rd_addr_r = N_BINS - 1 then
              rd_en_r <= '0';
            else
              rd_addr_r <= rd_addr_r + 1;
            end if;
          end if;
        else                                   -- ITERATIVE track: next bin when one leaves stage 1
          rd_en_r <= '0';
          if it_take = '1' and rd_addr_r /= N_BINS - 1 then
            rd_en_r   <= '1';
            rd_addr_r <= rd_addr_r + 1;
          end if;
        end if;
        if done_r = '1' then
          busy_r <= '0';
        end if;
      end if;
    end if;
  end process;

  bin_rd_en   <= rd_en_r;
  bin_rd_addr <= rd_addr_r;
  busy        <= busy_r;

  ---------------------------------------------------------------- Q RAM (registered read, read-first)
  -- read address: the value ret_cnt takes at this edge, i.e. the index of the bin that returns
  -- next, so q_rd holds Q[ret_cnt] whenever a bin returns.  ret_cnt is 0 when idle (a pass
  -- counts N_BINS returns and wraps), so the start case needs no term; ret_nx = ret_cnt + 1 is a
  -- register, leaving one LUT between registers and the block RAM address.  Learn writes use
  -- the same single port at ret_cnt (read data unused in learn), so the RAM is single-port
  -- (read-before-write within the port): no write/read collision logic after the block RAM,
  -- whose output register then holds q_a.
  -- N_ORIENT banks share the address; a learn writes every bank (bank o: H of bank o), an
  -- external write only bank q_ext_bank (N_ORIENT = 1: always bank 0), a parallel external write
  -- every bank (bank o: its slice of q_ext_all_data).
  q_addr_p <= q_ext_addr when q_ext_we = '1' or q_ext_all_we = '1' else
              ret_nx when bin_rd_valid = '1' and learn_r = '0' else ret_cnt;

  g_qram : for o in 0 to N_ORIENT - 1 generate
    signal q_ram   : ram_t;
    signal q_sel   : std_logic;                                -- q_ext_bank selects this bank
    signal q_we    : std_logic;                                -- Q RAM write (learn or external)
    signal q_wdata : std_logic_vector(HIST_W - 1 downto 0);   -- Q RAM write data (H, or q_ext_data)
  begin
    q_sel   <= '1' when N_ORIENT = 1 or q_ext_bank = o else '0';
    q_we    <= (bin_rd_valid and learn_r) or (q_ext_we and q_sel) or q_ext_all_we;
    q_wdata <= std_logic_vector(q_ext_data) when q_ext_we = '1' else
               q_ext_all_data((o + 1) * HIST_W - 1 downto o * HIST_W) when q_ext_all_we = '1' else
               std_logic_vector(h_in(o));

    p_ram : process (clk)
    begin
      if rising_edge(clk) then
        if q_we = '1' then
          q_ram(to_integer(q_addr_p)) <= q_wdata;
        end if;
        q_rd(o) <= q_ram(to_integer(q_addr_p));
      end if;
    end process;
  end generate;

  ---------------------------------------------------------------- return side: stage A
  p_ret : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        ret_cnt <= (others => '0');
        ret_nx  <= to_unsigned(1, BIN_W);
        va      <= '0';
      else
        if busy_r = '0' and start = '1' then
          ret_cnt <= (others => '0');
          ret_nx  <= to_unsigned(1, BIN_W);
        elsif bin_rd_valid = '1' then
          ret_cnt <= ret_nx;
          ret_nx  <= ret_nx + 1;
        end if;
        va <= bin_rd_valid and not learn_r;
      end if;
      if ITERATIVE = 0 or bin_rd_valid = '1' then   -- ITERATIVE: held until the next bin
        if ret_cnt = N_BINS - 1 then
          last_a <= '1';
        else
          last_a <= '0';
        end if;
        for o in 0 to N_ORIENT - 1 loop
          h_ab(o)  <= h_in(o);
          q_ab(o)  <= unsigned(q_rd(o));
          n_ab(o)  <= n_in(o);
          sx_ab(o) <= sx_in(o);
          sy_ab(o) <= sy_in(o);
        end loop;
      end if;
    end if;
  end process;

  h_a  <= h_ab(0);
  q_a  <= q_ab(0);
  n_a  <= n_ab(0);
  sx_a <= sx_ab(0);
  sy_a <= sy_ab(0);
  div_n <= shift_left(resize(q_a, DN_W), 2 * WF);

  g_pipe : if ITERATIVE = 0 generate
    type rs_arr_t is array (0 to N_ORIENT - 1) of unsigned(SQRT_IN_W / 2 - 1 downto 0);
    type wn_arr_t is array (0 to N_ORIENT - 1) of unsigned(SW_W - 1 downto 0);
    type wx_arr_t is array (0 to N_ORIENT - 1) of signed(SWX_W - 1 downto 0);
    signal sq_ov_v   : std_logic_vector(N_ORIENT - 1 downto 0);  -- per bank: rho term valid
    signal sq_last_v : std_logic_vector(N_ORIENT - 1 downto 0);  --   ... of the last bin
    signal sq_r_v    : rs_arr_t;                                 --   rho term t
    signal vm_v      : std_logic_vector(N_ORIENT - 1 downto 0);  -- per bank: w products valid
    signal last_m_v  : std_logic_vector(N_ORIENT - 1 downto 0);  --   ... of the last bin
    signal wn_v      : wn_arr_t;                                 --   w N
    signal wsx_v     : wx_arr_t;                                 --   w SX
    signal wsy_v     : wx_arr_t;                                 --   w SY
    signal dly_wp    : unsigned(DP_W - 1 downto 0) := (others => '0');
    signal dly_rp    : unsigned(DP_W - 1 downto 0) := to_unsigned((2 ** DP_W - (DLY - 2)) mod 2 ** DP_W, DP_W);
  begin
  -- delay memory pointers (shared by the banks): written every clock, read DLY - 2 clocks later
  p_dly_ptr : process (clk)
  begin
    if rising_edge(clk) then
      dly_wp <= dly_wp + 1;
      dly_rp <= dly_rp + 1;
      if rst = '1' then
        dly_wp <= (others => '0');
        dly_rp <= to_unsigned((2 ** DP_W - (DLY - 2)) mod 2 ** DP_W, DP_W);
      end if;
    end if;
  end process;

  -- one datapath per orientation bank (N_ORIENT = 1: the single datapath), all in lockstep
  g_dp : for o in 0 to N_ORIENT - 1 generate
    signal vb        : std_logic;
    signal last_b    : std_logic;
    signal prod_b    : unsigned(PW - 1 downto 0);
    signal sq_in     : unsigned(SQRT_IN_W - 1 downto 0);
    signal sq_tag    : std_logic_vector(0 downto 0);
    signal div_nb    : unsigned(DN_W - 1 downto 0);
    signal div_tag_i : std_logic_vector(1 downto 0);            -- last & hzero
    signal div_ov    : std_logic;
    signal div_q     : unsigned(RATIO_Q_W - 1 downto 0);
    signal div_tag_o : std_logic_vector(1 downto 0);
    signal wq_ov     : std_logic;
    signal wq_r      : unsigned(RATIO_Q_W / 2 - 1 downto 0);
    signal wq_tag    : std_logic_vector(0 downto 0);             -- last
    signal dly_ram   : dly_ram_t;
    signal dly_rd    : std_logic_vector(DLY_W - 1 downto 0);    -- memory read register
    signal dly_o     : std_logic_vector(DLY_W - 1 downto 0);    -- N & SX & SY beside wq_r
    signal sqw_in    : unsigned(RATIO_Q_W - 1 downto 0);
    signal w_n       : unsigned(COUNT_W - 1 downto 0);
  begin
  ---------------------------------------------------------------- rho path: H Q -> isqrt
  u_mult_hq : entity work.ms_mult_r4
    generic map (A_W => HIST_W, B_W => HIST_W, B_SIGNED => false, P_W => PW, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => va, in_a => h_ab(o), in_b => std_logic_vector(q_ab(o)),
              in_tag(0) => last_a, out_valid => vb, unsigned(out_p) => prod_b, out_tag(0) => last_b);

  sq_in <= shift_left(resize(prod_b, SQRT_IN_W), 2 * RF);

  u_sqrt_rho : entity work.ms_isqrt
    generic map (IN_W => SQRT_IN_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => vb, in_x => sq_in, in_tag(0) => last_b,
              out_valid => sq_ov_v(o), out_r => sq_r_v(o), out_tag => sq_tag);
  sq_last_v(o) <= sq_tag(0);

  ---------------------------------------------------------------- weight path: divide, isqrt, multiply
  div_nb    <= shift_left(resize(q_ab(o), DN_W), 2 * WF);
  div_tag_i <= last_a & (nor h_ab(o));

  u_div : entity work.ms_divider
    generic map (N_W => DN_W, D_W => HIST_W, Q_W => RATIO_Q_W, TAG_W => 2)
    port map (clk => clk, rst => rst, in_valid => va, in_n => div_nb, in_d => h_ab(o), in_tag => div_tag_i,
              out_valid => div_ov, out_q => div_q, out_tag => div_tag_o);

  -- H = 0: the divider saturates (d = 0); the ratio is forced to 0 here, so w = isqrt(0) = 0
  sqw_in <= (others => '0') when div_tag_o(0) = '1' else div_q;

  u_sqrt_w : entity work.ms_isqrt
    generic map (IN_W => RATIO_Q_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => div_ov, in_x => sqw_in, in_tag => div_tag_o(1 downto 1),
              out_valid => wq_ov, out_r => wq_r, out_tag => wq_tag);

  -- delay memory: written every clock with stage A's N, SX, SY, read DLY - 2 clocks later into
  -- dly_rd and registered once more (dly_o, no logic after the memory), so dly_o holds the
  -- values of the bin whose weight is in wq_r (the pipelines always flow: a fixed delay)
  p_dly : process (clk)
  begin
    if rising_edge(clk) then
      dly_ram(to_integer(dly_wp)) <= std_logic_vector(n_ab(o)) & std_logic_vector(sx_ab(o))
                                     & std_logic_vector(sy_ab(o));
      dly_rd <= dly_ram(to_integer(dly_rp));
      dly_o  <= dly_rd;
    end if;
  end process;

  -- weights w N, w SX, w SY (no mux after the isqrt: w = 0 for H = 0 comes from isqrt(0))
  w_n  <= unsigned(dly_o(2 * POSSUM_W + COUNT_W - 1 downto 2 * POSSUM_W));

  u_mult_n : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => COUNT_W, B_SIGNED => false, P_W => SW_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r, in_b => std_logic_vector(w_n),
              in_tag(0) => wq_tag(0), out_valid => vm_v(o), unsigned(out_p) => wn_v(o),
              out_tag(0) => last_m_v(o));

  u_mult_sx : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => POSSUM_W, B_SIGNED => true, P_W => SWX_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r,
              in_b => dly_o(2 * POSSUM_W - 1 downto POSSUM_W), in_tag => "0",
              out_valid => open, signed(out_p) => wsx_v(o), out_tag => open);

  u_mult_sy : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => POSSUM_W, B_SIGNED => true, P_W => SWX_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r,
              in_b => dly_o(POSSUM_W - 1 downto 0), in_tag => "0",
              out_valid => open, signed(out_p) => wsy_v(o), out_tag => open);
  end generate;

  g_one : if N_ORIENT = 1 generate
    add_s_en <= sq_ov_v(0);
    add_s    <= resize(sq_r_v(0), RHO_SUM_W);
    fin_s    <= sq_ov_v(0) and sq_last_v(0);
    add_w_en <= vm_v(0);
    add_wn   <= wn_v(0);
    add_wsx  <= wsx_v(0);
    add_wsy  <= wsy_v(0);
    fin_w    <= vm_v(0) and last_m_v(0);
  end generate;

  ---------------------------------------------------------------- N_ORIENT > 1: bank adder tree
  -- The N_ORIENT per-bank terms of one clock are added in a binary tree of TL = ceil(log2
  -- N_ORIENT) register levels (pairs per level, an odd node passes through), one word per
  -- node holding five fields [H | t | w N | w SX | w SY], each added modulo 2**its width (two's
  -- complement: signed = unsigned addition).  The fields enter at different clocks (H from
  -- the read port, t and the products from their pipelines) but every bank carries the same
  -- field at the same clock (lockstep), so each level adds valid terms of one bin address or
  -- ignored ones; the valid / last flags of each field travel beside it (reset) and enable
  -- the accumulators TL clocks later.  Partial sums wrap like the accumulators: the final sums
  -- are exact whenever the totals fit (they do, see the header).
  g_tree : if N_ORIENT > 1 generate
    constant TL   : natural := clog2(N_ORIENT);
    constant F_WY : natural := 0;                              -- field offsets (LSB first)
    constant F_WX : natural := SWX_W;
    constant F_WN : natural := 2 * SWX_W;
    constant F_S  : natural := 2 * SWX_W + SW_W;
    constant F_K  : natural := 2 * SWX_W + SW_W + RHO_SUM_W;
    constant TW   : natural := F_K + HIST_W;
    subtype node_t is std_logic_vector(TW - 1 downto 0);
    type level_t is array (0 to N_ORIENT - 1) of node_t;
    type tree_t is array (1 to TL) of level_t;                -- registered levels
    type flags_t is array (1 to TL) of std_logic_vector(5 downto 0);  -- fin k s w, valid k s w
    -- nodes of level l: ceil(N_ORIENT / 2**l)
    function nodes(l : natural) return natural is
    begin
      return (N_ORIENT + 2 ** l - 1) / 2 ** l;
    end function;
    -- field-wise sum (no carry between fields)
    function add_fields(a, b : node_t) return node_t is
      variable r : node_t;
    begin
      r(F_WX - 1 downto F_WY) := std_logic_vector(unsigned(a(F_WX - 1 downto F_WY)) + unsigned(b(F_WX - 1 downto F_WY)));
      r(F_WN - 1 downto F_WX) := std_logic_vector(unsigned(a(F_WN - 1 downto F_WX)) + unsigned(b(F_WN - 1 downto F_WX)));
      r(F_S - 1 downto F_WN)  := std_logic_vector(unsigned(a(F_S - 1 downto F_WN)) + unsigned(b(F_S - 1 downto F_WN)));
      r(F_K - 1 downto F_S)   := std_logic_vector(unsigned(a(F_K - 1 downto F_S)) + unsigned(b(F_K - 1 downto F_S)));
      r(TW - 1 downto F_K)    := std_logic_vector(unsigned(a(TW - 1 downto F_K)) + unsigned(b(TW - 1 downto F_K)));
      return r;
    end function;
    signal lv0 : level_t;                                     -- leaves: the banks' terms (not registered)
    signal fl0 : std_logic_vector(5 downto 0);
    signal tr  : tree_t;
    signal fl  : flags_t := (others => (others => '0'));
  begin
    g_leaf : for o in 0 to N_ORIENT - 1 generate
      lv0(o) <= std_logic_vector(h_in(o)) & std_logic_vector(resize(sq_r_v(o), RHO_SUM_W))
                  & std_logic_vector(wn_v(o)) & std_logic_vector(wsx_v(o)) & std_logic_vector(wsy_v(o));
    end generate;
    fl0 <= k_last & (sq_ov_v(0) and sq_last_v(0))
             & (vm_v(0) and last_m_v(0)) & bin_rd_valid & sq_ov_v(0) & vm_v(0);

    -- (lv0 / fl0 are separate signals: this process drives all of tr and fl)
    p_tree : process (clk)
      variable src : level_t;
    begin
      if rising_edge(clk) then
        for l in 1 to TL loop
          if l = 1 then
            src := lv0;
            fl(l) <= fl0;
          else
            src := tr(l - 1);
            fl(l) <= fl(l - 1);
          end if;
          for i in 0 to N_ORIENT - 1 loop
            if 2 * i + 1 < nodes(l - 1) then
              tr(l)(i) <= add_fields(src(work.ms_pkg.min(2 * i, N_ORIENT - 1)),
                                     src(work.ms_pkg.min(2 * i + 1, N_ORIENT - 1)));
            elsif 2 * i < nodes(l - 1) then
              tr(l)(i) <= src(work.ms_pkg.min(2 * i, N_ORIENT - 1));
            end if;
          end loop;
          if rst = '1' then
            fl(l) <= (others => '0');
          end if;
        end loop;
      end if;
    end process;

    add_k    <= unsigned(tr(TL)(0)(TW - 1 downto F_K));
    add_s    <= unsigned(tr(TL)(0)(F_K - 1 downto F_S));
    add_wn   <= unsigned(tr(TL)(0)(F_S - 1 downto F_WN));
    add_wsx  <= signed(tr(TL)(0)(F_WN - 1 downto F_WX));
    add_wsy  <= signed(tr(TL)(0)(F_WX - 1 downto F_WY));
    fin_k    <= fl(TL)(5);
    fin_s    <= fl(TL)(4);
    fin_w    <= fl(TL)(3);
    add_k_en <= fl(TL)(2);
    add_s_en <= fl(TL)(1);
    add_w_en <= fl(TL)(0);
  end generate;
  it_take  <= '0';
  end generate;

  ---------------------------------------------------------------- k_sum without the tree
  g_k1 : if N_ORIENT = 1 generate
    add_k_en <= bin_rd_valid;
    add_k    <= bin_h;
    fin_k    <= k_last;
  end generate;
  k_last <= '1' when bin_rd_valid = '1' and ret_cnt = N_BINS - 1 else '0';

  ---------------------------------------------------------------- ITERATIVE = 1
  -- Stage 1 (the bin in stage A, held there): ms_divider_iter (Q << 2WF) / H, RATIO_Q_W + 1
  -- clocks, and beside it H Q by shift-and-add (HIST_W clocks, multiplier Q in the low half of
  -- the product register).  Stage 2 (taken when the quotient is out and stage 2 is free; the
  -- next bin is requested then): the rho root, digit by digit on (H Q) << 2RF, one root bit per
  -- clock (SQRT_IN_W / 2 clocks), then s_acc += root; beside it the weight root (RATIO_Q_W / 2
  -- clocks) and w N, w SX, w SY added into the accumulators bit by bit of w, LSB first, with
  -- N, SX, SY doubling each clock (RATIO_Q_W / 2 clocks).
  g_iter : if ITERATIVE /= 0 generate
    constant RR_W   : natural := SQRT_IN_W / 2;             -- rho root bits (steps)
    constant RRM_W  : natural := RR_W + 3;                  -- its remainder / trial bits
    constant WR_W   : natural := RATIO_Q_W / 2;             -- weight root bits (steps)
    constant WRM_W  : natural := WR_W + 3;
    constant S2_LEN : natural := max(RR_W + 1, 2 * WR_W);   -- stage 2 clocks
    signal dv_ov   : std_logic;
    signal dv_q    : unsigned(RATIO_Q_W - 1 downto 0);
    signal pr      : unsigned(2 * HIST_W downto 0);         -- product high part & multiplier bits left
    signal k1      : natural range 0 to HIST_W := 0;        -- product steps still to do
    signal k1_zero : std_logic := '1';                      -- k1 = 0, registered (decided a clock ahead)
    signal s1_full : std_logic := '0';                      -- quotient ready
    signal s2_busy : std_logic := '0';
    signal k2      : natural range 0 to S2_LEN - 1 := 0;
    signal last2   : std_logic;
    signal rx      : unsigned(PW - 1 downto 0);             -- H Q, consumed two bits per step
    signal rrem    : unsigned(RRM_W - 1 downto 0);
    signal rroot   : unsigned(RR_W - 1 downto 0);
    signal wx      : unsigned(RATIO_Q_W - 1 downto 0);      -- ratio, consumed two bits per step
    signal wrem    : unsigned(WRM_W - 1 downto 0);
    signal wroot   : unsigned(WR_W - 1 downto 0);           -- w, then shifted out LSB first
    signal an      : unsigned(SW_W - 1 downto 0);           -- N 2**k
    signal asx     : signed(SWX_W - 1 downto 0);            -- SX 2**k
    signal asy     : signed(SWX_W - 1 downto 0);            -- SY 2**k
    signal take    : std_logic;
  begin
    assert 2 * HIST_W >= PW
      report "ms_bin_pass: ITERATIVE needs SQRT_IN_W - 2 RF <= 2 HIST_W" severity failure;

    u_div : entity work.ms_divider_iter
      generic map (N_W => DN_W, D_W => HIST_W, Q_W => RATIO_Q_W)
      port map (clk => clk, rst => rst, in_valid => va, in_n => div_n, in_d => h_a, busy => open,
                out_valid => dv_ov, out_q => dv_q);

    take    <= s1_full and k1_zero and not s2_busy;
    it_take <= take;

    p_s1 : process (clk)
      variable v : unsigned(2 * HIST_W downto 0);
    begin
      if rising_edge(clk) then
        if va = '0' and k1 <= 1 then                       -- k1 = 0 after this edge
          k1_zero <= '1';
        else
          k1_zero <= '0';
        end if;
        if va = '1' then                                   -- product register: 0 & Q
          pr <= resize(q_a, 2 * HIST_W + 1);
          k1 <= HIST_W;
        elsif k1 /= 0 then                                 -- LSB of the multiplier: add H above it
          v := pr;
          if v(0) = '1' then
            v(2 * HIST_W downto HIST_W) := v(2 * HIST_W downto HIST_W) + resize(h_a, HIST_W + 1);
          end if;
          pr <= shift_right(v, 1);
          k1 <= k1 - 1;
        end if;
        if dv_ov = '1' then
          s1_full <= '1';
        elsif take = '1' then
          s1_full <= '0';
        end if;
        if rst = '1' then
          k1      <= 0;
          k1_zero <= '1';
          s1_full <= '0';
        end if;
      end if;
    end process;

    p_s2 : process (clk)
      variable rm, tr : unsigned(RRM_W - 1 downto 0);
      variable dr     : unsigned(RRM_W downto 0);
      variable wm, tw : unsigned(WRM_W - 1 downto 0);
      variable dw     : unsigned(WRM_W downto 0);
    begin
      if rising_edge(clk) then
        if take = '1' then
          rx    <= resize(pr(2 * HIST_W - 1 downto 0), PW);
          rrem  <= (others => '0');
          rroot <= (others => '0');
          if h_a = 0 then                                  -- H = 0: ratio 0 (the divider saturates)
            wx <= (others => '0');
          else
            wx <= dv_q;
          end if;
          wrem  <= (others => '0');
          wroot <= (others => '0');
          an    <= resize(n_a, SW_W);
          asx   <= resize(sx_a, SWX_W);
          asy   <= resize(sy_a, SWX_W);
          last2 <= last_a;
          k2    <= 0;
          s2_busy <= '1';
        elsif s2_busy = '1' then
          if k2 < RR_W then                                -- rho root bit (zeros after H Q: << 2RF)
            rm := shift_left(rrem, 2);
            rm(1 downto 0) := rx(PW - 1 downto PW - 2);
            tr := shift_left(resize(rroot, RRM_W), 2);
            tr(0) := '1';
            dr := resize(rm, RRM_W + 1) - resize(tr, RRM_W + 1);
            if dr(RRM_W) = '0' then
              rrem  <= dr(RRM_W - 1 downto 0);
              rroot <= shift_left(rroot, 1) or to_unsigned(1, RR_W);
            else
              rrem  <= rm;
              rroot <= shift_left(rroot, 1);
            end if;
            rx <= shift_left(rx, 2);
          end if;
          if k2 < WR_W then                                -- weight root bit
            wm := shift_left(wrem, 2);
            wm(1 downto 0) := wx(RATIO_Q_W - 1 downto RATIO_Q_W - 2);
            tw := shift_left(resize(wroot, WRM_W), 2);
            tw(0) := '1';
            dw := resize(wm, WRM_W + 1) - resize(tw, WRM_W + 1);
            if dw(WRM_W) = '0' then
              wrem  <= dw(WRM_W - 1 downto 0);
              wroot <= shift_left(wroot, 1) or to_unsigned(1, WR_W);
            else
              wrem  <= wm;
              wroot <= shift_left(wroot, 1);
            end if;
            wx <= shift_left(wx, 2);
          elsif k2 < 2 * WR_W then                         -- w bit k2 - WR_W: terms added (add_w_en)
            wroot <= shift_right(wroot, 1);
            an    <= shift_left(an, 1);
            asx   <= shift_left(asx, 1);
            asy   <= shift_left(asy, 1);
          end if;
          if k2 = S2_LEN - 1 then
            s2_busy <= '0';
          else
            k2 <= k2 + 1;
          end if;
        end if;
        if rst = '1' then
          s2_busy <= '0';
        end if;
      end if;
    end process;

    add_s_en <= '1' when s2_busy = '1' and k2 = RR_W else '0';
    add_s    <= resize(rroot, RHO_SUM_W);
    fin_s    <= add_s_en and last2;
    add_w_en <= wroot(0) when s2_busy = '1' and k2 >= WR_W and k2 < 2 * WR_W else '0';
    add_wn   <= an;
    add_wsx  <= asx;
    add_wsy  <= asy;
    fin_w    <= last2 when s2_busy = '1' and k2 = 2 * WR_W - 1 else '0';
  end generate;

  ---------------------------------------------------------------- accumulators and done
  p_acc : process (clk)
  begin
    if rising_edge(clk) then
      if busy_r = '0' and start = '1' then
        s_acc   <= (others => '0');
        sw_acc  <= (others => '0');
        swx_acc <= (others => '0');
        swy_acc <= (others => '0');
        k_acc   <= (others => '0');
      else
        if add_k_en = '1' then
          k_acc <= k_acc + add_k;
        end if;
        if add_s_en = '1' then
          s_acc <= s_acc + add_s;
        end if;
        if add_w_en = '1' then
          sw_acc  <= sw_acc + add_wn;
          swx_acc <= swx_acc + add_wsx;
          swy_acc <= swy_acc + add_wsy;
        end if;
      end if;
      if rst = '1' then
        k_fin  <= '0';
        s_fin  <= '0';
        w_fin  <= '0';
        done_r <= '0';
      else
        done_r <= '0';
        if busy_r = '0' and start = '1' then
          k_fin <= '0';
          s_fin <= '0';
          w_fin <= '0';
        else
          if fin_k = '1' then
            k_fin <= '1';
          end if;
          if fin_s = '1' then
            s_fin <= '1';
          end if;
          if fin_w = '1' then
            w_fin <= '1';
          end if;
          if busy_r = '1' and done_r = '0' and k_fin = '1'
             and (learn_r = '1' or (s_fin = '1' and w_fin = '1')) then
            done_r <= '1';
          end if;
        end if;
      end if;
    end if;
  end process;

  done  <= done_r;
  s_sum <= s_acc;
  sw    <= sw_acc;
  swx   <= swx_acc;
  swy   <= swy_acc;
  k_sum <= k_acc;
end architecture;
