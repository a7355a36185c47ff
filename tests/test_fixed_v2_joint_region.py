"""FixedTrackerV2 with joint colour x orientation bins (orient_T > 0, experimental): the bins of the
captured region only (tracker_v2.joint_bins_region) equal the whole frame's (ms_orient_bin on
ms_grey of the frame, decimated), and so every TrackResult equals the whole-frame tracker's."""
from __future__ import annotations

import numpy as np
import pytest

from mstrack.fixed import tracker_v2 as tv2
from mstrack.fixed.blocks import Region, ms_colour_bin, ms_grey
from mstrack.fixed.blocks_v2 import ms_chroma_bin, ms_joint_bin, ms_orient_bin
from mstrack.fixed.tracker_v2 import FixedTrackerV2, joint_bins_region
from mstrack.track.params import TrackerParams


def _whole_frame(frame, d, bits, T, reg, chroma=0):
    """The definition: the whole frame's joint bins, decimated, then the region (the former path);
    ``chroma`` > 0: the chromaticity bins (TrackerParams.chroma_bins) in place of the RGB bins."""
    img = frame[::d, ::d]
    c = ms_chroma_bin(img, bits, chroma) if chroma else ms_colour_bin(img, bits)
    full = ms_joint_bin(c, ms_orient_bin(ms_grey(frame), T)[::d, ::d])
    return full[reg.y: reg.y + reg.h, reg.x: reg.x + reg.w]


@pytest.mark.parametrize("shape", [(37, 53), (64, 96), (3, 9), (2, 5), (41, 3)])
def test_joint_bins_region_equals_whole_frame(shape):
    rng = np.random.default_rng(sum(shape))
    frame = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    frame[shape[0] // 3:, : shape[1] // 2] //= 4  # an edge, flat areas
    for d in (1, 2, 4, 8):
        hd, wd = (shape[0] + d - 1) // d, (shape[1] + d - 1) // d
        for T in (1, 32, 64, 400):
            regs = [(0, 0, wd, hd), (0, 0, 1, 1), (wd - 1, hd - 1, 1, 1)]
            for _ in range(12):
                x, y = int(rng.integers(0, wd)), int(rng.integers(0, hd))
                regs.append((x, y, int(rng.integers(1, wd - x + 1)), int(rng.integers(1, hd - y + 1))))
            for x, y, w, h in regs:
                reg = Region(x, y, w, h, (0, 0), (0, 0))
                for k in (0, 2):
                    got = joint_bins_region(frame, d, 3, T, reg, k)
                    assert np.array_equal(got, _whole_frame(frame, d, 3, T, reg, k)), (d, T, x, y, w, h, k)


def _scenes():
    """Synthetic scenes: (name, frames, box).  A textured target moving on a textured background,
    near / onto the frame border, occluded (lost: the wide search at 2D), and large (D = 2, 4)."""
    out = []
    rng = np.random.default_rng(7)
    for name, size, n, path, occl in (("border", 24, 24, lambda i: (3 + 2 * i, 1 + (i % 5)), ()),
                                      ("corner", 20, 16, lambda i: (110 + 3 * i, 80 + 2 * i), ()),
                                      ("lost", 22, 24, lambda i: (40 + 3 * i, 40 + i), range(8, 14)),
                                      ("d2", 90, 14, lambda i: (30 + 3 * i, 20 + i), ()),
                                      ("d4", 190, 12, lambda i: (20 + 4 * i, 10 + 2 * i), range(6, 9))):
        fw, fh = (160, 120) if size < 60 else (400, 300)
        frames = []
        tex = rng.integers(0, 40, (size, size, 3)).astype(np.uint8)
        tex[:, : size // 2] += np.array([20, 30, 200], np.uint8)
        tex[:, size // 2:] += np.array([200, 40, 30], np.uint8)
        for i in range(n):
            f = rng.integers(60, 160, (fh, fw, 3)).astype(np.uint8)
            f[:, fw // 2:, 1] //= 3
            if i not in occl:
                x, y = path(i)
                x0, y0 = max(x, 0), max(y, 0)
                x1, y1 = min(x + size, fw), min(y + size, fh)
                if x1 > x0 and y1 > y0:
                    f[y0:y1, x0:x1] = tex[y0 - y: y1 - y, x0 - x: x1 - x]
            frames.append(f)
        x, y = path(0)
        out.append((name, frames, (max(x, 0), max(y, 0), min(size, fw - max(x, 0)), min(size, fh - max(y, 0)))))
    return out


@pytest.mark.parametrize("T", [64, 16])
def test_fixed_v2_joint_region_path_equals_whole_frame(T, monkeypatch):
    kw = dict(preset="v2", orient_T=T, scale_test=0.05, scale_test_gate=True)
    seen_d, seen_lost = set(), False
    for name, frames, box in _scenes():
        runs = []
        for ref in (False, True):
            if ref:
                monkeypatch.setattr(tv2, "joint_bins_region", _whole_frame)
            t = FixedTrackerV2(TrackerParams(**kw))
            runs.append([t.init(frames[0], box)] + [t.update(f) for f in frames[1:]])
            monkeypatch.undo()
        for i, (a, b) in enumerate(zip(*runs)):
            assert a == b, (name, i)
        seen_d |= {r.extra["decimation"] for r in runs[0]}
        seen_lost |= any(r.extra.get("searched", 0) > 0 for r in runs[0])
    assert {1, 2, 4} <= seen_d and seen_lost
