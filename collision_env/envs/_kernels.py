"""Batched task kernels: action -> nudge, and impacts -> target hits, reward, observation.

Both work on a batch of B scenes and are the only per-step task logic: the single env is a batch
of one, so the single env and the native vector env run the same arithmetic and agree bit for bit.
They are plain loops, compiled with numba when it is installed (like the engine's kernels) and run
as ordinary Python otherwise.

Wall codes follow ``collision_env.engine.WALL_NAMES``: 0 left, 1 right, 2 bottom, 3 top.
Target status: 0 pending, 1 hit, 2 failed (its time window closed unhit).
Row flags: 1 = a stepped scene (score it), 0 = a scene just reset (start its episode and observe it),
2 = leave it alone, 3 = observe it without changing anything.
"""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine._jit import njit
from collision_env.engine.motion import apply_impulses, ball_views

# indices into the float parameter vector P
P_XMIN, P_YMIN, P_XMAX, P_YMAX = 0, 1, 2, 3
P_HIT, P_MISS, P_BONUS, P_SHAPING = 4, 5, 6, 7
P_VSCALE, P_MSCALE, P_TLIMIT = 8, 9, 10
P_MAXDV, P_MAXSPEED, P_ACTCOST = 11, 12, 13
P_LEN = 14
# indices into the int parameter vector Q
Q_SEQ, Q_CLUSTER, Q_DIM, Q_NSTEPS, Q_STICKY = 0, 1, 2, 3, 4
Q_LEN = 5
# The per-scene task state lives in a few packed arrays, because every array handed to a
# compiled kernel costs about 0.1 us to pass (a step passes them all, every control step).
# columns of the per-scene float array S (B, S_LEN)
S_PHI, S_NUDGE, S_REWARD, S_ENERGY = 0, 1, 2, 3
S_LEN = 4
# columns of the per-scene int array C (B, C_LEN); the last two are the task kernel's scratch
C_CUR, C_STEPS, C_NHIT, C_TERM, C_TRUNC, C_SUCCESS, C_HITS, C_MISSES = 0, 1, 2, 3, 4, 5, 6, 7
C_LEN = 8
# last axis of the per-target int array T (B, K, T_LEN)
T_WALL, T_STATUS = 0, 1
T_LEN = 2


@njit
def nudge_kernel(actions, active, balls, body, ctrl, P, Q, dv, S):  # pragma: no cover - numba
    """Scale actions to velocity changes ``dv`` (B, N, 2) and their size ``S[:, S_NUDGE]``, and apply
    them to the engine's balls with the engine's own impulse kernel.

    Returns -1, or the first active row holding a NaN (then nothing is written). Only the controlled
    balls' entries of ``dv`` are written (the others must be zero).
    Each action component is clipped to [-1, 1] and multiplied by ``max_dv``. The nudge never
    raises a ball's speed above max(max_speed, current speed). ``nudge`` is the requested |dv|
    (after clipping), summed over the controlled balls, in m/s; the task kernel charges
    ``action_cost`` times it.
    Rows with ``active`` False get no nudge and no cost.
    """
    B = actions.shape[0]
    for b in range(B):
        if active[b]:  # (an inactive row's action is ignored, NaN or not)
            for c in range(actions.shape[1]):
                if actions[b, c] != actions[b, c]:
                    return b  # NaN: reject the whole call before changing anything
    _, vel, _, _, _, _ = ball_views(balls)
    dim = Q[Q_DIM]
    max_dv = P[P_MAXDV]
    max_speed = P[P_MAXSPEED]
    for b in range(B):
        c_total = 0.0
        if not active[b]:
            for c in range(ctrl.shape[0]):
                dv[b, ctrl[c], 0] = 0.0
                dv[b, ctrl[c], 1] = 0.0
        else:
            for c in range(ctrl.shape[0]):
                i = ctrl[c]
                ax = min(max(actions[b, c * dim], -1.0), 1.0)
                ay = 0.0
                if dim == 2:
                    ay = min(max(actions[b, c * dim + 1], -1.0), 1.0)
                dx = ax * max_dv
                dy = ay * max_dv
                c_total += math.sqrt(dx * dx + dy * dy)
                vx = vel[b, i, 0]
                vy = vel[b, i, 1]
                nx = vx + dx
                ny = vy + dy
                s_new = math.sqrt(nx * nx + ny * ny)
                cap = max(max_speed, math.sqrt(vx * vx + vy * vy))
                if s_new > cap:
                    f = cap / s_new
                    nx *= f
                    ny *= f
                dv[b, i, 0] = nx - vx
                dv[b, i, 1] = ny - vy
        S[b, S_NUDGE] = c_total
    apply_impulses(balls, body, dv, Q[Q_STICKY] != 0)
    return -1


@njit
def _segment(P, wall, centre, hw):  # pragma: no cover - numba
    """End points (x0, y0, x1, y1) of a target segment on a wall."""
    if wall == 0:
        return P[P_XMIN], centre - hw, P[P_XMIN], centre + hw
    if wall == 1:
        return P[P_XMAX], centre - hw, P[P_XMAX], centre + hw
    if wall == 2:
        return centre - hw, P[P_YMIN], centre + hw, P[P_YMIN]
    return centre - hw, P[P_YMAX], centre + hw, P[P_YMAX]


@njit
def _clip1(v):  # pragma: no cover - numba
    return min(max(v, -1.0), 1.0)


@njit
def _in_cluster(body, b, i):  # pragma: no cover - numba
    root = body[b, i]
    for k in range(body.shape[1]):
        if k != i and body[b, k] == root:
            return True
    return False


@njit
def task_kernel(flags, imp, balls, sim_time, clusters, S, C, T, t_geo, body, qual, P, Q,
                obs):  # pragma: no cover - numba
    """Score a step's impacts, update target state, and write reward, flags and observation.

    ``imp`` is the engine's impact record array for the batch (sorted by scene then time);
    ``balls`` (the per-ball state, ``engine.motion.BALL_FIELDS``), ``sim_time`` and ``clusters``
    are the engine's state after the step.
    In cluster mode ``body`` mirrors the engine's cluster roots through the step, replayed from
    the impacts (a ball-ball impact merges two clusters, a wall impact stops the cluster and
    takes it apart, as the engine does), so a wall impact scores only if its ball was part of a
    cluster at that instant; at the end ``body`` is set to the engine's ``clusters``.
    Updated in place: target status, current target, step count, body, phi. Written for rows
    whose flag is 0 or 1: the observation, reward, energy, targets hit and the end flags.
    """
    pos, vel, masses, _, radii, _ = ball_views(balls)  # (always a C array: one compiled version for any B, N)
    t_wall = T[:, :, T_WALL]
    t_status = T[:, :, T_STATUS]
    cur = C[:, C_CUR]
    steps = C[:, C_STEPS]
    n_hit = C[:, C_NHIT]
    terminated = C[:, C_TERM]
    truncated = C[:, C_TRUNC]
    success = C[:, C_SUCCESS]
    nudge = S[:, S_NUDGE]
    hits = C[:, C_HITS]
    misses = C[:, C_MISSES]
    phi = S[:, S_PHI]
    reward = S[:, S_REWARD]
    energy = S[:, S_ENERGY]
    B = flags.shape[0]
    N = pos.shape[1]
    K = t_wall.shape[1]
    seq = Q[Q_SEQ] != 0
    cluster = Q[Q_CLUSTER] != 0
    n_steps = Q[Q_NSTEPS]
    xmin = P[P_XMIN]
    ymin = P[P_YMIN]
    xmax = P[P_XMAX]
    ymax = P[P_YMAX]
    xc = 0.5 * (xmin + xmax)
    yc = 0.5 * (ymin + ymax)
    xh = 0.5 * (xmax - xmin)
    yh = 0.5 * (ymax - ymin)
    diag = math.sqrt((xmax - xmin) ** 2 + (ymax - ymin) ** 2)
    vscale = P[P_VSCALE]
    mscale = P[P_MSCALE]
    tlimit = P[P_TLIMIT]
    shaping = P[P_SHAPING] != 0.0  # the aiming potential is only computed when it is used

    for b in range(B):
        hits[b] = 0
        misses[b] = 0
    for j in range(imp.shape[0]):
        b = imp[j]["scene"]
        if flags[b] != 1:
            continue
        i = imp[j]["ball"]
        w = imp[j]["wall"]
        if w < 0:
            if cluster:
                o = imp[j]["other"]
                if o >= 0:
                    ri = body[b, i]
                    ro = body[b, o]
                    root = min(ri, ro)
                    gone = max(ri, ro)
                    for q in range(N):
                        if body[b, q] == gone:
                            body[b, q] = root
            continue
        scores = qual[i]
        if cluster:
            scores = scores and _in_cluster(body, b, i)
            root = body[b, i]
            for q in range(N):  # the cluster stops at the wall and comes apart
                if body[b, q] == root:
                    body[b, q] = q
        if not scores:
            continue
        s = imp[j]["y"] if w < 2 else imp[j]["x"]
        t = imp[j]["time"]
        k0 = 0
        k1 = K
        if seq:
            k0 = cur[b]
            k1 = min(cur[b] + 1, K)
        hit = False
        for k in range(k0, k1):
            if (t_status[b, k] == 0 and t_wall[b, k] == w and abs(s - t_geo[b, k, 0]) <= t_geo[b, k, 1]
                    and t_geo[b, k, 2] <= t and t <= t_geo[b, k, 3]):
                t_status[b, k] = 1
                hit = True
                hits[b] += 1
                if seq:
                    cur[b] += 1
                break
        if not hit:
            misses[b] += 1

    slots = 1 if seq else K
    for b in range(B):
        f = flags[b]
        if f == 2:
            continue
        now = sim_time[b]
        if f == 1:
            steps[b] += 1
            for k in range(K):  # windows that closed unhit fail
                if t_status[b, k] == 0 and t_geo[b, k, 3] < now:
                    t_status[b, k] = 2
        elif f == 0:
            steps[b] = 0
        if cluster:
            for q in range(N):
                body[b, q] = clusters[b, q]
        nh = 0
        failed = False
        for k in range(K):
            if t_status[b, k] == 1:
                nh += 1
            elif t_status[b, k] == 2:
                failed = True
        done_ok = nh == K
        n_hit[b] = nh

        # ---- observation
        o = 0
        ke = 0.0
        for i in range(N):
            vx = vel[b, i, 0]
            vy = vel[b, i, 1]
            ke += 0.5 * masses[b, i] * (vx * vx + vy * vy)
            obs[b, o] = _clip1((pos[b, i, 0] - xc) / xh)
            obs[b, o + 1] = _clip1((pos[b, i, 1] - yc) / yh)
            obs[b, o + 2] = _clip1(vx / vscale)
            obs[b, o + 3] = _clip1(vy / vscale)
            obs[b, o + 4] = _clip1(masses[b, i] / mscale)
            scoring = qual[i] and (not cluster or _in_cluster(body, b, i))
            obs[b, o + 5] = 1.0 if scoring else 0.0
            o += 6
        energy[b] = ke
        for sl in range(slots):
            k = sl
            if seq:
                k = min(cur[b], K - 1)
            w = t_wall[b, k]
            c = t_geo[b, k, 0]
            hw = t_geo[b, k, 1]
            if w == 0:
                px, py, half = -1.0, (c - yc) / yh, yh
            elif w == 1:
                px, py, half = 1.0, (c - yc) / yh, yh
            elif w == 2:
                px, py, half = (c - xc) / xh, -1.0, xh
            else:
                px, py, half = (c - xc) / xh, 1.0, xh
            obs[b, o] = _clip1(px)
            obs[b, o + 1] = _clip1(py)
            obs[b, o + 2] = _clip1(hw / half)
            for q in range(4):
                obs[b, o + 3 + q] = 1.0 if q == w else 0.0
            st = t_status[b, k]
            obs[b, o + 7] = 1.0 if st == 0 else (0.0 if st == 1 else -1.0)
            obs[b, o + 8] = _clip1((t_geo[b, k, 2] - now) / tlimit)
            obs[b, o + 9] = _clip1((t_geo[b, k, 3] - now) / tlimit)
            o += 10
        obs[b, o] = min(max(1.0 - steps[b] / n_steps, 0.0), 1.0)
        obs[b, o + 1] = (K - nh) / K

        # ---- aiming potential: distance from each scoring ball's straight-line wall contact point
        # to the nearest visible pending target, over the play-area diagonal (a shaping heuristic
        # that ignores other balls; 1 when nothing is aimed)
        best = 1.0
        for i in range(N if shaping else 0):
            if not (qual[i] and (not cluster or _in_cluster(body, b, i))):
                continue
            vx = vel[b, i, 0]
            vy = vel[b, i, 1]
            if vx == 0.0 and vy == 0.0:
                continue
            r = radii[b, i]
            x = pos[b, i, 0]
            y = pos[b, i, 1]
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
                cx = xmax if vx > 0.0 else xmin
                cy = y + vy * max(tx, 0.0)
            else:
                cx = x + vx * max(ty, 0.0)
                cy = ymax if vy > 0.0 else ymin
            k0 = 0
            k1 = K
            if seq:
                k0 = cur[b]
                k1 = min(cur[b] + 1, K)
            for k in range(k0, k1):
                if t_status[b, k] != 0:
                    continue
                x0, y0, x1, y1 = _segment(P, t_wall[b, k], t_geo[b, k, 0], t_geo[b, k, 1])
                sx = x1 - x0
                sy = y1 - y0
                u = ((cx - x0) * sx + (cy - y0) * sy) / (sx * sx + sy * sy)
                u = min(max(u, 0.0), 1.0)
                dx = cx - (x0 + u * sx)
                dy = cy - (y0 + u * sy)
                d = math.sqrt(dx * dx + dy * dy) / diag
                if d < best:
                    best = d
        phi_new = -best

        if f == 1:
            rew = hits[b] * P[P_HIT] - misses[b] * P[P_MISS] - P[P_ACTCOST] * nudge[b]
            if done_ok:
                rew += P[P_BONUS]
            if hits[b] == 0:
                rew += P[P_SHAPING] * (phi_new - phi[b])
            reward[b] = rew
            terminated[b] = done_ok or failed
            truncated[b] = steps[b] >= n_steps
            success[b] = done_ok
        else:
            reward[b] = 0.0
            terminated[b] = False
            truncated[b] = False
            success[b] = False
        if f != 3:
            phi[b] = phi_new


# --------------------------------------------------------------------------------------------- #
# episode construction from blocks of uniform random numbers

#: indices into the float parameter vector of ``build_episodes``
E_XMIN, E_YMIN, E_XMAX, E_YMAX = 0, 1, 2, 3
E_MLO, E_MHI, E_RADIUS = 4, 5, 6  # (masses and radii are computed by the caller from U[:, :N])
E_SLO, E_SHI, E_OLO, E_OHI = 7, 8, 9, 10
E_HW, E_WINDOW, E_TLIMIT = 11, 12, 13  # E_WINDOW < 0: no windows
E_LEN = 14
#: indices into the int parameter vector
F_DIM, F_N, F_K, F_RACK, F_TRIES = 0, 1, 2, 3, 4
F_LEN = 5
_GAP = 1e-3


def block_size(n_balls: int, n_targets: int, tries: int) -> int:
    """How many uniform numbers one attempt at an episode consumes."""
    return 3 * n_balls + 3 * n_targets + 2 * n_balls * tries


@njit
def build_episodes(U, ctrl_mask, walls, E, F, pos, vel, masses, radii, t_wall, t_geo, ok):  # pragma: no cover
    """Turn one block of uniforms per row of ``U`` into an episode's start state.

    ``masses`` and ``radii`` are inputs (the caller maps ``U[:, :N]`` to masses and applies the
    radius rule); everything else is written.
    Layout of a block (N balls, K targets, T placement tries per ball): N masses, N speeds,
    N directions (angle, or the sign in 1D), K target walls, K target centres, K window openings,
    then 2 N T placement coordinates (ball i's try t uses entries 2 (i T + t) and +1; a 1D line
    uses the first N). ``ok[r]`` is False when some ball found no free place in its T tries; the
    caller then draws a fresh block for that row.
    """
    R = U.shape[0]
    dim = F[F_DIM]
    N = F[F_N]
    K = F[F_K]
    rack = F[F_RACK] != 0
    T = F[F_TRIES]
    xmin = E[E_XMIN]
    ymin = E[E_YMIN]
    xmax = E[E_XMAX]
    ymax = E[E_YMAX]
    nw = walls.shape[0]
    off_p = 3 * N + 3 * K
    for r in range(R):
        ok[r] = True
        for i in range(N):
            if ctrl_mask[i]:
                speed = E[E_SLO] + (E[E_SHI] - E[E_SLO]) * U[r, N + i]
            else:
                speed = E[E_OLO] + (E[E_OHI] - E[E_OLO]) * U[r, N + i]
            u = U[r, 2 * N + i]
            if dim == 1:
                vel[r, i, 0] = speed if u < 0.5 else -speed
                vel[r, i, 1] = 0.0
            else:
                vel[r, i, 0] = speed * math.cos(2.0 * math.pi * u)
                vel[r, i, 1] = speed * math.sin(2.0 * math.pi * u)
        # placement
        if dim == 1:
            free = (xmax - xmin) - _GAP * (N + 1)
            for i in range(N):
                free -= 2.0 * radii[r, i]
            us = np.sort(U[r, off_p:off_p + N] * free)
            edge = xmin
            for i in range(N):
                edge += _GAP
                pos[r, i, 0] = edge + us[i] + radii[r, i]
                pos[r, i, 1] = 0.0
                edge += 2.0 * radii[r, i]
        else:
            for i in range(N):
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
                for t in range(T):
                    px = lo_x + (hi_x - lo_x) * U[r, off_p + 2 * (i * T + t)]
                    py = lo_y + (hi_y - lo_y) * U[r, off_p + 2 * (i * T + t) + 1]
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
        # targets
        for k in range(K):
            w = walls[min(int(U[r, 3 * N + k] * nw), nw - 1)]
            t_wall[r, k] = w
            if dim == 1:
                t_geo[r, k, 0] = 0.5 * (ymin + ymax)
                t_geo[r, k, 1] = 0.5 * (ymax - ymin)
            else:
                hw = E[E_HW]
                lo_s = (ymin if w < 2 else xmin) + hw
                hi_s = (ymax if w < 2 else xmax) - hw
                t_geo[r, k, 0] = lo_s + (hi_s - lo_s) * U[r, 3 * N + K + k]
                t_geo[r, k, 1] = hw
        if E[E_WINDOW] < 0.0:
            for k in range(K):
                t_geo[r, k, 2] = -1e300
                t_geo[r, k, 3] = 1e300
        else:
            win = E[E_WINDOW]
            latest = E[E_TLIMIT] - win
            earliest = min(1.0, latest)
            opens = np.sort(U[r, 3 * N + 2 * K:3 * N + 3 * K])
            for k in range(K):
                t_geo[r, k, 2] = earliest + (latest - earliest) * opens[k]
                t_geo[r, k, 3] = t_geo[r, k, 2] + win
