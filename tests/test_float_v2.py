"""Tests of tracker v2, float reference (mstrack/track/float_v2.py; docs/algorithm.md, "Tracker v2").

Pieces against their definitions (brute force), then synthetic scenes with exact ground truth
drawn by :func:`mstrack.io.synthetic.render_scene` (the red/yellow checkerboard target of
``make_scene`` at a given box per frame, optionally hidden by a background-textured patch),
then bad input, then a floor on the real sequences.

Figures in comments were measured on 2026-11-23 (seeds 0..2); the assertions are floors or
bounds with a margin, never the measured values themselves.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack import FrameError, Status, Tracker
from mstrack.track import float_v2 as v2
from mstrack.eval.agreement import shift_scene
from mstrack.eval.metrics import iou
from mstrack.track.params import V2_COLOUR, TrackerParams
from mstrack.io.synthetic import render_scene

SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
SEEDS = [0, 1, 2]


def _run(frames, box, **params):
    """Track ``frames`` from ``box`` on frame 0; the list of TrackResults (frame 0 = init)."""
    trk = Tracker(model="float", **params)
    res = [trk.init(frames[0], box)]
    res += [trk.update(f) for f in frames[1:]]
    return trk, res


def _boxes(results):
    return np.array([r.box.as_tuple() for r in results])


def _centre_boxes(cx, cy, w, h):
    """Integer (x, y, w, h) rows from centres and sizes (arrays or scalars)."""
    n = max(np.size(a) for a in (cx, cy, w, h))
    cx, cy, w, h = (np.broadcast_to(np.asarray(a, float), (n,)) for a in (cx, cy, w, h))
    w, h = np.rint(w), np.rint(h)
    return np.stack([np.rint(cx - w / 2), np.rint(cy - h / 2), w, h], axis=1)


# ============================================================================ pieces
@pytest.mark.parametrize("cx,cy,hx,hy,width,height", [
    (20.0, 15.0, 8.0, 5.0, 40, 30),          # inside, integer centre (pixels at d2 = 1 excluded)
    (20.3, 14.7, 7.6, 5.25, 40, 30),         # fractional centre and sizes
    (1.5, 2.2, 6.0, 9.0, 40, 30),            # cut by the left / top border
    (38.9, 29.0, 5.5, 4.0, 40, 30),          # cut by the right / bottom border
    (10.0, 10.0, 0.6, 0.6, 20, 20),          # one pixel
    (10.0, 10.0, 40.0, 40.0, 20, 20),        # larger than the image: every pixel
])
def test_window_pixels_is_the_d2_below_1_set(cx, cy, hx, hy, width, height):
    xs, ys, d2 = v2.window_pixels(cx, cy, hx, hy, width, height)
    want = {(x, y) for y in range(height) for x in range(width)
            if ((x - cx) / hx) ** 2 + ((y - cy) / hy) ** 2 < 1.0}
    got = list(zip(xs.tolist(), ys.tolist()))
    assert len(got) == len(set(got)), "a pixel listed twice"
    assert set(got) == want
    for x, y, d in zip(xs, ys, d2):
        assert d == pytest.approx(((x - cx) / hx) ** 2 + ((y - cy) / hy) ** 2, abs=1e-12)
    assert xs.dtype.kind == "i" and ys.dtype.kind == "i"


def test_window_pixels_entirely_outside_is_empty():
    xs, ys, d2 = v2.window_pixels(-20.0, 5.0, 4.0, 4.0, 30, 30)
    assert xs.size == ys.size == d2.size == 0


def _hand_bins():
    """40x40 bins image with a 20x20 box at (10, 10): the box holds bin 1 (left half) and bin 2
    (right half); around it, rows 0..24 are bin 2, columns 0..1 of rows 25..39 bin 3, the rest 0.

    With bg_ring 0.5 the grown box covers the whole image, so the ring is the 1200 pixels outside
    the box: bin 2: 25 * 40 - 15 * 20 = 700, bin 3: 2 * 15 = 30, bin 0: 1200 - 730 = 470."""
    bins = np.zeros((40, 40), np.int64)
    bins[:25, :] = 2
    bins[25:, :2] = 3
    bins[10:30, 10:20] = 1
    bins[10:30, 20:30] = 2
    return bins


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_background_model_hand_made(kernel):
    bins = _hand_bins()
    # box (10, 10, 20, 20): centre (19.5, 19.5) in pixel-index coordinates
    q, qb, t = v2.background_model(bins, 4, 19.5, 19.5, 20.0, 20.0, 0.5, kernel)
    # the ellipse is symmetric about x = 19.5: half of it bin 1, half bin 2, whatever the kernel
    np.testing.assert_allclose(q, [0.0, 0.5, 0.5, 0.0], atol=1e-12)
    o = np.array([470.0, 0.0, 700.0, 30.0]) / 1200.0
    o_star = o[o > 0].min()
    assert o_star == pytest.approx(30 / 1200)
    v = np.array([o_star / o[0], 1.0, o_star / o[2], 1.0])   # v_u = 1 where o_u = 0 (bin 1)
    np.testing.assert_allclose(v, [30 / 470, 1.0, 30 / 700, 1.0])
    want = v * q / (v * q).sum()
    np.testing.assert_allclose(qb, want, rtol=1e-12, atol=1e-15)
    assert qb.sum() == pytest.approx(1.0, abs=1e-12)
    assert qb[1] > q[1] and qb[2] < q[2]             # the background colour is played down
    # t_u = q_u > o_u: bin 1 only (bin 2 is more common in the ring, 0.583, than in the box, 0.5)
    np.testing.assert_array_equal(t, [0.0, 1.0, 0.0, 0.0])


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_background_model_random_brute_force(seed, kernel):
    """q, q', t on a random bins image against the definitions, pixel by pixel."""
    rng = np.random.default_rng(seed)
    height, width, n_bins = 50, 60, 16
    bins = rng.integers(0, n_bins, (height, width))
    cx, cy, w, h, ring = 27.3, 22.6, 17.0, 13.0, 0.6
    q, qb, t = v2.background_model(bins, n_bins, cx, cy, w, h, ring, kernel)
    qw = np.zeros(n_bins)
    o = np.zeros(n_bins)
    for y in range(height):
        for x in range(width):
            d2 = ((x - cx) / (w / 2)) ** 2 + ((y - cy) / (h / 2)) ** 2
            if d2 < 1:
                qw[bins[y, x]] += 1.0 if kernel == "flat" else 1.0 - d2
            in_grown = abs(x - cx) <= w / 2 + ring * w and abs(y - cy) <= h / 2 + ring * h
            in_box = abs(x - cx) <= w / 2 and abs(y - cy) <= h / 2
            if in_grown and not in_box:
                o[bins[y, x]] += 1
    qw /= qw.sum()
    o /= o.sum()
    np.testing.assert_allclose(q, qw, atol=1e-12)
    assert q.sum() == pytest.approx(1.0, abs=1e-12) and qb.sum() == pytest.approx(1.0, abs=1e-12)
    v = np.where(o > 0, np.minimum(o[o > 0].min() / np.where(o > 0, o, 1), 1.0), 1.0)
    np.testing.assert_allclose(qb, v * qw / (v * qw).sum(), atol=1e-12)
    np.testing.assert_array_equal(t, (qw > o).astype(float))


def test_background_model_box_filling_the_frame():
    """No background ring inside the frame: q' = q and t = (q > 0)."""
    rng = np.random.default_rng(4)
    bins = rng.integers(0, 8, (20, 30)) // 2 * 2     # even bins only: odd ones are absent
    q, qb, t = v2.background_model(bins, 8, 14.5, 9.5, 30.0, 20.0, 0.6, "flat")
    assert q.sum() == pytest.approx(1.0)
    np.testing.assert_array_equal(qb, q)
    np.testing.assert_array_equal(t, (q > 0).astype(float))
    assert t[1::2].sum() == 0 and t[0::2].sum() == 4


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_window_pass_sums_brute_force(seed, kernel):
    rng = np.random.default_rng(10 + seed)
    height, width, n_bins = 45, 55, 12
    bins = rng.integers(0, n_bins, (height, width))
    q = rng.random(n_bins)
    q[rng.integers(0, n_bins, 3)] = 0.0
    q /= q.sum()
    t = (rng.random(n_bins) < 0.5).astype(float)
    c, hx, hy, inner2 = (30.4, 19.8), 14.2, 11.5, 1 / 1.25 ** 2
    ps = v2.window_pass(bins, n_bins, q, t, c, hx, hy, inner2, kernel)
    p = np.zeros(n_bins)
    pix = []
    for y in range(height):
        for x in range(width):
            d2 = ((x - c[0]) / hx) ** 2 + ((y - c[1]) / hy) ** 2
            if d2 < 1:
                p[bins[y, x]] += 1.0 if kernel == "flat" else 1.0 - d2
                pix.append((x, y, bins[y, x], d2))
    p /= p.sum()
    assert ps.rho == pytest.approx(sum(math.sqrt(p[u] * q[u]) for u in range(n_bins)), abs=1e-12)
    wu = [math.sqrt(q[u] / p[u]) if p[u] > 0 else 0.0 for u in range(n_bins)]
    assert ps.sw == pytest.approx(sum(wu[u] for _, _, u, _ in pix), rel=1e-12)
    assert ps.swx == pytest.approx(sum(wu[u] * x for x, _, u, _ in pix), rel=1e-12)
    assert ps.swy == pytest.approx(sum(wu[u] * y for _, y, u, _ in pix), rel=1e-12)
    assert ps.nt == sum(t[u] for _, _, u, _ in pix)
    assert ps.st2 == pytest.approx(sum(t[u] * d2 for _, _, u, d2 in pix), rel=1e-12)
    assert ps.n_in == sum(d2 < inner2 for *_, d2 in pix)
    assert ps.nt_in == sum(t[u] for _, _, u, d2 in pix if d2 < inner2)
    assert ps.share == pytest.approx(ps.nt_in / ps.n_in) and ps.spread == pytest.approx(ps.st2 / ps.nt)
    # the mean-shift step is the weighted mean of the window's pixels
    assert ps.swx / ps.sw == pytest.approx(c[0], abs=hx) and ps.swy / ps.sw == pytest.approx(c[1], abs=hy)


def test_window_pass_empty_window_and_properties():
    ps = v2.window_pass(np.zeros((10, 10), np.int64), 4, np.full(4, 0.25), np.ones(4), (-30.0, 5.0), 3.0, 3.0,
                        0.5, "flat")
    assert (ps.rho, ps.sw, ps.nt, ps.n_in) == (0.0, 0.0, 0.0, 0)
    assert ps.share == 0.0 and ps.spread == 0.0


@pytest.mark.parametrize("pad,max_window", [(0.25, 127), (0.0, 63), (1.0, 200)])
def test_decimation_choice(pad, max_window):
    """D = the smallest power of two with max(w, h) (1 + pad) / D <= max_window, at most 8."""
    trk = v2.FloatTrackerV2(TrackerParams(preset="v2", pad=pad, max_window=max_window))
    for w, h in [(10, 10), (100, 40), (40, 101.6), (102, 30), (200, 300), (300, 200), (500, 90), (2000, 1500),
                 (max_window / (1 + pad), 5), (max_window / (1 + pad) + 0.01, 5)]:
        d = trk.decimation(w, h)
        fits = [k for k in (1, 2, 4, 8) if max(w, h) * (1 + pad) / k <= max_window]
        assert d == (fits[0] if fits else 8), (w, h, d)
        assert d in (1, 2, 4, 8)
    assert trk.decimation(max_window / (1 + pad), 5) == 1          # exactly at the limit: no decimation
    assert trk.decimation(max_window / (1 + pad) + 0.01, 5) == 2


def test_init_result_and_references():
    f0, _, box = shift_scene(0, 0)
    trk, (r0,) = _run([f0], box, preset="v2")
    assert r0.status == Status.INIT and r0.ok and r0.confidence == 1.0
    assert r0.box.as_tuple() == pytest.approx(tuple(box))
    assert r0.extra["decimation"] == 1 and 0.9 < r0.extra["share"] <= 1.0
    im = trk.impl
    assert isinstance(im, v2.FloatTrackerV2)
    assert im._rho_ref == pytest.approx(r0.rho_c) and im._share_ref == r0.extra["share"]
    # the same frame again: found in place (within one sub-pixel step: the weighted mean of the
    # padded window is not exactly its centre; measured 0.008 px), fully confident
    r1 = trk.update(f0)
    assert r1.status == Status.OK and r1.confidence == pytest.approx(1.0, abs=1e-3)
    assert math.hypot(r1.centre[0] - r0.centre[0], r1.centre[1] - r0.centre[1]) < 0.5


SHIFTS = [(3, -2), (-6, 4), (6, 6), (0, 8), (8, 8), (-8, -8)]


def _shift_error(dx, dy, n_updates=1):
    f0, f1, box = shift_scene(dx, dy)
    trk = Tracker(model="float", preset="v2", eps2=0.01)
    r0 = trk.init(f0, box)
    for _ in range(n_updates):
        r1 = trk.update(f1)
    return math.hypot(r1.centre[0] - r0.centre[0] - dx, r1.centre[1] - r0.centre[1] - dy), r1


@pytest.mark.parametrize("dx,dy", SHIFTS)
def test_v2_follows_a_shift(dx, dy):
    """One frame, target (41x31 ellipse) shifted by (dx, dy): v2 moves most of the way.
    Measured errors: (3,-2) 0.02, (-6,4) 0.96, (6,6) 1.70, (0,8) 1.72, (8,8) 3.14, (-8,-8) 3.14 px."""
    err, r1 = _shift_error(dx, dy)
    assert r1.status == Status.OK and r1.confidence > 0.8
    assert err < 0.45 * math.hypot(dx, dy), err


@pytest.mark.xfail(strict=True, reason=(
    "v2 algorithm limitation, not fixed here: the Bhattacharyya coefficient over the padded window "
    "(box x 1.25) is flat while the whole target is inside it (0.798 .. 0.800 over +-3 px around "
    "the truth for (8, 8)), and the mean-shift loop stops at the first step that lowers rho "
    "(paper rule), so it halts up to 3.1 px short of the optimum (the share of target-coloured "
    "pixels, 0.89 there against 0.996 at the truth, would still show the way); repeated updates "
    "on the same frame stay there for (6, 6), (0, 8), (-8, -8); the experimental rho_stop_margin "
    "(off by default) converges: tests/test_fixed_v2_widths.py::test_rho_stop_margin_crosses_the_flat_top_of_rho"))
@pytest.mark.parametrize("dx,dy", [(6, 6), (0, 8), (-8, -8)])
def test_v2_converges_to_a_shift(dx, dy):
    err, _ = _shift_error(dx, dy, n_updates=3)
    assert err < 0.5, err


def test_v2_params_validated():
    with pytest.raises(ValueError, match="colour only"):
        TrackerParams(preset="v2", features="fused")
    with pytest.raises(ValueError, match="conf_lost must be <= conf_uncertain"):
        TrackerParams(preset="v2", conf_lost=0.6, conf_uncertain=0.5)
    with pytest.raises(ValueError, match="preset"):
        TrackerParams(preset="v3")
    with pytest.raises(ValueError, match="flat kernel only"):
        Tracker(model="fixed", preset="v2", kernel="epanechnikov")
    assert TrackerParams().preset == "paper" and TrackerParams().features == "fused"


# ============================================================================ statuses
def _status_rule_holds(results, params: TrackerParams):
    """Each update's search state follows from its confidence and the previous state; its
    reported status from the loss flag (smoothed rho against rho at init = the init result's rho_c,
    and the smoothed contrast share - ring_share), the search state and the previous report."""
    state_lost = reported_lost = False
    rho0 = results[0].rho_c
    rho_s, con_s = rho0, results[0].extra["share"] - results[0].extra["ring_share"]
    a = params.loss_smooth
    for i, r in enumerate(results[1:], start=1):
        c = r.confidence
        assert 0.0 <= c <= 1.0 and math.isfinite(c), (i, c)
        if c < (params.conf_reacquire if state_lost else params.conf_lost):
            state = Status.LOST
        elif state_lost:
            state = Status.REACQUIRED
        elif c < params.conf_uncertain:
            state = Status.UNCERTAIN
        else:
            state = Status.OK
        assert r.extra["state"] == state.value, (i, c, r.extra["state"], state)
        rho_s += a * (r.rho_c - rho_s)
        con_s += a * (r.extra["share"] - r.extra["ring_share"] - con_s)
        assert (r.extra["rho_s"], r.extra["contrast_s"]) == (rho_s, con_s), i
        flagged = r.extra["share"] == 0 or (rho_s < params.loss_rho * rho0 and con_s < params.loss_contrast)
        if flagged:
            want = Status.LOST if state == Status.LOST else Status.UNCERTAIN
        else:
            want = Status.REACQUIRED if reported_lost else Status.OK
        assert r.status == want, (i, rho_s / rho0, con_s, r.status, want)
        assert r.ok == (not flagged)
        assert (r.extra["searched"] > 0) == state_lost, (i, r.extra)
        state_lost = state == Status.LOST
        reported_lost = want == Status.LOST or (want == Status.UNCERTAIN and reported_lost)


def _half_hidden_scene(frac, hidden_frames, seed=3):
    """A still 40x40 target in a 160x120 frame whose right ``frac`` is covered by background in
    ``hidden_frames``."""
    n = 40
    gt = np.tile([60.0, 40.0, 40.0, 40.0], (n, 1))
    frames = render_scene(gt, 160, 120, seed=seed)
    bg = render_scene(gt, 160, 120, seed=seed, hidden=np.ones(n, bool))
    cut = 60 + int(round(40 * (1 - frac)))
    frames[hidden_frames, :, cut:] = bg[hidden_frames, :, cut:]
    return frames, gt


def test_uncertain_status_learns_nothing():
    """Half the target hidden for 10 frames, thresholds conf_lost 0.1 / conf_uncertain 0.9: the
    search state of those frames is uncertain, the references of rho and share do not move; with
    loss_rho 0.9 / loss_contrast 0.6 the same frames are reported UNCERTAIN (ok False), the frames
    before and after OK.  (Measured while half hidden: confidence 0.43 .. 0.58, rho / rho0
    0.71 .. 0.83, contrast 0.40 .. 0.56.)"""
    frames, gt = _half_hidden_scene(0.5, slice(15, 25))
    kw = dict(preset="v2", conf_lost=0.1, conf_uncertain=0.9, loss_rho=0.9, loss_contrast=0.6)
    trk, res = _run(frames, gt[0], **kw)
    st = [r.status for r in res]
    assert all(r.extra["state"] == "uncertain" for r in res[15:25]), [r.extra["state"] for r in res]
    assert all(s == Status.UNCERTAIN for s in st[15:25]), st
    assert all(s == Status.OK for s in st[1:15]) and all(s == Status.OK for s in st[26:]), st
    assert not any(r.ok for r in res[15:25])
    assert all(r.confidence < 0.9 for r in res[15:25]) and all(r.confidence >= 0.9 for r in res[26:])
    _status_rule_holds(res, trk.params)
    # references frozen while uncertain: replay to frame 14 and compare with the end of the hidden run
    trk2, _ = _run(frames[:15], gt[0], **kw)
    ref14 = (trk2.impl._rho_ref, trk2.impl._share_ref)
    for f in frames[15:25]:
        trk2.update(f)
    assert (trk2.impl._rho_ref, trk2.impl._share_ref) == ref14


def test_default_thresholds_on_partial_occlusion():
    """Default thresholds, right part of the target hidden on frames 15..24.  30 %: search state
    and status ok.  70 %: the confidence starts the wide search (state lost), but the visible part
    still stands out from the ring (contrast 0.25 .. 0.37 >= loss_contrast): reported ok (IoU
    0.37 .. 0.47).  85 %: rho / rho0 < 0.45 and contrast 0.14 .. 0.19: once the smoothed contrast
    has fallen below 0.19 (frame 19) reported LOST to the end of the occlusion.  The status rule
    holds on every frame."""
    for frac, state, want, flagged in ((0.3, "ok", Status.OK, slice(16, 25)), (0.7, "lost", Status.OK, slice(16, 25)),
                                       (0.85, "lost", Status.LOST, slice(19, 25))):
        frames, gt = _half_hidden_scene(frac, slice(15, 25))
        trk, res = _run(frames, gt[0], preset="v2")
        assert all(r.extra["state"] == state for r in res[16:25]), (frac, [r.extra["state"] for r in res])
        assert all(r.status == want for r in res[flagged]), (frac, [r.status.value for r in res])
        _status_rule_holds(res, trk.params)
        assert res[-1].status == Status.OK and iou(_boxes(res[-1:]), gt[-1:])[0] > 0.8


# ============================================================================ scenes
def _scale_scene(seed, w0=40, h0=30, factor=1.6, n=121, width=320, height=240):
    """Target grows (or shrinks) steadily by ``factor`` over frames 0..60, then back over 60..120,
    while moving on a smooth path."""
    t = np.arange(n)
    s = np.where(t <= 60, factor ** (t / 60), factor ** ((120 - t) / 60))
    cx = width / 2 + 40 * np.sin(t / 40)
    cy = height / 2 + 20 * np.sin(t / 30)
    gt = _centre_boxes(cx, cy, w0 * s, h0 * s)
    return render_scene(gt, width, height, seed=seed), gt


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("w0,h0,factor", [(40, 30, 1.6), (60, 45, 1 / 1.6)])
def test_scale_followed(seed, w0, h0, factor):
    """x1.6 (or /1.6) over 60 frames and back.  Tracker v2's box size follows it, lagging (gain 0.3,
    pulled to the init size by reg 0.1); the paper preset keeps the init size.  This runs v2 on
    colour alone without the scale test (mstrack-v2-colour): the default's gated scale test vetoes the
    growth on this scene (test_scale_followed_default).
    Measured (seeds 0..2): size error max 0.20 (grow) / 0.18 (shrink); at the extreme v2's size is
    x1.28 / x0.73 of the init size; mean IoU v2 0.84 / 0.87, paper 0.53 / 0.64."""
    frames, gt = _scale_scene(seed, w0, h0, factor)
    _, r2 = _run(frames, gt[0], preset="v2", **V2_COLOUR)
    _, rp = _run(frames, gt[0], preset="paper")
    b2, bp = _boxes(r2), _boxes(rp)
    size = lambda b: np.sqrt(b[:, 2] * b[:, 3])  # noqa: E731
    rel = size(b2) / size(gt)
    assert np.abs(rel - 1).max() < 0.3, f"size error up to {np.abs(rel - 1).max():.3f}"
    grow = size(b2)[60] / size(b2)[0]
    if factor > 1:
        assert grow > 1.15, f"v2 grew only x{grow:.3f} while the target grew x{factor}"
    else:
        assert grow < 0.85, f"v2 shrank only to x{grow:.3f} while the target shrank to x{factor:.3f}"
    # the size follows the change back: at the end it is nearer the init size than at the extreme
    assert abs(size(b2)[-1] / size(b2)[0] - 1) < abs(grow - 1) / 2
    np.testing.assert_allclose(bp[:, 2:], np.tile(gt[0, 2:], (len(bp), 1)))   # paper: fixed size
    i2, ip = iou(b2, gt), iou(bp, gt)
    assert i2.mean() > 0.75 and i2.min() > 0.5, (i2.mean(), i2.min())
    assert i2.mean() > ip.mean() + 0.15, (i2.mean(), ip.mean())
    assert i2[55:66].mean() > ip[55:66].mean() + 0.2     # around the extreme size
    assert all(r.ok for r in r2)


@pytest.mark.parametrize("w0,h0,factor", [(40, 30, 1.6), (60, 45, 1 / 1.6)])
def test_scale_followed_default(w0, h0, factor):
    """The scene of test_scale_followed (seed 0) with the default tracker v2 (joint bins, the gated
    scale test): it follows the shrinking as the colour tracker does (size error max 0.17), but the
    gate vetoes most of the growth: on a uniform target whose padded window already holds it, rho at
    x1.05 is not above rho at x1, so the spread's growth is not confirmed (size error max 0.36, the
    box grows only about x1.06; the colour tracker's 0.20).  A known weakness of the default, kept
    visible here; on the dev set the gate pays (docs/results_v2_mean.md)."""
    frames, gt = _scale_scene(0, w0, h0, factor)
    _, r2 = _run(frames, gt[0], preset="v2")
    b2 = _boxes(r2)
    size = lambda b: np.sqrt(b[:, 2] * b[:, 3])  # noqa: E731
    err = np.abs(size(b2) / size(gt) - 1).max()
    grow = size(b2)[60] / size(b2)[0]
    i2 = iou(b2, gt)
    if factor > 1:
        assert 0.3 < err < 0.4 and grow < 1.1, (err, grow)   # vetoed (if this fails, the gate changed)
        assert i2.mean() > 0.6, i2.mean()
    else:
        assert err < 0.2 and grow < 0.85, (err, grow)
        assert i2.mean() > 0.75 and i2.min() > 0.5, (i2.mean(), i2.min())
    assert all(r.ok for r in r2)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("tw,th,d", [(300, 200, 4), (200, 300, 4), (160, 120, 2)])
def test_large_target_decimated(seed, tw, th, d):
    """Targets larger than the 127 px window memory are tracked on every D-th pixel, at full size.
    Measured (seeds 0..2): mean IoU 0.975 .. 0.982, min 0.919 .. 0.947, sizes within 0.2 px."""
    n, width, height = 60, 640, 480
    t = np.arange(n)
    gt = _centre_boxes(width / 2 + 80 * np.sin(t / 15), height / 2 + 50 * np.sin(t / 12), tw, th)
    frames = render_scene(gt, width, height, seed=seed)
    _, res = _run(frames, gt[0], preset="v2")
    assert res[0].extra["decimation"] == d and all(r.extra["decimation"] == d for r in res)
    assert max(tw, th) * 1.25 / d <= 127 < max(tw, th) * 1.25 / (d // 2)
    b = _boxes(res)
    assert np.abs(b[:, 2] - tw).max() < 0.05 * tw and np.abs(b[:, 3] - th).max() < 0.05 * th   # not shrunk
    io = iou(b, gt)
    assert io.mean() > 0.9 and io.min() > 0.8, (io.mean(), io.min())
    assert all(r.status in (Status.INIT, Status.OK) for r in res)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("speed", [0.0, 1.0, 2.0])
def test_full_occlusion_lost_then_reacquired(seed, speed):
    """A 40x40 target moving right at ``speed`` px/frame is hidden by a background-textured patch
    in frames 30..44.  Measured: LOST on all 15 hidden frames (confidence 0), REACQUIRED on frame
    45, OK after, IoU 0.96 .. 0.99 from frame 46 on (frame 45: 0.13 .. 0.99, the target moved
    while hidden)."""
    n = 80
    t = np.arange(n)
    gt = _centre_boxes(100 + speed * t, 120, 40, 40)
    hidden = (t >= 30) & (t < 45)
    frames = render_scene(gt, 320, 240, seed=seed, hidden=hidden)
    trk, res = _run(frames, gt[0], preset="v2")
    _status_rule_holds(res, trk.params)
    st = [r.status for r in res]
    assert all(s in (Status.OK, Status.INIT) for s in st[:30]), st
    assert not any(r.ok for r in res[30:45]), [s.value for s in st[30:45]]
    assert all(s in (Status.LOST, Status.UNCERTAIN) for s in st[30:45])
    assert Status.LOST in st[30:45]
    assert all(r.confidence < trk.params.conf_uncertain for r in res[30:45])
    assert st[45] == Status.REACQUIRED or st[46] == Status.REACQUIRED, [s.value for s in st[44:50]]
    assert all(r.ok for r in res[47:]), [s.value for s in st[47:]]
    io = iou(_boxes(res), gt)
    assert io[47:].min() > 0.8 and io[47:].mean() > 0.9, (io[47:].min(), io[47:].mean())


def _jump_scene(seed, jx, jy, n=40, at=20):
    t = np.arange(n)
    gt = _centre_boxes(np.where(t < at, 100, 100 + jx), np.where(t < at, 120, 120 + jy), 40, 40)
    return render_scene(gt, 320, 240, seed=seed), gt


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("jx,jy", [(60, 0), (80, 0), (0, -70), (70, 60), (-60, 50)])
def test_jump_reacquired_by_wide_search(seed, jx, jy):
    """A 40x40 target (window 50x50) jumps 60..92 px on frame 20: entirely outside the window, so
    frame 20 is LOST; the wide search (8 starts one window size away) finds it on frame 21.
    Measured: REACQUIRED on frame 21 in every case, IoU >= 0.96 after."""
    frames, gt = _jump_scene(seed, jx, jy)
    trk, res = _run(frames, gt[0], preset="v2")
    _status_rule_holds(res, trk.params)
    assert res[20].status == Status.LOST and not res[20].ok
    assert res[21].status == Status.REACQUIRED and res[21].extra["searched"] == 8
    assert all(r.status == Status.OK for r in res[22:])
    io = iou(_boxes(res), gt)
    assert io[21:].min() > 0.8


@pytest.mark.xfail(strict=True, reason=(
    "by design: the wide search starts one window size (search_step) from the last centre and "
    "does not widen while lost, so it reaches +-(search_step * 2 hx + hx) = 75 px of a 40 px "
    "target's last centre; a 100 or 150 px jump leaves the target outside every start window and "
    "the tracker stays LOST (confidence 0, box at the last place) to the end of the sequence; the "
    "experimental search_widen (off by default) reaches 100 px: "
    "tests/test_fixed_v2_widths.py::test_widened_search_reacquires_a_jump_beyond_the_default_reach"))
@pytest.mark.parametrize("jx", [100, 150])
def test_jump_beyond_search_reach(jx):
    frames, gt = _jump_scene(0, jx, 0)
    _, res = _run(frames, gt[0], preset="v2")
    assert res[-1].ok and iou(_boxes(res[-1:]), gt[-1:])[0] > 0.8


# ============================================================================ bad input
@pytest.fixture(scope="module")
def scene():
    f0, f1, box = shift_scene(3, -2)
    f2 = shift_scene(5, -1)[1]
    return f0, f1, f2, box


from test_bad_input import BAD_FRAMES, H, W  # noqa: E402  (the same bad frames as the paper preset)


@pytest.mark.parametrize("name", sorted(BAD_FRAMES))
def test_bad_frame_raises_frame_error(name, scene):
    f0, _, _, box = scene
    with pytest.raises(FrameError):
        Tracker(model="float", preset="v2").init(BAD_FRAMES[name], box)
    trk = Tracker(model="float", preset="v2")
    trk.init(f0, box)
    with pytest.raises(FrameError):
        trk.update(BAD_FRAMES[name])


@pytest.mark.parametrize("bad", ["smaller", "larger", "none", "float32"])
def test_bad_frame_does_not_change_state(bad, scene):
    f0, f1, f2, box = scene
    bad_frame = {"smaller": f1[:-10, :-6], "larger": np.pad(f1, ((0, 4), (0, 4), (0, 0))),
                 "none": None, "float32": f1.astype(np.float32)}[bad]
    ref = Tracker(model="float", preset="v2")
    ref.init(f0, box)
    want = [ref.update(f1), ref.update(f2)]
    trk = Tracker(model="float", preset="v2")
    trk.init(f0, box)
    got = [trk.update(f1)]
    with pytest.raises(FrameError):
        trk.update(bad_frame)
    got.append(trk.update(f2))
    for g, w in zip(got, want):
        assert (g.centre, g.box, g.rho_c, g.confidence, g.status) == (w.centre, w.box, w.rho_c, w.confidence,
                                                                      w.status)


def test_update_before_init(scene):
    with pytest.raises(RuntimeError, match="before init"):
        Tracker(model="float", preset="v2").update(scene[0])


def test_failed_init_leaves_no_state(scene):
    trk = Tracker(model="float", preset="v2")
    with pytest.raises(FrameError):
        trk.init(None, scene[3])
    with pytest.raises(RuntimeError):
        trk.update(scene[0])


@pytest.mark.parametrize("box", [(10, 10, 0, 20), (10, 10, -5, 20), (float("nan"), 10, 20, 20), (10, 10, 20),
                                 "5599", (-50, 10, 20, 20), (W + 5, 10, 20, 20)])
def test_invalid_box_raises(box, scene):
    with pytest.raises(ValueError):
        Tracker(model="float", preset="v2").init(scene[0], box)


@pytest.mark.parametrize("box", [(-10, 20, 40, 30), (140, 100, 40, 30), (-20, -20, W + 40, H + 40)])
def test_box_partly_outside_is_clipped(box, scene):
    f0, f1, _, _ = scene
    trk = Tracker(model="float", preset="v2")
    r = trk.init(f0, box)
    assert r.status == Status.CLIPPED and r.ok
    assert r.box.x >= 0 and r.box.y >= 0 and r.box.x + r.box.w <= W + 1e-9 and r.box.y + r.box.h <= H + 1e-9
    r1 = trk.update(f1)
    assert all(math.isfinite(v) for v in (*r1.centre, *r1.box.as_tuple(), r1.confidence))
    assert 0 <= r1.centre[0] <= W - 1 and 0 <= r1.centre[1] <= H - 1
    assert 3 <= r1.box.w <= W and 3 <= r1.box.h <= H


def test_grey_and_bgra_frames(scene):
    f0, f1, _, box = scene
    trk = Tracker(model="float", preset="v2")
    assert trk.init(cv2.cvtColor(f0, cv2.COLOR_BGR2GRAY), box).status == Status.INIT
    r = trk.update(cv2.cvtColor(f1, cv2.COLOR_BGR2GRAY)[:, :, None])
    assert all(math.isfinite(v) for v in r.centre)
    a, b = Tracker(model="float", preset="v2"), Tracker(model="float", preset="v2")
    a.init(f0, box)
    b.init(cv2.cvtColor(f0, cv2.COLOR_BGR2BGRA), box)
    assert a.update(f1).centre == b.update(cv2.cvtColor(f1, cv2.COLOR_BGR2BGRA)).centre


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_never_nan(kernel, scene):
    rng = np.random.default_rng(7)
    fr = {"black": np.zeros((H, W, 3), np.uint8), "white": np.full((H, W, 3), 255, np.uint8),
          "noise": rng.integers(0, 256, (H, W, 3), dtype=np.uint8)}
    box = scene[3]
    for init_name in ("black", "noise"):
        trk = Tracker(model="float", preset="v2", kernel=kernel)
        trk.init(fr[init_name], box)
        for name in ("black", "noise", "white", "black", "noise"):
            r = trk.update(fr[name])
            vals = (*r.centre, *r.box.as_tuple(), r.rho_c, r.confidence)
            assert all(math.isfinite(v) for v in vals), (init_name, name, r)
            assert 0.0 <= r.confidence <= 1.0
    # a model learnt on the real target, then black frames: lost, nothing target-coloured
    trk = Tracker(model="float", preset="v2", kernel=kernel)
    trk.init(scene[0], box)
    r = trk.update(fr["black"])
    assert r.status == Status.LOST and not r.ok and r.confidence == 0.0
    r = trk.update(fr["black"])
    assert r.status == Status.LOST and r.extra["searched"] == 8


# ============================================================================ real data
#: Overall frame-weighted OTB AUC (frame 0 included) of v2 float over the 10 sequences of
#: ../shared/data/sequences: the default (joint) v2 0.564 (2026-11-27), the colour tracker 0.551 (2026-11-23);
#: paper float fused/flat 0.366 (same run; 8 .. 15 s
#: for both on 2 shared cores).  Floor 0.50.
V2_AUC_FLOOR = 0.50
#: OpenCV CSRT on the same set (docs/results.md, `make results`): overall AUC 0.452, mean over
#: sequences 0.562 (CSRT is not bit-reproducible across runs here, so the targets are fixed numbers)
CSRT_AUC, CSRT_MEAN = 0.452, 0.562


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (CI has them)")
def test_real_sequences_default_v2_meets_accuracy_and_loss_targets():
    """The accuracy and loss targets for the default tracker v2 (mstrack-v2), float and fixed
    model, as docs/results.md's targets table computes them: fixed overall AUC >= 0.46 and >= CSRT's,
    fixed mean over sequences >= CSRT's, fixed within 0.01 AUC of float, and the loss flag (frames
    after the init frame with valid ground truth) at recall >= 0.6 with false alarms <= 0.05 in both
    models.  Measured (2026-11-27): AUC 0.564 / 0.570, mean 0.587 / 0.572, loss 0.63 at 0.048 /
    0.81 at 0.049 (float / fixed; the loss thresholds were chosen on this set).  Both models are
    deterministic (no BLAS), so the figures repeat bit for bit."""
    from mstrack.eval.evaluate import aggregate, make_tracker, run_sequence
    from mstrack.eval.metrics import iou, loss_detection, valid_gt
    from mstrack.io.data import load_dataset

    seqs = load_dataset(SEQ_ROOT)
    runs = {m: {s.name: run_sequence(make_tracker("mstrack-v2", m), s, label=m, model=m) for s in seqs}
            for m in ("float", "fixed")}
    ev = aggregate(runs, seqs)
    assert not ev.failed
    auc = {m: ev.overall[m].auc for m in runs}
    mean = {m: float(np.mean([ev.per_sequence[m][n].auc for n in ev.sequences])) for m in runs}
    assert auc["fixed"] >= max(0.46, CSRT_AUC), auc
    assert mean["fixed"] >= CSRT_MEAN, mean
    assert abs(auc["fixed"] - auc["float"]) <= 0.01, auc
    for m, per in runs.items():
        ious, oks = [], []
        for seq in seqs:
            run = per[seq.name]
            gt = seq.gt[:run.n_frames]
            v = valid_gt(gt)
            v[0] = False   # the init frame says nothing about loss detection
            ious.append(iou(run.boxes, gt)[v])
            oks.append(run.ok[v])
        ld = loss_detection(np.concatenate(ious), np.concatenate(oks))
        assert ld.recall >= 0.6 and ld.false_alarm <= 0.05, (m, ld)


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (CI has them)")
def test_real_sequences_auc_floor_and_beats_paper():
    from mstrack.io.data import load_dataset
    from mstrack.eval.evaluate import aggregate, make_tracker, run_sequence

    seqs = load_dataset(SEQ_ROOT)
    assert len(seqs) == 10, [s.name for s in seqs]
    t0 = time.perf_counter()
    runs = {name: {s.name: run_sequence(make_tracker(name), s, label=name) for s in seqs}
            for name in ("mstrack-v2", "mstrack-fused-flat")}
    elapsed = time.perf_counter() - t0
    ev = aggregate(runs, seqs)
    assert not ev.failed
    auc_v2, auc_paper = ev.overall["mstrack-v2"].auc, ev.overall["mstrack-fused-flat"].auc
    per = {n: round(ev.per_sequence["mstrack-v2"][n].auc, 3) for n in ev.sequences}
    assert auc_v2 >= V2_AUC_FLOOR, f"v2 AUC {auc_v2:.3f} < floor {V2_AUC_FLOOR} (measured 0.551); {per}"
    assert auc_v2 > auc_paper, f"v2 AUC {auc_v2:.3f} <= paper {auc_paper:.3f}"
    # every v2 status is one of the documented ones
    assert {s for r in runs["mstrack-v2"].values() for s in r.status} <= {s.value for s in Status}
    assert elapsed < 120, f"took {elapsed:.0f} s (budget ~60 s)"


def test_rescale_scale_test_options():
    """rescale with a rho-test estimate (experimental, docs/results_v2_mean.md): mix blends it with
    the spread estimate; the gate keeps the spread estimate only where both move the same way."""
    from mstrack.track.float_v2 import rescale
    shape, size0 = (480, 640), (40.0, 20.0)
    spread_up = 1.21  # sqrt -> est 1.1 (the bound)
    base = TrackerParams(preset="v2")
    grow = rescale(size0, size0, spread_up, 1.0, shape, base)
    assert grow[0] > 40.0
    gate = TrackerParams(preset="v2", scale_test=0.05, scale_test_gate=True)
    assert rescale(size0, size0, spread_up, 1.0, shape, gate, 1.05) == grow
    assert rescale(size0, size0, spread_up, 1.0, shape, gate, 1.0) == size0
    assert rescale(size0, size0, spread_up, 1.0, shape, gate, 0.95) == size0
    mix = TrackerParams(preset="v2", scale_test=0.05, scale_test_mix=0.5, scale_test_gate=False)
    w, _ = rescale(size0, size0, spread_up, 1.0, shape, mix, 0.95)
    assert w == pytest.approx(40.0 * (1.0 + 0.3 * (0.5 * 0.95 + 0.5 * 1.1 - 1.0)))
