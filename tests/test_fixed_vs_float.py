"""Fixed-point model against the float reference: synthetic shifts and real-data agreement.

Thresholds and their reasons are in docs/results_fixed.md.
"""
from __future__ import annotations

import math

import numpy as np

import pytest

from mstrack import Tracker
from mstrack.eval.agreement import (AUC_DIFF_MAX, DEFAULT_ROOT, MEAN_DIFF_MAX, compare_all, shift_scene)

INT_SHIFTS = [(3, -2), (-6, 4), (8, 8), (0, 0)]
SUB_SHIFTS = [(0.5, -0.25), (2.75, 1.5), (-1.25, -3.5)]

#: |c_fixed - c_float| bound on the synthetic scene: 0.5 px for the integer
#: window placement (the fixed loop places its window at round(c) and stops
#: once round(c) repeats, returning one mean-shift step from that integer
#: window; the float window follows c continuously) + 0.25 px stated
#: tolerance (weights 4.4, rho terms 6 fraction bits, centre 8 fraction bits).
#: Measured maximum 0.72 px (colour, flat, integer shifts) with eps2 = 0.01.
#: With the default eps2 = 1 px^2 either loop may stop up to sqrt(eps2) = 1 px
#: short of the optimum (last step < 1 px), so the bound there is 0.5 + 1.0.
SYNTH_TOL = 0.5 + 0.25


def synth_tol(eps2: float) -> float:
    return SYNTH_TOL if eps2 <= 0.01 else 0.5 + math.sqrt(eps2)


def _both(dx, dy, **params):
    f0, f1, box = shift_scene(dx, dy)
    out = []
    for model in ("float", "fixed"):
        trk = Tracker(model=model, **{"preset": "paper", **params})  # the paper model unless asked
        trk.init(f0, box)
        out.append(trk.update(f1))
    return out


@pytest.mark.parametrize("eps2", [0.01, 1.0])
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
@pytest.mark.parametrize("features", ["colour", "fused"])
@pytest.mark.parametrize("dx,dy", INT_SHIFTS + SUB_SHIFTS)
def test_synthetic_shift_same_convergence(features, kernel, dx, dy, eps2):
    rf, rx = _both(dx, dy, features=features, kernel=kernel, eps2=eps2)
    d = math.hypot(rf.centre[0] - rx.centre[0], rf.centre[1] - rx.centre[1])
    assert d < synth_tol(eps2), f"float {rf.centre} fixed {rx.centre}: {d:.3f} px"
    assert rx.status == rf.status


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
@pytest.mark.parametrize("dx,dy", INT_SHIFTS)
def test_synthetic_shift_edge_integer(kernel, dx, dy):
    """Edge only on integer shifts: sub-pixel resampling changes the Sobel magnitudes (see test_float_model)."""
    rf, rx = _both(dx, dy, features="edge", kernel=kernel, eps2=0.01)
    assert math.hypot(rf.centre[0] - rx.centre[0], rf.centre[1] - rx.centre[1]) < SYNTH_TOL


@pytest.mark.parametrize("features", ["colour", "fused", "edge"])
def test_synthetic_rho_and_alpha_agree(features):
    rf, rx = _both(3, -2, features=features, eps2=0.01)
    # rho: the fixed value (floor(S 2**10 / K), 6-bit terms: quantisation <= 0.002 here) is
    # taken at its own final integer window, up to 0.72 px from the float centre, where rho
    # is up to 0.03 lower on this sharp-edged target (measured 0.026) -> bound 0.04.
    for a, b in ((rf.rho_c, rx.rho_c), (rf.rho_e, rx.rho_e)):
        assert abs(a - b) < 0.04
    assert abs(rf.alpha_c - rx.alpha_c) < 0.02
    assert rx.alpha_c + rx.alpha_e == 1.0


# ----------------------------------------------------------------------------- real data
#: Regression bounds (current behaviour, docs/results_fixed.md), NOT the target (mean < 0.5 px, |dAUC| <= 0.01).
HOLDS_MEAN_MAX = 2.0   # px, sequences where the float tracker holds the target
HOLDS_AUC_MAX = 0.03
ALL_AUC_MAX = 0.2      # every sequence (Couple: the fixed model loses the target at frame 6)


@pytest.fixture(scope="module")
def agreement():
    if not DEFAULT_ROOT.is_dir():
        pytest.skip(f"real sequences not found at {DEFAULT_ROOT}")
    return compare_all(DEFAULT_ROOT)


def test_real_data_regression(agreement):
    assert len(agreement) >= 1
    bad = []
    for a in agreement:
        if abs(a.auc_diff) > ALL_AUC_MAX:
            bad.append(f"{a.sequence}: dAUC {a.auc_diff:+.3f}")
        if a.holds and (a.mean > HOLDS_MEAN_MAX or abs(a.auc_diff) > HOLDS_AUC_MAX):
            bad.append(f"{a.sequence}: mean {a.mean:.2f} px, dAUC {a.auc_diff:+.3f}")
    assert not bad, "; ".join(bad)


def test_real_data_init_agrees(agreement):
    """Frame 0: integer init boxes agree exactly; others within the box rounding.

    Fractional (VOT) boxes: edges rounded half up, <= 0.5 px per axis; a box larger than
    2 * MAX_HALF + 1 = 127 px is shrunk about its centre with a floor, another 0.5 px
    (bag_vot: 146 x 132.5 -> 127 x 127, measured 0.716 px).
    """
    for a in agreement:
        assert a.diff[0] <= 1.0, (a.sequence, a.diff[0])


@pytest.mark.xfail(reason="target not met: integer-grid window placement (kept by decision, "
                          "docs/results_fixed.md 'Decision') puts the fixed loop ~1 px from the float one",
                   strict=True)
def test_real_data_mean_centre_diff_and_auc_target(agreement):
    """Issue target: mean centre difference < 0.5 px and |dAUC| <= 0.01 where the float tracker holds."""
    held = [a for a in agreement if a.holds]
    assert held
    for a in held:
        assert a.mean < MEAN_DIFF_MAX and abs(a.auc_diff) <= AUC_DIFF_MAX, a.row()


def test_write_table_replaces_marked_section(tmp_path):
    from mstrack.eval.agreement import write_table

    p = tmp_path / "r.md"
    p.write_text("# title\n\ntext\n")
    write_table("| a |", p, command="cmd 1")
    write_table("| b |", p, command="cmd 2")
    write_table("| s |", p, command="cmd 3", section="sweep")
    text = p.read_text()
    assert text.count("agreement-table:begin") == 1 and "| b |" in text and "| a |" not in text
    assert "cmd 2" in text and "| s |" in text and text.startswith("# title\n\ntext\n")
    write_table("| c |", p, command="cmd 4")
    assert p.read_text().index("| c |") < p.read_text().index("| s |")


def test_grid_analysis_reproduces_window_quantisation():
    """The grid analysis of docs/results_fixed.md: snapping only the float window to the 1 px grid
    moves the float tracker by about as much as the fixed model differs; a finer grid moves it less.
    Grid 0 must be the unmodified float tracker (the snap is undone after the call)."""
    from mstrack.eval.agreement import DEFAULT_ROOT, float_on_grid

    seq = DEFAULT_ROOT / "Girl"
    if not seq.is_dir():
        pytest.skip(f"{seq} not found: the grid analysis needs ../shared/data/sequences")
    ref = float_on_grid(seq, 0.0, max_frames=120)
    d1 = np.hypot(*(float_on_grid(seq, 1.0, max_frames=120) - ref).T).mean()
    d4 = np.hypot(*(float_on_grid(seq, 0.25, max_frames=120) - ref).T).mean()
    again = float_on_grid(seq, 0.0, max_frames=120)
    assert np.array_equal(again, ref)
    assert d1 > 0.3 and d4 < d1
