"""cocotb test bench + pytest entry points for rtl/ms_bin_pass.vhd.

Model: :func:`mstrack.fixed.blocks.ms_bin_pass` (S, Sw, Swx, Swy) and sum(H) (k_sum).
A behavioural histogram (Python dict per pass) serves the read-and-clear port with
BIN_RD_LAT clocks of latency (throttled run: random extra delay, still in order).
Sequence per run: learn pass (Q := H), several track passes with random histograms
(many zero bins, H = 0 with Q > 0, Q = 0 with H > 0, saturating weights Q >> H),
a re-learn and more track passes.  Results compared exactly; full-speed runs assert
the documented pass latency; outputs must stay stable after done until the next start.

Run: ``.venv/bin/python -m pytest tb/test_ms_bin_pass.py``.
"""

from __future__ import annotations

import dataclasses
import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.blocks import Hist, ms_bin_pass
from mstrack.fixed.formats import FixedParams
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"BIN_W": 9, "HIST_W": 14, "COUNT_W": 14, "POSSUM_W": 21, "SQRT_IN_W": 40, "RHO_SUM_W": 21,
            "RATIO_Q_W": 16, "WEIGHT_W": 8, "WF": 4, "RF": 6, "SW_W": 22, "SWX_W": 29, "BIN_RD_LAT": 2,
            "ITERATIVE": 0}
CLK_NS = 10


def pass_latency(g: dict, learn: bool) -> int:
    """Documented start -> done latency of ms_bin_pass (header of rtl/ms_bin_pass.vhd)."""
    nb, lat = 2 ** int(g["BIN_W"]), int(g["BIN_RD_LAT"])
    if learn:
        return 2 + nb + lat
    rq = int(g["RATIO_Q_W"])
    if int(g.get("ITERATIVE", 0)):
        return iter_pass_latency(g)
    return 3 + nb + lat + max(int(g["SQRT_IN_W"]) // 2 + 1 + mult_latency(int(g["HIST_W"])),
                              rq + rq // 2 + 2 + mult_latency(int(g["WEIGHT_W"])))


def iter_pass_latency(g: dict) -> int:
    """ITERATIVE = 1, track (header of rtl/ms_bin_pass.vhd): T1 + (N_BINS - 1) P + S2_LEN + 2 with
    T1 = BIN_RD_LAT + max(RATIO_Q_W + 4, HIST_W + 3) (request -> bin leaves stage 1), S2_LEN = max(SQRT_IN_W / 2 + 1,
    RATIO_Q_W) (stage 2 clocks), P = max(T1, S2_LEN + 1) (clocks per bin)."""
    nb, lat, rq = 2 ** int(g["BIN_W"]), int(g["BIN_RD_LAT"]), int(g["RATIO_Q_W"])
    t1 = lat + max(rq + 4, int(g["HIST_W"]) + 3)
    s2 = max(int(g["SQRT_IN_W"]) // 2 + 1, rq)
    return t1 + (nb - 1) * max(t1, s2 + 1) + s2 + 2


def mult_latency(a_w: int) -> int:
    """ms_mult_r4 LATENCY: 1 + max(1, ceil(log2(ceil(A_W / 2))))."""
    return 1 + max(1, (((a_w + 1) // 2) - 1).bit_length())


def fixed_params(g: dict) -> FixedParams:
    wf = int(g["WF"])
    return dataclasses.replace(FixedParams(), weight_frac=wf, weight_int=int(g["RATIO_Q_W"]) // 2 - wf,
                               rho_frac=int(g["RF"]))


class HistModel:
    """Read-and-clear histogram port: request seen in cycle c -> data valid in cycle c + BIN_RD_LAT."""

    def __init__(self, dut, lat: int, rng: random.Random, jitter: bool):
        self.dut, self.lat, self.rng, self.jitter = dut, lat, rng, jitter
        self.bins: dict[int, tuple[int, int, int, int]] = {}
        self.sched: dict[int, tuple[int, int, int, int]] = {}
        self.last_ret = -1
        self.cycle = 0
        self.reads = 0

    async def run(self):
        dut = self.dut
        dut.bin_rd_valid.value = 0
        while True:
            await RisingEdge(dut.clk)
            self.cycle += 1
            if dut.bin_rd_en.value == 1:  # driven in cycle self.cycle - 1
                a = dut.bin_rd_addr.value.to_unsigned()
                t = self.cycle - 1 + self.lat + (self.rng.randint(0, 2) if self.jitter else 0)
                t = max(t, self.last_ret + 1)
                self.last_ret = t
                self.sched[t] = self.bins.pop(a, (0, 0, 0, 0))  # read and clear
                self.reads += 1
            d = self.sched.pop(self.cycle, None)
            if d is None:
                dut.bin_rd_valid.value = 0
            else:
                h, n, sx, sy = d
                dut.bin_rd_valid.value = 1
                dut.bin_h.value = h
                dut.bin_n.value = n
                dut.bin_sx.value = sx
                dut.bin_sy.value = sy


def random_hist(g: dict, rng: random.Random, q: np.ndarray | None, kind: str) -> Hist:
    """Random per-bin sums with sum H < 2**HIST_W, many zero bins; special bins against Q."""
    nb = 2 ** int(g["BIN_W"])
    hmax_tot = (1 << int(g["HIST_W"])) - 1
    cmax = (1 << int(g["COUNT_W"])) - 1
    pmax = (1 << (int(g["POSSUM_W"]) - 1)) - 1
    H = np.zeros(nb, np.int64)
    N = np.zeros(nb, np.int64)
    SX = np.zeros(nb, np.int64)
    SY = np.zeros(nb, np.int64)
    nz = rng.sample(range(nb), max(1, nb // rng.choice([3, 6, 12])))
    if kind == "max":                      # a single bin holding everything, extreme sums
        nz = [rng.randrange(nb)]
    budget = hmax_tot
    cbudget = cmax                         # sum N <= pixels in a window < 2**COUNT_W
    for u in nz:
        if budget <= 0:
            break
        if kind == "max":
            h = budget
        elif q is not None and q[u] > 0 and rng.random() < 0.3:
            h = 1                          # Q >> H: saturating weight
        else:
            h = rng.randint(1, max(1, min(budget, 3 * hmax_tot // len(nz))))
        h = min(h, budget)
        budget -= h
        n = min(cbudget, h if rng.random() < 0.5 else rng.randint(1, h))  # flat: N = H; Epanechnikov: N <= H
        cbudget -= n
        H[u], N[u] = h, n
        lim = min(pmax, n * 63)
        SX[u] = -lim if kind == "max" else rng.randint(-lim, lim)
        SY[u] = lim if kind == "max" else rng.randint(-lim, lim)
    return Hist(H=H, N=N, SX=SX, SY=SY)


def cap_counts(h: np.ndarray, total: int) -> np.ndarray:
    """N = H, cut so that sum N <= total (a window has at most 2**COUNT_W - 1 pixels)."""
    n = h.copy()
    csum = np.cumsum(n)
    n = np.where(csum <= total, n, np.maximum(0, total - (csum - n)))
    return n


async def run_pass(dut, hm: HistModel, hist: Hist, learn: int) -> tuple[dict, int]:
    hm.bins = {u: (int(hist.H[u]), int(hist.N[u]), int(hist.SX[u]), int(hist.SY[u]))
               for u in range(len(hist.H)) if hist.H[u] or hist.N[u] or hist.SX[u] or hist.SY[u]}
    dut.learn.value = learn
    dut.start.value = 1
    await RisingEdge(dut.clk)              # start driven in cycle 0, sampled at this edge
    dut.start.value = 0
    cyc = 0
    while True:
        await RisingEdge(dut.clk)
        cyc += 1
        if dut.done.value == 1:            # done high in cycle cyc
            break
        assert cyc < 100000, "no done"
    res = {"S": dut.s_sum.value.to_unsigned(), "Sw": dut.sw.value.to_unsigned(),
           "Swx": dut.swx.value.to_signed(), "Swy": dut.swy.value.to_signed(),
           "K": dut.k_sum.value.to_unsigned()}
    assert not hm.bins, f"bins not read: {sorted(hm.bins)[:5]}"
    return res, cyc


@cocotb.test()
@cocotb.parametrize(jitter=[False, True])
async def bin_pass_sequence(dut, jitter):
    g = dut_generics(DEFAULTS)
    assert len(dut.bin_rd_addr) == int(g["BIN_W"]) and len(dut.bin_h) == int(g["HIST_W"])
    fp = fixed_params(g)
    rng = random.Random(3000 + jitter)
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    hm = HistModel(dut, int(g["BIN_RD_LAT"]), rng, jitter)
    dut.start.value = 0
    dut.learn.value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    cocotb.start_soon(hm.run())
    await RisingEdge(dut.clk)

    q = None
    plan = ["learn", "track", "track", "same", "max", "zero", "learn", "track", "track"]
    for step, kind in enumerate(plan):
        learn = kind == "learn"
        if kind == "same":
            hist = Hist(H=q.copy(), N=cap_counts(q, (1 << int(g["COUNT_W"])) - 1),
                        SX=np.zeros_like(q), SY=np.zeros_like(q))
        elif kind == "zero":
            hist = Hist(*(np.zeros(2 ** int(g["BIN_W"]), np.int64) for _ in range(4)))
        else:
            hist = random_hist(g, rng, q, "max" if kind == "max" else "rand")
        res, cyc = await run_pass(dut, hm, hist, int(learn))
        assert res["K"] == int(hist.H.sum()), f"step {step}: k_sum {res['K']} != {int(hist.H.sum())}"
        if learn:
            q = hist.H.copy()
        else:
            bp = ms_bin_pass(q, hist, fp)
            exp = {"S": bp.S, "Sw": bp.Sw, "Swx": bp.Swx, "Swy": bp.Swy}
            for k, v in exp.items():
                assert res[k] == v, f"step {step} ({kind}): {k} = {res[k]}, model {v}"
        if not jitter:
            assert cyc == pass_latency(g, learn), f"step {step}: done after {cyc}, documented {pass_latency(g, learn)}"
        # outputs stable until the next start; done is a single pulse
        gap = rng.randint(1, 5)
        for _ in range(gap):
            await RisingEdge(dut.clk)
            assert dut.done.value == 0
            assert dut.s_sum.value.to_unsigned() == res["S"] and dut.sw.value.to_unsigned() == res["Sw"]
            assert dut.swx.value.to_signed() == res["Swx"] and dut.k_sum.value.to_unsigned() == res["K"]
        dut._log.info("step %d %s: %s in %d cycles", step, kind, res, cyc)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_bin_pass"
MODULE = "test_ms_bin_pass"


def bin_pass_generics(tp: TrackerParams | None = None, bin_w: str = "colour", lat: int = 2) -> dict:
    c = core_generics(tp or TrackerParams())
    g = {k: c[k] for k in DEFAULTS if k in c}
    g["BIN_W"] = 3 * c["COLOUR_BITS"] if bin_w == "colour" else c["EDGE_BINS_LOG2"]
    g["BIN_RD_LAT"] = lat
    return g


PARAMS = [
    pytest.param(bin_pass_generics(), id="colour"),
    pytest.param(bin_pass_generics(bin_w="edge"), id="edge"),
    pytest.param(bin_pass_generics(lat=1), id="colour_lat1"),
    pytest.param(bin_pass_generics(TrackerParams(kernel="epanechnikov"), lat=4), id="epan_colour_lat4"),
    pytest.param(bin_pass_generics(TrackerParams(kernel="epanechnikov"), bin_w="edge"), id="epan_edge"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("iterative", [0, 1], ids=["iter0", "iter1"])
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_bin_pass_ghdl(generics, iterative, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, {**generics, "ITERATIVE": iterative}, hdl.rtl_sources(TOP), waves=hdl_waves)
