"""cocotb test bench + pytest entry points for rtl/ms_frame_plan.vhd: a frame's plan (each live
target's job and verdict, oldest first, then the frame's adds) against
``mstrack.fixed.multi_capacity.plan_frame`` over ``ms_job_demand``, and ``check_add``.

The bench holds the state records: it answers each st_req with the k-th oldest target's slot and
state after 0 to 3 clocks.  Frames:
* the boundaries: no live target; one target whose region spans the frame (its slack is the
  blanking); MAX_TARGETS small targets, then an add with every slot live (code 1, full);
* frames where the rule holds targets: lost targets (84,000 clocks and more) and tall regions that
  leave the blanking as the budget, among small targets, so that a held job is followed by a
  smaller one that is taken;
* random frames of 0 .. MAX_TARGETS targets (random sizes, centres, lost or not), each followed by
  0 .. 3 adds (the init job of a random box: codes 0, 1 and 2);
* the state FixedTrackerV2 holds on real frames (Deer, Football1, MotorRolling), several of them a frame.
Two video timings (1080p60: 1125 lines of 2200 clocks; 720p60: 750 of 1650).  Every p_valid (slot,
verdict, D, region, clocks, lines), plan_done (sum, budget) and add code is compared with the model.

Run: ``.venv/bin/python -m pytest tb/test_ms_frame_plan.py``.
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

from mstrack.fixed.formats import FixedParams
from mstrack.fixed.multi_capacity import (ADD_OK, MultiCoreConfig, VideoTiming, _geometry, check_add, init_demand,
                                          ms_job_demand, plan_frame)
from mstrack.hw import hdl
from mstrack.hw.multi_core import job_demand_generics
from mstrack.track.params import TrackerParams

from v2_common import SEQ_ROOT, tracker_states

TP = TrackerParams(preset="v2")
SUM_W = 28
TIMINGS = {"1080p60": (VideoTiming(1080, 1125, 2200), (1920, 1080)), "720p60": (VideoTiming(720, 750, 1650), (1280, 720))}
P_OUT = ("p_slot", "p_taken", "p_log2_d", "p_reg_x", "p_reg_y", "p_reg_w", "p_reg_h", "p_clocks", "p_first_line",
         "p_release", "p_next_line")


def state(w: float, h: float, x: float, y: float, lost: bool) -> dict[str, int]:
    return {"w8": int(w * 256), "h8": int(h * 256), "c8x": int(x * 256), "c8y": int(y * 256), "lost": int(lost)}


def random_state(rng: random.Random, fw: int, fh: int) -> dict[str, int]:
    r = rng.random()
    if r < 0.15:                                          # tall: its region spans the frame
        w, h = rng.uniform(40, 300), rng.uniform(fh * 0.7, fh - 2)
    elif r < 0.3:
        w, h = rng.uniform(3, fw - 2), rng.uniform(3, fh - 2)
    else:
        w, h = rng.uniform(8, 120), rng.uniform(16, 240)
    return state(w, h, rng.uniform(0, fw - 1), rng.uniform(0, fh - 1), rng.random() < 0.3)


def demand(s: dict[str, int], slot: int, fw: int, fh: int):
    return ms_job_demand(s["w8"], s["h8"], (s["c8x"], s["c8y"]), bool(s["lost"]), (fh, fw), slot, TP, FixedParams())


class PlanTB:
    def __init__(self, dut):
        self.dut = dut
        self.rng = random.Random(5)
        self.targets: list[tuple[int, dict[str, int]]] = []     # age order: (slot, state)
        self.counts = {"taken": 0, "held": 0, "add0": 0, "add1": 0, "add2": 0}

    async def reset(self):
        d = self.dut
        for s in ("rst", "start", "st_valid", "a_offer", "a_full", "st_lost"):
            getattr(d, s).value = Immediate(0)
        for s in ("n_live", "st_slot", "a_clocks", "a_release", "a_next"):
            getattr(d, s).value = Immediate(0)
        for s in ("st_w8", "st_h8", "st_c8x", "st_c8y"):
            getattr(d, s).value = Immediate(3 << 8)
        cocotb.start_soon(Clock(d.clk, 10, unit="ns").start(start_high=False))
        cocotb.start_soon(self.records())
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        await RisingEdge(d.clk)

    def timing(self, t: VideoTiming):
        d = self.dut
        d.frame_lines.value, d.line_clocks.value, d.blank_clocks.value = t.frame_lines, t.line_clocks, t.blank_clocks

    async def records(self):
        """The state records: st_req -> st_valid with the k-th oldest target, 0 .. 3 clocks later."""
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            if not int(d.st_req.value):
                continue
            k = int(d.st_index.value)
            slot, s = self.targets[k]
            await RisingEdge(d.clk)
            for _ in range(self.rng.randint(0, 3)):
                await RisingEdge(d.clk)
            d.st_slot.value = slot
            for key, v in s.items():
                getattr(d, "st_" + key).value = v
            d.st_valid.value = 1
            await RisingEdge(d.clk)
            d.st_valid.value = 0
            for key in ("w8", "c8x"):                    # the record's data changes after: must not matter
                getattr(d, "st_" + key).value = self.rng.getrandbits(len(getattr(d, "st_" + key)))

    async def wait_pulse(self, name: str, limit: int = 20000) -> None:
        for _ in range(limit):
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            if int(getattr(self.dut, name).value):
                return
        raise AssertionError(f"no {name} within {limit} clocks")

    async def frame(self, targets: list[dict[str, int]], adds: list[tuple], cfg: MultiCoreConfig,
                    size: tuple[int, int]) -> None:
        d = self.dut
        fw, fh = size
        slots = self.rng.sample(range(cfg.max_targets), len(targets))
        self.targets = list(zip(slots, targets))
        demands = [demand(s, slot, fw, fh) for slot, s in self.targets]
        plan = plan_frame(demands, cfg)
        while True:                                      # start when busy = 0
            await ReadOnly()
            if not int(d.busy.value):
                break
            await RisingEdge(d.clk)
        await RisingEdge(d.clk)
        d.start.value, d.n_live.value, d.frame_w.value, d.frame_h.value = 1, len(targets), fw, fh
        await RisingEdge(d.clk)
        d.start.value = 0
        for (slot, s), dm in zip(self.targets, demands):
            await self.wait_pulse("p_valid")
            g = _geometry(s["w8"], s["h8"], (s["c8x"], s["c8y"]), bool(s["lost"]), fw, fh, TP, FixedParams())
            taken = slot in plan.tracked
            exp = (slot, int(taken), g.d.bit_length() - 1, g.region.x, g.region.y, dm.cols, dm.rows, dm.clocks,
                   dm.first_line, dm.release_line, dm.next_line)
            got = tuple(int(getattr(d, o).value) for o in P_OUT)
            assert got == exp, f"target {slot} {s}: got {dict(zip(P_OUT, got))}, model {dict(zip(P_OUT, exp))}"
            self.counts["taken" if taken else "held"] += 1
        await self.wait_pulse("plan_done")
        none = (1 << SUM_W) - 1
        assert int(d.plan_clocks.value) == plan.clocks, f"plan clocks {int(d.plan_clocks.value)} != {plan.clocks}"
        assert int(d.plan_budget.value) == (plan.budget if plan.tracked else none), \
            f"plan budget {int(d.plan_budget.value)} != {plan.budget}"
        jobs, n_live = list(plan.jobs), len(targets)
        for box in adds:
            try:
                new = init_demand(box, fw, fh, 99, TP, FixedParams())
            except ValueError:
                continue
            want = check_add(jobs, n_live, new, cfg)
            await RisingEdge(d.clk)
            while True:
                await ReadOnly()
                if int(d.a_ready.value):
                    break
                await RisingEdge(d.clk)
            await RisingEdge(d.clk)
            d.a_offer.value, d.a_full.value = 1, int(n_live >= cfg.max_targets)
            d.a_clocks.value, d.a_release.value, d.a_next.value = new.clocks, new.release_line, new.next_line
            await RisingEdge(d.clk)
            d.a_offer.value = 0
            await self.wait_pulse("a_done", 200)
            assert int(d.a_code.value) == want, f"add {box}: code {int(d.a_code.value)}, model {want}"
            self.counts[f"add{want}"] += 1
            if want == ADD_OK:
                jobs.append(new)
                n_live += 1
        await RisingEdge(d.clk)


@cocotb.test()
async def run_test(dut):
    mt = int(json.loads(os.environ["MSTRACK_FRAME_PLAN"])["max_targets"])
    real = bool(json.loads(os.environ["MSTRACK_FRAME_PLAN"])["real"])
    tb = PlanTB(dut)
    await tb.reset()
    rng = random.Random(17)
    n_frames = 0
    for name, (t, (fw, fh)) in TIMINGS.items():
        cfg = MultiCoreConfig(max_targets=mt, timing=t)
        tb.timing(t)
        await ClockCycles(dut.clk, 2)
        small = [state(30, 60, 100 + 110 * i % (fw - 200), 200 + 37 * i, False) for i in range(mt)]
        frames = [
            ([], [(10, 10, 60, 80)]),                                              # no live target
            ([state(200, fh - 2, fw / 2, fh / 2, False)], []),                     # the blanking as slack
            (small, [(500, 300, 40, 40)]),                                         # MAX_TARGETS, then full
            ([state(60, 120, 300, 500, True), state(60, 120, 900, 500, True), state(40, fh - 4, 700, fh / 2, False),
              *small[:max(0, mt - 4)], state(20, 40, 1000, 100, False)][:mt], [(20, 20, 40, 40), (fw - 400, fh - 300, 300, 280)]),
        ]
        for _ in range(12):
            n = rng.randint(0, mt)
            frames.append(([random_state(rng, fw, fh) for _ in range(n)],
                           [(rng.uniform(0, fw - 60), rng.uniform(0, fh - 60), rng.uniform(8, 400), rng.uniform(8, 400))
                            for _ in range(rng.randint(0, 3))]))
        if real and name == "1080p60":
            rs = [{k: v for k, v in st.items() if not k.startswith("frame")}
                  for st in tracker_states(("Deer", "Football1", "MotorRolling"), 40, TP)]
            for i in range(0, len(rs), mt):
                frames.append((rs[i:i + mt], []))
        for targets, adds in frames:
            await tb.frame(targets, adds, cfg, (fw, fh))
            n_frames += 1
    dut._log.info("%d frames match the model (MAX_TARGETS %d): %s", n_frames, mt, tb.counts)
    assert tb.counts["held"] > 0 and tb.counts["taken"] > 0 and tb.counts["add0"] > 0, tb.counts


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_frame_plan"
MODULE = "test_ms_frame_plan"


def generics(max_targets: int) -> dict[str, int]:
    return {"MAX_TARGETS": max_targets, **job_demand_generics(TP), "LC_W": 13, "SUM_W": SUM_W}


def _run(max_targets: int, real: bool, sim, waves: bool) -> None:
    sim(TOP, MODULE, generics(max_targets), hdl.rtl_sources(TOP), waves=waves,
        build_name=f"{sim.__name__}_{TOP}_{max_targets}",
        extra_env={"MSTRACK_FRAME_PLAN": json.dumps({"max_targets": max_targets, "real": real})})


@pytest.mark.ghdl
def test_ms_frame_plan(hdl_waves):
    """MAX_TARGETS 16, with tracker states from real frames."""
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"the real-frame states need the dev sequences in {SEQ_ROOT} (../shared)")
    _run(16, True, hdl.run_ghdl, hdl_waves)


@pytest.mark.ghdl
def test_ms_frame_plan_max4(hdl_waves):
    """MAX_TARGETS 4: the add refused for every slot live, more frames that hold."""
    _run(4, False, hdl.run_ghdl, hdl_waves)


@pytest.mark.verilator
def test_ms_frame_plan_verilator(hdl_waves):
    """The GHDL -> Verilog netlist under Verilator, MAX_TARGETS 4."""
    _run(4, False, hdl.run_verilator, hdl_waves)
