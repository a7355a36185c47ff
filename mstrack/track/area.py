"""Float reference, numpy fast path: bins on a search area around the previous centre (grown when
a window leaves it) and the mean-shift windows evaluated with few numpy calls.

Same floating-point operations in the same order as :func:`mstrack.track.kernel.meanshift`, so
centres, rhos and stop decisions are bit-identical (tests/test_speed_equivalence.py).
"""
from __future__ import annotations

import math

import numpy as np

from .params import TrackerParams
from .types import FeatureResult

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
