"""cocotb test bench + pytest entry points for rtl/ms_init_job.vhd: the target model learnt from the rectangle
captured into a slot (docs/multi_target_core.md, "The init job"), against FixedTrackerV2.init's model.

The bench top (tb/ms_init_job_tb_top.vhd) joins the block to an ms_region_ram, the RAM of one slot.  Per case
the bench computes :func:`mstrack.fixed.multi_capacity.init_capture` of an init frame and box, writes the
rectangle's bins into the slot (a pixel is {orientation bin, colour bin} with the joint bins; on the frame's
border the orientation written is 3, not the model's 8, since the core's slot takes orientation from the
Sobel's interior stream and the block must count border pixels as 8 itself), starts the job
with the centre relative to the rectangle and a model of its own, and waits for `done`.  Then it reads every
model back through the read port: each must equal the model FixedTrackerV2.init learnt from the whole frame
(Qn and T of every bin), also after the other cases have run.

The clocks from `start` to `done` must be the header's sum (ms_bg_model's set-up of the box, the scan, its
three passes).  Cases: a generated frame with the box at its top-left corner (the ring and the region clipped) and, with
../shared, the init frames of Girl (D = 1) and MotorRolling (640 x 360, D = 2).  Colour bins under GHDL
(`make test`), tracker v2's joint bins (N_ORIENT 9) as a netlist under Verilator (`make test-extra`).
Run: ``.venv/bin/python -m pytest tb/test_ms_init_job.py``.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

from mstrack.fixed.blocks_v2 import slot_words
from mstrack.hw import hdl
from mstrack.hw.hdl import dut_generics

TOP = "ms_init_job_tb_top"
MODULE = "test_ms_init_job"
TB_DIR = Path(__file__).resolve().parent
SEQ_ROOT = TB_DIR.parents[1] / "shared" / "data" / "sequences"
COLOUR = {"LANES": 4, "STRIDE": 64, "ADDR_W": 14, "REGION_W": 9, "BIN_W": 9, "N_ORIENT": 1, "MODELS": 3,
          "DEPTH": 16384, "RD_LAT": 4}
JOINT = {**COLOUR, "N_ORIENT": 9}


def cases(joint: bool) -> list[tuple]:
    """(name, tracker, frame, box): the generated corner box first, then the real init frames there are."""
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from mstrack.io.data import load_sequence
    from mstrack.io.synthetic import make_scene
    from mstrack.track.params import V2_COLOUR, TrackerParams
    tp = TrackerParams(preset="v2") if joint else TrackerParams(preset="v2", **V2_COLOUR)
    frames, _ = make_scene(1, 160, 120, seed=7)
    out = [("corner", FixedTrackerV2(tp), frames[0], (0, 0, 20, 16))]
    for name in ("Girl", "MotorRolling"):
        if (SEQ_ROOT / name).is_dir():
            seq = load_sequence(SEQ_ROOT / name)
            out.append((name, FixedTrackerV2(tp), seq.frame(0), seq.init_box()))
    return out


async def read_model(dut, sel: int, n_or: int, n_col: int) -> tuple[np.ndarray, np.ndarray]:
    """Every joint bin of model *sel* (joint bin j = N_ORIENT colour + obin) through m_qn / m_t."""
    qn = np.zeros(n_or * n_col, np.int64)
    t = np.zeros(n_or * n_col, np.int64)
    dut.m_rd_sel.value = sel
    for j in range(n_or * n_col):
        dut.m_rd_addr.value = j // n_or
        dut.m_rd_obin.value = j % n_or
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        qn[j] = int(dut.m_qn.value)
        t[j] = int(dut.m_t.value)
    return qn, t


@cocotb.test()
async def init_jobs(dut):
    from mstrack.fixed.multi_capacity import init_capture
    g = dut_generics(COLOUR)
    joint = int(g["N_ORIENT"]) > 1
    n_or, n_col, bin_w = int(g["N_ORIENT"]), 1 << int(g["BIN_W"]), int(g["BIN_W"])
    for s in ("rst", "we", "wbank", "waddr", "wdata", "start", "rect_w", "rect_h", "cx", "cy", "wb", "hb",
              "ring16", "model", "org_x", "org_y", "last_x", "last_y", "m_rd_addr", "m_rd_obin", "m_rd_sel"):
        getattr(dut, s).value = 0
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await FallingEdge(dut.clk)
    learnt: dict[int, tuple[str, object]] = {}
    todo = cases(joint)
    assert len(todo) >= 1
    for k, (name, trk, frame, box) in enumerate(todo):
        sel = (2 * k + 1) % int(g["MODELS"])
        trk.init(frame, box)
        fh, fw = frame.shape[:2]
        ic = init_capture(box, fw, fh, trk.params, trk.fixed)
        x, y, w, h = ic.rect
        rect = trk._bins(frame, ic.d)[y: y + h, x: x + w]
        data = (rect // n_or) | ((rect % n_or) << bin_w) if joint else rect
        d = ic.d
        last = tuple((s - 1) // d if (s - 1) % d == 0 else 4095 for s in (fw, fh))
        if joint:                                    # the slot's border orientation is not the model's 8
            ys, xs = np.mgrid[y: y + h, x: x + w]
            border = (xs == 0) | (ys == 0) | (xs == last[0]) | (ys == last[1])
            assert name != "corner" or border.any()
            data = np.where(border, (rect // n_or) | (3 << bin_w), data)
        for (bank, word), v in slot_words(data, int(g["LANES"]), int(g["STRIDE"])).items():
            dut.we.value, dut.wbank.value, dut.waddr.value, dut.wdata.value = 1, bank, word, v
            await FallingEdge(dut.clk)
        dut.we.value = 0
        while int(dut.busy.value):                   # the count RAM's clear after reset
            await FallingEdge(dut.clk)
        for port, v in (("rect_w", w), ("rect_h", h), ("cx", ic.cd[0] - x), ("cy", ic.cd[1] - y), ("wb", ic.wb),
                        ("hb", ic.hb), ("ring16", trk.ring16), ("model", sel), ("org_x", x), ("org_y", y),
                        ("last_x", last[0]), ("last_y", last[1])):
            getattr(dut, port).value = v
        dut.start.value = 1
        await FallingEdge(dut.clk)
        dut.start.value = 0
        dut.model.value = (sel + 1) % int(g["MODELS"])   # taken with start
        clocks = 1
        while not int(dut.done.value):
            await FallingEdge(dut.clk)
            clocks += 1
            assert clocks < w * h + 5 * n_or * n_col + 2000, f"{name}: no done after {clocks} clocks"
        from test_ms_bg_model import DEFAULTS as BG_DEFAULTS, lat_done, setup_latency
        want = (setup_latency(ic.wb, ic.hb, int(g.get("HALF_W", 6))) + int(g["RD_LAT"]) + w * h
                + lat_done({**BG_DEFAULTS, **g}) + 8)
        assert clocks == want, f"{name}: start -> done {clocks} clocks, the header's sum is {want}"
        learnt[sel] = (name, trk.model)
        qn, t = await read_model(dut, sel, n_or, n_col)
        assert np.array_equal(qn, trk.model.Qn) and np.array_equal(t, trk.model.T), \
            f"{name}: model {sel} differs from init's in {int(np.sum((qn != trk.model.Qn) | (t != trk.model.T)))} bins"
        dut._log.info("%s: rectangle %d x %d at (%d, %d), D = %d, model %d: init's model, done after %d clocks",
                      name, w, h, x, y, ic.d, sel, clocks)
    for sel, (name, m) in learnt.items():            # each model kept while the others were learnt
        qn, t = await read_model(dut, sel, n_or, n_col)
        assert np.array_equal(qn, m.Qn) and np.array_equal(t, m.T), f"{name}: model {sel} changed by a later job"


# ----------------------------------------------------------------------------- pytest side
def _sources() -> list:
    return hdl.rtl_sources(TOP, extra=[TB_DIR / "ms_init_job_tb_top.vhd"])


@pytest.mark.ghdl
def test_ms_init_job(hdl_waves):
    """Colour bins (512), 3 models: the corner box, Girl, MotorRolling (the real frames with ../shared)."""
    hdl.run_ghdl(TOP, MODULE, COLOUR, _sources(), waves=hdl_waves, build_name="ghdl_ms_init_job_colour")


@pytest.mark.verilator
def test_ms_init_job_joint_verilator(hdl_waves):
    """Tracker v2's joint bins (N_ORIENT 9, 4,608 bins): the netlist under Verilator."""
    hdl.run_verilator(TOP, MODULE, JOINT, _sources(), waves=hdl_waves, build_name="verilator_ms_init_job_joint")
