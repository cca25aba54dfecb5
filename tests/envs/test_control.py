"""Velocity control (control="velocity"): the action names a velocity and an engage flag per
controlled ball, and the env nudges towards it within the same limits as a nudge action.
Analytic values, the checkers, single-vs-vector equality, and the scripted policies under it."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

from collision_env.envs import PRESET_IDS
from collision_env.envs.scripted import as_env_action, scripted_policy
from tests.envs.test_vector import run_pair

IDS = sorted(PRESET_IDS.values())


def _resting_ball(**kwargs):
    # one ball at rest in the middle of the box, no shaping: the reward is the nudge's cost alone
    env = gym.make(
        "CollisionEnv/OneBallTarget-v0", control="velocity", shaping=0.0, speed_range=(0.0, 0.0), **kwargs
    ).unwrapped
    env.reset(seed=2)
    env.core.pos[0, 0] = (0.0, 0.0)
    return env


@pytest.mark.parametrize("env_id", IDS)
def test_each_controlled_ball_gets_one_component_per_axis_and_an_engage_flag(env_id):
    nudge = gym.make(env_id).unwrapped
    velocity = gym.make(env_id, control="velocity").unwrapped
    cfg = nudge.config
    assert velocity.action_space.shape == (len(cfg.controlled) * (cfg.dimension + 1),)
    assert nudge.action_space.shape == (len(cfg.controlled) * cfg.dimension,)


def test_the_ball_is_nudged_towards_the_named_velocity_by_at_most_max_dv_per_axis():
    env = _resting_ball()
    cfg = env.config
    step = cfg.max_dv
    want = np.array([1.0, 0.5])  # m/s: the action names want / max_speed
    action = np.array([*(want / cfg.max_speed), 1.0], np.float32)
    # along the straight line from rest to (1, 0.5): x changes by max_dv, y by half of it
    expected = np.zeros(2)
    for k in range(1, 10):
        _, reward, _, _, info = env.step(action)
        change = want - expected
        change *= min(1.0, step / max(np.abs(change).max(), step))
        expected = expected + change
        assert np.allclose(env.core.vel[0, 0], expected, rtol=0, atol=1e-12), k
        assert info["nudge"] == pytest.approx(np.linalg.norm(change), rel=1e-12)
        assert reward == pytest.approx(-cfg.action_cost * np.linalg.norm(change), rel=1e-12)
    # after 1 / max_dv steps (rounded up) the ball moves at the named velocity, and stays there for free
    assert np.allclose(env.core.vel[0, 0], want, rtol=0, atol=1e-6)
    _, reward, _, _, info = env.step(action)
    assert info["nudge"] < 1e-6 and np.allclose(env.core.vel[0, 0], want, rtol=0, atol=1e-6)


def test_a_flag_at_or_below_zero_leaves_the_ball_coasting_at_no_cost():
    env = _resting_ball()
    env.step(np.array([0.5, 0.0, 1.0], np.float32))
    v = env.core.vel[0, 0].copy()
    for flag in (0.0, -0.3, -1.0):
        _, reward, _, _, info = env.step(np.array([-1.0, 1.0, flag], np.float32))
        assert info["nudge"] == 0.0 and reward == 0.0
        assert np.array_equal(env.core.vel[0, 0], v)


def test_the_named_velocity_is_clipped_and_the_speed_cap_holds():
    env = _resting_ball()
    cfg = env.config
    for _ in range(12):  # (the ball reaches the cap after 10 steps, before it reaches a wall)
        _, _, _, _, info = env.step(np.array([5.0, 5.0, 1.0], np.float32))  # clipped: (2, 2) m/s, over the cap
        assert len(info["impacts"]) == 0
    assert np.linalg.norm(env.core.vel[0, 0]) == pytest.approx(cfg.max_speed, rel=1e-12)


def test_velocity_control_in_1d():
    env = gym.make("CollisionEnv/Line1D-v0", control="velocity").unwrapped
    env.reset(seed=0)
    cfg = env.config
    v0 = env.core.vel[0, 0, 0]
    env.step(np.array([0.5, 1.0], np.float32))
    want = 0.5 * cfg.max_speed
    assert env.core.vel[0, 0, 0] == pytest.approx(v0 + np.clip(want - v0, -cfg.max_dv, cfg.max_dv), abs=1e-12)
    assert env.core.vel[0, 0, 1] == 0.0


def test_a_nan_in_the_flag_raises_and_an_unknown_control_is_refused():
    env = _resting_ball()
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.array([0.1, 0.1, np.nan], np.float32))
    with pytest.raises(ValueError, match="control"):
        gym.make("CollisionEnv/Billiards-v0", control="torque")


@pytest.mark.parametrize("env_id", ["CollisionEnv/Billiards-v0", "CollisionEnv/Line1D-v0", "CollisionEnv/MultiBall-v0"])
def test_checkers_and_vector_equality_with_velocity_control(env_id):
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gym.make(env_id, control="velocity").unwrapped, skip_render_check=True)
        sb3_check_env(gym.make(env_id, control="velocity").unwrapped, warn=True)
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
        assert run_pair(env_id, mode, steps=30, seed=2, max_episode_steps=10, control="velocity") >= 4


@pytest.mark.parametrize("env_id", IDS)
def test_a_converted_nudge_changes_the_velocity_as_the_nudge_does(env_id):
    # as_env_action names the velocity a nudge leads to: the two controls then agree to the float32
    # rounding of that velocity
    nudge = gym.make(env_id).unwrapped
    velocity = gym.make(env_id, control="velocity").unwrapped
    rng = np.random.default_rng(1)
    nudge.reset(seed=5)
    velocity.reset(seed=5)
    for _ in range(12):
        a = rng.uniform(-1, 1, nudge.action_space.shape).astype(np.float32)
        a[rng.uniform(size=a.shape) < 0.2] = 0.0
        nudge.core.vel[...] = velocity.core.vel  # the same velocities before each step
        nudge.core.pos[...] = velocity.core.pos
        converted = as_env_action(velocity, a)
        _, _, _, _, i1 = nudge.step(a)
        _, _, _, _, i2 = velocity.step(converted)
        assert i2["nudge"] == pytest.approx(i1["nudge"], abs=1e-6)
        ctrl = list(nudge.config.controlled)
        assert np.allclose(velocity.core.vel[0, ctrl], nudge.core.vel[0, ctrl], rtol=0, atol=1e-6)
        if i1["is_success"] or i2["is_success"]:
            break


def test_the_scripted_billiards_policy_plays_under_velocity_control():
    # it plans on a copy of the env with the same conversion, so each shot it fires scores
    env = gym.make("CollisionEnv/Billiards-v0", control="velocity")
    hits = 0
    for episode in range(3):
        obs, _ = env.reset(seed=episode)
        policy = scripted_policy(env)
        done = False
        while not done:
            obs, _, term, trunc, info = env.step(policy(obs))
            done = term or trunc
        hits += info["targets_hit"]
    assert hits >= 4
