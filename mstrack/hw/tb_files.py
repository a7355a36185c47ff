"""Input and expected-output files of the standalone VHDL testbench (tb/vhdl/ms_tracker_file_tb.vhd).

The testbench needs no Python at simulation time: it reads the video and the init box from a
text file and writes one result word per frame.  This module writes those files
(``frames.txt``, ``expected.txt``, ``generics.json``) from frames in memory, with the expected
result words computed by the fixed-point model, and reads result files back::

    from mstrack.hw.tb_files import write_tb_files
    write_tb_files("out/tb", frames, (x, y, w, h), cfg)        # cfg: mstrack.hw.cosim.CoreConfig

or from the command line (frames 0 .. last of a sequence, init on frame 0 with its ground truth,
or any video / image folder with ``--box``)::

    mstrack vectors SEQ_DIR --format vhdl-files --frames 0,9 --out out/tb [--box x,y,w,h]

Formats (version 1; docs/packaging.md, "Simulating without Python"): see the header of
tb/vhdl/ms_tracker_file_tb.vhd.  Pixel words are 6 hexadecimal digits in the bus layout of
``RGB_PACKING`` (:func:`pack_pixels`); result words RESULT_W / 4 hexadecimal digits, MSB first.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Sequence

import numpy as np

from .cosim import CoreConfig, expected_results, frame_words
from ..fixed.vhdl_pkg import result_layout

MAGIC = "mstrack-frames"
VERSION = 1
FRAMES_TXT, EXPECTED_TXT, GENERICS_JSON = "frames.txt", "expected.txt", "generics.json"


def pack_pixels(frame: np.ndarray, packing: int = 0) -> np.ndarray:
    """(H, W) int64 bus words of a BGR uint8 frame.

    packing 0: R 23:16, G 15:8, B 7:0 (mstrack); 1: R 23:16, B 15:8, G 7:0 (AMD UG934, RGB).
    """
    if packing == 0:
        return frame_words(frame)
    if packing == 1:
        f = frame.astype(np.int64)
        return (f[..., 2] << 16) | (f[..., 0] << 8) | f[..., 1]
    raise ValueError(f"RGB packing {packing} unknown (0 mstrack, 1 UG934)")


def result_word(fields: dict[str, int], g: dict[str, int]) -> int:
    """The result word of ``fields`` (layout :func:`mstrack.fixed.vhdl_pkg.result_layout`).

    Raises ValueError when a field does not fit its width."""
    word = 0
    for name, off, w in result_layout(g):
        v = int(fields.get(name, 0))
        if not 0 <= v < 1 << w:
            raise ValueError(f"result field {name} = {v} does not fit in {w} bits")
        word |= v << off
    return word


def frames_text(frames: Sequence[np.ndarray], box: tuple[int, int, int, int], packing: int = 0,
                comment: Iterable[str] = ()) -> str:
    """The FRAMES_FILE text: header, size, init box before frame 0, then the frames."""
    h, w = frames[0].shape[:2]
    out = [f"# {c}" for c in comment]
    out += [f"{MAGIC} {VERSION}", f"packing {packing}", f"size {w} {h}",
            "init " + " ".join(str(int(v)) for v in box)]
    for i, fr in enumerate(frames):
        if fr.shape[:2] != (h, w):
            raise ValueError(f"frame {i} is {fr.shape[1]}x{fr.shape[0]}, frame 0 {w}x{h}: one size per file")
        out.append(f"frame  # {i}")
        words = pack_pixels(fr, packing)
        out += [" ".join(f"{int(v):06x}" for v in row) for row in words]
    out.append("end")
    return "\n".join(out) + "\n"


def word_lines(words: Iterable[int], result_w: int) -> str:
    digits = result_w // 4
    return "".join(f"{w:0{digits}x}\n" for w in words)


def expected_words(frames: Sequence[np.ndarray], box: tuple[int, int, int, int], cfg: CoreConfig) -> list[int]:
    """Result words the core gives for ``frames`` with ``box`` taken before frame 0 (fixed model)."""
    g = cfg.generics()
    return [result_word(r, g) for r in expected_results(frames, box, cfg.tp, cfg.fp)]


def write_tb_files(out_dir: str | Path, frames: Sequence[np.ndarray], box: tuple[int, int, int, int],
                   cfg: CoreConfig, packing: int = 0, source: str = "") -> dict[str, Path]:
    """Write frames.txt, expected.txt and generics.json (the generics to give the testbench) to ``out_dir``.

    Parameters
    ----------
    frames : sequence of (H, W, 3) uint8 BGR arrays, one size
    box : integer (x, y, w, h) init box, given to the core before frame 0
    cfg : CoreConfig (model parameters, LANES, MAX_FRAME_W) the expected words are made for
    packing : RGB_PACKING of the pixel words (the testbench's RGB_PACKING must match)
    source : text recorded in the file comments (where the frames come from)
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    g = {**cfg.generics(), "RGB_PACKING": packing}
    h, w = frames[0].shape[:2]
    if w > g["MAX_FRAME_W"]:
        raise ValueError(f"frames are {w} px wide, MAX_FRAME_W = {g['MAX_FRAME_W']}")
    note = [f"mstrack vhdl-files: {len(frames)} frames {w}x{h}" + (f" of {source}" if source else ""),
            f"init box {tuple(int(v) for v in box)}; expected words by the fixed-point model (mstrack.hw.cosim)",
            f"testbench generics: {GENERICS_JSON}"]
    paths = {"frames": out / FRAMES_TXT, "expected": out / EXPECTED_TXT, "generics": out / GENERICS_JSON}
    paths["frames"].write_text(frames_text(frames, box, packing, note))
    paths["expected"].write_text("# " + note[0] + "\n" + word_lines(expected_words(frames, box, cfg), g["RESULT_W"]))
    paths["generics"].write_text(json.dumps(g, indent=1) + "\n")
    return paths


def read_words(path: str | Path) -> list[int]:
    """Result words of a RESULTS_FILE / EXPECTED_FILE ('#' lines ignored)."""
    out = []
    for line in Path(path).read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            out.append(int(line, 16))
    return out
