-- flow_example: toy design used to prove the HDL simulation / synthesis flow
-- (mstrack/hw/hdl.py, tb/test_flow_example.py, docs/hdl_flow.md). Not part of the
-- tracker core.
--
-- Video in on an AXI4-Stream-style port, one pixel per beat:
--   s_axis_tuser = start of frame (first pixel of a frame)
--   s_axis_tlast = end of line (last pixel of each line)
-- For every line it emits one beat on m_axis:
--   m_axis_tdata = sum over the line of pixel(x, y) * pixel(x, y-1) + BIAS
--                  (the line above is 0 for the first line of a frame)
--   m_axis_tuser = '1' for the first line of a frame
--   m_axis_tlast = '1' (each result is a one-beat packet)
-- The previous line is held in an inferred block RAM (registered read,
-- read-before-write on the same address) and the product uses a WIDTH x WIDTH
-- multiplier, so RAM and DSP inference are exercised by synthesis.  The RAM
-- output is registered once more (OUTREG) so that ECP5 reaches ~150 MHz.
--
-- Flow control: one global clock enable.  The pipeline stalls when the output
-- register holds a beat that is not accepted; s_axis_tready = that enable.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity flow_example is
  generic (
    WIDTH     : natural := 8;     -- pixel width
    COLS_LOG2 : natural := 10;    -- line buffer depth = 2**COLS_LOG2 pixels
    BIAS      : natural := 0;     -- added to every line sum
    USE_ABOVE : boolean := true   -- false: sum of pixel**2 instead
  );
  port (
    clk           : in  std_logic;
    rst           : in  std_logic;  -- synchronous, active high

    s_axis_tdata  : in  std_logic_vector(WIDTH - 1 downto 0);
    s_axis_tvalid : in  std_logic;
    s_axis_tready : out std_logic;
    s_axis_tlast  : in  std_logic;
    s_axis_tuser  : in  std_logic;

    m_axis_tdata  : out std_logic_vector(2 * WIDTH + COLS_LOG2 - 1 downto 0);
    m_axis_tvalid : out std_logic;
    m_axis_tready : in  std_logic;
    m_axis_tlast  : out std_logic;
    m_axis_tuser  : out std_logic
  );
end entity;

architecture rtl of flow_example is
  constant SUM_W : natural := 2 * WIDTH + COLS_LOG2;

  type ram_t is array (0 to 2 ** COLS_LOG2 - 1) of std_logic_vector(WIDTH - 1 downto 0);
  signal ram : ram_t;

  signal ce       : std_logic;
  signal col      : unsigned(COLS_LOG2 - 1 downto 0) := (others => '0');
  signal in_first : std_logic := '0';  -- current line is the first of a frame

  -- stage 1: RAM read data valid
  signal v1, last1, first1 : std_logic := '0';
  signal pix1              : unsigned(WIDTH - 1 downto 0);
  signal above1            : std_logic_vector(WIDTH - 1 downto 0);
  -- stage 1r: RAM output register (DP16KD OUTREG / RAMB DOB_REG) for Fmax
  signal v1r, last1r, first1r : std_logic := '0';
  signal pix1r                : unsigned(WIDTH - 1 downto 0);
  signal above1r              : std_logic_vector(WIDTH - 1 downto 0);
  -- stage 2: product
  signal v2, last2, first2 : std_logic := '0';
  signal prod2             : unsigned(2 * WIDTH - 1 downto 0);
  -- stage 3: accumulate
  signal acc               : unsigned(SUM_W - 1 downto 0) := (others => '0');
  signal out_valid         : std_logic := '0';
  signal out_data          : unsigned(SUM_W - 1 downto 0) := (others => '0');
  signal out_first         : std_logic := '0';
begin
  ce            <= not (out_valid and not m_axis_tready);
  s_axis_tready <= ce;

  -- line buffer: write the incoming pixel, read what was there (line above)
  ram_p : process (clk)
  begin
    if rising_edge(clk) then
      if ce = '1' then
        if s_axis_tvalid = '1' then
          ram(to_integer(col)) <= s_axis_tdata;
        end if;
        above1  <= ram(to_integer(col));
        above1r <= above1;
      end if;
    end if;
  end process;

  pipe_p : process (clk)
    variable first_v : std_logic;
    variable above_v : unsigned(WIDTH - 1 downto 0);
    variable sel_v   : std_logic_vector(1 downto 0);
  begin
    if rising_edge(clk) then
      if rst = '1' then
        col       <= (others => '0');
        in_first  <= '0';
        v1        <= '0';
        v1r       <= '0';
        v2        <= '0';
        acc       <= (others => '0');
        out_valid <= '0';
      elsif ce = '1' then
        -- stage 0: accept a pixel
        v1 <= s_axis_tvalid;
        if s_axis_tvalid = '1' then
          first_v := s_axis_tuser or in_first;
          pix1    <= unsigned(s_axis_tdata);
          last1   <= s_axis_tlast;
          first1  <= first_v;
          if s_axis_tlast = '1' then
            col      <= (others => '0');
            in_first <= '0';
          else
            col      <= col + 1;
            in_first <= first_v;
          end if;
        end if;

        -- stage 1 -> 1r: wait for the registered RAM output
        v1r     <= v1;
        last1r  <= last1;
        first1r <= first1;
        pix1r   <= pix1;

        -- stage 1r -> 2: multiply by the pixel above (0 on the first line)
        v2     <= v1r;
        last2  <= last1r;
        first2 <= first1r;
        -- (a `case` with `others` on purpose: GHDL 2.0 drops the others branch
        -- in its Verilog output, mstrack.hw.hdl.fix_ghdl_pmux repairs it; the
        -- USE_ABOVE=false co-simulation checks that)
        sel_v := '0' & first1r;
        if USE_ABOVE then
          sel_v(1) := '1';
        end if;
        case sel_v is
          when "10"   => above_v := unsigned(above1r);
          when "11"   => above_v := (others => '0');
          when others => above_v := pix1r;
        end case;
        prod2 <= pix1r * above_v;

        -- stage 2 -> 3: accumulate, emit on end of line
        out_valid <= '0';
        if v2 = '1' then
          if last2 = '1' then
            out_data  <= acc + prod2 + to_unsigned(BIAS, SUM_W);
            out_first <= first2;
            out_valid <= '1';
            acc       <= (others => '0');
          else
            acc <= acc + prod2;
          end if;
        end if;
      end if;
    end if;
  end process;

  m_axis_tdata  <= std_logic_vector(out_data);
  m_axis_tvalid <= out_valid;
  m_axis_tlast  <= '1';
  m_axis_tuser  <= out_first;
end architecture;
