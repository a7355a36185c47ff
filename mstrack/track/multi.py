"""Several targets at once: :class:`MultiTracker` and its OpenCV-style front end :class:`MultiTrackerMeanShift`.

The executable specification of a multi-target core: each target is tracked exactly as a single
:class:`~mstrack.track.tracker.Tracker` tracks it (float) or bit for bit (fixed model) -- the
targets share the frame, never their state (region, model Q / T, search state) -- as long as the
core's capacity suffices; where it does not, the fixed model applies the core's capacity rule
(:mod:`mstrack.fixed.multi_capacity`, docs/multi_target_core.md "Capacity rule").

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
of the first target added while none was live).  An add is on the frame of the last ``update``
(the adds since it included); when no target is live it starts a new frame.

The capacity rule
-----------------
``capacity``: a :class:`mstrack.fixed.multi_capacity.MultiCoreConfig` (``max_targets``, the video
``timing``, the engine's pass ``costs``; default 16 targets, 1080p60 at 148.5 MHz, LANES 4).

* Both models: an add when ``max_targets`` targets are live is refused (:class:`CapacityError`,
  code ``"ADD_FULL"``).
* The fixed model of tracker v2 (the core the multi-target design extends) also applies the cycle
  rule: an add whose init job does not fit the frame's admitted jobs is refused (code
  ``"ADD_CYCLES"``, :func:`~mstrack.fixed.multi_capacity.check_add`), and on ``update`` a live
  target whose job does not fit is *held* for that frame
  (:func:`~mstrack.fixed.multi_capacity.plan_frame`, oldest target first): its tracker is not
  updated and its result has status error, ``extra["err_code"]`` 6
  (:func:`~mstrack.fixed.multi_capacity.held_result`).
* The float model and the fixed paper preset apply ``max_targets`` only: clocks are a property of
  the hardware, whose cycle model is core v2's.

docs/multi.md, "The capacity rule", is where the rule is written down for users.
"""
from __future__ import annotations

from typing import Any, Literal

import numpy as np

from .frames import FrameError, check_frame
from .params import TrackerParams
from .types import Box, TrackResult

__all__ = ["MultiTracker", "MultiTrackerMeanShift", "CapacityError"]

Model = Literal["float", "fixed"]
BoxLike = Box | tuple[float, float, float, float] | list[float] | np.ndarray


class CapacityError(RuntimeError):
    """An add the capacity rule refuses; nothing was changed.

    Attributes
    ----------
    code : str
        ``"ADD_FULL"`` (``max_targets`` targets live) or ``"ADD_CYCLES"`` (the new target's init job
        does not fit the frame's cycle budget): the names of
        :mod:`mstrack.fixed.multi_capacity`'s constants.
    add_code : int
        The value the core's add command returns (``ADD_FULL`` 1, ``ADD_CYCLES`` 2).
    """

    def __init__(self, code: str, add_code: int, message: str) -> None:
        self.code = code
        self.add_code = add_code
        super().__init__(f"{code}: {message}")


def _default_capacity(capacity: Any) -> Any:
    from ..fixed.multi_capacity import MultiCoreConfig
    if capacity is None:
        return MultiCoreConfig()
    if not isinstance(capacity, MultiCoreConfig):
        raise TypeError(f"capacity must be an mstrack.MultiCoreConfig, got {type(capacity).__name__}")
    return capacity


class MultiTracker:
    """Track several targets in one stream (float reference or the fixed-point model).

    Parameters
    ----------
    model : {"float", "fixed"}
        As :class:`mstrack.Tracker`.
    params : TrackerParams, optional
        Algorithm parameters of every target (default tracker v2).
    capacity : MultiCoreConfig, optional
        The multi-target core's configuration the capacity rule reads (``mstrack.MultiCoreConfig``:
        ``max_targets``, ``timing``, ``costs``; default 16 targets, 1080p60).  The float model and
        the fixed paper preset use its ``max_targets`` only (module docstring).
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
                 capacity: Any = None, **kwargs: Any) -> None:
        from .tracker import Tracker
        self.capacity: Any = _default_capacity(capacity)
        probe = Tracker(model=model, params=params, **kwargs)  # checks model and parameters now
        own = TrackerParams.field_names()
        self._rest = {k: v for k, v in kwargs.items() if k not in own}  # FixedParams fields (model fixed)
        self.model: Model = model
        self.params: TrackerParams = probe.params
        fixed = getattr(probe.impl, "fixed", None)
        if fixed is None:
            from ..fixed import FixedParams
            fixed = FixedParams()
        self.fixed = fixed
        #: True when the cycle rule applies (the fixed model of tracker v2).
        self.cycle_rule: bool = model == "fixed" and self.params.preset == "v2"
        self._trackers: dict[int, Any] = {}
        self._order: list[int] = []     # live ids, oldest first (the rule's priority)
        self._jobs: list[Any] = []      # the current frame's admitted jobs (TargetDemand)
        self._shape: tuple[int, int] | None = None
        #: Last result per live target id (its init result right after :meth:`add`).
        self.last: dict[int, TrackResult] = {}
        #: The last update's :class:`~mstrack.fixed.multi_capacity.FramePlan` (fixed tracker v2;
        #: None otherwise or before the first update).
        self.plan: Any = None

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
        frame or one whose size differs from the live targets', ValueError for a bad box or a frame
        larger than the capacity's video timing; nothing changes then.
        """
        from .tracker import Tracker
        frame = check_frame(frame, self._shape) if self._trackers else check_frame(frame)
        cap = self.capacity
        if len(self._trackers) >= cap.max_targets:
            raise CapacityError("ADD_FULL", 1, f"{len(self._trackers)} targets live, the core has "
                                               f"{cap.max_targets} slots (remove one first)")
        tid = next(i for i in range(cap.max_targets) if i not in self._trackers)
        jobs = self._jobs if self._trackers else []  # with no target live, a new frame
        new = None
        if self.cycle_rule:
            from ..fixed.multi_capacity import ADD_NAMES, ADD_OK, check_add, init_demand
            fh, fw = frame.shape[:2]
            if fh > cap.timing.active_lines or fw > cap.timing.line_clocks:
                raise ValueError(f"frame {fw}x{fh} is larger than the capacity's video timing "
                                 f"({cap.timing.active_lines} active lines of {cap.timing.line_clocks} clocks)")
            new = init_demand(Box.of(box), fw, fh, tid, self.params, self.fixed, cap.costs)  # ValueError: bad box
            code = check_add(jobs, len(self._trackers), new, cap)
            if code != ADD_OK:
                budget = min(j.slack(cap.timing) for j in [*jobs, new])
                raise CapacityError(ADD_NAMES[code], code, f"the init job ({new.clocks:,} clocks) with the "
                                    f"frame's {len(jobs)} admitted jobs ({sum(j.clocks for j in jobs):,} clocks) "
                                    f"exceeds the smallest slack, {budget:,} clocks")
        trk = Tracker(model=self.model, params=self.params, **self._rest)
        res = trk.init(frame, box)  # raises before anything is changed
        res.target_id = tid
        if not self._trackers:
            self._shape = (frame.shape[0], frame.shape[1])
        self._jobs = [*jobs, new] if new is not None else jobs
        self._trackers[tid], self.last[tid] = trk, res
        self._order.append(tid)
        return tid

    def remove(self, target_id: int) -> None:
        """Remove a live target; its slot (id) is free for the next :meth:`add`."""
        self._check_id(target_id)
        del self._trackers[target_id], self.last[target_id]
        self._order.remove(target_id)

    def update(self, frame: np.ndarray) -> list[TrackResult]:
        """Track every live target into ``frame`` (ndarray (H, W, 3) uint8 BGR, the targets' frame size).

        Returns one :class:`TrackResult` per live target, in ascending ``target_id`` order; each is
        what that target's own :class:`mstrack.Tracker` returns, except for a target the capacity rule
        holds on this frame (fixed tracker v2): status error, ``extra["err_code"]`` 6, its tracker
        not updated.  A bad frame raises :class:`FrameError` before any target is updated (all keep
        their state).
        """
        if not self._trackers:
            return []
        frame = check_frame(frame, self._shape)
        held: dict[int, Any] = {}
        if self.cycle_rule:
            from ..fixed.multi_capacity import plan_frame, target_demand
            jobs = [target_demand(self._trackers[t].impl, t, costs=self.capacity.costs) for t in self._order]
            self.plan = plan_frame(jobs, self.capacity)
            self._jobs = list(self.plan.jobs)
            held = {j.target_id: j for j in jobs if j.target_id in self.plan.held}
        out = []
        for tid in self.targets:
            if tid in held:
                from ..fixed.multi_capacity import held_result
                res = held_result(self._trackers[tid].impl, held[tid])
            else:
                res = self._trackers[tid].update(frame)
            res.target_id = tid
            self.last[tid] = res
            out.append(res)
        return out


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
                 capacity: Any = None) -> None:
        from .tracker import DEFAULT_PRESET
        self.multi = MultiTracker(model=model, params=params if params is not None
                                  else TrackerParams(preset=DEFAULT_PRESET), capacity=capacity)
        self._order: list[int] = []

    @classmethod
    def create(cls, params: TrackerParams | None = None, model: Model = "float",
               capacity: Any = None) -> "MultiTrackerMeanShift":
        """A new multi-tracker, as ``cv2.legacy.MultiTracker.create()``; ``params`` (default tracker v2)
        and ``model`` apply to every target; ``capacity``: an ``mstrack.MultiCoreConfig``, as
        :class:`MultiTracker`'s."""
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
