"""mstrack: mean-shift object tracker (float reference, fixed-point model, VHDL core).

Public API::

    import mstrack
    trk = mstrack.Tracker()                       # tracker v2 (the best measured), float model
    res = trk.init(frame_bgr, (x, y, w, h))       # 0-based pixels, see mstrack.types
    res = trk.update(next_frame_bgr)              # -> mstrack.TrackResult
    x, y, w, h = res.box                          # floats; res.box.to_cv() for OpenCV
    res.ok, res.confidence, res.status

    trk = mstrack.Tracker(preset="paper")         # the paper's colour + edge fusion (the RTL core)
    trk = mstrack.Tracker(model="fixed")          # the bit-accurate fixed-point model

    tracker = mstrack.TrackerMeanShift.create()   # OpenCV's tracker API (cv2.TrackerCSRT drop-in)
    tracker.init(frame, rect); ok, rect = tracker.update(frame)
"""
from typing import TYPE_CHECKING

from .types import Box, FeatureResult, Status, TrackResult

if TYPE_CHECKING:  # for type checkers; at run time they are imported lazily by __getattr__
    from .tracker import FrameError, Tracker, TrackerMeanShift, TrackerParams

__all__ = ["Box", "FeatureResult", "Status", "TrackResult", "Tracker", "TrackerMeanShift", "TrackerParams",
           "FrameError"]

_LAZY = ("Tracker", "TrackerMeanShift", "TrackerParams", "FrameError")


def __getattr__(name: str) -> object:  # lazy: keep `import mstrack` light
    if name in _LAZY:
        from . import tracker
        return getattr(tracker, name)
    raise AttributeError(name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])
