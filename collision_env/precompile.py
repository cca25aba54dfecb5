"""Compile every kernel of the engine and the environments now, instead of at the first step.

    python -m collision_env.precompile

numba compiles a kernel the first time it runs and caches it on disk (see
``collision_env.engine._jit``). Running this once after installing (``make`` does) means no later
process waits for the compiler, and parallel processes (test workers, RLlib env runners, SB3
subprocesses) do not each compile the same kernels at once. It is harmless to run again: it then
only loads the cache. This is the one way to compile ahead, from the shell or from Python
(:func:`precompile`).

While it compiles, one line per kernel on stderr says which part of the engine it is, how many
kernels are left and about how long they will take:
``collision_env: compiling exact mode for elastic scenes (3 of 9 kernels, ~40 s left) ... 14.1 s``.
"""

from __future__ import annotations

import sys
import time
from typing import Any

#: The env options tried beside each env's defaults: the predicted observation (with its aiming
#: term), which runs kernels of its own, and velocity control, a branch of the nudge kernel.
OPTIONS: tuple[dict[str, Any], ...] = ({}, {"observe": "predicted", "aim": "predicted", "control": "velocity"})


#: What the compile notice calls the engine's kernels that Python calls itself (compiled together).
HELPERS = "the engine's checks, nudges and frames"


def plan(envs: bool = True) -> list[str]:
    """What :func:`precompile` compiles, in order, as the compile notice calls each kernel: every
    engine mode's kernel for each kind of scene, the engine's helpers, then (``envs``) the
    environments' kernels."""
    from collision_env.engine.modes import MODES

    kernels: list[Any] = [kernel for spec in MODES.values() for kernel in spec.kernels()]
    labels = [getattr(kernel, "label", None) for kernel in kernels] + [HELPERS]
    if envs:
        from collision_env.envs.task import episodes, finish, nudge, predict

        kernels = [episodes.build_episodes, finish.task_kernel, nudge.nudge_kernel, predict.predict_kernel]
        labels += [getattr(kernel, "label", None) for kernel in kernels]
    return [label for label in labels if label]  # (without numba, kernels have no label)


def precompile(envs: bool = True) -> float:
    """Compile (or load from the on-disk cache) every engine kernel and, with ``envs``, those of
    the environments; returns the seconds it took.

    The engine's stepping kernels are compiled by their signatures (one per mode and kind of
    scene; periodic scenes' kernels are compiled at their first step), then a tiny scene reaches
    the kernels Python calls itself (the start-state checks, nudges, frames). With ``envs``, every
    registered env, single and vector, is made, reset and stepped with its defaults and with
    :data:`OPTIONS`. Without numba there is nothing to compile: it only runs those steps.
    """
    from collision_env.engine._jit import compile_plan

    start = time.perf_counter()
    with compile_plan(plan(envs)):
        _compile_engine()
        if envs:
            _step_every_env()
    return time.perf_counter() - start


def _compile_engine() -> None:
    """Every mode's stepping kernel by its signature (none is run), then a tiny scene that reaches
    the kernels Python calls itself: the start-state checks, a nudge, frames, a backward step."""
    import numpy as np

    from collision_env.engine import Scene, Simulator
    from collision_env.engine._jit import compile_for, compile_phase
    from collision_env.engine.argpack import pack_arrays
    from collision_env.engine.modes import MODES
    from collision_env.engine.state import START_STEP

    for spec in MODES.values():
        for kernel in spec.kernels():
            compile_for(kernel, pack_arrays([np.zeros(1)]), 1.0, START_STEP)
    with compile_phase(HELPERS):
        sim = Simulator(Scene(), [[-0.5, 0.0], [0.5, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 2.0])
        sim.nudge([[0.1, 0.0], [0.0, 0.0]])
        sim.frames(0.3, 2)
        sim.step(-0.3)


def _step_every_env() -> None:
    import gymnasium as gym

    import collision_env

    for options in OPTIONS:
        for env_id in collision_env.ENV_IDS:
            env = gym.make(env_id, **options)
            env.reset(seed=0)
            env.step(env.action_space.sample())
            env.close()
            envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point", **options)
            envs.reset(seed=0)
            envs.step(envs.action_space.sample())
            envs.close()


def main() -> None:
    """``python -m collision_env.precompile``: :func:`precompile`, then one line saying where the kernels are."""
    from collision_env.engine import BACKEND
    from collision_env.engine._jit import cache_dir

    seconds = precompile()
    where = f"cached in {cache_dir()}" if BACKEND == "numba" else "numba is not installed: nothing to compile"
    print(f"collision_env: kernels ready in {seconds:.1f} s ({where})", file=sys.stderr)


if __name__ == "__main__":
    main()
