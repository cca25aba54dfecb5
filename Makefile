# The two commands of the README: `make main` and `make test`. Both set up .venv first.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
# torch's CPU build first: a plain `torch` requirement would pull a multi-GB CUDA build
TORCH := torch==2.13.0
# Ray with RLlib pins its own gymnasium (1.2.2 for Ray 2.60): it gets a venv of its own.
RAY_VENV ?= .venv-ray
RAY_PY := $(RAY_VENV)/bin/python
RAY_STAMP := $(RAY_VENV)/.installed
# The oldest gymnasium pyproject.toml allows, for the compatibility run.
OLD_VENV ?= .venv-oldgym
OLD_PY := $(OLD_VENV)/bin/python
OLD_STAMP := $(OLD_VENV)/.installed
OLDEST_GYMNASIUM := gymnasium==1.1.1
# What the extra gymnasium versions run: the env API (checkers, vector envs, ids in fresh processes).
COMPAT_TESTS := tests/envs
RAY_PORT ?= 6390

.PHONY: main test lint docs wheel-check test-compat test-rllib rllib-two-nodes rllib-report bench figures agents-study clean-cache

# Each set-up step says what it does before it starts (pip itself runs quietly).
SAY := @echo "==>"

$(STAMP): pyproject.toml
	$(SAY) "setting up $(VENV), once: a virtual environment with the package and every extra but the distributed one"
	$(PYTHON) -m venv $(VENV)
	$(SAY) "upgrading pip in $(VENV)"
	$(PY) -m pip install --quiet --upgrade pip
	$(SAY) "installing torch's CPU build ($(TORCH), about 200 MB to download; a minute or two)"
	$(PY) -m pip install --quiet $(TORCH)
	$(SAY) "installing collision_env and its extras (pip install -e \".[all]\": numba, stable-baselines3, pygame, mkdocs, ...; about a minute)"
	$(PY) -m pip install --quiet -e ".[all]"
	$(SAY) "compiling the engine's kernels once now, not at the first run (about a minute; one line per kernel)"
	$(PY) -m collision_env.precompile
	touch $(STAMP)

$(RAY_STAMP): pyproject.toml
	$(SAY) "setting up $(RAY_VENV), once: Ray with RLlib, which pins its own gymnasium"
	$(PYTHON) -m venv $(RAY_VENV)
	$(RAY_PY) -m pip install --quiet --upgrade pip
	$(SAY) "installing torch's CPU build ($(TORCH)) in $(RAY_VENV)"
	$(RAY_PY) -m pip install --quiet $(TORCH)
	$(SAY) "installing collision_env with Ray RLlib in $(RAY_VENV) (a few minutes)"
	$(RAY_PY) -m pip install --quiet -e ".[render,test,distributed]"
	$(SAY) "compiling the engine's kernels for $(RAY_VENV)"
	$(RAY_PY) -m collision_env.precompile
	touch $(RAY_STAMP)

$(OLD_STAMP): pyproject.toml
	$(SAY) "setting up $(OLD_VENV), once: the oldest gymnasium the package allows ($(OLDEST_GYMNASIUM))"
	$(PYTHON) -m venv $(OLD_VENV)
	$(OLD_PY) -m pip install --quiet --upgrade pip
	$(SAY) "installing collision_env with $(OLDEST_GYMNASIUM) in $(OLD_VENV)"
	$(OLD_PY) -m pip install --quiet -e ".[render,test]" "$(OLDEST_GYMNASIUM)"
	$(SAY) "compiling the engine's kernels for $(OLD_VENV)"
	$(OLD_PY) -m collision_env.precompile
	touch $(OLD_STAMP)

# Train PPO on the default env and evaluate it (prints where the model, logs and GIF went).
main: $(STAMP)
	$(SAY) "training PPO on the default env, then evaluating it beside two baselines (a few minutes)"
	$(PY) -m agents.main

test: $(STAMP)
	$(PY) -m collision_env.precompile
	$(PY) -m pytest -n 2

# ruff's lint rules and its formatter (the pre-commit hooks run the same), then mypy's type check of
# collision_env, agents and scripts; all as configured in pyproject.toml.
lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy

# The documentation site (mkdocs.yml) into site/: every warning fails the build (--strict). The env
# pages and the API reference are generated from the docstrings (scripts/docs_hooks.py, docs_griffe.py).
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict

# The package as an index would get it: build the sdist and the wheel, check their metadata
# (twine), then install the wheel (numba comes with it) in a clean venv, outside the checkout, and make, reset
# and step the default env there (the first step compiles the kernels, once).
WHEEL_DIST ?= build/dist
WHEEL_VENV ?= build/wheel-venv
wheel-check: $(STAMP)
	rm -rf $(WHEEL_DIST) $(WHEEL_VENV)
	$(PY) -m build --quiet --outdir $(WHEEL_DIST) .
	$(PY) -m twine check --strict $(WHEEL_DIST)/*
	$(PYTHON) -m venv $(WHEEL_VENV)
	$(WHEEL_VENV)/bin/python -m pip install --quiet "$$(ls $(WHEEL_DIST)/*.whl)"
	cd $(WHEEL_VENV) && bin/python $(CURDIR)/scripts/wheel_smoke.py

# The env API under the oldest allowed gymnasium and under Ray's (1.2.2), with the RLlib smoke test and
# the code blocks of the README and docs/ (those that need Ray run there); then, on its own (its private
# Ray instance beside no other), a benchmark sweep on Ray against the same sweep run serially.
test-compat: $(OLD_STAMP) $(RAY_STAMP)
	$(OLD_PY) -m pytest -n 2 -q -p no:cacheprovider $(COMPAT_TESTS)
	$(RAY_PY) -m pytest -n 2 -q -p no:cacheprovider $(COMPAT_TESTS) tests/agents/test_rllib.py tests/test_docs_code.py
	$(RAY_PY) -m pytest -q -p no:cacheprovider tests/bench/test_parallel_ray.py

test-rllib: $(RAY_STAMP)
	$(RAY_PY) -m pytest -q -p no:cacheprovider tests/agents/test_rllib.py

# Two Ray nodes on this machine, each with one CPU, on loopback addresses of their own (Ray maps
# 127.0.0.1 itself to the machine's network address; 127.0.0.2 and .3 stay on loopback): a head
# and a worker node; train_rllib joins with --address and its two env runners land one per node.
# Token authentication (the token in ~/.ray) guards the cluster's ports, as on real machines.
HEAD_IP ?= 127.0.0.2
WORKER_IP ?= 127.0.0.3
rllib-two-nodes: export RAY_AUTH_MODE = token
rllib-two-nodes: $(RAY_STAMP)
	$(RAY_VENV)/bin/ray start --head --node-ip-address=$(HEAD_IP) --port=$(RAY_PORT) --num-cpus=1 \
		--include-dashboard=false --disable-usage-stats
	$(RAY_VENV)/bin/ray start --address=$(HEAD_IP):$(RAY_PORT) --node-ip-address=$(WORKER_IP) --num-cpus=1 \
		--disable-usage-stats; \
	$(RAY_PY) -m agents.train_rllib --address $(HEAD_IP):$(RAY_PORT) --node-ip-address $(HEAD_IP) \
		--env-runners 2 --run-name rllib-two-nodes --overwrite; status=$$?; $(RAY_VENV)/bin/ray stop; exit $$status

# Re-measure the agents page's RLlib block (throughput, a training run, the two-node run's placement).
rllib-report: $(RAY_STAMP)
	$(RAY_PY) -m agents.rllib_report --markdown docs/agents.md --cluster runs/rllib-two-nodes

# A quick look at the engine's speed against its peers (~30 s; writes nothing).
bench: $(STAMP)
	$(PY) -m collision_env.bench.engine --quick

# Re-measure every figure of the README and docs/ (the README holds the study's headline table and the
# env table; every other page is docs/bench/*.md; the agents study is separate). About an hour and a half, an
# hour of it the physics benchmark's literature section on two processes.
figures: $(STAMP)
	$(PY) -m collision_env.bench --readme README.md
	$(PY) -m collision_env.bench.engine --markdown docs/bench/engine.md
	$(PY) -m collision_env.bench.scale --markdown docs/bench/scale.md
	$(PY) -m collision_env.bench.physics --json docs/bench/physics.json --markdown docs/bench/physics.md --plot docs/img
	$(PY) -m collision_env.bench.physics --section literature --jobs 2 --json docs/bench/literature.json \
		--markdown docs/bench/physics.md --plot docs/img
	$(PY) -m collision_env.bench.chains --json docs/bench/chains.json --markdown docs/bench/chains.md
	$(PY) -m collision_env.bench.peer --json docs/bench/peer.json --markdown docs/bench/peer.md
	$(PY) -m collision_env.bench.envs --markdown docs/bench/envs_bench.md
	$(PY) -m collision_env.bench.compile --markdown docs/bench/compile.md --estimates collision_env/engine/compile_seconds.json
	$(PY) -m collision_env.bench.backend --markdown docs/bench/backend.md
	$(PY) scripts/render_presets.py --readme README.md

# Train cheap, evaluate exact: PPO under every engine mode and seed, then every preset (long).
agents-study: $(STAMP)
	$(PY) -m agents.study --jobs 2

# The compiled kernels live in a folder named by a hash of their sources, so an edit never runs
# stale code; this only frees the disk space (numba's own per-file caches included).
clean-cache:
	rm -rf collision_env/__pycache__/kernels-* "$${XDG_CACHE_HOME:-$$HOME/.cache}"/collision_env/kernels-*
	find collision_env -name '*.nbi' -delete -o -name '*.nbc' -delete
