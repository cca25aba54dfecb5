"""Contact groups: an impact inside a group of touching balls, resolved at one instant (e < 1).

At e < 1 an impact inside a touching group (a train pressed against a wall, a crowd, a pile) starts
a cascade of ever smaller impulses at the same instant: sequential impulses converge to the limit
geometrically. A contact group's cascade (:func:`cascade_kernel`) is resolved here, without
re-predicting every ball after each impulse, in bounded work that grows about linearly with the
group's size:

1. **Gather** the group, every ball connected to the impact through contacts (gaps within the
   contact tolerance of zero), breadth first, through the neighbour grid (the 3 x 3 cells around a
   ball; all balls in a scene too small for a grid), and in a periodic cell through the minimum
   images (:mod:`~collision_env.engine.physics.periodic`), as in a box. Its contacts are listed in a
   fixed order along the group (from the impact outwards), each with its separation vector.
2. **Sweep** the contacts, applying the same pairwise impulses as the event loop would, one after
   another (sequential impulses), until a sweep changes nothing; the collapse regulariser
   (:mod:`~collision_env.engine.physics.response`) ends every cascade among comparable masses
   within a few dozen sweeps. The sweeps of one group are bounded: :data:`MAX_SWEEPS`, and at most
   :data:`SWEEP_WORK` contact visits in all (so a group of many contacts gets fewer sweeps, at least
   :data:`MIN_SWEEPS`); sweeps that would take the step past its event budget give way to the limit.
   Under the TC model (``contact_duration`` > 0) each contact's restitution is 1 when either of its
   balls' previous collision instants, before the group's, is within ``t_c`` of it
   (``response.restitution``); the group's instant is recorded once it is resolved.
3. A cascade still running then is replaced by its **limit** (the settles below): the velocities
   closest to the current ones in the kinetic-energy metric at which every contact of the group
   separates at ``u_min`` or faster, a least-distance problem (Lawson & Hanson 1974, ch. 23):

   - a group of at most :data:`DENSE_BALLS` balls: exactly, dense (:func:`settle`, ``ldp``);
   - a row (every contact along one axis, each ball touching at most one ball on either side, walls
     only at its ends): exactly, in linear time (:func:`_settle_row`). With ``z_k = v_k' - k u_min``
     along the row the contacts say ``z`` is non-decreasing, and walls bound its ends, so the limit
     is a weighted isotonic regression clipped to the walls' bounds, which the pool-adjacent-
     violators algorithm solves in one pass (Ayer, Brunk, Ewing, Reid & Silverman 1955; Best &
     Chakravarti, *Math. Programming* 47, 1990, for its linear cost);
   - any other group (a pile, a cluster, a ring round a periodic cell): by an accelerated projected
     gradient on the dual of that problem, whose unknowns are the contact impulses, kept
     non-negative (Nesterov 1983; Beck & Teboulle, *SIAM J. Imaging Sci.* 2, 2009, with the restart
     of O'Donoghue & Candes, *Found. Comput. Math.* 15, 2015; applied to contact by Mazhar, Heyn,
     Negrut & Tasora, *ACM Trans. Graph.* 34, 2015), each iteration a few passes over the contacts,
     until every contact separates at ``u_min / 2`` or faster, in at most :data:`SETTLE_WORK`
     contact visits (:func:`_settle_accelerated`). Its iterations need about the square root of
     the condition number that Gauss-Seidel sweeps need (a pile of H layers: about H, not H^2, per
     digit). Every iterate conserves momentum (ball-ball impulses are equal and opposite) and
     gains no energy beyond the regulariser's allowance (the dual objective never rises above 0). A
     group still not separated then takes its centre-of-mass velocity, or stops when a wall is
     among its contacts (:func:`_stop_group`, the last resort).

Work is counted: each sweep, each iteration of the limit and each impulse is one unit towards the
step's event cap (``max_events``). Sweeps that reach the budget give way to the limit (dense or in
one pass: bounded by the group's size); an accelerated limit that reaches it stops there, in a
valid state (no ball moved, every impulse conserves momentum), and the step stops at the cap. Every
contact that takes an impulse is reported once.

Only scenes at e < 1 compile this module's kernels (see the scheduler's kinds of scene).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._jit import njit
from ..broadphase import block
from ..layout import C_CELL, EVENTS
from ..physics.impacts import record
from ..physics.ldp import least_distance
from ..physics.periodic import cell_lengths, nearest
from ..physics.response import ball_ball_along, ball_wall, group_threshold, normal_impulse, restitution
from ..physics.tolerance import balls_touch, touching_at
from ..physics.walls import is_low_wall, wall_axis, wall_contact, wall_count, wall_normal, wall_point
from . import grid
from .periodic import neighbour
from .trajectories import take_in_place

#: Sweeps of sequential impulses over a contact group in one instant before the cascade is replaced
#: by its limit. Cascades among comparable masses end within a few dozen sweeps; the criterion is a
#: count, so it does not depend on the masses, and the limit always ends the cascade.
MAX_SWEEPS = 1000
#: Contact visits the sequential sweeps of a group of more than :data:`DENSE_BALLS` balls may take
#: in all (``SWEEP_WORK // contacts`` sweeps, at least :data:`MIN_SWEEPS`); smaller groups get
#: :data:`MAX_SWEEPS`.
SWEEP_WORK = 2**14
#: Fewest sweeps of sequential impulses a group gets, however many contacts it has.
MIN_SWEEPS = 8
#: Rows of at least this many balls at e = 0 go to their limit after :data:`MIN_SWEEPS` sweeps, in
#: one pass (plastic sequential impulses along a row of L balls need about L^2 sweeps per digit,
#: and end where the limit is, up to the regulariser's ``u_min``).
PLASTIC_ROW_BALLS = 3
#: A contact whose normal is within this slope of an axis lies along it, for a row
#: (:func:`_row_axis`): balls stacked in a column drift apart sideways by round-off (a position
#: moved in one long stretch and one moved in many short ones round differently), and the row's
#: limit takes the tilt into account in its contacts' separations (its impulses, along the axis,
#: leave out their share of ``ROW_SLOPE`` across it).
ROW_SLOPE = 2.0**-40
#: Groups of up to this many balls go to their limit by the dense least-distance solve.
DENSE_BALLS = 32
#: Contact visits (each of a few passes) the accelerated limit of one group may take (at least
#: :data:`MIN_SETTLE_ITERATIONS` iterations).
SETTLE_WORK = 2**21
#: The accelerated limit is sought to this fraction of the group's fastest closing speed: no contact
#: an impulse pushes separates faster than that above ``u_min``.
SETTLE_RTOL = 1e-8
#: Fewest iterations the accelerated limit of a group gets.
MIN_SETTLE_ITERATIONS = 256

#: Columns of ``Work.c_f``, per contact: its separation vector (from ``c_a`` to ``c_b``; 0 for a
#: wall), its unit normal, its closing speed when the limit is sought (what the reports give), the
#: limit's impulses (the accelerated projected gradient's iterate, its extrapolated point and its
#: candidate) and its shortfall from separating at ``u_min`` at the start of that pass (``h``).
C_F = ("dx", "dy", "nx", "ny", "closing", "lam", "y", "z", "shortfall")
F_DX, F_DY, F_NX, F_NY, F_CLOSING, F_LAM, F_Y, F_Z, F_SHORTFALL = range(len(C_F))
#: How a phase of a cascade ended: every contact separating, still running, or out of budget.
DONE, OPEN, CAPPED = range(3)
#: Columns of ``Work.g_f`` in the accelerated limit, per group place: velocities before it, and at
#: its last iterate (x and y each).
_V0, _V_LAM = 0, 2
#: Columns of ``Work.g_f`` in a row's limit, per group place: its contact with the next ball's
#: slope off the axis and 1 / its normal's component along it (:func:`_row_axis`).
_TILT = 2
#: In a row's neighbour links: a wall.
_WALL = -2


def contact_capacity(n: int) -> int:
    """Most contacts a contact group of ``n`` balls can have: the contact graph of disks that do not
    overlap is planar (at most 3n - 6 edges), and a ball touches at most two walls (four in a box
    no wider than the ball)."""
    return 3 * n + 4 * n + 8


_CASCADES: dict = {}


def cascade_kernel(periodic: bool) -> Any:
    """The contact-group kernel of scenes in a box (``periodic`` False) or a periodic cell:
    ``cascade(sc, t_abs, now, i0, j0, budget, b, ph, cl, geo, wk) -> (size, work, capped)``.

    It resolves, at one instant, every contact of the group of touching balls an impact started
    (see the module doc). The impact was between ball ``i0`` and ball ``j0``, or the wall
    ``-1 - j0`` when ``j0 < 0``; the caller has applied and reported it, so that contact is not
    reported again here (one collision, one report, even when round-off leaves it closing at
    ~1e-16 m/s after a plastic impulse). The group's regulariser speed comes from its own balls when
    it is formed (``response.group_threshold``). ``b`` is the whole ball state of the scene, ``now``
    the impact's step time: the impact's balls are there in ``b`` (resolved), and every ball the
    group looks at is brought there from its record in the calendar ``cl`` (whose grid ``geo``
    finds neighbours), so that an impact costs the balls around it, not the scene. Returns the group size (its
    balls are listed in ``wk.pending``), the work done (sweeps and impulses) and whether ``budget``
    ran out before the cascade ended."""
    if periodic in _CASCADES:
        return _CASCADES[periodic]

    @njit(inline="always")
    def separation(a, k, pos, bounds, dim):
        """Ball ``k``'s centre from ball ``a``'s (through the nearest image in a periodic cell)."""
        if periodic:
            lx, ly = cell_lengths(bounds, dim)
            return nearest(pos[k, 0] - pos[a, 0], lx), nearest(pos[k, 1] - pos[a, 1], ly)
        return pos[k, 0] - pos[a, 0], pos[k, 1] - pos[a, 1]

    @njit(inline="always")
    def touching(a, now, b, ph, cl, geo, wk):
        """The balls touching ball ``a``, each once, into ``wk.near``; returns how many. Each ball
        looked at that is not in the group yet is first brought to step time ``now`` in its record
        and in its row of ``b`` (the group's balls are there already: the impact's two, resolved,
        and every other one since it joined)."""
        pos, radius, near = b.pos, b.radius, wk.near
        count = 0
        if periodic:
            lx, ly = cell_lengths(ph.bounds, ph.dim)
            reach_y = 1 if ly > 0.0 else 0
            c = cl.ci[a, C_CELL]
            for oy in range(-reach_y, reach_y + 1):
                for ox in range(-1, 2):
                    k = cl.heads[neighbour(c, oy, ox, geo.nx, geo.ny, lx, ly)[0]]
                    while k >= 0:
                        # (with one or two cells along an axis a cell comes round more than once)
                        if k != a and not wk.in_group[k]:
                            _bring(k, now, b, cl, wk)
                            dx, dy = separation(a, k, pos, ph.bounds, ph.dim)
                            if touching_at(a, k, dx, dy, pos, radius):
                                wk.in_group[k] = True
                                near[count] = k
                                count += 1
                        k = cl.rec[k]["cell_next"]
            for q in range(count):
                wk.in_group[near[q]] = False
        elif grid.has_cells(geo):
            cx0, cx1, cy0, cy1 = block(cl.ci[a, C_CELL], geo.nx, geo.ny)
            for cy in range(cy0, cy1 + 1):
                for cx in range(cx0, cx1 + 1):
                    k = cl.heads[cy * geo.nx + cx]
                    while k >= 0:
                        _bring(k, now, b, cl, wk)
                        if k != a and balls_touch(a, k, pos, radius):
                            near[count] = k
                            count += 1
                        k = cl.rec[k]["cell_next"]
        else:
            for k in range(pos.shape[0]):
                _bring(k, now, b, cl, wk)
                if k != a and balls_touch(a, k, pos, radius):
                    near[count] = k
                    count += 1
        return count

    @njit(inline="always")
    def gather(i0, j0, now, b, ph, cl, geo, wk):
        """Every ball connected to the impact's balls through contacts, into ``wk.pending``, breadth
        first (a ball's new neighbours in index order), each with its place in ``wk.slot``, and the
        group's contacts, each once, in a fixed order (``wk.c_a``, ``wk.c_b``; ``wk.c_hit`` marks
        the impact's own): each ball's partners of later place in the group in the order of their
        places, then its walls, each with its separation (``wk.c_f[:, :2]``, from ``c_a`` to
        ``c_b``) and normal. A ball's partners are all in the group once its neighbours have
        joined, so one look at the balls around it gives both. Returns how many balls and
        contacts."""
        group, slot, near = wk.pending, wk.slot, wk.near
        size = 0
        for start in (i0, j0):  # j0 < 0: a wall
            if start >= 0 and slot[start] < 0:
                group[size] = start
                slot[start] = size
                size += 1
        n_contacts = 0
        q = 0
        while q < size:
            a = group[q]
            if ph.pairs:
                m = touching(a, now, b, ph, cl, geo, wk)
                _sort_by(near, m, slot, False)
                later = 0
                for t in range(m):
                    k = near[t]
                    if slot[k] < 0:
                        group[size] = k
                        slot[k] = size
                        size += 1
                    if slot[k] > q:
                        near[later] = k
                        later += 1
                _sort_by(near, later, slot, True)
                for t in range(later):
                    k = near[t]
                    lo = min(a, k)
                    hi = max(a, k)
                    wk.c_a[n_contacts] = lo
                    wk.c_b[n_contacts] = hi
                    wk.c_hit[n_contacts] = j0 >= 0 and lo == min(i0, j0) and hi == max(i0, j0)
                    dx, dy = separation(lo, hi, b.pos, ph.bounds, ph.dim)
                    d = math.sqrt(dx * dx + dy * dy)
                    wk.c_f[n_contacts, F_DX] = dx
                    wk.c_f[n_contacts, F_DY] = dy
                    wk.c_f[n_contacts, F_NX] = dx / d
                    wk.c_f[n_contacts, F_NY] = dy / d
                    n_contacts += 1
            if ph.has_walls:
                for wall in range(wall_count(ph.dim)):
                    if wall_contact(a, wall, b.pos, b.radius, ph.bounds):
                        wk.c_a[n_contacts] = a
                        wk.c_b[n_contacts] = -1 - wall
                        wk.c_hit[n_contacts] = a == i0 and j0 == -1 - wall
                        wk.c_f[n_contacts, F_DX] = 0.0
                        wk.c_f[n_contacts, F_DY] = 0.0
                        wk.c_f[n_contacts, F_NX], wk.c_f[n_contacts, F_NY] = wall_normal(wall)
                        n_contacts += 1
            q += 1
        return size, n_contacts

    @njit(refcount=False, python=False)
    def cascade(sc, t_abs, now, i0, j0, budget, b, ph, cl, geo, wk):
        size, n_contacts = gather(i0, j0, now, b, ph, cl, geo, wk)
        u_min = group_threshold(wk.pending, size, b.vel, b.inv_mass, ph.ratio, ph.floor)
        small = size <= DENSE_BALLS
        # (a plastic row's sweeps end only after about its length squared: it goes to its limit at once)
        plastic_row = ph.e == 0.0 and size >= PLASTIC_ROW_BALLS and _row_axis(size, n_contacts, wk) >= 0
        sweeps = MAX_SWEEPS if small else min(MAX_SWEEPS, max(MIN_SWEEPS, SWEEP_WORK // n_contacts))
        if plastic_row:
            sweeps = MIN_SWEEPS
        for start in (i0, j0):  # (the impact's balls moved; the sweeps mark the others they move)
            if start >= 0:
                wk.in_group[start] = True
        # (the sweeps leave room in the budget for the limit's reports, should they not end)
        outcome, work = _sweep(sc, t_abs, n_contacts, u_min, sweeps, budget - n_contacts - 2, b, ph, cl.last_impact, wk)
        if outcome == OPEN:
            outcome, more = settle_group(sc, t_abs, size, n_contacts, u_min, plastic_row, budget - work, b, ph, wk)
            work += more
        _record_instant(t_abs, i0, j0, n_contacts, cl.last_impact, wk)
        for q in range(size):
            wk.slot[wk.pending[q]] = -1
            wk.in_group[wk.pending[q]] = False
        return size, work, outcome == CAPPED

    _CASCADES[periodic] = cascade
    return cascade


@njit(inline="always")
def _sort_by(items, count, slot, by_slot):
    """Sort ``items[:count]`` (balls) in place by index, or ``by_slot`` by their places in the group
    (insertion sort: a ball's contacts are few)."""
    for t in range(1, count):
        item = items[t]
        key = slot[item] if by_slot else item
        u = t - 1
        while u >= 0 and (slot[items[u]] if by_slot else items[u]) > key:
            items[u + 1] = items[u]
            u -= 1
        items[u + 1] = item


@njit(refcount=False, forceinline=True)
def _bring(k, now, b, cl, wk):
    """Ball ``k``, if not in the group being gathered, moved in its record to step time ``now`` and
    into its row of the ball state (events leave the rows of the balls they do not touch behind)."""
    if wk.slot[k] < 0:
        take_in_place(k, now, cl.rec, b)


@njit(refcount=False, python=False)
def _record_instant(t_abs, i0, j0, n_contacts, last, wk):
    """The TC model's record of a contact group's instant ``t_abs``, once the group is resolved: the
    last collision instant (``last``) of the impact's balls and of every ball of a contact that took
    an impulse (was reported)."""
    for c in range(n_contacts):
        if wk.c_hit[c]:
            last[wk.c_a[c]] = t_abs
            if wk.c_b[c] >= 0:
                last[wk.c_b[c]] = t_abs
    last[i0] = t_abs
    if j0 >= 0:
        last[j0] = t_abs


@njit(inline="always")
def _sweep(sc, t_abs, n_contacts, u_min, sweeps, budget, b, ph, last, wk):
    """Sweep the contacts, applying each one's impulse, until a sweep changes nothing (:data:`DONE`),
    or ``sweeps`` sweeps have or the work reaches ``budget`` (:data:`OPEN`: the limit is to end the
    cascade); returns that and the work done (sweeps and impulses). Each contact's restitution is the
    scene's, or 1 under the TC model (``last``: its balls' previous collision instants)."""
    work = 0
    for _ in range(sweeps):
        if work >= budget:
            return OPEN, work
        work += 1
        changed = False
        for c in range(n_contacts):
            a = wk.c_a[c]
            other = wk.c_b[c]
            e = restitution(ph.e, ph.contact_duration, t_abs, last, a, other)
            if other >= 0:
                speed = ball_ball_along(a, other, wk.c_f[c, F_DX], wk.c_f[c, F_DY], b.vel, b.inv_mass, e, u_min)
            else:
                speed = ball_wall(a, -1 - other, b.vel, e, u_min)
            if speed > 0.0:
                changed = True
                wk.in_group[a] = True
                if other >= 0:
                    wk.in_group[other] = True
                work += 1
                wk.counters[EVENTS] += 1
                w = _contact_inv_mass(c, wk.c_a, wk.c_b, b.inv_mass)
                _record_contact(sc, t_abs, c, speed, normal_impulse(speed, e, u_min, w), b, ph, wk)
                if work >= budget:
                    return OPEN, work
        if not changed:
            return DONE, work
    return OPEN, work


@njit(inline="always")
def _contact_normal(c, c_f):
    """Unit normal of contact ``c``, pointing from its ball ``c_a[c]`` to its partner (ball or wall)."""
    return c_f[c, F_NX], c_f[c, F_NY]


@njit(inline="always")
def _contact_inv_mass(c, c_a, c_b, inv_mass):
    """``w_a + w_b`` of contact ``c`` (``w_a`` alone for a wall)."""
    other = c_b[c]
    return inv_mass[c_a[c]] + (inv_mass[other] if other >= 0 else 0.0)


@njit(inline="always")
def _record_contact(sc, t_abs, c, speed, impulse, b, ph, wk):
    """Report contact ``c`` of a group the first time it takes an impulse, with that impulse's
    closing speed and normal impulse (N s). (In a periodic cell the caller wraps the point.)"""
    if wk.c_hit[c]:
        return
    wk.c_hit[c] = True
    a = wk.c_a[c]
    other = wk.c_b[c]
    pos, radius = b.pos, b.radius
    if other >= 0:
        nx, ny = _contact_normal(c, wk.c_f)
        x = pos[a, 0] + radius[a] * nx
        y = pos[a, 1] + radius[a] * ny
        record(wk.imp, wk.n_imp, sc, t_abs, a, other, -1, x, y, speed, impulse)
    else:
        x, y = wall_point(a, -1 - other, pos, ph.bounds)
        record(wk.imp, wk.n_imp, sc, t_abs, a, -1, -1 - other, x, y, speed, impulse)


@njit(python=False)
def settle_group(sc, t_abs, size, n_contacts, u_min, row, budget, b, ph, wk):
    """Replace a cascade still running after its sweeps by its limit (see the module doc): dense for
    a small group; for a large one, first over the balls the cascade moved (a column a ball landed
    on, in a pile), then over the whole group should that close a contact with the rest, each in
    one pass for a row, accelerated otherwise; then the last-resort check, and the report of every
    contact that was closing (``row``: the group is a row, at e = 0: in one pass whatever its
    size). Returns the outcome and the work."""
    closing, fastest = _closing_speeds(n_contacts, b, wk)
    slack = 16.0 * 2.0**-52 * fastest
    if row and _settle_row(size, n_contacts, u_min, b, wk):
        outcome, work = DONE, 1
    elif size <= DENSE_BALLS:
        settle(size, n_contacts, u_min, b, wk)
        outcome, work = DONE, 1
    else:
        # first the part the cascade moved, then, if that closes a contact with the rest, the whole
        moved, inner = _moved_first(size, n_contacts, wk)
        outcome, work = _settle_large(moved, inner, u_min, fastest, budget, b, wk)
        if outcome == DONE and moved < size and not _contacts_open(b.vel, n_contacts, wk, slack):
            outcome, more = _settle_large(size, n_contacts, u_min, fastest, budget - work, b, wk)
            work += more
    if outcome != CAPPED and not _contacts_open(b.vel, n_contacts, wk, slack):
        _stop_group(b.vel, b.inv_mass, wk.pending, size, wk.c_b, n_contacts)
    for c in range(n_contacts):
        if closing[c] > 0.0:
            work += 1
            wk.counters[EVENTS] += 1
            # (the two-body impulse from the contact's closing speed and its separation speed in the limit)
            sep = _separation(c, b.vel, wk)
            impulse = (closing[c] + sep) / _contact_inv_mass(c, wk.c_a, wk.c_b, b.inv_mass)
            _record_contact(sc, t_abs, c, closing[c], impulse, b, ph, wk)
    return outcome, work


@njit(refcount=False, python=False)
def _settle_large(size, n_contacts, u_min, fastest, budget, b, wk):
    """The limit of the first ``size`` balls of a large group over its first ``n_contacts``
    contacts: in one pass for a row, else accelerated. Returns the outcome and the work."""
    if _settle_row(size, n_contacts, u_min, b, wk):
        return DONE, 1
    iterations = max(MIN_SETTLE_ITERATIONS, SETTLE_WORK // n_contacts)
    accuracy = SETTLE_RTOL * fastest
    return _settle_accelerated(size, n_contacts, u_min, accuracy, iterations, budget, b, wk)


@njit(refcount=False, python=False)
def _moved_first(size, n_contacts, wk):
    """Reorder a group: the balls the cascade moved (marked in ``wk.in_group``) first, in group
    order, and the contacts among them (and their walls) first. Returns how many of each."""
    group, slot, order = wk.pending, wk.slot, wk.near
    moved = 0
    for q in range(size):
        if wk.in_group[group[q]]:
            order[moved] = group[q]
            moved += 1
    rest = moved
    for q in range(size):
        if not wk.in_group[group[q]]:
            order[rest] = group[q]
            rest += 1
    for q in range(size):
        group[q] = order[q]
        slot[group[q]] = q
    inner = 0
    for c in range(n_contacts):
        other = wk.c_b[c]
        if wk.in_group[wk.c_a[c]] and (other < 0 or wk.in_group[other]):
            _swap_contacts(c, inner, wk)
            inner += 1
    return moved, inner


@njit(inline="always")
def _swap_contacts(c, d, wk):
    """Swap contacts ``c`` and ``d`` of a group's list, everything about them."""
    if c != d:
        wk.c_a[c], wk.c_a[d] = wk.c_a[d], wk.c_a[c]
        wk.c_b[c], wk.c_b[d] = wk.c_b[d], wk.c_b[c]
        wk.c_hit[c], wk.c_hit[d] = wk.c_hit[d], wk.c_hit[c]
        for k in range(wk.c_f.shape[1]):
            wk.c_f[c, k], wk.c_f[d, k] = wk.c_f[d, k], wk.c_f[c, k]


@njit(python=False)
def _closing_speeds(n_contacts, b, wk):
    """Each contact's closing speed (``wk.c_f[:, F_CLOSING]``, a view of it is returned) and the largest
    normal speed of any contact."""
    fastest = 0.0
    for c in range(n_contacts):
        sep = _separation(c, b.vel, wk)
        wk.c_f[c, F_CLOSING] = -sep
        fastest = max(fastest, abs(sep))
    return wk.c_f[:, F_CLOSING], fastest


@njit(python=False)
def settle(size, n_contacts, u_min, b, wk):
    """The limit of a small group's cascade, dense: the velocities closest to the current ones in
    the kinetic-energy metric at which every contact of the group separates at ``u_min`` or faster
    (a least-distance problem in mass-weighted velocities, solved by ``ldp.least_distance`` whatever
    the mass ratio). Momentum is conserved by ball-ball impulses and energy does not grow by more
    than the regulariser's ``u_min`` allowance. Where no velocities separate every contact (a chain
    wedged between opposite walls), the contacts are brought to rest instead, which is always
    possible. (A light ball pressed between a wall and a ball ``M/m`` times heavier gets there by
    sequential impulses only after about ``M/m`` sweeps.)"""
    group, c_a, c_b, vel = wk.pending, wk.c_a, wk.c_b, b.vel
    dof = 2 * size
    g_mat = np.zeros((n_contacts, dof))
    h = np.empty(n_contacts)
    slot = wk.slot
    root_w = np.empty(size)
    for q in range(size):
        root_w[q] = math.sqrt(b.inv_mass[group[q]])
    for c in range(n_contacts):
        a = c_a[c]
        other = c_b[c]
        nx, ny = _contact_normal(c, wk.c_f)
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


@njit(refcount=False, python=False)
def _row_axis(size, n_contacts, wk):
    """The axis (0: x, 1: y) along which the group is a row, with each place's neighbours along it
    in ``wk.g_i`` (low side, high side; -1: none, ``_WALL``: a wall), or -1 if it is not one: a
    contact more than :data:`ROW_SLOPE` off the axis, a wall across it, or a ball with two
    neighbours on one side. Each place with a ball on its high side gets that contact's normal
    (from low to high) in ``wk.g_f[:, _TILT]``: its slope off the axis and ``1 / its component
    along it`` (0 and 1 for a contact right along it)."""
    links, slot, g_f = wk.g_i, wk.slot, wk.g_f
    for q in range(size):
        links[q, 0] = -1
        links[q, 1] = -1
    axis = -1
    for c in range(n_contacts):
        a = wk.c_a[c]
        other = wk.c_b[c]
        if other >= 0:
            nx, ny = _contact_normal(c, wk.c_f)
            along = 0 if abs(ny) <= ROW_SLOPE * abs(nx) else 1 if abs(nx) <= ROW_SLOPE * abs(ny) else -1
            if along < 0:
                return -1
            ahead = (nx if along == 0 else ny) > 0.0  # (the partner on the high side)
            low = slot[a] if ahead else slot[other]
            high = slot[other] if ahead else slot[a]
            n_along = abs(nx if along == 0 else ny)
            g_f[low, _TILT] = (ny if along == 0 else nx) * (1.0 if ahead else -1.0) / n_along
            g_f[low, _TILT + 1] = 1.0 / n_along
        else:
            wall = -1 - other
            along = wall_axis(wall)
            low = _WALL if is_low_wall(wall) else slot[a]
            high = slot[a] if is_low_wall(wall) else _WALL
        if axis >= 0 and along != axis:
            return -1
        axis = along
        if (low >= 0 and links[low, 1] != -1) or (high >= 0 and links[high, 0] != -1):
            return -1
        if low >= 0:
            links[low, 1] = high
        if high >= 0:
            links[high, 0] = low
    return axis


@njit(inline="always")
def _row_gap(k, u, axis, order, vel, wk):
    """How much faster than ball ``order[k]`` the next ball along a row must move along its axis for
    their contact to separate at ``u``, given their velocities across it (which the row's limit
    keeps): ``(u - dv_across * n_across) / n_along``, minus ``u`` (0 for a contact right along it)."""
    q = wk.slot[order[k]]
    tilt = wk.g_f[q, _TILT]
    across = 1 - axis
    return u * (wk.g_f[q, _TILT + 1] - 1.0) - (vel[order[k + 1], across] - vel[order[k], across]) * tilt


@njit(refcount=False, python=False)
def _settle_row(size, n_contacts, u_min, b, wk):
    """The limit of a row's cascade in one pass, if the group is a row (else False, nothing changed):
    with ``z_k = v_k - U_k`` along the row, ``U_k`` the separation speeds its contacts before place
    ``k`` ask for along the axis (``k u`` with ``u = u_min`` for contacts right along it; a tilted
    contact's, :func:`_row_gap`, allows for the balls' velocities across the row, which the limit
    keeps), the contacts ask for ``z`` non-decreasing, a wall at the low end for ``z >= u`` and one
    at the high end for ``z <= -u - U_{L-1}`` (``L`` balls), so the limit is the mass-weighted
    isotonic regression of ``z`` (pool adjacent violators) clipped to those bounds. With walls at
    both ends the contacts come to rest instead (``u = 0``), and where tilted contacts leave no room
    between the two walls' bounds the row is left to the general limit (False)."""
    axis = _row_axis(size, n_contacts, wk)
    if axis < 0:
        return False
    links, order, vel, inv_mass = wk.g_i, wk.near, b.vel, b.inv_mass
    start = 0
    while links[start, 0] >= 0:  # (a connected row has one low end; a ring has none)
        start += 1
        if start == size:
            return False
    length = 0
    q = start
    while q >= 0:
        order[length] = wk.pending[q]
        length += 1
        q = links[q, 1]
    if length != size:
        return False
    low_wall = links[start, 0] == _WALL
    high_wall = links[wk.slot[order[length - 1]], 1] == _WALL
    u = u_min
    if low_wall and high_wall:
        u = 0.0
    lo = u if low_wall else -math.inf
    hi = -length * u if high_wall else math.inf
    # pool adjacent violators: blocks of (weight, weighted sum, first place along the row); the
    # offset of place k is k u plus the tilted contacts' gaps before it (``tilted``)
    weight, total = wk.g_f[:, 0], wk.g_f[:, 1]
    first = wk.g_i[:, 0]  # (the links are read no more)
    blocks = 0
    tilted = 0.0
    for k in range(length):
        i = order[k]
        m = 1.0 / inv_mass[i]
        weight[blocks] = m
        total[blocks] = m * (vel[i, axis] - (k * u + tilted))
        first[blocks] = k
        blocks += 1
        while blocks > 1 and total[blocks - 2] / weight[blocks - 2] > total[blocks - 1] / weight[blocks - 1]:
            weight[blocks - 2] += weight[blocks - 1]
            total[blocks - 2] += total[blocks - 1]
            blocks -= 1
        if k + 1 < length:
            tilted += _row_gap(k, u, axis, order, vel, wk)
    hi -= tilted  # (the high wall bounds the last place, whose offset has the whole row's gaps)
    if hi < lo:  # (walls at both ends that tilted contacts moving apart across the row cannot both keep)
        return False
    tilted = 0.0
    for blk in range(blocks):
        z = min(max(total[blk] / weight[blk], lo), hi)
        end = first[blk + 1] if blk + 1 < blocks else length
        for k in range(first[blk], end):
            gap = _row_gap(k, u, axis, order, vel, wk) if k + 1 < length else 0.0
            vel[order[k], axis] = z + (k * u + tilted)
            tilted += gap
    return True


@njit(refcount=False, python=False)
def _lipschitz(size, n_contacts, inv_mass, wk):
    """A bound on the largest eigenvalue of the group's Delassus matrix ``A = G M^-1 G^T`` (row sums,
    Gershgorin): each contact's ``w_a deg_a + w_b deg_b`` at most, ``deg`` a ball's contacts."""
    deg = wk.g_i[:, 0]
    for q in range(size):
        deg[q] = 0
    for c in range(n_contacts):
        deg[wk.slot[wk.c_a[c]]] += 1
        if wk.c_b[c] >= 0:
            deg[wk.slot[wk.c_b[c]]] += 1
    bound = 0.0
    for c in range(n_contacts):
        a = wk.c_a[c]
        other = wk.c_b[c]
        row = inv_mass[a] * deg[wk.slot[a]]
        if other >= 0:
            row += inv_mass[other] * deg[wk.slot[other]]
        bound = max(bound, row)
    return bound


@njit(refcount=False, python=False)
def _settle_accelerated(size, n_contacts, u_min, accuracy, iterations, budget, b, wk):
    """The limit of any group's cascade by an accelerated projected gradient on the least-distance
    dual ``min f(l) = 1/2 l^T A l - h^T l`` over contact impulses ``l >= 0`` (``A = G M^-1 G^T``, ``h``
    each contact's shortfall from separating at ``u_min``): Nesterov's extrapolation (FISTA, Beck &
    Teboulle 2009), restarted whenever a step turns against the momentum (the gradient restart of
    O'Donoghue & Candes 2015, which needs no value of ``f`` finer than its round-off). Ends when an
    iterate is the limit to ``accuracy`` (m/s): every contact separating at ``u_min / 2`` or faster,
    none that an impulse pushes separating faster than ``u_min + accuracy`` (the optimality
    conditions), and ``f <= 0`` (:data:`DONE`); or after
    ``iterations`` (:data:`OPEN`) or where the work reaches ``budget`` (:data:`CAPPED`); returns that
    and the work (iterations). The velocities are the last iterate's; the energy it gains is
    ``f + u_min sum l``, so with ``f <= 0`` no more than the regulariser's allowance.

    Velocities are affine in the impulses, so each iteration's are formed from the last ones
    (``wk.g_f``: per group place, the velocities before and at the last iterate; ``b.vel``: at the
    extrapolated point), and an iteration is three passes over the contacts and two over the balls:
    a contact's next extrapolated impulse is formed where its gradient step reads it, and a ball's
    next extrapolated velocity where its share of the objective is summed."""
    c_f, vel, group, inv_mass = wk.c_f, b.vel, wk.pending, b.inv_mass
    g_f = wk.g_f
    for q in range(size):
        i = group[q]
        for axis in range(2):
            g_f[q, _V0 + axis] = vel[i, axis]
            g_f[q, _V_LAM + axis] = vel[i, axis]
    for c in range(n_contacts):
        c_f[c, F_LAM] = 0.0
        c_f[c, F_Z] = 0.0
        # (h from this pass's own start: a second pass starts where the first left the velocities)
        c_f[c, F_SHORTFALL] = u_min - _separation(c, vel, wk)
    step = 1.0 / _lipschitz(size, n_contacts, inv_mass, wk)
    t = 1.0
    momentum = 0.0  # (of the last iteration: its extrapolated impulses are formed in the next one's first pass)
    work = 0
    outcome = OPEN
    for _ in range(iterations):
        if work >= budget:
            break
        work += 1
        # (vel holds the extrapolated point's velocities) the extrapolated impulses and the
        # projected gradient step
        for c in range(n_contacts):
            z = c_f[c, F_Z]
            y = z + momentum * (z - c_f[c, F_LAM])
            c_f[c, F_Y] = y
            c_f[c, F_LAM] = z
            c_f[c, F_Z] = max(0.0, y - step * (_separation(c, vel, wk) - u_min))
        # the candidate's velocities, its objective and its worst contact
        for q in range(size):
            vel[group[q], 0] = g_f[q, _V0]
            vel[group[q], 1] = g_f[q, _V0 + 1]
        f_z = 0.0
        turn = 0.0
        for c in range(n_contacts):
            z = c_f[c, F_Z]
            f_z -= z * c_f[c, F_SHORTFALL]
            turn += (c_f[c, F_Y] - z) * (z - c_f[c, F_LAM])
            if z != 0.0:
                _push(c, z, vel, inv_mass, wk)
        worst = -math.inf  # (the largest shortfall from u_min, and excess where an impulse pushes)
        excess = 0.0
        for c in range(n_contacts):
            short = u_min - _separation(c, vel, wk)
            worst = max(worst, short)
            if c_f[c, F_Z] > 0.0:
                excess = max(excess, -short)
        # the next extrapolated point (none where the step turned against the momentum: a restart)
        t_next = 0.5 * (1.0 + math.sqrt(1.0 + 4.0 * t * t))
        momentum = (t - 1.0) / t_next if turn <= 0.0 else 0.0
        t = t_next if turn <= 0.0 else 1.0
        for q in range(size):
            i = group[q]
            vx = vel[i, 0]
            vy = vel[i, 1]
            dvx = vx - g_f[q, _V0]
            dvy = vy - g_f[q, _V0 + 1]
            f_z += 0.5 * (dvx * dvx + dvy * dvy) / inv_mass[i]
            vel[i, 0] = vx + momentum * (vx - g_f[q, _V_LAM])
            vel[i, 1] = vy + momentum * (vy - g_f[q, _V_LAM + 1])
            g_f[q, _V_LAM] = vx
            g_f[q, _V_LAM + 1] = vy
        outcome = DONE if worst <= 0.5 * u_min and excess <= accuracy and f_z <= 0.0 else OPEN
        if outcome == DONE:
            break
    for q in range(size):  # (the last iterate, or the candidate that is the limit)
        vel[group[q], 0] = g_f[q, _V_LAM]
        vel[group[q], 1] = g_f[q, _V_LAM + 1]
    if outcome == DONE:
        return DONE, work
    return (CAPPED if work >= budget else OPEN), work


@njit(inline="always")
def _push(c, impulse, vel, inv_mass, wk):
    """Apply ``impulse`` (N s) along contact ``c``'s normal, pushing its balls apart."""
    a = wk.c_a[c]
    other = wk.c_b[c]
    nx = wk.c_f[c, F_NX]
    ny = wk.c_f[c, F_NY]
    vel[a, 0] -= impulse * inv_mass[a] * nx
    vel[a, 1] -= impulse * inv_mass[a] * ny
    if other >= 0:
        vel[other, 0] += impulse * inv_mass[other] * nx
        vel[other, 1] += impulse * inv_mass[other] * ny


@njit(inline="always")
def _separation(c, vel, wk):
    """The normal speed at which contact ``c`` separates (m/s; negative: it closes)."""
    a = wk.c_a[c]
    other = wk.c_b[c]
    nx, ny = _contact_normal(c, wk.c_f)
    sep = -(vel[a, 0] * nx + vel[a, 1] * ny)
    if other >= 0:
        sep += vel[other, 0] * nx + vel[other, 1] * ny
    return sep


@njit(inline="always")
def _contacts_open(vel, n_contacts, wk, slack):
    """No contact of the group closes faster than ``slack`` (m/s)."""
    for c in range(n_contacts):
        if _separation(c, vel, wk) < -slack:
            return False
    return True


@njit(inline="always")
def _stop_group(vel, inv_mass, group, size, c_b, n_contacts):
    """The last resort of a group's limit: every contact at rest, at once."""
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
