"""cocotb test bench + pytest entry points for rtl/ms_divider_iter.vhd.

Model: :func:`mstrack.fixed.primitives.ms_divider_reference` (restoring division,
saturating to 2**Q_W - 1 when n >= d << Q_W; d = 0 gives all ones).  The cases of
tb/test_ms_divider.py, issued back to back (in_valid in the out_valid cycle of the previous
division) and with random gaps; every result compared exactly, the latency must be
LATENCY = Q_W + 1 clocks and in_valid must be ignored while busy.

Run: ``.venv/bin/python -m pytest tb/test_ms_divider_iter.py``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from mstrack.fixed.primitives import ms_divider_reference
from mstrack.hw.hdl import dut_generics
from test_ms_divider import divider_cases

DEFAULTS = {"N_W": 22, "D_W": 14, "Q_W": 16}
CLK_NS = 10


def divider_latency(g: dict) -> int:
    """Documented latency of ms_divider_iter (header of rtl/ms_divider_iter.vhd)."""
    return int(g["Q_W"]) + 1


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def divider_iter_stream(dut, gap_prob):
    g = dut_generics(DEFAULTS)
    nw, qw = int(g["N_W"]), int(g["Q_W"])
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    dut.rst.value = 1
    dut.in_valid.value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(2000 + int(gap_prob * 10))
    items = divider_cases(g, rng, 150)
    items += [{"in_n": 0, "in_d": 0}, {"in_n": 12345 % (1 << nw), "in_d": 0}]   # d = 0: all ones
    lat = divider_latency(g)
    i, cycle, t_in, pending = 0, 0, None, None
    done = 0
    while done < len(items):
        await RisingEdge(dut.clk)
        await ReadOnly()
        cycle += 1
        # values now: registered outputs of the edge just passed
        if dut.out_valid.value == 1:
            assert pending is not None, "out_valid without a division"
            exp = ms_divider_reference(pending["in_n"], pending["in_d"], qw) if pending["in_d"] else (1 << qw) - 1
            got = dut.out_q.value.to_unsigned()
            assert got == exp, f"item {done} {pending}: q = {got}, model {exp}"
            assert cycle - t_in == lat, f"item {done}: latency {cycle - t_in} != {lat}"
            pending = None
            done += 1
        busy = dut.busy.value == 1
        await Timer(1, "ns")                                   # leave the read-only phase, then drive
        if not busy and pending is None and i < len(items) and rng.random() >= gap_prob:
            for k, v in items[i].items():
                getattr(dut, k).value = v
            dut.in_valid.value = 1
            pending, t_in = items[i], cycle
            i += 1
        elif busy and rng.random() < 0.5:                       # ignored while busy
            dut.in_n.value = rng.randint(0, (1 << nw) - 1)
            dut.in_d.value = 1
            dut.in_valid.value = 1
        else:
            dut.in_valid.value = 0
        assert cycle < 40 * len(items) + 100, "stuck"
    if gap_prob == 0.0:   # back to back: one division per LATENCY clocks
        assert cycle <= len(items) * lat + 5


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_divider_iter"
MODULE = "test_ms_divider_iter"

PARAMS = [
    pytest.param(DEFAULTS, id="default"),
    pytest.param({**DEFAULTS, "Q_W": 1}, id="q1"),
    pytest.param({**DEFAULTS, "N_W": 8, "D_W": 20, "Q_W": 5}, id="wide_d"),
    pytest.param({"N_W": 38, "D_W": 22, "Q_W": 14}, id="centre"),          # ms_centre use
    pytest.param({"N_W": 31, "D_W": 22, "Q_W": 17}, id="fusion"),          # ms_fusion use
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_divider_iter_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
