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
from ..fixed.vhdl_pkg import RESULT_FLAGS, pack_result_multi
from ..track.params import TrackerParams

#: cmd_code: an add taken by a slot or a remove done (ok); an add with every slot taken or a remove of
#: an id that is not live (refused); an add whose box the engine rejected (box, reported when the
#: engine's word shows it)
CMD_OK, CMD_REFUSED, CMD_BOX = 0, 1, 3
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
                 max_targets: int = 2) -> None:
        if not 1 <= max_targets <= 16:
            raise ValueError(f"max_targets must be 1 .. 16, got {max_targets}")
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
        self.engines[k].init((x, y, w, h), fw, fh)
        self.outcomes.append(Outcome(CMD_OK, k))
        return k

    def remove(self, target_id: int) -> bool:
        """A remove taken: True when the slot was live (its engine is reset)."""
        if 0 <= target_id < self.n and self.alloc[target_id]:
            self.engines[target_id].reset()
            self.alloc[target_id] = self.pend[target_id] = False
            self.outcomes.append(Outcome(CMD_OK, target_id))
            return True
        self.outcomes.append(Outcome(CMD_REFUSED, target_id & 0xF))
        return False

    # -- the stream ----------------------------------------------------------------------------------
    def beat(self, data: int, tuser: int, tlast: int, fw: int, fh: int) -> None:
        """One beat taken by every engine."""
        for e in self.engines:
            e.beat(data, tuser, tlast, fw, fh)
        n = len(self.engines[0].results)
        if any(len(e.results) != n for e in self.engines):
            raise AssertionError("the engines see the same beats, so they give the same number of results")
        while self.merged < n:
            self._merge([e.results[self.merged] for e in self.engines])
            self.merged += 1

    def _merge(self, words: list[dict[str, int]]) -> None:
        rej = self.rej_flag
        for k, w in enumerate(words):
            rej = rej or bool(w["flags"] & _REJ)
            if self.pend[k]:
                if w["flags"] & _REJ:
                    self.alloc[k] = self.pend[k] = False
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
    beats only; the next frame's start of frame cuts it)."""
    h, w = words.shape
    out = []
    for y in range(h):
        n = w - 3 if fault == "short_line" and y == 5 else w
        out += [(int(words[y, x]), int(x == 0 and y == 0), int(x == n - 1)) for x in range(n)]
    return out[:700] if fault == "cut" else out


def expected_multi(frames, commands: dict[int, list[tuple]], tp: TrackerParams | None = None,
                   fp: FixedParams | None = None, max_targets: int = 2, max_frame_w: int = 2048,
                   faults: dict[int, str] | None = None) -> CoreModelMulti:
    """The model fed as :func:`mstrack.hw.fastsim.simulate_multi` feeds the core: *commands* (``{frame:
    [("add", (x, y, w, h)) | ("remove", id), ...]}``) before the frames they are keyed by, every frame
    (BGR arrays) as :func:`frame_beats` streams it with its fault in *faults*.  Returns the model
    (``frames``, ``results``, ``outcomes``)."""
    from .cosim import frame_words
    m = CoreModelMulti(tp, fp, max_frame_w, max_targets)
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


__all__ = ["CoreModelMulti", "expected_multi", "diff_words", "frame_beats", "Outcome", "CMD_OK", "CMD_REFUSED", "CMD_BOX"]
