"""Compose docs/results_multi.md from the multi-target evaluation reports (run by `make results-multi`).

Copies report.md/json and the plots of out/eval_multi_float and out/eval_multi_fixed into
docs/results/multi_float/ and docs/results/multi_fixed/, and writes docs/results_multi.md: the overall,
per-sequence and per-target tables of float and fixed mstrack-v2 against OpenCV CSRT and KCF (AUC,
P@20, HOTA, MOTA, IDF1, ID switches, the loss table), and the per-target speed of the float
MultiTracker against CamShift's from docs/bench_multi.md (`mstrack bench ../shared/data/multi ...`).
docs/results.md links here (tools/results_doc.py).
"""
from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RUNS = {"float": REPO / "out" / "eval_multi_float", "fixed": REPO / "out" / "eval_multi_fixed"}
DOCS = REPO / "docs"


def _f(v: float | None, nd: int = 3) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{nd}f}"


def _mot(m: dict) -> list[str]:
    return [_f(m.get("HOTA")), _f(m.get("MOTA")), _f(m.get("IDF1")), str(int(m["IDSW"])) if "IDSW" in m else "-"]


def _loss(d: dict) -> list[str]:
    ls = d["loss"]
    return [f"{ls['off']} / {_f(ls['recall'], 2)}", f"{ls['on']} / {_f(ls['false_alarm'], 3)}"]


def _line(md: str, start: str, default: str) -> str:
    return next((ln for ln in md.splitlines() if ln.startswith(start)), default)


def main(argv: list[str] | None = None) -> int:
    reps, mds = {}, {}
    for name, run in RUNS.items():
        if not (run / "report.json").is_file():
            print(f"missing {run / 'report.json'}: run `make results-multi`", file=sys.stderr)
            return 1
        dst = DOCS / "results" / f"multi_{name}"
        dst.mkdir(parents=True, exist_ok=True)
        for f in ("report.md", "report.json", "success.png", "precision.png"):
            shutil.copy(run / f, dst / f)
        reps[name] = json.loads((run / "report.json").read_text())
        mds[name] = (run / "report.md").read_text()
    # the labels in table order: mstrack float, fixed, then the baselines (float report)
    labels = [("float", t) for t in reps["float"]["trackers"] if t.startswith("mstrack-")] + \
             [("fixed", t) for t in reps["fixed"]["trackers"]] + \
             [("float", t) for t in reps["float"]["trackers"] if not t.startswith("mstrack-")]
    seqs = reps["float"]["sequences"]
    n_frames = sum(v["frames"] for v in seqs.values())
    n_tg = sum(v["targets"] for v in seqs.values())
    out = ["# Results: several targets (MOT sequences)", "",
           f"Multi-target tracking on the MOTChallenge-format sequences of `../shared/data/multi` ({len(seqs)} "
           f"sequences, {n_frames} frames, {n_tg} targets: " + ", ".join(
               f"{s} {v['frames']} frames / {v['targets']} targets / {v['gt_boxes']} boxes" for s, v in seqs.items())
           + ").  Regenerate with `make results-multi` (part of `make results`: the two commands below, then "
           "`python tools/results_multi_doc.py`).  API, CLI and protocol: [multi.md](multi.md).", "",
           "**Protocol.** " + reps["float"]["protocol"], ""]
    for name in RUNS:
        out += [_line(mds[name], "Command:", "Command: (not recorded)"), ""]
    out += [reps["float"].get("tools", ""), ""]
    head = ["tracker", "AUC", "P@20", "HOTA", "MOTA", "IDF1", "IDSW", "off-target frames / recall",
            "on-target frames / false alarms", "target updates/s"]
    rows = []
    for model, t in labels:
        d = reps[model]["overall"][t]
        rows.append([t, _f(d["auc"]), _f(d["precision20"]), *_mot(d["mot"]), *_loss(d), _f(d["updates_per_s"], 1)])
    out += ["## Overall (both sequences; AUC, P@20 and the loss table frame-weighted over the targets)", "",
            "| " + " | ".join(head) + " |", "|---|" + "---:|" * (len(head) - 1)]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    out += ["", "target updates/s: `update()` time in the evaluation (one process, every tracker in turn; "
            "CSRT and KCF use OpenCV's thread pool).  The benchmark below measures the speed properly.", ""]
    head = ["sequence", "tracker", "AUC", "P@20", "HOTA", "MOTA", "IDF1", "IDSW", "off / recall", "on / false alarms"]
    out += ["## Per sequence", "", "| " + " | ".join(head) + " |", "|---|---|" + "---:|" * (len(head) - 2)]
    for s in seqs:
        for model, t in labels:
            d = reps[model]["per_sequence"][t].get(s)
            if d is not None:
                out.append(f"| {s} | {t} | " + " | ".join([_f(d["auc"]), _f(d["precision20"]), *_mot(d["mot"]),
                                                           *_loss(d)]) + " |")
    names = [t for _, t in labels]
    out += ["", "## Per target", "",
            "AUC / P@20 over the frames where the target has ground truth (its init frame included); the "
            "frames column counts them.", "",
            "| sequence | id | frames | " + " | ".join(names) + " |", "|---|---:|---:|" + "---|" * len(names)]
    loss_rows = []
    for s in seqs:
        ids = sorted({int(g) for model, t in labels for g in reps[model]["per_target"][t].get(s, {})})
        for g in ids:
            cells, lcells, n = [], [], "-"
            for model, t in labels:
                d = reps[model]["per_target"][t].get(s, {}).get(str(g))
                if d is None:
                    cells.append("-")
                    lcells.append("-")
                    continue
                n = str(d["frames"])
                cells.append(f"{_f(d['auc'])} / {_f(d['precision20'])}")
                lcells.append(", ".join(_loss(d)))
            out.append(f"| {s} | {g} | {n} | " + " | ".join(cells) + " |")
            loss_rows.append(f"| {s} | {g} | " + " | ".join(lcells) + " |")
    out += ["", "Loss table per target (off-target frames / recall, on-target frames / false alarms; init frame "
            "excluded):", "", "| sequence | id | " + " | ".join(names) + " |", "|---|---:|" + "---|" * len(names)]
    out += loss_rows
    refused = {t: r for model in reps for t, r in reps[model].get("refused", {}).items() if r}
    out += ["", "Refused adds (the capacity rule, docs/multi.md): " + (json.dumps(refused) if refused else
                                                                       "none (at most 16 live targets here).")]
    bench = DOCS / "bench_multi.md"
    out += ["", "## Per-target update speed against CamShift (benchmark)", ""]
    if bench.is_file():
        text = bench.read_text().splitlines()
        for ln in text:
            if ln.startswith(("Command:", "Date:", "Tools:")):
                out += [ln, ""]
        out += ["From [bench_multi.md](bench_multi.md): target updates per second of the float MultiTracker "
                "(`mstrack-v2 upd/s`) and of one OpenCV CamShift per target on the same frames and targets "
                "(the eval protocol), frames preloaded; `mstrack-v2/camshift` is their ratio.  A benchmark, not "
                "a timed test: run the command above again to measure on another machine.  Each CamShift converts the "
                "whole frame to HSV and back-projects it on every update, so its cost grows with the frame, "
                "mstrack's with the target's region.", ""]
        out += [ln for ln in text if ln.startswith("|")]
    else:
        out += ["(missing docs/bench_multi.md: run `mstrack bench ../shared/data/multi --model float --frames 1000 "
                "--write-docs`)"]
    out += ["", "## Plots", ""]
    for name in RUNS:
        out += [f"{name}: ![success {name}](results/multi_{name}/success.png) "
                f"![precision {name}](results/multi_{name}/precision.png)  "
                f"(full report: [results/multi_{name}/report.md](results/multi_{name}/report.md))", ""]
    (DOCS / "results_multi.md").write_text("\n".join(out) + "\n")
    print(DOCS / "results_multi.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
