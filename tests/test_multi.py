"""mstrack.MultiTracker and MultiTrackerMeanShift (docs/multi.md): every target's results equal, field by
field and frame by frame, those of a single Tracker run on the same frames from the same box (float
exactly, fixed bit for bit), on a generated scene with targets entering and leaving and on a real MOT
clip, where the core's capacity suffices; where it does not, the fixed model applies the core's capacity
rule (mstrack.fixed.multi_capacity): adds refused for slots (ADD_FULL) or cycles (ADD_CYCLES), live targets
held for a frame (status error, err_code 6) and then continuing bit for bit."""
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

import mstrack
from mstrack import (CapacityError, FrameError, MultiCoreConfig, MultiTracker, MultiTrackerMeanShift, Status, Tracker,
                     TrackResult, VideoTiming)
from mstrack.fixed.multi_capacity import (ADD_CYCLES, ADD_FULL, ERR_CAPACITY, check_add, init_demand, plan_frame,
                                          target_demand)
from mstrack.fixed.vhdl_pkg import RESULT_FLAGS, pack_result_v2, result_fields_v2, unpack_result_v2
from mstrack.io.synthetic import make_multi_scene

MOT_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi"


@pytest.fixture(scope="module")
def scene():
    n = 24
    frames, gt = make_multi_scene(n, 240, 180, n_targets=4, seed=7, spans=[(0, n), (0, n), (6, n), (0, 16)])
    return frames, gt


def _assert_same(got: TrackResult, want: TrackResult, where: str) -> None:
    """Every field equal (extra entry by entry); target_id is the multi-tracker's own."""
    for f in fields(want):
        if f.name == "target_id":
            continue
        g, w = getattr(got, f.name), getattr(want, f.name)
        if f.name == "extra":
            assert g.keys() == w.keys(), f"{where}: extra keys"
            for k in w:
                assert g[k] == w[k], f"{where}: extra[{k!r}] {g[k]!r} != {w[k]!r}"
        else:
            assert g == w, f"{where}: {f.name} {g!r} != {w!r}"


def _check_against_single(frames, gt_rows, model, **params):
    """Run a MultiTracker with the eval protocol (add on the first frame, remove after the last) and
    one Tracker per target; compare every result."""
    n = len(frames)
    ids = [int(v) for v in np.unique(gt_rows[:, 1])]
    first = {k: int(gt_rows[gt_rows[:, 1] == k][0, 0]) for k in ids}
    last = {k: int(gt_rows[gt_rows[:, 1] == k][-1, 0]) for k in ids}
    box0 = {k: gt_rows[gt_rows[:, 1] == k][0, 2:6] for k in ids}
    mt = MultiTracker(model=model, **params)
    slot: dict[int, int] = {}
    got: dict[int, list[TrackResult]] = {k: [] for k in ids}
    for i in range(n):
        for k in [k for k in slot if last[k] < i]:
            mt.remove(slot.pop(k))
        by_slot = {r.target_id: r for r in mt.update(frames[i])}
        assert mt.plan is None or mt.plan.held == ()   # the default capacity suffices here
        assert sorted(by_slot) == mt.targets == sorted(slot.values())
        for k, s in slot.items():
            got[k].append(by_slot[s])
        for k in ids:
            if first[k] == i:
                slot[k] = mt.add(frames[i], box0[k])
                got[k].append(mt.last[slot[k]])
                assert mt.last[slot[k]].target_id == slot[k]
    for k in ids:
        trk = Tracker(model=model, **params)
        want = [trk.init(frames[first[k]], box0[k])] + [trk.update(frames[i]) for i in range(first[k] + 1, last[k] + 1)]
        assert len(got[k]) == len(want)
        for j, (g, w) in enumerate(zip(got[k], want)):
            _assert_same(g, w, f"{model} target {k} frame {first[k] + j}")
    return got


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_synthetic_targets_equal_single_trackers(scene, model):
    frames, gt = scene
    got = _check_against_single(frames, gt, model)
    assert len(got) == 4 and all(r.ok for rs in got.values() for r in rs[:3])


def test_synthetic_paper_preset_equal_single_trackers(scene):
    frames, gt = scene
    _check_against_single(frames[:10], gt[gt[:, 0] < 10], "fixed", preset="paper")


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_real_mot_clip_equal_single_trackers(model):
    """TUD-Stadtmitte, frames 0..29, three targets (one leaving early, by a shortened ground truth)."""
    from mstrack.io.mot import load_mot_sequence
    if not (MOT_ROOT / "TUD-Stadtmitte").is_dir():
        pytest.skip(f"../shared/data/multi not found: {MOT_ROOT}")
    seq = load_mot_sequence(MOT_ROOT / "TUD-Stadtmitte")
    n = 30
    rows = seq.rows[(seq.rows[:, 0] < n) & np.isin(seq.rows[:, 1], (2, 3, 5))]
    rows = rows[~((rows[:, 1] == 3) & (rows[:, 0] > 18))]  # target 3 removed after frame 18
    frames = [seq.frame(i) for i in range(n)]
    got = _check_against_single(frames, rows, model)
    assert sorted(got) == [2, 3, 5] and len(got[3]) == 19


def test_ids_lowest_free_slot_and_remove(scene):
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    mt = MultiTracker()
    assert [mt.add(frames[0], b[0]), mt.add(frames[0], b[1]), mt.add(frames[0], b[2])] == [0, 1, 2]
    mt.remove(1)
    assert mt.targets == [0, 2] and len(mt) == 2
    assert [r.target_id for r in mt.update(frames[1])] == [0, 2]
    assert mt.add(frames[1], b[1]) == 1          # the freed slot
    assert mt.targets == [0, 1, 2] and mt.last[1].status.value == "init"
    with pytest.raises(KeyError):
        mt.remove(7)
    assert MultiTracker().update(frames[0]) == []


def test_bad_frames_and_sizes_change_nothing(scene):
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    mt = MultiTracker()
    mt.add(frames[0], b[0])
    before = dict(mt.last)
    with pytest.raises(FrameError):
        mt.update(frames[1][:100])               # another size: no target updated
    with pytest.raises(FrameError):
        mt.add(frames[1][:100, :100], (5, 5, 20, 20))
    with pytest.raises(ValueError):
        mt.add(frames[0], (1e4, 1e4, 10, 10))    # a box the tracker cannot start from
    assert mt.targets == [0] and mt.last == before


def test_capacity_rule_max_targets(scene):
    """Both models: 16 slots by default; the 17th add is refused with ADD_FULL, nothing changes, and a
    remove makes room again."""
    frames, _ = scene
    for model in ("fixed", "float"):
        mt = MultiTracker(model=model)
        assert mt.capacity == MultiCoreConfig() and mt.capacity.max_targets == 16
        for k in range(16):
            assert mt.add(frames[0], (10 + 12 * (k % 8), 20 + 60 * (k // 8), 12, 14)) == k
        before = dict(mt.last)
        with pytest.raises(CapacityError) as e:
            mt.add(frames[0], (100, 100, 20, 20))
        assert (e.value.code, e.value.add_code) == ("ADD_FULL", ADD_FULL) and "16 slots" in str(e.value)
        assert mt.targets == list(range(16)) and mt.last == before
        mt.remove(5)
        assert mt.add(frames[0], (100, 100, 20, 20)) == 5
    front = MultiTrackerMeanShift.create(capacity=MultiCoreConfig(max_targets=1))
    assert front.add(None, frames[0], (10, 20, 12, 14)) is True
    assert front.add(None, frames[0], (50, 20, 12, 14)) is False and len(front.getObjects()) == 1


#: A raster for the 240 x 180 scene whose frame holds two of its targets' init jobs but not their
#: tracking jobs (the figures are read from the rule's own functions in the tests).
SMALL = MultiCoreConfig(timing=VideoTiming(active_lines=180, frame_lines=200, line_clocks=800))


def test_capacity_rule_cycles_refuses_an_add(scene):
    """Fixed tracker v2: an add whose init job breaks the frame's cycle rule is refused with ADD_CYCLES
    (check_add on the jobs admitted on that frame) and changes nothing; the float model applies
    max_targets only."""
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    jobs = [init_demand(b[k], 240, 180, k) for k in range(3)]
    assert check_add(jobs[:1], 1, jobs[1], SMALL) == 0 and check_add(jobs[:2], 2, jobs[2], SMALL) == ADD_CYCLES
    mt = MultiTracker(model="fixed", capacity=SMALL)
    assert [mt.add(frames[0], b[0]), mt.add(frames[0], b[1])] == [0, 1]
    before = dict(mt.last)
    with pytest.raises(CapacityError) as e:
        mt.add(frames[0], b[2])
    assert (e.value.code, e.value.add_code) == ("ADD_CYCLES", ADD_CYCLES) and "clocks" in str(e.value)
    assert mt.targets == [0, 1] and mt.last == before
    # the default raster holds all three; so does the float model on the small one
    assert MultiTracker(model="fixed").add(frames[0], b[0]) == 0
    fl = MultiTracker(model="float", capacity=SMALL)
    assert [fl.add(frames[0], box) for box in b] == [0, 1, 2] and fl.update(frames[1])[1].ok
    # an add on a frame with no target live is on a new frame: only its own job counts
    mt.remove(0)
    mt.remove(1)
    assert mt.add(frames[1], b[2]) == 0
    with pytest.raises(ValueError, match="video timing"):
        MultiTracker(model="fixed", capacity=SMALL).add(np.zeros((200, 240, 3), np.uint8), (10, 10, 20, 20))


def test_capacity_rule_cycles_holds_a_live_target(scene):
    """Fixed tracker v2: two targets whose tracking jobs do not fit one frame (their init jobs did):
    the newer is held on frame 1 (plan_frame: oldest first), its result status error, err_code 6, its
    box unchanged, and its result word says so; once the older is removed it continues, bit for bit,
    as a single Tracker that skipped frame 1.  The older is tracked as a single Tracker throughout."""
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    mt = MultiTracker(model="fixed", capacity=SMALL)
    a0, a1 = mt.add(frames[0], b[0]), mt.add(frames[0], b[1])
    singles = [Tracker(model="fixed") for _ in range(2)]
    inits = [singles[k].init(frames[0], b[k]) for k in range(2)]
    want = plan_frame([target_demand(s.impl, k) for k, s in enumerate(singles)], SMALL)
    assert want.tracked == (0,) and want.held == (1,)
    r = {x.target_id: x for x in mt.update(frames[1])}
    assert mt.plan == want
    _assert_same(r[a0], singles[0].update(frames[1]), "older target, frame 1")
    held = r[a1]
    assert held.status == Status.ERROR and not held.ok and held.extra["err_code"] == ERR_CAPACITY == 6
    assert held.box == inits[1].box and held.centre == inits[1].centre and mt.last[a1] is held
    word = unpack_result_v2(pack_result_v2(result_fields_v2(held.extra)))
    assert word["status"] == 6 and word["flag_error"] == 1 and word["err_code"] == 6
    assert word["flags"] == 1 << RESULT_FLAGS.index("error")
    mt.remove(a0)
    for i in range(2, 8):
        (got,) = mt.update(frames[i])
        assert mt.plan.held == ()
        _assert_same(got, singles[1].update(frames[i]), f"held target, frame {i}")
        assert got.target_id == a1 and "err_code" not in got.extra


def test_capacity_arguments_and_who_applies_the_cycle_rule(scene):
    """capacity must be a MultiCoreConfig; the cycle rule is the fixed tracker v2's only (the float
    model and the fixed paper preset take every add the slots allow, on the raster that refuses one)."""
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    with pytest.raises(TypeError, match="MultiCoreConfig"):
        MultiTracker(capacity=4)
    with pytest.raises(ValueError, match="1..16"):
        MultiCoreConfig(max_targets=17)
    with pytest.raises(TypeError):
        MultiTracker(model="float", margin=3)   # FixedParams field on the float model
    assert MultiTracker(model="fixed", margin=16).fixed.margin == 16
    assert [MultiTracker(model=m, preset=p).cycle_rule for m, p in
            (("fixed", "v2"), ("float", "v2"), ("fixed", "paper"))] == [True, False, False]
    paper = MultiTracker(model="fixed", preset="paper", capacity=SMALL)
    assert [paper.add(frames[0], box) for box in b] == [0, 1, 2]
    assert len(paper.update(frames[1])) == 3 and paper.plan is None


def test_opencv_style_front_end(scene):
    """mstrack.MultiTrackerMeanShift in a loop written for cv2.legacy.MultiTracker."""
    frames, gt = scene
    b = [tuple(int(v) for v in r) for r in gt[gt[:, 0] == 0][:, 2:6]]
    multi = MultiTrackerMeanShift.create()
    for box in b:
        assert multi.add(mstrack.TrackerMeanShift.create(), frames[0], box)
    ok, boxes = multi.update(frames[1])
    assert boxes.shape == (len(b), 4) and boxes.dtype == np.float64
    assert ok == all(r.ok for r in multi.last)
    assert np.array_equal(multi.getObjects(), boxes)
    single = Tracker()
    single.init(frames[0], b[1])
    assert tuple(boxes[1]) == single.update(frames[1]).box.as_tuple()
    bad_ok, same = multi.update(frames[2][:50])
    assert bad_ok is False and np.array_equal(same, boxes)
    with pytest.raises(ValueError):
        multi.add(mstrack.TrackerMeanShift.create(model="fixed"), frames[0], b[0])
    with pytest.raises(TypeError):
        multi.add(object(), frames[0], b[0])


def test_trackresult_target_id_default_and_dict(scene):
    frames, gt = scene
    r = Tracker().init(frames[0], gt[0, 2:6])
    assert r.target_id is None and r.to_dict()["target_id"] is None
    assert replace(r, target_id=3).to_dict()["target_id"] == 3
