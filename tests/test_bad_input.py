"""Bad input, for both models (documented behaviour: mstrack/frames.py docstring)."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from mstrack import FrameError, Status, Tracker
from mstrack.agreement import shift_scene

MODELS = ["float", "fixed"]
W, H = 160, 120


@pytest.fixture(scope="module")
def scene():
    f0, f1, box = shift_scene(3, -2)
    f2 = shift_scene(5, -1)[1]
    return f0, f1, f2, box


def _inside(box, w=W, h=H):
    return box.x >= 0 and box.y >= 0 and box.x + box.w <= w + 1e-9 and box.y + box.h <= h + 1e-9


# ----------------------------------------------------------------------------- boxes
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("box", [
    (10, 10, 0, 20), (10, 10, 20, 0), (10, 10, -5, 20), (10, 10, 20, -1),
    (float("nan"), 10, 20, 20), (10, 10, float("inf"), 20), (10, 10, 20), (10, 10, 20, 20, 1), "abcd", None,
])
def test_invalid_box_raises(model, box, scene):
    with pytest.raises(ValueError):
        Tracker(model=model).init(scene[0], box)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("box", [(-50, 10, 20, 20), (W + 5, 10, 20, 20), (10, H, 20, 20), (10, -30, 20, 20),
                                 (W - 1.5, 10, 20, 20)])
def test_box_entirely_outside_raises(model, box, scene):
    with pytest.raises(ValueError):
        Tracker(model=model).init(scene[0], box)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("box", [(-10, 20, 40, 30), (140, 100, 40, 30), (50, -5, 30, 30),
                                 (-20, -20, W + 40, H + 40)])
def test_box_partly_outside_or_too_large_is_clipped(model, box, scene):
    """The init box is clipped into the frame; later boxes only keep a finite centre in the frame
    (the trackers clamp the centre, not the box, so a frame-sized box may overhang by a fraction)."""
    f0, f1, _, _ = scene
    trk = Tracker(model=model)
    r = trk.init(f0, box)
    assert r.status == Status.CLIPPED
    assert _inside(r.box), r.box
    r1 = trk.update(f1)
    assert all(math.isfinite(v) for v in r1.centre)
    assert 0 <= r1.centre[0] <= W - 1 and 0 <= r1.centre[1] <= H - 1


@pytest.mark.parametrize("model", MODELS)
def test_whole_frame_box(model, scene):
    """(0, 0, W, H) is inside the frame for the float model; the fixed model drops the 1-px
    border (no Sobel neighbourhood there) and reports CLIPPED."""
    r = Tracker(model=model).init(scene[0], (0, 0, W, H))
    assert r.status == (Status.CLIPPED if model == "fixed" else Status.INIT)
    assert _inside(r.box)


# ----------------------------------------------------------------------------- frames
@pytest.mark.parametrize("model", MODELS)
def test_grey_frames(model, scene):
    f0, f1, _, box = scene
    for conv in (lambda f: cv2.cvtColor(f, cv2.COLOR_BGR2GRAY),
                 lambda f: cv2.cvtColor(f, cv2.COLOR_BGR2GRAY)[:, :, None]):
        trk = Tracker(model=model)
        assert trk.init(conv(f0), box).status == Status.INIT
        r = trk.update(conv(f1))
        assert r.status == Status.OK
        assert math.hypot(r.centre[0] - 74 - 3, r.centre[1] - 56 + 2) < 3.0


@pytest.mark.parametrize("model", MODELS)
def test_bgra_frames_equal_bgr(model, scene):
    f0, f1, _, box = scene
    a, b = Tracker(model=model), Tracker(model=model)
    a.init(f0, box)
    b.init(cv2.cvtColor(f0, cv2.COLOR_BGR2BGRA), box)
    assert a.update(f1).centre == b.update(cv2.cvtColor(f1, cv2.COLOR_BGR2BGRA)).centre


BAD_FRAMES = {
    "none": None,
    "list": [[0, 0, 0]],
    "float32": np.zeros((H, W, 3), np.float32),
    "uint16": np.zeros((H, W, 3), np.uint16),
    "1d": np.zeros(W * 3, np.uint8),
    "2ch": np.zeros((H, W, 2), np.uint8),
    "4d": np.zeros((H, W, 3, 1), np.uint8),
    "empty": np.zeros((0, 0, 3), np.uint8),
    "tiny": np.zeros((2, 2, 3), np.uint8),
}


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", sorted(BAD_FRAMES))
def test_bad_frame_raises_frame_error(model, name, scene):
    f0, _, _, box = scene
    with pytest.raises(FrameError):
        Tracker(model=model).init(BAD_FRAMES[name], box)
    trk = Tracker(model=model)
    trk.init(f0, box)
    with pytest.raises(FrameError):
        trk.update(BAD_FRAMES[name])


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("bad", ["smaller", "larger", "none", "float32"])
def test_bad_frame_does_not_change_state(model, bad, scene):
    """After a rejected frame the tracker continues exactly as if it had not been given."""
    f0, f1, f2, box = scene
    bad_frame = {"smaller": f1[:-10, :-6], "larger": np.pad(f1, ((0, 4), (0, 4), (0, 0))),
                 "none": None, "float32": f1.astype(np.float32)}[bad]
    ref = Tracker(model=model)
    ref.init(f0, box)
    want = [ref.update(f1), ref.update(f2)]
    trk = Tracker(model=model)
    trk.init(f0, box)
    got = [trk.update(f1)]
    with pytest.raises(FrameError):
        trk.update(bad_frame)
    got.append(trk.update(f2))
    for g, w in zip(got, want):
        assert g.centre == w.centre and g.box == w.box and g.rho_c == w.rho_c and g.rho_e == w.rho_e


@pytest.mark.parametrize("model", MODELS)
def test_update_before_init(model, scene):
    with pytest.raises(RuntimeError):
        Tracker(model=model).update(scene[0])


# ----------------------------------------------------------------------------- never NaN
def _frames_black_noise():
    rng = np.random.default_rng(7)
    return {"black": np.zeros((H, W, 3), np.uint8), "white": np.full((H, W, 3), 255, np.uint8),
            "noise": rng.integers(0, 256, (H, W, 3), dtype=np.uint8)}


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("features", ["fused", "colour", "edge"])
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_never_nan(model, features, kernel, scene):
    fr = _frames_black_noise()
    box = scene[3]
    for init_name in ("black", "noise"):
        trk = Tracker(model=model, features=features, kernel=kernel)
        trk.init(fr[init_name], box)
        for name in ("black", "noise", "white", "black"):
            r = trk.update(fr[name])
            vals = (*r.centre, *r.box.as_tuple(), r.rho_c, r.rho_e, r.alpha_c, r.alpha_e)
            assert all(math.isfinite(v) for v in vals), (init_name, name, r)
            assert _inside(r.box)
    # a target model learnt on a real target, then a black frame: lost, position kept
    trk = Tracker(model=model, features=features, kernel=kernel)
    r0 = trk.init(scene[0], box)
    r = trk.update(fr["black"])
    assert all(math.isfinite(v) for v in r.centre)
    if features == "colour":
        assert r.status == Status.LOST and r.centre == r0.centre


# ----------------------------------------------------------------------------- data readers
def test_data_reader_errors(tmp_path):
    """A couple of reader errors (the data helper's tests cover the rest)."""
    data = pytest.importorskip("mstrack.data")
    (tmp_path / "img").mkdir()
    (tmp_path / "groundtruth_rect.txt").write_text("1,1,10,10\n")
    with pytest.raises(data.DataError):
        data.load_sequence(tmp_path)            # no images
    bad = tmp_path / "img" / "0001.jpg"
    bad.write_bytes(b"not a jpeg")
    seq = data.load_sequence(tmp_path)
    with pytest.raises(data.DataError):
        seq.frame(0)                             # unreadable image
    with pytest.raises(data.DataError):
        data.load_sequence(tmp_path / "missing")
