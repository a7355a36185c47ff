"""Float reference, mean shift: kernel window, histograms, Bhattacharyya coefficient, weights and
the reference mean-shift iteration on whole-frame bin images (Comaniciu, Ramesh, Meer 2003;
docs/algorithm.md).

:func:`meanshift` is the algorithm as written (the "reference" path of
:class:`~mstrack.track.float_model.FloatTracker`); the fast paths (:mod:`.area`,
:mod:`.numba_kernels`) reproduce it bit for bit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .params import TrackerParams
from .types import FeatureResult

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
