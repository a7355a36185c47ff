"""One-pass evaluation (OPE) of trackers over a dataset, OTB style.

Each tracker is initialised on frame 0 with the ground-truth box and updated
on every following frame; frame 0 counts in the scores with the box the
tracker reports from ``init`` (as in OTB).  Speed is measured on ``update()``
only (frame decoding excluded).  Per-sequence results are cached as
``<out>/results/<label>/<sequence>.json`` and reused unless ``force``, or
the frame count, model, tracker code (:func:`tracker_fingerprint`), tracker
parameters (:func:`params_key`) or the sequence's content
(:func:`sequence_digest`: ground truth and the frame files' names, sizes and
modification times) changed, so one ``--out`` folder can serve several
datasets whose sequences share a name without mixing their results.

A sequence that cannot be run (unreadable frame, invalid frame-0 box, tracker
error) is recorded in :attr:`Evaluation.failed` with the reason and left out
of every tracker's scores; the other sequences go on and keep their cached
runs (a failed run is not cached, so it is retried next time).

Aggregates (:class:`Evaluation`): per sequence, per attribute and overall,
the latter two frame-weighted (the per-frame values of all sequences are
concatenated, as the OTB toolkit does).

Any object with ``init(frame, box)`` and ``update(frame)`` returning a
:class:`~mstrack.track.types.TrackResult`, a :class:`~mstrack.track.types.Box` or an
``(x, y, w, h)`` sequence can be run with :func:`run_sequence`.
"""
from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

import numpy as np
from tqdm import tqdm

from . import baselines
from ..io.data import DataError, Sequence
from .metrics import Scores, concat_scores, score, valid_gt
from ..track.params import V2_COLOUR, V2_JOINT  # mstrack-v2-colour's; the defaults of mstrack-v2 (re-exported)
from ..track.types import Box, Status

CACHE_VERSION = 3
MODELS = ("float", "fixed")


def _mstrack(features: str | None, kernel: str, preset: str = "paper", fixed: dict[str, Any] | None = None,
             **extra: Any) -> Callable[[str], Any]:
    """A factory of mstrack.Tracker; *fixed*: FixedParams fields given to the fixed model only."""
    def make(model: str = "float") -> Any:
        from ..track.tracker import Tracker  # imported late: written separately, may be absent
        more_fp = dict(fixed or {}) if model == "fixed" else {}
        return Tracker(model=model, features=features, kernel=kernel, preset=preset,  # type: ignore[arg-type]
                       **extra, **more_fp)
    more = "".join(f", {k}={v!r}" for k, v in {**extra, **(fixed or {})}.items())
    make.__doc__ = f"mstrack.Tracker(preset={preset!r}, features={features!r}, kernel={kernel!r}{more})"
    return make


def _baseline(fn: Callable[[], Any]) -> Callable[[str], Any]:
    def make(model: str = "float") -> Any:  # model does not apply to OpenCV trackers
        return fn()
    make.__doc__ = fn.__doc__
    return make


#: Tracker name -> factory ``f(model) -> tracker``.  Add entries here.
TRACKERS: dict[str, Callable[[str], Any]] = {
    "mstrack-v2": _mstrack(None, "flat", "v2"),
    "mstrack-v2-colour": _mstrack(None, "flat", "v2", **V2_COLOUR),
    # the tracker of the shared-engine core's eight-target build (mstrack synth --config shared8-colour-w63):
    # windows up to 63 decimated px; the fixed model with that build's MAX_HALF 31 and COORD_W 11
    "mstrack-v2-colour-w63": _mstrack(None, "flat", "v2", fixed={"max_half": 31, "coord_bits": 11}, **V2_COLOUR,
                                      max_window=63),
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


#: Tracker names that are refused, with the name to use instead: mstrack-v2-joint is the default v2
#: tracker mstrack-v2; the colour-only tracker v2 is mstrack-v2-colour.
RENAMED = {"mstrack-v2-joint": "mstrack-v2"}


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
    if name in RENAMED:
        raise ValueError(f"tracker {name!r} is now {RENAMED[name]!r}")
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


#: statuses under which a tracker vouches for its box (``TrackResult.ok``)
OK_STATUSES = frozenset(s.value for s in (Status.OK, Status.INIT, Status.CLIPPED, Status.REACQUIRED))


def result_confidence(result: Any) -> float:
    """``result.confidence`` as a float, NaN if the tracker gives none."""
    c = getattr(result, "confidence", None)
    return float(c) if c is not None else float("nan")


def result_status(result: Any) -> str:
    """Status string of a tracker's return value ("ok" if it has none)."""
    st = getattr(result, "status", Status.OK)
    return st.value if isinstance(st, Status) else str(st)


def frame_error_types() -> tuple[type[BaseException], ...]:
    """Exception types meaning "bad frame, go on" (``mstrack.FrameError`` once it exists)."""
    try:
        from ..track.frames import FrameError
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
    confidence : list of float, length N
        ``TrackResult.confidence`` per frame (NaN for trackers without one, and for
        rejected frames).
    """

    tracker: str
    sequence: str
    boxes: np.ndarray
    status: list[str]
    update_time: float
    model: str = "float"
    confidence: list[float] = field(default_factory=list)

    @property
    def ok(self) -> np.ndarray:
        """Per frame: the tracker vouches for its box (status ok, init, clipped or reacquired)."""
        return np.array([s in OK_STATUSES for s in self.status], dtype=bool)

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
                "update_time_s": self.update_time, "boxes": self.boxes.tolist(), "status": self.status,
                "confidence": [None if c != c else round(float(c), 6) for c in self.confidence]}

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> "SequenceRun":
        return cls(d["tracker"], d["sequence"], np.asarray(d["boxes"], dtype=np.float64).reshape(-1, 4),
                   list(d["status"]), float(d["update_time_s"]), d.get("model", "float"),
                   [float("nan") if c is None else float(c) for c in d.get("confidence", [])])


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
    conf: list[float] = []
    where = f"{label} on {seq.name}"
    try:
        res = tracker.init(seq.frame(0), seq.init_box())
        boxes[0] = to_box(res).as_tuple() if res is not None else seq.gt[0]
        status.append(result_status(res) if res is not None else Status.INIT.value)
        conf.append(result_confidence(res))
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
                conf.append(float("nan"))
                continue
            total += time.perf_counter() - t0
            boxes[i] = to_box(res).as_tuple()
            status.append(result_status(res))
            conf.append(result_confidence(res))
    except DataError:
        raise
    except Exception as exc:
        raise RuntimeError(f"{where}, frame {len(status)}: {type(exc).__name__}: {exc}") from exc
    return SequenceRun(label, seq.name, boxes, status, total, model, conf)


def sequence_digest(seq: Sequence, n_frames: int) -> str:
    """Short hash of what a run of the first ``n_frames`` of ``seq`` depends on in the data.

    The ground truth (0-based, as loaded) and, per frame file, its name, size and modification
    time (not its path: a moved dataset keeps its cache).  Part of the cache key."""
    return files_digest(np.ascontiguousarray(seq.gt[:n_frames], dtype=np.float64).tobytes(), seq.img_files[:n_frames])


def files_digest(data: bytes, files: Iterable[str | Path]) -> str:
    """Short hash of ``data`` (the ground truth) and, per file, its name, size and modification time
    (not its path: a moved dataset keeps its cache)."""
    import hashlib

    h = hashlib.sha1(data)
    for f in files:
        try:
            st = Path(f).stat()
            h.update(f"{Path(f).name}:{st.st_size}:{st.st_mtime_ns};".encode())
        except OSError:
            h.update(f"{Path(f).name}:missing;".encode())
    return h.hexdigest()[:16]


def params_key(tracker: Any) -> str:
    """The parameters of a tracker object as a string (``repr`` of its ``params`` and, for the
    fixed model, ``impl.fixed``); "" for trackers without them.  Part of the cache key."""
    parts = [getattr(tracker, "params", None), getattr(getattr(tracker, "impl", None), "fixed", None)]
    return "; ".join(repr(p) for p in parts if p is not None)


def tracker_fingerprint(name: str) -> str:
    """Short hash of the code behind tracker ``name``, stored with cached runs.

    mstrack trackers: the sources of the track layer (``mstrack/track/*.py``:
    tracker, float models, params, frames, types; and ``mstrack/fixed/*.py``); OpenCV
    baselines: ``eval/baselines.py`` and the OpenCV version.  A cached run whose
    fingerprint differs is recomputed, so editing the tracker invalidates it.
    """
    import hashlib

    import cv2

    pkg = Path(__file__).resolve().parents[1]  # mstrack/
    if uses_model(name):
        files = sorted((pkg / "track").glob("*.py")) + sorted((pkg / "fixed").glob("*.py"))
        extra = ""
    else:
        files, extra = [pkg / "eval" / "baselines.py"], cv2.__version__
    h = hashlib.sha1(extra.encode())
    for f in files:
        if f.is_file():
            h.update(f.name.encode() + f.read_bytes())
    return h.hexdigest()[:12]


def cache_path(out_dir: str | Path, label: str, seq_name: str) -> Path:
    """``<out>/results/<label>/<seq>.json``; ValueError if a name is not a plain file name."""
    for what, v in (("tracker label", label), ("sequence name", seq_name)):
        if not v or v in (".", "..") or any(c in v for c in "/\\\0"):
            raise ValueError(f"{what} {v!r} cannot name a cache file (no '/', '\\', '.' or '..')")
    return Path(out_dir) / "results" / label / f"{seq_name}.json"


def load_cached(path: Path, n_frames: int, model: str, fingerprint: str | None = None,
                content: str | None = None, params: str | None = None) -> SequenceRun | None:
    """A cached run if it exists and matches (frame count, model, code fingerprint, sequence content
    digest, tracker parameters, cache version); else None."""
    try:
        d = json.loads(path.read_text())
        if d.get("version") != CACHE_VERSION or d.get("n_frames") != n_frames or d.get("model") != model \
                or d.get("fingerprint") != fingerprint or d.get("content") != content \
                or d.get("params") != params:
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
        ``[label][seq or attribute]`` -> :class:`~mstrack.eval.metrics.Scores`.
    overall : dict
        ``[label]`` -> frame-weighted :class:`~mstrack.eval.metrics.Scores`.
    fps : dict
        ``[label]`` -> total updates / total update time.
    failed : dict
        Sequence name -> {label: reason} of the runs that failed; those sequences are
        not in :attr:`sequences` nor in any score.
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
    failed: dict[str, dict[str, str]] = field(default_factory=dict)


def aggregate(runs: dict[str, dict[str, SequenceRun]], sequences: list[Sequence],
              failed: dict[str, dict[str, str]] | None = None) -> Evaluation:
    """Score runs against the sequences' ground truth and aggregate them.

    Sequences named in ``failed`` (name -> {label: reason}) are left out of every score."""
    failed = dict(failed or {})
    sequences = [s for s in sequences if s.name not in failed]
    runs = {label: {n: r for n, r in per.items() if n not in failed} for label, per in runs.items()}
    attrs: dict[str, list[str]] = {}
    for s in sequences:
        for a in dict.fromkeys(s.attributes):
            attrs.setdefault(a, []).append(s.name)
    ev = Evaluation(list(runs), [s.name for s in sequences], dict(sorted(attrs.items())), runs, failed=failed)
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


#: Rough update() rate (frames per second, docs/results.md) of the slow trackers: parallel runs
#: are handed out longest first (estimated frames / rate), so one long run does not finish last.
FPS_HINT = {"opencv-csrt": 25.0, "opencv-kcf": 200.0, "mstrack-v2": 500.0}


def _run_job(factory: Callable[[str, str], Any], name: str, model: str, seq: Sequence, n: int, label: str,
             m: str) -> tuple[str, Any]:
    """One (tracker, sequence) run in a worker process (``--jobs`` / Dask): ``("ok", SequenceRun)`` or
    ``("failed", reason)`` (the reason as text: exceptions with custom arguments do not unpickle)."""
    try:
        return "ok", run_sequence(factory(name, model), seq, n, label=label, model=m)
    except (DataError, RuntimeError, ValueError) as exc:
        return "failed", str(exc)


def _run_job_threads(cv_threads: int, *call: Any) -> tuple[str, Any]:
    """:func:`_run_job` after limiting OpenCV's thread pool to ``cv_threads`` in this worker: N
    workers of 2 OpenCV threads each on 2 cores would fight for them (CSRT and KCF use the pool).
    The boxes do not depend on the thread count (checked for CSRT and KCF on real sequences)."""
    import cv2
    cv2.setNumThreads(cv_threads)
    return _run_job(*call)


class _Pool:
    """Runs :func:`_run_job` calls: in this process (jobs=1), on a local process pool (``jobs`` > 1)
    or on a Dask cluster (``scheduler``); :meth:`results` yields ``(index, outcome)`` as runs finish."""

    def __init__(self, jobs: int, scheduler: str | None) -> None:
        self.jobs, self.scheduler = jobs, scheduler
        # OpenCV threads per worker: the cores shared out (local workers); one on a remote cluster,
        # which is meant to run one single-threaded worker process per core
        self.cv_threads = max(1, (os.cpu_count() or 1) // jobs) if scheduler in (None, "local") else 1
        self.where = ("this process" if jobs == 1 and scheduler is None else
                      f"{jobs} processes" if scheduler is None else
                      f"a local Dask cluster of {jobs} workers" if scheduler == "local" else
                      f"the Dask scheduler at {scheduler}")

    def results(self, calls: list[tuple[Any, ...]]) -> Iterator[tuple[int, tuple[str, Any]]]:
        if not calls:
            return
        if self.scheduler is not None:
            yield from self._dask(calls)
        elif self.jobs == 1:
            for i, c in enumerate(calls):
                yield i, _run_job(*c)
        else:
            import concurrent.futures as cf
            import multiprocessing as mp
            # spawn: a fresh interpreter per worker (forking a process that runs OpenCV's thread pool
            # can deadlock); workers import mstrack and load the numba kernels from their disk cache
            with cf.ProcessPoolExecutor(max_workers=self.jobs, mp_context=mp.get_context("spawn")) as ex:
                futs = {ex.submit(_run_job_threads, self.cv_threads, *c): i for i, c in enumerate(calls)}
                for f in cf.as_completed(futs):
                    yield futs[f], f.result()

    def _dask(self, calls: list[tuple[Any, ...]]) -> Iterator[tuple[int, tuple[str, Any]]]:
        try:
            from distributed import Client, LocalCluster, as_completed
        except ImportError as exc:
            raise ImportError("--scheduler needs Dask distributed: pip install 'dask[distributed]' "
                              "(tools/setup.sh installs it, extra 'dist')") from exc
        import logging
        cluster = None
        if self.scheduler == "local":
            cluster = LocalCluster(n_workers=self.jobs, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster)
        else:
            client = Client(self.scheduler, timeout="20s")
        try:
            futs = {client.submit(_run_job_threads, self.cv_threads, *c, pure=False, key=f"mstrack-run-{i}-{c[5]}-{c[3].name}"): i
                    for i, c in enumerate(calls)}
            for f in as_completed(list(futs)):
                yield futs[f], f.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def evaluate(sequences: list[Sequence], trackers: Iterable[str], out_dir: str | Path, model: str = "float",
             force: bool = False, quiet: bool = False, max_frames: int | None = None,
             factory: Callable[[str, str], Any] = make_tracker, jobs: int = 1,
             scheduler: str | None = None) -> Evaluation:
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
        ``factory(name, model) -> tracker``; defaults to :func:`make_tracker`.  With ``jobs`` > 1
        or a ``scheduler`` it must be picklable (a module-level function).
    jobs : int
        Runs (tracker x sequence) in parallel: 1 runs them in this process; N > 1 on N worker
        processes of this machine (or N workers of the local Dask cluster).  The results are
        the same as with one process; only the timings (fps) differ.
    scheduler : str, optional
        Run on Dask distributed: ``"local"`` starts a ``LocalCluster`` of ``jobs`` workers on this
        machine, anything else is the address of a running scheduler (``tcp://host:8786``) whose
        workers see the sequences at the same paths and run the same mstrack.

    Runs are looked up in the cache first (here, in this process); the others are handed out
    longest first and each is written to the cache as soon as it comes back, so an interrupted
    evaluation resumes where it stopped.  A run that raises :class:`DataError`, ``RuntimeError``
    or ``ValueError`` (unreadable frame, invalid frame-0 box, tracker error) is recorded in
    ``Evaluation.failed`` and the evaluation goes on; ValueError for ``max_frames < 1``, ``jobs
    < 1`` or two sequences with the same name.
    """
    if max_frames is not None and (isinstance(max_frames, bool) or not isinstance(max_frames, int)
                                   or max_frames < 1):
        raise ValueError(f"max_frames must be a positive integer, got {max_frames!r}")
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be a positive integer, got {jobs!r}")
    seen: set[str] = set()
    for s in sequences:
        if s.name in seen:
            raise ValueError(f"two sequences named {s.name!r}")
        seen.add(s.name)
    progress = not quiet and sys.stderr.isatty()
    names = list(trackers)
    labels = list(dict.fromkeys(run_label(t, model) for t in names))
    done: dict[tuple[str, str], SequenceRun] = {}
    reasons: dict[tuple[str, str], str] = {}
    todo: list[tuple[tuple[Any, ...], Path, dict[str, Any], float]] = []
    for name, seq in [(t, s) for t in names for s in sequences]:
        label = run_label(name, model)
        m = model if uses_model(name) else "float"
        n = len(seq) if max_frames is None else min(len(seq), max_frames)
        path = cache_path(out_dir, label, seq.name)
        # mstrack trackers under other names (mstrack explore's points) depend on the same code
        fp = tracker_fingerprint(name) if name in TRACKERS or uses_model(name) else None
        key = {"fingerprint": fp, "content": sequence_digest(seq, n), "params": params_key(factory(name, model))}
        run = None if force else load_cached(path, n, m, **key)
        if run is not None:
            done[label, seq.name] = run
        else:
            todo.append(((factory, name, model, seq, n, label, m), path, key, n / FPS_HINT.get(name, 1000.0)))
    pool = _Pool(jobs, scheduler)
    if jobs > 1 or scheduler is not None:
        todo.sort(key=lambda t: -t[3])  # longest first (results do not depend on the order)
        if model == "float" and any(uses_model(t[0][1]) for t in todo):
            # compile (or load) the numba kernels here first: a first run compiles once, with the
            # CLI's notice, and the workers of this machine then load them from numba's disk cache
            from ..track.float_v2 import _numba_ready
            _numba_ready()
    if progress and todo:
        print(f"eval: {len(done)} runs cached, {len(todo)} to run on {pool.where}", file=sys.stderr)
    # in this process the per-frame bar of each run shows; with workers, one bar over the runs
    inner = progress and pool.where == "this process"
    with tqdm(total=len(done) + len(todo), initial=len(done), desc="eval", disable=not progress,
              unit="run", dynamic_ncols=True) as bar:
        calls = [t[0] for t in todo]
        for i, (kind, payload) in _inline(calls) if inner else pool.results(calls):
            (_, name, _, seq, _, label, _), path, key, _ = todo[i]
            bar.update(1)
            if kind == "failed":
                reasons[label, seq.name] = payload
                continue
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps({**payload.to_json(), **key}) + "\n")
            done[label, seq.name] = payload
    # the order of runs (and so of the report) is the tracker x sequence order, however they finished
    runs: dict[str, dict[str, SequenceRun]] = {label: {} for label in labels}
    failed: dict[str, dict[str, str]] = {}
    for name in names:
        for seq in sequences:
            label = run_label(name, model)
            if (label, seq.name) in done:
                runs[label][seq.name] = done[label, seq.name]
            elif (label, seq.name) in reasons:
                failed.setdefault(seq.name, {})[label] = reasons[label, seq.name]
    return aggregate(runs, sequences, failed)


def _inline(calls: list[tuple[Any, ...]]) -> Iterator[tuple[int, tuple[str, Any]]]:
    """:func:`_run_job` in this process, with the per-frame progress bar of each run."""
    for i, (factory, name, model, seq, n, label, m) in enumerate(calls):
        try:
            yield i, ("ok", run_sequence(factory(name, model), seq, n, label=label, model=m, progress=True))
        except (DataError, RuntimeError, ValueError) as exc:
            yield i, ("failed", str(exc))
