# mstrack: common commands.  Everything installs itself through tools/setup.sh.
VENV    ?= .venv
PY      := $(VENV)/bin/python
DATASET ?= ../shared/data/sequences
ARGS    ?=

.PHONY: setup demo test eval clean

setup:
	bash tools/setup.sh

demo: setup
	$(VENV)/bin/mstrack demo $(ARGS)

test: setup
	$(PY) -m pytest -q $(ARGS)

eval: setup
	$(VENV)/bin/mstrack eval $(DATASET) --out out/eval $(ARGS)

clean:
	rm -rf out build .pytest_cache sim_build* results.xml *.egg-info
	find . -path ./$(VENV) -prune -o -name __pycache__ -type d -exec rm -rf {} +
