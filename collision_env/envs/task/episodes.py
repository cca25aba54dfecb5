"""Episode start states, drawn from blocks of uniform random numbers.

Each episode consumes one block of uniforms (``rng.random(block_size(...))``) from its scene's
own generator, and :func:`build_episodes` turns a batch of blocks into start states, so that a
sub-env of the vector env and a single env seeded alike draw the same episodes. The builder's
parameters are laid out as ``layout.EPISODE_FLOATS`` and ``layout.EPISODE_INTS``.
"""

from __future__ import annotations

import math

from collision_env.engine.compiled import njit

from .layout import EPISODE_FLOATS, EPISODE_INTS, TARGET_GEOMETRY
from .scoring import on_side_wall

_GAP = 1e-3
_NO_WINDOW = 1e300  # a target without a time window is open from -_NO_WINDOW to _NO_WINDOW
#: The ``"fence"`` layout's centre-to-centre spacing of neighbouring balls of its column, in radii of
#: the largest of them: a gap of 1.2 radii, which a ball as large does not pass through.
FENCE_SPACING = 3.2


def block_size(n_balls: int, n_targets: int, tries: int) -> int:
    """How many uniform numbers one attempt at an episode consumes."""
    return 3 * n_balls + 3 * n_targets + 2 * n_balls * tries


@njit(inline="always")
def _sorted(values):  # pragma: no cover - numba
    """``values`` (a new array) sorted in place, ascending: an insertion sort, for the few numbers of
    one episode (numba's ``np.sort`` costs more to compile than a reset's whole work)."""
    for k in range(1, values.shape[0]):
        v = values[k]
        j = k
        while j > 0 and values[j - 1] > v:
            values[j] = values[j - 1]
            j -= 1
        values[j] = v
    return values


@njit(inline="always")
def _draw_velocities(uniforms, ctrl_mask, episode_f, dim, vel):  # pragma: no cover - numba
    """Speeds uniform in the ball's range, directions uniform (a random sign in 1D)."""
    N = vel.shape[1]
    for r in range(uniforms.shape[0]):
        for i in range(N):
            if ctrl_mask[i]:
                lo, hi = episode_f[EPISODE_FLOATS.speed_low], episode_f[EPISODE_FLOATS.speed_high]
            else:
                lo, hi = episode_f[EPISODE_FLOATS.others_low], episode_f[EPISODE_FLOATS.others_high]
            speed = lo + (hi - lo) * uniforms[r, N + i]
            u = uniforms[r, 2 * N + i]
            if dim == 1:
                vel[r, i, 0] = speed if u < 0.5 else -speed
                vel[r, i, 1] = 0.0
            else:
                vel[r, i, 0] = speed * math.cos(2.0 * math.pi * u)
                vel[r, i, 1] = speed * math.sin(2.0 * math.pi * u)


@njit(inline="always")
def _place_on_line(uniforms, off, radii, episode_f, pos, ok):  # pragma: no cover - numba
    """Balls left to right by index, the free length split at sorted uniform points; ``ok[r]`` False
    when the balls and their gaps do not fit the line."""
    N = pos.shape[1]
    xmin = episode_f[EPISODE_FLOATS.xmin]
    xmax = episode_f[EPISODE_FLOATS.xmax]
    for r in range(uniforms.shape[0]):
        free = (xmax - xmin) - _GAP * (N + 1)
        for i in range(N):
            free -= 2.0 * radii[r, i]
        if free < 0.0:
            ok[r] = False
            continue
        us = _sorted(uniforms[r, off : off + N] * free)
        edge = xmin
        for i in range(N):
            edge += _GAP
            pos[r, i, 0] = edge + us[i] + radii[r, i]
            pos[r, i, 1] = 0.0
            edge += 2.0 * radii[r, i]
        ok[r] = True


@njit(inline="always")
def _place_fence(ctrl_mask, radii, episode_f, pos):  # pragma: no cover - numba
    """The balls not controlled, fixed in a column across the vertical centre line (``TaskConfig.layout``
    ``"fence"``), downward from the top wall, ``FENCE_SPACING`` radii of the largest of them apart,
    the first half a spacing from the wall; the opening is left between the last and the bottom wall."""
    xc = 0.5 * (episode_f[EPISODE_FLOATS.xmin] + episode_f[EPISODE_FLOATS.xmax])
    ymax = episode_f[EPISODE_FLOATS.ymax]
    for r in range(pos.shape[0]):
        r_peg = 0.0
        for i in range(pos.shape[1]):
            if not ctrl_mask[i]:
                r_peg = max(r_peg, radii[r, i])
        spacing = FENCE_SPACING * r_peg
        k = 0
        for i in range(pos.shape[1]):
            if ctrl_mask[i]:
                continue
            pos[r, i, 0] = xc
            pos[r, i, 1] = ymax - (k + 0.5) * spacing
            k += 1


@njit(inline="always")
def _place_in_box(uniforms, off, tries, ctrl_mask, rack, fence, radii, episode_f, pos, ok):  # pragma: no cover
    """Each ball at the first of its tries that overlaps no ball placed before it, each at least
    ``_GAP`` from the others and the walls; ``ok[r]`` False when some ball of row r found no such
    place (or its range of places is empty). With ``fence`` the balls not controlled are the
    fence's, placed first where :func:`_place_fence` says (its own spacing, not ``_GAP``), and the
    controlled ones as with ``rack``, clear of the fence too."""
    xmin = episode_f[EPISODE_FLOATS.xmin]
    ymin = episode_f[EPISODE_FLOATS.ymin]
    xmax = episode_f[EPISODE_FLOATS.xmax]
    ymax = episode_f[EPISODE_FLOATS.ymax]
    if fence:
        _place_fence(ctrl_mask, radii, episode_f, pos)
    for r in range(uniforms.shape[0]):
        ok[r] = True
        for i in range(pos.shape[1]):
            if fence and not ctrl_mask[i]:
                continue  # (placed; the controlled balls' region lies left of the fence)
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
            if lo_x > hi_x or lo_y > hi_y:
                ok[r] = False
                break
            for t in range(tries):
                px = lo_x + (hi_x - lo_x) * uniforms[r, off + 2 * (i * tries + t)]
                py = lo_y + (hi_y - lo_y) * uniforms[r, off + 2 * (i * tries + t) + 1]
                free_spot = True
                for j in range(pos.shape[1]):
                    if not (j < i or (fence and not ctrl_mask[j] and j != i)):
                        continue  # (balls placed before it: those of lower index, and a fence's)
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
def _draw_targets(uniforms, off, walls, dim, episode_f, t_wall, t_geo):  # pragma: no cover - numba
    """Target walls uniform among ``walls``, centres uniform along the wall (the whole end wall in 1D)."""
    K = t_wall.shape[1]
    nw = walls.shape[0]
    xmin = episode_f[EPISODE_FLOATS.xmin]
    ymin = episode_f[EPISODE_FLOATS.ymin]
    xmax = episode_f[EPISODE_FLOATS.xmax]
    ymax = episode_f[EPISODE_FLOATS.ymax]
    hw = episode_f[EPISODE_FLOATS.half_width]
    for r in range(uniforms.shape[0]):
        for k in range(K):
            w = walls[min(int(uniforms[r, off + k] * nw), nw - 1)]
            t_wall[r, k] = w
            if dim == 1:
                t_geo[r, k, TARGET_GEOMETRY.centre] = 0.5 * (ymin + ymax)
                t_geo[r, k, TARGET_GEOMETRY.half_width] = 0.5 * (ymax - ymin)
            else:
                lo_s = (ymin if on_side_wall(w) else xmin) + hw
                hi_s = (ymax if on_side_wall(w) else xmax) - hw
                t_geo[r, k, TARGET_GEOMETRY.centre] = lo_s + (hi_s - lo_s) * uniforms[r, off + K + k]
                t_geo[r, k, TARGET_GEOMETRY.half_width] = hw


@njit(inline="always")
def _draw_windows(uniforms, off, episode_f, t_geo):  # pragma: no cover - numba
    """Time windows opening at sorted uniform times, so that the targets come due in index order."""
    K = t_geo.shape[1]
    win = episode_f[EPISODE_FLOATS.window]
    latest = episode_f[EPISODE_FLOATS.time_limit] - win
    earliest = min(1.0, latest)
    for r in range(uniforms.shape[0]):
        if win < 0.0:
            for k in range(K):
                t_geo[r, k, TARGET_GEOMETRY.opens] = -_NO_WINDOW
                t_geo[r, k, TARGET_GEOMETRY.closes] = _NO_WINDOW
            continue
        opens = _sorted(uniforms[r, off : off + K].copy())
        for k in range(K):
            t_geo[r, k, TARGET_GEOMETRY.opens] = earliest + (latest - earliest) * opens[k]
            t_geo[r, k, TARGET_GEOMETRY.closes] = t_geo[r, k, TARGET_GEOMETRY.opens] + win


@njit(label="the environments' resets")
def build_episodes(
    uniforms, ctrl_mask, walls, episode_f, episode_i, pos, vel, masses, radii, t_wall, t_geo, ok
):  # pragma: no cover
    """Turn one block of uniforms per row of ``uniforms`` into an episode's start state.

    ``episode_f`` and ``episode_i`` are laid out as ``EPISODE_FLOATS`` and ``EPISODE_INTS``. ``masses`` and ``radii``
    are inputs (the caller maps ``uniforms[:, :N]`` to masses and applies the radius rule); everything else
    is written.
    Layout of a block (N balls, K targets, T placement tries per ball): N masses, N speeds,
    N directions (angle, or the sign in 1D), K target walls, K target centres, K window openings,
    then 2 N T placement coordinates (ball i's try t uses entries 2 (i T + t) and +1; a 1D line
    uses the first N). ``ok[r]`` is False when some ball found no free place in its T tries; the
    caller then draws a fresh block for that row.
    """
    dim = episode_i[EPISODE_INTS.dimension]
    N = episode_i[EPISODE_INTS.n_balls]
    K = episode_i[EPISODE_INTS.n_targets]
    off_targets = 3 * N
    off_places = 3 * N + 3 * K
    _draw_velocities(uniforms, ctrl_mask, episode_f, dim, vel)
    if dim == 1:
        _place_on_line(uniforms, off_places, radii, episode_f, pos, ok)
    else:
        _place_in_box(
            uniforms,
            off_places,
            episode_i[EPISODE_INTS.tries],
            ctrl_mask,
            episode_i[EPISODE_INTS.rack] != 0,
            episode_i[EPISODE_INTS.fence] != 0,
            radii,
            episode_f,
            pos,
            ok,
        )
    _draw_targets(uniforms, off_targets, walls, dim, episode_f, t_wall, t_geo)
    _draw_windows(uniforms, off_targets + 2 * K, episode_f, t_geo)
