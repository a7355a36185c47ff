"""Float reference, features: colour bins and Sobel edge bins, on the whole frame or on an area.

Colour: the top ``bits`` of each of B, G, R (docs/algorithm.md).  Edge: |Gx| + |Gy| of the
3 x 3 Sobel on the grey image, shifted and clipped to ``n_bins`` (the frame's 1-px border is 0).
The area versions give the whole frame's values bit for bit on any rectangle (the fast paths of
:mod:`mstrack.track.float_model`; tests/test_speed_equivalence.py).
"""
from __future__ import annotations

import cv2
import numpy as np

from .params import TrackerParams

GREY_WEIGHTS_BGR = (0.114, 0.587, 0.299)  # grey = 0.299 R + 0.587 G + 0.114 B (ITU-R BT.601)


# ----------------------------------------------------------------------------- features
def colour_bins(frame: np.ndarray, bits: int) -> np.ndarray:
    """Colour bin per pixel: ((R >> s) << 2b) | ((G >> s) << b) | (B >> s), s = 8 - b.

    frame: (H, W, 3) uint8 BGR.  Returns (H, W) int32 in [0, 2**(3b)).
    """
    s = 8 - bits
    f = frame.astype(np.int32) >> s
    return (f[:, :, 2] << (2 * bits)) | (f[:, :, 1] << bits) | f[:, :, 0]


def chroma_bins(frame: np.ndarray, bits: int, k: int) -> np.ndarray:
    """Normalised-chromaticity bin per pixel (TrackerParams.chroma_bins = k): with S = R + G + B,
    ((S >> (10 - k)) << 2b) | (floor(2**b R / (S + 1)) << b) | floor(2**b G / (S + 1)), b = ``bits``.

    frame: (H, W, 3) uint8 BGR.  Returns (H, W) int32 in [0, 2**(2b + k)) (integers throughout)."""
    f = frame.astype(np.int32)
    s = f[:, :, 0] + f[:, :, 1] + f[:, :, 2]
    return ((s >> (10 - k)) << (2 * bits)) | (((f[:, :, 2] << bits) // (s + 1)) << bits) | ((f[:, :, 1] << bits) // (s + 1))


def edge_magnitude(frame: np.ndarray) -> np.ndarray:
    """|G| = |Gx| + |Gy| of the 3x3 Sobel on the float grey image.

    frame: (H, W, 3) uint8 BGR.  Returns (H, W) float32 in [0, 2040]; the
    1-pixel frame border has no full 3x3 neighbourhood and gets |G| = 0.
    """
    grey = grey_area(frame, 0, frame.shape[1], 0, frame.shape[0])
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    mag = np.abs(gx) + np.abs(gy)
    mag[0, :] = mag[-1, :] = 0
    mag[:, 0] = mag[:, -1] = 0
    return mag


def edge_bins(frame: np.ndarray, n_bins: int, shift: int) -> np.ndarray:
    """Edge bin per pixel: min(E - 1, floor(|G| / 2**shift)).  Returns (H, W) int32."""
    return np.minimum(n_bins - 1, np.floor(edge_magnitude(frame) / float(1 << shift))).astype(np.int32)


def _features_full_frame(frame: np.ndarray, params: TrackerParams) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Colour and edge bin images of the whole frame (None for an unused feature).

    The reference path: the search-area functions below must give exactly
    these values on every pixel they compute (tests/test_speed_equivalence.py).
    """
    use_c = params.features in ("fused", "colour")
    use_e = params.features in ("fused", "edge")
    bc = colour_bins(frame, params.colour_bits) if use_c else None
    be = edge_bins(frame, params.n_edge_bins, params.edge_shift) if use_e else None
    return bc, be


# ----------------------------------------------------------------------------- features on an area
# Column alignment of the Sobel strip (px).  OpenCV's separable filter rounds the vectorised
# columns, (a + c) + 2b, differently from its scalar tail, (a + 2b) + c, and which columns are
# which depends on the column's offset in the row and on the row width.  A strip that starts on
# a multiple of SOBEL_ALIGN (a multiple of every SIMD width) and either ends on one or runs to the
# frame's right edge puts every column in the same class as in the whole-frame call.
SOBEL_ALIGN = 64
_GREY_W = tuple(np.float32(w) for w in GREY_WEIGHTS_BGR)


def grey_area(frame: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """Float32 grey of ``frame[y0:y1, x0:x1]``: (B wb + G wg) + R wr, element-wise in float32.

    Every path (whole frame, search area, numba kernel) computes the grey with
    these operations in this order, so they agree bit for bit by construction.
    No BLAS product is used: a matrix product's rounding depends on the BLAS
    kernel (numpy 2.4 / OpenBLAS 0.3.31 rounds ``frame @ weights`` differently).
    """
    b, g, r = cv2.split(frame[y0:y1, x0:x1])
    wb, wg, wr = _GREY_W
    out = b.astype(np.float32)
    out *= wb
    t = g.astype(np.float32)
    t *= wg
    out += t
    t = r.astype(np.float32)
    t *= wr
    out += t
    return out


def colour_bins_area(frame: np.ndarray, bits: int, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
    """``colour_bins(frame, bits)[y0:y1, x0:x1]`` from those pixels only.  (y1-y0, x1-x0) intp."""
    s = 8 - bits
    b, g, r = cv2.split(frame[y0:y1, x0:x1])
    out = (r >> s).astype(np.intp)  # type: ignore[operator]  # uint8 channels
    out <<= 2 * bits
    t = (g >> s).astype(np.intp)  # type: ignore[operator]
    t <<= bits
    out |= t
    out |= b >> s  # type: ignore[operator]
    return out


def edge_bins_area(frame: np.ndarray, n_bins: int, shift: int, x0: int, x1: int, y0: int,
                   y1: int, dtype: type = np.intp, kernels: bool = False) -> np.ndarray:
    """``edge_bins(frame, n_bins, shift)[y0:y1, x0:x1]`` from the grey of the area plus 1 px.

    The Sobel runs on a strip of rows y0-1 .. y1 whose columns are aligned as
    SOBEL_ALIGN describes (grey outside the area's 1-px ring is left 0: it
    reaches no pixel of the area); the frame border gets |G| = 0 as in
    :func:`edge_magnitude`.  ``kernels``: grey and bins by the numba kernels
    (one pass each, same float32 operations).  Returns (y1-y0, x1-x0) ``dtype``.
    """
    if kernels:  # imported here: numba_kernels imports this module's grey weights
        from .numba_kernels import _nb_edge_bins, _nb_grey
    height, width = frame.shape[:2]
    gx0, gx1 = max(x0 - 1, 0), min(x1 + 1, width)
    gy0, gy1 = max(y0 - 1, 0), min(y1 + 1, height)
    sx0 = gx0 - gx0 % SOBEL_ALIGN
    sx1 = -(-gx1 // SOBEL_ALIGN) * SOBEL_ALIGN
    if sx1 > width - SOBEL_ALIGN:
        sx1 = width
    whole = (sx0, sx1) == (gx0, gx1)
    if kernels:
        strip = (np.empty if whole else np.zeros)((gy1 - gy0, sx1 - sx0), np.float32)
        _nb_grey(frame, gx0, gx1, gy0, gy1, strip, gx0 - sx0)
    elif whole:
        strip = grey_area(frame, gx0, gx1, gy0, gy1)
    else:
        strip = np.zeros((gy1 - gy0, sx1 - sx0), np.float32)
        strip[:, gx0 - sx0: gx1 - sx0] = grey_area(frame, gx0, gx1, gy0, gy1)
    r0, c0 = y0 - gy0, x0 - sx0
    gx = cv2.Sobel(strip, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(strip, cv2.CV_32F, 0, 1, ksize=3)
    if kernels:
        out: np.ndarray = np.empty((y1 - y0, x1 - x0), dtype)
        _nb_edge_bins(gx, gy, r0, c0, shift, n_bins - 1, out)
    else:
        mag = np.abs(gx[r0: r0 + y1 - y0, c0: c0 + x1 - x0])
        mag += np.abs(gy[r0: r0 + y1 - y0, c0: c0 + x1 - x0])
        # floor(|G| / 2**shift) of a non-negative float32 = int(|G|) >> shift
        out = mag.astype(dtype)
        out >>= shift
        np.minimum(out, n_bins - 1, out=out)
    if y0 == 0:         # the frame border: |G| = 0, bin 0
        out[0, :] = 0
    if y1 == height:
        out[-1, :] = 0
    if x0 == 0:
        out[:, 0] = 0
    if x1 == width:
        out[:, -1] = 0
    return out

