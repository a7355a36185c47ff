"""The command line as a vision engineer meets it: one test per usability point."""
import csv
import io
import json
import re

import numpy as np
import pytest

from mstrack import cli
from mstrack.io.synthetic import make_scene, write_otb_sequence, write_video
from mstrack.track.types import Box


@pytest.fixture(scope="module")
def tiny_video(tmp_path_factory):
    frames, gt = make_scene(12, 160, 120, seed=2)
    return write_video(frames, tmp_path_factory.mktemp("vid") / "tiny.avi", fps=10), gt


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    for name, seed in (("Crossing", 1), ("Girl", 2)):
        frames, gt = make_scene(8, 160, 120, seed=seed)
        write_otb_sequence(frames, gt, root / name)
    return root


def _help(capsys, *argv):
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args([*argv, "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_track_help_lists_tracker_names_and_explains_model(capsys):
    from mstrack.eval.evaluate import tracker_names
    text = _help(capsys, "track")
    for name in tracker_names():
        assert name in text.replace("- ", "-"), name   # argparse may wrap at a hyphen
    assert f"default {cli.DEFAULT_TRACKER}" in text
    assert re.search(r"--model \{float,fixed\} mstrack model: float .* fixed .*hardware", text)
    assert "mstrack model" in _help(capsys, "eval") and "mstrack model" in _help(capsys, "demo")


def test_unknown_tracker_lists_the_known_ones(tiny_video, tmp_path, capsys):
    assert cli.main(["track", str(tiny_video[0]), "--box", "1,1,9,9", "--tracker", "csrt", "--out",
                     str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert "unknown tracker 'csrt'" in err and "opencv-csrt" in err and "mstrack-v2" in err


def test_box_with_a_negative_value_needs_no_equals_sign(tiny_video, tmp_path, capsys):
    out = tmp_path / "o"
    assert cli.main(["track", str(tiny_video[0]), "--box", "-5,10,20,20", "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    # the box is clipped to the frame, and the command line says so and to what
    assert "init box (-5, 10, 20, 20) clipped to the 160x120 frame: tracking (0, 10, 15, 20)" in err
    assert cli.join_number_lists(["track", "v", "--box", "-5,10,20,20", "--max-frames", "3"]) == \
        ["track", "v", "--box=-5,10,20,20", "--max-frames", "3"]
    assert cli.join_number_lists(["--box", "--quiet"]) == ["--box", "--quiet"]     # not a box: left to argparse


def test_track_warns_when_the_fixed_model_shrinks_the_box(tmp_path, capsys):
    frames, _ = make_scene(3, 320, 240, seed=4)
    src = write_video(frames, tmp_path / "big.avi", fps=10)
    assert cli.main(["track", str(src), "--box", "10,10,300,200", "--model", "fixed", "--preset", "paper",
                     "--out", str(tmp_path / "o"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "mstrack: warning: init box (10, 10, 300, 200) shrunk to the largest window the model tracks: " \
           "tracking (96, 46, 127, 127) (x, y, w, h)" in err
    rows = list(csv.DictReader(open(tmp_path / "o" / "results.csv")))
    assert [float(rows[0][k]) for k in "xywh"] == [96, 46, 127, 127]
    assert cli.main(["track", str(src), "--box", "-20,10,400,200", "--model", "fixed", "--preset", "paper",
                     "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert "init box (-20, 10, 400, 200) clipped to the 320x240 frame and shrunk to the largest window the " \
           "model tracks: tracking (" in capsys.readouterr().err
    # a box inside the frame and within the window: no warning
    assert cli.main(["track", str(src), "--box", "10,10,40,30", "--out", str(tmp_path / "p"), "--quiet"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_eval_sequences_case_insensitive_and_lists_valid_names(dataset, tmp_path, capsys):
    out = tmp_path / "e"
    assert cli.main(["eval", str(dataset), "--sequences", "crossing", "--trackers", "opencv-camshift",
                     "--out", str(out), "--quiet"]) == 0
    assert list(json.loads((out / "report.json").read_text())["sequences"]) == ["Crossing"]
    assert cli.main(["eval", str(dataset), "--sequences", "crosing", "--trackers", "opencv-camshift",
                     "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "no sequence named crosing; the sequences are: Crossing, Girl" in err


def test_vectors_out_must_be_gzip(dataset, tmp_path, capsys):
    out = tmp_path / "x.json"
    assert cli.main(["vectors", str(dataset / "Girl"), "--frames", "0,1", "--out", str(out)]) == 1
    assert "name the --out file *.jsonl.gz, not 'x.json'" in capsys.readouterr().err
    assert not out.exists()


def test_csv_has_no_float_noise(tmp_path):
    class Noisy:                       # a tracker whose boxes carry float noise (145.96000000000004)
        def init(self, frame, box):
            return Box(145.96000000000004, 0.1 + 0.2, 30.000000000000004, 40.0)

        def update(self, frame):
            return Box(145.96000000000004, 0.1 + 0.2, 30.000000000000004, 40.0)

    frames, _ = make_scene(3, 200, 120, seed=1)
    cli.track_frames(Noisy(), frames, Box(1, 2, 30, 40), tmp_path)
    text = (tmp_path / "results.csv").read_text()
    assert "145.96," in text and "0.3," in text and "30.0," in text and "0000000" not in text
    data = json.loads((tmp_path / "results.json").read_text())["frames_data"]
    assert data[1]["x"] == 145.96 and data[1]["y"] == 0.3


def test_compile_notice_printed_once_before_a_numba_compile():
    numba = pytest.importorskip("numba")
    buf = io.StringIO()
    assert cli.install_compile_notice(buf)

    @numba.njit(cache=False)
    def add(a, b):
        return a + b

    assert buf.getvalue() == ""                # nothing before anything compiles
    add(1, 2)
    add(1.5, 2.5)                              # a second compilation: no second line
    assert buf.getvalue() == cli.COMPILE_NOTICE + "\n"


def test_progress_bar_has_total_and_eta(tiny_video, tmp_path, capsys):
    from mstrack.io.data import VideoSource
    src = VideoSource(tiny_video[0])
    cli.track_frames(cli_tracker(), src.frames(), Box.of(tiny_video[1][0]), tmp_path, progress=True, source=src)
    err = capsys.readouterr().err
    assert "12/12" in err and re.search(r"<\d\d:\d\d", err)          # total and time left
    cli.track_frames(cli_tracker(), make_scene(5, 160, 120, seed=2)[0], Box(60, 40, 30, 30), tmp_path / "b",
                     progress=True, max_frames=4)
    assert "4/4" in capsys.readouterr().err


def cli_tracker():
    from mstrack.eval.evaluate import make_tracker
    return make_tracker("opencv-camshift")


def test_overlay_small_frame_explains_the_numbers():
    frame = np.random.default_rng(0).integers(60, 200, (96, 128, 3), dtype=np.uint8)
    row = {"frame": 7, "x": 40.0, "y": 30.0, "w": 30.0, "h": 40.0, "cx": 54.5, "cy": 49.5, "rho_c": 0.9,
           "rho_e": 0.8, "alpha_c": 0.53, "confidence": float("nan"), "status": "ok"}
    banner = " ".join(cli.overlay_lines(row, 384, 0.4))
    assert cli.overlay_note(banner) == "rho_c/rho_e: colour/edge match to the target 0-1, a_c: weight of colour"
    v2 = dict(row, rho_e=0.0, alpha_c=1.0, confidence=0.8)
    assert cli.overlay_note(" ".join(cli.overlay_lines(v2, 384, 0.4))) == \
        "conf: confidence 0-1, rho_c: colour match to the target 0-1"
    for line in cli._wrap(cli.overlay_note(banner), 384, 0.4):
        import cv2
        assert cv2.getTextSize(line, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)[0][0] <= 384 - 8
    img = cli.draw_overlay(frame, row, np.array([40.0, 30.0, 30.0, 40.0]))
    assert img.shape == (288, 384, 3)
