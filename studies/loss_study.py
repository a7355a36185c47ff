"""Loss signal: per-frame signals of tracker v2 (float and fixed) against the IoU.

Usage::

    python studies/loss_study.py dump [SEQ_ROOT]     # runs float + fixed v2, writes out/loss_study/*.npz
    python studies/loss_study.py search [SEQ_ROOT]   # float v2 with the wide search started by the flag
    python studies/loss_study.py report              # -> docs/results_loss.md, docs/results/loss_*.png

``dump`` runs the v2 tracker as it is (``preset="v2"``) on every sequence and keeps, per
frame after the init frame: IoU with the ground truth (NaN where invalid), status, confidence,
rho, share, the references the decision used, the target statistics nt, nt_in, n_in and the
window's pixel count n (K in the fixed model), w / w0, iterations, the centre jump (in box
diameters) and the decimation.  ``report`` scores candidate loss rules on those frames: recall
= share of off-target frames (IoU = 0) flagged, false alarms = share of on-target frames
(IoU >= 0.5) flagged, with the thresholds chosen once for the whole set and leave-one-sequence-
out (thresholds chosen on 9 sequences, scored on the 10th).  The search state of v2 does not
depend on the loss flag, so the boxes (and these signals) are those of any v2 run.  ``search``
measures the alternative: the wide search started by the flag (AUC and loss signal, float).
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mstrack.io.data import load_dataset  # noqa: E402
from mstrack.eval.metrics import iou, valid_gt  # noqa: E402
from mstrack.track.tracker import Tracker  # noqa: E402
from mstrack.track.types import Status  # noqa: E402

OUT = ROOT / "out" / "loss_study"
DOC = ROOT / "docs" / "results_loss.md"
FIELDS = ("iou", "ok", "searching", "conf", "rho", "share", "rho_ref", "share_ref", "nt", "nt_in", "n_in", "n",
          "scale", "iters", "jump", "dec", "rho0", "rho_s", "con_s", "con0")
FA_MAX = 0.05


def default_root() -> str:
    return str(ROOT.parent / "shared" / "data" / "sequences")


# ----------------------------------------------------------------------------- dump
def main_dump(root: str) -> None:
    seqs = load_dataset(root)
    OUT.mkdir(parents=True, exist_ok=True)
    for model in ("float", "fixed"):
        data = {}
        one = 65536.0 if model == "fixed" else 1.0
        for seq in seqs:
            trk = Tracker(model=model, preset="v2")
            impl = trk.impl
            rows, boxes = [], []
            res = trk.init(seq.frame(0), seq.init_box())
            prev, w0, rho0 = res.centre, res.box.w, res.rho_c
            con0 = res.extra["contrast_s"] / one if model == "fixed" else res.extra["share"] - res.extra["ring_share"]
            for i in range(1, len(seq)):
                if model == "fixed":
                    rr, sr = impl.rho_ref, impl.share_ref
                else:
                    rr, sr = impl._rho_ref, impl._share_ref
                res = trk.update(seq.frame(i))
                e = res.extra
                n = e["K"] if model == "fixed" else e["n"]
                share = e["share"] / one
                state_lost = e["state"] == (2 if model == "fixed" else "lost")
                jump = math.hypot(res.centre[0] - prev[0], res.centre[1] - prev[1]) / max(res.box.w, res.box.h)
                prev = res.centre
                boxes.append(res.box.as_tuple())
                rows.append((np.nan, res.ok, state_lost, res.confidence, res.rho_c, share, rr / one, sr / one,
                             e["nt"], e["nt_in"], e["n_in"], n, res.box.w / w0, res.iter_c, jump,
                             e["decimation"], rho0, e["rho_s"] / one, e["contrast_s"] / one, con0))
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


# ----------------------------------------------------------------------------- search variants
def main_search(root: str) -> None:
    """Float v2 with the search state driven by the loss flag: AUC (overall, mean) and loss signal."""
    import json

    import mstrack.track.float_v2 as fv
    from mstrack.eval.metrics import IOU_THRESHOLDS, loss_detection
    from mstrack.track.params import TrackerParams
    from mstrack.track.types import Status

    base = fv.decide_status

    class Probe(fv.FloatTrackerV2):
        """Remembers the pass behind each confidence, so the state rule can see the flag."""

        def _confidence(self, ps):
            c = super()._confidence(ps)
            self._cand[c] = ps
            return c

    out = {}
    for variant in ("confidence", "flag", "flag and confidence < conf_uncertain"):
        def decide(conf, was_lost, p, variant=variant):
            trk = decide.trk
            ps = trk._cand[conf]  # the flag this frame will have (the filters step after the state)
            fl = fv.loss_flag(fv.loss_filter(trk._rho_s, ps.rho, p),
                              fv.loss_filter(trk._con_s, ps.share - ps.ring_share, p), trk._rho0, ps.share, p)
            if variant == "flag":
                if fl:
                    return Status.LOST
                return Status.REACQUIRED if was_lost else (Status.UNCERTAIN if conf < p.conf_uncertain else Status.OK)
            if variant.startswith("flag and") and fl and conf < p.conf_uncertain:
                return Status.LOST
            return base(conf, was_lost, p)
        fv.decide_status = decide
        ious, oks, per = [], [], []
        try:
            for seq in load_dataset(root):
                trk = Probe(TrackerParams(preset="v2"), path="numpy")
                decide.trk = trk
                trk._cand = {}
                boxes, ok = [], []
                trk.init(seq.frame(0), seq.init_box())
                for i in range(1, len(seq)):
                    trk._cand = {}
                    r = trk.update(seq.frame(i))
                    boxes.append(r.box.as_tuple())
                    ok.append(r.ok)
                gt = seq.gt[1:len(seq)]
                v = valid_gt(gt)
                io = iou(np.array(boxes)[v], gt[v])
                ious.append(io)
                oks.append(np.array(ok)[v])
                per.append(float(np.mean([(io > t).mean() for t in IOU_THRESHOLDS])))
        finally:
            fv.decide_status = base
        io = np.concatenate(ious)
        ld = loss_detection(io, np.concatenate(oks))
        out[variant] = {"auc": float(np.mean([(io > t).mean() for t in IOU_THRESHOLDS])),
                        "mean_auc": float(np.mean(per)), "recall": ld.recall, "false_alarm": ld.false_alarm}
        print(variant, out[variant], flush=True)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "search.json").write_text(json.dumps(out, indent=1))


# ----------------------------------------------------------------------------- rules
def signals(d: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Per-frame candidate signals (larger = more like the target)."""
    share = d["nt_in"] / np.maximum(d["n_in"], 1)
    ring = np.where(d["n"] > d["n_in"], (d["nt"] - d["nt_in"]) / np.maximum(d["n"] - d["n_in"], 1), 0.0)
    return {"confidence (today)": d["conf"], "rho / rho_ref": d["rho"] / d["rho_ref"],
            "share / share_ref": d["share"] / d["share_ref"], "rho / rho0": d["rho"] / d["rho0"],
            "share / share0": d["share"] / d["share_ref"][0], "rho": d["rho"], "share": share,
            "contrast = share - ring_share": share - ring, "1 - ring_share / share": 1 - ring / np.maximum(share, 1e-9),
            "-|log(w / w0)|": -np.abs(np.log(d["scale"])), "-jump (box diameters)": -d["jump"],
            "-|log(w / w_prev)| (scale change per frame)": -np.abs(np.diff(np.log(d["scale"]), prepend=0.0)),
            "-iterations": -d["iters"],
            "rho / rho0 change over 8 frames": _trend(d["rho"] / d["rho0"], 1.0, 8),
            "contrast change over 8 frames": _trend(share - ring, d["con0"][0], 8)}


def _trend(x: np.ndarray, x0: float, k: int) -> np.ndarray:
    """x_i - x_(i - k), x before the first frame taken as x0."""
    return x - np.concatenate([np.full(k, x0), x[:-k]])[:len(x)]


def smooth(x: np.ndarray, x0: float, rate: float) -> np.ndarray:
    """The loss flag's filter s <- s + rate (x - s) from s = x0 (float arithmetic)."""
    y = np.empty_like(x)
    s = x0
    for i, v in enumerate(x):
        s += rate * (v - s)
        y[i] = s
    return y


def sequences(model: str, rate: float | None = None) -> list[dict]:
    """Per sequence: rr0 = rho_s / rho0 and con = contrast_s as the tracker smoothed them
    (``rate`` None), or re-smoothed from the raw values with ``rate`` (1: raw)."""
    out = []
    for name, d in load(model).items():
        s = signals(d)
        if rate is None:
            rr0, con = d["rho_s"] / d["rho0"], d["con_s"]
        else:
            rr0 = smooth(s["rho / rho0"], 1.0, rate)
            con = smooth(s["contrast = share - ring_share"], d["con0"][0], rate)
        out.append({"name": name, "rr0": rr0, "con": con,
                    "off": d["iou"] == 0, "on": d["iou"] >= 0.5, "ok": d["ok"].astype(bool), "sig": s})
    return out


def in_sample_and_loo(seqs: list[dict]) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
    """Best (ta, tb) on all sequences with its recall / FA, and the leave-one-out recall / FA."""
    T = pair_table(seqs)
    a, b = pick(T)
    loo = np.zeros(4)
    for i in range(len(seqs)):
        x, y = pick(np.delete(T, i, 0))
        loo += T[i, x, y]
    return (TA[a], TB[b]), rate(T[:, a, b]), rate(loo)


def counts(flags: list[np.ndarray], seqs: list[dict]) -> np.ndarray:
    """Per sequence: flagged off-target, off-target, flagged on-target, on-target."""
    return np.array([((f & q["off"]).sum(), q["off"].sum(), (f & q["on"]).sum(), q["on"].sum())
                     for f, q in zip(flags, seqs)], dtype=np.float64)


def rate(c: np.ndarray) -> tuple[float, float]:
    t = c.sum(0) if c.ndim == 2 else c
    return t[0] / max(t[1], 1), t[2] / max(t[3], 1)


def single_best(seqs: list[dict], key: str) -> tuple[float, float, float]:
    """Recall at FA <= 0.05 of ``signal < threshold`` (the largest threshold that keeps FA)."""
    v = np.concatenate([q["sig"][key] for q in seqs])
    off = np.concatenate([q["off"] for q in seqs])
    on = np.concatenate([q["on"] for q in seqs])
    son = np.sort(v[on])
    t = son[int(np.floor(FA_MAX * len(son)))]
    return float((v[off] < t).mean()), float((v[on] < t).mean()), float(t)


TA = np.round(np.arange(0.70, 1.001, 0.01), 2)
TB = np.round(np.arange(0.00, 0.401, 0.01), 2)


def pair_table(seqs: list[dict]) -> np.ndarray:
    """counts of the rule rr0 < ta and contrast < tb: shape (sequences, len(TA), len(TB), 4)."""
    T = np.zeros((len(seqs), len(TA), len(TB), 4))
    for i, q in enumerate(seqs):
        a = q["rr0"][None, :] < TA[:, None]
        b = q["con"][None, :] < TB[:, None]
        f = a[:, None, :] & b[None, :, :]
        T[i, ..., 0] = (f & q["off"]).sum(-1)
        T[i, ..., 1] = q["off"].sum()
        T[i, ..., 2] = (f & q["on"]).sum(-1)
        T[i, ..., 3] = q["on"].sum()
    return T


def pick(T: np.ndarray) -> tuple[int, int]:
    """Best (ta, tb) index: max recall with FA <= 0.05 (ties: lower FA, then the first)."""
    t = T.sum(0)
    r = t[..., 0] / np.maximum(t[..., 1], 1)
    f = t[..., 2] / np.maximum(t[..., 3], 1)
    score = np.where(f <= FA_MAX, r - 1e-6 * f, -1.0)
    return np.unravel_index(int(np.argmax(score)), score.shape)


def latch_flags(q: dict, ta: float, tb: float, tr: float, tc: float) -> np.ndarray:
    """Latching variant: flagged = (rr0 < ta and con < tb) or (flagged before and rr0 < tr and con < tc)."""
    out = np.zeros(len(q["rr0"]), bool)
    f = False
    for i, (r, c) in enumerate(zip(q["rr0"], q["con"])):
        f = bool((r < ta and c < tb) or (f and r < tr and c < tc))
        out[i] = f
    return out


LATCH_GRID = [(ta, tb, tr, tc) for ta in np.round(np.arange(0.75, 0.91, 0.02), 2)
              for tb in np.round(np.arange(0.06, 0.26, 0.02), 2) for tr in (0.85, 0.9, 0.95, 1.0)
              for tc in (0.3, 0.4, 0.5, 1.0)]


def latch_study(seqs: list[dict]) -> tuple[tuple, tuple[float, float], tuple[float, float]]:
    C = np.array([counts([latch_flags(q, *g) for q in seqs], seqs) for g in LATCH_GRID])  # (grid, seq, 4)

    def best(c):
        t = c.sum(1)
        r, f = t[:, 0] / np.maximum(t[:, 1], 1), t[:, 2] / t[:, 3]
        return int(np.argmax(np.where(f <= FA_MAX, r - 1e-6 * f, -1.0)))
    j = best(C)
    loo = np.zeros(4)
    for i in range(len(seqs)):
        loo += C[best(np.delete(C, i, 1)), i]
    return LATCH_GRID[j], rate(C[j]), rate(loo)


# ----------------------------------------------------------------------------- rules tried
def _hyst(rs: np.ndarray, con: np.ndarray, z: np.ndarray, a: float, b: float, ha: float, hb: float) -> np.ndarray:
    """Hysteresis: enter on rs < a and con < b; stay while rs < a + ha and con < b + hb (z: share = 0)."""
    out = np.zeros(len(rs), bool)
    f = False
    for i in range(len(rs)):
        f = bool(z[i] or (rs[i] < a + ha and con[i] < b + hb) if f else z[i] or (rs[i] < a and con[i] < b))
        out[i] = f
    return out


def _persist(rs: np.ndarray, con: np.ndarray, z: np.ndarray, a: float, b: float, k: int) -> np.ndarray:
    """Flagged when rs < a and con < b held on this and the k - 1 frames before (or share = 0)."""
    c = (rs < a) & (con < b)
    run = np.zeros(len(c), int)
    r = 0
    for i, v in enumerate(c):
        r = r + 1 if v else 0
        run[i] = r
    return z | (run >= k)


def _running_max(x: np.ndarray, x0: float, k: int) -> np.ndarray:
    """m <- max(x, m - (m - x) / 2**k) from m = x0 (a peak that decays toward x)."""
    y = np.empty_like(x)
    m = x0
    for i, v in enumerate(x):
        m = max(v, m - (m - v) / 2 ** k)
        y[i] = m
    return y


def tried_signals(model: str) -> list[dict]:
    """Per sequence: the adopted filters' values (rs = rho_s / rho0, con_s), share = 0, and the extra
    signals the tried rules use (all re-computed in float from the dumped raw values)."""
    out = []
    for name, d in load(model).items():
        share = d["nt_in"] / np.maximum(d["n_in"], 1)
        sh0 = d["share_ref"][0]
        q = {"name": name, "off": d["iou"] == 0, "on": d["iou"] >= 0.5, "z": d["share"] == 0,
             "rs": d["rho_s"] / d["rho0"], "con": d["con_s"],
             "sh": smooth(share, sh0, 0.5) / max(sh0, 1e-9),
             "drop16": d["rho_s"] / smooth(d["rho"], d["rho0"][0], 1 / 16),
             "peak": d["rho_s"] / _running_max(d["rho_s"], d["rho0"][0], 5)}
        out.append(q)
    return out


GA = np.round(np.arange(0.70, 1.001, 0.01), 2)   # rho_s / rho0 thresholds
GB = np.round(np.arange(0.00, 0.401, 0.01), 2)   # contrast thresholds
GA2 = np.round(np.arange(0.70, 1.001, 0.02), 2)  # coarser grids for the 3-parameter rules
GB2 = np.round(np.arange(0.00, 0.401, 0.02), 2)
GC2 = np.round(np.arange(0.30, 1.001, 0.02), 2)


def tried_rules() -> list[tuple[str, object, list[tuple]]]:
    """(description, rule(q, *g) -> flags, grid) of every rule tried."""
    import itertools as it
    P2, P3 = list(it.product(GA, GB)), list(it.product(GA2, GB2, GC2))
    base = lambda q, a, b: q["z"] | ((q["rs"] < a) & (q["con"] < b))  # noqa: E731
    R = [("adopted rule (rs < a and con < b)", base, P2),
         ("adopted rule, grid steps 0.02", base, list(it.product(GA2, GB2)))]
    for ha, hb in ((0.02, 0.0), (0.05, 0.0), (0.0, 0.02), (0.02, 0.02), (0.05, 0.05)):
        R.append((f"hysteresis: stays flagged while rs < a + {ha:g} and con < b + {hb:g}",
                  lambda q, a, b, ha=ha, hb=hb: _hyst(q["rs"], q["con"], q["z"], a, b, ha, hb), P2))
    for k in (2, 3):
        R.append((f"persistence: the adopted condition on {k} frames in a row",
                  lambda q, a, b, k=k: _persist(q["rs"], q["con"], q["z"], a, b, k), P2))
    R += [("share drop as 2nd cue: rs < a and (con < b or share_s / share0 < c)",
           lambda q, a, b, c: q["z"] | ((q["rs"] < a) & ((q["con"] < b) | (q["sh"] < c))), P3),
          ("drift-following reference: rho_s < a rho_slow (rate 1/16) and con < b",
           lambda q, a, b: q["z"] | ((q["drop16"] < a) & (q["con"] < b)), P2),
          ("sudden drop added: adopted or (rho_s < c rho_slow (rate 1/16) and con < b)",
           lambda q, a, b, c: q["z"] | (((q["rs"] < a) | (q["drop16"] < c)) & (q["con"] < b)), P3),
          ("below the recent peak too: adopted and rho_s < c peak (decay 1/32)",
           lambda q, a, b, c: q["z"] | ((q["rs"] < a) & (q["con"] < b) & (q["peak"] < c)), P3),
          ("linear: rs + con < t (a = t, the contrast weight 1)",
           lambda q, t, _b: q["z"] | (q["rs"] + q["con"] < t), list(it.product(np.round(np.arange(0.5, 1.301, 0.01), 2), (0.0,))))]
    return R


def _best(C: np.ndarray) -> int:
    """Grid index of max recall with FA <= 0.05 (ties: lower FA) of counts C (grid, seq, 4)."""
    t = C.sum(1)
    r, f = t[:, 0] / np.maximum(t[:, 1], 1), t[:, 2] / np.maximum(t[:, 3], 1)
    score = np.where(f <= FA_MAX, r - 1e-6 * f, -1.0)
    return int(np.argmax(score)) if score.max() >= 0 else -1


def _best_joint(CF: np.ndarray, CX: np.ndarray) -> int:
    """Grid index of the highest lower recall of float and fixed, both FA <= 0.05."""
    tf, tx = CF.sum(1), CX.sum(1)
    rf, ff = tf[:, 0] / np.maximum(tf[:, 1], 1), tf[:, 2] / tf[:, 3]
    rx, fx = tx[:, 0] / np.maximum(tx[:, 1], 1), tx[:, 2] / tx[:, 3]
    score = np.where((ff <= FA_MAX) & (fx <= FA_MAX), np.minimum(rf, rx) - 1e-6 * (ff + fx), -1.0)
    return int(np.argmax(score)) if score.max() >= 0 else -1


def _scored(C: np.ndarray, picks: list[int]) -> np.ndarray:
    """Counts summed over sequences, sequence i scored at grid index picks[i] (-1: nothing flagged,
    no grid point met the false-alarm bound)."""
    return sum(C[k, i] if k >= 0 else C[0, i] * np.array([0, 1, 0, 1]) for i, k in enumerate(picks))


def tried_table() -> list[str]:
    """Markdown rows: per rule, per model (own thresholds) in sample and leave one sequence out, and the
    thresholds shared by float and fixed (as the defaults are chosen) in sample and leave one out.
    Where no grid point keeps false alarms <= 0.05 the rule flags nothing (recall 0)."""
    S = {m: tried_signals(m) for m in ("float", "fixed")}
    rows = []
    for name, rule, grid in tried_rules():
        C = {m: np.array([counts([rule(q, *g) for q in S[m]], S[m]) for g in grid]) for m in S}
        cells = []
        nseq = C["float"].shape[1]
        for m in ("float", "fixed"):
            j = _best(C[m])
            loo = _scored(C[m], [_best(np.delete(C[m], i, 1)) for i in range(nseq)])
            (ri, fi), (rl, fl) = rate(_scored(C[m], [j] * nseq)), rate(loo)
            cells.append(f"{ri:.3f} / {fi:.3f} | {rl:.3f} / {fl:.3f}")
        j = _best_joint(C["float"], C["fixed"])
        pk = [_best_joint(np.delete(C["float"], i, 1), np.delete(C["fixed"], i, 1)) for i in range(nseq)]
        g = ", ".join(f"{v:g}" for v in grid[j]) if j >= 0 else "none"
        (a, b), (c, d) = rate(_scored(C["float"], [j] * nseq)), rate(_scored(C["fixed"], [j] * nseq))
        (e, f_), (h, k) = rate(_scored(C["float"], pk)), rate(_scored(C["fixed"], pk))
        rows.append(f"| {name} | {len(grid)} | " + " | ".join(cells) +
                    f" | {g} | {a:.3f} / {b:.3f} | {c:.3f} / {d:.3f} | {e:.3f} / {f_:.3f} | {h:.3f} / {k:.3f} |")
        print(rows[-1], flush=True)
    return rows


def fmt(x: float) -> str:
    return "-" if x != x else f"{x:.2f}"


def main_report() -> None:
    import json

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mstrack.track.params import TrackerParams
    p = TrackerParams(preset="v2")
    L: list[str] = []
    L += ["# Loss signal of tracker v2", "",
          "Per frame after the init frame, on the 10 dev sequences: *recall* = share of off-target frames "
          "(IoU = 0) with `TrackResult.ok` false; *false alarms* = share of on-target frames (IoU >= 0.5) "
          "with `ok` false.  Target: recall >= 0.6 at false alarms <= 0.05.  The rule adopted is in "
          "docs/algorithm.md, \"v2.7a Loss flag\"; this page is the evidence.", "",
          "Commands: `python studies/loss_study.py dump` (runs float and fixed v2 and keeps the per-frame "
          "signals in out/loss_study/), `python studies/loss_study.py search` (float v2 with the search "
          "started by the flag), `python studies/loss_study.py report` (this page and its plots).  The search "
          "state of v2 does not depend on the flag, so the boxes, and every signal below, are those of "
          "the v2 runs of docs/results.md.  Two more cues (a ceiling on rho, a "
          "grey-template check): docs/results_loss_cues.md.", ""]
    models = ("float", "fixed")
    S = {m: sequences(m) for m in models}
    # --- the rule as adopted
    L += ["## The rule adopted", "",
          f"    rho_s      <- rho_s + {p.loss_smooth} (rho - rho_s)",
          f"    contrast_s <- contrast_s + {p.loss_smooth} (share - ring_share - contrast_s)",
          f"    flagged = share = 0  or  (rho_s < {p.loss_rho} rho0  and  contrast_s < {p.loss_contrast})", "",
          "rho0: rho at init; share: target-coloured share of the box; ring_share: the same in the window's "
          "ring around the box; the filters start at the init frame's values.  `ok` = not flagged.  Below, "
          "\"rho/rho0\" and \"contrast\" are the smoothed values unless said otherwise.", "",
          "| model | recall | false alarms | recall, leave one sequence out | false alarms, leave one sequence out |",
          "|---|---:|---:|---:|---:|"]
    loo_rows = {}
    tabs = {}
    for m in models:
        seqs = S[m]
        ok_flags = [~q["ok"] for q in seqs]
        r, f = rate(counts(ok_flags, seqs))
        T = pair_table(seqs)
        tabs[m] = T
        loo = np.zeros(4)
        rows = []
        for i, q in enumerate(seqs):
            a, b = pick(np.delete(T, i, 0))
            loo += T[i, a, b]
            rows.append((q["name"], TA[a], TB[b], T[i, a, b]))
        loo_rows[m] = rows
        lr, lf = rate(loo)
        L.append(f"| {m} v2 | {r:.3f} | {f:.3f} | {lr:.3f} | {lf:.3f} |")
    L += ["", "Leave one sequence out: the thresholds (the grid below) chosen on 9 sequences "
          "(max recall with false alarms <= 0.05), scored on the 10th; the counts summed over the 10.", "",
          "| sequence | float: thresholds on the other 9 | off flagged / off | on flagged / on | "
          "fixed: thresholds on the other 9 | off flagged / off | on flagged / on |", "|---|---|---|---|---|---|---|"]
    for (n, a, b, c), (_, a2, b2, c2) in zip(loo_rows["float"], loo_rows["fixed"]):
        L.append(f"| {n} | {a:.2f}, {b:.2f} | {c[0]:.0f} / {c[1]:.0f} | {c[2]:.0f} / {c[3]:.0f} | "
                 f"{a2:.2f}, {b2:.2f} | {c2[0]:.0f} / {c2[1]:.0f} | {c2[2]:.0f} / {c2[3]:.0f} |")
    # joint choice on the grid
    tf, tx = tabs["float"].sum(0), tabs["fixed"].sum(0)
    rf, ff = tf[..., 0] / tf[..., 1], tf[..., 2] / tf[..., 3]
    rx, fx = tx[..., 0] / tx[..., 1], tx[..., 2] / tx[..., 3]
    joint = np.where((ff <= FA_MAX) & (fx <= FA_MAX), np.minimum(rf, rx), -1.0)
    a, b = np.unravel_index(int(np.argmax(joint)), joint.shape)
    L += ["", f"Choice of the defaults: on the grid loss_rho in {TA[0]:.2f} .. {TA[-1]:.2f}, loss_contrast in "
          f"{TB[0]:.2f} .. {TB[-1]:.2f} (steps 0.01), the pair with the highest lower recall of float and "
          f"fixed, both false-alarm rates <= 0.05: **{TA[a]:.2f}, {TB[b]:.2f}** (float {rf[a, b]:.3f} / "
          f"{ff[a, b]:.3f}, fixed {rx[a, b]:.3f} / {fx[a, b]:.3f}).", ""]
    # smoothing rate
    L += ["## Smoothing", "", "The same rule on rho / rho0 and contrast smoothed by s <- s + r (x - s) (r = 1: the "
          "frame's own values), thresholds chosen per model and rate on the grid: in sample and leave one "
          "sequence out (recall / false alarms).  Re-smoothed here in float arithmetic from the raw values of the "
          f"runs (the adopted rate is r = {p.loss_smooth}).", "",
          "| r | float, in sample | float, leave one out | fixed, in sample | fixed, leave one out |", "|---:|---|---|---|---|"]
    for r_ in (1.0, 0.5, 0.25, 0.125):
        cells = []
        for m in models:
            (ta_, tb_), (ri, fi), (rl, fl_) = in_sample_and_loo(sequences(m, r_))
            cells += [f"{ri:.3f} / {fi:.3f} ({ta_:.2f}, {tb_:.2f})", f"{rl:.3f} / {fl_:.3f}"]
        L.append(f"| {r_:g} | " + " | ".join(cells) + " |")
    L += ["", "r = 1/2 is the only rate that improves both models out of sample; slower filters help in sample "
          "(the long off-target runs of MotorRolling and Girl) but the thresholds they choose do not carry over.", ""]
    # frontier
    L += ["## Frontier", "", "Best recall of the rule at a given false-alarm budget (thresholds chosen in sample):", "",
          "| false alarms <= | " + " | ".join(models) + " |", "|---:|" + "---:|" * len(models)]
    for fa in (0.02, 0.05, 0.10, 0.15, 0.20):
        cells = []
        for m in models:
            t = tabs[m].sum(0)
            r, f = t[..., 0] / t[..., 1], t[..., 2] / t[..., 3]
            cells.append(f"{np.where(f <= fa, r, 0).max():.3f}")
        L.append(f"| {fa:.2f} | " + " | ".join(cells) + " |")
    # per sequence signals
    L += ["", "## Per sequence", "", "Medians on off-target (IoU = 0) and on-target (IoU >= 0.5) frames, and the "
          "adopted flag's counts (float / fixed).", "",
          "| model | sequence | off | on | rho/rho0 off | rho/rho0 on | contrast off | contrast on | off flagged | on flagged |",
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for m in models:
        for q in S[m]:
            med = lambda x, k: float(np.median(x[k])) if k.any() else float("nan")  # noqa: E731
            fl = ~q["ok"]
            L.append(f"| {m} | {q['name']} | {q['off'].sum()} | {q['on'].sum()} | {fmt(med(q['rr0'], q['off']))} | "
                     f"{fmt(med(q['rr0'], q['on']))} | {fmt(med(q['con'], q['off']))} | {fmt(med(q['con'], q['on']))} | "
                     f"{(fl & q['off']).sum()} | {(fl & q['on']).sum()} |")
    # single signals
    L += ["", "## Single signals", "", "Each signal alone, flag = signal < threshold, the threshold the largest "
          "with false alarms <= 0.05 (in sample): recall.", "", "| signal | float | fixed |", "|---|---:|---:|"]
    for k in S["float"][0]["sig"]:
        L.append(f"| {k} | {single_best(S['float'], k)[0]:.3f} | {single_best(S['fixed'], k)[0]:.3f} |")
    L += ["", "The last four rows give recall near 0.1 at the bound (where a signal unrelated to the loss gives 0.05; the mean-shift loop reaches max_iter on fewer than 1 % of the on- and of the off-target frames).  The references of the confidence (rho_ref, share_ref) follow the drift: on MotorRolling and "
          "Girl the tracker stays `ok` for tens of frames while it slides off the target, so by the time it is "
          "off, rho / rho_ref is near 1 again.  rho against its init value does not drift, but alone it flags "
          "the on-target frames of Crossing and bag_vot (appearance change).  The contrast alone flags Suv, "
          "whose background has the target's colours.  Together (both low) they separate best.", ""]
    # latch
    g, (lr_, lf_), (lor, lof) = {}, (0, 0), (0, 0)
    L += ["## Variants measured and not adopted", ""]
    for m in models:
        g, (r_, f_), (lr_, lf_) = latch_study(sequences(m, 1.0))
        L.append(f"* Latching flag ({m}, unsmoothed values): flagged = (rho/rho0 < ta and contrast < tb) or (flagged on the "
                 f"previous frame and rho/rho0 < tr and contrast < tc); best in sample ta {g[0]:.2f}, tb {g[1]:.2f}, "
                 f"tr {g[2]:.2f}, tc {g[3]:.2f}: recall {r_:.3f} at {f_:.3f} false alarms; leave one sequence out "
                 f"{lr_:.3f} at {lf_:.3f}.  More recall in sample, more false alarms on unseen sequences (a "
                 "false alarm latches): not adopted.")
    sp = OUT / "search.json"
    if sp.exists():
        res = json.loads(sp.read_text())
        L += ["* Search state from the flag (float, `python studies/loss_study.py search`): the wide search of "
              "v2.7 started by the loss flag instead of the confidence.", "",
              "| search started by | AUC | mean AUC over sequences | recall | false alarms |", "|---|---:|---:|---:|---:|"]
        for k, v in res.items():
            L.append(f"| {k} | {v['auc']:.3f} | {v['mean_auc']:.3f} | {v['recall']:.3f} | {v['false_alarm']:.3f} |")
        L += ["", "  (AUC here over the frames after the init frame.)  The wide search, started on frames where the "
              "target has drifted but is still partly in the window, jumps to background: the confidence "
              "stays the search trigger.", ""]
    # rules tried
    L += ["## Rules tried", "",
          "The target (recall >= 0.6 at false alarms <= 0.05, float and fixed, in and out of sample) "
          "is not met by the adopted rule.  The cheap alternatives below were measured on the same dumped "
          "signals (`python studies/loss_study.py report` recomputes this table; the rules are `tried_rules()` in "
          "studies/loss_study.py).  rs = rho_s / rho0 and con = contrast_s are the adopted filters' values (rate "
          "1/2); share = 0 flags in every rule.  Per rule: its grid size; per model, thresholds chosen on that "
          "model (max recall with false alarms <= 0.05): in sample and leave one sequence out; then one set of "
          "thresholds for both models (the highest lower recall, both false-alarm rates <= 0.05, as the defaults "
          "are chosen): the thresholds, in sample, and leave one sequence out (the shared choice made on 9 "
          "sequences).  Cells: recall / false alarms.", "",
          "| rule | grid | float, in sample | float, leave one out | fixed, in sample | fixed, leave one out | "
          "shared thresholds | float | fixed | float, leave one out | fixed, leave one out |",
          "|---|---:|---|---|---|---|---|---|---|---|---|"]
    L += tried_table()
    hyst_now = ", ".join(f"{m} {r_:.3f} / {f_:.3f}" for m in models for r_, f_ in [rate(counts(
        [_hyst(q["rs"], q["con"], q["z"], p.loss_rho, p.loss_contrast, 0.02, 0.0) for q in tried_signals(m)],
        tried_signals(m)))])
    L += ["", "Findings:", "",
          "* No rule beats the adopted one clearly out of sample.  The best is hysteresis on rho (once flagged, "
          "the flag stays while rs < a + 0.02 and con < b): with shared thresholds it adds a few frames of recall "
          "in and out of sample (fixed reaches 0.6 in sample), but with thresholds chosen per model its float "
          "leave-one-out recall falls far below the adopted rule's; it moves along the same recall / "
          "false-alarm frontier as the thresholds themselves (a wider margin or a contrast margin buys recall "
          "with false alarms at the same rate; added to today's defaults 0.88, 0.19 without re-choosing them, "
          f"it takes fixed over the false-alarm bound: {hyst_now}).  Not adopted: the evidence is a handful of frames, and "
          "ms_loss_flag's RTL would need a state bit.",
          "* The per-model leave-one-out figures are noisy: the same adopted rule on a grid of step 0.02 "
          "instead of 0.01 drops float out-of-sample recall from about 0.53 to about 0.37, because the "
          "off-target frames sit mostly in two sequences (Girl, MotorRolling) and leaving one out moves the "
          "choice along a flat frontier.  Differences of a few hundredths between rules are within that noise.",
          "* References that follow the track (a slow running rho, or a decaying peak of rho_s) do worse than "
          "rho0: on Girl and MotorRolling the tracker slides onto the distractor over tens of frames, so there "
          "is no sudden drop to detect, and on Girl (float) rho is lower on the last on-target frames than on the "
          "first off-target ones.",
          "* The share's drop against its init value as an alternative second cue (share_s / share0 < c) "
          "does not add recall at the false-alarm bound: the on-target frames of Crossing, Subway and bag_vot "
          "(deformation, illumination) lose target-coloured share as much as Girl's off-target frames do.",
          "* Persistence (the condition on 2 or 3 frames in a row) reaches less recall at the bound than the "
          "adopted rule, in and out of sample; a single linear cut rs + con < t is worse than the two "
          "thresholds.",
          "* Limits of colour cues: in fixed Subway the tracker sits on a region that matches the model better "
          "than the init box did (rho / rho0 about 1.1 on its off-target frames), and on Girl the "
          "distractor is another face of the target's colours with a high contrast to its ring.  Neither can be "
          "flagged from rho, share or the ring; the centre jump and the scale change (\"Single signals\") do "
          "not separate them either, and the mean-shift iteration count has the median 1 on both the on- and "
          "the off-target frames of Girl and Subway (it stops at once: the distractor is a mode).", ""]
    # plot
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    for ax, m in zip(axes, models):
        for q in S[m]:
            for key, col, lab in (("on", "tab:blue", "IoU >= 0.5"), ("off", "tab:red", "IoU = 0")):
                k = q[key]
                ax.scatter(q["rr0"][k], q["con"][k], s=4, c=col, alpha=0.35, label=lab if q is S[m][0] else None)
        ax.axvline(p.loss_rho, c="k", lw=0.8)
        ax.axhline(p.loss_contrast, c="k", lw=0.8)
        ax.set_xlim(0, 1.6)
        ax.set_ylim(-0.4, 1.0)
        ax.set_xlabel("rho_s / rho0")
        ax.set_title(f"{m} v2: flagged = lower left")
    axes[0].set_ylabel("contrast_s (smoothed share - ring_share)")
    axes[0].legend(loc="upper right", markerscale=3)
    fig.tight_layout()
    png = ROOT / "docs" / "results" / "loss_scatter.png"
    fig.savefig(png, dpi=90)
    L += ["## Plot", "", "![rho / rho0 against contrast](results/loss_scatter.png)", ""]
    DOC.write_text("\n".join(L) + "\n")
    print("wrote", DOC, png)


if __name__ == "__main__":
    cmd = sys.argv[1] if len(sys.argv) > 1 else "report"
    if cmd == "dump":
        main_dump(sys.argv[2] if len(sys.argv) > 2 else default_root())
    elif cmd == "search":
        main_search(sys.argv[2] if len(sys.argv) > 2 else default_root())
    elif cmd == "report":
        main_report()
    else:
        raise SystemExit(__doc__)
