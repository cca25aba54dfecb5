"""Lazy motion: a ball's calendar record holds its straight-line trajectory.

A record (``layout.CAL_RECORD``) holds the ball's centre at its own ``ref_time`` and its velocity.
Balls are moved there lazily, only when an event touches them. An event's balls are copied from
their records (and the calendar's inverse masses) into two rows laid out as ball state
(``Work.event`` of the scheduler), the response kernels resolve them there, and the records take
back what changed; the engine's ball state (what the caller reads) is brought up to date from the
records for every ball when the step ends. So an event reads and writes the calendar alone: in a
large scene the ball state's rows stay out of the cache. Two kinds of scene resolve events
in the ball state itself instead (in place), and the records are loaded from it: stick scenes,
whose clusters move as a whole, so that every ball is advanced at once
(:func:`~.clusters.sync_all`); and inelastic forward steps, whose contact groups may take in any
ball, so that an event's balls, and every ball its contact group looks at, are brought to the
event's time in their own rows (:func:`take_in_place`), and the other rows stay behind until the
step ends.

Every prediction and every re-verification of a pair uses one formula on the records alone
(:func:`pair_time`), so the answer does not depend on when it is asked: a calendar kept for many
steps and a fresh one agree.
"""

from __future__ import annotations

from .._jit import njit
from ..physics.toi import toi_pair, toi_wall


@njit(inline="always")
def position_at(k, t, rec):
    """Where ball ``k`` is at step time ``t``."""
    r = rec[k]
    dt = t - r["ref_time"]
    return r["x"] + r["vx"] * dt, r["y"] + r["vy"] * dt


@njit(inline="always")
def sync(k, t, rec):
    """Move ball ``k``'s record to step time ``t`` (straight-line motion)."""
    r = rec[k]
    dt = t - r["ref_time"]
    if dt != 0.0:
        r["x"] += r["vx"] * dt
        r["y"] += r["vy"] * dt
        r["ref_time"] = t


@njit(inline="always")
def store(k, rec, pos, vel, row):
    """Ball ``k``'s record (position and velocity) into row ``row`` of a ball state."""
    r = rec[k]
    pos[row, 0] = r["x"]
    pos[row, 1] = r["y"]
    vel[row, 0] = r["vx"]
    vel[row, 1] = r["vy"]


@njit(inline="always")
def load(k, t, rec, pos, vel, row):
    """Row ``row`` of a ball state into ball ``k``'s record, as of step time ``t``."""
    r = rec[k]
    r["x"] = pos[row, 0]
    r["y"] = pos[row, 1]
    r["vx"] = vel[row, 0]
    r["vy"] = vel[row, 1]
    r["ref_time"] = t


@njit(inline="always")
def settle(k, t, rec, pos, vel):
    """End a step at step time ``t`` for ball ``k``: its record moved there and its times made
    relative to it (its reference time 0, its event's time less ``t``), its position and velocity
    into its row of the ball state (events resolved on their own rows left it behind)."""
    r = rec[k]
    dt = t - r["ref_time"]
    x = r["x"] + r["vx"] * dt
    y = r["y"] + r["vy"] * dt
    r["x"] = x
    r["y"] = y
    r["ref_time"] = 0.0
    r["event_time"] -= t
    pos[k, 0] = x
    pos[k, 1] = y
    vel[k, 0] = r["vx"]
    vel[k, 1] = r["vy"]


@njit(refcount=False, forceinline=True)
def take(k, row, t, cl, ev):
    """Ball ``k``, moved in its record to step time ``t``, into row ``row`` of an event's balls."""
    sync(k, t, cl.rec)
    store(k, cl.rec, ev.pos, ev.vel, row)
    ev.radius[row] = cl.rec[k]["radius"]
    ev.inv_mass[row] = cl.inv_mass[k]


@njit(refcount=False, forceinline=True)
def take_in_place(k, t, rec, b):
    """Ball ``k``, moved in its record to step time ``t``, into its own row of the ball state ``b``
    (an event resolved in place: see the module doc)."""
    sync(k, t, rec)
    store(k, rec, b.pos, b.vel, k)


@njit(refcount=False, forceinline=True)
def pair_gap(i, k, rec):
    """Balls ``i`` and ``k`` at the later of their reference times ``tc``: ``(tc, dx, dy, dvx, dvy,
    sigma)``, the separation and relative velocity of ``k`` from ``i`` and the radii sum."""
    ri = rec[i]
    rk = rec[k]
    tc = max(ri["ref_time"], rk["ref_time"])
    xi, yi = position_at(i, tc, rec)
    xk, yk = position_at(k, tc, rec)
    return tc, xk - xi, yk - yi, rk["vx"] - ri["vx"], rk["vy"] - ri["vy"], ri["radius"] + rk["radius"]


@njit(refcount=False, forceinline=True)
def pair_time(i, k, rec):
    """Step time at which balls ``i`` and ``k`` in straight-line motion meet (inf: never), computed
    from their records at the later of their reference times."""
    tc, dx, dy, dvx, dvy, sigma = pair_gap(i, k, rec)
    return tc + toi_pair(dx, dy, dvx, dvy, sigma)


@njit(refcount=False, forceinline=True)
def wall_time(i, bounds, dim, rec):
    """Step time and code of the first wall ball ``i`` meets in straight-line motion."""
    r = rec[i]
    tau, wall = toi_wall(r["x"], r["y"], r["vx"], r["vy"], r["radius"], bounds, dim)
    return r["ref_time"] + tau, wall
