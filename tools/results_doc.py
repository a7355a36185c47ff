"""Compose docs/results.md from the float and fixed evaluation reports (run by `make results`).

Copies report.md/json and the plots of out/eval_float and out/eval_fixed into docs/results/
and writes docs/results.md: the overall tables of both runs, side by side with their commands
and the "Tools:" line of each report (the numpy / OpenCV / numba versions that produced it).
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RUNS = {"float": REPO / "out" / "eval_float", "fixed": REPO / "out" / "eval_fixed"}
DOCS = REPO / "docs"


def section(md: str, title: str) -> str:
    """The body of the '## title' section of a report.md."""
    part = md.split(f"## {title}\n", 1)[1]
    return part.split("\n## ", 1)[0].strip()


def command(md: str) -> str:
    return next(line for line in md.splitlines() if line.startswith("Command:"))


def tools(md: str) -> str:
    """The report's "Tools: ..." line (mstrack.versions.tools_line), which names what produced it."""
    return next((line for line in md.splitlines() if line.startswith("Tools:")),
                "Tools: not recorded in this report (made before `mstrack eval` recorded them).")


LOSS_TRACKERS = (("mstrack-v2", "float"), ("mstrack-v2", "fixed"), ("mstrack-v2-joint", "float"),
                 ("mstrack-v2-joint", "fixed"), ("mstrack-fused-flat", "float"),
                 ("mstrack-fused-flat", "fixed"), ("mstrack-colour-flat", "float"))


def loss_section(seq_root: Path) -> list[str]:
    """Issue 10's loss signal: per tracker, off-target frames (IoU = 0) flagged not ok (recall) and
    on-target frames (IoU >= 0.5) flagged not ok (false alarms), from the cached runs; and the
    confidence-vs-IoU plot of v2 (docs/results/v2_confidence.png)."""
    import json

    import numpy as np

    sys.path.insert(0, str(REPO))
    from mstrack.io.data import load_dataset
    from mstrack.eval.evaluate import SequenceRun
    from mstrack.eval.metrics import iou, loss_detection, valid_gt

    seqs = {s.name: s for s in load_dataset(seq_root)}
    rows, per_seq, conf_io = [], {}, {}
    for name, model in LOSS_TRACKERS:
        label = name if model == "float" else f"{name}@fixed"
        ious, oks = [], []
        for sname, seq in seqs.items():
            f = RUNS[model] / "results" / label / f"{sname}.json"
            if not f.is_file():
                return [f"(loss table: {f} missing; run `make results`)"]
            run = SequenceRun.from_json(json.loads(f.read_text()))
            gt = seq.gt[:run.n_frames]
            v = valid_gt(gt)
            v[0] = False  # the init frame says nothing about loss detection
            io = iou(run.boxes, gt)[v]
            ok = run.ok[v]
            ious.append(io)
            oks.append(ok)
            ld = loss_detection(io, ok)
            per_seq.setdefault(sname, {})[label] = ld
            if name == "mstrack-v2":
                c = np.asarray(run.confidence, dtype=np.float64)[v]
                conf_io.setdefault(model, []).append((c, io))
        ld = loss_detection(np.concatenate(ious), np.concatenate(oks))
        rows.append(f"| {label} | {ld.off} | {ld.recall:.2f} | {ld.on} | {ld.false_alarm:.3f} |")
    out = ["## Loss detection (issue 10)", "",
           "Per frame, frames with valid ground truth after the init frame: *recall* = share of "
           "off-target frames (IoU = 0) whose result is not `ok`; *false alarms* = share of on-target "
           "frames (IoU >= 0.5) whose result is not `ok` (`TrackResult.ok`: status ok, init, clipped or "
           "reacquired).  Target: recall >= 0.6 at false alarms <= 0.05.  From the cached runs of the "
           "two commands above.  v2's `ok` is its loss flag (docs/algorithm.md, \"v2.7a Loss flag\"); "
           "the signals, the choice of the rule and its leave-one-sequence-out scores: "
           "[results_loss.md](results_loss.md).", "",
           "| tracker | off-target frames | recall | on-target frames | false alarms |", "|---|---:|---:|---:|---:|"]
    out += rows
    labels = [n if m == "float" else f"{n}@fixed" for n, m in LOSS_TRACKERS[:2]]
    out += ["", "Per sequence (v2): off-target frames / recall, on-target frames / false alarms:", "",
            "| sequence | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for sname, d in per_seq.items():
        cells = []
        for lab in labels:
            ld = d[lab]
            rec = "-" if ld.off == 0 else f"{ld.recall:.2f}"
            fa = "-" if ld.on == 0 else f"{ld.false_alarm:.2f}"
            cells.append(f"{ld.off} / {rec}, {ld.on} / {fa}")
        out.append(f"| {sname} | " + " | ".join(cells) + " |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        edges = np.linspace(0, 1, 11)
        for model, parts in conf_io.items():
            c = np.concatenate([p[0] for p in parts])
            io = np.concatenate([p[1] for p in parts])
            good = np.isfinite(c)
            c, io = c[good], io[good]
            idx = np.clip(np.digitize(c, edges) - 1, 0, 9)
            mids = [(edges[i] + edges[i + 1]) / 2 for i in range(10) if (idx == i).any()]
            mean = [io[idx == i].mean() for i in range(10) if (idx == i).any()]
            off = [(io[idx == i] == 0).mean() for i in range(10) if (idx == i).any()]
            ax.plot(mids, mean, "o-", label=f"v2 {model}: mean IoU")
            ax.plot(mids, off, "x--", label=f"v2 {model}: share IoU = 0")
        ax.set_xlabel("confidence (bins of 0.1)")
        ax.set_ylabel("IoU / share of frames")
        ax.set_ylim(0, 1)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("Tracker v2: confidence against IoU (dev set)")
        fig.tight_layout()
        fig.savefig(DOCS / "results" / "v2_confidence.png", dpi=100)
        plt.close(fig)
        out += ["", "![confidence vs IoU](results/v2_confidence.png)"]
    except ImportError:
        pass
    return out + [""]


def main(argv: list[str] | None = None) -> int:
    argv = [] if argv is None else argv
    out = ["# Results on real video", "",
           "OTB one-pass evaluation (init on frame 0 with the ground truth, no re-init) of mstrack "
           "(float reference and bit-accurate fixed-point model = the hardware) and four OpenCV "
           "baselines on every sequence of `../shared/data/sequences` (10 OTB/VOT sequences, 2490 "
           "frames). Metrics: `mstrack/eval/metrics.py` (success AUC over IoU thresholds 0:0.05:1, "
           "precision at 20 px; frame-weighted). Regenerate with `make results` "
           "(runs the two commands below, then `python tools/results_doc.py`).", ""]
    for name, run in RUNS.items():
        rep = run / "report.md"
        if not rep.is_file():
            print(f"missing {rep}: run `make results`", file=sys.stderr)
            return 1
        dst = DOCS / "results" / name
        dst.mkdir(parents=True, exist_ok=True)
        for f in ("report.md", "report.json", "success.png", "precision.png"):
            shutil.copy(run / f, dst / f)
        md = rep.read_text()
        out += [f"## {'Float reference and OpenCV baselines' if name == 'float' else 'Fixed-point model (= the RTL cores; mstrack-v2-joint: core v2 with ORIENT_T 64, experimental)'}",
                "", command(md), "", tools(md), "", section(md, "Overall"), "",
                f"Per sequence and per attribute: [results/{name}/report.md](results/{name}/report.md). "
                f"Machine-readable: `results/{name}/report.json`.", "",
                f"![success {name}](results/{name}/success.png) ![precision {name}](results/{name}/precision.png)", ""]
    seq_root = Path(argv[0]) if argv else REPO.parent / "shared" / "data" / "sequences"
    out += loss_section(seq_root) if seq_root.is_dir() else [f"(loss table: {seq_root} not found)", ""]
    out += ["## Reading the numbers", "",
            "* **Tracker v2** (`preset=\"v2\"`, docs/algorithm.md \"Tracker v2\"; fixed-point model "
            "docs/fixed_point.md \"Tracker v2\") is the background-weighted colour tracker with scale, "
            "decimation, confidence and a wide search.  It is the best mstrack tracker on this set in "
            "both layers and beats CSRT's overall AUC; its mean over sequences and its loss signal are "
            "below the issue's targets (the numbers above; docs/results.md is regenerated by `make results`).",
            "* **mstrack-v2-joint** (experimental: float and fixed models, and core v2 with generics ORIENT_T 64 and SCALE_TEST_D256 13, bit-exact in simulation since session 15) is tracker v2 "
            "with the joint colour x gradient-orientation histogram (`orient_T=64`: 512 colour bins x 9 "
            "orientation bins), the gated scale test (`scale_test=0.05, scale_test_gate=True`) and the loss "
            "flag's thresholds chosen again for it on this set (`loss_rho=0.69, loss_contrast=0.25`: in "
            "sample; leaving one sequence out gives about 0.54 / 0.83 recall at 0.063 / 0.070 false alarms, "
            "float / fixed).  It is the candidate for the next default (docs/results_v2_mean.md): the default "
            "stays `mstrack-v2` until the joint core's Fmax (112.65 MHz at grade 8) and the default switch with core v2's tests are done (\"Path to adoption\").",
            "* **Fusion does not pay on this set (paper preset).** In the run above, colour alone beats the fused "
            "tracker. The 16-bin gradient-magnitude histogram discriminates poorly (edge alone is the "
            "weakest mstrack variant): the background next to a target often has an edge histogram much "
            "like the target's. rho_e then stays near 1, and alpha_e = rho_e / (rho_c + rho_e) gives the "
            "edge centre a large weight. The paper's claim that fusion helps does not hold here with "
            "these parameters. Colour-only is one parameter away (`features=\"colour\"`, VHDL generic "
            "`FEATURES = 1`). The default stays fused because that is the paper's algorithm.",
            "* fps is `update()` only, on a shared 2-core machine, with every tracker in one process. It is a "
            "rough guide; `mstrack bench` (docs/bench.md) measures the speed properly.",
            "* The hardware runs at one pixel per clock whatever the tracker's speed in Python; "
            "see docs/performance.md and docs/realtime.md.",
            "* Float vs fixed on the same frames, frame by frame: docs/results_fixed.md.", ""]
    (DOCS / "results.md").write_text("\n".join(out))
    print(DOCS / "results.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
