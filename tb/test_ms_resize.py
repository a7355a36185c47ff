"""cocotb test bench + pytest entry points for rtl/ms_resize.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_resize(s8, s, frame_size)` ((s8 s) >> 16 clamped to
[3 2**8, frame_size 2**8]).  Core widths, 4-bit and 10-bit frame coordinates: edge cases (clamp to
3 px and to the frame, frame sizes below 3 px, the largest operands), 1,500 random
cases (s near 1 and anywhere) and the arguments of every ms_resize call FixedTrackerV2 makes on the
first 40 frames of 5 real sequences.  Back to back and with random gaps; latency SCALE_W + 2
asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_resize.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ONE, ms_resize
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_RESIZE_CFG"
INPUTS = ("s8", "s", "frame_size")


def resize_latency(g: dict) -> int:
    """rtl/ms_resize.vhd: RESIZE_LAT = SCALE_W + 2."""
    return g["SCALE_W"] + 2


def resize_items(g: dict, rng: random.Random, real: bool) -> list[tuple[int, int, int]]:
    sz_top, sc_top, f_top = (1 << g["SIZE_W"]) - 1, (1 << g["SCALE_W"]) - 1, (1 << g["COORD_W"]) - 1
    fm = min(100, f_top)
    cases = [(0, 0, 0), (sz_top, sc_top, f_top), (sz_top, sc_top, 0), (768, ONE, 3), (768, ONE - 1, fm),
             (767, ONE, fm), (769, ONE - 1, fm), (min(sz_top, f_top << 8), ONE, f_top),
             (min(sz_top, (f_top << 8) + 1), ONE, f_top), (min(sz_top, fm << 8), min(sc_top, ONE + (ONE >> 3)), fm),
             (min(sz_top, 6400), 0, f_top), (min(sz_top, 6400), sc_top, f_top)]
    for _ in range(1500):
        s8 = rng.randint(0, sz_top) >> rng.randint(0, 8)
        s = min(sc_top, int(ONE * rng.uniform(0.85, 1.15))) if rng.random() < 0.6 else rng.randint(0, sc_top)
        half = (s8 >> 8) // 2                  # mostly frames around the box size (clamp seldom)
        if rng.random() < 0.3 or half > f_top:
            f = rng.randint(0, f_top)
        else:
            f = rng.randint(half, f_top)
        cases.append((s8, s, f))
    if real:
        cases += record_v2_calls()["ms_resize"]
    return cases


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def resize_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(31 + int(gap_prob * 10))
    items = [dict(zip(INPUTS, c)) for c in resize_items(g, rng, real=g.get("REAL", 0) == 1)]
    if gap_prob > 0 and len(items) > 600:
        items = rng.sample(items, 600)
    model = lambda it: (ms_resize(it["s8"], it["s"], it["frame_size"]),)  # noqa: E731
    lat = resize_latency(g)
    clocks = await run_stream(dut, items, ["s8_out"], model, lat, gap_prob, rng,
                              {"s8": g["SIZE_W"], "s": g["SCALE_W"], "frame_size": g["COORD_W"]})
    if gap_prob == 0.0:
        assert clocks <= len(items) * lat + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_resize"
MODULE = "test_ms_resize"
_G = v2_scale_generics()

PARAMS = [
    pytest.param({"SIZE_W": _G["SIZE_W"], "SCALE_W": _G["SCALE_W"], "COORD_W": _G["COORD_W"]}, 1, id="core"),
    pytest.param({"SIZE_W": 12, "SCALE_W": 17, "COORD_W": 4}, 0, id="coord4"),
    pytest.param({"SIZE_W": 18, "SCALE_W": 17, "COORD_W": 10}, 0, id="coord10"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_resize_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_resize_verilator(hdl_waves):
    g = {"SIZE_W": _G["SIZE_W"], "SCALE_W": _G["SCALE_W"], "COORD_W": _G["COORD_W"]}
    hdl.run_verilator(TOP, MODULE, g, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**g, "REAL": 1})})
