"""Starting states for hard-disk studies: ``N`` disks at a given area fraction, on a triangular lattice
or at random, with Maxwell–Boltzmann velocities at a given temperature.

Units are the field's reduced ones by default: the (largest) diameter ``sigma = 1``, the mass ``m = 1``
and ``kT = 1``, so that times are in ``sigma * sqrt(m / kT)`` (Allen & Tildesley, *Computer
Simulation of Liquids*, 2nd ed., 2017, section 2.4 and appendix B). The area fraction (packing
fraction) is ``phi = sum(pi r_i^2) / A``, ``A`` the area of the box or periodic cell.

>>> gas = disk_gas(100, 0.3, seed=1)
>>> round(gas.packing_fraction, 12), gas.positions.shape, round(float(gas.kinetic_energy()), 12)
(0.3, (100, 2), 100.0)
>>> sim = gas.simulator()  # an exact-mode Simulator of the gas
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .scene import Scene
from .simulator import Simulator
from .validation import is_real

#: The densest packing of equal disks (the triangular lattice): ``pi / (2 sqrt 3)``.
CLOSE_PACKED = math.pi / (2.0 * math.sqrt(3.0))
#: The highest area fraction random placement is asked for: random sequential addition of equal
#: disks jams near 0.547 (Hinrichsen, Feder & Jøssang 1986), and slows down well before it.
RANDOM_MAX = 0.5
#: Random placement gives up after this many tries per disk.
RANDOM_TRIES_PER_DISK = 10_000
#: Where every disk's lattice site is at least this far (relative) from overlapping its neighbours.
LATTICE_SLACK = 1e-9


class Gas(NamedTuple):
    """``N`` disks in a box or periodic cell: what :class:`~collision_env.engine.Simulator` takes."""

    scene: Scene  #: the box (walls) or periodic cell, from (0, 0)
    positions: np.ndarray  #: (N, 2) centres
    velocities: np.ndarray  #: (N, 2) velocities
    masses: np.ndarray  #: (N,) masses
    radii: np.ndarray  #: (N,) radii

    @property
    def area(self) -> float:
        """The box's or cell's area."""
        assert self.scene.bounds is not None  # (a gas is always in a box or cell)
        x0, y0, x1, y1 = self.scene.bounds
        return (x1 - x0) * (y1 - y0)

    @property
    def packing_fraction(self) -> float:
        """``sum(pi r_i^2) / A``."""
        return float(np.pi * np.sum(self.radii**2) / self.area)

    def kinetic_energy(self) -> float:
        """``sum(m v^2) / 2``: ``N kT`` in two dimensions."""
        return float(0.5 * np.sum(self.masses * np.sum(self.velocities**2, axis=1)))

    def simulator(self, **options: Any) -> Simulator:
        """A :class:`~collision_env.engine.Simulator` of the gas (``options``: mode, max_events, ...)."""
        return Simulator(self.scene, self.positions, self.velocities, self.masses, self.radii, **options)


def disk_gas(
    n: int,
    packing_fraction: float,
    *,
    arrangement: str = "lattice",
    periodic: bool = False,
    diameters: tuple[float, ...] = (1.0,),
    mass: float = 1.0,
    temperature: float = 1.0,
    seed: int | np.random.Generator | None = None,
) -> Gas:
    """``n`` disks at area fraction ``packing_fraction`` in a near-square box (walls) or periodic cell.

    Parameters
    ----------
    n:
        Number of disks (at least 2).
    packing_fraction:
        ``sum(pi r^2) / A``, which sets the box's size.
    arrangement:
        ``"lattice"``: a triangular lattice, each row shifted by half a spacing, the sites spread
        evenly over the box (vacant sites, if ``n`` fills no whole lattice, are picked at random), up
        to close packing; or ``"random"``: random sequential addition, each disk placed uniformly
        where it overlaps no other, up to :data:`RANDOM_MAX`.
    periodic:
        The box is a periodic cell (``Scene(periodic=True)``): no walls, and disks meet across its
        edges (the lattice then fits the cell exactly, rows in even number).
    diameters:
        Diameters handed out in turn, disk ``i`` taking ``diameters[i % len(diameters)]``: ``(1.0,)``
        for a monodisperse gas, ``(1.0, 1.4)`` for the 50:50 bidisperse mixture of O'Hern et al.,
        Phys. Rev. E 68, 011306 (2003).
    mass, temperature:
        Every disk's mass, and ``kT``: velocities are drawn from the Maxwell–Boltzmann distribution,
        the centre of mass set at rest, then scaled so that the kinetic energy is exactly ``n kT``
        (two degrees of freedom per disk).
    seed:
        For the random draws (numpy's ``default_rng``).

    Raises ``ValueError`` for an area fraction the arrangement cannot reach.
    """
    rng = np.random.default_rng(seed)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise ValueError(f"n: must be an integer of at least 2, got {n!r}")
    n = int(n)
    sizes = np.asarray(diameters, dtype=np.float64)
    if sizes.ndim != 1 or not len(sizes) or not (np.isfinite(sizes) & (sizes > 0)).all():
        raise ValueError(f"diameters: expected positive finite numbers, got {diameters!r}")
    if arrangement not in ("lattice", "random"):
        raise ValueError(f"arrangement: must be 'lattice' or 'random', got {arrangement!r}")
    if not (is_real(mass) and math.isfinite(mass) and mass > 0):
        raise ValueError(f"mass: must be positive and finite, got {mass!r}")
    if not (is_real(temperature) and math.isfinite(temperature) and temperature > 0):
        raise ValueError(f"temperature: must be positive and finite, got {temperature!r}")
    radii = 0.5 * sizes[np.arange(n) % len(sizes)]
    disk_area = float(np.pi * np.sum(radii**2))
    limit = RANDOM_MAX if arrangement == "random" else CLOSE_PACKED
    if not (is_real(packing_fraction) and 0.0 < packing_fraction <= limit):
        raise ValueError(
            f"packing_fraction: must be in (0, {limit:.4f}] for the {arrangement} arrangement, got {packing_fraction!r}"
        )
    area = disk_area / packing_fraction
    sigma = 2.0 * radii.max()
    if arrangement == "lattice":
        width, height, positions = _lattice(n, area, sigma, periodic, rng)
    else:
        width = height = math.sqrt(area)
        positions = _random(radii, width, height, periodic, rng)
    scene = Scene(bounds=(0.0, 0.0, width, height), periodic=periodic)
    masses = np.full(n, float(mass))
    velocities = rng.normal(0.0, math.sqrt(temperature / mass), (n, 2))
    velocities -= velocities.mean(axis=0)  # equal masses: the centre of mass at rest
    velocities *= math.sqrt(n * temperature / (0.5 * np.sum(masses[:, None] * velocities**2)))
    return Gas(scene, positions, velocities, masses, radii)


def _lattice(n, area, sigma, periodic, rng):
    """``n`` sites of a triangular lattice (odd rows shifted by half a spacing) over a near-square
    box of ``area``. Returns the box's width and height and the positions."""
    row_height = math.sqrt(3.0) / 2.0
    most_rows = 2 * math.isqrt(n) + 2
    if periodic:
        # the lattice tiles the cell (rows in even number, as the shift repeats every two rows): the
        # most nearly square cell, then the fewest vacant sites
        def cell_shape(rows):
            cols = -(-n // rows)
            return abs(math.log(cols / (rows * row_height))), rows * cols - n, rows, cols

        _, _, rows, cols = min(cell_shape(rows) for rows in range(2, most_rows + 1, 2))
        dx = math.sqrt(area / (rows * cols * row_height))
        dy = dx * row_height
        width, height = cols * dx, rows * dy
        x0 = y0 = 0.5 * dy
    else:
        # a square box; the sites spread over the room the walls leave a centre (sigma / 2 from
        # each), in the rows and columns that keep neighbours furthest apart
        width = height = math.sqrt(area)
        room = width - sigma

        def spacing(rows):
            cols = -(-n // rows)
            dx = room / (cols - 0.5) if cols > 1 else 0.0
            dy = room / (rows - 1) if rows > 1 else 0.0
            return _nearest(rows, cols, dx, dy), rows, cols, dx, dy

        _, rows, cols, dx, dy = max(spacing(rows) for rows in range(1, most_rows + 1))
        x0 = y0 = 0.5 * sigma
    nearest = _nearest(rows, cols, dx, dy)
    if nearest < sigma * (1.0 + LATTICE_SLACK):
        raise ValueError(
            f"packing_fraction: {n} disks of diameter up to {sigma:g} do not fit a triangular lattice at this "
            f"area fraction (site spacing {nearest:.6g}); lower it, or compress the gas"
        )
    row, col = np.divmod(np.arange(rows * cols), cols)
    sites = np.stack([x0 + (col + 0.5 * (row % 2)) * dx, y0 + row * dy], axis=1)
    if not periodic:  # (the outermost sites, sigma / 2 from the walls, up to round-off)
        sites = np.clip(sites, 0.5 * sigma, width - 0.5 * sigma)
    keep = np.sort(rng.choice(len(sites), size=n, replace=False)) if len(sites) > n else np.arange(n)
    return width, height, sites[keep]


def _nearest(rows, cols, dx, dy):
    """The distance between nearest sites: along a row, to the next row (shifted by ``dx / 2``), or
    to the row after it (not shifted)."""
    return min(
        dx if cols > 1 else math.inf,
        math.hypot(0.5 * dx, dy) if rows > 1 else math.inf,
        2.0 * dy if rows > 2 else math.inf,
    )


def _random(radii, width, height, periodic, rng):
    """Random sequential addition in a ``width`` x ``height`` box, checked against the disks placed so
    far through a grid of cells one largest diameter wide."""
    n = len(radii)
    sigma = 2.0 * radii.max()
    nx, ny = max(1, int(width // sigma)), max(1, int(height // sigma))
    cw, ch = width / nx, height / ny
    cells: dict[tuple[int, int], list[int]] = {}
    positions = np.empty((n, 2))
    for i in range(n):
        r = radii[i]
        for _ in range(RANDOM_TRIES_PER_DISK):
            if periodic:
                p = rng.uniform((0.0, 0.0), (width, height))
            else:
                p = rng.uniform((r, r), (width - r, height - r))
            cx, cy = min(int(p[0] // cw), nx - 1), min(int(p[1] // ch), ny - 1)
            if not _overlaps(p, r, cx, cy, cells, positions, radii, nx, ny, width, height, periodic):
                break
        else:
            raise ValueError(
                f"packing_fraction: found no room for disk {i} of {n} in {RANDOM_TRIES_PER_DISK} random tries; "
                "use arrangement='lattice', or compress the gas"
            )
        positions[i] = p
        cells.setdefault((cx, cy), []).append(i)
    return positions


def _overlaps(p, r, cx, cy, cells, positions, radii, nx, ny, width, height, periodic):
    """Whether a disk of radius ``r`` at ``p`` (in cell ``cx, cy``) overlaps a disk placed before."""
    for gx in range(cx - 1, cx + 2):
        for gy in range(cy - 1, cy + 2):
            if periodic:
                key = (gx % nx, gy % ny)
            elif 0 <= gx < nx and 0 <= gy < ny:
                key = (gx, gy)
            else:
                continue
            for j in cells.get(key, ()):
                d = positions[j] - p
                if periodic:
                    d -= np.round(d / (width, height)) * (width, height)
                if d @ d < (r + radii[j]) ** 2:
                    return True
    return False
