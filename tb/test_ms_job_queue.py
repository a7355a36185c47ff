"""cocotb test bench + pytest entry points for rtl/ms_job_queue.vhd: the released jobs in release
order, slots released in the same clock in ascending order.

Frames of random release batches: each batch is a random set of the slots not yet queued in that
frame, released in one clock, batches at least N_SLOTS clocks apart (a line); the engine pops with
random back-pressure (q_ready low 0 to 60 % of the clocks).  The popped slots must be the batches in
order, each batch ascending, with no `merged` pulse.  Then batches closer than N_SLOTS clocks: every
job still leaves once, and `merged` pulses.  A flush in the middle of a frame empties the queue.
Run: ``.venv/bin/python -m pytest tb/test_ms_job_queue.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from mstrack.hw import hdl


class QueueTB:
    def __init__(self, dut, n: int):
        self.dut, self.n = dut, n
        self.rng = random.Random(4)
        self.popped: list[int] = []
        self.merged = 0
        self.busy_prob = 0.0

    async def reset(self):
        d = self.dut
        for s in ("rst", "flush", "rel", "q_ready"):
            getattr(d, s).value = Immediate(0)
        cocotb.start_soon(Clock(d.clk, 10, unit="ns").start(start_high=False))
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        cocotb.start_soon(self.engine())
        await RisingEdge(d.clk)

    async def engine(self):
        """Pops with random back-pressure; records every slot popped and every merged pulse.  Works on
        the falling edge: the registered outputs are stable, and q_ready is set for the next rising edge."""
        d = self.dut
        while True:
            await FallingEdge(d.clk)
            ready = int(self.rng.random() >= self.busy_prob)
            d.q_ready.value = ready
            if ready and int(d.q_valid.value):
                self.popped.append(int(d.q_slot.value))
            self.merged += int(d.merged.value)

    async def release(self, slots: list[int]) -> None:
        d = self.dut
        d.rel.value = sum(1 << s for s in slots)
        await RisingEdge(d.clk)
        d.rel.value = 0

    async def drain(self, expected: int) -> None:
        for _ in range(200 * (self.n + 1)):
            if len(self.popped) >= expected:
                break
            await RisingEdge(self.dut.clk)
        await ClockCycles(self.dut.clk, 4)
        await ReadOnly()
        assert not int(self.dut.q_valid.value), "a job left in the queue"
        await RisingEdge(self.dut.clk)


@cocotb.test()
async def run_test(dut):
    n = int(json.loads(os.environ["MSTRACK_JOB_QUEUE"])["n"])
    tb = QueueTB(dut, n)
    await tb.reset()
    rng = tb.rng
    jobs = 0
    for frame in range(60):
        tb.busy_prob = rng.choice([0.0, 0.3, 0.6])
        left = list(range(n))
        rng.shuffle(left)
        want: list[int] = []
        tb.popped = []
        while left:
            k = rng.randint(1, max(1, min(len(left), 4)))
            batch, left = left[:k], left[k:]
            await tb.release(batch)
            want += sorted(batch)
            await ClockCycles(dut.clk, n - 1 + rng.randint(0, 30))
        await tb.drain(len(want))
        assert tb.popped == want, f"frame {frame}: popped {tb.popped}, release order {want}"
        jobs += len(want)
    assert tb.merged == 0, f"{tb.merged} merged pulses with batches {n} clocks apart"
    # batches closer than N_SLOTS clocks: each job leaves once, merged pulses
    for frame in range(20):
        tb.popped = []
        slots = list(range(n))
        rng.shuffle(slots)
        for i in range(0, n, 2):
            await tb.release(slots[i:i + 2])
        await tb.drain(n)
        assert sorted(tb.popped) == list(range(n)), f"close batches: popped {tb.popped}"
    if n > 2:
        assert tb.merged > 0, "no merged pulse with batches one clock apart"
    # a flush empties mask and FIFO
    tb.busy_prob = 1.0
    await tb.release(list(range(n)))
    await ClockCycles(dut.clk, 3)
    dut.flush.value = 1
    await RisingEdge(dut.clk)
    dut.flush.value = 0
    tb.popped = []
    tb.busy_prob = 0.0
    await ClockCycles(dut.clk, 2 * n + 4)
    await ReadOnly()
    assert not int(dut.q_valid.value) and tb.popped == [], f"after flush: popped {tb.popped}"
    dut._log.info("%d jobs in release order (N_SLOTS %d), %d merged pulses on close batches", jobs, n, tb.merged)


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_job_queue"
MODULE = "test_ms_job_queue"


def _run(n: int, sim, waves: bool) -> None:
    sim(TOP, MODULE, {"N_SLOTS": n}, hdl.rtl_sources(TOP), waves=waves, build_name=f"{sim.__name__}_{TOP}_{n}",
        extra_env={"MSTRACK_JOB_QUEUE": json.dumps({"n": n})})


@pytest.mark.ghdl
@pytest.mark.parametrize("n", [16, 5, 1])
def test_ms_job_queue(n, hdl_waves):
    _run(n, hdl.run_ghdl, hdl_waves)


@pytest.mark.verilator
def test_ms_job_queue_verilator(hdl_waves):
    """The GHDL -> Verilog netlist under Verilator."""
    _run(5, hdl.run_verilator, hdl_waves)
