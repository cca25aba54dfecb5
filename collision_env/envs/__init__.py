"""Gymnasium environments: nudge ball velocities so that wall impacts land on targets.

Every registered id (``collision_env.ENV_IDS``) is a preset of one task class,
:class:`CollisionTargetEnv`, configured by a :class:`TaskConfig`; :class:`CollisionTargetVectorEnv`
is the native vector env on the batched engine and :class:`CollisionSB3VecEnv` (in
``collision_env.envs.sb3``) adapts it to stable-baselines3.
"""

from collision_env.envs._config import PRESETS, TaskConfig, make_config
from collision_env.envs._core import EpisodeSampler, Impacts, sample_episode
from collision_env.envs.billiards import BilliardsEnv, BilliardsVectorEnv
from collision_env.envs.inelastic_cluster import InelasticClusterEnv, InelasticClusterVectorEnv
from collision_env.envs.line_1d import Line1DEnv, Line1DVectorEnv
from collision_env.envs.multi_ball import MultiBallEnv, MultiBallVectorEnv
from collision_env.envs.one_ball import OneBallTargetEnv, OneBallTargetVectorEnv
from collision_env.envs.target_env import CollisionTargetEnv
from collision_env.envs.vector import CollisionTargetVectorEnv

#: preset name -> registered id
PRESET_IDS = {
    "one_ball": "CollisionEnv/OneBallTarget-v0",
    "line_1d": "CollisionEnv/Line1D-v0",
    "billiards": "CollisionEnv/Billiards-v0",
    "inelastic_cluster": "CollisionEnv/InelasticCluster-v0",
    "multi_ball": "CollisionEnv/MultiBall-v0",
}

__all__ = [
    "PRESETS",
    "PRESET_IDS",
    "BilliardsEnv",
    "BilliardsVectorEnv",
    "CollisionTargetEnv",
    "CollisionTargetVectorEnv",
    "Impacts",
    "InelasticClusterEnv",
    "InelasticClusterVectorEnv",
    "Line1DEnv",
    "Line1DVectorEnv",
    "MultiBallEnv",
    "MultiBallVectorEnv",
    "OneBallTargetEnv",
    "OneBallTargetVectorEnv",
    "TaskConfig",
    "make_config",
    "EpisodeSampler",
    "sample_episode",
]
