"""The standalone VHDL testbench tb/vhdl/ms_tracker_file_tb.vhd (no cocotb, no Python while simulating),
the RGB packings, the generic checks of ms_tracker and the FuseSoC targets.

* every result word the testbench writes equals the fixed-point model's (mstrack.hw.tb_files writes
  the frames and the expected words; the testbench compares too and must say PASSED);
  a synthetic scene at full speed and throttled, both RGB packings (same frames, same words),
  a stretch of a real sequence with the default generics;
* ``mstrack hdl config`` output elaborates in GHDL for several choices (the RTL's generic checks
  agree with the Python derivation), and a deliberately wrong derived generic is refused with
  its one-line message;
* ``fusesoc run --target sim`` passes and ``--target lint`` elaborates.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mstrack.hw.cosim import CoreConfig
from mstrack.fixed import FixedParams
from mstrack.track.params import TrackerParams

pytestmark = pytest.mark.ghdl

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
FILE_TB = REPO / "tb" / "vhdl" / "ms_tracker_file_tb.vhd"


def _sources(extra=()):
    from mstrack.hw.hdl import rtl_sources
    return rtl_sources("ms_tracker") + [FILE_TB, *extra]


def run_file_tb(tmp_path: Path, frames, box, cfg: CoreConfig, packing: int = 0, **tb_generics) -> str:
    """Write the files, run the testbench in tmp_path, check its verdict and every word."""
    from mstrack.hw.hdl import run_ghdl_plain
    from mstrack.hw.tb_files import read_words, write_tb_files
    paths = write_tb_files(tmp_path, frames, box, cfg, packing=packing)
    g = json.loads(paths["generics"].read_text())
    out = run_ghdl_plain("ms_tracker_file_tb", _sources(), {**g, **tb_generics}, build_name="ms_tracker_file_tb",
                         run_dir=tmp_path)
    assert "ms_tracker_file_tb: PASSED" in out, out[-2000:]
    got, exp = read_words(tmp_path / "results.txt"), read_words(paths["expected"])
    assert len(got) == len(frames) and got == exp
    return out


def _scene(n=4, w=64, h=48, seed=3):
    from mstrack.io.synthetic import make_scene
    frames, _ = make_scene(n, w, h, seed=seed)
    return [np.ascontiguousarray(f) for f in frames]


SMALL = CoreConfig(TrackerParams(), FixedParams(max_half=15, margin=8), lanes=4, max_frame_w=1024)


@pytest.mark.parametrize("packing", [0, 1], ids=["mstrack", "ug934"])
def test_file_tb_synthetic(packing, tmp_path):
    """Same frames in either RGB packing: the same result words, equal to the model's."""
    run_file_tb(tmp_path, _scene(), (22, 14, 14, 12), SMALL, packing=packing)


def test_file_tb_throttled(tmp_path):
    """Random tvalid gaps and result back-pressure; LANES 2, Epanechnikov kernel."""
    cfg = CoreConfig(TrackerParams(kernel="epanechnikov"), FixedParams(max_half=15, margin=8), lanes=2,
                     max_frame_w=64)
    run_file_tb(tmp_path, _scene(seed=4), (20, 12, 15, 13), cfg, PAUSE_IN_PCT=30, PAUSE_OUT_PCT=50, SEED=7)


def test_file_tb_real_sequence(tmp_path):
    """Default generics, init + 3 tracked frames of a real sequence (Girl, 128x96)."""
    seq = SEQ_ROOT / "Girl"
    if not seq.is_dir():
        pytest.skip(f"{seq} not found: the real-sequence run needs ../shared/data/sequences")
    from mstrack.io.data import load_sequence
    from mstrack.fixed.blocks import round_box
    s = load_sequence(seq)
    frames = [s.frame(i) for i in range(4)]
    box = round_box(*[float(v) for v in s.gt[0]])
    run_file_tb(tmp_path, frames, box, CoreConfig(TrackerParams(), FixedParams()))


def test_file_tb_detects_a_wrong_word(tmp_path):
    """A changed expected word makes the testbench fail (it is self-checking)."""
    from mstrack.hw.hdl import HdlError, run_ghdl_plain
    from mstrack.hw.tb_files import write_tb_files
    paths = write_tb_files(tmp_path, _scene(n=2), (22, 14, 14, 12), SMALL)
    lines = paths["expected"].read_text().splitlines()
    lines[-1] = ("f" if lines[-1][0] != "f" else "e") + lines[-1][1:]
    paths["expected"].write_text("\n".join(lines) + "\n")
    g = json.loads(paths["generics"].read_text())
    with pytest.raises(HdlError, match="FAILED: 1 mismatch"):
        run_ghdl_plain("ms_tracker_file_tb", _sources(), g, build_name="ms_tracker_file_tb", run_dir=tmp_path)


# ----------------------------------------------------------------------------- configuration
CONFIG_CASES = {
    "default": {},
    "small_l2_epan": dict(max_target=31, margin=8, lanes=2, kernel="epanechnikov"),
    "big_window": dict(max_target=511, max_frame_width=8000, coord_bits=13, kernel="epanechnikov"),
    "l1_edge_ug934": dict(lanes=1, features="edge", max_target=15, margin=0, rgb_packing="ug934"),
    "v2": dict(preset="v2", max_frame_width=1920),        # PRESET 1: core v2 (ms_tracker_v2 elaborated too)
    "v2_colour": dict(preset="v2", colour=True, max_frame_width=1920),   # mstrack-v2-colour: ORIENT_T -1
}


def _config_top(tmp_path: Path, pkg_text: str) -> list[Path]:
    """The generated package + a top that instantiates ms_tracker with its generic map."""
    pkg = tmp_path / "ms_tracker_config_pkg.vhd"
    pkg.write_text(pkg_text)
    gm = pkg_text.split("--   generic map (", 1)[1].split("--   )", 1)[0]
    gm = "generic map (" + gm.replace("\n--   ", "\n") + ")"
    top = tmp_path / "cfg_top.vhd"
    top.write_text(f"""library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use work.ms_tracker_config_pkg.all;
entity cfg_top is
end entity;
architecture a of cfg_top is
  signal clk, rst : std_logic := '0';
begin
  u_core : entity work.ms_tracker
    {gm}
    port map (clk => clk, rst => rst, frame_width => (others => '0'), frame_height => (others => '0'),
              s_init_tvalid => '0', s_init_tready => open, s_init_x => (others => '0'),
              s_init_y => (others => '0'), s_init_w => (others => '0'), s_init_h => (others => '0'),
              s_axis_tdata => (others => '0'), s_axis_tvalid => '0', s_axis_tready => open,
              s_axis_tlast => '0', s_axis_tuser => '0', m_axis_result_tdata => open,
              m_axis_result_tvalid => open, m_axis_result_tready => '1', m_axis_result_tlast => open,
              busy => open);
end architecture;
""")
    return [pkg, top]


@pytest.mark.parametrize("name", list(CONFIG_CASES))
def test_config_elaborates(name):
    """The generics `mstrack hdl config` derives pass every generic check of ms_tracker."""
    from mstrack.hw.hdl import rtl_sources, run_ghdl_plain
    from mstrack.hw.hdl_config import CoreChoices, derive
    g = derive(CoreChoices(**CONFIG_CASES[name])).generics
    run_ghdl_plain("ms_tracker", rtl_sources("ms_tracker"), g, build_name="ms_tracker_elab", elab_only=True)


def test_config_package_compiles(tmp_path):
    """The VHDL package of `mstrack hdl config` and the generic map in its header make a working instance."""
    from mstrack.hw.hdl import rtl_sources, run_ghdl_plain
    from mstrack.hw.hdl_config import CoreChoices, derive, render
    text = render(derive(CoreChoices(**CONFIG_CASES["small_l2_epan"])), "package")
    extra = _config_top(tmp_path, text)
    run_ghdl_plain("cfg_top", rtl_sources("ms_tracker") + extra, build_name="cfg_top", elab_only=True)


def test_config_package_v2_analyses(tmp_path):
    """The VHDL package of `mstrack hdl config --preset v2` (PRESET 1, LOSS_CONTRAST an integer) analyses."""
    from mstrack.hw.hdl import HdlError, have_ghdl
    from mstrack.hw.hdl_config import CoreChoices, derive, render
    if not have_ghdl():
        pytest.skip("ghdl not installed (tools/setup.sh)")
    pkg = tmp_path / "ms_tracker_config_pkg.vhd"
    pkg.write_text(render(derive(CoreChoices(preset="v2")), "package"))
    r = subprocess.run(["ghdl", "-a", "--std=08", f"--workdir={tmp_path}", str(pkg)], capture_output=True, text=True)
    if r.returncode:
        raise HdlError(r.stderr)


def test_config_axi_shared_elaborates(tmp_path):
    """`mstrack hdl config --top ms_tracker_axi --max-targets 8 --shared-engine` (the w63 choices): the
    generics elaborate ms_tracker_axi with ms_tracker_shared inside, and the package (boolean
    constants) analyses."""
    from mstrack.hw.hdl import HdlError, rtl_sources, run_ghdl_plain
    from mstrack.hw.hdl_config import BOOLEAN_GENERICS, CoreChoices, derive, render
    cfg = derive(CoreChoices(preset="v2", colour=True, max_frame_width=1920, max_target=63, coord_bits=11,
                             top="ms_tracker_axi", max_targets=8, shared_engine=True))
    g = {k: ("true" if v else "false") if k in BOOLEAN_GENERICS else v for k, v in cfg.generics.items()}
    run_ghdl_plain("ms_tracker_axi", rtl_sources("ms_tracker_axi"), g, build_name="ms_tracker_axi_elab",
                   elab_only=True)
    pkg = tmp_path / "ms_tracker_config_pkg.vhd"
    pkg.write_text(render(cfg, "package"))
    r = subprocess.run(["ghdl", "-a", "--std=08", f"--workdir={tmp_path}", str(pkg)], capture_output=True, text=True)
    if r.returncode:
        raise HdlError(r.stderr)


@pytest.mark.parametrize("generic,value,message", [
    ("REGION_W", 7, "ms_tracker: REGION_W = 7, expected bits_for(REGION_MAX) = 8"),
    ("STRIDE", 47, "ms_tracker: STRIDE = 47, expected ceil(REGION_MAX / LANES) = 48"),
    ("HIST_W", 13, "ms_tracker: HIST_W = 13, expected bits_for(window pixels x kernel maximum) = 14"),
    ("LANES", 3, "ms_tracker: LANES = 3 is not a power of two"),
    ("MAX_FRAME_W", 4096, "ms_tracker: MAX_FRAME_W = 4096 out of 3 .. 2**COORD_W - 1 = 4095"),
    ("RESULT_W", 152, "ms_tracker: RESULT_W = 152, expected PRESET 0 (the paper core): the result fields "
                      "rounded up to 8 bits = 144"),
    ("PRESET", 2, "ms_tracker: PRESET = 2 (0 the paper core, 1 core v2)"),
    ("PRESET", 1, "ms_tracker: RESULT_W = 144 but PRESET 1 (core v2) has a result word v2 of 160 bits"),
    ("PPC", 3, "ms_tracker: PPC = 3 (1, 2 or 4)"),
])
def test_wrong_generic_refused(generic, value, message):
    """Elaborating the core with one wrong generic fails with the relation it breaks."""
    from mstrack.hw.hdl import HdlError, rtl_sources, run_ghdl_plain
    from mstrack.hw.hdl_config import CoreChoices, derive
    g = {**derive(CoreChoices()).generics, generic: value}
    with pytest.raises(HdlError) as e:
        run_ghdl_plain("ms_tracker", rtl_sources("ms_tracker"), g, build_name="ms_tracker_elab", elab_only=True)
    assert message in str(e.value)
    # the right value elaborates
    run_ghdl_plain("ms_tracker", rtl_sources("ms_tracker"), derive(CoreChoices()).generics,
                   build_name="ms_tracker_elab", elab_only=True)


def test_ppc_above_lanes_refused():
    """PPC > LANES is refused at elaboration (the region capture needs PPC different banks)."""
    from mstrack.hw.hdl import HdlError, rtl_sources, run_ghdl_plain
    from mstrack.hw.hdl_config import CoreChoices, derive
    g = {**derive(CoreChoices(lanes=2)).generics, "PPC": 4}
    with pytest.raises(HdlError) as e:
        run_ghdl_plain("ms_tracker", rtl_sources("ms_tracker"), g, build_name="ms_tracker_elab", elab_only=True)
    assert "ms_tracker: PPC = 4 > LANES = 2 is not supported" in str(e.value)


# ----------------------------------------------------------------------------- FuseSoC
def _fusesoc() -> str:
    exe = Path(sys.executable).parent / "fusesoc"
    if exe.exists():
        return str(exe)
    if shutil.which("fusesoc"):
        return shutil.which("fusesoc")
    if os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0"):
        pytest.fail("fusesoc not installed (tools/setup.sh installs it: extra hdltools)")
    pytest.skip("fusesoc not installed (pip install fusesoc; tools/setup.sh does)")


@pytest.mark.parametrize("target", ["sim", "lint"])
def test_fusesoc_target(target, tmp_path):
    """`fusesoc run --target sim` (self-checking file testbench) and `--target lint` pass in a temp build dir."""
    from mstrack.hw.hdl import ghdl_backend
    cmd = [_fusesoc(), "--cores-root", str(REPO), "run", "--build-root", str(tmp_path / "build"),
           "--target", target, "mstrack:mstrack:ms_tracker"]
    r = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True,
                       env={**os.environ, "GHDL_BACKEND": ghdl_backend()})
    log = r.stdout + r.stderr
    assert r.returncode == 0, log[-3000:]
    if target == "sim":
        assert "ms_tracker_file_tb: PASSED: 3 results" in log


def _yosys_log_cells(log: str) -> dict[str, int]:
    """Cell counts of the last `stat` (synth_ecp5's "Printing statistics") in a yosys log."""
    last = log.rsplit("Printing statistics.", 1)[-1]
    block = last.split("Number of cells:", 1)[1].split("\n\n", 1)[0]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^\s+(\w+)\s+(\d+)$", block, re.M)}


@pytest.mark.synth
def test_fusesoc_synth_target(tmp_path):
    """`fusesoc run --target synth`: the generator ghdl_verilog writes the Verilog netlist (fix-ups applied,
    ECP5 RAM architecture), edalize's yosys (Debian's, Tcl) maps it with synth_ecp5 to ms_tracker.json.
    About 1 min on the full core (docs/packaging.md)."""
    yosys = shutil.which("yosys")
    if yosys is None:
        if os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0"):
            pytest.fail("yosys (with Tcl) not installed (tools/setup.sh: apt-get install yosys)")
        pytest.skip("yosys (with Tcl) not installed: apt-get install yosys (tools/setup.sh does)")
    build = tmp_path / "build"
    cmd = [_fusesoc(), "--cores-root", str(REPO), "run", "--build-root", str(build),
           "--target", "synth", "mstrack:mstrack:ms_tracker"]
    # the generator's interpreter is `python3`: this venv's, first on PATH
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    r = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, env=env)
    out = r.stdout + r.stderr
    assert r.returncode == 0, out[-3000:]
    work = build / "mstrack_mstrack_ms_tracker_0.1.0" / "synth-yosys"
    (v,) = work.glob("generator_cache/*/ms_tracker.v")
    text = v.read_text()
    assert text.count("\nmodule ms_tracker\n") == 1
    assert "module DP16KD" not in text, "GHDL's empty DP16KD module was not dropped (fix_ghdl_blackboxes)"
    assert re.search(r"^\s*DP16KD #\(", text, re.M), "no DP16KD instance: ECP5 architecture of ms_ram_sdp not used"
    log = (work / "yosys.log").read_text()
    cells = _yosys_log_cells(log)
    version = re.search(r"Yosys \d+\.\d+", log)
    print(f"\nfusesoc synth ({version.group(0) if version else 'yosys'}): {cells}")
    assert cells.get("DP16KD", 0) >= 1 and cells.get("LUT4", 0) > 1000 and cells.get("TRELLIS_FF", 0) > 1000, cells
    assert not any(k.startswith("$") and k != "$scopeinfo" for k in cells), f"unmapped cells: {cells}"
    netlist = json.loads((work / "ms_tracker.json").read_text())
    assert "ms_tracker" in netlist["modules"]
