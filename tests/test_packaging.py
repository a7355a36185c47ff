"""Generated packaging files are current: rtl/files.txt, mstrack.core, tb/vhdl/data/ (mstrack.hw.packaging).

Regenerate with ``mstrack hdl files``.  The FuseSoC targets themselves run in
tb/test_ms_tracker_file_tb.py (test_fusesoc_target: sim, lint; test_fusesoc_synth_target: synth).
"""
from __future__ import annotations

from pathlib import Path

import pytest

from mstrack.hw import packaging
from mstrack.hw.hdl import REPO_ROOT, rtl_sources


@pytest.mark.parametrize("path", sorted(packaging.generated(), key=str), ids=lambda p: p.name)
def test_generated_file_is_current(path):
    want = packaging.generated()[path]
    assert path.is_file(), f"{path} missing: run `mstrack hdl files`"
    assert path.read_text() == want, f"{path} is stale: run `mstrack hdl files`"


def test_files_txt_is_the_compile_order():
    lines = [ln for ln in packaging.FILES_TXT.read_text().splitlines() if ln and not ln.startswith("#")]
    # the paper core's top, core v2's (ms_tracker_v2) and the multi-target core's, with every block they use
    assert lines == [p.relative_to(REPO_ROOT).as_posix() for p in rtl_sources("ms_tracker", "ms_tracker_v2", "ms_tracker_multi")]
    assert all((REPO_ROOT / f).is_file() for f in lines)
    assert lines[-1] == "rtl/ms_tracker_multi.vhd" and lines.index("rtl/ms_tracker_v2.vhd") < len(lines) - 1
    assert "rtl/ms_tracker.vhd" in lines
    assert all(Path(f).name.startswith("ms_") for f in lines)


def test_core_file_lists_the_same_files():
    yaml = pytest.importorskip("yaml")
    core = yaml.safe_load(packaging.CORE_FILE.read_text().split("\n", 1)[1])   # after "CAPI=2:"
    assert core["name"] == packaging.CORE_NAME
    assert core["filesets"]["rtl"]["files"] == packaging.core_files()
    assert set(core["targets"]) == {"default", "sim", "lint", "synth", "synth_v2"}
    assert core["targets"]["sim"]["toplevel"] == "ms_tracker_file_tb"
    # synth: every generate entry names a generator of this core whose script exists
    for name in core["targets"]["synth"]["generate"] + core["targets"]["synth_v2"]["generate"]:
        gen = core["generators"][core["generate"][name]["generator"]]
        assert (REPO_ROOT / gen["command"]).is_file() and REPO_ROOT / gen["command"] == packaging.GENERATOR_SCRIPT
    assert core["targets"]["synth"]["tools"]["yosys"]["arch"] == "ecp5"
    # synth_v2: core v2, ms_tracker with PRESET 1 (the generator's preset parameter)
    (v2gen,) = core["targets"]["synth_v2"]["generate"]
    assert core["generate"][v2gen]["parameters"] == {"toplevel": "ms_tracker", "vendor": "ecp5", "preset": "v2"}
    assert core["targets"]["synth_v2"]["toplevel"] == "ms_tracker"


def test_check_mode_reports_stale(tmp_path, monkeypatch):
    monkeypatch.setattr(packaging, "FILES_TXT", tmp_path / "files.txt")
    stale = packaging.write_generated(check=True)
    assert stale == [tmp_path / "files.txt"] and not (tmp_path / "files.txt").exists()


def test_verilog_generator_writes_core(tmp_path):
    """The synth target's generator alone (FuseSoC GAPI 1.0 input -> <top>.v + a core naming it), with generics."""
    yaml = pytest.importorskip("yaml")
    from mstrack.hw.hdl import have_ghdl
    if not have_ghdl():
        pytest.skip("ghdl not installed (tools/setup.sh)")
    inp = tmp_path / "in.yml"
    inp.write_text(yaml.safe_dump({"gapi": "1.0", "vlnv": "x:y:ms_fifo-gen:1", "files_root": str(REPO_ROOT),
                                   "parameters": {"toplevel": "ms_fifo", "generics": {"WIDTH": 5, "DEPTH": 4}}}))
    core = packaging.run_verilog_generator(inp, tmp_path)
    c = yaml.safe_load(core.read_text().split("\n", 1)[1])
    assert c["name"] == "x:y:ms_fifo-gen:1" and c["targets"]["default"]["toplevel"] == "ms_fifo"
    (v,) = c["filesets"]["verilog"]["files"]
    text = (tmp_path / v).read_text()
    assert "module ms_fifo" in text and "[4:0]" in text      # WIDTH 5 baked in
    with pytest.raises(ValueError, match="not a FuseSoC generator input"):
        packaging.run_verilog_generator(tmp_path / "ms_fifo.v.hash", tmp_path)


def test_verilog_generator_preset_v2(tmp_path, monkeypatch):
    """The generator's ``preset: v2`` converts ms_tracker with core v2's generics (PRESET 1,
    CoreConfigV2.tracker_generics), explicit ``generics`` over them; an unknown preset is refused.
    ghdl_to_verilog is replaced (the PRESET 1 netlist itself is built by the Verilator runs of core v2)."""
    yaml = pytest.importorskip("yaml")
    from mstrack.fixed import FixedParams
    from mstrack.hw import hdl
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import TrackerParams
    seen = {}

    def fake(top, generics, srcs, out_path):
        seen.update(top=top, generics=generics, srcs=[p.name for p in srcs])
        out_path.write_text(f"module {top}; endmodule\n")
        return out_path

    monkeypatch.setattr(hdl, "ghdl_to_verilog", fake)
    inp = tmp_path / "in.yml"
    inp.write_text(yaml.safe_dump({"gapi": "1.0", "vlnv": "x:y:v2-gen:1", "files_root": str(REPO_ROOT),
                                   "parameters": {"toplevel": "ms_tracker", "preset": "v2",
                                                  "generics": {"MAX_FRAME_W": 1920}}}))
    packaging.run_verilog_generator(inp, tmp_path)
    want = {**CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).tracker_generics(), "MAX_FRAME_W": 1920}
    assert seen["top"] == "ms_tracker" and seen["generics"] == want and want["PRESET"] == 1
    assert "ms_tracker_v2.vhd" in seen["srcs"]
    inp.write_text(yaml.safe_dump({"gapi": "1.0", "vlnv": "x:y:v2-gen:1", "parameters": {"preset": "v3"}}))
    with pytest.raises(ValueError, match="preset 'v3' unknown"):
        packaging.run_verilog_generator(inp, tmp_path)
