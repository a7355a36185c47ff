"""mstrack.MultiTracker and MultiTrackerMeanShift (docs/multi.md): every target's results equal, field by
field and frame by frame, those of a single Tracker run on the same frames from the same box (float
exactly, fixed bit for bit), on a generated scene with targets entering and leaving and on a real MOT
clip; the capacity rule (Capacity) refuses adds when slots or region memory would be exceeded."""
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

import mstrack
from mstrack import Capacity, CapacityError, FrameError, MultiTracker, MultiTrackerMeanShift, Tracker, TrackResult
from mstrack.io.synthetic import make_multi_scene
from mstrack.track.multi import MAX_TARGETS, REGION_RAM_WORDS

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
    """The default rule: 16 slots; the 17th add is refused with code MAX_TARGETS, nothing changes,
    and a remove makes room again."""
    frames, _ = scene
    mt = MultiTracker(model="fixed")
    assert mt.capacity == Capacity() and Capacity().max_targets == MAX_TARGETS == 16
    for k in range(16):
        assert mt.add(frames[0], (10 + 12 * (k % 8), 20 + 60 * (k // 8), 12, 14)) == k
    with pytest.raises(CapacityError) as e:
        mt.add(frames[0], (100, 100, 20, 20))
    assert e.value.code == "MAX_TARGETS" and "16 slots" in str(e.value)
    assert mt.targets == list(range(16))
    mt.remove(5)
    assert mt.add(frames[0], (100, 100, 20, 20)) == 5


def test_capacity_rule_region_memory(scene):
    """A region memory of three worst-case regions: the fourth add is refused with REGION_WORDS; with
    double-buffered regions (buffers=2) the second already is."""
    frames, gt = scene
    b = gt[gt[:, 0] == 0][:, 2:6]
    cap = Capacity(region_words=3 * REGION_RAM_WORDS)
    words = cap.target_words(MultiTracker().params, MultiTracker().fixed, frames[0].shape)
    # 240 x 180 frame: columns 191 (tracking at D = 1: 127 + 2 x 32 + 1; lost at D = 2 the decimated frame
    # is 120 wide), rows 178 (S - 2)
    assert words == 191 * 178
    mt = MultiTracker(capacity=Capacity(region_words=3 * words))
    for k in range(3):
        mt.add(frames[0], b[k % len(b)])
    assert mt.region_words() == 3 * words
    with pytest.raises(CapacityError) as e:
        mt.add(frames[0], b[0])
    assert e.value.code == "REGION_WORDS" and mt.targets == [0, 1, 2]
    mt2 = MultiTracker(capacity=Capacity(region_words=3 * words, buffers=2))
    mt2.add(frames[0], b[0])
    with pytest.raises(CapacityError, match="REGION_WORDS"):
        mt2.add(frames[0], b[1])
    front = MultiTrackerMeanShift.create(capacity=Capacity(max_targets=1))
    assert front.add(None, frames[0], b[0]) is True and front.add(None, frames[0], b[1]) is False


@pytest.mark.parametrize("size", [640, 1920, 2048])
def test_target_words_is_region_max_v2(size):
    """Capacity.target_words of tracker v2 in a square frame is the square of core v2's region bound
    (mstrack.hw.cosim.region_max_v2), whose REGION_MAX 256 sizes the region RAM."""
    from mstrack.fixed import FixedParams
    from mstrack.hw.cosim import region_max_v2
    tp = MultiTracker().params
    n = region_max_v2(tp, FixedParams(), size)
    assert Capacity().target_words(tp, FixedParams(), (size, size, 3)) == n * n
    assert n * n <= REGION_RAM_WORDS


def test_capacity_arguments():
    for bad in (dict(max_targets=0), dict(region_words=0), dict(buffers=3), dict(max_targets=True)):
        with pytest.raises(ValueError):
            Capacity(**bad)
    with pytest.raises(TypeError):
        MultiTracker(capacity=4)
    with pytest.raises(TypeError):
        MultiTracker(model="float", margin=3)   # FixedParams field on the float model
    assert MultiTracker(model="fixed", margin=16).fixed.margin == 16


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
