"""Exact mode's event calendar: one pending event per ball, in a two-level event queue.

This is the sorter of an event-driven simulation (the scheduler is
:mod:`~collision_env.engine.exact.scheduler`, the neighbour search
:mod:`~collision_env.engine.exact.grid`). Following Lubachevsky (1991) and
Smallenburg (2022, "Efficient event-driven simulations of hard spheres", EPJE 45:22), each ball
holds only its earliest known event: a wall, a partner ball, or the crossing of a grid-cell
boundary. The queue orders balls by event time, and simultaneous events as a scan of the balls in
index order would meet them (:func:`order_key`). It is an 8-ary heap of every ball in small
scenes (O(log N) per event); in large ones, a heap of the near future and time buckets for the
rest (Paul 2007: O(1) per event, see the section below).

Invalidation is lazy (Sedgewick & Wayne, *Algorithms*, 4th ed., 6.1): every ball counts the
changes of its trajectory, and a pair event stores its partner's count when it was predicted. An
event whose partner has changed since is stale; when it comes to the front of the queue the ball
is simply predicted afresh. A pair event is held only by the ball whose prediction found it (as in
Smallenburg's code): the earliest pending event is always held, because the ball of the pair that
changed last looked at the other when it was predicted, and every event of a ball before that
time would have changed it.

Times in the calendar are relative to the start of the current step (the simulator rebases them
when a step ends), so no large absolute time enters it.

The per-ball fields live in one scene's calendar records ``rec`` (``layout.CAL_RECORD``: the event
time and the change counter) and its int32 rows ``ci`` (``layout.CAL_I``: what the event is, the
partner's count, where it is queued); the queue itself in an :class:`EventQueue`.

A scene without buckets (fewer than :data:`QUEUE_MIN_BALLS` balls) keeps every ball in the heap;
its scheduler calls the operations of :data:`HEAP_QUEUE`, which do what their two-level
counterparts (:data:`BUCKET_QUEUE`) do on such a queue without the bucket code, so that a small
scene never compiles it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .._jit import njit, prefetch
from ..layout import (
    C_EVENT_OTHER,
    C_EVENT_STAMP,
    C_QUEUE_NEXT,
    C_QUEUE_PREV,
    C_QUEUE_SLOT,
    H_BALL,
    H_TIME,
    W_QUEUE_BASE,
    W_QUEUE_BUCKET,
    W_QUEUE_FAR,
    W_QUEUE_HEAP,
    W_QUEUE_NEXT,
    W_QUEUE_RELEASE,
    W_QUEUE_RING,
    W_QUEUE_WIDTH,
)
from .trajectories import settle

INF = np.inf

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


@njit(forceinline=True)
def earlier(t, code, t_other, code_other, ball):
    """For ``ball``: candidate event ``(t, code)`` comes strictly before ``(t_other, code_other)``."""
    if t != t_other:
        return t < t_other
    lead, rk = order_key(ball, code)
    lead_other, rk_other = order_key(ball, code_other)
    return lead < lead_other or (lead == lead_other and rk < rk_other)


@njit(refcount=False, forceinline=True)
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


# ---------------------------------------------------------------------------- the event queue
# Paul's two-level queue (Paul 2007, "A complexity O(1) priority queue for event driven molecular
# dynamics simulations", J. Comput. Phys. 221:615; as in Smallenburg 2022): the near future is
# a heap, ordered by ``_before``; later events wait in unsorted time buckets ``width`` seconds
# wide, in a ring, and events beyond the ring in a far list. When the heap runs empty, the next
# bucket is moved into it. A pop then sifts through a heap of a few events, which stays in the
# cache, instead of through a heap of every ball, whose lower levels do not at 10^5 balls; moving
# an event between buckets touches its list neighbours, and moving it within a bucket nothing.
#
# Bucket ``k`` holds the events at step times ``t`` with ``floor((t - base) / width) = k``; the heap
# holds every event of ``k <= bucket`` (the bucket last moved into it), the ring events of
# ``bucket < k <= bucket + R`` (at position ``k % R``), the far list events of ``k > release``
# (``release >= bucket``; when the buckets reach ``release``, the far list's events the ring
# reaches by then are sorted into it, and ``release`` moves R buckets on). The bucket of a time is
# a monotonic function of it in floating point, so every heap event comes strictly before every
# other: the heap's first event is the queue's. Each list is doubly linked through the balls' int
# rows (``layout.CAL_I``), so an event leaves its list in O(1).
#
#: Scenes with fewer balls keep every event in the heap (no buckets): below this size the heap of
#: every ball stays in the cache, and the buckets' bookkeeping costs more than the levels it saves
#: (measured by the scale benchmark).
QUEUE_MIN_BALLS = 4096
#: Buckets in the ring per ball, and the events a bucket holds on average: the width is set from
#: the mean time to the balls' next events when the queue is built, so that the heap stays small
#: and the ring reaches some ``BUCKETS_PER_BALL * EVENTS_PER_BUCKET`` such times ahead.
BUCKETS_PER_BALL = 0.5
EVENTS_PER_BUCKET = 16


def bucket_count(n: int) -> int:
    """Buckets in the ring of a scene of ``n`` balls (0: every event in the heap)."""
    return int(BUCKETS_PER_BALL * n) if n >= QUEUE_MIN_BALLS else 0


class EventQueue(NamedTuple):
    """One scene's event queue: views of the arrays that hold it."""

    hp: np.ndarray  #: (rows, len(HEAP)) float64, the heap (slot s in row ``s + HEAP_OFFSET``)
    buckets: np.ndarray  #: (R + 1,) int32: the first ball of each bucket's list, then the far list's
    qf: np.ndarray  #: the scene's ``layout.WORK_F`` row (the buckets' base and width)
    qi: np.ndarray  #: the scene's ``layout.WORK_I`` row (the queue's counts, its bucket)


#: Children per node of the heap: an 8-ary heap is a third as deep as a binary one, and a node's
#: children lie side by side in ``hp``, in two adjacent cache lines (measured against a 4-ary heap
#: by the scale benchmark's gas: faster at 10^4 balls, the same at 10^5).
ARITY = 8
#: Slot s of the heap is row ``s + HEAP_OFFSET`` of ``hp``: the children of slot s (slots
#: 8s + 1 ... 8s + 8) then start on a 128-byte boundary, the 16-byte rows of an aligned array.
HEAP_OFFSET = ARITY - 1


def heap_rows(n: int) -> int:
    """Rows of a scene's heap array for ``n`` balls: the offset, then whole cache lines."""
    return -(-(n + HEAP_OFFSET) // ARITY) * ARITY


# The heap lives in ``hp`` (``layout.HEAP``: the event time and the ball of each slot), so that
# sifting reads neighbouring rows instead of chasing every ball's own row.
@njit(inline="always")
def _place(slot, ball, t, ci, hp):
    hp[slot + HEAP_OFFSET, H_TIME] = t
    hp[slot + HEAP_OFFSET, H_BALL] = ball
    ci[ball, C_QUEUE_SLOT] = slot


@njit(inline="always")
def _ball_at(slot, hp):
    return np.int64(hp[slot + HEAP_OFFSET, H_BALL])


@njit(inline="always")
def _time_at(slot, hp):
    return hp[slot + HEAP_OFFSET, H_TIME]


@njit(refcount=False, forceinline=True)
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


@njit(refcount=False, forceinline=True)
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


@njit(refcount=False, forceinline=True)
def _sift_down(slot, n, ci, hp):
    """Move the ball at ``slot`` down to its place in a heap of ``n`` (its time is the one held in
    the heap; a ball already in place is not written again, so ordering a heap that is in order
    reads only the heap)."""
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


@njit(refcount=False, python=False)
def _heapify(n, ci, hp):
    """Order a heap of ``n`` from scratch (Floyd's O(n) construction), from the times it holds."""
    for slot in range((n - 2) // ARITY, -1, -1):
        _sift_down(slot, n, ci, hp)


@njit(refcount=False, forceinline=True)
def _heap_push(ball, t, rec, ci, q):
    size = q.qi[W_QUEUE_HEAP]
    _place(size, ball, t, ci, q.hp)
    q.qi[W_QUEUE_HEAP] = size + 1
    _sift_up(size, rec, ci, q.hp)


@njit(refcount=False, forceinline=True)
def _vacate(slot, size, ci, hp):
    """Take the event at ``slot`` out of a heap of ``size``: the last event fills its place, out of
    order until the caller sifts it or re-orders the heap. Returns the new size."""
    size -= 1
    if slot < size:
        _place(slot, _ball_at(size, hp), _time_at(size, hp), ci, hp)
    return size


@njit(inline="always")
def _ring_size(q):
    return q.buckets.shape[0] - 1


@njit(inline="always")
def _heap_size(rec, q):
    """Events in the heap: every ball's without buckets (read without touching the counts)."""
    return rec.shape[0] if _ring_size(q) == 0 else q.qi[W_QUEUE_HEAP]


@njit(refcount=False, forceinline=True)
def _position(t, q):
    """Where an event at step time ``t`` is queued: -1 the heap, ``0 .. R - 1`` a bucket of the
    ring, ``R`` the far list (R = 0: no buckets, always the heap)."""
    ring = _ring_size(q)
    if ring == 0:
        return -1
    x = (t - q.qf[W_QUEUE_BASE]) / q.qf[W_QUEUE_WIDTH]
    bucket = q.qi[W_QUEUE_BUCKET]
    if x < bucket + 1:
        return -1
    if x < bucket + ring + 1:
        # (bucket int(x) % ring, counted on from the next bucket's place: no integer division)
        p = q.qi[W_QUEUE_NEXT] + (int(x) - bucket - 1)
        return p - ring if p >= ring else p
    return ring  # (also an event that never comes, t = inf)


@njit(refcount=False, forceinline=True)
def _link(ball, p, ci, q):
    """Put ``ball``'s event at the front of list ``p`` (a bucket, or the far list)."""
    head = q.buckets[p]
    ci[ball, C_QUEUE_SLOT] = -1 - p
    ci[ball, C_QUEUE_NEXT] = head
    ci[ball, C_QUEUE_PREV] = -1
    if head >= 0:
        ci[head, C_QUEUE_PREV] = ball
    q.buckets[p] = ball
    q.qi[W_QUEUE_FAR if p == _ring_size(q) else W_QUEUE_RING] += 1


@njit(refcount=False, forceinline=True)
def _unlink(ball, ci, q):
    """Take ``ball``'s event out of its list."""
    p = -1 - ci[ball, C_QUEUE_SLOT]
    prev = ci[ball, C_QUEUE_PREV]
    nxt = ci[ball, C_QUEUE_NEXT]
    if prev >= 0:
        ci[prev, C_QUEUE_NEXT] = nxt
    else:
        q.buckets[p] = nxt
    if nxt >= 0:
        ci[nxt, C_QUEUE_PREV] = prev
    q.qi[W_QUEUE_FAR if p == _ring_size(q) else W_QUEUE_RING] -= 1


@njit(refcount=False, forceinline=True)
def _file(ball, p, rec, ci, q):
    """Queue ``ball``'s event (in no list yet) at position ``p`` (see :func:`_position`)."""
    if p < 0:
        _heap_push(ball, rec[ball]["event_time"], rec, ci, q)
    else:
        _link(ball, p, ci, q)


@njit(refcount=False, forceinline=True)
def heap_schedule(ball, rec, ci, q):
    """:func:`schedule` in a queue without buckets (a heap of every ball)."""
    _sift_down(_sift_up(ci[ball, C_QUEUE_SLOT], rec, ci, q.hp), rec.shape[0], ci, q.hp)


@njit(refcount=False, forceinline=True)
def schedule(ball, rec, ci, q):
    """Move ``ball``'s event to its place in the queue after its time changed (either way)."""
    t = rec[ball]["event_time"]
    slot = ci[ball, C_QUEUE_SLOT]
    p = _position(t, q)
    if slot < 0:
        if p != -1 - slot:  # (a move within a bucket costs nothing: buckets are not sorted)
            _unlink(ball, ci, q)
            _file(ball, p, rec, ci, q)
        return
    size = _heap_size(rec, q)
    if p >= 0:  # out of the heap: the last event fills its slot, and is sifted instead
        size = _vacate(slot, size, ci, q.hp)
        q.qi[W_QUEUE_HEAP] = size
        _link(ball, p, ci, q)
        if slot == size:
            return
    _sift_down(_sift_up(slot, rec, ci, q.hp), size, ci, q.hp)


@njit(refcount=False, python=False)
def _release_far(rec, ci, q):
    """Sort the far list's events that the ring now reaches into the ring (or the heap), and note
    the bucket at which to do so next (before any event left in the far list is due)."""
    ring = _ring_size(q)
    q.qi[W_QUEUE_RELEASE] = q.qi[W_QUEUE_BUCKET] + ring
    ball = q.buckets[ring]
    while ball >= 0:
        nxt = ci[ball, C_QUEUE_NEXT]
        p = _position(rec[ball]["event_time"], q)
        if p != ring:
            _unlink(ball, ci, q)
            _file(ball, p, rec, ci, q)
        ball = nxt


@njit(refcount=False, python=False)
def _open_next_bucket(rec, ci, q):
    """Move the next bucket's events into the heap; when the ring is empty, start the buckets anew
    at the far list's first event instead of stepping through empty ones. Returns False if
    nothing is queued that will ever come."""
    ring = _ring_size(q)
    if q.qi[W_QUEUE_RING] == 0:
        # (every event is in the far list: its times also give a new width, for a scene whose
        # events have grown sparser or denser since the width was set)
        t_first = INF
        ball = q.buckets[ring]
        while ball >= 0:
            t_first = min(t_first, rec[ball]["event_time"])
            ball = ci[ball, C_QUEUE_NEXT]
        if t_first == INF:
            return False
        total = 0.0
        finite = 0
        ball = q.buckets[ring]
        while ball >= 0:
            t = rec[ball]["event_time"]
            if t < INF:
                total += t - t_first
                finite += 1
            ball = ci[ball, C_QUEUE_NEXT]
        width = _width(total, finite)
        if width < INF:
            q.qf[W_QUEUE_WIDTH] = width
        q.qf[W_QUEUE_BASE] = t_first
        q.qi[W_QUEUE_BUCKET] = -1
        q.qi[W_QUEUE_RELEASE] = -1
    q.qi[W_QUEUE_BUCKET] += 1
    bucket = q.qi[W_QUEUE_BUCKET]
    p = bucket % ring
    q.qi[W_QUEUE_NEXT] = (bucket + 1) % ring
    ball = q.buckets[p]
    q.buckets[p] = -1
    while ball >= 0:
        nxt = ci[ball, C_QUEUE_NEXT]
        q.qi[W_QUEUE_RING] -= 1
        _heap_push(ball, rec[ball]["event_time"], rec, ci, q)
        ball = nxt
    if bucket >= q.qi[W_QUEUE_RELEASE]:  # (after the bucket is emptied: the far list may refill it)
        _release_far(rec, ci, q)
    return True


@njit(refcount=False, forceinline=True)
def prefetch_int_row(ball, ci):
    """Ask for ``ball``'s int row (both ends: a row of seven int32 may straddle two cache lines)."""
    prefetch(ci, (ball, 0))
    prefetch(ci, (ball, ci.shape[1] - 1))


@njit(refcount=False, forceinline=True)
def walk_next_bucket(cursor, rec, ci, q):
    """One step down the list of the bucket that opens next, asking for the rows of the ball it
    reaches. Opening a bucket chases its list, one dependent load per ball, each a miss at 10^5
    balls; a step per popped event walks the list ahead of that. ``cursor`` is the ball the last
    step reached, or -1. The step starts at the list's head when there is none, or when that ball is
    no longer in the list (the bucket opened, or its event moved); returns the ball it reaches (-1
    past the list's end, and the next step starts again). Without buckets: always -1."""
    ring = _ring_size(q)
    if ring == 0:
        return -1
    p = q.qi[W_QUEUE_NEXT]
    ball = q.buckets[p] if cursor < 0 or ci[cursor, C_QUEUE_SLOT] != -1 - p else ci[cursor, C_QUEUE_NEXT]
    if ball >= 0:
        prefetch_int_row(ball, ci)
        prefetch(rec, ball)
    return ball


@njit(forceinline=True)
def no_walk(cursor, rec, ci, q):
    """:func:`walk_next_bucket` in a queue without buckets: there is no bucket to walk."""
    return -1


# Called where the heap ran empty, once per bucket (and never without buckets): a call of its own,
# so that the event loop that inlines ``next_ball`` stays small.
@njit(refcount=False, python=False)
def _refill_heap(rec, ci, q):
    """Open buckets until the heap holds an event; False if none will ever come."""
    while q.qi[W_QUEUE_HEAP] == 0:
        if _ring_size(q) == 0 or not _open_next_bucket(rec, ci, q):
            return False
    return True


@njit(refcount=False, forceinline=True)
def heap_first(rec, ci, q):
    """:func:`next_ball` in a queue without buckets (a heap of every ball)."""
    return _ball_at(0, q.hp)


@njit(refcount=False, forceinline=True)
def next_ball(rec, ci, q):
    """The ball whose event comes first (-1: none is queued but events that never come)."""
    if _heap_size(rec, q) == 0 and not _refill_heap(rec, ci, q):
        return -1
    return _ball_at(0, q.hp)


@njit
def _width(total, finite):
    """A bucket width for ``finite`` events whose times lie ``total`` seconds ahead in all: about
    :data:`EVENTS_PER_BUCKET` events per bucket, if each ball's next event is as far ahead as their
    mean (``finite / mean`` events per second). Inf when that is not a positive number."""
    width = EVENTS_PER_BUCKET * total / max(finite, 1) ** 2
    return width if 0.0 < width < INF else INF


@njit(refcount=False, python=False)
def bucket_width(n, now, rec):
    """A bucket width for a scene's events from step time ``now`` (inf, every finite time in the
    heap, when no finite event lies ahead)."""
    total = 0.0
    finite = 0
    for i in range(n):
        t = rec[i]["event_time"]
        if t < INF:
            total += t - now
            finite += 1
    return _width(total, finite)


@njit(refcount=False, python=False)
def build_queue(n, now, rec, ci, q):
    """Queue every ball's event afresh (their times are set), from step time ``now``, in buckets of
    the width their times call for (:func:`bucket_width`)."""
    reset_queue(n, now, bucket_width(n, now, rec), rec, ci, q)


@njit(refcount=False, python=False)
def heap_build(n, now, rec, ci, q):
    """:func:`build_queue` in a queue without buckets: every ball's event in the heap."""
    for i in range(n):
        _place(i, i, rec[i]["event_time"], ci, q.hp)
    _heapify(n, ci, q.hp)


@njit(refcount=False)
def reset_queue(n, now, width, rec, ci, q):
    """Queue every ball's event afresh (their times are set), in buckets of ``width`` seconds
    from step time ``now`` (a ring-less queue ignores it)."""
    ring = _ring_size(q)
    q.qi[W_QUEUE_HEAP] = 0
    q.qi[W_QUEUE_RING] = 0
    q.qi[W_QUEUE_FAR] = 0
    q.qi[W_QUEUE_BUCKET] = 0
    q.qi[W_QUEUE_NEXT] = 1 % max(ring, 1)
    q.qi[W_QUEUE_RELEASE] = ring
    q.qf[W_QUEUE_BASE] = now
    q.qf[W_QUEUE_WIDTH] = width
    q.buckets[:] = -1
    size = 0
    for i in range(n):
        p = _position(rec[i]["event_time"], q)
        if p < 0:
            _place(size, i, rec[i]["event_time"], ci, q.hp)
            size += 1
        else:
            _link(i, p, ci, q)
    q.qi[W_QUEUE_HEAP] = size
    _heapify(size, ci, q.hp)


@njit(inline="always")
def _refile_ball(i, size, moved, rec, ci, q):
    """After a rebase: move ball ``i``'s event if its rebased time fell into another bucket, or into
    or out of the heap (of ``size`` events, left out of order: ``moved`` becomes True if it
    changed). Returns the heap's new size and ``moved``."""
    p = _position(rec[i]["event_time"], q)
    slot = ci[i, C_QUEUE_SLOT]
    if slot >= 0 and p >= 0:
        size = _vacate(slot, size, ci, q.hp)
        _link(i, p, ci, q)
        moved = True
    elif slot < 0 and p != -1 - slot:
        _unlink(i, ci, q)
        if p < 0:
            _place(size, i, rec[i]["event_time"], ci, q.hp)
            size += 1
            moved = True
        else:
            _link(i, p, ci, q)
    return size, moved


# Called once per step in scenes with buckets: a call of its own, so that small scenes do not
# carry its code.
@njit(refcount=False, python=False)
def _settle_and_refile(n, t, rec, ci, q, pos, vel):
    """Bring every ball to step time ``t`` (:func:`~.trajectories.settle`) and move every event
    whose rebased time fell into another bucket, or into or out of the heap (the heap is left out
    of order: returns True if it changed), in one pass over the balls: each ball's record is read
    once at a step's end."""
    size = q.qi[W_QUEUE_HEAP]
    moved = False
    for i in range(n):
        settle(i, t, rec, pos, vel)
        size, moved = _refile_ball(i, size, moved, rec, ci, q)
    q.qi[W_QUEUE_HEAP] = size
    return moved


@njit(refcount=False, forceinline=True)
def _rebase_heap(size, t, hp):
    """Subtract ``t`` from the heap's times; True if round-off made a node and its parent tie (see
    :func:`finish_queue`)."""
    disorder = False
    for slot in range(size):
        row = slot + HEAP_OFFSET
        hp[row, H_TIME] -= t
        if slot > 0:
            above = _time_at((slot - 1) // ARITY, hp)
            disorder = disorder or (hp[row, H_TIME] == above and above < INF)
    return disorder


@njit(refcount=False, forceinline=True)
def heap_rebase(n, t, rec, ci, q):
    """Make a heap of every ball's times relative to step time ``t``, after every ball's event time
    was (the caller's): as :func:`finish_queue` does."""
    if _rebase_heap(n, t, q.hp):
        _heapify(n, ci, q.hp)


@njit(refcount=False, forceinline=True)
def finish_queue(n, t, rec, ci, q, pos, vel):
    """End a step at step time ``t``: every ball brought there (:func:`~.trajectories.settle`: its
    record, with its times made relative to ``t``, and its row of the ball state ``pos``, ``vel``),
    and the queue's times made relative to it the same way: the heap's times and the buckets' base.
    Round-off can move a time across a bucket boundary, or round a heap node's and its parent's
    times into a tie (which the tie rule, :func:`order_key`, may order the other way): such events
    are moved and the heap is re-ordered, which is rare. Subtracting the same number keeps every
    other pair in order."""
    disorder = _rebase_heap(_heap_size(rec, q), t, q.hp)
    if _ring_size(q) > 0:
        q.qf[W_QUEUE_BASE] -= t
        disorder = _settle_and_refile(n, t, rec, ci, q, pos, vel) or disorder
    else:
        for i in range(n):
            settle(i, t, rec, pos, vel)
    if disorder:
        _heapify(_heap_size(rec, q), ci, q.hp)


@njit(inline="always")
def set_event(ball, t, code, stamp, rec, ci):
    """Give ``ball`` the pending event ``(t, code)`` (``stamp``: the partner's change count);
    the caller queues it (:func:`schedule`, or :func:`reset_queue` for every ball)."""
    rec[ball]["event_time"] = t
    ci[ball, C_EVENT_OTHER] = code
    ci[ball, C_EVENT_STAMP] = stamp


@njit(inline="always")
def is_stale(ball, rec, ci):
    """A pair event whose partner's trajectory changed after it was predicted."""
    other = ci[ball, C_EVENT_OTHER]
    return other >= 0 and rec[other]["changes"] != ci[ball, C_EVENT_STAMP]


class QueueOps(NamedTuple):
    """The event queue's operations as the scheduler calls them, for one kind of queue: build it
    afresh, move an event after its time changed, the ball whose event comes first, and a step of
    the walk ahead of the next bucket. (A step's end is :func:`finish_queue` for either, or
    :func:`heap_rebase` where the balls are there already.)"""

    build: Callable[..., Any]
    schedule: Callable[..., Any]
    first: Callable[..., Any]
    walk: Callable[..., Any]


#: A heap of every ball (scenes of fewer than :data:`QUEUE_MIN_BALLS` balls), and Paul's two-level
#: queue of a heap and time buckets.
HEAP_QUEUE = QueueOps(heap_build, heap_schedule, heap_first, no_walk)
BUCKET_QUEUE = QueueOps(build_queue, schedule, next_ball, walk_next_bucket)
