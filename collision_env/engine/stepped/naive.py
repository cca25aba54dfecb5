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
from ..exact.grid import later_neighbours
from ..exact.scheduler import EVENTS, PAIR_TESTS, WALL_TESTS, record, wall_point
from ..physics.response import ball_ball, ball_wall, merge_bodies, stop_body


@njit(inline="always")
def body_inverse_mass(i, mass, body, sticky):
    """1 / the mass of ball ``i``'s cluster (of the ball alone unless the scene is a stick one)."""
    if not sticky:
        return 1.0 / mass[i]
    root = body[i]
    m_tot = 0.0
    for k in range(mass.shape[0]):
        if body[k] == root:
            m_tot += mass[k]
    return 1.0 / m_tot


@njit(inline="always")
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
def contain(sc, t_abs, pos, vel, radius, body, omega, bounds, dim, e, u_min, sticky, imp, n_imp, counters):
    """Put every ball that ended up past a wall back on it; reflect it if it still moves outward."""
    n = pos.shape[0]
    n_axes = 2 if dim == 2 else 1
    for i in range(n):
        counters[WALL_TESTS] += 1
        for axis in range(n_axes):
            lo = bounds[axis] + radius[i]
            hi = bounds[axis + 2] - radius[i]
            x = pos[i, axis]
            if x < lo:
                wall = 2 * axis
                push = lo - x
            elif x > hi:
                wall = 2 * axis + 1
                push = hi - x
            else:
                continue
            if axis == 0:
                shift_body(i, push, 0.0, pos, body, sticky)
            else:
                shift_body(i, 0.0, push, pos, body, sticky)
            v = vel[i, axis]
            if (v < 0.0) if wall % 2 == 0 else (v > 0.0):
                if sticky:
                    stop_body(i, vel, body, omega)
                    speed = abs(v)
                else:
                    speed = ball_wall(i, wall, vel, e, u_min)
                cx, cy = wall_point(i, wall, pos, radius, bounds)
                record(imp, n_imp, sc, t_abs, i, -1, wall, cx, cy, speed)
                counters[EVENTS] += 1


@njit(inline="always")
def resolve_naive(
    sc,
    t_abs,
    pos,
    vel,
    mass,
    inv_mass,
    radius,
    body,
    omega,
    bounds,
    dim,
    e,
    u_min,
    has_walls,
    pairs,
    sticky,
    imp,
    n_imp,
    counters,
    cells,
):
    """Resolve the overlaps at the end of a sub-step; ``cells`` is the sub-step's broad phase
    (``substep.cell_lists``): pairs come from it in index order."""
    n = pos.shape[0]
    head, nxt, cell, near, cells_x, cells_y = cells
    if pairs:
        for i in range(n):
            for q in range(later_neighbours(i, n, head, nxt, cell, cells_x, cells_y, near)):
                j = near[q]
                if body[i] == body[j]:
                    continue
                counters[PAIR_TESTS] += 1
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                sigma = radius[i] + radius[j]
                if dx * dx + dy * dy > sigma * sigma * (1.0 + 1e-12):  # (spares the root of far pairs)
                    continue
                dist = math.sqrt(dx * dx + dy * dy)
                if dist >= sigma:
                    continue
                if dist > 0.0:
                    nx = dx / dist
                    ny = dy / dist
                else:
                    nx = 1.0
                    ny = 0.0
                closing = (vel[j, 0] - vel[i, 0]) * nx + (vel[j, 1] - vel[i, 1]) * ny
                wi = body_inverse_mass(i, mass, body, sticky)
                wj = body_inverse_mass(j, mass, body, sticky)
                overlap = sigma - dist
                shift_body(i, -overlap * wi / (wi + wj) * nx, -overlap * wi / (wi + wj) * ny, pos, body, sticky)
                shift_body(j, overlap * wj / (wi + wj) * nx, overlap * wj / (wi + wj) * ny, pos, body, sticky)
                if closing < 0.0:
                    x = pos[i, 0] + radius[i] * nx
                    y = pos[i, 1] + radius[i] * ny
                    if sticky:
                        merge_bodies(i, j, pos, vel, mass, body, omega)
                        speed = -closing
                    else:
                        speed = ball_ball(i, j, pos, vel, inv_mass, e, u_min)
                    record(imp, n_imp, sc, t_abs, i, j, -1, x, y, speed)
                    counters[EVENTS] += 1
    if has_walls:
        contain(sc, t_abs, pos, vel, radius, body, omega, bounds, dim, e, u_min, sticky, imp, n_imp, counters)
