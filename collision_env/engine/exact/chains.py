"""The kernel of event-chain Monte Carlo for hard disks in a periodic cell (the sampler is
:func:`collision_env.engine.event_chain`, which states the method and its sources).

A chain moves one disk at a time along +x (or +y) at unit speed, for a total displacement
``chain_length``: the moving disk flies until it touches another, which then moves on in its place
(a lifting). Each flight is a one-dimensional time of impact: disk ``j``, ``d_along`` ahead (taken
modulo the period, so in ``[0, L)``) and ``d_across`` aside (nearest image), is hit after ``d_along -
sqrt(sigma^2 - d_across^2)`` when ``|d_across| < sigma``, and never otherwise.

The neighbour search is the engine's cell grid (:func:`~collision_env.engine.broadphase.grid_geometry`:
cells at least one largest diameter wide, at least 3 along a repeating axis or else one), with a
linked list of disks per cell. A flight never leaves the cell the disk is in: it ends at the cell's
far edge (the disk then moves into the next cell, through the periodic boundary from the last one)
or earlier. A disk it can hit within that flight lies at most a cell plus a diameter ahead, so in
the disk's own column of cells or the next one (rows: its own and either side): six cells, all the
candidates.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..blocking import push
from ..broadphase import cell_of

#: The run's tallies (``tally``, float64), by name.
TALLY_EVENTS = 0  #: liftings
TALLY_CHAINS = 1  #: chains completed
TALLY_LIFTED = 2  #: sum over liftings of the centres' distance along the chain's axis (m)
TALLY_DISPLACEMENT = 3  #: the moving disks' total displacement (m), the chain in progress included
TALLY_SIZE = 4

#: The chain in progress (``state``, float64): its moving disk, the displacement it has left (0: no
#: chain in progress), and the sum of its liftings' distances so far.
STATE_DISK, STATE_LEFT, STATE_LIFTED = range(3)
STATE_SIZE = 3


class ChainGrid(NamedTuple):
    """The periodic cell and its grid of ``nx * ny`` cells, numbered ``cy * nx + cx``."""

    x0: float
    y0: float
    lx: float  #: the periodic cell's width
    ly: float
    hx: float  #: a grid cell's width (``lx / nx``)
    hy: float
    nx: int
    ny: int


class CellLists(NamedTuple):
    """Per grid cell a doubly linked list of its disks."""

    at: np.ndarray  #: (N, 2) int64, each disk's cell ``(cx, cy)``
    head: np.ndarray  #: (nx * ny,) int64, a cell's first disk or -1
    nxt: np.ndarray  #: (N,) int64
    prv: np.ndarray  #: (N,) int64


def make_cells(n: int, grid: ChainGrid) -> CellLists:
    """Empty cell lists for ``n`` disks on ``grid`` (filled by :func:`fill_cells`)."""
    return CellLists(
        np.zeros((n, 2), dtype=np.int64),
        np.full(grid.nx * grid.ny, -1, dtype=np.int64),
        np.full(n, -1, dtype=np.int64),
        np.full(n, -1, dtype=np.int64),
    )


@njit(forceinline=True)
def _link(cells, grid, i, cx, cy):
    c = cy * grid.nx + cx
    cells.at[i, 0] = cx
    cells.at[i, 1] = cy
    first = cells.head[c]
    cells.nxt[i] = first
    cells.prv[i] = -1
    if first >= 0:
        cells.prv[first] = i
    cells.head[c] = i


@njit(forceinline=True)
def _unlink(cells, grid, i):
    before = cells.prv[i]
    after = cells.nxt[i]
    if before >= 0:
        cells.nxt[before] = after
    else:
        cells.head[cells.at[i, 1] * grid.nx + cells.at[i, 0]] = after
    if after >= 0:
        cells.prv[after] = before


@njit
def fill_cells(pos, cells, grid):
    """Put every disk (wrapped into the cell) into its grid cell's list."""
    cells.head[:] = -1
    for i in range(pos.shape[0] - 1, -1, -1):
        c = cell_of(pos[i, 0], pos[i, 1], grid.x0, grid.y0, grid.hx, grid.hy, grid.nx, grid.ny)
        _link(cells, grid, i, c % grid.nx, c // grid.nx)


@njit(forceinline=True)
def _first_hit(pos, radii, cells, grid, i, axis, flight):
    """The first disk that disk ``i`` hits moving along ``axis`` by at most ``flight`` (within its grid
    cell): ``(distance, partner, contact)``, ``contact`` the centres' distance along the axis at the
    hit; ``(flight, -1, 0)`` if none."""
    across = 1 - axis
    n_along = grid.nx if axis == 0 else grid.ny
    n_across = grid.ny if axis == 0 else grid.nx
    period_along = grid.lx if axis == 0 else grid.ly
    period_across = grid.ly if axis == 0 else grid.lx
    half_across = 0.5 * period_across
    col = cells.at[i, axis]
    row = cells.at[i, across]
    best = flight
    partner = -1
    contact = 0.0
    x = pos[i, axis]
    y = pos[i, across]
    r = radii[i]
    spread = 1 if n_across > 1 else 0
    for dc in range(min(n_along, 2)):
        a = col + dc
        if a == n_along:
            a = 0
        for dr in range(-spread, spread + 1):
            b = row + dr
            if b < 0:
                b += n_across
            elif b == n_across:
                b = 0
            j = cells.head[b * grid.nx + a if axis == 0 else a * grid.nx + b]
            while j >= 0:
                # (both in the cell: the nearest image across is within a period)
                d_across = pos[j, across] - y
                if d_across > half_across:
                    d_across -= period_across
                elif d_across < -half_across:
                    d_across += period_across
                sigma = r + radii[j]
                if abs(d_across) < sigma and j != i:
                    d_along = pos[j, axis] - x
                    if d_along < 0.0:
                        d_along += period_along
                    reach = math.sqrt(sigma * sigma - d_across * d_across)
                    s = d_along - reach
                    if s < best:
                        best = s
                        partner = j
                        contact = reach
                j = cells.nxt[j]
    return max(best, 0.0), partner, contact


@njit(forceinline=True)
def _next_cell(pos, images, cells, grid, i, axis):
    """Disk ``i`` is at its grid cell's far edge along ``axis``: move it into the next cell, through the
    periodic boundary from the last (its position then shifts by a period, and its image count by 1)."""
    cx = cells.at[i, 0]
    cy = cells.at[i, 1]
    if axis == 0:
        cx += 1
        if cx == grid.nx:
            cx = 0
            pos[i, 0] = max(pos[i, 0] - grid.lx, grid.x0)
            images[i, 0] += 1
    else:
        cy += 1
        if cy == grid.ny:
            cy = 0
            pos[i, 1] = max(pos[i, 1] - grid.ly, grid.y0)
            images[i, 1] += 1
    if grid.nx * grid.ny > 1:
        _unlink(cells, grid, i)
        _link(cells, grid, i, cx, cy)


@njit(forceinline=True)
def _far_edge(cells, grid, i, axis):
    """Where disk ``i``'s grid cell ends along ``axis`` (the last cell ends at the period exactly)."""
    k = cells.at[i, axis]
    if axis == 0:
        return grid.x0 + grid.lx if k == grid.nx - 1 else grid.x0 + (k + 1) * grid.hx
    return grid.y0 + grid.ly if k == grid.ny - 1 else grid.y0 + (k + 1) * grid.hy


@njit
def advance_chain(pos, images, radii, cells, grid, state, axis, until_events, tally):
    """Carry the chain in ``state`` along ``axis`` (0: +x, 1: +y) until it ends or the events reach
    ``until_events``. Returns whether it ended. Between two liftings, a disk crosses at most a
    period's cells (see the lane below): the work is bounded by the events and the chains."""
    i = int(state[STATE_DISK])
    remaining = state[STATE_LEFT]
    lifted = state[STATE_LIFTED]
    period = grid.lx if axis == 0 else grid.ly
    free = 0.0  # how far the moving disk has flown without a hit
    while remaining > 0.0 and tally[TALLY_EVENTS] < until_events:
        room = max(_far_edge(cells, grid, i, axis) - pos[i, axis], 0.0)
        flight = min(remaining, room)
        s, partner, contact = _first_hit(pos, radii, cells, grid, i, axis, flight)
        pos[i, axis] += s
        remaining -= s
        tally[TALLY_DISPLACEMENT] += s
        if partner >= 0:
            lifted += contact
            tally[TALLY_EVENTS] += 1.0
            tally[TALLY_LIFTED] += contact
            i = partner
            free = 0.0
        elif flight == room and remaining > 0.0:
            _next_cell(pos, images, cells, grid, i, axis)
            free += s
            if free >= period and remaining >= period:
                # a whole period without a hit: the disk's lane is empty (the others stand still),
                # and each further period brings it back where it is
                laps = math.floor(remaining / period)
                rest = remaining % period
                tally[TALLY_DISPLACEMENT] += remaining - rest
                remaining = rest
                images[i, axis] += np.int64(laps)
    state[STATE_DISK] = i
    state[STATE_LEFT] = remaining
    state[STATE_LIFTED] = lifted
    return not remaining > 0.0


@njit(label="event chains (hard disks)")
def run(pos, images, radii, cells, grid, starts, first, length, until_events, most_chains, tally, state, blocks):
    """Run chains until the events reach ``until_events`` (the chain in progress then stays in
    ``state``, to go on at the next call), ``most_chains`` chains are done, or the starting disks
    ``starts[first:]`` run out. Chains go alternately along x and y (by the count
    of chains completed), each ``length`` long from the next of ``starts``; each completed chain's
    pressure estimate ``1 + lifted / length`` goes into the blocking accumulator ``blocks``. Returns
    the index of the next unused start."""
    k = first
    while tally[TALLY_EVENTS] < until_events:
        if not state[STATE_LEFT] > 0.0:
            if k == starts.shape[0] or tally[TALLY_CHAINS] >= most_chains:
                break
            state[STATE_DISK] = starts[k]
            state[STATE_LEFT] = length
            state[STATE_LIFTED] = 0.0
            k += 1
        axis = int(tally[TALLY_CHAINS]) % 2
        if advance_chain(pos, images, radii, cells, grid, state, axis, until_events, tally):
            tally[TALLY_CHAINS] += 1.0
            push(blocks, 1.0 + state[STATE_LIFTED] / length)
    return k
