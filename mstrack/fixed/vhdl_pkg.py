"""VHDL generics and the generated package of formats, from the Python model.

``core_generics(tp, fp, lanes)`` is the one place that turns model parameters
into the VHDL generics of every block (tests pass them to each simulation);
``write_formats_pkg()`` writes rtl/ms_formats_pkg.vhd with the defaults
(run ``python -m mstrack.fixed.vhdl_pkg``; a test checks the file is current).
"""
from __future__ import annotations

import sys
from pathlib import Path

from ..track.params import TrackerParams
from .formats import FixedParams, widths
from .primitives import bits_for

PKG_PATH = Path(__file__).resolve().parents[2] / "rtl" / "ms_formats_pkg.vhd"
DEFAULT_LANES = 4


def core_generics(tp: TrackerParams | None = None, fp: FixedParams | None = None,
                  lanes: int = DEFAULT_LANES) -> dict[str, int]:
    """All generics of the core (primary and derived), as natural numbers."""
    tp = tp or TrackerParams()
    fp = fp or FixedParams()
    w = widths(tp, fp)
    if lanes < 1 or lanes & (lanes - 1):
        raise ValueError("lanes must be a power of two")
    region_max = w.region_max
    stride = -(-region_max // lanes)
    g = {
        "LANES": lanes,
        "COLOUR_BITS": tp.colour_bits,
        "EDGE_BINS_LOG2": tp.edge_bins_log2,
        "EDGE_SHIFT": tp.edge_shift,
        "FEATURES": {"fused": 0, "colour": 1, "edge": 2}[tp.features],
        "KERNEL_EPAN": int(tp.kernel == "epanechnikov"),
        "KERNEL_BITS": fp.kernel_bits,
        "MAX_HALF": fp.max_half,
        "MARGIN": fp.margin,
        "COORD_W": fp.coord_bits,
        "CF": fp.centre_frac,
        "WI": fp.weight_int,
        "WF": fp.weight_frac,
        "RF": fp.rho_frac,
        "AF": fp.alpha_frac,
        "RHO_OUT_FRAC": fp.rho_out_frac,
        "MAX_ITER": tp.max_iter,
        "EPS2": int(round(tp.eps2 * (1 << (2 * fp.centre_frac)))),
        # derived
        "HALF_W": bits_for(fp.max_half),
        "REGION_MAX": region_max,
        "REGION_W": bits_for(region_max),
        "STRIDE": stride,
        "ADDR_W": bits_for(region_max * stride - 1),
        "KVAL_W": w.kval,
        "HIST_W": w.hist,
        "COUNT_W": w.count,
        "POSSUM_W": w.possum,
        "KD_W": w.kd,
        "SQRT_IN_W": w.sqrt_in,
        "RHO_SUM_W": w.rho_sum,
        "RATIO_Q_W": w.ratio_q,
        "WEIGHT_W": w.weight,
        "SW_W": w.sw,
        "SWX_W": w.swx,
        "SHIFT_Q_W": w.shift_q,
        "CENTRE_W": bits_for(region_max) + fp.centre_frac,
        "CENTRE_ABS_W": w.centre,
        "ITER_W": bits_for(tp.max_iter),
        "RHO_OUT_W": w.rho_out,
        "ALPHA_W": w.alpha,
        "WIN_W": bits_for(2 * fp.max_half + 1),
    }
    g["RESULT_W"] = result_width(g)
    return g


def v2_scale_generics(tp: TrackerParams | None = None, fp: FixedParams | None = None,
                      lanes: int = DEFAULT_LANES) -> dict[str, int]:
    """Generics of the v2 statistics, scale and loss blocks (ms_target_stats, ms_share, ms_spread,
    ms_scale, ms_resize, ms_ring_share, ms_loss_filter, ms_loss_flag, ms_confidence, ms_ref_update),
    derived from the model (docs/fixed_point.md, "Tracker v2").

    Worst case over all windows: the counts hold the largest window's pixels; st2 the largest window
    times the largest d2q (2**(KB + 1) - 1, the bound docs/fixed_point.md states; inside the ellipse
    d2q < 2**KB in fact); spread = floor(st2 2**16 / nt) <= that d2q in Q.16.  ms_scale's ratio
    division needs only RATIO_Q_W quotient bits: every ratio r >= 2**RATIO_Q_W - 1 gives
    isqrt(r 2**16) >= 1 + step, clamped to the same value, so saturating there is exact.  The size
    ratio w8 2**16 / w0_8 (w0_8 >= 3 px, w8 < 2**SIZE_W) never saturates with WR_Q_W bits.
    """
    from .blocks_v2 import ONE, SIZE_FRAC, q16, rate_shift, sixteenths
    from .primitives import ms_isqrt

    tp = tp or TrackerParams(preset="v2")
    fp = fp or FixedParams()
    g = core_generics(tp, fp, lanes)
    w = widths(tp, fp)
    kb = fp.kernel_bits
    d2q_max = (1 << (kb + 1)) - 1
    step = q16(tp.scale_step)
    hi = ONE + step
    ratio_q = 1
    while int(ms_isqrt(((1 << ratio_q) - 1) << 16)) < hi:
        ratio_q += 1
    size_w = fp.coord_bits + SIZE_FRAC
    return {
        "LANES": lanes,
        "BIN_W": 3 * tp.colour_bits,
        "HALF_W": g["HALF_W"],
        "REGION_W": g["REGION_W"],
        "KERNEL_BITS": kb,
        "KT_W": kb + 1,
        "PAD16": sixteenths(tp.pad, "pad"),
        "COUNT_W": w.count,
        "ST2_W": bits_for(w.pix_max * d2q_max),
        "SHARE_W": bits_for(ONE),
        "SPREAD_W": bits_for(d2q_max << 16),
        "SIZE_W": size_w,
        "COORD_W": fp.coord_bits,
        "SCALE_W": bits_for(hi),
        "SCALE_GAIN": q16(tp.scale_gain),
        "SCALE_REG": q16(tp.scale_reg),
        "SCALE_STEP": step,
        "RATIO_Q_W": ratio_q,
        "WR_Q_W": bits_for((((1 << size_w) - 1) << 16) // (3 << SIZE_FRAC)),
        # loss flag, confidence, references: rho, share and their references are Q1.16 (SHARE_W bits);
        # the contrast share - ring_share and its smoothed value are signed Q1.16 (SHARE_W + 1 bits)
        "CON_W": bits_for(ONE) + 1,
        "LOSS_K": rate_shift(tp.loss_smooth),
        "REF_K": rate_shift(tp.ref_rate),
        "LOSS_RHO": q16(tp.loss_rho),
        "LOSS_CONTRAST": q16(tp.loss_contrast),
    }


def formats_pkg_text(lanes: int = DEFAULT_LANES) -> str:
    g = core_generics(lanes=lanes)
    lines = [
        "-- ms_formats_pkg: GENERATED by `python -m mstrack.fixed.vhdl_pkg` from mstrack.fixed.formats.",
        "-- Do not edit by hand.  Default generics of the core; widths derived by the Python model.",
        "package ms_formats_pkg is",
    ]
    lines += [f"  constant D_{k:<15s}: natural := {v};" for k, v in g.items()]
    lines += ["end package;", ""]
    return "\n".join(lines)


def write_formats_pkg(path: Path = PKG_PATH) -> Path:
    path.write_text(formats_pkg_text())
    return path



# ----------------------------------------------------------------------------- result word
RESULT_FLAGS = ("init", "clipped", "lost", "error", "rejected", "no_target", "overflow", "reserved")
ERR_CODE_W = 3
FRAME_COUNT_W = 16


def result_layout(g: dict[str, int] | None = None) -> list[tuple[str, int, int]]:
    """Fields of result word v1, LSB first: ``[(name, offset, width), ...]``.

    ms_tracker packs the same order (rtl/ms_tracker.vhd); the widths follow the generics ``g``
    (default: :func:`core_generics` of the default parameters).  Fields: ``cx, cy`` target centre,
    unsigned Q(COORD_W).CF px; ``rho_c, rho_e`` Bhattacharyya coefficients Q.RHO_OUT_FRAC;
    ``alpha_c`` colour weight Q.AF; ``iter_c, iter_e`` iterations; ``stop_c, stop_e`` stop codes
    (0 shift, 1 rho, 2 max_iter, 3 lost); ``flags`` (bits :data:`RESULT_FLAGS`); ``err_code``
    (stream error, rtl/ms_stream_pkg.vhd); ``box_w, box_h`` box size (px); ``frame_count``
    (frames since reset, mod 2**16).  The word is :func:`result_width` bits wide.
    """
    g = g or core_generics()
    win_w = g["WIN_W"]
    fields_ = [("cx", g["CENTRE_ABS_W"]), ("cy", g["CENTRE_ABS_W"]), ("rho_c", g["RHO_OUT_W"]),
               ("rho_e", g["RHO_OUT_W"]), ("alpha_c", g["ALPHA_W"]), ("iter_c", g["ITER_W"]),
               ("iter_e", g["ITER_W"]), ("stop_c", 2), ("stop_e", 2), ("flags", len(RESULT_FLAGS)),
               ("err_code", ERR_CODE_W), ("box_w", win_w), ("box_h", win_w),
               ("frame_count", FRAME_COUNT_W)]
    out, off = [], 0
    for name, w in fields_:
        out.append((name, off, w))
        off += w
    return out


def result_width(g: dict[str, int] | None = None) -> int:
    """Result word width: the fields rounded up to a multiple of 8 bits."""
    name, off, w = result_layout(g)[-1]
    return -(-(off + w) // 8) * 8


def pack_result(fields: dict[str, int], g: dict[str, int] | None = None) -> int:
    """Pack the fields of :func:`result_layout` (missing ones are 0) into one result word v1.

    Raises ValueError for an unknown field or a value that is negative or does not fit its width.
    """
    word = 0
    layout = result_layout(g)
    extra = set(fields) - {name for name, _, _ in layout}
    if extra:
        raise ValueError(f"unknown result field(s): {sorted(extra)}")
    for name, off, w in layout:
        v = int(fields.get(name, 0))
        if v < 0 or v >= 1 << w:
            raise ValueError(f"result field {name} = {v} does not fit in {w} bits")
        word |= v << off
    return word


def unpack_result(word: int, g: dict[str, int] | None = None) -> dict[str, int]:
    """Split a result word v1 into its fields (:func:`result_layout`), as non-negative ints.

    Flags are also given one key each (``flag_<name>``, 0 or 1, names :data:`RESULT_FLAGS`).
    ``g``: the generics of the core that produced the word (default: the default core).
    The C driver's ``mstrack_decode_word`` (sw/mstrack_drv.c) decodes the same way (tested).

    >>> unpack_result(pack_result({"cx": 5, "flags": 4}))["flag_lost"]
    1
    """
    out = {name: (word >> off) & ((1 << w) - 1) for name, off, w in result_layout(g)}
    for i, f in enumerate(RESULT_FLAGS):
        out[f"flag_{f}"] = (out["flags"] >> i) & 1
    return out


# ----------------------------------------------------------------------------- result word v2
# Core v2 carries tracker v2's result: the box size follows the target, the status is
# one of STATUS_V2 and the confidence is a Q1.16 number.  The model side (this layout, packing
# FixedTrackerV2's raw integers, decoding) exists before the RTL so that core v2 is built against
# it; docs/architecture.md ("Result word v2") lists it.
STATUS_V2 = ("ok", "uncertain", "lost", "reacquired", "init", "clipped", "error")
STATUS_W = 3
CONF_W = 17                 # Q1.16, 0 .. 2**16
DECIM_LOG2_W = 3            # log2 D: 0 .. 4 (D = 16 while lost at D = 8)
SEARCHED_W = 4              # start points searched besides the centre while lost: 0 .. 8
STOP_CODES_V2 = ("shift", "rho", "max_iter", "lost")


def result_layout_v2(g: dict[str, int] | None = None) -> list[tuple[str, int, int]]:
    """Fields of result word v2, LSB first: (name, offset, width).

    ``cx, cy``: centre Q(COORD_W).CF in full-resolution pixel-index coordinates;
    ``w8, h8``: box size Q(COORD_W).8 px; ``rho``, ``confidence``: Q1.16;
    ``status``: index into :data:`STATUS_V2`; ``iter``, ``stop``: the winning mean shift;
    ``decim_log2``: log2 of the decimation used in the frame; ``searched``: extra start points;
    ``flags`` and ``err_code`` as in result word v1 (stream errors); ``frame_count``.
    """
    if g is None:
        from ..track.params import TrackerParams
        g = core_generics(TrackerParams(preset="v2"))
    size_w = g["COORD_W"] + 8
    fields_ = [("cx", g["CENTRE_ABS_W"]), ("cy", g["CENTRE_ABS_W"]), ("w8", size_w), ("h8", size_w),
               ("rho", g["RHO_OUT_W"]), ("confidence", CONF_W), ("status", STATUS_W),
               ("iter", g["ITER_W"]), ("stop", 2), ("decim_log2", DECIM_LOG2_W), ("searched", SEARCHED_W),
               ("flags", len(RESULT_FLAGS)), ("err_code", ERR_CODE_W), ("frame_count", FRAME_COUNT_W)]
    out, off = [], 0
    for name, w in fields_:
        out.append((name, off, w))
        off += w
    return out


def result_width_v2(g: dict[str, int] | None = None) -> int:
    """Result word v2 width: the fields rounded up to a multiple of 8 bits."""
    name, off, w = result_layout_v2(g)[-1]
    return -(-(off + w) // 8) * 8


def pack_result_v2(fields: dict[str, int], g: dict[str, int] | None = None) -> int:
    """Pack the fields of :func:`result_layout_v2` (missing ones are 0) into one word.

    Raises ValueError when a value is negative or does not fit its field (the widths are the
    specification: a value that does not fit is a model or width bug, never truncated silently).
    """
    word = 0
    layout = result_layout_v2(g)
    known = {name for name, _, _ in layout}
    extra = set(fields) - known
    if extra:
        raise ValueError(f"unknown result v2 field(s): {sorted(extra)}")
    for name, off, w in layout:
        v = int(fields.get(name, 0))
        if v < 0 or v >= 1 << w:
            raise ValueError(f"result v2 field {name} = {v} does not fit in {w} bits")
        word |= v << off
    return word


def unpack_result_v2(word: int, g: dict[str, int] | None = None) -> dict[str, int]:
    """Split a result word v2 into its fields; flags also one key each (flag_<name>)."""
    out = {name: (word >> off) & ((1 << w) - 1) for name, off, w in result_layout_v2(g)}
    for i, f in enumerate(RESULT_FLAGS):
        out[f"flag_{f}"] = (out["flags"] >> i) & 1
    return out


def result_fields_v2(extra: dict[str, int], frame_count: int = 0) -> dict[str, int]:
    """The result word v2 fields of one frame of FixedTrackerV2 (``TrackResult.extra``).

    Flags follow the status (init, clipped, lost, error); a model frame has no stream error, so
    ``err_code`` is ``extra["err_code"]`` when the status is error (a target the multi-target core
    held, :func:`mstrack.fixed.multi_capacity.held_result`) and 0 otherwise.
    """
    status = STATUS_V2[int(extra["status"])]
    d = int(extra["decimation"])
    flags = 0
    for name in ("init", "clipped", "lost", "error"):
        if status == name:
            flags |= 1 << RESULT_FLAGS.index(name)
    return {"cx": int(extra["cx"]), "cy": int(extra["cy"]), "w8": int(extra["w8"]), "h8": int(extra["h8"]),
            "rho": int(extra["rho"]), "confidence": int(extra["confidence"]), "status": int(extra["status"]),
            "iter": int(extra["iter"]), "stop": int(extra.get("stop", 0)), "decim_log2": d.bit_length() - 1,
            "searched": int(extra.get("searched", 0)), "flags": flags,
            "err_code": int(extra.get("err_code", 0)) if status == "error" else 0,
            "frame_count": frame_count & ((1 << FRAME_COUNT_W) - 1)}


# ----------------------------------------------------------------------------- result word of the multi-target core
# One word per live target per frame: result word v2 (result_width_v2 bits) with the target's id
# (its slot, 0 .. MAX_TARGETS - 1 <= 15) above it (docs/multi_target_core.md, "Ports and result
# stream"; the executable model is mstrack.hw.cosim_multi.CoreModelMulti).
TARGET_ID_W = 4


def result_layout_multi(g: dict[str, int] | None = None) -> list[tuple[str, int, int]]:
    """Fields of the multi-target core's result word, LSB first: :func:`result_layout_v2`, then
    ``target_id`` (:data:`TARGET_ID_W` bits) at bit :func:`result_width_v2` (160 by default)."""
    return [*result_layout_v2(g), ("target_id", result_width_v2(g), TARGET_ID_W)]


def result_width_multi(g: dict[str, int] | None = None) -> int:
    """Width of the multi-target core's result word: result word v2 + the id (164 by default)."""
    return result_width_v2(g) + TARGET_ID_W


def pack_result_multi(fields: dict[str, int], g: dict[str, int] | None = None) -> int:
    """:func:`pack_result_v2` of the fields with ``target_id`` above them (ValueError when it does not fit)."""
    tid = int(fields.get("target_id", 0))
    if not 0 <= tid < 1 << TARGET_ID_W:
        raise ValueError(f"target_id = {tid} does not fit in {TARGET_ID_W} bits")
    word = pack_result_v2({k: v for k, v in fields.items() if k != "target_id"}, g)
    return word | tid << result_width_v2(g)


def unpack_result_multi(word: int, g: dict[str, int] | None = None) -> dict[str, int]:
    """Split a word of the multi-target core: :func:`unpack_result_v2` and ``target_id``."""
    w = result_width_v2(g)
    return {**unpack_result_v2(word & ((1 << w) - 1), g), "target_id": (word >> w) & ((1 << TARGET_ID_W) - 1)}



# ---------------------------------------------------------------------------- core v2's target state
#: the fields of core v2's target state record that hold signed values (two's complement)
TARGET_STATE_SIGNED = ("rho_s", "con_s")


def target_state_layout_v2(g: dict[str, int]) -> list[tuple[str, int, int]]:
    """Fields of core v2's target state record (ms_tracker_v2 ``tgt_state`` / ``tgt_load_state``), LSB
    first: (name, offset, width).  The state :class:`mstrack.fixed.tracker_v2.FixedTrackerV2` carries
    from one frame to the next (:func:`target_state_v2`); ``g``: the core's generics."""
    fields_ = [("target_valid", 1), ("lost", 1), ("reported_lost", 1),
               ("c8x", g["CENTRE_ABS_W"]), ("c8y", g["CENTRE_ABS_W"]),
               ("w8", g["SIZE_W"]), ("h8", g["SIZE_W"]), ("w0_8", g["SIZE_W"]),
               ("frame_w", g["COORD_W"]), ("frame_h", g["COORD_W"]),
               ("rho_ref", g["SHARE_W"]), ("share_ref", g["SHARE_W"]), ("rho0", g["SHARE_W"]),
               ("rho_s", g["CON_W"]), ("con_s", g["CON_W"]), ("spread_ref", g["SPREAD_W"])]
    out, off = [], 0
    for name, w in fields_:
        out.append((name, off, w))
        off += w
    return out


def unpack_target_state_v2(word: int, g: dict[str, int]) -> dict[str, int]:
    """Split a target state record into its fields (``rho_s``, ``con_s`` signed)."""
    out = {}
    for name, off, w in target_state_layout_v2(g):
        v = (word >> off) & ((1 << w) - 1)
        if name in TARGET_STATE_SIGNED and v >> (w - 1):
            v -= 1 << w
        out[name] = v
    return out


def target_state_v2(trk, g: dict[str, int]) -> dict[str, int]:
    """The target state record's fields of a FixedTrackerV2 (``trk``) after its last frame; a tracker
    never initialised gives the empty record (all 0).  Only the fields the core keeps: the tracker's
    options that keep more state (model update, loss latch) are off in core v2."""
    if getattr(trk, "_shape", None) is None:
        return {name: 0 for name, _, _ in target_state_layout_v2(g)}
    fh, fw = trk._shape
    return {"target_valid": 1, "lost": int(trk.lost), "reported_lost": int(trk.reported_lost),
            "c8x": trk.c8[0], "c8y": trk.c8[1], "w8": trk.w8, "h8": trk.h8, "w0_8": trk.w0_8,
            "frame_w": fw, "frame_h": fh, "rho_ref": trk.rho_ref, "share_ref": trk.share_ref,
            "rho0": trk.rho0, "rho_s": trk.rho_s, "con_s": trk.con_s, "spread_ref": trk.spread_ref}


if __name__ == "__main__":
    print(write_formats_pkg(Path(sys.argv[1]) if len(sys.argv) > 1 else PKG_PATH))
