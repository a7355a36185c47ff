-- ms_window_scan: address and offset generator of one pixel pass.
--
-- On `start` it latches the window centre (win_x, win_y, region-relative px)
-- and the half extents (ex, ey) and then emits, one beat per clock with no
-- gaps, for each row ry = win_y - ey .. win_y + ey (top to bottom) and each
-- LANES-aligned group g = floor((win_x - ex) / LANES) .. floor((win_x + ex) / LANES)
-- (left to right):
--   * out_addr = ry * STRIDE + g  (the same address for every region RAM bank:
--     region pixel (rx, ry) lives in bank rx mod LANES at ry * STRIDE + rx / LANES),
--   * out_dx   = g * LANES - win_x, the offset of lane 0 (lane l has out_dx + l),
--   * out_dy   = ry - win_y,
--   * out_last on the final beat.
-- Beats = (2 ey + 1) * (floor((win_x + ex) / L) - floor((win_x - ex) / L) + 1).
--
-- Latency: the first beat is valid SCAN_LAT = 2 clocks after the clock edge
-- that samples start = '1' (one set-up cycle computes the first address).
-- Throughput: one beat (LANES pixels) per clock; no back-pressure.
-- Handshake: `start` is a one-cycle pulse, ignored while busy = '1'.  The caller
-- guarantees win_x >= ex, win_y >= ey and that the window fits in the region
-- (the model asserts the same: ms_histogram raises on a window outside the region).
-- Model: the scan order of mstrack.fixed.blocks.ms_histogram (sums are order free).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.ms_pkg.all;

entity ms_window_scan is
  generic (
    LANES    : natural := 2;   -- pixels per clock (power of 2); more lanes = fewer beats, wider RAM
    HALF_W   : natural := 6;   -- width of ex, ey (max half extent MAX_HALF < 2**HALF_W)
    REGION_W : natural := 8;   -- width of region-relative coordinates
    STRIDE   : natural := 96;  -- RAM words per region row (ceil(REGION_MAX / LANES))
    ADDR_W   : natural := 15   -- region RAM address width
  );
  port (
    clk      : in  std_logic;                                -- clock
    rst      : in  std_logic;                                -- synchronous reset (control state)
    start    : in  std_logic;                                -- pulse: start a scan
    win_x    : in  unsigned(REGION_W - 1 downto 0);          -- window centre column (region-relative)
    win_y    : in  unsigned(REGION_W - 1 downto 0);          -- window centre row (region-relative)
    ex       : in  unsigned(HALF_W - 1 downto 0);            -- half extent x (window 2 ex + 1 wide)
    ey       : in  unsigned(HALF_W - 1 downto 0);            -- half extent y (window 2 ey + 1 high)
    busy     : out std_logic;                                -- scan in progress (set-up or beats)
    out_valid : out std_logic;                               -- beat valid
    out_addr : out unsigned(ADDR_W - 1 downto 0);            -- RAM word address of the beat (all banks)
    out_dx   : out signed(REGION_W downto 0);                -- dx of lane 0 (lane l: out_dx + l)
    out_dy   : out signed(REGION_W downto 0);                -- dy of the beat's row
    out_last : out std_logic                                 -- final beat of the scan
  );
end entity;

architecture rtl of ms_window_scan is
  constant D_W   : natural := REGION_W + 1;

  function log2_exact(n : natural) return natural is
    variable r : natural := 0;
    variable v : natural := 1;
  begin
    while v < n loop
      v := v * 2;
      r := r + 1;
    end loop;
    return r;
  end function;
  constant SH : natural := log2_exact(LANES);

  type state_t is (S_IDLE, S_SETUP, S_RUN);
  signal state : state_t := S_IDLE;

  -- latched inputs
  signal wx, wy       : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal exl, eyl     : unsigned(HALF_W - 1 downto 0) := (others => '0');
  -- per-scan constants (set-up cycle)
  signal ngrp_m1      : unsigned(REGION_W - 1 downto 0) := (others => '0');  -- groups per row - 1
  signal dx0          : signed(D_W - 1 downto 0) := (others => '0');         -- lane-0 dx of the first group
  signal ey_s         : signed(D_W - 1 downto 0) := (others => '0');
  -- running state = output registers
  signal row_addr     : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal addr         : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal gcnt         : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal dxb, dyr     : signed(D_W - 1 downto 0) := (others => '0');
  signal valid, last  : std_logic := '0';
begin
  assert LANES >= 1 and 2 ** SH = LANES report "ms_window_scan: LANES must be a power of 2" severity failure;

  p_scan : process (clk)
    variable lo, hi      : unsigned(REGION_W downto 0);
    variable g0, g1      : unsigned(REGION_W downto 0);
    variable first_row   : unsigned(REGION_W - 1 downto 0);
    variable gcnt_n      : unsigned(REGION_W - 1 downto 0);
    variable dy_n        : signed(D_W - 1 downto 0);
  begin
    if rising_edge(clk) then
      -- defaults (no don't-care values in the netlist)
      lo        := (others => '0');
      hi        := (others => '0');
      g0        := (others => '0');
      g1        := (others => '0');
      first_row := (others => '0');
      gcnt_n    := gcnt;
      dy_n      := dyr;
      -- if/elsif instead of case: GHDL 2.0's Verilog output of a full enum case has no default
      if state = S_IDLE then
        valid <= '0';
        last  <= '0';
        if start = '1' then
          wx    <= win_x;
          wy    <= win_y;
          exl   <= ex;
          eyl   <= ey;
          state <= S_SETUP;
        end if;

      elsif state = S_SETUP then
        lo := resize(wx, REGION_W + 1) - resize(exl, REGION_W + 1);
        hi := resize(wx, REGION_W + 1) + resize(exl, REGION_W + 1);
        g0 := shift_right(lo, SH);
        g1 := shift_right(hi, SH);
        first_row := wy - resize(eyl, REGION_W);
        ngrp_m1  <= resize(g1 - g0, REGION_W);
        dx0      <= signed(resize(shift_left(g0, SH), D_W)) - signed(resize(wx, D_W));
        dxb      <= signed(resize(shift_left(g0, SH), D_W)) - signed(resize(wx, D_W));
        ey_s     <= signed(resize(eyl, D_W));
        dyr      <= -signed(resize(eyl, D_W));
        row_addr <= resize(first_row * to_unsigned(STRIDE, ADDR_W) + resize(g0, ADDR_W), ADDR_W);
        addr     <= resize(first_row * to_unsigned(STRIDE, ADDR_W) + resize(g0, ADDR_W), ADDR_W);
        gcnt     <= (others => '0');
        valid    <= '1';
        -- single-beat scan is impossible (ey >= 1), but keep it exact anyway
        if g1 = g0 and eyl = 0 then
          last <= '1';
        else
          last <= '0';
        end if;
        state <= S_RUN;

      else  -- S_RUN
        if last = '1' then
          valid <= '0';
          last  <= '0';
          state <= S_IDLE;
        else
          if gcnt = ngrp_m1 then
            gcnt_n   := (others => '0');
            dy_n     := dyr + 1;
            row_addr <= row_addr + STRIDE;
            addr     <= row_addr + STRIDE;
            dxb      <= dx0;
          else
            gcnt_n   := gcnt + 1;
            dy_n     := dyr;
            addr     <= addr + 1;
            dxb      <= dxb + LANES;
          end if;
          gcnt <= gcnt_n;
          dyr  <= dy_n;
          if gcnt_n = ngrp_m1 and dy_n = ey_s then
            last <= '1';
          end if;
        end if;
      end if;
      if rst = '1' then
        state <= S_IDLE;
        valid <= '0';
        last  <= '0';
      end if;
    end if;
  end process;

  busy      <= '0' when state = S_IDLE else '1';
  out_valid <= valid;
  out_addr  <= addr;
  out_dx    <= dxb;
  out_dy    <= dyr;
  out_last  <= last;
end architecture;
