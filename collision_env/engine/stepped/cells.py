"""The cheap modes' cell lists: every sub-step sorts the balls into the grid's cells afresh (O(N)).

The grid is laid out by :mod:`~collision_env.engine.broadphase` (cells two diameters wide, see
``reach`` there). A sub-step's lists live in one int64 scratch array of :func:`scratch_size`
(``state.SubstepScratch``); :class:`CellLists` names its parts.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..broadphase import CHEAP_CELLS_PER_BALL, block, cell_of


class CellLists(NamedTuple):
    """A sub-step's cell lists (views of the scratch array)."""

    head: np.ndarray  #: (cells,) the first ball of each cell, -1 for none
    nxt: np.ndarray  #: (N,) the next ball in the same cell
    cell: np.ndarray  #: (N,) each ball's cell
    near: np.ndarray  #: (cells,) a count per cell, or a ball's neighbours
    nx: int  #: cells along x
    ny: int  #: cells along y


def scratch_size(n: int) -> int:
    """Length of the int scratch of the cell lists for ``n`` balls (at most
    ``broadphase.CHEAP_CELLS_PER_BALL`` cells per ball)."""
    return (2 + 2 * CHEAP_CELLS_PER_BALL) * n


@njit(inline="always")
def empty_lists(n, scratch, geo):
    """Cell lists of ``n`` balls in ``scratch``, every cell empty if the grid has more than one (a
    grid of one cell keeps no lists: every ball is every other's neighbour)."""
    m = CHEAP_CELLS_PER_BALL * n  # (``near`` holds a count per cell, or a ball's neighbours)
    head, nxt, cell, near = (
        scratch[0:m],
        scratch[m : m + n],
        scratch[m + n : m + 2 * n],
        scratch[m + 2 * n : 2 * m + 2 * n],
    )
    cells = CellLists(head, nxt, cell, near, geo.nx, geo.ny)
    if geo.nx * geo.ny > 1:
        for c in range(geo.nx * geo.ny):
            cells.head[c] = -1
    return cells


@njit(inline="always")
def file_ball(cells, i, c):
    """Put ball ``i`` in cell ``c`` (at the head of its list: balls filed from the last to the
    first are listed in index order)."""
    cells.cell[i] = c
    cells.nxt[i] = cells.head[c]
    cells.head[c] = i


@njit(inline="always")
def cell_lists(n, p, v, h, scratch, geo):
    """Sort the balls into the grid's cells where they will be after the sub-step's move of ``h``
    seconds (before it is made, so that a scene can still stall untouched)."""
    cells = empty_lists(n, scratch, geo)
    if geo.nx * geo.ny > 1:
        for i in range(n - 1, -1, -1):
            x, y = p[i, 0] + v[i, 0] * h, p[i, 1] + v[i, 1] * h
            file_ball(cells, i, cell_of(x, y, geo.x0, geo.y0, geo.hx, geo.hy, geo.nx, geo.ny))
    return cells


@njit(inline="always")
def worst_case_impacts(n, cells, room):
    """Most impacts a sub-step can record: a pair per neighbour, and border and containment
    impacts; counted cell by cell only when a cruder bound (every ball's 3 x 3 block as full as
    the fullest cell) exceeds the ``room`` left in the buffer."""
    if cells.nx * cells.ny == 1:
        return n * (n - 1) // 2 + 4 * n
    near = cells.near
    for c in range(cells.nx * cells.ny):
        near[c] = 0
    fullest = 0
    for i in range(n):
        near[cells.cell[i]] += 1
        fullest = max(fullest, near[cells.cell[i]])
    if 4 * n + 9 * n * fullest <= room:
        return 4 * n + 9 * n * fullest
    worst = 4 * n
    for i in range(n):
        cx0, cx1, cy0, cy1 = block(cells.cell[i], cells.nx, cells.ny)
        for cy in range(cy0, cy1 + 1):
            for cx in range(cx0, cx1 + 1):
                worst += near[cy * cells.nx + cx]
    return worst


@njit(inline="always")
def insert_sorted(out, m, j):
    """Insert ``j`` into the sorted prefix ``out[:m]`` (a handful of neighbours); returns ``m + 1``."""
    q = m
    while q > 0 and out[q - 1] > j:
        out[q] = out[q - 1]
        q -= 1
    out[q] = j
    return m + 1


@njit(inline="always")
def later_neighbours(i, n, cells):
    """The balls ``j > i`` in the 3 x 3 cells around ball ``i``, ascending, into ``cells.near``;
    returns how many. With one cell that is every ``j > i``, so the cheap modes visit pairs in the
    same index order with or without a grid."""
    out = cells.near
    m = 0
    if cells.nx * cells.ny == 1:
        for j in range(i + 1, n):
            out[m] = j
            m += 1
        return m
    cx0, cx1, cy0, cy1 = block(cells.cell[i], cells.nx, cells.ny)
    for cy in range(cy0, cy1 + 1):
        for cx in range(cx0, cx1 + 1):
            j = cells.head[cy * cells.nx + cx]
            while j >= 0:
                if j > i:
                    m = insert_sorted(out, m, j)
                j = cells.nxt[j]
    return m
