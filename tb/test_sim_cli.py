"""``mstrack sim`` (mstrack/simcli.py): the RTL core co-simulated on a user's video, end to end.

The simulations use :mod:`mstrack.hw.fastsim` (GHDL netlist + Verilator + C++ harness, marker
``verilator``: skipped without the tools unless MSTRACK_REQUIRE_TOOLS=1).  One Verilator build
(default generics, LANES 4, about 30-90 s the first time) is cached in build/fastsim/ and shared by
every test here; then each simulation takes about a second.

* ``test_sim_synthetic_video``: a generated scene (:func:`mstrack.io.synthetic.make_scene`, known
  ground truth) written as an .avi, through ``python -m mstrack.cli sim``: exit 0, one CSV row per
  frame, report bit-exact, every CSV row equal to the fixed-point model's result decoded the same
  way (raw word included), the box on the target, an overlay video of as many frames.
* ``test_sim_image_folder_negative_box``: the same scene as an image folder, ``--box=-…`` (clipped,
  with a warning) and ``--frames``: the frame column counts from FIRST.
* ``test_sim_real_sequence``: Girl frames 0..19 of ../shared with its ground truth as the box
  (skipped when absent).
* ``test_sim_detects_mismatch``: the model side is corrupted in one field of one frame: exit 1,
  and both the printed line and bitexact.json name that frame and field.
* ``test_sim_bad_input``: missing file, box outside the frame, frame too wide for MAX_FRAME_W,
  an unknown preset, frames beyond the end, no box: one-line error, exit 2 (no HDL tools needed).
* ``test_sim_preset_v2_decoding``: ``--preset v2`` without a simulator (fastsim.simulate replaced by
  the model's words): core v2 is asked for as ms_tracker with PRESET 1, results.csv has the v2
  columns decoded from result word v2, bitexact.json compares the v2 fields.
* ``test_sim_preset_v2_real``: ``--preset v2`` on 12 Girl frames through the verilated ms_tracker
  with PRESET 1 (marker ``long``: the Verilator build of core v2 at MAX_FRAME_W 1920 is the one the
  long core v2 runs use, so it is built once, on the second core of `make test`).
"""
from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack import cli
from mstrack.hw.cosim import COMPARED_FIELDS, CoreConfig, expected_results
from mstrack.io.data import VideoSource
from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.fixed.vhdl_pkg import DEFAULT_LANES, pack_result
from mstrack.track.params import TrackerParams
from mstrack.simcli import SIM_CSV_FIELDS, SIM_CSV_FIELDS_V2, bitexact_report, decode_row, decode_row_v2, report_line
from mstrack.io.synthetic import make_scene, write_video

REPO = Path(__file__).resolve().parents[1]
SEQ_ROOT = REPO.parent / "shared" / "data" / "sequences"
N_FRAMES = 16
W, H = 160, 120


@pytest.fixture(scope="module")
def scene() -> tuple[np.ndarray, np.ndarray]:
    return make_scene(N_FRAMES, W, H, seed=3)


@pytest.fixture(scope="module")
def video(scene, tmp_path_factory) -> Path:
    return write_video(scene[0], tmp_path_factory.mktemp("simcli") / "scene.avi")


def _rows(out: Path) -> list[dict[str, str]]:
    with open(out / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _model_rows(frames: list[np.ndarray], box: tuple[int, int, int, int], first: int = 0) -> list[dict[str, str]]:
    """The model's results, decoded as results.csv writes them (strings, as csv reads them back)."""
    g = CoreConfig(TrackerParams(), FixedParams(), lanes=DEFAULT_LANES).generics()
    exp = expected_results(frames, box, TrackerParams(), FixedParams())
    return [{k: str(v) for k, v in decode_row(r, g, first + i).items()} for i, r in enumerate(exp)]


def _frames_of(path: Path, first: int = 0, n: int | None = None) -> list[np.ndarray]:
    fr = [f for f in VideoSource(path).frames()]
    return fr[first:None if n is None else first + n]


def _count_video_frames(path: str) -> int:
    cap = cv2.VideoCapture(path)
    n = 0
    while cap.read()[0]:
        n += 1
    cap.release()
    return n


def _assert_equal_to_model(rows: list[dict[str, str]], want: list[dict[str, str]]) -> None:
    assert len(rows) == len(want)
    for got, exp in zip(rows, want):
        diff = {k: (got[k], exp[k]) for k in SIM_CSV_FIELDS if k != "latency" and got[k] != exp[k]}
        assert not diff, f"frame {got['frame']}: csv vs model {diff}"
        assert int(got["latency"]) > 0


@pytest.mark.verilator
def test_sim_synthetic_video(scene, video, tmp_path):
    frames, gt = scene
    box = round_box(*gt[0])
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "mstrack.cli", "sim", str(video), "--box", ",".join(map(str, box)),
                        "--out", str(out), "--quiet"], capture_output=True, text=True, cwd=REPO,
                       env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "bit-exact" in r.stdout
    rows = _rows(out)
    assert [int(x["frame"]) for x in rows] == list(range(N_FRAMES))
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] is True and rep["frames"] == N_FRAMES and rep["mismatches"] == 0
    assert rep["fields"] == list(COMPARED_FIELDS) and rep["simulation"]["status"] == "done"
    decoded = _frames_of(video)                      # the frames as the reader gives them (lossy codec)
    want = _model_rows(decoded, box)
    _assert_equal_to_model(rows, want)
    g = CoreConfig(TrackerParams(), FixedParams(), lanes=DEFAULT_LANES).generics()
    words = [pack_result(e, g) for e in expected_results(decoded, box, TrackerParams(), FixedParams())]
    assert [int(x["word"], 16) for x in rows] == words
    assert rows[0]["status"] == "init" and all(x["status"] in ("ok", "lost") for x in rows[1:])
    # the core follows the generated target (centre within 10 px of the ground truth)
    c = np.array([[float(x["cx"]) + 0.5, float(x["cy"]) + 0.5] for x in rows])
    err = np.hypot(*(c - (gt[:, :2] + gt[:, 2:] / 2)).T)
    assert err.max() < 10, err
    assert _count_video_frames(rep["files"]["video"]) == N_FRAMES


@pytest.mark.verilator
def test_sim_image_folder_negative_box(scene, tmp_path, capsys):
    frames, gt = scene
    folder = tmp_path / "imgs"
    folder.mkdir()
    for i, f in enumerate(frames):
        cv2.imwrite(str(folder / f"{i:03d}.png"), f)        # lossless: the frames are the scene's
    first, last = 2, 9
    out = tmp_path / "out"
    rc = cli.main(["sim", str(folder), "--box", "-6,30,40,40", "--frames", f"{first},{last}", "--out", str(out),
                   "--quiet"])
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    assert "clipped" in cap.err and "warning" in cap.err
    rows = _rows(out)
    assert [int(x["frame"]) for x in rows] == list(range(first, last + 1))
    assert rows[0]["status"] == "clipped"
    _assert_equal_to_model(rows, _model_rows(list(frames[first:last + 1]), (-6, 30, 40, 40), first))


@pytest.mark.verilator
def test_sim_real_sequence(tmp_path, capsys):
    seq = SEQ_ROOT / "Girl"
    if not seq.is_dir():
        pytest.skip(f"real sequence {seq} not found (../shared/data/sequences absent)")
    out = tmp_path / "girl"
    rc = cli.main(["sim", str(seq), "--max-frames", "20", "--out", str(out), "--quiet"])
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    rows = _rows(out)
    assert len(rows) == 20
    src = VideoSource(seq)
    assert src.sequence is not None
    box = round_box(*src.sequence.gt[0])
    _assert_equal_to_model(rows, _model_rows(_frames_of(seq, 0, 20), box))
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] and rep["init_box"] == list(box)


@pytest.mark.verilator
def test_sim_detects_mismatch(video, tmp_path, monkeypatch, capsys):
    import mstrack.hw.cosim

    real = mstrack.hw.cosim.expected_results
    bad_frame, bad_field = 5, "rho_c"

    def corrupted(*a, **kw):
        exp = real(*a, **kw)
        exp[bad_frame][bad_field] ^= 1                       # one bit of one field of one frame
        return exp

    monkeypatch.setattr(mstrack.hw.cosim, "expected_results", corrupted)
    out = tmp_path / "out"
    rc = cli.main(["sim", str(video), "--box", "50,40,30,30", "--max-frames", "8", "--out", str(out), "--quiet"])
    cap = capsys.readouterr()
    assert rc == 1
    assert "MISMATCH" in cap.out and f"frame {bad_frame}" in cap.out and f"field {bad_field}" in cap.out
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] is False and rep["mismatched_frames"] == 1 and rep["mismatches"] == 1
    m = rep["first_mismatch"]
    assert (m["frame"], m["field"]) == (bad_frame, bad_field) and m["core"] == m["model"] ^ 1
    assert len(_rows(out)) == 8                               # the results are still written


def test_report_missing_and_extra_results():
    """A missing or extra result word is a mismatch too (no simulator needed)."""
    exp = [{k: i for k in COMPARED_FIELDS} for i in range(3)]
    rep = bitexact_report(exp[:2], exp, [10, 11, 12])
    assert not rep["bit_exact"] and rep["first_mismatch"]["frame"] == 12
    assert "frame 12" in report_line(rep) and "(no result)" in report_line(rep)
    rep = bitexact_report(exp + [exp[0]], exp, [10, 11, 12])
    assert rep["first_mismatch"]["field"] == "(extra result)" and rep["first_mismatch"]["frame"] == 13
    assert bitexact_report(exp, [dict(e) for e in exp], [0, 1, 2])["bit_exact"]


@pytest.mark.parametrize("argv, says", [
    (["{missing}", "--box", "1,1,10,10"], "source not found"),
    (["{video}", "--box", "500,400,30,30"], "less than 3x3 px"),
    (["{video}", "--box=-100,10,20,20"], "less than 3x3 px"),
    (["{video}", "--box", "10,10,30,30", "--max-frame-width", "100"], "MAX_FRAME_W"),
    (["{video}", "--box", "10,10,30,30", "--preset", "v3"], "implements the presets paper, v2"),
    (["{video}", "--box", "10,10,30,30", "--frames", f"{N_FRAMES - 2},{N_FRAMES + 5}"], "the source ends"),
    (["{video}", "--box", "10,10,30,30", "--frames", f"{N_FRAMES + 3},{N_FRAMES + 5}"], f"no frame {N_FRAMES + 3}"),
    (["{video}", "--box", "10,10,30,30", "--lanes", "3"], "power of two"),
    (["{video}"], "--box x,y,w,h is required"),
    (["{video}", "--box", "10,10,30,30", "--box", "40,10,20,20", "--preset", "paper"], "leave out --preset paper"),
    (["{video}", "--box", "10,10,30,30", "--box", "40,10,20,20", "--slots", "1"], "at least one per box"),
    (["{video}", "--box", "10,10,30,30", "--box", "500,400,30,30"], "less than 3x3 px"),
    (["{video}", "--box", "10,10,30,30", "--colour"], "needs --preset v2"),
])
def test_sim_bad_input(video, tmp_path, capsys, argv, says):
    argv = [a.format(video=video, missing=tmp_path / "missing.avi") for a in argv]
    out = tmp_path / "out"
    rc = cli.main(["sim", *argv, "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mstrack sim: error: ") and says in lines[0], err
    assert not (out / "results.csv").exists()


def _v2_model_rows(frames: list[np.ndarray], box: tuple[int, int, int, int], first: int = 0) -> list[dict[str, str]]:
    """Core v2's expected results, decoded as results.csv writes them (strings)."""
    from mstrack.hw.cosim import CoreConfigV2, expected_results_v2
    g = CoreConfigV2(TrackerParams(preset="v2"), FixedParams(), lanes=DEFAULT_LANES).tracker_generics()
    exp = expected_results_v2(frames, box)
    return [{k: str(v) for k, v in decode_row_v2(r, g, first + i).items()} for i, r in enumerate(exp)]


def test_sim_preset_v2_decoding(scene, tmp_path, monkeypatch, capsys):
    """--preset v2 without a simulator: fastsim.simulate is replaced by the model's result words v2
    (unpacked as the harness output is); the CLI must ask for core v2 through ms_tracker (PRESET 1) and
    write the v2 columns, every one equal to the model's decoded row."""
    from mstrack.fixed.vhdl_pkg import pack_result_v2, unpack_result_v2
    from mstrack.hw import fastsim
    from mstrack.hw.cosim import COMPARED_FIELDS_V2, expected_results_v2

    frames, gt = scene
    folder = tmp_path / "imgs"
    folder.mkdir()
    n = 5
    for i, f in enumerate(frames[:n]):
        cv2.imwrite(str(folder / f"{i:03d}.png"), f)
    box = round_box(*gt[0])
    calls = []

    def fake_simulate(frames_it, box_, tp, fp, lanes, **kw):
        calls.append({"tp": tp, "lanes": lanes, **kw})
        fr = list(frames_it)
        res = []
        for i, e in enumerate(expected_results_v2(fr, box_, tp, fp)):
            word = pack_result_v2(e)
            r = unpack_result_v2(word)
            r.update(word=word, latency=1000 + i)
            res.append(r)
        return fastsim.FastsimRun(results=res, frames=[], cycles=1, seconds=0.0, cpu_seconds=0.0, status="done",
                                  detail="", build_seconds=0.0, workdir=None, config={})

    monkeypatch.setattr(fastsim, "simulate", fake_simulate)
    out = tmp_path / "out"
    rc = cli.main(["sim", str(folder), "--preset", "v2", "--box", ",".join(map(str, box)), "--out", str(out),
                   "--quiet"])
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    (call,) = calls
    assert call["v2"] is True and call["top"] == "ms_tracker" and call["tp"].preset == "v2"
    with open(out / "results.csv", newline="") as fh:
        assert tuple(csv.DictReader(fh).fieldnames or ()) == SIM_CSV_FIELDS_V2
    rows = _rows(out)
    want = _v2_model_rows(list(frames[:n]), box)
    for got, exp in zip(rows, want, strict=True):
        diff = {k: (got[k], exp[k]) for k in SIM_CSV_FIELDS_V2 if k != "latency" and got[k] != exp[k]}
        assert not diff, f"frame {got['frame']}: {diff}"
    assert rows[0]["status"] == "init" and float(rows[1]["confidence"]) > 0
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] and rep["preset"] == "v2" and rep["fields"] == list(COMPARED_FIELDS_V2)
    assert rep["generics"]["PRESET"] == 1 and rep["generics"]["RESULT_W"] == 160
    assert "expected_results_v2" in rep["reference"]


@pytest.mark.long
@pytest.mark.verilator
def test_sim_preset_v2_real(tmp_path, capsys):
    """`mstrack sim --preset v2` on 12 Girl frames: the verilated ms_tracker with PRESET 1, every field of
    every result word v2 equal to FixedTrackerV2's (the CSV rows too)."""
    seq = SEQ_ROOT / "Girl"
    if not seq.is_dir():
        pytest.skip(f"real sequence {seq} not found (../shared/data/sequences absent)")
    out = tmp_path / "girl_v2"
    rc = cli.main(["sim", str(seq), "--preset", "v2", "--max-frame-width", "1920", "--max-frames", "12",
                   "--out", str(out), "--quiet"])
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    assert "bit-exact: 12 frames x 14 fields" in cap.out
    box = round_box(*VideoSource(seq).sequence.gt[0])          # type: ignore[union-attr]
    rows = _rows(out)
    want = _v2_model_rows(_frames_of(seq, 0, 12), box)
    for got, exp in zip(rows, want, strict=True):
        diff = {k: (got[k], exp[k]) for k in SIM_CSV_FIELDS_V2 if k != "latency" and got[k] != exp[k]}
        assert not diff, f"frame {got['frame']}: {diff}"
        assert int(got["latency"]) > 0


def _scene_folder(tmp_path: Path) -> tuple[Path, list[str]]:
    """The generated 4-target scene (6 frames, 96 x 80) as an image folder, and three of its frame-0 boxes
    as --box values."""
    from mstrack.io.synthetic import make_multi_scene
    frames, rows = make_multi_scene(6, 96, 80, n_targets=4, seed=3)
    folder = tmp_path / "img"
    folder.mkdir()
    for i, f in enumerate(frames):
        cv2.imwrite(str(folder / f"{i:04d}.png"), f)
    return folder, [",".join(str(int(v)) for v in r[2:6]) for r in rows if r[0] == 0][:3]


@pytest.mark.long
@pytest.mark.verilator
def test_sim_several_boxes(tmp_path, capsys):
    """`mstrack sim` with three --box on a generated 4-target scene (an image folder) and --colour
    --max-frame-width 1024 --quick-build (the -O1 build of tb/test_ms_tracker_multi.py): the multi-target core
    ms_tracker_multi, every word bit-exact with CoreModelMulti, results.csv one row per word with the
    target's slot, the overlay written."""
    folder, boxes = _scene_folder(tmp_path)
    out = tmp_path / "multi"
    argv = ["sim", str(folder), *[f"--box={b}" for b in boxes], "--colour", "--max-frame-width", "1024",
            "--quick-build", "--out", str(out), "--quiet"]
    rc = cli.main(argv)
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    assert "bit-exact: yes (18 words, 0 differ" in cap.out
    with open(out / "results.csv") as fh:
        got = list(csv.DictReader(fh))
    assert [(r["frame"], r["target_id"]) for r in got] == [(str(i), str(k)) for i in range(6) for k in range(3)]
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] and rep["slots"] == 3 and rep["files"]["video"]


@pytest.mark.long
@pytest.mark.verilator
def test_sim_shared_engine(tmp_path, capsys):
    """`mstrack sim --shared-engine` with three --box in four slots on the generated scene: ms_tracker_shared
    (one colour engine), its capacity rule at the 720p60 raster, every word bit-exact with CoreModelMulti
    with that rule; bitexact.json names the core and the raster.  A frame larger than the raster is bad
    input (exit 2, one line)."""
    folder, boxes = _scene_folder(tmp_path)
    out = tmp_path / "shared"
    argv = ["sim", str(folder), *[f"--box={b}" for b in boxes], "--slots", "4", "--shared-engine", "--timing",
            "720p60", "--colour", "--max-frame-width", "1024", "--quick-build", "--out", str(out), "--quiet"]
    rc = cli.main(argv)
    cap = capsys.readouterr()
    assert rc == 0, cap.out + cap.err
    assert "bit-exact: yes (18 words, 0 differ" in cap.out
    rep = json.loads((out / "bitexact.json").read_text())
    assert rep["bit_exact"] and rep["core"] == "ms_tracker_shared" and rep["capacity_timing"] == "720p60"
    assert rep["generics"]["FRAME_LINES"] == 750 and rep["generics"]["LINE_CLOCKS"] == 1650
    with open(out / "results.csv") as fh:
        got = list(csv.DictReader(fh))
    assert [(r["frame"], r["target_id"]) for r in got] == [(str(i), str(k)) for i in range(6) for k in range(3)]
    # bad input: the frames do not fit the raster; one box only
    big = tmp_path / "big"
    big.mkdir()
    cv2.imwrite(str(big / "0000.png"), np.zeros((800, 96, 3), np.uint8))
    rc = cli.main(["sim", str(big), "--box=1,1,10,10", "--box=20,20,10,10", "--shared-engine", "--timing", "720p60",
                   "--out", str(tmp_path / "b1"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "do not fit the 720p60 raster" in err[0], err
    rc = cli.main(["sim", str(folder), "--box=1,1,10,10", "--shared-engine", "--out", str(tmp_path / "b2"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--shared-engine" in err[0], err
