"""Float reference tracker: the paper's algorithm as written, the yardstick for accuracy.

Mean-shift (Comaniciu, Ramesh, Meer 2003) on a colour and an edge feature,
fused by their Bhattacharyya coefficients (Asadi & Niaraki Asli).  Every
equation is in docs/algorithm.md; coordinates are pixel-index coordinates
(pixel (i, j) at (i, j)), see :mod:`mstrack.types`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

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
    grey = frame.astype(np.float32) @ np.asarray(GREY_WEIGHTS_BGR, np.float32)
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    mag = np.abs(gx) + np.abs(gy)
    mag[0, :] = mag[-1, :] = 0
    mag[:, 0] = mag[:, -1] = 0
    return mag


def edge_bins(frame: np.ndarray, n_bins: int, shift: int) -> np.ndarray:
    """Edge bin per pixel: min(E - 1, floor(|G| / 2**shift)).  Returns (H, W) int32."""
    return np.minimum(n_bins - 1, np.floor(edge_magnitude(frame) / float(1 << shift))).astype(np.int32)


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
    """The float reference tracker.  Use through :class:`mstrack.Tracker` (model="float")."""

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params or TrackerParams()
        self._shape: tuple[int, int] | None = None
        self._q_c: np.ndarray | None = None
        self._q_e: np.ndarray | None = None
        self._centre: tuple[float, float] = (0.0, 0.0)
        self._size: tuple[float, float] = (0.0, 0.0)

    @property
    def uses_colour(self) -> bool:
        return self.params.features in ("fused", "colour")

    @property
    def uses_edge(self) -> bool:
        return self.params.features in ("fused", "edge")

    def _feature_images(self, frame: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        p = self.params
        bc = colour_bins(frame, p.colour_bits) if self.uses_colour else None
        be = edge_bins(frame, p.n_edge_bins, p.edge_shift) if self.uses_edge else None
        return bc, be

    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        frame = check_frame(frame)
        height, width = frame.shape[:2]
        box, clipped = clip_box(Box.of(box), width, height)
        self._size = (box.w, box.h)
        cx, cy = box_centre_index(box)
        hx, hy = box.w / 2.0, box.h / 2.0
        win = kernel_window(cx, cy, hx, hy, self.params.kernel, width, height)
        bc, be = self._feature_images(frame)
        self._q_c = histogram(bc, win, self.params.n_colour_bins) if bc is not None else None
        self._q_e = histogram(be, win, self.params.n_edge_bins) if be is not None else None
        self._shape = (height, width)
        self._centre = (cx, cy)
        ac = 1.0 if self.params.features == "colour" else (0.0 if self.params.features == "edge" else 0.5)
        return TrackResult(box=box, centre=(cx, cy), rho_c=1.0 if bc is not None else 0.0,
                           rho_e=1.0 if be is not None else 0.0, alpha_c=ac, alpha_e=1.0 - ac,
                           iter_c=0, iter_e=0, status=Status.CLIPPED if clipped else Status.INIT,
                           message="init box clipped to the frame" if clipped else "")

    def update(self, frame: np.ndarray) -> TrackResult:
        if self._shape is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p = self.params
        hx, hy = self._size[0] / 2.0, self._size[1] / 2.0
        bc, be = self._feature_images(frame)
        rc = meanshift(bc, self._q_c, self._centre, hx, hy, p, p.n_colour_bins) if bc is not None else None
        re = meanshift(be, self._q_e, self._centre, hx, hy, p, p.n_edge_bins) if be is not None else None
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
