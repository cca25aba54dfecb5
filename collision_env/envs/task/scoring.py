"""Scoring: which wall impacts land on which targets, and how far an aim is from one.

The impacts of a step (or of the look-ahead, :mod:`~.predict`) come as the engine's records,
sorted by scene then time. :func:`next_wall_impact` walks them: in cluster mode the task mirrors the
engine's clusters through the step, replayed from the impacts (a ball-ball impact merges two
clusters under the smaller root; a wall impact stops the cluster and takes it apart, as the engine
does), so that a wall impact scores only if its ball was part of a cluster at that instant.
:func:`target_hit` says which visible pending target, if any, a wall impact lands on.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from collision_env.engine.compiled import njit
from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT

from .layout import (
    CONTROL_SHOT,
    PARAMS,
    ROW_SKIP,
    ROW_STEPPED,
    SCENE_INTS,
    SWITCHES,
    TARGET_FAILED,
    TARGET_GEOMETRY,
    TARGET_HIT,
    TARGET_INTS,
    TARGET_PENDING,
)


class Box(NamedTuple):
    """The play area's bounds (m), read from the parameters once per call of a kernel: a parameter
    read again in each scene's loop, after the scene's writes to the task state (which the compiler
    cannot tell apart from the parameters), costs as much as the scene's aim."""

    xmin: float
    ymin: float
    xmax: float
    ymax: float


@njit(inline="always")
def play_area(p):  # pragma: no cover - numba
    """The play area's :class:`Box`, from the parameters ``p``."""
    return Box(p[PARAMS.xmin], p[PARAMS.ymin], p[PARAMS.xmax], p[PARAMS.ymax])


@njit(inline="always")
def on_side_wall(wall):  # pragma: no cover - numba
    """Left and right walls run along y; bottom and top along x. (Inlined by numba: a kernel of its
    own, even one LLVM may inline, keeps the aim's loops over balls and targets from being compiled
    as one, which costs a fifth of the task kernel.)"""
    return wall == WALL_LEFT or wall == WALL_RIGHT


@njit(refcount=False, forceinline=True)
def in_cluster(body, b, i):  # pragma: no cover - numba
    """Ball ``i`` of scene ``b`` is stuck to another ball (``body``: the cluster mirror)."""
    root = body[b, i]
    for k in range(body.shape[1]):
        if k != i and body[b, k] == root:
            return True
    return False


@njit(refcount=False, forceinline=True)
def visible_targets(current, n_targets, seq):  # pragma: no cover - numba
    """The range of targets that can be hit now: the current one if sequential, else all."""
    if seq:
        return current, min(current + 1, n_targets)
    return 0, n_targets


@njit(refcount=False, forceinline=True)
def _merge(body, b, i, o):  # pragma: no cover - numba
    """Ball-ball impact in a stick scene: the two clusters become one, under the smaller root."""
    root = min(body[b, i], body[b, o])
    gone = max(body[b, i], body[b, o])
    for q in range(body.shape[1]):
        if body[b, q] == gone:
            body[b, q] = root


@njit(refcount=False, forceinline=True)
def _split(body, b, i):  # pragma: no cover - numba
    """Wall impact in a stick scene: the cluster of ball i stops and comes apart."""
    root = body[b, i]
    for q in range(body.shape[1]):
        if body[b, q] == root:
            body[b, q] = q


@njit(refcount=False, forceinline=True)
def next_wall_impact(j, imp, flags, stepped_only, body, scoring, cluster):  # pragma: no cover - numba
    """The first wall impact at or after record ``j`` of a scene the walk looks at (its flag is
    ``ROW_STEPPED``, or with ``stepped_only`` False anything but ``ROW_SKIP``), and whether its
    ball scores (``scoring[ball]``, and with ``cluster`` scoring only while stuck): ``(j, scores)``,
    ``j = len(imp)`` when there is none. On the way, ball-ball impacts merge the clusters of the
    mirror ``body``; the wall impact's cluster comes apart."""
    while j < imp.shape[0]:
        b = imp[j]["scene"]
        looked_at = flags[b] == ROW_STEPPED if stepped_only else flags[b] != ROW_SKIP
        if looked_at:
            i = imp[j]["ball"]
            if imp[j]["wall"] >= 0:
                scores = scoring[i] and (not cluster or in_cluster(body, b, i))
                if cluster:
                    _split(body, b, i)
                return j, scores
            o = imp[j]["other"]
            if cluster and o >= 0:
                _merge(body, b, i, o)
        j += 1
    return j, False


@njit(refcount=False, forceinline=True)
def target_hit(j, imp, state, seq):  # pragma: no cover - numba
    """The first visible pending target of wall impact ``j``'s scene that the impact lands on (on
    its segment, inside its window), or -1."""
    b = imp[j]["scene"]
    w = imp[j]["wall"]
    along = imp[j]["y"] if on_side_wall(w) else imp[j]["x"]
    t = imp[j]["time"]
    targets, geo = state.targets, state.target_geo
    k0, k1 = visible_targets(state.scene_i[b, SCENE_INTS.current], targets.shape[1], seq)
    for k in range(k0, k1):
        if (
            targets[b, k, TARGET_INTS.status] == TARGET_PENDING
            and targets[b, k, TARGET_INTS.wall] == w
            and abs(along - geo[b, k, TARGET_GEOMETRY.centre]) <= geo[b, k, TARGET_GEOMETRY.half_width]
            and geo[b, k, TARGET_GEOMETRY.opens] <= t
            and t <= geo[b, k, TARGET_GEOMETRY.closes]
        ):
            return k
    return -1


@njit(inline="always")
def _squared_distance_to_target(cx, cy, wall, centre, hw, xmin, ymin, xmax, ymax):  # pragma: no cover - numba
    """Squared distance from (cx, cy) to the target segment of half width hw centred at ``centre`` on
    ``wall``. (The segment's ends are selected, not branched to: a batch's targets sit on walls at
    random, which a processor's branch prediction cannot follow.)"""
    lo = centre - hw
    hi = centre + hw
    side = on_side_wall(wall)
    wx = xmin if wall == WALL_LEFT else xmax
    wy = ymin if wall == WALL_BOTTOM else ymax
    x0 = wx if side else lo
    x1 = wx if side else hi
    y0 = lo if side else wy
    y1 = hi if side else wy
    sx = x1 - x0
    sy = y1 - y0
    u = ((cx - x0) * sx + (cy - y0) * sy) / (sx * sx + sy * sy)
    u = min(max(u, 0.0), 1.0)
    dx = cx - (x0 + u * sx)
    dy = cy - (y0 + u * sy)
    return dx * dx + dy * dy


@njit(refcount=False, forceinline=True)
def aim_squared(cx, cy, b, state, seq, box):  # pragma: no cover - numba
    """Squared distance from a wall point (cx, cy) to the nearest visible pending target of scene b
    (inf if none; ``box``: the play area's :class:`Box`). The distance is its square root, taken
    once for the nearest: a square root (and a division by a positive scale) keeps the order of its
    arguments, so the root of the least square is the least root, bit for bit, for one root instead
    of one per target."""
    best = math.inf
    targets, geo = state.targets, state.target_geo
    k0, k1 = visible_targets(state.scene_i[b, SCENE_INTS.current], targets.shape[1], seq)
    for k in range(k0, k1):
        if targets[b, k, TARGET_INTS.status] == TARGET_PENDING:
            d = _squared_distance_to_target(
                cx,
                cy,
                targets[b, k, TARGET_INTS.wall],
                geo[b, k, TARGET_GEOMETRY.centre],
                geo[b, k, TARGET_GEOMETRY.half_width],
                box.xmin,
                box.ymin,
                box.xmax,
                box.ymax,
            )
            best = min(best, d)
    return best


@njit(refcount=False, forceinline=True)
def landing_squared(j, imp, state, seq):  # pragma: no cover - numba
    """Squared distance along its wall from wall impact ``j`` to the nearest visible pending target
    on that wall, 0 on it (inf if none: the impact does not land where a target waits)."""
    b = imp[j]["scene"]
    w = imp[j]["wall"]
    along = imp[j]["y"] if on_side_wall(w) else imp[j]["x"]
    best = math.inf
    targets, geo = state.targets, state.target_geo
    k0, k1 = visible_targets(state.scene_i[b, SCENE_INTS.current], targets.shape[1], seq)
    for k in range(k0, k1):
        if targets[b, k, TARGET_INTS.status] == TARGET_PENDING and targets[b, k, TARGET_INTS.wall] == w:
            d = max(abs(along - geo[b, k, TARGET_GEOMETRY.centre]) - geo[b, k, TARGET_GEOMETRY.half_width], 0.0)
            best = min(best, d * d)
    return best


@njit(refcount=False, forceinline=True)
def _fail_on_wall(j, imp, state, seq):  # pragma: no cover - numba
    """Shot control: wall impact ``j`` missed every target, so the visible pending targets on its
    wall fail (the shot that was to hit them has struck their wall elsewhere)."""
    b = imp[j]["scene"]
    targets = state.targets
    k0, k1 = visible_targets(state.scene_i[b, SCENE_INTS.current], targets.shape[1], seq)
    for k in range(k0, k1):
        if targets[b, k, TARGET_INTS.status] == TARGET_PENDING and targets[b, k, TARGET_INTS.wall] == imp[j]["wall"]:
            targets[b, k, TARGET_INTS.status] = TARGET_FAILED


@njit(refcount=False, forceinline=True)
def score_impacts(flags, imp, state, params):  # pragma: no cover - numba
    """Count each stepped scene's target hits and off-target wall impacts of scoring balls
    (``scene_i[:, hits]`` and ``misses``), marking the targets hit (and, with sequential targets,
    moving on to the next); with shot control an off-target impact fails the visible pending
    targets on its wall (:func:`_fail_on_wall`)."""
    seq = params.switches[SWITCHES.sequential] != 0
    shot = params.switches[SWITCHES.control] == CONTROL_SHOT
    cluster = params.switches[SWITCHES.cluster] != 0
    scene_i = state.scene_i
    for b in range(flags.shape[0]):
        scene_i[b, SCENE_INTS.hits] = 0
        scene_i[b, SCENE_INTS.misses] = 0
    j, scores = next_wall_impact(0, imp, flags, True, state.body, params.scoring, cluster)
    while j < imp.shape[0]:
        if scores:
            b = imp[j]["scene"]
            k = target_hit(j, imp, state, seq)
            if k >= 0:
                state.targets[b, k, TARGET_INTS.status] = TARGET_HIT
                if seq:
                    scene_i[b, SCENE_INTS.current] += 1
                scene_i[b, SCENE_INTS.hits] += 1
            else:
                scene_i[b, SCENE_INTS.misses] += 1
                if shot:
                    _fail_on_wall(j, imp, state, seq)
        j, scores = next_wall_impact(j + 1, imp, flags, True, state.body, params.scoring, cluster)
