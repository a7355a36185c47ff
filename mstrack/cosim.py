"""Co-simulation support: what the RTL must output, computed by the fixed-point model.

The RTL result word (fields in :func:`mstrack.fixed.vhdl_pkg.result_layout`) is compared
field by field, frame by frame, with :func:`expected_results`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

import numpy as np

from .fixed import FixedParams, FixedTracker
from .fixed.blocks import ms_box_clip
from .fixed.vhdl_pkg import DEFAULT_LANES, RESULT_FLAGS, core_generics, result_layout
from .params import TrackerParams
from .types import Status

COMPARED_FIELDS = ("cx", "cy", "rho_c", "rho_e", "alpha_c", "iter_c", "iter_e", "stop_c", "stop_e",
                   "flags", "err_code", "box_w", "box_h", "frame_count")


def flags_word(**kw: int) -> int:
    """Pack named flags (RESULT_FLAGS) into the flags field."""
    v = 0
    for i, name in enumerate(RESULT_FLAGS):
        if kw.pop(name, 0):
            v |= 1 << i
    if kw:
        raise KeyError(f"unknown flags {sorted(kw)}")
    return v


def expected_results(frames: Iterable[np.ndarray], box: tuple[int, int, int, int],
                     tp: TrackerParams, fp: FixedParams, first_count: int = 0) -> list[dict[str, int]]:
    """Result fields the core must produce for ``frames`` with the init box on the first frame.

    box: integer (x, y, w, h) as given to the core's init port.
    """
    trk = FixedTracker(tp, fp)
    out: list[dict[str, int]] = []
    for i, frame in enumerate(frames):
        if i == 0:
            r = trk.init_int(frame, *box)
            fl = flags_word(init=1, clipped=int(r.status == Status.CLIPPED))
        else:
            r = trk.update(frame)
            fl = flags_word(lost=r.extra["lost"])
        e = r.extra
        ib = trk._t.box
        out.append({"cx": e["cx"], "cy": e["cy"], "rho_c": e["rho_c"], "rho_e": e["rho_e"],
                    "alpha_c": e["alpha_c"], "iter_c": e["iter_c"], "iter_e": e["iter_e"],
                    "stop_c": e["stop_c"], "stop_e": e["stop_e"], "flags": fl, "err_code": 0,
                    "box_w": ib.w, "box_h": ib.h, "frame_count": (first_count + i) & 0xFFFF})
    return out


def frame_words(frame: np.ndarray) -> np.ndarray:
    """(H, W) int array of 24-bit pixels R<<16 | G<<8 | B from a BGR uint8 frame."""
    f = frame.astype(np.int64)
    return (f[..., 2] << 16) | (f[..., 1] << 8) | f[..., 0]


def diff_fields(got: dict[str, int], exp: dict[str, int],
                fields: Sequence[str] = COMPARED_FIELDS) -> list[str]:
    """Human-readable mismatches between a DUT result and the model."""
    return [f"{k}: dut={got.get(k)} model={exp.get(k)}" for k in fields if got.get(k) != exp.get(k)]


@dataclass
class CoreConfig:
    """Model parameters + lanes -> the generics of ms_tracker."""

    tp: TrackerParams
    fp: FixedParams
    lanes: int = DEFAULT_LANES
    max_frame_w: int = 2048

    def generics(self) -> dict[str, int]:
        g = core_generics(self.tp, self.fp, self.lanes)
        g["MAX_FRAME_W"] = self.max_frame_w
        return g

    def layout(self) -> list[tuple[str, int, int]]:
        return result_layout(self.generics())


def clip_ok(box: tuple[int, int, int, int], w: int, h: int, fp: FixedParams) -> bool:
    """True if the core accepts this init box for a w x h frame."""
    return ms_box_clip(*box, w, h, fp.max_half)[0] is not None
