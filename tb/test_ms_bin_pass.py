"""cocotb test bench + pytest entry points for rtl/ms_bin_pass.vhd.

Model: :func:`mstrack.fixed.blocks.ms_bin_pass` (S, Sw, Swx, Swy) and sum(H) (k_sum).
A behavioural histogram (Python dict per pass) serves the read-and-clear port with
BIN_RD_LAT clocks of latency (throttled run: random extra delay, still in order).
Sequence per run: learn pass (Q := H), several track passes with random histograms
(many zero bins, H = 0 with Q > 0, Q = 0 with H > 0, saturating weights Q >> H),
a re-learn and more track passes, and a pass on a Q written through the external port
(q_ext_*: random Q with zeros and full-scale words; one random Q through the parallel port
q_ext_all_we / q_ext_all_data, every bank of an address per clock).  Results compared exactly; full-speed
runs assert the documented pass latency; outputs must stay stable after done until the next start.

With N_ORIENT > 1 (tracker v2's joint colour x orientation bins, joint bin = N_ORIENT u + o) the
histograms are drawn over the N_ORIENT 2**BIN_W joint bins; the port model returns, per colour
address u, the N_ORIENT banks at once on bin_*_all (as ms_histogram does: bank o at o*width; the
scalar bin_h .. bin_sy carry garbage, which the block must ignore), the external Q load selects a
bank with q_ext_bank, and the results are compared with ms_bin_pass on the joint histogram.  Nine times the bins
per pass, so a shorter sequence: each pass kind once (learn, track on random and full-scale histograms,
H = Q, all zero, the three external loads).

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
            "ITERATIVE": 0, "N_ORIENT": 1}
CLK_NS = 10


def pass_latency(g: dict, learn: bool) -> int:
    """Documented start -> done latency of ms_bin_pass (header of rtl/ms_bin_pass.vhd)."""
    nb, lat = 2 ** int(g["BIN_W"]), int(g["BIN_RD_LAT"])
    tl = tree_levels(g)
    if learn:
        return 2 + nb + lat + tl
    rq = int(g["RATIO_Q_W"])
    if int(g.get("ITERATIVE", 0)):
        return iter_pass_latency(g)
    return 3 + nb + lat + tl + max(int(g["SQRT_IN_W"]) // 2 + 1 + mult_latency(int(g["HIST_W"])),
                              rq + rq // 2 + 2 + mult_latency(int(g["WEIGHT_W"])))


def tree_levels(g: dict) -> int:
    """Register levels of the bank adder tree: 0 with one bank, else ceil(log2(N_ORIENT))."""
    no = int(g.get("N_ORIENT", 1))
    return 0 if no == 1 else (no - 1).bit_length()


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
    """Read-and-clear histogram port: request seen in cycle c -> data valid in cycle c + BIN_RD_LAT.

    ``bins`` is keyed by joint bin; a read of address a returns joint bins n_orient a + o, o = 0 ..
    n_orient - 1 (bin_*_all, bank o at o*width) or, with one bank, bin a on bin_h .. bin_sy."""

    def __init__(self, dut, lat: int, rng: random.Random, jitter: bool, g: dict | None = None):
        self.dut, self.lat, self.rng, self.jitter = dut, lat, rng, jitter
        g = g or DEFAULTS
        self.no = int(g.get("N_ORIENT", 1))
        self.widths = (int(g["HIST_W"]), int(g["COUNT_W"]), int(g["POSSUM_W"]), int(g["POSSUM_W"]))
        self.bins: dict[int, tuple[int, int, int, int]] = {}
        self.sched: dict[int, list[tuple[int, int, int, int]]] = {}
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
                self.sched[t] = [self.bins.pop(self.no * a + o, (0, 0, 0, 0))  # read and clear
                                 for o in range(self.no)]
                self.reads += 1
            d = self.sched.pop(self.cycle, None)
            if d is None:
                dut.bin_rd_valid.value = 0
            elif self.no == 1:
                h, n, sx, sy = d[0]
                dut.bin_rd_valid.value = 1
                dut.bin_h.value = h
                dut.bin_n.value = n
                dut.bin_sx.value = sx
                dut.bin_sy.value = sy
            else:
                dut.bin_rd_valid.value = 1
                for port, w, k in zip((dut.bin_h_all, dut.bin_n_all, dut.bin_sx_all, dut.bin_sy_all),
                                      self.widths, range(4)):
                    port.value = sum((bank[k] & ((1 << w) - 1)) << (o * w) for o, bank in enumerate(d))
                # the scalar ports are not used with banks: garbage there
                dut.bin_h.value = self.rng.getrandbits(self.widths[0])
                dut.bin_n.value = self.rng.getrandbits(self.widths[1])
                dut.bin_sx.value = self.rng.getrandbits(self.widths[2])
                dut.bin_sy.value = self.rng.getrandbits(self.widths[3])


def random_hist(g: dict, rng: random.Random, q: np.ndarray | None, kind: str) -> Hist:
    """Random per-bin sums with sum H < 2**HIST_W, many zero bins; special bins against Q.
    Over the N_ORIENT 2**BIN_W joint bins."""
    nb = n_joint(g)
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


def n_joint(g: dict) -> int:
    """Bins seen by the model: N_ORIENT x 2**BIN_W joint bins (2**BIN_W with one bank)."""
    return int(g.get("N_ORIENT", 1)) * 2 ** int(g["BIN_W"])


def random_q(g: dict, rng: random.Random, full: bool) -> np.ndarray:
    """A Q for the external load with sum Q < 2**HIST_W (as ms_model_scale's Qw: the widths assume
    it): many zero bins; ``full``: one full-scale word 2**HIST_W - 1 and the rest 0."""
    nb, top = n_joint(g), (1 << int(g["HIST_W"])) - 1
    q = np.zeros(nb, np.int64)
    if full:
        q[rng.randrange(nb)] = top
        return q
    budget = top
    for u in rng.sample(range(nb), max(2, nb // 5)):
        v = min(budget, rng.choice((1, 2, rng.randint(1, 40), rng.randint(1, max(1, top // 50)))))
        q[u] = v
        budget -= v
    return q


async def load_q(dut, g: dict, q: np.ndarray, parallel: bool = False) -> None:
    """Write Q through q_ext_we / q_ext_addr / q_ext_bank / q_ext_data, one word per clock (idle
    block), joint bin N_ORIENT a + o at address a, bank o; random order.  ``parallel``: through
    q_ext_all_we / q_ext_all_data instead, the N_ORIENT banks of one address a per clock (bank o at
    bits o*HIST_W; random address order)."""
    no = int(g.get("N_ORIENT", 1))
    if parallel:
        hw = int(g["HIST_W"])
        addrs = list(range(len(q) // no))
        random.Random(int(q.sum()) + 1).shuffle(addrs)
        for a in addrs:
            dut.q_ext_all_we.value = 1
            dut.q_ext_addr.value = a
            dut.q_ext_all_data.value = sum(int(q[no * a + o]) << (o * hw) for o in range(no))
            await RisingEdge(dut.clk)
        dut.q_ext_all_we.value = 0
        return
    order = list(range(len(q)))
    random.Random(int(q.sum())).shuffle(order)
    for j in order:
        dut.q_ext_we.value = 1
        dut.q_ext_addr.value = j // no
        if no > 1:
            dut.q_ext_bank.value = j % no
        dut.q_ext_data.value = int(q[j])
        await RisingEdge(dut.clk)
    dut.q_ext_we.value = 0


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
    hm = HistModel(dut, int(g["BIN_RD_LAT"]), rng, jitter, g)
    dut.q_ext_we.value = 0
    dut.q_ext_all_we.value = 0
    dut.start.value = 0
    dut.learn.value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    cocotb.start_soon(hm.run())
    await RisingEdge(dut.clk)

    q = None
    plan = ["learn", "track", "track", "same", "max", "zero", "learn", "track", "track", "ext", "track",
            "ext_par", "track", "ext_full", "max"]
    if int(g.get("N_ORIENT", 1)) > 1:      # 9x the bins per pass: every kind once (the random passes after
        plan = ["learn", "max", "same", "zero", "ext", "ext_par", "ext_full", "max"]   # each Q load)
    for step, kind in enumerate(plan):
        learn = kind == "learn"
        if kind.startswith("ext"):         # Q written through the external port, then a track pass
            q = random_q(g, rng, kind == "ext_full")
            await load_q(dut, g, q, parallel=kind == "ext_par")
            hist = random_hist(g, rng, q, "rand")
        elif kind == "same":
            hist = Hist(H=q.copy(), N=cap_counts(q, (1 << int(g["COUNT_W"])) - 1),
                        SX=np.zeros_like(q), SY=np.zeros_like(q))
        elif kind == "zero":
            hist = Hist(*(np.zeros(n_joint(g), np.int64) for _ in range(4)))
        else:
            hist = random_hist(g, rng, q, "max" if kind == "max" else "rand")
        if kind == "max" and step == len(plan) - 1:   # full-scale H on the full-scale Q word
            hist = Hist(H=q.copy(), N=cap_counts(q, (1 << int(g["COUNT_W"])) - 1),
                        SX=np.zeros_like(q), SY=np.zeros_like(q))
            u = int(np.argmax(q))
            hist.SX[u] = -min((1 << (int(g["POSSUM_W"]) - 1)) - 1, int(hist.N[u]) * 63)
            hist.SY[u] = -hist.SX[u]
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


def orient(g: dict, no: int = 9) -> dict:
    """The same block with no orientation banks (tracker v2's joint bins: 9; ITERATIVE = 0 only)."""
    return {**g, "N_ORIENT": no}


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


# orientation banks (tracker v2's joint colour x orientation bins): 9 banks (4-level adder tree), 2 banks
# (1 level), an odd 3 (a node passing through a level); pipelined arithmetic only
ORIENT_PARAMS = [
    pytest.param(orient(bin_pass_generics()), id="colour_orient9"),
    pytest.param(orient(bin_pass_generics(TrackerParams(kernel="epanechnikov"), lat=4)), id="epan_colour_lat4_orient9"),
    pytest.param(orient(bin_pass_generics(bin_w="edge", lat=1), 2), id="edge_lat1_orient2"),
    pytest.param(orient(bin_pass_generics(bin_w="edge"), 3), id="edge_orient3"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", ORIENT_PARAMS)
def test_ms_bin_pass_orient_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.ghdl
def test_ms_bin_pass_synth_orient9(tmp_path):
    """ghdl --synth (to Verilog) of the colour bin pass with 9 orientation banks: 9 Q RAMs of 512 words."""
    gen = orient(bin_pass_generics())
    v = hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v").read_text()
    assert "module ms_bin_pass" in v and "bin_sy_all" in v and "q_ext_bank" in v


@pytest.mark.ghdl
def test_ms_bin_pass_iterative_orient_refused(tmp_path):
    """ITERATIVE = 1 has no banks: elaboration with N_ORIENT 9 must fail on the assertion."""
    gen = {**orient(bin_pass_generics(bin_w="edge")), "ITERATIVE": 1}
    with pytest.raises(hdl.HdlError, match="ITERATIVE = 1 has no orientation banks"):
        hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v")


@pytest.mark.verilator
@pytest.mark.parametrize("generics", [pytest.param(orient(bin_pass_generics()), id="colour_orient9")])
def test_ms_bin_pass_verilator(generics, hdl_waves):
    """Same bench on the GHDL -> Verilog -> Verilator netlist (the synthesis path) with 9 banks."""
    hdl.run_verilator(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
