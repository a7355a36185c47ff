"""cocotb test bench + pytest entry points for rtl/ms_model_scale.vhd.

Model: :func:`mstrack.fixed.blocks_v2.ms_model_scale` (Qw = (Qn K) >> 16).  Streams of
(Qn, K, tag): the extremes (Qn = 0, 1, 2**16 - 1, 2**16; K = 0, 1, 2**HIST_W - 1), random
values, and the models of real inits (FixedTrackerV2 on real sequences, each scaled by the K of
its window and of random windows) when ../shared/data/sequences is there.  Back to back and with
random gaps; every result compared exactly, in order, LATENCY = 1 + max(1, ceil(log2(ceil(HIST_W
/ 2)))) clocks after its input.

Run: ``.venv/bin/python -m pytest tb/test_ms_model_scale.py``.
"""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from mstrack.fixed.blocks_v2 import ms_model_scale
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"HIST_W": 14, "QN_FRAC": 16, "TAG_W": 10}
CLK_NS = 10
SEQ_ROOT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sequences"
REAL_SEQS = ("Girl", "MotorRolling")


def latency(g: dict) -> int:
    """Header of rtl/ms_model_scale.vhd: the ms_mult_r4 latency for A_W = HIST_W digits."""
    a_w = int(g["HIST_W"])
    return 1 + max(1, (((a_w + 1) // 2) - 1).bit_length())


def real_models(n: int) -> list[tuple[np.ndarray, int]]:
    """(Qn, K) of FixedTrackerV2's init model on real sequences, K of the init window."""
    if not all((SEQ_ROOT / s).is_dir() for s in REAL_SEQS):
        return []
    from mstrack.io.data import load_sequence
    from mstrack.fixed.blocks import ms_kernel
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    out = []
    for name in REAL_SEQS:
        seq = load_sequence(SEQ_ROOT / name)
        trk = FixedTrackerV2()
        trk.init(seq.frame(0), seq.init_box())
        qn = trk.model.Qn[:n]
        for wd, hd in ((trk.w8 >> 8, trk.h8 >> 8), (127, 127), (3, 3)):
            out.append((qn, ms_kernel(min(wd, 127), min(hd, 127), "flat", 8).K))
    return out


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.5])
async def model_scale_stream(dut, gap):
    g = dut_generics(DEFAULTS)
    hw, qf, tw = int(g["HIST_W"]), int(g["QN_FRAC"]), int(g["TAG_W"])
    cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start())
    dut.rst.value = 1
    dut.in_valid.value = 0
    dut.in_qn.value = 0
    dut.in_k.value = 0
    dut.in_tag.value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(3100 + int(gap * 10))
    one, kmax = 1 << qf, (1 << hw) - 1
    items = [(qn, k) for qn in (0, 1, one - 1, one) for k in (0, 1, kmax)]
    items += [(rng.randint(0, one), rng.randint(0, kmax)) for _ in range(300)]
    for qn, k in real_models(1 << 9):
        items += [(int(q), min(k, kmax)) for q in qn]
    lat = latency(g)
    sent: list[tuple[int, int, int, int]] = []     # (cycle, qn, k, tag)
    i, cycle, got = 0, 0, 0
    while got < len(items):
        await RisingEdge(dut.clk)
        await ReadOnly()
        cycle += 1
        if dut.out_valid.value == 1:
            t_in, qn, k, tag = sent[got]
            exp = int(ms_model_scale(np.array([qn], np.int64), k)[0])
            assert dut.out_qw.value.to_unsigned() == exp, f"item {got}: Qn={qn} K={k}: {dut.out_qw.value.to_unsigned()} != {exp}"
            assert dut.out_tag.value.to_unsigned() == tag, f"item {got}: tag"
            assert cycle - t_in == lat, f"item {got}: latency {cycle - t_in} != {lat}"
            got += 1
        await Timer(1, "ns")
        if i < len(items) and rng.random() >= gap:
            qn, k = items[i]
            tag = i % (1 << tw)
            dut.in_qn.value = qn
            dut.in_k.value = k
            dut.in_tag.value = tag
            dut.in_valid.value = 1
            sent.append((cycle, qn, k, tag))
            i += 1
        else:
            dut.in_valid.value = 0
            dut.in_qn.value = rng.randint(0, one)          # junk while not valid
        assert cycle < 3 * len(items) + 100, "stuck"
    if gap == 0.0:
        assert cycle == len(items) + lat, f"full speed: {cycle} clocks for {len(items)} items"
    dut._log.info("%d items, gap %.1f: ok in %d clocks (latency %d)", len(items), gap, cycle, lat)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_model_scale"
MODULE = "test_ms_model_scale"

PARAMS = [
    pytest.param(DEFAULTS, id="default"),                                  # K <= 16129 (127 x 127)
    pytest.param({**DEFAULTS, "HIST_W": 10, "TAG_W": 1}, id="hist10"),     # small windows (31 x 31)
    pytest.param({**DEFAULTS, "HIST_W": 16}, id="hist16"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_model_scale_ghdl(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.verilator
def test_ms_model_scale_verilator(hdl_waves):
    hdl.run_verilator(TOP, MODULE, DEFAULTS, hdl.rtl_sources(TOP), waves=hdl_waves)
