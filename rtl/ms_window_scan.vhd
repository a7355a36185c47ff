-- ms_window_scan: address and offset generator of one pixel pass.
--
-- On `start` it latches the window centre (win_x, win_y, region-relative px)
-- and the half extents (ex, ey) and then emits, one beat per clock with no
-- gaps (also between rows), for each row ry = win_y - ey .. win_y + ey (top to
-- bottom, dy = ry - win_y) and each LANES-aligned group
--   g = floor((win_x - XR[|dy|]) / LANES) .. floor((win_x + XR[|dy|]) / LANES)
-- (left to right), where XR[|dy|] is the row extent of the kernel ellipse (the
-- largest |dx| inside in that row, from ms_kernel_tables through the kt_* port):
--   * out_addr = ry * STRIDE + g  (the same address for every region RAM bank:
--     region pixel (rx, ry) lives in bank rx mod LANES at ry * STRIDE + rx / LANES),
--   * out_dx   = g * LANES - win_x, the offset of lane 0 (lane l has out_dx + l),
--   * out_dy   = ry - win_y,
--   * out_mask(l) = '1' when lane l is inside the row extent, |out_dx + l| <= XR[|dy|]
--     (all lanes of the inner groups; lanes >= (win_x - XR) mod LANES of the first
--     group and lanes <= (win_x + XR) mod LANES of the last group of the row),
--   * out_last on the final beat.
-- Since TA grows with |dx| and dx = 0 is inside every row |dy| <= ey, the row
-- extent is exactly the kernel ellipse: out_mask is the model's inside test
-- TA[|dx|] + TB[|dy|] < D (ms_kernel no longer has TA/TB tables).  Groups with no
-- lane inside are not emitted: the corners of the bounding box (about 21 % of it)
-- are not read.
-- Beats = sum over dy = -ey .. ey of G(dy),
--   G(dy) = floor((win_x + XR[|dy|]) / L) - floor((win_x - XR[|dy|]) / L) + 1.
--
-- Row parameters come from a 3-stage row pipeline that runs one row ahead of the
-- beats and moves on the last beat of each row: stage A reads XR[|dy|] (registered
-- table read) and keeps the row's RAM base ry * STRIDE; stage B computes the
-- row's first address, lane-0 dx, group count and first/last group lane masks; the
-- beat registers load stage B.
-- Latency: the first beat is valid SCAN_LAT = 3 clocks after the clock edge
-- that samples start = '1' (two cycles fill the row pipeline).
-- out_addr_next: the address out_addr takes at the next edge (the D input of its register,
-- combinational): a read port with one more register in front of the RAM (a copy per memory, where
-- the memories sit) reads out_addr_next and returns the data at the same clock as from out_addr.
-- Throughput: one beat (LANES pixels) per clock; no back-pressure.
-- Handshake: `start` is a one-cycle pulse, ignored while busy = '1'.  win_y and ey
-- must be stable from the clock before start on (the first row's base
-- (win_y - ey) * STRIDE is computed from win_y - ey registered one clock ahead, so
-- that the subtraction and the multiplier are not in one clock; ms_meanshift sets
-- win_y one clock before its start pulse; a simulation assertion checks it).  The
-- caller guarantees win_x >= ex, win_y >= ey and that the window fits in the region
-- (the model asserts the same: ms_histogram raises on a window outside the region),
-- and that the XR table (written at init) is stable during a scan.
-- Model: the scan order of mstrack.fixed.blocks.ms_histogram (sums are order free).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.ms_pkg.all;

entity ms_window_scan is
  generic (
    LANES    : natural := 2;   -- pixels per clock (power of 2); more lanes = fewer beats, wider RAM
    HALF_W   : natural := 6;   -- width of ex, ey, XR (max half extent MAX_HALF < 2**HALF_W); XR table 2**HALF_W x HALF_W
    REGION_W : natural := 8;   -- width of region-relative coordinates
    STRIDE   : natural := 96;  -- RAM words per region row (ceil(REGION_MAX / LANES))
    ADDR_W   : natural := 15   -- region RAM address width
  );
  port (
    clk      : in  std_logic;                                -- clock
    rst      : in  std_logic;                                -- synchronous reset (control state)
    -- row extent table write port (from ms_kernel_tables, at init)
    kt_we    : in  std_logic;                                -- write entry kt_addr
    kt_addr  : in  unsigned(HALF_W - 1 downto 0);            -- entry i = |dy|
    kt_xr    : in  unsigned(HALF_W - 1 downto 0);            -- XR[i]: largest |dx| inside in row |dy| = i
    -- scan
    start    : in  std_logic;                                -- pulse: start a scan
    win_x    : in  unsigned(REGION_W - 1 downto 0);          -- window centre column (region-relative)
    win_y    : in  unsigned(REGION_W - 1 downto 0);          -- window centre row (region-relative)
    ex       : in  unsigned(HALF_W - 1 downto 0);            -- half extent x (window 2 ex + 1 wide)
    ey       : in  unsigned(HALF_W - 1 downto 0);            -- half extent y (window 2 ey + 1 high)
    busy     : out std_logic;                                -- scan in progress (set-up or beats)
    out_valid : out std_logic;                               -- beat valid
    out_addr : out unsigned(ADDR_W - 1 downto 0);            -- RAM word address of the beat (all banks)
    out_addr_next : out unsigned(ADDR_W - 1 downto 0);       -- out_addr of the next clock (combinational)
    out_dx   : out signed(REGION_W downto 0);                -- dx of lane 0 (lane l: out_dx + l)
    out_dy   : out signed(REGION_W downto 0);                -- dy of the beat's row
    out_mask : out std_logic_vector(LANES - 1 downto 0);     -- lane l inside the row extent (|out_dx + l| <= XR[|dy|])
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

  -- S_FILL: stage B takes row 0; S_LOAD: the beat registers take row 0
  type state_t is (S_IDLE, S_FILL, S_LOAD, S_RUN);
  signal state : state_t := S_IDLE;

  -- row extent table (LUT RAM, registered read)
  type xr_ram_t is array (0 to 2 ** HALF_W - 1) of unsigned(HALF_W - 1 downto 0);
  signal xr_ram : xr_ram_t := (others => (others => '0'));

  -- latched inputs
  signal wx           : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal ey_s         : signed(D_W - 1 downto 0) := (others => '0');
  -- row pipeline, stage A: XR of its row, RAM base of its row, |dy| of the row after it
  signal xr_a         : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal rb_a         : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal ysub         : unsigned(REGION_W - 1 downto 0) := (others => '0');  -- win_y - ey, every clock
  signal ra           : unsigned(HALF_W - 1 downto 0) := (others => '0');
  signal ra_dn        : std_logic := '0';                                     -- |dy| still falling
  -- row pipeline, stage B: first address, lane-0 dx and groups - 1 of its row
  signal addr_b       : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal dx_b         : signed(D_W - 1 downto 0) := (others => '0');
  signal ngm1_b       : unsigned(REGION_W - 1 downto 0) := (others => '0');
  signal fm_b, lm_b   : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- lanes inside in the first / last group
  -- beat registers = outputs
  signal addr         : unsigned(ADDR_W - 1 downto 0) := (others => '0');
  signal addr_next    : unsigned(ADDR_W - 1 downto 0);
  signal rem_g        : unsigned(REGION_W - 1 downto 0) := (others => '0');   -- groups left in the row after this beat
  signal dxb, dyr     : signed(D_W - 1 downto 0) := (others => '0');
  signal valid, last  : std_logic := '0';
  signal mask         : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- lanes inside in this beat
  signal lm_row       : std_logic_vector(LANES - 1 downto 0) := (others => '0');  -- lanes inside in the row's last group
begin
  assert LANES >= 1 and 2 ** SH = LANES report "ms_window_scan: LANES must be a power of 2" severity failure;

  -- win_y and ey stable since the clock before start (ysub is then win_y - ey)
  assert not (rising_edge(clk) and state = S_IDLE and start = '1' and ysub /= win_y - resize(ey, REGION_W))
    report "ms_window_scan: win_y or ey changed in the clock of start" severity failure;

  p_table : process (clk)
  begin
    if rising_edge(clk) then
      if kt_we = '1' then
        xr_ram(to_integer(kt_addr)) <= kt_xr;
      end if;
    end if;
  end process;

  p_scan : process (clk)
    variable lo, hi   : unsigned(REGION_W downto 0);
    variable g0, g1   : unsigned(REGION_W downto 0);
    variable adv      : boolean;   -- row pipeline moves: A reads the next row, B takes A
    variable ld       : boolean;   -- beat registers take stage B (first beat of a row)
    variable dy_n     : signed(D_W - 1 downto 0);
    variable rd_a     : unsigned(HALF_W - 1 downto 0);  -- the table's one read address
    variable lo_l, hi_l : natural range 0 to LANES - 1;  -- lane of the row's first / last pixel
  begin
    if rising_edge(clk) then
      ysub <= win_y - resize(ey, REGION_W);   -- the first row of a start in the next clock
      -- defaults (no don't-care values in the netlist)
      lo   := (others => '0');
      hi   := (others => '0');
      g0   := (others => '0');
      g1   := (others => '0');
      lo_l := 0;
      hi_l := 0;
      dy_n := dyr + 1;
      adv  := false;
      ld   := false;
      if state = S_IDLE then
        rd_a := ey;
      else
        rd_a := ra;
      end if;
      -- if/elsif instead of case: GHDL 2.0's Verilog output of a full enum case has no default
      if state = S_IDLE then
        valid <= '0';
        last  <= '0';
        if start = '1' then
          -- stage A takes row 0 (|dy| = ey)
          wx    <= win_x;
          ey_s  <= signed(resize(ey, D_W));
          xr_a  <= xr_ram(to_integer(rd_a));
          rb_a  <= resize(ysub * to_unsigned(STRIDE, ADDR_W), ADDR_W);
          if ey /= 0 then
            ra    <= ey - 1;
            ra_dn <= '1';
          else
            ra    <= to_unsigned(1, HALF_W);
            ra_dn <= '0';
          end if;
          state <= S_FILL;
        end if;

      elsif state = S_FILL then
        adv   := true;
        state <= S_LOAD;

      elsif state = S_LOAD then
        adv   := true;
        ld    := true;
        dy_n  := -ey_s;
        state <= S_RUN;

      else  -- S_RUN
        if last = '1' then
          valid <= '0';
          last  <= '0';
          state <= S_IDLE;
        elsif rem_g = 0 then
          adv := true;
          ld  := true;
        else
          rem_g <= rem_g - 1;
          dxb   <= dxb + LANES;
          if rem_g = 1 then
            mask <= lm_row;
          else
            mask <= (others => '1');
          end if;
          if rem_g = 1 and dyr = ey_s then
            last <= '1';
          end if;
        end if;
      end if;

      if ld then                     -- first beat of the next row
        valid <= '1';
        dxb   <= dx_b;
        dyr   <= dy_n;
        rem_g <= ngm1_b;
        if ngm1_b = 0 and dy_n = ey_s then
          last <= '1';
        else
          last <= '0';
        end if;
        if ngm1_b = 0 then
          mask <= fm_b and lm_b;
        else
          mask <= fm_b;
        end if;
        lm_row <= lm_b;
      end if;

      if adv then
        -- stage B <- stage A: groups floor((wx - XR) / L) .. floor((wx + XR) / L)
        lo := resize(wx, REGION_W + 1) - resize(xr_a, REGION_W + 1);
        hi := resize(wx, REGION_W + 1) + resize(xr_a, REGION_W + 1);
        g0 := shift_right(lo, SH);
        g1 := shift_right(hi, SH);
        ngm1_b <= resize(g1 - g0, REGION_W);
        lo_l := to_integer(lo and to_unsigned(LANES - 1, REGION_W + 1));
        hi_l := to_integer(hi and to_unsigned(LANES - 1, REGION_W + 1));
        for l in 0 to LANES - 1 loop
          if l >= lo_l then
            fm_b(l) <= '1';
          else
            fm_b(l) <= '0';
          end if;
          if l <= hi_l then
            lm_b(l) <= '1';
          else
            lm_b(l) <= '0';
          end if;
        end loop;
        dx_b   <= signed(resize(shift_left(g0, SH), D_W)) - signed(resize(wx, D_W));
        addr_b <= rb_a + resize(g0, ADDR_W);
        -- stage A <- next row: |dy| = ey, ey - 1, .., 0, 1, .., ey (reads past the last row are unused)
        xr_a <= xr_ram(to_integer(rd_a));
        rb_a <= rb_a + STRIDE;
        if ra_dn = '1' and ra /= 0 then
          ra <= ra - 1;
        else
          ra_dn <= '0';
          ra    <= ra + 1;
        end if;
      end if;

      addr <= addr_next;

      if rst = '1' then
        state <= S_IDLE;
        valid <= '0';
        last  <= '0';
      end if;
    end if;
  end process;

  -- the beat address register's next value: stage B's first address on a row's first beat (S_LOAD,
  -- or S_RUN at the end of a row), + 1 on the row's other beats, else held (p_scan's conditions)
  addr_next <= addr_b when state = S_LOAD or (state = S_RUN and last = '0' and rem_g = 0) else
               addr + 1 when state = S_RUN and last = '0' else
               addr;

  busy      <= '0' when state = S_IDLE else '1';
  out_valid <= valid;
  out_addr  <= addr;
  out_addr_next <= addr_next;
  out_dx    <= dxb;
  out_dy    <= dyr;
  out_mask  <= mask;
  out_last  <= last;
end architecture;
