"""What the multi-target core outputs for an arbitrary input stream: :class:`CoreModelMulti`.

The executable specification of the multi-target core's ports (docs/multi_target_core.md, "Ports
and result stream"), the model its RTL is to be compared with, word by word.  It is
:class:`mstrack.hw.cosim.CoreModelV2`'s stream checker and frame gate around the fixed-point
:class:`mstrack.MultiTracker` (so each target is tracked bit for bit as a single fixed-point
tracker v2, and the capacity rule of :mod:`mstrack.fixed.multi_capacity` holds or refuses), with:

* **commands** (the init stream with an op and an id, or the AXI4-Lite command registers), taken
  between frames like core v2's init box and applied, in arrival order, on the next good frame:
  ``add(box, fw, fh)``: a new target, its id the lowest free slot (refused: the box does not clip
  to the frame, ``ADD_FULL``, ``ADD_CYCLES``); ``remove(id)``: no word for that id from that frame on
  (an id that is not live is ignored);
* **words**: after each good frame, one word per live target in ascending id order
  (:func:`mstrack.fixed.vhdl_pkg.pack_result_multi`: result word v2 + the id): tracked, held
  (status error, ``err_code`` 6) and the frame's new targets (status init / clipped) alike; the
  live targets' words come from :meth:`MultiTracker.update`, the adds are initialised after it on
  the same frame; a frame with no live target gives one ``no_target`` word (id 0), as core v2;
* **stream faults** (short / long line, missing start, cut frame, size out of range) and a good frame
  of another size than the live targets': one error word per live target (status error, flag
  ``error``, the ``err_code`` of core v2, the target's centre and size, its state unchanged), or one
  error word with ``no_target`` when none is live; the commands stay queued;
* **refusals**: the flag ``rejected`` on the first word of the frame on which an add was refused;
  the reason and the frame are in :attr:`CoreModelMulti.adds` (the core's ADD_STATUS register);
* ``frame_count``: the frames the core has seen (good or not) since reset, the same in every word
  of a frame.

Feed it, in stream order, ``beat(data, tuser, tlast, fw, fh)`` for every accepted beat,
``add`` / ``remove`` where a command was taken, and ``reset()``.  ``frames`` holds, per result
frame, the list of predicted words as field dicts (``target_id`` included).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cosim import ERR_NAMES, ERR_SIZE_CHANGED, CoreModelV2, flags_word, words_frame
from ..fixed import FixedParams
from ..fixed.blocks import ms_box_clip
from ..fixed.multi_capacity import ADD_CYCLES, ADD_FULL, ADD_OK, MultiCoreConfig
from ..fixed.vhdl_pkg import STATUS_V2, pack_result_multi, result_fields_v2
from ..track.params import TrackerParams

#: outcome of an add (the ADD_STATUS register's code): the capacity rule's codes, and a box that does
#: not clip to the frame (core v2's rejected init box)
ADD_BOX = 3
ADD_CODES = {ADD_OK: "ok", ADD_FULL: "full", ADD_CYCLES: "cycles", ADD_BOX: "box"}


@dataclass(frozen=True)
class AddOutcome:
    """One add, as the core reports it: the result frame it was applied on, its code (:data:`ADD_CODES`)
    and the id it was given (-1 when refused)."""
    frame: int
    code: int
    target_id: int


class CoreModelMulti(CoreModelV2):
    """The multi-target core's words for an arbitrary input stream (module docstring).

    ``capacity``: the core's :class:`~mstrack.fixed.multi_capacity.MultiCoreConfig` (``max_targets`` =
    the generic MAX_TARGETS, the video timing and pass costs the capacity rule uses).
    """

    def __init__(self, tp: TrackerParams | None = None, fp: FixedParams | None = None, max_frame_w: int = 2048,
                 capacity: MultiCoreConfig | None = None) -> None:
        self.capacity = capacity or MultiCoreConfig()
        self.frames: list[list[dict[str, int]]] = []
        self.adds: list[AddOutcome] = []
        super().__init__(tp or TrackerParams(preset="v2"), fp or FixedParams(), max_frame_w)

    def _reset_state(self) -> None:
        from ..track.multi import MultiTracker
        super()._reset_state()
        from dataclasses import asdict
        self.mt = MultiTracker("fixed", self.tp, capacity=self.capacity, **asdict(self.fp))
        self.queue: list[tuple] = []          # ("add", box, fw, fh) / ("remove", id), in arrival order
        self.refused = False                  # an add refused since the last word

    # -- commands ----------------------------------------------------------------------------------
    def add(self, box: tuple[int, int, int, int], fw: int, fh: int) -> None:
        """An add command taken while frame_width, frame_height = fw, fh (applies on the next good frame)."""
        self.queue.append(("add", tuple(int(v) for v in box), fw, fh))

    def remove(self, target_id: int) -> None:
        """A remove command (applies on the next good frame)."""
        self.queue.append(("remove", int(target_id)))

    def init(self, box: tuple[int, int, int, int], fw: int, fh: int) -> None:
        """Core v2's init box is an add here."""
        self.add(box, fw, fh)

    def has_target(self) -> bool:
        return bool(self.mt.targets)

    # -- words ---------------------------------------------------------------------------------------
    def _emit(self, words: list[dict[str, int]], kind: str) -> None:
        count = self.count & 0xFFFF
        for w in words:
            w["frame_count"] = count
        if self.refused:
            words[0]["flags"] |= flags_word(rejected=1)
            self.refused = False
        self.count += 1
        self.frames.append(words)
        self.kinds.append(kind)
        self.epochs.append(self.epoch)
        for w in words:
            pack_result_multi(w)              # every field fits its width (ValueError otherwise)

    @property
    def results(self) -> list[dict[str, int]]:  # type: ignore[override]
        """Every word, frame after frame, in stream order."""
        return [w for f in getattr(self, "frames", []) for w in f]

    @results.setter
    def results(self, value: list) -> None:      # CoreModel's constructor assigns []
        pass

    def _state_word(self, tid: int, **fields: int) -> dict[str, int]:
        trk = self.mt.tracker(tid).impl
        w = {"cx": trk.c8[0], "cy": trk.c8[1], "w8": trk.w8, "h8": trk.h8, "rho": 0, "confidence": 0, "status": 0,
             "iter": 0, "stop": 0, "decim_log2": 0, "searched": 0, "flags": 0, "err_code": 0, "target_id": tid}
        w.update(fields)
        return w

    def _no_target_word(self, **fields: int) -> dict[str, int]:
        w = {"cx": 0, "cy": 0, "w8": 0, "h8": 0, "rho": 0, "confidence": 0, "status": 0, "iter": 0, "stop": 0,
             "decim_log2": 0, "searched": 0, "flags": flags_word(no_target=1), "err_code": 0, "target_id": 0}
        w.update(fields)
        return w

    def _error(self, code: int) -> None:
        err = STATUS_V2.index("error")
        if self.mt.targets:
            words = [self._state_word(t, status=err, err_code=code, flags=flags_word(error=1))
                     for t in self.mt.targets]
        else:
            words = [self._no_target_word(status=err, err_code=code, flags=flags_word(error=1, no_target=1))]
        self._emit(words, f"error:{ERR_NAMES[code]}")

    def _frame(self, words: np.ndarray) -> None:
        h, w = words.shape
        live = self.mt.targets
        shape = self.mt._shape
        if live and shape is not None and (w, h) != (shape[1], shape[0]):
            self._error(ERR_SIZE_CHANGED)
            return
        frame = words_frame(words)
        keep: list[tuple] = []
        adds: list[tuple[int, int, int, int]] = []
        for op in self.queue:
            if op[0] == "remove":
                if op[1] in self.mt.targets:
                    self.mt.remove(op[1])
            elif (op[2], op[3]) != (w, h):
                keep.append(op)                   # an add for another frame size waits for one
            else:
                adds.append(op[1])
        self.queue = keep
        out: dict[int, dict[str, int]] = {}
        for tid, r in zip(self.mt.targets, self.mt.update(frame)):   # both in ascending id order
            out[tid] = {**result_fields_v2(r.extra), "target_id": tid}
        frame_no = len(self.frames)
        for box in adds:
            code, tid = self._try_add(frame, box, w, h)
            self.adds.append(AddOutcome(frame_no, code, tid))
            if code == ADD_OK:
                r = self.mt.last[tid]
                out[tid] = {**result_fields_v2(r.extra), "target_id": tid}
            else:
                self.refused = True
        if out:
            kind = "init" if adds and not live else "track"
            self._emit([out[t] for t in sorted(out)], kind)
        else:
            self._emit([self._no_target_word()], "no_target")

    def _try_add(self, frame: np.ndarray, box: tuple[int, int, int, int], w: int, h: int) -> tuple[int, int]:
        from ..track.multi import CapacityError
        if ms_box_clip(*box, w, h, (1 << (self.fp.coord_bits - 1)) - 1)[0] is None or not self.size_ok(w, h):
            return ADD_BOX, -1
        try:
            return ADD_OK, self.mt.add(frame, box)
        except CapacityError as e:
            return e.add_code, -1
        except ValueError:
            return ADD_BOX, -1


__all__ = ["CoreModelMulti", "AddOutcome", "ADD_BOX", "ADD_CODES"]
