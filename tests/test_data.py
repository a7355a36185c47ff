"""Sequence / video readers: coordinate bases, layouts, and errors."""
from pathlib import Path

import cv2
import numpy as np
import pytest

from mstrack.io.data import (DataError, DataWarning, VideoSource, load_dataset, load_sequence, normalise_attribute,
                          parse_gt)
from mstrack.io.synthetic import make_scene, write_otb_sequence, write_video

SEQ_DIR = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "sequences"


def _need_data():
    if not SEQ_DIR.is_dir():
        pytest.skip(f"../shared/data/sequences not found: {SEQ_DIR.resolve()}")


def _first_line(path: Path) -> np.ndarray:
    line = path.read_text().splitlines()[0]
    return np.array([float(v) for v in line.replace(",", " ").split()])


def test_otb_real_sequence_is_converted_to_0_based():
    _need_data()
    seq = load_sequence(SEQ_DIR / "Couple")
    raw = _first_line(SEQ_DIR / "Couple" / "groundtruth_rect.txt")   # 1-based: 51,47,25,62
    assert seq.gt[0] == pytest.approx(raw - [1, 1, 0, 0])
    assert len(seq) == len(seq.gt) == 140
    assert "BC" in seq.attributes
    f = seq.frame(0)
    assert f.dtype == np.uint8 and f.shape == (240, 320, 3)
    assert isinstance(seq.img_files[0], Path)            # frames are read lazily


def test_vot_real_sequence_keeps_0_based_and_grey_sequence_gives_bgr():
    _need_data()
    seq = load_sequence(SEQ_DIR / "bag_vot")
    assert seq.gt[0] == pytest.approx(_first_line(SEQ_DIR / "bag_vot" / "groundtruth_rect.txt"))
    assert seq.attributes[0] == "DEF"                    # "DEF (plastic bag)"
    assert load_sequence(SEQ_DIR / "Suv").frame(0).shape[2] == 3


def test_load_dataset_real():
    _need_data()
    seqs = load_dataset(SEQ_DIR)
    names = [s.name for s in seqs]
    assert names == sorted(names) and "Couple" in names and len(names) >= 2
    assert [s.name for s in load_dataset(SEQ_DIR, ["Deer", "Girl"])] == ["Deer", "Girl"]
    with pytest.raises(DataError):
        load_dataset(SEQ_DIR, ["NoSuchSequence"])


def _img(path: Path, value: int = 100) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), np.full((20, 30, 3), value, np.uint8))


def test_vot_polygon_folder_without_meta(tmp_path):
    d = tmp_path / "votseq"
    for i in range(1, 3):
        _img(d / f"{i:08d}.jpg")
    (d / "groundtruth.txt").write_text("1,2,11,2,11,7,1,7\n3.5,4,13.5,6,11.5,10,1.5,8\n")
    seq = load_sequence(d)
    assert seq.gt[0] == pytest.approx([1, 2, 10, 5])       # 0-based, no shift
    assert seq.gt[1] == pytest.approx([1.5, 4, 12, 6])     # axis-aligned min/max of the polygon


def test_otb_tab_separated_without_meta_is_1_based(tmp_path):
    d = tmp_path / "otbseq"
    for i in range(1, 4):
        _img(d / "img" / f"{i:04d}.jpg")
    (d / "groundtruth_rect.txt").write_text("5\t6\t7\t8\n5 6 7 8\nNaN,NaN,NaN,NaN\n")
    seq = load_sequence(d)
    assert seq.gt[0] == pytest.approx([4, 5, 7, 8]) and seq.gt[1] == pytest.approx([4, 5, 7, 8])
    assert np.isnan(seq.gt[2]).all()


def test_synthetic_round_trip(tmp_path):
    frames, gt = make_scene(3, 64, 48, seed=3)
    seq = load_sequence(write_otb_sequence(frames, gt, tmp_path / "syn", attributes=["SV"]))
    assert seq.gt == pytest.approx(gt)
    assert seq.attributes == ["SV"]


def test_missing_folder_and_no_images(tmp_path):
    with pytest.raises(DataError) as e:
        load_sequence(tmp_path / "nope")
    assert e.value.path == tmp_path / "nope"
    d = tmp_path / "empty"
    (d / "img").mkdir(parents=True)
    (d / "groundtruth_rect.txt").write_text("1,1,5,5\n")
    with pytest.raises(DataError, match="no images"):
        load_sequence(d)
    with pytest.raises(DataError):
        load_dataset(tmp_path / "nope")


def test_corrupt_image_raises_with_path(tmp_path):
    d = tmp_path / "seq"
    _img(d / "img" / "0001.jpg")
    bad = d / "img" / "0002.jpg"
    bad.write_bytes(b"\xff\xd8\xff\xe0 this is not a jpeg")
    (d / "groundtruth_rect.txt").write_text("1,1,5,5\n1,1,5,5\n")
    seq = load_sequence(d)
    assert seq.frame(0).shape == (20, 30, 3)
    with pytest.raises(DataError) as e:
        seq.frame(1)
    assert e.value.path == bad and "corrupt" in str(e.value)
    frames = list(VideoSource(d).frames(on_bad="none"))
    assert frames[1] is None and frames[0] is not None
    assert len(list(VideoSource(d).frames(on_bad="skip"))) == 1


def test_gt_count_mismatch_warns_and_truncates(tmp_path):
    d = tmp_path / "seq"
    for i in range(1, 4):
        _img(d / "img" / f"{i:04d}.jpg")
    (d / "groundtruth_rect.txt").write_text("1,1,5,5\n1,1,5,5\n")
    with pytest.warns(DataWarning, match="3 images but 2"):
        seq = load_sequence(d)
    assert len(seq) == 2 and len(seq.gt) == 2
    with pytest.raises(DataError, match="3 images but 2"):
        load_sequence(d, strict=True)


def test_bad_gt_line(tmp_path):
    p = tmp_path / "gt.txt"
    p.write_text("1,2,3\n")
    with pytest.raises(DataError, match="expected 4 or 8"):
        parse_gt(p)
    p.write_text("\n\n")
    with pytest.raises(DataError, match="empty"):
        parse_gt(p)


def test_empty_and_missing_video(tmp_path):
    empty = tmp_path / "empty.mp4"
    empty.write_bytes(b"")
    with pytest.raises(DataError) as e:
        VideoSource(empty)
    assert e.value.path == empty
    with pytest.raises(DataError):
        VideoSource(tmp_path / "missing.avi")


def test_video_source_reads_all_frames(tmp_path):
    frames, _ = make_scene(7, 64, 48, seed=0)
    vid = write_video(frames, tmp_path / "v.avi", fps=12)
    src = VideoSource(vid)
    got = list(src)
    assert src.kind == "video" and len(got) == 7
    assert got[0].shape == (48, 64, 3) and got[0].dtype == np.uint8
    assert src.fps == pytest.approx(12)


@pytest.mark.parametrize("raw, code", [("DEF (plastic bag)", "DEF"), ("background clutter", "BC"),
                                       ("OCC", "OCC"), ("sv", "SV"), ("camera motion", "camera"),
                                       ("FM (fast ball motion)", "FM")])
def test_normalise_attribute(raw, code):
    assert normalise_attribute(raw) == code
