"""Multi-object evaluation on MOTChallenge-format sequences (``mstrack eval`` on a MOT folder).

Protocol (one pass, no re-initialisation): every ground-truth target is added on its first
annotated frame with its ground-truth box there, tracked on every frame up to its last annotated
frame and removed after it (gaps in its annotation are tracked through).  The mstrack trackers run
as one :class:`mstrack.MultiTracker` (capacity rule included: a refused add is reported); the
OpenCV baselines as one instance per target, through the same harness.  Per frame the order is:
remove the targets whose ground truth ended, update the live ones (timed), add the new ones.

Scores
------
* per target, per sequence and overall (frame-weighted: the targets' frames concatenated): the OTB
  success AUC and precision@20 (:mod:`mstrack.eval.metrics`) over the frames where the target has
  ground truth, its init frame included (as OTB's frame 0); and the loss table of the single-target
  evaluation (:func:`mstrack.eval.metrics.loss_detection`: over those frames but the init frame,
  *recall* = share of frames with IoU = 0 whose result is not ``ok``, *false alarms* = share of
  frames with IoU >= 0.5 whose result is not ``ok``);
* per sequence and overall: HOTA, MOTA, IDF1, ID switches (and DetA, AssA, MOTP, FP, FN) computed by
  TrackEval (``trackeval`` on PyPI, the MOTChallenge evaluation code: :func:`mot_metrics`) with its
  default thresholds (CLEAR and Identity match at IoU >= 0.5; HOTA averages alpha 0.05..0.95).  A
  tracker's hypothesis on a frame is its box when its result is ``ok`` (a box it vouches for); its
  identity is the id of the ground-truth target it was initialised from.

Runs are cached per (tracker, sequence) in ``<out>/results/<label>/<sequence>.json`` with the code
fingerprint, the tracker parameters and a digest of the ground truth and frame files, as
:mod:`mstrack.eval.evaluate` does.
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from .evaluate import (Evaluation, files_digest, frame_error_types, make_tracker, result_confidence, result_status,
                       run_label, to_box, tracker_fingerprint, uses_model, OK_STATUSES)
from .metrics import Scores, concat_scores, iou, loss_detection, LossDetection, score, valid_gt
from ..io.data import DataError
from ..io.mot import MotSequence
from ..track.types import Status

CACHE_VERSION = 1
#: The MOT metrics of the report (TrackEval field names; HOTA, DetA and AssA are the means over alpha).
MOT_FIELDS = ("HOTA", "DetA", "AssA", "MOTA", "MOTP", "IDF1", "IDSW", "CLR_FP", "CLR_FN")


# ----------------------------------------------------------------------------- harness
class PerTarget:
    """One tracker instance per target (the OpenCV baselines): the add / remove / update of
    :class:`mstrack.MultiTracker`, ids the lowest free slot, without a capacity rule."""

    def __init__(self, factory: Callable[[], Any]) -> None:
        self._factory = factory
        self._trackers: dict[int, Any] = {}

    @property
    def targets(self) -> list[int]:
        return sorted(self._trackers)

    def add(self, frame: np.ndarray, box: Any) -> tuple[int, Any]:
        trk = self._factory()
        res = trk.init(frame, box)
        tid = next(i for i in range(len(self._trackers) + 1) if i not in self._trackers)
        self._trackers[tid] = trk
        return tid, res

    def remove(self, tid: int) -> None:
        del self._trackers[tid]

    def update(self, frame: np.ndarray) -> list[tuple[int, Any]]:
        return [(t, self._trackers[t].update(frame)) for t in self.targets]


class _Multi:
    """:class:`mstrack.MultiTracker` behind the harness's interface."""

    def __init__(self, mt: Any) -> None:
        self.mt = mt

    def add(self, frame: np.ndarray, box: Any) -> tuple[int, Any]:
        tid = self.mt.add(frame, box)
        return tid, self.mt.last[tid]

    def remove(self, tid: int) -> None:
        self.mt.remove(tid)

    def update(self, frame: np.ndarray) -> list[tuple[int, Any]]:
        return [(r.target_id, r) for r in self.mt.update(frame)]


def make_multi(name: str, model: str = "float", capacity: Any = None) -> Any:
    """The harness of tracker ``name``: a :class:`mstrack.MultiTracker` with the registered tracker's
    parameters for the mstrack trackers (``capacity``: its :class:`mstrack.MultiCoreConfig`, default
    the MultiTracker's), :class:`PerTarget` of the registered factory otherwise."""
    if uses_model(name):
        from ..track.multi import MultiTracker
        trk = make_tracker(name, model)  # the registered tracker's parameters (default FixedParams)
        return _Multi(MultiTracker(model=model, params=trk.params, capacity=capacity))  # type: ignore[arg-type]
    make_tracker(name, model)  # unknown names fail here
    return PerTarget(lambda: make_tracker(name, model))


@dataclass
class TargetRun:
    """One target of a :class:`MotRun`: frames ``first .. first + len(boxes) - 1`` tracked."""

    id: int
    first: int
    boxes: np.ndarray
    status: list[str]
    confidence: list[float]

    @property
    def frames(self) -> np.ndarray:
        return np.arange(self.first, self.first + len(self.boxes))

    @property
    def ok(self) -> np.ndarray:
        return np.array([s in OK_STATUSES for s in self.status], dtype=bool)


@dataclass
class MotRun:
    """One tracker on one MOT sequence.

    ``targets``: ground-truth id -> :class:`TargetRun`; ``refused``: ground-truth id -> reason of the
    targets whose add was refused (the capacity rule) or failed (a box the tracker cannot start from);
    ``update_time``: seconds in the harness's update over ``updates`` target updates."""

    tracker: str
    sequence: str
    n_frames: int
    targets: dict[int, TargetRun]
    refused: dict[int, str]
    update_time: float
    updates: int
    model: str = "float"

    @property
    def fps(self) -> float:
        """Target updates per second."""
        return self.updates / self.update_time if self.updates and self.update_time > 0 else float("nan")

    def hypotheses(self) -> np.ndarray:
        """(M, 6) ``(frame, id, x, y, w, h)`` of the boxes the tracker vouches for (``ok``), 0-based."""
        rows = [(f, t.id, *b) for t in self.targets.values() for f, b, ok in zip(t.frames, t.boxes, t.ok) if ok]
        a = np.asarray(rows, dtype=np.float64).reshape(-1, 6)
        return a[np.lexsort((a[:, 1], a[:, 0]))]

    def to_json(self) -> dict[str, Any]:
        return {"version": CACHE_VERSION, "tracker": self.tracker, "sequence": self.sequence,
                "n_frames": self.n_frames, "model": self.model, "update_time_s": self.update_time,
                "updates": self.updates, "refused": {str(k): v for k, v in self.refused.items()},
                "targets": {str(k): {"first": t.first, "boxes": t.boxes.tolist(), "status": t.status,
                                     "confidence": [None if c != c else round(float(c), 6) for c in t.confidence]}
                            for k, t in self.targets.items()}}

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> "MotRun":
        targets = {int(k): TargetRun(int(k), int(t["first"]), np.asarray(t["boxes"], np.float64).reshape(-1, 4),
                                     list(t["status"]), [math.nan if c is None else float(c) for c in t["confidence"]])
                   for k, t in d["targets"].items()}
        return cls(d["tracker"], d["sequence"], int(d["n_frames"]), targets,
                   {int(k): v for k, v in d.get("refused", {}).items()}, float(d["update_time_s"]),
                   int(d["updates"]), d.get("model", "float"))


def run_mot(harness: Any, seq: MotSequence, max_frames: int | None = None, label: str = "tracker",
            model: str = "float") -> MotRun:
    """Run one harness (:func:`make_multi`) over a MOT sequence (module docstring: the protocol).

    A bad-frame error on update gives every live target status "error" with its previous box; an
    add the tracker refuses (:class:`mstrack.track.multi.CapacityError`, or a ValueError for a box it
    cannot start from) is recorded in :attr:`MotRun.refused`; any other error is re-raised as
    RuntimeError naming the tracker, sequence and frame."""
    from ..track.multi import CapacityError
    n = len(seq) if max_frames is None else min(len(seq), max_frames)
    bad_frame = frame_error_types()
    ends = {t.id: min(t.last, n - 1) for t in seq.tracks.values() if t.first < n}
    live: dict[int, int] = {}  # ground-truth id -> harness id
    recs: dict[int, tuple[int, list[Any], list[str], list[float]]] = {}
    refused: dict[int, str] = {}
    total, updates = 0.0, 0
    where = f"{label} on {seq.name}"
    i = 0
    try:
        for i in range(n):
            for gid in [g for g, _ in live.items() if ends[g] < i]:
                harness.remove(live.pop(gid))
            frame = seq.frame(i)
            if live:
                t0 = time.perf_counter()
                try:
                    results = dict(harness.update(frame))
                except bad_frame:
                    results = None
                total += time.perf_counter() - t0
                updates += len(live)
                for gid, tid in live.items():
                    _, boxes, status, conf = recs[gid]
                    if results is None:
                        boxes.append(boxes[-1])
                        status.append(Status.ERROR.value)
                        conf.append(math.nan)
                    else:
                        res = results[tid]
                        boxes.append(to_box(res).as_tuple())
                        status.append(result_status(res))
                        conf.append(result_confidence(res))
            for t in seq.starting_at(i):
                try:
                    tid, res = harness.add(frame, t.boxes[0])
                except (CapacityError, ValueError) as exc:
                    refused[t.id] = f"frame {i}: {exc}"
                    continue
                live[t.id] = tid
                recs[t.id] = (i, [to_box(res).as_tuple()], [result_status(res)], [result_confidence(res)])
    except DataError:
        raise
    except Exception as exc:
        raise RuntimeError(f"{where}, frame {i}: {type(exc).__name__}: {exc}") from exc
    targets = {g: TargetRun(g, first, np.asarray(b, np.float64).reshape(-1, 4), s, c)
               for g, (first, b, s, c) in sorted(recs.items())}
    return MotRun(label, seq.name, n, targets, refused, total, updates, model)


# ----------------------------------------------------------------------------- MOT metrics (TrackEval)
def _trackeval() -> Any:
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # it prints the datasets whose packages are missing
            import trackeval
    except ImportError as exc:
        raise ImportError("the MOT metrics need TrackEval: pip install --no-deps trackeval==1.3.0 scipy "
                          "(tools/setup.sh installs it, extra 'mot')") from exc
    return trackeval


def mot_data(gt_rows: np.ndarray, hyp_rows: np.ndarray, n_frames: int, name: str = "seq") -> dict[str, Any]:
    """TrackEval's per-sequence input from ground-truth and hypothesis rows ``(frame, id, x, y, w, h)``
    (0-based frames, boxes ``x, y, w, h``): what ``MotChallenge2DBox.get_preprocessed_seq_data`` returns
    for MOT15 (no preprocessing), ids relabelled 0.., similarity = TrackEval's box IoU."""
    te = _trackeval()
    ious = te.datasets._base_dataset._BaseDataset._calculate_box_ious
    gt, hyp = np.asarray(gt_rows, np.float64).reshape(-1, 6), np.asarray(hyp_rows, np.float64).reshape(-1, 6)
    g_ids, h_ids = np.unique(gt[:, 1]), np.unique(hyp[:, 1])
    g_map = {int(v): i for i, v in enumerate(g_ids)}
    h_map = {int(v): i for i, v in enumerate(h_ids)}
    data: dict[str, Any] = {"gt_ids": [], "tracker_ids": [], "gt_dets": [], "tracker_dets": [],
                            "similarity_scores": []}
    for t in range(n_frames):
        g, h = gt[gt[:, 0] == t], hyp[hyp[:, 0] == t]
        data["gt_ids"].append(np.array([g_map[int(v)] for v in g[:, 1]], dtype=int))
        data["tracker_ids"].append(np.array([h_map[int(v)] for v in h[:, 1]], dtype=int))
        data["gt_dets"].append(g[:, 2:6].copy())
        data["tracker_dets"].append(h[:, 2:6].copy())
        data["similarity_scores"].append(ious(g[:, 2:6].copy(), h[:, 2:6].copy(), box_format="xywh"))
    data.update(num_timesteps=n_frames, num_gt_ids=len(g_ids), num_tracker_ids=len(h_ids),
                num_gt_dets=len(gt), num_tracker_dets=len(hyp), seq=name)
    return data


def _metrics() -> list[Any]:
    te = _trackeval()
    with contextlib.redirect_stdout(io.StringIO()):
        return [te.metrics.HOTA(), te.metrics.CLEAR({"PRINT_CONFIG": False}),
                te.metrics.Identity({"PRINT_CONFIG": False})]


def mot_metrics(data: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """TrackEval's HOTA, CLEAR and Identity results of one sequence (:func:`mot_data`):
    ``{"HOTA": {...}, "CLEAR": {...}, "Identity": {...}}`` (TrackEval's fields)."""
    return {m.get_name(): m.eval_sequence(data) for m in _metrics()}


def combine_mot(per_seq: dict[str, dict[str, dict[str, Any]]]) -> dict[str, dict[str, Any]]:
    """TrackEval's combination of several sequences' results (``combine_sequences``)."""
    return {m.get_name(): m.combine_sequences({s: r[m.get_name()] for s, r in per_seq.items()}) for m in _metrics()}


def mot_summary(res: dict[str, dict[str, Any]]) -> dict[str, float]:
    """The :data:`MOT_FIELDS` of a TrackEval result (HOTA, DetA, AssA: means over alpha, as
    TrackEval's summary reports them)."""
    out: dict[str, float] = {}
    for k in MOT_FIELDS:
        for part in ("HOTA", "CLEAR", "Identity"):
            if k in res[part]:
                v = res[part][k]
                out[k] = float(np.mean(v))
                break
    return out


# ----------------------------------------------------------------------------- scores
@dataclass
class MotScores:
    """Scores of one tracker on a set of targets: OTB (``otb``), the loss table (``loss``), the MOT
    metrics (``mot``: :data:`MOT_FIELDS`; per sequence and overall only)."""

    otb: Scores
    loss: LossDetection
    frames: int
    mot: dict[str, float] = field(default_factory=dict)


def target_frames(run: TargetRun, seq: MotSequence) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(predicted boxes, ground truth, ok) of the target over its tracked frames (GT NaN where absent)."""
    tr = seq.tracks[run.id]
    span = tr.gt_span()
    gt = span[: len(run.boxes)]
    return run.boxes, gt, run.ok


def _target_parts(run: TargetRun, seq: MotSequence) -> tuple[Scores, np.ndarray, np.ndarray]:
    boxes, gt, ok = target_frames(run, seq)
    sc = score(boxes, gt)
    v = valid_gt(gt)
    v[0] = False  # the init frame says nothing about loss detection
    return sc, iou(boxes, gt)[v], ok[v]


def _combine(parts: list[tuple[Scores, np.ndarray, np.ndarray]]) -> MotScores:
    sc = concat_scores([p[0] for p in parts])
    io_ = np.concatenate([p[1] for p in parts]) if parts else np.zeros(0)
    ok = np.concatenate([p[2] for p in parts]) if parts else np.zeros(0, bool)
    return MotScores(sc, loss_detection(io_, ok), sc.n_frames)


@dataclass
class MotEvaluation:
    """Results of :func:`evaluate_mot`: ``runs[label][seq]``, ``per_target[label][seq][gt id]``,
    ``per_sequence[label][seq]``, ``overall[label]`` (:class:`MotScores`), ``fps[label]`` (target
    updates per second), ``failed[seq][label]`` (reasons)."""

    trackers: list[str]
    sequences: list[str]
    runs: dict[str, dict[str, MotRun]] = field(default_factory=dict)
    per_target: dict[str, dict[str, dict[int, MotScores]]] = field(default_factory=dict)
    per_sequence: dict[str, dict[str, MotScores]] = field(default_factory=dict)
    overall: dict[str, MotScores] = field(default_factory=dict)
    fps: dict[str, float] = field(default_factory=dict)
    failed: dict[str, dict[str, str]] = field(default_factory=dict)
    seq_info: dict[str, dict[str, int]] = field(default_factory=dict)

    def as_evaluation(self) -> Evaluation:
        """An :class:`~mstrack.eval.evaluate.Evaluation` with the overall OTB scores (for the plots)."""
        ev = Evaluation(list(self.trackers), list(self.sequences), {})
        ev.overall = {t: self.overall[t].otb for t in self.trackers}
        ev.fps = dict(self.fps)
        return ev


def aggregate_mot(runs: dict[str, dict[str, MotRun]], sequences: list[MotSequence],
                  failed: dict[str, dict[str, str]] | None = None) -> MotEvaluation:
    """Score the runs (OTB per target, loss table, TrackEval's MOT metrics) and aggregate them."""
    failed = dict(failed or {})
    seqs = [s for s in sequences if s.name not in failed]
    ev = MotEvaluation(list(runs), [s.name for s in seqs], failed=failed)
    ev.runs = {label: {n: r for n, r in per.items() if n not in failed} for label, per in runs.items()}
    for label, per in runs.items():
        all_parts = []
        mot_per_seq = {}
        ev.per_target[label], ev.per_sequence[label] = {}, {}
        for s in seqs:
            if s.name not in ev.runs[label]:
                continue
            run = per[s.name]
            parts = {gid: _target_parts(t, s) for gid, t in run.targets.items()}
            ev.per_target[label][s.name] = {gid: _combine([p]) for gid, p in parts.items()}
            ms = _combine(list(parts.values()))
            gt = s.rows[s.rows[:, 0] < run.n_frames]
            mot_per_seq[s.name] = mot_metrics(mot_data(gt, run.hypotheses(), run.n_frames, s.name))
            ms.mot = mot_summary(mot_per_seq[s.name])
            ev.per_sequence[label][s.name] = ms
            all_parts += list(parts.values())
            ev.seq_info[s.name] = {"frames": run.n_frames, "targets": len(s.tracks), "gt_boxes": int(len(gt))}
        ov = _combine(all_parts)
        ov.mot = mot_summary(combine_mot(mot_per_seq)) if mot_per_seq else {}
        ev.overall[label] = ov
        n = sum(r.updates for r in per.values())
        t = sum(r.update_time for r in per.values())
        ev.fps[label] = n / t if n and t > 0 else float("nan")
    return ev


# ----------------------------------------------------------------------------- evaluate (cached)
def mot_digest(seq: MotSequence, n_frames: int) -> str:
    """Short hash of the ground truth and of the first ``n_frames`` frame files (name, size, mtime)."""
    return files_digest(np.ascontiguousarray(seq.rows[seq.rows[:, 0] < n_frames]).tobytes(), seq.img_files[:n_frames])


def _params_key(harness: Any) -> str:
    mt = getattr(harness, "mt", None)
    return "" if mt is None else f"{mt.params!r}; {mt.fixed!r}; {mt.capacity!r}"


def _harness_fingerprint(name: str) -> str:
    """The tracker's code fingerprint and this harness's (eval/multi.py)."""
    return tracker_fingerprint(name) + hashlib.sha1(Path(__file__).read_bytes()).hexdigest()[:8]


def evaluate_mot(sequences: list[MotSequence], trackers: Iterable[str], out_dir: str | Path, model: str = "float",
                 force: bool = False, max_frames: int | None = None, progress: bool = False,
                 make: Callable[[str, str], Any] = make_multi) -> MotEvaluation:
    """Run trackers over MOT sequences (module docstring: the protocol), with the per-sequence cache
    in ``<out_dir>/results/``, and aggregate (:func:`aggregate_mot`).  A run that fails (unreadable
    frame, tracker error) is recorded in ``failed`` and its sequence left out of every score."""
    from .evaluate import cache_path
    if max_frames is not None and (isinstance(max_frames, bool) or not isinstance(max_frames, int) or max_frames < 1):
        raise ValueError(f"max_frames must be a positive integer, got {max_frames!r}")
    names = list(trackers)
    runs: dict[str, dict[str, MotRun]] = {}
    failed: dict[str, dict[str, str]] = {}
    for name in names:
        label = run_label(name, model)
        m = model if uses_model(name) else "float"
        runs.setdefault(label, {})
        for seq in sequences:
            n = len(seq) if max_frames is None else min(len(seq), max_frames)
            path = cache_path(out_dir, label, seq.name)
            harness = make(name, model)
            key = {"fingerprint": _harness_fingerprint(name), "content": mot_digest(seq, n),
                   "params": _params_key(harness)}
            run = None
            if not force and path.is_file():
                try:
                    d = json.loads(path.read_text())
                    if d.get("version") == CACHE_VERSION and d.get("n_frames") == n and d.get("model") == m \
                            and all(d.get(k) == v for k, v in key.items()):
                        run = MotRun.from_json(d)
                except (OSError, ValueError, KeyError, TypeError):
                    run = None
            if run is None:
                if progress:
                    print(f"eval: {label} on {seq.name} ({n} frames, {len(seq.tracks)} targets)", flush=True)
                try:
                    run = run_mot(harness, seq, n, label=label, model=m)
                except (DataError, RuntimeError, ValueError) as exc:
                    failed.setdefault(seq.name, {})[label] = str(exc)
                    continue
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(json.dumps({**run.to_json(), **key}) + "\n")
            runs[label][seq.name] = run
    return aggregate_mot(runs, sequences, failed)


# ----------------------------------------------------------------------------- report
def _f(v: float | None, nd: int = 3) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{nd}f}"


def _mot_cells(m: dict[str, float]) -> list[str]:
    return [_f(m.get("HOTA")), _f(m.get("MOTA")), _f(m.get("IDF1")),
            "-" if "IDSW" not in m else str(int(m["IDSW"]))]


def _loss_cells(ld: LossDetection) -> list[str]:
    return [f"{ld.off} / {_f(ld.recall, 2)}", f"{ld.on} / {_f(ld.false_alarm, 3)}"]


def tools_line_mot() -> str:
    """The report's "Tools:" line: numpy, OpenCV, numba and TrackEval."""
    from importlib import metadata

    from ..versions import PYTHON_TOOLS, tools_line
    try:
        te = metadata.version("trackeval")
    except metadata.PackageNotFoundError:
        te = "not installed"
    return tools_line(PYTHON_TOOLS).rstrip(".") + f", TrackEval {te}."


PROTOCOL = ("Each ground-truth target is added on its first annotated frame with its ground-truth box and "
            "tracked to its last annotated frame (then removed); no re-initialisation.  mstrack runs as one "
            "`mstrack.MultiTracker` per sequence, the OpenCV baselines as one instance per target.  AUC and "
            "P@20: OTB success AUC (IoU thresholds 0:0.05:1) and precision at 20 px over the frames where the "
            "target has ground truth (init frame included), frame-weighted.  Loss: off-target frames (IoU = 0) / "
            "*recall* = share not `ok`, on-target frames (IoU >= 0.5) / *false alarms* = share not `ok`, init "
            "frames excluded (the single-target loss table's definitions).  HOTA, MOTA, IDF1, IDSW: TrackEval "
            "(the MOTChallenge evaluation code) on the boxes each tracker reports `ok`, identities = the "
            "ground-truth id each track was started from; CLEAR / Identity at IoU >= 0.5.  upd/s: target "
            "updates per second (update() only).")


def report_markdown_mot(ev: MotEvaluation, title: str = "mstrack multi-target evaluation",
                        command: str | None = None) -> str:
    """Markdown of a :class:`MotEvaluation` (trackers sorted by overall HOTA)."""
    order = sorted(ev.trackers, key=lambda t: -ev.overall[t].mot.get("HOTA", -1.0))
    n_frames = sum(v["frames"] for v in ev.seq_info.values())
    n_tg = sum(v["targets"] for v in ev.seq_info.values())
    out = [f"# {title}", "",
           f"{len(ev.sequences)} MOT sequences, {n_frames} frames, {n_tg} targets.  {PROTOCOL}", ""]
    if command:
        out += [f"Command: `{command}`", ""]
    out += [tools_line_mot(), ""]
    head = ["tracker", "AUC", "P@20", "HOTA", "MOTA", "IDF1", "IDSW", "off / recall", "on / false alarms", "upd/s"]
    out += ["## Overall", "", _table(head, [[t, _f(ev.overall[t].otb.auc), _f(ev.overall[t].otb.precision20),
                                             *_mot_cells(ev.overall[t].mot), *_loss_cells(ev.overall[t].loss),
                                             _f(ev.fps[t], 1)] for t in order]), ""]
    out += ["## Per sequence", ""]
    rows = []
    for s in ev.sequences:
        info = ev.seq_info.get(s, {})
        for t in order:
            if s in ev.per_sequence[t]:
                m = ev.per_sequence[t][s]
                rows.append([s, str(info.get("frames", "")), str(info.get("targets", "")), t, _f(m.otb.auc),
                             _f(m.otb.precision20), *_mot_cells(m.mot), *_loss_cells(m.loss)])
    out += [_table(["sequence", "frames", "targets", "tracker", "AUC", "P@20", "HOTA", "MOTA", "IDF1", "IDSW",
                    "off / recall", "on / false alarms"], rows), ""]
    out += ["## Per target (AUC / P@20; frames with ground truth)", ""]
    rows = []
    for s in ev.sequences:
        ids = sorted({g for t in order for g in ev.per_target[t].get(s, {})})
        for g in ids:
            n = next((ev.per_target[t][s][g].frames for t in order if g in ev.per_target[t].get(s, {})), 0)
            rows.append([s, str(g), str(n), *(f"{_f(ev.per_target[t][s][g].otb.auc)} / "
                                            f"{_f(ev.per_target[t][s][g].otb.precision20)}"
                                            if g in ev.per_target[t].get(s, {}) else "-" for t in order)])
    out += [_table(["sequence", "id", "frames", *order], rows), ""]
    refused = [(s, t, g, r) for t in order for s, run in ev.runs.get(t, {}).items() for g, r in run.refused.items()]
    if refused:
        out += ["## Refused adds", "", _table(["sequence", "tracker", "id", "reason"],
                                              [[s, t, str(g), r.replace("|", "\\|")] for s, t, g, r in refused]), ""]
    if ev.failed:
        out += ["## Failed runs", "", _table(["sequence", "tracker", "reason"],
                                             [[s, t, r.replace("|", "\\|").replace("\n", " ")]
                                              for s, per in ev.failed.items() for t, r in per.items()]), ""]
    return "\n".join(out)


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])


def report_dict_mot(ev: MotEvaluation) -> dict[str, Any]:
    """The numbers of ``ev`` as a JSON-ready dict."""
    def sc(m: MotScores) -> dict[str, Any]:
        return {"auc": m.otb.auc, "precision20": m.otb.precision20, "frames": m.frames,
                "success": m.otb.success.tolist(), "precision": m.otb.precision.tolist(),
                "loss": {"off": m.loss.off, "recall": _num(m.loss.recall), "on": m.loss.on,
                         "false_alarm": _num(m.loss.false_alarm)},
                "mot": m.mot}
    return {"protocol": PROTOCOL, "trackers": ev.trackers, "sequences": ev.seq_info,
            "overall": {t: {**sc(ev.overall[t]), "updates_per_s": _num(ev.fps[t])} for t in ev.trackers},
            "per_sequence": {t: {s: sc(m) for s, m in ev.per_sequence[t].items()} for t in ev.trackers},
            "per_target": {t: {s: {str(g): sc(m) for g, m in d.items()} for s, d in ev.per_target[t].items()}
                           for t in ev.trackers},
            "refused": {t: {s: {str(g): r for g, r in run.refused.items()} for s, run in ev.runs.get(t, {}).items()
                            if run.refused} for t in ev.trackers},
            "failed": ev.failed, "tools": tools_line_mot()}


def _num(v: float) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def write_report_mot(ev: MotEvaluation, out_dir: str | Path, command: str | None = None) -> dict[str, Path]:
    """report.md, report.json, success.png and precision.png (all targets, frame-weighted) in ``out_dir``."""
    from .report import plot_curves
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    md = out / "report.md"
    md.write_text(report_markdown_mot(ev, command=command) + "\n")
    js = out / "report.json"
    d = report_dict_mot(ev)
    if command:
        d["command"] = command
    js.write_text(json.dumps(d, indent=1) + "\n")
    sp, pp = plot_curves(ev.as_evaluation(), out)
    return {"md": md, "json": js, "success": sp, "precision": pp}
