"""cocotb test bench + pytest entry points for rtl/ms_confidence.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_confidence` ((min(1, rho / rho_ref) min(1, share /
share_ref)) >> 16, each ratio floored, 0 when its reference is 0).  W = 3: every (rho, share,
rho_ref, share_ref).  Core width (W = 17, Q1.16): edge cases (zero references, 2**16, the largest
values, x = ref, x = ref +- 1), 1,500 random tuples (x below and above its reference: ratios
clamped to 1) and the arguments of every ms_confidence call FixedTrackerV2 makes on the first 40
frames of 5 real sequences (tb/v2_common.py; search start points while lost included).  Back to
back and with random gaps; the latency 57 is asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_confidence.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ms_confidence
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_CONFIDENCE_CFG"
INPUTS = ("rho", "share", "rho_ref", "share_ref")
CONF_LAT = 57   # rtl/ms_confidence.vhd: 2 (Q_W + 2) + Q_W + 2, Q_W = 17


def conf_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    w = g["W"]
    top = (1 << w) - 1
    if w <= 3:
        rng_ = range(top + 1)
        return [dict(zip(INPUTS, (a, b, c, d))) for a in rng_ for b in rng_ for c in rng_ for d in rng_]
    one = min(top, 1 << 16)

    def pair() -> tuple[int, int]:
        """(x, ref): x near ref, below, above, or anywhere."""
        r = rng.random()
        ref = rng.randint(0, one) >> rng.randint(0, 8)
        if r < 0.3:
            return max(0, min(top, ref + rng.randint(-3, 3))), ref
        if r < 0.6:
            return rng.randint(0, ref), ref
        if r < 0.9:
            return rng.randint(0, one), ref
        return rng.randint(0, top), rng.randint(0, top)

    ed = [(0, 0), (1, 0), (one, 0), (0, 1), (one, one), (one, 1), (top, 1), (1, top), (top, top),
          (one - 1, one), (one + 1, one), (1000, 1001), (1001, 1000), (top, top - 1)]
    cases = [a + b for a in ed for b in ed]
    for _ in range(1500):
        (r, rr), (s, sr) = pair(), pair()
        cases.append((r, s, rr, sr))
    if real:
        cases += record_v2_calls()["ms_confidence"]
    return [dict(zip(INPUTS, c)) for c in cases]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def confidence_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(71 + int(gap_prob * 10))
    items = conf_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 400:
        items = rng.sample(items, 400)
    model = lambda it: (ms_confidence(it["rho"], it["share"], it["rho_ref"], it["share_ref"]),)  # noqa: E731
    clocks = await run_stream(dut, items, ["conf"], model, CONF_LAT, gap_prob, rng, {n: g["W"] for n in INPUTS})
    if gap_prob == 0.0:   # back to back: one result per CONF_LAT clocks
        assert clocks <= len(items) * CONF_LAT + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_confidence"
MODULE = "test_ms_confidence"
CORE = {"W": v2_scale_generics()["SHARE_W"]}

PARAMS = [
    pytest.param(CORE, 1, id="core"),
    pytest.param({"W": 3}, 0, id="exhaustive3"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_confidence_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_confidence_verilator(hdl_waves):
    hdl.run_verilator(TOP, MODULE, CORE, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**CORE, "REAL": 1})})
