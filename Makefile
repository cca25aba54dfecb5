# The two commands of the README: `make main` and `make test`. Both set up .venv first.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: main test bench clean-cache

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	# torch's CPU build first: stable-baselines3 would otherwise pull a multi-GB CUDA build
	$(PY) -m pip install --quiet torch==2.13.0
	$(PY) -m pip install --quiet -e ".[all]"
	touch $(STAMP)

main: $(STAMP)
	$(PY) -m collision_env.demo

test: $(STAMP)
	$(PY) -m pytest -n 2

bench: $(STAMP)
	$(PY) -m collision_env.engine.bench --quick

# numba caches compiled kernels next to the sources and does not notice edits to a kernel's
# callees in other files: clear the cache after editing the engine.
clean-cache:
	find collision_env -name '*.nbi' -delete -o -name '*.nbc' -delete
