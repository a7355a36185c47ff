"""cocotb test bench + pytest entry points for rtl/ms_loss_flag.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_loss_flag` (share = 0 or rho_s = 0 or (rho_s 2**16 <
LOSS_RHO rho0 and con_s < LOSS_CONTRAST)).  RHO_W = 4: every (rho_s, rho0, share) with con_s at
LOSS_CONTRAST - 1, LOSS_CONTRAST, LOSS_CONTRAST + 1.  Core widths: edge cases (zeros, 2**16, the
largest values, negative contrast at -2**16), for random rho0 the rho_s at the product's boundary
(rho_s 2**16 = LOSS_RHO rho0 exactly and +-1) with con_s at its boundary, 1,500 random tuples in the
tracker's ranges and beyond, and the arguments of every ms_loss_flag call FixedTrackerV2 makes on the
first 40 frames of 5 real sequences (tb/v2_common.py, default parameters).  Parameter variations:
loss_rho 0.88 (default), 0, 1, 2; loss_contrast 0.19 (default), -1, 0, 1.  Back to back and with
random gaps; the latency LR_W + 2 = 20 is asserted for every item.

Run: ``.venv/bin/python -m pytest tb/test_ms_loss_flag.py``.
"""
from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock

from mstrack.fixed.blocks_v2 import ms_loss_flag
from v2_common import record_v2_calls, reset, run_stream

CFG_ENV = "MS_LOSS_FLAG_CFG"
INPUTS = ("rho_s", "rho0", "con_s", "share")
FLAG_LAT = 20   # rtl/ms_loss_flag.vhd: LR_W + 2


def flag_items(g: dict, rng: random.Random, real: bool) -> list[tuple[int, int, int, int]]:
    """(rho_s, rho0, con_s, share) tuples, con_s as a signed value."""
    rw, cw = g["RHO_W"], g["CON_W"]
    lr, lc = g["LOSS_RHO"], g["LOSS_CONTRAST"]
    top = (1 << rw) - 1
    clo, chi = -(1 << (cw - 1)), (1 << (cw - 1)) - 1
    cons = [c for c in (lc - 1, lc, lc + 1) if clo <= c <= chi]
    if rw <= 4:
        return [(a, b, c, d) for a in range(top + 1) for b in range(top + 1) for c in cons for d in range(top + 1)]
    one = min(top, 1 << 16)
    ed = [0, 1, one - 1, one, top]
    cases = [(a, b, c, d) for a in ed for b in ed for c in (clo, -one, 0, one, chi) + tuple(cons) for d in (0, 1, one)]
    for _ in range(600):                         # the product's boundary
        r0 = rng.randint(0, one)
        t = lr * r0
        for rs in {(t >> 16) - 1, t >> 16, (t >> 16) + 1, (t - 1) >> 16}:
            if 0 <= rs <= top:
                cases.append((rs, r0, rng.choice(cons), rng.randint(0, one)))
    for _ in range(1500):
        if rng.random() < 0.7:
            cases.append((rng.randint(0, one), rng.randint(0, one), rng.randint(-one, one),
                          rng.randint(0, one) if rng.random() < 0.9 else 0))
        else:
            cases.append((rng.randint(0, top), rng.randint(0, top), rng.randint(clo, chi), rng.randint(0, top)))
    if real:
        cases += [c[:4] for c in record_v2_calls()["ms_loss_flag"] if c[4:] == (lr, lc)]
    return cases


@cocotb.test()
@cocotb.parametrize(gap_prob=[0.0, 0.4])
async def loss_flag_stream(dut, gap_prob):
    g = json.loads(os.environ[CFG_ENV])
    lr, lc, cw = g["LOSS_RHO"], g["LOSS_CONTRAST"], g["CON_W"]
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    await reset(dut, INPUTS)
    rng = random.Random(61 + int(gap_prob * 10) + lr + lc)
    cases = flag_items(g, rng, real=g.get("REAL", 0) == 1)
    if gap_prob > 0 and len(cases) > 600:
        cases = rng.sample(cases, 600)
    mask = (1 << cw) - 1
    items = [{"rho_s": a, "rho0": b, "con_s": c & mask, "share": d} for a, b, c, d in cases]  # con_s as bits

    def model(it: dict[str, int]) -> tuple[int]:
        con = it["con_s"] - ((it["con_s"] >> (cw - 1)) << cw)
        return (int(ms_loss_flag(it["rho_s"], it["rho0"], con, it["share"], lr, lc)),)

    flags = [model(it)[0] for it in items]
    assert 0 < sum(flags) < len(flags), "the items must give both flag values"
    clocks = await run_stream(dut, items, ["lost"], model, FLAG_LAT, gap_prob, rng,
                              {"rho_s": g["RHO_W"], "rho0": g["RHO_W"], "con_s": cw, "share": g["RHO_W"]})
    if gap_prob == 0.0:
        assert clocks <= len(items) * FLAG_LAT + 3, clocks
    dut._log.info("%d items (%d lost), %d clocks", len(items), sum(flags), clocks)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import v2_scale_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_loss_flag"
MODULE = "test_ms_loss_flag"


def flag_generics(**tp_kw: float) -> dict:
    g = v2_scale_generics(TrackerParams(preset="v2", **tp_kw))
    return {"RHO_W": g["SHARE_W"], "CON_W": g["CON_W"], "LOSS_RHO": g["LOSS_RHO"],
            "LOSS_CONTRAST": g["LOSS_CONTRAST"]}


CORE = flag_generics()
PARAMS = [
    pytest.param(CORE, 1, id="v2_defaults"),
    pytest.param(flag_generics(loss_rho=0.0, loss_contrast=-1.0), 0, id="rho0_con-1"),
    pytest.param(flag_generics(loss_rho=1.0, loss_contrast=0.0), 0, id="rho1_con0"),
    pytest.param(flag_generics(loss_rho=2.0, loss_contrast=1.0), 0, id="rho2_con1"),
    pytest.param({**CORE, "RHO_W": 4}, 0, id="exhaustive4"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics,real", PARAMS)
def test_ms_loss_flag_ghdl(generics, real, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                 extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})


@pytest.mark.verilator
@pytest.mark.parametrize("generics,real", [PARAMS[0], PARAMS[1]])
def test_ms_loss_flag_verilator(generics, real, hdl_waves):
    hdl.run_verilator(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves,
                      extra_env={CFG_ENV: json.dumps({**generics, "REAL": real})})
