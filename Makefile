# Two commands do all set-up on a fresh machine: `make demo` and `make test`. The install compiles the contact3d
# kernels once for this machine (wormsim.runtime.jit_cache.main with wormsim.contact3d.runner.warm_runs, ~1 min;
# every later process loads them).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO   ?= scenarios/seat_motor_demo.yaml

.PHONY: demo test test-long lint install bench images docs clean

# public modules whose types are checked (the API of wormsim/__init__.py and the shared theory)
TYPED  := wormsim/__init__.py wormsim/exceptions.py wormsim/run.py wormsim/results/result.py \
          wormsim/scenario/__init__.py wormsim/scenario/schema.py wormsim/scenario/loader.py wormsim/scenario/messages.py \
          wormsim/physics/gear_theory.py wormsim/physics/geometry.py wormsim/cli/entry.py
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/python -c 'import sys, wormsim.runtime.jit_cache as j, wormsim.contact3d.runner as r; sys.exit(j.main(r.warm_runs))'
	@# CalculiX (the FE contact check, wormsim.tooth.calculix): Debian's calculix-ccx, installed when missing and root
	command -v ccx >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && apt-get update -qq && apt-get install -y -qq calculix-ccx; } \
	  || echo "note: CalculiX (ccx) not installed (not root?): apt-get install calculix-ccx; its tests skip without it"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/wormsim run $(DEMO) --out out/demo

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy $(TYPED)

# the suite on every core (pytest-xdist, one test file per worker at a time: a file's module fixtures are built once)
JOBS   ?= $(shell nproc 2>/dev/null || echo 1)
test: lint
	$(BIN)/python -m pytest -q -n $(JOBS) --dist loadfile

# the tests kept out of `make test` for time (tests/conftest.py LONG_TESTS)
test-long: $(STAMP)
	$(BIN)/python -m pytest -q -m long

bench: $(STAMP)
	$(BIN)/wormsim bench --out out/bench

export SECTION = import sys; from meshgen.section import plot_section; from wormsim.physics.geometry import gear_set; \
	from wormsim.scenario import load_scenario; sc = load_scenario(sys.argv[1]); plot_section(*gear_set(sc), sys.argv[2], sc.name)

# docs/img from the current code: the demo's report, the mesh section (the records' figures: `make docs`)
images: $(STAMP)
	$(BIN)/wormsim run $(DEMO) --out out/demo --no-progress
	cp out/demo/report.png docs/img/seat_motor_demo_report.png
	$(BIN)/python -c "$$SECTION" scenarios/seat_motor.yaml docs/img/seat_motor_section.png

# README/docs tables and docs/img figures rendered from the records docs/data/*.json (tools.docs_render); no simulation
docs: $(STAMP)
	$(BIN)/python -m tools.docs_render

clean:
	rm -rf out .pytest_cache
