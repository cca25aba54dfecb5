"""The envs' set_state checks the task state's values as the engine checks its own:
finite floats in range, indices within their arrays, flags of the right kind, no unknown key.
A refusal names the field and leaves the env as it was; a state it takes steps to finite outputs."""

import copy
import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.envs.task.layout import SCENE_FLOATS, SCENE_INTS, TARGET_GEOMETRY, TARGET_INTS

# (a task that reads every field: shaping reads phi, windows the target geometry, 3 balls the body)
TASK = dict(n_balls=3, n_targets=3, sequential=True, shaping=1.0, window=5.0)
K, N = TASK["n_targets"], TASK["n_balls"]
COLUMNS = {
    "scene_f": SCENE_FLOATS,
    "scene_i": SCENE_INTS,
    "targets": TARGET_INTS,
    "target_geo": TARGET_GEOMETRY,
}


def stepped_env(**overrides):
    env = gym.make("CollisionEnv/Target-v0", **{**TASK, **overrides}).unwrapped
    env.reset(seed=7)
    env.action_space.seed(7)
    for _ in range(3):
        env.step(env.action_space.sample())
    return env


def stepped_vector_env():
    envs = gym.make_vec("CollisionEnv/Target-v0", num_envs=2, vectorization_mode="vector_entry_point", **TASK)
    envs.reset(seed=7)
    for _ in range(3):
        envs.step(envs.action_space.sample())
    return envs.unwrapped


def changed(state, field, column, value, row=0, item=0):
    """A deep copy of an env state with one task value changed (``item``: the target or the ball)."""
    bad = copy.deepcopy(state)
    arr = bad["core"][field]
    if field == "body":
        arr[row, item] = value
    elif field in ("targets", "target_geo"):
        arr[row, item, getattr(COLUMNS[field], column)] = value
    else:
        arr[row, getattr(COLUMNS[field], column)] = value
    return bad


def refused(env, bad, match, error=ValueError):
    before = env.get_state()
    with pytest.raises(error, match=match):
        env.set_state(bad)
    assert data_equivalence(before, env.get_state(), exact=True)


# field, column, value, what the message says
BAD_VALUES = [
    ("scene_f", "phi", math.nan, "scene_f phi: .*must be from -1 to 0"),
    ("scene_f", "phi", 0.5, "scene_f phi: .*must be from -1 to 0"),
    ("scene_f", "nudge", -1.0, "scene_f nudge: .*must be finite and >= 0"),
    ("scene_f", "nudge", math.inf, "scene_f nudge: .*must be finite and >= 0"),
    ("scene_f", "reward", -math.inf, "scene_f reward: .*must be finite"),
    ("scene_f", "energy", math.nan, "scene_f energy: .*must be finite and >= 0"),
    ("scene_i", "current", -5, f"scene_i current: .*must be a target index from 0 to {K}"),
    ("scene_i", "current", K + 1, f"scene_i current: .*must be a target index from 0 to {K}"),
    ("scene_i", "steps", -1, "scene_i steps: .*must be from 0 to"),
    ("scene_i", "targets_hit", K + 1, f"scene_i targets_hit: .*must be from 0 to {K}"),
    ("scene_i", "terminated", 2, "scene_i terminated: .*must be 0 or 1"),
    ("scene_i", "success", -1, "scene_i success: .*must be 0 or 1"),
    ("scene_i", "misses", -3, "scene_i misses: .*must be from 0 to"),
    ("targets", "wall", 4, "targets wall: .*target 0: must be the code of one of the walls"),
    ("targets", "wall", -1, "targets wall: .*target 0: must be the code of one of the walls"),
    ("targets", "status", 3, "targets status: .*target 0: must be 0, 1 or 2"),
    ("target_geo", "centre", math.nan, "target_geo centre: .*target 0: must be finite"),
    ("target_geo", "half_width", 0.0, "target_geo half_width: .*target 0: must be finite and > 0"),
    ("target_geo", "half_width", math.nan, "target_geo half_width: .*target 0: must be finite and > 0"),
    ("target_geo", "opens", math.nan, "target_geo opens: .*target 0: must be a time"),
    ("target_geo", "closes", -1e301, "target_geo closes: .*target 0: must be a time.*at least opens"),
    ("body", None, N, f"body: .*ball 0: must be a ball index from 0 to {N - 1}"),
    ("body", None, -1, f"body: .*ball 0: must be a ball index from 0 to {N - 1}"),
]


@pytest.mark.parametrize(("field", "column", "value", "match"), BAD_VALUES)
def test_set_state_refuses_a_bad_task_value_naming_it_and_changes_nothing(field, column, value, match):
    env = stepped_env()
    refused(env, changed(env.get_state(), field, column, value), f"set_state: {match}")


@pytest.mark.parametrize(("field", "column", "value", "match"), BAD_VALUES[::4])
def test_the_vector_env_refuses_them_naming_the_sub_env(field, column, value, match):
    envs = stepped_vector_env()
    state = envs.get_state()
    bad = copy.deepcopy(state)
    bad["core"] = changed({"core": state["core"]}, field, column, value, row=1)["core"]
    refused(envs, bad, f"set_state: {match.replace(': .*', ': scene 1[:,] .*', 1)}")


def test_a_cluster_root_must_be_its_own_root():
    env = stepped_env(elasticity=0.0, inelastic="stick", scorers="cluster")
    state = env.get_state()
    bad = copy.deepcopy(state)
    bad["core"]["body"][0] = [1, 2, 2]  # (ball 0's root, ball 1, has its root elsewhere)
    refused(env, bad, "set_state: body: ball 0: must be a ball index whose cluster root is its own, got 1")


def test_the_cluster_mirror_must_be_the_engine_states_clusters():
    """A task state and an engine state from two snapshots (a stick cluster in one, none in the
    other) are refused together, naming the first ball that differs; the matching pairs are taken."""
    env = gym.make("CollisionEnv/InelasticCluster-v0").unwrapped
    env.reset(seed=0)
    env.action_space.seed(0)
    free = env.get_state()
    for _ in range(2000):  # (random nudges stick two balls within a few episodes)
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if (env.core.body[0] != np.arange(len(env.core.body[0]))).any():
            break
        if terminated or truncated:
            env.reset()
    stuck = env.get_state()
    ball = int(np.flatnonzero(stuck["core"]["body"][0] != np.arange(len(stuck["core"]["body"][0])))[0])
    for task, engine in ((free, stuck), (stuck, free)):
        mixed = copy.deepcopy(task)
        mixed["core"]["engine"] = copy.deepcopy(engine["core"]["engine"])
        refused(env, mixed, f"set_state: body: ball {ball}: must be the ball's cluster root in the engine's state")
    for whole in (free, stuck):
        env.set_state(whole)
        np.testing.assert_array_equal(env.core.body, whole["core"]["body"])


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("scene_i", np.zeros((1, len(SCENE_INTS))), "scene_i: expected integers, got dtype float64"),
        ("targets", np.ones((1, K, len(TARGET_INTS)), dtype=bool), "targets: expected integers, got dtype bool"),
        ("body", np.array([[0.0, 1.5, 2.0]]), "body: expected integers, got dtype float64"),
        ("scene_f", np.zeros((1, len(SCENE_FLOATS)), dtype=bool), "scene_f: expected real numbers, got dtype bool"),
        ("target_geo", np.full((1, K, len(TARGET_GEOMETRY)), "0.1"), "target_geo: expected real numbers, got dtype"),
        ("scene_i", np.full((1, len(SCENE_INTS)), 2**63, dtype=np.uint64), "scene_i current: must be a target"),
    ],
)
def test_set_state_refuses_values_of_the_wrong_kind(field, value, match):
    env = stepped_env()
    bad = copy.deepcopy(env.get_state())
    bad["core"][field] = value
    refused(env, bad, f"set_state: {match}")


def test_set_state_refuses_unknown_keys_naming_the_closest():
    env = stepped_env()
    state = env.get_state()
    bad = copy.deepcopy(state)
    bad["core"]["target_geometry"] = bad["core"]["target_geo"]
    refused(env, bad, r"set_state: unknown key\(s\) 'target_geometry' \(did you mean 'target_geo'")
    bad = {**copy.deepcopy(state), "rngs": state["rng"]}
    refused(env, bad, r"set_state: unknown key\(s\) 'rngs' \(did you mean 'rng'")
    envs = stepped_vector_env()
    vector = envs.get_state()
    bad = {**copy.deepcopy(vector), "auto_reset": vector["autoreset"]}
    refused(envs, bad, r"set_state: unknown key\(s\) 'auto_reset' \(did you mean 'autoreset'")


def test_a_refused_state_leaves_the_episode_running_bit_for_bit():
    env, twin = stepped_env(), stepped_env()
    with pytest.raises(ValueError):
        env.set_state(changed(env.get_state(), "scene_i", "current", -5))
    actions = [env.action_space.sample() for _ in range(30)]
    assert data_equivalence([env.step(a) for a in actions], [twin.step(a) for a in actions], exact=True)


EXTREMES = [-1e300, -5.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 1e300, math.inf, -math.inf, math.nan]


@settings(max_examples=80, deadline=None)
@given(
    where=st.sampled_from(
        [(f, c) for f, layout in COLUMNS.items() for c in layout._fields] + [("body", None)],
    ),
    item=st.integers(0, 2),
    value=st.sampled_from(EXTREMES),
)
def test_a_state_set_state_takes_steps_to_finite_outputs(where, item, value):
    """Any one task value set to an extreme: refused by name, or taken and then stepped to a
    finite reward and observation (never a NaN, never an index out of its array)."""
    field, column = where
    whole = field in ("scene_i", "targets", "body")
    if whole and not (float(value).is_integer() and abs(value) < 2**62):
        return  # (no int64 value: the kind check refuses an array of these before any value is read)
    env = stepped_env()
    bad = changed(env.get_state(), field, column, int(value) if whole else value, 0, item)
    try:
        env.set_state(bad)
    except ValueError as error:
        assert str(error).startswith(f"set_state: {field}")  # (opens after closes: closes is named)
        return
    for _ in range(5):
        obs, reward, *_ = env.step(env.action_space.sample())
        assert np.isfinite(obs).all() and math.isfinite(reward)
