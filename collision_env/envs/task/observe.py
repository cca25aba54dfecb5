"""The observation: the shown balls' blocks, the target slots and the globals (laid out by
``layout.BALL_OBS``, ``TARGET_OBS`` and ``GLOBAL_OBS``), normalised to [-1, 1]."""

from __future__ import annotations

from typing import NamedTuple

from collision_env.engine.compiled import ball_views, njit
from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_NAMES

from .layout import (
    BALL_OBS,
    GLOBAL_OBS,
    PARAMS,
    ROW_SKIP,
    SCENE_FLOATS,
    SCENE_INTS,
    SWITCHES,
    TARGET_GEOMETRY,
    TARGET_HIT,
    TARGET_INTS,
    TARGET_OBS,
    TARGET_PENDING,
)
from .nudge import clip1
from .scoring import in_cluster, on_side_wall


@njit(inline="always")
def centre_and_half_size(p):  # pragma: no cover - numba
    """The play area's centre and half size, ``(xc, yc, xh, yh)``, from the parameters ``p``."""
    xmin = p[PARAMS.xmin]
    ymin = p[PARAMS.ymin]
    xmax = p[PARAMS.xmax]
    ymax = p[PARAMS.ymax]
    return 0.5 * (xmin + xmax), 0.5 * (ymin + ymax), 0.5 * (xmax - xmin), 0.5 * (ymax - ymin)


class Scales(NamedTuple):
    """What the observation is normalised by: the play area's centre and half size (m), and the
    velocity (m/s), mass (kg) and time (s) scales."""

    xc: float
    yc: float
    xh: float
    yh: float
    vscale: float
    mscale: float
    tlimit: float


@njit(refcount=False, forceinline=True)
def scales(p):  # pragma: no cover - numba
    """The observation's :class:`Scales`, from the parameters ``p`` (read once per call, not per scene)."""
    xc, yc, xh, yh = centre_and_half_size(p)
    return Scales(xc, yc, xh, yh, p[PARAMS.vscale], p[PARAMS.mscale], p[PARAMS.time_limit])


@njit(inline="always")
def _observed_point(wall, centre, xc, yc, xh, yh):  # pragma: no cover - numba
    """A target's centre point in observation coordinates, and the half length of its wall (selected,
    not branched to: see ``scoring._squared_distance_to_target``)."""
    side = on_side_wall(wall)
    half = yh if side else xh
    along = (centre - (yc if side else xc)) / half
    edge = -1.0 if wall == WALL_LEFT or wall == WALL_BOTTOM else 1.0
    return (edge if side else along), (along if side else edge), half


@njit(refcount=False, forceinline=True)
def _observe_balls(b, o, obs, views, state, params, cluster, sc):  # pragma: no cover - numba
    """Scene ``b``'s ball blocks from entry ``o`` on (``views``: the engine's ``ball_views``, ``sc``:
    the :class:`Scales`); returns the entry after them and the scene's kinetic energy."""
    pos, vel, masses, _, _, _ = views
    xc, yc, xh, yh, vscale, mscale = sc.xc, sc.yc, sc.xh, sc.yh, sc.vscale, sc.mscale
    ke = 0.0
    for i in range(pos.shape[1]):
        vx = vel[b, i, 0]
        vy = vel[b, i, 1]
        ke += 0.5 * masses[b, i] * (vx * vx + vy * vy)
        if not params.shown[i]:
            continue
        obs[b, o + BALL_OBS.x] = clip1((pos[b, i, 0] - xc) / xh)
        obs[b, o + BALL_OBS.y] = clip1((pos[b, i, 1] - yc) / yh)
        obs[b, o + BALL_OBS.vx] = clip1(vx / vscale)
        obs[b, o + BALL_OBS.vy] = clip1(vy / vscale)
        obs[b, o + BALL_OBS.mass] = clip1(masses[b, i] / mscale)
        scoring = params.scoring[i] and (not cluster or in_cluster(state.body, b, i))
        obs[b, o + BALL_OBS.scoring] = 1.0 if scoring else 0.0
        o += len(BALL_OBS)
    return o, ke


@njit(refcount=False, forceinline=True)
def _observe_targets(b, o, obs, now, state, seq, sc):  # pragma: no cover - numba
    """Scene ``b``'s target slots from entry ``o`` on (the current target when sequential, else
    every target); returns the entry after them."""
    targets, geo = state.targets, state.target_geo
    xc, yc, xh, yh, tlimit = sc.xc, sc.yc, sc.xh, sc.yh, sc.tlimit
    n_targets = targets.shape[1]
    for slot in range(1 if seq else n_targets):
        k = min(state.scene_i[b, SCENE_INTS.current], n_targets - 1) if seq else slot
        w = targets[b, k, TARGET_INTS.wall]
        px, py, half = _observed_point(w, geo[b, k, TARGET_GEOMETRY.centre], xc, yc, xh, yh)
        obs[b, o + TARGET_OBS.x] = clip1(px)
        obs[b, o + TARGET_OBS.y] = clip1(py)
        obs[b, o + TARGET_OBS.half_width] = clip1(geo[b, k, TARGET_GEOMETRY.half_width] / half)
        for q in range(len(WALL_NAMES)):
            obs[b, o + TARGET_OBS.wall_left + q] = 1.0 if q == w else 0.0
        st = targets[b, k, TARGET_INTS.status]
        obs[b, o + TARGET_OBS.status] = 1.0 if st == TARGET_PENDING else (0.0 if st == TARGET_HIT else -1.0)
        obs[b, o + TARGET_OBS.opens] = clip1((geo[b, k, TARGET_GEOMETRY.opens] - now) / tlimit)
        obs[b, o + TARGET_OBS.closes] = clip1((geo[b, k, TARGET_GEOMETRY.closes] - now) / tlimit)
        o += len(TARGET_OBS)
    return o


@njit(refcount=False, forceinline=True)
def observe(flags, obs, engine, state, params):  # pragma: no cover - numba
    """Write the observation of every scene not flagged ``ROW_SKIP``, and its kinetic energy
    (``scene_f[:, energy]``)."""
    seq = params.switches[SWITCHES.sequential] != 0
    cluster = params.switches[SWITCHES.cluster] != 0
    n_steps = params.switches[SWITCHES.n_steps]
    n_targets = state.targets.shape[1]
    # (once per call, not per scene: a view of the batch's state, or a parameter read again after each
    # write to the observation, costs as much as a scene's block)
    views = ball_views(engine.balls)
    sc = scales(params.params)
    for b in range(flags.shape[0]):
        if flags[b] == ROW_SKIP:
            continue
        o, ke = _observe_balls(b, 0, obs, views, state, params, cluster, sc)
        state.scene_f[b, SCENE_FLOATS.energy] = ke
        o = _observe_targets(b, o, obs, engine.time[b], state, seq, sc)
        steps = state.scene_i[b, SCENE_INTS.steps]
        obs[b, o + GLOBAL_OBS.steps_left] = min(max(1.0 - steps / n_steps, 0.0), 1.0)
        obs[b, o + GLOBAL_OBS.targets_left] = (n_targets - state.scene_i[b, SCENE_INTS.targets_hit]) / n_targets
