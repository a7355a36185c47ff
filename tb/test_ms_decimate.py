"""cocotb test bench + pytest entry points for rtl/ms_decimate.vhd: the v2 capture path
ms_frontend -> ms_decimate -> ms_region_capture -> colour / edge ms_region_ram
(tb/ms_decimate_tb_top.vhd).

Each case is a frame, a decimation D and a region of the decimated frame ``frame[::D, ::D]``;
the frame is streamed (full speed or with random valid gaps, dec_log2 and the region scrambled
once the frame has started: both are latched at frame start), then the whole region is read
back through the RAM read ports and compared with the model:

* colour RAM = ``FixedTrackerV2._capture(frame[::D, ::D], region)`` (what tracker v2 tracks on);
* edge RAM = the full-resolution edge bin of frame pixel (x D, y D) (ms_decimate passes it on;
  v2 does not use it);
* with generic ORIENT_T >= 0 (the joint core's capture, step 1 of docs/results_v2_mean.md "Path
  to adoption") the edge RAM holds ms_sobel's orientation bin instead: for the model cases
  (``FixedTrackerV2`` with ``orient_T`` = ORIENT_T, whose capture is the region of its joint
  bins 9 colour + orientation) colour RAM x 9 + orientation RAM = the model's joint bins, value
  by value; for the corner cases the orientation RAM = ``ms_orient_bin(ms_grey(frame),
  ORIENT_T)`` at frame pixel (x D, y D).

Cases:

* **model** cases: ``FixedTrackerV2`` is initialised on the frame with a box and its state is
  set to a target size that ms_decimation maps to D (lost, at twice the decimation, for
  D = 16); ``update(frame)`` runs and the (decimated image, region) of its capture is
  recorded: the region is the one ms_region computes on the decimated image in the model's own
  update (window + MARGIN, + the search offset while lost).  On real frames of
  ../shared/data/sequences (skipped with a message when absent) and on generated scenes.
* **corner** cases on random frames: regions at the four corners of the decimated interior,
  the whole interior, one pixel; frame sizes that D does not divide.
* an abandoned frame (protocol error) raises no ``done``; the next frame is captured exactly.

D in {1, 2, 4, 8, 16} everywhere.  Run: ``.venv/bin/python -m pytest tb/test_ms_decimate.py``.
"""

from __future__ import annotations

import json
import os
import random
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import cocotb
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from mstrack.fixed.blocks import Region, ms_edge_bin, ms_grey, ms_sobel, round_box
from mstrack.fixed.blocks_v2 import PAD_FRAC, SIZE_FRAC, ms_orient_bin, sixteenths
from mstrack.fixed.formats import FixedParams
from mstrack.fixed.tracker_v2 import FixedTrackerV2
from mstrack.track.params import V2_COLOUR, TrackerParams

from test_ms_frontend import ERR_SHORT_LINE, TB, frame_beats, random_frame

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
DEC_VALUES = (1, 2, 4, 8, 16)


# ---------------------------------------------------------------- cases (model side)

@dataclass
class Case:
    """One captured frame: the frame, D, the region (decimated px) and the model's colour bins."""

    name: str
    frame: np.ndarray
    d: int
    reg: Region
    colour: np.ndarray   # model: FixedTrackerV2._capture(frame[::d, ::d], reg)
    joint: bool = False  # colour holds the model's joint bins (orient_T > 0)


def model_case(name: str, frame: np.ndarray, box: tuple[int, int, int, int], d: int, tp: TrackerParams,
               fx: FixedParams, rng: random.Random) -> Case:
    """The region and colour bins of ``FixedTrackerV2.update(frame)`` with the target size set so
    that the frame is tracked at decimation ``d`` (lost at d / 2 for d = 16)."""
    trk = FixedTrackerV2(tp, fx)
    trk.init(frame, box)
    lost = d > 8
    k = (d // 2 if lost else d).bit_length() - 1
    pad16 = sixteenths(tp.pad, "pad")
    sh = PAD_FRAC + SIZE_FRAC

    def th(j: int) -> int:   # the largest size (Q.8) that ms_decimation maps to D = 2**j
        return (tp.max_window << (sh + j)) // (16 + pad16)
    fh, fw = frame.shape[:2]
    lo = 3 << SIZE_FRAC if k == 0 else th(k - 1) + 1
    hi = th(k) if k < 3 else max(fw, fh) << SIZE_FRAC
    s8 = rng.randint(lo, hi)
    if s8 > (fw << SIZE_FRAC) and s8 > (fh << SIZE_FRAC):
        raise ValueError(f"{name}: D = {d} needs a target larger than the frame (max_window too large)")
    # the larger side s8 (on the box's longer axis if it fits in the frame there), the other side
    # s8 times the box's aspect ratio (<= s8): max(w8, h8) = s8 sets D
    small = max(3 << SIZE_FRAC, s8 * min(box[2], box[3]) // max(box[2], box[3], 1))
    wide = box[2] >= box[3] if s8 <= min(fw, fh) << SIZE_FRAC else s8 <= fw << SIZE_FRAC
    if wide:
        trk.w8, trk.h8 = s8, min(small, fh << SIZE_FRAC)
    else:
        trk.w8, trk.h8 = min(small, fw << SIZE_FRAC), s8
    trk.lost = lost
    seen: list[tuple[np.ndarray, Region, np.ndarray]] = []
    capture = trk._capture

    def record(img: np.ndarray, reg: Region, *frame_d) -> np.ndarray:
        sub = capture(img, reg, *frame_d)
        seen.append((img, reg, sub))
        return sub
    trk._capture = record  # type: ignore[method-assign]
    res = trk.update(frame)
    assert res.extra["decimation"] == d, (name, d, res.extra["decimation"])
    img, reg, sub = seen[0]
    assert img.shape == frame[::d, ::d].shape
    return Case(f"{name} D={d} {'lost ' if lost else ''}{reg.w}x{reg.h}", frame, d, reg, sub, tp.orient_T > 0)


def corner_cases(frame: np.ndarray, d: int, region_max: int, tp: TrackerParams) -> list[Case]:
    """Regions at the corners of the decimated interior (1 .. Wd - 2), the whole interior, one pixel."""
    img = frame[::d, ::d]
    hd, wd = img.shape[:2]
    iw, ih = min(wd - 2, region_max), min(hd - 2, region_max)
    boxes = {(1, 1, iw, ih), (wd - 1 - iw, hd - 1 - ih, iw, ih), (1, hd - 1 - min(ih, 3), iw, min(ih, 3)),
             (wd - 1 - min(iw, 2), 1, min(iw, 2), ih), (wd // 2, hd // 2, 1, 1)}
    trk = FixedTrackerV2(tp)
    out = []
    for x, y, w, h in sorted(boxes):
        reg = Region(x, y, w, h, lo=(x, y), hi=(x + w - 1, y + h - 1))
        out.append(Case(f"corner {frame.shape[1]}x{frame.shape[0]} D={d} ({x},{y},{w},{h})", frame, d, reg,
                        trk._capture(img, reg)))
    return out


def job_cases(job: dict, g: dict) -> list[Case]:
    """The cases of one simulation (job from the pytest side)."""
    rng = random.Random(job["seed"])
    nrng = np.random.default_rng(job["seed"])
    fx = FixedParams(**job.get("fp", {}))
    out: list[Case] = []
    orient_t = int(g.get("ORIENT_T", -1))
    for src in job["sources"]:
        # colour bins (V2_COLOUR) unless the job's generics have ORIENT_T: then the model's joint bins
        tp = TrackerParams(preset="v2", **V2_COLOUR, colour_bits=int(g["COLOUR_BITS"]), max_window=src["max_window"])
        tp_model = tp.with_(orient_T=orient_t) if orient_t > 0 else tp  # corner cases: colour bins
        if "seq" in src:
            from mstrack.io.data import load_sequence
            seq = load_sequence(src["seq"])
            frame = seq.frame(src.get("frame", 0))
            box = round_box(*[float(v) for v in seq.gt[src.get("frame", 0)]])
            name = seq.name
        elif "scene" in src:
            from mstrack.io.synthetic import make_scene
            frames, boxes = make_scene(2, src["w"], src["h"], seed=src["scene"])
            frame = np.ascontiguousarray(frames[0])
            box = round_box(*[float(v) for v in boxes[0]])
            name = f"scene{src['scene']} {src['w']}x{src['h']}"
        else:
            frame = random_frame(nrng, src["h"], src["w"])
            out += [c for d in src["d"] for c in corner_cases(frame, d, int(g["REGION_MAX"]), tp)]
            continue
        out += [model_case(name, frame, box, d, tp_model, fx, rng) for d in src["d"]]
    return out


# ---------------------------------------------------------------- TB

class DecimateTB(TB):
    def __init__(self, dut):
        super().__init__(dut, {})
        self.lanes = int(self.g["LANES"])
        self.addr_w = int(self.g["ADDR_W"])
        self.stride = int(self.g["STRIDE"])
        self.cw = 3 * int(self.g["COLOUR_BITS"])
        self.ew = int(self.g["EDGE_BINS_LOG2"])
        self.n_edge = 1 << self.ew
        self.edge_shift = int(self.g["EDGE_SHIFT"])
        self.orient_t = int(self.g.get("ORIENT_T", -1))
        self.dones: list[int] = []
        dut.raddr.value = 0
        dut.dec_log2.value = 0

    async def done_monitor(self):
        """Edge-triggered (no per-clock Python): cycle of each done pulse."""
        while True:
            await RisingEdge(self.dut.done)
            self.dones.append(self.cycle())

    async def error_monitor(self):
        while True:
            await RisingEdge(self.dut.frame_error)
            await ReadOnly()
            self.events.append((self.cycle(), ("error", int(self.dut.err_code.value))))

    def set_inputs(self, d: int, reg: Region) -> None:
        dut = self.dut
        dut.dec_log2.value = d.bit_length() - 1
        dut.reg_x.value, dut.reg_y.value, dut.reg_w.value, dut.reg_h.value = reg.x, reg.y, reg.w, reg.h

    async def drive_scrambled(self, frame: np.ndarray, rng: random.Random, gap: float, scramble_at: int) -> None:
        """Stream a frame (as TB.drive, writing only the signals that change: this bench streams
        640x360 frames), with dec_log2 and the region scrambled from beat ``scramble_at`` on
        (after the frame's start event: the front end raises it 9 clocks after the sof beat)."""
        dut = self.dut
        h, w = frame.shape[:2]
        words = ((frame[..., 2].astype(np.int64) << 16) | (frame[..., 1].astype(np.int64) << 8)
                 | frame[..., 0]).ravel().tolist()
        dut.frame_width.value = w
        dut.frame_height.value = h
        sof = eol = valid = -1
        for i, data in enumerate(words):
            while gap and rng.random() < gap:
                dut.in_valid.value = valid = 0
                dut.in_data.value = rng.getrandbits(24)
                dut.in_sof.value = sof = rng.getrandbits(1)
                dut.in_eol.value = eol = rng.getrandbits(1)
                await RisingEdge(dut.clk)
            if i == scramble_at:
                dut.dec_log2.value = rng.getrandbits(3)
                for s in ("reg_x", "reg_y", "reg_w", "reg_h"):
                    getattr(dut, s).value = rng.getrandbits(6)
            if valid != 1:
                dut.in_valid.value = valid = 1
            dut.in_data.value = data
            x = i % w
            if sof != (i == 0):
                sof = int(i == 0)
                dut.in_sof.value = sof
            if eol != (x == w - 1):
                eol = int(x == w - 1)
                dut.in_eol.value = eol
            await RisingEdge(dut.clk)
        dut.in_valid.value = 0

    def addr(self, ry: int, j: int) -> int:
        return ry * self.stride + j

    def bank_addr(self, a: int) -> int:
        return sum(a << (b * self.addr_w) for b in range(self.lanes))

    async def read_region(self, reg: Region) -> tuple[np.ndarray, np.ndarray]:
        """Read the region back, one word (all banks) per clock: address set after a falling
        edge, data (registered at the rising edge) sampled at the next falling edge."""
        dut = self.dut
        cm, em = (1 << self.cw) - 1, (1 << self.ew) - 1
        got_c = np.zeros((reg.h, reg.w), np.int64)
        got_e = np.zeros((reg.h, reg.w), np.int64)
        nj = -(-reg.w // self.lanes)
        await FallingEdge(dut.clk)
        for ry in range(reg.h):
            for j in range(nj):
                dut.raddr.value = self.bank_addr(self.addr(ry, j))
                await FallingEdge(dut.clk)
                c, e = int(dut.rdata_colour.value), int(dut.rdata_edge.value)
                for b in range(self.lanes):
                    rx = j * self.lanes + b
                    if rx < reg.w:
                        got_c[ry, rx] = (c >> (b * self.cw)) & cm
                        got_e[ry, rx] = (e >> (b * self.ew)) & em
        await RisingEdge(dut.clk)
        return got_c, got_e

    def expected_edge(self, case: Case) -> np.ndarray:
        d, reg = case.d, case.reg
        if self.orient_t >= 0:   # orientation bins, defined on the whole frame (8 on its border)
            full = ms_orient_bin(ms_grey(case.frame), self.orient_t)
            return full[np.ix_((reg.y + np.arange(reg.h)) * d, (reg.x + np.arange(reg.w)) * d)]
        full = ms_edge_bin(ms_sobel(ms_grey(case.frame)), self.n_edge, self.edge_shift)  # interior (H-2, W-2)
        ys = (reg.y + np.arange(reg.h)) * d - 1
        xs = (reg.x + np.arange(reg.w)) * d - 1
        return full[np.ix_(ys, xs)]

    async def capture(self, case: Case, rng: random.Random, gap: float) -> None:
        dut = self.dut
        reg = case.reg
        assert max(reg.w, reg.h) <= int(self.g["REGION_MAX"]), f"{case.name}: region larger than REGION_MAX"
        self.set_inputs(case.d, reg)
        exp_c, exp_e = case.colour, self.expected_edge(case)
        if case.joint:   # the model's joint bins = 9 colour + orientation
            assert self.orient_t > 0
            exp_c, exp_e = case.colour // 9, case.colour % 9
        # the last region word is addressed during the frame: a read in the done clock must see it
        last_j, last_b = (reg.w - 1) // self.lanes, (reg.w - 1) % self.lanes
        dut.raddr.value = self.bank_addr(self.addr(reg.h - 1, last_j))
        n_done = len(self.dones)
        w = case.frame.shape[1]
        await self.drive_scrambled(case.frame, rng, gap, scramble_at=2 * w + 12)
        for _ in range(40):
            await RisingEdge(dut.clk)
            await ReadOnly()
            if len(self.dones) > n_done:
                break
        assert len(self.dones) == n_done + 1, f"{case.name}: no done after a good frame"
        assert int(dut.dec_q.value) == case.d.bit_length() - 1, f"{case.name}: latched log2 D"
        await RisingEdge(dut.clk)                 # raddr sampled in the done clock
        await ReadOnly()
        c_last = (int(dut.rdata_colour.value) >> (last_b * self.cw)) & ((1 << self.cw) - 1)
        assert c_last == exp_c[-1, -1], f"{case.name}: last write not visible at done"
        await RisingEdge(dut.clk)
        got_c, got_e = await self.read_region(reg)
        assert np.array_equal(got_c, exp_c), f"{case.name}: colour region differs from the model " \
            f"at {np.argwhere(got_c != exp_c)[:5].tolist()}"
        assert np.array_equal(got_e, exp_e), f"{case.name}: edge region differs at " \
            f"{np.argwhere(got_e != exp_e)[:5].tolist()}"
        if case.joint:
            assert np.array_equal(got_c * 9 + got_e, case.colour), f"{case.name}: joint bins differ"


@cocotb.test()
async def decimated_capture(dut):
    job = json.loads(os.environ["MSTRACK_JOB"])
    tb = DecimateTB(dut)
    await tb.reset()
    cocotb.start_soon(tb.error_monitor())
    cocotb.start_soon(tb.done_monitor())
    rng = random.Random(job["seed"])
    gap = float(job.get("gap", 0.0))
    cases = job_cases(job, tb.g)
    seen_d: set[int] = set()
    for i, case in enumerate(cases):
        if job.get("abandon") and i == 1:
            # an abandoned frame (short line) raises no done; the next good frame is exact
            n_done = len(tb.dones)
            tb.set_inputs(case.d, case.reg)
            beats = frame_beats(case.frame)
            w = case.frame.shape[1]
            k = 3 * w + 4
            beats = beats[:k] + [beats[k][:2] + (1,) + beats[k][3:]] + beats[k + 1:]
            await tb.drive(beats, rng, gap)
            await ClockCycles(dut.clk, 20)
            assert len(tb.dones) == n_done, "done raised for an abandoned frame"
            assert tb.events[-1][1] == ("error", ERR_SHORT_LINE), f"expected a short-line error: {tb.events[-2:]}"
        await tb.capture(case, rng, gap)
        seen_d.add(case.d)
        dut._log.info("%s: region matches the model", case.name)
    assert seen_d == set(job["expect_d"]), f"decimations covered {sorted(seen_d)}"
    dut._log.info("%d regions captured and read back exactly, D in %s, gap %.2f", len(cases), sorted(seen_d), gap)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402

TOP = "ms_decimate_tb_top"
MODULE = "test_ms_decimate"
WRAPPER = hdl.TB_DIR / "ms_decimate_tb_top.vhd"


def dec_generics(lanes: int, fp: FixedParams, max_frame_w: int, orient_t: int | None = None, **tp_kw) -> dict:
    g = core_generics(TrackerParams(**tp_kw), fp, lanes=lanes)
    keys = ("LANES", "COORD_W", "REGION_MAX", "STRIDE", "ADDR_W", "COLOUR_BITS", "EDGE_BINS_LOG2", "EDGE_SHIFT")
    out = {**{k: g[k] for k in keys}, "MAX_FRAME_W": max_frame_w, "LOG2_D_MAX": 4}
    if orient_t is not None:
        out["ORIENT_T"] = orient_t
    return out


def _seq(name: str) -> str:
    p = SEQ_ROOT / name
    if not p.is_dir():
        pytest.skip(f"{p} not found: the real-frame cases need ../shared/data/sequences")
    return str(p)


def _run(name: str, generics: dict, job: dict, waves: bool) -> None:
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=waves,
                 build_name=f"ms_decimate_{name}", extra_env={"MSTRACK_JOB": json.dumps(job)})


SMALL_FP = {"max_half": 4, "margin": 2}


def synthetic_sources(scene: int) -> list[dict]:
    """Random frames whose sizes D does not divide (corner regions, D 1-4 and 8-16) and a generated
    scene (the model's own regions at every D), small generics (max_window 7)."""
    return [{"w": 45, "h": 37, "d": [1, 2, 4], "max_window": 7},
            {"w": 83, "h": 70, "d": [8, 16], "max_window": 7},
            {"scene": scene, "w": 96, "h": 80, "d": list(DEC_VALUES), "max_window": 7}]


@pytest.mark.ghdl
@pytest.mark.parametrize("gap", [0.0, 0.3], ids=["full_speed", "gaps"])
@pytest.mark.parametrize("lanes", [2, 4])
def test_ms_decimate_synthetic(lanes, gap, hdl_waves):
    """Random frames (sizes D does not divide): corner regions of the decimated interior for every D;
    generated scenes: the model's own regions for every D; an abandoned frame; small generics."""
    g = dec_generics(lanes, FixedParams(**SMALL_FP), 128)
    job = {"seed": 21 + lanes + int(10 * gap), "gap": gap, "fp": SMALL_FP, "abandon": True,
           "expect_d": list(DEC_VALUES),
           "sources": synthetic_sources(scene=5)}
    _run(f"synth_l{lanes}_{'gap' if gap else 'full'}", g, job, hdl_waves)


@pytest.mark.ghdl
@pytest.mark.parametrize("gap", [0.0, 0.3], ids=["full_speed", "gaps"])
def test_ms_decimate_real_small(gap, hdl_waves):
    """Girl (128x96), default v2 generics region RAM (LANES 2, REGION_MAX 191): the model's regions at
    every D (max_window 15 so that a target inside the frame reaches D = 8)."""
    g = dec_generics(2, FixedParams(), 256)
    job = {"seed": 31 + int(10 * gap), "gap": gap, "expect_d": list(DEC_VALUES),
           "sources": [{"seq": _seq("Girl"), "d": list(DEC_VALUES), "max_window": 15}]}
    _run(f"girl_{'gap' if gap else 'full'}", g, job, hdl_waves)


@pytest.mark.ghdl
@pytest.mark.parametrize("gap", [0.0, 0.2], ids=["full_speed", "gaps"])
def test_ms_decimate_real_640(gap, hdl_waves):
    """Large real frames, default generics, LANES 4: ball1_vot (640x360) at D = 1 (max_window 127,
    a 129x125 region) at full speed; Deer (704x400) at D = 8 (max_window 63) with input gaps."""
    g = dec_generics(4, FixedParams(), 1024)
    src = ({"seq": _seq("ball1_vot"), "d": [1], "max_window": 127} if gap == 0.0
           else {"seq": _seq("Deer"), "d": [8], "max_window": 63})
    job = {"seed": 41, "gap": gap, "expect_d": src["d"], "sources": [src]}
    _run(f"real640_{'gap' if gap else 'full'}", g, job, hdl_waves)


@pytest.mark.ghdl
def test_ms_decimate_orient(hdl_waves):
    """The joint core's capture (ORIENT_T 64, the candidate's threshold): colour and orientation
    region RAMs against the fixed model's joint bins (generated scene, every D) and against
    ms_orient_bin (corner regions of random frames: frame border, sizes D does not divide); LANES 4,
    input gaps (the Girl case below runs at full speed)."""
    g = dec_generics(4, FixedParams(**SMALL_FP), 128, orient_t=64)
    job = {"seed": 54, "gap": 0.3, "fp": SMALL_FP, "abandon": True,
           "expect_d": list(DEC_VALUES),
           "sources": synthetic_sources(scene=6)}
    _run("orient_gap", g, job, hdl_waves)


@pytest.mark.ghdl
def test_ms_decimate_orient_real(hdl_waves):
    """The joint core's capture on real frames: Girl (128x96) at every D, the model's regions
    (FixedTrackerV2 with orient_T 64), default v2 region generics (LANES 2)."""
    g = dec_generics(2, FixedParams(), 256, orient_t=64)
    job = {"seed": 61, "gap": 0.0, "expect_d": list(DEC_VALUES),
           "sources": [{"seq": _seq("Girl"), "d": list(DEC_VALUES), "max_window": 15}]}
    _run("orient_girl", g, job, hdl_waves)


@pytest.mark.verilator
def test_ms_decimate_verilator(hdl_waves):
    """The GHDL -> Verilog netlist of the capture path (shift muxes, latch) under Verilator:
    the synthetic cases, LANES 2, with input gaps."""
    g = dec_generics(2, FixedParams(**SMALL_FP), 128)
    job = {"seed": 27, "gap": 0.3, "fp": SMALL_FP, "abandon": True, "expect_d": list(DEC_VALUES),
           "sources": synthetic_sources(scene=5)}
    hdl.run_verilator(TOP, MODULE, g, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=hdl_waves,
                      build_name="ms_decimate_verilator", extra_env={"MSTRACK_JOB": json.dumps(job)})
