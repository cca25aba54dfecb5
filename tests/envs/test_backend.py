"""The env kernels' plain-Python form (numba's JIT disabled) gives the same episodes as the compiled one."""

import json
import os
import subprocess
import sys

import numpy as np

from collision_env.engine import BACKEND

SCRIPT = """
import json
import gymnasium as gym
import numpy as np
import collision_env
from collision_env.engine import BACKEND
from collision_env.envs import PRESET_IDS
out = {"backend": BACKEND}
for env_id in PRESET_IDS.values():
    venv = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    venv.action_space.seed(1)
    obs, _ = venv.reset(seed=1)
    rows = [obs.tolist()]
    for _ in range(40):
        obs, reward, terminated, truncated, info = venv.step(venv.action_space.sample())
        rows.append([obs.tolist(), reward.tolist(), terminated.tolist(), truncated.tolist()])
    out[env_id] = rows
env = gym.make(next(iter(PRESET_IDS.values())))
env.action_space.seed(2)
obs, _ = env.reset(seed=2)
out["single"] = [obs.tolist()] + [env.step(env.action_space.sample())[:2] for _ in range(40)]
out["single"] = json.loads(json.dumps(out["single"], default=lambda a: a.tolist()))
print(json.dumps(out))
"""


def run(disable_jit: bool) -> dict:
    env = dict(os.environ, NUMBA_DISABLE_JIT="1" if disable_jit else "0")
    done = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def flatten(rows) -> np.ndarray:
    if isinstance(rows, list):
        return np.concatenate([flatten(r) for r in rows]) if rows else np.zeros(0)
    return np.array([float(rows)])


def test_env_kernels_python_path_matches_compiled():
    compiled, python = run(False), run(True)
    assert python.pop("backend") == "python"
    assert compiled.pop("backend") == BACKEND
    assert compiled.keys() == python.keys()
    for key in compiled:
        # float32 observations: both paths compute in float64 and round once at the env boundary
        np.testing.assert_allclose(flatten(python[key]), flatten(compiled[key]), rtol=1e-6, atol=1e-6, err_msg=key)
