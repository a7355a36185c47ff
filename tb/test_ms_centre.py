"""cocotb test bench + pytest entry points for rtl/ms_centre.vhd.

Model: :func:`mstrack.fixed.blocks.ms_centre` (round_div_signed + clamp_centre) on
region-relative coordinates.  Random sums (negative, zero Swx, Sw = 1, Sw = 0 -> lost,
extreme values that saturate the divider, shifts that need clamping at both limits),
started back to back (full speed, asserting the documented latency SHIFT_Q_W + 6) and
with random gaps.

Run: ``.venv/bin/python -m pytest tb/test_ms_centre.py``.
"""

from __future__ import annotations

import dataclasses
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed.blocks import BinPass, Region, ms_centre
from mstrack.fixed.formats import FixedParams
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"SW_W": 22, "SWX_W": 29, "SHIFT_Q_W": 14, "CF": 8, "REGION_W": 8, "CENTRE_W": 16}
CLK_NS = 10
MAX_HALF = 63


def centre_latency(g: dict) -> int:
    """Documented start -> done latency of ms_centre (header of rtl/ms_centre.vhd)."""
    return int(g["SHIFT_Q_W"]) + 6


def centre_cases(g: dict, rng: random.Random, n: int) -> list[dict]:
    sw_max = (1 << int(g["SW_W"])) - 1
    sx_max = (1 << (int(g["SWX_W"]) - 1)) - 1
    r_max = (1 << int(g["REGION_W"])) - 1
    out = []

    def geom():
        lo_x, hi_x = sorted(rng.randint(0, r_max) for _ in range(2))
        lo_y, hi_y = sorted(rng.randint(0, r_max) for _ in range(2))
        return {"win_x": rng.randint(lo_x, hi_x), "win_y": rng.randint(lo_y, hi_y),
                "lo_x": lo_x, "hi_x": hi_x, "lo_y": lo_y, "hi_y": hi_y}

    fixed = [(1, 0, 0), (1, 1, -1), (1, MAX_HALF, -MAX_HALF), (0, 5, -5), (0, 0, 0), (sw_max, 0, 0),
             (sw_max, sx_max, -sx_max - 1), (1, sx_max, -sx_max - 1), (2, 1, -1), (2, 3, -3),
             (3, 1, -1), (1000, 500, -500), (1000, 499, -501)]
    for sw, sx, sy in fixed:
        out.append({"sw": sw, "swx": sx, "swy": sy, **geom()})
    for k in range(n):
        sw = max(1, rng.randint(0, sw_max) >> rng.randint(0, int(g["SW_W"]) - 1))
        if rng.random() < 0.05:
            sw = rng.choice([0, 1])
        if rng.random() < 0.8:   # realistic: |Swx| <= MAX_HALF Sw
            lim = min(sx_max, MAX_HALF * sw)
        else:
            lim = sx_max
        sx, sy = rng.randint(-lim, lim), rng.randint(-lim, lim)
        if rng.random() < 0.1:
            sx = 0
        gm = geom()
        if k % 7 == 0:           # window in the middle of a narrow clamp range: clamps at both sides
            c = rng.randint(0, r_max)
            gm.update(lo_x=max(0, c - 2), hi_x=min(r_max, c + 2), win_x=c, lo_y=c, hi_y=c, win_y=c)
        out.append({"sw": sw, "swx": sx, "swy": sy, **gm})
    return out


def model(g: dict, c: dict) -> tuple[int, int, bool]:
    fp = dataclasses.replace(FixedParams(), centre_frac=int(g["CF"]))
    bp = BinPass(S=0, w=None, Sw=c["sw"], Swx=c["swx"], Swy=c["swy"])
    reg = Region(0, 0, 0, 0, lo=(c["lo_x"], c["lo_y"]), hi=(c["hi_x"], c["hi_y"]))
    r = ms_centre(bp, (c["win_x"], c["win_y"]), reg, fp, int(g["SHIFT_Q_W"]))
    return (0, 0, True) if r is None else (int(r[0]), int(r[1]), False)


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.5])
async def centre_stream(dut, gap_prob):
    g = dut_generics(DEFAULTS)
    assert len(dut.cx) == int(g["CENTRE_W"]) and len(dut.sw) == int(g["SW_W"])
    rng = random.Random(4000 + int(gap_prob * 10))
    cases = centre_cases(g, rng, 300)
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    dut.start.value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    lat = centre_latency(g)
    n_clamped = 0
    for k, c in enumerate(cases):
        while gap_prob and rng.random() < gap_prob:
            await RisingEdge(dut.clk)
        for p, v in c.items():
            getattr(dut, p).value = v
        dut.start.value = 1
        await RisingEdge(dut.clk)
        assert dut.busy.value == 0, "start while busy"
        dut.start.value = 0
        cyc = 0
        while True:
            await RisingEdge(dut.clk)
            cyc += 1
            if dut.done.value == 1:
                break
            assert cyc < 100, "no done"
        assert cyc == lat, f"case {k}: done after {cyc}, documented {lat}"
        ex, ey, elost = model(g, c)
        lost = dut.lost.value == 1
        assert lost == elost, f"case {k} {c}: lost {lost}, model {elost}"
        if not elost:
            cx, cy = dut.cx.value.to_unsigned(), dut.cy.value.to_unsigned()
            assert (cx, cy) == (ex, ey), f"case {k} {c}: ({cx}, {cy}), model ({ex}, {ey})"
            cf = int(g["CF"])
            n_clamped += ex in (c["lo_x"] << cf, c["hi_x"] << cf) and ex != c["win_x"] << cf
            n_clamped += ey in (c["lo_y"] << cf, c["hi_y"] << cf) and c["swy"] != 0
        # gap_prob = 0: the next start goes in the clock after done (busy low since the done cycle)
    assert n_clamped > 20, f"only {n_clamped} clamped results: cases too gentle"


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402

TOP = "ms_centre"
MODULE = "test_ms_centre"

_CORE = {k: core_generics()[k] for k in DEFAULTS}

PARAMS = [
    pytest.param(_CORE, id="core"),
    pytest.param({**_CORE, "SHIFT_Q_W": 6}, id="shift_q6"),
    pytest.param({**_CORE, "CF": 4, "CENTRE_W": _CORE["REGION_W"] + 4}, id="cf4"),
    pytest.param({**_CORE, "REGION_W": 10, "CENTRE_W": 10 + _CORE["CF"]}, id="region10"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_centre_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
