"""What the multi-target core ``ms_tracker_multi`` outputs for an arbitrary input stream: :class:`CoreModelMulti`.

The executable specification of the multi-target core's ports (docs/multi_target_core.md, "Ports
and result stream"), the model its RTL is compared with word by word (tb/test_ms_tracker_multi.py).
The core has one core v2 engine per target slot, so the model is ``MAX_TARGETS`` instances of
:class:`mstrack.hw.cosim.CoreModelV2` (each a single fixed-point tracker v2 with core v2's stream
behaviour) fed the same beats, plus:

* **commands**, taken between frames: ``add(box, fw, fh)`` gives the box to the lowest free slot's
  engine as its init box (core v2: applied on the next good frame of its size; a box that does not
  clip is rejected by the engine, which frees the slot once its next word shows the flag
  ``rejected``); with every slot taken the add is refused (``full``) and the flag ``rejected`` is set on
  the next frame's first word.  ``remove(id)`` resets that slot's engine (an id that is not live:
  refused, nothing changes);
* **words**: when every engine has its word of a frame, one word per engine whose word does not carry
  ``no_target`` (a live target: tracked, lost, error on a stream fault), in ascending slot order, with
  ``target_id`` = the slot and ``frame_count`` = the frames merged since reset; a frame with none
  gives slot 0's word alone (``no_target``, as core v2).  ``rejected`` of any engine's word of the frame
  (or of a refused add) is set on the frame's first word.

**The capacity rule** (``capacity``: a :class:`mstrack.fixed.multi_capacity.MultiCoreConfig`; the shared-engine
core, docs/multi_target_core.md "Capacity rule"; None: ``ms_tracker_multi``, every engine its own budget).
At each frame's start the frame is planned: the live targets, oldest first, by
:func:`~mstrack.fixed.multi_capacity.plan_frame` on their states (:func:`~mstrack.fixed.multi_capacity.target_demand`);
a held target's word is :func:`~mstrack.fixed.multi_capacity.held_result`'s (status error, ``err_code`` 6) and its
state stays.  Then the adds taken since the last frame, in the order taken: an init job that fits
(:func:`~mstrack.fixed.multi_capacity.check_add` with the frame's admitted jobs and the adds taken before it) is
initialised on this frame; one that does not is refused: report ``CMD_CYCLES`` with its slot, which is free again,
and the flag ``rejected`` on the frame's first word.  The add itself was reported ``CMD_OK`` with its slot when it
was taken, as without the rule (a box the engine rejects is reported later, ``CMD_BOX``, in the same way).  An
accepted add whose init frame has a stream fault keeps its verdict and is initialised on the next good frame (a
fault changes no state, so it still fits; it counts before that frame's adds).  On a frame with a stream fault
every live target's word is the error word, held or not.

Feed it, in stream order, ``beat(data, tuser, tlast, fw, fh)`` for every accepted beat, ``add`` /
``remove`` where the core took a command, and ``reset()``.  ``frames`` holds, per frame, the list of
predicted words (field dicts with ``target_id``); ``outcomes`` each command's and each rejected box's
report (``cmd_done``: code, id).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from .cosim import COMPARED_FIELDS_V2, CoreModelV2, diff_fields
from ..fixed import FixedParams
from ..fixed.multi_capacity import MultiCoreConfig
from ..fixed.vhdl_pkg import RESULT_FLAGS, pack_result_multi
from ..track.params import TrackerParams

#: cmd_code: an add taken by a slot or a remove done (ok); an add with every slot taken or a remove of
#: an id that is not live (refused); with the capacity rule, an add whose init job does not fit its frame
#: (cycles, reported at that frame's start); an add whose box the engine rejected (box, reported when the
#: engine's word shows it)
CMD_OK, CMD_REFUSED, CMD_CYCLES, CMD_BOX = 0, 1, 2, 3
_REJ = 1 << RESULT_FLAGS.index("rejected")
_NOT = 1 << RESULT_FLAGS.index("no_target")


@dataclass(frozen=True)
class Outcome:
    """One cmd_done report: ``code`` (CMD_*) and the slot ``target_id`` (0 for a refused add)."""
    code: int
    target_id: int


class CoreModelMulti:
    """The words of ``ms_tracker_multi`` with ``max_targets`` slots for an arbitrary input stream
    (module docstring)."""

    def __init__(self, tp: TrackerParams | None = None, fp: FixedParams | None = None, max_frame_w: int = 2048,
                 max_targets: int = 2, capacity: MultiCoreConfig | None = None) -> None:
        if not 1 <= max_targets <= 16:
            raise ValueError(f"max_targets must be 1 .. 16, got {max_targets}")
        if capacity is not None and capacity.max_targets != max_targets:
            raise ValueError(f"capacity.max_targets ({capacity.max_targets}) must be max_targets ({max_targets})")
        self.capacity = capacity
        self.tp, self.fp, self.max_frame_w, self.n = tp or TrackerParams(preset="v2"), fp or FixedParams(), \
            max_frame_w, max_targets
        self.frames: list[list[dict[str, int]]] = []
        self.outcomes: list[Outcome] = []
        self.reset()

    def reset(self) -> None:
        """The core's reset: every engine, slot and counter."""
        self.engines = [CoreModelV2(self.tp, self.fp, self.max_frame_w) for _ in range(self.n)]
        self.alloc = [False] * self.n
        self.pend = [False] * self.n
        self.rej_flag = False
        self.merged = 0                       # engine results merged (the same index in every engine)
        self.count = 0
        self.order: list[int] = []            # capacity rule: slots in the order their adds were taken
        self.waiting: dict[int, tuple] = {}   # capacity rule: adds taken since the last frame start
        #: capacity rule: each frame's plan (:class:`mstrack.fixed.multi_capacity.FramePlan`), in order
        self.plans: list = []

    @property
    def results(self) -> list[dict[str, int]]:
        """Every word, frame after frame, in stream order."""
        return [w for f in self.frames for w in f]

    @property
    def live(self) -> list[int]:
        """Slots holding a target or an add waiting for its engine's first word (the ``live`` port)."""
        return [k for k in range(self.n) if self.alloc[k]]

    # -- commands ----------------------------------------------------------------------------------
    def add(self, box: tuple[int, int, int, int], fw: int, fh: int) -> int | None:
        """An add taken while frame_width, frame_height = fw, fh: the slot, or None when refused."""
        free = [k for k in range(self.n) if not self.alloc[k]]
        if not free:
            self.rej_flag = True
            self.outcomes.append(Outcome(CMD_REFUSED, 0))
            return None
        k = free[0]
        self.alloc[k] = self.pend[k] = True
        x, y, w, h = (int(v) for v in box)
        if self.capacity is not None:         # initialised at the next frame's start if it fits
            self.waiting[k] = ((x, y, w, h), fw, fh)
            self.order.append(k)
        else:
            self.engines[k].init((x, y, w, h), fw, fh)
        self.outcomes.append(Outcome(CMD_OK, k))
        return k

    def remove(self, target_id: int) -> bool:
        """A remove taken: True when the slot was live (its engine is reset)."""
        if 0 <= target_id < self.n and self.alloc[target_id]:
            self.engines[target_id].reset()
            self.alloc[target_id] = self.pend[target_id] = False
            self.waiting.pop(target_id, None)
            if target_id in self.order:
                self.order.remove(target_id)
            self.outcomes.append(Outcome(CMD_OK, target_id))
            return True
        self.outcomes.append(Outcome(CMD_REFUSED, target_id & 0xF))
        return False

    # -- the stream ----------------------------------------------------------------------------------
    def beat(self, data: int, tuser: int, tlast: int, fw: int, fh: int) -> None:
        """One beat taken by every engine."""
        if tuser and self.capacity is not None:
            self._plan()
        for e in self.engines:
            e.beat(data, tuser, tlast, fw, fh)
        n = len(self.engines[0].results)
        if any(len(e.results) != n for e in self.engines):
            raise AssertionError("the engines see the same beats, so they give the same number of results")
        while self.merged < n:
            self._merge([e.results[self.merged] for e in self.engines])
            self.merged += 1

    def _plan(self) -> None:
        """The capacity rule at a frame's start (module docstring)."""
        from ..fixed.multi_capacity import ADD_OK, TargetDemand, check_add, plan_frame, target_demand
        cap = self.capacity
        assert cap is not None
        trackers = {k: e.v2 for k, e in enumerate(self.engines) if e.v2 is not None and not e.pending}
        live = [k for k in self.order if k in trackers]
        demands = {k: target_demand(trackers[k], k, costs=cap.costs) for k in live}
        plan = plan_frame([demands[k] for k in live], cap)
        self.plans.append(plan)
        admitted: list[TargetDemand] = list(plan.jobs)
        n_live = len(self.order) - len(self.waiting)
        for k in live:
            self.engines[k].hold = demands[k] if k in plan.held else None
        # accepted adds whose init frame had a fault keep their verdict: a fault changes no state, so the
        # live targets' jobs are those the add was checked against, and it is checked before this frame's adds
        for k in self.order:
            pending = self.engines[k].pending
            if pending is not None:
                (fw, fh) = self.engines[k].tgt
                new = self._init_job(pending[0], fw, fh, k)
                admitted += [new] if new is not None else []
        for k, (box, fw, fh) in list(self.waiting.items()):
            del self.waiting[k]
            new = self._init_job(box, fw, fh, k)
            if new is not None and check_add(admitted, n_live, new, cap) != ADD_OK:
                self.alloc[k] = self.pend[k] = False
                self.order.remove(k)
                self.rej_flag = True
                self.outcomes.append(Outcome(CMD_CYCLES, k))
                continue
            self.engines[k].init(box, fw, fh)
            n_live += 1
            admitted += [new] if new is not None else []

    def _init_job(self, box: tuple, fw: int, fh: int, k: int):
        """The add's init job, or None for a box its engine rejects (reported CMD_BOX by the engine's word)."""
        from ..fixed.multi_capacity import init_demand
        assert self.capacity is not None
        try:
            return init_demand(box, fw, fh, k, self.tp, self.fp, self.capacity.costs)
        except ValueError:
            return None

    def _merge(self, words: list[dict[str, int]]) -> None:
        rej = self.rej_flag
        for k, w in enumerate(words):
            rej = rej or bool(w["flags"] & _REJ)
            if self.pend[k]:
                if w["flags"] & _REJ:
                    self.alloc[k] = self.pend[k] = False
                    if k in self.order:               # the slot is free: out of the age order
                        self.order.remove(k)
                    self.outcomes.append(Outcome(CMD_BOX, k))
                elif not w["flags"] & _NOT:
                    self.pend[k] = False
        self.rej_flag = False
        live = [k for k, w in enumerate(words) if not w["flags"] & _NOT] or [0]
        out = []
        for i, k in enumerate(live):
            w = {**words[k], "target_id": k, "frame_count": self.count & 0xFFFF}
            if i == 0 and rej:
                w["flags"] |= _REJ
            pack_result_multi(w)              # every field fits its width (ValueError otherwise)
            out.append(w)
        self.frames.append(out)
        self.count += 1


def diff_words(words: Sequence[dict], frames: Sequence[Sequence[dict[str, int]]]) -> list[str]:
    """The words a core sent (field dicts of :func:`mstrack.fixed.vhdl_pkg.unpack_result_multi` with
    ``last``, the stream's tlast) against the model's words of each frame (:attr:`CoreModelMulti.frames`):
    every compared field, the target id, tlast on each frame's last word; one string per difference,
    empty when bit-exact."""
    want = [(w, i, j == len(f) - 1) for i, f in enumerate(frames) for j, w in enumerate(f)]
    out = [] if len(words) == len(want) else [f"{len(words)} beats, the model has {len(want)} words"]
    for b, (w, i, last) in zip(words, want):
        d = diff_fields(b, w, (*COMPARED_FIELDS_V2, "target_id"))
        if bool(b["last"]) != last:
            d.append(f"tlast: dut={b['last']} model={int(last)}")
        if d:
            out.append(f"frame {i} target {w['target_id']}: " + "; ".join(d))
    return out


def frame_beats(words, fault: str | None = None) -> list[tuple[int, int, int]]:
    """The beats (data, tuser, tlast) of one frame of 24-bit words as the harness streams it: whole, or
    with a fault: ``short_line`` (row 5 three pixels short, tlast on its last), ``cut`` (the first 700
    beats only; the next frame's start of frame cuts it); ``short_line:R`` and ``cut:N`` put the short
    line at row R, the cut after N beats."""
    kind, _, at = (fault or "").partition(":")
    if kind not in ("", "short_line", "cut") or (at and not at.isdigit()):
        raise ValueError(f"fault {fault!r}: short_line[:ROW] or cut[:BEATS]")
    h, w = words.shape
    row = int(at) if at else 5
    out = []
    for y in range(h):
        n = w - 3 if kind == "short_line" and y == row else w
        out += [(int(words[y, x]), int(x == 0 and y == 0), int(x == n - 1)) for x in range(n)]
    return out[:int(at) if at else 700] if kind == "cut" else out


def expected_multi(frames, commands: dict[int, list[tuple]], tp: TrackerParams | None = None,
                   fp: FixedParams | None = None, max_targets: int = 2, max_frame_w: int = 2048,
                   faults: dict[int, str] | None = None, capacity: MultiCoreConfig | None = None) -> CoreModelMulti:
    """The model fed as :func:`mstrack.hw.fastsim.simulate_multi` feeds the core: *commands* (``{frame:
    [("add", (x, y, w, h)) | ("remove", id), ...]}``) before the frames they are keyed by, every frame
    (BGR arrays) as :func:`frame_beats` streams it with its fault in *faults*.  Returns the model
    (``frames``, ``results``, ``outcomes``)."""
    from .cosim import frame_words
    m = CoreModelMulti(tp, fp, max_frame_w, max_targets, capacity)
    n = 0
    for i, fr in enumerate(frames):
        words = frame_words(fr)
        h, w = words.shape
        for op, arg in commands.get(i, []):
            m.add(arg, w, h) if op == "add" else m.remove(arg)
        for b in frame_beats(words, (faults or {}).get(i)):
            m.beat(*b, w, h)
        n = i + 1
    for op, arg in commands.get(n, []):
        m.add(arg, w, h) if op == "add" else m.remove(arg)
    return m


__all__ = ["CoreModelMulti", "expected_multi", "diff_words", "frame_beats", "Outcome", "CMD_OK", "CMD_REFUSED",
           "CMD_CYCLES", "CMD_BOX"]
