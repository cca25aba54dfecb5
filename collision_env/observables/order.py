"""Bond-orientational order: the hexatic order parameter and its correlation, through freud.

The local hexatic order of disk ``j`` is (Nelson & Halperin, *Phys. Rev. B* 19, 2457 (1979))

    psi6(j) = (1 / n_j) sum_k exp(6 i theta_jk)

over its ``n_j`` neighbours ``k``, ``theta_jk`` the angle of the bond from ``j`` to ``k`` with the x
axis. It is 1 in modulus for a disk whose neighbours sit at multiples of 60°, and its phase gives
the bonds' orientation. The global order ``Psi6 = (1 / N) sum_j psi6(j)`` is 1 on a perfect
triangular crystal and of order ``1 / sqrt(N)`` in a disordered fluid; the orientational
correlation ``g6(r) = < psi6(j) psi6(k)* >`` over the pairs ``j, k`` at distance ``r`` decays
exponentially in the liquid, algebraically in the hexatic phase and not at all in the solid.

**Neighbours.** By default the Voronoi neighbours, the literature's choice for hard disks (Bernard &
Krauth, *Phys. Rev. Lett.* 107, 155704 (2011)): two disks are neighbours when their Voronoi cells
share an edge. In a walled box the cells are those clipped by the walls (the disks are mirrored in
the four walls, whose cells then bound theirs). Edges shorter than :data:`SHORTEST_EDGE` of the mean
spacing ``sqrt(A / N)`` are round-off at a vertex where four or more cells meet, not a bond, and are
left out. ``neighbors=k`` takes the ``k`` nearest disks instead (minimum images in a periodic cell).

The Voronoi cells, the neighbour queries and the sums are freud's (V. Ramasubramani et al., *Comput.
Phys. Commun.* 254, 107275 (2020)), in single precision: ``pip install "collision_env[analysis]"``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.scene import Scene
from collision_env.extras import require

from . import _checks

__all__ = ["SHORTEST_EDGE", "global_hexatic_order", "hexatic_correlation", "hexatic_order"]

#: Voronoi edges shorter than this fraction of the mean spacing ``sqrt(A / N)`` make no neighbours.
SHORTEST_EDGE = 1e-4


def _freud(who: str) -> Any:
    require("analysis", who, modules=("freud",))
    import freud

    return freud


def _samples(positions: ArrayLike, scene: Scene) -> tuple[np.ndarray, bool]:
    """``(S, N, 2)`` positions (and whether one sample was given), each inside a walled box."""
    p = np.asarray(positions, dtype=np.float64)
    single = p.ndim == 2
    if single:
        p = p[None]
    if p.ndim != 3 or p.shape[-1] != 2 or p.shape[1] < 2:
        raise ValueError(f"positions: expected (N, 2) or (S, N, 2) with N >= 2, got shape {np.shape(positions)}")
    if not np.isfinite(p).all():
        raise ValueError("positions: values must be finite")
    assert scene.bounds is not None
    if not scene.periodic:
        low, high = np.array(scene.bounds[:2]), np.array(scene.bounds[2:])
        outside = np.flatnonzero(((p < low) | (p > high)).any(axis=(0, 2)))
        if len(outside):
            raise ValueError(f"positions: disk {outside[0]} lies outside the box {scene.bounds}")
    return p, single


class _System:
    """freud's box for a scene and the points of one sample in it: a periodic cell as it is; a walled
    box inside a periodic box wide enough that no image of a point is nearer to the box than the
    point itself (``3 (L_x + L_y)`` a side), the points centred on the origin as freud wants them."""

    def __init__(self, freud: Any, scene: Scene) -> None:
        assert scene.bounds is not None
        xmin, ymin, xmax, ymax = scene.bounds
        self.size = np.array([xmax - xmin, ymax - ymin])
        self.centre = np.array([xmin, ymin]) + 0.5 * self.size
        self.periodic = scene.periodic
        side = self.size if scene.periodic else np.full(2, 3.0 * self.size.sum())
        self.box = freud.box.Box(float(side[0]), float(side[1]), is2D=True)

    def points(self, sample: np.ndarray) -> np.ndarray:
        """``(N, 3)`` points for freud (z = 0), wrapped into the periodic cell."""
        p = np.zeros((len(sample), 3))
        p[:, :2] = sample - self.centre
        return self.box.wrap(p) if self.periodic else p

    def mirrored(self, points: np.ndarray) -> np.ndarray:
        """The points and their mirror images in the box's four walls, ``(5 N, 3)``."""
        hx, hy = 0.5 * self.size
        images = [points]
        for axis, half in ((0, hx), (0, -hx), (1, hy), (1, -hy)):
            image = points.copy()
            image[:, axis] = 2.0 * half - points[:, axis]
            images.append(image)
        return np.concatenate(images)


def _neighbours(freud: Any, system: _System, points: np.ndarray, neighbors) -> tuple[np.ndarray, Any]:
    """The points freud sees and the neighbour list of the first ``N`` of them (see the module)."""
    n = len(points)
    if neighbors == "voronoi":
        every = points if system.periodic else system.mirrored(points)
        voronoi = freud.locality.Voronoi()
        voronoi.compute((system.box, every))
        bonds = voronoi.nlist
        spacing = math.sqrt(float(np.prod(system.size)) / n)
        keep = (bonds.query_point_indices < n) & (bonds.point_indices < n) & (bonds.weights > SHORTEST_EDGE * spacing)
        return every, bonds.copy().filter(keep)
    query = freud.locality.AABBQuery(system.box, points)
    bonds = query.query(points, {"num_neighbors": neighbors, "exclude_ii": True}).toNeighborList()
    return points, bonds


def _check_neighbors(neighbors, n: int):
    if neighbors == "voronoi":
        return neighbors
    if (
        isinstance(neighbors, (bool, np.bool_))
        or not isinstance(neighbors, (int, np.integer))
        or not 1 <= neighbors < n
    ):
        raise ValueError(f"neighbors: 'voronoi' or a whole number of nearest disks from 1 to N - 1, got {neighbors!r}")
    return int(neighbors)


def hexatic_order(positions: ArrayLike, scene: Scene, *, neighbors: str | int = "voronoi") -> np.ndarray:
    """The local hexatic order ``psi6(j)`` of every disk (see the module): a complex array of ``N``
    values for ``(N, 2)`` positions, ``(S, N)`` for ``S`` samples ``(S, N, 2)``.

    ``scene``: the walled box or periodic cell the disks are in. ``neighbors``: ``"voronoi"`` (the
    Voronoi neighbours, the default) or a number ``k`` of nearest disks. Needs freud (the
    ``analysis`` extra).

    >>> from collision_env.engine import disk_gas
    >>> crystal = disk_gas(64, 0.7, arrangement="crystal", periodic=True)
    >>> psi = hexatic_order(crystal.positions, crystal.scene)
    >>> psi.shape, bool(np.allclose(np.abs(psi), 1.0, atol=1e-5))
    ((64,), True)
    """
    freud = _freud("observables.hexatic_order")
    s = _checks.bounded_scene(scene)
    p, single = _samples(positions, s)
    k = _check_neighbors(neighbors, p.shape[1])
    system = _System(freud, s)
    out = np.empty(p.shape[:2], dtype=np.complex128)
    hexatic = freud.order.Hexatic(k=6)
    for row, sample in zip(out, p, strict=True):
        points, bonds = _neighbours(freud, system, system.points(sample), k)
        hexatic.compute(system=(system.box, points), neighbors=bonds)
        row[:] = hexatic.particle_order[: len(sample)]
    return out[0] if single else out


def global_hexatic_order(
    positions: ArrayLike, scene: Scene, *, neighbors: str | int = "voronoi"
) -> complex | np.ndarray:
    """The global hexatic order ``Psi6 = (1 / N) sum_j psi6(j)``: a complex number for ``(N, 2)``
    positions, ``(S,)`` for ``S`` samples (:func:`hexatic_order`, whose arguments it takes). Its
    modulus is 1 on a perfect triangular crystal, of order ``1 / sqrt(N)`` in a fluid."""
    psi = hexatic_order(positions, scene, neighbors=neighbors)
    mean = psi.mean(axis=-1)
    return complex(mean) if mean.ndim == 0 else mean


def hexatic_correlation(
    positions: ArrayLike, scene: Scene, r_max: float, bins: int = 50, *, neighbors: str | int = "voronoi"
) -> tuple[np.ndarray, np.ndarray]:
    """The orientational correlation ``g6(r) = < psi6(j) psi6(k)* >`` over the pairs of disks at
    distance ``r``: ``(r, g6)``, the centres of ``bins`` shells of equal width up to ``r_max`` and
    the mean of ``Re psi6(j) psi6(k)*`` over the pairs in each (0 in a shell without pairs), the
    samples of ``(S, N, 2)`` positions pooled. ``psi6`` is :func:`hexatic_order`'s (with its
    ``neighbors``); the pairs are minimum images in a periodic cell, which needs ``r_max < L / 2``.
    Normalised by the pairs in each shell (not by an ideal gas's), so that it tends to ``|Psi6|^2``
    at long range in a crystal. Needs freud (the ``analysis`` extra)."""
    freud = _freud("observables.hexatic_correlation")
    s = _checks.bounded_scene(scene)
    p, _ = _samples(positions, s)
    r_max = _checks.positive(r_max, "r_max")
    bins = _checks.whole(bins, "bins", 1)
    system = _System(freud, s)
    reach = 0.5 * system.size.min() if s.periodic else float(np.hypot(*system.size))
    if not r_max < reach:
        what = "half the periodic cell's side" if s.periodic else "the box's diagonal"
        raise ValueError(f"r_max: must be below {what} ({reach:g}), got {r_max!r}")
    psi = hexatic_order(p, s, neighbors=neighbors)
    correlation = freud.density.CorrelationFunction(bins, r_max)
    for sample, values in zip(p, psi, strict=True):
        correlation.compute(system=(system.box, system.points(sample)), values=values, reset=False)
    return np.asarray(correlation.bin_centers, dtype=np.float64), np.real(correlation.correlation).astype(np.float64)
