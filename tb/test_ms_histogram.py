"""cocotb test bench + pytest entry points for rtl/ms_histogram.vhd.

Random per-lane pixel streams (valid mask, bin, k, dx) + dy are accumulated
and then read out and cleared through the bin port; the result is compared
exactly with the accumulation that mstrack.fixed.blocks.ms_histogram defines
(H = sum k, N = count, SX = sum dx, SY = sum dy per bin; H = N when flat).
Streams drawn from very few bins, back to back or with 1-2 idle clocks, hit
the read-modify-write hazards (same bin in the same lane 1, 2, 3 clocks apart).
Full speed and throttled (random idle cycles) runs; BIN_RD_LAT and the clear
after reset are checked; ``ready`` must rise after N_BINS clocks.

Run: ``.venv/bin/python -m pytest tb/test_ms_histogram.py``.
"""

from __future__ import annotations

import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.hw.hdl import dut_generics

BIN_RD_LAT = 3
HIST_ACC_LAT = 4   # rtl/ms_histogram.vhd header: last_done after in_last


def model_hist(pix: list[tuple[int, int, int, int]], n_bins: int, flat: bool) -> dict[str, np.ndarray]:
    """The sums of mstrack.fixed.blocks.ms_histogram for a list of (bin, k, dx, dy) inside pixels."""
    b = np.array([p[0] for p in pix], np.int64)
    k = np.array([p[1] for p in pix], np.float64)
    dx = np.array([p[2] for p in pix], np.float64)
    dy = np.array([p[3] for p in pix], np.float64)

    def acc(wt):
        return np.rint(np.bincount(b, weights=wt, minlength=n_bins)).astype(np.int64)
    N = np.bincount(b, minlength=n_bins).astype(np.int64)
    return {"H": N if flat else acc(k), "N": N, "SX": acc(dx), "SY": acc(dy)}


class TB:
    def __init__(self, dut):
        self.dut = dut
        g = dut_generics()
        self.L = int(g["LANES"])
        self.bw = int(g["BIN_W"])
        self.dw = int(g["D_W"])
        self.kw = int(g["KVAL_W"])
        self.flat = int(g["KERNEL_EPAN"]) == 0
        self.n_bins = 1 << self.bw
        dut.rst.value = Immediate(1)
        dut.in_valid.value = Immediate(0)
        dut.in_last.value = Immediate(0)
        dut.bin_rd_en.value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))

    async def reset(self):
        d = self.dut
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        n = 0
        while True:
            await RisingEdge(d.clk)
            n += 1
            if int(d.ready.value):
                break
        assert n == self.n_bins + 1, f"ready after {n} clocks"

    async def feed(self, beats, rng: random.Random | None):
        """beats: list of (valid_mask, [(bin, k, dx)] * L, dy).  Returns after last_done."""
        d = self.dut
        L, bw, dw, kw = self.L, self.bw, self.dw, self.kw
        i = 0
        while i < len(beats):
            if rng is not None and rng.random() < 0.3:
                d.in_valid.value = 0
                d.in_last.value = 0
            else:
                mask, lanes, dy = beats[i]
                b = k = x = 0
                for lane, (bb, kk, dx) in enumerate(lanes):
                    b |= bb << (lane * bw)
                    k |= kk << (lane * kw)
                    x |= (dx & ((1 << dw) - 1)) << (lane * dw)
                d.in_valid.value = mask
                d.in_bin.value = b
                d.in_k.value = k
                d.in_dx.value = x
                d.in_dy.value = dy
                d.in_last.value = int(i == len(beats) - 1)
                i += 1
            await RisingEdge(d.clk)
        d.in_valid.value = 0
        d.in_last.value = 0
        n = 0
        while True:
            await RisingEdge(d.clk)
            n += 1
            if int(d.last_done.value):
                break
            assert n < 10, "no last_done"
        assert n == HIST_ACC_LAT, f"last_done {n} clocks after the last beat"

    async def read_bins(self, rng: random.Random | None) -> dict[str, np.ndarray]:
        d = self.dut
        out = {k: np.zeros(self.n_bins, np.int64) for k in ("H", "N", "SX", "SY")}
        issued: list[tuple[int, int]] = []
        got = nxt = cyc = 0
        while got < self.n_bins:
            await RisingEdge(d.clk)
            cyc += 1
            if int(d.bin_rd_valid.value):
                u, c = issued.pop(0)
                assert cyc - c == BIN_RD_LAT + 1, f"read latency {cyc - c - 1}"
                out["H"][u] = int(d.bin_h.value)
                out["N"][u] = int(d.bin_n.value)
                out["SX"][u] = d.bin_sx.value.to_signed()
                out["SY"][u] = d.bin_sy.value.to_signed()
                got += 1
            if nxt < self.n_bins and (rng is None or rng.random() < 0.6):
                d.bin_rd_en.value = 1
                d.bin_rd_addr.value = nxt
                issued.append((nxt, cyc))
                nxt += 1
            else:
                d.bin_rd_en.value = 0
        d.bin_rd_en.value = 0
        assert not issued
        return out

    def random_beats(self, rng: random.Random, n: int, few_bins: int, dmax: int, kmax: int):
        beats, pix = [], []
        for _ in range(n):
            mask = rng.randrange(1 << self.L) if rng.random() < 0.5 else (1 << self.L) - 1
            dy = rng.randint(-dmax, dmax)
            lanes = []
            for lane in range(self.L):
                u = rng.randrange(few_bins)
                k = 1 if self.flat else rng.randint(1, kmax)
                dx = rng.randint(-dmax, dmax)
                lanes.append((u, k, dx))
                if mask >> lane & 1:
                    pix.append((u, k, dx, dy))
            beats.append((mask, lanes, dy))
        return beats, pix


async def run(dut, throttle: bool, seed: int):
    tb = TB(dut)
    rng = random.Random(seed)
    await tb.reset()
    # the clear after reset: everything reads 0
    got = await tb.read_bins(None)
    assert not any(v.any() for v in got.values()), "RAM not cleared after reset"
    dmax = (1 << (tb.dw - 1)) - 1
    kmax = (1 << tb.kw) - 1
    for rnd, few in enumerate([1, 2, 3, tb.n_bins, 4]):
        beats, pix = tb.random_beats(rng, 300, few, dmax, kmax)
        await tb.feed(beats, rng if throttle else None)
        got = await tb.read_bins(rng if throttle else None)
        exp = model_hist(pix, tb.n_bins, tb.flat)
        for name in ("H", "N", "SX", "SY"):
            bad = np.nonzero(got[name] != exp[name])[0]
            assert bad.size == 0, (f"round {rnd} ({few} bins): {name} differs at {bad[:8].tolist()}: "
                                   f"got {got[name][bad[:8]].tolist()} exp {exp[name][bad[:8]].tolist()}")


@cocotb.test()
async def full_speed(dut):
    await run(dut, throttle=False, seed=11)


@cocotb.test()
async def throttled(dut):
    await run(dut, throttle=True, seed=12)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_histogram"
MODULE = "test_ms_histogram"
BASE = {"LANES": 2, "BIN_W": 6, "D_W": 5, "KERNEL_EPAN": 0, "KVAL_W": 1, "HIST_W": 12, "COUNT_W": 12,
        "POSSUM_W": 14}
CASES = [
    pytest.param({}, id="default"),
    pytest.param({"LANES": 1}, id="L1"),
    pytest.param({"LANES": 4}, id="L4"),
    pytest.param({"KERNEL_EPAN": 1, "KVAL_W": 9, "HIST_W": 18}, id="epan"),
    pytest.param({"BIN_W": 3}, id="bins8"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("var", CASES)
def test_ms_histogram(var, hdl_waves):
    gen = {**BASE, **var}
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves)
