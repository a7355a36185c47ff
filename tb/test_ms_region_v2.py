"""cocotb test bench + pytest entry points for rtl/ms_region_v2.vhd (tracker v2's search region).

Every vector is compared with ``mstrack.fixed.blocks_v2.ms_region_v2`` (region, its window-centre
limit hi and the margin), output by output:

* the calls FixedTrackerV2 makes on real frames (Deer: lost at D = 8, Football1: losses,
  MotorRolling: D = 2 and scale; 60 frames each), replayed value by value;
* the clamps of each axis: centres at, and one pixel either side of, the positions where the start
  is cut to 1 or to S - 1 - n, and where n = 2e + 2m + 1 meets S - 2; the margin at MARGIN_MAX and one
  below; lost and tracking;
* random vectors over the port ranges the core uses (a window inside the decimated frame's interior,
  e <= (S - 3) / 2, as ms_window_size's limit S - 2 gives).

Streamed one per 6 clocks (the block's throughput; garbage on the inputs in between) and with random
in_valid gaps; the latency is asserted for every result.  Run: ``.venv/bin/python -m pytest tb/test_ms_region_v2.py``.
"""
from __future__ import annotations

import json
import random

import cocotb
import pytest

from mstrack.fixed.blocks_v2 import ms_region_v2
from mstrack.fixed.formats import FixedParams
from mstrack.hw import hdl
from mstrack.hw.hdl import dut_generics

from test_ms_window_size import start, stream
from v2_common import SEQ_ROOT, record_v2_calls

#: in_valid -> out_valid (rtl/ms_region_v2.vhd header)
LATENCY = 6
OUTPUTS = ("reg_x", "reg_y", "reg_w", "reg_h", "hi_x", "hi_y", "region_margin")
REAL_SEQS = ("Deer", "Football1", "MotorRolling")


def model(v: dict[str, int], g: dict) -> tuple[int, ...]:
    fp = FixedParams(margin=int(g["MARGIN"]), centre_frac=int(g["CF"]))
    reg, m = ms_region_v2((v["cx"], v["cy"]), v["ex"], v["ey"], v["ox"], v["oy"], bool(v["lost"]),
                          v["frame_w"], v["frame_h"], fp, int(g["MARGIN_MAX"]))
    mask = (1 << int(g["REGION_W"])) - 1
    hi_x, hi_y = reg.hi[0] - reg.x, reg.hi[1] - reg.y           # region-relative
    return (reg.x, reg.y, reg.w & mask, reg.h & mask, hi_x & mask, hi_y & mask, m)


def real_vectors(frames: int = 60) -> list[dict[str, int]]:
    """The arguments of every ms_region_v2 call of FixedTrackerV2 on REAL_SEQS."""
    keys = ("cx", "cy", "ex", "ey", "ox", "oy", "lost", "frame_w", "frame_h")
    return [dict(zip(keys, a)) for a in record_v2_calls(REAL_SEQS, frames)["ms_region_v2"]]


def edge_vectors(g: dict, rng: random.Random) -> list[dict[str, int]]:
    """Centres around every clamp of both axes, margins around MARGIN_MAX."""
    cf, cw, hw = int(g["CF"]), int(g["COORD_W"]), int(g["HALF_W"])
    mg, mmax = int(g["MARGIN"]), int(g["MARGIN_MAX"])
    out: list[dict[str, int]] = []
    for _ in range(400):
        s = min(rng.choice([3, 4, 5, 40, 100, 131, 132, 133, 134, 240, 480, 1920, (1 << cw) - 1]), (1 << cw) - 1)
        t = min(rng.choice([3, 7, 64, 135, 270, 1080, (1 << cw) - 1]), (1 << cw) - 1)
        e = min(rng.choice([0, 1, rng.randint(0, (1 << hw) - 1), (1 << hw) - 1]), (s - 3) // 2)
        lost = rng.random() < 0.5
        o = rng.choice([0, mmax - mg - 1, mmax - mg, mmax - mg + 1, rng.randint(0, (1 << cw) - 1)]) if lost else 0
        o = max(0, min(o, (1 << cw) - 1))
        m = min(mg + o, mmax) if lost else mg
        n = min(2 * e + 2 * m + 1, s - 2)
        for pos in (e + m + 1, s - 1 - n + e + m):       # round(c) where start is cut to 1 / to S - 1 - n
            for dp in (-1, 0, 1):
                p = max(0, min(pos + dp, s - 1))
                for frac in (0, (1 << (cf - 1)) - 1, 1 << (cf - 1)):   # rounding down / half up
                    c = max(0, (p << cf) - (1 << (cf - 1)) + frac)
                    out.append({"cx": c, "cy": rng.randint(0, (t << cf) - 1), "ex": e,
                                "ey": rng.randint(0, min((1 << hw) - 1, (t - 3) // 2)),
                                "ox": o, "oy": rng.randint(0, o) if o else 0, "lost": int(lost),
                                "frame_w": s, "frame_h": t})
    return out


def random_vectors(g: dict, rng: random.Random, n: int) -> list[dict[str, int]]:
    cf, cw, hw = int(g["CF"]), int(g["COORD_W"]), int(g["HALF_W"])
    out = []
    for _ in range(n):
        s, t = rng.randint(3, (1 << cw) - 1), rng.randint(3, (1 << cw) - 1)
        out.append({"cx": rng.randint(0, (s << cf) - 1), "cy": rng.randint(0, (t << cf) - 1),
                    "ex": rng.randint(0, min((1 << hw) - 1, (s - 3) // 2)),
                    "ey": rng.randint(0, min((1 << hw) - 1, (t - 3) // 2)),
                    "ox": rng.randint(0, min(300, (1 << cw) - 1)), "oy": rng.randint(0, min(300, (1 << cw) - 1)), "lost": rng.randint(0, 1),
                    "frame_w": s, "frame_h": t})
    return out


def swap_axes(v: dict[str, int]) -> dict[str, int]:
    """The same vector with x and y exchanged (the edges of the y axis)."""
    return {"cx": v["cy"], "cy": v["cx"], "ex": v["ey"], "ey": v["ex"], "ox": v["oy"], "oy": v["ox"],
            "lost": v["lost"], "frame_w": v["frame_h"], "frame_h": v["frame_w"]}


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def region_v2(dut, gap):
    g = dut_generics()
    rng = random.Random(11 + int(gap * 10))
    await start(dut)
    vecs = edge_vectors(g, rng)
    vecs += [swap_axes(v) for v in vecs]
    vecs += random_vectors(g, rng, 2000)
    if int(g.get("REAL_TB", 0)):
        vecs += real_vectors()
    rng.shuffle(vecs)
    n = await stream(dut, vecs, OUTPUTS, LATENCY, lambda v: model(v, g), gap, seed=3, spacing=LATENCY)
    dut._log.info("%d vectors match the model (gap %.1f)", n, gap)


# ---------------------------------------------------------------- pytest entry points

TOP = "ms_region_v2"
MODULE = "test_ms_region_v2"


def v2_generics() -> dict[str, int]:
    """Core v2's: COORD_W 12, CF 8, HALF_W 6, MARGIN 32, MARGIN_MAX 255; REGION_W 10 holds every n the
    random vectors give (2e + 2m + 1 <= 637)."""
    fp = FixedParams()
    return {"COORD_W": fp.coord_bits, "CF": fp.centre_frac, "HALF_W": 6, "REGION_W": 10,
            "MARGIN": fp.margin, "MARGIN_MAX": 255}


def _run(gen: dict, sim, waves: bool, name: str) -> None:
    rtl_gen = {k: v for k, v in gen.items() if not k.endswith("_TB")}
    sim(TOP, MODULE, rtl_gen, hdl.rtl_sources(TOP), waves=waves, build_name=name,
        extra_env={hdl.GENERICS_ENV: json.dumps(gen)})


@pytest.mark.ghdl
def test_ms_region_v2(hdl_waves):
    if not SEQ_ROOT.is_dir():
        pytest.skip(f"the real-frame vectors need the dev sequences in {SEQ_ROOT} (../shared)")
    _run({**v2_generics(), "REAL_TB": 1}, hdl.run_ghdl, hdl_waves, f"ghdl_{TOP}")


@pytest.mark.ghdl
def test_ms_region_v2_small(hdl_waves):
    """A small margin, a low MARGIN_MAX and narrow coordinates: the clamps hit often."""
    _run({"COORD_W": 8, "CF": 4, "HALF_W": 4, "REGION_W": 9, "MARGIN": 3, "MARGIN_MAX": 40},
         hdl.run_ghdl, hdl_waves, f"ghdl_{TOP}_small")


@pytest.mark.verilator
def test_ms_region_v2_verilator(hdl_waves):
    """The GHDL -> Verilog netlist under Verilator (random and edge vectors)."""
    _run(v2_generics(), hdl.run_verilator, hdl_waves, f"verilator_{TOP}")
