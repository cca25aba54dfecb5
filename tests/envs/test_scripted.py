"""Scripted policies that aim with the engine's exact prediction reach the targets.

This proves every preset's reward is reachable and tied to the engine's exact impacts: the
planner predicts a hit by stepping the engine ahead (a copy of the BatchSimulator, or the env from
a saved state), and the real episode then hits the target at exactly the predicted step, with
exactly the predicted impact, whose contact point lies on the target segment.
"""

import math

import gymnasium as gym
import numpy as np
import pytest

WALLS = ("left", "right", "bottom", "top")


def on_target(core, k, wall_code, x, y, t):
    c, hw, t_open, t_close = core.t_geo[0, k]
    s = y if wall_code < 2 else x
    return core.t_wall[0, k] == wall_code and abs(s - c) <= hw and t_open <= t <= t_close


def first_wall_impact(imp, ball=None):
    for r in imp:
        if r["wall"] >= 0 and (ball is None or r["ball"] == ball):
            return r
    return None


# ------------------------------------------------------------------------------------------------ one ball


class OneBallAimer:
    """Aims the ball's next wall impact at the current target with BatchSimulator.copy() + step."""

    def __init__(self, env, speed=1.2, lookahead=6.0):
        self.env, self.speed, self.lookahead = env, speed, lookahead
        self.want = None

    def _hits(self, dv):
        core = self.env.core
        sim = core.batch.copy()
        sim.nudge(dv[None, None, :])
        r = first_wall_impact(sim.step(self.lookahead), ball=0)
        return r is not None and on_target(core, int(core.cur[0]), r["wall"], r["x"], r["y"], r["time"])

    def __call__(self):
        core, cfg = self.env.core, self.env.config
        v = core.vel[0, 0]
        if self._hits(np.zeros(2)):
            self.want = None
            return np.zeros(2, np.float32)  # already on course: coast
        if self.want is None or not self._hits(self.want - v):
            self.want = None
            cur = math.atan2(v[1], v[0])
            for ang in sorted(np.linspace(-math.pi, math.pi, 144, endpoint=False),
                              key=lambda a: abs(math.remainder(a - cur, 2 * math.pi))):
                want = self.speed * np.array([math.cos(ang), math.sin(ang)])
                if self._hits(want - v):
                    self.want = want
                    break
        if self.want is None:
            return np.zeros(2, np.float32)
        return np.clip((self.want - v) / cfg.max_dv, -1, 1).astype(np.float32)


@pytest.mark.parametrize("env_id", ["CollisionEnv/OneBallTarget-v0", "CollisionEnv/Target-v0"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_one_ball_aimer_hits_every_target(env_id, seed):
    env = gym.make(env_id).unwrapped
    env.reset(seed=seed)
    aim = OneBallAimer(env)
    hits = 0
    for _ in range(env.config.n_steps):
        k = int(env.core.cur[0])
        obs, reward, term, trunc, info = env.step(aim())
        if info["targets_hit"] > hits:
            hits = info["targets_hit"]
            r = first_wall_impact(info["impacts"].records, ball=0)
            assert on_target(env.core, k, r["wall"], r["x"], r["y"], r["time"])
            assert reward > 0.5
        if term or trunc:
            break
    assert info["is_success"] and term and hits == 3


# ------------------------------------------------------------------------------------------------ shooting


def shoot(env, plans, horizon):
    """The first plan whose predicted rollout (the env run ahead from a saved state) hits a target.

    A plan is a function (step, env) -> action. Returns (plan, hit step, predicted impacts), and
    leaves the env in the state it was in.
    """
    start = env.get_state()
    try:
        for plan in plans:
            env.set_state(start)
            hits = int((env.core.t_status[0] == 1).sum())
            for t in range(horizon):
                _, _, term, trunc, info = env.step(plan(t, env))
                if info["targets_hit"] > hits:
                    return plan, t, info["impacts"].records.copy()
                if term or trunc:
                    break
        return None, None, None
    finally:
        env.set_state(start)


def replay_and_check(env, plan, hit_step, predicted, horizon):
    before = env.core.t_status[0].copy()
    for t in range(horizon):
        _, reward, _, _, info = env.step(plan(t, env))
        if t == hit_step:
            break
    assert t == hit_step and info["targets_hit"] >= 1
    assert np.array_equal(info["impacts"].records, predicted)  # exactly the predicted impacts
    newly = np.flatnonzero((before == 0) & (env.core.t_status[0] == 1))
    assert len(newly) >= 1
    assert any(on_target(env.core, k, r["wall"], r["x"], r["y"], r["time"])
               for k in newly for r in predicted if r["wall"] >= 0)
    assert reward >= env.config.hit_reward - 0.1


def push(direction, steps, delay=0):
    d = np.asarray(direction, np.float32)
    return lambda t, env: d if delay <= t < delay + steps else np.zeros_like(d)


@pytest.mark.parametrize("seed", [0, 1])
def test_billiards_ghost_ball_shot_pots_an_object_ball(seed):
    env = gym.make("CollisionEnv/Billiards-v0").unwrapped
    env.reset(seed=seed)
    core = env.core
    pos, r = core.pos[0], core.radii[0]
    plans = []
    for k in range(core.t_wall.shape[1]):
        wall, c = int(core.t_wall[0, k]), core.t_geo[0, k, 0]
        xmin, ymin, xmax, ymax = env.config.bounds
        target = {0: (xmin, c), 1: (xmax, c), 2: (c, ymin), 3: (c, ymax)}[wall]
        for j in range(1, env.config.n_balls):
            u = np.subtract(target, pos[j])
            ghost = pos[j] - (r[0] + r[j]) * u / np.linalg.norm(u)
            base = math.atan2(*(ghost - pos[0])[::-1])
            for off in (0.0, 0.5, -0.5, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0):
                ang = base + math.radians(off)
                for steps in (8, 14):
                    plans.append(push((math.cos(ang), math.sin(ang)), steps))
    plan, t_hit, predicted = shoot(env, plans, horizon=env.config.n_steps)
    assert plan is not None, "no ghost-ball shot predicted a hit"
    replay_and_check(env, plan, t_hit, predicted, env.config.n_steps)
    scorer = [rec for rec in predicted if rec["wall"] >= 0 and rec["ball"] != 0]
    assert scorer  # an object ball scored, not the cue ball


@pytest.mark.parametrize("seed", [0, 1])
def test_inelastic_cluster_is_formed_then_steered_onto_the_target(seed):
    env = gym.make("CollisionEnv/InelasticCluster-v0").unwrapped
    env.reset(seed=seed)
    core = env.core

    def stuck():
        return core.body[0, 0] == core.body[0, 1]

    # phase 1: ram ball 1 (steer ball 0 straight at it) until the two stick
    for _ in range(env.config.n_steps // 2):
        d = core.pos[0, 1] - core.pos[0, 0]
        want = 0.8 * d / np.linalg.norm(d)
        env.step(np.clip((want - core.vel[0, 0]) / env.config.max_dv, -1, 1).astype(np.float32))
        if stuck():
            break
    assert stuck()
    # phase 2: shoot the cluster (nudges on ball 0 are impulses on the cluster)
    plans = [push((math.cos(a), math.sin(a)), steps)
             for steps in (8, 20, 40) for a in np.linspace(0, 2 * math.pi, 64, endpoint=False)]
    horizon = env.config.n_steps - int(core.steps[0])
    plan, t_hit, predicted = shoot(env, plans, horizon=horizon)
    assert plan is not None, "no cluster shot predicted a hit"
    replay_and_check(env, plan, t_hit, predicted, horizon)


@pytest.mark.parametrize("seed", [0, 1])
def test_line_1d_hits_an_end_wall_inside_a_window(seed):
    env = gym.make("CollisionEnv/Line1D-v0").unwrapped
    env.reset(seed=seed)
    plans = [push((s,), steps, delay) for delay in (0, 20, 40, 60, 90) for steps in (2, 6, 12) for s in (1.0, -1.0)]
    plan, t_hit, predicted = shoot(env, plans, horizon=env.config.n_steps)
    assert plan is not None, "no push predicted an end-wall impact inside a window"
    replay_and_check(env, plan, t_hit, predicted, env.config.n_steps)
