"""Structure and motion: the radial distribution function and the mean squared displacement.

- :func:`radial_distribution`: g(r) in a box or a periodic cell (minimum images), through a cell
  list: memory O(N) and time O(N + the pairs within reach), for any distribution of points;
- :func:`unwrapped_positions`, :func:`mean_squared_displacement`: the MSD of a run's frames, the
  periodic cell's wrapping undone with the image counts.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.scene import Scene

from . import _checks

__all__ = ["PAIR_CHUNK", "mean_squared_displacement", "radial_distribution", "unwrapped_positions"]

#: Candidate pairs :func:`radial_distribution` measures at once: its memory beyond the points' own
#: is a few arrays of this length (or of one point's candidates, if more).
PAIR_CHUNK = 1 << 20


def _cells(length: float, r_max: float, periodic: bool) -> tuple[int, float]:
    """Cells along an axis of ``length`` at least ``r_max`` wide: how many, and their width. A
    periodic axis of fewer than three is one cell (the 3-cell stencil would visit a cell twice)."""
    count = max(1, int(min(length // r_max, 2**20)))
    if periodic and count < 3:
        count = 1
    return count, length / count


def _half_stencil(nx: int, ny: int) -> list[tuple[int, int]]:
    """The cell offsets that visit each pair of neighbouring cells once: the cell itself and four of
    its eight neighbours (none along an axis of one cell, whose only neighbour is itself)."""
    offsets = [(0, 0)]
    for dx, dy in ((1, -1), (1, 0), (1, 1), (0, 1)):
        if not ((dx and nx == 1) or (dy and ny == 1)):
            offsets.append((dx, dy))
    return offsets


def _count_pairs(sample, origin, size, r_max, bins, periodic, counts):
    """Add the unordered pairs of ``sample`` closer than ``r_max``, binned, to ``counts``: the points
    sorted by cell, each cell's pairs with itself and its half stencil, ``PAIR_CHUNK`` at a time."""
    n = len(sample)
    (nx, hx), (ny, hy) = (_cells(size[a], r_max, periodic) for a in range(2))
    rel = sample - origin
    if periodic:
        rel = np.mod(rel, size)
    cx = np.clip((rel[:, 0] // hx).astype(np.int64), 0, nx - 1)
    cy = np.clip((rel[:, 1] // hy).astype(np.int64), 0, ny - 1)
    order = np.argsort(cx * ny + cy, kind="stable")
    points, gx, gy = sample[order], cx[order], cy[order]
    cell = gx * ny + gy
    count = np.bincount(cell, minlength=nx * ny)
    start = np.cumsum(count) - count
    for dx, dy in _half_stencil(nx, ny):
        if (dx, dy) == (0, 0):  # the points after each one in its own cell
            first = np.arange(1, n + 1)
            many = start[cell] + count[cell] - first
        else:
            ox, oy = gx + dx, gy + dy
            if periodic:
                other = (ox % nx) * ny + oy % ny
                many = count[other]
            else:
                inside = (ox >= 0) & (ox < nx) & (oy >= 0) & (oy < ny)
                other = np.where(inside, ox * ny + oy, 0)
                many = np.where(inside, count[other], 0)
            first = start[other]
        total = np.cumsum(many)
        a = 0
        while a < n:
            done = int(total[a - 1]) if a else 0
            b = max(int(np.searchsorted(total, done + PAIR_CHUNK, side="right")), a + 1)
            reps = many[a:b]
            if int(total[b - 1]) > done:
                i = np.repeat(np.arange(a, b), reps)
                j = first[i] + np.arange(len(i)) - np.repeat(np.cumsum(reps) - reps, reps)
                d = points[j] - points[i]
                if periodic:
                    d -= size * np.round(d / size)
                counts += np.histogram(np.sqrt((d * d).sum(-1)), bins=bins, range=(0.0, r_max))[0]
            a = b


def radial_distribution(
    positions: ArrayLike,
    bounds: tuple[float, float, float, float],
    r_max: float,
    bins: int = 50,
    periodic: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """The radial distribution function g(r) of 2D positions in ``bounds = (xmin, ymin, xmax,
    ymax)``: ``(r, g)``, the centres of ``bins`` shells of equal width up to ``r_max`` and g there.

    ``positions`` is ``(N, 2)`` or ``(S, N, 2)`` (S samples, averaged: every disk at one time per
    sample, as ``Simulator.frames`` records them). Each unordered pair closer than ``r_max`` is
    counted once per sample, ``n_k`` pairs in shell k, and (Allen & Tildesley, *Computer Simulation
    of Liquids*, 2nd ed. 2017, §8.2)

        g(r_k) = 2 n_k A / (S N (N - 1) pi (r_{k+1}^2 - r_k^2))

    (``N (N - 1)``: an ideal gas of N points gives exactly 1). The pairs come from a cell list of
    cells at least ``r_max`` wide, each cell's pairs with its own disks and with four of its
    neighbours' (each pair of cells once), :data:`PAIR_CHUNK` pairs at a time: memory O(N) whatever
    the distribution of the points, time O(N + the pairs in neighbouring cells), O(N) per sample at
    fixed density. ``periodic``: the bounds are a periodic cell (as with ``Scene(periodic=True)``):
    the cell grid wraps and separations are minimum images, which needs ``r_max <= L / 2``. In a
    walled box the normalisation is the bulk one: pairs near a wall have fewer partners, which
    lowers g by O(r P / A) (P the perimeter) at separation r.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    if p.ndim != 3 or p.shape[-1] != 2 or p.shape[1] < 2:
        raise ValueError(f"positions: expected (N, 2) or (S, N, 2) with N >= 2, got shape {np.shape(positions)}")
    if not np.isfinite(p).all():
        raise ValueError("positions: values must be finite")
    box = np.asarray(bounds, dtype=np.float64)
    if box.shape != (4,) or not np.isfinite(box).all():
        raise ValueError(f"bounds: expected four finite numbers (xmin, ymin, xmax, ymax), got {bounds!r}")
    origin, size = box[:2], box[2:] - box[:2]
    r_max = _checks.positive(r_max, "r_max")
    bins = _checks.whole(bins, "bins", 1)
    if not (size > 0).all():
        raise ValueError(f"bounds: expected xmin < xmax and ymin < ymax, got {bounds}")
    if not isinstance(periodic, (bool, np.bool_)):
        raise ValueError(f"periodic: expected True or False, got {periodic!r}")
    if periodic and r_max > size.min() / 2:
        half = size.min() / 2
        raise ValueError(f"r_max: at most half the periodic cell's side ({half}) for minimum images, got {r_max}")
    s, n = p.shape[0], p.shape[1]
    counts = np.zeros(bins, dtype=np.int64)
    for sample in p:
        _count_pairs(sample, origin, size, r_max, bins, bool(periodic), counts)
    edges = np.linspace(0.0, r_max, bins + 1)
    shell = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    g = 2.0 * counts * float(size[0] * size[1]) / (s * n * (n - 1) * shell)
    return 0.5 * (edges[1:] + edges[:-1]), g


def unwrapped_positions(frames: Any, scene: Scene) -> np.ndarray:
    """A run's centres as if the periodic cell did not wrap them: ``positions + images * period``
    (``Scene.period``; a walled box's positions as they are), for frames of a ``Simulator``
    (``(F, N, 2)``) or of a ``BatchSimulator`` (``(F, B, N, 2)``): any object with ``positions``
    and ``images`` (the image counts, as :attr:`Simulator.images <collision_env.engine.Simulator.images>`
    gives them) of one shape."""
    s = _checks.scene(scene)
    positions = np.asarray(frames.positions, dtype=np.float64)
    images = np.asarray(frames.images)
    if images.shape != positions.shape:
        raise ValueError(f"frames: images of shape {images.shape} do not match positions of shape {positions.shape}")
    if images.dtype.kind not in "iu":
        raise ValueError(f"frames: images must be integers, got dtype {images.dtype}")
    return positions + images * np.array(s.period)


def _lags(lags, frames: int) -> np.ndarray:
    """``lags`` as int64, each a whole number from 0 to ``frames - 1``."""
    if lags is None:
        return np.arange(frames)
    raw = np.asarray(lags)
    if (
        raw.ndim != 1
        or raw.dtype.kind not in "iuf"
        or (raw.dtype.kind == "f" and not (np.isfinite(raw).all() and (raw == np.round(raw)).all()))
    ):
        raise ValueError(f"lags: expected whole numbers of frames from 0 to {frames - 1}, got {lags!r}")
    k = raw.astype(np.int64)
    if k.size and (k.min() < 0 or k.max() >= frames):
        raise ValueError(f"lags: expected whole numbers of frames from 0 to {frames - 1}, got {lags!r}")
    return k


def mean_squared_displacement(
    trajectory: Any, lags: ArrayLike | None = None, *, scene: Scene | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The mean squared displacement over a run's equally spaced frames: ``(lags, msd)``, with

        MSD(k) = < |r_i(t + k) - r_i(t)|^2 >   over the disks i and every time origin t

    for each lag ``k`` in frames (default: 0 to F - 1; multiply by the frames' spacing for
    seconds). ``trajectory`` is either a run's :class:`~collision_env.engine.Frames` with the
    ``scene`` (their positions unwrapped by :func:`unwrapped_positions`, so that no jump across a
    periodic cell shows), or an array of unwrapped positions ``(F, ..., N, d)``. Leading axes after
    the first (a batch's scenes) are kept: ``msd`` is ``(K,)`` for a simulator's frames, ``(K, B)``
    for a batch's (Allen & Tildesley 2017, §8.3). Ballistic motion gives ``|v|^2 (k dt)^2``; a
    fluid at long times ``2 d D k dt`` (Einstein).
    """
    if hasattr(trajectory, "positions"):
        if scene is None:
            raise ValueError("scene: frames need their scene, whose period unwraps their positions")
        p = unwrapped_positions(trajectory, scene)
    else:
        if scene is not None:
            raise ValueError("scene: only for frames; an array of positions is taken as unwrapped already")
        p = np.asarray(trajectory, dtype=np.float64)
    if p.ndim < 3:
        raise ValueError(f"positions: expected shape (F, ..., N, d), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError("positions: values must be finite")
    frames = p.shape[0]
    k = _lags(lags, frames)
    msd = np.array([np.mean(np.sum((p[lag:] - p[: frames - lag]) ** 2, axis=-1), axis=(0, -1)) for lag in k.tolist()])
    return k, msd.reshape((len(k), *p.shape[1:-2]))
