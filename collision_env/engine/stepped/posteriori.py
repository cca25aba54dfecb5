"""Posteriori mode: the overlap-time reconstruction of PhET Collision Lab's first engine (B. Li, 2020).

Move every ball by the (sub)step; then, for each overlap found, reconstruct how long ago contact
happened, rewind to it, respond there, and re-advance by the same time with the new velocities.

- Ball-ball, pairs in index order: the root of ``|dv|^2 t^2 - 2 (dr.dv) t + (|dr|^2 - sigma^2) = 0``
  that lies in the past (``t >= 0``), taken in its cancellation-free form.
- Ball-border, as PhET's ``getBallToBorderCollisionOverlapTime``: ``ds = r - r_closest``, ``r_closest`` the
  centre clamped into the bounds eroded by the radius, and ``t = |ds|^2 / (v . ds)``;
  ``v . ds = 0`` gives ``t = 0`` instead of a division by zero. Every axis on which the ball is
  outside is reflected. This is exact for one wall; past a corner it returns a
  projection-weighted mix of the two crossing times (a known error, pinned by a test and measured
  by the benchmarks).

Reconstructed times are clamped into the sub-step, and a final :func:`~.naive.contain` pass puts
any ball still past a wall back on it, so no ball ends a step outside the border. What remains
wrong is the trade this mode makes: one collision per pair per step, pairs handled in index order
rather than time order, corners approximated, and tunnelling when a step jumps a whole contact.
"""

from __future__ import annotations

import math

from .._jit import njit
from ..layout import EVENTS, PAIR_TESTS, WALL_TESTS
from ..physics.impacts import record
from ..physics.motion import advance_body
from ..physics.response import ball_ball, ball_wall, body_inverse_mass, merge_bodies, normal_impulse, stop_body
from ..physics.walls import wall_of, wall_point
from .cells import later_neighbours
from .naive import contain, shift_body


@njit(refcount=False, forceinline=True)
def _move(i, dt, pos, vel, mass, body, omega, sticky):
    """Move ball ``i``'s body by ``dt`` (negative: rewind), leaving the other balls in place (the
    ball alone unless the scene is a stick one)."""
    if not sticky:
        pos[i, 0] += vel[i, 0] * dt
        pos[i, 1] += vel[i, 1] * dt
        return
    root = body[i]
    if omega[root] != 0.0:
        advance_body(root, dt, pos, vel, mass, body, omega)
    else:
        for k in range(pos.shape[0]):
            if body[k] == root:
                pos[k, 0] += vel[k, 0] * dt
                pos[k, 1] += vel[k, 1] * dt


@njit(inline="always")
def overlap_time_pair(dx, dy, dvx, dvy, sigma):
    """How long ago an overlapping pair touched: the non-negative root of PhET's quadratic."""
    a = dvx * dvx + dvy * dvy
    if a == 0.0:
        return 0.0
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    sq = math.sqrt(max(b * b - a * c, 0.0))
    if b >= 0.0:
        return (b + sq) / a
    return c / (b - sq)


@njit(inline="always")
def overlap_time_border(x, y, vx, vy, r, bounds, dim):
    """PhET's ``|ds|^2 / (v . ds)``, with the overshoot vector ``ds`` it uses."""
    cx = min(max(x, bounds[0] + r), bounds[2] - r)
    cy = min(max(y, bounds[1] + r), bounds[3] - r) if dim == 2 else y
    dsx = x - cx
    dsy = y - cy
    vds = vx * dsx + vy * dsy
    t = (dsx * dsx + dsy * dsy) / vds if vds != 0.0 else 0.0
    return t, dsx, dsy


@njit(inline="always")
def _resolve_pair(sc, t_end, h, i, j, u_min, b, ph, state):
    """Reconstruct and resolve the collision of balls ``i`` and ``j``, if they overlap."""
    pos, vel, mass, radius, body, omega, sticky = b.pos, b.vel, b.mass, b.radius, b.body, b.omega, ph.sticky
    state.counters[PAIR_TESTS] += 1
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    sigma = radius[i] + radius[j]
    if dx * dx + dy * dy >= sigma * sigma:
        return
    t = overlap_time_pair(dx, dy, vel[j, 0] - vel[i, 0], vel[j, 1] - vel[i, 1], sigma)
    t = min(max(t, 0.0), h)
    _move(i, -t, pos, vel, mass, body, omega, sticky)
    _move(j, -t, pos, vel, mass, body, omega, sticky)
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    dist = math.sqrt(dx * dx + dy * dy)
    closing = (vel[j, 0] - vel[i, 0]) * dx + (vel[j, 1] - vel[i, 1]) * dy
    if closing < 0.0 and dist > 0.0:
        x = pos[i, 0] + radius[i] * dx / dist
        y = pos[i, 1] + radius[i] * dy / dist
        w = body_inverse_mass(i, mass, body, sticky) + body_inverse_mass(j, mass, body, sticky)
        if sticky:
            merge_bodies(i, j, pos, vel, mass, body, omega)
            speed = -closing / dist
            impulse = speed / w
        else:
            speed = ball_ball(i, j, pos, vel, b.inv_mass, ph.e, u_min)
            impulse = normal_impulse(speed, ph.e, u_min, w)
        record(state.imp, state.n_imp, sc, t_end - ph.sign * t, i, j, -1, x, y, speed, impulse)
        state.counters[EVENTS] += 1
    _move(i, t, pos, vel, mass, body, omega, sticky)
    if body[j] != body[i]:
        _move(j, t, pos, vel, mass, body, omega, sticky)


@njit(inline="always")
def _resolve_border(sc, t_end, h, i, u_min, b, ph, state):
    """Reconstruct and resolve ball ``i``'s collision with the border, if it is past it."""
    pos, vel, body, sticky = b.pos, b.vel, b.body, ph.sticky
    state.counters[WALL_TESTS] += 1
    t, dsx, dsy = overlap_time_border(pos[i, 0], pos[i, 1], vel[i, 0], vel[i, 1], b.radius[i], ph.bounds, ph.dim)
    if dsx == 0.0 and dsy == 0.0:
        return
    t = min(max(t, 0.0), h)
    t_abs = t_end - ph.sign * t
    shift_body(i, -t * vel[i, 0], -t * vel[i, 1], pos, body, sticky)
    for axis in range(2):
        ds = dsx if axis == 0 else dsy
        if ds == 0.0:
            continue
        wall = wall_of(axis, ds > 0.0)
        v = vel[i, axis]
        w = body_inverse_mass(i, b.mass, body, sticky)
        if sticky:
            if v == 0.0:
                continue
            stop_body(i, vel, body, b.omega)
            speed = abs(v)
            impulse = speed / w
        else:
            speed = ball_wall(i, wall, vel, ph.e, u_min)
            impulse = normal_impulse(speed, ph.e, u_min, w)
        if speed > 0.0:
            x, y = wall_point(i, wall, pos, ph.bounds)
            record(state.imp, state.n_imp, sc, t_abs, i, -1, wall, x, y, speed, impulse)
            state.counters[EVENTS] += 1
    shift_body(i, t * vel[i, 0], t * vel[i, 1], pos, body, sticky)


@njit(refcount=False, forceinline=True)
def resolve(sc, t_end, h, u_min, b, ph, state, cells):
    """Reconstruct and resolve the collisions of a sub-step of ``h`` seconds ending at ``t_end``;
    ``cells`` is the sub-step's broad phase (``cells.cell_lists``): pairs come from it in index
    order."""
    n = b.pos.shape[0]
    if ph.pairs:
        for i in range(n):
            for q in range(later_neighbours(i, n, cells)):
                j = cells.near[q]
                if b.body[i] != b.body[j]:
                    _resolve_pair(sc, t_end, h, i, j, u_min, b, ph, state)
    if ph.has_walls:
        for i in range(n):
            _resolve_border(sc, t_end, h, i, u_min, b, ph, state)
        contain(sc, t_end, u_min, b, ph, state)
