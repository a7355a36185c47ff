"""Number formats of the fixed-point model: the single source of truth.

Every width used by the model and the RTL is derived here from a few
parameters (which become VHDL generics / constants).  ``rtl/ms_formats_pkg.vhd``
is generated from this module by ``mstrack.fixed.vhdl_pkg`` (never edited by
hand); docs/fixed_point.md explains each signal.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from ..track.params import TrackerParams, check_param_types
from .primitives import bits_for


@dataclass(frozen=True)
class FixedParams:
    """Hardware sizes and number formats.

    Attributes
    ----------
    max_half : int
        MAX_HALF: largest window half-extent ex, ey (window bounding box at most
        2 * max_half + 1 px square).  Larger init boxes are shrunk about their centre.
    margin : int
        MARGIN: the search region is the window bounding box grown by ``margin``
        px on every side (the largest motion per frame that can be followed).
    coord_bits : int
        Integer bits of frame coordinates (frames up to 2**coord_bits px wide/high).
    centre_frac : int
        CF: fraction bits of centres and shifts (paper: 8).
    weight_int, weight_frac : int
        WI.WF: format of the per-bin weight sqrt(q/p) (paper: 4.4).
    rho_frac : int
        RF: fraction bits kept by each Bhattacharyya term isqrt(P Q 2**(2 RF)).
    kernel_bits : int
        KB: Epanechnikov kernel values are k = 2**KB - A[dx] - B[dy] in 1..2**KB.
    alpha_frac : int
        AF: fraction bits of the fusion weights alpha_c, alpha_e.
    rho_out_frac : int
        Fraction bits of the rho values reported in results (paper: 16).
    model_frac : int
        Tracker v2 only: fraction bits of the model at the window Qw = (Qn K) >> (16 - model_frac)
        (default 0: integer counts, core v2).  With 4608 joint bins and windows of a few thousand
        pixels most Qw floor to 0 at 0 fraction bits; the bin pass then scales H by 2**model_frac
        for the weight and the Bhattacharyya term (docs/fixed_point.md, "Model fraction bits").
    bg_frac : int
        Tracker v2 only: fraction bits of the CBWH factors v_u = min(o* / O_u, 1) of the init
        model (ms_bg_model; default 8, core v2).  At 8 a ring colour more than 256 times as
        frequent as the rarest ring colour gets v_u = 0, where the float model keeps o* / o_u.
    """

    max_half: int = 63
    margin: int = 32
    coord_bits: int = 12
    centre_frac: int = 8
    weight_int: int = 4
    weight_frac: int = 4
    rho_frac: int = 6
    kernel_bits: int = 8
    alpha_frac: int = 8
    rho_out_frac: int = 16
    model_frac: int = 0
    bg_frac: int = 8

    def __post_init__(self) -> None:
        check_param_types(self)
        if not 0 <= self.model_frac <= 8:
            raise ValueError("model_frac must be in 0..8")
        if not 8 <= self.bg_frac <= 24:
            raise ValueError("bg_frac must be in 8..24")
        if not 1 <= self.max_half <= 255:
            raise ValueError("max_half must be in 1..255")
        if not 0 <= self.margin <= 255:
            raise ValueError("margin must be in 0..255")
        if not 8 <= self.coord_bits <= 14:
            raise ValueError("coord_bits must be in 8..14")
        if not 1 <= self.centre_frac <= 12:
            raise ValueError("centre_frac must be in 1..12")
        if not (1 <= self.weight_int <= 8 and 1 <= self.weight_frac <= 12):
            raise ValueError("weight format out of range")
        if not 0 <= self.rho_frac <= self.rho_out_frac:
            raise ValueError("rho_frac must be in 0..rho_out_frac")
        if not 1 <= self.kernel_bits <= 12:
            raise ValueError("kernel_bits must be in 1..12")
        if not 1 <= self.alpha_frac <= 16:
            raise ValueError("alpha_frac must be in 1..16")

    @classmethod
    def split(cls, kwargs: dict[str, Any]) -> tuple["FixedParams", dict[str, Any]]:
        names = {f.name for f in fields(cls)}
        mine = {k: v for k, v in kwargs.items() if k in names}
        return cls(**mine), {k: v for k, v in kwargs.items() if k not in names}

    def with_(self, **kw: Any) -> "FixedParams":
        return replace(self, **kw)


@dataclass(frozen=True)
class Widths:
    """Derived widths (bits) of every stored or computed quantity; see docs/fixed_point.md."""

    colour_bin: int       # colour bin index
    edge_bin: int         # edge bin index
    win_max: int          # max window extent 2*MAX_HALF+1
    region_max: int       # max region extent win_max + 2*MARGIN
    pix_max: int          # max pixels in a window bounding box
    kval: int             # kernel value k (1 for flat; 1..2**KB for Epanechnikov)
    hist: int             # histogram accumulator H[u] (sum of k)
    count: int            # pixel count N[u]
    possum: int           # signed per-bin position sums SX[u], SY[u]
    kd: int               # kernel compare terms 4 dx^2 h^2, 4 dy^2 w^2, D = w^2 h^2
    sqrt_in: int          # input of the Bhattacharyya isqrt (even)
    rho_sum: int          # S = sum of isqrt terms
    ratio_q: int          # quotient bits of Q * 2**(2WF) / H (= 2 (WI + WF))
    weight: int           # per-bin weight WI.WF
    sw: int               # sum w N
    swx: int              # signed sum w SX (and w SY)
    shift_q: int          # quotient bits of the centre-shift division
    centre: int           # centre Q(coord_bits).CF
    rho_out: int          # rho output (0 .. 2**rho_out_frac inclusive)
    alpha: int            # alpha (0 .. 2**AF inclusive)


def widths(tp: TrackerParams, fp: FixedParams) -> Widths:
    """Compute every width from the parameters (worst case over all windows)."""
    win_max = 2 * fp.max_half + 1
    pix_max = win_max * win_max
    kmax = 1 if tp.kernel == "flat" else (1 << fp.kernel_bits)
    hist_max = pix_max * kmax
    count = bits_for(pix_max)
    possum_max = pix_max * fp.max_half
    kd_max = 4 * fp.max_half ** 2 * win_max ** 2 + win_max ** 4  # num + D bound
    sqrt_in = bits_for(hist_max * hist_max << (2 * fp.rho_frac))
    sqrt_in += sqrt_in % 2
    n_bins = max(tp.n_colour_bins, tp.n_edge_bins)
    rho_sum = bits_for(hist_max << fp.rho_frac) + 1  # S <= K * 2**RF (Cauchy-Schwarz), +1 for floor slack
    weight = fp.weight_int + fp.weight_frac
    w_max = (1 << weight) - 1
    sw = bits_for(w_max * pix_max)
    swx = bits_for(w_max * possum_max) + 1
    shift_q = bits_for(fp.max_half << fp.centre_frac)
    del n_bins
    return Widths(
        colour_bin=3 * tp.colour_bits, edge_bin=tp.edge_bins_log2, win_max=win_max,
        region_max=win_max + 2 * fp.margin, pix_max=pix_max, kval=bits_for(kmax), hist=bits_for(hist_max),
        count=count, possum=bits_for(possum_max) + 1, kd=bits_for(kd_max), sqrt_in=sqrt_in,
        rho_sum=rho_sum, ratio_q=2 * weight, weight=weight, sw=sw, swx=swx, shift_q=shift_q,
        centre=fp.coord_bits + fp.centre_frac, rho_out=fp.rho_out_frac + 1, alpha=fp.alpha_frac + 1)
