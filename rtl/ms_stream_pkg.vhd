-- ms_stream_pkg: error codes of ms_stream_check (err_code, with frame_error = '1') and of the
-- top (ERR_SIZE_CHANGED).  Shared by ms_stream_check, ms_frontend and the top (result word).
library ieee;
use ieee.std_logic_1164.all;

package ms_stream_pkg is
  constant ERR_CODE_W     : natural := 3;
  -- eol (tlast) on a pixel with x < W-1: the line is too short
  constant ERR_SHORT_LINE : std_logic_vector(2 downto 0) := "000";
  -- pixel x = W-1 without eol: the line is too long
  constant ERR_LONG_LINE  : std_logic_vector(2 downto 0) := "001";
  -- a beat without sof while waiting for a start of frame (reported once until the next sof)
  constant ERR_NO_SOF     : std_logic_vector(2 downto 0) := "010";
  -- sof in the middle of a frame: that frame is abandoned, the sof beat starts a new frame
  constant ERR_CUT        : std_logic_vector(2 downto 0) := "011";
  -- sof with frame_width / frame_height out of range (W < MIN_SIZE, H < MIN_SIZE, W > MAX_W,
  -- or W not a multiple of the pixels per clock PPC of a PPC > 1 core):
  -- the frame is dropped (a frame in progress is abandoned too, reported by this one code)
  constant ERR_SIZE       : std_logic_vector(2 downto 0) := "100";
  -- (top only) a good frame whose size differs from the size the target was initialised for:
  -- not tracked, the state is unchanged
  constant ERR_SIZE_CHANGED : std_logic_vector(2 downto 0) := "101";
end package;
