"""The multi-target core's cost model (mstrack/hw/multi_core.py, ``mstrack explore --multi``,
docs/multi_target_core.md): N = 1 is core v2 as synthesised, the model grows with N, the memory
tiling equals yosys on the blocks synthesised, and the doc's tables are the generator's."""
from __future__ import annotations

import pytest

from mstrack import cli
from mstrack.fixed.formats import FixedParams
from mstrack.hw import multi_core as mc
from mstrack.hw.multi_core import CORE_V2, TABLE_CONFIGS, MultiCoreParams, multi_cost


@pytest.mark.parametrize("joint", [True, False])
def test_one_target_is_core_v2(joint):
    """N = 1 with the default max_window is the measured core v2 (DP16KD, LUT4, FF, MULT18X18D)."""
    c = multi_cost(1, MultiCoreParams(joint=joint))
    base = CORE_V2["joint" if joint else "colour"]
    assert (c.dp16kd_total, c.lut4, c.ff, c.mult18, c.comb) == (base["DP16KD"], base["LUT4"], base["FF"],
                                                                base["MULT18X18D"], base["comb"])
    assert c.dp16kd["pool"] == base["region"] and c.dp16kd["models"] == base["model"]


def test_slot_is_core_v2s_region():
    """The default slot is core v2's lost-state region bound (mstrack.hw.cosim.region_max_v2) and fits
    its REGION_MAX 256 x STRIDE 64 words; max_window 63 needs 159 rows."""
    from mstrack.hw.cosim import region_max_v2
    from mstrack.track.params import TrackerParams
    assert mc.slot_shape(MultiCoreParams()) == (255, 255)
    assert region_max_v2(TrackerParams(preset="v2"), FixedParams(), 2048) == 255
    assert mc.slot_words(MultiCoreParams()) <= mc.CORE_V2_REGION_WORDS
    assert mc.slot_shape(MultiCoreParams(max_window=63)) == (159, 159)
    assert mc.slot_shape(MultiCoreParams(max_window=31)) == (111, 118)   # columns: lost at D = 16


@pytest.mark.parametrize("mp", TABLE_CONFIGS, ids=lambda m: m.name)
def test_cost_grows_with_n(mp):
    costs = [multi_cost(n, mp) for n in range(1, 17)]
    for a, b in zip(costs, costs[1:]):
        assert b.dp16kd_total >= a.dp16kd_total and b.lut4 > a.lut4 and b.ff > a.ff and b.comb > a.comb
        assert b.dp16kd["pool"] >= a.dp16kd["pool"] and b.dp16kd["models"] >= a.dp16kd["models"]
    assert len({c.worst for c in costs}) == 1                       # one target's job does not depend on N
    # N slots in one pool never take more blocks than N pools of one slot
    assert all(c.dp16kd["pool"] <= c.n * costs[0].dp16kd["pool"] for c in costs)
    fits = [c.fits_85f for c in costs]
    assert fits == sorted(fits, reverse=True)                        # once it does not fit, never again


def test_what_fits_the_85f():
    assert [mc.max_fit(mp) for mp in TABLE_CONFIGS] == [2, 4, 5, 14]


def test_memory_tiling_equals_yosys():
    """Every block of :data:`YOSYS_BLOCKS`: DP16KD exactly as predicted, LUT4 / FF within the fit's
    stated bounds; the fit is the least-squares line of those measurements."""
    import numpy as np
    pts = {name: (e, g) for name, e, g in mc.check_points()}
    assert set(pts) == set(mc.YOSYS_BLOCKS)
    xs, luts, ffs = [], [], []
    for name, meas in mc.YOSYS_BLOCKS.items():
        entity, g = pts[name]
        p = mc.predicted_block(entity, g)
        assert p["DP16KD"] == meas["DP16KD"], name
        if entity == "ms_region_ram":
            assert abs(p["LUT4"] - meas["LUT4"]) <= 750 and abs(p["FF"] - meas["FF"]) <= 70, (name, p, meas)
            xs.append(g["LANES"] * (mc.pool_rows(g["DEPTH"], g["DATA_W"]) - 1) * g["DATA_W"])
            luts.append(meas["LUT4"])
            ffs.append(meas["FF"])
    a = np.vstack([np.ones(len(xs)), np.array(xs, float)]).T
    for coef, ys in ((mc.POOL_LUT4, luts), (mc.POOL_FF, ffs)):
        fit = np.linalg.lstsq(a, np.array(ys, float), rcond=None)[0]
        assert fit == pytest.approx(coef, rel=0.01, abs=1.0)


def test_per_target_against_vitis_is_in_the_table():
    """What docs/multi_target_core.md says: per target (N = 16 less N = 1, over 15; xc7 estimate) the
    joint core with slots of max_window 63 needs fewer LUT and FF than Vitis' per-object share and
    more block RAM."""
    a, b = multi_cost(1, TABLE_CONFIGS[1]).xc7(), multi_cost(16, TABLE_CONFIGS[1]).xc7()
    per = {k: (b[k] - a[k]) / 15 for k in a}
    v = {k: mc.VITIS[k] / mc.VITIS["targets"] for k in ("LUT", "FF", "BRAM36")}
    assert per["LUT"] < v["LUT"] and per["FF"] < v["FF"] and per["BRAM36"] > v["BRAM36"], (per, v)
    assert "Vitis Vision MeanShift" in mc.vitis_table()


def test_bad_n():
    with pytest.raises(ValueError, match="1..16"):
        multi_cost(17)


def test_doc_tables_are_current():
    text = mc.DOC.read_text()
    assert mc.render_doc(text) == text, "stale: run mstrack explore --multi --write"


def test_cli_explore_multi(capsys):
    assert cli.main(["explore", "--multi", "--targets", "1,3"]) == 0
    out = capsys.readouterr().out
    assert "| 3 |" in out and "LFE5U-85F" in out and "| 4 |" not in out.split("Per target")[0].split("Resources")[1]
    assert cli.main(["explore", "--multi", "--targets", "0,17"]) == 1
    assert "--targets wants comma-separated integers in 1..16" in capsys.readouterr().err
    assert cli.main(["explore", "--write"]) == 1
    assert "go with --multi" in capsys.readouterr().err
