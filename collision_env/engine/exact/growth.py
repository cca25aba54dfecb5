"""The event loop of a compression: hard disks whose radii grow in proportion (Lubachevsky &
Stillinger, *J. Stat. Phys.* 60, 561 (1990); the physics is in
:mod:`~collision_env.engine.physics.growth`), in a box or a periodic cell, on the exact engine's own
event calendar and cell grid.

- **The disks** are the calendar's records (``layout.CAL_RECORD``, one cache line each): a disk's
  centre at its own ``ref_time`` and its velocity, moved lazily (:mod:`.trajectories`). Its
  ``radius`` field is its radius at time 0: every radius grows as ``r_i(t) = r_i(0) (1 + gamma t)``
  (:class:`Growth`), so a pair's contact distance is ``sigma_ij(0) (1 + gamma t)``.
- **The calendar** (:mod:`.calendar`) keeps each disk's earliest event (a collision with a disk of
  its 3 x 3 block of cells, a wall in a box, or leaving its cell), ordered in the engine's event
  queue (an 8-ary heap, with time buckets from 4,096 disks). A pair's prediction lives in the
  slot of the disk that found it; an event whose partner's trajectory changed since is stale
  (the records' change counters), and its disk is predicted afresh.
- **The grid** is the engine's (:mod:`.grid`; :mod:`.periodic` for a cell's wrapping crossings),
  with cells at least one largest diameter wide until the clock reaches the time the caller made
  it for; the caller then makes one of wider cells and predicts every disk again.

:func:`run` processes events until a number of collisions, or until the clock would pass a time;
the caller (:mod:`~collision_env.engine.compression`) then brings every disk to that time
(:func:`synchronise`), rescales the velocities, and :func:`reschedule` predicts every disk again.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..layout import C_CELL, C_EVENT_OTHER, CAL_I, CAL_RECORD, HEAP, WORK_F, WORK_I
from ..physics.growth import bounce_growing_wall, growing_pair_impulse, toi_growing_pair, toi_growing_wall
from ..physics.periodic import nearest
from ..physics.toi import INF
from . import calendar as cal
from . import grid, periodic
from .bundles import SceneCalendar
from .trajectories import pair_gap, sync

#: The run's tallies (``tally``, float64), by name.
TALLY_CLOCK = 0  #: the time of the last event
TALLY_PAIR_VIRIAL = 1  #: sum over collisions of sigma_ij J_ij (J m)
TALLY_WALL_VIRIAL = 2  #: sum over wall impacts of r_i J_i (J m)
TALLY_COLLISIONS = 3  #: collisions of disk pairs and with walls
TALLY_CROSSINGS = 4  #: disks that left their cell
TALLY_SIZE = 5

#: Why :func:`run` returned.
RAN_COLLISIONS = 0  #: it processed the collisions it was asked for
RAN_UNTIL = 1  #: the next event is at or after ``until``
RAN_IDLE = 2  #: it processed ``idle`` events (crossings, stale predictions) without a collision


class Growth(NamedTuple):
    """A compression's constants: how the radii grow, and the box or periodic cell."""

    gamma: float  #: ``r_i(t) = r_i(0) (1 + gamma t)`` (1/s)
    periodic: bool
    bounds: tuple  #: ``(x0, y0, x1, y1)``


def make_calendar(n: int, cells: int, inv_mass: np.ndarray) -> SceneCalendar:
    """A calendar for ``n`` disks on a grid of ``cells`` cells (filled by :func:`reschedule`)."""
    queue = cal.EventQueue(
        np.zeros((cal.heap_rows(n), len(HEAP))),
        np.full(cal.bucket_count(n) + 1, -1, dtype=np.int32),
        np.zeros(len(WORK_F)),
        np.zeros(len(WORK_I), dtype=np.int64),
    )
    return SceneCalendar(
        np.zeros(n, dtype=CAL_RECORD),
        np.zeros((n, len(CAL_I)), dtype=np.int32),
        np.full(cells, -1, dtype=np.int32),
        queue,
        inv_mass,
        np.full(n, -np.inf),
    )


# --- predictions ----------------------------------------------------------------------------------


@njit(inline="always")
def _around(c, ox, oy, geo, g):
    """The cell ``(ox, oy)`` cells away from cell ``c`` and the shift ``(sx, sy)`` that brings a disk
    there next to cell ``c``: wrapped in a periodic cell (where a grid of one cell along an axis is
    its own neighbour on either side, through an image), -1 beyond a box's grid."""
    gx = c % geo.nx + ox
    gy = c // geo.nx + oy
    sx = 0.0
    sy = 0.0
    if g.periodic:
        if gx < 0:
            gx += geo.nx
            sx = g.bounds[0] - g.bounds[2]
        elif gx >= geo.nx:
            gx -= geo.nx
            sx = g.bounds[2] - g.bounds[0]
        if gy < 0:
            gy += geo.ny
            sy = g.bounds[1] - g.bounds[3]
        elif gy >= geo.ny:
            gy -= geo.ny
            sy = g.bounds[3] - g.bounds[1]
    elif gx < 0 or gx >= geo.nx or gy < 0 or gy >= geo.ny:
        return -1, sx, sy
    return gy * geo.nx + gx, sx, sy


@njit(inline="always")
def _not_before(dx, dy, dvx, dvy, sigma, sigma_dot, span):
    """Two growing disks (as :func:`~collision_env.engine.physics.growth.toi_growing_pair` takes them)
    cannot touch within ``span``: where the quadratic's ``t^2`` term is not negative, the time of
    impact is at least ``c / (-2 b)`` (``physics.toi.not_before``, for growing disks). A cheap test
    that spares most pairs the square root and the division."""
    a = dvx * dvx + dvy * dvy - sigma_dot * sigma_dot
    b = dx * dvx + dy * dvy - sigma * sigma_dot
    c = dx * dx + dy * dy - sigma * sigma
    return a >= 0.0 and (b >= 0.0 or c * (1.0 - 1e-9) > -2.0 * b * span)


@njit(refcount=False, forceinline=True)
def predict(i, t, rebuild, cl, geo, g):
    """Bring disk ``i`` to time ``t`` and set its earliest event: leaving its cell, a wall (in a box),
    or a disk of the cells around it (``rebuild``: only disks of higher index, when every disk is
    predicted at once, so that each pair is looked at once); the caller queues it."""
    rec = cl.rec
    sync(i, t, rec)
    r = rec[i]
    c = cl.ci[i, C_CELL]
    if g.periodic:
        tau, direction = periodic.crossing(r["x"], r["y"], r["vx"], r["vy"], c, geo)
    else:
        tau, direction = grid.crossing(r["x"], r["y"], r["vx"], r["vy"], c, geo)
    best_t = INF
    best_code = cal.EV_NONE
    if direction >= 0:
        best_t = t + tau
        best_code = cal.EV_CROSS - direction
    grow = 1.0 + g.gamma * t
    if not g.periodic:
        for axis in range(2):
            x = r["x"] if axis == 0 else r["y"]
            v = r["vx"] if axis == 0 else r["vy"]
            tw, side = toi_growing_wall(
                x, v, r["radius"] * grow, r["radius"] * g.gamma, g.bounds[axis], g.bounds[axis + 2]
            )
            code = cal.EV_WALL - (2 * axis + side)
            if side >= 0 and cal.earlier(t + tw, code, best_t, best_code, i):
                best_t = t + tw
                best_code = code
    best_stamp = 0
    for oy in range(-1, 2):
        for ox in range(-1, 2):
            cell, sx, sy = _around(c, ox, oy, geo, g)
            k = cl.heads[cell] if cell >= 0 else -1
            while k >= 0:
                if k != i and (k > i or not rebuild):
                    tc, dx, dy, dvx, dvy, sigma0 = pair_gap(i, k, rec)
                    dx += sx
                    dy += sy
                    sigma = sigma0 * (1.0 + g.gamma * tc)
                    sigma_dot = sigma0 * g.gamma
                    if not _not_before(dx, dy, dvx, dvy, sigma, sigma_dot, best_t - tc):
                        tp = tc + toi_growing_pair(dx, dy, dvx, dvy, sigma, sigma_dot)
                        if tp < INF and cal.earlier(tp, k, best_t, best_code, i):
                            best_t = tp
                            best_code = k
                            best_stamp = rec[k]["changes"]
                k = rec[k]["cell_next"]
    cal.set_event(i, best_t, best_code, best_stamp, rec, cl.ci)


@njit(refcount=False, forceinline=True)
def _schedule(i, t, cl, geo, g):
    """:func:`predict` disk ``i`` at ``t`` and queue its new event."""
    predict(i, t, False, cl, geo, g)
    cal.schedule(i, cl.rec, cl.ci, cl.q)


# --- the events -----------------------------------------------------------------------------------


@njit(refcount=False, forceinline=True)
def _collide(i, j, t, cl, geo, g, tally):
    """Disks ``i`` and ``j`` touch at ``t``: bounce them apart, add their virial, predict both."""
    rec = cl.rec
    sync(i, t, rec)
    sync(j, t, rec)
    ri = rec[i]
    rj = rec[j]
    dx = rj["x"] - ri["x"]
    dy = rj["y"] - ri["y"]
    if g.periodic:  # (the images in contact are the nearest ones: a diameter is under half the cell)
        dx = nearest(dx, g.bounds[2] - g.bounds[0])
        dy = nearest(dy, g.bounds[3] - g.bounds[1])
    dist = math.sqrt(dx * dx + dy * dy)
    nx = dx / dist
    ny = dy / dist
    sigma0 = ri["radius"] + rj["radius"]
    u = (rj["vx"] - ri["vx"]) * nx + (rj["vy"] - ri["vy"]) * ny
    wi = cl.inv_mass[i]
    wj = cl.inv_mass[j]
    impulse = growing_pair_impulse(u, sigma0 * g.gamma, wi, wj)
    ri["vx"] -= impulse * wi * nx
    ri["vy"] -= impulse * wi * ny
    rj["vx"] += impulse * wj * nx
    rj["vy"] += impulse * wj * ny
    ri["changes"] += 1
    rj["changes"] += 1
    tally[TALLY_PAIR_VIRIAL] += impulse * sigma0 * (1.0 + g.gamma * t)
    tally[TALLY_COLLISIONS] += 1.0
    _schedule(i, t, cl, geo, g)
    _schedule(j, t, cl, geo, g)


@njit(refcount=False, forceinline=True)
def _hit_wall(i, wall, t, cl, geo, g, tally):
    """Disk ``i`` touches ``wall`` (2 * axis + side) at ``t``: bounce it, add its virial, predict it."""
    rec = cl.rec
    sync(i, t, rec)
    r = rec[i]
    v = r["vx"] if wall >> 1 == 0 else r["vy"]
    v_new = bounce_growing_wall(v, r["radius"] * g.gamma, wall & 1)
    if wall >> 1 == 0:
        r["vx"] = v_new
    else:
        r["vy"] = v_new
    r["changes"] += 1
    tally[TALLY_WALL_VIRIAL] += abs(v_new - v) / cl.inv_mass[i] * r["radius"] * (1.0 + g.gamma * t)
    tally[TALLY_COLLISIONS] += 1.0
    _schedule(i, t, cl, geo, g)


@njit(refcount=False, forceinline=True)
def _cross(i, direction, t, cl, geo, g, images, tally):
    """Disk ``i`` leaves its cell at ``t`` towards ``direction``: move it to the next cell (through the
    periodic boundary, its record shifting by a period), then predict it."""
    if g.periodic:
        periodic.cross(i, direction, cl, geo, images, g.bounds, 2)
    else:
        grid.unlink(i, cl.rec, cl.ci, cl.heads)
        grid.link(i, grid.neighbour_cell(cl.ci[i, C_CELL], direction, geo.nx), cl.rec, cl.ci, cl.heads)
    tally[TALLY_CROSSINGS] += 1.0
    _schedule(i, t, cl, geo, g)


@njit(refcount=False, label="the compression (growing disks)")
def run(cl, geo, g, images, tally, collisions, until, idle):
    """Process events in time order until ``collisions`` more collisions (pairs and walls) are done,
    the next event is at or after ``until``, or ``idle`` events in a row were no collision (disks
    that no longer meet, without growth). Returns ``RAN_COLLISIONS``, ``RAN_UNTIL`` or ``RAN_IDLE``."""
    goal = tally[TALLY_COLLISIONS] + collisions
    quiet = 0
    while tally[TALLY_COLLISIONS] < goal:
        i = cal.next_ball(cl.rec, cl.ci, cl.q)
        if i < 0:  # (nothing will ever happen)
            return RAN_IDLE
        t = cl.rec[i]["event_time"]
        if not t < until:
            return RAN_UNTIL
        if quiet >= idle:
            return RAN_IDLE
        tally[TALLY_CLOCK] = t
        code = cl.ci[i, C_EVENT_OTHER]
        quiet += 1
        if code >= 0:
            if cal.is_stale(i, cl.rec, cl.ci):  # (the partner collided since: predict again)
                _schedule(i, t, cl, geo, g)
            else:
                _collide(i, code, t, cl, geo, g, tally)
                quiet = 0
        elif cal.is_crossing(code):
            _cross(i, cal.EV_CROSS - code, t, cl, geo, g, images, tally)
        else:
            _hit_wall(i, cal.EV_WALL - code, t, cl, geo, g, tally)
            quiet = 0
    return RAN_COLLISIONS


# --- starting and restarting ------------------------------------------------------------------------


@njit(refcount=False)
def synchronise(cl, t):
    """Bring every disk's record to time ``t``."""
    for i in range(cl.rec.shape[0]):
        sync(i, t, cl.rec)


@njit(refcount=False)
def reschedule(cl, geo, g, t):
    """Every disk, at time ``t`` (:func:`synchronise`), into ``geo``'s grid, and its next event
    predicted and queued anew (after its velocity, or the grid, changed)."""
    n = cl.rec.shape[0]
    grid.fill_cells(n, cl.rec, cl.ci, cl.heads, geo)
    for i in range(n):
        predict(i, t, True, cl, geo, g)
    cal.build_queue(n, t, cl.rec, cl.ci, cl.q)
