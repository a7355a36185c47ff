"""mstrack: mean-shift object tracker (float reference, fixed-point model, VHDL core).

Public API::

    import mstrack
    trk = mstrack.Tracker()                       # tracker v2 (the best measured), float model
    res = trk.init(frame_bgr, (x, y, w, h))       # 0-based pixels, see mstrack.track.types
    res = trk.update(next_frame_bgr)              # -> mstrack.TrackResult
    x, y, w, h = res.box                          # floats; res.box.to_cv() for OpenCV
    res.ok, res.confidence, res.status

    trk = mstrack.Tracker(preset="paper")         # the paper's colour + edge fusion (the RTL core)
    trk = mstrack.Tracker(model="fixed")          # the bit-accurate fixed-point model

    mstrack.__version__                           # the package version ("0.2.0")

    tracker = mstrack.TrackerMeanShift.create()   # OpenCV's tracker API (cv2.TrackerCSRT drop-in)
    tracker.init(frame, rect); ok, rect = tracker.update(frame)

    mt = mstrack.MultiTracker()                   # several targets (docs/multi.md)
    tid = mt.add(frame, (x, y, w, h))             # -> target id (lowest free slot); mt.last[tid]: init result
    results = mt.update(next_frame)               # one TrackResult per live target, .target_id set
    mt.remove(tid)
    multi = mstrack.MultiTrackerMeanShift.create()  # cv2.legacy.MultiTracker's API
    mt = mstrack.MultiTracker(model="fixed", capacity=mstrack.MultiCoreConfig(max_targets=4))  # the core's rule

The core's result word (v1 and v2): ``mstrack.unpack_result(word)``, ``result_layout()``, ...
(re-exported from :mod:`mstrack.fixed`; docs/integration.md, "Result word").
"""
from typing import TYPE_CHECKING

from .track.types import Box, FeatureResult, Status, TrackResult

if TYPE_CHECKING:  # for type checkers; at run time they are imported lazily by __getattr__
    from .fixed.multi_capacity import MultiCoreConfig, VideoTiming
    from .track.multi import CapacityError, MultiTracker, MultiTrackerMeanShift
    from .track.tracker import FrameError, Tracker, TrackerMeanShift, TrackerParams

_RESULT_API = ("RESULT_FLAGS", "result_layout", "result_width", "pack_result", "unpack_result",
               "STATUS_V2", "result_layout_v2", "result_width_v2", "pack_result_v2", "unpack_result_v2")
_MULTI = ("MultiTracker", "MultiTrackerMeanShift", "CapacityError")
_CAPACITY = ("MultiCoreConfig", "VideoTiming")  # the multi-target core's configuration (docs/multi.md)
__all__ = ["__version__", "Box", "FeatureResult", "Status", "TrackResult", "Tracker", "TrackerMeanShift",
           "TrackerParams", "FrameError", *_MULTI, *_CAPACITY, *_RESULT_API]

_LAZY = ("Tracker", "TrackerMeanShift", "TrackerParams", "FrameError")


def __getattr__(name: str) -> object:  # lazy: keep `import mstrack` light
    if name == "__version__":
        from .versions import package_version
        return package_version()
    if name in _LAZY:
        from .track import tracker
        return getattr(tracker, name)
    if name in _MULTI:
        from .track import multi
        return getattr(multi, name)
    if name in _CAPACITY:
        from .fixed import multi_capacity
        return getattr(multi_capacity, name)
    if name in _RESULT_API:
        from .fixed import vhdl_pkg
        return getattr(vhdl_pkg, name)
    raise AttributeError(name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY, *_MULTI, *_CAPACITY])
