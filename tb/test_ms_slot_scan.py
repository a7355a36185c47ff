"""cocotb test bench + pytest entry points for rtl/ms_slot_scan.vhd: every pixel of a rectangle captured in a
slot, one per clock in raster order, against :func:`mstrack.fixed.blocks_v2.ms_slot_scan`.

The bench top (tb/ms_slot_scan_tb_top.vhd) joins the block to an ms_region_ram, the RAM of a slot.  The
bench writes a rectangle into it in the slot layout (:func:`mstrack.fixed.blocks_v2.slot_words`), starts
a scan, and checks the stream:
* every pixel's coordinates and value, in raster order;
* one pixel per clock with no gap, `px_last` on the last pixel only;
* the first pixel RD_LAT + 2 clocks after `start`; `busy` until the clock after `px_last`;
* a `start` while busy is ignored.

Cases: random rectangles from 1 x 1 to the slot's full width (LANES x STRIDE), widths that are not a
multiple of LANES, scans back to back.  The scan of a real init rectangle into ms_bg_model is
tb/test_ms_init_job.py's.
Run: ``.venv/bin/python -m pytest tb/test_ms_slot_scan.py``.
"""
from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

from mstrack.fixed.blocks_v2 import ms_slot_scan, slot_words
from mstrack.hw import hdl
from mstrack.hw.hdl import dut_generics

TOP = "ms_slot_scan_tb_top"
MODULE = "test_ms_slot_scan"
TB_DIR = Path(__file__).resolve().parent
SMALL = {"LANES": 4, "STRIDE": 8, "ADDR_W": 8, "DATA_W": 13, "REGION_W": 6, "DEPTH": 256, "RD_LAT": 4}


class ScanTB:
    def __init__(self, dut):
        self.dut = dut
        self.g = dut_generics(SMALL)
        self.cycle = 0

    async def reset(self) -> None:
        d = self.dut
        for s in ("rst", "we", "wbank", "waddr", "wdata", "start", "rect_w", "rect_h"):
            getattr(d, s).value = 0
        cocotb.start_soon(Clock(d.clk, 10, unit="ns").start(start_high=False))
        cocotb.start_soon(self._count())
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        await FallingEdge(d.clk)

    async def _count(self) -> None:
        while True:
            await RisingEdge(self.dut.clk)
            self.cycle += 1

    async def fill(self, region: np.ndarray) -> None:
        """Write the rectangle into the slot through the RAM's write port (on falling edges)."""
        d = self.dut
        words = slot_words(region, int(self.g["LANES"]), int(self.g["STRIDE"]))
        for (bank, word), v in words.items():
            d.we.value = 1
            d.wbank.value = bank
            d.waddr.value = word
            d.wdata.value = v
            await FallingEdge(d.clk)
        d.we.value = 0

    async def scan(self, region: np.ndarray, name: str, poke_start: bool = True) -> list[tuple[int, int, int]]:
        """Start a scan of the rectangle's size and check the stream; returns it."""
        d, g = self.dut, self.g
        h, w = region.shape
        rd_lat = int(g["RD_LAT"])
        d.rect_w.value = w
        d.rect_h.value = h
        d.start.value = 1
        await FallingEdge(d.clk)                      # taken at this rising edge
        t0 = self.cycle
        d.start.value = 0
        got: list[tuple[int, int, int]] = []
        firsts, lasts, gaps = [], [], 0
        n = w * h
        busy_after_last = None
        while True:
            await FallingEdge(d.clk)                  # outputs of the rising edge before
            if poke_start and len(got) == n // 2:     # a start while busy: ignored
                d.rect_w.value = max(1, w - 1)
                d.start.value = 1
            else:
                d.start.value = 0
            if int(d.px_valid.value):
                if not got:
                    firsts.append(self.cycle - t0)
                got.append((int(d.px_x.value), int(d.px_y.value), int(d.px_data.value)))
                if int(d.px_last.value):
                    lasts.append(len(got))
            elif got and len(got) < n:
                gaps += 1
            if busy_after_last is not None:
                busy_after_last = int(d.busy.value)
                break
            if len(got) == n and lasts:
                busy_after_last = -1                  # look at busy once more, a clock later
            assert self.cycle - t0 < n + 50, f"{name}: {len(got)} of {n} pixels after {self.cycle - t0} clocks"
        d.start.value = 0
        want = ms_slot_scan(region)
        assert gaps == 0, f"{name}: {gaps} clocks without a pixel inside the scan"
        assert firsts == [rd_lat + 2], f"{name}: first pixel {firsts} clocks after start, header says {rd_lat + 2}"
        assert lasts == [n], f"{name}: px_last with pixels {lasts}, expected only the last ({n})"
        bad = [i for i, (a, b) in enumerate(zip(got, want)) if a != b]
        assert len(got) == n and not bad, f"{name}: {len(bad)} pixels differ, first {[(got[i], want[i]) for i in bad[:3]]}"
        assert busy_after_last == 0, f"{name}: busy still high the clock after px_last"
        # nothing more comes
        for _ in range(rd_lat + 4):
            await FallingEdge(d.clk)
            assert not int(d.px_valid.value), f"{name}: a pixel after the scan (the ignored start ran)"
        d._log.info("%s: %d x %d, %d pixels, first after %d clocks", name, w, h, n, firsts[0])
        return got


def _cases(g: dict, rng: random.Random) -> list[tuple[str, np.ndarray]]:
    lanes, stride = int(g["LANES"]), int(g["STRIDE"])
    hmax = min(int(g["DEPTH"]) // stride, (1 << int(g["REGION_W"])) - 1)
    wmax = min(lanes * stride, (1 << int(g["REGION_W"])) - 1)
    top = 1 << int(g["DATA_W"])

    def img(h, w):
        return np.array([[rng.randrange(top) for _ in range(w)] for _ in range(h)], np.int64)

    out = [("one_pixel", img(1, 1)), ("one_row", img(1, wmax)), ("one_column", img(hmax, 1)),
           ("full_slot", img(hmax, wmax))]
    for w in (2, 3, 5, lanes, lanes + 1, 2 * lanes - 1):
        out.append((f"width_{w}", img(rng.randrange(2, 6), w)))
    for i in range(6):
        out.append((f"random_{i}", img(rng.randrange(1, hmax + 1), rng.randrange(1, wmax + 1))))
    return out


@cocotb.test()
async def slot_scan_cases(dut):
    tb = ScanTB(dut)
    await tb.reset()
    rng = random.Random(7)
    for i, (name, region) in enumerate(_cases(tb.g, rng)):
        await tb.fill(region)
        await tb.scan(region, name, poke_start=i % 2 == 0)
    # back to back: the next start in the clock busy falls
    region = _cases(tb.g, random.Random(8))[-1][1]
    await tb.fill(region)
    await tb.scan(region, "back_to_back_a", poke_start=False)
    await tb.scan(region, "back_to_back_b", poke_start=False)


# ----------------------------------------------------------------------------- pytest side
def _sources() -> list:
    return hdl.rtl_sources(TOP, extra=[TB_DIR / "ms_slot_scan_tb_top.vhd"])


@pytest.mark.ghdl
def test_ms_slot_scan(hdl_waves):
    hdl.run_ghdl(TOP, MODULE, SMALL, _sources(), waves=hdl_waves, test_filter="slot_scan_cases",
                 build_name="ghdl_ms_slot_scan_small")


@pytest.mark.verilator
def test_ms_slot_scan_verilator(hdl_waves):
    hdl.run_verilator(TOP, MODULE, SMALL, _sources(), waves=hdl_waves, test_filter="slot_scan_cases",
                      build_name="verilator_ms_slot_scan_small")
