-- ms_decimation: decimation of tracker v2 for a target of size (w8, h8).
--
-- Computes (model: mstrack.fixed.blocks_v2.ms_decimation) log2_d = log2 D, D the smallest
-- power of two <= 8 with (1 + pad) max(w, h) / D <= MAX_WINDOW, exactly:
--   (16 + PAD16) max(w8, h8) <= MAX_WINDOW D 2**12      (w8, h8 in Q.8 px, pad = PAD16 / 16)
-- D = 8 when even that does not hold (the window is then clamped by ms_window_size).
-- No multiplier: a * s <= B  <=>  s <= floor(B / a) for a > 0, so the test for each D in 1, 2, 4
-- is two compares of w8 and h8 with the constant TH(D) = floor(MAX_WINDOW D 2**12 / (16 + PAD16))
-- (max(w8, h8) <= TH  <=>  w8 <= TH and h8 <= TH); a priority select gives the smallest D.
-- The x2 of the lost state (D up to 16) is the caller's: log2_d + 1.
-- Latency: 1 clock from in_valid to out_valid.  Throughput: 1 per clock.
-- Handshake: valid only (no back-pressure); used once per frame.
-- Cost: 6 constant compares of S8_W bits and a 2-bit priority select; 3 FF + 1 valid FF.
-- Reset: synchronous, active high; out_valid only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_decimation is
  generic (
    S8_W       : natural range 9 to 30 := 20;   -- width of w8, h8 (Q(COORD_W).8: COORD_W + 8)
    PAD16      : natural range 0 to 64 := 4;    -- window padding pad in 1/16 (v2 default 4/16)
    MAX_WINDOW : natural range 7 to 1023 := 127 -- largest window diameter (decimated px)
  );
  port (
    clk       : in  std_logic;                         -- clock
    rst       : in  std_logic;                         -- synchronous reset (out_valid only)
    in_valid  : in  std_logic;                         -- w8, h8 valid
    w8        : in  unsigned(S8_W - 1 downto 0);       -- target width, Q.8 px
    h8        : in  unsigned(S8_W - 1 downto 0);       -- target height, Q.8 px
    out_valid : out std_logic;                         -- log2_d valid (in_valid delayed 1 clock)
    log2_d    : out unsigned(1 downto 0)               -- log2 D, D = 1, 2, 4, 8
  );
end entity;

architecture rtl of ms_decimation is
  constant S_MAX : natural := 2 ** S8_W - 1;           -- largest w8, h8
  -- TH(k) = floor(MAX_WINDOW 2**(12 + k) / (16 + PAD16)), saturated at S_MAX (same compare result)
  function th(k : natural) return natural is
    variable t : natural;
  begin
    t := (MAX_WINDOW * 2 ** (12 + k)) / (16 + PAD16);
    if t > S_MAX then
      return S_MAX;
    end if;
    return t;
  end function;
  type th_t is array (0 to 2) of unsigned(S8_W - 1 downto 0);
  constant TH_C : th_t := (to_unsigned(th(0), S8_W), to_unsigned(th(1), S8_W), to_unsigned(th(2), S8_W));
begin
  p_dec : process (clk)
    variable k : unsigned(1 downto 0);
  begin
    if rising_edge(clk) then
      k := "11";
      for i in 2 downto 0 loop                         -- the smallest D that fits wins
        if w8 <= TH_C(i) and h8 <= TH_C(i) then
          k := to_unsigned(i, 2);
        end if;
      end loop;
      log2_d    <= k;
      out_valid <= in_valid;
      if rst = '1' then
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
