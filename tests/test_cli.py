"""CLI and evaluation harness end to end on tiny synthetic data."""
import csv
import importlib.util
import json
import textwrap

import cv2
import numpy as np
import pytest

from mstrack import cli
from mstrack.evaluate import Evaluation, evaluate, run_sequence
from mstrack.data import load_dataset, load_sequence
from mstrack.synthetic import make_scene, write_otb_sequence, write_video
from mstrack.types import Box

HAVE_TRACKER = importlib.util.find_spec("mstrack.tracker") is not None
needs_tracker = pytest.mark.skipif(not HAVE_TRACKER, reason="mstrack.tracker not importable yet")
FAST = "opencv-meanshift,opencv-camshift"


def _count_frames(path) -> int:
    cap = cv2.VideoCapture(str(path))
    n = 0
    while cap.read()[0]:
        n += 1
    cap.release()
    return n


@pytest.fixture(scope="module")
def tiny_video(tmp_path_factory):
    frames, gt = make_scene(20, 160, 120, seed=2)
    path = write_video(frames, tmp_path_factory.mktemp("vid") / "tiny.avi", fps=10)
    return path, gt


@pytest.fixture(scope="module")
def tiny_dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    for i, attrs in enumerate((["SV"], ["SV", "BC"])):
        frames, gt = make_scene(15 + 5 * i, 160, 120, seed=10 + i)
        write_otb_sequence(frames, gt, root / f"seq{i}", attributes=attrs)
    return root


def _read_csv(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize("tracker", ["opencv-meanshift", pytest.param("mstrack-fused-flat", marks=needs_tracker)])
def test_track_video(tiny_video, tmp_path, tracker):
    path, gt = tiny_video
    n_in = _count_frames(path)
    out = tmp_path / "out"
    box = ",".join(str(int(v)) for v in gt[0])
    assert cli.main(["track", str(path), "--box", box, "--tracker", tracker, "--out", str(out), "--quiet"]) == 0
    rows = _read_csv(out / "results.csv")
    assert n_in == 20 and len(rows) == n_in
    assert [int(r["frame"]) for r in rows] == list(range(n_in))
    assert set(rows[0]) == set(cli.CSV_FIELDS)
    assert rows[0]["status"] in ("init", "clipped") and all(r["status"] != "error" for r in rows)
    video = next(out.glob("overlay.*"))
    assert _count_frames(video) == n_in
    data = json.loads((out / "results.json").read_text())
    assert len(data["frames_data"]) == n_in and data["frames_data"][0]["x"] == pytest.approx(gt[0][0])
    # the target was followed (box centre within 10 px of the truth on the last frame)
    last = rows[-1]
    cx, cy = float(last["x"]) + float(last["w"]) / 2, float(last["y"]) + float(last["h"]) / 2
    assert np.hypot(cx - (gt[-1][0] + gt[-1][2] / 2), cy - (gt[-1][1] + gt[-1][3] / 2)) < 10


def test_track_sequence_folder_defaults_to_gt_box(tiny_dataset, tmp_path):
    out = tmp_path / "o"
    assert cli.main(["track", str(tiny_dataset / "seq0"), "--tracker", "opencv-meanshift", "--out", str(out),
                     "--quiet"]) == 0
    rows = _read_csv(out / "results.csv")
    gt0 = load_sequence(tiny_dataset / "seq0").gt[0]
    assert len(rows) == 15
    assert [float(rows[0][k]) for k in "xywh"] == pytest.approx(gt0)


def test_track_requires_box_for_video(tiny_video, tmp_path, capsys):
    assert cli.main(["track", str(tiny_video[0]), "--tracker", "opencv-meanshift", "--out", str(tmp_path)]) == 1
    assert "--box" in capsys.readouterr().err


def test_bad_frames_are_recorded_as_error(tmp_path):
    frames, gt = make_scene(6, 96, 72, seed=1)
    seq = [frames[0], frames[1], None, frames[3][:40, :40], frames[4], frames[5]]   # unreadable + wrong size
    from mstrack.baselines import meanshift
    rows, info = cli.track_frames(meanshift(), seq, Box.of(gt[0]), tmp_path)
    assert [r["status"] for r in rows] == ["init", "ok", "error", "error", "ok", "ok"]
    assert rows[2]["x"] == rows[1]["x"]                      # previous box kept
    assert _count_frames(info["video"]) == 6


def test_eval_report_and_cache(tiny_dataset, tmp_path):
    out = tmp_path / "eval"
    trackers = FAST + (",mstrack-fused-flat" if HAVE_TRACKER else "")
    args = ["eval", str(tiny_dataset), "--trackers", trackers, "--out", str(out), "--quiet"]
    assert cli.main(args) == 0
    for f in ("report.md", "report.json", "success.png", "precision.png"):
        assert (out / f).is_file() and (out / f).stat().st_size > 0
    md = (out / "report.md").read_text()
    rep = json.loads((out / "report.json").read_text())
    names = trackers.split(",")
    for t in names:
        assert f"| {t} |" in md
        assert set(rep["per_sequence"][t]) == {"seq0", "seq1"}
        assert len(rep["overall"][t]["success"]) == 21 and len(rep["overall"][t]["precision"]) == 51
        assert 0.0 <= rep["overall"][t]["auc"] <= 1.0
    assert rep["overall"]["opencv-meanshift"]["auc"] > 0.6
    assert rep["overall"]["opencv-meanshift"]["n_frames"] == 35
    assert set(rep["attributes"]) == {"SV", "BC"} and rep["attributes"]["BC"] == ["seq1"]
    assert rep["per_attribute"]["opencv-meanshift"]["SV"]["n_frames"] == 35
    assert "## AUC per attribute" in md and "| BC | 1 |" in md
    cached = out / "results" / "opencv-meanshift" / "seq0.json"
    run = json.loads(cached.read_text())
    assert len(run["boxes"]) == 15 and run["fps"] > 0
    # rerun reuses the cache; --force recomputes
    t0 = cached.stat().st_mtime_ns
    assert cli.main(args) == 0
    assert cached.stat().st_mtime_ns == t0
    assert cli.main(args + ["--force"]) == 0
    assert cached.stat().st_mtime_ns != t0
    # --max-frames changes the frame count, so the cache is not reused
    assert cli.main(args + ["--max-frames", "5", "--trackers", "opencv-meanshift"]) == 0
    assert len(json.loads(cached.read_text())["boxes"]) == 5


def test_eval_unknown_tracker(tiny_dataset, tmp_path, capsys):
    assert cli.main(["eval", str(tiny_dataset), "--trackers", "nope", "--out", str(tmp_path)]) == 1
    assert "unknown tracker" in capsys.readouterr().err


def test_harness_accepts_plain_box_trackers(tiny_dataset, tmp_path):
    seq = load_sequence(tiny_dataset / "seq0")

    class Oracle:                                   # returns tuples, knows the truth
        def init(self, frame, box):
            self.i = 0
            return None

        def update(self, frame):
            self.i += 1
            return tuple(seq.gt[self.i])

    run = run_sequence(Oracle(), seq, label="oracle")
    assert run.boxes == pytest.approx(seq.gt) and run.status[0] == "init"
    ev = evaluate([seq], ["oracle"], tmp_path, factory=lambda name, model: Oracle(), quiet=True)
    assert isinstance(ev, Evaluation)
    assert ev.overall["oracle"].auc == pytest.approx(20 / 21)       # IoU 1 > every threshold but 1
    assert ev.overall["oracle"].precision20 == 1.0


def test_cli_extension_registry(tmp_path, monkeypatch, capsys):
    (tmp_path / "fake_ext.py").write_text(textwrap.dedent("""
        def register(sub):
            p = sub.add_parser("hello")
            p.add_argument("--n", type=int, default=1)
            p.set_defaults(func=lambda args: print("hello" * args.n) or 3)
    """))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(cli, "EXTENSIONS", ["fake_ext:register", "no_such_module_xyz:register"])
    assert cli.main(["hello", "--n", "2"]) == 3
    cap = capsys.readouterr()
    assert "hellohello" in cap.out and "no_such_module_xyz" in cap.err


def test_demo_with_baseline(tmp_path, capsys):
    out = tmp_path / "demo"
    assert cli.main(["demo", "--out", str(out), "--tracker", "opencv-meanshift", "--synthetic-frames", "20",
                     "--frames", "5"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["synthetic"]["frames"] == 20 and summary["synthetic"]["auc"] > 0.6
    assert _count_frames(summary["synthetic"]["video"]) == 20
    if summary["vtest"] is not None:
        assert summary["vtest"]["frames"] == 5
    assert "[demo] synthetic scene" in capsys.readouterr().out


@needs_tracker
def test_bench_synthetic_writes_docs(tmp_path, capsys):
    doc = tmp_path / "bench.md"
    assert cli.main(["bench", "--frames", "4", "--model", "float", "--write-docs", "--docs-file", str(doc)]) == 0
    out = capsys.readouterr().out
    assert "synthetic-640x360" in out and "mstrack-fused-flat/camshift" in out
    text = doc.read_text()
    assert "mstrack bench --frames 4 --model float" in text and "| synthetic-640x360 | 4 | 640x360 |" in text


@needs_tracker
def test_bench_dataset_both_models(tiny_dataset, capsys):
    assert cli.main(["bench", str(tiny_dataset), "--frames", "3", "--model", "both"]) == 0
    out = capsys.readouterr().out
    assert "mstrack-fused-flat@fixed fps" in out and "seq1" in out and out.splitlines()[-1].startswith("all")


def test_load_dataset_of_tiny(tiny_dataset):
    assert [s.name for s in load_dataset(tiny_dataset)] == ["seq0", "seq1"]


def test_eval_cache_invalidated_by_code_change(tiny_dataset, tmp_path, monkeypatch):
    from mstrack import evaluate as ev_mod
    seqs = load_dataset(tiny_dataset, ["seq0"])
    evaluate(seqs, ["opencv-meanshift"], tmp_path, quiet=True)
    cached = tmp_path / "results" / "opencv-meanshift" / "seq0.json"
    fp = json.loads(cached.read_text())["fingerprint"]
    assert fp == ev_mod.tracker_fingerprint("opencv-meanshift") and len(fp) == 12
    t0 = cached.stat().st_mtime_ns
    evaluate(seqs, ["opencv-meanshift"], tmp_path, quiet=True)
    assert cached.stat().st_mtime_ns == t0
    monkeypatch.setattr(ev_mod, "tracker_fingerprint", lambda name: "changed")
    evaluate(seqs, ["opencv-meanshift"], tmp_path, quiet=True)
    assert json.loads(cached.read_text())["fingerprint"] == "changed"


def test_default_parser_has_builtin_and_listed_extension_commands(capsys):
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert {"eval", "track", "bench", "demo"} <= set(sub.choices)
    assert "not found" not in capsys.readouterr().err    # every listed extension module loads
    assert len(sub.choices) >= 4 + len(cli.EXTENSIONS)
