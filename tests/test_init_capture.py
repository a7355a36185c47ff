"""mstrack.fixed.multi_capacity.init_capture: what the shared-engine core captures of a target on the
frame it is added, and why the init job can learn the model from that slot (docs/multi_target_core.md,
"The init job").

* The model ``ms_bg_model`` learns from the captured rectangle alone (coordinates relative to it) equals
  the model ``FixedTrackerV2.init`` learns from the whole decimated frame: Qn, T, Q and O of every bin, on
  the dev set's init frames (joint bins) and on boxes at every border and corner of generated frames.
* The rectangle holds the ring and the init region, and fits the slot
  (:func:`mstrack.hw.multi_core.slot_shape`) for every box the tracker accepts, at max_window 127, 63
  and 31 on 1920 x 1080 frames.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mstrack.fixed.blocks_v2 import ms_bg_model
from mstrack.fixed.multi_capacity import init_capture, init_demand
from mstrack.fixed.tracker_v2 import FixedTrackerV2
from mstrack.track.params import V2_COLOUR, TrackerParams

SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"
DEV = ("Girl", "MotorRolling", "Couple", "Deer", "bag_vot", "Crossing")


def _model_from_slot(trk: FixedTrackerV2, frame: np.ndarray, box) -> tuple:
    """ms_bg_model on the captured rectangle of the init frame's bins, and the tracker's own model."""
    fh, fw = frame.shape[:2]
    ic = init_capture(box, fw, fh, trk.params, trk.fixed)
    bins = trk._bins(frame, ic.d)                       # the decimated frame's bins, border included
    x, y, w, h = ic.rect
    slot = bins[y: y + h, x: x + w]
    got = ms_bg_model(slot, ic.cd[0] - x, ic.cd[1] - y, ic.wb, ic.hb, trk.ring16, trk.params.n_bins_v2,
                      trk.fixed.bg_frac)
    return ic, got


def _same_model(got, want, what: str) -> None:
    for k in ("Qn", "T", "Q", "O"):
        a, b = np.asarray(getattr(got, k)), np.asarray(getattr(want, k))
        bad = np.nonzero(a != b)[0]
        assert bad.size == 0, f"{what}: {k} differs in {bad.size} bins, first {bad[:5].tolist()}"


@pytest.mark.parametrize("name", DEV)
def test_model_from_the_slot_is_inits(name):
    """The dev set's init frames with their ground-truth boxes (joint bins, tracker v2's defaults)."""
    from mstrack.io.data import load_sequence
    if not (SEQ_ROOT / name).is_dir():
        pytest.skip(f"{SEQ_ROOT / name} not found: the real init frames need ../shared/data/sequences")
    seq = load_sequence(SEQ_ROOT / name)
    frame, box = seq.frame(0), seq.init_box()
    trk = FixedTrackerV2()
    trk.init(frame, box)
    ic, got = _model_from_slot(trk, frame, box)
    _same_model(got, trk.model, name)
    assert int(np.asarray(got.O).sum()) > 0, "the ring counted nothing: the case does not test the ring"


#: boxes (x, y, w, h) on a 160 x 120 frame: every border and corner (the ring and the region clipped),
#: the middle, a box wider than the region's margin, and one large enough for D = 2
BORDER_BOXES = [(0, 0, 20, 16), (140, 0, 20, 16), (0, 104, 20, 16), (140, 104, 20, 16), (70, 0, 24, 18),
                (0, 50, 18, 24), (142, 50, 18, 24), (70, 102, 24, 18), (60, 45, 30, 28), (5, 5, 150, 40),
                (10, 20, 120, 90)]


@pytest.mark.parametrize("tp", [TrackerParams(preset="v2"), TrackerParams(preset="v2", **V2_COLOUR)],
                         ids=["joint", "colour"])
def test_model_from_the_slot_at_the_borders(tp):
    from mstrack.io.synthetic import make_scene
    frames, _ = make_scene(1, 160, 120, seed=7)
    for box in BORDER_BOXES:
        trk = FixedTrackerV2(tp)
        trk.init(frames[0], box)
        ic, got = _model_from_slot(trk, frames[0], box)
        _same_model(got, trk.model, f"box {box}")
        x, y, w, h = ic.rect
        rx, ry, rw, rh = ic.ring
        reg = ic.region
        assert x <= rx and y <= ry and rx + rw <= x + w and ry + rh <= y + h, f"box {box}: ring outside the rectangle"
        assert x <= reg.x and y <= reg.y and reg.x + reg.w <= x + w and reg.y + reg.h <= y + h, \
            f"box {box}: init region outside the rectangle"


def test_init_demand_is_the_capture():
    """init_demand's rectangle, first line and release line are init_capture's."""
    ic = init_capture((30, 20, 24, 30), 160, 120)
    dm = init_demand((30, 20, 24, 30), 160, 120, 0)
    x, y, w, h = ic.rect
    assert (dm.rows, dm.cols, dm.first_line, dm.d) == (h, w, y * ic.d, ic.d)
    assert dm.release_line == min((y + h) * ic.d + 1, 120)


@pytest.mark.parametrize("max_window", [127, 63, 31])
def test_init_capture_fits_the_slot(max_window):
    """Every box the tracker accepts on a 1920 x 1080 frame (sides 3 .. the frame, in steps; at the
    corners and in the middle): the captured rectangle fits the slot."""
    from mstrack.hw.multi_core import MultiCoreParams, slot_shape
    mp = MultiCoreParams(max_window=max_window)
    tp = mp.tracker_params()
    rows, cols = slot_shape(mp)
    fw, fh = mp.max_frame_w, mp.max_frame_h
    sides = sorted({3, 4, 5, 7, 10, 16, 25, 40, 63, 64, 80, 101, 102, 127, 128, 160, 200, 203, 255, 256, 300,
                    400, 510, 640, 800, 1000, 1080, 1500, 1920})
    worst = (0, 0)
    n = 0
    for w in sides:
        for h in sides:
            if w > fw or h > fh:
                continue
            for x, y in ((1, 1), (fw - w - 1, 1), (1, fh - h - 1), (fw - w - 1, fh - h - 1),
                         ((fw - w) // 2, (fh - h) // 2), (0, 0)):
                try:
                    ic = init_capture((max(x, 0), max(y, 0), w, h), fw, fh, tp)
                except ValueError:                      # a box init refuses (less than 3 x 3 inside)
                    continue
                worst = (max(worst[0], ic.rect[3]), max(worst[1], ic.rect[2]))
                assert ic.rect[3] <= rows and ic.rect[2] <= cols, \
                    f"box ({x}, {y}, {w}, {h}): rectangle {ic.rect[2]} x {ic.rect[3]} > slot {cols} x {rows}"
                n += 1
    assert n > 3000 and worst[0] > rows // 2, f"{n} boxes, largest rectangle {worst}: the sweep is too small"
