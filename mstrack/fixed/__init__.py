"""Bit-accurate fixed-point model of the mstrack hardware (the executable specification).

Public API: the model (:class:`FixedTracker`, :class:`FixedParams`, :func:`widths`) and the
result word of the core, v1 and v2 (layout, width, pack, unpack; docs/integration.md,
"Result word")::

    from mstrack.fixed import unpack_result
    fields = unpack_result(word)            # {"cx": ..., "cy": ..., "flags": ..., "flag_lost": ...}
"""
from .formats import FixedParams, Widths, widths
from .tracker import RESULT_FIELDS, FixedTracker
from .vhdl_pkg import (RESULT_FLAGS, STATUS_V2, STOP_CODES_V2, core_generics, pack_result, pack_result_v2,
                       result_layout, result_layout_v2, result_width, result_width_v2, unpack_result,
                       unpack_result_v2)

__all__ = ["FixedParams", "Widths", "widths", "FixedTracker", "RESULT_FIELDS",
           "core_generics", "RESULT_FLAGS", "result_layout", "result_width", "pack_result", "unpack_result",
           "STATUS_V2", "STOP_CODES_V2", "result_layout_v2", "result_width_v2", "pack_result_v2",
           "unpack_result_v2"]
