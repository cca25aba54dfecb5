"""collision_env: Gymnasium environments on a time-of-impact-correct ball collision engine.

``import collision_env`` registers the environment ids (namespace ``CollisionEnv``) with Gymnasium:

>>> import gymnasium as gym
>>> import collision_env  # noqa: F401
>>> env = gym.make("CollisionEnv/OneBallTarget-v0")

``gym.make("collision_env:CollisionEnv/OneBallTarget-v0")`` imports the package itself (handy for
tools that take a bare id, such as SB3's ``make_vec_env``). ``collision_env.ENV_IDS`` lists the ids.
"""

__version__ = "0.1.0"

from gymnasium.envs.registration import register as _register
from gymnasium.envs.registration import registry as _registry

#: id -> (module:class of the single env, module:class of the native vector env)
_ENVS = {
    "CollisionEnv/OneBallTarget-v0": ("one_ball:OneBallTargetEnv", "one_ball:OneBallTargetVectorEnv"),
    "CollisionEnv/Line1D-v0": ("line_1d:Line1DEnv", "line_1d:Line1DVectorEnv"),
    "CollisionEnv/Billiards-v0": ("billiards:BilliardsEnv", "billiards:BilliardsVectorEnv"),
    "CollisionEnv/InelasticCluster-v0": ("inelastic_cluster:InelasticClusterEnv",
                                         "inelastic_cluster:InelasticClusterVectorEnv"),
    "CollisionEnv/MultiBall-v0": ("multi_ball:MultiBallEnv", "multi_ball:MultiBallVectorEnv"),
    "CollisionEnv/Target-v0": ("target_env:CollisionTargetEnv", "vector:CollisionTargetVectorEnv"),
}

#: Every registered environment id.
ENV_IDS = tuple(_ENVS)

#: Control steps per episode: every preset runs 10 s of simulated time at dt = 0.05 s.
MAX_EPISODE_STEPS = 200

for _id, (_single, _vector) in _ENVS.items():
    if _id not in _registry:  # re-importing (e.g. importlib.reload) must not re-register
        _register(
            id=_id,
            entry_point=f"collision_env.envs.{_single}",
            vector_entry_point=f"collision_env.envs.{_vector}",
            max_episode_steps=MAX_EPISODE_STEPS,
        )

__all__ = ["ENV_IDS", "MAX_EPISODE_STEPS", "__version__"]
