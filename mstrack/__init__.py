"""mstrack: mean-shift colour + edge fusion tracker (float reference, fixed-point model, VHDL core).

Public API::

    import mstrack
    trk = mstrack.Tracker(model="float")          # or model="fixed"
    trk.init(frame_bgr, (x, y, w, h))             # 0-based box, see mstrack.types
    res = trk.update(next_frame_bgr)              # -> mstrack.TrackResult
"""
from .types import Box, FeatureResult, Status, TrackResult

__all__ = ["Box", "FeatureResult", "Status", "TrackResult", "Tracker", "TrackerParams", "FrameError"]


def __getattr__(name: str):  # lazy: keep `import mstrack` light
    if name in ("Tracker", "TrackerParams", "FrameError"):
        from . import tracker
        return getattr(tracker, name)
    raise AttributeError(name)
