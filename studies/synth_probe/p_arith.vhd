-- numeric_std multiplications (signed/unsigned, mixed via resize), to_integer on signed,
-- shift_right on signed, integer ranges, generics of type natural/boolean/integer/slv
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.p_pkg.all;

entity p_arith is
  generic (W : natural := 12; ROUND : boolean := true; OFFS : integer := -3;
           INIT : std_logic_vector(3 downto 0) := "1010");
  port (clk : in std_logic;
        a, b : in signed(W - 1 downto 0); u : in unsigned(W - 1 downto 0);
        p_ss : out signed(2 * W - 1 downto 0);
        p_uu : out unsigned(2 * W - 1 downto 0);
        p_su : out signed(2 * W downto 0);
        sh   : out signed(W - 1 downto 0);
        idx  : out integer range -2 ** (W - 1) to 2 ** (W - 1) - 1;
        sat  : out unsigned(W - 1 downto 0);
        lg   : out unsigned(3 downto 0);
        ini  : out std_logic_vector(3 downto 0));
end entity;

architecture rtl of p_arith is
  constant LOG_W : natural := clog2(W);
begin
  process (clk)
    variable i : integer;
  begin
    if rising_edge(clk) then
      p_ss <= a * b;
      p_uu <= u * u;
      p_su <= a * signed(resize(u, W + 1));
      i := to_integer(a) + OFFS;
      if ROUND then
        sh <= shift_right(a + 2, 2);
      else
        sh <= shift_right(a, 2);
      end if;
      idx <= i;
      sat <= sat_add(u, unsigned(b));
      lg  <= to_unsigned(LOG_W, 4);
      ini <= INIT;
    end if;
  end process;
end architecture;
