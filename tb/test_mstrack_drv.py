"""The C driver sw/mstrack_drv.c against the RTL: ms_tracker_axi (core v2 with the default generics, the
paper core, and the multi-target core: MAX_TARGETS 2) under Verilator, every register access of the driver an
AXI4-Lite transaction (mstrack.hw.drvsim, tools/hdl/drv_main.cpp).

The driver initialises the core, gives the init box, enables the interrupts, and its interrupt
handler reads every result through the registers while the video streams with 1080p60 blanking.
Each result is compared with the fixed-point model field by field, frame by frame (the raw word and
the driver's decode of the RES_* registers), with the interrupt bits the handler saw and the
counters at the end (:func:`mstrack.hw.drvsim.check_run`).  In the simulation half of `make test`
(no marker ``long``), the multi-target run in the netlist half (marker ``long``).  tests/test_sw_driver.py
checks the same driver's decoder on the host without RTL.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from mstrack.hw.cosim import COMPARED_FIELDS_V2, expected_results_v2
from mstrack.track.params import TrackerParams
from test_ms_tracker_v2 import _real_clip


@pytest.mark.verilator
def test_driver_against_core_v2():
    """Deer, 30 frames at 704x400 (D = 4): tracked, lost on frame 25, searched and re-acquired on 27, so
    the lost and reacquired interrupts fire; a CPU 8 idle clocks per register access slower than the
    bus; 1080p60 blanking (the video never waits for the CPU)."""
    from mstrack.hw import drvsim, fastsim
    frames, box = _real_clip("Deer", 0, 30)
    exp = expected_results_v2(frames, box, TrackerParams(preset="v2"))
    assert any(e["status"] == drvsim.STATUS["lost"] for e in exp)
    assert any(e["status"] == drvsim.STATUS["reacquired"] for e in exp)
    run = drvsim.simulate_driver(frames, box, io_gap=8, **fastsim.HD1080P60)
    diffs = drvsim.check_run(run, exp)
    assert not diffs, "\n".join(diffs[:10])
    # the handler's reads end well before the next result: no result can be overwritten unread
    assert max(run.handler_clocks()) < 2000


@pytest.mark.verilator
def test_driver_against_paper_core():
    """The paper core (PRESET 0, result word v1: the driver's mstrack_read_result path): Girl, 20 frames
    at 128x96, 1080p60 blanking, every field of every result word v1 and the driver's decode."""
    from mstrack.fixed import FixedParams
    from mstrack.hw import drvsim, fastsim
    from mstrack.hw.cosim import expected_results
    frames, box = _real_clip("Girl", 0, 20)
    exp = expected_results(frames, box, TrackerParams(), FixedParams())
    run = drvsim.simulate_driver(frames, box, v2=False, io_gap=8, **fastsim.HD1080P60)
    diffs = drvsim.check_run(run, exp, v2=False)
    assert not diffs, "\n".join(diffs[:10])
    assert {"rho_e", "alpha_c", "box_w"} <= set(run.results[0]["driver"])   # the v1 fields, read by the driver


@pytest.mark.long
@pytest.mark.verilator
def test_driver_against_multi_target_core():
    """ms_tracker_axi with MAX_TARGETS 2 (two colour core v2 engines, MAX_FRAME_W 1024) on TUD-Stadtmitte
    (640 x 480), 12 frames, 1080p60 blanking, a CPU 8 idle clocks per access slower than the bus, and the
    result stream on too, into a sink that idles 64 clocks after each word (so a frame's two words come
    65 clocks apart, and an event of the first must wait for the second to interrupt).  The
    driver (mstrack_enable, then mstrack_add / mstrack_remove between frames, as the people appear and
    leave): three people added before frame 0 (the third refused: both slots taken, flag rejected on
    frame 0's word); before frame 5 the first removed and another person added in its slot (id 0); before
    frame 7 that person removed and a box outside the frame added (taken, then rejected by its engine: the
    command report code 3, the slot free again; its word is id 0's, so the error comes with the frame's
    first word and must reach the handler in the frame's one interrupt, with the result); before frame 9 a
    person added in that slot; before frame 10 a
    remove of the refused person (the driver refuses it: no id).  Every target's word of every frame, read
    by the handler through RES_SEL / RES_HEAD, and every word of the stream, against CoreModelMulti fed the
    commands where they landed."""
    from mstrack.fixed import FixedParams
    from mstrack.fixed.blocks import round_box
    from mstrack.hw import drvsim, fastsim
    from mstrack.hw.cosim_multi import CMD_BOX, expected_multi
    from mstrack.io.mot import load_mot_sequence
    from mstrack.track.params import V2_COLOUR
    seq_dir = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi" / "TUD-Stadtmitte"
    if not seq_dir.is_dir():
        pytest.skip(f"{seq_dir} not found: the multi-target driver run needs ../shared/data/multi")
    seq = load_mot_sequence(seq_dir)
    tp = TrackerParams(preset="v2", **V2_COLOUR)
    frames = [seq.frame(i) for i in range(12)]

    def box(frame, pid):
        return round_box(*seq.boxes_at(frame)[pid].as_tuple())
    ops = [(0, "add", "p1", box(0, 1)), (0, "add", "p4", box(0, 4)), (0, "add", "p7", box(0, 7)),
           (5, "remove", "p1"), (5, "add", "p8", box(5, 8)),
           (7, "remove", "p8"), (7, "add", "off", (2000, -500, 10, 10)),
           (9, "add", "p7b", box(9, 7)), (10, "remove", "p7")]
    run = drvsim.simulate_driver_multi(frames, ops, tp, FixedParams(), max_targets=2, max_frame_w=1024, io_gap=8,
                                       result_gap=64, **fastsim.HD1080P60)
    cmds = run.commands(2)                   # where each command landed: the frame planned (the result of
    assert sorted(cmds) == [0, 5, 7, 9]      # the frame before is read well inside the vertical blanking)
    model = expected_multi(frames, cmds, tp, FixedParams(), 2, 1024)
    diffs = drvsim.check_run_multi(run, model, 2)
    assert not diffs, "\n".join(diffs[:10])
    assert [o["rc"] for o in run.ops] == [0, 0, -5, 0, 0, 0, 0, 0, -3]   # MSTRACK_ERR_FULL, MSTRACK_ERR_ARG
    # the rejected box: reported (command interrupt) with the frame whose word shows it; its slot given
    # again before frame 9, which clears the driver's bit
    assert [o.code for o in model.outcomes].count(CMD_BOX) == 1
    assert [f["box_rejected"] for f in run.frames] == [0] * 7 + [0b01] * 2 + [0] * 3
    assert run.frames[7]["irq"] & drvsim.irq_bits()["command"]
    assert run.frames[7]["irq"] & drvsim.irq_bits()["error"]      # id 0's rejected word, in the result's interrupt
    assert [f["mask"] for f in run.frames] == [0b11] * 7 + [0b10] * 2 + [0b11] * 3
    assert max(run.handler_clocks()) < 2000
    assert run.stream is not None and len(run.stream) == len(model.results) == 22
    assert min(b["cycle"] - a["cycle"] for a, b in zip(run.stream, run.stream[1:])) == 65


@pytest.mark.long
@pytest.mark.verilator
def test_driver_against_shared_core():
    """ms_tracker_axi with SHARED_ENGINE (ms_tracker_shared: one colour engine for three slots, MAX_FRAME_W
    1024) on TUD-Stadtmitte (640 x 480), 10 frames, streamed at the raster its capacity rule is built for:
    520 lines of 1,200 clocks (hblank 560, vblank 40 lines), a budget that takes two of these people a
    frame.  The driver, a CPU 8 idle clocks per access slower than the bus, and a result stream sink that
    idles 64 clocks after each word.  Before frame 0 three people added: all three reported taken (code 0),
    the third refused at frame 0 by the capacity rule (code 2, seen by the handler: dev.add_refused, its
    slot free again); before frame 2 a box outside the frame added in that slot (rejected by the engine,
    code 3: dev.box_rejected); before frame 4 the first person removed and the refused one added again (id
    0; held by the rule from frame 5 on, err_code 6 words); before frame 6 another person added (id 2, taken:
    three live); before frame 8 one more (refused: no free slot, MSTRACK_ERR_FULL).  Every target's word of
    every frame read by the handler, and every word of the stream, against CoreModelMulti with the capacity
    rule, fed the commands where they landed; MULTI.shared_engine read by mstrack_init."""
    from mstrack.fixed import FixedParams
    from mstrack.fixed.blocks import round_box
    from mstrack.fixed.multi_capacity import MultiCoreConfig, VideoTiming
    from mstrack.hw import drvsim
    from mstrack.hw.cosim_multi import CMD_BOX, CMD_CYCLES, expected_multi
    from mstrack.hw.multi_core import pass_costs
    from mstrack.io.mot import load_mot_sequence
    from mstrack.track.params import V2_COLOUR
    seq_dir = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi" / "TUD-Stadtmitte"
    if not seq_dir.is_dir():
        pytest.skip(f"{seq_dir} not found: the shared-engine driver run needs ../shared/data/multi")
    seq = load_mot_sequence(seq_dir)
    tp = TrackerParams(preset="v2", **V2_COLOUR)
    frames = [seq.frame(i) for i in range(10)]
    timing = VideoTiming(480, 520, 1200)

    def box(frame, pid):
        return round_box(*seq.boxes_at(frame)[pid].as_tuple())
    ops = [(0, "add", "p1", box(0, 1)), (0, "add", "p4", box(0, 4)), (0, "add", "p7", box(0, 7)),
           (2, "add", "off", (2000, -500, 10, 10)),
           (4, "remove", "p1"), (4, "add", "p7b", box(4, 7)),
           (6, "add", "p2", box(6, 2)), (8, "add", "p3", box(8, 3))]
    run = drvsim.simulate_driver_multi(frames, ops, tp, FixedParams(), max_targets=3, max_frame_w=1024, io_gap=8,
                                       result_gap=64, shared=timing, hblank=1200 - 640, vblank=40 * 1200)
    cmds = run.commands(3)
    assert sorted(cmds) == [0, 2, 4, 6, 8]
    model = expected_multi(frames, cmds, tp, FixedParams(), 3, 1024,
                           capacity=MultiCoreConfig(3, timing, pass_costs(4)))
    diffs = drvsim.check_run_multi(run, model, 3)
    assert not diffs, "\n".join(diffs[:10])
    assert run.shared_engine == 1
    assert [o["rc"] for o in run.ops] == [0, 0, 0, 0, 0, 0, 0, -5]
    # the model's later reports: the third add refused at frame 0, the box rejected at frame 2
    assert [(o.code, o.target_id) for o in model.outcomes if o.code in (CMD_CYCLES, CMD_BOX)] == [(2, 2), (3, 2)]
    assert [f["add_refused"] for f in run.frames] == [0b100] * 2 + [0] * 8   # cleared by the next add given id 2
    assert [f["box_rejected"] for f in run.frames] == [0] * 2 + [0b100] * 4 + [0] * 4
    held = [(i, w["target_id"]) for i, f in enumerate(model.frames) for w in f if w["err_code"] == 6]
    assert held and all(k == 0 and i >= 5 for i, k in held)
    assert [f["mask"] for f in run.frames][-1] == 0b111
    assert run.stream is not None and len(run.stream) == len(model.results)
    assert max(run.handler_clocks()) < 2000
    print(f"shared engine: {len(run.frames)} frames, {len(model.results)} words ({len(held)} held), "
          f"{run.cycles} clocks in {run.seconds:.0f} s (build {run.build_seconds:.0f} s), handler up to "
          f"{max(run.handler_clocks())} clocks, bit-exact")


@pytest.mark.extra
@pytest.mark.verilator
@pytest.mark.parametrize("name", ["TUD-Stadtmitte", "PETS09-S3MF1"])
def test_driver_multi_mot_sequence(name):
    """Every frame and every target of a MOT sequence through ms_tracker_axi with MAX_TARGETS 8 (colour
    engines, MAX_FRAME_W 1024; the sequences peak at 8 and 7 people at once) and its driver, 1080p60
    blanking: each person added before its first frame, removed after its last (drvsim.mot_ops; TUD-Stadtmitte's
    four leavers free slots that later people take), every word bit-exact with CoreModelMulti.  `make
    test-multi-mot` (not in `make test`: 75 M and 97 M clocks on an 8-engine netlist).  MSTRACK_MOT_FRAMES / MSTRACK_MOT_SLOTS run a prefix on fewer slots (then
    the people beyond the slots are refused, which the check expects from the model)."""
    import os
    from mstrack.fixed import FixedParams
    from mstrack.hw import drvsim, fastsim
    from mstrack.hw.cosim_multi import expected_multi
    from mstrack.io.mot import load_mot_sequence
    from mstrack.track.params import V2_COLOUR
    seq_dir = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi" / name
    if not seq_dir.is_dir():
        pytest.skip(f"{seq_dir} not found: the MOT driver run needs ../shared/data/multi")
    seq = load_mot_sequence(seq_dir)
    n = min(len(seq), int(os.environ.get("MSTRACK_MOT_FRAMES", len(seq))))
    slots = int(os.environ.get("MSTRACK_MOT_SLOTS", 8))
    tp = TrackerParams(preset="v2", **V2_COLOUR)
    frames = [seq.frame(i) for i in range(n)]
    ops = drvsim.mot_ops(seq, n)
    max_w = 1024 if frames[0].shape[1] <= 1024 else 2048
    run = drvsim.simulate_driver_multi(frames, ops, tp, FixedParams(), max_targets=slots, max_frame_w=max_w,
                                       **fastsim.HD1080P60)
    model = expected_multi(frames, run.commands(slots), tp, FixedParams(), slots, max_w)
    diffs = drvsim.check_run_multi(run, model, slots)
    assert not diffs, "\n".join(diffs[:10])
    words = sum(len(f["words"]) for f in run.frames)
    print(f"{name}: {n} frames, {words} target words, {len(ops)} ops, {run.cycles} clocks in {run.seconds:.0f} s "
          f"(build {run.build_seconds:.0f} s), bit-exact")


def test_check_run_finds_differences():
    """check_run reports a changed field, a driver decode that differs from the raw word, a missing
    interrupt bit and wrong counters (on a run assembled by hand, no RTL)."""
    from mstrack.fixed.vhdl_pkg import pack_result_v2, unpack_result_v2
    from mstrack.hw import drvsim
    exp = [{"cx": 100, "cy": 50, "w8": 256, "h8": 512, "rho": 1000, "confidence": 200, "status": 2, "iter": 1,
            "stop": 0, "decim_log2": 1, "searched": 0, "flags": 4, "err_code": 0, "frame_count": 1}]
    exp = [unpack_result_v2(pack_result_v2(e)) for e in exp]
    exp = [{k: e[k] for k in COMPARED_FIELDS_V2} for e in exp]
    word = pack_result_v2(exp[0])
    irq = drvsim.irq_bits()
    good = drvsim.DriverRun(results=[{"word": word, "fields": unpack_result_v2(word),
                                      "irq": irq["result"] | irq["lost"],
                                      "driver": {**{k: exp[0][k] for k in exp[0]}, "valid": 1},
                                      "irq_cycle": 0, "handled_cycle": 50}],
                            calls={"init": 0, "start": 0},
                            counters={"results": 1, "lost": 1, "errors": 0, "rejected": 0, "dropped": 0}, status="done")
    assert drvsim.check_run(good, exp) == []
    bad = drvsim.DriverRun(**{**good.__dict__, "results": [dict(good.results[0])]})
    bad.results[0]["driver"] = {**bad.results[0]["driver"], "cy": 51}
    bad.results[0]["irq"] = irq["result"]
    bad.counters = {**good.counters, "lost": 0}
    msgs = "\n".join(drvsim.check_run(bad, [{**exp[0], "cx": 101}]))
    for what in ("cx: dut=100 model=101", "cy: driver=51", "interrupt bits", "counters"):
        assert what in msgs


def test_check_run_multi_finds_differences():
    """check_run_multi reports a changed field, a wrong target mask, a driver decode that differs from the
    raw word, an add whose id differs from the model's, wrong counters and a result stream beat that differs
    (a run assembled by hand, no RTL)."""
    from mstrack.fixed.vhdl_pkg import pack_result_v2, unpack_result_v2
    from mstrack.hw import drvsim
    from mstrack.hw.cosim_multi import CMD_OK, Outcome

    class Model:                             # the two attributes check_run_multi reads, and live
        def __init__(self, frames, outcomes):
            self.frames, self.outcomes, self.live = frames, outcomes, [0]

        @property
        def results(self):
            return [w for f in self.frames for w in f]
    base = {"cx": 100, "cy": 50, "w8": 256, "h8": 512, "rho": 1000, "confidence": 200, "status": 0, "iter": 1,
            "stop": 0, "decim_log2": 1, "searched": 0, "flags": 0, "err_code": 0, "frame_count": 0}
    f = {k: v for k, v in unpack_result_v2(pack_result_v2(base)).items() if k in COMPARED_FIELDS_V2}
    word = pack_result_v2(f)
    irq = drvsim.irq_bits()
    good = drvsim.DriverMultiRun(
        frames=[{"mask": 1, "irq": irq["result"], "irq_cycle": 0, "handled_cycle": 90, "frame_count": 0, "box_rejected": 0,
                 "words": {0: {"word": word, "fields": unpack_result_v2(word),
                               "driver": {**f, "valid": 1, "target_id": 0, "again_frame_count": 0}}}}],
        ops=[{"op": "add", "label": "a", "rc": 0, "id": 0, "before": 0, "after": 0, "box": (1, 2, 3, 4)}],
        calls={"init": 0, "start": 0}, counters={"results": 1, "lost": 0, "errors": 0, "rejected": 0, "dropped": 0},
        live=1, status="done")
    model = Model([[{**f, "target_id": 0}]], [Outcome(CMD_OK, 0)])
    assert drvsim.check_run_multi(good, model, 2) == []
    assert good.commands(2) == {0: [("add", (1, 2, 3, 4))]}
    bad = drvsim.DriverMultiRun(**{**good.__dict__})
    bad.frames = [{**good.frames[0], "mask": 3, "words": {0: {**good.frames[0]["words"][0],
                                                              "driver": {**good.frames[0]["words"][0]["driver"],
                                                                         "cy": 51}}}}]
    bad.ops = [{**good.ops[0], "id": 1}]
    bad.counters = {**good.counters, "results": 2}
    msgs = "\n".join(drvsim.check_run_multi(bad, Model([[{**f, "cx": 101, "target_id": 0}]], [Outcome(CMD_OK, 0)]), 2))
    for what in ("cx: dut=100 model=101", "targets 0x3", "cy: driver=51", "add a: driver rc=0 id=1", "counters"):
        assert what in msgs, what
    with pytest.raises(ValueError, match="started during the call"):
        drvsim.DriverMultiRun(ops=[{**good.ops[0], "after": 1}]).commands(2)
    # the result stream: its beat against the model's word, field by field, tlast on the frame's last
    beat = {**unpack_result_v2(word), "target_id": 0, "word": word, "last": 1, "cycle": 10}
    assert drvsim.check_run_multi(drvsim.DriverMultiRun(**{**good.__dict__, "stream": [beat]}), model, 2) == []
    msgs = "\n".join(drvsim.check_run_multi(drvsim.DriverMultiRun(**{**good.__dict__, "stream": [
        {**beat, "target_id": 1, "last": 0}, beat]}), model, 2))
    for what in ("2 beats, the model has 1", "target_id: dut=1 model=0", "tlast: dut=0 model=1"):
        assert what in msgs, what
