-- ms_region_v2: tracker v2's search region around a decimated centre, its margin set at run time
-- (model: mstrack.fixed.blocks_v2.ms_region_v2).
--
-- Computes, with m the margin = MARGIN, + max(ox, oy) (the search offsets) while lost, at most
-- MARGIN_MAX, per axis (c the centre Q.CF, e the window half extent, S the decimated frame size):
--   n     = min(2e + 2m + 1, S - 2)
--   start = min(max(round(c) - e - m, 1), S - 1 - n),   round(c) = (c + 2**(CF-1)) >> CF
--   hi    = n - 1 - e (the largest window centre, region-relative; the smallest is e)
-- the region being columns start .. start + n - 1 (inside the frame interior).  This is
-- mstrack.fixed.blocks.ms_region with that margin; rtl/ms_region is the same with the margin a
-- generic (the paper core), two clocks.
-- Used by ms_tracker_v2 before each frame and by ms_job_demand for each target's next job.
-- Pipeline, one carry chain per clock and axis, signed COORD_W + 3 bits:
--   1 round(c), max(ox, oy), 2e + 1, e + 1, S - 2, S - 1
--   2 round(c) - e, m
--   3 2e + 2m + 1, round(c) - e - m
--   4 n = min(2e + 2m + 1, S - 2), round(c) - e - m < 1
--   5 S - 1 - n, hi = n - (e + 1)
--   6 start = clamp, the outputs
-- Latency: 6 clocks from in_valid to out_valid.  Throughput: one input per 6 clocks (in_valid again
-- at the earliest in out_valid's clock): stage 1 holds its values, the later stages read them.
-- Handshake: valid only (no back-pressure); the inputs are sampled with in_valid; the outputs hold
-- until the next out_valid.
-- Reset: synchronous, active high; valid flags only.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_region_v2 is
  generic (
    COORD_W    : natural := 12;   -- frame coordinate bits
    CF         : natural := 8;    -- centre fraction bits
    HALF_W     : natural := 6;    -- window half extent bits
    REGION_W   : natural := 8;    -- region size bits
    MARGIN     : natural := 32;   -- search margin (decimated px)
    MARGIN_MAX : natural := 255   -- largest margin (MARGIN + the search offset)
  );
  port (
    clk       : in  std_logic;
    rst       : in  std_logic;                            -- synchronous reset (valid flags only)
    in_valid  : in  std_logic;
    cx, cy    : in  unsigned(COORD_W + CF - 1 downto 0);  -- window centre, decimated px, Q.CF
    ex, ey    : in  unsigned(HALF_W - 1 downto 0);        -- window half extents
    ox, oy    : in  unsigned(COORD_W - 1 downto 0);       -- search offsets (used while lost)
    lost      : in  std_logic;                            -- '1': margin + max(ox, oy)
    frame_w   : in  unsigned(COORD_W - 1 downto 0);       -- decimated frame width
    frame_h   : in  unsigned(COORD_W - 1 downto 0);       -- decimated frame height
    out_valid : out std_logic;                            -- in_valid delayed 6 clocks
    reg_x     : out unsigned(COORD_W - 1 downto 0);       -- region left column
    reg_y     : out unsigned(COORD_W - 1 downto 0);       -- region top row
    reg_w     : out unsigned(REGION_W - 1 downto 0);      -- region width n_x
    reg_h     : out unsigned(REGION_W - 1 downto 0);      -- region height n_y
    hi_x      : out unsigned(REGION_W - 1 downto 0);      -- largest window centre x, region-relative
    hi_y      : out unsigned(REGION_W - 1 downto 0);      -- largest window centre y, region-relative
    region_margin : out unsigned(COORD_W - 1 downto 0)    -- m
  );
end entity;

architecture rtl of ms_region_v2 is
  constant SW : natural := COORD_W + 3;
  subtype s_t is signed(SW - 1 downto 0);
  type pair_t is array (0 to 1) of s_t;
  signal v : std_logic_vector(1 to 6) := (others => '0');
  -- stage 1 holds its values until the next input; the later stages compute from them and from each
  -- other (one register per value, as the FSM states they replace in core v2 had)
  signal rc, ee, e2, ep1, s2, s1, rce, na, a0, nn, t, hi : pair_t;
  signal a0lt1 : std_logic_vector(0 to 1);
  signal mx, m : unsigned(COORD_W - 1 downto 0);
  signal lost1 : std_logic;

  function to_s(u : unsigned) return s_t is
  begin
    return signed(resize(u, SW));
  end function;
  function round_c(c : unsigned) return s_t is
  begin
    return signed(resize(shift_right(c + to_unsigned(2 ** (CF - 1), c'length), CF), SW));
  end function;
  -- start = min(max(a0, 1), t), the compare a0 < 1 registered the clock before
  function clamp(a0v, tv : s_t; lt1 : std_logic) return unsigned is
    variable a : s_t;
  begin
    if a0v > tv then
      a := tv;
      if tv < 1 then a := to_signed(1, SW); end if;
    else
      a := a0v;
      if lt1 = '1' then a := to_signed(1, SW); end if;
    end if;
    return unsigned(a(COORD_W - 1 downto 0));
  end function;
begin
  assert MARGIN_MAX >= MARGIN and MARGIN_MAX < 2 ** COORD_W
    report "ms_region_v2: need MARGIN <= MARGIN_MAX < 2**COORD_W" severity failure;

  p_region : process (clk)
    variable c, e, s : pair_t;
  begin
    if rising_edge(clk) then
      v <= in_valid & v(1 to 5);
      -- 1: round(c), max(ox, oy), the terms without the margin
      c(0) := round_c(cx);  c(1) := round_c(cy);
      e(0) := to_s(ex);     e(1) := to_s(ey);
      s(0) := to_s(frame_w); s(1) := to_s(frame_h);
      if in_valid = '1' then                  -- held until the next input: stages 2 .. 6 read them
        for i in 0 to 1 loop
          rc(i)  <= c(i);
          ee(i)  <= e(i);
          e2(i)  <= shift_left(e(i), 1) + 1;
          ep1(i) <= e(i) + 1;
          s2(i)  <= s(i) - 2;
          s1(i)  <= s(i) - 1;
        end loop;
        if ox >= oy then mx <= ox; else mx <= oy; end if;
        lost1 <= lost;
      end if;
      -- 2: round(c) - e, the margin
      for i in 0 to 1 loop
        rce(i) <= rc(i) - ee(i);
      end loop;
      if lost1 = '1' then
        if resize(mx, COORD_W + 1) + MARGIN > MARGIN_MAX then
          m <= to_unsigned(MARGIN_MAX, COORD_W);
        else
          m <= mx + MARGIN;
        end if;
      else
        m <= to_unsigned(MARGIN, COORD_W);
      end if;
      -- 3: 2e + 2m + 1, round(c) - e - m
      for i in 0 to 1 loop
        na(i) <= e2(i) + shift_left(to_s(m), 1);
        a0(i) <= rce(i) - to_s(m);
      end loop;
      -- 4: n = min(2e + 2m + 1, S - 2), a0 < 1
      for i in 0 to 1 loop
        if na(i) < s2(i) then nn(i) <= na(i); else nn(i) <= s2(i); end if;
        if a0(i) < 1 then a0lt1(i) <= '1'; else a0lt1(i) <= '0'; end if;
      end loop;
      -- 5: S - 1 - n, hi = n - (e + 1)
      for i in 0 to 1 loop
        t(i)  <= s1(i) - nn(i);
        hi(i) <= nn(i) - ep1(i);
      end loop;
      -- 6: start = clamp(a0, 1, S - 1 - n), registered outputs
      if v(5) = '1' then
        reg_x  <= clamp(a0(0), t(0), a0lt1(0));
        reg_y  <= clamp(a0(1), t(1), a0lt1(1));
        reg_w  <= resize(unsigned(nn(0)(COORD_W - 1 downto 0)), REGION_W);
        reg_h  <= resize(unsigned(nn(1)(COORD_W - 1 downto 0)), REGION_W);
        hi_x   <= resize(unsigned(hi(0)(COORD_W - 1 downto 0)), REGION_W);
        hi_y   <= resize(unsigned(hi(1)(COORD_W - 1 downto 0)), REGION_W);
        region_margin <= m;
      end if;
      if rst = '1' then
        v <= (others => '0');
      end if;
    end if;
  end process;
  out_valid <= v(6);
end architecture;
