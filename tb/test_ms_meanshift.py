"""rtl/ms_meanshift.vhd (one feature's engine) against mstrack.fixed.blocks.ms_meanshift.

A region of bins is written into a real ms_region_ram (wrapper tb/ms_meanshift_tb_top.vhd),
the kernel tables are written from the model, the engine learns Q at one centre, then tracks
from several start centres; centre, S, iterations and stop code must equal the model's.
Regions: a target blob shifted against its learnt position (so the loop converges, stops on
rho or shift), and pure noise (max_iter / lost cases appear).
"""
from __future__ import annotations

import json
import os

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import STOP_CODES, Region, ms_histogram, ms_kernel, ms_meanshift
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.track.params import TrackerParams

ENGINE_GENERICS = ("LANES", "HALF_W", "REGION_W", "REGION_MAX", "STRIDE", "ADDR_W", "COORD_W", "KERNEL_EPAN",
                   "KERNEL_BITS", "KVAL_W", "KD_W", "HIST_W", "COUNT_W", "POSSUM_W", "SQRT_IN_W", "RHO_SUM_W",
                   "RATIO_Q_W", "WEIGHT_W", "WF", "RF", "SW_W", "SWX_W", "SHIFT_Q_W", "CF", "CENTRE_W",
                   "CENTRE_ABS_W", "MAX_ITER", "ITER_W", "EPS2")


def make_region(rng: np.random.Generator, h: int, w: int, nb: int, kind: str) -> np.ndarray:
    if kind == "noise":
        return rng.integers(0, nb, size=(h, w))
    base = rng.integers(0, nb // 4, size=(h, w))                 # background: low bins
    yy, xx = np.mgrid[0:h, 0:w]
    cy, cx = h / 2 + rng.uniform(-3, 3), w / 2 + rng.uniform(-3, 3)
    blob = ((yy - cy) / (h / 4)) ** 2 + ((xx - cx) / (w / 4)) ** 2 < 1
    base[blob] = rng.integers(nb // 2, nb, size=int(blob.sum()))  # target: high bins
    return base


async def write_region(dut, bins: np.ndarray, g: dict) -> None:
    L, stride = g["LANES"], g["STRIDE"]
    dut.we.value = 1
    for ry in range(bins.shape[0]):
        for rx in range(bins.shape[1]):
            dut.wbank.value = rx % L
            dut.waddr.value = ry * stride + rx // L
            dut.wdata.value = int(bins[ry, rx])
            await RisingEdge(dut.clk)
    dut.we.value = 0


def model_xr(ker: ms_kernel, n: int) -> list[int]:
    """Row extents XR[i] (ms_kernel_tables): largest dx with TA[dx] + TB[i] < D, 0 when i > ey."""
    return [max((dx for dx in range(ker.ex + 1) if i <= ker.ey and int(ker.TA[dx]) + int(ker.TB[i]) < ker.D),
                default=0) for i in range(n)]


async def write_tables(dut, ker: ms_kernel) -> None:
    n = max(ker.ex, ker.ey) + 1
    xr = model_xr(ker, n)
    dut.kd_d.value = ker.D
    dut.ex.value = ker.ex
    dut.ey.value = ker.ey
    dut.kt_we.value = 1
    for i in range(n):
        dut.kt_addr.value = i
        dut.kt_ta.value = int(ker.TA[min(i, ker.ex)]) if i <= ker.ex else (1 << len(dut.kt_ta)) - 1
        dut.kt_tb.value = int(ker.TB[min(i, ker.ey)]) if i <= ker.ey else (1 << len(dut.kt_tb)) - 1
        kmask = (1 << len(dut.kt_ka)) - 1
        dut.kt_ka.value = int(ker.KA[i]) & kmask if i <= ker.ex else kmask
        dut.kt_kb.value = int(ker.KB[i]) & kmask if i <= ker.ey else kmask
        dut.kt_xr.value = xr[i]
        await RisingEdge(dut.clk)
    dut.kt_we.value = 0


async def run(dut, learn: int, c8: tuple[int, int]) -> dict:
    dut.start_cx.value = c8[0]
    dut.start_cy.value = c8[1]
    dut.learn.value = learn
    dut.start.value = 1
    await RisingEdge(dut.clk)
    dut.start.value = 0
    for _ in range(2_000_000):
        await RisingEdge(dut.clk)
        if int(dut.done.value):
            return {k: int(getattr(dut, f"res_{k}").value) for k in ("cx", "cy", "s", "iter", "stop", "k")}
    raise AssertionError("engine did not finish")


@cocotb.test()
async def engine_vs_model(dut):
    g = json.loads(os.environ["MSTRACK_GENERICS"])
    job = json.loads(os.environ["MSTRACK_JOB"])
    tp = TrackerParams(**job["tp"])
    fp = FixedParams(**job["fp"])
    nb = 1 << g["BIN_W"]
    rng = np.random.default_rng(job["seed"])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    for s in ("we", "kt_we", "start", "learn"):
        getattr(dut, s).value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    cf = fp.centre_frac
    for case in range(job["cases"]):
        w, h = (int(v) for v in rng.integers(3, 2 * fp.max_half + 2, size=2))
        ker = ms_kernel(w, h, tp.kernel, fp.kernel_bits)
        rw = min(2 * ker.ex + 2 * fp.margin + 1, g["REGION_MAX"])
        rh = min(2 * ker.ey + 2 * fp.margin + 1, g["REGION_MAX"])
        org = (int(rng.integers(1, 300)), int(rng.integers(1, 200)))
        reg = Region(org[0], org[1], rw, rh, lo=(org[0] + ker.ex, org[1] + ker.ey),
                     hi=(org[0] + rw - 1 - ker.ex, org[1] + rh - 1 - ker.ey))
        kind = "noise" if case % 3 == 2 else "blob"
        learn_bins = make_region(rng, rh, rw, nb, kind)
        dut.reg_x.value = reg.x
        dut.reg_y.value = reg.y
        dut.hi_x.value = reg.hi[0] - reg.x
        dut.hi_y.value = reg.hi[1] - reg.y
        await write_tables(dut, ker)
        await write_region(dut, learn_bins, g)
        c_learn = ((reg.x + rw // 2) << cf, (reg.y + rh // 2) << cf)
        r = await run(dut, 1, c_learn)
        win = ((c_learn[0] + (1 << (cf - 1))) >> cf, (c_learn[1] + (1 << (cf - 1))) >> cf)
        Q = ms_histogram(learn_bins, reg, win, ker, nb).H
        assert r["k"] == ker.K, f"case {case}: K {r['k']} != {ker.K}"
        # track on a shifted copy of the region (target moved), from several starts
        sh = (int(rng.integers(-3, 4)), int(rng.integers(-3, 4)))
        bins = np.roll(learn_bins, sh, axis=(0, 1)) if kind == "blob" else make_region(rng, rh, rw, nb, kind)
        await write_region(dut, bins, g)
        for t in range(3):
            start = (int(rng.integers((reg.x - 2) << cf, (reg.x + rw + 2) << cf)),
                     int(rng.integers((reg.y - 2) << cf, (reg.y + rh + 2) << cf)))
            m = ms_meanshift(bins, Q, start, reg, ker, tp, fp, nb, g["SHIFT_Q_W"])
            got = await run(dut, 0, start)
            exp = {"cx": m.c8[0], "cy": m.c8[1], "s": m.S, "iter": m.iterations, "stop": STOP_CODES[m.stop]}
            assert {k: got[k] for k in exp} == exp, f"case {case}.{t} ({kind}, {w}x{h}, start {start}): " \
                                                     f"dut {got} model {exp}"


CONFIGS = {
    "colour_l2": (TrackerParams(colour_bits=2), FixedParams(max_half=7, margin=4), 2, "colour"),
    "edge_l1": (TrackerParams(), FixedParams(max_half=7, margin=4), 1, "edge"),
    "colour_l4_epan": (TrackerParams(colour_bits=2, kernel="epanechnikov"), FixedParams(max_half=7, margin=4), 4,
                       "colour"),
    "colour_default": (TrackerParams(), FixedParams(), 2, "colour"),
}


@pytest.mark.parametrize("name", list(CONFIGS))
def test_ms_meanshift(name):
    from mstrack.hw.hdl import TB_DIR, rtl_sources, run_ghdl
    tp, fp, lanes, feature = CONFIGS[name]
    g = core_generics(tp, fp, lanes)
    g["BIN_W"] = 3 * tp.colour_bits if feature == "colour" else tp.edge_bins_log2
    gen = {k: g[k] for k in ENGINE_GENERICS + ("BIN_W",)}
    job = {"tp": {"colour_bits": tp.colour_bits, "kernel": tp.kernel}, "fp": {"max_half": fp.max_half,
           "margin": fp.margin}, "seed": 5, "cases": 1 if name == "colour_default" else 4}
    run_ghdl("ms_meanshift_tb_top", "test_ms_meanshift", generics=gen,
             sources=rtl_sources("ms_meanshift_tb_top", extra=[TB_DIR / "ms_meanshift_tb_top.vhd"]),
             build_name=f"ms_meanshift_{name}",
             extra_env={"MSTRACK_GENERICS": json.dumps(g), "MSTRACK_JOB": json.dumps(job)})
