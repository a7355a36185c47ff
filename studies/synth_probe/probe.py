"""Which VHDL-2008 constructs does `ghdl --synth` (GHDL 2.0, Debian) accept?

    .venv/bin/python studies/synth_probe/probe.py

For each probe entity: GHDL analysis+elaboration for simulation (mcode),
`ghdl --synth --out=verilog` (through mstrack.hw.hdl.ghdl_to_verilog), then Yosys
reading the Verilog (`synth_ecp5` for cell counts).  Prints one line per probe;
logs under build/synth_probe/.  Results are recorded in docs/hdl_flow.md.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from mstrack.hw import hdl  # noqa: E402

PROBES = ["p_record_port", "p_unconstrained", "p_unconstrained_top", "p_arith", "p_ram_rdw", "p_2008", "p_2008_sel", "p_2008_casem",
          "p_fixed", "p_mathreal", "p_mathreal_sqrt"]


def main() -> int:
    out = hdl.BUILD_DIR / "synth_probe"
    out.mkdir(parents=True, exist_ok=True)
    for top in PROBES:
        srcs = [HERE / "p_pkg.vhd", HERE / f"{top}.vhd"]
        wd = out / top
        wd.mkdir(exist_ok=True)
        sim = subprocess.run(["ghdl", "-a", *hdl.GHDL_STD_FLAGS, *map(str, srcs)], cwd=wd,
                             capture_output=True, text=True)
        if sim.returncode == 0:
            sim = subprocess.run(["ghdl", "-e", *hdl.GHDL_STD_FLAGS, top], cwd=wd, capture_output=True, text=True)
        sim_ok = "ok" if sim.returncode == 0 else "FAIL: " + (sim.stderr.strip().splitlines() or ["?"])[0]
        try:
            v = hdl.ghdl_to_verilog(top, {}, srcs, out_path=wd / f"{top}.v")
            syn_ok = "ok"
        except hdl.HdlError as e:
            lines = [ln for ln in str(e).splitlines()[1:] if "error" in ln.lower() or ":" in ln]
            syn_ok = "FAIL: " + (lines[0] if lines else str(e).splitlines()[0])
            v = None
        ys = "-"
        if v is not None:
            try:
                r = hdl.synth_ecp5(top, {}, srcs, pnr=False, name=f"probe_{top}")
                cells = {k: n for k, n in r["cells"].items() if k in ("DP16KD", "MULT18X18D", "TRELLIS_DPR16X4")}
                ys = f"ok {cells or ''} LUT4={r['LUT4']} FF={r['TRELLIS_FF']}"
            except hdl.HdlError as e:
                ys = "FAIL: " + str(e).splitlines()[0]
        print(f"{top:22s} sim: {sim_ok}\n{'':22s} synth: {syn_ok}\n{'':22s} yosys: {ys}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
