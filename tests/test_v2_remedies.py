"""Tracker v2's experimental scale and illumination options (off by default; no RTL): the shrink
guard (TrackerParams.scale_ring_guard), the guarded model update (model_rate, model_mix) and the
normalised-chromaticity bins (chroma_bins).

Each fixed block against its exact definition (Python integers / Fraction), the option's effect on
a synthetic scene in both models, and the defaults unchanged (docs/algorithm.md "v2.2b", "v2.5a", "v2.6a";
docs/fixed_point.md "The shrink guard and the guarded model update"; figures on 22 sequences in
docs/results_accuracy22.md).
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from mstrack import Tracker
from mstrack.eval.metrics import iou
from mstrack.fixed.blocks_v2 import ONE, ms_chroma_bin, ms_model_update, ms_no_shrink, ms_ring_guard, q16
from mstrack.track.features import chroma_bins
from mstrack.track.float_v2 import PassV2, ring_guard
from mstrack.track.params import TrackerParams

WIDE = dict(model_frac=4, bg_frac=16, weight_frac=8)
MODELS = [("float", {}), ("fixed", WIDE)]


def _scene(n: int, shrink: float = 1.0, dark: float = 1.0, seed: int = 0) -> tuple[list[np.ndarray], np.ndarray]:
    """A 60 x 44 textured red target moving right by 0.5 px per frame on random colours; its size
    goes linearly to ``shrink`` x and its colour to ``dark`` x over the n frames."""
    rng = np.random.default_rng(seed)
    H, W = 160, 200
    bg = rng.integers(0, 256, (H, W, 3)).astype(np.float64)
    tex = np.random.default_rng(seed + 1).integers(-30, 30, (H, W, 3))
    colour = np.array([200.0, 60.0, 40.0])
    frames, gt = [], []
    for i in range(n):
        f = bg.copy()
        s, lum = 1 + (shrink - 1) * i / (n - 1), 1 + (dark - 1) * i / (n - 1)
        w, h, cx, cy = 60 * s, 44 * s, 100 + 0.5 * i, 80.0
        x0, y0 = int(round(cx - w / 2)), int(round(cy - h / 2))
        x1, y1 = int(round(cx + w / 2)), int(round(cy + h / 2))
        f[y0:y1, x0:x1] = np.clip(colour * lum + tex[y0:y1, x0:x1], 0, 255)
        frames.append(f.astype(np.uint8))
        gt.append((x0, y0, x1 - x0, y1 - y0))
    return frames, np.array(gt, dtype=np.float64)


def _boxes(res) -> np.ndarray:
    return np.array([r.box.as_tuple() for r in res])


# ----------------------------------------------------------------------------- exact definitions
@pytest.mark.parametrize("seed", range(3))
def test_ring_guard_against_exact_definition(seed):
    rng = np.random.default_rng(seed)
    for _ in range(2000):
        share, ring = (int(x) for x in rng.integers(0, ONE + 1, 2))
        g16 = int(rng.integers(0, 4 * ONE + 1)) if rng.random() < 0.9 else 0
        if rng.random() < 0.2:  # on the boundary
            ring = (g16 * share) >> 16
        want = g16 > 0 and Fraction(ring, ONE) >= Fraction(g16, ONE) * Fraction(share, ONE)
        assert ms_ring_guard(share, ring, g16) == want
    for s in (ONE - 5, ONE, ONE + 5):
        assert ms_no_shrink(s, True) == max(s, ONE) and ms_no_shrink(s, False) == s


@pytest.mark.parametrize("k", range(0, 8))
def test_model_update_against_exact_definition(k):
    rng = np.random.default_rng(k)
    old = rng.integers(0, ONE + 1, 4608)
    new = rng.integers(0, ONE + 1, 4608)
    new[:100] = 0
    got = ms_model_update(old, new, k)
    want = [int(a) + int(Fraction(int(b) - int(a), 1 << k).__floor__()) for a, b in zip(old, new)]
    assert got.tolist() == want
    assert np.all(got >= np.minimum(old, new)) and np.all(got <= np.maximum(old, new))


@pytest.mark.parametrize("k", [1, 2, 3])
def test_chroma_bin_against_exact_definition(k):
    """ms_chroma_bin (fixed) and chroma_bins (float) against Fraction arithmetic on random pixels and
    the extremes; 3 colour bits: every bin < 2**(6 + k) <= 512."""
    rng = np.random.default_rng(k)
    px = rng.integers(0, 256, (64, 64, 3)).astype(np.uint8)
    px[0, :4] = [[0, 0, 0], [255, 255, 255], [0, 0, 255], [255, 0, 0]]
    got = ms_chroma_bin(px, 3, k)
    assert np.array_equal(got, chroma_bins(px, 3, k)) and got.max() < 1 << (6 + k)
    for (y, x) in [(0, 0), (0, 1), (0, 2), (0, 3)] + [tuple(rng.integers(0, 64, 2)) for _ in range(300)]:
        b, g, r = (int(v) for v in px[y, x])
        s = r + g + b
        want = ((s * (1 << k)) // 1024 << 6) + (int(Fraction(8 * r, s + 1)) << 3) + int(Fraction(8 * g, s + 1))
        assert got[y, x] == want


def test_float_ring_guard_rule():
    p = TrackerParams(preset="v2", scale_ring_guard=0.5)
    # share = nt_in / n_in = 0.5; ring_share = (nt - nt_in) / (n - n_in)
    at = PassV2(rho=1, sw=1, swx=0, swy=0, nt=75, st2=0, n_in=100, nt_in=50, n=150)  # ring 0.5 >= 0.25
    below = PassV2(rho=1, sw=1, swx=0, swy=0, nt=60, st2=0, n_in=100, nt_in=50, n=150)  # ring 0.2 < 0.25
    assert ring_guard(at, p) and not ring_guard(below, p)
    assert not ring_guard(at, TrackerParams(preset="v2"))  # off by default


# ----------------------------------------------------------------------------- effect on scenes
@pytest.mark.parametrize("model,kw", MODELS)
def test_shrink_guard_stops_a_biased_collapse(model, kw):
    """A shrink-biased spread estimate (spread_ref doubled after init, as when the target's
    coloured pixels gather in the window's middle) and no pull toward the init size: the box
    collapses to about half its size; with the guard (0.5) every shrinking step is refused while the
    ring is target-coloured, and the box keeps its size."""
    frames, gt = _scene(40)
    out = {}
    for g in (0.0, 0.5):
        t = Tracker(model=model, preset="v2", scale_reg=0.0, scale_ring_guard=g, **kw)
        t.init(frames[0], gt[0])
        if model == "fixed":
            t.impl.spread_ref *= 2
        else:
            t.impl._spread_ref *= 2
        w = [gt[0, 2]]
        for f in frames[1:]:
            r = t.update(f)
            e = r.extra
            if g > 0 and (ms_ring_guard(e["share"], e["ring_share"], q16(g)) if model == "fixed"
                          else e["ring_share"] >= g * e["share"]):
                assert r.box.w >= w[-1] - 1e-9  # no shrinking step on a guarded frame
            w.append(r.box.w)
        out[g] = w[-1] / gt[0, 2]
    assert out[0.0] < 0.7 and out[0.5] > 0.9, out


@pytest.mark.parametrize("model,kw", MODELS)
def test_shrink_guard_follows_a_shrinking_target(model, kw):
    """A target shrinking to 0.6 x: with the guard and no pull toward the init size the box follows
    it (the ring is background, nothing is refused), closer than the defaults (pulled toward w0)."""
    frames, gt = _scene(60, shrink=0.6)
    ratio = {}
    for label, extra in (("default", {}), ("guard", dict(scale_reg=0.0, scale_ring_guard=0.5))):
        t = Tracker(model=model, preset="v2", **extra, **kw)
        res = [t.init(frames[0], gt[0])] + [t.update(f) for f in frames[1:]]
        ratio[label] = res[-1].box.w / gt[-1, 2]
    assert abs(ratio["guard"] - 1) < 0.1 and abs(ratio["guard"] - 1) < abs(ratio["default"] - 1) - 0.1, ratio


@pytest.mark.parametrize("model,kw", MODELS)
def test_model_update_follows_a_darkening_target(model, kw):
    """A target whose colour darkens to half over 100 frames: the init model loses it (confidence
    0, IoU 0 at the end); with the guarded model update (1/16) the model follows the light and the
    box stays on the target."""
    frames, gt = _scene(100, dark=0.5)
    last = {}
    for rate in (0.0, 0.0625):
        t = Tracker(model=model, preset="v2", model_rate=rate, **kw)
        res = [t.init(frames[0], gt[0])] + [t.update(f) for f in frames[1:]]
        last[rate] = iou(_boxes(res[-10:]), gt[-10:])
    assert last[0.0].max() < 0.3 and last[0.0625].min() > 0.8, last


@pytest.mark.parametrize("model,kw", MODELS)
def test_model_contrast_guard(model, kw):
    """model_contrast: the update learns only on frames with contrast_s >= model_contrast; at 1.0
    (contrast_s < 1 here) it learns nothing and the results equal model_rate 0's bit for bit, at -1
    (the default) the update changes them."""
    frames, gt = _scene(30, dark=0.6)
    runs = {}
    for label, extra in (("off", {}), ("c1", dict(model_rate=0.25, model_contrast=1.0)),
                         ("c-1", dict(model_rate=0.25))):
        t = Tracker(model=model, preset="v2", **extra, **kw)
        res = [t.init(frames[0], gt[0])] + [t.update(f) for f in frames[1:]]
        runs[label] = [(r.box.as_tuple(), r.confidence) for r in res]
        assert max(r.extra["contrast_s"] for r in res[1:]) < (ONE if model == "fixed" else 1.0)
    assert runs["c1"] == runs["off"] and runs["c-1"] != runs["off"]


def test_model_update_keeps_the_init_model_share():
    """model_mix 1/2 (fixed): Qn = Qn0 + ((Qr - Qn0) >> 1) after every update, Qr the running model."""
    frames, gt = _scene(20, dark=0.7)
    t = Tracker(model="fixed", preset="v2", model_rate=0.25, model_mix=0.5, **WIDE)
    t.init(frames[0], gt[0])
    impl = t.impl
    q0 = impl.Qn0.copy()
    for f in frames[1:]:
        t.update(f)
        assert np.array_equal(impl.model.Qn, q0 + ((impl.Qr - q0) >> 1))
    assert not np.array_equal(impl.Qr, q0)  # the running model moved


@pytest.mark.parametrize("model,kw", MODELS)
def test_chroma_bins_keep_a_darkening_target(model, kw):
    """The target darkening to half (previous test): with chromaticity bins (2 intensity bits) the box
    stays on it (IoU >= 0.5 over the last 10 frames) where the RGB bins lose it."""
    frames, gt = _scene(100, dark=0.5)
    last = {}
    for k in (0, 2):
        t = Tracker(model=model, preset="v2", chroma_bins=k, **kw)
        res = [t.init(frames[0], gt[0])] + [t.update(f) for f in frames[1:]]
        last[k] = iou(_boxes(res[-10:]), gt[-10:])
    assert last[0].max() < 0.3 and last[2].min() > 0.5, last


@pytest.mark.parametrize("model,kw", MODELS + [("fixed", {})])
def test_options_off_change_nothing(model, kw):
    """scale_ring_guard 0, model_rate 0, model_mix 1 and chroma_bins 0 (the defaults, spelt out) give
    the defaults' results bit for bit."""
    frames, gt = _scene(25, shrink=0.8, dark=0.8)
    runs = []
    for extra in ({}, dict(scale_ring_guard=0.0, model_rate=0.0, model_mix=1.0, chroma_bins=0)):
        t = Tracker(model=model, preset="v2", **extra, **kw)
        res = [t.init(frames[0], gt[0])] + [t.update(f) for f in frames[1:]]
        runs.append([(r.box.as_tuple(), r.confidence, r.status) for r in res])
    assert runs[0] == runs[1]


def test_fixed_rates_must_be_powers_of_two():
    with pytest.raises(ValueError, match="model_rate"):
        Tracker(model="fixed", preset="v2", model_rate=0.1)
    with pytest.raises(ValueError, match="model_mix"):
        Tracker(model="fixed", preset="v2", model_rate=0.0625, model_mix=0.3)
    with pytest.raises(ValueError, match="chroma_bins"):
        TrackerParams(preset="v2", chroma_bins=4)
    with pytest.raises(ValueError, match="scale_ring_guard"):
        TrackerParams(preset="v2", scale_ring_guard=-0.1)
