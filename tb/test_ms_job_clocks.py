"""cocotb test bench + pytest entry points for rtl/ms_job_clocks.vhd: one target's worst-case job
clocks on the shared engine, against ``mstrack.fixed.multi_capacity.job_clocks``.

Two trackers: the default tracker v2 (joint bins, the gated scale test at 0.05: a second pixel pass
at the larger window) and mstrack-v2-colour (colour bins, no scale test), with the generics
``mstrack.hw.multi_core.job_clocks_generics`` gives them.  Jobs: track, lost and init on the
corner windows (3 and 127) and random odd ones, a window limit between the window and 127 (the
scale test's window clipped to it), init rectangles up to 290 x 290.  Every result value by value.

Run: ``.venv/bin/python -m pytest tb/test_ms_job_clocks.py``.
"""
from __future__ import annotations

import json
import os
import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.multi_capacity import job_clocks
from mstrack.hw.multi_core import job_clocks_generics
from mstrack.track.params import V2_COLOUR, TrackerParams

KINDS = {"track": 0, "lost": 1, "init": 2}
TRACKERS = {"v2": TrackerParams(preset="v2"), "v2-colour": TrackerParams(preset="v2", **V2_COLOUR)}


def jobs(rng: random.Random, n: int) -> list[tuple[str, int, int, int, tuple[int, int]]]:
    out = []
    for kind in KINDS:
        for wd, hd in ((3, 3), (127, 127), (3, 127), (127, 3)):
            out.append((kind, wd, hd, max(wd, hd), (3, 3)))
    for _ in range(n):
        wd, hd = rng.randrange(3, 128, 2), rng.randrange(3, 128, 2)
        lim = rng.choice([max(wd, hd), rng.randint(max(wd, hd), 127), 127])
        out.append((rng.choice(list(KINDS)), wd, hd, lim, (rng.randint(3, 290), rng.randint(3, 290))))
    return out


@cocotb.test()
async def run_test(dut):
    tp = TRACKERS[json.loads(os.environ["MSTRACK_JOB"])["tracker"]]
    for s in ("rst", "start"):
        getattr(dut, s).value = Immediate(0)
    for s in ("kind", "wd", "hd", "lim", "ring_rows", "ring_cols"):
        getattr(dut, s).value = Immediate(3)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    n_checked = 0
    worst = 0
    for kind, wd, hd, lim, ring in jobs(random.Random(3), 40):
        dut.kind.value, dut.wd.value, dut.hd.value, dut.lim.value = KINDS[kind], wd, hd, lim
        dut.ring_rows.value, dut.ring_cols.value = ring
        dut.start.value = 1
        await RisingEdge(dut.clk)
        dut.start.value = 0
        for n in range(1, 1000):
            await RisingEdge(dut.clk)
            await ReadOnly()
            if int(dut.done.value):
                break
        else:
            raise AssertionError(f"{kind} {wd}x{hd}: no done")
        worst = max(worst, n)
        want = job_clocks(kind, wd, hd, tp, ring=ring, window_limit=lim)  # type: ignore[arg-type]
        got = int(dut.clocks.value)
        assert got == want, f"{kind} {wd}x{hd} lim {lim} ring {ring}: {got} clocks, model {want}"
        n_checked += 1
        await RisingEdge(dut.clk)
    assert worst <= 2 * 223 + 12, f"latency {worst}"
    dut._log.info("%d jobs equal the model; start -> done at most %d clocks", n_checked, worst)


from mstrack.hw import hdl  # noqa: E402

TOP = "ms_job_clocks"
MODULE = "test_ms_job_clocks"


@pytest.mark.ghdl
@pytest.mark.parametrize("tracker", list(TRACKERS))
def test_ms_job_clocks(tracker, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, job_clocks_generics(TRACKERS[tracker]), hdl.rtl_sources(TOP), waves=hdl_waves,
                 build_name=f"ms_job_clocks_{tracker}", extra_env={"MSTRACK_JOB": json.dumps({"tracker": tracker})})


@pytest.mark.verilator
def test_ms_job_clocks_verilator(hdl_waves):
    """The netlist under Verilator (the constant products, the elaboration-time table of up())."""
    hdl.run_verilator(TOP, MODULE, job_clocks_generics(TRACKERS["v2"]), hdl.rtl_sources(TOP), waves=hdl_waves,
                      build_name="ms_job_clocks_verilator", extra_env={"MSTRACK_JOB": json.dumps({"tracker": "v2"})})
