"""mstrack.hw.hdl_config: user-level choices -> every generic of ms_tracker, refusals with one-line reasons.

The RTL side (the same relations asserted at elaboration) is tested with GHDL in
tb/test_ms_tracker_file_tb.py (test_config_elaborates / test_wrong_generic_refused).
"""
from __future__ import annotations

import json
import re

import pytest

from mstrack.cli import main
from mstrack.fixed import FixedParams
from mstrack.fixed.vhdl_pkg import core_generics
from mstrack.hw.cosim import CoreConfigV2
from mstrack.hw.hdl_config import (V2_GENERICS, ConfigError, CoreChoices, derive, entity_generics, generic_map,
                                   render)
from mstrack.track.params import TrackerParams


def test_default_choices_give_the_default_generics():
    cfg = derive(CoreChoices())
    assert cfg.generics == {"PRESET": 0, "MAX_FRAME_W": 2048, "RGB_PACKING": 0, "PPC": 1, **core_generics()}


def test_preset_v2_gives_core_v2_generics():
    """Preset v2: PRESET 1 and CoreConfigV2's generics for ms_tracker (the ones the core v2 tests run),
    colour only by default, result word v2 of 160 bits."""
    cfg = derive(CoreChoices(preset="v2"))
    want = CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).tracker_generics()
    assert cfg.tp.preset == "v2" and cfg.tp.features == "colour"
    assert {k: cfg.generics[k] for k in want} == want
    assert cfg.generics["PRESET"] == 1 and cfg.generics["RESULT_W"] == 160 and cfg.generics["PPC"] == 1
    assert cfg.generics["FEATURES"] == 1 and cfg.generics["REGION_MAX"] == 256
    g = derive(CoreChoices(preset="v2", max_frame_width=1920, lanes=2, rgb_packing="ug934")).generics
    assert {k: g[k] for k in want} == CoreConfigV2(TrackerParams(preset="v2"), FixedParams(), 2, 1920).tracker_generics()
    assert g["RGB_PACKING"] == 1


def test_scale_test_choice():
    """Preset v2's gated scale test reaches SCALE_TEST_D256 (round(256 x), the generics of CoreConfigV2
    with scale_test + gate, the header says so); left out it is the tracker's (mstrack-v2 0.05 -> 13, the
    VHDL default; --colour 0); 0 turns it off; the paper preset, a step that rounds to 0 and one above
    0.5 are refused with the reason."""
    cfg = derive(CoreChoices(preset="v2", scale_test=0.1))
    tp = TrackerParams(preset="v2", scale_test=0.1, scale_test_gate=True)
    assert cfg.tp == tp and cfg.generics["SCALE_TEST_D256"] == 26
    assert {k: cfg.generics[k] for k in CoreConfigV2(tp, FixedParams()).tracker_generics()} == \
        CoreConfigV2(tp, FixedParams()).tracker_generics()
    assert derive(CoreChoices(preset="v2")).generics["SCALE_TEST_D256"] == 13
    assert derive(CoreChoices(preset="v2", colour=True)).generics["SCALE_TEST_D256"] == 0
    assert derive(CoreChoices(preset="v2", colour=True, scale_test=0.05)).generics["SCALE_TEST_D256"] == 13
    off = derive(CoreChoices(preset="v2", scale_test=0.0))
    assert off.generics["SCALE_TEST_D256"] == 0 and off.tp.scale_test == 0.0 and off.generics["ORIENT_T"] == 64
    assert "SCALE_TEST_D256 26)" in render(cfg, "package")
    for bad, why in ((dict(scale_test=0.05), "core v2's"), (dict(preset="v2", scale_test=0.001), "d256 = 0"),
                     (dict(preset="v2", scale_test=0.7), "up to 0.5")):
        with pytest.raises(ConfigError, match=why):
            derive(CoreChoices(**bad))
    assert "SCALE_TEST_D256" not in derive(CoreChoices()).generics


def test_colour_choice():
    """Preset v2 builds the default tracker mstrack-v2 (the joint bins: ORIENT_T 64, SCALE_TEST_D256 13);
    --colour builds mstrack-v2-colour: TrackerParams(preset="v2", **V2_COLOUR), ORIENT_T -1 (rendered as
    an integer constant) and SCALE_TEST_D256 0 (CoreConfigV2's generics); the header names the tracker;
    --colour with the paper preset is refused with the reason."""
    from mstrack.track.params import V2_COLOUR, V2_JOINT
    joint = derive(CoreChoices(preset="v2"))
    assert joint.tp == TrackerParams(preset="v2", **V2_JOINT, max_window=joint.tp.max_window)
    assert joint.generics["ORIENT_T"] == 64 and joint.generics["SCALE_TEST_D256"] == 13
    cfg = derive(CoreChoices(preset="v2", colour=True))
    tp = TrackerParams(preset="v2", **V2_COLOUR)
    assert cfg.tp == tp and cfg.generics["ORIENT_T"] == -1 and cfg.generics["SCALE_TEST_D256"] == 0
    want = CoreConfigV2(tp, FixedParams()).tracker_generics()
    assert {k: cfg.generics[k] for k in want} == want
    text = render(cfg, "package")
    assert "tracker mstrack-v2-colour (ORIENT_T -1" in text
    assert re.search(r"constant C_ORIENT_T +: integer := -1;", text)
    assert re.search(r"constant C_ORIENT_T +: integer := 64;", render(joint, "package"))
    assert "tracker mstrack-v2 (ORIENT_T 64, SCALE_TEST_D256 13)" in render(joint, "package")
    with pytest.raises(ConfigError, match="core v2 tracker"):
        derive(CoreChoices(colour=True))


def test_ppc_choice():
    """PPC 1, 2, 4 (<= LANES) reaches the generic; other values and PPC > LANES are refused."""
    assert derive(CoreChoices(ppc=4)).generics["PPC"] == 4
    for bad in (dict(ppc=3), dict(ppc=8, lanes=8), dict(ppc=4, lanes=2)):
        with pytest.raises(ConfigError, match="PPC"):
            derive(CoreChoices(**bad))


def test_every_entity_generic_is_configured():
    """The configuration sets every generic of ms_tracker, in declaration order: preset v2 all of them,
    the paper preset all but core v2's own."""
    assert list(derive(CoreChoices(preset="v2")).generics) == entity_generics()
    assert list(derive(CoreChoices()).generics) == [k for k in entity_generics() if k not in V2_GENERICS]
    assert set(V2_GENERICS) <= set(entity_generics())


@pytest.mark.parametrize("choices,tp,fp,lanes", [
    (dict(max_target=63, margin=16), {}, dict(max_half=31, margin=16), 4),
    (dict(max_target=64), {}, dict(max_half=32), 4),              # even: MAX_HALF = 32, windows up to 65 px
    (dict(kernel="epanechnikov", lanes=2, features="colour"), dict(kernel="epanechnikov", features="colour"), {}, 2),
    (dict(max_frame_width=8000, coord_bits=13, max_target=511), {}, dict(max_half=255, coord_bits=13), 4),
    (dict(lanes=1, max_target=3, margin=0), {}, dict(max_half=1, margin=0), 1),
])
def test_choices_map_to_model_parameters(choices, tp, fp, lanes):
    cfg = derive(CoreChoices(**choices))
    want = core_generics(TrackerParams(**tp), FixedParams(**fp), lanes)
    assert {k: cfg.generics[k] for k in want} == want
    assert cfg.generics["MAX_FRAME_W"] == choices.get("max_frame_width", 2048)


@pytest.mark.parametrize("choices,reason", [
    (dict(preset="v3"), "preset 'v3' unknown"),
    (dict(preset="v2", features="fused"), "preset v2 tracks colour only"),
    (dict(preset="v2", kernel="epanechnikov"), "preset v2 has the flat kernel only"),
    (dict(preset="v2", ppc=2), "core v2 (preset v2) takes one pixel per clock"),
    (dict(preset="v2", max_target=255), "core v2 windows are 7 .. 127 decimated px"),
    (dict(preset="v2", max_target=5), "core v2 windows are 7 .. 127 decimated px"),
    (dict(preset="v2", coord_bits=13, max_frame_width=5000), "core v2 is built for COORD_W 12"),
    (dict(lanes=3), "LANES 3 is not a power of two"),
    (dict(lanes=0), "LANES 0 is not a power of two"),
    (dict(lanes=256, max_target=63, margin=16), "LANES 256 > the region width 95 px"),
    (dict(max_target=600), "largest target 600 px > 511 px, the largest window the kernel tables hold"),
    (dict(max_target=2), "at least 3x3"),
    (dict(max_frame_width=5000), "max frame width 5000 px does not fit COORD_W = 12 bits (at most 4095 px); "
                                 "use --coord-bits 13"),
    (dict(max_frame_width=4096), "does not fit COORD_W = 12 bits"),
    (dict(max_frame_width=2), "at least 3 px wide"),
    (dict(coord_bits=15), "COORD_W 15 out of 8..14"),
    (dict(margin=300), "margin 300 px out of 0..255"),
    (dict(features="depth"), "features 'depth' unknown"),
    (dict(kernel="gauss"), "kernel 'gauss' unknown"),
    (dict(rgb_packing="bgr"), "rgb packing 'bgr' unknown"),
    (dict(top="ms_tracker_apb"), "top 'ms_tracker_apb' unknown"),
    (dict(preset="v2", max_targets=4), "ms_tracker_axi's (--top ms_tracker_axi)"),
    (dict(preset="v2", result_stream=False), "ms_tracker_axi's (--top ms_tracker_axi)"),
    (dict(top="ms_tracker_axi", max_targets=4), "the multi-target core is core v2 (--preset v2)"),
    (dict(top="ms_tracker_axi", preset="v2", max_targets=17), "17 targets: the multi-target core has 1 .. 16 slots"),
    (dict(top="ms_tracker_axi", preset="v2", shared_engine=True), "give --max-targets 1 .. 16"),
    (dict(top="ms_tracker_axi", preset="v2", max_targets=8, shared_engine=True, timing="1080i50"),
     "video timing '1080i50' unknown"),
    (dict(top="ms_tracker_axi", preset="v2", max_targets=8, coord_bits=11, max_frame_width=1920),
     "core v2 is built for COORD_W 12"),
])
def test_impossible_choices_refused(choices, reason):
    with pytest.raises(ConfigError) as e:
        derive(CoreChoices(**choices))
    msg = str(e.value)
    assert reason in msg
    assert "\n" not in msg


def test_package_text():
    cfg = derive(CoreChoices(max_frame_width=1920, rgb_packing="ug934"))
    text = render(cfg, "package", "my_cfg_pkg", command="mstrack hdl config --max-frame-width 1920")
    assert "package my_cfg_pkg is" in text and "end package my_cfg_pkg;" in text
    assert "GENERATED by `mstrack hdl config --max-frame-width 1920`" in text
    consts = dict(re.findall(r"^  constant C_(\w+) +: natural := (\d+);$", text, re.M))
    assert {k: int(v) for k, v in consts.items()} == cfg.generics
    assert consts["RGB_PACKING"] == "1" and consts["MAX_FRAME_W"] == "1920"
    assert "--     MAX_FRAME_W    => C_MAX_FRAME_W," in text        # the generic map to paste
    with pytest.raises(ConfigError):
        render(cfg, "package", "1bad")


def test_generic_map_and_json():
    cfg = derive(CoreChoices())
    gm = render(cfg, "generic-map")
    assert generic_map(cfg.generics) in gm and "RESULT_W       => 144\n)" in gm
    js = json.loads(render(cfg, "json"))
    assert js["generics"] == cfg.generics and js["choices"]["lanes"] == 4


def test_cli_writes_package(tmp_path, capsys):
    out = tmp_path / "cfg" / "ms_tracker_config_pkg.vhd"
    assert main(["hdl", "config", "--max-frame-width", "1280", "--lanes", "2", "--out", str(out)]) == 0
    text = out.read_text()
    assert re.search(r"constant C_MAX_FRAME_W +: natural := 1280;", text)
    assert re.search(r"constant C_LANES +: natural := 2;", text)
    assert "--max-frame-width 1280 --lanes 2" in text      # the command that made it


@pytest.mark.parametrize("argv,reason", [
    (["--preset", "v2", "--ppc", "2"], "core v2 (preset v2) takes one pixel per clock"),
    (["--lanes", "6"], "LANES 6 is not a power of two"),
    (["--max-target", "1001"], "the largest window the kernel tables hold"),
])
def test_cli_refuses_with_one_line(argv, reason, capsys):
    assert main(["hdl", "config", *argv]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("mstrack hdl: error: ") and reason in err and "\n" not in err


def test_cli_preset_v2_package(tmp_path):
    """`mstrack hdl config --preset v2` writes core v2's configuration: PRESET 1, every generic of ms_tracker."""
    out = tmp_path / "v2_pkg.vhd"
    assert main(["hdl", "config", "--preset", "v2", "--max-frame-width", "1920", "--out", str(out)]) == 0
    text = out.read_text()
    consts = dict(re.findall(r"^  constant C_(\w+) +: (?:natural|integer) := (-?\d+);$", text, re.M))
    assert list(consts) == entity_generics()
    assert consts["PRESET"] == "1" and consts["RESULT_W"] == "160" and consts["MAX_FRAME_W"] == "1920"
    assert re.search(r"constant C_LOSS_CONTRAST +: integer := 16384;", text)   # 0.25, the joint tracker's
    assert re.search(r"constant C_ORIENT_T +: integer := 64;", text)
    assert "preset v2 (PRESET 1)" in text and "result_layout_v2" in text


def _vhdl_defaults(path, entity):
    """Literal integer defaults of *entity*'s generics (names with a non-literal default are left out)."""
    text = re.sub(r"--[^\n]*", "", path.read_text())
    m = re.search(rf"entity\s+{entity}\s+is\s+generic\s*\((.*?)\)\s*;\s*port", text, re.S | re.I)
    assert m, f"no generic clause in {path}"
    return {k: int(v) for k, v in re.findall(r"(\w+)\s*:\s*(?:natural|integer)(?:\s+range\s+-?\d+\s+to\s+\d+)?\s*:=\s*(-?\d+)\b", m.group(1), re.I)}


def test_core_v2_vhdl_defaults_are_the_models():
    """The VHDL defaults of core v2's own generics (in ms_tracker) and of every generic of the engine
    ms_tracker_v2 are the values CoreConfigV2 derives from the default v2 parameters, so an
    instantiation that leaves them out still runs the specification (SPREAD_DEFAULT and the region
    sizes were stale once)."""
    from mstrack.hw.hdl_config import TRACKER_VHD
    want = CoreConfigV2(TrackerParams(preset="v2"), FixedParams()).generics()
    top = _vhdl_defaults(TRACKER_VHD, "ms_tracker")
    own = [k for k in V2_GENERICS if k in want]          # BG_Q_W, BG_O_W: engine constants, not derived
    assert len(own) >= len(V2_GENERICS) - 2
    assert {k: top[k] for k in own} == {k: want[k] for k in own}
    keys = [k for k in want if k != "MAX_FRAME_W"]        # the frame width is the integrator's choice
    eng = _vhdl_defaults(TRACKER_VHD.with_name("ms_tracker_v2.vhd"), "ms_tracker_v2")
    assert set(keys) <= set(eng)
    assert {k: eng[k] for k in keys} == {k: want[k] for k in keys}


#: the choices of an integrator who builds eight colour targets on one engine at 1080p60 behind
#: AXI4-Lite, windows up to 63 px: the configuration `mstrack synth --config shared8-colour-w63` measures
W63_AXI = dict(preset="v2", colour=True, max_frame_width=1920, max_target=63, coord_bits=11, top="ms_tracker_axi",
               max_targets=8, shared_engine=True, timing="1080p60")


def test_axi_shared_engine_is_what_the_driver_and_synthesis_build():
    """`--top ms_tracker_axi --max-targets N --shared-engine`: the generics of ms_tracker_axi that the C
    driver's co-simulation builds (drvsim.axi_generics) and, for the w63 choices, those of the
    synthesised configuration shared8-colour-w63; every name is a generic of ms_tracker_axi."""
    from mstrack.hw.drvsim import axi_generics
    from mstrack.hw.fastsim import mode_timing
    from mstrack.hw.synth import CONFIGS
    from mstrack.track.params import V2_COLOUR
    g = derive(CoreChoices(**W63_AXI)).generics
    tp = TrackerParams(preset="v2", **{**V2_COLOUR, "max_window": 63})
    cfg = CoreConfigV2(tp, FixedParams(max_half=31, coord_bits=11), 4, 1920)
    want = axi_generics(cfg, 8, True, shared=mode_timing("1080p60"))
    assert {k: g[k] for k in want} == want
    assert g["SHARED_ENGINE"] == 1 and g["MAX_TARGETS"] == 8 and g["COORD_W"] == 11 and g["RESULT_STREAM"] == 1
    assert g["FRAME_LINES"] == 1125 and g["ACTIVE_LINES"] == 1080 and g["LINE_CLOCKS"] == 2200
    synth = CONFIGS["shared8-colour-w63"].pins_generics()
    assert {k: g[k] for k in synth} == {k: int(v) for k, v in synth.items()}
    assert set(g) <= set(entity_generics(entity="ms_tracker_axi"))
    # another raster: the rule's lines and clocks follow it
    g30 = derive(CoreChoices(**{**W63_AXI, "timing": "720p60"})).generics
    assert (g30["ACTIVE_LINES"], g30["FRAME_LINES"], g30["LINE_CLOCKS"]) == (720, 750, 1650)


def test_axi_engine_per_slot_and_single_target():
    """ms_tracker_axi without a shared engine: MAX_TARGETS slots with an engine each, or one target
    (MAX_TARGETS 0), SHARED_ENGINE false; the paper core behind the registers keeps PRESET 0."""
    g = derive(CoreChoices(preset="v2", top="ms_tracker_axi", max_targets=3, result_stream=False)).generics
    assert (g["MAX_TARGETS"], g["SHARED_ENGINE"], g["RESULT_STREAM"]) == (3, 0, 0)
    assert "FRAME_LINES" not in g
    p = derive(CoreChoices(top="ms_tracker_axi")).generics
    assert (p["PRESET"], p["MAX_TARGETS"], p["SHARED_ENGINE"]) == (0, 0, 0)


def test_cli_axi_package_has_boolean_generics(tmp_path):
    """The package of ms_tracker_axi: boolean constants for SHARED_ENGINE / RESULT_STREAM, the generic
    map for ms_tracker_axi, the choices in its header."""
    out = tmp_path / "axi_pkg.vhd"
    argv = ["hdl", "config", "--preset", "v2", "--colour", "--max-frame-width", "1920", "--max-target", "63",
            "--coord-bits", "11", "--top", "ms_tracker_axi", "--max-targets", "8", "--shared-engine",
            "--no-result-stream", "--out", str(out)]
    assert main(argv) == 0
    text = out.read_text()
    assert re.search(r"constant C_SHARED_ENGINE +: boolean := true;", text)
    assert re.search(r"constant C_RESULT_STREAM +: boolean := false;", text)
    assert re.search(r"constant C_MAX_TARGETS +: natural := 8;", text)
    assert "u_tracker : entity work.ms_tracker_axi" in text
    assert "8 target slot(s), one shared engine, capacity rule at 1080p60, result stream off" in text
    gm = render(derive(CoreChoices(**W63_AXI)), "generic-map")
    assert re.search(r"SHARED_ENGINE +=> true", gm) and re.search(r"RESULT_STREAM +=> true", gm)
