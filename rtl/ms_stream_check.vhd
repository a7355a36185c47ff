-- ms_stream_check: video stream protocol checker and pixel coordinate counter.
--
-- Computes: for each input beat (PPC pixels per beat, pixel k of the beat in
-- in_data((k+1)*DATA_W-1 downto k*DATA_W), the leftmost pixel in the low bits;
-- in_sof = AXI tuser = the frame's first beat, in_eol = AXI tlast = the line's
-- last beat) the column x of its first pixel (x counts in steps of PPC) and its
-- row y against the runtime frame size (frame_width, frame_height, sampled on
-- the sof beat), and flags protocol errors:
--   ERR_SHORT_LINE  eol on a beat with x < W-PPC           -> frame abandoned
--   ERR_LONG_LINE   beat x = W-PPC without eol             -> frame abandoned
--   ERR_NO_SOF      beat without sof while waiting for a start of frame
--                   (after reset or after a good frame); reported once until
--                   the next sof, the beats are dropped
--   ERR_CUT         sof while a frame is in progress: that frame is abandoned
--                   (frame_error) AND the sof beat starts a new frame normally
--                   (frame_start in the same clock)
--   ERR_SIZE        sof while frame_width < MIN_SIZE, frame_height < MIN_SIZE,
--                   frame_width > MAX_W (MAX_W = 0: no limit) or frame_width not
--                   a multiple of PPC: no frame starts,
--                   the beats are dropped until the next sof; a frame in progress
--                   is abandoned and reported by this one code (it wins over CUT)
-- After an error the beats are dropped silently until the next sof.  The beat
-- that causes SHORT_LINE / LONG_LINE is dropped too.  A frame with an error
-- never gets frame_end.  Codes: rtl/ms_stream_pkg.vhd.  Only one code per clock:
-- if a sof beat both cuts a frame and is itself bad (eol while W > 1), the
-- SHORT_LINE code wins over CUT (the new frame is then abandoned at once).
--
-- Accepted beats leave on px_* with their (x, y); frame_end is raised with the
-- frame's last beat (x = W-PPC, y = H-1, with eol).
-- Latency: 1 clock (all outputs registered).  Throughput: 1 beat (PPC pixels)/clock; it
-- never stalls its input (no ready).  Reset: synchronous, control state only.
-- Frame size: checked on each sof against MIN_SIZE (>= 1), MAX_W and PPC (ERR_SIZE).
-- PPC in {1, 2, 4}; PPC = 1 is the one-pixel-per-beat checker (ports as before).
-- Python model: the front end of mstrack.fixed.tracker (frames are complete
-- arrays there); the coordinates are the array indices (column x, row y).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_stream_pkg.all;

entity ms_stream_check is
  generic (
    COORD_W : natural := 12;  -- width of x, y and of the frame size (frames up to 2**COORD_W - 1)
    DATA_W  : natural := 24;  -- pixel width (RGB: R 23:16, G 15:8, B 7:0)
    MIN_SIZE : positive := 1; -- smallest frame_width and frame_height accepted
    MAX_W   : natural := 0;   -- widest frame_width accepted (0: no limit)
    PPC     : positive := 1   -- pixels per beat (1, 2 or 4); frame_width must be a multiple of it
  );
  port (
    clk          : in  std_logic;                               -- clock
    rst          : in  std_logic;                               -- synchronous reset, active high
    frame_width  : in  unsigned(COORD_W - 1 downto 0);          -- W, sampled on each sof beat
    frame_height : in  unsigned(COORD_W - 1 downto 0);          -- H, sampled on each sof beat
    in_valid     : in  std_logic;                               -- beat present (no ready: never stalls)
    in_data      : in  std_logic_vector(PPC * DATA_W - 1 downto 0);  -- PPC pixels, pixel k at (k+1)*DATA_W-1 .. k*DATA_W
    in_sof       : in  std_logic;                               -- start of frame (AXI tuser)
    in_eol       : in  std_logic;                               -- end of line (AXI tlast)
    px_valid     : out std_logic;                               -- accepted beat (PPC pixels)
    px_data      : out std_logic_vector(PPC * DATA_W - 1 downto 0);  -- its data
    px_x         : out unsigned(COORD_W - 1 downto 0);          -- column of its first pixel (a multiple of PPC)
    px_y         : out unsigned(COORD_W - 1 downto 0);          -- its row
    frame_start  : out std_logic;                               -- pulse: sof accepted (with px_valid of pixel (0, 0))
    frame_end    : out std_logic;                               -- pulse: last pixel of a good frame (with its px_valid)
    frame_error  : out std_logic;                               -- pulse: protocol error, code on err_code
    err_code     : out std_logic_vector(ERR_CODE_W - 1 downto 0) -- ERR_* of ms_stream_pkg, valid with frame_error
  );
end entity;

architecture rtl of ms_stream_check is
  type state_t is (S_WAIT, S_DROP, S_FRAME);  -- S_WAIT: waiting for sof, NO_SOF armed
  signal state  : state_t := S_WAIT;
  signal x, y   : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- position of the next beat
  -- timing: the end-of-line / end-of-frame compares are kept as registered flags, updated
  -- with x and y (the next flag compares the current x with W - 2), so that no compare sits
  -- in front of the control decisions of a beat
  signal pre_x  : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- W - 2 PPC
  signal pre_y  : unsigned(COORD_W - 1 downto 0) := (others => '0');  -- H - 2
  signal x_last : std_logic := '1';  -- x = W - PPC
  signal y_last : std_logic := '1';  -- y = H - 1
  signal w_one  : std_logic := '1';  -- W = PPC (one beat per line)

  -- frame_width not a multiple of PPC (PPC a power of two: its low bits)
  function not_multiple(w : unsigned) return boolean is
  begin
    for i in 0 to 1 loop
      if 2 ** (i + 1) <= PPC and w(i) = '1' then
        return true;
      end if;
    end loop;
    return false;
  end function;
begin
  assert PPC = 1 or PPC = 2 or PPC = 4 report "ms_stream_check: PPC must be 1, 2 or 4" severity failure;

  p_check : process (clk)
    variable cx, cy     : unsigned(COORD_W - 1 downto 0);
    variable cx_last    : boolean;  -- cx = W - PPC
    variable cy_last    : boolean;  -- cy = H - 1
    variable cx_pre     : boolean;  -- cx = W - 2 PPC
    variable cy_pre     : boolean;  -- cy = H - 2
    variable w1         : std_logic;
    variable active     : boolean;  -- the beat belongs to a frame in progress
    variable size_bad   : boolean;  -- frame size out of range (sampled on sof)
  begin
    if rising_edge(clk) then
      px_valid    <= '0';
      frame_start <= '0';
      frame_end   <= '0';
      frame_error <= '0';
      px_data     <= in_data;
      if in_valid = '1' then
        active := false;
        cx := x;
        cy := y;
        cx_last := x_last = '1';
        cy_last := y_last = '1';
        cx_pre  := x = pre_x;
        cy_pre  := y = pre_y;
        w1      := w_one;
        size_bad := frame_width < MIN_SIZE or frame_height < MIN_SIZE
                    or (MAX_W > 0 and frame_width > MAX_W) or not_multiple(frame_width);
        if in_sof = '1' and size_bad then
          frame_error <= '1';
          err_code    <= ERR_SIZE;
          state       <= S_DROP;
        elsif in_sof = '1' then
          if state = S_FRAME then
            frame_error <= '1';
            err_code    <= ERR_CUT;
          end if;
          frame_start <= '1';
          pre_x  <= frame_width - 2 * PPC;
          pre_y  <= frame_height - 2;
          cx := (others => '0');
          cy := (others => '0');
          cx_last := frame_width = PPC;
          cy_last := frame_height = 1;
          cx_pre  := frame_width = 2 * PPC;
          cy_pre  := frame_height = 2;
          w1      := '1' when frame_width = PPC else '0';
          w_one   <= w1;
          active := true;
        elsif state = S_FRAME then
          active := true;
        elsif state = S_WAIT then
          frame_error <= '1';
          err_code    <= ERR_NO_SOF;
          state       <= S_DROP;
        end if;
        if active then
          if in_eol = '1' and not cx_last then
            frame_error <= '1';
            err_code    <= ERR_SHORT_LINE;
            state       <= S_DROP;
          elsif in_eol = '0' and cx_last then
            frame_error <= '1';
            err_code    <= ERR_LONG_LINE;
            state       <= S_DROP;
          else
            px_valid <= '1';
            px_x     <= cx;
            px_y     <= cy;
            state    <= S_FRAME;
            if cx_last then
              x      <= (others => '0');
              x_last <= w1;
              y      <= cy + 1;
              y_last <= '1' when cy_pre else '0';
              if cy_last then
                frame_end <= '1';
                state     <= S_WAIT;
              end if;
            else
              x      <= cx + PPC;
              x_last <= '1' when cx_pre else '0';
              y      <= cy;
              y_last <= '1' when cy_last else '0';
            end if;
          end if;
        end if;
      end if;
      if rst = '1' then
        state       <= S_WAIT;
        px_valid    <= '0';
        frame_start <= '0';
        frame_end   <= '0';
        frame_error <= '0';
      end if;
    end if;
  end process;
end architecture;
