"""Exact mode: a-priori, event-driven stepping to machine precision at any dt.

The scheduler of the event-driven loop (Alder & Wainwright 1959; Rapaport 1980; Lubachevsky
1991). Its parts, each with one job:

- the **calendar** (:mod:`~collision_env.engine.calendar`): one pending event per ball, invalidated
  lazily, in an event queue (a heap, and time buckets in large scenes); it persists from one step
  to the next;
- the **broad phase** (:mod:`~collision_env.engine.grid`): a cell grid, so that a prediction looks
  only at the 3 x 3 cells around a ball, kept current by cell-crossing events (one cell, i.e. all
  pairs, in small scenes);
- this **scheduler**, :func:`step_exact`, in named phases: *begin* (:func:`_begin_changed_balls`:
  re-predict only the balls that changed since the last step, a nudge, an env's action, a
  reversal of time; :func:`_begin_whole_scene` after a reset or ``set_state``), then repeatedly
  *predict* (:func:`_predict`), *pop* the earliest event and screen it (:func:`_screen`: stale,
  a cell crossing, or re-verified), *advance* the balls it involves (:func:`_advance`), *resolve*
  it (:func:`_resolve_wall`, :func:`_resolve_pair`, and a contact group's cascade) and
  *invalidate* (:func:`_invalidate`), and finally *finish* (:func:`_finish`: bring every ball to
  the end of the step and rebase the calendar's times). The phases take a scene's arrays in
  named bundles (:class:`SceneBalls`, :class:`SceneCalendar`, :class:`Physics`, :class:`Work`);
  they are inlined, so the bundles cost nothing.

Balls move lazily: a ball's calendar record holds its position at its own ``ref_time``, brought
up to date only when an event involves it (or when the step ends), so an event costs O(log N)
with O(1) partners instead of moving every ball. Stick scenes (rotating clusters) keep every ball
at the same time instead, as their kinematics need.

Determinism: ties are broken by index (a ball's wall before its partners, then the lowest ball
index, then the lowest partner index). Simultaneous events are therefore resolved one after
another, each seeing the velocities the previous one produced; an exact corner hit is an x-wall
event followed by a y-wall event at the same instant, and a touching train (Newton's cradle) is a
chain of zero-time events.

Times are relative: the calendar's times run from 0 at the start of each step, and absolute
times are formed once, when an impact is recorded, as ``start + sign * local``. An event's time
is re-computed from the two balls' stored states when it is popped (DynamO's re-verification), so
a prediction made steps ago gives the same impact time as a fresh one.

The cap on events per step (``max_events``) is never silent: a scene that reaches it stops at
the instant of its last resolved event, in a valid state (no overlap, nothing outside the border),
is flagged in ``capped``, and its clock shows how far it got.

Reverse steps are run forward on negated velocities with restitution 1/e (the caller negates).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import HAVE_NUMBA, njit, prefetch
from ..clock import finish_step
from ..layout import (
    BALL,
    C_CELL,
    C_EVENT_OTHER,
    CAL_RECORD,
    IMPACT_DTYPE,
    S_COLLAPSE_FLOOR,
    S_COLLAPSE_RATIO,
    S_DIM,
    S_ELASTICITY,
    S_HAS_WALLS,
    S_MAX_EVENTS,
    S_PAIRS,
    S_SIGN,
    S_STICKY,
    S_XMIN,
    S_YMAX,
    W_ACTIVE,
    W_CALENDAR_VALID,
    W_EVENTS,
    W_REMAINING,
    W_STALLED,
    W_STALLED_AT,
)
from ..physics.ldp import least_distance
from . import calendar as cal
from . import grid

if HAVE_NUMBA:
    from ..argpack import view1, view2, view3
from ..physics.motion import advance_all, ball_views, body_kinematics, has_rotation
from ..physics.response import ball_ball, ball_wall, group_threshold, impact_threshold, merge_bodies, stop_body
from ..physics.toi import INF, ca_pair, ca_wall, toi_pair, toi_wall
from ..physics.tolerance import CONTACT_RTOL, contact_tolerance

#: Work counters (``BatchSimulator.stats``): pair predictions, wall predictions, events,
#: rotating-cluster predictions, grid-cell crossings, stale calendar entries re-predicted.
COUNTERS = ("pair_tests", "wall_tests", "events", "cluster_tests", "cell_crossings", "stale_events")
PAIR_TESTS, WALL_TESTS, EVENTS, CLUSTER_TESTS, CELL_CROSSINGS, STALE_EVENTS = range(6)

#: How a call of a stepping kernel (``step_exact``, ``substep.step_substeps``) starts: it resumes
#: the scenes a full impact buffer stopped, starts a step (exact mode re-predicts the balls that
#: changed since the last step), or starts the next step of a run of steps made in one compiled
#: loop, where nothing can have changed in between (the cheap modes treat both starts alike).
RESUME, START_STEP, START_NEXT = range(3)

#: Sweeps over a contact group in one instant before the cascade is replaced by its limit (see
#: ``_settle_contact_group``). Cascades among comparable masses end within a few dozen sweeps; the
#: criterion is a count, so it does not depend on the masses, and the limit always ends the cascade.
_MAX_SWEEPS = 1000


@njit(inline="always")
def scene_params(fparams, iparams):
    """The scene's parameters (``layout.SCENE_F`` and ``layout.SCENE_I``). Returns bounds, e, ratio,
    floor, sign, has_walls, pairs, dim, sticky, max_events."""
    return (
        fparams[S_XMIN : S_YMAX + 1],
        fparams[S_ELASTICITY],
        fparams[S_COLLAPSE_RATIO],
        fparams[S_COLLAPSE_FLOOR],
        fparams[S_SIGN],
        iparams[S_HAS_WALLS] != 0,
        iparams[S_PAIRS] != 0,
        iparams[S_DIM],
        iparams[S_STICKY] != 0,
        iparams[S_MAX_EVENTS],
    )


class SceneBalls(NamedTuple):
    """One scene's ball state: views of the batch's ``layout.BALL`` array and cluster roots."""

    pos: np.ndarray  #: (N, 2) centres, m
    vel: np.ndarray  #: (N, 2) velocities, m/s
    mass: np.ndarray  #: (N,) kg
    inv_mass: np.ndarray  #: (N,) 1 / kg
    radius: np.ndarray  #: (N,) m
    body: np.ndarray  #: (N,) the ball rooting each ball's cluster
    omega: np.ndarray  #: (N,) angular velocity of the cluster each ball roots, rad/s


class SceneCalendar(NamedTuple):
    """One scene's calendar (see :mod:`~collision_env.engine.calendar`)."""

    rec: np.ndarray  #: (N,) ``layout.CAL_RECORD``
    ci: np.ndarray  #: (N, len(CAL_I)) int32
    heads: np.ndarray  #: (cells,) int32, the first ball of each grid cell
    q: cal.EventQueue  #: the event queue
    inv_mass: np.ndarray  #: (N,) float64, each ball's inverse mass, taken with its radius


class Physics(NamedTuple):
    """What a step's physics depends on, shared by the scenes of a batch (``scene_params``)."""

    bounds: np.ndarray  #: (xmin, ymin, xmax, ymax), m
    e: float  #: restitution used this step
    ratio: float  #: collapse regulariser: u_min / fastest speed
    floor: float  #: collapse regulariser: smallest u_min, m/s
    sign: float  #: direction of time, +1 or -1
    has_walls: bool
    pairs: bool  #: ball pairs are modelled
    dim: int
    sticky: bool  #: stick clusters are formed
    cascades: bool  #: forward inelastic: touching groups are resolved at one instant


class Work(NamedTuple):
    """The step's buffers: impact records and counters, and scratch space (``scratch_sizes``)."""

    imp: np.ndarray  #: impact records (``layout.IMPACT_DTYPE``)
    n_imp: np.ndarray  #: rows filled, scenes that reached the event cap, scenes that stalled
    counters: np.ndarray  #: work counters (``COUNTERS``)
    pending: np.ndarray  #: balls to predict (or whose motion an event changed)
    in_group: np.ndarray  #: a contact group's membership, per ball
    c_a: np.ndarray  #: a contact group's contacts: the lower ball
    c_b: np.ndarray  #: ... and the other ball (>= 0) or the wall (-1 - wall)
    c_hit: np.ndarray  #: ... and whether it was reported already
    ki: np.ndarray  #: a rotating cluster member's kinematics (7 floats)
    kj: np.ndarray  #: ... and its partner's
    event: SceneBalls  #: the two balls of an event, rows 0 and 1 (see ``_event_balls``)


@njit(inline="always")
def _physics(fparams, iparams):
    bounds, e, ratio, floor, sign, has_walls, pairs, dim, sticky, _ = scene_params(fparams, iparams)
    return Physics(bounds, e, ratio, floor, sign, has_walls, pairs, dim, sticky, e < 1.0)


@njit(inline="always")
def _work(n, imp, n_imp, counters, scratch_f, scratch_i, scratch_b):
    nc = contact_capacity(n)
    return Work(
        imp,
        n_imp,
        counters,
        scratch_i[0:n],
        scratch_b[0:n],
        scratch_i[n : n + nc],
        scratch_i[n + nc : n + 2 * nc],
        scratch_b[n : n + nc],
        scratch_f[0:7],
        scratch_f[7:14],
        _event_balls(
            scratch_f[14 : 14 + 2 * len(BALL)].reshape((1, 2, len(BALL))), scratch_i[n + 2 * nc : n + 2 * nc + 2]
        ),
    )


@njit(inline="always")
def _event_balls(rows, body):
    """The two balls of an event, rows 0 and 1 of ``rows``: a (1, 2, len(BALL)) scratch laid out as
    the ball state (``layout.BALL``), so that the response kernels take them as they take a scene."""
    pos, vel, mass, inv_mass, radius, omega = ball_views(rows)
    return SceneBalls(pos[0], vel[0], mass[0], inv_mass[0], radius[0], body, omega[0])


@njit(inline="always")
def record(imp, n_imp, scene, time, ball, other, wall, x, y, speed):
    """Append an impact to the record buffer ``imp`` (``layout.IMPACT_DTYPE``)."""
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


@njit(refcount=False)
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
    counters[PAIR_TESTS] += 1
    return now + toi_pair(
        pos[k, 0] - pos[i, 0],
        pos[k, 1] - pos[i, 1],
        vel[k, 0] - vel[i, 0],
        vel[k, 1] - vel[i, 1],
        radius[i] + radius[k],
    )


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


@njit(refcount=False)
def _resolve_contact_group(
    sc,
    t_abs,
    i0,
    j0,
    pos,
    vel,
    inv_mass,
    radius,
    bounds,
    has_walls,
    pairs,
    dim,
    e,
    ratio,
    floor,
    imp,
    n_imp,
    counters,
    group,
    in_group,
    c_a,
    c_b,
    c_hit,
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
            sc,
            t_abs,
            pos,
            vel,
            inv_mass,
            radius,
            bounds,
            u_min,
            imp,
            n_imp,
            counters,
            group,
            size,
            c_a,
            c_b,
            c_hit,
            n_contacts,
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


@njit(refcount=False)
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
    sc,
    t_abs,
    pos,
    vel,
    inv_mass,
    radius,
    bounds,
    u_min,
    imp,
    n_imp,
    counters,
    group,
    size,
    c_a,
    c_b,
    c_hit,
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


@njit(refcount=False)
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


@njit(refcount=False)
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
    """Lengths of :func:`step_exact`'s float, int and bool work buffers for ``n`` balls: O(N)."""
    nc = contact_capacity(n)
    return 14 + 2 * len(BALL), n + 2 * nc + 2, n + nc


@njit
def contact_capacity(n):
    """Most contacts a contact group of ``n`` balls can have: the contact graph of disks that do not
    overlap is planar (at most 3n - 6 edges), and a ball touches at most two walls (four in a box
    no wider than the ball)."""
    return 3 * n + 4 * n + 8


@njit
def impacts_per_event(n, cascades):
    """Most impacts one event can record: a contact group's contacts, or the event alone."""
    return contact_capacity(n) + 1 if cascades else 2


# ---------------------------------------------------------------------------- lazy motion
# A ball's calendar record (``layout.CAL_RECORD``) holds its straight-line trajectory: its centre
# at its own ``ref_time`` and its velocity. Balls are moved there lazily, only when an event
# touches them. An event's balls are copied from their records (and the calendar's inverse
# masses) into two rows laid out as ball state (``Work.event``), the response kernels resolve
# them there, and the records take back what changed; the engine's ball state (what the caller
# reads) is brought up to date from the records for every ball when the step ends. So an event
# reads and writes the calendar alone: in a large scene the ball state's rows stay out of the
# cache. Stick scenes and inelastic forward steps are the exception (:func:`_whole_state`):
# clusters move as a whole and a contact group may take in any ball, so the whole ball state is
# advanced at once, resolved in place, and the records are loaded from it.
@njit(inline="always")
def _position_at(k, t, rec):
    """Where ball ``k`` is at step time ``t``."""
    r = rec[k]
    dt = t - r["ref_time"]
    return r["x"] + r["vx"] * dt, r["y"] + r["vy"] * dt


@njit(inline="always")
def _sync(k, t, rec):
    """Move ball ``k``'s record to step time ``t`` (straight-line motion)."""
    r = rec[k]
    dt = t - r["ref_time"]
    if dt != 0.0:
        r["x"] += r["vx"] * dt
        r["y"] += r["vy"] * dt
        r["ref_time"] = t


@njit(inline="always")
def _store(k, rec, pos, vel, row):
    """Ball ``k``'s record (position and velocity) into row ``row`` of a ball state."""
    r = rec[k]
    pos[row, 0] = r["x"]
    pos[row, 1] = r["y"]
    vel[row, 0] = r["vx"]
    vel[row, 1] = r["vy"]


@njit(inline="always")
def _load(k, t, rec, pos, vel, row):
    """Row ``row`` of a ball state into ball ``k``'s record, as of step time ``t``."""
    r = rec[k]
    r["x"] = pos[row, 0]
    r["y"] = pos[row, 1]
    r["vx"] = vel[row, 0]
    r["vy"] = vel[row, 1]
    r["ref_time"] = t


@njit(inline="always")
def _take(k, row, t, cl, ev):
    """Ball ``k``, moved in its record to step time ``t``, into row ``row`` of an event's balls."""
    _sync(k, t, cl.rec)
    _store(k, cl.rec, ev.pos, ev.vel, row)
    ev.radius[row] = cl.rec[k]["radius"]
    ev.inv_mass[row] = cl.inv_mass[k]


@njit(inline="always")
def _sync_all(t, pos, vel, mass, body, omega, rot, sticky, rec):
    """Bring every ball to step time ``t``, in the records and in the ball state alike."""
    n = pos.shape[0]
    if sticky:
        dt = t - rec[0]["ref_time"]
        if dt != 0.0:
            advance_all(dt, pos, vel, mass, body, omega, rot)
            for k in range(n):
                _load(k, t, rec, pos, vel, k)
    else:
        for k in range(n):
            _sync(k, t, rec)
            _store(k, rec, pos, vel, k)


@njit(inline="always")
def _pair_gap(i, k, rec):
    """Balls ``i`` and ``k`` at the later of their reference times ``tc``: ``(tc, dx, dy, dvx, dvy,
    sigma)``, the separation and relative velocity of ``k`` from ``i`` and the radii sum."""
    ri = rec[i]
    rk = rec[k]
    tc = max(ri["ref_time"], rk["ref_time"])
    xi, yi = _position_at(i, tc, rec)
    xk, yk = _position_at(k, tc, rec)
    return tc, xk - xi, yk - yi, rk["vx"] - ri["vx"], rk["vy"] - ri["vy"], ri["radius"] + rk["radius"]


@njit(inline="always")
def _pair_time(i, k, rec):
    """Step time at which balls ``i`` and ``k`` in straight-line motion meet (inf: never), computed
    from their records at the later of their reference times. Every prediction and every
    re-verification of a pair uses this one formula on the records alone, so the answer does not
    depend on when it is asked: a calendar kept for many steps and a fresh one agree."""
    tc, dx, dy, dvx, dvy, sigma = _pair_gap(i, k, rec)
    return tc + toi_pair(dx, dy, dvx, dvy, sigma)


@njit(inline="always")
def _not_before(dx, dy, dvx, dvy, sigma, span):
    """Two balls apart by ``(dx, dy)``, closing at ``(dvx, dvy)``, cannot touch within ``span``
    seconds: their time of impact is at least ``c / (-2 b)`` (``b = dr . dv < 0``, ``c = |dr|^2 -
    sigma^2``: the quadratic's ``t^2`` term is never negative), with a margin far above the round-off
    of the time of impact itself. A cheap test that spares the square root and the division of
    most pairs a prediction looks at (Smallenburg 2022)."""
    b = dx * dvx + dy * dvy
    c = dx * dx + dy * dy - sigma * sigma
    return b >= 0.0 or c * (1.0 - 1e-9) > -2.0 * b * span


@njit(inline="always")
def _wall_time(i, bounds, dim, rec):
    """Step time and code of the first wall ball ``i`` meets in straight-line motion."""
    r = rec[i]
    tau, wall = toi_wall(r["x"], r["y"], r["vx"], r["vy"], r["radius"], bounds, dim)
    return r["ref_time"] + tau, wall


# ---------------------------------------------------------------------------- predict
@njit(inline="always")
def _wall_event(i, now, horizon, rot, b, ph, rec, wk):
    """Ball ``i``'s next wall: ``(time, code)``, or ``(inf, EV_NONE)``."""
    if not ph.has_walls:
        return INF, cal.EV_NONE
    if rot:  # (from the ball state, which stick scenes keep at ``now``)
        t, wall = _predict_wall(
            i, now, horizon, b.pos, b.vel, b.mass, b.radius, b.body, b.omega, rot, ph.bounds, ph.dim, wk.ki, wk.counters
        )
    else:
        wk.counters[WALL_TESTS] += 1
        t, wall = _wall_time(i, ph.bounds, ph.dim, rec)
    return (t, cal.EV_WALL - wall) if wall >= 0 else (INF, cal.EV_NONE)


@njit(inline="always")
def _near_border(c, nx, ny):
    """Cell ``c`` is one of the grid's outermost (or the only one): a ball elsewhere is at least a
    cell's width, more than its radius, from every wall."""
    cx = c % nx
    cy = c // nx
    return cx == 0 or cx == nx - 1 or cy == 0 or cy == ny - 1


@njit(inline="always")
def _crossing_event(i, rec, ci, geo):
    """When ball ``i`` leaves its grid cell, and for which neighbour: ``(time, code)``."""
    x0, y0, hx, hy, nx, ny = geo
    r = rec[i]
    tau, direction = grid.crossing(r["x"], r["y"], r["vx"], r["vy"], ci[i, C_CELL], x0, y0, hx, hy, nx, ny)
    return (tau + r["ref_time"], cal.EV_CROSS - direction) if direction >= 0 else (INF, cal.EV_NONE)


@njit(inline="always")
def _partner_event(i, now, horizon, rebuild, rot, best_t, best_code, best_stamp, b, ph, cl, geo, wk):
    """Ball ``i``'s earliest collision with a partner in the 3 x 3 cells around it (every other
    ball when the grid has one cell), if it comes before ``(best_t, best_code)``: the new best
    ``(time, code, partner's change count)``. With ``rebuild``, only partners of higher index."""
    rec = cl.rec
    n = rec.shape[0]
    nx, ny = geo[4], geo[5]
    one_cell = not grid.has_cells(geo)
    tests = 0
    cx0, cx1, cy0, cy1 = (0, 0, 0, 0) if one_cell else grid.block(cl.ci[i, C_CELL], nx, ny)
    for cy in range(cy0, cy1 + 1):
        for cx in range(cx0, cx1 + 1):
            k = (i + 1 if rebuild else 0) if one_cell else cl.heads[cy * nx + cx]
            while 0 <= k < n:
                if k != i and (k > i or not rebuild):
                    if rot:
                        t = _predict_pair(
                            i, k, now, horizon, b.pos, b.vel, b.mass, b.radius, b.body, b.omega, rot, wk.ki, wk.kj,
                            wk.counters,
                        )  # fmt: skip
                    elif ph.sticky and b.body[i] == b.body[k]:
                        t = INF
                    else:
                        tests += 1
                        tc, dx, dy, dvx, dvy, sigma = _pair_gap(i, k, rec)
                        if _not_before(dx, dy, dvx, dvy, sigma, best_t - tc):
                            t = INF
                        else:
                            t = tc + toi_pair(dx, dy, dvx, dvy, sigma)
                    if t < INF and cal.earlier(t, k, best_t, best_code, i):
                        best_t = t
                        best_code = k
                        best_stamp = rec[k]["changes"]
                k = k + 1 if one_cell else rec[k]["cell_next"]
    wk.counters[PAIR_TESTS] += tests
    return best_t, best_code, best_stamp


@njit(inline="always")
def _predict(i, now, horizon, rebuild, rot, b, cl, ph, geo, wk):
    """Find ball ``i``'s next event and schedule it: the earliest of its wall, its cell crossing
    (found first: an early bound spares most pairs their time of impact) and its partners, from the
    records (rotating clusters from the ball state; ``horizon`` matters only to them).

    ``rebuild`` is the first prediction of a whole scene: only partners of higher index are
    looked at, so each pair is tested once, by its lower ball (which is enough: the earliest event
    of the scene is then held by its lower ball), and the queue is built afterwards
    (``calendar.reset_queue``).
    """
    if _near_border(cl.ci[i, C_CELL], geo[4], geo[5]):
        best_t, best_code = _wall_event(i, now, horizon, rot, b, ph, cl.rec, wk)
    else:  # (a ball in an inner cell crosses into a cell at the border before it can touch a wall)
        best_t, best_code = INF, cal.EV_NONE
    best_stamp = 0
    if ph.pairs:
        if grid.has_cells(geo):
            t, code = _crossing_event(i, cl.rec, cl.ci, geo)
            if cal.earlier(t, code, best_t, best_code, i):
                best_t, best_code = t, code
        best_t, best_code, best_stamp = _partner_event(
            i, now, horizon, rebuild, rot, best_t, best_code, best_stamp, b, ph, cl, geo, wk
        )
    cal.set_event(i, best_t, best_code, best_stamp, cl.rec, cl.ci)
    if not rebuild:
        cal.schedule(i, cl.rec, cl.ci, cl.q)


# ---------------------------------------------------------------------------- prefetch
# In a large scene an event's data is out of the cache, and a prediction waits first for the cell
# heads around its ball, then for the records they name. The heads' addresses are known as soon as
# the event is popped: asking for them then overlaps their loads with the event's own work (screen,
# advance, resolve), which cut the cost per event at 10^5 balls by 5 to 10 % and cost nothing
# measurable at 10^2 (scale benchmark). Asking for the records too, once the heads are in, cost more
# at 10^2 than it saved at 10^5, with a branch per cell or without. (The queue's own walk ahead is
# ``calendar.walk_next_bucket``.)
@njit(inline="always")
def _prefetch_heads(c, nx, heads):
    """Ask for the heads of the 3 x 3 cells around cell ``c`` (both ends of each row of three, which
    may straddle two cache lines; clamped to the array, since only the lines matter)."""
    last = heads.shape[0] - 1
    for dy in range(-1, 2):
        middle = np.int64(c) + dy * np.int64(nx)
        prefetch(heads, min(max(middle - 1, 0), last))
        prefetch(heads, min(max(middle + 1, 0), last))


@njit(inline="always")
def _prefetch_popped(bi, cl, geo):
    """Ask for what ball ``bi``'s popped event reads first: its partner's record and int row, and
    the cell heads of the prediction that follows (around the cell it enters, for a crossing).
    Only with a grid: a scene without one is small enough to stay in the cache."""
    if grid.has_cells(geo):
        nx = geo[4]
        code = cl.ci[bi, C_EVENT_OTHER]
        c = cl.ci[bi, C_CELL]
        if cal.is_crossing(code):
            c = grid.neighbour_cell(c, cal.EV_CROSS - code, nx)
        _prefetch_heads(c, nx, cl.heads)
        if code >= 0:
            prefetch(cl.rec, code)
            cal.prefetch_int_row(code, cl.ci)


@njit(inline="always")
def _prefetch_partner(bj, cl, geo):
    """Ask for the cell heads of pair partner ``bj``'s coming prediction (its cell is in its int row,
    which :func:`_prefetch_popped` asked for)."""
    if grid.has_cells(geo):
        _prefetch_heads(cl.ci[bj, C_CELL], geo[4], cl.heads)


# ---------------------------------------------------------------------------- begin
@njit(inline="always")
def _begin_whole_scene(now, b, cl, geo, pending):
    """Forget every prediction of a scene, take every ball's state (its radius and inverse mass
    too) into the calendar as of step time ``now`` and lay the balls into the grid; every ball is
    then to be predicted (listed in ``pending``). Returns how many."""
    n = b.pos.shape[0]
    x0, y0, hx, hy, nx, ny = geo
    for i in range(n):
        _load(i, now, cl.rec, b.pos, b.vel, i)
        cl.rec[i]["radius"] = b.radius[i]
        cl.inv_mass[i] = b.inv_mass[i]
        cal.set_event(i, INF, cal.EV_NONE, 0, cl.rec, cl.ci)
        pending[i] = i
    grid.fill_cells(n, cl.rec, cl.ci, cl.heads, x0, y0, hx, hy, nx, ny)
    return n


@njit(inline="always")
def _changed_since_last_step(i, pos, vel, rec):
    r = rec[i]
    return pos[i, 0] != r["x"] or pos[i, 1] != r["y"] or vel[i, 0] != r["vx"] or vel[i, 1] != r["vy"]


@njit(inline="always")
def _begin_changed_balls(pos, vel, rec, ci, heads, geo, pending):
    """List in ``pending`` the balls whose position or velocity changed since the last step ended
    (a nudge, an env's action, the negated velocities of a reversal of time): their records take
    the new state, their trajectories are new (their change counters move on, which makes events
    others hold with them stale) and they may sit in another cell. Returns how many."""
    n = pos.shape[0]
    x0, y0, hx, hy, nx, ny = geo
    n_changed = 0
    for i in range(n):
        if _changed_since_last_step(i, pos, vel, rec):
            pending[n_changed] = i
            n_changed += 1
            _load(i, 0.0, rec, pos, vel, i)
            rec[i]["changes"] += 1
            if grid.has_cells(geo):
                grid.move_to_cell(i, grid.cell_of(pos[i, 0], pos[i, 1], x0, y0, hx, hy, nx, ny), rec, ci, heads)
    return n_changed


# ---------------------------------------------------------------------------- verify
@njit(inline="always")
def _verified_time(i, code, bounds, dim, rec):
    """The popped event's time, computed afresh from the records (a prediction from an earlier
    step carries the round-off of rebasing its time), or inf if it no longer happens."""
    if code >= 0:
        return _pair_time(i, code, rec)
    t, wall = _wall_time(i, bounds, dim, rec)
    return t if wall == cal.EV_WALL - code else INF


# ---------------------------------------------------------------------------- finish
@njit(inline="always")
def _finish(t_end, pos, vel, mass, body, omega, rot, sticky, rec, ci, q):
    """End the step at step time ``t_end``: every ball there (records and ball state), and the
    calendar's times made relative to it (the next step starts at 0)."""
    n = pos.shape[0]
    if sticky:
        _sync_all(t_end, pos, vel, mass, body, omega, rot, sticky, rec)
    for i in range(n):
        r = rec[i]
        if not sticky:
            dt = t_end - r["ref_time"]
            r["x"] += r["vx"] * dt
            r["y"] += r["vy"] * dt
            _store(i, rec, pos, vel, i)  # (events resolved on their own rows left it behind)
        r["ref_time"] = 0.0
        r["event_time"] -= t_end
    cal.rebase_queue(n, t_end, rec, ci, q)  # (the same times, rebased the same way)


# ---------------------------------------------------------------------------- resolve
@njit(inline="always")
def _cascade(sc, t_abs, i0, j0, b, ph, wk):
    """The contact group an impact of ball ``i0`` with ``j0`` (a ball, or the wall ``-1 - j0``)
    started, resolved at one instant (:func:`_resolve_contact_group`); its balls are listed in
    ``wk.pending``. Returns how many."""
    return _resolve_contact_group(
        sc, t_abs, i0, j0, b.pos, b.vel, b.inv_mass, b.radius, ph.bounds, ph.has_walls, ph.pairs, ph.dim, ph.e,
        ph.ratio, ph.floor, wk.imp, wk.n_imp, wk.counters, wk.pending, wk.in_group, wk.c_a, wk.c_b, wk.c_hit,
    )  # fmt: skip


@njit(inline="always")
def _resolve_wall(sc, t_abs, bi, li, wall, b, ph, wk):
    """Ball ``bi``, row ``li`` of ``b`` (the whole ball state, ``li = bi``, in stick scenes and
    where contact groups may form, see :func:`_whole_state`; else the event's rows), meets
    ``wall``. Returns how many balls' motion it changed (listed in ``wk.pending``)."""
    pos, vel, radius, body, omega, bounds = b.pos, b.vel, b.radius, b.body, b.omega, ph.bounds
    involved = wk.pending
    n = pos.shape[0]
    n_inv = 0
    if ph.sticky:
        axis = 0 if wall < 2 else 1
        into = vel[bi, axis] < 0.0 if wall % 2 == 0 else vel[bi, axis] > 0.0
        if wall_contact(bi, wall, pos, radius, bounds) and into:
            if omega[body[bi]] == 0.0:
                snap_to_wall(bi, wall, pos, radius, bounds)
            x, y = wall_point(bi, wall, pos, radius, bounds)
            record(wk.imp, wk.n_imp, sc, t_abs, bi, -1, wall, x, y, abs(vel[bi, axis]))
            root = body[bi]
            for k in range(n):
                if body[k] == root:
                    involved[n_inv] = k
                    n_inv += 1
            stop_body(bi, vel, body, omega)
        else:
            involved[0] = bi
            n_inv = 1
        return n_inv
    snap_to_wall(li, wall, pos, radius, bounds)
    u_min = impact_threshold(li, -1, vel, ph.ratio, ph.floor)
    speed = ball_wall(li, wall, vel, ph.e, u_min)
    if speed > 0.0:
        x, y = wall_point(li, wall, pos, radius, bounds)
        record(wk.imp, wk.n_imp, sc, t_abs, bi, -1, wall, x, y, speed)
    involved[0] = bi
    n_inv = 1
    if ph.cascades and speed > 0.0:
        n_inv = _cascade(sc, t_abs, bi, -1 - wall, b, ph, wk)
    return n_inv


@njit(inline="always")
def _resolve_pair(sc, t_abs, bi, bj, li, lj, b, ph, wk):
    """Balls ``bi`` and ``bj``, rows ``li`` and ``lj`` of ``b`` (as in :func:`_resolve_wall`), meet.
    Returns how many balls' motion it changed (listed in ``wk.pending``)."""
    pos, vel, radius, body = b.pos, b.vel, b.radius, b.body
    involved = wk.pending
    n = pos.shape[0]
    n_inv = 0
    dx = pos[lj, 0] - pos[li, 0]
    dy = pos[lj, 1] - pos[li, 1]
    dist = math.sqrt(dx * dx + dy * dy)
    closing = (vel[lj, 0] - vel[li, 0]) * dx + (vel[lj, 1] - vel[li, 1]) * dy
    if ph.sticky:
        if _touching(bi, bj, pos, radius) and closing < 0.0:
            x = pos[bi, 0] + radius[bi] * dx / dist
            y = pos[bi, 1] + radius[bi] * dy / dist
            record(wk.imp, wk.n_imp, sc, t_abs, bi, bj, -1, x, y, -closing / dist)
            root = merge_bodies(bi, bj, pos, vel, b.mass, body, b.omega)
            for k in range(n):
                if body[k] == root:
                    involved[n_inv] = k
                    n_inv += 1
        else:
            involved[0] = bi
            involved[1] = bj
            n_inv = 2
        return n_inv
    u_min = impact_threshold(li, lj, vel, ph.ratio, ph.floor)
    speed = ball_ball(li, lj, pos, vel, b.inv_mass, ph.e, u_min)
    if speed > 0.0:
        x = pos[li, 0] + radius[li] * dx / dist
        y = pos[li, 1] + radius[li] * dy / dist
        record(wk.imp, wk.n_imp, sc, t_abs, bi, bj, -1, x, y, speed)
    involved[0] = bi
    involved[1] = bj
    n_inv = 2
    if ph.cascades and speed > 0.0:
        n_inv = _cascade(sc, t_abs, bi, bj, b, ph, wk)
    return n_inv


# ---------------------------------------------------------------------------- pop, advance, invalidate
@njit(inline="always")
def _screen(bi, t, now, ph, cl, geo, wk):
    """Look at ball ``bi``'s popped event (due at ``t``) before it is run.

    Returns ``(n, t, now)``: ``n = -1``, an event to resolve at the re-verified time ``t``;
    otherwise there is none, and ``n`` balls (ball ``bi``, listed in ``wk.pending``) are to be
    predicted afresh: a stale pair, a grid-cell crossing (the ball moves to its new cell), or an
    event that no longer happens; or none (``n = 0``), when the event comes later than it said and
    was rescheduled."""
    code = cl.ci[bi, C_EVENT_OTHER]
    if cal.is_stale(bi, cl.rec, cl.ci):
        wk.counters[STALE_EVENTS] += 1
        wk.pending[0] = bi
        return 1, t, now
    if cal.is_crossing(code):
        wk.counters[CELL_CROSSINGS] += 1
        grid.unlink(bi, cl.rec, cl.ci, cl.heads)
        grid.link(bi, grid.neighbour_cell(cl.ci[bi, C_CELL], cal.EV_CROSS - code, geo[4]), cl.rec, cl.ci, cl.heads)
        wk.pending[0] = bi
        return 1, t, max(now, t)
    if ph.sticky:  # (rotating clusters' predictions are re-checked by the contact test instead)
        return -1, t, now
    t_check = _verified_time(bi, code, ph.bounds, ph.dim, cl.rec)
    if t_check <= t:
        return -1, t_check, now
    if t_check == INF:
        wk.pending[0] = bi
        return 1, t, now
    cl.rec[bi]["event_time"] = t_check
    cal.schedule(bi, cl.rec, cl.ci, cl.q)
    return 0, t, now


@njit(inline="always")
def _whole_state(ph):
    """The response works on the whole ball state, not on the event's two rows: in stick scenes,
    and in every step at e < 1 forward, where any event may start a contact group."""
    return ph.sticky or ph.cascades


@njit(inline="always")
def _advance(bi, bj, now, rot, in_place, b, cl, ph, wk):
    """Bring the balls of an event (``bj < 0``: a wall) to ``now``, in their records and in the
    rows the response reads: the whole ball state if ``in_place`` (:func:`_whole_state`), or else
    rows 0 and 1 of ``wk.event``."""
    if in_place:
        _sync_all(now, b.pos, b.vel, b.mass, b.body, b.omega, rot, ph.sticky, cl.rec)
    else:
        _take(bi, 0, now, cl, wk.event)
        if bj >= 0:
            _take(bj, 1, now, cl, wk.event)


@njit(inline="always")
def _invalidate(n_changed, now, ev, in_place, cl, wk):
    """The balls whose motion an event changed (``wk.pending``) take their new state into their
    records, from the rows the response changed (``ev``: the whole ball state if ``in_place``, else
    the event's rows, in the order of ``wk.pending``), and their change counters move on: events
    other balls hold with them become stale."""
    for q in range(n_changed):
        k = wk.pending[q]
        _load(k, now, cl.rec, ev.pos, ev.vel, k if in_place else q)
        cl.rec[k]["changes"] += 1


# ---------------------------------------------------------------------------- the scheduler
@njit(refcount=False)
def step_exact(
    balls,
    body_all,
    time,
    capped,
    fparams,
    iparams,
    imp,
    n_imp,
    counters,
    work_f,
    work_i,
    clock,
    cal_rec,
    cal_i,
    cal_heads,
    cal_heap,
    cal_buckets,
    cal_inv_mass,
    scratch_f,
    scratch_i,
    scratch_b,
    dt_abs,
    start,
):
    """Advance every active scene of the batch by its remaining time (see module doc).

    ``balls`` is the (B, N, 8) per-ball state (``layout.BALL``), ``body_all`` the (B, N) cluster
    roots, ``time`` the (B,) clocks; ``fparams``/``iparams`` the scene parameters
    (``layout.SCENE_F``/``SCENE_I``); ``work_f``/``work_i`` the per-scene bookkeeping and grid
    geometry (``layout.WORK_F``/``WORK_I``, which also hold the event queue's counts);
    ``cal_rec``/``cal_i``/``cal_heads``/``cal_heap``/``cal_buckets`` the persistent calendar records,
    its int rows, the grid's cell heads, and the event queue's heap and buckets
    (``layout.CAL_RECORD``/``CAL_I``/``HEAP``, :class:`~collision_env.engine.calendar.EventQueue`),
    ``cal_inv_mass`` the (B, N) inverse masses the calendar took with the radii;
    ``clock`` the compensated clocks (:mod:`~collision_env.engine.clock`), advanced when a scene's
    step ends. ``start`` is
    :data:`START_STEP` to start a step of ``dt_abs`` for every scene, :data:`START_NEXT` to start
    one right after a completed step of this kernel that nobody touched since (the balls need not
    be compared with their records), or :data:`RESUME` to resume the scenes flagged active.
    Impacts go to ``imp`` rows (``layout.IMPACT_DTYPE``) from row 0, ``n_imp[0]`` rows in all; a
    scene that finds the buffer full stops where it is and is flagged stalled, so the caller can
    empty the buffer and call again for those scenes. ``n_imp[1]`` counts the scenes that reached
    the event cap, ``n_imp[2]`` the stalled ones. Returns ``n_imp[0]`` when neither happened (the
    common case, read without looking at ``n_imp``), else -1.
    ``scratch_*`` are work buffers of :func:`scratch_sizes` (allocated once by the caller).

    The whole batch is one call with the scene loop inside: a call between compiled functions
    reference-counts every array it passes, which would cost as much as a small scene's events.
    """
    pos_all, vel_all, mass_all, inv_mass_all, radius_all, omega_all = ball_views(balls)
    n_imp[0] = 0
    n_scenes = pos_all.shape[0]
    n = pos_all.shape[1]
    ph = _physics(fparams, iparams)
    max_events = iparams[S_MAX_EVENTS]
    wk = _work(n, imp, n_imp, counters, scratch_f, scratch_i, scratch_b)
    room = impacts_per_event(n, ph.cascades)
    if start != RESUME:
        for sc in range(n_scenes):
            work_i[sc, W_ACTIVE] = True
            work_f[sc, W_REMAINING] = dt_abs
            work_f[sc, W_STALLED_AT] = 0.0
            work_i[sc, W_EVENTS] = 0
            capped[sc] = False
        n_imp[1] = 0
    n_imp[2] = 0
    for sc in range(n_scenes):
        if not work_i[sc, W_ACTIVE]:
            continue
        work_i[sc, W_STALLED] = False
        b = SceneBalls(
            pos_all[sc], vel_all[sc], mass_all[sc], inv_mass_all[sc], radius_all[sc], body_all[sc], omega_all[sc]
        )
        queue = cal.EventQueue(cal_heap[sc], cal_buckets[sc], work_f[sc], work_i[sc])
        cl = SceneCalendar(cal_rec[sc], cal_i[sc], cal_heads[sc], queue, cal_inv_mass[sc])
        geo = grid.scene_geometry(work_f, work_i, sc)
        horizon_end = work_f[sc, W_REMAINING]
        t0 = time[sc]
        now = work_f[sc, W_STALLED_AT]  # (0 at a step's start)
        rot = ph.sticky and has_rotation(b.body, b.omega)
        in_place = _whole_state(ph)  # (the rows an event is resolved on: see _advance)
        ev = b if in_place else wk.event

        # begin: everything afresh after a reset (and for rotating clusters, whose predictions reach
        # only to the end of a step), otherwise only the balls changed since the last step
        whole = not work_i[sc, W_CALENDAR_VALID] or rot
        if whole:
            n_pending = _begin_whole_scene(now, b, cl, geo, wk.pending)
        elif start == START_STEP:
            n_pending = _begin_changed_balls(b.pos, b.vel, cl.rec, cl.ci, cl.heads, geo, wk.pending)
        else:
            n_pending = 0

        walk = -1  # (see calendar.walk_next_bucket)
        while True:
            # predict (the one place where predictions are made: what begin or the last event listed)
            for q in range(n_pending):
                _predict(wk.pending[q], now, horizon_end - now, whole, rot, b, cl, ph, geo, wk)
            if whole:
                cal.reset_queue(n, now, cal.bucket_width(n, now, cl.rec), cl.rec, cl.ci, cl.q)
                work_i[sc, W_CALENDAR_VALID] = True
                whole = False
            # pop
            bi = cal.next_ball(cl.rec, cl.ci, cl.q)
            if bi < 0:
                break
            _prefetch_popped(bi, cl, geo)
            walk = cal.walk_next_bucket(walk, cl.rec, cl.ci, cl.q)
            t = cl.rec[bi]["event_time"]
            if not t <= horizon_end:
                break
            n_pending, t, now = _screen(bi, t, now, ph, cl, geo, wk)
            if n_pending >= 0:
                continue
            if work_i[sc, W_EVENTS] >= max_events:
                capped[sc] = True
                break
            if n_imp[0] + room > imp.shape[0]:
                work_i[sc, W_STALLED] = True
                break
            # advance (a pair is resolved, and reported, from its lower ball)
            now = max(now, t)
            code = cl.ci[bi, C_EVENT_OTHER]
            if code >= 0:
                _prefetch_partner(code, cl, geo)
            bj = max(bi, code) if code >= 0 else -1
            bi = min(bi, code) if code >= 0 else bi
            _advance(bi, bj, now, rot, in_place, b, cl, ph, wk)
            work_i[sc, W_EVENTS] += 1
            counters[EVENTS] += 1
            # resolve (the balls whose motion changed are listed in ``wk.pending``)
            t_abs = t0 + ph.sign * now
            li = bi if in_place else 0
            if bj < 0:
                n_pending = _resolve_wall(sc, t_abs, bi, li, cal.EV_WALL - code, ev, ph, wk)
            else:
                n_pending = _resolve_pair(sc, t_abs, bi, bj, li, bj if in_place else 1, ev, ph, wk)
            if ph.sticky:
                rot = has_rotation(b.body, b.omega)
            # invalidate (the changed balls are predicted afresh at the top of the loop)
            _invalidate(n_pending, now, ev, in_place, cl, wk)

        if work_i[sc, W_STALLED]:  # the next call goes on from here, as if nothing had stopped it
            work_f[sc, W_STALLED_AT] = now
            n_imp[2] += 1
            continue
        # finish
        t_end = now if capped[sc] else horizon_end
        _finish(t_end, b.pos, b.vel, b.mass, b.body, b.omega, rot, ph.sticky, cl.rec, cl.ci, cl.q)
        time[sc] = t0 + ph.sign * t_end
        work_f[sc, W_REMAINING] = horizon_end - t_end
        n_imp[1] += capped[sc]
        work_i[sc, W_ACTIVE] = False
        finish_step(sc, not capped[sc], ph.sign * dt_abs, time, clock)
    return n_imp[0] if n_imp[1] == 0 and n_imp[2] == 0 else -1


if HAVE_NUMBA:

    @njit(inline="always")
    def unpack_state(h):
        """Slots 0 to 11 of a pack (:mod:`~collision_env.engine.argpack`): the arrays every mode's
        kernel takes first, in order (the balls, cluster roots, clocks, cap flags, scene
        parameters, impact buffer and counts, work counters, per-scene work arrays and compensated
        clocks)."""
        return (
            view3(h, 0, np.float64),
            view2(h, 1, np.int64),
            view1(h, 2, np.float64),
            view1(h, 3, np.bool_),
            view1(h, 4, np.float64),
            view1(h, 5, np.int64),
            view1(h, 6, IMPACT_DTYPE),
            view1(h, 7, np.int64),
            view1(h, 8, np.int64),
            view2(h, 9, np.float64),
            view2(h, 10, np.int64),
            view2(h, 11, np.float64),
        )

    @njit
    def step_exact_packed(h, dt_abs, start):
        """:func:`step_exact` on the arrays packed in ``h`` (:mod:`~collision_env.engine.argpack`),
        one slot per array in the order of its parameters; the call Python makes, with one array
        to check instead of twenty."""
        return step_exact(
            *unpack_state(h),
            view2(h, 12, CAL_RECORD),
            view3(h, 13, np.int32),
            view2(h, 14, np.int32),
            view3(h, 15, np.float64),
            view2(h, 16, np.int32),
            view2(h, 17, np.float64),
            view1(h, 18, np.float64),
            view1(h, 19, np.int64),
            view1(h, 20, np.bool_),
            dt_abs,
            start,
        )
