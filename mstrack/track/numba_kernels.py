"""Float reference, numba path: the ``@jit`` kernels (mean shift of one feature in one call,
pairwise sums, Sobel / grey on an area) and their work buffers.

Compiled with an on-disk cache (``cache=True``: numba keys it by this file's path and
contents, so it is rebuilt once after the file moves).  The Python driver and the self-check that
decides whether they are used are in :mod:`mstrack.track.float_model`.
"""
from __future__ import annotations

import math

import numpy as np

from .features import _GREY_W

# ----------------------------------------------------------------------------- numba kernels
# The same loop compiled with numba, when it is installed and passes _numba_ready()'s self-check
# (otherwise the numpy fast path above runs).  It gives the same results bit for bit because it
# does the same IEEE double operations in the same order: numpy's pairwise summation is
# replicated by _nb_sum / _nb_sum3, bincount's sequential sums by the scan, and the one
# Python-float operation, shift2 = dx ** 2 + dy ** 2 (libm pow, which may round x ** 2
# differently from x * x), is left to Python whenever that could change the stop decision.
# The colour bins are computed from the frame's pixels inside the scan (no colour area).
try:
    from numba import njit as _numba_njit
except ImportError:  # pragma: no cover - numba is a declared dependency
    _numba_njit = None  # type: ignore[assignment]


def _jit(fn):
    """numba.njit with an on-disk cache (compiled once per install); plain ``fn`` without numba."""
    if _numba_njit is None:
        return fn
    try:
        return _numba_njit(cache=True, nogil=True, error_model="numpy")(fn)
    except RuntimeError:  # no writable cache location: compile in every process
        return _numba_njit(nogil=True, error_model="numpy")(fn)


def _jit_inline(fn):
    """:func:`_jit` for a small helper that numba inlines into its callers (in its IR, before LLVM):
    no call and no reference counting of the arrays passed, which for helpers called per row or
    per pixel costs more than their work."""
    if _numba_njit is None:
        return fn
    try:
        return _numba_njit(cache=True, nogil=True, error_model="numpy", inline="always")(fn)
    except RuntimeError:
        return _numba_njit(nogil=True, error_model="numpy", inline="always")(fn)


if _numba_njit is not None:
    from llvmlite import ir as _ir
    from numba import types as _types
    from numba.core import cgutils as _cgutils
    from numba.extending import intrinsic as _intrinsic

    @_intrinsic
    def _prefetch(typingctx, a, i, j):
        """Prefetch a[i, j, 0] (an (H, W, C) array; i, j >= 0) into the caches for reading: LLVM's
        prefetch hint, no load (no fault, nothing to wait for).  The kernels read each new frame's
        pixels once, from memory: a hint a few rows ahead lets those misses overlap the work."""
        def codegen(context, builder, sig, args):
            aryty = sig.args[0]
            ary = context.make_array(aryty)(context, builder, args[0])
            inds = [context.cast(builder, v, t, _types.intp) for v, t in zip(args[1:], sig.args[1:])]
            inds.append(context.get_constant(_types.intp, 0))
            ptr = _cgutils.get_item_pointer2(context, builder, data=ary.data,
                                             shape=_cgutils.unpack_tuple(builder, ary.shape),
                                             strides=_cgutils.unpack_tuple(builder, ary.strides),
                                             layout=aryty.layout, inds=inds, wraparound=False)
            i32, ptrty = _ir.IntType(32), _ir.PointerType()
            fn = _cgutils.get_or_insert_function(builder.module, _ir.FunctionType(
                _ir.VoidType(), [ptrty, i32, i32, i32]), "llvm.prefetch.p0")
            # read, high locality, data cache
            builder.call(fn, [builder.bitcast(ptr, ptrty), _ir.Constant(i32, 0), _ir.Constant(i32, 3),
                              _ir.Constant(i32, 1)])
            return context.get_dummy_value()
        return _types.void(a, i, j), codegen
else:  # pragma: no cover - numba is a declared dependency
    def _prefetch(a, i, j):
        """(no numba: nothing to prefetch)"""


_PW_BLOCK = 128            # numpy's PW_BLOCKSIZE (numpy/_core/src/umath/loops_utils.h.src)
_SHIFT2_BAND = 1e-9        # |dx*dx + dy*dy - eps2| <= band * eps2: Python decides the shift test


_WB, _WG, _WR = _GREY_W  # float32 constants: numba multiplies float32 by float32 in float32


@_jit
def _nb_grey(frame, x0, x1, y0, y1, out, c0):
    """:func:`grey_area` of [y0, y1) x [x0, x1) into ``out[:, c0:]``: (B wb + G wg) + R wr in float32."""
    for y in range(y0, y1):
        px = frame[y, x0:x1]
        row = out[y - y0, c0:c0 + x1 - x0]
        for k in range(x1 - x0):
            row[k] = (np.float32(px[k, 0]) * _WB + np.float32(px[k, 1]) * _WG) + np.float32(px[k, 2]) * _WR


@_jit
def _nb_edge_bins(gx, gy, r0, c0, shift, top, out):
    """out = min(top, int(|gx| + |gy|) >> shift) on the window of gx, gy at (r0, c0) (float32 |G|)."""
    w = out.shape[1]
    for i in range(out.shape[0]):
        a, b, row = gx[r0 + i, c0:c0 + w], gy[r0 + i, c0:c0 + w], out[i]
        for j in range(w):
            row[j] = min(top, np.int32(abs(a[j]) + abs(b[j])) >> shift)


# The sums index with uint64 (ints known to be >= 0): numba then skips its negative-index
# wraparound on every access, which also lets LLVM vectorise the leaves' 8 accumulators.
_U1, _U2, _U3, _U4, _U5, _U6, _U7 = (np.uint64(k) for k in range(1, 8))


@_jit
def _nb_leaf(a, lo, n):
    """numpy's pairwise-sum leaf over a[lo:lo+n] (n <= 128): 8 accumulators, then the rest."""
    b = np.uint64(lo)
    if n < 8:
        res = 0.0
        for k in range(n):
            res += a[b + np.uint64(k)]
        return res
    r0, r1, r2, r3 = a[b], a[b + _U1], a[b + _U2], a[b + _U3]
    r4, r5, r6, r7 = a[b + _U4], a[b + _U5], a[b + _U6], a[b + _U7]
    end = n - n % 8
    for k in range(8, end, 8):
        i = b + np.uint64(k)
        r0 += a[i]
        r1 += a[i + _U1]
        r2 += a[i + _U2]
        r3 += a[i + _U3]
        r4 += a[i + _U4]
        r5 += a[i + _U5]
        r6 += a[i + _U6]
        r7 += a[i + _U7]
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for k in range(end, n):
        res += a[b + np.uint64(k)]
    return res


@_jit
def _nb_sum(a, n):
    """numpy's ``a[:n].sum()`` bit for bit: 0 + pairwise sum.

    numpy halves a block (rounded down to a multiple of 8) until it is at most
    128 long; the recursion runs here on an explicit stack (one allocation;
    numba's on-disk cache does not take recursive functions well).
    """
    if n <= _PW_BLOCK:
        return 0.0 + _nb_leaf(a, 0, n)
    stk = np.empty((3, 64), np.int64)  # lo, n, state (0: left half next, 1: right half next, 2: add)
    vals = np.empty(64)
    sp, vp = 1, 0
    stk[0, 0], stk[1, 0], stk[2, 0] = 0, n, 0
    while sp > 0:
        lo, m, st = stk[0, sp - 1], stk[1, sp - 1], stk[2, sp - 1]
        if m <= _PW_BLOCK:
            vals[vp] = _nb_leaf(a, lo, m)
            vp += 1
            sp -= 1
            continue
        half = m // 2
        half -= half % 8
        if st == 0:      # left half
            stk[2, sp - 1] = 1
            stk[0, sp], stk[1, sp], stk[2, sp] = lo, half, 0
            sp += 1
        elif st == 1:    # right half
            stk[2, sp - 1] = 2
            stk[0, sp], stk[1, sp], stk[2, sp] = lo + half, m - half, 0
            sp += 1
        else:            # left + right
            vals[vp - 2] = vals[vp - 2] + vals[vp - 1]
            vp -= 1
            sp -= 1
    return 0.0 + vals[0]


@_jit
def _nb_leaf3(wb, B, X, Y, lo, n):
    """Three pairwise leaves at once: w = wb[B], sums of w, w * X and w * Y over [lo, lo+n)."""
    b = np.uint64(lo)
    if n < 8:
        s0 = s1 = s2 = 0.0
        for k in range(n):
            i = b + np.uint64(k)
            w = wb[np.uint64(B[i])]
            s0 += w
            s1 += w * X[i]
            s2 += w * Y[i]
        return s0, s1, s2
    i = b
    w0, w1 = wb[np.uint64(B[i])], wb[np.uint64(B[i + _U1])]
    w2, w3 = wb[np.uint64(B[i + _U2])], wb[np.uint64(B[i + _U3])]
    w4, w5 = wb[np.uint64(B[i + _U4])], wb[np.uint64(B[i + _U5])]
    w6, w7 = wb[np.uint64(B[i + _U6])], wb[np.uint64(B[i + _U7])]
    a0, a1, a2, a3, a4, a5, a6, a7 = w0, w1, w2, w3, w4, w5, w6, w7
    b0, b1, b2, b3 = w0 * X[i], w1 * X[i + _U1], w2 * X[i + _U2], w3 * X[i + _U3]
    b4, b5, b6, b7 = w4 * X[i + _U4], w5 * X[i + _U5], w6 * X[i + _U6], w7 * X[i + _U7]
    c0, c1, c2, c3 = w0 * Y[i], w1 * Y[i + _U1], w2 * Y[i + _U2], w3 * Y[i + _U3]
    c4, c5, c6, c7 = w4 * Y[i + _U4], w5 * Y[i + _U5], w6 * Y[i + _U6], w7 * Y[i + _U7]
    end = n - n % 8
    for k in range(8, end, 8):
        i = b + np.uint64(k)
        w0, w1 = wb[np.uint64(B[i])], wb[np.uint64(B[i + _U1])]
        w2, w3 = wb[np.uint64(B[i + _U2])], wb[np.uint64(B[i + _U3])]
        w4, w5 = wb[np.uint64(B[i + _U4])], wb[np.uint64(B[i + _U5])]
        w6, w7 = wb[np.uint64(B[i + _U6])], wb[np.uint64(B[i + _U7])]
        a0 += w0
        a1 += w1
        a2 += w2
        a3 += w3
        a4 += w4
        a5 += w5
        a6 += w6
        a7 += w7
        b0 += w0 * X[i]
        b1 += w1 * X[i + _U1]
        b2 += w2 * X[i + _U2]
        b3 += w3 * X[i + _U3]
        b4 += w4 * X[i + _U4]
        b5 += w5 * X[i + _U5]
        b6 += w6 * X[i + _U6]
        b7 += w7 * X[i + _U7]
        c0 += w0 * Y[i]
        c1 += w1 * Y[i + _U1]
        c2 += w2 * Y[i + _U2]
        c3 += w3 * Y[i + _U3]
        c4 += w4 * Y[i + _U4]
        c5 += w5 * Y[i + _U5]
        c6 += w6 * Y[i + _U6]
        c7 += w7 * Y[i + _U7]
    s0 = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7))
    s1 = ((b0 + b1) + (b2 + b3)) + ((b4 + b5) + (b6 + b7))
    s2 = ((c0 + c1) + (c2 + c3)) + ((c4 + c5) + (c6 + c7))
    for k in range(end, n):
        i = b + np.uint64(k)
        w = wb[np.uint64(B[i])]
        s0 += w
        s1 += w * X[i]
        s2 += w * Y[i]
    return s0, s1, s2


@_jit
def _nb_sum3(wb, B, X, Y, n):
    """numpy's ``w.sum(), (w * xs).sum(), (w * ys).sum()`` with w = wb[B], bit for bit (one pass;
    :func:`_nb_sum`'s explicit stack)."""
    if n <= _PW_BLOCK:
        s0, s1, s2 = _nb_leaf3(wb, B, X, Y, 0, n)
        return 0.0 + s0, 0.0 + s1, 0.0 + s2
    stk = np.empty((3, 64), np.int64)
    v = np.empty((3, 64))
    sp, vp = 1, 0
    stk[0, 0], stk[1, 0], stk[2, 0] = 0, n, 0
    while sp > 0:
        lo, m, st = stk[0, sp - 1], stk[1, sp - 1], stk[2, sp - 1]
        if m <= _PW_BLOCK:
            v[0, vp], v[1, vp], v[2, vp] = _nb_leaf3(wb, B, X, Y, lo, m)
            vp += 1
            sp -= 1
            continue
        half = m // 2
        half -= half % 8
        if st == 0:
            stk[2, sp - 1] = 1
            stk[0, sp], stk[1, sp], stk[2, sp] = lo, half, 0
            sp += 1
        elif st == 1:
            stk[2, sp - 1] = 2
            stk[0, sp], stk[1, sp], stk[2, sp] = lo + half, m - half, 0
            sp += 1
        else:
            v[0, vp - 2] = v[0, vp - 2] + v[0, vp - 1]
            v[1, vp - 2] = v[1, vp - 2] + v[1, vp - 1]
            v[2, vp - 2] = v[2, vp - 2] + v[2, vp - 1]
            vp -= 1
            sp -= 1
    return 0.0 + v[0, 0], 0.0 + v[1, 0], 0.0 + v[2, 0]


@_jit
def _nb_columns(cx, hx, x0, nx, ax):
    """The column terms of d2 for the box's nx columns from x0: ax[j] = ((x0 + j - cx) / hx) ** 2.
    Returns jc, the first column of least ax (where each row's run of inside pixels lies)."""
    jc = 0
    for j in range(nx):
        t = (x0 + j - cx) / hx
        ax[j] = t * t
        if ax[j] < ax[jc]:
            jc = j
    return jc


@_jit
def _nb_run(ax, jc, nx, by):
    """A row's inside pixels (ax[j] + by < 1): (ja, m), the run's first column and length; m = 0
    when the row has none.  d2 = ax + by is unimodal in x (every step rounds monotonically), so
    two binary searches either side of jc find the run exactly."""
    if not ax[jc] + by < 1.0:
        return 0, 0
    lo, hi = 0, jc
    while lo < hi:
        mid = (lo + hi) // 2
        if ax[mid] + by < 1.0:
            hi = mid
        else:
            lo = mid + 1
    ja = lo
    lo, hi = jc, nx - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if ax[mid] + by < 1.0:
            lo = mid
        else:
            hi = mid - 1
    return ja, lo - ja + 1


@_jit
def _nb_scan(cx, cy, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B, X, Y, h, ax, cnt):
    """:func:`kernel_window` and :func:`histogram` (unnormalised) at (cx, cy).

    Fills the inside pixels' bins B and coordinates X, Y in row-major order and
    h: counts (flat) or bincount's sequential kernel sums.  Bins come from the
    frame's pixels when ``bits`` > 0 (colour), else from ``bins`` at (ox, oy).
    Each row's inside pixels form one run: d2 = ax + by is unimodal in x (every
    step rounds monotonically), so two binary searches find it exactly.
    """
    x0 = max(0, math.ceil(cx - hx))
    x1 = min(width - 1, math.floor(cx + hx))
    y0 = max(0, math.ceil(cy - hy))
    y1 = min(height - 1, math.floor(cy + hy))
    nx = x1 - x0 + 1
    jc = _nb_columns(cx, hx, x0, nx, ax)
    h[:] = 0.0
    if flat:
        cnt[:] = 0
    s, s1, s2 = np.uint32(8 - bits), np.uint32(bits), np.uint32(2 * bits)
    mask = cnt.shape[0] - 1  # 4 tables, or 1 for very many bins
    n = 0
    for y in range(y0, y1 + 1):
        t = (y - cy) / hy
        by = t * t
        ja, m = _nb_run(ax, jc, nx, by)
        if m == 0:
            continue
        xa = x0 + ja
        b, xs, ys = B[n:n + m], X[n:n + m], Y[n:n + m]
        if bits > 0:
            px = frame[y, xa:xa + m]
            for k in range(m):
                b[k] = (((np.uint32(px[k, 2]) >> s) << s2) | ((np.uint32(px[k, 1]) >> s) << s1)
                        | (np.uint32(px[k, 0]) >> s))
        else:
            row = bins[y - oy, xa - ox:xa - ox + m]
            for k in range(m):
                b[k] = row[k]
        for k in range(m):
            xs[k] = xa + k
            ys[k] = y
        if flat:  # integer counts in interleaved tables: no store-to-load chain on runs of one bin
            for k in range(m):
                cnt[(n + k) & mask, b[k]] += 1
        else:
            axr = ax[ja:ja + m]
            for k in range(m):
                h[b[k]] += 1.0 - (axr[k] + by)
        n += m
    if flat:
        for u in range(h.shape[0]):
            c = 0
            for r in range(cnt.shape[0]):
                c += cnt[r, u]
            h[u] = float(c)
    return n


@_jit
def _nb_normalise(h, q, n, flat, p, tmp):
    """p = h / sum(h) as :func:`histogram` normalises; returns rho(p, q)."""
    nb = h.shape[0]
    total = float(n) if flat else _nb_sum(h, nb)  # flat: the sum of the counts is the count, exactly
    for u in range(nb):
        if h[u] == 0.0:  # 0 / total and sqrt(0 * q) are 0: skip the division and the root
            p[u] = tmp[u] = 0.0
        else:
            p[u] = h[u] / total if total > 0 else h[u]
            tmp[u] = math.sqrt(p[u] * q[u]) if q[u] != 0.0 else 0.0
    return _nb_sum(tmp, nb)


@_jit
def _nb_outside(cx, cy, hx, hy, width, height, ox, oy, bw, bh):
    """True if the window box at (cx, cy) is not inside the area [ox, ox + bw) x [oy, oy + bh)."""
    return (max(0, math.ceil(cx - hx)) < ox or min(width - 1, math.floor(cx + hx)) >= ox + bw
            or max(0, math.ceil(cy - hy)) < oy or min(height - 1, math.floor(cy + hy)) >= oy + bh)


@_jit
def _nb_meanshift(frame, bits, bins, ox, oy, bw, bh, q, sx, sy, it0, hx, hy, width, height, flat,
                  max_iter, eps2, ibuf, fbuf, ax, cnt):
    """:func:`meanshift` from (sx, sy) after ``it0`` iterations (bins as in :func:`_nb_scan`).

    Returns (code, c0x, c0y, c1x, c1y, rho, it): code 0..3 a stop (centre c0);
    -1 the window at c1 leaves the bins' area [ox, ox + bw) x [oy, oy + bh) (grow
    it, resume from c0 after ``it`` iterations); -2 the shift test c0 -> c1 is
    left to Python (rho is rho(c1)).  Work buffers: :func:`_nb_buffers`.
    """
    nb = q.shape[0]
    B0, B1, X0, X1, Y0, Y1 = ibuf[0], ibuf[1], ibuf[2], ibuf[3], ibuf[4], ibuf[5]
    h, p0, p1, wb = fbuf[0, :nb], fbuf[1, :nb], fbuf[2, :nb], fbuf[3, :nb]
    tmp = wb  # rho's temporary: wb is rewritten before every use
    cnt = cnt[:, :nb]
    c0x = min(max(sx, 0.0), width - 1.0)
    c0y = min(max(sy, 0.0), height - 1.0)
    if _nb_outside(c0x, c0y, hx, hy, width, height, ox, oy, bw, bh):
        return -1, c0x, c0y, c0x, c0y, 0.0, it0
    n0 = _nb_scan(c0x, c0y, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B0, X0, Y0, h, ax, cnt)
    rho0 = _nb_normalise(h, q, n0, flat, p0, tmp)
    for it in range(it0 + 1, max_iter + 1):
        for u in range(nb):
            wb[u] = math.sqrt(q[u] / p0[u]) if p0[u] > 0 and q[u] != 0.0 else 0.0
        sw, swx, swy = _nb_sum3(wb, B0, X0, Y0, n0)
        if sw <= 0:
            return 3, c0x, c0y, c0x, c0y, rho0, it
        c1x = min(max(swx / sw, 0.0), width - 1.0)
        c1y = min(max(swy / sw, 0.0), height - 1.0)
        if _nb_outside(c1x, c1y, hx, hy, width, height, ox, oy, bw, bh):
            return -1, c0x, c0y, c1x, c1y, rho0, it - 1
        n1 = _nb_scan(c1x, c1y, hx, hy, width, height, frame, bits, bins, ox, oy, flat, B1, X1, Y1, h, ax, cnt)
        rho1 = _nb_normalise(h, q, n1, flat, p1, tmp)
        if rho1 < rho0:
            return 1, c0x, c0y, c0x, c0y, rho0, it
        shift2 = (c1x - c0x) * (c1x - c0x) + (c1y - c0y) * (c1y - c0y)
        if abs(shift2 - eps2) <= _SHIFT2_BAND * eps2:
            return -2, c0x, c0y, c1x, c1y, rho1, it
        c0x, c0y, rho0, n0 = c1x, c1y, rho1, n1
        B0, B1, X0, X1, Y0, Y1, p0, p1 = B1, B0, X1, X0, Y1, Y0, p1, p0
        if shift2 < eps2:
            return 0, c0x, c0y, c0x, c0y, rho0, it
    return 2, c0x, c0y, c0x, c0y, rho0, max_iter


def _nb_buffers(hx: float, hy: float, n_bins: int) -> tuple[np.ndarray, ...]:
    """Work buffers of :func:`_nb_meanshift` for a target of half-sizes hx, hy (reused every frame).

    int32 bins and coordinates of two windows (6, box px); float64 histogram,
    two normalised histograms and the weights (4, bins); the column terms of
    d2 (box width); int32 counts (4 interleaved tables, 1 beyond 2**16 bins).
    """
    box_w = int(2.0 * hx) + 2
    return (np.empty((6, box_w * (int(2.0 * hy) + 2)), np.int32), np.empty((4, n_bins)),
            np.empty(box_w), np.empty((4 if n_bins <= 1 << 16 else 1, n_bins), np.int32))
