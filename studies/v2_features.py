"""Tracker v2: edge feature and fusion variants, measured (docs/results_v2_features.md).

Runs tracker v2 variants (mstrack/track/features_v2.py) over every sequence of a
dataset, one-pass (OPE), and scores them exactly as ``mstrack eval`` does
(mstrack.eval.evaluate.run_sequence + aggregate: frame-weighted AUC over all
frames, the mean of the per-sequence AUCs, and the per-sequence AUCs).

The baseline row is FloatTrackerV2 itself (``Tracker(model="float",
preset="v2")``); before anything is reported the tool checks that
MultiFeatureV2 with the colour feature alone gives the same boxes on every
frame (so the variants differ from the baseline only in what they add).
Parameters are the same on every sequence.

    .venv/bin/python studies/v2_features.py [--data DIR] [--jobs 2] [--md OUT.md]
    .venv/bin/python studies/v2_features.py --robust [--md OUT.md]

``--robust``: the shortlisted variants (ROBUST) again under 8 perturbed
starts, OTB-style: TRE (start at frames n//3 and 2n//3 of every sequence,
from the ground truth there) and SRE (init box centre shifted by +-10 % of
its width / height, or the box scaled by 0.9 / 1.1; the tracker's frame-0
box is scored against the true ground truth).  Reported: frame-weighted AUC
per perturbation, over all 9 starts (OPE + 8), and on how many of the 8 the
variant beats the baseline.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from dataclasses import replace  # noqa: E402

from mstrack.io.data import load_dataset  # noqa: E402
from mstrack.eval.metrics import valid_gt  # noqa: E402
from mstrack.track.types import Box  # noqa: E402
from mstrack.eval.evaluate import aggregate, run_sequence  # noqa: E402
from mstrack.track.features_v2 import Feature, MultiFeatureV2  # noqa: E402

THRESHOLDS = (16, 32, 64, 128)
FUSIONS = ("rho", "disc", "disc_frame", "wta", "tie")
BASELINE = "v2 colour (FloatTrackerV2)"


def variants() -> dict[str, tuple]:
    """label -> (group, factory args) ; factory args = None for the baseline."""
    C3, C2 = Feature("colour", bits=3), Feature("colour", bits=2)
    v: dict[str, tuple] = {BASELINE: ("a", None)}
    v["colour 2b (64 bins) alone"] = ("a", ([C2], "rho", False))
    for T in THRESHOLDS:
        for fu in FUSIONS:
            v[f"colour + orient(T={T}), {fu}"] = ("b", ([C3, Feature("orient", T=T)], fu, False))
    for fu in FUSIONS:
        v[f"colour + mag16, {fu}"] = ("c", ([C3, Feature("mag")], fu, False))
    for fu in ("rho", "disc"):  # confidence/scale from a colour pass at the fused centre
        v[f"colour + orient(T=64), {fu}, final pass"] = ("b", ([C3, Feature("orient", T=64)], fu, True))
        v[f"colour + mag16, {fu}, final pass"] = ("c", ([C3, Feature("mag")], fu, True))
    for T in THRESHOLDS:
        v[f"joint colour 2b x orient(T={T}) (576 bins)"] = ("d", ([Feature("joint", T=T, bits=2)], "rho", False))
    v["joint colour 3b x orient(T=64) (4608 bins)"] = ("d", ([Feature("joint", T=64, bits=3)], "rho", False))
    v["joint colour 1b x orient(T=64) (72 bins)"] = ("d", ([Feature("joint", T=64, bits=1)], "rho", False))
    for T in (32, 64):
        v[f"orient(T={T}) alone"] = ("e", ([Feature("orient", T=T)], "rho", False))
    v["mag16 alone"] = ("e", ([Feature("mag")], "rho", False))
    return v


def make(args):
    if args is None:
        from mstrack import Tracker
        return Tracker(model="float", preset="v2")
    feats, fusion, final = args
    return MultiFeatureV2(feats, fusion=fusion, final_pass=final)


_SEQS = None


def _run(job):
    label, args, data = job
    global _SEQS
    if _SEQS is None:
        _SEQS = load_dataset(data)
    t0 = time.perf_counter()
    runs = {s.name: run_sequence(make(args), s, label=label) for s in _SEQS}
    return label, runs, time.perf_counter() - t0


ROBUST = (BASELINE, "colour + orient(T=16), disc_frame", "colour + orient(T=32), disc_frame",
          "colour + orient(T=64), disc_frame", "colour + orient(T=32), disc", "colour + mag16, disc_frame",
          "colour + mag16, tie", "joint colour 2b x orient(T=16) (576 bins)",
          "joint colour 2b x orient(T=64) (576 bins)")
PERTURB = ("OPE", "TRE 1/3", "TRE 2/3", "SRE x-", "SRE x+", "SRE y-", "SRE y+", "SRE s0.9", "SRE s1.1")


class _Shifted:
    """Wraps a tracker: init with the box moved / scaled (SRE)."""

    def __init__(self, inner, kind: str) -> None:
        self.inner, self.kind = inner, kind

    def init(self, frame, box):
        x, y, w, h = Box.of(box).as_tuple()
        cx, cy = x + w / 2, y + h / 2
        if self.kind.startswith("SRE s"):
            k = float(self.kind[5:])
            w, h = w * k, h * k
        else:
            sgn = -1.0 if self.kind.endswith("-") else 1.0
            if "x" in self.kind:
                cx += sgn * 0.1 * w
            else:
                cy += sgn * 0.1 * h
        return self.inner.init(frame, (cx - w / 2, cy - h / 2, w, h))

    def update(self, frame):
        return self.inner.update(frame)


def perturbed(seq, kind: str, tracker):
    """(sequence, tracker) for one start of the robustness run."""
    if kind.startswith("TRE"):
        s = len(seq) // 3 * (1 if kind.endswith("1/3") else 2)
        ok = np.nonzero(valid_gt(seq.gt[s:]))[0]
        s += int(ok[0])
        return replace(seq, img_files=seq.img_files[s:], gt=seq.gt[s:]), tracker
    if kind.startswith("SRE"):
        return seq, _Shifted(tracker, kind)
    return seq, tracker


def _run_robust(job):
    label, args, kind, data = job
    global _SEQS
    if _SEQS is None:
        _SEQS = load_dataset(data)
    runs = {}
    for s in _SEQS:
        s2, trk = perturbed(s, kind, make(args))
        runs[s.name] = (s2, run_sequence(trk, s2, label=label))
    return label, kind, runs


def robust(a, names) -> str:
    from mstrack.eval.metrics import concat_scores, score
    vs = variants()
    jobs = [(label, vs[label][1], kind, a.data) for label in ROBUST for kind in PERTURB]
    res: dict = {}
    with mp.get_context("fork").Pool(a.jobs) as pool:
        for label, kind, runs in pool.imap_unordered(_run_robust, jobs):
            res[(label, kind)] = [score(r.boxes, s2.gt[:r.n_frames]) for s2, r in runs.values()]
            print(f"  {label} / {kind}", file=sys.stderr)
    auc = {k: concat_scores(v).auc for k, v in res.items()}
    head = ["variant", "all 9", "d all 9", "wins /8"] + list(PERTURB)
    lines = ["| " + " | ".join(head) + " |", "|---|" + "|".join(["---:"] * (len(head) - 1)) + "|"]
    base_all = concat_scores([x for k in PERTURB for x in res[(BASELINE, k)]]).auc
    for label in ROBUST:
        allv = concat_scores([x for k in PERTURB for x in res[(label, k)]]).auc
        wins = sum(auc[(label, k)] > auc[(BASELINE, k)] for k in PERTURB[1:])
        lines.append(f"| {label} | {allv:.3f} | {allv - base_all:+.3f} | "
                     f"{'-' if label == BASELINE else wins} | " + " | ".join(f"{auc[(label, k)]:.3f}" for k in PERTURB) + " |")
    return "\n".join(lines) + "\n"


def check_reproduces(seqs) -> None:
    """MultiFeatureV2([colour 3b]) must give FloatTrackerV2's boxes on every frame."""
    for s in seqs:
        a = run_sequence(make(None), s).boxes
        b = run_sequence(make(([Feature("colour", bits=3)], "rho", False)), s).boxes
        if not np.array_equal(a, b):
            raise SystemExit(f"MultiFeatureV2(colour) differs from FloatTrackerV2 on {s.name}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default=str(Path(__file__).resolve().parents[2] / "shared/data/sequences"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--md", help="also write the table (markdown) to this file")
    ap.add_argument("--robust", action="store_true", help="the shortlist under perturbed starts (TRE/SRE)")
    a = ap.parse_args(argv)
    seqs = load_dataset(a.data)
    names = [s.name for s in seqs]
    if a.robust:
        out = robust(a, names)
        print(out)
        if a.md:
            Path(a.md).write_text(out)
        return 0
    check_reproduces(seqs)
    print("check: MultiFeatureV2(colour) == FloatTrackerV2 on every frame of every sequence", file=sys.stderr)
    vs = variants()
    jobs = [(label, args, a.data) for label, (_, args) in vs.items()]
    runs, secs = {}, {}
    with mp.get_context("fork").Pool(a.jobs) as pool:
        for label, r, t in pool.imap_unordered(_run, jobs):
            runs[label], secs[label] = r, t
            print(f"  {label}: {t:.0f} s", file=sys.stderr)
    runs = {label: runs[label] for label in vs}
    ev = aggregate(runs, seqs)
    base = ev.overall[BASELINE].auc
    short = {"MotorRolling": "MotorR", "Football1": "Footb1", "ball1_vot": "ball1", "bag_vot": "bag"}
    head = ["group", "variant", "AUC", "d AUC", "mean"] + [short.get(n, n) for n in names]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(["---"] * 2 + ["---:"] * (len(head) - 2)) + "|"]
    for label, (group, _) in vs.items():
        o = ev.overall[label].auc
        per = [ev.per_sequence[label][n].auc for n in names]
        lines.append(f"| {group} | {label} | {o:.3f} | {o - base:+.3f} | {np.mean(per):.3f} | "
                     + " | ".join(f"{x:.3f}" for x in per) + " |")
    out = "\n".join(lines) + "\n"
    print(out)
    if a.md:
        Path(a.md).write_text(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
