"""Co-simulation support: what the RTL must output, computed by the fixed-point model.

The RTL result word (fields in :func:`mstrack.fixed.vhdl_pkg.result_layout`) is compared
field by field, frame by frame, with :func:`expected_results`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Iterable, Sequence

import numpy as np

from ..fixed import FixedParams, FixedTracker
from ..fixed.blocks import init_centre, ms_box_clip
from ..fixed.vhdl_pkg import DEFAULT_LANES, RESULT_FLAGS, core_generics, result_layout
from ..track.params import TrackerParams
from ..track.types import Status

if TYPE_CHECKING:
    from ..fixed.tracker_v2 import FixedTrackerV2

COMPARED_FIELDS = ("cx", "cy", "rho_c", "rho_e", "alpha_c", "iter_c", "iter_e", "stop_c", "stop_e",
                   "flags", "err_code", "box_w", "box_h", "frame_count")


def flags_word(**kw: int) -> int:
    """Pack named flags (RESULT_FLAGS) into the flags field."""
    v = 0
    for i, name in enumerate(RESULT_FLAGS):
        if kw.pop(name, 0):
            v |= 1 << i
    if kw:
        raise KeyError(f"unknown flags {sorted(kw)}")
    return v


def expected_results(frames: Iterable[np.ndarray], box: tuple[int, int, int, int],
                     tp: TrackerParams, fp: FixedParams, first_count: int = 0) -> list[dict[str, int]]:
    """Result fields the core must produce for ``frames`` with the init box on the first frame.

    box: integer (x, y, w, h) as given to the core's init port.
    """
    trk = FixedTracker(tp, fp)
    out: list[dict[str, int]] = []
    for i, frame in enumerate(frames):
        if i == 0:
            r = trk.init_int(frame, *box)
            fl = flags_word(init=1, clipped=int(r.status == Status.CLIPPED))
        else:
            r = trk.update(frame)
            fl = flags_word(lost=r.extra["lost"])
        e = r.extra
        assert trk._t is not None
        ib = trk._t.box
        out.append({"cx": e["cx"], "cy": e["cy"], "rho_c": e["rho_c"], "rho_e": e["rho_e"],
                    "alpha_c": e["alpha_c"], "iter_c": e["iter_c"], "iter_e": e["iter_e"],
                    "stop_c": e["stop_c"], "stop_e": e["stop_e"], "flags": fl, "err_code": 0,
                    "box_w": ib.w, "box_h": ib.h, "frame_count": (first_count + i) & 0xFFFF})
    return out


def frame_words(frame: np.ndarray) -> np.ndarray:
    """(H, W) int array of 24-bit pixels R<<16 | G<<8 | B from a BGR uint8 frame."""
    f = frame.astype(np.int64)
    return (f[..., 2] << 16) | (f[..., 1] << 8) | f[..., 0]


def diff_fields(got: dict[str, int], exp: dict[str, int],
                fields: Sequence[str] = COMPARED_FIELDS) -> list[str]:
    """Human-readable mismatches between a DUT result and the model."""
    return [f"{k}: dut={got.get(k)} model={exp.get(k)}" for k in fields if got.get(k) != exp.get(k)]


@dataclass
class CoreConfig:
    """Model parameters + lanes (+ pixels per clock) -> the generics of ms_tracker.

    ppc: pixels per clock of the video input (generic PPC, 1, 2 or 4, <= lanes); the results do
    not depend on it.  PPC = 1 is not passed (the core's default), so the generic sets (and build
    names) of the one-pixel core stay as they were."""

    tp: TrackerParams
    fp: FixedParams
    lanes: int = DEFAULT_LANES
    max_frame_w: int = 2048
    ppc: int = 1

    def generics(self) -> dict[str, int]:
        g = core_generics(self.tp, self.fp, self.lanes)
        g["MAX_FRAME_W"] = self.max_frame_w
        if self.ppc != 1:
            g["PPC"] = self.ppc
        return g

    def layout(self) -> list[tuple[str, int, int]]:
        return result_layout(self.generics())


def clip_ok(box: tuple[int, int, int, int], w: int, h: int, fp: FixedParams) -> bool:
    """True if the core accepts this init box for a w x h frame."""
    return ms_box_clip(*box, w, h, fp.max_half)[0] is not None


# ----------------------------------------------------------------------------- stream-level model
# Error codes of the result word (rtl/ms_stream_pkg.vhd).
ERR_SHORT_LINE, ERR_LONG_LINE, ERR_NO_SOF, ERR_CUT, ERR_SIZE, ERR_SIZE_CHANGED = range(6)
ERR_NAMES = ("short_line", "long_line", "no_sof", "cut", "size", "size_changed")
MIN_FRAME = 3           # smallest frame_width / frame_height the core accepts


def words_frame(words: np.ndarray) -> np.ndarray:
    """Inverse of :func:`frame_words`: (H, W) 24-bit words -> (H, W, 3) uint8 BGR."""
    w = np.asarray(words, dtype=np.int64)
    return np.stack([w & 0xFF, (w >> 8) & 0xFF, (w >> 16) & 0xFF], axis=-1).astype(np.uint8)


class CoreModel:
    """What ms_tracker outputs for an arbitrary input stream (docs/architecture.md, errors).

    The fixed-point model :class:`FixedTracker` computes every tracked frame; this class adds
    the system behaviour around it, beat by beat, as the RTL defines it: the stream checker
    (ms_stream_check: short / long line, missing start of frame, cut frame, frame size out of
    range), the top's frame gate (the line count that decides when an init box may be taken),
    init boxes (clipped / rejected, taken between frames, applying to the next frame), frames of
    another size than the target's (error ``size_changed``, state unchanged), results before
    any init (``no_target``) and reset.

    Feed it, in stream order, ``beat(data, tuser, tlast, fw, fh)`` for every accepted beat
    (fw, fh: frame_width / frame_height at that beat), ``init(box, fw, fh)`` where an init box
    was taken, and ``reset()``.  ``results`` holds the predicted result words (dicts of the
    COMPARED_FIELDS) in order; ``epochs[i]`` the reset epoch of result i.
    """

    def __init__(self, tp: TrackerParams, fp: FixedParams, max_frame_w: int, ppc: int = 1) -> None:
        self.tp, self.fp, self.max_frame_w, self.ppc = tp, fp, max_frame_w, ppc
        self.results: list[dict[str, int]] = []
        self.kinds: list[str] = []          # "init", "track", "no_target", "error:<code name>"
        self.epochs: list[int] = []
        self.epoch = 0
        self._reset_state()

    # -- state -------------------------------------------------------------------------------
    def _reset_state(self) -> None:
        self.trk: FixedTracker | None = None       # target_valid
        self.pending: tuple | None = None          # init_pending: (box, clipped)
        self.rejected = 0
        self.c8 = (0, 0)
        self.box_wh = (0, 0)
        self.tgt = (MIN_FRAME, MIN_FRAME)
        self.count = 0
        # ms_stream_check
        self.sc = "wait"
        self.W = self.H = 0
        self.x = self.y = 0
        self.rows: list[list[int]] = []
        # the top's frame gate (line count)
        self.in_frame = False
        self.line = 0
        self.fr_h = 0

    def reset(self) -> None:
        self._reset_state()
        self.epoch += 1

    def has_target(self) -> bool:
        """A target is valid (its init frame was learnt)."""
        return self.trk is not None

    def size_ok(self, fw: int, fh: int) -> bool:
        """The frame size check (ERR_SIZE): also a width that is not a multiple of PPC."""
        return fw >= MIN_FRAME and fh >= MIN_FRAME and fw <= self.max_frame_w and fw % self.ppc == 0

    # -- results -----------------------------------------------------------------------------
    def _push(self, kind: str, flags: dict[str, int] | None = None, **fields: int) -> None:
        r = {"cx": self.c8[0], "cy": self.c8[1], "rho_c": 0, "rho_e": 0, "alpha_c": 0, "iter_c": 0,
             "iter_e": 0, "stop_c": 0, "stop_e": 0, "err_code": 0,
             "box_w": self.box_wh[0], "box_h": self.box_wh[1], "frame_count": self.count & 0xFFFF}
        r.update(fields)
        r["flags"] = flags_word(rejected=self.rejected, **(flags or {}))
        self.rejected = 0
        self.count += 1
        self.results.append(r)
        self.kinds.append(kind)
        self.epochs.append(self.epoch)

    def _error(self, code: int) -> None:
        self._push(f"error:{ERR_NAMES[code]}", err_code=code,
                   flags={"error": 1, "no_target": int(self.trk is None)})

    def init(self, box: tuple[int, int, int, int], fw: int, fh: int) -> None:
        """An init box taken while frame_width, frame_height = fw, fh."""
        ib, clipped = ms_box_clip(*box, fw, fh, self.fp.max_half)
        if ib is None or not self.size_ok(fw, fh):
            self.rejected = 1                      # the previous target (or pending init) stays
            return
        self.pending = (tuple(box), clipped)
        self.trk = None
        self.c8 = init_centre(ib, self.fp.centre_frac)
        self.box_wh = (ib.w, ib.h)
        self.tgt = (fw, fh)

    def _frame(self, words: np.ndarray) -> None:
        """A good frame (as far as the stream goes) reached the control."""
        h, w = words.shape
        if (self.pending or self.trk) and (w, h) != self.tgt:
            self._error(ERR_SIZE_CHANGED)
            return
        if self.pending:
            box, clipped = self.pending
            trk = FixedTracker(self.tp, self.fp)
            r = trk.init_int(words_frame(words), *box)
            self.trk, self.pending = trk, None
            flags = {"init": 1, "clipped": int(clipped)}
            kind = "init"
        elif self.trk:
            r = self.trk.update(words_frame(words))
            flags = {"lost": r.extra["lost"]}
            kind = "track"
        else:
            self._push("no_target", flags={"no_target": 1})
            return
        e = r.extra
        self.c8 = (e["cx"], e["cy"])
        assert self.trk._t is not None
        self.box_wh = (self.trk._t.box.w, self.trk._t.box.h)
        self._push(kind, flags=flags, **{k: e[k] for k in ("cx", "cy", "rho_c", "rho_e", "alpha_c",
                                                            "iter_c", "iter_e", "stop_c", "stop_e")})

    # -- the stream --------------------------------------------------------------------------
    def beat(self, data: int, tuser: int, tlast: int, fw: int, fh: int) -> None:
        """One accepted beat (ms_stream_check, then the top's line count)."""
        # the top's frame gate: in_frame says whether an init box must wait
        was_in, line = self.in_frame, self.line
        if tuser:
            self.in_frame, self.fr_h, self.line = self.size_ok(fw, fh), fh, 0
        elif was_in and tlast:
            self.line += 1
        if was_in and not tuser and tlast and line == self.fr_h - 1:
            self.in_frame = False
        # ms_stream_check: at most one error per beat (the last code set wins)
        err = None
        active = False
        if tuser and not self.size_ok(fw, fh):
            err, self.sc = ERR_SIZE, "drop"
        elif tuser:
            if self.sc == "frame":
                err = ERR_CUT
            self.W, self.H, self.x, self.y, self.rows = fw, fh, 0, 0, [[]]
            active = True
        elif self.sc == "frame":
            active = True
        elif self.sc == "wait":
            err, self.sc = ERR_NO_SOF, "drop"
        done = None
        if active:
            x_last = self.x == self.W - 1
            if tlast and not x_last:
                err, self.sc = ERR_SHORT_LINE, "drop"
            elif not tlast and x_last:
                err, self.sc = ERR_LONG_LINE, "drop"
            else:
                self.sc = "frame"
                self.rows[-1].append(data)
                if x_last:
                    self.x, self.y = 0, self.y + 1
                    if self.y == self.H:
                        done = np.array(self.rows, dtype=np.int64)
                        self.sc = "wait"
                    else:
                        self.rows.append([])
                else:
                    self.x += 1
        if err is not None:
            self._error(err)
        if done is not None:
            self._frame(done)


# ----------------------------------------------------------------------------- core v2
#: fields of result word v2 compared frame by frame (mstrack.fixed.vhdl_pkg.result_layout_v2)
COMPARED_FIELDS_V2 = ("cx", "cy", "w8", "h8", "rho", "confidence", "status", "iter", "stop", "decim_log2",
                      "searched", "flags", "err_code", "frame_count")


def expected_results_v2(frames: Iterable[np.ndarray], box: tuple[int, int, int, int],
                        tp: TrackerParams | None = None, fp: FixedParams | None = None,
                        first_count: int = 0) -> list[dict[str, int]]:
    """Result word v2 fields ms_tracker_v2 must produce for ``frames`` (init box on the first).

    box: integer (x, y, w, h) as given to the core's init port (FixedTrackerV2 rounds a float box
    edge by edge; integers pass unchanged).  Fields from :func:`mstrack.fixed.vhdl_pkg.result_fields_v2`.
    """
    from ..fixed.tracker_v2 import FixedTrackerV2
    from ..fixed.vhdl_pkg import result_fields_v2
    trk = FixedTrackerV2(tp or TrackerParams(preset="v2"), fp or FixedParams())
    out: list[dict[str, int]] = []
    for i, frame in enumerate(frames):
        r = trk.init(frame, box) if i == 0 else trk.update(frame)
        out.append(result_fields_v2(r.extra, first_count + i))
    return out


def region_max_v2(tp: TrackerParams, fp: FixedParams, max_frame_size: int) -> int:
    """The widest search region (decimated px, either axis) of tracker v2's fixed model in frames up
    to ``max_frame_size`` px on either side, the rows and columns core v2's region RAM needs
    (docs/fixed_point.md "Search region").

    ms_region gives n = min(2e + 2m + 1, S - 2) with S the decimated frame size ((W - 1) >> log2 D) + 1.
    Three cases: tracking (e <= max_half, m = MARGIN); lost at D' = 2D <= MAX_DECIMATION: D was not the
    largest, (1 + pad) s <= max_window D exactly (ms_decimation), so the window at 2D is at most
    round_half_up(max_window / 2) px and the margin MARGIN + its search offset (at most 255); lost at
    D' = 2 MAX_DECIMATION: any window up to max_window, but S is that of the frame at D'.
    (The exhaustive check: tests/test_fixed_v2.py::test_lost_window_at_doubled_decimation_is_half.)
    """
    from ..fixed.blocks_v2 import MAX_DECIMATION, sixteenths
    step16 = sixteenths(tp.search_step, "search_step")

    def n(wd: int, lost: bool, d: int) -> int:
        e = (wd - 1) >> 1
        m = min(fp.margin + ((step16 * wd) >> 4), 255) if lost else fp.margin
        return min(2 * e + 2 * m + 1, ((max_frame_size - 1) // d + 1) - 2)

    win = 2 * fp.max_half + 1
    half = min((tp.max_window + 1) // 2, win)
    # n shrinks as D grows (S does), so each case's smallest D is its widest region
    return max(n(win, False, 1), n(half, True, 2), n(win, True, 2 * MAX_DECIMATION))


@dataclass
class CoreConfigV2:
    """Tracker v2 parameters + lanes -> the generics of ms_tracker_v2 (:meth:`generics`), or of
    ms_tracker with PRESET = 1 (:meth:`tracker_generics`: the entity integrators instantiate)."""
    tp: TrackerParams
    fp: FixedParams
    lanes: int = DEFAULT_LANES
    max_frame_w: int = 2048

    def __post_init__(self) -> None:
        # the experimental option motion_gain is in the float model only: a generic for it would build
        # a core that tracks differently from the model it names.  The default tracker v2's options have
        # RTL: the gated scale test (scale_test with scale_test_gate: generic SCALE_TEST_D256) and the
        # joint bins (orient_T: generic ORIENT_T); the ungated scale test has no fixed model either.
        tp = self.tp
        rtl_less = [k for k, off in (("motion_gain", 0.0), ("loss_ref_running", False),
                                          ("scale_test_margin", 0.0), ("search_widen", 0),
                                          ("rho_stop_margin", 0.0), ("loss_jump", 0.0), ("scale_ring_guard", 0.0),
                                          ("model_rate", 0.0), ("model_mix", 1.0),
                                          ("chroma_bins", 0), ("model_contrast", -1.0)) if getattr(tp, k) != off]
        # the wider model formats of the fixed model (FixedParams.model_frac, bg_frac) have no RTL yet
        rtl_less += [k for k, off in (("model_frac", 0), ("bg_frac", 8)) if getattr(self.fp, k) != off]
        if tp.scale_test != 0.0 and not tp.scale_test_gate:
            rtl_less.append("scale_test without scale_test_gate")
        if rtl_less:
            raise ValueError(f"core v2 has no RTL yet for {', '.join(rtl_less)} (float and fixed models only; "
                             "docs/results_v2_mean.md)")

    def generics(self) -> dict[str, int]:
        from ..fixed.blocks_v2 import q16, sixteenths
        from ..fixed.vhdl_pkg import result_width_v2, v2_scale_generics
        tp, fp = self.tp, self.fp
        g = core_generics(tp, fp, self.lanes)
        v = v2_scale_generics(tp, fp, self.lanes)
        pad16 = sixteenths(tp.pad, "pad")
        g.update({k: v[k] for k in ("PAD16", "KT_W", "ST2_W", "SHARE_W", "SPREAD_W", "SIZE_W", "SCALE_W",
                                    "SCALE_GAIN", "SCALE_REG", "SCALE_STEP", "WR_Q_W", "CON_W", "LOSS_K",
                                    "REF_K", "LOSS_RHO", "LOSS_CONTRAST")})
        g["SCALE_RATIO_Q_W"] = v["RATIO_Q_W"]
        g["RING16"] = sixteenths(tp.bg_ring, "bg_ring")
        g["MAX_WINDOW"] = tp.max_window
        g["CONF_LOST"] = q16(tp.conf_lost)
        g["CONF_UNCERTAIN"] = q16(tp.conf_uncertain)
        g["CONF_REACQUIRE"] = q16(tp.conf_reacquire)
        g["SPREAD_DEFAULT"] = (128 << (fp.kernel_bits + 16)) // (16 + pad16) ** 2
        g["RESULT_W"] = result_width_v2(core_generics(tp, fp, self.lanes))
        # the lost state: start points +- search_step windows, the region margin grows by that offset
        # (at most 255, as the model); the region RAM and the engine's region widths hold the widest
        # region the model can ask for (region_max_v2), rounded up to a multiple of LANES
        step16 = sixteenths(tp.search_step, "search_step")
        g["SEARCH_ITER"] = tp.search_iter
        g["STEP16"] = step16
        g["MARGIN_MAX"] = 255
        # (frame_width <= MAX_FRAME_W, frame_height < 2**COORD_W)
        rmax = region_max_v2(tp, fp, max(self.max_frame_w, 2 ** g["COORD_W"] - 1))
        rmax = max(-(-rmax // self.lanes) * self.lanes, g["REGION_MAX"])
        stride = -(-rmax // self.lanes)
        g["REGION_MAX"] = rmax
        g["REGION_W"] = rmax.bit_length()
        g["STRIDE"] = stride
        g["ADDR_W"] = (rmax * stride - 1).bit_length()
        g["CENTRE_W"] = g["REGION_W"] + fp.centre_frac
        g["MAX_FRAME_W"] = self.max_frame_w
        # the gated scale test (0 = off: mstrack-v2-colour; the VHDL default 13 = mstrack-v2's 0.05)
        g["SCALE_TEST_D256"] = self.scale_test_d256()
        # the joint colour x orientation bins (-1 = off: mstrack-v2-colour; the VHDL default 64)
        if tp.orient_T > 0 and g["EDGE_BINS_LOG2"] != 4:
            raise ValueError("the joint bins carry the orientation on the 4-bit edge path: edge_bins_log2 must be 4")
        g["ORIENT_T"] = int(tp.orient_T) if tp.orient_T > 0 else -1
        return g

    def scale_test_d256(self) -> int:
        """d256 = round(256 scale_test) of the gated scale test (0: off), as FixedTrackerV2."""
        if self.tp.scale_test <= 0:
            return 0
        d = round(self.tp.scale_test * 256)
        if not 1 <= d <= 255:   # d256 = 0 would be the generic's "off", while the model still gates
            raise ValueError(f"scale_test {self.tp.scale_test} gives d256 = {d}, core v2 needs 1 .. 255")
        return d

    def tracker_generics(self) -> dict[str, int]:
        """The generics of ``ms_tracker`` for core v2: PRESET = 1 and :meth:`generics` (ms_tracker passes
        them all, SCALE_TEST_D256 and ORIENT_T included, to the engine ms_tracker_v2)."""
        return {"PRESET": 1, **self.generics()}

    def generics_for(self, top: str) -> dict[str, int]:
        """:meth:`tracker_generics` for ``ms_tracker``, :meth:`generics` for ``ms_tracker_v2``."""
        if top == "ms_tracker":
            return self.tracker_generics()
        if top == "ms_tracker_v2":
            return self.generics()
        raise ValueError(f"core v2 is built as ms_tracker (PRESET 1) or ms_tracker_v2, not {top!r}")


class CoreModelV2(CoreModel):
    """What ms_tracker_v2 outputs for an arbitrary input stream (docs/architecture.md, "Core v2:
    stream faults"): :class:`CoreModel`'s stream checker, frame gate, init boxes, size checks and
    reset, around :class:`mstrack.fixed.tracker_v2.FixedTrackerV2`, with result word v2.

    Every field of every result is predicted (COMPARED_FIELDS_V2):

    * tracked / init frames: :func:`mstrack.fixed.vhdl_pkg.result_fields_v2` of the model's frame,
      plus the flag ``rejected`` when an init box was rejected since the last result;
    * error results (protocol errors, frame size out of range, a frame of another size than the
      target's): status 6 (error), flags ``error`` (+ ``no_target`` while there is no target: before
      any init or while an init is pending, + ``rejected``), ``err_code``; cx, cy, w8, h8 of the
      current target (the pending init box's centre and size while an init is pending: centre
      (2x + w - 1) << (CF - 1), size w << 8 of the clipped box; 0 after a reset); rho, confidence,
      iter, stop, decim_log2 and searched 0.  The target state (centre, size, model Qn and T,
      references, loss filters, search state lost / not lost) is unchanged: a lost target stays
      lost (the next good frame is searched at D x 2 with the 8 start points);
    * results without a target (``no_target``: no init since reset): status 0, cx, cy, w8, h8 of the
      state (0), the rest 0.
    A bad init frame leaves the init pending: the next good frame of the box's size is the init
    frame (the background model learns it from its first pixel; ms_tracker_v2 re-arms ms_bg_model).
    """

    def __init__(self, tp: TrackerParams, fp: FixedParams, max_frame_w: int) -> None:
        super().__init__(tp, fp, max_frame_w, ppc=1)

    def _reset_state(self) -> None:
        super()._reset_state()
        self.box_wh = (0, 0)                      # w8, h8 of the state
        self.v2: FixedTrackerV2 | None = None     # the target (CoreModel.trk stays None)
        #: the multi-target core's capacity rule for the next frame (CoreModelMulti with a capacity): the
        #: target's TargetDemand when it is held on that frame, else None
        self.hold: Any = None

    def has_target(self) -> bool:
        return self.v2 is not None

    def _push(self, kind: str, flags: dict[str, int] | int | None = None, **fields: int) -> None:
        """flags: named flags, or the flags field of result_fields_v2; ``rejected`` is added."""
        r = {"cx": self.c8[0], "cy": self.c8[1], "w8": self.box_wh[0], "h8": self.box_wh[1], "rho": 0,
             "confidence": 0, "status": 0, "iter": 0, "stop": 0, "decim_log2": 0, "searched": 0,
             "err_code": 0, "frame_count": self.count & 0xFFFF}
        r.update(fields)
        fl = flags if isinstance(flags, int) else flags_word(**(flags or {}))
        r["flags"] = fl | flags_word(rejected=self.rejected)
        self.rejected = 0
        self.count += 1
        self.results.append(r)
        self.kinds.append(kind)
        self.epochs.append(self.epoch)

    def _error(self, code: int) -> None:
        from ..fixed.vhdl_pkg import STATUS_V2
        self._push(f"error:{ERR_NAMES[code]}", err_code=code, status=STATUS_V2.index("error"),
                   flags={"error": 1, "no_target": int(self.v2 is None)})

    def init(self, box: tuple[int, int, int, int], fw: int, fh: int) -> None:
        """An init box taken while frame_width, frame_height = fw, fh (clipped without shrink, as
        FixedTrackerV2.init: large targets are decimated)."""
        ib, clipped = ms_box_clip(*box, fw, fh, (1 << (self.fp.coord_bits - 1)) - 1)
        if ib is None or not self.size_ok(fw, fh):
            self.rejected = 1
            return
        self.pending = (tuple(box), clipped)
        self.v2 = None
        self.c8 = init_centre(ib, self.fp.centre_frac)
        self.box_wh = (ib.w << 8, ib.h << 8)
        self.tgt = (fw, fh)

    def _frame(self, words: np.ndarray) -> None:
        from ..fixed.tracker_v2 import FixedTrackerV2
        from ..fixed.vhdl_pkg import result_fields_v2
        h, w = words.shape
        hold, self.hold = self.hold, None
        if (self.pending or self.v2) and (w, h) != self.tgt:
            self._error(ERR_SIZE_CHANGED)
            return
        if hold is not None and self.v2 and not self.pending:   # held by the capacity rule: the state stays
            from ..fixed.multi_capacity import held_result
            f = result_fields_v2(held_result(self.v2, hold).extra, self.count)
            del f["frame_count"]
            self._push("held", **f)
            return
        if self.pending:
            box, _ = self.pending
            trk = FixedTrackerV2(self.tp, self.fp)
            r = trk.init(words_frame(words), box)
            self.v2, self.pending = trk, None
            kind = "init"
        elif self.v2:
            trk = self.v2
            r = trk.update(words_frame(words))
            kind = "track"
        else:
            self._push("no_target", flags={"no_target": 1})
            return
        self.c8 = trk.c8
        self.box_wh = (trk.w8, trk.h8)
        f = result_fields_v2(r.extra, self.count)
        del f["frame_count"]
        self._push(kind, **f)
