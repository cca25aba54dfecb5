"""Gymnasium environments: nudge ball velocities so that wall impacts land on targets.

Every registered id (``collision_env.ENV_IDS``) is a preset of one task class,
:class:`CollisionTargetEnv`, configured by a :class:`TaskConfig`; :class:`CollisionTargetVectorEnv`
is the native vector env on the batched engine and :class:`CollisionSB3VecEnv` (in
``collision_env.envs.sb3``) adapts it to stable-baselines3. Each preset's env file registers its
task (``collision_env.envs.registry``); importing a file here is what ships it.
"""

# The preset files are imported in the order their ids are listed (registration order), not sorted.
from collision_env.envs._config import PRESETS, TaskConfig, make_config  # noqa: I001
from collision_env.envs._core import EpisodeSampler, sample_episode
from collision_env.envs.one_ball import OneBallTargetEnv, OneBallTargetVectorEnv
from collision_env.envs.line_1d import Line1DEnv, Line1DVectorEnv
from collision_env.envs.billiards import BilliardsEnv, BilliardsVectorEnv
from collision_env.envs.inelastic_cluster import InelasticClusterEnv, InelasticClusterVectorEnv
from collision_env.envs.multi_ball import MultiBallEnv, MultiBallVectorEnv
from collision_env.envs.crowd import CrowdEnv, CrowdVectorEnv
from collision_env.envs.pegs import PegsEnv, PegsVectorEnv
from collision_env.envs.fence import FenceEnv, FenceVectorEnv
from collision_env.envs.registry import PRESET_IDS, REGISTERED, Task, register_env, register_task
from collision_env.envs.target_env import CollisionTargetEnv
from collision_env.envs.vector import CollisionTargetVectorEnv

#: The generic env: any preset by name, any TaskConfig field by keyword.
GENERIC_ID = "CollisionEnv/Target-v0"
register_env(
    GENERIC_ID,
    CollisionTargetEnv,
    CollisionTargetVectorEnv,
    bench_scene=f"generic ({CollisionTargetEnv.preset} preset)",
)

__all__ = [
    "GENERIC_ID",
    "PRESETS",
    "PRESET_IDS",
    "REGISTERED",
    "BilliardsEnv",
    "BilliardsVectorEnv",
    "CollisionTargetEnv",
    "CollisionTargetVectorEnv",
    "CrowdEnv",
    "CrowdVectorEnv",
    "FenceEnv",
    "FenceVectorEnv",
    "InelasticClusterEnv",
    "InelasticClusterVectorEnv",
    "Line1DEnv",
    "Line1DVectorEnv",
    "MultiBallEnv",
    "MultiBallVectorEnv",
    "OneBallTargetEnv",
    "OneBallTargetVectorEnv",
    "PegsEnv",
    "PegsVectorEnv",
    "Task",
    "TaskConfig",
    "make_config",
    "register_task",
    "EpisodeSampler",
    "sample_episode",
]
