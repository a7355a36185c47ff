"""The multi-target side of the CLI (called from :mod:`mstrack.cli`; docs/multi.md).

* ``mstrack track SOURCE --box x,y,w,h --box ...`` or ``--init gt.txt``: several targets; writes
  ``results.csv`` in MOT format, ``results.json`` (every field of every target per frame) and an
  overlay video with each target in its own colour, its id and status (:func:`track_multi_frames`);
* ``mstrack eval MOT_DIR``: the multi-object evaluation (:mod:`mstrack.eval.multi`);
* ``mstrack bench MOT_DIR``: per-target update speed against OpenCV CamShift's;
* ``mstrack demo``: a multi-target run on a generated scene (:func:`demo_multi`).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .io.data import DataError, VideoSource, open_video_writer
from .track.types import Box, Status, box_centre_index

#: Columns of the MOT-format results.csv: ``frame,id,x,y,w,h,conf,-1,-1,-1`` (1-based frame, x, y).
MOT_COLUMNS = ("frame", "id", "x", "y", "w", "h", "conf", "x3d", "y3d", "z3d")
#: Per-target colours of the overlay (BGR), by label: distinct hues, then again.
TARGET_COLOURS = ((0, 220, 0), (255, 160, 0), (0, 160, 255), (255, 0, 255), (0, 255, 255), (255, 255, 0),
                  (128, 0, 255), (0, 96, 255), (255, 96, 128), (160, 255, 96), (96, 128, 255), (200, 200, 200))


def target_colour(label: int) -> tuple[int, int, int]:
    """Overlay colour of target ``label`` (BGR)."""
    return TARGET_COLOURS[(int(label) - 1) % len(TARGET_COLOURS)]


# --------------------------------------------------------------------------- init boxes
def read_init(path: str | Path) -> list[tuple[int, int, Box]]:
    """``(frame, id, box)`` of each target of a MOT file at its first frame (0-based frame and box;
    the file is MOTChallenge's 1-based), in frame then id order."""
    from .io.mot import parse_mot_gt
    rows = parse_mot_gt(path)
    out: dict[int, tuple[int, int, Box]] = {}
    for r in rows:
        tid = int(r[1])
        if tid not in out:
            out[tid] = (int(r[0]) - 1, tid, Box(r[2] - 1, r[3] - 1, r[4], r[5]))
    return sorted(out.values(), key=lambda t: (t[0], t[1]))


# --------------------------------------------------------------------------- overlay
def draw_multi_overlay(frame: np.ndarray, frame_no: int, rows: list[dict[str, Any]],
                       gt: dict[int, Box] | None = None) -> np.ndarray:
    """Overlay of one frame: each target's box in its own colour (2 px when ``ok``, 1 px otherwise),
    a tag above it with its id and status (and confidence when known), ground truth in thin white,
    a banner with the frame number and the targets' count."""
    import cv2

    from .cli import _FONT, GT_COLOUR, _text_block, overlay_scale
    k = overlay_scale(frame.shape[1])
    img = cv2.resize(frame, (frame.shape[1] * k, frame.shape[0] * k), interpolation=cv2.INTER_NEAREST) \
        if k > 1 else frame.copy()
    s = lambda v: int(round(v * k))  # noqa: E731
    fs = 0.4
    for b in (gt or {}).values():
        cv2.rectangle(img, (s(b.x), s(b.y)), (s(b.x + b.w) - 1, s(b.y + b.h) - 1), GT_COLOUR, 1)
    n_ok = sum(r["status"] in ("ok", "init", "clipped", "reacquired") for r in rows)
    _text_block(img, [(f"#{frame_no}  {len(rows)} targets, {n_ok} ok", None)], True, 0.45)  # tags drawn over it
    for r in rows:
        col = target_colour(r["id"])
        ok = r["status"] in ("ok", "init", "clipped", "reacquired")
        p0, p1 = (s(r["x"]), s(r["y"])), (s(r["x"] + r["w"]) - 1, s(r["y"] + r["h"]) - 1)
        cv2.rectangle(img, p0, p1, col, 2 if ok else 1)
        conf = r.get("confidence")
        tag = f"{r['id']} {str(r['status']).upper()}" + (f" {conf:.2f}" if conf is not None and math.isfinite(conf)
                                                          else "")
        (tw, th), base = cv2.getTextSize(tag, _FONT, fs, 1)
        x0 = min(max(p0[0], 0), max(img.shape[1] - tw - 2, 0))
        y0 = p0[1] - 3 if p0[1] - th - base - 3 >= 0 else min(p1[1] + th + 3, img.shape[0] - base - 1)
        cv2.rectangle(img, (x0, y0 - th - 2), (x0 + tw + 2, y0 + base - 1), (0, 0, 0), -1)
        cv2.putText(img, tag, (x0 + 1, y0 - 1), _FONT, fs, col, 1, cv2.LINE_AA)
    return img


# --------------------------------------------------------------------------- tracking
def _row(i: int, label: int, tid: int, res: Any, box: Box, status: str, confidence: bool) -> dict[str, Any]:
    from .cli import CONFIDENCE_DECIMALS, POSITION_DECIMALS
    cx, cy = getattr(res, "centre", None) or box_centre_index(box)
    g = lambda k: float(getattr(res, k, math.nan))  # noqa: E731
    r = lambda v: round(float(v), POSITION_DECIMALS)  # noqa: E731
    conf = round(g("confidence"), CONFIDENCE_DECIMALS) if confidence and res is not None else math.nan
    return {"frame": i, "id": label, "target_id": tid, "x": r(box.x), "y": r(box.y), "w": r(box.w),
            "h": r(box.h), "cx": r(cx), "cy": r(cy), "rho_c": r(g("rho_c")), "rho_e": r(g("rho_e")),
            "alpha_c": r(g("alpha_c")), "confidence": conf, "status": status}


def track_multi_frames(harness: Any, frames: Iterable[np.ndarray | None], inits: list[tuple[int, int, Box]],
                       out_dir: Path, fps: float = 30.0, ends: dict[int, int] | None = None,
                       gt_rows: np.ndarray | None = None, confidence: bool = False, show: bool = False,
                       max_frames: int | None = None, source: VideoSource | None = None,
                       progress: bool = False) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Track several targets through ``frames``; write results.csv (MOT), results.json and overlay.mp4.

    Parameters
    ----------
    harness
        :func:`mstrack.eval.multi.make_multi`'s (a MultiTracker, or one baseline per target).
    inits : list of (frame, label, box)
        Each target's first frame (0-based), its label (the MOT id written to results.csv) and box.
    ends : dict, optional
        label -> last frame: the target is removed after it (default: tracked to the end).
    gt_rows : ndarray (M, 6), optional
        Ground truth ``(frame, id, x, y, w, h)`` (0-based) drawn in white.

    Returns ``(rows, info)``: one row per target per frame (``frame, id, target_id, x, y, w, h, cx, cy,
    rho_c, rho_e, alpha_c, confidence, status``), and ``info`` (``frames``, ``video``, ``fps`` =
    target updates per second, ``refused``: label -> reason, ``targets``).  A refused add
    (:class:`mstrack.track.multi.CapacityError`) or a box a tracker cannot start from is reported in
    ``refused`` and tracking goes on; an unreadable frame or a FrameError gives every live target
    status "error" with its previous box."""
    from tqdm import tqdm

    from .cli import _Display
    from .eval.evaluate import frame_error_types, result_status, to_box
    from .track.multi import CapacityError

    bad_frame = frame_error_types()
    out_dir.mkdir(parents=True, exist_ok=True)
    by_frame: dict[int, list[tuple[int, Box]]] = {}
    for f, label, box in inits:
        by_frame.setdefault(f, []).append((label, box))
    labels = [lab for _, lab, _ in inits]
    if len(set(labels)) != len(labels):
        raise ValueError(f"two targets with one id in {sorted(labels)}")
    ends = ends or {}
    rows: list[dict[str, Any]] = []
    live: dict[int, int] = {}   # label -> harness id
    added: set[int] = set()
    last: dict[int, dict[str, Any]] = {}
    refused: dict[int, str] = {}
    writer, video_path, size = None, None, (0, 0)
    display = _Display(show)
    t_upd, n_upd, n = 0.0, 0, 0
    try:
        for i, frame in enumerate(tqdm(frames, desc="track", disable=not progress, unit="f", dynamic_ncols=True)):
            if max_frames is not None and i >= max_frames:
                break
            n = i + 1
            for lab in [lab for lab in live if ends.get(lab, 1 << 62) < i]:
                harness.remove(live.pop(lab))
            if i == 0 and frame is None:
                err = source.errors.get(0) if source is not None else None
                if err is not None:
                    raise DataError(f"frame 0 is unreadable ({err.reason})", err.path)
                raise DataError("frame 0 is unreadable", getattr(source, "path", out_dir))
            if i == 0:
                size = (frame.shape[1], frame.shape[0])  # type: ignore[union-attr]
            now: list[dict[str, Any]] = []
            if live:
                results = None
                if frame is not None:
                    t0 = time.perf_counter()
                    try:
                        results = dict(harness.update(frame))
                    except bad_frame:
                        results = None
                    t_upd += time.perf_counter() - t0
                    n_upd += len(live)
                for lab, tid in live.items():
                    if results is None:
                        p = last[lab]
                        row = _row(i, lab, tid, None, Box(p["x"], p["y"], p["w"], p["h"]), Status.ERROR.value, False)
                        row.update(cx=p["cx"], cy=p["cy"])
                    else:
                        res = results[tid]
                        row = _row(i, lab, tid, res, to_box(res), result_status(res), confidence)
                    now.append(row)
            for lab, box in by_frame.get(i, []):
                if frame is None:
                    refused[lab] = f"frame {i} is unreadable"
                    continue
                try:
                    tid, res = harness.add(frame, box)
                except (CapacityError, ValueError) as exc:
                    refused[lab] = f"frame {i}: {exc}"
                    continue
                live[lab] = tid
                added.add(lab)
                now.append(_row(i, lab, tid, res, to_box(res), result_status(res), confidence))
            now.sort(key=lambda r: r["id"])
            for r in now:
                last[r["id"]] = r
            rows += now
            if frame is None or frame.ndim != 3 or (frame.shape[1], frame.shape[0]) != size:
                import cv2
                canvas = np.zeros((size[1], size[0], 3), np.uint8) if frame is None or frame.ndim != 3 \
                    else cv2.resize(frame, size)
            else:
                canvas = frame
            gt = None
            if gt_rows is not None:
                sel = gt_rows[gt_rows[:, 0] == i]
                gt = {int(r[1]): Box.of(r[2:6]) for r in sel}
            img = draw_multi_overlay(canvas, i, now, gt)
            if writer is None:
                writer, video_path = open_video_writer(out_dir / "overlay.mp4", fps, (img.shape[1], img.shape[0]))
            writer.write(img)
            display.show(img)
    finally:
        if writer is not None:
            writer.release()
        display.close()
    write_mot_csv(out_dir / "results.csv", rows)
    info: dict[str, Any] = {"frames": n, "video": str(video_path), "fps": n_upd / t_upd if t_upd > 0 else math.nan,
                            "targets": {str(lab): {"first_frame": f, "init_box": list(b.as_tuple())}
                                        for f, lab, b in inits if lab in added},
                            "refused": {str(k): v for k, v in refused.items()}}
    if source is not None:
        info["source"] = {"path": str(source.path), "kind": source.kind, "frames_decoded": source.decoded,
                          "truncated": source.truncated}
        info["frame_errors"] = {str(i): str(e) for i, e in source.errors.items() if i < n}
    clean = [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in rows]
    (out_dir / "results.json").write_text(json.dumps({
        **info, "box_convention": "0-based x,y,w,h; cx,cy pixel-index centre; id = the target's label "
                                  "(MOT id of --init, else 1.. in --box order), target_id = its MultiTracker slot",
        "results_csv": "MOT format frame,id,x,y,w,h,conf,-1,-1,-1 (1-based frame, x, y) of the results that are ok",
        "frames_data": clean}, indent=1) + "\n")
    return rows, info


def write_mot_csv(path: Path, rows: list[dict[str, Any]]) -> Path:
    """MOT-format results (``frame,id,x,y,w,h,conf,-1,-1,-1``, 1-based frame and x, y, no header) of
    the rows whose status is ok (a box the tracker vouches for: what MOT tools score); conf = the
    confidence (1 for trackers without one)."""
    from .io.mot import write_mot_gt
    ok = ("ok", "init", "clipped", "reacquired")
    sel = [(r["frame"], r["id"], r["x"], r["y"], r["w"], r["h"],
            r["confidence"] if r["confidence"] is not None and math.isfinite(r["confidence"]) else 1.0)
           for r in rows if r["status"] in ok]
    return write_mot_gt(path, np.asarray(sel, dtype=np.float64).reshape(-1, 7))


def cmd_track_multi(args: argparse.Namespace, boxes: list[Box], init: str | None) -> int:
    """``mstrack track`` with several ``--box`` or ``--init`` (or a MOT sequence folder)."""
    from .cli import _fmt, _warn, check_out_dir, reports_confidence, resolve_tracker
    from .eval.multi import make_multi
    from .io.mot import is_mot_dir, load_mot_sequence

    src_path = Path(args.source)
    gt_rows = None
    if is_mot_dir(src_path):
        seq = load_mot_sequence(src_path)
        src = VideoSource(seq.img_files[0].parent)
        gt_rows = seq.rows
        if not boxes and init is None:
            init = str(src_path / "gt.txt")
    else:
        src = VideoSource(src_path)
    inits = [(0, k + 1, b) for k, b in enumerate(boxes)]  # --box targets: labels 1.. in order, frame 0
    if init is not None:
        file_inits = read_init(init)  # labels = the file's ids; --box targets get labels after them
        top = max(lab for _, lab, _ in file_inits)
        inits = file_inits + [(f, top + k + 1, b) for k, (f, _, b) in enumerate(inits)]
    if not inits:
        raise ValueError("--box x,y,w,h (one or more) or --init gt.txt is required")
    out = Path(args.out) if args.out else Path("out/track") / src_path.resolve().name
    check_out_dir(out)
    name = resolve_tracker(args.tracker, args.preset)
    harness = make_multi(name, args.model)
    conf = reports_confidence(getattr(harness, "mt", None))
    rows, info = track_multi_frames(harness, src.frames(on_bad="none"), inits, out, fps=src.fps, gt_rows=gt_rows,
                                    confidence=conf, show=args.show, max_frames=args.max_frames, source=src,
                                    progress=not args.quiet and sys.stderr.isatty())
    for i, err in info["frame_errors"].items():
        _warn(f"frame {i}: {err}")
    for lab, why in info["refused"].items():
        _warn(f"target {lab} not added: {why}")
    if src.truncated:
        _warn(f"{src.path}: {src.truncated}")
    n_tg = len(info["targets"])
    print(f"{info['frames']} frames, {n_tg} targets ({len(info['refused'])} refused), "
          f"{_fmt(info['fps'], 1)} target updates/s (update only)"
          + (f"; VIDEO TRUNCATED: {src.truncated}" if src.truncated else ""))
    print(f"wrote {out / 'results.csv'} (MOT format), {out / 'results.json'}, {info['video']}")
    return 0


# --------------------------------------------------------------------------- eval
def cmd_eval_mot(args: argparse.Namespace) -> int:
    """``mstrack eval`` on a MOT sequence folder or a folder of them."""
    from .cli import _csv_list, _fmt, _print_table, _warn, check_out_dir
    from .eval.evaluate import tracker_names
    from .eval.multi import evaluate_mot, write_report_mot
    from .io.mot import load_mot_dataset

    names = _csv_list(args.trackers) or tracker_names()
    unknown = [n for n in names if n not in tracker_names()]
    if unknown:
        raise ValueError(f"unknown tracker(s) {', '.join(unknown)}; known: {', '.join(tracker_names())}")
    if args.jobs > 1 or args.scheduler is not None:
        _warn("--jobs / --scheduler: the MOT evaluation runs in this process")
    check_out_dir(args.out)
    seqs = load_mot_dataset(args.dataset, _csv_list(args.sequences))
    ev = evaluate_mot(seqs, names, args.out, model=args.model, force=args.force, max_frames=args.max_frames,
                      progress=not args.quiet and sys.stderr.isatty())
    for s, per in ev.failed.items():
        for t, reason in per.items():
            _warn(f"{t} on {s} failed, sequence left out of the scores: {reason}")
    paths = write_report_mot(ev, args.out, command=args.command_line)
    order = sorted(ev.trackers, key=lambda t: -ev.overall[t].mot.get("HOTA", -1.0))
    _print_table(["tracker", "AUC", "P@20", "HOTA", "MOTA", "IDF1", "IDSW", "upd/s"],
                 [[t, _fmt(ev.overall[t].otb.auc), _fmt(ev.overall[t].otb.precision20),
                   _fmt(ev.overall[t].mot.get("HOTA")), _fmt(ev.overall[t].mot.get("MOTA")),
                   _fmt(ev.overall[t].mot.get("IDF1")), str(int(ev.overall[t].mot.get("IDSW", 0))),
                   _fmt(ev.fps[t], 1)] for t in order])
    if ev.failed:
        print(f"{len(ev.failed)} of {len(seqs)} sequences failed: {', '.join(ev.failed)} (see the report)")
    print(f"report: {paths['md']}")
    return 0 if ev.sequences else 1


# --------------------------------------------------------------------------- bench
def bench_mot_fps(harness: Any, frames: list[np.ndarray], tracks: list[tuple[int, int, Box]]) -> float:
    """Target updates per second of ``harness`` over preloaded ``frames``: each target ``(first, last,
    box)`` added on its first frame and removed after its last (as ``mstrack eval``); update() only."""
    live: dict[int, tuple[int, int]] = {}
    total, n = 0.0, 0
    for i, f in enumerate(frames):
        for k in [k for k, (_, last) in live.items() if last < i]:
            harness.remove(live.pop(k)[0])
        if live:
            t0 = time.perf_counter()
            harness.update(f)
            total += time.perf_counter() - t0
            n += len(live)
        for k, (first, last, box) in enumerate(tracks):
            if first == i:
                live[k] = (harness.add(f, box)[0], last)
    return n / total if total > 0 else math.nan


def cmd_bench_mot(args: argparse.Namespace) -> int:
    """``mstrack bench MOT_DIR``: target updates per second of the mstrack MultiTracker and of one
    OpenCV CamShift per target, on the same frames and targets (the eval protocol)."""
    from .cli import _csv_list, _fmt, _print_table
    from .eval.evaluate import run_label
    from .eval.multi import make_multi
    from .io.mot import load_mot_dataset

    models = ["float", "fixed"] if args.model == "both" else [args.model]
    runs = [(run_label(args.tracker, m), args.tracker, m) for m in models] + \
           [("opencv-camshift", "opencv-camshift", "float")]
    header = ["sequence", "frames", "targets", "size", *[r[0] + " upd/s" for r in runs],
              *[f"{r[0]}/camshift" for r in runs[:-1]]]
    rows, tot = [], {r[0]: [0.0, 0.0] for r in runs}
    for s in load_mot_dataset(args.dataset, _csv_list(args.sequences)):
        n = min(len(s), args.frames)
        frames = [s.frame(i) for i in range(n)]
        tracks = [(t.first, min(t.last, n - 1), Box.of(t.boxes[0])) for t in s.tracks.values() if t.first < n]
        updates = sum(min(t.last, n - 1) - t.first for t in s.tracks.values() if t.first < n)
        fps = {}
        for label, name, m in runs:
            fps[label] = bench_mot_fps(make_multi(name, m), frames, tracks)
            tot[label][0] += updates
            tot[label][1] += updates / fps[label] if fps[label] > 0 else 0.0
        cam = fps["opencv-camshift"]
        rows.append([s.name, str(n), str(len(tracks)), f"{frames[0].shape[1]}x{frames[0].shape[0]}",
                     *[_fmt(fps[r[0]], 1) for r in runs], *[_fmt(fps[r[0]] / cam, 3) for r in runs[:-1]]])
    all_fps = {k: (u / t if t > 0 else math.nan) for k, (u, t) in tot.items()}
    if len(rows) > 1:
        rows.append(["all", str(sum(int(r[1]) for r in rows)), str(sum(int(r[2]) for r in rows)), "",
                     *[_fmt(all_fps[r[0]], 1) for r in runs],
                     *[_fmt(all_fps[r[0]] / all_fps["opencv-camshift"], 3) for r in runs[:-1]]])
    _print_table(header, rows)
    if args.write_docs:
        from .versions import PYTHON_TOOLS, tools_line
        doc = Path(args.docs_file if args.docs_file != "docs/bench.md" else "docs/bench_multi.md")
        md = ["# mstrack multi-target speed benchmark", "",
              f"Command: `{args.command_line}`", "",
              f"Date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M UTC}; machine: {platform.machine()}, "
              f"{os.cpu_count()} cores, Python {platform.python_version()}.", "",
              tools_line(PYTHON_TOOLS), "",
              "upd/s = target updates per second: the time in update() of the multi-tracker (mstrack: one "
              "`mstrack.MultiTracker`; CamShift: one OpenCV CamShift per target, the OpenCV tutorial's) over "
              "the number of target updates, on frames preloaded in memory; each ground-truth target is added on "
              "its first frame and removed after its last, as `mstrack eval` does (init excluded).  Each CamShift "
              "converts the whole frame to HSV and back-projects it on every update (OpenCV's tutorial recipe, "
              "mstrack/eval/baselines.py), so its cost grows with the frame; mstrack's with the target's search "
              "region.  A benchmark, not a timed test.", "",
              "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        md += ["| " + " | ".join(r) + " |" for r in rows]
        doc.parent.mkdir(parents=True, exist_ok=True)
        doc.write_text("\n".join(md) + "\n")
        print(f"wrote {doc}")
    return 0


# --------------------------------------------------------------------------- demo
def demo_multi(name: str, model: str, out: Path, n_frames: int = 60) -> dict[str, Any]:
    """Track the targets of a generated scene (:func:`mstrack.io.synthetic.make_multi_scene`: four
    targets, two entering late / leaving early) with the eval protocol; per-target AUC and, when
    TrackEval is installed, HOTA / MOTA / IDF1.  Writes ``out`` (results.csv, results.json, overlay)."""
    from .eval.metrics import score
    from .eval.multi import make_multi
    from .io.synthetic import make_multi_scene

    n = max(int(n_frames), 8)
    spans = [(0, n), (0, n), (n // 4, n), (0, 3 * n // 4)]
    frames, gt = make_multi_scene(n, 320, 240, n_targets=4, seed=5, spans=spans)
    harness = make_multi(name, model)
    ids = [int(v) for v in np.unique(gt[:, 1])]
    inits = [(int(gt[gt[:, 1] == k][0, 0]), k, Box.of(gt[gt[:, 1] == k][0, 2:6])) for k in ids]
    ends = {k: int(gt[gt[:, 1] == k][-1, 0]) for k in ids}
    from .cli import reports_confidence
    rows, info = track_multi_frames(harness, frames, inits, out, fps=25.0, ends=ends, gt_rows=gt,
                                    confidence=reports_confidence(getattr(harness, "mt", None)))
    aucs = {}
    for k in ids:
        g = gt[gt[:, 1] == k]
        p = np.array([[r["x"], r["y"], r["w"], r["h"]] for r in rows if r["id"] == k])
        aucs[k] = score(p, g[:, 2:6]).auc
    summary: dict[str, Any] = {"frames": n, "targets": len(ids), "auc_per_target": aucs,
                               "mean_auc": float(np.mean(list(aucs.values()))), "fps": info["fps"],
                               "video": info["video"]}
    try:
        from .eval.multi import mot_data, mot_metrics, mot_summary
        ok = ("ok", "init", "clipped", "reacquired")
        hyp = np.array([[r["frame"], r["id"], r["x"], r["y"], r["w"], r["h"]] for r in rows if r["status"] in ok])
        summary["mot"] = mot_summary(mot_metrics(mot_data(gt, hyp, n, "synthetic-multi")))
    except ImportError:
        summary["mot"] = None
    return summary
