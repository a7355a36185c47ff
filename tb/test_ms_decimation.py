"""cocotb test bench + pytest entry points for rtl/ms_decimation.vhd (tracker v2 decimation).

Every vector is compared with ``mstrack.fixed.blocks_v2.ms_decimation(w8, h8, PAD16,
MAX_WINDOW)``: both sides of each decision boundary of D = 1, 2, 4 (the largest size that
still fits and the next one, on w8, on h8 and on both), random sizes (log-uniform over the
whole range, both orders of w8 / h8), the extremes, and for the small configuration every
value of max(w8, h8) (w8 exhaustive with h8 random below it, and the same with the roles
swapped).  Full speed and with random in_valid gaps; latency asserted (streaming harness of
tb/test_ms_window_size.py).

Run: ``.venv/bin/python -m pytest tb/test_ms_decimation.py``.
"""

from __future__ import annotations

import json
import random
from typing import Callable

import cocotb
import pytest

from mstrack.hw import hdl
from mstrack.fixed.blocks_v2 import ms_decimation, sixteenths
from mstrack.fixed.formats import FixedParams
from mstrack.hw.hdl import dut_generics
from mstrack.track.params import TrackerParams

from test_ms_window_size import start, stream

#: in_valid -> out_valid (rtl/ms_decimation.vhd header)
LATENCY = 1


def dec_vectors(g: dict, seed: int) -> list[dict[str, int]]:
    rng = random.Random(seed)
    sw = int(g["S8_W"])
    s_max = (1 << sw) - 1
    pad16, mw = int(g["PAD16"]), int(g["MAX_WINDOW"])
    out: list[dict[str, int]] = []

    def pair(a: int, b: int) -> None:
        out.append({"w8": a, "h8": b})
        out.append({"w8": b, "h8": a})

    for k in range(3):
        # the decision boundary of D = 2**k: (16 + pad16) s <= mw 2**(12 + k); the test's own
        # arithmetic only picks the sizes, the expected D comes from the model
        b = (mw << (12 + k)) // (16 + pad16)
        for s in range(b - 2, b + 3):
            if 0 <= s <= s_max:
                pair(s, rng.randint(0, s))
                pair(s, s)
                pair(s, rng.randint(0, s_max))
    for s in (0, 1, s_max):
        pair(s, 0)
        pair(s, s_max)
    for _ in range(3000):
        pair(min(s_max, int(2 ** rng.uniform(0, sw))), min(s_max, int(2 ** rng.uniform(0, sw))))
    if g.get("EXHAUSTIVE_TB"):
        for s in range(s_max + 1):
            pair(s, rng.randint(0, s))
    rng.shuffle(out)
    return out


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def decimation(dut, gap):
    g = dut_generics()
    pad16, mw = int(g["PAD16"]), int(g["MAX_WINDOW"])
    await start(dut)
    vecs = dec_vectors(g, seed=3 + int(gap * 10))
    n = await stream(dut, vecs, ("log2_d",), LATENCY,
                     lambda v: (ms_decimation(v["w8"], v["h8"], pad16, mw).bit_length() - 1,), gap, seed=4)
    dut._log.info("%d vectors match the model (PAD16 %d, MAX_WINDOW %d, gap %.1f)", n, pad16, mw, gap)


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_decimation"
MODULE = "test_ms_decimation"


def v2_generics(tp: TrackerParams | None = None, fp: FixedParams | None = None) -> dict[str, int]:
    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    return {"S8_W": fp.coord_bits + 8, "PAD16": sixteenths(tp.pad, "pad"), "MAX_WINDOW": tp.max_window}


PARAMS = [
    pytest.param(v2_generics(), id="v2_default"),
    pytest.param({**v2_generics(), "PAD16": 0}, id="pad0"),
    pytest.param(v2_generics(TrackerParams(preset="v2", pad=2.0, max_window=1023)), id="pad32_w1023"),
    pytest.param(v2_generics(TrackerParams(preset="v2", pad=0.4375, max_window=7)), id="pad7_w7"),
    pytest.param({"S8_W": 12, "PAD16": 4, "MAX_WINDOW": 7, "EXHAUSTIVE_TB": 1}, id="small_exhaustive"),
]


def _run(gen: dict, sim: Callable, waves: bool, name: str) -> None:
    rtl_gen = {k: v for k, v in gen.items() if not k.endswith("_TB")}
    sim(TOP, MODULE, rtl_gen, hdl.rtl_sources(TOP), waves=waves, build_name=name,
        extra_env={hdl.GENERICS_ENV: json.dumps(gen)})


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_decimation(generics, hdl_waves, request):
    _run(generics, hdl.run_ghdl, hdl_waves, f"ghdl_{TOP}_{request.node.callspec.id}")


@pytest.mark.verilator
def test_ms_decimation_verilator(hdl_waves):
    _run(v2_generics(), hdl.run_verilator, hdl_waves, f"verilator_{TOP}_v2")
