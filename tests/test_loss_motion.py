"""The loss flag's motion latch (loss_jump, loss_stay; off by default): the fixed-point test against
its exact definition, the rule on a synthetic jump to a look-alike, and off = unchanged."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from mstrack.fixed.blocks_v2 import SIZE_FRAC, ms_loss_jump, ms_loss_latch
from mstrack.track.float_v2 import loss_jump, loss_latch
from mstrack.track.params import TrackerParams
from mstrack.track.tracker import Tracker


def test_ms_loss_jump_matches_its_exact_definition():
    """|sx - px| + |sy - py| > jump16 / 16 (w + h) / 2 in frame px, exactly (Fractions), on random
    steps and sizes and on the ties, for centre_frac 4 and 8."""
    rng = np.random.default_rng(1)
    n_true = 0
    for cf in (4, 8):
        for _ in range(3000):
            step = tuple(int(v) for v in rng.integers(-(40 << cf), 40 << cf, 2))
            prev = tuple(int(v) for v in rng.integers(-(40 << cf), 40 << cf, 2))
            w8, h8 = (int(v) for v in rng.integers(1 << SIZE_FRAC, 60 << SIZE_FRAC, 2))
            j16 = int(rng.integers(0, 41))
            d = Fraction(abs(step[0] - prev[0]) + abs(step[1] - prev[1]), 1 << cf)
            want = j16 > 0 and d > Fraction(j16, 16) * Fraction(w8 + h8, 1 << SIZE_FRAC) / 2
            assert ms_loss_jump(step, prev, w8, h8, j16, cf) == want, (step, prev, w8, h8, j16, cf)
            n_true += want
        # ties: exactly at the bound is no jump, one LSB more is
        w8 = h8 = 20 << SIZE_FRAC  # (w + h) / 2 = 20 px; loss_jump 1.25 -> 25 px
        assert not ms_loss_jump((25 << cf, 0), (0, 0), w8, h8, 20, cf)
        assert ms_loss_jump((25 << cf, 1), (0, 0), w8, h8, 20, cf)
        assert not ms_loss_jump((1 << 20, 1 << 20), (0, 0), w8, h8, 0, cf)  # jump16 0: off
    assert 1000 < n_true < 5000, n_true  # both outcomes drawn, often


def test_loss_latch_truth_table_float_and_fixed():
    p = TrackerParams(preset="v2", loss_jump=1.25, loss_stay=0.95)
    stay16 = int(round(0.95 * 65536))
    for latch in (False, True):
        for jump in (False, True):
            for rho_s, ref in ((0.90, 1.0), (0.95, 1.0), (0.97, 1.0)):
                want = jump or (latch and rho_s < 0.95 * ref)
                assert loss_latch(latch, jump, rho_s, ref, p) == want
                assert ms_loss_latch(latch, jump, int(round(rho_s * 65536)), 65536, stay16) == want
    assert not loss_jump((30.0, 0.0), (0.0, 0.0), 20.0, 20.0, TrackerParams(preset="v2"))  # off by default
    assert loss_jump((30.0, 0.0), (0.0, 0.0), 20.0, 20.0, p) and not loss_jump((25.0, 0.0), (0.0, 0.0), 20.0, 20.0, p)


def _look_alike_scene(n: int = 24, k: int = 10):
    """A red square moving right 2 px a frame; from frame k it is gone and a look-alike (the same
    red with a yellow fifth) sits off its path, where the tracker's search finds it."""
    rng = np.random.default_rng(0)
    frames, boxes = [], []
    for i in range(n):
        f = np.zeros((120, 160, 3), np.uint8)
        f[..., 0] = rng.integers(100, 200, (120, 160))
        f[..., 1] = rng.integers(60, 140, (120, 160))
        x, y = 30 + 2 * i, 40
        if i < k:
            f[y:y + 20, x:x + 20] = (30, 30, 220)
        else:
            dx, dy = 30 + 2 * k + 22, 40 + 14
            f[dy:dy + 20, dx:dx + 20] = (30, 30, 220)
            f[dy + 16:dy + 20, dx:dx + 20] = (30, 220, 220)
        frames.append(f)
        boxes.append((x, y, 20, 20))
    return frames, boxes, (30 + 2 * k + 32, 40 + 14 + 10)


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_motion_latch_flags_a_jump_to_a_look_alike(model):
    """The colour rule (here loss_rho 0.8, loss_contrast 0.08 against rho_ref) reports the
    look-alike as the target; the motion latch flags the frames after the jump to it, and flags
    none of the frames tracked on the target.  The flag does not steer: the boxes are the same."""
    frames, boxes, (dx, dy) = _look_alike_scene()
    kw = {"loss_ref_running": True, "loss_rho": 0.8, "loss_contrast": 0.08, "loss_stay": 0.95}
    runs = {}
    for jump in (0.0, 1.25):
        trk = Tracker(model=model, preset="v2", loss_jump=jump, **kw)
        trk.init(frames[0], boxes[0])
        runs[jump] = [trk.update(f) for f in frames[1:]]
    assert [r.box for r in runs[0.0]] == [r.box for r in runs[1.25]]
    on_target = [i for i, r in enumerate(runs[0.0][:9]) if abs(r.centre[0] - (boxes[i + 1][0] + 10)) < 4]
    on_alike = [i for i, r in enumerate(runs[0.0]) if np.hypot(r.centre[0] - dx, r.centre[1] - dy) < 4]
    assert len(on_target) >= 8 and len(on_alike) >= 10, (on_target, on_alike)
    assert all(runs[0.0][i].ok for i in on_alike)  # the colour rule misses the look-alike
    assert all(runs[1.25][i].ok for i in on_target)  # no false alarm on the target
    flagged = [i for i in on_alike if not runs[1.25][i].ok]
    assert flagged[:5] == on_alike[:5], flagged  # flagged from the jump on
    assert all(runs[1.25][i].extra["latch"] == 1 for i in flagged)


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_motion_latch_off_by_default_changes_nothing(model):
    """Off (the default, loss_jump 0): no motion signals in the results; any loss_stay gives the same
    results as the defaults (the latch is not evaluated)."""
    frames, boxes, _ = _look_alike_scene(14)
    assert TrackerParams(preset="v2").loss_jump == 0.0
    runs = []
    for kw in ({}, {"loss_stay": 0.5}):
        trk = Tracker(model=model, preset="v2", **kw)
        trk.init(frames[0], boxes[0])
        runs.append([trk.update(f) for f in frames[1:]])
    assert runs[0] == runs[1]
    assert not any("jump" in r.extra or "latch" in r.extra for r in runs[0])


def test_fixed_model_needs_loss_jump_in_sixteenths():
    with pytest.raises(ValueError, match="loss_jump = 1.3 is not a multiple of 1/16"):
        Tracker(model="fixed", preset="v2", loss_jump=1.3)
    with pytest.raises(ValueError, match="loss_jump must be in"):
        TrackerParams(preset="v2", loss_jump=-1.0)


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_motion_latch_on_an_occlusion_adds_no_false_alarm(model):
    """mstrack.io.synthetic's target (moving 3 px, 1 px a frame) hidden for frames 12..17: the
    colour rule flags the hidden frames; when the target reappears the box catches up (about 20 px
    in one frame, below loss_jump 1.25 x 35 px) and neither rule flags a tracked frame."""
    from mstrack.io.synthetic import render_scene

    n = 30
    boxes = np.array([(60 + 3 * i, 80 + i, 40, 30) for i in range(n)], float)
    hidden = np.zeros(n, bool)
    hidden[12:18] = True
    frames = render_scene(boxes, 320, 240, seed=3, hidden=hidden)
    kw = {"loss_ref_running": True, "loss_rho": 0.9, "loss_contrast": 0.08, "loss_stay": 0.95}
    runs = {}
    for jump in (0.0, 1.25):
        trk = Tracker(model=model, preset="v2", loss_jump=jump, **kw)
        trk.init(frames[0], tuple(boxes[0]))
        runs[jump] = [trk.update(f) for f in frames[1:]]
    for jump, rs in runs.items():
        ok = np.array([r.ok for r in rs])
        err = np.array([np.hypot(r.centre[0] - boxes[i + 1, 0] - 20, r.centre[1] - boxes[i + 1, 1] - 15)
                        for i, r in enumerate(rs)])
        assert not ok[hidden[1:]].any(), jump           # the hidden frames are flagged
        tracked = ~hidden[1:] & (err < 3)
        assert tracked.sum() >= 20 and ok[tracked].all(), (jump, ok, err)  # no false alarm
    assert not any(r.extra["latch"] for r in runs[1.25])
