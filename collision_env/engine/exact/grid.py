"""Exact mode's neighbour search: each ball's cell, kept current by cell-crossing events.

The grid is laid out by :mod:`~collision_env.engine.broadphase`; here a ball leaves its cell at a
predicted time, like any other event (:func:`crossing`), and moves to the neighbour it enters.
Cell lists are doubly linked, so a ball leaves its cell in O(1): a ball's ``cell_next`` is in its
calendar record (``layout.CAL_RECORD``, read for every neighbour), its ``cell`` and ``cell_prev``
in its int32 row (``layout.CAL_I``); the first ball of cell c is ``heads[c]``, in an int32 array of
its own (the heads of a 3 x 3 block share a few cache lines).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .._jit import njit
from ..broadphase import cell_of
from ..layout import C_CELL, C_CELL_PREV, W_GRID_HX, W_GRID_HY, W_GRID_NX, W_GRID_NY, W_GRID_X0, W_GRID_Y0

#: Directions a ball leaves its cell in (crossing codes), and ``NO_CROSSING``.
CROSS_LEFT, CROSS_RIGHT, CROSS_DOWN, CROSS_UP = 0, 1, 2, 3
NO_CROSSING = -1


class GridGeometry(NamedTuple):
    """A scene's grid (``broadphase.grid_geometry``): its origin, cell sizes and cell counts."""

    x0: float  #: m
    y0: float  #: m
    hx: float  #: cell width, m (inf: one cell along x)
    hy: float  #: cell height, m
    nx: int  #: cells along x
    ny: int  #: cells along y


@njit(inline="always")
def scene_geometry(work_f, work_i, sc):
    """Scene ``sc``'s grid, as :func:`~collision_env.engine.broadphase.grid_geometry` laid it out in
    the per-scene work arrays (``layout.WORK_F``/``WORK_I``)."""
    return GridGeometry(
        work_f[sc, W_GRID_X0],
        work_f[sc, W_GRID_Y0],
        work_f[sc, W_GRID_HX],
        work_f[sc, W_GRID_HY],
        work_i[sc, W_GRID_NX],
        work_i[sc, W_GRID_NY],
    )


@njit(inline="always")
def has_cells(geo):
    """The grid has more than one cell: the scene uses it."""
    return geo.nx * geo.ny > 1


@njit(inline="always")
def near_border(c, geo):
    """Cell ``c`` is one of the grid's outermost (or the only one): a ball elsewhere is at least a
    cell's width, more than its radius, from every wall."""
    cx = c % geo.nx
    cy = c // geo.nx
    return cx == 0 or cx == geo.nx - 1 or cy == 0 or cy == geo.ny - 1


@njit(refcount=False, forceinline=True)
def link(i, c, rec, ci, heads):
    """Put ball ``i`` at the front of cell ``c``'s list."""
    head = heads[c]
    ci[i, C_CELL] = c
    ci[i, C_CELL_PREV] = -1
    rec[i]["cell_next"] = head
    if head >= 0:
        ci[head, C_CELL_PREV] = i
    heads[c] = i


@njit(refcount=False, forceinline=True)
def unlink(i, rec, ci, heads):
    """Take ball ``i`` out of its cell's list."""
    prev = ci[i, C_CELL_PREV]
    nxt = rec[i]["cell_next"]
    if prev >= 0:
        rec[prev]["cell_next"] = nxt
    else:
        heads[ci[i, C_CELL]] = nxt
    if nxt >= 0:
        ci[nxt, C_CELL_PREV] = prev


@njit(refcount=False, forceinline=True)
def move_to_cell(i, c, rec, ci, heads):
    """Move ball ``i`` into cell ``c`` (nothing to do if it is there already)."""
    if c != ci[i, C_CELL]:
        unlink(i, rec, ci, heads)
        link(i, c, rec, ci, heads)


@njit(refcount=False, python=False)
def fill_cells(n, rec, ci, heads, geo):
    """Empty every cell and put every ball in the cell of its calendar position."""
    for c in range(geo.nx * geo.ny):
        heads[c] = -1
    for i in range(n - 1, -1, -1):
        link(i, cell_of(rec[i]["x"], rec[i]["y"], geo.x0, geo.y0, geo.hx, geo.hy, geo.nx, geo.ny), rec, ci, heads)


@njit(forceinline=True)
def crossing(x, y, vx, vy, c, geo):
    """Time until a ball at ``(x, y)`` moving at ``(vx, vy)`` leaves cell ``c`` for a neighbour, and
    the direction (``CROSS_*``, or ``NO_CROSSING``). The outermost cells reach to infinity, so
    there is no crossing out of the grid."""
    x0, y0, hx, hy, nx, ny = geo
    cx = c % nx
    cy = c // nx
    best = math.inf
    direction = NO_CROSSING
    if vx > 0.0 and cx < nx - 1:
        best = max((x0 + (cx + 1) * hx - x) / vx, 0.0)
        direction = CROSS_RIGHT
    elif vx < 0.0 and cx > 0:
        best = max((x0 + cx * hx - x) / vx, 0.0)
        direction = CROSS_LEFT
    if vy > 0.0 and cy < ny - 1:
        t = max((y0 + (cy + 1) * hy - y) / vy, 0.0)
        if t < best:
            best = t
            direction = CROSS_UP
    elif vy < 0.0 and cy > 0:
        t = max((y0 + cy * hy - y) / vy, 0.0)
        if t < best:
            best = t
            direction = CROSS_DOWN
    return best, direction


@njit(inline="always")
def neighbour_cell(c, direction, nx):
    """The cell a ball enters when it leaves cell ``c`` in ``direction``."""
    if direction == CROSS_LEFT:
        return c - 1
    if direction == CROSS_RIGHT:
        return c + 1
    if direction == CROSS_DOWN:
        return c - nx
    return c + nx
