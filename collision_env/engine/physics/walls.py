"""The four walls of a reflecting border, by name, and where a ball meets them.

A border is ``bounds = (xmin, ymin, xmax, ymax)``. A wall is a code, an index into
:data:`WALL_NAMES`, as the impact records store it: :data:`WALL_LEFT` (``x = xmin``),
:data:`WALL_RIGHT` (``x = xmax``), :data:`WALL_BOTTOM` (``y = ymin``) and :data:`WALL_TOP`
(``y = ymax``). The left and right walls are the walls of axis 0 (x), bottom and top of axis 1; the
first wall of each axis is its low side. The kernels below are the only place that turns a code
into geometry.
"""

from __future__ import annotations

from .._jit import njit
from .tolerance import CONTACT_RTOL, contact_tolerance, coordinate_size

WALL_NAMES = ("left", "right", "bottom", "top")
"""The walls by name, as ``Impact.wall`` gives them; a raw impact record's ``wall`` code is an index
into this tuple (-1 for a ball-ball impact)."""
#: Wall codes: indices into ``WALL_NAMES``, as impact records and the kernels store them.
WALL_LEFT, WALL_RIGHT, WALL_BOTTOM, WALL_TOP = 0, 1, 2, 3


@njit(inline="always")
def wall_count(dim):
    """A scene of ``dim`` dimensions has the walls ``0 .. wall_count(dim) - 1``: left and right,
    then in 2D bottom and top."""
    return 4 if dim == 2 else 2


@njit(inline="always")
def wall_axis(wall):
    """The axis a wall stops motion along: 0 (x) for left and right, 1 (y) for bottom and top."""
    return 0 if wall < WALL_BOTTOM else 1


@njit(inline="always")
def wall_of(axis, high):
    """The wall of ``axis`` (0: x, 1: y) on its high side (right, top) or its low one (left, bottom)."""
    return (WALL_LEFT if axis == 0 else WALL_BOTTOM) + (1 if high else 0)


@njit(inline="always")
def is_low_wall(wall):
    """The wall is on its axis's low side (left or bottom): motion into it is towards -x or -y."""
    return wall == WALL_LEFT or wall == WALL_BOTTOM


@njit(inline="always")
def heads_into(wall, v):
    """A ball whose velocity along the wall's axis is ``v`` moves into the wall."""
    return v < 0.0 if is_low_wall(wall) else v > 0.0


@njit(inline="always")
def wall_line(wall, bounds):
    """The coordinate of the wall's line (x for left and right, y for bottom and top)."""
    if wall == WALL_LEFT:
        return bounds[0]
    if wall == WALL_RIGHT:
        return bounds[2]
    if wall == WALL_BOTTOM:
        return bounds[1]
    return bounds[3]


@njit(inline="always")
def wall_normal(wall):
    """The wall's outward normal (from the box into the wall)."""
    if wall == WALL_LEFT:
        return -1.0, 0.0
    if wall == WALL_RIGHT:
        return 1.0, 0.0
    if wall == WALL_BOTTOM:
        return 0.0, -1.0
    return 0.0, 1.0


@njit(refcount=False, forceinline=True)
def wall_point(i, wall, pos, bounds):
    """Where ball ``i`` touching ``wall`` touches it."""
    if wall_axis(wall) == 0:
        return wall_line(wall, bounds), pos[i, 1]
    return pos[i, 0], wall_line(wall, bounds)


@njit(refcount=False, forceinline=True)
def wall_gap(i, wall, pos, radius, bounds):
    """The gap (m) between ball ``i`` and ``wall`` (negative: past it)."""
    if wall == WALL_LEFT:
        return pos[i, 0] - radius[i] - bounds[0]
    if wall == WALL_RIGHT:
        return bounds[2] - radius[i] - pos[i, 0]
    if wall == WALL_BOTTOM:
        return pos[i, 1] - radius[i] - bounds[1]
    return bounds[3] - radius[i] - pos[i, 1]


@njit(refcount=False, forceinline=True)
def snap_to_wall(i, wall, pos, radius, bounds):
    """Put ball ``i`` exactly on the wall it touches (it is there up to round-off)."""
    if wall == WALL_LEFT:
        pos[i, 0] = bounds[0] + radius[i]
    elif wall == WALL_RIGHT:
        pos[i, 0] = bounds[2] - radius[i]
    elif wall == WALL_BOTTOM:
        pos[i, 1] = bounds[1] + radius[i]
    else:
        pos[i, 1] = bounds[3] - radius[i]


@njit(refcount=False, forceinline=True)
def wall_contact(i, wall, pos, radius, bounds):
    """Ball ``i`` touches ``wall`` within the contact tolerance (1e-9 of its diameter, or the
    round-off of its coordinates and the wall's)."""
    coord = max(coordinate_size(i, pos), abs(wall_line(wall, bounds)))
    return wall_gap(i, wall, pos, radius, bounds) <= contact_tolerance(2.0 * radius[i], coord, CONTACT_RTOL)
