"""The episodes' progress and end: step counts, closed windows, targets hit, and each stepped
scene's reward and end flags (``terminated``, ``truncated``, ``success``).

The reward of a step is ``hits * hit_reward - misses * miss_penalty - action_cost * nudge``, plus
``success_bonus`` when the last target is hit, plus the shaping term ``shaping * (phi' - phi)`` of
a step without a hit (a potential-based shaping, Ng, Harada & Russell 1999), phi being the aiming
potential: minus the distance, over the play-area diagonal, from the nearest scoring ball's aim
point to a visible pending target (straight flight here; the engine's prediction with
``aim="predicted"``, :mod:`~.predict`).
"""

from __future__ import annotations

import math

from collision_env.engine.compiled import ball_views, njit

from .layout import (
    PARAMS,
    ROW_OBSERVE,
    ROW_RESET,
    ROW_SKIP,
    ROW_STEPPED,
    SCENE_FLOATS,
    SCENE_INTS,
    SWITCHES,
    TARGET_FAILED,
    TARGET_GEOMETRY,
    TARGET_HIT,
    TARGET_INTS,
    TARGET_PENDING,
)
from .scoring import aim_squared, in_cluster, play_area


@njit(refcount=False, forceinline=True)
def advance_episodes(flags, engine, state, params):  # pragma: no cover - numba
    """Count the step (restart the count on a reset), fail targets whose window closed unhit, take
    the engine's clusters, and count the targets hit."""
    cluster = params.switches[SWITCHES.cluster] != 0
    targets, scene_i, body = state.targets, state.scene_i, state.body
    for b in range(flags.shape[0]):
        f = flags[b]
        if f == ROW_SKIP:
            continue
        if f == ROW_STEPPED:
            scene_i[b, SCENE_INTS.steps] += 1
            now = engine.time[b]
            for k in range(targets.shape[1]):
                pending = targets[b, k, TARGET_INTS.status] == TARGET_PENDING
                if pending and state.target_geo[b, k, TARGET_GEOMETRY.closes] < now:
                    targets[b, k, TARGET_INTS.status] = TARGET_FAILED
        elif f == ROW_RESET:
            scene_i[b, SCENE_INTS.steps] = 0
        if cluster:
            for q in range(body.shape[1]):
                body[b, q] = engine.clusters[b, q]
        n_hit = 0
        for k in range(targets.shape[1]):
            if targets[b, k, TARGET_INTS.status] == TARGET_HIT:
                n_hit += 1
        scene_i[b, SCENE_INTS.targets_hit] = n_hit


@njit(inline="always")
def border_contact(x, y, vx, vy, r, xmin, ymin, xmax, ymax):  # pragma: no cover - numba
    """Where a ball at (x, y) of radius r would touch the border flying straight on at (vx, vy) != 0.
    (Walls and results are selected, not branched to: the directions of a batch's balls are random,
    which a processor's branch prediction cannot follow.)"""
    ex = xmax - r if vx > 0.0 else xmin + r
    ey = ymax - r if vy > 0.0 else ymin + r
    tx = (ex - x) / vx if vx != 0.0 else math.inf
    ty = (ey - y) / vy if vy != 0.0 else math.inf
    at_x = tx <= ty
    cx = (xmax if vx > 0.0 else xmin) if at_x else x + vx * max(ty, 0.0)
    cy = y + vy * max(tx, 0.0) if at_x else (ymax if vy > 0.0 else ymin)
    return cx, cy


@njit(inline="always")
def play_area_diagonal(box):  # pragma: no cover - numba
    """The length of the play area's diagonal (the aiming potential's unit), from its ``scoring.Box``."""
    return math.sqrt((box.xmax - box.xmin) ** 2 + (box.ymax - box.ymin) ** 2)


@njit(refcount=False, forceinline=True)
def _straight_aim(b, views, box, diag, shaping, state, params, seq, cluster):  # pragma: no cover - numba
    """Scene ``b``'s aiming potential phi in straight flight (``views``: the engine's ``ball_views``,
    ``box`` and ``diag``: the play area's ``scoring.Box`` and diagonal, ``shaping``: the parameter):
    minus the distance, over the play-area diagonal, from each scoring ball's straight-line border
    contact point to the nearest visible pending target, at its smallest (-1 when nothing is aimed,
    or when the task does not shape): a heuristic that ignores other balls."""
    if shaping == 0.0:
        return -1.0
    pos, vel, _, _, radii, _ = views
    best = math.inf  # (the least squared distance: see scoring.aim_squared)
    for i in range(pos.shape[1]):
        if not (params.scoring[i] and (not cluster or in_cluster(state.body, b, i))):
            continue
        vx = vel[b, i, 0]
        vy = vel[b, i, 1]
        if vx == 0.0 and vy == 0.0:
            continue
        cx, cy = border_contact(
            pos[b, i, 0],
            pos[b, i, 1],
            vx,
            vy,
            radii[b, i],
            box.xmin,
            box.ymin,
            box.xmax,
            box.ymax,
        )
        best = min(best, aim_squared(cx, cy, b, state, seq, box))
    return -min(1.0, math.sqrt(best) / diag)


@njit(refcount=False, forceinline=True)
def _reward(b, phi_new, state, params, straight):  # pragma: no cover - numba
    """Stepped scene ``b``'s reward and end flags."""
    p, scene_f, scene_i = params.params, state.scene_f, state.scene_i
    n_targets = state.targets.shape[1]
    failed = False
    for k in range(n_targets):
        if state.targets[b, k, TARGET_INTS.status] == TARGET_FAILED:
            failed = True
    done_ok = scene_i[b, SCENE_INTS.targets_hit] == n_targets
    hits = scene_i[b, SCENE_INTS.hits]
    rew = (
        hits * p[PARAMS.hit_reward]
        - scene_i[b, SCENE_INTS.misses] * p[PARAMS.miss_penalty]
        - p[PARAMS.action_cost] * scene_f[b, SCENE_FLOATS.nudge]
    )
    if done_ok:
        rew += p[PARAMS.success_bonus]
    if hits == 0 and straight:
        rew += p[PARAMS.shaping] * (phi_new - scene_f[b, SCENE_FLOATS.phi])
    scene_f[b, SCENE_FLOATS.reward] = rew
    scene_i[b, SCENE_INTS.terminated] = done_ok or failed
    scene_i[b, SCENE_INTS.truncated] = scene_i[b, SCENE_INTS.steps] >= params.switches[SWITCHES.n_steps]
    scene_i[b, SCENE_INTS.success] = done_ok


@njit(refcount=False, forceinline=True)
def settle(flags, engine, state, params):  # pragma: no cover - numba
    """Reward and end flags of each stepped scene (zero and False for a reset or observed one), and
    the aiming potential phi kept for the next step (unless the scene was only observed). The
    straight-flight potential is computed only where it is used (:mod:`~.predict` computes the
    predicted one)."""
    seq = params.switches[SWITCHES.sequential] != 0
    cluster = params.switches[SWITCHES.cluster] != 0
    straight = params.switches[SWITCHES.aim_predicted] == 0
    scene_f, scene_i = state.scene_f, state.scene_i
    views = ball_views(engine.balls)
    # (read once per call: see scoring.Box)
    box = play_area(params.params)
    diag = play_area_diagonal(box)
    shaping = params.params[PARAMS.shaping]
    for b in range(flags.shape[0]):
        f = flags[b]
        if f == ROW_SKIP:
            continue
        phi_new = _straight_aim(b, views, box, diag, shaping, state, params, seq, cluster) if straight else -1.0
        if f == ROW_STEPPED:
            _reward(b, phi_new, state, params, straight)
        else:
            scene_f[b, SCENE_FLOATS.reward] = 0.0
            scene_i[b, SCENE_INTS.terminated] = False
            scene_i[b, SCENE_INTS.truncated] = False
            scene_i[b, SCENE_INTS.success] = False
        if f != ROW_OBSERVE and straight:
            scene_f[b, SCENE_FLOATS.phi] = phi_new
