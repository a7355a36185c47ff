"""Capacity rule of the multi-target core (docs/multi_target_core.md, "Capacity rule").

The multi-target core shares one front end and one mean-shift engine between up to ``MAX_TARGETS``
targets.  Each target's work of a frame (its *job*: the mean shift, the statistics, the result
word, or on the frame it is added the background model) runs on the shared engine after its own
search region has streamed in, and must end before the next frame's raster reaches that target's
next region (the capture of the next region needs the result of this one).  This module is the
rule the core applies, as integers, so the fixed-point MultiTracker applies it bit for bit:

* :func:`target_demand`: the job of a live target on its next frame, from its
  :class:`~mstrack.fixed.tracker_v2.FixedTrackerV2` state (the geometry ``update`` computes);
* :func:`init_demand`: the job of a target added on a frame with a box;
* :func:`plan_frame`: which live targets are tracked on a frame and which are *held* (not tracked
  on that frame: state unchanged, result word status 6 error with ``err_code``
  :data:`ERR_CAPACITY`);
* :func:`check_add`: whether an add is taken (:data:`ADD_OK`) or refused (:data:`ADD_FULL`,
  :data:`ADD_CYCLES`);
* :func:`held_result`: the result of a held target.

``mstrack.MultiTracker(model="fixed")`` applies the rule on every ``add`` and ``update``
(docs/multi.md, "The capacity rule").

The rule (a sufficient condition for every deadline of a frame, whatever the order the engine
takes the jobs in, as long as it never idles while a job waits): the jobs admitted on a frame
satisfy ``sum(clocks) <= min(slack)``, where ``clocks`` is the job's worst case (every iteration
at the worst LANES alignment) and ``slack`` the clocks from the end of its region in this frame
to the earliest line its next region can start in the next frame.  Targets are admitted oldest
first (the order the caller passes them in: the order they were added); one that does not fit
is held and the next ones are still tried.  Memory never limits a live target: every target owns
a region slot sized for the widest region its parameters allow (docs/multi_target_core.md,
"Memory plan"), so memory is a configuration-time choice (``MAX_TARGETS`` x slot), not a run-time
rule.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal, Sequence

import numpy as np

from ..track.params import TrackerParams
from ..track.types import Box, Status, TrackResult
from .blocks import Region, ms_box_clip, ms_kernel, ms_region, ms_round_centre, round_box
from .blocks_v2 import ms_box_size, ms_decimation, ms_region_v2, ms_window_size, q16, sixteenths
from .formats import FixedParams
from .tracker_v2 import STATUS_CODES_V2, FixedTrackerV2

#: :func:`check_add` results.  ADD_FULL: ``MAX_TARGETS`` targets are live; ADD_CYCLES: the new
#: target's init job with this frame's admitted jobs breaks the cycle rule.
ADD_OK, ADD_FULL, ADD_CYCLES = 0, 1, 2
ADD_CODES = {ADD_OK: "ok", ADD_FULL: "full", ADD_CYCLES: "cycles"}
#: The constants' names, by value (what ``mstrack.CapacityError.code`` says).
ADD_NAMES = {ADD_OK: "ADD_OK", ADD_FULL: "ADD_FULL", ADD_CYCLES: "ADD_CYCLES"}
#: ``err_code`` of the result word of a held target (status 6 error; codes 0..5 are the stream
#: faults of rtl/ms_stream_pkg.vhd).
ERR_CAPACITY = 6
#: ``MAX_TARGETS`` range of the core's generic.
MAX_TARGETS_RANGE = (1, 16)

JobKind = Literal["init", "track", "lost"]


@dataclass(frozen=True)
class VideoTiming:
    """Raster timing in core clocks (one pixel per clock): default CEA-861 1080p60 at 148.5 MHz."""

    active_lines: int = 1080
    frame_lines: int = 1125
    line_clocks: int = 2200

    def __post_init__(self) -> None:
        if not (1 <= self.active_lines < self.frame_lines and self.line_clocks >= 1):
            raise ValueError(f"bad video timing {self}: needs 1 <= active_lines < frame_lines, line_clocks >= 1")

    @property
    def frame_clocks(self) -> int:
        return self.frame_lines * self.line_clocks

    @property
    def blank_clocks(self) -> int:
        """Vertical blanking (clocks between a frame's last active line and the next frame)."""
        return (self.frame_lines - self.active_lines) * self.line_clocks


@dataclass(frozen=True)
class PassCosts:
    """Clocks of the shared engine's steps, default core v2 generics, LANES 4 (the values of
    ``mstrack.hw.synth``'s cycle model; ``mstrack.hw.multi_core.pass_costs`` builds them for other
    generics and tests/test_multi_core.py checks these defaults against it)."""

    lanes: int = 4
    pass_lat: int = 10          # ms_pixel_pass: sum of row groups + PASS_LAT
    bin_pass: int = 547         # ms_bin_pass, track pass over the 512 colour addresses
    bank_tree: int = 4          # + per bin pass with the 9 orientation banks (orient_T > 0)
    learn_pass: int = 517       # ms_bin_pass, learn pass
    centre: int = 20            # ms_centre
    iter_overhead: int = 6      # ms_meanshift controller per iteration
    front: int = 12             # region complete -> engine start
    back: int = 3               # engine done -> result word
    v2_overhead: int = 560      # per frame: divisions, isqrt, confidence / loss blocks, kernel tables
    confidence: int = 57        # ms_confidence, per extra start point of the wide search
    kernel_tables: int = 289    # ms_kernel_tables with KA/KB, worst
    qload_extra: int = 6        # Qw load = colour addresses + 6
    scale_window_extra: int = 77  # per scale-test window: size / window / fit 8 + bin pass tail 35 + rho 34
    bg_drain: int = 65          # ms_bg_model: 3 passes over the bins + 65
    init_start: int = 229       # init job (rtl/ms_init_job.vhd): ms_bg_model's set-up of the largest box, 217
                                # at HALF_W 6, + the slot scan's start: its read latency 5 + 7 registers
    job_switch: int = 64        # multi-target core: state record in / out, region set-up per job

    def __post_init__(self) -> None:
        if self.lanes < 1 or self.lanes & (self.lanes - 1):
            raise ValueError(f"lanes must be a power of two, got {self.lanes}")


@dataclass(frozen=True)
class MultiCoreConfig:
    """What the capacity rule depends on: ``MAX_TARGETS``, the raster timing (the cycle budget) and
    the engine's pass costs (LANES)."""

    max_targets: int = 16
    timing: VideoTiming = field(default_factory=VideoTiming)
    costs: PassCosts = field(default_factory=PassCosts)

    def __post_init__(self) -> None:
        lo, hi = MAX_TARGETS_RANGE
        if not lo <= self.max_targets <= hi:
            raise ValueError(f"max_targets must be in {lo}..{hi}, got {self.max_targets}")


@dataclass(frozen=True)
class TargetDemand:
    """One target's job on one frame.

    ``clocks``: worst-case engine clocks of the job; ``release_line``: the frame line after which
    its region (or, for an init, its box and ring) has streamed in; ``next_line``: the earliest
    line of the next frame its next region can start on; ``d``: decimation; ``wd``, ``hd``: window
    diameters (decimated px); ``rows``, ``cols``: the captured rectangle (decimated px), from frame line
    ``first_line``."""

    target_id: int
    kind: JobKind
    d: int
    wd: int
    hd: int
    rows: int
    cols: int
    first_line: int
    clocks: int
    release_line: int
    next_line: int

    def slack(self, timing: VideoTiming) -> int:
        """Clocks from the end of this frame's region to the start of the next frame's: from input line
        ``release_line`` to input line ``next_line`` of the next frame, less one line.  The region's first
        row (at or below ``next_line``) reaches the colour capture, on the all-pixel stream, in its own
        input line, and the release can come a few clocks into line ``release_line`` (D = 1: 13 clocks
        after the line's first beat, rtl/ms_slot_capture.vhd): the line taken off covers both."""
        lines = timing.frame_lines - self.release_line + self.next_line - 1
        return max(lines * timing.line_clocks, timing.blank_clocks)


@dataclass(frozen=True)
class FramePlan:
    """:func:`plan_frame`: ids tracked and held on the frame, the admitted jobs' clocks and the
    budget they were checked against (the smallest slack among them); ``jobs``: the admitted jobs
    (what :func:`check_add` takes, with the adds taken since)."""

    tracked: tuple[int, ...]
    held: tuple[int, ...]
    clocks: int
    budget: int
    jobs: tuple[TargetDemand, ...] = ()


# ----------------------------------------------------------------------------- job clocks
@lru_cache(maxsize=4096)
def pixel_pass_clocks(wd: int, hd: int, lanes: int = 4, pass_lat: int = 10, kernel_bits: int = 8) -> int:
    """ms_pixel_pass start -> done for a flat wd x hd window at its worst LANES alignment: the sum
    over rows of the LANES groups the kernel ellipse's row extent XR covers, + PASS_LAT."""
    ker = ms_kernel(wd, hd, "flat", kernel_bits)
    cols = np.arange(ker.inside.shape[1]) - ker.ex
    xr = np.array([int(np.max(np.abs(cols[row]))) if row.any() else 0 for row in ker.inside], np.int64)
    best = 0
    for wx in range(ker.ex, ker.ex + lanes):
        g = (wx + xr) // lanes - (wx - xr) // lanes + 1
        best = max(best, int(g.sum()))
    return best + pass_lat


def _engine(passes: int, pp: int, b: int, c: PassCosts) -> int:
    """ms_meanshift, ``passes - 1`` iterations, every pass at ``pp`` clocks, bin pass ``b``."""
    n = passes - 1
    return passes * pp + passes * b + n * c.centre + c.iter_overhead * n + 6


def job_clocks(kind: JobKind, wd: int, hd: int, tp: TrackerParams, costs: PassCosts = PassCosts(),
               ring: tuple[int, int] = (0, 0), window_limit: int | None = None) -> int:
    """Worst-case clocks of one target's job on the shared engine.

    track: Qw load, ``max_iter`` iterations, the v2 per-frame work, the gated scale test's two
    windows (the larger at +scale_test, up to ``window_limit``); lost: the centre and 8 more start
    points of ``search_iter`` iterations each, 8 more confidences; init: ms_init_job (``init_start``: the
    background model's set-up and the scan's start), the background model
    counted from the captured rectangle ``ring`` (rows, cols: :func:`init_capture`'s ``rect``, the box,
    its ring and the init region) at one pixel per clock,
    its 3 passes over the bins, the Qw load and one pass at the init centre.  Every job adds
    ``job_switch`` (the target's state record in and out)."""
    c = costs
    nc = tp.n_colour_bins
    b = c.bin_pass + (c.bank_tree if tp.orient_T > 0 else 0)
    qload = nc + c.qload_extra
    pp = pixel_pass_clocks(wd, hd, c.lanes, c.pass_lat)
    scale = 0
    if tp.scale_test > 0 and kind != "init":
        lim = window_limit if window_limit is not None else tp.max_window
        up = lambda s: min(lim, -(-s * (1000 + round(1000 * tp.scale_test)) // 1000))  # noqa: E731
        scale = 2 * (c.kernel_tables + qload + pixel_pass_clocks(up(wd), up(hd), c.lanes, c.pass_lat) + b
                     + c.scale_window_extra)
    if kind == "track":
        work = qload + _engine(tp.max_iter + 1, pp, b, c) + scale
    elif kind == "lost":
        work = qload + 9 * _engine(tp.search_iter + 1, pp, b, c) + 8 * c.confidence + scale
    elif kind == "init":
        work = c.init_start + ring[0] * ring[1] + 3 * tp.n_bins_v2 + c.bg_drain + qload + pp + b
    else:
        raise ValueError(f"job kind must be init, track or lost, got {kind!r}")
    return c.front + work + c.v2_overhead + c.back + c.job_switch


# ----------------------------------------------------------------------------- demands
def release_line(reg_y: int, reg_h: int, d: int, frame_h: int) -> int:
    """The frame line after which a region (rows ``reg_y`` .. ``reg_y + reg_h - 1`` of the decimated
    frame at decimation ``d``) has streamed in: its last full-resolution row, the Sobel's line of delay
    and the capture, D + 1 lines after its last row (at most the frame's height).  rtl/ms_slot_capture.vhd
    releases the region no later (tb/test_ms_slot_capture.py)."""
    return min((reg_y + reg_h) * d + 1, frame_h)


def _dims(frame_w: int, frame_h: int, d: int) -> tuple[int, int]:
    """(width, height) of frame[::d, ::d]."""
    return (frame_w - 1) // d + 1, (frame_h - 1) // d + 1


def _window(s8: int, pad16: int, d: int, size: int, tp: TrackerParams) -> int:
    return ms_window_size(s8, pad16, d, min(tp.max_window, size - 2))


@dataclass(frozen=True)
class _Geometry:
    """A frame's geometry from a target's state: decimation, decimated frame size, window, region."""

    d: int
    dw: int
    dh: int
    wd: int
    hd: int
    region: Region
    margin: int


def _geometry(w8: int, h8: int, c8: tuple[int, int], lost: bool, frame_w: int, frame_h: int, tp: TrackerParams,
              fp: FixedParams) -> _Geometry:
    """What ``FixedTrackerV2.update`` computes before a frame from the state (size w8, h8, centre c8,
    lost; search_widen 0): D (x 2 while lost), the window and the region with its margin."""
    pad16, step16 = sixteenths(tp.pad, "pad"), sixteenths(tp.search_step, "search_step")
    d = ms_decimation(w8, h8, pad16, tp.max_window) * (2 if lost else 1)
    dw, dh = _dims(frame_w, frame_h, d)
    wd, hd = _window(w8, pad16, d, dw, tp), _window(h8, pad16, d, dh, tp)
    sh = d.bit_length() - 1
    reg, margin = ms_region_v2((c8[0] >> sh, c8[1] >> sh), (wd - 1) // 2, (hd - 1) // 2, (step16 * wd) >> 4,
                               (step16 * hd) >> 4, lost, dw, dh, fp)
    return _Geometry(d, dw, dh, wd, hd, reg, margin)


def target_demand(trk: FixedTrackerV2, target_id: int, tp: TrackerParams | None = None,
                  fp: FixedParams | None = None, costs: PassCosts = PassCosts()) -> TargetDemand:
    """The job of a live target on its next frame, from its FixedTrackerV2 state (the decimation,
    window and region ``FixedTrackerV2.update`` will use).

    ``next_line`` bounds the next region from above over every outcome of this job: the window
    centre ends inside this region's centre range (``Region.lo``), and the next frame tracks
    (the size grown by ``scale_step``) or searches (lost: D x 2, the search offset)."""
    tp = tp or trk.params
    fp = fp or trk.fixed
    if trk._shape is None:
        raise ValueError("target_demand needs an initialised tracker (init() first)")
    return ms_job_demand(trk.w8, trk.h8, trk.c8, trk.lost, trk._shape, target_id, tp, fp, costs)


def ms_job_demand(w8: int, h8: int, c8: tuple[int, int], lost: bool, frame_shape: tuple[int, int],
                  target_id: int, tp: TrackerParams | None = None, fp: FixedParams | None = None,
                  costs: PassCosts = PassCosts()) -> TargetDemand:
    """:func:`target_demand` from the state fields it reads: size w8, h8 (Q.8 px), centre c8 (Q.CF
    px), the search state ``lost`` and the frame shape (height, width).  rtl/ms_job_demand.vhd
    computes the same in three geometry passes (this frame's, the next frame's tracked with the size
    grown by scale_step, and searched at twice the base D)."""
    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    fh, fw = frame_shape
    g = _geometry(w8, h8, c8, lost, fw, fh, tp, fp)
    reg, d = g.region, g.d
    kind: JobKind = "lost" if lost else "track"
    clocks = job_clocks(kind, g.wd, g.hd, tp, costs, window_limit=min(tp.max_window, g.dw - 2, g.dh - 2))
    release = release_line(reg.y, reg.h, d, fh)
    # the next frame: tracked with the size grown by scale_step, or searched (lost) at twice the base D:
    # from a window centre to the top of its region, e + margin + 1 decimated lines
    gr = (1 << 16) + q16(tp.scale_step)
    w8g, h8g = min((w8 * gr) >> 16, fw << 8), min((h8 * gr) >> 16, fh << 8)
    half = max(((n.hd - 1) // 2 + n.margin + 1) * n.d
               for n in (_geometry(w8g, h8g, c8, False, fw, fh, tp, fp), _geometry(w8, h8, c8, True, fw, fh, tp, fp)))
    next_line = max(0, reg.lo[1] * d - half)
    return TargetDemand(target_id, kind, d, g.wd, g.hd, reg.h, reg.w, reg.y * d, clocks, release, next_line)


@dataclass(frozen=True)
class InitCapture:
    """What the shared-engine core captures of a target on the frame it is added (:func:`init_capture`).

    ``d``: decimation; ``cd``: the box centre (decimated px) kept inside the decimated interior, and
    ``wb``, ``hb`` the box diameters, as ``FixedTrackerV2.init`` gives them to ``ms_bg_model``; ``ring``:
    the box and its background ring, clipped to the decimated frame (the pixels ``ms_bg_model``
    counts); ``region``: the init region (``ms_region`` around the centre: the pass that gives the
    references); ``rect`` (x, y, w, h): the rectangle the capture writes into the slot, the smallest that holds
    both, border pixels included.  ``wd``, ``hd``: the window."""

    d: int
    cd: tuple[int, int]
    wb: int
    hb: int
    wd: int
    hd: int
    ring: tuple[int, int, int, int]
    region: Region
    rect: tuple[int, int, int, int]


def init_capture(box: Box | tuple[float, float, float, float], frame_w: int, frame_h: int,
                 tp: TrackerParams | None = None, fp: FixedParams | None = None) -> InitCapture:
    """The init job's capture of a target added with ``box`` on a ``frame_w`` x ``frame_h`` frame,
    with the geometry of ``FixedTrackerV2.init`` (docs/multi_target_core.md, "The init job").

    The init job counts ``ms_bg_model`` from the slot: every pixel of ``rect`` with its coordinates
    relative to ``rect`` and the centre ``cd - rect`` origin gives the model ``init`` learns from the
    whole frame (the ring is inside ``rect``; pixels outside the ring are not counted), then the
    reference pass reads the window from the same slot with the clamp of ``region``.  Raises
    ValueError for a box ``init`` refuses."""
    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    b = Box.of(box)
    if b.w <= 0 or b.h <= 0:
        raise ValueError(f"box must have positive width and height, got {b}")
    x, y, w, h = round_box(*b.as_tuple())
    ib, _ = ms_box_clip(x, y, w, h, frame_w, frame_h, 4095)
    if ib is None:
        raise ValueError(f"box ({x}, {y}, {w}, {h}) leaves less than 3x3 px inside the interior of the "
                         f"{frame_w}x{frame_h} frame")
    pad16, ring16 = sixteenths(tp.pad, "pad"), sixteenths(tp.bg_ring, "bg_ring")
    cf = fp.centre_frac
    w8, h8 = ib.w << 8, ib.h << 8
    c8 = ((2 * ib.x + ib.w - 1) << (cf - 1), (2 * ib.y + ib.h - 1) << (cf - 1))
    d = ms_decimation(w8, h8, pad16, tp.max_window)
    dw, dh = _dims(frame_w, frame_h, d)
    sh = d.bit_length() - 1
    wb, hb = ms_box_size(w8, d, min(tp.max_window, dw - 2)), ms_box_size(h8, d, min(tp.max_window, dh - 2))
    cx = min(max(ms_round_centre(c8[0] >> sh, cf), (wb - 1) // 2 + 1), dw - 2 - (wb - 1) // 2)
    cy = min(max(ms_round_centre(c8[1] >> sh, cf), (hb - 1) // 2 + 1), dh - 2 - (hb - 1) // 2)
    gx, gy = (ring16 * wb) >> 4, (ring16 * hb) >> 4
    y0, y1 = max(0, cy - (hb - 1) // 2 - gy), min(dh - 1, cy + (hb - 1) // 2 + gy)
    x0, x1 = max(0, cx - (wb - 1) // 2 - gx), min(dw - 1, cx + (wb - 1) // 2 + gx)
    ring = (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
    wd, hd = _window(w8, pad16, d, dw, tp), _window(h8, pad16, d, dh, tp)
    reg: Region = ms_region((c8[0] >> sh, c8[1] >> sh), (wd - 1) // 2, (hd - 1) // 2, dw, dh, fp)
    rx0, ry0 = min(x0, reg.x), min(y0, reg.y)
    rx1, ry1 = max(x1, reg.x + reg.w - 1), max(y1, reg.y + reg.h - 1)
    rect = (rx0, ry0, rx1 - rx0 + 1, ry1 - ry0 + 1)
    return InitCapture(d, (cx, cy), wb, hb, wd, hd, ring, reg, rect)


def init_demand(box: Box | tuple[float, float, float, float], frame_w: int, frame_h: int, target_id: int,
                tp: TrackerParams | None = None, fp: FixedParams | None = None,
                costs: PassCosts = PassCosts()) -> TargetDemand:
    """The job of a target added with ``box`` on a ``frame_w`` x ``frame_h`` frame (the geometry of
    ``FixedTrackerV2.init``): :func:`init_capture`'s rectangle (the box, its background ring and the
    init region) is captured into the target's slot and counted after it has streamed in.  Raises
    ValueError for a box ``init`` refuses."""
    tp = tp or TrackerParams(preset="v2")
    ic = init_capture(box, frame_w, frame_h, tp, fp)
    d, (_, ry, rw, rh), reg = ic.d, ic.rect, ic.region
    clocks = job_clocks("init", ic.wd, ic.hd, tp, costs, ring=(rh, rw))
    release = min((ry + rh) * d + 1, frame_h)
    # the first tracking frame's region is this one (the init frame does not move the centre)
    return TargetDemand(target_id, "init", d, ic.wd, ic.hd, rh, rw, ry * d, clocks, release, reg.y * d)


# ----------------------------------------------------------------------------- the rule
def _fits(jobs: Sequence[TargetDemand], timing: VideoTiming) -> bool:
    return sum(j.clocks for j in jobs) <= min(j.slack(timing) for j in jobs)


def plan_frame(demands: Sequence[TargetDemand], cfg: MultiCoreConfig = MultiCoreConfig()) -> FramePlan:
    """Which of a frame's jobs run.  ``demands`` in priority order (the order the targets were
    added, oldest first); each is admitted if, with the jobs admitted before it, the cycle rule
    holds (``sum(clocks) <= min(slack)``) and at most ``max_targets`` are admitted; otherwise it is
    held (on this frame only) and the next is tried."""
    ids = [dm.target_id for dm in demands]
    if len(set(ids)) != len(ids):
        raise ValueError(f"target ids must be distinct, got {ids}")
    admitted: list[TargetDemand] = []
    held: list[int] = []
    for dm in demands:
        if len(admitted) < cfg.max_targets and _fits([*admitted, dm], cfg.timing):
            admitted.append(dm)
        else:
            held.append(dm.target_id)
    budget = min((j.slack(cfg.timing) for j in admitted), default=cfg.timing.frame_clocks)
    return FramePlan(tuple(j.target_id for j in admitted), tuple(held), sum(j.clocks for j in admitted), budget,
                     tuple(admitted))


def check_add(admitted: Sequence[TargetDemand], n_live: int, new: TargetDemand,
              cfg: MultiCoreConfig = MultiCoreConfig()) -> int:
    """Is a target added on this frame taken?  ``admitted``: the frame's jobs already admitted
    (its tracked targets and the adds taken before this one); ``n_live``: targets live before
    this add (held ones count).  Returns :data:`ADD_OK`, :data:`ADD_FULL` (``max_targets`` live)
    or :data:`ADD_CYCLES` (the init job does not fit the frame's cycle rule).  Live targets are
    never held to make room for an add."""
    if n_live >= cfg.max_targets:
        return ADD_FULL
    if not _fits([*admitted, new], cfg.timing):
        return ADD_CYCLES
    return ADD_OK


def held_result(trk: FixedTrackerV2, demand: TargetDemand) -> TrackResult:
    """The result of a live target held on a frame (:func:`plan_frame`): status error (result word
    status 6, flag ``error``, ``err_code`` :data:`ERR_CAPACITY`) with the target's current centre and
    size; rho, confidence and iterations 0, ``decimation`` that of the job it was not given.  The
    tracker is not touched: its next frame continues from the same state."""
    if trk._shape is None:
        raise ValueError("held_result needs an initialised tracker (init() first)")
    cf = trk.fixed.centre_frac
    raw = {"cx": trk.c8[0], "cy": trk.c8[1], "w8": trk.w8, "h8": trk.h8, "rho": 0, "confidence": 0,
           "status": STATUS_CODES_V2[Status.ERROR], "iter": 0, "decimation": demand.d, "err_code": ERR_CAPACITY}
    return TrackResult(box=trk._box(), centre=(trk.c8[0] / (1 << cf), trk.c8[1] / (1 << cf)), rho_c=0.0,
                       rho_e=0.0, alpha_c=1.0, alpha_e=0.0, iter_c=0, iter_e=0, status=Status.ERROR,
                       message=f"held: the frame's cycle budget is taken (err_code {ERR_CAPACITY})",
                       confidence=0.0, extra=raw)
