"""Environment benchmark: step cost of every registered id against Gymnasium's CartPole, same run.

    python -m collision_env.bench.envs [--seconds 1.0] [--num-envs 1024] [--modes exact naive posteriori]

Prints two Markdown tables (ratios, not pass/fail tests); ``--markdown`` also writes them to a page
(``docs/bench/envs_bench.md``):

* single env via ``gym.make`` (all default wrappers, random actions, resets included), in us per
  step and as a multiple of ``CartPole-v1`` via ``gym.make``;
* the native vector env at ``--num-envs`` sub-envs (next-step autoreset, random actions), in
  env-steps/s and as a fraction of Gymnasium's ``CartPoleVectorEnv``.

Each env's slices alternate with CartPole's (:func:`~collision_env.bench.timing.best_rates`), and
its ratio is to the CartPole slices timed beside it, so that a machine busy with other work slows
both alike.

The "engine" column is the part of a step spent in the engine's own calls: for the single env,
``nudge`` and ``step`` of the ``BatchSimulator`` timed on a copy of the env's engine in the same
state; for the vector env, the share of the env's run spent in its engines' ``step`` calls.
:func:`single_env_us` and :func:`vector_env_steps_per_s` are the env timers every benchmark uses.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import cast

import gymnasium as gym
import numpy as np

import collision_env
from collision_env.bench.readme import write_outputs
from collision_env.engine import MODES
from collision_env.envs import CollisionTargetEnv, CollisionTargetVectorEnv

from .machine import cpus, machine, timestamp, versions
from .timing import add_timer, best_rate, best_rates

REPEATS = 5  # each figure is the best of this many equal slices of --seconds (robust to a busy machine)


def single_env_us(env: gym.Env, seconds: float, slices: int = REPEATS) -> float:
    """Microseconds per ``env.step`` (random actions, resets included): the best of ``slices`` slices."""
    return 1e6 / best_rate(_single_steps(env), seconds, slices)


def _single_steps(env: gym.Env) -> Callable[[], int]:
    """A chunk of ``env.step`` calls for :func:`best_rate` (random actions, resets included), after
    a warm-up (which compiles the kernels on a first run)."""
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(1024)]

    def steps(count: int = 500) -> int:
        for i in range(count):
            _, _, term, trunc, _ = env.step(actions[i % len(actions)])
            if term or trunc:
                env.reset()
        return count

    steps(300)  # warm-up
    return steps


def vector_env_steps_per_s(venv: gym.vector.VectorEnv, seconds: float, slices: int = REPEATS) -> float:
    """Env-steps per second of a vector env (random actions, its own autoreset): the best of ``slices``."""
    return best_rate(_vector_steps(venv), seconds, slices)


def _vector_steps(venv: gym.vector.VectorEnv) -> Callable[[], int]:
    """A chunk of ``venv.step`` calls for :func:`best_rate` (random actions, its own autoreset),
    after a warm-up."""
    venv.reset(seed=0)
    venv.action_space.seed(0)
    actions = [venv.action_space.sample() for _ in range(16)]

    def steps(count: int = 10) -> int:
        for i in range(count):
            venv.step(actions[i % len(actions)])
        return count * venv.num_envs

    steps()  # warm-up
    return steps


def _engine_us(core, seconds: float, steps: int = 200) -> float:
    """us per (nudge + step) call pair of the engine alone, on a copy of ``core``'s engine (each
    slice starts from the same state, calendar included, as the env's engine would go on)."""
    start = core.batch.copy()
    sim = core.batch.copy()
    dv = np.zeros_like(core.vel)
    dt = core.cfg.dt
    best, total = float("inf"), 0.0
    while total < seconds:
        sim.load(start)
        t0 = time.perf_counter()
        for _ in range(steps):
            sim.nudge(dv, check=False)  # the impulse kernel the env applies from its own nudge kernel
            sim.step(dt)
        elapsed = time.perf_counter() - t0
        total += elapsed
        best = min(best, elapsed / steps * 1e6)
    return best


def _engine_share(venv: gym.vector.VectorEnv, seconds: float) -> float:
    """The engine's share of a vector env's step time: every engine ``step`` of its core (the
    look-ahead engine's too) is timed inside the env's own run, random actions and resets
    included. (A timer costs well under a microsecond, nothing beside a step of a whole batch.)"""
    engines = cast(CollisionTargetVectorEnv, venv.unwrapped).core.engines
    spent = {"engine": 0.0}
    for sim in engines:
        add_timer(sim, "step", spent, "engine")
    try:
        t0 = time.perf_counter()
        vector_env_steps_per_s(venv, seconds, slices=1)
        return spent["engine"] / (time.perf_counter() - t0)
    finally:
        for sim in engines:
            delattr(sim, "step")  # the class's method again


def _fmt_rate(x: float) -> str:
    return f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x / 1e3:.0f} k"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m collision_env.bench.envs",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--seconds", type=float, default=1.0, help="time per measurement (s)")
    parser.add_argument("--num-envs", type=int, default=1024, help="sub-envs of the vector env")
    parser.add_argument("--modes", nargs="+", default=["exact"], choices=MODES, help="engine modes to time the envs in")
    parser.add_argument("--ids", nargs="+", default=list(collision_env.ENV_IDS), help="env ids")
    parser.add_argument("--markdown", metavar="PATH", help="also write the tables to PATH")
    args = parser.parse_args(argv)

    started = time.perf_counter()
    # each env's slices alternate with CartPole's, whose best over the run heads the table
    cart_steps = _single_steps(gym.make("CartPole-v1"))
    single, cart = [], float("inf")
    for env_id in args.ids:
        for mode in args.modes:
            env = gym.make(env_id, mode=mode)
            rate, cart_rate = best_rates([_single_steps(env), cart_steps], args.seconds, REPEATS)
            us, cart = 1e6 / rate, min(cart, 1e6 / cart_rate)
            eng = _engine_us(cast(CollisionTargetEnv, env.unwrapped).core, args.seconds / 2)
            single.append(f"| `{env_id}` | {mode} | {us:.2f} | {eng:.2f} | {us * cart_rate / 1e6:.2f} |")
            env.close()
    single.insert(0, f"| `CartPole-v1` | | {cart:.2f} | | 1.00 |")

    n = args.num_envs
    cart_vec_steps = _vector_steps(gym.make_vec("CartPole-v1", n, vectorization_mode="vector_entry_point"))
    vector, cart_vec = [], 0.0
    for env_id in args.ids:
        for mode in args.modes:
            venv = gym.make_vec(env_id, n, vectorization_mode="vector_entry_point", mode=mode)
            sps, cart_sps = best_rates([_vector_steps(venv), cart_vec_steps], args.seconds, REPEATS)
            cart_vec = max(cart_vec, cart_sps)
            share = _engine_share(venv, args.seconds / 2)
            vector.append(f"| `{env_id}` | {mode} | {_fmt_rate(sps)} | {share:.0%} | {sps / cart_sps:.3f} |")
            venv.close()
    vector.insert(0, f"| `CartPoleVectorEnv` | | {_fmt_rate(cart_vec)} | | 1.000 |")

    v = versions(["gymnasium"])
    text = "\n".join(
        [
            f"`python -m collision_env.bench.envs` on {machine()}, {cpus()} CPUs, "
            f"Python {v['python']}, gymnasium {v['gymnasium']}, numpy {v['numpy']}, engine backend "
            f"`{v['backend']}`; {timestamp()}, {time.perf_counter() - started:.0f} s. Each figure is the "
            f"best of {REPEATS} slices of {args.seconds:g} s, each env's slices alternating with CartPole's "
            "(its ratio is to the CartPole slices beside it; CartPole's row is its best over the run): "
            "compare the ratios.",
            "",
            "Single env via `gym.make` (default wrappers, random actions, resets included); *engine* is the part "
            "spent in the engine's `nudge` + `step`:",
            "",
            "| id | mode | µs per step | engine µs | × CartPole-v1 |",
            "|---|---|---:|---:|---:|",
            *single,
            "",
            f"Native vector env, {n} sub-envs (next-step autoreset, random actions); *engine* is the engine's share "
            "of the step:",
            "",
            "| id | mode | env-steps/s | engine | × CartPoleVectorEnv |",
            "|---|---|---:|---:|---:|",
            *vector,
        ]
    )
    write_outputs(text, markdown=args.markdown)


if __name__ == "__main__":
    main()
