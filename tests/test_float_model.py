"""Tests of the float reference tracker (mstrack/track/float_model.py).

Synthetic scenes come from :func:`mstrack.eval.agreement.shift_scene` (seeded): an
elliptical red/yellow checkerboard target moved by (dx, dy) over a smooth
bluish background.  The convergence tests use ``eps2 = 0.01`` px^2 so that
the loop runs to the optimum rather than stopping at the default 1 px step.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mstrack import Tracker
from mstrack.track import float_model as fm
from mstrack.eval.agreement import shift_scene
from mstrack.track.params import TrackerParams
from mstrack.track.types import FeatureResult

SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
INT_SHIFTS = [(3, -2), (-6, 4), (8, 8)]
SUB_SHIFTS = [(0.5, -0.25), (2.75, 1.5), (-1.25, -3.5)]


def _track(dx, dy, **params):
    f0, f1, box = shift_scene(dx, dy)
    trk = Tracker(model="float", **{"preset": "paper", **params})  # the paper model unless asked
    r0 = trk.init(f0, box)
    r1 = trk.update(f1)
    err = math.hypot(r1.centre[0] - r0.centre[0] - dx, r1.centre[1] - r0.centre[1] - dy)
    return r0, r1, err


# ----------------------------------------------------------------------------- primitives
def test_histogram_sums_to_one():
    rng = np.random.default_rng(1)
    bins = rng.integers(0, 512, (60, 80))
    for kernel in ("flat", "epanechnikov"):
        win = fm.kernel_window(40.3, 29.7, 12.5, 9.0, kernel, 80, 60)
        h = fm.histogram(bins, win, 512)
        assert h.shape == (512,)
        assert h.sum() == pytest.approx(1.0, abs=1e-12)
        assert (h >= 0).all()


def test_histogram_of_empty_window_is_zero():
    win = fm._Window(np.zeros(0, int), np.zeros(0, int), np.zeros(0))
    assert fm.histogram(np.zeros((5, 5), int), win, 4).sum() == 0


def test_bhattacharyya_identical_and_disjoint():
    rng = np.random.default_rng(2)
    p = rng.random(64)
    p /= p.sum()
    assert fm.bhattacharyya(p, p) == pytest.approx(1.0, abs=1e-12)
    a = np.zeros(64)
    b = np.zeros(64)
    a[:32] = 1 / 32
    b[32:] = 1 / 32
    assert fm.bhattacharyya(a, b) == 0.0


def test_weights_zero_where_p_is_zero():
    p = np.array([0.0, 0.25, 0.75, 0.0])
    q = np.array([0.5, 0.25, 0.0, 0.25])
    w = fm.bin_weights(p, q)
    np.testing.assert_allclose(w, [0.0, 1.0, 0.0, 0.0])
    assert np.isfinite(w).all()


# ----------------------------------------------------------------------------- convergence
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
@pytest.mark.parametrize("dx,dy", INT_SHIFTS + SUB_SHIFTS)
def test_colour_finds_shift_within_half_pixel(kernel, dx, dy):
    _, r1, err = _track(dx, dy, features="colour", kernel=kernel, eps2=0.01)
    assert err < 0.5, f"colour/{kernel} shift ({dx}, {dy}): error {err:.3f} px, {r1.extra}"


# Edge and fused on the same scene: the edge histogram (16 |G| bins, 94 % of
# the target in the saturated bin) gives a very flat rho surface (0.995 ..
# 0.9999 within +-1 px), so the "rho" stop rule ends the loop up to ~1.2 px
# from the optimum; sub-pixel motion resamples the texture and changes its
# Sobel magnitudes (the edge model no longer matches).  Measured errors on
# integer shifts: edge <= 1.17 px, fused <= 0.64 px.  Tolerances below.
EDGE_TOL = {"edge": 1.25, "fused": 0.75}


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
@pytest.mark.parametrize("features", ["edge", "fused"])
@pytest.mark.parametrize("dx,dy", INT_SHIFTS)
def test_edge_and_fused_find_integer_shift(features, kernel, dx, dy):
    _, r1, err = _track(dx, dy, features=features, kernel=kernel, eps2=0.01)
    assert err < EDGE_TOL[features], f"{features}/{kernel} ({dx}, {dy}): {err:.3f} px {r1.extra}"


@pytest.mark.parametrize("features", ["fused", "colour", "edge"])
def test_zero_shift_stays_put(features):
    _, r1, err = _track(0, 0, features=features)
    assert err < 1e-9
    assert r1.iter_c <= 1 and r1.iter_e <= 1


# ----------------------------------------------------------------------------- max_iter
@pytest.mark.parametrize("max_iter", [1, 2])
def test_stops_at_max_iter(max_iter):
    _, r1, err = _track(8, 8, features="colour", max_iter=max_iter, eps2=0.01)
    assert r1.iter_c == max_iter
    assert r1.extra["stop_c"] == "max_iter"
    assert err > 2.0  # built to need more: an (8, 8) px move takes 8 iterations


def test_case_needing_more_iterations_converges_with_default():
    _, r1, err = _track(8, 8, features="colour", eps2=0.01)
    assert 2 < r1.iter_c < 20 and r1.extra["stop_c"] == "shift" and err < 0.5


# ----------------------------------------------------------------------------- stop reasons
def _ms(bins, q, start, h, **kw):
    p = TrackerParams(features="colour", **kw)
    return fm.meanshift(bins, q, start, h, h, p, len(q))


def test_stop_shift():
    f0, _, box = shift_scene(0, 0)
    trk = Tracker(model="float", preset="paper", features="colour")
    trk.init(f0, box)
    r = trk.update(f0)
    assert r.extra["stop_c"] == "shift" and r.iter_c == 1


def test_stop_rho():
    """Seeded random 3-bin image (seed 40 found by search): the first step lowers rho."""
    rng = np.random.default_rng(40)
    bins = rng.integers(0, 3, (15, 15))
    q = fm.histogram(rng.integers(0, 3, (15, 15)), fm.kernel_window(7, 7, 3.5, 3.5, "flat", 15, 15), 3)
    r = _ms(bins, q, (7.0, 7.0), 3.5, eps2=0.01)
    assert r.stop == "rho" and r.iterations == 1
    assert r.centre == (7.0, 7.0)  # the rejected step is not taken
    win = fm.kernel_window(7.0, 7.0, 3.5, 3.5, "flat", 15, 15)
    assert r.rho == pytest.approx(fm.bhattacharyya(fm.histogram(bins, win, 3), q))


def test_stop_max_iter_direct():
    f0, f1, box = shift_scene(8, 8)
    trk = Tracker(model="float", preset="paper", features="colour", max_iter=1)
    trk.init(f0, box)
    assert trk.update(f1).extra["stop_c"] == "max_iter"


def test_stop_lost():
    """No model bin in the window (frame of a colour absent from the target): all weights 0."""
    f0, _, box = shift_scene(0, 0)
    trk = Tracker(model="float", preset="paper", features="colour")
    r0 = trk.init(f0, box)
    blue = np.zeros_like(f0)
    blue[..., 0] = 255
    r = trk.update(blue)
    assert r.extra["stop_c"] == "lost" and r.status.value == "lost"
    assert r.centre == r0.centre


# ----------------------------------------------------------------------------- fusion
def test_fuse_alphas_follow_rhos():
    a = FeatureResult((10.0, 20.0), 0.9, 3, "shift")
    b = FeatureResult((14.0, 16.0), 0.3, 2, "shift")
    c, ac, ae = fm.fuse(a, b)
    assert ac + ae == pytest.approx(1.0)
    assert ac == pytest.approx(0.75) and ac > ae
    assert c == pytest.approx((11.0, 19.0))
    c, ac, ae = fm.fuse(b, a)
    assert ac < ae
    _, ac, ae = fm.fuse(FeatureResult((0, 0), 0.0, 1, "lost"), FeatureResult((0, 0), 0.0, 1, "lost"))
    assert ac == ae == 0.5
    assert fm.fuse(a, None)[1:] == (1.0, 0.0) and fm.fuse(None, b)[1:] == (0.0, 1.0)


@pytest.mark.parametrize("dx,dy", INT_SHIFTS + SUB_SHIFTS)
def test_tracker_alphas_sum_to_one_and_follow_rhos(dx, dy):
    _, r1, _ = _track(dx, dy)
    assert r1.alpha_c + r1.alpha_e == pytest.approx(1.0)
    if r1.rho_c != r1.rho_e:
        assert (r1.alpha_c > r1.alpha_e) == (r1.rho_c > r1.rho_e)
    assert r1.alpha_c == pytest.approx(r1.rho_c / (r1.rho_c + r1.rho_e))


# ----------------------------------------------------------------------------- real data
#: AUC floors, fused tracker, flat kernel, defaults.  OTB AUC (mstrack.eval.metrics:
#: mean over 21 IoU thresholds linspace(0, 1, 21) of the fraction of frames
#: with IoU > t), frame 0 (the init box) INCLUDED.  Measured 2026-11-21 with
#: `python -m mstrack.eval.agreement` (same runs): Crossing 0.305, Girl 0.570,
#: Deer 0.198; floor = measured - 0.05.
AUC_FLOORS = {"Crossing": (0.305, 0.255), "Girl": (0.570, 0.520), "Deer": (0.198, 0.148)}


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT}")
@pytest.mark.parametrize("name", sorted(AUC_FLOORS))
def test_auc_floor_real_sequences(name):
    """Fused/flat/defaults AUC on Crossing (measured 0.305, floor 0.255), Girl (0.570, 0.520), Deer (0.198, 0.148)."""
    from mstrack.io.data import load_sequence
    from mstrack.eval.metrics import score

    seq = load_sequence(SEQ_ROOT / name)
    trk = Tracker(model="float", preset="paper")
    boxes = [trk.init(seq.frame(0), seq.init_box()).box.as_tuple()]
    boxes += [trk.update(f).box.as_tuple() for f in list(seq.frames())[1:]]
    auc = score(np.asarray(boxes), seq.gt).auc
    measured, floor = AUC_FLOORS[name]
    assert auc >= floor, f"{name}: AUC {auc:.3f} < floor {floor} (measured {measured})"
