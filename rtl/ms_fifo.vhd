-- ms_fifo: small synchronous FIFO with ready/valid on both sides (the core's one skid/FIFO).
--
-- Computes: nothing; stores up to DEPTH words in order.  Registered outputs.
-- Latency: 1 clock from s_valid & s_ready to m_valid.  Throughput: 1 word per clock.
-- Handshake: AXI-Stream style; s_ready = not full, m_valid = not empty.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_fifo is
  generic (
    WIDTH : natural := 8;   -- word bits
    DEPTH : natural := 4    -- words (power of two, >= 2)
  );
  port (
    clk     : in  std_logic;                            -- clock
    rst     : in  std_logic;                            -- synchronous reset (empties the FIFO)
    s_valid : in  std_logic;                            -- input word valid
    s_ready : out std_logic;                            -- FIFO not full
    s_data  : in  std_logic_vector(WIDTH - 1 downto 0); -- input word
    m_valid : out std_logic;                            -- output word valid
    m_ready : in  std_logic;                            -- consumer takes the word
    m_data  : out std_logic_vector(WIDTH - 1 downto 0)  -- output word
  );
end entity;

architecture rtl of ms_fifo is
  constant AW : natural := clog2(DEPTH);
  type mem_t is array (0 to DEPTH - 1) of std_logic_vector(WIDTH - 1 downto 0);
  signal mem    : mem_t;
  signal wp, rp : unsigned(AW downto 0) := (others => '0');
  signal full, empty : std_logic;
begin
  assert DEPTH >= 2 and 2 ** AW = DEPTH report "ms_fifo: DEPTH must be a power of two >= 2" severity failure;
  empty <= '1' when wp = rp else '0';
  full <= '1' when wp(AW) /= rp(AW) and wp(AW - 1 downto 0) = rp(AW - 1 downto 0) else '0';
  s_ready <= not full;
  m_valid <= not empty;
  m_data <= mem(to_integer(rp(AW - 1 downto 0)));

  p_fifo : process(clk)
  begin
    if rising_edge(clk) then
      if s_valid = '1' and full = '0' then
        mem(to_integer(wp(AW - 1 downto 0))) <= s_data;
        wp <= wp + 1;
      end if;
      if m_ready = '1' and empty = '0' then
        rp <= rp + 1;
      end if;
      if rst = '1' then
        wp <= (others => '0');
        rp <= (others => '0');
      end if;
    end if;
  end process;
end architecture;
