"""cocotb test bench + pytest entry points for rtl/ms_box_size.vhd (tracker v2 init box size).

Every vector is compared with ``mstrack.fixed.blocks_v2.ms_box_size(s8, D, limit)``: rounding
boundaries of every D, clamp boundaries, random sizes, and every s8 with every D for the small
configuration (the vectors and the streaming harness of tb/test_ms_window_size.py, with
PAD16 = 0: the entity is ms_window_size with PAD16 = 0).  Full speed and with random in_valid
gaps; latency asserted for every result.

Run: ``.venv/bin/python -m pytest tb/test_ms_box_size.py``.
"""

from __future__ import annotations

import json
from typing import Callable

import cocotb
import pytest

from mstrack.hw import hdl
from mstrack.fixed.blocks_v2 import ms_box_size
from mstrack.fixed.formats import FixedParams
from mstrack.hw.hdl import dut_generics

from test_ms_window_size import LATENCY, size_vectors, start, stream


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def box_size(dut, gap):
    g = dut_generics()
    kmax = 7                                   # the whole log2_d port
    await start(dut)
    vecs = size_vectors(g, 0, kmax, seed=9 + int(gap * 10), exhaustive=bool(g.get("EXHAUSTIVE_TB", 0)))
    n = await stream(dut, vecs, ("n",), LATENCY,
                     lambda v: (ms_box_size(v["s8"], 1 << v["log2_d"], v["limit"]),), gap, seed=2)
    dut._log.info("%d vectors match the model (gap %.1f)", n, gap)


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_box_size"
MODULE = "test_ms_box_size"


def v2_generics(fp: FixedParams | None = None) -> dict[str, int]:
    """ms_box_size generics of the v2 core: s8 in Q(COORD_W).8, limit = decimated frame - 2."""
    fp = fp or FixedParams()
    return {"S8_W": fp.coord_bits + 8, "N_W": fp.coord_bits}


PARAMS = [
    pytest.param(v2_generics(), id="v2_default"),
    pytest.param({"S8_W": 12, "N_W": 6, "EXHAUSTIVE_TB": 1}, id="small_exhaustive"),
]


def _run(gen: dict, sim: Callable, waves: bool, name: str) -> None:
    rtl_gen = {k: v for k, v in gen.items() if not k.endswith("_TB")}
    sim(TOP, MODULE, rtl_gen, hdl.rtl_sources(TOP), waves=waves, build_name=name,
        extra_env={hdl.GENERICS_ENV: json.dumps(gen)})


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_box_size(generics, hdl_waves, request):
    _run(generics, hdl.run_ghdl, hdl_waves, f"ghdl_{TOP}_{request.node.callspec.id}")


@pytest.mark.verilator
def test_ms_box_size_verilator(hdl_waves):
    _run(v2_generics(), hdl.run_verilator, hdl_waves, f"verilator_{TOP}_v2")
