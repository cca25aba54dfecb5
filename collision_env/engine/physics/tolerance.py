"""How close counts as touching: contact tolerances from the local geometry.

A gap is "zero" when it is within a small fraction of the size of the features involved (the
radii) or within the round-off of the coordinates it is computed from, whichever is larger. The
round-off term is the resolution of float64 at those coordinates (a few units in the last place):
no gap can be resolved more finely than that, wherever the scene is. Neither term grows with
the distance from the origin beyond that resolution: 1e6 m away, a 0.1 m ball's contact tolerance
is ~2e-9 m (eight units in the last place of 1e6), where a tolerance relative to ``|x| + |y|`` would
be a millimetre.
"""

from __future__ import annotations

import math

from .._jit import njit

#: Contact tolerance relative to the feature size (radii, diameters).
CONTACT_RTOL = 1e-9
#: Units in the last place of the coordinates that a computed gap may be off by.
ROUNDOFF_ULPS = 8.0
#: float64 machine epsilon (the spacing of float64 numbers relative to their size).
EPS = 2.0**-52
#: :func:`touching_at` calls two balls apart, without a square root, when their squared distance
#: exceeds ``(sigma + tol)^2`` by this factor: the round-off of the square, of the square root and of
#: the gap (a few ``EPS``) is far below the margin, so the full test would say the same.
SQUARED_MARGIN = 1.0 + 2.0**-20
#: ... where ``sigma + tol`` exceeds this (m), so that its square is a normal float64, whose round-off
#: is relative (a subnormal square's is not).
SQUARED_FLOOR = 1e-150


@njit
def roundoff(coord):
    """The round-off (m) of a gap computed from coordinates of magnitude up to ``coord``."""
    return ROUNDOFF_ULPS * EPS * coord


@njit
def contact_tolerance(length, coord, rtol):
    """Largest gap (m) that counts as contact between features of size ``length`` (m), computed
    from coordinates of magnitude up to ``coord`` (m): ``rtol * length`` or the round-off."""
    return max(rtol * length, roundoff(coord))


@njit(inline="always")
def coordinate_size(i, pos):
    """Magnitude of ball ``i``'s coordinates (what the round-off of its gaps is relative to)."""
    return max(abs(pos[i, 0]), abs(pos[i, 1]))


@njit(refcount=False, forceinline=True)
def balls_touch(a, k, pos, radius):
    """Balls ``a`` and ``k`` touch within the contact tolerance (:func:`contact_tolerance`: 1e-9 of
    the radii, or the round-off of their coordinates)."""
    return touching_at(a, k, pos[k, 0] - pos[a, 0], pos[k, 1] - pos[a, 1], pos, radius)


@njit(refcount=False, forceinline=True)
def touching_at(a, k, dx, dy, pos, radius):
    """:func:`balls_touch` for balls whose centres are ``(dx, dy)`` apart (``k``'s from ``a``'s: in
    a periodic cell, through the nearest image)."""
    sigma = radius[a] + radius[k]
    tol = contact_tolerance(sigma, max(coordinate_size(a, pos), coordinate_size(k, pos)), CONTACT_RTOL)
    d2 = dx * dx + dy * dy
    reach = sigma + tol
    # (most balls looked at are clearly out of reach: their squared distance says so without the
    # square root, and gives the same verdict, see SQUARED_MARGIN)
    if reach > SQUARED_FLOOR and d2 > reach * reach * SQUARED_MARGIN:
        return False
    return math.sqrt(d2) - sigma <= tol
