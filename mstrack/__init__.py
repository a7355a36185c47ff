"""mstrack: mean-shift colour + edge fusion tracker (float reference, fixed-point model, VHDL core).

Public API::

    import mstrack
    trk = mstrack.Tracker(model="float")          # or model="fixed"
    trk.init(frame_bgr, (x, y, w, h))             # 0-based box, see mstrack.types
    res = trk.update(next_frame_bgr)              # -> mstrack.TrackResult

The core's result word (v1 and v2): ``mstrack.unpack_result(word)``, ``result_layout()``, ...
(re-exported from :mod:`mstrack.fixed`; docs/integration.md, "Result word").
"""
from .types import Box, FeatureResult, Status, TrackResult

_RESULT_API = ("RESULT_FLAGS", "result_layout", "result_width", "pack_result", "unpack_result",
               "STATUS_V2", "result_layout_v2", "result_width_v2", "pack_result_v2", "unpack_result_v2")
__all__ = ["Box", "FeatureResult", "Status", "TrackResult", "Tracker", "TrackerParams", "FrameError",
           *_RESULT_API]


def __getattr__(name: str):  # lazy: keep `import mstrack` light
    if name in ("Tracker", "TrackerParams", "FrameError"):
        from . import tracker
        return getattr(tracker, name)
    if name in _RESULT_API:
        from .fixed import vhdl_pkg
        return getattr(vhdl_pkg, name)
    raise AttributeError(name)
