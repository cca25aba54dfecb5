"""Run by ``make wheel-check`` in a clean venv holding only the built wheel and its dependencies
(numba among them): the wheel installs ``collision_env`` alone, and the default env makes, resets
and steps."""

import importlib.util
import sysconfig
from pathlib import Path

import gymnasium as gym

import collision_env

site = Path(sysconfig.get_paths()["purelib"])
assert Path(collision_env.__file__).is_relative_to(site), f"collision_env imported from {collision_env.__file__}"
assert importlib.util.find_spec("agents") is None, "the wheel installs a top-level package 'agents'"
assert collision_env.engine.BACKEND == "numba", collision_env.engine.BACKEND

env = gym.make("CollisionEnv/OneBallTarget-v0")
obs, info = env.reset(seed=0)
obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
assert env.observation_space.contains(obs)
print(f"collision_env {collision_env.__version__} from {site}: reset and step ok (reward {reward:.3f})")
