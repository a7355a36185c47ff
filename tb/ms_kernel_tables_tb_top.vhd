-- ms_kernel_tables_tb_top: test wrapper (not part of the core) for the exhaustive v2 run of
-- tb/test_ms_kernel_tables.py: ms_kernel_tables plus a copy of every table write (as the
-- engines' table memories hold them), exposed as flat vectors so that the bench reads all the
-- tables of a size at once instead of watching every clock.
-- n_writes counts the writes since start; order_err is set when a write's address is not the
-- next index (the entries must come 0, 1, .., max(ex, ey)).
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity ms_kernel_tables_tb_top is
  generic (
    HALF_W      : natural := 6;   -- see ms_kernel_tables
    KERNEL_EPAN : natural := 1;   -- 1: KA/KB computed (v2 needs them for d2q with the flat kernel)
    KERNEL_BITS : natural := 8;   -- KA, KB scale
    KVAL_W      : natural := 9;   -- width of KA, KB
    KD_W        : natural := 29   -- width of TA, TB, D
  );
  port (
    clk       : in  std_logic;                                        -- clock
    rst       : in  std_logic;                                        -- reset
    start     : in  std_logic;                                        -- start pulse
    w         : in  unsigned(HALF_W downto 0);                        -- window width
    h         : in  unsigned(HALF_W downto 0);                        -- window height
    busy      : out std_logic;                                        -- computing
    done      : out std_logic;                                        -- done pulse
    ex        : out unsigned(HALF_W - 1 downto 0);                    -- (w - 1) / 2
    ey        : out unsigned(HALF_W - 1 downto 0);                    -- (h - 1) / 2
    kd_d      : out unsigned(KD_W - 1 downto 0);                      -- D
    tab_ta    : out std_logic_vector(2 ** HALF_W * KD_W - 1 downto 0);   -- TA[i] at (i+1)*KD_W-1 .. i*KD_W
    tab_tb    : out std_logic_vector(2 ** HALF_W * KD_W - 1 downto 0);   -- TB[i]
    tab_ka    : out std_logic_vector(2 ** HALF_W * KVAL_W - 1 downto 0); -- KA[i]
    tab_kb    : out std_logic_vector(2 ** HALF_W * KVAL_W - 1 downto 0); -- KB[i]
    tab_xr    : out std_logic_vector(2 ** HALF_W * HALF_W - 1 downto 0); -- XR[i]
    n_writes  : out unsigned(HALF_W downto 0);                        -- writes since start
    order_err : out std_logic                                         -- a write out of order since start
  );
end entity;

architecture tb of ms_kernel_tables_tb_top is
  constant N : natural := 2 ** HALF_W;
  signal we : std_logic;
  signal addr : unsigned(HALF_W - 1 downto 0);
  signal ta, tb : unsigned(KD_W - 1 downto 0);
  signal ka, kb : unsigned(KVAL_W - 1 downto 0);
  signal xr : unsigned(HALF_W - 1 downto 0);
  signal cnt : unsigned(HALF_W downto 0) := (others => '0');
  signal err : std_logic := '0';
  signal r_ta, r_tb : std_logic_vector(N * KD_W - 1 downto 0) := (others => '0');
  signal r_ka, r_kb : std_logic_vector(N * KVAL_W - 1 downto 0) := (others => '0');
  signal r_xr : std_logic_vector(N * HALF_W - 1 downto 0) := (others => '0');
begin
  u_tab : entity work.ms_kernel_tables
    generic map (HALF_W => HALF_W, KERNEL_EPAN => KERNEL_EPAN, KERNEL_BITS => KERNEL_BITS, KVAL_W => KVAL_W,
                 KD_W => KD_W)
    port map (clk => clk, rst => rst, start => start, w => w, h => h, busy => busy, done => done, ex => ex,
              ey => ey, kd_d => kd_d, kt_we => we, kt_addr => addr, kt_ta => ta, kt_tb => tb, kt_ka => ka,
              kt_kb => kb, kt_xr => xr);

  p_copy : process (clk)
    variable i : natural;
  begin
    if rising_edge(clk) then
      if we = '1' then
        i := to_integer(addr);
        r_ta((i + 1) * KD_W - 1 downto i * KD_W) <= std_logic_vector(ta);
        r_tb((i + 1) * KD_W - 1 downto i * KD_W) <= std_logic_vector(tb);
        r_ka((i + 1) * KVAL_W - 1 downto i * KVAL_W) <= std_logic_vector(ka);
        r_kb((i + 1) * KVAL_W - 1 downto i * KVAL_W) <= std_logic_vector(kb);
        r_xr((i + 1) * HALF_W - 1 downto i * HALF_W) <= std_logic_vector(xr);
        cnt <= cnt + 1;
        if resize(addr, HALF_W + 1) /= cnt then
          err <= '1';
        end if;
      end if;
      if start = '1' then
        cnt <= (others => '0');
        err <= '0';
      end if;
    end if;
  end process;
  tab_ta    <= r_ta;
  tab_tb    <= r_tb;
  tab_ka    <= r_ka;
  tab_kb    <= r_kb;
  tab_xr    <= r_xr;
  n_writes  <= cnt;
  order_err <= err;
end architecture;
