"""cocotb test bench + pytest entry points for rtl/ms_ring_share.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_ring_share` (floor((nt - nt_in) 2**16 / (K - n_in)), 0 when
K <= n_in), on its domain nt >= nt_in.  COUNT_W = 3: every (nt, nt_in, n_in, K) of the domain
(K <= n_in and nt - nt_in > K - n_in included).  Core widths: edge cases, 1,500 random tuples (as
ms_target_stats gives them and beyond) and the arguments of every ms_ring_share call FixedTrackerV2
makes on the first 40 frames of 5 real sequences (tb/v2_common.py).  Back to back and with random
gaps; the latency SHARE_W + 1 is asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_ring_share.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import TargetStats, ms_ring_share
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_RING_SHARE_CFG"
INPUTS = ("nt", "nt_in", "n_in", "k")


def ring_share_latency(g: dict) -> int:
    """rtl/ms_ring_share.vhd: SHARE_W + 1."""
    return g["SHARE_W"] + 1


def ring_share_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    cw = g["COUNT_W"]
    top = (1 << cw) - 1
    if cw <= 3:
        cases = [(a, b, c, d) for a in range(top + 1) for b in range(a + 1) for c in range(top + 1)
                 for d in range(top + 1)]
    else:
        cases = [(0, 0, 0, 0), (top, 0, 0, top), (top, top, top, top), (top, 0, top - 1, top), (1, 0, 0, top),
                 (top, 0, 0, 1), (top, 1, 5, 3), (0, 0, 0, 1), (top - 1, 0, 1, top), (5, 2, top, top - 1)]
        for _ in range(1500):
            kk = rng.randint(0, top) >> rng.randint(0, cw - 1)
            if rng.random() < 0.8:      # as ms_target_stats: nt_in <= n_in <= K, nt - nt_in <= K - n_in
                n_in = rng.randint(0, kk)
                nt_in = rng.randint(0, n_in)
                nt = nt_in + rng.randint(0, kk - n_in)
            else:                       # anywhere in the domain nt >= nt_in
                n_in = rng.randint(0, top)
                nt = rng.randint(0, top)
                nt_in = rng.randint(0, nt)
            cases.append((nt, nt_in, n_in, kk))
        if real:
            cases += record_v2_calls()["ms_ring_share"]
    return [dict(zip(INPUTS, c)) for c in cases]


def model(it: dict[str, int]) -> tuple[int]:
    return (ms_ring_share(TargetStats(nt=it["nt"], st2=0, n_in=it["n_in"], nt_in=it["nt_in"]), it["k"]),)


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def ring_share_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(31 + int(gap_prob * 10))
    items = ring_share_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 600:
        items = rng.sample(items, 600)
    lat = ring_share_latency(g)
    clocks = await run_stream(dut, items, ["ring_share"], model, lat, gap_prob, rng,
                              {k: g["COUNT_W"] for k in INPUTS})
    if gap_prob == 0.0:   # back to back: one result per LATENCY clocks
        assert clocks <= len(items) * lat + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_ring_share"
MODULE = "test_ms_ring_share"
_G = v2_scale_generics()

PARAMS = [
    pytest.param({"COUNT_W": _G["COUNT_W"], "SHARE_W": _G["SHARE_W"]}, 1, id="core"),
    pytest.param({"COUNT_W": 3, "SHARE_W": 17}, 0, id="exhaustive3"),
    pytest.param({"COUNT_W": v2_scale_generics(fp=FixedParams(max_half=31))["COUNT_W"], "SHARE_W": 17}, 0,
                 id="max_half31"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_ring_share_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_ring_share_verilator(hdl_waves):
    g = {"COUNT_W": _G["COUNT_W"], "SHARE_W": _G["SHARE_W"]}
    hdl.run_verilator(TOP, MODULE, g, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**g, "REAL": 1})})
