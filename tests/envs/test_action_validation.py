"""The env's action path: an action that is not real numbers raises, and changes nothing."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence

import collision_env  # noqa: F401  (registers the ids)

BAD_ACTIONS = [
    np.array([0.5 + 1j, 0.0]),
    np.array([0.5, 0.0], dtype=np.complex64),
    [0.5 + 0j, 0.0],
    np.array(["0.5", "0.0"]),
    ["0.5", 0.0],
    np.array([True, False]),
    [True, 0.0],
    [np.bool_(True), 0.0],
]


@pytest.mark.parametrize("action", BAD_ACTIONS, ids=repr)
def test_a_non_real_action_raises_and_changes_nothing(action):
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    before = env.get_state()
    with pytest.raises(ValueError, match="action: expected real numbers"):
        env.step(action)
    assert data_equivalence(before["core"], env.get_state()["core"], exact=True)


@pytest.mark.parametrize("action", BAD_ACTIONS, ids=repr)
def test_a_non_real_vector_action_raises(action):
    envs = gym.make_vec("CollisionEnv/OneBallTarget-v0", num_envs=2, vectorization_mode="vector_entry_point")
    envs.reset(seed=0)
    actions = [action, [0.0, 0.0]]
    with pytest.raises(ValueError, match="actions: expected real numbers"):
        envs.step(actions)
    if isinstance(action, np.ndarray):  # a batch of them, as one array of that dtype
        with pytest.raises(ValueError, match="actions: expected real numbers"):
            envs.step(np.stack([action, action]))


@pytest.mark.parametrize(
    "action", [[0.5, 0.0], (np.float32(0.5), np.int64(0)), np.array([0.5, 0.0], np.float16), np.array([1, 0])]
)
def test_real_actions_of_any_numeric_type_are_taken(action):
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    env.step(action)


@pytest.mark.parametrize("values, accepted", [([0.5, -0.25], True), ([0.5, None], False), ([0.5, "x"], False)])
def test_object_arrays_follow_one_rule_in_the_single_and_the_vector_env(values, accepted):
    """An object array of real numbers is an action like any other; one holding anything else is
    refused, by the single env and the vector env alike."""
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    envs = gym.make_vec("CollisionEnv/OneBallTarget-v0", num_envs=2, vectorization_mode="vector_entry_point")
    envs.reset(seed=0)
    single = np.array(values, dtype=object)
    batch = np.array([values, [0.0, 0.0]], dtype=object)
    if accepted:
        env.step(single)
        envs.step(batch)
    else:
        with pytest.raises(ValueError, match="action: expected real numbers"):
            env.step(single)
        with pytest.raises(ValueError, match="actions: expected real numbers"):
            envs.step(batch)
