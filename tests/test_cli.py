"""CLI and evaluation harness end to end on tiny synthetic data."""
import csv
import importlib.util
import json
import math
import textwrap

import cv2
import numpy as np
import pytest

from mstrack import cli
from mstrack.eval.evaluate import Evaluation, evaluate, run_sequence
from mstrack.io.data import load_dataset, load_sequence
from mstrack.io.synthetic import make_scene, write_otb_sequence, write_video
from mstrack.track.types import Box

HAVE_TRACKER = importlib.util.find_spec("mstrack.track.tracker") is not None
needs_tracker = pytest.mark.skipif(not HAVE_TRACKER, reason="mstrack.track.tracker not importable yet")
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
    from mstrack.eval.baselines import meanshift
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
    assert "synthetic-640x360" in out and f"{cli.DEFAULT_TRACKER}/camshift" in out
    text = doc.read_text()
    assert "mstrack bench --frames 4 --model float" in text and "| synthetic-640x360 | 4 | 640x360 |" in text


@needs_tracker
def test_bench_dataset_both_models(tiny_dataset, capsys):
    assert cli.main(["bench", str(tiny_dataset), "--frames", "3", "--model", "both"]) == 0
    out = capsys.readouterr().out
    assert f"{cli.DEFAULT_TRACKER}@fixed fps" in out and "seq1" in out and out.splitlines()[-1].startswith("all")


@needs_tracker
def test_bench_variant(tiny_dataset, capsys):
    """--variant runs the tracker with TrackerParams overrides beside the default (tracker v2's joint
    candidate here), both models; a bad variant is refused."""
    assert cli.main(["bench", str(tiny_dataset), "--frames", "3", "--model", "both", "--variant",
                     "joint:orient_T=64,scale_test=0.05,scale_test_gate=true"]) == 0
    out = capsys.readouterr().out
    assert "mstrack-v2[joint] fps" in out and "mstrack-v2@fixed[joint] fps" in out
    assert cli.parse_variant("orient_T=64,scale_test=0.05,scale_test_gate=true,kernel=flat") == {
        "orient_T": 64, "scale_test": 0.05, "scale_test_gate": True, "kernel": "flat"}
    with pytest.raises(ValueError):
        cli.parse_variant("nonsense=1")


def test_load_dataset_of_tiny(tiny_dataset):
    assert [s.name for s in load_dataset(tiny_dataset)] == ["seq0", "seq1"]


def test_eval_cache_invalidated_by_code_change(tiny_dataset, tmp_path, monkeypatch):
    from mstrack.eval import evaluate as ev_mod
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


# ----------------------------------------------------------------------------- tracker v2 outputs
V2_STATUSES = {"init", "clipped", "ok", "uncertain", "lost", "reacquired", "error"}


def _video_size(path):
    cap = cv2.VideoCapture(str(path))
    ok, f = cap.read()
    cap.release()
    assert ok
    return f.shape[1], f.shape[0]


@pytest.fixture(scope="module")
def occluded_small_seq(tmp_path_factory):
    """128x96 (Girl's size) sequence, a 24x24 target moving right, hidden by background in frames
    10..17 (v2: LOST there, REACQUIRED on frame 18 or 19)."""
    from mstrack.io.synthetic import render_scene
    n = 30
    t = np.arange(n)
    gt = np.stack([30 + t, np.full(n, 36), np.full(n, 24), np.full(n, 24)], axis=1).astype(float)
    frames = render_scene(gt, 128, 96, seed=5, hidden=(t >= 10) & (t < 18))
    return write_otb_sequence(frames, gt, tmp_path_factory.mktemp("small") / "occl"), gt


@needs_tracker
def test_track_v2_writes_confidence_and_statuses(occluded_small_seq, tmp_path):
    seq, gt = occluded_small_seq
    out = tmp_path / "v2"
    assert cli.main(["track", str(seq), "--preset", "v2", "--out", str(out), "--quiet"]) == 0
    with open(out / "results.csv") as fh:
        header = fh.readline().strip().split(",")
    assert header == list(cli.CSV_FIELDS) and "confidence" in header
    rows = _read_csv(out / "results.csv")
    assert len(rows) == 30 and {r["status"] for r in rows} <= V2_STATUSES
    conf = [float(r["confidence"]) for r in rows]
    assert conf[0] == 1.0 and all(0.0 <= c <= 1.0 for c in conf)
    assert all(len(r["confidence"].partition(".")[2]) <= cli.CONFIDENCE_DECIMALS for r in rows)
    st = [r["status"] for r in rows]
    assert "lost" in st[10:18] and "reacquired" in st[18:21], st
    assert all(c < 0.5 for c, s in zip(conf, st) if s in ("lost", "uncertain"))
    data = json.loads((out / "results.json").read_text())
    assert [d["status"] for d in data["frames_data"]] == st
    assert [d["confidence"] for d in data["frames_data"]] == pytest.approx(conf)
    # Girl-sized frames: the overlay is upscaled x3 so the banner is legible
    assert _video_size(next(out.glob("overlay.*"))) == (384, 288)
    assert _count_frames(next(out.glob("overlay.*"))) == 30


@needs_tracker
def test_track_paper_leaves_confidence_empty(occluded_small_seq, tmp_path):
    out = tmp_path / "paper"
    assert cli.main(["track", str(occluded_small_seq[0]), "--preset", "paper", "--out", str(out), "--quiet",
                     "--max-frames", "4"]) == 0
    rows = _read_csv(out / "results.csv")
    assert len(rows) == 4 and all(r["confidence"] == "nan" for r in rows)
    assert all(d["confidence"] is None for d in json.loads((out / "results.json").read_text())["frames_data"])


@pytest.mark.parametrize("tracker,preset,want", [(None, None, cli.DEFAULT_TRACKER), (None, "paper", cli.PAPER_TRACKER),
                                                 (None, "v2", "mstrack-v2"), ("mstrack-v2", "v2", "mstrack-v2"),
                                                 ("mstrack-v2", None, "mstrack-v2"),
                                                 ("opencv-kcf", None, "opencv-kcf"), ("opencv-kcf", "paper", "opencv-kcf")])
def test_resolve_tracker(tracker, preset, want):
    assert cli.resolve_tracker(tracker, preset) == want


@pytest.mark.parametrize("args,msg", [(["--preset", "v2", "--tracker", "opencv-meanshift"], "--preset v2 runs mstrack-v2"),
                                      (["--preset", "paper", "--tracker", "mstrack-v2"], "is the v2 preset")])
def test_track_preset_conflicts(occluded_small_seq, tmp_path, capsys, args, msg):
    out = tmp_path / "x"
    assert cli.main(["track", str(occluded_small_seq[0]), "--out", str(out), "--quiet", *args]) == 1
    assert msg in capsys.readouterr().err
    assert not (out / "results.csv").exists()


def test_preset_choices(capsys):
    with pytest.raises(SystemExit) as ei:
        cli.build_parser().parse_args(["track", "x", "--preset", "v3"])
    assert ei.value.code == 2 and "invalid choice" in capsys.readouterr().err
    for cmd in ("track", "demo"):
        args = cli.build_parser().parse_args([cmd, "x"] if cmd == "track" else [cmd])
        assert args.preset is None and args.tracker is None     # -> DEFAULT_TRACKER (v2)


def _row(status="ok", confidence=0.8765, alpha_c=1.0, rho_e=0.0, frame=123):
    return {"frame": frame, "x": 40.0, "y": 30.0, "w": 30.0, "h": 40.0, "cx": 54.5, "cy": 49.5, "rho_c": 0.91,
            "rho_e": rho_e, "alpha_c": alpha_c, "confidence": confidence, "status": status}


@pytest.mark.parametrize("width", [128, 320, 768])
@pytest.mark.parametrize("status", ["ok", "uncertain", "reacquired", "lost"])
def test_overlay_banner_fits_and_leads_with_status(width, status):
    k = cli.overlay_scale(width)
    assert width * k >= cli.OVERLAY_MIN_WIDTH and (k == 1 or width * (k - 1) < cli.OVERLAY_MIN_WIDTH)
    for row in (_row(status), _row(status, confidence=float("nan"), alpha_c=0.55, rho_e=0.7)):
        lines = cli.overlay_lines(row, width * k, 0.4)
        assert lines[0].startswith(f"#123  {status.upper()}")
        if math.isfinite(row["confidence"]):
            assert "conf 0.88" in lines[0]
        else:
            assert "conf" not in " ".join(lines) and "a_c 0.55" in " ".join(lines)
        for ln in lines:
            assert cv2.getTextSize(ln, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)[0][0] <= width * k - 8, ln
    # one feature (v2, colour only): rho_e and alpha_c are not shown
    assert "rho_e" not in " ".join(cli.overlay_lines(_row(), 2000)) and "a_c" not in " ".join(cli.overlay_lines(_row(), 2000))


def test_overlay_small_frame_upscaled_with_legend():
    rng = np.random.default_rng(0)
    frame = rng.integers(60, 200, (96, 128, 3), dtype=np.uint8)
    gt = np.array([42.0, 32.0, 30.0, 40.0])
    with_gt = cli.draw_overlay(frame, _row("uncertain"), gt)
    no_gt = cli.draw_overlay(frame, _row("uncertain"))
    assert with_gt.shape == no_gt.shape == (288, 384, 3)
    assert frame.shape == (96, 128, 3)                            # the input is not drawn on
    big = cv2.resize(frame, (384, 288), interpolation=cv2.INTER_NEAREST)
    dark = lambda a: (a * 0.35).astype(np.uint8)  # noqa: E731  (the bands' background)
    # banner at the top: a darkened band (its top margin) with white text
    assert (no_gt[:3, :100] == dark(big[:3, :100])).all() and (no_gt[:20, :100] > 230).all(axis=2).any()
    # legend at the bottom only where ground truth is drawn
    assert (no_gt[-12:, :60] == big[-12:, :60]).all()
    assert (with_gt[-3:, :60] == dark(big[-3:, :60])).all() and (with_gt[-40:, :100] > 230).all(axis=2).any()
    # the tracker box in the status colour, the ground truth in white (scaled x3)
    assert tuple(with_gt[30 * 3 + 60, 40 * 3]) == cli.STATUS_COLOURS["uncertain"]
    assert tuple(with_gt[32 * 3 + 60, 42 * 3 + 30 * 3 - 1]) == cli.GT_COLOUR


def test_overlay_large_frame_not_scaled():
    frame = np.full((240, 400, 3), 128, np.uint8)
    img = cli.draw_overlay(frame, _row("lost"))
    assert img.shape == frame.shape
    assert tuple(img[30 + 20, 40]) == cli.STATUS_COLOURS["lost"]


@needs_tracker
def test_demo_with_v2_preset(tmp_path, capsys):
    out = tmp_path / "demo"
    assert cli.main(["demo", "--out", str(out), "--preset", "v2", "--synthetic-frames", "20", "--frames", "5"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["tracker"] == "mstrack-v2"
    assert summary["synthetic"]["frames"] == 20 and summary["synthetic"]["auc"] > 0.6
    rows = _read_csv(out / "synthetic" / "results.csv")
    assert all(0.0 <= float(r["confidence"]) <= 1.0 for r in rows)
    if summary["vtest"] is not None:
        assert summary["vtest"]["frames"] == 5 and 0.0 <= summary["vtest"]["mean_confidence"] <= 1.0
    assert "mstrack-v2" in capsys.readouterr().out
