"""The cheap modes in a periodic cell: cell lists that wrap, overlaps between nearest images, and
positions wrapped after every sub-step.

Only the cheap modes' periodic kernels compile this module (``substep.step_kernel(mode, True)``).
A sub-step moves every ball, resolves the overlaps its mode finds between nearest images (each pair
close enough to overlap is resolved with the partner moved to its image next to the ball, then
moved back), and wraps every
ball into the cell by floor division (``physics.periodic.wrap_all``): a ball that crossed the cell
many times in one sub-step is wrapped at once. The grid (``broadphase.grid_geometry``) has at least
3 cells along each repeating axis, or one, so the 3 x 3 cells around a ball are distinct.
"""

from __future__ import annotations

from .._jit import njit
from ..broadphase import cell_of
from ..layout import PAIR_TESTS
from ..physics.periodic import cell_lengths, nearest, wrap_all, wrap_coordinate, wrap_point
from . import naive, posteriori
from .cells import empty_lists, file_ball, insert_sorted


@njit(inline="always")
def cell_lists(n, p, v, h, scratch, geo, bounds, dim):
    """``cells.cell_lists`` for a periodic cell: the balls are sorted by where they will be after
    the sub-step's move, wrapped into the cell."""
    cells = empty_lists(n, scratch, geo)
    if geo.nx * geo.ny > 1:
        lx, ly = cell_lengths(bounds, dim)
        for i in range(n - 1, -1, -1):
            x = wrap_coordinate(p[i, 0] + v[i, 0] * h, bounds[0], lx)[0]
            y = wrap_coordinate(p[i, 1] + v[i, 1] * h, bounds[1], ly)[0]
            file_ball(cells, i, cell_of(x, y, geo.x0, geo.y0, geo.hx, geo.hy, geo.nx, geo.ny))
    return cells


@njit(inline="always")
def _reach(count):
    """How far the block around a cell reaches along an axis of ``count`` cells (3 or more: one
    cell each way, wrapped; one: the cell alone)."""
    return 1 if count >= 3 else 0


@njit(refcount=False, forceinline=True)
def worst_case_impacts(n, cells, room):
    """``cells.worst_case_impacts`` with blocks that wrap (no walls: a pair per neighbour)."""
    if cells.nx * cells.ny == 1:
        return n * (n - 1) // 2
    near = cells.near
    for c in range(cells.nx * cells.ny):
        near[c] = 0
    fullest = 0
    for i in range(n):
        near[cells.cell[i]] += 1
        fullest = max(fullest, near[cells.cell[i]])
    if 9 * n * fullest <= room:
        return 9 * n * fullest
    worst = 0
    rx = _reach(cells.nx)
    ry = _reach(cells.ny)
    for i in range(n):
        cx = cells.cell[i] % cells.nx
        cy = cells.cell[i] // cells.nx
        for oy in range(-ry, ry + 1):
            for ox in range(-rx, rx + 1):
                worst += near[((cy + oy) % cells.ny) * cells.nx + (cx + ox) % cells.nx]
    return worst


@njit(refcount=False, forceinline=True)
def later_neighbours(i, n, cells):
    """``cells.later_neighbours`` with blocks that wrap: the balls ``j > i`` in the cells around
    ball ``i``, ascending, into ``cells.near``; returns how many."""
    out = cells.near
    m = 0
    if cells.nx * cells.ny == 1:
        for j in range(i + 1, n):
            out[m] = j
            m += 1
        return m
    rx = _reach(cells.nx)
    ry = _reach(cells.ny)
    cx = cells.cell[i] % cells.nx
    cy = cells.cell[i] // cells.nx
    for oy in range(-ry, ry + 1):
        for ox in range(-rx, rx + 1):
            j = cells.head[((cy + oy) % cells.ny) * cells.nx + (cx + ox) % cells.nx]
            while j >= 0:
                if j > i:
                    m = insert_sorted(out, m, j)
                j = cells.nxt[j]
    return m


@njit(inline="always")
def _image_shift(i, j, pos, radius, lx, ly):
    """The shift that moves ball ``j`` to its image nearest ball ``i``, and whether that image is
    close enough to overlap (a far pair is left alone: moving it there and back would cost it
    round-off)."""
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    nx = nearest(dx, lx)
    ny = nearest(dy, ly)
    sigma = radius[i] + radius[j]
    return nx - dx, ny - dy, nx * nx + ny * ny <= sigma * sigma * (1.0 + 1e-9)


def _resolver(mode):
    """The periodic resolve of cheap ``mode``, with the signature of ``naive.resolve``."""
    is_naive = mode == "naive"

    @njit(refcount=False, forceinline=True)
    def resolve(sc, t_end, h, u_min, b, ph, state, cells):
        """Resolve the overlaps at the end of a sub-step between nearest images, each pair in index
        order as the mode does, then wrap every ball into the cell."""
        n = b.pos.shape[0]
        pos = b.pos
        lx, ly = cell_lengths(ph.bounds, ph.dim)
        if ph.pairs:
            for i in range(n):
                for q in range(later_neighbours(i, n, cells)):
                    j = cells.near[q]
                    sx, sy, close = _image_shift(i, j, pos, b.radius, lx, ly)
                    if not close:
                        state.counters[PAIR_TESTS] += 1
                        continue
                    pos[j, 0] += sx
                    pos[j, 1] += sy
                    rows = state.n_imp[0]
                    if is_naive:
                        naive._resolve_pair(sc, t_end, i, j, u_min, b, ph, state)
                    else:
                        posteriori._resolve_pair(sc, t_end, h, i, j, u_min, b, ph, state)
                    pos[j, 0] -= sx
                    pos[j, 1] -= sy
                    if state.n_imp[0] > rows:
                        wrap_point(state.imp, rows, ph.bounds, ph.dim)
        wrap_all(pos, state.images[sc], ph.bounds, ph.dim)

    return resolve


#: The periodic resolver of each cheap mode.
RESOLVERS = {"naive": _resolver("naive"), "posteriori": _resolver("posteriori")}
