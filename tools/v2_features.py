"""Tracker v2: edge feature and fusion variants, measured (issue 10, item 5).

Runs tracker v2 variants (mstrack/features_v2.py) over every sequence of a
dataset, one-pass (OPE), and scores them exactly as ``mstrack eval`` does
(mstrack.evaluate.run_sequence + aggregate: frame-weighted AUC over all
frames, the mean of the per-sequence AUCs, and the per-sequence AUCs).

The baseline row is FloatTrackerV2 itself (``Tracker(model="float",
preset="v2")``); before anything is reported the tool checks that
MultiFeatureV2 with the colour feature alone gives the same boxes on every
frame (so the variants differ from the baseline only in what they add).
Parameters are the same on every sequence.

    .venv/bin/python tools/v2_features.py [--data DIR] [--jobs 2] [--md OUT.md]
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mstrack.data import load_dataset  # noqa: E402
from mstrack.evaluate import aggregate, run_sequence  # noqa: E402
from mstrack.features_v2 import Feature, MultiFeatureV2  # noqa: E402

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
    a = ap.parse_args(argv)
    seqs = load_dataset(a.data)
    names = [s.name for s in seqs]
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
