-- ms_job_queue: the released jobs of the shared-engine multi-target core, for the engine, first
-- come first served (docs/multi_target_core.md, "Schedule").
--
-- Computes: each slot's `released` pulse (ms_slot_capture) enters a mask; every clock the lowest
-- slot of the mask moves into a FIFO of N_SLOTS entries (two for one slot); the engine pops the FIFO
-- (q_valid / q_ready).  Slots released in the same clock leave in ascending order, and a slot released later
-- leaves after them, as long as releases of different clocks are at least N_SLOTS clocks apart: the
-- slot captures release on the first pixel of a line, so that is one line.  A release that comes
-- while the mask still holds an earlier one raises `merged` (for the tests; the order among them is
-- then by slot).  Each slot has at most one job queued (one capture per slot and frame), so the FIFO
-- never overflows.  `flush` empties mask and FIFO (a stream fault drops the frame's jobs).
-- Latency: a release at an edge is on q_slot at the earliest 2 clocks later (mask, FIFO); q_slot is
-- read from the FIFO's LUT RAM at rp (first word fall-through), q_valid from a register.
-- Throughput: one release moved per clock, one pop per clock.
-- Handshake: rel pulses (no back-pressure); q_valid / q_ready.
-- Reset: synchronous, active high: empty.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_job_queue is
  generic (
    N_SLOTS : positive range 1 to 16 := 16
  );
  port (
    clk     : in  std_logic;
    rst     : in  std_logic;
    flush   : in  std_logic;                               -- drop every queued job
    rel     : in  std_logic_vector(N_SLOTS - 1 downto 0);  -- slot s released its region
    q_valid : out std_logic;                               -- a job: slot q_slot
    q_ready : in  std_logic;
    q_slot  : out unsigned(3 downto 0);
    merged  : out std_logic                                -- pulse: releases of two clocks met in the mask
  );
end entity;

architecture rtl of ms_job_queue is
  constant PW : natural := 5;                              -- FIFO pointers, one bit more than 4
  -- at least two entries: GHDL 2.0's synthesis fails on a one-entry memory (N_SLOTS 1)
  constant DEPTH : positive := maximum(2, N_SLOTS);
  type fifo_t is array (0 to DEPTH - 1) of unsigned(3 downto 0);
  signal fifo   : fifo_t;
  signal mask   : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal wp, rp : unsigned(PW - 1 downto 0) := (others => '0');
  signal count  : natural range 0 to N_SLOTS := 0;

  function wrap_inc(p : unsigned) return unsigned is
  begin
    if p = DEPTH - 1 then
      return to_unsigned(0, p'length);
    end if;
    return p + 1;
  end function;
begin
  p_queue : process (clk)
    variable m     : std_logic_vector(N_SLOTS - 1 downto 0);
    variable push  : boolean;
    variable pop   : boolean;
    variable low   : natural range 0 to N_SLOTS - 1;
  begin
    if rising_edge(clk) then
      merged <= '0';
      -- the lowest slot of the mask moves to the FIFO
      push := false;
      low  := 0;
      for i in N_SLOTS - 1 downto 0 loop
        if mask(i) = '1' then
          low  := i;
          push := true;
        end if;
      end loop;
      m := mask;
      if push then
        for i in 0 to N_SLOTS - 1 loop                     -- clear it (compare with each index)
          if i = low then
            m(i) := '0';
          end if;
        end loop;
        fifo(to_integer(wp)) <= to_unsigned(low, 4);
        wp <= wrap_inc(wp);
      end if;
      if unsigned(rel) /= 0 and unsigned(m) /= 0 then
        merged <= '1';
      end if;
      mask <= m or rel;
      pop := count > 0 and q_ready = '1';
      if pop then
        rp <= wrap_inc(rp);
      end if;
      if push and not pop then
        count <= count + 1;
      elsif pop and not push then
        count <= count - 1;
      end if;
      if rst = '1' or flush = '1' then
        mask  <= (others => '0');
        wp    <= (others => '0');
        rp    <= (others => '0');
        count <= 0;
        merged <= '0';
      end if;
    end if;
  end process;
  q_valid <= '1' when count > 0 else '0';
  q_slot  <= fifo(to_integer(rp));
end architecture;
