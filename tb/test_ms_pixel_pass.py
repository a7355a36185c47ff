"""cocotb test bench + pytest entry points for rtl/ms_pixel_pass.vhd.

The region RAM (LANES banks, region pixel (rx, ry) in bank rx mod LANES at
ry * STRIDE + rx // LANES, data 1 clock after the address) is a cocotb model.
The kernel tables are written from the model (mstrack.fixed.blocks.ms_kernel);
ms_kernel_tables has its own test.  Each pass is compared exactly, bin by bin,
with ``ms_histogram(bins, Region(0, 0, ...), win, ms_kernel(w, h, ...), n_bins)``
after reading every bin out through the read-and-clear port; the next pass
then checks the clear.  Cycle counts are asserted on every pass (full throughput):
start -> done = sum over rows dy of groups(dy) + PASS_LAT, where a row scans only the
LANES-aligned groups reaching |dx| <= XR[|dy|] (row extent of the kernel ellipse,
:func:`model_xr`).

Run: ``.venv/bin/python -m pytest tb/test_ms_pixel_pass.py``.
"""

from __future__ import annotations

import json
import os
import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.blocks import Region, ms_histogram, ms_kernel

PASS_LAT = 10    # rtl/ms_pixel_pass.vhd header
BIN_RD_LAT = 3   # rtl/ms_histogram.vhd header
CFG_ENV = "MS_PIXEL_PASS_CFG"


def model_xr(ker: ms_kernel) -> list[int]:
    """XR[i], i = 0 .. max(ex, ey): largest dx with TA[dx] + TB[i] < D (0 when i > ey), from the model."""
    xr = []
    for i in range(max(ker.ex, ker.ey) + 1):
        ins = [dx for dx in range(ker.ex + 1) if i <= ker.ey and int(ker.TA[dx]) + int(ker.TB[i]) < ker.D]
        xr.append(ins[-1] if ins else 0)
    return xr


def pass_beats(ker: ms_kernel, wx: int, lanes: int) -> int:
    """Beats of one pass (ms_window_scan): sum over rows of the LANES-aligned groups of |dx| <= XR[|dy|]."""
    xr = model_xr(ker)
    return sum((wx + xr[abs(dy)]) // lanes - (wx - xr[abs(dy)]) // lanes + 1
               for dy in range(-ker.ey, ker.ey + 1))


# ---------------------------------------------------------------- TB

class TB:
    def __init__(self, dut):
        self.dut = dut
        self.cfg = json.loads(os.environ[CFG_ENV])
        c = self.cfg
        self.L = c["LANES"]
        self.bw = c["BIN_W"]
        self.aw = c["ADDR_W"]
        self.stride = c["STRIDE"]
        self.rmax = c["REGION_MAX"]
        self.max_half = c["MAX_HALF"]
        self.n_bins = 1 << self.bw
        self.kernel = "epanechnikov" if c["KERNEL_EPAN"] else "flat"
        self.kb = c["KERNEL_BITS"]
        self.ram_lat = c.get("RAM_LAT", 1)
        self.no = c.get("N_ORIENT", 1)          # > 1: mem holds joint bins no u + o (ram_data u, ram_obin o)
        self.mem = [dict() for _ in range(self.L)]
        self.next_bad: list[tuple[int, int, int]] = []   # (edge, ram_addr_next before, ram_addr)
        self.edges = 0
        dut.rst.value = Immediate(1)
        for name in ("start", "kt_we", "bin_rd_en"):
            getattr(dut, name).value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        cocotb.start_soon(self._ram_and_counter())

    async def _ram_and_counter(self):
        """Region RAM model (registered read: data RAM_LAT clocks after the address) and a cycle counter."""
        L, aw, bw = self.L, self.aw, self.bw
        amask = (1 << aw) - 1
        pipe = [(0, 0)] * self.ram_lat     # (bins, orientations); pipe[0]: read at this edge; pipe[-1]: on ram_data now
        nxt = None                         # ram_addr_next sampled at the edge before: ram_addr now
        while True:
            await RisingEdge(self.dut.clk)
            a = int(self.dut.ram_addr.value)
            if nxt is not None and nxt != a:
                self.next_bad.append((self.edges, nxt, a))
            nxt = int(self.dut.ram_addr_next.value)
            self.edges += 1
            d = o = 0
            for lane in range(L):
                v = self.mem[lane].get((a >> (lane * aw)) & amask, 0)
                d |= (v // self.no) << (lane * bw)
                o |= (v % self.no) << (lane * 4)
            pipe = [(d, o)] + pipe[:-1]
            self.dut.ram_data.value = pipe[-1][0]
            if self.no > 1:
                self.dut.ram_obin.value = pipe[-1][1]

    def load_region(self, bins: np.ndarray, rng: random.Random):
        """bins (rmax, rmax) -> bank memories; padding words get random bins (must be masked)."""
        L = self.L
        self.mem = [dict() for _ in range(L)]
        for ry in range(self.rmax):
            for rx in range(self.stride * L):
                v = int(bins[ry, rx]) if rx < self.rmax else rng.randrange(self.n_bins * self.no)
                self.mem[rx % L][ry * self.stride + rx // L] = v

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)
        n = 0
        while not int(self.dut.ready.value):
            await RisingEdge(self.dut.clk)
            n += 1
        assert n <= self.n_bins + 2, f"ready after {n} clocks"

    async def write_tables(self, ker: ms_kernel):
        d = self.dut
        d.ex.value = ker.ex
        d.ey.value = ker.ey
        d.kd_d.value = ker.D
        xr = model_xr(ker)
        for i in range(max(ker.ex, ker.ey) + 1):
            d.kt_we.value = 1
            d.kt_addr.value = i
            d.kt_ta.value = int(ker.TA[i]) if i <= ker.ex else 0
            d.kt_tb.value = int(ker.TB[i]) if i <= ker.ey else 0
            d.kt_ka.value = int(ker.KA[i]) if (i <= ker.ex and self.kernel != "flat") else 0
            d.kt_kb.value = int(ker.KB[i]) if (i <= ker.ey and self.kernel != "flat") else 0
            d.kt_xr.value = xr[i]
            await RisingEdge(d.clk)
        d.kt_we.value = 0
        await RisingEdge(d.clk)

    async def run_pass(self, ker: ms_kernel, wx: int, wy: int) -> int:
        """Start a pass; return the clocks from the start edge to done (checked against the formula)."""
        d = self.dut
        d.win_x.value = wx
        d.win_y.value = wy
        await RisingEdge(d.clk)  # win_y stable from the clock before start (ms_window_scan)
        d.start.value = 1
        await RisingEdge(d.clk)  # this edge samples start
        d.start.value = 0
        clocks = 0
        while True:
            await RisingEdge(d.clk)
            clocks += 1
            if int(d.done.value):  # sampled at this edge
                break
            assert clocks < 100000, "no done"
        beats = pass_beats(ker, wx, self.L)
        assert clocks == beats + PASS_LAT, f"pass took {clocks} clocks, expected {beats} + {PASS_LAT}"
        return clocks

    async def read_bins(self, rng: random.Random | None) -> dict[str, np.ndarray]:
        """Read and clear every bin; rng: random idle cycles between reads (throttled)."""
        d = self.dut
        no = self.no
        out = {k: np.zeros(self.n_bins * no, np.int64) for k in ("H", "N", "SX", "SY")}
        widths = {"H": self.cfg["HIST_W"], "N": self.cfg["COUNT_W"], "SX": self.cfg["POSSUM_W"],
                  "SY": self.cfg["POSSUM_W"]}
        issued: list[tuple[int, int]] = []
        got = 0
        nxt = 0
        cyc = 0
        while got < self.n_bins:
            await RisingEdge(d.clk)
            cyc += 1
            # sample (values of the cycle that just ended)
            if int(d.bin_rd_valid.value):
                u, c_issue = issued.pop(0)
                # en high in cycle c_issue+1 -> valid in cycle c_issue+1+BIN_RD_LAT, sampled one edge later
                assert cyc - c_issue == BIN_RD_LAT + 1, f"read latency {cyc - c_issue - 1}"
                if no == 1:
                    out["H"][u] = int(d.bin_h.value)
                    out["N"][u] = int(d.bin_n.value)
                    out["SX"][u] = d.bin_sx.value.to_signed()
                    out["SY"][u] = d.bin_sy.value.to_signed()
                else:                  # bank o of address u = joint bin no u + o (bin_*_all, o*width)
                    for k, port in (("H", d.bin_h_all), ("N", d.bin_n_all), ("SX", d.bin_sx_all),
                                    ("SY", d.bin_sy_all)):
                        w, word = widths[k], int(port.value)
                        for ob in range(no):
                            v = (word >> (ob * w)) & ((1 << w) - 1)
                            if k in ("SX", "SY") and v >> (w - 1):
                                v -= 1 << w
                            out[k][no * u + ob] = v
                    assert int(d.bin_h.value) == out["H"][no * u]     # bank 0 on the scalar port
                got += 1
            # drive
            if nxt < self.n_bins and (rng is None or rng.random() < 0.6):
                d.bin_rd_en.value = 1
                d.bin_rd_addr.value = nxt
                issued.append((nxt, cyc))
                nxt += 1
            else:
                d.bin_rd_en.value = 0
        d.bin_rd_en.value = 0
        return out


def random_kernel(rng: random.Random, tb: TB, big: bool = False, p: int = 0) -> ms_kernel:
    mx = min(2 * tb.max_half + 1, tb.rmax)
    if big:  # the largest window, then 64 x 64 (the sizes quoted in docs/blocks/ms_pixel_pass.md)
        w = h = mx if p % 2 == 0 or mx < 64 else 64
    else:
        w, h = rng.randint(3, mx), rng.randint(3, mx)
    return ms_kernel(w, h, tb.kernel, tb.kb)


def region_bins(rng: np.random.Generator, tb: TB, runs: bool) -> np.ndarray:
    n = tb.rmax
    if tb.no > 1:       # joint bins no u + o; runs: few colours and orientations (one joint bin, or one
        if not runs:    # colour with changing orientations, stress the per-bank forwarding)
            return rng.integers(0, tb.n_bins * tb.no, size=(n, n), dtype=np.int64)
        b = tb.no * rng.integers(0, min(2, tb.n_bins), size=(n, n)) + rng.integers(0, tb.no, size=(n, n))
        b[n // 3] = tb.no + 2
        b[n // 2: n // 2 + 4, : n // 2] = tb.no * (n // 2 % 2) + np.arange(n // 2) % tb.no
        return b
    if not runs:
        return rng.integers(0, tb.n_bins, size=(n, n), dtype=np.int64)
    # long runs of equal bins (stress the read-modify-write forwarding): horizontal runs of a few
    # bins, a few constant rows, and a constant block
    b = np.empty((n, n), np.int64)
    for y in range(n):
        x = 0
        while x < n:
            ln = int(rng.integers(1, 2 * n))
            b[y, x: x + ln] = rng.integers(0, min(4, tb.n_bins))
            x += ln
    b[n // 3] = 1
    b[n // 2: n // 2 + 4, : n // 2] = 2 % tb.n_bins
    return b


async def check_passes(dut, n_passes: int, runs: bool, throttle: bool, seed: int, big: bool = False):
    tb = TB(dut)
    rng = random.Random(seed)
    nrng = np.random.default_rng(seed)
    bins = region_bins(nrng, tb, runs)
    tb.load_region(bins, rng)
    await tb.reset()
    reg = Region(0, 0, tb.rmax, tb.rmax, lo=(0, 0), hi=(tb.rmax - 1, tb.rmax - 1))
    for p in range(n_passes):
        ker = random_kernel(rng, tb, big, p)
        await tb.write_tables(ker)
        wx = rng.randint(ker.ex, tb.rmax - 1 - ker.ex)
        wy = rng.randint(ker.ey, tb.rmax - 1 - ker.ey)
        clocks = await tb.run_pass(ker, wx, wy)
        got = await tb.read_bins(rng if throttle else None)
        exp = ms_histogram(bins, reg, (wx, wy), ker, tb.n_bins * tb.no)
        for name in ("H", "N", "SX", "SY"):
            e = getattr(exp, name)
            bad = np.nonzero(got[name] != e)[0]
            assert bad.size == 0, (f"pass {p} win ({wx},{wy}) {ker.w}x{ker.h}: {name} differs at bins "
                                   f"{bad[:8].tolist()}: got {got[name][bad[:8]].tolist()} exp {e[bad[:8]].tolist()}")
        box = (2 * ker.ey + 1) * ((wx + ker.ex) // tb.L - (wx - ker.ex) // tb.L + 1)
        dut._log.info("pass %d: %dx%d at (%d,%d), %d clocks = %d beats (bounding box: %d) + %d, %d px inside OK",
                      p, ker.w, ker.h, wx, wy, clocks, clocks - PASS_LAT, box, PASS_LAT, int(exp.N.sum()))
    # everything was cleared: a final read gives zeros
    got = await tb.read_bins(None)
    for name in ("H", "N", "SX", "SY"):
        assert not got[name].any(), f"{name} not cleared"
    # ram_addr_next is, at every clock, the ram_addr of the next one
    assert not tb.next_bad, f"ram_addr_next differs from the next clock's ram_addr at {tb.next_bad[:4]}"
    dut._log.info("ram_addr_next = the next clock's ram_addr on %d clocks", tb.edges - 1)


# ---------------------------------------------------------------- cocotb tests

@cocotb.test()
async def random_bins(dut):
    """Random region, random windows, full-speed bin reads."""
    n = int(os.environ.get("MS_PIXEL_PASS_N", "20"))
    await check_passes(dut, n, runs=False, throttle=False, seed=1, big="MS_PIXEL_PASS_BIG" in os.environ)


@cocotb.test()
async def runs_of_equal_bins_throttled(dut):
    """Long runs of equal bins (forwarding), throttled bin reads."""
    n = int(os.environ.get("MS_PIXEL_PASS_N", "20"))
    await check_passes(dut, n, runs=True, throttle=True, seed=2, big="MS_PIXEL_PASS_BIG" in os.environ)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_pixel_pass"
MODULE = "test_ms_pixel_pass"
GEN_KEYS = ("LANES", "HALF_W", "REGION_W", "STRIDE", "ADDR_W", "KERNEL_EPAN", "KERNEL_BITS", "KVAL_W",
            "KD_W", "HIST_W", "COUNT_W", "POSSUM_W")


def pass_generics(tp: TrackerParams, fp: FixedParams, lanes: int) -> tuple[dict, dict]:
    g = core_generics(tp, fp, lanes)
    gen = {k: g[k] for k in GEN_KEYS}
    gen["BIN_W"] = 3 * tp.colour_bits
    cfg = {**gen, "REGION_MAX": g["REGION_MAX"], "MAX_HALF": g["MAX_HALF"]}
    return gen, cfg


SMALL_FP = FixedParams(max_half=7, margin=4)
CASES = [
    pytest.param("flat", 2, id="flat_L2"),
    pytest.param("flat", 1, id="flat_L1"),
    pytest.param("flat", 4, id="flat_L4"),
    pytest.param("epanechnikov", 2, id="epan_L2"),
    pytest.param("epanechnikov", 1, id="epan_L1"),
    pytest.param("epanechnikov", 4, id="epan_L4"),
    pytest.param("flat", 8, id="flat_L8"),
    pytest.param("epanechnikov", 8, id="epan_L8"),
]


def test_row_extent_is_inside_test():
    """The RTL's inside test is the scan's row-extent mask |dx| <= XR[|dy|] (|dy| <= ey), XR as
    ms_kernel_tables defines it (largest dx in 0..ex with TA[dx] + TB[i] < D).  It equals the
    model's ms_kernel.inside (TA[|dx|] + TB[|dy|] < D) for every target size w, h in 3 .. 127
    (MAX_HALF 63) and every offset of the window, both kernels (the mask does not depend on k)."""
    for w in range(3, 128):
        for h in range(3, 128):
            ker = ms_kernel(w, h, "flat", 8)
            xr = model_xr(ker)
            dx = np.abs(np.arange(-ker.ex, ker.ex + 1))[None, :]
            dy = np.abs(np.arange(-ker.ey, ker.ey + 1))[:, None]
            mask = dx <= np.asarray(xr)[dy]
            assert np.array_equal(mask, ker.inside), (w, h)
            assert ker.inside[:, ker.ex].all()     # dx = 0 inside every row: no empty row


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,lanes", CASES)
def test_ms_pixel_pass_small(kernel, lanes, hdl_waves):
    gen, cfg = pass_generics(TrackerParams(colour_bits=2, kernel=kernel), SMALL_FP, lanes)
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps(cfg)})


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,lanes,ram_lat", [("flat", 4, 3), ("epanechnikov", 2, 3), ("flat", 1, 2),
                                                       ("flat", 4, 4)])
def test_ms_pixel_pass_ram_lat(kernel, lanes, ram_lat, hdl_waves):
    """Region RAM read latency RAM_LAT > 1 (ms_tracker uses 3, ms_tracker_v2 4: ms_ram_sdp's ecp5 architecture):
    same sums and the same PASS_LAT (the read hides in the kernel pipeline)."""
    gen, cfg = pass_generics(TrackerParams(colour_bits=2, kernel=kernel), SMALL_FP, lanes)
    gen["RAM_LAT"] = cfg["RAM_LAT"] = ram_lat
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps(cfg)})


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,lanes", [("epanechnikov", 2), ("flat", 8)])
def test_ms_pixel_pass_default_config(kernel, lanes, hdl_waves):
    """Default colour config (512 bins, MAX_HALF 63): a 127 x 127 and a 64 x 64 window per test."""
    gen, cfg = pass_generics(TrackerParams(kernel=kernel), FixedParams(), lanes)
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps(cfg), "MS_PIXEL_PASS_N": "2", "MS_PIXEL_PASS_BIG": "1"})


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,lanes", [("flat", 2), ("epanechnikov", 4), ("flat", 1)])
def test_ms_pixel_pass_synth(kernel, lanes, tmp_path):
    """ghdl --synth (to Verilog, as the Verilator/yosys flow does) of the default-size pass succeeds."""
    gen, _ = pass_generics(TrackerParams(kernel=kernel), FixedParams(), lanes)
    hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v")


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,lanes,ram_lat", [("flat", 4, 4), ("epanechnikov", 2, 1), ("flat", 1, 3)])
def test_ms_pixel_pass_orient_ghdl(kernel, lanes, ram_lat, hdl_waves):
    """N_ORIENT 9 (joint bins 9 u + o: colour u on ram_data, orientation o on ram_obin, both RAM_LAT clocks
    after the address; RAM_LAT 4 = core v2's, no delay stage, 1 and 3: 3 and 1 stages): every bank of
    every address read through bin_*_all, value by value against ms_histogram on the joint bins."""
    gen, cfg = pass_generics(TrackerParams(colour_bits=2, kernel=kernel), SMALL_FP, lanes)
    gen["RAM_LAT"] = cfg["RAM_LAT"] = ram_lat
    gen["N_ORIENT"] = cfg["N_ORIENT"] = 9
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps(cfg), "MS_PIXEL_PASS_N": "8"})


@pytest.mark.ghdl
def test_ms_pixel_pass_synth_orient9(tmp_path):
    """ghdl --synth of the default-size pass (LANES 4) with N_ORIENT 9 (joint bins; the input ram_obin and
    the banked read port bin_*_all).  Its values are checked through ms_meanshift (tb/test_ms_meanshift.py
    test_ms_meanshift_orient_*)."""
    gen, _ = pass_generics(TrackerParams(), FixedParams(), 4)
    v = hdl.ghdl_to_verilog(TOP, {**gen, "N_ORIENT": 9}, hdl.rtl_sources(TOP),
                            out_path=tmp_path / f"{TOP}.v").read_text()
    assert "module ms_pixel_pass" in v and "ram_obin" in v and "bin_sy_all" in v


@pytest.mark.verilator
@pytest.mark.parametrize("kernel,lanes", [("epanechnikov", 2)])
def test_ms_pixel_pass_verilator(kernel, lanes, hdl_waves):
    """Same bench on the GHDL -> Verilog -> Verilator netlist (the synthesis path)."""
    gen, cfg = pass_generics(TrackerParams(colour_bits=2, kernel=kernel), SMALL_FP, lanes)
    hdl.run_verilator(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps(cfg)})
