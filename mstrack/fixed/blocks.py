"""The blocks of the fixed-point model, one function per RTL entity of the same name.

Everything is integer (numpy int64).  Coordinates: pixel-index, column x,
row y.  Centres are unsigned Q(coord_bits).CF: ``c8 = round(c * 2**CF)``.
docs/fixed_point.md gives format, range and rounding of each signal.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..track.params import TrackerParams
from .formats import FixedParams
from .primitives import ms_divider, ms_isqrt, round_div_signed

GREY_WEIGHTS_RGB = (77, 150, 29)  # grey = (77 R + 150 G + 29 B) >> 8, weights sum to 256
GREY_SHIFT = 8
MIN_WINDOW = 3                    # smallest window extent in px (ex, ey >= 1)


# ----------------------------------------------------------------------------- front end
def ms_colour_bin(frame: np.ndarray, bits: int) -> np.ndarray:
    """Colour bin: ((R >> s) << 2b) | ((G >> s) << b) | (B >> s), s = 8 - b.  (H, W) int64."""
    s = 8 - bits
    f = frame >> s  # uint8; the bin (< 2**24) is built in int32, returned as int64
    return ((f[..., 2].astype(np.int32) << (2 * bits)) | (f[..., 1].astype(np.int32) << bits)
            | f[..., 0]).astype(np.int64)


def ms_grey(frame: np.ndarray) -> np.ndarray:
    """Grey: (77 R + 150 G + 29 B) >> 8 (truncating), 0..255.  frame BGR uint8 -> (H, W) int64."""
    wr, wg, wb = GREY_WEIGHTS_RGB  # the sum (< 2**16) is formed in int32, returned as int64
    return ((wr * frame[..., 2].astype(np.int32) + wg * frame[..., 1].astype(np.int32)
             + wb * frame[..., 0].astype(np.int32)) >> GREY_SHIFT).astype(np.int64)


def ms_sobel(grey: np.ndarray) -> np.ndarray:
    """|G| = |Gx| + |Gy| of the 3x3 Sobel, for the interior of ``grey`` only.

    grey (h, w) -> (h - 2, w - 2) int64 in 0..2040 (11 bits).  Gx and Gy are
    11-bit signed (-1020..1020).  Gx = right column - left column with weights
    1, 2, 1; Gy = bottom row - top row.
    """
    g = grey
    gx = (g[:-2, 2:] + 2 * g[1:-1, 2:] + g[2:, 2:]) - (g[:-2, :-2] + 2 * g[1:-1, :-2] + g[2:, :-2])
    gy = (g[2:, :-2] + 2 * g[2:, 1:-1] + g[2:, 2:]) - (g[:-2, :-2] + 2 * g[:-2, 1:-1] + g[:-2, 2:])
    return np.abs(gx) + np.abs(gy)


def ms_edge_bin(mag: np.ndarray, n_bins: int, shift: int) -> np.ndarray:
    """Edge bin: min(E - 1, |G| >> shift) (saturating)."""
    return np.minimum(n_bins - 1, mag >> shift)


# ----------------------------------------------------------------------------- geometry
@dataclass(frozen=True)
class IntBox:
    """Integer target box: columns x .. x + w - 1, rows y .. y + h - 1."""

    x: int
    y: int
    w: int
    h: int


def ms_box_clip(x: int, y: int, w: int, h: int, frame_w: int, frame_h: int,
                max_half: int) -> tuple[IntBox | None, bool]:
    """Clip an integer init box to the frame interior, then to the largest window.

    The interior is columns 1 .. W - 2 and rows 1 .. H - 2 (the 1-px border has
    no Sobel neighbourhood).  Returns (box, clipped) or (None, True) when the
    box is rejected: after clipping narrower or lower than 3 px (this includes
    boxes entirely outside).  A box larger than 2 * max_half + 1 is shrunk about
    its centre: start += (size - max) // 2.
    """
    def axis(a: int, n: int, size: int) -> tuple[int, int] | None:
        lo = max(a, 1)
        hi = min(a + n, size - 1)  # exclusive
        ln = hi - lo
        if ln < MIN_WINDOW:
            return None
        mx = 2 * max_half + 1
        if ln > mx:
            lo += (ln - mx) // 2
            ln = mx
        return lo, ln

    ax = axis(x, w, frame_w)
    ay = axis(y, h, frame_h)
    if ax is None or ay is None:
        return None, True
    box = IntBox(ax[0], ay[0], ax[1], ay[1])
    return box, box != IntBox(x, y, w, h)


def round_box(x: float, y: float, w: float, h: float) -> tuple[int, int, int, int]:
    """Float box -> integer box: edges rounded half up (x0 = floor(x + .5), x1 = floor(x + w + .5)).

    Raises ValueError if an edge is not finite (e.g. x + w overflows for x = w = 1e308)."""
    if not all(np.isfinite(v) for v in (x + 0.5, y + 0.5, x + w + 0.5, y + h + 0.5)):
        raise ValueError(f"box ({x:g}, {y:g}, {w:g}, {h:g}) is out of range (an edge is not finite)")
    x0 = int(np.floor(x + 0.5))
    y0 = int(np.floor(y + 0.5))
    return x0, y0, int(np.floor(x + w + 0.5)) - x0, int(np.floor(y + h + 0.5)) - y0


def init_centre(box: IntBox, cf: int) -> tuple[int, int]:
    """Box centre (x + (w - 1) / 2) in Q.CF, exact: (2x + w - 1) << (CF - 1)."""
    return (2 * box.x + box.w - 1) << (cf - 1), (2 * box.y + box.h - 1) << (cf - 1)


def ms_round_centre(c8: int, cf: int) -> int:
    """Window position of a Q.CF centre: round half up, (c + 2**(CF-1)) >> CF."""
    return (c8 + (1 << (cf - 1))) >> cf


@dataclass(frozen=True)
class Region:
    """Search region captured from a frame: columns x .. x + w - 1, rows y .. y + h - 1.

    ``lo``/``hi`` are the (x, y) limits of the window centre so that the
    window (half-extents ex, ey) stays inside the region.
    """

    x: int
    y: int
    w: int
    h: int
    lo: tuple[int, int]
    hi: tuple[int, int]


def ms_region(c8: tuple[int, int], ex: int, ey: int, frame_w: int, frame_h: int,
              fp: FixedParams) -> Region:
    """Region around round(c8): window box + MARGIN on each side, shifted/clipped into the interior.

    Per axis: n = min(2e + 2 MARGIN + 1, S - 2); start = clamp(round(c) - e - MARGIN,
    1, S - 1 - n); window centres allowed in [start + e, start + n - 1 - e].
    """
    def axis(c: int, e: int, size: int) -> tuple[int, int]:
        n = min(2 * e + 2 * fp.margin + 1, size - 2)
        start = min(max(ms_round_centre(c, fp.centre_frac) - e - fp.margin, 1), size - 1 - n)
        return start, n

    x, w = axis(c8[0], ex, frame_w)
    y, h = axis(c8[1], ey, frame_h)
    return Region(x, y, w, h, lo=(x + ex, y + ey), hi=(x + w - 1 - ex, y + h - 1 - ey))


def ms_region_capture(frame: np.ndarray, reg: Region, tp: TrackerParams) -> tuple[np.ndarray, np.ndarray]:
    """Colour and edge bins of the region's pixels (what the capture RAMs hold), each (h, w)."""
    sub = frame[reg.y - 1: reg.y + reg.h + 1, reg.x - 1: reg.x + reg.w + 1]
    colour = ms_colour_bin(sub[1:-1, 1:-1], tp.colour_bits)
    edge = ms_edge_bin(ms_sobel(ms_grey(sub)), tp.n_edge_bins, tp.edge_shift)
    return colour, edge


def clamp_centre(c8: tuple[int, int], reg: Region, cf: int) -> tuple[int, int]:
    """Clamp a Q.CF centre to [lo << CF, hi << CF] per axis."""
    return (min(max(c8[0], reg.lo[0] << cf), reg.hi[0] << cf),
            min(max(c8[1], reg.lo[1] << cf), reg.hi[1] << cf))


# ----------------------------------------------------------------------------- kernel
@dataclass
class ms_kernel:  # noqa: N801 -- named after rtl/ms_kernel.vhd
    """Kernel of a w x h target: window half-extents, inside test and kernel values.

    ex = (w - 1) // 2, ey = (h - 1) // 2; relative offsets dx in -ex..ex, dy in -ey..ey.
    Inside test (exact, no division): TA[|dx|] + TB[|dy|] < D with
    TA = 4 dx^2 h^2, TB = 4 dy^2 w^2, D = w^2 h^2  (<=> (2dx/w)^2 + (2dy/h)^2 < 1).
    Kernel value: flat k = 1; Epanechnikov k = 2**KB - KA[|dx|] - KB[|dy|] with
    KA = floor(2**KB * 4 dx^2 / w^2), KB = floor(2**KB * 4 dy^2 / h^2) (tables
    computed once per target; k >= 1 for every inside pixel).
    """

    w: int
    h: int
    kernel: str
    kernel_bits: int
    ex: int = field(init=False)
    ey: int = field(init=False)

    def __post_init__(self) -> None:
        w, h, kb = self.w, self.h, self.kernel_bits
        self.ex, self.ey = (w - 1) // 2, (h - 1) // 2
        dx = np.arange(self.ex + 1, dtype=np.int64)
        dy = np.arange(self.ey + 1, dtype=np.int64)
        self.D = w * w * h * h
        self.TA = 4 * dx * dx * h * h
        self.TB = 4 * dy * dy * w * w
        self.KA = ((4 * dx * dx) << kb) // (w * w)
        self.KB = ((4 * dy * dy) << kb) // (h * h)
        adx = np.abs(np.arange(-self.ex, self.ex + 1))
        ady = np.abs(np.arange(-self.ey, self.ey + 1))
        inside = (self.TA[adx][None, :] + self.TB[ady][:, None]) < self.D
        if self.kernel == "flat":
            k = np.ones(inside.shape, np.int64)
        else:
            k = (1 << kb) - self.KA[adx][None, :] - self.KB[ady][:, None]
        self.inside = inside                    # (2ey+1, 2ex+1) bool
        self.k = np.where(inside, k, 0)         # (2ey+1, 2ex+1) int64
        yy, xx = np.nonzero(inside)
        self._iy, self._ix = yy, xx
        self._k_in = self.k[yy, xx]
        self._dx_in = xx - self.ex
        self._dy_in = yy - self.ey
        # float64 copies for np.bincount's weights (integer sums < 2**53: exact in any order)
        self._k_f = self._k_in.astype(np.float64)
        self._dx_f = self._dx_in.astype(np.float64)
        self._dy_f = self._dy_in.astype(np.float64)
        self.K = int(self._k_in.sum())          # sum of k over the window (same at every position)


# ----------------------------------------------------------------------------- pixel pass
@dataclass
class Hist:
    """Accumulators of one pixel pass, per bin: H = sum k, N = count, SX/SY = sum dx/dy."""

    H: np.ndarray
    N: np.ndarray
    SX: np.ndarray
    SY: np.ndarray


def ms_histogram(bins: np.ndarray, reg: Region, win: tuple[int, int], ker: ms_kernel,
                 n_bins: int) -> Hist:
    """One pixel pass over the window centred at ``win`` (absolute px) of the captured region.

    The sums are exact integers, so the scan order (rows top to bottom, LANES
    pixels per clock in the RTL) does not change them.
    """
    r0 = win[1] - ker.ey - reg.y
    c0 = win[0] - ker.ex - reg.x
    if r0 < 0 or c0 < 0 or r0 + 2 * ker.ey + 1 > reg.h or c0 + 2 * ker.ex + 1 > reg.w:
        raise AssertionError("window outside the captured region (centre not clamped)")
    # inside pixels in row-major order (the order of np.nonzero(ker.inside))
    b = bins[r0: r0 + 2 * ker.ey + 1, c0: c0 + 2 * ker.ex + 1][ker.inside]

    def acc(weights: np.ndarray) -> np.ndarray:
        return np.rint(np.bincount(b, weights=weights, minlength=n_bins)).astype(np.int64)
    N = np.bincount(b, minlength=n_bins).astype(np.int64)
    H = N if ker.kernel == "flat" else acc(ker._k_f)
    return Hist(H=H, N=N, SX=acc(ker._dx_f), SY=acc(ker._dy_f))


def ms_histogram_banks(hist: Hist, n_orient: int) -> Hist:
    """The read-out of rtl/ms_histogram.vhd with N_ORIENT = ``n_orient`` banks per lane.

    ``hist`` is :func:`ms_histogram` over joint bins ``n_orient * u + o`` (colour bin u,
    orientation o in 0 .. n_orient - 1; ``blocks_v2.ms_joint_bin`` with n_orient = 9), so
    ``n_bins = n_orient * n_colour``.  The RTL keeps joint bin ``n_orient * u + o`` in bank o at
    address u and its read port returns the n_orient banks of one address u at once: H[u, o] etc.
    Returns a Hist whose H, N, SX, SY are views of shape (n_colour, n_orient) (C order: no
    arithmetic, the joint histogram seen as [colour][orientation]).
    """
    n = hist.N.shape[0]
    if n_orient < 1 or n % n_orient:
        raise ValueError(f"{n} joint bins are not n_colour x {n_orient} orientations")
    return Hist(*(a.reshape(n // n_orient, n_orient) for a in (hist.H, hist.N, hist.SX, hist.SY)))


# ----------------------------------------------------------------------------- bin pass
@dataclass
class BinPass:
    """Results of one bin pass: S = sum_u isqrt(H Q 2**(2RF)), weight table, weighted sums."""

    S: int
    w: np.ndarray
    Sw: int
    Swx: int
    Swy: int


def ms_weight(Q: np.ndarray, H: np.ndarray, fp: FixedParams) -> np.ndarray:
    """Per-bin weight sqrt(q/p) in WI.WF: isqrt(min(floor(Q 2**(2WF) / H), 2**(2(WI+WF)) - 1)); 0 where H = 0.

    floor(sqrt(floor(x))) = floor(sqrt(x)), so this is the exact floor of the
    true weight in WF fraction bits, saturated at 2**WI - 2**-WF.
    """
    qbits = 2 * (fp.weight_int + fp.weight_frac)
    nz = (H > 0) & (Q > 0)  # elsewhere the ratio and its root are 0
    w = np.zeros_like(Q)
    w[nz] = ms_isqrt(ms_divider(Q[nz] << (2 * fp.weight_frac), H[nz], qbits))
    return w


def ms_bin_pass(Q: np.ndarray, hist: Hist, fp: FixedParams, q_frac: int = 0) -> BinPass:
    """Bhattacharyya sum, weight table and weighted position sums (one pass over the bins).

    Bins with H Q = 0 add isqrt(0) = 0 and have weight 0: only the others are evaluated.
    ``q_frac``: Q carries q_frac fraction bits (tracker v2's FixedParams.model_frac; 0 for the
    paper's cores): the term is isqrt(H Q 2**(2 RF + q_frac)) >> q_frac (the same floor of
    sqrt(H Q') 2**RF for Q' = Q 2**-q_frac, computed with H 2**q_frac) and the weight divides
    Q 2**(2 WF) by H 2**q_frac.
    """
    H = hist.H << q_frac if q_frac else hist.H
    hq = H * Q
    nz = np.flatnonzero(hq)
    S = int(ms_isqrt(hq[nz] << (2 * fp.rho_frac)).sum()) if not q_frac else \
        int((ms_isqrt(hq[nz] << (2 * fp.rho_frac)) >> q_frac).sum())
    w = ms_weight(Q, H, fp)
    wn = w[nz]
    return BinPass(S=S, w=w, Sw=int((wn * hist.N[nz]).sum()), Swx=int((wn * hist.SX[nz]).sum()),
                   Swy=int((wn * hist.SY[nz]).sum()))


def ms_centre(bp: BinPass, win: tuple[int, int], reg: Region, fp: FixedParams,
              shift_q: int) -> tuple[int, int] | None:
    """New centre: win + round_half_away(Swx 2**CF / Sw), clamped to the region; None if Sw = 0."""
    if bp.Sw == 0:
        return None
    cf = fp.centre_frac
    dx = int(round_div_signed(bp.Swx << cf, bp.Sw, shift_q))
    dy = int(round_div_signed(bp.Swy << cf, bp.Sw, shift_q))
    return clamp_centre(((win[0] << cf) + dx, (win[1] << cf) + dy), reg, cf)


# ----------------------------------------------------------------------------- iteration
@dataclass
class FeatureFixed:
    """Fixed-point result of one feature's mean-shift loop on one frame."""

    c8: tuple[int, int]
    S: int
    iterations: int
    stop: str
    trace: list[dict] = field(default_factory=list)


STOP_CODES = {"shift": 0, "rho": 1, "max_iter": 2, "lost": 3}


def ms_meanshift(bins: np.ndarray, Q: np.ndarray, start8: tuple[int, int], reg: Region, ker: ms_kernel,
                 tp: TrackerParams, fp: FixedParams, n_bins: int, shift_q: int,
                 trace: bool = False, q_frac: int = 0) -> FeatureFixed:
    """Iteration controller (rtl/ms_meanshift.vhd): the loop of docs/algorithm.md in integers.

    c0 = clamp(start); pass at round(c0) -> S0, sums.  Iteration i = 1..max_iter:
    Sw = 0 -> stop "lost" (keep c0); c1 = centre(sums); pass at round(c1) -> S1;
    S1 < S0 - m -> stop "rho" (keep c0, S0; m = 0 unless tracker v2's rho_stop_margin); shift2 = |c1 - c0|^2 (Q.2CF);
    c0 = c1; shift2 < EPS2 -> stop "shift"; after max_iter -> "max_iter".
    """
    cf = fp.centre_frac
    eps2_q = int(round(tp.eps2 * (1 << (2 * cf))))
    tr: list[dict] = []

    def run_pass(c8: tuple[int, int]) -> tuple[tuple[int, int], Hist, BinPass]:
        win = (ms_round_centre(c8[0], cf), ms_round_centre(c8[1], cf))
        h = ms_histogram(bins, reg, win, ker, n_bins)
        bp = ms_bin_pass(Q, h, fp, q_frac)
        if trace:
            nz = np.nonzero(h.N)[0]
            tr.append({"centre": list(c8), "win": list(win), "bins": nz.tolist(),
                       "H": h.H[nz].tolist(), "N": h.N[nz].tolist(), "SX": h.SX[nz].tolist(),
                       "SY": h.SY[nz].tolist(), "w": bp.w[nz].tolist(), "S": bp.S,
                       "Sw": bp.Sw, "Swx": bp.Swx, "Swy": bp.Swy})
        return win, h, bp

    # tracker v2's rho_stop_margin (0 by default, and for the paper preset): rho margin m in S's
    # units, S = rho K 2**(RF - 16): (round(m 2**16) K) >> (16 - RF), one multiplier per frame
    m_s = (int(round(getattr(tp, "rho_stop_margin", 0.0) * 65536)) * ker.K) >> (16 - fp.rho_frac)
    c0 = clamp_centre(start8, reg, cf)
    win0, _, bp0 = run_pass(c0)
    for it in range(1, tp.max_iter + 1):
        c1 = ms_centre(bp0, win0, reg, fp, shift_q)
        if c1 is None:
            return FeatureFixed(c0, bp0.S, it, "lost", tr)
        win1, _, bp1 = run_pass(c1)
        if bp1.S < bp0.S - m_s:
            return FeatureFixed(c0, bp0.S, it, "rho", tr)
        shift2 = (c1[0] - c0[0]) ** 2 + (c1[1] - c0[1]) ** 2
        c0, win0, bp0 = c1, win1, bp1
        if shift2 < eps2_q:
            return FeatureFixed(c0, bp0.S, it, "shift", tr)
    return FeatureFixed(c0, bp0.S, tp.max_iter, "max_iter", tr)


# ----------------------------------------------------------------------------- outputs
def ms_fusion(S_c: int, S_e: int, c_c: tuple[int, int], c_e: tuple[int, int], features: str,
              af: int) -> tuple[tuple[int, int], int, int]:
    """Fusion (rtl/ms_fusion.vhd): alpha_c = round(S_c 2**AF / (S_c + S_e)), alpha_e = 2**AF - alpha_c.

    Rounding half up; alpha_c = 2**(AF-1) when S_c + S_e = 0; colour-only ->
    alpha_c = 2**AF, edge-only -> 0.  Centre = (alpha_c c_c + alpha_e c_e + 2**(AF-1)) >> AF.
    """
    one = 1 << af
    if features == "colour":
        a_c = one
    elif features == "edge":
        a_c = 0
    else:
        tot = S_c + S_e
        a_c = one >> 1 if tot == 0 else int(ms_divider((S_c << af) + (tot >> 1), tot, af + 1))
    a_e = one - a_c
    half = one >> 1
    c = ((a_c * c_c[0] + a_e * c_e[0] + half) >> af, (a_c * c_c[1] + a_e * c_e[1] + half) >> af)
    return c, a_c, a_e


def ms_rho_out(S: int, K: int, fp: FixedParams) -> int:
    """Reported rho: floor(S 2**(16 - RF) / K), 0 .. 2**16 (17 bits; 2**16 = 1.0)."""
    return int(ms_divider(S << (fp.rho_out_frac - fp.rho_frac), K, fp.rho_out_frac + 1))
