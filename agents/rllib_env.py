"""collision_env ids as RLlib environments: a creator that works in any Ray worker process.

RLlib's env runners are separate processes (on other machines, in a cluster) that never import
``collision_env``, so a bare id such as ``"CollisionEnv/OneBallTarget-v0"`` is unknown there
(Gymnasium raises ``NamespaceNotFound``). :func:`make_env` imports the package first, and is what
:func:`rllib_env_name` registers with Ray's registry under a name of its own; Ray ships the creator
to every worker.

RLlib calls the creator once per env runner with ``num_envs`` in its config when the runner
vectorises through the registered ``vector_entry_point`` (``gym_env_vectorize_mode=
"vector_entry_point"``): it then returns the project's native vector env, one batched engine for
all sub-envs. Without ``num_envs`` (RLlib's default ``"sync"`` mode: one ``gym.make`` per sub-env)
it returns a single env.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
from gymnasium.vector import VectorWrapper

#: RLlib's names for the two ways an env runner can vectorise its sub-envs.
VECTORIZE_MODES = {"native": "vector_entry_point", "sync": "sync"}


class ListFriendlyInfos(VectorWrapper):
    """Drop the native vector env's batch-wide ``impacts`` entry from the infos.

    RLlib splits a vector env's info dict into one dict per sub-env (Gymnasium's
    ``DictInfoToList``), which needs an array per key; the native env reports every sub-env's
    impacts in one :class:`~collision_env.engine.Impacts` record array instead.
    """

    @staticmethod
    def _strip(info: dict) -> dict:
        return {k: v for k, v in info.items() if k not in ("impacts", "_impacts")}

    def reset(self, **kwargs: Any) -> tuple[Any, dict]:
        obs, info = self.env.reset(**kwargs)
        return obs, self._strip(info)

    def step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict]:
        obs, reward, term, trunc, info = self.env.step(actions)
        return obs, reward, term, trunc, self._strip(info)


def make_env(config: dict[str, Any]) -> gym.Env | gym.vector.VectorEnv:
    """RLlib env creator: ``config`` holds ``env_id``, the env keywords and, for the native vector
    env, ``num_envs``. Imports ``collision_env`` itself, so it works in a fresh worker process."""
    import collision_env  # noqa: F401  (registers the ids in this process)

    kwargs = dict(config)
    env_id = kwargs.pop("env_id")
    num_envs = kwargs.pop("num_envs", None)
    if num_envs is None:
        return gym.make(env_id, **kwargs)
    return ListFriendlyInfos(
        gym.make_vec(env_id, num_envs=int(num_envs), vectorization_mode="vector_entry_point", **kwargs)
    )


def rllib_env_name(env_id: str) -> str:
    """Register :func:`make_env` with Ray's registry for ``env_id``; returns the name to give RLlib."""
    from ray.tune.registry import register_env

    name = f"collision_env:{env_id}"
    register_env(name, make_env)
    return name
