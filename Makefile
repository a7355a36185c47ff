# mstrack: common commands.  Everything installs itself through tools/setup.sh.
VENV    ?= .venv
PY      := $(VENV)/bin/python
DATASET ?= ../shared/data/sequences
MULTI_DATASET ?= ../shared/data/multi
VALIDATION ?= ../shared/data/validation
ARGS    ?=

# Compiled bytecode goes to build/pycache.  The machines may set PYTHONDONTWRITEBYTECODE; then every
# pytest run and every cocotb simulator's Python compiled mstrack again and re-wrote the test modules'
# asserts (a pytest collection: 99 s without a cache, 3.7 s with one, docs/performance.md "CI time").
export PYTHONPYCACHEPREFIX := $(CURDIR)/build/pycache
unexport PYTHONDONTWRITEBYTECODE

.PHONY: regs setup demo typecheck test test-fuzz test-fuzz-v2 test-fuzz-multi test-fuzz-shared test-multi-mot test-shared-mot test-sim test-synth test-long test-extra test-sim-only test-synth-only test-latest lock eval results clean synth hdl-files

setup:
	bash tools/setup.sh

demo: setup
	$(VENV)/bin/mstrack demo $(ARGS)

# mypy on the package (configuration: pyproject.toml [tool.mypy]); also run by tests/test_typing.py
typecheck: setup
	$(PY) -m mypy --cache-dir build/mypy_cache

# `make test` = the simulation and Python tests (pytest -m "not synth and not long and not extra") and,
# in parallel on the second core, the ECP5 netlist build of the default core (tb/test_synth.py, marker
# `synth`: GHDL -> yosys synth_ecp5 -> nextpnr-ecp5, seed 1; fits, Fmax floor, resource ceilings)
# followed by the long co-simulations (marker `long`, Verilator: core v2 on 120 real frames (1,545 with test-extra), the
# paper core on 760, the 1080p60 / 720p60 real-time checks of both cores, core v2's stream faults;
# GHDL: core v2's AXI-Lite top).  Tests listed in tb/conftest.py CI_EXTRA (marker `extra`) are left
# to `make test-extra` in both halves.
# yosys, nextpnr and the simulations are single-threaded, so running both halves side by side keeps
# CI within its 30 min (times in docs/performance.md, "Netlist build limits (CI)").
test: setup
	$(MAKE) --no-print-directory -j2 -Oline test-sim-only test-synth-only

test-sim: setup
	$(MAKE) --no-print-directory test-sim-only

test-synth: setup
	$(MAKE) --no-print-directory test-synth-only

# the halves without setup (setup must not run twice at once)
test-sim-only:
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -m "not synth and not long and not extra" --durations=60 $(ARGS)

test-synth-only:
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -m "synth and not extra" -s -p no:cacheprovider $(ARGS); a=$$?; \
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -m "long and not extra" --durations=60 -p no:cacheprovider $(ARGS); b=$$?; \
	test $$a -eq 0 -o $$a -eq 5 && test $$b -eq 0 -o $$b -eq 5  # 5: nothing selected (ARGS)

# the long co-simulations alone (core v2 on 120 real frames (1,545 with test-extra), the paper core on 760, the real-time checks,
# core v2's stream faults; Verilator; part of `make test`)
test-long: setup
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -m "long and not extra" -p no:cacheprovider $(ARGS)

# not in `make test` (CI time): PPC 2/4 on real frames (Verilator, plain and throttled), the PPC
# real-time modes (2160p30 at PPC 4; MSTRACK_RT_PPC_EXTRA=1 adds 1080p60 at PPC 2), the wheel installed
# with its dependencies from PyPI into a fresh venv (tests/test_release.py) and the test cases of
# tb/conftest.py CI_EXTRA (each names what covers it in `make test`)
test-extra: setup
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -s -m extra -p no:cacheprovider $(ARGS)

# Constrained-random stream-fault test of the core (tb/test_ms_tracker_faults.py::fuzz): N seeds
# from SEEDS in one GHDL simulation (CI runs 3 of them); a failure prints its seed, replay it
# with `make test-fuzz SEEDS=<seed> N=1`.  Coverage of the fault classes / crosses in FUZZ_REPORT.
SEEDS ?= 1
N     ?= 200
FUZZ_REPORT ?= build/fuzz_report.json
test-fuzz: setup
	mkdir -p build
	MSTRACK_FUZZ=$(SEEDS):$(N) MSTRACK_FUZZ_REPORT=$(abspath $(FUZZ_REPORT)) MSTRACK_REQUIRE_TOOLS=1 \
	  $(PY) -m pytest -q -s -p no:cacheprovider tb/test_ms_tracker_faults.py -k test_tracker_fuzz $(ARGS)

# The same constrained-random stream-fault test on core v2 (tb/test_ms_tracker_v2_faults.py::fuzz,
# Verilator; CI runs seeds 1..3); replay a failing seed with `make test-fuzz-v2 SEEDS=<seed> N=1`.
FUZZ_V2_REPORT ?= build/fuzz_v2_report.json
test-fuzz-v2: setup
	mkdir -p build
	MSTRACK_FUZZ=$(SEEDS):$(N) MSTRACK_FUZZ_REPORT=$(abspath $(FUZZ_V2_REPORT)) MSTRACK_REQUIRE_TOOLS=1 \
	  $(PY) -m pytest -q -s -p no:cacheprovider tb/test_ms_tracker_v2_faults.py -k test_tracker_v2_fuzz $(ARGS)

# Every frame and every target of both MOT sequences through the multi-target core (ms_tracker_axi,
# MAX_TARGETS 8 colour engines) and its C driver, people added and removed as they come and go
# (tb/test_mstrack_drv.py::test_driver_multi_mot_sequence; not in `make test`: over an hour)
test-multi-mot: setup
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -s -m extra -p no:cacheprovider tb/test_mstrack_drv.py -k mot_sequence $(ARGS)

# The shared-engine multi-target core (ms_tracker_shared) on every frame and target of both MOT
# sequences, its GHDL netlist under Verilator (part of test-extra; about 15 minutes with the build)
test-shared-mot: setup
	MSTRACK_REQUIRE_TOOLS=1 $(PY) -m pytest -q -s -m extra -p no:cacheprovider tb/test_ms_tracker_shared.py -k mot_sequence $(ARGS)

# The constrained-random test of the shared-engine core (tb/test_ms_tracker_shared.py::test_shared_fuzz:
# commands, stream faults, result back-pressure, line gaps, the capacity rule at a short frame period;
# its netlist under Verilator; CI runs seeds 1..10); replay a failing seed with
# `make test-fuzz-shared SEEDS=<seed> N=1`.
test-fuzz-shared: setup
	MSTRACK_FUZZ=$(SEEDS):$(N) MSTRACK_REQUIRE_TOOLS=1 \
	  $(PY) -m pytest -q -s -p no:cacheprovider tb/test_ms_tracker_shared.py -k test_shared_fuzz $(ARGS)

# The constrained-random test of the multi-target core (tb/test_ms_tracker_multi.py::test_multi_fuzz:
# commands, stream faults, result back-pressure; Verilator; CI runs seeds 1..10); replay a failing seed
# with `make test-fuzz-multi SEEDS=<seed> N=1`.
test-fuzz-multi: setup
	MSTRACK_FUZZ=$(SEEDS):$(N) MSTRACK_REQUIRE_TOOLS=1 \
	  $(PY) -m pytest -q -s -p no:cacheprovider tb/test_ms_tracker_multi.py -k test_multi_fuzz $(ARGS)

# The tests against the newest PyPI versions (not in CI): a separate venv, installed without the
# lock, so drift in numpy/OpenCV/cocotb/... is seen before it reaches the lock.
LATEST_VENV ?= .venv-latest
test-latest:
	SETUP_LATEST=1 VENV=$(LATEST_VENV) bash tools/setup.sh
	$(MAKE) --no-print-directory VENV=$(LATEST_VENV) -j2 -Oline test-sim-only test-synth-only

# Rewrite requirements.lock from the latest venv (run after `make test-latest` passes).
lock:
	{ sed -n '1,2p' requirements.lock; $(LATEST_VENV)/bin/python -m pip freeze --exclude-editable \
	  | grep -v '^#'; echo "setuptools==$$($(LATEST_VENV)/bin/python -m pip index versions setuptools 2>/dev/null \
	  | sed -n 's/^setuptools (\(.*\))/\1/p')"; } > requirements.lock.new && mv requirements.lock.new requirements.lock

# Register interface: regenerate everything made from regs/ms_tracker_regs.rdl (PeakRDL: the VHDL
# register block, the C header, docs/registers.md) and sw/ms_tracker_result.h (result word layout);
# tests/test_regs.py fails when a checked-in file differs from a fresh generation.
regs: setup
	$(PY) -m mstrack.hw.regs

eval: setup
	$(VENV)/bin/mstrack eval $(DATASET) --out out/eval $(ARGS)

results: setup
	$(VENV)/bin/mstrack eval $(DATASET) --out out/eval_float --quiet
	$(VENV)/bin/mstrack eval $(DATASET) --model fixed --trackers mstrack-v2,mstrack-v2-colour,mstrack-v2-colour-w63,mstrack-fused-flat,mstrack-colour-flat,mstrack-edge-flat,mstrack-fused-epan,mstrack-colour-epan,mstrack-edge-epan --out out/eval_fixed --quiet
	$(VENV)/bin/mstrack eval $(VALIDATION) --trackers mstrack-v2,mstrack-v2-colour,mstrack-v2-colour-w63,opencv-csrt --out out/eval_float_validation --quiet
	$(VENV)/bin/mstrack eval $(VALIDATION) --model fixed --trackers mstrack-v2,mstrack-v2-colour,mstrack-v2-colour-w63 --out out/eval_fixed_validation --quiet
	$(MAKE) --no-print-directory results-multi
	$(PY) tools/results_doc.py $(DATASET) $(VALIDATION)

.PHONY: results-multi
# the multi-target section (docs/results_multi.md, linked from docs/results.md): mstrack-v2 float and fixed,
# OpenCV CSRT and KCF (one per target) on the MOT sequences; it reads the speed benchmark docs/bench_multi.md
# (`mstrack bench $(MULTI_DATASET) --model float --frames 1000 --write-docs`, not run here: timings)
results-multi: setup
	$(VENV)/bin/mstrack eval $(MULTI_DATASET) --trackers mstrack-v2,opencv-csrt,opencv-kcf --out out/eval_multi_float --quiet
	$(VENV)/bin/mstrack eval $(MULTI_DATASET) --model fixed --trackers mstrack-v2 --out out/eval_multi_fixed --quiet
	$(PY) tools/results_multi_doc.py

clean:
	rm -rf out build .pytest_cache sim_build* results.xml *.egg-info
	find . -path ./$(VENV) -prune -o -name __pycache__ -type d -exec rm -rf {} +

# open synthesis of the core (yosys + nextpnr-ecp5 3 seeds + synth_xilinx, all configurations;
# long on 2 cores, see docs/performance.md); tables rewritten in docs/performance.md.
# Quick: make synth ARGS="--config default --seeds 1"
synth: setup
	$(VENV)/bin/mstrack synth --write $(ARGS)

# generated packaging files: rtl/files.txt, mstrack.core, tb/vhdl/data/ (docs/packaging.md);
# tests/test_packaging.py fails when they are stale
hdl-files: setup
	$(VENV)/bin/mstrack hdl files
