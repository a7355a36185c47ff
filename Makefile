# mstrack: common commands.  Everything installs itself through tools/setup.sh.
VENV    ?= .venv
PY      := $(VENV)/bin/python
DATASET ?= ../shared/data/sequences
ARGS    ?=

.PHONY: setup demo test test-synth eval results clean synth

setup:
	bash tools/setup.sh

demo: setup
	$(VENV)/bin/mstrack demo $(ARGS)

# The ECP5 netlist build (tb/test_synth.py, marker `synth`: yosys + nextpnr, 12-17 min on 2 cores)
# is left out of `make test` to keep it under CI's 30 min; `make test-synth` runs it.
test: setup
	$(PY) -m pytest -q -m "not synth" $(ARGS)

test-synth: setup
	$(PY) -m pytest -q -m synth -s $(ARGS)

eval: setup
	$(VENV)/bin/mstrack eval $(DATASET) --out out/eval $(ARGS)

results: setup
	$(VENV)/bin/mstrack eval $(DATASET) --out out/eval_float --quiet
	$(VENV)/bin/mstrack eval $(DATASET) --model fixed --trackers mstrack-fused-flat,mstrack-colour-flat,mstrack-edge-flat,mstrack-fused-epan,mstrack-colour-epan,mstrack-edge-epan --out out/eval_fixed --quiet
	$(PY) tools/results_doc.py

clean:
	rm -rf out build .pytest_cache sim_build* results.xml *.egg-info
	find . -path ./$(VENV) -prune -o -name __pycache__ -type d -exec rm -rf {} +

# open synthesis of the core (yosys + nextpnr-ecp5 3 seeds + synth_xilinx, all configurations;
# long on 2 cores, see docs/performance.md); tables rewritten in docs/performance.md.
# Quick: make synth ARGS="--config default --seeds 1"
synth: setup
	$(VENV)/bin/mstrack synth --write $(ARGS)
