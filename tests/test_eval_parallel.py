"""``mstrack eval --jobs N`` and ``--scheduler`` (Dask): the same results as one process.

Two tiny synthetic sequences (15 and 20 frames, 160x120), a fast mstrack tracker and an OpenCV one.
Everything a run produces is compared (boxes, status, confidence in results/*.json; every score
and curve in report.json), except the timings (fps, update time), which depend on the machine.
"""
import importlib.util
import json

import pytest

from mstrack import cli
from mstrack.io.data import load_dataset
from mstrack.eval.evaluate import evaluate
from mstrack.io.synthetic import make_scene, write_otb_sequence

TRACKERS = "mstrack-v2,mstrack-colour-flat,opencv-camshift"
HAVE_DASK = importlib.util.find_spec("distributed") is not None
TIMING = {"fps", "update_time_s"}


@pytest.fixture(scope="module")
def tiny_dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    for i in range(2):
        frames, gt = make_scene(15 + 5 * i, 160, 120, seed=20 + i)
        write_otb_sequence(frames, gt, root / f"seq{i}", attributes=["SV"])
    return root


def _strip(obj):
    """``obj`` without its timing fields (fps, update time) and the command line."""
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in TIMING and k != "command"}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _outputs(out):
    runs = {str(p.relative_to(out)): _strip(json.loads(p.read_text())) for p in sorted((out / "results").rglob("*.json"))}
    return _strip(json.loads((out / "report.json").read_text())), runs


@pytest.fixture(scope="module")
def one_process(tiny_dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("one")
    assert cli.main(["eval", str(tiny_dataset), "--trackers", TRACKERS, "--out", str(out), "--quiet"]) == 0
    return _outputs(out)


def test_jobs_same_results_as_one_process(tiny_dataset, one_process, tmp_path):
    out = tmp_path / "two"
    assert cli.main(["eval", str(tiny_dataset), "--trackers", TRACKERS, "--out", str(out), "--quiet",
                     "--jobs", "2"]) == 0
    report, runs = _outputs(out)
    assert len(runs) == 6 and runs == one_process[1]
    assert report == one_process[0]


def test_jobs_reuses_and_fills_the_cache(tiny_dataset, tmp_path):
    seqs = load_dataset(tiny_dataset)
    evaluate(seqs, ["opencv-camshift"], tmp_path, quiet=True)
    cached = tmp_path / "results" / "opencv-camshift" / "seq0.json"
    t0 = cached.stat().st_mtime_ns
    ev = evaluate(seqs, ["opencv-camshift", "opencv-meanshift"], tmp_path, quiet=True, jobs=2)
    assert cached.stat().st_mtime_ns == t0                                    # reused, not rerun
    assert (tmp_path / "results" / "opencv-meanshift" / "seq1.json").is_file()  # written as it came back
    assert list(ev.runs) == ["opencv-camshift", "opencv-meanshift"]
    assert [list(r) for r in ev.runs.values()] == [["seq0", "seq1"]] * 2         # job order, not finish order


def test_jobs_validated(tiny_dataset, tmp_path, capsys):
    with pytest.raises(ValueError, match="jobs"):
        evaluate(load_dataset(tiny_dataset), ["opencv-camshift"], tmp_path, jobs=0)
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["eval", "x", "--jobs", "0"])


@pytest.mark.skipif(not HAVE_DASK, reason="dask[distributed] not installed (tools/setup.sh installs it)")
def test_dask_local_cluster_same_results(tiny_dataset, one_process, tmp_path):
    out = tmp_path / "dask"
    assert cli.main(["eval", str(tiny_dataset), "--trackers", TRACKERS, "--out", str(out), "--quiet",
                     "--jobs", "2", "--scheduler"]) == 0
    report, runs = _outputs(out)
    assert runs == one_process[1] and report == one_process[0]
