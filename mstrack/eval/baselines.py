"""OpenCV baseline trackers with the mstrack ``init`` / ``update`` API.

* :class:`MeanShiftTracker` and :class:`CamShiftTracker` follow OpenCV's
  meanshift/camshift tutorial recipe: HSV, mask
  ``inRange((0, 60, 32), (180, 255, 255))``, a 180-bin hue histogram of the
  ROI normalised to 0..255, ``calcBackProject`` and ``cv2.meanShift`` /
  ``cv2.CamShift`` with criteria ``(EPS | COUNT, 10, 1)``.  CamShift reports
  the axis-aligned bounding rectangle of its rotated box.
* :class:`OpenCVTracker` wraps ``cv2.TrackerKCF`` / ``cv2.TrackerCSRT`` (from
  opencv-contrib; the ``cv2.legacy`` factories are used if the main ones are
  missing).

All return :class:`mstrack.track.types.TrackResult` (``rho_*`` / ``alpha_*`` are NaN:
these trackers have no such quantities).  Boxes are 0-based ``(x, y, w, h)``
(:mod:`mstrack.track.types`).  An init box partly outside the frame is clipped to
it (status ``CLIPPED``); a box with no pixel inside raises ``ValueError``.
Bad frames (not uint8 BGR, or a size other than the init frame's) raise
:class:`mstrack.FrameError` and leave the state unchanged.
"""
from __future__ import annotations

import math
from typing import Any, Callable

import cv2
import numpy as np

from ..track.frames import FrameError
from ..track.types import Box, Status, TrackResult, box_centre_index

TERM_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 10, 1)
HSV_LO = np.array((0.0, 60.0, 32.0))
HSV_HI = np.array((180.0, 255.0, 255.0))


def _check_frame(frame: np.ndarray, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """Return a BGR uint8 (H, W, 3) frame or raise FrameError (grey frames are expanded)."""
    if not isinstance(frame, np.ndarray) or frame.dtype != np.uint8 or frame.ndim not in (2, 3) \
            or frame.size == 0 or (frame.ndim == 3 and frame.shape[2] != 3):
        raise FrameError("frame must be a non-empty BGR uint8 array of shape (H, W, 3)")
    if frame.ndim == 2:
        frame = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)
    if shape is not None and frame.shape[:2] != shape[:2]:
        raise FrameError(f"frame size {frame.shape[1]}x{frame.shape[0]} differs from the init frame's "
                         f"{shape[1]}x{shape[0]}")
    return frame


def clip_box(box: Box | tuple[float, float, float, float], width: int, height: int) -> tuple[tuple[int, int, int, int], bool]:
    """Round a box to integer pixels and clip it to a ``width`` x ``height`` frame.

    Returns
    -------
    (x, y, w, h) : tuple of int
        Integer window inside the frame, ``w, h >= 1``.
    clipped : bool
        True if clipping changed the (rounded) box.

    Raises
    ------
    ValueError
        If no pixel of the box lies inside the frame.
    """
    b = Box.of(box)
    x0, y0 = int(round(b.x)), int(round(b.y))
    x1, y1 = int(round(b.x + b.w)), int(round(b.y + b.h))
    cx0, cy0 = max(0, x0), max(0, y0)
    cx1, cy1 = min(width, x1), min(height, y1)
    if cx1 <= cx0 or cy1 <= cy0:
        raise ValueError(f"box {b.as_tuple()} has no pixel inside the {width}x{height} frame")
    return (cx0, cy0, cx1 - cx0, cy1 - cy0), (cx0, cy0, cx1, cy1) != (x0, y0, x1, y1)


def _result(box: tuple[float, ...], status: Status, iters: int = 0, message: str = "") -> TrackResult:
    b = Box.of(box)
    nan = math.nan
    return TrackResult(box=b, centre=box_centre_index(b), rho_c=nan, rho_e=nan, alpha_c=nan,
                       alpha_e=nan, iter_c=iters, iter_e=0, status=status, message=message)


class _HueTracker:
    """Shared part of the meanshift / camshift tutorial trackers."""

    def __init__(self) -> None:
        self._hist: np.ndarray | None = None
        self._window: tuple[int, ...] = ()          # (x, y, w, h) integer window once initialised
        self._box: tuple[float, ...] = ()           # (x, y, w, h) last box reported
        self._shape: tuple[int, ...] | None = None

    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        """Build the hue histogram of ``box`` in ``frame`` (BGR uint8)."""
        frame = _check_frame(frame)
        h, w = frame.shape[:2]
        win, clipped = clip_box(box, w, h)
        x, y, bw, bh = win
        hsv = cv2.cvtColor(frame[y:y + bh, x:x + bw], cv2.COLOR_BGR2HSV)
        mask = cv2.inRange(hsv, HSV_LO, HSV_HI)
        hist = cv2.calcHist([hsv], [0], mask, [180], [0, 180])
        cv2.normalize(hist, hist, 0, 255, cv2.NORM_MINMAX)
        self._hist, self._window, self._shape = hist, win, frame.shape
        self._box = tuple(float(v) for v in win)
        return _result(self._box, Status.CLIPPED if clipped else Status.INIT)

    def _backproject(self, frame: np.ndarray) -> np.ndarray:
        if self._hist is None:
            raise RuntimeError("update() called before init()")
        hsv = cv2.cvtColor(_check_frame(frame, self._shape), cv2.COLOR_BGR2HSV)
        return cv2.calcBackProject([hsv], [0], self._hist, [0, 180], 1)


class MeanShiftTracker(_HueTracker):
    """OpenCV tutorial mean-shift tracker (fixed-size window on the hue back-projection)."""

    def update(self, frame: np.ndarray) -> TrackResult:
        """Move the window to the new frame (BGR uint8); box size never changes."""
        dst = self._backproject(frame)
        iters, win = cv2.meanShift(dst, self._window, TERM_CRITERIA)
        self._window = tuple(int(v) for v in win)
        self._box = tuple(float(v) for v in self._window)
        x, y, w, h = self._window
        status = Status.OK if dst[y:y + h, x:x + w].any() else Status.LOST
        return _result(self._box, status, int(iters))


class CamShiftTracker(_HueTracker):
    """OpenCV tutorial CamShift tracker; reports the bounding rect of the rotated box."""

    def update(self, frame: np.ndarray) -> TrackResult:
        """Track into the new frame (BGR uint8); the window adapts size and angle."""
        dst = self._backproject(frame)
        fh, fw = dst.shape[:2]
        try:
            rot, win = cv2.CamShift(dst, self._window, TERM_CRITERIA)
        except cv2.error:
            return _result(self._box, Status.LOST, message="CamShift failed")
        x, y, w, h = (int(v) for v in win)
        if w <= 0 or h <= 0 or rot[1][0] <= 0 or rot[1][1] <= 0:
            # the window collapsed (no back-projection mass): keep the last box
            return _result(self._box, Status.LOST, message="window collapsed")
        self._window = (x, y, w, h)
        pts = cv2.boxPoints(rot)
        x0, y0 = pts.min(axis=0)
        x1, y1 = pts.max(axis=0)
        self._box = (float(x0), float(y0), float(x1 - x0), float(y1 - y0))
        return _result(self._box, Status.OK)


def _contrib_factory(name: str) -> Callable[[], object]:
    for mod in (cv2, getattr(cv2, "legacy", None)):
        f = getattr(mod, f"Tracker{name}_create", None) if mod is not None else None
        if f is not None:
            return f
    raise RuntimeError(f"cv2.Tracker{name}_create not available (needs opencv-contrib-python)")


class OpenCVTracker:
    """Wrapper of an opencv-contrib tracker (``"KCF"`` or ``"CSRT"``)."""

    def __init__(self, kind: str) -> None:
        self.kind = kind.upper()
        self._factory = _contrib_factory(self.kind)
        self._trk: Any = None                       # the cv2.Tracker (KCF / CSRT) once initialised
        self._box: tuple[float, ...] = ()           # (x, y, w, h) last box reported
        self._shape: tuple[int, ...] | None = None

    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        frame = _check_frame(frame)
        h, w = frame.shape[:2]
        win, clipped = clip_box(box, w, h)
        self._trk = self._factory()
        self._trk.init(frame, win)
        self._shape = frame.shape
        self._box = tuple(float(v) for v in win)
        return _result(self._box, Status.CLIPPED if clipped else Status.INIT)

    def update(self, frame: np.ndarray) -> TrackResult:
        if self._trk is None:
            raise RuntimeError("update() called before init()")
        ok, box = self._trk.update(_check_frame(frame, self._shape))
        if not ok:
            return _result(self._box, Status.LOST, message=f"{self.kind} lost the target")
        self._box = tuple(float(v) for v in box)
        return _result(self._box, Status.OK)


def kcf() -> OpenCVTracker:
    """KCF tracker (opencv-contrib)."""
    return OpenCVTracker("KCF")


def csrt() -> OpenCVTracker:
    """CSRT tracker (opencv-contrib)."""
    return OpenCVTracker("CSRT")


def meanshift() -> MeanShiftTracker:
    """OpenCV tutorial mean-shift tracker."""
    return MeanShiftTracker()


def camshift() -> CamShiftTracker:
    """OpenCV tutorial CamShift tracker."""
    return CamShiftTracker()
