-- ms_loss_flag: the loss flag of tracker v2 (reported status uncertain / lost),
--
--   lost = share = 0  or  rho_s = 0  or  (rho_s 2**16 < LOSS_RHO rho0  and  con_s < LOSS_CONTRAST)
--
-- rho_s (smoothed rho) and rho0 (rho at init): unsigned Q1.16 (0 .. 2**16); share: this frame's share
-- of the box (Q1.16); con_s: smoothed contrast share - ring_share, signed Q1.16 (-2**16 .. 2**16).
-- LOSS_RHO = round(loss_rho 2**16) (0 .. 2**17) and LOSS_CONTRAST = round(loss_contrast 2**16)
-- (-2**16 .. 2**16) are the rounded parameters (mstrack.fixed.vhdl_pkg.v2_scale_generics).
-- Exact: the product LOSS_RHO rho0 (< 2**(RHO_W + 18)) is formed by shift-and-add, one bit of the
-- constant per clock, MSB first (no multiplier block; an ECP5 MULT18X18D without its registers would
-- be the slowest path of the core, rtl/ms_mult_r4.vhd), then compared with rho_s 2**16.
-- Model: mstrack.fixed.blocks_v2.ms_loss_flag(rho_s, rho0, con_s, share, loss_rho, loss_contrast),
-- bit for bit (every input).
--
-- Latency    : FLAG_LAT = LR_W + 2 = 20 clocks: if edge s samples start = 1 (busy = 0), edge
--              s + FLAG_LAT samples done = 1 (tb/test_ms_loss_flag.py asserts it).  Once per frame.
-- Throughput : one flag per FLAG_LAT clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; lost is registered and
--              held until the next done.
-- Cost       : one RHO_W + 18 bit adder (the product), one RHO_W + 18 bit compare, a CON_W-bit compare
--              with a constant, two zero tests; 3 RHO_W + 29 flip-flops (80 at RHO_W = 17).
-- Reset      : synchronous, active high: control state.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_loss_flag is
  generic (
    RHO_W         : positive := 17;     -- rho_s, rho0, share bits (unsigned Q1.16)
    CON_W         : positive := 18;     -- con_s bits (signed Q1.16)
    LOSS_RHO      : natural  := 57672;  -- round(loss_rho 2**16), 0 .. 2**17
    LOSS_CONTRAST : integer  := 12452   -- round(loss_contrast 2**16), -2**16 .. 2**16
  );
  port (
    clk   : in  std_logic;                        -- clock
    rst   : in  std_logic;                        -- synchronous reset
    start : in  std_logic;                        -- pulse: inputs valid (while busy = 0)
    rho_s : in  unsigned(RHO_W - 1 downto 0);     -- smoothed rho (ms_loss_filter)
    rho0  : in  unsigned(RHO_W - 1 downto 0);     -- rho at init
    con_s : in  signed(CON_W - 1 downto 0);       -- smoothed contrast (ms_loss_filter)
    share : in  unsigned(RHO_W - 1 downto 0);     -- this frame's share (ms_share)
    busy  : out std_logic;                        -- computing
    done  : out std_logic;                        -- pulse: lost valid
    lost  : out std_logic                         -- the loss flag
  );
end entity;

architecture rtl of ms_loss_flag is
  constant LR_W : natural := 18;                  -- LOSS_RHO bits (<= 2**17)
  constant P_W  : natural := RHO_W + LR_W;        -- product bits
  constant LR_V : unsigned(LR_W - 1 downto 0) := to_unsigned(LOSS_RHO, LR_W);

  type state_t is (S_IDLE, S_MUL, S_OUT);
  signal state  : state_t := S_IDLE;
  signal r0     : unsigned(RHO_W - 1 downto 0);   -- rho0, held for the product
  signal rs     : unsigned(RHO_W - 1 downto 0);   -- rho_s
  signal zero   : std_logic;                      -- share = 0 or rho_s = 0
  signal con_lt : std_logic;                      -- con_s < LOSS_CONTRAST
  signal p      : unsigned(P_W - 1 downto 0);     -- LOSS_RHO rho0 (partial)
  signal k      : natural range 0 to LR_W - 1;
  signal lost_r : std_logic := '0';
  signal done_r : std_logic := '0';
begin
  assert LOSS_RHO <= 2 ** 17 and LOSS_CONTRAST >= -2 ** 16 and LOSS_CONTRAST <= 2 ** 16
    report "ms_loss_flag: LOSS_RHO in 0 .. 2**17, LOSS_CONTRAST in -2**16 .. 2**16" severity failure;
  assert CON_W >= 18 report "ms_loss_flag: CON_W >= 18 (holds LOSS_CONTRAST)" severity failure;

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      done_r <= '0';
      if state = S_IDLE then
        if start = '1' then
          r0 <= rho0;
          rs <= rho_s;
          if share = 0 or rho_s = 0 then
            zero <= '1';
          else
            zero <= '0';
          end if;
          if con_s < to_signed(LOSS_CONTRAST, CON_W) then
            con_lt <= '1';
          else
            con_lt <= '0';
          end if;
          p     <= (others => '0');
          k     <= LR_W - 1;
          state <= S_MUL;
        end if;
      elsif state = S_MUL then  -- MSB first: p = 2 p + bit_k rho0
        if LR_V(k) = '1' then
          p <= shift_left(p, 1) + resize(r0, P_W);
        else
          p <= shift_left(p, 1);
        end if;
        if k = 0 then
          state <= S_OUT;
        else
          k <= k - 1;
        end if;
      elsif state = S_OUT then
        if zero = '1' or (shift_left(resize(rs, P_W), 16) < p and con_lt = '1') then
          lost_r <= '1';
        else
          lost_r <= '0';
        end if;
        done_r <= '1';
        state  <= S_IDLE;
      end if;
      if rst = '1' then
        state  <= S_IDLE;
        done_r <= '0';
      end if;
    end if;
  end process;

  busy <= '0' when state = S_IDLE else '1';
  done <= done_r;
  lost <= lost_r;
end architecture;
