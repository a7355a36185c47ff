"""cocotb test bench + pytest entry points for rtl/ms_init_merge.vhd: the joint core's init path
ms_frontend -> ms_decimate -> ms_init_merge -> ms_bg_model (N_ORIENT 9) (tb/ms_init_merge_tb_top.vhd).

Each case is a frame, a decimation D and a box (decimated px) with ring16: ms_bg_model and the merge
are started with the box, the frame is streamed (full speed or with random tvalid gaps), then

* the model: ``Qn`` and ``T`` of all 4,608 joint bins (read through m_rd_addr / m_rd_obin) and the
  totals sum Q, sum O = ``ms_bg_model(FixedTrackerV2(orient_T=64)._bins(frame, D), cx, cy, wb, hb,
  ring16, 4608)``, value by value: for the *tracker* cases exactly the call
  ``FixedTrackerV2(orient_T=64).init(frame, box)`` makes (recorded, and checked against the
  tracker's model), for the *geometry* cases a box placed by the case (frame corners and edges,
  rings reaching the frame border, the bottom row inside the ring at D = 1: the FIFO's worst case);
* the merge's own output, from the start to px_last: no pixel twice, every pixel of the decimated
  frame inside ms_bg_model's rectangle present, each with its joint bin (colour, orientation 0 .. 8;
  8 on the frame border), nothing outside the decimated frame; no FIFO overflow.

Some cases are followed at once (no idle clock) by another frame, which must not reach
ms_bg_model before px_last; one case is preceded by a frame abandoned in its bottom row (short
line) after which the merge must emit nothing more (its FIFO emptied), then the blocks are reset as
core v2 does.  D in {1, 2, 4, 8, 16}, frame sizes D does not divide (W - 1, H - 1), and sizes it
does (the last decimated row / column on the frame border).

Run: ``.venv/bin/python -m pytest tb/test_ms_init_merge.py``.
"""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

import numpy as np

import cocotb
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from mstrack.fixed.blocks import ms_kernel
from mstrack.track.params import TrackerParams

from test_ms_bg_model import expected
from test_ms_frontend import TB, frame_beats

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
N_OR = 9
ORIENT_T = 64


def scene(seed: int, h: int, w: int) -> np.ndarray:
    """Generated frame: coloured rectangles on a background, mild noise (flat areas: orientation 8,
    edges: the 8 octants)."""
    rng = np.random.default_rng(seed)
    img = np.empty((h, w, 3), np.int64)
    img[:] = rng.integers(0, 256, 3)
    for _ in range(14):
        x0, y0 = int(rng.integers(0, w)), int(rng.integers(0, h))
        x1, y1 = x0 + int(rng.integers(3, w // 2)), y0 + int(rng.integers(3, h // 2))
        img[y0:y1, x0:x1] = rng.integers(0, 256, 3)
    img += rng.integers(-12, 13, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def tracker_params(max_window: int | None = None) -> TrackerParams:
    kw = {} if max_window is None else {"max_window": max_window}
    return TrackerParams(preset="v2", orient_T=ORIENT_T, **kw)


def joint_bins(frame: np.ndarray, d: int) -> np.ndarray:
    """FixedTrackerV2(orient_T=64)._bins(frame, d): 9 colour + orientation of frame[::d, ::d]."""
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    return FixedTrackerV2(tracker_params())._bins(frame, d)


def tracker_case(name: str, frame: np.ndarray, box, max_window: int | None = None) -> dict:
    """The ms_bg_model call of FixedTrackerV2(orient_T=64).init(frame, box), as the tracker makes it."""
    import mstrack.fixed.tracker_v2 as tv2
    tp = tracker_params(max_window)
    calls: list[tuple] = []
    ds: list[int] = []
    orig = tv2.ms_bg_model

    def rec(bins, cx, cy, wb, hb, ring16, n_bins, *more):  # more: the model's optional widths (defaults: core v2's)
        calls.append((bins.copy(), cx, cy, wb, hb, ring16, n_bins))
        return orig(bins, cx, cy, wb, hb, ring16, n_bins, *more)

    tv2.ms_bg_model = rec
    try:
        trk = tv2.FixedTrackerV2(tp)
        bins_of = trk._bins

        def rec_bins(fr, d):
            ds.append(d)
            return bins_of(fr, d)
        trk._bins = rec_bins  # type: ignore[method-assign]
        trk.init(frame, box)
    finally:
        tv2.ms_bg_model = orig
    assert len(calls) == 1 and len(ds) == 1, name
    bins, cx, cy, wb, hb, ring16, n_bins = calls[0]
    assert n_bins == N_OR * 512
    assert np.array_equal(bins, joint_bins(frame, ds[0]))
    exp = expected(bins, cx, cy, wb, hb, ring16, n_bins, 17)
    assert np.array_equal(exp["Qn"], trk.model.Qn) and np.array_equal(exp["T"], trk.model.T), name
    return {"name": f"{name} (tracker init, D={ds[0]}, box {wb}x{hb} at ({cx},{cy}))", "frame": frame,
            "d": ds[0], "bins": bins, "cx": cx, "cy": cy, "wb": wb, "hb": hb, "ring16": ring16}


def geom_case(name: str, frame: np.ndarray, d: int, cx: int, cy: int, wb: int, hb: int, ring16: int) -> dict:
    bins = joint_bins(frame, d)
    hd, wd = bins.shape
    ker = ms_kernel(wb, hb, "flat", 8)
    assert 0 <= cx - ker.ex and cx + ker.ex < wd and 0 <= cy - ker.ey and cy + ker.ey < hd, name
    return {"name": f"{name} {frame.shape[1]}x{frame.shape[0]} D={d} box {wb}x{hb} at ({cx},{cy}) "
                    f"ring16 {ring16}",
            "frame": frame, "d": d, "bins": bins, "cx": cx, "cy": cy, "wb": wb, "hb": hb, "ring16": ring16}


def job_cases(job: dict) -> list[dict]:
    out = []
    for c in job["cases"]:
        if "seq" in c:
            from mstrack.io.data import load_sequence
            seq = load_sequence(Path(c["seq"]))
            frame = seq.frame(0)
            box = seq.init_box()
            label = Path(c["seq"]).name
        else:
            frame = scene(c["seed"], c["h"], c["w"])
            box = tuple(c.get("box", ()))
            label = f"scene {c['seed']}"
        if c["kind"] == "tracker":
            case = tracker_case(label, frame, box, c.get("max_window"))
        else:
            case = geom_case(label, frame, c["d"], *c["geom"])
        case.update({k: c[k] for k in ("gap", "follow", "abandon") if k in c})
        out.append(case)
    return out


class MergeTB(TB):
    def __init__(self, dut):
        super().__init__(dut, {})
        dut.start.value = 0
        dut.dec_log2.value = 0
        dut.m_rd_addr.value = 0
        dut.m_rd_obin.value = 0
        for k in ("cx", "cy", "wb", "hb", "ring16"):
            getattr(dut, k).value = 0
        self.arm = False
        self.out: list[tuple[int, int, int, int]] = []
        self.last_seen = False
        self.watch_quiet = False
        self.quiet_bad = 0
        self.dones = 0
        self.peak = 0                                     # FIFO words + reads in flight + prefetch buffer
        try:                                              # (if the simulator shows the hierarchy)
            m = dut.u_merge
            self.fifo = (m.wp, m.rp, m.qn, m.rv)
            self.fifo_aw = len(m.wp) - 1
        except AttributeError:
            self.fifo = None

    async def done_monitor(self):
        """Edge-triggered: counts ms_bg_model's done pulses (one may come while a next frame streams)."""
        while True:
            await RisingEdge(self.dut.done)
            self.dones += 1

    async def px_monitor(self):
        """The merge's output from start to px_last (and stray pixels while `watch_quiet`)."""
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            if self.fifo is not None:
                wp, rp, qn = (int(v.value) for v in self.fifo[:3])
                rv = bin(int(self.fifo[3].value)).count("1")
                self.peak = max(self.peak, (wp - rp) % (2 << self.fifo_aw) + qn + rv)
            if int(d.px_valid.value):
                if self.watch_quiet:
                    self.quiet_bad += 1
                if self.arm:
                    self.out.append((int(d.px_x.value), int(d.px_y.value), int(d.px_bin.value),
                                     int(d.px_obin.value)))
                    self.out_t.append((self.cycle(), int(d.px_last.value)))
                    if int(d.px_last.value):
                        self.arm = False
                        self.last_seen = True

    async def wait_idle(self):
        while True:
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            if int(self.dut.busy.value) == 0:
                break
        await Timer(1, "ns")

    async def start_model(self, c: dict) -> None:
        d = self.dut
        await self.wait_idle()
        for k in ("cx", "cy", "wb", "hb", "ring16"):
            getattr(d, k).value = int(c[k])
        d.dec_log2.value = c["d"].bit_length() - 1
        d.start.value = 1
        await RisingEdge(d.clk)
        d.start.value = 0
        for _ in range(400):
            await RisingEdge(d.clk)
            await ReadOnly()
            if int(d.counting.value):
                break
        else:
            raise AssertionError("ms_bg_model does not start counting")
        self.t_count = self.cycle()
        await Timer(1, "ns")

    def check_stream(self, c: dict) -> None:
        """No pixel twice, every pixel of ms_bg_model's rectangle present, bins right."""
        bins, cx, cy, wb, hb, r16 = c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"]
        hd, wd = bins.shape
        ker = ms_kernel(wb, hb, "flat", 8)
        rx, ry = ker.ex + ((r16 * wb) >> 4), ker.ey + ((r16 * hb) >> 4)
        ones = (1 << int(self.g["COORD_W"])) - 1
        assert self.last_seen, f"{c['name']}: no px_last"
        seen: dict[tuple[int, int], int] = {}
        for i, (x, y, b, o) in enumerate(self.out):
            if i == len(self.out) - 1 and x == ones and y == ones:
                continue                                   # px_last alone
            assert x < wd and y < hd, f"{c['name']}: pixel ({x},{y}) outside the {wd}x{hd} decimated frame"
            assert (x, y) not in seen, f"{c['name']}: pixel ({x},{y}) twice"
            seen[(x, y)] = 9 * b + o
            assert 9 * b + o == bins[y, x], \
                f"{c['name']}: pixel ({x},{y}) joint bin {9 * b + o} (colour {b}, obin {o}), model {bins[y, x]}"
        need = {(x, y) for y in range(max(0, cy - ry), min(hd - 1, cy + ry) + 1)
                for x in range(max(0, cx - rx), min(wd - 1, cx + rx) + 1)}
        missing = sorted(need - seen.keys())
        assert not missing, f"{c['name']}: {len(missing)} pixels of the rectangle missing, first {missing[:5]}"
        border = sum(1 for (x, y) in seen if seen[(x, y)] % 9 == 8)
        # the FIFO's worst case of rtl/ms_init_merge.vhd's header: min(W - 1, 2 RX + 1) + 7 at D = 1,
        # 7 at D >= 2 (memory, reads in flight and prefetch buffer together)
        bound = (min(wd - 1, 2 * rx + 1) if c["d"] == 1 else 0) + 7
        peak = "-" if self.fifo is None else self.peak
        self.dut._log.info("%s: merged stream ok (%d pixels, %d in the rectangle, %d with obin 8; FIFO peak %s "
                           "entries, bound %d)", c["name"], len(seen), len(need), border, peak, bound)
        assert self.fifo is None or self.peak <= bound, f"{c['name']}: FIFO peak {self.peak} > bound {bound}"

    async def run_case(self, c: dict, rng: random.Random, follower: np.ndarray | None) -> None:
        d = self.dut
        gap = float(c.get("gap", 0.0))
        await self.start_model(c)
        self.out, self.last_seen, self.arm, self.peak = [], False, True, 0
        self.out_t = []
        n_done = self.dones
        await self.drive(frame_beats(c["frame"]), rng, gap)
        if follower is not None:                          # the next frame at once
            await self.drive(frame_beats(follower), rng, gap)
        for _ in range(40000):
            if self.dones > n_done:
                break
            await RisingEdge(d.clk)
        else:
            raise AssertionError(f"{c['name']}: done does not come")
        assert self.dones == n_done + 1
        await ReadOnly()
        assert int(d.overflow.value) == 0, f"{c['name']}: merge FIFO overflow"
        exp = expected(c["bins"], c["cx"], c["cy"], c["wb"], c["hb"], c["ring16"], N_OR * 512, 17)
        nq, no = int(d.n_box.value), int(d.n_ring.value)
        await Timer(1, "ns")
        n = N_OR * 512
        qn = np.zeros(n, np.int64)
        t = np.zeros(n, np.int64)
        for u in range(n):
            d.m_rd_addr.value = u // N_OR
            d.m_rd_obin.value = u % N_OR
            await RisingEdge(d.clk)
            await ReadOnly()
            qn[u] = int(d.m_qn.value)
            t[u] = int(d.m_t.value)
            await Timer(1, "ns")
        self.check_stream(c)
        assert (nq, no) == (exp["nq"], exp["no"]), f"{c['name']}: sum Q, sum O = {nq}, {no}, model " \
            f"{exp['nq']}, {exp['no']}"
        if os.environ.get("MSTRACK_DUMP"):                # (debug: the stream into ms_bg_model, replayable)
            with open(os.environ["MSTRACK_DUMP"], "a") as f:
                f.write(json.dumps({"name": c["name"], "box": [int(c[k]) for k in ("cx", "cy", "wb", "hb", "ring16")],
                                    "px": self.out, "t": self.out_t, "t_count": self.t_count, "Qn": exp["Qn"].tolist(),
                                    "T": exp["T"].tolist(), "got": qn.tolist()}) + "\n")
        bad = np.nonzero((qn != exp["Qn"]) | (t != exp["T"]))[0]
        assert bad.size == 0, (f"{c['name']}: {bad.size} joint bins differ, first {bad[:5].tolist()}: Qn "
                               f"{qn[bad[:5]].tolist()} model {exp['Qn'][bad[:5]].tolist()}")
        d._log.info("%s gap %.1f%s: model exact (4608 joint bins, sum Q %d, sum O %d, %d bins with T)",
                    c["name"], gap, " + next frame at once" if follower is not None else "", nq, no,
                    int(exp["T"].sum()))

    async def abandoned(self, c: dict, rng: random.Random) -> None:
        """A frame abandoned in its bottom row (short line): the merge emits nothing after the error
        (its FIFO, full of bottom-row pixels at D = 1, emptied); then all blocks reset (core v2
        resets ms_bg_model and the merge)."""
        d = self.dut
        await self.start_model(c)
        self.arm = False
        beats = frame_beats(c["frame"])
        h, w = c["frame"].shape[:2]
        k = (h - 1) * w + w // 2                          # the bottom row's middle: eol there
        beats = beats[:k] + [beats[k][:2] + (1,) + beats[k][3:]]
        await self.drive(beats, rng, 0.0)
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            if int(d.frame_error.value):
                break
        for _ in range(4):                               # dp_error empties the FIFO 3 clocks later
            await RisingEdge(d.clk)
        await ReadOnly()
        self.watch_quiet, self.quiet_bad = True, 0
        await ClockCycles(d.clk, 3 * w)
        self.watch_quiet = False
        assert self.quiet_bad == 0, f"{c['name']}: {self.quiet_bad} pixels after the abandoned frame's error"
        await Timer(1, "ns")
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        d._log.info("abandoned frame (short line in its bottom row): nothing out after the error")


@cocotb.test()
async def init_merge(dut):
    job = json.loads(os.environ["MSTRACK_JOB"])
    tb = MergeTB(dut)
    await tb.reset()
    cocotb.start_soon(tb.px_monitor())
    cocotb.start_soon(tb.done_monitor())
    rng = random.Random(job["seed"])
    cases = job_cases(job)
    ds = set()
    for i, c in enumerate(cases):
        if c.get("abandon"):
            await tb.abandoned(c, rng)
        follower = scene(1000 + i, *c["frame"].shape[:2]) if c.get("follow") else None
        await tb.run_case(c, rng, follower)
        ds.add(c["d"])
    dut._log.info("%d cases exact, D in %s", len(cases), sorted(ds))
    if "expect_d" in job:
        assert ds == set(job["expect_d"]), f"decimations covered {sorted(ds)}"


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_init_merge_tb_top"
MODULE = "test_ms_init_merge"
WRAPPER = hdl.TB_DIR / "ms_init_merge_tb_top.vhd"
GENERICS = {"COORD_W": 12, "MAX_FRAME_W": 128, "COLOUR_BITS": 3, "HALF_W": 6, "RING_W": 5, "RING16_MAX": 31,
            "Q_W": 14, "O_W": 17, "KD_W": 29, "LOG2_D_MAX": 4, "ORIENT_T": ORIENT_T, "N_ORIENT": N_OR}


def synthetic_job(gap: float) -> dict:
    """Generated scenes: D = 1 with the bottom row in the ring (the FIFO's worst case) and the next
    frame at once, boxes at the four frame corners (box edge on the frame border), sizes D does and
    does not divide, D = 2 .. 16, the tracker's own init at D = 1 and 2; an abandoned frame."""
    cases = [
        # D = 1: ring over the whole width and the bottom row (FIFO: the bottom row's 64 px)
        # and the next frame at once; before it a frame abandoned in its bottom row
        {"kind": "geom", "seed": 1, "w": 64, "h": 48, "d": 1, "geom": [32, 40, 21, 11, 31], "follow": True,
         "abandon": True},
        # D = 1, box at the top-left corner (box edge on the frame border)
        {"kind": "geom", "seed": 2, "w": 45, "h": 37, "d": 1, "geom": [5, 4, 11, 9, 10]},
        # D = 1, bottom-right corner
        {"kind": "geom", "seed": 3, "w": 45, "h": 37, "d": 1, "geom": [39, 32, 11, 9, 16]},
        # D = 2: W - 1 = 45, H - 1 = 36 (D does not divide 45: the last decimated column is interior)
        {"kind": "geom", "seed": 4, "w": 46, "h": 37, "d": 2, "geom": [18, 15, 9, 7, 31], "follow": True},
        # D = 2: both divide (65 x 49: decimated 33 x 25, its last row and column on the frame border)
        {"kind": "geom", "seed": 5, "w": 65, "h": 49, "d": 2, "geom": [29, 21, 7, 7, 16]},
        # D = 4 (82 % 4 = 2, 69 % 4 = 1), top-right corner
        {"kind": "geom", "seed": 6, "w": 83, "h": 70, "d": 4, "geom": [18, 2, 5, 5, 31]},
        # D = 8 and 16
        {"kind": "geom", "seed": 7, "w": 83, "h": 70, "d": 8, "geom": [5, 4, 5, 5, 31]},
        {"kind": "geom", "seed": 8, "w": 83, "h": 70, "d": 16, "geom": [2, 2, 3, 3, 16]},
        # the tracker's init: D = 1 and (max_window 15) D = 2
        {"kind": "tracker", "seed": 9, "w": 64, "h": 48, "box": [40, 28, 17, 14]},
        {"kind": "tracker", "seed": 10, "w": 96, "h": 80, "box": [50, 52, 33, 26], "max_window": 15},
    ]
    for i, c in enumerate(cases):
        c["gap"] = gap if i % 2 == 0 else (0.3 - gap)
    return {"seed": 71 + int(10 * gap), "cases": cases, "expect_d": [1, 2, 4, 8, 16]}


def _run(name: str, job: dict, waves: bool) -> None:
    hdl.run_ghdl(TOP, MODULE, GENERICS, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=waves,
                 build_name=f"ms_init_merge_{name}", extra_env={"MSTRACK_JOB": json.dumps(job)})


@pytest.mark.ghdl
@pytest.mark.parametrize("gap", [0.0, 0.3], ids=["full_speed_first", "gaps_first"])
def test_ms_init_merge_synthetic(gap, hdl_waves):
    """Generated scenes (see synthetic_job), each case at full speed or with 30 % tvalid gaps
    (alternating; the two runs swap them)."""
    _run(f"synth_{int(10 * gap)}", synthetic_job(gap), hdl_waves)


@pytest.mark.ghdl
def test_ms_init_merge_real(hdl_waves):
    """Girl's init frame (128 x 96): FixedTrackerV2(orient_T=64).init's model at its own D = 1, with
    gaps, and with max_window 15 (D = 4) at full speed."""
    p = SEQ_ROOT / "Girl"
    if not p.is_dir():
        pytest.skip(f"{p} not found: the real-frame case needs ../shared/data/sequences")
    job = {"seed": 81, "cases": [{"kind": "tracker", "seq": str(p), "gap": 0.3, "follow": True},
                                 {"kind": "tracker", "seq": str(p), "max_window": 15}]}
    _run("girl", job, hdl_waves)


@pytest.mark.verilator
def test_ms_init_merge_verilator(hdl_waves):
    """The GHDL -> Verilog netlist (the av delay line's LUT RAM, the FIFO, the rectangle's product and
    |dx|) under Verilator: the D = 1 worst case (abandoned frame before it, next frame at once), D = 2
    with a size D does not divide, D = 16; with gaps."""
    job = synthetic_job(0.3)
    job["cases"] = [job["cases"][i] for i in (0, 3, 7)]
    del job["expect_d"]
    hdl.run_verilator(TOP, MODULE, GENERICS, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=hdl_waves,
                      build_name="ms_init_merge_verilator", extra_env={"MSTRACK_JOB": json.dumps(job)})


@cocotb.test(skip=os.environ.get("MSTRACK_REPLAY") is None)
async def bg_replay(dut):
    """Debug: replay a recorded merge output (MSTRACK_REPLAY, one JSON line) into ms_bg_model alone,
    clock by clock, and compare its model."""
    from cocotb.clock import Clock
    rec = json.loads(open(os.environ["MSTRACK_REPLAY"]).readline())
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    for k in ("start", "px_valid", "px_last", "px_bin", "px_obin", "px_x", "px_y", "m_rd_addr", "m_rd_obin"):
        getattr(dut, k).value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        if int(dut.busy.value) == 0:
            break
    await Timer(1, "ns")
    for k, v in zip(("cx", "cy", "wb", "hb", "ring16"), rec["box"]):
        getattr(dut, k).value = v
    dut.start.value = 1
    await RisingEdge(dut.clk)
    dut.start.value = 0
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        if int(dut.counting.value):
            break
    await Timer(1, "ns")
    t0 = rec["t"][0][0]
    cyc = rec.get("t_count", t0) if os.environ.get("MSTRACK_REPLAY_ABS") else t0
    junk = bool(os.environ.get("MSTRACK_REPLAY_JUNK"))
    rng = random.Random(5)
    for (x, y, b, o), (t, last) in zip(rec["px"], rec["t"]):
        while cyc < t:
            dut.px_valid.value = 0
            if junk:                                      # data lines change while px_valid is low
                dut.px_x.value, dut.px_y.value = rng.randrange(64), rng.randrange(48)
                dut.px_bin.value, dut.px_obin.value = rng.randrange(512), rng.randrange(9)
            await RisingEdge(dut.clk)
            cyc += 1
        dut.px_valid.value = 1
        dut.px_x.value, dut.px_y.value, dut.px_bin.value, dut.px_obin.value, dut.px_last.value = x, y, b, o, last
        await RisingEdge(dut.clk)
        cyc += 1
    dut.px_valid.value = 0
    dut.px_last.value = 0
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        if int(dut.done.value):
            break
    await Timer(1, "ns")
    qn = []
    for u in range(N_OR * 512):
        dut.m_rd_addr.value = u // N_OR
        dut.m_rd_obin.value = u % N_OR
        await RisingEdge(dut.clk)
        await ReadOnly()
        qn.append(int(dut.m_qn.value))
        await Timer(1, "ns")
    bad = [u for u in range(len(qn)) if qn[u] != rec["Qn"][u]]
    dut._log.info("replay %s: %d bins differ from the model %s; %d differ from the recorded chain run",
                  rec["name"], len(bad), bad[:5], sum(1 for u in range(len(qn)) if qn[u] != rec["got"][u]))
    assert not bad
