"""Cycle count of ms_tracker on the worst case: a 64x64 target, 20 mean-shift iterations.

cocotb module and pytest entry point in one file (the bench is tb/test_ms_tracker.py's TB).
Two 256x192 frames: the init frame and a frame whose scene drifted by 70 px along the
diagonal.  The scene is a dither of two colours whose mixing ratio ramps slowly along x + y,
so that the colour engine's weighted centroid moves by about 1.5 px per iteration, never less
than 1 px, and rho keeps rising: the colour loop stops at MAX_ITER = 20 (the edge loop stops
earlier; both run in parallel and the frame waits for the later one).  The model confirms
the iteration counts before the simulation starts.

Asserted: every result field bit-exact with the fixed model, and the cycles from the last
pixel of each frame to its result equal :func:`mstrack.hw.synth.frame_latency` computed from the
block latencies and the window positions of each pass (the model's trace,
:func:`mstrack.hw.synth.model_latencies`).  Two simulators: the Verilator C++ harness
(:mod:`mstrack.hw.fastsim`, seconds per run once built; LANES 2, 4, 8) and GHDL + cocotb on the
VHDL (default LANES; minutes).  Reports: build/synth/cycles_64x64_lanes<L>[_ghdl].json, quoted
by docs/performance.md.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import cocotb
from cocotb.triggers import ClockCycles

from mstrack.hw.cosim import CoreConfig, diff_fields, expected_results
from mstrack.fixed import FixedParams
from mstrack.track.params import TrackerParams

W, H = 256, 192
BOX = (W // 2 - 32, H // 2 - 32, 64, 64)
DRIFT = 70          # px along the diagonal between the two frames
REPORT = Path(__file__).resolve().parents[1] / "build" / "synth" / "cycles_64x64.json"


def scene(drift: float = 0.0, p0: float = 0.4, slope: float = 0.007) -> np.ndarray:
    """(H, W, 3) uint8 BGR: colour A where a low-discrepancy dither is below P(u), else B,
    P(u) = p0 + slope (u - drift - mean u), u = (x + y) / sqrt 2 (clipped to 0..1)."""
    yy, xx = np.mgrid[0:H, 0:W]
    u = (xx + yy) / np.sqrt(2.0)
    t = np.mod(xx * 0.7548776662 + yy * 0.5698402910, 1.0)
    p = np.clip(p0 + slope * (u - drift - u.mean()), 0.0, 1.0)
    a = np.array([40, 40, 208], np.uint8)
    b = np.array([194, 144, 40], np.uint8)
    return np.where((t < p)[..., None], a, b).astype(np.uint8)


def frames() -> list[np.ndarray]:
    return [scene(0.0), scene(DRIFT)]


def expected_cycles(lanes: int) -> dict:
    """Model iterations and analytic latency per frame (window positions from the model's trace)."""
    from mstrack.hw import synth
    m = synth.model_latencies(frames(), BOX, "default", lanes=lanes)
    return {"latency": [f["latency"] for f in m], "iter_c": m[1]["iter_c"], "iter_e": m[1]["iter_e"],
            "engine_c": m[1]["engine_c"], "engine_e": m[1]["engine_e"]}


# ----------------------------------------------------------------------------- cocotb side
@cocotb.test()
async def worst_case(dut):
    """Init + one 20-iteration frame; results bit-exact, cycles recorded."""
    import test_ms_tracker as sys_tb          # the system bench: TB, lines_of, recv_result
    job = json.loads(os.environ["MSTRACK_JOB"])
    cfg = CoreConfig(TrackerParams(), FixedParams(), lanes=job["lanes"], max_frame_w=job["max_frame_w"])
    g = cfg.generics()
    fr = frames()
    exp = expected_results(fr, BOX, cfg.tp, cfg.fp)
    tb = sys_tb.TB(dut, job)
    await tb.reset(W, H)
    cocotb.start_soon(tb.monitor(H))
    await tb.init(BOX)
    for f in fr:
        for line in sys_tb.lines_of(f):
            tb.source.send_nowait(line)
    bad = []
    for i in range(len(fr)):
        got = await sys_tb.recv_result(tb, g, 400_000)
        d = diff_fields(got, exp[i])
        if d:
            bad.append(f"frame {i}: " + "; ".join(d))
    await ClockCycles(dut.clk, 10)
    lat = [r - b for b, r in zip(tb.last_beat_cycles, tb.result_cycles)]
    Path(job["report"]).write_text(json.dumps({"latency_cycles": lat, "stall_cycles": tb.stall_cycles,
                                               "iter_c": [e["iter_c"] for e in exp],
                                               "iter_e": [e["iter_e"] for e in exp], "mismatches": bad}))
    assert not bad, "\n".join(bad)


# ----------------------------------------------------------------------------- pytest side
def _check(lanes: int, latency: list[int], mismatches: list[str]) -> dict:
    from mstrack.hw import synth
    want = expected_cycles(lanes)
    assert want["iter_c"] == 20, want                                   # the scene does its job
    assert not mismatches, "\n".join(mismatches)
    assert latency == want["latency"], (latency, want)
    assert latency[1] < synth.VBLANK_1080P60
    return want


@pytest.mark.verilator
@pytest.mark.parametrize("lanes", [2, 4, 8])
def test_worst_case_cycles(lanes):
    """Verilator (GHDL netlist, C++ harness: mstrack.hw.fastsim): results bit-exact, latency per
    frame = analytic model, for LANES 2, 4 (default) and 8."""
    from mstrack.hw import fastsim
    run = fastsim.simulate(frames(), BOX, TrackerParams(), FixedParams(), lanes=lanes, lead=1000)
    exp = expected_results(frames(), BOX, TrackerParams(), FixedParams())
    lat = [r["latency"] for r in run.results]
    want = _check(lanes, lat, fastsim.compare(run.results, exp))
    REPORT.parent.mkdir(parents=True, exist_ok=True)
    REPORT.with_name(f"cycles_64x64_lanes{lanes}.json").write_text(json.dumps(
        {"simulator": "verilator (mstrack.hw.fastsim)", "latency_cycles": lat, "model": want,
         "cycles": run.cycles, "cpu_seconds": run.cpu_seconds, "build_seconds": run.build_seconds}, indent=1))


@pytest.mark.ghdl
def test_worst_case_cycles_ghdl():
    """GHDL + cocotb (cocotbext-axi source and sink), default generics: the same check on the
    VHDL itself rather than the GHDL-synthesised netlist (slower: minutes)."""
    from mstrack.hw.hdl import run_ghdl
    cfg = CoreConfig(TrackerParams(), FixedParams(), max_frame_w=2048)
    lanes = cfg.lanes
    rep = REPORT.with_name(f"cycles_64x64_lanes{lanes}_ghdl.json")
    rep.parent.mkdir(parents=True, exist_ok=True)
    job = {"lanes": lanes, "max_frame_w": 2048, "report": str(rep)}
    run_ghdl("ms_tracker", "test_ms_tracker_cycles", generics=cfg.generics(),
             build_name=f"ms_tracker_cycles_l{lanes}", extra_env={"MSTRACK_JOB": json.dumps(job)})
    got = json.loads(rep.read_text())
    got.update(simulator="ghdl + cocotb", model=_check(lanes, got["latency_cycles"], got["mismatches"]))
    rep.write_text(json.dumps(got, indent=1))
