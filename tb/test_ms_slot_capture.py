"""cocotb test bench + pytest entry points for rtl/ms_slot_capture.vhd (one target's region capture
of the shared-engine multi-target core).

The bench drives the full-resolution interior pixel stream itself (ms_frontend's ip_* and frame
events, random gaps within and between rows) and records every write of the slot's write port.  Per
frame it checks, value by value:

* the words written are exactly ``slot_words(ms_slot_capture(bins, D, region))`` of the descriptor
  armed for that frame, less the pixels on the frame's border, which the interior stream does not bring
  (a region that reaches the border is an init rectangle's), each once (none for a frame without a load for it, a late load, or the rows
  after an abandoned frame's error);
* ``released`` pulses once per captured good frame, after the region's last write, no later than 3
  clocks after the first pixel below the region (5 after frame_end when the region reaches the
  frame's last rows; frame_end comes after the last pixel or, in half the frames, with it, as the
  all-pixel stream's ``av_end`` does), and so before the stream reaches the capacity rule's ``release_line``;
* ``late`` pulses for a ``load_now`` after the region's first row, and only then.

Scenarios: loads between frames, in the frame_start clock and during the previous frame after its
release (for the next one), ``load_now`` during the frame before the region (also in the
frame_start clock), a late ``load_now``, a frame with no load, a second load replacing a pending one,
an abandoned frame (frame_error) with its region half written and the same region loaded again, D =
1 .. 16 on regions touching the decimated interior's borders, then random frames, some with regions
that reach the frame's border (rows then start at the region's column 1 when column 0 is the frame's).  The region goes in
at full resolution (x D, y D, (x + w) D, (y + h) D), as the engine gives it.

Run: ``.venv/bin/python -m pytest tb/test_ms_slot_capture.py``.
"""
from __future__ import annotations

import random
from dataclasses import dataclass, field

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.blocks_v2 import ms_slot_capture, slot_words
from mstrack.fixed.multi_capacity import release_line
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"LANES": 4, "COORD_W": 12, "REGION_MAX": 24, "STRIDE": 6, "ADDR_W": 8, "DATA_W": 9, "LOG2_D_MAX": 4}
W, H = 42, 37          # frame; interior columns 1 .. W - 2, rows 1 .. H - 2


@dataclass
class Load:
    d: int                     # decimation
    reg: tuple[int, int, int, int]   # x, y, w, h (decimated px)
    now: bool = False          # load_now
    at: int = -1               # index of the frame's pixel in whose clock it comes (-1: before frame_start,
    #                            -2: in the frame_start clock)


@dataclass
class Frame:
    bins: np.ndarray
    loads: list[Load] = field(default_factory=list)
    error_at: int | None = None        # abandon the frame after this many pixels
    expect: Load | None = None         # the descriptor this frame captures with (None: nothing)
    late: int = 0                      # late pulses expected


def dec_dims(d: int) -> tuple[int, int]:
    return (W - 1) // d + 1, (H - 1) // d + 1


def random_region(rng: random.Random, d: int, rmax: int) -> tuple[int, int, int, int]:
    """A region inside the decimated interior (1 .. Wd - 2, 1 .. Hd - 2), often touching its borders."""
    wd, hd = dec_dims(d)
    out = []
    for n in (wd, hd):
        size = rng.randint(1, min(rmax, n - 2))
        lo = rng.choice([1, n - 1 - size, rng.randint(1, n - 1 - size)])
        out += [lo, size]
    return out[0], out[2], out[1], out[3]


def border_region(rng: random.Random, d: int, rmax: int) -> tuple[int, int, int, int]:
    """A region of the whole decimated frame that reaches its border (an init rectangle's): the interior
    stream brings none of its border pixels, so each row is written from the first interior column."""
    wd, hd = dec_dims(d)
    out = []
    for n in (wd, hd):
        size = rng.randint(1, min(rmax, n))
        lo = rng.choice([0, 0, n - size, rng.randint(0, n - size)])
        out += [lo, size]
    return out[0], out[2], out[1], out[3]


def interior_words(bins: np.ndarray, ld: Load, lanes: int, stride: int) -> dict[tuple[int, int], int]:
    """``slot_words`` of the region, less the pixels on the frame's border (not in the interior stream)."""
    reg = ms_slot_capture(bins, ld.d, *ld.reg)
    ys, xs = np.mgrid[0: reg.shape[0], 0: reg.shape[1]]
    fx, fy = (ld.reg[0] + xs) * ld.d, (ld.reg[1] + ys) * ld.d
    inside = (fx >= 1) & (fx <= W - 2) & (fy >= 1) & (fy <= H - 2)
    return {(int(rx) % lanes, int(ry) * stride + int(rx) // lanes): int(reg[ry, rx])
            for ry, rx in zip(*np.nonzero(inside))}


def pixel_index(x: int, y: int) -> int:
    """Index of interior pixel (x, y) in the frame's stream."""
    return (y - 1) * (W - 2) + (x - 1)


class SlotTB:
    def __init__(self, dut):
        self.dut = dut
        self.g = dut_generics(DEFAULTS)
        self.lanes, self.stride = int(self.g["LANES"]), int(self.g["STRIDE"])
        self.data_w, self.rmax = int(self.g["DATA_W"]), int(self.g["REGION_MAX"])
        self.cycle = 0
        for s in ("rst", "frame_start", "frame_end", "frame_error", "ip_valid", "load", "load_now"):
            getattr(dut, s).value = Immediate(0)
        for s in ("ip_x", "ip_y", "ip_data", "dec_log2", "fx0", "fy0", "fx1", "fy1"):
            getattr(dut, s).value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
        self.writes: list[tuple[int, int, int, int]] = []   # (cycle, bank, word, data)
        self.released: list[int] = []
        self.lates: list[int] = []

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0

    async def monitor(self):
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            self.cycle += 1
            if int(d.we.value):
                self.writes.append((self.cycle, int(d.wbank.value), int(d.waddr.value), int(d.wdata.value)))
            if int(d.released.value):
                self.released.append(self.cycle)
            if int(d.late.value):
                self.lates.append(self.cycle)

    def set_load(self, ld: Load | None):
        d = self.dut
        d.load.value = int(ld is not None)
        if ld is not None:
            d.load_now.value = int(ld.now)
            d.dec_log2.value = ld.d.bit_length() - 1
            x, y, w, h = ld.reg              # the engine gives the region at full resolution
            d.fx0.value, d.fy0.value, d.fx1.value, d.fy1.value = x * ld.d, y * ld.d, (x + w) * ld.d, (y + h) * ld.d
        else:
            d.load_now.value = 0

    async def clock(self):
        await RisingEdge(self.dut.clk)
        return self.cycle      # the cycle of the edge just passed is counted by the monitor

    async def run_frame(self, fr: Frame, rng: random.Random, gap: float) -> None:
        d = self.dut
        n0w, n0r, n0l = len(self.writes), len(self.released), len(self.lates)
        pre = [ld for ld in fr.loads if ld.at == -1]
        at_start = [ld for ld in fr.loads if ld.at == -2]
        during = {ld.at: ld for ld in fr.loads if ld.at >= 0}
        for ld in pre:                               # between frames
            self.set_load(ld)
            await RisingEdge(d.clk)
            self.set_load(None)
            await RisingEdge(d.clk)
        d.frame_start.value = 1
        self.set_load(at_start[0] if at_start else None)
        await RisingEdge(d.clk)
        d.frame_start.value = 0
        self.set_load(None)
        await ClockCycles(d.clk, 2)
        first_row_cycle: dict[int, int] = {}       # ip row -> cycle of its first pixel's edge
        end_cycle = None
        end_with_last = rng.random() < 0.5           # frame_end in the last pixel's clock (as av_end comes)
        i = 0
        aborted = False
        for y in range(1, H - 1):
            for x in range(1, W - 1):
                while rng.random() < gap:            # a gap; a load due at pixel i may come in it
                    d.ip_valid.value = 0
                    self.set_load(during.pop(i, None) if rng.random() < 0.5 else None)
                    await RisingEdge(d.clk)
                    self.set_load(None)
                if fr.error_at is not None and i == fr.error_at:
                    d.ip_valid.value = 0
                    d.frame_error.value = 1
                    await RisingEdge(d.clk)
                    d.frame_error.value = 0
                    aborted = True
                    break
                d.ip_valid.value = 1
                d.ip_x.value, d.ip_y.value = x, y
                d.ip_data.value = int(fr.bins[y, x])
                self.set_load(during.pop(i, None))
                last_px = y == H - 2 and x == W - 2 and end_with_last
                d.frame_end.value = int(last_px)
                await RisingEdge(d.clk)
                first_row_cycle.setdefault(y, self.cycle + 1)
                if last_px:
                    end_cycle = self.cycle + 1
                    d.frame_end.value = 0
                self.set_load(None)
                i += 1
            if aborted:
                break
            d.ip_valid.value = 0
            n = rng.randint(0, 3)
            if n:
                await ClockCycles(d.clk, n)
        d.ip_valid.value = 0
        if not aborted and end_cycle is None:
            d.frame_end.value = 1
            await RisingEdge(d.clk)
            end_cycle = self.cycle + 1
            d.frame_end.value = 0
        assert not during, f"loads not driven: {during}"
        await ClockCycles(d.clk, 8)
        await ReadOnly()
        writes = self.writes[n0w:]
        rel = self.released[n0r:]
        lates = self.lates[n0l:]
        assert len(lates) == fr.late, f"late pulses {lates}, expected {fr.late}"
        got = {(b, a): v for _, b, a, v in writes}
        assert len(got) == len(writes), "a slot word written twice"
        if fr.expect is None:
            assert not writes, f"{len(writes)} writes in a frame with no capture armed"
            assert not rel, "released without a capture"
            return
        ld = fr.expect
        want = interior_words(fr.bins, ld, self.lanes, self.stride)
        if aborted:
            assert not rel, "released in an abandoned frame"
            assert set(got) <= set(want) and all(got[k] == want[k] for k in got), "abandoned frame: a wrong write"
            return
        assert got == want, (f"slot words of D {ld.d} region {ld.reg}: {len(got)} written, {len(want)} expected, "
                             f"{sum(got.get(k) != v for k, v in want.items())} differ")
        assert len(rel) == 1, f"released {len(rel)} times"
        assert not writes or rel[0] > max(c for c, *_ in writes), "released before the region's last write"
        rx, ry, rw, rh = ld.reg
        below = (ry + rh - 1) * ld.d + 1                  # the first ip row below the region
        bound = first_row_cycle[below] + 3 if below in first_row_cycle else end_cycle + 5
        assert rel[0] <= bound, f"released at {rel[0]}, after {bound}"
        # the capacity rule's release_line (input lines; ip row y streams in with input line y + 1)
        assert below + 1 <= release_line(ry, rh, ld.d, H) or below > H - 2


def scripted(rng: random.Random, nrng: np.random.Generator, data_w: int, rmax: int) -> list[Frame]:
    """The scenarios of the module docstring, in order (each frame's capture depends on the loads)."""
    def bins():
        return nrng.integers(0, 1 << data_w, size=(H, W))
    fr: list[Frame] = []
    a = Load(1, random_region(rng, 1, rmax))
    fr.append(Frame(bins(), [a], expect=a))                                   # load between frames
    fr.append(Frame(bins()))                                                  # no load: nothing
    b = Load(2, (1, 9, 13, 5), now=True)
    b.at = pixel_index(3, 2 * 9 - 1)                                          # the row above the first
    fr.append(Frame(bins(), [b], expect=b))
    c = Load(2, (2, 4, 6, 3), now=True, at=pixel_index(5, 8))                 # its first row (8) started
    fr.append(Frame(bins(), [c], late=1))
    e = Load(4, (3, 2, 5, 4))                                                 # full-resolution rows 8 .. 20
    fr.append(Frame(bins(), [e], error_at=pixel_index(4, 11), expect=e))      # abandoned mid-region
    fr.append(Frame(bins(), [e], expect=e))                                   # loaded again: captured
    r = Load(2, (1, 2, 6, 3))                                                 # rows 4 .. 8: released at row 9
    r_next = Load(8, random_region(rng, 8, rmax), at=pixel_index(1, 20))       # after the release, for the next
    fr.append(Frame(bins(), [r, r_next], expect=r))
    fr.append(Frame(bins(), [], expect=r_next))
    f1, f2 = Load(16, (1, 1, 1, 1)), Load(1, (1, 1, min(rmax, W - 2), min(rmax, H - 2)))
    fr.append(Frame(bins(), [f1, f2], expect=f2))                              # the second load replaces
    g = Load(1, (W - 2 - 7, H - 2 - 5, 7, 5), now=True, at=-2)                 # load_now with frame_start
    fr.append(Frame(bins(), [g], expect=g))
    g2 = Load(2, random_region(rng, 2, rmax), at=-2)                           # a load with frame_start
    fr.append(Frame(bins(), [g2], expect=g2))
    h = Load(4, (1, 1, 3, 2), now=True, at=0)                                 # first row 4: not late
    fr.append(Frame(bins(), [h], expect=h))
    return fr


def random_frames(rng: random.Random, nrng: np.random.Generator, data_w: int, rmax: int, n: int) -> list[Frame]:
    out = []
    for _ in range(n):
        d = rng.choice([1, 1, 2, 2, 4, 8, 16])
        ld = Load(d, border_region(rng, d, rmax) if rng.random() < 0.4 else random_region(rng, d, rmax))
        first = ld.reg[1] * d
        if rng.random() < 0.5 and first >= 2:         # load_now before the region's first row
            ld.now = True
            ld.at = pixel_index(rng.randint(1, W - 2), rng.randint(1, first - 1))
        out.append(Frame(nrng.integers(0, 1 << data_w, size=(H, W)), [ld], expect=ld))
    return out


@cocotb.test()
async def run_test(dut):
    tb = SlotTB(dut)
    await tb.reset()
    cocotb.start_soon(tb.monitor())
    await ClockCycles(dut.clk, 2)
    for gap, seed in ((0.0, 5), (0.3, 6)):
        rng, nrng = random.Random(seed), np.random.default_rng(seed)
        frames = scripted(rng, nrng, tb.data_w, tb.rmax) + random_frames(rng, nrng, tb.data_w, tb.rmax, 12)
        for k, fr in enumerate(frames):
            try:
                await tb.run_frame(fr, rng, gap)
            except AssertionError as exc:
                raise AssertionError(f"gap {gap}, frame {k}: {exc}") from exc
            await RisingEdge(dut.clk)
    dut._log.info("%d writes, %d releases, %d late", len(tb.writes), len(tb.released), len(tb.lates))


# ---------------------------------------------------------------- pytest entry points

from mstrack.hw import hdl  # noqa: E402

TOP = "ms_slot_capture"
MODULE = "test_ms_slot_capture"


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", [
    pytest.param(DEFAULTS, id="lanes4"),
    pytest.param({**DEFAULTS, "LANES": 2, "STRIDE": 12, "ADDR_W": 9, "DATA_W": 13}, id="lanes2_joint"),
])
def test_ms_slot_capture(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.ghdl
def test_ms_slot_capture_addr_w_refused():
    """A slot address too narrow for REGION_MAX rows of STRIDE words is refused at elaboration."""
    g = {**DEFAULTS, "LANES": 2, "STRIDE": 12}
    with pytest.raises(hdl.HdlError, match="ADDR_W too small"):
        hdl.run_ghdl_plain(TOP, hdl.rtl_sources(TOP), g, build_name="slot_capture_addr_w", stop_time="1ns")


@pytest.mark.verilator
def test_ms_slot_capture_verilator(hdl_waves):
    """The same bench on the GHDL -> Verilog netlist under Verilator (the synthesis path: the record
    descriptor, the variable shifts of the grid test and of the first / last rows)."""
    hdl.run_verilator(TOP, MODULE, DEFAULTS, hdl.rtl_sources(TOP), waves=hdl_waves)
