"""Fixed-point tracker: the per-frame control of rtl/ms_tracker.vhd, bit for bit.

Frame n: capture the search region around the fused centre of frame n - 1,
run both features' mean-shift loops from that centre (clamped to the
region), fuse.  Raw integers of each frame are in ``TrackResult.extra``
(keys listed in :data:`RESULT_FIELDS`), which is what the RTL's result
stream carries and what the co-simulation compares.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..track.frames import check_frame
from ..track.params import TrackerParams
from ..track.types import Box, Status, TrackResult
from .blocks import (STOP_CODES, IntBox, Region, ms_box_clip, ms_fusion, ms_histogram, ms_kernel,
                     ms_meanshift, ms_region, ms_region_capture, ms_rho_out, ms_round_centre,
                     clamp_centre, init_centre, round_box)
from .formats import FixedParams, Widths, widths

# Integer fields of one result, as the RTL result stream carries them.
RESULT_FIELDS = ("cx", "cy", "rho_c", "rho_e", "alpha_c", "iter_c", "iter_e", "stop_c", "stop_e",
                 "lost", "error")


@dataclass
class _Target:
    box: IntBox
    ker: ms_kernel
    Q_c: np.ndarray
    Q_e: np.ndarray
    c8: tuple[int, int]


class FixedTracker:
    """Bit-accurate model of the hardware.  Use through :class:`mstrack.Tracker` (model="fixed")."""

    def __init__(self, params: TrackerParams | None = None, fixed: FixedParams | None = None) -> None:
        self.params = params or TrackerParams()
        self.fixed = fixed or FixedParams()
        self.widths: Widths = widths(self.params, self.fixed)
        self._shape: tuple[int, int] | None = None
        self._t: _Target | None = None
        self.last_trace: dict[str, Any] | None = None

    # -- helpers ---------------------------------------------------------------------------
    def _uses(self) -> tuple[bool, bool]:
        f = self.params.features
        return f in ("fused", "colour"), f in ("fused", "edge")

    def _to_float(self, c8: tuple[int, int]) -> tuple[float, float]:
        s = float(1 << self.fixed.centre_frac)
        return (c8[0] / s, c8[1] / s)

    def _box_at(self, c8: tuple[int, int]) -> Box:
        cx, cy = self._to_float(c8)
        assert self._t is not None, "init() first"
        b = self._t.box
        return Box(cx - (b.w - 1) / 2.0, cy - (b.h - 1) / 2.0, float(b.w), float(b.h))

    # -- API ---------------------------------------------------------------------------------
    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        """Round the float box to integers (edges half up) and initialise as the hardware does."""
        b = Box.of(box)
        if b.w <= 0 or b.h <= 0:
            raise ValueError(f"box must have positive width and height, got {b}")
        return self.init_int(frame, *round_box(*b.as_tuple()))

    def init_int(self, frame: np.ndarray, x: int, y: int, w: int, h: int,
                 trace: bool = False) -> TrackResult:
        """Initialise from an integer box, exactly as the RTL's init port does."""
        frame = check_frame(frame)
        fh, fw = frame.shape[:2]
        if fw >= (1 << self.fixed.coord_bits) or fh >= (1 << self.fixed.coord_bits):
            raise ValueError(f"frame {fw}x{fh} larger than coord_bits={self.fixed.coord_bits} allows")
        ib, clipped = ms_box_clip(x, y, w, h, fw, fh, self.fixed.max_half)
        if ib is None:
            raise ValueError(f"box ({x}, {y}, {w}, {h}) leaves less than 3x3 px inside the "
                             f"interior of the {fw}x{fh} frame")
        p, cf = self.params, self.fixed.centre_frac
        ker = ms_kernel(ib.w, ib.h, p.kernel, self.fixed.kernel_bits)
        c8 = init_centre(ib, cf)
        reg = ms_region(c8, ker.ex, ker.ey, fw, fh, self.fixed)
        c8 = clamp_centre(c8, reg, cf)
        win = (ms_round_centre(c8[0], cf), ms_round_centre(c8[1], cf))
        colour, edge = ms_region_capture(frame, reg, p)
        Q_c = ms_histogram(colour, reg, win, ker, p.n_colour_bins).H
        Q_e = ms_histogram(edge, reg, win, ker, p.n_edge_bins).H
        self._shape = (fh, fw)
        self._t = _Target(ib, ker, Q_c, Q_e, c8)
        one = 1 << self.fixed.rho_out_frac
        a_one = 1 << self.fixed.alpha_frac
        a_c = {"colour": a_one, "edge": 0}.get(p.features, a_one >> 1)
        raw = {"cx": c8[0], "cy": c8[1], "rho_c": one, "rho_e": one, "alpha_c": a_c, "iter_c": 0,
               "iter_e": 0, "stop_c": 0, "stop_e": 0, "lost": 0, "error": 0,
               "box": [ib.x, ib.y, ib.w, ib.h], "K": ker.K}
        if trace:
            self.last_trace = {"init": True, "region": [reg.x, reg.y, reg.w, reg.h],
                               "colour_bins": colour.tolist(), "edge_bins": edge.tolist(),
                               "Q_c": Q_c.tolist(), "Q_e": Q_e.tolist(), "result": raw}
        return TrackResult(box=self._box_at(c8), centre=self._to_float(c8), rho_c=1.0, rho_e=1.0,
                           alpha_c=a_c / a_one, alpha_e=1 - a_c / a_one, iter_c=0, iter_e=0,
                           status=Status.CLIPPED if clipped else Status.INIT,
                           message="init box clipped" if clipped else "", extra=raw)

    def update(self, frame: np.ndarray, trace: bool = False) -> TrackResult:
        """Track one frame.  Bad frames raise FrameError and leave the state unchanged."""
        if self._t is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p, fx, t = self.params, self.fixed, self._t
        cf = fx.centre_frac
        assert self._shape is not None
        fh, fw = self._shape
        reg: Region = ms_region(t.c8, t.ker.ex, t.ker.ey, fw, fh, fx)
        colour, edge = ms_region_capture(frame, reg, p)
        use_c, use_e = self._uses()
        sq = self.widths.shift_q
        rc = ms_meanshift(colour, t.Q_c, t.c8, reg, t.ker, p, fx, p.n_colour_bins, sq, trace) if use_c else None
        re = ms_meanshift(edge, t.Q_e, t.c8, reg, t.ker, p, fx, p.n_edge_bins, sq, trace) if use_e else None
        S_c = rc.S if rc else 0
        S_e = re.S if re else 0
        c8, a_c, a_e = ms_fusion(S_c, S_e, rc.c8 if rc else (0, 0), re.c8 if re else (0, 0),
                                 p.features, fx.alpha_frac)
        t.c8 = c8
        lost = all(r is None or r.stop == "lost" for r in (rc, re))
        rho_c = ms_rho_out(S_c, t.ker.K, fx) if rc else 0
        rho_e = ms_rho_out(S_e, t.ker.K, fx) if re else 0
        raw = {"cx": c8[0], "cy": c8[1], "rho_c": rho_c, "rho_e": rho_e, "alpha_c": a_c,
               "iter_c": rc.iterations if rc else 0, "iter_e": re.iterations if re else 0,
               "stop_c": STOP_CODES[rc.stop] if rc else 0, "stop_e": STOP_CODES[re.stop] if re else 0,
               "lost": int(lost), "error": 0, "region": [reg.x, reg.y, reg.w, reg.h],
               "S_c": S_c, "S_e": S_e, "centre_c": list(rc.c8) if rc else None,
               "centre_e": list(re.c8) if re else None}
        if trace:
            self.last_trace = {"init": False, "region": [reg.x, reg.y, reg.w, reg.h],
                               "colour_bins": colour.tolist(), "edge_bins": edge.tolist(),
                               "iter_colour": rc.trace if rc else [], "iter_edge": re.trace if re else [],
                               "result": raw}
        one_r = float(1 << fx.rho_out_frac)
        one_a = float(1 << fx.alpha_frac)
        return TrackResult(
            box=self._box_at(c8), centre=self._to_float(c8), rho_c=rho_c / one_r, rho_e=rho_e / one_r,
            alpha_c=a_c / one_a, alpha_e=a_e / one_a, iter_c=int(raw["iter_c"]), iter_e=int(raw["iter_e"]),  # type: ignore[call-overload]
            status=Status.LOST if lost else Status.OK,
            extra={**raw, "stop_c_name": rc.stop if rc else None, "stop_e_name": re.stop if re else None})
