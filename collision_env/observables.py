"""Observables of a hard-disk gas, from the engine's impacts and positions.

Each function states its formula and its source. Units are SI, ``kT`` in J (the engine has no
Boltzmann constant: ``kT`` is an energy), ``N`` is the number of disks, ``A`` the box's area.

- :func:`collision_virial`, :func:`reduced_pressure`: the pressure from the collision virial;
- :func:`wall_pressure`: the mechanical pressure on the walls, from the wall impulses;
- :func:`collision_rate`, :func:`mean_free_time`, and the Enskog prediction :func:`enskog_rate`
  (with Henderson's contact value :func:`henderson_g`);
- :func:`radial_distribution`: g(r), O(N) per sample through a cell list, in a box or a periodic
  cell (minimum image);
- :func:`mean_squared_displacement`: the MSD of unwrapped positions over time.

Impacts are :class:`~collision_env.engine.Impacts` or their structured arrays
(:data:`~collision_env.engine.IMPACT_DTYPE`), of one scene, over a run of ``duration`` seconds
(``Simulator.frames(dt, n).impacts`` of a run of ``n * dt`` seconds, say).

>>> import numpy as np
>>> from collision_env.engine import Scene, Simulator
>>> from collision_env.observables import collision_rate, reduced_pressure
>>> sim = Simulator(Scene(bounds=None), [[-1.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 1.0], [0.5, 0.5])
>>> imp = sim.step(2.0)  # one head-on collision: impulse 2 N s at contact distance 1 m
>>> reduced_pressure(imp, sim.radii, 2.0, sim.kinetic_energy()), collision_rate(imp, 2, 2.0)
(1.5, 0.5)
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.impacts import Impacts

__all__ = [
    "collision_rate",
    "collision_virial",
    "enskog_rate",
    "henderson_g",
    "mean_free_time",
    "mean_squared_displacement",
    "radial_distribution",
    "reduced_pressure",
    "wall_pressure",
]


def _records(impacts) -> np.ndarray:
    """The structured array of ``impacts`` (an ``Impacts`` or an ``IMPACT_DTYPE`` array)."""
    array = getattr(impacts, "array", impacts)
    if not (isinstance(array, np.ndarray) and array.dtype.names and "impulse" in array.dtype.names):
        raise TypeError(f"impacts: expected Impacts or an IMPACT_DTYPE array, got {type(impacts).__name__}")
    return array


def _positive(value, name: str) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name}: must be a finite number > 0, got {value!r}")
    return value


def collision_virial(impacts: Impacts | np.ndarray, radii: ArrayLike) -> float:
    """``W = sum over ball-ball impacts of sigma_ij J_ij`` (J m): the collision virial, with
    ``sigma_ij = r_i + r_j`` the contact distance and ``J_ij`` the normal impulse (the record's
    ``impulse``). At contact ``r_ij . Δp_i = sigma_ij J_ij`` (the impulse lies along the line of
    centres), so ``W`` is the collisions' share of the virial ``sum r . F`` integrated over time
    (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed. 2017, §3.7)."""
    rows = _records(impacts)
    r = np.asarray(radii, dtype=np.float64)
    pairs = rows[rows["other"] >= 0]
    return float(np.sum((r[pairs["ball"]] + r[pairs["other"]]) * pairs["impulse"]))


def reduced_pressure(impacts: Impacts | np.ndarray, radii: ArrayLike, duration: float, kinetic_energy: float) -> float:
    """The compressibility factor ``Z = P A / (N kT)`` from the collision virial over a run of
    ``duration`` seconds (Alder & Wainwright, *J. Chem. Phys.* 33, 1439 (1960); Allen & Tildesley
    2017, §3.7):

        Z = 1 + W / (d N kT t) = 1 + W / (2 K t)

    The virial theorem for a d-dimensional system, ``P V = N kT + (1 / (d t)) sum_coll r_ij . Δp_i``,
    averaged over a run of ``t`` seconds, with ``W`` the :func:`collision_virial`. Equipartition,
    ``d N kT = 2 K`` with ``K`` the kinetic energy, makes the second form hold in any dimension;
    it takes ``kT = 2K / (d N)``, the temperature of a walled box (in a periodic cell, whose total
    momentum is conserved, ``N`` is ``N - 1`` there, an O(1/N) difference). For elastic disks ``K``
    is constant; pass its mean otherwise. Ball-ball impacts only: the walls' share is the
    :func:`wall_pressure`.
    """
    t = _positive(duration, "duration")
    k = _positive(kinetic_energy, "kinetic_energy")
    return 1.0 + collision_virial(impacts, radii) / (2.0 * k * t)


def wall_pressure(
    impacts: Impacts | np.ndarray, duration: float, bounds: tuple[float, float, float, float], radius: float
) -> float:
    """The mechanical pressure on the walls of a 2D box, N/m: the wall impacts' impulses per unit
    time and per unit of the length the centres can reach,

        P_w = sum_wall J / (t L'),   L' = 2 (L_x - 2 r) + 2 (L_y - 2 r)

    for disks of radius ``radius`` in ``bounds = (xmin, ymin, xmax, ymax)``. By the virial theorem
    for the centres, which move in the box shrunk by ``r`` (area ``A' = (L_x - 2r)(L_y - 2r)``),
    ``P_w A' = K + W / (2 t)`` on average: ``P_w A' / K`` is the :func:`reduced_pressure` of the
    same run, up to the fluctuation of ``sum r . p`` over ``t`` (Hansen & McDonald, *Theory of
    Simple Liquids*, 4th ed. 2013, §2.4; the walls' own virial is ``-P_w`` times the boundary's
    ``r . n`` integral, ``2 A'``). It differs from the bulk pressure at density ``N / A'`` by the
    layering at the walls, O(perimeter / area)."""
    rows = _records(impacts)
    t = _positive(duration, "duration")
    xmin, ymin, xmax, ymax = (float(b) for b in bounds)
    length = 2.0 * ((xmax - xmin - 2.0 * radius) + (ymax - ymin - 2.0 * radius))
    length = _positive(length, "bounds (the length the centres reach)")
    return float(np.sum(rows["impulse"][rows["wall"] >= 0])) / (t * length)


def collision_rate(impacts: Impacts | np.ndarray, n: int, duration: float) -> float:
    """Collisions per disk per second, ``omega = 2 N_coll / (N t)``: each ball-ball impact
    involves two disks (wall impacts are not counted). Its inverse is :func:`mean_free_time`."""
    rows = _records(impacts)
    t = _positive(duration, "duration")
    return 2.0 * float(np.count_nonzero(rows["other"] >= 0)) / (_positive(n, "n") * t)


def mean_free_time(impacts: Impacts | np.ndarray, n: int, duration: float) -> float:
    """The mean time between a disk's collisions, ``tau = 1 / omega`` (:func:`collision_rate`), s;
    infinite if no disk collided."""
    omega = collision_rate(impacts, n, duration)
    return 1.0 / omega if omega > 0.0 else math.inf


def henderson_g(packing: float) -> float:
    """Henderson's contact value of the hard-disk pair correlation, ``g(sigma+) = (1 - 7 eta / 16)
    / (1 - eta)^2`` at area fraction ``eta``: the contact theorem ``Z = 1 + 2 eta g(sigma+)``
    applied to Henderson's equation of state ``Z = (1 + eta^2 / 8) / (1 - eta)^2`` (D. Henderson,
    *Mol. Phys.* 30, 971 (1975)), within 0.5 % of the simulated Z up to eta = 0.5."""
    return (1.0 - 7.0 * packing / 16.0) / (1.0 - packing) ** 2


def enskog_rate(density: float, diameter: float, packing: float, kT: float, mass: float) -> float:
    """Enskog's collision frequency per disk in 2D, ``omega = 2 sqrt(pi) n sigma g(sigma+)
    sqrt(kT / m)`` (= ``2 n sigma g sqrt(pi kT / m)``): the flux of partners through a
    cross-section ``2 sigma`` at the mean relative speed ``sqrt(pi kT / m)`` of two Maxwellian disks,
    times the contact density ``g(sigma+)`` (:func:`henderson_g`) (Chapman & Cowling, *The
    Mathematical Theory of Non-uniform Gases*, 3rd ed. 1970, §16.8, in two dimensions). Exact at
    equilibrium for uncorrelated velocities; at n → 0 it is the Boltzmann rate."""
    return 2.0 * density * diameter * henderson_g(packing) * math.sqrt(math.pi * kT / mass)


def _cells(length: float, r_max: float, periodic: bool) -> tuple[int, float]:
    """Cells along an axis of ``length`` at least ``r_max`` wide: how many, and their width. A
    periodic axis of fewer than three is one cell (the 3-cell stencil would visit a cell twice)."""
    count = max(1, int(length // r_max))
    if periodic and count < 3:
        count = 1
    return count, length / count


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
    counted once per sample, ``n_k`` pairs in shell k, and (Allen & Tildesley 2017, §8.2)

        g(r_k) = 2 n_k A / (S N (N - 1) pi (r_{k+1}^2 - r_k^2))

    (``N (N - 1)``: an ideal gas of N points gives exactly 1). The pairs come from a cell list of
    cells at least ``r_max`` wide, each cell's pairs with its own and its 8 neighbours' disks: O(N)
    per sample at fixed density (``r_max`` is up to a few diameters; a box narrower than three cells
    along an axis pairs every disk along it). ``periodic``: the bounds are a periodic cell (as with
    ``Scene(periodic=True)``): the cell grid wraps and separations are minimum images, which needs
    ``r_max <= L / 2``. In a walled box the normalisation is the bulk one: pairs near a wall have
    fewer partners, which lowers g by O(r P / A) (P the perimeter) at separation r.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    if p.ndim != 3 or p.shape[-1] != 2 or p.shape[1] < 2:
        raise ValueError(f"positions: expected (N, 2) or (S, N, 2) with N >= 2, got shape {np.shape(positions)}")
    if not np.isfinite(p).all():
        raise ValueError("positions: values must be finite")
    xmin, ymin, xmax, ymax = (float(b) for b in bounds)
    size = np.array([xmax - xmin, ymax - ymin])
    r_max = _positive(r_max, "r_max")
    if not (isinstance(bins, (int, np.integer)) and bins >= 1):
        raise ValueError(f"bins: must be a whole number >= 1, got {bins!r}")
    if not (size > 0).all():
        raise ValueError(f"bounds: expected xmin < xmax and ymin < ymax, got {bounds}")
    if periodic and r_max > size.min() / 2:
        half = size.min() / 2
        raise ValueError(f"r_max: at most half the periodic cell's side ({half}) for minimum images, got {r_max}")
    s, n = p.shape[0], p.shape[1]
    (nx, hx), (ny, hy) = (_cells(size[a], r_max, periodic) for a in range(2))
    counts = np.zeros(bins, dtype=np.int64)
    for sample in p:
        rel = sample - (xmin, ymin)
        if periodic:
            rel = np.mod(rel, size)
        cx = np.clip((rel[:, 0] // hx).astype(np.int64), 0, nx - 1)
        cy = np.clip((rel[:, 1] // hy).astype(np.int64), 0, ny - 1)
        cell = cx * ny + cy
        order = np.argsort(cell, kind="stable")
        # the disks of each cell as a padded table (cells, most per cell), -1 where empty
        per_cell = np.bincount(cell, minlength=nx * ny)
        start = np.concatenate(([0], np.cumsum(per_cell)[:-1]))
        slot = np.arange(n) - start[cell[order]]
        table = np.full((nx * ny, max(int(per_cell.max()), 1)), -1, dtype=np.int64)
        table[cell[order], slot] = order
        gx, gy = np.divmod(np.arange(nx * ny), ny)
        for dx in (-1, 0, 1) if nx > 1 else (0,):
            for dy in (-1, 0, 1) if ny > 1 else (0,):
                ox, oy = gx + dx, gy + dy
                if periodic:
                    ox, oy = ox % nx, oy % ny
                    keep = np.ones(nx * ny, dtype=bool)
                else:
                    keep = (ox >= 0) & (ox < nx) & (oy >= 0) & (oy < ny)
                a = table[keep][:, :, None]  # (cells, k, 1) against (cells, 1, k): ordered pairs
                b = table[(ox * ny + oy)[keep]][:, None, :]
                valid = (a >= 0) & (b >= 0) & (a != b)
                i, j = np.broadcast_arrays(a, b)
                i, j = i[valid], j[valid]
                d = sample[j] - sample[i]
                if periodic:
                    d -= size * np.round(d / size)
                dist = np.sqrt((d * d).sum(-1))
                counts += np.histogram(dist, bins=bins, range=(0.0, r_max))[0]
    edges = np.linspace(0.0, r_max, bins + 1)
    shell = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    area = float(size[0] * size[1])
    pairs = counts / 2  # (ordered pairs were counted: each unordered one twice)
    g = 2.0 * pairs * area / (s * n * (n - 1) * shell)
    return 0.5 * (edges[1:] + edges[:-1]), g


def mean_squared_displacement(positions: ArrayLike, lags: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The mean squared displacement of ``(T, N, d)`` unwrapped positions at equally spaced times:
    ``(lags, msd)``, with

        MSD(k) = < |r_i(t + k) - r_i(t)|^2 >   over the disks i and every time origin t

    for each lag ``k`` in frames (default: 0 to T - 1; multiply by the frames' spacing for
    seconds). Unwrapped: a walled box's positions as they are; in a periodic cell, positions plus
    the cell's side times the image counters, so that no jump across the cell shows (Allen &
    Tildesley 2017, §8.3). Ballistic motion gives ``|v|^2 (k dt)^2``; a fluid at long times
    ``2 d D k dt`` (Einstein)."""
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3:
        raise ValueError(f"positions: expected shape (T, N, d), got {np.shape(positions)}")
    frames = p.shape[0]
    k = np.arange(frames) if lags is None else np.asarray(lags, dtype=np.int64)
    if k.ndim != 1 or (k.size and (k.min() < 0 or k.max() >= frames)):
        raise ValueError(f"lags: expected whole numbers from 0 to {frames - 1}, got {lags!r}")
    msd = np.array([np.mean(np.sum((p[lag:] - p[: frames - lag]) ** 2, axis=-1)) for lag in k.tolist()])
    return k, msd
