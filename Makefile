# Two commands on a fresh machine: `make run` (set up .venv, run the main job) and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SBIB   := $(VENV)/bin/sbib
# Shared benchmark data (structure, records, test data) live beside the checkout; override to relocate.
export SBIB_SHARED      ?= $(abspath ../shared)
export SBIB_RECORDS_DIR ?= $(SBIB_SHARED)/records/raw/FDZ
OUT ?= results

# numba compiles for the host CPU; the golden tests are run a second time with numba compiled for the
# generic x86-64 target (its own cache folder), so that a CPU other than the developer's cannot break
# `make test` (issue #22). NUMBA_CPU_NAME is numba's documented switch for the compilation target.
GENERIC_CACHE := $(abspath .numba-generic)

.PHONY: setup run test test-generic test-all bench clean

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	@# byte-compile the project once: an editable install does not, and where PYTHONDONTWRITEBYTECODE
	@# is set every `sbib` process would compile its ~380 modules again (0.2 s a start)
	$(PY) -m compileall -q benchmark damper controllers records
	@echo "compiling the numba kernels once (sbib warm-up, about 6 minutes on 2 cores; later runs load them from the cache)"
	$(SBIB) warm-up
	touch $@

run: setup
	$(SBIB) study --out $(OUT)

test: setup
	$(VENV)/bin/lint-imports
	$(VENV)/bin/mypy
	$(PY) -m pytest -q
	$(MAKE) --no-print-directory test-generic

test-generic: setup
	NUMBA_CPU_NAME=generic NUMBA_CACHE_DIR=$(GENERIC_CACHE) $(PY) -m pytest -q -p no:cacheprovider tests/golden

test-all: setup
	$(PY) -m pytest -q -m ''

bench: setup
	$(SBIB) bench --out $(OUT)/bench

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache $(GENERIC_CACHE)
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
