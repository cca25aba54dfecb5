"""Exact mode: a-priori, event-driven stepping to machine precision at any dt.

Per scene and step: predict every ball's wall time and every pair's time of impact, then repeat
"advance everything to the earliest event, resolve it, re-predict only the balls it changed"
until the step ends. Pair predictions live in an N x N table of step-local times with cached
per-row minima, so finding the next event is O(N) and an event re-predicts O(N) pairs per ball
it changed.

Determinism: ties are broken by index (walls before pairs for the same ball, then the lowest
ball index, then the lowest partner index). Simultaneous events are therefore resolved one after
another, each seeing the velocities the previous one produced; an exact corner hit is an x-wall
event followed by a y-wall event at the same instant, and a touching train (Newton's cradle) is a
chain of zero-time events.

Times are relative: the clock runs from 0 to the step length within each step, and absolute
times are formed once, when an impact is recorded, as ``start + sign * local``.

The cap on events per step (``max_events``) is never silent: a scene that reaches it stops at
the instant of its last resolved event, in a valid state (no overlap, nothing outside the border),
is flagged in ``capped``, and its clock shows how far it got.

Reverse steps are run forward on negated velocities with restitution 1/e (the caller negates).
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import njit
from .ldp import least_distance
from .motion import advance_all, ball_views, body_kinematics, has_rotation
from .response import ball_ball, ball_wall, group_threshold, impact_threshold, merge_bodies, stop_body
from .toi import INF, ca_pair, ca_wall, toi_pair, toi_wall
from .tolerance import CONTACT_RTOL, contact_tolerance

# counters: 0 pair predictions, 1 wall predictions, 2 events, 3 rotating-cluster predictions
PAIR_TESTS, WALL_TESTS, EVENTS, CLUSTER_TESTS = 0, 1, 2, 3

#: Sweeps over a contact group in one instant before the cascade is replaced by its limit (see
#: ``_settle_contact_group``). Cascades among comparable masses end within a few dozen sweeps; the
#: criterion is a count, so it does not depend on the masses, and the limit always ends the cascade.
_MAX_SWEEPS = 1000
#: Columns of the per-scene work arrays: float (time left in the step, start time of the step);
#: int (events so far, active, stalled, sub-steps done).
WORK_F = 2
WORK_I = 4


@njit(inline="always")
def scene_params(fparams, iparams):
    """The scene's parameters: ``fparams`` = (xmin, ymin, xmax, ymax, e, collapse_ratio, sign,
    collapse_floor), ``iparams`` = (has_walls, pairs, dim, sticky, max_events). Returns bounds, e,
    ratio, floor, sign, has_walls, pairs, dim, sticky, max_events."""
    return (fparams[0:4], fparams[4], fparams[5], fparams[7], fparams[6], iparams[0] != 0, iparams[1] != 0,
            iparams[2], iparams[3] != 0, iparams[4])


@njit(inline="always")
def record(imp, n_imp, scene, time, ball, other, wall, x, y, speed):
    """Append an impact to the record buffer ``imp`` (``simulator.IMPACT_DTYPE``)."""
    k = n_imp[0]
    r = imp[k]  # a view of row k (in numba and in numpy alike)
    r["scene"] = scene
    r["time"] = time
    r["ball"] = ball
    r["other"] = other
    r["wall"] = wall
    r["x"] = x
    r["y"] = y
    r["speed"] = speed
    n_imp[0] = k + 1


@njit(inline="always")
def wall_point(i, wall, pos, radius, bounds):
    if wall == 0:
        return bounds[0], pos[i, 1]
    if wall == 1:
        return bounds[2], pos[i, 1]
    if wall == 2:
        return pos[i, 0], bounds[1]
    return pos[i, 0], bounds[3]


@njit(inline="always")
def wall_gap(i, wall, pos, radius, bounds):
    if wall == 0:
        return pos[i, 0] - radius[i] - bounds[0]
    if wall == 1:
        return bounds[2] - radius[i] - pos[i, 0]
    if wall == 2:
        return pos[i, 1] - radius[i] - bounds[1]
    return bounds[3] - radius[i] - pos[i, 1]


@njit(inline="always")
def snap_to_wall(i, wall, pos, radius, bounds):
    """Put a ball exactly on the wall it touches (it is there up to round-off)."""
    if wall == 0:
        pos[i, 0] = bounds[0] + radius[i]
    elif wall == 1:
        pos[i, 0] = bounds[2] - radius[i]
    elif wall == 2:
        pos[i, 1] = bounds[1] + radius[i]
    else:
        pos[i, 1] = bounds[3] - radius[i]


@njit(inline="always")
def _straight_pair(i, k, now, pos, vel, radius, body, counters):
    """``_predict_pair`` when nothing rotates: inlined into the loops, which call it O(N) times per
    event (a call that numba does not inline costs as much as the time-of-impact kernel itself)."""
    if body[i] == body[k]:
        return INF
    counters[PAIR_TESTS] += 1
    return now + toi_pair(
        pos[k, 0] - pos[i, 0], pos[k, 1] - pos[i, 1], vel[k, 0] - vel[i, 0], vel[k, 1] - vel[i, 1],
        radius[i] + radius[k],
    )


@njit
def _predict_pair(i, k, now, horizon, pos, vel, mass, radius, body, omega, rot, ki, kj, counters):
    if body[i] == body[k]:
        return INF
    if rot and (omega[body[i]] != 0.0 or omega[body[k]] != 0.0):
        counters[CLUSTER_TESTS] += 1
        a = body_kinematics(i, pos, vel, mass, body, omega)
        c = body_kinematics(k, pos, vel, mass, body, omega)
        for q in range(7):
            ki[q] = a[q]
            kj[q] = c[q]
        return now + ca_pair(ki, kj, radius[i] + radius[k], horizon)
    return _straight_pair(i, k, now, pos, vel, radius, body, counters)


@njit(inline="always")
def _predict_wall(i, now, horizon, pos, vel, mass, radius, body, omega, rot, bounds, dim, ki, counters):
    if rot and omega[body[i]] != 0.0:
        counters[CLUSTER_TESTS] += 1
        a = body_kinematics(i, pos, vel, mass, body, omega)
        for q in range(7):
            ki[q] = a[q]
        tau, wall = ca_wall(ki, radius[i], bounds, dim, horizon)
        return now + tau, wall
    counters[WALL_TESTS] += 1
    tau, wall = toi_wall(pos[i, 0], pos[i, 1], vel[i, 0], vel[i, 1], radius[i], bounds, dim)
    return now + tau, wall


@njit(inline="always")
def _rescan(i, pt, rmin, rarg):
    best = INF
    arg = -1
    for k in range(pt.shape[0]):
        if pt[i, k] < best:
            best = pt[i, k]
            arg = k
    rmin[i] = best
    rarg[i] = arg


@njit(inline="always")
def _coord(i, pos):
    """Magnitude of ball ``i``'s coordinates (what the round-off of its gaps is relative to)."""
    return max(abs(pos[i, 0]), abs(pos[i, 1]))


@njit(inline="always")
def _touching(a, k, pos, radius):
    """Balls ``a`` and ``k`` touch within the contact tolerance (``tolerance.contact_tolerance``:
    1e-9 of the radii, or the round-off of their coordinates)."""
    dx = pos[k, 0] - pos[a, 0]
    dy = pos[k, 1] - pos[a, 1]
    sigma = radius[a] + radius[k]
    tol = contact_tolerance(sigma, max(_coord(a, pos), _coord(k, pos)), CONTACT_RTOL)
    return math.sqrt(dx * dx + dy * dy) - sigma <= tol


@njit(inline="always")
def wall_contact(i, wall, pos, radius, bounds):
    """Ball ``i`` touches ``wall`` within the contact tolerance (1e-9 of its diameter, or the
    round-off of its coordinates and the wall's)."""
    line = bounds[0] if wall == 0 else bounds[2] if wall == 1 else bounds[1] if wall == 2 else bounds[3]
    coord = max(_coord(i, pos), abs(line))
    return wall_gap(i, wall, pos, radius, bounds) <= contact_tolerance(2.0 * radius[i], coord, CONTACT_RTOL)


@njit
def _resolve_contact_group(
    sc, t_abs, i0, j0, pos, vel, inv_mass, radius, bounds, has_walls, pairs, dim, e, ratio, floor, imp, n_imp,
    counters, group, in_group, c_a, c_b, c_hit,
):
    """Resolve, at one instant, every contact of the group of touching balls an impact started.

    The impact was between ball ``i0`` and ball ``j0``, or the wall ``-1 - j0`` when ``j0 < 0``;
    the caller has applied and reported it, so that contact is not reported again here (one
    collision, one report, even when round-off leaves it closing at ~1e-16 m/s after a plastic
    impulse). The group's regulariser speed comes from its own balls when it is formed
    (``response.group_threshold`` of the collapse ``ratio`` and ``floor``).

    At e < 1 an impact inside a touching group (a train pressed against a wall, a crowd) starts a
    cascade of ever smaller impulses at the same instant: sequential impulses converge to the
    limit geometrically. This runs that cascade here: sweeps over the group's contacts in a fixed
    order apply the same pairwise impulses as the event loop would, one after another, without
    re-predicting every ball after each; the collapse regulariser ends it. A cascade still running
    after ``_MAX_SWEEPS`` sweeps (its convergence rate is set by a mass ratio) is finished by
    ``_settle_contact_group``. Contacts are gaps within the contact tolerance of zero
    (:func:`_touching`, :func:`wall_contact`). Every contact that takes an impulse is reported
    once. Returns the group size (its balls are in ``group``).
    """
    n = pos.shape[0]
    for k in range(n):
        in_group[k] = False
    size = 0
    for start in (i0, j0):  # j0 < 0: a wall
        if start >= 0 and not in_group[start]:
            group[size] = start
            in_group[start] = True
            size += 1
    # the group: everything connected to the impact through contacts
    q = 0
    while q < size and pairs:
        a = group[q]
        q += 1
        for k in range(n):
            if not in_group[k] and _touching(a, k, pos, radius):
                group[size] = k
                in_group[k] = True
                size += 1
    # its contacts, each once, in a fixed order
    n_contacts = 0
    for qa in range(size):
        a = group[qa]
        if pairs:
            for qb in range(qa + 1, size):
                k = group[qb]
                if _touching(a, k, pos, radius):
                    c_a[n_contacts] = min(a, k)
                    c_b[n_contacts] = max(a, k)
                    c_hit[n_contacts] = j0 >= 0 and c_a[n_contacts] == min(i0, j0) and c_b[n_contacts] == max(i0, j0)
                    n_contacts += 1
        if has_walls:
            for wall in range(4 if dim == 2 else 2):
                if wall_contact(a, wall, pos, radius, bounds):
                    c_a[n_contacts] = a
                    c_b[n_contacts] = -1 - wall
                    c_hit[n_contacts] = a == i0 and j0 == -1 - wall
                    n_contacts += 1
    u_min = group_threshold(group, size, vel, inv_mass, ratio, floor)
    changed = True
    for _ in range(_MAX_SWEEPS):
        changed = False
        for c in range(n_contacts):
            a = c_a[c]
            b = c_b[c]
            if b >= 0:
                speed = ball_ball(a, b, pos, vel, inv_mass, e, u_min)
            else:
                speed = ball_wall(a, -1 - b, vel, e, u_min)
            if speed > 0.0:
                changed = True
                counters[EVENTS] += 1
                _record_contact(sc, t_abs, c, c_a, c_b, c_hit, pos, radius, bounds, speed, imp, n_imp)
        if not changed:
            break
    if changed:
        _settle_contact_group(
            sc, t_abs, pos, vel, inv_mass, radius, bounds, u_min, imp, n_imp, counters, group, size,
            c_a, c_b, c_hit, n_contacts,
        )
    return size


@njit(inline="always")
def _contact_normal(c, c_a, c_b, pos):
    """Unit normal of contact ``c``, pointing from ball ``c_a[c]`` to its partner (ball or wall)."""
    a = c_a[c]
    b = c_b[c]
    if b >= 0:
        dx = pos[b, 0] - pos[a, 0]
        dy = pos[b, 1] - pos[a, 1]
        d = math.sqrt(dx * dx + dy * dy)
        return dx / d, dy / d
    wall = -1 - b
    if wall == 0:
        return -1.0, 0.0
    if wall == 1:
        return 1.0, 0.0
    if wall == 2:
        return 0.0, -1.0
    return 0.0, 1.0


@njit
def _record_contact(sc, t_abs, c, c_a, c_b, c_hit, pos, radius, bounds, speed, imp, n_imp):
    """Report contact ``c`` of a group the first time it takes an impulse."""
    if c_hit[c]:
        return
    c_hit[c] = True
    a = c_a[c]
    b = c_b[c]
    if b >= 0:
        nx, ny = _contact_normal(c, c_a, c_b, pos)
        record(imp, n_imp, sc, t_abs, a, b, -1, pos[a, 0] + radius[a] * nx, pos[a, 1] + radius[a] * ny, speed)
    else:
        x, y = wall_point(a, -1 - b, pos, radius, bounds)
        record(imp, n_imp, sc, t_abs, a, -1, -1 - b, x, y, speed)


@njit
def _settle_contact_group(
    sc, t_abs, pos, vel, inv_mass, radius, bounds, u_min, imp, n_imp, counters, group, size, c_a, c_b, c_hit,
    n_contacts,
):
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
    dof = 2 * size
    g_mat = np.zeros((n_contacts, dof))
    h = np.empty(n_contacts)
    slot = np.full(pos.shape[0], -1, dtype=np.int64)
    root_w = np.empty(size)
    for q in range(size):
        slot[group[q]] = q
        root_w[q] = math.sqrt(inv_mass[group[q]])
    closing = np.empty(n_contacts)
    fastest = 0.0
    for c in range(n_contacts):
        a = c_a[c]
        b = c_b[c]
        nx, ny = _contact_normal(c, c_a, c_b, pos)
        # separation speed of the contact = G_c . y with y = sqrt(m) v (mass-weighted velocities)
        qa = slot[a]
        g_mat[c, 2 * qa] = -nx * root_w[qa]
        g_mat[c, 2 * qa + 1] = -ny * root_w[qa]
        sep = -(vel[a, 0] * nx + vel[a, 1] * ny)
        if b >= 0:
            qb = slot[b]
            g_mat[c, 2 * qb] = nx * root_w[qb]
            g_mat[c, 2 * qb + 1] = ny * root_w[qb]
            sep += vel[b, 0] * nx + vel[b, 1] * ny
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
        _stop_group(vel, inv_mass, group, size, c_b, n_contacts)
    for c in range(n_contacts):
        if closing[c] > 0.0:
            counters[EVENTS] += 1
            _record_contact(sc, t_abs, c, c_a, c_b, c_hit, pos, radius, bounds, closing[c], imp, n_imp)


@njit
def _contacts_open(vel, pos, c_a, c_b, n_contacts, slack):
    """No contact of the group closes faster than ``slack`` (m/s)."""
    for c in range(n_contacts):
        a = c_a[c]
        b = c_b[c]
        nx, ny = _contact_normal(c, c_a, c_b, pos)
        sep = -(vel[a, 0] * nx + vel[a, 1] * ny)
        if b >= 0:
            sep += vel[b, 0] * nx + vel[b, 1] * ny
        if sep < -slack:
            return False
    return True


@njit
def _stop_group(vel, inv_mass, group, size, c_b, n_contacts):
    """The last resort of :func:`_settle_contact_group`: every contact at rest, at once."""
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


def scratch_sizes(n):
    """Lengths of :func:`step_exact`'s float, int and bool work buffers for ``n`` balls."""
    nc = n * (n - 1) // 2 + 4 * n
    return n * n + 2 * n + 14, 3 * n + 2 * nc, 2 * n + nc


@njit
def step_exact(balls, body_all, time, capped, fparams, iparams, imp, n_imp, counters, work_f, work_i, scratch_f,
               scratch_i, scratch_b, dt_abs, fresh):
    """Advance every active scene of the batch by its remaining time (see module doc).

    ``balls`` is the (B, N, 8) per-ball state (``motion.BALL_FIELDS``), ``body_all`` the (B, N) cluster
    roots, ``time`` the (B,) clocks. ``fparams`` = (xmin, ymin, xmax, ymax, e, collapse_ratio,
    sign, collapse_floor); ``iparams`` = (has_walls, pairs, dim, sticky, max_events).
    ``fresh`` starts a step of ``dt_abs`` for every scene (all active, the whole step left, no
    events yet); otherwise the call resumes the scenes flagged active in ``work_i``.
    Impacts go to ``imp`` rows (scene, time, ball, other, wall, x, y, speed) from row 0,
    ``n_imp[0]`` rows in all; a scene that finds the buffer full stops where it is and is flagged
    stalled, so the caller can empty the buffer and call again for those scenes. Returns the
    number of stalled scenes; ``n_imp[1]`` counts the scenes that reached the event cap.
    ``scratch_*`` are work buffers of :func:`scratch_sizes` (allocated once by the caller: an
    allocation here, per call, would cost more than a one-ball step).

    The whole batch is one call with the scene loop inside: a call between compiled functions
    reference-counts every array it passes, which would cost as much as a small scene's events.
    """
    pos_all, vel_all, mass_all, inv_mass_all, radius_all, omega_all = ball_views(balls)
    remaining = work_f[:, 0]
    events = work_i[:, 0]
    active = work_i[:, 1]
    stalled = work_i[:, 2]
    n_imp[0] = 0
    n_scenes = pos_all.shape[0]
    n = pos_all.shape[1]
    nc = n * (n - 1) // 2 + 4 * n
    pt = scratch_f[0:n * n].reshape((n, n))
    rmin = scratch_f[n * n:n * n + n]
    wt = scratch_f[n * n + n:n * n + 2 * n]
    ki = scratch_f[n * n + 2 * n:n * n + 2 * n + 7]
    kj = scratch_f[n * n + 2 * n + 7:n * n + 2 * n + 14]
    rarg = scratch_i[0:n]
    wid = scratch_i[n:2 * n]
    involved = scratch_i[2 * n:3 * n]
    c_a = scratch_i[3 * n:3 * n + nc]
    c_b = scratch_i[3 * n + nc:3 * n + 2 * nc]
    flag = scratch_b[0:n]
    in_group = scratch_b[n:2 * n]
    c_hit = scratch_b[2 * n:2 * n + nc]
    bounds, e, ratio, floor, sign, has_walls, pairs, dim, sticky, max_events = scene_params(fparams, iparams)
    if fresh:
        for sc in range(n_scenes):
            active[sc] = True
            remaining[sc] = dt_abs
            events[sc] = 0
            capped[sc] = False
        n_imp[1] = 0
    n_stalled = 0
    for sc in range(pos_all.shape[0]):
        if not active[sc]:
            continue
        stalled[sc] = False
        pos = pos_all[sc]
        vel = vel_all[sc]
        mass = mass_all[sc]
        inv_mass = inv_mass_all[sc]
        radius = radius_all[sc]
        body = body_all[sc]
        omega = omega_all[sc]
        n = pos.shape[0]
        cascades = e < 1.0  # forward inelastic: resolve touching groups at one instant
        room = n * (n - 1) // 2 + 4 * n + 1  # the most impacts one event can record (a contact group)
        horizon_end = remaining[sc]
        t0 = time[sc]
        now = 0.0
        rot = sticky and has_rotation(body, omega)

        for i in range(n):
            wt[i] = INF
            wid[i] = -1
            rmin[i] = INF
            rarg[i] = -1
            flag[i] = False
            for k in range(n):
                pt[i, k] = INF
        if has_walls:
            for i in range(n):
                wt[i], wid[i] = _predict_wall(
                    i, now, horizon_end, pos, vel, mass, radius, body, omega, rot, bounds, dim, ki, counters
                )
        if pairs:
            for i in range(n):
                for k in range(i + 1, n):
                    if rot:
                        v = _predict_pair(i, k, now, horizon_end, pos, vel, mass, radius, body, omega, rot, ki, kj,
                                          counters)
                    else:
                        v = _straight_pair(i, k, now, pos, vel, radius, body, counters)
                    pt[i, k] = v
                    pt[k, i] = v
            for i in range(n):
                _rescan(i, pt, rmin, rarg)

        while True:
            best = INF
            bi = -1
            bj = -1
            for i in range(n):
                if wt[i] < best:
                    best = wt[i]
                    bi = i
                    bj = -1
                if rmin[i] < best:
                    best = rmin[i]
                    bi = i
                    bj = rarg[i]
            if not best <= horizon_end:
                break
            if events[sc] >= max_events:
                capped[sc] = True
                break
            if n_imp[0] + room > imp.shape[0]:
                stalled[sc] = True
                break
            if best > now:
                advance_all(best - now, pos, vel, mass, body, omega, rot)
                now = best
            events[sc] += 1
            counters[EVENTS] += 1
            t_abs = t0 + sign * now

            n_inv = 0
            if bj < 0:  # ball bi meets wall wid[bi]
                wall = wid[bi]
                if sticky:
                    axis = 0 if wall < 2 else 1
                    into = vel[bi, axis] < 0.0 if wall % 2 == 0 else vel[bi, axis] > 0.0
                    if wall_contact(bi, wall, pos, radius, bounds) and into:
                        if omega[body[bi]] == 0.0:
                            snap_to_wall(bi, wall, pos, radius, bounds)
                        x, y = wall_point(bi, wall, pos, radius, bounds)
                        record(imp, n_imp, sc, t_abs, bi, -1, wall, x, y, abs(vel[bi, axis]))
                        root = body[bi]
                        for k in range(n):
                            if body[k] == root:
                                involved[n_inv] = k
                                n_inv += 1
                        stop_body(bi, vel, body, omega)
                    else:
                        involved[0] = bi
                        n_inv = 1
                else:
                    snap_to_wall(bi, wall, pos, radius, bounds)
                    u_min = impact_threshold(bi, -1, vel, ratio, floor)
                    speed = ball_wall(bi, wall, vel, e, u_min)
                    if speed > 0.0:
                        x, y = wall_point(bi, wall, pos, radius, bounds)
                        record(imp, n_imp, sc, t_abs, bi, -1, wall, x, y, speed)
                    involved[0] = bi
                    n_inv = 1
                    if cascades and speed > 0.0:
                        n_inv = _resolve_contact_group(
                            sc, t_abs, bi, -1 - wall, pos, vel, inv_mass, radius, bounds, has_walls, pairs, dim, e,
                            ratio, floor, imp, n_imp, counters, involved, in_group, c_a, c_b, c_hit,
                        )
            else:  # balls bi and bj meet
                dx = pos[bj, 0] - pos[bi, 0]
                dy = pos[bj, 1] - pos[bi, 1]
                dist = math.sqrt(dx * dx + dy * dy)
                closing = (vel[bj, 0] - vel[bi, 0]) * dx + (vel[bj, 1] - vel[bi, 1]) * dy
                if sticky:
                    if _touching(bi, bj, pos, radius) and closing < 0.0:
                        x = pos[bi, 0] + radius[bi] * dx / dist
                        y = pos[bi, 1] + radius[bi] * dy / dist
                        record(imp, n_imp, sc, t_abs, bi, bj, -1, x, y, -closing / dist)
                        root = merge_bodies(bi, bj, pos, vel, mass, body, omega)
                        for k in range(n):
                            if body[k] == root:
                                involved[n_inv] = k
                                n_inv += 1
                        rot = has_rotation(body, omega)
                    else:
                        involved[0] = bi
                        involved[1] = bj
                        n_inv = 2
                else:
                    u_min = impact_threshold(bi, bj, vel, ratio, floor)
                    speed = ball_ball(bi, bj, pos, vel, inv_mass, e, u_min)
                    if speed > 0.0:
                        x = pos[bi, 0] + radius[bi] * dx / dist
                        y = pos[bi, 1] + radius[bi] * dy / dist
                        record(imp, n_imp, sc, t_abs, bi, bj, -1, x, y, speed)
                    involved[0] = bi
                    involved[1] = bj
                    n_inv = 2
                    if cascades and speed > 0.0:
                        n_inv = _resolve_contact_group(
                            sc, t_abs, bi, bj, pos, vel, inv_mass, radius, bounds, has_walls, pairs, dim, e, ratio,
                            floor, imp, n_imp, counters, involved, in_group, c_a, c_b, c_hit,
                        )
            if sticky:
                rot = has_rotation(body, omega)

            # Re-predict what the event changed.
            for q in range(n_inv):
                i = involved[q]
                flag[i] = True
                if has_walls:
                    wt[i], wid[i] = _predict_wall(
                        i, now, horizon_end - now, pos, vel, mass, radius, body, omega, rot, bounds, dim, ki, counters
                    )
            if pairs:
                for q in range(n_inv):
                    i = involved[q]
                    for k in range(n):
                        if k != i and not (flag[k] and k < i):
                            if rot:
                                v = _predict_pair(
                                    i, k, now, horizon_end - now, pos, vel, mass, radius, body, omega, rot, ki, kj,
                                    counters,
                                )
                            else:
                                v = _straight_pair(i, k, now, pos, vel, radius, body, counters)
                            pt[i, k] = v
                            pt[k, i] = v
                for q in range(n_inv):
                    _rescan(involved[q], pt, rmin, rarg)
                for k in range(n):
                    if flag[k]:
                        continue
                    stale = False
                    for q in range(n_inv):
                        i = involved[q]
                        v = pt[k, i]
                        if v < rmin[k]:
                            rmin[k] = v
                            rarg[k] = i
                        elif rarg[k] == i and v > rmin[k]:
                            stale = True
                    if stale:
                        _rescan(k, pt, rmin, rarg)
            for q in range(n_inv):
                flag[involved[q]] = False

        if not (capped[sc] or stalled[sc]) and now < horizon_end:
            advance_all(horizon_end - now, pos, vel, mass, body, omega, rot)
            now = horizon_end
        if now == horizon_end:
            time[sc] = t0 + sign * horizon_end
            remaining[sc] = 0.0
        else:
            time[sc] = t0 + sign * now
            remaining[sc] = horizon_end - now
        n_stalled += stalled[sc]
        n_imp[1] += capped[sc]
        active[sc] = stalled[sc]
    return n_stalled


