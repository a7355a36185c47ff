"""The public tracker: one API over the float reference and the fixed-point model."""
from __future__ import annotations

from typing import Any, Literal

import numpy as np

from .frames import FrameError
from .params import TrackerParams
from .types import Box, TrackResult

__all__ = ["Tracker", "TrackerParams", "FrameError"]


class Tracker:
    """Mean-shift colour + edge fusion tracker.

    Parameters
    ----------
    model : {"float", "fixed"}
        "float": the reference algorithm in floating point; "fixed": the
        bit-accurate model of the hardware (:mod:`mstrack.fixed`).
    **params
        :class:`TrackerParams` fields (features, kernel, colour_bits, ...) and,
        for model="fixed", :class:`mstrack.fixed.FixedParams` fields.

    Examples
    --------
    >>> trk = Tracker(model="float", features="fused", kernel="flat")
    >>> res = trk.init(frame0, (x, y, w, h))        # doctest: +SKIP
    >>> res = trk.update(frame1); res.box            # doctest: +SKIP
    """

    def __init__(self, model: Literal["float", "fixed"] = "float", **params: Any) -> None:
        tp, rest = TrackerParams.split(params)
        if model == "float":
            if rest:
                raise TypeError(f"unknown parameters for the float model: {sorted(rest)}")
            if tp.preset == "v2":
                from .float_v2 import FloatTrackerV2
                self._impl: Any = FloatTrackerV2(tp)
            else:
                from .float_model import FloatTracker
                self._impl = FloatTracker(tp)
        elif model == "fixed":
            from .fixed import FixedParams, FixedTracker
            fp, rest = FixedParams.split(rest)
            if rest:
                raise TypeError(f"unknown parameters: {sorted(rest)}")
            if tp.preset == "v2":
                from .fixed.tracker_v2 import FixedTrackerV2
                self._impl = FixedTrackerV2(tp, fp)
            else:
                self._impl = FixedTracker(tp, fp)
        else:
            raise ValueError(f"model must be 'float' or 'fixed', got {model!r}")
        self.model = model
        self.params = tp

    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        """Learn the target model from ``box`` (0-based x, y, w, h) in ``frame`` (BGR uint8)."""
        return self._impl.init(frame, box)

    def update(self, frame: np.ndarray) -> TrackResult:
        """Track the target into ``frame``; raises :class:`FrameError` on a bad frame (state kept)."""
        return self._impl.update(frame)

    @property
    def impl(self) -> Any:
        """The underlying FloatTracker / FixedTracker (for traces and raw integers)."""
        return self._impl
