"""Stream faults of core v2: rtl/ms_tracker_v2.vhd against the model, result by result.

The bench of tb/test_ms_tracker_faults.py (beat-by-beat driver with tuser / tlast per beat, input
gaps, frame size per frame, init boxes and resets at any clock, result consumer always / never /
random ready, lock-up watchdogs) with :class:`mstrack.hw.cosim.CoreModelV2` (FixedTrackerV2 plus the
stream, init and error behaviour of docs/architecture.md, "Core v2: stream faults"), which predicts
every field of every result word v2 (COMPARED_FIELDS_V2), error results included.

Directed cases (``DIRECTED``): the init frame bad in every way (the init stays pending; the next
good frame learns the background-weighted model from its first pixel, also after a frame cut by
its start of frame), faults while tracking and while lost (the search state is kept: the next good
frame is searched at D x 2), re-init / reset with an init pending.  Constrained random: the seeds
of the paper core's fuzz (``fuzz_seed``) on core v2.  Default v2 parameters, MAX_FRAME_W 64,
synthetic frames 32x24 .. 64x48.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import cocotb

from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import unpack_result_v2
from mstrack.hw.cosim import COMPARED_FIELDS_V2, CoreConfigV2, CoreModelV2
from mstrack.track.params import V2_COLOUR, TrackerParams
import test_ms_tracker_faults as faults
from test_ms_tracker_faults import H0, MAX_FRAME_W, W0, Bench, beats_of, kinds_of, play_plan, scene

ERROR = 6                       # status error (STATUS_V2)
LOST = 2


def core_config_v2() -> CoreConfigV2:
    # tracker v2 on colour alone (V2_COLOUR): the stream faults hit the same control path as with the
    # default joint bins, at a fifth of GHDL's time
    return CoreConfigV2(TrackerParams(preset="v2", **V2_COLOUR), FixedParams(), max_frame_w=MAX_FRAME_W)


class BenchV2(Bench):
    """Bench with core v2's generics, model and result word."""
    fields = COMPARED_FIELDS_V2

    def make_config(self) -> CoreConfigV2:
        return core_config_v2()

    def make_model(self) -> CoreModelV2:
        return CoreModelV2(self.cfg.tp, self.cfg.fp, MAX_FRAME_W)

    def unpack(self, word: int) -> dict[str, int]:
        return unpack_result_v2(word, self.g)


async def run_directed(dut, body, seed: int = 1, size: tuple[int, int] = (W0, H0)) -> Bench:
    return await faults.run_directed(dut, body, seed, size, bench=BenchV2)


def blank(w: int = W0, h: int = H0) -> np.ndarray:
    """A flat frame without the target (the tracker loses it)."""
    return np.full((h, w), 0x204060, dtype=np.int64)


# ----------------------------------------------------------------------------- directed cases
@cocotb.test()
async def init_frame_faults(dut):
    """The init frame bad in every way: short / long line, no start of frame, a missing tlast, a
    frame of another size (size_changed) or of a bad size: error with no_target, the init stays
    pending (its box in cx, cy, w8, h8), the next good frame learns and tracking follows."""
    async def body(b: BenchV2) -> None:
        fr, gt = scene(16, W0, H0, 31)
        plan = [("short_line", 20), ("long_line", H0 - 1), ("no_sof", 0), ("no_tlast", 5), ("sof_eol", 0),
                ("extra_lines", 2)]
        i = 0
        for f, arg in plan:
            await b.init(gt[i])
            await b.frame(fr[i], f, arg)
            await b.frame(fr[i + 1])
            i += 2
        await b.init(gt[i])
        b.set_size(40, 32)                              # the init frame in another size
        await b.frame(fr[i][:32, :40])
        b.set_size(1, H0)                               # a bad size
        await b.frame(fr[i])
        b.set_size(W0, H0)
        await b.frame(fr[i + 1])
        await b.frame(fr[i + 2])
        k = kinds_of(b)
        assert k == ["error:short_line", "init", "error:long_line", "init", "error:no_sof", "init",
                     "error:long_line", "init", "error:short_line", "init", "init", "error:no_sof", "track",
                     "error:size_changed", "error:size", "init", "track"], k
        for r, kind, nxt in zip(b.model.results, k, k[1:]):
            if kind.startswith("error") and nxt in ("init", "error:size"):
                assert r["status"] == ERROR and r["flags"] & (1 << 5), r        # no_target while pending
    await run_directed(dut, body)


@cocotb.test()
async def cut_init_frame(dut):
    """The init frame cut by the next start of frame (after 1 beat, a line, most of the frame, in
    its last line), also with a box in the top-left corner whose background ring holds pixel (0, 0),
    the first pixel of the frame that cuts: error cut (no_target) with that start of frame, and that
    frame, complete, is the init frame (ms_bg_model counts it from its first pixel).  Also the
    init frame cut by a start of frame of a bad size (error size) and by a tuser + tlast beat."""
    async def body(b: BenchV2) -> None:
        fr, gt = scene(16, W0, H0, 32)
        corner = (1, 1, 12, 10)
        for j, (box, cut) in enumerate([(corner, 1), (corner, W0), (gt[4], 1500), (corner, W0 * H0 - 3)]):
            await b.init(box)
            await b.frame(fr[3 * j], "cut", cut)
            await b.frame(fr[3 * j + 1])
            await b.frame(fr[3 * j + 2])
        await b.init(corner)
        await b.frame(fr[12], "cut", 900)
        b.set_size(MAX_FRAME_W + 1, H0)                 # the cutting start of frame has a bad size
        await b.frame(fr[12])
        b.set_size(W0, H0)
        await b.frame(fr[13], "cut", 600)
        await b.frame(fr[14], "sof_eol")                 # cut by a tuser beat that is also a tlast
        await b.frame(fr[15])
        k = kinds_of(b)
        assert k == ["error:cut", "init", "track"] * 4 + ["error:size", "error:short_line", "init"], k
    await run_directed(dut, body)


@cocotb.test()
async def tuser_stuck_init_frame(dut):
    """tuser stuck high on the first beats of the init frame (each beat cuts the one-pixel frame
    before it), then a cut init frame and a good one: one error per beat, the init stays pending,
    the good frame learns."""
    async def body(b: BenchV2) -> None:
        fr, _ = scene(4, 32, 24, 33)
        await b.init((1, 1, 12, 10))
        await b.frame(fr[0], "tuser_stuck", 40)
        await b.frame(fr[1])
        await b.frame(fr[2])
        k = kinds_of(b)
        assert k[0] == "error:cut" and k[-2:] == ["init", "track"], k
    await run_directed(dut, body, size=(32, 24))


@cocotb.test()
async def faults_while_tracking(dut):
    """Every fault class while tracking, with random input gaps and a random / stalled result
    consumer: error results with the target's cx, cy, w8, h8; the state is unchanged."""
    async def body(b: BenchV2) -> None:
        fr, gt = scene(20, W0, H0, 34)
        b.gap = 0.2
        b.ready(0.3)
        await b.init(gt[0])
        plan = [None, ("short_line", 3), None, ("long_line", 11), ("no_sof", 0), None, ("cut", 777),
                None, ("no_tlast", 9), ("extra_lines", 2), None, ("tuser_stuck", 4), None, ("sof_eol", 0),
                "size", None, "resize", ("cut", 50), ("short_line", 0), None]

        await play_plan(b, fr, plan, stall_every=7, stall_cycles=8_000, bad_width=2)
        names = {k.split(":")[-1] for k in kinds_of(b)}
        assert {"short_line", "long_line", "no_sof", "cut", "size", "size_changed", "track"} <= names, names
    await run_directed(dut, body)


@cocotb.test()
async def faults_while_lost(dut):
    """Faults while the target is lost (a flat frame without it): the search state is kept, so the
    next good frame is still searched (D x 2, 8 more start points) and re-acquires as the model."""
    async def body(b: BenchV2) -> None:
        fr, gt = scene(14, W0, H0, 19)
        flat = blank()
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1])
        await b.frame(flat)                             # lost
        await b.frame(flat, "short_line", 4)
        await b.frame(flat)                             # searched, still lost
        await b.frame(fr[5], "cut", 1000)
        await b.frame(flat, "long_line", 30)
        b.set_size(40, 32)
        await b.frame(fr[6][:32, :40])                  # size_changed while lost
        b.set_size(W0, 1)
        await b.frame(fr[6])                            # bad size while lost
        b.set_size(W0, H0)
        await b.frame(fr[7], "no_sof")
        await b.frame(fr[8])                            # searched: re-acquired
        await b.frame(fr[9])
        await b.frame(flat)
        await b.frame(fr[10], "extra_lines", 1)         # a good frame (tracked, lost) + no_sof
        await b.frame(fr[11])
        k = kinds_of(b)
        res = b.model.results
        assert k[:5] == ["init", "track", "track", "error:short_line", "track"], k
        assert res[2]["status"] == LOST and res[4]["status"] == LOST and res[4]["searched"] == 8, res[2:5]
        searched = [r["searched"] for r, kk in zip(res, k) if kk == "track"]
        assert searched.count(8) >= 3, searched
        assert {"error:short_line", "error:cut", "error:long_line", "error:size_changed", "error:size",
                "error:no_sof"} <= set(k), k
    await run_directed(dut, body)


@cocotb.test()
async def reinit_and_reset_pending(dut):
    """Init boxes and resets around a pending init: a box offered mid-frame (taken after the frame),
    a rejected box while an init is pending (the pending init stays, flag rejected), a re-init while
    lost, a reset while the init frame streams and while its background model learns."""
    async def body(b: BenchV2) -> None:
        fr, gt = scene(16, W0, H0, 35)
        await b.init(gt[0])
        await b.frame(fr[0])
        bt = beats_of(fr[1])
        await b.send(bt[:700])
        b.offer_init(gt[1])                             # mid-frame: taken after this frame
        await b.send(bt[700:])
        while b.init_task is not None:                  # taken after the frame's last beat
            await b.idle(16)
        await b.init((-40, -40, 20, 20))                # rejected: the pending init stays
        await b.frame(fr[2], "short_line", 3)
        await b.frame(fr[3])
        await b.frame(blank())                          # lost
        await b.init(gt[5])                             # re-init while lost
        await b.frame(fr[5])
        await b.frame(fr[6])
        await b.init(gt[7])
        bt = beats_of(fr[7])
        await b.send(bt[:1000])
        await b.reset()                                 # reset while the init frame streams
        await b.init(gt[8])
        await b.frame(fr[8])                            # init frame; reset while it learns
        await b.idle(400)
        await b.reset()
        await b.init((1, 1, 12, 10))
        await b.frame(fr[9], "cut", 30)
        await b.frame(fr[10])
        await b.frame(fr[11])
        await b.drain()
        assert [k for k, e in zip(kinds_of(b), b.model.epochs) if e == 0] == \
            ["init", "track", "error:short_line", "init", "track", "init", "track"], kinds_of(b)
        assert b.model.results[2]["flags"] & (1 << 4), "rejected flag expected"
        assert [k for k, e in zip(kinds_of(b), b.model.epochs) if e == 2] == ["error:cut", "init", "track"]
    await run_directed(dut, body)


DIRECTED = ["init_frame_faults", "cut_init_frame", "tuser_stuck_init_frame", "faults_while_tracking",
            "faults_while_lost", "reinit_and_reset_pending"]


@cocotb.test()
async def fuzz(dut):
    """Constrained-random protocol test on core v2: seeds ``first:count`` of MSTRACK_FUZZ."""
    await faults.run_fuzz(dut, BenchV2, "v2 fuzz", "make test-fuzz-v2 SEEDS={seed} N=1")


# ----------------------------------------------------------------------------- pytest side
def _run(testcase, env: dict[str, str]) -> None:
    """Verilator on the GHDL netlist when installed (C++ at run_verilator's -O1, hdl.VERILATOR_CXX_O1),
    else GHDL (MSTRACK_FAULTS_SIM=ghdl forces it)."""
    from mstrack.hw.hdl import have_verilator, run_ghdl, run_verilator
    verilator = os.environ.get("MSTRACK_FAULTS_SIM", "verilator") == "verilator" and have_verilator()
    kw = dict(generics=core_config_v2().generics(), testcase=testcase, extra_env=env)
    if verilator:
        run_verilator("ms_tracker_v2", "test_ms_tracker_v2_faults", build_name="ms_tracker_v2_faults_o1", **kw)
    else:
        run_ghdl("ms_tracker_v2", "test_ms_tracker_v2_faults", build_name="ms_tracker_v2_faults", **kw)


@pytest.mark.long
@pytest.mark.verilator
def test_tracker_v2_faults():
    """The directed stream-fault cases of core v2 in one simulation, every field of every result
    compared with CoreModelV2.  Marker ``long``: `make test` runs it on the second core after the
    netlist build (CI time: the Verilator build of core v2 is the larger part)."""
    _run(DIRECTED, {})


@pytest.mark.long
@pytest.mark.verilator
def test_tracker_v2_fuzz(tmp_path):
    """Seeds of the constrained-random protocol test on core v2 (MSTRACK_FUZZ=first:count, default 1:3)."""
    seeds = os.environ.get("MSTRACK_FUZZ", "1:3")
    rep = Path(os.environ.get("MSTRACK_FUZZ_REPORT") or tmp_path / "fuzz_v2.json")
    _run("fuzz", {"MSTRACK_FUZZ": seeds, "MSTRACK_FUZZ_REPORT": str(rep)})
    s = json.loads(rep.read_text())
    assert s["seeds"] == int(seeds.split(":")[1]) and s["results"] > 0
    print(f"\nv2 fuzz seeds {seeds}: {s['results']} results, {s['beats']} beats, {s['seconds']} s")
