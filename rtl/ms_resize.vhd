-- ms_resize: new box size of one axis, s8' = clamp((s8 s) >> 16, 3 2**8, frame_size 2**8) (Q.8 px).
--
-- s8 (Q.8 px) times the scale factor s (Q.16, ms_scale) by shift-and-add, one bit of s per clock,
-- MSB first (acc = 2 acc + bit s8: no multiplier block), then >> 16 (floor) and the clamp
-- min(max(p, 3 2**8), frame_size 2**8) (as the model: a frame_size below 3 gives frame_size 2**8),
-- as two compares side by side and a select (max then min in series: 119 MHz alone on ECP5).
-- Per frame the tracker resizes w8 (frame width) and h8 (frame height): two instances, or one used
-- twice.
-- Model: mstrack.fixed.blocks_v2.ms_resize(s8, s, frame_size), bit for bit, for any s8 < 2**SIZE_W,
-- s < 2**SCALE_W (the result is clamped to frame_size 2**8 < 2**SIZE_W).
--
-- Latency    : RESIZE_LAT = SCALE_W + 2 clocks (19 with the defaults): if edge e samples start = 1
--              (busy = 0), edge e + RESIZE_LAT samples done = 1 (asserted by tb/test_ms_resize.py).
-- Throughput : one size per RESIZE_LAT clocks (busy is low in the done cycle: back to back).
-- Handshake  : start pulse, ignored while busy = 1; done is a one-clock pulse; s8_out is registered and
--              held until the next done.
-- Cost       : one SIZE_W + SCALE_W bit adder, two comparators, ~2 SIZE_W + SCALE_W + COORD_W
--              flip-flops.
-- Reset      : synchronous, active high: control state.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_resize is
  generic (
    SIZE_W  : natural := 20;   -- s8 bits (COORD_W + 8)
    SCALE_W : natural := 17;   -- s bits (Q.16)
    COORD_W : natural := 12    -- frame_size bits
  );
  port (
    clk        : in  std_logic;                          -- clock
    rst        : in  std_logic;                          -- synchronous reset
    start      : in  std_logic;                          -- pulse: inputs valid (while busy = 0)
    s8         : in  unsigned(SIZE_W - 1 downto 0);      -- size now, Q.8 px
    s          : in  unsigned(SCALE_W - 1 downto 0);     -- scale factor, Q.16
    frame_size : in  unsigned(COORD_W - 1 downto 0);     -- frame width (for w8) or height (for h8), px
    busy       : out std_logic;                          -- computing
    done       : out std_logic;                          -- pulse: s8_out valid
    s8_out     : out unsigned(SIZE_W - 1 downto 0)       -- new size, Q.8 px
  );
end entity;

architecture rtl of ms_resize is
  constant P_W  : natural := SIZE_W + SCALE_W;           -- s8 s
  constant MIN8 : natural := 3 * 2 ** 8;

  signal busy_r, done_r : std_logic := '0';
  signal clamp_r        : std_logic := '0';
  signal a_r            : unsigned(SIZE_W - 1 downto 0);
  signal m_r            : unsigned(SCALE_W - 1 downto 0);  -- multiplier bits, MSB first
  signal hi_r           : unsigned(P_W - 17 downto 0);     -- frame_size 2**8
  signal small_r        : std_logic;                       -- frame_size < 3: the result is hi_r
  signal p_r            : unsigned(P_W - 1 downto 0);
  signal cnt            : natural range 0 to SCALE_W - 1;
  signal out_r          : unsigned(SIZE_W - 1 downto 0) := (others => '0');
begin
  assert SIZE_W >= COORD_W + 8 and SIZE_W + SCALE_W >= 26
    report "ms_resize: SIZE_W must hold frame_size 2**8, (s8 s) >> 16 must hold 3 2**8" severity failure;

  p_main : process (clk)
    variable q  : unsigned(P_W - 17 downto 0);
  begin
    if rising_edge(clk) then
      done_r  <= '0';
      clamp_r <= '0';
      if busy_r = '0' then
        if start = '1' then
          a_r    <= s8;
          m_r    <= s;
          hi_r   <= shift_left(resize(frame_size, P_W - 16), 8);
          small_r <= '1' when frame_size < 3 else '0';
          p_r    <= (others => '0');
          cnt    <= SCALE_W - 1;
          busy_r <= '1';
        end if;
      elsif clamp_r = '0' then                          -- p = 2 p + bit s8 (MSB of s first)
        if m_r(SCALE_W - 1) = '1' then
          p_r <= shift_left(p_r, 1) + resize(a_r, P_W);
        else
          p_r <= shift_left(p_r, 1);
        end if;
        m_r <= shift_left(m_r, 1);
        if cnt = 0 then
          clamp_r <= '1';
        else
          cnt <= cnt - 1;
        end if;
      else                                              -- >> 16, min(max(q, 3 px), frame): two
        q := p_r(P_W - 1 downto 16);                    -- compares side by side, then a select
        if small_r = '1' or q > hi_r then
          out_r <= resize(hi_r, SIZE_W);
        elsif q < MIN8 then
          out_r <= to_unsigned(MIN8, SIZE_W);
        else
          out_r <= resize(q, SIZE_W);
        end if;
        done_r <= '1';
        busy_r <= '0';
      end if;
      if rst = '1' then
        busy_r  <= '0';
        done_r  <= '0';
        clamp_r <= '0';
      end if;
    end if;
  end process;

  busy   <= busy_r;
  done   <= done_r;
  s8_out <= out_r;
end architecture;
