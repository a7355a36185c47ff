-- ms_model_scale: the v2 target model at a window of K pixels, Qw[u] = (Qn[u] K) >> 16.
--
-- Computes mstrack.fixed.blocks_v2.ms_model_scale(Qn, K) bit for bit, one bin per clock: the
-- normalised model Qn (Q0.16, <= 2**16, from ms_bg_model's model RAM) times the window's kernel
-- sum K (flat kernel: its pixel count), floored to the scale of the histogram H (sum Qw ~ K).
-- Meant to sit in the bin pass's model read path (Qn read one bin ahead, Qw beside H); the
-- product is an ms_mult_r4 LUT multiplier (digits of K), so no MULT18X18D and no unregistered
-- DSP path.  Qw <= K < 2**HIST_W, so the result has HIST_W bits.
--
-- Latency    : LATENCY = 1 + max(1, ceil(log2(ceil(HIST_W / 2)))) clocks (HIST_W = 14: 4), the
--              multiplier's; the >> 16 is wiring.
-- Throughput : one bin per clock, no back-pressure.
-- Handshake  : in_valid qualifies in_qn / in_k / in_tag; out_valid qualifies out_qw / out_tag
--              (in order, LATENCY clocks later).
-- Cost       : one ms_mult_r4 (A_W = HIST_W, B_W = QN_FRAC + 1, P_W = HIST_W + QN_FRAC + 1).
-- Reset      : synchronous, active high; the valid pipeline only.
-- Model      : mstrack.fixed.blocks_v2.ms_model_scale.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_model_scale is
  generic (
    HIST_W  : natural := 14;  -- K and Qw bits (the histogram H width)
    QN_FRAC : natural := 16;  -- Qn fraction bits (blocks_v2.QN_BITS); Qn has QN_FRAC + 1 bits
    TAG_W   : natural := 1    -- user tag bits passed alongside (>= 1)
  );
  port (
    clk       : in  std_logic;                             -- clock
    rst       : in  std_logic;                             -- synchronous reset, active high
    in_valid  : in  std_logic;                             -- operands valid
    in_qn     : in  unsigned(QN_FRAC downto 0);            -- Qn[u] (<= 2**QN_FRAC)
    in_k      : in  unsigned(HIST_W - 1 downto 0);         -- K (window pixel count)
    in_tag    : in  std_logic_vector(TAG_W - 1 downto 0);  -- user tag (e.g. the bin)
    out_valid : out std_logic;                             -- result valid (LATENCY clocks later)
    out_qw    : out unsigned(HIST_W - 1 downto 0);         -- Qw[u] = (Qn K) >> QN_FRAC
    out_tag   : out std_logic_vector(TAG_W - 1 downto 0)   -- tag of this result
  );
end entity;

architecture rtl of ms_model_scale is
  constant P_W : natural := HIST_W + QN_FRAC + 1;         -- Qn K < 2**(HIST_W + QN_FRAC + 1)
  signal p     : std_logic_vector(P_W - 1 downto 0);
begin
  u_mult : entity work.ms_mult_r4
    generic map (A_W => HIST_W, B_W => QN_FRAC + 1, B_SIGNED => false, P_W => P_W, TAG_W => TAG_W)
    port map (clk => clk, rst => rst, in_valid => in_valid, in_a => in_k,
              in_b => std_logic_vector(in_qn), in_tag => in_tag, out_valid => out_valid,
              out_p => p, out_tag => out_tag);
  -- Qn <= 2**QN_FRAC, so (Qn K) >> QN_FRAC <= K fits in HIST_W bits
  out_qw <= resize(unsigned(p(P_W - 1 downto QN_FRAC)), HIST_W);
end architecture;
