"""cocotb test bench + pytest entry points for rtl/ms_job_demand.vhd: a live target's next job
(decimation, window, region, worst clocks, first, release and next line) from its state, against
``mstrack.fixed.multi_capacity.ms_job_demand``.

States:
* every frame's state of FixedTrackerV2 on real sequences (Deer: lost at D = 8 and 16, Football1:
  losses, MotorRolling: D = 2 and scale, Couple: 704 x 400), replayed value by value;
* targets at the frame's corners and edges (the region clamped to the interior, next_line cut to 0),
  the largest sizes (D = 8, 16 while lost; the window limited by the frame), the smallest (3 x 3 px);
* random states on frames from 64 x 48 to 1920 x 1080 (lost or not).
Two trackers: the default tracker v2 (joint bins, the gated scale test) and mstrack-v2-colour, with the
generics ``mstrack.hw.multi_core.job_demand_generics`` derives from their parameters.  Every output of every job is compared.

Run: ``.venv/bin/python -m pytest tb/test_ms_job_demand.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.formats import FixedParams
from mstrack.fixed.multi_capacity import _geometry, ms_job_demand
from mstrack.hw import hdl
from mstrack.hw.multi_core import job_demand_generics
from mstrack.track.params import V2_COLOUR, TrackerParams

from v2_common import SEQ_ROOT, tracker_states

TRACKERS = {"v2": TrackerParams(preset="v2"), "v2-colour": TrackerParams(preset="v2", **V2_COLOUR)}
OUTPUTS = ("log2_d", "wd", "hd", "reg_x", "reg_y", "reg_w", "reg_h", "clocks", "first_line", "release_line",
           "next_line")
REAL_SEQS = ("Deer", "Football1", "MotorRolling", "Couple")
FRAMES = [(64, 48), (128, 96), (320, 240), (640, 360), (704, 400), (1280, 720), (1920, 1080), (1023, 577)]


def model(s: dict[str, int], tp: TrackerParams) -> tuple[int, ...]:
    fp = FixedParams()
    shape = (s["frame_h"], s["frame_w"])
    c8 = (s["c8x"], s["c8y"])
    dm = ms_job_demand(s["w8"], s["h8"], c8, bool(s["lost"]), shape, 0, tp, fp)
    g = _geometry(s["w8"], s["h8"], c8, bool(s["lost"]), s["frame_w"], s["frame_h"], tp, fp)
    assert (g.d, g.region.h, g.region.w) == (dm.d, dm.rows, dm.cols)
    return (g.d.bit_length() - 1, dm.wd, dm.hd, g.region.x, g.region.y, dm.cols, dm.rows, dm.clocks,
            dm.first_line, dm.release_line, dm.next_line)


def synthetic_states(rng: random.Random, n: int) -> list[dict[str, int]]:
    out = []
    for fw, fh in FRAMES:                               # corners, edges, the largest and smallest sizes
        for w, h in ((3, 3), (fw - 2, fh - 2), (fw // 3, fh // 2), (40, 100)):
            for x, y in ((0, 0), (fw - 1, fh - 1), (fw // 2, 0), (0, fh // 2), (fw // 2, fh // 2)):
                for lost in (0, 1):
                    out.append({"w8": w << 8, "h8": h << 8, "c8x": x << 8, "c8y": y << 8, "lost": lost,
                                "frame_w": fw, "frame_h": fh})
    for _ in range(n):
        fw, fh = rng.choice(FRAMES)
        w8 = rng.randint(3 << 8, (fw - 2) << 8) if rng.random() < 0.2 else rng.randint(3 << 8, min(fw, 200) << 8)
        h8 = rng.randint(3 << 8, (fh - 2) << 8) if rng.random() < 0.2 else rng.randint(3 << 8, min(fh, 200) << 8)
        out.append({"w8": w8, "h8": h8, "c8x": rng.randint(0, (fw << 8) - 1), "c8y": rng.randint(0, (fh << 8) - 1),
                    "lost": int(rng.random() < 0.4), "frame_w": fw, "frame_h": fh})
    return out


@cocotb.test()
async def job_demand(dut):
    cfg = json.loads(os.environ["MSTRACK_JOB_DEMAND"])
    tp = TRACKERS[cfg["tracker"]]
    for sig in ("rst", "start", "lost"):
        getattr(dut, sig).value = Immediate(0)
    for sig in ("w8", "h8", "c8x", "c8y"):
        getattr(dut, sig).value = Immediate(3 << 8)
    dut.frame_w.value = Immediate(64)
    dut.frame_h.value = Immediate(48)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    rng = random.Random(7)
    states = synthetic_states(rng, int(cfg["random"]))
    if cfg.get("real"):
        states += tracker_states(REAL_SEQS, 80, tp)
    bad, worst = [], 0
    for s in states:
        for k, v in s.items():
            getattr(dut, k).value = v
        dut.start.value = 1
        await RisingEdge(dut.clk)                       # taken: busy is '0' between jobs
        dut.start.value = 0
        for k, w in (("w8", len(dut.w8)), ("c8x", len(dut.c8x))):   # inputs change while busy: must not matter
            getattr(dut, k).value = rng.getrandbits(w)
        t = 0
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            t += 1
            if int(dut.done.value):
                break
            assert t < 2000, f"no done after {t} clocks for {s}"
        worst = max(worst, t)
        got = tuple(int(getattr(dut, o).value) for o in OUTPUTS)
        exp = model(s, tp)
        if got != exp:
            bad.append(f"{s}: got {dict(zip(OUTPUTS, got))}, model {dict(zip(OUTPUTS, exp))}")
        await RisingEdge(dut.clk)
        assert not int(dut.busy.value), "busy after done"
    assert not bad, f"{len(bad)} of {len(states)} jobs differ, first: " + "; ".join(bad[:3])
    dut._log.info("%d jobs match the model (%s); at most %d clocks start -> done", len(states), cfg["tracker"], worst)


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_job_demand"
MODULE = "test_ms_job_demand"


def _run(tracker: str, sim, waves: bool, real: bool, n_random: int) -> None:
    sim(TOP, MODULE, job_demand_generics(TRACKERS[tracker]), hdl.rtl_sources(TOP), waves=waves,
        build_name=f"{sim.__name__}_{TOP}_{tracker}",
        extra_env={"MSTRACK_JOB_DEMAND": json.dumps({"tracker": tracker, "real": real, "random": n_random})})


@pytest.mark.ghdl
def test_ms_job_demand_real(hdl_waves):
    """Tracker v2's states on real frames, and the synthetic ones."""
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"the real-frame states need the dev sequences in {SEQ_ROOT} (../shared)")
    _run("v2", hdl.run_ghdl, hdl_waves, True, 300)


@pytest.mark.ghdl
def test_ms_job_demand_colour(hdl_waves):
    """mstrack-v2-colour (no scale test: its own job clocks), synthetic states."""
    _run("v2-colour", hdl.run_ghdl, hdl_waves, False, 300)


@pytest.mark.verilator
def test_ms_job_demand_verilator(hdl_waves):
    """The GHDL -> Verilog netlist under Verilator."""
    _run("v2", hdl.run_verilator, hdl_waves, False, 300)
