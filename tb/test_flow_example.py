"""cocotb test bench + pytest entry points for tb/flow_example.vhd (flow smoke test).

One file holds both:
  * the cocotb tests (run inside the simulator: ``@cocotb.test`` functions), and
  * the pytest tests (``test_*`` functions at the bottom) that build the design
    with GHDL or GHDL->Verilator and run this same module in the simulator.

Video framing with cocotbext-axi (one pixel per beat):
  * one ``AxiStreamFrame`` per *line*: the source drives tlast=1 on its last beat;
  * ``tuser`` per beat as a list: ``[1, 0, 0, ...]`` on the first line of a
    frame (start of frame on the first pixel), ``0`` (scalar) on the others;
  * ``byte_lanes=1`` on source and sink so that one beat = one pixel of any
    width (the default splits tdata into 8-bit lanes and rejects widths that
    are not a multiple of 8).

Run: ``.venv/bin/python -m pytest tb/test_flow_example.py`` (``--waves`` for waves).
"""

from __future__ import annotations

import os
import random
import time

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, RisingEdge, Timer
from cocotb.utils import get_sim_time

from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

try:
    from mstrack.hw.hdl import dut_generics
except ImportError:  # pragma: no cover
    import json

    def dut_generics(defaults=None):
        return {**(defaults or {}), **json.loads(os.environ.get("MSTRACK_GENERICS", "{}"))}


DEFAULTS = {"WIDTH": 8, "COLS_LOG2": 10, "BIAS": 0, "USE_ABOVE": True}
CLK_NS = 10


# ---------------------------------------------------------------- model

def model_lines(frame: list[list[int]], bias: int, use_above: bool) -> list[tuple[int, int]]:
    """Expected (tdata, tuser) per line of one frame."""
    out = []
    for y, line in enumerate(frame):
        if use_above:
            above = frame[y - 1] if y > 0 else [0] * len(line)
            s = sum(p * a for p, a in zip(line, above))
        else:
            s = sum(p * p for p in line)
        out.append((s + bias, 1 if y == 0 else 0))
    return out


def frame_to_axis(frame: list[list[int]]) -> list[AxiStreamFrame]:
    """One AxiStreamFrame per line; tuser=1 on the first pixel of the frame only."""
    beats = []
    for y, line in enumerate(frame):
        tuser = [1] + [0] * (len(line) - 1) if y == 0 else 0
        beats.append(AxiStreamFrame(tdata=list(line), tuser=tuser))
    return beats


# ---------------------------------------------------------------- TB

class TB:
    def __init__(self, dut):
        self.dut = dut
        self.g = dut_generics(DEFAULTS)
        # widths from the ports: works for GHDL and for the Verilator netlist alike
        self.width = len(dut.s_axis_tdata)
        self.cols = 2 ** (len(dut.m_axis_tdata) - 2 * self.width)
        assert self.width == int(self.g["WIDTH"]), (self.width, self.g)
        # drive reset before the AXI models start watching it ('U' cannot be read as a bool)
        dut.rst.value = Immediate(1)
        cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start(start_high=False))
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.clk, dut.rst, byte_lanes=1)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.clk, dut.rst, byte_lanes=1)

    def set_idle_generator(self, generator=None):
        if generator:
            self.source.set_pause_generator(generator())

    def set_backpressure_generator(self, generator=None):
        if generator:
            self.sink.set_pause_generator(generator())

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)

    def random_frame(self, rng: random.Random, lines: int, cols: int) -> list[list[int]]:
        hi = 2 ** self.width - 1
        return [[rng.randint(0, hi) for _ in range(cols)] for _ in range(lines)]

    async def check_frames(self, frames):
        bias, use_above = int(self.g["BIAS"]), bool(self.g["USE_ABOVE"])
        for f in frames:
            for beat in frame_to_axis(f):
                await self.source.send(beat)
        for f in frames:
            for exp_data, exp_user in model_lines(f, bias, use_above):
                rx = await self.sink.recv()
                assert rx.tdata == [exp_data], f"line sum {rx.tdata} != {exp_data}"
                tuser = rx.tuser if isinstance(rx.tuser, int) else rx.tuser[0]
                assert tuser == exp_user, f"tuser {rx.tuser} != {exp_user}"
        assert self.sink.empty()


def cycle_pause():
    return iter(lambda: random.random() < 0.3, None)  # endless, 30 % pause


# ---------------------------------------------------------------- cocotb tests

@cocotb.test()
@cocotb.parametrize(idle_inserter=[None, cycle_pause], backpressure_inserter=[None, cycle_pause])
async def run_test(dut, idle_inserter, backpressure_inserter):
    tb = TB(dut)
    rng = random.Random(1234)
    tb.set_idle_generator(idle_inserter)
    tb.set_backpressure_generator(backpressure_inserter)
    await tb.reset()
    # frames of different sizes, including 1-pixel lines and full-width lines
    frames = [tb.random_frame(rng, 4, 17), tb.random_frame(rng, 3, 1), tb.random_frame(rng, 2, min(tb.cols, 300))]
    # all-ones frame: maximal sums (checks the accumulator width)
    hi = 2 ** tb.width - 1
    frames.append([[hi] * tb.cols for _ in range(2)])
    await tb.check_frames(frames)


@cocotb.test()
async def throughput(dut):
    """One pixel per clock with no pauses; reports simulated cycles per wall second."""
    tb = TB(dut)
    await tb.reset()
    lines, cols = int(os.environ.get("FLOW_EXAMPLE_LINES", "40")), min(tb.cols, 256)
    frame = tb.random_frame(random.Random(5), lines, cols)
    t0, c0 = time.perf_counter(), get_sim_time("ns")
    await tb.check_frames([frame])
    wall = time.perf_counter() - t0
    cycles = (get_sim_time("ns") - c0) / CLK_NS
    assert cycles < lines * cols * 1.05 + 20, f"not 1 pixel/clock: {cycles} cycles for {lines * cols} pixels"
    dut._log.info("SPEED %d cycles in %.2f s = %.0f cycles/s", cycles, wall, cycles / wall)


@cocotb.test()
async def raw_speed(dut):
    """Simulator speed without per-cycle Python: inputs held constant (valid pixels,
    tlast every 2**COLS_LOG2 by the column counter wrapping), only the clock runs."""
    cycles = int(os.environ.get("FLOW_EXAMPLE_RAW_CYCLES", "20000"))
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start(start_high=False))
    dut.rst.value = 1
    dut.s_axis_tvalid.value = 1
    dut.s_axis_tdata.value = 3
    dut.s_axis_tlast.value = 0
    dut.s_axis_tuser.value = 0
    dut.m_axis_tready.value = 1
    await Timer(3 * CLK_NS, "ns")
    dut.rst.value = 0
    t0 = time.perf_counter()
    await Timer(cycles * CLK_NS, "ns")
    wall = time.perf_counter() - t0
    assert dut.s_axis_tready.value == 1
    dut._log.info("SPEED raw %d cycles in %.2f s = %.0f cycles/s", cycles, wall, cycles / wall)


@cocotb.test(skip=os.environ.get("FLOW_EXAMPLE_DELIBERATE_FAIL") != "1")
async def deliberate_failure(dut):
    """Only run by test_failure_is_reported: proves that a failing cocotb test fails pytest."""
    tb = TB(dut)
    await tb.reset()
    await tb.source.send(AxiStreamFrame(tdata=[1, 2], tuser=[1, 0]))
    rx = await tb.sink.recv()
    assert rx.tdata == [12345], "deliberate failure"


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402  (only needed on the pytest side)

from mstrack.hw import hdl  # noqa: E402

TOP = "flow_example"
MODULE = "test_flow_example"
#: the toy lives in tb/ (not in rtl/: it is no part of the core and not in the ms_ namespace)
SOURCES = [hdl.TB_DIR / "flow_example.vhd"]

PARAMS = [
    pytest.param({"WIDTH": 8}, id="w8"),
    pytest.param({"WIDTH": 12, "COLS_LOG2": 9, "BIAS": 7, "USE_ABOVE": False}, id="w12"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_flow_example_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, SOURCES, waves=hdl_waves)


@pytest.mark.verilator
@pytest.mark.parametrize("generics", PARAMS)
def test_flow_example_verilator(generics, hdl_waves):
    hdl.run_verilator(TOP, MODULE, generics, SOURCES, waves=hdl_waves)


@pytest.mark.ghdl
def test_failure_is_reported():
    with pytest.raises(hdl.HdlTestFailure, match="deliberate failure"):
        hdl.run_ghdl(TOP, MODULE, {"WIDTH": 8}, SOURCES, build_name="ghdl_flow_example_fail",
                     testcase="deliberate_failure", extra_env={"FLOW_EXAMPLE_DELIBERATE_FAIL": "1"})


@pytest.mark.synth
def test_flow_example_synth():
    """Flow smoke test: GHDL -> Yosys (ECP5 + Xilinx) -> nextpnr; RAM and multiplier inferred."""
    r = hdl.synth_ecp5(TOP, {"WIDTH": 8}, SOURCES, seed=1, freq_mhz=150)
    assert (r["DP16KD"], r["MULT18X18D"]) == (1, 1), r["cells"]
    assert r["fmax_min_mhz"] and r["fmax_min_mhz"] > 60, r["fmax_mhz"]
    x = hdl.synth_xilinx(TOP, {"WIDTH": 8}, SOURCES)
    assert (x["BRAM36"], x["DSP48E1"]) == (0.5, 1), x["cells"]


@pytest.mark.verilator
@pytest.mark.parametrize("pause", [0, 30])
def test_flow_example_verilator_axis(pause):
    """Long-run path: generated Verilator C++ harness, whole frames, numpy model."""
    import numpy as np

    rng = np.random.default_rng(7)
    frames, lines, cols = 2, 120, 160
    pix = rng.integers(0, 256, size=(frames, lines, cols), dtype=np.uint64)
    tuser = np.zeros_like(pix)
    tuser[:, 0, 0] = 1                      # start of frame on the first pixel
    tlast = np.zeros_like(pix)
    tlast[:, :, -1] = 1                     # end of each line
    beats = np.stack([pix.reshape(-1), tuser.reshape(-1), tlast.reshape(-1)], axis=1)
    r = hdl.run_verilator_axis(TOP, {"WIDTH": 8}, beats, sources=SOURCES, in_pause_pct=pause, out_pause_pct=pause)
    p = pix.astype(np.int64)
    above = np.concatenate([np.zeros((frames, 1, cols), np.int64), p[:, :-1, :]], axis=1)
    expected = (p * above).sum(axis=2).reshape(-1)
    assert r["consumed"] == len(beats)
    assert np.array_equal(r["out"][:, 0].astype(np.int64), expected)
    first = np.zeros((frames, lines), np.uint64)
    first[:, 0] = 1
    assert np.array_equal(r["out"][:, 1], first.reshape(-1))
