-- ms_tracker_file_tb: self-checking file-driven testbench of ms_tracker (not part of the core).
--
-- Reads the video and the init box(es) from a text file, streams them into ms_tracker as
-- AXI4-Stream (1 pixel per beat, tuser on the first pixel, tlast on each line's last pixel),
-- writes every result word to RESULTS_FILE and, when EXPECTED_FILE is not "", compares each
-- word with the expected one (written by the fixed-point model: `mstrack vectors --format
-- vhdl-files`) and fails on any mismatch.  Plain VHDL-2008 (std.textio, ieee only): runs in
-- GHDL, Questa, Riviera-PRO, xsim, ... with no Python at simulation time.
--
-- FRAMES_FILE format (mstrack.hw.tb_files, docs/packaging.md "Simulating without Python"):
-- text, one record per line, '#' lines and empty lines ignored:
--   mstrack-frames 1          magic and version (first record)
--   packing P                 the s_axis_tdata layout of the pixel words (must equal RGB_PACKING)
--   size W H                  frame_width, frame_height from now on
--   init X Y W H              an init box (integers, X and Y may be negative), given to s_init
--                             before the next frame
--   frame                     a frame: the next H lines hold W pixel words each, hexadecimal
--                             (6 digits, bus layout), separated by spaces
--   end                       end of the stimulus (optional)
-- EXPECTED_FILE / RESULTS_FILE: one result word per line, RESULT_W / 4 hexadecimal digits,
-- MSB first ('#' lines ignored in EXPECTED_FILE).  One result per frame record.
--
-- Stream conditions: PAUSE_IN_PCT % of the clocks tvalid is low (random, SEED), PAUSE_OUT_PCT %
-- of the clocks m_axis_result_tready is low.  A watchdog fails the run when nothing moves for
-- WATCHDOG clocks.  The run ends with std.env.finish (or a failure assertion).
-- Generics of the core: every ms_tracker generic, passed through (defaults: ms_formats_pkg).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use ieee.math_real.all;
use std.textio.all;
use work.ms_formats_pkg.all;

entity ms_tracker_file_tb is
  generic (
    FRAMES_FILE    : string   := "frames.txt";    -- stimulus (format above)
    EXPECTED_FILE  : string   := "expected.txt";  -- expected result words; "" = do not compare
    RESULTS_FILE   : string   := "results.txt";   -- result words written here
    PAUSE_IN_PCT   : natural  := 0;               -- % of clocks without a pixel offered
    PAUSE_OUT_PCT  : natural  := 0;               -- % of clocks the result is not taken
    SEED           : positive := 1;               -- seed of the pauses
    WATCHDOG       : positive := 10000000;        -- clocks without progress before failing
    -- ms_tracker generics (passed through)
    MAX_FRAME_W    : natural := 2048;
    RGB_PACKING    : natural := 0;
    LANES          : natural := D_LANES;
    COLOUR_BITS    : natural := D_COLOUR_BITS;
    EDGE_BINS_LOG2 : natural := D_EDGE_BINS_LOG2;
    EDGE_SHIFT     : natural := D_EDGE_SHIFT;
    FEATURES       : natural := D_FEATURES;
    KERNEL_EPAN    : natural := D_KERNEL_EPAN;
    KERNEL_BITS    : natural := D_KERNEL_BITS;
    MAX_HALF       : natural := D_MAX_HALF;
    MARGIN         : natural := D_MARGIN;
    COORD_W        : natural := D_COORD_W;
    CF             : natural := D_CF;
    WI             : natural := D_WI;
    WF             : natural := D_WF;
    RF             : natural := D_RF;
    AF             : natural := D_AF;
    RHO_OUT_FRAC   : natural := D_RHO_OUT_FRAC;
    MAX_ITER       : natural := D_MAX_ITER;
    EPS2           : natural := D_EPS2;
    HALF_W         : natural := D_HALF_W;
    REGION_MAX     : natural := D_REGION_MAX;
    REGION_W       : natural := D_REGION_W;
    STRIDE         : natural := D_STRIDE;
    ADDR_W         : natural := D_ADDR_W;
    KVAL_W         : natural := D_KVAL_W;
    HIST_W         : natural := D_HIST_W;
    COUNT_W        : natural := D_COUNT_W;
    POSSUM_W       : natural := D_POSSUM_W;
    KD_W           : natural := D_KD_W;
    SQRT_IN_W      : natural := D_SQRT_IN_W;
    RHO_SUM_W      : natural := D_RHO_SUM_W;
    RATIO_Q_W      : natural := D_RATIO_Q_W;
    WEIGHT_W       : natural := D_WEIGHT_W;
    SW_W           : natural := D_SW_W;
    SWX_W          : natural := D_SWX_W;
    SHIFT_Q_W      : natural := D_SHIFT_Q_W;
    CENTRE_W       : natural := D_CENTRE_W;
    CENTRE_ABS_W   : natural := D_CENTRE_ABS_W;
    ITER_W         : natural := D_ITER_W;
    RHO_OUT_W      : natural := D_RHO_OUT_W;
    ALPHA_W        : natural := D_ALPHA_W;
    WIN_W          : natural := D_WIN_W;
    RESULT_W       : natural := D_RESULT_W
  );
end entity;

architecture sim of ms_tracker_file_tb is
  constant CLK_PERIOD : time := 10 ns;

  signal clk           : std_logic := '0';
  signal rst           : std_logic := '1';
  signal frame_width   : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal frame_height  : unsigned(COORD_W - 1 downto 0) := (others => '0');
  signal s_init_tvalid : std_logic := '0';
  signal s_init_tready : std_logic;
  signal s_init_x      : signed(COORD_W + 1 downto 0) := (others => '0');
  signal s_init_y      : signed(COORD_W + 1 downto 0) := (others => '0');
  signal s_init_w      : unsigned(COORD_W downto 0) := (others => '0');
  signal s_init_h      : unsigned(COORD_W downto 0) := (others => '0');
  signal s_axis_tdata  : std_logic_vector(23 downto 0) := (others => '0');
  signal s_axis_tvalid : std_logic := '0';
  signal s_axis_tready : std_logic;
  signal s_axis_tlast  : std_logic := '0';
  signal s_axis_tuser  : std_logic := '0';
  signal m_tdata       : std_logic_vector(RESULT_W - 1 downto 0);
  signal m_tvalid      : std_logic;
  signal m_tready      : std_logic := '0';
  signal m_tlast       : std_logic;
  signal busy          : std_logic;

  signal frames_sent   : natural := 0;        -- frame records streamed so far
  signal stim_done     : boolean := false;    -- every record of FRAMES_FILE is streamed
  signal results       : natural := 0;        -- result words received
  signal mismatches    : natural := 0;
  signal progress      : natural := 0;        -- clock of the last beat or result (watchdog)
  signal cycle         : natural := 0;

  -- next non-comment, non-empty line of f into l (l = null at the end of the file)
  procedure next_record(file f : text; l : inout line) is
    variable c : character;
  begin
    loop
      if endfile(f) then
        deallocate(l);
        l := null;
        return;
      end if;
      readline(f, l);
      -- skip leading blanks
      while l'length > 0 and (l(l'left) = ' ' or l(l'left) = HT) loop
        read(l, c);  -- drop one blank
      end loop;
      if l'length > 0 and l(l'left) /= '#' then
        return;
      end if;
    end loop;
  end procedure;

  -- the first word of l (up to a blank), removed from l
  procedure word(l : inout line; w : out line) is
    variable s  : string(1 to 32);
    variable n  : natural;
  begin
    sread(l, s, n);
    w := new string'(s(1 to n));
  end procedure;
begin
  clk <= not clk after CLK_PERIOD / 2;
  rst <= '1', '0' after 5 * CLK_PERIOD;

  dut : entity work.ms_tracker
    generic map (
      MAX_FRAME_W => MAX_FRAME_W, RGB_PACKING => RGB_PACKING, LANES => LANES, COLOUR_BITS => COLOUR_BITS,
      EDGE_BINS_LOG2 => EDGE_BINS_LOG2, EDGE_SHIFT => EDGE_SHIFT, FEATURES => FEATURES,
      KERNEL_EPAN => KERNEL_EPAN, KERNEL_BITS => KERNEL_BITS, MAX_HALF => MAX_HALF, MARGIN => MARGIN,
      COORD_W => COORD_W, CF => CF, WI => WI, WF => WF, RF => RF, AF => AF, RHO_OUT_FRAC => RHO_OUT_FRAC,
      MAX_ITER => MAX_ITER, EPS2 => EPS2, HALF_W => HALF_W, REGION_MAX => REGION_MAX, REGION_W => REGION_W,
      STRIDE => STRIDE, ADDR_W => ADDR_W, KVAL_W => KVAL_W, HIST_W => HIST_W, COUNT_W => COUNT_W,
      POSSUM_W => POSSUM_W, KD_W => KD_W, SQRT_IN_W => SQRT_IN_W, RHO_SUM_W => RHO_SUM_W,
      RATIO_Q_W => RATIO_Q_W, WEIGHT_W => WEIGHT_W, SW_W => SW_W, SWX_W => SWX_W, SHIFT_Q_W => SHIFT_Q_W,
      CENTRE_W => CENTRE_W, CENTRE_ABS_W => CENTRE_ABS_W, ITER_W => ITER_W, RHO_OUT_W => RHO_OUT_W,
      ALPHA_W => ALPHA_W, WIN_W => WIN_W, RESULT_W => RESULT_W)
    port map (
      clk => clk, rst => rst, frame_width => frame_width, frame_height => frame_height,
      s_init_tvalid => s_init_tvalid, s_init_tready => s_init_tready, s_init_x => s_init_x,
      s_init_y => s_init_y, s_init_w => s_init_w, s_init_h => s_init_h,
      s_axis_tdata => s_axis_tdata, s_axis_tvalid => s_axis_tvalid, s_axis_tready => s_axis_tready,
      s_axis_tlast => s_axis_tlast, s_axis_tuser => s_axis_tuser,
      m_axis_result_tdata => m_tdata, m_axis_result_tvalid => m_tvalid, m_axis_result_tready => m_tready,
      m_axis_result_tlast => m_tlast, busy => busy);

  ------------------------------------------------------------------------------ stimulus
  p_stim : process
    file f         : text;
    variable st    : file_open_status;
    variable l, w  : line;
    variable ln    : natural := 0;
    variable fw, fh : integer := 0;
    variable bx, by, bw, bh : integer;
    variable pix   : std_logic_vector(23 downto 0);
    variable ok    : boolean;
    variable s1, s2 : positive := SEED;
    variable r     : real;
    variable got_magic : boolean := false;
    variable ver, pk : integer;
    variable b_sof, b_eol : std_logic;

    procedure fail(msg : string) is
    begin
      report "ms_tracker_file_tb: " & FRAMES_FILE & ": " & msg severity failure;
    end procedure;

    -- offer one beat; returns once the core has taken it
    procedure beat(data : std_logic_vector(23 downto 0); sof, eol : std_logic) is
    begin
      if PAUSE_IN_PCT > 0 then
        loop
          uniform(s1, s2, r);
          exit when r * 100.0 >= real(PAUSE_IN_PCT);
          s_axis_tvalid <= '0';
          wait until rising_edge(clk);
        end loop;
      end if;
      s_axis_tdata <= data;
      s_axis_tuser <= sof;
      s_axis_tlast <= eol;
      s_axis_tvalid <= '1';
      loop
        wait until rising_edge(clk);
        exit when s_axis_tready = '1';
      end loop;
      s_axis_tvalid <= '0';
    end procedure;
  begin
    file_open(st, f, FRAMES_FILE, read_mode);
    if st /= open_ok then
      fail("cannot open");
      wait;
    end if;
    wait until rst = '0';
    wait until rising_edge(clk);
    loop
      next_record(f, l);
      exit when l = null;
      word(l, w);
      if not got_magic then
        if w.all /= "mstrack-frames" then
          fail("not an mstrack-frames file (first record " & w.all & ")");
        end if;
        read(l, ver, ok);
        if not ok or ver /= 1 then
          fail("version " & integer'image(ver) & ", this testbench reads version 1");
        end if;
        got_magic := true;
      elsif w.all = "packing" then
        read(l, pk, ok);
        if not ok or pk /= RGB_PACKING then
          fail("pixel words in packing " & integer'image(pk) & " but RGB_PACKING = "
               & integer'image(RGB_PACKING));
        end if;
      elsif w.all = "size" then
        read(l, fw, ok);
        read(l, fh, ok);
        if not ok then fail("size W H expected"); end if;
        frame_width <= to_unsigned(fw, COORD_W);
        frame_height <= to_unsigned(fh, COORD_W);
        wait until rising_edge(clk);
      elsif w.all = "init" then
        read(l, bx, ok); read(l, by, ok); read(l, bw, ok); read(l, bh, ok);
        if not ok then fail("init X Y W H expected"); end if;
        s_init_x <= to_signed(bx, COORD_W + 2);
        s_init_y <= to_signed(by, COORD_W + 2);
        s_init_w <= to_unsigned(bw, COORD_W + 1);
        s_init_h <= to_unsigned(bh, COORD_W + 1);
        s_init_tvalid <= '1';
        loop
          wait until rising_edge(clk);
          exit when s_init_tready = '1';
        end loop;
        s_init_tvalid <= '0';
      elsif w.all = "frame" then
        for y in 0 to fh - 1 loop
          next_record(f, l);
          if l = null then fail("frame cut short at line " & integer'image(y)); end if;
          for x in 0 to fw - 1 loop
            hread(l, pix, ok);
            if not ok then
              fail("frame " & integer'image(frames_sent) & " line " & integer'image(y)
                   & ": pixel " & integer'image(x) & " unreadable");
            end if;
            b_sof := '0';
            b_eol := '0';
            if x = 0 and y = 0 then b_sof := '1'; end if;
            if x = fw - 1 then b_eol := '1'; end if;
            beat(pix, b_sof, b_eol);
          end loop;
        end loop;
        frames_sent <= frames_sent + 1;
      elsif w.all = "end" then
        exit;
      else
        fail("unknown record " & w.all);
      end if;
      deallocate(w);
    end loop;
    file_close(f);
    stim_done <= true;
    wait;
  end process;

  ------------------------------------------------------------------------------ results
  p_ready : process(clk)
    variable s1, s2 : positive := SEED + 7;
    variable r      : real;
  begin
    if rising_edge(clk) then
      uniform(s1, s2, r);
      m_tready <= '1' when r * 100.0 >= real(PAUSE_OUT_PCT) else '0';
    end if;
  end process;

  p_results : process
    file fr, fe      : text;
    variable st      : file_open_status;
    variable l, le   : line;
    variable exp     : std_logic_vector(RESULT_W - 1 downto 0);
    variable ok      : boolean;
    variable have_exp : boolean := EXPECTED_FILE'length > 0;
    variable n, bad  : natural := 0;
  begin
    file_open(st, fr, RESULTS_FILE, write_mode);
    assert st = open_ok report "ms_tracker_file_tb: cannot write " & RESULTS_FILE severity failure;
    if have_exp then
      file_open(st, fe, EXPECTED_FILE, read_mode);
      assert st = open_ok report "ms_tracker_file_tb: cannot open " & EXPECTED_FILE severity failure;
    end if;
    loop
      wait until rising_edge(clk);
      if m_tvalid = '1' and m_tready = '1' then
        hwrite(l, m_tdata);
        writeline(fr, l);
        if have_exp then
          next_record(fe, le);
          if le = null then
            report "result " & integer'image(n) & ": more results than expected words" severity error;
            bad := bad + 1;
          else
            hread(le, exp, ok);
            if not ok then
              report "result " & integer'image(n) & ": expected word unreadable" severity error;
              bad := bad + 1;
            elsif exp /= m_tdata then
              report "result " & integer'image(n) & ": got " & to_hstring(m_tdata) & ", expected "
                     & to_hstring(exp) severity error;
              bad := bad + 1;
            end if;
          end if;
        end if;
        n := n + 1;
        results <= n;
        mismatches <= bad;
      end if;
      -- all frames streamed and all their results taken: finish
      if stim_done and n = frames_sent then
        for i in 1 to 20 loop               -- no extra result may follow
          wait until rising_edge(clk);
          if m_tvalid = '1' then
            report "a result more than frames" severity error;
            bad := bad + 1;
            exit;
          end if;
        end loop;
        if have_exp then
          next_record(fe, le);
          if le /= null then
            report "fewer results than expected words" severity error;
            bad := bad + 1;
          end if;
        end if;
        file_close(fr);
        assert bad = 0
          report "ms_tracker_file_tb: FAILED: " & integer'image(bad) & " mismatch(es) in " & integer'image(n)
                 & " results" severity failure;
        if have_exp then
          report "ms_tracker_file_tb: PASSED: " & integer'image(n) & " results, all equal to " & EXPECTED_FILE
            severity note;
        else
          report "ms_tracker_file_tb: " & integer'image(n) & " results written to " & RESULTS_FILE
                 & " (not compared)" severity note;
        end if;
        std.env.finish;
        wait;
      end if;
    end loop;
  end process;

  ------------------------------------------------------------------------------ watchdog
  p_watch : process(clk)
  begin
    if rising_edge(clk) then
      cycle <= cycle + 1;
      if (s_axis_tvalid = '1' and s_axis_tready = '1') or (m_tvalid = '1' and m_tready = '1')
         or (s_init_tvalid = '1' and s_init_tready = '1') then
        progress <= cycle;
      end if;
      assert cycle - progress < WATCHDOG
        report "ms_tracker_file_tb: no beat and no result for " & integer'image(WATCHDOG) & " clocks ("
               & integer'image(frames_sent) & " frames sent, " & integer'image(results) & " results)"
        severity failure;
    end if;
  end process;
end architecture;
