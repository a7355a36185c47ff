"""Validation of input frames and boxes, shared by every tracker layer.

Documented behaviour for bad input (tested in tests/test_bad_input.py):

* ``None``, non-array, empty, wrong ndim, wrong channel count, non-uint8
  frames raise :class:`FrameError` (a ``ValueError``); the tracker state is
  untouched, so tracking can go on with the next frame.
* ndarray subclasses (``np.matrix``, masked arrays) are read as plain arrays (a uint8
  ``np.matrix`` is a grey frame).
* grey (2-D, or H x W x 1) uint8 frames are accepted and replicated into
  B = G = R (the colour histogram then only uses the grey diagonal).
* BGRA frames: the alpha channel is dropped.
* a frame whose size differs from the init frame raises :class:`FrameError`.
* boxes: non-finite, zero or negative sizes raise ``ValueError``; a box
  partly outside the frame is clipped to the frame (status ``CLIPPED``); a
  box entirely outside, or one that is smaller than 3 x 3 px after
  clipping, raises ``ValueError``.
"""
from __future__ import annotations

import math

import numpy as np

from .types import Box

MIN_BOX_SIZE = 3  # px: the smallest window with a pixel on each side of its centre


class FrameError(ValueError):
    """A frame cannot be tracked on; the tracker state is unchanged."""


def check_frame(frame: object, expect_shape: tuple[int, int] | None = None) -> np.ndarray:
    """Return ``frame`` as a contiguous (H, W, 3) uint8 BGR array or raise FrameError.

    Parameters
    ----------
    frame : array-like
        (H, W, 3) BGR, (H, W, 4) BGRA or (H, W) / (H, W, 1) grey, uint8.
    expect_shape : (H, W), optional
        Required frame size (the init frame's).
    """
    if frame is None:
        raise FrameError("frame is None (unreadable or corrupt image?)")
    if not isinstance(frame, np.ndarray):
        raise FrameError(f"frame must be a numpy array, got {type(frame).__name__}")
    if type(frame) is not np.ndarray:  # a subclass (np.matrix, masked array): its plain data
        frame = np.asarray(frame).view(np.ndarray)
    if frame.dtype != np.uint8:
        raise FrameError(f"frame must be uint8 (8-bit BGR as OpenCV gives it), got dtype {frame.dtype}")
    if frame.ndim == 3 and frame.shape[2] == 1:
        frame = frame[:, :, 0]
    if frame.ndim == 2:
        frame = np.repeat(frame[:, :, None], 3, axis=2)
    elif frame.ndim == 3 and frame.shape[2] == 4:
        frame = frame[:, :, :3]
    elif not (frame.ndim == 3 and frame.shape[2] == 3):
        raise FrameError(f"frame must be HxW, HxWx1, HxWx3 or HxWx4, got shape {frame.shape}")
    h, w = frame.shape[:2]
    if h < MIN_BOX_SIZE or w < MIN_BOX_SIZE:
        raise FrameError(f"frame too small: {w}x{h}")
    if expect_shape is not None and (h, w) != tuple(expect_shape):
        raise FrameError(
            f"frame size changed from {expect_shape[1]}x{expect_shape[0]} to {w}x{h}; "
            "call init() again to track at the new size")
    return np.ascontiguousarray(frame)


def clip_box(box: Box, width: int, height: int, lo: int = 0) -> tuple[Box, bool]:
    """Clip ``box`` to the pixels ``[lo, width - lo) x [lo, height - lo)``.

    Returns the clipped box and whether it changed.  Raises ``ValueError`` for
    a box with non-positive size, entirely outside, or smaller than
    ``MIN_BOX_SIZE`` after clipping.
    """
    box = Box.of(box)
    if box.w <= 0 or box.h <= 0:
        raise ValueError(f"box must have positive width and height, got {box}")
    x0 = max(box.x, float(lo))
    y0 = max(box.y, float(lo))
    x1 = min(box.x + box.w, float(width - lo))
    y1 = min(box.y + box.h, float(height - lo))
    if x1 <= x0 or y1 <= y0:
        raise ValueError(f"box {box.as_tuple()} lies entirely outside the {width}x{height} frame")
    if x1 - x0 < MIN_BOX_SIZE or y1 - y0 < MIN_BOX_SIZE:
        raise ValueError(
            f"box {box.as_tuple()} is smaller than {MIN_BOX_SIZE}x{MIN_BOX_SIZE} px inside the frame")
    out = Box(x0, y0, x1 - x0, y1 - y0)
    changed = any(not math.isclose(a, b) for a, b in zip(out.as_tuple(), box.as_tuple()))
    return out, changed
