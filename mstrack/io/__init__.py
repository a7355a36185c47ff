"""Frames in and out: dataset sequences and videos (:mod:`.data`), synthetic scenes with exact ground
truth (:mod:`.synthetic`).

Shared by :mod:`mstrack.eval` (sequences to score) and :mod:`mstrack.hw` (test vectors, simulation
frames), so it sits below both: it imports only :mod:`mstrack.track` (tests/test_layout.py).
"""
