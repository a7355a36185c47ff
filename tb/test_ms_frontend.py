"""cocotb test bench + pytest entry points for rtl/ms_frontend.vhd
(ms_stream_check -> ms_colour_bin | ms_grey -> ms_sobel).

Frames are streamed beat by beat (in_valid/in_data/in_sof/in_eol), PPC pixels
per beat (generic PPC = 1, 2, 4: pixel k in bits 24k+23 .. 24k, in_sof on the
frame's first beat, in_eol on the line's last beat), at full speed and with
random valid gaps.  Every interior pixel's (x, y, cbin, ebin, obin) is
compared exactly with the fixed model (``ms_colour_bin``,
``ms_edge_bin(ms_sobel(ms_grey(frame)))`` and tracker v2's orientation bin
``ms_orient_bin(ms_grey(frame), ORIENT_T)``); the frame events and error codes
are checked against the expected sequence; with PPC = 1 the all-pixel stream delayed to the frame events, ``ad_*``, too: every
pixel's (x, y, cbin) of a good frame, in order, after its ``frame_start`` (an earlier clock) and up to
its ``ad_end`` (the same clock), a prefix of them up to ``frame_error``, none outside a frame; protocol errors (short line, long
line, missing sof, cut frame, frame size, and with PPC > 1 a width that is not a
multiple of PPC) are each followed by a good frame that must be processed exactly.

Run: ``.venv/bin/python -m pytest tb/test_ms_frontend.py`` (``--waves`` for waves).
"""

from __future__ import annotations

import os
import random

import numpy as np

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time

from mstrack.fixed.blocks import ms_colour_bin, ms_edge_bin, ms_grey, ms_sobel
from mstrack.fixed.blocks_v2 import ms_orient_bin
from mstrack.hw.hdl import dut_generics

CLK_NS = 10
DEFAULTS = {"COORD_W": 12, "MAX_FRAME_W": 64, "COLOUR_BITS": 3, "EDGE_BINS_LOG2": 4, "EDGE_SHIFT": 5,
            "ORIENT_T": 64, "PPC": 1}
# error codes of rtl/ms_stream_pkg.vhd
ERR_SHORT_LINE, ERR_LONG_LINE, ERR_NO_SOF, ERR_CUT, ERR_SIZE = 0, 1, 2, 3, 4
#: input beat (last one accepted in clock c) -> frame_end high in clock c + FRAME_END_LAT
FRAME_END_LAT = 9


# ---------------------------------------------------------------- frames and model

def random_frame(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    return rng.integers(0, 256, size=(h, w, 3), dtype=np.uint8)


def grey_frame(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    g = rng.integers(0, 256, size=(h, w, 1), dtype=np.uint8)
    return np.repeat(g, 3, axis=2)


def edge_frame(h: int, w: int) -> np.ndarray:
    """Black/white checkerboard of 1 px with white stripes: |G| up to 2040 (bins saturate)."""
    yy, xx = np.mgrid[0:h, 0:w]
    on = ((xx + yy) % 2 == 0) | (xx % 5 == 0)
    f = np.where(on[..., None], 255, 0).astype(np.uint8)
    return np.repeat(f, 3, axis=2)


def pixel_word(frame: np.ndarray, y: int, x: int) -> int:
    """24-bit RGB word (R 23:16, G 15:8, B 7:0) of a BGR frame pixel."""
    b, g, r = (int(v) for v in frame[y, x])
    return (r << 16) | (g << 8) | b


def frame_beats(frame: np.ndarray, sof: bool = True) -> list[tuple[int, int, int, int, int]]:
    """(data, sof, eol, W, H) of every pixel in raster order."""
    h, w = frame.shape[:2]
    return [(pixel_word(frame, y, x), int(sof and x == 0 and y == 0), int(x == w - 1), w, h)
            for y in range(h) for x in range(w)]


def pack_beats(beats, ppc: int) -> list[tuple[int, int, int, int, int]]:
    """Pixel beats (frame_beats) -> beats of ppc pixels: pixel k of a beat in bits 24k+23 .. 24k,
    sof of the beat's first pixel, eol if one of its pixels has eol (a beat closes at ppc pixels
    or at an eol; a short last beat is padded with zero pixels)."""
    if ppc == 1:
        return list(beats)
    out, cur = [], []

    def close():
        data = sum(p[0] << (24 * k) for k, p in enumerate(cur))
        out.append((data, cur[0][1], int(any(p[2] for p in cur)), cur[0][3], cur[0][4]))
        cur.clear()

    for b in beats:
        cur.append(b)
        if len(cur) == ppc or b[2]:
            close()
    if cur:
        close()
    return out


def model_interior(frame: np.ndarray, g: dict) -> list[tuple[int, int, int, int, int]]:
    """(x, y, cbin, ebin, obin) of every interior pixel in raster order, from the fixed model."""
    cb = ms_colour_bin(frame, int(g["COLOUR_BITS"]))[1:-1, 1:-1]
    eb = ms_edge_bin(ms_sobel(ms_grey(frame)), 1 << int(g["EDGE_BINS_LOG2"]), int(g["EDGE_SHIFT"]))
    ob = ms_orient_bin(ms_grey(frame), int(g["ORIENT_T"]))[1:-1, 1:-1]
    h, w = cb.shape
    return [(x + 1, y + 1, int(cb[y, x]), int(eb[y, x]), int(ob[y, x])) for y in range(h) for x in range(w)]


# ---------------------------------------------------------------- TB

class TB:
    def __init__(self, dut, defaults=DEFAULTS):
        self.dut = dut
        self.g = dut_generics(defaults)
        dut.rst.value = Immediate(1)
        dut.in_valid.value = Immediate(0)
        cocotb.start_soon(Clock(dut.clk, CLK_NS, unit="ns").start(start_high=False))
        self.ppc = int(self.g.get("PPC", 1))
        self.ips: list[tuple[int, tuple]] = []       # (cycle, (x, y, cbin, ebin, obin)), one per pixel
        self.events: list[tuple[int, tuple]] = []    # (cycle, ("start",) | ("end",) | ("error", code))
        self.ads: list[tuple[int, tuple]] = []       # (cycle, (x, y, cbin)) of the delayed all-pixel stream
        self.ad_ends: list[int] = []                 # cycles of ad_end
        self.last_beat_cycle = -1

    @staticmethod
    def cycle() -> int:
        return int(get_sim_time("ns")) // CLK_NS

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)

    async def monitor(self):
        d = self.dut
        has_code = hasattr(d, "err_code")
        has_ip = hasattr(d, "ip_valid") and (self.ppc == 1 or hasattr(d, "ip_mask"))
        has_ob = hasattr(d, "ip_obin")   # (wrappers of other benches may not expose it: None then)
        has_ad = self.ppc == 1 and hasattr(d, "ad_end")
        while True:
            await RisingEdge(d.clk)
            await ReadOnly()
            c = self.cycle()
            if has_ad:
                if int(d.ad_end.value):
                    self.ad_ends.append(c)
                if int(d.ad_valid.value):
                    self.ads.append((c, (int(d.ad_x.value), int(d.ad_y.value), int(d.ad_cbin.value))))
            if int(d.frame_error.value):
                self.events.append((c, ("error", int(d.err_code.value) if has_code else -1)))
            if int(d.frame_start.value):
                self.events.append((c, ("start",)))
            if int(d.frame_end.value):
                self.events.append((c, ("end",)))
            if has_ip and int(d.ip_valid.value):
                if self.ppc == 1:
                    self.ips.append((c, (int(d.ip_x.value), int(d.ip_y.value), int(d.ip_cbin.value),
                                         int(d.ip_ebin.value), int(d.ip_obin.value) if has_ob else None)))
                    continue
                # lanes: column ip_x + k where ip_mask(k) (ip_x wraps on a line's first beat)
                mask, x0, y = int(d.ip_mask.value), int(d.ip_x.value), int(d.ip_y.value)
                cb, eb = int(d.ip_cbin.value), int(d.ip_ebin.value)
                ob = int(d.ip_obin.value) if has_ob else None
                cw, ew = 3 * int(self.g["COLOUR_BITS"]), int(self.g["EDGE_BINS_LOG2"])
                xm = (1 << int(self.g["COORD_W"])) - 1
                for k in range(self.ppc):
                    if mask >> k & 1:
                        self.ips.append((c, ((x0 + k) & xm, y, (cb >> (k * cw)) & ((1 << cw) - 1),
                                             (eb >> (k * ew)) & ((1 << ew) - 1),
                                             None if ob is None else (ob >> (4 * k)) & 15)))

    async def drive(self, beats, rng: random.Random, gap: float):
        """Drive pixel beats (frame_beats), packed PPC pixels per beat."""
        d = self.dut
        for data, sof, eol, w, h in pack_beats(beats, self.ppc):
            while gap and rng.random() < gap:
                d.in_valid.value = 0
                d.in_data.value = rng.getrandbits(24 * self.ppc)  # garbage while not valid
                d.in_sof.value = rng.getrandbits(1)
                d.in_eol.value = rng.getrandbits(1)
                await RisingEdge(d.clk)
            d.in_valid.value = 1
            d.in_data.value = data
            d.in_sof.value = sof
            d.in_eol.value = eol
            d.frame_width.value = w
            d.frame_height.value = h
            self.last_beat_cycle = self.cycle()
            await RisingEdge(d.clk)
        d.in_valid.value = 0


def scenario(g: dict, seed: int):
    """Segments (beats, expected events, expected interior pixels, exact?) of one run.

    PPC = 1: the original scenario.  PPC > 1: the frame widths are multiples of 4 (23 -> 24) and
    every fault sits at the end of a beat (a short line ends on a full beat, a long line has
    whole extra beats); plus a frame whose width is not a multiple of PPC (ERR_SIZE)."""
    rng = np.random.default_rng(seed)
    segs = []
    ppc = int(g.get("PPC", 1))
    W = 23 if ppc == 1 else 24                    # the usual frame width

    def al(i):
        """Pixel index i moved up to the last pixel of its beat (a beat boundary after it)."""
        return i + (-(i + 1)) % ppc

    def good(frame):
        segs.append((frame_beats(frame), [("start",), ("end",)], model_interior(frame, g), True))

    def bad(beats, events, frame):
        segs.append((beats, events, model_interior(frame, g), False))

    good(random_frame(rng, 11, W))
    good(random_frame(rng, 17, 40))
    good(grey_frame(rng, 11, W))
    good(edge_frame(9, 16))
    # short line: row 4 ends (eol) at x = 9 (PPC > 1: at the end of that pixel's beat); the rest
    # of the frame is dropped
    f = random_frame(rng, 11, W)
    b = frame_beats(f)
    k = 4 * W + al(9)
    b = b[:k] + [b[k][:2] + (1,) + b[k][3:]] + b[5 * W:]
    bad(b, [("start",), ("error", ERR_SHORT_LINE)], f)
    good(random_frame(rng, 11, W))
    # long line: row 3 has 3 extra pixels (PPC > 1: one extra beat; eol on the last one)
    f = random_frame(rng, 11, W)
    b = frame_beats(f)
    row3 = [(p[0], 0, 0, W, 11) for p in b[3 * W:4 * W]]
    extra = [(0x123456, 0, 0, W, 11), (0x654321, 0, 0, W, 11), (0xABCDEF, 0, 0, W, 11)][:al(2) + 1]
    extra += [(0x0F0F0F, 0, 0, W, 11)] * (al(2) + 1 - len(extra))
    extra[-1] = extra[-1][:2] + (1,) + extra[-1][3:]
    b = b[:3 * W] + row3 + extra + b[4 * W:]
    bad(b, [("start",), ("error", ERR_LONG_LINE)], f)
    good(random_frame(rng, 17, 40))
    # missing sof: a whole frame without sof (reported once), then a good frame
    f = random_frame(rng, 5, W)
    segs.append((frame_beats(f, sof=False), [("error", ERR_NO_SOF)], [], True))
    good(random_frame(rng, 11, W))
    # cut: a new frame (sof) after 5 rows and 3 pixels (PPC > 1: the beat of pixel 2)
    f = random_frame(rng, 11, W)
    bad(frame_beats(f)[:5 * W + al(2) + 1], [("start",)], f)
    f2 = random_frame(rng, 11, W)
    segs.append((frame_beats(f2), [("error", ERR_CUT), ("start",), ("end",)], model_interior(f2, g), True))
    good(edge_frame(9, 16))
    # frame size out of range at the sof (W > MAX_FRAME_W, W < 3, H < 3): one ERR_SIZE, no frame
    mw = int(g["MAX_FRAME_W"])
    for h, w in [(4, mw + 1), (5, 2), (2, W)]:
        segs.append((frame_beats(random_frame(rng, h, w)), [("error", ERR_SIZE)], [], True))
        good(random_frame(rng, 11, W))
    # a frame cut by a sof of a bad size: one ERR_SIZE (no ERR_CUT), then a good frame
    f = random_frame(rng, 11, W)
    bad(frame_beats(f)[:4 * W + al(5) + 1], [("start",)], f)
    segs.append((frame_beats(random_frame(rng, 6, 1)), [("error", ERR_SIZE)], [], True))
    good(random_frame(rng, 11, W))
    if ppc > 1:
        # a frame width that is not a multiple of PPC (rows padded to whole beats): ERR_SIZE,
        # the frame is dropped; the next good frame is processed exactly
        for wbad in (W - 1, W - ppc // 2, 2 * ppc + 1):
            segs.append((frame_beats(random_frame(rng, 7, wbad)), [("error", ERR_SIZE)], [], True))
            good(random_frame(rng, 11, W))
        # ... also when it cuts a frame in progress (one ERR_SIZE, no ERR_CUT)
        f = random_frame(rng, 11, W)
        bad(frame_beats(f)[:3 * W + al(4) + 1], [("start",)], f)
        segs.append((frame_beats(random_frame(rng, 5, W + 1)), [("error", ERR_SIZE)], [], True))
        good(random_frame(rng, 11, 40))
    return segs


async def run_scenario(tb: TB, gap: float, seed: int):
    g = tb.g
    await tb.reset()
    mon = cocotb.start_soon(tb.monitor())
    segs = scenario(g, seed)
    rng = random.Random(seed)
    for beats, _, _, _ in segs:
        await tb.drive(beats, rng, gap)
    await ClockCycles(tb.dut.clk, 20)
    mon.cancel()
    # events
    exp_events = [e for _, evs, _, _ in segs for e in evs]
    got_events = [e for _, e in tb.events]
    assert got_events == exp_events, f"events {got_events} != {exp_events}"
    # interior pixels grouped by frame: a frame is open from its start event to its end/error
    timeline = sorted([(c, 0, e) for c, e in tb.events] + [(c, 1, px) for c, px in tb.ips],
                      key=lambda t: (t[0], t[1]))
    frames: list[list] = []
    orphans = []
    is_open = False
    for c, kind, item in timeline:
        if kind == 0:
            if item == ("start",):
                frames.append([])
                is_open = True
            elif item != ("error", ERR_NO_SOF):
                is_open = False
        elif is_open:
            frames[-1].append(item)
        else:
            orphans.append((c, item))
    assert not orphans, f"interior pixels outside a frame: {orphans[:5]}"
    exp_frames = [(exp, exact) for _, evs, exp, exact in segs if ("start",) in evs]
    assert len(frames) == len(exp_frames)
    for i, (got, (exp, exact)) in enumerate(zip(frames, exp_frames)):
        if exact:
            if got != exp:
                bad = next(j for j in range(min(len(got), len(exp)) + 1)
                           if j >= len(got) or j >= len(exp) or got[j] != exp[j])
                raise AssertionError(f"frame {i}: {len(got)} interior pixels vs {len(exp)}; first "
                                     f"difference at #{bad}: got {got[bad:bad + 3]} exp {exp[bad:bad + 3]}")
        else:
            assert got == exp[:len(got)], f"abandoned frame {i}: pixels are not a prefix of the model's"
    if tb.ads or tb.ad_ends:
        check_ad(tb, segs)
    tb.dut._log.info("%d frames, %d interior pixels, %d all-stream pixels checked, gap %.2f", len(exp_frames),
                     len(tb.ips), len(tb.ads), gap)


def check_ad(tb: TB, segs) -> None:
    """The delayed all-pixel stream against frame_start, ad_end and frame_error, as a capture on it
    (ms_slot_capture) takes them: in one clock a pixel first, then ad_end, frame_error, frame_start (a
    frame's pixels come in the clocks after its frame_start, up to its ad_end or frame_error; a missing
    sof's frame_error may share the clock of the good frame's ad_end before it, which still ends it)."""
    cb_bits = int(tb.g["COLOUR_BITS"])
    evs = [(c, 3, "start") for c, e in tb.events if e == ("start",)]
    evs += [(c, 2, "error") for c, e in tb.events if e[0] == "error"]
    evs += [(c, 1, "end") for c in tb.ad_ends]
    timeline = sorted(evs + [(c, 0, px) for c, px in tb.ads], key=lambda t: (t[0], t[1]))
    frames: list[tuple[list, str | None]] = []
    orphans = []
    is_open = False
    for c, kind, item in timeline:
        if kind == 3:
            frames.append(([], None))
            is_open = True
        elif kind in (1, 2):
            if is_open:
                frames[-1] = (frames[-1][0], item)
            is_open = False
        elif is_open:
            frames[-1][0].append(item)
        else:
            orphans.append((c, item))
    assert not orphans, f"ad pixels outside a frame: {orphans[:5]}"
    exp = [(beats, evs) for beats, evs, _, _ in segs if ("start",) in evs]
    assert len(frames) == len(exp), f"{len(frames)} ad frames, {len(exp)} expected"
    for i, ((got, closed), (beats, evs)) in enumerate(zip(frames, exp)):
        w, h = beats[0][3], beats[0][4]
        want = []
        for k, (data, *_rest) in enumerate(beats[:w * h]):
            r, g_, b = (data >> 16) & 255, (data >> 8) & 255, data & 255
            s_ = 8 - cb_bits
            want.append((k % w, k // w, ((r >> s_) << (2 * cb_bits)) | ((g_ >> s_) << cb_bits) | (b >> s_)))
        if evs[-1] == ("end",):
            assert closed == "end", f"ad frame {i}: closed by {closed}"
            assert got == want, f"ad frame {i}: {len(got)} pixels vs {len(want)}"
        else:
            assert closed in ("error", None), f"ad frame {i}: closed by {closed}"
            assert got == want[:len(got)], f"abandoned ad frame {i}: not a prefix of the frame's pixels"


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def run_test(dut, gap):
    """Good and bad frames, full speed (gap 0) and throttled (30 % idle clocks)."""
    tb = TB(dut)
    await run_scenario(tb, gap, seed=int(gap * 100) + 7)


@cocotb.test()
async def latency(dut):
    """Full speed: one pixel per clock; last beat -> last ip_valid -> frame_end latencies."""
    tb = TB(dut)
    await tb.reset()
    mon = cocotb.start_soon(tb.monitor())
    f = random_frame(np.random.default_rng(3), 12, 30 if tb.ppc == 1 else 32)
    beats = frame_beats(f)
    first = tb.cycle()
    await tb.drive(beats, random.Random(0), 0.0)
    last = tb.last_beat_cycle
    assert last - first == len(beats) // tb.ppc - 1, "driver not at one beat per clock"
    await ClockCycles(dut.clk, 20)
    mon.cancel()
    end = [c for c, e in tb.events if e == ("end",)]
    assert len(end) == 1
    last_ip = tb.ips[-1][0]
    assert [p for _, p in tb.ips] == model_interior(f, tb.g)
    dut._log.info("LATENCY last beat (clock %d) -> last ip_valid +%d, frame_end +%d", last, last_ip - last,
                  end[0] - last)
    assert end[0] - last == FRAME_END_LAT, f"frame_end latency {end[0] - last} != {FRAME_END_LAT}"
    assert end[0] == last_ip + 1, "frame_end must come 1 clock after the last interior pixel"
    if tb.ads:
        # the delayed all-pixel stream: its last pixel and ad_end 1 clock after frame_end
        assert tb.ad_ends == [end[0] + 1] and tb.ads[-1][0] == end[0] + 1, "ad_end not with the last ad pixel"
        first_start = next(c for c, e in tb.events if e == ("start",))
        assert tb.ads[0][0] == first_start + 1, "the first ad pixel must come 1 clock after frame_start"
    # throughput: interior pixels come out at PPC per clock within a line (the first beat of a
    # line carries PPC - 2 of them, the next ones PPC each)
    cyc = sorted({c for c, _ in tb.ips[:f.shape[1] - 2]})
    assert cyc == list(range(cyc[0], cyc[0] + len(cyc))), "interior beats not at 1 per clock"
    # interior column c (lane k of the beat at x = c + 1 - k) leaves with the beat (c + 1) // PPC
    assert len(cyc) == len({(c + 1) // tb.ppc for c in range(1, f.shape[1] - 1)}), \
        f"{len(cyc)} clocks for a line of {f.shape[1] - 2} interior pixels at PPC {tb.ppc}"


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402
from mstrack.track.params import TrackerParams  # noqa: E402

TOP = "ms_frontend"
MODULE = "test_ms_frontend"


def fe_generics(max_frame_w: int = 64, ppc: int = 1, orient_t: int | None = None, **tp_kw) -> dict:
    """ms_frontend generics from the model parameters (core_generics); ORIENT_T only when given."""
    g = core_generics(TrackerParams(**tp_kw), FixedParams(max_half=4, margin=2), lanes=2)
    out = {k: g[k] for k in ("COORD_W", "COLOUR_BITS", "EDGE_BINS_LOG2", "EDGE_SHIFT")}
    out["MAX_FRAME_W"] = max_frame_w
    if orient_t is not None:
        out["ORIENT_T"] = orient_t
    if ppc != 1:
        out["PPC"] = ppc
    return out


PARAMS = [
    pytest.param(fe_generics(), id="ppc1-default"),
    pytest.param(fe_generics(max_frame_w=40), id="ppc1-maxw40"),
    pytest.param(fe_generics(colour_bits=2, edge_bins_log2=3, edge_shift=2), id="ppc1-cb2_e3_s2"),
    pytest.param(fe_generics(colour_bits=8, edge_bins_log2=8, edge_shift=0), id="ppc1-cb8_e8_s0"),
    # orientation threshold at its ends: 0 (every interior pixel has an octant), 2040 (the edge
    # frame's saturating pixels only), 2047 (none: always flat), and a middle value
    pytest.param(fe_generics(orient_t=0), id="ppc1-orient0"),
    pytest.param(fe_generics(orient_t=2040, ppc=2), id="ppc2-orient2040"),
    pytest.param(fe_generics(orient_t=2047), id="ppc1-orient2047"),
    pytest.param(fe_generics(orient_t=200, ppc=4), id="ppc4-orient200"),
    pytest.param(fe_generics(ppc=2), id="ppc2-default"),
    pytest.param(fe_generics(ppc=4), id="ppc4-default"),
    pytest.param(fe_generics(ppc=4, max_frame_w=40, colour_bits=2, edge_bins_log2=3, edge_shift=2),
                 id="ppc4-maxw40_cb2_e3_s2"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_frontend(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)
