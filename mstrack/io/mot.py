"""Multi-object sequences in MOTChallenge format (``gt.txt``, ``img/``, ``meta.json``).

Layout (``../shared/data/multi/<name>/``): ``img/000001.jpg ...`` (frame k of ``gt.txt`` is the
k-th image in natural order), ``gt.txt`` with one box per line
``frame,id,x,y,w,h[,conf,class,visibility,...]`` (``frame`` 1-based, ``x, y`` MOTChallenge's 1-based
left / top, fractional values allowed) and an optional ``meta.json`` (``name``, ``fps``,
``gt_coordinate_base``: 1 unless it says 0).  Boxes come back 0-based (:mod:`mstrack.track.types`).
Rows whose ``conf`` (7th value) is 0 are "ignore" annotations in MOTChallenge and are dropped.

Bad input raises :class:`~mstrack.io.data.DataError` naming the file, one line, as the OTB reader
(:mod:`mstrack.io.data`) does: a missing folder, no ``gt.txt`` or no images, a line that is not
numbers, has fewer than 6 values, a frame that is not a positive integer, an id that is not an
integer, a box without positive width and height, the same id twice in one frame, an empty file;
the meta.json checks of :func:`mstrack.io.data.load_sequence`.  Ground truth on frames beyond the
last image is cut with a :class:`~mstrack.io.data.DataWarning` (``strict=True``: DataError).
"""
from __future__ import annotations

import json
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..track.types import Box
from .data import (DataError, DataWarning, FrameFiles, _find_image_dir, _meta_name, _meta_number, list_images,
                   unique_names)

MOT_GT = "gt.txt"


@dataclass
class MotTrack:
    """One target's ground truth: ``frames`` (0-based frame indices, ascending) and ``boxes`` (N, 4)
    0-based ``(x, y, w, h)``.  ``first`` / ``last``: its first and last annotated frame."""

    id: int
    frames: np.ndarray
    boxes: np.ndarray

    @property
    def first(self) -> int:
        return int(self.frames[0])

    @property
    def last(self) -> int:
        return int(self.frames[-1])

    def gt_span(self) -> np.ndarray:
        """Boxes over frames ``first .. last`` (rows of frames without an annotation are NaN)."""
        out = np.full((self.last - self.first + 1, 4), np.nan)
        out[self.frames - self.first] = self.boxes
        return out


@dataclass
class MotSequence(FrameFiles):
    """A multi-object sequence.

    Attributes
    ----------
    name : str
    img_files : list of Path
        Frame files in order.
    rows : ndarray, shape (M, 6), float64
        The ground truth, one row per box: ``(frame, id, x, y, w, h)``, frame 0-based, box 0-based.
    tracks : dict
        Target id -> :class:`MotTrack`, ids ascending.
    fps : float or None
    meta : dict
    path : Path
    """

    name: str
    img_files: list[Path]
    rows: np.ndarray
    tracks: dict[int, MotTrack] = field(default_factory=dict)
    fps: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    path: Path = Path(".")

    @property
    def ids(self) -> list[int]:
        return list(self.tracks)

    def boxes_at(self, i: int) -> dict[int, Box]:
        """Ground-truth boxes of frame ``i``: id -> Box."""
        sel = self.rows[self.rows[:, 0] == i]
        return {int(r[1]): Box.of(r[2:6]) for r in sel}

    def starting_at(self, i: int) -> list[MotTrack]:
        """The targets whose ground truth starts on frame ``i``, ids ascending."""
        return [t for t in self.tracks.values() if t.first == i]


def parse_mot_gt(path: str | Path) -> np.ndarray:
    """Parse a MOTChallenge ``gt.txt`` as written (1-based frames and coordinates).

    Returns an (M, 6) float64 array ``(frame, id, x, y, w, h)``, sorted by frame then id, without
    the rows whose 7th value (conf / "consider") is 0."""
    p = Path(path)
    if not p.is_file():
        raise DataError("ground-truth file not found", p)
    try:
        text = p.read_text()
    except UnicodeDecodeError as exc:
        raise DataError("ground-truth file is not text", p) from exc
    rows: list[list[float]] = []
    seen: dict[tuple[int, int], int] = {}
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s:
            continue
        try:
            vals = [float(t) for t in re.split(r"[,\s;]+", s) if t]
        except ValueError as exc:
            raise DataError(f"line {lineno}: not numbers ({s!r})", p) from exc
        if len(vals) < 6:
            raise DataError(f"line {lineno}: expected frame,id,x,y,w,h[,...] (at least 6 values), got {len(vals)}", p)
        fr, tid, x, y, w, h = vals[:6]
        if not np.isfinite(vals[:6]).all():
            raise DataError(f"line {lineno}: non-finite value ({s!r})", p)
        if fr != int(fr) or fr < 1:
            raise DataError(f"line {lineno}: frame must be a positive integer, got {fr:g}", p)
        if tid != int(tid):
            raise DataError(f"line {lineno}: id must be an integer, got {tid:g}", p)
        if w <= 0 or h <= 0:
            raise DataError(f"line {lineno}: box width and height must be positive, got {w:g} x {h:g}", p)
        key = (int(fr), int(tid))
        if key in seen:
            raise DataError(f"line {lineno}: id {key[1]} twice in frame {key[0]} (also line {seen[key]})", p)
        seen[key] = lineno
        if len(vals) >= 7 and vals[6] == 0:
            continue  # MOTChallenge's "ignore" row
        rows.append([fr, tid, x, y, w, h])
    if not rows:
        raise DataError("ground-truth file is empty" if not seen else "ground-truth file has no box to evaluate", p)
    a = np.asarray(rows, dtype=np.float64)
    return a[np.lexsort((a[:, 1], a[:, 0]))]


def is_mot_dir(path: str | Path) -> bool:
    """True for a MOT sequence folder (it has ``gt.txt``)."""
    return (Path(path) / MOT_GT).is_file()


def is_mot_dataset(path: str | Path) -> bool:
    """True for a MOT sequence folder or a folder of them (a subfolder with ``gt.txt``), and no
    OTB / VOT sequence among them."""
    d = Path(path)
    if is_mot_dir(d):
        return True
    return d.is_dir() and any(is_mot_dir(s) for s in d.iterdir() if s.is_dir())


def _read_meta(d: Path) -> dict[str, Any]:
    f = d / "meta.json"
    if not f.is_file():
        return {}
    try:
        meta = json.loads(f.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DataError(f"invalid meta.json ({exc})", f) from exc
    if not isinstance(meta, dict):
        raise DataError(f"meta.json must be a JSON object, got {type(meta).__name__}", f)
    return meta


def load_mot_sequence(path: str | Path, strict: bool = False) -> MotSequence:
    """Load a MOTChallenge-format sequence folder (``gt.txt``, ``img/``, optional ``meta.json``).

    Raises :class:`DataError` on bad input (module docstring); ground truth beyond the last image
    is cut with a :class:`DataWarning`, or raises with ``strict``."""
    d = Path(path)
    if not d.is_dir():
        raise DataError("sequence folder not found", d)
    meta = _read_meta(d)
    if not is_mot_dir(d):
        raise DataError(f"no ground truth ({MOT_GT})", d)
    base = _meta_number(meta, "gt_coordinate_base", d / "meta.json", 1.0)
    fps = _meta_number(meta, "fps", d / "meta.json", None, positive=True)
    name = _meta_name(meta, d.name, d / "meta.json")
    img_dir = _find_image_dir(d)
    files = list_images(img_dir)
    if not files:
        raise DataError("no images", img_dir)
    rows = parse_mot_gt(d / MOT_GT)
    rows[:, 0] -= 1
    rows[:, 2:4] -= base
    beyond = rows[:, 0] >= len(files)
    if beyond.any():
        msg = f"ground truth up to frame {int(rows[:, 0].max()) + 1} but {len(files)} images"
        if strict:
            raise DataError(msg, d / MOT_GT)
        warnings.warn(f"{d / MOT_GT}: {msg}; the boxes beyond frame {len(files)} are dropped", DataWarning,
                      stacklevel=2)
        rows = rows[~beyond]
        if not len(rows):
            raise DataError(f"{msg}: no box left", d / MOT_GT)
    tracks = {}
    for tid in np.unique(rows[:, 1]).astype(int):
        sel = rows[rows[:, 1] == tid]
        tracks[int(tid)] = MotTrack(int(tid), sel[:, 0].astype(int), sel[:, 2:6].copy())
    return MotSequence(name=name, img_files=files, rows=rows, tracks=tracks, fps=fps, meta=meta, path=d)


def load_mot_dataset(path: str | Path, names: list[str] | None = None, strict: bool = False) -> list[MotSequence]:
    """The MOT sequence folder ``path``, or every MOT sequence subfolder of ``path`` (sorted by name;
    ``names``: only these, in this order).  DataError for unknown names or two sequences with one name."""
    d = Path(path)
    if not d.is_dir():
        raise DataError("dataset folder not found", d)
    if is_mot_dir(d):
        seqs = [load_mot_sequence(d, strict)]
    else:
        avail = sorted((p.name for p in d.iterdir() if is_mot_dir(p)), key=str.lower)
        if names:
            missing = [n for n in names if n not in avail]
            if missing:
                raise DataError(f"no MOT sequence named {', '.join(missing)}; the sequences are: "
                                f"{', '.join(avail) or '(none)'}", d)
            avail = list(dict.fromkeys(names))
        seqs = [load_mot_sequence(d / n, strict) for n in avail]
    if not seqs:
        raise DataError(f"no MOT sequence folders (with {MOT_GT})", d)
    return unique_names(seqs, d)


def write_mot_gt(path: str | Path, rows: np.ndarray | list, base: int = 1) -> Path:
    """Write ``(frame, id, x, y, w, h[, conf])`` rows (0-based frame and box) as a MOTChallenge file:
    ``frame + 1, id, x + base, y + base, w, h, conf, -1, -1, -1`` (conf 1 when not given)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    lines = []
    for r in np.asarray(rows, dtype=np.float64).reshape(-1, np.asarray(rows).shape[-1] if len(rows) else 6):
        conf = r[6] if len(r) > 6 else 1.0
        lines.append(f"{int(r[0]) + 1},{int(r[1])},{_g(r[2] + base)},{_g(r[3] + base)},{_g(r[4])},{_g(r[5])},"
                     f"{_g(conf)},-1,-1,-1")
    p.write_text("".join(line + "\n" for line in lines))
    return p


def _g(v: float) -> str:
    """A number for a MOT file: up to 6 decimals, no trailing zeros (12.5, 3, 0.8125)."""
    s = f"{float(v):.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s
