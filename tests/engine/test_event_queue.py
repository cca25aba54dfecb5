"""Exact mode's event queue (a heap, and time buckets in large scenes) against a sorted list.

Random sequences of the calendar's operations (pop and re-queue the first event, move any
event earlier or later, rebase every time as a step's end does) on rings of 0 to 16 buckets of
several widths, with times drawn from a coarse set so that ties and bucket boundaries are
frequent: the queue's first ball is always the one a sort by time and the tie rule names, and
after every operation its structure is intact (heap order, lists, counts, each event's bucket).
A walk down the list of the bucket that opens next (the sorter's prefetching) takes a step
before every operation: it reaches a ball of that list, or the list's end.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine._jit import njit
from collision_env.engine.exact import calendar as cal
from collision_env.engine.layout import (
    C_EVENT_OTHER,
    C_QUEUE_NEXT,
    C_QUEUE_PREV,
    C_QUEUE_SLOT,
    CAL_I,
    CAL_RECORD,
    H_BALL,
    H_TIME,
    W_QUEUE_BASE,
    W_QUEUE_BUCKET,
    W_QUEUE_FAR,
    W_QUEUE_HEAP,
    W_QUEUE_RELEASE,
    W_QUEUE_RING,
    W_QUEUE_WIDTH,
    WORK_F,
    WORK_I,
)

POP, MOVE, REBASE = range(3)


@njit
def queue_intact(n, rec, ci, q):
    """The queue's structure: the heap in order under the tie rule and holding the balls' times,
    each list doubly linked and holding the events of its buckets, the counts those of the lists,
    every ball queued once."""
    ring = q.buckets.shape[0] - 1
    size = q.qi[W_QUEUE_HEAP] if ring > 0 else n
    base, width = q.qf[W_QUEUE_BASE], q.qf[W_QUEUE_WIDTH]
    bucket, release = q.qi[W_QUEUE_BUCKET], q.qi[W_QUEUE_RELEASE]
    if not bucket <= release <= bucket + ring:
        return False
    seen = 0
    for slot in range(size):
        ball = int(q.hp[slot + cal.HEAP_OFFSET, H_BALL])
        t = q.hp[slot + cal.HEAP_OFFSET, H_TIME]
        if ci[ball, C_QUEUE_SLOT] != slot or t != rec[ball]["event_time"]:
            return False
        if ring > 0 and not (t - base) / width < bucket + 1:
            return False
        if slot > 0:
            above = int(q.hp[(slot - 1) // cal.ARITY + cal.HEAP_OFFSET, H_BALL])
            if cal._before(t, ball, rec[above]["event_time"], above, ci):
                return False
        seen += 1
    in_ring = 0
    for p in range(ring + 1):
        ball = q.buckets[p]
        prev = -1
        length = 0
        while ball >= 0 and length <= n:
            x = (rec[ball]["event_time"] - base) / width
            if ci[ball, C_QUEUE_SLOT] != -1 - p or ci[ball, C_QUEUE_PREV] != prev:
                return False
            if p < ring and not (bucket + 1 <= x < bucket + ring + 1 and int(x) % ring == p):
                return False
            if p == ring and x < release + 1:  # (an event that never comes: x is inf or nan)
                return False
            prev = ball
            ball = ci[ball, C_QUEUE_NEXT]
            length += 1
        if p < ring:
            in_ring += length
        elif length != q.qi[W_QUEUE_FAR]:
            return False
        seen += length
    return seen == n and (ring == 0 or in_ring == q.qi[W_QUEUE_RING])


@njit
def walk_in_next_bucket(cursor, ball, ci, q):
    """A step of the walk from ``cursor`` reached ``ball``: a ball queued in the bucket that opens
    next, or -1 only past the end of that list (from its last ball, or on an empty list)."""
    ring = q.buckets.shape[0] - 1
    if ring == 0:
        return ball == -1
    p = (q.qi[W_QUEUE_BUCKET] + 1) % ring
    if ball >= 0:
        return ci[ball, C_QUEUE_SLOT] == -1 - p
    return q.buckets[p] < 0 or (cursor >= 0 and ci[cursor, C_QUEUE_SLOT] == -1 - p and ci[cursor, C_QUEUE_NEXT] < 0)


@njit
def run_queue(width, rec, ci, hp, buckets, qf, qi, kinds, balls, times):
    """Queue the events of ``rec``, then apply the operations, each after noting the queue's
    first ball (-1: none) and taking a step of the walk down the next bucket: pop the first event
    and queue the ball's next ``times[k]`` later, move ball ``balls[k]``'s event to ``times[k]``,
    or rebase every time by ``times[k]``. Returns the first ball before each operation, and how
    many operations left the queue intact and had a step of the walk land where it should (it
    stops at the first that did not)."""
    n = rec.shape[0]
    q = cal.EventQueue(hp, buckets, qf, qi)
    cal.reset_queue(n, 0.0, width, rec, ci, q)
    firsts = np.full(kinds.shape[0], -2, dtype=np.int64)
    if not queue_intact(n, rec, ci, q):
        return firsts, -1
    walk = -1
    for k in range(kinds.shape[0]):
        first = cal.next_ball(rec, ci, q)
        firsts[k] = first
        walked = cal.walk_next_bucket(walk, rec, ci, q)
        if not walk_in_next_bucket(walk, walked, ci, q):
            return firsts, k
        walk = walked
        if kinds[k] == REBASE:  # (a step's end: the balls, at rest, keep their places)
            cal.finish_queue(n, times[k], rec, ci, q, np.zeros((n, 2)), np.zeros((n, 2)))
        elif kinds[k] == MOVE or first >= 0:
            ball = balls[k] if kinds[k] == MOVE else first
            rec[ball]["event_time"] = times[k] + (rec[ball]["event_time"] if kinds[k] == POP else 0.0)
            cal.schedule(ball, rec, ci, q)
        if not queue_intact(n, rec, ci, q):
            return firsts, k
    return firsts, kinds.shape[0]


def check_queue(ring, width, times, codes, kinds, balls, steps):
    """Run the operations on a queue and on a sorted list of times alike; the queue's first ball
    must always be the list's."""
    n = len(times)
    rec = np.zeros(n, dtype=CAL_RECORD)
    rec["event_time"] = times
    ci = np.zeros((n, len(CAL_I)), dtype=np.int32)
    ci[:, C_EVENT_OTHER] = codes
    qi = np.zeros(len(WORK_I), dtype=np.int64)
    heap, buckets, qf = np.zeros((cal.heap_rows(n), 2)), np.full(ring + 1, -1, dtype=np.int32), np.zeros(len(WORK_F))
    firsts, intact = run_queue(width, rec, ci, heap, buckets, qf, qi, kinds, balls, steps)
    assert intact == len(kinds), f"the queue (or the walk) broke at operation {intact}"

    keys = np.array([cal.order_key(i, codes[i]) for i in range(n)])  # the tie rule, per ball
    t = np.array(times, dtype=np.float64)
    for k, (kind, ball, step) in enumerate(zip(kinds, balls, steps, strict=True)):
        order = np.lexsort((np.arange(n), keys[:, 1], keys[:, 0], t))
        if t[order[0]] == np.inf:  # (the heap of a ring-less queue holds events that never come, too)
            assert firsts[k] == -1 or t[firsts[k]] == np.inf
        else:
            assert firsts[k] == order[0], k
            if kind == POP:
                t[order[0]] += step
        if kind == MOVE:
            t[ball] = step
        elif kind == REBASE:
            t -= step
    np.testing.assert_array_equal(rec["event_time"], t)


@njit
def walk_steps(steps, width, rec, ci, hp, buckets, qf, qi):
    """Queue the events of ``rec`` and take ``steps`` steps of the walk on the queue as it stands;
    also the list of the bucket that opens next, as its links give it."""
    q = cal.EventQueue(hp, buckets, qf, qi)
    cal.reset_queue(rec.shape[0], 0.0, width, rec, ci, q)
    walked = np.empty(steps, dtype=np.int64)
    walk = -1
    for k in range(steps):
        walk = cal.walk_next_bucket(walk, rec, ci, q)
        walked[k] = walk
    listed = []
    ball = buckets[(qi[W_QUEUE_BUCKET] + 1) % (buckets.shape[0] - 1)]
    while ball >= 0:
        listed.append(ball)
        ball = ci[ball, C_QUEUE_NEXT]
    return walked, listed


def test_the_walk_goes_down_the_next_bucket_and_starts_again_at_its_end():
    """Balls 1, 3 and 4 fall in bucket 1 (the next to open; 0 and 2 are in the heap's bucket 0,
    5 in bucket 2): the walk visits the list as it is linked (the last queued first), then -1,
    then the list again."""
    times = [0.05, 0.12, 0.01, 0.15, 0.11, 0.25]
    n = len(times)
    rec = np.zeros(n, dtype=CAL_RECORD)
    rec["event_time"] = times
    ci = np.zeros((n, len(CAL_I)), dtype=np.int32)
    heap, buckets, qf = np.zeros((cal.heap_rows(n), 2)), np.full(4 + 1, -1, dtype=np.int32), np.zeros(len(WORK_F))
    walked, listed = walk_steps(9, 0.1, rec, ci, heap, buckets, qf, np.zeros(len(WORK_I), dtype=np.int64))
    assert list(listed) == [4, 3, 1]
    assert walked.tolist() == [4, 3, 1, -1, 4, 3, 1, -1, 4]


def tie_codes(n, codes):
    """Partners, walls, cell crossings and nothing pending: the tie rule's every case."""
    code = np.array([c % n if c >= 0 else c for c in codes[:n]], dtype=np.int32)
    code[code == np.arange(n)] = cal.EV_NONE
    return code


@pytest.fixture(scope="module", autouse=True)
def compiled_first():
    """Compile (or load) the driver before any example runs: hypothesis traces the code its
    examples run, which makes numba's compiler several times slower."""
    check_queue(1, 0.5, [0.0, 1.0], tie_codes(2, [-1, -1]), np.array([POP]), np.array([0]), np.array([1.0]))


#: Times of binary fractions (exact sums) and of tenths and thirds (whose sums and differences
#: round, so rebasing moves events across bucket boundaries and into ties).
TIMES = st.sampled_from([0.0, 0.1, 0.25, 0.3, 1 / 3, 0.5, 0.7, 1.0, 1.5, 2.0, 2.1, 3.0, 8.0, 40.0, np.inf])


@settings(max_examples=200, deadline=None)
@given(
    ring=st.sampled_from([0, 1, 2, 3, 7, 16]),
    width=st.sampled_from([0.1, 0.25, 0.3, 1 / 3, 1.0, np.inf]),
    times=st.lists(TIMES, min_size=1, max_size=24),
    codes=st.lists(st.integers(-9, 23), min_size=24, max_size=24),
    ops=st.lists(
        st.tuples(st.sampled_from([POP, POP, MOVE, REBASE]), st.integers(0, 23), TIMES), min_size=1, max_size=200
    ),
)
def test_the_queue_always_names_the_first_event(ring, width, times, codes, ops):
    n = len(times)
    kinds = np.array([k for k, _, _ in ops])
    balls = np.array([b % n for _, b, _ in ops])
    steps = np.array([t if k != REBASE else min(t, 1.0) for k, _, t in ops])
    check_queue(ring, width, times, tie_codes(n, codes), kinds, balls, steps)


@pytest.mark.parametrize("ring", [1, 2, 5, 16])
def test_a_long_run_of_a_gas_like_queue(ring):
    """Events a mean time of 1 ahead, on times rounded to eighths of a bucket (many ties, many
    boundaries): 20,000 operations, mostly pops, with moves earlier and later and a rebase now
    and then, as a gas's calendar sees them."""
    rng = np.random.default_rng(ring)
    n, width, ops = 40, 0.1, 20_000
    grain = width / 8

    def ahead(size):
        return np.round(rng.exponential(1.0, size) / grain) * grain

    kinds = rng.choice([POP, MOVE, REBASE], size=ops, p=[0.7, 0.29, 0.01])
    balls = rng.integers(0, n, ops)
    rebase = rng.uniform(0, 0.5, ops)  # (off the grain: rebased times round)
    # a move goes to a time around the current one (roughly: each pop advances it by 1/n)
    now = np.cumsum(np.where(kinds == POP, 1.0 / n, 0.0) - np.where(kinds == REBASE, rebase, 0.0))
    steps = np.select(
        [kinds == MOVE, kinds == REBASE], [np.round(now / grain) * grain + ahead(ops), rebase], ahead(ops)
    )
    check_queue(ring, width, ahead(n), tie_codes(n, rng.integers(-9, n, n)), kinds, balls, steps)


@pytest.mark.parametrize("ring", [0, 2])
def test_a_rebase_that_rounds_two_times_into_a_tie_reorders_the_heap(ring):
    """1e-17 s and 2e-17 s, rebased by 1 s, both round to -1 s: the tie rule then puts ball 1
    (lower index) before ball 5, which was first until then."""
    times = [np.inf, 2e-17, np.inf, np.inf, np.inf, 1e-17]
    kinds, balls, steps = np.array([REBASE, POP, POP]), np.zeros(3, dtype=np.int64), np.array([1.0, 5.0, 5.0])
    check_queue(ring, 0.1, times, np.full(6, cal.EV_NONE, dtype=np.int32), kinds, balls, steps)
