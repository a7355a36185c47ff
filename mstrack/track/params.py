"""Tracker parameters shared by the float reference and the fixed-point model.

Names follow the paper and Comaniciu et al. 2003 (see docs/algorithm.md).
The fixed-point widths live in :class:`mstrack.fixed.formats.FixedParams`.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields, replace
from typing import Any, Literal

Features = Literal["fused", "colour", "edge"]
Preset = Literal["paper", "v2"]
Kernel = Literal["flat", "epanechnikov"]

#: Accepted spellings of the string parameters (case-insensitive) -> canonical value.  The
#: canonical values are the ones stored in :class:`TrackerParams`, reports and cache keys; the
#: short forms are the ones in tracker names (``mstrack-colour-epan``).
ALIASES: dict[str, dict[str, str]] = {
    "features": {"fused": "fused", "fusion": "fused", "colour": "colour", "color": "colour",
                 "edge": "edge", "edges": "edge"},
    "kernel": {"flat": "flat", "uniform": "flat", "epanechnikov": "epanechnikov", "epan": "epanechnikov"},
    "preset": {"paper": "paper", "v2": "v2"},
}


def canonical(name: str, value: Any) -> Any:
    """The canonical spelling of ``value`` for the string parameter ``name`` (see :data:`ALIASES`):
    ``canonical("kernel", "Epan") == "epanechnikov"``.  Values that are not known aliases (and
    non-strings) are returned unchanged, to be refused by the parameter check with the valid names."""
    if isinstance(value, str):
        return ALIASES.get(name, {}).get(value.strip().lower(), value)
    return value


def _choices(name: str) -> str:
    canon = dict.fromkeys(ALIASES[name].values())
    return ", ".join(f"'{c}'" + (f" (or {', '.join(repr(a) for a, v in ALIASES[name].items() if v == c and a != c)})"
                                 if any(v == c and a != c for a, v in ALIASES[name].items()) else "")
                     for c in canon)


class ParamTypeError(TypeError, ValueError):
    """A parameter of the wrong type (e.g. ``max_iter=1.5``); both a TypeError and a ValueError."""


def check_param_types(obj: Any) -> None:
    """Check the ``int`` / ``float`` fields of the frozen dataclass ``obj`` (shared by every layer).

    ``int`` fields take a Python or numpy integer (not bool, not float); ``float`` fields a real,
    finite number (not bool).  Numpy scalars are converted to ``int`` / ``float`` in place.
    Raises :class:`ParamTypeError` naming the field.
    """
    for f in fields(obj):
        kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "")
        v = getattr(obj, f.name)
        if kind == "int":
            if isinstance(v, bool) or not isinstance(v, numbers.Integral):
                raise ParamTypeError(f"{f.name} must be an integer, got {v!r} ({type(v).__name__})")
            object.__setattr__(obj, f.name, int(v))
        elif kind == "float":
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise ParamTypeError(f"{f.name} must be a finite real number, got {v!r} ({type(v).__name__})")
            object.__setattr__(obj, f.name, float(v))


#: Tracker v2's defaults that make it the joint tracker (the default v2 tracker, ``mstrack-v2``): the joint colour x gradient-
#: orientation bins, the gated scale test and the loss flag's thresholds chosen for them
#: (docs/results_v2_mean.md).  Core v2: generics ORIENT_T 64, SCALE_TEST_D256 13
#: (mstrack.hw.cosim.CoreConfigV2).
V2_JOINT: dict[str, Any] = {"orient_T": 64, "scale_test": 0.05, "scale_test_gate": True, "loss_rho": 0.69, "loss_contrast": 0.25}

#: Tracker v2 on colour alone (tracker ``mstrack-v2-colour``):
#: ``TrackerParams(preset="v2", **V2_COLOUR)``.  512 bins instead of 4608: a smaller, faster core
#: (ORIENT_T -1, SCALE_TEST_D256 0), about twice the float reference's speed, and lower accuracy
#: (docs/results.md).
V2_COLOUR: dict[str, Any] = {"orient_T": 0, "scale_test": 0.0, "scale_test_gate": False, "loss_rho": 0.88, "loss_contrast": 0.19}


@dataclass(frozen=True)
class TrackerParams:
    """Algorithm parameters (identical meaning in every layer).

    Attributes
    ----------
    features : {"fused", "colour", "edge"}
        Which feature(s) drive the result; "fused" runs both and blends them.
        Aliases (:data:`ALIASES`, case-insensitive): "color", "fusion", "edges".
    kernel : {"flat", "epanechnikov"}
        Kernel profile used for the histograms: flat (1 inside d2 < 1, the
        paper's hardware) or Epanechnikov (1 - d2).  The mean-shift step uses
        the shadow of the profile, which is flat for both.
    colour_bits : int
        Bits kept per R, G, B channel; B = 2**colour_bits bins per channel,
        B**3 colour bins (default 3 -> 8 per channel -> 512 bins).
    edge_bins_log2 : int
        log2 of the number of edge bins E (default 4 -> 16 bins).
    edge_shift : int
        Edge bin = min(E - 1, floor(|G| / 2**edge_shift)), |G| = |Gx| + |Gy|
        of the 3x3 Sobel on the grey image (|G| in 0..2040).  Default 5: the
        16 bins span |G| = 0..511, stronger edges saturate into the last bin.
    max_iter : int
        Maximum mean-shift iterations per feature per frame (paper: 20).
    eps2 : float
        Stop when the squared shift of one iteration is below eps2 (px^2).
    preset : {"paper", "v2"}
        "paper": the paper's algorithm (fixed-size window, colour + edge
        fusion), bit for bit as before; "v2": tracker v2 (docs/algorithm.md,
        "Tracker v2"; the joint colour x orientation bins by default,
        :data:`V2_COLOUR` for colour alone).  ``features`` defaults to "fused"
        for the paper and "colour" for v2 (the colour that the v2 bins join).

    The remaining fields are tracker v2's (ignored by the paper preset):

    pad : float
        The mean-shift window is the box grown by ``pad`` x its size (0.25:
        each half-size x 1.25); the ring it adds shows the target growing.
    bg_ring : float
        Background ring for the background-weighted model: the box grown by
        ``bg_ring`` x its size on each side, less the box.
    max_window : int
        Largest window extent in (decimated) pixels; a larger target is tracked
        on every 2nd / 4th / 8th pixel.
    scale_gain, scale_step, scale_reg : float
        Scale update per frame: s = clamp(1 + gain (clamp(est, 1 - step,
        1 + step) - 1) - reg (w / w0 - 1), 1 - step, 1 + step), est =
        sqrt(spread / spread at init).  scale_gain = 0 keeps the init size.
    conf_lost, conf_uncertain, conf_reacquire : float
        Search state from the confidence: below conf_lost the tracker searches
        (wide search from the next frame on, nothing learnt); below
        conf_uncertain nothing is learnt; a wide search ends at conf_reacquire
        or above.
    loss_rho, loss_contrast, loss_smooth : float
        Loss flag (``TrackResult.ok`` False): rho < loss_rho x rho at init and
        contrast = share in the box - share in the window's ring < loss_contrast,
        both smoothed by s <- s + loss_smooth (x - s) (1: no smoothing; a power
        of two for the fixed model) (docs/algorithm.md, "v2.7a Loss flag").
        Defaults 0.69 / 0.25 (the joint tracker's); :data:`V2_COLOUR`'s 0.88 / 0.19.
    scale_test_margin : float
        The gated scale test's margin (experimental, off by default: 0): a scaled window wins
        only when its rho exceeds the best so far by more than the margin, so that a verdict
        does not hang on the last bits of rho (docs/results_accuracy22.md).
    rho_stop_margin : float
        The mean shift's rho stop with a margin (experimental, off by default: 0): a step is
        refused only when rho falls by more than the margin, so that the loop crosses the flat top
        of rho (where the padded window holds the whole target) instead of halting short of the
        optimum (docs/results_accuracy22.md).  The float model then runs its numpy path.
    search_widen : int
        Widening of the wide search (experimental, off by default: 0): while lost, the search's
        decimation (2 D) doubles again after every ``search_widen`` lost frames, up to 16 (the
        region RAM's bound), so that its start points reach 2x, 4x ... as far at the same memory
        (docs/results_accuracy22.md).
    loss_ref_running : bool
        Loss flag against the running reference rho_ref (the confidence's, as it is before the
        frame's update) instead of rho at init (experimental, off by default; docs/results_accuracy22.md).
    loss_jump, loss_stay : float
        Motion latch of the loss flag (experimental, off by default: loss_jump 0): a frame whose
        centre step differs from the previous frame's step by more than loss_jump x (w + h) / 2
        (L1 norm, frame px; w, h the box before the frame's resize) sets a latch that stays set
        while rho_s < loss_stay x the loss flag's reference; the flag is raised while the latch
        is set (docs/algorithm.md "v2.7a Loss flag", docs/results_accuracy22.md).  The fixed
        model needs loss_jump in sixteenths.
    scale_ring_guard : float
        Shrink guard of the scale update (experimental, off by default: 0): a size step that
        shrinks the box (s < 1) is not taken while the share of target-coloured pixels in the
        window's ring around the box is at least scale_ring_guard x their share in the box (the
        target still fills the ring: the box is not too large), so that the box can follow a
        shrinking target without the pull toward the init size (scale_reg 0) and does not
        collapse inside a uniform target (docs/algorithm.md "v2.5a", docs/results_accuracy22.md).
    model_rate : float
        Guarded model update (experimental, off by default: 0): on frames whose search state is
        ok and whose loss flag is down, the background-weighted model q' is learnt again at the
        tracked box in the frame (the init's CBWH model, the same ring) and blended in:
        r <- r + model_rate (q'_new - r) (r starts at q'_0, the init's), and the tracker uses
        q' = q'_0 + model_mix (r - q'_0); t (the target-coloured bins) becomes the new model's.  Powers of
        two for the fixed model (docs/algorithm.md "v2.6a", docs/results_accuracy22.md).
    model_mix : float
        The running model's share in the guarded model update (1: the running model alone; 1/2:
        half the init model is always kept).  Only with model_rate > 0.
    model_contrast : float
        A further guard of the model update: it learns only on frames whose smoothed contrast
        (the loss flag's contrast_s, share - ring_share) is at least model_contrast (default -1:
        every ok, unflagged frame).  Only with model_rate > 0.
    chroma_bins : int
        Normalised-chromaticity colour bins (experimental, off by default: 0): k = chroma_bins
        intensity bits (1 <= k <= colour_bits); with S = R + G + B and b = colour_bits, bin =
        ((S >> (10 - k)) << 2b) | (floor(2**b R / (S + 1)) << b) | floor(2**b G / (S + 1)):
        chromaticity r, g at b bits and the intensity at k bits, in place of R, G, B at b bits (the
        joint bins join these).  The float model then runs its numpy path (docs/algorithm.md "v2.2b").
    ref_rate : float
        Rate of the running references of rho and share (confident frames).
    search_step : float
        Wide search start points: the last centre +- search_step window
        sizes in x and y (8 points).
    search_iter : int
        Mean-shift iterations from each start point of the wide search.
    motion_gain : float
        Constant-velocity start (experimental, off by default: 0): the mean
        shift starts at the last centre + motion_gain x the last centre step
        (the step is set to 0 unless the frame's search state is ok)
        (docs/results_v2_mean.md).
    scale_test, scale_test_mix : float
        Scale test by rho (default 0.05, gated; 0 = off, :data:`V2_COLOUR`): two more passes
        at the final centre with the window scaled by 1 -+ scale_test; the
        scale of the largest rho (1, 1 - scale_test or 1 + scale_test) is the
        rho estimate, and the size step uses scale_test_mix x it + (1 -
        scale_test_mix) x the spread estimate; scale_test_gate: instead, the
        spread estimate is kept only where the rho test moves the same way
        (else no step; the default) (docs/results_v2_mean.md).
    orient_T : int
        Joint colour x gradient-orientation bins (default 64; 0 = colour bins
        only, :data:`V2_COLOUR`): bin = colour bin x 9 + octant of the 3x3 Sobel
        gradient of the grey frame where |Gx| + |Gy| >= orient_T, 8 for flatter
        pixels (9 x 512 bins) (docs/algorithm.md, docs/results_v2_mean.md).
    """

    features: Features = None  # type: ignore[assignment]  # resolved per preset
    kernel: Kernel = "flat"
    colour_bits: int = 3
    edge_bins_log2: int = 4
    edge_shift: int = 5
    max_iter: int = 20
    eps2: float = 1.0
    preset: Preset = "paper"
    pad: float = 0.25
    bg_ring: float = 0.625
    max_window: int = 127
    scale_gain: float = 0.3
    scale_step: float = 0.1
    scale_reg: float = 0.1
    conf_lost: float = 0.4
    conf_uncertain: float = 0.5
    conf_reacquire: float = 0.5
    loss_rho: float = 0.69
    loss_contrast: float = 0.25
    loss_smooth: float = 0.5
    ref_rate: float = 0.015625
    search_step: float = 1.0
    search_iter: int = 5
    motion_gain: float = 0.0
    scale_test: float = 0.05
    scale_test_mix: float = 1.0
    scale_test_gate: bool = True
    orient_T: int = 64
    loss_ref_running: bool = False
    scale_test_margin: float = 0.0
    search_widen: int = 0
    rho_stop_margin: float = 0.0
    loss_jump: float = 0.0
    loss_stay: float = 0.95
    scale_ring_guard: float = 0.0
    model_rate: float = 0.0
    model_mix: float = 1.0
    model_contrast: float = -1.0
    chroma_bins: int = 0

    def __post_init__(self) -> None:
        for name in ALIASES:
            object.__setattr__(self, name, canonical(name, getattr(self, name)))
        if self.preset not in ("paper", "v2"):
            raise ValueError(f"preset must be {_choices('preset')}, got {self.preset!r}")
        if self.features is None:
            object.__setattr__(self, "features", "fused" if self.preset == "paper" else "colour")
        check_param_types(self)
        if self.features not in ("fused", "colour", "edge"):
            raise ValueError(f"features must be {_choices('features')}, got {self.features!r}")
        if self.kernel not in ("flat", "epanechnikov"):
            raise ValueError(f"kernel must be {_choices('kernel')}, got {self.kernel!r}")
        if not 1 <= self.colour_bits <= 8:
            raise ValueError("colour_bits must be in 1..8")
        if not 1 <= self.edge_bins_log2 <= 8:
            raise ValueError("edge_bins_log2 must be in 1..8")
        if not 0 <= self.edge_shift <= 11:
            raise ValueError("edge_shift must be in 0..11")
        if self.max_iter < 1:
            raise ValueError("max_iter must be >= 1")
        if not self.eps2 > 0:
            raise ValueError("eps2 must be > 0")
        if self.preset == "v2":
            if self.features != "colour":
                raise ValueError(f"preset 'v2' tracks on colour only (features='colour'); features="
                                 f"{self.features!r} is the paper preset: preset='paper', features={self.features!r}")
            for name, lo, hi in (("pad", 0.0, 2.0), ("bg_ring", 0.05, 4.0), ("scale_gain", 0.0, 1.0),
                                 ("scale_step", 0.0, 0.5), ("scale_reg", 0.0, 1.0), ("conf_lost", 0.0, 1.0),
                                 ("conf_uncertain", 0.0, 1.0), ("conf_reacquire", 0.0, 1.0),
                                 ("loss_rho", 0.0, 2.0), ("loss_contrast", -1.0, 1.0), ("loss_smooth", 0.0, 1.0),
                                 ("ref_rate", 0.0, 1.0), ("search_step", 0.0, 4.0), ("motion_gain", 0.0, 2.0),
                                 ("scale_test", 0.0, 0.5), ("scale_test_mix", 0.0, 1.0),
                                 ("scale_test_margin", 0.0, 0.5), ("rho_stop_margin", 0.0, 0.5),
                                 ("loss_jump", 0.0, 8.0), ("loss_stay", 0.0, 2.0),
                                 ("scale_ring_guard", 0.0, 4.0), ("model_rate", 0.0, 1.0), ("model_mix", 0.0, 1.0),
                                 ("model_contrast", -1.0, 1.0)):
                if not lo <= getattr(self, name) <= hi:
                    raise ValueError(f"{name} must be in {lo}..{hi}, got {getattr(self, name)}")
            if not self.conf_lost <= self.conf_uncertain:
                raise ValueError("conf_lost must be <= conf_uncertain")
            if not 7 <= self.max_window <= 1023:
                raise ValueError("max_window must be in 7..1023")
            if not 0 <= self.chroma_bins <= self.colour_bits:
                raise ValueError(f"chroma_bins must be in 0..colour_bits ({self.colour_bits}), got {self.chroma_bins}")
            if self.search_widen < 0:
                raise ValueError("search_widen must be >= 0")
            if self.search_iter < 1:
                raise ValueError("search_iter must be >= 1")
            if not 0 <= self.orient_T <= 2040:
                raise ValueError("orient_T must be in 0..2040")

    @property
    def n_colour_bins(self) -> int:
        return 1 << (3 * self.colour_bits)

    @property
    def n_bins_v2(self) -> int:
        """Bins of tracker v2's feature: the colour bins, x 9 with orient_T > 0."""
        return self.n_colour_bins * (9 if self.orient_T > 0 else 1)

    @property
    def n_edge_bins(self) -> int:
        return 1 << self.edge_bins_log2

    @classmethod
    def field_names(cls) -> frozenset[str]:
        """Names of the fields (the keyword arguments :class:`mstrack.Tracker` takes for them)."""
        return frozenset(f.name for f in fields(cls))

    @classmethod
    def split(cls, kwargs: dict[str, Any]) -> tuple["TrackerParams", dict[str, Any]]:
        """Take this class's fields out of ``kwargs``; return (params, rest)."""
        names = {f.name for f in fields(cls)}
        mine = {k: v for k, v in kwargs.items() if k in names}
        rest = {k: v for k, v in kwargs.items() if k not in names}
        return cls(**mine), rest

    def with_(self, **kw: Any) -> "TrackerParams":
        return replace(self, **kw)
