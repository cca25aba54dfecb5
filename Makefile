# The two commands of the README: `make main` and `make test`. Both set up .venv first.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: main test lint bench figures agents-study clean-cache

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	# torch's CPU build first: stable-baselines3 would otherwise pull a multi-GB CUDA build
	$(PY) -m pip install --quiet torch==2.13.0
	$(PY) -m pip install --quiet -e ".[all]"
	touch $(STAMP)

# Train PPO on the default env and evaluate it (prints where the model, logs and GIF went).
main: $(STAMP)
	$(PY) -m agents.main

test: $(STAMP)
	$(PY) -m pytest -n 2

# ruff's lint rules and its formatter, as configured in pyproject.toml (the pre-commit hooks run the same).
lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .

# A quick look at the engine's speed against its peers (~30 s; writes nothing).
bench: $(STAMP)
	$(PY) -m collision_env.bench.engine --quick

# Re-measure every figure of the README and docs/ (a few minutes; the agents study is separate).
figures: $(STAMP)
	$(PY) -m collision_env.bench --readme README.md
	$(PY) -m collision_env.bench.engine --markdown docs/bench/engine.md --readme README.md
	$(PY) -m collision_env.bench.scale --markdown docs/bench/scale.md --readme README.md
	$(PY) -m collision_env.bench.envs --markdown docs/bench/envs_bench.md --readme README.md
	$(PY) scripts/render_presets.py

# Train cheap, evaluate exact: PPO under every engine mode and seed, then every preset (long).
agents-study: $(STAMP)
	$(PY) -m agents.study --jobs 2 --readme README.md

# numba caches compiled kernels next to the sources and does not notice edits to a kernel's
# callees in other files: clear the cache after editing the engine.
clean-cache:
	find collision_env -name '*.nbi' -delete -o -name '*.nbc' -delete
