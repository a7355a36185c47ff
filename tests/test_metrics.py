"""OTB metrics on hand-made cases with exactly computed expected values."""
import numpy as np
import pytest

from mstrack.eval.metrics import (CE_THRESHOLDS, IOU_THRESHOLDS, centre_error, concat_scores, iou, precision_curve,
                             score, success_curve, valid_gt)


def test_iou_identical_disjoint_touching():
    a = np.array([[10, 20, 30, 40], [0, 0, 1, 1]], float)
    assert iou(a, a) == pytest.approx([1.0, 1.0])
    assert iou([0, 0, 10, 10], [20, 20, 5, 5]) == pytest.approx([0.0])
    # edge-adjacent boxes share no area ([0,10) and [10,20))
    assert iou([0, 0, 10, 10], [10, 0, 10, 10]) == pytest.approx([0.0])


def test_iou_partial_exact():
    # half-overlap along x: inter 50, union 150
    assert iou([0, 0, 10, 10], [5, 0, 10, 10])[0] == pytest.approx(1 / 3)
    # corner overlap 2x2 of two 4x4 boxes: inter 4, union 28
    assert iou([0, 0, 4, 4], [2, 2, 4, 4])[0] == pytest.approx(1 / 7)
    # containment: 2x2 inside 4x4
    assert iou([0, 0, 4, 4], [1, 1, 2, 2])[0] == pytest.approx(4 / 16)
    # vectorised and symmetric
    a = np.array([[0, 0, 10, 10], [0, 0, 4, 4]], float)
    b = np.array([[5, 0, 10, 10], [2, 2, 4, 4]], float)
    assert iou(a, b) == pytest.approx([1 / 3, 1 / 7])
    assert iou(b, a) == pytest.approx([1 / 3, 1 / 7])


def test_iou_invalid_boxes_are_zero():
    a = np.array([[0, 0, 10, 10]] * 3, float)
    b = np.array([[np.nan, 0, 10, 10], [0, 0, 0, 10], [0, 0, 10, -1]], float)
    assert iou(a, b) == pytest.approx([0, 0, 0])


def test_valid_gt():
    g = np.array([[0, 0, 1, 1], [np.nan] * 4, [0, 0, 0, 5], [0, 0, 5, -2], [1, 2, 3, 4]], float)
    assert valid_gt(g).tolist() == [True, False, False, False, True]


def test_centre_error():
    assert centre_error([0, 0, 10, 10], [3, 4, 10, 10])[0] == pytest.approx(5.0)
    # same centre, different size -> 0
    assert centre_error([0, 0, 10, 10], [2, 2, 6, 6])[0] == pytest.approx(0.0)
    assert np.isinf(centre_error([0, 0, 10, 10], [np.nan, 0, 10, 10])[0])


def test_thresholds():
    assert len(IOU_THRESHOLDS) == 21 and IOU_THRESHOLDS[0] == 0 and IOU_THRESHOLDS[-1] == 1
    assert CE_THRESHOLDS.tolist() == list(range(51))


def test_success_curve_exact():
    ious = [0.0, 0.33, 0.62, 1.0]
    expected = [0.75] * 7 + [0.5] * 6 + [0.25] * 7 + [0.0]   # t=0..0.30, 0.35..0.60, 0.65..0.95, 1.0
    s = success_curve(ious)
    assert s == pytest.approx(expected)
    assert np.mean(s) == pytest.approx(10 / 21)


def test_precision_curve_exact():
    errs = [0.0, 5.0, 20.0, 20.5, np.inf]
    p = precision_curve(errs)
    expected = [0.2] * 5 + [0.4] * 15 + [0.6] + [0.8] * 30    # t=0..4, 5..19, 20, 21..50
    assert p == pytest.approx(expected)
    assert p[20] == pytest.approx(0.6)


def test_score_excludes_invalid_gt_and_perfect_run():
    gt = np.array([[0, 0, 10, 10], [np.nan] * 4, [5, 5, 0, 3], [2, 2, 10, 10]], float)
    pred = np.array([[0, 0, 10, 10], [100, 100, 5, 5], [0, 0, 1, 1], [2, 2, 10, 10]], float)
    sc = score(pred, gt)
    assert sc.n_frames == 2
    # perfect on the two valid frames: success 1 for every threshold < 1, 0 at 1
    assert sc.auc == pytest.approx(20 / 21)
    assert sc.precision20 == 1.0


def test_concat_scores_is_frame_weighted():
    one = score(np.array([[0, 0, 10, 10]], float), np.array([[0, 0, 10, 10]], float))
    three = score(np.full((3, 4), [50, 50, 10, 10], float), np.full((3, 4), [0, 0, 10, 10], float))
    agg = concat_scores([one, three])
    assert agg.n_frames == 4
    assert agg.success[10] == pytest.approx(0.25)       # not the per-sequence mean 0.5
    assert agg.precision20 == pytest.approx(0.25)
