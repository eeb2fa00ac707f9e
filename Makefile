# Two commands on a fresh machine: `make run` (set up .venv, run the main job) and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SBIB   := $(VENV)/bin/sbib
# Shared benchmark data (structure, records, test data) live beside the checkout; override to relocate.
export SBIB_SHARED      ?= $(abspath ../shared)
export SBIB_RECORDS_DIR ?= $(SBIB_SHARED)/records/raw/FDZ
OUT ?= results

.PHONY: setup run test test-all bench clean

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	@echo "compiling the numba kernels once (sbib warm-up, about 2 minutes; later runs load them from the cache)"
	$(SBIB) warm-up
	touch $@

run: setup
	$(SBIB) study --out $(OUT)

test: setup
	$(VENV)/bin/lint-imports
	$(VENV)/bin/mypy
	$(PY) -m pytest -q

test-all: setup
	$(PY) -m pytest -q -m ''

bench: setup
	$(SBIB) bench --out $(OUT)/bench

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
