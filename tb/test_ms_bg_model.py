"""cocotb test bench + pytest entry points for rtl/ms_bg_model.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_bg_model` (CBWH target model of tracker v2; with N_ORIENT > 1 on
joint colour x orientation bins, n_bins = N_ORIENT 2**BIN_W, px_bin / px_obin = colour / obin).  Each case
starts the block with (cx, cy, wb, hb, ring16), streams every pixel of a bins image (with its
coordinates; raster order, or shuffled: the block takes any order), then reads the model RAM
back and compares Qn[u] and T[u] for every bin, and the totals nq = sum Q, no = sum O,
o* and tot = sum Q v, exactly.  Synthetic cases: random images (all bins), no ring pixel
(ring16 = 0; box = whole image), box touching each frame edge, a one-bin ring, v = 0 bins and
tot = 0, even sizes, the largest box; real cases: the init frame of real sequences with the
geometry of FixedTrackerV2.init (checked against the tracker's own model).  Full speed and with
random input gaps, with a `start` pulse while busy (ignored); an init frame abandoned half way
by a reset, then a model from scratch.  The clocks from the last pixel to `done` must equal LAT_DONE of the header
(3 N_BINS + 65 at the default widths), models follow each other without reset (pass 3 clears the counts).
With MODELS > 1 (one model per target): models learnt into models chosen by m_wr_sel in a mixed order,
each read back through m_rd_sel, then every model read again after the others were learnt and after a
reset (the model RAM keeps them).

Run: ``.venv/bin/python -m pytest tb/test_ms_bg_model.py``.
"""

from __future__ import annotations

import os
import random
from pathlib import Path

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from mstrack.fixed.blocks import ms_kernel
from mstrack.fixed.blocks_v2 import BG_FRAC, ms_bg_model
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"BIN_W": 9, "HALF_W": 6, "COORD_W": 12, "RING_W": 5, "Q_W": 14, "O_W": 17, "KD_W": 29}
CLK_NS = 10
SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
REAL_SEQS = ("Girl", "MotorRolling", "bag_vot")   # D = 1, 2 (640x360), 2 (fractional box)


def mult_lat(a_w: int) -> int:
    """ms_mult_r4 latency: 1 + max(1, ceil(log2(ceil(A_W / 2))))."""
    return 1 + max(1, (((a_w + 1) // 2) - 1).bit_length())


def n_orient(g: dict) -> int:
    """N_ORIENT of the run (1 when the generic is not given: the block's default)."""
    return int(g.get("N_ORIENT", 1))


def lat_done(g: dict) -> int:
    """px_last -> done of rtl/ms_bg_model.vhd (header: LAT_DONE; 3 N + 65 at the defaults, N =
    N_ORIENT 2**BIN_W joint bins; count RAM read latency 3): drain 7, pass 1 N + 4, pass 2 N + 3 + M(Q_W)
    + 1 + 18 + M(9) + 1, pass 3 N + 3 + 18 + 2."""
    n = n_orient(g) << int(g["BIN_W"])
    return 7 + (n + 4) + (n + 3 + mult_lat(int(g["Q_W"])) + 1 + 18 + mult_lat(9) + 1) + (n + 3 + 18 + 2)


def _counts(bins: np.ndarray, cx: int, cy: int, wb: int, hb: int, ring16: int, n_bins: int):
    """Q, O as the model's docstring defines them (only for the case the model cannot return)."""
    ker = ms_kernel(wb, hb, "flat", 8)
    h, w = bins.shape
    yy, xx = np.mgrid[0:h, 0:w]
    adx, ady = np.abs(xx - cx), np.abs(yy - cy)
    inside = np.zeros((h, w), bool)
    inside[cy - ker.ey: cy + ker.ey + 1, cx - ker.ex: cx + ker.ex + 1] = ker.inside
    gx, gy = (ring16 * wb) >> 4, (ring16 * hb) >> 4
    ring = (adx <= ker.ex + gx) & (ady <= ker.ey + gy) & ~((adx <= ker.ex) & (ady <= ker.ey))
    return (np.bincount(bins[inside], minlength=n_bins).astype(np.int64),
            np.bincount(bins[ring], minlength=n_bins).astype(np.int64))


def expected(bins: np.ndarray, cx: int, cy: int, wb: int, hb: int, ring16: int, n_bins: int, o_w: int) -> dict:
    """Model results and the totals the block reports.

    tot = sum Q v = 0 (every box bin has v = 0: O[u] > 2**8 o*) makes the model raise (ms_divider
    by zero: a model bug, reported, not changed here); the RTL then writes Qn = 0 for every bin
    (qv = 0 -> Qn = 0) and T as defined, which is what this case expects.
    """
    try:
        m = ms_bg_model(bins, cx, cy, wb, hb, ring16, n_bins)
        Q, O, Qn, T = m.Q, m.O, m.Qn, m.T
    except ValueError:
        Q, O = _counts(bins, cx, cy, wb, hb, ring16, n_bins)
        Qn = np.zeros(n_bins, np.int64)
        T = (Q * int(O.sum()) > O * int(Q.sum())).astype(np.int64)
    no = int(O.sum())
    omin = int(O[O > 0].min()) if no else (1 << o_w) - 1
    one = 1 << BG_FRAC
    v = np.full(n_bins, one, np.int64)
    if no:
        nz = O > 0
        v[nz] = np.minimum((omin << BG_FRAC) // O[nz], one)
    tot = int((Q * v).sum())
    if tot == 0:
        assert no > 0, "tot = 0 needs ring pixels"
    return {"Qn": Qn, "T": T, "nq": int(Q.sum()), "no": no, "omin": omin, "tot": tot}


def setup_latency(wb: int, hb: int, half_w: int) -> int:
    """start -> counting: the flat ms_kernel_tables latency of (wb, hb) (its header: n + S + 2 + X,
    n = max(ex, ey), S = 3 (HALF_W + 1) + 3, X = 2 ex - XR[n]) + 2 (start taken, done seen)."""
    ker = ms_kernel(wb, hb, "flat", 8)
    n = max(ker.ex, ker.ey)
    row = ker.inside[ker.ey + n] if n <= ker.ey else np.zeros(1, bool)
    xr_n = int(np.nonzero(row)[0].max()) - ker.ex if row.any() else 0
    return n + 3 * (half_w + 1) + 3 + 2 + (2 * ker.ex - xr_n) + 2


class BgTB:
    def __init__(self, dut):
        self.dut = dut
        self.g = dut_generics(DEFAULTS)
        self.n_or = n_orient(self.g)
        # joint bins j = N_ORIENT colour + obin (ms_joint_bin): px_bin = j // N_ORIENT, px_obin = j % N_ORIENT
        self.n_bins = self.n_or << int(self.g["BIN_W"])
        self.cyc = 0

    async def clock_count(self):
        while True:
            await RisingEdge(self.dut.clk)
            self.cyc += 1

    async def reset(self):
        d = self.dut
        cocotb.start_soon(Clock(d.clk, CLK_NS, unit="ns").start())
        cocotb.start_soon(self.clock_count())
        d.rst.value = 1
        d.start.value = 0
        d.px_valid.value = 0
        d.px_last.value = 0
        d.px_bin.value = 0
        d.px_obin.value = 0
        d.m_rd_obin.value = 0
        d.px_x.value = 0
        d.px_y.value = 0
        d.m_rd_addr.value = 0
        d.m_wr_sel.value = 0
        d.m_rd_sel.value = 0
        for k in ("cx", "cy", "wb", "hb", "ring16"):
            getattr(d, k).value = 0
        await ClockCycles(d.clk, 3)
        d.rst.value = 0

    async def wait_idle(self):
        while True:
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            if int(self.dut.busy.value) == 0:
                break
        await Timer(1, "ns")

    async def run(self, bins: np.ndarray, cx: int, cy: int, wb: int, hb: int, ring16: int, gap: float,
                  rng: random.Random, order: str = "raster", name: str = "", sel: int = 0) -> dict:
        """Learn a model of *bins* into model *sel* (m_wr_sel) and check it (read through m_rd_sel), its
        sums and both latencies; returns the expected model."""
        d, g = self.dut, self.g
        exp = expected(bins, cx, cy, wb, hb, ring16, self.n_bins, int(g["O_W"]))
        await self.wait_idle()
        for k, v in (("cx", cx), ("cy", cy), ("wb", wb), ("hb", hb), ("ring16", ring16)):
            getattr(d, k).value = v
        d.m_wr_sel.value = sel
        d.start.value = 1
        await RisingEdge(d.clk)
        t_start = self.cyc
        d.start.value = 0
        d.m_wr_sel.value = (sel + 1) % int(g.get("MODELS", 1))   # taken with start: changes after it are ignored
        while True:                                  # set-up (kernel tables of the box)
            await RisingEdge(d.clk)
            await ReadOnly()
            if int(d.counting.value):
                break
            assert self.cyc - t_start < 400, "set-up does not finish"
        setup = self.cyc - t_start
        assert setup == setup_latency(wb, hb, int(g["HALF_W"])), \
            f"{name}: start -> counting {setup} clocks, documented {setup_latency(wb, hb, int(g['HALF_W']))}"
        await Timer(1, "ns")
        h, w = bins.shape
        ys, xs = np.mgrid[0:h, 0:w]
        pix = list(zip(ys.ravel().tolist(), xs.ravel().tolist()))
        if order == "shuffled":
            rng.shuffle(pix)
        last = len(pix) - 1
        i = 0
        while i <= last:
            if gap and rng.random() < gap:
                d.px_valid.value = 0
                # junk on the data lines while not valid (obin also beyond N_ORIENT - 1)
                d.px_bin.value = rng.randrange(self.n_bins // self.n_or)
                d.px_obin.value = rng.randrange(16)
            else:
                y, x = pix[i]
                d.start.value = int(i == last // 2)         # ignored while busy
                d.cx.value = rng.randrange(1 << int(g["COORD_W"])) if i == last // 2 else cx
                d.px_valid.value = 1
                d.px_bin.value = int(bins[y, x]) // self.n_or
                d.px_obin.value = int(bins[y, x]) % self.n_or
                d.px_x.value = x
                d.px_y.value = y
                d.px_last.value = int(i == last)
                i += 1
            await RisingEdge(d.clk)
        t_last = self.cyc
        d.start.value = 0
        d.cx.value = cx
        d.px_valid.value = 0
        d.px_last.value = 0
        await ClockCycles(d.clk, lat_done(g) - 2)     # done earlier than that is missed: a failure
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            if int(d.done.value):
                break
            assert self.cyc - t_last < 4 * self.n_bins + 500, "done does not come"
        lat = self.cyc - t_last
        got = {"nq": d.n_box.value.to_unsigned(), "no": d.n_ring.value.to_unsigned(),
               "omin": d.o_min.value.to_unsigned(), "tot": d.qv_sum.value.to_unsigned()}
        await Timer(1, "ns")
        qn, t, qn_all, t_all = await self.read_model(sel)
        msg = f"{name}: cx={cx} cy={cy} wb={wb} hb={hb} ring16={ring16} image {w}x{h} gap={gap} model {sel}"
        for k in ("nq", "no", "omin", "tot"):
            assert got[k] == exp[k], f"{msg}: {k} = {got[k]}, model {exp[k]}"
        self.compare_model(exp, qn, t, qn_all, t_all, msg)
        assert lat == lat_done(g), f"{msg}: px_last -> done {lat} clocks, header says {lat_done(g)}"
        d._log.info("%s: ok (nq %d, no %d, o* %d, tot %d, %d bins with T; set-up %d, last -> done %d clocks)",
                    msg, exp["nq"], exp["no"], exp["omin"], exp["tot"], int(exp["T"].sum()), setup, lat)
        return exp

    @staticmethod
    def compare_model(exp: dict, qn, t, qn_all, t_all, msg: str) -> None:
        bad = np.nonzero((qn != exp["Qn"]) | (t != exp["T"]))[0]
        assert bad.size == 0, (f"{msg}: {bad.size} bins differ, first {bad[:5].tolist()}: "
                               f"Qn {qn[bad[:5]].tolist()} model {exp['Qn'][bad[:5]].tolist()}, "
                               f"T {t[bad[:5]].tolist()} model {exp['T'][bad[:5]].tolist()}")
        bad = np.nonzero((qn_all != exp["Qn"]) | (t_all != exp["T"]))[0]
        assert bad.size == 0, f"{msg}: m_qn_all / m_t_all: {bad.size} joint bins differ, first {bad[:5].tolist()}"

    async def read_model(self, sel: int) -> tuple:
        """Every joint bin of model *sel* through m_qn / m_t and m_qn_all / m_t_all."""
        d = self.dut
        d.m_rd_sel.value = sel
        qn = np.zeros(self.n_bins, np.int64)
        t = np.zeros(self.n_bins, np.int64)
        qn_all = np.zeros(self.n_bins, np.int64)     # from m_qn_all / m_t_all (all banks of a colour)
        t_all = np.zeros(self.n_bins, np.int64)
        nor = self.n_or
        for u in range(self.n_bins):                 # read port: address before the edge, data after it
            d.m_rd_addr.value = u // nor             # colour bin
            d.m_rd_obin.value = u % nor              # orientation bank
            await RisingEdge(d.clk)
            await ReadOnly()
            qn[u] = d.m_qn.value.to_unsigned()
            t[u] = int(d.m_t.value)
            if u % nor == 0:
                # m_t_all is one bit at N_ORIENT 1: a Logic in the Verilator netlist
                ta = d.m_t_all.value
                qa, ta = d.m_qn_all.value.to_unsigned(), ta.to_unsigned() if hasattr(ta, "to_unsigned") else int(ta)
                for o in range(nor):
                    qn_all[u + o] = (qa >> (17 * o)) & 0x1FFFF
                    t_all[u + o] = (ta >> o) & 1
            await Timer(1, "ns")
        return qn, t, qn_all, t_all


def synthetic_cases(g: dict, rng: random.Random) -> list[dict]:
    """(name, bins, cx, cy, wb, hb, ring16) cases within the generics' limits; bins are joint bins
    N_ORIENT colour + obin (the colour bins when N_ORIENT = 1)."""
    nor = n_orient(g)
    n = nor << int(g["BIN_W"])
    wmax = (1 << (int(g["HALF_W"]) + 1)) - 1
    rmax = (1 << int(g["RING_W"])) - 1
    out = []

    def case(name, bins, cx, cy, wb, hb, ring16, order="raster"):
        out.append({"name": name, "bins": bins, "cx": cx, "cy": cy, "wb": wb, "hb": hb,
                    "ring16": min(ring16, rmax), "order": order})

    def rand_img(h, w, k=n):
        return np.array([[rng.randrange(k) for _ in range(w)] for _ in range(h)], np.int64)

    # every bin present in box and ring (ring = the whole image)
    perm = np.resize(np.arange(n), 48 * 48)
    rng.shuffle(perm)
    case("all_bins", perm.reshape(48, 48), 24, 23, 21, 21, 16)
    w, h = 40, 32
    case("random", rand_img(h, w), 20, 15, 11, 9, 10)
    case("random_shuffled", rand_img(h, w), 17, 18, 9, 13, 6, order="shuffled")
    # no ring pixel: ring16 = 0; box = the whole image
    case("no_ring_r0", rand_img(20, 24), 11, 9, 9, 7, 0)
    case("no_ring_whole", rand_img(9, 11), 5, 4, 11, 9, 10)
    # box touching the frame edges (ring clipped)
    case("edge_left_top", rand_img(h, w), 3, 2, 7, 5, 10)
    case("edge_right_bottom", rand_img(h, w), w - 1 - 4, h - 1 - 3, 9, 7, 16)
    # one-bin ring: uniform background, random box
    img = np.full((h, w), rng.randrange(n), np.int64)
    img[11:20, 13:26] = rand_img(9, 13)             # exactly the box's rectangle
    case("one_bin_ring", img, 19, 15, 13, 9, 10)
    # v = 0 bins and tot = 0: bin a fills box and most of the ring (O_a > 256 o*), one pixel of bin b
    a, b = 0, n - 1
    img = np.full((48, 48), a, np.int64)
    img[2, 2] = b                                     # a corner of the ring
    case("tot_zero", img, 24, 24, 15, 15, 16)
    img = img.copy()
    img[20:29, 20:29] = rand_img(9, 9)
    case("v_zero", img, 24, 24, 15, 15, 16)
    # even sizes, largest box, large ring
    case("even", rand_img(h, w), 20, 16, 10, 8, 12)
    big = wmax                                         # 127 x 127 at HALF_W = 6
    case("largest", rand_img(big + 6, big + 10), (big + 10) // 2, (big + 6) // 2, big, big, rmax)
    if nor > 1:
        nc = n // nor
        # every joint bin in the ring (72 x 72 > 4608 px at N_ORIENT 9, BIN_W 9; ring = the whole image)
        side = max(int(np.ceil(np.sqrt(n))) + 4, 30)
        perm = np.resize(np.arange(n), side * side)
        rng.shuffle(perm)
        case("all_joint_bins", perm.reshape(side, side), side // 2, side // 2 - 1, 21, 21, rmax)
        # box and ring differ in orientation only: one colour everywhere, box obins 0 .. lo - 1 (and a
        # few N_ORIENT - 1), ring obins lo .. N_ORIENT - 1 (lo = 4 at N_ORIENT 9)
        c0 = rng.randrange(nc)
        h, w = 40, 48
        lo = nor // 2
        ob = np.array([[rng.randrange(lo, nor) for _ in range(w)] for _ in range(h)], np.int64)
        box_ob = list(range(lo)) + [lo - 1, nor - 1]
        ob[13:26, 17:32] = [[rng.choice(box_ob) for _ in range(15)] for _ in range(13)]
        case("orient_only_one_colour", c0 * nor + ob, 24, 19, 15, 13, 12)
        # the same colour mix (3 colours) in box and ring, orientation biased: box mostly 0 .. 2,
        # ring all 9 obins
        cols = [rng.randrange(nc) for _ in range(3)]
        col = np.array([[rng.choice(cols) for _ in range(w)] for _ in range(h)], np.int64)
        ob = np.array([[rng.randrange(nor) for _ in range(w)] for _ in range(h)], np.int64)
        ob[12:27, 16:33] = [[rng.choice([0, 1, 2, 2, rng.randrange(nor)]) for _ in range(17)] for _ in range(15)]
        case("orient_only_colour_mix", col * nor + ob, 24, 19, 17, 15, 10, order="shuffled")
        # one colour, one obin per region: box obin N_ORIENT - 2, ring that obin and 0 (T only at
        # obin N_ORIENT - 2)
        ob = np.where(np.arange(w)[None, :] % 3 == 0, 0, nor - 2) * np.ones((h, 1), np.int64)
        ob[14:25, 18:31] = nor - 2
        case("orient_two_bins", c0 * nor + ob, 24, 19, 13, 11, 16)
    return out


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.4])
async def bg_model_synthetic(dut, gap):
    tb = BgTB(dut)
    await tb.reset()
    rng = random.Random(1100 + int(gap * 10))
    for c in synthetic_cases(tb.g, rng):
        await tb.run(c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"], gap, rng,
                     order=c["order"], name=c["name"])


@cocotb.test()
async def bg_model_models(dut):
    """MODELS > 1: one model per target.  Learn a different case into each model in a mixed order (the
    last model learnt twice), then read every model again after the others and after a reset."""
    tb = BgTB(dut)
    await tb.reset()
    n_models = int(tb.g.get("MODELS", 1))
    rng = random.Random(1400)
    cases = synthetic_cases(tb.g, rng)
    order = list(range(n_models))[::-1] + [n_models - 1]     # n - 1 .. 0, then n - 1 again
    held: dict[int, dict] = {}
    for i, sel in enumerate(order):
        c = cases[(1 + 2 * i) % len(cases)]
        held[sel] = await tb.run(c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"], 0.2, rng,
                                 order=c["order"], name=c["name"], sel=sel)
    for when in ("after all were learnt", "after a reset"):
        if when == "after a reset":
            tb.dut.rst.value = 1
            await ClockCycles(tb.dut.clk, 2)
            tb.dut.rst.value = 0
            await tb.wait_idle()
        for sel in rng.sample(range(n_models), n_models):
            got = await tb.read_model(sel)
            tb.compare_model(held[sel], *got, msg=f"model {sel} {when}")
    dut._log.info("%d models kept apart, %d learnt", n_models, len(order))


@cocotb.test()
async def bg_model_abandoned(dut):
    """An init frame abandoned half way (reset, as after a stream error): the reset clears the
    counts, the next model is exact."""
    tb = BgTB(dut)
    await tb.reset()
    rng = random.Random(1300)
    c = synthetic_cases(tb.g, rng)[1]
    d = tb.dut
    await tb.wait_idle()
    for k in ("cx", "cy", "wb", "hb", "ring16"):
        getattr(d, k).value = c[k]
    d.start.value = 1
    await RisingEdge(d.clk)
    d.start.value = 0
    while True:
        await RisingEdge(d.clk)
        await ReadOnly()
        if int(d.counting.value):
            break
    await Timer(1, "ns")
    h, w = c["bins"].shape
    for i in range(h * w // 2):                       # half the frame, then reset
        d.px_valid.value = 1
        d.px_bin.value = int(c["bins"][i // w, i % w]) // tb.n_or
        d.px_obin.value = int(c["bins"][i // w, i % w]) % tb.n_or
        d.px_x.value = i % w
        d.px_y.value = i // w
        await RisingEdge(d.clk)
    d.px_valid.value = 0
    d.rst.value = 1
    await RisingEdge(d.clk)
    d.rst.value = 0
    await tb.run(c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"], 0.0, rng, name="after reset")


def real_cases(g: dict) -> list[dict]:
    """The init frame of real sequences, with FixedTrackerV2.init's geometry (decimation D,
    box diameters, centre clamped into the decimated interior)."""
    from mstrack.io.data import load_sequence
    from mstrack.fixed.blocks import ms_box_clip, ms_colour_bin, ms_round_centre, round_box
    from mstrack.fixed.blocks_v2 import SIZE_FRAC, ms_box_size, ms_decimation, sixteenths
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from mstrack.track.params import V2_COLOUR, TrackerParams

    colour_bits = int(g["BIN_W"]) // 3
    # the colour tracker (V2_COLOUR): tracker v2's default learns on the joint bins (real_cases_joint)
    tp = TrackerParams(preset="v2", colour_bits=colour_bits, **V2_COLOUR)
    out = []
    for name in REAL_SEQS:
        seq = load_sequence(SEQ_ROOT / name)
        frame = seq.frame(0)
        box = seq.init_box()
        fh, fw = frame.shape[:2]
        trk = FixedTrackerV2(tp)
        trk.init(frame, box)
        fx = trk.fixed
        cf = fx.centre_frac
        x, y, w, h = round_box(*box.as_tuple())
        ib, _ = ms_box_clip(x, y, w, h, fw, fh, 4095)
        w8, h8 = ib.w << SIZE_FRAC, ib.h << SIZE_FRAC
        c8 = ((2 * ib.x + ib.w - 1) << (cf - 1), (2 * ib.y + ib.h - 1) << (cf - 1))
        pad16, ring16 = sixteenths(tp.pad, "pad"), sixteenths(tp.bg_ring, "bg_ring")
        d = ms_decimation(w8, h8, pad16, tp.max_window)
        bins = ms_colour_bin(frame[::d, ::d], colour_bits)
        hd_, wd_ = bins.shape
        sh = d.bit_length() - 1
        cd = (ms_round_centre(c8[0] >> sh, cf), ms_round_centre(c8[1] >> sh, cf))
        wb, hb = ms_box_size(w8, d, wd_ - 2), ms_box_size(h8, d, hd_ - 2)
        cd = (min(max(cd[0], (wb - 1) // 2 + 1), wd_ - 2 - (wb - 1) // 2),
              min(max(cd[1], (hb - 1) // 2 + 1), hd_ - 2 - (hb - 1) // 2))
        m = ms_bg_model(bins, cd[0], cd[1], wb, hb, ring16, 1 << int(g["BIN_W"]))
        # the geometry is the tracker's: same model as FixedTrackerV2.init learnt
        assert np.array_equal(m.Qn, trk.model.Qn) and np.array_equal(m.T, trk.model.T), name
        out.append({"name": f"{name} frame 0 (D={d})", "bins": bins, "cx": cd[0], "cy": cd[1], "wb": wb,
                    "hb": hb, "ring16": ring16})
    return out


def real_cases_joint(g: dict, orient_t: int = 64) -> list[dict]:
    """The ms_bg_model calls of FixedTrackerV2(orient_T=orient_t).init on the init frame of real
    sequences, recorded as the tracker makes them: the joint bins of the decimated frame
    (ms_joint_bin(ms_colour_bin(frame[::D, ::D]), ms_orient_bin(ms_grey(frame), T)[::D, ::D])),
    the geometry, and n_bins = N_ORIENT 2**BIN_W."""
    import mstrack.fixed.tracker_v2 as tv2
    from mstrack.io.data import load_sequence
    from mstrack.track.params import TrackerParams

    colour_bits = int(g["BIN_W"]) // 3
    tp = TrackerParams(preset="v2", colour_bits=colour_bits, orient_T=orient_t)
    assert tp.n_bins_v2 == n_orient(g) << int(g["BIN_W"]), "N_ORIENT / BIN_W do not match the joint bins"
    out: list[dict] = []
    orig = tv2.ms_bg_model
    calls: list[tuple] = []

    def rec(bins, cx, cy, wb, hb, ring16, n_bins, *more):  # more: the model's optional widths (defaults: core v2's)
        calls.append((bins.copy(), cx, cy, wb, hb, ring16, n_bins))
        return orig(bins, cx, cy, wb, hb, ring16, n_bins, *more)

    tv2.ms_bg_model = rec
    try:
        for name in REAL_SEQS:
            seq = load_sequence(SEQ_ROOT / name)
            calls.clear()
            trk = tv2.FixedTrackerV2(tp)
            trk.init(seq.frame(0), seq.init_box())
            assert len(calls) == 1, name
            bins, cx, cy, wb, hb, ring16, n_bins = calls[0]
            assert n_bins == tp.n_bins_v2 and int(bins.max()) < n_bins
            d = seq.frame(0).shape[1] // bins.shape[1] if bins.shape[1] else 1
            out.append({"name": f"{name} frame 0 joint (T={orient_t}, {bins.shape[1]}x{bins.shape[0]}, D~{d})",
                        "bins": bins, "cx": cx, "cy": cy, "wb": wb, "hb": hb, "ring16": ring16})
    finally:
        tv2.ms_bg_model = orig
    return out


@cocotb.test()
async def bg_model_real(dut):
    tb = BgTB(dut)
    await tb.reset()
    rng = random.Random(1200)
    cases = real_cases(tb.g) if tb.n_or == 1 else real_cases_joint(tb.g)
    for i, c in enumerate(cases):
        await tb.run(c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"], 0.3 if i % 2 else 0.0, rng,
                     name=c["name"])


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_bg_model"
MODULE = "test_ms_bg_model"

PARAMS = [
    pytest.param(DEFAULTS, id="colour3"),                                       # 512 bins
    pytest.param({**DEFAULTS, "BIN_W": 6}, id="colour2"),                       # 64 bins
    pytest.param({**DEFAULTS, "BIN_W": 3, "HALF_W": 4, "COORD_W": 8, "RING_W": 6, "Q_W": 10, "O_W": 12,
                  "KD_W": 21}, id="small"),                                     # 8 bins, boxes <= 31
    pytest.param({**DEFAULTS, "N_ORIENT": 9}, id="orient9"),                    # 9 x 512 joint bins
    pytest.param({**DEFAULTS, "BIN_W": 3, "HALF_W": 4, "COORD_W": 8, "RING_W": 6, "Q_W": 10, "O_W": 12,
                  "KD_W": 21, "N_ORIENT": 4}, id="small_orient4"),              # 4 x 8, banks 2**k
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_bg_model_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 test_filter="bg_model_synthetic|bg_model_abandoned")


@pytest.mark.ghdl
def test_ms_bg_model_models_ghdl(hdl_waves):
    """MODELS 3 (one model per target) on the small joint bins (4 x 8): each model its own."""
    generics = {**PARAMS[4].values[0], "MODELS": 3}
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves, test_filter="bg_model_models",
                 build_name=f"ghdl_{TOP}_models3")


@pytest.mark.verilator
def test_ms_bg_model_models_verilator(hdl_waves):
    """The netlist of MODELS 3 (one model per target) on the small joint bins."""
    generics = {**PARAMS[4].values[0], "MODELS": 3}
    hdl.run_verilator(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves, test_filter="bg_model_models",
                      build_name=f"verilator_{TOP}_models3")


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS[:2] + [PARAMS[3]])
def test_ms_bg_model_real_ghdl(generics, hdl_waves):
    """The init frames of real sequences: colour bins (512, 64), and at N_ORIENT 9 the joint bins of
    FixedTrackerV2(orient_T=64) (colour_bits 3: 4608 bins)."""
    missing = [s for s in REAL_SEQS if not (SEQ_ROOT / s).is_dir()]
    if missing:
        pytest.skip(f"{SEQ_ROOT} has no {', '.join(missing)}: the real-frame cases need ../shared/data/sequences")
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves, test_filter="bg_model_real",
                 build_name=f"ghdl_{TOP}_real_{generics['BIN_W']}_o{generics.get('N_ORIENT', 1)}")


@pytest.mark.ghdl
def test_ms_bg_model_synth_orient9(tmp_path):
    """ghdl --synth (to Verilog) at N_ORIENT 9, tracker v2's widths: 4608-word count RAM, 9 model banks."""
    gen = {**DEFAULTS, "N_ORIENT": 9}
    v = hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v").read_text()
    assert "module ms_bg_model" in v and "m_qn_all" in v and "px_obin" in v


@pytest.mark.verilator
@pytest.mark.parametrize("generics", [PARAMS[0], PARAMS[3]])
def test_ms_bg_model_verilator(generics, hdl_waves):
    """The synthesised netlist (GHDL -> Verilog -> Verilator) on the synthetic cases (512 colour bins,
    and 9 x 512 joint bins)."""
    hdl.run_verilator(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                      test_filter="bg_model_synthetic|bg_model_abandoned")
