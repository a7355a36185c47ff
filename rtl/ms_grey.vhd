-- ms_grey: grey level of an RGB pixel.
--
-- Computes: grey = (77 R + 150 G + 29 B) >> 8 (truncating, 0..255; the
-- weights sum to 256).  Stage 1 registers the three constant products
-- (15, 16 and 13 bits), stage 2 their sum (16 bits) and keeps bits 15:8.
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
  signal v1         : std_logic := '0';
  signal pr, pg, pb : unsigned(15 downto 0);  -- 77 R, 150 G, 29 B
begin
  p_grey : process (clk)
  begin
    if rising_edge(clk) then
      v1        <= in_valid;
      pr        <= resize(unsigned(in_data(23 downto 16)) * to_unsigned(77, 8), 16);
      pg        <= resize(unsigned(in_data(15 downto 8)) * to_unsigned(150, 8), 16);
      pb        <= resize(unsigned(in_data(7 downto 0)) * to_unsigned(29, 8), 16);
      out_valid <= v1;
      out_grey  <= resize(shift_right(pr + pg + pb, 8), 8);
      if rst = '1' then
        v1        <= '0';
        out_valid <= '0';
      end if;
    end if;
  end process;
end architecture;
