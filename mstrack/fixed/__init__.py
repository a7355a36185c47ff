"""Bit-accurate fixed-point model of the mstrack hardware (the executable specification)."""
from .formats import FixedParams, Widths, widths
from .tracker import RESULT_FIELDS, FixedTracker

__all__ = ["FixedParams", "Widths", "widths", "FixedTracker", "RESULT_FIELDS"]
