"""cocotb test bench + pytest entry points for rtl/ms_admit.vhd (the capacity rule of the
shared-engine multi-target core) against ``mstrack.fixed.multi_capacity.plan_frame`` and
``check_add``.

Each frame offers its live targets' jobs oldest first, then some adds; the bench compares every
verdict (taken or held; ok, full or cycles) and, after the frame, ``sum`` and ``min_slack`` with the
model's ``plan.clocks`` / ``plan.budget`` grown by the adds taken.  Frames: the boundaries (a job
that fills the budget exactly is taken, one clock more is held; a held job does not stop a later,
smaller one; a region spanning the frame leaves the blanking; MAX_TARGETS taken, an add with every
slot live), then random frames at 1080p60 and at 720p60 timing (the timing is a port).

Run: ``.venv/bin/python -m pytest tb/test_ms_admit.py``.
"""
from __future__ import annotations

import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.multi_capacity import (ADD_OK, MultiCoreConfig, TargetDemand, VideoTiming, check_add,
                                          plan_frame)
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"MAX_TARGETS": 4, "CLK_W": 24, "LINE_W": 12, "LC_W": 13, "SUM_W": 28}


def job(tid: int, clocks: int, release: int, nxt: int, kind: str = "track") -> TargetDemand:
    """A demand with the fields the rule reads (clocks, release and next line)."""
    return TargetDemand(tid, kind, 1, 31, 31, 95, 95, 0, clocks, release, nxt)  # type: ignore[arg-type]


class AdmitTB:
    def __init__(self, dut):
        self.dut = dut
        g = dut_generics(DEFAULTS)
        self.max_targets = int(g["MAX_TARGETS"])
        for s in ("rst", "clear", "offer", "o_add", "o_full"):
            getattr(dut, s).value = Immediate(0)
        for s in ("o_clocks", "o_release", "o_next", "frame_lines", "line_clocks", "blank_clocks"):
            getattr(dut, s).value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        self.latency: set[int] = set()
        self.verdicts: dict[tuple[bool, int], int] = {}   # (add, code) -> count

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)

    def timing(self, t: VideoTiming):
        d = self.dut
        d.frame_lines.value, d.line_clocks.value, d.blank_clocks.value = t.frame_lines, t.line_clocks, t.blank_clocks

    async def wait_ready(self):
        while True:
            await ReadOnly()
            if int(self.dut.ready.value):
                break
            await RisingEdge(self.dut.clk)
        await RisingEdge(self.dut.clk)   # drive in the next clock (ready is a register)

    async def clear(self):
        await self.wait_ready()
        self.dut.clear.value = 1
        await RisingEdge(self.dut.clk)
        self.dut.clear.value = 0

    async def offer(self, dm: TargetDemand, add: bool, full: bool = False) -> tuple[int, int]:
        d = self.dut
        await self.wait_ready()
        d.offer.value, d.o_add.value, d.o_full.value = 1, int(add), int(full)
        d.o_clocks.value, d.o_release.value, d.o_next.value = dm.clocks, dm.release_line, dm.next_line
        await RisingEdge(d.clk)
        d.offer.value = 0
        n = 0
        while True:
            await RisingEdge(d.clk)
            n += 1
            await ReadOnly()
            if int(d.done.value):
                self.latency.add(n)
                out = int(d.taken.value), int(d.code.value)
                self.verdicts[(add, out[1])] = self.verdicts.get((add, out[1]), 0) + 1
                await RisingEdge(d.clk)
                return out

    async def frame(self, live: list[TargetDemand], adds: list[TargetDemand], cfg: MultiCoreConfig) -> int:
        """Offer a frame's jobs and compare each verdict with the model; returns the jobs taken."""
        await self.clear()
        plan = plan_frame(live, cfg)
        for dm in live:
            taken, code = await self.offer(dm, add=False)
            want = dm.target_id in plan.tracked
            assert (taken, code) == (int(want), 0 if want else 2), f"job {dm}: got {taken, code}, plan {plan}"
        jobs = list(plan.jobs)
        n_live = len(live)
        for dm in adds:
            full = n_live >= cfg.max_targets
            want = check_add(jobs, n_live, dm, cfg)
            taken, code = await self.offer(dm, add=True, full=full)
            assert (taken, code) == (int(want == ADD_OK), want), f"add {dm}: got {taken, code}, model {want}"
            if want == ADD_OK:
                jobs.append(dm)
                n_live += 1
        await ReadOnly()
        budget = min((j.slack(cfg.timing) for j in jobs), default=None)
        assert int(self.dut.sum.value) == sum(j.clocks for j in jobs)
        assert int(self.dut.min_slack.value) == (budget if budget is not None else (1 << 28) - 1)
        await RisingEdge(self.dut.clk)
        return len(jobs)


@cocotb.test()
async def run_test(dut):
    tb = AdmitTB(dut)
    await tb.reset()
    mt = tb.max_targets
    t60 = VideoTiming()
    cfg = MultiCoreConfig(max_targets=mt, timing=t60)
    tb.timing(t60)
    blank = t60.blank_clocks
    # boundaries: a region spanning the frame has the blanking as its slack
    span = job(0, blank, 1080, 0)
    assert span.slack(t60) == blank
    assert await tb.frame([span], [], cfg) == 1                                   # equal: taken
    assert await tb.frame([job(0, blank + 1, 1080, 0)], [], cfg) == 0             # one clock more: held
    # a held job does not stop a later, smaller one; the oldest first
    small = job(2, 1000, 200, 150)
    assert await tb.frame([job(0, 90_000, 1080, 0), job(1, 20_000, 1080, 0), small], [], cfg) == min(2, mt)
    # MAX_TARGETS taken, then an add with every slot live (full) and one that breaks the rule (cycles)
    live = [job(i, 5_000, 100 + 50 * i, 90 + 50 * i) for i in range(mt)]
    assert await tb.frame(live, [job(mt, 1_000, 300, 290, "init")], cfg) == mt
    assert await tb.frame(live[:mt - 1], [job(mt, 10_000_000, 300, 290, "init"), job(mt + 1, 100, 300, 290, "init")],
                          cfg) == mt
    assert await tb.frame([], [job(0, 5_000, 400, 390, "init")], cfg) == 1        # an add alone
    assert await tb.frame([], [], cfg) == 0                                       # nothing offered
    # random frames, 1080p60 and 720p60 timing
    rng = random.Random(7)
    for timing in (t60, VideoTiming(720, 750, 1650)):
        tb.timing(timing)
        cfg = MultiCoreConfig(max_targets=mt, timing=timing)
        for _ in range(30):
            n = rng.randint(0, mt)
            tot = rng.choice([timing.blank_clocks, timing.frame_clocks // 4, timing.frame_clocks])
            def rnd(tid, kind="track"):
                rel = rng.randint(1, timing.active_lines)
                nxt = rng.randint(0, max(0, rel - rng.randint(1, 300)))
                return job(tid, rng.randint(1, tot), rel, nxt, kind)
            await tb.frame([rnd(i) for i in range(n)], [rnd(n + i, "init") for i in range(rng.randint(0, 2))], cfg)
    assert len(tb.latency) == 1, f"latency varies: {tb.latency}"
    assert all(tb.verdicts.get(k, 0) >= 2 for k in ((False, 0), (False, 2), (True, 0), (True, 1), (True, 2))), tb.verdicts
    dut._log.info("verdicts equal the model's; offer -> done %s clocks", tb.latency)


# ---------------------------------------------------------------- pytest entry points

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_admit"
MODULE = "test_ms_admit"


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", [pytest.param(DEFAULTS, id="max4"),
                                      pytest.param({**DEFAULTS, "MAX_TARGETS": 1}, id="max1")])
def test_ms_admit(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.verilator
def test_ms_admit_verilator(hdl_waves):
    """The netlist (the shift-and-add product, the comparisons) under Verilator."""
    hdl.run_verilator(TOP, MODULE, DEFAULTS, hdl.rtl_sources(TOP), waves=hdl_waves)
