"""Tracker v2 float: the numba path gives the numpy path's results bit for bit.

Every TrackResult (box, centre, confidence, rho, status, iterations, extra: share,
spread, decimation, searched) is compared with ``==`` frame by frame, on synthetic
scenes (moving target, scale change, decimated large targets, occlusion / loss /
re-acquisition, frame borders, both kernels) and on two real sequences from
../shared/data/sequences (skipped if absent).  Single window passes are compared
on random frames and windows, tiny and empty windows included.
"""
from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack.track import float_model as fm
from mstrack.track import float_v2 as v2
from mstrack.io.data import load_dataset
from mstrack.track.params import V2_COLOUR, TrackerParams
from mstrack.io.synthetic import make_scene
from mstrack.track.types import Status

SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
# numba installed and not switched off: the self-check must pass (a failure is a test failure, not a skip)
HAVE_NUMBA = fm._numba_njit is not None and os.environ.get("MSTRACK_NUMBA", "1") != "0"
needs_numba = pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed or MSTRACK_NUMBA=0")
KERNELS = ["flat", "epanechnikov"]


def _run(path, frames, box, **params):
    trk = v2.FloatTrackerV2(TrackerParams(preset="v2", **params), path=path)
    assert trk.active_path() == path
    out = [trk.init(frames[0], box)]
    for f in frames[1:]:
        out.append(trk.update(f))
    return out


def _assert_identical(frames, box, **params):
    want = _run("numpy", frames, box, **params)
    got = _run("numba", frames, box, **params)
    assert len(got) == len(want)
    for i, (g, w) in enumerate(zip(got, want)):
        assert g == w, f"frame {i}: numba {g} != numpy {w}"
    return want


def _background(rng, height, width):
    """Smooth green / blue texture with fine grain (BGR)."""
    small = rng.integers(0, 256, (height // 16 + 2, width // 16 + 2, 3)).astype(np.float32)
    bg = cv2.resize(small, (width, height), interpolation=cv2.INTER_CUBIC)
    bg = bg * np.float32([0.5, 0.4, 0.15]) + np.float32([90, 80, 30])
    return bg + rng.normal(0.0, 8.0, bg.shape).astype(np.float32)


def _target(rng, h, w):
    """Red / yellow checkerboard (BGR)."""
    yy, xx = np.mgrid[0:h, 0:w]
    cell = max(3, min(w, h) // 6)
    check = ((yy // cell + xx // cell) % 2).astype(bool)
    t = np.empty((h, w, 3), np.float32)
    t[check], t[~check] = (30, 40, 210), (40, 200, 230)
    return t + rng.normal(0.0, 6.0, t.shape).astype(np.float32)


def _render(height, width, boxes, seed=0, occluded=()):
    """Frames with the target at ``boxes`` (x, y, w, h; may leave the frame); frames in ``occluded``
    have a grey occluder over the target."""
    rng = np.random.default_rng(seed)
    bg = _background(rng, height, width)
    frames = []
    for i, (x, y, w, h) in enumerate(boxes):
        f = bg + rng.normal(0.0, 3.0, bg.shape).astype(np.float32)
        t = _target(rng, h, w)
        fx0, fy0, fx1, fy1 = max(x, 0), max(y, 0), min(x + w, width), min(y + h, height)
        if fx1 > fx0 and fy1 > fy0:
            f[fy0:fy1, fx0:fx1] = t[fy0 - y:fy1 - y, fx0 - x:fx1 - x]
        if i in occluded:
            f[max(y - 6, 0):max(y + h + 6, 0), max(x - 6, 0):max(x + w + 6, 0)] = 128.0
        frames.append(np.clip(f, 0, 255).astype(np.uint8))
    return frames


# ----------------------------------------------------------------------------- single passes
@needs_numba
def test_numba_self_check_passes():
    assert v2._numba_self_check()
    assert v2._numba_ready()


@needs_numba
def test_window_pass_equal_random_windows():
    rng = np.random.default_rng(11)
    for _ in range(60):
        height, width = (int(v) for v in rng.integers(4, 150, 2))
        frame = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
        if rng.random() < 0.5:
            frame = cv2.GaussianBlur(frame, (5, 5), 1.5)
        d = int(rng.choice([1, 2, 4, 8]))
        src = frame[::d, ::d]
        bits = int(rng.integers(1, 5))
        nb = 1 << (3 * bits)
        q = rng.random(nb)
        q[rng.random(nb) < 0.4] = 0.0
        q /= q.sum()
        t = (rng.random(nb) < 0.5).astype(np.float64)
        bins = fm.colour_bins(src, bits)
        h, w = bins.shape
        for _ in range(8):
            c = (float(rng.uniform(0, w - 1)), float(rng.uniform(0, h - 1)))
            if rng.random() < 0.2:
                c = (float(rng.choice([0.0, w - 1.0])), float(rng.choice([0.0, h - 1.0])))
            hx, hy = (float(v) for v in rng.uniform(0.05, 70.0, 2) ** rng.choice([1.0, 0.5]))
            inner2 = float(rng.choice([1.0 / 1.25 ** 2, 0.5]))
            for kernel in KERNELS:
                want = v2.window_pass(bins, nb, q, t, c, hx, hy, inner2, kernel)
                got = v2.window_pass_numba(src, bits, q, t, c, hx, hy, inner2, kernel)
                assert got == want, (d, c, hx, hy, kernel)


@needs_numba
def test_window_pass_without_pixels():
    """A window narrower than a pixel between two columns holds no pixel: rho 0, sums 0."""
    frame = np.full((20, 20, 3), 200, np.uint8)
    q = np.full(512, 1 / 512)
    t = np.ones(512)
    bins = fm.colour_bins(frame, 3)
    for kernel in KERNELS:
        want = v2.window_pass(bins, 512, q, t, (5.5, 7.0), 0.3, 4.0, 0.64, kernel)
        got = v2.window_pass_numba(frame, 3, q, t, (5.5, 7.0), 0.3, 4.0, 0.64, kernel)
        assert got == want and got.rho == 0.0 and got.n_in == 0


# ----------------------------------------------------------------------------- trackers
@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_moving_target(kernel):
    frames, gt = make_scene(40, 320, 240, seed=3, target_size=(41, 33))
    res = _assert_identical(list(frames), tuple(gt[0]), kernel=kernel)
    assert sum(r.status == Status.OK for r in res) > 30


@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_scale_change(kernel):
    """The target grows from 20 to 50 px and shrinks back: the two paths agree, and tracker v2 on
    colour alone (V2_COLOUR) follows it (scale every frame); the default's gated scale test vetoes
    the growth on this scene (tests/test_float_v2.py::test_scale_followed_default)."""
    sizes = [20 + i for i in range(30)] + [50 - i for i in range(25)]
    boxes = [(60 + 2 * i - s // 2, 90 - s // 2, s, s) for i, s in enumerate(sizes)]
    frames = _render(200, 280, boxes, seed=1)
    res = _assert_identical(frames, boxes[0], kernel=kernel, **V2_COLOUR)
    widths = [r.box.w for r in res]
    assert max(widths) > 24 and widths[-1] < max(widths) - 1
    _assert_identical(frames, boxes[0], kernel=kernel)


@needs_numba
@pytest.mark.parametrize("extra", [{"scale_test": 0.05, "scale_test_gate": True},
                                   {"scale_test": 0.1, "scale_test_mix": 0.5}, {"motion_gain": 0.5},
                                   {"orient_T": 64}, {"orient_T": 32, "scale_test": 0.05, "scale_test_gate": True},
                                   {"orient_T": 32, "scale_test": 0.05, "scale_test_gate": True,
                                    "kernel": "epanechnikov"}])
def test_experimental_options(extra):
    """The experimental options (off by default; docs/results_v2_mean.md) are bit-identical too."""
    sizes = [20 + i for i in range(30)] + [50 - i for i in range(25)]
    boxes = [(60 + 2 * i - s // 2, 90 - s // 2, s, s) for i, s in enumerate(sizes)]
    res = _assert_identical(_render(200, 280, boxes, seed=1), boxes[0], **extra)
    assert sum(r.ok for r in res) > 40


@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_large_target_decimated(kernel):
    """Targets of 300 and 430 px: decimation 4 and 8 (the kernel reads every D-th pixel)."""
    boxes = [(100 + 3 * i, 60 + i, 300 + 4 * i, 280 + 3 * i) for i in range(8)]
    res = _assert_identical(_render(420, 640, boxes, seed=2), boxes[0], kernel=kernel)
    assert {r.extra["decimation"] for r in res[1:]} == {4}
    boxes = [(60 + 2 * i, 40, 430, 330) for i in range(6)]
    res = _assert_identical(_render(420, 640, boxes, seed=3), boxes[0], kernel=kernel)
    assert {r.extra["decimation"] for r in res[1:]} == {8}


@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_occlusion_loss_and_reacquisition(kernel):
    """Occluded for 8 frames: lost (wide search from 9 start points at 2 D), then re-acquired."""
    boxes = [(80 + 2 * i, 70 + (i % 7), 36, 30) for i in range(40)]
    frames = _render(220, 320, boxes, seed=4, occluded=range(15, 23))
    res = _assert_identical(frames, boxes[0], kernel=kernel)
    status = [r.status for r in res]
    assert Status.LOST in status and Status.REACQUIRED in status
    assert any(r.extra.get("searched") == 8 for r in res)


@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_frame_borders(kernel):
    """Init box partly outside (clipped), windows clipped at every border, target leaving the frame."""
    # enters at the top-left corner, crosses, leaves through the bottom-right corner
    boxes = [(-12 + 9 * i, -10 + 6 * i, 34, 28) for i in range(36)]
    res = _assert_identical(_render(180, 260, boxes, seed=5), boxes[0], kernel=kernel)
    assert res[0].status == Status.CLIPPED
    # along the right border, then out of the frame
    boxes = [(230 + i, 40 + 2 * i, 30, 30) for i in range(30)]
    _assert_identical(_render(180, 260, boxes, seed=6), boxes[0], kernel=kernel)


@needs_numba
def test_shift_test_near_eps2_is_decided_in_python(monkeypatch):
    """s2 within rounding of eps2 goes back to Python (``dx ** 2`` is libm's pow, not dx * dx)."""
    boxes = [(50, 40, 37, 29), (53, 42, 37, 29)]
    frames = _render(150, 200, boxes, seed=7)
    trk = v2.FloatTrackerV2(TrackerParams(preset="v2", **V2_COLOUR), path="numpy")   # colour bins below
    trk.init(frames[0], boxes[0])
    w, h = trk._size
    hx, hy = 1.25 * w / 2.0, 1.25 * h / 2.0
    start = trk._centre
    bins = fm.colour_bins(frames[1], 3)
    c1, _, _ = trk._track(bins, start, hx, hy, 1)
    assert c1 != start
    s2 = (c1[0] - start[0]) ** 2 + (c1[1] - start[1]) ** 2
    codes = []
    kernel = v2._nb_track

    def spy(*args):
        r = kernel(*args)
        codes.append(r[0])
        return r

    monkeypatch.setattr(v2, "_nb_track", spy)
    trk._bufs = v2._nb_buffers_v2(hx, hy, 512)
    trk._cache = v2._bins_cache(*frames[1].shape[:2])
    for eps2 in (s2, float(np.nextafter(s2, np.inf))):  # go on, stop at c1
        trk.params = TrackerParams(preset="v2", eps2=eps2, **V2_COLOUR)
        want = trk._track(bins, start, hx, hy, 10)
        got = trk._track(frames[1], start, hx, hy, 10)
        assert got == want
    assert codes.count(1) == 2


@pytest.fixture(scope="module")
def real_sequences():
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"real sequences not found at {SEQ_ROOT}")
    seqs = {s.name: s for s in load_dataset(SEQ_ROOT)}
    # Couple: loss and re-acquisition at D 1 / 2; bag_vot: decimation 2 and 4, long loss
    names = [n for n in ("Couple", "bag_vot") if n in seqs] or sorted(seqs)[:2]
    return {n: ([seqs[n].frame(i) for i in range(len(seqs[n]))], seqs[n].init_box()) for n in names}


@needs_numba
def test_real_sequences_identical(real_sequences):
    for name, (frames, box) in real_sequences.items():
        _assert_identical(frames, box)


@needs_numba
def test_real_sequences_identical_joint_gate(real_sequences):
    """The joint colour x orientation bins with the gated scale test (off by default), both paths."""
    for name, (frames, box) in real_sequences.items():
        _assert_identical(frames, box, orient_T=64, scale_test=0.05, scale_test_gate=True)


def _assert_fields_identical(frames, box, **params):
    """Both paths, every TrackResult field compared by itself (box, centre, rho, iterations, status,
    confidence and each entry of ``extra``), frame by frame."""
    from dataclasses import fields
    want = _run("numpy", frames, box, **params)
    got = _run("numba", frames, box, **params)
    assert len(got) == len(want)
    for i, (g, w) in enumerate(zip(got, want)):
        for f in fields(w):
            gv, wv = getattr(g, f.name), getattr(w, f.name)
            if f.name == "extra":
                assert gv.keys() == wv.keys(), f"frame {i}: extra keys"
                for k in wv:
                    assert gv[k] == wv[k], f"frame {i}: extra[{k!r}] numba {gv[k]!r} != numpy {wv[k]!r}"
            else:
                assert gv == wv, f"frame {i}: {f.name} numba {gv!r} != numpy {wv!r}"
        assert g == w
    return want


@needs_numba
@pytest.mark.parametrize("kernel", KERNELS)
def test_joint_synthetic_all_decimations(kernel):
    """The joint tracker (V2_JOINT, the candidate default) on synthetic scenes that need D 1, 2 and 4
    and a lost target (the wide search at 2 D): the joint bins' three paths (D 1, D 2 with the grey
    cache, D > 2 straight-line), the prefetch and the many-bins passes, both paths field by field."""
    from mstrack.track.params import V2_JOINT
    boxes = [(80 + 2 * i, 70 + (i % 7), 36, 30) for i in range(30)]
    res = _assert_fields_identical(_render(220, 320, boxes, seed=4, occluded=range(12, 18)), boxes[0],
                                   kernel=kernel, **V2_JOINT)
    assert any(r.extra.get("searched") for r in res)
    boxes = [(40 + 4 * i, 30 + 2 * i, 150 + 2 * i, 120 + i) for i in range(12)]
    res = _assert_fields_identical(_render(300, 480, boxes, seed=8), boxes[0], kernel=kernel, **V2_JOINT)
    assert {r.extra["decimation"] for r in res[1:]} == {2}
    boxes = [(60 + 3 * i, 40 + i, 300 + 4 * i, 260 + 3 * i) for i in range(8)]
    res = _assert_fields_identical(_render(420, 640, boxes, seed=2), boxes[0], kernel=kernel, **V2_JOINT)
    assert {r.extra["decimation"] for r in res[1:]} == {4}


@pytest.fixture(scope="module")
def real_joint_clips():
    """Real clips that take the joint tracker through D 1, 2 and 4 (MotorRolling: D 2 and its lost
    search at D 4; Deer: large D 1 windows; Girl: a 128 x 96 frame)."""
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"real sequences not found at {SEQ_ROOT} (the synthetic joint test runs without them)")
    seqs = {s.name: s for s in load_dataset(SEQ_ROOT)}
    names = [n for n in ("MotorRolling", "Deer", "Girl") if n in seqs]
    if not names:
        pytest.skip(f"none of MotorRolling, Deer, Girl in {SEQ_ROOT}")
    return {n: ([seqs[n].frame(i) for i in range(min(len(seqs[n]), 60))], seqs[n].init_box()) for n in names}


@needs_numba
def test_real_joint_fields_identical(real_joint_clips):
    """V2_JOINT (orient_T 64, gated scale test, its loss thresholds) on real frames: numba and numpy
    give every TrackResult field equal, frame by frame."""
    from mstrack.track.params import V2_JOINT
    for name, (frames, box) in real_joint_clips.items():
        _assert_fields_identical(frames, box, **V2_JOINT)


# ----------------------------------------------------------------------------- path selection
def test_unknown_path_rejected():
    with pytest.raises(ValueError):
        v2.FloatTrackerV2(path="fast")


def test_auto_path():
    trk = v2.FloatTrackerV2()
    assert trk.active_path() == ("numba" if HAVE_NUMBA else "numpy")
    assert v2.FloatTrackerV2(path="numpy").active_path() == "numpy"


def test_numba_switched_off_falls_back_to_numpy(monkeypatch):
    monkeypatch.setenv("MSTRACK_NUMBA", "0")
    monkeypatch.setattr(fm, "_NUMBA_OK", None)
    monkeypatch.setattr(v2, "_NUMBA_OK", None)
    assert not v2._numba_ready()
    assert v2.FloatTrackerV2().active_path() == "numpy"
    with pytest.raises(RuntimeError):
        v2.FloatTrackerV2(path="numba").active_path()


@needs_numba
@pytest.mark.parametrize("T", [1, 32, 64, 300])
def test_joint_bins_kernel_equals_whole_frame(T):
    """The joint bins the numba kernel computes lazily (_nb_bins, pixel by pixel, areas in any
    order) equal the whole decimated image's (FloatTrackerV2._bins, numpy), frame border included."""
    rng = np.random.default_rng(5 + T)
    frame = np.ascontiguousarray(rng.integers(0, 256, (97, 203, 3), dtype=np.uint8))
    frame[20:60, 30:150] = cv2.GaussianBlur(frame[20:60, 30:150], (0, 0), 3)
    frame[70:, 100:] //= 7
    for d in (1, 2, 4, 8):
        trk = v2.FloatTrackerV2(TrackerParams(preset="v2", orient_T=T), path="numpy")
        whole = trk._bins(frame, d)
        h, w = whole.shape
        cache, rows, grey = v2._bins_cache(*frame.shape[:2], True)
        src = frame[::d, ::d]
        for x0, x1, y0, y1 in ((3, 40, 2, 11), (0, 4, 0, 6), (w - 9, w - 1, h - 4, h - 1), (1, 50, 5, 30),
                               (w // 3, w // 2, h // 4, h - 2), (0, w - 1, 0, h - 1)):  # inclusive
            x0, x1, y0, y1 = min(x0, w - 1), min(x1, w - 1), min(y0, h - 1), min(y1, h - 1)
            v2._nb_bins(src, 3, cache, rows, grey, x0, x1, y0, y1, frame, d, T)
        assert np.array_equal(cache[:h, :w], whole), d
    # features_v2.sobel's float32 order is cv2.Sobel's on frames whose width is a multiple of 8
    from mstrack.track.features import grey_area
    from mstrack.track.features_v2 import sobel
    f2 = np.ascontiguousarray(rng.integers(0, 256, (61, 320, 3), dtype=np.uint8))
    g = grey_area(f2, 0, f2.shape[1], 0, f2.shape[0])
    gx, gy = sobel(f2)
    assert np.array_equal(gx[1:-1, 1:-1], cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=3)[1:-1, 1:-1])
    assert np.array_equal(gy[1:-1, 1:-1], cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=3)[1:-1, 1:-1])
