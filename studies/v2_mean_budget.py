"""Worst-frame clocks of the docs/results_v2_mean.md candidate (joint colour x orientation bins,
gated scale test) with the paper engine's pass costs, as ``mstrack.hw.synth.v2_cycle_budget`` counts
the v2 default (an estimate until core v2 exists).

The joint histogram has 512 x 9 = 4608 bins: every bin pass (one per mean-shift pass) walks
4608 bins instead of 512.  The gated scale test adds, on the final centre, two pixel passes
(windows x0.95 and x1.05, the larger one limited to the window memory) and two bin passes.

A bin pass with B banks (the histogram and model RAMs split by orientation bin, B datapaths
walking the addresses in parallel, partial sums added) walks 4608 / B addresses: rows "4608 / B".

Usage: PYTHONPATH=. python studies/v2_mean_budget.py
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mstrack.hw import synth  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402


def budget(lanes: int, n_bins: int, max_iter: int, scale_test: bool) -> list[tuple[str, int]]:
    g = dict(synth.CONFIGS["default"].generics())
    g["LANES"] = lanes
    tp = TrackerParams(preset="v2")
    rows_scan = synth.scan_kind() == "rows"

    def pp_of(w: int) -> int:
        ex = (w - 1) // 2
        xr = synth.row_extents(w, w, "flat", 8) if rows_scan else None
        return synth.pixel_pass_cycles(ex, ex, g["LANES"], None, xr)

    ov = synth.v2_frame_overhead(g["MAX_HALF"])
    L = synth.bin_pass_cycles(g, n_bins)
    w = tp.max_window
    pp = pp_of(w)
    track = synth.FRONT + synth.engine_cycles(g, [pp] * (max_iter + 1), n_bins, max_iter) + ov + 3
    w2 = (w + 1) // 2
    pp2 = pp_of(w2)
    lost = synth.FRONT + 9 * synth.engine_cycles(g, [pp2] * (tp.search_iter + 1), n_bins, tp.search_iter) + ov + 3
    if scale_test:
        small = 2 * ((int(0.95 * w) - 1) // 2) + 1
        track += pp_of(small) + pp_of(w) + 2 * L + 2 * 195  # x1.05 limited to the 127 px memory
        small2 = 2 * ((int(0.95 * w2) - 1) // 2) + 1
        big2 = 2 * ((int(1.05 * w2) + 1) // 2) + 1
        lost += pp_of(small2) + pp_of(big2) + 2 * L + 2 * 195
    return [(f"tracking, {w}x{w}, {max_iter} iterations", track),
            (f"lost, {w2}x{w2} at 2D, 9 x {tp.search_iter} iterations", lost)]


def main() -> None:
    print("| LANES | bins (/ banks) | max_iter | scale test | frame | worst clocks | vs 99,000 |")
    print("|---:|---:|---:|---|---|---:|---|")
    for lanes in (4, 8):
        for nb, banks, it, st in ((512, 1, 20, False), (512, 1, 20, True), (4608, 1, 20, False),
                                  (4608, 1, 20, True), (4608, 1, 15, True), (4608, 1, 10, True),
                                  (4608, 3, 20, True), (4608, 9, 20, True)):
            if lanes == 8 and banks > 1:
                continue
            for case, clk in budget(lanes, nb // banks, it, st):
                fit = "fits" if clk <= 99000 else "**does not fit**"
                label = f"{nb}" + (f" / {banks}" if banks > 1 else "")
                print(f"| {lanes} | {label} | {it} | {'gated' if st else '-'} | {case} | {clk:,} | {fit} |")


if __name__ == "__main__":
    main()
