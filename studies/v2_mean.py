"""The mean-AUC target: mean AUC over the dev sequences of tracker v2 variants.

Every variant runs on every sequence with the same parameters (no per-sequence choice), one
pass (OPE), scored as ``mstrack eval`` (mstrack.eval.evaluate.run_sequence + aggregate).  Prints the
overall (frame-weighted) AUC, the mean of the per-sequence AUCs, the per-sequence AUCs and the
wins / losses against the default v2 on the sequences (docs/results_v2_mean.md).

    PYTHONPATH=. python studies/v2_mean.py [--data DIR] [--jobs 2] [--only LABEL ...] [--md OUT.md]
    PYTHONPATH=. python studies/v2_mean.py --robust LABEL ...
    PYTHONPATH=. python studies/v2_mean.py --loss-grid LABEL ...

``--loss-grid``: for FloatTrackerV2 variants, the loss flag's thresholds (loss_rho, loss_contrast)
chosen again on a 0.01 grid as docs/algorithm.md v2.7a does (the highest recall with false alarms
<= 0.05, in sample; the boxes do not depend on the flag, so this re-scores one run exactly).

``--robust``: the given variants and the baseline under the 8 perturbed starts of
studies/v2_features.py (TRE at n//3 and 2n//3, SRE shifts +-10 % and scales 0.9 / 1.1): overall
AUC and mean over sequences per start, over all 9 starts, and wins on the 8 perturbed starts.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mstrack import Tracker  # noqa: E402
from mstrack.io.data import load_dataset  # noqa: E402
from mstrack.eval.evaluate import aggregate, run_sequence  # noqa: E402
from mstrack.track.features_v2 import Feature, MultiFeatureV2  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

BASELINE = "v2 default (float)"


def variants() -> dict[str, tuple]:
    """label -> (kind, kwargs): kind "v2" = Tracker(model, preset="v2", **kwargs); "multi" =
    MultiFeatureV2(colour + orient(T=32), disc_frame) with TrackerParams(preset="v2", **kwargs)."""
    v: dict[str, tuple] = {BASELINE: ("v2", {})}
    for g in (0.5, 1.0):
        v[f"motion_gain {g}"] = ("v2", {"motion_gain": g})
    v["orient(T=32) disc_frame"] = ("multi", {})
    v["orient(T=32) disc_frame + scale_test 0.05 gate"] = ("multi", {"scale_test": 0.05, "scale_test_gate": True})
    v["orient(T=32) disc_frame + scale_test 0.02 mix 0.5"] = ("multi", {"scale_test": 0.02, "scale_test_mix": 0.5})
    for d in (0.03, 0.1):
        v[f"orient(T=32) disc_frame + scale_test {d} gate"] = ("multi", {"scale_test": d, "scale_test_gate": True})
    g = {"scale_test": 0.05, "scale_test_gate": True}
    for T in (16, 64):
        v[f"orient(T={T}) disc_frame + scale_test 0.05 gate"] = (f"multi:{T}", g)
    for T in (32, 64):
        v[f"joint colour 3b x orient(T={T}) + scale_test 0.05 gate"] = (f"joint:{T}:3", g)
    v["joint colour 3b x orient(T=64)"] = ("joint:64:3", {})
    for k, x in (("scale_reg", 0.05), ("scale_reg", 0.2), ("scale_gain", 0.5), ("scale_gain", 0.2)):
        v[f"orient(T=32) disc_frame + scale_test 0.05 gate, {k} {x}"] = ("multi", {**g, k: x})
    for T in (32, 64):
        v[f"v2 orient_T {T} + scale_test 0.05 gate (FloatTrackerV2)"] = ("v2", {**g, "orient_T": T})
    v["v2 orient_T 64 (FloatTrackerV2)"] = ("v2", {"orient_T": 64})
    for d in (0.03, 0.1):
        v[f"v2 orient_T 64 + scale_test {d} gate"] = ("v2", {"scale_test": d, "scale_test_gate": True, "orient_T": 64})
    for T in (48, 96, 128):
        v[f"v2 orient_T {T} + scale_test 0.05 gate"] = ("v2", {**g, "orient_T": T})
    for k, x in (("max_iter", 10), ("max_iter", 15), ("search_iter", 3)):
        v[f"v2 orient_T 64 + scale_test 0.05 gate, {k} {x}"] = ("v2", {**g, "orient_T": 64, k: x})
    v["fixed v2 default"] = ("v2fixed", {})
    v["float v2 default (for --loss-grid)"] = ("v2", {})
    v["fixed v2 orient_T 64 + scale_test 0.05 gate"] = ("v2fixed", {**g, "orient_T": 64})
    v["v2 orient_T 64 + scale_test 0.05 gate, colour_bits 2"] = ("v2", {**g, "orient_T": 64, "colour_bits": 2})
    for T in (32, 48):
        v[f"v2 orient_T {T} + scale_test 0.05 gate, colour_bits 2"] = ("v2", {**g, "orient_T": T, "colour_bits": 2})
    for T in (48, 64):
        v[f"fixed v2 orient_T {T} + scale_test 0.05 gate, colour_bits 2"] = ("v2fixed", {**g, "orient_T": T, "colour_bits": 2})
    v["kernel epanechnikov"] = ("v2", {"kernel": "epanechnikov"})
    v["eps2 0.25"] = ("v2", {"eps2": 0.25})
    v["colour_bits 4"] = ("v2", {"colour_bits": 4})
    v["search_step 0.5"] = ("v2", {"search_step": 0.5})
    v["conf_lost 0.45"] = ("v2", {"conf_lost": 0.45})
    for d in (0.05, 0.1):
        v[f"scale_test {d} gate"] = ("v2", {"scale_test": d, "scale_test_gate": True})
    for d in (0.02, 0.05, 0.1):
        for m in (1.0, 0.5):
            v[f"scale_test {d} mix {m}"] = ("v2", {"scale_test": d, "scale_test_mix": m})
    return v


def make(kind: str, kw: dict):
    if kind == "v2":
        return Tracker(model="float", preset="v2", **kw)
    if kind == "v2fixed":
        return Tracker(model="fixed", preset="v2", **kw)
    # "multi" = colour + orient(T=32), disc_frame; "multi:T" = another threshold; "joint:T:b" = the
    # joint colour b bits x orient(T) histogram as the only feature
    parts = kind.split(":")
    params = TrackerParams(preset="v2", **kw)
    if parts[0] == "joint":
        return MultiFeatureV2([Feature("joint", T=int(parts[1]), bits=int(parts[2]))], fusion="rho", params=params)
    T = int(parts[1]) if len(parts) > 1 else 32
    return MultiFeatureV2([Feature("colour", bits=3), Feature("orient", T=T)], fusion="disc_frame", params=params)


_SEQS = None


def _run(job):
    label, kind, kw, data = job
    global _SEQS
    if _SEQS is None:
        _SEQS = load_dataset(data)
    t0 = time.perf_counter()
    runs = {s.name: run_sequence(make(kind, kw), s, label=label) for s in _SEQS}
    return label, runs, time.perf_counter() - t0


def _run_robust(job):
    label, kind, kw, pert, data = job
    global _SEQS
    if _SEQS is None:
        _SEQS = load_dataset(data)
    from v2_features import perturbed
    runs = []
    for s in _SEQS:
        s2, trk = perturbed(s, pert, make(kind, kw))
        runs.append((s2, run_sequence(trk, s2, label=label)))
    return label, pert, runs


def robust(a, labels: list[str]) -> str:
    from v2_features import PERTURB
    from mstrack.eval.metrics import concat_scores, score
    vs = variants()
    labels = [BASELINE] + [x for x in labels if x != BASELINE]
    jobs = [(lb, *vs[lb], k, a.data) for lb in labels for k in PERTURB]
    res: dict = {}
    with mp.get_context("fork").Pool(a.jobs) as pool:
        for lb, k, runs in pool.imap_unordered(_run_robust, jobs):
            res[(lb, k)] = [score(r.boxes, s2.gt[:r.n_frames]) for s2, r in runs]
            print(f"  {lb} / {k}", file=sys.stderr, flush=True)
    auc = {key: concat_scores(v).auc for key, v in res.items()}
    mean = {key: float(np.mean([x.auc for x in v])) for key, v in res.items()}
    head = ["variant", "all 9 AUC", "all 9 mean", "wins /8 (AUC, mean)"] + [f"{k} AUC / mean" for k in PERTURB]
    lines = ["| " + " | ".join(head) + " |", "|---|" + "|".join(["---:"] * (len(head) - 1)) + "|"]
    for lb in labels:
        all_auc = concat_scores([x for k in PERTURB for x in res[(lb, k)]]).auc
        all_mean = float(np.mean([mean[(lb, k)] for k in PERTURB]))
        wa = sum(auc[(lb, k)] > auc[(BASELINE, k)] for k in PERTURB[1:])
        wm = sum(mean[(lb, k)] > mean[(BASELINE, k)] for k in PERTURB[1:])
        lines.append(f"| {lb} | {all_auc:.3f} | {all_mean:.3f} | {'-' if lb == BASELINE else f'{wa}, {wm}'} | "
                     + " | ".join(f"{auc[(lb, k)]:.3f} / {mean[(lb, k)]:.3f}" for k in PERTURB) + " |")
    return "\n".join(lines) + "\n"


def loss_figures(runs: dict, seqs) -> tuple[float, float]:
    """The loss flag on the frames after init (as studies/loss_study.py scores it, with the default
    thresholds; MultiFeatureV2 reports the search state instead): recall = share of off-target
    frames (IoU = 0) not ok, false alarms = share of on-target frames (IoU >= 0.5) not ok."""
    from mstrack.eval.metrics import iou, valid_gt
    off = on = off_f = on_f = 0
    for s in seqs:
        r = runs[s.name]
        gt = s.gt[:r.n_frames]
        v = valid_gt(gt)
        v[0] = False
        io = np.full(len(gt), np.nan)
        io[v] = iou(r.boxes[v], gt[v])
        flag = np.array([st in ("uncertain", "lost") for st in r.status])
        off += int(np.sum(io == 0)); off_f += int(np.sum((io == 0) & flag))
        on += int(np.sum(io >= 0.5)); on_f += int(np.sum((io >= 0.5) & flag))
    return off_f / max(off, 1), on_f / max(on, 1)


def loss_grid(a, labels: list[str]) -> str:
    from mstrack.eval.metrics import iou, valid_gt
    seqs = load_dataset(a.data)
    vs = variants()
    lines = ["| variant | loss_rho | loss_contrast | recall | false alarms |", "|---|---:|---:|---:|---:|"]
    data: dict = {}
    sid: dict = {}
    for lb in [BASELINE] + [x for x in labels if x != BASELINE]:
        kind, kw = vs[lb]
        if kind not in ("v2", "v2fixed"):
            raise SystemExit(f"--loss-grid needs a Tracker variant, not {lb!r}")
        R, C, S, IO, SID = [], [], [], [], []
        for k_s, s in enumerate(seqs):
            t = make(kind, kw)
            r0 = t.init(s.frame(0), s.init_box())
            rho0 = r0.rho_c
            boxes = []
            for i in range(1, len(s)):
                r = t.update(s.frame(i))
                boxes.append(r.box.as_tuple())
                u = 65536.0 if kind == "v2fixed" else 1.0  # the fixed model's extras are Q.16
                R.append(r.extra["rho_s"] / u / rho0 if rho0 > 0 else 0.0)
                C.append(r.extra["contrast_s"] / u)
                S.append(r.extra["share"])
            gt = s.gt[1:len(s)]
            io = np.full(len(gt), np.nan)
            v = valid_gt(gt)
            io[v] = iou(np.array(boxes)[v], gt[v])
            IO.append(io)
            SID.append(np.full(len(gt), k_s))
        R, C, S, io = np.array(R), np.array(C), np.array(S), np.concatenate(IO)
        data[lb] = (R, C, S, io == 0, io >= 0.5)
        sid[lb] = np.concatenate(SID)
        best = (-1.0, 0.0, 0.0, 0.0)
        for lr, lc, (rec, fa) in grid(data[lb]):
            if fa <= 0.05 and rec > best[0]:
                best = (rec, fa, lr, lc)
        lines.append(f"| {lb} | {best[2]:.2f} | {best[3]:.2f} | {best[0]:.3f} | {best[1]:.3f} |")
        print(lines[-1], file=sys.stderr, flush=True)
    others = [lb for lb in data if lb != BASELINE]
    if len(others) > 1:  # one pair for all of them: the highest lowest recall, every FA <= 0.05
        best = None
        per = [list(grid(data[lb])) for lb in others]
        for k in range(len(per[0])):
            lr, lc = per[0][k][:2]
            rf = [per[i][k][2] for i in range(len(others))]
            if all(fa <= 0.05 for _, fa in rf) and (best is None or min(r for r, _ in rf) > best[0]):
                best = (min(r for r, _ in rf), lr, lc, rf)
        if best:
            lines.append(f"| one pair for: {' / '.join(others)} | {best[1]:.2f} | {best[2]:.2f} | "
                         + " / ".join(f"{r:.3f}" for r, _ in best[3]) + " | "
                         + " / ".join(f"{fa:.3f}" for _, fa in best[3]) + " |")
        # leave one sequence out: the pair chosen on 9 sequences, its flags on the 10th
        flags = {lb: np.zeros(len(data[lb][0]), bool) for lb in others}
        for k_s in range(len(seqs)):
            tr = {lb: tuple(a[sid[lb] != k_s] for a in data[lb]) for lb in others}
            per = [list(grid(tr[lb])) for lb in others]
            best = None
            for k in range(len(per[0])):
                rf = [per[i][k][2] for i in range(len(others))]
                if all(fa <= 0.05 for _, fa in rf) and (best is None or min(r for r, _ in rf) > best[0]):
                    best = (min(r for r, _ in rf), per[0][k][0], per[0][k][1])
            for lb in others:
                R, C, S, _, _ = data[lb]
                m = sid[lb] == k_s
                flags[lb][m] = (S[m] == 0) | ((R[m] < best[1]) & (C[m] < best[2]))
        rec = [flags[lb][data[lb][3]].mean() for lb in others]
        fa = [flags[lb][data[lb][4]].mean() for lb in others]
        lines.append("| the same, leave one sequence out | - | - | " + " / ".join(f"{r:.3f}" for r in rec) + " | "
                     + " / ".join(f"{f:.3f}" for f in fa) + " |")
    return "\n".join(lines) + "\n"


def grid(d):
    """(loss_rho, loss_contrast, (recall, false alarms)) on the 0.01 grid."""
    R, C, S, off, on = d
    for lr in np.round(np.arange(0.50, 1.201, 0.01), 2):
        for lc in np.round(np.arange(-0.20, 0.601, 0.01), 2):
            f = (S == 0) | ((R < lr) & (C < lc))
            yield lr, lc, (float(f[off].mean()), float(f[on].mean()))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default=str(Path(__file__).resolve().parents[2] / "shared/data/sequences"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", nargs="*", help="labels to run (the baseline always runs)")
    ap.add_argument("--md", help="also write the table (markdown) to this file")
    ap.add_argument("--robust", nargs="+", metavar="LABEL", help="these variants under perturbed starts")
    ap.add_argument("--loss-grid", nargs="+", metavar="LABEL", help="loss thresholds chosen again")
    a = ap.parse_args(argv)
    if a.loss_grid:
        out = loss_grid(a, a.loss_grid)
        print(out)
        return 0
    if a.robust:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        out = robust(a, a.robust)
        print(out)
        if a.md:
            Path(a.md).write_text(out)
        return 0
    seqs = load_dataset(a.data)
    names = [s.name for s in seqs]
    vs = variants()
    if a.only:
        vs = {k: v for k, v in vs.items() if k == BASELINE or k in a.only}
    jobs = [(label, kind, kw, a.data) for label, (kind, kw) in vs.items()]
    runs = {}
    with mp.get_context("fork").Pool(a.jobs) as pool:
        for label, r, t in pool.imap_unordered(_run, jobs):
            runs[label] = r
            print(f"  {label}: {t:.0f} s", file=sys.stderr, flush=True)
    runs = {label: runs[label] for label in vs}
    ev = aggregate(runs, seqs)
    base = [ev.per_sequence[BASELINE][n].auc for n in names]
    short = {"MotorRolling": "MotorR", "Football1": "Footb1", "ball1_vot": "ball1", "bag_vot": "bag"}
    head = ["variant", "AUC", "mean", "wins/losses", "loss flag recall / FA"] + [short.get(n, n) for n in names]
    lines = ["| " + " | ".join(head) + " |", "|---|" + "|".join(["---:"] * (len(head) - 1)) + "|"]
    for label in vs:
        per = [ev.per_sequence[label][n].auc for n in names]
        w = sum(x > b + 1e-9 for x, b in zip(per, base))
        lo = sum(x < b - 1e-9 for x, b in zip(per, base))
        rec, fa = loss_figures(runs[label], seqs)
        lines.append(f"| {label} | {ev.overall[label].auc:.3f} | {np.mean(per):.3f} | "
                     f"{'-' if label == BASELINE else f'{w}/{lo}'} | {rec:.2f} / {fa:.3f} | "
                     + " | ".join(f"{x:.3f}" for x in per) + " |")
    out = "\n".join(lines) + "\n"
    print(out)
    if a.md:
        Path(a.md).write_text(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
