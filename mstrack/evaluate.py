"""One-pass evaluation (OPE) of trackers over a dataset, OTB style.

Each tracker is initialised on frame 0 with the ground-truth box and updated
on every following frame; frame 0 counts in the scores with the box the
tracker reports from ``init`` (as in OTB).  Speed is measured on ``update()``
only (frame decoding excluded).  Per-sequence results are cached as
``<out>/results/<label>/<sequence>.json`` and reused unless ``force``, or
the frame count, model or tracker code (:func:`tracker_fingerprint`) changed.

Aggregates (:class:`Evaluation`): per sequence, per attribute and overall,
the latter two frame-weighted (the per-frame values of all sequences are
concatenated, as the OTB toolkit does).

Any object with ``init(frame, box)`` and ``update(frame)`` returning a
:class:`~mstrack.types.TrackResult`, a :class:`~mstrack.types.Box` or an
``(x, y, w, h)`` sequence can be run with :func:`run_sequence`.
"""
from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np
from tqdm import tqdm

from . import baselines
from .data import DataError, Sequence
from .metrics import Scores, concat_scores, score, valid_gt
from .types import Box, Status

CACHE_VERSION = 1
MODELS = ("float", "fixed")


def _mstrack(features: str, kernel: str) -> Callable[[str], Any]:
    def make(model: str = "float") -> Any:
        from .tracker import Tracker  # imported late: written separately, may be absent
        return Tracker(model=model, features=features, kernel=kernel)
    make.__doc__ = f"mstrack.Tracker(features={features!r}, kernel={kernel!r})"
    return make


def _baseline(fn: Callable[[], Any]) -> Callable[[str], Any]:
    def make(model: str = "float") -> Any:  # model does not apply to OpenCV trackers
        return fn()
    make.__doc__ = fn.__doc__
    return make


#: Tracker name -> factory ``f(model) -> tracker``.  Add entries here.
TRACKERS: dict[str, Callable[[str], Any]] = {
    "mstrack-fused-flat": _mstrack("fused", "flat"),
    "mstrack-colour-flat": _mstrack("colour", "flat"),
    "mstrack-edge-flat": _mstrack("edge", "flat"),
    "mstrack-fused-epan": _mstrack("fused", "epanechnikov"),
    "mstrack-colour-epan": _mstrack("colour", "epanechnikov"),
    "mstrack-edge-epan": _mstrack("edge", "epanechnikov"),
    "opencv-meanshift": _baseline(baselines.meanshift),
    "opencv-camshift": _baseline(baselines.camshift),
    "opencv-kcf": _baseline(baselines.kcf),
    "opencv-csrt": _baseline(baselines.csrt),
}


def tracker_names() -> list[str]:
    """Registered tracker names."""
    return list(TRACKERS)


def uses_model(name: str) -> bool:
    """True if the tracker ``name`` has a float/fixed model choice (the mstrack ones)."""
    return name.startswith("mstrack-")


def make_tracker(name: str, model: str = "float") -> Any:
    """Build a registered tracker.

    Parameters
    ----------
    name : str
        One of :func:`tracker_names`.
    model : {"float", "fixed"}
        mstrack model (ignored by the OpenCV baselines).
    """
    if name not in TRACKERS:
        raise ValueError(f"unknown tracker {name!r}; known: {', '.join(TRACKERS)}")
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, not {model!r}")
    return TRACKERS[name](model)


def run_label(name: str, model: str = "float") -> str:
    """Label of a run in reports and the cache: ``name``, plus ``@fixed`` for the fixed model."""
    return f"{name}@{model}" if uses_model(name) and model != "float" else name


def to_box(result: Any) -> Box:
    """Box of a tracker's return value (TrackResult-like with ``.box``, Box, or 4-sequence)."""
    if hasattr(result, "box"):
        result = result.box
    return Box.of(result)


def result_status(result: Any) -> str:
    """Status string of a tracker's return value ("ok" if it has none)."""
    st = getattr(result, "status", Status.OK)
    return st.value if isinstance(st, Status) else str(st)


def frame_error_types() -> tuple[type[BaseException], ...]:
    """Exception types meaning "bad frame, go on" (``mstrack.FrameError`` once it exists)."""
    try:
        from .frames import FrameError
    except ImportError:
        return ()
    return (FrameError,)


@dataclass
class SequenceRun:
    """One tracker on one sequence.

    Attributes
    ----------
    tracker : str
        Run label (see :func:`run_label`).
    sequence : str
    boxes : ndarray, shape (N, 4)
        Reported boxes, 0-based ``(x, y, w, h)``; frame 0 is the init box.
    status : list of str, length N
    update_time : float
        Total seconds spent in ``update()`` (N - 1 calls).
    model : str
    """

    tracker: str
    sequence: str
    boxes: np.ndarray
    status: list[str]
    update_time: float
    model: str = "float"

    @property
    def n_frames(self) -> int:
        return len(self.boxes)

    @property
    def fps(self) -> float:
        """Updates per second (NaN if there was no update)."""
        n = self.n_frames - 1
        return n / self.update_time if n > 0 and self.update_time > 0 else float("nan")

    def to_json(self) -> dict[str, Any]:
        return {"version": CACHE_VERSION, "tracker": self.tracker, "sequence": self.sequence,
                "model": self.model, "n_frames": self.n_frames, "fps": self.fps,
                "update_time_s": self.update_time, "boxes": self.boxes.tolist(), "status": self.status}

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> "SequenceRun":
        return cls(d["tracker"], d["sequence"], np.asarray(d["boxes"], dtype=np.float64).reshape(-1, 4),
                   list(d["status"]), float(d["update_time_s"]), d.get("model", "float"))


def run_sequence(tracker: Any, seq: Sequence, max_frames: int | None = None, label: str = "tracker",
                 model: str = "float", progress: bool = False) -> SequenceRun:
    """Run one tracker over one sequence (OPE).

    A bad-frame error (``mstrack.FrameError``) on ``update`` is recorded as
    status ``"error"`` with the previous box; any other exception is re-raised
    as ``RuntimeError`` naming the tracker, sequence and frame.
    """
    n = len(seq) if max_frames is None else min(len(seq), max_frames)
    if not valid_gt(seq.gt[:1])[0]:
        raise DataError("frame 0 ground truth is invalid, cannot initialise", seq.path)
    bad_frame = frame_error_types()
    boxes = np.empty((n, 4), np.float64)
    status: list[str] = []
    where = f"{label} on {seq.name}"
    try:
        res = tracker.init(seq.frame(0), seq.init_box())
        boxes[0] = to_box(res).as_tuple() if res is not None else seq.gt[0]
        status.append(result_status(res) if res is not None else Status.INIT.value)
        total = 0.0
        for i in tqdm(range(1, n), desc=where, leave=False, disable=not progress, unit="f"):
            frame = seq.frame(i)
            t0 = time.perf_counter()
            try:
                res = tracker.update(frame)
            except bad_frame as exc:  # noqa: PERF203
                total += time.perf_counter() - t0
                boxes[i] = boxes[i - 1]
                status.append(Status.ERROR.value)
                continue
            total += time.perf_counter() - t0
            boxes[i] = to_box(res).as_tuple()
            status.append(result_status(res))
    except DataError:
        raise
    except Exception as exc:
        raise RuntimeError(f"{where}, frame {len(status)}: {type(exc).__name__}: {exc}") from exc
    return SequenceRun(label, seq.name, boxes, status, total, model)


def tracker_fingerprint(name: str) -> str:
    """Short hash of the code behind tracker ``name``, stored with cached runs.

    mstrack trackers: the sources of the tracker modules (``tracker``,
    ``float_model``, ``params``, ``frames``, ``types``, ``fixed/``); OpenCV
    baselines: ``baselines.py`` and the OpenCV version.  A cached run whose
    fingerprint differs is recomputed, so editing the tracker invalidates it.
    """
    import hashlib

    import cv2

    pkg = Path(__file__).resolve().parent
    if uses_model(name):
        files = [pkg / f"{m}.py" for m in ("tracker", "float_model", "params", "frames", "types")]
        files += sorted((pkg / "fixed").glob("*.py"))
        extra = ""
    else:
        files, extra = [pkg / "baselines.py"], cv2.__version__
    h = hashlib.sha1(extra.encode())
    for f in files:
        if f.is_file():
            h.update(f.name.encode() + f.read_bytes())
    return h.hexdigest()[:12]


def cache_path(out_dir: str | Path, label: str, seq_name: str) -> Path:
    """``<out>/results/<label>/<seq>.json``."""
    return Path(out_dir) / "results" / label / f"{seq_name}.json"


def load_cached(path: Path, n_frames: int, model: str, fingerprint: str | None = None) -> SequenceRun | None:
    """A cached run if it exists and matches (frame count, model, code fingerprint, cache version); else None."""
    try:
        d = json.loads(path.read_text())
        if d.get("version") != CACHE_VERSION or d.get("n_frames") != n_frames or d.get("model") != model \
                or d.get("fingerprint") != fingerprint:
            return None
        return SequenceRun.from_json(d)
    except (OSError, ValueError, KeyError, TypeError):
        return None


@dataclass
class Evaluation:
    """Results of :func:`evaluate`.

    Attributes
    ----------
    trackers : list of str
        Run labels, in the order run.
    sequences : list of str
    attributes : dict
        Attribute code -> sequence names having it.
    runs : dict
        ``runs[label][seq]`` -> :class:`SequenceRun`.
    per_sequence, per_attribute : dict
        ``[label][seq or attribute]`` -> :class:`~mstrack.metrics.Scores`.
    overall : dict
        ``[label]`` -> frame-weighted :class:`~mstrack.metrics.Scores`.
    fps : dict
        ``[label]`` -> total updates / total update time.
    """

    trackers: list[str]
    sequences: list[str]
    attributes: dict[str, list[str]]
    runs: dict[str, dict[str, SequenceRun]] = field(default_factory=dict)
    per_sequence: dict[str, dict[str, Scores]] = field(default_factory=dict)
    per_attribute: dict[str, dict[str, Scores]] = field(default_factory=dict)
    overall: dict[str, Scores] = field(default_factory=dict)
    fps: dict[str, float] = field(default_factory=dict)
    seq_frames: dict[str, int] = field(default_factory=dict)


def aggregate(runs: dict[str, dict[str, SequenceRun]], sequences: list[Sequence]) -> Evaluation:
    """Score runs against the sequences' ground truth and aggregate them."""
    attrs: dict[str, list[str]] = {}
    for s in sequences:
        for a in dict.fromkeys(s.attributes):
            attrs.setdefault(a, []).append(s.name)
    ev = Evaluation(list(runs), [s.name for s in sequences], dict(sorted(attrs.items())), runs)
    by_name = {s.name: s for s in sequences}
    for label, per in runs.items():
        ev.per_sequence[label] = {name: score(r.boxes, by_name[name].gt[:r.n_frames]) for name, r in per.items()}
        ev.seq_frames.update({name: r.n_frames for name, r in per.items()})
        ev.per_attribute[label] = {a: concat_scores([ev.per_sequence[label][n] for n in names if n in per])
                                   for a, names in ev.attributes.items()}
        ev.overall[label] = concat_scores(list(ev.per_sequence[label].values()))
        n_upd = sum(r.n_frames - 1 for r in per.values())
        t_upd = sum(r.update_time for r in per.values())
        ev.fps[label] = n_upd / t_upd if n_upd > 0 and t_upd > 0 else float("nan")
    return ev


def evaluate(sequences: list[Sequence], trackers: Iterable[str], out_dir: str | Path, model: str = "float",
             force: bool = False, quiet: bool = False, max_frames: int | None = None,
             factory: Callable[[str, str], Any] = make_tracker) -> Evaluation:
    """Run trackers over sequences (OPE), with result caching, and aggregate.

    Parameters
    ----------
    sequences : list of Sequence
    trackers : iterable of str
        Registered names (see :func:`tracker_names`).
    out_dir : str or Path
        Report folder; runs are cached in ``<out_dir>/results/``.
    model : {"float", "fixed"}
        Model of the mstrack trackers.
    force : bool
        Ignore cached results.
    quiet : bool
        No progress bars (they are also off when stderr is not a terminal).
    max_frames : int, optional
        Use at most this many frames of each sequence.
    factory : callable
        ``factory(name, model) -> tracker``; defaults to :func:`make_tracker`.
    """
    progress = not quiet and sys.stderr.isatty()
    names = list(trackers)
    runs: dict[str, dict[str, SequenceRun]] = {}
    jobs = [(t, s) for t in names for s in sequences]
    for name, seq in tqdm(jobs, desc="eval", disable=not progress, unit="seq"):
        label = run_label(name, model)
        m = model if uses_model(name) else "float"
        n = len(seq) if max_frames is None else min(len(seq), max_frames)
        path = cache_path(out_dir, label, seq.name)
        fp = tracker_fingerprint(name) if name in TRACKERS else None
        run = None if force else load_cached(path, n, m, fp)
        if run is None:
            run = run_sequence(factory(name, model), seq, n, label=label, model=m, progress=progress)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps({**run.to_json(), "fingerprint": fp}) + "\n")
        runs.setdefault(label, {})[seq.name] = run
    return aggregate(runs, sequences)
