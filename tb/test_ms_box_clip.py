"""rtl/ms_box_clip.vhd and rtl/ms_region.vhd against mstrack.fixed.blocks (ms_box_clip,
init_centre, ms_region): random boxes/centres including boxes off every border."""
from __future__ import annotations

import json
import os
import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import init_centre, ms_box_clip, ms_region
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.track.params import TrackerParams


#: clocks from in_valid to out_valid (the headers of rtl/ms_box_clip.vhd and rtl/ms_region.vhd)
BOX_CLIP_LAT = 4
REGION_LAT = 2


def _g():
    return json.loads(os.environ["MSTRACK_GENERICS"])


@cocotb.test()
async def box_clip_random(dut):
    g = _g()
    fp = FixedParams(max_half=g["MAX_HALF"], coord_bits=g["COORD_W"], centre_frac=g["CF"])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.rst.value = 1
    dut.in_valid.value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(7)
    for n in range(400):
        fw, fh = rng.randint(8, 400), rng.randint(8, 300)
        x, y = rng.randint(-60, fw + 10), rng.randint(-60, fh + 10)
        w, h = rng.randint(1, 2 * g["MAX_HALF"] + 40), rng.randint(1, 2 * g["MAX_HALF"] + 40)
        dut.frame_w.value = fw
        dut.frame_h.value = fh
        dut.box_x.value = x
        dut.box_y.value = y
        dut.box_w.value = w
        dut.box_h.value = h
        dut.in_valid.value = 1
        await RisingEdge(dut.clk)
        dut.in_valid.value = 0
        lat = 0
        while True:
            await RisingEdge(dut.clk)
            lat += 1
            if int(dut.out_valid.value):
                break
        assert lat == BOX_CLIP_LAT, f"latency {lat} != {BOX_CLIP_LAT}"
        box, clipped = ms_box_clip(x, y, w, h, fw, fh, fp.max_half)
        ctx = f"case {n}: box {(x, y, w, h)} frame {fw}x{fh}"
        assert int(dut.rejected.value) == int(box is None), ctx
        assert int(dut.clipped.value) == int(clipped), ctx
        if box is not None:
            got = tuple(int(getattr(dut, s).value) for s in ("clip_x", "clip_y", "clip_w", "clip_h"))
            assert got == (box.x, box.y, box.w, box.h), ctx
            assert (int(dut.ex.value), int(dut.ey.value)) == ((box.w - 1) // 2, (box.h - 1) // 2), ctx
            assert (int(dut.cx.value), int(dut.cy.value)) == init_centre(box, fp.centre_frac), ctx


@cocotb.test()
async def region_random(dut):
    g = _g()
    fp = FixedParams(max_half=g["MAX_HALF"], margin=g["MARGIN"], centre_frac=g["CF"])
    cf = fp.centre_frac
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.rst.value = 1
    dut.in_valid.value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(11)
    for n in range(400):
        ex, ey = rng.randint(1, fp.max_half), rng.randint(1, fp.max_half)
        fw = rng.randint(2 * ex + 3, 2 * ex + 3 + 300)
        fh = rng.randint(2 * ey + 3, 2 * ey + 3 + 200)
        cx = rng.randint(0, (fw - 1) << cf)
        cy = rng.randint(0, (fh - 1) << cf)
        for s, v in (("cx", cx), ("cy", cy), ("ex", ex), ("ey", ey), ("frame_w", fw), ("frame_h", fh)):
            getattr(dut, s).value = v
        dut.in_valid.value = 1
        await RisingEdge(dut.clk)
        dut.in_valid.value = 0
        lat = 0
        while True:
            await RisingEdge(dut.clk)
            lat += 1
            if int(dut.out_valid.value):
                break
        assert lat == REGION_LAT, f"latency {lat} != {REGION_LAT}"
        reg = ms_region((cx, cy), ex, ey, fw, fh, fp)
        got = tuple(int(getattr(dut, s).value) for s in ("reg_x", "reg_y", "reg_w", "reg_h", "hi_x", "hi_y"))
        exp = (reg.x, reg.y, reg.w, reg.h, reg.hi[0] - reg.x, reg.hi[1] - reg.y)
        assert got == exp, f"case {n}: centre {(cx, cy)} e {(ex, ey)} frame {fw}x{fh}"


@pytest.mark.parametrize("max_half,margin", [(63, 32), (15, 8)])
def test_ms_box_clip(max_half, margin):
    from mstrack.hw.hdl import rtl_sources, run_ghdl
    g = core_generics(TrackerParams(), FixedParams(max_half=max_half, margin=margin))
    gen = {k: g[k] for k in ("COORD_W", "HALF_W", "MAX_HALF", "CF")}
    run_ghdl("ms_box_clip", "test_ms_box_clip", generics=gen, sources=rtl_sources("ms_box_clip"),
             build_name=f"ms_box_clip_{max_half}", extra_env={"MSTRACK_GENERICS": json.dumps(g)},
             testcase="box_clip_random")


@pytest.mark.parametrize("max_half,margin", [(63, 32), (15, 8)])
def test_ms_region(max_half, margin):
    from mstrack.hw.hdl import rtl_sources, run_ghdl
    g = core_generics(TrackerParams(), FixedParams(max_half=max_half, margin=margin))
    gen = {k: g[k] for k in ("COORD_W", "HALF_W", "REGION_W", "MARGIN", "CF")}
    run_ghdl("ms_region", "test_ms_box_clip", generics=gen, sources=rtl_sources("ms_region"),
             build_name=f"ms_region_{max_half}", extra_env={"MSTRACK_GENERICS": json.dumps(g)},
             testcase="region_random")
