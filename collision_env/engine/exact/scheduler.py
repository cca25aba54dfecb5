"""Exact mode: a-priori, event-driven stepping to machine precision at any dt.

The scheduler of the event-driven loop (Alder & Wainwright 1959; Rapaport 1980; Lubachevsky
1991). Its parts, each with one job:

- the **calendar** (:mod:`~collision_env.engine.exact.calendar`): one pending event per ball,
  invalidated lazily, in an event queue (a heap, and time buckets in large scenes); it persists
  from one step to the next;
- the **broad phase** (:mod:`~collision_env.engine.exact.grid`): a cell grid, so that a prediction
  looks only at the 3 x 3 cells around a ball, kept current by cell-crossing events (one cell, i.e.
  all pairs, in small scenes);
- this **scheduler**, in named phases: *begin* (:func:`begin_changed_balls`: re-predict only the
  balls that changed since the last step, a nudge, an env's action, a reversal of time;
  :func:`begin_whole_scene` after a reset or ``set_state``), then repeatedly *predict*
  (:func:`next_event`), *pop* the earliest event and *screen* it (:func:`screen`: stale, a cell
  crossing, or re-verified), *advance* the balls it involves, *resolve* it (:func:`resolve_wall`,
  :func:`resolve_pair`, and a contact group's :func:`~.contacts.cascade`) and *invalidate*
  (:func:`invalidate`), and finally *finish* (:func:`~.calendar.finish_queue`: bring every ball to the end of the
  step and rebase the calendar's times). The phases take a scene's arrays in named bundles
  (:mod:`~collision_env.engine.exact.bundles`).

**Kinds of scene.** A stepping kernel is built for one :class:`Kind` of scene by
:func:`step_kernel`: whether it forms stick clusters (:mod:`~.clusters`) or resolves contact
groups at e < 1 (:mod:`~.contacts`). The kind's paths are chosen where the kernel is built
(constants of a closure, which numba prunes), so a scene never compiles, nor runs, a path it cannot
take: an elastic scene compiles neither.

Balls move lazily: a ball's calendar record holds its position at its own ``ref_time``, brought
up to date only when an event involves it (or when the step ends), so an event costs O(log N)
with O(1) partners instead of moving every ball (:mod:`~.trajectories`). Stick scenes (rotating
clusters) keep every ball at the same time instead, as their kinematics need.

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
is flagged in ``capped``, and its clock shows how far it got. It counts every resolved event, every
sweep, iteration and impulse of a contact group (:mod:`~.contacts`) and, in a periodic cell, every
cell crossing, so that a step's laps round the cell are bounded by it too (a step of any length is
accepted; one that laps the cell without bound stops at the cap).

Reverse steps are run forward on negated velocities with restitution 1/e (the caller negates).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .._jit import njit, prefetch
from ..broadphase import EXACT_CELLS_PER_BALL, block, cell_of
from ..clock import finish_step
from ..frames import frames_kernel
from ..layout import (
    BALL,
    C_CELL,
    C_EVENT_OTHER,
    CAL_I,
    CAL_RECORD,
    CELL_CROSSINGS,
    EVENTS,
    HEAP,
    KINEMATICS,
    PAIR_TESTS,
    S_MAX_EVENTS,
    STALE_EVENTS,
    W_ACTIVE,
    W_CALENDAR_VALID,
    W_EVENTS,
    W_REMAINING,
    W_STALLED,
    W_STALLED_AT,
    WALL_TESTS,
)
from ..physics.impacts import record
from ..physics.motion import ball_views, has_rotation
from ..physics.periodic import cell_lengths, nearest, wrap_point
from ..physics.response import ball_ball_along, ball_wall, impact_threshold, normal_impulse, restitution
from ..physics.toi import INF, not_before, toi_pair
from ..physics.walls import snap_to_wall, wall_point
from ..state import (
    EXACT_FRAMES_SLOT,
    RESUME,
    START_STEP,
    Calendar,
    ExactScratch,
    aligned_zeros,
    physics,
    scene_balls,
    unpack_calendar,
    unpack_exact_scratch,
    unpack_state,
)
from . import calendar as cal
from . import clusters, contacts, grid
from . import periodic as cyclic
from .bundles import SceneCalendar, work
from .trajectories import load, pair_time, take, take_in_place, wall_time


class Kind(NamedTuple):
    """What a scene needs its stepping kernel to do beyond elastic events among free balls."""

    sticky: bool  #: form stick clusters (``inelastic="stick"`` at e = 0)
    cascades: bool  #: resolve contact groups at one instant (e < 1, slip)
    periodic: bool = False  #: a periodic cell (:mod:`~.periodic`): no walls, pairs through images

    @property
    def label(self) -> str:
        """What the compile notice calls the kernel of this kind."""
        if self.periodic:
            return f"exact mode for {'inelastic ' if self.cascades else ''}periodic scenes"
        return f"exact mode for {'stick' if self.sticky else 'inelastic' if self.cascades else 'elastic'} scenes"


def scene_kind(sticky: bool, elasticity: float, periodic: bool = False) -> Kind:
    """The :class:`Kind` of a scene (``sticky``: ``Scene.sticky``). Periodic scenes have no stick
    clusters; at e < 1 they have contact groups, as in a box."""
    cascades = not sticky and elasticity < 1.0
    if periodic:
        return Kind(False, cascades, True)
    return Kind(bool(sticky), cascades)


#: Every kind a scene can be (stick scenes have no contact groups), but periodic scenes: their
#: kernel is compiled only when a periodic scene is first stepped (``precompile`` leaves it out).
KINDS = (Kind(False, False), Kind(False, True), Kind(True, False))


def queues_in_buckets(kind: Kind, n: int) -> bool:
    """Scenes of ``kind`` and ``n`` balls queue events in time buckets (``calendar.QUEUE_MIN_BALLS``
    balls or more). Stick scenes keep every event in the heap whatever their size: a cluster's
    events cost O(N) each (its members move together), far more than a heap's levels, and the queue
    orders events alike either way."""
    return not kind.sticky and cal.bucket_count(n) > 0


# ---------------------------------------------------------------------------- arrays
def calendar_arrays(kind: Kind, n_scenes: int, n: int) -> Calendar:
    """The :class:`~collision_env.engine.state.Calendar` of a batch of ``n_scenes`` scenes of ``kind``
    and ``n`` balls."""
    return Calendar(
        aligned_zeros((n_scenes, n), CAL_RECORD),
        np.zeros((n_scenes, n, len(CAL_I)), dtype=np.int32),
        np.zeros((n_scenes, EXACT_CELLS_PER_BALL * n), dtype=np.int32),
        aligned_zeros((n_scenes, cal.heap_rows(n), len(HEAP)), np.float64),
        np.full((n_scenes, (cal.bucket_count(n) if queues_in_buckets(kind, n) else 0) + 1), -1, dtype=np.int32),
        np.zeros((n_scenes, n)),
        np.full((n_scenes, n), -np.inf),
    )


def exact_scratch(n: int) -> ExactScratch:
    """Exact mode's work space for scenes of ``n`` balls (O(N))."""
    nc = contacts.contact_capacity(n)
    return ExactScratch(
        np.empty(n, dtype=np.int64),
        np.zeros(n, dtype=np.bool_),
        np.empty(nc, dtype=np.int64),
        np.empty(nc, dtype=np.int64),
        np.zeros(nc, dtype=np.bool_),
        np.empty((2, len(KINEMATICS))),
        np.empty((1, 2, len(BALL))),
        np.zeros(2, dtype=np.int64),
        np.full(n, -1, dtype=np.int64),
        np.empty(n, dtype=np.int64),
        np.empty((n, 2), dtype=np.int64),
        np.empty((n, 4)),
        np.empty((nc, len(contacts.C_F))),
    )


def impacts_per_event(n: int, cascades: bool) -> int:
    """Most impacts one event can record: a contact group's contacts, or the event alone."""
    return contacts.contact_capacity(n) + 1 if cascades else 2


# ---------------------------------------------------------------------------- begin
@njit(refcount=False, python=False)
def begin_whole_scene(now, b, cl, geo, pending):
    """Forget every prediction of a scene, take every ball's state (its radius and inverse mass
    too) into the calendar as of step time ``now`` and lay the balls into the grid; every ball is
    then to be predicted (listed in ``pending``). Returns how many."""
    n = b.pos.shape[0]
    for i in range(n):
        load(i, now, cl.rec, b.pos, b.vel, i)
        cl.rec[i]["radius"] = b.radius[i]
        cl.inv_mass[i] = b.inv_mass[i]
        cal.set_event(i, INF, cal.EV_NONE, 0, cl.rec, cl.ci)
        pending[i] = i
    grid.fill_cells(n, cl.rec, cl.ci, cl.heads, geo)
    return n


@njit(refcount=False, forceinline=True)
def begin_changed_balls(b, cl, geo, pending):
    """List in ``pending`` the balls whose position or velocity changed since the last step ended
    (a nudge, an env's action, the negated velocities of a reversal of time): their records take
    the new state, their trajectories are new (their change counters move on, which makes events
    others hold with them stale) and they may sit in another cell. Returns how many."""
    pos, vel, rec = b.pos, b.vel, cl.rec
    n_changed = 0
    for i in range(pos.shape[0]):
        r = rec[i]
        if pos[i, 0] != r["x"] or pos[i, 1] != r["y"] or vel[i, 0] != r["vx"] or vel[i, 1] != r["vy"]:
            pending[n_changed] = i
            n_changed += 1
            load(i, 0.0, rec, pos, vel, i)
            rec[i]["changes"] += 1
            if grid.has_cells(geo):
                c = cell_of(pos[i, 0], pos[i, 1], geo.x0, geo.y0, geo.hx, geo.hy, geo.nx, geo.ny)
                grid.move_to_cell(i, c, rec, cl.ci, cl.heads)
    return n_changed


# ---------------------------------------------------------------------------- predict
@njit(inline="always")
def _crossing_event(i, rec, ci, geo):
    """When ball ``i`` leaves its grid cell, and for which neighbour: ``(time, code)``."""
    r = rec[i]
    tau, direction = grid.crossing(r["x"], r["y"], r["vx"], r["vy"], ci[i, C_CELL], geo)
    return (tau + r["ref_time"], cal.EV_CROSS - direction) if direction >= 0 else (INF, cal.EV_NONE)


@njit(inline="always")
def _partner_event(i, rebuild, best_t, best_code, b, ph, cl, geo, wk):
    """Ball ``i``'s earliest collision with a partner in the 3 x 3 cells around it (every other
    ball when the grid has one cell), if it comes before ``(best_t, best_code)``: the new best
    ``(time, code, partner's change count)``. With ``rebuild``, only partners of higher index."""
    rec = cl.rec
    n = rec.shape[0]
    one_cell = not grid.has_cells(geo)
    best_stamp = 0
    tests = 0
    cx0, cx1, cy0, cy1 = (0, 0, 0, 0) if one_cell else block(cl.ci[i, C_CELL], geo.nx, geo.ny)
    # (trajectories.pair_gap's arithmetic, term for term, with ball i's record read once and each
    # partner's once: the same times, and less work per pair)
    ri = rec[i]
    xi, yi, vxi, vyi, ti, radius = ri["x"], ri["y"], ri["vx"], ri["vy"], ri["ref_time"], ri["radius"]
    for cy in range(cy0, cy1 + 1):
        for cx in range(cx0, cx1 + 1):
            k = (i + 1 if rebuild else 0) if one_cell else cl.heads[cy * geo.nx + cx]
            while 0 <= k < n:
                rk = rec[k]
                if k != i and (k > i or not rebuild) and not (ph.sticky and b.body[i] == b.body[k]):
                    tests += 1
                    tk = rk["ref_time"]
                    tc = max(ti, tk)
                    dti = tc - ti
                    dtk = tc - tk
                    dx = (rk["x"] + rk["vx"] * dtk) - (xi + vxi * dti)
                    dy = (rk["y"] + rk["vy"] * dtk) - (yi + vyi * dti)
                    dvx = rk["vx"] - vxi
                    dvy = rk["vy"] - vyi
                    sigma = radius + rk["radius"]
                    if not not_before(dx, dy, dvx, dvy, sigma, best_t - tc):
                        t = tc + toi_pair(dx, dy, dvx, dvy, sigma)
                        if t < INF and cal.earlier(t, k, best_t, best_code, i):
                            best_t = t
                            best_code = k
                            best_stamp = rk["changes"]
                k = k + 1 if one_cell else rk["cell_next"]
    wk.counters[PAIR_TESTS] += tests
    return best_t, best_code, best_stamp


@njit(refcount=False, forceinline=True)
def next_event(i, rebuild, b, cl, ph, geo, wk):
    """Ball ``i``'s next event in straight-line motion, from the records: the earliest of its wall,
    its cell crossing (found first: an early bound spares most pairs their time of impact) and its
    partners, as ``(time, code, partner's change count)``.

    ``rebuild`` is the first prediction of a whole scene: only partners of higher index are
    looked at, so each pair is tested once, by its lower ball (which is enough: the earliest event
    of the scene is then held by its lower ball), and the queue is built afterwards.
    """
    best_t, best_code = INF, cal.EV_NONE
    # (a ball in an inner cell crosses into a cell at the border before it can touch a wall)
    if ph.has_walls and grid.near_border(cl.ci[i, C_CELL], geo):
        wk.counters[WALL_TESTS] += 1
        t, wall = wall_time(i, ph.bounds, ph.dim, cl.rec)
        if wall >= 0:
            best_t, best_code = t, cal.EV_WALL - wall
    if not ph.pairs:
        return best_t, best_code, 0
    if grid.has_cells(geo):
        t, code = _crossing_event(i, cl.rec, cl.ci, geo)
        if cal.earlier(t, code, best_t, best_code, i):
            best_t, best_code = t, code
    return _partner_event(i, rebuild, best_t, best_code, b, ph, cl, geo, wk)


# ---------------------------------------------------------------------------- pop and screen
@njit(inline="always")
def _verified_time(i, code, bounds, dim, rec):
    """The popped event's time, computed afresh from the records (a prediction from an earlier
    step carries the round-off of rebasing its time), or inf if it no longer happens."""
    if code >= 0:
        return pair_time(i, code, rec)
    t, wall = wall_time(i, bounds, dim, rec)
    return t if wall == cal.EV_WALL - code else INF


#: What :func:`screen` makes of a popped event.
RUN, PREDICT, RESCHEDULE = range(3)


@njit(refcount=False, forceinline=True)
def screen(bi, t, now, ph, cl, geo, wk):
    """Look at ball ``bi``'s popped event (due at ``t``) before it is run.

    Returns ``(verdict, t, now)``: :data:`RUN`, an event to resolve at the re-verified time ``t``;
    :data:`PREDICT`, none, and ball ``bi`` (listed in ``wk.pending``) is to be predicted afresh (a
    stale pair, a grid-cell crossing, which moves the ball to its new cell, or an event that no
    longer happens); :data:`RESCHEDULE`, the event comes later than it said: its new time is set,
    and the caller queues it there."""
    code = cl.ci[bi, C_EVENT_OTHER]
    if cal.is_stale(bi, cl.rec, cl.ci):
        wk.counters[STALE_EVENTS] += 1
        wk.pending[0] = bi
        return PREDICT, t, now
    if cal.is_crossing(code):
        wk.counters[CELL_CROSSINGS] += 1
        grid.unlink(bi, cl.rec, cl.ci, cl.heads)
        grid.link(bi, grid.neighbour_cell(cl.ci[bi, C_CELL], cal.EV_CROSS - code, geo.nx), cl.rec, cl.ci, cl.heads)
        wk.pending[0] = bi
        return PREDICT, t, max(now, t)
    if ph.sticky:  # (rotating clusters' predictions are re-checked by the contact test instead)
        return RUN, t, now
    t_check = _verified_time(bi, code, ph.bounds, ph.dim, cl.rec)
    if t_check <= t:
        return RUN, t_check, now
    if t_check == INF:
        wk.pending[0] = bi
        return PREDICT, t, now
    cl.rec[bi]["event_time"] = t_check
    return RESCHEDULE, t, now


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


@njit(refcount=False, forceinline=True)
def prefetch_popped(bi, cl, geo):
    """Ask for what ball ``bi``'s popped event reads first: its partner's record and int row, and
    the cell heads of the prediction that follows (around the cell it enters, for a crossing).
    Only with a grid: a scene without one is small enough to stay in the cache."""
    if grid.has_cells(geo):
        code = cl.ci[bi, C_EVENT_OTHER]
        c = cl.ci[bi, C_CELL]
        if cal.is_crossing(code):
            c = grid.neighbour_cell(c, cal.EV_CROSS - code, geo.nx)
        _prefetch_heads(c, geo.nx, cl.heads)
        if code >= 0:
            prefetch(cl.rec, code)
            cal.prefetch_int_row(code, cl.ci)


@njit(refcount=False, forceinline=True)
def prefetch_partner(bj, cl, geo):
    """Ask for the cell heads of pair partner ``bj``'s coming prediction (its cell is in its int row,
    which :func:`prefetch_popped` asked for)."""
    if grid.has_cells(geo):
        _prefetch_heads(cl.ci[bj, C_CELL], geo.nx, cl.heads)


# ---------------------------------------------------------------------------- resolve
@njit(refcount=False, forceinline=True)
def resolve_wall(sc, t_abs, bi, li, wall, b, ph, last, wk):
    """Ball ``bi``, row ``li`` of ``b`` (the whole ball state, ``li = bi``, where contact groups
    may form; else the event's rows), meets ``wall``; it is listed in ``wk.pending``. Returns the
    closing speed (0: no impulse). ``last``: each ball's last collision instant (the TC model's)."""
    snap_to_wall(li, wall, b.pos, b.radius, ph.bounds)
    u_min = impact_threshold(li, -1, b.vel, ph.ratio, ph.floor)
    e = restitution(ph.e, ph.contact_duration, t_abs, last, bi, -1)
    speed = ball_wall(li, wall, b.vel, e, u_min)
    if speed > 0.0:
        x, y = wall_point(li, wall, b.pos, ph.bounds)
        impulse = normal_impulse(speed, e, u_min, b.inv_mass[li])
        record(wk.imp, wk.n_imp, sc, t_abs, bi, -1, wall, x, y, speed, impulse)
    wk.pending[0] = bi
    return speed


@njit(refcount=False, forceinline=True)
def resolve_pair(sc, t_abs, bi, bj, li, lj, dx, dy, b, ph, last, wk):
    """Balls ``bi`` and ``bj``, rows ``li`` and ``lj`` of ``b`` (as in :func:`resolve_wall`), their
    centres ``(dx, dy)`` apart (in a periodic cell, through the nearest image), meet; they are
    listed in ``wk.pending``. Returns the closing speed (0: no impulse)."""
    pos, vel, radius = b.pos, b.vel, b.radius
    u_min = impact_threshold(li, lj, vel, ph.ratio, ph.floor)
    e = restitution(ph.e, ph.contact_duration, t_abs, last, bi, bj)
    speed = ball_ball_along(li, lj, dx, dy, vel, b.inv_mass, e, u_min)
    if speed > 0.0:
        dist = math.sqrt(dx * dx + dy * dy)
        x = pos[li, 0] + radius[li] * dx / dist
        y = pos[li, 1] + radius[li] * dy / dist
        impulse = normal_impulse(speed, e, u_min, b.inv_mass[li] + b.inv_mass[lj])
        record(wk.imp, wk.n_imp, sc, t_abs, bi, bj, -1, x, y, speed, impulse)
    wk.pending[0] = bi
    wk.pending[1] = bj
    return speed


@njit(refcount=False, forceinline=True)
def invalidate(n_changed, now, ev, in_place, cl, wk):
    """The balls whose motion an event changed (``wk.pending``) take their new state into their
    records, from the rows the response changed (``ev``: the whole ball state if ``in_place``, else
    the event's rows, in the order of ``wk.pending``), and their change counters move on: events
    other balls hold with them become stale."""
    for q in range(n_changed):
        k = wk.pending[q]
        load(k, now, cl.rec, ev.pos, ev.vel, k if in_place else q)
        cl.rec[k]["changes"] += 1


# ---------------------------------------------------------------------------- finish
@njit(refcount=False, forceinline=True)
def finish_synced(t_end, rec):
    """Make the records' times relative to step time ``t_end`` in a scene whose balls are all there
    already (stick scenes; :func:`~.calendar.finish_queue` brings the others there)."""
    for i in range(rec.shape[0]):
        rec[i]["ref_time"] = 0.0
        rec[i]["event_time"] -= t_end


@njit(refcount=False, forceinline=True)
def open_step(state, dt_abs, start):
    """Start a step of ``dt_abs`` for every scene (``start``: not :data:`RESUME`), or resume the
    scenes a full impact buffer stopped. Impacts are recorded from row ``n_imp[0]`` on, where the
    caller left it (see ``Stepper``: rows it handed out are never written again)."""
    if start != RESUME:
        for sc in range(state.time.shape[0]):
            state.work_i[sc, W_ACTIVE] = True
            state.work_f[sc, W_REMAINING] = dt_abs
            state.work_f[sc, W_STALLED_AT] = 0.0
            state.work_i[sc, W_EVENTS] = 0
            state.capped[sc] = False
        state.n_imp[1] = 0
    state.n_imp[2] = 0


@njit(refcount=False, forceinline=True)
def close_scene(sc, t0, now, horizon_end, sign, dt_abs, state):
    """Scene ``sc`` stopped at step time ``now``: stalled (a full impact buffer: the next call goes
    on from there, as if nothing had stopped it), capped, or done; returns the step time it ends
    at (-1 if stalled). Its clock is set when it ends."""
    if state.work_i[sc, W_STALLED]:
        state.work_f[sc, W_STALLED_AT] = now
        state.n_imp[2] += 1
        return -1.0
    capped = state.capped[sc]
    t_end = now if capped else horizon_end
    state.time[sc] = t0 + sign * t_end
    state.work_f[sc, W_REMAINING] = horizon_end - t_end
    state.n_imp[1] += capped
    state.work_i[sc, W_ACTIVE] = False
    finish_step(sc, not capped, sign * dt_abs, state.time, state.clock)
    return t_end


@njit(inline="always")
def scene_calendar(calendar, state, sc):
    """Scene ``sc``'s :class:`~.bundles.SceneCalendar` (views of the batch's calendar)."""
    queue = cal.EventQueue(calendar.heap[sc], calendar.buckets[sc], state.work_f[sc], state.work_i[sc])
    return SceneCalendar(
        calendar.rec[sc], calendar.ci[sc], calendar.heads[sc], queue, calendar.inv_mass[sc], calendar.last_impact[sc]
    )


# ---------------------------------------------------------------------------- the scheduler
def _step(kind: Kind):
    """The step of every active scene of a batch for scenes of ``kind`` (see the module doc): a
    function ``step(h, dt_abs, start)`` of a pack ``h`` (``state``: a ``State``, a ``Calendar``
    and an ``ExactScratch``), inlined into its kernel (:func:`step_kernel`).

    ``start`` is ``START_STEP`` to start a step of ``dt_abs`` for every scene, ``START_NEXT`` to
    start one right after a completed step of this kernel that nobody touched since (the balls
    need not be compared with their records), or ``RESUME`` to resume the scenes flagged active.
    Impacts go to ``state.imp`` from row ``n_imp[0]`` on (the caller's cursor, which each record
    moves on); a scene that finds the buffer full stops where it is and is flagged stalled, so the
    caller can hand over a buffer with room and call again for those scenes. ``n_imp[1]`` counts
    the scenes that reached the event cap, ``n_imp[2]`` the stalled ones. Returns the cursor
    ``n_imp[0]`` when neither happened (the common case, read without looking at ``n_imp``), else
    -1.

    The whole batch is one call with the scene loop inside: a call from Python checks every
    argument, which would cost as much as a small scene's events.
    """
    sticky, cascades, periodic = kind.sticky, kind.cascades, kind.periodic
    # (the two-level queue works as a heap of every ball when a scene has no buckets; stick scenes never do)
    build, schedule, first, walk_ahead = cal.HEAP_QUEUE if kind.sticky else cal.BUCKET_QUEUE
    cascade = contacts.cascade_kernel(periodic)  # (compiled only where called: scenes with cascades)

    @njit(inline="always")
    def predict(i, now, horizon, rebuild, rot, b, cl, ph, geo, wk):
        """Find ball ``i``'s next event and queue it (``rebuild``: see ``next_event``)."""
        if sticky and rot:
            t, code, stamp = clusters.next_event(i, now, horizon, rebuild, b, cl, ph, wk)
        elif periodic:
            t, code, stamp = cyclic.next_event(i, rebuild, cl, ph, geo, wk)
        else:
            t, code, stamp = next_event(i, rebuild, b, cl, ph, geo, wk)
        cal.set_event(i, t, code, stamp, cl.rec, cl.ci)
        if not rebuild:
            schedule(i, cl.rec, cl.ci, cl.q)

    @njit(inline="always")
    def resolve(sc, t_abs, now, bi, bj, code, in_place, budget, b, ev, ph, cl, geo, wk):
        """Resolve the event of balls ``bi`` and ``bj`` (``bj < 0``: the wall of ``code``); returns
        how many balls' motion it changed (listed in ``wk.pending``), the work of a contact group it
        started (beyond the event itself) and whether that ran out of ``budget``."""
        if sticky:
            if bj < 0:
                return clusters.resolve_wall(sc, t_abs, bi, cal.EV_WALL - code, b, ph, wk), 0, False
            return clusters.resolve_pair(sc, t_abs, bi, bj, b, wk), 0, False
        li = bi if in_place else 0
        if bj < 0:
            speed = resolve_wall(sc, t_abs, bi, li, cal.EV_WALL - code, ev, ph, cl.last_impact, wk)
            n_changed = 1
        else:
            lj = bj if in_place else 1
            dx = ev.pos[lj, 0] - ev.pos[li, 0]
            dy = ev.pos[lj, 1] - ev.pos[li, 1]
            if periodic and in_place:  # (the rows path put the partner at its nearest image)
                lx, ly = cell_lengths(ph.bounds, ph.dim)
                dx = nearest(dx, lx)
                dy = nearest(dy, ly)
            speed = resolve_pair(sc, t_abs, bi, bj, li, lj, dx, dy, ev, ph, cl.last_impact, wk)
            n_changed = 2
        if cascades:
            if in_place and speed > 0.0:
                j0 = -1 - (cal.EV_WALL - code) if bj < 0 else bj
                return cascade(sc, t_abs, now, bi, j0, budget, b, ph, cl, geo, wk)
        return n_changed, 0, False

    @njit(inline="always")
    def run_scene(sc, start, state, b, cl, geo, ph, wk):
        """Scene ``sc``'s events up to the end of its step, the event cap or a full impact buffer;
        returns the step time it got to."""
        n = b.pos.shape[0]
        horizon_end = state.work_f[sc, W_REMAINING]
        t0 = state.time[sc]
        now = state.work_f[sc, W_STALLED_AT]  # (0 at a step's start)
        rot = sticky and has_rotation(b.body, b.omega)
        in_place = sticky or (cascades and ph.cascades)  # (the rows an event is resolved on)
        ev = b if in_place else wk.event
        room = wk.c_a.shape[0] + 1 if cascades and ph.cascades else 2  # (impacts an event may record)
        max_events = state.iparams[S_MAX_EVENTS]
        # begin: everything afresh after a reset (and for rotating clusters, whose predictions reach
        # only to the end of a step), otherwise only the balls changed since the last step
        whole = not state.work_i[sc, W_CALENDAR_VALID] or rot
        if whole:
            n_pending = begin_whole_scene(now, b, cl, geo, wk.pending)
        elif start == START_STEP:
            n_pending = begin_changed_balls(b, cl, geo, wk.pending)
        else:
            n_pending = 0
        walk = -1  # (see calendar.walk_next_bucket)
        while True:
            # predict (the one place where predictions are made: what begin or the last event listed)
            for q in range(n_pending):
                predict(wk.pending[q], now, horizon_end - now, whole, rot, b, cl, ph, geo, wk)
            if whole:
                build(n, now, cl.rec, cl.ci, cl.q)
                state.work_i[sc, W_CALENDAR_VALID] = True
                whole = False
            # pop and screen
            bi = first(cl.rec, cl.ci, cl.q)
            if bi < 0:
                break
            prefetch_popped(bi, cl, geo)
            walk = walk_ahead(walk, cl.rec, cl.ci, cl.q)
            t = cl.rec[bi]["event_time"]
            if not t <= horizon_end:
                break
            if periodic:
                # a cell crossing counts toward the cap: a step's laps round the cell are bounded by it
                # (checked here, within the step's horizon: a step whose last crossing reaches the cap
                # exactly, with nothing left to run, is not capped)
                crossed = cal.is_crossing(cl.ci[bi, C_EVENT_OTHER])
                if crossed and state.work_i[sc, W_EVENTS] >= max_events:
                    state.capped[sc] = True
                    break
                state.work_i[sc, W_EVENTS] += crossed
                verdict, t, now = cyclic.screen(bi, t, now, ph, cl, geo, wk, state.images[sc])
            else:
                verdict, t, now = screen(bi, t, now, ph, cl, geo, wk)
            if verdict != RUN:
                n_pending = 1 if verdict == PREDICT else 0
                if verdict == RESCHEDULE:
                    schedule(bi, cl.rec, cl.ci, cl.q)
                continue
            if state.work_i[sc, W_EVENTS] >= max_events:
                state.capped[sc] = True
                break
            if state.n_imp[0] + room > state.imp.shape[0]:
                state.work_i[sc, W_STALLED] = True
                break
            # advance (a pair is resolved, and reported, from its lower ball)
            now = max(now, t)
            code = cl.ci[bi, C_EVENT_OTHER]
            if code >= 0:
                prefetch_partner(code, cl, geo)
            bj = max(bi, code) if code >= 0 else -1
            bi = min(bi, code) if code >= 0 else bi
            if sticky:
                clusters.sync_all(now, b, rot, cl.rec)
            elif in_place:
                # (a contact group brings in the balls it reaches itself: see contacts.touching)
                take_in_place(bi, now, cl.rec, b)
                if bj >= 0:
                    take_in_place(bj, now, cl.rec, b)
            else:
                take(bi, 0, now, cl, wk.event)
                if bj >= 0:
                    take(bj, 1, now, cl, wk.event)
                    if periodic:
                        cyclic.nearest_partner(wk.event, ph.bounds, ph.dim)
            state.work_i[sc, W_EVENTS] += 1
            wk.counters[EVENTS] += 1
            # resolve, then invalidate (the changed balls are predicted afresh at the top of the loop)
            rows_before = state.n_imp[0] if periodic else 0
            budget = max_events - state.work_i[sc, W_EVENTS]
            n_pending, work, out_of_budget = resolve(
                sc, t0 + ph.sign * now, now, bi, bj, code, in_place, budget, b, ev, ph, cl, geo, wk
            )
            state.work_i[sc, W_EVENTS] += work
            if periodic and in_place:
                for row in range(rows_before, state.n_imp[0]):
                    wrap_point(wk.imp, row, ph.bounds, ph.dim)
            elif periodic and bj >= 0:
                cyclic.after_pair(bj, rows_before, cl, wk.event, wk, ph.bounds, ph.dim)
            if sticky:
                rot = has_rotation(b.body, b.omega)
            invalidate(n_pending, now, ev, in_place, cl, wk)
            # (a contact group cut short, whose contacts may still close, or one that took the step's
            # work to the cap: the step stops here)
            if out_of_budget or (work > 0 and state.work_i[sc, W_EVENTS] >= max_events):
                state.capped[sc] = True
                break
        return now, rot

    @njit(inline="always")
    def step(h, dt_abs, start):
        state = unpack_state(h)
        calendar = unpack_calendar(h)
        ph = physics(state.fparams, state.iparams)
        wk = work(state, unpack_exact_scratch(h))
        open_step(state, dt_abs, start)
        views = ball_views(state.balls)
        for sc in range(state.time.shape[0]):
            if not state.work_i[sc, W_ACTIVE]:
                continue
            state.work_i[sc, W_STALLED] = False
            b = scene_balls(views, state.body, sc)
            cl = scene_calendar(calendar, state, sc)
            t0 = state.time[sc]
            horizon_end = state.work_f[sc, W_REMAINING]
            now, rot = run_scene(sc, start, state, b, cl, grid.scene_geometry(state.work_f, state.work_i, sc), ph, wk)
            t_end = close_scene(sc, t0, now, horizon_end, ph.sign, dt_abs, state)
            if t_end < 0.0:
                continue
            # finish: every ball at the step's end, and the calendar's times made relative to it
            if sticky:
                clusters.sync_all(t_end, b, rot, cl.rec)
                finish_synced(t_end, cl.rec)
                cal.heap_rebase(b.pos.shape[0], t_end, cl.rec, cl.ci, cl.q)  # (the same times, rebased alike)
            else:
                cal.finish_queue(b.pos.shape[0], t_end, cl.rec, cl.ci, cl.q, b.pos, b.vel)
        n_imp = state.n_imp
        return n_imp[0] if n_imp[1] == 0 and n_imp[2] == 0 else -1

    return step


_KERNELS: dict = {}


def step_kernel(kind: Kind) -> Any:
    """The compiled stepping kernel for scenes of ``kind`` (built on first use):
    ``kernel(h, dt_abs, start)`` on a pack of a ``State``, a ``Calendar``, an ``ExactScratch`` and
    room for frames (see :func:`~collision_env.engine.frames.frames_kernel`)."""
    if kind not in _KERNELS:
        _KERNELS[kind] = frames_kernel(_step(kind), kind.label, EXACT_FRAMES_SLOT)
    return _KERNELS[kind]
