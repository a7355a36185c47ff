"""Fixed-point tracker as a whole: exact values, width bounds, determinism, documentation."""
from __future__ import annotations

import numpy as np
import pytest

from mstrack import Status, Tracker
from mstrack.eval.agreement import shift_scene
from mstrack.fixed import FixedParams, FixedTracker, RESULT_FIELDS, widths
from mstrack.fixed import doc
from mstrack.track.params import TrackerParams


def _run(frames, box, trace=False, **params):
    tp, rest = TrackerParams.split(params)
    fp, _ = FixedParams.split(rest)
    trk = FixedTracker(tp, fp)
    out = [trk.init(frames[0], box)]
    traces = []
    for f in frames[1:]:
        out.append(trk.update(f, trace=trace))
        traces.append(trk.last_trace)
    return trk, out, traces


# ----------------------------------------------------------------------------- exact values
@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
def test_identical_frame_exact(kernel):
    """Same frame again: S = K 2^RF exactly, rho out = 1.0, alpha = 1/2, centre unchanged (odd box)."""
    f0, _, box = shift_scene(0, 0)          # 41 x 31: odd, the window is centred on the box
    trk, (r0, r1), _ = _run([f0, f0], box, kernel=kernel)
    K = trk._t.ker.K
    assert r1.extra["S_c"] == r1.extra["S_e"] == K << trk.fixed.rho_frac
    assert r1.extra["rho_c"] == r1.extra["rho_e"] == 1 << 16
    assert r1.extra["alpha_c"] == 128 and r1.alpha_c == 0.5
    assert r1.centre == r0.centre
    assert r1.extra["stop_c_name"] == r1.extra["stop_e_name"] == "shift"
    assert r1.iter_c == r1.iter_e == 1


def test_target_histogram_sums_to_K():
    f0, _, box = shift_scene(0, 0)
    for kernel in ("flat", "epanechnikov"):
        trk = FixedTracker(TrackerParams(kernel=kernel))
        trk.init(f0, box)
        assert trk._t.Q_c.sum() == trk._t.Q_e.sum() == trk._t.ker.K


def test_even_box_window_offset():
    """Documented limitation (docs/results_fixed.md): an even box size gets an odd window centred on
    round(c) (round half up), so on an unmoving target the centre moves +0.5 px on each even axis."""
    f0, _, box = shift_scene(0, 0, w=40, h=31)
    _, (r0, r1), _ = _run([f0, f0], box, features="colour")
    assert r1.centre[0] - r0.centre[0] == 0.5 and r1.centre[1] == r0.centre[1]


@pytest.mark.parametrize("features", ["colour", "edge", "fused"])
def test_fixed_finds_integer_shift(features):
    for dx, dy in ((3, -2), (-6, 4)):
        f0, f1, box = shift_scene(dx, dy)
        _, (r0, r1), _ = _run([f0, f1], box, features=features, eps2=0.01)
        err = np.hypot(r1.centre[0] - r0.centre[0] - dx, r1.centre[1] - r0.centre[1] - dy)
        assert err < 1.5, (features, dx, dy, err)  # window placement, see test_fixed_vs_float


def test_result_fields_and_api_equivalence():
    f0, f1, box = shift_scene(3, -2)
    _, (_, r_direct), _ = _run([f0, f1], box)
    trk = Tracker(model="fixed", preset="paper")
    trk.init(f0, box)
    r_api = trk.update(f1)
    for k in RESULT_FIELDS:
        assert k in r_api.extra and isinstance(r_api.extra[k], int)
        assert r_api.extra[k] == r_direct.extra[k]
    assert r_api.centre == (r_api.extra["cx"] / 256, r_api.extra["cy"] / 256)
    assert r_api.rho_c == r_api.extra["rho_c"] / 65536


def test_deterministic():
    f0, f1, box = shift_scene(2.75, 1.5)
    a = _run([f0, f1, f0], box, trace=True)
    b = _run([f0, f1, f0], box, trace=True)
    assert [r.extra for r in a[1]] == [r.extra for r in b[1]]
    assert a[2] == b[2]


# ----------------------------------------------------------------------------- width bounds
def _fits_u(v, bits):
    return 0 <= int(v) < (1 << bits)


def _fits_s(v, bits):
    return -(1 << (bits - 1)) <= int(v) < (1 << (bits - 1))


@pytest.mark.parametrize("kernel", ["flat", "epanechnikov"])
@pytest.mark.parametrize("size", [(3, 3), (41, 31), (127, 127), (200, 150)])
def test_intermediates_fit_widths(kernel, size):
    """Every traced intermediate fits the width widths() gives it (largest window included)."""
    rng = np.random.default_rng(sum(size))
    W, H = 320, 240
    noise = rng.integers(0, 256, (H, W, 3), dtype=np.uint8)
    blocks = np.repeat(np.repeat(rng.integers(0, 256, (H // 8, W // 8, 3), dtype=np.uint8), 8, 0), 8, 1)
    flat = np.full((H, W, 3), 200, np.uint8)
    box = (W // 2 - size[0] // 2, H // 2 - size[1] // 2, *size)
    tp, fp = TrackerParams(kernel=kernel), FixedParams()
    wd = widths(tp, fp)
    # init on a flat frame -> one bin in Q; then frames where that bin is rare push the weights up
    for frames in ([flat, blocks, noise], [blocks, noise, blocks], [noise, flat, noise]):
        trk, res, traces = _run(frames, box, trace=True, kernel=kernel)
        for r in res:
            e = r.extra
            assert _fits_u(e["cx"], wd.centre) and _fits_u(e["cy"], wd.centre)
            assert _fits_u(e["rho_c"], wd.rho_out) and e["rho_c"] <= 1 << 16
            assert _fits_u(e["alpha_c"], wd.alpha) and e["alpha_c"] <= 1 << fp.alpha_frac
        assert _fits_u(trk._t.ker.K, wd.hist) and _fits_u(trk._t.ker.D, wd.kd)
        for t in traces:
            for it in t["iter_colour"] + t["iter_edge"]:
                assert all(_fits_u(v, wd.hist) for v in it["H"])
                assert all(_fits_u(v, wd.count) for v in it["N"])
                assert all(_fits_s(v, wd.possum) for v in it["SX"] + it["SY"])
                assert all(_fits_u(v, wd.weight) for v in it["w"])
                assert _fits_u(it["S"], wd.rho_sum) and it["S"] <= trk._t.ker.K << fp.rho_frac
                assert _fits_u(it["Sw"], wd.sw)
                assert _fits_s(it["Swx"], wd.swx) and _fits_s(it["Swy"], wd.swx)
                H_ = np.asarray(it["H"], dtype=np.int64)
                assert _fits_u(int(H_.max()) * int(trk._t.ker.K) << (2 * fp.rho_frac), wd.sqrt_in)


def test_large_box_is_shrunk_to_max_window():
    f0 = shift_scene(0, 0, width=320, height=240)[0]
    r = Tracker(model="fixed", preset="paper").init(f0, (10, 10, 200, 150))
    assert r.status == Status.CLIPPED and (r.box.w, r.box.h) == (127, 127)


# ----------------------------------------------------------------------------- documentation
def test_fixed_point_doc_is_current():
    text = doc.DOC_PATH.read_text()
    assert doc.BEGIN in text and doc.END in text, "docs/fixed_point.md has no generated section"
    assert doc.render(text) == text, "docs/fixed_point.md is stale: run `python -m mstrack.fixed.doc`"


def test_doc_table_names_every_width():
    t = doc.table()
    for gen in ("HIST_W", "COUNT_W", "POSSUM_W", "KD_W", "SQRT_IN_W", "RHO_SUM_W", "RATIO_Q_W", "WEIGHT_W",
                "SW_W", "SWX_W", "SHIFT_Q_W", "CENTRE_ABS_W", "RHO_OUT_W", "ALPHA_W", "KVAL_W", "EPS2"):
        assert gen in t, gen
