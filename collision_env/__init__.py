"""collision_env: Gymnasium environments on a time-of-impact-correct ball collision engine.

``import collision_env`` registers the environment ids (namespace ``CollisionEnv``) with Gymnasium:

>>> import gymnasium as gym
>>> import collision_env  # noqa: F401
>>> env = gym.make("CollisionEnv/OneBallTarget-v0")

``gym.make("collision_env:CollisionEnv/OneBallTarget-v0")`` imports the package itself (handy for
tools that take a bare id, such as SB3's ``make_vec_env``). ``collision_env.ENV_IDS`` lists the ids;
each comes from one entry of the task registry (``collision_env.envs.registry``).
"""

#: The package's version.
__version__ = "0.1.0"

from collision_env.envs import REGISTERED as _REGISTERED  # importing the envs registers them
from collision_env.envs import TaskConfig as _TaskConfig

#: Every registered environment id.
ENV_IDS = tuple(_REGISTERED)

#: Control steps per episode of the default task (10 s of simulated time at dt = 0.05 s), which
#: every shipped task keeps but ``Fence`` (one shot, decided within 15 steps of 0.1 s).
MAX_EPISODE_STEPS = _TaskConfig().n_steps

__all__ = ["ENV_IDS", "MAX_EPISODE_STEPS", "__version__"]
