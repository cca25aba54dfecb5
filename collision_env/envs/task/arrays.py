"""The task's arrays as named bundles, and how its kernels get them.

A batch of B task instances keeps its state in a few packed arrays (columns named in
:mod:`~.layout`), allocated once by ``TaskCore`` and updated in place; the kernels also read the
engine's balls, clocks and clusters (``BatchSimulator.live_arrays``). All of these are handed over
once, as one pack (:func:`pack`), so that a kernel call from Python checks one array instead of
fifteen; each call adds only what changes from call to call (the actions, the row flags, the
step's impacts, the observation).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from collision_env.engine.compiled import HAVE_NUMBA, njit, pack_arrays


class Engine(NamedTuple):
    """The engine's arrays the task reads (views of the simulator's own)."""

    balls: np.ndarray  #: (B, N, len(BALL)) float64 per-ball state
    time: np.ndarray  #: (B,) float64 clocks, s
    clusters: np.ndarray  #: (B, N) int64, the ball rooting each ball's cluster


class TaskState(NamedTuple):
    """Each scene's task state (one row per scene)."""

    scene_f: np.ndarray  #: (B, len(SCENE_FLOATS)) float64: aiming potential, nudge, reward, energy
    scene_i: np.ndarray  #: (B, len(SCENE_INTS)) int64: current target, steps, targets hit, flags
    targets: np.ndarray  #: (B, K, len(TARGET_INTS)) int64: each target's wall and status
    target_geo: np.ndarray  #: (B, K, len(TARGET_GEOMETRY)) float64: each target's segment and window
    body: np.ndarray  #: (B, N) int64: the task's mirror of the engine's cluster roots
    nudge: np.ndarray  #: (B, N, 2) float64: the step's velocity changes (rewritten every step)
    ahead_body: np.ndarray  #: (B, N) int64: the clusters replayed through the look-ahead (scratch)


class TaskParams(NamedTuple):
    """The task's parameters, shared by every scene."""

    params: np.ndarray  #: (len(PARAMS),) float64
    switches: np.ndarray  #: (len(SWITCHES),) int64
    controlled: np.ndarray  #: (C,) int64: the balls the action nudges, in action order
    scoring: np.ndarray  #: (N,) bool: the balls whose wall impacts score
    shown: np.ndarray  #: (N,) bool: the balls the observation shows


def pack(engine: Engine, state: TaskState, params: TaskParams) -> np.ndarray | tuple:
    """The bundles as the kernels take them: one int64 pack of their arrays (with numba), or the
    tuple of bundles (without). The owner keeps the arrays alive and packs again if one is replaced."""
    if not HAVE_NUMBA:
        return engine, state, params
    return pack_arrays([*engine, *state, *params])


_STATE_SLOT = len(Engine._fields)
_PARAMS_SLOT = _STATE_SLOT + len(TaskState._fields)

if HAVE_NUMBA:
    from collision_env.engine.compiled import view

    @njit(inline="always")
    def unpack(h):
        """The :class:`Engine`, :class:`TaskState` and :class:`TaskParams` of pack ``h``."""
        s, p = _STATE_SLOT, _PARAMS_SLOT
        engine = Engine(view(h, 0, np.float64, 3), view(h, 1, np.float64, 1), view(h, 2, np.int64, 2))
        state = TaskState(
            view(h, s, np.float64, 2),
            view(h, s + 1, np.int64, 2),
            view(h, s + 2, np.int64, 3),
            view(h, s + 3, np.float64, 3),
            view(h, s + 4, np.int64, 2),
            view(h, s + 5, np.float64, 3),
            view(h, s + 6, np.int64, 2),
        )
        params = TaskParams(
            view(h, p, np.float64, 1),
            view(h, p + 1, np.int64, 1),
            view(h, p + 2, np.int64, 1),
            view(h, p + 3, np.bool_, 1),
            view(h, p + 4, np.bool_, 1),
        )
        return engine, state, params

else:

    def unpack(h: tuple) -> tuple[Engine, TaskState, TaskParams]:
        """The :class:`Engine`, :class:`TaskState` and :class:`TaskParams` of ``h`` (the tuple)."""
        return h
