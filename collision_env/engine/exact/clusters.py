"""Stick scenes (``inelastic="stick"`` at e = 0): what exact mode does differently for rigid clusters.

Colliding balls merge into one rigid cluster spinning about its centre of mass, and a cluster that
touches a wall stops dead and comes apart (``response.merge_bodies``, ``response.stop_body``;
PhET's Inelastic screen). A rotating cluster's members move on circles, so every ball is kept at
the same time (:func:`sync_all`), the times of impact of a rotating ball come from conservative
advancement and bisection (``toi.ca_pair``, ``toi.ca_wall``; :func:`next_event`), and a predicted
contact is re-checked by the contact test when it is resolved (:func:`resolve_wall`,
:func:`resolve_pair`). Stick scenes have no grid (one cell).

Only stick scenes compile this module's kernels (see the scheduler's kinds of scene).
"""

from __future__ import annotations

import math

from .._jit import njit
from ..layout import CLUSTER_TESTS, KINEMATICS, PAIR_TESTS, WALL_TESTS
from ..physics.impacts import record
from ..physics.motion import advance_all, body_kinematics
from ..physics.response import body_inverse_mass, merge_bodies, stop_body
from ..physics.toi import INF, ca_pair, ca_wall, toi_pair, toi_wall
from ..physics.tolerance import balls_touch
from ..physics.walls import heads_into, snap_to_wall, wall_axis, wall_contact, wall_point
from . import calendar as cal
from .trajectories import load


@njit(inline="always")
def _copy_kinematics(i, b, out):
    """Ball ``i``'s rigid kinematics (``motion.body_kinematics``) into ``out`` (``layout.KINEMATICS``)."""
    k = body_kinematics(i, b.pos, b.vel, b.mass, b.body, b.omega)
    for q in range(len(KINEMATICS)):
        out[q] = k[q]


@njit(inline="always")
def _pair_time(i, k, now, horizon, b, wk):
    """When balls ``i`` and ``k`` (of different clusters) touch, from the ball state at ``now``."""
    pos, vel, body, omega = b.pos, b.vel, b.body, b.omega
    if omega[body[i]] != 0.0 or omega[body[k]] != 0.0:
        wk.counters[CLUSTER_TESTS] += 1
        _copy_kinematics(i, b, wk.ki)
        _copy_kinematics(k, b, wk.kj)
        return now + ca_pair(wk.ki, wk.kj, b.radius[i] + b.radius[k], horizon)
    wk.counters[PAIR_TESTS] += 1
    return now + toi_pair(
        pos[k, 0] - pos[i, 0],
        pos[k, 1] - pos[i, 1],
        vel[k, 0] - vel[i, 0],
        vel[k, 1] - vel[i, 1],
        b.radius[i] + b.radius[k],
    )


@njit(inline="always")
def _wall_time(i, now, horizon, b, ph, wk):
    """When ball ``i`` first touches a wall, from the ball state at ``now``: ``(time, wall)``."""
    if b.omega[b.body[i]] != 0.0:
        wk.counters[CLUSTER_TESTS] += 1
        _copy_kinematics(i, b, wk.ki)
        tau, wall = ca_wall(wk.ki, b.radius[i], ph.bounds, ph.dim, horizon)
        return now + tau, wall
    wk.counters[WALL_TESTS] += 1
    tau, wall = toi_wall(b.pos[i, 0], b.pos[i, 1], b.vel[i, 0], b.vel[i, 1], b.radius[i], ph.bounds, ph.dim)
    return now + tau, wall


@njit(refcount=False, forceinline=True)
def next_event(i, now, horizon, rebuild, b, cl, ph, wk):
    """Ball ``i``'s next event in a scene with a rotating cluster, from the ball state (which stick
    scenes keep at ``now``): ``(time, code, partner's change count)``, as the scheduler's
    ``next_event`` finds it for straight-line motion (``rebuild``: partners of higher index only).
    ``horizon`` bounds the conservative advancement (the rest of the step)."""
    best_t, best_code = INF, cal.EV_NONE
    if ph.has_walls:
        t, wall = _wall_time(i, now, horizon, b, ph, wk)
        if wall >= 0:
            best_t, best_code = t, cal.EV_WALL - wall
    best_stamp = 0
    if ph.pairs:
        for k in range(i + 1 if rebuild else 0, b.pos.shape[0]):
            if k == i or b.body[i] == b.body[k]:
                continue
            t = _pair_time(i, k, now, horizon, b, wk)
            if t < INF and cal.earlier(t, k, best_t, best_code, i):
                best_t = t
                best_code = k
                best_stamp = cl.rec[k]["changes"]
    return best_t, best_code, best_stamp


@njit(refcount=False, forceinline=True)
def sync_all(t, b, rot, rec):
    """Bring every ball to step time ``t`` (rigid rotation for spinning clusters), in the ball state
    and in the records alike."""
    dt = t - rec[0]["ref_time"]
    if dt != 0.0:
        advance_all(dt, b.pos, b.vel, b.mass, b.body, b.omega, rot)
        for k in range(b.pos.shape[0]):
            load(k, t, rec, b.pos, b.vel, k)


@njit(inline="always")
def _list_cluster(root, body, involved):
    """The balls of the cluster rooted at ``root``, into ``involved``; returns how many."""
    n_inv = 0
    for k in range(body.shape[0]):
        if body[k] == root:
            involved[n_inv] = k
            n_inv += 1
    return n_inv


@njit(refcount=False, forceinline=True)
def resolve_wall(sc, t_abs, bi, wall, b, ph, wk):
    """Ball ``bi`` meets ``wall`` (the whole ball state ``b``): if it touches it and moves into it,
    its cluster stops dead and comes apart. Returns how many balls' motion it changed (listed in
    ``wk.pending``)."""
    pos, vel, radius = b.pos, b.vel, b.radius
    axis = wall_axis(wall)
    if not (wall_contact(bi, wall, pos, radius, ph.bounds) and heads_into(wall, vel[bi, axis])):
        wk.pending[0] = bi
        return 1
    if b.omega[b.body[bi]] == 0.0:
        snap_to_wall(bi, wall, pos, radius, ph.bounds)
    x, y = wall_point(bi, wall, pos, ph.bounds)
    speed = abs(vel[bi, axis])
    record(wk.imp, wk.n_imp, sc, t_abs, bi, -1, wall, x, y, speed, speed / body_inverse_mass(bi, b.mass, b.body, True))
    n_inv = _list_cluster(b.body[bi], b.body, wk.pending)
    stop_body(bi, vel, b.body, b.omega)
    return n_inv


@njit(refcount=False, forceinline=True)
def resolve_pair(sc, t_abs, bi, bj, b, wk):
    """Balls ``bi`` and ``bj`` meet (the whole ball state ``b``): if they touch and close, their
    clusters stick into one. Returns how many balls' motion it changed (listed in ``wk.pending``)."""
    pos, vel, radius = b.pos, b.vel, b.radius
    dx = pos[bj, 0] - pos[bi, 0]
    dy = pos[bj, 1] - pos[bi, 1]
    dist = math.sqrt(dx * dx + dy * dy)
    closing = (vel[bj, 0] - vel[bi, 0]) * dx + (vel[bj, 1] - vel[bi, 1]) * dy
    if not (balls_touch(bi, bj, pos, radius) and closing < 0.0):
        wk.pending[0] = bi
        wk.pending[1] = bj
        return 2
    x = pos[bi, 0] + radius[bi] * dx / dist
    y = pos[bi, 1] + radius[bi] * dy / dist
    w = body_inverse_mass(bi, b.mass, b.body, True) + body_inverse_mass(bj, b.mass, b.body, True)
    record(wk.imp, wk.n_imp, sc, t_abs, bi, bj, -1, x, y, -closing / dist, -closing / dist / w)
    root = merge_bodies(bi, bj, pos, vel, b.mass, b.body, b.omega)
    return _list_cluster(root, b.body, wk.pending)
