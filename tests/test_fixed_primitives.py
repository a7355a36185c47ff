"""Integer primitives and geometry blocks of the fixed-point model against exact definitions."""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import (IntBox, clamp_centre, ms_box_clip, ms_kernel, ms_region, ms_round_centre,
                                  ms_weight)
from mstrack.fixed.primitives import (bits_for, ms_divider, ms_divider_reference, ms_isqrt,
                                      ms_isqrt_reference, round_div_signed)

RNG_SEED = 20261121


# ----------------------------------------------------------------------------- isqrt
def test_isqrt_exhaustive_16_bit():
    x = np.arange(1 << 16, dtype=np.int64)
    got = ms_isqrt(x)
    ref = np.array([ms_isqrt_reference(int(v), 16) for v in x])
    np.testing.assert_array_equal(got, ref)
    np.testing.assert_array_equal(got, [math.isqrt(int(v)) for v in x])


def _edge_values(bits: int) -> list[int]:
    top = (1 << bits) - 1
    r = math.isqrt(top)
    vals = {0, 1, 2, 3, 4, top, top - 1, 1 << (bits - 1), (1 << (bits - 1)) - 1}
    for k in (1, 2, 3, 1000, r - 1, r):
        vals |= {k * k, k * k - 1, k * k + 1, (k + 1) * (k + 1) - 1}
    return sorted(v for v in vals if 0 <= v <= top)


@pytest.mark.parametrize("bits", [40, 60])
def test_isqrt_random_and_edges(bits):
    rng = np.random.default_rng(RNG_SEED + bits)
    vals = _edge_values(bits)
    vals += [int(v) for v in rng.integers(0, 1 << bits, 3000, dtype=np.int64)]
    # log-uniform magnitudes so small inputs are covered too
    vals += [int(v) >> int(s) for v, s in zip(rng.integers(0, 1 << bits, 2000, dtype=np.int64),
                                              rng.integers(0, bits, 2000))]
    got = ms_isqrt(np.array(vals, dtype=np.int64))
    for v, g in zip(vals, got):
        assert g == math.isqrt(v) == ms_isqrt_reference(v, bits), v


def test_isqrt_rejects_out_of_range():
    with pytest.raises(ValueError):
        ms_isqrt(-1)
    with pytest.raises(ValueError):
        ms_isqrt(1 << 62)
    with pytest.raises(ValueError):
        ms_isqrt_reference(1 << 16, 16)
    with pytest.raises(ValueError):
        ms_isqrt_reference(3, 15)


# ----------------------------------------------------------------------------- divider
@pytest.mark.parametrize("q_bits", [1, 2, 3, 4, 6])
def test_divider_exhaustive_small(q_bits):
    n = np.arange(0, 256, dtype=np.int64)
    for d in range(1, 40):
        got = ms_divider(n, np.full_like(n, d), q_bits)
        ref = [ms_divider_reference(int(v), d, q_bits) for v in n]
        np.testing.assert_array_equal(got, ref)
        np.testing.assert_array_equal(got, np.minimum(n // d, (1 << q_bits) - 1))


@pytest.mark.parametrize("q_bits", [9, 17, 24, 32])
def test_divider_random_and_saturation_edges(q_bits):
    rng = np.random.default_rng(RNG_SEED + q_bits)
    d = rng.integers(1, 1 << 20, 2000, dtype=np.int64)
    n = rng.integers(0, 1 << 40, 2000, dtype=np.int64) >> rng.integers(0, 40, 2000)
    top = (1 << q_bits) - 1
    # saturation edges: n = d * 2**q - 1 (largest unsaturated), d * 2**q (first saturated), +-1
    dd = np.array([1, 2, 3, 7, 1000, (1 << 20) - 1], dtype=np.int64)
    edge_n = np.concatenate([(dd << q_bits) - 1, dd << q_bits, (dd << q_bits) + 1, (dd << q_bits) - dd])
    n = np.concatenate([n, edge_n])
    d = np.concatenate([d, np.tile(dd, 4)])
    got = ms_divider(n, d, q_bits)
    for a, b, g in zip(n, d, got):
        a, b = int(a), int(b)
        assert g == min(a // b, top) == ms_divider_reference(a, b, q_bits), (a, b)
    assert ms_divider((3 << q_bits) - 1, 3, q_bits) == top
    assert ms_divider((3 << q_bits) - 4, 3, q_bits) == top - 1


def test_divider_rejects_bad_operands():
    with pytest.raises(ValueError):
        ms_divider(5, 0, 8)
    with pytest.raises(ValueError):
        ms_divider(-5, 3, 8)
    with pytest.raises(ValueError):
        ms_divider_reference(5, 0, 8)


# ----------------------------------------------------------------------------- round_div_signed
@pytest.mark.parametrize("num,den,want", [
    (5, 2, 3), (-5, 2, -3), (3, 2, 2), (-3, 2, -2), (1, 2, 1), (-1, 2, -1),   # halves away from 0
    (1, 3, 0), (2, 3, 1), (-2, 3, -1), (-1, 3, 0), (0, 7, 0), (7, 7, 1), (-7, 7, -1),
    (4, 8, 1), (3, 8, 0), (-4, 8, -1), (-3, 8, 0), (11, 4, 3), (-10, 4, -3), (-9, 4, -2),
])
def test_round_div_signed_cases(num, den, want):
    assert int(round_div_signed(num, den, 16)) == want


def test_round_div_signed_random_vs_fraction():
    rng = np.random.default_rng(RNG_SEED)
    num = rng.integers(-(1 << 30), 1 << 30, 5000, dtype=np.int64)
    den = rng.integers(1, 1 << 16, 5000, dtype=np.int64)
    got = round_div_signed(num, den, 40)
    for a, b, g in zip(num, den, got):
        f = Fraction(abs(int(a)), int(b))
        mag = math.floor(f + Fraction(1, 2))
        assert g == (-mag if a < 0 else mag)


def test_round_div_signed_saturates_symmetrically():
    assert int(round_div_signed(1000, 1, 4)) == 15
    assert int(round_div_signed(-1000, 1, 4)) == -15
    assert int(round_div_signed(31, 2, 4)) == 15  # 15.5 -> 16 saturates to 15


# ----------------------------------------------------------------------------- weight
def _weight_exact(q: int, h: int, fp: FixedParams) -> int:
    if h == 0:
        return 0
    ratio = Fraction(q, h) * (1 << (2 * fp.weight_frac))
    w = math.isqrt(math.floor(ratio))   # floor(sqrt(floor(x))) == floor(sqrt(x))
    return min(w, (1 << (fp.weight_int + fp.weight_frac)) - 1)


@pytest.mark.parametrize("fp", [FixedParams(), FixedParams(weight_frac=6), FixedParams(weight_frac=8),
                                FixedParams(weight_int=2, weight_frac=3)])
def test_weight_vs_exact(fp):
    rng = np.random.default_rng(RNG_SEED)
    Q = rng.integers(0, 5000, 4000, dtype=np.int64)
    H = rng.integers(0, 5000, 4000, dtype=np.int64)
    Q[:20] = 0                          # Q = 0
    H[20:40] = 0                        # H = 0 -> weight 0
    Q[40:60] = 16129                    # 127 * 127: saturation for small H
    H[40:60] = np.arange(1, 21)
    H[60:80] = Q[60:80]                 # ratio 1 -> exactly 2**WF
    got = ms_weight(Q, H, fp)
    want = [_weight_exact(int(q), int(h), fp) for q, h in zip(Q, H)]
    np.testing.assert_array_equal(got, want)
    assert (got[20:40] == 0).all() and (got[:20] == 0).all()
    assert (got[60:80][H[60:80] > 0] == 1 << fp.weight_frac).all()
    assert got.max() <= (1 << (fp.weight_int + fp.weight_frac)) - 1
    assert (got[40:45] == (1 << (fp.weight_int + fp.weight_frac)) - 1).all()


# ----------------------------------------------------------------------------- kernel
def test_kernel_inside_vs_exact_rational():
    """Inside test == (2dx/w)^2 + (2dy/h)^2 < 1 (Fractions) for every w, h in 3..40."""
    for w in range(3, 41):
        for h in range(3, 41):
            ker = ms_kernel(w, h, "flat", 8)
            ex, ey = ker.ex, ker.ey
            # every pixel with (2dx/w)^2 + (2dy/h)^2 < 1 lies in the (2ex+1) x (2ey+1) window
            assert Fraction(2 * (ex + 1), w) ** 2 >= 1 and Fraction(2 * (ey + 1), h) ** 2 >= 1
            dxs = np.arange(-ex, ex + 1)
            exact = np.zeros(ker.inside.shape, bool)
            for iy, dy in enumerate(range(-ey, ey + 1)):
                # row dy: inside <=> dx^2 < (w/2)^2 (1 - (2dy/h)^2), an exact rational bound
                limit = Fraction(w * w, 4) * (1 - Fraction(2 * dy, h) ** 2)
                exact[iy] = dxs * dxs < math.ceil(limit)  # integer n < limit <=> n < ceil(limit)
            np.testing.assert_array_equal(ker.inside, exact, err_msg=f"w={w} h={h}")
            assert ker.K == int(exact.sum())


@pytest.mark.parametrize("kb", [4, 8, 12])
def test_epanechnikov_values(kb):
    """k >= 1 inside, 0 outside, and 2**KB (1 - d2) <= k < 2**KB (1 - d2) + 2 (two floored tables).

    Checked exactly in integers scaled by w^2 h^2 (the common denominator of d2).
    """
    for w in range(3, 41):
        for h in range(3, 41):
            ker = ms_kernel(w, h, "epanechnikov", kb)
            k = ker.k[ker.inside]
            assert (k >= 1).all() and (k <= 1 << kb).all()
            assert (ker.k[~ker.inside] == 0).all()
            assert ker.k[ker.ey, ker.ex] == 1 << kb            # centre
            dy, dx = np.mgrid[-ker.ey:ker.ey + 1, -ker.ex:ker.ex + 1].astype(object)
            den = w * w * h * h
            exact_num = (den - 4 * dx * dx * h * h - 4 * dy * dy * w * w) * (1 << kb)  # 2**KB (1-d2) * den
            kk = ker.k.astype(object) * den
            m = ker.inside
            assert (exact_num[m] <= kk[m]).all() and (kk[m] < exact_num[m] + 2 * den).all(), (w, h)


# ----------------------------------------------------------------------------- box clip
@pytest.mark.parametrize("args,want,clipped", [
    ((10, 10, 20, 15), IntBox(10, 10, 20, 15), False),
    ((0, 10, 20, 15), IntBox(1, 10, 19, 15), True),          # 1-px border dropped
    ((-10, -10, 20, 15), IntBox(1, 1, 9, 4), True),
    ((90, 70, 20, 15), IntBox(90, 70, 9, 9), True),           # right/bottom: columns .. W-2
    ((1, 1, 98, 78), IntBox(1, 1, 98, 78), False),
    ((0, 0, 100, 80), IntBox(1, 1, 98, 78), True),
    ((-50, -50, 300, 300), IntBox(1, 1, 98, 78), True),
    ((96, 10, 20, 15), IntBox(96, 10, 3, 15), True),          # exactly 3 px left
])
def test_box_clip_cases(args, want, clipped):
    assert ms_box_clip(*args, 100, 80, 63) == (want, clipped)


@pytest.mark.parametrize("args", [(97, 10, 20, 15), (10, 77, 20, 15), (200, 10, 5, 5), (-20, 10, 20, 5),
                                  (10, 10, 2, 15), (10, 10, 15, 2), (0, 0, 1, 1)])
def test_box_clip_rejects(args):
    assert ms_box_clip(*args, 100, 80, 63) == (None, True)


def test_box_clip_shrinks_to_max_window_about_centre():
    box, clipped = ms_box_clip(10, 20, 100, 51, 400, 300, 20)   # max extent 41
    assert clipped and box == IntBox(10 + (100 - 41) // 2, 20 + (51 - 41) // 2, 41, 41)


# ----------------------------------------------------------------------------- region
@pytest.mark.parametrize("size", [(40, 30), (97, 64), (320, 240)])
@pytest.mark.parametrize("ext", [(1, 1), (5, 3), (12, 9)])
@pytest.mark.parametrize("margin", [0, 4, 32])
def test_region_inside_interior_at_every_border(size, ext, margin):
    fw, fh = size
    ex, ey = ext
    fp = FixedParams(margin=margin)
    cf = fp.centre_frac
    xs = list(range(-3, fw + 3)) if fw < 100 else list(range(-3, 40)) + list(range(fw - 40, fw + 3))
    ys = list(range(-3, fh + 3)) if fh < 100 else list(range(-3, 40)) + list(range(fh - 40, fh + 3))
    for cx in xs:
        for cy in (ys[0], ys[len(ys) // 2], ys[-1], 0, fh - 1):
            for frac in (0, 1 << (cf - 1), (1 << cf) - 1):
                c8 = ((cx << cf) + frac if cx >= 0 else 0, (cy << cf) + frac if cy >= 0 else 0)
                reg = ms_region(c8, ex, ey, fw, fh, fp)
                assert reg.x >= 1 and reg.y >= 1
                assert reg.x + reg.w <= fw - 1 and reg.y + reg.h <= fh - 1
                assert reg.w == min(2 * ex + 2 * margin + 1, fw - 2)
                assert reg.lo[0] <= reg.hi[0] and reg.lo[1] <= reg.hi[1]
                c = clamp_centre(c8, reg, cf)
                wx, wy = ms_round_centre(c[0], cf), ms_round_centre(c[1], cf)
                assert reg.x <= wx - ex and wx + ex <= reg.x + reg.w - 1
                assert reg.y <= wy - ey and wy + ey <= reg.y + reg.h - 1


def test_region_centred_when_room():
    fp = FixedParams(margin=8)
    reg = ms_region((100 << 8, 80 << 8), 5, 4, 320, 240, fp)
    assert (reg.x, reg.w, reg.y, reg.h) == (100 - 13, 27, 80 - 12, 25)


def test_bits_for():
    assert [bits_for(v) for v in (0, 1, 2, 3, 255, 256)] == [1, 1, 2, 2, 8, 9]
