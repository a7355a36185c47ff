"""Float reference tracker: the paper's algorithm as written, the yardstick for accuracy.

Mean-shift (Comaniciu, Ramesh, Meer 2003) on a colour and an edge feature,
fused by their Bhattacharyya coefficients (Asadi & Niaraki Asli).  Every
equation is in docs/algorithm.md; coordinates are pixel-index coordinates
(pixel (i, j) at (i, j)), see :mod:`mstrack.track.types`.

Three paths compute the same numbers (:class:`FloatTracker` ``path``).  The
reference path (:func:`meanshift` on whole-frame bin images from
:func:`_features_full_frame`) is the algorithm as written.  The fast paths
compute bins only on a search area around the previous centre, grown when a
window leaves it, and evaluate the windows with few numpy calls
(:func:`_meanshift_area`) or in one numba kernel per feature and frame
(:func:`_nb_meanshift`, the default when numba is installed).  They do the same
floating-point operations in the same order, so bins, centres, rhos and stop
decisions are bit-identical (tests/test_speed_equivalence.py; speed: docs/bench.md).

The parts live in their own modules: :mod:`.features` (colour / edge bins), :mod:`.kernel`
(kernel window, histograms, reference mean-shift), :mod:`.area` (numpy fast path),
:mod:`.numba_kernels` (``@jit`` kernels).  This module is the tracker: fusion, the choice of
path, the numba driver and its self-check (whose state, ``_NUMBA_OK``, tracker v2 shares).  The
parts' names are imported here too, so ``mstrack.track.float_model.X`` names all of them; a
replaced ``kernel_window`` here selects the reference path.
"""
from __future__ import annotations

import math
import os
import warnings
from typing import cast

import numpy as np

from .frames import check_frame, clip_box
from .params import TrackerParams
from .types import Box, FeatureResult, Status, TrackResult, box_centre_index, box_from_centre_index
# the parts; names not used below are re-exported (mstrack.track.float_model.X names the whole reference)
from .features import (GREY_WEIGHTS_BGR, SOBEL_ALIGN, _features_full_frame, colour_bins, colour_bins_area,  # noqa: F401
                       edge_bins, edge_bins_area, edge_magnitude, grey_area)
from .kernel import _Window, bhattacharyya, bin_weights, histogram, kernel_window, meanshift  # noqa: F401
from .area import SEARCH_MARGIN, _Area, _meanshift_area, _Win, _window_histogram
from .numba_kernels import _nb_buffers, _nb_meanshift, _nb_sum, _nb_sum3, _numba_njit

_KERNEL_WINDOW = kernel_window  # a replaced module-level kernel_window selects the reference path
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
    A replaced module-level :func:`kernel_window` (mstrack.eval.agreement's
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
