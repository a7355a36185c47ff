-- ms_result_order: the result words of the shared-engine multi-target core, sent in the documented
-- order: the jobs of a frame end in release order, the words leave in ascending target id.
--
-- Computes: words written during a frame (s_id, s_word; a later word of the same id replaces the
-- earlier one) are held in the frame's bank; on `close` with close_mask, the ids of the mask leave on
-- m_* in ascending order, each as {id, word} (the id at bits WORD_W + 3 .. WORD_W: the layout of
-- mstrack.fixed.vhdl_pkg.result_layout_multi), m_last on the last one.  The next frame's words go to
-- the other bank meanwhile, so the engine never waits for the result stream unless a second close
-- comes before the first frame's words have all been read from their bank (close_ready = '0').  An id
-- of the mask with no word in that frame is sent with what its entry holds and pulses `missing` (the
-- top never does this; the flag is for its tests).  An empty mask sends nothing (the top sends the
-- frame's no_target word as id 0).
-- Send pipeline: the ids of the mask are found one per clock, lowest first (gen: the mask register
-- and one subtraction, the id registered), then read from the store (RD_LAT = 2 clocks), then go
-- through a ring of RD_LAT + 1 = 3 words into the m_* register (a word that finds the ring empty goes
-- straight to m_*).  A read starts only when its word will find room (at most RD_LAT + 2 words read
-- and not yet sent: in flight, in the ring, on m_*), decided on registers, not on this clock's
-- m_ready; so one word per clock leaves while m_ready is high, and back-pressure stops the reads.
-- Latency: a word is in the store at the clock edge after the one that takes it (s_valid; the store's
-- write port is registered).  The first word is on m_data RD_LAT + 3 = 5 clocks after the close is
-- taken (edges after the close edge: 1 the close applied, 2 the first id found, 3 its read started,
-- 3 + RD_LAT on m_data); a word taken in the close clock belongs to the closed frame.  Then one word
-- per clock while m_ready.
-- Throughput: one word in and one word out per clock.
-- Handshake: s_valid (always taken: s_ready = '1'); close when close_ready; AXI4-Stream out.
-- Memory: the store, 16 + N_SLOTS words of WORD_W bits at address {bank, id} (2 x N_SLOTS of them
-- used), an ms_ram_sdp with RD_LAT 2 and WR_LAT 1: on ECP5 one row of ceil(WORD_W / 18) DP16KD (9 at
-- WORD_W 160) with their output register (one row: RD_LAT 2 is enough for it); the ring and m_* in
-- flip-flops.
-- Python model: the word order of mstrack.hw.cosim_multi.CoreModelMulti (ascending ids, tlast on the
-- frame's last word); tb/test_ms_result_order.py.
-- Reset: synchronous, active high: both banks empty, nothing to send (the store's words are kept).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_result_order is
  generic (
    N_SLOTS : positive range 1 to 16 := 16;   -- target ids 0 .. N_SLOTS - 1
    WORD_W  : positive := 160                 -- result word v2
  );
  port (
    clk         : in  std_logic;
    rst         : in  std_logic;
    s_valid     : in  std_logic;                                  -- a target's word of the frame
    s_ready     : out std_logic;                                  -- always '1'
    s_id        : in  unsigned(3 downto 0);
    s_word      : in  std_logic_vector(WORD_W - 1 downto 0);
    close       : in  std_logic;                                  -- the frame's words are in
    close_mask  : in  std_logic_vector(N_SLOTS - 1 downto 0);     -- ids to send
    close_ready : out std_logic;                                  -- a close can be taken
    m_valid     : out std_logic;                                  -- {id, word}, ascending ids
    m_ready     : in  std_logic;
    m_data      : out std_logic_vector(WORD_W + 3 downto 0);
    m_last      : out std_logic;                                  -- the frame's last word
    missing     : out std_logic                                   -- pulse: a sent id had no word
  );
end entity;

architecture rtl of ms_result_order is
  constant RD_LAT : positive := 2;            -- store read latency (ECP5: the DP16KD output register)
  constant NQ     : positive := RD_LAT + 1;   -- ring words in front of m_*
  constant CAP    : positive := RD_LAT + 2;   -- words read and not yet sent (in flight, ring, m_*)
  type word_arr_t is array (natural range <>) of std_logic_vector(WORD_W - 1 downto 0);
  type id_arr_t is array (natural range <>) of natural range 0 to N_SLOTS - 1;

  -- write side: the store's write port (registered in ms_ram_sdp, WR_LAT 1)
  signal we      : std_logic;
  signal waddr   : unsigned(4 downto 0);
  signal raddr   : unsigned(4 downto 0);
  signal rdata   : std_logic_vector(WORD_W - 1 downto 0);
  -- ids written in each bank (two vectors, not an array of two: written with two different
  -- run-time indices in one clock, the array went wrong in GHDL's netlist under Verilator)
  signal has0, has1 : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal w_v     : std_logic := '0';                               -- the registered write (has flags)
  signal w_bank  : natural range 0 to 1 := 0;
  signal w_id    : natural range 0 to N_SLOTS - 1 := 0;
  signal cb      : natural range 0 to 1 := 0;                      -- the collecting bank
  signal db      : natural range 0 to 1 := 1;                      -- the bank being sent
  -- close
  signal close_q : std_logic := '0';                               -- a close taken, applied next clock
  signal mask_q  : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal busy    : std_logic := '0';                               -- ids of the bank left to read
  -- gen: the ids still to find, the next id found (registered)
  signal rem_m   : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal rem_nz  : std_logic := '0';                               -- rem_m /= 0
  signal g_v     : std_logic := '0';
  signal g_id    : natural range 0 to N_SLOTS - 1 := 0;
  signal g_last  : std_logic := '0';                               -- g_id is the frame's last id
  -- reads in flight: the id, last and missing flags beside the store's read pipeline
  signal used    : natural range 0 to CAP := 0;                    -- words read and not yet sent
  signal room    : std_logic := '1';                               -- used < CAP (registered)
  signal pv      : std_logic_vector(1 to RD_LAT) := (others => '0');
  signal pid     : id_arr_t(1 to RD_LAT) := (others => 0);
  signal plast   : std_logic_vector(1 to RD_LAT) := (others => '0');
  signal pmiss   : std_logic_vector(1 to RD_LAT) := (others => '0');
  -- ring of NQ words in front of m_*
  signal q_word  : word_arr_t(0 to NQ - 1) := (others => (others => '0'));
  signal q_id    : id_arr_t(0 to NQ - 1) := (others => 0);
  signal q_last  : std_logic_vector(0 to NQ - 1) := (others => '0');
  signal q_miss  : std_logic_vector(0 to NQ - 1) := (others => '0');
  signal wp_hot  : std_logic_vector(0 to NQ - 1) := (0 => '1', others => '0');  -- the ring's tail, one-hot
  signal rp_hot  : std_logic_vector(0 to NQ - 1) := (0 => '1', others => '0');  -- the ring's head, one-hot
  signal cnt     : natural range 0 to NQ := 0;                     -- words in the ring
  signal q_ne    : std_logic := '0';                               -- cnt /= 0
  signal o_valid : std_logic := '0';

  -- the index of the one set bit of a one-hot vector (an OR per index bit)
  function encode(h : std_logic_vector) return natural is
    alias hn : std_logic_vector(h'length - 1 downto 0) is h;   -- (the logical operators return 1 to n)
    variable k : unsigned(3 downto 0) := (others => '0');
  begin
    for i in hn'range loop
      if hn(i) = '1' then
        k := k or to_unsigned(i, 4);
      end if;
    end loop;
    return to_integer(k);
  end function;
begin
  -- the store: bank cb, address {bank, id}; a word of an id >= N_SLOTS is dropped
  we    <= '1' when s_valid = '1' and to_integer(s_id) < N_SLOTS else '0';
  waddr <= to_unsigned(cb, 1) & s_id;
  raddr <= to_unsigned(db, 1) & to_unsigned(g_id, 4);

  u_store : entity work.ms_ram_sdp
    generic map (DEPTH => 16 + N_SLOTS, DATA_W => WORD_W, ADDR_W => 5, RD_LAT => RD_LAT, WR_LAT => 1)
    port map (clk => clk, we => we, waddr => waddr, wdata => s_word, raddr => raddr, rdata => rdata);

  p_order : process (clk)
    variable r    : std_logic_vector(N_SLOTS - 1 downto 0);
    variable rd   : boolean;                  -- the read of g_id starts
    variable u    : natural range 0 to CAP;   -- used, next
    variable pop  : boolean;                  -- a word leaves on m_*
    variable ld   : boolean;                  -- the m_* register loads
    variable push : boolean;                  -- the arriving word goes into the ring
    variable take : boolean;                  -- the m_* register loads the ring's head
    variable hw   : std_logic_vector(WORD_W - 1 downto 0);
    variable hid  : natural range 0 to N_SLOTS - 1;
    variable hl, hm : std_logic;
  begin
    if rising_edge(clk) then
      -- the has flags follow the store's registered write port
      w_v <= we;
      w_bank <= cb;
      if to_integer(s_id) < N_SLOTS then
        w_id <= to_integer(s_id);
      end if;
      if w_v = '1' then
        if w_bank = 0 then
          has0(w_id) <= '1';
        else
          has1(w_id) <= '1';
        end if;
      end if;

      -- read: the id found, when its word will find room (`used` counts the reads not yet sent)
      rd  := g_v = '1' and room = '1';
      pop := o_valid = '1' and m_ready = '1';
      u   := used;
      if rd and not pop then
        u := used + 1;
      elsif pop and not rd then
        u := used - 1;
      end if;
      used <= u;
      room <= '1' when u < CAP else '0';
      pv(1) <= '1' when rd else '0';
      pid(1) <= g_id;
      plast(1) <= g_last;
      if db = 0 then
        pmiss(1) <= not has0(g_id);
      else
        pmiss(1) <= not has1(g_id);
      end if;
      for i in 2 to RD_LAT loop
        pv(i) <= pv(i - 1);
        pid(i) <= pid(i - 1);
        plast(i) <= plast(i - 1);
        pmiss(i) <= pmiss(i - 1);
      end loop;
      if rd and g_last = '1' then
        busy <= '0';                              -- the bank's last id is read
      end if;

      -- gen: the lowest id left, one per clock while the reads take them
      if rem_nz = '1' and (g_v = '0' or rd) then
        r := rem_m and std_logic_vector(unsigned(rem_m) - 1);   -- the lowest id cleared
        g_id   <= encode(rem_m and not std_logic_vector(unsigned(rem_m) - 1));
        g_last <= '1' when unsigned(r) = 0 else '0';
        g_v    <= '1';
        rem_m  <= r;
        rem_nz <= '0' when unsigned(r) = 0 else '1';
      elsif rd then
        g_v <= '0';
      end if;

      -- the ring and m_*: the word read RD_LAT clocks ago arrives (pv(RD_LAT), rdata); m_* loads the
      -- ring's head, or the arriving word when the ring is empty; else the word goes into the ring
      -- (its tail entry is written whenever a word arrives, and counted only when pushed)
      ld   := o_valid = '0' or m_ready = '1';
      take := ld and q_ne = '1';
      push := pv(RD_LAT) = '1' and not (ld and q_ne = '0');
      for i in 0 to NQ - 1 loop
        if pv(RD_LAT) = '1' and wp_hot(i) = '1' then
          q_word(i) <= rdata;
          q_id(i)   <= pid(RD_LAT);
          q_last(i) <= plast(RD_LAT);
          q_miss(i) <= pmiss(RD_LAT);
        end if;
      end loop;
      hw := (others => '0');
      hid := 0;
      hl := '0';
      hm := '0';
      for i in 0 to NQ - 1 loop
        if rp_hot(i) = '1' then
          hw  := hw or q_word(i);
          hid := q_id(i);
          hl  := q_last(i);
          hm  := q_miss(i);
        end if;
      end loop;
      if q_ne = '0' then
        hw  := rdata;
        hid := pid(RD_LAT);
        hl  := plast(RD_LAT);
        hm  := pmiss(RD_LAT);
      end if;
      missing <= '0';
      if ld then
        if q_ne = '1' or pv(RD_LAT) = '1' then
          m_data  <= std_logic_vector(to_unsigned(hid, 4)) & hw;
          m_last  <= hl;
          missing <= hm;
          o_valid <= '1';
        else
          o_valid <= '0';
        end if;
      end if;
      if push then
        wp_hot <= wp_hot(NQ - 1) & wp_hot(0 to NQ - 2);
      end if;
      if take then
        rp_hot <= rp_hot(NQ - 1) & rp_hot(0 to NQ - 2);
      end if;
      if push and not take then
        cnt  <= cnt + 1;
        q_ne <= '1';
      elsif take and not push then
        cnt  <= cnt - 1;
        q_ne <= '1' when cnt > 1 else '0';
      end if;

      -- close: the collecting bank becomes the one sent, the other one collects (emptied); a word
      -- taken in the close clock is the closed frame's.  A close is registered (close_q, mask_q), then
      -- applied: the bank switch and the mask come from flip-flops, not from the input handshake
      close_q <= close and not busy and not close_q;
      if close = '1' and busy = '0' and close_q = '0' then
        mask_q <= close_mask;
        cb     <= 1 - cb;                         -- the next word is the next frame's
      end if;
      if close_q = '1' then                       -- (gen is idle: busy was '0')
        rem_m  <= mask_q;
        rem_nz <= '0' when unsigned(mask_q) = 0 else '1';
        busy   <= '0' when unsigned(mask_q) = 0 else '1';
        db     <= 1 - cb;                         -- (cb switched in the close clock)
        if cb = 0 then                            -- the bank that collects now starts empty (its
          has0 <= (others => '0');                -- first word's flag is set a clock later)
        else
          has1 <= (others => '0');
        end if;
      end if;
      if rst = '1' then
        has0    <= (others => '0');
        has1    <= (others => '0');
        w_v     <= '0';
        close_q <= '0';
        busy    <= '0';
        rem_m   <= (others => '0');
        rem_nz  <= '0';
        g_v     <= '0';
        used    <= 0;
        room    <= '1';
        pv      <= (others => '0');
        wp_hot  <= (0 => '1', others => '0');
        rp_hot  <= (0 => '1', others => '0');
        cnt     <= 0;
        q_ne    <= '0';
        o_valid <= '0';
        missing <= '0';
        cb      <= 0;
        db      <= 1;
      end if;
    end if;
  end process;
  s_ready     <= '1';
  close_ready <= not busy and not close_q;
  m_valid     <= o_valid;
end architecture;
