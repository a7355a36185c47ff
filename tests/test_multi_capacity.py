"""The multi-target core's capacity rule (mstrack/fixed/multi_capacity.py, docs/multi_target_core.md):
job clocks against the hardware cycle model, the rule's boundaries, and the geometry it reads from a
FixedTrackerV2 against what the tracker then does."""
from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import pytest

from mstrack.fixed.multi_capacity import (ADD_CYCLES, ADD_FULL, ADD_OK, ERR_CAPACITY, MultiCoreConfig, PassCosts,
                                          TargetDemand, VideoTiming, check_add, init_demand, job_clocks,
                                          pixel_pass_clocks, plan_frame, target_demand)
from mstrack.fixed.tracker_v2 import FixedTrackerV2
from mstrack.track.params import V2_COLOUR, TrackerParams

SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"
T = VideoTiming()


# ----------------------------------------------------------------------------- clocks
@pytest.mark.parametrize("lanes", [2, 4, 8])
@pytest.mark.parametrize("wd, hd", [(3, 3), (31, 47), (64, 64), (127, 127), (127, 40)])
def test_pixel_pass_equals_the_hardware_cycle_model(wd, hd, lanes):
    from mstrack.hw import synth
    xr = synth.row_extents(wd, hd, "flat", 8)
    assert pixel_pass_clocks(wd, hd, lanes) == synth.pixel_pass_cycles((wd - 1) // 2, (hd - 1) // 2, lanes, None, xr)


def test_default_pass_costs_are_the_hardware_cycle_models():
    from mstrack.hw.multi_core import pass_costs
    assert PassCosts() == pass_costs(4)
    assert pass_costs(2).lanes == 2 and pass_costs(2).bin_pass == PassCosts().bin_pass


def test_one_target_job_is_core_v2s_budget():
    """Without the multi-target additions (Qw load, state switch; the colour core, no scale test) a
    target's worst jobs are docs/fixed_point.md's v2 budget rows (mstrack.hw.synth.v2_cycle_budget)."""
    from mstrack.hw import synth
    tp = TrackerParams(preset="v2", **V2_COLOUR)
    c = PassCosts()
    extra = tp.n_colour_bins + c.qload_extra + c.job_switch
    track, lost, _ = synth.v2_cycle_budget(4)
    assert job_clocks("track", 127, 127, tp) - extra == track["clocks"]
    assert job_clocks("lost", 64, 64, tp) - extra == lost["clocks"]


def test_job_clocks_grow_with_window_and_iterations():
    tp = TrackerParams(preset="v2")
    for kind in ("track", "lost"):
        seq = [job_clocks(kind, w, w, tp) for w in (3, 15, 31, 63, 95, 127)]  # type: ignore[arg-type]
        assert seq == sorted(seq) and len(set(seq)) == len(seq)
    assert job_clocks("track", 63, 63, tp.with_(max_iter=10)) < job_clocks("track", 63, 63, tp)
    assert job_clocks("init", 63, 63, tp, ring=(100, 100)) < job_clocks("init", 63, 63, tp, ring=(140, 100))
    # the joint bins cost 4 clocks per bin pass; the scale test two windows
    assert job_clocks("track", 63, 63, tp) > job_clocks("track", 63, 63, tp.with_(orient_T=0, scale_test=0.0,
                                                                                  scale_test_gate=False))
    with pytest.raises(ValueError, match="init, track or lost"):
        job_clocks("search", 9, 9, tp)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- the rule
def _job(i: int, clocks: int, release: int = 500, nxt: int = 100, kind: str = "track") -> TargetDemand:
    return TargetDemand(i, kind, 1, 31, 31, 95, 95, 0, clocks, release, nxt)  # type: ignore[arg-type]


def test_slack_is_the_raster_distance_and_never_below_the_blanking():
    j = _job(0, 1, release=500, nxt=100)
    assert j.slack(T) == (1125 - 500 + 100 - 1) * 2200
    assert _job(0, 1, release=1080, nxt=0).slack(T) == T.blank_clocks == 99_000
    assert T.frame_clocks == 2_475_000


def test_plan_frame_boundary_is_exact():
    budget = _job(0, 1).slack(T)
    jobs = [_job(i, budget // 4) for i in range(4)]
    rest = budget - 4 * (budget // 4)
    assert plan_frame(jobs).tracked == (0, 1, 2, 3)                    # sum <= min slack
    edge = [*jobs[:3], _job(3, budget // 4 + rest)]
    p = plan_frame(edge)
    assert p.tracked == (0, 1, 2, 3) and p.clocks == budget == p.budget  # equality fits
    over = [*jobs[:3], _job(3, budget // 4 + rest + 1)]
    assert plan_frame(over).held == (3,)                               # one clock more does not


def test_plan_frame_holds_newest_first_and_tries_the_rest():
    budget = _job(0, 1).slack(T)
    jobs = [_job(7, budget // 2), _job(3, budget // 2), _job(5, 10), _job(1, 1)]
    p = plan_frame(jobs)
    assert p.tracked == (7, 3) and p.held == (5, 1)                    # priority = the order given
    assert [j.target_id for j in p.jobs] == [7, 3]
    big_first = [_job(0, budget // 2), _job(1, budget), _job(2, budget // 2)]
    assert plan_frame(big_first).tracked == (0, 2) and plan_frame(big_first).held == (1,)


def test_plan_frame_tight_slack_limits_every_job():
    """One target whose region spans the frame leaves only the blanking for all the frame's jobs."""
    tall = _job(0, 50_000, release=1080, nxt=0)
    small = [_job(i, 30_000) for i in range(1, 4)]
    assert plan_frame([tall, *small]).tracked == (0, 1)                # 80,000 <= 99,000 < 110,000
    assert plan_frame(small).tracked == (1, 2, 3)


def test_plan_frame_max_targets_and_bad_ids():
    jobs = [_job(i, 10) for i in range(5)]
    assert plan_frame(jobs, MultiCoreConfig(max_targets=3)).held == (3, 4)
    with pytest.raises(ValueError, match="distinct"):
        plan_frame([_job(1, 1), _job(1, 1)])


def test_check_add_codes():
    cfg = MultiCoreConfig(max_targets=2)
    budget = _job(0, 1).slack(T)
    live = [_job(0, budget // 2)]
    assert check_add(live, 1, _job(1, budget // 2, kind="init"), cfg) == ADD_OK
    assert check_add(live, 1, _job(1, budget // 2 + 1, kind="init"), cfg) == ADD_CYCLES
    assert check_add(live, 2, _job(1, 1, kind="init"), cfg) == ADD_FULL   # held targets count as live
    assert check_add([], 0, _job(0, 10**9, kind="init"), cfg) == ADD_CYCLES
    assert ERR_CAPACITY == 6


@pytest.mark.parametrize("kw, words", [({"max_targets": 0}, "1..16"), ({"max_targets": 17}, "1..16")])
def test_config_errors(kw, words):
    with pytest.raises(ValueError, match=words):
        MultiCoreConfig(**kw)
    with pytest.raises(ValueError, match="active_lines"):
        VideoTiming(active_lines=1125)
    with pytest.raises(ValueError, match="power of two"):
        PassCosts(lanes=3)


# ----------------------------------------------------------------------------- geometry from the tracker
def _check_track(frames, box, tp=None):
    """Per frame: the demand read before update has the decimation the tracker then uses, and the next
    region never starts above the previous demand's next_line (the bound the deadline relies on)."""
    trk = FixedTrackerV2(tp or TrackerParams(preset="v2"))
    fh, fw = frames[0].shape[:2]
    d0 = init_demand(box, fw, fh, 0, trk.params, trk.fixed)
    r = trk.init(frames[0], box)
    assert d0.d == r.extra["decimation"] and d0.kind == "init"
    first = target_demand(trk, 0)
    assert first.d == d0.d and first.release_line <= fh
    assert first.first_line == d0.next_line                              # the init frame does not move
    assert first.next_line <= first.first_line                           # the bound is above the region
    prev_next, kinds = d0.next_line, []
    for f in frames[1:]:
        dm = target_demand(trk, 0)
        kinds.append(dm.kind)
        assert dm.first_line >= prev_next, (dm, prev_next)
        r = trk.update(f)
        assert r.extra["decimation"] == dm.d
        prev_next = dm.next_line
    return kinds


def test_demand_follows_the_tracker_on_a_synthetic_scene():
    from mstrack.io.synthetic import make_scene
    frames, gt = make_scene(12, 160, 120, seed=3)
    kinds = _check_track(list(frames), tuple(gt[0]))
    assert kinds and set(kinds) <= {"track", "lost"}


@pytest.mark.skipif(not (SEQ_ROOT / "Couple").is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (../shared absent)")
def test_demand_follows_the_tracker_through_a_loss():
    """Couple 0-59: the tracker goes lost on frames 46-48 and searches at D x 2
    (docs/blocks/ms_tracker_v2.md); Deer 0-29 at 704x400, D = 2, lost on frame 25.  With
    MSTRACK_MULTI_ALL=1: every frame of the 10 dev sequences (23 s)."""
    from mstrack.io.data import load_dataset, load_sequence
    if os.environ.get("MSTRACK_MULTI_ALL"):
        kinds = []
        for seq in load_dataset(SEQ_ROOT):
            kinds += _check_track(list(seq.frames()), tuple(seq.gt[0]))
        assert kinds.count("lost") > 100
        return
    seq = load_sequence(SEQ_ROOT / "Couple")
    kinds = _check_track([seq.frame(i) for i in range(60)], tuple(seq.gt[0]))
    seq = load_sequence(SEQ_ROOT / "Deer")
    kinds += _check_track([seq.frame(i) for i in range(30)], tuple(seq.gt[0]))
    assert "lost" in kinds and "track" in kinds


@pytest.mark.parametrize("box", [(30, 20, 24, 30), (2, 3, 40, 28), (100, 70, 60, 45)])
def test_init_demand_is_the_init_frames_geometry(box):
    """The init capture's ring is ms_bg_model's: its area is the ring count plus the box rectangle
    (box at the frame border included); D is the init frame's; the job counts the whole captured
    rectangle (the ring and the init region)."""
    from mstrack.fixed.blocks import ms_kernel
    from mstrack.fixed.multi_capacity import init_capture
    from mstrack.io.synthetic import make_scene
    frames, _ = make_scene(1, 160, 120, seed=5)
    trk = FixedTrackerV2()
    r = trk.init(frames[0], box)
    dm = init_demand(box, 160, 120, 0)
    ic = init_capture(box, 160, 120)
    assert dm.d == ic.d == r.extra["decimation"]
    ker = ms_kernel(*_box_diameters(dm, box), "flat", 8)
    assert ic.ring[2] * ic.ring[3] == int(trk.model.O.sum()) + (2 * ker.ex + 1) * (2 * ker.ey + 1)
    assert dm.rows * dm.cols == ic.rect[2] * ic.rect[3] >= ic.ring[2] * ic.ring[3]


def _box_diameters(dm, box):
    from mstrack.fixed.blocks_v2 import ms_box_size
    fw, fh = 160, 120
    d = dm.d
    return (ms_box_size(round(box[2]) << 8, d, min(127, (fw - 1) // d + 1 - 2)),
            ms_box_size(round(box[3]) << 8, d, min(127, (fh - 1) // d + 1 - 2)))


def test_init_demand_refuses_what_init_refuses():
    with pytest.raises(ValueError, match="3x3"):
        init_demand((0, 0, 2, 2), 64, 48, 0)
    with pytest.raises(ValueError, match="positive"):
        init_demand((5, 5, 0, 4), 64, 48, 0)
    a, b = init_demand((10, 10, 20, 20), 320, 240, 0), init_demand((10, 10, 60, 60), 320, 240, 1)
    assert a.clocks < b.clocks and a.rows < b.rows                       # ring counted from the slot
    big = init_demand((100, 100, 900, 700), 1920, 1080, 2)
    assert big.d == 8 and big.slack(T) >= T.blank_clocks


def test_target_demand_needs_an_initialised_tracker():
    with pytest.raises(ValueError, match="init"):
        target_demand(FixedTrackerV2(), 0)


def test_replace_keeps_the_rule_pure():
    """The rule reads only its arguments: the same demands give the same plan."""
    jobs = [_job(i, 40_000 + i) for i in range(6)]
    assert plan_frame(jobs) == plan_frame([replace(j) for j in jobs])
