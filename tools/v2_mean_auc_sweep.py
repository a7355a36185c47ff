"""Issue 10, secondary target (mean AUC over sequences >= CSRT's 0.562): float v2 with one
parameter moved at a time from its default; prints overall AUC, mean AUC over sequences and the
per-sequence AUCs.

Usage: python tools/v2_mean_auc_sweep.py [SEQ_ROOT]
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mstrack import Tracker  # noqa: E402
from mstrack.io.data import load_dataset  # noqa: E402
from mstrack.eval.metrics import IOU_THRESHOLDS, iou, valid_gt  # noqa: E402

VARIANTS = [("default", {})] + [(f"{k} {v}", {k: v}) for k, vals in (
    ("pad", (0.1875, 0.3125, 0.375)), ("scale_gain", (0.2, 0.4)), ("scale_reg", (0.05, 0.2)),
    ("scale_step", (0.05, 0.15)), ("bg_ring", (0.5, 0.75, 1.0)), ("conf_lost", (0.3,)),
    ("max_iter", (10, 30))) for v in vals]


def run(seqs, frames, **kw) -> tuple[float, float, list[float]]:
    per, allio = [], []
    for s in seqs:
        t = Tracker(model="float", preset="v2", **kw)
        bx = []
        for i, fr in enumerate(frames[s.name]):
            r = t.init(fr, s.init_box()) if i == 0 else t.update(fr)
            bx.append(r.box.as_tuple())
        gt = s.gt[:len(bx)]
        v = valid_gt(gt)
        io = iou(np.array(bx)[v], gt[v])
        allio.append(io)
        per.append(float(np.mean([(io > th).mean() for th in IOU_THRESHOLDS])))
    io = np.concatenate(allio)
    return float(np.mean([(io > th).mean() for th in IOU_THRESHOLDS])), float(np.mean(per)), per


def main() -> None:
    root = sys.argv[1] if len(sys.argv) > 1 else str(ROOT.parent / "shared" / "data" / "sequences")
    seqs = load_dataset(root)
    frames = {s.name: [s.frame(i) for i in range(len(s))] for s in seqs}
    print("| variant | AUC | mean AUC | " + " | ".join(s.name for s in seqs) + " |")
    print("|---|---:|---:|" + "---:|" * len(seqs))
    for name, kw in VARIANTS:
        a, m, per = run(seqs, frames, **kw)
        print(f"| {name} | {a:.3f} | {m:.3f} | " + " | ".join(f"{x:.2f}" for x in per) + " |", flush=True)


if __name__ == "__main__":
    main()
