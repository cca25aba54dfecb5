"""Where a PPO training run's wall-clock time goes, and the CPU time it took.

:func:`time_split` is a callback that wraps, on one model's policy and env (instance attributes
only, nothing global, removed when training ends), the calls that make up stable-baselines3's PPO
loop and adds up the time spent in each (a rollout runs from the callback's ``on_rollout_start`` to
its ``on_rollout_end``, an update from there to the next rollout):

| part | what is timed |
|---|---|
| engine | ``BatchSimulator.step`` of the env's engine and its look-ahead copy (``observe="predicted"``) |
| env, besides the engine | the rest of the innermost ``VecEnv.step_wait``: task kernels, the SB3 adapter |
| policy forward, acting | ``policy.forward`` while collecting rollouts (sampling the actions) |
| policy forward, training | ``policy.evaluate_actions`` in ``PPO.train`` |
| backward and optimiser | the rest of the update: losses, ``backward()``, clipping, ``Adam.step``, logging |
| rollout bookkeeping | the rest of the rollout: ``VecMonitor``, ``VecNormalize``, tensors, the buffer, callbacks, GAE |
| other | the rest of ``learn``: its set-up (the first reset of the env) |

The engine is timed only with the native vector env (SB3's dummy and subprocess vector envs build
their own envs); then its part is ``None``. The timers cost a ``perf_counter`` pair per call.

On a machine shared with other work the wall-clock time of a run grows with the load, while its CPU
time (:func:`cpu_seconds`: user and system time, summed over the process's threads and its ended
child processes) stays that of the work done: a run's ``config.yml`` records both.
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict
from typing import Any

from collision_env.bench.timing import add_timer

PARTS = (
    "engine",
    "env, besides the engine",
    "policy forward, acting",
    "policy forward, training",
    "backward and optimiser",
    "rollout bookkeeping",
    "other",
)


def cpu_seconds() -> float:
    """CPU time (user + system, s) of this process so far, every thread of it, plus that of its
    child processes that have ended and been waited for (``resource.getrusage``; on a platform
    without it, this process's own, ``time.process_time``).

    The workers of SB3's ``SubprocVecEnv`` count once the vector env is closed (which waits for
    them); the native vector env and ``DummyVecEnv`` step in this process."""
    if sys.platform == "win32":
        return time.process_time()
    import resource

    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def time_split(venv: Any) -> Any:
    """A stable-baselines3 callback that times the parts of ``learn`` (see the module docstring).

    Give it to ``learn`` with the model's vector env ``venv``; after training, ``split(total)``
    gives the seconds per part of a ``learn`` call that took ``total`` seconds. The rollouts and
    the updates are timed by the callback's hooks, the env and the policy's forward passes by
    timers on those objects (never on the model, which is saved with its attributes).
    """
    from stable_baselines3.common.callbacks import BaseCallback

    class TimeSplit(BaseCallback):
        def __init__(self):
            super().__init__()
            self.raw: dict = defaultdict(float)
            self._mark: float | None = None
            self.engine_timed = False
            self._wrapped: list[tuple[object, str]] = []  # (object, attribute) of the timers added

        def _on_training_start(self) -> None:
            self._timed(self.model.policy, "forward", "act")
            self._timed(self.model.policy, "evaluate_actions", "train_forward")
            inner = venv
            while getattr(inner, "venv", None) is not None and not _is_native(inner):
                inner = inner.venv  # below VecNormalize and VecMonitor, which are saved with their attributes
            self._timed(inner, "step_wait", "env")
            core = _native_core(venv)
            if core is not None:
                for sim in core.engines:
                    self._timed(sim, "step", "engine")
                self.engine_timed = True

        def _lap(self, key: str) -> None:
            now = time.perf_counter()
            if self._mark is not None:
                self.raw[key] += now - self._mark
            self._mark = now

        def _on_rollout_start(self) -> None:
            if self._mark is not None:
                self._lap("train")  # since the last rollout ended: PPO's update
            self._mark = time.perf_counter()

        def _on_rollout_end(self) -> None:
            self._lap("rollouts")

        def _on_training_end(self) -> None:
            self._lap("train")
            self._mark = None
            for obj, name in self._wrapped:
                delattr(obj, name)  # the env and policy go on without the timers
            self._wrapped = []

        def _on_step(self) -> bool:
            return True

        def _timed(self, obj, name: str, key: str) -> None:
            add_timer(obj, name, self.raw, key)
            self._wrapped.append((obj, name))

        def split(self, total: float) -> dict:
            """Seconds per part (``PARTS``) of a ``learn`` call that took ``total`` seconds."""
            r = self.raw
            engine = r["engine"] if self.engine_timed else None
            return {
                "engine": engine,
                "env, besides the engine": r["env"] - (engine or 0.0),
                "policy forward, acting": r["act"],
                "policy forward, training": r["train_forward"],
                "backward and optimiser": r["train"] - r["train_forward"],
                "rollout bookkeeping": r["rollouts"] - r["env"] - r["act"],
                "other": total - r["rollouts"] - r["train"],
            }

    return TimeSplit()


def _is_native(venv) -> bool:
    from collision_env.envs.sb3 import CollisionSB3VecEnv

    return isinstance(venv, CollisionSB3VecEnv)


def _native_core(venv):
    """The ``TaskCore`` under SB3 wrappers and the native-env adapter, or None for other vector envs."""
    while not _is_native(venv):
        venv = getattr(venv, "venv", None)
        if venv is None:
            return None
    return venv.venv.unwrapped.core
