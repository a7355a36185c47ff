"""Tracker v2 on the 22 sequences (dev + validation): accuracy, float/fixed stability, loss flag.

Usage::

    python studies/accuracy22.py run [--tag T] [--set k=v ...]   # float + fixed v2 -> out/acc22/<T>/
    python studies/accuracy22.py report [--tag T]                # tables of one run (stdout)
    python studies/accuracy22.py diverge [--tag T]               # first float/fixed divergence per sequence
    python studies/accuracy22.py loss [--tag T]                  # loss thresholds: in sample and LOSO
    python studies/accuracy22.py loss --tag T --motion [--orient] [--fa-fit F]   # the motion latch's rule
    python studies/accuracy22.py orient --tag T                  # the orientation cue on the kept boxes

``run`` keeps, per sequence and model, the boxes, centres, the loss flag's smoothed signals
(rho_s, contrast_s, rho0, share) and the per-frame decimation / search state / size, so that the
other commands need no tracking.  The loss flag does not steer the tracker (the search state
comes from the confidence), so its thresholds are re-scored from the kept signals: float in
float arithmetic, fixed with the integer comparison of ms_loss_flag (the same decision).
With loss_jump > 0 the run also keeps the motion latch's signals (jump, w + h, latch), from
which ``loss --motion`` re-scores the latch exactly for any loss_jump / loss_stay.
Sequences: ../shared/data/sequences (dev, 10) and ../shared/data/validation (12).
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import fields
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mstrack.eval.metrics import centre_error, iou, score, valid_gt  # noqa: E402
from mstrack.fixed.blocks_v2 import q16  # noqa: E402
from mstrack.io.data import load_dataset  # noqa: E402
from mstrack.track.tracker import Tracker  # noqa: E402
from mstrack.track.types import Status  # noqa: E402

DATA = ROOT.parent / "shared" / "data"
SETS = {"dev": DATA / "sequences", "validation": DATA / "validation"}
OUT = ROOT / "out" / "acc22"
MODELS = ("float", "fixed")
FA_MAX = 0.05


def sequences() -> list[tuple[str, object]]:
    out = []
    for set_name, root in SETS.items():
        if not root.is_dir():
            raise SystemExit(f"{root} not found (needs ../shared/data)")
        out += [(set_name, s) for s in load_dataset(root)]
    return out


def parse_sets(items: list[str]) -> dict:
    kw = {}
    for it in items:
        k, v = it.split("=", 1)
        kw[k] = json.loads(v.lower()) if v.lower() in ("true", "false") else (int(v) if v.lstrip("-").isdigit() else float(v))
    return kw


def run_one(seq, model: str, kw: dict) -> dict:
    if model == "float":  # FixedParams fields (widths) are the fixed model's only
        from mstrack.fixed.formats import FixedParams
        kw = {k: v for k, v in kw.items() if k not in {f.name for f in fields(FixedParams)}}
    trk = Tracker(model=model, preset="v2", **kw)
    n = len(seq)
    boxes = np.zeros((n, 4))
    cen = np.zeros((n, 2))
    ok = np.ones(n, bool)
    sig = {k: np.zeros(n) for k in ("rho", "rho_s", "con_s", "share", "dec", "state", "w", "h", "iter", "conf",
                                    "rho_ref", "share_ref", "ring")}
    impl = trk.impl
    one = 65536.0 if model == "fixed" else 1.0
    res = trk.init(seq.frame(0), seq.init_box())
    rho0 = res.extra["rho"] if model == "fixed" else res.rho_c
    boxes[0] = res.box.as_tuple()
    cen[0] = res.centre
    for i in range(1, n):
        r = trk.update(seq.frame(i))
        boxes[i] = r.box.as_tuple()
        cen[i] = r.centre
        ok[i] = r.ok
        e = r.extra
        sig["rho"][i] = e["rho"] if model == "fixed" else r.rho_c
        sig["rho_s"][i] = e["rho_s"]
        sig["con_s"][i] = e["contrast_s"]
        sig["share"][i] = e["share"]
        sig["dec"][i] = e["decimation"]
        st = e["state"]
        sig["state"][i] = st if isinstance(st, (int, np.integer)) else {"ok": 0, "uncertain": 1, "lost": 2, "reacquired": 3}.get(st, 9)
        sig["w"][i], sig["h"][i] = r.box.w, r.box.h
        sig["iter"][i] = r.iter_c
        sig["conf"][i] = r.confidence
        sig["rho_ref"][i] = impl.rho_ref if model == "fixed" else impl._rho_ref
        sig["share_ref"][i] = impl.share_ref if model == "fixed" else impl._share_ref
        sig["ring"][i] = e["ring_share"]
        for k in ("jump", "latch"):  # the loss flag's motion latch (loss_jump > 0)
            if k in e:
                sig.setdefault(k, np.zeros(n))[i] = e[k]
        if "jump" in e:
            sig.setdefault("wh", np.zeros(n))[i] = e["wh8" if model == "fixed" else "wh"]
    return {"boxes": boxes, "centre": cen, "ok": ok, "rho0": np.array(rho0), "one": np.array(one), **sig}


def main_run(tag: str, kw: dict, models: tuple[str, ...]) -> None:
    d = OUT / tag
    d.mkdir(parents=True, exist_ok=True)
    (d / "params.json").write_text(json.dumps(kw))
    for set_name, seq in sequences():
        for model in models:
            f = d / f"{model}_{seq.name}.npz"
            if f.is_file():
                continue
            np.savez(f, set=set_name, **run_one(seq, model, kw))
        print(tag, seq.name, flush=True)


def load(tag: str, model: str) -> dict[str, tuple[str, dict, np.ndarray]]:
    """name -> (set, arrays, gt)."""
    out = {}
    for set_name, seq in sequences():
        f = OUT / tag / f"{model}_{seq.name}.npz"
        if not f.is_file():
            continue
        z = dict(np.load(f))
        out[seq.name] = (set_name, z, np.asarray(seq.gt[:len(z["boxes"])], dtype=np.float64))
    return out


def seq_scores(runs: dict) -> dict[str, tuple[str, float, float, np.ndarray, np.ndarray]]:
    """name -> (set, AUC, P@20, ious, errors) on valid-GT frames."""
    out = {}
    for name, (set_name, z, gt) in runs.items():
        s = score(z["boxes"], gt)
        out[name] = (set_name, s.auc, s.precision20, s.ious, s.errors)
    return out


def summary(sc: dict, which: str) -> tuple[float, float, float, float, int]:
    """(frame-weighted AUC, P@20, mean AUC over sequences, mean P@20 over sequences, n seqs)."""
    from mstrack.eval.metrics import score_frames
    part = [v for v in sc.values() if which == "all" or v[0] == which]
    if not part:
        return (float("nan"),) * 4 + (0,)  # type: ignore[return-value]
    s = score_frames(np.concatenate([p[3] for p in part]), np.concatenate([p[4] for p in part]))
    return s.auc, s.precision20, float(np.mean([p[1] for p in part])), float(np.mean([p[2] for p in part])), len(part)


# ----------------------------------------------------------------------------- loss flag
#: the loss flag's rho reference: "rho0" (rho at init, the tracker's rule) or "rho_ref" (the running
#: reference of the confidence, as it was before the frame's update)
LOSS_REF = {"ref": "rho0"}


def loss_arrays(runs: dict, model: str) -> dict[str, dict[str, np.ndarray]]:
    """Per sequence, frames after init with valid GT: iou, rho_s, its reference, con_s, share."""
    out = {}
    for name, (_, z, gt) in runs.items():
        v = valid_gt(gt)
        v[0] = False
        rho0 = float(z["rho0"])
        if LOSS_REF["ref"] == "rho_ref":
            ref = np.concatenate([[rho0], z["rho_ref"][1:-1]]) if "rho_ref" in z else None
            if ref is None:
                raise SystemExit(f"run without rho_ref: {name}")
            ref = np.concatenate([[rho0], ref])[:len(v)] if len(ref) < len(v) else ref
        else:
            ref = np.full(len(v), rho0)
        out[name] = {"iou": iou(z["boxes"], gt)[v], "rho_s": z["rho_s"][v], "con_s": z["con_s"][v],
                     "share": z["share"][v], "ref": ref[v], "ok": z["ok"][v]}
    return out


def flag(a: dict, lr: float, lc: float, model: str) -> np.ndarray:
    if model == "fixed":
        rs = a["rho_s"].astype(np.int64)
        return (a["share"] == 0) | (rs == 0) | ((rs << 16) < q16(lr) * a["ref"].astype(np.int64)) & (a["con_s"] < q16(lc))
    return (a["share"] == 0) | (a["rho_s"] == 0) | ((a["rho_s"] < lr * a["ref"]) & (a["con_s"] < lc))


RHO_GRID = np.round(np.arange(0.50, 1.001, 0.01), 2)
CON_GRID = np.round(np.arange(0.00, 0.401, 0.01), 2)


def counts(arr: dict, names: list[str], lr: float, lc: float, model: str) -> tuple[int, int, int, int]:
    offf = off = onf = on = 0
    for n in names:
        a = arr[n]
        f = flag(a, lr, lc, model)
        o, g = a["iou"] == 0, a["iou"] >= 0.5
        offf += int((f & o).sum())
        off += int(o.sum())
        onf += int((f & g).sum())
        on += int(g.sum())
    return offf, off, onf, on


def table(arr: dict, names: list[str], model: str) -> np.ndarray:
    """(rho, con) grid -> (offf, off, onf, on) per sequence summed over names."""
    t = np.zeros((len(RHO_GRID), len(CON_GRID), 4), np.int64)
    for i, lr in enumerate(RHO_GRID):
        for j, lc in enumerate(CON_GRID):
            t[i, j] = counts(arr, names, lr, lc, model)
    return t


def choose(t: np.ndarray) -> tuple[int, int]:
    """Highest recall with false alarms <= FA_MAX (ties: fewer false alarms, then larger margins)."""
    rec = t[..., 0] / np.maximum(t[..., 1], 1)
    fa = t[..., 2] / np.maximum(t[..., 3], 1)
    key = np.where(fa <= FA_MAX, rec * 1e6 - fa * 1e3, -np.inf)
    i, j = np.unravel_index(int(np.argmax(key)), key.shape)
    return int(i), int(j)


def loso(runs_by_model: dict[str, dict], models=MODELS, joint: bool = True):
    """Per model: in-sample choice and LOSO counts.  joint: one pair for float and fixed
    (highest lower recall of the two with both false-alarm rates <= FA_MAX)."""
    arrs = {m: loss_arrays(runs_by_model[m], m) for m in models}
    names = sorted(set.intersection(*(set(a) for a in arrs.values())))
    per_seq = {m: {n: table(arrs[m], [n], m) for n in names} for m in models}
    total = {m: sum(per_seq[m].values()) for m in models}

    def pick(tabs: dict[str, np.ndarray]) -> tuple[int, int]:
        if not joint:
            raise NotImplementedError
        recs, fas = [], []
        for m, t in tabs.items():
            recs.append(t[..., 0] / np.maximum(t[..., 1], 1))
            fas.append(t[..., 2] / np.maximum(t[..., 3], 1))
        rec, fa = np.minimum(*recs) if len(recs) > 1 else recs[0], np.maximum(*fas) if len(fas) > 1 else fas[0]
        key = np.where(fa <= FA_MAX, rec * 1e6 - fa * 1e3, -np.inf)
        i, j = np.unravel_index(int(np.argmax(key)), key.shape)
        return int(i), int(j)

    i, j = pick(total)
    ins = {m: total[m][i, j] for m in models}
    lo = {m: np.zeros(4, np.int64) for m in models}
    chosen = {}
    for n in names:
        rest = {m: total[m] - per_seq[m][n] for m in models}
        a, b = pick(rest)
        chosen[n] = (RHO_GRID[a], CON_GRID[b])
        for m in models:
            lo[m] += per_seq[m][n][a, b]
    return (RHO_GRID[i], CON_GRID[j]), ins, lo, chosen


def fmt_ld(c) -> str:
    return f"{c[0] / max(c[1], 1):.3f} / {c[2] / max(c[3], 1):.3f}"


def main_loss(tag: str) -> None:
    runs = {m: load(tag, m) for m in MODELS}
    (lr, lc), ins, lo, chosen = loso(runs)
    print(f"joint choice on 22 (in sample): loss_rho {lr:.2f}, loss_contrast {lc:.2f}")
    print("| model | recall / false alarms, in sample | recall / false alarms, LOSO |")
    print("|---|---|---|")
    for m in MODELS:
        print(f"| {m} | {fmt_ld(ins[m])} | {fmt_ld(lo[m])} |")
    # the current thresholds as they are
    p = json.loads((OUT / tag / "params.json").read_text())
    for m in MODELS:
        arr = loss_arrays(runs[m], m)
        c = counts(arr, list(arr), p.get("loss_rho", 0.69), p.get("loss_contrast", 0.25), m)
        okc = np.zeros(4, np.int64)
        for a in arr.values():
            f = ~a["ok"]
            okc += [int((f & (a["iou"] == 0)).sum()), int((a["iou"] == 0).sum()), int((f & (a["iou"] >= 0.5)).sum()),
                    int((a["iou"] >= 0.5).sum())]
        print(f"{m}: run's thresholds recall / FA {fmt_ld(c)} (from ok: {fmt_ld(okc)}; off {okc[1]}, on {okc[3]})")
    print("LOSO choices:", {n: (float(a), float(b)) for n, (a, b) in chosen.items()})


# ----------------------------------------------------------------------------- loss flag: motion latch
#: the grid of the motion latch's rule (docs/algorithm.md "v2.7a Loss flag"): loss_rho, loss_contrast
#: (the base rule, against the running reference rho_ref), loss_jump (sixteenths), loss_stay
M_RHO = np.round(np.arange(0.80, 0.951, 0.01), 2)
M_CON = np.round(np.arange(0.00, 0.161, 0.02), 2)
M_JUMP = (1.0, 1.25, 1.5, 1.75, 2.0)
M_STAY = (0.9, 0.925, 0.95, 0.975)
#: the orientation cue's thresholds (measured on the kept boxes, not a model signal): 0 = off
M_ORIENT = (0.0, 0.9, 0.92, 0.94)


def orient_rho(tag: str, orient_t: int = 64) -> None:
    """Per sequence and model: the orientation marginal's rho of the kept box, kept in
    out/acc22/<tag>/orient_<model>_<seq>.npz (ro: smoothed with rate 1/2 from 1 at init).

    An offline measure, not the models' signal: the 9 orientation bins of ms_orient_bin (Sobel of
    the full-resolution grey frame, |Gx| + |Gy| >= orient_t, else flat), counted over the box (all
    pixels alike), against the init box's counts, rho = sum sqrt(p q) in float."""
    from mstrack.fixed.blocks import ms_grey
    from mstrack.fixed.blocks_v2 import ms_orient_bin

    def hist(ob: np.ndarray, b) -> np.ndarray:
        x0, y0 = max(int(round(b[0])), 0), max(int(round(b[1])), 0)
        x1, y1 = min(int(round(b[0] + b[2])), ob.shape[1]), min(int(round(b[1] + b[3])), ob.shape[0])
        if x1 <= x0 or y1 <= y0:
            return np.zeros(9)
        c = np.bincount(ob[y0:y1, x0:x1].ravel(), minlength=9).astype(np.float64)
        return c / c.sum()

    for _, seq in sequences():
        boxes = {m: np.load(OUT / tag / f"{m}_{seq.name}.npz")["boxes"] for m in MODELS}
        ro = {m: np.ones(len(boxes[m])) for m in MODELS}
        q = None
        for i in range(len(seq)):
            ob = ms_orient_bin(ms_grey(seq.frame(i)), orient_t)
            if i == 0:
                q = hist(ob, seq.init_box().as_tuple())
                continue
            for m in MODELS:
                if i < len(boxes[m]):
                    rho = float(np.sqrt(hist(ob, boxes[m][i]) * q).sum())
                    ro[m][i] = ro[m][i - 1] + 0.5 * (rho - ro[m][i - 1])
        for m in MODELS:
            np.savez(OUT / tag / f"orient_{m}_{seq.name}.npz", ro=ro[m])
        print(tag, "orient", seq.name, flush=True)


def running_ref(z: dict) -> np.ndarray:
    """Per frame, the running reference rho_ref as it was before the frame's update (frame 0, 1: rho0)."""
    rho0 = float(z["rho0"])
    n = len(z["rho_s"])
    return np.concatenate([[rho0, rho0], z["rho_ref"][1:n - 1]])[:n]


def motion_latch(z: dict, model: str, cf: int = 8, variant: str = "rho") -> np.ndarray:
    """(frames, len(M_JUMP) x len(M_STAY)): the latch of every (loss_jump, loss_stay) pair,
    recomputed from the kept signals with the models' own comparisons (fixed: ms_loss_jump and
    ms_loss_latch's integer tests; float: loss_jump, loss_latch).  variant "rho": the models' latch;
    "rho+state" (measured, not in the models): it holds only while the search state is not ok too."""
    ref = running_ref(z)
    n = len(ref)
    if model == "fixed":
        jl = z["jump"].astype(np.int64)[:, None] << 13
        jumps = jl > (np.array([round(j * 16) for j in M_JUMP], np.int64)[None, :] * z["wh"].astype(np.int64)[:, None]) << cf
        stays = (z["rho_s"].astype(np.int64)[:, None] << 16) < np.array([q16(m) for m in M_STAY], np.int64)[None, :] * \
            ref.astype(np.int64)[:, None]
    else:
        jumps = z["jump"][:, None] > np.array(M_JUMP)[None, :] * z["wh"][:, None] / 2.0
        stays = z["rho_s"][:, None] < np.array(M_STAY)[None, :] * ref[:, None]
    if variant == "rho+state":
        stays &= (z["state"] != 0)[:, None]
    jumps = np.repeat(jumps, len(M_STAY), axis=1)   # (n, J x M), M fastest
    stays = np.tile(stays, (1, len(M_JUMP)))
    out = np.zeros((n, jumps.shape[1]), bool)
    prev = np.zeros(jumps.shape[1], bool)
    for i in range(1, n):
        prev = jumps[i] | (prev & stays[i])
        out[i] = prev
    return out


def motion_tables(runs: dict, model: str, cf: int = 8, variant: str = "rho", tag: str | None = None
                  ) -> dict[str, np.ndarray]:
    """Per sequence: (len(M_RHO) x len(M_CON) [x len(M_ORIENT)], len(M_JUMP) x len(M_STAY), 4) counts
    (off flagged, off, on flagged, on) of the rule base(loss_rho, loss_contrast; ref rho_ref) or latch
    [or ro < t: the orientation cue of :func:`orient_rho`, with ``tag``]."""
    out = {}
    for name, (_, z, gt) in runs.items():
        if "jump" not in z:
            raise SystemExit(f"run without the motion signals (loss_jump 0): {name}")
        v = valid_gt(gt)
        v[0] = False
        io = iou(z["boxes"], gt)
        off, on = (io == 0) & v, (io >= 0.5) & v
        lat = motion_latch(z, model, cf, variant)
        a = {"rho_s": z["rho_s"], "con_s": z["con_s"], "share": z["share"], "ref": running_ref(z)}
        base = np.stack([flag(a, lr, lc, model) for lr in M_RHO for lc in M_CON], axis=1)
        if tag is not None:
            ro = np.load(OUT / tag / f"orient_{model}_{name}.npz")["ro"]
            base = np.concatenate([base | (ro < t)[:, None] for t in M_ORIENT], axis=1)  # t 0: off
        t = np.zeros((base.shape[1], lat.shape[1], 4), np.int64)
        for k, m in ((0, off), (2, on)):
            b, la = base[m].astype(np.int64), lat[m].astype(np.int64)
            both = np.einsum("tb,tl->bl", b, la)  # integer counts
            t[..., k] = b.sum(0)[:, None] + la.sum(0)[None, :] - both
            t[..., k + 1] = int(m.sum())
        out[name] = t
    return out


def motion_key(i: int, j: int, orient: bool = False) -> tuple[float, ...]:
    """(loss_rho, loss_contrast, loss_jump, loss_stay[, orientation threshold]) of a table cell."""
    nb = len(M_RHO) * len(M_CON)
    key = (float(M_RHO[(i % nb) // len(M_CON)]), float(M_CON[i % len(M_CON)]), float(M_JUMP[j // len(M_STAY)]),
           float(M_STAY[j % len(M_STAY)]))
    return key + ((float(M_ORIENT[i // nb]),) if orient else ())


def pick_joint(tabs: dict[str, np.ndarray], fa_max: float) -> tuple[int, ...]:
    """One grid point for all models: the highest lower recall with every false-alarm rate <= fa_max
    (ties: fewer false alarms, then the first point of the grid)."""
    rec = np.minimum.reduce([t[..., 0] / np.maximum(t[..., 1], 1) for t in tabs.values()])
    fa = np.maximum.reduce([t[..., 2] / np.maximum(t[..., 3], 1) for t in tabs.values()])
    key = np.where(fa <= fa_max, rec * 1e6 - fa * 1e3, -np.inf)
    if not np.isfinite(key).any():
        raise SystemExit(f"no grid point with false alarms <= {fa_max}")
    return tuple(int(x) for x in np.unravel_index(int(np.argmax(key)), key.shape))


def loso_motion(tag: str, fa_fit: float = FA_MAX, cf: int = 8, variant: str = "rho", orient: bool = False):
    """The motion latch's rule: the point chosen on all sequences (in sample; false alarms <= fa_fit)
    and leave one sequence out (chosen on the others, scored on the one left out, counts summed)."""
    per = {m: motion_tables(load(tag, m), m, cf, variant, tag if orient else None) for m in MODELS}
    names = sorted(set.intersection(*(set(p) for p in per.values())))
    total = {m: sum(per[m][n] for n in names) for m in MODELS}
    i, j = pick_joint(total, fa_fit)
    ins = {m: total[m][i, j] for m in MODELS}
    lo = {m: np.zeros(4, np.int64) for m in MODELS}
    chosen = {}
    for n in names:
        a, b = pick_joint({m: total[m] - per[m][n] for m in MODELS}, fa_fit)
        chosen[n] = motion_key(a, b, orient)
        for m in MODELS:
            lo[m] += per[m][n][a, b]
    return motion_key(i, j, orient), ins, lo, chosen


def main_loss_motion(tag: str, fa_fit: float, orient: bool = False) -> None:
    key, ins, lo, chosen = loso_motion(tag, fa_fit, orient=orient)
    print(f"motion latch, chosen on all with false alarms <= {fa_fit}: loss_rho {key[0]:.2f}, loss_contrast "
          f"{key[1]:.2f}, loss_jump {key[2]:g}, loss_stay {key[3]:g} (ref rho_ref)" +
          (f", orientation rho < {key[4]:g}" if orient else ""))
    print("| model | recall / false alarms, in sample | recall / false alarms, LOSO |")
    print("|---|---|---|")
    for m in MODELS:
        print(f"| {m} | {fmt_ld(ins[m])} | {fmt_ld(lo[m])} |")
    print("LOSO choices:", chosen)


# ----------------------------------------------------------------------------- report / diverge
def main_report(tag: str, ref: str | None = None) -> None:
    sc = {m: seq_scores(load(tag, m)) for m in MODELS}
    print(f"tag {tag}: {json.loads((OUT / tag / 'params.json').read_text())}")
    print("| model | set | seqs | AUC | P@20 | mean AUC | mean P@20 |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for m in MODELS:
        for w in ("dev", "validation", "all"):
            a, p, ma, mp, n = summary(sc[m], w)
            print(f"| {m} | {w} | {n} | {a:.3f} | {p:.3f} | {ma:.3f} | {mp:.3f} |")
    print("\n| sequence | set | float AUC | fixed AUC | gap | float P@20 | fixed P@20 |")
    print("|---|---|---:|---:|---:|---:|---:|")
    within = 0
    for n in sc["float"]:
        if n not in sc["fixed"]:
            continue
        f, x = sc["float"][n], sc["fixed"][n]
        within += abs(f[1] - x[1]) <= 0.01
        print(f"| {n} | {f[0]} | {f[1]:.3f} | {x[1]:.3f} | {x[1] - f[1]:+.3f} | {f[2]:.3f} | {x[2]:.3f} |")
    print(f"\nwithin 0.01 AUC: {within} of {len(sc['fixed'])}")


def main_diverge(tag: str, px: float = 4.0) -> None:
    runs = {m: load(tag, m) for m in MODELS}
    print(f"| sequence | first frame > {px:g} px | dec f/x | state f/x | w f/x | iter f/x | conf f/x | frames later > {px:g} px |")
    print("|---|---:|---|---|---|---|---|---:|")
    for n, (_, zf, _) in runs["float"].items():
        zx = runs["fixed"][n][1]
        d = np.hypot(*(zf["centre"] - zx["centre"]).T)
        bad = np.nonzero(d > px)[0]
        if not len(bad):
            print(f"| {n} | - | | | | | | 0 |")
            continue
        i = int(bad[0])
        j = max(i - 1, 0)
        print(f"| {n} | {i} | {zf['dec'][j]:.0f}/{zx['dec'][j]:.0f} | {zf['state'][i]:.0f}/{zx['state'][i]:.0f} | "
              f"{zf['w'][j]:.1f}/{zx['w'][j]:.1f} | {zf['iter'][i]:.0f}/{zx['iter'][i]:.0f} | "
              f"{zf['conf'][i]:.2f}/{zx['conf'][i]:.2f} | {len(bad)} |")


def csrt_scores() -> dict:
    """CSRT's per-sequence runs from the `make results` caches (out/eval_float*, opencv-csrt)."""
    from mstrack.eval.evaluate import SequenceRun
    out = {}
    for set_name, seq in sequences():
        d = "eval_float" if set_name == "dev" else "eval_float_validation"
        f = ROOT / "out" / d / "results" / "opencv-csrt" / f"{seq.name}.json"
        if not f.is_file():
            continue
        run = SequenceRun.from_json(json.loads(f.read_text()))
        s = score(run.boxes, np.asarray(seq.gt[:run.n_frames], dtype=np.float64))
        out[seq.name] = (set_name, s.auc, s.precision20, s.ious, s.errors)
    return out


def capture(fn, *a) -> list[str]:
    import contextlib
    import io
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        fn(*a)
    return buf.getvalue().rstrip().splitlines()


CHANGE = 0.02


def changes(base: str, tags: list[str]) -> list[str]:
    """Table rows: per run and model, the sequences whose AUC moves by more than CHANGE against
    run ``base`` (better / worse, largest move first)."""
    ref = {m: seq_scores(load(base, m)) for m in MODELS}
    rows = []
    for tag in tags:
        for m in MODELS:
            sc = seq_scores(load(tag, m))
            d = sorted(((sc[n][1] - ref[m][n][1], n) for n in sc if n in ref[m]), reverse=True)
            cell = [", ".join(f"{n} {ref[m][n][1]:.3f} -> {sc[n][1]:.3f}" for v, n in part)
                    for part in ([x for x in d if x[0] > CHANGE], [x for x in d[::-1] if x[0] < -CHANGE])]
            rows.append(f"| {tag} | {m} | {cell[0] or '-'} | {cell[1] or '-'} |")
    return rows


def main_doc(tags: list[str], notes: dict[str, str]) -> None:
    """docs/results_accuracy22.md and docs/results/accuracy22.json from the runs of ``tags``
    (the first is the defaults)."""
    cs = csrt_scores()
    lines = ["# Tracker v2 on 22 sequences: accuracy, float/fixed stability, loss flag", "",
             "Dev (`../shared/data/sequences`, 10) + validation (`../shared/data/validation`, 12) = 22 OTB "
             "sequences, 5,286 frames.  Made by `python studies/accuracy22.py run --tag T --set k=v ...` "
             "(float + fixed v2 with TrackerParams / FixedParams fields k=v, kept in out/acc22/T/) and "
             "`python studies/accuracy22.py doc` (this page).  AUC / P@20 frame-weighted and as the plain mean "
             "over sequences; *within 0.01*: sequences whose float and fixed AUC differ by at most 0.01.  "
             "Every parameter is chosen for the whole set, never per sequence.", "",
             "## Accuracy of the runs", "",
             "| run | parameters | model | dev AUC / P@20 | validation AUC / P@20 | 22: AUC / P@20 | 22: mean AUC / mean P@20 | float-fixed within 0.01 |",
             "|---|---|---|---|---|---|---|---:|"]
    if cs:
        a = [summary(cs, w) for w in ("dev", "validation", "all")]
        lines.append(f"| opencv-csrt | OpenCV defaults | - | {a[0][0]:.3f} / {a[0][1]:.3f} | {a[1][0]:.3f} / {a[1][1]:.3f} | "
                     f"{a[2][0]:.3f} / {a[2][1]:.3f} | {a[2][2]:.3f} / {a[2][3]:.3f} | |")
    for tag in tags:
        sc = {m: seq_scores(load(tag, m)) for m in MODELS}
        within = sum(abs(sc["float"][n][1] - sc["fixed"][n][1]) <= 0.01 for n in sc["fixed"] if n in sc["float"])
        par = json.loads((OUT / tag / "params.json").read_text())
        for m in MODELS:
            a = [summary(sc[m], w) for w in ("dev", "validation", "all")]
            lines.append(f"| {tag} | {', '.join(f'{k}={v}' for k, v in par.items()) or 'defaults'} | {m} | "
                         f"{a[0][0]:.3f} / {a[0][1]:.3f} | {a[1][0]:.3f} / {a[1][1]:.3f} | {a[2][0]:.3f} / {a[2][1]:.3f} | "
                         f"{a[2][2]:.3f} / {a[2][3]:.3f} | {within if m == 'fixed' else ''} |")
    lines += [""] + [f"* **{t}**: {notes[t]}" for t in tags if t in notes] + [""]
    if len(tags) > 2:
        lines += ["## Per sequence, each run against run " + tags[1], "",
                  f"Sequences whose AUC moves by more than {CHANGE} against run {tags[1]} (same model), "
                  "from -> to.", "",
                  "| run | model | better | worse |", "|---|---|---|---|"]
        lines += changes(tags[1], tags[2:]) + [""]
    for tag in tags[:2]:
        lines += [f"## Per sequence, run {tag}", ""] + capture(main_report, tag)[9:] + [""]
        lines += [f"First frame where the float and fixed centres are more than 4 px apart (run {tag}; "
                  "decimation and width on the frame before, search state 0 ok / 1 uncertain / 2 lost):", ""]
        lines += capture(main_diverge, tag, 4.0) + [""]
    res = {"command": "python studies/accuracy22.py doc", "loss": {}}
    for tag in tags[:2]:
        runs = {m: load(tag, m) for m in MODELS}
        p = json.loads((OUT / tag / "params.json").read_text())
        lines += [f"## Loss flag, run {tag}", "",
                  "The rule of docs/algorithm.md \"v2.7a Loss flag\" (rho_s < loss_rho ref and contrast_s < "
                  "loss_contrast; ref = rho0, rho at init, the tracker's rule, or rho_ref, the running reference "
                  "before the frame's update, `loss_ref_running`), re-scored from the kept signals on the grid "
                  "loss_rho 0.50..1.00, loss_contrast 0.00..0.40 (steps 0.01): one pair for float and fixed, the "
                  "highest lower recall with both false-alarm rates <= 0.05; leave one sequence out: the pair "
                  "chosen on 21 sequences, scored on the 22nd, counts summed.  Cells: recall / false alarms.", "",
                  "| model | ref | thresholds of the run (0.69, 0.25) | chosen on 22 (in sample) | leave one sequence out |",
                  "|---|---|---|---|---|"]
        chosen_all = {}
        for ref in ("rho0", "rho_ref"):
            LOSS_REF["ref"] = ref
            (lr, lc), ins, lo, chosen = loso(runs)
            chosen_all[ref] = chosen
            for m in MODELS:
                arr = loss_arrays(runs[m], m)
                c = counts(arr, list(arr), p.get("loss_rho", 0.69), p.get("loss_contrast", 0.25), m)
                lines.append(f"| {m} | {ref} | {fmt_ld(c)} | {fmt_ld(ins[m])} ({lr:.2f}, {lc:.2f}) | {fmt_ld(lo[m])} |")
                if tag == tags[0]:
                    res["loss"][f"{m}, ref {ref}"] = {"in_sample": f"{lr:.2f}, {lc:.2f}: {fmt_ld(ins[m])}",
                                                     "loso": fmt_ld(lo[m])}
        LOSS_REF["ref"] = "rho0"
        for ref, chosen in chosen_all.items():
            lines += ["", f"Pairs chosen leaving each sequence out (ref {ref}): " +
                      ", ".join(f"{n} ({a:.2f}, {b:.2f})" for n, (a, b) in chosen.items()) + "."]
        lines.append("")
    if "motion" in tags:
        lines += motion_doc("motion", res)
    lines += ["## Findings", ""] + [f"* {f}" for f in FINDINGS] + [""]
    (ROOT / "docs" / "results_accuracy22.md").write_text("\n".join(lines) + "\n")
    (ROOT / "docs" / "results").mkdir(exist_ok=True)
    (ROOT / "docs" / "results" / "accuracy22.json").write_text(json.dumps(res, indent=1) + "\n")
    print(ROOT / "docs" / "results_accuracy22.md")


def motion_doc(tag: str, res: dict) -> list[str]:
    """The section on the loss flag's motion latch (run ``tag``, with loss_jump > 0)."""
    lines = [f"## Loss flag with the motion latch, run {tag}", "",
             "The rule of docs/algorithm.md \"v2.7a Loss flag\", motion latch: flagged = share = 0 or rho_s = 0 or "
             "(rho_s < loss_rho rho_ref and contrast_s < loss_contrast) or latch; latch = jump or (latch on the "
             "previous frame and rho_s < loss_stay rho_ref); jump = |step - previous step| (L1, frame px) > "
             "loss_jump (w + h) / 2.  rho_ref is the running reference before the frame's update "
             "(loss_ref_running).  Re-scored from the kept signals with each model's own comparisons "
             "(`python studies/accuracy22.py loss --tag motion --motion [--fa-fit F]`; the kept flag of the "
             "run equals the re-scored one on every frame) on the grid loss_rho 0.80..0.95 (0.01), "
             "loss_contrast 0.00..0.16 (0.02), loss_jump 1, 1.25, 1.5, 1.75, 2, loss_stay 0.9, 0.925, 0.95, "
             "0.975 (3,060 points): one point for float and fixed, the highest lower recall with both "
             "false-alarm rates <= F on the sequences it is chosen on (F = 0.05, the target's bound, or "
             "a tighter 0.035 / 0.03, a margin for unseen sequences); leave one sequence out: chosen on 21, "
             "scored on the 22nd, counts summed.  Fixed model: the wide formats (model_frac 4, bg_frac 16, "
             "weight_frac 8).  Rows *holds only ...*: a variant measured here only (not in the models), the latch "
             "holds only while the search state (from the confidence) is not ok as well.  Rows *or orientation "
             "rho < t*: one more cue, measured here only (`python studies/accuracy22.py orient --tag motion`, "
             "then `loss --tag motion --motion --orient`): rho between the 9-bin orientation histogram "
             "(ms_orient_bin, orient_T 64, full resolution) of the kept box and of the init box, smoothed "
             "with rate 1/2; t in 0.90, 0.92, 0.94 or off (grid of 12,240 points).  "
             "Cells: recall / false alarms.", "",
             "| latch; choice bound F | point (loss_rho, loss_contrast, loss_jump, loss_stay) | float, in sample | "
             "fixed, in sample | float, leave one out | fixed, leave one out |",
             "|---:|---|---|---|---|---|"]
    chosen_at = {}
    for variant, fa in (("rho", FA_MAX), ("rho", 0.035), ("rho", 0.03), ("rho+state", FA_MAX), ("rho+state", 0.03)):
        key, ins, lo, chosen = loso_motion(tag, fa, variant=variant)
        if variant == "rho":
            chosen_at[fa] = chosen
        lines.append(f"| {'' if variant == 'rho' else 'holds only while the search state is not ok; '}{fa:g} | {key[0]:.2f}, {key[1]:.2f}, {key[2]:g}, {key[3]:g} | {fmt_ld(ins['float'])} | "
                     f"{fmt_ld(ins['fixed'])} | {fmt_ld(lo['float'])} | {fmt_ld(lo['fixed'])} |")
        res["loss"][f"motion latch ({variant}), F {fa:g}"] = {"point": list(key), "in_sample": {m: fmt_ld(ins[m]) for m in MODELS},
                                                  "loso": {m: fmt_ld(lo[m]) for m in MODELS}}
    if (OUT / tag / f"orient_fixed_{sorted(load(tag, 'fixed'))[0]}.npz").is_file():
        for fa in (FA_MAX, 0.035, 0.03):
            key, ins, lo, chosen = loso_motion(tag, fa, orient=True)
            lines.append(f"| or orientation rho < t; {fa:g} | {key[0]:.2f}, {key[1]:.2f}, {key[2]:g}, {key[3]:g}, "
                         f"t {key[4]:g} | {fmt_ld(ins['float'])} | {fmt_ld(ins['fixed'])} | {fmt_ld(lo['float'])} | "
                         f"{fmt_ld(lo['fixed'])} |")
            res["loss"][f"motion latch + orientation, F {fa:g}"] = {
                "point": list(key), "in_sample": {m: fmt_ld(ins[m]) for m in MODELS},
                "loso": {m: fmt_ld(lo[m]) for m in MODELS}}
    lines += ["", "Points chosen leaving each sequence out (F = 0.05): " +
              ", ".join(f"{n} ({', '.join(f'{x:g}' for x in k)})" for n, k in chosen_at[FA_MAX].items()) + ".", ""]
    # where the leave-one-out errors are: per sequence, the point chosen without it (F = 0.05)
    lines += ["Per sequence, scored at the point chosen without it (F = 0.05): off-target frames flagged / "
              "off-target frames, on-target frames flagged / on-target frames.", "",
              "| sequence | float off | float on | fixed off | fixed on |", "|---|---:|---:|---:|---:|"]
    per = {m: motion_tables(load(tag, m), m) for m in MODELS}
    for n, k in chosen_at[FA_MAX].items():
        i = (int(np.argmin(np.abs(M_RHO - k[0]))) * len(M_CON) + int(np.argmin(np.abs(M_CON - k[1]))))
        j = M_JUMP.index(k[2]) * len(M_STAY) + M_STAY.index(k[3])
        c = {m: per[m][n][i, j] for m in MODELS}
        lines.append(f"| {n} | {c['float'][0]} / {c['float'][1]} | {c['float'][2]} / {c['float'][3]} | "
                     f"{c['fixed'][0]} / {c['fixed'][1]} | {c['fixed'][2]} / {c['fixed'][3]} |")
    return lines + [""]


NOTES = {
    "defaults": "tracker v2's defaults in both models (the fixed model = core v2).",
    "wide": "the defaults with the fixed model's wider formats model_frac 4, bg_frac 16, weight_frac 8 "
            "(FixedParams; float unchanged).  Every run below uses them in the fixed model.",
    "stm2": "gated scale test margin 0.002 (scale_test_margin).",
    "stm5": "gated scale test margin 0.005.",
    "sr0": "no pull toward the init size (scale_reg 0).",
    "sr03": "scale_reg 0.03.",
    "sg5sr03": "scale_gain 0.5, scale_reg 0.03.",
    "sw2": "widened search while lost (search_widen 2).",
    "rsm2": "the mean shift's rho stop with a margin of 0.002 (rho_stop_margin; float on its numpy path).",
    "motion": "the loss flag's motion latch (loss_jump 1.25, loss_stay 0.95) with the base rule at 0.90 / 0.08 "
              "against rho_ref (loss_ref_running), the point chosen for it on the 22; the boxes are those of "
              "wide (the flag does not steer the tracker).",
    "rg5": "shrink guard 0.5 (scale_ring_guard; docs/algorithm.md v2.5a), scale_reg at its default 0.1.",
    "rg3": "shrink guard 0.3, scale_reg 0.1.",
    "rg5sr05": "shrink guard 0.5, scale_reg 0.05.",
    "rg3sr0": "shrink guard 0.3 without the pull toward the init size (scale_reg 0).",
    "rg5sr0": "shrink guard 0.5, scale_reg 0.",
    "rg7sr0": "shrink guard 0.7, scale_reg 0.",
    "mu16": "guarded model update at rate 1/16 (model_rate; docs/algorithm.md v2.6a).",
    "mu64": "guarded model update at rate 1/64.",
    "mu128": "guarded model update at rate 1/128.",
    "mu16m2": "guarded model update at rate 1/16, half the init model kept (model_mix 1/2).",
    "mu64m2": "guarded model update at rate 1/64, model_mix 1/2.",
    "mu64rg5": "guarded model update at 1/64 and shrink guard 0.5 (scale_reg 0.1).",
    "mu64rg5sr05": "guarded model update at 1/64, shrink guard 0.5, scale_reg 0.05.",
    "mu64c15": "guarded model update at 1/64, learning only where contrast_s >= 0.15 (model_contrast).",
    "mu64c15rg5": "guarded model update at 1/64 with model_contrast 0.15, and shrink guard 0.5 (scale_reg 0.1).",
    "mu64c15rg5sr05": "as mu64c15rg5 with scale_reg 0.05.",
    "chroma1": "normalised-chromaticity bins with 1 intensity bit (chroma_bins; docs/algorithm.md v2.2b; "
               "float on its numpy path).",
    "chroma2": "chromaticity bins with 2 intensity bits.",
    "chroma3": "chromaticity bins with 3 intensity bits.",
    "lref": "loss flag against the running reference (loss_ref_running) at 0.91 / 0.13, the pair chosen "
            "for it on the 22 (the boxes are those of defaults: the flag does not steer the tracker).",
}


#: what the runs above show (each item names the run and table it rests on)
FINDINGS = [
    "**v2 is below CSRT on the 22** (mean AUC 0.499 / 0.501 float / fixed against 0.563, mean P@20 "
    "0.718 / 0.713 against 0.796): ahead on the dev set, behind on validation (Car1, Car4, David, Dog1 most).",
    "**Where float and fixed part (run defaults, divergence table).**  On Car4, Deer and Woman on the first "
    "frame: rho at init differs by up to 0.23 (Car4 0.794 float, 0.565 fixed).  Two formats of the fixed "
    "model's init model and bin pass cause it: (1) ms_bg_model's CBWH factors in Q.8 set v = 0 for every ring "
    "colour more than 256x as frequent as the rarest (large rings: Car1, Car4, Suv, Deer, David); (2) "
    "ms_model_scale's integer Qw = (Qn K) >> 16 floors most of 4,608 joint bins to 0 in windows of a few "
    "thousand pixels (Football1, Couple, Surfer, ball1_vot).  With 16 bits for v (bg_frac), 4 fraction "
    "bits for Qw (model_frac) and a 4.8 weight (weight_frac 8) the init rho differs by at most 0.01 on 15 of 22 "
    "sequences and 0.02 on 20 (0 of 22 at the core's formats; ClifBar keeps 0.053) and float and fixed stay within 0.01 AUC on 15 of 22 "
    "sequences instead of 7 (run wide); Car4's gap goes from -0.129 to -0.000, Football1's from -0.192 "
    "to -0.005.",
    "**What still parts them (run wide).**  Decision points hit by rounding: the gated scale test's verdict "
    "(Freeman1: the fixed model takes a size step on frame 50 that float does not; Girl frame 37), the "
    "search state from the confidence (Girl, Jogging-1), and the init box itself (ball1_vot: float keeps "
    "23.5 px, fixed rounds to 24).  A margin on the scale test (runs stm2, stm5) does not help: 10 and 12 "
    "of 22 within 0.01 (the count moves by several sequences with any small change: the remaining gaps "
    "are losses and recoveries that happen in one model and not the other).",
    "**Car4, Car1 (grey, the target shrinks to 63 % / 42 % of its init size)**: the box stays near its init "
    "size (the pull toward w0, scale_reg 0.1, and the gated test's vetoes), the oversized window takes in "
    "the road and drifts off (Car4: IoU 0.59 at frame 100, 0.19 at 150; Car1 lost at about frame 200).  "
    "Without the pull (run sr0) Car1 goes from 0.353 to 0.568 (float) and Freeman1 from 0.181 to 0.496, "
    "but Suv falls from 0.590 to 0.106 and the 22's mean AUC from 0.499 to 0.459; scale_reg 0.03 and "
    "scale_gain 0.5 (runs sr03, sg5sr03) are also worse on the whole set.  **David** (illumination, the "
    "face darkens): the confidence falls below conf_lost from frame 12 and the tracker alternates between "
    "search and tracking with IoU 0.25..0.4 throughout; a grey or chromaticity remedy was not measured.",
    "**Widened search (run sw2)**: re-acquires a 100 px jump on synthetic frames "
    "(tests/test_fixed_v2_widths.py), but on real video the lost state is frequent and a wider search "
    "jumps to distractors: mean AUC 0.407 / 0.431 (float / fixed) against 0.499 / 0.509.",
    "**rho stop with a margin (run rsm2)**: on the synthetic shifts of tests/test_float_v2.py float v2 stops "
    "up to 3.1 px short on rho's flat top where the fixed model (its quantised S ties instead of falling) "
    "goes on to the optimum; a margin of 0.002 makes float converge too "
    "(tests/test_fixed_v2_widths.py), but on the 22 it costs AUC (mean 0.493 / 0.501 against 0.499 / "
    "0.509) and P@20 (0.715 / 0.716 against 0.718 / 0.733), and 12 of 22 sequences within 0.01.",
    "**Shrink guard (runs rg*, docs/algorithm.md v2.5a)**: refusing a shrinking step while the window's "
    "ring is as target-coloured as g x the box stops Suv's collapse without the pull toward the init size "
    "(run rg5sr0: Suv 0.520 / 0.549 float / fixed against 0.106 / 0.103 in sr0) and keeps most of sr0's "
    "gain on Car1 (0.483 / 0.494; wide 0.353 / 0.357, sr0 0.568 / 0.569), but the other sequences that shrink too far without the pull (Jogging-1, "
    "bag_vot, Girl, ball1_vot, Crossing: the box at 0.3..0.75 of the ground truth's width) do so with "
    "ring / share 0.3..0.6, below the guard: mean AUC 0.480 / 0.500.  With a weaker pull (run rg5sr05, "
    "scale_reg 0.05) the guard is the best scale setting measured: mean AUC 0.501 / 0.520, P@20 0.721 / "
    "0.741 (wide: 0.499 / 0.509, 0.718 / 0.733); better on Freeman1, Suv, bag_vot, ClifBar, Football1; "
    "worse on ball1_vot and, in float only, Jogging-1 (a loss that float and fixed take differently in "
    "most runs: 0.21 or 0.58..0.73).  Car1 and Car4 do not gain with any guard that keeps a pull "
    "(per-sequence table above): their boxes stay oversized with ring / share about 0.6, so the ring "
    "cue does not separate a grey car from a grey road.",
    "**Guarded model update (runs mu*, docs/algorithm.md v2.6a)**: re-learning the CBWH model at the "
    "tracked box on ok, unflagged frames and blending it in at 1/64 (run mu64) lifts David from 0.384 "
    "/ 0.385 to 0.549 / 0.555 (the face's colours move with the light), Jogging-1, Skiing, Bolt2, "
    "Surfer, Football1 and Subway; it costs Suv (0.590 -> 0.349 float: the box shrinks to about 0.76 "
    "of the ground truth's width once updates start), MotorRolling, bag_vot, Crossing, Car4 and "
    "ClifBar.  Mean AUC 0.507 / 0.522, mean P@20 0.772 / 0.798 (fixed P@20 at CSRT's 0.796; AUC "
    "below its 0.563).  At 1/16 the drift wins (0.472 / 0.453; Crossing 0.667 -> 0.161); 1/128 and "
    "keeping half the init model (model_mix 1/2) are no better than 1/64.  Update and shrink guard "
    "together (run mu64rg5): 0.508 / 0.527, P@20 0.765 / 0.795, the highest fixed mean AUC measured, "
    "still 0.036 below CSRT; with scale_reg 0.05 as well (mu64rg5sr05) 0.502 / 0.519.  Learning only "
    "where the target stands out from its ring (model_contrast 0.15, the loss flag's smoothed contrast; "
    "run mu64c15) spares Suv, MotorRolling and ClifBar part of their loss (median contrast_s on ok frames "
    "0.02 / 0.10 / 0.08 in run wide, against 0.22 for David): 0.515 / 0.522, P@20 0.780 / 0.777.  With "
    "the shrink guard 0.5 (run mu64c15rg5) the fixed model reaches mean AUC 0.537 and mean P@20 0.804, "
    "above CSRT's P@20 (0.796) and 0.026 below its AUC (0.563); float 0.505 / 0.752 (MotorRolling 0.134 "
    "float, 0.319 fixed: float and fixed within 0.01 on 9 of 22).  The rates, the contrast 0.15 and the "
    "guard 0.5 were compared on these 22 sequences only (in sample, no held-out set).",
    "**Chromaticity bins (runs chroma*, docs/algorithm.md v2.2b)**: r, g at 3 bits and 1, 2 or 3 "
    "intensity bits in place of RGB at 3 bits lift David (0.384 -> 0.499 / 0.472 / 0.431 float with 1 / "
    "2 / 3 bits), Skiing and Girl, but lose where target and background differ mostly in brightness, "
    "the grey sequences among them (2 bits: Surfer 0.456 -> 0.133, Car4 0.412 -> 0.189, Couple, Woman, "
    "MotorRolling, ClifBar; 1 bit: Bolt2 0.554 -> 0.010, Subway 0.695 -> 0.202): mean AUC 0.406 / 0.451 / "
    "0.467 float, 0.423 / 0.451 / 0.466 fixed, below every other run.  The guarded model update does "
    "more for David with fewer losses elsewhere.",
        "**Loss flag**: no pair of the two thresholds reaches recall 0.6 at false alarms <= 0.05 on the 22, in "
    "sample or out (best in sample 0.36 / 0.38 at 0.048 / 0.042 against rho0).  Comparing with the running "
    "reference rho_ref (loss_ref_running) keeps the pair stable when a sequence is left out (0.90..0.94 / "
    "0.11..0.16; false alarms out of sample 0.064 / 0.068 against 0.145 / 0.135) but does not raise recall "
    "(0.35 / 0.41).  The off-target frames the flag misses sit on same-coloured background or distractors "
    "(Car1 63 frames, Bolt2 39, ClifBar 32: rho_s / rho0 0.76..0.92 there); most false alarms are Woman's "
    "(135 of its 210 on-target frames: rho_s / rho0 0.55, the target's look changes after frame 1).",
    "**Loss flag with the motion latch (run motion)**: a jump of the centre against its last step (more than "
    "1.25 x (w + h) / 2) starts a loss that holds while rho_s < 0.95 rho_ref; with the base rule at 0.90 / 0.08 "
    "it reaches the target in sample on the 22 (recall 0.627 / 0.660 at 0.047 / 0.049 false alarms, float / "
    "fixed) but not leaving one sequence out (0.493 / 0.516 at 0.077 / 0.092; chosen at a tighter bound of "
    "0.03: 0.562 / 0.574 at 0.054 / 0.061).  The latch catches what no colour cue sees: the jumps to a "
    "look-alike or to background of Girl, MotorRolling, Skiing, Surfer, Diving and Jogging-1 (all or most of "
    "their off-target frames); it does not catch a slow slide onto a same-coloured neighbour (Bolt2 0 of 39, "
    "Car1 3..4 of 63).  Out of sample the false alarms come from sequences where a jump is followed by a "
    "tracked target whose rho stays below 0.95 rho_ref (Woman 72 / 55 of about 205, Suv, Girl's fixed run) "
    "and from the choice moving along a flat frontier when one sequence is left out (Football1 left out: "
    "loss_jump 1, loss_stay 0.975, 39 of its 46 on-target frames flagged).  A latch that holds only while "
    "the search state is not ok as well comes closest to the false-alarm bound out of sample (0.052 / 0.056) "
    "at lower recall (0.463 / 0.462; 0.488 / 0.503 in sample).",
    "**Orientation cue (measured on the kept boxes, not yet a model signal)**: or'ing in the rho of the "
    "box's 9-bin orientation histogram against the init box's (< 0.92) raises float recall (in sample 0.698 "
    "/ 0.669 at 0.049 / 0.050, float / fixed; leaving one sequence out 0.668 / 0.605) but the false alarms "
    "out of sample stay above the bound (0.086 / 0.097; chosen at a bound of 0.03: 0.647 / 0.547 at 0.051 / "
    "0.060).  It is the next candidate for a model signal (the joint bins' pass would accumulate the 9 "
    "orientation counts of the window), with a margin on its choice.",
]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("cmd", choices=("run", "report", "diverge", "loss", "doc", "orient"))
    ap.add_argument("--tags", default="default")
    ap.add_argument("--tag", default="default")
    ap.add_argument("--set", nargs="*", default=[])
    ap.add_argument("--models", default="float,fixed")
    ap.add_argument("--px", type=float, default=4.0)
    ap.add_argument("--ref", choices=("rho0", "rho_ref"), default="rho0")
    ap.add_argument("--motion", action="store_true", help="loss: the motion latch's rule (a run with loss_jump > 0)")
    ap.add_argument("--orient", action="store_true", help="loss --motion: with the orientation cue (after `orient`)")
    ap.add_argument("--fa-fit", type=float, default=FA_MAX, help="loss --motion: false-alarm bound of the choice")
    a = ap.parse_args(argv)
    LOSS_REF["ref"] = a.ref
    if a.cmd == "run":
        main_run(a.tag, parse_sets(a.set), tuple(a.models.split(",")))
    elif a.cmd == "report":
        main_report(a.tag)
    elif a.cmd == "diverge":
        main_diverge(a.tag, a.px)
    elif a.cmd == "orient":
        orient_rho(a.tag)
    elif a.cmd == "doc":
        main_doc(a.tags.split(","), NOTES)
    elif a.motion:
        main_loss_motion(a.tag, a.fa_fit, a.orient)
    else:
        main_loss(a.tag)
    return 0


if __name__ == "__main__":
    sys.exit(main())
