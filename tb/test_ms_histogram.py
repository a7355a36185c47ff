"""cocotb test bench + pytest entry points for rtl/ms_histogram.vhd.

Random per-lane pixel streams (valid mask, bin, k, dx) + dy are accumulated
and then read out and cleared through the bin port; the result is compared
exactly with the accumulation that mstrack.fixed.blocks.ms_histogram defines
(H = sum k, N = count, SX = sum dx, SY = sum dy per bin; H = N when flat).
Streams drawn from very few bins, back to back or with 1-2 idle clocks, hit
the read-modify-write hazards (same bin in the same lane 1, 2, 3 clocks apart).
Full speed and throttled (random idle cycles) runs; BIN_RD_LAT and the clear
after reset are checked; ``ready`` must rise after N_BINS clocks.

With N_ORIENT > 1 (orientation banks, tracker v2's joint bins) every lane pixel
also gets an orientation o: the expected read-out is mstrack.fixed.blocks.
ms_histogram_banks of the histogram of the joint bins N_ORIENT u + o, and every
bank of every address is compared (bin_*_all; bin_h/n/sx/sy must equal bank 0).
Those streams draw from few colour bins x few orientations (runs of one joint
bin; one colour bin with orientations changing beat to beat, 1, 2, 3 beats
apart) plus a directed pattern.  Each pass is read and cleared; the next pass
(and the all-zero read after reset) proves the clear.

Run: ``.venv/bin/python -m pytest tb/test_ms_histogram.py``.
"""

from __future__ import annotations

import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.blocks import Hist, ms_histogram_banks
from mstrack.hw.hdl import dut_generics

BIN_RD_LAT = 3
HIST_ACC_LAT = 4   # rtl/ms_histogram.vhd header: last_done after in_last


def model_hist(pix: list[tuple[int, int, int, int]], n_bins: int, flat: bool) -> dict[str, np.ndarray]:
    """The sums of mstrack.fixed.blocks.ms_histogram for a list of (bin, k, dx, dy) inside pixels."""
    b = np.array([p[0] for p in pix], np.int64).reshape(-1)
    k = np.array([p[1] for p in pix], np.float64)
    dx = np.array([p[2] for p in pix], np.float64)
    dy = np.array([p[3] for p in pix], np.float64)

    def acc(wt):
        return np.rint(np.bincount(b, weights=wt, minlength=n_bins)).astype(np.int64)
    N = np.bincount(b, minlength=n_bins).astype(np.int64)
    return {"H": N if flat else acc(k), "N": N, "SX": acc(dx), "SY": acc(dy)}


def model_banks(pix: list[tuple[int, int, int, int, int]], n_bins: int, n_orient: int,
                flat: bool) -> dict[str, np.ndarray]:
    """(n_bins, n_orient) read-out for (bin, obin, k, dx, dy) pixels: ms_histogram_banks of the
    histogram of the joint bins n_orient bin + obin."""
    joint = [(u * n_orient + o, k, dx, dy) for u, o, k, dx, dy in pix]
    h = model_hist(joint, n_bins * n_orient, flat)
    b = ms_histogram_banks(Hist(h["H"], h["N"], h["SX"], h["SY"]), n_orient)
    return {"H": b.H, "N": b.N, "SX": b.SX, "SY": b.SY}


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
        self.no = int(g.get("N_ORIENT", 1))
        self.ow = int(g.get("ORIENT_W", 4))
        self.widths = {"H": int(g["HIST_W"]), "N": int(g["COUNT_W"]), "SX": int(g["POSSUM_W"]),
                       "SY": int(g["POSSUM_W"])}
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

    def drive(self, beat, last: bool):
        """Set the pixel inputs to one beat (valid_mask, [(bin, obin, k, dx)] * L, dy)."""
        d = self.dut
        bw, dw, kw = self.bw, self.dw, self.kw
        mask, lanes, dy = beat
        b = k = x = o = 0
        for lane, (bb, oo, kk, dx) in enumerate(lanes):
            b |= bb << (lane * bw)
            o |= oo << (lane * self.ow)
            k |= kk << (lane * kw)
            x |= (dx & ((1 << dw) - 1)) << (lane * dw)
        d.in_valid.value = mask
        d.in_bin.value = b
        d.in_obin.value = o
        d.in_k.value = k
        d.in_dx.value = x
        d.in_dy.value = dy
        d.in_last.value = int(last)

    async def feed(self, beats, rng: random.Random | None):
        """beats: list of (valid_mask, [(bin, obin, k, dx)] * L, dy).  Returns after last_done."""
        d = self.dut
        i = 0
        while i < len(beats):
            if rng is not None and rng.random() < 0.3:
                d.in_valid.value = 0
                d.in_last.value = 0
            else:
                self.drive(beats[i], i == len(beats) - 1)
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

    async def read_bins(self, rng: random.Random | None, follow=()) -> tuple[dict[str, np.ndarray], int]:
        """Read and clear every address, n_bins - 1 down to 0: {H, N, SX, SY} of shape
        (n_bins, N_ORIENT), bank o in column o (from bin_*_all; bin_h, bin_n, bin_sx, bin_sy are
        checked = bank 0).  ``follow``: the next pass's beats, driven from the clock after the last
        read on while its sums come out (its first pixels hit bin 0 1, 2, 3 clocks after its
        clear: the clear is forwarded to every bank); returns (sums, beats of follow driven)."""
        d = self.dut
        out = {k: np.zeros((self.n_bins, self.no), np.int64) for k in ("H", "N", "SX", "SY")}
        ports = {"H": d.bin_h_all, "N": d.bin_n_all, "SX": d.bin_sx_all, "SY": d.bin_sy_all}
        scalar = {"H": d.bin_h, "N": d.bin_n, "SX": d.bin_sx, "SY": d.bin_sy}
        issued: list[tuple[int, int]] = []
        got = nxt = cyc = fed = 0
        while got < self.n_bins:
            await RisingEdge(d.clk)
            cyc += 1
            if int(d.bin_rd_valid.value):
                u, c = issued.pop(0)
                assert cyc - c == BIN_RD_LAT + 1, f"read latency {cyc - c - 1}"
                for name, port in ports.items():
                    w = self.widths[name]
                    v = int(port.value)
                    for o in range(self.no):
                        f = (v >> (o * w)) & ((1 << w) - 1)
                        if name in ("SX", "SY") and f >> (w - 1):
                            f -= 1 << w
                        out[name][u, o] = f
                    sv = scalar[name].value.to_signed() if name in ("SX", "SY") else int(scalar[name].value)
                    assert sv == out[name][u, 0], f"bin_{name.lower()} {sv} != bank 0 {out[name][u, 0]}"
                got += 1
            if nxt < self.n_bins and (rng is None or rng.random() < 0.6):
                d.bin_rd_en.value = 1
                d.bin_rd_addr.value = self.n_bins - 1 - nxt
                issued.append((self.n_bins - 1 - nxt, cyc))
                nxt += 1
            else:
                d.bin_rd_en.value = 0
                # not once the last sums are out: feed() drives the next beat before the next edge
                if nxt == self.n_bins and got < self.n_bins and fed < len(follow) - 1:
                    self.drive(follow[fed], False)
                    fed += 1
        d.bin_rd_en.value = 0
        assert not issued
        return out, fed

    def random_beats(self, rng: random.Random, n: int, few_bins: int, dmax: int, kmax: int,
                     few_orient: int = 1, orient=None):
        """n beats of bins < few_bins and orientations < few_orient (or orient(beat, lane)); pixels
        as (bin, obin, k, dx, dy).  With one bank no orientation is drawn (the same streams as
        before the banks)."""
        beats, pix = [], []
        for i in range(n):
            mask = rng.randrange(1 << self.L) if rng.random() < 0.5 else (1 << self.L) - 1
            dy = rng.randint(-dmax, dmax)
            lanes = []
            for lane in range(self.L):
                u = rng.randrange(few_bins)
                o = orient(i, lane) if orient else rng.randrange(few_orient) if self.no > 1 else 0
                k = 1 if self.flat else rng.randint(1, kmax)
                dx = rng.randint(-dmax, dmax)
                lanes.append((u, o, k, dx))
                if mask >> lane & 1:
                    pix.append((u, o, k, dx, dy))
            beats.append((mask, lanes, dy))
        return beats, pix


async def run(dut, throttle: bool, seed: int):
    tb = TB(dut)
    rng = random.Random(seed)
    await tb.reset()
    # the clear after reset: everything reads 0
    got, _ = await tb.read_bins(None)
    assert not any(v.any() for v in got.values()), "RAM not cleared after reset"
    dmax = (1 << (tb.dw - 1)) - 1
    kmax = (1 << tb.kw) - 1
    if tb.no == 1:
        rounds = [(few, 1, None) for few in (1, 2, 3, tb.n_bins, 4)]
    else:
        no = tb.no
        # (colour bins, orientations, directed orientation pattern): runs of one joint bin; one colour
        # bin with every orientation; 2 x 2 (same joint bin 1, 2, 3 beats apart, other banks between);
        # everything; orientation o, o, o', o, o' ... (a lane's pattern: bank changes each beat or not)
        rounds = [(1, 1, None), (1, no, None), (2, 2, None), (tb.n_bins, no, None), (4, 3, None),
                  (1, no, lambda i, lane: (i // (1 + lane % 3) + lane) % no),
                  (2, no, lambda i, lane: (0, 1, 0, 0, 2, 0, 1, 1, no - 1)[(i + lane) % 9])]
    passes = [tb.random_beats(rng, 300, few, dmax, kmax, few_o, pattern) for few, few_o, pattern in rounds]
    fed = 0
    for rnd, (few, few_o, _) in enumerate(rounds):
        beats, pix = passes[rnd]
        await tb.feed(beats[fed:], rng if throttle else None)
        # the next pass starts while this one's last reads are in flight
        follow = passes[rnd + 1][0] if rnd + 1 < len(passes) else ()
        got, fed = await tb.read_bins(rng if throttle else None, follow)
        if follow:
            assert fed >= BIN_RD_LAT, f"{fed} beats overlap the last reads"
        exp = model_banks(pix, tb.n_bins, tb.no, tb.flat)
        assert exp["N"].sum() == len(pix) and (exp["N"] > 0).sum() >= min(few * few_o, 2 if few * few_o > 1 else 1)
        for name in ("H", "N", "SX", "SY"):
            bad = np.argwhere(got[name] != exp[name])
            assert bad.size == 0, (f"round {rnd} ({few} bins x {few_o} orientations): {name} differs at "
                                   f"(bin, bank) {bad[:8].tolist()}: got {got[name][tuple(bad[:8].T)].tolist()} "
                                   f"exp {exp[name][tuple(bad[:8].T)].tolist()}")


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
    # orientation banks (tracker v2's joint colour x orientation bins): 9 banks per lane
    pytest.param({"N_ORIENT": 9}, id="orient9"),
    pytest.param({"N_ORIENT": 9, "LANES": 1}, id="orient9_L1"),
    pytest.param({"N_ORIENT": 9, "LANES": 4}, id="orient9_L4"),
    pytest.param({"N_ORIENT": 9, "KERNEL_EPAN": 1, "KVAL_W": 9, "HIST_W": 18}, id="orient9_epan"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("var", CASES)
def test_ms_histogram(var, hdl_waves):
    gen = {**BASE, **var}
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.ghdl
def test_ms_histogram_synth_orient9(tmp_path):
    """ghdl --synth (to Verilog) of tracker v2's size with 9 orientation banks: LANES 4, BIN_W 9,
    flat, HIST_W = COUNT_W 14, POSSUM_W 21 (56-bit words): 36 RAMs of 512 words."""
    gen = {"LANES": 4, "BIN_W": 9, "N_ORIENT": 9, "D_W": 9, "KERNEL_EPAN": 0, "KVAL_W": 1, "HIST_W": 14,
           "COUNT_W": 14, "POSSUM_W": 21}
    v = hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v").read_text()
    assert "module ms_histogram" in v and "bin_sy_all" in v


@pytest.mark.verilator
@pytest.mark.parametrize("var", [pytest.param({"N_ORIENT": 9, "LANES": 4}, id="orient9_L4"),
                                 pytest.param({"N_ORIENT": 9, "LANES": 2, "KERNEL_EPAN": 1, "KVAL_W": 9,
                                               "HIST_W": 18}, id="orient9_epan")])
def test_ms_histogram_verilator(var, hdl_waves):
    """Same bench on the GHDL -> Verilog -> Verilator netlist (the synthesis path) with the banks."""
    gen = {**BASE, **var}
    hdl.run_verilator(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves)
