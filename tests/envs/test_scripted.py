"""Scripted policies that aim with the engine's exact prediction reach the targets.

This proves every preset's reward is reachable and tied to the engine's exact impacts: the
planner predicts a hit by stepping the engine ahead (a copy of the BatchSimulator, or the env from
a saved state), and the real episode then hits the target at exactly the predicted step, with
exactly the predicted impact, whose contact point lies on the target segment.
"""

import gymnasium as gym
import numpy as np
import pytest

from collision_env.envs.scripted import (
    AimingPolicy,
    billiards_plans,
    cluster_plans,
    line_plans,
    on_target,
    ram,
    scripted_policy,
    shoot,
    stuck,
)


@pytest.mark.parametrize(
    "env_id", ["CollisionEnv/OneBallTarget-v0", "CollisionEnv/Target-v0", "CollisionEnv/MultiBall-v0"]
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_aimer_hits_every_target(env_id, seed):
    env = gym.make(env_id).unwrapped
    env.reset(seed=seed)
    aim = AimingPolicy(env)
    hits = 0
    for _ in range(env.config.n_steps):
        pending = np.flatnonzero(env.core.t_status[0] == 0)
        obs, reward, term, trunc, info = env.step(aim())
        if info["targets_hit"] > hits:
            hits = info["targets_hit"]
            assert any(
                on_target(env.core, 0, k, r["wall"], r["x"], r["y"], r["time"])
                for r in info["impacts"].array
                if r["wall"] >= 0
                for k in pending
            )
            assert reward > 0.5
        if term or trunc:
            break
    assert info["is_success"] and term and hits == env.config.n_targets


def replay_and_check(env, plan, hit_step, predicted, horizon):
    before = env.core.t_status[0].copy()
    for t in range(horizon):
        _, reward, _, _, info = env.step(plan(t, env))
        if t == hit_step:
            break
    assert t == hit_step and info["targets_hit"] >= 1
    assert np.array_equal(info["impacts"].array, predicted)  # exactly the predicted impacts
    newly = np.flatnonzero((before == 0) & (env.core.t_status[0] == 1))
    assert len(newly) >= 1
    assert any(
        on_target(env.core, 0, k, r["wall"], r["x"], r["y"], r["time"])
        for k in newly
        for r in predicted
        if r["wall"] >= 0
    )
    assert reward >= env.config.hit_reward - 0.1


@pytest.mark.parametrize("seed", [0, 1])
def test_billiards_ghost_ball_shot_pots_an_object_ball(seed):
    env = gym.make("CollisionEnv/Billiards-v0").unwrapped
    env.reset(seed=seed)
    plan, t_hit, predicted = shoot(env, billiards_plans(env), horizon=env.config.n_steps)
    assert plan is not None, "no ghost-ball shot predicted a hit"
    replay_and_check(env, plan, t_hit, predicted, env.config.n_steps)
    assert [rec for rec in predicted if rec["wall"] >= 0 and rec["ball"] != 0]  # an object ball scored


@pytest.mark.parametrize("seed", [0, 1])
def test_inelastic_cluster_is_formed_then_steered_onto_the_target(seed):
    env = gym.make("CollisionEnv/InelasticCluster-v0").unwrapped
    env.reset(seed=seed)
    for _ in range(env.config.n_steps // 2):  # phase 1: ram ball 1 until the two stick
        env.step(ram(env))
        if stuck(env):
            break
    assert stuck(env)
    horizon = env.config.n_steps - int(env.core.steps[0])  # phase 2: shoot the cluster
    plan, t_hit, predicted = shoot(env, cluster_plans(env), horizon=horizon)
    assert plan is not None, "no cluster shot predicted a hit"
    replay_and_check(env, plan, t_hit, predicted, horizon)


@pytest.mark.parametrize("seed", [0, 1])
def test_line_1d_hits_an_end_wall_inside_a_window(seed):
    env = gym.make("CollisionEnv/Line1D-v0").unwrapped
    env.reset(seed=seed)
    plan, t_hit, predicted = shoot(env, line_plans(env), horizon=env.config.n_steps)
    assert plan is not None, "no push predicted an end-wall impact inside a window"
    replay_and_check(env, plan, t_hit, predicted, env.config.n_steps)


@pytest.mark.parametrize(
    "env_id", ["CollisionEnv/Billiards-v0", "CollisionEnv/InelasticCluster-v0", "CollisionEnv/Line1D-v0"]
)
def test_scripted_policy_scores_in_a_full_episode(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    policy = scripted_policy(env)
    total = 0.0
    for _ in range(env.config.n_steps):
        _, reward, term, trunc, info = env.step(policy())
        total += reward
        if term or trunc:
            break
    assert info["targets_hit"] >= 1 and total > 0.5
