"""Registered ids work in processes that never imported collision_env, and the optional parts say
how to install what they need."""

import os
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

ENV_ID = "CollisionEnv/OneBallTarget-v0"
MODULE_ID = f"collision_env:{ENV_ID}"


def fresh_python(code: str, **env) -> subprocess.CompletedProcess:
    """Run ``code`` in a new interpreter (nothing of this test process imported)."""
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env={**os.environ, **env}
    )


@pytest.mark.parametrize(
    "code",
    [
        # the bare id, after importing the package (the README's first example)
        f"import gymnasium as gym, collision_env; env = gym.make({ENV_ID!r})",
        # the module:id form imports the package itself (for tools that only take an id)
        f"import gymnasium as gym; env = gym.make({MODULE_ID!r})",
        f"import gymnasium as gym; env = gym.make_vec({MODULE_ID!r}, num_envs=2)",
    ],
)
def test_each_documented_id_form_makes_and_steps_in_a_fresh_interpreter(code):
    run = fresh_python(
        code + "\nenv.reset(seed=0); env.step(env.action_space.sample())\nprint(type(env.unwrapped).__name__)"
    )
    assert run.returncode == 0, run.stderr
    assert "OneBallTarget" in run.stdout


def test_the_bare_id_without_the_import_is_gymnasiums_namespace_error():
    run = fresh_python(f"import gymnasium as gym; gym.make({ENV_ID!r})")
    assert run.returncode != 0 and "NamespaceNotFound" in run.stderr


@pytest.mark.parametrize("context", ["spawn", "forkserver"])
def test_async_vector_env_with_fresh_worker_processes_matches_the_sync_one(context):
    actions = np.random.default_rng(0).uniform(-1, 1, (5, 2, 2)).astype(np.float32)
    sync = gym.make_vec(MODULE_ID, num_envs=2, vectorization_mode="sync")
    asyn = gym.make_vec(MODULE_ID, num_envs=2, vectorization_mode="async", vector_kwargs={"context": context})
    try:
        obs_s, _ = sync.reset(seed=3)
        obs_a, _ = asyn.reset(seed=3)
        np.testing.assert_array_equal(obs_s, obs_a)
        for a in actions:
            step_s, step_a = sync.step(a), asyn.step(a)
            for x, y in zip(step_s[:4], step_a[:4], strict=True):
                np.testing.assert_array_equal(x, y)
    finally:
        sync.close()
        asyn.close()


def test_sb3_subproc_vec_env_over_the_module_id():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = make_vec_env(
        MODULE_ID, n_envs=2, seed=0, vec_env_cls=SubprocVecEnv, vec_env_kwargs={"start_method": "spawn"}
    )
    try:
        obs = venv.reset()
        assert obs.shape == (2, *venv.observation_space.shape)
        obs, rewards, dones, infos = venv.step(np.zeros((2, *venv.action_space.shape), np.float32))
        assert np.isfinite(obs).all() and len(infos) == 2
    finally:
        venv.close()


def test_a_rejected_make_vec_prints_no_destructor_error():
    run = fresh_python(f"""
import gymnasium as gym, collision_env
try:
    gym.make_vec({ENV_ID!r}, num_envs=2, dt=-1.0)
except ValueError as err:
    print("rejected:", err)
import gc; gc.collect()
""")
    assert run.returncode == 0, run.stderr
    assert "rejected: dt" in run.stdout
    assert "Exception ignored" not in run.stderr and "_renderers" not in run.stderr


def test_the_sb3_adapter_without_sb3_says_how_to_install_it():
    run = fresh_python("""
import sys
sys.modules["stable_baselines3"] = None  # as if it were not installed
try:
    import collision_env.envs.sb3
except ModuleNotFoundError as err:
    print(err)
""")
    assert run.returncode == 0, run.stderr
    assert 'pip install "collision_env[train]"' in run.stdout
