"""Test vectors (mstrack/hw/vectors.py): reproducible files that match a rerun of the model."""
from __future__ import annotations

import gzip
import json

import numpy as np
import pytest

from mstrack import Tracker
from mstrack.fixed import FixedParams, FixedTracker
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.track.params import TrackerParams
from mstrack.io.synthetic import make_scene, write_otb_sequence
from mstrack.hw.vectors import FORMAT, VERSION, dump_vectors, load_vectors, main

FRAMES = [0, 1, 5]


@pytest.fixture(scope="module")
def seq_dir(tmp_path_factory):
    frames, gt = make_scene(n_frames=7, width=128, height=96, seed=3, target_size=(25, 20))
    return write_otb_sequence(frames, gt, tmp_path_factory.mktemp("seq") / "synth")


@pytest.mark.parametrize("params", [{}, {"kernel": "epanechnikov", "weight_frac": 6}])
def test_byte_identical(seq_dir, tmp_path, params):
    a = dump_vectors(seq_dir, FRAMES, tmp_path / "a.jsonl.gz", **params)
    b = dump_vectors(seq_dir, FRAMES, tmp_path / "b.jsonl.gz", **params)
    assert a.read_bytes() == b.read_bytes()
    raw = a.read_bytes()
    assert raw[:2] == b"\x1f\x8b" and raw[4:8] == b"\0\0\0\0"      # gzip, mtime 0
    for line in gzip.decompress(raw).decode().splitlines():
        d = json.loads(line)
        assert line == json.dumps(d, sort_keys=True, separators=(",", ":"))


def test_header(seq_dir, tmp_path):
    out = dump_vectors(seq_dir, [5, 0, 1, 1], tmp_path / "v.jsonl.gz", weight_frac=6, features="colour")
    head, recs = load_vectors(out)
    assert head["format"] == FORMAT and head["version"] == VERSION
    assert head["frames"] == FRAMES and [r["frame"] for r in recs] == FRAMES
    tp, fp = TrackerParams(features="colour"), FixedParams(weight_frac=6)
    assert head["generics"] == core_generics(tp, fp)
    assert head["params"]["fixed"]["weight_frac"] == 6 and head["params"]["tracker"]["features"] == "colour"
    assert head["frame_size"] == [128, 96]
    assert [r["kind"] for r in recs] == ["init", "update", "update"]


def test_reload_equals_rerun(seq_dir, tmp_path):
    """Every number in the file equals a fresh run of the model with trace=True."""
    from mstrack.io.data import load_sequence

    out = dump_vectors(seq_dir, FRAMES, tmp_path / "v.jsonl.gz")
    head, recs = load_vectors(out)
    seq = load_sequence(seq_dir)
    trk = FixedTracker()
    trk.init_int(seq.frame(0), *head["init_box"], trace=True)
    want = {0: json.loads(json.dumps(trk.last_trace))}
    for i in range(1, max(FRAMES) + 1):
        trk.update(seq.frame(i), trace=True)
        want[i] = json.loads(json.dumps(trk.last_trace))
    for r in recs:
        assert r["trace"] == want[r["frame"]], r["frame"]


def test_trace_contents_consistent(seq_dir, tmp_path):
    """The intermediates are self-consistent: sums from the per-bin values, result from the iterations."""
    from mstrack.io.data import load_sequence

    head, recs = load_vectors(dump_vectors(seq_dir, FRAMES, tmp_path / "v.jsonl.gz"))
    init = recs[0]["trace"]
    x, y, w, h = init["region"]
    assert np.asarray(init["colour_bins"]).shape == (h, w) == np.asarray(init["edge_bins"]).shape
    K = init["result"]["K"]
    assert sum(init["Q_c"]) == sum(init["Q_e"]) == K          # flat kernel: Q = pixel counts
    for r in recs[1:]:
        t = r["trace"]
        for feat in ("iter_colour", "iter_edge"):
            its = t[feat]
            assert its, feat
            for it in its:
                wv, N, SX, SY = (np.asarray(it[k], dtype=np.int64) for k in ("w", "N", "SX", "SY"))
                assert it["Sw"] == int((wv * N).sum()) and it["Swx"] == int((wv * SX).sum())
                assert it["Swy"] == int((wv * SY).sum()) and sum(it["N"]) == K
                assert it["win"] == [(c + 128) >> 8 for c in it["centre"]]
        res = t["result"]
        assert res["centre_c"] in [it["centre"] for it in t["iter_colour"]]
        assert res["iter_c"] == len(t["iter_colour"]) - 1 or res["stop_c"] != 0
    # the Tracker API gives the same centre as the vectors
    seq = load_sequence(seq_dir)
    trk = Tracker(model="fixed", preset="paper")  # the vectors are the RTL core's (paper preset)
    trk.init(seq.frame(0), tuple(seq.gt[0]))
    for i in range(1, 6):
        res = trk.update(seq.frame(i))
    assert [res.extra["cx"], res.extra["cy"]] == [recs[-1]["trace"]["result"]["cx"], recs[-1]["trace"]["result"]["cy"]]


def test_cli(seq_dir, tmp_path, capsys):
    out = tmp_path / "cli.jsonl.gz"
    assert main([str(seq_dir), "--frames", "0,2", "--out", str(out), "--param", "rho_frac=4"]) == 0
    head, recs = load_vectors(out)
    assert head["params"]["fixed"]["rho_frac"] == 4 and [r["frame"] for r in recs] == [0, 2]


def test_errors(seq_dir, tmp_path):
    with pytest.raises(ValueError):
        dump_vectors(seq_dir, [0, 99], tmp_path / "x.gz")
    with pytest.raises(TypeError):
        dump_vectors(seq_dir, [0], tmp_path / "x.gz", no_such_param=1)
    bad = tmp_path / "bad.gz"
    with gzip.open(bad, "wt") as f:
        f.write('{"format": "other"}\n')
    with pytest.raises(ValueError):
        load_vectors(bad)


def test_cli_extension(seq_dir, tmp_path):
    """`mstrack vectors` and `mstrack agree` register through mstrack.cli's extension list."""
    cli = pytest.importorskip("mstrack.cli")
    parser = cli.build_parser(extensions=["mstrack.hw.vectors:register_cli", "mstrack.eval.agreement:register_cli"])
    out = tmp_path / "ext.jsonl.gz"
    args = parser.parse_args(["vectors", str(seq_dir), "--frames", "0,1,5", "--out", str(out)])
    assert args.func(args) == 0
    assert [r["frame"] for r in load_vectors(out)[1]] == FRAMES
    args = parser.parse_args(["agree", str(seq_dir.parent), "--max-frames", "3"])
    assert args.func(args) == 0
