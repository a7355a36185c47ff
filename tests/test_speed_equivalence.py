"""The float tracker's fast paths give the reference path's results, bit for bit.

mstrack/track/float_model.py has three ways to compute the same numbers (docs/bench.md):
"reference" (whole-frame bins, ``meanshift``), "numpy" (bins of a search area only,
``_meanshift_area``) and "numba" (the same loop compiled, ``_nb_meanshift``).  These
tests hold the fast paths to the reference on real sequences (../shared/data/sequences,
skipped if absent) and on synthetic frames: identical bins on every computed pixel
(including the Sobel at the area border and the zero-gradient frame border), identical
iterations, stops and statuses, and centres equal to 1e-9 px (they are in fact equal to
the last bit; the synthetic tests assert that).
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack.track import float_model as fm
from mstrack.eval.agreement import shift_scene
from mstrack.io.data import load_dataset
from mstrack.track.params import TrackerParams
from mstrack.io.synthetic import make_scene

SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
HAVE_NUMBA = fm._numba_ready()
FAST_PATHS = ["numpy"] + (["numba"] if HAVE_NUMBA else [])
VARIANTS = {
    "default": {},
    "epanechnikov": {"kernel": "epanechnikov"},
    "colour5": {"features": "colour", "colour_bits": 5, "eps2": 0.01},
    "edge64": {"features": "edge", "edge_bins_log2": 6, "edge_shift": 2, "max_iter": 7},
}
CENTRE_TOL = 1e-9  # px


@pytest.fixture(scope="module")
def real_frames():
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"real sequences not found at {SEQ_ROOT}")
    return {s.name: ([s.frame(i) for i in range(min(len(s), 40))], s.init_box())
            for s in load_dataset(SEQ_ROOT)}


def _run(path, frames, box, **params):
    trk = fm.FloatTracker(TrackerParams(**params), path=path)
    out = [trk.init(frames[0], box)]
    for f in frames[1:]:
        out.append(trk.update(f))
    return out, trk


def _assert_same(got, want, exact=False):
    assert len(got) == len(want)
    for i, (g, w) in enumerate(zip(got, want)):
        where = f"frame {i}"
        assert (g.iter_c, g.iter_e, g.status, g.extra.get("stop_c"), g.extra.get("stop_e")) == \
               (w.iter_c, w.iter_e, w.status, w.extra.get("stop_c"), w.extra.get("stop_e")), where
        if exact:
            assert (g.centre, g.rho_c, g.rho_e, g.alpha_c, g.extra) == \
                   (w.centre, w.rho_c, w.rho_e, w.alpha_c, w.extra), where
        else:
            assert np.allclose(g.centre, w.centre, rtol=0, atol=CENTRE_TOL), where
            assert np.allclose((g.rho_c, g.rho_e, g.alpha_c), (w.rho_c, w.rho_e, w.alpha_c),
                               rtol=0, atol=1e-12), where


def _random_frames(rng, n):
    for i in range(n):
        h, w = (int(v) for v in rng.integers(3, 260, 2))
        f = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
        yield cv2.GaussianBlur(f, (5, 5), 1.5) if i % 2 else f


def _random_areas(rng, width, height, n):
    yield 0, width, 0, height
    yield 0, 1, 0, 1
    yield width - 1, width, height - 1, height
    for _ in range(n):
        x0 = int(rng.integers(0, width))
        y0 = int(rng.integers(0, height))
        yield x0, int(rng.integers(x0 + 1, width + 1)), y0, int(rng.integers(y0 + 1, height + 1))


def _check_bins(frame, rng, n_areas):
    height, width = frame.shape[:2]
    for bits in (1, 3, 8):
        ref = fm.colour_bins(frame, bits)
        for x0, x1, y0, y1 in _random_areas(rng, width, height, n_areas):
            np.testing.assert_array_equal(fm.colour_bins_area(frame, bits, x0, x1, y0, y1), ref[y0:y1, x0:x1])
    for n_bins, shift in ((16, 5), (256, 0), (8, 3)):
        ref = fm.edge_bins(frame, n_bins, shift)
        for x0, x1, y0, y1 in _random_areas(rng, width, height, n_areas):
            want = ref[y0:y1, x0:x1]
            np.testing.assert_array_equal(fm.edge_bins_area(frame, n_bins, shift, x0, x1, y0, y1), want)
            if HAVE_NUMBA:
                got = fm.edge_bins_area(frame, n_bins, shift, x0, x1, y0, y1, np.int32, kernels=True)
                np.testing.assert_array_equal(got, want)


# ----------------------------------------------------------------------------- bins
def test_grey_area_equals_whole_frame_product():
    rng = np.random.default_rng(1)
    for frame in _random_frames(rng, 20):
        height, width = frame.shape[:2]
        # the definition element-wise in float32 ((B wb + G wg) + R wr); not ``frame @ weights``,
        # whose rounding depends on the BLAS kernel the CPU selects (it differs on AVX-512 machines)
        f = frame.astype(np.float32)
        wb, wg, wr = (np.float32(w) for w in fm.GREY_WEIGHTS_BGR)
        ref = (f[..., 0] * wb + f[..., 1] * wg) + f[..., 2] * wr
        for x0, x1, y0, y1 in _random_areas(rng, width, height, 10):
            np.testing.assert_array_equal(fm.grey_area(frame, x0, x1, y0, y1), ref[y0:y1, x0:x1])


def test_area_bins_equal_whole_frame_bins_synthetic():
    """Random sizes (widths around every SIMD block), areas touching the frame border or not."""
    rng = np.random.default_rng(2)
    for frame in _random_frames(rng, 40):
        _check_bins(frame, rng, 12)
    for width in (63, 64, 65, 127, 130, 200):  # strips that end on the alignment or on the frame
        _check_bins(rng.integers(0, 256, (20, width, 3), dtype=np.uint8), rng, 40)


def test_area_bins_equal_whole_frame_bins_real(real_frames):
    rng = np.random.default_rng(3)
    for frames, _ in real_frames.values():
        for frame in (frames[0], frames[-1]):
            _check_bins(frame, rng, 15)


# ----------------------------------------------------------------------------- numba kernels
@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed (the numpy path runs)")
def test_pairwise_sums_equal_numpy():
    rng = np.random.default_rng(4)
    for n in list(range(0, 300)) + [1023, 1024, 1025, 8191, 8192, 8193, 40000]:
        w = rng.random(n) * rng.choice([1e-6, 1.0, 1e6])
        x, y = rng.integers(0, 4000, n), rng.integers(0, 3000, n)
        assert fm._nb_sum(w, n) == w.sum()
        got = fm._nb_sum3(w, np.arange(n, dtype=np.int32), x.astype(np.int32), y.astype(np.int32), n)
        assert got == (w.sum(), (w * x).sum(), (w * y).sum())


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed (the numpy path runs)")
def test_shift_test_near_eps2_is_decided_as_meanshift_does(monkeypatch):
    """shift2 within rounding of eps2 goes back to Python (libm pow rounds x**2 its own way)."""
    f0, f1, box = shift_scene(2.5, -1.75)
    ref = fm.FloatTracker(TrackerParams(features="colour"), path="reference")
    ref.init(f0, box)
    start = ref._centre
    hx, hy = ref._size[0] / 2.0, ref._size[1] / 2.0
    bc = fm.colour_bins(f1, 3)
    step = fm.meanshift(bc, ref._q_c, start, hx, hy, TrackerParams(features="colour", max_iter=1), 512)
    assert step.stop in ("shift", "max_iter")
    shift2 = (step.centre[0] - start[0]) ** 2 + (step.centre[1] - start[1]) ** 2
    codes = []
    kernel = fm._nb_meanshift

    def spy(*args):
        r = kernel(*args)
        codes.append(r[0])
        return r

    monkeypatch.setattr(fm, "_nb_meanshift", spy)
    for eps2 in (shift2, np.nextafter(shift2, np.inf)):  # continue, stop
        params = TrackerParams(features="colour", eps2=float(eps2))
        want = fm.meanshift(bc, ref._q_c, start, hx, hy, params, 512)
        got = fm._meanshift_numba(np.ascontiguousarray(f1), 3, None, ref._q_c, start, hx, hy, params,
                                  f1.shape[1], f1.shape[0], fm._nb_buffers(hx, hy, 512))
        assert got == want
    assert codes.count(-2) == 2


# ----------------------------------------------------------------------------- tracking
@pytest.mark.parametrize("variant", list(VARIANTS))
@pytest.mark.parametrize("path", FAST_PATHS)
def test_tracking_equal_real(real_frames, path, variant):
    for name, (frames, box) in real_frames.items():
        want, _ = _run("reference", frames, box, **VARIANTS[variant])
        got, trk = _run(path, frames, box, **VARIANTS[variant])
        assert trk.active_path() == path
        _assert_same(got, want)


@pytest.mark.parametrize("path", FAST_PATHS)
@pytest.mark.parametrize("variant", list(VARIANTS))
def test_tracking_bit_identical_synthetic(path, variant):
    frames, gt = make_scene(25, 200, 150, seed=5, target_size=(37, 29))
    want, _ = _run("reference", list(frames), tuple(gt[0]), **VARIANTS[variant])
    got, _ = _run(path, list(frames), tuple(gt[0]), **VARIANTS[variant])
    _assert_same(got, want, exact=True)


@pytest.mark.parametrize("path", FAST_PATHS)
def test_area_grows_when_the_window_leaves_it(path):
    """A 14 px jump of a 41 x 31 target: the windows leave the first area, which is regrown."""
    f0, f1, box = shift_scene(14.0, -9.0)
    want, _ = _run("reference", [f0, f1, f0], box, eps2=0.01)
    got, trk = _run(path, [f0, f1], box, eps2=0.01)
    grown = [a.n_computed for a in trk.last_areas if a is not None]
    got.append(trk.update(f0))
    assert max(grown) > 1
    _assert_same(got, want, exact=True)


@pytest.mark.parametrize("path", FAST_PATHS)
@pytest.mark.parametrize("corner", ["top-left", "bottom-right"])
def test_target_at_the_frame_border(path, corner):
    """Windows clipped by the frame; the border pixels have |G| = 0 in every path."""
    frames, gt = make_scene(12, 160, 120, seed=7, target_size=(30, 26))
    x, y, w, h = gt[0]
    if corner == "top-left":
        frames = frames[:, int(y) + 5:, int(x) + 6:]
        box = (-6.0, -5.0, w, h)
    else:
        frames = frames[:, :int(y + h) - 4, :int(x + w) - 7]
        box = (x, y, w, h)
    frames = [np.ascontiguousarray(f) for f in frames]
    want, _ = _run("reference", frames, box)
    got, _ = _run(path, frames, box)
    _assert_same(got, want, exact=True)


def test_replaced_kernel_window_selects_the_reference_path(monkeypatch):
    """mstrack.eval.agreement's window-grid analysis replaces kernel_window: the tracker must call it."""
    calls = []
    orig = fm.kernel_window

    def spy(*args):
        calls.append(args)
        return orig(*args)

    trk = fm.FloatTracker()
    assert trk.active_path() in ("numpy", "numba")
    monkeypatch.setattr(fm, "kernel_window", spy)
    f0, f1, box = shift_scene(1.0, 1.0)
    trk.init(f0, box)
    trk.update(f1)
    assert trk.active_path() == "reference" and calls


def test_unknown_path_rejected():
    with pytest.raises(ValueError):
        fm.FloatTracker(path="fast")


def test_numba_switched_off_falls_back_to_numpy(monkeypatch):
    monkeypatch.setenv("MSTRACK_NUMBA", "0")
    monkeypatch.setattr(fm, "_NUMBA_OK", None)
    assert not fm._numba_ready()
    assert fm.FloatTracker().active_path() == "numpy"
    with pytest.raises(RuntimeError):
        fm.FloatTracker(path="numba").active_path()
