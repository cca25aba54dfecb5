"""stable-baselines3 adapter: the native vector env as an SB3 ``VecEnv`` (needs stable-baselines3).

SB3 cannot consume a Gymnasium ``VectorEnv``; :class:`CollisionSB3VecEnv` runs the native batched env
in same-step autoreset mode and speaks SB3's API: ``reset()`` returns only the observation (the
reset infos are in ``reset_infos``), ``step`` returns ``obs, rewards, dones, infos`` with one dict
per sub-env holding ``is_success``, ``TimeLimit.truncated`` and, when the episode ended,
``terminal_observation``. ``seed(s)`` then ``reset()`` seeds sub-env i with ``s + i``, as SB3's own
``DummyVecEnv`` does, so both give the same episodes.

>>> from collision_env.envs.sb3 import make_sb3_vec_env
>>> venv = make_sb3_vec_env("CollisionEnv/OneBallTarget-v0", n_envs=8, seed=0)  # VecMonitor-wrapped
>>> # PPO("MlpPolicy", venv).learn(100_000)
"""

from __future__ import annotations

from typing import Any, cast

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode

from collision_env.extras import require

require("train", "collision_env.envs.sb3", modules=("stable_baselines3",))  # an optional extra: say how to get it

from stable_baselines3.common.vec_env import VecEnv, VecMonitor  # noqa: E402
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices  # noqa: E402

from collision_env.envs.vector import CollisionTargetVectorEnv  # noqa: E402


class CollisionSB3VecEnv(VecEnv):
    """An SB3 ``VecEnv`` over :class:`~collision_env.envs.CollisionTargetVectorEnv`.

    Give it a registered id (``env_id``, with ``n_envs`` and env kwargs) or an existing native
    vector env (``venv``; it must use ``AutoresetMode.SAME_STEP``). Per-step infos carry
    ``is_success``, ``targets_hit``, ``nudge`` and ``TimeLimit.truncated``; add ``VecMonitor`` for episode
    statistics (``make_sb3_vec_env`` does).
    """

    def __init__(
        self,
        env_id: str | None = None,
        n_envs: int = 1,
        venv: gym.vector.VectorEnv | None = None,
        **env_kwargs: Any,
    ) -> None:
        if venv is None:
            if env_id is None:
                raise ValueError("give env_id (a registered id) or venv (a native vector env)")
            import collision_env  # noqa: F401  (registers the ids)

            venv = gym.make_vec(
                env_id,
                num_envs=n_envs,
                vectorization_mode="vector_entry_point",
                autoreset_mode=AutoresetMode.SAME_STEP,
                **env_kwargs,
            )
        if not isinstance(venv.unwrapped, CollisionTargetVectorEnv):
            raise ValueError(f"venv: expected a CollisionTargetVectorEnv, got {type(venv).__name__}")
        if venv.metadata.get("autoreset_mode") != AutoresetMode.SAME_STEP:
            raise ValueError(
                "venv: SB3 needs same-step autoreset; create it with autoreset_mode=AutoresetMode.SAME_STEP"
            )
        self.venv = venv
        """The native vector env underneath (same-step autoreset)."""
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self._actions: np.ndarray | None = None

    # ------------------------------------------------------------------------------------- #
    def reset(self) -> np.ndarray:
        """Reset every sub-env (with the seeds and options ``seed`` and ``set_options`` gave): the
        observations; their infos are in ``reset_infos``."""
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        options = None
        if any(self._options):
            if any(o != self._options[0] for o in self._options):
                raise ValueError("per-sub-env reset options differ; the batched env takes one options dict")
            options = dict(self._options[0])
        # (one seed per sub-env, as CollisionTargetVectorEnv.reset takes; VectorEnv declares int | None)
        obs, info = self.venv.reset(seed=cast(Any, seeds), options=options)
        self.reset_infos = self._split(info, np.ones(self.num_envs, dtype=bool))
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        """Keep the actions for :meth:`step_wait` (the batched step runs there)."""
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """Step every sub-env: SB3's ``(observations, rewards, dones, infos)``, a finished sub-env's
        last observation in its info's ``terminal_observation`` and ``TimeLimit.truncated`` set."""
        obs, reward, term, trunc, info = self.venv.step(np.asarray(self._actions, dtype=np.float32))
        dones = term | trunc
        n = self.num_envs
        limit = (trunc & ~term).tolist()
        if dones.any():
            fin = info["final_info"]
            success = np.where(dones, fin["is_success"], info["is_success"]).tolist()
            hits = np.where(dones, fin["targets_hit"], info["targets_hit"]).tolist()
            nudge = np.where(dones, fin["nudge"], info["nudge"]).tolist()
        else:
            success = info["is_success"].tolist()
            hits = info["targets_hit"].tolist()
            nudge = info["nudge"].tolist()
        infos = [
            {"is_success": success[i], "targets_hit": hits[i], "nudge": nudge[i], "TimeLimit.truncated": limit[i]}
            for i in range(n)
        ]
        if dones.any():
            final_obs = info["final_obs"]
            for i in np.flatnonzero(dones):
                infos[i]["terminal_observation"] = final_obs[i]
                self.reset_infos[i] = {"is_success": False, "targets_hit": 0, "nudge": 0.0}
        return obs, reward.astype(np.float32), dones, infos

    @staticmethod
    def _split(info: dict, mask: np.ndarray) -> list:
        keys = [k for k in ("is_success", "targets_hit", "nudge", "energy", "time", "event_cap") if k in info]
        return [{k: info[k][i].item() for k in keys} for i in range(len(mask))]

    def close(self) -> None:
        """Close the native vector env."""
        self.venv.close()

    # ------------------------------------------------------------------------------------- #
    def get_images(self) -> list[np.ndarray | None]:
        """One frame per sub-env (the native env's ``render``), or ``None`` each without a render mode."""
        frames = self.venv.render()
        return cast("list[np.ndarray | None]", list(frames)) if frames is not None else [None] * self.num_envs

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list:
        """The native env's attribute, once per sub-env of ``indices`` (the sub-envs share it)."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set the native env's attribute (for every sub-env at once: ``indices`` must cover them all)."""
        if indices is not None and len(list(self._get_indices(indices))) != self.num_envs:
            raise ValueError("set_attr: the batched env shares its attributes; set them for all sub-envs at once")
        setattr(self.venv, attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: VecEnvIndices = None, **method_kwargs: Any
    ) -> list:
        """Call the native env's method once; its result per sub-env of ``indices`` (a tuple with one
        item per sub-env is split among them)."""
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        idx = list(self._get_indices(indices))
        if isinstance(result, tuple) and len(result) == self.num_envs:
            return [result[i] for i in idx]
        return [result for _ in idx]

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: VecEnvIndices = None) -> list[bool]:
        """``False`` for each sub-env: the scenes of the batched env are not Gymnasium envs to wrap."""
        return [False for _ in self._get_indices(indices)]


def make_sb3_vec_env(
    env_id: str,
    n_envs: int = 8,
    seed: int | None = None,
    monitor: bool = True,
    monitor_file: str | None = None,
    **env_kwargs: Any,
) -> VecEnv:
    """A :class:`CollisionSB3VecEnv` for ``env_id`` (seeded with ``seed + i`` at the first reset),
    wrapped in ``VecMonitor(info_keywords=("is_success",))`` (writing ``monitor_file`` if given)
    unless ``monitor=False``."""
    venv = CollisionSB3VecEnv(env_id, n_envs, **env_kwargs)
    if seed is not None:
        venv.seed(seed)
    return VecMonitor(venv, filename=monitor_file, info_keywords=("is_success",)) if monitor else venv
