"""Shared by the benches of the v2 per-frame blocks (ms_share, ms_spread, ms_scale, ms_resize,
ms_ring_share, ms_loss_filter, ms_loss_flag, ms_confidence, ms_ref_update).

* :func:`record_v2_calls`: the arguments of every call of those blocks
  FixedTrackerV2 makes on the first frames of real sequences (the model's own inputs, replayed
  value by value through the RTL).
* :func:`run_stream`: a start/busy/done driver: each item's inputs are held with start = 1 until the
  block takes them (the edge that samples start = 1 with busy = 0), back to back (start already high
  in the done cycle) or after random gaps (throttled, inputs randomised while the block is busy to
  check they are latched); every result is compared with the model and its latency asserted.
"""
from __future__ import annotations

import random
from pathlib import Path
from typing import Callable, Sequence

from cocotb.triggers import ClockCycles, RisingEdge

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
if not SEQ_ROOT.is_dir():
    SEQ_ROOT = Path("/work/shared/data/sequences")

#: sequences with scale change (MotorRolling, Couple), decimation (Deer, MotorRolling), losses (Football1)
REAL_SEQS = ("Couple", "MotorRolling", "Deer", "Football1", "Subway")


def record_v2_calls(names: Sequence[str] = REAL_SEQS, frames: int = 40) -> dict[str, list[tuple]]:
    """The arguments of every call FixedTrackerV2 (default v2 parameters) makes on the first ``frames``
    frames of each sequence (init included), per block:

    ms_share (nt_in, n_in), ms_spread (st2, nt), ms_scale (spread, spread_ref, w8, w0_8),
    ms_resize (s8, s, frame_size), ms_ring_share (nt, nt_in, n_in, K), ms_loss_filter (s, x, k),
    ms_loss_flag (rho_s, rho0, con_s, share, loss_rho, loss_contrast),
    ms_confidence (rho, share, rho_ref, share_ref), ms_ref_update (ref, x, k),
    ms_region_v2 (cx, cy, ex, ey, ox, oy, lost, frame_w, frame_h: the decimated centre and frame)."""
    import mstrack.fixed.tracker_v2 as tv2
    from mstrack.io.data import load_sequence

    args_of: dict[str, Callable[..., tuple]] = {
        "ms_share": lambda st: (st.nt_in, st.n_in),
        "ms_spread": lambda st: (st.st2, st.nt),
        "ms_scale": lambda sp, sp_ref, w8, w0_8, tp: (sp, sp_ref, w8, w0_8),
        "ms_resize": lambda s8, s, fs: (s8, s, fs),
        "ms_ring_share": lambda st, K: (st.nt, st.nt_in, st.n_in, K),
        "ms_loss_filter": lambda s, x, k: (s, x, k),
        "ms_loss_flag": lambda *a: tuple(a),
        "ms_confidence": lambda *a: tuple(a),
        "ms_ref_update": lambda r, x, k: (r, x, k),
        "ms_region_v2": lambda c8d, ex, ey, ox, oy, lost, fw, fh, fp: (*c8d, ex, ey, ox, oy, int(lost), fw, fh),
    }
    out: dict[str, list[tuple]] = {k: [] for k in args_of}
    orig = {k: getattr(tv2, k) for k in out}

    def wrap(name: str) -> Callable:
        def f(*a):
            out[name].append(args_of[name](*a))
            return orig[name](*a)
        return f

    for k in out:
        setattr(tv2, k, wrap(k))
    try:
        for name in names:
            seq = load_sequence(SEQ_ROOT / name)
            t = tv2.FixedTrackerV2()
            t.init(seq.frame(0), seq.init_box())
            for i in range(1, min(frames, len(seq))):
                t.update(seq.frame(i))
    finally:
        for k, f in orig.items():
            setattr(tv2, k, f)
    return out


def tracker_states(names: Sequence[str], frames: int, tp=None) -> list[dict[str, int]]:
    """The state FixedTrackerV2 (parameters ``tp``, default v2) holds before each of the first ``frames``
    frames of each sequence, after init: w8, h8, c8x, c8y, lost and the frame size."""
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from mstrack.io.data import load_sequence

    out = []
    for name in names:
        seq = load_sequence(SEQ_ROOT / name)
        t = FixedTrackerV2(tp)
        f0 = seq.frame(0)
        t.init(f0, seq.init_box())
        for i in range(1, min(frames, len(seq))):
            out.append({"w8": t.w8, "h8": t.h8, "c8x": t.c8[0], "c8y": t.c8[1], "lost": int(t.lost),
                        "frame_w": f0.shape[1], "frame_h": f0.shape[0]})
            t.update(seq.frame(i))
    return out


async def reset(dut, inputs: Sequence[str]) -> None:
    dut.rst.value = 1
    dut.start.value = 0
    for n in inputs:
        getattr(dut, n).value = 0
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


async def run_stream(dut, items: Sequence[dict[str, int]], outputs: Sequence[str],
                     model: Callable[[dict[str, int]], tuple[int, ...]], latency: int, gap_prob: float,
                     rng: random.Random, widths: dict[str, int]) -> int:
    """Drive ``items`` (input port -> value) through a start/busy/done block; returns the clocks used.

    Asserts for every item: one done, ``latency`` edges after the edge that took the item, outputs ==
    ``model(item)``; no done without a pending item."""
    pending: list[tuple[int, int]] = []        # (edge that took it, item index)
    cur: int | None = None                     # item presented now (start = 1)
    nxt, checked, cycle = 0, 0, 0
    dut.start.value = 0
    while checked < len(items):
        await RisingEdge(dut.clk)
        cycle += 1
        busy, done, st = int(dut.busy.value), int(dut.done.value), int(dut.start.value)
        if done:
            assert pending, f"done at clock {cycle} with no item pending"
            t0, idx = pending.pop(0)
            got = tuple(int(getattr(dut, o).value) for o in outputs)
            exp = model(items[idx])
            assert got == exp, f"item {idx} {items[idx]}: {dict(zip(outputs, got))}, model {dict(zip(outputs, exp))}"
            assert cycle - t0 == latency, f"item {idx}: latency {cycle - t0} != {latency}"
            checked += 1
        if st and not busy and cur is not None:
            pending.append((cycle, cur))
            cur = None
        if cur is None and nxt < len(items) and rng.random() >= gap_prob:
            cur = nxt
            nxt += 1
            for k, v in items[cur].items():
                getattr(dut, k).value = v
            dut.start.value = 1
        elif cur is None:
            dut.start.value = 0
            if gap_prob > 0:                   # inputs change while busy / idle: must not matter
                for k, w in widths.items():
                    getattr(dut, k).value = rng.getrandbits(w)
        assert cycle < (len(items) + 4) * (latency + 20) + 1000, "stuck"
    return cycle
