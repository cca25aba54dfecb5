"""The generic collision-target environment: every preset is a configuration of this class."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import ArrayLike

from collision_env.engine import BatchSimulator, Impacts
from collision_env.envs._config import TaskConfig, keywords_of, make_config
from collision_env.envs._core import TaskCore, check_state_keys
from collision_env.envs.task.layout import ROW_RESET, ROW_STEPPED, SCENE_FLOATS, SCENE_INTS

if TYPE_CHECKING:
    from collision_env.envs.registry import Task
    from collision_env.envs.rendering import Renderer

_CLASS_PRESET = "__class_preset__"


class CollisionTargetEnv(gym.Env):
    """
    ## Description

    Balls move in PhET Collision Lab's play area under a time-of-impact-exact collision engine
    (`collision_env.engine`). The agent **nudges the velocities** of the balls it controls, once
    per control step, and is rewarded when a scoring ball's **wall impact**, as the engine
    reports it (exact time and contact point), lands on a **target**: a wall segment (wall,
    centre, width), in some tasks only inside a time window. This class is the generic,
    configurable task: `gym.make("CollisionEnv/Target-v0", preset=..., **fields)`; each registered
    preset (`collision_env.envs.PRESET_IDS`) is one configuration of it (`collision_env.envs.PRESETS`),
    and any field of `TaskConfig` can be overridden by keyword.

    ## Action Space

    `Box(-1, 1, (len(controlled) * dimension,), float32)`: for each controlled ball in order,
    (ax, ay) in 2D or ax in 1D. Component `a` becomes a velocity change `a * max_dv` (m/s),
    applied as an impulse at the start of the step. **Out-of-range actions are clipped** to
    [-1, 1]; an action containing NaN raises `ValueError`. A nudge never raises a ball's speed above
    `max(max_speed, its current speed)` (the change is scaled back along the new velocity).

    With `control="velocity"` the action names, for each controlled ball, the velocity to steer it
    to and an engage flag: `Box(-1, 1, (len(controlled) * (dimension + 1),), float32)`, per ball
    (ux, uy, engage) in 2D or (ux, engage) in 1D. While `engage > 0` the ball is nudged towards the
    velocity `u * max_speed` (scaled back to `max_speed` if longer), along the straight line to it
    and by at most `max_dv` per axis and step; while `engage <= 0` it coasts. The agent names where
    the velocity should go instead of each step's change, so aiming a shot is one output instead of
    a sum of many. A step costs what a nudge costs per m/s of change; since the line to the named
    velocity never leaves the speed cap, the change charged is always the change made (a nudge pays
    for the change it asks for, even where the cap shortens it). A ball faster than `max_speed` (after
    a collision) can only be steered towards a slower velocity.

    With `control="shot"` the agent has one shot per episode: `Box(-1, 1, (len(controlled) *
    dimension,), float32)`, per ball the velocity `u * max_speed` (scaled back to `max_speed` if
    longer) it is given at once in the episode's first step (charged as a nudge of that change);
    the actions of later steps are ignored. The outcome is committed before any impact is seen,
    as a shot at a target is.

    ## Observation Space

    `Box(-1, 1, (D,), float32)` with a fixed layout, `D = 6 N + 10 S + 2` (N observed balls: every
    ball, or the controlled ones with `observed_balls="controlled"`; S target slots: 1 when targets
    are sequential, else `n_targets`), plus `4 N` with `observe="predicted"` and `3 (2 n + 1)` with
    `bank_images=n` (which shift the predicted blocks' indices below by as many). Centre
    and half-size of the play area are (xc, yc), (xh, yh); `vs = 2 * max_speed`. Every entry is
    clipped to [-1, 1].

    | Index                    | Observation                                                                |
    |--------------------------|----------------------------------------------------------------------------|
    | 6i + 0, 1                | ball i position: (x - xc) / xh, (y - yc) / yh                              |
    | 6i + 2, 3                | ball i velocity: vx / vs, vy / vs (0 for y in 1D)                          |
    | 6i + 4                   | ball i mass / 3 kg                                                         |
    | 6i + 5                   | 1 if ball i's wall impacts currently score, else 0                         |
    | 6N + 10s + 0, 1          | target s centre point, normalised like positions                           |
    | 6N + 10s + 2             | target s half width / half length of its wall                              |
    | 6N + 10s + 3..6          | target s wall one-hot (left, right, bottom, top)                           |
    | 6N + 10s + 7             | target s status: 1 pending, 0 hit, -1 failed (window closed)               |
    | 6N + 10s + 8, 9          | (window open - t) / time_limit, (window close - t) / time_limit            |
    | 6N + 10S + 0             | fraction of the episode's control steps left                               |
    | 6N + 10S + 1             | fraction of targets not yet hit                                            |
    | 6N + 10S + 2 + 4i + 0, 1 | ball i's predicted wall impact (no more nudges), normalised like positions |
    | 6N + 10S + 2 + 4i + 2    | time until it / time_limit (1, and point 0, 0: none within the lookahead)  |
    | 6N + 10S + 2 + 4i + 3    | 1 if it lands on a visible pending target inside its window, else 0        |

    With `bank_images=n` (2D, one target at a time), `3 (2 n + 1)` entries follow the globals (the
    predicted blocks, if any, come after them): for m = -n .. n, the unit direction from the first
    controlled ball to image m of the current target, and 1 if that straight unfolded path passes
    every other ball (else 0). Image m is the point where the ball's centre meets the target's wall
    at its centre, mirrored |m| times in the two walls along that wall (first in the lower or left
    one for m < 0): a ball sent at it bounces |m| times before it lands if nothing is in its way
    (`task.images`; the plane geometry of the scripted bank shots, the other balls taken at rest).

    With sequential targets the single slot shows the current target. Targets without a window
    read -1 and 1 in the window entries. The predicted entries (`observe="predicted"`) come from a
    copy of the engine, in the env's own mode, loaded with the current state and run `lookahead`
    seconds ahead with no nudge at every step: what the engine will do if the agent stops acting
    now (the planning the scripted policies do, offered to the agent as an observation). A ball's
    entry is its next wall impact, or with `predicted_impact="scoring"`, for a ball whose impacts
    score, the first of its impacts within the look-ahead that lands on a pending target (its next
    one when none does): whether coasting will score, however many bounces away. A hit is judged
    against the targets as they stand now: the prediction does not stop at the episode's end, nor
    account for another ball reaching the same target first.

    ## Rewards

    Per step: `hit_reward` per target hit, `+ success_bonus` when the last target is hit,
    `- miss_penalty` per wall impact of a scoring ball that hits no target,
    `- action_cost * sum |requested dv|` (m/s), and, when `shaping > 0` and no target was hit this
    step, `shaping * (phi(s') - phi(s))` where `-phi` is the distance (over the play-area diagonal)
    from the nearest point where a scoring ball would touch the border if it flew straight on to the
    nearest visible pending target (a potential-based aiming heuristic that ignores other balls).
    With `aim="predicted"` that point is the engine's predicted next wall impact instead (see
    `observe="predicted"`); with `aim="landing"`, the predicted first impact on the wall of a
    visible pending target (past any bounces off other walls and balls: the impact that decides a
    shot), measured to that target.

    ## Starting State

    Drawn from `self.np_random` at every reset: masses uniform in `mass_range`, radii by
    `radius`, positions without overlap by `layout`, speeds uniform in `speed_range` (controlled)
    and `others_speed_range` (others) in random directions; `n_targets` targets on random walls among
    `target_walls` at random centres (the whole end wall in 1D), with time windows of length
    `window` at random times if the task has them. The engine's time starts at 0.

    ## Episode End

    - Termination: every target hit (`info["is_success"] = True`), or a target failed
      (`is_success = False`): its time window closed before it was hit, or, with `control="shot"`,
      a scoring ball struck its wall off it.
    - Truncation: after `round(time_limit / dt)` control steps (also the registered
      `max_episode_steps`; if you change `dt`, pass `max_episode_steps` to `gym.make` to match).

    ## Info

    `impacts` (`Impacts`: every wall and ball-ball impact of the step, exact time, balls, wall and
    contact point), `event_cap` (the engine's per-step event cap stopped the step early), `nudge`
    (the step's requested velocity change, m/s, summed over the controlled balls; its cost is
    `action_cost * nudge`),
    `energy` (kinetic energy, J), `time` (simulated time, s), `targets_hit` (so far),
    `is_success`. Fresh objects on every call.

    ## Arguments

    `preset` (a name in `PRESETS`, or `None` for the bare `TaskConfig` defaults), any
    `TaskConfig` field (among them the engine's `mode`, `substeps`, `max_events` and the control
    step `dt`), `render_mode` ("rgb_array" or "human"), `trails` (draw ball trails).
    Bad values raise `ValueError` at construction.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 20}
    """Gymnasium's metadata: the render modes, and frames per second (an instance's follow its ``dt``)."""
    preset: str | None = "one_ball"
    """The preset a class makes when ``preset`` is not given (a name in ``PRESETS``)."""
    task: Task | None = None
    """The task registry entry of a preset's env class (its id, preset and config); ``None`` here."""

    def __init__(
        self, preset: str | None = _CLASS_PRESET, render_mode: str | None = None, trails: bool = False, **overrides: Any
    ) -> None:
        if preset is _CLASS_PRESET:
            preset = type(self).preset
        self.config: TaskConfig = make_config(preset, also=keywords_of(type(self).__init__, gym.make), **overrides)
        """The task this env runs: the preset's fields with the keyword overrides, checked."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode: expected one of {self.metadata['render_modes']} or None, got {render_mode!r}"
            )
        self.render_mode = render_mode
        """``"rgb_array"``, ``"human"`` or ``None``."""
        self.metadata = {**type(self).metadata, "render_fps": max(1, int(round(1.0 / self.config.dt)))}
        self._core = TaskCore(self.config, 1)
        cfg = self.config
        self.action_space = spaces.Box(-1.0, 1.0, (cfg.action_dim,), np.float32)
        """``Box(-1, 1, (config.action_dim,), float32)``: see "Action Space" above."""
        self.observation_space = spaces.Box(-1.0, 1.0, (cfg.obs_dim,), np.float32)
        """``Box(-1, 1, (config.obs_dim,), float32)``: see "Observation Space" above."""
        self._ones = np.ones(1, dtype=bool)
        self._reset_flag = np.full(1, ROW_RESET, dtype=np.int8)
        self._step_flag = np.full(1, ROW_STEPPED, dtype=np.int8)
        self._adim = cfg.action_dim
        self._action = np.zeros((1, cfg.action_dim))
        self._dt = cfg.dt
        self._trails = bool(trails)
        self._renderer: Renderer | None = None

    def _obs(self):
        return np.empty((1, self._core.obs_dim), dtype=np.float32)  # fresh on every call

    def _scalars(self) -> tuple:
        """This step's (reward, terminated, truncated, success, targets hit, energy, nudge) as Python values."""
        S, C = self._core.scene_f[0].tolist(), self._core.scene_i[0].tolist()
        sf, si = SCENE_FLOATS, SCENE_INTS
        return (
            S[sf.reward],
            bool(C[si.terminated]),
            bool(C[si.truncated]),
            bool(C[si.success]),
            C[si.targets_hit],
            S[sf.energy],
            S[sf.nudge],
        )

    # ------------------------------------------------------------------------------------- #
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode (Gymnasium's ``Env.reset``): ``(observation, info)``; ``seed`` seeds
        ``self.np_random``, from which the start state is drawn; ``options`` is unused."""
        super().reset(seed=seed)
        core = self._core
        core.reset_scenes(np.zeros(1, dtype=np.int64), [self.np_random])
        imp = core.empty_impacts()
        obs = core.finish(self._reset_flag, imp, self._obs())
        _, _, _, _, n_hit, energy, _ = self._scalars()
        info = {
            "impacts": Impacts(imp),
            "event_cap": False,
            "nudge": 0.0,
            "energy": energy,
            "time": float(core.batch.live_arrays().time[0]),
            "targets_hit": n_hit,
            "is_success": False,
        }
        if self.render_mode is not None:
            self._get_renderer().start()  # trails and flashes are recorded from the episode start
        if self.render_mode == "human":
            self.render()
        return obs[0], info

    def step(self, action: ArrayLike) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        """One control step (Gymnasium's ``Env.step``): nudge, advance the engine by ``config.dt``,
        score; ``(observation, reward, terminated, truncated, info)``. ``info`` holds the step's
        ``impacts`` (an ``Impacts``), ``event_cap``, ``nudge``, ``energy``, ``time``,
        ``targets_hit`` and ``is_success``. An action with a NaN raises; others are clipped."""
        TaskCore.check_actions(action)
        a = self._action  # (1, A) float64, the kernel's input (reused: the kernel only reads it)
        if getattr(action, "shape", None) == self.action_space.shape:
            a[0] = action
        elif np.size(action) == self._adim:
            a[0] = np.ravel(action)
        else:
            raise ValueError(f"action: expected shape {self.action_space.shape}, got {np.shape(action)}")
        core = self._core
        imp = core.advance(a, self._ones, self._dt)  # raises on NaN
        obs = core.finish(self._step_flag, imp, self._obs())
        reward, term, trunc, success, n_hit, energy, nudge = self._scalars()
        live = core.batch.live_arrays()
        info = {
            "impacts": Impacts(imp),
            "event_cap": bool(live.capped[0]),
            "nudge": nudge,
            "energy": energy,
            "time": float(live.time[0]),
            "targets_hit": n_hit,
            "is_success": success,
        }
        if self._renderer is not None:
            self._renderer.record(core, 0, imp)
        if self.render_mode == "human":
            self.render()
        return obs[0], reward, term, trunc, info

    # ------------------------------------------------------------------------------------- #
    def render(self) -> np.ndarray | None:
        """An ``(H, W, 3)`` uint8 frame (``render_mode="rgb_array"``), or draw the window (``"human"``)."""
        if self.render_mode is None:
            env_id = self.spec.id if self.spec is not None else "..."
            gym.logger.warn(
                "You are calling render method without specifying any render mode. You can specify the "
                f'render_mode at initialization, e.g. gym.make("{env_id}", render_mode="rgb_array")'
            )
            return None
        renderer = self._get_renderer()
        frame = renderer.draw(self._core, 0)
        if self.render_mode == "human":
            renderer.show(frame, self.metadata["render_fps"])
            return None
        return frame

    def _get_renderer(self) -> Renderer:
        if self._renderer is None:
            from collision_env.envs.rendering import Renderer

            self._renderer = Renderer(self.config, trails=self._trails)
        return self._renderer

    def close(self) -> None:
        """Close the window, if one is open."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ------------------------------------------------------------------------------------- #
    def get_state(self) -> dict:
        """A snapshot of the whole env (engine, task, RNG) that :meth:`set_state` restores exactly."""
        return {"core": self._core.get_state(), "rng": copy.deepcopy(self.np_random.bit_generator.state)}

    def set_state(self, state: dict) -> None:
        """Restore a snapshot from :meth:`get_state` (checked; on error nothing changes)."""
        check_state_keys(state, ("core", "rng"), "as get_state gives")
        rng = copy.deepcopy(self.np_random)
        rng.bit_generator.state = copy.deepcopy(state["rng"])  # (checked by numpy before the core changes)
        self._core.set_state(state["core"])
        self.np_random.bit_generator.state = rng.bit_generator.state
        if self._renderer is not None:
            self._renderer.start()

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderer"] = None  # pygame surfaces and windows do not pickle; rebuilt on demand
        return state

    @property
    def core(self) -> TaskCore:
        """The batched task core (a batch of one): engine in ``core.batch``, task arrays alongside. Its
        kernel calls (``advance``, ``finish``) take the env's own buffers unchecked: drive the env
        through ``step`` and ``reset``."""
        return self._core

    @property
    def simulator(self) -> BatchSimulator:
        """The engine's :class:`~collision_env.engine.BatchSimulator` (one scene) behind this env."""
        return self._core.batch
