"""Tracker v2, float reference (docs/algorithm.md, "Tracker v2").

Mean shift on a background-weighted colour model (CBWH, Ning et al. 2012),
in a window padded around the target, with

* scale from the spread of the target-coloured pixels (calibrated on the
  init frame, bounded step, pulled toward the init size),
* decimation (every D-th pixel, D a power of two) for targets larger than
  the window memory,
* a confidence = min(1, rho / rho_ref) * min(1, share / share_ref) from the
  Bhattacharyya coefficient and the share of target-coloured pixels in the
  box, against their running references,
* a search state from the confidence (below a threshold: nothing is
  learnt, and a wider search from several start points runs next frame),
* a loss flag, the reported status (``TrackResult.ok`` False): rho below
  loss_rho x rho at init and the target colours' share in the box less
  their share in the window's ring below loss_contrast.

Every step is a pass over the window's pixels or over the bins, so the
fixed-point model and the RTL can do the same in integers.

Coordinates are pixel-index (pixel (i, j) at (i, j)).  With decimation D the
tracker works on the image of the pixels with x % D == 0 and y % D == 0
(``bins[::D, ::D]``), in which pixel (i, j) is frame pixel (D i, D j).  The
window of half-sizes (hx, hy) around (cx, cy) holds the pixels with
d2 = ((x - cx) / hx)^2 + ((y - cy) / hy)^2 < 1.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import cv2
import numpy as np

from . import float_model as _fm
from .features import _GREY_W, chroma_bins, colour_bins
from .frames import check_frame, clip_box
from .numba_kernels import (_SHIFT2_BAND, _jit, _jit_inline, _nb_columns, _nb_normalise, _nb_run, _nb_scan, _nb_sum,
                            _nb_sum3, _prefetch)
from .params import TrackerParams
from .types import Box, Status, TrackResult, box_centre_index, box_from_centre_index


@dataclass
class PassV2:
    """Sums of one pass over a window (one pixel pass + one bin pass in the hardware).

    rho: Bhattacharyya coefficient of the window histogram p against q;
    sw, swx, swy: sums of the mean-shift weights sqrt(q_u / p_u), and of the
    weights times x, y; nt, st2: count and sum of d2 of the target-coloured
    pixels (t_u = 1) in the window; n_in, nt_in: pixels, and target-coloured
    pixels, in the inner window d2 < 1 / (1 + pad)^2 (the box itself); n: pixels
    in the window.
    """

    rho: float
    sw: float
    swx: float
    swy: float
    nt: float
    st2: float
    n_in: int
    nt_in: int
    n: int

    @property
    def share(self) -> float:
        """Share of target-coloured pixels in the box (inner window)."""
        return self.nt_in / self.n_in if self.n_in else 0.0

    @property
    def ring_share(self) -> float:
        """Share of target-coloured pixels in the window's ring around the box (0 if none)."""
        return (self.nt - self.nt_in) / (self.n - self.n_in) if self.n > self.n_in else 0.0

    @property
    def spread(self) -> float:
        """Mean d2 of the target-coloured pixels in the window (0 if none)."""
        return self.st2 / self.nt if self.nt else 0.0


def window_pixels(cx: float, cy: float, hx: float, hy: float, width: int,
                  height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Columns, rows (int) and d2 of the pixels with d2 < 1 inside a width x height image."""
    x0 = max(0, math.ceil(cx - hx))
    x1 = min(width - 1, math.floor(cx + hx))
    y0 = max(0, math.ceil(cy - hy))
    y1 = min(height - 1, math.floor(cy + hy))
    xs = np.arange(x0, x1 + 1, dtype=np.float64)
    ys = np.arange(y0, y1 + 1, dtype=np.float64)
    d2 = ((xs[None, :] - cx) / hx) ** 2 + ((ys[:, None] - cy) / hy) ** 2
    yy, xx = np.nonzero(d2 < 1.0)
    return (xx + x0).astype(np.intp), (yy + y0).astype(np.intp), d2[yy, xx]


def background_model(bins: np.ndarray, n_bins: int, cx: float, cy: float, w: float, h: float,
                     ring: float, kernel: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Target model of a w x h box at (cx, cy): (q, q', t).

    q: kernel-weighted histogram of the box ellipse (sums to 1).  o: histogram
    of the background ring, the pixels of the box grown by ``ring`` x its size
    on each side that are outside the box.  CBWH (Ning et al. 2012):
    v_u = min(o* / o_u, 1), o* the smallest non-zero o_u (v_u = 1 where o_u = 0);
    q'_u = v_u q_u / sum(v q).  t_u = 1 where q_u > o_u (target-coloured bin).
    """
    height, width = bins.shape
    xs, ys, d2 = window_pixels(cx, cy, w / 2.0, h / 2.0, width, height)
    k = np.ones_like(d2) if kernel == "flat" else 1.0 - d2
    q = np.bincount(bins[ys, xs], weights=k, minlength=n_bins)
    q /= q.sum()  # type: ignore[misc]
    gx, gy = ring * w, ring * h
    x0, x1 = max(0, math.ceil(cx - w / 2 - gx)), min(width - 1, math.floor(cx + w / 2 + gx))
    y0, y1 = max(0, math.ceil(cy - h / 2 - gy)), min(height - 1, math.floor(cy + h / 2 + gy))
    yy, xx = np.mgrid[y0:y1 + 1, x0:x1 + 1]
    outside = (np.abs(xx - cx) > w / 2.0) | (np.abs(yy - cy) > h / 2.0)
    o = np.bincount(bins[yy[outside], xx[outside]], minlength=n_bins).astype(np.float64)
    if o.sum() == 0:  # box fills the frame: no background seen
        return q, q.copy(), (q > 0).astype(np.float64)
    o /= o.sum()
    v = np.ones(n_bins)
    nz = o > 0
    v[nz] = np.minimum(o[nz].min() / o[nz], 1.0)
    qb = q * v
    return q, qb / qb.sum(), (q > o).astype(np.float64)


def window_pass(bins: np.ndarray, n_bins: int, q: np.ndarray, t: np.ndarray, c: tuple[float, float],
                hx: float, hy: float, inner2: float, kernel: str) -> PassV2:
    """One pass over the window at ``c``: histogram, rho, weights and their sums (:class:`PassV2`)."""
    height, width = bins.shape
    xs, ys, d2 = window_pixels(c[0], c[1], hx, hy, width, height)
    b = bins[ys, xs]
    k = np.ones_like(d2) if kernel == "flat" else 1.0 - d2
    p = np.bincount(b, weights=k, minlength=n_bins)
    s = p.sum()
    if s > 0:
        p /= s  # type: ignore[misc]
    rho = float(np.sqrt(p * q).sum())
    wb = np.zeros(n_bins)
    nz = p > 0
    wb[nz] = np.sqrt(q[nz] / p[nz])
    w = wb[b]
    tp = t[b]
    inner = d2 < inner2
    return PassV2(rho=rho, sw=float(w.sum()), swx=float((w * xs).sum()), swy=float((w * ys).sum()),
                  nt=float(tp.sum()), st2=float((tp * d2).sum()), n_in=int(inner.sum()),
                  nt_in=int(tp[inner].sum()), n=len(b))


# ----------------------------------------------------------------------------- numba kernels
# FloatTrackerV2._track (mean shift + window_pass) compiled with numba, with float_model's
# "numba kernels" helpers: the same IEEE double operations in the same order, so every pass, and
# so every result, is bit-identical to numpy.  The window's pixels are found row by row as in
# window_pixels (d2 = ax + by, ax = ((x - cx) / hx) * ((x - cx) / hx) as numpy's ``** 2`` on a
# float64 array, row-major order = np.nonzero's) by float_model's _nb_scan, on colour bins
# computed once per frame from the (decimated) frame's pixels (_nb_bins: colour_bins' integers);
# the histogram is bincount's sequential sum; p.sum(), sqrt(p q).sum(), w.sum(), (w x).sum(),
# (w y).sum() and (t d2).sum() are numpy's pairwise sums (_nb_sum, _nb_sum3); nt, n_in, nt_in are
# counts (t is 0 / 1), exact in any order, computed for the final window only.  The one Python
# float operation of the loop, s2 = dx ** 2 + dy ** 2 (libm pow), is left to Python when s2 is
# within rounding of eps2.  init() and everything per frame run the same Python for both paths.
# With orient_T > 0 the kernels bin joint colour x orientation bins lazily too (_nb_bins_joint, the
# Sobel in features_v2.sobel's float32 order on greys computed once per frame in a grey cache), and
# with more than _SPARSE_BINS bins a pass runs its per-bin steps on the bins its pixels touch
# (_nb_pass_sparse), the same numbers.

@_jit
def _nb_box(cx, cy, hx, hy, width, height):
    """The window's bounding box x0, x1, y0, y1 (inclusive) in the image, as :func:`window_pixels`."""
    return (max(0, math.ceil(cx - hx)), min(width - 1, math.floor(cx + hx)),
            max(0, math.ceil(cy - hy)), min(height - 1, math.floor(cy + hy)))


_WB, _WG, _WR = _GREY_W  # float32 constants: numba multiplies float32 by float32 in float32
# the three float32 products of grey_area as tables (the same IEEE products: v wb, v wg, v wr)
_LB, _LG, _LR = (np.arange(256, dtype=np.float32) * w for w in _GREY_W)
_TWO = np.float32(2.0)


@_jit_inline
def _nb_colour(r, g, b, s, s1, s2):
    """The colour bin (:func:`colour_bins`) of one pixel's R, G, B (uint8); s = 8 - bits, s1 = bits,
    s2 = 2 bits (uint32)."""
    return ((np.uint32(r) >> s) << s2) | ((np.uint32(g) >> s) << s1) | (np.uint32(b) >> s)


@_jit_inline
def _nb_grey(b, g, r):
    """The grey of one pixel's B, G, R (uint8): :func:`~mstrack.track.features.grey_area`'s
    (B wb + G wg) + R wr in float32 (the products from the _LB, _LG, _LR tables)."""
    return (_LB[b] + _LG[g]) + _LR[r]


@_jit_inline
def _nb_octant(l0, m0, r0, l1, r1, l2, m2, r2, tf):
    """The orientation bin of a pixel from the greys of its 3 x 3 neighbourhood (rows 0 .. 2, left,
    middle, right; the centre is not used): :func:`~mstrack.track.features_v2.sobel`'s float32 Gx,
    Gy in its order, then :func:`~mstrack.track.features_v2.orientation_bins` (no branches: the flat
    test is as often true as not)."""
    gx = ((r0 - l0) + (r2 - l2)) + (r1 - l1) * _TWO
    gy = ((l2 + r2) + m2 * _TWO) - ((l0 + r0) + m0 * _TWO)
    ax, ay = abs(gx), abs(gy)
    o = 4 * np.int32(gx < 0) + 2 * np.int32(gy < 0) + np.int32(ay > ax)
    return o + np.int32(ax + ay < tf) * (8 - o)


@_jit
def _nb_bins(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T):
    """Colour bins (:func:`colour_bins`) of ``frame``'s [y0, y1] x [x0, x1] into ``cache``, once;
    T > 0: joint bins (:func:`_nb_bins_joint`).

    rows[0, y], rows[1, y]: the computed columns [lo, hi) of row y (one run, grown
    to the union; lo >= hi: none yet).  The bins never depend on what was asked before."""
    if T > 0:
        _nb_bins_joint(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T, _NO_AX, 0, 0.0, 0.0)
        return
    s, s1, s2 = np.uint32(8 - bits), np.uint32(bits), np.uint32(2 * bits)
    for y in range(y0, y1 + 1):
        lo, hi = rows[0, y], rows[1, y]
        if lo <= x0 and x1 < hi:
            continue
        if lo >= hi:  # nothing yet in this row
            a, b = x0, x1 + 1
            lo, hi = x0, x0
        else:
            a, b = min(x0, lo), max(x1 + 1, hi)
        px, row = frame[y], cache[y]
        for x in range(a, lo):
            row[x] = (((np.uint32(px[x, 2]) >> s) << s2) | ((np.uint32(px[x, 1]) >> s) << s1)
                      | (np.uint32(px[x, 0]) >> s))
        for x in range(hi, b):
            row[x] = (((np.uint32(px[x, 2]) >> s) << s2) | ((np.uint32(px[x, 1]) >> s) << s1)
                      | (np.uint32(px[x, 0]) >> s))
        rows[0, y], rows[1, y] = a, b


@_jit
def _nb_bins_window(frame, bits, cache, rows, grey, cx, cy, hx, hy, width, height, ax, full, d, T):
    """:func:`_nb_bins` for the window at (cx, cy): joint bins (T > 0) of its pixels only (each row's
    run of inside pixels, as the scan finds them: ``ax`` gets the window's column terms, see
    float_model's ``_nb_columns``, ``_nb_run``), the other bins of its box."""
    x0, x1, y0, y1 = _nb_box(cx, cy, hx, hy, width, height)
    if x1 < x0 or y1 < y0:
        return
    if T > 0:
        jc = _nb_columns(cx, hx, x0, x1 - x0 + 1, ax)
        _nb_bins_joint(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T, ax, jc, cy, hy)
    else:
        _nb_bins(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T)


#: _nb_bins_joint prefetches the frame rows of the next rows this far ahead (1: measured best on the dev set)
_PF_ROWS = 1
_NO_AX = np.zeros(1)  # (_nb_bins_joint's ax for a box: not read)


@_jit
def _nb_bins_joint(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T, ax, jc, cy, hy):
    """:func:`_nb_bins` with joint bins: colour x 9 + the orientation bin of frame pixel (d y, d x)
    of ``full`` (``frame`` = ``full[::d, ::d]``), as ``FloatTrackerV2._bins``: the colour bin
    (:func:`_nb_colour`), the orientation bin (:func:`_nb_octant`) of the greys around the pixel
    (:func:`_nb_grey`); 8 on the frame's 1-px border.  hy > 0: in each row [y0, y1] only the run
    of pixels inside the window at (., cy) of column terms ``ax`` (from x0; least at jc), the
    pixels the scan reads (a box has a fifth more); hy = 0: the box [x0, x1] x [y0, y1].

    D <= 2: the greys come from the frame's grey cache ``grey``, each computed once per frame
    (at D 1 and 2 neighbouring pixels share greys): rows[2, R], rows[3, R] are frame row R's
    computed columns [lo, hi) (one run, grown to the union as the bins' runs); the loops for D 1
    and 2 are separate (a constant stride).  D > 2: no two pixels share a grey; each pixel's 8
    greys (the Sobel does not use the centre's) are computed in straight-line code.

    One function without array-passing helpers and with uint64 indices (ints known to be >= 0):
    numba then neither reference-counts arrays nor checks for negative indices per row or pixel,
    which for the short runs a moved window adds to each row cost more than the bins."""
    s, s1, s2 = np.uint32(8 - bits), np.uint32(bits), np.uint32(2 * bits)
    H, W = full.shape[0], full.shape[1]
    tf = float(T)
    one = np.uint64(1)
    xl, xr, nx = x0, x1, x1 - x0 + 1  # the row's pixels [xl, xr]
    yf = y0  # rows before yf: prefetched
    for y in range(y0, y1 + 1):
        if hy > 0:  # the window's run in this row
            v = (y - cy) / hy
            ja, m = _nb_run(ax, jc, nx, v * v)
            if m == 0:
                continue
            xl, xr = x0 + ja, x0 + ja + m - 1
        # the frame rows of the next _PF_ROWS rows whose bins lack some of this row's columns: into
        # the caches while this row is worked on (a new frame is read from memory)
        while yf <= min(y + _PF_ROWS, y1):
            if not (rows[0, yf] <= xl and xr < rows[1, yf]):
                for R in range(max(d * yf - 1, 0), min(d * yf + 2, H)):
                    for X in range(max(d * xl - 1, 0), min(d * xr + 2, W), 21):  # 64 bytes apart
                        _prefetch(full, np.uint64(R), np.uint64(X))
            yf += 1
        lo, hi = rows[0, y], rows[1, y]
        if lo <= xl and xr < hi:
            continue
        if lo >= hi:  # nothing yet in this row
            a, b = xl, xr + 1
            lo, hi = xl, xl
        else:
            a, b = min(xl, lo), max(xr + 1, hi)
        rows[0, y], rows[1, y] = a, b
        yu, Y = np.uint64(y), d * y
        for run in range(2):  # the new runs [a, lo) and [hi, b)
            xa, xb = (a, lo) if run == 0 else (hi, b)
            if xb <= xa:
                continue
            for X in range(xa, xb):
                x = np.uint64(X)
                cache[yu, x] = 9 * _nb_colour(frame[yu, x, 2], frame[yu, x, 1], frame[yu, x, 0], s, s1, s2)
            if Y == 0 or Y == H - 1:
                for X in range(xa, xb):
                    cache[yu, np.uint64(X)] += 8
                continue
            if xa == 0:  # the frame's left / right column
                cache[yu, 0] += 8
                xa = 1
            if d * (xb - 1) == W - 1 and xb > xa:
                cache[yu, np.uint64(xb - 1)] += 8
                xb -= 1
            if xb <= xa:
                continue
            r0, r1, r2 = np.uint64(Y - 1), np.uint64(Y), np.uint64(Y + 1)
            if d > 2:
                for X in range(xa, xb):
                    x = np.uint64(d * X)
                    l, r = x - one, x + one
                    o = _nb_octant(
                        _nb_grey(full[r0, l, 0], full[r0, l, 1], full[r0, l, 2]),
                        _nb_grey(full[r0, x, 0], full[r0, x, 1], full[r0, x, 2]),
                        _nb_grey(full[r0, r, 0], full[r0, r, 1], full[r0, r, 2]),
                        _nb_grey(full[r1, l, 0], full[r1, l, 1], full[r1, l, 2]),
                        _nb_grey(full[r1, r, 0], full[r1, r, 1], full[r1, r, 2]),
                        _nb_grey(full[r2, l, 0], full[r2, l, 1], full[r2, l, 2]),
                        _nb_grey(full[r2, x, 0], full[r2, x, 1], full[r2, x, 2]),
                        _nb_grey(full[r2, r, 0], full[r2, r, 1], full[r2, r, 2]), tf)
                    cache[yu, np.uint64(X)] += o
                continue
            c0, c1 = d * xa - 1, d * (xb - 1) + 2  # frame columns [c0, c1): X - 1 .. X + 1 of every pixel
            for R in range(Y - 1, Y + 2):  # their greys, once per frame
                glo, ghi = rows[2, R], rows[3, R]
                if glo <= c0 and c1 <= ghi:
                    continue
                if glo >= ghi:  # nothing yet in this row
                    glo = ghi = c0
                ga, gb = min(c0, glo), max(c1, ghi)
                ru = np.uint64(R)
                for X in range(ga, glo):
                    x = np.uint64(X)
                    grey[ru, x] = _nb_grey(full[ru, x, 0], full[ru, x, 1], full[ru, x, 2])
                for X in range(ghi, gb):
                    x = np.uint64(X)
                    grey[ru, x] = _nb_grey(full[ru, x, 0], full[ru, x, 1], full[ru, x, 2])
                rows[2, R], rows[3, R] = ga, gb
            if d == 1:
                for X in range(xa, xb):
                    x = np.uint64(X)
                    l, r = x - one, x + one
                    cache[yu, x] += _nb_octant(grey[r0, l], grey[r0, x], grey[r0, r], grey[r1, l], grey[r1, r],
                                               grey[r2, l], grey[r2, x], grey[r2, r], tf)
            else:
                for X in range(xa, xb):
                    c = np.uint64(2 * X)
                    l, r = c - one, c + one
                    cache[yu, np.uint64(X)] += _nb_octant(grey[r0, l], grey[r0, c], grey[r0, r], grey[r1, l],
                                                          grey[r1, r], grey[r2, l], grey[r2, c], grey[r2, r], tf)


#: More bins than this (the joint colour x orientation bins, 4608): :func:`_nb_pass` works on the bins
#: the window's pixels touch (:func:`_nb_scan_sparse`), not on every bin; fewer (colour, 512): as before.
_SPARSE_BINS = 1024


@_jit
def _nb_scan_sparse(cx, cy, hx, hy, width, height, bins, flat, lists, B, X, Y, h, ax, cnt, U):
    """numba_kernels._nb_scan on the bins image ``bins`` (the bins cache), for many bins: the same
    pixels, B, X, Y (``lists``; else not written) and histogram h (the same sums in the same order),
    without clearing h and the counts cnt[0] first: they must be zero (as :func:`_nb_pass_sparse`
    leaves them).  The touched bins go to U (a bin is new where its count, or h, is still 0: every
    pixel adds 1, or 1 - d2 > 0); h is set for them only.  Returns (n, nu).

    (One count table: with many bins runs of one bin are short.  uint64 indices and no views:
    numba then neither checks for negative indices nor reference-counts a view per row.)"""
    x0, x1, y0, y1 = _nb_box(cx, cy, hx, hy, width, height)
    nx = x1 - x0 + 1
    jc = _nb_columns(cx, hx, x0, nx, ax)
    c1 = cnt[0]
    n = nu = 0
    for y in range(y0, y1 + 1):
        t = (y - cy) / hy
        by = t * t
        ja, m = _nb_run(ax, jc, nx, by)
        if m == 0:
            continue
        xa, yu = x0 + ja, np.uint64(y)
        for k in range(m):
            i, x = np.uint64(n + k), np.uint64(xa + k)
            u = np.uint64(bins[yu, x])
            if lists:
                B[i], X[i], Y[i] = u, xa + k, y
            if flat:  # integer counts
                c = c1[u]
                if c == 0:
                    U[np.uint64(nu)] = u
                    nu += 1
                c1[u] = c + 1
            else:  # bincount's sequential sum
                hu = h[u]
                if hu == 0.0:
                    U[np.uint64(nu)] = u
                    nu += 1
                h[u] = hu + (1.0 - (ax[np.uint64(ja + k)] + by))
        n += m
    if flat:
        for i in range(nu):
            u = np.uint64(U[i])
            h[u] = float(c1[u])
    return n, nu


@_jit
def _nb_pass_sparse(frame, bits, cx, cy, hx, hy, width, height, flat, q, B, X, Y, fbuf, ax, cnt, ubuf,
                    cache, rows, grey, full, d, T, rho_only):
    """:func:`_nb_pass` for many bins: the same numbers.  The per-bin steps run on the bins the
    window's pixels touch (U, :func:`_nb_scan_sparse`) and only where q > 0 (elsewhere the root
    sqrt(p q) and the weight sqrt(q / p) are 0, p is not used): p = h / total, the root in p's row
    (rho: their pairwise sum over all bins), the weight in h's (after h's sum).  h, p and the counts
    are 0 elsewhere, bit for bit what the dense steps give, and are cleared again for the touched
    bins at the end.  rho_only: no pixel lists, no weights (sw, swx, swy returned 0)."""
    nb = q.shape[0]
    h, p = fbuf[0, :nb], fbuf[1, :nb]
    U = ubuf[0]
    x0, x1, y0, y1 = _nb_box(cx, cy, hx, hy, width, height)
    if x1 < x0 or y1 < y0:  # no pixel in the box
        n = nu = 0
    else:
        _nb_bins_window(frame, bits, cache, rows, grey, cx, cy, hx, hy, width, height, ax, full, d, T)
        n, nu = _nb_scan_sparse(cx, cy, hx, hy, width, height, cache, flat, not rho_only, B, X, Y, h, ax, cnt, U)
    total = float(n) if flat else _nb_sum(h, nb)
    for i in range(nu):
        u = np.uint64(U[i])
        qu = q[u]
        if qu != 0.0:
            pu = h[u] / total if total > 0 else h[u]
            p[u] = math.sqrt(pu * qu)
            h[u] = math.sqrt(qu / pu) if pu > 0 else 0.0
        else:
            h[u] = 0.0
    rho = _nb_sum(p, nb)
    sw = swx = swy = 0.0
    if not rho_only:
        sw, swx, swy = _nb_sum3(h, B, X, Y, n)
    c1 = cnt[0]
    for i in range(nu):
        u = np.uint64(U[i])
        h[u] = p[u] = 0.0
        c1[u] = 0
    return n, rho, sw, swx, swy


@_jit
def _nb_pass(frame, bits, cx, cy, hx, hy, width, height, flat, q, B, X, Y, fbuf, ax, cnt, ubuf, cache, rows, grey,
             full, d, T):
    """The mean-shift part of :func:`window_pass` at (cx, cy): (n, rho, sw, swx, swy).

    Pixels and histogram by float_model's ``_nb_scan`` on the colour bins of
    ``frame``'s pixels (:func:`_nb_bins`, computed once per frame in ``cache``);
    the window's pixels stay in B, X, Y (n of them) and its column terms of d2 in
    ``ax``, for :func:`_nb_stats`.  More than _SPARSE_BINS bins: :func:`_nb_pass_sparse`."""
    nb = q.shape[0]
    if nb > _SPARSE_BINS:
        return _nb_pass_sparse(frame, bits, cx, cy, hx, hy, width, height, flat, q, B, X, Y, fbuf, ax, cnt, ubuf,
                               cache, rows, grey, full, d, T, False)
    h, p, wb = fbuf[0, :nb], fbuf[1, :nb], fbuf[2, :nb]
    x0, x1, y0, y1 = _nb_box(cx, cy, hx, hy, width, height)
    if x1 < x0 or y1 < y0:  # no pixel in the box (_nb_scan needs one column)
        h[:] = 0.0
        n = 0
    else:
        _nb_bins(frame, bits, cache, rows, grey, x0, x1, y0, y1, full, d, T)
        n = _nb_scan(cx, cy, hx, hy, width, height, frame, 0, cache, 0, 0, flat, B, X, Y, h, ax, cnt[:, :nb])
    rho = _nb_normalise(h, q, n, flat, p, wb)  # wb: rho's temporary
    for u in range(nb):
        wb[u] = math.sqrt(q[u] / p[u]) if p[u] > 0 else 0.0
    sw, swx, swy = _nb_sum3(wb, B, X, Y, n)
    return n, rho, sw, swx, swy


@_jit
def _nb_stats(n, B, X, Y, ax, cx, cy, hx, hy, t, inner2, td):
    """The target statistics of :func:`window_pass` at (cx, cy) from :func:`_nb_pass`'s pixels
    (B, X, Y, ax of that window): (nt, st2, n_in, nt_in).

    d2 = ax + by as the scan found the pixels (row-major, each row's pixels one run
    of consecutive columns); td = t[b] d2 per pixel, st2 its pairwise sum.  (uint64
    indices, no views: see :func:`_nb_scan_sparse`.)"""
    x0 = max(0, math.ceil(cx - hx))
    nt = n_in = nt_in = 0
    i = 0
    while i < n:
        y = Y[np.uint64(i)]
        v = (y - cy) / hy
        by = v * v
        xa = X[np.uint64(i)] - x0
        j = i + 1
        while j < n and Y[np.uint64(j)] == y:
            j += 1
        for k in range(j - i):
            ik = np.uint64(i + k)
            d2 = ax[np.uint64(xa + k)] + by
            tv = t[np.uint64(B[ik])]
            td[ik] = tv * d2
            inner = d2 < inner2
            target = tv != 0.0
            n_in += inner  # (no branches: t is as often 0 as 1)
            nt += target
            nt_in += inner & target
        i = j
    return float(nt), _nb_sum(td, n), n_in, nt_in


@_jit
def _nb_window_pass(frame, bits, cx, cy, hx, hy, width, height, inner2, flat, q, t,
                    ibuf, fbuf, ax, cnt, td, ubuf, cache, rows, grey, full, d, T):
    """:func:`window_pass` at (cx, cy) on the colour bins of ``frame`` (an (H, W, 3) uint8 view,
    the decimated frame): (rho, sw, swx, swy, nt, st2, n_in, nt_in, n).  Buffers: :func:`_nb_buffers_v2`."""
    n, rho, sw, swx, swy = _nb_pass(frame, bits, cx, cy, hx, hy, width, height, flat, q, ibuf[0], ibuf[1],
                                    ibuf[2], fbuf, ax[0], cnt, ubuf, cache, rows, grey, full, d, T)
    nt, st2, n_in, nt_in = _nb_stats(n, ibuf[0], ibuf[1], ibuf[2], ax[0], cx, cy, hx, hy, t, inner2, td)
    return rho, sw, swx, swy, nt, st2, n_in, nt_in, n


@_jit
def _nb_window_rho(frame, bits, cx, cy, hx, hy, width, height, flat, q, ibuf, fbuf, ax, cnt, td, ubuf, cache, rows,
                   grey, full, d, T):
    """rho of :func:`_nb_window_pass` at (cx, cy) (many bins: :func:`_nb_pass_sparse` without the
    pixel lists and the weights)."""
    if q.shape[0] > _SPARSE_BINS:
        return _nb_pass_sparse(frame, bits, cx, cy, hx, hy, width, height, flat, q, ibuf[0], ibuf[1], ibuf[2],
                               fbuf, ax[0], cnt, ubuf, cache, rows, grey, full, d, T, True)[1]
    return _nb_pass(frame, bits, cx, cy, hx, hy, width, height, flat, q, ibuf[0], ibuf[1], ibuf[2], fbuf, ax[0],
                    cnt, ubuf, cache, rows, grey, full, d, T)[1]


@_jit
def _nb_window_rho2(frame, bits, cx, cy, hx1, hy1, hx2, hy2, width, height, flat, q, ibuf, fbuf, ax, cnt, td, ubuf,
                    cache, rows, grey, full, d, T):
    """:func:`_nb_window_rho` at (cx, cy) for two window sizes (the scale test's), one call."""
    return (_nb_window_rho(frame, bits, cx, cy, hx1, hy1, width, height, flat, q, ibuf, fbuf, ax, cnt, td, ubuf,
                           cache, rows, grey, full, d, T),
            _nb_window_rho(frame, bits, cx, cy, hx2, hy2, width, height, flat, q, ibuf, fbuf, ax, cnt, td, ubuf,
                           cache, rows, grey, full, d, T))


@_jit
def _nb_track(frame, bits, sx, sy, it0, hx, hy, width, height, inner2, flat, q, t, max_iter, eps2,
              ibuf, fbuf, ax, cnt, td, ubuf, cache, rows, grey, full, d, T):
    """FloatTrackerV2._track's mean shift from (sx, sy) after ``it0`` iterations.

    Returns (code, it, c0x, c0y, c1x, c1y, pass): code 0 a stop at c0 after ``it``
    iterations, ``pass`` the :func:`_nb_window_pass` tuple at c0 (the target
    statistics of that window only, from its pixels kept in the other half of the
    buffers); 1 the shift test c0 -> c1 is left to Python (|s2 - eps2| tiny:
    Python's ``dx ** 2`` is libm's pow, which may round differently from dx * dx),
    ``pass`` then holds rho at c0 and c1 only.
    """
    B0, X0, Y0, B1, X1, Y1, ax0, ax1 = ibuf[0], ibuf[1], ibuf[2], ibuf[3], ibuf[4], ibuf[5], ax[0], ax[1]
    c0x = min(max(sx, 0.0), width - 1.0)
    c0y = min(max(sy, 0.0), height - 1.0)
    n0, rho0, sw0, swx0, swy0 = _nb_pass(frame, bits, c0x, c0y, hx, hy, width, height, flat, q, B0, X0, Y0, fbuf,
                                         ax0, cnt, ubuf, cache, rows, grey, full, d, T)
    it = it0
    for it in range(it0 + 1, max_iter + 1):
        if sw0 <= 0:
            break
        c1x = min(max(swx0 / sw0, 0.0), width - 1.0)
        c1y = min(max(swy0 / sw0, 0.0), height - 1.0)
        n1, rho1, sw1, swx1, swy1 = _nb_pass(frame, bits, c1x, c1y, hx, hy, width, height, flat, q, B1, X1, Y1,
                                             fbuf, ax1, cnt, ubuf, cache, rows, grey, full, d, T)
        if rho1 < rho0:
            break
        s2 = (c1x - c0x) * (c1x - c0x) + (c1y - c0y) * (c1y - c0y)
        if abs(s2 - eps2) <= _SHIFT2_BAND * eps2:
            return 1, it, c0x, c0y, c1x, c1y, (rho0, rho1, 0.0, 0.0, 0.0, 0.0, 0, 0, 0)
        c0x, c0y, n0, rho0, sw0, swx0, swy0 = c1x, c1y, n1, rho1, sw1, swx1, swy1
        B0, X0, Y0, ax0, B1, X1, Y1, ax1 = B1, X1, Y1, ax1, B0, X0, Y0, ax0
        if s2 < eps2:
            break
    nt, st2, n_in, nt_in = _nb_stats(n0, B0, X0, Y0, ax0, c0x, c0y, hx, hy, t, inner2, td)
    return 0, it, c0x, c0y, c0x, c0y, (rho0, sw0, swx0, swy0, nt, st2, n_in, nt_in, n0)


def _nb_buffers_v2(hx: float, hy: float, n_bins: int) -> tuple[np.ndarray, ...]:
    """Work buffers of :func:`_nb_track` for windows of half-sizes up to hx, hy.

    int32 bins and coordinates of two windows (6, box px); float64 histogram,
    normalised histogram, weights (3, bins); d2 column terms of two windows
    (2, box width); int32 counts (4 interleaved tables, 1 beyond 2**16 bins);
    float64 t d2 (box px); int32 touched bins (1, bins).  The histogram rows and
    the counts start at zero: with more than _SPARSE_BINS bins
    :func:`_nb_pass_sparse` relies on it (and leaves them so).
    """
    box_w, box_h = int(2.0 * hx) + 2, int(2.0 * hy) + 2
    return (np.empty((6, box_w * box_h), np.int32), np.zeros((3, n_bins)), np.empty((2, box_w)),
            np.zeros((4 if n_bins <= 1 << 16 else 1, n_bins), np.int32), np.empty(box_w * box_h),
            np.zeros((1, n_bins), np.int32))


def _bins_cache(height: int, width: int, joint: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An empty bins cache of :func:`_nb_bins` for a height x width frame: (bins, rows, grey).

    bins: the (decimated) image's bins in its top-left part; rows[0:2]: each bins row's computed
    columns; rows[2:4] and grey (``joint``: float32, the frame's size; else 1 x 1, unused): each
    frame row's computed grey columns and the greys (:func:`_nb_grey_row`).  Zeroing ``rows``
    empties both caches (a new frame)."""
    rows = np.zeros((4, height), np.int32)
    grey = np.empty((height, width) if joint else (1, 1), np.float32)
    return np.empty((height, width), np.int32), rows, grey


def _buffers_fit(bufs: tuple[np.ndarray, ...], hx: float, hy: float, n_bins: int) -> bool:
    box_w, box_h = int(2.0 * hx) + 2, int(2.0 * hy) + 2
    return bufs[2].shape[1] >= box_w and bufs[0].shape[1] >= box_w * box_h and bufs[1].shape[1] >= n_bins


def window_pass_numba(frame: np.ndarray, bits: int, q: np.ndarray, t: np.ndarray, c: tuple[float, float],
                      hx: float, hy: float, inner2: float, kernel: str,
                      bufs: tuple[np.ndarray, ...] | None = None) -> PassV2:
    """:func:`window_pass` on ``colour_bins(frame, bits)`` by the numba kernel (bit-identical).

    ``frame``: (H, W, 3) uint8, e.g. the decimated view ``frame[::D, ::D]``.
    """
    height, width = frame.shape[:2]
    if bufs is None or not _buffers_fit(bufs, hx, hy, q.shape[0]):
        bufs = _nb_buffers_v2(hx, hy, q.shape[0])
    return PassV2(*_nb_window_pass(frame, bits, float(c[0]), float(c[1]), float(hx), float(hy), width, height,
                                   float(inner2), kernel == "flat", q, t, *bufs, *_bins_cache(height, width),
                                   frame, 1, 0))


class LazyBins:
    """Colour bins of an image, computed on the first request for a rectangle and kept.

    Indexing ``bins[ys, xs]`` (integer arrays) computes the bins of the bounding box of the
    request (grown by ``margin`` px and united with what is already there); the values never
    depend on which rectangles were asked for, so results equal those of the whole image.
    """

    def __init__(self, image: np.ndarray, bits: int, margin: int, chroma: int = 0) -> None:
        self.image, self.bits, self.margin, self.chroma = image, bits, margin, chroma
        self.shape = image.shape[:2]
        self.values = np.empty(self.shape, np.intp)
        self.box: tuple[int, int, int, int] | None = None  # y0, y1, x0, x1 (half-open)

    def _ensure(self, y0: int, y1: int, x0: int, x1: int) -> None:
        b = self.box
        if b is not None and y0 >= b[0] and y1 <= b[1] and x0 >= b[2] and x1 <= b[3]:
            return
        m = self.margin
        ny0, ny1, nx0, nx1 = max(0, y0 - m), min(self.shape[0], y1 + m), max(0, x0 - m), min(self.shape[1], x1 + m)
        if b is not None:
            ny0, ny1, nx0, nx1 = min(ny0, b[0]), max(ny1, b[1]), min(nx0, b[2]), max(nx1, b[3])
        img = self.image[ny0:ny1, nx0:nx1]
        self.values[ny0:ny1, nx0:nx1] = chroma_bins(img, self.bits, self.chroma) if self.chroma else colour_bins(img, self.bits)
        self.box = (ny0, ny1, nx0, nx1)

    def __getitem__(self, key: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        ys, xs = key
        if len(ys):
            self._ensure(int(ys.min()), int(ys.max()) + 1, int(xs.min()), int(xs.max()) + 1)
        return self.values[ys, xs]


def decimation(w: float, h: float, p: TrackerParams) -> int:
    """D: the smallest power of two (<= 8) with max(w, h) (1 + pad) / D <= max_window."""
    d = 1
    while max(w, h) * (1.0 + p.pad) / d > p.max_window and d < 8:
        d *= 2
    return d


def lost_decimation(d0: int, lost_n: int, p: TrackerParams) -> int:
    """The decimation of a frame after ``lost_n`` consecutive lost frames (0: tracking, d0):
    2 d0, doubled again every ``search_widen`` lost frames (0: never), at most max(16, 2 d0).
    The wide search's start points go d / (2 d0) times as far (in window sizes), so its region
    holds the same number of decimated pixels at every step."""
    if lost_n <= 0:
        return d0
    k = 1 + ((lost_n - 1) // p.search_widen if p.search_widen > 0 else 0)
    return max(min(d0 << k, 16), 2 * d0)


def meanshift_v2(bins: np.ndarray | LazyBins, n_bins: int, q: np.ndarray, t: np.ndarray,
                 start: tuple[float, float], hx: float, hy: float, p: TrackerParams,
                 max_iter: int) -> tuple[tuple[float, float], PassV2, int]:
    """Mean shift of one feature from ``start`` (decimated coordinates), the paper's loop on
    :func:`window_pass`: stop when the weights vanish, when rho falls (keep the previous centre)
    or when the squared step is below eps2.  Returns (centre, pass at the centre, iterations)."""
    height, width = bins.shape[:2]
    inner2 = 1.0 / (1.0 + p.pad) ** 2

    def clamp(c: tuple[float, float]) -> tuple[float, float]:
        return (min(max(c[0], 0.0), width - 1.0), min(max(c[1], 0.0), height - 1.0))

    c0 = clamp(start)
    p0 = window_pass(bins, n_bins, q, t, c0, hx, hy, inner2, p.kernel)  # type: ignore[arg-type]
    it = 0
    for it in range(1, max_iter + 1):
        if p0.sw <= 0:
            break
        c1 = clamp((p0.swx / p0.sw, p0.swy / p0.sw))
        p1 = window_pass(bins, n_bins, q, t, c1, hx, hy, inner2, p.kernel)  # type: ignore[arg-type]
        if p1.rho < p0.rho - p.rho_stop_margin:  # (rho_stop_margin: 0 by default)
            break
        s2 = (c1[0] - c0[0]) ** 2 + (c1[1] - c0[1]) ** 2
        c0, p0 = c1, p1
        if s2 < p.eps2:
            break
    return c0, p0, it


def confidence(ps: PassV2, rho_ref: float, share_ref: float) -> float:
    """min(1, rho / rho_ref) * min(1, share / share_ref) (0 for a zero reference)."""
    cr = min(1.0, ps.rho / rho_ref) if rho_ref > 0 else 0.0
    cs = min(1.0, ps.share / share_ref) if share_ref > 0 else 0.0
    return cr * cs


def loss_filter(s: float, x: float, p: TrackerParams) -> float:
    """One step of the loss flag's smoothing: s + loss_smooth (x - s)."""
    return s + p.loss_smooth * (x - s)


def loss_flag(rho_s: float, con_s: float, rho0: float, share: float, p: TrackerParams) -> bool:
    """The loss flag (docs/algorithm.md, "v2.7a Loss flag"): no target-coloured pixel in the box
    (share = 0), or the window matches the model worse than at init *and* its target colours do
    not stand out from the ring around the box, both smoothed (:func:`loss_filter` of rho and of
    contrast = share - ring_share): rho_s < loss_rho rho0 and con_s < loss_contrast."""
    return share == 0 or rho_s == 0 or (rho_s < p.loss_rho * rho0 and con_s < p.loss_contrast)


def loss_jump(step: tuple[float, float], prev: tuple[float, float], w: float, h: float,
              p: TrackerParams) -> bool:
    """The loss flag's motion test (docs/algorithm.md "v2.7a Loss flag"; off: loss_jump 0): the
    centre's step against the previous frame's step, |sx - px| + |sy - py| > loss_jump (w + h) / 2
    (frame px; w, h the box before the frame's resize)."""
    return p.loss_jump > 0 and abs(step[0] - prev[0]) + abs(step[1] - prev[1]) > p.loss_jump * (w + h) / 2.0


def loss_latch(latch: bool, jump: bool, rho_s: float, ref: float, p: TrackerParams) -> bool:
    """The loss flag's motion latch: set by a jump (:func:`loss_jump`), kept while rho_s < loss_stay ref."""
    return jump or (latch and rho_s < p.loss_stay * ref)


def report_status(searching: bool, flagged: bool, was_flagged_lost: bool) -> Status:
    """The reported status: flagged -> lost (while the wide search runs) or uncertain; not
    flagged -> reacquired on the first unflagged frame after a reported loss, else ok."""
    if flagged:
        return Status.LOST if searching else Status.UNCERTAIN
    return Status.REACQUIRED if was_flagged_lost else Status.OK


def search_starts(start: tuple[float, float], hx: float, hy: float,
                  p: TrackerParams, reach: int = 1) -> list[tuple[float, float]]:
    """The 8 wide-search start points: start +- reach x search_step window diameters in x and y
    (``reach`` > 1: the widened search, :func:`lost_decimation`)."""
    return [(start[0] + sx * reach * p.search_step * 2 * hx, start[1] + sy * reach * p.search_step * 2 * hy)
            for sy in (-1, 0, 1) for sx in (-1, 0, 1) if sx or sy]


def decide_status(conf: float, was_lost: bool, p: TrackerParams) -> Status:
    """The search state from the confidence and whether the tracker was searching: lost (search
    from the next frame on) / reacquired / uncertain / ok (only ok frames teach the references).
    FloatTrackerV2 reports :func:`report_status` (the loss flag), not this."""
    if conf < (p.conf_reacquire if was_lost else p.conf_lost):
        return Status.LOST
    if was_lost:
        return Status.REACQUIRED
    return Status.UNCERTAIN if conf < p.conf_uncertain else Status.OK


def rescale(size: tuple[float, float], size0: tuple[float, float], spread: float, spread_ref: float,
            shape: tuple[int, int], p: TrackerParams, est_rho: float | None = None,
            no_shrink: bool = False) -> tuple[float, float]:
    """One frame's size update: est = sqrt(spread / spread_ref) clamped to 1 +- step;
    s = clamp(1 + gain (est - 1) - reg (w / w0 - 1), 1 +- step); size s, in [3, frame].
    ``est_rho`` (the scale test, off by default): est <- mix est_rho + (1 - mix) est.
    ``no_shrink`` (the shrink guard, :func:`ring_guard`): s <- max(s, 1)."""
    w, h = size
    est = math.sqrt(spread / spread_ref)
    est = min(max(est, 1.0 - p.scale_step), 1.0 + p.scale_step)
    if est_rho is not None and p.scale_test_gate:
        est = est if (est - 1.0) * (est_rho - 1.0) > 0 else 1.0
    elif est_rho is not None:
        est = p.scale_test_mix * est_rho + (1.0 - p.scale_test_mix) * est
    s = 1.0 + p.scale_gain * (est - 1.0) - p.scale_reg * (w / size0[0] - 1.0)
    s = min(max(s, 1.0 - p.scale_step), 1.0 + p.scale_step)
    if no_shrink:
        s = max(s, 1.0)
    return (min(max(w * s, 3.0), float(shape[1])), min(max(h * s, 3.0), float(shape[0])))


def ring_guard(ps: PassV2, p: TrackerParams) -> bool:
    """The shrink guard (scale_ring_guard > 0; off by default): True (no shrinking step this
    frame) when the window's ring holds target-coloured pixels at a share of at least
    scale_ring_guard x their share in the box: ring_share >= scale_ring_guard share."""
    return p.scale_ring_guard > 0 and ps.ring_share >= p.scale_ring_guard * ps.share


def blend_model(qb: np.ndarray, qb_new: np.ndarray, rate: float) -> np.ndarray:
    """The guarded model update's blend: qb + rate (qb_new - qb) (model_rate: r and q'_new; model_mix:
    q'_0 and r)."""
    return qb + rate * (qb_new - qb)


class FloatTrackerV2:
    """Float reference of tracker v2.  Use through :class:`mstrack.Tracker` (preset="v2").

    ``path`` picks how the mean shift of :meth:`update` is computed, with the same
    results bit for bit: "numpy" (:meth:`_track`, :func:`window_pass` on
    :class:`LazyBins`), "numba" (:meth:`_track_numba`, one :func:`_nb_track` call
    per start point), or "auto": numba when it is installed and passes its
    self-check (:func:`_numba_ready`; MSTRACK_NUMBA=0 disables it), else numpy.
    :meth:`init` runs numpy in both.
    """

    PATHS = ("auto", "numba", "numpy")

    def __init__(self, params: TrackerParams | None = None, path: str = "auto") -> None:
        if path not in self.PATHS:
            raise ValueError(f"path must be one of {self.PATHS}, got {path!r}")
        self.params = params or TrackerParams(preset="v2")
        self.path = path
        self._shape: tuple[int, int] | None = None
        self._bufs: tuple[np.ndarray, ...] | None = None
        self._cache: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._use_numba = False

    def active_path(self) -> str:
        """The path :meth:`update` runs now: "numpy" or "numba"."""
        if self.path == "numpy" or self.params.rho_stop_margin > 0 or self.params.chroma_bins:
            # (the numba kernel has neither the margin nor the chromaticity bins)
            return "numpy"
        if self._use_numba:  # (the self-check's own run)
            return "numba"
        if _numba_ready():
            return "numba"
        if self.path == "numba":
            raise RuntimeError("path='numba' but numba is not installed or failed its self-check")
        return "numpy"

    # ------------------------------------------------------------------ helpers
    def decimation(self, w: float, h: float) -> int:
        """D: the smallest power of two with max(w, h) (1 + pad) / D <= max_window."""
        return decimation(w, h, self.params)

    def _bins(self, frame: np.ndarray, d: int) -> np.ndarray:
        p = self.params
        img = frame[::d, ::d]
        c = chroma_bins(img, p.colour_bits, p.chroma_bins) if p.chroma_bins else colour_bins(img, p.colour_bits)
        if p.orient_T <= 0:
            return c
        # joint colour x orientation (off by default): Sobel on the full-resolution grey frame
        from .features_v2 import orientation_bins, sobel
        gx, gy = sobel(frame)
        return c * 9 + orientation_bins(gx[::d, ::d], gy[::d, ::d], p.orient_T)

    def _lazy_bins(self, frame: np.ndarray, d: int, w: float, h: float) -> LazyBins:
        """Bins computed around the windows the frame's mean shift visits (same values)."""
        return LazyBins(frame[::d, ::d], self.params.colour_bits, int(max(w, h) / d) // 2 + 8, self.params.chroma_bins)

    def _track(self, bins: np.ndarray | LazyBins, start: tuple[float, float], hx: float, hy: float,
               max_iter: int) -> tuple[tuple[float, float], PassV2, int]:
        """Mean shift from ``start`` (decimated coordinates): centre, pass at the centre, iterations.

        ``bins``: the decimated image's bins (numpy path), or the decimated frame
        itself (numba path, :meth:`_track_numba`: the same loop in the kernel).
        """
        p = self.params
        if isinstance(bins, np.ndarray) and bins.ndim == 3:
            return self._track_numba(bins, start, hx, hy, max_iter)
        return meanshift_v2(bins, p.n_bins_v2, self._qb, self._t, start, hx, hy, p, max_iter)

    def _track_numba(self, frame: np.ndarray, start: tuple[float, float], hx: float, hy: float,
                     max_iter: int) -> tuple[tuple[float, float], PassV2, int]:
        """:meth:`_track` by :func:`_nb_track` on the decimated frame (same results bit for bit)."""
        p = self.params
        height, width = frame.shape[:2]
        inner2 = 1.0 / (1.0 + p.pad) ** 2
        flat = p.kernel == "flat"
        eps2 = float(p.eps2)
        sx, sy, it0 = float(start[0]), float(start[1]), 0
        while True:
            code, it, c0x, c0y, c1x, c1y, r = _nb_track(  # type: ignore[misc]
                frame, p.colour_bits, sx, sy, it0, hx, hy, width, height, inner2, flat, self._qb, self._t,
                int(max_iter), eps2, *self._bufs, *self._cache, *self._source(frame))
            if code == 0:
                return (c0x, c0y), PassV2(*r), it
            # code 1: the shift test c0 -> c1 as _track does it (c1 accepted: rho1 >= rho0)
            if (c1x - c0x) ** 2 + (c1y - c0y) ** 2 < p.eps2:
                c = (c1x, c1y)
                return c, self._pass(frame, c, hx, hy), it  # (on the frame's bins cache)
            sx, sy, it0 = c1x, c1y, it  # go on from c1 (its pass is recomputed: the same numbers)

    def _confidence(self, ps: PassV2) -> float:
        return confidence(ps, self._rho_ref, self._share_ref)

    def _source(self, frame: np.ndarray) -> tuple[np.ndarray, int, int]:
        """The numba kernels' (full frame, D, orient_T): joint bins need the frame's pixels around
        each decimated pixel (set by :meth:`update`); colour bins only the decimated ``frame``."""
        if self.params.orient_T > 0:
            return self._src
        return frame, 1, 0

    def _pass(self, bins: np.ndarray | LazyBins, c: tuple[float, float], hx: float, hy: float) -> PassV2:
        p = self.params
        inner2 = 1.0 / (1.0 + p.pad) ** 2
        if isinstance(bins, np.ndarray) and bins.ndim == 3:  # numba: the frame's bins cache
            if not _buffers_fit(self._bufs, hx, hy, p.n_bins_v2):  # type: ignore[arg-type]
                self._bufs = _nb_buffers_v2(1.25 * hx, 1.25 * hy, p.n_bins_v2)
            height, width = bins.shape[:2]
            return PassV2(*_nb_window_pass(  # type: ignore[misc]
                bins, p.colour_bits, float(c[0]), float(c[1]), float(hx), float(hy), width, height, float(inner2),
                p.kernel == "flat", self._qb, self._t, *self._bufs, *self._cache, *self._source(bins)))
        return window_pass(bins, p.n_bins_v2, self._qb, self._t, c, hx, hy, inner2, p.kernel)  # type: ignore[arg-type]

    def _rho(self, bins: np.ndarray | LazyBins, c: tuple[float, float], hx: float, hy: float) -> float:
        """``self._pass(bins, c, hx, hy).rho`` (numba: :func:`_nb_window_rho`, the same value)."""
        p = self.params
        if isinstance(bins, np.ndarray) and bins.ndim == 3:
            if not _buffers_fit(self._bufs, hx, hy, p.n_bins_v2):  # type: ignore[arg-type]
                self._bufs = _nb_buffers_v2(1.25 * hx, 1.25 * hy, p.n_bins_v2)
            height, width = bins.shape[:2]
            return _nb_window_rho(bins, p.colour_bits, float(c[0]), float(c[1]), float(hx), float(hy), width,  # type: ignore[misc]
                                  height, p.kernel == "flat", self._qb, *self._bufs, *self._cache, *self._source(bins))
        return self._pass(bins, c, hx, hy).rho

    def _rho2(self, bins: np.ndarray | LazyBins, c: tuple[float, float], hx: float, hy: float,
              scales: tuple[float, float]) -> tuple[float, float]:
        """:meth:`_rho` at (s hx, s hy) for the two scales s (numba: one :func:`_nb_window_rho2` call)."""
        p = self.params
        s1, s2 = scales
        if isinstance(bins, np.ndarray) and bins.ndim == 3:
            hm, hmy = max(s1, s2) * hx, max(s1, s2) * hy
            if not _buffers_fit(self._bufs, hm, hmy, p.n_bins_v2):  # type: ignore[arg-type]
                self._bufs = _nb_buffers_v2(1.25 * hm, 1.25 * hmy, p.n_bins_v2)
            height, width = bins.shape[:2]
            return _nb_window_rho2(bins, p.colour_bits, float(c[0]), float(c[1]), float(s1 * hx), float(s1 * hy),  # type: ignore[misc]
                                   float(s2 * hx), float(s2 * hy), width, height, p.kernel == "flat", self._qb,
                                   *self._bufs, *self._cache, *self._source(bins))
        return self._rho(bins, c, s1 * hx, s1 * hy), self._rho(bins, c, s2 * hx, s2 * hy)

    def _scale_test(self, bins: np.ndarray | LazyBins, c: tuple[float, float], hx: float, hy: float,
                    rho: float) -> float:
        """Scale test (off by default): the window scale among 1 -+ scale_test and 1 whose rho is
        the largest (two more passes at the final centre; ``rho``: the pass at c, hx, hy's)."""
        d, m = self.params.scale_test, self.params.scale_test_margin
        best = 1.0
        for s, r in zip((1.0 - d, 1.0 + d), self._rho2(bins, c, hx, hy, (1.0 - d, 1.0 + d))):
            if r - m > rho:  # (margin m: scale_test_margin, 0 by default)
                best, rho = s, r - m
        return best

    # ------------------------------------------------------------------ API
    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        frame = check_frame(frame)
        height, width = frame.shape[:2]
        box, clipped = clip_box(Box.of(box), width, height)
        p = self.params
        self.active_path()  # numba: compile / self-check here, not in update()
        self._bufs = self._cache = None
        self._shape = (height, width)
        cx, cy = box_centre_index(box)
        self._size = self._size0 = (box.w, box.h)
        self._centre = (cx, cy)
        d = self.decimation(box.w, box.h)
        bins = self._bins(frame, d)
        self._q, self._qb, self._t = background_model(bins, p.n_bins_v2, cx / d, cy / d, box.w / d,
                                                      box.h / d, p.bg_ring, p.kernel)
        self._qb0 = self._qr = self._qb  # the guarded model update's init and running models
        pad = 1.0 + p.pad
        ps = window_pass(bins, p.n_bins_v2, self._qb, self._t, (cx / d, cy / d), pad * box.w / 2 / d,
                         pad * box.h / 2 / d, 1.0 / pad ** 2, p.kernel)
        # references: rho and share are learnt from the first tracked frames (start at the init values)
        self._rho_ref = ps.rho
        self._share_ref = ps.share
        self._spread_ref = ps.spread if ps.spread > 0 else 0.5 / pad ** 2
        self._rho0 = ps.rho  # the loss flag's reference: rho at init
        self._rho_s, self._con_s = ps.rho, ps.share - ps.ring_share  # its filters start at init
        self._lost = False
        self._lost_n = 0  # consecutive lost frames (the search's decimation)
        self._reported_lost = False
        self._vel = (0.0, 0.0)  # last centre step (frame px), for motion_gain
        self._loss_step = (0.0, 0.0)  # the loss flag's motion latch: the last centre step (frame px), the latch
        self._loss_latch = False
        return TrackResult(box=box, centre=(cx, cy), rho_c=ps.rho, rho_e=0.0, alpha_c=1.0, alpha_e=0.0,
                           iter_c=0, iter_e=0, status=Status.CLIPPED if clipped else Status.INIT,
                           message="init box clipped to the frame" if clipped else "",
                           confidence=1.0, extra={"decimation": d, "share": ps.share, "ring_share": ps.ring_share})

    def update(self, frame: np.ndarray) -> TrackResult:
        if self._shape is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p = self.params
        w, h = self._size
        # lost: the whole search runs at twice the decimation (a region 2x wider in the same memory)
        d0 = self.decimation(w, h)
        d = lost_decimation(d0, max(self._lost_n, int(self._lost)), p)  # lost: at least one lost frame
        reach = d // (2 * d0) if self._lost else 1  # the widened search: its start points reach as far x reach
        pad = 1.0 + p.pad
        hx, hy = pad * w / 2.0 / d, pad * h / 2.0 / d
        if self.active_path() == "numba":
            bins: np.ndarray | LazyBins = frame[::d, ::d]  # the kernel bins the pixels it visits
            if self._bufs is None or not _buffers_fit(self._bufs, hx, hy, p.n_bins_v2):
                self._bufs = _nb_buffers_v2(1.25 * hx, 1.25 * hy, p.n_bins_v2)  # room to grow
            if self._cache is None:
                self._cache = _bins_cache(*self._shape, p.orient_T > 0)  # (the decimated image: its top-left part)
            else:
                self._cache[1][:] = 0  # a new frame: no bins, no greys yet
            # joint bins (orient_T > 0): the kernel adds each binned pixel's orientation from the frame
            self._src = (frame, d, int(p.orient_T))
        elif p.orient_T > 0:
            bins = self._bins(frame, d)
        else:
            bins = self._lazy_bins(frame, d, w, h)
        start = (self._centre[0] / d, self._centre[1] / d)
        if p.motion_gain > 0 and not self._lost:  # constant-velocity start (off by default)
            start = ((self._centre[0] + p.motion_gain * self._vel[0]) / d,
                     (self._centre[1] + p.motion_gain * self._vel[1]) / d)
        # lost: every start point (this one included) runs search_iter iterations
        c, ps, it = self._track(bins, start, hx, hy, p.search_iter if self._lost else p.max_iter)
        conf = self._confidence(ps)
        searched = 0
        if self._lost:
            # wide search: mean shift from start points around the last centre, best confidence wins
            for s0 in search_starts(start, hx, hy, p, reach):
                c2, ps2, _ = self._track(bins, s0, hx, hy, p.search_iter)
                searched += 1
                conf2 = self._confidence(ps2)
                if conf2 > conf:
                    c, ps, conf = c2, ps2, conf2
        state = decide_status(conf, self._lost, p)  # the search state (what the tracker does next)
        self._rho_s = loss_filter(self._rho_s, ps.rho, p)
        self._con_s = loss_filter(self._con_s, ps.share - ps.ring_share, p)
        ref = self._rho_ref if p.loss_ref_running else self._rho0  # (the running one: before this frame's update)
        flagged = loss_flag(self._rho_s, self._con_s, ref, ps.share, p)  # what it reports (ok False when flagged)
        centre = (c[0] * d, c[1] * d)  # searching: the search's best candidate
        step = (centre[0] - self._centre[0], centre[1] - self._centre[1])
        motion: dict[str, float] = {}
        if p.loss_jump > 0:  # the motion latch (off by default)
            self._loss_latch = loss_latch(self._loss_latch, loss_jump(step, self._loss_step, w, h, p),
                                          self._rho_s, ref, p)
            flagged = flagged or self._loss_latch
            motion = {"jump": abs(step[0] - self._loss_step[0]) + abs(step[1] - self._loss_step[1]),
                      "wh": w + h, "latch": int(self._loss_latch)}
        self._loss_step = step
        status = report_status(state == Status.LOST, flagged, self._reported_lost)
        self._lost = state == Status.LOST
        self._lost_n = self._lost_n + 1 if self._lost else 0
        # a loss stays reported (uncertain frames keep it) until a frame is ok again
        self._reported_lost = status == Status.LOST or (status == Status.UNCERTAIN and self._reported_lost)
        old = self._centre
        self._centre = centre
        self._vel = (self._centre[0] - old[0], self._centre[1] - old[1]) if state == Status.OK else (0.0, 0.0)
        if state == Status.OK:
            a = p.ref_rate
            self._rho_ref += a * (ps.rho - self._rho_ref)
            self._share_ref += a * (ps.share - self._share_ref)
        # scale: every frame (a lost or uncertain target changes size too), from the spread
        if p.scale_gain > 0 and ps.nt > 0:
            est_rho = self._scale_test(bins, c, hx, hy, ps.rho) if p.scale_test > 0 else None
            self._size = rescale((w, h), self._size0, ps.spread, self._spread_ref, self._shape, p, est_rho,
                                 ring_guard(ps, p))
        if p.model_rate > 0 and state == Status.OK and not flagged and self._con_s >= p.model_contrast:
            # guarded model update (off by default): the init's CBWH model at the tracked box (the
            # size this frame tracked with), blended in; t becomes the new model's
            mb = self._bins(frame, d)
            _, qb_new, self._t = background_model(mb, p.n_bins_v2, c[0], c[1], w / d, h / d, p.bg_ring, p.kernel)
            self._qr = blend_model(self._qr, qb_new, p.model_rate)
            self._qb = self._qr if p.model_mix == 1.0 else blend_model(self._qb0, self._qr, p.model_mix)
        box = box_from_centre_index(*self._centre, *self._size)
        return TrackResult(box=box, centre=self._centre, rho_c=ps.rho, rho_e=0.0, alpha_c=1.0, alpha_e=0.0,
                           iter_c=it, iter_e=0, status=status, confidence=conf,
                           extra={"decimation": d, "share": ps.share, "spread": ps.spread,
                                  "searched": searched, "nt": ps.nt, "n_in": ps.n_in, "nt_in": ps.nt_in,
                                  "n": ps.n, "ring_share": ps.ring_share, "state": state.value,
                                  "rho_s": self._rho_s, "contrast_s": self._con_s, **motion})


_NUMBA_OK: bool | None = None


def _numba_ready() -> bool:
    """Compile (or load) the v2 numba kernel and check it against numpy; False: use numpy.

    Needs float_model's kernels to pass their own self-check (the pairwise sums
    and the scan are theirs); MSTRACK_NUMBA=0 in the environment skips numba.
    """
    global _NUMBA_OK
    if _NUMBA_OK is None:
        _NUMBA_OK = False
        if _fm._numba_ready():
            try:
                _NUMBA_OK = _numba_self_check()
            except Exception as exc:  # noqa: BLE001 - any failure means: use numpy
                warnings.warn(f"mstrack: numba v2 kernel disabled ({exc!r}); using numpy", RuntimeWarning)
            else:
                if not _NUMBA_OK:
                    warnings.warn("mstrack: numba v2 kernel disagrees with numpy here; using numpy",
                                  RuntimeWarning)
    return _NUMBA_OK


def _numba_self_check() -> bool:
    """window_pass_numba == window_pass on random frames (decimated views, both kernels, windows
    across the frame borders, tiny and empty windows, zeros in q), and the tracker both ways."""
    rng = np.random.default_rng(0)
    frame = np.ascontiguousarray(rng.integers(0, 256, (45, 61, 3), dtype=np.uint8))
    inner2 = 1.0 / 1.25 ** 2
    for bits in (2, 3):
        nb = 1 << (3 * bits)
        q = rng.random(nb)
        q[rng.random(nb) < 0.3] = 0.0
        q /= q.sum()
        t = (rng.random(nb) < 0.5).astype(np.float64)
        for d in (1, 2):
            src = frame[::d, ::d]
            bins = colour_bins(src, bits)
            height, width = bins.shape
            for c, hx, hy in (((width / 2.0 + 0.3, height / 2.0 - 0.2), 9.4, 7.1), ((0.0, 0.0), 12.5, 5.0),
                              ((width - 1.0, height - 1.0), 3.3, 20.25), ((5.5, 3.5), 0.3, 0.4),
                              ((7.25, 9.75), 80.0, 60.0)):
                for kernel in ("flat", "epanechnikov"):
                    if window_pass_numba(src, bits, q, t, c, hx, hy, inner2, kernel) != \
                            window_pass(bins, nb, q, t, c, hx, hy, inner2, kernel):
                        return False
    # the whole tracker (compiles _nb_track): a block moving on noise, both kernels, lost and found
    frames = []
    for i in range(6):
        f = rng.integers(0, 256, (48, 64, 3), dtype=np.uint8)
        if i != 3:  # frame 3: the target is gone
            f[10 + i:26 + i, 12 + 2 * i:30 + 2 * i] = (20, 40, 230)
        frames.append(f)
    # (and the joint colour x orientation bins with the scale test, off by default: the many-bins path)
    joint = {"orient_T": 32, "scale_test": 0.05, "scale_test_gate": True}
    for kernel, extra in (("flat", {}), ("epanechnikov", {}), ("flat", joint), ("epanechnikov", joint)):
        runs = []
        for path in ("numpy", "numba"):
            trk = FloatTrackerV2(TrackerParams(preset="v2", kernel=kernel, **extra), path=path)  # type: ignore[arg-type]
            trk._use_numba = path == "numba"  # (the self-check runs inside active_path)
            runs.append([trk.init(frames[0], (12, 10, 18, 16))] + [trk.update(f) for f in frames[1:]])
        if runs[0] != runs[1]:
            return False
    return True
