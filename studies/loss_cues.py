"""Loss signal: two more cues for the loss flag, measured (not adopted).

Usage::

    python studies/loss_cues.py dump [SEQ_ROOT]   # runs float + fixed v2, writes out/loss_cues/{float,fixed}.json
    python studies/loss_cues.py report            # -> docs/results_loss_cues.md

Per frame after the init frame (the v2 defaults; the flag does not steer the tracker, so the
boxes are those of docs/results.md): IoU, the adopted flag's inputs rs = rho_s / rho0 and
con = contrast_s, the share, and two candidate cues:

* **ceiling**: rs itself, flagged when rs > h (the window matches the model clearly better than the
  init box did: a distractor made of the target's colours only);
* **template**: the normalised cross-correlation (NCC) of the box's grey image, resized to 16 x 16
  (OpenCV INTER_AREA), with the init box's, smoothed like the other signals (s <- s + (x - s) / 2,
  from 1); flagged when below c.

Rules: flagged = share = 0 or (rs < a and con < b) [or rs > h] [or ncc_s < c].  Thresholds chosen
once for both models on the grid below (the highest lower recall of float and fixed, both
false-alarm rates <= 0.05, as the defaults were chosen), and leave one sequence out (the same
choice made on 9 sequences, scored on the 10th, counts summed).
"""
from __future__ import annotations

import itertools
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OUT = ROOT / "out" / "loss_cues"
DOC = ROOT / "docs" / "results_loss_cues.md"
FA_MAX = 0.05
N_T = 16                                         # template side (px)
GA = np.round(np.arange(0.84, 0.921, 0.01), 2)   # loss_rho
GB = np.round(np.arange(0.14, 0.241, 0.01), 2)   # loss_contrast
GH = np.append(np.round(np.arange(1.02, 1.121, 0.01), 2), np.inf)   # ceiling (inf: off)
GC = np.append(np.round(np.arange(-0.30, 0.101, 0.02), 2), -np.inf)  # template (-inf: off)


def _template(frame: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray | None:
    import cv2
    x, y, w, h = box
    H, W = frame.shape[:2]
    x0, y0 = max(int(round(x)), 0), max(int(round(y)), 0)
    x1, y1 = min(int(round(x + w)), W), min(int(round(y + h)), H)
    if x1 - x0 < 2 or y1 - y0 < 2:
        return None
    g = cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY).astype(np.float32)
    t = cv2.resize(g, (N_T, N_T), interpolation=cv2.INTER_AREA).astype(np.float64).ravel()
    t -= t.mean()
    n = np.linalg.norm(t)
    return t / n if n > 0 else t


def main_dump(root: str) -> None:
    from mstrack.eval.metrics import iou, valid_gt
    from mstrack.io.data import load_dataset
    from mstrack.track.tracker import Tracker
    OUT.mkdir(parents=True, exist_ok=True)
    seqs = load_dataset(root)
    for model in ("float", "fixed"):
        one = 65536.0 if model == "fixed" else 1.0
        out = {}
        for seq in seqs:
            trk = Tracker(model=model, preset="v2")
            res = trk.init(seq.frame(0), seq.init_box())
            rho0 = res.rho_c
            t0 = _template(seq.frame(0), res.box.as_tuple())
            rows, boxes = [], []
            for i in range(1, len(seq)):
                fr = seq.frame(i)
                res = trk.update(fr)
                e = res.extra
                t = _template(fr, res.box.as_tuple())
                ncc = float(t @ t0) if t is not None and t0 is not None else 0.0
                boxes.append(res.box.as_tuple())
                rows.append((float(res.ok), e["rho_s"] / one / rho0 if rho0 > 0 else 0.0, e["contrast_s"] / one,
                             e["share"] / one, ncc))
            a = np.array(rows, dtype=np.float64)
            gt = seq.gt[1:len(seq)]
            v = valid_gt(gt)
            io = np.full(len(gt), np.nan)
            io[v] = iou(np.array(boxes)[v], gt[v])
            out[seq.name] = {"iou": io.tolist(), "ok": a[:, 0].tolist(), "rs": a[:, 1].tolist(),
                             "con": a[:, 2].tolist(), "share": a[:, 3].tolist(), "ncc": a[:, 4].tolist()}
            print(model, seq.name, len(rows), flush=True)
        (OUT / f"{model}.json").write_text(json.dumps(out))


def _smooth(x: np.ndarray, x0: float) -> np.ndarray:
    y, s = np.empty_like(x), x0
    for i, v in enumerate(x):
        s += 0.5 * (v - s)
        y[i] = s
    return y


def _counts(q: dict[str, np.ndarray]) -> np.ndarray:
    """(len GA, len GB, len GH, len GC, 4): flagged off, off, flagged on, on."""
    io = q["iou"]
    off, on = io == 0, io >= 0.5
    z = q["share"] == 0
    low = (q["rs"][None, None, :] < GA[:, None, None]) & (q["con"][None, None, :] < GB[None, :, None])
    hi = q["rs"][None, :] > GH[:, None]
    tm = q["ncc_s"][None, :] < GC[:, None]
    out = np.zeros((len(GA), len(GB), len(GH), len(GC), 4))
    out[..., 1], out[..., 3] = off.sum(), on.sum()
    for k in range(len(GH)):
        for m in range(len(GC)):
            f = z | low | hi[k] | tm[m]
            out[:, :, k, m, 0] = (f & off).sum(-1)
            out[:, :, k, m, 2] = (f & on).sum(-1)
    return out


def _choose(C: dict[str, np.ndarray], idx: list[int], mask: np.ndarray) -> tuple[tuple[int, ...], dict[str, tuple[float, float]]]:
    rates = {}
    for m, c in C.items():
        t = c[idx].sum(0)
        rates[m] = (t[..., 0] / np.maximum(t[..., 1], 1), t[..., 2] / np.maximum(t[..., 3], 1))
    ok = mask & np.logical_and.reduce([f <= FA_MAX for _, f in rates.values()])
    key = np.where(ok, np.minimum.reduce([r for r, _ in rates.values()]), -1.0)
    j = tuple(int(x) for x in np.unravel_index(int(np.argmax(key)), key.shape))
    return j, {m: (float(r[j]), float(f[j])) for m, (r, f) in rates.items()}


def main_report() -> None:
    from mstrack.versions import tools_line
    data = {}
    for m in ("float", "fixed"):
        raw = json.loads((OUT / f"{m}.json").read_text())
        data[m] = {}
        for s, d in raw.items():
            q = {k: np.array(v, dtype=np.float64) for k, v in d.items()}
            q["ncc_s"] = _smooth(q["ncc"], 1.0)
            data[m][s] = q
    names = list(data["float"])
    C = {m: np.stack([_counts(data[m][s]) for s in names]) for m in data}
    shape = C["float"].shape[1:5]
    ih, ic = np.arange(shape[2]), np.arange(shape[3])
    h_off = (ih == len(GH) - 1)[None, None, :, None]
    c_off = (ic == len(GC) - 1)[None, None, None, :]
    full = np.ones(shape, dtype=bool)
    rules = [("adopted rule: share = 0 or (rs < a and con < b)", full & h_off & c_off),
             ("+ ceiling: or rs > h", full & c_off),
             ("+ template: or ncc_s < c", full & h_off),
             ("+ ceiling + template", full)]
    L = ["# Loss flag: two more cues (measured, not adopted)", "",
         "The target is recall >= 0.6 at false alarms <= 0.05 (docs/results_loss.md has the adopted rule and "
         "the rules tried).  This page measures two cues those rules do not have: a **ceiling** on "
         "rho (rs = rho_s / rho0 > h: the window matches the model clearly better than the init box did) and a "
         f"**template** check (NCC of the box's grey image at {N_T} x {N_T} px against the init box's, smoothed "
         "with rate 1/2, below c).  Commands: `python studies/loss_cues.py dump` (float and fixed v2, default "
         "parameters, about 4 min), `python studies/loss_cues.py report` (this page).", "",
         f"Grid: a {GA[0]:.2f} .. {GA[-1]:.2f}, b {GB[0]:.2f} .. {GB[-1]:.2f} (steps 0.01), h {GH[0]:.2f} .. "
         f"{GH[-2]:.2f} (0.01) or off, c {GC[0]:.2f} .. {GC[-2]:.2f} (0.02) or off.  One set of thresholds for "
         "both models (the highest lower recall, both false-alarm rates <= 0.05); leave one sequence out: the "
         "same choice on 9 sequences, scored on the 10th.  Cells: recall / false alarms.", "",
         "| rule | thresholds (a, b, h, c) | float | fixed | float, leave one out | fixed, leave one out |",
         "|---|---|---|---|---|---|"]
    for label, mask in rules:
        j, r = _choose(C, list(range(len(names))), mask)
        loo = {m: np.zeros(4) for m in C}
        for i in range(len(names)):
            jj, _ = _choose(C, [k for k in range(len(names)) if k != i], mask)
            for m in C:
                loo[m] += C[m][i][jj]
        th = f"{GA[j[0]]:.2f}, {GB[j[1]]:.2f}, " + ("off" if np.isinf(GH[j[2]]) else f"{GH[j[2]]:.2f}") + ", " + \
             ("off" if np.isinf(GC[j[3]]) else f"{GC[j[3]]:.2f}")
        cells = [f"{r[m][0]:.3f} / {r[m][1]:.3f}" for m in C] + \
                [f"{loo[m][0] / loo[m][1]:.3f} / {loo[m][2] / loo[m][3]:.3f}" for m in C]
        L.append(f"| {label} | {th} | " + " | ".join(cells) + " |")
    L += ["", "Per sequence (off-target / on-target frames; medians of rs and of the smoothed NCC on them):", "",
          "| model | sequence | off | on | rs off | rs on | ncc_s off | ncc_s on | frames with rs > 1.05: off / on |",
          "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for m in data:
        for s in names:
            q = data[m][s]
            off, on = q["iou"] == 0, q["iou"] >= 0.5
            med = lambda x, k: f"{np.median(x[k]):.2f}" if k.any() else "-"  # noqa: E731
            hi = q["rs"] > 1.05
            L.append(f"| {m} | {s} | {off.sum()} | {on.sum()} | {med(q['rs'], off)} | {med(q['rs'], on)} | "
                     f"{med(q['ncc_s'], off)} | {med(q['ncc_s'], on)} | {(hi & off).sum()} / {(hi & on).sum()} |")
    L += ["", "## Findings", "",
          "* **The ceiling** lifts the fixed model's recall far above the target on the dev set, almost all of it on "
          "one sequence: in fixed Subway the tracker sits on another person whose colours match the model better "
          "than the init box did (rs about 1.14 on its off-target frames), and on Deer.  It is **not adopted**: it "
          "flags a correctly tracked target that grows, because the window (lagging in size) then holds target "
          "colours only and rho rises above its init value: on the synthetic square growing from 20 to 34 px of "
          "tests/test_fixed_v2.py (`_scene`), rs reaches 1.10 and h = 1.06 flags 22 of its 29 tracked frames in "
          "float and 24 in fixed, all with IoU >= 0.54 (that file's test_fixed_v2_tracks_a_growing_target_like_float "
          "fails with the ceiling).  Approaching targets are common in camera pipelines; a "
          "flag that fires on them is worse than a missed distractor.  It also lowers float's leave-one-out recall.",
          "* **The template** check separates the off-target frames of float Girl and MotorRolling (another face, "
          "the background of the jump), which no colour cue does: float recall rises by about 0.1 in and out of "
          "sample.  The fixed model's misses are elsewhere (Subway: NCC as high off the target as on it), so its "
          "recall barely moves.  It would be a new v2 step in all three layers: a 16 x 16 cell sum of the box's "
          "grey values (one more pass over the window pixels in the region RAM, which holds colour bins only, so "
          "the grey would come from the bins), a 256-entry template RAM per target and one NCC (256 "
          "multiply-adds, a square root and a division) per frame.  Not adopted: it does not bring "
          "the fixed model (the hardware) to the target, and it would move the specification of core v2.  It is the next candidate if the float model's loss signal matters more than the "
          "hardware's.",
          "* With both cues both models pass 0.6 in sample, but the gain of the fixed model is the ceiling's, with "
          "the failure above.", "", tools_line(), ""]
    DOC.write_text("\n".join(L))
    print(f"wrote {DOC}")


if __name__ == "__main__":
    cmd = sys.argv[1] if len(sys.argv) > 1 else "report"
    if cmd == "dump":
        main_dump(sys.argv[2] if len(sys.argv) > 2 else str(ROOT.parent / "shared" / "data" / "sequences"))
    elif cmd == "report":
        main_report()
    else:
        sys.exit(f"unknown command {cmd!r}: dump or report")
