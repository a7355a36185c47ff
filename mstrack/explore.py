"""Design-space exploration: accuracy against hardware cost (``mstrack explore``, docs/explore.md).

Sweeps model parameters (:class:`mstrack.track.params.TrackerParams`), fixed-point widths
(:class:`mstrack.fixed.formats.FixedParams`) and LANES over a grid; for every point it reports

* accuracy on a dataset, from the evaluator (:func:`mstrack.eval.evaluate.evaluate`, so with its
  ``--jobs`` / Dask ``--scheduler`` machinery and its per-(tracker, params, sequence) cache):
  AUC, P@20 and, for trackers with a loss flag (``TrackResult.ok``, tracker v2), the loss
  recall and false alarms of docs/results_loss.md;
* hardware cost of the RTL core ``ms_tracker`` with the point's generics
  (:func:`estimate`): block RAM bits and DP16KD count of the region, histogram and model (Q)
  RAMs, MULT18X18D, and LUT4 / FF scaled block by block from the measured synthesis results of
  docs/performance.md (basis and error: :data:`MEASURED`, docs/explore.md); with ``--yosys``
  also real yosys ``synth_ecp5`` counts (:func:`mstrack.hw.synth.yosys_cached`, cached, slow).

Points that differ only in LANES (a throughput generic: the core's results do not depend on it)
share their accuracy runs.  Outputs in ``--out``: ``explore.md``, ``explore.csv``,
``explore.json`` and ``explore_pareto.png`` (AUC against LUT4 and against DP16KD, Pareto front
highlighted); the evaluator's run cache in ``<out>/results/``.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import math
import sys
import time
from dataclasses import asdict, dataclass, field
from itertools import product
from pathlib import Path
from typing import Any, Callable, Sequence

from .fixed.formats import FixedParams
from .fixed.vhdl_pkg import DEFAULT_LANES, core_generics
from .track.params import ALIASES, TrackerParams, canonical
from .hw.synth import VBLANK_1080P60

# ----------------------------------------------------------------------------- grid
#: grid key -> (where, field, help).  "tp": TrackerParams, "fp": FixedParams, "hw": generic only.
GRID_KEYS: dict[str, tuple[str, str, str]] = {
    "bins": ("tp", "colour_bits", "colour bins per channel (4, 8, 16, ...: a power of two; 8 = paper)"),
    "edge_bins": ("tp", "edge_bins_log2", "edge bins (a power of two; 16 = paper)"),
    "kernel": ("tp", "kernel", "flat or epan(echnikov)"),
    "features": ("tp", "features", "fused, colour or edge (preset paper)"),
    "preset": ("tp", "preset", "paper or v2 (v2 tracks colour only)"),
    "max_iter": ("tp", "max_iter", "mean-shift iterations per frame"),
    "wi": ("fp", "weight_int", "weight integer bits WI"),
    "wf": ("fp", "weight_frac", "weight fraction bits WF"),
    "cf": ("fp", "centre_frac", "centre fraction bits CF"),
    "rf": ("fp", "rho_frac", "rho fraction bits RF"),
    "af": ("fp", "alpha_frac", "fusion weight fraction bits AF"),
    "kb": ("fp", "kernel_bits", "Epanechnikov kernel bits KB"),
    "max_half": ("fp", "max_half", "largest window half extent MAX_HALF"),
    "margin": ("fp", "margin", "search margin MARGIN (px)"),
    "lanes": ("hw", "lanes", "pixels per clock LANES (a power of two; throughput only)"),
}

#: ``mstrack explore`` without ``--grid``: colour bins x weight fraction bits x LANES (12 points,
#: 6 accuracy runs per tracker: LANES does not change results).
DEFAULT_GRID = "bins=4,8,16;wf=2,4;lanes=2,4"
DEFAULT_TRACKERS = ("mstrack-fused-flat",)


class GridError(ValueError):
    """A bad ``--grid`` (one line, lists the valid keys or values)."""


def _valid_keys() -> str:
    return ", ".join(GRID_KEYS)


def _parse_value(key: str, text: str) -> Any:
    where, name, _ = GRID_KEYS[key]
    t = text.strip()
    if name in ALIASES:
        v = canonical(name, t)
        if v not in set(ALIASES[name].values()):
            raise GridError(f"grid key {key!r}: bad value {t!r}; valid: {', '.join(dict.fromkeys(ALIASES[name]))}")
        return v
    try:
        n = int(t)
    except ValueError:
        raise GridError(f"grid key {key!r}: bad value {t!r}; wants integers ({GRID_KEYS[key][2]})") from None
    if key in ("bins", "edge_bins", "lanes"):
        if n < 1 or n & (n - 1):
            raise GridError(f"grid key {key!r}: bad value {t!r}; wants a power of two ({GRID_KEYS[key][2]})")
        if key == "bins":
            return n.bit_length() - 1 if n > 1 else 0
        if key == "edge_bins":
            return n.bit_length() - 1
    return n


def parse_grid(spec: str) -> dict[str, list[Any]]:
    """``"bins=8,16;lanes=2,4"`` -> ``{"bins": [3, 4], "lanes": [2, 4]}`` (values in the units of the
    dataclass field: bins per channel -> colour_bits, edge bins -> edge_bins_log2).

    Keys are :data:`GRID_KEYS`; each value is checked against its dataclass (e.g. ``bins=512`` is
    refused with the valid range).  Raises :class:`GridError` (a ValueError) naming the valid keys
    or values."""
    grid: dict[str, list[Any]] = {}
    for part in (p.strip() for p in spec.replace("\n", ";").split(";")):
        if not part:
            continue
        key, eq, vals = part.partition("=")
        key = key.strip().lower().replace("-", "_")
        if not eq or not vals.strip():
            raise GridError(f"grid item {part!r} is not KEY=V1,V2,...; valid keys: {_valid_keys()}")
        if key not in GRID_KEYS:
            raise GridError(f"unknown grid key {key!r}; valid keys: {_valid_keys()}")
        if key in grid:
            raise GridError(f"grid key {key!r} given twice")
        values = list(dict.fromkeys(_parse_value(key, v) for v in vals.split(",") if v.strip()))
        for v in values:
            _check_one(key, v)
        grid[key] = values
    if not grid:
        raise GridError(f"empty grid; valid keys: {_valid_keys()}")
    return grid


def _check_one(key: str, value: Any) -> None:
    """Refuse a value its dataclass refuses, with the dataclass' message."""
    where, name, _ = GRID_KEYS[key]
    try:
        if where == "tp":
            kw: dict[str, Any] = {name: value}
            if name == "features" and value != "fused":
                kw["preset"] = "paper"
            TrackerParams(**kw)
        elif where == "fp":
            FixedParams(**{name: value})
        elif not 1 <= value <= 64:
            raise ValueError("lanes must be in 1..64")
    except ValueError as exc:
        raise GridError(f"grid key {key!r}: bad value {_show(key, value)!r} ({exc}; {GRID_KEYS[key][2]})") from None


# ----------------------------------------------------------------------------- points
@dataclass(frozen=True)
class Point:
    """One configuration: a base tracker, its TrackerParams / FixedParams overrides and LANES."""

    tracker: str
    tp: tuple[tuple[str, Any], ...]
    fp: tuple[tuple[str, Any], ...]
    lanes: int = DEFAULT_LANES
    grid: tuple[tuple[str, Any], ...] = ()

    def params(self) -> tuple[TrackerParams, FixedParams]:
        return TrackerParams(**dict(self.tp)), FixedParams(**dict(self.fp))

    @property
    def run_name(self) -> str:
        """Evaluator tracker name of this point's accuracy runs: the base tracker and the
        parameters that change results (not LANES), e.g. ``mstrack-fused-flat~colour_bits=4,weight_frac=2``."""
        tp, fp = self.params()
        base_tp, _ = _base_params(self.tracker)
        diff = [f"{k}={v}" for k, v in sorted(asdict(tp).items()) if asdict(base_tp).get(k) != v]
        diff += [f"{k}={v}" for k, v in sorted(asdict(fp).items()) if asdict(FixedParams()).get(k) != v]
        return self.tracker + ("~" + ",".join(diff) if diff else "")

    @property
    def label(self) -> str:
        """Short label: base tracker and the grid values, e.g. ``fused-flat bins=16 wf=2 lanes=4``."""
        return " ".join([self.tracker.removeprefix("mstrack-")] + [f"{k}={_show(k, v)}" for k, v in self.grid])


def _show(key: str, v: Any) -> Any:
    if key == "bins":
        return 1 << v
    if key == "edge_bins":
        return 1 << v
    return v


def _base_params(tracker: str) -> tuple[TrackerParams, dict[str, Any]]:
    """TrackerParams of a registered mstrack tracker name (``mstrack-v2``, ``mstrack-<features>-<kernel>``)."""
    from .eval.evaluate import tracker_names, uses_model
    if tracker not in tracker_names() or not uses_model(tracker):
        known = [t for t in tracker_names() if uses_model(t)]
        raise ValueError(f"explore runs mstrack trackers; unknown {tracker!r}; known: {', '.join(known)}")
    if tracker == "mstrack-v2":
        kw: dict[str, Any] = {"preset": "v2"}
    elif tracker in ("mstrack-v2-colour", "mstrack-v2-colour-w63"):
        from .track.params import V2_COLOUR
        kw = {"preset": "v2", **V2_COLOUR}
        if tracker.endswith("-w63"):    # the tracker parameter; a grid's fp keys set the fixed widths
            kw["max_window"] = 63
    else:
        _, feat, ker = tracker.split("-")
        kw = {"preset": "paper", "features": canonical("features", feat), "kernel": canonical("kernel", ker)}
    return TrackerParams(**kw), kw


def make_points(trackers: Sequence[str], grid: dict[str, list[Any]], model: str = "fixed") -> list[Point]:
    """The grid crossed with each base tracker, as :class:`Point` s (duplicates dropped).

    ``preset=v2`` sets ``features=colour`` (tracker v2 tracks colour only) and ignores a
    ``features`` value; with ``model="float"`` FixedParams keys are refused."""
    if model == "float":
        fixed_keys = [k for k in grid if GRID_KEYS[k][0] == "fp"]
        if fixed_keys:
            raise GridError(f"grid key(s) {', '.join(fixed_keys)} are fixed-point widths: use --model fixed")
    keys = list(grid)
    out: dict[tuple[Any, ...], Point] = {}
    for trk in trackers:
        _, base = _base_params(trk)
        for combo in product(*(grid[k] for k in keys)):
            tp_kw, fp_kw, lanes = dict(base), {}, DEFAULT_LANES
            for k, v in zip(keys, combo):
                where, name, _ = GRID_KEYS[k]
                if where == "tp":
                    tp_kw[name] = v
                elif where == "fp":
                    fp_kw[name] = v
                else:
                    lanes = v
            if tp_kw.get("preset") == "v2":
                tp_kw["features"] = "colour"
            elif tp_kw.get("features") is None:
                tp_kw["features"] = "fused"
            try:
                TrackerParams(**tp_kw), FixedParams(**fp_kw)
            except ValueError as exc:
                raise GridError(f"grid point {dict(zip(keys, combo))} of {trk}: {exc}") from None
            p = Point(trk, tuple(sorted(tp_kw.items())), tuple(sorted(fp_kw.items())), lanes,
                      tuple((k, v) for k, v in zip(keys, combo)))
            out.setdefault((p.run_name, lanes), p)
    return list(out.values())


@dataclass(frozen=True)
class PointFactory:
    """``factory(name, model)`` for :func:`mstrack.eval.evaluate.evaluate`: builds the tracker of the point
    whose :attr:`Point.run_name` is ``name`` (picklable, so it runs on ``--jobs`` workers and Dask)."""

    specs: tuple[tuple[str, tuple[tuple[str, Any], ...], tuple[tuple[str, Any], ...]], ...]

    @classmethod
    def of(cls, points: Sequence[Point]) -> "PointFactory":
        return cls(tuple(dict.fromkeys((p.run_name, p.tp, p.fp) for p in points)))

    def __call__(self, name: str, model: str = "fixed") -> Any:
        from .track.tracker import Tracker
        for run_name, tp, fp in self.specs:
            if run_name == name:
                return Tracker(model=model, params=TrackerParams(**dict(tp)),  # type: ignore[arg-type]
                               **(dict(fp) if model == "fixed" else {}))
        raise ValueError(f"no explore point named {name!r}")


# ----------------------------------------------------------------------------- resource estimate
#: DP16KD (18 kbit) aspect ratios yosys' ECP5 memory library uses (pseudo dual port for x36).
DP16KD_SHAPES = ((16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36))
#: yosys' ECP5 memory library costs (share/lattice/brams_16kd.txt, lutrams_trellis.txt): DP16KD 128,
#: TRELLIS_DPR16X4 (16 x 4 distributed RAM) 4; yosys maps each memory to the cheaper.  Distributed
#: RAM deeper than 16 words also needs a read multiplexer, counted here as 2 per DPR16X4 (fitted to
#: the mappings seen in the measured netlists: 64 x 56 histogram banks -> DP16KD, 64 x 14 model Q,
#: 64 x 6 XR and 64 x 9 KA/KB tables and 16 x 56 edge histogram banks -> DPR16X4, 512 x 1 T tables
#: -> DP16KD).
COST_DP16KD, COST_DPR16X4, COST_DPR16X4_MUX = 128, 4, 2
#: Frame line buffer of ms_sobel: three RAMs of MAX_FRAME_W (2048) words of up to 9 bits.
LINE_BUFFER = (3, 2048, 9)


def dp16kd_tiles(depth: int, width: int) -> tuple[int, int]:
    """(DP16KD, DPR16X4) for one depth x width memory with one read port: the cheapest DP16KD
    tiling of :data:`DP16KD_SHAPES` or distributed RAM, whichever costs less (:data:`COST_DP16KD`)."""
    if depth <= 0 or width <= 0:
        return 0, 0
    bram = min(-(-depth // d) * -(-width // w) for d, w in DP16KD_SHAPES)
    dpr = -(-depth // 16) * -(-width // 4)
    if dpr * (COST_DPR16X4 + (COST_DPR16X4_MUX if depth > 16 else 0)) < bram * COST_DP16KD:
        return 0, dpr
    return bram, 0


@dataclass(frozen=True)
class Memory:
    """One RAM of the core: ``copies`` x (``depth`` x ``width``)."""

    name: str
    copies: int
    depth: int
    width: int

    @property
    def bits(self) -> int:
        return self.copies * self.depth * self.width

    @property
    def tiles(self) -> tuple[int, int]:
        d, r = dp16kd_tiles(self.depth, self.width)
        return self.copies * d, self.copies * r


def memories(tp: TrackerParams, fp: FixedParams, lanes: int = DEFAULT_LANES) -> list[Memory]:
    """The RAMs of ``ms_tracker`` for these parameters (rtl/ms_region_ram.vhd, ms_histogram.vhd,
    ms_bin_pass.vhd, ms_window_scan.vhd, ms_sobel.vhd): per engine (colour, edge) a region RAM of
    LANES banks, a histogram of LANES banks (words H (Epanechnikov only), N, SX, SY), the model Q
    and the XR table (+ KA/KB per lane for Epanechnikov); the front end's line buffer."""
    g = core_generics(tp.with_(preset="paper", features="fused"), fp, lanes)
    depth = g["REGION_MAX"] * g["STRIDE"]
    e_w = g["HIST_W"] * g["KERNEL_EPAN"] + g["COUNT_W"] + 2 * g["POSSUM_W"]
    out = [Memory("line buffer", LINE_BUFFER[0], LINE_BUFFER[1], LINE_BUFFER[2])]
    for feat, bin_w in (("colour", 3 * g["COLOUR_BITS"]), ("edge", g["EDGE_BINS_LOG2"])):
        out += [Memory(f"{feat} region", lanes, depth, bin_w),
                Memory(f"{feat} histogram", lanes, 1 << bin_w, e_w),
                Memory(f"{feat} model Q", 1, 1 << bin_w, g["HIST_W"]),
                Memory(f"{feat} XR table", 1, fp.max_half + 1, g["HALF_W"])]
        if g["KERNEL_EPAN"]:
            out.append(Memory(f"{feat} KA/KB", 2 * lanes, fp.max_half + 1, g["KVAL_W"]))
    if tp.preset == "v2":
        nc = 1 << (3 * g["COLOUR_BITS"])
        out += [Memory("v2 T table (ms_target_stats)", lanes, nc, 1),           # one copy per lane
                Memory("v2 counts [T | Q | O] (ms_bg_model)", 1, nc, 1 + g["COUNT_W"] + 17),
                Memory("v2 model [T | Qn] (ms_bg_model)", 1, nc, 1 + 17)]
    return out


#: Blocks measured alone at the default generics (docs/performance.md "Each block alone", RTL
#: 468ea34, yosys synth_ecp5 + nextpnr seed 1): (LUT4, FF) and the driver they are scaled by.
BLOCK_BASE: dict[str, tuple[int, int]] = {
    "ms_frontend": (195, 641), "ms_region_capture": (115, 141), "ms_region_ram": (285, 79),
    "ms_box_clip": (150, 374), "ms_kernel_tables": (293, 468), "ms_region": (184, 156),
    "ms_pixel_pass": (1499, 1524), "ms_bin_pass": (1232, 2335), "ms_bin_pass_edge": (1228, 2334),
    "ms_centre": (369, 458), "ms_fusion": (520, 739),
}
#: Epanechnikov variants measured alone (docs/blocks/ms_pixel_pass.md, ms_kernel_tables.md)
BLOCK_BASE_EPAN: dict[str, tuple[int, int]] = {"ms_pixel_pass": (2282, 2180), "ms_kernel_tables": (447, 969)}
#: Part of a block that does not scale with its driver (LUT4, FF): the pixel pass' FF from its
#: LANES 2 and 4 measurements (docs/blocks/ms_pixel_pass.md: 906 and 1,524 FF -> 288 + 309 per lane;
#: LUT4 720 and 1,499 -> about 0 + 390 per lane).
BLOCK_FIXED: dict[str, tuple[int, int]] = {"ms_pixel_pass": (0, 288)}
#: Tracker v2 blocks measured alone (docs/blocks/<block>.md; LANES 4): added for preset v2.  The v2
#: estimate is the paper core + these blocks (ms_target_stats scales with LANES), not core v2 as built
#: (ms_tracker with PRESET 1, docs/performance.md "Core v2").
V2_BLOCKS: dict[str, tuple[int, int]] = {
    "ms_target_stats": (253, 472), "ms_share": (77, 54), "ms_spread": (95, 70), "ms_scale": (408, 459),
    "ms_resize": (123, 115), "ms_bg_model": (1866, 2654), "ms_model_scale": (241, 192),
    "ms_window_size": (54, 55), "ms_box_size": (56, 69), "ms_decimation": (44, 3), "ms_decimate": (80, 47),
}
#: Measured core at the default generics (docs/performance.md, ECP5 table, RTL 8671c1f): the
#: blocks above leave a remainder (ms_meanshift x 2, ms_tracker's own logic) taken as constant.
CORE_DEFAULT = {"LUT4": 8657, "FF": 12187, "DP16KD": 44, "MULT18X18D": 6}


def _drivers(g: dict[str, int], lanes: int) -> dict[str, float]:
    """Per block the width product its area is taken proportional to."""
    n_blocks = lambda w: max(1, dp16kd_tiles(g["REGION_MAX"] * g["STRIDE"], w)[0])  # noqa: E731
    e_w = g["HIST_W"] * g["KERNEL_EPAN"] + g["COUNT_W"] + 2 * g["POSSUM_W"]
    bp = g["RATIO_Q_W"] * (g["RATIO_Q_W"] + g["HIST_W"]) + g["SQRT_IN_W"] ** 2 / 4 + g["WEIGHT_W"] * g["HIST_W"] \
        + 4 * e_w
    return {
        # bank read multiplexer (blocks in depth - 1 per data bit) and address decode, per bank
        "region_ram_c": lanes * (3 * g["COLOUR_BITS"] * (n_blocks(3 * g["COLOUR_BITS"]) - 1) + g["ADDR_W"]),
        "region_ram_e": lanes * (g["EDGE_BINS_LOG2"] * (n_blocks(g["EDGE_BINS_LOG2"]) - 1) + g["ADDR_W"]),
        # LANES adders of each histogram field (read-modify-write)
        "pixel_pass": lanes * e_w,
        # weight divider (RATIO_Q_W stages), Bhattacharyya isqrt, products, N/SX/SY delay line
        "bin_pass": bp,
        # two iterative dividers of SWX_W, SHIFT_Q_W quotient bits
        "centre": g["SWX_W"] + g["SHIFT_Q_W"],
        "fusion": g["RHO_OUT_W"] + g["ALPHA_W"] + g["RHO_SUM_W"],
    }


@dataclass
class Estimate:
    """Estimated ECP5 resources of ``ms_tracker`` for one configuration (:func:`estimate`)."""

    lut4: int
    ff: int
    dp16kd: int
    dpr16x4: int
    mult18: int
    ram_bits: int
    memories: dict[str, dict[str, int]] = field(default_factory=dict)
    blocks: dict[str, tuple[int, int]] = field(default_factory=dict)


def mult18_count(g: dict[str, int]) -> int:
    """MULT18X18D: per engine the constant ``row * STRIDE`` of the window scan and the two squares
    of ms_meanshift's stop test (SCW = CENTRE_W + 2 bits signed; ceil(SCW / 18)^2 each)."""
    scw = g["CENTRE_W"] + 2
    return 2 * (1 + 2 * (-(-scw // 18)) ** 2)


def estimate(tp: TrackerParams, fp: FixedParams, lanes: int = DEFAULT_LANES) -> Estimate:
    """Resource estimate of ``ms_tracker`` (ECP5, yosys ``synth_ecp5``) for one configuration.

    * DP16KD / DPR16X4 / RAM bits: counted from :func:`memories` with the cheapest tiling
      (:func:`dp16kd_tiles`): the structure of the RTL, exact on the measured configurations.
    * MULT18X18D: :func:`mult18_count`.
    * LUT4 / FF: each block of :data:`BLOCK_BASE` (measured alone) scaled by the ratio of its
      driver (:func:`_drivers`) to the default's, plus the measured remainder of the default core
      (:data:`CORE_DEFAULT`), plus :data:`V2_BLOCKS` for preset v2.

    The paper core runs both engines (colour and edge) whatever ``features``; ``features`` and
    ``max_iter`` change no resource.  Error against synthesis: docs/explore.md (:data:`MEASURED`).
    """
    core_tp = tp.with_(preset="paper", features="fused")
    g = core_generics(core_tp, fp, lanes)
    epan = tp.kernel == "epanechnikov"
    d = _drivers(g, lanes)
    # each block is scaled from the default it was measured at (flat, or Epanechnikov for BLOCK_BASE_EPAN)
    d0_flat = _drivers(core_generics(TrackerParams(), FixedParams(), DEFAULT_LANES), DEFAULT_LANES)
    d0_epan = _drivers(core_generics(TrackerParams(kernel="epanechnikov"), FixedParams(), DEFAULT_LANES),
                       DEFAULT_LANES)

    def scaled(block: str, key: str | None, n: int = 1, key0: str | None = None) -> tuple[int, int]:
        from_epan = epan and block in BLOCK_BASE_EPAN
        base = (BLOCK_BASE_EPAN if from_epan else BLOCK_BASE)[block]
        fixed = BLOCK_FIXED.get(block, (0, 0))
        r = d[key] / (d0_epan if from_epan else d0_flat)[key0 or key] if key else 1.0
        return tuple(round(n * (f + (b - f) * r)) for b, f in zip(base, fixed))  # type: ignore[return-value]

    blocks = {
        "ms_frontend": scaled("ms_frontend", None), "ms_region_capture": scaled("ms_region_capture", None),
        "ms_region_ram (colour)": scaled("ms_region_ram", "region_ram_c"),
        "ms_region_ram (edge)": scaled("ms_region_ram", "region_ram_e", key0="region_ram_c"),
        "ms_box_clip": scaled("ms_box_clip", None), "ms_kernel_tables": scaled("ms_kernel_tables", None),
        "ms_region": scaled("ms_region", None), "ms_pixel_pass x 2": scaled("ms_pixel_pass", "pixel_pass", 2),
        "ms_bin_pass (colour)": scaled("ms_bin_pass", "bin_pass"),
        "ms_bin_pass (edge)": scaled("ms_bin_pass_edge", "bin_pass"),
        "ms_centre x 2": scaled("ms_centre", "centre", 2), "ms_fusion": scaled("ms_fusion", "fusion"),
    }
    blocks["rest (ms_meanshift x 2, top)"] = _remainder()
    if tp.preset == "v2":
        for b, (lut, ff) in V2_BLOCKS.items():
            r = lanes / DEFAULT_LANES if b == "ms_target_stats" else 1.0
            blocks[b] = (round(lut * r), round(ff * r))
    mems = memories(tp, fp, lanes)
    dp = sum(m.tiles[0] for m in mems)
    return Estimate(lut4=sum(v[0] for v in blocks.values()), ff=sum(v[1] for v in blocks.values()),
                    dp16kd=dp, dpr16x4=sum(m.tiles[1] for m in mems), mult18=mult18_count(g),
                    ram_bits=sum(m.bits for m in mems),
                    memories={m.name: {"copies": m.copies, "depth": m.depth, "width": m.width, "bits": m.bits,
                                       "DP16KD": m.tiles[0], "DPR16X4": m.tiles[1]} for m in mems},
                    blocks=blocks)


def v2_extra(tp: TrackerParams, fp: FixedParams, lanes: int = DEFAULT_LANES) -> dict[str, int]:
    """What :func:`estimate` adds to the paper core for preset v2 (the v2 blocks and their RAMs):
    ``{"LUT4", "FF", "DP16KD"}``; zeros for the paper preset."""
    if tp.preset != "v2":
        return {"LUT4": 0, "FF": 0, "DP16KD": 0}
    e, p = estimate(tp, fp, lanes), estimate(tp.with_(preset="paper", features="fused"), fp, lanes)
    return {"LUT4": e.lut4 - p.lut4, "FF": e.ff - p.ff, "DP16KD": e.dp16kd - p.dp16kd}


def _remainder() -> tuple[int, int]:
    """CORE_DEFAULT minus the blocks at the default generics (ms_meanshift x 2 and ms_tracker's own logic)."""
    g0 = core_generics(TrackerParams(), FixedParams(), DEFAULT_LANES)
    d0 = _drivers(g0, DEFAULT_LANES)
    edge_rr = BLOCK_BASE["ms_region_ram"][0] * d0["region_ram_e"] / d0["region_ram_c"], \
        BLOCK_BASE["ms_region_ram"][1] * d0["region_ram_e"] / d0["region_ram_c"]
    lut = sum(v[0] for v in BLOCK_BASE.values()) + BLOCK_BASE["ms_pixel_pass"][0] + BLOCK_BASE["ms_centre"][0] \
        + round(edge_rr[0])
    ff = sum(v[1] for v in BLOCK_BASE.values()) + BLOCK_BASE["ms_pixel_pass"][1] + BLOCK_BASE["ms_centre"][1] \
        + round(edge_rr[1])
    return CORE_DEFAULT["LUT4"] - lut, CORE_DEFAULT["FF"] - ff


@dataclass(frozen=True)
class Measured:
    """A synthesis result in the docs that the estimate is checked against."""

    name: str
    source: str
    tp: dict = field(default_factory=dict)
    fp: dict = field(default_factory=dict)
    lanes: int = DEFAULT_LANES
    block: str | None = None            # None: the whole core; else the block alone (per engine)
    values: dict = field(default_factory=dict)
    calibration: tuple[str, ...] = ()   # quantities that set the estimate (so do not test it)


ALL = ("LUT4", "FF", "DP16KD", "MULT18X18D")
#: The other cores of docs/explore.md's grid (colour bins per channel, WF, LANES) -> yosys LUT4, FF,
#: DP16KD (`mstrack explore ... --yosys`, RTL d6f83cc); those also listed above are left out.
EXPLORE_YOSYS: dict[tuple[int, int, int], tuple[int, int, int]] = {
    (4, 2, 2): (6550, 10329, 35), (4, 2, 4): (8068, 11586, 43), (4, 4, 2): (6972, 10905, 35),
    (8, 2, 2): (6676, 10404, 36), (8, 4, 4): (8553, 12271, 44), (16, 2, 2): (6660, 10490, 76),
    (16, 2, 4): (8207, 11817, 112), (16, 4, 2): (7001, 11066, 76),
}
#: yosys synth_ecp5 of the core, RTL d6f83cc (docs/explore.md, "The estimate")
_EXPLORE_MD = "docs/explore.md (yosys synth_ecp5, RTL d6f83cc)"

#: Measured configurations (docs/performance.md, docs/blocks/ms_pixel_pass.md, docs/explore.md).
MEASURED: tuple[Measured, ...] = (
    Measured("default core", "docs/performance.md ECP5 table (8671c1f)",
             values={"LUT4": 8657, "FF": 12187, "DP16KD": 44, "MULT18X18D": 6}, calibration=ALL),
    Measured("default core (3f94c5f, less the pin wrapper's ~90 LUT4 / ~234 FF)", "docs/performance.md limits table",
             values={"LUT4": 8622 - 90, "FF": 12505 - 234, "DP16KD": 44, "MULT18X18D": 6}),
    Measured("lanes2 core", _EXPLORE_MD, lanes=2, values={"LUT4": 7051, "FF": 10980, "DP16KD": 36, "MULT18X18D": 6}),
    Measured("small core (MAX_HALF 31, MARGIN 16)", _EXPLORE_MD, fp={"max_half": 31, "margin": 16},
             values={"LUT4": 7492, "FF": 11053, "DP16KD": 24, "MULT18X18D": 6}),
    Measured("bins=4 core (64 colour bins)", _EXPLORE_MD, tp={"colour_bits": 2},
             values={"LUT4": 8482, "FF": 12162, "DP16KD": 43, "MULT18X18D": 6}, calibration=("DP16KD",)),
    Measured("bins=16 core (4096 colour bins)", _EXPLORE_MD, tp={"colour_bits": 4},
             values={"LUT4": 8651, "FF": 12393, "DP16KD": 112, "MULT18X18D": 6}),
    Measured("wf=2 core (weights 4.2)", _EXPLORE_MD, fp={"weight_frac": 2},
             values={"LUT4": 8203, "FF": 11695, "DP16KD": 44, "MULT18X18D": 6}),
    Measured("wf=6 core (weights 4.6)", _EXPLORE_MD, fp={"weight_frac": 6},
             values={"LUT4": 8993, "FF": 13341, "DP16KD": 44, "MULT18X18D": 6}),
    *(Measured(f"bins={b} wf={wf} lanes={ln} core", _EXPLORE_MD + ", mstrack explore --yosys",
               tp={"colour_bits": b.bit_length() - 1}, fp={"weight_frac": wf}, lanes=ln,
               values={"LUT4": v[0], "FF": v[1], "DP16KD": v[2], "MULT18X18D": 6})
      for (b, wf, ln), v in EXPLORE_YOSYS.items()),
    Measured("ms_pixel_pass default", "docs/blocks/ms_pixel_pass.md", block="ms_pixel_pass",
             values={"LUT4": 1499, "FF": 1524, "DP16KD": 8}, calibration=("LUT4", "FF")),
    Measured("ms_pixel_pass lanes2", "docs/blocks/ms_pixel_pass.md", lanes=2, block="ms_pixel_pass",
             values={"LUT4": 720, "FF": 906, "DP16KD": 4}, calibration=("FF",)),
    Measured("ms_pixel_pass small", "docs/blocks/ms_pixel_pass.md", fp={"max_half": 31, "margin": 16},
             block="ms_pixel_pass", values={"LUT4": 1331, "FF": 1356, "DP16KD": 8}),
    Measured("ms_pixel_pass epan", "docs/blocks/ms_pixel_pass.md", tp={"kernel": "epanechnikov"},
             block="ms_pixel_pass", values={"LUT4": 2282, "FF": 2180, "DP16KD": 12}, calibration=("LUT4", "FF")),
    Measured("ms_region_ram default (colour)", "docs/performance.md blocks table (468ea34)", block="ms_region_ram",
             values={"LUT4": 285, "FF": 79, "DP16KD": 20}, calibration=("LUT4", "FF")),
    Measured("ms_bin_pass default (colour)", "docs/performance.md blocks table (468ea34)", block="ms_bin_pass",
             values={"DP16KD": 1}),
    Measured("ms_bin_pass_edge default", "docs/performance.md blocks table (468ea34)", block="ms_bin_pass_edge",
             values={"DP16KD": 0}),
    Measured("ms_frontend default", "docs/performance.md blocks table (468ea34)", block="ms_frontend",
             values={"DP16KD": 3}),
)

#: Stated error of the estimate on the measured configurations (relative; the largest error of the
#: values that did not set it, rounded up: docs/explore.md).  DP16KD: exact but at 4096 colour bins
#: (one block short of yosys); MULT18X18D: exact.
ERROR_BOUND = {"LUT4": 0.06, "FF": 0.05, "DP16KD": 0.02, "MULT18X18D": 0.0}


def estimate_measured(m: Measured) -> dict[str, int]:
    """The estimate of what ``m`` measured (the whole core or one block alone)."""
    tp = TrackerParams(**m.tp)
    fp = FixedParams(**m.fp)
    e = estimate(tp, fp, m.lanes)
    if m.block is None:
        return {"LUT4": e.lut4, "FF": e.ff, "DP16KD": e.dp16kd, "MULT18X18D": e.mult18}
    mem = {"ms_pixel_pass": "colour histogram", "ms_region_ram": "colour region", "ms_bin_pass": "colour model Q",
           "ms_bin_pass_edge": "edge model Q", "ms_frontend": "line buffer"}[m.block]
    key = {"ms_pixel_pass": "ms_pixel_pass x 2", "ms_region_ram": "ms_region_ram (colour)",
           "ms_bin_pass": "ms_bin_pass (colour)", "ms_bin_pass_edge": "ms_bin_pass (edge)",
           "ms_frontend": "ms_frontend"}[m.block]
    lut, ff = e.blocks[key]
    n = 2 if key.endswith("x 2") else 1
    return {"LUT4": round(lut / n), "FF": round(ff / n), "DP16KD": e.memories[mem]["DP16KD"]}


def check_table() -> list[dict[str, Any]]:
    """Estimate against every :data:`MEASURED` value: rows of name, quantity, measured, estimate,
    relative error, calibration flag."""
    rows = []
    for m in MEASURED:
        est = estimate_measured(m)
        for q, v in m.values.items():
            rel = (est[q] - v) / v if v else float(est[q] != v)
            rows.append({"config": m.name, "source": m.source, "quantity": q, "measured": v, "estimate": est[q],
                         "error": rel, "calibration": q in m.calibration})
    return rows


# ----------------------------------------------------------------------------- accuracy
def loss_rates(runs: dict[str, Any], sequences: Sequence[Any]) -> tuple[float, float, int, int]:
    """(recall, false alarms, off-target frames, on-target frames) of the ``ok`` flag over ``runs``
    (sequence name -> SequenceRun), as docs/results_loss.md: per frame after the init frame with a
    valid ground truth, recall = share of off-target frames (IoU = 0) with ok false, false alarms =
    share of on-target frames (IoU >= 0.5) with ok false."""
    import numpy as np
    from .eval.metrics import iou, loss_detection, valid_gt
    by = {s.name: s for s in sequences}
    ious, oks = [], []
    for name, r in runs.items():
        gt = by[name].gt[: r.n_frames]
        v = valid_gt(gt)
        v[0] = False
        ious.append(iou(r.boxes[v], gt[v]))
        oks.append(np.asarray(r.ok, dtype=bool)[v])
    d = loss_detection(np.concatenate(ious) if ious else np.zeros(0), np.concatenate(oks) if oks else np.zeros(0, bool))
    return d.recall, d.false_alarm, d.off, d.on


def has_ok_flag(tp: TrackerParams) -> bool:
    """The tracker reports loss (``TrackResult.ok`` False): tracker v2 only."""
    return tp.preset == "v2"


# ----------------------------------------------------------------------------- run
@dataclass
class Row:
    """One point of the table."""

    point: str
    tracker: str
    grid: dict[str, Any]
    lanes: int
    auc: float
    p20: float
    loss_recall: float | None
    false_alarms: float | None
    frames: int
    lut4: int
    ff: int
    dp16kd: int
    ram_kbit: float
    mult18: int
    cycles_64: int
    fits: bool = True
    yosys: dict[str, Any] | None = None
    pareto_lut: bool = False
    pareto_dp16kd: bool = False


def pareto_front(points: Sequence[tuple[float, float]]) -> list[bool]:
    """For (cost, accuracy) pairs: True where no other point is at most as costly and at least as
    accurate with one of the two strictly better (lower cost is better, higher accuracy is better).
    Points with a NaN are never on the front; of equal points, all are on it."""
    out = []
    for i, (c, a) in enumerate(points):
        if c != c or a != a:
            out.append(False)
            continue
        dominated = any(j != i and c2 <= c and a2 >= a and (c2 < c or a2 > a)
                        for j, (c2, a2) in enumerate(points) if c2 == c2 and a2 == a2)
        out.append(not dominated)
    return out


#: Default cycle budget of a frame: the 1080p60 vertical blanking (99,000 clocks at 148.5 MHz).
BUDGET = VBLANK_1080P60


def worst_frame_cycles(tp: TrackerParams, fp: FixedParams, lanes: int) -> int:
    """Worst-case clocks of a 20-iteration frame for a 64x64 target (mstrack.hw.synth cycle model)."""
    from .hw import synth
    cfg = synth.Config("explore", "", tp={k: v for k, v in asdict(tp).items()
                                          if k in ("kernel", "colour_bits", "edge_bins_log2", "max_iter")},
                       fp=asdict(fp), lanes=lanes)
    return synth.cycle_figures(cfg, 64, 64).worst_frame


def yosys_counts(p: Point) -> dict[str, Any]:
    """Real yosys ``synth_ecp5`` counts of ``ms_tracker`` with the point's generics (cached in
    build/synth/ecp5_explore_<hash>/ by :func:`mstrack.hw.synth.yosys_cached`).  The paper core only:
    :func:`explore` adds :func:`v2_extra` for v2 points."""
    import hashlib
    from .hw import synth
    tp, fp = p.params()
    g = core_generics(tp.with_(preset="paper", features="fused"), fp, p.lanes)
    g["MAX_FRAME_W"] = 2048
    name = "ecp5_explore_" + hashlib.sha1(json.dumps(g, sort_keys=True).encode()).hexdigest()[:10]
    r = synth.yosys_cached("ecp5", "ms_tracker", g, None, name)
    return {k: r[k] for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D", "TRELLIS_DPR16X4")}


def explore(sequences: Sequence[Any], points: Sequence[Point], out_dir: str | Path, model: str = "fixed",
            jobs: int = 1, scheduler: str | None = None, force: bool = False, quiet: bool = False,
            max_frames: int | None = None, yosys: bool = False, budget: int | None = None,
            log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> list[Row]:
    """Evaluate every point (one :func:`mstrack.eval.evaluate.evaluate` call over the distinct accuracy
    runs) and estimate its cost; returns the rows with their Pareto flags set.

    ``budget``: clocks a 20-iteration frame of a 64x64 target may take (default
    :data:`BUDGET`, the 1080p60 vertical blanking); points over it are marked (``fits`` False)
    and left out of the Pareto fronts."""
    budget = BUDGET if budget is None else budget
    from .eval.evaluate import evaluate, run_label
    factory = PointFactory.of(points)
    names = list(dict.fromkeys(p.run_name for p in points))
    ev = evaluate(list(sequences), names, out_dir, model=model, force=force, quiet=quiet, max_frames=max_frames,
                  factory=factory, jobs=jobs, scheduler=scheduler)
    for s, per in ev.failed.items():
        for t, reason in per.items():
            log(f"explore: {t} on {s} failed, sequence left out: {reason}")
    kept = [s for s in sequences if s.name in ev.sequences]
    rows = []
    for p in points:
        tp, fp = p.params()
        label = run_label(p.run_name, model)
        sc = ev.overall[label]
        rec = fa = None
        if has_ok_flag(tp):
            rec, fa, _, _ = loss_rates(ev.runs[label], kept)
        e = estimate(tp, fp, p.lanes)
        y = None
        if yosys:
            t0 = time.monotonic()
            y = yosys_counts(p)
            if tp.preset == "v2":          # the RTL core is the paper's: + the v2 blocks measured alone
                x = v2_extra(tp, fp, p.lanes)
                y = {**y, "LUT4": y["LUT4"] + x["LUT4"], "TRELLIS_FF": y["TRELLIS_FF"] + x["FF"],
                     "DP16KD": y["DP16KD"] + x["DP16KD"], "v2_blocks_added": x}
            log(f"explore: yosys {p.label}: {y} ({time.monotonic() - t0:.0f} s)")
        cyc = worst_frame_cycles(tp, fp, p.lanes)
        rows.append(Row(p.label, p.tracker, {k: _show(k, v) for k, v in p.grid}, p.lanes, float(sc.auc),
                        float(sc.precision20), rec, fa, int(sc.n_frames), e.lut4, e.ff, e.dp16kd,
                        round(e.ram_bits / 1024, 1), e.mult18, cyc, cyc < budget, y))
    nan = float("nan")
    lut = [(float(r.yosys["LUT4"]) if r.yosys else float(r.lut4)) if r.fits else nan for r in rows]
    dp = [(float(r.yosys["DP16KD"]) if r.yosys else float(r.dp16kd)) if r.fits else nan for r in rows]
    for r, a, b in zip(rows, pareto_front([(c, r.auc) for c, r in zip(lut, rows)]),
                       pareto_front([(c, r.auc) for c, r in zip(dp, rows)])):
        r.pareto_lut, r.pareto_dp16kd = a, b
    return rows


# ----------------------------------------------------------------------------- outputs
COLUMNS = ("point", "tracker", "lanes", "auc", "p20", "loss_recall", "false_alarms", "frames", "lut4", "ff",
           "dp16kd", "ram_kbit", "mult18", "cycles_64", "fits", "yosys_lut4", "yosys_ff", "yosys_dp16kd",
           "pareto_lut", "pareto_dp16kd")


def _flat(r: Row) -> dict[str, Any]:
    d = {k: getattr(r, k) for k in COLUMNS if hasattr(r, k)}
    y = r.yosys or {}
    d.update(yosys_lut4=y.get("LUT4"), yosys_ff=y.get("TRELLIS_FF"), yosys_dp16kd=y.get("DP16KD"))
    return {k: d.get(k) for k in COLUMNS}


def _f(v: Any, nd: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    if isinstance(v, bool):
        return "yes" if v else ""
    if isinstance(v, float):
        return f"{v:.{nd}f}"
    return f"{v:,}" if isinstance(v, int) else str(v)


def markdown_table(rows: Sequence[Row]) -> str:
    """Rows sorted by AUC (best first); * = on the Pareto front (AUC vs LUT4 / vs DP16KD, yosys counts
    where run); "over" = the worst 64x64 frame takes more clocks than the budget (not on any front)."""
    ys = any(r.yosys for r in rows)
    head = ["point", "AUC", "P@20", "loss recall", "false alarms", "LUT4 (est.)", "FF (est.)", "DP16KD",
            "RAM kbit", "MULT18", "worst frame, 64x64 (clk)"] + (["yosys LUT4 / FF / DP16KD"] if ys else []) \
        + ["Pareto (LUT4 / DP16KD)"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in sorted(rows, key=lambda r: (-r.auc, r.lut4)):
        cells = [r.point, _f(r.auc), _f(r.p20), _f(r.loss_recall), _f(r.false_alarms), _f(r.lut4), _f(r.ff),
                 _f(r.dp16kd), _f(r.ram_kbit, 1), _f(r.mult18), _f(r.cycles_64) + ("" if r.fits else " (over)")]
        if ys:
            y = r.yosys or {}
            cells.append(" / ".join(_f(y.get(k)) for k in ("LUT4", "TRELLIS_FF", "DP16KD")) if y else "-")
        cells.append(" / ".join("*" if f else "" for f in (r.pareto_lut, r.pareto_dp16kd)))
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def check_markdown() -> str:
    """The estimate against the measured configurations (:func:`check_table`), one row per
    configuration: measured / estimate (error); "(cal.)" = the value set the estimate."""
    rows: dict[str, dict[str, Any]] = {}
    for r in check_table():
        rows.setdefault(r["config"], {"source": r["source"]})[r["quantity"]] = (
            f"{r['measured']:,} / {r['estimate']:,} ({100 * r['error']:+.1f} %)" + (" (cal.)" if r["calibration"] else ""))
    out = ["| configuration | LUT4 measured / estimate | FF | DP16KD | MULT18X18D | source |", "|---|---|---|---|---|---|"]
    for name, d in rows.items():
        out.append(f"| {name} | " + " | ".join(d.get(q, "") for q in ALL) + f" | {d['source']} |")
    return "\n".join(out)


def plot_pareto(rows: Sequence[Row], path: str | Path, title: str = "") -> Path:
    """Two panels, AUC against LUT4 and against DP16KD (yosys counts where measured), Pareto front
    joined and highlighted."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
    have_yosys = any(r.yosys for r in rows)
    for ax, (what, cost, flag) in zip(axes, (
            ("LUT4 (yosys)" if have_yosys else "LUT4 (estimate)", lambda r: r.yosys["LUT4"] if r.yosys else r.lut4,
             "pareto_lut"),
            ("DP16KD (yosys)" if have_yosys else "DP16KD", lambda r: r.yosys["DP16KD"] if r.yosys else r.dp16kd,
             "pareto_dp16kd"))):
        xs = [cost(r) for r in rows]
        ys = [r.auc for r in rows]
        on = [getattr(r, flag) for r in rows]
        fit = [r.fits for r in rows]
        ax.scatter([x for x, o, f in zip(xs, on, fit) if not o and f], [y for y, o, f in zip(ys, on, fit) if not o and f],
                   c="0.6", s=28, label="dominated")
        if not all(fit):
            ax.scatter([x for x, f in zip(xs, fit) if not f], [y for y, f in zip(ys, fit) if not f], marker="x",
                       c="0.45", s=30, label="over the cycle budget")
        front = sorted((x, y) for x, y, o in zip(xs, ys, on) if o)
        if front:
            ax.step([f[0] for f in front], [f[1] for f in front], where="post", c="C3", lw=1.2)
            ax.scatter([f[0] for f in front], [f[1] for f in front], c="C3", s=46, zorder=3, label="Pareto front")
        for x, y, r, o in zip(xs, ys, rows, on):
            if o:
                ax.annotate(r.point, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlabel(what)
        ax.set_ylabel("AUC")
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_outputs(rows: Sequence[Row], out_dir: str | Path, command: str = "", plot: bool = True) -> dict[str, Path]:
    """``explore.md`` / ``.csv`` / ``.json`` (and ``explore_pareto.png``) in ``out_dir``."""
    from .versions import PYTHON_TOOLS, tool_versions
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"md": out / "explore.md", "csv": out / "explore.csv", "json": out / "explore.json"}
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(COLUMNS) + ["grid"])
    w.writeheader()
    for r in rows:
        w.writerow({**_flat(r), "grid": json.dumps(r.grid)})
    paths["csv"].write_text(buf.getvalue())
    import platform
    from importlib.metadata import version
    tv = tool_versions()
    tools = {"python": platform.python_version(), **{k: tv[k] for k in PYTHON_TOOLS},
             "matplotlib": version("matplotlib")}
    paths["json"].write_text(json.dumps({"command": command, "tools": tools, "rows": [asdict(r) for r in rows]},
                                        indent=1, default=str) + "\n")
    md = [f"# mstrack explore\n\nCommand: `{command}`\n", markdown_table(rows)]
    paths["md"].write_text("\n".join(md) + "\n")
    if plot and rows:
        import textwrap
        paths["png"] = plot_pareto(rows, out / "explore_pareto.png", title=textwrap.fill(command, 160))
    return paths


# ----------------------------------------------------------------------------- CLI
def add_arguments(ap: argparse.ArgumentParser) -> None:
    from .cli import _positive_int
    ap.add_argument("dataset", metavar="DATASET_DIR", nargs="?", help="folder of OTB/VOT sequence folders")
    ap.add_argument("--grid", default=DEFAULT_GRID,
                    help=f"KEY=V1,V2;KEY=... (default {DEFAULT_GRID!r}); keys: "
                         + "; ".join(f"{k}: {h}" for k, (_, _, h) in GRID_KEYS.items()))
    ap.add_argument("--trackers", default=",".join(DEFAULT_TRACKERS),
                    help="comma-separated base mstrack trackers (default mstrack-fused-flat, the RTL core's "
                         "algorithm; mstrack-v2 for tracker v2)")
    ap.add_argument("--model", choices=("float", "fixed"), default="fixed",
                    help="mstrack model (default fixed: the bit-accurate model of the core)")
    ap.add_argument("--out", default="out/explore", help="output folder (default out/explore)")
    ap.add_argument("--sequences", help="comma-separated sequence names (default: all)")
    ap.add_argument("--max-frames", type=_positive_int, help="use at most N frames per sequence")
    ap.add_argument("--jobs", "-j", type=_positive_int, default=1, metavar="N", help="runs in parallel (as mstrack eval)")
    ap.add_argument("--scheduler", nargs="?", const="local", default=None, metavar="ADDRESS",
                    help="Dask distributed scheduler (as mstrack eval, docs/distributed.md)")
    ap.add_argument("--yosys", action="store_true",
                    help="also real yosys synth_ecp5 counts per distinct core (cached; 3-7 min each)")
    ap.add_argument("--budget", type=_positive_int, default=BUDGET, metavar="CLOCKS",
                    help=f"a 20-iteration 64x64 frame must take fewer clocks (default {BUDGET:,}, the 1080p60 "
                         "vertical blanking); points over it are marked and kept off the Pareto fronts")
    ap.add_argument("--force", action="store_true", help="ignore cached runs")
    ap.add_argument("--quiet", action="store_true", help="no progress bars")
    ap.add_argument("--no-plot", action="store_true", help="no PNG")
    ap.add_argument("--check", action="store_true",
                    help="only print the estimate against the measured configurations (no DATASET run)")
    ap.add_argument("--multi", action="store_true",
                    help="only print the multi-target core's cost model for MAX_TARGETS = --targets (cycles per "
                         "frame, DP16KD, LUT4 / FF, what fits the LFE5U-85F; docs/multi_target_core.md; no DATASET run)")
    ap.add_argument("--targets", default=",".join(str(n) for n in (1, 2, 4, 8, 10, 16)), metavar="N1,N2,...",
                    help="with --multi: the MAX_TARGETS values (1..16; default 1,2,4,8,10,16)")
    ap.add_argument("--write", action="store_true",
                    help="with --multi: regenerate the tables of docs/multi_target_core.md")
    ap.add_argument("--yosys-check", action="store_true",
                    help="with --multi: synthesise the region-slot pool and model RAM at several N with yosys "
                         "synth_ecp5 (cached, seconds each) and print them against the model")


def _targets(text: str) -> list[int]:
    try:
        ns = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise ValueError(f"--targets wants comma-separated integers in 1..16, got {text!r}") from None
    if not ns or any(not 1 <= n <= 16 for n in ns):
        raise ValueError(f"--targets wants comma-separated integers in 1..16, got {text!r}")
    return ns


def run_multi(args: argparse.Namespace) -> int:
    """``mstrack explore --multi``: the multi-target core's cost model (mstrack.hw.multi_core)."""
    from .hw import multi_core
    ns = _targets(args.targets)
    if args.yosys_check:
        for r in multi_core.yosys_check():
            print(r)
        return 0
    if args.write:
        doc = multi_core.DOC
        doc.write_text(multi_core.render_doc(doc.read_text()))
        print(f"wrote {doc}", file=sys.stderr)
    print(multi_core.markdown(ns))
    return 0


def run(args: argparse.Namespace) -> int:
    if args.check:
        print(check_markdown())
        return 0
    if args.multi or args.write or args.yosys_check:
        if not args.multi:
            raise ValueError("--write and --yosys-check go with --multi")
        return run_multi(args)
    from .cli import _csv_list, check_out_dir
    from .io.data import load_dataset
    if not args.dataset:
        raise ValueError("DATASET_DIR is missing (only --check runs without it)")
    grid = parse_grid(args.grid)
    trackers = _csv_list(args.trackers) or list(DEFAULT_TRACKERS)
    points = make_points(trackers, grid, args.model)
    check_out_dir(args.out)
    seqs = load_dataset(args.dataset, _csv_list(args.sequences))
    n_runs = len({p.run_name for p in points})
    print(f"explore: {len(points)} points, {n_runs} accuracy runs x {len(seqs)} sequences ({args.model} model)",
          file=sys.stderr)
    rows = explore(seqs, points, args.out, model=args.model, jobs=args.jobs, scheduler=args.scheduler,
                   force=args.force, quiet=args.quiet, max_frames=args.max_frames, yosys=args.yosys,
                   budget=args.budget)
    paths = write_outputs(rows, args.out, command=getattr(args, "command_line", ""), plot=not args.no_plot)
    print(markdown_table(rows))
    print("outputs: " + ", ".join(str(p) for p in paths.values()))
    return 0


def register_cli(sub: argparse._SubParsersAction) -> None:
    """CLI extension (mstrack.cli.EXTENSIONS entry ``"mstrack.explore:register_cli"``): ``mstrack explore``."""
    p = sub.add_parser("explore", help="design-space sweep: accuracy against hardware cost, Pareto plot",
                       description=__doc__.split("\n\n")[0])
    add_arguments(p)
    p.set_defaults(func=run)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mstrack.explore", description=__doc__.split("\n\n")[0])
    add_arguments(ap)
    return run(ap.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
