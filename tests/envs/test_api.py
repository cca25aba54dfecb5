"""Registration, both env checkers, determinism, pickling and bad input, for every registered id."""

import copy
import importlib.util
import math
import pickle
import re
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence

import collision_env
from collision_env.engine import Impacts
from collision_env.envs import GENERIC_ID, PRESET_IDS, PRESETS, TaskConfig


def rollout(env, seed, n=60, action_seed=0):
    rng = np.random.default_rng(action_seed)
    out = [env.reset(seed=seed)]
    for _ in range(n):
        a = rng.uniform(-1.2, 1.2, env.action_space.shape).astype(np.float32)
        step = env.step(a)
        out.append(step)
        if step[2] or step[3]:
            out.append(env.reset())
    return out


def test_every_id_is_registered_with_a_vector_entry_point():
    assert set(PRESET_IDS.values()) == set(collision_env.ENV_IDS) - {GENERIC_ID}  # every id but the generic one
    for env_id in collision_env.ENV_IDS:
        spec = gym.spec(env_id)
        assert spec.namespace == "CollisionEnv" and spec.version == 0
        shot = env_id == "CollisionEnv/Fence-v0"  # (one shot, decided within 1.5 s)
        assert spec.max_episode_steps == (15 if shot else collision_env.MAX_EPISODE_STEPS)
        assert spec.vector_entry_point is not None and spec.entry_point is not None


def test_module_import_syntax():
    env = gym.make("collision_env:CollisionEnv/OneBallTarget-v0")
    assert env.reset(seed=1)[0].shape == (18,)


def test_gymnasium_check_env_without_warnings(env_id):
    env = gym.make(env_id).unwrapped  # spec set: the checker also builds every render mode
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env, skip_render_check=importlib.util.find_spec("pygame") is None)
    env.close()


def test_sb3_check_env_without_warnings(env_id):
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(env_id).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(env, warn=True)


def test_wrapped_env_passive_checker_without_warnings(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rollout(env, seed=3, n=5)


def test_spaces_and_return_types(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=0)
    assert env.observation_space.dtype == np.float32 and env.action_space.dtype == np.float32
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)
    assert obs.dtype == np.float32 and env.observation_space.contains(obs)
    obs, reward, term, trunc, info = env.step(env.action_space.sample())
    assert type(reward) is float and type(term) is bool and type(trunc) is bool
    assert isinstance(info["impacts"], Impacts) and type(info["is_success"]) is bool
    assert type(info["event_cap"]) is bool and type(info["energy"]) is float


def test_same_seed_same_rollout_different_seed_differs(env_id):
    a = rollout(gym.make(env_id), seed=7)
    b = rollout(gym.make(env_id), seed=7)
    c = rollout(gym.make(env_id), seed=8)
    assert data_equivalence(a, b, exact=True)
    assert not data_equivalence(a, c, exact=True)


def test_episode_runs_to_truncation_at_max_episode_steps(env_id):
    env = gym.make(env_id)
    env.reset(seed=0)
    steps, term, trunc = 0, False, False
    while not (term or trunc):
        _, _, term, trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
        steps += 1
        assert np.isfinite(info["energy"])
    assert term or (trunc and steps == env.spec.max_episode_steps == env.unwrapped.config.n_steps)


def test_pickle_round_trip(env_id):
    env = gym.make(env_id)
    env.reset(seed=5)
    for _ in range(10):
        env.step(env.action_space.sample())
    clone = pickle.loads(pickle.dumps(env))
    for _ in range(30):
        a = env.action_space.sample()
        assert data_equivalence(env.step(a), clone.step(a), exact=True)
    assert data_equivalence(env.reset(), clone.reset(), exact=True)


def test_get_state_set_state_restores_exactly(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=11)
    for _ in range(5):
        env.step(env.action_space.sample())
    state = env.get_state()
    actions = [env.action_space.sample() for _ in range(40)]
    first = [env.step(a) for a in actions] + [env.reset()]
    env.set_state(copy.deepcopy(state))
    second = [env.step(a) for a in actions] + [env.reset()]
    assert data_equivalence(first, second, exact=True)


def test_set_state_names_the_keys_it_expects_and_changes_nothing():
    env = gym.make("CollisionEnv/Target-v0").unwrapped
    env.reset(seed=3)
    envs = gym.make_vec("CollisionEnv/Target-v0", num_envs=2, vectorization_mode="vector_entry_point")
    envs.reset(seed=3)
    for target, keys in ((env, "['core', 'rng']"), (envs, "['core', 'autoreset', 'rngs']")):
        before = target.get_state()
        with pytest.raises(ValueError, match=re.escape(f"expected a dict with the keys {keys}")):
            target.set_state({"engine": before["core"]["engine"]})
        with pytest.raises(TypeError, match="set_state: expected a dict"):
            target.set_state(None)
        bad = copy.deepcopy(before)
        bad["core"]["engine"]["velocities"][0, 0] = (1e200, 0.0)
        with pytest.raises(ValueError, match="ball 0: velocity must be finite"):
            target.set_state(bad)
        assert data_equivalence(before, target.get_state(), exact=True)


def test_substeps_beyond_the_engine_bound_are_refused_at_make():
    from collision_env.engine import MAX_SUBSTEPS

    with pytest.raises(ValueError, match=f"substeps: must be <= {MAX_SUBSTEPS}"):
        gym.make("CollisionEnv/Target-v0", mode="naive", substeps=10**9)
    env = gym.make("CollisionEnv/Target-v0", mode="naive", substeps=1000, observe="predicted").unwrapped
    assert env._core.ahead.substeps == MAX_SUBSTEPS  # the look-ahead's sub-steps, capped at the bound


def test_generic_env_reaches_every_preset():
    for preset, env_id in PRESET_IDS.items():
        a = rollout(gym.make(env_id), seed=2, n=30)
        b = rollout(gym.make("CollisionEnv/Target-v0", preset=preset), seed=2, n=30)
        assert data_equivalence(a, b, exact=True), preset
    assert set(PRESETS) == set(PRESET_IDS)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"n_balls": -1},
        {"n_balls": 0},
        {"mode": "fast"},
        {"elasticity": 1.5},
        {"elasticity": -0.1},
        {"dt": 0.0},
        {"dt": float("nan")},
        {"substeps": 0},
        {"mode": "exact", "substeps": 3},
        {"max_dv": -1.0},
        {"controlled": (5,)},
        {"target_walls": ("ceiling",)},
        {"window": 100.0},
        {"n_targets": 0},
        {"scorers": "cluster"},
        {"preset": "snooker"},
        {"mass_range": (0.0, 1.0)},
        {"radius": -0.1},
        {"n_balls": 400},
        {"target_width": 10.0},
        {"render_mode": "ansi"},
        {"max_events": 0},
    ],
)
@pytest.mark.filterwarnings("ignore:.*render_mode")
def test_bad_kwargs_raise_value_error_at_make(kwargs):
    env_id = "CollisionEnv/Target-v0" if "preset" in kwargs else "CollisionEnv/OneBallTarget-v0"
    with pytest.raises(ValueError):
        gym.make(env_id, **kwargs)


def test_bad_kwargs_raise_for_vector_env_too():
    with pytest.raises(ValueError):
        gym.make_vec("CollisionEnv/Billiards-v0", 4, mode="bogus")
    with pytest.raises(ValueError):
        gym.make_vec("CollisionEnv/Line1D-v0", 4, n_balls=-2)


@pytest.mark.parametrize(
    "make",
    [
        lambda **kw: gym.make("CollisionEnv/OneBallTarget-v0", **kw),
        lambda **kw: gym.make_vec("CollisionEnv/OneBallTarget-v0", 2, **kw),
        lambda **kw: TaskConfig(**kw),
    ],
    ids=["make", "make_vec", "TaskConfig"],
)
def test_a_misspelt_keyword_names_the_closest_ones(make):
    with pytest.raises(ValueError, match=r"'substep' \(did you mean 'substeps'\?\)") as err:
        make(substep=4)
    assert isinstance(err.value, TypeError)  # as for any call with an unknown keyword
    with pytest.raises(ValueError, match=r"'zzz';"):  # nothing close: no suggestion
        make(zzz=1)


def test_a_misspelt_env_argument_or_preset_is_suggested_too():
    with pytest.raises(ValueError, match=r"did you mean 'trails'\?"):
        gym.make("CollisionEnv/OneBallTarget-v0", trail=True)
    with pytest.raises(ValueError, match=r"did you mean 'billiards'\?"):
        gym.make("CollisionEnv/Target-v0", preset="billiard")


def test_nan_action_raises_and_leaves_state_unchanged():
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    before = env.get_state()
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.array([np.nan, 0.0], np.float32))
    after = env.get_state()
    assert data_equivalence(before["core"], after["core"], exact=True)
    with pytest.raises(ValueError):
        env.step(np.zeros(3, np.float32))  # wrong size


def test_out_of_range_actions_are_clipped():
    a = gym.make("CollisionEnv/OneBallTarget-v0", shaping=0.0).unwrapped
    b = gym.make("CollisionEnv/OneBallTarget-v0", shaping=0.0).unwrapped
    a.reset(seed=4)
    b.reset(seed=4)
    for big in ([5.0, -7.0], [np.inf, -np.inf], [1.0, -0.3]):
        ra = a.step(np.array(big, np.float32))
        rb = b.step(np.clip(np.array(big, np.float32), -1, 1))
        assert data_equivalence(ra, rb, exact=True)


def test_info_nudge_is_the_requested_velocity_change_and_its_cost_is_charged():
    # shaping off and a ball far from the walls: the reward is -action_cost * |requested dv| exactly
    env = gym.make("CollisionEnv/OneBallTarget-v0", shaping=0.0, speed_range=(0.0, 0.0)).unwrapped
    _, info = env.reset(seed=2)
    assert info["nudge"] == 0.0
    cfg = env.config
    for action, size in (
        ([1.0, 0.0], cfg.max_dv),
        ([3.0, 0.0], cfg.max_dv),
        ([-1.0, 1.0], cfg.max_dv * 2**0.5),
        ([0.0, 0.0], 0.0),
    ):
        _, reward, _, _, info = env.step(np.array(action, np.float32))
        assert type(info["nudge"]) is float and info["nudge"] == pytest.approx(size, rel=1e-6)
        assert reward == pytest.approx(-cfg.action_cost * size, rel=1e-6) and len(info["impacts"]) == 0


def test_kwargs_reach_the_engine():
    env = gym.make("CollisionEnv/Billiards-v0", mode="posteriori", substeps=3, dt=0.1, max_events=77).unwrapped
    sim = env.simulator
    assert (sim.mode, sim.substeps, sim.max_events) == ("posteriori", 3, 77)
    assert env.config.dt == 0.1 and env.config.n_steps == 100 and env.metadata["render_fps"] == 10
    env.reset(seed=0)
    assert env.step(env.action_space.sample())[4]["time"] == pytest.approx(0.1)
    for mode in ("naive", "posteriori", "exact"):
        venv = gym.make_vec("CollisionEnv/OneBallTarget-v0", 3, mode=mode)
        assert venv.unwrapped.core.batch.mode == mode


def test_info_is_fresh_and_impacts_match_the_engine():
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    seen = 0
    for _ in range(200):
        _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        imp = info["impacts"]
        for rec in imp:
            seen += 1
            assert rec.wall in ("left", "right", "bottom", "top") and rec.ball == 0
            x, y = rec.point
            assert x in (-2.0, 2.0) or y in (-1.0, 1.0)  # contact points lie exactly on the walls
        # (the info's records are its own: a view of the engine's impact buffer would keep it
        # alive whole for as long as the info is kept)
        assert not isinstance(imp.array.base, np.ndarray)  # (a view of any impact buffer has one as its base)
        if term or trunc:
            break
    assert seen > 0


def test_engine_models_only_what_each_preset_needs():
    expect = {  # id: (ball pairs, clusters, dimension)
        "CollisionEnv/OneBallTarget-v0": (False, False, 2),
        "CollisionEnv/MultiBall-v0": (False, False, 2),
        "CollisionEnv/Line1D-v0": (True, False, 1),
        "CollisionEnv/Billiards-v0": (True, False, 2),
        "CollisionEnv/InelasticCluster-v0": (True, True, 2),
    }
    for env_id, (pairs, clusters, dim) in expect.items():
        env = gym.make(env_id).unwrapped
        models = env.simulator.models
        assert (models["ball_pairs"], models["clusters"], models["dimension"]) == (pairs, clusters, dim), env_id
        env.reset(seed=0)
        for _ in range(50):
            env.step(env.action_space.sample())
        if not pairs:
            assert env.simulator.stats["pair_tests"] == 0, env_id


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(dt=1e-300), r"time_limit: 10 s in control steps of dt = 1e-300 s is 1e\+301 steps"),
        (dict(time_limit=1e300), r"time_limit: 1e\+300 s in control steps of dt = 0.05 s"),
        (dict(max_events=10**20), r"max_events: must be <= 9223372036854775807"),
    ],
)
def test_episode_lengths_and_event_caps_beyond_what_is_counted_exactly_are_refused_by_name(kwargs, message):
    # (these raised OverflowError, naming no field, when the step counter or the cap was stored)
    with pytest.raises(ValueError, match=message):
        gym.make("CollisionEnv/OneBallTarget-v0", **kwargs)


@pytest.mark.parametrize(
    "field", ["max_dv", "max_speed", "hit_reward", "success_bonus", "miss_penalty", "action_cost", "shaping"]
)
def test_speeds_and_reward_weights_beyond_the_engines_range_are_refused_by_name(field):
    # (on d8ab1a0 max_dv=1e300 squared to inf in the nudge's size, and the reward was -inf)
    with pytest.raises(ValueError, match=rf"{field}: must be <= 1e\+150, got 1e\+300"):
        gym.make("CollisionEnv/OneBallTarget-v0", **{field: 1e300})
    if field not in ("max_dv", "max_speed"):
        with pytest.raises(ValueError, match=rf"{field}: must be >= -1e\+150, got -1e\+300"):
            gym.make("CollisionEnv/OneBallTarget-v0", **{field: -1e300})


def test_the_largest_nudge_and_action_cost_give_finite_rewards():
    env = gym.make("CollisionEnv/OneBallTarget-v0", max_dv=1e150, action_cost=1e150, shaping=1e150)
    env.reset(seed=0)
    for _ in range(20):
        obs, reward, *_ = env.step(np.ones(env.action_space.shape, dtype=np.float32))
        assert np.isfinite(obs).all() and math.isfinite(reward) and reward < -1e299
