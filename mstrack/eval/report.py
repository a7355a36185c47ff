"""Write an evaluation report folder.

``write_report(ev, out)`` writes:

* ``report.md``: overall table (tracker, AUC, precision@20, fps), per-sequence
  AUC table, per-attribute AUC table, the failed runs with their reasons; a
  ``Tools:`` line names the numpy / OpenCV / numba versions
  (:func:`mstrack.versions.tools_line`);
* ``report.json``: the same numbers plus all curves, ``failed`` and
  ``tools``, machine readable;
* ``success.png`` / ``precision.png``: overall OTB-style plots, legend
  entries ``name [AUC]`` / ``name [P@20]`` sorted best first.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from .evaluate import Evaluation
from .metrics import CE_THRESHOLDS, IOU_THRESHOLDS, PRECISION_AT, Scores
from ..versions import PYTHON_TOOLS, tool_versions, tools_line


def _f(v: float, nd: int = 3) -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{nd}f}"


def _scores_json(s: Scores) -> dict[str, Any]:
    return {"auc": s.auc, "precision20": s.precision20, "n_frames": s.n_frames,
            "success": s.success.tolist(), "precision": s.precision.tolist()}


def _num(v: float) -> float | None:
    return None if v is None or math.isnan(v) else float(v)


def report_dict(ev: Evaluation) -> dict[str, Any]:
    """All numbers and curves of ``ev`` as a JSON-ready dict."""
    return {
        "protocol": "OTB one-pass evaluation (OPE); overall and attribute scores frame-weighted",
        "iou_thresholds": IOU_THRESHOLDS.tolist(),
        "centre_error_thresholds_px": CE_THRESHOLDS.tolist(),
        "precision_at_px": PRECISION_AT,
        "trackers": ev.trackers,
        "sequences": {s: {"frames": ev.seq_frames.get(s)} for s in ev.sequences},
        "attributes": ev.attributes,
        "overall": {t: {**_scores_json(ev.overall[t]), "fps": _num(ev.fps[t])} for t in ev.trackers},
        "per_sequence": {t: {s: {**_scores_json(sc), "fps": _num(ev.runs[t][s].fps)}
                             for s, sc in ev.per_sequence[t].items()} for t in ev.trackers},
        "per_attribute": {t: {a: _scores_json(sc) for a, sc in ev.per_attribute[t].items()}
                          for t in ev.trackers},
        "failed": ev.failed,
        "tools": {k: tool_versions()[k] for k in PYTHON_TOOLS},
    }


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def report_markdown(ev: Evaluation, title: str = "mstrack evaluation", command: str | None = None) -> str:
    """Markdown text of the report (trackers sorted by overall AUC)."""
    order = sorted(ev.trackers, key=lambda t: -ev.overall[t].auc)
    n_total = sum(ev.seq_frames.get(s, 0) for s in ev.sequences)
    out = [f"# {title}", "",
           f"OTB one-pass evaluation on {len(ev.sequences)} sequences ({n_total} frames). "
           "AUC = mean of the success curve over IoU thresholds 0:0.05:1 (success = IoU > threshold); "
           f"P@{PRECISION_AT} = fraction of frames with centre error <= {PRECISION_AT} px; "
           "overall and per-attribute numbers are frame-weighted; fps counts update() only.", ""]
    if command:
        out += ["Command: `" + command + "`", ""]
    out += [tools_line(PYTHON_TOOLS), ""]
    if ev.failed:
        out += [f"**{len(ev.failed)} sequence(s) failed** and are left out of every score below "
                "(see \"Failed runs\").", ""]
    out += ["## Overall", "", _table(["tracker", "AUC", f"P@{PRECISION_AT}", "fps"],
            [[t, _f(ev.overall[t].auc), _f(ev.overall[t].precision20), _f(ev.fps[t], 1)] for t in order]), ""]
    out += ["## AUC per sequence", "", _table(
        ["sequence", "frames", *order],
        [[s, str(ev.seq_frames.get(s, "")), *(_f(ev.per_sequence[t][s].auc) if s in ev.per_sequence[t] else "-"
                                              for t in order)] for s in ev.sequences]), ""]
    if ev.attributes:
        out += ["## AUC per attribute", "", _table(
            ["attribute", "sequences", *order],
            [[a, str(len(seqs)), *(_f(ev.per_attribute[t][a].auc) for t in order)]
             for a, seqs in ev.attributes.items()]), ""]
    if ev.failed:
        out += ["## Failed runs", "", _table(
            ["sequence", "tracker", "reason"],
            [[s, t, r.replace("|", "\\|").replace("\n", " ")] for s, per in ev.failed.items() for t, r in per.items()]), ""]
    return "\n".join(out)


def plot_curves(ev: Evaluation, out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``success.png`` and ``precision.png`` (overall curves); returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    paths = []
    specs = [("success.png", IOU_THRESHOLDS, "success", "auc", "Overlap threshold (IoU)",
              "Success rate", "Success plots of OPE"),
             ("precision.png", CE_THRESHOLDS, "precision", "precision20", "Location error threshold (px)",
              "Precision", "Precision plots of OPE")]
    for fname, x, curve, key, xl, yl, title in specs:
        fig, ax = plt.subplots(figsize=(8.5, 4.5), dpi=100)
        for i, t in enumerate(sorted(ev.trackers, key=lambda t: -getattr(ev.overall[t], key))):
            s = ev.overall[t]
            ax.plot(x, getattr(s, curve), lw=2, ls=("-", "--", ":")[i // 10 % 3],
                    label=f"{t} [{getattr(s, key):.3f}]")
        ax.set(xlabel=xl, ylabel=yl, title=title, ylim=(0, 1), xlim=(x[0], x[-1]))
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, borderaxespad=0)
        fig.tight_layout()
        p = out / fname
        fig.savefig(p)
        plt.close(fig)
        paths.append(p)
    return paths[0], paths[1]


def write_report(ev: Evaluation, out_dir: str | Path, command: str | None = None) -> dict[str, Path]:
    """Write report.md, report.json, success.png and precision.png into ``out_dir``.

    Returns
    -------
    dict
        ``{"md", "json", "success", "precision"}`` -> path written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    md = out / "report.md"
    md.write_text(report_markdown(ev, command=command) + "\n")
    js = out / "report.json"
    d = report_dict(ev)
    if command:
        d["command"] = command
    js.write_text(json.dumps(d, indent=1) + "\n")
    sp, pp = plot_curves(ev, out)
    return {"md": md, "json": js, "success": sp, "precision": pp}
