"""The public API with OpenCV habits: Box as a 4-tuple and an OpenCV rect,
TrackResult.ok / .confidence, TrackerMeanShift in a loop written for cv2 trackers, parameter
aliases, the default tracker."""
import dataclasses
import math

import cv2
import numpy as np
import pytest

import mstrack
from mstrack import Box, Status, Tracker, TrackerMeanShift, TrackerParams
from mstrack.eval.metrics import iou
from mstrack.io.synthetic import make_scene


@pytest.fixture(scope="module")
def scene():
    frames, gt = make_scene(30, 240, 180, seed=3)
    return frames, gt


# ----------------------------------------------------------------------------- Box
def test_box_unpacks_indexes_and_compares_like_a_tuple():
    b = Box(10.25, 20.0, 30.5, 40.0)
    x, y, w, h = b
    assert (x, y, w, h) == (10.25, 20.0, 30.5, 40.0) and b[2] == 30.5 and b[-1] == 40.0 and len(b) == 4
    assert b == (10.25, 20.0, 30.5, 40.0) and b == Box.of([10.25, 20, 30.5, 40]) and b != Box(10, 20, 30, 40)
    assert hash(b) == hash((10.25, 20.0, 30.5, 40.0)) and {b: 1}[Box.of(b.as_tuple())] == 1
    assert b.as_tuple() == tuple(b) and type(b.as_tuple()) is tuple
    assert b.centre == (25.5, 40.0) and b.x == 10.25 and b._replace(x=0.0) == (0.0, 20.0, 30.5, 40.0)
    assert np.array_equal(np.asarray(b), [10.25, 20.0, 30.5, 40.0])
    with pytest.raises(AttributeError):
        b.x = 3.0  # type: ignore[misc]
    for bad in ("5599", [1, 2, 3], [1, 2, 3, math.nan], [True, 1, 2, 3]):
        with pytest.raises(ValueError):
            Box.of(bad)


@pytest.mark.parametrize("box,rect", [((10.25, 20.0, 30.5, 40.0), (10, 20, 31, 40)),
                                      ((0.4, 0.6, 10.4, 5.0), (0, 1, 11, 5)),
                                      ((-5.0, 10.0, 20.0, 20.0), (-5, 10, 20, 20)),
                                      ((2.5, 2.5, 3.0, 3.0), (3, 3, 3, 3))])
def test_box_to_cv_rect_in_real_cv2_calls(box, rect):
    b = Box.of(box)
    r = b.to_cv()
    assert r == rect and all(type(v) is int for v in r)
    img = np.zeros((60, 80, 3), np.uint8)
    with pytest.raises(cv2.error):              # what the issue met: OpenCV refuses the float box
        cv2.rectangle(img, tuple(b), (0, 255, 0), 1)
    cv2.rectangle(img, b.to_cv(), (0, 255, 0), 1)
    x, y, w, h = rect
    if x >= 0 and y >= 0:
        assert (img[y, x] == (0, 255, 0)).all() and (img[y + h - 1, x + w - 1] == (0, 255, 0)).all()
    tracker = cv2.TrackerKCF.create()           # a cv2 tracker takes it as its init rect too
    tracker.init(np.random.default_rng(0).integers(0, 255, (60, 80, 3), dtype=np.uint8), (10, 10, 20, 20))


# ----------------------------------------------------------------------------- TrackResult, Tracker
def test_trackresult_ok_confidence_and_box(scene):
    frames, gt = scene
    trk = Tracker()
    r0 = trk.init(frames[0], gt[0])
    r1 = trk.update(frames[1])
    x, y, w, h = r1.box                          # the OpenCV habit: unpack the box
    assert r0.ok and r1.ok and r1.status in (Status.OK, Status.REACQUIRED)
    assert 0.0 <= r1.confidence <= 1.0
    d = r1.to_dict()
    assert d["box"] == [x, y, w, h] and d["status"] == r1.status.value
    # the paper preset has no confidence: always 1.0; ok follows the status
    p = Tracker(preset="paper")
    p.init(frames[0], gt[0])
    rp = p.update(frames[1])
    assert rp.confidence == 1.0 and rp.ok
    assert not dataclasses.replace(rp, status=Status.LOST).ok and not dataclasses.replace(rp, status=Status.ERROR).ok


def test_default_is_tracker_v2_and_paper_one_argument_away():
    assert Tracker().params.preset == "v2" and Tracker(model="fixed").params.preset == "v2"
    assert TrackerMeanShift.create().params.preset == "v2"
    assert type(Tracker().impl).__name__ == "FloatTrackerV2"
    p = Tracker(preset="paper")
    assert p.params.preset == "paper" and p.params.features == "fused" and type(p.impl).__name__ == "FloatTracker"
    assert TrackerParams().preset == "paper"     # the RTL core's parameter set (vectors, cosim) is unchanged
    with pytest.raises(ValueError, match="preset='paper', features='fused'"):
        Tracker(features="fused")                # v2 is colour only: the message says what to write


@pytest.mark.parametrize("kw,field,want", [({"kernel": "epan"}, "kernel", "epanechnikov"),
                                           ({"kernel": "Epanechnikov"}, "kernel", "epanechnikov"),
                                           ({"kernel": "uniform"}, "kernel", "flat"),
                                           ({"features": "color"}, "features", "colour"),
                                           ({"preset": "paper", "features": "Color"}, "features", "colour"),
                                           ({"preset": "paper", "features": "edges"}, "features", "edge"),
                                           ({"preset": "V2"}, "preset", "v2")])
def test_parameter_aliases(kw, field, want):
    assert getattr(Tracker(**kw).params, field) == want
    assert getattr(TrackerParams(**kw), field) == want


def test_unknown_parameter_value_lists_the_choices():
    with pytest.raises(ValueError, match=r"kernel must be 'flat' \(or 'uniform'\), 'epanechnikov' \(or 'epan'\)"):
        Tracker(kernel="gauss")


def test_tracker_params_object():
    tp = TrackerParams(preset="paper", features="colour", kernel="epan")
    trk = Tracker(params=tp)
    assert trk.params is tp
    with pytest.raises(TypeError, match="either in params or as keywords"):
        Tracker(params=tp, kernel="flat")


# ----------------------------------------------------------------------------- OpenCV-style tracker
def _cv_loop(tracker, frames, rect):
    """A loop as written for OpenCV's trackers (cv2.TrackerCSRT): init, then (ok, rect) per frame."""
    tracker.init(frames[0], rect)
    out = []
    for frame in frames[1:]:
        ok, bbox = tracker.update(frame)
        canvas = frame.copy()
        if ok:
            p1 = (int(bbox[0]), int(bbox[1]))
            p2 = (int(bbox[0] + bbox[2]), int(bbox[1] + bbox[3]))
            cv2.rectangle(canvas, p1, p2, (255, 0, 0), 2, 1)
        cv2.rectangle(canvas, bbox, (0, 255, 0), 1)
        out.append((ok, tuple(bbox)))
    return out


@pytest.mark.parametrize("preset", ["v2", "paper"])
def test_trackermeanshift_drops_into_a_cv2_tracker_loop(scene, preset):
    frames, gt = scene
    rect = tuple(int(v) for v in gt[0])
    res = {"csrt": _cv_loop(cv2.TrackerCSRT.create(), frames, rect),
           "mstrack": _cv_loop(TrackerMeanShift.create(TrackerParams(preset=preset)), frames, rect)}
    for name, out in res.items():
        assert len(out) == len(frames) - 1
        for ok, r in out:
            assert isinstance(ok, bool) and len(r) == 4 and all(isinstance(v, (int, np.integer)) for v in r), name
    ious = iou(np.array([r for _, r in res["mstrack"]], float), gt[1:])
    assert ious.mean() > 0.5 and all(ok for ok, _ in res["mstrack"])


def test_trackermeanshift_result_and_bad_frame(scene):
    frames, gt = scene
    t = TrackerMeanShift.create(model="fixed")
    with pytest.raises(RuntimeError, match="before init"):
        t.update(frames[0])
    assert t.init(frames[0], gt[0]) is None
    ok, rect = t.update(frames[1])
    assert ok and rect == t.last.box.to_cv() and 0.0 <= t.getTrackingScore() <= 1.0
    assert t.update(frames[2][:50]) == (False, rect)         # a bad frame: not ok, rect kept (no raise)


def test_public_names():
    for name in ("Box", "TrackResult", "Status", "Tracker", "TrackerMeanShift", "TrackerParams", "FrameError"):
        assert name in mstrack.__all__ and name in dir(mstrack) and getattr(mstrack, name) is not None
