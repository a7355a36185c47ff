"""Configuration of the core from user-level choices: ``mstrack hdl config``.

An integrator chooses what the system needs (preset, widest frame, largest target, pixels per
clock, features, kernel, pixel packing; behind AXI4-Lite: the targets, one engine per target or one
shared engine and its video timing); :func:`derive` turns the choices into every generic of
``ms_tracker`` or ``ms_tracker_axi`` (PRESET 0 the paper core, 1 core v2; the derived widths come from
:func:`mstrack.fixed.vhdl_pkg.core_generics`, core v2's from
:meth:`mstrack.hw.cosim.CoreConfigV2.tracker_generics`, the single sources of truth) and refuses
impossible combinations with a one-line reason (:class:`ConfigError`).  The RTL checks the same relations at elaboration (``ms_tracker``,
"generic checks"), so a hand-edited generic map is refused too.

Outputs (:func:`render`): a VHDL package of constants (``C_<GENERIC>``, plus the generic map
that uses them, as a comment to paste), a plain generic map, or JSON::

    mstrack hdl config --max-frame-width 1920 --max-target 127 --lanes 4 --out ms_tracker_config_pkg.vhd
    mstrack hdl config --kernel epanechnikov --format generic-map
    mstrack hdl config --preset v2 --max-frame-width 1920 --out ms_tracker_config_pkg.vhd
    mstrack hdl config --preset v2 --colour --max-frame-width 1920 --top ms_tracker_axi --max-targets 8 \
        --shared-engine --timing 1080p60 --max-target 63 --coord-bits 11 --format generic-map

docs/packaging.md, "Configuration", lists the choices and the refusals.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from ..fixed.formats import FixedParams
from ..fixed.vhdl_pkg import DEFAULT_LANES, core_generics
from ..track.params import V2_COLOUR, TrackerParams
from .fastsim import VIDEO_MODES, mode_timing

REPO_ROOT = Path(__file__).resolve().parents[2]
TRACKER_VHD = REPO_ROOT / "rtl" / "ms_tracker.vhd"

#: s_axis_tdata layouts (generic RGB_PACKING): name -> (value, description)
RGB_PACKINGS = {
    "mstrack": (0, "R 23:16, G 15:8, B 7:0"),
    "ug934": (1, "R 23:16, B 15:8, G 7:0 (AMD UG934, video format code 2: RGB)"),
}
#: largest window half-extent the kernel tables and the fixed-point formats are built for
#: (FixedParams.max_half), i.e. targets up to 2 * 255 + 1 = 511 px
MAX_HALF_LIMIT = 255
FEATURES = ("fused", "colour", "edge")
KERNELS = ("flat", "epanechnikov")
PRESETS = ("paper", "v2")
#: generic PRESET of ms_tracker per preset
PRESET_GENERIC = {"paper": 0, "v2": 1}
#: core v2's own generics (ms_tracker, after RESULT_W; PRESET 1 only), in declaration order
V2_GENERICS = ("PAD16", "RING16", "MAX_WINDOW", "KT_W", "ST2_W", "SHARE_W", "SPREAD_W", "SIZE_W", "SCALE_W",
               "SCALE_GAIN", "SCALE_REG", "SCALE_STEP", "SCALE_RATIO_Q_W", "WR_Q_W", "CON_W", "LOSS_K", "REF_K",
               "LOSS_RHO", "LOSS_CONTRAST", "CONF_LOST", "CONF_UNCERTAIN", "CONF_REACQUIRE", "SPREAD_DEFAULT",
               "BG_Q_W", "BG_O_W", "SEARCH_ITER", "STEP16", "MARGIN_MAX", "SCALE_TEST_D256", "ORIENT_T")
#: generics of type integer (the others are natural)
INTEGER_GENERICS = ("LOSS_CONTRAST", "ORIENT_T")
#: window range of core v2 (decimated px): TrackerParams.max_window >= 7; ms_bg_model's count widths
#: (BG_Q_W 14, BG_O_W 17, ms_tracker_v2's defaults, which CoreConfigV2 does not derive) hold windows up to 127
V2_MIN_TARGET, V2_MAX_TARGET = 7, 127
V2_BG_WIDTHS = {"BG_Q_W": 14, "BG_O_W": 17}
#: COORD_W of core v2 (ms_tracker_v2 packs result word v2 in 160 bits for COORD_W 12)
V2_COORD_BITS = 12
FORMATS = ("package", "generic-map", "json")
#: the top levels: the core alone, or behind AXI4-Lite (registers, interrupt, the C driver)
TOPS = ("ms_tracker", "ms_tracker_axi")
#: generics of type boolean (ms_tracker_axi); 0 / 1 in :attr:`CoreConfiguration.generics`
BOOLEAN_GENERICS = ("SHARED_ENGINE", "RESULT_STREAM")
#: COORD_W of the shared-engine core: 12, or 11 (frames up to 2047 px high: a smaller slot, REGION_MAX)
SHARED_COORD_BITS = (11, 12)


class ConfigError(ValueError):
    """An impossible combination of choices; the message is one line saying why."""


@dataclass(frozen=True)
class CoreChoices:
    """What an integrator chooses (everything else is derived).

    Attributes
    ----------
    max_frame_width : int
        Widest frame in px (MAX_FRAME_W: depth of the Sobel line buffer); 3 .. 2**coord_bits - 1.
    max_target : int
        Largest target (window) in px, width and height; larger init boxes are shrunk about their
        centre.  MAX_HALF = max_target // 2, so the largest window is 2 MAX_HALF + 1 px (odd).
        Preset v2: the largest window in decimated px (MAX_WINDOW = 2 MAX_HALF + 1, at least 7);
        larger targets are tracked on a decimated frame, so no target is too large.
    lanes : int
        LANES: region pixels per clock in a pixel pass (power of two).
    features : {"fused", "colour", "edge"}, optional
        Default: the preset's (paper: fused; v2: colour, the only one it has).
    kernel : {"flat", "epanechnikov"}
        Preset v2: flat only.
    preset : {"paper", "v2"}
        The tracker: generic PRESET 0 (the paper core) or 1 (core v2: tracker v2, flat kernel,
        PPC 1, result word v2 of 160 bits).
    margin : int
        MARGIN: search margin in px around the window (largest motion per frame followed).
    coord_bits : int
        COORD_W: frame coordinate bits; frames up to 2**coord_bits - 1 px wide and high.
    rgb_packing : {"mstrack", "ug934"}
        Layout of s_axis_tdata (:data:`RGB_PACKINGS`).
    ppc : {1, 2, 4}
        PPC: pixels per clock of the video input (s_axis_tdata of 24 PPC bits); at most LANES.
    colour : bool
        Preset v2 only: tracker mstrack-v2-colour (mstrack.track.params.V2_COLOUR: colour bins
        alone, ORIENT_T -1; no scale test; its loss thresholds), a smaller and faster core than the
        default mstrack-v2 (the joint colour x gradient-orientation bins, ORIENT_T 64).
    scale_test : float or None
        Preset v2 only: the gated scale test's relative size step (TrackerParams scale_test with
        scale_test_gate), generic SCALE_TEST_D256 = round(256 scale_test); None (default): the
        tracker's (mstrack-v2 0.05, mstrack-v2-colour 0 = off).
    top : {"ms_tracker", "ms_tracker_axi"}
        The entity configured: the core alone, or behind AXI4-Lite (the register map of
        docs/integration.md, the C driver); ms_tracker_axi has every generic of ms_tracker and its own.
    max_targets : int
        ms_tracker_axi, preset v2: 0 one target (ms_tracker), 1 .. 16 the multi-target core's slots
        (MAX_TARGETS).
    shared_engine : bool
        With max_targets: one engine for every slot (ms_tracker_shared, SHARED_ENGINE) instead of an
        engine per slot (ms_tracker_multi); its capacity rule is built for the video timing ``timing``.
    timing : str
        shared_engine: the video mode the capacity rule plans each frame for
        (:data:`mstrack.hw.fastsim.VIDEO_MODES`, one pixel per clock: ACTIVE_LINES, FRAME_LINES,
        LINE_CLOCKS).
    result_stream : bool
        ms_tracker_axi: the result words on m_axis_result as well as in the registers (RESULT_STREAM);
        false for a CPU-only integration.
    """

    max_frame_width: int = 2048
    max_target: int = 2 * FixedParams.max_half + 1
    lanes: int = DEFAULT_LANES
    features: str | None = None
    kernel: str = "flat"
    preset: str = "paper"
    margin: int = FixedParams.margin
    coord_bits: int = FixedParams.coord_bits
    rgb_packing: str = "mstrack"
    ppc: int = 1
    scale_test: float | None = None
    colour: bool = False
    top: str = "ms_tracker"
    max_targets: int = 0
    shared_engine: bool = False
    timing: str = "1080p60"
    result_stream: bool = True


@dataclass(frozen=True)
class CoreConfiguration:
    """The result of :func:`derive`: model parameters and every generic of ms_tracker (preset v2:
    those of core v2 too)."""

    choices: CoreChoices
    tp: TrackerParams
    fp: FixedParams
    generics: dict[str, int]


def derive(c: CoreChoices) -> CoreConfiguration:
    """Every generic of ms_tracker for the choices ``c``; :class:`ConfigError` with the reason if impossible."""
    if c.preset not in PRESETS:
        raise ConfigError(f"preset {c.preset!r} unknown (one of {', '.join(PRESETS)})")
    _check_top(c)
    v2 = c.preset == "v2"
    features = c.features if c.features is not None else ("colour" if v2 else "fused")
    if features not in FEATURES:
        raise ConfigError(f"features {features!r} unknown (one of {', '.join(FEATURES)})")
    if c.kernel not in KERNELS:
        raise ConfigError(f"kernel {c.kernel!r} unknown (one of {', '.join(KERNELS)})")
    if c.rgb_packing not in RGB_PACKINGS:
        raise ConfigError(f"rgb packing {c.rgb_packing!r} unknown (one of {', '.join(RGB_PACKINGS)})")
    if not 8 <= c.coord_bits <= 14:
        raise ConfigError(f"COORD_W {c.coord_bits} out of 8..14 (frames up to 255 .. 16383 px)")
    coord_max = (1 << c.coord_bits) - 1
    if c.max_frame_width < 3:
        raise ConfigError(f"max frame width {c.max_frame_width} px: frames are at least 3 px wide")
    if c.max_frame_width > coord_max:
        need = c.max_frame_width.bit_length()
        hint = f"; use --coord-bits {need}" if need <= 14 else "; COORD_W is at most 14 (16383 px)"
        raise ConfigError(f"max frame width {c.max_frame_width} px does not fit COORD_W = {c.coord_bits} bits "
                          f"(at most {coord_max} px){hint}")
    if c.max_target < 3:
        raise ConfigError(f"largest target {c.max_target} px: windows are at least 3x3 px")
    if v2:
        if features != "colour":
            raise ConfigError(f"preset v2 tracks colour only: features {features} (use --features colour "
                              "or leave it out)")
        if c.kernel != "flat":
            raise ConfigError(f"preset v2 has the flat kernel only: kernel {c.kernel}")
        if c.ppc != 1:
            raise ConfigError(f"PPC {c.ppc}: core v2 (preset v2) takes one pixel per clock (PPC 1)")
        if not V2_MIN_TARGET <= c.max_target <= V2_MAX_TARGET:
            raise ConfigError(f"largest window {c.max_target} px: core v2 windows are {V2_MIN_TARGET} .. "
                              f"{V2_MAX_TARGET} decimated px (larger targets are tracked on a decimated frame)")
        if c.scale_test is not None and not 0 <= c.scale_test <= 0.5:
            raise ConfigError(f"scale test {c.scale_test}: 0 (off) or a relative size step up to 0.5")
        if c.coord_bits != V2_COORD_BITS and not (c.shared_engine and c.coord_bits in SHARED_COORD_BITS):
            raise ConfigError(f"COORD_W {c.coord_bits}: core v2 is built for COORD_W {V2_COORD_BITS} (frames up to "
                              "4095 px; result word v2 of 160 bits)")
    elif c.scale_test is not None:
        raise ConfigError(f"scale test {c.scale_test}: the gated scale test is core v2's (--preset v2)")
    elif c.colour:
        raise ConfigError("--colour (mstrack-v2-colour) is a core v2 tracker (--preset v2)")
    max_half = c.max_target // 2
    if max_half > MAX_HALF_LIMIT:
        raise ConfigError(f"largest target {c.max_target} px > {2 * MAX_HALF_LIMIT + 1} px, the largest window "
                          f"the kernel tables hold (MAX_HALF <= {MAX_HALF_LIMIT})")
    if not 0 <= c.margin <= 255:
        raise ConfigError(f"margin {c.margin} px out of 0..255")
    if c.lanes < 1 or c.lanes & (c.lanes - 1):
        raise ConfigError(f"LANES {c.lanes} is not a power of two (1, 2, 4, 8, ...)")
    if c.ppc not in (1, 2, 4):
        raise ConfigError(f"PPC {c.ppc} pixels per clock: 1, 2 or 4")
    if c.ppc > c.lanes:
        raise ConfigError(f"PPC {c.ppc} > LANES {c.lanes}: the region capture writes the pixels of a beat into "
                          f"PPC different banks; use --lanes {c.ppc} or more")
    region_max = 2 * max_half + 1 + 2 * c.margin
    if c.lanes > region_max:
        raise ConfigError(f"LANES {c.lanes} > the region width {region_max} px (REGION_MAX): "
                          f"more lanes than pixels in a region row")
    try:
        tp_kw: dict[str, Any] = {"max_window": 2 * max_half + 1} if v2 else {}
        if c.colour:
            tp_kw.update(V2_COLOUR)
        if v2 and c.scale_test is not None:
            tp_kw.update(scale_test=c.scale_test, scale_test_gate=True)
        tp = TrackerParams(features=features, kernel=c.kernel, preset=c.preset, **tp_kw)  # type: ignore[arg-type]
        fp = FixedParams(max_half=max_half, margin=c.margin, coord_bits=c.coord_bits)
    except ValueError as exc:  # the model's own checks (one line each)
        raise ConfigError(str(exc)) from None
    head = {"PRESET": PRESET_GENERIC[c.preset], "MAX_FRAME_W": c.max_frame_width,
            "RGB_PACKING": RGB_PACKINGS[c.rgb_packing][0], "PPC": c.ppc}
    base = core_generics(tp, fp, c.lanes)
    if not v2:
        return CoreConfiguration(c, tp, fp, _axi_generics(c, tp, fp, {**head, **base}))
    from .cosim import CoreConfigV2
    try:
        gv2 = {**CoreConfigV2(tp, fp, c.lanes, c.max_frame_width).tracker_generics(), **V2_BG_WIDTHS}
    except ValueError as exc:  # e.g. a scale test whose d256 rounds to 0
        raise ConfigError(str(exc)) from None
    g = {**head, **{k: gv2[k] for k in base}, **{k: gv2[k] for k in V2_GENERICS}}
    missing = set(gv2) - set(g)
    if missing:    # CoreConfigV2 sets a generic this module does not know: keep the two in step
        raise RuntimeError(f"core v2 generics not in V2_GENERICS: {sorted(missing)}")
    return CoreConfiguration(c, tp, fp, _axi_generics(c, tp, fp, g))


def _check_top(c: CoreChoices) -> None:
    """The choices of the top level that do not depend on the tracker (one-line refusals)."""
    if c.top not in TOPS:
        raise ConfigError(f"top {c.top!r} unknown (one of {', '.join(TOPS)})")
    if c.top == "ms_tracker" and (c.max_targets or c.shared_engine or not c.result_stream):
        raise ConfigError("several targets, a shared engine and the result stream's choice are ms_tracker_axi's "
                          "(--top ms_tracker_axi)")
    if not 0 <= c.max_targets <= 16:
        raise ConfigError(f"{c.max_targets} targets: the multi-target core has 1 .. 16 slots")
    if c.max_targets and c.preset != "v2":
        raise ConfigError("several targets: the multi-target core is core v2 (--preset v2)")
    if c.shared_engine and not c.max_targets:
        raise ConfigError("a shared engine serves the slots of the multi-target core: give --max-targets 1 .. 16")
    if c.shared_engine and c.timing not in VIDEO_MODES:
        raise ConfigError(f"video timing {c.timing!r} unknown (one of {', '.join(VIDEO_MODES)})")


def _axi_generics(c: CoreChoices, tp: TrackerParams, fp: FixedParams, g: dict[str, int]) -> dict[str, int]:
    """ms_tracker's generics *g*, with ms_tracker_axi's own when ``c.top`` is ms_tracker_axi: those of
    :func:`mstrack.hw.drvsim.axi_generics` (RESULT_STREAM, MAX_TARGETS, SHARED_ENGINE and the shared
    engine's), MAX_TARGETS and SHARED_ENGINE always given."""
    if c.top == "ms_tracker":
        return g
    from .cosim import CoreConfig, CoreConfigV2
    from .drvsim import axi_generics
    cfg = (CoreConfigV2(tp, fp, c.lanes, c.max_frame_width) if c.preset == "v2"
           else CoreConfig(tp, fp, c.lanes, c.max_frame_width))
    own = axi_generics(cfg, c.max_targets, c.result_stream, mode_timing(c.timing) if c.shared_engine else None)
    return {**g, "MAX_TARGETS": c.max_targets, "SHARED_ENGINE": int(c.shared_engine),
            **{k: v for k, v in own.items() if k not in g}}


def entity_generics(path: Path = TRACKER_VHD, entity: str = "ms_tracker") -> list[str]:
    """Names of the generics of *entity* (ms_tracker, or ms_tracker_axi in its own file), in declaration
    order (read from the VHDL)."""
    if entity != "ms_tracker" and path == TRACKER_VHD:
        path = TRACKER_VHD.with_name(f"{entity}.vhd")
    text = re.sub(r"--[^\n]*", "", path.read_text())
    m = re.search(rf"entity\s+{entity}\s+is\s+generic\s*\((.*?)\)\s*;\s*port", text, re.S | re.I)
    if not m:
        raise RuntimeError(f"no generic clause found in {path}")
    return re.findall(r"(\w+)\s*:\s*(?:natural|integer|positive|boolean)\b", m.group(1), re.I)


def _value(k: str, v: int) -> str:
    """A generic's value as VHDL text (booleans: true / false)."""
    return ("true" if v else "false") if k in BOOLEAN_GENERICS else str(v)


def generic_map(g: dict[str, int], prefix: str = "", indent: str = "    ") -> str:
    """``generic map (...)`` text: NAME => value, or NAME => <prefix>NAME when ``prefix`` is given."""
    width = max(len(k) for k in g)
    items = [f"{indent}{k:<{width}} => {prefix + k if prefix else _value(k, v)}" for k, v in g.items()]
    return "generic map (\n" + ",\n".join(items) + "\n)"


def _header(cfg: CoreConfiguration, command: str, comment: str) -> list[str]:
    c = cfg.choices
    g = cfg.generics
    lines = [f"GENERATED by `{command}`; do not edit (regenerate instead).",
             f"mstrack configuration of {c.top} (docs/packaging.md, \"Configuration\"):",
             f"  frames up to {c.max_frame_width} px wide, {(1 << c.coord_bits) - 1} px high (COORD_W {c.coord_bits});",
             (f"  targets up to {2 * g['MAX_HALF'] + 1} px (MAX_HALF {g['MAX_HALF']}), search margin {c.margin} px;"
              if c.preset != "v2" else
              f"  windows up to {2 * g['MAX_HALF'] + 1} decimated px (MAX_HALF {g['MAX_HALF']}; larger targets are "
              f"decimated), search margin {c.margin} decimated px;"),
             f"  LANES {c.lanes}, features {cfg.tp.features}, kernel {c.kernel}, preset {c.preset} (PRESET {g['PRESET']})"
             + (f", tracker {'mstrack-v2-colour' if c.colour else 'mstrack-v2'} (ORIENT_T {g['ORIENT_T']}, "
                f"SCALE_TEST_D256 {g['SCALE_TEST_D256']})" if c.preset == "v2" else "") + ";",
             f"  s_axis_tdata {RGB_PACKINGS[c.rgb_packing][1]}, {c.ppc} pixel(s) per clock (PPC);",
             f"  result word {g['RESULT_W']} bits (fields: mstrack.fixed.vhdl_pkg.result_layout"
             f"{'_v2' if c.preset == 'v2' else ''})" + (";" if c.top != "ms_tracker" else ".")]
    if c.top != "ms_tracker":
        lines.append("  behind AXI4-Lite (docs/integration.md), " + (
            f"{c.max_targets} target slot(s), " + (f"one shared engine, capacity rule at {c.timing}" if c.shared_engine
                                                   else "an engine per slot") if c.max_targets else "one target")
            + f", result stream {'on' if c.result_stream else 'off'}.")
    return [f"{comment} {ln}".rstrip() for ln in lines]


def render(cfg: CoreConfiguration, fmt: str = "package", name: str = "ms_tracker_config_pkg",
           command: str = "mstrack hdl config") -> str:
    """The configuration as a VHDL package (``package``), a ``generic-map`` or ``json``."""
    g = cfg.generics
    if fmt == "json":
        return json.dumps({"command": command, "choices": asdict(cfg.choices), "generics": g}, indent=1) + "\n"
    if fmt == "generic-map":
        return "\n".join(_header(cfg, command, "--")) + "\n" + generic_map(g) + "\n"
    if fmt != "package":
        raise ConfigError(f"format {fmt!r} unknown (one of {', '.join(FORMATS)})")
    if not re.fullmatch(r"[A-Za-z]\w*", name):
        raise ConfigError(f"package name {name!r} is not a VHDL identifier")
    width = max(len(k) for k in g) + 3      # "C_" + the longest name + one blank
    out = _header(cfg, command, "--")
    out += ["--", "-- Use: compile this file before the core's instance, then", "--   use work." + name + ".all;",
            f"--   u_tracker : entity work.{cfg.choices.top}"]
    out += ["--   " + ln for ln in generic_map(g, prefix="C_", indent="  ").splitlines()]
    out += [f"package {name} is"]
    out += [f"  constant {'C_' + k:<{width}}: {_type(k)} := {_value(k, v)};" for k, v in g.items()]
    out += [f"end package {name};", ""]
    return "\n".join(out)


def _type(k: str) -> str:
    return "boolean" if k in BOOLEAN_GENERICS else "integer" if k in INTEGER_GENERICS else "natural"


# ----------------------------------------------------------------------------- CLI
def add_config_arguments(p: argparse.ArgumentParser) -> None:
    d = CoreChoices()
    p.add_argument("--max-frame-width", type=int, default=d.max_frame_width,
                   help=f"widest frame in px (MAX_FRAME_W, default {d.max_frame_width})")
    p.add_argument("--max-target", type=int, default=d.max_target,
                   help=f"largest target (window) in px, width and height (default {d.max_target}); "
                        f"at most {2 * MAX_HALF_LIMIT + 1}")
    p.add_argument("--lanes", type=int, default=d.lanes, help=f"LANES, a power of two (default {d.lanes})")
    p.add_argument("--features", choices=FEATURES, default=d.features,
                   help="default: the preset's (paper fused, v2 colour, the only one v2 has)")
    p.add_argument("--kernel", choices=KERNELS, default=d.kernel)
    p.add_argument("--preset", default=d.preset,
                   help="paper (PRESET 0, default) or v2 (PRESET 1: core v2, tracker v2, flat kernel, PPC 1, "
                        "result word v2)")
    p.add_argument("--margin", type=int, default=d.margin, help=f"search margin in px (default {d.margin})")
    p.add_argument("--coord-bits", type=int, default=d.coord_bits,
                   help=f"COORD_W: frames up to 2**N - 1 px (default {d.coord_bits})")
    p.add_argument("--rgb-packing", choices=tuple(RGB_PACKINGS), default=d.rgb_packing,
                   help="s_axis_tdata layout: mstrack (R, G, B from the MSB) or ug934 (R, B, G)")
    p.add_argument("--ppc", type=int, choices=(1, 2, 4), default=d.ppc,
                   help="pixels per clock of the video input (PPC, <= LANES; default 1)")
    p.add_argument("--scale-test", type=float, default=d.scale_test,
                   help="preset v2: the gated scale test's relative size step (SCALE_TEST_D256 = round(256 x); "
                        "0 = off; default: the tracker's, mstrack-v2 0.05, --colour 0)")
    p.add_argument("--colour", action="store_true",
                   help="preset v2: tracker mstrack-v2-colour (colour bins alone, ORIENT_T -1: a smaller, "
                        "faster core than mstrack-v2's joint colour x orientation bins)")
    p.add_argument("--top", choices=TOPS, default=d.top,
                   help="the entity configured: ms_tracker (default) or ms_tracker_axi (behind AXI4-Lite, the C "
                        "driver; docs/integration.md)")
    p.add_argument("--max-targets", type=int, default=d.max_targets,
                   help="ms_tracker_axi, --preset v2: target slots of the multi-target core (MAX_TARGETS 1 .. 16; "
                        "default 0: one target)")
    p.add_argument("--shared-engine", action="store_true",
                   help="with --max-targets: one engine for every slot (ms_tracker_shared) instead of one per slot")
    p.add_argument("--timing", choices=tuple(VIDEO_MODES), default=d.timing,
                   help=f"--shared-engine: the video mode its capacity rule plans for (default {d.timing})")
    p.add_argument("--no-result-stream", action="store_true",
                   help="ms_tracker_axi: results through the registers only (RESULT_STREAM false)")
    p.add_argument("--format", choices=FORMATS, default="package", help="output (default: VHDL package)")
    p.add_argument("--name", default="ms_tracker_config_pkg", help="package name (--format package)")
    p.add_argument("--out", help="output file (default: standard output)")


def run_config(args: argparse.Namespace) -> int:
    choices = CoreChoices(max_frame_width=args.max_frame_width, max_target=args.max_target, lanes=args.lanes,
                          features=args.features, kernel=args.kernel, preset=args.preset, margin=args.margin,
                          coord_bits=args.coord_bits, rgb_packing=args.rgb_packing, ppc=args.ppc,
                          scale_test=args.scale_test, colour=args.colour, top=args.top,
                          max_targets=args.max_targets, shared_engine=args.shared_engine, timing=args.timing,
                          result_stream=not args.no_result_stream)
    cfg = derive(choices)
    command = getattr(args, "command_line", None) or "mstrack hdl config"
    text = render(cfg, args.format, args.name, command)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text)
        print(f"wrote {args.out}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def run_files(args: argparse.Namespace) -> int:
    from . import packaging
    stale = packaging.write_generated(check=args.check)
    if args.check:
        if stale:
            print("stale (regenerate with `mstrack hdl files`): " + ", ".join(map(str, stale)))
            return 1
        print("up to date")
        return 0
    for p in stale:
        print(f"wrote {p}")
    return 0


def register_cli(sub: argparse._SubParsersAction) -> None:
    """CLI extension (mstrack.cli.EXTENSIONS entry ``"mstrack.hw.hdl_config:register_cli"``): ``mstrack hdl ...``."""
    p = sub.add_parser("hdl", help="integration of the VHDL core: configuration, file lists",
                       description="Integration helpers for the VHDL core (docs/packaging.md).")
    hsub = p.add_subparsers(dest="hdl_command", metavar="HDL_COMMAND", required=True)
    c = hsub.add_parser("config", help="generics of ms_tracker from user-level choices (VHDL package / generic map)",
                        description=__doc__.split("\n\n")[1].replace("\n", " "))
    add_config_arguments(c)
    c.set_defaults(func=run_config)
    f = hsub.add_parser("files", help="regenerate rtl/files.txt and mstrack.core from mstrack.hw.hdl's source list",
                        description="Write the ordered file list rtl/files.txt and the FuseSoC core file "
                                    "mstrack.core (both generated from mstrack.hw.hdl.rtl_sources).")
    f.add_argument("--check", action="store_true", help="only check that they are up to date (exit 1 if not)")
    f.set_defaults(func=run_files)
