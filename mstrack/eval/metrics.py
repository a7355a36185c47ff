"""OTB one-pass-evaluation metrics (Wu, Lim, Yang, CVPR 2013 / TPAMI 2015).

Boxes are ``(x, y, w, h)`` rows in the convention of :mod:`mstrack.track.types`
(0-based, left/top + size, covering ``[x, x + w) x [y, y + h)``); the
overlap is the area of the continuous intersection, as in OTB's
``calcRectInt`` (its ``-1``/``+1`` cancel).  Centre errors are differences of
centres, so the centre convention cancels.

Frames whose ground truth is invalid (any NaN, or ``w <= 0`` or ``h <= 0``)
are excluded from the curves (:func:`valid_gt`).  A tracker box that is NaN or
has non-positive size counts as a failure (IoU 0, centre error +inf).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..track.types import Box  # noqa: F401  (box convention, see module docstring)

#: IoU thresholds of the success plot: 0, 0.05, ..., 1 (21 values).
IOU_THRESHOLDS = np.linspace(0.0, 1.0, 21)
#: Centre-error thresholds of the precision plot: 0, 1, ..., 50 px (51 values).
CE_THRESHOLDS = np.arange(0, 51, dtype=np.float64)
#: The precision plot's summary threshold (px).
PRECISION_AT = 20


def _as_boxes(a: np.ndarray | list) -> np.ndarray:
    b = np.asarray(a, dtype=np.float64)
    if b.ndim == 1:
        b = b[None, :]
    if b.ndim != 2 or b.shape[1] != 4:
        raise ValueError(f"boxes must have shape (N, 4), got {b.shape}")
    return b


def valid_gt(gt: np.ndarray) -> np.ndarray:
    """Mask of usable ground-truth rows.

    Parameters
    ----------
    gt : array_like, shape (N, 4)

    Returns
    -------
    ndarray of bool, shape (N,)
        True where all four values are finite and ``w > 0`` and ``h > 0``.
    """
    g = _as_boxes(gt)
    with np.errstate(invalid="ignore"):
        return np.isfinite(g).all(axis=1) & (g[:, 2] > 0) & (g[:, 3] > 0)


def iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Intersection over union of paired boxes.

    Parameters
    ----------
    a, b : array_like, shape (N, 4) or (4,)
        Boxes ``(x, y, w, h)`` in pixels.

    Returns
    -------
    ndarray, shape (N,)
        IoU in [0, 1]; 0 where either box is NaN or has non-positive size.
    """
    a, b = np.broadcast_arrays(_as_boxes(a), _as_boxes(b))
    with np.errstate(invalid="ignore", divide="ignore"):
        iw = np.minimum(a[:, 0] + a[:, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, 0], b[:, 0])
        ih = np.minimum(a[:, 1] + a[:, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, 1], b[:, 1])
        inter = np.clip(iw, 0, None) * np.clip(ih, 0, None)
        union = a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter
        out = inter / union
    ok = valid_gt(a) & valid_gt(b) & np.isfinite(out)
    return np.where(ok, np.clip(out, 0.0, 1.0), 0.0)


def centre_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance between box centres.

    Parameters
    ----------
    a, b : array_like, shape (N, 4) or (4,)

    Returns
    -------
    ndarray, shape (N,)
        Distance in pixels; +inf where either box is invalid.
    """
    a, b = np.broadcast_arrays(_as_boxes(a), _as_boxes(b))
    d = np.hypot((a[:, 0] + a[:, 2] / 2) - (b[:, 0] + b[:, 2] / 2),
                 (a[:, 1] + a[:, 3] / 2) - (b[:, 1] + b[:, 3] / 2))
    return np.where(valid_gt(a) & valid_gt(b) & np.isfinite(d), d, np.inf)


def success_curve(ious: np.ndarray, thresholds: np.ndarray = IOU_THRESHOLDS) -> np.ndarray:
    """Fraction of frames with IoU strictly above each threshold.

    Parameters
    ----------
    ious : array_like, shape (N,)
        Per-frame IoU of the valid frames.
    thresholds : array_like, shape (T,)

    Returns
    -------
    ndarray, shape (T,)
        Zeros if ``N == 0``.
    """
    v = np.asarray(ious, dtype=np.float64).ravel()
    if v.size == 0:
        return np.zeros(len(thresholds))
    return (v[None, :] > np.asarray(thresholds)[:, None]).mean(axis=1)


def precision_curve(errors: np.ndarray, thresholds: np.ndarray = CE_THRESHOLDS) -> np.ndarray:
    """Fraction of frames with centre error at most each threshold.

    Parameters
    ----------
    errors : array_like, shape (N,)
        Per-frame centre error (px) of the valid frames.
    thresholds : array_like, shape (T,)
        Pixels.

    Returns
    -------
    ndarray, shape (T,)
        Zeros if ``N == 0``.
    """
    v = np.asarray(errors, dtype=np.float64).ravel()
    if v.size == 0:
        return np.zeros(len(thresholds))
    return (v[None, :] <= np.asarray(thresholds)[:, None]).mean(axis=1)


def auc(success: np.ndarray) -> float:
    """Area under the success curve as OTB reports it: the mean of the curve."""
    return float(np.mean(success))


@dataclass
class Scores:
    """Summary of one tracker on a set of frames.

    Attributes
    ----------
    ious, errors : ndarray, shape (N,)
        Per-frame IoU and centre error (px) over the valid-GT frames.
    success : ndarray, shape (21,)
    precision : ndarray, shape (51,)
    auc : float
        Mean of ``success``.
    precision20 : float
        ``precision`` at 20 px.
    n_frames : int
        Number of valid frames N.
    """

    ious: np.ndarray
    errors: np.ndarray
    success: np.ndarray
    precision: np.ndarray
    auc: float
    precision20: float
    n_frames: int


def score_frames(ious: np.ndarray, errors: np.ndarray) -> Scores:
    """Curves and summary numbers from per-frame IoU and centre errors (already filtered)."""
    ious = np.asarray(ious, dtype=np.float64).ravel()
    errors = np.asarray(errors, dtype=np.float64).ravel()
    s = success_curve(ious)
    p = precision_curve(errors)
    return Scores(ious, errors, s, p, auc(s), float(p[PRECISION_AT]), int(ious.size))


def score(pred: np.ndarray, gt: np.ndarray) -> Scores:
    """Score predicted boxes against ground truth (OTB OPE on one sequence).

    Parameters
    ----------
    pred, gt : array_like, shape (N, 4)
        Predicted and ground-truth boxes, frame-aligned.  Frames with invalid
        ground truth are dropped.
    """
    p, g = _as_boxes(pred), _as_boxes(gt)
    if p.shape != g.shape:
        raise ValueError(f"pred {p.shape} and gt {g.shape} differ in shape")
    m = valid_gt(g)
    return score_frames(iou(p[m], g[m]), centre_error(p[m], g[m]))


def concat_scores(parts: list[Scores]) -> Scores:
    """Frame-weighted aggregate (OTB style): concatenate the per-frame values."""
    if not parts:
        return score_frames(np.zeros(0), np.zeros(0))
    return score_frames(np.concatenate([s.ious for s in parts]),
                        np.concatenate([s.errors for s in parts]))


@dataclass
class LossDetection:
    """How well a tracker's ``ok`` flag tells when it is off the target (the loss signal).

    off: frames with IoU = 0 (off the target); recall: share of them with ok False.
    on: frames with IoU >= 0.5 (on the target); false_alarm: share of them with ok False.
    """

    off: int
    recall: float
    on: int
    false_alarm: float


def loss_detection(ious: np.ndarray, ok: np.ndarray) -> LossDetection:
    """Per-frame loss recall and false-alarm rate from IoUs and the tracker's ok flags (same length;
    pass only frames with valid ground truth)."""
    ious, ok = np.asarray(ious, dtype=np.float64), np.asarray(ok, dtype=bool)
    if ious.shape != ok.shape:
        raise ValueError(f"ious {ious.shape} and ok {ok.shape} differ in shape")
    off, on = ious == 0, ious >= 0.5
    return LossDetection(int(off.sum()), float((off & ~ok).sum() / off.sum()) if off.any() else float("nan"),
                         int(on.sum()), float((on & ~ok).sum() / on.sum()) if on.any() else float("nan"))
