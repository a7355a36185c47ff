-- ms_ram_sdp, architecture ecp5: the RAM as Lattice ECP5 DP16KD primitives with their output register.
--
-- Same entity, ports and rdata sequence as the `inferred` architecture (rtl/ms_ram_sdp.vhd); this
-- file is analysed after it only for ECP5 synthesis (mstrack.synth), which makes `ecp5` the
-- entity's default architecture there; simulation never sees it.
-- Tiling: mode width WM = the narrowest DP16KD width in (1, 2, 4, 9, 18) >= DATA_W (18 above), so
-- a block holds BW = 16384 / WM words (1024 for x18); NCOL = ceil(DATA_W / WM) blocks side by side,
-- NROW = ceil(DEPTH / BW) rows.  Port A writes, port B reads (WEB = 0).
-- Read pipeline (edge s samples raddr): s: DP16KD address register (CEB = raddr < DEPTH, so the
-- read latch holds on reads >= DEPTH, as in `inferred`; CEB = 1 with two multiplexer levels, whose
-- output register alone holds); s + 1: DP16KD output register
-- (REGMODE_B = "OUTREG": clock-to-out ~1 ns instead of ~5.8 ns).  One row (NROW = 1): that is
-- rdata, RD_LAT = 2.  Several rows: s + 2: row multiplexer (the row of raddr one-hot at s + 1, an
-- AND-OR of the output registers; the in-range flag delayed two clocks) -> output register, loaded
-- only for reads < DEPTH; RD_LAT >= 3.  More than 4 rows and RD_LAT >= 4 (core v2's 25 rows per
-- bank): the multiplexer in two registered levels, s + 2: NGRP groups of GRP consecutive rows (AND-OR
-- per group: 0 in the groups without the read's row) -> s + 3: OR of the groups -> output register
-- (loaded only for reads < DEPTH): MUX_LAT = 4.  RD_LAT - MUX_LAT more plain registers.
-- RD_LAT = 1, or 2 with several rows: the inferred RAM of rtl/ms_ram_sdp.vhd (yosys maps it,
-- without the output register).
-- Write port: the row decode (and, WR_LAT = 1, a register after it: WEA, address and data from
-- flip-flops).  Write/read of the same word at the same edge: undefined (DP16KD port collision).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

architecture ecp5 of ms_ram_sdp is
  component DP16KD is
    generic (
      DATA_WIDTH_A        : integer := 18;
      DATA_WIDTH_B        : integer := 18;
      REGMODE_A           : string  := "NOREG";
      REGMODE_B           : string  := "NOREG";
      RESETMODE           : string  := "SYNC";
      ASYNC_RESET_RELEASE : string  := "SYNC";
      CSDECODE_A          : string  := "0b000";
      CSDECODE_B          : string  := "0b000";
      WRITEMODE_A         : string  := "NORMAL";
      WRITEMODE_B         : string  := "NORMAL";
      GSR                 : string  := "ENABLED"
    );
    port (
      DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9,
      DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0 : in std_logic;
      ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4,
      ADA3, ADA2, ADA1, ADA0 : in std_logic;
      CEA, OCEA, CLKA, WEA, RSTA, CSA2, CSA1, CSA0 : in std_logic;
      DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9,
      DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0 : out std_logic;
      DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9,
      DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0 : in std_logic;
      ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4,
      ADB3, ADB2, ADB1, ADB0 : in std_logic;
      CEB, OCEB, CLKB, WEB, RSTB, CSB2, CSB1, CSB0 : in std_logic;
      DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9,
      DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0 : out std_logic
    );
  end component;

  -- a < DEPTH, with DEPTH = 2**ADDR_W allowed (GHDL 2.0 --synth truncates a natural that does not
  -- fit the unsigned's width: `a < 2**ADDR_W` became `a < 0`, always false)
  function in_range(a : unsigned) return boolean is
  begin
    return resize(a, ADDR_W + 1) < DEPTH;
  end function;

  function mode_width(w : positive) return positive is
  begin
    if w <= 1 then return 1;
    elsif w <= 2 then return 2;
    elsif w <= 4 then return 4;
    elsif w <= 9 then return 9;
    else return 18;
    end if;
  end function;

  function block_abits(wm : positive) return positive is
  begin
    case wm is
      when 1 => return 14;
      when 2 => return 13;
      when 4 => return 12;
      when 9 => return 11;
      when others => return 10;
    end case;
  end function;

  constant WM    : positive := mode_width(DATA_W);
  constant ABITS : positive := block_abits(WM);
  constant BW    : positive := 2 ** ABITS;                  -- words per block
  constant NCOL  : positive := (DATA_W + WM - 1) / WM;
  constant NROW  : positive := (DEPTH + BW - 1) / BW;
  constant LO    : natural  := 14 - ABITS;                  -- DP16KD address pins below the word address

  type rows_t is array (0 to NROW - 1) of std_logic_vector(NCOL * WM - 1 downto 0);
  type sel_t is array (1 to 2) of natural range 0 to NROW - 1;
  -- two registered multiplexer levels (groups of rows, then the groups) when the latency allows it
  constant TWO_LEVEL : boolean := NROW > 4 and RD_LAT >= 4;
  function isqrt_ceil(n : positive) return positive is
    variable g : positive := 1;
  begin
    while g * g < n loop
      g := g + 1;
    end loop;
    return g;
  end function;
  constant GRP     : positive := isqrt_ceil(NROW);              -- rows per group (two levels)
  constant NGRP    : positive := (NROW + GRP - 1) / GRP;        -- groups
  function grp_last(g : natural) return natural is              -- last row of group g
  begin
    if g * GRP + GRP - 1 < NROW then
      return g * GRP + GRP - 1;
    end if;
    return NROW - 1;
  end function;
  -- DP16KD path: 2 (one row), 3 (one multiplexer level) or 4 clocks (two levels)
  constant MUX_LAT : positive := 2 + boolean'pos(NROW > 1) + boolean'pos(TWO_LEVEL);
  constant USE_BRAM : boolean := RD_LAT >= MUX_LAT;

  -- word address inside a block, as the DP16KD pins AD13..AD0 (x18: AD1..AD0 = byte enables = 1)
  function ad_pins(a : unsigned) return std_logic_vector is
    variable v : std_logic_vector(13 downto 0) := (others => '0');
  begin
    v(13 downto LO) := std_logic_vector(resize(a mod BW, ABITS));
    if WM = 18 then
      v(1 downto 0) := "11";
    end if;
    return v;
  end function;

  function row_of(a : unsigned) return natural is
  begin
    if NROW = 1 or not in_range(a) then
      return 0;
    end if;
    return to_integer(a / BW);
  end function;
  type row_we_t is array (0 to NROW - 1) of std_logic;
begin
  assert 2 ** ADDR_W >= DEPTH report "ms_ram_sdp: ADDR_W too small for DEPTH" severity failure;
  assert WR_LAT <= 1 report "ms_ram_sdp: WR_LAT must be 0 or 1" severity failure;

  g_inferred : if not USE_BRAM generate
    type ram_t is array (0 to DEPTH - 1) of std_logic_vector(DATA_W - 1 downto 0);
    type lat_t is array (1 to RD_LAT) of std_logic_vector(DATA_W - 1 downto 0);
    signal ram  : ram_t := (others => (others => '0'));
    signal lat  : lat_t := (others => (others => '0'));
    signal w_en   : std_logic := '0';
    signal w_addr : unsigned(ADDR_W - 1 downto 0) := (others => '0');
    signal w_data : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
  begin
    g_wr0 : if WR_LAT = 0 generate
      w_en <= we; w_addr <= waddr; w_data <= wdata;
    end generate;
    g_wr1 : if WR_LAT = 1 generate
      p_wr : process (clk)
      begin
        if rising_edge(clk) then
          w_en <= we; w_addr <= waddr; w_data <= wdata;
        end if;
      end process;
    end generate;

    p_ram : process (clk)
    begin
      if rising_edge(clk) then
        if in_range(raddr) then
          lat(1) <= ram(to_integer(raddr));
        end if;
        for i in 2 to RD_LAT loop
          lat(i) <= lat(i - 1);
        end loop;
        if w_en = '1' and in_range(w_addr) then
          ram(to_integer(w_addr)) <= w_data;
        end if;
      end if;
    end process;
    rdata <= lat(RD_LAT);
  end generate;

  g_dp16kd : if USE_BRAM generate
    signal ada, adb : std_logic_vector(13 downto 0);
    signal wrow     : natural range 0 to NROW - 1;
    signal wr_ok    : std_logic;
    signal row_we   : row_we_t;                                -- write enable per row (decoded)
    signal ada_w    : std_logic_vector(13 downto 0) := (others => '0');          -- port A after WR_LAT
    signal wdata_w  : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
    signal row_we_w : row_we_t := (others => '0');
    signal rd_ok    : std_logic;
    signal ceb      : std_logic;                               -- DP16KD read clock enable
    signal dout     : rows_t;
    signal head     : std_logic_vector(DATA_W - 1 downto 0);  -- the read data after MUX_LAT clocks
  begin
    ada   <= ad_pins(waddr);
    adb   <= ad_pins(raddr);
    wrow  <= row_of(waddr);
    wr_ok <= we when in_range(waddr) else '0';
    g_row_we : for r in 0 to NROW - 1 generate
      row_we(r) <= wr_ok when wrow = r else '0';
    end generate;

    -- WR_LAT = 1: the decoded write port from flip-flops (no compare or decode before WEA)
    g_wr0 : if WR_LAT = 0 generate
      ada_w <= ada; wdata_w <= wdata; row_we_w <= row_we;
    end generate;
    g_wr1 : if WR_LAT = 1 generate
      p_wr : process (clk)
      begin
        if rising_edge(clk) then
          ada_w <= ada; wdata_w <= wdata; row_we_w <= row_we;
        end if;
      end process;
    end generate;
    rd_ok <= '1' when in_range(raddr) else '0';
    -- two levels: the output register alone holds on reads >= DEPTH (loaded only for reads < DEPTH),
    -- so the DP16KD read every clock (timing: the compare raddr < DEPTH fed the CEB of a whole bank,
    -- core v2's path after the two levels)
    ceb <= '1' when TWO_LEVEL else rd_ok;

    g_row : for r in 0 to NROW - 1 generate
      g_col : for c in 0 to NCOL - 1 generate
        signal dia, dib, doa, dob : std_logic_vector(17 downto 0);
        signal wea                : std_logic;
      begin
        p_dia : process (wdata_w)
        begin
          dia <= (others => '0');
          for i in 0 to WM - 1 loop
            if c * WM + i < DATA_W then
              dia(i) <= wdata_w(c * WM + i);
            end if;
          end loop;
        end process;
        dib <= (others => '0');
        wea <= row_we_w(r);

        u_bram : DP16KD
          generic map (
            DATA_WIDTH_A => WM, DATA_WIDTH_B => WM, REGMODE_A => "NOREG", REGMODE_B => "OUTREG",
            RESETMODE => "SYNC", ASYNC_RESET_RELEASE => "SYNC", CSDECODE_A => "0b000",
            CSDECODE_B => "0b000", WRITEMODE_A => "NORMAL", WRITEMODE_B => "NORMAL", GSR => "DISABLED")
          port map (
            CEA => '1', OCEA => '1', CLKA => clk, WEA => wea, RSTA => '0', CSA2 => '0', CSA1 => '0', CSA0 => '0',
            CEB => ceb, OCEB => '1', CLKB => clk, WEB => '0', RSTB => '0', CSB2 => '0', CSB1 => '0', CSB0 => '0',
          DIA0 => dia(0), DIA1 => dia(1), DIA2 => dia(2), DIA3 => dia(3), DIA4 => dia(4), DIA5 =>
          dia(5), DIA6 => dia(6), DIA7 => dia(7), DIA8 => dia(8), DIA9 => dia(9), DIA10 => dia(10),
          DIA11 => dia(11), DIA12 => dia(12), DIA13 => dia(13), DIA14 => dia(14), DIA15 => dia(15),
          DIA16 => dia(16), DIA17 => dia(17),
          ADA0 => ada_w(0), ADA1 => ada_w(1), ADA2 => ada_w(2), ADA3 => ada_w(3), ADA4 => ada_w(4), ADA5 =>
          ada_w(5), ADA6 => ada_w(6), ADA7 => ada_w(7), ADA8 => ada_w(8), ADA9 => ada_w(9), ADA10 => ada_w(10),
          ADA11 => ada_w(11), ADA12 => ada_w(12), ADA13 => ada_w(13),
          DOA0 => doa(0), DOA1 => doa(1), DOA2 => doa(2), DOA3 => doa(3), DOA4 => doa(4), DOA5 =>
          doa(5), DOA6 => doa(6), DOA7 => doa(7), DOA8 => doa(8), DOA9 => doa(9), DOA10 => doa(10),
          DOA11 => doa(11), DOA12 => doa(12), DOA13 => doa(13), DOA14 => doa(14), DOA15 => doa(15),
          DOA16 => doa(16), DOA17 => doa(17),
          DIB0 => dib(0), DIB1 => dib(1), DIB2 => dib(2), DIB3 => dib(3), DIB4 => dib(4), DIB5 =>
          dib(5), DIB6 => dib(6), DIB7 => dib(7), DIB8 => dib(8), DIB9 => dib(9), DIB10 => dib(10),
          DIB11 => dib(11), DIB12 => dib(12), DIB13 => dib(13), DIB14 => dib(14), DIB15 => dib(15),
          DIB16 => dib(16), DIB17 => dib(17),
          ADB0 => adb(0), ADB1 => adb(1), ADB2 => adb(2), ADB3 => adb(3), ADB4 => adb(4), ADB5 =>
          adb(5), ADB6 => adb(6), ADB7 => adb(7), ADB8 => adb(8), ADB9 => adb(9), ADB10 => adb(10),
          ADB11 => adb(11), ADB12 => adb(12), ADB13 => adb(13),
          DOB0 => dob(0), DOB1 => dob(1), DOB2 => dob(2), DOB3 => dob(3), DOB4 => dob(4), DOB5 =>
          dob(5), DOB6 => dob(6), DOB7 => dob(7), DOB8 => dob(8), DOB9 => dob(9), DOB10 => dob(10),
          DOB11 => dob(11), DOB12 => dob(12), DOB13 => dob(13), DOB14 => dob(14), DOB15 => dob(15),
          DOB16 => dob(16), DOB17 => dob(17));

        dout(r)((c + 1) * WM - 1 downto c * WM) <= dob(WM - 1 downto 0);
      end generate;
    end generate;

    -- one row: the DP16KD output register is the data after 2 clocks
    g_one : if NROW = 1 generate
      head <= dout(0)(DATA_W - 1 downto 0);
    end generate;

    -- several rows: the row multiplexer behind the output registers, then a register
    g_mux : if NROW > 1 and not TWO_LEVEL generate
      signal sel  : sel_t := (others => 0);
      signal inr  : std_logic_vector(1 to 2) := (others => '0');
      signal mux_q : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
      signal hot   : std_logic_vector(0 to NROW - 1) := (others => '0');  -- the row, one-hot
    begin
      -- (timing: the row is decoded one-hot a clock ahead, so the multiplexer is an AND-OR of
      -- the output registers, no row compare in it: core v2's 25 rows per bank were its
      -- critical path, the decode of a binary row index spread over the bank's DP16KD)
      p_mux : process (clk)
        variable acc : std_logic_vector(DATA_W - 1 downto 0);
      begin
        if rising_edge(clk) then
          sel(1) <= row_of(raddr);     -- edge s: the read's row ...
          for r in 0 to NROW - 1 loop  -- ... edge s + 1, one-hot, beside the DP16KD output register
            if sel(1) = r then
              hot(r) <= '1';
            else
              hot(r) <= '0';
            end if;
          end loop;
          inr(1) <= rd_ok;
          inr(2) <= inr(1);
          if inr(2) = '1' then         -- edge s + 2: the output registers hold the read of edge s
            acc := (others => '0');
            for r in 0 to NROW - 1 loop
              acc := acc or (dout(r)(DATA_W - 1 downto 0) and (DATA_W - 1 downto 0 => hot(r)));
            end loop;
            mux_q <= acc;
          end if;
        end if;
      end process;
      head <= mux_q;
    end generate;

    -- many rows, RD_LAT >= 4: the one-hot AND-OR in two registered levels (timing: core v2's
    -- 25-row AND-OR in one clock was its critical path, 4 LUT levels and ~10 ns of routing between
    -- DP16KD spread over the device)
    g_mux2 : if TWO_LEVEL generate
      type grp_t is array (0 to NGRP - 1) of std_logic_vector(DATA_W - 1 downto 0);
      signal sel   : natural range 0 to NROW - 1 := 0;
      signal inr   : std_logic_vector(1 to 3) := (others => '0');
      signal hot   : std_logic_vector(0 to NROW - 1) := (others => '0');  -- the row, one-hot
      signal grp_q : grp_t := (others => (others => '0'));                -- per group: its rows' AND-OR
      signal mux_q : std_logic_vector(DATA_W - 1 downto 0) := (others => '0');
    begin
      p_mux : process (clk)
        variable acc : std_logic_vector(DATA_W - 1 downto 0);
      begin
        if rising_edge(clk) then
          sel <= row_of(raddr);        -- edge s: the read's row ...
          for r in 0 to NROW - 1 loop  -- ... edge s + 1, one-hot, beside the DP16KD output register
            if sel = r then
              hot(r) <= '1';
            else
              hot(r) <= '0';
            end if;
          end loop;
          inr <= rd_ok & inr(1 to 2);
          for g in 0 to NGRP - 1 loop  -- edge s + 2: each group's AND-OR (0 unless it holds the row)
            acc := (others => '0');
            for r in g * GRP to grp_last(g) loop
              acc := acc or (dout(r)(DATA_W - 1 downto 0) and (DATA_W - 1 downto 0 => hot(r)));
            end loop;
            grp_q(g) <= acc;
          end loop;
          if inr(3) = '1' then         -- edge s + 3: OR of the groups, only for reads < DEPTH
            acc := (others => '0');
            for g in 0 to NGRP - 1 loop
              acc := acc or grp_q(g);
            end loop;
            mux_q <= acc;
          end if;
        end if;
      end process;
      head <= mux_q;
    end generate;

    g_lat : if RD_LAT = MUX_LAT generate
      rdata <= head;
    end generate;

    g_ext : if RD_LAT > MUX_LAT generate
      type ext_t is array (1 to RD_LAT - MUX_LAT) of std_logic_vector(DATA_W - 1 downto 0);
      signal ext : ext_t := (others => (others => '0'));
    begin
      p_ext : process (clk)
      begin
        if rising_edge(clk) then
          ext(1) <= head;
          for i in 2 to RD_LAT - MUX_LAT loop
            ext(i) <= ext(i - 1);
          end loop;
        end if;
      end process;
      rdata <= ext(RD_LAT - MUX_LAT);
    end generate;
  end generate;
end architecture;
