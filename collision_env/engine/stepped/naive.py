"""Naive mode: move every ball by the (sub)step, then resolve the overlaps found at its end.

No time of impact at all: impacts are reported at the end of the sub-step, at the contact point
of the overlapped configuration (both wrong by up to ``|v| dt``), a collision that a step jumps
over entirely is missed (tunnelling), and only the last position is checked. It is the cheapest
mode and the floor of the speed/accuracy trade.

Resolution, in a fixed order:

1. pairs in index order: an overlapping, approaching pair gets the impulse (or sticks); every
   overlapping pair is pushed apart along its line of centres, in inverse proportion to mass;
2. walls (:func:`contain`): a ball past a wall is put back on it, and reflected if it is still
   moving into it. This runs last, so no ball ever ends a step outside a reflecting border.
"""

from __future__ import annotations

import math

from .._jit import njit
from ..layout import EVENTS, PAIR_TESTS, WALL_TESTS
from ..physics.impacts import record
from ..physics.response import ball_ball, ball_wall, body_inverse_mass, merge_bodies, normal_impulse, stop_body
from ..physics.walls import heads_into, wall_of, wall_point
from .cells import later_neighbours


@njit(refcount=False, forceinline=True)
def shift_body(i, dx, dy, pos, body, sticky):
    """Move ball ``i``'s cluster (the ball alone unless the scene is a stick one) by (dx, dy)."""
    if not sticky:
        pos[i, 0] += dx
        pos[i, 1] += dy
        return
    root = body[i]
    for k in range(pos.shape[0]):
        if body[k] == root:
            pos[k, 0] += dx
            pos[k, 1] += dy


@njit(inline="always")
def contain(sc, t_abs, u_min, b, ph, state):
    """Put every ball that ended up past a wall back on it; reflect it if it still moves outward."""
    pos, vel, radius, bounds = b.pos, b.vel, b.radius, ph.bounds
    n_axes = 2 if ph.dim == 2 else 1
    for i in range(pos.shape[0]):
        state.counters[WALL_TESTS] += 1
        for axis in range(n_axes):
            lo = bounds[axis] + radius[i]
            hi = bounds[axis + 2] - radius[i]
            x = pos[i, axis]
            if x < lo:
                wall = wall_of(axis, False)
                push = lo - x
            elif x > hi:
                wall = wall_of(axis, True)
                push = hi - x
            else:
                continue
            if axis == 0:
                shift_body(i, push, 0.0, pos, b.body, ph.sticky)
            else:
                shift_body(i, 0.0, push, pos, b.body, ph.sticky)
            v = vel[i, axis]
            if heads_into(wall, v):
                w = body_inverse_mass(i, b.mass, b.body, ph.sticky)
                if ph.sticky:
                    stop_body(i, vel, b.body, b.omega)
                    speed = abs(v)
                    impulse = speed / w
                else:
                    speed = ball_wall(i, wall, vel, ph.e, u_min)
                    impulse = normal_impulse(speed, ph.e, u_min, w)
                cx, cy = wall_point(i, wall, pos, bounds)
                record(state.imp, state.n_imp, sc, t_abs, i, -1, wall, cx, cy, speed, impulse)
                state.counters[EVENTS] += 1


@njit(inline="always")
def _resolve_pair(sc, t_abs, i, j, u_min, b, ph, state):
    """Resolve an overlap of balls ``i`` and ``j``, if they overlap."""
    pos, vel, radius, body, sticky = b.pos, b.vel, b.radius, b.body, ph.sticky
    state.counters[PAIR_TESTS] += 1
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    sigma = radius[i] + radius[j]
    if dx * dx + dy * dy > sigma * sigma * (1.0 + 1e-12):  # (spares the root of far pairs)
        return
    dist = math.sqrt(dx * dx + dy * dy)
    if dist >= sigma:
        return
    if dist > 0.0:
        nx = dx / dist
        ny = dy / dist
    else:
        nx = 1.0
        ny = 0.0
    closing = (vel[j, 0] - vel[i, 0]) * nx + (vel[j, 1] - vel[i, 1]) * ny
    wi = body_inverse_mass(i, b.mass, body, sticky)
    wj = body_inverse_mass(j, b.mass, body, sticky)
    overlap = sigma - dist
    shift_body(i, -overlap * wi / (wi + wj) * nx, -overlap * wi / (wi + wj) * ny, pos, body, sticky)
    shift_body(j, overlap * wj / (wi + wj) * nx, overlap * wj / (wi + wj) * ny, pos, body, sticky)
    if closing < 0.0:
        x = pos[i, 0] + radius[i] * nx
        y = pos[i, 1] + radius[i] * ny
        if sticky:
            merge_bodies(i, j, pos, vel, b.mass, body, b.omega)
            speed = -closing
            impulse = speed / (wi + wj)
        else:
            speed = ball_ball(i, j, pos, vel, b.inv_mass, ph.e, u_min)
            impulse = normal_impulse(speed, ph.e, u_min, wi + wj)
        record(state.imp, state.n_imp, sc, t_abs, i, j, -1, x, y, speed, impulse)
        state.counters[EVENTS] += 1


@njit(refcount=False, forceinline=True)
def resolve(sc, t_abs, h, u_min, b, ph, state, cells):
    """Resolve the overlaps at the end of a sub-step of ``h`` seconds ending at ``t_abs``; ``cells``
    is the sub-step's broad phase (``cells.cell_lists``): pairs come from it in index order."""
    n = b.pos.shape[0]
    if ph.pairs:
        for i in range(n):
            for q in range(later_neighbours(i, n, cells)):
                j = cells.near[q]
                if b.body[i] != b.body[j]:
                    _resolve_pair(sc, t_abs, i, j, u_min, b, ph, state)
    if ph.has_walls:
        contain(sc, t_abs, u_min, b, ph, state)
