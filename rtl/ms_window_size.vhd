-- ms_window_size: window diameter of tracker v2 along one axis, in decimated px.
--
-- Computes (model: mstrack.fixed.blocks_v2.ms_window_size(s8, PAD16, D, limit))
--   n = round((1 + pad) s / D) = ((16 + PAD16) s8 + 2**(sh - 1)) >> sh,  sh = 12 + log2 D
--   (half up, exact), then n = max(3, min(n, limit))
-- with s8 the target size in Q.8 px and pad = PAD16 / 16.  With PAD16 = 0 this is
-- round(s / D) = (s8 + 2**(7 + log2 D)) >> (8 + log2 D): ms_box_size is this entity with PAD16 = 0.
-- limit is the caller's: min(MAX_WINDOW, decimated frame size - 2) for the window,
-- decimated frame size - 2 for the init box (tracker_v2: _geometry, init).
-- Pipeline: 1 p = (16 + PAD16) s8 as a sum of shifted copies of s8, one per set bit of the
-- constant (no multiplier block); 2 t = p >> (sh - 1) (a 3-level barrel shifter over log2 D),
-- n0 = (t + 1) >> 1;
-- 3 clamp to [3, limit].
-- Latency: 3 clocks from in_valid to out_valid.  Throughput: 1 per clock.
-- Handshake: valid only (no back-pressure); used once or twice per frame.
-- Cost: popcount(16 + PAD16) - 1 adders of S8_W + bits(16 + PAD16) bits (1 for the default PAD16 = 4, 0 for
-- PAD16 = 0), a barrel shifter, one incrementer, two compares of N0_W bits; about
-- 2 S8_W + 2 N_W FF (docs/blocks/ms_window_size.md: 54 LUT4, 55 FF, 36 CCU2C for the defaults).
-- Reset: synchronous, active high; valid flags only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_window_size is
  generic (
    S8_W       : natural range 9 to 30 := 20;  -- width of s8 (Q(COORD_W).8: COORD_W + 8)
    PAD16      : natural range 0 to 64 := 4;   -- window padding in 1/16 (0: ms_box_size)
    N_W        : natural range 2 to 16 := 7    -- width of limit and n (7: MAX_WINDOW 127)
  );
  port (
    clk       : in  std_logic;                          -- clock
    rst       : in  std_logic;                          -- synchronous reset (valid flags only)
    in_valid  : in  std_logic;                          -- inputs valid
    s8        : in  unsigned(S8_W - 1 downto 0);        -- target size along this axis, Q.8 px
    log2_d    : in  unsigned(2 downto 0);               -- log2 D, 0 .. 7 (v2: 0 .. 4, D = 16 while lost)
    limit     : in  unsigned(N_W - 1 downto 0);         -- largest n (values below 3 give 3)
    out_valid : out std_logic;                          -- n valid (in_valid delayed 3 clocks)
    n         : out unsigned(N_W - 1 downto 0)          -- diameter in decimated px, 3 .. max(3, limit)
  );
end entity;

architecture rtl of ms_window_size is
  constant C    : natural := 16 + PAD16;                -- (1 + pad) in 1/16
  function bits(v : natural) return natural is
    variable r : natural := 0;
    variable x : natural := v;
  begin
    while x > 0 loop
      x := x / 2;
      r := r + 1;
    end loop;
    return r;
  end function;
  constant P_W  : natural := S8_W + bits(C);            -- (16 + PAD16) s8
  constant N0_W : natural := P_W - 11;                  -- round(p / 2**12) and larger shifts
  constant SH0  : natural := 11;                        -- sh - 1 for D = 1
  constant CMP_W : natural := maximum(N0_W, N_W);       -- n0 against limit

  -- (16 + PAD16) s8 as shift-and-add over the constant's bits
  function times_c(s : unsigned) return unsigned is
    variable acc : unsigned(P_W - 1 downto 0) := (others => '0');
  begin
    for b in 0 to bits(C) - 1 loop
      if (C / 2 ** b) mod 2 = 1 then
        acc := acc + shift_left(resize(s, P_W), b);
      end if;
    end loop;
    return acc;
  end function;

  signal v1, v2, v3 : std_logic := '0';
  signal p1         : unsigned(P_W - 1 downto 0);
  signal k1         : unsigned(2 downto 0);
  signal lim1, lim2 : unsigned(N_W - 1 downto 0);
  signal n0         : unsigned(N0_W - 1 downto 0);
  signal n_r        : unsigned(N_W - 1 downto 0);
begin
  p_size : process (clk)
    variable t : unsigned(N0_W downto 0);
  begin
    if rising_edge(clk) then
      -- stage 1: p = (16 + PAD16) s8
      p1   <= times_c(s8);
      k1   <= log2_d;
      lim1 <= limit;
      v1   <= in_valid;
      -- stage 2: t = p >> (11 + log2 D), n0 = (t + 1) >> 1 (round half up)
      t := resize(shift_right(p1, SH0 + to_integer(k1)), N0_W + 1);
      t    := t + 1;
      n0   <= t(N0_W downto 1);
      lim2 <= lim1;
      v2   <= v1;
      -- stage 3: n = max(3, min(n0, limit))
      if resize(n0, CMP_W) > resize(lim2, CMP_W) then
        if lim2 < 3 then
          n_r <= to_unsigned(3, N_W);
        else
          n_r <= lim2;
        end if;
      elsif n0 < 3 then
        n_r <= to_unsigned(3, N_W);
      else
        n_r <= resize(n0, N_W);
      end if;
      v3 <= v2;
      if rst = '1' then
        v1 <= '0';
        v2 <= '0';
        v3 <= '0';
      end if;
    end if;
  end process;
  out_valid <= v3;
  n         <= n_r;
end architecture;
