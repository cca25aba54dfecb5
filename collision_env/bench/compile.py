"""Compile time: the CPU seconds a user waits for numba, with empty kernel caches.

    python -m collision_env.bench.compile [--repeats 1] [--markdown PATH] [--estimates PATH]

Each row is a fresh Python process with a new, empty kernel cache (``NUMBA_CACHE_DIR`` and
``XDG_CACHE_HOME`` in a temporary folder): its CPU seconds (user and system, of the whole process:
the interpreter, the imports and the compiler) are what a first run on a new install costs. The
rows are what users meet first (the first exact-mode step of a small elastic scene, the first
``gym.make`` + ``reset`` + ``step`` of the default env, ``python -m collision_env.precompile``),
then each kernel family compiled alone: every stepping kernel of the engine (one per mode and kind
of scene, see :mod:`collision_env.engine.modes`) and the environments' kernels. A family's row
includes what its kernels call that no other row has compiled before, since each starts empty.
Without numba there is nothing to compile and the rows measure plain Python.

``--estimates collision_env/engine/compile_seconds.json`` also writes the seconds each labelled
kernel took in the precompile row: the compile notice's guide to the wait
(``collision_env.engine._jit.EXPECTED_SECONDS``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable

from collision_env.bench.readme import write_outputs

from .machine import cpus, machine, timestamp, versions

_STEP = """
from collision_env.engine import Scene, Simulator
Simulator(Scene(), [[-0.5, 0.0], [0.5, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 2.0]).step(0.1)
"""
_ENV = """
import gymnasium as gym
import collision_env
env = gym.make("CollisionEnv/OneBallTarget-v0")
env.reset(seed=0)
env.step(env.action_space.sample())
"""
_PRECOMPILE = """
import json
from collision_env.engine._jit import compile_seconds
from collision_env.precompile import precompile
precompile()
print(json.dumps(compile_seconds()))
"""
_KERNEL = """
import numpy as np
from collision_env.engine._jit import compile_for
from collision_env.engine.argpack import pack_arrays
from collision_env.engine.modes import MODES
compile_for(MODES[{mode!r}].kernels()[{index}], pack_arrays([np.zeros(1)]), 1.0, 1)
"""
_PREDICTED = """
import gymnasium as gym
import collision_env
env = gym.make("CollisionEnv/OneBallTarget-v0", observe="predicted", aim="predicted", control="velocity")
env.reset(seed=0)
env.step(env.action_space.sample())
"""


def rows() -> list[tuple[str, str, float | None]]:
    """``(what, code, goal in CPU seconds or None)`` of every row, in order."""
    from collision_env.engine.modes import MODES

    out: list[tuple[str, str, float | None]] = [
        ("first exact-mode `Simulator.step` (2 elastic balls)", _STEP, 20.0),
        ('first `gym.make("CollisionEnv/OneBallTarget-v0")` + `reset` + `step`', _ENV, 30.0),
        ("`python -m collision_env.precompile` (every kernel)", _PRECOMPILE, 60.0),
    ]
    for name, spec in MODES.items():
        for index, kernel in enumerate(spec.kernels()):
            out.append(
                (
                    f"kernel alone: {getattr(kernel, 'label', name + ' mode')}",
                    _KERNEL.format(mode=name, index=index),
                    None,
                )
            )
    out.append(("env with the predicted observation: first `make` + `reset` + `step`", _PREDICTED, None))
    return out


def cpu_seconds(code: str) -> tuple[float, float, str]:
    """Run ``code`` in a fresh interpreter with empty kernel caches: ``(CPU s, wall s, stdout)``."""
    with tempfile.TemporaryDirectory(prefix="collision-env-compile-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "XDG_CACHE_HOME": cache}
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        raise RuntimeError(f"compile benchmark: the run failed:\n{done.stderr[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, done.stdout


def run(repeats: int = 1, log: Callable[[str], None] = print) -> dict:
    """Every row, each the fewest CPU seconds of ``repeats`` runs."""
    started = time.perf_counter()
    results = []
    kernels: dict[str, float] = {}
    for what, code, goal in rows():
        runs = [cpu_seconds(code) for _ in range(repeats)]
        cpu, wall, out = min(runs)
        results.append({"what": what, "cpu_s": cpu, "wall_s": wall, "goal_s": goal})
        if code == _PRECOMPILE:
            kernels = json.loads(out.strip().splitlines()[-1])
        log(f"  {what}: {cpu:.1f} s CPU ({wall:.1f} s wall)")
    return {
        "machine": machine(),
        "cpus": cpus(),
        "versions": versions(["numpy", "numba", "llvmlite"]),
        "timestamp": timestamp(),
        "repeats": repeats,
        "seconds": time.perf_counter() - started,
        "rows": results,
        "kernel_seconds": kernels,
    }


def render_markdown(results: dict) -> str:
    v = results["versions"]
    head = (
        f"`python -m collision_env.bench.compile` on {results['machine']}, {results['cpus']} CPUs, "
        f"numba {v.get('numba')}, llvmlite {v.get('llvmlite')}; {results['timestamp']}, "
        f"{results['seconds']:.0f} s. Each row is a fresh process with empty kernel caches: its CPU seconds "
        "(user + system, the whole process), the fewest of "
        f"{results['repeats']} run{'s' if results['repeats'] > 1 else ''}. A kernel's row includes what it "
        "calls that it compiles first."
    )
    lines = [head, "", "| what | CPU s | wall s | goal |", "|---|---:|---:|---:|"]
    for row in results["rows"]:
        goal = f"≤ {row['goal_s']:.0f} s" if row["goal_s"] else ""
        lines.append(f"| {row['what']} | {row['cpu_s']:.1f} | {row['wall_s']:.1f} | {goal} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.compile", description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=1, help="runs per row (the fewest CPU seconds count)")
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument("--markdown", help="write the table here")
    parser.add_argument("--estimates", help="write the precompile row's seconds per kernel here (JSON)")
    args = parser.parse_args(argv)
    results = run(args.repeats)
    table = render_markdown(results)
    write_outputs(table, results, json_path=args.json, markdown=args.markdown, title="# Compile time")
    if args.estimates:
        with open(args.estimates, "w") as f:
            estimates = {"measured_by": "python -m collision_env.bench.compile", "machine": results["machine"]}
            json.dump(
                {
                    **estimates,
                    "timestamp": results["timestamp"],
                    "seconds": {k: round(v, 1) for k, v in results["kernel_seconds"].items()},
                },
                f,
                indent=1,
            )
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
