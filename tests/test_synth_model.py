"""mstrack.hw.synth without tools: cycle model, critical-path parsing, doc sections."""
from __future__ import annotations

import json

import pytest

from mstrack.hw import synth


def test_pixel_pass_cycles_box_and_rows():
    # bounding-box scan: (2 ey + 1) G + 5; 63 px rows are ex + 1 = 32 groups of 2 lanes
    assert synth.pixel_pass_cycles(31, 31, 2, 50) == 63 * 32 + 5 == 2021
    # LANES 4: 16 or 17 groups depending on the alignment; worst case taken when wx is None
    assert {synth.pixel_pass_cycles(31, 31, 4, wx) for wx in range(31, 35)} == {63 * 16 + 5, 63 * 17 + 5}
    assert synth.pixel_pass_cycles(31, 31, 4) == 63 * 17 + 5
    # row-extent scan of a 64x64 flat kernel (docs/performance.md: 1,640 with L 2, 863 worst with L 4
    # at PASS_LAT 6; PASS_LAT 10 since the kernel/histogram register stages)
    xr = synth.row_extents(64, 64)
    assert len(xr) == 32 and xr[0] == 31 and xr == sorted(xr, reverse=True)
    assert synth.pass_lat_rows() == 10
    assert synth.pixel_pass_cycles(31, 31, 2, 50, xr) == 1634 + 10
    assert synth.pixel_pass_cycles(31, 31, 4, None, xr) == 857 + 10


def test_engine_cycles_matches_documented_worst_case():
    """docs/realtime.md: 127x127 window, LANES 2, box scan, 20 colour iterations: 182,763 clocks
    from the last pixel = 11 + engine + 28 (fusion of that RTL: RHO_OUT_FRAC + 8)."""
    g = synth.CONFIGS["lanes2"].generics()
    p = synth.pixel_pass_cycles(63, 63, 2)                  # box scan, 127 x 64 + 5
    eng = synth.engine_cycles(g, [p] * 21, 512, 20)
    # + 21 x 2 (bin pass, LUT multipliers) + 20 x 2 (centre: registered divider operands,
    # iterative dividers)
    assert 11 + eng + 1 + (g["RHO_OUT_FRAC"] + 8) + 3 == 182_763 + 21 * 2 + 20 * 2
    # stop "lost" at the first centre: one pass, one bin pass, one centre
    assert synth.engine_cycles(g, [p], 512, 1, "lost") == p + 547 + 20 + 7
    with pytest.raises(AssertionError):
        synth.engine_cycles(g, [p] * 20, 512, 20)           # n iterations need n + 1 passes


def test_bin_pass_and_centre_latencies():
    g = synth.CONFIGS["default"].generics()
    assert synth.bin_pass_cycles(g, 512) == 547 and synth.bin_pass_cycles(g, 16) == 51
    assert synth.bin_pass_cycles(g, 512, learn=True) == 517
    # ITERATIVE = 1 (the edge engine): T1 + 15 P + S2 + 2 = 23 + 15 x 23 + 23, learn unchanged
    assert synth.bin_pass_cycles(g, 16, iterative=True) == 391
    assert synth.bin_pass_cycles(g, 16, learn=True, iterative=True) == 21
    assert synth.edge_bins_iterative()
    f = synth.cycle_figures("default")
    assert f.bin_pass_e == 391 and f.iteration_e < f.iteration_c      # the colour loop still decides
    assert synth.centre_cycles(g) == 20


NETLIST = """module sub_1_2 (input clk);
  reg [3:0] n12_q;
  assign cnt = n12_q; // (signal)
endmodule
module top (input clk);
  reg n5_q;
  assign flag = n5_q; // (signal)
  sub_1_2 u_sub (
    .clk(clk));
endmodule
"""


def test_netlist_names_and_critical_path(tmp_path):
    v = tmp_path / "top.v"
    v.write_text(NETLIST)
    n = synth.NetlistNames(v, "top")
    assert n.vhdl("u_sub.n12_q_TRELLIS_FF_Q_3") == "u_sub.cnt"
    assert n.vhdl("n5_q_TRELLIS_FF_Q") == "flag"
    assert n.module_of("u_sub.n12_q_TRELLIS_FF_Q_3") == "sub"
    rep = {"critical_paths": [{"from": "posedge clk", "to": "posedge clk", "path": [
        {"type": "clk-to-q", "delay": 0.5, "from": {"cell": "n5_q_TRELLIS_FF_Q", "port": "Q"},
         "to": {"cell": "n5_q_TRELLIS_FF_Q", "port": "Q"}},
        {"type": "routing", "delay": 1.0, "net": "x", "from": {"cell": "n5_q_TRELLIS_FF_Q", "port": "Q"},
         "to": {"cell": "u_sub.n12_q_TRELLIS_FF_Q_3", "port": "DI"}},
        {"type": "setup", "delay": 0.25, "from": {"cell": "u_sub.n12_q_TRELLIS_FF_Q_3", "port": "DI"},
         "to": {"cell": "u_sub.n12_q_TRELLIS_FF_Q_3", "port": "DI"}}]}]}
    cp = synth.critical_path(rep, n)
    assert cp["total_ns"] == 1.75 and cp["routing_ns"] == 1.0 and cp["logic_ns"] == 0.75
    assert (cp["source"], cp["sink"], cp["sink_module"]) == ("flag", "u_sub.cnt", "sub")
    assert synth.path_summary(cp) == "flag -> u_sub.cnt"


LATE_NETLIST = NETLIST.replace("""  assign flag = n5_q; // (signal)
""", """  assign flag = n5_q; // (signal)
  reg [7:0] n7_q;
  reg [3:0] n8_q;
  wire [3:0] n9_o;
  initial begin
    recs = n7_q; // (isignal)
  end
  assign n9_o = recs[7:4];
""")


def test_late_endpoints_group_by_vhdl_name(tmp_path):
    v = tmp_path / "top.v"
    v.write_text(LATE_NETLIST)
    n = synth.NetlistNames(v, "top")
    assert n.vhdl("n7_q_TRELLIS_FF_Q_2") == "recs"          # a signal with an initial value
    assert n.vhdl("n9_o_TRELLIS_FF_Q") == "recs"            # a slice of it
    period = 1000 / synth.TARGET_FMAX_MHZ

    def ep(cell: str, port: str, arrival: float) -> dict:
        return {"cell": cell, "port": port, "delay": [arrival / 2, arrival], "event": "posedge clk"}
    rep = {"detailed_net_timings": [
        {"net": "a", "endpoints": [ep("n7_q_TRELLIS_FF_Q_2", "CE", period), ep("n9_o_TRELLIS_FF_Q", "LSR", period + 1),
                                   ep("u_sub.n12_q_TRELLIS_FF_Q_3", "DI", period + 0.5)]},
        {"net": "b", "endpoints": [ep("n5_q_TRELLIS_FF_Q", "DI", period - 1.0),      # in time
                                   ep("u_sub.n12_q_TRELLIS_FF_Q_1", "CE", period - 0.2)]}]}
    rows = synth.late_endpoints(rep, n)
    assert [(r["name"], r["endpoints"]) for r in rows] == [("recs", 2), ("u_sub.cnt", 2)]
    assert rows[0]["ports"] == {"CE": 1, "LSR": 1} and rows[0]["worst_ns"] == round(period + 1, 3)
    # without the setup time an arrival at the period, or 0.2 ns before it, is in time
    assert [(r["name"], r["endpoints"]) for r in synth.late_endpoints(rep, n, setup_ns=0.0)] == [
        ("recs", 1), ("u_sub.cnt", 1)]
    table = synth.late_table(rows)
    assert "| `recs` | 2 |" in table and table.endswith("| all (2 groups) | 4 | | |")
    assert synth.late_endpoints({"detailed_net_timings": []}) == []


def test_late_endpoints_cli(tmp_path, capsys):
    v = tmp_path / "top.v"
    v.write_text(LATE_NETLIST)
    rep = tmp_path / "report.json"
    rep.write_text(json.dumps({"detailed_net_timings": [{"net": "a", "endpoints": [
        {"cell": "n9_o_TRELLIS_FF_Q", "port": "CE", "delay": [1.0, 9.0]}]}]}))
    assert synth.main(["--late-endpoints", str(rep), "--netlist", str(v)]) == 0
    assert "| `recs` | 1 | 9.00 | CE 1 |" in capsys.readouterr().out
    rep.write_text(json.dumps({"critical_paths": []}))                 # written without the detail
    assert synth.main(["--late-endpoints", str(rep)]) == 2
    assert "--detailed-timing-report" in capsys.readouterr().err


def test_write_section_replaces_in_place(tmp_path):
    p = tmp_path / "perf.md"
    p.write_text("# P\n\n<!-- perf-x:begin -->\nold\n<!-- perf-x:end -->\n\ntail\n")
    synth.write_section("| a |\n|---|", "x", "mstrack synth --x", p)
    synth.write_section("| b |\n|---|", "x", "mstrack synth --x", p)
    text = p.read_text()
    assert "| b |" in text and "| a |" not in text and "old" not in text and text.endswith("tail\n")
    assert text.count("perf-x:begin") == 1 and "Command: `mstrack synth --x`" in text


def test_tables_from_a_summary():
    s = {"config": "c", "ecp5": {"LUT4": 1, "TRELLIS_FF": 2, "CCU2C": 3, "DP16KD": 4, "MULT18X18D": 5,
                                 "TRELLIS_DPR16X4": 6},
         "pnr": [{"fmax_mhz": 70.0, "utilization": {"TRELLIS_COMB": (10, 100), "TRELLIS_FF": (2, 100)}}],
         "fmax_max_mhz": 70.0, "fmax_median_mhz": 70.0,
         "xc7": {"LUT": 10, "FF": 20, "BRAM36": 1.5, "RAMB36E1": 1, "RAMB18E1": 1, "DSP48E1": 2, "CARRY4": 3,
                 "LUTRAM": 4, "SRL": 5}}
    assert "| c | 1 | 2 | 3 | 4 | 5 | 6 | 70.0 | 70.0 | 70.0 | yes: 10 % / 2 % / 0 % / 0 % |" in synth.ecp5_table([s])
    assert "1.5 (1 + 1/2)" in synth.xc7_table([s])
    assert "1,006 / 1,320 / 7.6 / 1.4" in synth.vitis_table([s])
    json.dumps(s)


# ----------------------------------------------------------------------------- Lattice Nexus
def test_nexus_counts_classify_cells():
    from mstrack.hw import hdl
    cells = {"LUT4": 10, "WIDEFN9": 2, "FD1P3IX": 7, "FD1P3JX": 1, "FD1P3DX": 2, "CCU2": 5, "DP16K": 1,
             "PDPSC16K": 3, "PDP16K": 1, "SP16K": 1, "DPSC512K": 1, "MULT18X18": 2, "MULTPREADD18X18": 1,
             "MULT9X9": 2, "IB": 4, "OB": 1, "VLO": 1, "DPR16X4": 6}
    c = hdl.nexus_counts(cells)
    assert c == {"LUT4": 10, "FF": 10, "CCU2": 5, "EBR": 6, "LRAM": 1, "MULT": 4.0, "WIDEFN9": 2, "DPR16X4": 6}


def test_nexus_fix_carry_in_disconnects_only_constant_zero(tmp_path):
    from mstrack.hw import hdl
    net = {"modules": {"top": {"cells": {
        "lo": {"type": "VLO", "connections": {"Z": [2]}, "port_directions": {"Z": "output"}},
        "hi": {"type": "VHI", "connections": {"Z": [3]}, "port_directions": {"Z": "output"}},
        "c0": {"type": "CCU2", "connections": {"CIN": [2], "COUT": [4]}},   # chain start tied to VLO
        "c1": {"type": "CCU2", "connections": {"CIN": [4], "COUT": [5]}},   # inside the chain
        "c2": {"type": "CCU2", "connections": {"CIN": [3], "COUT": [6]}},   # VHI: must stay
        "l": {"type": "LUT4", "connections": {"A": [2], "Z": [7]}},          # other users of the VLO stay
    }}}}
    src, dst = tmp_path / "in.json", tmp_path / "out.json"
    src.write_text(json.dumps(net))
    assert hdl.nexus_fix_carry_in(src, dst) == 1
    cells = json.loads(dst.read_text())["modules"]["top"]["cells"]
    assert cells["c0"]["connections"]["CIN"] == ["x"]
    assert cells["c1"]["connections"]["CIN"] == [4] and cells["c2"]["connections"]["CIN"] == [3]
    assert cells["l"]["connections"]["A"] == [2]


def test_nexus_table_row():
    s = {"config": "default",
         "nexus": {"LUT4": 5178, "FF": 12241, "CCU2": 3381, "EBR": 44, "LRAM": 0, "MULT": 6.0, "WIDEFN9": 1596,
                   "DPR16X4": 168},
         "nexus_pnr": [{"fmax_mhz": 70.12, "utilization": {"OXIDE_COMB": (9000, 32000), "OXIDE_FF": (12000, 32000),
                                                           "OXIDE_EBR": (44, 84)}},
                       {"fmax_mhz": 71.5, "utilization": {}}],
         "nexus_fmax_max_mhz": 71.5, "nexus_fmax_median_mhz": 70.81}
    t = synth.nexus_table([s]).splitlines()
    assert len(t) == 3 and t[0].count("|") == t[2].count("|")
    row = t[2]
    assert "| 5,178 | 12,241 | 3,381 | 44 | 0 | 6 | 168 | 70.1 / 71.5 | 71.5 | 70.8 |" in row
    assert row.endswith("yes: 28 % / 38 % / 52 % / 0 % |")


# ----------------------------------------------------------------------------- core v2
def test_v2_config_has_v2_generics_and_wrapper():
    """Configuration "v2": ms_tracker_v2 with CoreConfigV2's generics, placed through ms_tracker_pins with
    PRESET 1; the one pins wrapper has exactly ms_tracker's generics (every one passed through, the same
    defaults), so every generic the flow sets exists on it; the paper configurations unchanged."""
    import re

    from mstrack.fixed import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import TrackerParams
    c = synth.CONFIGS["v2"]
    assert c.v2 and c.core == "ms_tracker_v2" and c.pins_top == "ms_tracker_pins"
    g = c.generics()
    assert g == CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).generics()
    assert g["RESULT_W"] == 160 and g["REGION_MAX"] == 256 and g["STRIDE"] == 64 and g["FEATURES"] == 1
    d = synth.CONFIGS["default"]
    assert (d.core, d.pins_top) == ("ms_tracker", "ms_tracker_pins") and "RESULT_W" in d.generics()
    assert d.generics()["RESULT_W"] != 160
    assert c.pins_generics() == CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).tracker_generics()
    assert d.pins_generics() == d.generics() and "PRESET" not in d.generics()
    srcs = synth.pins_sources(c.pins_top)
    assert srcs[-1] == synth.PINS_VHD and {"ms_tracker.vhd", "ms_tracker_v2.vhd"} <= {p.name for p in srcs}

    core = _wrapper_passes_every_generic("ms_tracker", "PRESET", synth.PINS_VHD, "ms_tracker_pins")
    engine = {n for n, _ in _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_v2.vhd", "ms_tracker_v2")}
    assert set(c.pins_generics()) <= {n for n, _ in core} and set(g) <= engine


def _vhdl_generics(path, entity) -> list[tuple[str, str]]:
    """(name, type and default) of each generic of *entity* in *path*, comments and spacing left out."""
    import re
    t = path.read_text()
    t = t[t.index(f"entity {entity} is"):]
    t = re.sub(r"--[^\n]*", "", t[t.index("generic ("):t.index("  port (")])
    return [(n, " ".join(d.split())) for n, d in re.findall(r"^\s+(\w+)\s*:([^;]*?)\s*(?:;|\)\s*;?\s*$)", t, re.M)]


def _wrapper_passes_every_generic(core: str, first: str, wrapper_vhd, wrapper: str,
                                  more: int = 0) -> list[tuple[str, str]]:
    """Assert that pin wrapper *wrapper* has exactly the generics of rtl/<core>.vhd (the first one *first*)
    and then *more* of its own, and maps each of the core's by name; returns the core's generics."""
    import re
    gen = _vhdl_generics(synth.REPO_ROOT / "rtl" / f"{core}.vhd", core)
    assert len(gen) > 70 and gen[0][0] == first
    wg = _vhdl_generics(wrapper_vhd, wrapper)
    assert wg[:len(gen)] == gen and len(wg) == len(gen) + more
    body = wrapper_vhd.read_text()
    assert all(re.search(rf"^\s+{n}\s+=> {n}\b", body, re.M) for n, _ in gen)
    return gen


def test_multi_pins_wrapper_passes_every_generic():
    """rtl/wrappers/ms_tracker_multi_pins.vhd has ms_tracker_multi's generics (names, types, defaults), then
    SHARED_ENGINE and ms_tracker_shared's own (test_multi_pins_wrapper_passes_every_shared_generic), and
    passes each on by name, so the placed core is the one `mstrack synth` counts."""
    shared = _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_shared.vhd", "ms_tracker_shared")
    multi = _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_multi.vhd", "ms_tracker_multi")
    _wrapper_passes_every_generic("ms_tracker_multi", "MAX_TARGETS", synth.MULTI_PINS_VHD, "ms_tracker_multi_pins",
                                  more=1 + len(shared) - len(multi))


def test_v2_configs_are_the_v2_trackers():
    """Configuration "v2": ms_tracker_v2 with the generics of tracker v2's default parameters (mstrack-v2:
    ORIENT_T 64, the gated scale test SCALE_TEST_D256 13; the VHDL defaults of ms_tracker_pins, which
    nextpnr places); "v2-colour": those of mstrack-v2-colour (V2_COLOUR: ORIENT_T -1, SCALE_TEST_D256 0)."""
    import re

    from mstrack.fixed import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import V2_COLOUR, TrackerParams
    c = synth.CONFIGS["v2"]
    assert c.v2 and c.pins_top == "ms_tracker_pins"
    g = c.generics()
    tp = TrackerParams(preset="v2", orient_T=64, scale_test=0.05, scale_test_gate=True, loss_rho=0.69,
                       loss_contrast=0.25)
    assert g == CoreConfigV2(tp, FixedParams()).generics()
    assert g["ORIENT_T"] == 64 and g["SCALE_TEST_D256"] == 13 and g["REGION_MAX"] == 256
    col = synth.CONFIGS["v2-colour"]
    assert col.v2 and col.generics() == CoreConfigV2(TrackerParams(preset="v2", **V2_COLOUR), FixedParams()).generics()
    assert col.generics()["ORIENT_T"] == -1 and col.generics()["SCALE_TEST_D256"] == 0
    body = synth.PINS_VHD.read_text()
    assert re.search(r"^\s+ORIENT_T\s*: integer range -1 to 2047 := 64", body, re.M)


@pytest.mark.parametrize("name,n", [("multi4-colour", 4), ("multi3-colour", 3), ("multi1-colour", 1),
                                    ("multi8-colour", 8), ("multi10-colour", 10), ("multi16-colour", 16)])
def test_multi_colour_configs_are_colour_engines(name, n):
    """Configurations "multi4-colour" / "multi3-colour": ms_tracker_multi with MAX_TARGETS 4 / 3 and the
    generics of "v2-colour" (each engine is core v2 of mstrack-v2-colour), placed through its own pin
    wrapper (ms_tracker_multi_pins); a plain `mstrack synth` leaves them out.  The other configurations
    synthesise their own core as before."""
    import argparse
    import re

    from mstrack.fixed import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import V2_COLOUR, TrackerParams
    multi = ("multi4-colour", "multi3-colour", "multi1-colour", "multi8-colour", "multi10-colour", "multi16-colour")
    m = synth.CONFIGS[name]
    assert (m.top, m.core, m.max_targets) == ("ms_tracker_multi", "ms_tracker_v2", n) and m.v2 and m.placeable
    assert m.pins_top == "ms_tracker_multi_pins" and m.pins_generics() == m.generics()
    assert synth.pins_sources(m.pins_top)[-1] == synth.MULTI_PINS_VHD
    g = m.generics()
    colour = CoreConfigV2(TrackerParams(preset="v2", **V2_COLOUR), FixedParams(), lanes=4, max_frame_w=2048).generics()
    assert g == {"MAX_TARGETS": n, **colour} == {"MAX_TARGETS": n, **synth.CONFIGS["v2-colour"].generics()}
    assert list(g)[0] == "MAX_TARGETS" and g["ORIENT_T"] == -1 and g["SCALE_TEST_D256"] == 0
    # every generic is one of ms_tracker_multi's (MAX_TARGETS + those of ms_tracker_v2)
    t = (synth.REPO_ROOT / "rtl" / "ms_tracker_multi.vhd").read_text()
    t = re.sub(r"--[^\n]*", "", t[t.index("entity ms_tracker_multi is"):])
    t = t[t.index("generic ("):t.index("  port (")]
    names = set(re.findall(r"^\s+(\w+)\s*:", t, re.M))
    assert "MAX_TARGETS" in names and set(g) <= names
    assert "ms_tracker_multi.vhd" in {p.name for p in synth.sources(m.top)}
    shared = tuple(c for c in synth.CONFIGS if c.startswith("shared"))
    for other, c in synth.CONFIGS.items():
        if other not in multi + shared:
            assert c.top == c.core and c.placeable and "MAX_TARGETS" not in c.generics()
            assert c.pins_top == "ms_tracker_pins"
    assert synth.DEFAULT_CONFIGS == tuple(c for c in synth.CONFIGS if c not in multi + shared)
    ap = argparse.ArgumentParser()
    synth.add_arguments(ap)
    assert ap.parse_args([]).config == list(synth.DEFAULT_CONFIGS)
    assert ap.parse_args(["--config", name]).config == [name]
    # the Vitis comparison counts its MAX_TARGETS targets (a single-target core: 1, figures as before)
    x = {"LUT": 40000, "FF": 50000, "BRAM36": 92.0, "DSP48E1": 8}
    rows = synth.vitis_table([{"config": "multi4-colour", "xc7": x, "generics": synth.CONFIGS["multi4-colour"].generics()},
                              {"config": "v2-colour", "xc7": x, "generics": synth.CONFIGS["v2-colour"].generics()}])
    assert "| mstrack multi4-colour (xc7, yosys) | 4 | 40,000 | 50,000 | 92 | 8 | 10,000 / 12,500 / 23.0 / 2.0 |" in rows
    assert "| mstrack v2-colour (xc7, yosys) | 1 | 40,000 | 50,000 | 92 | 8 | 40,000 / 50,000 / 92 / 8 |" in rows
    assert "per added target" not in rows
    # beside the one-slot core, the cost of an added target: (core(N) - core(1)) / (N - 1)
    one = {"LUT": 12000, "FF": 13000, "BRAM36": 23.0, "DSP48E1": 2}
    eight = {"LUT": 89000, "FF": 97000, "BRAM36": 184.0, "DSP48E1": 16}
    rows = synth.vitis_table([{"config": c, "xc7": x, "generics": synth.CONFIGS[c].generics()}
                              for c, x in (("multi1-colour", one), ("multi4-colour", x), ("multi8-colour", eight))])
    assert ("| mstrack per added target: (multi8-colour - multi1-colour) / 7 | 1 | 11,000 | 12,000 | 23.0 | 2.0 | "
            "11,000 / 12,000 / 23.0 / 2.0 |") in rows
    assert "| mstrack per added target: (multi4-colour - multi1-colour) / 3 | 1 | 9,333 | 12,333 | 23.0 | 2.0 |" in rows
    assert rows.index("(multi4-colour - multi1-colour)") < rows.index("(multi8-colour - multi1-colour)")


def test_multi_pins_wrapper_passes_every_shared_generic():
    """rtl/wrappers/ms_tracker_multi_pins.vhd has, after ms_tracker_multi's generics, SHARED_ENGINE and
    ms_tracker_shared's own (names, types, defaults), and passes every generic of ms_tracker_shared on by
    name in its SHARED_ENGINE branch, so the placed shared core is the one `mstrack synth` counts."""
    import re
    multi = _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_multi.vhd", "ms_tracker_multi")
    shared = _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_shared.vhd", "ms_tracker_shared")
    own = [g for g in shared if g[0] not in {n for n, _ in multi}]
    assert own and own[0][0] == "RD_LAT" and [g for g in shared if g not in own] == multi
    wrapper = _vhdl_generics(synth.MULTI_PINS_VHD, "ms_tracker_multi_pins")
    assert wrapper[:len(multi)] == multi and wrapper[len(multi)][0] == "SHARED_ENGINE"
    assert wrapper[len(multi) + 1:] == own
    body = synth.MULTI_PINS_VHD.read_text()
    branch = body[body.index("g_shared : if SHARED_ENGINE generate"):]
    assert all(re.search(rf"^\s+{n}\s+=> {n}\b", branch, re.M) for n, _ in shared)


@pytest.mark.parametrize("n", [1, 2, 4, 5, 8, 10, 16])
def test_shared_colour_configs_are_the_simulated_core(n):
    """Configurations "shared<N>-colour": ms_tracker_shared with MAX_TARGETS N and the generics its test bench
    simulates it with (tb/test_ms_tracker_shared.py generics_of: the v2-colour engine, MAX_FRAME_W 2048, the
    capacity rule at 1080p60), placed through ms_tracker_multi_pins with SHARED_ENGINE; only when named with
    --config.  Every generic is one of the entity's."""
    import argparse

    from mstrack.track.params import V2_COLOUR
    c = synth.CONFIGS[f"shared{n}-colour"]
    assert (c.top, c.core, c.max_targets) == ("ms_tracker_shared", "ms_tracker_v2", n) and c.v2 and c.placeable
    assert c.pins_top == "ms_tracker_multi_pins" and c.pins_generics() == {**c.generics(), "SHARED_ENGINE": True}
    assert synth.pins_sources(c.pins_top)[-1] == synth.MULTI_PINS_VHD
    assert "ms_tracker_shared.vhd" in {p.name for p in synth.sources(c.top)}
    g = c.generics()
    tb = _tb_generics_of({"slots": n, "max_frame_w": 2048, "timing": [1080, 1125, 2200], "tp": V2_COLOUR})
    assert g == tb and list(g)[0] == "MAX_TARGETS" and g["MAX_TARGETS"] == n
    assert g["ORIENT_T"] == -1 and (g["FRAME_LINES"], g["ACTIVE_LINES"], g["LINE_CLOCKS"]) == (1125, 1080, 2200)
    assert {k: v for k, v in g.items() if k in synth.CONFIGS["v2-colour"].generics()} == \
        synth.CONFIGS["v2-colour"].generics()
    names = {n for n, _ in _vhdl_generics(synth.REPO_ROOT / "rtl" / "ms_tracker_shared.vhd", "ms_tracker_shared")}
    assert set(g) <= names
    assert c.name not in synth.DEFAULT_CONFIGS
    ap = argparse.ArgumentParser()
    synth.add_arguments(ap)
    assert ap.parse_args(["--config", c.name]).config == [c.name]


@pytest.mark.parametrize("n", [1, 4, 8, 10, 14])
def test_shared_w63_configs_are_the_simulated_core(n):
    """Configurations "shared<N>-colour-w63": ms_tracker_shared with the generics tb/test_ms_tracker_shared.py's
    generics_of gives tracker v2-colour with max_window 63, MAX_HALF 31 and COORD_W 11 (test_shared_w63_real_people
    runs them on real frames at MAX_FRAME_W 1024), MAX_FRAME_W 1920: a slot of 160 rows of 40 words, the
    rule at 1080p60."""
    from mstrack.track.params import V2_COLOUR
    c = synth.CONFIGS[f"shared{n}-colour-w63"]
    assert (c.top, c.max_targets, c.max_frame_w) == ("ms_tracker_shared", n, 1920) and c.placeable
    g = c.generics()
    tb = _tb_generics_of({"slots": n, "max_frame_w": 1920, "timing": [1080, 1125, 2200],
                          "tp": {**V2_COLOUR, "max_window": 63}, "fp": {"max_half": 31, "coord_bits": 11}})
    assert g == tb
    assert (g["MAX_WINDOW"], g["MAX_HALF"], g["COORD_W"], g["REGION_MAX"], g["STRIDE"]) == (63, 31, 11, 160, 40)
    assert c.name not in synth.DEFAULT_CONFIGS


def _tb_generics_of(job: dict) -> dict:
    """tb/test_ms_tracker_shared.py's generics_of, read from its source (the bench imports cocotb)."""
    import ast

    src = (synth.REPO_ROOT / "tb" / "test_ms_tracker_shared.py").read_text()
    tree = ast.parse(src)
    keep = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in ("params_of", "generics_of")]
    from mstrack.fixed import FixedParams
    from mstrack.fixed.multi_capacity import MultiCoreConfig, VideoTiming
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.hw.multi_core import job_demand_generics
    from mstrack.track.params import TrackerParams
    ns = {"TrackerParams": TrackerParams, "FixedParams": FixedParams, "MultiCoreConfig": MultiCoreConfig,
          "VideoTiming": VideoTiming, "CoreConfigV2": CoreConfigV2, "job_demand_generics": job_demand_generics}
    exec(compile(ast.Module(body=keep, type_ignores=[]), "tb/test_ms_tracker_shared.py", "exec"), ns)  # noqa: S102
    return ns["generics_of"](job)


def test_vitis_table_per_target_of_each_core():
    """The per-target rows ((core(N) - core(1)) / (N - 1)) pair each multi-target core with its own N = 1 (or its
    smallest N synthesised)."""
    one_m = {"LUT": 12000, "FF": 13000, "BRAM36": 23.0, "DSP48E1": 2}
    eight_m = {"LUT": 89000, "FF": 97000, "BRAM36": 184.0, "DSP48E1": 16}
    one_s = {"LUT": 14000, "FF": 15000, "BRAM36": 30.0, "DSP48E1": 2}
    eight_s = {"LUT": 21000, "FF": 22000, "BRAM36": 100.0, "DSP48E1": 2}
    rows = synth.vitis_table([{"config": c, "xc7": x, "generics": synth.CONFIGS[c].generics()}
                              for c, x in (("multi1-colour", one_m), ("multi8-colour", eight_m),
                                           ("shared1-colour", one_s), ("shared8-colour", eight_s))])
    assert ("| mstrack per added target: (multi8-colour - multi1-colour) / 7 | 1 | 11,000 | 12,000 | 23.0 | 2.0 |"
            in rows)
    assert ("| mstrack per added target: (shared8-colour - shared1-colour) / 7 | 1 | 1,000 | 1,000 | 10.0 | 0.0 |"
            in rows)
    assert "(shared8-colour - multi1-colour)" not in rows and "(multi8-colour - shared1-colour)" not in rows
    # without the one-slot configuration, beside the smallest one synthesised: (core(N) - core(M)) / (N - M)
    two_s = {"LUT": 15000, "FF": 16000, "BRAM36": 40.0, "DSP48E1": 2}
    rows = synth.vitis_table([{"config": c, "xc7": x, "generics": synth.CONFIGS[c].generics()}
                              for c, x in (("shared2-colour", two_s), ("shared8-colour", eight_s))])
    assert ("| mstrack per added target: (shared8-colour - shared2-colour) / 6 | 1 | 1,000 | 1,000 | 10.0 | 0.0 |"
            in rows)


def test_ghdl_zero_width_index_wires_dropped():
    """GHDL 2.0's Verilog of a dynamic index into a one-element array (ms_tracker_shared with MAX_TARGETS 1):
    the offset's wires, which nothing reads, are dropped; a read of one is refused."""
    from mstrack.hw import hdl
    v = ('module m (input a, output y);\n  wire n1_o;\n  wire n2_o;\n  wire n3_o;\n'
         '  assign n1_o = "";  // trunc\n  /* x.vhd:1:2  */\n  assign n2_o = 0\'b - n1_o;\n'
         '  assign n3_o = a;\n  assign y = n3_o;\nendmodule\n')
    out, n = hdl.fix_ghdl_zero_width(v)
    assert n == 2 and "n1_o" not in out and "n2_o" not in out and "assign y = n3_o;" in out
    assert hdl.fix_ghdl_zero_width(out) == (out, 0)
    with pytest.raises(hdl.HdlError, match="n2_o"):
        hdl.fix_ghdl_zero_width(v.replace("assign y = n3_o;", "assign y = n2_o;"))


def test_write_section_keeps_rows_of_other_configs(tmp_path):
    """--write of one configuration keeps the other configurations' rows (and says where they came from);
    a row of the same configuration is replaced; without keep_rows the table is replaced whole."""
    p = tmp_path / "perf.md"
    synth.write_section("RTL: r1.\n\n| config | n |\n|---|---|\n| default | 1 |\n| v2 | 0 |", "x",
                        "mstrack synth --config default v2", p, tools="Tools: t1.")
    synth.write_section("RTL: r2.\n\n| config | n |\n|---|---|\n| v2 | 2 |", "x", "mstrack synth --config v2", p,
                        tools="Tools: t2.", keep_rows=True)
    text = p.read_text()
    assert "| default | 1 |\n| v2 | 2 |" in text and "| v2 | 0 |" not in text
    assert ("Rows kept from an earlier run (default): Command: `mstrack synth --config default v2` "
            "Tools: t1. RTL: r1.") in text
    assert "Command: `mstrack synth --config v2`" in text and text.index("RTL: r2.") < text.index("| config |")
    synth.write_section("RTL: r3.\n\n| config | n |\n|---|---|\n| v2 | 3 |", "x", "mstrack synth --config v2", p,
                        tools="Tools: t3.", keep_rows=True)
    text = p.read_text()
    assert "| default | 1 |\n| v2 | 3 |" in text and text.count("Rows kept from an earlier run (default)") == 1
    assert "RTL: r1." in text and "RTL: r2." not in text
    synth.write_section("RTL: r4.\n\n| config | n |\n|---|---|\n| v2 | 4 |", "x", "mstrack synth --config v2", p)
    assert "| default |" not in p.read_text()


def test_cycle_table_skips_core_v2(capsys):
    """The analytic cycle model is the paper core's: `mstrack synth --cycles` lists no v2 row."""
    assert synth.main(["--cycles", "--config", "default", "v2"]) == 0
    out = capsys.readouterr().out
    assert "| default | 64x64" in out and "| v2 |" not in out


def test_write_section_replaces_kept_table_rows_in_place(tmp_path):
    p = tmp_path / "perf.md"
    synth.write_section("RTL: r1.\n\n| design | n |\n|---|---|\n| ref | 0 |\n| a | 1 |", "x", "c1", p, tools="T1.")
    synth.write_section("RTL: r2.\n\n| design | n |\n|---|---|\n| ref | 0 |\n| b | 2 |", "x", "c2", p, tools="T2.",
                        keep_rows=True)
    assert "| ref | 0 |\n| a | 1 |\n| b | 2 |\n\n<!-- perf-x:end -->" in p.read_text()


def test_speed_grade_selection(tmp_path, monkeypatch):
    """ECP5 speed grade: nextpnr gets --speed only off its default grade 6, every ECP5 run gets the
    flow's NEXTPNR_ECP5_OPTS, the files and summaries of another grade carry _g<speed>,
    a grade nextpnr-ecp5 does not model is refused before any tool runs, and the CLI takes --speed."""
    assert synth.SPEED == 6 and synth.CI_SPEED in synth.SPEEDS == (6, 7, 8)
    with pytest.raises(ValueError, match="speed grade 9"):
        synth.run_nextpnr(tmp_path, seed=1, speed=9)
    assert synth._gtag(6) == "" and synth._gtag(8) == "_g8"
    calls = []

    def fake_run(cmd, log, cwd, name):
        calls.append(cmd)
        rep = cmd[cmd.index("--report") + 1]
        (tmp_path / rep).write_text(json.dumps({"fmax": {"clk": {"achieved": 150.0}}, "utilization": {},
                                                "critical_paths": []}))
        return 1.0

    from mstrack.hw import hdl
    monkeypatch.setattr(hdl, "_run", fake_run)
    monkeypatch.setattr(hdl, "_tool", lambda name: name)
    (tmp_path / "yosys.stamp").write_text("x")
    r8 = synth.run_nextpnr(tmp_path, seed=1, speed=8)
    r6 = synth.run_nextpnr(tmp_path, seed=1)
    assert calls[0][calls[0].index("--speed") + 1] == "8" and "--speed" not in calls[1]
    assert all(" ".join(synth.NEXTPNR_ECP5_OPTS) in " ".join(c) for c in calls)
    assert (tmp_path / "report_s1_g8.json").is_file() and (tmp_path / "report_s1.json").is_file()
    assert (r8["speed"], r6["speed"], r8["fmax_mhz"]) == (8, 6, 150.0)
    import argparse
    ap = argparse.ArgumentParser()
    synth.add_arguments(ap)
    assert ap.parse_args(["--speed", "8"]).speed == 8 and ap.parse_args([]).speed == 6
    with pytest.raises(SystemExit):
        ap.parse_args(["--speed", "5"])


@pytest.mark.parametrize("config", ["default", "v2-colour", "multi1-colour", "multi3-colour", "multi8-colour"])
def test_nexus_pdc_places_every_pin_of_its_wrapper(config):
    """nextpnr-nexus refuses an unconstrained I/O: the PDC that synth_config gives a configuration's pin
    wrapper (ms_tracker_pins for both presets, ms_tracker_multi_pins for N targets) gives every port bit
    a site, no site twice, and names no port the wrapper does not have."""
    import re
    cfg = synth.CONFIGS[config]
    want = synth.wrapper_ports(synth.MULTI_PINS_VHD if cfg.top == synth.TOP_MULTI else synth.PINS_VHD,
                               cfg.pins_generics())
    assert {"clk", "s_axis_tdata[23]", "res_dout"} <= want and "s_axis_tdata[24]" not in want
    # 37 pins for the single-target wrapper (docs/performance.md); the multi-target one has 45 + N
    # (46 I/Os in the multi1-colour LIFCL-40 run)
    assert len(want) == (45 + cfg.max_targets if cfg.top == synth.TOP_MULTI else 37)
    live = "live" if cfg.max_targets == 1 else "live[%d]" % (cfg.max_targets - 1)   # one bit: a scalar port
    assert (live in want) == (cfg.top == synth.TOP_MULTI)
    got = re.findall(r"ldc_set_location -site \{(\w+)\} \[get_ports \{?([\w\[\]]+)\}?\]", synth.nexus_pdc(cfg))
    assert {p for _, p in got} == want
    assert len({s for s, _ in got}) == len(got)


def test_load_summary_takes_the_ecp5_run_then_one_without_it(tmp_path, monkeypatch):
    """--from-summaries finds a configuration's summary whether or not its run had ECP5: the full run's
    first, then an xc7-only or Nexus-only run's (saved beside it, not over it)."""
    import json
    monkeypatch.setattr(synth, "SYNTH_DIR", tmp_path)
    assert synth.load_summary("multi8-colour") is None
    (tmp_path / "summary_multi8-colour_xc7.json").write_text(json.dumps({"config": "multi8-colour", "run": "xc7"}))
    assert synth.load_summary("multi8-colour")["run"] == "xc7"
    (tmp_path / "summary_multi8-colour.json").write_text(json.dumps({"config": "multi8-colour", "run": "all"}))
    assert synth.load_summary("multi8-colour")["run"] == "all"
    assert synth.load_summary("multi8-colour", speed=8) is None


def test_write_section_keeps_notes_of_rows_named_with_parentheses(tmp_path):
    """Row names such as "mstrack v2 (xc7, yosys)" hold parentheses and commas: a third --write still
    credits each kept row to the run that made it."""
    p = tmp_path / "perf.md"
    t = "| design | n |\n|---|---|\n"
    synth.write_section("RTL: r1.\n\n" + t + "| mstrack a (xc7, yosys) | 1 |", "v", "cmd a", p, tools="Tools: t1.")
    synth.write_section("RTL: r2.\n\n" + t + "| mstrack b (xc7, yosys) | 2 |", "v", "cmd b", p, tools="Tools: t2.",
                        keep_rows=True)
    synth.write_section("RTL: r3.\n\n" + t + "| mstrack c (xc7, yosys) | 3 |", "v", "cmd c", p, tools="Tools: t3.",
                        keep_rows=True)
    text = p.read_text()
    assert "Rows kept from an earlier run (mstrack a (xc7, yosys)): Command: `cmd a` Tools: t1. RTL: r1." in text
    assert "Rows kept from an earlier run (mstrack b (xc7, yosys)): Command: `cmd b` Tools: t2. RTL: r2." in text
    assert "| mstrack a (xc7, yosys) | 1 |\n| mstrack b (xc7, yosys) | 2 |\n| mstrack c (xc7, yosys) | 3 |" in text
