"""cocotb test bench + pytest entry points for rtl/ms_result_order.vhd: the shared-engine core's
result words in ascending target id, whatever order the jobs end in.

Each frame writes the words of its live targets in a random order (some ids twice: the later word
counts; some ids outside the frame's mask), closes with the mask, and the next frame's words are
written while the previous frame's leave; the sink takes words with random back-pressure.  The bench
checks every word, value by value: the ids of each frame in ascending order
(``mstrack.hw.cosim_multi.CoreModelMulti``'s order), each with the last word written for it in that
frame, ``m_last`` on the frame's last word only; ``missing`` pulses exactly for a mask id that had no
word; a close waits (``close_ready``) while a frame's words are still to be read from their bank (a
slow sink for six frames makes it wait).  A last frame of all ids (id 0's word in the close clock),
closed when everything has left, into a sink that is always ready: its first word is on ``m_data``
FIRST_LAT clocks after the close edge, the others follow one per clock.

Run: ``.venv/bin/python -m pytest tb/test_ms_result_order.py``.
"""
from __future__ import annotations

import random

import pytest

import cocotb
from cocotb.clock import Clock
from cocotb.handle import Immediate
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from mstrack.fixed.vhdl_pkg import TARGET_ID_W
from mstrack.hw.hdl import dut_generics

DEFAULTS = {"N_SLOTS": 5, "WORD_W": 160}
#: edges after the close edge until the first word is on m_data (rtl/ms_result_order.vhd, Latency:
#: RD_LAT + 3 with the store's RD_LAT 2)
FIRST_LAT = 5


@cocotb.test()
async def run_test(dut):
    g = dut_generics(DEFAULTS)
    n, ww = int(g["N_SLOTS"]), int(g["WORD_W"])
    assert TARGET_ID_W == 4
    for s in ("rst", "s_valid", "close", "m_ready"):
        getattr(dut, s).value = Immediate(0)
    for s in ("s_id", "s_word", "close_mask"):
        getattr(dut, s).value = Immediate(0)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start(start_high=False))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    rng = random.Random(n)
    got: list[tuple[int, int | None, int]] = []   # (id, word: None when undefined, last)
    missing = [0]
    stop = [False]
    p_ready = [0.7]                                            # the sink's readiness
    waits = 0                                                  # clocks a close waited for close_ready

    fe = [0]                                                   # falling edges so far
    got_at: list[int] = []                                     # the falling edge of each word taken

    async def sink():
        # decide m_ready mid-cycle; a word moves at the next rising edge when m_valid and m_ready
        while not stop[0]:
            await FallingEdge(dut.clk)
            fe[0] += 1
            dut.m_ready.value = int(rng.random() < p_ready[0])
            await ReadOnly()
            if int(dut.m_valid.value) and int(dut.m_ready.value):
                bits = str(dut.m_data.value)          # a missing id's entry may never have been written
                word = int(bits[4:], 2) if set(bits[4:]) <= {"0", "1"} else None
                got.append((int(bits[:4], 2), word, int(dut.m_last.value)))
                got_at.append(fe[0])
            missing[0] += int(dut.missing.value)

    cocotb.start_soon(sink())
    want: list[tuple[int, int | None, int]] = []             # (id, word or None: no word written, last)
    want_missing = 0
    for f in range(40):
        p_ready[0] = 0.05 if 10 <= f < 16 else 0.7              # a slow sink: closes must wait
        mask = [i for i in range(n) if rng.random() < 0.6]
        if f == 3:
            mask = []                                            # nothing to send
        words: dict[int, int] = {}
        order = mask + [rng.randrange(n) for _ in range(2)]      # repeats and ids outside the mask
        rng.shuffle(order)
        skip = rng.choice(mask) if mask and f % 7 == 5 else None  # a mask id without a word
        for i in order:
            if i == skip:
                continue
            w = rng.getrandbits(ww)
            words[i] = w
            dut.s_valid.value, dut.s_id.value, dut.s_word.value = 1, i, w
            await RisingEdge(dut.clk)
            dut.s_valid.value = 0
            for _ in range(rng.randint(0, 2)):
                await RisingEdge(dut.clk)
        for _ in range(2000):                                    # close when the bank is free
            await ReadOnly()
            ready = int(dut.close_ready.value)
            await RisingEdge(dut.clk)
            if ready:
                break
            waits += 1
        else:
            raise AssertionError(f"frame {f}: close_ready stayed low for 2000 clocks")
        dut.close.value, dut.close_mask.value = 1, sum(1 << i for i in mask)
        await RisingEdge(dut.clk)
        dut.close.value = 0
        want += [(i, words.get(i), int(j == len(mask) - 1)) for j, i in enumerate(sorted(mask))]
        want_missing += skip is not None
    for _ in range(2000):
        await RisingEdge(dut.clk)
        if len(got) >= len(want):
            break
    # latency and throughput: every id, closed when all has left, into a sink that is always ready
    p_ready[0] = 1.0
    words = {i: rng.getrandbits(ww) for i in range(n)}
    for i in reversed(range(1, n)):
        dut.s_valid.value, dut.s_id.value, dut.s_word.value = 1, i, words[i]
        await RisingEdge(dut.clk)
    dut.s_valid.value = 0
    await ReadOnly()
    assert int(dut.close_ready.value) and not int(dut.m_valid.value)
    await RisingEdge(dut.clk)
    # id 0's word in the close clock: it belongs to the closed frame
    dut.s_valid.value, dut.s_id.value, dut.s_word.value = 1, 0, words[0]
    dut.close.value, dut.close_mask.value = 1, (1 << n) - 1
    await RisingEdge(dut.clk)                                    # the close edge
    close_fe = fe[0]                                             # its cycle's falling edge comes next
    dut.close.value = dut.s_valid.value = 0
    first = len(got)
    want += [(i, words[i], int(i == n - 1)) for i in range(n)]
    for _ in range(FIRST_LAT + n + 4):
        await RisingEdge(dut.clk)
    await ClockCycles(dut.clk, 4)
    stop[0] = True
    assert len(got) == len(want), f"{len(got)} words sent, {len(want)} expected"
    for k, ((gi, gw, gl), (wi, ww_, wl)) in enumerate(zip(got, want)):
        assert (gi, gl) == (wi, wl), f"word {k}: id {gi} last {gl}, expected id {wi} last {wl}"
        assert ww_ is None or gw == ww_, f"word {k} (id {gi}): data differs"
    assert missing[0] == want_missing, f"missing pulsed {missing[0]} times, expected {want_missing}"
    assert got_at[first:] == [close_fe + FIRST_LAT + 1 + j for j in range(n)], \
        f"words of the last frame on the falling edges {[f - close_fe for f in got_at[first:]]} after the close " \
        f"edge, expected {FIRST_LAT + 1} .. {FIRST_LAT + n} (one per clock)"
    assert waits > 0, "no close had to wait"
    dut._log.info("%d words in order, %d missing flagged, closes waited %d clocks", len(got), missing[0], waits)


from mstrack.hw import hdl  # noqa: E402

TOP = "ms_result_order"
MODULE = "test_ms_result_order"


@pytest.mark.ghdl
@pytest.mark.parametrize("generics", [pytest.param(DEFAULTS, id="n5"), pytest.param({**DEFAULTS, "N_SLOTS": 16}, id="n16"),
                                      pytest.param({**DEFAULTS, "N_SLOTS": 1, "WORD_W": 8}, id="n1")])
def test_ms_result_order(generics, hdl_waves):
    hdl.run_ghdl(TOP, MODULE, generics, hdl.rtl_sources(TOP), waves=hdl_waves)


@pytest.mark.verilator
def test_ms_result_order_verilator(hdl_waves):
    """The netlist under Verilator (the word store as ms_ram_sdp, the read pipeline and ring, the lowest-id finder)."""
    hdl.run_verilator(TOP, MODULE, DEFAULTS, hdl.rtl_sources(TOP), waves=hdl_waves)
