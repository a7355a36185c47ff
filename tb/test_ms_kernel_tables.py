"""cocotb test bench + pytest entry points for rtl/ms_kernel_tables.vhd.

A monitor records every write of the table port; after `done` the tables,
ex, ey and kd_d are compared with mstrack.fixed.blocks.ms_kernel(w, h, kernel,
KERNEL_BITS) for many target sizes (3x3, odd/even, thin, max size).  Entries
beyond ex (TA, KA) / ey (TB, KB) are never used by ms_kernel; they are checked
to be the exact TA/TB and the saturating KA/KB (ms_divider of the model).
XR[i] (row extent of the ellipse, for ms_window_scan) is checked against
:func:`model_xr`, computed from the model's TA, TB, D (and its ``inside`` mask),
and the start -> done latency against the documented formula.

Tracker v2 (``v2_windows``, through tb/ms_kernel_tables_tb_top.vhd, which keeps a copy of
every table write): the window size changes every frame, so the tables are recomputed per
frame for any (wd, hd) = ms_window_size output, 3 .. max_window each, odd and even.  Every one
of these sizes (the full grid, in a random order, each start right after the previous done) is
compared with ``ms_kernel(wd, hd, "flat", KERNEL_BITS)``: ex, ey, D, TA, TB, XR and KA, KB,
which v2 needs with the flat kernel (d2q = KA[|dx|] + KB[|dy|] of ms_target_stats), so the
tables run with KERNEL_EPAN = 1 (divider in) while the pixel pass stays flat.  The start ->
done latency is asserted against the documented formula for every size.

Run: ``.venv/bin/python -m pytest tb/test_ms_kernel_tables.py``.
"""

from __future__ import annotations

import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time

from mstrack.fixed.blocks import ms_kernel
from mstrack.fixed.primitives import ms_divider
from mstrack.hw.hdl import dut_generics


def model_xr(ker: ms_kernel, n: int) -> list[int]:
    """XR[i], i = 0 .. n - 1: largest dx in 0..ex with TA[dx] + TB[i] < D (0 if none, i.e. i > ey)."""
    xr = []
    for i in range(n):
        if i > ker.ey:
            xr.append(0)
            continue
        inside = [dx for dx in range(ker.ex + 1) if int(ker.TA[dx]) + int(ker.TB[i]) < ker.D]
        assert inside and inside[0] == 0
        # same as the model's inside mask: row dy = +-i holds exactly |dx| <= XR[i]
        row = ker.inside[ker.ey + i]
        assert row.tolist() == [abs(dx) <= inside[-1] for dx in range(-ker.ex, ker.ex + 1)]
        xr.append(inside[-1])
    return xr


class TB:
    def __init__(self, dut):
        self.dut = dut
        self.g = dut_generics()
        self.max_half = int(self.g["MAX_HALF_TB"]) if "MAX_HALF_TB" in self.g else (1 << int(self.g["HALF_W"])) - 1
        self.epan = int(self.g["KERNEL_EPAN"])
        self.kb = int(self.g["KERNEL_BITS"])
        self.kval_w = int(self.g["KVAL_W"])
        self.half_w = int(self.g["HALF_W"])
        self.writes: list[tuple[int, int, int, int, int, int]] = []
        dut.rst.value = Immediate(1)
        dut.start.value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        cocotb.start_soon(self._monitor())

    async def _monitor(self):
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            if int(d.kt_we.value):
                self.writes.append((int(d.kt_addr.value), int(d.kt_ta.value), int(d.kt_tb.value),
                                    int(d.kt_ka.value), int(d.kt_kb.value), int(d.kt_xr.value)))

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)

    async def check(self, w: int, h: int):
        d = self.dut
        self.writes = []
        d.w.value = w
        d.h.value = h
        d.start.value = 1
        await RisingEdge(d.clk)
        d.start.value = 0
        n = 0
        while True:
            await RisingEdge(d.clk)
            n += 1
            if int(d.done.value):
                break
            assert n < 10000, "no done"
        await RisingEdge(d.clk)  # the monitor has seen the write that came with done
        ker = ms_kernel(w, h, "epanechnikov" if self.epan else "flat", self.kb)
        assert int(d.ex.value) == ker.ex and int(d.ey.value) == ker.ey, (w, h)
        assert int(d.kd_d.value) == ker.D, (w, h, int(d.kd_d.value), ker.D)
        n_last = max(ker.ex, ker.ey)
        xr = model_xr(ker, n_last + 1)
        walk = 2 * ker.ex - xr[n_last]  # set-up walk to TA[ex] + the down steps
        setup = 3 * (self.half_w + 1) + 3   # S_SETUP1, w^2/h^2 (HALF_W + 1), S_DINIT, D (2 HALF_W + 2), S_SETUP2
        exp_n = (2 * (n_last + 1) + self.kval_w + setup + 2 if self.epan else n_last + setup + 2) + walk
        assert n == exp_n, f"{w}x{h}: done after {n} clocks, documented {exp_n}"
        assert [a for a, *_ in self.writes] == list(range(n_last + 1)), f"{w}x{h}: addresses {self.writes}"
        got_xr = [x for *_, x in self.writes]
        assert got_xr == xr, f"{w}x{h}: XR {got_xr} != model {xr}"
        sat = (1 << self.kval_w) - 1
        for i, ta, tb, ka, kb, _ in self.writes:
            assert ta == 4 * i * i * h * h and tb == 4 * i * i * w * w, (w, h, i, ta, tb)
            if i <= ker.ex:
                assert ta == int(ker.TA[i]), (w, h, i)
            if i <= ker.ey:
                assert tb == int(ker.TB[i]), (w, h, i)
            if self.epan:
                if i <= ker.ex:
                    assert ka == int(ker.KA[i]), (w, h, i, ka, int(ker.KA[i]))
                if i <= ker.ey:
                    assert kb == int(ker.KB[i]), (w, h, i, kb, int(ker.KB[i]))
                assert ka == int(ms_divider((4 * i * i) << self.kb, w * w, self.kval_w)) <= sat
                assert kb == int(ms_divider((4 * i * i) << self.kb, h * h, self.kval_w)) <= sat
            else:
                assert ka == 0 and kb == 0
        return n


@cocotb.test()
async def tables(dut):
    tb = TB(dut)
    await tb.reset()
    mx = 2 * tb.max_half + 1
    sizes = [(3, 3), (3, mx), (mx, 3), (mx, mx), (4, 4), (mx - 1, mx - 1), (5, 8), (8, 5)]
    rng = random.Random(7)
    sizes += [(rng.randint(3, mx), rng.randint(3, mx)) for _ in range(30)]
    sizes += [(64, 64), (127, 127), (mx, 4), (4, mx)]
    sizes = [(w, h) for w, h in sizes if w <= mx and h <= mx]
    worst = 0
    for w, h in sizes:
        n = await tb.check(w, h)
        worst = max(worst, n)
        dut._log.debug("%dx%d: %d clocks", w, h, n)
    # documented bound (rtl/ms_kernel_tables.vhd header): n + S + 2 + 2 ex (+ n + 2 + KVAL_W when Epanechnikov)
    bound = 3 * tb.max_half + 3 * (tb.half_w + 1) + 5 + (tb.max_half + 2 + tb.kval_w if tb.epan else 0)
    assert worst <= bound, f"latency {worst} > bound {bound}"
    dut._log.info("%d sizes OK, worst latency %d clocks (bound %d)", len(sizes), worst, bound)


def documented_latency(ker: ms_kernel, xr: list[int], half_w: int, kval_w: int, epan: bool) -> int:
    """start -> done clocks of the rtl/ms_kernel_tables.vhd header."""
    n_last = max(ker.ex, ker.ey)
    walk = 2 * ker.ex - xr[n_last]
    setup = 3 * (half_w + 1) + 3
    return (2 * (n_last + 1) + kval_w + setup + 2 if epan else n_last + setup + 2) + walk


def unpack(v: int, width: int, n: int) -> list[int]:
    m = (1 << width) - 1
    return [(v >> (i * width)) & m for i in range(n)]


@cocotb.test()
async def v2_windows(dut):
    """Every v2 window size (wd, hd) in 3 .. MAX_WINDOW_TB, against ms_kernel(wd, hd, "flat", KB)."""
    g = dut_generics()
    mw, kb, kval_w = int(g["MAX_WINDOW_TB"]), int(g["KERNEL_BITS"]), int(g["KVAL_W"])
    half_w, kd_w, epan = int(g["HALF_W"]), int(g["KD_W"]), int(g["KERNEL_EPAN"]) == 1
    assert epan, "v2 needs KA/KB: run the tables with KERNEL_EPAN = 1"
    dut.rst.value = Immediate(1)
    dut.start.value = Immediate(0)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    sizes = [(w, h) for w in range(3, mw + 1) for h in range(3, mw + 1)]
    random.Random(11).shuffle(sizes)
    worst = 0
    for w, h in sizes:
        dut.w.value = w
        dut.h.value = h
        dut.start.value = 1
        await RisingEdge(dut.clk)
        t0 = int(get_sim_time("ns")) // 10
        dut.start.value = 0
        await RisingEdge(dut.done)
        # counted as ``tables`` does: up to the clock edge at which a consumer samples done = 1
        lat = int(get_sim_time("ns")) // 10 - t0 + 1
        await RisingEdge(dut.clk)            # the copy has the write that came with done
        await ReadOnly()
        ker = ms_kernel(w, h, "flat", kb)
        n = max(ker.ex, ker.ey) + 1
        ctx = f"{w}x{h}"
        assert (int(dut.ex.value), int(dut.ey.value), int(dut.kd_d.value)) == (ker.ex, ker.ey, ker.D), ctx
        assert int(dut.n_writes.value) == n and int(dut.order_err.value) == 0, f"{ctx}: writes not 0..{n - 1}"
        i = np.arange(n, dtype=np.int64)
        ta, tb = unpack(int(dut.tab_ta.value), kd_w, n), unpack(int(dut.tab_tb.value), kd_w, n)
        ka, kbt = unpack(int(dut.tab_ka.value), kval_w, n), unpack(int(dut.tab_kb.value), kval_w, n)
        xr = unpack(int(dut.tab_xr.value), half_w, n)
        # the model's tables (entries <= ex / ey); beyond them the exact TA/TB and saturating KA/KB
        exp_ta, exp_tb = (4 * i * i * h * h).tolist(), (4 * i * i * w * w).tolist()
        exp_ka = ms_divider((4 * i * i) << kb, w * w, kval_w).tolist()
        exp_kb = ms_divider((4 * i * i) << kb, h * h, kval_w).tolist()
        assert exp_ta[:ker.ex + 1] == ker.TA.tolist() and exp_ka[:ker.ex + 1] == ker.KA.tolist(), ctx
        assert exp_tb[:ker.ey + 1] == ker.TB.tolist() and exp_kb[:ker.ey + 1] == ker.KB.tolist(), ctx
        rows = ker.inside[ker.ey:].sum(axis=1)          # row |dy| = i holds |dx| <= XR[i]
        exp_xr = [(int(r) - 1) // 2 for r in rows] + [0] * (n - len(rows))
        assert ta == exp_ta and tb == exp_tb, f"{ctx}: TA/TB"
        assert ka == exp_ka and kbt == exp_kb, f"{ctx}: KA {ka} / {exp_ka}, KB {kbt} / {exp_kb}"
        assert xr == exp_xr, f"{ctx}: XR {xr} != {exp_xr}"
        exp_lat = documented_latency(ker, exp_xr, half_w, kval_w, epan)
        assert lat == exp_lat, f"{ctx}: done after {lat} clocks, documented {exp_lat}"
        worst = max(worst, lat)
        await RisingEdge(dut.clk)
    dut._log.info("%d window sizes (3..%d)^2 match ms_kernel(wd, hd, 'flat', %d); worst latency %d clocks",
                  len(sizes), mw, kb, worst)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_kernel_tables"
MODULE = "test_ms_kernel_tables"


def tables_generics(kernel: str, fp: FixedParams) -> dict:
    g = core_generics(TrackerParams(kernel=kernel), fp)
    return {k: g[k] for k in ("HALF_W", "KERNEL_EPAN", "KERNEL_BITS", "KVAL_W", "KD_W")}


CASES = [
    pytest.param("epanechnikov", FixedParams(), id="epan_default"),
    pytest.param("flat", FixedParams(), id="flat_default"),
    pytest.param("epanechnikov", FixedParams(max_half=7, margin=4), id="epan_mh7"),
    pytest.param("epanechnikov", FixedParams(kernel_bits=4), id="epan_kb4"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel,fp", CASES)
def test_ms_kernel_tables(kernel, fp, hdl_waves):
    gen = tables_generics(kernel, fp)
    # MAX_HALF is not a generic of the entity: pass it to the test through the generics env only
    import json
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, testcase="tables",
                 extra_env={hdl.GENERICS_ENV: json.dumps({**gen, "MAX_HALF_TB": fp.max_half})})


@pytest.mark.ghdl
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_ms_kernel_tables_synth(kernel, tmp_path):
    """ghdl --synth (to Verilog, as the Verilator/yosys flow does) succeeds."""
    gen = tables_generics(kernel, FixedParams())
    hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v")


V2_TOP = "ms_kernel_tables_tb_top"
V2_WRAPPER = hdl.TB_DIR / "ms_kernel_tables_tb_top.vhd"


def v2_tables_generics(tp: TrackerParams, fp: FixedParams) -> dict:
    """ms_kernel_tables as core v2 instantiates it: KA/KB computed (KERNEL_EPAN = 1, KVAL_W =
    KERNEL_BITS + 1) for the flat-kernel tracker's d2q; HALF_W, KD_W for windows up to max_window."""
    g = core_generics(tp.with_(kernel="epanechnikov", preset="paper", features="fused"), fp)
    return {k: g[k] for k in ("HALF_W", "KERNEL_EPAN", "KERNEL_BITS", "KVAL_W", "KD_W")}


V2_CASES = [
    pytest.param(TrackerParams(preset="v2"), FixedParams(), id="v2_default"),
    pytest.param(TrackerParams(preset="v2", max_window=31), FixedParams(max_half=15, margin=8, kernel_bits=6),
                 id="v2_w31_kb6"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("tp,fp", V2_CASES)
def test_ms_kernel_tables_v2(tp, fp, hdl_waves, request):
    """Every (wd, hd) window size tracker v2 can produce (3 .. max_window each)."""
    import json
    gen = v2_tables_generics(tp, fp)
    assert gen["KERNEL_EPAN"] == 1 and gen["KVAL_W"] == fp.kernel_bits + 1, gen
    hdl.run_ghdl(V2_TOP, MODULE, gen, hdl.rtl_sources(V2_TOP, extra=[V2_WRAPPER]), waves=hdl_waves,
                 testcase="v2_windows", build_name=f"ms_kernel_tables_{request.node.callspec.id}",
                 extra_env={hdl.GENERICS_ENV: json.dumps({**gen, "MAX_WINDOW_TB": tp.max_window})})
