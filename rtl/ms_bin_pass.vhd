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
-- The Q RAM is read one clock ahead (address = index of the next returning bin) and its word
-- registered beside H in stage A, so the H Q product and the divider are fed from registers,
-- not from the block RAM's 5.6 ns output (ECP5: 79 MHz -> the multiplier path).
-- The products H Q, w N, w SX, w SY are pipelined radix-4 LUT multipliers (ms_mult_r4, latency
-- M(a) = 1 + max(1, ceil(log2(ceil(a/2)))) for an a of a bits), not MULT18X18D (unregistered as
-- yosys maps it on ECP5); H = 0 forces the ratio, not the weight, to 0 (isqrt(0) = 0).
-- N, SX, SY do not travel through the divider and isqrt stages: they wait in a small delay
-- memory (2**ceil(log2(DLY)) x (COUNT_W + 2 POSSUM_W), DLY = the two latencies) and two
-- registers, read out beside the weight.
--
-- ITERATIVE = 1 (for few bins, e.g. the 16 edge bins): same results, ports and handshake, with
-- iterative arithmetic: one bin at a time is requested (the next when the previous leaves stage
-- 1; learn passes still read one bin per clock).  Stage 1: one ms_divider_iter (one quotient bit
-- per clock) and H Q by shift-and-add; stage 2 (overlapping stage 1 of the next bin): the rho
-- and weight roots digit by digit (one root bit per clock each, as ms_scale), w N, w SX, w SY
-- added into the accumulators bit by bit of w.  No ms_divider, ms_isqrt, ms_mult_r4, no delay
-- memory: stage A's registers hold the bin until it leaves stage 1.
--
-- Latency    : learn (both): done 2 + N_BINS + BIN_RD_LAT clocks after start;
--              track, ITERATIVE = 0: done 3 + N_BINS + BIN_RD_LAT + max(SQRT_IN_W/2 + 1 + M(HIST_W),
--              RATIO_Q_W + RATIO_Q_W/2 + 2 + M(WEIGHT_W)) clocks after start (rho path: product +
--              isqrt; weight path: divider + isqrt + multiply; core flat: 3 + N_BINS + BIN_RD_LAT + 29);
--              track, ITERATIVE = 1: done T1 + (N_BINS - 1) P + S2 + 2 clocks after start, with
--              T1 = BIN_RD_LAT + max(RATIO_Q_W + 4, HIST_W + 3) (request -> the bin leaves stage 1),
--              S2 = max(SQRT_IN_W/2 + 1, RATIO_Q_W) (stage 2 clocks), P = max(T1, S2 + 1) (clocks
--              per bin); core flat, edge engine (16 bins, BIN_RD_LAT 3): 23 + 15 * 23 + 23 = 391
--              (start in cycle c, done high in cycle c + latency; tb/test_ms_bin_pass.py asserts it).
-- Throughput : ITERATIVE = 0: one bin per clock; a pass takes N_BINS + pipeline latency clocks.
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
    ITERATIVE  : natural := 0    -- 0: one bin per clock (pipelined); 1: iterative arithmetic (see above)
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
    q_ext_data   : in  unsigned(HIST_W - 1 downto 0) := (others => '0')
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
  signal q_ram : ram_t;

  -- issue side
  signal busy_r    : std_logic := '0';
  signal learn_r   : std_logic := '0';
  signal rd_en_r   : std_logic := '0';
  signal rd_addr_r : unsigned(BIN_W - 1 downto 0) := (others => '0');
  -- return side
  signal ret_cnt   : unsigned(BIN_W - 1 downto 0) := (others => '0');
  signal q_rd      : std_logic_vector(HIST_W - 1 downto 0);   -- Q RAM read register
  signal ret_nx    : unsigned(BIN_W - 1 downto 0) := to_unsigned(1, BIN_W);  -- ret_cnt + 1
  signal q_we      : std_logic;                                -- Q RAM write (learn)
  signal q_addr_p  : unsigned(BIN_W - 1 downto 0);             -- Q RAM address (write or read)
  signal q_wdata   : std_logic_vector(HIST_W - 1 downto 0);   -- Q RAM write data (H, or q_ext_data)
  signal q_a       : unsigned(HIST_W - 1 downto 0);            -- Q of the bin in stage A
  signal va        : std_logic := '0';                        -- stage A valid (track bins)
  signal last_a    : std_logic;
  signal h_a       : unsigned(HIST_W - 1 downto 0);
  signal n_a       : unsigned(COUNT_W - 1 downto 0);
  signal sx_a      : signed(POSSUM_W - 1 downto 0);
  signal sy_a      : signed(POSSUM_W - 1 downto 0);
  -- rho path
  signal vb        : std_logic;
  signal last_b    : std_logic;
  signal prod_b    : unsigned(PW - 1 downto 0);
  signal sq_in     : unsigned(SQRT_IN_W - 1 downto 0);
  signal sq_ov     : std_logic;
  signal sq_r      : unsigned(SQRT_IN_W / 2 - 1 downto 0);
  signal sq_tag    : std_logic_vector(0 downto 0);
  -- weight path
  signal div_n     : unsigned(DN_W - 1 downto 0);
  signal div_tag_i : std_logic_vector(1 downto 0);            -- last & hzero
  signal div_ov    : std_logic;
  signal div_q     : unsigned(RATIO_Q_W - 1 downto 0);
  signal div_tag_o : std_logic_vector(1 downto 0);
  signal wq_ov     : std_logic;
  signal wq_r      : unsigned(RATIO_Q_W / 2 - 1 downto 0);
  signal wq_tag    : std_logic_vector(0 downto 0);             -- last
  signal dly_ram   : dly_ram_t;
  signal dly_wp    : unsigned(DP_W - 1 downto 0) := (others => '0');
  signal dly_rp    : unsigned(DP_W - 1 downto 0) := to_unsigned((2 ** DP_W - (DLY - 2)) mod 2 ** DP_W, DP_W);
  signal dly_rd    : std_logic_vector(DLY_W - 1 downto 0);    -- memory read register
  signal dly_o     : std_logic_vector(DLY_W - 1 downto 0);    -- N & SX & SY beside wq_r
  signal sqw_in    : unsigned(RATIO_Q_W - 1 downto 0);
  signal w_n       : unsigned(COUNT_W - 1 downto 0);
  signal vm        : std_logic;
  signal last_m    : std_logic;
  signal wn_m      : unsigned(SW_W - 1 downto 0);
  signal wsx_m     : signed(SWX_W - 1 downto 0);
  signal wsy_m     : signed(SWX_W - 1 downto 0);
  -- accumulator inputs (from either arithmetic path)
  signal add_s_en  : std_logic;                                -- s_acc += add_s
  signal add_s     : unsigned(SQRT_IN_W / 2 - 1 downto 0);
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
  q_we     <= (bin_rd_valid and learn_r) or q_ext_we;
  q_addr_p <= q_ext_addr when q_ext_we = '1' else
              ret_nx when bin_rd_valid = '1' and learn_r = '0' else ret_cnt;
  q_wdata  <= std_logic_vector(q_ext_data) when q_ext_we = '1' else std_logic_vector(bin_h);

  p_ram : process (clk)
  begin
    if rising_edge(clk) then
      if q_we = '1' then
        q_ram(to_integer(q_addr_p)) <= q_wdata;
      end if;
      q_rd <= q_ram(to_integer(q_addr_p));
    end if;
  end process;

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
        h_a  <= bin_h;
        q_a  <= unsigned(q_rd);
        n_a  <= bin_n;
        sx_a <= bin_sx;
        sy_a <= bin_sy;
      end if;
    end if;
  end process;

  div_n <= shift_left(resize(q_a, DN_W), 2 * WF);

  g_pipe : if ITERATIVE = 0 generate
  ---------------------------------------------------------------- rho path: H Q -> isqrt
  u_mult_hq : entity work.ms_mult_r4
    generic map (A_W => HIST_W, B_W => HIST_W, B_SIGNED => false, P_W => PW, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => va, in_a => h_a, in_b => std_logic_vector(q_a),
              in_tag(0) => last_a, out_valid => vb, unsigned(out_p) => prod_b, out_tag(0) => last_b);

  sq_in <= shift_left(resize(prod_b, SQRT_IN_W), 2 * RF);

  u_sqrt_rho : entity work.ms_isqrt
    generic map (IN_W => SQRT_IN_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => vb, in_x => sq_in, in_tag(0) => last_b,
              out_valid => sq_ov, out_r => sq_r, out_tag => sq_tag);

  ---------------------------------------------------------------- weight path: divide, isqrt, multiply
  div_tag_i <= last_a & (nor h_a);

  u_div : entity work.ms_divider
    generic map (N_W => DN_W, D_W => HIST_W, Q_W => RATIO_Q_W, TAG_W => 2)
    port map (clk => clk, rst => rst, in_valid => va, in_n => div_n, in_d => h_a, in_tag => div_tag_i,
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
      dly_ram(to_integer(dly_wp)) <= std_logic_vector(n_a) & std_logic_vector(sx_a) & std_logic_vector(sy_a);
      dly_rd <= dly_ram(to_integer(dly_rp));
      dly_o  <= dly_rd;
      dly_wp <= dly_wp + 1;
      dly_rp <= dly_rp + 1;
      if rst = '1' then
        dly_wp <= (others => '0');
        dly_rp <= to_unsigned((2 ** DP_W - (DLY - 2)) mod 2 ** DP_W, DP_W);
      end if;
    end if;
  end process;

  -- weights w N, w SX, w SY (no mux after the isqrt: w = 0 for H = 0 comes from isqrt(0))
  w_n  <= unsigned(dly_o(2 * POSSUM_W + COUNT_W - 1 downto 2 * POSSUM_W));

  u_mult_n : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => COUNT_W, B_SIGNED => false, P_W => SW_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r, in_b => std_logic_vector(w_n),
              in_tag(0) => wq_tag(0), out_valid => vm, unsigned(out_p) => wn_m,
              out_tag(0) => last_m);

  u_mult_sx : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => POSSUM_W, B_SIGNED => true, P_W => SWX_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r,
              in_b => dly_o(2 * POSSUM_W - 1 downto POSSUM_W), in_tag => "0",
              out_valid => open, signed(out_p) => wsx_m, out_tag => open);

  u_mult_sy : entity work.ms_mult_r4
    generic map (A_W => WEIGHT_W, B_W => POSSUM_W, B_SIGNED => true, P_W => SWX_W, TAG_W => 1)
    port map (clk => clk, rst => rst, in_valid => wq_ov, in_a => wq_r,
              in_b => dly_o(POSSUM_W - 1 downto 0), in_tag => "0",
              out_valid => open, signed(out_p) => wsy_m, out_tag => open);

  add_s_en <= sq_ov;
  add_s    <= sq_r;
  fin_s    <= sq_ov and sq_tag(0);
  add_w_en <= vm;
  add_wn   <= wn_m;
  add_wsx  <= wsx_m;
  add_wsy  <= wsy_m;
  fin_w    <= vm and last_m;
  it_take  <= '0';
  end generate;

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
    add_s    <= rroot;
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
        if bin_rd_valid = '1' then
          k_acc <= k_acc + bin_h;
        end if;
        if add_s_en = '1' then
          s_acc <= s_acc + resize(add_s, RHO_SUM_W);
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
          if bin_rd_valid = '1' and ret_cnt = N_BINS - 1 then
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
