-- DP16KD (Lattice ECP5 16 kbit true dual-port block RAM): behavioural model for simulation of
-- rtl/ecp5/ms_ram_sdp_ecp5.vhd only (test bench file, never synthesised; yosys has the real cell).
--
-- Modelled subset, as ms_ram_sdp's ecp5 architecture uses it (other settings are rejected by an
-- assertion): one clock edge per port (CLKx rising), DATA_WIDTH 1, 2, 4, 9 or 18 (16384 / 8192 /
-- 4096 / 2048 / 1024 words; word address on ADx13 .. ADx(14 - log2 words), as Lattice TN1264 and
-- yosys' brams_map_16kd.v place it), CSDECODE "0b000" with CSx = 0, WRITEMODE "NORMAL" (the
-- writing port's own output is not modelled: port A only writes), CEx read/write enable, REGMODE
-- "NOREG" (DOx = the word read at the last CEx edge) or "OUTREG" (one more register, enabled by
-- OCEx), RSTx unused (must be 0).  Port collision (B reads the word A writes at the same edge):
-- the old word here; undefined on the device.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity DP16KD is
  generic (
    DATA_WIDTH_A        : integer := 18;
    DATA_WIDTH_B        : integer := 18;
    REGMODE_A           : string  := "NOREG";
    REGMODE_B           : string  := "NOREG";
    RESETMODE           : string  := "SYNC";
    ASYNC_RESET_RELEASE : string  := "SYNC";
    CSDECODE_A          : string  := "0b000";
    CSDECODE_B          : string  := "0b000";
    WRITEMODE_A         : string  := "NORMAL";
    WRITEMODE_B         : string  := "NORMAL";
    GSR                 : string  := "ENABLED"
  );
  port (
    DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9,
    DIA8, DIA7, DIA6, DIA5, DIA4, DIA3, DIA2, DIA1, DIA0 : in std_logic;
    ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4,
    ADA3, ADA2, ADA1, ADA0 : in std_logic;
    CEA, OCEA, CLKA, WEA, RSTA, CSA2, CSA1, CSA0 : in std_logic;
    DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9,
    DOA8, DOA7, DOA6, DOA5, DOA4, DOA3, DOA2, DOA1, DOA0 : out std_logic;
    DIB17, DIB16, DIB15, DIB14, DIB13, DIB12, DIB11, DIB10, DIB9,
    DIB8, DIB7, DIB6, DIB5, DIB4, DIB3, DIB2, DIB1, DIB0 : in std_logic;
    ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4,
    ADB3, ADB2, ADB1, ADB0 : in std_logic;
    CEB, OCEB, CLKB, WEB, RSTB, CSB2, CSB1, CSB0 : in std_logic;
    DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9,
    DOB8, DOB7, DOB6, DOB5, DOB4, DOB3, DOB2, DOB1, DOB0 : out std_logic
  );
end entity;

architecture model of DP16KD is
  function abits(w : integer) return natural is
  begin
    case w is
      when 1 => return 14;
      when 2 => return 13;
      when 4 => return 12;
      when 9 => return 11;
      when 18 => return 10;
      when others => return 0;
    end case;
  end function;
  constant W  : integer := DATA_WIDTH_A;
  constant AB : natural := abits(W);
  type mem_t is array (0 to 2 ** AB - 1) of std_logic_vector(17 downto 0);
  signal mem       : mem_t := (others => (others => '0'));
  signal qa, qb    : std_logic_vector(17 downto 0) := (others => '0');
  signal ra, rb    : std_logic_vector(17 downto 0) := (others => '0');
  signal ada, adb  : std_logic_vector(13 downto 0);
  signal dia, dob_i, doa_i : std_logic_vector(17 downto 0);
begin
  assert DATA_WIDTH_A = DATA_WIDTH_B and AB > 0
    report "DP16KD model: equal widths 1, 2, 4, 9 or 18 only" severity failure;
  assert CSDECODE_A = "0b000" and CSDECODE_B = "0b000" and WRITEMODE_A = "NORMAL" and WRITEMODE_B = "NORMAL"
    report "DP16KD model: CSDECODE 0b000 and WRITEMODE NORMAL only" severity failure;

  ada <= (ADA13, ADA12, ADA11, ADA10, ADA9, ADA8, ADA7, ADA6, ADA5, ADA4, ADA3, ADA2, ADA1, ADA0);
  adb <= (ADB13, ADB12, ADB11, ADB10, ADB9, ADB8, ADB7, ADB6, ADB5, ADB4, ADB3, ADB2, ADB1, ADB0);
  dia <= (DIA17, DIA16, DIA15, DIA14, DIA13, DIA12, DIA11, DIA10, DIA9, DIA8, DIA7, DIA6, DIA5, DIA4,
          DIA3, DIA2, DIA1, DIA0);

  p_a : process (CLKA)
  begin
    if rising_edge(CLKA) then
      assert RSTA /= '1' and CSA0 = '0' and CSA1 = '0' and CSA2 = '0' report "DP16KD model: RSTA/CSA unused" severity failure;
      if CEA = '1' then
        if WEA = '1' then
          mem(to_integer(unsigned(ada(13 downto 14 - AB)))) <= dia;
        else
          qa <= mem(to_integer(unsigned(ada(13 downto 14 - AB))));
        end if;
      end if;
      if OCEA = '1' then
        ra <= qa;
      end if;
    end if;
  end process;

  p_b : process (CLKB)
  begin
    if rising_edge(CLKB) then
      assert RSTB /= '1' and CSB0 = '0' and CSB1 = '0' and CSB2 = '0' report "DP16KD model: RSTB/CSB unused" severity failure;
      assert WEB /= '1' report "DP16KD model: port B write not modelled" severity failure;
      if CEB = '1' then
        qb <= mem(to_integer(unsigned(adb(13 downto 14 - AB))));
      end if;
      if OCEB = '1' then
        rb <= qb;
      end if;
    end if;
  end process;

  doa_i <= ra when REGMODE_A = "OUTREG" else qa;
  dob_i <= rb when REGMODE_B = "OUTREG" else qb;
  (DOA17, DOA16, DOA15, DOA14, DOA13, DOA12, DOA11, DOA10, DOA9, DOA8, DOA7, DOA6, DOA5, DOA4,
   DOA3, DOA2, DOA1, DOA0) <= doa_i;
  (DOB17, DOB16, DOB15, DOB14, DOB13, DOB12, DOB11, DOB10, DOB9, DOB8, DOB7, DOB6, DOB5, DOB4,
   DOB3, DOB2, DOB1, DOB0) <= dob_i;
end architecture;
