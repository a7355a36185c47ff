"""The MOTChallenge-format reader (mstrack/io/mot.py): the two real sequences, a round trip of a
generated scene, and bad files, each refused with one line naming the file (as the OTB reader)."""
import json
from pathlib import Path

import numpy as np
import pytest

from mstrack import cli
from mstrack.io.data import DataError, DataWarning
from mstrack.io.mot import is_mot_dataset, is_mot_dir, load_mot_dataset, load_mot_sequence, parse_mot_gt
from mstrack.io.synthetic import make_multi_scene, write_mot_sequence

MOT_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "multi"


@pytest.fixture(scope="module")
def mot_dir(tmp_path_factory):
    frames, rows = make_multi_scene(6, 96, 80, n_targets=2, seed=1, spans=[(0, 6), (2, 5)])
    return write_mot_sequence(frames, rows, tmp_path_factory.mktemp("mot") / "syn", fps=10), rows


def test_real_sequences():
    if not MOT_ROOT.is_dir():
        pytest.skip(f"../shared/data/multi not found: {MOT_ROOT}")
    seqs = {s.name: s for s in load_mot_dataset(MOT_ROOT)}
    assert set(seqs) == {"TUD-Stadtmitte", "PETS09-S3MF1"}
    tud = seqs["TUD-Stadtmitte"]
    assert len(tud) == 179 and len(tud.tracks) == 10 and len(tud.rows) == 1156
    assert tud.frame(0).shape == (480, 640, 3)
    # gt.txt line 1: 1,1,88,99,61.08,218.56 (1-based) -> frame 0, box (87, 98, 61.08, 218.56)
    assert tud.boxes_at(0)[1] == (87.0, 98.0, 61.08, 218.56)
    assert tud.tracks[1].first == 0
    pets = seqs["PETS09-S3MF1"]
    assert len(pets) == 107 and len(pets.tracks) == 7 and len(pets.rows) == 620
    assert is_mot_dataset(MOT_ROOT) and is_mot_dir(MOT_ROOT / "PETS09-S3MF1")


def test_round_trip(mot_dir):
    d, rows = mot_dir
    s = load_mot_sequence(d)
    assert np.array_equal(s.rows, rows) and s.fps == 10 and s.name == "syn"
    assert {k: (t.first, t.last) for k, t in s.tracks.items()} == {1: (0, 5), 2: (2, 4)}
    assert [t.id for t in s.starting_at(2)] == [2]
    span = s.tracks[2].gt_span()
    assert span.shape == (3, 4) and np.isfinite(span).all()
    assert load_mot_dataset(d.parent)[0].name == "syn" and load_mot_dataset(d)[0].name == "syn"


def _copy(src: Path, dst: Path, gt: str | None = None, meta: str | None = None) -> Path:
    import shutil
    shutil.copytree(src, dst)
    if gt is not None:
        (dst / "gt.txt").write_text(gt)
    if meta is not None:
        (dst / "meta.json").write_text(meta)
    return dst


@pytest.mark.parametrize("gt, msg", [
    ("", "ground-truth file is empty"),
    ("1,1,10,10,20,20,1,-1,-1,-1\n1,x,3,4,5,6\n", "line 2: not numbers"),
    ("1,1,10,10,20\n", "line 1: expected frame,id,x,y,w,h[,...] (at least 6 values), got 5"),
    ("0,1,10,10,20,20\n", "line 1: frame must be a positive integer, got 0"),
    ("1.5,1,10,10,20,20\n", "line 1: frame must be a positive integer, got 1.5"),
    ("1,2.5,10,10,20,20\n", "line 1: id must be an integer, got 2.5"),
    ("1,1,10,10,0,20\n", "line 1: box width and height must be positive, got 0 x 20"),
    ("1,1,10,10,20,20\n1,1,11,10,20,20\n", "line 2: id 1 twice in frame 1 (also line 1)"),
    ("1,1,nan,10,20,20\n", "line 1: non-finite value"),
    ("1,1,10,10,20,20,0,-1,-1,-1\n", "ground-truth file has no box to evaluate"),
])
def test_bad_gt_files(mot_dir, tmp_path, gt, msg):
    d = _copy(mot_dir[0], tmp_path / "bad", gt=gt)
    with pytest.raises(DataError) as e:
        load_mot_sequence(d)
    assert msg in str(e.value) and str(e.value).endswith(str(d / "gt.txt")) and "\n" not in str(e.value)


@pytest.mark.parametrize("meta, msg", [
    ("{", "invalid meta.json"),
    ("[1]", "meta.json must be a JSON object, got list"),
    ('{"fps": -3}', "meta.json 'fps' must be a positive number, got -3"),
    ('{"name": "../x"}', "meta.json 'name' must be a plain name"),
    ('{"gt_coordinate_base": "one"}', "meta.json 'gt_coordinate_base' must be a number"),
])
def test_bad_meta(mot_dir, tmp_path, meta, msg):
    d = _copy(mot_dir[0], tmp_path / "bad", meta=meta)
    with pytest.raises(DataError) as e:
        load_mot_sequence(d)
    assert msg in str(e.value) and str(e.value).endswith(str(d / "meta.json"))


def test_gt_beyond_images_and_missing_parts(mot_dir, tmp_path):
    d = _copy(mot_dir[0], tmp_path / "long", gt="1,1,10,10,20,20\n9,1,10,10,20,20\n")
    with pytest.warns(DataWarning, match="ground truth up to frame 9 but 6 images"):
        s = load_mot_sequence(d)
    assert len(s.rows) == 1
    with pytest.raises(DataError, match="ground truth up to frame 9 but 6 images"):
        load_mot_sequence(d, strict=True)
    with pytest.raises(DataError, match="sequence folder not found"):
        load_mot_sequence(tmp_path / "nothing")
    (tmp_path / "nogt").mkdir()
    with pytest.raises(DataError, match=r"no ground truth \(gt.txt\)"):
        load_mot_sequence(tmp_path / "nogt")
    e = _copy(mot_dir[0], tmp_path / "noimg")
    for f in (e / "img").iterdir():
        f.unlink()
    with pytest.raises(DataError, match="no images"):
        load_mot_sequence(e)
    with pytest.raises(DataError, match="no MOT sequence named zzz; the sequences are: long"):
        load_mot_dataset(tmp_path, ["zzz"])
    with pytest.raises(DataError, match="ground-truth file not found"):
        parse_mot_gt(tmp_path / "gt.txt")


def test_bad_gt_is_one_cli_line(mot_dir, tmp_path, capsys):
    d = _copy(mot_dir[0], tmp_path / "seq", gt="1,1,10,10,20\n")
    assert cli.main(["eval", str(d), "--out", str(tmp_path / "o"), "--trackers", "opencv-camshift", "--quiet"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("mstrack eval: error: line 1: expected frame,id,x,y,w,h") and len(err.splitlines()) == 1


def test_meta_round_trip_fields(mot_dir):
    meta = json.loads((mot_dir[0] / "meta.json").read_text())
    assert meta["format"] == "mot" and meta["targets"] == 2 and meta["frames"] == 6
