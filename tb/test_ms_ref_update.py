"""cocotb test bench + pytest entry points for rtl/ms_ref_update.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_ref_update` (ref + ((x - ref) >> k), floor), unsigned.
W = 6: every (ref_in, x) pair for K_SHIFT = 6 (default), 0, 2 and W + 1.  Core width (W = 17, Q1.16
rho / share references): edge cases (0, 1, 2**16, 2**17 - 1, ref = x, ref = x +- 1), 2,000 random
pairs (half within 0 .. 2**16, the tracker's range; x below and above ref) and the (ref, x) of every
ms_ref_update call FixedTrackerV2 makes on the first 40 frames of 5 real sequences
(tb/v2_common.py); K_SHIFT = 6, 0, 3.  Back to back (one result per clock, asserted) and with
random gaps; latency 1 asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_ref_update.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ms_ref_update
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_REF_UPDATE_CFG"
INPUTS = ("ref_in", "x")  # ref is a SystemVerilog keyword


def ref_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    w = g["W"]
    top = (1 << w) - 1
    if w <= 6:
        cases = [(a, b) for a in range(top + 1) for b in range(top + 1)]
    else:
        span = min(top, 1 << 16)
        ed = [0, 1, 2, span - 1, span, top - 1, top, span // 2]
        cases = [(a, b) for a in ed for b in ed] + [(v, v + d) for v in (1, 1000, span - 1) for d in (-1, 1)]
        for _ in range(2000):
            if rng.random() < 0.5:
                a = rng.randint(0, span)
                cases.append((a, max(0, min(span, a + rng.randint(-300, 300))) if rng.random() < 0.5
                              else rng.randint(0, span)))
            else:
                cases.append((rng.randint(0, top), rng.randint(0, top)))
        if real:
            cases += [(r, x) for r, x, k in record_v2_calls()["ms_ref_update"] if k == g["K_SHIFT"]]
    return [dict(zip(INPUTS, c)) for c in cases]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def ref_update_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    k = g["K_SHIFT"]
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(53 + int(gap_prob * 10) + k)
    items = ref_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 1500:
        items = rng.sample(items, 1500)
    model = lambda it: (ms_ref_update(it["ref_in"], it["x"], k),)  # noqa: E731
    clocks = await run_stream(dut, items, ["ref_next"], model, 1, gap_prob, rng, {n: g["W"] for n in INPUTS})
    if gap_prob == 0.0:   # full throughput: one result per clock
        assert clocks <= len(items) + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_ref_update"
MODULE = "test_ms_ref_update"
_G = v2_scale_generics()
CORE = {"W": _G["SHARE_W"], "K_SHIFT": _G["REF_K"]}

PARAMS = [
    pytest.param(CORE, 1, id="core"),
    pytest.param({"W": _G["SHARE_W"], "K_SHIFT": 0}, 0, id="k0"),
    pytest.param({"W": _G["SHARE_W"], "K_SHIFT": 3}, 0, id="k3"),
    pytest.param({"W": 6, "K_SHIFT": 6}, 0, id="exhaustive6_k6"),
    pytest.param({"W": 6, "K_SHIFT": 0}, 0, id="exhaustive6_k0"),
    pytest.param({"W": 6, "K_SHIFT": 2}, 0, id="exhaustive6_k2"),
    pytest.param({"W": 6, "K_SHIFT": 7}, 0, id="exhaustive6_k7"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_ref_update_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_ref_update_verilator(hdl_waves):
    hdl.run_verilator(TOP, MODULE, CORE, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**CORE, "REAL": 1})})
