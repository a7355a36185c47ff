"""cocotb test bench + pytest entry points for rtl/ms_share.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_share` (floor(nt_in 2**16 / n_in), 0 when n_in = 0).
Small COUNT_W: every (nt_in, n_in) pair, nt_in > n_in included.  Core widths: edge cases, 1,500 random
pairs (nt_in <= n_in and beyond) and the (nt_in, n_in) of every ms_share call FixedTrackerV2 makes on
the first 40 frames of 5 real sequences (tb/v2_common.py).  Back to back and with random gaps; the
latency SHARE_W + 1 is asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_share.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import TargetStats, ms_share
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_SHARE_CFG"


def share_latency(g: dict) -> int:
    """rtl/ms_share.vhd: SHARE_W + 1."""
    return g["SHARE_W"] + 1


def share_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    cw = g["COUNT_W"]
    top = (1 << cw) - 1
    if cw <= 5:
        return [{"nt_in": a, "n_in": b} for a in range(top + 1) for b in range(top + 1)]
    pairs = [(0, 0), (top, 0), (0, 1), (1, 1), (top, top), (top - 1, top), (1, top), (top, 1), (2, 3)]
    for _ in range(1500):
        n = rng.randint(0, top) >> rng.randint(0, cw - 1)
        pairs.append((rng.randint(0, n) if rng.random() < 0.8 else rng.randint(0, top), n))
    if real:
        pairs += record_v2_calls()["ms_share"]
    return [{"nt_in": a, "n_in": b} for a, b in pairs]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def share_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, ("nt_in", "n_in"))
    rng = random.Random(7 + int(gap_prob * 10))
    items = share_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 600:
        items = rng.sample(items, 600)
    model = lambda it: (ms_share(TargetStats(nt=0, st2=0, n_in=it["n_in"], nt_in=it["nt_in"])),)  # noqa: E731
    lat = share_latency(g)
    clocks = await run_stream(dut, items, ["share"], model, lat, gap_prob, rng,
                              {"nt_in": g["COUNT_W"], "n_in": g["COUNT_W"]})
    if gap_prob == 0.0:   # back to back: one share per LATENCY clocks
        assert clocks <= len(items) * lat + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_share"
MODULE = "test_ms_share"
_G = v2_scale_generics()

PARAMS = [
    pytest.param({"COUNT_W": _G["COUNT_W"], "SHARE_W": _G["SHARE_W"]}, 1, id="core"),
    pytest.param({"COUNT_W": 5, "SHARE_W": 17}, 0, id="exhaustive5"),
    pytest.param({"COUNT_W": v2_scale_generics(fp=FixedParams(max_half=31))["COUNT_W"], "SHARE_W": 17}, 0,
                 id="max_half31"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_share_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_share_verilator(hdl_waves):
    g = {"COUNT_W": _G["COUNT_W"], "SHARE_W": _G["SHARE_W"]}
    hdl.run_verilator(TOP, MODULE, g, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**g, "REAL": 1})})
