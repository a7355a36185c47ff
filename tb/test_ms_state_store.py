"""cocotb test bench + pytest entry points for rtl/ms_state_store.vhd: the targets' state records with
the stream-fault rule (a job's state is committed when its frame ends good, dropped when it fails).

A reference model in the bench: per slot the committed record and at most one write waiting for its
frame's verdict.  Random frames (tag = frame number mod 2, 20 % of them with a stream fault); in each,
every slot's job writes either before the verdict (pending), in the verdict's clock, or after it
(a job that ends during the next frame, written after the next frame's start); some pending writes are
dropped (a removal).  After each phase of each frame every slot's committed record (rd_data) and the
pending bits are compared with the reference.  Run: ``.venv/bin/python -m pytest tb/test_ms_state_store.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.hw import hdl


class Ref:
    def __init__(self, n: int):
        self.comm: dict[int, int] = {}
        self.pend: dict[int, tuple[int, int]] = {}          # slot -> (frame, data)
        self.verdict: dict[int, bool] = {}                   # frame -> good

    def start(self, f: int) -> None:
        self.verdict.pop(f, None)

    def done(self, f: int, good: bool) -> None:
        self.verdict[f] = good
        for s, (pf, data) in list(self.pend.items()):
            if pf == f:
                if good:
                    self.comm[s] = data
                del self.pend[s]

    def write(self, s: int, f: int, data: int) -> None:
        if f in self.verdict:
            if self.verdict[f]:
                self.comm[s] = data
            self.pend.pop(s, None)
        else:
            self.pend[s] = (f, data)


class StoreTB:
    def __init__(self, dut, n: int, width: int):
        self.dut, self.n, self.width = dut, n, width
        self.ref = Ref(n)
        self.rng = random.Random(9)
        self.checks = 0

    async def reset(self):
        d = self.dut
        for s in ("rst", "wr_en", "wr_tag", "fr_start", "fr_done", "fr_tag", "fr_good", "drop"):
            getattr(d, s).value = Immediate(0)
        for s in ("wr_slot", "wr_data", "drop_slot", "rd_slot"):
            getattr(d, s).value = Immediate(0)
        cocotb.start_soon(Clock(d.clk, 10, unit="ns").start(start_high=False))
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        await RisingEdge(d.clk)

    def idle(self):
        d = self.dut
        d.wr_en.value, d.fr_start.value, d.fr_done.value, d.drop.value = 0, 0, 0, 0
        d.wr_data.value = self.rng.getrandbits(self.width)          # garbage while not written

    async def write(self, s: int, f: int, verdict: tuple[bool] | None = None) -> None:
        """One clock: slot s's job of frame f writes; with ``verdict``, frame f's fr_done in the same clock."""
        d = self.dut
        data = self.rng.getrandbits(self.width)
        d.wr_en.value, d.wr_slot.value, d.wr_tag.value, d.wr_data.value = 1, s, f % 2, data
        if verdict is not None:
            d.fr_done.value, d.fr_tag.value, d.fr_good.value = 1, f % 2, int(verdict[0])
            self.ref.done(f, verdict[0])
        self.ref.write(s, f, data)
        await RisingEdge(d.clk)
        self.idle()

    async def start(self, f: int) -> None:
        d = self.dut
        d.fr_start.value, d.fr_tag.value = 1, f % 2
        self.ref.start(f)
        await RisingEdge(d.clk)
        self.idle()

    async def done(self, f: int, good: bool) -> None:
        d = self.dut
        d.fr_done.value, d.fr_tag.value, d.fr_good.value = 1, f % 2, int(good)
        self.ref.done(f, good)
        await RisingEdge(d.clk)
        self.idle()

    async def drop(self, s: int) -> None:
        d = self.dut
        d.drop.value, d.drop_slot.value = 1, s
        self.ref.pend.pop(s, None)
        await RisingEdge(d.clk)
        self.idle()

    async def check(self) -> None:
        d = self.dut
        await ClockCycles(d.clk, 2)
        await ReadOnly()
        pend = int(d.pending.value)
        want = sum(1 << s for s in self.ref.pend)
        assert pend == want, f"pending {pend:#x}, reference {want:#x}"
        await RisingEdge(d.clk)
        for s in range(self.n):
            d.rd_slot.value = s
            await RisingEdge(d.clk)
            await RisingEdge(d.clk)
            await ReadOnly()
            if s in self.ref.comm:
                got = int(d.rd_data.value)
                assert got == self.ref.comm[s], f"slot {s}: {got:#x}, committed {self.ref.comm[s]:#x}"
                self.checks += 1
            await RisingEdge(d.clk)


@cocotb.test()
async def run_test(dut):
    cfg = json.loads(os.environ["MSTRACK_STATE_STORE"])
    n, width = int(cfg["n"]), int(cfg["width"])
    tb = StoreTB(dut, n, width)
    await tb.reset()
    rng = tb.rng
    late: list[int] = []                                     # slots of the previous frame still running
    counts = {"pending": 0, "same": 0, "late": 0, "bad": 0, "drop": 0}
    for f in range(1, 160):
        good = rng.random() >= 0.2
        counts["bad"] += not good
        await tb.start(f)
        for s in late:                                       # frame f - 1's jobs that end during frame f
            await tb.write(s, f - 1)
            counts["late"] += 1
        await tb.check()
        kinds = {s: rng.choice(["none", "pending", "pending", "same", "late"]) for s in range(n)}
        if f == 1:
            kinds = {s: "pending" for s in range(n)}
        for s, k in kinds.items():
            if k == "pending":
                await tb.write(s, f)
                counts["pending"] += 1
        if rng.random() < 0.3 and tb.ref.pend:
            await tb.drop(rng.choice(sorted(tb.ref.pend)))
            counts["drop"] += 1
        await tb.check()
        same = [s for s, k in kinds.items() if k == "same"]
        if same:
            await tb.write(same[0], f, verdict=(good,))
            counts["same"] += 1
            for s in same[1:]:
                await tb.write(s, f)
        else:
            await tb.done(f, good)
        await tb.check()
        late = [s for s, k in kinds.items() if k == "late"]
    dut._log.info("%d records compared (N_SLOTS %d): %s", tb.checks, n, counts)
    assert all(counts.values()), counts


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_state_store"
MODULE = "test_ms_state_store"


def _run(n: int, width: int, sim, waves: bool) -> None:
    sim(TOP, MODULE, {"N_SLOTS": n, "DATA_W": width}, hdl.rtl_sources(TOP), waves=waves,
        build_name=f"{sim.__name__}_{TOP}_{n}",
        extra_env={"MSTRACK_STATE_STORE": json.dumps({"n": n, "width": width})})


@pytest.mark.ghdl
@pytest.mark.parametrize("n", [16, 5, 1])
def test_ms_state_store(n, hdl_waves):
    _run(n, 213, hdl.run_ghdl, hdl_waves)


@pytest.mark.verilator
def test_ms_state_store_verilator(hdl_waves):
    """The GHDL -> Verilog netlist under Verilator (run-time indexed records and flags)."""
    _run(5, 213, hdl.run_verilator, hdl_waves)
