-- ms_mult_r4: pipelined radix-4 multiplier in LUTs and carry chains (no DSP block).
--
-- Computes p = (a * b) mod 2**P_W for an unsigned a (A_W bits) and a b of B_W bits, signed
-- (B_SIGNED = true, two's complement) or unsigned: the low P_W bits of the product (equal to
-- numeric_std resize(a * b, P_W) whenever the product fits in P_W bits, as in ms_bin_pass).
-- a is split into ND = ceil(A_W / 2) radix-4 digits; digit j selects 0, b, 2b or 3b (3b is
-- registered in stage 0 with the operands), weighted 4**j.  The ND partial products are summed
-- by a pipelined binary tree, NLEV = max(1, ceil(log2 ND)) levels, one adder of P_W bits per
-- node and per clock: level 1 adds the selected products of two digits.
-- Why: ECP5 MULT18X18D as yosys maps it has no input/output registers (register -> multiplier
-- -> register is ~7.5-9.5 ns placed); every stage here is select -> one carry chain.
--
-- Latency    : LATENCY = 1 + NLEV clocks from in_valid to out_valid (A_W = 8: 3, A_W = 14: 4).
-- Throughput : one product per clock, no back-pressure: the pipeline always flows.
-- Handshake  : in_valid qualifies in_a/in_b/in_tag; out_valid qualifies out_p/out_tag
--              (one out_valid per in_valid, in order, LATENCY clocks later).
-- Cost       : one P_W-bit adder for 3b, 2**NLEV - 1 adders of P_W bits, their registers.
-- Reset      : synchronous, active high; clears the valid pipeline only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_pkg.all;

entity ms_mult_r4 is
  generic (
    A_W      : natural := 8;      -- bits of the unsigned digit operand a (>= 1)
    B_W      : natural := 21;     -- bits of b (>= 1)
    B_SIGNED : boolean := true;   -- b is two's complement (else unsigned)
    P_W      : natural := 29;     -- product bits kept (mod 2**P_W)
    TAG_W    : natural := 1       -- user tag bits passed alongside (>= 1)
  );
  port (
    clk       : in  std_logic;                             -- clock
    rst       : in  std_logic;                             -- synchronous reset, active high
    in_valid  : in  std_logic;                             -- operands valid
    in_a      : in  unsigned(A_W - 1 downto 0);            -- a (unsigned)
    in_b      : in  std_logic_vector(B_W - 1 downto 0);    -- b (signed if B_SIGNED)
    in_tag    : in  std_logic_vector(TAG_W - 1 downto 0);  -- user tag
    out_valid : out std_logic;                             -- product valid (LATENCY clocks after in_valid)
    out_p     : out std_logic_vector(P_W - 1 downto 0);    -- (a * b) mod 2**P_W
    out_tag   : out std_logic_vector(TAG_W - 1 downto 0)   -- tag of this product
  );
end entity;

architecture rtl of ms_mult_r4 is
  constant ND      : natural := (A_W + 1) / 2;               -- radix-4 digits of a
  constant NLEV    : natural := max(1, clog2(ND));          -- adder tree levels
  constant NDP     : natural := 2 ** NLEV;                   -- digits padded to a power of two
  constant LATENCY : natural := 1 + NLEV;                    -- in_valid -> out_valid
  constant BX_W    : natural := max(P_W, B_W);              -- b extended

  subtype p_t is unsigned(P_W - 1 downto 0);
  type p_arr_t is array (0 to NDP - 1) of p_t;
  type lev_arr_t is array (1 to NLEV) of p_arr_t;
  type tag_arr_t is array (0 to NLEV) of std_logic_vector(TAG_W - 1 downto 0);

  signal v_r   : std_logic_vector(0 to NLEV) := (others => '0');
  signal a_r   : unsigned(2 * NDP - 1 downto 0);              -- a, zero-padded to NDP digits
  signal b1_r  : p_t;                                         -- b (extended to P_W bits)
  signal b3_r  : p_t;                                         -- 3 b mod 2**P_W
  signal lev_r : lev_arr_t;                                   -- node sums of each level
  signal tag_r : tag_arr_t;
begin
  assert A_W >= 1 and B_W >= 1 and P_W >= 1 and TAG_W >= 1
    report "ms_mult_r4: widths must be >= 1" severity failure;

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        v_r <= (others => '0');
      else
        v_r <= in_valid & v_r(0 to NLEV - 1);
      end if;
    end if;
  end process;

  p_data : process (clk)
    variable bx  : unsigned(BX_W - 1 downto 0);
    variable b   : p_t;
    variable sel : p_arr_t;
    variable d   : unsigned(1 downto 0);
  begin
    if rising_edge(clk) then
      -- stage 0: operands and 3 b
      if B_SIGNED then                            -- b mod 2**P_W (low bits, also if P_W < B_W)
        bx := unsigned(resize(signed(in_b), BX_W));
      else
        bx := resize(unsigned(in_b), BX_W);
      end if;
      b := bx(P_W - 1 downto 0);
      a_r      <= resize(in_a, 2 * NDP);
      b1_r     <= b;
      b3_r     <= b + shift_left(b, 1);
      tag_r(0) <= in_tag;
      -- level 1: digit selects, pairs summed (digit 2p + 1 weighted 4)
      for j in 0 to NDP - 1 loop
        d := a_r(2 * j + 1 downto 2 * j);
        case d is
          when "00"   => sel(j) := (others => '0');
          when "01"   => sel(j) := b1_r;
          when "10"   => sel(j) := shift_left(b1_r, 1);
          when others => sel(j) := b3_r;
        end case;
      end loop;
      for p in 0 to NDP / 2 - 1 loop
        lev_r(1)(p) <= sel(2 * p) + shift_left(sel(2 * p + 1), 2);
      end loop;
      -- level l: node p = node 2p + node 2p+1 shifted by 2**l bits (2**(l-1) digits)
      for l in 2 to NLEV loop
        for p in 0 to NDP / 2 ** l - 1 loop
          lev_r(l)(p) <= lev_r(l - 1)(2 * p) + shift_left(lev_r(l - 1)(2 * p + 1), 2 ** l);
        end loop;
      end loop;
      for l in 1 to NLEV loop
        tag_r(l) <= tag_r(l - 1);
      end loop;
    end if;
  end process;

  out_valid <= v_r(NLEV);
  out_p     <= std_logic_vector(lev_r(NLEV)(0));
  out_tag   <= tag_r(NLEV);
end architecture;
