"""The public tracker: one API over the float reference and the fixed-point model.

Two front ends over the same trackers:

* :class:`Tracker`: ``init(frame, box) -> TrackResult``, ``update(frame) -> TrackResult``
  (box, status, confidence, rho, ...);
* :class:`TrackerMeanShift`: OpenCV's tracker API, ``TrackerMeanShift.create()``,
  ``init(img, rect)``, ``update(img) -> (ok, rect)`` with an integer rect, so it drops into
  code written for ``cv2.TrackerCSRT`` / ``cv2.TrackerKCF``.

Both default to tracker v2 (``preset="v2"``), the best mstrack tracker measured (docs/results.md);
the paper's algorithm, which the RTL core implements today, is ``preset="paper"``.

Layout (README.md, "Package layout"): this module belongs to :mod:`mstrack.track`, which
:mod:`mstrack.fixed` builds on (params, types, frame checks), so ``Tracker(model="fixed")`` imports
the fixed-point model inside :meth:`Tracker.__init__`, not at module level: importing the float
tracker never loads the fixed model, there is no import cycle, and fixed still imports only
mstrack.track.  The float models are imported there too, so ``import mstrack`` stays light
(tests/test_layout.py allows track -> fixed only inside a function).
"""
from __future__ import annotations

from typing import Any, Literal

import numpy as np

from .frames import FrameError
from .params import Preset, TrackerParams
from .types import Box, TrackResult

__all__ = ["Tracker", "TrackerMeanShift", "TrackerParams", "FrameError", "DEFAULT_PRESET"]

#: Preset of :class:`Tracker` / :class:`TrackerMeanShift` when none is given: tracker v2, the best
#: measured (docs/results.md).  :class:`TrackerParams` itself defaults to "paper", the algorithm
#: of the RTL core (the fixed-point model, test vectors and co-simulation use it).
DEFAULT_PRESET: Preset = "v2"

Model = Literal["float", "fixed"]
BoxLike = Box | tuple[float, float, float, float] | list[float] | np.ndarray


class Tracker:
    """Mean-shift tracker (tracker v2 by default; the paper's colour + edge fusion on request).

    Parameters
    ----------
    model : {"float", "fixed"}
        "float": the reference algorithm in floating point; "fixed": the
        bit-accurate model of the hardware (:mod:`mstrack.fixed`).
    params : TrackerParams, optional
        All algorithm parameters at once (then ``**kwargs`` may only hold
        :class:`mstrack.fixed.FixedParams` fields).
    **kwargs
        :class:`TrackerParams` fields (``preset``, ``features``, ``kernel``,
        ``colour_bits``, ...; string values accept the aliases of
        :data:`mstrack.track.params.ALIASES`, e.g. ``kernel="epan"``, ``features="color"``) and, for
        model="fixed", :class:`mstrack.fixed.FixedParams` fields.  ``preset`` defaults to
        :data:`DEFAULT_PRESET` ("v2"); ``preset="paper"`` is the paper's algorithm
        (``features="fused"`` by default, also "colour" or "edge").

    Examples
    --------
    >>> trk = Tracker()                                  # tracker v2, float model
    >>> trk = Tracker(preset="paper", kernel="epan")     # the paper's fusion, Epanechnikov kernel
    >>> res = trk.init(frame0, (x, y, w, h))             # doctest: +SKIP
    >>> res = trk.update(frame1)                         # doctest: +SKIP
    >>> x, y, w, h = res.box; res.ok, res.confidence     # doctest: +SKIP
    """

    def __init__(self, model: Model = "float", params: TrackerParams | None = None, **kwargs: Any) -> None:
        if params is not None:
            if not isinstance(params, TrackerParams):
                raise TypeError(f"params must be a TrackerParams, got {type(params).__name__}")
            own = TrackerParams.field_names()
            names = sorted(k for k in kwargs if k in own)
            rest = {k: v for k, v in kwargs.items() if k not in own}
            if names:
                raise TypeError(f"give {names} either in params or as keywords, not both")
            tp = params
        else:
            kwargs.setdefault("preset", DEFAULT_PRESET)
            tp, rest = TrackerParams.split(kwargs)
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
            from ..fixed import FixedParams, FixedTracker
            fp, rest = FixedParams.split(rest)
            if rest:
                raise TypeError(f"unknown parameters: {sorted(rest)}")
            if tp.preset == "v2":
                from ..fixed.tracker_v2 import FixedTrackerV2
                self._impl = FixedTrackerV2(tp, fp)
            else:
                self._impl = FixedTracker(tp, fp)
        else:
            raise ValueError(f"model must be 'float' or 'fixed', got {model!r}")
        self.model: Model = model
        self.params: TrackerParams = tp

    def init(self, frame: np.ndarray, box: BoxLike) -> TrackResult:
        """Learn the target model from ``box`` in ``frame``.

        Parameters
        ----------
        frame : ndarray, shape (H, W, 3), uint8
            BGR image (OpenCV's channel order).
        box : Box or sequence of 4 numbers
            ``(x, y, w, h)``: left, top, width, height in 0-based pixels (see :mod:`mstrack.track.types`).

        Returns
        -------
        TrackResult
            Status "init", or "clipped" when the box was clipped to the frame or shrunk to the
            largest window (``message`` says to what).

        Raises
        ------
        FrameError
            Bad frame (shape, dtype, empty); ValueError for a bad box.
        """
        return self._impl.init(frame, box)

    def update(self, frame: np.ndarray) -> TrackResult:
        """Track the target into ``frame`` (ndarray (H, W, 3) uint8 BGR, the size of the init frame).

        Returns a :class:`TrackResult` (``box`` in pixels, ``ok``, ``confidence`` 0..1); raises
        :class:`FrameError` on a bad frame, keeping the tracker's state.
        """
        return self._impl.update(frame)

    @property
    def impl(self) -> Any:
        """The underlying FloatTracker / FloatTrackerV2 / FixedTracker / FixedTrackerV2 (for traces
        and raw integers)."""
        return self._impl


class TrackerMeanShift:
    """OpenCV-style front end: a drop-in for ``cv2.TrackerCSRT`` / ``cv2.TrackerKCF`` in code written
    for OpenCV's tracking API.

    >>> tracker = mstrack.TrackerMeanShift.create()     # instead of cv2.TrackerCSRT.create()
    >>> tracker.init(frame, (x, y, w, h))               # doctest: +SKIP
    >>> ok, (x, y, w, h) = tracker.update(frame)        # doctest: +SKIP

    ``rect`` values are integers (OpenCV's ``cv::Rect``: left, top, width, height in 0-based
    pixels; :meth:`Box.to_cv`).  ``ok`` is :attr:`TrackResult.ok` (False when tracker v2 reports
    the target lost or uncertain, or for a rejected frame; the rect then stays where it was).
    The full result of the last call (float box, confidence, status) is :attr:`last`.
    """

    def __init__(self, params: TrackerParams | None = None, model: Model = "float") -> None:
        self._tracker = Tracker(model=model, params=params if params is not None
                                else TrackerParams(preset=DEFAULT_PRESET))
        self.last: TrackResult | None = None

    @classmethod
    def create(cls, params: TrackerParams | None = None, model: Model = "float") -> "TrackerMeanShift":
        """A new tracker, as ``cv2.TrackerCSRT.create(params)``.

        Parameters
        ----------
        params : TrackerParams, optional
            Default ``TrackerParams(preset="v2")`` (tracker v2); ``TrackerParams(preset="paper")``
            for the paper's algorithm (the RTL core's).
        model : {"float", "fixed"}
            Float reference or the bit-accurate fixed-point model of the hardware.
        """
        return cls(params, model)

    @property
    def params(self) -> TrackerParams:
        return self._tracker.params

    @property
    def tracker(self) -> Tracker:
        """The :class:`Tracker` behind this front end."""
        return self._tracker

    def init(self, image: np.ndarray, boundingBox: BoxLike) -> None:  # noqa: N803 (OpenCV's name)
        """Initialise on ``image`` (ndarray (H, W, 3) uint8 BGR) with ``boundingBox`` ``(x, y, w, h)``
        in pixels (ints as OpenCV gives them, or floats).  Returns None, as OpenCV 4.5+ does."""
        self.last = self._tracker.init(image, boundingBox)

    def update(self, image: np.ndarray) -> tuple[bool, tuple[int, int, int, int]]:
        """Track into ``image`` (ndarray (H, W, 3) uint8 BGR); returns ``(ok, (x, y, w, h))``, the rect
        in integer pixels.  A bad frame gives ``(False, previous rect)`` instead of raising (as
        OpenCV's trackers report failure)."""
        if self.last is None:
            raise RuntimeError("update() before init()")
        try:
            self.last = self._tracker.update(image)
        except FrameError:
            return False, self.last.box.to_cv()
        return self.last.ok, self.last.box.to_cv()

    def getTrackingScore(self) -> float:  # noqa: N802 (OpenCV's name, as TrackerKCF / TrackerCSRT)
        """Confidence of the last result, 0..1 (:attr:`TrackResult.confidence`)."""
        return float(self.last.confidence) if self.last is not None else 0.0
