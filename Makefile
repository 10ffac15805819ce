# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO   ?= scenarios/seat_motor_demo.yaml

.PHONY: demo test test-long lint install bench images clean

# public modules whose types are checked (the API of wormsim/__init__.py and the shared theory)
TYPED  := wormsim/__init__.py wormsim/scenario.py wormsim/run.py wormsim/result.py wormsim/errors.py \
          wormsim/gear_theory.py wormsim/cli.py wormsim/geometry.py
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/wormsim run $(DEMO) --out out/demo

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy $(TYPED)

test: lint
	$(BIN)/python -m pytest -q

# the tests kept out of `make test` for time (tests/conftest.py LONG_TESTS): about 5 minutes more
test-long: $(STAMP)
	$(BIN)/python -m pytest -q -m long

bench: $(STAMP)
	$(BIN)/wormsim bench --out out/bench

export REPLOT = import json, sys, pathlib; from wormsim.bench.run import plot_bench; \
	plot_bench(json.loads(pathlib.Path(sys.argv[1]).read_text()), pathlib.Path(sys.argv[2]))

export SECTION = import sys; from meshgen.section import plot_section; from wormsim.geometry import gear_set; \
	from wormsim.scenario import load_scenario; sc = load_scenario(sys.argv[1]); plot_section(*gear_set(sc), sys.argv[2], sc.name)

# docs/img from the current code: the demo's report, the mesh section, the stored benchmarks redrawn
images: $(STAMP)
	$(BIN)/wormsim run $(DEMO) --out out/demo --no-progress
	cp out/demo/report.png docs/img/seat_motor_demo_report.png
	$(BIN)/python -c "$$SECTION" scenarios/seat_motor.yaml docs/img/seat_motor_section.png
	$(BIN)/python -c "$$REPLOT" docs/bench_quick.json docs/img/bench_quick.png
	$(BIN)/python -c "$$REPLOT" docs/bench_full.json docs/img/bench_full.png

clean:
	rm -rf out .pytest_cache
