"""mstrack.hw.cosim_multi.CoreModelMulti, the stream-level model of the multi-target core ms_tracker_multi
(docs/multi_target_core.md, "Ports and result stream"), against what it is built from: core v2's
model for one target, single fixed-point trackers for several, and the multi-target result word's
layout; refusals, faults and frames without a live target; with the capacity rule of the shared-engine
core, against mstrack.MultiTracker(model="fixed") under the same rule."""
from __future__ import annotations

import numpy as np
import pytest

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.fixed.vhdl_pkg import (RESULT_FLAGS, STATUS_V2, pack_result_multi, result_fields_v2,
                                    result_layout_multi, result_width_multi, unpack_result_multi)
from mstrack.hw.cosim import COMPARED_FIELDS_V2, ERR_SHORT_LINE, CoreModelV2, frame_words
from mstrack.hw.cosim_multi import CMD_BOX, CMD_CYCLES, CMD_OK, CMD_REFUSED, CoreModelMulti, Outcome
from mstrack.io.synthetic import make_multi_scene, make_scene
from mstrack.track.params import TrackerParams
from mstrack.track.tracker import Tracker

TP, FP = TrackerParams(preset="v2"), FixedParams()
FLAG = {f: 1 << i for i, f in enumerate(RESULT_FLAGS)}
ERROR = STATUS_V2.index("error")


def _beats(words: np.ndarray, fault: str | None = None) -> list[tuple[int, int, int]]:
    """One frame's beats; short_line: row 5 three pixels short."""
    h, w = words.shape
    out = []
    for y, row in enumerate(words):
        px = [int(v) for v in row][: w - 3 if fault == "short_line" and y == 5 else w]
        out += [(v, int(y == 0 and x == 0), int(x == len(px) - 1)) for x, v in enumerate(px)]
    return out


def _feed(m, words: np.ndarray, fault: str | None = None) -> None:
    h, w = words.shape
    for b in _beats(words, fault):
        m.beat(*b, w, h)


def _v2(word: dict[str, int]) -> dict[str, int]:
    return {k: word[k] for k in COMPARED_FIELDS_V2}


def test_result_word_layout() -> None:
    """Result word v2 with the 4-bit id at bits 163..160; round trip; an id that does not fit raises."""
    assert result_layout_multi()[-1] == ("target_id", 160, 4) and result_width_multi() == 164
    f = {"cx": 1234, "cy": 99, "w8": 256 * 30, "h8": 256 * 40, "rho": 40000, "confidence": 65536, "status": 3,
         "iter": 5, "stop": 1, "decim_log2": 2, "searched": 8, "flags": 5, "err_code": 0, "frame_count": 77,
         "target_id": 13}
    word = pack_result_multi(f)
    assert word >> 160 == 13
    assert {k: v for k, v in unpack_result_multi(word).items() if k in f} == f
    with pytest.raises(ValueError, match="target_id"):
        pack_result_multi({**f, "target_id": 16})


@pytest.mark.parametrize("n", [1, 3])
def test_one_target_is_core_v2(n) -> None:
    """One add (before the first frame), a stream fault on the init frame and two after it: with 1 or 3
    slots every word equals core v2's result (CoreModelV2), with id 0."""
    frames, gt = make_scene(9, 48, 40, seed=19, target_size=(14, 12))
    words = [frame_words(f) for f in frames]
    box = round_box(*map(float, gt[0]))
    m, v = CoreModelMulti(TP, FP, 64, max_targets=n), CoreModelV2(TP, FP, 64)
    assert m.add(box, 48, 40) == 0
    v.init(box, 48, 40)
    for i, f in enumerate(words):
        fault = {0: "short_line", 3: "short_line", 6: "short_line"}.get(i)
        _feed(m, f, fault)
        _feed(v, f, fault)
    assert [len(f) for f in m.frames] == [1] * 9
    assert [_v2(w) for w in m.results] == [_v2(r) for r in v.results]
    assert all(w["target_id"] == 0 for w in m.results)
    assert v.kinds[:2] == ["error:short_line", "init"] and m.results[3]["err_code"] == ERR_SHORT_LINE


def _multi(n: int = 10, **kw):
    frames, rows = make_multi_scene(n, 96, 80, n_targets=3, seed=3, **kw)
    boxes = {(int(r[0]), int(r[1])): tuple(int(v) for v in r[2:6]) for r in rows}
    return [frame_words(f) for f in frames], frames, boxes


def _single(frames: np.ndarray, box, first: int, last: int) -> list[dict[str, int]]:
    """A single fixed-point tracker v2 from frame ``first`` to ``last`` (inclusive): result word v2 fields."""
    t = Tracker(model="fixed", params=TP)
    out = [t.init(frames[first], box)]
    out += [t.update(frames[i]) for i in range(first + 1, last + 1)]
    return [result_fields_v2(r.extra) for r in out]


def test_targets_added_and_removed_match_single_trackers() -> None:
    """Targets 1, 2 added before frame 0, target 3 before frame 3, slot 0 removed before frame 5 and given
    to target 1 again before frame 7: each frame's words are in slot order, one per live target, each
    equal to a single fixed-point tracker of that target from its add, the frame count the same."""
    words, frames, boxes = _multi()
    m = CoreModelMulti(TP, FP, 128, max_targets=3)
    cmds = {0: [("add", 1), ("add", 2)], 3: [("add", 3)], 5: [("remove", 0)], 7: [("add", 1)]}
    for i, f in enumerate(words):
        for op, arg in cmds.get(i, []):
            m.add(boxes[(i, arg)], 96, 80) if op == "add" else m.remove(arg)
        _feed(m, f)
    ids = [[w["target_id"] for w in fr] for fr in m.frames]
    assert ids == [[0, 1]] * 3 + [[0, 1, 2]] * 2 + [[1, 2]] * 2 + [[0, 1, 2]] * 3
    assert m.outcomes == [Outcome(CMD_OK, 0), Outcome(CMD_OK, 1), Outcome(CMD_OK, 2), Outcome(CMD_OK, 0),
                          Outcome(CMD_OK, 0)]
    runs = {(0, 0): _single(frames, boxes[(0, 1)], 0, 4), (1, 0): _single(frames, boxes[(0, 2)], 0, 9),
            (2, 3): _single(frames, boxes[(3, 3)], 3, 9), (0, 7): _single(frames, boxes[(7, 1)], 7, 9)}
    for i, fr in enumerate(m.frames):
        assert len({w["frame_count"] for w in fr}) == 1 and fr[0]["frame_count"] == i
        for w in fr:
            (tid, first), = [k for k in runs if k[0] == w["target_id"] and k[1] <= i
                             and i - k[1] < len(runs[k])][-1:]
            exp = runs[(tid, first)][i - first]
            assert {k: w[k] for k in exp if k != "frame_count"} == {k: v for k, v in exp.items()
                                                                    if k != "frame_count"}, (i, tid)


def test_refused_adds() -> None:
    """Two slots: the third add is refused (full); a box outside the frame is taken by a slot whose engine
    rejects it (box, the slot free again); each sets `rejected` on the first word of the next frame only,
    and gets no word; a remove of a slot that is not live is refused."""
    words, frames, boxes = _multi(5)
    m = CoreModelMulti(TP, FP, 128, max_targets=2)
    m.add(boxes[(0, 1)], 96, 80)
    m.add(boxes[(0, 2)], 96, 80)
    _feed(m, words[0])
    assert m.add(boxes[(1, 3)], 96, 80) is None
    _feed(m, words[1])
    _feed(m, words[2])
    m.remove(1)
    assert m.add((500, 500, 20, 20), 96, 80) == 1 and m.live == [0, 1]
    _feed(m, words[3])
    assert m.live == [0] and not m.remove(1)
    _feed(m, words[4])
    assert m.outcomes == [Outcome(CMD_OK, 0), Outcome(CMD_OK, 1), Outcome(CMD_REFUSED, 0), Outcome(CMD_OK, 1),
                          Outcome(CMD_OK, 1), Outcome(CMD_BOX, 1), Outcome(CMD_REFUSED, 1)]
    rej = [[bool(w["flags"] & FLAG["rejected"]) for w in fr] for fr in m.frames]
    assert rej == [[False, False], [True, False], [False, False], [True], [False]]
    assert [[w["target_id"] for w in fr] for fr in m.frames] == [[0, 1], [0, 1], [0, 1], [0], [0]]


def test_fault_gives_one_error_word_per_target() -> None:
    """A short line on frame 3 with two targets: two error words (err_code, each target's centre and size),
    and the next frames as if frame 3 had never come."""
    words, frames, boxes = _multi(7)
    ref = CoreModelMulti(TP, FP, 128, max_targets=3)
    m = CoreModelMulti(TP, FP, 128, max_targets=3)
    for model in (m, ref):
        model.add(boxes[(0, 1)], 96, 80)
        model.add(boxes[(0, 2)], 96, 80)
    for i, f in enumerate(words):
        _feed(m, f, "short_line" if i == 3 else None)
        if i != 3:
            _feed(ref, f)
    bad = m.frames[3]
    assert [(w["target_id"], w["status"], w["err_code"], w["flags"]) for w in bad] == \
        [(0, ERROR, ERR_SHORT_LINE, FLAG["error"]), (1, ERROR, ERR_SHORT_LINE, FLAG["error"])]
    for w, prev in zip(bad, m.frames[2]):
        assert (w["cx"], w["cy"], w["w8"], w["h8"]) == (prev["cx"], prev["cy"], prev["w8"], prev["h8"])
    strip = [[{k: v for k, v in w.items() if k != "frame_count"} for w in fr] for fr in m.frames[:3] + m.frames[4:]]
    assert strip == [[{k: v for k, v in w.items() if k != "frame_count"} for w in fr] for fr in ref.frames]


def test_no_live_target_gives_one_no_target_word() -> None:
    """Before any add and after the last remove: one word per frame, slot 0's, flag no_target."""
    words, frames, boxes = _multi(3)
    m = CoreModelMulti(TP, FP, 128, max_targets=2)
    _feed(m, words[0])
    m.add(boxes[(1, 1)], 96, 80)
    _feed(m, words[1])
    m.remove(0)
    _feed(m, words[2])
    assert [len(fr) for fr in m.frames] == [1, 1, 1] and m.results[1]["status"] == STATUS_V2.index("init")
    for fr in (m.frames[0], m.frames[2]):
        assert fr[0]["flags"] == FLAG["no_target"] and fr[0]["target_id"] == 0


# ----------------------------------------------------------------------------- the capacity rule
def _capacity_run(cap, frames, cmds, n_slots: int = 3):
    """The model with the capacity rule and mstrack.MultiTracker(model="fixed") with the same rule on the same
    frames and adds ({frame: [box, ...]}, taken before the frame; MultiTracker: update(frame) then add(frame, box)).
    Returns the model and, per frame, MultiTracker's results by the model's slot of each target."""
    from mstrack.track.multi import CapacityError, MultiTracker
    m = CoreModelMulti(TP, FP, 128, max_targets=n_slots, capacity=cap)
    mt = MultiTracker(model="fixed", params=TP, capacity=cap)
    slot_of: dict[int, int] = {}                    # MultiTracker id -> the model's slot
    api: list[dict[int, dict]] = []
    api_codes: list[int] = []
    for i, fr in enumerate(frames):
        words = frame_words(fr)
        taken = []
        for box in cmds.get(i, []):
            taken.append(m.add(box, 96, 80))
        _feed(m, words)
        res = {r.target_id: r for r in mt.update(fr)} if mt.targets else {}
        for box, slot in zip(cmds.get(i, []), taken):
            try:
                tid = mt.add(fr, box)
                res[tid] = mt.last[tid]
                slot_of[tid] = slot
                api_codes.append(CMD_OK)
            except CapacityError as e:
                api_codes.append(e.add_code)
        api.append({slot_of[t]: result_fields_v2(r.extra) for t, r in res.items()})
    return m, api, api_codes


def _same_words(m, api) -> int:
    """Every frame: the model's words are MultiTracker's results, field by field (the flag rejected and the
    frame count are the core's own); returns the number of held words."""
    held = 0
    for i, (fr, want) in enumerate(zip(m.frames, api)):
        assert [w["target_id"] for w in fr] == sorted(want), f"frame {i}: slots {[w['target_id'] for w in fr]}"
        for w in fr:
            e = want[w["target_id"]]
            got = {k: w[k] for k in COMPARED_FIELDS_V2 if k != "frame_count"}
            got["flags"] &= ~FLAG["rejected"]
            assert got == {k: e[k] for k in got}, f"frame {i} slot {w['target_id']}"
            held += w["err_code"] == 6
    return held


def test_capacity_rule_is_multitrackers() -> None:
    """A budget (line_clocks 100, 450 blank lines: 45,000 clocks) that holds two of these targets' jobs: of
    three adds before frame 0 the third is refused (CMD_CYCLES, its slot free again, `rejected` on frame 0's
    first word); blank frames 4-6 lose both targets, whose wide searches do not fit together, so one is held
    (status error, err_code 6, its state kept); the third target added again before frame 7.  Every word equals
    MultiTracker(model="fixed")'s result with the same rule."""
    from mstrack.fixed.multi_capacity import ADD_CYCLES, MultiCoreConfig, VideoTiming
    words, frames, boxes = _multi(10)
    frames = [f if i not in (4, 5, 6) else np.zeros_like(f) for i, f in enumerate(frames)]
    cap = MultiCoreConfig(3, VideoTiming(80, 530, 100))
    cmds = {0: [boxes[(0, 1)], boxes[(0, 2)], boxes[(0, 3)]], 7: [boxes[(7, 3)]]}
    m, api, codes = _capacity_run(cap, frames, cmds)
    held = _same_words(m, api)
    assert held >= 1, "no target was held: the case does not test the rule's hold"
    cycles = [o for o in m.outcomes if o.code == CMD_CYCLES]
    assert codes.count(ADD_CYCLES) == len(cycles) >= 1 and m.outcomes[:3] == [
        Outcome(CMD_OK, 0), Outcome(CMD_OK, 1), Outcome(CMD_OK, 2)] and m.outcomes[3] == Outcome(CMD_CYCLES, 2)
    assert m.frames[0][0]["flags"] & FLAG["rejected"] and [w["target_id"] for w in m.frames[0]] == [0, 1]
    assert any(p.held for p in m.plans)


def test_capacity_rule_with_room_is_ms_tracker_multi() -> None:
    """With 1080p60's budget nothing is held or refused: the words and reports are those without the rule
    (targets added and removed as in test_targets_added_and_removed_match_single_trackers)."""
    from mstrack.fixed.multi_capacity import MultiCoreConfig
    words, frames, boxes = _multi()
    cmds = {0: [("add", 1), ("add", 2)], 3: [("add", 3)], 5: [("remove", 0)], 7: [("add", 1)]}
    models = [CoreModelMulti(TP, FP, 128, max_targets=3), CoreModelMulti(TP, FP, 128, 3, MultiCoreConfig(3))]
    for m in models:
        for i, f in enumerate(words):
            for op, arg in cmds.get(i, []):
                m.add(boxes[(i, arg)], 96, 80) if op == "add" else m.remove(arg)
            _feed(m, f)
    assert models[0].frames == models[1].frames and models[0].outcomes == models[1].outcomes
    assert not any(p.held for p in models[1].plans)


def test_capacity_rule_init_after_a_fault_keeps_its_verdict() -> None:
    """An accepted add whose init frame has a stream fault: one error word per live target on the faulty
    frame and none for the add; its init runs on the next good frame, before a later add that then does not
    fit (CMD_CYCLES); the flag rejected only on that frame."""
    from mstrack.fixed.multi_capacity import MultiCoreConfig, VideoTiming
    words, frames, boxes = _multi(6)
    m = CoreModelMulti(TP, FP, 128, max_targets=3, capacity=MultiCoreConfig(3, VideoTiming(80, 530, 100)))
    m.add(boxes[(0, 1)], 96, 80)
    _feed(m, words[0])
    m.add(boxes[(1, 2)], 96, 80)
    _feed(m, words[1], "short_line")               # the add's init frame is faulty
    assert [(w["target_id"], w["err_code"]) for w in m.frames[1]] == [(0, ERR_SHORT_LINE)]
    m.add(boxes[(2, 3)], 96, 80)                   # with the pending init there is no room for this one
    for i in range(2, 6):
        _feed(m, words[i])
    assert [w["target_id"] for w in m.frames[2]] == [0, 1] and m.frames[2][1]["status"] == STATUS_V2.index("init")
    assert m.outcomes == [Outcome(CMD_OK, 0), Outcome(CMD_OK, 1), Outcome(CMD_OK, 2), Outcome(CMD_CYCLES, 2)]
    assert [i for i, fr in enumerate(m.frames) if fr[0]["flags"] & FLAG["rejected"]] == [2]


def test_frame_beats_fault_positions() -> None:
    """frame_beats: a short line at a given row, a cut after a given number of beats, bad names refused."""
    from mstrack.hw.cosim_multi import frame_beats
    words = np.arange(8 * 6, dtype=np.uint32).reshape(6, 8)
    whole = frame_beats(words)
    assert len(whole) == 48 and whole[0][1] == 1 and sum(b[2] for b in whole) == 6
    short = frame_beats(words, "short_line:4")
    assert len(short) == 45 and short[4 * 8 + 4][2] == 1          # row 4 ends 3 pixels early
    assert frame_beats(words, "short_line") == frame_beats(words, "short_line:5")
    assert len(frame_beats(words, "cut:20")) == 20 and len(frame_beats(words, "cut")) == 48
    with pytest.raises(ValueError):
        frame_beats(words, "long_line")
    with pytest.raises(ValueError):
        frame_beats(words, "cut:x")
