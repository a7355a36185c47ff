"""cocotb test bench + pytest entry points for rtl/ms_mult_r4.vhd.

Model: (a * b) mod 2**P_W (numeric_std resize of the product), a unsigned, b signed or
unsigned.  Edge values (0, 1, max, min, all digit patterns of a) and random operands, streamed
one per clock and with random gaps; every product and tag compared exactly, latency
LATENCY = 1 + max(1, ceil(log2(ceil(A_W / 2)))) asserted per item.

Run: ``.venv/bin/python -m pytest tb/test_ms_mult_r4.py``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock

from mstrack.hw.hdl import dut_generics
from test_ms_divider import check_stream, reset, stream

DEFAULTS = {"A_W": 8, "B_W": 21, "B_SIGNED": True, "P_W": 29, "TAG_W": 4}
CLK_NS = 10


def mult_latency(g: dict) -> int:
    """Documented latency of ms_mult_r4 (header of rtl/ms_mult_r4.vhd)."""
    return 1 + max(1, (((int(g["A_W"]) + 1) // 2) - 1).bit_length())


def _bool(v) -> bool:
    return str(v).lower() in ("1", "true")


@cocotb.test()
async def mult_stream(dut):
    g = dut_generics(DEFAULTS)
    aw, bw, pw, tw = int(g["A_W"]), int(g["B_W"]), int(g["P_W"]), int(g["TAG_W"])
    signed_b = _bool(g["B_SIGNED"])
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    await reset(dut)
    rng = random.Random(7)
    amax = (1 << aw) - 1
    bvals = [0, 1, 2, 3, (1 << bw) - 1, (1 << (bw - 1)), (1 << (bw - 1)) - 1]
    avals = [0, 1, 2, 3, amax, amax - 1] + [rng.randint(0, amax) for _ in range(6)]
    if aw <= 8:
        avals += list(range(0, amax + 1, max(1, (amax + 1) // 64)))
    bmask = (1 << bw) - 1
    items = [{"in_a": a, "in_b": b & bmask} for a in sorted(set(x & amax for x in avals)) for b in bvals]
    items += [{"in_a": rng.randint(0, amax), "in_b": rng.randint(0, (1 << bw) - 1)} for _ in range(300)]

    def model(a: int, b: int) -> int:
        if signed_b and b >> (bw - 1):
            b -= 1 << bw
        return (a * b) % (1 << pw)

    lat = mult_latency(g)
    for gap in (0.0, 0.4):
        got = await stream(dut, items, ["out_p"], gap, rng, tw, lat + 3)
        check_stream(dut, items, got, [model(it["in_a"], it["in_b"]) for it in items], "out_p", lat, tw)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_mult_r4"
MODULE = "test_ms_mult_r4"

PARAMS = [
    pytest.param(DEFAULTS, id="w_sx"),                                                     # w SX
    pytest.param({"A_W": 8, "B_W": 14, "B_SIGNED": False, "P_W": 22, "TAG_W": 1}, id="w_n"),   # w N
    pytest.param({"A_W": 14, "B_W": 14, "B_SIGNED": False, "P_W": 28, "TAG_W": 1}, id="hq"),   # H Q
    pytest.param({"A_W": 22, "B_W": 22, "B_SIGNED": False, "P_W": 44, "TAG_W": 2}, id="hq_epan"),
    pytest.param({"A_W": 1, "B_W": 5, "B_SIGNED": True, "P_W": 4, "TAG_W": 1}, id="tiny"),    # truncating
    pytest.param({"A_W": 5, "B_W": 7, "B_SIGNED": True, "P_W": 12, "TAG_W": 1}, id="odd"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_mult_r4_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
