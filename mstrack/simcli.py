"""``mstrack sim VIDEO --box x,y,w,h``: the RTL core co-simulated on your own video.

The frames of VIDEO (a video file, an image folder or an OTB/VOT sequence folder, read by
:class:`mstrack.io.data.VideoSource` as ``mstrack track`` reads them) are streamed through the
verilated netlist of ``ms_tracker`` (:func:`mstrack.hw.fastsim.simulate`: GHDL ``--synth`` to
Verilog, Verilator, the C++ harness tools/hdl/cosim_main.cpp; the build is cached in
``build/fastsim/``), with the init box given before the first frame.  ``--preset paper`` (default)
is the paper core (generic PRESET 0, :class:`mstrack.hw.cosim.CoreConfig`); ``--preset v2`` core v2
(PRESET 1, :meth:`mstrack.hw.cosim.CoreConfigV2.tracker_generics`, result word v2).  Every result
word is decoded and compared, field by field, with what the fixed-point model says the core must
output (:func:`mstrack.hw.cosim.expected_results`, v2: :func:`mstrack.hw.cosim.expected_results_v2`).
Written to ``--out``:

* ``results.csv``: one row per frame, the decoded result word (:data:`SIM_CSV_FIELDS`; v2:
  :data:`SIM_CSV_FIELDS_V2`);
* ``overlay.mp4`` (``.avi`` when mp4 cannot be written): the core's box on the frames, drawn by
  :func:`mstrack.cli.draw_overlay` (the ``mstrack track`` overlay: status colour, banner, legend);
* ``bitexact.json``: the comparison (:func:`bitexact_report`), also printed as one line.

Exit codes: 0 bit-exact; 1 a field of a frame differs from the model (the first one is named),
or the simulation failed; 2 bad input (missing file, box outside the frame, frame too large for
the core's generics, a preset the core does not implement), with a one-line error.

Registered in :data:`mstrack.cli.EXTENSIONS` as ``"mstrack.simcli:register_cli"``;
docs/integration.md, "Simulate your own video".
"""
from __future__ import annotations

import argparse
import csv
import itertools
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from .hw.cosim import COMPARED_FIELDS, COMPARED_FIELDS_V2, ERR_NAMES, MIN_FRAME, CoreConfig, CoreConfigV2
from .hw.fastsim import VIDEO_MODES, mode_timing
from .io.data import DataError, VideoSource
from .fixed import FixedParams
from .fixed.blocks import STOP_CODES, ms_box_clip, round_box
from .fixed.vhdl_pkg import DEFAULT_LANES, RESULT_FLAGS, STATUS_V2, pack_result, pack_result_v2
from .track.params import V2_COLOUR, TrackerParams
from .track.types import Box, Status, box_from_centre_index

#: Columns of results.csv.  ``frame``: index in VIDEO; x, y, w, h: the core's box (0-based
#: pixels, x, y = centre - (size - 1) / 2, exact: multiples of 2**-CF); cx, cy: its centre in
#: pixel-index coordinates (Q.CF, exact); rho_c, rho_e, alpha_c: Q.RHO_OUT_FRAC / Q.AF as
#: decimals (:data:`RHO_DECIMALS`); iter_*, stop_* (names of the stop codes); status (from the
#: flags, :func:`result_status`); flags (the flag names set, "|"-joined); err_code (stream error
#: name, empty when none); frame_count (the core's counter); latency (clocks from the frame's last
#: pixel to the result); word: the raw result word, hexadecimal (every field, exactly).
SIM_CSV_FIELDS = ("frame", "x", "y", "w", "h", "cx", "cy", "rho_c", "rho_e", "alpha_c", "iter_c", "iter_e",
                  "stop_c", "stop_e", "status", "flags", "err_code", "frame_count", "latency", "word")
#: Columns of results.csv for core v2 (``--preset v2``, result word v2): frame, the box x, y, w, h
#: (from the centre and w8, h8, exact), cx, cy (Q.CF, exact), rho and confidence (Q1.16 as decimals),
#: status (:data:`mstrack.fixed.vhdl_pkg.STATUS_V2` name), iter, stop (name), decim_log2, searched,
#: flags, err_code, frame_count, latency, word (hexadecimal).
SIM_CSV_FIELDS_V2 = ("frame", "x", "y", "w", "h", "cx", "cy", "rho", "confidence", "status", "iter", "stop",
                     "decim_log2", "searched", "flags", "err_code", "frame_count", "latency", "word")
#: Decimals of rho_c, rho_e, alpha_c in results.csv: 2**-16 = 1.5e-5 apart, so 6 decimals keep
#: every value apart (the raw integers are in ``word``).
RHO_DECIMALS = 6
STOP_NAMES = {v: k for k, v in STOP_CODES.items()}
#: Presets the RTL core implements (generic PRESET of ms_tracker: paper 0, v2 1).
CORE_PRESETS = ("paper", "v2")
#: Mismatches listed in bitexact.json (the count is always complete).
MAX_LISTED = 200
EXIT_OK, EXIT_MISMATCH, EXIT_BAD_INPUT = 0, 1, 2


class SimInputError(ValueError):
    """Bad input to ``mstrack sim`` (exit code 2)."""


# ----------------------------------------------------------------------------- decoding
def result_status(fields: dict[str, int]) -> str:
    """Status of a result word from its flags: error, no_target, clipped / init (the init frame),
    lost, else ok (:class:`mstrack.track.types.Status` values, plus ``no_target``)."""
    f = fields["flags"]
    on = lambda name: (f >> RESULT_FLAGS.index(name)) & 1  # noqa: E731
    if on("error"):
        return Status.ERROR.value
    if on("no_target"):
        return "no_target"
    if on("init"):
        return Status.CLIPPED.value if on("clipped") else Status.INIT.value
    return Status.LOST.value if on("lost") else Status.OK.value


def decode_row(fields: dict[str, int], g: dict[str, int], frame: int, latency: int | None = None
               ) -> dict[str, Any]:
    """One results.csv row (:data:`SIM_CSV_FIELDS`) from the fields of a result word.

    ``g``: the generics of the core (CF, RHO_OUT_FRAC, AF scale the fixed-point fields);
    ``frame``: the frame's index in the video.  The row also serves the overlay
    (:func:`mstrack.cli.draw_overlay` reads frame, status, x, y, w, h, cx, cy, rho_c, rho_e, alpha_c).
    """
    cf = float(1 << g["CF"])
    cx, cy = fields["cx"] / cf, fields["cy"] / cf
    b = box_from_centre_index(cx, cy, fields["box_w"], fields["box_h"])
    rho = lambda v: round(v / (1 << g["RHO_OUT_FRAC"]), RHO_DECIMALS)  # noqa: E731
    flags = "|".join(n for i, n in enumerate(RESULT_FLAGS) if (fields["flags"] >> i) & 1)
    err = fields["err_code"]
    err_name = ERR_NAMES[err] if err < len(ERR_NAMES) else str(err)
    return {"frame": frame, "x": b.x, "y": b.y, "w": b.w, "h": b.h, "cx": cx, "cy": cy,
            "rho_c": rho(fields["rho_c"]), "rho_e": rho(fields["rho_e"]),
            "alpha_c": round(fields["alpha_c"] / (1 << g["AF"]), RHO_DECIMALS),
            "iter_c": fields["iter_c"], "iter_e": fields["iter_e"],
            "stop_c": STOP_NAMES[fields["stop_c"]], "stop_e": STOP_NAMES[fields["stop_e"]],
            "status": result_status(fields), "flags": flags,
            "err_code": err_name if fields["flags"] >> RESULT_FLAGS.index("error") & 1 else "",
            "frame_count": fields["frame_count"], "latency": "" if latency is None else latency,
            "word": f"{pack_result({k: fields[k] for k in COMPARED_FIELDS}, g):0{g['RESULT_W'] // 4}x}"}


def decode_row_v2(fields: dict[str, int], g: dict[str, int], frame: int, latency: int | None = None
                  ) -> dict[str, Any]:
    """One results.csv row of core v2 (:data:`SIM_CSV_FIELDS_V2`) from the fields of a result word v2
    (``g``: the core's generics; CF scales the centre, w8 and h8 are Q.8, rho and confidence Q1.16)."""
    cf = float(1 << g["CF"])
    cx, cy = fields["cx"] / cf, fields["cy"] / cf
    b = box_from_centre_index(cx, cy, fields["w8"] / 256.0, fields["h8"] / 256.0)
    q16 = lambda v: round(v / 65536.0, RHO_DECIMALS)  # noqa: E731
    flags = "|".join(n for i, n in enumerate(RESULT_FLAGS) if (fields["flags"] >> i) & 1)
    err = fields["err_code"]
    err_name = ERR_NAMES[err] if err < len(ERR_NAMES) else str(err)
    st = fields["status"]
    return {"frame": frame, "x": b.x, "y": b.y, "w": b.w, "h": b.h, "cx": cx, "cy": cy,
            "rho": q16(fields["rho"]), "confidence": q16(fields["confidence"]),
            "status": STATUS_V2[st] if st < len(STATUS_V2) else str(st), "iter": fields["iter"],
            "stop": STOP_NAMES[fields["stop"]], "decim_log2": fields["decim_log2"], "searched": fields["searched"],
            "flags": flags, "err_code": err_name if fields["flags"] >> RESULT_FLAGS.index("error") & 1 else "",
            "frame_count": fields["frame_count"], "latency": "" if latency is None else latency,
            "word": f"{pack_result_v2({k: fields[k] for k in COMPARED_FIELDS_V2}, g):0{g['RESULT_W'] // 4}x}"}


# ----------------------------------------------------------------------------- comparison
def field_mismatches(results: Sequence[dict], expected: Sequence[dict], frames: Sequence[int],
                     fields: Sequence[str] = COMPARED_FIELDS) -> list[dict[str, Any]]:
    """Every differing (frame, field) between the core's results and the model's, in frame order:
    ``{"result": i, "frame": frames[i], "field": name, "core": .., "model": ..}``; a missing
    result has field ``"(no result)"``, an extra one ``"(extra result)"``."""
    out: list[dict[str, Any]] = []
    for i in range(max(len(results), len(expected))):
        fr = frames[i] if i < len(frames) else frames[-1] + i - len(frames) + 1
        if i >= len(results):
            out.append({"result": i, "frame": fr, "field": "(no result)", "core": None, "model": "a result"})
        elif i >= len(expected):
            out.append({"result": i, "frame": fr, "field": "(extra result)", "core": results[i].get("word"),
                        "model": None})
        else:
            out += [{"result": i, "frame": fr, "field": k, "core": results[i].get(k), "model": expected[i].get(k)}
                    for k in fields if results[i].get(k) != expected[i].get(k)]
    return out


def bitexact_report(results: Sequence[dict], expected: Sequence[dict], frames: Sequence[int],
                    fields: Sequence[str] = COMPARED_FIELDS,
                    reference: str = "mstrack.hw.cosim.expected_results") -> dict[str, Any]:
    """The bit-exactness report: ``bit_exact``, ``frames`` compared, ``fields``, ``mismatched_frames``,
    ``mismatches`` (count), ``first_mismatch`` (or None) and the first :data:`MAX_LISTED` in
    ``listed`` (:func:`field_mismatches`)."""
    mm = field_mismatches(results, expected, frames, fields)
    return {"bit_exact": not mm, "frames": len(expected), "results": len(results), "fields": list(fields),
            "reference": f"fixed-point model, {reference}",
            "mismatched_frames": len({m["result"] for m in mm}), "mismatches": len(mm),
            "first_mismatch": mm[0] if mm else None, "listed": mm[:MAX_LISTED]}


def report_line(rep: dict[str, Any]) -> str:
    """The one printed line of a :func:`bitexact_report`."""
    if rep["bit_exact"]:
        return (f"bit-exact: {rep['frames']} frames x {len(rep['fields'])} fields of the result word "
                "equal the fixed-point model")
    m = rep["first_mismatch"]
    return (f"MISMATCH: {rep['mismatched_frames']} of {rep['frames']} frames differ from the fixed-point model "
            f"({rep['mismatches']} field{'s' if rep['mismatches'] != 1 else ''}); first: frame {m['frame']} (result {m['result']}), field {m['field']}: "
            f"core={m['core']} model={m['model']}")


# ----------------------------------------------------------------------------- input
def parse_frame_range(s: str) -> tuple[int, int]:
    """``"FIRST,LAST"`` (0-based, inclusive) -> (first, last)."""
    try:
        a, b = (int(v) for v in s.replace(" ", "").split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--frames wants FIRST,LAST (0-based, inclusive), got {s!r}") from None
    if a < 0 or b < a:
        raise argparse.ArgumentTypeError(f"--frames wants 0 <= FIRST <= LAST, got {s!r}")
    return a, b


@dataclass
class SimJob:
    """What ``mstrack sim`` streams: frames ``first`` .. ``first + count - 1`` of ``source`` with
    the integer init box ``box`` (given on the core's init port) before the first."""

    source: VideoSource
    first: int
    count: int
    box: tuple[int, int, int, int]
    given: Box
    cfg: CoreConfig | CoreConfigV2
    size: tuple[int, int]                     # (W, H)
    gt: np.ndarray | None = None              # ground truth of the streamed frames (sequence folder)
    notes: list[str] = field(default_factory=list)

    @property
    def frame_indices(self) -> list[int]:
        return list(range(self.first, self.first + self.count))

    def frames(self) -> Iterator[np.ndarray]:
        """The streamed frames, read again from the source on every call (nothing held in memory)."""
        for f in itertools.islice(self.source.frames(on_bad="raise"), self.first, self.first + self.count):
            assert f is not None
            yield f


def check_frame_size(w: int, h: int, g: dict[str, int]) -> None:
    """Raise :class:`SimInputError` when a w x h frame is outside what the core's generics take."""
    if w > g["MAX_FRAME_W"]:
        raise SimInputError(f"frames are {w}x{h}: wider than the core's MAX_FRAME_W = {g['MAX_FRAME_W']} "
                            "(--max-frame-width)")
    lim = (1 << g["COORD_W"]) - 1
    if w > lim or h > lim:
        raise SimInputError(f"frames are {w}x{h}: larger than the core's coordinates allow "
                            f"(COORD_W = {g['COORD_W']}: at most {lim} px per side)")
    if w < MIN_FRAME or h < MIN_FRAME:
        raise SimInputError(f"frames are {w}x{h}: smaller than the core's {MIN_FRAME}x{MIN_FRAME} minimum")


def check_box(box: Box, size: tuple[int, int], cfg: CoreConfig | CoreConfigV2) -> tuple[int, int, int, int]:
    """The integer box the init port takes for ``box`` on a ``size`` = (W, H) frame; SimInputError when
    it is empty, does not fit the port or leaves less than 3 x 3 px inside the frame."""
    if box.w <= 0 or box.h <= 0:
        raise SimInputError(f"--box {box.as_tuple()}: width and height must be positive")
    ib = round_box(*box.as_tuple())
    cw = cfg.generics()["COORD_W"]
    if not (-(1 << (cw + 1)) <= ib[0] < 1 << (cw + 1) and -(1 << (cw + 1)) <= ib[1] < 1 << (cw + 1)
            and ib[2] < 1 << (cw + 1) and ib[3] < 1 << (cw + 1)):
        raise SimInputError(f"--box {ib}: does not fit the core's init port (COORD_W = {cw})")
    # core v2 clips the box to the frame without shrinking it (large targets are decimated), as
    # FixedTrackerV2.init
    clipped, _ = ms_box_clip(*ib, size[0], size[1], 4095 if isinstance(cfg, CoreConfigV2) else cfg.fp.max_half)
    if clipped is None:
        raise SimInputError(f"--box {ib} leaves less than 3x3 px inside the {size[0]}x{size[1]} frame "
                            "(the core rejects it; 1-px border excluded)")
    return ib


def prepare(video: str | Path, box: Box | None, frame_range: tuple[int, int] | None, max_frames: int | None,
            cfg: CoreConfig | CoreConfigV2) -> SimJob:
    """Open ``video``, pick the frames and the init box and check them against the core.

    Raises :class:`SimInputError` / :class:`mstrack.io.data.DataError` (both exit 2)."""
    from .cli import init_box_note

    src = VideoSource(video)
    first, last = frame_range if frame_range is not None else (0, None)
    n_max = None if last is None else last - first + 1
    if max_frames is not None:
        n_max = max_frames if n_max is None else min(n_max, max_frames)
    # one pass: count the frames, check that they are readable and of one size
    size: tuple[int, int] | None = None
    count = 0
    for i, f in enumerate(itertools.islice(src.frames(on_bad="raise"), first, None if n_max is None else first + n_max)):
        assert f is not None
        hw = (f.shape[1], f.shape[0])
        if size is None:
            size = hw
            check_frame_size(*size, cfg.generics())
        elif hw != size:
            raise SimInputError(f"frame {first + i} is {hw[0]}x{hw[1]}, frame {first} {size[0]}x{size[1]}: "
                                "the core tracks one frame size")
        count += 1
    if size is None:
        raise SimInputError(f"{video}: no frame {first} (the source has {src.decoded} frames)")
    if last is not None and count < last - first + 1 and (max_frames is None or count < max_frames):
        raise SimInputError(f"--frames {first},{last}: the source ends after frame {first + count - 1}")
    gt = None
    if src.sequence is not None:
        gt = src.sequence.gt[first:first + count]
        if box is None:
            g0 = src.sequence.gt[first]
            if not np.isfinite(g0).all() or g0[2] <= 0 or g0[3] <= 0:
                raise SimInputError(f"no ground truth box for frame {first} of {video}: give --box x,y,w,h")
            box = Box.of(g0)
    if box is None:
        raise SimInputError("--box x,y,w,h is required unless VIDEO is a sequence folder with ground truth")
    ib = check_box(box, size, cfg)
    clipped, _ = ms_box_clip(*ib, size[0], size[1], 4095 if isinstance(cfg, CoreConfigV2) else cfg.fp.max_half)
    assert clipped is not None
    job = SimJob(src, first, count, ib, box, cfg, size, gt)
    note = init_box_note(box, Box(clipped.x, clipped.y, clipped.w, clipped.h), (size[1], size[0]))
    if note:
        job.notes.append(note.replace("tracking", "the core tracks"))
    return job


# ----------------------------------------------------------------------------- run
#: The model side: (frames, box, tp, fp) -> expected result fields per frame.  A parameter of
#: :func:`run_sim` so that tests can check that a wrong expectation is caught.
ModelFn = Callable[[Iterator[np.ndarray], tuple[int, int, int, int], TrackerParams, FixedParams],
                   list[dict[str, int]]]


def write_overlay(path: Path, fps: float, images: Iterator[np.ndarray]) -> Path | None:
    """Write *images* as the overlay video at *path* (``open_video_writer``: .avi where mp4 cannot be
    written); returns the file written, None when there was no image."""
    from .io.data import open_video_writer
    writer, video = None, None
    try:
        for img in images:
            if writer is None:
                writer, video = open_video_writer(path, fps, (img.shape[1], img.shape[0]))
            writer.write(img)
    finally:
        if writer is not None:
            writer.release()
    return video


def run_sim(job: SimJob, out: Path, model: ModelFn | None = None, progress: bool = False,
            command: str = "", quick_build: bool = False) -> dict[str, Any]:
    """Simulate ``job`` and write results.csv, the overlay video and bitexact.json to ``out``
    (*quick_build*: the Verilator model's C++ at ``fastsim.CXX_OPT_SHORT``, as ``--quick-build``).

    Returns the report (bitexact.json's content)."""
    from .hw import fastsim
    from .cli import draw_overlay
    from .hw.cosim import expected_results, expected_results_v2

    v2 = isinstance(job.cfg, CoreConfigV2)
    model = model or (expected_results_v2 if v2 else expected_results)
    g = job.cfg.tracker_generics() if isinstance(job.cfg, CoreConfigV2) else job.cfg.generics()
    say = (lambda m: print(f"mstrack sim: {m}", file=sys.stderr, flush=True)) if progress else (lambda m: None)
    t0 = time.monotonic()
    say(f"co-simulating {job.count} frames {job.size[0]}x{job.size[1]} (LANES {job.cfg.lanes}; the first "
        "run of a generic set builds the Verilator model, 1-2 min)...")
    # ms_tracker, the entity integrators instantiate (v2: generic PRESET 1)
    run = fastsim.simulate(job.frames(), job.box, job.cfg.tp, job.cfg.fp, lanes=job.cfg.lanes,
                           max_frame_w=job.cfg.max_frame_w, check=False, v2=v2, top=fastsim.TOP,
                           cxx_opt=fastsim.CXX_OPT_SHORT if quick_build else fastsim.CXX_OPT)
    t_sim = time.monotonic() - t0
    say(f"simulated {run.cycles} clocks in {run.seconds:.1f} s ({run.status}); running the fixed-point model...")
    t1 = time.monotonic()
    expected = model(job.frames(), job.box, job.cfg.tp, job.cfg.fp)
    t_model = time.monotonic() - t1
    idx = job.frame_indices
    if v2:
        rep = bitexact_report(run.results, expected, idx, COMPARED_FIELDS_V2, "mstrack.hw.cosim.expected_results_v2")
    else:
        rep = bitexact_report(run.results, expected, idx)
    decode = decode_row_v2 if v2 else decode_row
    rows = [decode(r, g, idx[i] if i < len(idx) else idx[-1] + i - len(idx) + 1, r.get("latency"))
            for i, r in enumerate(run.results)]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "results.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=SIM_CSV_FIELDS_V2 if v2 else SIM_CSV_FIELDS)
        w.writeheader()
        w.writerows(rows)
    video = None
    if rows:
        def images() -> Iterator[np.ndarray]:
            for i, frame in enumerate(job.frames()):
                if i >= len(rows):
                    break
                gt = None if job.gt is None or i >= len(job.gt) else job.gt[i]
                # core v2: one feature (colour), its rho as rho_c and the confidence in the banner
                row = {**rows[i], "rho_c": rows[i]["rho"], "alpha_c": 1.0} if v2 else rows[i]
                yield draw_overlay(frame, row, gt)
        video = write_overlay(out / "overlay.mp4", job.source.fps, images())
    lat = [r["latency"] for r in run.results if "latency" in r]
    listed = rep.pop("listed")
    rep = {**rep, "command": command, "source": str(job.source.path), "kind": job.source.kind,
           "first_frame": job.first, "frames_streamed": job.count, "frame_size": list(job.size),
           "init_box_given": list(job.given.as_tuple()), "init_box": list(job.box),
           "preset": job.cfg.tp.preset, "lanes": job.cfg.lanes, "generics": g,
           "simulation": {"status": run.status, "detail": run.detail, "cycles": run.cycles,
                          "seconds": round(run.seconds, 3), "cpu_seconds": round(run.cpu_seconds, 3),
                          "build_seconds": round(run.build_seconds, 1), "wall_seconds": round(t_sim, 1),
                          "latency_min": min(lat) if lat else None, "latency_max": max(lat) if lat else None},
           "model_seconds": round(t_model, 1),
           "files": {"csv": str(out / "results.csv"), "video": None if video is None else str(video),
                     "report": str(out / "bitexact.json")},
           "listed": listed}
    (out / "bitexact.json").write_text(json.dumps(rep, indent=1) + "\n")
    return rep


#: Columns of results.csv of the multi-target core (several ``--box``): the slot id after the frame,
#: then :data:`SIM_CSV_FIELDS_V2` (without latency: words follow one another per frame).
SIM_CSV_FIELDS_MULTI = ("frame", "target_id", *[f for f in SIM_CSV_FIELDS_V2 if f not in ("frame", "latency")])


def run_sim_multi(job: SimJob, boxes: list[tuple[int, int, int, int]], out: Path, slots: int,
                  progress: bool = False, command: str = "", quick_build: bool = False,
                  shared: str | None = None) -> dict[str, Any]:
    """Several targets: the boxes added before the first frame of the multi-target core
    ``ms_tracker_multi`` (``slots`` core v2 engines, :func:`mstrack.hw.fastsim.simulate_multi`), or with
    *shared* (a video mode of :data:`mstrack.hw.fastsim.VIDEO_MODES`) ``ms_tracker_shared`` (one engine for
    the ``slots`` slots, its capacity rule at that mode's raster); every word compared with
    :func:`mstrack.hw.cosim_multi.expected_multi`; writes results.csv (:data:`SIM_CSV_FIELDS_MULTI`, one
    row per word), overlay.mp4 and bitexact.json to ``out`` (*quick_build* as :func:`run_sim`).  The
    frames stream without blanking: the shared core holds its input while a frame's jobs run, which
    changes no word (the rule's verdicts depend on the mode's raster only)."""
    from .fixed.multi_capacity import MultiCoreConfig
    from .hw import fastsim
    from .hw.cosim_multi import expected_multi
    from .hw.multi_core import pass_costs, shared_core_generics
    from .multicli import draw_multi_overlay

    assert isinstance(job.cfg, CoreConfigV2)
    cfg = job.cfg
    g = {"MAX_TARGETS": slots, **cfg.generics()}
    top, extra, capacity = fastsim.MULTI_TOP, None, None
    if shared is not None:
        timing = mode_timing(shared)
        capacity = MultiCoreConfig(slots, timing, pass_costs(cfg.lanes))
        sg = shared_core_generics(cfg.tp, cfg.fp, slots, timing, cfg.max_frame_w, costs=capacity.costs)
        extra = {k: v for k, v in sg.items() if k not in g}
        top = "ms_tracker_shared"
        g.update(extra)
    say = (lambda m: print(f"mstrack sim: {m}", file=sys.stderr, flush=True)) if progress else (lambda m: None)
    frames = list(job.frames())
    cmds: dict[int, list[tuple]] = {0: [("add", b) for b in boxes]}
    say(f"running the fixed-point model of {slots} slots on {len(frames)} frames...")
    t1 = time.monotonic()
    m = expected_multi(frames, cmds, cfg.tp, cfg.fp, slots, cfg.max_frame_w, capacity=capacity)
    t_model = time.monotonic() - t1
    say(f"co-simulating {top} ({slots} slots, {'one engine' if shared else f'{slots} engines'}; the first run "
        "of a generic set builds the Verilator model, several minutes)...")
    t0 = time.monotonic()
    run = fastsim.simulate_multi(frames, cmds, cfg.tp, cfg.fp, max_targets=slots, lanes=cfg.lanes,
                                 max_frame_w=cfg.max_frame_w, words=len(m.results), check=False,
                                 cxx_opt=fastsim.CXX_OPT_SHORT if quick_build else fastsim.CXX_OPT,
                                 top=top, extra_generics=extra)
    t_sim = time.monotonic() - t0
    keys = [*COMPARED_FIELDS_V2, "target_id"]
    frame_of = [job.first + i for i, fr in enumerate(m.frames) for _ in fr]
    mism: list[dict[str, Any]] = []
    for i in range(max(len(run.words), len(m.results))):
        if i >= len(run.words) or i >= len(m.results):
            mism.append({"word": i, "frame": frame_of[i] if i < len(frame_of) else None,
                         "fields": {"missing": "dut" if i >= len(run.words) else "model"}})
            continue
        d = {k: {"dut": run.words[i][k], "model": m.results[i][k]} for k in keys if run.words[i][k] != m.results[i][k]}
        if d:
            mism.append({"word": i, "frame": frame_of[i], "fields": d})
    rows = [{**decode_row_v2(w, g, frame_of[i] if i < len(frame_of) else -1), "target_id": w["target_id"]}
            for i, w in enumerate(run.words)]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "results.csv", "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=SIM_CSV_FIELDS_MULTI, extrasaction="ignore")
        wr.writeheader()
        wr.writerows(rows)
    video = write_overlay(out / "overlay.mp4", job.source.fps,
                          (draw_multi_overlay(frame, job.first + i,
                                              [{**r, "id": r["target_id"]} for r in rows if r["frame"] == job.first + i])
                           for i, frame in enumerate(frames)))
    rep = {"bit_exact": not mism and run.status == "done", "words": len(run.words), "expected_words": len(m.results),
           "mismatches": len(mism), "compared_fields": keys, "model": "mstrack.hw.cosim_multi.expected_multi",
           "command": command, "source": str(job.source.path), "kind": job.source.kind, "first_frame": job.first,
           "frames_streamed": job.count, "frame_size": list(job.size), "init_boxes": [list(b) for b in boxes],
           "slots": slots, "lanes": cfg.lanes, "core": top, "capacity_timing": shared, "generics": g,
           "simulation": {"status": run.status, "detail": run.detail, "cycles": run.cycles,
                          "seconds": round(run.seconds, 3), "build_seconds": round(run.build_seconds, 1),
                          "wall_seconds": round(t_sim, 1)},
           "model_seconds": round(t_model, 1),
           "files": {"csv": str(out / "results.csv"), "video": None if video is None else str(video),
                     "report": str(out / "bitexact.json")},
           "listed": mism[:MAX_LISTED]}
    (out / "bitexact.json").write_text(json.dumps(rep, indent=1) + "\n")
    return rep


# ----------------------------------------------------------------------------- CLI
def _cmd_sim(args: argparse.Namespace) -> int:
    from .cli import check_out_dir

    def bad(msg: str) -> int:
        if os.environ.get("MSTRACK_TRACEBACK"):
            raise SimInputError(msg)
        print(f"mstrack sim: error: {msg}", file=sys.stderr)
        return EXIT_BAD_INPUT

    boxes = args.box or []
    multi = len(boxes) > 1 or args.slots is not None
    preset = args.preset or ("v2" if multi else "paper")
    if preset not in CORE_PRESETS:
        return bad(f"--preset {preset}: the RTL core implements the presets {', '.join(CORE_PRESETS)}")
    if multi and preset != "v2":
        return bad("several --box (or --slots) run the multi-target core, whose engines are core v2: "
                   "leave out --preset paper")
    if args.shared_engine and not multi:
        return bad("--shared-engine is the multi-target core on one engine: give several --box (or --slots)")
    slots = args.slots if args.slots is not None else len(boxes)
    if multi and not 1 <= len(boxes) <= slots <= 16:
        return bad(f"--slots {slots} with {len(boxes)} --box: the multi-target core has 1 .. 16 slots, "
                   "at least one per box")
    if args.lanes & (args.lanes - 1):
        return bad(f"--lanes {args.lanes}: LANES must be a power of two (1, 2, 4, 8, ...)")
    try:
        cfg: CoreConfig | CoreConfigV2
        if args.colour and preset != "v2":
            return bad("--colour is core v2 on colour bins alone: it needs --preset v2 (or several --box)")
        if preset == "v2":
            tp = TrackerParams(preset="v2", **(V2_COLOUR if args.colour else {}))
            cfg = CoreConfigV2(tp, FixedParams(), lanes=args.lanes, max_frame_w=args.max_frame_width)
        else:
            cfg = CoreConfig(TrackerParams(preset="paper"), FixedParams(), lanes=args.lanes,
                             max_frame_w=args.max_frame_width)
        cfg.generics()
        out = Path(args.out) if args.out else Path("out/sim") / Path(args.video).resolve().name
        job = prepare(args.video, boxes[0] if boxes else None, args.frames, args.max_frames, cfg)
        more = [check_box(b, job.size, cfg) for b in boxes[1:]]
        if args.shared_engine:
            t = mode_timing(args.timing)
            if job.size[0] > t.line_clocks or job.size[1] > t.active_lines:
                return bad(f"{job.size[0]}x{job.size[1]} frames do not fit the {args.timing} raster of the capacity "
                           "rule (--timing)")
        check_out_dir(out)
    except (DataError, ValueError) as exc:
        return bad(str(exc))
    for n in job.notes:
        print(f"mstrack: warning: {n}", file=sys.stderr)
    if job.source.truncated:
        print(f"mstrack: warning: {job.source.path}: {job.source.truncated}", file=sys.stderr)
    if multi:
        rep = run_sim_multi(job, [job.box, *more], out, slots, progress=not args.quiet,
                            command=getattr(args, "command_line", ""), quick_build=args.quick_build,
                            shared=args.timing if args.shared_engine else None)
        sim = rep["simulation"]
        print(f"{rep['words']} words for {job.count} frames {job.size[0]}x{job.size[1]}, {len(boxes)} targets in "
              f"{slots} slots, {sim['cycles']} clocks ({sim['status']})")
        print(f"bit-exact: {'yes' if rep['bit_exact'] else 'NO'} ({rep['words']} words, {rep['mismatches']} differ "
              "from mstrack.hw.cosim_multi.expected_multi)")
        print(f"wrote {rep['files']['csv']}, {rep['files']['video']}, {rep['files']['report']}")
        if sim["status"] != "done":
            print(f"mstrack sim: error: the harness stopped early: {sim['status']} {sim['detail']}", file=sys.stderr)
            return EXIT_MISMATCH
        return EXIT_OK if rep["bit_exact"] else EXIT_MISMATCH
    rep = run_sim(job, out, progress=not args.quiet, command=getattr(args, "command_line", ""),
                  quick_build=args.quick_build)
    sim = rep["simulation"]
    print(f"{rep['results']} results for {job.count} frames {job.size[0]}x{job.size[1]}, {sim['cycles']} clocks "
          f"({sim['status']}), latency {sim['latency_min']}..{sim['latency_max']} clocks after the last pixel")
    print(report_line(rep))
    print(f"wrote {rep['files']['csv']}, {rep['files']['video']}, {rep['files']['report']}")
    if sim["status"] != "done":
        print(f"mstrack sim: error: the harness stopped early: {sim['status']} {sim['detail']}", file=sys.stderr)
        return EXIT_MISMATCH
    return EXIT_OK if rep["bit_exact"] else EXIT_MISMATCH


def register_cli(sub: argparse._SubParsersAction) -> None:
    """CLI extension (:data:`mstrack.cli.EXTENSIONS` entry ``"mstrack.simcli:register_cli"``): ``mstrack sim``."""
    p = sub.add_parser("sim", help="co-simulate the RTL core on a video and check it bit by bit against the model",
                       description="Stream VIDEO through the verilated RTL core (GHDL -> Verilog -> Verilator, "
                                   "mstrack.hw.fastsim), write results.csv, an overlay video and bitexact.json "
                                   "(every result field vs the fixed-point model). Exit 0 bit-exact, 1 mismatch "
                                   "or simulation failure, 2 bad input.")
    p.add_argument("video", metavar="VIDEO", help="video file, image folder or OTB/VOT sequence folder")
    p.add_argument("--box", type=_box_arg, metavar="X,Y,W,H", action="append",
                   help="init box on the first frame, 0-based pixels (rounded to integers as the init port "
                        "takes them), e.g. --box=-5,10,20,20 (default for a sequence folder: its ground truth); "
                        "a box partly outside the frame is clipped, one larger than the core's window shrunk, "
                        "with a warning.  Several --box: the multi-target core ms_tracker_multi, one slot "
                        "(core v2 engine) per box")
    p.add_argument("--slots", type=_positive, metavar="N",
                   help="multi-target core with N slots (MAX_TARGETS, 1 .. 16; default: one per --box)")
    p.add_argument("--shared-engine", action="store_true",
                   help="several --box on one engine (ms_tracker_shared) instead of one engine per slot "
                        "(ms_tracker_multi): a target whose job does not fit the frame is held, an add refused "
                        "(the capacity rule at the --timing raster)")
    p.add_argument("--timing", default="1080p60", choices=sorted(VIDEO_MODES),
                   help="--shared-engine: the video mode whose raster (lines and clocks per frame) the capacity "
                        "rule budgets (default 1080p60); the frames themselves stream without blanking")
    p.add_argument("--frames", type=parse_frame_range, metavar="FIRST,LAST",
                   help="stream frames FIRST..LAST (0-based, inclusive; init on FIRST); default all")
    p.add_argument("--max-frames", type=_positive, metavar="N", help="stream at most N frames")
    p.add_argument("--lanes", type=_positive, default=DEFAULT_LANES,
                   help=f"LANES generic, pixels per clock in the bin passes, a power of two (default {DEFAULT_LANES}; "
                        "one Verilator build per value, cached)")
    p.add_argument("--max-frame-width", type=_positive, default=2048, help="MAX_FRAME_W generic (default 2048)")
    p.add_argument("--preset", default=None,
                   help="tracker preset of the core: paper (default with one box; generic PRESET 0) or v2 (core v2, "
                        "PRESET 1: result word v2, results.csv with confidence and status; the multi-target "
                        "core's engines)")
    p.add_argument("--colour", action="store_true",
                   help="core v2 on colour bins alone (tracker mstrack-v2-colour's generics, ORIENT_T -1)")
    p.add_argument("--quick-build", action="store_true",
                   help="compile the Verilator model at -O1 instead of -O3: a build in about a third of the "
                        "time, a slower simulation (for a short clip; cached apart from the -O3 build)")
    p.add_argument("--out", help="output folder (default out/sim/<VIDEO name>)")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    p.set_defaults(func=_cmd_sim)


def _box_arg(s: str) -> Box:
    from .cli import _parse_box
    return _parse_box(s)


def _positive(s: str) -> int:
    from .cli import _positive_int
    return _positive_int(s)


__all__ = [
    "SIM_CSV_FIELDS", "SIM_CSV_FIELDS_V2", "SIM_CSV_FIELDS_MULTI", "run_sim_multi", "check_box",
    "SimInputError", "SimJob", "bitexact_report", "decode_row", "decode_row_v2", "field_mismatches",
    "parse_frame_range", "prepare", "register_cli", "report_line", "result_status", "run_sim"]
