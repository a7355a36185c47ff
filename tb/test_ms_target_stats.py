"""cocotb test bench + pytest entry points for rtl/ms_target_stats.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_target_stats` (nt, st2, n_in, nt_in of a window), compared
exactly for every pass.  Two benches:

* ``ms_target_stats`` alone: the test plays ms_pixel_pass's scan (the beats of the window's
  kernel ellipse, LANES-aligned groups with lane masks: :func:`scan_beats`, the rule of
  rtl/ms_window_scan.vhd) on the px_* tap and the bins one clock later on ram_data, at full speed
  (one beat per clock, passes back to back) and throttled (random idle clocks between beats and
  passes); masked lanes carry random bins.  Tables from the model (ms_kernel KA/KB, T).  The
  latency STATS_LAT = 6 + log2(LANES) (edge sampling the last beat -> edge sampling done) is
  asserted for every pass.
* ``ms_target_stats_tb_top`` (tb/ms_target_stats_tb_top.vhd): attached as in the core, to a real
  ms_pixel_pass (flat) with its kernel tables from a real ms_kernel_tables (KERNEL_EPAN = 1:
  the KA/KB it writes feed ms_target_stats) and a region RAM model; the windows, T tables and
  bins are those FixedTrackerV2 used on the first frames of real sequences (:func:`real_windows`).
  The offset from the pass's done to the statistics' done is asserted.

Run: ``.venv/bin/python -m pytest tb/test_ms_target_stats.py``.
"""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.blocks import ms_kernel
from mstrack.fixed.blocks_v2 import TargetStats, ms_target_stats

CFG_ENV = "MS_TARGET_STATS_CFG"
REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
if not SEQ_ROOT.is_dir():
    SEQ_ROOT = Path("/work/shared/data/sequences")


def stats_latency(lanes: int) -> int:
    """STATS_LAT of rtl/ms_target_stats.vhd: 6 + log2(LANES)."""
    return 6 + (lanes.bit_length() - 1)


def model_xr(ker: ms_kernel) -> list[int]:
    """XR[i]: largest dx in 0..ex inside row |dy| = i (the scan's row extent), from the model."""
    xr = []
    for i in range(ker.ey + 1):
        ins = [dx for dx in range(ker.ex + 1) if int(ker.TA[dx]) + int(ker.TB[i]) < ker.D]
        xr.append(ins[-1])
    return xr


def scan_beats(ker: ms_kernel, wx: int, wy: int, lanes: int) -> list[tuple[int, int, int, int]]:
    """Beats of ms_window_scan for the window at (wx, wy): (x0, dy, mask, last), x0 = first column
    of the LANES-aligned group (lane l: column x0 + l, dx = x0 + l - wx)."""
    xr = model_xr(ker)
    out = []
    for dy in range(-ker.ey, ker.ey + 1):
        r = xr[abs(dy)]
        for g in range((wx - r) // lanes, (wx + r) // lanes + 1):
            x0 = g * lanes
            mask = sum(1 << l for l in range(lanes) if abs(x0 + l - wx) <= r)
            out.append((x0, dy, mask, 0))
    x0, dy, mask, _ = out[-1]
    out[-1] = (x0, dy, mask, 1)
    return out


def signed_bits(v: int, w: int) -> int:
    return v & ((1 << w) - 1)


@cocotb.test()
@cocotb.parametrize(throttle=[False, True])
async def random_windows(dut, throttle):
    """Random bins, random T, random window sizes and positions (the block alone).  Each kernel
    size gets two windows; at full speed the second pass follows the first with no gap."""
    c = json.loads(os.environ[CFG_ENV])
    lanes, bw, kb, pad16 = c["LANES"], c["BIN_W"], c["KERNEL_BITS"], c["PAD16"]
    dw = c["REGION_W"] + 1
    max_win = 2 * ((1 << c["HALF_W"]) - 1) + 1
    n_kernels = c.get("N", 40)
    lat = stats_latency(lanes)
    rng = random.Random(11 + throttle)
    nrng = np.random.default_rng(11 + throttle)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    for s in ("rst", "t_we", "kt_we", "px_valid", "px_last"):
        getattr(dut, s).value = Immediate(1 if s == "rst" else 0)
    # N_ORIENT > 1: joint bins j = N_ORIENT colour + obin (ms_joint_bin); T indexed by j as in the
    # model; the block gets colour = j // N_ORIENT on ram_data / t_addr and obin = j % N_ORIENT on
    # ram_obin (masked lanes and idle beats: random obins 0 .. 15); T written as N_ORIENT-bit words
    nor = int(c.get("N_ORIENT", 1))
    n_bins = nor << bw
    cycle = 0
    got: list[tuple[int, tuple[int, int, int, int]]] = []     # (edge sampling done = 1, results)
    expected: list[tuple[int, TargetStats, str]] = []        # (edge sampling the last beat, model, what)

    async def tick():
        nonlocal cycle
        await RisingEdge(dut.clk)
        cycle += 1
        if int(dut.done.value):                              # sampled by this edge
            got.append((cycle, (int(dut.nt.value), int(dut.st2.value), int(dut.n_in.value),
                                int(dut.nt_in.value))))

    async def settle():
        """Wait for every pass driven so far, then check them all."""
        for _ in range(lat + 2):
            await tick()
        assert len(got) == len(expected), f"{len(got)} results for {len(expected)} passes"
        for (t_done, g), (t_last, e, what) in zip(got, expected):
            assert g == (e.nt, e.st2, e.n_in, e.nt_in), f"{what}: got {g}, model {e}"
            assert t_done - t_last == lat, f"{what}: latency {t_done - t_last} != {lat}"
        got.clear()
        expected.clear()

    async def write_T(T: np.ndarray):
        # N_ORIENT > 1: one colour address per clock, bit o = T[N_ORIENT colour + o] (ms_bg_model's
        # m_t_all), t_data random (ignored); N_ORIENT = 1: one bin per clock on t_data
        for u in range(n_bins // nor):
            dut.t_we.value = 1
            dut.t_addr.value = u
            if nor > 1:
                dut.t_data_all.value = sum(int(T[nor * u + o]) << o for o in range(nor))
                dut.t_data.value = rng.getrandbits(1)
            else:
                dut.t_data.value = int(T[u])
            await tick()
        dut.t_we.value = 0

    async def write_kernel(ker: ms_kernel):
        for i in range(max(ker.ex, ker.ey) + 1):
            dut.kt_we.value = 1
            dut.kt_addr.value = i
            dut.kt_ka.value = int(ker.KA[i]) if i <= ker.ex else (1 << c["KT_W"]) - 1
            dut.kt_kb.value = int(ker.KB[i]) if i <= ker.ey else (1 << c["KT_W"]) - 1
            await tick()
        dut.kt_we.value = 0

    async def run_pass(ker: ms_kernel, bins: np.ndarray, wx: int, wy: int, what: str):
        beats = scan_beats(ker, wx, wy, lanes)
        prev, prev_o = None, 0
        i = 0
        while i < len(beats) or prev is not None:
            # this cycle: the bins of the beat driven one cycle ago (random otherwise), and the next beat
            dut.ram_data.value = prev if prev is not None else rng.getrandbits(lanes * bw)
            if nor > 1:
                dut.ram_obin.value = prev_o if prev is not None else rng.getrandbits(lanes * 4)
            prev = None
            drive = i < len(beats) and not (throttle and rng.random() < 0.3)
            if drive:
                x0, dy, mask, last = beats[i]
                dut.px_valid.value = 1
                dut.px_mask.value = mask
                dut.px_dx.value = signed_bits(x0 - wx, dw)
                dut.px_dy.value = signed_bits(dy, dw)
                dut.px_last.value = last
                prev, prev_o = 0, 0
                for l in range(lanes):
                    if (mask >> l) & 1:
                        j = int(bins[wy + dy, x0 + l])
                        v, o = j // nor, j % nor
                    else:
                        v, o = rng.randrange(n_bins // nor), rng.randrange(16)
                    prev |= v << (l * bw)
                    prev_o |= o << (l * 4)
                i += 1
            else:
                dut.px_valid.value = 0
                dut.px_mask.value = rng.getrandbits(lanes)      # ignored when not valid
                dut.px_last.value = rng.getrandbits(1)
                dut.px_dx.value = rng.getrandbits(dw)
            await tick()
            if drive and beats[i - 1][3]:
                expected.append((cycle, ms_target_stats(bins, T, (wx, wy), ker, kb, pad16), what))
        dut.px_valid.value = 0
        dut.px_last.value = 0
        dut._log.info("%s: %d beats, %s", what, len(beats), expected[-1][1])

    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    if c.get("REAL_ORIENT_T"):
        # the windows FixedTrackerV2(orient_T) passed to ms_target_stats on real frames (joint bins,
        # the model's T of the joint bins), played through the same scan
        lastT = None
        for k, rw in enumerate(real_windows(SEGMENTS_JOINT, max_window=max_win, orient_t=c["REAL_ORIENT_T"])):
            assert int(rw["bins"].max()) < n_bins and len(rw["T"]) == n_bins
            if lastT is None or not np.array_equal(lastT, rw["T"]):
                T = rw["T"]
                await write_T(T)
                lastT = T
            ker = ms_kernel(rw["w"], rw["h"], "flat", rw["kb"])
            await write_kernel(ker)
            await run_pass(ker, rw["bins"], rw["win"][0], rw["win"][1], f"real window {k} {rw['w']}x{rw['h']}")
            assert expected[-1][1] == rw["stats"], "the replayed window's model differs from the tracker's"
            await settle()
        return
    T = (nrng.random(n_bins) < 0.4).astype(np.int64)
    await write_T(T)
    region_n = min(2 * max_win + 8, (1 << c["REGION_W"]) - 1)
    for p in range(n_kernels):
        if p == n_kernels // 2:
            T = (nrng.random(n_bins) < rng.choice([0.05, 0.9])).astype(np.int64)
            await write_T(T)
        w, h = (max_win, max_win) if p == 0 else (rng.randint(3, max_win), rng.randint(3, max_win))
        ker = ms_kernel(w, h, "flat", kb)
        await write_kernel(ker)
        for q in range(2):
            if (p + q) % 3 == 2:   # runs of equal bins
                bins = np.repeat(nrng.integers(0, n_bins, size=(region_n, region_n // 8 + 1)), 8, axis=1)
                bins = bins[:, :region_n]
            else:
                bins = nrng.integers(0, n_bins, size=(region_n, region_n))
            wx = rng.randint(ker.ex, region_n - 1 - ker.ex)
            wy = rng.randint(ker.ey, region_n - 1 - ker.ey)
            await run_pass(ker, bins, wx, wy, f"pass {p}.{q} {w}x{h} at ({wx},{wy})")
            if throttle:
                for _ in range(rng.randint(0, 8)):
                    await tick()
        await settle()


# ---------------------------------------------------------------- attached to ms_pixel_pass

#: (sequence, first frame, frames) whose ms_target_stats calls are replayed: tracking at decimation 1
#: and 2 (Couple, MotorRolling, Deer), and frames lost with the wide search (9 start points at 2D:
#: Couple 46-47, Subway 38-39, bag_vot 11-12)
SEGMENTS = (("Couple", 0, 3), ("MotorRolling", 0, 3), ("Deer", 0, 3), ("Couple", 45, 3), ("Subway", 37, 3),
            ("bag_vot", 10, 3))


#: joint-bin segments (FixedTrackerV2(orient_T=64)): init and first frames at D = 1 and 2
SEGMENTS_JOINT = (("Girl", 0, 3), ("MotorRolling", 0, 2), ("Couple", 0, 2))


def real_windows(segments=SEGMENTS, max_window: int = 127, orient_t: int = 0) -> list[dict]:
    """The (bins, T, win, ker) of every ms_target_stats call FixedTrackerV2 makes on the frames of
    ``segments`` (the tracker runs from frame 0; frame 0 is the init pass), with the model's result;
    bins cropped to the window box plus 2 px (the statistics see only the window).  ``orient_t`` > 0:
    the tracker with joint colour x orientation bins (bins and T over 9 2**(3 colour_bits))."""
    import mstrack.fixed.tracker_v2 as tv2
    from mstrack.io.data import load_sequence
    from mstrack.track.params import TrackerParams

    out: list[dict] = []
    orig = tv2.ms_target_stats
    on = [False]

    def rec(bins, T, win, ker, kb, pad16):
        st = orig(bins, T, win, ker, kb, pad16)
        if on[0]:
            x0, y0 = max(0, win[0] - ker.ex - 2), max(0, win[1] - ker.ey - 2)
            sub = bins[y0: win[1] + ker.ey + 3, x0: win[0] + ker.ex + 3]
            out.append({"bins": sub.copy(), "T": T.copy(), "win": (win[0] - x0, win[1] - y0), "w": ker.w,
                        "h": ker.h, "kb": kb, "pad16": pad16, "stats": st})
        return st

    tv2.ms_target_stats = rec
    try:
        for name, first, n in segments:
            seq = load_sequence(SEQ_ROOT / name)
            t = tv2.FixedTrackerV2(TrackerParams(preset="v2", max_window=max_window, orient_T=orient_t))
            on[0] = first == 0
            t.init(seq.frame(0), seq.init_box())
            for i in range(1, first + n):
                on[0] = i >= first
                t.update(seq.frame(i))
    finally:
        tv2.ms_target_stats = orig
    return out


@cocotb.test()
async def attached_real_windows(dut):
    """ms_kernel_tables -> ms_pixel_pass (flat) + ms_target_stats on the windows of real frames."""
    c = json.loads(os.environ[CFG_ENV])
    lanes, bw, aw, stride, rmax = c["LANES"], c["BIN_W"], c["ADDR_W"], c["STRIDE"], c["REGION_MAX"]
    n_bins = 1 << bw
    rng = random.Random(5)
    mem = [dict() for _ in range(lanes)]
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    for s in ("rst", "t_we", "kt_start", "start"):
        getattr(dut, s).value = Immediate(1 if s == "rst" else 0)

    async def ram():
        amask = (1 << aw) - 1
        while True:
            await RisingEdge(dut.clk)
            a = int(dut.ram_addr.value)
            d = 0
            for lane in range(lanes):
                d |= mem[lane].get((a >> (lane * aw)) & amask, 0) << (lane * bw)
            dut.ram_data.value = d

    cocotb.start_soon(ram())
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    while not int(dut.ready.value):
        await RisingEdge(dut.clk)
    windows = real_windows(max_window=c["MAX_WINDOW"])
    windows = windows[:: c.get("EVERY", 1)]
    lastT = None
    offsets = set()
    for k, rw in enumerate(windows):
        if lastT is None or not np.array_equal(lastT, rw["T"]):
            for u in range(n_bins):
                dut.t_we.value = 1
                dut.t_addr.value = u
                dut.t_data.value = int(rw["T"][u])
                await RisingEdge(dut.clk)
            dut.t_we.value = 0
            lastT = rw["T"]
        ker = ms_kernel(rw["w"], rw["h"], "flat", rw["kb"])
        dut.w.value = rw["w"]
        dut.h.value = rw["h"]
        dut.kt_start.value = 1
        await RisingEdge(dut.clk)
        dut.kt_start.value = 0
        while True:
            await RisingEdge(dut.clk)
            if int(dut.kt_done.value):
                break
        bins = rw["bins"]
        assert bins.shape[0] <= rmax and bins.shape[1] <= rmax
        for lane in range(lanes):
            mem[lane].clear()
        for ry in range(rmax):
            for rx in range(stride * lanes):
                inside = ry < bins.shape[0] and rx < bins.shape[1]
                mem[rx % lanes][ry * stride + rx // lanes] = int(bins[ry, rx]) if inside else rng.randrange(n_bins)
        wx, wy = rw["win"]
        dut.win_x.value = wx
        dut.win_y.value = wy
        await RisingEdge(dut.clk)    # win_y stable from the clock before start (ms_window_scan)
        dut.start.value = 1
        await RisingEdge(dut.clk)
        dut.start.value = 0
        n, pp_done_at, st_done_at, got = 0, None, None, None
        while st_done_at is None or pp_done_at is None:
            await RisingEdge(dut.clk)
            n += 1
            if int(dut.done.value):
                pp_done_at = n
            if int(dut.st_done.value):
                st_done_at = n
                got = (int(dut.nt.value), int(dut.st2.value), int(dut.n_in.value), int(dut.nt_in.value))
            assert n < 100000, "no done"
        offsets.add(st_done_at - pp_done_at)
        exp: TargetStats = rw["stats"]
        assert got == (exp.nt, exp.st2, exp.n_in, exp.nt_in), \
            f"window {k} {rw['w']}x{rw['h']} at {rw['win']}: got {got}, model {exp}"
        dut._log.info("window %d: %dx%d, pass %d clocks, stats %d after done: %s OK", k, rw["w"], rw["h"],
                      pp_done_at, st_done_at - pp_done_at, exp)
    assert offsets == {c["DONE_OFFSET"]}, f"stats done - pass done = {offsets}, expected {c['DONE_OFFSET']}"


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics, v2_scale_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_target_stats"
MODULE = "test_ms_target_stats"
KEYS = ("LANES", "BIN_W", "HALF_W", "REGION_W", "KERNEL_BITS", "KT_W", "PAD16", "COUNT_W", "ST2_W")
TB_TOP = "ms_target_stats_tb_top"
TB_TOP_VHD = Path(__file__).resolve().parent / f"{TB_TOP}.vhd"
PASS_LAT = 10   # rtl/ms_pixel_pass.vhd


def stats_generics(tp: TrackerParams, fp: FixedParams, lanes: int) -> dict:
    g = v2_scale_generics(tp, fp, lanes)
    return {k: g[k] for k in KEYS}


CASES = [
    pytest.param(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 4, {}, id="small_L4"),
    pytest.param(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 1, {}, id="small_L1"),
    pytest.param(TrackerParams(preset="v2", colour_bits=2, pad=0.0), FixedParams(max_half=7, margin=4), 2, {},
                 id="small_L2_pad0"),
    pytest.param(TrackerParams(preset="v2", colour_bits=2, pad=0.5), FixedParams(max_half=7, margin=4, kernel_bits=5),
                 8, {}, id="small_L8_pad8_kb5"),
    pytest.param(TrackerParams(preset="v2"), FixedParams(), 4, {"N": 3}, id="default_L4"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("tp,fp,lanes,extra", CASES)
def test_ms_target_stats_ghdl(tp, fp, lanes, extra, hdl_waves):
    gen = stats_generics(tp, fp, lanes)
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, testcase=None,
                 test_filter="random_windows", extra_env={CFG_ENV: json.dumps({**gen, **extra})})


ORIENT_CASES = [
    pytest.param(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 4, {"N": 20},
                 id="small_L4_o9"),
    pytest.param(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 1, {"N": 12},
                 id="small_L1_o9"),
    pytest.param(TrackerParams(preset="v2"), FixedParams(), 4, {"N": 3}, id="default_L4_o9"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("tp,fp,lanes,extra", ORIENT_CASES)
def test_ms_target_stats_orient_ghdl(tp, fp, lanes, extra, hdl_waves):
    """N_ORIENT 9: T over the 9 x 2**BIN_W joint bins (colour bits 2: 576, 3: 4608), looked up per lane
    at (ram_data, ram_obin), written as 2**BIN_W words of 9 bits (t_addr, t_data_all); random joint bins, compared with
    ms_target_stats(joint bins, T of the joint bins, ...)."""
    gen = {**stats_generics(tp, fp, lanes), "N_ORIENT": 9}
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, testcase=None,
                 test_filter="random_windows", extra_env={CFG_ENV: json.dumps({**gen, **extra})})


@pytest.mark.ghdl
def test_ms_target_stats_orient_real_ghdl(hdl_waves):
    """N_ORIENT 9 at core v2's size (LANES 4, 4,608 joint bins) on the windows, joint bins and T of
    FixedTrackerV2(orient_T=64) on real frames (SEGMENTS_JOINT)."""
    missing = [s for s, _, _ in SEGMENTS_JOINT if not (SEQ_ROOT / s).is_dir()]
    if missing:
        pytest.skip(f"{SEQ_ROOT} has no {', '.join(missing)}: the real windows need ../shared/data/sequences")
    gen = {**stats_generics(TrackerParams(preset="v2"), FixedParams(), 4), "N_ORIENT": 9}
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, testcase=None,
                 test_filter="random_windows", build_name=f"ghdl_{TOP}_real_o9",
                 extra_env={CFG_ENV: json.dumps({**gen, "REAL_ORIENT_T": 64})})


@pytest.mark.ghdl
def test_ms_target_stats_synth_orient9(tmp_path):
    """ghdl --synth (to Verilog) at core v2's size with N_ORIENT 9: LANES 4 T tables of 512 x 9 b."""
    gen = {**stats_generics(TrackerParams(preset="v2"), FixedParams(), 4), "N_ORIENT": 9}
    v = hdl.ghdl_to_verilog(TOP, gen, hdl.rtl_sources(TOP), out_path=tmp_path / f"{TOP}.v").read_text()
    assert "module ms_target_stats" in v and "ram_obin" in v and "t_data_all" in v


@pytest.mark.verilator
def test_ms_target_stats_orient_verilator(hdl_waves):
    """The N_ORIENT 9 bench on the GHDL -> Verilog -> Verilator netlist (colour bits 2, LANES 4)."""
    gen = {**stats_generics(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 4),
           "N_ORIENT": 9}
    hdl.run_verilator(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, test_filter="random_windows",
                      extra_env={CFG_ENV: json.dumps({**gen, "N": 20})})


@pytest.mark.verilator
def test_ms_target_stats_verilator(hdl_waves):
    """The same bench on the GHDL -> Verilog -> Verilator netlist."""
    gen = stats_generics(TrackerParams(preset="v2", colour_bits=2), FixedParams(max_half=7, margin=4), 4)
    hdl.run_verilator(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves, test_filter="random_windows",
                      extra_env={CFG_ENV: json.dumps(gen)})


def tb_top_generics(lanes: int) -> tuple[dict, dict]:
    tp, fp = TrackerParams(preset="v2"), FixedParams()
    g = core_generics(tp, fp, lanes)
    gen = {**stats_generics(tp, fp, lanes),
           **{k: g[k] for k in ("STRIDE", "ADDR_W", "KD_W", "HIST_W", "COUNT_W", "POSSUM_W")}}
    cfg = {**gen, "REGION_MAX": g["REGION_MAX"], "MAX_WINDOW": tp.max_window,
           # stats done - pass done: both count from the edge sampling the scan's last beat, the
           # statistics STATS_LAT edges, the pass's done PASS_LAT - 2 (rtl/ms_pixel_pass.vhd's pipeline:
           # the start edge and the scan's first stage come before the first beat)
           "DONE_OFFSET": stats_latency(lanes) - (PASS_LAT - 2)}
    return gen, cfg


@pytest.mark.ghdl
@pytest.mark.parametrize("lanes", [4, 2])
def test_ms_target_stats_attached(lanes, hdl_waves):
    """Attached to ms_pixel_pass + ms_kernel_tables, on the windows FixedTrackerV2 used on real frames."""
    gen, cfg = tb_top_generics(lanes)
    hdl.run_ghdl(TB_TOP, MODULE, gen, hdl.rtl_sources(TB_TOP, extra=[TB_TOP_VHD]), waves=hdl_waves,
                 test_filter="attached_real_windows", extra_env={CFG_ENV: json.dumps(cfg)})


@pytest.mark.verilator
def test_ms_target_stats_attached_verilator(hdl_waves):
    gen, cfg = tb_top_generics(4)
    hdl.run_verilator(TB_TOP, MODULE, gen, hdl.rtl_sources(TB_TOP, extra=[TB_TOP_VHD]), waves=hdl_waves,
                      test_filter="attached_real_windows", extra_env={CFG_ENV: json.dumps({**cfg, "EVERY": 6})})
