"""Experimental feature and fusion variants of tracker v2 (docs/results_v2_features.md).

Used by ``studies/v2_features.py`` to measure, on the dev sequences, whether an
edge feature helps tracker v2 (:mod:`mstrack.track.float_v2`) and how to fuse it.
Nothing here changes :class:`~mstrack.track.float_v2.FloatTrackerV2`; the pieces
it is built from (:func:`~mstrack.track.float_v2.window_pixels`,
:func:`~mstrack.track.float_v2.background_model`,
:func:`~mstrack.track.float_v2.window_pass`) are reused as they are.

Features (bin images on the decimated grid, see :mod:`mstrack.track.float_v2`):

* ``colour``: :func:`~mstrack.track.float_model.colour_bins` (3 bits/channel, 512 bins).
* ``orient`` (T): orientation of the 3x3 Sobel gradient of the grey image,
  quantised to 8 octants in hardware form (no atan): bin = 4 [Gx < 0] +
  2 [Gy < 0] + [|Gy| > |Gx|] for pixels with |Gx| + |Gy| >= T, bin 8 for the
  flatter ones (9 bins).
* ``mag``: the paper's 16-bin magnitude histogram,
  min(15, floor((|Gx| + |Gy|) / 32)) (:func:`~mstrack.track.float_model.edge_bins`).
* ``joint`` (T, b): colour at b bits/channel x orient(T): 2**(3b) x 9 bins,
  one feature.

The Sobel runs on the full-resolution frame (as a streaming line-buffer
Sobel would) and is then decimated with the colour bins.

:class:`MultiFeatureV2` is FloatTrackerV2 with a list of features: the first
("main") feature plays the colour feature's role everywhere (confidence,
scale, loss and the wide search); an optional second feature runs its own
mean shift from the same start and the two centres are fused by a rule
(``fusion``):

* ``rho``: alpha_f = rho_f / (rho_main + rho_second) (the paper's rule);
* ``disc``: alpha_f proportional to max(d_f, 0), d_f = rho_f - rho_bg_f,
  rho_bg_f the Bhattacharyya coefficient of the feature's background-ring
  histogram (init box's ring in the init frame) against its target model;
  main feature alone if both d_f <= 0;
* ``disc_frame``: as ``disc`` with rho_bg_f re-measured every frame on the
  ring around the box just found (used for the next frame; one more pass per
  feature over the ring);
* ``wta``: winner takes all by d_f (the second feature only where it
  discriminates better);
* ``tie``: main feature unless its confidence is below ``conf_uncertain``,
  then ``disc``.

With a single feature ``colour`` the class reproduces FloatTrackerV2's boxes
(checked by the tool before it reports); its status is v2's search state
(``decide_status``), without v2's loss flag.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .features import colour_bins, edge_bins, grey_area
from .frames import check_frame, clip_box
from .float_v2 import (PassV2, background_model, confidence, decide_status, decimation, meanshift_v2, rescale,
                       search_starts, window_pass)
from .params import TrackerParams
from .types import Box, Status, TrackResult, box_centre_index, box_from_centre_index

FUSIONS = ("rho", "disc", "disc_frame", "wta", "tie")


@dataclass(frozen=True)
class Feature:
    """A per-pixel feature: ``kind`` in colour / orient / mag / joint; ``T`` the |G| threshold
    of orient / joint; ``bits`` the colour bits per channel of colour / joint."""

    kind: str
    T: int = 64
    bits: int = 3

    @property
    def n_bins(self) -> int:
        if self.kind == "colour":
            return 1 << (3 * self.bits)
        if self.kind == "orient":
            return 9
        if self.kind == "mag":
            return 16
        if self.kind == "joint":
            return (1 << (3 * self.bits)) * 9
        raise ValueError(self.kind)

    @property
    def label(self) -> str:
        if self.kind == "colour":
            return f"colour{self.bits}b"
        if self.kind == "orient":
            return f"orient(T={self.T})"
        if self.kind == "mag":
            return "mag16"
        return f"colour{self.bits}b x orient(T={self.T})"


def sobel(frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gx, Gy (float32) of the 3x3 Sobel on the float32 grey image; 0 on the 1-px frame border.

    Element-wise float32 operations in a fixed order (so the numba kernel,
    float_v2._nb_joint_run, computes the same values pixel by pixel):
    Gx = (d[y-1] + d[y+1]) + 2 d[y] with d = g[x+1] - g[x-1] (the row difference), and
    Gy = s[y+1] - s[y-1] with s = (g[x-1] + g[x+1]) + 2 g[x] (the row smoothing).  This is
    cv2.Sobel(grey, CV_32F, ksize=3)'s order in its vector loop: equal to it bit for bit on
    frames whose width is a multiple of 8 (every dev sequence); OpenCV's scalar tail (the last
    columns of other widths) may round differently.  (Before: cv2.Sobel itself.)"""
    g = grey_area(frame, 0, frame.shape[1], 0, frame.shape[0])
    gx = np.zeros_like(g)
    gy = np.zeros_like(g)
    if g.shape[0] >= 3 and g.shape[1] >= 3:
        two = np.float32(2)
        d = g[:, 2:] - g[:, :-2]
        gx[1:-1, 1:-1] = (d[:-2] + d[2:]) + d[1:-1] * two
        sm = (g[:, :-2] + g[:, 2:]) + g[:, 1:-1] * two
        gy[1:-1, 1:-1] = sm[2:] - sm[:-2]
    return gx, gy


def orientation_bins(gx: np.ndarray, gy: np.ndarray, T: float) -> np.ndarray:
    """Octant 4 [Gx < 0] + 2 [Gy < 0] + [|Gy| > |Gx|] where |Gx| + |Gy| >= T, else 8 (flat)."""
    ax, ay = np.abs(gx), np.abs(gy)
    octant = (gx < 0).astype(np.intp) * 4 + (gy < 0) * 2 + (ay > ax)
    return np.where(ax + ay >= T, octant, 8)


class _FrameFeatures:
    """Feature images of one frame (the Sobel computed once, shared)."""

    def __init__(self, frame: np.ndarray) -> None:
        self.frame = frame
        self._g: tuple[np.ndarray, np.ndarray] | None = None

    def grad(self) -> tuple[np.ndarray, np.ndarray]:
        if self._g is None:
            self._g = sobel(self.frame)
        return self._g

    def bins(self, f: Feature, d: int) -> np.ndarray:
        if f.kind == "colour":
            return colour_bins(self.frame[::d, ::d], f.bits)
        if f.kind == "mag":
            return edge_bins(self.frame, 16, 5)[::d, ::d]
        gx, gy = self.grad()
        o = orientation_bins(gx[::d, ::d], gy[::d, ::d], f.T)
        if f.kind == "orient":
            return o
        return colour_bins(self.frame[::d, ::d], f.bits) * 9 + o


def ring_histogram(bins: np.ndarray, n_bins: int, cx: float, cy: float, w: float, h: float,
                   ring: float) -> np.ndarray:
    """Normalised histogram of the background ring of :func:`~mstrack.track.float_v2.background_model`."""
    height, width = bins.shape
    gx, gy = ring * w, ring * h
    x0, x1 = max(0, math.ceil(cx - w / 2 - gx)), min(width - 1, math.floor(cx + w / 2 + gx))
    y0, y1 = max(0, math.ceil(cy - h / 2 - gy)), min(height - 1, math.floor(cy + h / 2 + gy))
    yy, xx = np.mgrid[y0:y1 + 1, x0:x1 + 1]
    outside = (np.abs(xx - cx) > w / 2.0) | (np.abs(yy - cy) > h / 2.0)
    o = np.bincount(bins[yy[outside], xx[outside]], minlength=n_bins).astype(np.float64)
    s = o.sum()
    return o / s if s > 0 else o


class MultiFeatureV2:
    """Tracker v2 with a main feature and an optional second feature fused by ``fusion``.

    ``final_pass``: after fusion, confidence and scale come from a main-feature pass at the fused
    centre (one more pass per frame) instead of the main feature's pass at its own centre.
    """

    def __init__(self, features: list[Feature], fusion: str = "rho", params: TrackerParams | None = None,
                 final_pass: bool = False) -> None:
        if not 1 <= len(features) <= 2:
            raise ValueError("one or two features")
        if fusion not in FUSIONS:
            raise ValueError(f"fusion must be one of {FUSIONS}")
        self.features = list(features)
        self.fusion = fusion
        self.final_pass = final_pass
        self.params = params or TrackerParams(preset="v2")
        self._shape: tuple[int, int] | None = None

    def decimation(self, w: float, h: float) -> int:
        return decimation(w, h, self.params)

    def _track(self, k: int, bins: np.ndarray, start: tuple[float, float], hx: float, hy: float,
               max_iter: int) -> tuple[tuple[float, float], PassV2, int]:
        """FloatTrackerV2's mean shift (:func:`meanshift_v2`) for feature k."""
        return meanshift_v2(bins, self.features[k].n_bins, self._qb[k], self._t[k], start, hx, hy,
                            self.params, max_iter)

    def _confidence(self, ps: PassV2) -> float:
        return confidence(ps, self._rho_ref, self._share_ref)

    def _rho_bg(self, k: int, bins: np.ndarray, cx: float, cy: float, w: float, h: float) -> float:
        o = ring_histogram(bins, self.features[k].n_bins, cx, cy, w, h, self.params.bg_ring)
        return float(np.sqrt(o * self._qb[k]).sum())

    def _alphas(self, rho: list[float], conf: float) -> tuple[float, float]:
        if self.fusion == "rho":
            s = rho[0] + rho[1]
            a = rho[0] / s if s > 0 else 0.5
            return a, 1.0 - a
        if self.fusion == "tie" and conf >= self.params.conf_uncertain:
            return 1.0, 0.0
        d = [max(rho[k] - self._rbg[k], 0.0) for k in range(2)]
        if self.fusion == "wta":
            return (1.0, 0.0) if d[0] >= d[1] else (0.0, 1.0)
        s = d[0] + d[1]
        if s <= 0:
            return 1.0, 0.0
        return d[0] / s, d[1] / s

    # ------------------------------------------------------------------ API
    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        frame = check_frame(frame)
        height, width = frame.shape[:2]
        box, clipped = clip_box(Box.of(box), width, height)
        p = self.params
        self._shape = (height, width)
        cx, cy = box_centre_index(box)
        self._size = self._size0 = (box.w, box.h)
        self._centre = (cx, cy)
        d = self.decimation(box.w, box.h)
        ff = _FrameFeatures(frame)
        self._qb, self._t, self._rbg = [], [], []
        pad = 1.0 + p.pad
        for k, f in enumerate(self.features):
            bins = ff.bins(f, d)
            _, qb, t = background_model(bins, f.n_bins, cx / d, cy / d, box.w / d, box.h / d, p.bg_ring,
                                        p.kernel)
            self._qb.append(qb)
            self._t.append(t)
            self._rbg.append(self._rho_bg(k, bins, cx / d, cy / d, box.w / d, box.h / d))
            if k == 0:
                ps = window_pass(bins, f.n_bins, qb, t, (cx / d, cy / d), pad * box.w / 2 / d,
                                 pad * box.h / 2 / d, 1.0 / pad ** 2, p.kernel)
        self._rho_ref = ps.rho
        self._share_ref = ps.share
        self._spread_ref = ps.spread if ps.spread > 0 else 0.5 / pad ** 2
        self._lost = False
        return TrackResult(box=box, centre=(cx, cy), rho_c=ps.rho, rho_e=0.0, alpha_c=1.0, alpha_e=0.0,
                           iter_c=0, iter_e=0, status=Status.CLIPPED if clipped else Status.INIT,
                           confidence=1.0, extra={"decimation": d})

    def update(self, frame: np.ndarray) -> TrackResult:
        if self._shape is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p = self.params
        w, h = self._size
        d = self.decimation(w, h) * (2 if self._lost else 1)  # as FloatTrackerV2: lost at 2D
        ff = _FrameFeatures(frame)
        bins = [ff.bins(f, d) for f in self.features]
        pad = 1.0 + p.pad
        hx, hy = pad * w / 2.0 / d, pad * h / 2.0 / d
        inner2 = 1.0 / pad ** 2
        start = (self._centre[0] / d, self._centre[1] / d)
        n_iter = p.search_iter if self._lost else p.max_iter  # as FloatTrackerV2
        c, ps, it = self._track(0, bins[0], start, hx, hy, n_iter)
        conf = self._confidence(ps)
        ac, ae, it_e, rho_e = 1.0, 0.0, 0, 0.0
        if len(self.features) == 2:
            ce, pse, it_e = self._track(1, bins[1], start, hx, hy, n_iter)
            rho_e = pse.rho
            ac, ae = self._alphas([ps.rho, pse.rho], conf)
            if ae > 0:
                c = (ac * c[0] + ae * ce[0], ac * c[1] + ae * ce[1])
                if self.final_pass:
                    ps = window_pass(bins[0], self.features[0].n_bins, self._qb[0], self._t[0], c, hx, hy,
                                     inner2, p.kernel)
                    conf = self._confidence(ps)
        searched = 0
        if self._lost:
            for s0 in search_starts(start, hx, hy, p):
                c2, ps2, _ = self._track(0, bins[0], s0, hx, hy, p.search_iter)
                searched += 1
                conf2 = self._confidence(ps2)
                if conf2 > conf:
                    c, ps, conf = c2, ps2, conf2
        status = decide_status(conf, self._lost, p)
        self._lost = status == Status.LOST
        self._centre = (c[0] * d, c[1] * d)
        if status == Status.OK:
            a = p.ref_rate
            self._rho_ref += a * (ps.rho - self._rho_ref)
            self._share_ref += a * (ps.share - self._share_ref)
        if p.scale_gain > 0 and ps.nt > 0:
            est_rho = None
            if p.scale_test > 0:  # FloatTrackerV2._scale_test on the main feature at the final centre
                k0 = self.features[0].n_bins
                best, rho = 1.0, window_pass(bins[0], k0, self._qb[0], self._t[0], c, hx, hy, inner2, p.kernel).rho
                for sc in (1.0 - p.scale_test, 1.0 + p.scale_test):
                    r = window_pass(bins[0], k0, self._qb[0], self._t[0], c, sc * hx, sc * hy, inner2, p.kernel).rho
                    if r > rho:
                        best, rho = sc, r
                est_rho = best
            self._size = rescale((w, h), self._size0, ps.spread, self._spread_ref, self._shape, p, est_rho)
        if self.fusion == "disc_frame" and len(self.features) == 2 and status == Status.OK:
            # background rho re-measured on the ring around the box just found (for the next frame)
            for k in range(2):
                self._rbg[k] = self._rho_bg(k, bins[k], c[0], c[1], w / d, h / d)
        box = box_from_centre_index(*self._centre, *self._size)
        return TrackResult(box=box, centre=self._centre, rho_c=ps.rho, rho_e=rho_e, alpha_c=ac, alpha_e=ae,
                           iter_c=it, iter_e=it_e, status=status, confidence=conf,
                           extra={"decimation": d, "searched": searched})
