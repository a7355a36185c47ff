"""Multi-object evaluation and CLI (docs/multi.md): `mstrack eval` on MOT folders (protocol, cache,
report), the MOT metrics through TrackEval checked against motmetrics, `mstrack track` with several
targets (MOT-format results.csv), `mstrack bench` and `mstrack demo` on several targets."""
import csv
import json
import warnings

import cv2
import numpy as np
import pytest

from mstrack import MultiCoreConfig, cli
from mstrack.eval import multi as em
from mstrack.io.mot import load_mot_sequence, parse_mot_gt
from mstrack.io.synthetic import make_multi_scene, write_mot_sequence, write_video


@pytest.fixture(scope="module")
def mot_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("mot")
    frames, rows = make_multi_scene(16, 200, 150, n_targets=3, seed=3, spans=[(0, 16), (0, 12), (4, 16)])
    write_mot_sequence(frames, rows, root / "syn-a", fps=10)
    frames, rows = make_multi_scene(12, 180, 140, n_targets=2, seed=4)
    write_mot_sequence(frames, rows, root / "syn-b")
    return root


def _frames(path):
    cap = cv2.VideoCapture(str(path))
    n = 0
    while cap.read()[0]:
        n += 1
    cap.release()
    return n


class _Spy:
    """A harness that records what run_mot asks of it (boxes: the ground truth it was given)."""

    def __init__(self):
        self.log, self.live, self.boxes = [], {}, {}

    def add(self, frame, box):
        tid = len(self.log)
        self.log.append(("add", tid))
        self.live[tid] = box
        from mstrack.track.types import Box
        return tid, Box.of(box)

    def remove(self, tid):
        self.log.append(("remove", tid))
        del self.live[tid]

    def update(self, frame):
        from mstrack.track.types import Box
        return [(t, Box.of(b)) for t, b in self.live.items()]


def test_protocol_add_on_first_remove_after_last(mot_root):
    seq = load_mot_sequence(mot_root / "syn-a")
    spy = _Spy()
    run = em.run_mot(spy, seq)
    assert {g: (t.first, t.first + len(t.boxes) - 1) for g, t in run.targets.items()} == \
        {g: (t.first, t.last) for g, t in seq.tracks.items()}
    assert run.updates == sum(t.last - t.first for t in seq.tracks.values())
    assert ("remove", 1) in spy.log and spy.log.index(("remove", 1)) > spy.log.index(("add", 2))
    # a tracker standing still on its init box: MOT scores of a perfect first frame only
    assert em.MotRun.from_json(json.loads(json.dumps(run.to_json()))).to_json() == run.to_json()


def test_perfect_hypotheses_score_one(mot_root):
    seq = load_mot_sequence(mot_root / "syn-a")
    m = em.mot_summary(em.mot_metrics(em.mot_data(seq.rows, seq.rows, len(seq))))
    assert m["HOTA"] == pytest.approx(1.0) and m["MOTA"] == 1.0 and m["IDF1"] == 1.0 and m["IDSW"] == 0
    swapped = seq.rows.copy()
    late = swapped[:, 0] >= 8
    swapped[late & (seq.rows[:, 1] == 1), 1] = 3
    swapped[late & (seq.rows[:, 1] == 3), 1] = 1
    m = em.mot_summary(em.mot_metrics(em.mot_data(seq.rows, swapped, len(seq))))
    assert m["IDSW"] == 2 and m["MOTA"] < 1.0 and m["HOTA"] < 1.0


def test_trackeval_agrees_with_motmetrics(mot_root, tmp_path):
    """MOTA, IDF1, FP, FN of the TrackEval route equal motmetrics' (an independent implementation) on
    real tracker output; ID switches within one (their definitions differ in a corner case)."""
    mm = pytest.importorskip("motmetrics")
    seqs = [load_mot_sequence(mot_root / n) for n in ("syn-a", "syn-b")]
    ev = em.evaluate_mot(seqs, ["opencv-camshift", "mstrack-v2"], tmp_path / "ev")
    for label in ev.trackers:
        for s in seqs:
            run = ev.runs[label][s.name]
            gt, hyp = s.rows, run.hypotheses()
            acc = mm.MOTAccumulator(auto_id=True)
            for t in range(run.n_frames):
                g, h = gt[gt[:, 0] == t], hyp[hyp[:, 0] == t]
                # motmetrics 1.4.0's iou_matrix calls np.asfarray (removed in numpy 2): its boxiou directly
                d = 1 - mm.distances.boxiou(g[:, None, 2:6], h[None, :, 2:6]) if len(g) and len(h) \
                    else np.empty((len(g), len(h)))
                acc.update(g[:, 1].astype(int).tolist(), h[:, 1].astype(int).tolist(), np.where(d > 0.5, np.nan, d))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = mm.metrics.create().compute(acc, metrics=["mota", "idf1", "num_switches", "num_false_positives",
                                                              "num_misses"], name="x").to_dict("records")[0]
            te = ev.per_sequence[label][s.name].mot
            assert te["IDF1"] == pytest.approx(r["idf1"]) and te["CLR_FP"] == r["num_false_positives"]
            assert te["CLR_FN"] == r["num_misses"] and abs(te["IDSW"] - r["num_switches"]) <= 1
            n_gt = len(gt)
            assert te["MOTA"] == pytest.approx(r["mota"], abs=1.0 / n_gt + 1e-12)


def test_eval_cli_report_and_cache(mot_root, tmp_path, capsys, monkeypatch):
    out = tmp_path / "ev"
    args = ["eval", str(mot_root), "--trackers", "mstrack-v2,opencv-camshift", "--out", str(out), "--quiet"]
    assert cli.main(args) == 0
    text = capsys.readouterr().out
    assert "HOTA" in text and "mstrack-v2" in text and "opencv-camshift" in text
    rep = json.loads((out / "report.json").read_text())
    assert set(rep["overall"]) == {"mstrack-v2", "opencv-camshift"} and set(rep["sequences"]) == {"syn-a", "syn-b"}
    o = rep["overall"]["mstrack-v2"]
    assert 0.5 < o["auc"] <= 1 and {"HOTA", "MOTA", "IDF1", "IDSW"} <= set(o["mot"]) and o["loss"]["on"] > 0
    assert set(rep["per_target"]["mstrack-v2"]["syn-a"]) == {"1", "2", "3"}
    md = (out / "report.md").read_text()
    assert "## Per target" in md and "TrackEval" in md and (out / "success.png").is_file()
    # cached: a second run does not track again
    monkeypatch.setattr(em, "run_mot", lambda *a, **k: (_ for _ in ()).throw(AssertionError("ran again")))
    assert cli.main(args) == 0
    # the fixed model under its own label
    monkeypatch.undo()
    assert cli.main(["eval", str(mot_root / "syn-b"), "--model", "fixed", "--trackers", "mstrack-v2",
                     "--out", str(tmp_path / "fx"), "--quiet"]) == 0
    assert "mstrack-v2@fixed" in json.loads((tmp_path / "fx" / "report.json").read_text())["overall"]


def test_refused_adds_are_reported(mot_root, tmp_path):
    seq = load_mot_sequence(mot_root / "syn-a")
    two = MultiCoreConfig(max_targets=2)
    ev = em.evaluate_mot([seq], ["mstrack-v2"], tmp_path, make=lambda n, m: em.make_multi(n, m, two))
    run = ev.runs["mstrack-v2"]["syn-a"]
    assert sorted(run.targets) == [1, 2] and list(run.refused) == [3] and "ADD_FULL" in run.refused[3]
    assert "## Refused adds" in em.report_markdown_mot(ev)


def test_track_cli_several_boxes(tmp_path, capsys):
    frames, rows = make_multi_scene(12, 160, 120, n_targets=2, seed=2)
    video = write_video(frames, tmp_path / "v.avi", fps=10)
    b = [",".join(str(int(v)) for v in rows[rows[:, 1] == k][0, 2:6]) for k in (1, 2)]
    out = tmp_path / "o"
    assert cli.main(["track", str(video), "--box", b[0], "--box", b[1], "--out", str(out), "--quiet"]) == 0
    lines = (out / "results.csv").read_text().splitlines()
    first = [ln.split(",") for ln in lines if ln.startswith("1,")]
    assert [f[1] for f in first] == ["1", "2"] and first[0][6:] == ["1", "-1", "-1", "-1"]
    x0, y0 = (int(v) for v in b[0].split(",")[:2])
    assert (float(first[0][2]), float(first[0][3])) == (x0 + 1, y0 + 1)   # MOT's 1-based x, y
    res = json.loads((out / "results.json").read_text())
    data = res["frames_data"]
    assert len(data) == 24 and {d["id"] for d in data} == {1, 2} and {d["target_id"] for d in data} == {0, 1}
    assert all(0 <= d["confidence"] <= 1 for d in data) and res["frames"] == 12
    assert _frames(res["video"]) == 12
    ok = ("ok", "init", "clipped", "reacquired")   # results.csv: the results that are ok
    assert parse_mot_gt(out / "results.csv").shape[0] == sum(d["status"] in ok for d in data)


def test_track_cli_init_file_and_mot_folder(mot_root, tmp_path, capsys):
    d = mot_root / "syn-a"
    out = tmp_path / "a"
    assert cli.main(["track", str(d / "img"), "--init", str(d / "gt.txt"), "--out", str(out), "--quiet",
                     "--tracker", "opencv-camshift"]) == 0
    res = json.loads((out / "results.json").read_text())
    assert res["targets"]["3"]["first_frame"] == 4 and res["refused"] == {}
    assert min(r["frame"] for r in res["frames_data"] if r["id"] == 3) == 4
    assert max(r["frame"] for r in res["frames_data"] if r["id"] == 2) == 15   # tracked to the end
    out2 = tmp_path / "b"   # a MOT folder: its gt.txt by default, ground truth drawn
    assert cli.main(["track", str(d), "--out", str(out2), "--quiet", "--max-frames", "5"]) == 0
    assert json.loads((out2 / "results.json").read_text())["frames"] == 5
    assert "3 targets" not in capsys.readouterr().err


def test_track_cli_single_box_unchanged(tmp_path):
    frames, rows = make_multi_scene(6, 160, 120, n_targets=1, seed=2)
    video = write_video(frames, tmp_path / "v.avi", fps=10)
    out = tmp_path / "o"
    box = ",".join(str(int(v)) for v in rows[0, 2:6])
    assert cli.main(["track", str(video), "--box", box, "--out", str(out), "--quiet"]) == 0
    with open(out / "results.csv") as fh:
        assert tuple(next(csv.reader(fh))) == cli.CSV_FIELDS


def test_bench_mot(mot_root, tmp_path, capsys):
    doc = tmp_path / "bench_multi.md"
    assert cli.main(["bench", str(mot_root), "--model", "float", "--frames", "6", "--write-docs",
                     "--docs-file", str(doc)]) == 0
    out = capsys.readouterr().out
    assert "mstrack-v2 upd/s" in out and "mstrack-v2/camshift" in out and out.splitlines()[-2].startswith("all")
    assert "| syn-a | 6 | 3 |" in doc.read_text() and "target updates per second" in doc.read_text()


def test_demo_multi_part(tmp_path, capsys):
    out = tmp_path / "d"
    assert cli.main(["demo", "--out", str(out), "--synthetic-frames", "8", "--frames", "3",
                     "--multi-frames", "24"]) == 0
    s = json.loads((out / "summary.json").read_text())["multi"]
    assert s["frames"] == 24 and s["targets"] == 4 and s["mean_auc"] > 0.6 and s["mot"]["HOTA"] > 0.6
    assert _frames(s["video"]) == 24 and "[demo] multi-target scene" in capsys.readouterr().out
