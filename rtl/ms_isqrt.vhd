-- ms_isqrt: pipelined digit-by-digit (restoring) integer square root.
--
-- Computes r = floor(sqrt(x)) for an unsigned x of IN_W bits (IN_W even), r of IN_W / 2 bits,
-- bit-exact with mstrack.fixed.primitives.ms_isqrt_reference (and the vectorised ms_isqrt).
-- Stage 0 registers the input; stage k = 1..IN_W/2 brings down the next two input bits into
-- the remainder (rem = rem * 4 + x[2i+1:2i], i = IN_W/2 - k) and tries rem - (4 * root + 1):
-- if the trial is >= 0 the root bit is 1 and the remainder becomes the trial, else 0.
-- The remainder never exceeds 2 * root, so it is held in IN_W/2 + 3 bits, and stage k only
-- subtracts over the k + 2 bits it can occupy (one subtractor, its borrow selecting).
--
-- Latency    : LATENCY = IN_W / 2 + 1 clocks from in_valid to out_valid (constant LATENCY below).
-- Throughput : one root per clock, no back-pressure: the pipeline always flows.
-- Handshake  : in_valid qualifies in_x/in_tag; out_valid qualifies out_r/out_tag
--              (one out_valid per in_valid, in order, LATENCY clocks later).
-- Cost       : IN_W/2 subtractors of at most IN_W/2 + 2 bits; per stage the remaining input bits,
--              remainder, root and tag registers.
-- Reset      : synchronous, active high; clears the valid pipeline only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_isqrt is
  generic (
    IN_W  : natural := 40;  -- input bits (even, >= 2); each 2 bits add one pipeline stage
    TAG_W : natural := 1    -- user tag bits passed alongside (>= 1)
  );
  port (
    clk       : in  std_logic;                             -- clock
    rst       : in  std_logic;                             -- synchronous reset, active high
    in_valid  : in  std_logic;                             -- input valid
    in_x      : in  unsigned(IN_W - 1 downto 0);           -- radicand
    in_tag    : in  std_logic_vector(TAG_W - 1 downto 0);  -- user tag
    out_valid : out std_logic;                             -- result valid (LATENCY clocks after in_valid)
    out_r     : out unsigned(IN_W / 2 - 1 downto 0);       -- floor(sqrt(x))
    out_tag   : out std_logic_vector(TAG_W - 1 downto 0)   -- tag of this result
  );
end entity;

architecture rtl of ms_isqrt is
  constant R_W     : natural := IN_W / 2;
  constant LATENCY : natural := R_W + 1;                   -- clocks from in_valid to out_valid
  constant RW      : natural := R_W + 3;                   -- remainder / trial width
  function minn(a, b : natural) return natural is
  begin
    if a < b then return a; end if;
    return b;
  end function;

  type x_arr_t is array (0 to R_W) of unsigned(IN_W - 1 downto 0);
  type rem_arr_t is array (0 to R_W) of unsigned(RW - 1 downto 0);
  type r_arr_t is array (0 to R_W) of unsigned(R_W - 1 downto 0);
  type tag_arr_t is array (0 to R_W) of std_logic_vector(TAG_W - 1 downto 0);

  signal v_r   : std_logic_vector(0 to R_W) := (others => '0');
  signal x_r   : x_arr_t;    -- input, consumed from the top two bits down
  signal rem_r : rem_arr_t;
  signal r_r   : r_arr_t;
  signal tag_r : tag_arr_t;
begin
  assert IN_W >= 2 and IN_W mod 2 = 0 and TAG_W >= 1
    report "ms_isqrt: IN_W must be even and >= 2, TAG_W >= 1" severity failure;

  p_ctrl : process (clk)
  begin
    if rising_edge(clk) then
      if rst = '1' then
        v_r <= (others => '0');
      else
        v_r <= in_valid & v_r(0 to R_W - 1);
      end if;
    end if;
  end process;

  p_data : process (clk)
    variable rm   : unsigned(RW - 1 downto 0);
    variable sub  : unsigned(RW - 1 downto 0);
    variable diff : unsigned(RW downto 0);        -- rm - sub, top bit = borrow
    variable nw   : natural;                      -- significant bits of rm in stage k
  begin
    if rising_edge(clk) then
      x_r(0)   <= in_x;
      rem_r(0) <= (others => '0');
      r_r(0)   <= (others => '0');
      tag_r(0) <= in_tag;
      for k in 1 to R_W loop
        -- after stage k - 1 the root has k - 1 bits and rem <= 2 root < 2**k, so rm has
        -- k + 2 significant bits: the trial subtraction is only that wide (bit-exact)
        nw := minn(k + 2, RW);
        -- bring down the next two bits (top of the shifted input)
        rm  := shift_left(rem_r(k - 1), 2);
        rm(1 downto 0) := x_r(k - 1)(IN_W - 1 downto IN_W - 2);
        sub := shift_left(resize(r_r(k - 1), RW), 2);
        sub(0) := '1';
        diff := (others => '0');
        diff(nw downto 0) := resize(rm(nw - 1 downto 0), nw + 1) - resize(sub(nw - 1 downto 0), nw + 1);
        x_r(k)   <= shift_left(x_r(k - 1), 2);
        tag_r(k) <= tag_r(k - 1);
        rem_r(k) <= (others => '0');
        if diff(nw) = '0' then
          rem_r(k)(nw - 1 downto 0) <= diff(nw - 1 downto 0);
          r_r(k)   <= shift_left(r_r(k - 1), 1) or to_unsigned(1, R_W);
        else
          rem_r(k)(nw - 1 downto 0) <= rm(nw - 1 downto 0);
          r_r(k)   <= shift_left(r_r(k - 1), 1);
        end if;
      end loop;
    end if;
  end process;

  out_valid <= v_r(R_W);
  out_r     <= r_r(R_W);
  out_tag   <= tag_r(R_W);
end architecture;
