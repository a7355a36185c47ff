"""Issue 10, loss signal: per-frame signals of tracker v2 (float and fixed) against the IoU.

Usage::

    python tools/loss_study.py dump [SEQ_ROOT]     # runs float + fixed v2, writes out/loss_study/*.npz
    python tools/loss_study.py report              # signals -> docs/results_loss.md (+ plot)

``dump`` runs the v2 tracker as it is (``preset="v2"``) on every sequence and keeps, per
frame after the init frame: IoU with the ground truth (NaN where invalid), status, confidence,
rho, share, the references the decision used, the target statistics nt, nt_in, n_in and the
window's pixel count n (K in the fixed model), w / w0, iterations, the centre jump (in box
diameters) and the decimation.  ``report`` scores candidate loss rules on those frames: recall
= share of off-target frames (IoU = 0) flagged, false alarms = share of on-target frames
(IoU >= 0.5) flagged, with the thresholds chosen once for the whole set and leave-one-sequence-
out (thresholds chosen on 9 sequences, scored on the 10th).
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mstrack.data import load_dataset  # noqa: E402
from mstrack.metrics import iou, valid_gt  # noqa: E402
from mstrack.tracker import Tracker  # noqa: E402
from mstrack.types import Status  # noqa: E402

OUT = ROOT / "out" / "loss_study"
FIELDS = ("iou", "ok", "lost", "conf", "rho", "share", "rho_ref", "share_ref", "nt", "nt_in", "n_in", "n",
          "scale", "iters", "jump", "dec")


def main_dump(root: str) -> None:
    seqs = load_dataset(root)
    OUT.mkdir(parents=True, exist_ok=True)
    for model in ("float", "fixed"):
        data = {}
        for seq in seqs:
            trk = Tracker(model=model, preset="v2")
            impl = trk.impl
            rows, boxes = [], []
            res = trk.init(seq.frame(0), seq.init_box())
            prev, w0 = res.centre, res.box.w
            for i in range(1, len(seq)):
                if model == "fixed":
                    rr, sr, one = impl.rho_ref, impl.share_ref, 65536.0
                else:
                    rr, sr, one = impl._rho_ref, impl._share_ref, 1.0
                res = trk.update(seq.frame(i))
                e = res.extra
                d = e["decimation"]
                n = e["K"] if model == "fixed" else e["n"]
                rho, share = (e["rho"] / one, e["share"] / one) if model == "fixed" else (res.rho_c, e["share"])
                jump = math.hypot(res.centre[0] - prev[0], res.centre[1] - prev[1]) / max(res.box.w, res.box.h)
                prev = res.centre
                boxes.append(res.box.as_tuple())
                rows.append((np.nan, res.ok, res.status == Status.LOST, res.confidence, rho, share, rr / one,
                             sr / one, e["nt"], e["nt_in"], e["n_in"], n, res.box.w / w0, res.iter_c, jump, d))
            a = np.array(rows, dtype=np.float64)
            gt = seq.gt[1:len(seq)]
            v = valid_gt(gt)
            io = np.full(len(gt), np.nan)
            io[v] = iou(np.array(boxes)[v], gt[v])
            a[:, 0] = io
            for k, f in enumerate(FIELDS):
                data[f"{seq.name}/{f}"] = a[:, k]
            print(model, seq.name, len(rows), flush=True)
        np.savez(OUT / f"{model}.npz", **data)


def load(model: str) -> dict[str, dict[str, np.ndarray]]:
    z = np.load(OUT / f"{model}.npz")
    out: dict[str, dict[str, np.ndarray]] = {}
    for k in z.files:
        s, f = k.split("/")
        out.setdefault(s, {})[f] = z[k]
    return out


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        main_dump(sys.argv[2] if len(sys.argv) > 2 else str(ROOT.parent / "shared" / "data" / "sequences"))
