"""The native vector env: one BatchSimulator steps every sub-env at once (no loop over envs).

It is step-for-step identical to ``gym.make_vec(id, n, vectorization_mode="sync")`` for the same seeds
and actions, autoresets included: every sub-env owns its own ``np.random.Generator``, seeded as the
single env would be (``seed + i``), and the per-step task logic is the same batched kernel the single
env runs on a batch of one. Infos follow Gymnasium's vector layout (an array per key and a ``_key``
mask) with one documented difference: ``info["impacts"]`` is a single :class:`Impacts` holding every
sub-env's impacts with their index in the ``scene`` field (the sync vector env has an object array of
per-env ``Impacts``); ``Impacts.for_scene(i)`` splits it.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import ArrayLike

from collision_env.engine import Impacts
from collision_env.envs._config import TaskConfig, keywords_of, make_config
from collision_env.envs._core import TaskCore, check_state_keys
from collision_env.envs.task.layout import ROW_OBSERVE, ROW_RESET, ROW_SKIP, ROW_STEPPED

if TYPE_CHECKING:
    from collision_env.envs.rendering import Renderer

_CLASS_PRESET = "__class_preset__"
_SCALAR_KEYS = ("event_cap", "nudge", "energy", "time", "targets_hit", "is_success")


class CollisionTargetVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`~collision_env.envs.CollisionTargetEnv` on one batched engine.

    Arguments: ``num_envs``, ``max_episode_steps`` (its own truncation, as ``TimeLimit`` does for the
    single env; ``gym.make_vec`` passes the registered value), ``render_mode`` (``"rgb_array"``:
    ``render()`` returns a tuple of frames), ``autoreset_mode`` (``AutoresetMode.NEXT_STEP``, the
    default, or ``SAME_STEP``; also as the strings "NextStep"/"SameStep"), ``preset`` and any
    ``TaskConfig`` field, as for the single env.

    ``reset(seed=s)`` seeds sub-env i with ``s + i`` (a list gives one seed each; ``None`` keeps the
    current generators); ``options={"reset_mask": mask}`` resets only the masked sub-envs.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20, "autoreset_mode": AutoresetMode.NEXT_STEP}
    """Gymnasium's metadata: the render modes, frames per second and the autoreset mode."""
    preset: str | None = "one_ball"
    """The preset a class makes when ``preset`` is not given (a name in ``PRESETS``)."""
    # set before __init__ can fail: gymnasium < 1.3's VectorEnv.__del__ closes a half-made env
    _renderers: list[Renderer] | None = None

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        preset: str | None = _CLASS_PRESET,
        trails: bool = False,
        **overrides: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs: must be a positive integer, got {num_envs!r}")
        if max_episode_steps is not None and (
            not isinstance(max_episode_steps, (int, np.integer)) or max_episode_steps < 1
        ):
            raise ValueError(f"max_episode_steps: must be a positive integer or None, got {max_episode_steps!r}")
        try:
            autoreset_mode = AutoresetMode(autoreset_mode)
        except ValueError:
            raise ValueError(f"autoreset_mode: expected NEXT_STEP or SAME_STEP, got {autoreset_mode!r}") from None
        if autoreset_mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ValueError(f"autoreset_mode: {autoreset_mode} is not supported (NEXT_STEP or SAME_STEP)")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode: expected 'rgb_array' or None, got {render_mode!r}")
        if preset is _CLASS_PRESET:
            preset = type(self).preset
        self.config: TaskConfig = make_config(preset, also=keywords_of(type(self).__init__, gym.make_vec), **overrides)
        """The task every sub-env runs: the preset's fields with the keyword overrides, checked."""
        cfg = self.config
        self.num_envs = int(num_envs)
        """Number of sub-envs: scenes of one batched engine."""
        self.max_episode_steps = None if max_episode_steps is None else int(max_episode_steps)
        """Steps after which a sub-env is truncated (``None``: only by its ``time_limit``)."""
        self.render_mode = render_mode
        """``"rgb_array"`` or ``None``."""
        self.autoreset_mode = autoreset_mode
        """When a finished sub-env is reset: ``AutoresetMode.NEXT_STEP`` or ``SAME_STEP``."""
        self.metadata = {
            **type(self).metadata,
            "autoreset_mode": autoreset_mode,
            "render_fps": max(1, int(round(1.0 / cfg.dt))),
        }
        self.single_action_space = spaces.Box(-1.0, 1.0, (cfg.action_dim,), np.float32)
        """One sub-env's action space, as the single env's."""
        self.single_observation_space = spaces.Box(-1.0, 1.0, (cfg.obs_dim,), np.float32)
        """One sub-env's observation space, as the single env's."""
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        """``(num_envs, action_dim)``: one action per sub-env."""
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        """``(num_envs, obs_dim)``: one observation per sub-env."""

        self._core = TaskCore(cfg, self.num_envs)
        self._rngs: list = [None] * self.num_envs
        self._rng_seeds: list = [None] * self.num_envs
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._all = np.ones(self.num_envs, dtype=bool)
        # the task kernel's row flags (which it only reads): every row stepped, and a buffer for a
        # step with resets
        self._stepped_rows = np.full(self.num_envs, ROW_STEPPED, dtype=np.int8)
        self._rows = np.empty(self.num_envs, dtype=np.int8)
        self._trails = bool(trails)
        self._renderers = None

    # ------------------------------------------------------------------------------------- #
    def _seed_envs(self, seed, mask) -> None:
        n = self.num_envs
        seeds: list[int | None]
        if seed is None:
            seeds = [None] * n
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError(f"seed: a list of seeds must have length num_envs={n}, got {len(seeds)}")
        for i in np.flatnonzero(mask):
            if seeds[i] is not None:
                self._rngs[i], self._rng_seeds[i] = seeding.np_random(seeds[i])
            elif self._rngs[i] is None:
                self._rngs[i], self._rng_seeds[i] = seeding.np_random()
        if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            self._np_random, self._np_random_seed = seeding.np_random(int(seed))

    def _info(self, energy, event_cap, nudge, success, n_hit, imp) -> dict:
        every = np.ones(self.num_envs, dtype=bool)  # (each key's mask a copy: cheaper than a new array)
        info = {"impacts": Impacts(imp), "_impacts": every}
        for key, value in (
            ("event_cap", event_cap),
            ("nudge", nudge),
            ("energy", energy),
            ("time", self._core.time.copy()),  # (the clock itself moves on: a kept info keeps its time)
            ("targets_hit", n_hit),
            ("is_success", success),
        ):
            info[key] = value
            info["_" + key] = every.copy()
        return info

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset every sub-env, or those of ``options={"reset_mask": mask}``: ``(observations, info)``
        (see the class docstring for ``seed``)."""
        options = dict(options) if options else {}
        mask = options.pop("reset_mask", None)
        if mask is None:
            mask = self._all
        else:
            if not isinstance(mask, np.ndarray) or mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ValueError(f"options['reset_mask']: expected a ({self.num_envs},) bool array, got {mask!r}")
            if not mask.any():
                raise ValueError("options['reset_mask']: must select at least one sub-env")
        self._seed_envs(seed, mask)
        idx = np.flatnonzero(mask)
        core = self._core
        core.reset_scenes(idx, [self._rngs[i] for i in idx])
        flags = np.where(mask, ROW_RESET, ROW_OBSERVE).astype(np.int8)  # the others are observed unchanged
        imp = core.empty_impacts()
        obs = core.finish(flags, imp, self._fresh_obs())
        _, _, _, success, n_hit, energy, _ = core.outputs()
        self._autoreset[mask] = False
        if self.render_mode is not None:
            renderers = self._get_renderers()
            for i in idx:
                renderers[i].start()
        info = self._info(energy, np.zeros(self.num_envs, dtype=bool), np.zeros(self.num_envs), success, n_hit, imp)
        if not mask.all():  # a partial reset reports (and masks) only the sub-envs it reset
            for key in _SCALAR_KEYS:
                info[key] = np.where(mask, info[key], np.zeros_like(info[key]))
                info["_" + key] = mask.copy()
            info["_impacts"] = mask.copy()
        return obs, info

    def _fresh_obs(self):
        # (not zeroed: the task kernel writes every entry of every row it is given to observe, and
        # each call the fresh array is given to observes every row)
        return np.empty((self.num_envs, self._core.obs_dim), dtype=np.float32)

    def step(self, actions: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Step every sub-env (one row of ``actions`` each) in one call of the batched engine:
        ``(observations, rewards, terminations, truncations, info)``, the single env's info keys as
        arrays; finished sub-envs are reset as ``autoreset_mode`` says."""
        if self._rngs[0] is None:
            raise ResetNeeded("call reset() before step() on the vector env")
        TaskCore.check_actions(actions, "actions")
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"actions: expected shape {self.action_space.shape}, got {a.shape}")
        if not a.flags.c_contiguous:  # (the nudge kernel takes C-contiguous actions: see TaskCore._bind)
            a = np.ascontiguousarray(a)
        core = self._core
        B = self.num_envs
        cap_limit = self.max_episode_steps
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            resetting = self._autoreset
            any_reset = bool(resetting.any())
            active = ~resetting if any_reset else self._all
            imp = core.advance(a, active, self.config.dt)
            event_cap = core.batch.cap_reached
            if any_reset:
                idx = resetting.nonzero()[0]
                core.reset_scenes(idx, [self._rngs[i] for i in idx])
                flags = self._rows
                flags.fill(ROW_STEPPED)
                flags[idx] = ROW_RESET
                if len(imp):
                    imp = imp[active[imp["scene"]]]
                event_cap = event_cap & active
            else:
                flags = self._stepped_rows
            obs = core.finish(flags, imp, self._fresh_obs())
            reward, term, trunc, success, n_hit, energy, nudge = core.outputs()
            if cap_limit is not None:
                trunc |= (core.steps >= cap_limit) & active
            self._autoreset = term | trunc
            info = self._info(energy, event_cap, nudge, success, n_hit, imp)
            if self._renderers is not None:
                self._record(self._renderers, imp, resetting if any_reset else None)
            return obs, reward, term, trunc, info

        # SAME_STEP: step everything, then reset the sub-envs that ended and report their last step
        imp = core.advance(a, self._all, self.config.dt)
        event_cap = core.batch.cap_reached
        obs = core.finish(self._stepped_rows, imp, self._fresh_obs())
        reward, term, trunc, success, n_hit, energy, nudge = core.outputs()
        if cap_limit is not None:
            trunc |= core.steps >= cap_limit
        done = term | trunc
        if self._renderers is not None:
            self._record(self._renderers, imp, None)
        if not done.any():
            return obs, reward, term, trunc, self._info(energy, event_cap, nudge, success, n_hit, imp)
        idx = np.flatnonzero(done)
        in_done = done[imp["scene"]]
        final_obs = np.full(B, None, dtype=object)
        for i in idx:
            final_obs[i] = obs[i].copy()
        final_info = {"impacts": Impacts(imp[in_done]), "_impacts": done.copy()}
        time_now = core.time
        for key, value in (
            ("event_cap", event_cap),
            ("nudge", nudge),
            ("energy", energy),
            ("time", time_now),
            ("targets_hit", n_hit),
            ("is_success", success),
        ):
            v = np.zeros_like(value)
            v[done] = value[done]
            final_info[key] = v
            final_info["_" + key] = done.copy()
        core.reset_scenes(idx, [self._rngs[i] for i in idx])
        flags = np.where(done, ROW_RESET, ROW_SKIP).astype(np.int8)
        core.finish(flags, imp[:0], obs)  # the reset sub-envs' first observations, in place
        _, _, _, _, r_hit, r_energy, _ = core.outputs()
        event_cap = event_cap & ~done
        energy = np.where(done, r_energy, energy)
        success = success & ~done
        n_hit = np.where(done, r_hit, n_hit)
        info = self._info(energy, event_cap, np.where(done, 0.0, nudge), success, n_hit, imp[~in_done])
        info["final_obs"] = final_obs
        info["_final_obs"] = done.copy()
        info["final_info"] = final_info
        info["_final_info"] = done.copy()
        if self._renderers is not None:
            for i in idx:
                self._renderers[i].start()
        return obs, reward, term, trunc, info

    # ------------------------------------------------------------------------------------- #
    def _record(self, renderers: list[Renderer], imp: np.ndarray, skip: np.ndarray | None) -> None:
        for i, r in enumerate(renderers):
            if skip is not None and skip[i]:
                r.start()
            else:
                r.record(self._core, i, imp[imp["scene"] == i])

    def render(self) -> tuple[np.ndarray, ...] | None:
        """A tuple with one ``(H, W, 3)`` uint8 frame per sub-env (``render_mode="rgb_array"``)."""
        if self.render_mode is None:
            return None
        return tuple(r.draw(self._core, i) for i, r in enumerate(self._get_renderers()))

    def _get_renderers(self) -> list[Renderer]:
        if self._renderers is None:
            from collision_env.envs.rendering import Renderer

            self._renderers = [Renderer(self.config, trails=self._trails) for _ in range(self.num_envs)]
        return self._renderers

    def close_extras(self, **kwargs: Any) -> None:
        """Free the renderers (``close()`` calls it)."""
        if self._renderers is not None:
            for r in self._renderers:
                r.close()
            self._renderers = None

    # ------------------------------------------------------------------------------------- #
    def get_state(self) -> dict:
        """Engine, task arrays, autoreset flags and every sub-env's RNG state."""
        return {
            "core": self._core.get_state(),
            "autoreset": self._autoreset.copy(),
            "rngs": [None if g is None else copy.deepcopy(g.bit_generator.state) for g in self._rngs],
        }

    def set_state(self, state: dict) -> None:
        """Restore a snapshot from :meth:`get_state` (checked; on error nothing changes)."""
        check_state_keys(state, ("core", "autoreset", "rngs"), "as get_state gives")
        autoreset = np.asarray(state["autoreset"])
        if autoreset.shape != self._autoreset.shape or autoreset.dtype != np.bool_:
            raise ValueError(f"set_state: autoreset must be {self._autoreset.shape} booleans, got {autoreset!r}")
        if len(state["rngs"]) != len(self._rngs):
            raise ValueError(f"set_state: rngs must hold {len(self._rngs)} generator states, got {len(state['rngs'])}")
        rngs = []  # (each state checked by numpy before anything changes)
        for i, st in enumerate(state["rngs"]):
            rng = None
            if st is not None:
                rng = np.random.Generator(np.random.PCG64()) if self._rngs[i] is None else copy.deepcopy(self._rngs[i])
                rng.bit_generator.state = copy.deepcopy(st)
            rngs.append(rng)
        self._core.set_state(state["core"])
        self._autoreset = autoreset.copy()
        for i, rng in enumerate(rngs):
            if rng is None:
                self._rngs[i] = None
            elif self._rngs[i] is None:
                self._rngs[i] = rng
            else:  # (the same generator object, which callers may hold)
                self._rngs[i].bit_generator.state = rng.bit_generator.state

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderers"] = None
        return state

    @property
    def core(self) -> TaskCore:
        """The batched task core: the engine in ``core.batch``, the task arrays alongside. Its kernel
        calls (``advance``, ``finish``) take the env's own buffers unchecked: drive the env through
        ``step`` and ``reset``."""
        return self._core
