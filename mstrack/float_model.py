"""Float reference tracker: the paper's algorithm as written, the yardstick for accuracy.

Mean-shift (Comaniciu, Ramesh, Meer 2003) on a colour and an edge feature,
fused by their Bhattacharyya coefficients (Asadi & Niaraki Asli).  Every
equation is in docs/algorithm.md; coordinates are pixel-index coordinates
(pixel (i, j) at (i, j)), see :mod:`mstrack.types`.

Three paths compute the same numbers (:class:`FloatTracker` ``path``).  The
reference path (:func:`meanshift` on whole-frame bin images from
:func:`_features_full_frame`) is the algorithm as written.  The fast paths
compute bins only on a search area around the previous centre, grown when a
window leaves it, and evaluate the windows with few numpy calls
(:func:`_meanshift_area`) or in one numba kernel per feature and frame
(:func:`_nb_meanshift`, the default when numba is installed).  They do the same
floating-point operations in the same order, so bins, centres, rhos and stop
decisions are bit-identical (tests/test_speed_equivalence.py; speed: docs/bench.md).
"""
from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np

from .frames import check_frame, clip_box
from .params import TrackerParams
from .types import Box, FeatureResult, Status, TrackResult, box_centre_index, box_from_centre_index

GREY_WEIGHTS_BGR = (0.114, 0.587, 0.299)  # grey = 0.299 R + 0.587 G + 0.114 B (ITU-R BT.601)


# ----------------------------------------------------------------------------- features
def colour_bins(frame: np.ndarray, bits: int) -> np.ndarray:
    """Colour bin per pixel: ((R >> s) << 2b) | ((G >> s) << b) | (B >> s), s = 8 - b.

    frame: (H, W, 3) uint8 BGR.  Returns (H, W) int32 in [0, 2**(3b)).
    """
    s = 8 - bits
    f = frame.astype(np.int32) >> s
    return (f[:, :, 2] << (2 * bits)) | (f[:, :, 1] << bits) | f[:, :, 0]


def edge_magnitude(frame: np.ndarray) -> np.ndarray:
    """|G| = |Gx| + |Gy| of the 3x3 Sobel on the float grey image.

    frame: (H, W, 3) uint8 BGR.  Returns (H, W) float32 in [0, 2040]; the
    1-pixel frame border has no full 3x3 neighbourhood and gets |G| = 0.
    """
    grey = grey_area(frame, 0, frame.shape[1], 0, frame.shape[0])
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    mag = np.abs(gx) + np.abs(gy)
    mag[0, :] = mag[-1, :] = 0
    mag[:, 0] = mag[:, -1] = 0
    return mag


def edge_bins(frame: np.ndarray, n_bins: int, shift: int) -> np.ndarray:
    """Edge bin per pixel: min(E - 1, floor(|G| / 2**shift)).  Returns (H, W) int32."""
    return np.minimum(n_bins - 1, np.floor(edge_magnitude(frame) / float(1 << shift))).astype(np.int32)


def _features_full_frame(frame: np.ndarray, params: TrackerParams) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Colour and edge bin images of the whole frame (None for an unused feature).

    The reference path: the search-area functions below must give exactly
    these values on every pixel they compute (tests/test_speed_equivalence.py).
    """
    use_c = params.features in ("fused", "colour")
    use_e = params.features in ("fused", "edge")
    bc = colour_bins(frame, params.colour_bits) if use_c else None
    be = edge_bins(frame, params.n_edge_bins, params.edge_shift) if use_e else None
    return bc, be


# ----------------------------------------------------------------------------- features on an area
# Column alignment of the Sobel strip (px).  OpenCV's separable filter rounds the vectorised
# columns, (a + c) + 2b, differently from its scalar tail, (a + 2b) + c, and which columns are
# which depends on the column's offset in the row and on the row width.  A strip that starts on
# a multiple of SOBEL_ALIGN (a multiple of every SIMD width) and either ends on one or runs to the
# frame's right edge puts every column in the same class as in the whole-frame call.
SOBEL_ALIGN = 64
_GREY_W = tuple(np.float32(w) for w in GREY_WEIGHTS_BGR)


def grey_area(frame: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """Float32 grey of ``frame[y0:y1, x0:x1]``: (B wb + G wg) + R wr, element-wise in float32.

    Every path (whole frame, search area, numba kernel) computes the grey with
    these operations in this order, so they agree bit for bit by construction.
    No BLAS product is used: a matrix product's rounding depends on the BLAS
    kernel (numpy 2.4 / OpenBLAS 0.3.31 rounds ``frame @ weights`` differently).
    """
    b, g, r = cv2.split(frame[y0:y1, x0:x1])
    wb, wg, wr = _GREY_W
    out = b.astype(np.float32)
    out *= wb
    t = g.astype(np.float32)
    t *= wg
    out += t
    t = r.astype(np.float32)
    t *= wr
    out += t
    return out


def colour_bins_area(frame: np.ndarray, bits: int, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """``colour_bins(frame, bits)[y0:y1, x0:x1]`` from those pixels only.  (y1-y0, x1-x0) intp."""
    s = 8 - bits
    b, g, r = cv2.split(frame[y0:y1, x0:x1])
    out = (r >> s).astype(np.intp)  # type: ignore[operator]  # uint8 channels
    out <<= 2 * bits
    t = (g >> s).astype(np.intp)  # type: ignore[operator]
    t <<= bits
    out |= t
    out |= b >> s  # type: ignore[operator]
    return out


def edge_bins_area(frame: np.ndarray, n_bins: int, shift: int, x0: int, x1: int, y0: int,
                   y1: int, dtype: type = np.intp, kernels: bool = False) -> np.ndarray:
    """``edge_bins(frame, n_bins, shift)[y0:y1, x0:x1]`` from the grey of the area plus 1 px.

    The Sobel runs on a strip of rows y0-1 .. y1 whose columns are aligned as
    SOBEL_ALIGN describes (grey outside the area's 1-px ring is left 0: it
    reaches no pixel of the area); the frame border gets |G| = 0 as in
    :func:`edge_magnitude`.  ``kernels``: grey and bins by the numba kernels
    (one pass each, same float32 operations).  Returns (y1-y0, x1-x0) ``dtype``.
    """
    height, width = frame.shape[:2]
    gx0, gx1 = max(x0 - 1, 0), min(x1 + 1, width)
    gy0, gy1 = max(y0 - 1, 0), min(y1 + 1, height)
    sx0 = gx0 - gx0 % SOBEL_ALIGN
    sx1 = -(-gx1 // SOBEL_ALIGN) * SOBEL_ALIGN
    if sx1 > width - SOBEL_ALIGN:
        sx1 = width
    whole = (sx0, sx1) == (gx0, gx1)
    if kernels:
        strip = (np.empty if whole else np.zeros)((gy1 - gy0, sx1 - sx0), np.float32)
        _nb_grey(frame, gx0, gx1, gy0, gy1, strip, gx0 - sx0)
    elif whole:
        strip = grey_area(frame, gx0, gx1, gy0, gy1)
    else:
        strip = np.zeros((gy1 - gy0, sx1 - sx0), np.float32)
        strip[:, gx0 - sx0: gx1 - sx0] = grey_area(frame, gx0, gx1, gy0, gy1)
    r0, c0 = y0 - gy0, x0 - sx0
    gx = cv2.Sobel(strip, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(strip, cv2.CV_32F, 0, 1, ksize=3)
    if kernels:
        out: np.ndarray = np.empty((y1 - y0, x1 - x0), dtype)
        _nb_edge_bins(gx, gy, r0, c0, shift, n_bins - 1, out)
    else:
        mag = np.abs(gx[r0: r0 + y1 - y0, c0: c0 + x1 - x0])
        mag += np.abs(gy[r0: r0 + y1 - y0, c0: c0 + x1 - x0])
        # floor(|G| / 2**shift) of a non-negative float32 = int(|G|) >> shift
        out = mag.astype(dtype)
        out >>= shift
        np.minimum(out, n_bins - 1, out=out)
    if y0 == 0:         # the frame border: |G| = 0, bin 0
        out[0, :] = 0
    if y1 == height:
        out[-1, :] = 0
    if x0 == 0:
        out[:, 0] = 0
    if x1 == width:
        out[:, -1] = 0
    return out


# ----------------------------------------------------------------------------- mean shift
@dataclass
class _Window:
    """Pixels of the kernel window around a (continuous) centre, clipped to the frame."""

    xs: np.ndarray  # (n,) int column index of each inside pixel
    ys: np.ndarray  # (n,) int row index
    k: np.ndarray   # (n,) float kernel value


def kernel_window(cx: float, cy: float, hx: float, hy: float, kernel: str,
                  width: int, height: int) -> _Window:
    """Pixels with d2 = ((x-cx)/hx)^2 + ((y-cy)/hy)^2 < 1 inside the frame, and k(d2)."""
    x0 = max(0, math.ceil(cx - hx))
    x1 = min(width - 1, math.floor(cx + hx))
    y0 = max(0, math.ceil(cy - hy))
    y1 = min(height - 1, math.floor(cy + hy))
    xs = np.arange(x0, x1 + 1)
    ys = np.arange(y0, y1 + 1)
    d2 = ((xs[None, :] - cx) / hx) ** 2 + ((ys[:, None] - cy) / hy) ** 2
    inside = d2 < 1.0
    yy, xx = np.nonzero(inside)
    d2i = d2[yy, xx]
    k = np.ones_like(d2i) if kernel == "flat" else 1.0 - d2i
    return _Window(xs=xs[xx], ys=ys[yy], k=k)


def histogram(bins: np.ndarray, win: _Window, n_bins: int) -> np.ndarray:
    """Kernel-weighted, normalised histogram of ``bins`` over ``win`` (sums to 1)."""
    h = np.bincount(bins[win.ys, win.xs], weights=win.k, minlength=n_bins)
    total = h.sum()
    return h / total if total > 0 else h


def bhattacharyya(p: np.ndarray, q: np.ndarray) -> float:
    """rho = sum_u sqrt(p_u q_u)."""
    return float(np.sqrt(p * q).sum())


def bin_weights(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """w_u = sqrt(q_u / p_u), 0 where p_u = 0 (one weight per bin)."""
    w = np.zeros_like(q)
    nz = p > 0
    w[nz] = np.sqrt(q[nz] / p[nz])
    return w


def meanshift(bins: np.ndarray, q: np.ndarray, start: tuple[float, float], hx: float, hy: float,
              params: TrackerParams, n_bins: int) -> FeatureResult:
    """Run the mean-shift loop of one feature from ``start``; see docs/algorithm.md (Alg. 1).

    Each iteration: weights w from q and p(y0); y1 = sum(x w) / sum(w) over
    the window (flat shadow kernel); p(y1), rho(y1); stop and keep y0 if
    rho(y1) < rho(y0); stop with y1 if |y1 - y0|^2 < eps2; at most max_iter.
    """
    height, width = bins.shape

    def clamp(c: tuple[float, float]) -> tuple[float, float]:
        return (min(max(c[0], 0.0), width - 1.0), min(max(c[1], 0.0), height - 1.0))

    y0 = clamp(start)
    win0 = kernel_window(*y0, hx, hy, params.kernel, width, height)
    p0 = histogram(bins, win0, n_bins)
    rho0 = bhattacharyya(p0, q)
    for it in range(1, params.max_iter + 1):
        w = bin_weights(p0, q)[bins[win0.ys, win0.xs]]
        sw = w.sum()
        if sw <= 0:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="lost")
        y1 = clamp((float((w * win0.xs).sum() / sw), float((w * win0.ys).sum() / sw)))
        win1 = kernel_window(*y1, hx, hy, params.kernel, width, height)
        p1 = histogram(bins, win1, n_bins)
        rho1 = bhattacharyya(p1, q)
        if rho1 < rho0:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="rho")
        shift2 = (y1[0] - y0[0]) ** 2 + (y1[1] - y0[1]) ** 2
        y0, win0, p0, rho0 = y1, win1, p1, rho1
        if shift2 < params.eps2:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="shift")
    return FeatureResult(centre=y0, rho=rho0, iterations=params.max_iter, stop="max_iter")


# ----------------------------------------------------------------------------- fast path
_KERNEL_WINDOW = kernel_window  # a replaced module-level kernel_window selects the reference path
SEARCH_MARGIN = (0.125, 6)      # area = window box + (half-size / 8 + 6) px per side, grown on demand


class _Win:
    """One kernel window (as :func:`kernel_window`), kept as a mask over its bounding box.

    Inside pixels in row-major order, which is the order of ``np.nonzero`` in
    :func:`kernel_window`, so sums and bincounts over them round the same way.
    """

    __slots__ = ("x0", "x1", "y0", "y1", "inside", "k", "_xs", "_ys")

    def __init__(self, cx: float, cy: float, hx: float, hy: float, flat: bool, xf: np.ndarray,
                 yf: np.ndarray) -> None:
        width, height = len(xf), len(yf)
        self.x0 = x0 = max(0, math.ceil(cx - hx))
        self.x1 = x1 = min(width - 1, math.floor(cx + hx))
        self.y0 = y0 = max(0, math.ceil(cy - hy))
        self.y1 = y1 = min(height - 1, math.floor(cy + hy))
        d2 = np.add.outer(((yf[y0:y1 + 1] - cy) / hy) ** 2, ((xf[x0:x1 + 1] - cx) / hx) ** 2)
        self.inside = d2 < 1.0
        self.k = None if flat else 1.0 - d2[self.inside]
        self._xs: np.ndarray | None = None
        self._ys: np.ndarray | None = None

    def coords(self, xf: np.ndarray, yf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Column and row (float64) of each inside pixel."""
        if self._xs is None:
            shape = self.inside.shape
            self._xs = np.broadcast_to(xf[self.x0:self.x1 + 1], shape)[self.inside]
            self._ys = np.broadcast_to(yf[self.y0:self.y1 + 1, None], shape)[self.inside]
        assert self._ys is not None
        return self._xs, self._ys


class _Area:
    """Bins of one feature on a rectangle of one frame, computed when a window first needs them.

    ``compute(x0, x1, y0, y1)`` returns the bins of ``[y0, y1) x [x0, x1)``.  A
    window outside the rectangle recomputes it as the union of both, grown by the
    margin and clipped to the frame; the values never depend on the rectangle.
    """

    __slots__ = ("compute", "width", "height", "mx", "my", "box", "bins", "n_computed")

    def __init__(self, compute, width: int, height: int, mx: int, my: int) -> None:
        self.compute = compute
        self.width, self.height = width, height
        self.mx, self.my = mx, my
        self.box: tuple[int, int, int, int] | None = None  # x0, x1, y0, y1 (half-open)
        self.bins: np.ndarray | None = None
        self.n_computed = 0

    def ensure(self, x0: int, x1: int, y0: int, y1: int) -> tuple[int, int, int, int]:
        """Make the bins cover ``[y0, y1) x [x0, x1)``; returns the area's box (x0, x1, y0, y1)."""
        box = self.box
        if box is None or x0 < box[0] or x1 > box[1] or y0 < box[2] or y1 > box[3]:
            if box is not None:
                x0, x1, y0, y1 = min(x0, box[0]), max(x1, box[1]), min(y0, box[2]), max(y1, box[3])
            box = (max(0, x0 - self.mx), min(self.width, x1 + self.mx),
                   max(0, y0 - self.my), min(self.height, y1 + self.my))
            self.bins = self.compute(*box)
            self.box = box
            self.n_computed += 1
        return box

    def window_bins(self, win: _Win) -> np.ndarray:
        """Bins of the window's inside pixels (row-major order)."""
        box = self.ensure(win.x0, win.x1 + 1, win.y0, win.y1 + 1)
        assert self.bins is not None
        return self.bins[win.y0 - box[2]: win.y1 + 1 - box[2], win.x0 - box[0]: win.x1 + 1 - box[0]][win.inside]


def _window_histogram(b: np.ndarray, win: _Win, n_bins: int) -> np.ndarray:
    """:func:`histogram` from the window's bins ``b``: same values, bit for bit."""
    if win.k is None:
        # flat: bincount with unit weights counts exactly, and the total is the count
        return np.bincount(b, minlength=n_bins) / b.size if b.size else np.zeros(n_bins)
    h = np.bincount(b, weights=win.k, minlength=n_bins)
    total = h.sum()
    return h / total if total > 0 else h


def _meanshift_area(area: _Area, windows: dict, q: np.ndarray, start: tuple[float, float],
                    hx: float, hy: float, params: TrackerParams, n_bins: int, xf: np.ndarray,
                    yf: np.ndarray) -> FeatureResult:
    """:func:`meanshift` on an area's bins: the same steps, decisions and rounding.

    ``windows`` caches windows by centre for one frame (both features start at
    the same centre).
    """
    width, height = len(xf), len(yf)
    flat = params.kernel == "flat"

    def window(c: tuple[float, float]) -> _Win:
        w = windows.get(c)
        if w is None:
            w = windows[c] = _Win(c[0], c[1], hx, hy, flat, xf, yf)
        return w

    def clamp(c: tuple[float, float]) -> tuple[float, float]:
        return (min(max(c[0], 0.0), width - 1.0), min(max(c[1], 0.0), height - 1.0))

    y0 = clamp(start)
    win0 = window(y0)
    b0 = area.window_bins(win0)
    p0 = _window_histogram(b0, win0, n_bins)
    rho0 = float(np.sqrt(p0 * q).sum())
    for it in range(1, params.max_iter + 1):
        wb = np.zeros_like(q)
        np.divide(q, p0, out=wb, where=p0 > 0)
        w = np.sqrt(wb, out=wb).take(b0)
        sw = w.sum()
        if sw <= 0:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="lost")
        xs, ys = win0.coords(xf, yf)
        y1 = clamp((float((w * xs).sum() / sw), float((w * ys).sum() / sw)))
        win1 = window(y1)
        b1 = area.window_bins(win1)
        p1 = _window_histogram(b1, win1, n_bins)
        rho1 = float(np.sqrt(p1 * q).sum())
        if rho1 < rho0:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="rho")
        shift2 = (y1[0] - y0[0]) ** 2 + (y1[1] - y0[1]) ** 2
        y0, win0, b0, p0, rho0 = y1, win1, b1, p1, rho1
        if shift2 < params.eps2:
            return FeatureResult(centre=y0, rho=rho0, iterations=it, stop="shift")
    return FeatureResult(centre=y0, rho=rho0, iterations=params.max_iter, stop="max_iter")


# ----------------------------------------------------------------------------- numba kernels
# The same loop compiled with numba, when it is installed and passes _numba_ready()'s self-check
# (otherwise the numpy fast path above runs).  It gives the same results bit for bit because it
# does the same IEEE double operations in the same order: numpy's pairwise summation is
# replicated by _nb_sum / _nb_sum3, bincount's sequential sums by the scan, and the one
# Python-float operation, shift2 = dx ** 2 + dy ** 2 (libm pow, which may round x ** 2
# differently from x * x), is left to Python whenever that could change the stop decision.
# The colour bins are computed from the frame's pixels inside the scan (no colour area).
try:
    from numba import njit as _numba_njit
except ImportError:  # pragma: no cover - numba is a declared dependency
    _numba_njit = None  # type: ignore[assignment]


def _jit(fn):
    """numba.njit with an on-disk cache (compiled once per install); plain ``fn`` without numba."""
    if _numba_njit is None:
        return fn
    try:
        return _numba_njit(cache=True, nogil=True, error_model="numpy")(fn)
    except RuntimeError:  # no writable cache location: compile in every process
        return _numba_njit(nogil=True, error_model="numpy")(fn)


_PW_BLOCK = 128            # numpy's PW_BLOCKSIZE (numpy/_core/src/umath/loops_utils.h.src)
_SHIFT2_BAND = 1e-9        # |dx*dx + dy*dy - eps2| <= band * eps2: Python decides the shift test


_WB, _WG, _WR = _GREY_W  # float32 constants: numba multiplies float32 by float32 in float32


@_jit
def _nb_grey(frame, x0, x1, y0, y1, out, c0):
    """:func:`grey_area` of [y0, y1) x [x0, x1) into ``out[:, c0:]``: (B wb + G wg) + R wr in float32."""
    for y in range(y0, y1):
        px = frame[y, x0:x1]
        row = out[y - y0, c0:c0 + x1 - x0]
        for k in range(x1 - x0):
            row[k] = (np.float32(px[k, 0]) * _WB + np.float32(px[k, 1]) * _WG) + np.float32(px[k, 2]) * _WR


@_jit
def _nb_edge_bins(gx, gy, r0, c0, shift, top, out):
    """out = min(top, int(|gx| + |gy|) >> shift) on the window of gx, gy at (r0, c0) (float32 |G|)."""
    w = out.shape[1]
    for i in range(out.shape[0]):
        a, b, row = gx[r0 + i, c0:c0 + w], gy[r0 + i, c0:c0 + w], out[i]
        for j in range(w):
            row[j] = min(top, np.int32(abs(a[j]) + abs(b[j])) >> shift)


@_jit
def _nb_leaf(a, lo, n):
    """numpy's pairwise-sum leaf over a[lo:lo+n] (n <= 128): 8 accumulators, then the rest."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = lo + 8
    end = lo + n - n % 8
    while i < end:
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < lo + n:
        res += a[i]
        i += 1
    return res


@_jit
def _nb_sum(a, n):
    """numpy's ``a[:n].sum()`` bit for bit: 0 + pairwise sum.

    numpy halves a block (rounded down to a multiple of 8) until it is at most
    128 long; the recursion runs here on an explicit stack.
    """
    if n <= _PW_BLOCK:
        return 0.0 + _nb_leaf(a, 0, n)
    lo_s, n_s, st_s = np.empty(64, np.int64), np.empty(64, np.int64), np.empty(64, np.int64)
    vals = np.empty(64)
    sp, vp = 1, 0
    lo_s[0], n_s[0], st_s[0] = 0, n, 0
    while sp > 0:
        lo, m = lo_s[sp - 1], n_s[sp - 1]
        if m <= _PW_BLOCK:
            vals[vp] = _nb_leaf(a, lo, m)
            vp += 1
            sp -= 1
            continue
        half = m // 2
        half -= half % 8
        if st_s[sp - 1] == 0:      # left half
            st_s[sp - 1] = 1
            lo_s[sp], n_s[sp], st_s[sp] = lo, half, 0
            sp += 1
        elif st_s[sp - 1] == 1:    # right half
            st_s[sp - 1] = 2
            lo_s[sp], n_s[sp], st_s[sp] = lo + half, m - half, 0
            sp += 1
        else:                      # left + right
            vals[vp - 2] = vals[vp - 2] + vals[vp - 1]
            vp -= 1
            sp -= 1
    return 0.0 + vals[0]


@_jit
def _nb_leaf3(wb, B, X, Y, lo, n):
    """Three pairwise leaves at once: w = wb[B], sums of w, w * X and w * Y over [lo, lo+n)."""
    B, X, Y = B[lo:lo + n], X[lo:lo + n], Y[lo:lo + n]  # indices from 0: no negative-index checks
    if n < 8:
        s0 = s1 = s2 = 0.0
        for i in range(n):
            w = wb[B[i]]
            s0 += w
            s1 += w * X[i]
            s2 += w * Y[i]
        return s0, s1, s2
    w0, w1, w2, w3 = wb[B[0]], wb[B[1]], wb[B[2]], wb[B[3]]
    w4, w5, w6, w7 = wb[B[4]], wb[B[5]], wb[B[6]], wb[B[7]]
    a0, a1, a2, a3, a4, a5, a6, a7 = w0, w1, w2, w3, w4, w5, w6, w7
    b0, b1, b2, b3 = w0 * X[0], w1 * X[1], w2 * X[2], w3 * X[3]
    b4, b5, b6, b7 = w4 * X[4], w5 * X[5], w6 * X[6], w7 * X[7]
    c0, c1, c2, c3 = w0 * Y[0], w1 * Y[1], w2 * Y[2], w3 * Y[3]
    c4, c5, c6, c7 = w4 * Y[4], w5 * Y[5], w6 * Y[6], w7 * Y[7]
    end = n - n % 8
    for i in range(8, end, 8):
        w0, w1, w2, w3 = wb[B[i]], wb[B[i + 1]], wb[B[i + 2]], wb[B[i + 3]]
        w4, w5, w6, w7 = wb[B[i + 4]], wb[B[i + 5]], wb[B[i + 6]], wb[B[i + 7]]
        a0 += w0
        a1 += w1
        a2 += w2
        a3 += w3
        a4 += w4
        a5 += w5
        a6 += w6
        a7 += w7
        b0 += w0 * X[i]
        b1 += w1 * X[i + 1]
        b2 += w2 * X[i + 2]
        b3 += w3 * X[i + 3]
        b4 += w4 * X[i + 4]
        b5 += w5 * X[i + 5]
        b6 += w6 * X[i + 6]
        b7 += w7 * X[i + 7]
        c0 += w0 * Y[i]
        c1 += w1 * Y[i + 1]
        c2 += w2 * Y[i + 2]
        c3 += w3 * Y[i + 3]
        c4 += w4 * Y[i + 4]
        c5 += w5 * Y[i + 5]
        c6 += w6 * Y[i + 6]
        c7 += w7 * Y[i + 7]
    s0 = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7))
    s1 = ((b0 + b1) + (b2 + b3)) + ((b4 + b5) + (b6 + b7))
    s2 = ((c0 + c1) + (c2 + c3)) + ((c4 + c5) + (c6 + c7))
    for i in range(end, n):
        w = wb[B[i]]
        s0 += w
        s1 += w * X[i]
        s2 += w * Y[i]
    return s0, s1, s2


@_jit
def _nb_sum3(wb, B, X, Y, n):
    """numpy's ``w.sum(), (w * xs).sum(), (w * ys).sum()`` with w = wb[B], bit for bit (one pass)."""
    if n <= _PW_BLOCK:
        s0, s1, s2 = _nb_leaf3(wb, B, X, Y, 0, n)
        return 0.0 + s0, 0.0 + s1, 0.0 + s2
    lo_s, n_s, st_s = np.empty(64, np.int64), np.empty(64, np.int64), np.empty(64, np.int64)
    v0, v1, v2 = np.empty(64), np.empty(64), np.empty(64)
    sp, vp = 1, 0
    lo_s[0], n_s[0], st_s[0] = 0, n, 0
    while sp > 0:
        lo, m = lo_s[sp - 1], n_s[sp - 1]
        if m <= _PW_BLOCK:
            v0[vp], v1[vp], v2[vp] = _nb_leaf3(wb, B, X, Y, lo, m)
            vp += 1
            sp -= 1
            continue
        half = m // 2
        half -= half % 8
        if st_s[sp - 1] == 0:
            st_s[sp - 1] = 1
            lo_s[sp], n_s[sp], st_s[sp] = lo, half, 0
            sp += 1
        elif st_s[sp - 1] == 1:
            st_s[sp - 1] = 2
            lo_s[sp], n_s[sp], st_s[sp] = lo + half, m - half, 0
            sp += 1
        else:
            v0[vp - 2] = v0[vp - 2] + v0[vp - 1]
            v1[vp - 2] = v1[vp - 2] + v1[vp - 1]
            v2[vp - 2] = v2[vp - 2] + v2[vp - 1]
            vp -= 1
            sp -= 1
    return 0.0 + v0[0], 0.0 + v1[0], 0.0 + v2[0]


@_jit
def _nb_scan(cx, cy, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B, X, Y, h, ax, cnt):
    """:func:`kernel_window` and :func:`histogram` (unnormalised) at (cx, cy).

    Fills the inside pixels' bins B and coordinates X, Y in row-major order and
    h: counts (flat) or bincount's sequential kernel sums.  Bins come from the
    frame's pixels when ``bits`` > 0 (colour), else from ``bins`` at (ox, oy).
    Each row's inside pixels form one run: d2 = ax + by is unimodal in x (every
    step rounds monotonically), so two binary searches find it exactly.
    """
    x0 = max(0, math.ceil(cx - hx))
    x1 = min(width - 1, math.floor(cx + hx))
    y0 = max(0, math.ceil(cy - hy))
    y1 = min(height - 1, math.floor(cy + hy))
    nx = x1 - x0 + 1
    jc = 0
    for j in range(nx):
        t = (x0 + j - cx) / hx
        ax[j] = t * t
        if ax[j] < ax[jc]:
            jc = j
    h[:] = 0.0
    if flat:
        cnt[:] = 0
    s, s1, s2 = np.uint32(8 - bits), np.uint32(bits), np.uint32(2 * bits)
    mask = cnt.shape[0] - 1  # 4 tables, or 1 for very many bins
    n = 0
    for y in range(y0, y1 + 1):
        t = (y - cy) / hy
        by = t * t
        if not ax[jc] + by < 1.0:
            continue
        lo, hi = 0, jc
        while lo < hi:
            mid = (lo + hi) // 2
            if ax[mid] + by < 1.0:
                hi = mid
            else:
                lo = mid + 1
        ja = lo
        lo, hi = jc, nx - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if ax[mid] + by < 1.0:
                lo = mid
            else:
                hi = mid - 1
        m = lo - ja + 1
        xa = x0 + ja
        b, xs, ys = B[n:n + m], X[n:n + m], Y[n:n + m]
        if bits > 0:
            px = frame[y, xa:xa + m]
            for k in range(m):
                b[k] = (((np.uint32(px[k, 2]) >> s) << s2) | ((np.uint32(px[k, 1]) >> s) << s1)
                        | (np.uint32(px[k, 0]) >> s))
        else:
            row = bins[y - oy, xa - ox:xa - ox + m]
            for k in range(m):
                b[k] = row[k]
        for k in range(m):
            xs[k] = xa + k
            ys[k] = y
        if flat:  # integer counts in interleaved tables: no store-to-load chain on runs of one bin
            for k in range(m):
                cnt[(n + k) & mask, b[k]] += 1
        else:
            axr = ax[ja:ja + m]
            for k in range(m):
                h[b[k]] += 1.0 - (axr[k] + by)
        n += m
    if flat:
        for u in range(h.shape[0]):
            c = 0
            for r in range(cnt.shape[0]):
                c += cnt[r, u]
            h[u] = float(c)
    return n


@_jit
def _nb_normalise(h, q, n, flat, p, tmp):
    """p = h / sum(h) as :func:`histogram` normalises; returns rho(p, q)."""
    nb = h.shape[0]
    total = float(n) if flat else _nb_sum(h, nb)  # flat: the sum of the counts is the count, exactly
    for u in range(nb):
        if h[u] == 0.0:  # 0 / total and sqrt(0 * q) are 0: skip the division and the root
            p[u] = tmp[u] = 0.0
        else:
            p[u] = h[u] / total if total > 0 else h[u]
            tmp[u] = math.sqrt(p[u] * q[u]) if q[u] != 0.0 else 0.0
    return _nb_sum(tmp, nb)


@_jit
def _nb_outside(cx, cy, hx, hy, width, height, ox, oy, bw, bh):
    """True if the window box at (cx, cy) is not inside the area [ox, ox + bw) x [oy, oy + bh)."""
    return (max(0, math.ceil(cx - hx)) < ox or min(width - 1, math.floor(cx + hx)) >= ox + bw
            or max(0, math.ceil(cy - hy)) < oy or min(height - 1, math.floor(cy + hy)) >= oy + bh)


@_jit
def _nb_meanshift(frame, bits, bins, ox, oy, bw, bh, q, sx, sy, it0, hx, hy, width, height, flat,
                  max_iter, eps2, ibuf, fbuf, ax, cnt):
    """:func:`meanshift` from (sx, sy) after ``it0`` iterations (bins as in :func:`_nb_scan`).

    Returns (code, c0x, c0y, c1x, c1y, rho, it): code 0..3 a stop (centre c0);
    -1 the window at c1 leaves the bins' area [ox, ox + bw) x [oy, oy + bh) (grow
    it, resume from c0 after ``it`` iterations); -2 the shift test c0 -> c1 is
    left to Python (rho is rho(c1)).  Work buffers: :func:`_nb_buffers`.
    """
    nb = q.shape[0]
    B0, B1, X0, X1, Y0, Y1 = ibuf[0], ibuf[1], ibuf[2], ibuf[3], ibuf[4], ibuf[5]
    h, p0, p1, wb = fbuf[0, :nb], fbuf[1, :nb], fbuf[2, :nb], fbuf[3, :nb]
    tmp = wb  # rho's temporary: wb is rewritten before every use
    cnt = cnt[:, :nb]
    c0x = min(max(sx, 0.0), width - 1.0)
    c0y = min(max(sy, 0.0), height - 1.0)
    if _nb_outside(c0x, c0y, hx, hy, width, height, ox, oy, bw, bh):
        return -1, c0x, c0y, c0x, c0y, 0.0, it0
    n0 = _nb_scan(c0x, c0y, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B0, X0, Y0, h, ax, cnt)
    rho0 = _nb_normalise(h, q, n0, flat, p0, tmp)
    for it in range(it0 + 1, max_iter + 1):
        for u in range(nb):
            wb[u] = math.sqrt(q[u] / p0[u]) if p0[u] > 0 and q[u] != 0.0 else 0.0
        sw, swx, swy = _nb_sum3(wb, B0, X0, Y0, n0)
        if sw <= 0:
            return 3, c0x, c0y, c0x, c0y, rho0, it
        c1x = min(max(swx / sw, 0.0), width - 1.0)
        c1y = min(max(swy / sw, 0.0), height - 1.0)
        if _nb_outside(c1x, c1y, hx, hy, width, height, ox, oy, bw, bh):
            return -1, c0x, c0y, c1x, c1y, rho0, it - 1
        n1 = _nb_scan(c1x, c1y, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B1, X1, Y1, h, ax, cnt)
        rho1 = _nb_normalise(h, q, n1, flat, p1, tmp)
        if rho1 < rho0:
            return 1, c0x, c0y, c0x, c0y, rho0, it
        shift2 = (c1x - c0x) * (c1x - c0x) + (c1y - c0y) * (c1y - c0y)
        if abs(shift2 - eps2) <= _SHIFT2_BAND * eps2:
            return -2, c0x, c0y, c1x, c1y, rho1, it
        c0x, c0y, rho0, n0 = c1x, c1y, rho1, n1
        B0, B1, X0, X1, Y0, Y1, p0, p1 = B1, B0, X1, X0, Y1, Y0, p1, p0
        if shift2 < eps2:
            return 0, c0x, c0y, c0x, c0y, rho0, it
    return 2, c0x, c0y, c0x, c0y, rho0, max_iter


def _nb_buffers(hx: float, hy: float, n_bins: int) -> tuple[np.ndarray, ...]:
    """Work buffers of :func:`_nb_meanshift` for a target of half-sizes hx, hy (reused every frame).

    int32 bins and coordinates of two windows (6, box px); float64 histogram,
    two normalised histograms and the weights (4, bins); the column terms of
    d2 (box width); int32 counts (4 interleaved tables, 1 beyond 2**16 bins).
    """
    box_w = int(2.0 * hx) + 2
    return (np.empty((6, box_w * (int(2.0 * hy) + 2)), np.int32), np.empty((4, n_bins)),
            np.empty(box_w), np.empty((4 if n_bins <= 1 << 16 else 1, n_bins), np.int32))


_STOPS = ("shift", "rho", "max_iter", "lost")
_NO_BINS = np.zeros((1, 1), np.int32)


def _window_box(cx: float, cy: float, hx: float, hy: float, width: int,
                height: int) -> tuple[int, int, int, int]:
    """Bounding box (x0, x1, y0, y1), half-open, of the window at (cx, cy)."""
    return (max(0, math.ceil(cx - hx)), min(width - 1, math.floor(cx + hx)) + 1,
            max(0, math.ceil(cy - hy)), min(height - 1, math.floor(cy + hy)) + 1)


def _meanshift_numba(frame: np.ndarray, bits: int, area: _Area | None, q: np.ndarray,
                     start: tuple[float, float], hx: float, hy: float, params: TrackerParams,
                     width: int, height: int, bufs: tuple[np.ndarray, ...]) -> FeatureResult:
    """:func:`meanshift` with the numba kernel on colour bins of ``frame`` (``bits`` > 0) or
    the area's int32 bins (``bits`` = 0); same results bit for bit."""
    flat = params.kernel == "flat"
    max_iter, eps2 = int(params.max_iter), float(params.eps2)  # the types the kernel was compiled for
    sx, sy, it0 = float(start[0]), float(start[1]), 0
    bins, box = _NO_BINS, (0, width, 0, height)
    if area is not None and area.box is None:
        area.ensure(*_window_box(min(max(sx, 0.0), width - 1.0), min(max(sy, 0.0), height - 1.0),
                                 hx, hy, width, height))
    while True:
        if area is not None:
            assert area.bins is not None and area.box is not None
            bins, box = area.bins, area.box
        code, c0x, c0y, c1x, c1y, rho, it = _nb_meanshift(
            frame, bits, bins, box[0], box[2], box[1] - box[0], box[3] - box[2], q, sx, sy, it0,
            hx, hy, width, height, flat, max_iter, eps2, *bufs)
        if code >= 0:
            return FeatureResult(centre=(c0x, c0y), rho=rho, iterations=it, stop=_STOPS[code])
        if code == -1:    # grow the area, then redo the step from c0 (same numbers)
            assert area is not None
            area.ensure(*_window_box(c1x, c1y, hx, hy, width, height))
            sx, sy, it0 = c0x, c0y, it
        elif (c1x - c0x) ** 2 + (c1y - c0y) ** 2 < params.eps2:  # -2: meanshift's own test
            return FeatureResult(centre=(c1x, c1y), rho=rho, iterations=it, stop="shift")
        else:
            sx, sy, it0 = c1x, c1y, it


_NUMBA_OK: bool | None = None


def _numba_ready() -> bool:
    """Compile (or load) the numba kernels and check them against numpy; False: use numpy.

    MSTRACK_NUMBA=0 in the environment skips numba.  The check (which also
    warms up the JIT) compares the pairwise sums with numpy's at every block
    boundary, and small tracking problems with the numpy fast path.
    """
    global _NUMBA_OK
    if _NUMBA_OK is None:
        _NUMBA_OK = False
        if _numba_njit is not None and os.environ.get("MSTRACK_NUMBA", "1") != "0":
            try:
                _NUMBA_OK = _numba_self_check()
            except Exception as exc:  # noqa: BLE001 - any failure means: use numpy
                warnings.warn(f"mstrack: numba kernels disabled ({exc!r}); using numpy", RuntimeWarning)
            else:
                if not _NUMBA_OK:
                    warnings.warn("mstrack: numba kernels disagree with numpy here; using numpy",
                                  RuntimeWarning)
    return _NUMBA_OK


def _numba_self_check() -> bool:
    rng = np.random.default_rng(0)
    for n in (0, 1, 7, 8, 9, 15, 16, 17, 127, 128, 129, 255, 256, 257, 1000, 8191, 8192, 8193, 30011):
        w, x, y = rng.random(n) * 100.0, rng.integers(0, 640, n), rng.integers(0, 360, n)
        wb, idx = w.copy(), np.arange(n, dtype=np.int32)
        if _nb_sum(w, n) != w.sum() or _nb_sum3(wb, idx, x.astype(np.int32), y.astype(np.int32), n) != \
                (w.sum(), (w * x).sum(), (w * y).sum()):
            return False
    height, width = 40, 50
    frame = np.ascontiguousarray(rng.integers(0, 256, (height, width, 3), dtype=np.uint8))
    xf, yf = np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64)
    for x0, x1, y0, y1 in ((0, width, 0, height), (3, 31, 5, 22), (20, 49, 1, 39)):
        for n_bins, shift in ((16, 5), (256, 0)):
            want = edge_bins_area(frame, n_bins, shift, x0, x1, y0, y1)
            if not np.array_equal(edge_bins_area(frame, n_bins, shift, x0, x1, y0, y1, np.int32, True), want):
                return False
    bins = colour_bins_area(frame, 2, 0, width, 0, height)

    def crop(x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
        return bins[y0:y1, x0:x1].astype(np.int32)

    for kernel in ("flat", "epanechnikov"):
        params = TrackerParams(kernel=kernel, colour_bits=2, eps2=1e-6)
        win = _Win(24.5, 19.0, 7.5, 6.0, kernel == "flat", xf, yf)
        q = _window_histogram(bins[win.y0:win.y1 + 1, win.x0:win.x1 + 1][win.inside], win, 64)
        for start in ((21.25, 17.5), (30.0, 24.75)):
            want_ms = _meanshift_area(_Area(crop, width, height, 0, 0), {}, q, start, 7.5, 6.0, params, 64, xf, yf)
            for bits, area in ((2, None), (0, _Area(crop, width, height, 0, 0))):
                got = _meanshift_numba(frame, bits, area, q, start, 7.5, 6.0, params, width, height,
                                       _nb_buffers(7.5, 6.0, 64))
                if got != want_ms:
                    return False
    return True


def fuse(rc: FeatureResult | None, re: FeatureResult | None) -> tuple[tuple[float, float], float, float]:
    """Fusion: alpha_c = rho_c / (rho_c + rho_e), alpha_e = 1 - alpha_c; centre = sum alpha * c.

    A missing feature gets alpha 0; if both rhos are 0 the alphas are 1/2.
    """
    if re is None:
        assert rc is not None
        return rc.centre, 1.0, 0.0
    if rc is None:
        return re.centre, 0.0, 1.0
    s = rc.rho + re.rho
    ac = rc.rho / s if s > 0 else 0.5
    ae = 1.0 - ac
    return (ac * rc.centre[0] + ae * re.centre[0], ac * rc.centre[1] + ae * re.centre[1]), ac, ae


# ----------------------------------------------------------------------------- tracker
class FloatTracker:
    """The float reference tracker.  Use through :class:`mstrack.Tracker` (model="float").

    ``path`` picks how the same numbers are computed (module docstring):
    "reference" (whole-frame bins, :func:`meanshift`), "numpy" (search area,
    :func:`_meanshift_area`), "numba" (search area, :func:`_nb_meanshift`), or
    "auto": numba when it is installed and passes its self-check, else numpy.
    A replaced module-level :func:`kernel_window` (mstrack.agreement's
    window-grid analysis) selects the reference path, the one that calls it.
    """

    PATHS = ("auto", "numba", "numpy", "reference")

    def __init__(self, params: TrackerParams | None = None, path: str = "auto") -> None:
        if path not in self.PATHS:
            raise ValueError(f"path must be one of {self.PATHS}, got {path!r}")
        self.params = params or TrackerParams()
        self.path = path
        self._shape: tuple[int, int] | None = None
        self._q_c: np.ndarray | None = None
        self._q_e: np.ndarray | None = None
        self._centre: tuple[float, float] = (0.0, 0.0)
        self._size: tuple[float, float] = (0.0, 0.0)
        self._xf: np.ndarray | None = None
        self._yf: np.ndarray | None = None
        self.last_areas: tuple[_Area | None, _Area | None] = (None, None)
        self._bufs: tuple[np.ndarray, ...] | None = None

    @property
    def uses_colour(self) -> bool:
        return self.params.features in ("fused", "colour")

    @property
    def uses_edge(self) -> bool:
        return self.params.features in ("fused", "edge")

    def active_path(self) -> str:
        """The path :meth:`update` runs now: "reference", "numpy" or "numba"."""
        if self.path == "reference" or kernel_window is not _KERNEL_WINDOW:
            return "reference"
        if self.path == "numpy":
            return "numpy"
        if _numba_ready():
            return "numba"
        if self.path == "numba":
            raise RuntimeError("path='numba' but numba is not installed or failed its self-check")
        return "numpy"

    def _feature_images(self, frame: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        return _features_full_frame(frame, self.params)

    def _areas(self, frame: np.ndarray, numba: bool = False) -> tuple[_Area | None, _Area | None]:
        """Lazily computed colour and edge bins of ``frame`` (None for an unused feature).

        The numba path takes colour bins from the pixels (no colour area) and
        int32 edge bins.
        """
        p = self.params
        height, width = frame.shape[:2]
        hx, hy = self._size[0] / 2.0, self._size[1] / 2.0
        mx = int(SEARCH_MARGIN[0] * hx) + SEARCH_MARGIN[1]
        my = int(SEARCH_MARGIN[0] * hy) + SEARCH_MARGIN[1]
        dtype = np.int32 if numba else np.intp
        area_c = area_e = None
        if self.uses_colour and not numba:
            area_c = _Area(lambda x0, x1, y0, y1: colour_bins_area(frame, p.colour_bits, x0, x1, y0, y1),
                           width, height, mx, my)
        if self.uses_edge:
            area_e = _Area(lambda x0, x1, y0, y1: edge_bins_area(frame, p.n_edge_bins, p.edge_shift, x0, x1,
                                                                 y0, y1, dtype, numba), width, height, mx, my)
        return area_c, area_e

    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        frame = check_frame(frame)
        height, width = frame.shape[:2]
        box, clipped = clip_box(Box.of(box), width, height)
        self._size = (box.w, box.h)
        cx, cy = box_centre_index(box)
        hx, hy = box.w / 2.0, box.h / 2.0
        p = self.params
        self._xf = np.arange(width, dtype=np.float64)
        self._yf = np.arange(height, dtype=np.float64)
        if self.active_path() != "reference":  # (also compiles the numba kernels: not in update())
            win = _Win(cx, cy, hx, hy, p.kernel == "flat", self._xf, self._yf)
            area_c, area_e = self._areas(frame)
            self._q_c = _window_histogram(area_c.window_bins(win), win, p.n_colour_bins) if area_c else None
            self._q_e = _window_histogram(area_e.window_bins(win), win, p.n_edge_bins) if area_e else None
        else:
            kwin = kernel_window(cx, cy, hx, hy, p.kernel, width, height)
            bc, be = self._feature_images(frame)
            self._q_c = histogram(bc, kwin, p.n_colour_bins) if bc is not None else None
            self._q_e = histogram(be, kwin, p.n_edge_bins) if be is not None else None
        self._shape = (height, width)
        self._centre = (cx, cy)
        self._bufs = None
        has_c, has_e = self._q_c is not None, self._q_e is not None
        ac = 1.0 if p.features == "colour" else (0.0 if p.features == "edge" else 0.5)
        return TrackResult(box=box, centre=(cx, cy), rho_c=1.0 if has_c else 0.0,
                           rho_e=1.0 if has_e else 0.0, alpha_c=ac, alpha_e=1.0 - ac,
                           iter_c=0, iter_e=0, status=Status.CLIPPED if clipped else Status.INIT,
                           message="init box clipped to the frame" if clipped else "")

    def update(self, frame: np.ndarray) -> TrackResult:
        if self._shape is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p = self.params
        hx, hy = self._size[0] / 2.0, self._size[1] / 2.0
        path = self.active_path()
        q_c, q_e = cast(np.ndarray, self._q_c), cast(np.ndarray, self._q_e)  # set for the features in use
        if path == "numba":
            _, area_e = self.last_areas = self._areas(frame, numba=True)
            height, width = self._shape
            if self._bufs is None:
                self._bufs = _nb_buffers(hx, hy, max(p.n_colour_bins, p.n_edge_bins))
            rc = _meanshift_numba(frame, p.colour_bits, None, q_c, self._centre, hx, hy, p,
                                  width, height, self._bufs) if self.uses_colour else None
            re = _meanshift_numba(frame, 0, area_e, q_e, self._centre, hx, hy, p,
                                  width, height, self._bufs) if area_e else None
        elif path == "numpy":
            area_c, area_e = self.last_areas = self._areas(frame)
            windows: dict = {}
            xf, yf = cast(np.ndarray, self._xf), cast(np.ndarray, self._yf)  # set by init()
            rc = _meanshift_area(area_c, windows, q_c, self._centre, hx, hy, p, p.n_colour_bins,
                                 xf, yf) if area_c else None
            re = _meanshift_area(area_e, windows, q_e, self._centre, hx, hy, p, p.n_edge_bins,
                                 xf, yf) if area_e else None
        else:
            bc, be = self._feature_images(frame)
            rc = meanshift(bc, q_c, self._centre, hx, hy, p, p.n_colour_bins) if bc is not None else None
            re = meanshift(be, q_e, self._centre, hx, hy, p, p.n_edge_bins) if be is not None else None
        centre, ac, ae = fuse(rc, re)
        lost = all(r is None or r.stop == "lost" for r in (rc, re))
        self._centre = centre
        return TrackResult(
            box=box_from_centre_index(*centre, *self._size), centre=centre,
            rho_c=rc.rho if rc else 0.0, rho_e=re.rho if re else 0.0, alpha_c=ac, alpha_e=ae,
            iter_c=rc.iterations if rc else 0, iter_e=re.iterations if re else 0,
            status=Status.LOST if lost else Status.OK,
            extra={"stop_c": rc.stop if rc else None, "stop_e": re.stop if re else None,
                   "centre_c": rc.centre if rc else None, "centre_e": re.centre if re else None})
