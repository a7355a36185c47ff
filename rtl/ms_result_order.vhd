-- ms_result_order: the result words of the shared-engine multi-target core, sent in the documented
-- order: the jobs of a frame end in release order, the words leave in ascending target id.
--
-- Computes: words written during a frame (s_id, s_word; a later word of the same id replaces the
-- earlier one) are held in the frame's bank; on `close` with close_mask, the ids of the mask leave on
-- m_* in ascending order, each as {id, word} (the id at bits WORD_W + 3 .. WORD_W: the layout of
-- mstrack.fixed.vhdl_pkg.result_layout_multi), m_last on the last one.  The next frame's words go to
-- the other bank meanwhile, so the engine never waits for the result stream unless a second close
-- comes before the first frame's words have all left the bank (close_ready = '0').  An id of the mask with no
-- word in that frame is sent with what its entry holds and pulses `missing` (the top never does
-- this; the flag is for its tests).  An empty mask sends nothing (the top sends the frame's
-- no_target word as id 0).
-- Latency: a word is in the store 2 clocks after s_valid (a registered write port); the first word is
-- on m_data 3 clocks after the close is taken (it is registered, then applied); then one word per
-- clock while m_ready.
-- Throughput: one word in and one word out per clock.
-- Handshake: s_valid (always taken: s_ready = '1'); close when close_ready; AXI4-Stream out.
-- Memory: 2 x N_SLOTS words of WORD_W bits (LUT RAM: one write, one read port).
-- Python model: the word order of mstrack.hw.cosim_multi.CoreModelMulti (ascending ids, tlast on the
-- frame's last word); tb/test_ms_result_order.py.
-- Reset: synchronous, active high: both banks empty, nothing to send.
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
  type mem_t is array (0 to 2 * N_SLOTS - 1) of std_logic_vector(WORD_W - 1 downto 0);
  signal mem     : mem_t;
  -- ids written in each bank (two vectors, not an array of two: written with two different
  -- run-time indices in one clock, the array went wrong in GHDL's netlist under Verilator)
  signal has0, has1 : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal cb      : natural range 0 to 1 := 0;                     -- the collecting bank
  signal db      : natural range 0 to 1 := 1;                     -- the bank being sent
  signal rem_m   : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');  -- ids still to send
  signal o_valid : std_logic := '0';
  signal k_r     : natural range 0 to N_SLOTS - 1 := 0;            -- the next id to send
  signal any_r   : std_logic := '0';                               -- ids left to send
  signal one_r   : std_logic := '0';                               -- k_r is the last of them
  signal go      : std_logic := '0';                               -- the close applied + 1
  signal close_q : std_logic := '0';                               -- a close taken, applied next clock
  signal mask_q  : std_logic_vector(N_SLOTS - 1 downto 0) := (others => '0');
  signal w_v     : std_logic := '0';                               -- the registered write
  signal w_addr  : natural range 0 to 2 * N_SLOTS - 1 := 0;
  signal w_bank  : natural range 0 to 1 := 0;
  signal w_id    : natural range 0 to N_SLOTS - 1 := 0;
  signal w_word  : std_logic_vector(WORD_W - 1 downto 0);

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
  p_order : process (clk)
    variable r : std_logic_vector(N_SLOTS - 1 downto 0);
  begin
    if rising_edge(clk) then
      missing <= '0';
      -- a word is registered with its bank, then written (the store's write port from flip-flops)
      w_v <= '0';
      if s_valid = '1' and to_integer(s_id) < N_SLOTS then
        w_v    <= '1';
        w_addr <= cb * N_SLOTS + to_integer(s_id);
        w_bank <= cb;
        w_id   <= to_integer(s_id);
        w_word <= s_word;
      end if;
      if w_v = '1' then
        mem(w_addr) <= w_word;
        if w_bank = 0 then
          has0(w_id) <= '1';
        else
          has1(w_id) <= '1';
        end if;
      end if;
      -- send: one word per clock from the bank of the closed frame; the next id (k_r, one_r: it is
      -- the last) is found a clock ahead, so the encoder and the word store are on different paths
      if o_valid = '1' and m_ready = '1' then
        o_valid <= '0';
      end if;
      go <= '0';
      if (o_valid = '0' or m_ready = '1') and any_r = '1' and go = '0' then
        m_data  <= std_logic_vector(to_unsigned(k_r, 4)) & mem(db * N_SLOTS + k_r);
        m_last  <= one_r;
        o_valid <= '1';
        if (db = 0 and has0(k_r) = '0') or (db = 1 and has1(k_r) = '0') then
          missing <= '1';
        end if;
        r := rem_m and std_logic_vector(unsigned(rem_m) - 1);   -- k_r (its lowest id) cleared
        rem_m <= r;
        k_r   <= encode(r and std_logic_vector(unsigned(not r) + 1));   -- the lowest id of what is left
        any_r <= '1' when unsigned(r) /= 0 else '0';
        one_r <= '1' when unsigned(r and std_logic_vector(unsigned(r) - 1)) = 0 and unsigned(r) /= 0 else '0';
      end if;
      -- close: the collecting bank becomes the one sent, the other one collects (emptied); a word
      -- written in the close clock is the closed frame's
      -- a close is registered (close_q, mask_q), then applied: the bank switch and the mask come from
      -- flip-flops, not from the input handshake
      close_q <= close and not any_r and not close_q;
      if close = '1' and any_r = '0' and close_q = '0' then
        mask_q <= close_mask;
        cb     <= 1 - cb;                         -- the next word is the next frame's
      end if;
      if close_q = '1' then
        go    <= '1';                             -- send from the next clock: a word of the close
        rem_m <= mask_q;                          -- clock is written first
        k_r   <= encode(mask_q and std_logic_vector(unsigned(not mask_q) + 1));
        any_r <= '1' when unsigned(mask_q) /= 0 else '0';
        one_r <= '1' when unsigned(mask_q and std_logic_vector(unsigned(mask_q) - 1)) = 0
                          and unsigned(mask_q) /= 0 else '0';
        db    <= 1 - cb;                          -- (cb switched in the close clock)
        if cb = 0 then                            -- the bank that collects now starts empty (its
          has0 <= (others => '0');                -- first word is written a clock later)
        else
          has1 <= (others => '0');
        end if;
      end if;
      if rst = '1' then
        has0    <= (others => '0');
        has1    <= (others => '0');
        rem_m   <= (others => '0');
        any_r   <= '0';
        o_valid <= '0';
        w_v     <= '0';
        go      <= '0';
        close_q <= '0';
        cb      <= 0;
        db      <= 1;
      end if;
    end if;
  end process;
  s_ready     <= '1';
  close_ready <= not any_r and not close_q;
  m_valid     <= o_valid;
end architecture;
