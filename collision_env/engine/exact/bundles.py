"""What the phases of an exact step take besides a scene's balls and physics
(``state.SceneBalls``, ``state.Physics``): its calendar and the step's work space, in named bundles.

The scheduler makes them once per scene and step (views of the batch's arrays, see
:mod:`~collision_env.engine.state`) and hands them to every phase, so that a phase takes a handful
of bundles instead of twenty arrays, and reads ``cl.rec`` rather than the twelfth of them.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..physics.motion import ball_views
from ..state import SceneBalls
from .calendar import EventQueue


class SceneCalendar(NamedTuple):
    """One scene's calendar (see :mod:`~collision_env.engine.exact.calendar`)."""

    rec: np.ndarray  #: (N,) ``layout.CAL_RECORD``
    ci: np.ndarray  #: (N, len(CAL_I)) int32
    heads: np.ndarray  #: (cells,) int32, the first ball of each grid cell
    q: EventQueue  #: the event queue
    inv_mass: np.ndarray  #: (N,) float64, each ball's inverse mass, taken with its radius
    last_impact: np.ndarray  #: (N,) float64, each ball's last collision instant (the TC model's)


class Work(NamedTuple):
    """A step's buffers: impact records and counters, and work space (``state.ExactScratch``)."""

    imp: np.ndarray  #: impact records (``layout.IMPACT_DTYPE``)
    n_imp: np.ndarray  #: rows filled, scenes that reached the event cap, scenes that stalled
    counters: np.ndarray  #: work counters (``layout.COUNTERS``)
    pending: np.ndarray  #: balls to predict (or whose motion an event changed, or a contact group)
    in_group: np.ndarray  #: a contact group's membership, per ball
    c_a: np.ndarray  #: a contact group's contacts: the lower ball
    c_b: np.ndarray  #: ... and the other ball (>= 0) or the wall (-1 - wall)
    c_hit: np.ndarray  #: ... and whether it was reported already
    c_f: np.ndarray  #: ... and its separation (dx, dy), closing speed and impulse (``contacts``)
    slot: np.ndarray  #: a ball's place in the contact group (-1: none)
    near: np.ndarray  #: the balls touching one ball of the group; a group's new order when reordered
    g_i: np.ndarray  #: per group place: neighbours along a row, pooled blocks, contact degrees (``contacts``)
    g_f: np.ndarray  #: per group place: pooled blocks' weights and sums
    ki: np.ndarray  #: a rotating cluster member's kinematics (``layout.KINEMATICS``)
    kj: np.ndarray  #: ... and its partner's
    event: SceneBalls  #: the two balls of an event, rows 0 and 1 (see ``scheduler.advance``)


@njit(inline="always")
def work(state, scratch):
    """The :class:`Work` of a step (``state.State`` and ``state.ExactScratch``)."""
    pos, vel, mass, inv_mass, radius, omega = ball_views(scratch.event)
    event = SceneBalls(pos[0], vel[0], mass[0], inv_mass[0], radius[0], scratch.event_body, omega[0])
    return Work(
        state.imp,
        state.n_imp,
        state.counters,
        scratch.pending,
        scratch.in_group,
        scratch.c_a,
        scratch.c_b,
        scratch.c_hit,
        scratch.c_f,
        scratch.slot,
        scratch.near,
        scratch.g_i,
        scratch.g_f,
        scratch.kinematics[0],
        scratch.kinematics[1],
        event,
    )
