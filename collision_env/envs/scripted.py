"""Scripted policies that aim with the engine's exact prediction (baselines, tests, demo GIFs).

* :class:`AimingPolicy` (controlled balls with nothing but walls in the way): each step it asks a copy
  of the engine (``BatchSimulator.copy()`` then ``step``) where each ball's next wall impact will land;
  if not on a target, it searches directions the same way and steers towards one that is.
* :class:`SteeringPolicy` (one controlled ball among balls it does not control: ``Crowd``, ``Pegs``):
  it steers at the target and coasts when a copy of the engine predicts a hit.
* :class:`BankShotPolicy` (one shot, ``control="shot"``: ``Fence``): plane geometry, no engine;
  it aims at the target directly or off the bottom or top wall, whichever straight path clears
  every other ball.
* :class:`ShootingPolicy` (any preset): candidate plans (action sequences) are run ahead on a
  planning copy of the env (``copy.deepcopy``, no renderer) from the env's current state
  (``get_state``/``set_state``); the first whose predicted rollout hits a target is executed.
  Because the engine is deterministic and exact, the real episode hits the target at exactly the
  predicted step with exactly the predicted impact. The env itself is never stepped by the
  planning, so it neither renders the look-ahead nor loses its trails.

Each plans nudges (velocity changes over ``max_dv``) in :meth:`ScriptedPolicy.nudge`; called, it
returns them in the form the env's ``control`` reads (:func:`as_env_action`).
``scripted_policy(env)`` picks the right one for the env's preset; ``env`` may be a ``gym.make``
env (wrappers included) or the bare env. The policy is called each step and returns the action:

>>> import gymnasium as gym
>>> import collision_env
>>> env = gym.make("CollisionEnv/Billiards-v0")
>>> obs, info = env.reset(seed=0)
>>> policy = scripted_policy(env)
>>> obs, reward, terminated, truncated, info = env.step(policy(obs))
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT, WALL_TOP
from collision_env.envs.task.layout import TARGET_GEOMETRY, TARGET_HIT, TARGET_PENDING
from collision_env.envs.task.nudge import capped_change

#: A plan: ``plan(t, env)`` is the nudge action for step ``t`` of the plan (converted for the env's
#: control by :func:`as_env_action` when it is played).
Plan = Callable[[int, object], np.ndarray]

if TYPE_CHECKING:
    import gymnasium as gym

    from collision_env.envs._core import TaskCore
    from collision_env.envs.target_env import CollisionTargetEnv


def _bare(env: gym.Env) -> CollisionTargetEnv:
    """The task env under ``env``'s wrappers (or ``env`` itself)."""
    return cast("CollisionTargetEnv", env.unwrapped)


def on_target(core: TaskCore, b: int, k: int, wall: int, x: float, y: float, t: float) -> bool:
    """Whether an impact at wall code ``wall``, point (x, y), time t lands on target k of scene b."""
    c, hw, t_open, t_close = core.target_geo[b, k]
    s = y if wall in (WALL_LEFT, WALL_RIGHT) else x
    return core.t_wall[b, k] == wall and abs(s - c) <= hw and t_open <= t <= t_close


def first_wall_impact(records: np.ndarray, ball: int | None = None) -> np.void | None:
    for r in records:
        if r["wall"] >= 0 and (ball is None or r["ball"] == ball):
            return r
    return None


class ScriptedPolicy:
    """A policy that plans nudges on the bare env it plays (``self.env``).

    Subclasses implement :meth:`nudge`; calling the policy converts its result with
    :func:`as_env_action`, so one plan serves both controls.
    """

    def __init__(self, env: gym.Env) -> None:
        self.env = _bare(env)

    def nudge(self, obs: np.ndarray | None = None) -> np.ndarray:
        """The nudge action for this step (one component per axis and controlled ball)."""
        raise NotImplementedError

    def __call__(self, obs: np.ndarray | None = None) -> np.ndarray:
        return as_env_action(self.env, self.nudge(obs))


class AimingPolicy(ScriptedPolicy):
    """Steer each controlled ball so that its next wall impact lands on a pending target.

    For scenes where the controlled balls score and meet nothing on the way but walls (one ball,
    or ``ball_collisions=False``): ``OneBallTarget`` and ``MultiBall``. Ball j of the controlled
    balls aims at the (j mod n)-th of the n pending visible targets. Call it with no argument each
    step; it returns the action.
    """

    def __init__(self, env: gym.Env, speed: float = 1.2, lookahead: float = 6.0, directions: int = 144) -> None:
        super().__init__(env)
        self.speed = speed
        self.lookahead = lookahead
        self.angles = np.linspace(-math.pi, math.pi, directions, endpoint=False)
        self.want: dict[int, np.ndarray | None] = {}

    def _pending(self) -> list:
        core, cfg = self.env.core, self.env.config
        if cfg.sequential:
            k = int(core.cur[0])
            return [k] if k < core.t_wall.shape[1] else []
        return np.flatnonzero(core.t_status[0] == TARGET_PENDING).tolist()

    def predicts_hit(self, ball: int, dv: np.ndarray, targets: Iterable[int]) -> bool:
        """Does ``ball`` hit one of ``targets`` next if its velocity changes by ``dv`` now?"""
        core = self.env.core
        sim = core.batch.copy()
        nudge = np.zeros((1, core.cfg.n_balls, 2))
        nudge[0, ball] = dv
        sim.nudge(nudge)
        r = first_wall_impact(sim.step(self.lookahead).array, ball=ball)
        return r is not None and any(on_target(core, 0, k, r["wall"], r["x"], r["y"], r["time"]) for k in targets)

    def nudge(self, obs: np.ndarray | None = None) -> np.ndarray:
        core, cfg = self.env.core, self.env.config
        action = no_nudge(self.env)
        pending = self._pending()
        if not pending:
            return action
        for j, i in enumerate(cfg.controlled):
            v = core.vel[0, i]
            if self.predicts_hit(i, np.zeros(2), pending):
                self.want[i] = None
                continue  # already on course to some target: coast
            mine = [pending[j % len(pending)]]
            want = self.want.get(i)
            if want is None or not self.predicts_hit(i, want - v, mine):
                want = None
                cur = math.atan2(v[1], v[0])
                for ang in sorted(self.angles, key=lambda a: abs(math.remainder(a - cur, 2 * math.pi))):
                    cand = self.speed * np.array([math.cos(ang), math.sin(ang)])
                    if self.predicts_hit(i, cand - v, mine):
                        want = cand
                        break
                self.want[i] = want
            if want is not None:
                action[2 * j : 2 * j + 2] = towards(self.env, want, v)
        return action


class SteeringPolicy(AimingPolicy):
    """Steer the controlled ball straight at the current target's centre, at ``speed``, and coast
    whenever the engine predicts that its next wall impact lands on the target.

    For a controlled ball among balls it cannot steer (``Crowd``): they knock it off any aim it
    takes, so it re-aims at every step rather than searching for a shot, and only one prediction
    (a copy of the engine run ``lookahead`` s ahead) is made per step.
    """

    def nudge(self, obs: np.ndarray | None = None) -> np.ndarray:
        core, cfg = self.env.core, self.env.config
        action = no_nudge(self.env)
        pending = self._pending()
        if not pending:
            return action
        k = pending[0]
        goal = _target_point(cfg, int(core.t_wall[0, k]), core.target_geo[0, k, TARGET_GEOMETRY.centre])
        for j, i in enumerate(cfg.controlled):
            if self.predicts_hit(i, np.zeros(2), [k]):
                continue
            pos, v = core.pos[0, i], core.vel[0, i]
            heading = np.subtract(goal, pos)
            want = self.speed * heading / max(np.linalg.norm(heading), 1e-12)
            action[2 * j : 2 * j + 2] = towards(self.env, want, v)
        return action


def _clear(p: np.ndarray, q: np.ndarray, centres: np.ndarray, reach: np.ndarray) -> bool:
    """Does the segment from ``p`` to ``q`` keep a distance of more than ``reach`` from every centre?"""
    d = q - p
    u = np.clip(((centres - p) @ d) / float(d @ d), 0.0, 1.0)
    gaps = np.linalg.norm(p + u[:, None] * d - centres, axis=1)
    return bool((gaps > reach).all())


class BankShotPolicy(ScriptedPolicy):
    """One shot (``control="shot"``), aimed by plane geometry alone (no engine): at points across
    the current target (its centre, and out to ``spread`` of its half width), sent directly or off
    the two walls along the target's wall (aimed at the point's mirror images in them, the path
    unfolded, out to ``bounces`` periods of the mirroring), at ``max_speed``; the shortest unfolded
    straight path that passes every other ball's mirror images with ``margin`` m to spare is taken,
    else the direct shot at the centre. For one scoring ball among balls at rest (``Fence``): it
    never plans a bounce off a ball (a ball in the way rules a path out).
    """

    def __init__(self, env: gym.Env, spread: float = 0.8, margin: float = 0.01, bounces: int = 4) -> None:
        super().__init__(env)
        self.spread = spread
        self.margin = margin
        self.bounces = bounces

    def shot(self) -> np.ndarray:
        """The shot's velocity (m/s) for the current state."""
        core, cfg = self.env.core, self.env.config
        assert cfg.bounds is not None  # (None only as an argument of TaskConfig)
        xmin, ymin, xmax, ymax = cfg.bounds
        i = cfg.controlled[0]
        pos, r = core.pos[0], core.radii[0]
        others = [j for j in range(cfg.n_balls) if j != i]
        k = min(int(core.cur[0]), core.t_wall.shape[1] - 1)
        wall = int(core.t_wall[0, k])
        centre, half = core.target_geo[0, k, TARGET_GEOMETRY.centre], core.target_geo[0, k, TARGET_GEOMETRY.half_width]
        # the ball's centre meets the target's wall r from it, and bounces off the other walls r from them
        axis = 1 if wall in (WALL_LEFT, WALL_RIGHT) else 0  # the axis along the target's wall
        lo, hi = (ymin, ymax) if axis else (xmin, xmax)
        lo, hi = lo + r[i], hi - r[i]
        period = 2.0 * (hi - lo)

        def images(s: np.ndarray, n: int) -> list:  # s's unfolded images after n bounces
            return [s + period * q for q in range(-n, n + 1)] + [2 * lo - s + period * q for q in range(-n, n + 1)]

        goal = np.array(_target_point(cfg, wall, centre), float)
        goal[1 - axis] += r[i] * (1.0 if goal[1 - axis] < pos[i, 1 - axis] else -1.0)
        centres = pos[others]
        mirrored = []
        for image in images(centres[:, axis], self.bounces + 1):
            c = centres.copy()
            c[:, axis] = image
            mirrored.append(c)
        ghosts = np.concatenate(mirrored)
        reach = np.tile(r[others] + r[i] + self.margin, len(mirrored))
        offsets = [0.0] + [sign * f * half for f in np.linspace(0.2, self.spread, 3) for sign in (1.0, -1.0)]
        along = [image for off in offsets for image in images(np.array(centre + off), self.bounces)]
        for image in sorted(along, key=lambda a: abs(a - pos[i, axis])):  # the shortest paths first
            aim = goal.copy()
            aim[axis] = image
            if _clear(pos[i], aim, ghosts, reach):
                return cfg.max_speed * (aim - pos[i]) / np.linalg.norm(aim - pos[i])
        return cfg.max_speed * (goal - pos[i]) / np.linalg.norm(goal - pos[i])

    def __call__(self, obs: np.ndarray | None = None) -> np.ndarray:
        cfg = self.env.config
        return (self.shot() / cfg.max_speed).astype(np.float32)


# --------------------------------------------------------------------------------------------- #


def no_nudge(env: gym.Env) -> np.ndarray:
    """The nudge action that changes nothing."""
    cfg = _bare(env).config
    return np.zeros(len(cfg.controlled) * cfg.dimension, np.float32)


def towards(env: gym.Env, want: ArrayLike, v: np.ndarray) -> np.ndarray:
    """One ball's nudge components that change velocity ``v`` towards ``want`` (m/s), each axis by at
    most ``max_dv``."""
    return np.clip((np.asarray(want) - v) / _bare(env).config.max_dv, -1.0, 1.0).astype(np.float32)


def as_env_action(env: gym.Env, nudge: ArrayLike) -> np.ndarray:
    """A nudge action (velocity changes over ``max_dv``, as every policy here plans them) in the
    form ``env``'s ``control`` reads, as a new float32 array: the nudge itself for "nudge"; for
    "velocity", per controlled ball the velocity the nudge leads to (over ``max_speed``, after the
    env's speed cap) and the engage flag, set when the nudge is not zero; for "shot", that velocity
    alone (the shot a nudge in the episode's first step amounts to). A plan and the episode
    that follows it convert alike, so they stay identical.

    The converted action moves the ball as the nudge does (to float32 rounding) except at the speed
    cap, which a nudge meets as a pull back onto the cap's circle: a ball faster than ``max_speed``
    is steered towards a velocity no longer than ``max_speed`` (a named velocity never is), and a
    nudge that turns a ball at the cap can change one axis by more than ``max_dv``, which one
    velocity step cannot."""
    bare = _bare(env)
    cfg = bare.config
    if cfg.control == "nudge":
        return np.array(nudge, np.float32)
    dim = cfg.dimension
    a = np.clip(np.asarray(nudge, np.float64).reshape(len(cfg.controlled), dim), -1.0, 1.0)
    out = np.empty((len(cfg.controlled), dim + 1), np.float32)
    max_dv, max_speed = float(cfg.max_dv), float(cfg.max_speed)
    for j, i in enumerate(cfg.controlled):
        vx, vy = (float(x) for x in bare.core.vel[0, i])
        dy = float(a[j, 1]) * max_dv if dim == 2 else 0.0
        dx, dy = capped_change(vx, vy, float(a[j, 0]) * max_dv, dy, max_speed)  # as the env caps the nudge
        named = np.array([vx + dx, vy + dy][:dim]) / max_speed
        named /= max(1.0, float(np.linalg.norm(named)))  # no longer than max_speed, in the nudge's direction
        out[j, :dim] = np.clip(named, -1.0, 1.0)  # (float rounding)
        out[j, dim] = 1.0 if (a[j] != 0.0).any() else -1.0
    return (out[:, :dim] if cfg.control == "shot" else out).ravel()


def push(direction: ArrayLike, steps: int, delay: int = 0) -> Plan:
    """A plan: a full nudge along ``direction`` for ``steps`` steps after ``delay``, then nothing."""
    d = np.asarray(direction, np.float32)
    zero = np.zeros_like(d)
    return lambda t, env: d if delay <= t < delay + steps else zero


def planning_copy(env: CollisionTargetEnv) -> CollisionTargetEnv:
    """A copy of the (unwrapped) env to plan on: same task and state, no renderer, no render mode."""
    planner = copy.deepcopy(env)  # the env's __getstate__ leaves its renderer behind
    planner.render_mode = None
    return planner


def shoot(
    env: CollisionTargetEnv, plans: list[Plan], horizon: int, planner: CollisionTargetEnv | None = None
) -> tuple[Plan, int, np.ndarray] | tuple[None, None, None]:
    """The first plan whose predicted rollout hits a target within ``horizon`` steps.

    Each plan (of nudges, each converted by :func:`as_env_action`) runs on ``planner`` (default: a
    fresh :func:`planning_copy` of ``env``) from the current state of ``env``, which is left
    untouched. Returns ``(plan, hit_step, impacts of that step)`` or ``(None, None, None)``.
    """
    planner = planning_copy(env) if planner is None else planner
    start = env.get_state()
    for plan in plans:
        planner.set_state(start)
        hits = int((planner.core.t_status[0] == TARGET_HIT).sum())
        for t in range(horizon):
            _, _, term, trunc, info = planner.step(as_env_action(planner, plan(t, planner)))
            if info["targets_hit"] > hits:
                return plan, t, info["impacts"].array.copy()
            if term or trunc:
                break
    return None, None, None


def _target_point(cfg, wall: int, c: float):
    xmin, ymin, xmax, ymax = cfg.bounds
    return {WALL_LEFT: (xmin, c), WALL_RIGHT: (xmax, c), WALL_BOTTOM: (c, ymin), WALL_TOP: (c, ymax)}[wall]


def billiards_plans(env: CollisionTargetEnv) -> list[Plan]:
    """Ghost-ball shots: send the cue ball at the spot from which each object ball heads for each target."""
    core, cfg = env.core, env.config
    pos, r = core.pos[0], core.radii[0]
    plans = []
    for k in np.flatnonzero(core.t_status[0] == TARGET_PENDING):
        target = _target_point(cfg, int(core.t_wall[0, k]), core.target_geo[0, k, TARGET_GEOMETRY.centre])
        for j in range(cfg.n_balls):
            if j in cfg.controlled:
                continue
            u = np.subtract(target, pos[j])
            ghost = pos[j] - (r[0] + r[j]) * u / np.linalg.norm(u)
            base = math.atan2(ghost[1] - pos[0, 1], ghost[0] - pos[0, 0])
            for off in (0.0, 0.5, -0.5, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0):
                ang = base + math.radians(off)
                for steps in (8, 14):
                    plans.append(push((math.cos(ang), math.sin(ang)), steps))
    return plans


def stuck(env: CollisionTargetEnv) -> bool:
    """Is ball 0 part of a cluster?"""
    core = env.core
    return bool((core.body[0] == core.body[0, 0]).sum() > 1)


def cluster_plans(env: CollisionTargetEnv) -> list[Plan]:
    """Once stuck: push the cluster in one of 64 directions for 8, 20 or 40 steps."""
    if not stuck(env):
        return []
    return [
        push((math.cos(a), math.sin(a)), steps)
        for steps in (8, 20, 40)
        for a in np.linspace(0, 2 * math.pi, 64, endpoint=False)
    ]


def ram(env: CollisionTargetEnv) -> np.ndarray:
    """Steer ball 0 straight at ball 1 (to form a cluster)."""
    core = env.core
    d = core.pos[0, 1] - core.pos[0, 0]
    want = 0.8 * d / np.linalg.norm(d)
    return towards(env, want, core.vel[0, 0])


def line_plans(env: CollisionTargetEnv) -> list[Plan]:
    """Pushes of the first ball either way, of several lengths and delays."""
    return [push((s,), steps, delay) for delay in (0, 20, 40, 60, 90) for steps in (2, 6, 12) for s in (1.0, -1.0)]


class ShootingPolicy(ScriptedPolicy):
    """Plan by shooting (see :func:`shoot`), follow the plan, re-plan after each hit.

    ``candidates(env)`` lists plans; ``fallback(env)`` gives the nudge while no plan hits
    (default: no nudge); planning is retried every ``retry`` steps. :meth:`nudge` moves the plan
    on by a step: call it (or the policy) once per env step.
    """

    def __init__(self, env: gym.Env, candidates: Callable, fallback: Callable | None = None, retry: int = 10) -> None:
        super().__init__(env)
        self.candidates = candidates
        self.fallback = fallback
        self.retry = retry
        self.plan: Plan | None = None
        self.t = 0
        self.hit_step: int | None = None
        self.wait = 0
        self.planner = planning_copy(self.env)

    def nudge(self, obs: np.ndarray | None = None) -> np.ndarray:
        env = self.env
        if self.plan is None and self.wait <= 0:
            horizon = env.config.n_steps - int(env.core.steps[0])
            plans = self.candidates(env)
            plan, hit_step, _ = shoot(env, plans, horizon, self.planner) if plans else (None, None, None)
            if plan is not None:
                self.plan, self.t, self.hit_step = plan, 0, hit_step
            else:
                self.wait = self.retry if plans else 0
        if self.plan is None:
            self.wait -= 1
            if self.fallback is not None:
                return self.fallback(env)
            return no_nudge(env)
        action = self.plan(self.t, env)
        self.t += 1
        assert self.hit_step is not None  # (set with the plan)
        if self.t > self.hit_step:
            self.plan = None  # the predicted hit happens in this step: plan afresh next step
        return action


def scripted_policy(env: gym.Env) -> ScriptedPolicy | None:
    """A scripted policy for the env's preset (``None`` when there is none): ``policy(obs) -> action``.

    ``env`` is a ``gym.make`` env or the bare env; the policy reads the state of the bare env. It
    plans nudges and hands them over in the form the env's ``control`` reads (:func:`as_env_action`).
    """
    env = _bare(env)
    cfg = env.config
    if cfg.control == "shot" and cfg.dimension == 2 and len(cfg.controlled) == 1:
        return BankShotPolicy(env)
    if (
        cfg.dimension == 2
        and cfg.scorers in ("any", "controlled")
        and (cfg.n_balls == 1 or not cfg.ball_collisions)
        and len(cfg.controlled) == cfg.n_balls
    ):
        return AimingPolicy(env)
    if cfg.dimension == 2 and cfg.scorers == "controlled" and cfg.sequential and len(cfg.controlled) == 1:
        return SteeringPolicy(env, lookahead=2.0)
    if cfg.scorers == "cluster":

        def ram_first(e):
            return no_nudge(e) if stuck(e) else ram(e)

        return ShootingPolicy(env, cluster_plans, fallback=ram_first)
    if cfg.scorers == "others":
        return ShootingPolicy(env, billiards_plans)
    if cfg.dimension == 1:
        return ShootingPolicy(env, line_plans)
    return None
