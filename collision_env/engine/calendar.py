"""Exact mode's event calendar: one pending event per ball, in an 8-ary heap of balls.

This is the sorter of an event-driven simulation (the scheduler is ``exact.step_exact``, the
neighbour search is :mod:`collision_env.engine.grid`). Following Lubachevsky (1991) and
Smallenburg (2022, "Efficient event-driven simulations of hard spheres", EPJE 45:22), each ball
holds only its earliest known event: a wall, a partner ball, or the crossing of a grid-cell
boundary. An 8-ary heap orders balls by event time, and simultaneous events as a scan of the balls in
index order would meet them (:func:`order_key`); finding, updating or removing an event is
O(log N).

Invalidation is lazy (Sedgewick & Wayne, *Algorithms*, 4th ed., 6.1): every ball counts the
changes of its trajectory, and a pair event stores its partner's count when it was predicted. An
event whose partner has changed since is stale; when it comes to the top of the heap the ball is
simply predicted afresh. A pair event is held only by the ball whose prediction found it (as in
Smallenburg's code): the earliest pending event is always held, because the ball of the pair that
changed last looked at the other when it was predicted, and every event of a ball before that
time would have changed it.

Times in the calendar are relative to the start of the current step (the simulator rebases them
when a step ends), so no large absolute time enters it.

The per-ball fields live in one scene's calendar records ``rec`` (``layout.CAL_RECORD``: the event
time and the change counter) and its int32 rows ``ci`` (``layout.CAL_I``: what the event is, the
partner's count, the heap slot); the heap itself in ``hp`` (``layout.HEAP``).
"""

from __future__ import annotations

import numpy as np

from ._jit import njit
from .layout import C_EVENT_OTHER, C_EVENT_STAMP, C_HEAP_SLOT, H_BALL, H_TIME

#: ``event_other`` codes below zero. A ball's wall events are ``EV_WALL - wall`` (wall codes 0..3
#: as in ``scene.WALL_NAMES``); its grid-cell crossings are ``EV_CROSS - direction`` (0: -x,
#: 1: +x, 2: -y, 3: +y); ``EV_NONE``: nothing is pending.
EV_WALL = -1
EV_CROSS = -5
EV_NONE = -9


@njit(inline="always")
def is_wall(code):
    return EV_CROSS < code <= EV_WALL


@njit(inline="always")
def is_crossing(code):
    return EV_NONE < code <= EV_CROSS


#: Order keys of a cell crossing and of "nothing pending" among events at the same instant.
_LAST = 1 << 62


@njit(inline="always")
def order_key(ball, code):
    """Where ``ball``'s event ``code`` stands among events at the same instant: ``(lead, rank)``.

    A pair event leads with its lower ball and ranks by the higher one; a wall event leads with
    its ball and comes before that ball's pairs; a cell crossing (which changes no velocity, so
    its place among ties does not matter) comes after them. Ordering ties by this key resolves
    simultaneous events exactly as scanning balls in index order would: the lowest ball's wall,
    then its partners by index, then the next ball.
    """
    if code >= 0:
        return min(ball, code), max(ball, code)
    if is_wall(code):
        return ball, -1
    return ball, _LAST if is_crossing(code) else _LAST + 1


@njit(inline="always")
def earlier(t, code, t_other, code_other, ball):
    """For ``ball``: candidate event ``(t, code)`` comes strictly before ``(t_other, code_other)``."""
    if t != t_other:
        return t < t_other
    lead, rk = order_key(ball, code)
    lead_other, rk_other = order_key(ball, code_other)
    return lead < lead_other or (lead == lead_other and rk < rk_other)


@njit(inline="always")
def _before(ta, a, tb, b, ci):
    """Ball ``a``'s event at ``ta`` comes before ball ``b``'s at ``tb`` (ties: see
    :func:`order_key`, then the ball)."""
    if ta != tb:
        return ta < tb
    lead_a, rank_a = order_key(a, ci[a, C_EVENT_OTHER])
    lead_b, rank_b = order_key(b, ci[b, C_EVENT_OTHER])
    if lead_a != lead_b:
        return lead_a < lead_b
    if rank_a != rank_b:
        return rank_a < rank_b
    return a < b


#: Children per node of the heap: an 8-ary heap is a third as deep as a binary one, and a node's
#: children lie side by side in ``hp``, in two adjacent cache lines (measured against a 4-ary heap
#: by the scale benchmark's gas: faster at 10^4 balls, the same at 10^5).
ARITY = 8
#: Slot s of the heap is row ``s + HEAP_OFFSET`` of ``hp``: the children of slot s (slots
#: 8s + 1 ... 8s + 8) then start on a 128-byte boundary, the 16-byte rows of an aligned array.
HEAP_OFFSET = ARITY - 1


def heap_rows(n):
    """Rows of a scene's heap array for ``n`` balls: the offset, then whole cache lines."""
    return -(-(n + HEAP_OFFSET) // ARITY) * ARITY


# The heap lives in ``hp`` (``layout.HEAP``: the event time and the ball of each slot), so that
# sifting reads neighbouring rows instead of chasing every ball's own row.
@njit(inline="always")
def _place(slot, ball, t, ci, hp):
    hp[slot + HEAP_OFFSET, H_TIME] = t
    hp[slot + HEAP_OFFSET, H_BALL] = ball
    ci[ball, C_HEAP_SLOT] = slot


@njit(inline="always")
def _ball_at(slot, hp):
    return np.int64(hp[slot + HEAP_OFFSET, H_BALL])


@njit(inline="always")
def _time_at(slot, hp):
    return hp[slot + HEAP_OFFSET, H_TIME]


@njit(inline="always")
def _sift_up(slot, rec, ci, hp):
    ball = _ball_at(slot, hp)
    t = rec[ball]["event_time"]
    while slot > 0:
        parent = (slot - 1) // ARITY
        above = _ball_at(parent, hp)
        t_above = _time_at(parent, hp)
        if not _before(t, ball, t_above, above, ci):
            break
        _place(slot, above, t_above, ci, hp)
        slot = parent
    _place(slot, ball, t, ci, hp)
    return slot


@njit(inline="always")
def _earlier_of(ca, ta, cb, tb):
    """Of two children ``(slot, time)``, the one whose time comes first (``a`` on a tie; ties are
    settled by :func:`_first_child`'s full order)."""
    return (cb, tb) if tb < ta else (ca, ta)


@njit(inline="always")
def _first_child(first, n, ci, hp):
    """The child slot (of ``first`` ... ``first + ARITY - 1``) whose event comes first, and its time."""
    if first + ARITY <= n:
        # a full set of children: the earliest time by a tournament without branches (a heap's
        # comparisons are coin flips to a branch predictor); exact ties fall through to the full order
        c0, t0 = _earlier_of(first, _time_at(first, hp), first + 1, _time_at(first + 1, hp))
        c1, t1 = _earlier_of(first + 2, _time_at(first + 2, hp), first + 3, _time_at(first + 3, hp))
        c2, t2 = _earlier_of(first + 4, _time_at(first + 4, hp), first + 5, _time_at(first + 5, hp))
        c3, t3 = _earlier_of(first + 6, _time_at(first + 6, hp), first + 7, _time_at(first + 7, hp))
        tie = (
            _time_at(first, hp) == _time_at(first + 1, hp)
            or _time_at(first + 2, hp) == _time_at(first + 3, hp)
            or _time_at(first + 4, hp) == _time_at(first + 5, hp)
            or _time_at(first + 6, hp) == _time_at(first + 7, hp)
            or t0 == t1
            or t2 == t3
        )
        c0, t0 = _earlier_of(c0, t0, c1, t1)
        c2, t2 = _earlier_of(c2, t2, c3, t3)
        if not (tie or t0 == t2):
            return _earlier_of(c0, t0, c2, t2)
    child = first
    t_child = _time_at(first, hp)
    for c in range(first + 1, min(first + ARITY, n)):
        t_c = _time_at(c, hp)
        if t_c <= t_child and _before(t_c, _ball_at(c, hp), t_child, _ball_at(child, hp), ci):
            child = c
            t_child = t_c
    return child, t_child


@njit(inline="always")
def _sift_down(slot, n, ci, hp):
    """Move the ball at ``slot`` down to its place (its time is the one held in the heap; a ball
    already in place is not written again, so ordering a heap that is in order reads only the
    heap)."""
    ball = _ball_at(slot, hp)
    t = _time_at(slot, hp)
    start = slot
    while True:
        first = ARITY * slot + 1
        if first >= n:
            break
        child, t_child = _first_child(first, n, ci, hp)
        below = _ball_at(child, hp)
        if not _before(t_child, below, t, ball, ci):
            break
        _place(slot, below, t_child, ci, hp)
        slot = child
    if slot != start:
        _place(slot, ball, t, ci, hp)


@njit(inline="always")
def reschedule(ball, n, rec, ci, hp):
    """Restore the heap order after ``ball``'s event time changed (either way)."""
    slot = _sift_up(ci[ball, C_HEAP_SLOT], rec, ci, hp)
    _sift_down(slot, n, ci, hp)


@njit(inline="always")
def heapify(n, ci, hp):
    """Order the heap from scratch (Floyd's O(N) construction), from the event times it holds."""
    for slot in range((n - 2) // ARITY, -1, -1):
        _sift_down(slot, n, ci, hp)


@njit(inline="always")
def reset_heap(n, rec, ci, hp):
    """Put every ball in the heap (slot = index) and order it."""
    for i in range(n):
        _place(i, i, rec[i]["event_time"], ci, hp)
    heapify(n, ci, hp)


@njit(inline="always")
def next_ball(hp):
    """The ball whose event comes first."""
    return _ball_at(0, hp)


@njit(inline="always")
def rebase(n, t, hp):
    """Subtract ``t`` from every event time in the heap (the balls' own times are the caller's),
    and restore the heap order if that rounded a node's and its parent's times into a tie (which
    the tie rule, :func:`order_key`, may order the other way). Subtracting the same number keeps
    every other pair in order, so the heap is re-ordered only then (or when finite times were tied
    already, which is rare)."""
    tie = False
    for slot in range(n):
        row = slot + HEAP_OFFSET
        hp[row, H_TIME] -= t
        if slot > 0:
            above = _time_at((slot - 1) // ARITY, hp)
            tie = tie or (hp[row, H_TIME] == above and above < np.inf)
    return tie


@njit(inline="always")
def set_event(ball, t, code, stamp, rec, ci):
    """Give ``ball`` the pending event ``(t, code)`` (``stamp``: the partner's change count);
    the caller restores the heap order."""
    rec[ball]["event_time"] = t
    ci[ball, C_EVENT_OTHER] = code
    ci[ball, C_EVENT_STAMP] = stamp


@njit(inline="always")
def is_stale(ball, rec, ci):
    """A pair event whose partner's trajectory changed after it was predicted."""
    other = ci[ball, C_EVENT_OTHER]
    return other >= 0 and rec[other]["changes"] != ci[ball, C_EVENT_STAMP]
