"""Phase 1 of a control step: the actions become velocity changes of the controlled balls.

Each action component is clipped to [-1, 1] (:func:`requested_change` reads a ball's components as
``TaskConfig.control`` says; a shot is taken in the episode's first step, whose step count is 0).
The nudge never raises a ball's speed above max(max_speed, current speed) (:func:`capped_change`).
The changes are applied with the engine's own impulse kernel, which moves stuck clusters as rigid
bodies.
"""

from __future__ import annotations

import math

from collision_env.engine.compiled import apply_impulses, ball_views, njit

from .arrays import unpack
from .layout import CONTROL_NUDGE, CONTROL_SHOT, CONTROL_VELOCITY, PARAMS, SCENE_FLOATS, SCENE_INTS, SWITCHES


@njit(refcount=False, forceinline=True)
def clip1(v):  # pragma: no cover - numba
    """``v`` clipped to [-1, 1]."""
    return min(max(v, -1.0), 1.0)


@njit(refcount=False, forceinline=True)
def _first_nan_row(actions, active):  # pragma: no cover - numba
    """The first active row holding a NaN, or -1 (an inactive row's action is ignored, NaN or not)."""
    for b in range(actions.shape[0]):
        if active[b]:
            for c in range(actions.shape[1]):
                if actions[b, c] != actions[b, c]:
                    return b
    return -1


@njit(forceinline=True, python=True)  # (the scripted policies call it too)
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


@njit(refcount=False, forceinline=True)
def requested_change(a, o, dim, control, first, vx, vy, max_dv, max_speed):  # pragma: no cover - numba
    """The velocity change one controlled ball's action components ``a[o:]`` ask for: with nudge
    control the components times ``max_dv``; with velocity control the step along the straight
    line from (vx, vy) to the named velocity (components times ``max_speed``, scaled back to
    ``max_speed`` if longer), shortened until no axis exceeds ``max_dv``, or none when the engage
    flag is <= 0; with shot control the whole change to the named velocity in the episode's
    ``first`` step, and none after it.

    A named velocity no longer than ``max_speed`` keeps the whole line within the speed cap of
    :func:`capped_change` (a disc holds the segment between two of its points), so under velocity
    and shot control the change charged is the change made."""
    ax = clip1(a[o])
    ay = clip1(a[o + 1]) if dim == 2 else 0.0
    if control == CONTROL_NUDGE:
        return ax * max_dv, ay * max_dv
    if control == CONTROL_SHOT:
        if not first:
            return 0.0, 0.0
    elif not a[o + dim] > 0.0:
        return 0.0, 0.0
    length = math.sqrt(ax * ax + ay * ay)
    if length > 1.0:
        ax /= length
        ay /= length
    dx = ax * max_speed - vx
    dy = ay * max_speed - vy if dim == 2 else 0.0
    longest = max(abs(dx), abs(dy))
    if control == CONTROL_VELOCITY and longest > max_dv:
        f = max_dv / longest
        dx *= f
        dy *= f
    return dx, dy


@njit(refcount=False, label="the environments' actions")
def nudge_kernel(h, actions, active):  # pragma: no cover - numba
    """Turn ``actions`` (B, A) into velocity changes of the controlled balls (``TaskState.nudge``)
    and their size (``scene_f[:, nudge]``: the requested |dv| summed over the controlled balls, m/s,
    which the task charges ``action_cost`` for), and apply them to the engine's balls. Rows with
    ``active`` False get no nudge and no cost.

    Returns -1, or the first active row holding a NaN (then nothing is written). Only the controlled
    balls' entries of the nudge are written (the others stay zero).
    """
    bad = _first_nan_row(actions, active)
    if bad >= 0:
        return bad  # reject the whole call before changing anything
    engine, state, params = unpack(h)
    balls, dv = engine.balls, state.nudge
    dim = params.switches[SWITCHES.dimension]
    control = params.switches[SWITCHES.control]
    per_ball = dim + 1 if control == CONTROL_VELOCITY else dim
    max_dv = params.params[PARAMS.max_dv]
    max_speed = params.params[PARAMS.max_speed]
    _, vel, _, _, _, _ = ball_views(balls)
    for b in range(actions.shape[0]):
        requested = 0.0
        first = state.scene_i[b, SCENE_INTS.steps] == 0
        for c in range(params.controlled.shape[0]):
            i = params.controlled[c]
            if not active[b]:
                dv[b, i, 0] = 0.0
                dv[b, i, 1] = 0.0
                continue
            dx, dy = requested_change(
                actions[b], c * per_ball, dim, control, first, vel[b, i, 0], vel[b, i, 1], max_dv, max_speed
            )
            requested += math.sqrt(dx * dx + dy * dy)
            cdx, cdy = capped_change(vel[b, i, 0], vel[b, i, 1], dx, dy, max_speed)
            dv[b, i, 0] = cdx
            dv[b, i, 1] = cdy
        state.scene_f[b, SCENE_FLOATS.nudge] = requested
    apply_impulses(balls, engine.clusters, dv, params.switches[SWITCHES.sticky] != 0)
    return -1
