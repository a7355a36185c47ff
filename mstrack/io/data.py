"""Sequence and video readers.

Boxes follow the convention of :mod:`mstrack.track.types` (0-based ``x, y, w, h``).
OTB ground truth is 1-based, VOT ground truth 0-based; :func:`load_sequence`
converts both to 0-based.

Frames are read lazily from disk (``cv2.imread``), one at a time, as BGR
``uint8`` arrays of shape ``(H, W, 3)`` (grayscale JPEGs come back with three
identical channels).

Ground-truth / image count mismatch: a sequence is cut to the shorter of the
two, with a :class:`DataWarning`; pass ``strict=True`` to get a
:class:`DataError` instead.

Bad input (each raises :class:`DataError` naming the file, unless said otherwise):

* a blank line in the middle of a ground-truth file is a missing annotation
  for that frame (a NaN row, as OTB writes them), so later rows keep their
  frame; blank lines at the end of the file are ignored;
* ``meta.json`` must be a JSON object; ``fps`` a positive number,
  ``gt_coordinate_base`` a number, ``attributes`` a list of strings and
  ``name`` a plain name (no ``/``, ``\\``, ``.`` or ``..``: it names cache files);
* :func:`load_dataset` refuses two sequences with the same name (the same
  name twice in ``names``, or two folders whose meta.json give one name);
* a video (:class:`VideoSource`) that decodes fewer frames than its container
  announces sets :attr:`VideoSource.truncated` (a message) after iterating.
"""
from __future__ import annotations

import json
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import cv2
import numpy as np

from ..track.types import Box

IMAGE_EXTS = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".ppm", ".pgm")
VIDEO_EXTS = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".mpg", ".mpeg", ".webm")
GT_NAMES = ("groundtruth_rect.txt", "groundtruth.txt")


class DataError(ValueError):
    """A data file or folder is missing, empty or unreadable.

    Attributes
    ----------
    path : Path
        The offending file or folder.
    reason : str
        The message without the path.
    """

    def __init__(self, message: str, path: str | Path) -> None:
        self.path = Path(path)
        self.reason = message
        super().__init__(f"{message}: {self.path}")


class DataWarning(UserWarning):
    """Recoverable data problem (e.g. ground truth and image counts differ)."""


class FrameFiles:
    """Frames read lazily from a list of image files ``img_files`` (:class:`Sequence`,
    :class:`mstrack.io.mot.MotSequence`)."""

    img_files: list[Path]

    def __len__(self) -> int:
        return len(self.img_files)

    def frame(self, i: int) -> np.ndarray:
        """Read frame ``i`` (BGR uint8, shape (H, W, 3)); raises DataError if unreadable."""
        return read_image(self.img_files[i])

    def frames(self, max_frames: int | None = None) -> Iterator[np.ndarray]:
        """Iterate over the frames lazily (one image in memory at a time)."""
        n = len(self) if max_frames is None else min(len(self), max_frames)
        for i in range(n):
            yield self.frame(i)


@dataclass
class Sequence(FrameFiles):
    """An annotated image sequence.

    Attributes
    ----------
    name : str
        Sequence name (folder name unless meta.json says otherwise).
    img_files : list of Path
        Frame files in order, length N.
    gt : ndarray, shape (N, 4), float64
        Ground-truth boxes ``(x, y, w, h)``, 0-based pixels; rows may be NaN
        (target absent).
    attributes : list of str
        Normalised attribute codes (see :func:`normalise_attribute`).
    fps : float or None
        Frame-rate hint for writing videos (from meta.json ``fps``, else None).
    meta : dict
        The raw meta.json content (empty if there is none).
    path : Path
        The sequence folder.
    """

    name: str
    img_files: list[Path]
    gt: np.ndarray
    attributes: list[str] = field(default_factory=list)
    fps: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    path: Path = Path(".")

    def __iter__(self) -> Iterator[np.ndarray]:
        return self.frames()

    def init_box(self) -> Box:
        """Ground-truth box of frame 0."""
        return Box.of(self.gt[0])


def read_image(path: str | Path) -> np.ndarray:
    """Read one image as BGR uint8 ``(H, W, 3)``; raise :class:`DataError` if unreadable."""
    p = Path(path)
    if not p.is_file():
        raise DataError("image file not found", p)
    img = cv2.imread(str(p), cv2.IMREAD_COLOR)
    if img is None or img.size == 0:
        raise DataError("unreadable or corrupt image", p)
    return img


def _natural_key(p: Path) -> list[Any]:
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", p.name)]


def list_images(folder: str | Path) -> list[Path]:
    """Image files of ``folder`` (not recursive), in natural sort order."""
    d = Path(folder)
    if not d.is_dir():
        raise DataError("image folder not found", d)
    files = [p for p in d.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_EXTS]
    return sorted(files, key=_natural_key)


def parse_gt(path: str | Path) -> np.ndarray:
    """Parse a ground-truth text file without changing its coordinate base.

    Values may be separated by commas, tabs or spaces; ``NaN`` is accepted.
    Lines of 8 values (VOT polygons ``x1,y1,...,x4,y4``) become their
    axis-aligned min/max box.  A blank line is a missing annotation (a NaN
    row, so later lines keep their frame number); blank lines at the end of
    the file are dropped.

    Returns
    -------
    ndarray, shape (N, 4), float64
        ``(x, y, w, h)`` per line, in the file's own coordinate base.
    """
    p = Path(path)
    if not p.is_file():
        raise DataError("ground-truth file not found", p)
    rows: list[list[float]] = []
    lines = p.read_text().splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    for lineno, line in enumerate(lines, start=1):
        s = line.strip()
        if not s:
            rows.append([float("nan")] * 4)
            continue
        try:
            vals = [float(t) for t in re.split(r"[,\s;]+", s) if t]
        except ValueError as exc:
            raise DataError(f"line {lineno}: not numbers ({s!r})", p) from exc
        if len(vals) == 4:
            rows.append(vals)
        elif len(vals) == 8:
            xs, ys = np.asarray(vals[0::2]), np.asarray(vals[1::2])
            x0, y0 = xs.min(), ys.min()
            rows.append([x0, y0, xs.max() - x0, ys.max() - y0])
        else:
            raise DataError(f"line {lineno}: expected 4 or 8 values, got {len(vals)}", p)
    if not rows or not np.isfinite(np.asarray(rows)).any():
        raise DataError("ground-truth file is empty" if not rows else "ground-truth file has no box", p)
    return np.asarray(rows, dtype=np.float64)


OTB_ATTRIBUTES = {
    "IV": "illumination variation", "SV": "scale variation", "OCC": "occlusion",
    "DEF": "deformation", "MB": "motion blur", "FM": "fast motion",
    "IPR": "in-plane rotation", "OPR": "out-of-plane rotation", "OV": "out of view",
    "BC": "background clutter", "LR": "low resolution",
}
_OTB_BY_NAME = {v: k for k, v in OTB_ATTRIBUTES.items()}


def normalise_attribute(attr: str) -> str:
    """Normalise an attribute string to a short code.

    The parenthesised remark is dropped and OTB codes / OTB long names map to
    the OTB code; otherwise the first token is used (as VOT tags such as
    ``"DEF (plastic bag)"`` put the code first).

    Examples: ``"DEF (plastic bag)" -> "DEF"``, ``"background clutter" -> "BC"``,
    ``"camera motion" -> "camera"``.
    """
    s = re.sub(r"\(.*?\)", " ", attr).strip()
    low = " ".join(s.lower().replace("-", " ").split())
    if low in _OTB_BY_NAME:
        return _OTB_BY_NAME[low]
    tok = s.split()[0] if s.split() else attr.strip()
    return tok.upper() if tok.upper() in OTB_ATTRIBUTES else tok


def _is_sequence_dir(d: Path) -> bool:
    return d.is_dir() and any((d / g).is_file() for g in GT_NAMES)


def _find_image_dir(d: Path) -> Path:
    for sub in ("img", "color"):
        if (d / sub).is_dir():
            return d / sub
    return d


def _meta_number(meta: dict[str, Any], key: str, path: Path, default: float | None,
                 positive: bool = False) -> float | None:
    """``meta[key]`` as a finite float (``default`` if absent or null); DataError naming meta.json if not."""
    v = meta.get(key)
    if v is None:
        return default
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or (positive and v <= 0):
        raise DataError(f"meta.json {key!r} must be a {'positive ' if positive else ''}number, got {v!r}", path)
    return float(v)


def _meta_name(meta: dict[str, Any], default: str, path: Path) -> str:
    """The sequence name: a plain file name (it names cache and result files)."""
    v = meta.get("name", default)
    if not isinstance(v, str) or not v.strip() or v in (".", "..") or "/" in v or "\\" in v or "\0" in v:
        raise DataError(f"meta.json 'name' must be a plain name (no '/', '\\', '.' or '..'), got {v!r}", path)
    return v


def load_sequence(path: str | Path, strict: bool = False) -> Sequence:
    """Load an OTB or VOT sequence folder.

    OTB layout: ``img/`` + ``groundtruth_rect.txt`` (1-based unless meta.json
    says ``gt_coordinate_base: 0``).  VOT layout: ``groundtruth.txt`` (boxes or
    8-value polygons, 0-based) with images in ``img/``, ``color/`` or the
    folder itself.  ``meta.json`` (optional) gives ``format``,
    ``gt_coordinate_base``, ``attributes``, ``fps``.

    Parameters
    ----------
    path : str or Path
        Sequence folder.
    strict : bool
        Raise :class:`DataError` when the image and ground-truth counts
        differ, instead of cutting to the shorter one with a warning.

    Raises
    ------
    DataError
        Missing folder, no images, no or malformed ground truth, bad meta.json.
    """
    d = Path(path)
    if not d.is_dir():
        raise DataError("sequence folder not found", d)
    meta: dict[str, Any] = {}
    if (d / "meta.json").is_file():
        try:
            meta = json.loads((d / "meta.json").read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise DataError(f"invalid meta.json ({exc})", d / "meta.json") from exc
        if not isinstance(meta, dict):
            raise DataError(f"meta.json must be a JSON object, got {type(meta).__name__}", d / "meta.json")
        attrs = meta.get("attributes", [])
        if not isinstance(attrs, list) or not all(isinstance(a, str) for a in attrs):
            raise DataError(f"meta.json 'attributes' must be a list of strings, got {attrs!r}", d / "meta.json")
    gt_file = next((d / g for g in GT_NAMES if (d / g).is_file()), None)
    if gt_file is None:
        raise DataError(f"no ground truth ({' or '.join(GT_NAMES)})", d)
    fmt = meta.get("format", "vot" if gt_file.name == "groundtruth.txt" else "otb")
    base = _meta_number(meta, "gt_coordinate_base", d / "meta.json", 0.0 if fmt == "vot" else 1.0)
    fps = _meta_number(meta, "fps", d / "meta.json", None, positive=True)
    name = _meta_name(meta, d.name, d / "meta.json")
    img_dir = _find_image_dir(d)
    files = list_images(img_dir)
    if not files:
        raise DataError("no images", img_dir)
    gt = parse_gt(gt_file)
    gt[:, :2] -= base
    if len(gt) != len(files):
        msg = f"{len(files)} images but {len(gt)} ground-truth lines"
        if strict:
            raise DataError(msg, d)
        n = min(len(gt), len(files))
        warnings.warn(f"{d}: {msg}; using the first {n} frames", DataWarning, stacklevel=2)
        gt, files = gt[:n], files[:n]
    return Sequence(
        name=name,
        img_files=files,
        gt=gt,
        attributes=[normalise_attribute(a) for a in meta.get("attributes", [])],
        fps=fps,
        meta=meta,
        path=d,
    )


def load_dataset(path: str | Path, names: list[str] | None = None, strict: bool = False) -> list[Sequence]:
    """Load every sequence subfolder of ``path`` (sorted by name).

    Parameters
    ----------
    path : str or Path
        Dataset folder, one subfolder per sequence.
    names : list of str, optional
        Only these sequences (folder names), in this order.  A name that is
        no folder matches the one folder whose name is the same but for case
        (``crossing`` -> ``Crossing``); unknown or ambiguous names raise
        :class:`DataError` listing the sequences of the dataset.
    """
    d = Path(path)
    if not d.is_dir():
        raise DataError("dataset folder not found", d)
    if names:
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise DataError(f"sequence {', '.join(twice)} given more than once", d)
        avail = sorted((p.name for p in d.iterdir() if _is_sequence_dir(p)), key=str.lower)
        resolved: list[str] = []
        missing: list[str] = []
        for n in names:
            if _is_sequence_dir(d / n):
                resolved.append(n)
                continue
            cands = [a for a in avail if a.lower() == n.lower()]
            if len(cands) == 1:
                resolved.append(cands[0])
            else:
                missing.append(n + (f" (ambiguous: {', '.join(cands)})" if cands else ""))
        if missing:
            raise DataError(f"no sequence named {', '.join(missing)}; the sequences are: "
                            f"{', '.join(avail) or '(none)'}", d)
        twice = sorted({n for n in resolved if resolved.count(n) > 1})
        if twice:
            raise DataError(f"sequence {', '.join(twice)} given more than once", d)
        seqs = [load_sequence(d / n, strict=strict) for n in resolved]
    else:
        seqs = [load_sequence(p, strict=strict) for p in sorted(d.iterdir()) if _is_sequence_dir(p)]
    if not seqs:
        raise DataError("no sequence folders (with groundtruth_rect.txt / groundtruth.txt)", d)
    return unique_names(seqs, d)


def unique_names(seqs: list[Any], root: Path) -> list[Any]:
    """``seqs`` (sequences with ``name`` and ``path``) unchanged, or DataError if two share a name."""
    seen: dict[str, Path] = {}
    for s in seqs:
        if s.name in seen:
            raise DataError(f"two sequences named {s.name!r} ({seen[s.name].name}/ and {s.path.name}/; "
                            "see their meta.json 'name')", root)
        seen[s.name] = s.path
    return seqs


class VideoSource:
    """Iterate BGR frames from a video file, an image folder or a sequence folder.

    Parameters
    ----------
    path : str or Path
        Video file (anything ``cv2.VideoCapture`` opens, e.g. mp4/avi), image
        folder, or sequence folder (OTB/VOT layout; then :attr:`sequence` is
        set and its ground truth is available).

    Attributes
    ----------
    kind : {"video", "images", "sequence"}
    fps : float
        Frame rate from the container, the meta.json hint, or 30.
    sequence : Sequence or None
    decoded : int
        Frames yielded by the last :meth:`frames` iteration so far.
    truncated : str or None
        Set when a video ended before the frame count of its container (cut
        or garbled file): e.g. "decoded 7 of 15 frames ...".
    errors : dict
        Frame index -> :class:`DataError` of each unreadable image met by
        :meth:`frames` (``on_bad`` "none" or "skip").

    Raises
    ------
    DataError
        Missing path, folder without images, video that cannot be opened or
        has no frame.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.sequence: Sequence | None = None
        self._files: list[Path] = []
        self.decoded = 0
        self.truncated: str | None = None
        self.errors: dict[int, DataError] = {}
        if self.path.is_dir():
            if _is_sequence_dir(self.path):
                self.kind = "sequence"
                self.sequence = load_sequence(self.path)
                self._files = self.sequence.img_files
                self.fps = self.sequence.fps or 30.0
            else:
                self.kind = "images"
                self._files = list_images(self.path)
                if not self._files:
                    raise DataError("no images", self.path)
                self.fps = 30.0
        elif self.path.is_file():
            self.kind = "video"
            cap = cv2.VideoCapture(str(self.path))
            try:
                if not cap.isOpened():
                    raise DataError("cannot open video", self.path)
                ok, frame = cap.read()
                if not ok or frame is None:
                    raise DataError("video has no readable frame", self.path)
                fps = cap.get(cv2.CAP_PROP_FPS)
                self.fps = float(fps) if fps and np.isfinite(fps) and 0 < fps < 1000 else 30.0
            finally:
                cap.release()
        else:
            raise DataError("source not found", self.path)

    def __len__(self) -> int:
        """Number of frames (for videos: the container's count, may be approximate)."""
        if self.kind != "video":
            return len(self._files)
        cap = cv2.VideoCapture(str(self.path))
        try:
            return int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        finally:
            cap.release()

    def frames(self, on_bad: str = "raise") -> Iterator[np.ndarray | None]:
        """Iterate frames, BGR uint8 ``(H, W, 3)``.

        Parameters
        ----------
        on_bad : {"raise", "none", "skip"}
            For an unreadable image in a folder: raise :class:`DataError`,
            yield ``None`` in its place, or skip it (the error is kept in
            :attr:`errors`).  A video ends at its first undecodable frame; if
            that is before the container's frame count, :attr:`truncated`
            says so (``mstrack track`` warns and records it in results.json).
        """
        if on_bad not in ("raise", "none", "skip"):
            raise ValueError(f"on_bad must be raise, none or skip, not {on_bad!r}")
        self.decoded, self.truncated, self.errors = 0, None, {}
        if self.kind == "video":
            cap = cv2.VideoCapture(str(self.path))
            try:
                expected = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
                while True:
                    ok, frame = cap.read()
                    if not ok or frame is None:
                        if expected > self.decoded:
                            self.truncated = (f"decoded {self.decoded} of {expected} frames (the container "
                                              f"announces {expected}; the file is cut or corrupt after frame "
                                              f"{self.decoded - 1})")
                        return
                    if frame.ndim == 2:
                        frame = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)
                    self.decoded += 1
                    yield frame
            finally:
                cap.release()
        for i, f in enumerate(self._files):
            try:
                img = read_image(f)
            except DataError as exc:
                if on_bad == "raise":
                    raise
                self.errors[i] = exc
                if on_bad == "none":
                    self.decoded += 1
                    yield None
                continue
            self.decoded += 1
            yield img

    def __iter__(self) -> Iterator[np.ndarray | None]:
        return self.frames()


def open_video_writer(path: str | Path, fps: float, size: tuple[int, int]) -> tuple[cv2.VideoWriter, Path]:
    """Open a video writer, falling back from mp4 (``mp4v``) to avi (``MJPG``).

    Parameters
    ----------
    path : str or Path
        Wanted file name; the suffix decides the first codec tried.
    fps : float
        Frames per second.
    size : (width, height)
        Frame size in pixels.

    Returns
    -------
    writer : cv2.VideoWriter
        An opened writer (the caller releases it).
    path : Path
        The file actually written (``.avi`` after a fallback).

    Raises
    ------
    DataError
        If no codec could be opened.
    """
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tries = [(p, "mp4v"), (p.with_suffix(".avi"), "MJPG")] if p.suffix.lower() == ".mp4" \
        else [(p, "MJPG"), (p.with_suffix(".mp4"), "mp4v")]
    for out, codec in tries:
        w = cv2.VideoWriter(str(out), cv2.VideoWriter.fourcc(*codec), float(fps), tuple(int(v) for v in size))
        if w.isOpened():
            return w, out
        w.release()
    raise DataError("cannot open a video writer (tried mp4v and MJPG)", p)
