"""Blocks of tracker v2 in integers, one function per (future) RTL entity of the same name.

docs/fixed_point.md ("Tracker v2") gives format, range and rounding of each
signal; docs/algorithm.md ("Tracker v2") the float algorithm these follow.
Ratios and fractions are Q.16 (``ONE = 2**16`` is 1.0) unless said otherwise.
Sizes are Q.8 px (``w8 = round(w * 256)``).  All shifts of signed values are
arithmetic (floor).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..track.params import TrackerParams
from .blocks import Region, ms_kernel, ms_region
from .formats import FixedParams
from .primitives import ms_divider, ms_isqrt

ONE = 1 << 16          # Q.16 one
SIZE_FRAC = 8          # box sizes w8, h8 are Q.8 px
BG_FRAC = 8            # CBWH factors v_u are Q.8 (2**8 = 1)
QN_BITS = 16           # the normalised model Qn sums to about 2**16
PAD_FRAC = 4           # pad, bg_ring, search_step are multiples of 1/16
MAX_DECIMATION = 8
MARGIN_MAX = 255       # largest region margin (MARGIN + the search offset while lost)


def q16(x: float) -> int:
    """A parameter in [0, 1+] as Q.16, rounded to nearest."""
    return int(round(x * ONE))


def sixteenths(x: float, name: str) -> int:
    """A parameter that must be a multiple of 1/16 (pad, bg_ring, search_step), as an integer."""
    n = int(round(x * 16))
    if abs(n - x * 16) > 1e-9:
        raise ValueError(f"{name} = {x} is not a multiple of 1/16 (the fixed-point model needs it)")
    return n


def rate_shift(rate: float, name: str = "ref_rate") -> int:
    """ref_rate = 2**-k -> k (the running references update with a shift)."""
    k = int(round(-np.log2(rate))) if rate > 0 else 0
    if rate <= 0 or abs(2.0 ** -k - rate) > 1e-12:
        raise ValueError(f"{name} = {rate} must be a power of two 2**-k for the fixed-point model")
    return k


# ----------------------------------------------------------------------------- geometry
def ms_decimation(w8: int, h8: int, pad16: int, max_window: int) -> int:
    """D: the smallest power of two (<= 8) with (1 + pad) max(w, h) / D <= max_window.

    Exact: (16 + pad16) max(w8, h8) <= max_window D 2**(4 + 8).
    """
    d = 1
    m = (16 + pad16) * max(w8, h8)
    while m > max_window * d << (PAD_FRAC + SIZE_FRAC) and d < MAX_DECIMATION:
        d *= 2
    return d


def ms_window_size(s8: int, pad16: int, d: int, limit: int) -> int:
    """Window diameter in decimated px: round((1 + pad) s / D) (half up), in 3 .. limit."""
    sh = PAD_FRAC + SIZE_FRAC + (d.bit_length() - 1)
    n = ((16 + pad16) * s8 + (1 << (sh - 1))) >> sh
    return max(3, min(n, limit))


def ms_box_size(s8: int, d: int, limit: int) -> int:
    """Box diameter in decimated px: round(s / D) (half up), in 3 .. limit."""
    sh = SIZE_FRAC + (d.bit_length() - 1)
    return max(3, min((s8 + (1 << (sh - 1))) >> sh, limit))


# ----------------------------------------------------------------------------- target model
@dataclass
class ModelV2:
    """Target model of v2 (per target: what a multi-target core keeps per target).

    Qn: background-weighted histogram normalised to about 2**16 (sum of Q v,
    scaled); T: 1 for target-coloured bins (q_u > o_u); Q, O: the raw box and
    ring counts (for traces and tests).
    """

    Qn: np.ndarray
    T: np.ndarray
    Q: np.ndarray
    O: np.ndarray


def ms_bg_model(bins: np.ndarray, cx: int, cy: int, wb: int, hb: int, ring16: int,
                n_bins: int, bg_frac: int = BG_FRAC) -> ModelV2:
    """CBWH target model of the box of diameters (wb, hb) decimated px centred on pixel (cx, cy).

    Box: the pixels of the ellipse (2dx/wb)^2 + (2dy/hb)^2 < 1 (exact integer
    test of :class:`ms_kernel`, flat) -> counts Q.  Ring: the pixels of the
    rectangle grown by g = (ring16 * n) >> 4 on each side (n = wb, hb), clipped
    to the image, that lie outside the box's rectangle (|dx| > ex or
    |dy| > ey) -> counts O.  o* = the smallest non-zero O;
    v_u = min(floor(o* 2**BF / O_u), 2**BF) (2**BF where O_u = 0; BF = ``bg_frac``,
    FixedParams.bg_frac, default 8: a ring colour more than 2**BF times as frequent as the rarest
    gets v_u = 0);
    Qn_u = floor(Q_u v_u 2**16 / sum(Q v));  T_u = 1 where Q_u sum(O) > O_u sum(Q)
    (q_u > o_u, exact); without any ring pixel: v = 1 and T_u = (Q_u > 0).
    When sum(Q v) = 0 (every colour of the box more than 256x as frequent in the ring as the
    rarest ring colour, so every v_u = 0), Qn = 0: the model matches nothing and the first
    frame reports the target lost (rtl/ms_bg_model.vhd does the same).
    """
    height, width = bins.shape
    ker = ms_kernel(wb, hb, "flat", 8)
    ex, ey = ker.ex, ker.ey
    box = bins[cy - ey: cy + ey + 1, cx - ex: cx + ex + 1]
    Q = np.bincount(box[ker.inside], minlength=n_bins).astype(np.int64)
    gx, gy = (ring16 * wb) >> PAD_FRAC, (ring16 * hb) >> PAD_FRAC
    x0, x1 = max(0, cx - ex - gx), min(width - 1, cx + ex + gx)
    y0, y1 = max(0, cy - ey - gy), min(height - 1, cy + ey + gy)
    yy, xx = np.mgrid[y0:y1 + 1, x0:x1 + 1]
    outside = (np.abs(xx - cx) > ex) | (np.abs(yy - cy) > ey)
    O = np.bincount(bins[yy[outside], xx[outside]], minlength=n_bins).astype(np.int64)
    nq, no = int(Q.sum()), int(O.sum())
    one_v = 1 << bg_frac
    if no == 0:
        v = np.full(n_bins, one_v, np.int64)
        T = (Q > 0).astype(np.int64)
    else:
        omin = int(O[O > 0].min())
        v = np.full(n_bins, one_v, np.int64)
        nz = O > 0
        v[nz] = np.minimum(ms_divider(omin << bg_frac, O[nz], bg_frac + 1), one_v)
        T = (Q * no > O * nq).astype(np.int64)
    qv = Q * v
    tot = int(qv.sum())
    Qn = np.zeros(n_bins, np.int64)
    nz = qv > 0
    if tot > 0:  # tot = 0: every box colour has v = 0 (> 256x more frequent in the ring): Qn = 0
        Qn[nz] = ms_divider(qv[nz] << QN_BITS, tot, QN_BITS + 1)
    return ModelV2(Qn=Qn, T=T, Q=Q, O=O)


def ms_model_scale(Qn: np.ndarray, K: int, frac: int = 0) -> np.ndarray:
    """The model at a window of K pixels: Qw_u = (Qn_u K) >> (16 - frac) (so sum Qw ~ K 2**frac,
    like H 2**frac); ``frac``: FixedParams.model_frac (default 0)."""
    return (Qn * K) >> (QN_BITS - frac)


# ----------------------------------------------------------------------------- per-pass statistics
@dataclass
class TargetStats:
    """Target-coloured pixel statistics of one window (accumulated in the pixel pass).

    nt: count of pixels with T = 1; st2: their sum of d2q = KA[|dx|] + KB[|dy|]
    (d2 in Q.KB); n_in / nt_in: pixels / target-coloured pixels of the inner
    window d2q (16 + pad16)^2 < 2**(KB + 8) (the box inside the padded window).
    """

    nt: int
    st2: int
    n_in: int
    nt_in: int


def ms_target_stats(bins: np.ndarray, T: np.ndarray, win: tuple[int, int], ker: ms_kernel, kb: int,
                    pad16: int) -> TargetStats:
    """Statistics of the window at integer centre ``win`` (within ``bins``' coordinates)."""
    ex, ey = ker.ex, ker.ey
    b = bins[win[1] - ey: win[1] + ey + 1, win[0] - ex: win[0] + ex + 1][ker.inside]
    adx = np.abs(ker._dx_in)
    ady = np.abs(ker._dy_in)
    d2q = ker.KA[adx] + ker.KB[ady]
    t = T[b]
    inner = d2q * (16 + pad16) ** 2 < (1 << (kb + 8))
    return TargetStats(nt=int(t.sum()), st2=int((t * d2q).sum()), n_in=int(inner.sum()),
                       nt_in=int(t[inner].sum()))


# ----------------------------------------------------------------------------- confidence, scale
def ms_share(st: TargetStats) -> int:
    """share = floor(nt_in 2**16 / n_in) (Q.16; 0 when n_in = 0)."""
    return int(ms_divider(st.nt_in << 16, st.n_in, 17)) if st.n_in else 0


def ms_ring_share(st: TargetStats, K: int) -> int:
    """ring_share = floor((nt - nt_in) 2**16 / (K - n_in)) (Q.16; 0 when K <= n_in).

    The share of target-coloured pixels in the window's ring around the box
    (the K - n_in window pixels outside the inner window; flat kernel: K is the
    window's pixel count).  nt - nt_in <= K - n_in, so the result is in
    0 .. 2**16 (17 bits); dividend < 2**(16 + 14) for K < 2**14.
    """
    den = K - st.n_in
    return int(ms_divider((st.nt - st.nt_in) << 16, den, 17)) if den > 0 else 0


def ms_region_v2(c8d: tuple[int, int], ex: int, ey: int, ox: int, oy: int, lost: bool, frame_w: int,
                 frame_h: int, fp: FixedParams, margin_max: int = MARGIN_MAX) -> tuple[Region, int]:
    """Tracker v2's search region and its margin: :func:`ms_region` around the decimated centre
    ``c8d`` (Q.CF) for the window half extents ``ex``, ``ey`` on the decimated ``frame_w`` x
    ``frame_h`` frame, with the margin MARGIN, + max(ox, oy) (the search offsets) while lost, at most
    ``margin_max`` (MARGIN_MAX).  Returns (region, margin)."""
    margin = min(fp.margin + (max(ox, oy) if lost else 0), margin_max)
    return ms_region(c8d, ex, ey, frame_w, frame_h, fp.with_(margin=margin)), margin


def ms_lost_decimation(d0: int, lost_n: int, widen: int) -> int:
    """The decimation after ``lost_n`` consecutive lost frames: d0 while tracking; 2 d0, shifted
    left once more every ``widen`` lost frames (search_widen; 0: never), at most max(16, 2 d0).
    A lost-frame counter, one compare per frame (widen a power of two: a shift)."""
    if lost_n <= 0:
        return d0
    k = 1 + ((lost_n - 1) // widen if widen > 0 else 0)
    return max(min(d0 << k, 16), 2 * d0)


def ms_loss_filter(s: int, x: int, k: int) -> int:
    """One step of the loss flag's smoothing: s + ((x - s) >> k) (arithmetic shift = floor).

    Used for rho (unsigned Q1.16, 0 .. 2**16) and for contrast = share - ring_share
    (signed Q1.16, -2**16 .. 2**16); k = log2(1 / loss_smooth) (default 1).  The
    result lies between s and x, so it keeps the range of its inputs (18 bits signed).
    """
    return s + ((x - s) >> k)


def ms_loss_flag(rho_s: int, rho0: int, con_s: int, share: int, loss_rho: int, loss_contrast: int) -> bool:
    """The loss flag: share = 0  or  rho_s = 0  or  (rho_s 2**16 < loss_rho rho0  and  con_s < loss_contrast).

    rho_s (smoothed rho) and rho0 (rho at init): unsigned Q1.16 in 0 .. 2**16;
    con_s (smoothed share - ring_share): signed Q1.16 in -2**16 .. 2**16;
    loss_rho (unsigned Q1.16, 0 .. 2**17) and loss_contrast (signed Q1.16,
    -2**16 .. 2**16) are the rounded parameters.  Exact comparisons: an 18 x 17 bit
    product (< 2**34) against rho_s 2**16 (< 2**33), an 18-bit signed compare, and a
    zero test of this frame's share (Q1.16; 0 = no target-coloured pixel in the box) and of rho_s
    (0 = the model matches nothing, e.g. a degenerate init model with Qn = 0, where rho0 = 0 too).
    """
    return share == 0 or rho_s == 0 or (rho_s << 16 < loss_rho * rho0 and con_s < loss_contrast)


def ms_loss_jump(step: tuple[int, int], prev: tuple[int, int], w8: int, h8: int, jump16: int, cf: int) -> bool:
    """The loss flag's motion test: the centre's step against the previous frame's step,
    |sx - px| + |sy - py| > jump16 / 16 x (w + h) / 2, exact in integers:

        (|sx - px| + |sy - py|) 2**(SIZE_FRAC + 5)  >  jump16 (w8 + h8) 2**cf.

    step, prev: the frame's and the previous frame's centre steps, signed Q.cf frame px (frames up
    to 4096 px: |step| < 2**(12 + cf), 14 + cf bits signed; the L1 distance < 2**(14 + cf)); w8, h8:
    the box before the frame's resize, unsigned Q.8 px (w8 + h8 < 2**21); jump16 = loss_jump in
    sixteenths (unsigned, 0 .. 128: 8 bits).  Left side < 2**(27 + cf), right side < 2**(29 + cf):
    one 8 x 21 bit product, two shifts, one unsigned compare of 29 + cf bits (37 at centre_frac 8).
    jump16 = 0: off (never true).
    """
    if jump16 <= 0:
        return False
    j = abs(step[0] - prev[0]) + abs(step[1] - prev[1])
    return j << (SIZE_FRAC + 5) > (jump16 * (w8 + h8)) << cf


def ms_loss_latch(latch: bool, jump: bool, rho_s: int, ref: int, loss_stay: int) -> bool:
    """The loss flag's motion latch: set by a jump (:func:`ms_loss_jump`), kept while
    rho_s 2**16 < loss_stay ref (rho_s, ref unsigned Q1.16; loss_stay unsigned Q1.16, 0 .. 2**17:
    the same 18 x 17 bit product and compare as :func:`ms_loss_flag`).  One state bit per target."""
    return jump or (latch and rho_s << 16 < loss_stay * ref)


def ms_spread(st: TargetStats) -> int:
    """spread = floor(st2 2**16 / nt): mean d2q of the target-coloured pixels, Q.(KB + 16); 0 if nt = 0."""
    return int(ms_divider(st.st2 << 16, st.nt, 40)) if st.nt else 0


def ms_confidence(rho: int, share: int, rho_ref: int, share_ref: int) -> int:
    """conf = (min(1, rho / rho_ref) min(1, share / share_ref)) in Q.16, each ratio floored."""
    def ratio(x: int, ref: int) -> int:
        return min(ONE, int(ms_divider(x << 16, ref, 34))) if ref > 0 else 0
    return (ratio(rho, rho_ref) * ratio(share, share_ref)) >> 16


def ms_ref_update(ref: int, x: int, k: int) -> int:
    """Running reference: ref + ((x - ref) >> k) (arithmetic shift = floor)."""
    return ref + ((x - ref) >> k)


def ms_scale(spread: int, spread_ref: int, w8: int, w0_8: int, tp: TrackerParams) -> int:
    """Scale factor s (Q.16) of one frame (float: FloatTrackerV2.update).

    est = isqrt(floor(spread 2**16 / spread_ref) 2**16) (Q.16, floored), clamped to
    [1 - step, 1 + step]; s = 1 + ((gain (est - 1)) >> 16) - ((reg (w / w0 - 1)) >> 16)
    with w / w0 = floor(w8 2**16 / w0_8); clamped to [1 - step, 1 + step].  gain,
    reg, step in Q.16 (rounded).
    """
    lo, hi = ONE - q16(tp.scale_step), ONE + q16(tp.scale_step)
    r = int(ms_divider(spread << 16, spread_ref, 40))
    est = min(max(int(ms_isqrt(r << 16)), lo), hi)
    wr = int(ms_divider(w8 << 16, w0_8, 40))
    s = ONE + ((q16(tp.scale_gain) * (est - ONE)) >> 16) - ((q16(tp.scale_reg) * (wr - ONE)) >> 16)
    return min(max(s, lo), hi)


def ms_resize(s8: int, s: int, frame_size: int) -> int:
    """New size (Q.8): (s8 s) >> 16, clamped to [3, frame_size] px."""
    return min(max((s8 * s) >> 16, 3 << SIZE_FRAC), frame_size << SIZE_FRAC)


# ----------------------------------------------------------------------------- joint bins, gated scale test
# docs/results_v2_mean.md: joint colour x orientation bins and the gated scale test, tracker v2's
# defaults (TrackerParams.orient_T, scale_test, scale_test_gate; docs/fixed_point.md
# "The joint bins and the gated scale test").
ORIENT_FLAT = 8  # the orientation bin of pixels with |Gx| + |Gy| < T (and of the frame's 1-px border)


def ms_orient_bin(grey: np.ndarray, T: int) -> np.ndarray:
    """Orientation bin of every pixel of ``grey`` (H, W) from the 3x3 Sobel (ms_sobel's Gx, Gy):
    4 [Gx < 0] + 2 [Gy < 0] + [|Gy| > |Gx|] where |Gx| + |Gy| >= T, else 8; 8 on the 1-px frame
    border (no Sobel there).  Gx, Gy 11-bit signed, |Gx| + |Gy| 11 bits (0..2040); T 11 bits.
    Two sign bits, one 10-bit compare, one 11-bit compare.  (H, W) int64 in 0..8."""
    g = grey.astype(np.int64)
    out = np.full(g.shape, ORIENT_FLAT, np.int64)
    if g.shape[0] < 3 or g.shape[1] < 3:
        return out
    gx = (g[:-2, 2:] + 2 * g[1:-1, 2:] + g[2:, 2:]) - (g[:-2, :-2] + 2 * g[1:-1, :-2] + g[2:, :-2])
    gy = (g[2:, :-2] + 2 * g[2:, 1:-1] + g[2:, 2:]) - (g[:-2, :-2] + 2 * g[:-2, 1:-1] + g[:-2, 2:])
    ax, ay = np.abs(gx), np.abs(gy)
    octant = 4 * (gx < 0) + 2 * (gy < 0) + (ay > ax)
    out[1:-1, 1:-1] = np.where(ax + ay >= T, octant, ORIENT_FLAT)
    return out


def ms_joint_bin(colour: np.ndarray, orient: np.ndarray) -> np.ndarray:
    """Joint bin = 9 colour + orient ((colour << 3) + colour + orient: one adder), < 9 2**(3b)."""
    return (colour << 3) + colour + orient


def ms_scale_test_size(s8: int, d256: int, up: bool) -> int:
    """Size (Q.8) of a scale-test window: (s8 (256 +- d256) + 128) >> 8 (round half up)."""
    return (s8 * (256 + d256 if up else 256 - d256) + 128) >> 8


def ms_scale_test(rho: int, rho_lo: int | None, rho_hi: int | None, margin: int = 0) -> int:
    """The scale test's verdict from rho at the window x1, x(1 - d), x(1 + d) (Q.16; None: that
    window did not fit the captured region, it never wins): -1 / 0 / +1, the largest of rho,
    rho_lo - margin, rho_hi - margin, ties to the earlier of (1, 1 - d, 1 + d).  ``margin``:
    round(scale_test_margin 2**16) (default 0: two 17-bit compares; else two subtractions more)."""
    best, v = rho, 0
    if rho_lo is not None and rho_lo - margin > best:
        best, v = rho_lo - margin, -1
    if rho_hi is not None and rho_hi - margin > best:
        v = 1
    return v


def ms_scale_gate(spread: int, spread_ref: int, verdict: int) -> int:
    """The spread that ms_scale gets: ``spread`` when the rho test moves the same way
    (spread > spread_ref and verdict +1, or spread < spread_ref and verdict -1), else spread_ref
    (est = 1 exactly in ms_scale: floor(r 2**16 / r) = 2**16, isqrt(2**32) = 2**16).  One
    40-bit compare."""
    if (spread > spread_ref and verdict > 0) or (spread < spread_ref and verdict < 0):
        return spread
    return spread_ref


# ----------------------------------------------------------------------------- shrink guard, guarded model update
# Experimental options, off by default (TrackerParams.scale_ring_guard, model_rate; docs/fixed_point.md
# "The shrink guard and the guarded model update"); core v2 has no RTL for them.
def ms_ring_guard(share: int, ring: int, guard16: int) -> bool:
    """The shrink guard: True (no shrinking step) when ring_share >= guard share, as
    ring 2**16 >= guard16 share (ring, share Q.16 <= 2**16, 17 bits; guard16 = round(scale_ring_guard
    2**16), 19 bits: one 17 x 19-bit product and one 36-bit compare); False when guard16 = 0 (off)."""
    return guard16 > 0 and (ring << 16) >= guard16 * share


def ms_no_shrink(s: int, veto: bool) -> int:
    """The scale factor (Q.16) after the shrink guard: max(s, 2**16) when vetoed, else s."""
    return max(s, ONE) if veto else s


def ms_model_update(Qn: np.ndarray, Qn_new: np.ndarray, k: int) -> np.ndarray:
    """The guarded model update's blend, per bin: Qn_u + ((Qn_new_u - Qn_u) >> k) (arithmetic
    shift = floor; Qn, Qn_new 17-bit unsigned, the difference 18-bit signed; the result stays in
    [min, max] of the two, so within 17 bits).  k = rate_shift(model_rate)."""
    return Qn + ((Qn_new - Qn) >> k)


def ms_chroma_bin(frame: np.ndarray, bits: int, k: int) -> np.ndarray:
    """Normalised-chromaticity bin (TrackerParams.chroma_bins = k, 1..bits; off by default): S = R + G + B
    (10 bits), bin = ((S >> (10 - k)) << 2b) | (floor(2**b R / (S + 1)) << b) | floor(2**b G / (S + 1)).
    Each quotient is b bits (R <= S, so 2**b R / (S + 1) < 2**b): a (8 + b)-bit by 10-bit divider,
    or 2**b - 1 compares of 2**b R with j (S + 1), per channel; the intensity is S's top k bits.
    (H, W) int64, < 2**(2b + k) <= 2**(3b)."""
    f = frame.astype(np.int64)
    s = f[..., 0] + f[..., 1] + f[..., 2]
    return ((s >> (10 - k)) << (2 * bits)) | (((f[..., 2] << bits) // (s + 1)) << bits) | ((f[..., 1] << bits) // (s + 1))


def ms_slot_capture(bins: np.ndarray, d: int, reg_x: int, reg_y: int, reg_w: int, reg_h: int) -> np.ndarray:
    """One target's slot of the shared-engine multi-target core (rtl/ms_slot_capture.vhd): the
    pixels of the decimated image ``bins[::d, ::d]`` inside the region (decimated px), (reg_h, reg_w):
    ``FixedTrackerV2._capture`` of that target's decimation and region.  The RTL writes region pixel
    (rx, ry) to bank ``rx % LANES``, word ``ry * STRIDE + rx // LANES`` (:func:`slot_words`)."""
    dec = bins[::d, ::d]
    if not (0 <= reg_x and 0 <= reg_y and reg_w >= 1 and reg_h >= 1
            and reg_x + reg_w <= dec.shape[1] and reg_y + reg_h <= dec.shape[0]):
        raise ValueError(f"region ({reg_x}, {reg_y}, {reg_w}, {reg_h}) is not inside the {dec.shape[1]}x{dec.shape[0]} "
                         f"decimated image (d = {d})")
    return dec[reg_y: reg_y + reg_h, reg_x: reg_x + reg_w].copy()


def ms_slot_scan(region: np.ndarray) -> list[tuple[int, int, int]]:
    """The init job's pixel stream (rtl/ms_slot_scan.vhd): every pixel of a rectangle captured in a slot,
    ``(rx, ry, value)`` in raster order with coordinates relative to the rectangle; ``ms_bg_model``
    counts them (``mstrack.fixed.multi_capacity.init_capture``)."""
    h, w = region.shape
    return [(rx, ry, int(region[ry, rx])) for ry in range(h) for rx in range(w)]


def slot_words(region: np.ndarray, lanes: int, stride: int) -> dict[tuple[int, int], int]:
    """The slot's RAM words of a captured region: ``{(bank, word): value}`` (ms_region_capture's layout)."""
    h, w = region.shape
    return {(rx % lanes, ry * stride + rx // lanes): int(region[ry, rx]) for ry in range(h) for rx in range(w)}
