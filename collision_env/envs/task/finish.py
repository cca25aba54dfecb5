"""The task kernel: what a control step makes of the engine's step, phase by phase."""

from __future__ import annotations

from collision_env.engine.compiled import njit

from .arrays import unpack
from .episode_end import advance_episodes, settle
from .observe import observe
from .scoring import score_impacts


@njit(refcount=False, label="the environments' rewards and observations")
def task_kernel(h, flags, imp, obs):  # pragma: no cover - numba
    """Score a step's impacts, update the targets, and write the observation, reward and end flags.

    ``h`` is the task's pack (:mod:`~.arrays`: the engine's state after the step, the task state
    and parameters); ``imp`` the engine's impact records of the step (sorted by scene, then time);
    ``flags`` one ``layout.ROW_*`` code per scene; ``obs`` the observation, written for the rows
    whose flag is not ``ROW_SKIP``, as are the reward, energy, targets hit and end flags. Updated in
    place: target status, current target, step count, the cluster mirror, phi.
    """
    engine, state, params = unpack(h)
    score_impacts(flags, imp, state, params)
    advance_episodes(flags, engine, state, params)
    observe(flags, obs, engine, state, params)
    settle(flags, engine, state, params)
