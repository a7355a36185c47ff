"""Hardware tooling around the VHDL core (rtl/): GHDL / Verilator flow (:mod:`.hdl`), core
configuration and file lists (:mod:`.hdl_config`, :mod:`.packaging`), co-simulation against the
fixed-point model (:mod:`.cosim`, :mod:`.fastsim`), synthesis (:mod:`.synth`), registers
(:mod:`.regs`), test vectors (:mod:`.vectors`, :mod:`.tb_files`).

Imports :mod:`mstrack.track`, :mod:`mstrack.fixed`, :mod:`mstrack.io` and :mod:`mstrack.versions`;
never :mod:`mstrack.eval` or :mod:`mstrack.cli` (tests/test_layout.py).
"""
