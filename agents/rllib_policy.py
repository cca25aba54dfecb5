"""An RLlib RLModule as a deterministic policy for ``agents.evaluate`` (needs ray and torch).

An RLlib run folder keeps the algorithm checkpoint in ``checkpoint/``; its policy network is the
RLModule saved under ``checkpoint/learner_group/learner/rl_module/default_policy``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

#: Where an Algorithm checkpoint keeps the (single-agent) RLModule.
MODULE_SUBPATH = Path("learner_group") / "learner" / "rl_module" / "default_policy"


def load_module(checkpoint: str | Path) -> Any:
    """The RLModule of an RLlib PPO checkpoint folder."""
    from ray.rllib.core.rl_module.rl_module import RLModule

    return RLModule.from_checkpoint(str(Path(checkpoint).resolve() / MODULE_SUBPATH))


def deterministic_actions(module: Any, obs: np.ndarray) -> np.ndarray:
    """The module's most likely action for each row of ``obs``, clipped into the [-1, 1] box."""
    import torch

    with torch.no_grad():
        out = module.forward_inference({"obs": torch.as_tensor(np.asarray(obs, dtype=np.float32))})
        dist = module.get_inference_action_dist_cls().from_logits(out["action_dist_inputs"])
        actions = dist.to_deterministic().sample().numpy()
    return np.clip(actions, -1.0, 1.0).astype(np.float32)


def module_policy(module: Any) -> Callable[[object, int], Callable[[np.ndarray], np.ndarray]]:
    """A policy factory for ``agents.evaluate.play``: deterministic actions of ``module``."""

    def factory(env: object, episode: int) -> Callable[[np.ndarray], np.ndarray]:
        return lambda obs: deterministic_actions(module, obs[None])[0]

    return factory
