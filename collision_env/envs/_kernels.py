"""Batched task kernels: action -> nudge, and impacts -> target hits, reward, observation.

Both work on a batch of B scenes and are the only per-step task logic: the single env is a batch
of one, so the single env and the native vector env run the same arithmetic and agree bit for bit.
They are plain loops, compiled with numba when it is installed (like the engine's kernels) and run
as ordinary Python otherwise. Each kernel is a short sequence of named phases, each a loop over the
scenes; the phases are ``inline="always"`` helpers, so numba compiles a kernel into one function.
(Phases loop over the scenes themselves because a helper that takes arrays, called once per scene,
pays numba's reference counting on every call: several times the work of a one-ball scene.)

The packed arrays are indexed by the named layouts of ``_layout`` (``S[b, SCENE_FLOATS.reward]``);
wall codes are the engine's (``collision_env.engine.WALL_LEFT`` ... ``WALL_TOP``).
"""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine._jit import njit
from collision_env.engine.physics.motion import apply_impulses, ball_views
from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT, WALL_TOP
from collision_env.envs._layout import (
    BALL_OBS,
    EPISODE_FLOATS,
    EPISODE_INTS,
    GLOBAL_OBS,
    PARAMS,
    PREDICTED_OBS,
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
    TARGET_OBS,
    TARGET_PENDING,
)

# short local names for the layouts the kernels index most
SF, SI, TI, TG = SCENE_FLOATS, SCENE_INTS, TARGET_INTS, TARGET_GEOMETRY


@njit(inline="always")
def _on_side_wall(wall):  # pragma: no cover - numba
    """Left and right walls run along y; bottom and top along x."""
    return wall == WALL_LEFT or wall == WALL_RIGHT


@njit(inline="always")
def _clip1(v):  # pragma: no cover - numba
    return min(max(v, -1.0), 1.0)


# --------------------------------------------------------------------------------------------- #
# nudge


@njit(inline="always")
def _first_nan_row(actions, active):  # pragma: no cover - numba
    """The first active row holding a NaN, or -1 (an inactive row's action is ignored, NaN or not)."""
    for b in range(actions.shape[0]):
        if active[b]:
            for c in range(actions.shape[1]):
                if actions[b, c] != actions[b, c]:
                    return b
    return -1


@njit(inline="always")
def capped_change(vx, vy, dx, dy, max_speed):  # pragma: no cover - numba
    """The velocity change that applies (dx, dy) to (vx, vy) without exceeding max(max_speed, |v|)."""
    nx = vx + dx
    ny = vy + dy
    s_new = math.sqrt(nx * nx + ny * ny)
    cap = max(max_speed, math.sqrt(vx * vx + vy * vy))
    if s_new > cap:
        f = cap / s_new
        nx *= f
        ny *= f
    return nx - vx, ny - vy


@njit(inline="always")
def _requested_change(a, o, dim, velocity_control, vx, vy, max_dv, max_speed):  # pragma: no cover - numba
    """The velocity change one controlled ball's action components ``a[o:]`` ask for, each axis
    within ``max_dv``: with nudge control the components times ``max_dv``; with velocity control the
    step along the straight line from (vx, vy) to the named velocity (components times
    ``max_speed``, scaled back to ``max_speed`` if longer), shortened until no axis exceeds
    ``max_dv``, or none when the engage flag is <= 0.

    A named velocity no longer than ``max_speed`` keeps the whole line within the speed cap of
    :func:`capped_change` (a disc holds the segment between two of its points), so under velocity
    control the change charged is the change made."""
    ax = _clip1(a[o])
    ay = _clip1(a[o + 1]) if dim == 2 else 0.0
    if not velocity_control:
        return ax * max_dv, ay * max_dv
    if not a[o + dim] > 0.0:
        return 0.0, 0.0
    length = math.sqrt(ax * ax + ay * ay)
    if length > 1.0:
        ax /= length
        ay /= length
    dx = ax * max_speed - vx
    dy = ay * max_speed - vy if dim == 2 else 0.0
    longest = max(abs(dx), abs(dy))
    if longest > max_dv:
        f = max_dv / longest
        dx *= f
        dy *= f
    return dx, dy


@njit(refcount=False)
def nudge_kernel(actions, active, balls, body, ctrl, P, Q, dv, S):  # pragma: no cover - numba
    """Turn actions into velocity changes ``dv`` (B, N, 2) and their size ``S[:, nudge]``, and apply
    them to the engine's balls with the engine's own impulse kernel.

    Returns -1, or the first active row holding a NaN (then nothing is written). Only the controlled
    balls' entries of ``dv`` are written (the others must be zero).
    Each action component is clipped to [-1, 1]; :func:`_requested_change` reads a ball's
    components as ``TaskConfig.control`` says. The nudge never raises a ball's speed above
    max(max_speed, current speed). ``nudge`` is the requested |dv|, summed over the controlled
    balls, in m/s; the task kernel charges ``action_cost`` times it.
    Rows with ``active`` False get no nudge and no cost.
    """
    bad = _first_nan_row(actions, active)
    if bad >= 0:
        return bad  # reject the whole call before changing anything
    _, vel, _, _, _, _ = ball_views(balls)
    dim = Q[SWITCHES.dimension]
    velocity_control = Q[SWITCHES.velocity_control] != 0
    per_ball = dim + 1 if velocity_control else dim
    max_dv = P[PARAMS.max_dv]
    max_speed = P[PARAMS.max_speed]
    for b in range(actions.shape[0]):
        requested = 0.0
        for c in range(ctrl.shape[0]):
            i = ctrl[c]
            if not active[b]:
                dv[b, i, 0] = 0.0
                dv[b, i, 1] = 0.0
                continue
            dx, dy = _requested_change(
                actions[b], c * per_ball, dim, velocity_control, vel[b, i, 0], vel[b, i, 1], max_dv, max_speed
            )
            requested += math.sqrt(dx * dx + dy * dy)
            cdx, cdy = capped_change(vel[b, i, 0], vel[b, i, 1], dx, dy, max_speed)
            dv[b, i, 0] = cdx
            dv[b, i, 1] = cdy
        S[b, SF.nudge] = requested
    apply_impulses(balls, body, dv, Q[SWITCHES.sticky] != 0)
    return -1


# --------------------------------------------------------------------------------------------- #
# scoring: impacts -> target hits


@njit
def _in_cluster(body, b, i):  # pragma: no cover - numba
    root = body[b, i]
    for k in range(body.shape[1]):
        if k != i and body[b, k] == root:
            return True
    return False


@njit(inline="always")
def _visible_targets(current, n_targets, seq):  # pragma: no cover - numba
    """The range of targets that can be hit now: the current one if sequential, else all."""
    if seq:
        return current, min(current + 1, n_targets)
    return 0, n_targets


# The phases below loop over the scenes themselves; the helpers they call per scene take scalars
# (see the module docstring).


@njit(inline="always")
def _merge(body, b, i, o):  # pragma: no cover - numba
    """Ball-ball impact in a stick scene: the two clusters become one, under the smaller root."""
    root = min(body[b, i], body[b, o])
    gone = max(body[b, i], body[b, o])
    for q in range(body.shape[1]):
        if body[b, q] == gone:
            body[b, q] = root


@njit(inline="always")
def _split(body, b, i):  # pragma: no cover - numba
    """Wall impact in a stick scene: the cluster of ball i stops and comes apart."""
    root = body[b, i]
    for q in range(body.shape[1]):
        if body[b, q] == root:
            body[b, q] = q


@njit(inline="always")
def _target_at(T, t_geo, b, k0, k1, w, along, t):  # pragma: no cover - numba
    """The first pending target among k0..k1-1 of scene b that a wall-w impact at ``along``, time t, hits; or -1."""
    for k in range(k0, k1):
        if (
            T[b, k, TI.status] == TARGET_PENDING
            and T[b, k, TI.wall] == w
            and abs(along - t_geo[b, k, TG.centre]) <= t_geo[b, k, TG.half_width]
            and t_geo[b, k, TG.opens] <= t
            and t <= t_geo[b, k, TG.closes]
        ):
            return k
    return -1


@njit(inline="always")
def _score_impacts(flags, imp, C, T, t_geo, body, qual, seq, cluster):  # pragma: no cover - numba
    """Count each stepped scene's target hits and off-target wall impacts of scoring balls.

    In cluster mode ``body`` mirrors the engine's clusters through the step, replayed from the
    impacts (a ball-ball impact merges two clusters under the smaller root; a wall impact stops the
    cluster and takes it apart, as the engine does), so that a wall impact scores only if its ball
    was part of a cluster at that instant.
    """
    for b in range(flags.shape[0]):
        C[b, SI.hits] = 0
        C[b, SI.misses] = 0
    for j in range(imp.shape[0]):
        b = imp[j]["scene"]
        if flags[b] != ROW_STEPPED:
            continue
        i = imp[j]["ball"]
        w = imp[j]["wall"]
        if w < 0:
            o = imp[j]["other"]
            if cluster and o >= 0:
                _merge(body, b, i, o)
            continue
        scores = qual[i]
        if cluster:
            scores = scores and _in_cluster(body, b, i)
            _split(body, b, i)
        if not scores:
            continue
        along = imp[j]["y"] if _on_side_wall(w) else imp[j]["x"]
        k0, k1 = _visible_targets(C[b, SI.current], T.shape[1], seq)
        k = _target_at(T, t_geo, b, k0, k1, w, along, imp[j]["time"])
        if k >= 0:
            T[b, k, TI.status] = TARGET_HIT
            if seq:
                C[b, SI.current] += 1
            C[b, SI.hits] += 1
        else:
            C[b, SI.misses] += 1


@njit(inline="always")
def _advance_episodes(flags, sim_time, clusters, C, T, t_geo, body, cluster):  # pragma: no cover - numba
    """Count the step (restart the count on a reset), fail targets whose window closed unhit, take
    the engine's clusters, and count the targets hit."""
    for b in range(flags.shape[0]):
        f = flags[b]
        if f == ROW_SKIP:
            continue
        if f == ROW_STEPPED:
            C[b, SI.steps] += 1
            for k in range(T.shape[1]):
                if T[b, k, TI.status] == TARGET_PENDING and t_geo[b, k, TG.closes] < sim_time[b]:
                    T[b, k, TI.status] = TARGET_FAILED
        elif f == ROW_RESET:
            C[b, SI.steps] = 0
        if cluster:
            for q in range(body.shape[1]):
                body[b, q] = clusters[b, q]
        n_hit = 0
        for k in range(T.shape[1]):
            if T[b, k, TI.status] == TARGET_HIT:
                n_hit += 1
        C[b, SI.targets_hit] = n_hit


@njit(inline="always")
def _observed_point(wall, centre, xc, yc, xh, yh):  # pragma: no cover - numba
    """A target's centre point in observation coordinates, and the half length of its wall."""
    if wall == WALL_LEFT:
        return -1.0, (centre - yc) / yh, yh
    if wall == WALL_RIGHT:
        return 1.0, (centre - yc) / yh, yh
    if wall == WALL_BOTTOM:
        return (centre - xc) / xh, -1.0, xh
    return (centre - xc) / xh, 1.0, xh


@njit(inline="always")
def _observe(
    flags, obs, S, pos, vel, masses, body, qual, shown, C, T, t_geo, sim_time, seq, cluster, n_steps, P
):  # pragma: no cover - numba
    """Write the observation (the ``shown`` balls' blocks, target slots, globals) and the kinetic energy."""
    xc, yc, xh, yh = _centre_and_half_size(P)
    vscale = P[PARAMS.vscale]
    mscale = P[PARAMS.mscale]
    tlimit = P[PARAMS.time_limit]
    N = pos.shape[1]
    K = T.shape[1]
    for b in range(flags.shape[0]):
        if flags[b] == ROW_SKIP:
            continue
        ke = 0.0
        o = 0
        for i in range(N):  # ball blocks
            vx = vel[b, i, 0]
            vy = vel[b, i, 1]
            ke += 0.5 * masses[b, i] * (vx * vx + vy * vy)
            if not shown[i]:
                continue
            obs[b, o + BALL_OBS.x] = _clip1((pos[b, i, 0] - xc) / xh)
            obs[b, o + BALL_OBS.y] = _clip1((pos[b, i, 1] - yc) / yh)
            obs[b, o + BALL_OBS.vx] = _clip1(vx / vscale)
            obs[b, o + BALL_OBS.vy] = _clip1(vy / vscale)
            obs[b, o + BALL_OBS.mass] = _clip1(masses[b, i] / mscale)
            scoring = qual[i] and (not cluster or _in_cluster(body, b, i))
            obs[b, o + BALL_OBS.scoring] = 1.0 if scoring else 0.0
            o += len(BALL_OBS)
        S[b, SF.energy] = ke
        now = sim_time[b]
        for slot in range(1 if seq else K):  # target slots: the current target when sequential
            k = min(C[b, SI.current], K - 1) if seq else slot
            w = T[b, k, TI.wall]
            px, py, half = _observed_point(w, t_geo[b, k, TG.centre], xc, yc, xh, yh)
            obs[b, o + TARGET_OBS.x] = _clip1(px)
            obs[b, o + TARGET_OBS.y] = _clip1(py)
            obs[b, o + TARGET_OBS.half_width] = _clip1(t_geo[b, k, TG.half_width] / half)
            for q in range(WALL_TOP + 1):
                obs[b, o + TARGET_OBS.wall_left + q] = 1.0 if q == w else 0.0
            st = T[b, k, TI.status]
            obs[b, o + TARGET_OBS.status] = 1.0 if st == TARGET_PENDING else (0.0 if st == TARGET_HIT else -1.0)
            obs[b, o + TARGET_OBS.opens] = _clip1((t_geo[b, k, TG.opens] - now) / tlimit)
            obs[b, o + TARGET_OBS.closes] = _clip1((t_geo[b, k, TG.closes] - now) / tlimit)
            o += len(TARGET_OBS)
        obs[b, o + GLOBAL_OBS.steps_left] = min(max(1.0 - C[b, SI.steps] / n_steps, 0.0), 1.0)
        obs[b, o + GLOBAL_OBS.targets_left] = (K - C[b, SI.targets_hit]) / K


@njit(inline="always")
def _centre_and_half_size(P):  # pragma: no cover - numba
    xmin = P[PARAMS.xmin]
    ymin = P[PARAMS.ymin]
    xmax = P[PARAMS.xmax]
    ymax = P[PARAMS.ymax]
    return 0.5 * (xmin + xmax), 0.5 * (ymin + ymax), 0.5 * (xmax - xmin), 0.5 * (ymax - ymin)


@njit(inline="always")
def _border_contact(x, y, vx, vy, r, xmin, ymin, xmax, ymax):  # pragma: no cover - numba
    """Where a ball at (x, y) of radius r would touch the border flying straight on at (vx, vy) != 0."""
    tx = math.inf
    ty = math.inf
    if vx > 0.0:
        tx = (xmax - r - x) / vx
    elif vx < 0.0:
        tx = (xmin + r - x) / vx
    if vy > 0.0:
        ty = (ymax - r - y) / vy
    elif vy < 0.0:
        ty = (ymin + r - y) / vy
    if tx <= ty:
        return xmax if vx > 0.0 else xmin, y + vy * max(tx, 0.0)
    return x + vx * max(ty, 0.0), ymax if vy > 0.0 else ymin


@njit(inline="always")
def _distance_to_target(cx, cy, wall, centre, hw, xmin, ymin, xmax, ymax):  # pragma: no cover - numba
    """Distance from (cx, cy) to the target segment of half width hw centred at ``centre`` on ``wall``."""
    if wall == WALL_LEFT:
        x0, y0, x1, y1 = xmin, centre - hw, xmin, centre + hw
    elif wall == WALL_RIGHT:
        x0, y0, x1, y1 = xmax, centre - hw, xmax, centre + hw
    elif wall == WALL_BOTTOM:
        x0, y0, x1, y1 = centre - hw, ymin, centre + hw, ymin
    else:
        x0, y0, x1, y1 = centre - hw, ymax, centre + hw, ymax
    sx = x1 - x0
    sy = y1 - y0
    u = ((cx - x0) * sx + (cy - y0) * sy) / (sx * sx + sy * sy)
    u = min(max(u, 0.0), 1.0)
    dx = cx - (x0 + u * sx)
    dy = cy - (y0 + u * sy)
    return math.sqrt(dx * dx + dy * dy)


@njit(inline="always")
def _aim_distance(cx, cy, b, C, T, t_geo, seq, P):  # pragma: no cover - numba
    """Distance from a wall point (cx, cy) to the nearest visible pending target of scene b (inf if none)."""
    best = math.inf
    k0, k1 = _visible_targets(C[b, SI.current], T.shape[1], seq)
    for k in range(k0, k1):
        if T[b, k, TI.status] == TARGET_PENDING:
            d = _distance_to_target(
                cx,
                cy,
                T[b, k, TI.wall],
                t_geo[b, k, TG.centre],
                t_geo[b, k, TG.half_width],
                P[PARAMS.xmin],
                P[PARAMS.ymin],
                P[PARAMS.xmax],
                P[PARAMS.ymax],
            )
            best = min(best, d)
    return best


@njit(inline="always")
def _settle(flags, S, C, T, t_geo, pos, vel, radii, body, qual, seq, cluster, n_steps, P, Q):  # pragma: no cover
    """Reward and end flags of each stepped scene (zero and False for a reset or observed one), and
    the aiming potential phi kept for the next step (unless the scene was only observed).

    phi is minus the distance, over the play-area diagonal, from each scoring ball's straight-line
    border contact point to the nearest visible pending target, at its smallest (-1 when nothing is
    aimed, or when the task does not shape): a heuristic that ignores other balls.
    """
    xmin = P[PARAMS.xmin]
    ymin = P[PARAMS.ymin]
    xmax = P[PARAMS.xmax]
    ymax = P[PARAMS.ymax]
    diag = math.sqrt((xmax - xmin) ** 2 + (ymax - ymin) ** 2)
    # the straight-line aiming potential is only computed when it is used (predict_kernel computes
    # the predicted one)
    straight = Q[SWITCHES.aim_predicted] == 0
    shaping = P[PARAMS.shaping] != 0.0 and straight
    K = T.shape[1]
    for b in range(flags.shape[0]):
        f = flags[b]
        if f == ROW_SKIP:
            continue
        best = 1.0
        for i in range(pos.shape[1] if shaping else 0):
            if not (qual[i] and (not cluster or _in_cluster(body, b, i))):
                continue
            vx = vel[b, i, 0]
            vy = vel[b, i, 1]
            if vx == 0.0 and vy == 0.0:
                continue
            cx, cy = _border_contact(pos[b, i, 0], pos[b, i, 1], vx, vy, radii[b, i], xmin, ymin, xmax, ymax)
            best = min(best, _aim_distance(cx, cy, b, C, T, t_geo, seq, P) / diag)
        phi_new = -best

        if f == ROW_STEPPED:
            failed = False
            for k in range(K):
                if T[b, k, TI.status] == TARGET_FAILED:
                    failed = True
            done_ok = C[b, SI.targets_hit] == K
            hits = C[b, SI.hits]
            rew = (
                hits * P[PARAMS.hit_reward]
                - C[b, SI.misses] * P[PARAMS.miss_penalty]
                - P[PARAMS.action_cost] * S[b, SF.nudge]
            )
            if done_ok:
                rew += P[PARAMS.success_bonus]
            if hits == 0 and straight:
                rew += P[PARAMS.shaping] * (phi_new - S[b, SF.phi])
            S[b, SF.reward] = rew
            C[b, SI.terminated] = done_ok or failed
            C[b, SI.truncated] = C[b, SI.steps] >= n_steps
            C[b, SI.success] = done_ok
        else:
            S[b, SF.reward] = 0.0
            C[b, SI.terminated] = False
            C[b, SI.truncated] = False
            C[b, SI.success] = False
        if f != ROW_OBSERVE and straight:
            S[b, SF.phi] = phi_new


@njit(refcount=False)
def task_kernel(
    flags, imp, balls, sim_time, clusters, S, C, T, t_geo, body, qual, shown, P, Q, obs
):  # pragma: no cover - numba
    """Score a step's impacts, update target state, and write reward, flags and observation.

    ``imp`` is the engine's impact record array for the batch (sorted by scene then time);
    ``balls`` (the per-ball state, ``engine.layout.BALL``), ``sim_time`` and ``clusters``
    are the engine's state after the step. ``flags`` holds one ``ROW_*`` code per scene.
    In cluster mode ``body`` mirrors the engine's cluster roots through the step (see
    ``_score_impacts``); at the end it is set to the engine's ``clusters``.
    Updated in place: target status, current target, step count, body, phi. Written for rows
    whose flag is not ``ROW_SKIP``: the observation, reward, energy, targets hit and the end flags.
    ``shown`` (N,) says whose ball blocks the observation has (``TaskConfig.observed_balls``).
    """
    pos, vel, masses, _, radii, _ = ball_views(balls)  # (always a C array: one compiled version for any B, N)
    seq = Q[SWITCHES.sequential] != 0
    cluster = Q[SWITCHES.cluster] != 0
    n_steps = Q[SWITCHES.n_steps]
    _score_impacts(flags, imp, C, T, t_geo, body, qual, seq, cluster)
    _advance_episodes(flags, sim_time, clusters, C, T, t_geo, body, cluster)
    _observe(flags, obs, S, pos, vel, masses, body, qual, shown, C, T, t_geo, sim_time, seq, cluster, n_steps, P)
    _settle(flags, S, C, T, t_geo, pos, vel, radii, body, qual, seq, cluster, n_steps, P, Q)


# --------------------------------------------------------------------------------------------- #
# the engine's prediction (observe="predicted")


@njit
def predict_kernel(flags, imp, sim_time, clusters, body, S, C, T, t_geo, qual, shown, P, Q, obs):  # pragma: no cover
    """Each ball's predicted wall impact: written into the observation's last entries, one
    ``PREDICTED_OBS`` block per ``shown`` ball (``observe_predicted``), and made the aiming potential
    (``aim_predicted``), for the rows whose flag is not ``ROW_SKIP``.

    ``imp`` are the impacts of a copy of the engine run ahead from the scenes' current state with no
    nudge (sorted by scene then time); ``sim_time`` is the scenes' current time and ``clusters``
    their cluster roots, from which ``body`` (scratch, (B, N)) replays the clusters through the
    look-ahead as the task kernel does. A ball's entry is its first wall impact: the contact point,
    the time until it over ``time_limit``, and whether it would score on a visible pending target
    (target status as the task kernel left it, so a target hit this step no longer counts); with
    ``predict_scoring``, a scoring ball's entry is its first impact that scores so, if one does.
    With ``aim_predicted``, phi is minus the distance, over the play-area diagonal, from the nearest
    of the scoring balls' predicted impact points (their first ones; all of them with
    ``predict_scoring``) to a visible pending target (-1 when none is predicted): the task kernel's
    shaping term, computed here with the engine's prediction instead of straight flight, added to
    the reward of stepped scenes without a hit.
    """
    xc, yc, xh, yh = _centre_and_half_size(P)
    diag = 2.0 * math.sqrt(xh * xh + yh * yh)
    tlimit = P[PARAMS.time_limit]
    seq = Q[SWITCHES.sequential] != 0
    cluster = Q[SWITCHES.cluster] != 0
    observe = Q[SWITCHES.observe_predicted] != 0
    aim = Q[SWITCHES.aim_predicted] != 0
    scan = Q[SWITCHES.predict_scoring] != 0
    N = body.shape[1]
    block = np.full(N, -1)  # the observation entry where each shown ball's block starts
    n_shown = 0
    for i in range(N):
        if shown[i]:
            n_shown += 1
    o = obs.shape[1] - n_shown * len(PREDICTED_OBS)
    for i in range(N):
        if shown[i]:
            block[i] = o
            o += len(PREDICTED_OBS)
    seen = np.zeros(body.shape, dtype=np.bool_)
    found = np.zeros(body.shape, dtype=np.bool_)  # (a scoring impact is in the ball's block)
    best = np.ones(body.shape[0])
    for b in range(flags.shape[0]):
        if flags[b] == ROW_SKIP:
            continue
        for i in range(N):
            body[b, i] = clusters[b, i]
            if observe and shown[i]:
                o = block[i]
                obs[b, o + PREDICTED_OBS.x] = 0.0
                obs[b, o + PREDICTED_OBS.y] = 0.0
                obs[b, o + PREDICTED_OBS.time] = 1.0
                obs[b, o + PREDICTED_OBS.hits] = 0.0
    for j in range(imp.shape[0]):
        b = imp[j]["scene"]
        if flags[b] == ROW_SKIP:
            continue
        i = imp[j]["ball"]
        w = imp[j]["wall"]
        if w < 0:
            o = imp[j]["other"]
            if cluster and o >= 0:
                _merge(body, b, i, o)
            continue
        scores = qual[i] and (not cluster or _in_cluster(body, b, i))
        if cluster:
            _split(body, b, i)
        first = not seen[b, i]
        if not (first or (scan and scores and not found[b, i])):
            continue
        seen[b, i] = True
        x = imp[j]["x"]
        y = imp[j]["y"]
        t = imp[j]["time"]
        if aim and scores:
            best[b] = min(best[b], _aim_distance(x, y, b, C, T, t_geo, seq, P) / diag)
        if observe and shown[i]:
            hits = False
            if scores:
                k0, k1 = _visible_targets(C[b, SI.current], T.shape[1], seq)
                hits = _target_at(T, t_geo, b, k0, k1, w, y if _on_side_wall(w) else x, t) >= 0
            if first or hits:
                found[b, i] = hits
                o = block[i]
                obs[b, o + PREDICTED_OBS.x] = _clip1((x - xc) / xh)
                obs[b, o + PREDICTED_OBS.y] = _clip1((y - yc) / yh)
                obs[b, o + PREDICTED_OBS.time] = _clip1((t - sim_time[b]) / tlimit)
                obs[b, o + PREDICTED_OBS.hits] = 1.0 if hits else 0.0
    if aim:
        for b in range(flags.shape[0]):
            f = flags[b]
            if f == ROW_STEPPED and C[b, SI.hits] == 0:
                S[b, SF.reward] += P[PARAMS.shaping] * (-best[b] - S[b, SF.phi])
            if f == ROW_STEPPED or f == ROW_RESET:
                S[b, SF.phi] = -best[b]


# --------------------------------------------------------------------------------------------- #
# episode construction from blocks of uniform random numbers

_GAP = 1e-3
_NO_WINDOW = 1e300  # a target without a time window is open from -_NO_WINDOW to _NO_WINDOW


def block_size(n_balls: int, n_targets: int, tries: int) -> int:
    """How many uniform numbers one attempt at an episode consumes."""
    return 3 * n_balls + 3 * n_targets + 2 * n_balls * tries


@njit(inline="always")
def _draw_velocities(U, ctrl_mask, E, dim, vel):  # pragma: no cover - numba
    """Speeds uniform in the ball's range, directions uniform (a random sign in 1D)."""
    N = vel.shape[1]
    for r in range(U.shape[0]):
        for i in range(N):
            if ctrl_mask[i]:
                lo, hi = E[EPISODE_FLOATS.speed_low], E[EPISODE_FLOATS.speed_high]
            else:
                lo, hi = E[EPISODE_FLOATS.others_low], E[EPISODE_FLOATS.others_high]
            speed = lo + (hi - lo) * U[r, N + i]
            u = U[r, 2 * N + i]
            if dim == 1:
                vel[r, i, 0] = speed if u < 0.5 else -speed
                vel[r, i, 1] = 0.0
            else:
                vel[r, i, 0] = speed * math.cos(2.0 * math.pi * u)
                vel[r, i, 1] = speed * math.sin(2.0 * math.pi * u)


@njit(inline="always")
def _place_on_line(U, off, radii, E, pos, ok):  # pragma: no cover - numba
    """Balls left to right by index, the free length split at sorted uniform points (always fits)."""
    N = pos.shape[1]
    xmin = E[EPISODE_FLOATS.xmin]
    xmax = E[EPISODE_FLOATS.xmax]
    for r in range(U.shape[0]):
        free = (xmax - xmin) - _GAP * (N + 1)
        for i in range(N):
            free -= 2.0 * radii[r, i]
        us = np.sort(U[r, off : off + N] * free)
        edge = xmin
        for i in range(N):
            edge += _GAP
            pos[r, i, 0] = edge + us[i] + radii[r, i]
            pos[r, i, 1] = 0.0
            edge += 2.0 * radii[r, i]
        ok[r] = True


@njit(inline="always")
def _place_in_box(U, off, tries, ctrl_mask, rack, radii, E, pos, ok):  # pragma: no cover - numba
    """Each ball at the first of its tries that overlaps no ball placed before it; ``ok[r]`` False
    when some ball of row r found no such place."""
    xmin = E[EPISODE_FLOATS.xmin]
    ymin = E[EPISODE_FLOATS.ymin]
    xmax = E[EPISODE_FLOATS.xmax]
    ymax = E[EPISODE_FLOATS.ymax]
    for r in range(U.shape[0]):
        ok[r] = True
        for i in range(pos.shape[1]):
            rad = radii[r, i]
            lo_x = xmin + rad + _GAP
            hi_x = xmax - rad - _GAP
            if rack:
                if ctrl_mask[i]:
                    hi_x = min(hi_x, xmin + 0.4 * (xmax - xmin) - rad)
                else:
                    lo_x = max(lo_x, xmin + 0.5 * (xmax - xmin) + rad)
            lo_y = ymin + rad + _GAP
            hi_y = ymax - rad - _GAP
            placed = False
            for t in range(tries):
                px = lo_x + (hi_x - lo_x) * U[r, off + 2 * (i * tries + t)]
                py = lo_y + (hi_y - lo_y) * U[r, off + 2 * (i * tries + t) + 1]
                free_spot = True
                for j in range(i):
                    dx = pos[r, j, 0] - px
                    dy = pos[r, j, 1] - py
                    if math.sqrt(dx * dx + dy * dy) <= radii[r, j] + rad + _GAP:
                        free_spot = False
                        break
                if free_spot:
                    pos[r, i, 0] = px
                    pos[r, i, 1] = py
                    placed = True
                    break
            if not placed:
                ok[r] = False
                break


@njit(inline="always")
def _draw_targets(U, off, walls, dim, E, t_wall, t_geo):  # pragma: no cover - numba
    """Target walls uniform among ``walls``, centres uniform along the wall (the whole end wall in 1D)."""
    K = t_wall.shape[1]
    nw = walls.shape[0]
    xmin = E[EPISODE_FLOATS.xmin]
    ymin = E[EPISODE_FLOATS.ymin]
    xmax = E[EPISODE_FLOATS.xmax]
    ymax = E[EPISODE_FLOATS.ymax]
    hw = E[EPISODE_FLOATS.half_width]
    for r in range(U.shape[0]):
        for k in range(K):
            w = walls[min(int(U[r, off + k] * nw), nw - 1)]
            t_wall[r, k] = w
            if dim == 1:
                t_geo[r, k, TG.centre] = 0.5 * (ymin + ymax)
                t_geo[r, k, TG.half_width] = 0.5 * (ymax - ymin)
            else:
                lo_s = (ymin if _on_side_wall(w) else xmin) + hw
                hi_s = (ymax if _on_side_wall(w) else xmax) - hw
                t_geo[r, k, TG.centre] = lo_s + (hi_s - lo_s) * U[r, off + K + k]
                t_geo[r, k, TG.half_width] = hw


@njit(inline="always")
def _draw_windows(U, off, E, t_geo):  # pragma: no cover - numba
    """Time windows opening at sorted uniform times, so that the targets come due in index order."""
    K = t_geo.shape[1]
    win = E[EPISODE_FLOATS.window]
    latest = E[EPISODE_FLOATS.time_limit] - win
    earliest = min(1.0, latest)
    for r in range(U.shape[0]):
        if win < 0.0:
            for k in range(K):
                t_geo[r, k, TG.opens] = -_NO_WINDOW
                t_geo[r, k, TG.closes] = _NO_WINDOW
            continue
        opens = np.sort(U[r, off : off + K])
        for k in range(K):
            t_geo[r, k, TG.opens] = earliest + (latest - earliest) * opens[k]
            t_geo[r, k, TG.closes] = t_geo[r, k, TG.opens] + win


@njit
def build_episodes(U, ctrl_mask, walls, E, F, pos, vel, masses, radii, t_wall, t_geo, ok):  # pragma: no cover
    """Turn one block of uniforms per row of ``U`` into an episode's start state.

    ``E`` and ``F`` are laid out as ``EPISODE_FLOATS`` and ``EPISODE_INTS``. ``masses`` and ``radii``
    are inputs (the caller maps ``U[:, :N]`` to masses and applies the radius rule); everything else
    is written.
    Layout of a block (N balls, K targets, T placement tries per ball): N masses, N speeds,
    N directions (angle, or the sign in 1D), K target walls, K target centres, K window openings,
    then 2 N T placement coordinates (ball i's try t uses entries 2 (i T + t) and +1; a 1D line
    uses the first N). ``ok[r]`` is False when some ball found no free place in its T tries; the
    caller then draws a fresh block for that row.
    """
    dim = F[EPISODE_INTS.dimension]
    N = F[EPISODE_INTS.n_balls]
    K = F[EPISODE_INTS.n_targets]
    off_targets = 3 * N
    off_places = 3 * N + 3 * K
    _draw_velocities(U, ctrl_mask, E, dim, vel)
    if dim == 1:
        _place_on_line(U, off_places, radii, E, pos, ok)
    else:
        _place_in_box(U, off_places, F[EPISODE_INTS.tries], ctrl_mask, F[EPISODE_INTS.rack] != 0, radii, E, pos, ok)
    _draw_targets(U, off_targets, walls, dim, E, t_wall, t_geo)
    _draw_windows(U, off_targets + 2 * K, E, t_geo)
