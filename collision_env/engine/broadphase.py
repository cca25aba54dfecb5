"""The broad phase every mode shares: a uniform grid of cells over the scene, so that a ball meets
only its neighbours.

Cells are at least one largest ball diameter wide, so two balls that touch are always in the same
or adjacent cells, and a ball's neighbours are in the 3 x 3 block of cells around it (Rapaport
1980; Isobe 1999; Smallenburg 2022). Cells are numbered ``cy * nx + cx``. The grid covers the
border, or, without one, the box around the balls' starting positions; the outermost cells reach
to infinity (positions are clamped), so a ball far outside still has a cell and the neighbour rule
still holds. There are at most a few cells per ball, so the grid costs O(N) memory.

The grid is used only where it pays (the model-only-what-is-needed rule): with fewer than
:data:`GRID_MIN_BALLS` balls (:data:`PERIODIC_GRID_MIN_BALLS` in a periodic cell), in stick
scenes, or when ball pairs are not modelled, the grid has one cell and the neighbours of a ball are
all the others. How each mode keeps its balls in cells
is its own: exact mode's lists follow cell-crossing events (:mod:`~collision_env.engine.exact.grid`),
the cheap modes rebuild theirs at every sub-step (:mod:`~collision_env.engine.stepped.cells`).
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import njit
from .physics.tolerance import CONTACT_RTOL, balls_touch, contact_tolerance, coordinate_size, roundoff
from .physics.walls import wall_contact, wall_count, wall_of

#: Scenes with fewer balls keep one cell (every ball is every other's neighbour): below this size
#: the grid's bookkeeping costs more than the pairs it saves (measured by the engine benchmark).
GRID_MIN_BALLS = 64
#: The same for a periodic cell, where one cell means looking at each pair's nine images: the grid
#: pays from two balls on (a 50-disk gas at phi = 0.3: 8.9 us per event in one cell, 0.63 on the grid).
PERIODIC_GRID_MIN_BALLS = 2
#: Balls per cell exact mode's grid aims at, and the most cells it has per ball (cells are never
#: narrower than a diameter): fewer cells cost more pair predictions per event, more cells more
#: cell crossings (measured by the scale benchmark).
EXACT_BALLS_PER_CELL = 0.3
EXACT_CELLS_PER_BALL = 4
#: The cheap modes' grid: cells at least two diameters wide, up to this many per ball.
CHEAP_CELLS_PER_BALL = 4
#: Cells are this much wider than the largest diameter, so that round-off in a ball's position at
#: a cell boundary can never hide a neighbour.
CELL_MARGIN = 1.0 + 1e-6


def grid_geometry(
    bounds: tuple[float, float, float, float] | None,
    positions: np.ndarray,
    radii: np.ndarray,
    use_grid: bool | np.ndarray,
    reach: float = 1.0,
    balls_per_cell: float = 1.0,
    cells_per_ball: float = 1,
    period: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Per-scene grid ``(x0, y0, hx, hy)`` and ``(nx, ny)`` for ``(B, N, 2)`` positions and
    ``(B, N)`` radii; scenes with ``use_grid`` False get a single cell. The cells are at least
    ``reach * CELL_MARGIN`` largest diameters wide, hold about ``balls_per_cell`` balls each, and
    number at most ``cells_per_ball`` per ball. The cheap modes use ``reach = 2``: their grid is
    built before a sub-step's overlaps are pushed apart, and a pushed ball must still find the
    balls it now overlaps. Exact mode uses :data:`EXACT_BALLS_PER_CELL` and
    :data:`EXACT_CELLS_PER_BALL`.

    ``period``: a periodic scene's cell lengths ``(lx, ly)`` (``ly = 0`` in 1D). The grid then wraps:
    its cells tile the periodic cell exactly, at least 3 along each repeating axis or else 1 (the
    periodic cell's own length, so that a ball crossing it is seen), and one row along y in 1D."""
    n_scenes, n = radii.shape
    if bounds is not None:  # (the same for every scene: broadcast)
        lo = np.array(bounds[:2], dtype=np.float64)
        hi = np.array(bounds[2:], dtype=np.float64)
    else:
        r = radii[..., None]
        lo = (positions - r).min(axis=1)
        hi = (positions + r).max(axis=1)
    if not use_grid and period is None:  # one cell, with no boundary (a small scene: the common reset)
        cells = np.full((n_scenes, 4), np.inf)
        cells[:, :2] = lo
        return cells, np.ones((n_scenes, 2), dtype=np.int64)
    lo = np.broadcast_to(lo, (n_scenes, 2))
    size = hi - lo
    sigma = 2.0 * reach * radii.max(axis=1) * CELL_MARGIN
    # about one ball per cell, but never narrower than a diameter
    width = np.maximum(sigma, np.sqrt(balls_per_cell * size[:, 0] * size[:, 1] / n))
    most = cells_per_ball * n
    counts = np.ones((n_scenes, 2), dtype=np.int64)
    if use_grid:
        for axis in range(2):
            c = np.floor(size[:, axis] / width)
            counts[:, axis] = np.clip(np.nan_to_num(c, nan=1.0, posinf=1.0), 1, most).astype(np.int64)
        # a thin box: cells along its long axis alone
        while np.any(counts[:, 0] * counts[:, 1] > most):
            over = counts[:, 0] * counts[:, 1] > most
            big = np.argmax(counts, axis=1)
            counts[over, big[over]] -= 1
    if period is not None:
        counts[counts < 3] = 1  # (the 3 x 3 cells around a ball are then distinct)
        if period[1] == 0.0:
            counts[:, 1] = 1
        repeats = np.array(period) > 0.0
        cell = np.where(repeats | (counts > 1), size / counts, np.inf)
        return np.concatenate([lo, cell], axis=1), counts
    cell = np.where(counts > 1, size / counts, np.inf)  # one cell along an axis: no boundary there
    return np.concatenate([lo, cell], axis=1), counts


@njit(inline="always")
def _axis_cell(x, x0, h, n_cells):
    f = (x - x0) / h
    if not f > 0.0:  # (also the one-cell case, h = inf)
        return 0
    if f >= n_cells:
        return n_cells - 1
    return int(f)


@njit(forceinline=True)
def cell_of(x, y, x0, y0, hx, hy, nx, ny):
    """The cell holding point ``(x, y)`` (clamped into the grid)."""
    return _axis_cell(y, y0, hy, ny) * nx + _axis_cell(x, x0, hx, nx)


@njit(forceinline=True)
def block(c, nx, ny):
    """The 3 x 3 block of cells around cell ``c``: ``(cx0, cx1, cy0, cy1)``, inclusive."""
    cx = c % nx
    cy = c // nx
    return max(cx - 1, 0), min(cx + 1, nx - 1), max(cy - 1, 0), min(cy + 1, ny - 1)


@njit(inline="always")
def _link_cells(pos, x0, y0, hx, hy, nx, ny):
    """Each ball's cell, and per cell a linked list of its balls in index order (``head``, ``nxt``)."""
    n = pos.shape[0]
    head = np.full(nx * ny, -1, dtype=np.int64)
    nxt = np.empty(n, dtype=np.int64)
    cell = np.empty(n, dtype=np.int64)
    for i in range(n - 1, -1, -1):
        c = cell_of(pos[i, 0], pos[i, 1], x0, y0, hx, hy, nx, ny)
        cell[i] = c
        nxt[i] = head[c]
        head[c] = i
    return head, nxt, cell


@njit
def _ball_cells(pos, radius):
    """Cell lists of the balls on a grid of their box, cells one largest diameter wide (with the
    margin): ``(head, nxt, cell, nx, ny)``, each cell's balls in index order."""
    n = pos.shape[0]
    x0 = pos[0, 0]
    y0 = pos[0, 1]
    x1 = x0
    y1 = y0
    r_max = 0.0
    for i in range(n):
        x0 = min(x0, pos[i, 0])
        x1 = max(x1, pos[i, 0])
        y0 = min(y0, pos[i, 1])
        y1 = max(y1, pos[i, 1])
        r_max = max(r_max, radius[i])
    h = 2.0 * r_max * CELL_MARGIN
    nx = min(max(int((x1 - x0) / h), 1), n)
    ny = min(max(int((y1 - y0) / h), 1), max(n // nx, 1))
    hx = (x1 - x0) / nx if nx > 1 else math.inf
    hy = (y1 - y0) / ny if ny > 1 else math.inf
    hx = max(hx, h)
    hy = max(hy, h)
    head, nxt, cell = _link_cells(pos, x0, y0, hx, hy, nx, ny)
    return head, nxt, cell, nx, ny


@njit(inline="always")
def _overlap(i, j, dx, dy, pos, radius, rtol):
    """Balls ``i`` and ``j``, ``(dx, dy)`` apart, overlap by more than the contact tolerance: ``rtol``
    of their radii sum, or the round-off of their coordinates (the engine leaves touching balls a
    few ulps apart either way: far from the origin an ulp can be more than ``rtol`` of the radii)."""
    coord = max(coordinate_size(i, pos), coordinate_size(j, pos))
    sigma = radius[i] + radius[j]
    return math.sqrt(dx * dx + dy * dy) < sigma - contact_tolerance(sigma, coord, rtol)


@njit
def first_overlap(pos, radius, rtol):
    """The first pair ``(i, j)``, ``i < j`` in lexicographic order, whose disks overlap by more than
    the contact tolerance (``rtol`` of their radii sum, or the round-off of their coordinates), or
    ``(-1, -1)``; O(N) expected time on a grid of the balls' box."""
    n = pos.shape[0]
    if n < 2:
        return -1, -1
    head, nxt, cell, nx, ny = _ball_cells(pos, radius)
    best_i = -1
    best_j = -1
    for i in range(n):
        cx0, cx1, cy0, cy1 = block(cell[i], nx, ny)
        for cy in range(cy0, cy1 + 1):
            for cx in range(cx0, cx1 + 1):
                j = head[cy * nx + cx]
                while j >= 0:
                    if j > i:
                        dx = pos[j, 0] - pos[i, 0]
                        dy = pos[j, 1] - pos[i, 1]
                        if _overlap(i, j, dx, dy, pos, radius, rtol):
                            if best_i < 0 or j < best_j:
                                best_i = i
                                best_j = j
                    j = nxt[j]
        if best_i >= 0:
            return best_i, best_j
    return -1, -1


@njit(inline="always")
def _root(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]  # (path halving)
        i = parent[i]
    return i


@njit
def spans_walls(pos, radius, extent, bounds, dim):
    """Which of the ``(K, N, 2)`` scenes have balls near both walls along an axis, within twice the
    contact tolerance of the radii and of ``extent`` (``(K,)``, each scene's coordinate magnitude):
    the only scenes :func:`wall_to_wall` can find a network in (this test is looser than its contact
    test, so it never skips one). One compiled pass, as it runs at every start-state check."""
    k, n = radius.shape
    out = np.zeros(k, dtype=np.bool_)
    for sc in range(k):
        for axis in range(dim):
            low = high = False
            for i in range(n):
                near = CONTACT_RTOL * 2.0 * radius[sc, i] + 2.0 * roundoff(extent[sc])
                low |= pos[sc, i, axis] - radius[sc, i] - bounds[axis] <= near
                high |= bounds[axis + 2] - radius[sc, i] - pos[sc, i, axis] <= near
            out[sc] |= low and high
    return out


@njit
def wall_to_wall(pos, radius, bounds, dim, pairs):
    """A network of touching balls that reaches from a wall to the opposite one, or ``(-1, -1, 0)``.

    Balls touch each other and the walls within the engine's contact tolerance (``balls_touch``,
    ``wall_contact``: 1e-9 of the radii, or the round-off of the coordinates), as the event loop
    judges contact; ``pairs`` False: each ball is a network of its own. Returns ``(ball, axis,
    size)``: the lowest-numbered ball of the first such network, the axis along which it spans the
    box (0: x, left to right; 1: y, bottom to top) and how many balls it has. Such a network is
    jammed between the walls (a straight row, or a square lattice, has no velocity along that axis
    that closes none of its contacts), which resolving its impacts one pair at a time never gets
    through. O(N) expected time (union-find over the contacts of a cell grid).
    """
    n = pos.shape[0]
    parent = np.arange(n)
    if pairs and n > 1:
        head, nxt, cell, nx, ny = _ball_cells(pos, radius)
        for i in range(n):
            cx0, cx1, cy0, cy1 = block(cell[i], nx, ny)
            for cy in range(cy0, cy1 + 1):
                for cx in range(cx0, cx1 + 1):
                    j = head[cy * nx + cx]
                    while j >= 0:
                        if j > i and balls_touch(i, j, pos, radius):
                            a = _root(parent, i)
                            b = _root(parent, j)
                            if a != b:
                                parent[max(a, b)] = min(a, b)
                        j = nxt[j]
    walls = np.zeros(n, dtype=np.int64)  # per root: a bit per wall its network touches
    size = np.zeros(n, dtype=np.int64)
    for i in range(n):
        a = _root(parent, i)
        size[a] += 1
        for wall in range(wall_count(dim)):
            if wall_contact(i, wall, pos, radius, bounds):
                walls[a] |= 1 << wall
    for i in range(n):
        a = _root(parent, i)
        for axis in range(dim):
            both = (1 << wall_of(axis, False)) | (1 << wall_of(axis, True))
            if walls[a] & both == both:
                return a, axis, size[a]
    return -1, -1, 0


@njit
def first_overlap_periodic(pos, radius, rtol, x0, y0, lx, ly):
    """:func:`first_overlap` in a periodic cell of lengths ``lx``, ``ly`` (``ly = 0``: y does not
    repeat) starting at ``(x0, y0)``, for positions inside it: pairs are measured between nearest
    images, on a grid that wraps (at least 3 cells along a repeating axis, or one)."""
    n = pos.shape[0]
    if n < 2:
        return -1, -1
    r_max = 0.0
    for i in range(n):
        r_max = max(r_max, radius[i])
    h = 2.0 * r_max * CELL_MARGIN
    nx = min(max(int(lx / h), 1), n)
    ny = min(max(int(ly / h), 1), max(n // nx, 1)) if ly > 0.0 else 1
    nx = nx if nx >= 3 else 1
    ny = ny if ny >= 3 else 1
    hx = lx / nx
    hy = ly / ny if ly > 0.0 else math.inf
    head, nxt, cell = _link_cells(pos, x0, y0, hx, hy, nx, ny)
    reach_x = 1 if nx >= 3 else 0
    reach_y = 1 if ny >= 3 else 0
    best_j = -1
    for i in range(n):
        cx = cell[i] % nx
        cy = cell[i] // nx
        for oy in range(-reach_y, reach_y + 1):
            for ox in range(-reach_x, reach_x + 1):
                j = head[((cy + oy) % ny) * nx + (cx + ox) % nx]
                while j >= 0:
                    if j > i:
                        dx = pos[j, 0] - pos[i, 0]
                        dx -= lx * math.floor(dx / lx + 0.5)
                        dy = pos[j, 1] - pos[i, 1]
                        if ly > 0.0:
                            dy -= ly * math.floor(dy / ly + 0.5)
                        if _overlap(i, j, dx, dy, pos, radius, rtol):
                            if best_j < 0 or j < best_j:
                                best_j = j
                    j = nxt[j]
        if best_j >= 0:
            return i, best_j
    return -1, -1
