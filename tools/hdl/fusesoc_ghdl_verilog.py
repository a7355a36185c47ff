"""FuseSoC generator `ghdl_verilog` of mstrack.core (the `synth` target): VHDL -> Verilog.

FuseSoC runs it as ``python3 tools/hdl/fusesoc_ghdl_verilog.py <input.yml>`` in the generator's
work directory; it writes the Verilog netlist and a generated core there
(:func:`mstrack.hw.packaging.run_verilog_generator`).  ``python3`` must be the project's
virtualenv (numpy, pyyaml): activate .venv, or put .venv/bin first on PATH.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))   # this checkout's mstrack

try:
    from mstrack.hw.packaging import run_verilog_generator
except ModuleNotFoundError as e:   # pragma: no cover - depends on the caller's PATH
    sys.exit(f"fusesoc_ghdl_verilog: {e}: run fusesoc with the project's virtualenv first on PATH "
             f"(`. .venv/bin/activate`); the generator's interpreter is `python3` ({sys.executable})")

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: fusesoc_ghdl_verilog.py GENERATOR_INPUT.yml")
    print(run_verilog_generator(Path(sys.argv[1])))
