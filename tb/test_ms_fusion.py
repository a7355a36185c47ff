"""rtl/ms_fusion.vhd against mstrack.fixed.blocks.ms_fusion / ms_rho_out, per FEATURES mode."""
from __future__ import annotations

import json
import os
import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import ms_fusion, ms_rho_out
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.track.params import TrackerParams

MODES = {0: "fused", 1: "colour", 2: "edge"}


@cocotb.test()
async def fusion_random(dut):
    g = json.loads(os.environ["MSTRACK_GENERICS"])
    fp = FixedParams(rho_frac=g["RF"], alpha_frac=g["AF"], rho_out_frac=g["RHO_OUT_FRAC"])
    features = MODES[g["FEATURES"]]
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.rst.value = 1
    dut.start.value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(3)
    kmax = (1 << g["HIST_W"]) - 1
    cmax = (1 << g["CENTRE_ABS_W"]) - 1
    for n in range(300):
        K = rng.randint(1, kmax)
        smax = K << fp.rho_frac                    # S <= K 2**RF
        s_c = rng.choice([0, smax, rng.randint(0, smax)])
        s_e = rng.choice([0, smax, rng.randint(0, smax)])
        cc = (rng.randint(0, cmax), rng.randint(0, cmax))
        ce = (rng.randint(0, cmax), rng.randint(0, cmax))
        for s, v in (("s_c", s_c), ("s_e", s_e), ("c_cx", cc[0]), ("c_cy", cc[1]), ("e_cx", ce[0]),
                     ("e_cy", ce[1]), ("k_sum", K)):
            getattr(dut, s).value = v
        dut.start.value = 1
        await RisingEdge(dut.clk)
        dut.start.value = 0
        for _ in range(200):
            await RisingEdge(dut.clk)
            if int(dut.done.value):
                break
        else:
            raise AssertionError("ms_fusion: no done within 200 clocks")
        c, a_c, _ = ms_fusion(s_c, s_e, cc, ce, features, fp.alpha_frac)
        rc = ms_rho_out(s_c, K, fp) if features != "edge" else 0
        re = ms_rho_out(s_e, K, fp) if features != "colour" else 0
        got = tuple(int(getattr(dut, s).value) for s in ("cx", "cy", "alpha_c", "rho_c", "rho_e"))
        assert got == (c[0], c[1], a_c, rc, re), f"case {n}: S {(s_c, s_e)} K {K} centres {cc} {ce}"


@pytest.mark.parametrize("features", ["fused", "colour", "edge"])
def test_ms_fusion(features):
    from mstrack.hw.hdl import rtl_sources, run_ghdl
    g = core_generics(TrackerParams(features=features), FixedParams())
    names = ("FEATURES", "RHO_SUM_W", "HIST_W", "CENTRE_ABS_W", "AF", "ALPHA_W", "RF", "RHO_OUT_FRAC",
             "RHO_OUT_W")
    run_ghdl("ms_fusion", "test_ms_fusion", generics={k: g[k] for k in names},
             sources=rtl_sources("ms_fusion"), build_name=f"ms_fusion_{features}",
             extra_env={"MSTRACK_GENERICS": json.dumps(g)})
