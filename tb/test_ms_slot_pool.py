"""cocotb test bench + pytest entry points for rtl/ms_slot_pool.vhd (the region slots of the
shared-engine multi-target core: one ms_slot_capture and one ms_region_ram per slot, one read port).

Each frame gives every slot a load between frames, a ``load_now`` before its region, or no load;
the regions overlap (a pixel inside several regions is written into each slot).  The bench streams
the frame (ms_frontend's interior stream, with gaps) and checks, value by value through the read
port:

* the slot whose region is released first is read back while the frame still streams in (the
  raster-slack schedule: a job reads its slot as soon as it is released, other slots still being
  written): its region is ``ms_slot_capture(bins, D, region)``;
* after the frame every slot is read back: a slot captured in the frame holds its new region, a slot
  without a load still holds the region it captured before;
* ``released`` pulses once per captured slot, ``late`` never; in an abandoned frame only the slots
  whose region ended above the error are released (and hold it whole), and the slots captured again
  afterwards hold their new regions.

Run: ``.venv/bin/python -m pytest tb/test_ms_slot_pool.py``.
"""
from __future__ import annotations

import random

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from mstrack.fixed.blocks_v2 import ms_slot_capture
from mstrack.hw.hdl import dut_generics

from test_ms_slot_capture import H, W, Load, pixel_index, random_region

DEFAULTS = {"N_SLOTS": 3, "LANES": 4, "COORD_W": 12, "REGION_MAX": 24, "STRIDE": 6, "ADDR_W": 8, "DATA_W": 9,
            "LOG2_D_MAX": 4, "RD_LAT": 3, "WR_LAT": 1}


class PoolTB:
    def __init__(self, dut):
        self.dut = dut
        g = dut_generics(DEFAULTS)
        self.n, self.lanes, self.stride = int(g["N_SLOTS"]), int(g["LANES"]), int(g["STRIDE"])
        self.addr_w, self.data_w, self.rmax = int(g["ADDR_W"]), int(g["DATA_W"]), int(g["REGION_MAX"])
        self.lat = int(g["RD_LAT"]) + 1
        for s in ("rst", "frame_start", "frame_end", "frame_error", "ip_valid", "load", "load_now"):
            getattr(dut, s).value = Immediate(0)
        for s in ("ip_x", "ip_y", "ip_data", "dec_log2", "fx0", "fy0", "fx1", "fy1", "load_slot", "rd_slot", "raddr"):
            getattr(dut, s).value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        self.released: list[list[int]] = [[] for _ in range(self.n)]
        self.lates = 0
        self.cycle = 0

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0

    async def monitor(self):
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            self.cycle += 1
            rel, late = int(d.released.value), int(d.late.value)
            for s in range(self.n):
                if rel >> s & 1:
                    self.released[s].append(self.cycle)
            self.lates += bin(late).count("1")

    def set_load(self, slot: int | None, ld: Load | None):
        d = self.dut
        d.load.value = int(ld is not None)
        d.load_now.value = int(ld is not None and ld.now)
        if ld is not None:
            x, y, w, h = ld.reg
            d.load_slot.value = slot
            d.dec_log2.value = ld.d.bit_length() - 1
            d.fx0.value, d.fy0.value, d.fx1.value, d.fy1.value = x * ld.d, y * ld.d, (x + w) * ld.d, (y + h) * ld.d

    async def read_regions(self, regions: dict[int, tuple[int, int, int, int]]) -> dict[int, np.ndarray]:
        """Slot regions read back through the read port, one read per clock, the slots interleaved
        word by word (so the read multiplexer's slot must follow its address through the pipeline)."""
        d = self.dut
        out = {s: np.zeros((r[3], r[2]), np.int64) for s, r in regions.items()}
        words = {s: [(ry, j) for ry in range(r[3]) for j in range(-(-r[2] // self.lanes))] for s, r in regions.items()}
        reqs = []
        for i in range(max(len(v) for v in words.values())):
            reqs += [(s, *words[s][i]) for s in regions if i < len(words[s])]
        m = (1 << self.data_w) - 1
        for t in range(len(reqs) + self.lat):
            await FallingEdge(d.clk)
            if t < len(reqs):
                s, ry, j = reqs[t]
                d.rd_slot.value = s
                d.raddr.value = sum((ry * self.stride + j) << (b * self.addr_w) for b in range(self.lanes))
            await RisingEdge(d.clk)
            await ReadOnly()
            u = t - (self.lat - 1)
            if 0 <= u < len(reqs):
                s, ry, j = reqs[u]
                v = int(d.rdata.value)
                for b in range(self.lanes):
                    if j * self.lanes + b < regions[s][2]:
                        out[s][ry, j * self.lanes + b] = (v >> (b * self.data_w)) & m
        await RisingEdge(d.clk)
        return out

    async def early_read(self, slot: int, want: np.ndarray, reg, done: list):
        """Read a slot as soon as it is released, while the frame streams on."""
        n0 = len(self.released[slot])
        while len(self.released[slot]) == n0:
            await RisingEdge(self.dut.clk)
        got = (await self.read_regions({slot: reg}))[slot]
        done.append(np.array_equal(got, want))

    async def run_frame(self, bins: np.ndarray, pre: dict[int, Load], now: dict[int, Load], rng: random.Random,
                        gap: float, error_at: int | None = None) -> tuple[bool, int]:
        """Stream one frame; returns (abandoned, cycle of its frame_end)."""
        d = self.dut
        for s, ld in pre.items():
            self.set_load(s, ld)
            await RisingEdge(d.clk)
        self.set_load(None, None)
        d.frame_start.value = 1
        await RisingEdge(d.clk)
        d.frame_start.value = 0
        await ClockCycles(d.clk, 2)
        at = {ld.at: (s, ld) for s, ld in now.items()}
        i = 0
        for y in range(1, H - 1):
            for x in range(1, W - 1):
                while rng.random() < gap:
                    d.ip_valid.value = 0
                    await RisingEdge(d.clk)
                if error_at is not None and i == error_at:
                    d.ip_valid.value = 0
                    d.frame_error.value = 1
                    await RisingEdge(d.clk)
                    d.frame_error.value = 0
                    return True, self.cycle
                d.ip_valid.value = 1
                d.ip_x.value, d.ip_y.value, d.ip_data.value = x, y, int(bins[y, x])
                self.set_load(*at.pop(i, (None, None)))
                await RisingEdge(d.clk)
                self.set_load(None, None)
                i += 1
            d.ip_valid.value = 0
            await RisingEdge(d.clk)
        d.frame_end.value = 1
        await RisingEdge(d.clk)
        d.frame_end.value = 0
        assert not at, "a load_now was not driven"
        return False, self.cycle


def plan(rng: random.Random, n: int, rmax: int) -> tuple[dict[int, Load], dict[int, Load]]:
    """Per slot: a load between frames, a load_now before its region (at a pixel no other slot's
    load_now takes), or none; at least one slot loads."""
    pre: dict[int, Load] = {}
    now: dict[int, Load] = {}
    taken: set[int] = set()
    while not pre and not now:
        for s in range(n):
            kind = rng.choice(["pre", "pre", "now", "none"])
            d = rng.choice([1, 1, 2, 4, 8, 16])
            ld = Load(d, random_region(rng, d, rmax))
            if kind == "now" and ld.reg[1] * d >= 2:
                ld.now = True
                while ld.at < 0 or ld.at in taken:
                    ld.at = pixel_index(rng.randint(1, W - 2), rng.randint(1, ld.reg[1] * d - 1))
                taken.add(ld.at)
                now[s] = ld
            elif kind != "none":
                pre[s] = ld
    return pre, now


@cocotb.test()
async def run_test(dut):
    tb = PoolTB(dut)
    await tb.reset()
    cocotb.start_soon(tb.monitor())
    await ClockCycles(dut.clk, 2)
    held: dict[int, tuple[Load, np.ndarray]] = {}      # slot -> (its last capture, the region it holds)
    checked = 0
    for gap, seed in ((0.0, 21), (0.3, 22)):
        rng, nrng = random.Random(seed), np.random.default_rng(seed)
        for k in range(8):
            bins = nrng.integers(0, 1 << tb.data_w, size=(H, W))
            pre, now = plan(rng, tb.n, tb.rmax)
            loads = {**pre, **now}
            want = {s: ms_slot_capture(bins, ld.d, *ld.reg) for s, ld in loads.items()}
            n_rel = [len(r) for r in tb.released]
            error_at = pixel_index(10, 20) if k == 5 else None
            # the slot whose region ends first is read while the frame streams on
            first = min(loads, key=lambda s: (loads[s].reg[1] + loads[s].reg[3]) * loads[s].d)
            early: list[bool] = []
            if error_at is None:
                cocotb.start_soon(tb.early_read(first, want[first], loads[first].reg, early))
            aborted, _ = await tb.run_frame(bins, pre, now, rng, gap, error_at)
            await ClockCycles(dut.clk, 8)
            if aborted:
                # armed: the loads between frames and the load_nows before the error; released: those
                # whose region ended above the error's row (20), complete in their slots
                armed = {s: ld for s, ld in loads.items() if not ld.now or ld.at < error_at}
                for s in range(tb.n):
                    ld = armed.get(s)
                    exp = int(ld is not None and (ld.reg[1] + ld.reg[3] - 1) * ld.d < 20)
                    assert len(tb.released[s]) - n_rel[s] == exp, f"abandoned frame: slot {s} released"
                    if exp:
                        held[s] = (ld, want[s])
                    elif ld is not None:
                        held.pop(s, None)           # half written: unknown until captured again
                continue
            while not early:
                await RisingEdge(dut.clk)
            assert early == [True], f"gap {gap}, frame {k}: slot {first} read at its release differs"
            for s in range(tb.n):
                got_rel = len(tb.released[s]) - n_rel[s]
                assert got_rel == (1 if s in loads else 0), f"gap {gap}, frame {k}: slot {s} released {got_rel} times"
                if s in loads:
                    held[s] = (loads[s], want[s])
            got = await tb.read_regions({s: ld.reg for s, (ld, _) in held.items()})
            for s, (ld, region) in held.items():
                assert np.array_equal(got[s], region), f"gap {gap}, frame {k}: slot {s} region {ld.reg}"
                checked += 1
            assert tb.lates == 0, "late pulsed"
    assert checked >= 4 * tb.n + 8, f"only {checked} regions checked"
    dut._log.info("%d slot regions read back and checked", checked)


# ---------------------------------------------------------------- pytest entry points

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_slot_pool"
MODULE = "test_ms_slot_pool"


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", [
    pytest.param(DEFAULTS, id="slots3"),
    pytest.param({**DEFAULTS, "N_SLOTS": 1, "LANES": 2, "STRIDE": 12, "ADDR_W": 9, "RD_LAT": 1, "WR_LAT": 0},
                 id="slots1_lanes2"),
])
def test_ms_slot_pool(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
