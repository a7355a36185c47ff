"""cocotb test bench + pytest entry points for rtl/ms_pass_clocks.vhd: the worst-case clocks of a
pixel pass over a w x h window, against ``mstrack.fixed.multi_capacity.pixel_pass_clocks``.

Windows: the corners of the range (3 and 127 on each side), every odd w with h = 3, 63 and 127, and
random odd sizes; LANES 4 (the default), 2 and 8.  Each result is compared value by value, and the
start -> done latency against the bound of the block's header.

Run: ``.venv/bin/python -m pytest tb/test_ms_pass_clocks.py``.
"""
from __future__ import annotations

import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.multi_capacity import pixel_pass_clocks
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"LANES": 4, "HALF_W": 6, "PASS_LAT": 10, "KD_W": 29, "OUT_W": 16}


def sizes(rng: random.Random, n_random: int) -> list[tuple[int, int]]:
    out = [(3, 3), (3, 127), (127, 3), (127, 127), (5, 7), (63, 63)]
    out += [(w, h) for h in (3, 63, 127) for w in range(3, 128, 2)]
    out += [(rng.randrange(3, 128, 2), rng.randrange(3, 128, 2)) for _ in range(n_random)]
    return out


@cocotb.test()
async def run_test(dut):
    g = dut_generics(DEFAULTS)
    lanes, lat = int(g["LANES"]), int(g["PASS_LAT"])
    dut.rst.value = Immediate(1)
    dut.start.value = Immediate(0)
    dut.w.value = Immediate(3)
    dut.h.value = Immediate(3)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    worst = 0
    rng = random.Random(lanes)
    for w, h in sizes(rng, 60):
        dut.w.value, dut.h.value, dut.start.value = w, h, 1
        await RisingEdge(dut.clk)
        dut.start.value = 0
        n = 0
        while True:
            await RisingEdge(dut.clk)
            n += 1
            await ReadOnly()
            if int(dut.done.value):
                break
            assert n < 300, f"{w}x{h}: no done"
        got, want = int(dut.clocks.value), pixel_pass_clocks(w, h, lanes, lat)
        assert got == want, f"{w}x{h}, LANES {lanes}: {got} clocks, model {want}"
        worst = max(worst, n)
        await RisingEdge(dut.clk)
    assert worst <= 215 + lanes + 5, f"latency {worst}"
    dut._log.info("LANES %d: every window equals the model; latency at most %d clocks", lanes, worst)


from mstrack.hw import hdl  # noqa: E402

TOP = "ms_pass_clocks"
MODULE = "test_ms_pass_clocks"


@pytest.mark.ghdl
@pytest.mark.parametrize("lanes", [4, 2, 8])
def test_ms_pass_clocks(lanes, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, {**DEFAULTS, "LANES": lanes}, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.verilator
def test_ms_pass_clocks_verilator(hdl_waves):
    """The netlist under Verilator (the group arithmetic, the accumulators, the maximum)."""
    hdl.run_verilator(TOP, MODULE, DEFAULTS, hdl.rtl_sources(TOP), waves=hdl_waves)
