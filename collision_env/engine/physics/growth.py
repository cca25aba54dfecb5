"""Growing disks (Lubachevsky & Stillinger, *J. Stat. Phys.* 60, 561 (1990)): when two disks whose
radii grow at constant speeds touch, and how they bounce so that they separate.

Disk ``i``'s radius grows at ``rdot_i``, so the contact distance of a pair, ``sigma(t) = sigma +
sigma_dot t`` with ``sigma_dot = rdot_i + rdot_j``, grows too. With ``dr = r_j - r_i`` and ``dv =
v_j - v_i``, the pair touches when ``|dr + dv t| = sigma + sigma_dot t``, a quadratic in ``t``:

    a t^2 + 2 b t + c = 0,   a = dv^2 - sigma_dot^2,   b = dr . dv - sigma sigma_dot,
                             c = dr^2 - sigma^2

(Donev, Torquato & Stillinger, *J. Comput. Phys.* 202, 737 (2005)). ``c >= 0`` apart; the
earliest root is ``t = c / (-b + sqrt(b^2 - a c))``, the stable form (no cancellation near contact),
whenever the pair closes in (``b < 0``) or the growth outruns the relative speed (``a < 0``: then
they always meet, and the root is real). ``sigma_dot = 0`` gives back ``toi.toi_pair``.

At contact the surfaces move apart at ``sigma_dot`` of their own accord, so the pair's normal
speed ``u = dv . n`` (``n`` from ``i`` to ``j``) bounces elastically about ``sigma_dot``, not about 0:
``u' = 2 sigma_dot - u``. That adds ``2 (sigma_dot - u)`` to the normal speed, shared in inverse
proportion to the masses (momentum is conserved), and leaves ``u' - sigma_dot = -(u -
sigma_dot) > 0``: the pair separates. Energy grows at each collision; the compression rescales the
velocities to hold the temperature. A wall is a disk of infinite mass that does not grow.
"""

from __future__ import annotations

import math

from .._jit import njit
from .toi import INF


@njit(forceinline=True)
def toi_growing_pair(dx, dy, dvx, dvy, sigma, sigma_dot):
    """Time until two disks ``(dx, dy)`` apart, moving apart at ``(dvx, dvy)``, with contact distance
    ``sigma`` growing at ``sigma_dot``, touch; or inf. Touching or overlapping by round-off and
    closing in means "now" (0)."""
    a = dvx * dvx + dvy * dvy - sigma_dot * sigma_dot
    b = dx * dvx + dy * dvy - sigma * sigma_dot
    if not (b < 0.0 or a < 0.0):
        return INF
    c = dx * dx + dy * dy - sigma * sigma
    if c <= 0.0:
        return 0.0
    disc = b * b - a * c
    if not disc > 0.0:
        return INF
    return c / (-b + math.sqrt(disc))


@njit(forceinline=True)
def toi_growing_wall(x, v, r, r_dot, lo, hi):
    """Time until a disk at ``x`` moving at ``v`` along an axis, its radius ``r`` growing at
    ``r_dot``, touches the wall at ``lo`` or at ``hi``: ``(t, side)``, side 0 for ``lo``, 1 for ``hi``
    (-1 and inf for no event). Each gap closes at the disk's speed towards the wall plus its growth."""
    t_lo = INF
    t_hi = INF
    closing = r_dot - v  # the gap to lo, x - r - lo, closes at this speed
    if closing > 0.0:
        t_lo = max(x - r - lo, 0.0) / closing
    closing = r_dot + v
    if closing > 0.0:
        t_hi = max(hi - r - x, 0.0) / closing
    if t_hi < t_lo:
        return t_hi, 1
    if t_lo < INF:
        return t_lo, 0
    return INF, -1


@njit(forceinline=True)
def growing_pair_impulse(u, sigma_dot, inv_mass_i, inv_mass_j):
    """The normal impulse (N s, >= 0) that bounces two disks in contact, closing at normal speed
    ``-u`` (``u = (v_j - v_i) . n``, ``n`` from ``i`` to ``j``), about the growth speed ``sigma_dot``
    of their contact distance: ``u' = 2 sigma_dot - u``, so ``J = 2 (sigma_dot - u) / (w_i + w_j)``
    with ``w`` the inverse masses. Disk ``j`` takes ``+J n``, disk ``i`` ``-J n``."""
    impulse = 2.0 * (sigma_dot - u) / (inv_mass_i + inv_mass_j)
    if not impulse > 0.0:  # (receding faster than the growth: a round-off contact, no impulse)
        return 0.0
    return impulse


@njit(forceinline=True)
def bounce_growing_wall(v, r_dot, side):
    """A disk's velocity component ``v`` normal to a wall after it bounces off it (side 0: the low
    wall, 1: the high one), its radius growing at ``r_dot``: the gap's closing speed is reversed."""
    if side == 0:
        return 2.0 * r_dot - v
    return -v - 2.0 * r_dot
