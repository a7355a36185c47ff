-- ms_ram_sdp: simple dual-port RAM (one write port, one read port, one clock), initialised to zero.
--
-- Write: we, waddr, wdata -> word waddr at the clock edge that samples them (WR_LAT = 0) or at the
--        next one (WR_LAT = 1: the write port is registered first); addresses >= DEPTH write nothing.
-- Read : raddr in cycle t (sampled by edge s) -> rdata in cycle t + RD_LAT (after edge
--        s + RD_LAT - 1): read latency RD_LAT clocks;
--        a read of an address >= DEPTH returns the previous read's data (the output holds); a read of
--        the address written at the same edge returns the OLD word in this architecture (on ECP5 the
--        DP16KD port collision is undefined: users must not read a word while writing it).
-- Throughput: one write and one read per clock.  No reset (RAM and data path only).
-- Architectures (pick one per build, both give the same rdata sequence):
--   * `inferred` (this file): a block RAM any tool infers, read register then RD_LAT - 1 plain
--     registers.  Used by simulation (GHDL, GHDL -> Verilog -> Verilator) and for other vendors.
--   * `ecp5` (rtl/ecp5/ms_ram_sdp_ecp5.vhd): DP16KD instantiated with the output register
--     (REGMODE_B = "OUTREG", which yosys 0.70 never infers), tiled in depth and width, the depth
--     multiplexer behind a register: RD_LAT >= 3 (>= 4 and more than 4 rows: two registered levels).  mstrack.synth analyses it after this file for
--     ECP5 runs, so it becomes the entity's default (most recently analysed) architecture.
-- Each extra clock of RD_LAT costs DATA_W flip-flops; RD_LAT = 3 lets ECP5 run a block-RAM read at
-- the fabric's speed (DP16KD clock-to-out without the output register: ~5.8 ns).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_ram_sdp is
  generic (
    DEPTH  : positive := 1024;  -- words
    DATA_W : positive := 9;     -- word width
    ADDR_W : positive := 10;    -- address width, 2**ADDR_W >= DEPTH
    RD_LAT : positive := 1;     -- read latency (clocks); the ecp5 architecture's DP16KD path needs >= 2 / 3
    WR_LAT : natural  := 0      -- 0 or 1: clocks from the write port to the RAM (1 registers the port:
                                -- on ECP5 the DP16KD write enable, address and data come from flip-flops;
                                -- costs ADDR_W + DATA_W + 1 FF)
  );
  port (
    clk   : in  std_logic;                              -- clock
    we    : in  std_logic;                              -- write enable
    waddr : in  unsigned(ADDR_W - 1 downto 0);          -- write address
    wdata : in  std_logic_vector(DATA_W - 1 downto 0);  -- write data
    raddr : in  unsigned(ADDR_W - 1 downto 0);          -- read address
    rdata : out std_logic_vector(DATA_W - 1 downto 0)   -- read data, RD_LAT clocks after raddr
  );
end entity;

architecture inferred of ms_ram_sdp is
  type ram_t is array (0 to DEPTH - 1) of std_logic_vector(DATA_W - 1 downto 0);
  type pipe_t is array (1 to RD_LAT) of std_logic_vector(DATA_W - 1 downto 0);
  -- a < DEPTH, with DEPTH = 2**ADDR_W allowed (GHDL 2.0 --synth truncates a natural that does not
  -- fit the unsigned's width: `a < 2**ADDR_W` became `a < 0`, always false)
  function in_range(a : unsigned) return boolean is
  begin
    return resize(a, ADDR_W + 1) < DEPTH;
  end function;
  signal ram  : ram_t := (others => (others => '0'));
  signal pipe : pipe_t := (others => (others => '0'));  -- pipe(1): RAM read register
  signal w_en   : std_logic := '0';                       -- the write port after WR_LAT clocks
  signal w_addr : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal w_data : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
begin
  assert 2 ** ADDR_W >= DEPTH report "ms_ram_sdp: ADDR_W too small for DEPTH" severity failure;
  assert WR_LAT <= 1 report "ms_ram_sdp: WR_LAT must be 0 or 1" severity failure;

  g_wr0 : if WR_LAT = 0 generate
    w_en   <= we;
    w_addr <= waddr;
    w_data <= wdata;
  end generate;

  g_wr1 : if WR_LAT = 1 generate
    p_wr : process (clk)
    begin
      if rising_edge(clk) then
        w_en   <= we;
        w_addr <= waddr;
        w_data <= wdata;
      end if;
    end process;
  end generate;

  p_ram : process (clk)
  begin
    if rising_edge(clk) then
      if in_range(raddr) then
        pipe(1) <= ram(to_integer(raddr));
      end if;
      for i in 2 to RD_LAT loop
        pipe(i) <= pipe(i - 1);
      end loop;
      if w_en = '1' and in_range(w_addr) then
        ram(to_integer(w_addr)) <= w_data;
      end if;
    end if;
  end process;

  rdata <= pipe(RD_LAT);
end architecture;
