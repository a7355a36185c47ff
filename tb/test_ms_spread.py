"""cocotb test bench + pytest entry points for rtl/ms_spread.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_spread` (floor(st2 2**16 / nt), 0 when nt = 0), on its
domain st2 < 2**(SPREAD_W - 16) nt (every mean d2q the kernel tables can give; rtl/ms_spread.vhd).
Small widths: every (st2, nt) pair of the domain.  Core widths: edge cases (the largest window full of
the largest d2q, a single pixel, ...), 1,500 random pairs and the (st2, nt) of every ms_spread call
FixedTrackerV2 makes on the first 40 frames of 5 real sequences.  Back to back and with random gaps;
the latency SPREAD_W + 1 is asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_spread.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import TargetStats, ms_spread
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_SPREAD_CFG"


def spread_latency(g: dict) -> int:
    """rtl/ms_spread.vhd: SPREAD_W + 1."""
    return g["SPREAD_W"] + 1


def in_domain(st2: int, nt: int, g: dict) -> bool:
    return st2 < (nt << (g["SPREAD_W"] - 16)) or nt == 0


def spread_items(g: dict, rng: random.Random, real: bool) -> list[dict[str, int]]:
    cw, sw = g["COUNT_W"], g["ST2_W"]
    ctop, stop = (1 << cw) - 1, (1 << sw) - 1
    dmax = (1 << (g["SPREAD_W"] - 16)) - 1          # largest mean d2q
    if cw + sw <= 12:
        pairs = [(a, b) for a in range(stop + 1) for b in range(ctop + 1)]
    else:
        pairs = [(0, 0), (stop, 0), (0, 1), (dmax, 1), (min(stop, ctop * dmax), ctop), (1, ctop), (0, ctop),
                 (min(stop, (ctop - 1) * dmax + dmax - 1), ctop)]
        for _ in range(1500):
            n = rng.randint(1, ctop) >> rng.randint(0, cw - 1)
            pairs.append((rng.randint(0, min(stop, n * dmax)), n))
        if real:
            pairs += record_v2_calls()["ms_spread"]
    return [{"st2": a, "nt": b} for a, b in pairs if in_domain(a, b, g)]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def spread_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, ("st2", "nt"))
    rng = random.Random(17 + int(gap_prob * 10))
    items = spread_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(items) > 600:
        items = rng.sample(items, 600)
    model = lambda it: (ms_spread(TargetStats(nt=it["nt"], st2=it["st2"], n_in=0, nt_in=0)),)  # noqa: E731
    lat = spread_latency(g)
    clocks = await run_stream(dut, items, ["spread"], model, lat, gap_prob, rng,
                              {"st2": g["ST2_W"], "nt": g["COUNT_W"]})
    if gap_prob == 0.0:
        assert clocks <= len(items) * lat + 3, clocks
    dut._log.info("%d items, %d clocks", len(items), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402

TOP = "ms_spread"
MODULE = "test_ms_spread"
KEYS = ("COUNT_W", "ST2_W", "SPREAD_W")


def pick(g: dict) -> dict:
    return {k: g[k] for k in KEYS}


PARAMS = [
    pytest.param(pick(v2_scale_generics()), 1, id="core"),
    pytest.param({"COUNT_W": 4, "ST2_W": 8, "SPREAD_W": 20}, 0, id="exhaustive"),
    pytest.param(pick(v2_scale_generics(fp=FixedParams(max_half=31, kernel_bits=6))), 0, id="max_half31_kb6"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_spread_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
def test_ms_spread_verilator(hdl_waves):
    g = pick(v2_scale_generics())
    hdl.run_verilator(TOP, MODULE, g, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**g, "REAL": 1})})
