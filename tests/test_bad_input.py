"""Bad input, for both models (documented behaviour: mstrack/track/frames.py docstring)."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from mstrack import FrameError, Status, Tracker
from mstrack.eval.agreement import shift_scene

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
        trk = Tracker(model=model, preset="paper", features=features, kernel=kernel)
        trk.init(fr[init_name], box)
        for name in ("black", "noise", "white", "black"):
            r = trk.update(fr[name])
            vals = (*r.centre, *r.box.as_tuple(), r.rho_c, r.rho_e, r.alpha_c, r.alpha_e)
            assert all(math.isfinite(v) for v in vals), (init_name, name, r)
            assert _inside(r.box)
    # a target model learnt on a real target, then a black frame: lost, position kept
    trk = Tracker(model=model, preset="paper", features=features, kernel=kernel)
    r0 = trk.init(scene[0], box)
    r = trk.update(fr["black"])
    assert all(math.isfinite(v) for v in r.centre)
    if features == "colour":
        assert r.status == Status.LOST and r.centre == r0.centre


# ----------------------------------------------------------------------------- data readers
def test_data_reader_errors(tmp_path):
    """A couple of reader errors (the data helper's tests cover the rest)."""
    data = pytest.importorskip("mstrack.io.data")
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


# ----------------------------------------------------------------------------- boxes and parameters
@pytest.mark.parametrize("box", ["5599", b"5599", bytearray(b"5599"), {1.0, 2.0, 30.0, 40.0},
                                 {"x": 1, "y": 2, "w": 3, "h": 4}, (True, 10, 20, 20), ("10", "10", "20", "20"),
                                 (10, 10, 20, None), iter((10, 10, 20, 20))])
def test_box_must_be_four_real_numbers(box):
    """Strings and bytes iterate as digits, a set has no order: none of them is a box."""
    from mstrack.track.types import Box
    with pytest.raises(ValueError, match="box must be"):
        Box.of(box)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("box", ["5599", b"5599", {10, 11, 20, 21}])
def test_tracker_refuses_non_numeric_box(model, box, scene):
    with pytest.raises(ValueError, match="box must be"):
        Tracker(model=model).init(scene[0], box)


def test_box_accepts_numpy_and_python_numbers():
    from mstrack.track.types import Box
    assert Box.of(np.array([1, 2, 3, 4], np.int32)) == Box.of((1.0, 2, np.float32(3), np.int64(4))) == Box(1, 2, 3, 4)


@pytest.mark.parametrize("model", MODELS)
def test_huge_box_is_a_value_error(model, scene):
    """1e308 boxes: x + w overflows to inf (the fixed model raised OverflowError)."""
    with pytest.raises(ValueError) as ei:
        Tracker(model=model).init(scene[0], (1e308, 1e308, 1e308, 1e308))
    assert not isinstance(ei.value, OverflowError)


PARAM_CASES = [({"max_iter": 1.5}, "max_iter must be an integer"), ({"colour_bits": 3.5}, "colour_bits must be an integer"),
               ({"max_iter": True}, "max_iter must be an integer"), ({"edge_shift": 5.0}, "edge_shift must be an integer"),
               ({"colour_bits": "3"}, "colour_bits must be an integer"), ({"eps2": float("nan")}, "eps2 must be a finite"),
               ({"eps2": float("inf")}, "eps2 must be a finite"), ({"eps2": "1"}, "eps2 must be a finite"),
               ({"eps2": False}, "eps2 must be a finite")]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kw,msg", PARAM_CASES)
def test_param_types_checked_in_both_models(model, kw, msg):
    """Same check, same message, at construction, in both models (one shared class)."""
    from mstrack.track.params import ParamTypeError
    with pytest.raises(ParamTypeError, match=msg) as ei:
        Tracker(model=model, **kw)
    assert isinstance(ei.value, TypeError) and isinstance(ei.value, ValueError)


@pytest.mark.parametrize("kw", [{"max_half": 63.0}, {"margin": True}, {"centre_frac": 8.5}, {"rho_frac": None}])
def test_fixed_param_types_checked(kw):
    from mstrack.fixed import FixedParams
    from mstrack.track.params import ParamTypeError
    with pytest.raises(ParamTypeError, match=next(iter(kw))):
        FixedParams(**kw)


def test_numpy_integer_params_are_accepted_as_int(scene):
    from mstrack.track.params import TrackerParams
    tp = TrackerParams(colour_bits=np.int64(3), max_iter=np.int32(20), eps2=np.float32(1.0))
    assert type(tp.colour_bits) is int and type(tp.max_iter) is int and type(tp.eps2) is float
    assert tp == TrackerParams()


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")
@pytest.mark.parametrize("model", MODELS)
def test_np_matrix_frames_are_grey_frames(model, scene):
    """np.matrix is an ndarray subclass that cannot be 3-D: read as a plain 2-D (grey) array."""
    f0, f1, _, box = scene
    g0, g1 = (cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) for f in (f0, f1))
    ref = Tracker(model=model)
    ref.init(g0, box)
    trk = Tracker(model=model)
    assert trk.init(np.matrix(g0), box).status == Status.INIT
    assert trk.update(np.matrix(g1)).box == ref.update(g1).box
