"""Bank-shot aims (``TaskConfig.bank_images``): the directions from the first controlled ball to its
current target and the target's mirror images in the two walls along the target's wall, each with
whether that straight unfolded path passes every other ball.

A ball that bounces off the walls along its target's wall flies, in the plane unfolded across those
walls (each bounce reflects the plane in the wall it strikes), straight at an image of the target:
the target itself, its reflection in one wall, the reflection of that in the other, and so on. The
ball's centre bounces ``r`` from each wall, so the images are those of the target's centre in the
lines ``r`` inside the walls, and the path passes another ball if it keeps more than the sum of their
radii from each of that ball's images (at rest, as in ``Fence``: a moving ball's images are where it
is now). This is the plane geometry the scripted bank shots plan with
(:class:`~collision_env.envs.scripted.BankShotPolicy`), written into the observation; it ignores
that a ball struck on the way moves.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT, WALL_TOP

from .layout import ROW_SKIP, SCENE_INTS, TARGET_GEOMETRY, TARGET_INTS

if TYPE_CHECKING:
    from collision_env.envs._core import TaskCore

#: Entries per image: the unit direction (x, y) from the ball to the image, and 1 if its path is clear.
IMAGE_FEATURES = 3


def unfolded(s: np.ndarray, lo: np.ndarray, period: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Image ``m`` of the coordinates ``s`` (along the axis the mirrors cross) between mirrors at
    ``lo`` and ``lo + period / 2``: ``s`` itself for ``m = 0``, ``m`` reflections away (towards
    smaller coordinates for ``m < 0``): ``s + m / 2 * period`` for even ``m``, else ``2 lo - s + (m + 1)
    / 2 * period``. Arrays broadcast."""
    even = m % 2 == 0
    return np.where(even, s + (m // 2) * period, 2.0 * lo - s + ((m + 1) // 2) * period)


def observe_images(core: TaskCore, flags: np.ndarray, obs: np.ndarray, start: int) -> None:
    """Write the bank-shot aims of every scene not flagged ``ROW_SKIP`` into ``obs`` from entry
    ``start`` on: for images ``m = -n .. n`` of the current target (``n = bank_images``), the unit
    direction from the first controlled ball's centre to the image, and 1.0 if that unfolded path
    keeps clear of every other ball's images (0.0 if not)."""
    cfg = core.cfg
    rows = np.flatnonzero(flags != ROW_SKIP)
    if not len(rows):
        return
    n = cfg.bank_images
    i = cfg.controlled[0]
    assert cfg.bounds is not None  # (None only as an argument of TaskConfig)
    xmin, ymin, xmax, ymax = cfg.bounds
    live = core.batch.live_arrays()
    pos, radii = live.positions[rows], live.radii[rows]  # (R, N, 2), (R, N)
    k = np.minimum(core.state.scene_i[rows, SCENE_INTS.current], cfg.n_targets - 1)
    wall = core.state.targets[rows, k, TARGET_INTS.wall]
    centre = core.state.target_geo[rows, k, TARGET_GEOMETRY.centre]
    r = radii[:, i]
    side = (wall == WALL_LEFT) | (wall == WALL_RIGHT)
    along = np.where(side, 1, 0)  # the axis along the target's wall (the mirrors cross it)
    across = 1 - along
    lo = np.where(side, ymin, xmin) + r
    period = 2.0 * (np.where(side, ymax, xmax) - r - lo)
    face = np.where((wall == WALL_LEFT) | (wall == WALL_BOTTOM), np.where(side, xmin, ymin) + r, 0.0)
    face = np.where((wall == WALL_RIGHT) | (wall == WALL_TOP), np.where(side, xmax, ymax) - r, face)
    m = np.arange(-n, n + 1)
    ball = pos[:, i]  # (R, 2)
    R = len(rows)
    idx = np.arange(R)
    aim = np.empty((R, len(m), 2))
    aim[idx, :, along] = unfolded(centre[:, None], lo[:, None], period[:, None], m[None, :])
    aim[idx, :, across] = face[:, None]
    dx = aim[:, :, 0] - ball[:, 0, None]  # (R, M)
    dy = aim[:, :, 1] - ball[:, 1, None]
    length2 = dx * dx + dy * dy
    # a ball whose centre sits on an image point has no direction to it: (0, 0), not 0 / 0
    length2 = np.where(length2 > 0.0, length2, np.inf)
    length = np.sqrt(length2)
    unit = np.stack([dx / length, dy / length], axis=2)
    # the other balls' images, out to one more reflection than the aims, relative to the ball
    others = [j for j in range(cfg.n_balls) if j != i]
    g = np.arange(-n - 2, n + 3)
    ghosts = np.empty((R, len(others), len(g), 2))
    placed = pos[:, others]  # (R, O, 2)
    ghosts[idx, :, :, along] = unfolded(placed[idx, :, along][:, :, None], lo[:, None, None], period[:, None, None], g)
    ghosts[idx, :, :, across] = placed[idx, :, across][:, :, None]
    gx = (ghosts[..., 0] - ball[:, 0, None, None]).reshape(R, 1, -1)  # (R, 1, G)
    gy = (ghosts[..., 1] - ball[:, 1, None, None]).reshape(R, 1, -1)
    reach = np.repeat(radii[:, others] + r[:, None], len(g), axis=1)[:, None, :]  # (R, 1, G)
    dx3, dy3 = dx[:, :, None], dy[:, :, None]
    u = np.clip((gx * dx3 + gy * dy3) / length2[:, :, None], 0.0, 1.0)  # (R, M, G): the nearest point
    ex = gx - u * dx3
    ey = gy - u * dy3
    clear = (ex * ex + ey * ey > reach * reach).all(axis=2)
    block = np.concatenate([unit, clear[..., None].astype(np.float64)], axis=2).reshape(R, -1)
    obs[rows, start : start + block.shape[1]] = block
