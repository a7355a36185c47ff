"""``mstrack explore`` (mstrack/explore.py): grid parsing, the resource estimate, the Pareto front and
an end-to-end run on two tiny synthetic sequences (``--jobs 2`` gives the numbers of ``--jobs 1``)."""
import csv
import importlib.util
import json

import pytest

from mstrack import cli
from mstrack.explore import (ERROR_BOUND, MEASURED, GridError, check_table, dp16kd_tiles, estimate, make_points,
                             pareto_front, parse_grid)
from mstrack.fixed.formats import FixedParams
from mstrack.track.params import TrackerParams
from mstrack.io.synthetic import make_scene, write_otb_sequence


# ----------------------------------------------------------------------------- grid
def test_grid_parsing():
    g = parse_grid("bins=4,8,16; wf=2,4 ;lanes=2,4;kernel=flat,Epan;preset=v2")
    assert g == {"bins": [2, 3, 4], "wf": [2, 4], "lanes": [2, 4], "kernel": ["flat", "epanechnikov"],
                 "preset": ["v2"]}
    assert parse_grid("edge_bins=16,32")["edge_bins"] == [4, 5]
    assert parse_grid("bins=8,8")["bins"] == [3]                     # duplicates dropped


@pytest.mark.parametrize("spec, words", [
    ("colours=8", ["unknown grid key 'colours'", "bins", "lanes", "wf"]),
    ("bins=12", ["power of two"]),
    ("bins=512", ["colour_bits must be in 1..8"]),
    ("kernel=gauss", ["bad value 'gauss'", "flat", "epanechnikov"]),
    ("wf=x", ["wants integers"]),
    ("wf=20", ["weight format out of range"]),
    ("lanes=3", ["power of two"]),
    ("bins", ["KEY=V1,V2", "valid keys"]),
    ("", ["empty grid"]),
    ("bins=8;bins=16", ["given twice"]),
])
def test_grid_errors(spec, words):
    with pytest.raises(GridError) as ei:
        parse_grid(spec)
    msg = str(ei.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_grid_error_is_one_cli_line(tmp_path, capsys):
    assert cli.main(["explore", str(tmp_path), "--grid", "foo=1", "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("mstrack explore: error: unknown grid key 'foo'")
    assert "bins" in err and "lanes" in err


def test_points_share_runs_across_lanes():
    pts = make_points(["mstrack-fused-flat", "mstrack-v2"], parse_grid("bins=4,8;lanes=2,4"))
    assert len(pts) == 8
    assert len({p.run_name for p in pts}) == 4                       # LANES does not change results
    default = [p for p in pts if p.tracker == "mstrack-fused-flat" and dict(p.grid) == {"bins": 3, "lanes": 4}]
    assert default[0].run_name == "mstrack-fused-flat"               # the defaults: eval's own cache label
    v2 = [p for p in pts if p.tracker == "mstrack-v2"]
    assert all(p.params()[0].features == "colour" for p in v2)
    with pytest.raises(GridError, match="fixed-point widths"):
        make_points(["mstrack-fused-flat"], parse_grid("wf=2"), model="float")


# ----------------------------------------------------------------------------- estimate
def test_dp16kd_tiles():
    assert dp16kd_tiles(512, 56) == (2, 0)         # 512 x 36 + 512 x 36
    assert dp16kd_tiles(9168, 9) == (5, 0)         # 2048 x 9
    assert dp16kd_tiles(9168, 4) == (3, 0)         # 4096 x 4
    assert dp16kd_tiles(16, 56) == (0, 14)         # distributed RAM
    assert dp16kd_tiles(512, 14) == (1, 0)
    # the mappings seen in measured netlists (distributed RAM when cheaper at yosys' costs)
    assert dp16kd_tiles(64, 56) == (2, 0)          # histogram bank, 64 colour bins
    assert dp16kd_tiles(64, 14)[0] == 0            # model Q, 64 bins
    assert dp16kd_tiles(64, 6) == (0, 8)           # XR table
    assert dp16kd_tiles(512, 1) == (1, 0)          # v2 T table


@pytest.mark.parametrize("field, values", [("colour_bits", [1, 2, 3, 4, 5]), ("edge_bins_log2", [3, 4, 5, 6, 7])])
def test_more_bins_more_ram(field, values):
    est = [estimate(TrackerParams(**{field: v}), FixedParams()) for v in values]
    for a, b in zip(est, est[1:]):
        assert b.ram_bits > a.ram_bits
        assert b.dp16kd + b.dpr16x4 / 32 >= a.dp16kd + a.dpr16x4 / 32
        assert b.lut4 >= a.lut4
    assert est[-1].dp16kd > est[0].dp16kd


def test_monotone_in_lanes_and_widths():
    lanes = [estimate(TrackerParams(), FixedParams(), n) for n in (1, 2, 4, 8)]
    for a, b in zip(lanes, lanes[1:]):
        assert b.lut4 > a.lut4 and b.ff > a.ff and b.dp16kd >= a.dp16kd and b.ram_bits >= a.ram_bits
    wf = [estimate(TrackerParams(), FixedParams(weight_frac=w)) for w in (2, 4, 6, 8)]
    for a, b in zip(wf, wf[1:]):
        assert b.lut4 > a.lut4 and b.ff > a.ff
    mh = [estimate(TrackerParams(), FixedParams(max_half=h)) for h in (15, 31, 63, 127)]
    for a, b in zip(mh, mh[1:]):
        assert b.ram_bits > a.ram_bits and b.dp16kd >= a.dp16kd
    assert estimate(TrackerParams(kernel="epanechnikov"), FixedParams()).ram_bits > estimate(
        TrackerParams(), FixedParams()).ram_bits


def test_estimate_matches_measured_within_stated_error():
    rows = check_table()
    assert len(rows) >= len(MEASURED)
    held_out = [r for r in rows if not r["calibration"]]
    assert held_out, "no measured value tests the estimate"
    for r in rows:
        bound = ERROR_BOUND[r["quantity"]]
        assert abs(r["error"]) <= bound + 1e-9, r
    # the calibration points are reproduced (the default core exactly)
    core = {r["quantity"]: r for r in rows if r["config"] == "default core"}
    assert all(r["estimate"] == r["measured"] for r in core.values())


# ----------------------------------------------------------------------------- Pareto
def test_pareto_front_hand_made():
    pts = [(100, 0.50), (200, 0.60), (150, 0.55), (150, 0.50), (300, 0.58), (100, 0.40), (200, 0.60),
           (50, float("nan")), (400, 0.61)]
    assert pareto_front(pts) == [True, True, True, False, False, False, True, False, True]
    assert pareto_front([]) == []
    assert pareto_front([(1, 0.1)]) == [True]


# ----------------------------------------------------------------------------- end to end
@pytest.fixture(scope="module")
def tiny_dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    for i in range(2):
        frames, gt = make_scene(12 + 4 * i, 160, 120, seed=30 + i)
        write_otb_sequence(frames, gt, root / f"seq{i}")
    return root


GRID = "bins=4,8;wf=2,4;lanes=2,4"


def _table(out):
    rows = list(csv.DictReader((out / "explore.csv").open()))
    return [{k: v for k, v in r.items()} for r in rows]


def test_end_to_end_jobs(tiny_dataset, tmp_path):
    outs = {}
    for jobs in (1, 2):
        out = tmp_path / f"j{jobs}"
        assert cli.main(["explore", str(tiny_dataset), "--grid", GRID, "--trackers", "mstrack-fused-flat,mstrack-v2",
                         "--out", str(out), "--quiet", "--jobs", str(jobs)]) == 0
        outs[jobs] = out
    t1, t2 = _table(outs[1]), _table(outs[2])
    assert len(t1) == 2 * 2 * 2 * 2                               # one row per point
    assert len({r["point"] for r in t1}) == len(t1)
    assert t1 == t2                                               # --jobs 2: the same numbers
    assert (outs[1] / "explore_pareto.png").stat().st_size > 1000
    assert (outs[1] / "explore.md").read_text().count("\n| ") == len(t1) + 1
    j = json.loads((outs[1] / "explore.json").read_text())
    assert len(j["rows"]) == len(t1) and "matplotlib" in j["tools"]
    for r in t1:
        assert 0.0 <= float(r["auc"]) <= 1.0
        if r["tracker"] == "mstrack-v2":          # loss flag: v2 only ("nan" when no frame is off target)
            assert r["loss_recall"] != "" and r["false_alarms"] != ""
            assert float(r["false_alarms"]) != float(r["false_alarms"]) or 0 <= float(r["false_alarms"]) <= 1
        else:
            assert r["loss_recall"] == "" and r["false_alarms"] == ""
    # LANES changes the cost, not the accuracy
    by = {}
    for r in t1:
        by.setdefault(r["point"].rsplit(" lanes=", 1)[0], []).append(r)
    for pair in by.values():
        assert len(pair) == 2 and pair[0]["auc"] == pair[1]["auc"] and pair[0]["lut4"] != pair[1]["lut4"]
    # at least one point on each front; a dominated point is not
    assert any(r["pareto_lut"] == "True" for r in t1) and any(r["pareto_dp16kd"] == "True" for r in t1)
    runs = sorted(p.parent.name for p in (outs[1] / "results").rglob("*.json"))
    assert len(runs) == 2 * 8                                     # cached per (accuracy run, sequence)
    # a budget no point meets: every point marked, no front (the runs come from the cache)
    before = {p: p.stat().st_mtime_ns for p in (outs[1] / "results").rglob("*.json")}
    assert cli.main(["explore", str(tiny_dataset), "--grid", GRID, "--trackers", "mstrack-fused-flat,mstrack-v2",
                     "--out", str(outs[1]), "--quiet", "--budget", "1000", "--no-plot"]) == 0
    assert {p: p.stat().st_mtime_ns for p in (outs[1] / "results").rglob("*.json")} == before
    t3 = _table(outs[1])
    assert all(r["fits"] == "False" and r["pareto_lut"] == "False" for r in t3)
    assert [r["auc"] for r in t3] == [r["auc"] for r in t1]


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="Dask distributed not installed (extra 'dist')")
def test_dask_local_cluster_same_table(tiny_dataset, tmp_path):
    """The point factory travels to Dask workers; the table is the one of one process."""
    outs = []
    for extra in ([], ["--scheduler", "--jobs", "2"]):
        out = tmp_path / ("dask" if extra else "one")
        assert cli.main(["explore", str(tiny_dataset), "--grid", "bins=4,8;lanes=2", "--out", str(out), "--quiet",
                         "--no-plot", *extra]) == 0
        outs.append(_table(out))
    assert len(outs[0]) == 2 and outs[0] == outs[1]
