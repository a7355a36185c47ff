"""The tracker layer: parameters, result types, frame checks, the float reference and the public API.

* :mod:`.params`, :mod:`.types`, :mod:`.frames`: TrackerParams, Box / TrackResult / Status, frame
  checks and box clipping (shared by every model, float and fixed-point).
* The float reference of tracker v1 (the paper's colour + edge fusion), by what each part does:
  :mod:`.features` (colour bins, Sobel / edge bins), :mod:`.kernel` (kernel window, histograms,
  Bhattacharyya, the reference mean-shift), :mod:`.area` (the numpy fast path: histograms over a
  search area), :mod:`.numba_kernels` (the ``@jit`` kernels), :mod:`.float_model` (FloatTracker:
  fusion and the choice of path).
* :mod:`.float_v2` (tracker v2, float reference) and :mod:`.features_v2` (v2 feature studies).
* :mod:`.tracker`: the public :class:`~.tracker.Tracker` / :class:`~.tracker.TrackerMeanShift`.

:mod:`mstrack.fixed` (the bit-accurate model, the executable specification of rtl/) belongs to
this layer too.  Nothing here imports :mod:`mstrack.eval`, :mod:`mstrack.hw`, :mod:`mstrack.io` or
:mod:`mstrack.cli` (tests/test_layout.py).
"""
