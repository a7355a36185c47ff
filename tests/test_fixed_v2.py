"""Tracker v2 in fixed point: each block against its exact definition, and the tracker against float v2.

Exact definitions use Python integers and fractions.Fraction (no floats), so a
rounding or width slip in mstrack/fixed/blocks_v2.py shows as a mismatch.
"""
from __future__ import annotations

import functools
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from mstrack import Tracker
from mstrack.fixed.blocks import ms_colour_bin, ms_kernel
from mstrack.fixed.blocks_v2 import (ONE, ms_bg_model, ms_box_size, ms_confidence, ms_decimation, ms_loss_filter,
                                     ms_loss_flag, ms_model_scale, ms_ref_update, ms_resize, ms_ring_share, ms_scale, ms_share,
                                     ms_spread,
                                     ms_target_stats, ms_window_size, rate_shift, sixteenths, TargetStats)
from mstrack.track.float_v2 import FloatTrackerV2
from mstrack.track.params import V2_COLOUR, TrackerParams

SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"
V2 = TrackerParams(preset="v2")


def floor_frac(x: Fraction) -> int:
    return math.floor(x)


# ----------------------------------------------------------------------------- geometry
def test_decimation_exhaustive():
    """D is the smallest power of two <= 8 with (1 + pad) max(w, h) / D <= max_window (exact)."""
    for pad16 in (0, 4, 8):
        for s8 in range(3 << 8, 1200 << 8, 37):
            want = next((d for d in (1, 2, 4, 8) if Fraction(16 + pad16, 16) * Fraction(s8, 256) / d <= 127), 8)
            assert ms_decimation(s8, 3 << 8, pad16, 127) == want, (pad16, s8)
            assert ms_decimation(3 << 8, s8, pad16, 127) == want


def test_decimation_matches_float():
    flt = FloatTrackerV2(V2)
    for s in np.linspace(3, 1000, 997):
        s8 = int(round(s * 256))
        assert ms_decimation(s8, s8, 4, 127) == flt.decimation(s8 / 256, s8 / 256)


def test_window_and_box_size_round_half_up():
    for d in (1, 2, 4, 8):
        for s8 in range(3 << 8, 1100 << 8, 53):
            exact = Fraction(20, 16) * Fraction(s8, 256) / d
            assert ms_window_size(s8, 4, d, 10 ** 6) == max(3, floor_frac(exact + Fraction(1, 2)))
            assert ms_box_size(s8, d, 10 ** 6) == max(3, floor_frac(Fraction(s8, 256 * d) + Fraction(1, 2)))
    assert ms_window_size(1000 << 8, 4, 1, 127) == 127


def test_parameter_representation():
    assert sixteenths(0.25, "pad") == 4 and sixteenths(0.625, "bg_ring") == 10
    with pytest.raises(ValueError, match="1/16"):
        sixteenths(0.6, "bg_ring")
    assert rate_shift(1 / 64) == 6
    with pytest.raises(ValueError, match="power of two"):
        rate_shift(0.02)
    with pytest.raises(ValueError, match="1/16"):
        Tracker(model="fixed", preset="v2", bg_ring=0.6)


# ----------------------------------------------------------------------------- model
def _bg_model_exact(bins, cx, cy, wb, hb, ring16, n_bins, bf=8):
    """ms_bg_model by its definition in exact fractions (bf: the CBWH factors' fraction bits, bg_frac)."""
    ker = ms_kernel(wb, hb, "flat", 8)
    ex, ey = ker.ex, ker.ey
    Q = [0] * n_bins
    for dy in range(-ey, ey + 1):
        for dx in range(-ex, ex + 1):
            if Fraction(2 * dx, wb) ** 2 + Fraction(2 * dy, hb) ** 2 < 1:
                Q[bins[cy + dy, cx + dx]] += 1
    gx, gy = ring16 * wb // 16, ring16 * hb // 16
    H, W = bins.shape
    O = [0] * n_bins
    for y in range(max(0, cy - ey - gy), min(H - 1, cy + ey + gy) + 1):
        for x in range(max(0, cx - ex - gx), min(W - 1, cx + ex + gx) + 1):
            if abs(x - cx) > ex or abs(y - cy) > ey:
                O[bins[y, x]] += 1
    nq, no = sum(Q), sum(O)
    omin = min(o for o in O if o > 0)
    v = [min(floor_frac(Fraction(omin << bf, o)), 1 << bf) if o else 1 << bf for o in O]
    tot = sum(q * vv for q, vv in zip(Q, v))
    Qn = [floor_frac(Fraction(q * vv * ONE, tot)) for q, vv in zip(Q, v)]
    T = [int(Fraction(q, nq) > Fraction(o, no)) for q, o in zip(Q, O)]
    return Q, O, Qn, T


@pytest.mark.parametrize("seed", range(6))
def test_bg_model_against_exact_definition(seed):
    rng = np.random.default_rng(seed)
    n_bins = 64
    H, W = 60, 80
    bins = rng.integers(0, n_bins, (H, W))
    bins[20:40, 30:50] = rng.integers(0, 8, (20, 20))  # a "target" of few colours
    wb, hb = int(rng.integers(3, 30)), int(rng.integers(3, 25))
    cx, cy = int(rng.integers(wb // 2 + 1, W - wb // 2 - 1)), int(rng.integers(hb // 2 + 1, H - hb // 2 - 1))
    m = ms_bg_model(bins, cx, cy, wb, hb, 10, n_bins)
    Q, O, Qn, T = _bg_model_exact(bins, cx, cy, wb, hb, 10, n_bins)
    assert m.Q.tolist() == Q and m.O.tolist() == O and m.Qn.tolist() == Qn and m.T.tolist() == T
    assert ONE - n_bins <= m.Qn.sum() <= ONE


def test_bg_model_without_background():
    bins = np.zeros((9, 9), np.int64)
    bins[4, 4] = 3
    m = ms_bg_model(bins, 4, 4, 9, 9, 10, 8)  # the ring falls outside the image
    assert m.O.sum() == 0 and m.T.tolist() == [1, 0, 0, 1, 0, 0, 0, 0]
    assert m.Qn[3] == (1 << 16) // m.Q.sum()


def test_model_scale():
    rng = np.random.default_rng(1)
    Qn = rng.integers(0, 1 << 16, 512)
    for K in (3, 100, 16129):
        assert ms_model_scale(Qn, K).tolist() == [q * K >> 16 for q in Qn.tolist()]


@pytest.mark.parametrize("wd,hd,pad16", [(3, 3, 4), (17, 31, 4), (127, 127, 4), (40, 9, 0), (25, 64, 8)])
def test_target_stats_brute_force(wd, hd, pad16):
    rng = np.random.default_rng(wd * hd)
    ker = ms_kernel(wd, hd, "flat", 8)
    bins = rng.integers(0, 16, (hd + 4, wd + 4))
    T = rng.integers(0, 2, 16)
    win = (ker.ex + 2, ker.ey + 2)
    nt = st2 = n_in = nt_in = 0
    for dy in range(-ker.ey, ker.ey + 1):
        for dx in range(-ker.ex, ker.ex + 1):
            if 4 * dx * dx * hd * hd + 4 * dy * dy * wd * wd >= wd * wd * hd * hd:
                continue
            d2q = (4 * dx * dx * 256) // (wd * wd) + (4 * dy * dy * 256) // (hd * hd)
            t = int(T[bins[win[1] + dy, win[0] + dx]])
            inner = Fraction(d2q, 256) < Fraction(256, (16 + pad16) ** 2)
            nt += t
            st2 += t * d2q
            n_in += inner
            nt_in += t * inner
    assert ms_target_stats(bins, T, win, ker, 8, pad16) == TargetStats(nt, st2, n_in, nt_in)


# ----------------------------------------------------------------------------- confidence, scale
def test_share_spread_confidence_random():
    rng = np.random.default_rng(7)
    for _ in range(3000):
        n_in = int(rng.integers(1, 16130))
        st = TargetStats(nt=int(rng.integers(1, 16130)), st2=int(rng.integers(0, 16129 * 512)), n_in=n_in,
                         nt_in=int(rng.integers(0, n_in + 1)))
        assert ms_share(st) == floor_frac(Fraction(st.nt_in * ONE, st.n_in))
        assert ms_spread(st) == floor_frac(Fraction(st.st2 * ONE, st.nt))
        rho, share = int(rng.integers(0, ONE + 1)), int(rng.integers(0, ONE + 1))
        rr, sr = int(rng.integers(1, ONE + 1)), int(rng.integers(1, ONE + 1))
        want = (min(ONE, floor_frac(Fraction(rho * ONE, rr))) * min(ONE, floor_frac(Fraction(share * ONE, sr)))) >> 16
        assert ms_confidence(rho, share, rr, sr) == want
        assert 0 <= want <= ONE
    assert ms_share(TargetStats(0, 0, 0, 0)) == 0 and ms_spread(TargetStats(0, 0, 0, 0)) == 0
    assert ms_confidence(5, 5, 0, 0) == 0


def test_ring_share_against_exact_definition():
    """ring_share = floor((nt - nt_in) 2**16 / (K - n_in)), 0 without ring pixels; large random
    plus the edges (empty ring, all-target ring, one-pixel ring)."""
    rng = np.random.default_rng(11)
    cases = [(1, 0, 1, 0), (5, 5, 5, 5), (16129, 0, 16129, 0), (16129, 16129, 1, 0), (16129, 16128, 16128, 16128),
             (16129, 1, 16128, 0)]
    for _ in range(20000):
        K = int(rng.integers(1, 16130))
        n_in = int(rng.integers(0, K + 1))
        nt_in = int(rng.integers(0, n_in + 1))
        nt = nt_in + int(rng.integers(0, K - n_in + 1))
        cases.append((K, n_in, nt, nt_in))
    for K, n_in, nt, nt_in in cases:
        st = TargetStats(nt=nt, st2=0, n_in=n_in, nt_in=nt_in)
        want = floor_frac(Fraction((nt - nt_in) * ONE, K - n_in)) if K > n_in else 0
        got = ms_ring_share(st, K)
        assert got == want, (K, n_in, nt, nt_in)
        assert 0 <= got <= ONE


def test_loss_filter_against_exact_definition():
    """s + floor((x - s) / 2**k) over the signed range, exhaustive on a coarse grid + edges, and
    the result always between s and x."""
    vals = list(range(-ONE, ONE + 1, 997)) + [-ONE, -1, 0, 1, ONE - 1, ONE]
    for k in (0, 1, 2, 6):
        for s_ in vals:
            for x in vals:
                got = ms_loss_filter(s_, x, k)
                assert got == s_ + math.floor(Fraction(x - s_, 1 << k)), (s_, x, k)
                assert min(s_, x) <= got <= max(s_, x)


def test_degenerate_init_model_reports_lost_not_ok():
    """Every box colour > 256x as frequent in the ring as the rarest ring colour: every v_u = 0,
    sum(Q v) = 0, Qn = 0 (as rtl/ms_bg_model.vhd); the model matches nothing, so the tracker
    must not report ok (rho_s = 0 raises the loss flag)."""
    f = np.zeros((120, 160, 3), np.uint8)
    f[42, 62] = 255
    m = ms_bg_model(ms_colour_bin(f, 3), 77, 57, 15, 15, 10, 512)
    assert m.Qn.sum() == 0 and m.Q.sum() > 0
    trk = Tracker(model="fixed", preset="v2")
    trk.init(f, (70, 50, 15, 15))
    r = trk.update(f)
    assert not r.ok and r.confidence == 0.0


def test_loss_flag_against_exact_definition():
    """flag = share = 0 or rho_s = 0 or (rho_s / rho0 < loss_rho / 2**16 and con_s < loss_contrast), as exact
    rationals; large random over the full ranges plus every threshold edge."""
    rng = np.random.default_rng(12)
    cases = []
    for _ in range(50000):
        cases.append((int(rng.integers(0, 3) > 0) * int(rng.integers(0, ONE + 1)), int(rng.integers(0, ONE + 1)), int(rng.integers(-ONE, ONE + 1)),
                      int(rng.integers(0, 3)) * int(rng.integers(0, ONE + 1)),  # share: 0 one time in three
                      int(rng.integers(0, 2 * ONE + 1)), int(rng.integers(-ONE, ONE + 1))))
    lr, lc = round(V2.loss_rho * ONE), round(V2.loss_contrast * ONE)
    for rho0 in (1, 1000, 40000, ONE):  # rho_s exactly at and next to the threshold
        for rho in {(lr * rho0) >> 16, ((lr * rho0) >> 16) + 1, max(((lr * rho0) >> 16) - 1, 0)}:
            for c in (lc - 1, lc, lc + 1):
                for share in (0, 1, ONE):
                    cases.append((rho, rho0, c, share, lr, lc))
    for rho_s, rho0, con_s, share, loss_rho, loss_contrast in cases:
        want = share == 0 or rho_s == 0 or ((Fraction(rho_s) < Fraction(loss_rho, ONE) * rho0) and (con_s < loss_contrast))
        assert ms_loss_flag(rho_s, rho0, con_s, share, loss_rho, loss_contrast) == want, \
            (rho_s, rho0, con_s, share, loss_rho, loss_contrast)


def test_fixed_v2_status_from_loss_flag():
    """Each fixed-model update: the search state from the confidence (as before), the reported
    status from ms_loss_flag on its raw integers (rho and share - ring_share, each smoothed by
    s + floor((x - s) / 2), against rho at init)."""
    from mstrack.fixed.tracker_v2 import STATUS_CODES_V2
    from mstrack.track.types import Status
    frames, boxes = _scene(30)
    for f in frames[12:18]:  # the target leaves for 6 frames
        f[:] = frames[0][0, 0]
    trk = Tracker(model="fixed", preset="v2")
    r0 = trk.init(frames[0], boxes[0])
    rho0 = r0.extra["rho"]
    rho_s, con_s = r0.extra["rho_s"], r0.extra["contrast_s"]
    assert rho_s == rho0
    k = round(-math.log2(V2.loss_smooth))
    codes = {v: k for k, v in STATUS_CODES_V2.items()}
    lr, lc = round(V2.loss_rho * ONE), round(V2.loss_contrast * ONE)
    searching = reported_lost = False
    seen = set()
    for f in frames[1:]:
        r = trk.update(f)
        e = r.extra
        assert ms_ring_share(TargetStats(e["nt"], 0, e["n_in"], e["nt_in"]), e["K"]) == e["ring_share"]
        rho_s = rho_s + math.floor(Fraction(e["rho"] - rho_s, 1 << k))
        con_s = con_s + math.floor(Fraction(e["share"] - e["ring_share"] - con_s, 1 << k))
        assert (e["rho_s"], e["contrast_s"]) == (rho_s, con_s)
        flagged = ms_loss_flag(rho_s, rho0, con_s, e["share"], lr, lc)
        state = codes[e["state"]]
        if flagged:
            want = Status.LOST if state == Status.LOST else Status.UNCERTAIN
        else:
            want = Status.REACQUIRED if reported_lost else Status.OK
        assert codes[e["status"]] == want == r.status and r.ok == (not flagged)
        assert (e["searched"] > 0) == searching
        searching = state == Status.LOST
        reported_lost = want == Status.LOST or (want == Status.UNCERTAIN and reported_lost)
        seen.add(want)
    assert {Status.OK, Status.LOST, Status.REACQUIRED} <= seen, seen


def test_ref_update_floor():
    for ref, x in ((1000, 2000), (2000, 1000), (5, 6), (6, 5), (0, ONE)):
        assert ms_ref_update(ref, x, 6) == ref + math.floor(Fraction(x - ref, 64))


def test_scale_against_exact_definition():
    rng = np.random.default_rng(3)
    g, r, st = round(0.3 * ONE), round(0.1 * ONE), round(0.1 * ONE)
    for _ in range(3000):
        spread, ref = int(rng.integers(0, 1 << 30)), int(rng.integers(1, 1 << 30))
        w8, w0 = int(rng.integers(3 << 8, 4000 << 8)), int(rng.integers(3 << 8, 4000 << 8))
        ratio = min(floor_frac(Fraction(spread * ONE, ref)), (1 << 40) - 1)
        est = min(max(math.isqrt(ratio << 16), ONE - st), ONE + st)
        wr = min(floor_frac(Fraction(w8 * ONE, w0)), (1 << 40) - 1)
        s = ONE + math.floor(Fraction(g * (est - ONE), ONE)) - math.floor(Fraction(r * (wr - ONE), ONE))
        assert ms_scale(spread, ref, w8, w0, V2) == min(max(s, ONE - st), ONE + st)
    assert ms_resize(10 << 8, ONE - 6554, 640) == ((10 << 8) * (ONE - 6554)) >> 16
    assert ms_resize(3 << 8, ONE // 2, 640) == 3 << 8
    assert ms_resize(600 << 8, 2 * ONE, 640) == 640 << 8


# ----------------------------------------------------------------------------- tracker
def _scene(n: int = 30):
    """A red square on a textured green/blue background moving right and growing."""
    rng = np.random.default_rng(0)
    frames, boxes = [], []
    for i in range(n):
        f = np.zeros((120, 160, 3), np.uint8)
        f[..., 0] = rng.integers(100, 200, (120, 160))
        f[..., 1] = rng.integers(60, 140, (120, 160))
        s = 20 + i // 2
        x, y = 30 + 2 * i, 50 - i // 4
        f[y:y + s, x:x + s] = (30, 30, 220)
        frames.append(f)
        boxes.append((x, y, s, s))
    return frames, boxes


def test_fixed_v2_tracks_a_growing_target_like_float():
    frames, boxes = _scene()
    for model in ("float", "fixed"):
        # on colour alone, without the scale test: the default's gated scale test vetoes this growth
        # (test_fixed_v2_joint_gate_tracks_like_float)
        trk = Tracker(model=model, preset="v2", **V2_COLOUR)
        trk.init(frames[0], boxes[0])
        for f in frames[1:]:
            r = trk.update(f)
        x, y, s, _ = boxes[-1]
        assert abs(r.box.x + r.box.w / 2 - (x + s / 2)) < 5, (model, r.box)  # box lags the growth
        assert r.box.w > 22, (model, r.box)       # followed the growth (init 20 px, truth 34 px)
        assert r.ok and r.confidence > 0.5


def test_fixed_v2_results_are_integers_and_deterministic():
    frames, boxes = _scene(8)
    runs = []
    for _ in range(2):
        trk = Tracker(model="fixed", preset="v2")
        trk.init(frames[0], boxes[0])
        runs.append([trk.update(f).extra for f in frames[1:]])
    assert runs[0] == runs[1]
    for e in runs[0]:
        for k in ("cx", "cy", "w8", "h8", "rho", "confidence", "status", "iter", "decimation"):
            assert isinstance(e[k], int), k


def test_fixed_v2_large_target_is_decimated_not_shrunk():
    rng = np.random.default_rng(2)
    f = rng.integers(0, 120, (400, 640, 3)).astype(np.uint8)
    f[50:350, 100:400] = (40, 200, 60)
    trk = Tracker(model="fixed", preset="v2")
    r0 = trk.init(f, (100, 50, 300, 300))
    r = trk.update(f)
    assert r0.box.w == 300 and r.extra["decimation"] == 4  # 1.25 * 300 / 4 = 94 <= 127 < 188
    assert abs(r.box.w - 300) < 10 and abs(r.box.x - 100) < 3


def test_lost_window_at_doubled_decimation_is_half():
    """The bound behind core v2's region RAM (mstrack.hw.cosim.region_max_v2): unless D is already the
    largest (8), the window at 2D (the lost state) is at most round(max_window / 2) px; every target
    size 3 .. 4095 px and a random Q.8 fraction of each, pads 0, 4, 8 / 16.  At D = 8 it is not."""
    rng = np.random.default_rng(12)
    over = 0
    for pad16 in (0, 4, 8):
        for s in range(3, 4096):
            for s8 in (s << 8, (s << 8) + int(rng.integers(0, 256))):
                d = ms_decimation(s8, 3 << 8, pad16, 127)
                wd = ms_window_size(s8, pad16, 2 * d, 127)
                if d < 8:
                    assert wd <= 64, (pad16, s8, d, wd)
                over += wd > 64
    assert over > 0


@pytest.mark.parametrize("scene", ["lost_at_d4", "lost_at_d16", "tall_lost_at_d16"])
def test_region_max_v2_bounds_the_fixed_model_regions(scene, monkeypatch):
    """Every region the fixed model captures, while tracking and while lost, fits core v2's region RAM
    (REGION_MAX = region_max_v2 rounded up to LANES: 256 at the defaults); the
    lost region at D = 4 reaches past the tracking region's 191, so the lost-state bound is exercised."""
    from mstrack.fixed import FixedParams
    from mstrack.fixed import tracker_v2 as tv2
    from mstrack.hw.cosim import CoreConfigV2, region_max_v2
    g = CoreConfigV2(V2, FixedParams()).generics()
    assert g["REGION_MAX"] == 256 and region_max_v2(V2, FixedParams(), 4095) == 255
    sizes = []
    real, real_v2 = tv2.ms_region, tv2.ms_region_v2

    def spy(*a, **k):                       # the init frame's region
        reg = real(*a, **k)
        sizes.append((reg.w, reg.h))
        return reg

    def spy_v2(*a, **k):                    # every update's region (tracking and lost)
        reg, m = real_v2(*a, **k)
        sizes.append((reg.w, reg.h))
        return reg, m
    monkeypatch.setattr(tv2, "ms_region", spy)
    monkeypatch.setattr(tv2, "ms_region_v2", spy_v2)
    rng = np.random.default_rng(7)
    shape, box = {"lost_at_d4": ((1400, 1400), (500, 500, 203, 203)),    # D 2, lost D 4: window 63
                  "lost_at_d16": ((1300, 2048), (100, 100, 1800, 1100)),  # D 8, lost D 16: frame-bound
                  "tall_lost_at_d16": ((4095, 300), (10, 100, 280, 3900))}[scene]
    f = rng.integers(0, 256, (*shape, 3)).astype(np.uint8)
    x, y, w, h = box
    f[y:y + h, x:x + w] = (40, 200, 60)
    trk = Tracker(model="fixed", preset="v2")
    trk.init(f, box)
    for _ in range(3):
        r = trk.update(rng.integers(0, 256, f.shape).astype(np.uint8))
    assert r.status.value == "lost"
    big = max(max(s) for s in sizes)
    assert big <= g["REGION_MAX"], sizes
    if scene == "lost_at_d4":
        assert big > 191 and r.extra["decimation"] == 4, (sizes, r.extra["decimation"])


@functools.cache
def _dev_set_runs(model: str) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Tracker(model=model, preset="v2") on every dev sequence, through the public API: per sequence the
    boxes (init frame first), the ok flags of the updates and the ground truth.  Computed once per model for
    the two tests below (the same runs)."""
    from mstrack.io.data import load_dataset
    out = []
    for seq in load_dataset(SEQ_ROOT):
        trk = Tracker(model=model, preset="v2")
        boxes, oks = [], []
        for i, fr in enumerate(seq.frames()):
            r = trk.init(fr, seq.init_box()) if i == 0 else trk.update(fr)
            boxes.append(r.box.as_tuple())
            if i:
                oks.append(r.ok)
        out.append((np.array(boxes, dtype=float), np.array(oks, dtype=bool), seq.gt[:len(boxes)]))
    return out


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (../shared absent)")
def test_fixed_v2_within_001_auc_of_float_v2_on_the_dev_set():
    """Issue target: the fixed model (= hardware) within 0.01 AUC of float v2, whole dev set."""
    from mstrack.eval.metrics import iou, valid_gt, IOU_THRESHOLDS

    res = {}
    for model in ("float", "fixed"):
        ious = [iou(boxes, gt)[valid_gt(gt)] for boxes, _, gt in _dev_set_runs(model)]
        io = np.concatenate(ious)
        res[model] = float(np.mean([(io > t).mean() for t in IOU_THRESHOLDS]))
    # measured 2026-11-23: float 0.549, fixed 0.555
    assert abs(res["fixed"] - res["float"]) <= 0.01, res
    assert res["fixed"] >= 0.50, res


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (../shared absent)")
def test_v2_loss_flag_on_the_dev_set():
    """Loss signal floors, both models, whole dev set (docs/results_loss.md): recall (off-target
    frames, IoU = 0, not ok) and false alarms (IoU >= 0.5, not ok).  Measured 2026-11-23: float
    0.556 / 0.041, fixed 0.581 / 0.048 (target 0.6 / 0.05: recall not reached)."""
    from mstrack.eval.metrics import iou, loss_detection, valid_gt

    for model in ("float", "fixed"):
        ious, oks = [], []
        for boxes, ok, gt in _dev_set_runs(model):
            v = valid_gt(gt[1:])
            ious.append(iou(boxes[1:], gt[1:])[v])
            oks.append(ok[v])
        ld = loss_detection(np.concatenate(ious), np.concatenate(oks))
        assert ld.recall >= 0.50 and ld.false_alarm <= 0.05, (model, ld)


def test_v2_budget_section_is_current():
    """docs/fixed_point.md's v2 budget table is generated (python -m mstrack.hw.synth --v2-budget --write)."""
    from mstrack.hw.synth import render_v2_budget
    doc = Path(__file__).resolve().parents[1] / "docs" / "fixed_point.md"
    text = doc.read_text()
    assert render_v2_budget(text) == text, "stale: run python -m mstrack.hw.synth --v2-budget --write"


def test_v2_worst_frames_fit_1080p60_blanking_with_lanes_4():
    from mstrack.hw.synth import v2_cycle_budget
    rows = v2_cycle_budget(4)
    assert len(rows) == 3 and all(r["clocks"] <= 99000 for r in rows), rows


def test_init_model_box_is_limited_to_max_window():
    """A target above ~812 px (D capped at 8) is learned on at most MAX_WINDOW decimated px, the
    size rtl/ms_bg_model.vhd and the kernel tables hold (the box size clamp of ms_box_size)."""
    rng = np.random.default_rng(4)
    f = rng.integers(0, 120, (1080, 1920, 3)).astype(np.uint8)
    f[20:1060, 20:1900] = (40, 200, 60)
    trk = Tracker(model="fixed", preset="v2")
    trk.init(f, (20, 20, 1880, 1040))
    m = trk._impl.model
    assert m.Q.sum() <= 127 * 127 and m.Q.sum() > 0.7 * 127 * 127
    r = trk.update(f)
    assert r.extra["decimation"] == 8


# ----------------------------------------------------------------------------- experimental blocks
# docs/results_v2_mean.md (off by default): joint colour x orientation bins, gated scale test.
def _orient_exact(grey: np.ndarray, T: int) -> np.ndarray:
    """The orientation bin pixel by pixel in Python ints (docs/fixed_point.md "Experimental")."""
    h, w = grey.shape
    out = np.full((h, w), 8, np.int64)
    g = [[int(v) for v in row] for row in grey]
    for y in range(1, h - 1):
        for x in range(1, w - 1):
            gx = ((g[y - 1][x + 1] + 2 * g[y][x + 1] + g[y + 1][x + 1])
                  - (g[y - 1][x - 1] + 2 * g[y][x - 1] + g[y + 1][x - 1]))
            gy = ((g[y + 1][x - 1] + 2 * g[y + 1][x] + g[y + 1][x + 1])
                  - (g[y - 1][x - 1] + 2 * g[y - 1][x] + g[y - 1][x + 1]))
            if abs(gx) + abs(gy) >= T:
                out[y, x] = (4 if gx < 0 else 0) + (2 if gy < 0 else 0) + (1 if abs(gy) > abs(gx) else 0)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_orient_bin_against_exact_definition(seed):
    from mstrack.fixed.blocks_v2 import ms_orient_bin
    rng = np.random.default_rng(seed)
    grey = rng.integers(0, 256, (23, 31)).astype(np.int64)
    grey[5:12, 4:20] = rng.integers(0, 2) * 255  # flat patches and strong edges too
    for T in (0, 1, 32, 64, 500, 2040, 2041):
        assert np.array_equal(ms_orient_bin(grey, T), _orient_exact(grey, T))
    # every sign / magnitude case of a single step edge in all 8 directions
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            yy, xx = np.mgrid[0:7, 0:7]
            step = ((dx * (xx - 3) + dy * (yy - 3)) > 0).astype(np.int64) * 200
            assert np.array_equal(ms_orient_bin(step, 64), _orient_exact(step, 64))
    assert np.array_equal(ms_orient_bin(np.zeros((2, 5), np.int64), 1), np.full((2, 5), 8))


def test_joint_bin_and_scale_test_size_exhaustive():
    from mstrack.fixed.blocks_v2 import ms_joint_bin, ms_scale_test_size
    c = np.arange(512)[:, None].repeat(9, 1)
    o = np.arange(9)[None, :].repeat(512, 0)
    jb = ms_joint_bin(c, o)
    assert np.array_equal(jb, 9 * c + o) and sorted(jb.ravel().tolist()) == list(range(4608))
    for s8 in range(3 << 8, 700 << 8, 97):
        for d256 in (0, 1, 13, 26, 128):
            for up in (False, True):
                want = math.floor(Fraction(s8 * (256 + (d256 if up else -d256)), 256) + Fraction(1, 2))
                assert ms_scale_test_size(s8, d256, up) == want


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_histogram_banks_is_the_joint_histogram_by_colour_and_orientation(kernel):
    """ms_histogram_banks (rtl/ms_histogram.vhd with N_ORIENT = 9: bank o, address u): H, N, SX, SY
    at [u, o] are the sums over the window's inside pixels of colour u and orientation o, brute force."""
    from mstrack.fixed.blocks import Region, ms_histogram, ms_histogram_banks
    from mstrack.fixed.blocks_v2 import ms_joint_bin
    rng = np.random.default_rng(9)
    reg = Region(5, 7, 40, 30, (0, 0), (0, 0))           # lo, hi: not used by ms_histogram
    colour = rng.integers(0, 4, (reg.h, reg.w))          # few colours: many (u, o) with several pixels
    orient = rng.integers(0, 9, (reg.h, reg.w))
    colour[12:15, :] = 511                                # the last colour address too (inside the window)
    ker = ms_kernel(23, 17, kernel, 8)
    win = (reg.x + 20, reg.y + 14)
    h = ms_histogram(ms_joint_bin(colour, orient), reg, win, ker, 9 * 512)
    b = ms_histogram_banks(h, 9)
    assert b.H.shape == b.N.shape == b.SX.shape == b.SY.shape == (512, 9)
    want = {k: np.zeros((512, 9), np.int64) for k in ("H", "N", "SX", "SY")}
    for yy in range(-ker.ey, ker.ey + 1):
        for xx in range(-ker.ex, ker.ex + 1):
            if not ker.inside[yy + ker.ey, xx + ker.ex]:
                continue
            r, c = win[1] + yy - reg.y, win[0] + xx - reg.x
            u, o = colour[r, c], orient[r, c]
            want["H"][u, o] += ker.k[yy + ker.ey, xx + ker.ex]
            want["N"][u, o] += 1
            want["SX"][u, o] += xx
            want["SY"][u, o] += yy
    for k in want:
        assert np.array_equal(getattr(b, k), want[k]), k
    assert want["N"][511].sum() > 0 and (want["N"][:4] > 1).sum() > 20
    with pytest.raises(ValueError):
        ms_histogram_banks(h, 7)


def test_scale_test_and_gate_exhaustive():
    from mstrack.fixed.blocks_v2 import ms_scale_gate, ms_scale_test
    vals = (None, 0, 1, 2, ONE)
    for r in (0, 1, 2, ONE):
        for lo in vals:
            for hi in vals:
                cands = [(r, 0)] + ([(lo, -1)] if lo is not None else []) + ([(hi, 1)] if hi is not None else [])
                best = max(v for v, _ in cands)
                want = next(k for v, k in cands if v == best)  # ties: the earlier of (1, 1 - d, 1 + d)
                assert ms_scale_test(r, lo, hi) == want
    for sp in range(0, 6):
        for ref in range(1, 6):
            for v in (-1, 0, 1):
                same = (sp > ref and v == 1) or (sp < ref and v == -1)
                assert ms_scale_gate(sp, ref, v) == (sp if same else ref)
    # a vetoed step: est is exactly 1, only the pull toward the init size remains
    for ref in (1, 12345, (1 << 30) - 1):
        for w8, w0 in ((10 << 8, 10 << 8), (15 << 8, 10 << 8), (7 << 8, 10 << 8)):
            wr = floor_frac(Fraction(w8 * ONE, w0))
            want = ONE - math.floor(Fraction(round(0.1 * ONE) * (wr - ONE), ONE))
            st = round(0.1 * ONE)
            assert ms_scale(ms_scale_gate(2 * ref, ref, -1), ref, w8, w0, V2) == min(max(want, ONE - st), ONE + st)


def test_fixed_v2_joint_gate_tracks_like_float():
    """The experimental options in the fixed model track the target of _scene as float does (the
    centre; the gated scale test vetoes the growth here: the padded window already holds the whole
    target, and rho is not larger at x1.05, so both stay near the init size, docs/results_v2_mean.md);
    the fixed model refuses the options it does not have."""
    from mstrack.eval.metrics import iou
    frames, gt = _scene()
    gt = np.array(gt, np.float64)
    kw = dict(orient_T=64, scale_test=0.05, scale_test_gate=True)
    out = {}
    for model in ("float", "fixed"):
        t = Tracker(model=model, preset="v2", **kw)
        res = [t.init(frames[0], tuple(gt[0]))] + [t.update(f) for f in frames[1:]]
        out[model] = np.array([r.box.as_tuple() for r in res])
        assert np.mean(iou(out[model], gt)) > 0.5, model
    assert np.max(np.abs(out["fixed"] - out["float"])[:, :2]) < 3.0
    with pytest.raises(ValueError):
        Tracker(model="fixed", preset="v2", scale_test=0.05, scale_test_gate=False)
    with pytest.raises(ValueError):
        Tracker(model="fixed", preset="v2", motion_gain=0.5)


def test_registered_v2_trackers():
    """``mstrack-v2`` (make results, mstrack eval / bench / explore) builds the default tracker v2, the
    joint tracker's options and loss thresholds (V2_JOINT), in both models, and tracks the scene of
    test_fixed_v2_joint_gate_tracks_like_float exactly as those options given by hand do;
    ``mstrack-v2-colour`` builds V2_COLOUR's (ORIENT_T 0, no scale test) and tracks differently;
    ``mstrack-v2-colour-w63`` adds max_window 63 and, in the fixed model, the shared8-colour-w63 build's
    MAX_HALF 31 and COORD_W 11; the former name ``mstrack-v2-joint`` is refused with its new name."""
    from mstrack.eval.evaluate import V2_COLOUR, V2_JOINT, make_tracker
    from mstrack.explore import _base_params
    frames, gt = _scene()
    frames = frames[:12]
    for model in ("float", "fixed"):
        t = make_tracker("mstrack-v2", model)
        assert t.params == TrackerParams(preset="v2", **V2_JOINT) == TrackerParams(preset="v2"), model
        ref = Tracker(model=model, preset="v2", orient_T=64, scale_test=0.05, scale_test_gate=True,
                      loss_rho=0.69, loss_contrast=0.25)
        got = [t.init(frames[0], tuple(gt[0]))] + [t.update(f) for f in frames[1:]]
        want = [ref.init(frames[0], tuple(gt[0]))] + [ref.update(f) for f in frames[1:]]
        assert got == want, model
        c = make_tracker("mstrack-v2-colour", model)
        assert c.params == TrackerParams(preset="v2", **V2_COLOUR) and c.params.orient_T == 0, model
        colour = [c.init(frames[0], tuple(gt[0]))] + [c.update(f) for f in frames[1:]]
        assert colour != got, model
        w = make_tracker("mstrack-v2-colour-w63", model)   # the shared8-colour-w63 build's tracker
        assert w.params == TrackerParams(preset="v2", **V2_COLOUR, max_window=63), model
        if model == "fixed":
            assert (w._impl.fixed.max_half, w._impl.fixed.coord_bits) == (31, 11)
    with pytest.raises(ValueError, match="is now 'mstrack-v2'"):
        make_tracker("mstrack-v2-joint")
    tp, kw = _base_params("mstrack-v2")
    assert tp == TrackerParams(preset="v2", **V2_JOINT) and tp.orient_T == 64
    tp, kw = _base_params("mstrack-v2-colour")
    assert tp == TrackerParams(preset="v2", **V2_COLOUR) and kw["orient_T"] == 0
