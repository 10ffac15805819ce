# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO   ?= scenarios/seat_motor_demo.yaml

.PHONY: demo test lint install bench clean

# public modules whose types are checked (the API of wormsim/__init__.py and the shared theory)
TYPED  := wormsim/__init__.py wormsim/scenario.py wormsim/run.py wormsim/result.py wormsim/errors.py \
          wormsim/gear_theory.py wormsim/cli.py wormsim/geometry.py
# files held to `ruff format`; the rest follows once the parallel restructuring branches have merged
FORMATTED := meshgen/cache.py wormsim/sweep/*.py sweeps/*.py tests/test_sweep.py wormsim/gear_theory.py wormsim/errors.py wormsim/geometry.py wormsim/mesh_cmd.py wormsim/__init__.py \
          wormsim/contact3d/window.py wormsim/contact3d/timestep.py tests/conftest.py tests/test_gear_theory.py \
          tests/test_packaging.py

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
	$(BIN)/ruff format --check $(FORMATTED)
	$(BIN)/mypy $(TYPED)

test: lint
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/wormsim bench --out out/bench

clean:
	rm -rf out .pytest_cache
