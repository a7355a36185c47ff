"""Evaluation: metrics, the evaluation runner (``mstrack eval``, parallel / distributed), reports,
OpenCV baselines and the float vs fixed-point agreement study.

Imports :mod:`mstrack.track`, :mod:`mstrack.fixed`, :mod:`mstrack.io` and :mod:`mstrack.versions`;
never :mod:`mstrack.hw` or :mod:`mstrack.cli` (tests/test_layout.py).
"""
