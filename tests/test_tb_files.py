"""mstrack.hw.tb_files: the files of the standalone VHDL testbench (format version 1), and
``mstrack vectors --format vhdl-files``.  The testbench itself runs in tb/test_ms_tracker_file_tb.py."""
from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack.cli import main
from mstrack.hw.cosim import CoreConfig, expected_results
from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import unpack_result
from mstrack.track.params import TrackerParams
from mstrack.io.synthetic import make_scene
from mstrack.hw.tb_files import (expected_words, frames_text, pack_pixels, read_words, result_word,
                              write_tb_files)

CFG = CoreConfig(TrackerParams(), FixedParams(max_half=15, margin=8), lanes=4, max_frame_w=1024)


def _frames(n=3):
    frames, _ = make_scene(n, 40, 32, seed=2)
    return [np.ascontiguousarray(f) for f in frames]


def test_pack_pixels_layouts():
    px = np.array([[[0x33, 0x22, 0x11]]], dtype=np.uint8)       # BGR: B 0x33, G 0x22, R 0x11
    assert pack_pixels(px, 0)[0, 0] == 0x112233                 # R, G, B
    assert pack_pixels(px, 1)[0, 0] == 0x113322                 # UG934: R, B, G
    with pytest.raises(ValueError):
        pack_pixels(px, 2)


def test_result_word_round_trip():
    g = CFG.generics()
    for fields in expected_results(_frames(), (14, 10, 10, 9), CFG.tp, CFG.fp):
        got = unpack_result(result_word(fields, g), g)
        assert {k: got[k] for k in fields} == fields
    with pytest.raises(ValueError, match="does not fit"):
        result_word({"iter_c": 1 << 10}, g)


def parse_frames(text: str) -> tuple[dict, list[np.ndarray]]:
    """A reader of the format, as the VHDL testbench reads it (records, '#' lines skipped)."""
    recs = [ln.split("#", 1)[0].split() for ln in text.splitlines()]
    recs = [r for r in recs if r]
    assert recs[0] == ["mstrack-frames", "1"]
    head, frames, i = {}, [], 1
    while i < len(recs):
        r = recs[i]
        if r[0] == "frame":
            w, h = head["size"]
            frames.append(np.array([[int(v, 16) for v in recs[i + 1 + y]] for y in range(h)]))
            assert all(len(recs[i + 1 + y]) == w for y in range(h))
            i += 1 + h
            continue
        if r[0] != "end":
            head[r[0]] = [int(v) for v in r[1:]]
        i += 1
    return head, frames


@pytest.mark.parametrize("packing", [0, 1])
def test_frames_text_format(packing):
    frames = _frames()
    head, words = parse_frames(frames_text(frames, (14, 10, 10, 9), packing, ["a comment"]))
    assert head == {"packing": [packing], "size": [40, 32], "init": [14, 10, 10, 9]}
    assert len(words) == 3 and all((w == pack_pixels(f, packing)).all() for w, f in zip(words, frames))


def test_write_tb_files(tmp_path):
    frames = _frames()
    paths = write_tb_files(tmp_path, frames, (14, 10, 10, 9), CFG, packing=1)
    assert read_words(paths["expected"]) == expected_words(frames, (14, 10, 10, 9), CFG)
    g = json.loads(paths["generics"].read_text())
    assert g == {**CFG.generics(), "RGB_PACKING": 1}
    lines = [ln for ln in paths["expected"].read_text().splitlines() if not ln.startswith("#")]
    assert all(len(ln) == g["RESULT_W"] // 4 for ln in lines)
    with pytest.raises(ValueError, match="one size per file"):
        write_tb_files(tmp_path, [frames[0], frames[1][:, :20]], (14, 10, 10, 9), CFG)


def test_cli_vectors_vhdl_files(tmp_path):
    """`mstrack vectors IMAGE_FOLDER --format vhdl-files --box ...` writes the three files."""
    frames = _frames(4)
    img = tmp_path / "img"
    img.mkdir()
    for i, f in enumerate(frames):
        cv2.imwrite(str(img / f"{i:04d}.png"), f)
    out = tmp_path / "tb"
    assert main(["vectors", str(img), "--format", "vhdl-files", "--frames", "0,2", "--box", "14,10,10,9",
                 "--out", str(out), "--param", "max_half=15", "--param", "margin=8",
                 "--max-frame-width", "1024", "--rgb-packing", "ug934"]) == 0
    assert read_words(out / "expected.txt") == expected_words(frames[:3], (14, 10, 10, 9), CFG)
    head, words = parse_frames((out / "frames.txt").read_text())
    assert head["packing"] == [1] and len(words) == 3
    assert json.loads((out / "generics.json").read_text())["MAX_HALF"] == 15


def test_cli_vectors_vhdl_files_needs_a_box(tmp_path):
    img = tmp_path / "img"
    img.mkdir()
    cv2.imwrite(str(img / "0000.png"), _frames(1)[0])
    assert main(["vectors", str(img), "--format", "vhdl-files", "--out", str(tmp_path / "o")]) == 1
