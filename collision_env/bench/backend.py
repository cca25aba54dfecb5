"""Compiled against plain Python: what numba is worth, on the scenes a user meets.

    python -m collision_env.bench.backend [--seconds 5] [--markdown docs/bench/backend.md]

numba is a dependency of the package wherever it has wheels; elsewhere the same kernels run as
plain Python (``collision_env.engine._jit``), and the warning issued then states how much slower
(``PYTHON_SLOWDOWN``, this benchmark's figure, rounded). Each backend runs in a fresh process
(``NUMBA_DISABLE_JIT=1`` for the Python one, its kernels loaded from the cache or compiled first
for the compiled one) on the same scenes:

- the 1000-disk gas of the scale benchmark (elastic disks of radius 0.01 m at area fraction 0.3,
  ``collision_env.bench.scale.lattice_gas``), stepped by ``Simulator.step`` in frames of 1/60 s:
  impacts per second;
- the default env, ``gym.make("CollisionEnv/OneBallTarget-v0")``, stepped with random actions:
  env steps per second.

Each figure counts the work done in at least ``--seconds`` of wall time after one untimed frame or
step; the two backends alternate for ``--rounds`` rounds and the best of each is kept.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable

from collision_env.bench.readme import write_outputs

from .machine import cpus, machine, timestamp, versions

#: Run in a fresh process: ``{"gas": impacts/s, "env": steps/s, "backend": ...}`` on stdout.
_SCRIPT = """
import json, sys, time
import gymnasium as gym
import collision_env
from collision_env.bench.scale import lattice_gas
from collision_env.engine import BACKEND, Simulator

seconds = float(sys.argv[1])


def rate(step):
    step()
    start, done = time.perf_counter(), 0
    while time.perf_counter() - start < seconds:
        done += step()
    return done / (time.perf_counter() - start)


scene, pos, vel = lattice_gas(1000)
sim = Simulator(scene, pos, vel, [1.0] * 1000, [0.01] * 1000)
env = gym.make("CollisionEnv/OneBallTarget-v0")
env.reset(seed=0)


def env_step():
    *_, terminated, truncated, _ = env.step(env.action_space.sample())
    if terminated or truncated:
        env.reset()
    return 1


print(json.dumps({"backend": BACKEND, "gas": rate(lambda: len(sim.step(1 / 60))), "env": rate(env_step)}))
"""


def measure(python: bool, seconds: float) -> dict:
    """One fresh process of the compiled (``python=False``) or the plain-Python backend."""
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1" if python else "0"}
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, str(seconds)], env=env, capture_output=True, text=True, check=False
    )
    if done.returncode:
        raise RuntimeError(f"backend benchmark: the run failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout)


def run(seconds: float = 5.0, rounds: int = 2, log: Callable[[str], None] = print) -> dict:
    """Both backends, alternating, ``rounds`` times; the best figure of each."""
    started = time.perf_counter()
    best: dict[str, dict] = {}
    for r in range(rounds):
        for python in (False, True):
            got = measure(python, seconds)
            log(f"  round {r + 1}, {got['backend']}: gas {got['gas']:.3g} impacts/s, env {got['env']:.3g} steps/s")
            old = best.setdefault(got["backend"], got)
            best[got["backend"]] = {k: max(old[k], got[k]) if k != "backend" else got[k] for k in got}
    return {
        "machine": machine(),
        "cpus": cpus(),
        "versions": versions(["numba"]),
        "timestamp": timestamp(),
        "seconds": time.perf_counter() - started,
        "slice_s": seconds,
        "rounds": rounds,
        "numba": best["numba"],
        "python": best["python"],
    }


def render_markdown(results: dict) -> str:
    v, fast, slow = results["versions"], results["numba"], results["python"]
    gas_ratio, env_ratio = fast["gas"] / slow["gas"], fast["env"] / slow["env"]
    lines = [
        f"`python -m collision_env.bench.backend` on {results['machine']}, {results['cpus']} CPUs, "
        f"Python {v['python']}, numpy {v['numpy']}, numba {v.get('numba')}; {results['timestamp']}, "
        f"{results['seconds']:.0f} s. Each backend in a fresh process, the best of {results['rounds']} "
        f"alternating rounds of {results['slice_s']:g} s.",
        "",
        "| scene | compiled (numba) | plain Python | numba ÷ Python |",
        "|---|---:|---:|---:|",
        f"| 1000-disk gas, `Simulator.step(1/60)`: impacts/s | {fast['gas']:.3g} | {slow['gas']:.3g} | "
        f"{gas_ratio:,.0f} |",
        f"| `CollisionEnv/OneBallTarget-v0`, random actions: env steps/s | {fast['env']:.3g} | "
        f"{slow['env']:.3g} | {env_ratio:,.0f} |",
        "",
        f"On the gas, plain Python is **{gas_ratio:,.0f}×** slower per collision: the figure the engine's "
        "warning gives when numba is missing (`collision_env.engine._jit.PYTHON_SLOWDOWN`, rounded).",
    ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.backend", description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="wall seconds per figure (default 5)")
    parser.add_argument("--rounds", type=int, default=2, help="alternating rounds (default 2)")
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument("--markdown", help="write the table here")
    args = parser.parse_args(argv)
    results = run(args.seconds, args.rounds)
    table = render_markdown(results)
    write_outputs(table, results, json_path=args.json, markdown=args.markdown, title="# Compiled against plain Python")
    return 0


if __name__ == "__main__":
    sys.exit(main())
