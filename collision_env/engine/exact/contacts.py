"""Contact groups: an impact inside a group of touching balls, resolved at one instant (e < 1).

At e < 1 an impact inside a touching group (a train pressed against a wall, a crowd) starts a
cascade of ever smaller impulses at the same instant: sequential impulses converge to the limit
geometrically. :func:`cascade` runs that cascade here, without re-predicting every ball after each
impulse: it gathers the group (every ball connected to the impact through contacts, gaps within
the contact tolerance of zero), lists its contacts in a fixed order and sweeps over them, applying
the same pairwise impulses as the event loop would, one after another; the collapse regulariser
(:mod:`~collision_env.engine.physics.response`) ends it. A cascade still running after
:data:`MAX_SWEEPS` sweeps (its convergence rate is set by a mass ratio) is replaced by its limit
(:func:`settle`). Every contact that takes an impulse is reported once.

Only scenes at e < 1 compile this module's kernels (see the scheduler's kinds of scene).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from ..layout import EVENTS
from ..physics.impacts import record
from ..physics.ldp import least_distance
from ..physics.response import ball_ball, ball_wall, group_threshold, normal_impulse
from ..physics.tolerance import balls_touch
from ..physics.walls import wall_contact, wall_count, wall_normal, wall_point

#: Sweeps over a contact group in one instant before the cascade is replaced by its limit (see
#: :func:`settle`). Cascades among comparable masses end within a few dozen sweeps; the criterion
#: is a count, so it does not depend on the masses, and the limit always ends the cascade.
MAX_SWEEPS = 1000


def contact_capacity(n: int) -> int:
    """Most contacts a contact group of ``n`` balls can have: the contact graph of disks that do not
    overlap is planar (at most 3n - 6 edges), and a ball touches at most two walls (four in a box
    no wider than the ball)."""
    return 3 * n + 4 * n + 8


@njit(refcount=False, python=False)
def cascade(sc, t_abs, i0, j0, b, ph, wk):
    """Resolve, at one instant, every contact of the group of touching balls an impact started.

    The impact was between ball ``i0`` and ball ``j0``, or the wall ``-1 - j0`` when ``j0 < 0``;
    the caller has applied and reported it, so that contact is not reported again here (one
    collision, one report, even when round-off leaves it closing at ~1e-16 m/s after a plastic
    impulse). The group's regulariser speed comes from its own balls when it is formed
    (``response.group_threshold`` of the collapse ratio and floor). ``b`` is the whole ball state
    of the scene. Returns the group size; its balls are listed in ``wk.pending``.
    """
    size = _gather_group(i0, j0, b.pos, b.radius, ph.pairs, wk.pending, wk.in_group)
    n_contacts = _list_contacts(i0, j0, size, b, ph, wk)
    u_min = group_threshold(wk.pending, size, b.vel, b.inv_mass, ph.ratio, ph.floor)
    if not _sweep(sc, t_abs, n_contacts, u_min, b, ph, wk):
        settle(sc, t_abs, size, n_contacts, u_min, b, ph, wk)
    return size


@njit(inline="always")
def _gather_group(i0, j0, pos, radius, pairs, group, in_group):
    """Every ball connected to the impact's balls through contacts, into ``group``, breadth first;
    returns how many."""
    n = pos.shape[0]
    for k in range(n):
        in_group[k] = False
    size = 0
    for start in (i0, j0):  # j0 < 0: a wall
        if start >= 0 and not in_group[start]:
            group[size] = start
            in_group[start] = True
            size += 1
    q = 0
    while q < size and pairs:
        a = group[q]
        q += 1
        for k in range(n):
            if not in_group[k] and balls_touch(a, k, pos, radius):
                group[size] = k
                in_group[k] = True
                size += 1
    return size


@njit(inline="always")
def _list_contacts(i0, j0, size, b, ph, wk):
    """The group's contacts, each once, in a fixed order (``wk.c_a``, ``wk.c_b``; ``wk.c_hit`` marks
    the impact's own); returns how many."""
    group = wk.pending
    n_contacts = 0
    for qa in range(size):
        a = group[qa]
        if ph.pairs:
            for qb in range(qa + 1, size):
                k = group[qb]
                if balls_touch(a, k, b.pos, b.radius):
                    wk.c_a[n_contacts] = min(a, k)
                    wk.c_b[n_contacts] = max(a, k)
                    wk.c_hit[n_contacts] = j0 >= 0 and min(a, k) == min(i0, j0) and max(a, k) == max(i0, j0)
                    n_contacts += 1
        if ph.has_walls:
            for wall in range(wall_count(ph.dim)):
                if wall_contact(a, wall, b.pos, b.radius, ph.bounds):
                    wk.c_a[n_contacts] = a
                    wk.c_b[n_contacts] = -1 - wall
                    wk.c_hit[n_contacts] = a == i0 and j0 == -1 - wall
                    n_contacts += 1
    return n_contacts


@njit(inline="always")
def _sweep(sc, t_abs, n_contacts, u_min, b, ph, wk):
    """Sweep the contacts, applying each one's impulse, until a sweep changes nothing (True) or
    :data:`MAX_SWEEPS` sweeps have (False)."""
    for _ in range(MAX_SWEEPS):
        changed = False
        for c in range(n_contacts):
            a = wk.c_a[c]
            other = wk.c_b[c]
            if other >= 0:
                speed = ball_ball(a, other, b.pos, b.vel, b.inv_mass, ph.e, u_min)
            else:
                speed = ball_wall(a, -1 - other, b.vel, ph.e, u_min)
            if speed > 0.0:
                changed = True
                wk.counters[EVENTS] += 1
                w = _contact_inv_mass(c, wk.c_a, wk.c_b, b.inv_mass)
                _record_contact(sc, t_abs, c, speed, normal_impulse(speed, ph.e, u_min, w), b, ph, wk)
        if not changed:
            return True
    return False


@njit(inline="always")
def _contact_normal(c, c_a, c_b, pos):
    """Unit normal of contact ``c``, pointing from ball ``c_a[c]`` to its partner (ball or wall)."""
    a = c_a[c]
    other = c_b[c]
    if other >= 0:
        dx = pos[other, 0] - pos[a, 0]
        dy = pos[other, 1] - pos[a, 1]
        d = math.sqrt(dx * dx + dy * dy)
        return dx / d, dy / d
    return wall_normal(-1 - other)


@njit(inline="always")
def _contact_inv_mass(c, c_a, c_b, inv_mass):
    """``w_a + w_b`` of contact ``c`` (``w_a`` alone for a wall)."""
    other = c_b[c]
    return inv_mass[c_a[c]] + (inv_mass[other] if other >= 0 else 0.0)


@njit(inline="always")
def _record_contact(sc, t_abs, c, speed, impulse, b, ph, wk):
    """Report contact ``c`` of a group the first time it takes an impulse, with that impulse's
    closing speed and normal impulse (N s)."""
    if wk.c_hit[c]:
        return
    wk.c_hit[c] = True
    a = wk.c_a[c]
    other = wk.c_b[c]
    pos, radius = b.pos, b.radius
    if other >= 0:
        nx, ny = _contact_normal(c, wk.c_a, wk.c_b, pos)
        x = pos[a, 0] + radius[a] * nx
        y = pos[a, 1] + radius[a] * ny
        record(wk.imp, wk.n_imp, sc, t_abs, a, other, -1, x, y, speed, impulse)
    else:
        x, y = wall_point(a, -1 - other, pos, ph.bounds)
        record(wk.imp, wk.n_imp, sc, t_abs, a, -1, -1 - other, x, y, speed, impulse)


@njit(python=False)
def settle(sc, t_abs, size, n_contacts, u_min, b, ph, wk):
    """End a contact cascade that sequential impulses would need unboundedly many sweeps for.

    With e < 1 a cascade that does not stop converges: each impulse dissipates a fixed fraction of
    its contact's closing energy, so the contacts that keep firing close ever more slowly, and in
    the limit the group moves with every contact at rest or separating. A light ball pressed
    between a wall and a ball ``M/m`` times heavier gets there only after about ``M/m`` sweeps.
    This jumps to that limit, regularised as everywhere else: the velocities closest to the
    current ones in the kinetic-energy metric at which every contact of the group separates at
    ``u_min`` or faster (a least-distance problem in mass-weighted velocities, solved by
    ``ldp.least_distance`` whatever the mass ratio). Momentum is conserved by ball-ball impulses
    and energy does not grow by more than the regulariser's ``u_min`` allowance. Where no
    velocities separate every contact (a chain wedged between opposite walls), the contacts are
    brought to rest instead, which is always possible. The result is checked: should round-off
    still leave a contact closing, the group takes its centre-of-mass velocity (no wall among its
    contacts) or stops (a wall among them), which ends the cascade in every case.
    """
    group, c_a, c_b, pos, vel = wk.pending, wk.c_a, wk.c_b, b.pos, b.vel
    dof = 2 * size
    g_mat = np.zeros((n_contacts, dof))
    h = np.empty(n_contacts)
    slot = np.full(pos.shape[0], -1, dtype=np.int64)
    root_w = np.empty(size)
    for q in range(size):
        slot[group[q]] = q
        root_w[q] = math.sqrt(b.inv_mass[group[q]])
    closing = np.empty(n_contacts)
    fastest = 0.0
    for c in range(n_contacts):
        a = c_a[c]
        other = c_b[c]
        nx, ny = _contact_normal(c, c_a, c_b, pos)
        # separation speed of the contact = G_c . y with y = sqrt(m) v (mass-weighted velocities)
        qa = slot[a]
        g_mat[c, 2 * qa] = -nx * root_w[qa]
        g_mat[c, 2 * qa + 1] = -ny * root_w[qa]
        sep = -(vel[a, 0] * nx + vel[a, 1] * ny)
        if other >= 0:
            qb = slot[other]
            g_mat[c, 2 * qb] = nx * root_w[qb]
            g_mat[c, 2 * qb + 1] = ny * root_w[qb]
            sep += vel[other, 0] * nx + vel[other, 1] * ny
        closing[c] = -sep
        fastest = max(fastest, abs(sep))
        h[c] = u_min - sep
    x, feasible = least_distance(g_mat, h)
    if not feasible:
        for c in range(n_contacts):
            h[c] -= u_min
        x, feasible = least_distance(g_mat, h)
    for q in range(size):
        i = group[q]
        vel[i, 0] += x[2 * q] * root_w[q]
        vel[i, 1] += x[2 * q + 1] * root_w[q]
    if not _contacts_open(vel, pos, c_a, c_b, n_contacts, 16.0 * 2.0**-52 * fastest):
        _stop_group(vel, b.inv_mass, group, size, c_b, n_contacts)
    for c in range(n_contacts):
        if closing[c] > 0.0:
            wk.counters[EVENTS] += 1
            # (the two-body impulse from the contact's closing speed and its separation speed in the limit)
            sep = _separation(c, c_a, c_b, pos, vel)
            impulse = (closing[c] + sep) / _contact_inv_mass(c, c_a, c_b, b.inv_mass)
            _record_contact(sc, t_abs, c, closing[c], impulse, b, ph, wk)


@njit(inline="always")
def _separation(c, c_a, c_b, pos, vel):
    """The normal speed at which contact ``c`` separates (m/s; negative: it closes)."""
    a = c_a[c]
    other = c_b[c]
    nx, ny = _contact_normal(c, c_a, c_b, pos)
    sep = -(vel[a, 0] * nx + vel[a, 1] * ny)
    if other >= 0:
        sep += vel[other, 0] * nx + vel[other, 1] * ny
    return sep


@njit(inline="always")
def _contacts_open(vel, pos, c_a, c_b, n_contacts, slack):
    """No contact of the group closes faster than ``slack`` (m/s)."""
    for c in range(n_contacts):
        if _separation(c, c_a, c_b, pos, vel) < -slack:
            return False
    return True


@njit(inline="always")
def _stop_group(vel, inv_mass, group, size, c_b, n_contacts):
    """The last resort of :func:`settle`: every contact at rest, at once."""
    on_wall = False
    for c in range(n_contacts):
        on_wall = on_wall or c_b[c] < 0
    mass = 0.0
    px = 0.0
    py = 0.0
    for q in range(size):
        i = group[q]
        m = 1.0 / inv_mass[i]
        mass += m
        px += m * vel[i, 0]
        py += m * vel[i, 1]
    vx = 0.0 if on_wall else px / mass
    vy = 0.0 if on_wall else py / mass
    for q in range(size):
        i = group[q]
        vel[i, 0] = vx
        vel[i, 1] = vy
