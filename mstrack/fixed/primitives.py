"""Integer primitives of the fixed-point model, each with one exact definition.

Every function here has two forms: a vectorised numpy form used by the model,
and a bit-serial reference (``*_reference``) that spells out, step by step,
the algorithm the RTL implements (one pipeline stage per result bit).  Tests
check the two against each other on exhaustive and large random sets.

* :func:`ms_isqrt` -- floor(sqrt(x)), digit-by-digit (restoring) square root,
  ``rtl/ms_isqrt.vhd``.
* :func:`ms_divider` -- floor(n / d) with saturation, restoring division,
  ``rtl/ms_divider.vhd``.
"""
from __future__ import annotations

import numpy as np

MAX_ISQRT_BITS = 62  # numpy path: inputs up to 2**62 (roots < 2**31, squares fit in int64)


def _as_i64(x: np.ndarray | int) -> np.ndarray:
    a = np.asarray(x, dtype=np.int64)
    if np.any(a < 0):
        raise ValueError("negative input to an unsigned integer primitive")
    return a


def ms_isqrt(x: np.ndarray | int) -> np.ndarray:
    """floor(sqrt(x)) for integers 0 <= x < 2**62, exact.  Vectorised.

    Float sqrt gives a first guess that is off by at most one for these
    inputs; two correction rounds each way make it exact.
    """
    a = _as_i64(x)
    if np.any(a >= (1 << MAX_ISQRT_BITS)):
        raise ValueError("ms_isqrt input out of range (>= 2**62)")
    r = np.floor(np.sqrt(a.astype(np.float64))).astype(np.int64)
    for _ in range(2):
        r = np.where(r * r > a, r - 1, r)
        r = np.where((r + 1) * (r + 1) <= a, r + 1, r)
    return r


def ms_isqrt_reference(x: int, in_bits: int) -> int:
    """Digit-by-digit square root, the algorithm of rtl/ms_isqrt.vhd.

    ``in_bits`` (even) is the input width; the root has in_bits / 2 bits.
    Stage i (i = in_bits/2 - 1 down to 0) brings down the next two input bits
    into the remainder and tries to subtract (4 * root + 1): if the trial is
    >= 0 the root bit is 1 and the remainder is the trial, else the bit is 0.
    """
    if in_bits % 2:
        raise ValueError("in_bits must be even")
    if not 0 <= x < (1 << in_bits):
        raise ValueError("input does not fit in in_bits")
    root = 0
    rem = 0
    for i in range(in_bits // 2 - 1, -1, -1):
        rem = (rem << 2) | ((x >> (2 * i)) & 3)
        trial = rem - ((root << 2) | 1)
        if trial >= 0:
            rem = trial
            root = (root << 1) | 1
        else:
            root = root << 1
    return root


def ms_divider(n: np.ndarray | int, d: np.ndarray | int, q_bits: int) -> np.ndarray:
    """min(floor(n / d), 2**q_bits - 1) for n >= 0, d > 0.  Vectorised.

    The quotient saturates to all ones when it does not fit in ``q_bits``
    (the hardware detects this before the first stage: n >= d << q_bits).
    """
    nn = _as_i64(n)
    dd = _as_i64(d)
    if np.any(dd == 0):
        raise ValueError("ms_divider: division by zero (callers must handle d = 0)")
    return np.minimum(nn // dd, (1 << q_bits) - 1)


def ms_divider_reference(n: int, d: int, q_bits: int) -> int:
    """Restoring division, the algorithm of rtl/ms_divider.vhd.

    If n >= d * 2**q_bits the result saturates to 2**q_bits - 1.  Otherwise
    stage i (i = q_bits - 1 down to 0) compares the partial remainder with
    d * 2**i: if it is >= the quotient bit i is 1 and d * 2**i is subtracted.
    """
    if d <= 0 or n < 0:
        raise ValueError("ms_divider_reference needs n >= 0, d > 0")
    if n >= (d << q_bits):
        return (1 << q_bits) - 1
    q = 0
    rem = n
    for i in range(q_bits - 1, -1, -1):
        if rem >= (d << i):
            rem -= d << i
            q |= 1 << i
    return q


def round_div_signed(num: np.ndarray | int, den: np.ndarray | int, q_bits: int) -> np.ndarray:
    """Signed division rounding half away from zero: sign(num) * floor((|num| + den // 2) / den).

    den > 0.  The magnitude goes through :func:`ms_divider` (so it saturates
    at 2**q_bits - 1 like the hardware).
    """
    nn = np.asarray(num, dtype=np.int64)
    dd = np.asarray(den, dtype=np.int64)
    mag = ms_divider(np.abs(nn) + (dd >> 1), dd, q_bits)
    return np.where(nn < 0, -mag, mag)


def bits_for(max_value: int) -> int:
    """Unsigned bits needed to hold 0..max_value."""
    return max(1, int(max_value).bit_length())
