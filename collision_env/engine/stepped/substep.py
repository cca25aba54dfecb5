"""The fixed-step driver shared by naive and posteriori modes: k equal sub-steps per step."""

from __future__ import annotations

from .._jit import HAVE_NUMBA, njit
from ..clock import finish_step
from ..exact.grid import CHEAP_CELLS_PER_BALL, block, cell_of, scene_geometry
from ..exact.scheduler import RESUME, scene_params
from ..layout import (
    W_ACTIVE,
    W_STALLED,
    W_SUBSTEP_START,
    W_SUBSTEPS_DONE,
)
from ..physics.motion import advance_all, ball_views, has_rotation
from ..physics.response import elastic_threshold
from .naive import resolve_naive
from .posteriori import resolve_posteriori

if HAVE_NUMBA:
    import numpy as np

    from ..argpack import view1
    from ..exact.scheduler import unpack_state

NAIVE, POSTERIORI = 0, 1


def worst_case_impacts(n):
    """Most impacts one sub-step can record for one scene without a grid (every pair, border,
    containment); with a grid the bound is counted from the cells (:func:`_grid_worst_case`)."""
    return n * (n - 1) // 2 + 4 * n


def scratch_size(n):
    """Length of :func:`step_substeps`'s int work buffer for ``n`` balls (the sub-step's grid: at
    most ``grid.CHEAP_CELLS_PER_BALL`` cells per ball)."""
    return (2 + 2 * CHEAP_CELLS_PER_BALL) * n


@njit(inline="always")
def _cell_lists(n, p, v, h, scratch, geo):
    """Sort the balls into the grid's cells where they will be after the sub-step's move (before
    it is made, so that a scene can still stall untouched), and return the lists as
    ``(head, nxt, cell, near, nx, ny)`` for the resolvers."""
    x0, y0, hx, hy, nx, ny = geo
    m = CHEAP_CELLS_PER_BALL * n  # (``near`` holds a count per cell, or a ball's neighbours)
    head = scratch[0:m]
    nxt = scratch[m : m + n]
    cell = scratch[m + n : m + 2 * n]
    near = scratch[m + 2 * n : 2 * m + 2 * n]
    if nx * ny > 1:
        for c in range(nx * ny):
            head[c] = -1
        for i in range(n - 1, -1, -1):
            c = cell_of(p[i, 0] + v[i, 0] * h, p[i, 1] + v[i, 1] * h, x0, y0, hx, hy, nx, ny)
            cell[i] = c
            nxt[i] = head[c]
            head[c] = i
    return head, nxt, cell, near, nx, ny


@njit(inline="always")
def _grid_worst_case(n, cells, room):
    """Most impacts a sub-step can record on the grid: a pair per neighbour, and border and
    containment impacts; counted cell by cell only when a cruder bound (every ball's 3 x 3 block
    as full as the fullest cell) exceeds the ``room`` left in the buffer."""
    head, nxt, cell, near, nx, ny = cells
    if nx * ny == 1:
        return n * (n - 1) // 2 + 4 * n
    for c in range(nx * ny):
        near[c] = 0
    fullest = 0
    for i in range(n):
        near[cell[i]] += 1
        fullest = max(fullest, near[cell[i]])
    if 4 * n + 9 * n * fullest <= room:
        return 4 * n + 9 * n * fullest
    worst = 4 * n
    for i in range(n):
        cx0, cx1, cy0, cy1 = block(cell[i], nx, ny)
        for cy in range(cy0, cy1 + 1):
            for cx in range(cx0, cx1 + 1):
                worst += near[cy * nx + cx]
    return worst


@njit(refcount=False)
def step_substeps(
    mode,
    k_total,
    balls,
    body,
    time,
    capped,
    fparams,
    iparams,
    imp,
    n_imp,
    counters,
    work_f,
    work_i,
    clock,
    scratch,
    dt_abs,
    start,
):
    """Run the remaining sub-steps of every active scene.

    Parameters as :func:`exact.step_exact` (a ``start`` other than ``RESUME`` starts a step for
    every scene; ``capped`` is not used: the cheap modes have no event cap; ``scratch`` is an int
    buffer of :func:`scratch_size`); a scene stops between sub-steps when the impact buffer could not
    hold another sub-step's worst case, and is flagged stalled. Returns as
    :func:`exact.step_exact` does: the impact rows written, or -1 when a scene stalled.
    """
    pos, vel, mass, inv_mass, radius, omega = ball_views(balls)
    t_start = work_f[:, W_SUBSTEP_START]
    active = work_i[:, W_ACTIVE]
    stalled = work_i[:, W_STALLED]
    done = work_i[:, W_SUBSTEPS_DONE]
    n_imp[0] = 0
    n = pos.shape[1]
    bounds, e, ratio, floor, sign, has_walls, pairs, dim, sticky, _ = scene_params(fparams, iparams)
    h = dt_abs / k_total
    if start != RESUME:
        for sc in range(pos.shape[0]):
            active[sc] = True
            t_start[sc] = time[sc]
            done[sc] = 0
        n_imp[1] = 0
    n_imp[2] = 0
    for sc in range(pos.shape[0]):
        if not active[sc]:
            continue
        stalled[sc] = False
        p = pos[sc]
        v = vel[sc]
        m = mass[sc]
        b = body[sc]
        w = omega[sc]
        geo = scene_geometry(work_f, work_i, sc)
        u_min = elastic_threshold(v, ratio, floor)
        while done[sc] < k_total:
            cells = _cell_lists(n, p, v, h, scratch, geo)
            room = imp.shape[0] - n_imp[0]
            if room < _grid_worst_case(n, cells, room):
                stalled[sc] = True
                break
            k = done[sc] + 1
            t_end = t_start[sc] + sign * (dt_abs if k == k_total else h * k)
            advance_all(h, p, v, m, b, w, sticky and has_rotation(b, w))
            if mode == NAIVE:
                resolve_naive(
                    sc,
                    t_end,
                    p,
                    v,
                    m,
                    inv_mass[sc],
                    radius[sc],
                    b,
                    w,
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
                )
            else:
                resolve_posteriori(
                    sc,
                    t_end,
                    sign,
                    h,
                    p,
                    v,
                    m,
                    inv_mass[sc],
                    radius[sc],
                    b,
                    w,
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
                )
            done[sc] = k
            time[sc] = t_end
        n_imp[2] += stalled[sc]
        active[sc] = stalled[sc]
        if not stalled[sc]:
            finish_step(sc, True, sign * dt_abs, time, clock)
    return n_imp[0] if n_imp[2] == 0 else -1


if HAVE_NUMBA:

    @njit
    def step_substeps_packed(mode, k_total, h, dt_abs, start):
        """:func:`step_substeps` on the arrays packed in ``h`` (:mod:`~collision_env.engine.argpack`),
        one slot per array in the order of its parameters."""
        return step_substeps(mode, k_total, *unpack_state(h), view1(h, 12, np.int64), dt_abs, start)
