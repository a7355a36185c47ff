-- ms_grey: grey level of an RGB pixel.
--
-- Computes: grey = (77 R + 150 G + 29 B) >> 8 (truncating, 0..255; the
-- weights sum to 256), without multipliers: each constant product is a sum of
-- shifted copies of its channel (77 = 64+8+4+1, 150 = 128+16+4+2,
-- 29 = 16+8+4+1).  Stage 1 registers the three products, each as two adder
-- levels ((a + b) + (c + d)); stage 2 their 16-bit sum (two adder levels) and
-- keeps bits 15:8.  No MULT18X18D: at most two carry chains per clock.
-- Latency: 2 clocks.  Throughput: 1 pixel/clock, no handshake (valid only).
-- Python model: mstrack.fixed.blocks.ms_grey.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_grey is
  port (
    clk       : in  std_logic;                      -- clock
    rst       : in  std_logic;                      -- synchronous reset (valid only)
    in_valid  : in  std_logic;                      -- pixel present
    in_data   : in  std_logic_vector(23 downto 0);  -- RGB: R 23:16, G 15:8, B 7:0
    out_valid : out std_logic;                      -- in_valid delayed 2 clocks
    out_grey  : out unsigned(7 downto 0)            -- grey level
  );
end entity;

architecture rtl of ms_grey is
  constant P_W : natural := 16;  -- product / sum width (77 + 150 + 29 = 256: sum <= 65280)
  signal v1         : std_logic := '0';
  signal pr, pg, pb : unsigned(P_W - 1 downto 0);  -- 77 R, 150 G, 29 B

  -- c shifted left by s bits, P_W wide
  function sh(c : unsigned(7 downto 0); s : natural) return unsigned is
  begin
    return shift_left(resize(c, P_W), s);
  end function;
begin
  p_grey : process (clk)
    variable r, g, b : unsigned(7 downto 0);
  begin
    if rising_edge(clk) then
      r := unsigned(in_data(23 downto 16));
      g := unsigned(in_data(15 downto 8));
      b := unsigned(in_data(7 downto 0));
      v1        <= in_valid;
      pr        <= (sh(r, 6) + sh(r, 3)) + (sh(r, 2) + sh(r, 0));  -- 77 R
      pg        <= (sh(g, 7) + sh(g, 4)) + (sh(g, 2) + sh(g, 1));  -- 150 G
      pb        <= (sh(b, 4) + sh(b, 3)) + (sh(b, 2) + sh(b, 0));  -- 29 B
      out_valid <= v1;
      out_grey  <= resize(shift_right(pr + pg + pb, 8), 8);
      if rst = '1' then
        v1        <= '0';
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
