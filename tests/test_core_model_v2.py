"""mstrack.hw.cosim.CoreModelV2, the stream-fault model of core v2 (docs/architecture.md, "Core v2:
stream faults"), against FixedTrackerV2 itself: a bad frame gives one error result with the state's
fields and leaves the tracking exactly as if it never came (also while lost); a bad init frame
keeps the init pending.  The RTL is compared with this model in tb/test_ms_tracker_v2_faults.py."""
from __future__ import annotations

import numpy as np
import pytest

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.fixed.vhdl_pkg import RESULT_FLAGS, STATUS_V2
from mstrack.hw.cosim import (COMPARED_FIELDS_V2, ERR_CUT, ERR_SHORT_LINE, ERR_SIZE_CHANGED, CoreModelV2,
                              expected_results_v2, frame_words, words_frame)
from mstrack.io.synthetic import make_scene
from mstrack.track.params import TrackerParams

W, H = 48, 40
TP, FP = TrackerParams(preset="v2"), FixedParams()
ERROR, NO_TARGET = 1 << RESULT_FLAGS.index("error"), 1 << RESULT_FLAGS.index("no_target")


def _scene(n: int, seed: int = 19) -> tuple[list[np.ndarray], tuple[int, int, int, int]]:
    frames, gt = make_scene(n, W, H, seed=seed, target_size=(14, 12))
    return [frame_words(f) for f in frames], round_box(*map(float, gt[0]))


def _beats(words: np.ndarray, fault: str | None = None) -> list[tuple[int, int, int]]:
    """One frame's beats; short_line: row 5 three pixels short; cut: the first 700 beats only."""
    out = []
    for y, row in enumerate(words):
        px = [int(v) for v in row][: W - 3 if fault == "short_line" and y == 5 else W]
        out += [(v, int(y == 0 and x == 0), int(x == len(px) - 1)) for x, v in enumerate(px)]
    return out[:700] if fault == "cut" else out


def _run(frames: list[np.ndarray], box: tuple[int, int, int, int], faults: dict[int, str]) -> CoreModelV2:
    m = CoreModelV2(TP, FP, 64)
    m.init(box, W, H)
    for i, f in enumerate(frames):
        for b in _beats(f, faults.get(i)):
            m.beat(*b, W, H)
    return m


def _check(m: CoreModelV2, frames: list[np.ndarray], box: tuple[int, int, int, int], bad: set[int]) -> None:
    """The results that are not errors equal FixedTrackerV2 on the good frames alone."""
    exp = expected_results_v2([words_frame(f) for i, f in enumerate(frames) if i not in bad], box, TP, FP)
    good = [(i, r) for i, r in enumerate(m.results) if not m.kinds[i].startswith("error")]
    assert len(good) == len(exp)
    for (i, r), e in zip(good, exp):
        assert {k: r[k] for k in COMPARED_FIELDS_V2} == {**e, "frame_count": i}, i


def test_bad_tracking_frame_keeps_the_state() -> None:
    frames, box = _scene(6)
    m = _run(frames, box, {2: "short_line"})
    assert m.kinds == ["init", "track", "error:short_line", "track", "track", "track"]
    e, prev = m.results[2], m.results[1]
    assert e["status"] == STATUS_V2.index("error") and e["flags"] == ERROR and e["err_code"] == ERR_SHORT_LINE
    assert [e[k] for k in ("cx", "cy", "w8", "h8")] == [prev[k] for k in ("cx", "cy", "w8", "h8")]
    assert [e[k] for k in ("rho", "confidence", "iter", "stop", "decim_log2", "searched")] == [0] * 6
    _check(m, frames, box, {2})


def test_bad_init_frames_keep_the_init_pending() -> None:
    frames, box = _scene(6)
    # the init frame cut (its error comes with the next start of frame), then a frame of another size
    m = _run(frames[:1], box, {0: "cut"})
    for b in _beats(frames[1][:32, :40]):
        m.beat(*b, 40, 32)
    for f in frames[2:5]:
        for b in _beats(f):
            m.beat(*b, W, H)
    assert m.kinds == ["error:cut", "error:size_changed", "init", "track", "track"]
    x, y, w, h = box
    for r, code in zip(m.results[:2], (ERR_CUT, ERR_SIZE_CHANGED)):
        assert r["flags"] == ERROR | NO_TARGET and r["err_code"] == code
        assert (r["cx"], r["cy"], r["w8"], r["h8"]) == ((2 * x + w - 1) << 7, (2 * y + h - 1) << 7, w << 8, h << 8)
    exp = expected_results_v2([words_frame(f) for f in frames[2:5]], box, TP, FP)
    for r, e in zip(m.results[2:], exp):
        assert {k: r[k] for k in COMPARED_FIELDS_V2 if k != "frame_count"} == \
            {k: e[k] for k in COMPARED_FIELDS_V2 if k != "frame_count"}


def test_bad_frame_while_lost_keeps_searching() -> None:
    frames, box = _scene(8)
    flat = np.full((H, W), 0x204060, dtype=np.int64)
    frames = frames[:2] + [flat, flat, flat] + frames[5:]
    m = _run(frames, box, {3: "short_line"})
    assert m.results[2]["status"] == STATUS_V2.index("lost")
    assert m.kinds[3] == "error:short_line" and m.results[4]["searched"] == 8
    _check(m, frames, box, {3})


@pytest.mark.parametrize("kw,what", [({"motion_gain": 0.5}, "motion_gain"),
                                     ({"scale_test": 0.05, "scale_test_gate": False}, "scale_test without scale_test_gate"),
                                     ({"orient_T": 64, "motion_gain": 0.5}, "motion_gain"),
                                     ({"loss_ref_running": True}, "loss_ref_running"),
                                     ({"scale_test_margin": 0.005}, "scale_test_margin"),
                                     ({"search_widen": 2}, "search_widen"),
                                     ({"rho_stop_margin": 0.002}, "rho_stop_margin"),
                                     ({"loss_jump": 1.25}, "loss_jump"),
                                     ({"scale_ring_guard": 0.5}, "scale_ring_guard"),
                                     ({"model_rate": 0.0625}, "model_rate"), ({"model_mix": 0.5}, "model_mix"),
                                     ({"chroma_bins": 2}, "chroma_bins"),
                                     ({"model_contrast": 0.15}, "model_contrast"),
                                     ({"model_frac": 4}, "model_frac"), ({"bg_frac": 16}, "bg_frac")])
def test_core_config_v2_refuses_options_without_rtl(kw, what):
    """The experimental v2 options without RTL (motion_gain; the ungated scale test) are in
    the float (and fixed) models only: a core configuration for them is refused with a one-line
    reason, not built as a core that tracks differently."""
    from mstrack.fixed.formats import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import TrackerParams
    fp, kw = FixedParams.split(kw)
    with pytest.raises(ValueError, match="no RTL yet for " + what):
        CoreConfigV2(TrackerParams(preset="v2", **kw), fp)


def test_core_config_v2_joint():
    """The default tracker v2 (the joint bins) has ORIENT_T = orient_T (64) beside
    SCALE_TEST_D256 13 and the loss thresholds, for ms_tracker_v2 and ms_tracker (PRESET 1); every other
    generic as without the joint bins."""
    from mstrack.fixed.formats import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import V2_JOINT, TrackerParams
    assert TrackerParams(preset="v2") == TrackerParams(preset="v2", **V2_JOINT)   # the default
    j = CoreConfigV2(TrackerParams(preset="v2", **V2_JOINT), FixedParams()).generics()
    o = CoreConfigV2(TrackerParams(preset="v2", **{**V2_JOINT, "orient_T": 0}), FixedParams()).generics()
    assert j.pop("ORIENT_T") == 64 and o.pop("ORIENT_T") == -1 and j == o
    assert CoreConfigV2(TrackerParams(preset="v2", **V2_JOINT), FixedParams()).tracker_generics()["ORIENT_T"] == 64
    with pytest.raises(ValueError, match="edge_bins_log2"):
        CoreConfigV2(TrackerParams(preset="v2", **V2_JOINT, edge_bins_log2=3), FixedParams()).generics()


def test_core_config_v2_gated_scale_test():
    """The gated scale test (the default scale_test 0.05 + gate) has RTL: generic SCALE_TEST_D256 =
    round(256 scale_test) = 13 of ms_tracker_v2 and of ms_tracker (PRESET 1 passes it on), the VHDL
    default; off (mstrack-v2-colour's), it is 0 and every other generic is the same."""
    from mstrack.fixed.formats import FixedParams
    from mstrack.hw.cosim import CoreConfigV2
    from mstrack.track.params import TrackerParams
    on = CoreConfigV2(TrackerParams(preset="v2", orient_T=0), FixedParams())
    off = CoreConfigV2(TrackerParams(preset="v2", orient_T=0, scale_test=0.0, scale_test_gate=False), FixedParams())
    g, g_off = on.generics(), off.generics()
    assert g.pop("SCALE_TEST_D256") == 13 and g_off.pop("SCALE_TEST_D256") == 0
    assert g == g_off
    assert on.generics_for("ms_tracker_v2")["SCALE_TEST_D256"] == 13
    assert on.tracker_generics() == {"PRESET": 1, **on.generics()}
    assert on.generics_for("ms_tracker")["SCALE_TEST_D256"] == 13
    assert g_off["ORIENT_T"] == -1
    with pytest.raises(ValueError, match="d256"):   # d256 = 0: the generic's "off" while the model gates
        CoreConfigV2(TrackerParams(preset="v2", scale_test=0.001, scale_test_gate=True), FixedParams()).generics()
    assert CoreConfigV2(TrackerParams(preset="v2", scale_test=0.5, scale_test_gate=True),
                        FixedParams()).generics()["SCALE_TEST_D256"] == 128   # TrackerParams: scale_test <= 0.5
