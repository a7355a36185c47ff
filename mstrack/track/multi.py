"""Several targets at once: :class:`MultiTracker` and its OpenCV-style front end :class:`MultiTrackerMeanShift`.

The executable specification of a multi-target core: each target is tracked exactly as a single
:class:`~mstrack.track.tracker.Tracker` tracks it (float) or bit for bit (fixed model) -- the
targets share the frame, never their state (region, model Q / T, search state) -- and admission
follows one capacity rule, :class:`Capacity`, in one place.

Target ids
----------
A target's id is its *slot*: the lowest free slot ``0 .. max_targets - 1`` at :meth:`MultiTracker.add`,
freed by :meth:`MultiTracker.remove` and then given to the next target added (the hardware has
``MAX_TARGETS`` state records; a slot number is what its result word carries).  So an id names one
target while it lives; a program that removes and adds targets keeps its own labels if it needs
identities that are never reused (``mstrack eval`` and ``mstrack track --init`` do).

Frames
------
As OpenCV's ``cv2.legacy.MultiTracker``: ``add(frame, box)`` initialises the new target on ``frame``
(its first result, status init or clipped, is ``last[target_id]``); ``update(frame)`` processes a *new*
frame for every live target, the targets added before it.  All targets share one frame size (that
of the first target added while none was live).

The capacity rule (:class:`Capacity`)
-------------------------------------
An add is refused with :class:`CapacityError` (``code`` ``"MAX_TARGETS"`` or ``"REGION_WORDS"``)
and changes nothing when, with the new target,

* the live targets would exceed ``max_targets`` (default 16), or
* the region memory they hold would exceed ``region_words``: each target holds
  ``buffers`` x :meth:`Capacity.target_words` words (one per decimated pixel of its worst-case
  search region in this frame size; default budget 16 x 65,536 words = sixteen of core v2's
  REGION_MAX 256 x 256 region RAMs).

Both models apply the same rule, so float and fixed accept the same adds.  Clocks are not a
refusal reason in this model: with the pipelined schedule (the mean shift of frame t while frame
t + 1 streams in, one frame of 2,475,000 clocks at 1080p60) 16 worst-case targets fit (81,279 clocks
each, docs/architecture.md "Per-target state, and N targets"), so ``max_targets`` binds first.
The rule is written down in docs/multi.md; docs/architecture.md "Multi-target core" is where the
hardware's choice is made -- align :class:`Capacity` with it there.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .frames import FrameError, check_frame
from .params import TrackerParams
from .types import Box, TrackResult

__all__ = ["MultiTracker", "MultiTrackerMeanShift", "Capacity", "CapacityError", "MAX_TARGETS",
           "REGION_RAM_WORDS"]

#: Default number of target slots (the generic MAX_TARGETS of a multi-target core: 1..16).
MAX_TARGETS = 16
#: Words of core v2's region RAM today (REGION_MAX 256 x 256 decimated pixels, docs/architecture.md
#: "Region RAM"): one target's worst case in any frame up to 2048 px wide.
REGION_RAM_WORDS = 256 * 256

Model = Literal["float", "fixed"]
BoxLike = Box | tuple[float, float, float, float] | list[float] | np.ndarray


class CapacityError(RuntimeError):
    """An add the capacity rule refuses (:class:`Capacity`); nothing was changed.

    Attributes
    ----------
    code : str
        ``"MAX_TARGETS"`` (no free target slot) or ``"REGION_WORDS"`` (the region memory would be
        exceeded): the error code a core's add command would return.
    """

    def __init__(self, code: str, message: str) -> None:
        self.code = code
        super().__init__(f"{code}: {message}")


@dataclass(frozen=True)
class Capacity:
    """The multi-target core's capacity rule: when an add is refused (the one place it is written).

    Parameters
    ----------
    max_targets : int
        Target slots (the generic MAX_TARGETS, 1..16; default 16).
    region_words : int or None
        Region memory shared by the live targets, in words (one word per decimated pixel of a
        search region; default 16 x :data:`REGION_RAM_WORDS`); None: no memory limit.
    buffers : int
        Regions per target: 1 when a target's region is captured and used in the same blanking
        (core v2 today), 2 for double-buffered regions (the pipelined schedule: frame t's region is
        searched while frame t + 1's is captured).

    The rule (:meth:`check`): refuse the add (:class:`CapacityError`) if the live targets plus the
    new one would be more than ``max_targets``, or would hold more than ``region_words`` words, each
    target holding ``buffers * target_words(...)``.
    """

    max_targets: int = MAX_TARGETS
    region_words: int | None = MAX_TARGETS * REGION_RAM_WORDS
    buffers: int = 1

    def __post_init__(self) -> None:
        m = self.max_targets
        if isinstance(m, bool) or not isinstance(m, int) or not 1 <= m <= 1024:
            raise ValueError(f"max_targets must be an integer in 1..1024, got {self.max_targets!r}")
        if self.region_words is not None and (isinstance(self.region_words, bool)
                                              or not isinstance(self.region_words, int) or self.region_words < 1):
            raise ValueError(f"region_words must be a positive integer or None, got {self.region_words!r}")
        if self.buffers not in (1, 2):
            raise ValueError(f"buffers must be 1 or 2, got {self.buffers!r}")

    def target_words(self, params: TrackerParams, fixed: Any, frame_shape: tuple[int, ...]) -> int:
        """Region words one target may need in frames of ``frame_shape`` (H, W, ...): columns x rows
        of its worst-case search region, decimated pixels (what a region RAM slot must hold for it).

        Tracker v2 (docs/fixed_point.md "Search region", ``mstrack.hw.cosim.region_max_v2`` per
        axis): ms_region's n = min(2e + 2m + 1, S - 2), S the decimated frame size, over tracking
        (any window up to 2 max_half + 1 at D = 1, margin MARGIN), lost at D = 2 (half the largest
        window, margin + search offset) and lost at 2 x the largest decimation.  The paper
        preset: window 2 max_half + 1 + 2 MARGIN, at most S - 2.  ``fixed``: the
        :class:`mstrack.fixed.FixedParams` (margin, max_half; the hardware's defaults for the
        float model)."""
        h, w = int(frame_shape[0]), int(frame_shape[1])
        win = 2 * fixed.max_half + 1
        if params.preset != "v2":
            return min(win + 2 * fixed.margin, w - 2) * min(win + 2 * fixed.margin, h - 2)
        from ..fixed.blocks_v2 import MAX_DECIMATION, sixteenths
        step16 = sixteenths(params.search_step, "search_step")
        half = min((params.max_window + 1) // 2, win)

        def n(size: int, wd: int, lost: bool, d: int) -> int:
            e = (wd - 1) >> 1
            m = min(fixed.margin + ((step16 * wd) >> 4), 255) if lost else fixed.margin
            return min(2 * e + 2 * m + 1, ((size - 1) // d + 1) - 2)

        def axis(size: int) -> int:
            return max(n(size, win, False, 1), n(size, half, True, 2), n(size, win, True, 2 * MAX_DECIMATION))

        return axis(w) * axis(h)

    def check(self, live_words: list[int], new_words: int) -> None:
        """Raise :class:`CapacityError` if a target needing ``new_words`` region words (one buffer) may
        not join live targets holding ``live_words`` (one entry per live target, one buffer each)."""
        n = len(live_words) + 1
        if n > self.max_targets:
            raise CapacityError("MAX_TARGETS", f"{len(live_words)} targets live, the core has "
                                               f"{self.max_targets} slots (remove one first)")
        if self.region_words is not None:
            need = self.buffers * (sum(live_words) + new_words)
            if need > self.region_words:
                terms = " + ".join(str(v) for v in live_words + [new_words])
                raise CapacityError("REGION_WORDS", f"the {n} targets' regions need {need:,} words "
                                                    f"({self.buffers} x ({terms})), the region memory has "
                                                    f"{self.region_words:,}")


class MultiTracker:
    """Track several targets in one stream (float reference or the fixed-point model).

    Parameters
    ----------
    model : {"float", "fixed"}
        As :class:`mstrack.Tracker`.
    params : TrackerParams, optional
        Algorithm parameters of every target (default tracker v2).
    capacity : Capacity, optional
        The capacity rule (default ``Capacity()``: 16 slots, 16 x 65,536 region words).
    **kwargs
        :class:`TrackerParams` (and, for ``model="fixed"``, FixedParams) fields, as :class:`mstrack.Tracker`.

    Examples
    --------
    >>> mt = MultiTracker()                                # doctest: +SKIP
    >>> a = mt.add(frame0, (10, 20, 30, 60))               # doctest: +SKIP  (target id 0)
    >>> b = mt.add(frame0, (200, 40, 28, 64))              # doctest: +SKIP  (target id 1)
    >>> for r in mt.update(frame1):                        # doctest: +SKIP
    ...     print(r.target_id, r.box, r.ok)
    >>> mt.remove(a)                                       # doctest: +SKIP  (slot 0 is free again)
    """

    def __init__(self, model: Model = "float", params: TrackerParams | None = None,
                 capacity: Capacity | None = None, **kwargs: Any) -> None:
        from .tracker import Tracker
        if capacity is not None and not isinstance(capacity, Capacity):
            raise TypeError(f"capacity must be a Capacity, got {type(capacity).__name__}")
        probe = Tracker(model=model, params=params, **kwargs)  # checks model and parameters now
        own = TrackerParams.field_names()
        self._rest = {k: v for k, v in kwargs.items() if k not in own}  # FixedParams fields (model fixed)
        self.model: Model = model
        self.params: TrackerParams = probe.params
        self.capacity: Capacity = capacity or Capacity()
        fixed = getattr(probe.impl, "fixed", None)
        if fixed is None:
            from ..fixed import FixedParams
            fixed = FixedParams()
        self.fixed = fixed
        self._trackers: dict[int, Any] = {}
        self._words: dict[int, int] = {}
        self._shape: tuple[int, int] | None = None
        #: Last result per live target id (its init result right after :meth:`add`).
        self.last: dict[int, TrackResult] = {}

    # ------------------------------------------------------------------ targets
    @property
    def targets(self) -> list[int]:
        """Ids of the live targets, ascending."""
        return sorted(self._trackers)

    def __len__(self) -> int:
        return len(self._trackers)

    def tracker(self, target_id: int) -> Any:
        """The :class:`mstrack.Tracker` of target ``target_id`` (its ``impl`` for traces)."""
        self._check_id(target_id)
        return self._trackers[target_id]

    def _check_id(self, target_id: int) -> None:
        if target_id not in self._trackers:
            raise KeyError(f"no live target {target_id!r} (live: {self.targets})")

    def add(self, frame: np.ndarray, box: BoxLike) -> int:
        """Add a target: initialise it on ``frame`` (ndarray (H, W, 3) uint8 BGR) from ``box``
        ``(x, y, w, h)`` (0-based pixels) and return its id, the lowest free slot.

        Its init result is :attr:`last` ``[id]`` (with ``target_id`` set).  Raises
        :class:`CapacityError` when the capacity rule refuses the add, :class:`FrameError` for a bad
        frame or one whose size differs from the live targets', ValueError for a bad box; nothing
        changes then.
        """
        from .tracker import Tracker
        frame = check_frame(frame, self._shape) if self._trackers else check_frame(frame)
        words = self.capacity.target_words(self.params, self.fixed, frame.shape)
        self.capacity.check([self._words[i] for i in self.targets], words)
        tid = next(i for i in range(self.capacity.max_targets) if i not in self._trackers)
        trk = Tracker(model=self.model, params=self.params, **self._rest)
        res = trk.init(frame, box)  # raises before anything is changed
        res.target_id = tid
        if not self._trackers:
            self._shape = (frame.shape[0], frame.shape[1])
        self._trackers[tid], self._words[tid], self.last[tid] = trk, words, res
        return tid

    def remove(self, target_id: int) -> None:
        """Remove a live target; its slot (id) is free for the next :meth:`add`."""
        self._check_id(target_id)
        del self._trackers[target_id], self._words[target_id], self.last[target_id]

    def update(self, frame: np.ndarray) -> list[TrackResult]:
        """Track every live target into ``frame`` (ndarray (H, W, 3) uint8 BGR, the targets' frame size).

        Returns one :class:`TrackResult` per live target, in ascending ``target_id`` order; each is
        what that target's own :class:`mstrack.Tracker` returns.  A bad frame raises
        :class:`FrameError` before any target is updated (all keep their state).
        """
        if not self._trackers:
            return []
        frame = check_frame(frame, self._shape)
        out = []
        for tid in self.targets:
            res = self._trackers[tid].update(frame)
            res.target_id = tid
            self.last[tid] = res
            out.append(res)
        return out

    def region_words(self) -> int:
        """Region memory the live targets hold, in words (as the capacity rule counts it)."""
        return self.capacity.buffers * sum(self._words.values())


class MultiTrackerMeanShift:
    """OpenCV-style front end, after ``cv2.legacy.MultiTracker``: a drop-in for code written for it.

    >>> multi = mstrack.MultiTrackerMeanShift.create()           # instead of cv2.legacy.MultiTracker.create()
    >>> multi.add(mstrack.TrackerMeanShift.create(), frame, box)  # doctest: +SKIP  (or add(None, ...))
    >>> ok, boxes = multi.update(frame)                            # doctest: +SKIP  (boxes: (N, 4) float64)

    As OpenCV's: targets in the order added (no remove; :attr:`multi` is the :class:`MultiTracker`
    behind it, with remove), ``add`` returns a bool (False when the capacity rule refuses the add),
    ``update`` and ``getObjects`` give an (N, 4) float64 array of ``(x, y, w, h)`` boxes.  Unlike
    OpenCV 4/5's legacy MultiTracker, whose ``update`` returns True even when a tracker fails, ``ok``
    is True only when every target's result is ``ok`` (:attr:`TrackResult.ok`); the per-target
    results are :attr:`last`.  A bad frame gives ``(False, previous boxes)``.
    """

    def __init__(self, params: TrackerParams | None = None, model: Model = "float",
                 capacity: Capacity | None = None) -> None:
        from .tracker import DEFAULT_PRESET
        self.multi = MultiTracker(model=model, params=params if params is not None
                                  else TrackerParams(preset=DEFAULT_PRESET), capacity=capacity)
        self._order: list[int] = []

    @classmethod
    def create(cls, params: TrackerParams | None = None, model: Model = "float",
               capacity: Capacity | None = None) -> "MultiTrackerMeanShift":
        """A new multi-tracker, as ``cv2.legacy.MultiTracker.create()``; ``params`` (default tracker v2)
        and ``model`` apply to every target."""
        return cls(params, model, capacity)

    @property
    def last(self) -> list[TrackResult]:
        """The last result of each target, in the order added."""
        return [self.multi.last[t] for t in self._order if t in self.multi.last]

    def add(self, newTracker: Any, image: np.ndarray, boundingBox: BoxLike) -> bool:  # noqa: N803 (OpenCV's names)
        """Add a target on ``image`` at ``boundingBox`` ``(x, y, w, h)``.  ``newTracker``: None or a
        :class:`~mstrack.track.tracker.TrackerMeanShift` with this multi-tracker's params and model
        (OpenCV passes a fresh tracker per target; here they all share the multi-tracker's).
        Returns False when the capacity rule refuses the add."""
        from .tracker import TrackerMeanShift
        if newTracker is not None:
            if not isinstance(newTracker, TrackerMeanShift):
                raise TypeError(f"newTracker must be None or an mstrack.TrackerMeanShift, got "
                                f"{type(newTracker).__name__}")
            if newTracker.params != self.multi.params or newTracker.tracker.model != self.multi.model:
                raise ValueError("newTracker's params / model differ from the multi-tracker's: create it with "
                                 "MultiTrackerMeanShift.create(params, model)")
        try:
            tid = self.multi.add(image, boundingBox)
        except CapacityError:
            return False
        self._order.append(tid)
        return True

    def update(self, image: np.ndarray) -> tuple[bool, np.ndarray]:
        """Track every target into ``image``; ``(ok, boxes)``, boxes (N, 4) float64 in add order."""
        try:
            self.multi.update(image)
        except FrameError:
            return False, self.getObjects()
        return all(r.ok for r in self.last), self.getObjects()

    def getObjects(self) -> np.ndarray:  # noqa: N802 (OpenCV's name)
        """The last box of each target, (N, 4) float64 ``(x, y, w, h)``, in the order added."""
        return np.array([r.box.as_tuple() for r in self.last], dtype=np.float64).reshape(-1, 4)
