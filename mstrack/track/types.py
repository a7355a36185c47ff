"""Public result and box types of mstrack.

Box convention (defined here, once, for the whole package): a box is
``(x, y, w, h)`` in **0-based pixel coordinates**: ``x, y`` is the left/top
edge of the box and ``w, h`` its width and height, so the box covers the
continuous region ``[x, x + w) x [y, y + h)``.  Pixel ``(i, j)`` (column i,
row j) covers ``[i, i + 1) x [j, j + 1)``; its centre is ``(i + 0.5, j + 0.5)``.
The centre of a box is therefore ``(x + w / 2, y + h / 2)`` in these
continuous coordinates.  The trackers work internally in *pixel-index*
coordinates (pixel (i, j) sits at (i, j)); :func:`box_centre_index` and
:func:`box_from_centre_index` convert.

OTB ground truth is 1-based; the data readers subtract 1 from x and y.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, asdict
from enum import Enum
from typing import Any, NamedTuple, Sequence

import numpy as np


class Box(NamedTuple):
    """Axis-aligned box ``(x, y, w, h)``, 0-based, left/top + size, in pixels (floats).

    A :class:`typing.NamedTuple`: it unpacks, indexes and compares like the 4-tuple
    ``(x, y, w, h)`` (``x, y, w, h = res.box``; ``res.box[2]``; ``Box(1, 2, 3, 4) == (1, 2, 3, 4)``;
    hashable, so it can key a dict).  For OpenCV drawing functions, which want integers, use
    :meth:`to_cv` (``cv2.rectangle(img, res.box.to_cv(), colour)``).
    """

    x: float
    y: float
    w: float
    h: float

    @classmethod
    def of(cls, box: "Box | Sequence[float] | np.ndarray") -> "Box":
        """Build a Box from a Box or an ordered 4-sequence ``(x, y, w, h)`` (tuple, list, 1-D array).

        Values become Python floats.  Raises ValueError on a bad shape, a non-number (bools and
        strings included) or a non-finite value.
        """
        if isinstance(box, Box):
            b = box
        else:
            # an ordered sequence / 1-D array of 4 real numbers only: not a string or bytes ("5599"
            # would iterate as 4 digits), not a set or dict (no order), not bools or numeric strings
            if isinstance(box, (str, bytes, bytearray, memoryview, set, frozenset, dict)) \
                    or not hasattr(box, "__len__") or not hasattr(box, "__getitem__"):
                raise ValueError(f"box must be a sequence of 4 numbers (x, y, w, h), got {box!r}")
            try:
                items = list(box)
            except TypeError as exc:
                raise ValueError(f"box must be a sequence of 4 numbers (x, y, w, h), got {box!r}") from exc
            if len(items) != 4:
                raise ValueError(f"box must be 4 numbers (x, y, w, h), got {len(items)} values")
            if not all(isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)) for v in items):
                raise ValueError(f"box must be 4 real numbers (x, y, w, h), got {box!r}")
            b = cls(*(float(v) for v in items))
        if not all(math.isfinite(v) for v in b):
            raise ValueError(f"box has a non-finite value: {b}")
        return b

    def as_tuple(self) -> tuple[float, float, float, float]:
        """The plain tuple ``(x, y, w, h)`` (floats, pixels)."""
        return (self.x, self.y, self.w, self.h)

    @property
    def centre(self) -> tuple[float, float]:
        """Centre in continuous coordinates ``(x + w/2, y + h/2)``, pixels."""
        return (self.x + self.w / 2.0, self.y + self.h / 2.0)

    def to_cv(self) -> tuple[int, int, int, int]:
        """OpenCV's integer rect ``(x, y, w, h)`` (``cv::Rect``, pixels) for ``cv2.rectangle(img,
        box.to_cv(), colour)`` and the ``cv2.Tracker`` API.

        The corners are rounded to the nearest pixel edge (halves up) and the size taken between
        them, so the rect covers the pixels the box covers most of: ``Box(0.4, 0, 10.4, 5)`` ->
        ``(0, 0, 11, 5)``.
        """
        x0, y0 = math.floor(self.x + 0.5), math.floor(self.y + 0.5)
        x1, y1 = math.floor(self.x + self.w + 0.5), math.floor(self.y + self.h + 0.5)
        return (int(x0), int(y0), int(x1 - x0), int(y1 - y0))


def box_centre_index(box: Box) -> tuple[float, float]:
    """Centre of ``box`` in pixel-index coordinates (pixel (i, j) at (i, j))."""
    cx, cy = box.centre
    return (cx - 0.5, cy - 0.5)


def box_from_centre_index(cx: float, cy: float, w: float, h: float) -> Box:
    """Box of size (w, h) whose centre in pixel-index coordinates is (cx, cy)."""
    return Box(cx + 0.5 - w / 2.0, cy + 0.5 - h / 2.0, w, h)


class Status(str, Enum):
    """Per-frame tracker status."""

    OK = "ok"                  # tracked normally
    INIT = "init"              # the frame the target was initialised on
    LOST = "lost"              # the target is not where the tracker looks (v2: loss flag set while
                               # the wide search runs; paper preset: all weights 0); box kept
    UNCERTAIN = "uncertain"    # v2: loss flag set, position reported but not trusted
    REACQUIRED = "reacquired"  # v2: the loss flag clears after a reported loss
    CLIPPED = "clipped"        # init box clipped to the frame / to the maximum window
    ERROR = "error"            # frame rejected (bad frame); position kept from the previous frame


@dataclass
class FeatureResult:
    """Mean-shift result of one feature (colour or edge) on one frame.

    centre: converged centre, pixel-index coordinates; rho: Bhattacharyya
    coefficient at that centre (0..1); iterations: mean-shift iterations run;
    stop: why the loop stopped ("shift", "rho", "max_iter", "lost").
    """

    centre: tuple[float, float]
    rho: float
    iterations: int
    stop: str


@dataclass
class TrackResult:
    """Result of one frame (:meth:`mstrack.Tracker.init` / :meth:`~mstrack.Tracker.update`).

    Attributes
    ----------
    box : Box
        Tracked box ``(x, y, w, h)``, 0-based pixels (floats); ``box.to_cv()`` for OpenCV.
    centre : tuple of float
        Box centre ``(cx, cy)`` in pixel-index coordinates (pixel (i, j) at (i, j)).
    rho_c, rho_e : float
        Colour / edge Bhattacharyya coefficient at the result, 0..1 (NaN-free; 0 for a
        feature that is not run).
    alpha_c, alpha_e : float
        Fusion weights of colour / edge, 0..1, summing to 1 (1 / 0 for colour only).
    iter_c, iter_e : int
        Mean-shift iterations per feature on this frame.
    status : Status
        Per-frame status (:class:`Status`).
    message : str
        Human-readable detail (why a box was clipped, ...), "" if none.
    confidence : float
        0..1, tracker v2's estimate that the box is on the target (``preset="v2"``: rho and
        colour share against their running references); the paper preset has no confidence
        and always reports 1.0.
    extra : dict
        Model-specific detail (the fixed model puts its raw integers here).
    target_id : int or None
        The target's id in a :class:`mstrack.MultiTracker` (its slot, 0 .. max_targets - 1); None
        for a single :class:`mstrack.Tracker`.

    ``ok`` (property) is True when the box can be trusted (status ok, init, clipped or
    reacquired): the ``ok`` of OpenCV's ``(ok, rect) = tracker.update(frame)``.
    """

    box: Box
    centre: tuple[float, float]
    rho_c: float
    rho_e: float
    alpha_c: float
    alpha_e: float
    iter_c: int
    iter_e: int
    status: Status
    message: str = ""
    confidence: float = 1.0
    extra: dict[str, Any] = field(default_factory=dict)
    target_id: int | None = None

    @property
    def ok(self) -> bool:
        """True when the box can be trusted: not lost, uncertain or a rejected frame."""
        return self.status in (Status.OK, Status.INIT, Status.CLIPPED, Status.REACQUIRED)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["box"] = list(self.box.as_tuple())
        d["centre"] = list(self.centre)
        d["status"] = self.status.value
        return d
