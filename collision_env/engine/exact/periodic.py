"""Exact mode in a periodic cell: a wrapping grid, pair events through images, and wrapping by
cell crossings.

Only the kind of scene ``Kind(periodic=True)`` compiles this module (see the scheduler): it stands
in for the scheduler's wall and grid steps where a periodic scene differs.

- **The grid wraps.** Cells tile the periodic cell exactly (``broadphase.grid_geometry``); a ball
  leaving the last cell of a row enters the first. A scene too small for a grid has one cell, the
  periodic cell itself, and a ball leaving it enters it again through the opposite side. Either way
  a ball always has a crossing event along each axis it moves along: that is where it is wrapped.
- **Wrapping.** When a ball crosses the periodic boundary, its calendar record's position moves by
  one period and its image count (``State.images``) moves by one, so records, and so the ball state,
  stay inside the cell (up to round-off) however many times a ball goes round in one step.
- **Images.** A prediction looks at the 3 x 3 cells around a ball (3 in 1D), each with the shift
  that brings it next to the ball's own: a cell across the boundary is seen through the image on
  the ball's side. With one or two cells along an axis a cell appears more than once around a ball,
  once per image (one cell along x: its images one period to the left, none, and one to the right).
  Two balls can only touch when they are in neighbouring cells (cells are at least a diameter
  wide), and the ball that last crossed into a neighbourhood looked at every image it brought, so
  no contact is missed (Smallenburg 2022). An event's time is re-verified over the images of the
  two balls' records (:func:`pair_time`) and an event is resolved on the nearest image
  (:func:`nearest_partner`): at contact, with diameters below half a period, that is the touching
  one.

Pair events are the only collisions (there are no walls). At e < 1 an impact inside a touching
group resolves the whole group at one instant (:mod:`~.contacts`), its contacts found through the
minimum images as here (:func:`neighbour`), as in a box.
"""

from __future__ import annotations

from .._jit import njit
from ..layout import C_CELL, C_EVENT_OTHER, CELL_CROSSINGS, PAIR_TESTS, STALE_EVENTS
from ..physics.periodic import cell_lengths, nearest, toi_images, wrap_point
from ..physics.toi import INF, not_before, toi_pair
from . import calendar as cal
from . import grid
from .trajectories import pair_gap

#: What :func:`screen` makes of a popped event (as the scheduler's ``screen``).
RUN, PREDICT, RESCHEDULE = range(3)


@njit(forceinline=True)
def crossing(x, y, vx, vy, c, geo):
    """Time until a ball at ``(x, y)`` moving at ``(vx, vy)`` leaves cell ``c`` (every cell has
    neighbours on all sides: the grid wraps), and the direction (``grid.CROSS_*``, or
    ``grid.NO_CROSSING`` for a ball at rest)."""
    x0, y0, hx, hy, nx, ny = geo
    cx = c % nx
    cy = c // nx
    best = INF
    direction = grid.NO_CROSSING
    if vx > 0.0:
        best = max((x0 + (cx + 1) * hx - x) / vx, 0.0)
        direction = grid.CROSS_RIGHT
    elif vx < 0.0:
        best = max((x0 + cx * hx - x) / vx, 0.0)
        direction = grid.CROSS_LEFT
    if vy > 0.0:  # (in 1D vy is 0)
        t = max((y0 + (cy + 1) * hy - y) / vy, 0.0)
        if t < best:
            best = t
            direction = grid.CROSS_UP
    elif vy < 0.0:
        t = max((y0 + cy * hy - y) / vy, 0.0)
        if t < best:
            best = t
            direction = grid.CROSS_DOWN
    return best, direction


@njit(inline="always")
def neighbour(c, oy, ox, nx, ny, lx, ly):
    """The cell ``(ox, oy)`` cells away from cell ``c``, wrapped, and the shift ``(sx, sy)`` that
    brings a ball there next to cell ``c``."""
    gx = c % nx + ox
    gy = c // nx + oy
    sx = 0.0
    sy = 0.0
    if gx < 0:
        gx += nx
        sx = -lx
    elif gx >= nx:
        gx -= nx
        sx = lx
    if gy < 0:
        gy += ny
        sy = -ly
    elif gy >= ny:
        gy -= ny
        sy = ly
    return gy * nx + gx, sx, sy


@njit(refcount=False, forceinline=True)
def next_event(i, rebuild, cl, ph, geo, wk):
    """Ball ``i``'s next event, from the records: its cell crossing, and its earliest collision
    with a partner image in the cells around it, as ``(time, code, partner's change count)``
    (``rebuild``: only partners of higher index, as in the scheduler's ``next_event``)."""
    rec = cl.rec
    r = rec[i]
    best_t, best_code = INF, cal.EV_NONE
    tau, direction = crossing(r["x"], r["y"], r["vx"], r["vy"], cl.ci[i, C_CELL], geo)
    if direction >= 0:
        best_t, best_code = tau + r["ref_time"], cal.EV_CROSS - direction
    if not ph.pairs:
        return best_t, best_code, 0
    lx, ly = cell_lengths(ph.bounds, ph.dim)
    best_stamp = 0
    tests = 0
    c = cl.ci[i, C_CELL]
    reach_y = 1 if ly > 0.0 else 0
    for oy in range(-reach_y, reach_y + 1):
        for ox in range(-1, 2):
            cell, sx, sy = neighbour(c, oy, ox, geo.nx, geo.ny, lx, ly)
            k = cl.heads[cell]
            while k >= 0:
                if k != i and (k > i or not rebuild):
                    tests += 1
                    tc, dx, dy, dvx, dvy, sigma = pair_gap(i, k, rec)
                    dx += sx
                    dy += sy
                    if not not_before(dx, dy, dvx, dvy, sigma, best_t - tc):
                        t = tc + toi_pair(dx, dy, dvx, dvy, sigma)
                        if t < INF and cal.earlier(t, k, best_t, best_code, i):
                            best_t = t
                            best_code = k
                            best_stamp = rec[k]["changes"]
                k = rec[k]["cell_next"]
    wk.counters[PAIR_TESTS] += tests
    return best_t, best_code, best_stamp


@njit(refcount=False, forceinline=True)
def pair_time(i, k, rec, bounds, dim):
    """Step time at which balls ``i`` and ``k`` first touch through any image within a period
    (inf: never), from their records (as ``trajectories.pair_time``)."""
    lx, ly = cell_lengths(bounds, dim)
    tc, dx, dy, dvx, dvy, sigma = pair_gap(i, k, rec)
    return tc + toi_images(dx, dy, dvx, dvy, sigma, lx, ly)


@njit(refcount=False, forceinline=True)
def cross(bi, direction, cl, geo, images, bounds, dim):
    """Move ball ``bi`` into the cell it enters in ``direction``; across the periodic boundary its
    record moves by a period the other way and its image count by one."""
    lx, ly = cell_lengths(bounds, dim)
    c = cl.ci[bi, C_CELL]
    ox = 1 if direction == grid.CROSS_RIGHT else -1 if direction == grid.CROSS_LEFT else 0
    oy = 1 if direction == grid.CROSS_UP else -1 if direction == grid.CROSS_DOWN else 0
    cell, sx, sy = neighbour(c, oy, ox, geo.nx, geo.ny, lx, ly)
    r = cl.rec[bi]
    if sx != 0.0:
        r["x"] -= sx
        images[bi, 0] += ox
    if sy != 0.0:
        r["y"] -= sy
        images[bi, 1] += oy
    grid.unlink(bi, cl.rec, cl.ci, cl.heads)
    grid.link(bi, cell, cl.rec, cl.ci, cl.heads)


@njit(refcount=False, forceinline=True)
def screen(bi, t, now, ph, cl, geo, wk, images):
    """The scheduler's ``screen`` for a periodic scene: a crossing moves (and may wrap) the ball, a
    pair event is re-verified through the images."""
    code = cl.ci[bi, C_EVENT_OTHER]
    if cal.is_stale(bi, cl.rec, cl.ci):
        wk.counters[STALE_EVENTS] += 1
        wk.pending[0] = bi
        return PREDICT, t, now
    if cal.is_crossing(code):
        wk.counters[CELL_CROSSINGS] += 1
        cross(bi, cal.EV_CROSS - code, cl, geo, images, ph.bounds, ph.dim)
        wk.pending[0] = bi
        return PREDICT, t, max(now, t)
    t_check = pair_time(bi, code, cl.rec, ph.bounds, ph.dim) if code >= 0 else INF
    if t_check <= t:
        return RUN, t_check, now
    if t_check == INF:
        wk.pending[0] = bi
        return PREDICT, t, now
    cl.rec[bi]["event_time"] = t_check
    return RESCHEDULE, t, now


@njit(refcount=False, forceinline=True)
def nearest_partner(ev, bounds, dim):
    """Put row 1 of an event's balls (the partner) at its image nearest to row 0."""
    lx, ly = cell_lengths(bounds, dim)
    pos = ev.pos
    pos[1, 0] = pos[0, 0] + nearest(pos[1, 0] - pos[0, 0], lx)
    pos[1, 1] = pos[0, 1] + nearest(pos[1, 1] - pos[0, 1], ly)


@njit(refcount=False, forceinline=True)
def after_pair(bj, rows_before, cl, ev, wk, bounds, dim):
    """After a pair event resolved on the event's rows: the partner's row back at its own position
    (the records take the rows' state), and a reported contact point wrapped into the cell."""
    r = cl.rec[bj]
    ev.pos[1, 0] = r["x"]
    ev.pos[1, 1] = r["y"]
    if wk.n_imp[0] > rows_before:
        wrap_point(wk.imp, wk.n_imp[0] - 1, bounds, dim)
