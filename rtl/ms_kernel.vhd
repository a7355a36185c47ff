-- ms_kernel: kernel value of one lane (one pixel per clock).
--
-- For a pixel at offset (dx, dy) from the window centre:
--   k = 1                                   (KERNEL_EPAN = 0, flat)
--     = 2**KERNEL_BITS - KA[|dx|] - KB[|dy|]  (KERNEL_EPAN = 1, Epanechnikov)
--   k is forced to 0 when in_inside = '0'; out_inside = in_inside delayed.
-- The inside test itself (model: TA[|dx|] + TB[|dy|] < D) is done by the caller:
-- ms_window_scan's row-extent mask, |dx| <= XR[|dy|] (rows |dy| <= ey only), is the
-- same test because TA grows with |dx| and dx = 0 is inside every row |dy| <= ey
-- (checked over all target sizes by tb/test_ms_pixel_pass.py::test_row_extent_is_inside_test).
-- The tables KA, KB (KVAL_W bits, 2**HALF_W entries) come from ms_kernel_tables
-- through the table write port (broadcast to every lane's private copy).
--
-- Pipeline (KERNEL_EPAN = 1): stage 1 registers |dx|, |dy|; stage 2 the table read
-- (registered read, address from registers); stage 3 registers the read data once
-- more with no logic between (block RAM output register if yosys maps the tables to
-- DP16KD, else plain flip-flops after the LUT RAM); stage 4 registers k.  The flat
-- kernel has no tables; its inside flag goes through the same 4 stages.
-- Latency: KERNEL_LAT = 4 clocks (in_* sampled at edge n -> out_* valid after
-- edge n+3), for both kernels; throughput 1 pixel per clock; no handshake
-- (in_valid -> out_valid).
-- Model: mstrack.fixed.blocks.ms_kernel (.inside, .k; KA, KB).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_kernel is
  generic (
    HALF_W      : natural := 6;   -- table address width (2**HALF_W entries); |dx|, |dy| < 2**HALF_W when inside
    D_W         : natural := 9;   -- width of the signed dx, dy inputs (REGION_W + 1)
    KERNEL_EPAN : natural := 0;   -- 0 flat (k = 1, no tables), 1 Epanechnikov (two KVAL_W tables, two subtractors)
    KERNEL_BITS : natural := 8;   -- Epanechnikov k = 2**KERNEL_BITS - KA - KB
    KVAL_W      : natural := 1    -- width of k, KA, KB (1 for flat)
  );
  port (
    clk       : in  std_logic;                          -- clock
    rst       : in  std_logic;                          -- synchronous reset (valid pipeline)
    -- kernel table write port (broadcast)
    kt_we     : in  std_logic;                          -- write table entry kt_addr
    kt_addr   : in  unsigned(HALF_W - 1 downto 0);      -- table index i (= |dx| or |dy|)
    kt_ka     : in  unsigned(KVAL_W - 1 downto 0);      -- KA[i] (Epanechnikov only)
    kt_kb     : in  unsigned(KVAL_W - 1 downto 0);      -- KB[i] (Epanechnikov only)
    -- pixel in
    in_valid  : in  std_logic;                          -- pixel valid
    in_inside : in  std_logic;                          -- pixel inside the kernel ellipse (row-extent mask)
    in_dx     : in  signed(D_W - 1 downto 0);           -- column offset from the window centre
    in_dy     : in  signed(D_W - 1 downto 0);           -- row offset from the window centre
    -- result out (KERNEL_LAT clocks later)
    out_valid : out std_logic;                          -- in_valid delayed
    out_inside : out std_logic;                         -- in_inside delayed
    out_k     : out unsigned(KVAL_W - 1 downto 0)       -- kernel value (0 when outside)
  );
end entity;

architecture rtl of ms_kernel is
  constant N_ENT      : natural := 2 ** HALF_W;
  constant KERNEL_LAT : natural := 4;
  type kv_ram_t is array (0 to N_ENT - 1) of unsigned(KVAL_W - 1 downto 0);
  signal ka_ram, kb_ram : kv_ram_t := (others => (others => '0'));

  -- valid / inside delay line (index 1 .. KERNEL_LAT = stage)
  signal v_d, in_d    : std_logic_vector(1 to KERNEL_LAT) := (others => '0');
  -- stage 1: |dx|, |dy|
  signal adx1, ady1   : unsigned(HALF_W - 1 downto 0) := (others => '0');
  -- stage 2: table read; stage 3: read data registered again
  signal ka2, kb2     : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  signal ka3, kb3     : unsigned(KVAL_W - 1 downto 0) := (others => '0');
  -- stage 4: output
  signal k4           : unsigned(KVAL_W - 1 downto 0) := (others => '0');
begin
  assert KERNEL_EPAN = 0 or KVAL_W >= KERNEL_BITS + 1
    report "ms_kernel: KVAL_W must hold 2**KERNEL_BITS" severity failure;

  p_pipe : process (clk)
  begin
    if rising_edge(clk) then
      v_d  <= in_valid & v_d(1 to KERNEL_LAT - 1);
      in_d <= in_inside & in_d(1 to KERNEL_LAT - 1);
      if rst = '1' then
        v_d <= (others => '0');
      end if;
    end if;
  end process;

  g_flat : if KERNEL_EPAN = 0 generate
    k4 <= (0 => in_d(KERNEL_LAT), others => '0');
  end generate;

  g_epan : if KERNEL_EPAN = 1 generate
    p_tables : process (clk)
    begin
      if rising_edge(clk) then
        if kt_we = '1' then
          ka_ram(to_integer(kt_addr)) <= kt_ka;
          kb_ram(to_integer(kt_addr)) <= kt_kb;
        end if;
      end if;
    end process;

    p_k : process (clk)
      variable adx, ady : unsigned(D_W - 1 downto 0);
    begin
      if rising_edge(clk) then
        -- stage 1: |dx|, |dy| (explicit: GHDL 2.0's Verilog writer has no abs); only the
        -- HALF_W low bits matter (|dx| <= ex, |dy| <= ey for every inside pixel)
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
        adx1 <= adx(HALF_W - 1 downto 0);
        ady1 <= ady(HALF_W - 1 downto 0);
        -- stage 2: registered table read
        ka2 <= ka_ram(to_integer(adx1));
        kb2 <= kb_ram(to_integer(ady1));
        -- stage 3: read data registered once more (no logic between)
        ka3 <= ka2;
        kb3 <= kb2;
        -- stage 4: k
        if in_d(3) = '1' then
          k4 <= to_unsigned(2 ** KERNEL_BITS, KVAL_W) - ka3 - kb3;
        else
          k4 <= (others => '0');
        end if;
      end if;
    end process;
  end generate;

  out_valid  <= v_d(KERNEL_LAT);
  out_inside <= in_d(KERNEL_LAT);
  out_k      <= k4;
end architecture;
