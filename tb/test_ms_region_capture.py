"""cocotb test bench + pytest entry points for rtl/ms_region_capture.vhd and
rtl/ms_region_ram.vhd, through the wrapper tb/ms_capture_tb_top.vhd
(ms_frontend -> ms_region_capture -> colour and edge ms_region_ram).

For each region a frame is streamed (full speed and with random valid gaps),
then the whole region is read back through the RAM read ports (all banks in
parallel, bank b of word j = region column j * LANES + b) and compared with
``ms_region_capture(frame, Region(...), tp)``.  Regions touch the interior
borders and have odd sizes; LANES 1, 2 and 4; PPC 1, 2 and 4 pixels per clock
(PPC <= LANES; with PPC > 1 the frame is 24 px wide and the capture writes the
PPC pixels of a beat into PPC banks through its per-bank write port).  A frame
abandoned by a protocol error must not raise ``done``.

Run: ``.venv/bin/python -m pytest tb/test_ms_region_capture.py``.
"""

from __future__ import annotations

import random

import numpy as np

import cocotb
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from mstrack.fixed.blocks import Region, ms_region_capture
from mstrack.track.params import TrackerParams

from test_ms_frontend import ERR_SHORT_LINE, TB, edge_frame, frame_beats, random_frame

DEFAULTS = {"LANES": 2, "COORD_W": 12, "MAX_FRAME_W": 64, "REGION_MAX": 13, "STRIDE": 7, "ADDR_W": 7,
            "COLOUR_BITS": 3, "EDGE_BINS_LOG2": 4, "EDGE_SHIFT": 5, "PPC": 1}


def regions(g: dict, w: int, h: int) -> list[Region]:
    """Regions inside the interior (columns 1 .. w-2, rows 1 .. h-2), touching its borders."""
    m = int(g["REGION_MAX"])
    boxes = [
        (1, 1, m, m),                      # top-left interior corner, largest
        (w - 1 - m, h - 1 - m, m, m),      # bottom-right interior corner
        (1, h - 1 - 5, m, 5),              # bottom border, full width
        (w - 1 - 3, 1, 3, m),              # right border, narrow
        (6, 4, 7, 3),                      # odd sizes
        (9, 7, 1, 1),                      # one pixel
    ]
    return [Region(x, y, rw, rh, lo=(x, y), hi=(x + rw - 1, y + rh - 1)) for x, y, rw, rh in boxes]


class CaptureTB(TB):
    def __init__(self, dut):
        super().__init__(dut, DEFAULTS)
        self.lanes = int(self.g["LANES"])
        self.addr_w = int(self.g["ADDR_W"])
        self.stride = int(self.g["STRIDE"])
        self.cw = 3 * int(self.g["COLOUR_BITS"])
        self.ew = int(self.g["EDGE_BINS_LOG2"])
        self.tp = TrackerParams(colour_bits=int(self.g["COLOUR_BITS"]),
                                edge_bins_log2=int(self.g["EDGE_BINS_LOG2"]),
                                edge_shift=int(self.g["EDGE_SHIFT"]))
        self.dones: list[int] = []
        dut.raddr.value = 0

    async def done_monitor(self):
        while True:
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            if int(self.dut.done.value):
                self.dones.append(self.cycle())

    def set_region(self, reg: Region):
        d = self.dut
        d.reg_x.value = reg.x
        d.reg_y.value = reg.y
        d.reg_w.value = reg.w
        d.reg_h.value = reg.h

    def word_addr(self, ry: int, j: int) -> int:
        return ry * self.stride + j

    async def read_word(self, addr: int) -> tuple[list[int], list[int]]:
        """All banks' (colour, edge) words at addr: present raddr, sample 1 clock later."""
        d = self.dut
        d.raddr.value = sum(addr << (b * self.addr_w) for b in range(self.lanes))
        await RisingEdge(d.clk)
        await ReadOnly()
        c, e = int(d.rdata_colour.value), int(d.rdata_edge.value)
        cm, em = (1 << self.cw) - 1, (1 << self.ew) - 1
        out = ([(c >> (b * self.cw)) & cm for b in range(self.lanes)],
               [(e >> (b * self.ew)) & em for b in range(self.lanes)])
        await RisingEdge(d.clk)
        return out

    async def capture(self, frame: np.ndarray, reg: Region, rng: random.Random, gap: float):
        d = self.dut
        self.set_region(reg)
        exp_c, exp_e = ms_region_capture(frame, reg, self.tp)
        # present the last region word's address during the frame: the read issued in the clock
        # in which done is high must already see the frame's last write
        last_j = (reg.w - 1) // self.lanes
        last_b = (reg.w - 1) % self.lanes
        d.raddr.value = sum(self.word_addr(reg.h - 1, last_j) << (b * self.addr_w) for b in range(self.lanes))
        n_done = len(self.dones)
        await self.drive(frame_beats(frame), rng, gap)
        for _ in range(40):
            await RisingEdge(d.clk)
            await ReadOnly()
            if len(self.dones) > n_done:
                break
        assert len(self.dones) == n_done + 1, "no done after a good frame"
        await RisingEdge(d.clk)          # raddr sampled in the done clock
        await ReadOnly()
        cm, em = (1 << self.cw) - 1, (1 << self.ew) - 1
        c_last = (int(d.rdata_colour.value) >> (last_b * self.cw)) & cm
        e_last = (int(d.rdata_edge.value) >> (last_b * self.ew)) & em
        assert (c_last, e_last) == (exp_c[-1, -1], exp_e[-1, -1]), "last write not visible at done"
        await RisingEdge(d.clk)
        got_c = np.zeros_like(exp_c)
        got_e = np.zeros_like(exp_e)
        for ry in range(reg.h):
            for j in range(-(-reg.w // self.lanes)):
                cw, ew = await self.read_word(self.word_addr(ry, j))
                for b in range(self.lanes):
                    rx = j * self.lanes + b
                    if rx < reg.w:
                        got_c[ry, rx], got_e[ry, rx] = cw[b], ew[b]
        assert np.array_equal(got_c, exp_c), f"colour region {reg}:\n{got_c}\n!=\n{exp_c}"
        assert np.array_equal(got_e, exp_e), f"edge region {reg}:\n{got_e}\n!=\n{exp_e}"


@cocotb.test()
@cocotb.parametrize(gap=[0.0, 0.3])
async def run_test(dut, gap):
    tb = CaptureTB(dut)
    await tb.reset()
    cocotb.start_soon(tb.monitor())
    cocotb.start_soon(tb.done_monitor())
    seed = 11 + int(gap * 100)
    nrng = np.random.default_rng(seed)
    rng = random.Random(seed)
    h, w = 17, (21 if tb.ppc == 1 else 24)
    for i, reg in enumerate(regions(tb.g, w, h)):
        frame = edge_frame(h, w) if i == 4 else random_frame(nrng, h, w)
        await tb.capture(frame, reg, rng, gap)
    # an abandoned frame (short line) must not raise done; the next good frame is captured exactly
    n_done = len(tb.dones)
    reg = regions(tb.g, w, h)[0]
    tb.set_region(reg)
    beats = frame_beats(random_frame(nrng, h, w))
    k = 15 * w + 4 + (-(4 + 1)) % tb.ppc        # the end of a beat
    beats = beats[:k] + [beats[k][:2] + (1,) + beats[k][3:]] + beats[k + 1:]
    await tb.drive(beats, rng, gap)
    await ClockCycles(dut.clk, 20)
    assert len(tb.dones) == n_done, "done raised for an abandoned frame"
    assert tb.events[-1][1] == ("error", ERR_SHORT_LINE), f"expected a short-line error, got {tb.events[-2:]}"
    await tb.capture(random_frame(nrng, h, w), regions(tb.g, w, h)[1], rng, gap)
    dut._log.info("LANES %d PPC %d: %d regions captured and read back, gap %.2f", tb.lanes, tb.ppc, len(tb.dones), gap)


# ---------------------------------------------------------------- pytest entry points

import pytest  # noqa: E402

from mstrack.hw import hdl  # noqa: E402
from mstrack.fixed.formats import FixedParams  # noqa: E402
from mstrack.fixed.vhdl_pkg import core_generics  # noqa: E402

TOP = "ms_capture_tb_top"
MODULE = "test_ms_region_capture"
WRAPPER = hdl.TB_DIR / "ms_capture_tb_top.vhd"


def cap_generics(lanes: int, ppc: int = 1, **tp_kw) -> dict:
    g = core_generics(TrackerParams(**tp_kw), FixedParams(max_half=4, margin=2), lanes=lanes)
    keys = ("LANES", "COORD_W", "REGION_MAX", "STRIDE", "ADDR_W", "COLOUR_BITS", "EDGE_BINS_LOG2", "EDGE_SHIFT")
    out = {k: g[k] for k in keys}
    out["MAX_FRAME_W"] = 64
    if ppc != 1:
        out["PPC"] = ppc
    return out


PARAMS = [
    pytest.param(cap_generics(2), id="ppc1-lanes2"),
    pytest.param(cap_generics(1), id="ppc1-lanes1"),
    pytest.param(cap_generics(4), id="ppc1-lanes4"),
    pytest.param(cap_generics(4, colour_bits=2, edge_bins_log2=3, edge_shift=3), id="ppc1-lanes4_cb2_e3"),
    pytest.param(cap_generics(2, ppc=2), id="ppc2-lanes2"),
    pytest.param(cap_generics(4, ppc=2), id="ppc2-lanes4"),
    pytest.param(cap_generics(4, ppc=4), id="ppc4-lanes4"),
]


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", PARAMS)
def test_ms_region_capture(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP, extra=[WRAPPER]), waves=hdl_waves)


@pytest.mark.ghdl
def test_ms_region_capture_ppc_gt_lanes():
    """PPC > LANES is refused at elaboration (generic assertion): two pixels of a beat, one bank."""
    g = {**cap_generics(2), "PPC": 4}
    with pytest.raises(hdl.HdlError, match="PPC > LANES is not supported"):
        hdl.run_ghdl_plain(TOP, hdl.rtl_sources(TOP, extra=[WRAPPER]), g, build_name="capture_ppc4_lanes2",
                           stop_time="1ns")
