"""Command-line interface: ``mstrack <command> ...``.

Built-in commands: ``eval``, ``track``, ``bench``, ``demo``.

Errors are one line (``mstrack <command>: error: ...``, exit 1; set
``MSTRACK_TRACEBACK=1`` for the traceback).  Bad input (README.md, "Bad
input"): an ``--out`` that is a file, lies under a file or is not writable is
refused before anything is run or written; ``--max-frames`` must be >= 1;
``track`` names the unreadable image file, warns when a video decodes fewer
frames than its container announces (``source`` in results.json); ``eval``
records a sequence that fails (corrupt frame, invalid frame-0 box) as failed in
the report and goes on with the others.

Extension point
---------------
Each command is one ``register(subparsers)`` function that adds its parser
and sets ``func=handler`` (``handler(args) -> int`` exit code).  Built-in ones
are listed in :data:`BUILTIN_COMMANDS`; other modules add theirs by appending
``"module:function"`` to :data:`EXTENSIONS`, e.g. ``"mstrack.hw.hdl:register_cli"``
for ``vectors`` / ``synth`` / ``cosim``.  Extension modules are imported only
when the CLI starts, so they may import heavy tools lazily.
"""
from __future__ import annotations

import argparse
import csv
import importlib
import json
import math
import os
import platform
import shlex
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from .io.data import DataError, VideoSource, load_dataset, open_video_writer
from .track.types import Box, Status, box_centre_index

DEFAULT_DATASET = "../shared/data/sequences"
#: Tracker of ``track``, ``demo`` and ``bench`` when none is given: tracker v2, the best measured
#: (docs/results.md); ``--preset paper`` runs :data:`PAPER_TRACKER`, the RTL core's algorithm.
DEFAULT_TRACKER = "mstrack-v2"
PAPER_TRACKER = "mstrack-fused-flat"
#: Default box on a person (dark jacket, blue jeans) in frame 0 of OpenCV's vtest.avi (768x576); he
#: walks left, stands by the lamp post among other people (frames ~25-150), then walks right.
VTEST_BOX = (500.0, 157.0, 30.0, 76.0)
VTEST_CANDIDATES = (
    "/usr/share/doc/opencv-doc/examples/data/vtest.avi",  # Debian 12 package opencv-doc
    "/usr/share/opencv4/samples/data/vtest.avi",
    "/usr/local/share/opencv4/samples/data/vtest.avi",
)
CSV_FIELDS = ("frame", "x", "y", "w", "h", "cx", "cy", "rho_c", "rho_e", "alpha_c", "confidence", "status")
#: Decimals of positions (x, y, w, h, cx, cy: 1e-6 px) and of rho_c, rho_e, alpha_c in results.csv /
#: results.json: no float noise (145.96000000000004 -> 145.96); the fixed model's values (multiples
#: of 2**-CF) are exact up to CF = 6.
POSITION_DECIMALS = 6
#: Decimals of ``confidence`` in results.csv / results.json (0..1; NaN / null for trackers without one).
CONFIDENCE_DECIMALS = 4
#: Overlays of frames narrower than this are upscaled (nearest neighbour, integer factor) so that the
#: status banner stays legible (Girl, 128x96, becomes 384x288).
OVERLAY_MIN_WIDTH = 320
PRESETS = ("paper", "v2")


# --------------------------------------------------------------------------- helpers

def _positive_int(s: str) -> int:
    try:
        v = int(s)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"wants a positive integer, got {s!r}") from exc
    if v < 1:
        raise argparse.ArgumentTypeError(f"wants a positive integer (>= 1), got {s!r}")
    return v


def check_out_dir(path: str | Path, option: str = "--out") -> Path:
    """Create the output folder ``path`` if needed and check that files can be written in it.

    Raises :class:`DataError` (one line, nothing written or removed) if ``path`` is a file, lies
    under a file, or cannot be created or written."""
    p = Path(path)
    for q in (p, *p.parents):
        if q.exists() and not q.is_dir():
            raise DataError(f"{option} {'is' if q == p else 'lies under'} a file, not a folder", q)
    try:
        p.mkdir(parents=True, exist_ok=True)
        import tempfile
        with tempfile.NamedTemporaryFile(dir=p, prefix=".mstrack-write-test-"):
            pass
    except OSError as exc:
        raise DataError(f"{option} folder cannot be created or written ({exc.strerror or exc})", p) from exc
    return p


def _csv_list(s: str | None) -> list[str] | None:
    return [t.strip() for t in s.split(",") if t.strip()] if s else None


def _parse_box(s: str) -> Box:
    try:
        return Box.of([float(v) for v in s.replace(" ", "").split(",")])
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"--box wants x,y,w,h (0-based pixels), got {s!r}") from exc


def _fmt(v: Any, nd: int = 3) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{nd}f}"


def _print_table(header: list[str], rows: list[list[str]], file: Any = None) -> None:
    file = file or sys.stdout
    w = [max(len(str(h)), *(len(str(r[i])) for r in rows)) if rows else len(h) for i, h in enumerate(header)]
    print("  ".join(str(h).ljust(w[i]) for i, h in enumerate(header)), file=file)
    for r in rows:
        print("  ".join(str(c).ljust(w[i]) for i, c in enumerate(r)), file=file)


def reports_confidence(tracker: Any) -> bool:
    """True if ``tracker`` computes a confidence (mstrack tracker v2, ``preset="v2"``); the paper
    preset and the OpenCV baselines leave ``confidence`` empty (NaN in the CSV, null in the JSON)."""
    return getattr(getattr(tracker, "params", None), "preset", None) == "v2"


def _row(i: int, res: Any, box: Box, status: str, confidence: bool = False) -> dict[str, Any]:
    cx, cy = getattr(res, "centre", None) or box_centre_index(box)
    g = lambda k: float(getattr(res, k, math.nan))  # noqa: E731
    conf = round(g("confidence"), CONFIDENCE_DECIMALS) if confidence and res is not None else math.nan
    r = lambda v: round(float(v), POSITION_DECIMALS)  # noqa: E731  (NaN stays NaN)
    return {"frame": i, "x": r(box.x), "y": r(box.y), "w": r(box.w), "h": r(box.h), "cx": r(cx), "cy": r(cy),
            "rho_c": r(g("rho_c")), "rho_e": r(g("rho_e")), "alpha_c": r(g("alpha_c")), "confidence": conf,
            "status": status}


#: Box colour per status (BGR): trusted green, re-acquired cyan, uncertain orange, lost / error red.
STATUS_COLOURS = {Status.OK.value: (0, 220, 0), Status.INIT.value: (0, 220, 0), Status.CLIPPED.value: (0, 220, 0),
                  Status.REACQUIRED.value: (255, 220, 0), Status.UNCERTAIN.value: (0, 165, 255),
                  Status.LOST.value: (0, 0, 255), Status.ERROR.value: (0, 0, 255)}
GT_COLOUR = (255, 255, 255)
_FONT = 0  # cv2.FONT_HERSHEY_SIMPLEX


def overlay_scale(width: int) -> int:
    """Integer upscale factor of the overlay of a frame ``width`` px wide (1 from OVERLAY_MIN_WIDTH up)."""
    return max(1, math.ceil(OVERLAY_MIN_WIDTH / max(int(width), 1)))


def overlay_lines(row: dict[str, Any], width: int, font_scale: float = 0.45) -> list[str]:
    """The banner text of ``row``, wrapped to lines that fit ``width`` px (at ``font_scale``).

    The first line starts with the frame number, the status and the confidence (when known), so
    they are never wrapped away; rho_c, rho_e and alpha_c follow when finite (only the rho of the
    feature in use when one feature drives the result, alpha_c 1 or 0)."""
    import cv2

    tokens = [f"#{row['frame']}", str(row["status"]).upper()]
    conf = row.get("confidence", math.nan)
    if conf is not None and math.isfinite(conf):
        tokens.append(f"conf {conf:.2f}")
    a = row.get("alpha_c")
    single = a is not None and a in (0.0, 1.0)  # one feature (colour or edge, v2): no fusion to show
    for key, label, show in (("rho_c", "rho_c", not single or a == 1.0), ("rho_e", "rho_e", not single or a == 0.0),
                             ("alpha_c", "a_c", not single)):
        v = row.get(key)
        if show and v is not None and math.isfinite(v):
            tokens.append(f"{label} {v:.2f}")
    lines: list[str] = []
    for tok in tokens:
        cand = f"{lines[-1]}  {tok}" if lines else tok
        if lines and cv2.getTextSize(cand, _FONT, font_scale, 1)[0][0] <= width - 8:
            lines[-1] = cand
        else:
            lines.append(tok)
    return lines


def _text_block(img: np.ndarray, lines: list[tuple[str, tuple[int, int, int] | None]], top: bool,
                font_scale: float) -> None:
    """Lines of white text on a half-transparent black band at the top or bottom of ``img``; a line
    with a colour gets a short swatch line of that colour before its text (legend)."""
    import cv2

    (_, th), base = cv2.getTextSize("Ag", _FONT, font_scale, 1)
    step = th + base + 4
    sw = 3 * th  # swatch length
    widths = [cv2.getTextSize(t, _FONT, font_scale, 1)[0][0] + (sw + 6 if c else 0) for t, c in lines]
    bw = min(img.shape[1], max(widths) + 8)
    bh = min(img.shape[0], step * len(lines) + 4)
    y0 = 0 if top else img.shape[0] - bh
    roi = img[y0:y0 + bh, 0:bw]
    roi[:] = (roi * 0.35).astype(np.uint8)
    for i, (text, colour) in enumerate(lines):
        yb = y0 + 4 + th + i * step
        x = 4
        if colour is not None:
            cv2.line(img, (x, yb - th // 2), (x + sw, yb - th // 2), colour, 2)
            x += sw + 6
        cv2.putText(img, text, (x, yb), _FONT, font_scale, (255, 255, 255), 1, cv2.LINE_AA)


def draw_overlay(frame: np.ndarray, row: dict[str, Any], gt: np.ndarray | None = None) -> np.ndarray:
    """Overlay of one frame: the tracked box coloured by status (:data:`STATUS_COLOURS`), its centre,
    a banner at the top (frame, status, confidence, rho values; wrapped to the width) and, when the
    ground truth ``gt`` is drawn (white), a legend at the bottom (ground truth vs tracker).

    Frames narrower than :data:`OVERLAY_MIN_WIDTH` are upscaled by :func:`overlay_scale` first (the
    returned image is then larger than ``frame``) so that the text stays readable."""
    import cv2

    k = overlay_scale(frame.shape[1])
    img = cv2.resize(frame, (frame.shape[1] * k, frame.shape[0] * k), interpolation=cv2.INTER_NEAREST) \
        if k > 1 else frame.copy()
    s = lambda v: int(round(v * k))  # noqa: E731
    fs = 0.45 if img.shape[1] >= 400 else 0.4
    have_gt = gt is not None and np.isfinite(gt).all()
    if have_gt:
        assert gt is not None
        x, y, w, h = gt
        cv2.rectangle(img, (s(x), s(y)), (s(x + w) - 1, s(y + h) - 1), GT_COLOUR, 1)
    col = STATUS_COLOURS.get(row["status"], (0, 0, 255))
    cv2.rectangle(img, (s(row["x"]), s(row["y"])), (s(row["x"] + row["w"]) - 1, s(row["y"] + row["h"]) - 1), col, 2)
    cv2.circle(img, (s(row["cx"] + 0.5 - 0.5 / k), s(row["cy"] + 0.5 - 0.5 / k)), 3, col, -1)  # pixel centre
    lines = overlay_lines(row, img.shape[1], fs)
    _text_block(img, [(t, None) for t in lines], True, fs)
    if have_gt:
        legend: list[tuple[str, tuple[int, int, int] | None]] = [("ground truth", GT_COLOUR), ("tracker", col)]
        legend += [(t, None) for t in _wrap(overlay_note(" ".join(lines)), img.shape[1], fs)]
        _text_block(img, legend, False, fs)
    return img


def overlay_note(banner: str) -> str:
    """The legend's explanation of the banner's numbers (those in ``banner`` only)."""
    parts = []
    if "conf " in banner:
        parts.append("conf: confidence 0-1")
    rho = [r for r in ("rho_c", "rho_e") if f"{r} " in banner]
    if rho:
        what = {"rho_c": "colour", "rho_e": "edge"}
        parts.append(f"{'/'.join(rho)}: {'/'.join(what[r] for r in rho)} match to the target 0-1")
    if "a_c " in banner:
        parts.append("a_c: weight of colour")
    return ", ".join(parts)


def _wrap(text: str, width: int, font_scale: float) -> list[str]:
    """``text`` cut at ", " into lines that fit ``width`` px (each piece on a line of its own if needed)."""
    import cv2

    lines: list[str] = []
    for piece in (p for p in text.split(", ") if p):
        cand = f"{lines[-1]}, {piece}" if lines else piece
        if lines and cv2.getTextSize(cand, _FONT, font_scale, 1)[0][0] <= width - 8:
            lines[-1] = cand
        else:
            lines.append(piece)
    return lines


def _warn(msg: str) -> None:
    print(f"mstrack: warning: {msg}", file=sys.stderr)


class _Display:
    """cv2.imshow if a display exists and OpenCV has a GUI; otherwise warns once and does nothing."""

    def __init__(self, enabled: bool) -> None:
        self.on = enabled
        if enabled and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            _warn("--show: no display (DISPLAY not set); not showing frames")
            self.on = False

    def show(self, img: np.ndarray) -> None:
        if not self.on:
            return
        import cv2
        try:
            cv2.imshow("mstrack", img)
            cv2.waitKey(1)
        except cv2.error:
            _warn("--show: this OpenCV build has no GUI support (opencv-*-headless); not showing frames")
            self.on = False

    def close(self) -> None:
        if self.on:
            import cv2
            try:
                cv2.destroyAllWindows()
            except cv2.error:
                pass


def init_box_note(given: Box, got: Box, frame_shape: tuple[int, ...]) -> str | None:
    """One line saying how the tracker changed the init box ``given`` into ``got`` on a frame of
    ``frame_shape`` (H, W, ...): clipped to the frame and/or shrunk (to the model's largest
    window by more than a pixel); None otherwise (sub-pixel rounding of the box is not reported)."""
    hgt, wid = frame_shape[0], frame_shape[1]
    x0, y0 = max(given.x, 0.0), max(given.y, 0.0)
    x1, y1 = min(given.x + given.w, float(wid)), min(given.y + given.h, float(hgt))
    clipped = (x0, y0, x1, y1) != (given.x, given.y, given.x + given.w, given.y + given.h)
    shrunk = got.w < (x1 - x0) - 1.01 or got.h < (y1 - y0) - 1.01
    if not (clipped or shrunk):
        return None
    why = " and ".join(w for w, on in ((f"clipped to the {wid}x{hgt} frame", clipped),
                                       ("shrunk to the largest window the model tracks", shrunk)) if on)
    f = lambda b: "(" + ", ".join(f"{v:g}" for v in (round(c, 2) for c in b)) + ")"  # noqa: E731
    return f"init box {f(given)} {why}: tracking {f(got)} (x, y, w, h)"


def track_frames(tracker: Any, frames: Iterable[np.ndarray | None], box: Box, out_dir: Path, fps: float = 30.0,
                 gt: np.ndarray | None = None, show: bool = False, max_frames: int | None = None,
                 progress: bool = False, source: VideoSource | None = None, warn_init: bool = False
                 ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Track through ``frames`` and write results.csv, results.json and an overlay video.

    Parameters
    ----------
    tracker : object with ``init(frame, box)`` / ``update(frame)``
    frames : iterable of ndarray (H, W, 3) uint8 BGR, or None for an unreadable frame
    box : Box
        Initial box on frame 0, 0-based pixels.
    out_dir : Path
    fps : float
        Frame rate of the overlay video.
    gt : ndarray, shape (N, 4), optional
        Ground truth drawn in white on the overlay.
    show : bool
        Also display frames (only with a display).
    max_frames : int, optional
        At least 1.
    source : VideoSource, optional
        The source ``frames`` come from: unreadable images are then named
        (``frame_errors`` in results.json) and a video that decoded fewer
        frames than its container announces is reported (``source``).
    warn_init : bool
        Warn on stderr when the tracker clips or shrinks the init box (:func:`init_box_note`).

    Returns
    -------
    rows : list of dict
        One per frame with the :data:`CSV_FIELDS`.
    info : dict
        ``video`` (path written), ``fps`` (update() calls per second), ``frames``,
        ``source`` (``kind``, ``frames_decoded``, ``truncated``; with ``source``).

    Notes
    -----
    A ``FrameError`` from ``update`` (or an unreadable frame) is recorded as
    status "error" with the previous box, and tracking goes on.  ``status`` is
    a :class:`~mstrack.track.types.Status` value (v2 adds "uncertain" and
    "reacquired"); ``confidence`` (0..1, :data:`CONFIDENCE_DECIMALS` decimals)
    is filled for tracker v2 only (:func:`reports_confidence`).  The overlay
    video is upscaled for frames narrower than :data:`OVERLAY_MIN_WIDTH`.
    """
    from tqdm import tqdm

    from .eval.evaluate import frame_error_types, result_status, to_box

    if max_frames is not None and max_frames < 1:
        raise ValueError(f"max_frames must be >= 1, got {max_frames}")
    bad_frame = frame_error_types()
    conf = reports_confidence(tracker)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    writer = None
    video_path = None
    size: tuple[int, int] = (0, 0)
    display = _Display(show)
    t_upd, n_upd = 0.0, 0
    total: int | None = len(frames) if hasattr(frames, "__len__") else len(source) if source is not None else None  # type: ignore[arg-type]
    if total is not None and max_frames is not None:
        total = min(total, max_frames)
    try:
        for i, frame in enumerate(tqdm(frames, desc="track", disable=not progress, unit="f", total=total or None,
                                       dynamic_ncols=True)):
            if max_frames is not None and i >= max_frames:
                break
            if i == 0:
                if frame is None:
                    err = source.errors.get(0) if source is not None else None
                    if err is not None:
                        raise DataError(f"frame 0 is unreadable ({err.reason})", err.path)
                    raise DataError("frame 0 is unreadable", getattr(source, "path", out_dir))
                res = tracker.init(frame, box)
                b = to_box(res) if res is not None else box
                note = init_box_note(box, b, frame.shape) if warn_init else None
                if note:
                    _warn(note)
                row = _row(0, res, b, result_status(res) if res is not None else Status.INIT.value, conf)
                size = (frame.shape[1], frame.shape[0])
            else:
                prev = rows[-1]
                res, st = None, Status.ERROR.value
                if frame is not None:
                    t0 = time.perf_counter()
                    try:
                        res = tracker.update(frame)
                        st = result_status(res)
                    except bad_frame:
                        res = None
                    t_upd += time.perf_counter() - t0
                    n_upd += 1
                if res is None:
                    b = Box(prev["x"], prev["y"], prev["w"], prev["h"])
                    row = _row(i, None, b, Status.ERROR.value)
                    row.update(cx=prev["cx"], cy=prev["cy"])
                else:
                    row = _row(i, res, to_box(res), st, conf)
            rows.append(row)
            if frame is None or frame.ndim != 3 or (frame.shape[1], frame.shape[0]) != size:
                import cv2
                canvas = np.zeros((size[1], size[0], 3), np.uint8) if frame is None or frame.ndim != 3 \
                    else cv2.resize(frame, size)
            else:
                canvas = frame
            img = draw_overlay(canvas, row, None if gt is None or i >= len(gt) else gt[i])
            if writer is None:  # the overlay may be larger than the frame (small frames are upscaled)
                writer, video_path = open_video_writer(out_dir / "overlay.mp4", fps, (img.shape[1], img.shape[0]))
            writer.write(img)
            display.show(img)
    finally:
        if writer is not None:
            writer.release()
        display.close()
    with open(out_dir / "results.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS)
        w.writeheader()
        w.writerows(rows)
    info: dict[str, Any] = {"frames": len(rows), "video": str(video_path),
                            "fps": n_upd / t_upd if t_upd > 0 else math.nan}
    if source is not None:
        info["source"] = {"path": str(source.path), "kind": source.kind, "frames_decoded": source.decoded,
                          "truncated": source.truncated}
        info["frame_errors"] = {str(i): str(e) for i, e in source.errors.items() if i < len(rows)}
    clean = [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in rows]
    (out_dir / "results.json").write_text(json.dumps({"init_box": list(box.as_tuple()), **info,
                                                      "box_convention": "0-based x,y,w,h; cx,cy pixel-index centre",
                                                      "frames_data": clean}, indent=1) + "\n")
    return rows, info


def resolve_tracker(tracker: str | None, preset: str | None) -> str:
    """Tracker name from ``--tracker`` and ``--preset`` (track, demo, bench).

    No option: :data:`DEFAULT_TRACKER` (mstrack-v2).  ``--preset v2`` runs ``mstrack-v2`` (or
    ``--tracker mstrack-v2-colour``, tracker v2 on colour alone); ``--preset paper`` runs ``--tracker`` or
    :data:`PAPER_TRACKER` (mstrack-fused-flat, the paper's algorithm: the RTL core's).  An unknown
    name is refused with the list of known ones."""
    from .eval.evaluate import tracker_names

    from .eval.evaluate import RENAMED

    v2, v2s = "mstrack-v2", ("mstrack-v2", "mstrack-v2-colour")
    if tracker in RENAMED:
        raise ValueError(f"tracker {tracker!r} is now {RENAMED[tracker]!r}")
    if tracker is not None and tracker not in tracker_names():
        raise ValueError(f"unknown tracker {tracker!r}; known: {', '.join(tracker_names())}")
    if preset == "v2":
        if tracker not in (None, *v2s):
            raise ValueError(f"--preset v2 runs {' or '.join(v2s)}; leave out --tracker {tracker} "
                             "(or use --preset paper)")
        return tracker or v2
    if preset == "paper":
        if tracker in v2s:
            raise ValueError(f"--tracker {tracker} is the v2 preset; leave out --preset paper")
        return tracker or PAPER_TRACKER
    return tracker or DEFAULT_TRACKER


def _tracker_help() -> str:
    from .eval.evaluate import tracker_names

    return (f"tracker name: {', '.join(tracker_names())} (default {DEFAULT_TRACKER}, the best measured, "
            "docs/results.md; with --preset paper: " + PAPER_TRACKER + ")")


MODEL_HELP = ("mstrack model: float (the floating-point reference, default) or fixed (the bit-accurate "
              "fixed-point model of the hardware core; slower)")


def _add_preset_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--tracker", default=None, metavar="NAME", help=_tracker_help())
    p.add_argument("--preset", choices=PRESETS, default=None,
                   help="mstrack algorithm: v2 (default: tracker v2, scale, confidence, loss and "
                        "re-acquisition) or paper (the paper's fixed-size colour + edge fusion, as the RTL "
                        "core runs it today; then --tracker picks its variant)")


# --------------------------------------------------------------------------- eval

def _cmd_eval(args: argparse.Namespace) -> int:
    from .eval.evaluate import evaluate, tracker_names
    from .eval.report import write_report
    from .io.mot import is_mot_dataset

    if is_mot_dataset(args.dataset):  # MOT format (gt.txt): the multi-object evaluation (docs/multi.md)
        from .multicli import cmd_eval_mot
        return cmd_eval_mot(args)

    names = _csv_list(args.trackers) or tracker_names()
    unknown = [n for n in names if n not in tracker_names()]
    if unknown:
        raise ValueError(f"unknown tracker(s) {', '.join(unknown)}; known: {', '.join(tracker_names())}")
    check_out_dir(args.out)
    seqs = load_dataset(args.dataset, _csv_list(args.sequences))
    ev = evaluate(seqs, names, args.out, model=args.model, force=args.force, quiet=args.quiet,
                  max_frames=args.max_frames, jobs=args.jobs, scheduler=args.scheduler)
    for s, per in ev.failed.items():
        for t, reason in per.items():
            _warn(f"{t} on {s} failed, sequence left out of the scores: {reason}")
    paths = write_report(ev, args.out, command=args.command_line)
    order = sorted(ev.trackers, key=lambda t: -ev.overall[t].auc)
    _print_table(["tracker", "AUC", "P@20", "fps"],
                 [[t, _fmt(ev.overall[t].auc), _fmt(ev.overall[t].precision20), _fmt(ev.fps[t], 1)] for t in order])
    if ev.failed:
        print(f"{len(ev.failed)} of {len(seqs)} sequences failed: {', '.join(ev.failed)} (see the report)")
    print(f"report: {paths['md']}")
    return 0 if ev.sequences else 1


def register_eval(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("eval", help="OTB one-pass evaluation of trackers on a dataset folder",
                       description="Run trackers over every sequence of DATASET_DIR (OPE) and write a report. "
                                   "A MOT folder (gt.txt) gets the multi-object evaluation (docs/multi.md).")
    p.add_argument("dataset", metavar="DATASET_DIR", help="folder of OTB/VOT sequence folders, or a MOT "
                                                           "sequence folder (gt.txt, img/) or a folder of them")
    p.add_argument("--trackers", help="comma-separated tracker names (default: all registered)")
    p.add_argument("--model", choices=("float", "fixed"), default="float", help=MODEL_HELP)
    p.add_argument("--out", default="out/eval", help="report folder (default out/eval)")
    p.add_argument("--sequences", help="comma-separated sequence names (default: all; case-insensitive when "
                                       "that names one sequence)")
    p.add_argument("--max-frames", type=_positive_int, help="use at most N frames per sequence (N >= 1)")
    p.add_argument("--force", action="store_true", help="ignore cached per-sequence results")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument("--jobs", "-j", type=_positive_int, default=1, metavar="N",
                   help="run N (tracker, sequence) runs at once in worker processes (default 1); the "
                        "results are those of one process, only the fps differ")
    p.add_argument("--scheduler", nargs="?", const="local", default=None, metavar="ADDRESS",
                   help="run on Dask distributed: the scheduler at ADDRESS (tcp://host:8786; its workers "
                        "must see DATASET_DIR at the same path), or, with no ADDRESS, a local cluster of "
                        "--jobs workers (docs/distributed.md)")
    p.set_defaults(func=_cmd_eval)


# --------------------------------------------------------------------------- track

def _cmd_track(args: argparse.Namespace) -> int:
    from .eval.evaluate import make_tracker
    from .io.mot import is_mot_dir

    boxes = list(args.box or [])
    if len(boxes) > 1 or args.init is not None or (not boxes and is_mot_dir(args.source)):
        from .multicli import cmd_track_multi  # several targets (docs/multi.md)
        return cmd_track_multi(args, boxes, args.init)
    src = VideoSource(args.source)
    box = boxes[0] if boxes else None
    gt = None
    if src.sequence is not None:
        gt = src.sequence.gt
        if box is None:
            box = src.sequence.init_box()
    if box is None:
        raise ValueError("--box x,y,w,h is required unless SOURCE is a sequence folder with ground truth")
    out = Path(args.out) if args.out else Path("out/track") / Path(args.source).resolve().name
    check_out_dir(out)
    tracker = make_tracker(resolve_tracker(args.tracker, args.preset), args.model)
    rows, info = track_frames(tracker, src.frames(on_bad="none"), box, out, fps=src.fps, gt=gt, show=args.show,
                              max_frames=args.max_frames, progress=not args.quiet and sys.stderr.isatty(),
                              source=src, warn_init=True)
    for i, err in info["frame_errors"].items():
        _warn(f"frame {i}: {err}")
    if src.truncated:
        _warn(f"{src.path}: {src.truncated}")
    n_err = sum(r["status"] == Status.ERROR.value for r in rows)
    print(f"{len(rows)} frames, {n_err} error frames, {_fmt(info['fps'], 1)} fps (update only)"
          + (f"; VIDEO TRUNCATED: {src.truncated}" if src.truncated else ""))
    print(f"wrote {out / 'results.csv'}, {out / 'results.json'}, {info['video']}")
    return 0


def register_track(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("track", help="track one or several targets in a video, image folder or sequence folder",
                       description="Track one target and write results.csv, results.json and an overlay video; "
                                   "with several --box or --init: several targets, results.csv in MOT format "
                                   "(docs/multi.md).")
    p.add_argument("source", metavar="SOURCE", help="video file, image folder, OTB/VOT sequence folder or MOT "
                                                   "sequence folder (gt.txt: its targets by default)")
    p.add_argument("--box", type=_parse_box, metavar="X,Y,W,H", action="append",
                   help="initial box, 0-based pixels, e.g. --box -5,10,20,20 (default: frame 0 ground truth); "
                        "a box outside the frame is clipped, one larger than the model's window shrunk, "
                        "with a warning.  Repeat it for several targets (ids 1, 2, ... in order)")
    p.add_argument("--init", metavar="GT_TXT",
                   help="a MOT file (frame,id,x,y,w,h,...; 1-based): each id is added on its first frame with "
                        "its box there (id = its MOT id) and tracked to the end")
    p.add_argument("--model", choices=("float", "fixed"), default="float", help=MODEL_HELP)
    _add_preset_options(p)
    p.add_argument("--out", help="output folder (default out/track/<source name>)")
    p.add_argument("--max-frames", type=_positive_int, help="stop after N frames (N >= 1)")
    p.add_argument("--show", action="store_true", help="display frames (needs a display)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_track)


# --------------------------------------------------------------------------- bench

def bench_fps(tracker: Any, frames: list[np.ndarray], box: Box) -> float:
    """update() calls per second of ``tracker`` over preloaded ``frames`` (init on frames[0])."""
    tracker.init(frames[0], box)
    t0 = time.perf_counter()
    for f in frames[1:]:
        tracker.update(f)
    dt = time.perf_counter() - t0
    return (len(frames) - 1) / dt if dt > 0 else math.nan


def parse_variant(text: str) -> dict[str, Any]:
    """``KEY=VALUE[,KEY=VALUE...]`` (``bench --variant``) as TrackerParams overrides; values are
    int, float, true / false, or else strings: ``"orient_T=64,scale_test=0.05,scale_test_gate=true"``."""
    from .track.params import TrackerParams

    out: dict[str, Any] = {}
    for item in _csv_list(text) or []:
        key, sep, val = item.partition("=")
        key, val = key.strip(), val.strip()
        if not sep or key not in TrackerParams.field_names():
            raise ValueError(f"--variant: {item!r} is not KEY=VALUE with KEY a TrackerParams field")
        v: Any = val
        if val.lower() in ("true", "false"):
            v = val.lower() == "true"
        else:
            for conv in (int, float):
                try:
                    v = conv(val)
                    break
                except ValueError:
                    pass
        out[key] = v
    if not out:
        raise ValueError("--variant needs KEY=VALUE")
    return out


def _cmd_bench(args: argparse.Namespace) -> int:
    from .eval.evaluate import make_tracker, run_label
    from .io.mot import is_mot_dataset

    if args.dataset and is_mot_dataset(args.dataset):  # per-target speed of the MultiTracker (docs/multi.md)
        from .multicli import cmd_bench_mot
        return cmd_bench_mot(args)

    models = ["float", "fixed"] if args.model == "both" else [args.model]
    variants: list[tuple[str, dict[str, Any]]] = [("", {})]
    for text in args.variant or []:
        if not args.tracker.startswith("mstrack-"):
            raise ValueError("--variant needs an mstrack tracker")
        label, colon, rest = text.partition(":")
        kv = parse_variant(rest if colon else text)
        variants.append(("[" + (label if colon else ",".join(f"{k}={v}" for k, v in kv.items())) + "]", kv))
    runs = [(run_label(args.tracker, m) + tag, (args.tracker, kv), m) for tag, kv in variants for m in models]
    runs += [("opencv-camshift", ("opencv-camshift", {}), "float")]

    def make(spec: tuple[str, dict[str, Any]], m: str) -> Any:
        name, kv = spec
        if not kv:
            return make_tracker(name, m)
        from .explore import _base_params
        from .track.tracker import Tracker
        _, base = _base_params(name)
        return Tracker(model=m, **{**base, **kv})  # type: ignore[arg-type]
    cases: list[tuple[str, list[np.ndarray], Box]] = []
    if args.dataset:
        for s in load_dataset(args.dataset, _csv_list(args.sequences)):
            n = min(len(s), args.frames)
            cases.append((s.name, [s.frame(i) for i in range(n)], s.init_box()))
    else:
        from .io.synthetic import make_scene
        scene, gt = make_scene(args.frames, 640, 360, seed=0)
        cases.append(("synthetic-640x360", list(scene), Box.of(gt[0])))
    header = ["sequence", "frames", "size", *[r[0] + " fps" for r in runs],
              *[f"{r[0]}/camshift" for r in runs[:-1]]]
    rows = []
    tot = {r[0]: [0, 0.0] for r in runs}
    for name, frames, box in cases:
        fps = {}
        for label, tname, m in runs:
            fps[label] = bench_fps(make(tname, m), frames, box)
            tot[label][0] += len(frames) - 1
            tot[label][1] += (len(frames) - 1) / fps[label] if fps[label] > 0 else 0.0
        cam = fps["opencv-camshift"]
        rows.append([name, str(len(frames)), f"{frames[0].shape[1]}x{frames[0].shape[0]}",
                     *[_fmt(fps[r[0]], 1) for r in runs], *[_fmt(fps[r[0]] / cam, 4) for r in runs[:-1]]])
    all_fps = {k: (n / t if t > 0 else math.nan) for k, (n, t) in tot.items()}
    if len(cases) > 1:
        rows.append(["all", str(sum(len(c[1]) for c in cases)), "", *[_fmt(all_fps[r[0]], 1) for r in runs],
                     *[_fmt(all_fps[r[0]] / all_fps["opencv-camshift"], 4) for r in runs[:-1]]])
    _print_table(header, rows)
    if args.write_docs:
        from .versions import PYTHON_TOOLS, tools_line
        md = ["# mstrack speed benchmark", "",
              f"Command: `{args.command_line}`", "",
              f"Date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M UTC}; machine: {platform.machine()}, "
              f"{os.cpu_count()} cores, Python {platform.python_version()}.", "",
              tools_line(PYTHON_TOOLS), "",
              "fps = update() calls per second on frames preloaded in memory (init excluded).", "",
              "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        md += ["| " + " | ".join(r) + " |" for r in rows]
        path = Path(args.docs_file)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(md) + "\n")
        print(f"wrote {path}")
    return 0


def register_bench(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="speed of mstrack vs OpenCV CamShift",
                       description="fps of the mstrack tracker(s) and of OpenCV CamShift on the same frames. "
                                   "Without DATASET_DIR: a synthetic 640x360 scene with a 64x64 target.")
    p.add_argument("dataset", metavar="DATASET_DIR", nargs="?",
                   help="folder of sequences (optional); a MOT folder (gt.txt): target updates per second of "
                        "the MultiTracker against one CamShift per target (--write-docs: docs/bench_multi.md)")
    p.add_argument("--sequences", help="comma-separated sequence names (default: all)")
    p.add_argument("--model", choices=("float", "fixed", "both"), default="both",
                   help="float reference, fixed-point model, or both (default)")
    p.add_argument("--tracker", default=DEFAULT_TRACKER, help=f"mstrack variant (default {DEFAULT_TRACKER})")
    p.add_argument("--frames", type=int, default=100, help="frames per sequence (default 100)")
    p.add_argument("--variant", action="append", metavar="[LABEL:]KEY=VALUE[,KEY=VALUE...]",
                   help="also run the tracker with these TrackerParams (repeatable; labelled tracker[LABEL], "
                        "default tracker[KEY=VALUE,...]), e.g. tracker v2's joint candidate: "
                        "--variant joint:orient_T=64,scale_test=0.05,scale_test_gate=true")
    p.add_argument("--write-docs", action="store_true", help="write the table to docs/bench.md")
    p.add_argument("--docs-file", default="docs/bench.md", help=argparse.SUPPRESS)
    p.set_defaults(func=_cmd_bench)


# --------------------------------------------------------------------------- demo

def find_vtest() -> Path | None:
    """Path of OpenCV's sample video vtest.avi if installed (opencv-doc, samples dir, cv2 package), else None."""
    cands = [Path(p) for p in VTEST_CANDIDATES]
    try:
        import cv2
        found = cv2.samples.findFile("vtest.avi", required=False, silentMode=True)
        if found:
            cands.insert(0, Path(found))
        cands += sorted(Path(cv2.__file__).parent.rglob("vtest.avi"))
    except Exception:  # noqa: BLE001  (samples API differs between builds)
        pass
    return next((p for p in cands if p.is_file()), None)


def _cmd_demo(args: argparse.Namespace) -> int:
    from .eval.evaluate import make_tracker, run_label
    from .eval.metrics import score
    from .io.synthetic import make_scene

    out = Path(args.out)
    name = resolve_tracker(args.tracker, args.preset)
    label = run_label(name, args.model)
    summary: dict[str, Any] = {"tracker": label}
    # (a) synthetic scene with exact ground truth
    frames, gt = make_scene(args.synthetic_frames, 320, 240, seed=1)
    rows, info = track_frames(make_tracker(name, args.model), frames, Box.of(gt[0]), out / "synthetic",
                              fps=25.0, gt=gt)
    pred = np.array([[r["x"], r["y"], r["w"], r["h"]] for r in rows])
    sc = score(pred, gt[:len(pred)])
    summary["synthetic"] = {"frames": len(rows), "auc": sc.auc, "precision20": sc.precision20,
                            "mean_iou": float(sc.ious.mean()), "fps": info["fps"], "video": info["video"]}
    print(f"[demo] synthetic scene, {len(rows)} frames, {label}: AUC {sc.auc:.3f}, P@20 {sc.precision20:.3f}, "
          f"mean IoU {sc.ious.mean():.3f}, {_fmt(info['fps'], 1)} fps -> {info['video']}")
    # (b) OpenCV's sample video, if installed
    vt = Path(args.video) if args.video else find_vtest()
    if vt is None:
        print("[demo] vtest.avi not found (Debian: apt-get install opencv-doc); skipping the video part")
        summary["vtest"] = None
    else:
        src = VideoSource(vt)
        rows, info = track_frames(make_tracker(name, args.model), src.frames(), Box.of(args.box), out / "vtest",
                                  fps=src.fps, max_frames=args.frames)
        rho = np.array([r["rho_c"] for r in rows[1:]], dtype=float)
        conf = np.array([r["confidence"] for r in rows[1:]], dtype=float)
        st = {s: sum(r["status"] == s for r in rows) for s in dict.fromkeys(r["status"] for r in rows)}
        summary["vtest"] = {"source": str(vt), "box": list(Box.of(args.box).as_tuple()), "frames": len(rows),
                            "fps": info["fps"], "status": st, "video": info["video"],
                            "mean_rho_c": float(np.nanmean(rho)) if np.isfinite(rho).any() else None,
                            "mean_confidence": float(np.nanmean(conf)) if np.isfinite(conf).any() else None}
        print(f"[demo] {vt.name}, {len(rows)} frames from box {Box.of(args.box).as_tuple()}: status {st}, "
              f"{_fmt(info['fps'], 1)} fps -> {info['video']}")
    # (c) several targets at once: a generated scene with four targets (docs/multi.md)
    if args.multi_frames > 0:
        from .multicli import demo_multi
        m = demo_multi(name, args.model, out / "multi", args.multi_frames)
        summary["multi"] = m
        mot = m["mot"] or {}
        print(f"[demo] multi-target scene, {m['frames']} frames, {m['targets']} targets (two enter / leave "
              f"mid-scene), {label}: mean AUC {m['mean_auc']:.3f}"
              + (f", HOTA {mot['HOTA']:.3f}, MOTA {mot['MOTA']:.3f}, IDF1 {mot['IDF1']:.3f}" if mot else "")
              + f", {_fmt(m['fps'], 1)} target updates/s -> {m['video']}")
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=lambda v: None) + "\n")
    print(f"[demo] results in {out}/ (summary.json, */results.csv, */overlay video)")
    return 0


def register_demo(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the tracker on a synthetic scene, OpenCV's vtest.avi and a "
                                    "multi-target scene",
                       description="Default job: needs no dataset. Writes overlays and results to --out.")
    p.add_argument("--out", default="out/demo", help="output folder (default out/demo)")
    p.add_argument("--model", choices=("float", "fixed"), default="float", help=MODEL_HELP)
    _add_preset_options(p)
    p.add_argument("--frames", type=int, default=200, help="vtest.avi frames to track (default 200)")
    p.add_argument("--synthetic-frames", type=int, default=120, help="synthetic scene length (default 120)")
    p.add_argument("--multi-frames", type=int, default=60,
                   help="length of the multi-target scene (four targets; default 60, 0: skip it)")
    p.add_argument("--video", help="video to use instead of vtest.avi (then also give --box)")
    p.add_argument("--box", type=_parse_box, default=Box(*VTEST_BOX),
                   help="init box x,y,w,h for the video (default: a person in vtest.avi)")
    p.set_defaults(func=_cmd_demo)


# --------------------------------------------------------------------------- registry / main

#: Built-in commands: name -> register(subparsers).
BUILTIN_COMMANDS: dict[str, Callable[[argparse._SubParsersAction], None]] = {
    "eval": register_eval,
    "track": register_track,
    "bench": register_bench,
    "demo": register_demo,
}

#: EXTENSION POINT: "module:function" entries, each function registering one or
#: more subcommands exactly like the built-in ``register_*`` functions above.
EXTENSIONS: list[str] = [
    "mstrack.hw.vectors:register_cli",     # vectors: test vectors for the VHDL core
    "mstrack.eval.agreement:register_cli",   # agree: float vs fixed-point agreement
    "mstrack.hw.synth:register_cli",       # synth: open synthesis, Fmax, cycle figures (performance.md)
    "mstrack.hw.hdl_config:register_cli",  # hdl config / hdl files: core configuration, file lists (packaging.md)
    "mstrack.explore:register_cli",     # explore: design-space sweep, accuracy vs resources (explore.md)
    "mstrack.simcli:register_cli",      # sim: the RTL core co-simulated on a video, bit-exact check (integration.md)
    # "mstrack.hw.hdl:register_cli",       # synth / cosim (HDL helpers add their line here)
]


class _VersionAction(argparse.Action):
    """``mstrack --version``: the package version, then one line of tool versions."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any,
                 option_string: str | None = None) -> None:
        from .versions import package_version, tools_line
        print(f"mstrack {package_version()}")
        print(tools_line())
        parser.exit()


def build_parser(extensions: list[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser with built-in commands and the :data:`EXTENSIONS`."""
    parser = argparse.ArgumentParser(
        prog="mstrack", description="mstrack: mean-shift object tracking, from the float reference to the FPGA core: "
                                    "track, evaluate, benchmark, co-simulate and synthesise.")
    parser.add_argument("--version", action=_VersionAction, nargs=0,
                        help="print the package version and the versions of the tools it uses, then exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for register in BUILTIN_COMMANDS.values():
        register(sub)
    for spec in EXTENSIONS if extensions is None else extensions:
        mod_name, _, fn_name = spec.partition(":")
        try:
            mod = importlib.import_module(mod_name)
        except ModuleNotFoundError as exc:
            if exc.name != mod_name:
                raise
            print(f"mstrack: warning: CLI extension {mod_name} not found, skipped", file=sys.stderr)
            continue
        getattr(mod, fn_name or "register")(sub)
    return parser


#: Options whose value is a list of numbers that may start with "-" (``--box -5,10,20,20``).
NUMBER_LIST_OPTIONS = ("--box",)


def join_number_lists(argv: list[str]) -> list[str]:
    """``["--box", "-5,10,20,20"]`` -> ``["--box=-5,10,20,20"]``: argparse would take a value that
    starts with "-" (and is not one number) for an option; the ``--box=`` form needs no help."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in NUMBER_LIST_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-") \
                and all(_is_number(t) for t in argv[i + 1].replace(" ", "").split(",")):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


COMPILE_NOTICE = ("mstrack: compiling the numba kernels (first run after an install or update, about 10 s; "
                  "cached on disk afterwards)...")


def install_compile_notice(file: Any = None) -> bool:
    """Print :data:`COMPILE_NOTICE` once, on stderr, when numba starts its first compilation in this
    process (a numba event listener: nothing is printed when the kernels load from numba's disk
    cache).  False if numba is not installed."""
    try:
        from numba.core import event
    except ImportError:
        return False

    class _Notice(event.Listener):
        said = False

        def on_start(self, ev: Any) -> None:
            if not self.said:
                self.said = True
                print(COMPILE_NOTICE, file=file or sys.stderr, flush=True)

        def on_end(self, ev: Any) -> None:
            pass

    event.register("numba:compile", _Notice())
    return True


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mstrack`` command; returns the exit code."""
    argv = join_number_lists(list(sys.argv[1:] if argv is None else argv))
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    args.command_line = "mstrack " + shlex.join(argv)
    install_compile_notice()
    try:
        return int(args.func(args) or 0)
    except (DataError, ValueError, ImportError, RuntimeError, OSError) as exc:
        if os.environ.get("MSTRACK_TRACEBACK"):
            raise
        print(f"mstrack {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
