-- ms_stream_pkg: error codes of ms_stream_check (err_code, with frame_error = '1').
-- Shared by ms_stream_check, ms_frontend and the top (status register).
library ieee;
use ieee.std_logic_1164.all;

package ms_stream_pkg is
  constant ERR_CODE_W     : natural := 2;
  -- eol (tlast) on a pixel with x < W-1: the line is too short
  constant ERR_SHORT_LINE : std_logic_vector(1 downto 0) := "00";
  -- pixel x = W-1 without eol: the line is too long
  constant ERR_LONG_LINE  : std_logic_vector(1 downto 0) := "01";
  -- a beat without sof while waiting for a start of frame (reported once until the next sof)
  constant ERR_NO_SOF     : std_logic_vector(1 downto 0) := "10";
  -- sof in the middle of a frame: that frame is abandoned, the sof beat starts a new frame
  constant ERR_CUT        : std_logic_vector(1 downto 0) := "11";
end package;
