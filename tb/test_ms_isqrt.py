"""cocotb test bench + pytest entry points for rtl/ms_isqrt.vhd.

Model: :func:`mstrack.fixed.primitives.ms_isqrt_reference` (digit-by-digit square root).
Small IN_W (12): exhaustive at full speed.  Wide IN_W (SQRT_IN_W = 40 of the default core,
56 of the Epanechnikov core, 60): edge cases (0, 1, max, perfect squares and squares - 1,
powers of two) + random, full speed and with random gaps.  Exact compare, tag order and
latency LATENCY = IN_W / 2 + 1 asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_isqrt.py``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.primitives import ms_isqrt_reference
from mstrack.hw.hdl import dut_generics
from test_ms_divider import check_stream, reset, stream

DEFAULTS = {"IN_W": 40, "TAG_W": 8}
CLK_NS = 10
EXHAUSTIVE_MAX_W = 12


def isqrt_latency(g: dict) -> int:
    """Documented latency of ms_isqrt (header of rtl/ms_isqrt.vhd)."""
    return int(g["IN_W"]) // 2 + 1


def isqrt_cases(in_w: int, rng: random.Random, n_random: int) -> list[int]:
    if in_w <= EXHAUSTIVE_MAX_W:
        return list(range(1 << in_w))
    xmax = (1 << in_w) - 1
    rmax = (1 << (in_w // 2)) - 1
    xs = [0, 1, 2, 3, 4, xmax, xmax - 1, rmax * rmax, rmax * rmax - 1, rmax * rmax + 1]
    for _ in range(40):
        r = rng.randint(1, rmax) >> rng.randint(0, in_w // 2 - 1)
        r = max(r, 1)
        xs += [r * r, r * r - 1, min(xmax, r * r + 2 * r)]
    xs += [1 << i for i in range(in_w)] + [(1 << i) - 1 for i in range(1, in_w + 1)]
    xs += [rng.randint(0, xmax) >> rng.randint(0, in_w - 1) for _ in range(n_random)]
    return xs


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def isqrt_stream(dut, gap_prob):
    g = dut_generics(DEFAULTS)
    in_w, tw = int(g["IN_W"]), int(g["TAG_W"])
    assert len(dut.in_x) == in_w and len(dut.out_r) == in_w // 2
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    await reset(dut)
    rng = random.Random(2000 + int(gap_prob * 10))
    xs = isqrt_cases(in_w, rng, 300)
    if gap_prob > 0 and in_w <= EXHAUSTIVE_MAX_W:
        xs = rng.sample(xs, min(len(xs), 600))
    items = [{"in_x": x} for x in xs]
    lat = isqrt_latency(g)
    got = await stream(dut, items, ["out_r"], gap_prob, rng, tw, lat + 3)
    check_stream(dut, items, got, [ms_isqrt_reference(x, in_w) for x in xs], "out_r", lat, tw)
    if gap_prob == 0.0:
        assert got[-1][1] - got[0][1] == len(items) - 1


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_isqrt"
MODULE = "test_ms_isqrt"

_SQRT_DEFAULT = core_generics()["SQRT_IN_W"]
_SQRT_EPAN = core_generics(TrackerParams(kernel="epanechnikov"), FixedParams())["SQRT_IN_W"]

PARAMS = [
    pytest.param({"IN_W": _SQRT_DEFAULT, "TAG_W": 8}, id=f"sqrt_in{_SQRT_DEFAULT}"),
    pytest.param({"IN_W": 12, "TAG_W": 12}, id="exhaustive12"),
    pytest.param({"IN_W": 2, "TAG_W": 1}, id="exhaustive2"),
    pytest.param({"IN_W": core_generics()["RATIO_Q_W"], "TAG_W": 4}, id="ratio_q"),
    pytest.param({"IN_W": _SQRT_EPAN, "TAG_W": 8}, id=f"epan{_SQRT_EPAN}"),
    pytest.param({"IN_W": 60, "TAG_W": 8}, id="w60"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_isqrt_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
