-- ms_confidence: confidence of one mean-shift result, tracker v2,
--
--   conf = (min(1, rho / rho_ref) min(1, share / share_ref)) >> 16        (Q1.16, 0 .. 2**16)
--
-- each ratio = min(2**16, floor(x 2**16 / ref)) (Q1.16), 0 when ref = 0.  Both divisions go through
-- one ms_divider_iter of 17 quotient bits, one after the other: the model's ms_divider(x << 16, ref, 34)
-- and the divider's saturation at 2**17 - 1 both clamp to 2**16 all the same, so the block is exact for
-- every input.  ref = 0 divides 0 by 1 (the operands are chosen in front of the divider).  The product
-- of the two ratios (17 x 17 bits) is shift-and-add, one bit of the share ratio per clock, MSB first
-- (no multiplier block).
-- Model: mstrack.fixed.blocks_v2.ms_confidence(rho, share, rho_ref, share_ref), bit for bit.
--
-- Latency    : CONF_LAT = 2 (Q_W + 2) + Q_W + 2 = 57 clocks (Q_W = 17): if edge s samples start = 1
--              (busy = 0), edge s + CONF_LAT samples done = 1 (tb/test_ms_confidence.py asserts it).
--              Once per start point (9 x per frame while lost).
-- Throughput : one confidence per CONF_LAT clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; conf is registered and
--              held until the next done.
-- Cost       : one ms_divider_iter (a W + 2 bit subtractor), one 34-bit adder (the product), two
--              W-bit zero tests, two 17-bit clamps; 222 flip-flops, 318 LUT4 at W = 17
--              (docs/blocks/ms_confidence.md).
-- Reset      : synchronous, active high: control state.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_confidence is
  generic (
    W : positive := 17  -- rho, share, rho_ref, share_ref bits (unsigned Q1.16)
  );
  port (
    clk       : in  std_logic;                     -- clock
    rst       : in  std_logic;                     -- synchronous reset
    start     : in  std_logic;                     -- pulse: inputs valid (while busy = 0)
    rho       : in  unsigned(W - 1 downto 0);      -- rho of this result
    share     : in  unsigned(W - 1 downto 0);      -- share of this result (ms_share)
    rho_ref   : in  unsigned(W - 1 downto 0);      -- running reference of rho (ms_ref_update)
    share_ref : in  unsigned(W - 1 downto 0);      -- running reference of share
    busy      : out std_logic;                     -- computing
    done      : out std_logic;                     -- pulse: conf valid
    conf      : out unsigned(16 downto 0)          -- Q1.16, 0 .. 2**16
  );
end entity;

architecture rtl of ms_confidence is
  constant ONE : natural := 2 ** 16;
  constant Q_W : natural := 17;                    -- quotient bits (>= 2**16 clamps to ONE)
  constant P_W : natural := 2 * Q_W;               -- product bits

  type state_t is (S_IDLE, S_DIV1, S_DIV2, S_MUL, S_OUT);
  signal state    : state_t := S_IDLE;
  signal sh_r     : unsigned(W - 1 downto 0);      -- share, share_ref held for the second division
  signal shref_r  : unsigned(W - 1 downto 0);
  signal dv_valid : std_logic := '0';
  signal dv_n     : unsigned(W + 15 downto 0);
  signal dv_d     : unsigned(W - 1 downto 0);
  signal dv_busy  : std_logic;
  signal dv_ov    : std_logic;
  signal dv_q     : unsigned(Q_W - 1 downto 0);
  signal ra, rb   : unsigned(Q_W - 1 downto 0);    -- the two ratios, 0 .. ONE
  signal p        : unsigned(P_W - 1 downto 0);
  signal k        : natural range 0 to Q_W - 1;
  signal conf_r   : unsigned(16 downto 0) := (others => '0');
  signal done_r   : std_logic := '0';

  function clamp_one(q : unsigned) return unsigned is
  begin
    if q > ONE then
      return to_unsigned(ONE, q'length);
    end if;
    return q;
  end function;
begin
  u_div : entity work.ms_divider_iter
    generic map (N_W => W + 16, D_W => W, Q_W => Q_W)
    port map (clk => clk, rst => rst, in_valid => dv_valid, in_n => dv_n, in_d => dv_d, busy => dv_busy,
              out_valid => dv_ov, out_q => dv_q);

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      dv_valid <= '0';
      done_r   <= '0';
      if state = S_IDLE then
        if start = '1' then                            -- division 1: rho 2**16 / rho_ref (0 / 1 if 0)
          if rho_ref = 0 then
            dv_n <= (others => '0');
            dv_d <= to_unsigned(1, W);
          else
            dv_n <= shift_left(resize(rho, W + 16), 16);
            dv_d <= rho_ref;
          end if;
          dv_valid <= '1';
          sh_r     <= share;
          shref_r  <= share_ref;
          state    <= S_DIV1;
        end if;
      elsif state = S_DIV1 then
        if dv_ov = '1' then                            -- division 2: share 2**16 / share_ref
          ra <= clamp_one(dv_q);
          if shref_r = 0 then
            dv_n <= (others => '0');
            dv_d <= to_unsigned(1, W);
          else
            dv_n <= shift_left(resize(sh_r, W + 16), 16);
            dv_d <= shref_r;
          end if;
          dv_valid <= '1';
          state    <= S_DIV2;
        end if;
      elsif state = S_DIV2 then
        if dv_ov = '1' then
          rb    <= clamp_one(dv_q);
          p     <= (others => '0');
          k     <= Q_W - 1;
          state <= S_MUL;
        end if;
      elsif state = S_MUL then  -- MSB first: p = 2 p + bit_k(rb) ra (rb shifts up)
        if rb(Q_W - 1) = '1' then
          p <= shift_left(p, 1) + resize(ra, P_W);
        else
          p <= shift_left(p, 1);
        end if;
        rb <= shift_left(rb, 1);
        if k = 0 then
          state <= S_OUT;
        else
          k <= k - 1;
        end if;
      elsif state = S_OUT then  -- >> 16 (p <= 2**32: 17 bits)
        conf_r <= p(32 downto 16);
        done_r <= '1';
        state  <= S_IDLE;
      end if;
      if rst = '1' then
        state    <= S_IDLE;
        dv_valid <= '0';
        done_r   <= '0';
      end if;
    end if;
  end process;

  busy <= '0' when state = S_IDLE else '1';
  done <= done_r;
  conf <= conf_r;
end architecture;
