"""cocotb test bench + pytest entry points for rtl/ms_slot_pool.vhd (the region slots of the
shared-engine multi-target core: per slot a colour RAM and an orientation RAM, each with its own
ms_slot_capture, and one read port), behind ms_frontend as the core joins them
(tb/ms_slot_pool_tb_top.vhd): colour from the all-pixel stream delayed to the frame events (``ad_*``),
orientation from the interior stream.

Each frame (random RGB, 42 x 37) gives every slot a load between frames, a ``load_now`` before its
region, or no load; the regions overlap, and some reach the frame's border (an init rectangle's).  The
bench streams the frame beat by beat (with gaps) and checks, value by value through the read port:

* the slot whose region is released first is read back while the frame still streams in (the
  raster-slack schedule: a job reads its slot as soon as it is released, other slots still being
  written): its colour is ``ms_slot_capture(ms_colour_bin(frame), D, region)`` on every pixel, border
  included, its orientation ``ms_slot_capture(ms_orient_bin(ms_grey(frame)), D, region)`` on every
  pixel off the frame's border (the interior stream has no border pixel; ms_init_job never reads one);
* after the frame every slot is read back: a slot captured in the frame holds its new region, a slot
  without a load still holds the region it captured before;
* ``released`` pulses once per captured slot, ``late`` never; in a frame cut by a short line at the
  start of row 20, only the slots whose region ended where both streams had brought the row below it
  are released (and hold it whole): the last row at most 17 with orientation (the interior stream is
  one line behind), 18 colour only; the slots captured again afterwards hold their new regions.

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

from mstrack.fixed.blocks import ms_colour_bin, ms_grey
from mstrack.fixed.blocks_v2 import ms_orient_bin, ms_slot_capture
from mstrack.hw.hdl import dut_generics

from test_ms_frontend import frame_beats, random_frame
from test_ms_slot_capture import H, W, Load, border_region, random_region

DEFAULTS = {"N_SLOTS": 3, "LANES": 4, "COORD_W": 12, "MAX_FRAME_W": 64, "REGION_MAX": 24, "STRIDE": 6,
            "ADDR_W": 8, "COLOUR_BITS": 3, "ORIENT": True, "ORIENT_T": 64, "LOG2_D_MAX": 4, "RD_LAT": 3,
            "WR_LAT": 1}
ERROR_ROW = 20       # the cut frame: a short line at the start of this row


class PoolTB:
    def __init__(self, dut):
        self.dut = dut
        g = dut_generics(DEFAULTS)
        self.n, self.lanes, self.stride = int(g["N_SLOTS"]), int(g["LANES"]), int(g["STRIDE"])
        self.addr_w, self.rmax = int(g["ADDR_W"]), int(g["REGION_MAX"])
        self.cbits, self.orient_t = int(g["COLOUR_BITS"]), int(g["ORIENT_T"])
        self.orient = str(g["ORIENT"]).lower() in ("true", "1")
        self.lat = int(g["RD_LAT"]) + 2
        for s in ("rst", "in_valid", "in_sof", "in_eol", "load", "load_now"):
            getattr(dut, s).value = Immediate(0)
        for s in ("in_data", "dec_log2", "fx0", "fy0", "fx1", "fy1", "load_slot", "rd_slot", "raddr"):
            getattr(dut, s).value = Immediate(0)
        dut.frame_width.value = Immediate(W)
        dut.frame_height.value = Immediate(H)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        self.released: list[list[int]] = [[] for _ in range(self.n)]
        self.lates = 0
        self.cycle = 0
        self.ends = 0

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
            self.ends += int(d.ad_end.value) + int(d.frame_error.value)

    def set_load(self, slot: int | None, ld: Load | None):
        d = self.dut
        d.load.value = int(ld is not None)
        d.load_now.value = int(ld is not None and ld.now)
        if ld is not None:
            x, y, w, h = ld.reg
            d.load_slot.value = slot
            d.dec_log2.value = ld.d.bit_length() - 1
            d.fx0.value, d.fy0.value, d.fx1.value, d.fy1.value = x * ld.d, y * ld.d, (x + w) * ld.d, (y + h) * ld.d

    async def read_regions(self, regions: dict[int, tuple[int, int, int, int]]) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """Slot regions (colour, orientation) read back through the read port, one read per clock, the
        slots interleaved word by word (so the read multiplexer's slot must follow its address)."""
        d = self.dut
        out = {s: (np.zeros((r[3], r[2]), np.int64), np.zeros((r[3], r[2]), np.int64)) for s, r in regions.items()}
        words = {s: [(ry, j) for ry in range(r[3]) for j in range(-(-r[2] // self.lanes))] for s, r in regions.items()}
        reqs = []
        for i in range(max(len(v) for v in words.values())):
            reqs += [(s, *words[s][i]) for s in regions if i < len(words[s])]
        cw = 3 * self.cbits
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
                vc, vo = int(d.rdata.value), int(d.robin.value)
                for b in range(self.lanes):
                    if j * self.lanes + b < regions[s][2]:
                        out[s][0][ry, j * self.lanes + b] = (vc >> (b * cw)) & ((1 << cw) - 1)
                        out[s][1][ry, j * self.lanes + b] = (vo >> (b * 4)) & 15
        await RisingEdge(d.clk)
        return out

    def expected(self, frame: np.ndarray, ld: Load) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(colour, orientation, where the orientation is defined: off the frame's border) of a region."""
        cb = ms_slot_capture(ms_colour_bin(frame, self.cbits), ld.d, *ld.reg)
        ob = ms_slot_capture(ms_orient_bin(ms_grey(frame), self.orient_t), ld.d, *ld.reg)
        ys, xs = np.mgrid[0: cb.shape[0], 0: cb.shape[1]]
        fx, fy = (ld.reg[0] + xs) * ld.d, (ld.reg[1] + ys) * ld.d
        inner = (fx >= 1) & (fx <= W - 2) & (fy >= 1) & (fy <= H - 2)
        return cb, ob, inner

    def compare(self, got: tuple[np.ndarray, np.ndarray], want: tuple[np.ndarray, np.ndarray, np.ndarray]) -> str:
        """'' when the slot holds the region, else what differs."""
        if not np.array_equal(got[0], want[0]):
            return f"colour: {int(np.sum(got[0] != want[0]))} of {want[0].size} pixels differ"
        if self.orient and not np.array_equal(got[1][want[2]], want[1][want[2]]):
            return f"orientation: {int(np.sum(got[1][want[2]] != want[1][want[2]]))} pixels differ"
        if not self.orient and np.any(got[1]):
            return "orientation read without ORIENT"
        return ""

    async def early_read(self, slot: int, want, reg, done: list):
        """Read a slot as soon as it is released, while the frame streams on."""
        n0 = len(self.released[slot])
        while len(self.released[slot]) == n0:
            await RisingEdge(self.dut.clk)
        got = (await self.read_regions({slot: reg}))[slot]
        done.append(self.compare(got, want))

    async def run_frame(self, frame: np.ndarray, pre: dict[int, Load], now: dict[int, Load], rng: random.Random,
                        gap: float, cut: bool = False) -> None:
        """Stream one frame (cut: a short line at the start of ERROR_ROW) and wait for its end event."""
        d = self.dut
        for s, ld in pre.items():
            self.set_load(s, ld)
            await RisingEdge(d.clk)
        self.set_load(None, None)
        await RisingEdge(d.clk)
        at = {ld.at: (s, ld) for s, ld in now.items()}
        beats = frame_beats(frame)
        if cut:
            k = ERROR_ROW * W
            beats = beats[:k] + [beats[k][:2] + (1,) + beats[k][3:]]
        n_end = self.ends
        for i, (data, sof, eol, _, _) in enumerate(beats):
            while rng.random() < gap:
                d.in_valid.value = 0
                self.set_load(*at.pop(i, (None, None)) if rng.random() < 0.5 else (None, None))
                await RisingEdge(d.clk)
                self.set_load(None, None)
            d.in_valid.value = 1
            d.in_data.value, d.in_sof.value, d.in_eol.value = data, sof, eol
            self.set_load(*at.pop(i, (None, None)))
            await RisingEdge(d.clk)
            self.set_load(None, None)
        d.in_valid.value = 0
        assert not at, "a load_now was not driven"
        while self.ends == n_end:
            await RisingEdge(d.clk)


def plan(rng: random.Random, n: int, rmax: int) -> tuple[dict[int, Load], dict[int, Load]]:
    """Per slot: a load between frames, a load_now before its region (at an input beat above its first
    row that no other slot's load_now takes), or none; at least one slot loads.  A third of the
    regions reach the frame's border."""
    pre: dict[int, Load] = {}
    now: dict[int, Load] = {}
    taken: set[int] = set()
    while not pre and not now:
        for s in range(n):
            kind = rng.choice(["pre", "pre", "now", "none"])
            d = rng.choice([1, 1, 2, 4, 8, 16])
            reg = border_region(rng, d, rmax) if rng.random() < 1 / 3 else random_region(rng, d, rmax)
            ld = Load(d, reg)
            if kind == "now" and ld.reg[1] * d >= 1:
                ld.now = True
                while ld.at < 0 or ld.at in taken:
                    ld.at = rng.randint(0, ld.reg[1] * d * W - 1)
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
    held: dict[int, tuple[Load, tuple]] = {}      # slot -> (its last capture, the region it holds)
    checked = 0
    last_ok = ERROR_ROW - (3 if tb.orient else 2)
    for gap, seed in ((0.0, 21), (0.3, 22)):
        rng, nrng = random.Random(seed), np.random.default_rng(seed)
        for k in range(8):
            frame = random_frame(nrng, H, W)
            pre, now = plan(rng, tb.n, tb.rmax)
            loads = {**pre, **now}
            want = {s: tb.expected(frame, ld) for s, ld in loads.items()}
            n_rel = [len(r) for r in tb.released]
            cut = k == 5
            # the slot whose region ends first is read while the frame streams on
            first = min(loads, key=lambda s: (loads[s].reg[1] + loads[s].reg[3]) * loads[s].d)
            early: list[str] = []
            if not cut:
                cocotb.start_soon(tb.early_read(first, want[first], loads[first].reg, early))
            if cut:
                now = {s: ld for s, ld in now.items() if ld.at < ERROR_ROW * W}
                loads = {**pre, **now}
            await tb.run_frame(frame, pre, now, rng, gap, cut)
            await ClockCycles(dut.clk, 12)
            if cut:
                for s in range(tb.n):
                    ld = loads.get(s)
                    exp = int(ld is not None and (ld.reg[1] + ld.reg[3] - 1) * ld.d <= last_ok)
                    assert len(tb.released[s]) - n_rel[s] == exp, f"cut frame: slot {s} released"
                    if exp:
                        held[s] = (ld, want[s])
                    elif ld is not None:
                        held.pop(s, None)           # half written: unknown until captured again
                continue
            while not early:
                await RisingEdge(dut.clk)
            assert early == [""], f"gap {gap}, frame {k}: slot {first} read at its release: {early[0]}"
            for s in range(tb.n):
                got_rel = len(tb.released[s]) - n_rel[s]
                assert got_rel == (1 if s in loads else 0), f"gap {gap}, frame {k}: slot {s} released {got_rel} times"
                if s in loads:
                    held[s] = (loads[s], want[s])
            got = await tb.read_regions({s: ld.reg for s, (ld, _) in held.items()})
            for s, (ld, region) in held.items():
                msg = tb.compare(got[s], region)
                assert not msg, f"gap {gap}, frame {k}: slot {s} D {ld.d} region {ld.reg}: {msg}"
                checked += 1
            assert tb.lates == 0, "late pulsed"
    assert checked >= 4 * tb.n + 8, f"only {checked} regions checked"
    dut._log.info("%d slot regions read back and checked", checked)


# ---------------------------------------------------------------- pytest entry points

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_slot_pool_tb_top"
MODULE = "test_ms_slot_pool"
WRAPPER = hdl.TB_DIR / "ms_slot_pool_tb_top.vhd"


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", [
    pytest.param(DEFAULTS, id="slots3"),
    pytest.param({**DEFAULTS, "N_SLOTS": 1, "LANES": 2, "STRIDE": 12, "ADDR_W": 9, "RD_LAT": 1, "WR_LAT": 0,
                  "ORIENT": False}, id="slots1_lanes2_colour"),
])
def test_ms_slot_pool(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=hdl_waves)
