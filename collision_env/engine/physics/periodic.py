"""Periodic cells: wrapping into the cell and the minimum-image convention.

A periodic scene (``Scene(periodic=True)``) makes its bounds a cell that repeats in both axes (x
only in 1D): a ball that leaves through one side comes back through the opposite one, and two balls
interact through their nearest images (the minimum-image convention: Allen & Tildesley, *Computer
Simulation of Liquids*, 2nd ed., 2017, section 1.6.4). A ball's diameter is less than half the
cell's width and height (``validation``), so at contact the touching image is the nearest one along
each axis, and a ball never touches two images of another at once.

An axis's period ``length`` is 0 when the axis does not repeat (y in 1D): every helper then leaves
that axis alone. Positions are wrapped by floor division, so a ball that crossed the cell many times
in one step is wrapped at once, and each ball's count of crossings (its image count) is kept, so
that ``position + images * length`` is where it would be without wrapping.

Only periodic scenes compile these kernels (see the kinds of scene of exact mode and the cheap
modes' kernels): the other scenes' kernels never reference them.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from .toi import not_before, toi_pair

#: Most periods a ball may lie from the cell, along an axis: image counts up to this are exact in
#: float64 (and their sums far from int64's range), so that ``position + images * length`` holds.
MAX_IMAGES = 2**53


def periods(bounds: tuple[float, float, float, float], dim: int) -> tuple[float, float]:
    """The cell lengths ``(lx, ly)`` of a periodic scene's ``bounds`` (``ly = 0`` in 1D), computed as
    the kernels compute them (:func:`cell_lengths`)."""
    return bounds[2] - bounds[0], (bounds[3] - bounds[1]) if dim == 2 else 0.0


@njit(inline="always")
def cell_lengths(bounds, dim):
    """The periodic cell's lengths ``(lx, ly)`` from a scene's bounds (``ly = 0``: y does not repeat,
    in 1D)."""
    return bounds[2] - bounds[0], (bounds[3] - bounds[1]) if dim == 2 else 0.0


@njit(inline="always")
def nearest(d, length):
    """The separation ``d`` along an axis of period ``length``, reduced to its nearest image (within
    half a period; ``length = 0``: the axis does not repeat)."""
    if length > 0.0:
        return d - length * math.floor(d / length + 0.5)
    return d


@njit(inline="always")
def wrap_coordinate(x, lo, length):
    """``x`` wrapped into ``[lo, lo + length)`` by floor division, and how many periods it moved:
    ``(x', k)`` with ``x = x' + k * length`` up to round-off (``length = 0``: no wrapping)."""
    if not length > 0.0:
        return x, 0
    k = math.floor((x - lo) / length)
    x = x - k * length
    # (round-off of the division can leave x a hair outside the cell)
    if x >= lo + length:
        x -= length
        k += 1
    elif x < lo:
        x += length
        k -= 1
    return x, np.int64(k)


@njit(refcount=False, forceinline=True)
def wrap_all(pos, images, bounds, dim):
    """Wrap every ball of a scene into the cell (``pos``: (N, 2)), counting the periods each crossed
    in ``images`` ((N, 2) int64)."""
    lx, ly = cell_lengths(bounds, dim)
    for i in range(pos.shape[0]):
        x, kx = wrap_coordinate(pos[i, 0], bounds[0], lx)
        if kx != 0:
            pos[i, 0] = x
            images[i, 0] += kx
        if ly > 0.0:
            y, ky = wrap_coordinate(pos[i, 1], bounds[1], ly)
            if ky != 0:
                pos[i, 1] = y
                images[i, 1] += ky


@njit(refcount=False, forceinline=True)
def wrap_point(imp, row, bounds, dim):
    """Wrap the contact point of impact record ``row`` into the cell (a contact across the boundary
    is reported where it is in the cell)."""
    lx, ly = cell_lengths(bounds, dim)
    imp[row]["x"] = wrap_coordinate(imp[row]["x"], bounds[0], lx)[0]
    if ly > 0.0:
        imp[row]["y"] = wrap_coordinate(imp[row]["y"], bounds[1], ly)[0]


@njit(inline="always")
def _nearest_offset(d, length):
    """The periods (-1, 0 or 1) to add to a separation ``d`` within one period to bring it nearest."""
    return -1 if d > 0.5 * length else 1 if d < -0.5 * length else 0


@njit(refcount=False, forceinline=True)
def toi_images(dx, dy, dvx, dvy, sigma, lx, ly):
    """Time until two balls in straight-line motion, ``(dx, dy)`` apart with each inside the cell,
    touch through any of the images within one period of each other along each repeating axis (3
    along x, times 3 along y in 2D), or inf. While neither ball leaves the cell, these are the only
    images that can touch (the separation along an axis is less than a period, and contact needs
    less than half of one).

    The nearest image's time is found first: it bounds the others, which :func:`~.toi.not_before`
    then rules out without a square root (an image it passes cannot touch before that time, so the
    earliest of the nine is the same)."""
    ny = 1 if ly > 0.0 else 0
    near_x = _nearest_offset(dx, lx)
    near_y = _nearest_offset(dy, ly) if ny else 0
    best = toi_pair(dx + near_x * lx, dy + near_y * ly, dvx, dvy, sigma)
    for oy in range(-ny, ny + 1):
        for ox in range(-1, 2):
            if ox == near_x and oy == near_y:
                continue
            ex = dx + ox * lx
            ey = dy + oy * ly
            if not not_before(ex, ey, dvx, dvy, sigma, best):
                t = toi_pair(ex, ey, dvx, dvy, sigma)
                if t < best:
                    best = t
    return best


def wrap_positions(
    positions: np.ndarray, bounds: tuple[float, float, float, float], dim: int, keep: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """``(..., 2)`` positions wrapped into a periodic cell by floor division, and the periods each
    was moved by (int64, ``(..., 2)``): ``positions = wrapped + images * (lx, ly)`` up to round-off.
    Coordinates less than ``keep`` (m) outside the cell stay as they are: a step leaves balls a
    round-off past the cell's edge (they are wrapped at their next crossing), and a state read from
    a simulator goes back into one bit for bit."""
    lx, ly = periods(bounds, dim)
    out = np.array(positions, dtype=np.float64, copy=True)
    images = np.zeros(out.shape, dtype=np.int64)
    for axis, (lo, length) in enumerate(((bounds[0], lx), (bounds[1], ly))):
        if length > 0.0:
            x = out[..., axis]
            near = (x >= lo - keep) & (x < lo + length + keep)
            k = np.where(near, 0.0, np.floor((x - lo) / length))
            x = x - k * length
            # (round-off of the division can leave x a hair outside the cell)
            high = ~near & (x >= lo + length)
            low = ~near & (x < lo)
            x = np.where(high, x - length, np.where(low, x + length, x))
            k = k + high - low
            out[..., axis] = x
            images[..., axis] = k.astype(np.int64)
    return out, images
