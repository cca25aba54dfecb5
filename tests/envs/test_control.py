"""Velocity control (control="velocity"): the action names a velocity and an engage flag per
controlled ball, and the env nudges towards it within the same per-step limit and speed cap as a
nudge action.
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


def _resting_ball(control="velocity", x=0.0, v=(0.0, 0.0)):
    # one ball at (x, 0) moving at v (at rest by default), no shaping: the reward is the nudge's cost alone
    env = gym.make("CollisionEnv/OneBallTarget-v0", control=control, shaping=0.0, speed_range=(0.0, 0.0)).unwrapped
    env.reset(seed=2)
    state = env.get_state()
    state["core"]["engine"]["positions"][0, 0] = (x, 0.0)
    state["core"]["engine"]["velocities"][0, 0] = v
    env.set_state(state)
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


def test_the_named_velocity_is_clipped_then_kept_within_max_speed_and_each_step_costs_what_it_changes():
    env = _resting_ball(x=-1.0)
    cfg = env.config
    # (5, 0.5) is clipped to (1, 0.5), then scaled back to length 1: the velocity named is
    # max_speed * (2, 1) / sqrt(5), the only one of its direction on the cap's circle
    named = cfg.max_speed * np.array([2.0, 1.0]) / np.sqrt(5.0)
    for k in range(16):  # (it gets there after 12 steps, before it reaches a wall)
        before = env.core.vel[0, 0].copy()
        _, reward, _, _, info = env.step(np.array([5.0, 0.5, 1.0], np.float32))
        assert len(info["impacts"]) == 0, k
        change = np.linalg.norm(env.core.vel[0, 0] - before)
        assert info["nudge"] == pytest.approx(change, rel=1e-9, abs=1e-12), k
        assert reward == pytest.approx(-cfg.action_cost * info["nudge"], rel=1e-12, abs=1e-15), k
    assert np.allclose(env.core.vel[0, 0], named, rtol=0, atol=1e-12)
    assert info["nudge"] < 1e-12  # there: held for free


def test_a_ball_faster_than_max_speed_is_steered_to_a_velocity_no_longer_than_max_speed():
    v = np.array([2.5, 0.0])  # (after a collision, say)
    env = _resting_ball(v=v)
    cfg = env.config
    _, _, _, _, info = env.step(np.array([1.0, 1.0, 1.0], np.float32))  # (1, 1): scaled back to length 1
    named = cfg.max_speed * np.array([1.0, 1.0]) / np.sqrt(2.0)
    step = (named - v) * cfg.max_dv / np.abs(named - v).max()  # y changes by max_dv, x in proportion
    assert env.core.vel[0, 0] == pytest.approx(v + step, abs=1e-12)
    assert np.linalg.norm(env.core.vel[0, 0]) < np.linalg.norm(v)  # slower: it can name no more than max_speed
    assert info["nudge"] == pytest.approx(np.linalg.norm(step), rel=1e-12)


def test_velocity_control_in_1d():
    # the first ball from rest (the others rest too, over a metre away)
    env = gym.make("CollisionEnv/Line1D-v0", control="velocity", speed_range=(0.0, 0.0)).unwrapped
    env.reset(seed=0)
    cfg = env.config
    assert env.core.pos[0, 1, 0] - env.core.pos[0, 0, 0] > 1.0
    env.step(np.array([0.5, 1.0], np.float32))
    assert env.core.vel[0, 0, 0] == pytest.approx(cfg.max_dv, abs=1e-12)
    assert env.core.vel[0, 0, 1] == 0.0
    # a flag at or below zero coasts
    _, _, _, _, info = env.step(np.array([-1.0, 0.0], np.float32))
    assert info["nudge"] == 0.0 and env.core.vel[0, 0, 0] == pytest.approx(cfg.max_dv, abs=1e-12)
    # a named velocity beyond 1 is clipped: the ball is steered to max_speed and held there
    for _ in range(int(np.ceil(cfg.max_speed / cfg.max_dv))):
        _, _, _, _, info = env.step(np.array([7.0, 1.0], np.float32))
        assert len(info["impacts"]) == 0
    assert env.core.vel[0, 0, 0] == pytest.approx(cfg.max_speed, abs=1e-12) and info["nudge"] < 1e-12


def test_each_ball_follows_its_own_flag_and_velocity():
    # MultiBall at rest: only ball 1 is engaged, towards (-1, 0.4) m/s; balls 0 and 2 name
    # velocities too but their flags are off
    env = gym.make("CollisionEnv/MultiBall-v0", control="velocity", speed_range=(0.0, 0.0)).unwrapped
    env.reset(seed=3)
    cfg = env.config
    want = np.array([-1.0, 0.4])
    action = np.array([0.9, 0.9, -1.0, *(want / cfg.max_speed), 1.0, -0.5, 0.5, 0.0], np.float32)
    _, _, _, _, info = env.step(action)
    named = action[3:5].astype(np.float64) * cfg.max_speed  # want, to float32 precision
    step = named * cfg.max_dv / np.abs(named).max()  # x changes by max_dv, y in proportion
    assert np.allclose(env.core.vel[0, 1], step, rtol=0, atol=1e-12)
    assert np.array_equal(env.core.vel[0, [0, 2]], np.zeros((2, 2)))
    assert info["nudge"] == pytest.approx(np.linalg.norm(step), rel=1e-12)


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
    nudge = gym.make(env_id, control="nudge").unwrapped
    velocity = gym.make(env_id, control="velocity").unwrapped
    rng = np.random.default_rng(1)
    velocity.reset(seed=5)
    ctrl = list(nudge.config.controlled)
    for _ in range(12):
        a = rng.uniform(-1, 1, nudge.action_space.shape).astype(np.float32)
        a[rng.uniform(size=a.shape) < 0.2] = 0.0
        nudge.set_state(velocity.get_state())  # the same scene before each step
        converted = as_env_action(velocity, a)
        _, _, _, _, i1 = nudge.step(a)
        _, _, _, _, i2 = velocity.step(converted)
        assert i2["nudge"] == pytest.approx(i1["nudge"], abs=1e-6)
        assert np.allclose(velocity.core.vel[0, ctrl], nudge.core.vel[0, ctrl], rtol=0, atol=1e-6)
        if i1["is_success"] or i2["is_success"]:
            break


def test_a_converted_nudge_at_the_speed_cap_turns_the_ball_as_the_nudge_does():
    # at max_speed the cap shortens each nudge; the converted action names the capped velocity, so
    # a 14-step push at 10 degrees off the ball's heading turns it alike under both controls
    nudge, velocity = _resting_ball("nudge"), _resting_ball(x=-1.8)  # room to run to the right wall
    cfg = velocity.config
    while velocity.core.vel[0, 0, 0] < cfg.max_speed - 1e-12:  # accelerate along +x to the cap
        velocity.step(np.array([1.0, 0.0, 1.0], np.float32))
    nudge.set_state(velocity.get_state())
    push = np.array([np.cos(np.radians(10)), np.sin(np.radians(10))], np.float32)
    for k in range(14):
        v_before = velocity.core.vel[0, 0].copy()
        _, _, _, _, i1 = nudge.step(push)
        _, _, _, _, i2 = velocity.step(as_env_action(velocity, push))
        assert len(i1["impacts"]) == len(i2["impacts"]) == 0, k
        assert np.allclose(velocity.core.vel[0, 0], nudge.core.vel[0, 0], rtol=0, atol=1e-6), k
        # the velocity step pays for the change it makes, the nudge for the change it asked for
        assert i2["nudge"] == pytest.approx(np.linalg.norm(velocity.core.vel[0, 0] - v_before), rel=1e-5)
        assert i1["nudge"] == pytest.approx(cfg.max_dv, rel=1e-6)
    assert np.linalg.norm(nudge.core.vel[0, 0]) == pytest.approx(cfg.max_speed, rel=1e-9)
    heading = np.degrees(np.arctan2(velocity.core.vel[0, 0, 1], velocity.core.vel[0, 0, 0]))
    assert heading == pytest.approx(np.degrees(np.arctan2(*nudge.core.vel[0, 0, ::-1])), abs=1e-4)
    assert 0.0 < heading < 10.0


def test_a_nudge_that_turns_a_ball_at_the_cap_converts_to_the_same_line_within_max_dv_per_axis():
    # at the cap on the diagonal, a nudge across it is pulled back onto the cap's circle, which
    # changes y by more than max_dv; the converted action names the same velocity, and the velocity
    # step goes along the same line, shortened to max_dv on that axis
    v = np.array([1.0, 1.0]) * np.sqrt(2.0)
    nudge, velocity = _resting_ball("nudge", v=v), _resting_ball(v=v)
    cfg = velocity.config
    across = np.array([1.0, -1.0], np.float32)
    converted = as_env_action(velocity, across)
    nudge.step(across)
    velocity.step(converted)
    assert np.allclose(converted[:2] * cfg.max_speed, nudge.core.vel[0, 0], rtol=0, atol=1e-6)  # on the circle
    change = nudge.core.vel[0, 0] - v
    assert np.abs(change).max() > cfg.max_dv  # the cap's pull-back
    shortened = change * cfg.max_dv / np.abs(change).max()
    assert np.allclose(velocity.core.vel[0, 0], v + shortened, rtol=0, atol=1e-6)


@pytest.mark.parametrize("env_id", ["CollisionEnv/Billiards-v0", "CollisionEnv/InelasticCluster-v0"])
def test_the_scripted_shots_under_velocity_control_score_at_the_planned_step(env_id, monkeypatch):
    # the shooting policy plans on a copy of the env with the same conversion: each shot it fires
    # hits its target at exactly the step the plan predicted
    from collision_env.envs import scripted

    env = gym.make(env_id, control="velocity")
    planned = []

    def recorded_shoot(played, plans, horizon, planner=None):
        plan, hit_step, records = shoot(played, plans, horizon, planner)
        if plan is not None:
            planned.append(int(played.core.steps[0]) + hit_step)
        return plan, hit_step, records

    shoot = scripted.shoot
    monkeypatch.setattr(scripted, "shoot", recorded_shoot)
    fired = 0
    for episode in range(3):
        obs, info = env.reset(seed=episode)
        policy = scripted_policy(env)
        planned.clear()
        scored, hits, done = [], 0, False
        while not done:
            step = int(env.unwrapped.core.steps[0])
            obs, _, term, trunc, info = env.step(policy(obs))
            if info["targets_hit"] > hits:
                scored.append(step)
            hits, done = info["targets_hit"], term or trunc
        assert set(planned) <= set(scored), (episode, planned, scored)
        fired += len(planned)
    assert fired >= 3
