"""The C driver sw/mstrack_drv.c against the RTL: ms_tracker_axi (core v2 with the default generics, and
the paper core) under Verilator, every register access of the driver an AXI4-Lite transaction (mstrack.hw.drvsim,
tools/hdl/drv_main.cpp).

The driver initialises the core, gives the init box, enables the interrupts, and its interrupt
handler reads every result through the registers while the video streams with 1080p60 blanking.
Each result is compared with the fixed-point model field by field, frame by frame (the raw word and
the driver's decode of the RES_* registers), with the interrupt bits the handler saw and the
counters at the end (:func:`mstrack.hw.drvsim.check_run`).  In the simulation half of `make test`
(no marker ``long``: the netlist half is the longer one).  tests/test_sw_driver.py checks the same
driver's decoder on the host without RTL.
"""
from __future__ import annotations

import pytest

from mstrack.hw.cosim import COMPARED_FIELDS_V2, expected_results_v2
from mstrack.track.params import TrackerParams
from test_ms_tracker_v2 import _real_clip


@pytest.mark.verilator
def test_driver_against_core_v2():
    """Deer, 30 frames at 704x400 (D = 4): tracked, lost on frame 25, searched and re-acquired on 27, so
    the lost and reacquired interrupts fire; a CPU 8 idle clocks per register access slower than the
    bus; 1080p60 blanking (the video never waits for the CPU)."""
    from mstrack.hw import drvsim, fastsim
    frames, box = _real_clip("Deer", 0, 30)
    exp = expected_results_v2(frames, box, TrackerParams(preset="v2"))
    assert any(e["status"] == drvsim.STATUS["lost"] for e in exp)
    assert any(e["status"] == drvsim.STATUS["reacquired"] for e in exp)
    run = drvsim.simulate_driver(frames, box, io_gap=8, **fastsim.HD1080P60)
    diffs = drvsim.check_run(run, exp)
    assert not diffs, "\n".join(diffs[:10])
    # the handler's reads end well before the next result: no result can be overwritten unread
    assert max(run.handler_clocks()) < 2000


@pytest.mark.verilator
def test_driver_against_paper_core():
    """The paper core (PRESET 0, result word v1: the driver's mstrack_read_result path): Girl, 20 frames
    at 128x96, 1080p60 blanking, every field of every result word v1 and the driver's decode."""
    from mstrack.fixed import FixedParams
    from mstrack.hw import drvsim, fastsim
    from mstrack.hw.cosim import expected_results
    frames, box = _real_clip("Girl", 0, 20)
    exp = expected_results(frames, box, TrackerParams(), FixedParams())
    run = drvsim.simulate_driver(frames, box, v2=False, io_gap=8, **fastsim.HD1080P60)
    diffs = drvsim.check_run(run, exp, v2=False)
    assert not diffs, "\n".join(diffs[:10])
    assert {"rho_e", "alpha_c", "box_w"} <= set(run.results[0]["driver"])   # the v1 fields, read by the driver


def test_check_run_finds_differences():
    """check_run reports a changed field, a driver decode that differs from the raw word, a missing
    interrupt bit and wrong counters (on a run assembled by hand, no RTL)."""
    from mstrack.fixed.vhdl_pkg import pack_result_v2, unpack_result_v2
    from mstrack.hw import drvsim
    exp = [{"cx": 100, "cy": 50, "w8": 256, "h8": 512, "rho": 1000, "confidence": 200, "status": 2, "iter": 1,
            "stop": 0, "decim_log2": 1, "searched": 0, "flags": 4, "err_code": 0, "frame_count": 1}]
    exp = [unpack_result_v2(pack_result_v2(e)) for e in exp]
    exp = [{k: e[k] for k in COMPARED_FIELDS_V2} for e in exp]
    word = pack_result_v2(exp[0])
    irq = drvsim.irq_bits()
    good = drvsim.DriverRun(results=[{"word": word, "fields": unpack_result_v2(word),
                                      "irq": irq["result"] | irq["lost"],
                                      "driver": {**{k: exp[0][k] for k in exp[0]}, "valid": 1},
                                      "irq_cycle": 0, "handled_cycle": 50}],
                            calls={"init": 0, "start": 0},
                            counters={"results": 1, "lost": 1, "errors": 0, "rejected": 0, "dropped": 0}, status="done")
    assert drvsim.check_run(good, exp) == []
    bad = drvsim.DriverRun(**{**good.__dict__, "results": [dict(good.results[0])]})
    bad.results[0]["driver"] = {**bad.results[0]["driver"], "cy": 51}
    bad.results[0]["irq"] = irq["result"]
    bad.counters = {**good.counters, "lost": 0}
    msgs = "\n".join(drvsim.check_run(bad, [{**exp[0], "cx": 101}]))
    for what in ("cx: dut=100 model=101", "cy: driver=51", "interrupt bits", "counters"):
        assert what in msgs
