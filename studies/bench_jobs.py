"""Time ``mstrack eval --jobs N`` against one process on a dataset and write docs/bench_jobs.md.

    python studies/bench_jobs.py [DATASET_DIR] [--jobs 1,2] [--trackers a,b] [--scheduler] [--out build/bench_jobs]

Each run is a fresh evaluation (``--force``: nothing from the cache) into its own folder, one after
the other; then the reports are compared without their timings (fps): they must be identical.
The page names the command, the machine (cores, load average before each run) and the tool
versions.  The machine may be shared: the load average says how busy it was.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from mstrack.versions import PYTHON_TOOLS, tools_line  # noqa: E402


def strip(obj):
    """``obj`` without timing fields (fps, update time) and the command line."""
    if isinstance(obj, dict):
        return {k: strip(v) for k, v in obj.items() if k not in ("fps", "update_time_s", "command")}
    if isinstance(obj, list):
        return [strip(v) for v in obj]
    return obj


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", nargs="?", default=str(REPO.parent / "shared" / "data" / "sequences"))
    ap.add_argument("--jobs", default="1,2", help="comma-separated job counts (default 1,2)")
    ap.add_argument("--trackers", help="as mstrack eval (default: all)")
    ap.add_argument("--scheduler", action="store_true", help="also time --jobs N --scheduler (local Dask)")
    ap.add_argument("--out", default=str(REPO / "build" / "bench_jobs"))
    ap.add_argument("--docs-file", default=str(REPO / "docs" / "bench_jobs.md"))
    args = ap.parse_args(argv)
    jobs = [int(j) for j in args.jobs.split(",")]
    cases = [(j, False) for j in jobs] + ([(j, True) for j in jobs if j > 1] if args.scheduler else [])
    rows, reports = [], {}
    for j, dask in cases:
        out = Path(args.out) / (f"dask{j}" if dask else f"jobs{j}")
        cmd = [sys.executable, "-m", "mstrack.cli", "eval", args.dataset, "--out", str(out), "--force", "--quiet",
               "--jobs", str(j), *(["--trackers", args.trackers] if args.trackers else []),
               *(["--scheduler"] if dask else [])]
        load = os.getloadavg()[0]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, cwd=REPO, stdout=subprocess.DEVNULL)
        dt = time.perf_counter() - t0
        reports[(j, dask)] = strip(json.loads((out / "report.json").read_text()))
        shown = ["mstrack", "eval", "DATASET", "--force", "--quiet", "--jobs", str(j),
                 *(["--trackers", args.trackers] if args.trackers else []), *(["--scheduler"] if dask else [])]
        rows.append((shlex.join(shown), j, dask, dt, load))
        print(f"jobs {j}{' (Dask LocalCluster)' if dask else ''}: {dt:.1f} s (load average before {load:.2f})")
    base = rows[0][3]
    same = all(r == reports[cases[0]] for r in reports.values())
    ev = reports[cases[0]]
    n_frames = sum(s["frames"] for s in ev["sequences"].values())
    try:
        import distributed
        dask_v = f", dask/distributed {distributed.__version__}"
    except ImportError:
        dask_v = ""
    md = ["# Parallel evaluation: `mstrack eval --jobs N`", "",
          f"Command: `python studies/bench_jobs.py {' '.join(shlex.quote(a) for a in (argv or sys.argv[1:]))}`".rstrip()
          + f" (DATASET = `{os.path.relpath(args.dataset, REPO)}`: {len(ev['sequences'])} sequences, "
          f"{n_frames} frames; trackers: {', '.join(ev['trackers'])}).", "",
          f"Date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M UTC}; machine: {platform.machine()}, "
          f"{os.cpu_count()} cores, Python {platform.python_version()}.", "",
          tools_line(PYTHON_TOOLS).rstrip(".") + dask_v + ".", "",
          "Wall time of each whole command (start-up, numba kernels loaded from their disk cache, every "
          "(tracker, sequence) run with `--force`, report and plots), run one after the other.  The "
          "machine is shared with other jobs: the load average before each run says how busy it was, and "
          "a busy machine makes the speed-up look smaller than on an idle one (pessimistic figure).", "",
          "| command | workers | wall time (s) | speed-up | load average before |", "|---|---:|---:|---:|---:|"]
    md += [f"| `{c}` | {j}{' (Dask)' if d else ''} | {dt:.1f} | {base / dt:.2f}x | {ld:.2f} |" for c, j, d, dt, ld in rows]
    md += ["", f"Reports identical to the one-process run (every score and curve of report.json, fps "
           f"excluded): **{'yes' if same else 'NO'}**.", ""]
    Path(args.docs_file).write_text("\n".join(md))
    print(f"wrote {args.docs_file}; reports identical: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
