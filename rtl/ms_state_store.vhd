-- ms_state_store: the targets' state records of the shared-engine multi-target core, with the
-- stream-fault rule of docs/multi_target_core.md ("The shared engine's RTL"): a job's new state is
-- committed only when its frame has ended good, and dropped when the frame fails.
--
-- Computes: each slot has two records; cur(s) says which one is committed.  A job of frame tag t
-- (frame number mod 2) writes its slot's other record.  If t's verdict is known (fr_done has come
-- for t since fr_start of t), a good frame commits the write at once (cur flips) and a bad one
-- drops it; otherwise the write is pending, and fr_done for t commits (good) or drops (bad) every
-- slot pending on t in the same clock (the cur bits flip together: no copy).  A write in the clock
-- of its frame's fr_done sees that verdict.  `drop` clears a slot's pending write (a removal).
-- rd_data is the committed record of rd_slot.
-- Two tags suffice: a job of frame t ends before frame t + 1's raster reaches its next region,
-- so every job of frame t - 1 has written before fr_start of frame t + 1 reuses the tag.
-- Latency: a write or a verdict sampled at an edge shows on rd_data after the next edge (the
-- records and cur, then the read register); rd_slot -> rd_data 1 clock.
-- Throughput: one write, one verdict and one read per clock.
-- Handshake: valid only (wr_en, fr_start, fr_done, drop pulses).
-- Memory: 2 x N_SLOTS records of DATA_W bits: record 0 and record 1 of the slots in two LUT RAMs
-- (one write, one read port each).
-- Rule of use: a slot's next write comes after the verdict of its pending one (one job per slot
-- and frame, released after the previous frame has ended).
-- Reset: synchronous, active high: every cur and pending bit 0, both tags unknown (the records
-- themselves are not reset; a slot is written by its init job before it is read).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_state_store is
  generic (
    N_SLOTS : positive range 1 to 16 := 16;
    DATA_W  : positive := 213                 -- a state record (docs/multi_target_core.md)
  );
  port (
    clk      : in  std_logic;
    rst      : in  std_logic;
    wr_en    : in  std_logic;                                -- a job's new state
    wr_slot  : in  unsigned(3 downto 0);
    wr_tag   : in  std_logic;                                -- its frame number mod 2
    wr_data  : in  std_logic_vector(DATA_W - 1 downto 0);
    fr_start : in  std_logic;                                -- a frame starts: its tag's verdict is unknown
    fr_done  : in  std_logic;                                -- a frame's verdict
    fr_tag   : in  std_logic;                                -- the frame's tag (fr_start and fr_done)
    fr_good  : in  std_logic;                                -- '1' ended good, '0' stream fault
    drop     : in  std_logic;                                -- forget drop_slot's pending write
    drop_slot : in unsigned(3 downto 0);
    rd_slot  : in  unsigned(3 downto 0);
    rd_data  : out std_logic_vector(DATA_W - 1 downto 0);    -- the committed record
    pending  : out std_logic_vector(N_SLOTS - 1 downto 0)    -- slots with a write waiting for its verdict
  );
end entity;

architecture rtl of ms_state_store is
  -- record r of every slot in its own LUT RAM, so that a read looks up cur(rd_slot) beside the two
  -- RAM reads instead of before one
  type mem_t is array (0 to N_SLOTS - 1) of std_logic_vector(DATA_W - 1 downto 0);
  signal mem0, mem1 : mem_t;
  signal cur    : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal pend   : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal ptag   : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal known  : std_logic_vector(0 to 1) := "00";          -- per tag: verdict given
  signal good   : std_logic_vector(0 to 1) := "00";          -- per tag: the verdict
begin
  -- the records: a write goes to the record that is not committed
  p_mem : process (clk)
  begin
    if rising_edge(clk) then
      if wr_en = '1' and to_integer(wr_slot) < N_SLOTS then
        if cur(to_integer(wr_slot)) = '1' then
          mem0(to_integer(wr_slot)) <= wr_data;
        else
          mem1(to_integer(wr_slot)) <= wr_data;
        end if;
      end if;
    end if;
  end process;

  p_ctl : process (clk)
    variable k_now, g_now : std_logic;                        -- wr_tag's verdict as of this clock
    variable t, ft        : natural range 0 to 1;
    variable cur_v, pend_v : std_logic_vector(N_SLOTS - 1 downto 0);
  begin
    if rising_edge(clk) then
      cur_v  := cur;
      pend_v := pend;
      ft := to_integer(unsigned'("" & fr_tag));
      -- a verdict: every slot pending on that tag commits (good) or drops (bad)
      if fr_done = '1' then
        for i in 0 to N_SLOTS - 1 loop
          if pend(i) = '1' and ptag(i) = fr_tag then
            if fr_good = '1' then
              cur_v(i) := not cur_v(i);
            end if;
            pend_v(i) := '0';
          end if;
        end loop;
        known(ft) <= '1';
        good(ft)  <= fr_good;
      elsif fr_start = '1' then
        known(ft) <= '0';
      end if;
      -- a write: committed or dropped at once if its verdict is known, else pending.  Every bit is
      -- addressed by a compare with its index (no run-time indexed write: GHDL's netlist of two such
      -- writes in one clock is wrong, docs/hdl_flow.md)
      t := to_integer(unsigned'("" & wr_tag));
      k_now := known(t);
      g_now := good(t);
      if fr_done = '1' and fr_tag = wr_tag then
        k_now := '1';
        g_now := fr_good;
      end if;
      for i in 0 to N_SLOTS - 1 loop
        if wr_en = '1' and wr_slot = i then
          if k_now = '1' then
            if g_now = '1' then
              cur_v(i) := not cur(i);                           -- the record written is the other one
            end if;
            pend_v(i) := '0';
          else
            pend_v(i) := '1';
            ptag(i) <= wr_tag;
          end if;
        end if;
        if drop = '1' and drop_slot = i then
          pend_v(i) := '0';
        end if;
      end loop;
      cur  <= cur_v;
      pend <= pend_v;
      -- the committed record of rd_slot, registered
      if to_integer(rd_slot) < N_SLOTS then
        if cur(to_integer(rd_slot)) = '1' then
          rd_data <= mem1(to_integer(rd_slot));
        else
          rd_data <= mem0(to_integer(rd_slot));
        end if;
      end if;
      if rst = '1' then
        cur   <= (others => '0');
        pend  <= (others => '0');
        known <= "00";
        good  <= "00";
      end if;
    end if;
  end process;
  pending <= pend;
end architecture;
