"""The event loop of a compression: hard disks whose radii grow at constant speeds
(Lubachevsky & Stillinger, *J. Stat. Phys.* 60, 561 (1990); the physics is in
:mod:`~collision_env.engine.physics.growth`), in a box or a periodic cell.

Its parts, each with one job, as in event-driven codes (Rapaport, *The Art of Molecular Dynamics
Simulation*, 2nd ed. 2004, ch. 14; Smallenburg, arXiv:2204.06662 (2022)):

- **The disks** (:class:`Disks`) are updated lazily: each stores its position at its own time
  ``t_local``, and is moved only when an event involves it. A disk's radius is ``r0 + r_dot t`` at
  the compression's clock ``t``. Each disk counts its collisions (``collisions``): a predicted collision
  whose partner has collided since is stale.
- **The scheduler** (:func:`predict`) keeps one event per disk, its earliest: a collision with a
  disk of its 3 x 3 block of cells, a wall (in a box), or leaving its cell. The pair's prediction
  lives in one of the two disks' slots only; whichever of them moves first predicts the pair anew
  (the scheme of Lubachevsky's original code).
- **The sorter** (:class:`Events`) is a tournament tree over the disks' event times: the root holds
  the disk whose event is next, and a disk's new time climbs ``log2 N`` levels.
- **The neighbour grid** (:class:`Cells`) is a linked list of disks per cell, cells at least one
  largest diameter wide (with ``broadphase.CELL_MARGIN``) until the clock reaches ``t_grid``: the
  caller then makes a grid of wider cells and reschedules.

:func:`run` processes events until a number of collisions, or until the clock would pass a time;
the caller (:mod:`~collision_env.engine.compression`) then brings every disk to that time
(:func:`synchronise`), rescales the velocities, and :func:`reschedule` predicts every disk again.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..broadphase import cell_of
from ..physics.growth import bounce_growing_pair, bounce_growing_wall, toi_growing_pair, toi_growing_wall
from ..physics.periodic import nearest
from ..physics.toi import INF

#: What an event's ``other`` holds besides a partner disk (>= 0): a wall, ``WALL_EVENT - wall``
#: (``physics.walls`` codes), or leaving the cell, ``CROSS_EVENT - direction`` with the directions
#: -x, +x, -y, +y as 0..3.
WALL_EVENT = -1
CROSS_EVENT = -5
NO_EVENT = -9
#: Along an axis of a periodic cell with at least this many grid cells, the nearest image of a pair
#: is the only one to predict (see ``_images``).
NEAREST_IMAGE_CELLS = 6

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


class Disks(NamedTuple):
    """The disks, each at its own time (see the module docstring)."""

    pos: np.ndarray  #: (N, 2) centres at ``t_local``
    vel: np.ndarray  #: (N, 2)
    t_local: np.ndarray  #: (N,)
    r0: np.ndarray  #: (N,) radii at time 0
    r_dot: np.ndarray  #: (N,) growth speeds of the radii
    mass: np.ndarray  #: (N,)
    collisions: np.ndarray  #: (N,) int64, each disk's collisions so far


class Events(NamedTuple):
    """Each disk's next event, and the tournament tree that sorts them."""

    time: np.ndarray  #: (N,) absolute time
    other: np.ndarray  #: (N,) int64: partner disk, or a wall or crossing code
    other_count: np.ndarray  #: (N,) int64: the partner's ``collisions`` when predicted
    tree: np.ndarray  #: (2 P,) int64, P the power of two >= N: node k holds the earlier of 2k, 2k+1


class Cells(NamedTuple):
    """The neighbour grid: per cell a doubly linked list of its disks."""

    cell: np.ndarray  #: (N,) int64, each disk's cell ``cy * nx + cx``
    head: np.ndarray  #: (nx * ny,) int64, a cell's first disk or -1
    nxt: np.ndarray  #: (N,) int64
    prv: np.ndarray  #: (N,) int64


class Box(NamedTuple):
    """The box or periodic cell and its grid."""

    x0: float
    y0: float
    lx: float  #: the box's or cell's width
    ly: float
    periodic: bool
    hx: float  #: cell width (the width of the box with one cell along x)
    hy: float
    nx: int
    ny: int


def make_events(n: int) -> Events:
    """Event slots and tree for ``n`` disks (filled by :func:`reschedule`)."""
    leaves = 1 << max(n - 1, 1).bit_length()
    return Events(
        np.full(n, INF),
        np.full(n, NO_EVENT, dtype=np.int64),
        np.zeros(n, dtype=np.int64),
        np.full(2 * leaves, -1, dtype=np.int64),
    )


def make_cells(n: int, box: Box) -> Cells:
    """Cell lists for ``n`` disks on ``box``'s grid (filled by :func:`reschedule`)."""
    return Cells(
        np.zeros(n, dtype=np.int64),
        np.full(box.nx * box.ny, -1, dtype=np.int64),
        np.full(n, -1, dtype=np.int64),
        np.full(n, -1, dtype=np.int64),
    )


# --- the sorter ---------------------------------------------------------------------------------


@njit(forceinline=True)
def _earlier(time, a, b):
    if a < 0:
        return b
    if b < 0 or time[a] <= time[b]:
        return a
    return b


@njit(forceinline=True)
def sort_event(ev, i):
    """Disk ``i``'s event time changed: climb the tree from its leaf."""
    k = (ev.tree.shape[0] >> 1) + i
    k >>= 1
    while k >= 1:
        ev.tree[k] = _earlier(ev.time, ev.tree[2 * k], ev.tree[2 * k + 1])
        k >>= 1


@njit
def sort_all(ev):
    """Build the tree over every disk's event."""
    leaves = ev.tree.shape[0] >> 1
    for i in range(leaves):
        ev.tree[leaves + i] = i if i < ev.time.shape[0] else -1
    for k in range(leaves - 1, 0, -1):
        ev.tree[k] = _earlier(ev.time, ev.tree[2 * k], ev.tree[2 * k + 1])


# --- the neighbour grid ---------------------------------------------------------------------------


@njit(forceinline=True)
def _link(cells, i, c):
    cells.cell[i] = c
    first = cells.head[c]
    cells.nxt[i] = first
    cells.prv[i] = -1
    if first >= 0:
        cells.prv[first] = i
    cells.head[c] = i


@njit(forceinline=True)
def _unlink(cells, i):
    before = cells.prv[i]
    after = cells.nxt[i]
    if before >= 0:
        cells.nxt[before] = after
    else:
        cells.head[cells.cell[i]] = after
    if after >= 0:
        cells.prv[after] = before


@njit(forceinline=True)
def _neighbour_cell(cx, cy, ox, oy, box):
    """The cell ``(ox, oy)`` away from ``(cx, cy)``, wrapped in a periodic cell; -1 outside a box."""
    x = cx + ox
    y = cy + oy
    if box.periodic:
        x %= box.nx
        y %= box.ny
    elif x < 0 or x >= box.nx or y < 0 or y >= box.ny:
        return -1
    return y * box.nx + x


# --- the scheduler --------------------------------------------------------------------------------


@njit(forceinline=True)
def _advance(disks, i, t):
    """Move disk ``i`` along its straight line to time ``t``."""
    dt = t - disks.t_local[i]
    disks.pos[i, 0] += disks.vel[i, 0] * dt
    disks.pos[i, 1] += disks.vel[i, 1] * dt
    disks.t_local[i] = t


@njit(forceinline=True)
def _separation(disks, i, j, t, box):
    """``r_j - r_i`` at time ``t`` (disk ``i`` is at ``t``), both inside the box or cell."""
    dt = t - disks.t_local[j]
    dx = disks.pos[j, 0] + disks.vel[j, 0] * dt - disks.pos[i, 0]
    dy = disks.pos[j, 1] + disks.vel[j, 1] * dt - disks.pos[i, 1]
    return dx, dy


@njit(forceinline=True)
def _images(n_cells, periodic):
    """How many images either side to try along an axis of a periodic cell of ``n_cells`` cells: 0
    (the nearest image alone) where a disk is predicted anew before it moves a cell, and a cell is
    at most a sixth of the period, so that no farther image can come into contact first (the
    others start half a period away, and the two disks close in by less than two cells); else 1.
    Both disks are in the cell, so their separation is within a period, and these three images are
    all that can touch."""
    return 1 if periodic and n_cells < NEAREST_IMAGE_CELLS else 0


@njit(forceinline=True)
def _pair_toi(dx, dy, dvx, dvy, sigma, sigma_dot, box):
    """:func:`~collision_env.engine.physics.growth.toi_growing_pair` through the images that can
    touch (see :func:`_images`)."""
    kx = _images(box.nx, box.periodic)
    ky = _images(box.ny, box.periodic)
    if box.periodic and kx == 0:
        dx = nearest(dx, box.lx)
    if box.periodic and ky == 0:
        dy = nearest(dy, box.ly)
    best = INF
    for oy in range(-ky, ky + 1):
        for ox in range(-kx, kx + 1):
            t = toi_growing_pair(dx + ox * box.lx, dy + oy * box.ly, dvx, dvy, sigma, sigma_dot)
            if t < best:
                best = t
    return best


@njit(forceinline=True)
def _crossing(disks, cells, box, i):
    """Time until disk ``i`` (at its own time) leaves its cell, and the direction, or ``(inf, -1)``."""
    best = INF
    direction = -1
    c = cells.cell[i]
    for axis in range(2):
        n_cells = box.nx if axis == 0 else box.ny
        if n_cells == 1 and not box.periodic:
            continue
        k = c % box.nx if axis == 0 else c // box.nx
        lo = box.x0 if axis == 0 else box.y0
        h = box.hx if axis == 0 else box.hy
        v = disks.vel[i, axis]
        x = disks.pos[i, axis]
        if v > 0.0 and (box.periodic or k < n_cells - 1):
            t = max(lo + (k + 1) * h - x, 0.0) / v
            if t < best:
                best = t
                direction = 2 * axis + 1
        elif v < 0.0 and (box.periodic or k > 0):
            t = max(x - (lo + k * h), 0.0) / -v
            if t < best:
                best = t
                direction = 2 * axis
    return best, direction


@njit
def predict(disks, ev, cells, box, i, t):
    """Bring disk ``i`` to time ``t`` and store its earliest event (a collision in its block of cells,
    a wall in a box, or leaving its cell); the caller sorts it."""
    _advance(disks, i, t)
    best, direction = _crossing(disks, cells, box, i)
    other = CROSS_EVENT - direction
    r = disks.r0[i] + disks.r_dot[i] * t
    if not box.periodic:
        for axis in range(2):
            lo = box.x0 if axis == 0 else box.y0
            hi = lo + (box.lx if axis == 0 else box.ly)
            tw, side = toi_growing_wall(disks.pos[i, axis], disks.vel[i, axis], r, disks.r_dot[i], lo, hi)
            if tw < best:
                best = tw
                other = WALL_EVENT - (2 * axis + side)
    partner_count = 0
    c = cells.cell[i]
    cx = c % box.nx
    cy = c // box.nx
    rx = 0 if box.nx == 1 else 1  # (a periodic grid has 1 cell or at least 3 along an axis)
    ry = 0 if box.ny == 1 else 1
    for oy in range(-ry, ry + 1):
        for ox in range(-rx, rx + 1):
            cc = _neighbour_cell(cx, cy, ox, oy, box)
            j = cells.head[cc] if cc >= 0 else -1
            while j >= 0:
                if j != i:
                    dx, dy = _separation(disks, i, j, t, box)
                    sigma = r + disks.r0[j] + disks.r_dot[j] * t
                    sigma_dot = disks.r_dot[i] + disks.r_dot[j]
                    dvx = disks.vel[j, 0] - disks.vel[i, 0]
                    dvy = disks.vel[j, 1] - disks.vel[i, 1]
                    tp = _pair_toi(dx, dy, dvx, dvy, sigma, sigma_dot, box)
                    if tp < best:
                        best = tp
                        other = j
                        partner_count = disks.collisions[j]
                j = cells.nxt[j]
    ev.time[i] = t + best
    ev.other[i] = other
    ev.other_count[i] = partner_count


@njit(forceinline=True)
def schedule(disks, ev, cells, box, i, t):
    """:func:`predict` disk ``i`` at ``t`` and sort its new event."""
    predict(disks, ev, cells, box, i, t)
    sort_event(ev, i)


# --- the events -----------------------------------------------------------------------------------


@njit(forceinline=True)
def _collide(disks, ev, cells, box, tally, i, j, t):
    """Disks ``i`` and ``j`` touch at ``t``: bounce them apart, add their virial, predict both."""
    _advance(disks, i, t)
    _advance(disks, j, t)
    dx, dy = _separation(disks, i, j, t, box)
    if box.periodic:  # (the images in contact are the nearest ones: a diameter is under half the cell)
        dx = nearest(dx, box.lx)
        dy = nearest(dy, box.ly)
    dist = math.sqrt(dx * dx + dy * dy)
    sigma_dot = disks.r_dot[i] + disks.r_dot[j]
    impulse = bounce_growing_pair(disks.vel, i, j, dx / dist, dy / dist, sigma_dot, disks.mass[i], disks.mass[j])
    tally[TALLY_PAIR_VIRIAL] += impulse * (disks.r0[i] + disks.r0[j] + sigma_dot * t)
    tally[TALLY_COLLISIONS] += 1.0
    disks.collisions[i] += 1
    disks.collisions[j] += 1
    schedule(disks, ev, cells, box, i, t)
    schedule(disks, ev, cells, box, j, t)


@njit(forceinline=True)
def _hit_wall(disks, ev, cells, box, tally, i, wall, t):
    """Disk ``i`` touches ``wall`` (2 * axis + side) at ``t``: bounce it, add its virial, predict it."""
    _advance(disks, i, t)
    axis = wall >> 1
    v = disks.vel[i, axis]
    v_new = bounce_growing_wall(v, disks.r_dot[i], wall & 1)
    disks.vel[i, axis] = v_new
    tally[TALLY_WALL_VIRIAL] += disks.mass[i] * abs(v_new - v) * (disks.r0[i] + disks.r_dot[i] * t)
    tally[TALLY_COLLISIONS] += 1.0
    disks.collisions[i] += 1
    schedule(disks, ev, cells, box, i, t)


@njit(forceinline=True)
def _cross(disks, ev, cells, box, tally, i, direction, t):
    """Disk ``i`` leaves its cell at ``t`` towards ``direction``: move it to the next cell (through
    the periodic boundary, shifting its position by a period), then predict it."""
    _advance(disks, i, t)
    axis = direction >> 1
    step = 1 if direction & 1 else -1
    c = cells.cell[i]
    cx = c % box.nx + (step if axis == 0 else 0)
    cy = c // box.nx + (step if axis == 1 else 0)
    if cx < 0 or cx >= box.nx:
        disks.pos[i, 0] -= step * box.lx
        cx %= box.nx
    if cy < 0 or cy >= box.ny:
        disks.pos[i, 1] -= step * box.ly
        cy %= box.ny
    _unlink(cells, i)
    _link(cells, i, cy * box.nx + cx)
    tally[TALLY_CROSSINGS] += 1.0
    schedule(disks, ev, cells, box, i, t)


@njit(label="the compression (growing disks)")
def run(disks, ev, cells, box, tally, collisions, until, idle):
    """Process events in time order until ``collisions`` more collisions (pairs and walls) are done,
    the next event is at or after ``until``, or ``idle`` events in a row were no collision (disks
    that no longer meet, without growth). Returns ``RAN_COLLISIONS``, ``RAN_UNTIL`` or ``RAN_IDLE``."""
    goal = tally[TALLY_COLLISIONS] + collisions
    quiet = 0
    while tally[TALLY_COLLISIONS] < goal:
        i = ev.tree[1]
        t = ev.time[i]
        if not t < until:
            return RAN_UNTIL
        if quiet >= idle:
            return RAN_IDLE
        tally[TALLY_CLOCK] = t
        other = ev.other[i]
        quiet += 1
        if other >= 0:
            if disks.collisions[other] == ev.other_count[i]:
                _collide(disks, ev, cells, box, tally, i, other, t)
                quiet = 0
            else:  # the partner collided since: predict again
                schedule(disks, ev, cells, box, i, t)
        elif other <= CROSS_EVENT:
            _cross(disks, ev, cells, box, tally, i, CROSS_EVENT - other, t)
        else:
            _hit_wall(disks, ev, cells, box, tally, i, WALL_EVENT - other, t)
            quiet = 0
    return RAN_COLLISIONS


# --- starting and restarting ------------------------------------------------------------------------


@njit
def synchronise(disks, t):
    """Bring every disk to time ``t``."""
    for i in range(disks.pos.shape[0]):
        _advance(disks, i, t)


@njit
def reschedule(disks, ev, cells, box, t):
    """Every disk, at time ``t`` (:func:`synchronise`), into ``box``'s grid, and its next event
    predicted and sorted anew (after its velocity, or the grid, changed)."""
    cells.head[:] = -1
    for i in range(disks.pos.shape[0] - 1, -1, -1):
        c = cell_of(disks.pos[i, 0], disks.pos[i, 1], box.x0, box.y0, box.hx, box.hy, box.nx, box.ny)
        _link(cells, i, c)
    for i in range(disks.pos.shape[0]):
        predict(disks, ev, cells, box, i, t)
    sort_all(ev)
