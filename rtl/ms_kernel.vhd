-- ms_kernel: inside test and kernel value of one lane (one pixel per clock).
--
-- For a pixel at offset (dx, dy) from the window centre:
--   inside = |dx| <= ex and |dy| <= ey and TA[|dx|] + TB[|dy|] < D
--   k      = 1                                   (KERNEL_EPAN = 0, flat)
--          = 2**KERNEL_BITS - KA[|dx|] - KB[|dy|]  (KERNEL_EPAN = 1, Epanechnikov)
--   k is forced to 0 when not inside.
-- The tables TA, TB (KD_W), KA, KB (KVAL_W) and D come from ms_kernel_tables
-- through the table write port (broadcast to every lane's private copy, a
-- 2**HALF_W-entry register file / LUT RAM with a registered read); D, ex and
-- ey are levels that are stable while pixels flow.
--
-- Latency: KERNEL_LAT = 2 clocks (in_* sampled at edge n -> out_* valid after
-- edge n+1); throughput 1 pixel per clock; no handshake (in_valid -> out_valid).
-- Model: mstrack.fixed.blocks.ms_kernel (.inside, .k; TA, TB, KA, KB, D).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_kernel is
  generic (
    HALF_W      : natural := 6;   -- width of ex, ey and of the table address (2**HALF_W entries)
    D_W         : natural := 9;   -- width of the signed dx, dy inputs (REGION_W + 1)
    KERNEL_EPAN : natural := 0;   -- 0 flat (k = 1, no KA/KB tables), 1 Epanechnikov (two KVAL_W tables, two subtractors)
    KERNEL_BITS : natural := 8;   -- Epanechnikov k = 2**KERNEL_BITS - KA - KB
    KVAL_W      : natural := 1;   -- width of k, KA, KB (1 for flat)
    KD_W        : natural := 29   -- width of TA, TB, D
  );
  port (
    clk       : in  std_logic;                          -- clock
    rst       : in  std_logic;                          -- synchronous reset (valid pipeline)
    -- kernel table write port (broadcast) and levels
    kt_we     : in  std_logic;                          -- write table entry kt_addr
    kt_addr   : in  unsigned(HALF_W - 1 downto 0);      -- table index i (= |dx| or |dy|)
    kt_ta     : in  unsigned(KD_W - 1 downto 0);        -- TA[i] = 4 i^2 h^2
    kt_tb     : in  unsigned(KD_W - 1 downto 0);        -- TB[i] = 4 i^2 w^2
    kt_ka     : in  unsigned(KVAL_W - 1 downto 0);      -- KA[i] (Epanechnikov only)
    kt_kb     : in  unsigned(KVAL_W - 1 downto 0);      -- KB[i] (Epanechnikov only)
    kd_d      : in  unsigned(KD_W - 1 downto 0);        -- D = w^2 h^2 (level)
    ex        : in  unsigned(HALF_W - 1 downto 0);      -- half extent x (level)
    ey        : in  unsigned(HALF_W - 1 downto 0);      -- half extent y (level)
    -- pixel in
    in_valid  : in  std_logic;                          -- pixel valid
    in_dx     : in  signed(D_W - 1 downto 0);           -- column offset from the window centre
    in_dy     : in  signed(D_W - 1 downto 0);           -- row offset from the window centre
    -- result out (KERNEL_LAT clocks later)
    out_valid : out std_logic;                          -- in_valid delayed
    out_inside : out std_logic;                         -- pixel inside the kernel ellipse
    out_k     : out unsigned(KVAL_W - 1 downto 0)       -- kernel value (0 when outside)
  );
end entity;

architecture rtl of ms_kernel is
  constant N_ENT : natural := 2 ** HALF_W;
  type kd_ram_t is array (0 to N_ENT - 1) of unsigned(KD_W - 1 downto 0);
  type kv_ram_t is array (0 to N_ENT - 1) of unsigned(KVAL_W - 1 downto 0);
  signal ta_ram, tb_ram : kd_ram_t := (others => (others => '0'));
  signal ka_ram, kb_ram : kv_ram_t := (others => (others => '0'));

  -- stage 1: table values
  signal v1, ok1      : std_logic := '0';
  signal ta1, tb1     : unsigned(KD_W - 1 downto 0) := (others => '0');
  signal ka1, kb1     : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  -- stage 2: outputs
  signal v2, in2      : std_logic := '0';
  signal k2           : unsigned(KVAL_W - 1 downto 0) := (others => '0');
begin
  assert KERNEL_EPAN = 0 or KVAL_W >= KERNEL_BITS + 1
    report "ms_kernel: KVAL_W must hold 2**KERNEL_BITS" severity failure;

  p_tables : process (clk)
  begin
    if rising_edge(clk) then
      if kt_we = '1' then
        ta_ram(to_integer(kt_addr)) <= kt_ta;
        tb_ram(to_integer(kt_addr)) <= kt_tb;
        if KERNEL_EPAN = 1 then
          ka_ram(to_integer(kt_addr)) <= kt_ka;
          kb_ram(to_integer(kt_addr)) <= kt_kb;
        end if;
      end if;
    end if;
  end process;

  p_stage1 : process (clk)
    variable adx, ady : unsigned(D_W - 1 downto 0);
    variable ix, iy   : natural range 0 to N_ENT - 1;
  begin
    if rising_edge(clk) then
      -- |dx|, |dy| (explicit: GHDL 2.0's Verilog writer has no abs)
      if in_dx(D_W - 1) = '1' then
        adx := unsigned(-in_dx);
      else
        adx := unsigned(in_dx);
      end if;
      if in_dy(D_W - 1) = '1' then
        ady := unsigned(-in_dy);
      else
        ady := unsigned(in_dy);
      end if;
      ix  := to_integer(adx(HALF_W - 1 downto 0));
      iy  := to_integer(ady(HALF_W - 1 downto 0));
      ta1 <= ta_ram(ix);
      tb1 <= tb_ram(iy);
      if KERNEL_EPAN = 1 then
        ka1 <= ka_ram(ix);
        kb1 <= kb_ram(iy);
      end if;
      if adx <= resize(ex, D_W) and ady <= resize(ey, D_W) then
        ok1 <= '1';
      else
        ok1 <= '0';
      end if;
      v1 <= in_valid;
      if rst = '1' then
        v1 <= '0';
      end if;
    end if;
  end process;

  p_stage2 : process (clk)
    variable s  : unsigned(KD_W downto 0);
    variable kv : unsigned(KVAL_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      s := resize(ta1, KD_W + 1) + resize(tb1, KD_W + 1);
      if KERNEL_EPAN = 1 then
        kv := to_unsigned(2 ** KERNEL_BITS, KVAL_W) - ka1 - kb1;
      else
        kv := to_unsigned(1, KVAL_W);
      end if;
      if ok1 = '1' and s < resize(kd_d, KD_W + 1) then
        in2 <= '1';
        k2  <= kv;
      else
        in2 <= '0';
        k2  <= (others => '0');
      end if;
      v2 <= v1;
      if rst = '1' then
        v2 <= '0';
      end if;
    end if;
  end process;

  out_valid  <= v2;
  out_inside <= in2;
  out_k      <= k2;
end architecture;
