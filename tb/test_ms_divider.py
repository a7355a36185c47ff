"""cocotb test bench + pytest entry points for rtl/ms_divider.vhd.

Model: :func:`mstrack.fixed.primitives.ms_divider_reference` (restoring division,
saturating to 2**Q_W - 1 when n >= d << Q_W).  Operands are streamed back to back
(one per clock) and with random gaps; every result is compared exactly, the tag
must come back with it, and the latency must be LATENCY = Q_W + 1 clocks.

Run: ``.venv/bin/python -m pytest tb/test_ms_divider.py``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.primitives import ms_divider_reference
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"N_W": 22, "D_W": 14, "Q_W": 16, "TAG_W": 8}
CLK_NS = 10


def divider_latency(g: dict) -> int:
    """Documented latency of ms_divider (header of rtl/ms_divider.vhd)."""
    return int(g["Q_W"]) + 1


# ---------------------------------------------------------------- generic pipeline driver

async def reset(dut, cycles: int = 3) -> None:
    dut.rst.value = 1
    dut.in_valid.value = 0
    await ClockCycles(dut.clk, cycles)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


async def stream(dut, items: list[dict], outputs: list[str], gap_prob: float, rng: random.Random,
                 tag_w: int, drain: int) -> list[tuple[int, int, dict]]:
    """Drive ``items`` (dicts port -> int) into an in_valid/in_* pipeline, tag = index mod 2**tag_w.

    Returns (issue cycle, result cycle, {output: int, 'tag': int}) per item, in output order.
    One pipeline input per clock when gap_prob = 0, else a random idle clock with that probability.
    """
    issued: list[int] = []
    results: list[tuple[int, dict]] = []
    i = 0
    cycle = 0
    idle = 0
    while i < len(items) or idle < drain:
        await RisingEdge(dut.clk)
        cycle += 1
        # outputs seen now were driven during the previous cycle
        if dut.out_valid.value == 1:
            res = {o: getattr(dut, o).value.to_unsigned() for o in outputs}
            res["tag"] = dut.out_tag.value.to_unsigned()
            results.append((cycle - 1, res))
        if i < len(items) and rng.random() >= gap_prob:
            for k, v in items[i].items():
                getattr(dut, k).value = v
            dut.in_tag.value = i % (1 << tag_w)
            dut.in_valid.value = 1
            issued.append(cycle)
            i += 1
        else:
            dut.in_valid.value = 0
            if i >= len(items):
                idle += 1
    assert len(results) == len(items), f"{len(results)} results for {len(items)} inputs"
    return [(issued[k], results[k][0], results[k][1]) for k in range(len(items))]


def check_stream(dut, items, got, expected, key: str, latency: int, tag_w: int) -> None:
    for k, (t_in, t_out, res) in enumerate(got):
        assert res["tag"] == k % (1 << tag_w), f"item {k}: tag {res['tag']} (order broken)"
        assert res[key] == expected[k], f"item {k} {items[k]}: {key} = {res[key]}, model {expected[k]}"
        assert t_out - t_in == latency, f"item {k}: latency {t_out - t_in} != {latency}"


# ---------------------------------------------------------------- cases

def divider_cases(g: dict, rng: random.Random, n_random: int) -> list[dict]:
    nw, dw, qw = int(g["N_W"]), int(g["D_W"]), int(g["Q_W"])
    nmax, dmax = (1 << nw) - 1, (1 << dw) - 1
    cases = [(0, 1), (0, dmax), (1, 1), (nmax, 1), (nmax, dmax), (dmax, dmax), (dmax - 1, dmax)]
    for d in (1, 2, 3, dmax, rng.randint(1, dmax), rng.randint(1, 1 << min(dw, 4))):
        edge = d << qw
        for n in (edge - 1, edge, edge + 1, d - 1, d, d + 1, (edge - 1) // 2):
            if 0 <= n <= nmax:
                cases.append((n, d))
    for _ in range(n_random):
        d = rng.randint(1, dmax) >> rng.randint(0, dw - 1)  # spread divisor magnitudes
        d = max(d, 1)
        n = rng.randint(0, nmax) >> rng.randint(0, nw - 1)
        if rng.random() < 0.3:                              # quotients near the saturation limit
            n = min(nmax, rng.randint(0, (d << qw) + d))
        cases.append((n, d))
    return [{"in_n": n, "in_d": d} for n, d in cases if n <= nmax and 1 <= d <= dmax]


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def divider_stream(dut, gap_prob):
    g = dut_generics(DEFAULTS)
    assert len(dut.in_n) == int(g["N_W"]) and len(dut.out_q) == int(g["Q_W"])
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    await reset(dut)
    rng = random.Random(1000 + int(gap_prob * 10))
    items = divider_cases(g, rng, 400)
    qw, tw = int(g["Q_W"]), int(g["TAG_W"])
    lat = divider_latency(g)
    got = await stream(dut, items, ["out_q"], gap_prob, rng, tw, lat + 3)
    expected = [ms_divider_reference(it["in_n"], it["in_d"], qw) for it in items]
    check_stream(dut, items, got, expected, "out_q", lat, tw)
    if gap_prob == 0.0:  # full throughput: one result per clock, no bubbles
        assert got[-1][1] - got[0][1] == len(items) - 1


@cocotb.test()
async def divider_zero_divisor(dut):
    """d = 0 is documented to give all ones (callers avoid it)."""
    g = dut_generics(DEFAULTS)
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    await reset(dut)
    items = [{"in_n": 0, "in_d": 0}, {"in_n": 12345 % (1 << int(g["N_W"])), "in_d": 0}]
    got = await stream(dut, items, ["out_q"], 0.0, random.Random(1), int(g["TAG_W"]), divider_latency(g) + 2)
    for _, _, res in got:
        assert res["out_q"] == (1 << int(g["Q_W"])) - 1


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_divider"
MODULE = "test_ms_divider"

PARAMS = [
    pytest.param(DEFAULTS, id="default"),
    pytest.param({**DEFAULTS, "Q_W": 1}, id="q1"),
    pytest.param({**DEFAULTS, "N_W": 8, "D_W": 20, "Q_W": 5}, id="wide_d"),
    pytest.param({**DEFAULTS, "N_W": 38, "D_W": 22, "Q_W": 14, "TAG_W": 3}, id="centre"),  # ms_centre use
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_divider_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
