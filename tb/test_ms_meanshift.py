"""rtl/ms_meanshift.vhd (one feature's engine) against mstrack.fixed.blocks.ms_meanshift.

A region of bins is written into a real ms_region_ram (wrapper tb/ms_meanshift_tb_top.vhd),
the kernel tables are written from the model, the engine learns Q at one centre, then tracks
from several start centres; centre, S, iterations and stop code must equal the model's.
Regions: a target blob shifted against its learnt position (so the loop converges, stops on
rho or shift), and pure noise (max_iter / lost cases appear).

N_ORIENT 9 (tracker v2's joint colour x orientation bins, joint bin = 9 colour + orient): the
wrapper adds an orientation region RAM (ram_obin) written with the colour RAM; the model runs on the
joint bins (n_bins = 9 x 2**BIN_W).  Learn mode (K), track mode on the learnt Q, then on a Q loaded
through the one-word port (q_ext_we, q_ext_bank: 9 x 2**BIN_W clocks) and on one loaded through the
parallel port (q_ext_all_we, q_ext_all_data: 2**BIN_W clocks).  ``engine_real_calls`` replays the
ms_meanshift calls of FixedTrackerV2(orient_T=64) on real frames (region, Qw, start, kernel, max_iter)
with Qw loaded through either port, and compares with the model's results.
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
import pickle
from pathlib import Path

from mstrack.fixed.blocks import (STOP_CODES, Region, clamp_centre, ms_histogram, ms_kernel, ms_meanshift,
                                  ms_round_centre)
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
    """bins: colour bins (N_ORIENT 1) or joint bins N_ORIENT u + o (colour u to the colour RAM,
    orientation o to the orientation RAM, same address)."""
    L, stride, no = g["LANES"], g["STRIDE"], g.get("N_ORIENT", 1)
    dut.we.value = 1
    for ry in range(bins.shape[0]):
        for rx in range(bins.shape[1]):
            dut.wbank.value = rx % L
            dut.waddr.value = ry * stride + rx // L
            v = int(bins[ry, rx])
            dut.wdata.value = v // no
            if no > 1:
                dut.wodata.value = v % no
            await RisingEdge(dut.clk)
    dut.we.value = 0


def joint_region(rng: np.random.Generator, colour: np.ndarray, no: int, kind: str) -> np.ndarray:
    """Joint bins no colour + orient: flat (orientation no - 1) background pixels with some random
    orientations; inside the high-bin target random orientations 0 .. no - 2 (edges)."""
    o = np.where(rng.random(colour.shape) < 0.7, no - 1, rng.integers(0, no, size=colour.shape))
    if kind != "noise":
        tgt = colour >= int(colour.max() + 1) // 2
        o[tgt] = rng.integers(0, no - 1, size=int(tgt.sum()))
    return no * colour + o


async def load_q(dut, q: np.ndarray, g: dict, parallel: bool) -> None:
    """Q (joint bins N_ORIENT a + o) into the engine, while idle: one word per clock (q_ext_we,
    q_ext_bank o, address a; random order) or one address of every bank per clock (q_ext_all_we)."""
    no, hw = g.get("N_ORIENT", 1), g["HIST_W"]
    if parallel:
        dut.q_ext_all_we.value = 1
        for a in range(len(q) // no):
            dut.q_ext_addr.value = a
            dut.q_ext_all_data.value = sum(int(q[no * a + o]) << (o * hw) for o in range(no))
            await RisingEdge(dut.clk)
        dut.q_ext_all_we.value = 0
    else:
        dut.q_ext_we.value = 1
        order = np.random.default_rng(int(q.sum())).permutation(len(q))
        for j in order:
            dut.q_ext_addr.value = int(j) // no
            dut.q_ext_bank.value = int(j) % no
            dut.q_ext_data.value = int(q[j])
            await RisingEdge(dut.clk)
        dut.q_ext_we.value = 0


def idle_inputs(dut) -> None:
    """Every input at rest (the Verilator netlist has no port defaults)."""
    for s in ("we", "kt_we", "start", "learn", "wodata", "q_ext_we", "q_ext_addr", "q_ext_data", "q_ext_bank",
              "q_ext_all_we", "q_ext_all_data", "lo_x_in", "lo_y_in"):
        if hasattr(dut, s):
            getattr(dut, s).value = 0


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


async def run(dut, learn: int, c8: tuple[int, int], max_it: int | None = None) -> dict:
    dut.start_cx.value = c8[0]
    dut.start_cy.value = c8[1]
    dut.learn.value = learn
    if max_it is not None:
        dut.max_it.value = max_it
    dut.start.value = 1
    await RisingEdge(dut.clk)
    dut.start.value = 0
    for _ in range(2_000_000):
        await RisingEdge(dut.clk)
        if int(dut.done.value):
            return {k: int(getattr(dut, f"res_{k}").value)   # res_k: set by learn passes only
                    for k in ("cx", "cy", "s", "iter", "stop") + (("k",) if learn else ())}
    raise AssertionError("engine did not finish")


@cocotb.test()
async def engine_vs_model(dut):
    g = json.loads(os.environ["MSTRACK_GENERICS"])
    job = json.loads(os.environ["MSTRACK_JOB"])
    tp = TrackerParams(**job["tp"])
    fp = FixedParams(**job["fp"])
    no = g.get("N_ORIENT", 1)
    nb = 1 << g["BIN_W"]
    rng = np.random.default_rng(job["seed"])
    orng = np.random.default_rng(job["seed"] + 1000)        # orientations (N_ORIENT > 1) apart
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    idle_inputs(dut)
    if no > 1:
        dut.max_it.value = g["MAX_ITER"]
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
        if g.get("LO_IN") and case % 2 == 1:
            # LO_IN: the clamp's lower bound above ex / ey (an init job's region inside its slot rectangle)
            up = (int(rng.integers(1, 6)), int(rng.integers(1, 6)))
            reg = Region(reg.x, reg.y, rw, rh, lo=(min(reg.lo[0] + up[0], reg.hi[0]), min(reg.lo[1] + up[1], reg.hi[1])),
                         hi=reg.hi)
        if g.get("LO_IN"):
            dut.lo_x_in.value = reg.lo[0] - reg.x
            dut.lo_y_in.value = reg.lo[1] - reg.y
        kind = "noise" if case % 3 == 2 else "blob"
        learn_bins = make_region(rng, rh, rw, nb, kind)
        if no > 1:
            learn_bins = joint_region(orng, learn_bins, no, kind)
        dut.reg_x.value = reg.x
        dut.reg_y.value = reg.y
        dut.hi_x.value = reg.hi[0] - reg.x
        dut.hi_y.value = reg.hi[1] - reg.y
        await write_tables(dut, ker)
        await write_region(dut, learn_bins, g)
        c_learn = ((reg.x + rw // 2) << cf, (reg.y + rh // 2) << cf)
        r = await run(dut, 1, c_learn)
        win = ((c_learn[0] + (1 << (cf - 1))) >> cf, (c_learn[1] + (1 << (cf - 1))) >> cf)
        Q = ms_histogram(learn_bins, reg, win, ker, no * nb).H
        assert r["k"] == ker.K, f"case {case}: K {r['k']} != {ker.K}"
        # track on a shifted copy of the region (target moved), from several starts
        sh = (int(rng.integers(-3, 4)), int(rng.integers(-3, 4)))
        if kind == "blob":
            bins = np.roll(learn_bins, sh, axis=(0, 1))
        else:
            bins = make_region(rng, rh, rw, nb, kind)
            if no > 1:
                bins = joint_region(orng, bins, no, kind)
        await write_region(dut, bins, g)
        # Q: learnt; with job["qload"] then a Q loaded word by word (bank select) and one loaded an
        # address of every bank per clock (the model histograms of other windows of the learn region)
        qs = [("learnt", Q)]
        if job.get("qload"):
            for how in ("word", "parallel"):
                ow = (int(rng.integers(reg.lo[0], reg.hi[0] + 1)), int(rng.integers(reg.lo[1], reg.hi[1] + 1)))
                qs.append((how, ms_histogram(learn_bins, reg, ow, ker, no * nb).H))
        for how, Qt in qs:
            if how != "learnt":
                await load_q(dut, Qt, g, how == "parallel")
            for t in range(3):
                start = (int(rng.integers((reg.x - 2) << cf, (reg.x + rw + 2) << cf)),
                         int(rng.integers((reg.y - 2) << cf, (reg.y + rh + 2) << cf)))
                # N_ORIENT > 1: the third start with max_it = 2 (the iteration limit port; max_iter stops)
                mi = 2 if (no > 1 and t == 2) else g["MAX_ITER"]
                m = ms_meanshift(bins, Qt, start, reg, ker, tp.with_(max_iter=mi), fp, no * nb, g["SHIFT_Q_W"])
                got = await run(dut, 0, start, mi if no > 1 else None)
                exp = {"cx": m.c8[0], "cy": m.c8[1], "s": m.S, "iter": m.iterations, "stop": STOP_CODES[m.stop]}
                assert {k: got[k] for k in exp} == exp, f"case {case}.{t} ({kind}, {w}x{h}, Q {how}, start " \
                                                         f"{start}): dut {got} model {exp}"
                dut._log.info("case %d.%d %s %dx%d Q %s: %s", case, t, kind, w, h, how, exp)


@cocotb.test()
async def engine_real_calls(dut):
    """The ms_meanshift calls of FixedTrackerV2(orient_T=64) on real frames (pickled by the pytest side,
    :func:`real_calls`): region (joint bins), Qw (through the one-word port or the parallel port, in
    turn), kernel tables, start, max_iter; the result must equal the tracker's.  Every LEARN_EVERY-th
    call also learns Q at the result centre (K) and tracks again from the start on the learnt Q."""
    g = json.loads(os.environ["MSTRACK_GENERICS"])
    job = json.loads(os.environ["MSTRACK_JOB"])
    calls = pickle.loads(Path(job["calls"]).read_bytes())
    tp = TrackerParams(preset="v2", orient_T=64)
    fp = FixedParams()
    no, cf = g["N_ORIENT"], fp.centre_frac
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    idle_inputs(dut)
    dut.max_it.value = g["MAX_ITER"]
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    for k, c in enumerate(calls):
        reg, ker = c["reg"], c["ker"]
        dut.reg_x.value = reg.x
        dut.reg_y.value = reg.y
        dut.hi_x.value = reg.hi[0] - reg.x
        dut.hi_y.value = reg.hi[1] - reg.y
        await write_tables(dut, ker)
        await write_region(dut, c["sub"], g)
        parallel = k % 2 == 0
        await load_q(dut, c["Qw"], g, parallel)
        got = await run(dut, 0, c["start8"], c["max_iter"])
        exp = {"cx": c["c8"][0], "cy": c["c8"][1], "s": c["S"], "iter": c["iter"], "stop": STOP_CODES[c["stop"]]}
        assert {q: got[q] for q in exp} == exp, f"call {k} ({c['where']}, {ker.w}x{ker.h}, region {reg.w}x" \
                                                 f"{reg.h}, Qw {'parallel' if parallel else 'word'}): dut {got} " \
                                                 f"tracker {exp}"
        dut._log.info("call %d %s %dx%d region %dx%d: %s", k, c["where"], ker.w, ker.h, reg.w, reg.h, exp)
        if k % job["learn_every"] == 0:
            r = await run(dut, 1, c["c8"])
            c0 = clamp_centre(c["c8"], reg, cf)
            cl = (ms_round_centre(c0[0], cf), ms_round_centre(c0[1], cf))
            Q = ms_histogram(c["sub"], reg, cl, ker, no << g["BIN_W"]).H
            assert r["k"] == ker.K == int(Q.sum()), f"call {k}: learn K {r['k']} != {ker.K}"
            m = ms_meanshift(c["sub"], Q, c["start8"], reg, ker, tp.with_(max_iter=c["max_iter"]), fp,
                             no << g["BIN_W"], g["SHIFT_Q_W"])
            got = await run(dut, 0, c["start8"], c["max_iter"])
            exp = {"cx": m.c8[0], "cy": m.c8[1], "s": m.S, "iter": m.iterations, "stop": STOP_CODES[m.stop]}
            assert {q: got[q] for q in exp} == exp, f"call {k} learnt Q: dut {got} model {exp}"


CONFIGS = {
    "colour_l2": (TrackerParams(colour_bits=2), FixedParams(max_half=7, margin=4), 2, "colour"),
    "edge_l1": (TrackerParams(), FixedParams(max_half=7, margin=4), 1, "edge"),
    "colour_l4_epan": (TrackerParams(colour_bits=2, kernel="epanechnikov"), FixedParams(max_half=7, margin=4), 4,
                       "colour"),
    "colour_default": (TrackerParams(), FixedParams(), 2, "colour"),
}


@pytest.mark.ghdl
def test_ms_meanshift_lo_in():
    """LO_IN: the clamp's lower bound from lo_x_in / lo_y_in (the init job's reference pass); in every second
    case it is 1 to 5 px above ex / ey, and the model's Region carries the same bound."""
    from mstrack.hw.hdl import TB_DIR, rtl_sources, run_ghdl
    tp, fp, lanes, _ = CONFIGS["colour_l2"]
    g = core_generics(tp, fp, lanes)
    g["BIN_W"] = 3 * tp.colour_bits
    g["LO_IN"] = 1
    gen = {k: g[k] for k in ENGINE_GENERICS + ("BIN_W", "LO_IN")}
    job = {"tp": {"colour_bits": tp.colour_bits, "kernel": tp.kernel}, "fp": {"max_half": fp.max_half,
           "margin": fp.margin}, "seed": 9, "cases": 6}
    run_ghdl("ms_meanshift_tb_top", "test_ms_meanshift", generics=gen,
             sources=rtl_sources("ms_meanshift_tb_top", extra=[TB_DIR / "ms_meanshift_tb_top.vhd"]),
             build_name="ms_meanshift_lo_in", testcase="engine_vs_model",
             extra_env={"MSTRACK_GENERICS": json.dumps(g), "MSTRACK_JOB": json.dumps(job)})


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
             build_name=f"ms_meanshift_{name}", testcase="engine_vs_model",
             extra_env={"MSTRACK_GENERICS": json.dumps(g), "MSTRACK_JOB": json.dumps(job)})


# ---------------------------------------------------------------- N_ORIENT 9: joint colour x orientation bins

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
if not SEQ_ROOT.is_dir():
    SEQ_ROOT = Path("/work/shared/data/sequences")
TB_TOP = "ms_meanshift_tb_top"


def _engine_run(sim: str, gen: dict, g: dict, job: dict, build: str, test: str) -> None:
    from mstrack.hw import hdl
    src = hdl.rtl_sources(TB_TOP, extra=[hdl.TB_DIR / "ms_meanshift_tb_top.vhd"])
    env = {"MSTRACK_GENERICS": json.dumps(g), "MSTRACK_JOB": json.dumps(job)}
    if sim == "ghdl":
        hdl.run_ghdl(TB_TOP, "test_ms_meanshift", generics=gen, sources=src, build_name=build,
                     testcase=test, extra_env=env)
    else:
        hdl.run_verilator(TB_TOP, "test_ms_meanshift", gen, src, build_name=build, testcase=test,
                          extra_env=env)


def orient_generics(tp: TrackerParams, fp: FixedParams, lanes: int) -> tuple[dict, dict]:
    g = core_generics(tp, fp, lanes)
    g["BIN_W"] = 3 * tp.colour_bits
    g["N_ORIENT"] = 9
    return {k: g[k] for k in ENGINE_GENERICS + ("BIN_W", "N_ORIENT")}, g


@pytest.mark.ghdl
def test_ms_meanshift_orient_ghdl():
    """N_ORIENT 9 (576 joint bins: colour bits 2, LANES 2): generated regions of joint bins, learn (K),
    track on the learnt Q and on Qs loaded through q_ext_we / q_ext_bank and q_ext_all_we (seed 26: every stop
    code, shift, rho, lost and max_iter with max_it = 2 on every third start)."""
    tp, fp = TrackerParams(colour_bits=2), FixedParams(max_half=7, margin=4)
    gen, g = orient_generics(tp, fp, 2)
    job = {"tp": {"colour_bits": 2, "kernel": "flat"}, "fp": {"max_half": 7, "margin": 4}, "seed": 26,
           "cases": 3, "qload": True}
    _engine_run("ghdl", gen, g, job, "ms_meanshift_orient9", "engine_vs_model")


#: (sequence, frames) for the real calls: the init frame, then frames 1 .. n - 1 tracked
REAL_SHORT = (("Girl", 2),)
REAL_LONG = (("Girl", 40), ("MotorRolling", 12), ("Couple", 20))


def real_calls(segments) -> list[dict]:
    """Every ms_meanshift call FixedTrackerV2(TrackerParams(preset="v2", orient_T=64)) makes on the
    first frames of ``segments``: its region of joint bins, Qw, start, kernel, max_iter and result."""
    import mstrack.fixed.tracker_v2 as tv2
    from mstrack.fixed.formats import widths
    from mstrack.io.data import load_sequence

    out: list[dict] = []
    orig = tv2.ms_meanshift
    where = [""]

    def rec(sub, Qw, start8, reg, ker, tp, fx, n_bins, shift_q, trace=False, **more):  # more: q_frac (0: core v2's)
        r = orig(sub, Qw, start8, reg, ker, tp, fx, n_bins, shift_q, trace, **more)
        out.append({"sub": np.asarray(sub).copy(), "Qw": np.asarray(Qw).copy(), "start8": tuple(int(v) for v in start8),
                    "reg": reg, "ker": ker, "max_iter": tp.max_iter, "n_bins": n_bins, "shift_q": shift_q,
                    "c8": tuple(int(v) for v in r.c8), "S": int(r.S), "iter": int(r.iterations), "stop": r.stop,
                    "where": where[0]})
        return r

    tv2.ms_meanshift = rec
    try:
        for name, n in segments:
            seq = load_sequence(SEQ_ROOT / name)
            t = tv2.FixedTrackerV2(TrackerParams(preset="v2", orient_T=64))
            t.init(seq.frame(0), seq.init_box())
            for i in range(1, n):
                where[0] = f"{name} frame {i}"
                t.update(seq.frame(i))
            assert widths(t.params, t.fixed).shift_q == out[-1]["shift_q"]
    finally:
        tv2.ms_meanshift = orig
    return out


def _real(sim: str, segments, build: str, tmp_path, learn_every: int) -> None:
    missing = [s for s, _ in segments if not (SEQ_ROOT / s).is_dir()]
    if missing:
        pytest.skip(f"{SEQ_ROOT} has no {', '.join(missing)}: the real calls need ../shared/data/sequences")
    tp, fp = TrackerParams(preset="v2", orient_T=64), FixedParams()
    gen, g = orient_generics(tp, fp, 4)
    calls = real_calls(segments)
    assert calls and all(c["n_bins"] == 9 << g["BIN_W"] and c["shift_q"] == g["SHIFT_Q_W"] for c in calls)
    assert all(c["reg"].w <= g["REGION_MAX"] and c["reg"].h <= g["REGION_MAX"] for c in calls)
    path = tmp_path / "calls.pkl"
    path.write_bytes(pickle.dumps(calls))
    _engine_run(sim, gen, g, {"calls": str(path), "learn_every": learn_every}, build, "engine_real_calls")


@pytest.mark.ghdl
def test_ms_meanshift_orient_real_ghdl(tmp_path):
    """N_ORIENT 9 at core v2's size (LANES 4, 512 colour x 9 = 4,608 joint bins) on the ms_meanshift calls of
    FixedTrackerV2(orient_T=64) on Girl's frame 1 (REAL_SHORT: one call, Qw through the parallel port, then a
    learn (K) and a track run on the learnt Q)."""
    _real("ghdl", REAL_SHORT, "ms_meanshift_orient9_real", tmp_path, learn_every=1)


@pytest.mark.verilator
def test_ms_meanshift_orient_real_verilator(tmp_path):
    """The same bench on the GHDL -> Verilog -> Verilator netlist, more frames (REAL_LONG: Girl,
    MotorRolling, Couple)."""
    _real("verilator", REAL_LONG, "verilator_ms_meanshift_orient9_real", tmp_path, learn_every=5)
