"""Measure simulator speed (cycles/s) on the toy tb/flow_example.vhd.

    .venv/bin/python studies/bench_example.py [LINES]

Runs the cocotb ``throughput`` test (LINES x 256 pixels, one pixel per clock)
with GHDL mcode, GHDL llvm (if installed) and Verilator, and prints the
cycles/s reported by the test (the rate inside the test, i.e. without build
and simulator start-up) and the wall time of the whole call.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mstrack.hw import hdl  # noqa: E402


def main() -> None:
    lines = sys.argv[1] if len(sys.argv) > 1 else "400"
    env = {"FLOW_EXAMPLE_LINES": lines, "FLOW_EXAMPLE_RAW_CYCLES": str(int(lines) * 2560)}
    g = {"WIDTH": 8}
    runs = [("ghdl-mcode", "mcode"), ("ghdl-llvm", "llvm")]
    for name, backend in runs:
        if backend == "llvm" and hdl.ghdl_backend() != "llvm" and not Path("/usr/bin/ghdl-llvm").exists():
            continue
        with hdl._environ(MSTRACK_GHDL_BACKEND=backend):
            t0 = time.monotonic()
            hdl.run_ghdl("flow_example", "test_flow_example", g, [hdl.TB_DIR / "flow_example.vhd"], build_name=f"bench_{name}",
                         testcase=["throughput", "raw_speed"], extra_env=env)
            print(f"{name:12s} wall {time.monotonic() - t0:6.1f} s  (see SPEED line above)", flush=True)
    t0 = time.monotonic()
    hdl.run_verilator("flow_example", "test_flow_example", g, [hdl.TB_DIR / "flow_example.vhd"], build_name="bench_verilator",
                      testcase=["throughput", "raw_speed"], extra_env=env)
    print(f"{'verilator':12s} wall {time.monotonic() - t0:6.1f} s  (see SPEED line above)", flush=True)


if __name__ == "__main__":
    main()
