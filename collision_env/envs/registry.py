"""The task registry: a task is one entry, and everything the suite knows about it is derived from it.

A task is an env class whose docstring tables its observation, action, reward, start state and
episode end (the layout of Gymnasium's classic-control envs), carrying a :class:`Task` entry: its id,
its preset name, its ``TaskConfig`` fields, the engine benchmark scene it matches and, optionally,
whose hyperparameters the sample agent borrows when ``agents/hyperparams/ppo.yml`` has no entry for
it. :func:`register_task` derives the rest:

* the preset, in ``PRESETS`` (so ``gym.make("CollisionEnv/Target-v0", preset=...)`` reaches it);
* the id, in ``PRESET_IDS`` and in ``collision_env.ENV_IDS``;
* the native vector env class (``<Name>VectorEnv``, a :class:`CollisionTargetVectorEnv` of the preset);
* the Gymnasium registration, with both entry points and the episode length of the config;
* the benchmark's scene map (:func:`bench_scenes`) and the agents' fallback
  (:func:`hyperparams_fallback`).

A new task is therefore one file::

    class SpinEnv(CollisionTargetEnv):
        \"\"\"## Description ... ## Episode End ...\"\"\"

        task = Task(env_id="CollisionEnv/Spin-v0", preset="spin", config=dict(n_balls=2, ...),
                    bench_scene="2 balls")

    SpinVectorEnv = register_task(SpinEnv)

imported from ``collision_env/envs/__init__.py`` (which exports the classes).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from gymnasium.envs.registration import register as _gym_register
from gymnasium.envs.registration import registry as _gym_registry

from collision_env.envs._config import PRESETS, make_config
from collision_env.envs.target_env import CollisionTargetEnv
from collision_env.envs.vector import CollisionTargetVectorEnv

#: The sections every task's docstring has, in this order.
DOC_SECTIONS = (
    "## Description",
    "## Action Space",
    "## Observation Space",
    "## Rewards",
    "## Starting State",
    "## Episode End",
)

#: The hyperparameter entry an id without one of its own falls back to.
DEFAULT_HYPERPARAMS = "default"


@dataclass(frozen=True)
class Task:
    """One task of the suite (see the module docstring): what an env class carries as ``task``."""

    env_id: str
    """The Gymnasium id."""
    preset: str
    """Its name among ``PRESETS``."""
    config: Mapping[str, Any]
    """The ``TaskConfig`` fields that differ from the defaults (checked at registration)."""
    bench_scene: str
    """The engine benchmark scene it matches most closely (shown beside its step rates)."""
    hyperparams_like: str | None = None
    """The id whose hyperparameter entry serves when the file has none for this one (``None``: the
    file's ``default`` entry)."""


@dataclass(frozen=True)
class RegisteredEnv:
    """A registered id: its single and native vector env classes, and the task it runs (if a preset)."""

    env_id: str
    single: type[CollisionTargetEnv]
    vector: type[CollisionTargetVectorEnv]
    bench_scene: str
    task: Task | None = field(default=None)


#: Every registered id, in registration order.
REGISTERED: dict[str, RegisteredEnv] = {}
#: Preset name -> registered id.
PRESET_IDS: dict[str, str] = {}


def _entry_point(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def register_env(
    env_id: str,
    single: type[CollisionTargetEnv],
    vector: type[CollisionTargetVectorEnv],
    bench_scene: str,
    task: Task | None = None,
) -> None:
    """Register ``env_id`` with Gymnasium (single and vector entry points) and in ``REGISTERED``."""
    steps = make_config(single.preset).n_steps
    if env_id not in _gym_registry:  # re-importing (e.g. importlib.reload) must not re-register
        _gym_register(
            id=env_id,
            entry_point=_entry_point(single),
            vector_entry_point=_entry_point(vector),
            max_episode_steps=steps,
        )
    REGISTERED[env_id] = RegisteredEnv(env_id, single, vector, bench_scene, task)


def register_task(env_class: type) -> type:
    """Register the task that ``env_class`` carries (its ``task`` attribute); returns its vector env class.

    Checks the entry first (a ``ValueError`` names what is wrong, and nothing is registered): a
    ``CollisionTargetEnv`` subclass with a :class:`Task`, a new id and preset, a config that
    ``TaskConfig`` accepts, and a docstring with every section of ``DOC_SECTIONS``. The vector env
    class is named after the env class (``FooEnv`` -> ``FooVectorEnv``) and bound in its module, so
    that both entry points are importable.
    """
    task = getattr(env_class, "task", None)
    name = getattr(env_class, "__name__", repr(env_class))
    if not (isinstance(env_class, type) and issubclass(env_class, CollisionTargetEnv)):
        raise TypeError(f"register_task: expected a CollisionTargetEnv subclass, got {name}")
    if not isinstance(task, Task):
        raise ValueError(f"{name}.task: expected a Task, got {task!r}")
    if task.env_id in REGISTERED or task.env_id in _gym_registry:
        raise ValueError(f"{name}.task.env_id: {task.env_id!r} is already registered")
    if task.preset in PRESETS:
        raise ValueError(f"{name}.task.preset: {task.preset!r} is already a preset")
    if not name.endswith("Env"):
        raise ValueError(f"{name}: an env class name ends in 'Env' (its vector env is named after it)")
    doc = env_class.__doc__ or ""
    missing = [s for s in DOC_SECTIONS if s not in doc]
    if missing:
        raise ValueError(f"{name}: the docstring lacks the section(s) {missing}")
    try:
        make_config(None, **task.config)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name}.task.config: {err}") from None

    vector = type(
        f"{name[:-3]}VectorEnv",
        (CollisionTargetVectorEnv,),
        {
            "__doc__": f"Native vector version of :class:`{name}` (see :class:`CollisionTargetVectorEnv`).",
            "__module__": env_class.__module__,
            "preset": task.preset,
        },
    )
    setattr(sys.modules[env_class.__module__], vector.__name__, vector)
    env_class.preset = task.preset
    PRESETS[task.preset] = dict(task.config)
    PRESET_IDS[task.preset] = task.env_id
    register_env(task.env_id, env_class, vector, task.bench_scene, task)
    return vector


def bench_scenes() -> dict:
    """Registered id -> the engine benchmark scene it matches most closely."""
    return {env_id: reg.bench_scene for env_id, reg in REGISTERED.items()}


def hyperparams_fallback(env_id: str) -> str:
    """The hyperparameter entry ``env_id`` uses when the file has none of its own."""
    reg = REGISTERED.get(env_id)
    if reg is None or reg.task is None or reg.task.hyperparams_like is None:
        return DEFAULT_HYPERPARAMS
    return reg.task.hyperparams_like
