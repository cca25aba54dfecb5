"""Time-of-impact kernels: when will two balls, or a ball and a wall, first touch?

All times are durations from "now" (relative times): callers add them to a step-local clock, so
no large absolute time ever enters a subtraction.

Ball-ball, straight-line motion (``toi_pair``), with ``dr = r_j - r_i``, ``dv = v_j - v_i`` and
``sigma = R_i + R_j``:

- ``b = dr . dv``; no event unless ``b < 0`` (approaching). Touching and receding never
  re-collides, which is what lets Newton's cradle work through exact-contact trains.
- ``c = |dr|^2 - sigma^2``; ``c <= 0`` (touching or overlapping by round-off) and approaching
  means "collide now" (Bannerman et al. 2014).
- The discriminant is formed as ``|dv|^2 sigma^2 - (dr x dv)^2`` (Lagrange's identity), which stays
  accurate far from contact where ``b^2 - a c`` cancels catastrophically.
- ``t = c / (-b + sqrt(disc))``: the sum of two positive numbers, so no cancellation near contact.

Rotating clusters (stick scenes) have no closed form; ``ca_pair`` and ``ca_wall`` use
conservative advancement (steps of gap / bound-on-closing-speed never jump past a contact), then
a sign-change bracket and bisection to machine precision once the gap is small.
"""

from __future__ import annotations

import math

from .._jit import njit
from ..layout import K_CX, K_CY, K_DX, K_DY, K_OMEGA, K_VX, K_VY
from .motion import position_at
from .tolerance import contact_tolerance
from .walls import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT, wall_axis, wall_count

INF = math.inf

#: Iteration cap for conservative advancement; a prediction that hits it is returned as a
#: "check point" that the event loop re-verifies (no collision unless the balls really touch).
CA_MAX_ITERATIONS = 2000
#: Conservative advancement stops within 1e-12 of the radii of contact, or within a quarter of the
#: contact tolerance's round-off term (``tolerance.contact_tolerance``), so that the contact it
#: finds always passes the engine's contact test.
CA_RTOL = 1e-12
_CA_ROUNDOFF_SHARE = 0.25


@njit(forceinline=True)
def toi_pair(dx, dy, dvx, dvy, sigma):
    """Time until two balls in straight-line motion touch, or inf."""
    b = dx * dvx + dy * dvy
    if not b < 0.0:
        return INF
    c = dx * dx + dy * dy - sigma * sigma
    if c <= 0.0:
        return 0.0
    a = dvx * dvx + dvy * dvy
    cross = dx * dvy - dy * dvx
    disc = a * sigma * sigma - cross * cross
    if not disc > 0.0:
        return INF  # a miss, or an exact graze (tangent: no impulse along the normal)
    return c / (-b + math.sqrt(disc))


@njit(inline="always")
def not_before(dx, dy, dvx, dvy, sigma, span):
    """Two balls apart by ``(dx, dy)``, closing at ``(dvx, dvy)``, cannot touch within ``span``
    seconds: their time of impact is at least ``c / (-2 b)`` (``b = dr . dv < 0``, ``c = |dr|^2 -
    sigma^2``: the quadratic's ``t^2`` term is never negative), with a margin far above the round-off
    of the time of impact itself. A cheap test that spares the square root and the division of
    most pairs a prediction looks at (Smallenburg 2022)."""
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    return b >= 0.0 or c * (1.0 - 1e-9) > -2.0 * b * span


@njit(inline="always")
def toi_wall_axis(x, v, r, lo, hi):
    """Time until a ball moving along one axis touches the wall it heads for, and that wall.

    Returns ``(t, side)`` with side 0 for ``lo``, 1 for ``hi``, -1 for no event. A ball already at
    or beyond the wall and still moving into it collides now.
    """
    if v > 0.0:
        gap = (hi - r) - x
        return (gap / v if gap > 0.0 else 0.0), 1
    if v < 0.0:
        gap = x - (lo + r)
        return (gap / -v if gap > 0.0 else 0.0), 0
    return INF, -1


@njit(refcount=False, forceinline=True)
def toi_wall(x, y, vx, vy, r, bounds, dim):
    """First wall a ball in straight-line motion touches: ``(t, wall)``, a wall code
    (:mod:`~collision_env.engine.physics.walls`) or -1. On an exact tie (a corner) the x wall comes
    first; the y wall then follows at the same instant, so both components flip.
    """
    t, side = toi_wall_axis(x, vx, r, bounds[0], bounds[2])
    wall = WALL_LEFT + side if side >= 0 else -1
    if dim == 2:
        ty, sy = toi_wall_axis(y, vy, r, bounds[1], bounds[3])
        if ty < t:
            t = ty
            wall = WALL_BOTTOM + sy
    return t, wall


@njit(inline="always")
def _rigid(k):
    """The kinematics ``k`` (``layout.KINEMATICS``) as ``motion.position_at`` takes them."""
    return k[K_CX], k[K_CY], k[K_VX], k[K_VY], k[K_DX], k[K_DY], k[K_OMEGA]


@njit(inline="always")
def _pair_gap(tau, ki, kj, sigma):
    xi, yi, vxi, vyi = position_at(tau, *_rigid(ki))
    xj, yj, vxj, vyj = position_at(tau, *_rigid(kj))
    rx = xj - xi
    ry = yj - yi
    dist = math.sqrt(rx * rx + ry * ry)
    rate = (rx * (vxj - vxi) + ry * (vyj - vyi)) / dist if dist > 0.0 else -1.0
    return dist - sigma, rate


@njit(inline="always")
def _wall_gap(tau, k, r, wall, bounds):
    x, y, vx, vy = position_at(tau, *_rigid(k))
    if wall == WALL_LEFT:
        return (x - r) - bounds[0], vx
    if wall == WALL_RIGHT:
        return (bounds[2] - r) - x, -vx
    if wall == WALL_BOTTOM:
        return (y - r) - bounds[1], vy
    return (bounds[3] - r) - y, -vy


@njit(refcount=False, python=False)
def _ca_solve(is_pair, ki, kj, sigma, wall, bounds, bound_speed, horizon, tol):
    """Conservative advancement on a gap function ``g(tau)`` with ``|g'| <= bound_speed``.

    Returns the first ``tau`` in [0, horizon] where ``g <= tol`` and the gap closes, or inf.
    """
    if bound_speed <= 0.0:
        return INF
    tau = 0.0
    for _ in range(CA_MAX_ITERATIONS):
        if is_pair:
            g, rate = _pair_gap(tau, ki, kj, sigma)
        else:
            g, rate = _wall_gap(tau, ki, sigma, wall, bounds)
        if g <= tol:
            if rate < 0.0:
                return tau
            tau += tol / bound_speed  # touching but opening: step off the contact
        else:
            if rate < 0.0 and g < 1e-3 * (sigma + tol):
                # Close and closing: a Newton step usually lands just past contact; a sign change
                # brackets the first root (CA proved there is none before tau), bisect it.
                hi = tau - g / rate
                if hi <= horizon:
                    if is_pair:
                        g_hi, _ = _pair_gap(hi, ki, kj, sigma)
                    else:
                        g_hi, _ = _wall_gap(hi, ki, sigma, wall, bounds)
                    if g_hi < 0.0:
                        lo = tau
                        for _ in range(100):
                            mid = 0.5 * (lo + hi)
                            if mid <= lo or mid >= hi:
                                break
                            if is_pair:
                                g_mid, _ = _pair_gap(mid, ki, kj, sigma)
                            else:
                                g_mid, _ = _wall_gap(mid, ki, sigma, wall, bounds)
                            if g_mid < 0.0:
                                hi = mid
                            else:
                                lo = mid
                                if g_mid <= tol:
                                    break
                        return lo
            tau += g / bound_speed
        if tau > horizon:
            return INF
    return tau


@njit(refcount=False, python=False)
def ca_pair(ki, kj, sigma, horizon):
    """Time until two balls, either of them in a rotating cluster, touch (or inf).

    ``ki``/``kj`` are the balls' kinematics (``layout.KINEMATICS``, from :func:`motion.body_kinematics`).
    """
    rel = math.hypot(ki[K_VX] - kj[K_VX], ki[K_VY] - kj[K_VY])
    arm_i = math.hypot(ki[K_DX], ki[K_DY])
    arm_j = math.hypot(kj[K_DX], kj[K_DY])
    bound = rel + abs(ki[K_OMEGA]) * arm_i + abs(kj[K_OMEGA]) * arm_j
    coord = max(abs(ki[K_CX]), abs(ki[K_CY]), abs(kj[K_CX]), abs(kj[K_CY])) + arm_i + arm_j
    tol = _CA_ROUNDOFF_SHARE * contact_tolerance(sigma, coord, CA_RTOL)
    return _ca_solve(True, ki, kj, sigma, -1, ki, bound, horizon, tol)


@njit(refcount=False, python=False)
def ca_wall(k, r, bounds, dim, horizon):
    """First wall a ball of a rotating cluster touches (``k``: its kinematics): ``(t, wall)``."""
    best = INF
    best_wall = -1
    arm = math.hypot(k[K_DX], k[K_DY])
    spin = abs(k[K_OMEGA]) * arm
    coord = max(abs(k[K_CX]), abs(k[K_CY]), abs(bounds[0]), abs(bounds[1]), abs(bounds[2]), abs(bounds[3]))
    tol = _CA_ROUNDOFF_SHARE * contact_tolerance(r, coord + arm, CA_RTOL)
    for wall in range(wall_count(dim)):
        normal_speed = abs(k[K_VX]) if wall_axis(wall) == 0 else abs(k[K_VY])
        t = _ca_solve(False, k, k, r, wall, bounds, normal_speed + spin, min(horizon, best), tol)
        if t < best:
            best = t
            best_wall = wall
    return best, best_wall
