"""cocotb test bench + pytest entry points for rtl/ms_window_size.vhd (tracker v2 geometry).

Every vector is compared with ``mstrack.fixed.blocks_v2.ms_window_size(s8, PAD16, D, limit)``:
the rounding boundaries of every D (the s8 on both sides of each half-way point for
n = 1 .. 300), the clamp boundaries (limit 0 .. 2**N_W - 1), random sizes (log-uniform over the
whole s8 range) and, for the small configuration, every s8 with every D (exhaustive).  Vectors
are streamed one per clock (full speed) and with random in_valid gaps; the latency is asserted
for every result.  :func:`stream` is shared by the other valid-only v2 geometry benches
(test_ms_box_size.py, test_ms_decimation.py).

Run: ``.venv/bin/python -m pytest tb/test_ms_window_size.py``.
"""

from __future__ import annotations

import random
from typing import Callable, Sequence

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time

from mstrack.fixed.blocks_v2 import ms_window_size
from mstrack.hw.hdl import dut_generics

CLK_NS = 10
#: in_valid -> out_valid (rtl/ms_window_size.vhd header)
LATENCY = 3


def cycle() -> int:
    return int(get_sim_time("ns")) // CLK_NS


async def start(dut) -> None:
    """Clock, reset (3 clocks), in_valid low."""
    dut.rst.value = Immediate(1)
    dut.in_valid.value = Immediate(0)
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start(start_high=False))
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


async def stream(dut, vectors: Sequence[dict[str, int]], outputs: Sequence[str], latency: int,
                 expected: Callable[[dict[str, int]], tuple[int, ...]], gap: float, seed: int,
                 spacing: int = 1) -> int:
    """Drive ``vectors`` (port -> value) with in_valid, one per clock (at most one per ``spacing``
    clocks) or with random gaps (garbage on the inputs while in_valid = 0); check every result
    (``outputs`` when out_valid) against ``expected(vector)`` and its latency.  Returns the number
    of vectors checked."""
    rng = random.Random(seed)
    got: list[tuple[int, tuple[int, ...]]] = []
    widths = {p: len(getattr(dut, p)) for p in vectors[0]}

    async def monitor() -> None:
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if int(dut.out_valid.value):
                got.append((cycle(), tuple(int(getattr(dut, o).value) for o in outputs)))

    mon = cocotb.start_soon(monitor())
    issued: list[int] = []
    for v in vectors:
        while gap and rng.random() < gap:
            dut.in_valid.value = 0
            for p, w in widths.items():
                getattr(dut, p).value = rng.getrandbits(w)
            await RisingEdge(dut.clk)
        for p, x in v.items():
            getattr(dut, p).value = x
        dut.in_valid.value = 1
        issued.append(cycle())
        await RisingEdge(dut.clk)
        for _ in range(spacing - 1):                   # the block is busy: garbage on the inputs
            dut.in_valid.value = 0
            for p, w in widths.items():
                getattr(dut, p).value = rng.getrandbits(w)
            await RisingEdge(dut.clk)
    dut.in_valid.value = 0
    await ClockCycles(dut.clk, latency + 3)
    mon.cancel()
    assert len(got) == len(vectors), f"{len(got)} results for {len(vectors)} vectors"
    bad = []
    for v, t_in, (t_out, res) in zip(vectors, issued, got):
        assert t_out - t_in == latency, f"latency {t_out - t_in} != {latency} for {v}"
        exp = expected(v)
        if res != exp:
            bad.append(f"{v}: got {res}, model {exp}")
    assert not bad, f"{len(bad)} mismatches, first: " + "; ".join(bad[:5])
    return len(vectors)


def size_vectors(g: dict, pad16: int, kmax: int, seed: int, exhaustive: bool) -> list[dict[str, int]]:
    """s8 / log2_d / limit vectors: rounding and clamp boundaries, random, exhaustive if asked."""
    rng = random.Random(seed)
    s_max = (1 << int(g["S8_W"])) - 1
    l_max = (1 << int(g["N_W"])) - 1
    c = 16 + pad16

    def limit() -> int:
        r = rng.random()
        return l_max if r < 0.4 else rng.randint(0, 4) if r < 0.5 else rng.randint(0, l_max)

    out: list[dict[str, int]] = []
    for k in range(kmax + 1):
        sh = 12 + k
        for n in range(1, 301):                          # n - 1 -> n at c s8 >= (2n - 1) 2**(sh - 1)
            b = -(-((2 * n - 1) << (sh - 1)) // c)
            for s in (b - 1, b):
                if 0 <= s <= s_max:
                    out.append({"s8": s, "log2_d": k, "limit": limit()})
        lims = range(l_max + 1) if l_max <= 255 else sorted({0, 1, 2, 3, 4, l_max - 1, l_max,
                                                              *rng.sample(range(l_max + 1), 200)})
        for lim in lims:                                 # clamp boundaries: n = limit - 1 .. limit + 1
            for n in (lim - 1, lim, lim + 1):
                s = -(-((2 * n - 1) << (sh - 1)) // c) if n > 0 else 0
                if 0 <= s <= s_max:
                    out.append({"s8": s, "log2_d": k, "limit": lim})
        for s in (0, 1, 255, 256, 3 << 8, s_max - 1, s_max):
            out.append({"s8": s, "log2_d": k, "limit": limit()})
    for _ in range(3000):
        s = min(s_max, int(2 ** rng.uniform(0, int(g["S8_W"]))))
        out.append({"s8": s, "log2_d": rng.randint(0, kmax), "limit": limit()})
    if exhaustive:
        out += [{"s8": s, "log2_d": k, "limit": limit()} for s in range(s_max + 1) for k in range(kmax + 1)]
    rng.shuffle(out)
    return out


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def window_size(dut, gap):
    g = dut_generics()
    pad16, kmax = int(g["PAD16"]), 7           # the whole log2_d port
    await start(dut)
    vecs = size_vectors(g, pad16, kmax, seed=5 + int(gap * 10), exhaustive=bool(g.get("EXHAUSTIVE_TB", 0)))
    n = await stream(dut, vecs, ("n",), LATENCY,
                     lambda v: (ms_window_size(v["s8"], pad16, 1 << v["log2_d"], v["limit"]),), gap, seed=1)
    dut._log.info("%d vectors match the model (PAD16 %d, gap %.1f)", n, pad16, gap)


# ---------------------------------------------------------------- pytest entry points

import json  # noqa: E402

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.blocks_v2 import sixteenths  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_window_size"
MODULE = "test_ms_window_size"


def v2_generics(tp: TrackerParams | None = None, fp: FixedParams | None = None) -> dict[str, int]:
    """ms_window_size generics of the v2 core: s8 in Q(COORD_W).8, n up to max_window."""
    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    return {"S8_W": fp.coord_bits + 8, "PAD16": sixteenths(tp.pad, "pad"),
            "N_W": tp.max_window.bit_length()}


PARAMS = [
    pytest.param(v2_generics(), id="v2_default"),
    pytest.param({**v2_generics(), "PAD16": 0}, id="pad0"),
    pytest.param({**v2_generics(TrackerParams(preset="v2", pad=0.4375, max_window=1023))}, id="pad7_w1023"),
    pytest.param({"S8_W": 12, "PAD16": 4, "N_W": 5, "EXHAUSTIVE_TB": 1}, id="small_exhaustive"),
]


def _run(gen: dict, sim: Callable, waves: bool, name: str) -> None:
    rtl_gen = {k: v for k, v in gen.items() if not k.endswith("_TB")}
    sim(TOP, MODULE, rtl_gen, hdl.rtl_sources(TOP), waves=waves, build_name=name,
        extra_env={hdl.GENERICS_ENV: json.dumps(gen)})


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_window_size(generics, hdl_waves, request):
    _run(generics, hdl.run_ghdl, hdl_waves, f"ghdl_{TOP}_{request.node.callspec.id}")


@pytest.mark.verilator
def test_ms_window_size_verilator(hdl_waves):
    """The GHDL -> Verilog netlist (shift-add constant multiply, shift mux) under Verilator."""
    _run(v2_generics(), hdl.run_verilator, hdl_waves, f"verilator_{TOP}_v2")
