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
