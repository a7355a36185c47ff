"""Bad input: clear one-line errors, nothing lost (CLI, data readers, eval harness).

Each case was reproduced on main first; the test asserts the message and that files written
earlier are still there.  Tiny synthetic data (mstrack.io.synthetic)."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest

from mstrack import cli
from mstrack.io.data import DataError, load_dataset, load_sequence, parse_gt
from mstrack.eval.evaluate import evaluate
from mstrack.io.synthetic import make_scene, write_otb_sequence, write_video
from mstrack.track.types import Box, Status, TrackResult

FAST = ["--trackers", "opencv-camshift", "--quiet"]


def _dataset(root, seed, names=("s0",), n=15):
    for i, name in enumerate(names):
        frames, gt = make_scene(n, 160, 120, seed=seed + i)
        write_otb_sequence(frames, gt, root / name)
    return root


def _snapshot(folder):
    """{relative path: bytes} of every file under folder."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _one_line_error(capsys, command, *needles):
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines and lines[-1].startswith(f"mstrack {command}: error: "), err
    assert "Traceback" not in err
    for n in needles:
        assert n in lines[-1], (n, lines[-1])
    return lines[-1]


def _auc(out):
    return json.loads((out / "report.json").read_text())["overall"]["opencv-camshift"]["auc"]


# ----------------------------------------------------------------------------- eval cache
def test_eval_cache_is_keyed_by_sequence_content(tmp_path):
    """dsA and dsB both have a 15-frame s0: the second eval into the same --out must not reuse dsA's runs."""
    ds_a, ds_b = _dataset(tmp_path / "dsA", 1), _dataset(tmp_path / "dsB", 2)
    shared, fresh_a, fresh_b = tmp_path / "X", tmp_path / "A", tmp_path / "B"
    for ds, out in ((ds_a, fresh_a), (ds_b, fresh_b)):
        assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 0
    assert _auc(fresh_a) != pytest.approx(_auc(fresh_b))       # the two datasets score differently
    assert cli.main(["eval", str(ds_a), "--out", str(shared), *FAST]) == 0
    assert cli.main(["eval", str(ds_b), "--out", str(shared), *FAST]) == 0
    assert _auc(shared) == pytest.approx(_auc(fresh_b))
    # and an unchanged dataset reuses its cache (the cached file is not rewritten)
    cached = shared / "results" / "opencv-camshift" / "s0.json"
    before = cached.read_bytes(), cached.stat().st_mtime_ns
    assert cli.main(["eval", str(ds_b), "--out", str(shared), *FAST]) == 0
    assert (cached.read_bytes(), cached.stat().st_mtime_ns) == before


class _CountingTracker:
    """A plain tracker with a ``params`` attribute that counts init() calls."""
    calls = 0

    def __init__(self, params):
        self.params = params

    def init(self, frame, box):
        type(self).calls += 1
        self.box = Box.of(box)
        return self.box

    def update(self, frame):
        return self.box


def test_eval_cache_is_keyed_by_tracker_parameters(tmp_path):
    from mstrack.track.params import TrackerParams
    seqs = load_dataset(_dataset(tmp_path / "ds", 1))
    run = lambda tp: evaluate(seqs, ["mstrack-colour-flat"], tmp_path / "out", quiet=True,  # noqa: E731
                              factory=lambda name, model: _CountingTracker(tp))
    run(TrackerParams(max_iter=20))
    assert _CountingTracker.calls == 1
    run(TrackerParams(max_iter=20))
    assert _CountingTracker.calls == 1                  # same parameters: cached
    run(TrackerParams(max_iter=5))
    assert _CountingTracker.calls == 2                  # other parameters: run again


# ----------------------------------------------------------------------------- sequence names
def test_same_sequence_twice_on_the_command_line(tmp_path, capsys):
    ds = _dataset(tmp_path / "ds", 1, ("s0", "s1"))
    out = tmp_path / "out"
    assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 0
    before = _snapshot(out)
    assert cli.main(["eval", str(ds), "--sequences", "s0,s0", "--out", str(out), *FAST]) == 1
    _one_line_error(capsys, "eval", "s0 given more than once")
    assert _snapshot(out) == before


def test_two_folders_with_the_same_meta_name(tmp_path, capsys):
    ds = _dataset(tmp_path / "ds", 1, ("s0", "s1"))
    meta = json.loads((ds / "s1" / "meta.json").read_text())
    (ds / "s1" / "meta.json").write_text(json.dumps({**meta, "name": "s0"}))
    assert cli.main(["eval", str(ds), "--out", str(tmp_path / "out"), *FAST]) == 1
    _one_line_error(capsys, "eval", "two sequences named 's0'", "s0/", "s1/")
    with pytest.raises(ValueError, match="two sequences named"):   # the harness checks too
        evaluate([load_sequence(ds / "s0"), load_sequence(ds / "s1")], ["opencv-camshift"], tmp_path / "o2")


@pytest.mark.parametrize("name", ["../../x", "a/b", "..", ".", "", "a\\b", 5])
def test_meta_name_cannot_escape_the_cache(tmp_path, capsys, name):
    ds = _dataset(tmp_path / "ds", 1)
    meta = json.loads((ds / "s0" / "meta.json").read_text())
    (ds / "s0" / "meta.json").write_text(json.dumps({**meta, "name": name}))
    out = tmp_path / "a" / "b" / "out"
    assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 1
    _one_line_error(capsys, "eval", "'name' must be a plain name", "meta.json")
    assert not [p for p in tmp_path.rglob("*.json") if "ds" not in p.parts]   # no result written anywhere


def test_cache_path_refuses_path_names(tmp_path):
    from mstrack.eval.evaluate import cache_path
    with pytest.raises(ValueError, match="cannot name a cache file"):
        cache_path(tmp_path, "opencv-camshift", "../../x")


# ----------------------------------------------------------------------------- ground truth
def test_blank_gt_line_is_a_missing_annotation(tmp_path):
    p = tmp_path / "groundtruth_rect.txt"
    p.write_text("1,2,10,10\n2,3,10,10\n\n4,5,10,10\n5,6,10,10\n\n\n")
    gt = parse_gt(p)
    assert gt.shape == (4 + 1, 4)                       # trailing blank lines dropped, middle one kept
    assert np.isnan(gt[2]).all()
    assert gt[3].tolist() == [4, 5, 10, 10] and gt[4].tolist() == [5, 6, 10, 10]   # later rows keep their frame


def test_blank_gt_line_in_a_sequence_keeps_frame_alignment(tmp_path):
    frames, gt = make_scene(8, 160, 120, seed=3)
    d = write_otb_sequence(frames, gt, tmp_path / "s0")
    lines = (d / "groundtruth_rect.txt").read_text().splitlines()
    lines[4] = ""
    (d / "groundtruth_rect.txt").write_text("\n".join(lines) + "\n")
    seq = load_sequence(d, strict=True)                 # 8 images, 8 rows: no count mismatch
    assert np.isnan(seq.gt[4]).all()
    assert np.array_equal(seq.gt[5:], gt[5:]) and np.array_equal(seq.gt[:4], gt[:4])


# ----------------------------------------------------------------------------- --out
def _bad_out(kind, tmp_path, monkeypatch):
    f = tmp_path / "afile"
    f.write_text("keep me\n")
    if kind == "file":
        return f, "is a file"
    if kind == "under-file":
        return f / "sub", "lies under a file"
    d = tmp_path / "readonly"
    d.mkdir()
    import tempfile

    def deny(*a, **k):
        raise PermissionError(13, "Permission denied")
    monkeypatch.setattr(tempfile, "NamedTemporaryFile", deny)   # chmod does not stop root
    return d, "cannot be created or written (Permission denied)"


@pytest.mark.parametrize("kind", ["file", "under-file", "not-writable"])
@pytest.mark.parametrize("command", ["track", "eval"])
def test_bad_out_is_refused_before_anything_runs(tmp_path, monkeypatch, capsys, kind, command):
    ds = _dataset(tmp_path / "ds", 1)
    good = tmp_path / "good"
    assert cli.main(["eval", str(ds), "--out", str(good), *FAST]) == 0
    before, before_tmp = _snapshot(good), (tmp_path / "afile").exists()
    out, msg = _bad_out(kind, tmp_path, monkeypatch)
    args = (["eval", str(ds), *FAST] if command == "eval"
            else ["track", str(ds / "s0"), "--tracker", "opencv-camshift", "--quiet"])
    assert cli.main([*args, "--out", str(out)]) == 1
    _one_line_error(capsys, command, "--out", msg)
    assert (tmp_path / "afile").read_text() == "keep me\n"
    assert _snapshot(good) == before and before_tmp is False
    if kind == "not-writable":
        assert list(out.iterdir()) == []


# ----------------------------------------------------------------------------- meta.json
@pytest.mark.parametrize("meta,msg", [
    ("[1, 2]", "meta.json must be a JSON object"),
    ('"s0"', "meta.json must be a JSON object"),
    ('{"fps": "abc"}', "'fps' must be a positive number"),
    ('{"fps": [1]}', "'fps' must be a positive number"),
    ('{"fps": true}', "'fps' must be a positive number"),
    ('{"fps": -5}', "'fps' must be a positive number"),
    ('{"gt_coordinate_base": "one"}', "'gt_coordinate_base' must be a number"),
    ('{"gt_coordinate_base": {}}', "'gt_coordinate_base' must be a number"),
    ('{"attributes": "SV"}', "'attributes' must be a list of strings"),
])
def test_bad_meta_json_names_the_file(tmp_path, capsys, meta, msg):
    ds = _dataset(tmp_path / "ds", 1)
    (ds / "s0" / "meta.json").write_text(meta)
    with pytest.raises(DataError, match=msg) as ei:
        load_sequence(ds / "s0")
    assert ei.value.path == ds / "s0" / "meta.json"
    assert cli.main(["eval", str(ds), "--out", str(tmp_path / "out"), *FAST]) == 1
    _one_line_error(capsys, "eval", msg, str(ds / "s0" / "meta.json"))
    assert cli.main(["track", str(ds / "s0"), "--out", str(tmp_path / "t"), "--quiet"]) == 1
    _one_line_error(capsys, "track", msg)


# ----------------------------------------------------------------------------- numbers
@pytest.mark.parametrize("args", [["eval", "DS", "--max-frames", "0"], ["eval", "DS", "--max-frames", "-3"],
                                  ["track", "DS/s0", "--max-frames", "0"], ["eval", "DS", "--max-frames", "x"]])
def test_max_frames_must_be_positive(tmp_path, capsys, args):
    ds = _dataset(tmp_path / "ds", 1)
    argv = [a.replace("DS", str(ds)) for a in args] + ["--out", str(tmp_path / "out")]
    with pytest.raises(SystemExit) as ei:
        cli.main(argv)
    assert ei.value.code == 2
    assert "--max-frames: wants a positive integer" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
    with pytest.raises(ValueError, match="max_frames must be a positive integer"):
        evaluate(load_dataset(ds), ["opencv-camshift"], tmp_path / "o", max_frames=0)


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_huge_box_is_one_line(tmp_path, capsys, model):
    frames, _ = make_scene(5, 160, 120, seed=1)
    video = write_video(frames, tmp_path / "v.avi")
    assert cli.main(["track", str(video), "--box", "1e308,1e308,1e308,1e308", "--model", model,
                     "--out", str(tmp_path / "o"), "--quiet"]) == 1
    _one_line_error(capsys, "track", "1e+308")


# ----------------------------------------------------------------------------- truncated videos
@pytest.mark.parametrize("damage", ["cut", "garbled"])
def test_truncated_video_is_reported(tmp_path, capsys, damage):
    frames, gt = make_scene(15, 160, 120, seed=3)
    video = write_video(frames, tmp_path / "v.avi", fps=10)
    data = bytearray(video.read_bytes())
    if damage == "cut":
        data = data[:len(data) // 2]
    else:
        data[len(data) // 2:len(data) // 2 + 3000] = bytes(3000)
    bad = tmp_path / f"{damage}.avi"
    bad.write_bytes(bytes(data))
    out = tmp_path / "out"
    box = ",".join(str(int(v)) for v in gt[0])
    assert cli.main(["track", str(bad), "--box", box, "--tracker", "opencv-camshift", "--out", str(out),
                     "--quiet"]) == 0
    io = capsys.readouterr()
    res = json.loads((out / "results.json").read_text())
    n = res["frames"]
    assert n < 15 and res["source"]["frames_decoded"] == n
    assert res["source"]["truncated"].startswith(f"decoded {n} of 15 frames")
    assert f"decoded {n} of 15 frames" in io.err and "VIDEO TRUNCATED" in io.out


def test_intact_video_is_not_truncated(tmp_path):
    frames, gt = make_scene(12, 160, 120, seed=3)
    video = write_video(frames, tmp_path / "v.avi", fps=10)
    out = tmp_path / "out"
    box = ",".join(str(int(v)) for v in gt[0])
    assert cli.main(["track", str(video), "--box", box, "--tracker", "opencv-camshift", "--out", str(out),
                     "--quiet"]) == 0
    res = json.loads((out / "results.json").read_text())
    assert res["frames"] == 12 and res["source"]["truncated"] is None


# ----------------------------------------------------------------------------- unreadable frames
def test_unreadable_frame0_names_the_image(tmp_path, capsys):
    d = _dataset(tmp_path / "ds", 1) / "s0"
    (d / "img" / "0001.jpg").write_bytes(b"not a jpeg")
    out = tmp_path / "out"
    assert cli.main(["track", str(d), "--tracker", "opencv-camshift", "--out", str(out), "--quiet"]) == 1
    line = _one_line_error(capsys, "track", "frame 0 is unreadable", str(d / "img" / "0001.jpg"))
    assert not line.endswith(str(out))


def test_unreadable_middle_frame_is_named_and_recorded(tmp_path, capsys):
    d = _dataset(tmp_path / "ds", 1) / "s0"
    (d / "img" / "0005.jpg").write_bytes(b"not a jpeg")
    out = tmp_path / "out"
    assert cli.main(["track", str(d), "--tracker", "opencv-camshift", "--out", str(out), "--quiet"]) == 0
    assert str(d / "img" / "0005.jpg") in capsys.readouterr().err
    res = json.loads((out / "results.json").read_text())
    assert list(res["frame_errors"]) == ["4"] and res["frames_data"][4]["status"] == Status.ERROR.value


# ----------------------------------------------------------------------------- eval goes on
def _break(kind, seq_dir):
    if kind == "corrupt-frame":
        (seq_dir / "img" / "0007.jpg").write_bytes(b"garbage")
        return str(seq_dir / "img" / "0007.jpg")
    gt = seq_dir / "groundtruth_rect.txt"
    lines = gt.read_text().splitlines()
    lines[0] = "NaN,NaN,NaN,NaN" if kind == "nan-frame0-box" else "900,900,20,20"
    gt.write_text("\n".join(lines) + "\n")
    return "frame 0 ground truth is invalid" if kind == "nan-frame0-box" else "frame 0: ValueError: box (899.0"


@pytest.mark.parametrize("kind", ["corrupt-frame", "nan-frame0-box", "outside-frame0-box"])
def test_eval_records_a_failed_sequence_and_goes_on(tmp_path, capsys, kind):
    ds = _dataset(tmp_path / "ds", 1, ("s0", "s1", "s2"))
    out = tmp_path / "out"
    assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 0
    cache = out / "results" / "opencv-camshift"
    kept = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in cache.glob("*.json")}
    assert set(kept) == {"s0.json", "s1.json", "s2.json"}
    capsys.readouterr()
    reason = _break(kind, ds / "s1")
    assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 0
    io = capsys.readouterr()
    assert "opencv-camshift on s1 failed" in io.err and reason in io.err and "1 of 3 sequences failed" in io.out
    rep = json.loads((out / "report.json").read_text())
    assert list(rep["failed"]) == ["s1"] and reason in rep["failed"]["s1"]["opencv-camshift"]
    assert set(rep["sequences"]) == {"s0", "s2"}
    md = (out / "report.md").read_text()
    assert "## Failed runs" in md and "| s1 | opencv-camshift |" in md
    # the other sequences' cached runs were reused, untouched
    for name in ("s0.json", "s2.json"):
        p = cache / name
        assert (p.read_bytes(), p.stat().st_mtime_ns) == kept[name]


def test_eval_exits_1_when_every_sequence_fails(tmp_path, capsys):
    ds = _dataset(tmp_path / "ds", 1)
    _break("corrupt-frame", ds / "s0")
    out = tmp_path / "out"
    assert cli.main(["eval", str(ds), "--out", str(out), *FAST]) == 1
    assert "## Failed runs" in (out / "report.md").read_text()


def test_failed_runs_are_not_cached(tmp_path):
    ds = _dataset(tmp_path / "ds", 1)
    img = ds / "s0" / "img" / "0003.jpg"
    good = img.read_bytes()
    img.write_bytes(b"garbage")
    ev = evaluate(load_dataset(ds), ["opencv-camshift"], tmp_path / "out", quiet=True)
    assert "s0" in ev.failed and not (tmp_path / "out" / "results" / "opencv-camshift" / "s0.json").exists()
    img.write_bytes(good)
    ev = evaluate(load_dataset(ds), ["opencv-camshift"], tmp_path / "out", quiet=True)
    assert not ev.failed and ev.sequences == ["s0"]
