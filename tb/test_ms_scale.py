"""cocotb test bench + pytest entry points for rtl/ms_scale.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_scale(spread, spread_ref, w8, w0_8, tp)`, on its domain
(spread_ref > 0, w0_8 >= 3 2**8, w8 < 2**SIZE_W: rtl/ms_scale.vhd).  Edge cases (spread 0, equal
spreads, the largest and smallest ratios, ratios at the clamp limits 1 +- step and the
RATIO_Q_W saturation point, w8 = w0_8, the smallest and largest sizes), 1,000 random cases and the
arguments of every ms_scale call FixedTrackerV2 makes on the first 40 frames of 5 real sequences.
Parameter sets (generics SCALE_GAIN / SCALE_REG / SCALE_STEP from TrackerParams): the v2 defaults,
step 0.5 with gain 1 and no regulariser, gain 0 (s = 1 - reg term only), a small step.  Back to back
and with random gaps; latency 2 Q_W + 25 (Q_W = max(RATIO_Q_W, WR_Q_W)) asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_scale.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ONE, ms_scale
from mstrack.track.params import TrackerParams
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_SCALE_CFG"
INPUTS = ("spread", "spread_ref", "w8", "w0_8")


def scale_latency(g: dict) -> int:
    """rtl/ms_scale.vhd: SCALE_LAT = 2 max(RATIO_Q_W, WR_Q_W) + 25."""
    return 2 * max(g["RATIO_Q_W"], g["WR_Q_W"]) + 25


def scale_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    sp_top = (1 << g["SPREAD_W"]) - 1
    sz_top = (1 << g["SIZE_W"]) - 1
    mn = 3 << 8
    step = g["SCALE_STEP"]
    cases = [(0, 1, mn, mn), (sp_top, 1, sz_top, mn), (1, sp_top, mn, sz_top), (sp_top, sp_top, sz_top, sz_top),
             (12345, 12345, 6400, 6400), (0, sp_top, 6400, 6400)]
    # ratios r = floor(spread 2**16 / ref) around the clamp limits: est = isqrt(r 2**16) = (1 +- step)
    ref = 1 << 20
    for e in (ONE - step, ONE + step, ONE):
        for d in (-2, -1, 0, 1, 2):
            x = (e + d) ** 2                       # est^2 = r 2**16
            r = x >> 16
            cases.append(((r * ref) >> 16, ref, 6400, 6400))
    # ratio at the RATIO_Q_W saturation point
    rs = (1 << g["RATIO_Q_W"]) - 1
    for r in (rs - 1, rs, rs + 1):
        cases.append((min(sp_top, (r * 64) >> 16 << 0) if False else min(sp_top, r * 64 >> 16), 64, 6400, 6400))
    for _ in range(1000):
        ref = rng.randint(1, sp_top) >> rng.randint(0, g["SPREAD_W"] - 1) or 1
        k = rng.random()
        if k < 0.5:                               # near 1
            sp = min(sp_top, max(0, int(ref * rng.uniform(0.5, 1.6))))
        else:
            sp = rng.randint(0, sp_top) >> rng.randint(0, g["SPREAD_W"] - 1)
        w0 = rng.randint(mn, sz_top) >> rng.randint(0, 6)
        w0 = max(w0, mn)
        w = max(mn, min(sz_top, int(w0 * rng.uniform(0.2, 3.0)))) if rng.random() < 0.7 else rng.randint(mn, sz_top)
        cases.append((sp, ref, w, w0))
    if real:
        cases += record_v2_calls()["ms_scale"]
    return [dict(zip(INPUTS, c)) for c in cases]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def scale_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    tp = TrackerParams(**g["TP"])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(23 + int(gap_prob * 10))
    items = scale_items(g, rng, real=g.get("REAL", 0) == 1)
    model = lambda it: (ms_scale(it["spread"], it["spread_ref"], it["w8"], it["w0_8"], tp),)  # noqa: E731
    lat = scale_latency(g)
    clocks = await run_stream(dut, items, ["s"], model, lat, gap_prob, rng,
                              {"spread": g["SPREAD_W"], "spread_ref": g["SPREAD_W"], "w8": g["SIZE_W"],
                               "w0_8": g["SIZE_W"]})
    if gap_prob == 0.0:
        assert clocks <= len(items) * lat + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_scale"
MODULE = "test_ms_scale"
KEYS = ("SPREAD_W", "SIZE_W", "SCALE_W", "SCALE_GAIN", "SCALE_REG", "SCALE_STEP", "RATIO_Q_W", "WR_Q_W")

TPS = [
    pytest.param({}, 1, id="v2_defaults"),
    pytest.param({"scale_step": 0.5, "scale_gain": 1.0, "scale_reg": 0.0}, 0, id="step0.5_gain1_reg0"),
    pytest.param({"scale_gain": 0.0, "scale_reg": 1.0}, 0, id="gain0_reg1"),
    pytest.param({"scale_step": 0.02, "scale_gain": 0.7, "scale_reg": 0.33}, 0, id="step0.02"),
]


def scale_generics(tp_kw: dict) -> dict:
    g = v2_scale_generics(TrackerParams(preset="v2", **tp_kw))
    return {k: g[k] for k in KEYS}


@pytest.mark.ghdl
@pytest.mark.parametrize("tp_kw,real", TPS)
def test_ms_scale_ghdl(tp_kw, real, hdl_waves):
    gen = scale_generics(tp_kw)
    hdl.run_ghdl(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**gen, "TP": {"preset": "v2", **tp_kw}, "REAL": real})})


@pytest.mark.verilator
def test_ms_scale_verilator(hdl_waves):
    gen = scale_generics({})
    hdl.run_verilator(TOP, MODULE, gen, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**gen, "TP": {"preset": "v2"}, "REAL": 1})})
