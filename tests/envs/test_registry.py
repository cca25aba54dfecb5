"""The task registry: a task registered from its entry alone (a config plus its docstring) is a full
citizen: both env checkers pass, the native vector env matches Gymnasium's sync vector env, and the
ids, presets, benchmark scene map and hyperparameter fallback all know it."""

import importlib.util
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.registration import registry as gym_registry
from gymnasium.utils.env_checker import check_env, data_equivalence

import collision_env
from collision_env.envs import PRESET_IDS, PRESETS, REGISTERED, CollisionTargetEnv, Task, register_task
from collision_env.envs.registry import bench_scenes, hyperparams_fallback

TINY_ID = "CollisionEnv/TestTwoBallRelay-v0"


class TwoBallRelayEnv(CollisionTargetEnv):
    """
    ## Description

    A hypothetical task for the tests: two balls, only ball 0 nudged, only ball 1 scores.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: ball 0's velocity change.

    ## Observation Space

    `Box(-1, 1, (24,), float32)`:

    | Index     | Observation                                   |
    |-----------|-----------------------------------------------|
    | 6i + 0..5 | ball i = 0, 1: position, velocity, mass, scoring |
    | 12..21    | the current target                            |
    | 22, 23    | steps left, targets left                      |

    ## Rewards

    +1 per target hit by ball 1.

    ## Starting State

    Random.

    ## Episode End

    Both targets hit, or 5 s.
    """

    task = Task(
        env_id=TINY_ID,
        preset="test_two_ball_relay",
        config=dict(
            n_balls=2,
            controlled=(0,),
            scorers="others",
            n_targets=2,
            sequential=True,
            time_limit=5.0,
            mass_range=(0.5, 1.5),
            speed_range=(0.2, 0.6),
            others_speed_range=(0.0, 0.2),
        ),
        bench_scene="2 balls (test)",
        hyperparams_like="CollisionEnv/Line1D-v0",
    )


def _unregister(cls) -> None:
    task = cls.task
    for table, key in (
        (REGISTERED, task.env_id),
        (gym_registry, task.env_id),
        (PRESETS, task.preset),
        (PRESET_IDS, task.preset),
    ):
        table.pop(key, None)
    vector_name = cls.__name__[:-3] + "VectorEnv"
    if hasattr(sys.modules[cls.__module__], vector_name):
        delattr(sys.modules[cls.__module__], vector_name)


@pytest.fixture
def relay():
    """The hypothetical task, registered for one test only."""
    vector = register_task(TwoBallRelayEnv)
    try:
        yield vector
    finally:
        _unregister(TwoBallRelayEnv)


def test_a_task_registered_from_its_entry_passes_both_env_checkers(relay):
    env = gym.make(TINY_ID)
    assert env.unwrapped.config.n_balls == 2 and env.spec.max_episode_steps == 100  # 5 s at dt = 0.05 s
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=importlib.util.find_spec("pygame") is None)
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(gym.make(TINY_ID).unwrapped, warn=True)


def test_its_native_vector_env_matches_the_sync_vector_env(relay):
    native = gym.make_vec(TINY_ID, 3, vectorization_mode="vector_entry_point")
    sync = gym.make_vec(TINY_ID, 3, vectorization_mode="sync")
    assert type(native.unwrapped) is relay and relay.__name__ == "TwoBallRelayVectorEnv"
    rng = np.random.default_rng(1)
    a, b = [native.reset(seed=7)[0]], [sync.reset(seed=7)[0]]
    for _ in range(120):  # past the 100-step episodes: autoresets included
        act = rng.uniform(-1, 1, native.action_space.shape).astype(np.float32)
        a.append(native.step(act)[:4])
        b.append(sync.step(act)[:4])
    assert data_equivalence(a, b, exact=True)


def test_everything_else_is_derived_from_the_entry(relay):
    assert PRESET_IDS["test_two_ball_relay"] == TINY_ID and PRESETS["test_two_ball_relay"]["n_balls"] == 2
    assert bench_scenes()[TINY_ID] == "2 balls (test)"
    assert hyperparams_fallback(TINY_ID) == "CollisionEnv/Line1D-v0"
    generic = gym.make("CollisionEnv/Target-v0", preset="test_two_ball_relay")
    assert generic.unwrapped.config == gym.make(TINY_ID).unwrapped.config
    pytest.importorskip("yaml")
    from agents import config

    assert TINY_ID not in config.load_yaml(config.HYPERPARAMS)  # no entry of its own: it borrows Line1D's
    assert config.hyperparams_for(TINY_ID) == config.hyperparams_for("CollisionEnv/Line1D-v0")


def test_shipped_ids_come_from_the_registry():
    presets = {reg.task.preset: env_id for env_id, reg in REGISTERED.items() if reg.task is not None}
    assert presets == PRESET_IDS and set(PRESETS) == set(PRESET_IDS)
    assert collision_env.ENV_IDS == tuple(REGISTERED)
    for env_id, reg in REGISTERED.items():
        spec = gym.spec(env_id)
        assert spec.entry_point == f"{reg.single.__module__}:{reg.single.__name__}"
        assert spec.vector_entry_point == f"{reg.vector.__module__}:{reg.vector.__name__}"


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(config=dict(n_balls=0)), "task.config: n_balls"),
        (dict(config=dict(n_ball=2)), "task.config: unexpected keyword"),
        (dict(env_id="CollisionEnv/OneBallTarget-v0"), "already registered"),
        (dict(preset="one_ball"), "already a preset"),
    ],
)
def test_a_bad_entry_is_rejected_and_registers_nothing(change, message):
    import dataclasses

    bad = type(
        "BadEnv",
        (TwoBallRelayEnv,),
        {"__doc__": TwoBallRelayEnv.__doc__, "task": dataclasses.replace(TwoBallRelayEnv.task, **change)},
    )
    before = (dict(REGISTERED), dict(PRESETS), dict(PRESET_IDS), len(gym_registry))
    with pytest.raises(ValueError, match=message):
        register_task(bad)
    assert before == (dict(REGISTERED), dict(PRESETS), dict(PRESET_IDS), len(gym_registry))


def test_a_task_without_the_documented_sections_is_rejected():
    bare = type("BareEnv", (TwoBallRelayEnv,), {"__doc__": "No table here."})
    with pytest.raises(ValueError, match="lacks the section"):
        register_task(bare)
    assert TINY_ID not in REGISTERED
