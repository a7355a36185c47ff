-- ms_colour_bin: colour histogram bin of an RGB pixel.
--
-- Computes: bin = ((R >> s) << 2b) | ((G >> s) << b) | (B >> s), s = 8 - b,
-- b = COLOUR_BITS, i.e. the COLOUR_BITS most significant bits of R, G, B
-- concatenated (pure wiring plus the output register).
-- Latency: 1 clock.  Throughput: 1 pixel/clock, no handshake (valid only).
-- Python model: mstrack.fixed.blocks.ms_colour_bin.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_colour_bin is
  generic (
    COLOUR_BITS : natural range 1 to 8 := 3  -- bits kept per channel; 2**(3*COLOUR_BITS) bins
  );
  port (
    clk       : in  std_logic;                                       -- clock
    rst       : in  std_logic;                                       -- synchronous reset (out_valid only)
    in_valid  : in  std_logic;                                       -- pixel present
    in_data   : in  std_logic_vector(23 downto 0);                   -- RGB: R 23:16, G 15:8, B 7:0
    out_valid : out std_logic;                                       -- in_valid delayed 1 clock
    out_bin   : out std_logic_vector(3 * COLOUR_BITS - 1 downto 0)   -- colour bin
  );
end entity;

architecture rtl of ms_colour_bin is
  constant B : natural := COLOUR_BITS;
begin
  p_bin : process (clk)
  begin
    if rising_edge(clk) then
      out_valid <= in_valid;
      out_bin   <= in_data(23 downto 24 - B) & in_data(15 downto 16 - B) & in_data(7 downto 8 - B);
      if rst = '1' then
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
