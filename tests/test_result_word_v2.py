"""Result word v2: layout, packing and decoding of tracker v2's results.

The layout is the specification core v2 is built against: every field of every frame of the
fixed-point model v2 must fit its width and decode back to the same integers.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mstrack import Tracker
from mstrack.fixed.tracker_v2 import RESULT_FIELDS_V2, STATUS_CODES_V2
from mstrack.fixed.vhdl_pkg import (RESULT_FLAGS, STATUS_V2, pack_result_v2, result_fields_v2, result_layout_v2,
                                    result_width_v2, unpack_result_v2)
from mstrack.io.synthetic import make_scene

SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"


def test_layout_is_contiguous_and_byte_aligned():
    lay = result_layout_v2()
    off = 0
    for name, o, w in lay:
        assert o == off and w > 0, name
        off += w
    assert result_width_v2() % 8 == 0 and result_width_v2() >= off
    names = {n for n, _, _ in lay}
    # everything the model reports per frame has a field (decimation as its log2)
    for f in RESULT_FIELDS_V2:
        assert f in names or f == "decimation", f
    assert "decim_log2" in names


def test_status_names_match_the_model_codes():
    for status, code in STATUS_CODES_V2.items():
        assert STATUS_V2[code] == status.value


def test_pack_unpack_round_trip_random():
    rng = np.random.default_rng(5)
    lay = result_layout_v2()
    for _ in range(500):
        f = {name: int(rng.integers(0, 1 << w)) for name, _, w in lay}
        u = unpack_result_v2(pack_result_v2(f))
        assert {k: u[k] for k in f} == f
        for i, flag in enumerate(RESULT_FLAGS):
            assert u[f"flag_{flag}"] == (f["flags"] >> i) & 1


@pytest.mark.parametrize("name", [n for n, _, _ in result_layout_v2()])
def test_pack_refuses_values_that_do_not_fit(name):
    w = dict((n, w) for n, _, w in result_layout_v2())[name]
    with pytest.raises(ValueError, match=name):
        pack_result_v2({name: 1 << w})
    with pytest.raises(ValueError, match=name):
        pack_result_v2({name: -1})


def test_pack_refuses_unknown_fields():
    with pytest.raises(ValueError, match="unknown"):
        pack_result_v2({"box_w": 3})


def _track(frames, box, n=None):
    trk = Tracker(model="fixed", preset="v2")
    out = []
    for i, fr in enumerate(frames):
        if n is not None and i >= n:
            break
        r = trk.init(fr, box) if i == 0 else trk.update(fr)
        out.append(r)
    return out


def _check_frames(results):
    for i, r in enumerate(results):
        f = result_fields_v2(r.extra, frame_count=i)
        u = unpack_result_v2(pack_result_v2(f))
        assert {k: u[k] for k in f} == f
        # decoded values are the model's
        assert u["cx"] == r.extra["cx"] and u["w8"] == r.extra["w8"] and u["h8"] == r.extra["h8"]
        assert u["confidence"] == r.extra["confidence"] and 1 << u["decim_log2"] == r.extra["decimation"]
        assert STATUS_V2[u["status"]] == r.status.value
        assert u["flag_lost"] == int(r.status.value == "lost")


def test_every_frame_of_a_synthetic_scene_fits_and_decodes():
    frames, gt = make_scene(n_frames=40, width=320, height=240, seed=3)
    res = _track(frames, tuple(gt[0]))
    _check_frames(res)


def test_large_target_and_frame_edge_values_fit():
    # a 600 px target in a 1280x720 frame: decimation 8, sizes near the frame
    rng = np.random.default_rng(1)
    f = rng.integers(0, 120, (720, 1280, 3)).astype(np.uint8)
    f[50:690, 300:900] = (40, 200, 60)
    res = _track([f, f, f], (300, 50, 600, 640))
    assert res[-1].extra["decimation"] == 8
    _check_frames(res)


@pytest.mark.skipif(not SEQ_ROOT.is_dir(), reason=f"real sequences not found at {SEQ_ROOT} (../shared absent)")
@pytest.mark.parametrize("name", ["MotorRolling", "Girl", "Suv"])
def test_real_sequence_results_fit_and_decode(name):
    from mstrack.io.data import load_sequence
    seq = load_sequence(SEQ_ROOT / name)
    res = _track(seq.frames(), seq.init_box(), n=120)
    _check_frames(res)


def test_target_state_record_holds_every_state_of_a_run():
    """Core v2's target state record (target_state_layout_v2, the RTL's tgt_state): contiguous, 239 bits at
    the default widths (ms_pkg.v2_state_w), and every state FixedTrackerV2 reaches on a generated scene
    with a loss fits its fields and reads back the same (rho_s, con_s signed)."""
    from mstrack.fixed.tracker_v2 import FixedTrackerV2
    from mstrack.fixed.vhdl_pkg import (TARGET_STATE_SIGNED, target_state_layout_v2, target_state_v2,
                                        unpack_target_state_v2)
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.fixed import FixedParams
    from mstrack.track.params import TrackerParams
    g = CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).generics()
    lay = target_state_layout_v2(g)
    off = 0
    for name, o, w in lay:
        assert o == off and w > 0, name
        off += w
    assert off == 3 + 2 * g["CENTRE_ABS_W"] + 3 * g["SIZE_W"] + 2 * g["COORD_W"] + 3 * g["SHARE_W"] \
        + 2 * g["CON_W"] + g["SPREAD_W"] == 239
    trk = FixedTrackerV2()
    assert set(target_state_v2(trk, g).values()) == {0}              # no target: the empty record
    frames, boxes = make_scene(20, 96, 72, seed=4)
    trk.init(frames[0], tuple(int(v) for v in boxes[0]))
    for f in [*frames[1:], *[np.zeros_like(frames[0])] * 3]:           # three blank frames: lost
        trk.update(f)
        st = target_state_v2(trk, g)
        word = 0
        for name, o, w in lay:
            v = st[name]
            lo, hi = (-(1 << (w - 1)), 1 << (w - 1)) if name in TARGET_STATE_SIGNED else (0, 1 << w)
            assert lo <= v < hi, f"{name} = {v} does not fit {w} bits"
            word |= (v & ((1 << w) - 1)) << o
        assert unpack_target_state_v2(word, g) == st
    assert trk.lost
