"""Starting states for hard-disk studies: ``N`` disks at a given area fraction, on a triangular lattice,
as a perfect triangular crystal, or at random, with Maxwell–Boltzmann velocities at a given temperature,
in a box or periodic cell of a given shape.

Units are the field's reduced ones by default: the (largest) diameter ``sigma = 1``, the mass ``m = 1``
and ``kT = 1``, so that times are in ``sigma * sqrt(m / kT)`` (Allen & Tildesley, *Computer
Simulation of Liquids*, 2nd ed., 2017, section 2.4 and appendix B). The area fraction (packing
fraction) is ``phi = sum(pi r_i^2) / A``, ``A`` the area of the box or periodic cell.

>>> gas = disk_gas(100, 0.3, seed=1)
>>> round(gas.packing_fraction, 12), gas.positions.shape, round(float(gas.kinetic_energy()), 12)
(0.3, (100, 2), 100.0)
>>> sim = gas.simulator()  # an exact-mode Simulator of the gas
>>> crystal = disk_gas(72, 0.7, arrangement="crystal", periodic=True, aspect=(9, 8 * math.sqrt(3) / 2))
>>> [round(side, 6) for side in crystal.scene.period]  # 9 disks a row, 8 rows: Li et al.'s N = 72 cell
[10.244084, 7.885899]
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
#: How closely (relative) a periodic crystal's cell must match the shape asked for.
CRYSTAL_SHAPE_RTOL = 1e-9
#: The arrangements :func:`disk_gas` offers.
ARRANGEMENTS = ("lattice", "crystal", "random")


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
        """``sum(m v^2) / 2``: ``N kT`` in a box, ``(N - 1) kT`` in a periodic cell (whose centre of
        mass is at rest: see :func:`~collision_env.observables.temperature`)."""
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
    aspect: float | tuple[float, float] | None = None,
    diameters: tuple[float, ...] = (1.0,),
    mass: float = 1.0,
    temperature: float = 1.0,
    seed: int | np.random.Generator | None = None,
) -> Gas:
    """``n`` disks at area fraction ``packing_fraction`` in a box (walls) or periodic cell.

    Parameters
    ----------
    n:
        Number of disks (at least 2).
    packing_fraction:
        ``sum(pi r^2) / A``, which sets the box's size.
    arrangement:
        ``"lattice"``: a triangular lattice, each row shifted by half a spacing, the sites spread
        evenly over the box (vacant sites, if ``n`` fills no whole lattice, are picked at random), up
        to close packing; ``"crystal"``: a perfect triangular crystal of ``n = k * 2m`` disks, ``k``
        to a row and ``2m`` rows, in the periodic cell it tiles, ``k a`` by ``2m a sqrt(3) / 2`` for a
        spacing ``a`` (periodic only; the cell's shape follows from ``k`` and ``m``, see ``aspect``);
        or ``"random"``: random sequential addition, each disk placed uniformly where it overlaps no
        other, up to :data:`RANDOM_MAX`.
    periodic:
        The box is a periodic cell (``Scene(periodic=True)``): no walls, and disks meet across its
        edges (the lattice then fits the cell exactly, rows in even number).
    aspect:
        The shape of the box or cell: its height over its width (a number), or its sides in
        proportion, ``(width, height)``: ``(1, sqrt(3) / 2)`` for the ``1 : sqrt(3)/2`` cells of the
        hard-disk literature (e.g. Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, *J. Chem. Phys.*
        157, 234111 (2022)). ``None`` (the default): a square box, or with ``periodic`` and the
        lattice, the most nearly square cell that the lattice tiles; for a crystal, the most nearly
        square of its cells. A crystal's cell must be the one asked for (to ``1e-9``): with ``n = 72``
        at ``(9, 8 sqrt(3) / 2)``, say, 9 disks a row in 8 rows; any other shape raises a
        ``ValueError`` that names the shapes ``n`` disks can tile.
    diameters:
        Diameters handed out in turn, disk ``i`` taking ``diameters[i % len(diameters)]``: ``(1.0,)``
        for a monodisperse gas, ``(1.0, 1.4)`` for the 50:50 bidisperse mixture of O'Hern et al.,
        Phys. Rev. E 68, 011306 (2003).
    mass, temperature:
        Every disk's mass, and ``kT``: velocities are drawn from the Maxwell–Boltzmann distribution,
        the centre of mass set at rest, then scaled so that the gas's
        :func:`~collision_env.observables.temperature` is exactly ``kT``: a kinetic energy of
        ``n kT`` in a box (two degrees of freedom per disk), ``(n - 1) kT`` in a periodic cell
        (whose conserved momentum takes two).
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
    if arrangement not in ARRANGEMENTS:
        raise ValueError(f"arrangement: must be one of {ARRANGEMENTS}, got {arrangement!r}")
    if arrangement == "crystal" and not periodic:
        raise ValueError("arrangement: a perfect crystal needs periodic=True (walls do not fit a triangular lattice)")
    ratio = _ratio(aspect)
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
    if arrangement == "crystal":
        width, height, positions = _crystal(n, area, sigma, ratio)
        _roomy(width, height, sigma, periodic)
    elif arrangement == "lattice" and periodic and ratio is None:
        width, height, positions = _tiled_lattice(n, area, sigma, rng)
        _roomy(width, height, sigma, periodic)
    else:
        width = math.sqrt(area / (1.0 if ratio is None else ratio))
        height = width if ratio is None else ratio * width
        _roomy(width, height, sigma, periodic)
        if arrangement == "lattice":
            positions = _lattice(n, width, height, sigma, periodic, rng)
        else:
            positions = _random(radii, width, height, periodic, rng)
    scene = Scene(bounds=(0.0, 0.0, width, height), periodic=periodic)
    masses = np.full(n, float(mass))
    velocities = rng.normal(0.0, math.sqrt(temperature / mass), (n, 2))
    velocities -= velocities.mean(axis=0)  # equal masses: the centre of mass at rest
    from collision_env.observables.pressure import temperature as measured  # (observables import the engine)

    velocities *= math.sqrt(temperature / measured(velocities, masses, scene))
    return Gas(scene, positions, velocities, masses, radii)


def _roomy(width, height, sigma, periodic):
    """Refuse a box narrower than a disk, or a periodic cell narrower than two (a disk would touch
    two images of another: see ``Scene(periodic=True)``)."""
    least = 2.0 * sigma * (1.0 + LATTICE_SLACK) if periodic else sigma
    if min(width, height) <= least:
        kind = "periodic cell" if periodic else "box"
        raise ValueError(
            f"packing_fraction: at this area fraction the {kind} is {width:.6g} x {height:.6g}, too narrow for disks "
            f"of diameter {sigma:g} (a side must exceed {least:.6g}); lower it, add disks, or make the shape squarer"
        )


def _ratio(aspect) -> float | None:
    """``aspect`` as the height over the width (``None`` stays ``None``)."""
    if aspect is None:
        return None
    values = aspect if isinstance(aspect, (tuple, list, np.ndarray)) else (aspect,)
    if len(values) not in (1, 2) or not all(is_real(v) and math.isfinite(v) and v > 0 for v in values):
        raise ValueError(f"aspect: a height over width, or (width, height), positive and finite, got {aspect!r}")
    return float(values[0]) if len(values) == 1 else float(values[1]) / float(values[0])


def _sites(rows, cols, dx, dy, x0, y0):
    """A triangular lattice's sites, row by row, odd rows shifted by half a spacing."""
    row, col = np.divmod(np.arange(rows * cols), cols)
    return np.stack([x0 + (col + 0.5 * (row % 2)) * dx, y0 + row * dy], axis=1)


def _fits(n, sigma, rows, cols, dx, dy):
    """Refuse a lattice whose nearest sites are closer than a diameter."""
    nearest = _nearest(rows, cols, dx, dy)
    if nearest < sigma * (1.0 + LATTICE_SLACK):
        raise ValueError(
            f"packing_fraction: {n} disks of diameter up to {sigma:g} do not fit a triangular lattice at this "
            f"area fraction (site spacing {nearest:.6g}); lower it, or compress the gas"
        )


def _vacancies(sites, n, rng):
    """``n`` of the ``sites``, the vacant ones picked at random."""
    keep = np.sort(rng.choice(len(sites), size=n, replace=False)) if len(sites) > n else np.arange(n)
    return sites[keep]


def _crystal(n, area, sigma, ratio):
    """A perfect triangular crystal of ``n`` disks in the periodic cell it tiles (see ``disk_gas``).
    Returns the cell's width and height and the positions."""
    row_height = math.sqrt(3.0) / 2.0
    shapes = [(rows * row_height / (n // rows), rows) for rows in range(2, n + 1, 2) if n % rows == 0]
    if not shapes:
        raise ValueError(f"n: a periodic triangular crystal has rows in even number, so n must be even, got {n}")
    target = 1.0 if ratio is None else ratio
    shape, rows = min(shapes, key=lambda s: (abs(math.log(s[0] / target)), s[1]))
    if ratio is not None and abs(shape / ratio - 1.0) > CRYSTAL_SHAPE_RTOL:
        near = sorted(shapes, key=lambda s: abs(math.log(s[0] / ratio)))[:3]
        options = ", ".join(f"{n // r} x {r} rows (height / width {q:.6g})" for q, r in near)
        raise ValueError(
            f"aspect: {n} disks tile no periodic cell of height / width {ratio:.6g}; the nearest are {options}"
        )
    cols = n // rows
    dx = math.sqrt(area / (n * row_height))
    dy = dx * row_height
    _fits(n, sigma, rows, cols, dx, dy)
    return cols * dx, rows * dy, _sites(rows, cols, dx, dy, 0.25 * dx, 0.5 * dy)


def _tiled_lattice(n, area, sigma, rng):
    """``n`` sites of a triangular lattice in the most nearly square periodic cell it tiles (rows in
    even number, as the shift repeats every two rows), then the fewest vacant sites. Returns the
    cell's width and height and the positions."""
    row_height = math.sqrt(3.0) / 2.0

    def cell_shape(rows):
        cols = -(-n // rows)
        return abs(math.log(cols / (rows * row_height))), rows * cols - n, rows, cols

    _, _, rows, cols = min(cell_shape(rows) for rows in range(2, 2 * math.isqrt(n) + 3, 2))
    dx = math.sqrt(area / (rows * cols * row_height))
    dy = dx * row_height
    _fits(n, sigma, rows, cols, dx, dy)
    return cols * dx, rows * dy, _vacancies(_sites(rows, cols, dx, dy, 0.5 * dy, 0.5 * dy), n, rng)


def _lattice(n, width, height, sigma, periodic, rng):
    """``n`` sites of a triangular lattice (odd rows shifted by half a spacing) spread over a
    ``width`` x ``height`` box, in the rows and columns that keep neighbours furthest apart: over the
    room the walls leave a centre (``sigma / 2`` from each), or the whole periodic cell (rows in even
    number). Returns the positions."""
    most_rows = 2 * math.isqrt(n) + 2
    if periodic:
        candidates = range(2, most_rows + 1, 2)

        def spacing(rows):
            cols = -(-n // rows)
            dx, dy = width / cols, height / rows
            return _nearest(rows, cols, dx, dy), rows, cols, dx, dy

        x0, y0 = None, None
    else:
        candidates = range(1, most_rows + 1)
        room_x, room_y = width - sigma, height - sigma

        def spacing(rows):
            cols = -(-n // rows)
            dx = room_x / (cols - 0.5) if cols > 1 else 0.0
            dy = room_y / (rows - 1) if rows > 1 else 0.0
            return _nearest(rows, cols, dx, dy), rows, cols, dx, dy

        x0 = y0 = 0.5 * sigma
    _, rows, cols, dx, dy = max(spacing(rows) for rows in candidates)
    _fits(n, sigma, rows, cols, dx, dy)
    if periodic:
        x0, y0 = 0.25 * dx, 0.5 * dy
    sites = _sites(rows, cols, dx, dy, x0, y0)
    if not periodic:  # (the outermost sites, sigma / 2 from the walls, up to round-off)
        sites = np.clip(sites, 0.5 * sigma, (width - 0.5 * sigma, height - 0.5 * sigma))
    return _vacancies(sites, n, rng)


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
