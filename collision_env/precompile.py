"""Compile every kernel of the engine and the environments now, instead of at the first step.

    python -m collision_env.precompile

numba compiles a kernel the first time it runs and caches it on disk (see
``collision_env.engine._jit``). Running this once after installing (``make`` does) means no later
process waits for the compiler, and parallel processes (test workers, RLlib env runners, SB3
subprocesses) do not each compile the same kernels at once. It is harmless to run again: it then
only loads the cache.
"""

from __future__ import annotations

import sys
import time
from typing import Any

#: The env options tried beside each env's defaults: the predicted observation (with its aiming
#: term), which runs kernels of its own, and velocity control, a branch of the nudge kernel.
OPTIONS: tuple[dict[str, Any], ...] = ({}, {"observe": "predicted", "aim": "predicted", "control": "velocity"})


def precompile() -> float:
    """Run every engine mode and one step of every registered env, single and vector, with its
    defaults and with :data:`OPTIONS`; returns seconds."""
    import gymnasium as gym

    import collision_env
    from collision_env.engine import warm_up

    start = time.perf_counter()
    warm_up()
    for env_id in collision_env.ENV_IDS:
        for options in OPTIONS:
            env = gym.make(env_id, **options)
            env.reset(seed=0)
            env.step(env.action_space.sample())
            env.close()
            envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point", **options)
            envs.reset(seed=0)
            envs.step(envs.action_space.sample())
            envs.close()
    return time.perf_counter() - start


def main() -> None:
    from collision_env.engine import BACKEND
    from collision_env.engine._jit import cache_dir

    seconds = precompile()
    where = f"cached in {cache_dir()}" if BACKEND == "numba" else "numba is not installed: nothing to compile"
    print(f"collision_env: kernels ready in {seconds:.1f} s ({where})", file=sys.stderr)


if __name__ == "__main__":
    main()
