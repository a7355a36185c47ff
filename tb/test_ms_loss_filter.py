"""cocotb test bench + pytest entry points for rtl/ms_loss_filter.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_loss_filter` (s + ((x - s) >> k), floor), two's complement.
W = 6: every (s, x) pair, for K_SHIFT = 0, 1, 3 and W.  Core width (W = 18, the signed Q1.16 contrast
and rho): edge cases (both extremes, zero, +-1, s = x), 2,000 random pairs (half of them within
+-2**16, the tracker's range: negative contrast included) and the (s, x) of every ms_loss_filter call
FixedTrackerV2 makes on the first 40 frames of 5 real sequences (tb/v2_common.py, K_SHIFT = 1 there);
K_SHIFT = 1 (default), 0, 4.  Back to back (one result per clock, asserted) and with random gaps;
latency 1 asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_loss_filter.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ms_loss_filter
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_LOSS_FILTER_CFG"
INPUTS = ("s", "x")


def signed_cases(w: int, rng: random.Random, n: int, span: int) -> list[tuple[int, int]]:
    """Edge cases and ``n`` random (s, x) pairs of W-bit two's complement values (half within +-span)."""
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    ed = [lo, lo + 1, -span, -1, 0, 1, span, hi - 1, hi]
    ed = [v for v in ed if lo <= v <= hi]
    cases = [(a, b) for a in ed for b in ed]
    for _ in range(n):
        if rng.random() < 0.5:
            cases.append((rng.randint(max(lo, -span), min(hi, span)), rng.randint(max(lo, -span), min(hi, span))))
        else:
            a = rng.randint(lo, hi)
            cases.append((a, a + rng.randint(-64, 64) if rng.random() < 0.3 and lo + 64 <= a <= hi - 64
                          else rng.randint(lo, hi)))
    return cases


def filter_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    w = g["W"]
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    if w <= 6:
        cases = [(a, b) for a in range(lo, hi + 1) for b in range(lo, hi + 1)]
    else:
        cases = signed_cases(w, rng, 2000, 1 << 16)
        if real:
            cases += [(s, x) for s, x, k in record_v2_calls()["ms_loss_filter"] if k == g["K_SHIFT"]]
    return [{"s": a, "x": b} for a, b in cases]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def loss_filter_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    w, k = g["W"], g["K_SHIFT"]
    mask = (1 << w) - 1
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(41 + int(gap_prob * 10) + k)
    items = filter_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 1500:
        items = rng.sample(items, 1500)
    drive = [{n: v & mask for n, v in it.items()} for it in items]   # two's complement bit patterns

    def model(it: dict[str, int]) -> tuple[int]:
        s = it["s"] - ((it["s"] >> (w - 1)) << w)
        x = it["x"] - ((it["x"] >> (w - 1)) << w)
        return (ms_loss_filter(s, x, k) & mask,)

    clocks = await run_stream(dut, drive, ["s_next"], model, 1, gap_prob, rng, {n: w for n in INPUTS})
    if gap_prob == 0.0:   # full throughput: one result per clock
        assert clocks <= len(items) + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_loss_filter"
MODULE = "test_ms_loss_filter"
_G = v2_scale_generics()
CORE = {"W": _G["CON_W"], "K_SHIFT": _G["LOSS_K"]}

PARAMS = [
    pytest.param(CORE, 1, id="core"),
    pytest.param({"W": _G["CON_W"], "K_SHIFT": 0}, 0, id="k0"),
    pytest.param({"W": _G["CON_W"], "K_SHIFT": 4}, 0, id="k4"),
    pytest.param({"W": 6, "K_SHIFT": 1}, 0, id="exhaustive6_k1"),
    pytest.param({"W": 6, "K_SHIFT": 0}, 0, id="exhaustive6_k0"),
    pytest.param({"W": 6, "K_SHIFT": 3}, 0, id="exhaustive6_k3"),
    pytest.param({"W": 6, "K_SHIFT": 6}, 0, id="exhaustive6_k6"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_loss_filter_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
@pytest.mark.parametrize("generics", [pytest.param(CORE, id="core"), pytest.param({"W": 6, "K_SHIFT": 3}, id="w6_k3")])
def test_ms_loss_filter_verilator(generics, hdl_waves):
    hdl.run_verilator(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**generics, "REAL": 1 if generics == CORE else 0})})
