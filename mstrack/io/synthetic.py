"""Synthetic test scenes with exact ground truth.

:func:`make_scene` renders a textured, coloured target (a red/yellow
checkerboard with noise, so it has both a distinctive colour histogram and
internal edges) moving smoothly over a textured blue-green background.  The
scene is deterministic for a given seed.  :func:`render_scene` draws the same
kind of target at any given box per frame (size changes, jumps) with optional
full occlusion by a background-textured patch.  Boxes follow :mod:`mstrack.track.types`
(0-based ``x, y, w, h``).
"""
from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np

from .data import open_video_writer


def _texture(rng: np.random.Generator, h: int, w: int, cell: int, lo: np.ndarray | np.floating,
             hi: np.ndarray | np.floating) -> np.ndarray:
    """Smooth random colour texture, float32 (h, w, 3), each channel in [lo, hi]."""
    small = rng.random((max(2, h // cell), max(2, w // cell), 3), dtype=np.float32)
    t = cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
    t = np.clip(t, 0.0, 1.0)
    return lo + t * (hi - lo)


def make_scene(n_frames: int = 100, width: int = 320, height: int = 240, seed: int = 0,
               target_size: tuple[int, int] | None = None, noise: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """Render a moving-target scene.

    Parameters
    ----------
    n_frames : int
        Number of frames N (>= 1).
    width, height : int
        Frame size in pixels (at least 32 x 32).
    seed : int
        Random seed; the same arguments give identical output.
    target_size : (w, h), optional
        Target size in pixels; default a square of side
        ``min(64, min(width, height) // 3)``.
    noise : float
        Standard deviation of per-frame sensor noise (grey levels).

    Returns
    -------
    frames : ndarray, shape (N, height, width, 3), uint8
        BGR frames.
    gt : ndarray, shape (N, 4), float64
        Target boxes ``(x, y, w, h)``, 0-based, integer-valued.
    """
    if n_frames < 1 or width < 32 or height < 32:
        raise ValueError("need n_frames >= 1 and a frame of at least 32 x 32")
    rng = np.random.default_rng(seed)
    side = min(64, min(width, height) // 3)
    tw, th = target_size if target_size is not None else (side, side)
    bg = background_texture(rng, width, height)  # blue/green/grey, large blobs + fine grain (BGR)
    tgt = target_texture(rng, tw, th)  # red/yellow checkerboard with texture (BGR)
    # smooth Lissajous trajectory inside the frame (max speed about 3 px/frame)
    mx, my = (width - tw) / 2.0, (height - th) / 2.0
    ax, ay = 0.8 * mx, 0.8 * my
    px, py = rng.uniform(0, 2 * np.pi, 2)
    t = np.arange(n_frames, dtype=np.float64)
    wx = min(3.0 / max(ax, 1.0), 2 * np.pi / 90)
    wy = min(2.5 / max(ay, 1.0), 2 * np.pi / 70)
    xs = np.round(mx + ax * np.sin(wx * t + px)).astype(int)
    ys = np.round(my + ay * np.sin(wy * t + py)).astype(int)
    frames = np.empty((n_frames, height, width, 3), np.uint8)
    for i in range(n_frames):
        f = bg.copy()
        f[ys[i]:ys[i] + th, xs[i]:xs[i] + tw] = tgt
        f += rng.normal(0.0, noise, f.shape).astype(np.float32)
        frames[i] = np.clip(f, 0, 255).astype(np.uint8)
    gt = np.stack([xs, ys, np.full(n_frames, tw), np.full(n_frames, th)], axis=1).astype(np.float64)
    return frames, gt


def target_texture(rng: np.random.Generator, tw: int, th: int) -> np.ndarray:
    """The red/yellow textured checkerboard of :func:`make_scene`, float32 (th, tw, 3) BGR."""
    yy, xx = np.mgrid[0:th, 0:tw]
    cell = max(4, min(tw, th) // 6)
    check = ((yy // cell + xx // cell) % 2).astype(bool)
    tgt = np.empty((th, tw, 3), np.float32)
    tgt[check] = (30, 40, 210)     # red
    tgt[~check] = (40, 200, 230)   # yellow/orange
    tgt += _texture(rng, th, tw, 4, np.float32(-20), np.float32(20))
    return tgt


def background_texture(rng: np.random.Generator, width: int, height: int) -> np.ndarray:
    """The blue/green/grey background of :func:`make_scene`, float32 (height, width, 3) BGR."""
    bg = _texture(rng, height, width, 24, np.array([90, 80, 40], np.float32), np.array([200, 170, 110], np.float32))
    bg += _texture(rng, height, width, 3, np.float32(-25), np.float32(25))
    return bg


def render_scene(boxes: np.ndarray, width: int, height: int, seed: int = 0, noise: float = 4.0,
                 hidden: np.ndarray | None = None) -> np.ndarray:
    """Frames of the :func:`make_scene` target drawn at given boxes (size and place per frame).

    Parameters
    ----------
    boxes : ndarray, shape (N, 4)
        Target box per frame, 0-based ``(x, y, w, h)``, rounded to whole pixels; the target
        texture (made once at the largest size) is resized to each box, so a growing box shows a
        growing target.  Parts outside the frame are cut.
    width, height : int
        Frame size.
    seed : int
        Random seed (background, target texture, noise).
    noise : float
        Standard deviation of per-frame sensor noise (grey levels).
    hidden : ndarray of bool, shape (N,), optional
        Frames where the target is fully occluded by a patch of background texture (a piece of
        the background from elsewhere in the scene, so the patch has background colours only).

    Returns
    -------
    ndarray, shape (N, height, width, 3), uint8 BGR.
    """
    b = np.rint(np.asarray(boxes, dtype=np.float64)).astype(int).reshape(-1, 4)
    n = len(b)
    if n < 1 or width < 32 or height < 32 or (b[:, 2:] < 1).any():
        raise ValueError("need >= 1 box of positive size and a frame of at least 32 x 32")
    rng = np.random.default_rng(seed)
    bg = background_texture(rng, width, height)
    tw, th = int(b[:, 2].max()), int(b[:, 3].max())
    tgt = target_texture(rng, tw, th)
    # the occluder: a background-textured patch (the background rolled by half the frame)
    cover = np.roll(bg, (height // 2, width // 2), axis=(0, 1))
    frames = np.empty((n, height, width, 3), np.uint8)
    for i, (x, y, w, h) in enumerate(b):
        f = bg.copy()
        x0, y0, x1, y1 = max(x, 0), max(y, 0), min(x + w, width), min(y + h, height)
        if x1 > x0 and y1 > y0:
            if hidden is not None and hidden[i]:
                f[y0:y1, x0:x1] = cover[y0:y1, x0:x1]
            else:
                t = tgt if (w, h) == (tw, th) else cv2.resize(tgt, (int(w), int(h)), interpolation=cv2.INTER_AREA)
                f[y0:y1, x0:x1] = t[y0 - y:y1 - y, x0 - x:x1 - x]
        f += rng.normal(0.0, noise, f.shape).astype(np.float32)
        frames[i] = np.clip(f, 0, 255).astype(np.uint8)
    return frames


def write_video(frames: np.ndarray, path: str | Path, fps: float = 25.0) -> Path:
    """Write BGR frames ``(N, H, W, 3)`` uint8 to a video (mp4v, else MJPG avi); returns the path written."""
    n, h, w = frames.shape[:3]
    writer, out = open_video_writer(path, fps, (w, h))
    try:
        for f in frames:
            writer.write(f)
    finally:
        writer.release()
    return out


def write_otb_sequence(frames: np.ndarray, gt: np.ndarray, folder: str | Path,
                       attributes: list[str] | None = None, name: str | None = None) -> Path:
    """Write frames and 0-based boxes as an OTB sequence folder.

    Creates ``img/0001.jpg ...``, ``groundtruth_rect.txt`` (1-based, comma
    separated) and ``meta.json``.  Returns the folder.
    """
    d = Path(folder)
    (d / "img").mkdir(parents=True, exist_ok=True)
    for i, f in enumerate(frames, start=1):
        if not cv2.imwrite(str(d / "img" / f"{i:04d}.jpg"), f, [cv2.IMWRITE_JPEG_QUALITY, 95]):
            raise OSError(f"cannot write {d / 'img' / f'{i:04d}.jpg'}")
    g = np.asarray(gt, dtype=np.float64).copy()
    g[:, :2] += 1
    lines = [",".join(f"{v:g}" for v in row) for row in g]
    (d / "groundtruth_rect.txt").write_text("\n".join(lines) + "\n")
    h, w = frames.shape[1:3]
    meta = {"name": name or d.name, "format": "otb", "gt_coordinate_base": 1,
            "attributes": list(attributes or []), "width": int(w), "height": int(h),
            "frames": int(len(frames)), "source": "mstrack.io.synthetic.make_scene"}
    (d / "meta.json").write_text(json.dumps(meta, indent=1) + "\n")
    return d


#: Colour pairs (BGR) of the checkerboard targets of :func:`make_multi_scene`: red / yellow (the
#: target of :func:`make_scene`), magenta / white, orange / black, purple / pink, then again.
MULTI_COLOURS = (((30, 40, 210), (40, 200, 230)), ((200, 40, 200), (235, 235, 235)),
                 ((20, 120, 240), (25, 25, 25)), ((140, 30, 110), (180, 150, 250)))


def make_multi_scene(n_frames: int = 60, width: int = 320, height: int = 240, n_targets: int = 4, seed: int = 0,
                     spans: list[tuple[int, int]] | None = None, sizes: list[tuple[int, int]] | None = None,
                     noise: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """A scene with several targets (ground truth known), for multi-target tracking.

    Each target is a checkerboard of its own colour pair (:data:`MULTI_COLOURS`) moving on its own
    smooth Lissajous path (at most about 3 px/frame) over the background of :func:`make_scene`;
    targets drawn later (higher id) pass in front of earlier ones where they cross.

    Parameters
    ----------
    n_frames, width, height : int
        Frames and frame size (at least 64 x 64).
    n_targets : int
        Targets, ids 1 .. n_targets.
    seed : int
        Random seed; the same arguments give identical output.
    spans : list of (first, end), optional
        Per target, the frames it is in the scene: ``first <= frame < end`` (default: the whole
        scene for every target); a target appears (enters) and disappears at these frames.
    sizes : list of (w, h), optional
        Per target size in pixels (default: squares of side ``min(40, min(width, height) // 5)``
        minus 4 px per id, so they differ).
    noise : float
        Standard deviation of the per-frame sensor noise.

    Returns
    -------
    frames : ndarray, shape (N, height, width, 3), uint8 BGR
    rows : ndarray, shape (M, 6), float64
        Ground truth ``(frame, id, x, y, w, h)``, frame 0-based, boxes 0-based integer-valued, sorted
        by frame then id (the layout of :attr:`mstrack.io.mot.MotSequence.rows`).
    """
    if n_frames < 1 or width < 64 or height < 64 or n_targets < 1:
        raise ValueError("need n_frames >= 1, n_targets >= 1 and a frame of at least 64 x 64")
    rng = np.random.default_rng(seed)
    bg = background_texture(rng, width, height)
    side = min(40, min(width, height) // 5)
    sizes = sizes or [(max(12, side - 4 * (i % 4)), max(12, side + 8 - 4 * (i % 3))) for i in range(n_targets)]
    spans = spans or [(0, n_frames)] * n_targets
    if len(sizes) != n_targets or len(spans) != n_targets:
        raise ValueError("sizes and spans need one entry per target")
    t = np.arange(n_frames, dtype=np.float64)
    paths, texs = [], []
    for i, (tw, th) in enumerate(sizes):
        tex = target_texture(rng, tw, th)
        c0, c1 = MULTI_COLOURS[i % len(MULTI_COLOURS)]
        yy, xx = np.mgrid[0:th, 0:tw]
        cell = max(4, min(tw, th) // 6)
        check = ((yy // cell + xx // cell) % 2).astype(bool)
        red, yellow = np.array((30, 40, 210), np.float32), np.array((40, 200, 230), np.float32)
        tex = tex - np.where(check[..., None], red, yellow)  # target_texture's colours -> this target's
        tex += np.where(check[..., None], np.array(c0, np.float32), np.array(c1, np.float32))
        texs.append(np.clip(tex, 0, 255))
        mx, my = (width - tw) / 2.0, (height - th) / 2.0
        ax, ay = 0.85 * mx, 0.85 * my
        px, py = rng.uniform(0, 2 * np.pi, 2)
        wx = min(3.0 / max(ax, 1.0), 2 * np.pi / rng.uniform(60, 110))
        wy = min(2.5 / max(ay, 1.0), 2 * np.pi / rng.uniform(50, 90))
        paths.append((np.round(mx + ax * np.sin(wx * t + px)).astype(int),
                      np.round(my + ay * np.sin(wy * t + py)).astype(int)))
    frames = np.empty((n_frames, height, width, 3), np.uint8)
    rows = []
    for k in range(n_frames):
        f = bg.copy()
        for i, ((tw, th), (xs, ys), (first, end)) in enumerate(zip(sizes, paths, spans)):
            if first <= k < end:
                f[ys[k]:ys[k] + th, xs[k]:xs[k] + tw] = texs[i]
                rows.append((k, i + 1, xs[k], ys[k], tw, th))
        f += rng.normal(0.0, noise, f.shape).astype(np.float32)
        frames[k] = np.clip(f, 0, 255).astype(np.uint8)
    return frames, np.asarray(rows, dtype=np.float64).reshape(-1, 6)


def write_mot_sequence(frames: np.ndarray, rows: np.ndarray, folder: str | Path, name: str | None = None,
                       fps: float | None = None) -> Path:
    """Write frames and ground-truth rows ``(frame, id, x, y, w, h)`` (0-based, as
    :func:`make_multi_scene` returns them) as a MOTChallenge-format folder: ``img/000001.jpg ...``,
    ``gt.txt`` (1-based frames and x, y) and ``meta.json``.  Returns the folder."""
    from .mot import write_mot_gt
    d = Path(folder)
    (d / "img").mkdir(parents=True, exist_ok=True)
    for i, f in enumerate(frames, start=1):
        if not cv2.imwrite(str(d / "img" / f"{i:06d}.jpg"), f, [cv2.IMWRITE_JPEG_QUALITY, 95]):
            raise OSError(f"cannot write {d / 'img' / f'{i:06d}.jpg'}")
    write_mot_gt(d / "gt.txt", rows)
    h, w = frames.shape[1:3]
    meta: dict[str, object] = {"name": name or d.name, "format": "mot", "width": int(w), "height": int(h),
                               "frames": int(len(frames)), "targets": int(len(np.unique(np.asarray(rows)[:, 1]))),
                               "source": "mstrack.io.synthetic.make_multi_scene"}
    if fps is not None:
        meta["fps"] = float(fps)
    (d / "meta.json").write_text(json.dumps(meta, indent=1) + "\n")
    return d
