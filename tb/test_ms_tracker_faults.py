"""Stream faults at system level: rtl/ms_tracker.vhd against the model, result by result.

cocotb module and pytest entry points in one file.  The bench drives the core beat by beat
(own AXI-Stream driver: tuser / tlast per beat, random input gaps, frame_width / frame_height
per frame, init boxes at any time, resets at any time) and consumes the results with a
ready pattern (always, never = sustained back-pressure, random).  Every accepted beat, every
init box the core takes and every reset is fed, in stream order, to
:class:`mstrack.hw.cosim.CoreModel` (the fixed-point model plus the documented stream, init and
error behaviour of docs/architecture.md, "Errors and recovery"), which predicts every result
word; each is compared field by field.  Watchdogs: a beat stalled too long, an init box never
taken, or a predicted result that does not come fails the test as a lock-up.

Directed cases: one cocotb test each (``DIRECTED``), all in one simulation
(``test_tracker_faults``).  Constrained random: :func:`fuzz` runs the seeds of MSTRACK_FUZZ
(``first:count``) in one simulation; the failing seed is printed (replay:
``make test-fuzz SEEDS=<seed> N=1``).  Small generics (max_half 15, margin 8, MAX_FRAME_W 64) and
small synthetic frames (32x24 .. 64x48).
"""
from __future__ import annotations

import json
import os
import random
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import cocotb
from cocotb.utils import get_sim_time
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, Event, First, RisingEdge, Timer

from mstrack.hw.cosim import (COMPARED_FIELDS, ERR_NAMES, CoreConfig, CoreModel, diff_fields,
                           frame_words)
from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.fixed.vhdl_pkg import unpack_result
from mstrack.track.params import TrackerParams

CLK_NS = 10
MAX_FRAME_W = 64
FIFO_DEPTH = 4
STALL_LIMIT = 200_000        # cycles a beat / an init box may wait while results are consumed
RESULT_LIMIT = 200_000       # cycles to wait for a predicted result


def core_config() -> CoreConfig:
    return CoreConfig(TrackerParams(), FixedParams(max_half=15, margin=8), max_frame_w=MAX_FRAME_W)


# ----------------------------------------------------------------------------- stimulus
def scene(n: int, w: int, h: int, seed: int) -> tuple[list[np.ndarray], list[tuple[int, int, int, int]]]:
    """n synthetic frames w x h (cropped from a scene at least 32x32) and the target's boxes."""
    from mstrack.io.synthetic import make_scene
    frames, gt = make_scene(n, max(w, 32), max(h, 32), seed=seed, target_size=(14, 12))
    return ([frame_words(np.ascontiguousarray(f[:h, :w])) for f in frames],
            [round_box(*map(float, g)) for g in gt])


Beat = tuple[int, int, int]          # (data, tuser, tlast)


def beats_of(words: np.ndarray, fault: str | None = None, arg: int = 0) -> list[Beat]:
    """The beats of one frame (rows of 24-bit words), optionally with a fault.

    fault: short_line / long_line (row ``arg`` 3 px short / 2 px long), no_sof, no_tlast (row
    ``arg`` without tlast), cut (only the first ``arg`` beats), extra_lines (``arg`` lines
    without sof after the last), tuser_stuck (tuser on the first ``arg`` beats, 0 = all), sof_eol
    (tlast on the first beat too).
    """
    h, w = words.shape
    out: list[Beat] = []
    for y in range(h):
        row = [int(v) for v in words[y]]
        if fault == "short_line" and y == arg:
            row = row[: w - 3]
        if fault == "long_line" and y == arg:
            row = row + row[:2]
        for x, v in enumerate(row):
            out.append((v, int(y == 0 and x == 0), int(x == len(row) - 1)))
        if fault == "no_tlast" and y == arg:
            out[-1] = (out[-1][0], out[-1][1], 0)
    if fault == "no_sof":
        out[0] = (out[0][0], 0, out[0][2])
    elif fault == "cut":
        out = out[:arg]
    elif fault == "extra_lines":
        for y in range(arg):
            out += [(int(v), 0, int(x == w - 1)) for x, v in enumerate(words[y % h])]
    elif fault == "tuser_stuck":
        k = arg or len(out)
        out = [(d, 1 if i < k else u, t) for i, (d, u, t) in enumerate(out)]
    elif fault == "sof_eol":
        out[0] = (out[0][0], 1, 1)
    return out


# ----------------------------------------------------------------------------- bench
@dataclass
class Stats:
    beats: int = 0
    stall_cycles: int = 0
    inits: int = 0
    resets: int = 0
    results: int = 0
    kinds: dict[str, int] = field(default_factory=dict)


class Bench:
    """Driver, consumer, init port and model of one run (one cocotb test or one fuzz seed)."""

    #: the result fields compared (core v2's bench, tb/test_ms_tracker_v2_faults.py, overrides these
    #: three and make_config / make_model)
    fields: tuple[str, ...] = COMPARED_FIELDS

    def __init__(self, dut, seed: int = 0, label: str = "") -> None:
        self.dut = dut
        self.cfg = self.make_config()
        self.g = self.cfg.generics()
        self.rng = random.Random(seed)
        self.label = label or f"seed {seed}"
        self.model = self.make_model()
        self.fw = self.fh = 0
        self.gap = 0.0                      # probability of an idle clock before a beat
        self.ready_mode: float = 1.0        # P(result tready) per clock; 0 = sustained back-pressure
        self.got: list[tuple[int, int]] = []   # (epoch, word)
        self.epoch = 0
        self.in_reset = False
        self.init_task = None
        self.stats = Stats()
        self.errors: list[str] = []
        self.mode_evt = Event()
        self.stopped = False

    def make_config(self):
        return core_config()

    def make_model(self) -> CoreModel:
        return CoreModel(self.cfg.tp, self.cfg.fp, MAX_FRAME_W)

    def unpack(self, word: int) -> dict[str, int]:
        return unpack_result(word, self.g)

    # -- set-up ------------------------------------------------------------------------------
    async def start(self, fw: int, fh: int, clock: bool = True) -> None:
        d = self.dut
        self.set_size(fw, fh)
        d.s_init_tvalid.value = 0
        d.s_init_x.value = 0
        d.s_init_y.value = 0
        d.s_init_w.value = 0
        d.s_init_h.value = 0
        d.s_axis_tvalid.value = 0
        d.s_axis_tdata.value = 0
        d.s_axis_tuser.value = 0
        d.s_axis_tlast.value = 0
        d.m_axis_result_tready.value = 0
        if clock:
            cocotb.start_soon(Clock(d.clk, CLK_NS, unit="ns").start())
        d.rst.value = 1
        self.in_reset = True
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        self.in_reset = False
        self.consumer = cocotb.start_soon(self._consume())
        await ClockCycles(d.clk, 2)

    def stop(self) -> None:
        """End the consumer (and a pending init box) of this run."""
        self.stopped = True
        self.mode_evt.set()
        if self.init_task is not None:
            self.init_task.cancel()
            self.init_task = None
        self.dut.s_init_tvalid.value = 0

    def set_size(self, fw: int, fh: int) -> None:
        self.fw, self.fh = fw, fh
        self.dut.frame_width.value = fw & 0xFFF
        self.dut.frame_height.value = fh & 0xFFF

    def ready(self, p: float) -> None:
        self.ready_mode = p
        if p <= 0:
            self.dut.m_axis_result_tready.value = 0
        self.mode_evt.set()

    # -- the result consumer -----------------------------------------------------------------
    async def _consume(self) -> None:
        """Takes the results; event-driven while always / never ready (simulation speed)."""
        d = self.dut
        tvalid = d.m_axis_result_tvalid
        while not self.stopped:
            p = self.ready_mode
            if p <= 0:                                   # sustained back-pressure
                d.m_axis_result_tready.value = 0
                self.mode_evt.clear()
                await self.mode_evt.wait()
                continue
            if p >= 1:
                d.m_axis_result_tready.value = 1
                if not int(tvalid.value):
                    self.mode_evt.clear()
                    await First(RisingEdge(tvalid), self.mode_evt.wait())
                    continue
            else:
                d.m_axis_result_tready.value = int(self.rng.random() < p)
            await RisingEdge(d.clk)
            if not self.in_reset and int(tvalid.value) and int(d.m_axis_result_tready.value):
                self.got.append((self.epoch, int(d.m_axis_result_tdata.value)))

    # -- video -------------------------------------------------------------------------------
    async def send(self, beats: list[Beat]) -> None:
        """Drive beats one by one (random gaps); each accepted beat goes to the model."""
        d = self.dut
        m = self.model
        for data, user, last in beats:
            if self.gap and self.rng.random() < self.gap:
                d.s_axis_tvalid.value = 0
                await ClockCycles(d.clk, self.rng.randint(1, 4))
            d.s_axis_tdata.value = data
            d.s_axis_tuser.value = user
            d.s_axis_tlast.value = last
            d.s_axis_tvalid.value = 1
            t_stall = None
            while True:
                await RisingEdge(d.clk)
                if int(d.s_axis_tready.value):
                    break
                # stalled: sleep until tready rises (event-driven), watchdog on the time
                now = get_sim_time("ns")
                if t_stall is None:
                    t_stall = now
                stall = (now - t_stall) // CLK_NS
                # results not taken (ready 0) stall the input legitimately, but not for ever
                if stall > 4 * STALL_LIMIT or (stall > STALL_LIMIT and self.ready_mode > 0):
                    raise AssertionError(f"{self.label}: lock-up, beat {self.stats.beats} stalled "
                                         f"{stall} cycles")
                await First(RisingEdge(d.s_axis_tready), Timer(STALL_LIMIT * CLK_NS, "ns"))
            if t_stall is not None:
                self.stats.stall_cycles += (get_sim_time("ns") - t_stall) // CLK_NS
            if self.init_task is not None and not m.in_frame:
                # an init box is taken between frames, before the next beat
                self.errors.append(f"{self.label}: beat {self.stats.beats} accepted while an init box "
                                   "waited between frames")
            m.beat(data, user, last, self.fw, self.fh)
            self.stats.beats += 1
        d.s_axis_tvalid.value = 0

    async def frame(self, words: np.ndarray, fault: str | None = None, arg: int = 0) -> None:
        await self.send(beats_of(words, fault, arg))

    async def idle(self, n: int) -> None:
        """n clocks (a timer, not n callbacks), ending just after a rising edge."""
        if n > 1:
            await Timer(n * CLK_NS - CLK_NS // 2, "ns")
        await RisingEdge(self.dut.clk)

    # -- init port ---------------------------------------------------------------------------
    def offer_init(self, box: tuple[int, int, int, int]) -> None:
        """Present an init box (s_init_tvalid held until taken); returns at once."""
        assert self.init_task is None, "one init box at a time"
        self.init_task = cocotb.start_soon(self._init(tuple(box)))

    async def _init(self, box: tuple[int, int, int, int]) -> None:
        d = self.dut
        d.s_init_x.value = box[0]
        d.s_init_y.value = box[1]
        d.s_init_w.value = box[2]
        d.s_init_h.value = box[3]
        d.s_init_tvalid.value = 1
        wait = 0
        while True:
            await RisingEdge(d.clk)
            if int(d.s_init_tready.value):
                break
            wait += 1
            if not int(d.s_init_tready.value) and wait % 64 == 1:
                # sleep until tready rises (event-driven), with a watchdog on the time
                await First(RisingEdge(d.s_init_tready), Timer(64 * CLK_NS, "ns"))
            if wait > STALL_LIMIT + 100_000:
                self.errors.append(f"{self.label}: lock-up, init box not taken after {wait} cycles")
                return
        d.s_init_tvalid.value = 0
        if self.model.in_frame:
            self.errors.append(f"init box {box} taken inside a frame (beat {self.stats.beats})")
        self.model.init(box, int(d.frame_width.value), int(d.frame_height.value))
        self.stats.inits += 1
        self.init_task = None

    async def init(self, box: tuple[int, int, int, int]) -> None:
        """Present an init box and wait until the core takes it."""
        self.offer_init(box)
        task = self.init_task
        await task

    # -- reset -------------------------------------------------------------------------------
    async def reset(self, cycles: int = 3) -> None:
        """Synchronous reset now (between two beats of the driver); the queued results are lost."""
        d = self.dut
        if self.init_task is not None:
            self.init_task.cancel()
            self.init_task = None
            d.s_init_tvalid.value = 0
        d.s_axis_tvalid.value = 0
        d.rst.value = 1
        self.in_reset = True
        self.epoch += 1
        self.model.reset()
        self.stats.resets += 1
        await ClockCycles(d.clk, cycles)
        d.rst.value = 0
        self.in_reset = False
        await RisingEdge(d.clk)

    # -- results -----------------------------------------------------------------------------
    def expected(self, epoch: int | None = None) -> list[dict[str, int]]:
        e = self.epoch if epoch is None else epoch
        return [r for r, ep in zip(self.model.results, self.model.epochs) if ep == e]

    def received(self, epoch: int | None = None) -> list[int]:
        e = self.epoch if epoch is None else epoch
        return [w for ep, w in self.got if ep == e]

    async def drain(self, limit: int = RESULT_LIMIT) -> None:
        """Wait until every result predicted so far (this epoch) has come out; lock-up otherwise."""
        if self.ready_mode <= 0:
            self.ready(1.0)
        waited = 0
        while len(self.received()) < len(self.expected()):
            await self.idle(256)
            waited += 256
            if waited > limit:
                raise AssertionError(
                    f"{self.label}: lock-up: {len(self.received())} results of {len(self.expected())} "
                    f"predicted after {waited} cycles (next expected: "
                    f"{self.model.kinds[len(self.model.results) - len(self.expected()) + len(self.received())]})")

    def compare(self) -> list[str]:
        """Every received word against the model; earlier epochs (cut by a reset) may miss their
        last results (lost with the reset), the current epoch must be complete."""
        out = list(self.errors)
        kinds = self.model.kinds
        for ep in range(self.epoch + 1):
            exp = self.expected(ep)
            idx = [i for i, e in enumerate(self.model.epochs) if e == ep]
            got = self.received(ep)
            if len(got) > len(exp) or (ep == self.epoch and len(got) != len(exp)):
                out.append(f"epoch {ep}: {len(got)} results, model predicts {len(exp)}")
            for i, (w, e) in enumerate(zip(got, exp)):
                d = diff_fields(self.unpack(w), e, self.fields)
                if d:
                    out.append(f"epoch {ep} result {i} ({kinds[idx[i]]}): " + "; ".join(d))
        return out

    async def finish(self, quiet: int = 300) -> list[str]:
        """Drain, check that nothing more comes, compare everything."""
        await self.drain()
        await self.idle(quiet)
        for k in self.model.kinds:
            self.stats.kinds[k] = self.stats.kinds.get(k, 0) + 1
        self.stats.results = len(self.got)
        return self.compare()


async def play_plan(b: Bench, frames: list[np.ndarray], plan: list, stall_every: int,
                    stall_cycles: int, bad_width: int, ready: float = 0.3) -> None:
    """Stream ``frames`` (all of the bench's size) through ``b`` following ``plan``, one entry per
    frame: None a good frame, ``(fault, arg)`` a frame with that fault (:func:`beats_of`), "size" the
    frame announced ``bad_width`` wide (an out-of-range size), "resize" a frame 8 px narrower with
    the size set to match (then set back).  Every ``stall_every``-th frame the result consumer
    stops for ``stall_cycles`` clocks, then resumes at ready probability ``ready``."""
    w, h = b.fw, b.fh

    async def stall(cycles: int) -> None:
        b.ready(0)
        await b.idle(cycles)
        b.ready(ready)
    for i, p in enumerate(plan):
        if i % stall_every == stall_every - 1:
            cocotb.start_soon(stall(stall_cycles))
        if p == "size":
            b.set_size(bad_width, h)
            await b.frame(frames[i])
            b.set_size(w, h)
        elif p == "resize":
            b.set_size(w - 8, h)
            await b.frame(frames[i][:, : w - 8])
            b.set_size(w, h)
        else:
            await b.frame(frames[i], *(p or (None, 0)))


async def run_directed(dut, body, seed: int = 1, size: tuple[int, int] = (48, 40),
                       bench: type[Bench] = Bench) -> Bench:
    """One directed case: *body* drives a fresh *bench*; every result is compared with its model."""
    b = bench(dut, seed, label=body.__qualname__.split(".")[0])
    await b.start(*size)
    await body(b)
    errs = await b.finish()
    b.stop()
    dut._log.info(f"{b.label}: {b.stats}")
    assert not errs, "\n".join(errs[:20])
    return b


def kinds_of(b: Bench) -> list[str]:
    return list(b.model.kinds)


# ----------------------------------------------------------------------------- directed cases
W0, H0 = 48, 40


def outside(box: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """A box with less than 3x3 px inside the frame (rejected)."""
    return (-40, -40, 20, 20)


@cocotb.test()
async def result_backpressure(dut):
    """m_axis_result_tready low for many frames: the core back-pressures the video (FIFO full ->
    s_axis_tready low), no result is dropped (good or error), overflow never set; then a
    random consumer."""
    async def body(b: Bench) -> None:
        fr, gt = scene(14, W0, H0, 11)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.drain()
        b.ready(0)
        faults = {3: ("short_line", 5), 5: ("no_sof", 0), 6: ("long_line", 20)}
        async def stream():
            for i in range(1, 10):
                await b.frame(fr[i], *faults.get(i, (None, 0)))
        task = cocotb.start_soon(stream())
        await b.idle(10 * (W0 * H0 + 3000))          # ~10 frames' worth of time
        n = len(b.model.results) - 1                   # results since the consumer stopped
        assert not task.done(), "the video input was not back-pressured"
        assert len(b.got) == 1, "a result came out while tready was low"
        # the FIFO and the one result waiting to enter it, no more
        assert FIFO_DEPTH <= n <= FIFO_DEPTH + 1, f"{n} results pending"
        assert int(dut.m_axis_result_tvalid.value) == 1 and int(dut.s_axis_tready.value) == 0
        b.ready(1.0)
        await task
        b.ready(0.15)
        for i in range(10, 14):
            await b.frame(fr[i])
    await run_directed(dut, body)


@cocotb.test()
async def init_mid_frame(dut):
    """An init box presented in the middle of a frame is taken after that frame's last beat and
    applies to the next frame (the frame in progress is not tracked with it)."""
    async def body(b: Bench) -> None:
        fr, gt = scene(6, W0, H0, 12)
        await b.frame(fr[0])
        bt = beats_of(fr[1])
        await b.send(bt[: len(bt) // 2])
        b.offer_init(gt[1])
        await b.send(bt[len(bt) // 2:])
        for i in range(2, 6):
            await b.frame(fr[i])
        assert kinds_of(b) == ["no_target", "no_target", "init", "track", "track", "track"], kinds_of(b)
    await run_directed(dut, body)


@cocotb.test()
async def reinit_while_tracking(dut):
    """Re-init while tracking: between frames (next frame learns), mid-frame (the frame in
    progress is tracked with the old target, the next learns), a rejected box (the target stays,
    flag `rejected` on the next result) and a clipped one."""
    async def body(b: Bench) -> None:
        fr, gt = scene(12, W0, H0, 13)
        await b.init(gt[0])
        for i in range(0, 3):
            await b.frame(fr[i])
        await b.init((5, 5, 12, 10))                 # another target (background)
        await b.frame(fr[3])
        await b.frame(fr[4])
        bt = beats_of(fr[5])
        await b.send(bt[:700])
        b.offer_init(gt[5])
        await b.send(bt[700:])
        await b.frame(fr[6])
        await b.frame(fr[7])
        await b.init(outside(gt[7]))
        await b.frame(fr[8])
        await b.frame(fr[9])
        await b.init((W0 - 10, 20, 30, 12))          # clipped at the right border
        await b.frame(fr[10])
        await b.frame(fr[11])
        k = kinds_of(b)
        assert k == ["init", "track", "track", "init", "track", "track", "init", "track", "track",
                     "track", "init", "track"], k
        assert b.model.results[8]["flags"] & (1 << 4), "rejected flag expected on result 8"
        assert b.model.results[10]["flags"] & (1 << 1), "clipped flag expected on result 10"
    await run_directed(dut, body)


@cocotb.test()
async def frame_size_change(dut):
    """Frame size change between frames: before any init every size gives no_target; with a
    target, a frame of another size gives error size_changed and leaves the state unchanged
    (tracking resumes when the size comes back); an init at the new size tracks there."""
    async def body(b: Bench) -> None:
        fr, gt = scene(14, 64, 48, 14)
        crop = lambda f, w, h: f[:h, :w]            # noqa: E731
        await b.frame(crop(fr[0], W0, H0))
        b.set_size(40, 32)
        await b.frame(crop(fr[1], 40, 32))
        b.set_size(W0, H0)
        await b.init((10, 8, 14, 12))
        await b.frame(crop(fr[2], W0, H0))
        await b.frame(crop(fr[3], W0, H0))
        b.set_size(64, 48)
        await b.frame(fr[4])
        b.set_size(W0, 32)
        await b.frame(crop(fr[5], W0, 32))
        b.set_size(W0, H0)
        await b.frame(crop(fr[6], W0, H0))
        await b.frame(crop(fr[7], W0, H0))
        b.set_size(64, 48)
        await b.init(gt[8])
        for i in range(8, 11):
            await b.frame(fr[i])
        b.set_size(32, 24)
        await b.frame(crop(fr[11], 32, 24))
        b.set_size(64, 48)
        await b.frame(fr[12])
        await b.frame(fr[13])
        k = kinds_of(b)
        assert k == ["no_target", "no_target", "init", "track", "error:size_changed", "error:size_changed",
                     "track", "track", "init", "track", "track", "error:size_changed", "track", "track"], k
    await run_directed(dut, body)


@cocotb.test()
async def frame_size_out_of_range(dut):
    """frame_width / frame_height out of range (0, < 3, > MAX_FRAME_W): the frame is dropped with
    error `size`, a frame in progress is abandoned (one error), an init box taken while the size
    is out of range is rejected; no lock-up, the next good frame tracks."""
    async def body(b: Bench) -> None:
        fr, gt = scene(8, W0, H0, 15)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1])
        for fw, fh in [(0, H0), (1, H0), (2, H0), (MAX_FRAME_W + 1, H0), (W0, 0), (W0, 2), (0, 0),
                       (4095, 4095)]:
            b.set_size(fw, fh)
            await b.frame(fr[2])
        b.set_size(2, 2)                            # a real 2x2 frame
        await b.frame(fr[2][:2, :2])
        b.set_size(W0, H0)
        await b.frame(fr[3])
        await b.send(beats_of(fr[4])[:1000])        # a frame in progress ...
        b.set_size(MAX_FRAME_W + 8, H0)
        await b.frame(fr[4])                        # ... cut by a start of frame of a bad size
        await b.init(gt[4])                         # rejected: the size is out of range
        b.set_size(W0, H0)
        for i in range(5, 8):
            await b.frame(fr[i])
        k = kinds_of(b)
        assert k == ["init", "track"] + ["error:size"] * 9 + ["track", "error:size", "track", "track",
                                                              "track"], k
        assert b.model.results[-3]["flags"] & (1 << 4), "rejected flag expected"
    await run_directed(dut, body)


@cocotb.test()
async def reset_mid_frame(dut):
    """Reset in the middle of a frame: the core restarts clean (no target, frame count 0); the
    rest of that frame, if it keeps coming, is one missing-start-of-frame error."""
    async def body(b: Bench) -> None:
        fr, gt = scene(10, W0, H0, 16)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1])
        await b.drain()
        bt = beats_of(fr[2])
        await b.send(bt[:1100])
        await b.reset()
        await b.frame(fr[3])
        await b.init(gt[4])
        await b.frame(fr[4])
        await b.frame(fr[5])
        bt = beats_of(fr[6])
        await b.send(bt[:900])
        await b.drain()
        await b.reset()
        await b.send(bt[900:])                      # the rest of the frame after the reset
        await b.frame(fr[7])
        await b.init(gt[8])
        await b.frame(fr[8])
        await b.frame(fr[9])
        await b.drain()
        assert [len(b.received(e)) for e in range(3)] == [2, 3, 4]
        assert [k for k, e in zip(kinds_of(b), b.model.epochs) if e == 2] == \
            ["error:no_sof", "no_target", "init", "track"]
    await run_directed(dut, body)


@cocotb.test()
async def reset_during_meanshift(dut):
    """Reset while the mean shift of a frame runs (busy = 1): that result is lost, the core
    restarts clean; also a reset while the init frame learns."""
    async def body(b: Bench) -> None:
        fr, gt = scene(8, W0, H0, 17)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1])
        await b.frame(fr[2])
        for _ in range(5000):
            await RisingEdge(dut.clk)
            if int(dut.busy.value):
                break
        assert int(dut.busy.value), "mean shift of frame 2 not seen"
        await b.reset()
        await b.frame(fr[3])
        await b.init(gt[4])
        await b.frame(fr[4])                        # the init frame, reset while it learns
        for _ in range(5000):
            await RisingEdge(dut.clk)
            if int(dut.busy.value):
                break
        assert int(dut.busy.value), "learn pass of frame 4 not seen"
        await b.reset()
        await b.init(gt[5])
        for i in range(5, 8):
            await b.frame(fr[i])
        await b.drain()
        assert [len(b.received(e)) for e in range(3)] == [2, 1, 3]
        assert [len(b.expected(e)) for e in range(3)] == [3, 2, 3]
    await run_directed(dut, body)


@cocotb.test()
async def reset_with_results_queued(dut):
    """Reset with results in the output FIFO (consumer stalled): they are discarded, nothing
    stale comes out after the reset."""
    async def body(b: Bench) -> None:
        fr, gt = scene(8, W0, H0, 18)
        await b.init(gt[0])
        b.ready(0)
        for i in range(4):
            await b.frame(fr[i])
        await b.idle(8000)
        assert int(dut.m_axis_result_tvalid.value) == 1
        await b.reset()
        b.ready(1.0)
        await b.idle(200)
        await b.frame(fr[4])
        await b.init(gt[5])
        for i in range(5, 8):
            await b.frame(fr[i])
        await b.drain()
        assert len(b.received(0)) == 0 and len(b.expected(0)) == 4
    await run_directed(dut, body)


@cocotb.test()
async def two_bad_frames(dut):
    """Two bad frames in a row (short + long line; cut + a frame without start of frame, which
    the checker sees as the cut frame's continuation), then good frames track."""
    async def body(b: Bench) -> None:
        fr, gt = scene(8, W0, H0, 19)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1], "short_line", 7)
        await b.frame(fr[2], "long_line", 30)
        await b.frame(fr[3])
        await b.frame(fr[4], "cut", 500)
        await b.frame(fr[5], "no_sof")
        await b.frame(fr[6])
        await b.frame(fr[7])
        k = kinds_of(b)
        assert k[:4] == ["init", "error:short_line", "error:long_line", "track"], k
        assert k[-2:] == ["track", "track"] and sum(x.startswith("error") for x in k) >= 3, k
    await run_directed(dut, body)


@cocotb.test()
async def fault_on_init_frame(dut):
    """A fault on the init frame: error (no_target), the init stays pending and the next good
    frame learns; also a cut init frame (its error comes with the next start of frame)."""
    async def body(b: Bench) -> None:
        fr, gt = scene(7, W0, H0, 20)
        await b.init(gt[0])
        await b.frame(fr[0], "short_line", 20)
        await b.frame(fr[1])
        await b.frame(fr[2])
        await b.init(gt[3])
        await b.frame(fr[3], "cut", 1500)
        await b.frame(fr[4])
        await b.frame(fr[5])
        await b.frame(fr[6])
        k = kinds_of(b)
        assert k == ["error:short_line", "init", "track", "error:cut", "init", "track", "track"], k
        assert b.model.results[0]["flags"] & (1 << 5) and b.model.results[3]["flags"] & (1 << 5)
    await run_directed(dut, body)


@cocotb.test()
async def extra_lines(dut):
    """Extra lines after the last line of a frame: the frame is tracked, the extra lines are one
    missing-start-of-frame error, the next frame tracks."""
    async def body(b: Bench) -> None:
        fr, gt = scene(5, W0, H0, 21)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1], "extra_lines", 3)
        await b.frame(fr[2])
        await b.frame(fr[3], "extra_lines", 1)
        await b.frame(fr[4])
        assert kinds_of(b) == ["init", "track", "error:no_sof", "track", "track", "error:no_sof",
                               "track"], kinds_of(b)
    await run_directed(dut, body)


@cocotb.test()
async def tuser_stuck_high(dut):
    """tuser stuck high: every beat is a start of frame that abandons the previous one (one
    error per beat: cut, or short line on a tlast beat); the input is throttled to the result
    rate, no result is lost, the next proper frame tracks."""
    async def body(b: Bench) -> None:
        fr, _ = scene(5, 32, 24, 22)
        await b.init((8, 6, 12, 10))
        await b.frame(fr[0])
        await b.frame(fr[1], "tuser_stuck", 0)
        await b.frame(fr[2])
        await b.frame(fr[3], "tuser_stuck", 5)
        await b.frame(fr[4])
        k = kinds_of(b)
        assert k[:2] == ["init", "error:cut"] and k[-1] == "track", k
        assert sum(x.startswith("error") for x in k) >= 31 * 24, len(k)   # ~ one per beat
    await run_directed(dut, body, size=(32, 24))


@cocotb.test()
async def last_frame_cut(dut):
    """The last frame is cut and no start of frame follows: no result for it (the core cannot
    tell a cut from a long gap), the core keeps accepting pixels (no lock-up); the next start of
    frame reports the cut and tracks; a reset also recovers."""
    async def body(b: Bench) -> None:
        fr, gt = scene(7, W0, H0, 23)
        await b.init(gt[0])
        await b.frame(fr[0])
        await b.frame(fr[1])
        await b.frame(fr[2], "cut", 1234)
        await b.idle(30_000)
        assert len(b.got) == 2 and len(b.model.results) == 2
        assert int(dut.s_axis_tready.value) == 1, "the core should wait for pixels"
        await b.frame(fr[3])
        await b.frame(fr[4])
        await b.frame(fr[5], "cut", 300)
        await b.idle(5000)
        await b.drain()
        await b.reset()
        await b.frame(fr[6])
        assert kinds_of(b) == ["init", "track", "error:cut", "track", "track", "no_target"], kinds_of(b)
    await run_directed(dut, body)


@cocotb.test()
async def faults_with_gaps_and_backpressure(dut):
    """Every fault class with random input gaps and a random / stalled result consumer."""
    async def body(b: Bench) -> None:
        fr, gt = scene(24, W0, H0, 24)
        b.gap = 0.3
        b.ready(0.3)
        await b.init(gt[0])
        plan = [None, ("short_line", 3), None, ("long_line", 11), ("no_sof", 0), None, ("cut", 777),
                None, ("no_tlast", 9), None, ("extra_lines", 2), None, ("tuser_stuck", 6), None,
                ("sof_eol", 0), None, "size", None, "resize", None, ("cut", 50), ("short_line", 0),
                None, None]
        await play_plan(b, fr, plan, stall_every=6, stall_cycles=15_000, bad_width=1)
        names = {k.split(":")[-1] for k in kinds_of(b)}
        assert {"short_line", "long_line", "no_sof", "cut", "size", "size_changed", "track"} <= names, names
    await run_directed(dut, body)


@cocotb.test()
async def clipped_init(dut):
    """Clipped init boxes at system level: partly outside the frame, on the border (the 1-px
    border has no Sobel neighbourhood), larger than the largest window: flag `clipped` on the
    init result, then tracking."""
    async def body(b: Bench) -> None:
        fr, gt = scene(9, W0, H0, 25)
        boxes = [(-6, 10, 16, 14), (0, 0, 12, 12), (4, 2, 40, 36)]
        for j, box in enumerate(boxes):
            await b.init(box)
            for i in range(3 * j, 3 * j + 3):
                await b.frame(fr[i])
        for j in range(3):
            r = b.model.results[3 * j]
            assert b.model.kinds[3 * j] == "init" and r["flags"] & (1 << 1), (j, r)
        assert b.model.results[6]["box_w"] == 31 and b.model.results[6]["box_h"] == 31
    await run_directed(dut, body)


DIRECTED = ["result_backpressure", "init_mid_frame", "reinit_while_tracking", "frame_size_change",
            "frame_size_out_of_range", "reset_mid_frame", "reset_during_meanshift",
            "reset_with_results_queued", "two_bad_frames", "fault_on_init_frame", "extra_lines",
            "tuser_stuck_high", "last_frame_cut", "faults_with_gaps_and_backpressure", "clipped_init"]


# ----------------------------------------------------------------------------- pytest side
def _run(testcase, env: dict[str, str], build_name: str = "ms_tracker_faults") -> None:
    """Verilator on the GHDL netlist when installed (about 50x faster here), else GHDL;
    MSTRACK_FAULTS_SIM=ghdl forces GHDL on the VHDL."""
    from mstrack.hw.hdl import have_verilator, run_ghdl, run_verilator
    verilator = os.environ.get("MSTRACK_FAULTS_SIM", "verilator") == "verilator" and have_verilator()
    runner = run_verilator if verilator else run_ghdl
    runner("ms_tracker", "test_ms_tracker_faults", generics=core_config().generics(),
           build_name=build_name, testcase=testcase, extra_env=env)


@pytest.mark.ghdl
@pytest.mark.parametrize("case", DIRECTED)
def test_tracker_faults(case):
    """Directed stream-fault cases (one simulation each), every result compared with the model."""
    _run(case, {}, build_name="ms_tracker_fuzz")


# ----------------------------------------------------------------------------- constrained random
FAULTS = ["short_line", "long_line", "no_sof", "no_tlast", "cut", "extra_lines", "tuser_stuck", "sof_eol"]
BAD_SIZES = [(0, None), (1, None), (2, None), (MAX_FRAME_W + 1, None), (None, 0), (None, 2), (4095, 4095)]


async def fuzz_seed(dut, seed: int, first: bool, cover: dict[str, int], bench: type[Bench] = Bench,
                    replay: str = "make test-fuzz SEEDS={seed} N=1") -> Bench:
    """One random run: a seeded mix of good frames, every fault class, size changes, bad sizes,
    inits (good / clipped / rejected, between frames / mid-frame), resets (mid-frame, during the
    mean shift, with results queued), input gaps and result back-pressure.  bench: the Bench class
    (core v2: tb/test_ms_tracker_v2_faults.py); replay: the command printed for a failing seed."""
    rng = random.Random(seed)
    w = rng.choice([32, 40, 48, 64])
    h = rng.choice([24, 32, 40])
    b = bench(dut, seed, label=f"fuzz seed {seed}")
    b.rng = random.Random(seed * 7919 + 1)
    fr, gt = scene(16, 64, 48, seed)
    await b.start(w, h, clock=first)
    fi = 0
    hit = lambda k: cover.__setitem__(k, cover.get(k, 0) + 1)   # noqa: E731

    def nxt() -> np.ndarray:
        nonlocal fi
        fi = (fi + 1) % len(fr)
        return fr[fi]

    def box_choice() -> tuple[tuple[int, int, int, int], str]:
        x, y, bw, bh = gt[fi]
        r = rng.random()
        if r < 0.6:
            return (x, y, bw, bh), "good"
        if r < 0.8:
            return (x - rng.randint(bw // 2, bw), y + rng.randint(-bh, 2), bw + rng.randint(0, 30), bh), "clipped"
        return (rng.choice([-40, w + 5]), y, bw, bh), "rejected"

    async def init(box: tuple[int, int, int, int]) -> None:
        """Between frames: wait until taken; inside an open (cut) frame: offer and go on."""
        if b.init_task is not None:
            return
        if b.model.in_frame:
            b.offer_init(box)
        else:
            await b.init(box)

    async def bp_pulse(cycles: int, after: float) -> None:
        b.ready(0)
        await b.idle(cycles)
        b.ready(after)

    if rng.random() < 0.8:
        await init(box_choice()[0])
        hit("init:start")
    steps = rng.randint(8, 14)
    for _ in range(steps):
        cur = f"{'gap' if b.gap else 'nogap'}/{'bp' if b.ready_mode < 1 else 'ready'}/" + \
              ("track" if b.model.has_target() else "pending" if b.model.pending else "none")
        op = rng.choices(["good", "fault", "size", "badsize", "init", "reset", "flow"],
                         [30, 28, 7, 6, 12, 5, 12])[0]
        words = nxt()[:h, :w]
        if op == "good":
            await b.frame(words)
        elif op == "fault":
            f = rng.choice(FAULTS)
            arg = {"short_line": rng.randrange(h), "long_line": rng.randrange(h), "no_tlast": rng.randrange(h - 1),
                   "cut": rng.randrange(1, w * h), "extra_lines": rng.randint(1, 3),
                   "tuser_stuck": rng.randint(1, 12)}.get(f, 0)
            hit(f"fault:{f}")
            hit(f"cross:{f}:{cur}")
            await b.frame(words, f, arg)
        elif op == "size":
            w2, h2 = rng.choice([32, 40, 48, 64]), rng.choice([24, 32, 40])
            b.set_size(w2, h2)
            await b.frame(fr[fi][:h2, :w2])
            if rng.random() < 0.6:
                b.set_size(w, h)
            else:
                w, h = w2, h2
            hit("size_change")
        elif op == "badsize":
            bw_, bh_ = rng.choice(BAD_SIZES)
            b.set_size(w if bw_ is None else bw_, h if bh_ is None else bh_)
            if rng.random() < 0.3:
                await init(box_choice()[0])
                hit("init:badsize")
            await b.frame(words)
            b.set_size(w, h)
            hit("badsize")
        elif op == "init":
            box, kind = box_choice()
            hit(f"init:{kind}")
            if rng.random() < 0.5:
                bt = beats_of(words)
                k = rng.randrange(len(bt))
                await b.send(bt[:k])
                if b.init_task is None:
                    b.offer_init(box)
                hit(f"init:mid_frame:{kind}")
                await b.send(bt[k:])
            else:
                await init(box)
                await b.frame(words)
        elif op == "reset":
            r = rng.choice(["mid_frame", "meanshift", "queued"])
            hit(f"reset:{r}")
            if r == "mid_frame":
                bt = beats_of(words)
                await b.send(bt[: rng.randrange(len(bt))])
                await b.reset()
            elif r == "meanshift":
                await b.frame(words)
                await b.idle(rng.randint(1, 400))
                await b.reset()
            else:
                b.ready(0)
                await b.frame(words)
                await b.idle(1500)
                await b.reset()
                b.ready(1.0)
            if rng.random() < 0.7:
                await init(box_choice()[0])
        else:                                      # flow: gaps and result back-pressure
            b.gap = rng.choice([0.0, 0.0, 0.1, 0.3])
            mode = rng.choice([1.0, 1.0, 0.5, 0.1])
            if rng.random() < 0.5:
                cocotb.start_soon(bp_pulse(rng.randint(1000, 8000), mode))
                hit("flow:stall")
            else:
                b.ready(mode)
            hit(f"flow:gap{b.gap}:ready{mode}")
            await b.frame(words)
    errs = await b.finish()
    b.stop()
    for k in b.model.kinds:
        hit("result:" + k)
    if errs:
        raise AssertionError(f"FUZZ SEED {seed} FAILED (replay: {replay.format(seed=seed)})\n"
                             + "\n".join(errs[:20]))
    return b


async def run_fuzz(dut, bench: type[Bench] = Bench, name: str = "fuzz",
                   replay: str = "make test-fuzz SEEDS={seed} N=1") -> None:
    """Seeds ``first:count`` of MSTRACK_FUZZ of :func:`fuzz_seed` on *bench*, one reset each; the
    summary (results, beats, coverage) to the log and to MSTRACK_FUZZ_REPORT."""
    first, count = (int(v) for v in os.environ.get("MSTRACK_FUZZ", "1:3").split(":"))
    report = os.environ.get("MSTRACK_FUZZ_REPORT")
    cover: dict[str, int] = {}
    t0 = time.time()
    done, results, beats = 0, 0, 0
    for seed in range(first, first + count):
        dut._log.info(f"{name} seed {seed}")
        try:
            b = await fuzz_seed(dut, seed, done == 0, cover, bench=bench, replay=replay)
        except BaseException:
            dut._log.error(f"FUZZ SEED {seed} FAILED (replay: {replay.format(seed=seed)})")
            raise
        done += 1
        results += b.stats.results
        beats += b.stats.beats
    summary = {"first": first, "seeds": done, "results": results, "beats": beats,
               "seconds": round(time.time() - t0, 1), "coverage": dict(sorted(cover.items()))}
    dut._log.info(f"{name}: " + json.dumps(summary))
    if report:
        with open(report, "w") as f:
            json.dump(summary, f, indent=1)


@cocotb.test()
async def fuzz(dut):
    """Constrained-random protocol test: seeds ``first:count`` of MSTRACK_FUZZ, one reset each."""
    await run_fuzz(dut)


@pytest.mark.ghdl
def test_tracker_fuzz(tmp_path):
    """A few seeds of the constrained-random protocol test in CI (make test-fuzz runs many)."""
    seeds = os.environ.get("MSTRACK_FUZZ", "1:3")
    rep = Path(os.environ.get("MSTRACK_FUZZ_REPORT") or tmp_path / "fuzz.json")
    _run("fuzz", {"MSTRACK_FUZZ": seeds, "MSTRACK_FUZZ_REPORT": str(rep)}, build_name="ms_tracker_fuzz")
    s = json.loads(rep.read_text())
    assert s["seeds"] == int(seeds.split(":")[1]) and s["results"] > 0
    print(f"\nfuzz seeds {seeds}: {s['results']} results, {s['beats']} beats, {s['seconds']} s")

