"""Compression of hard disks to jamming by the Lubachevsky–Stillinger algorithm.

The disks' radii grow in proportion while they move and collide (Lubachevsky & Stillinger, *J.
Stat. Phys.* 60, 561 (1990); Donev, Torquato & Stillinger, *J. Comput. Phys.* 202, 737 (2005)): the
time of impact of growing disks is still a quadratic, and a colliding pair bounces about the growth
speed, so that it separates (:mod:`~collision_env.engine.physics.growth`; the event loop is
:mod:`~collision_env.engine.exact.growth`). Collisions feed energy in; after every ``4 N`` collisions
the velocities are rescaled to the starting temperature. As the packing approaches jamming, the
collision rate and the pressure diverge; the compression stops when the reduced pressure ``Z = P A
/ (N kT)`` passes ``until_pressure``, measured from the collision virial (walls included, see
:func:`compress`) over the last ``4 N`` collisions or more (:data:`WINDOW_PER_DISK`).

>>> from collision_env.engine import compress, disk_gas
>>> gas = disk_gas(64, 0.3, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=2)
>>> packing = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_pressure=100.0, seed=3)
>>> bool(0.7 < packing.packing_fraction < 0.85), packing.reduced_pressure >= 100.0
(True, True)
>>> sim = packing.gas().simulator()  # the packing, at its final radii, in the exact engine
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .broadphase import CELL_MARGIN, EXACT_CELLS_PER_BALL, grid_geometry
from .exact import growth
from .gas import Gas
from .physics.periodic import wrap_positions
from .scene import Scene
from .validation import Labels, checked_balls, is_real, positive_integer

#: The growth rate of the diameters, in mean diameters per unit of the thermal time (see
#: :func:`compress`): slow enough that the disks stay near equilibrium until close to jamming.
DEFAULT_RATE = 1e-3
#: The reduced pressure at which a packing is taken as jammed: the gaps between the disks of its
#: rigid network are then about ``1 / Z`` of a diameter (the free-volume equation of state near
#: jamming, ``Z ~ d / (1 - phi / phi_J)`` in ``d`` dimensions, Salsburg & Wood, *J. Chem. Phys.* 37,
#: 798 (1962), with ``1 - phi / phi_J ~ d gap / sigma``).
DEFAULT_UNTIL_PRESSURE = 1e6
#: Events per disk the compression may spend by default: it stops there with a warning.
DEFAULT_EVENTS_PER_DISK = 100_000
#: Cells of the neighbour grid are made this much wider than the largest diameter, so that the grid
#: is remade (and every disk rescheduled) once per 10 % of growth.
GRID_HEADROOM = 1.1
#: The largest disk stops growing a hair short of half the periodic cell (the minimum image).
HALF_CELL = 0.5 * (1.0 - 1e-9)
#: The velocities are rescaled, and the pressure measured, after every this many collisions per disk.
WINDOW_PER_DISK = 4
#: Without growth, the disks may stop meeting (a dilute few): the run ends after this many events
#: per disk without a collision.
IDLE_PER_DISK = 1000
#: Progress is shown on standard error every this many seconds, from the first such interval on.
PROGRESS_SECONDS = 5.0


class CompressionWarning(RuntimeWarning):
    """A compression stopped before the pressure reached ``until_pressure``."""


class Packing(NamedTuple):
    """The result of :func:`compress`: the disks at their final radii, and how the run ended."""

    scene: Scene  #: the box or periodic cell (as given)
    positions: np.ndarray  #: (N, 2) centres (wrapped into a periodic cell)
    velocities: np.ndarray  #: (N, 2) velocities, at the starting temperature
    masses: np.ndarray  #: (N,)
    radii: np.ndarray  #: (N,) the final radii
    packing_fraction: float  #: ``sum(pi r_i^2) / A``
    reduced_pressure: float  #: ``Z = P A / (N kT)`` over the last ``4 N`` collisions or more
    events: int  #: collisions (of pairs and with walls)
    time: float  #: how long the disks grew (s)
    jammed: bool  #: ``reduced_pressure`` reached ``until_pressure``

    def gas(self) -> Gas:
        """The packing as a :class:`~collision_env.engine.Gas` (``.simulator()`` runs it, without
        growth)."""
        return Gas(self.scene, self.positions, self.velocities, self.masses, self.radii)


def compress(
    scene: Scene,
    positions: ArrayLike,
    radii: ArrayLike,
    *,
    velocities: ArrayLike | None = None,
    masses: ArrayLike | None = None,
    rate: float = DEFAULT_RATE,
    until_pressure: float = DEFAULT_UNTIL_PRESSURE,
    max_events: int | None = None,
    seed: int | np.random.Generator | None = None,
    progress: bool = True,
) -> Packing:
    """Grow the disks in proportion until the reduced pressure passes ``until_pressure``.

    Parameters
    ----------
    scene:
        A 2D box (walls) or periodic cell (``Scene(periodic=True)``) with ball collisions.
    positions, radii:
        ``(N, 2)`` centres and ``(N,)`` starting radii, none overlapping (as ``Simulator`` takes
        them). Their ratios are kept: disk ``i`` grows as ``r_i(t) = r_i (1 + gamma t)``.
    velocities, masses:
        ``(N, 2)`` and ``(N,)``; by default unit masses and velocities drawn from the
        Maxwell–Boltzmann distribution at ``kT = 1`` (the centre of mass at rest). The kinetic
        energy ``K`` they start with (``N kT``, two degrees of freedom per disk) is held.
    rate:
        How fast the diameters grow, in mean diameters ``s`` per thermal time ``s / v``, with ``v =
        sqrt(kT / m)`` for the mean mass: ``gamma = rate v / s``. In the reduced units of
        :func:`~collision_env.engine.disk_gas` (``s = m = kT = 1``) it is the diameters' growth speed.
        Slower compressions jam denser (the rate dependence is measured by ``python -m
        collision_env.bench.physics``); 0 runs the gas without growth.
    until_pressure:
        Stop once ``Z = 1 + W / (2 K t)`` reaches it, over a window of at least ``4 N`` collisions:
        ``W`` sums ``sigma_ij J_ij`` over the collisions and, in a box, ``r_i J_i`` over the wall
        impacts (the virial theorem then gives the walls' pressure on the box area), ``J`` the
        normal impulses (see :func:`~collision_env.observables.reduced_pressure`).
    max_events:
        The budget of collisions (default ``DEFAULT_EVENTS_PER_DISK * N``): the run stops there
        with a :class:`CompressionWarning`.
    seed:
        For the default velocities.
    progress:
        Show the packing fraction, pressure and event rate on standard error every
        :data:`PROGRESS_SECONDS` of a long run.

    Returns a :class:`Packing`. Raises ``ValueError`` (naming the ball and the field) for a state
    ``Simulator`` would refuse, or a scene that is not a 2D box or cell with ball collisions.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene, got {type(scene).__name__}")
    if scene.bounds is None or scene.dimension != 2 or not scene.ball_collisions:
        raise ValueError("scene: compress needs a 2D scene with bounds (a box or a periodic cell) and ball collisions")
    if not (is_real(rate) and math.isfinite(rate) and rate >= 0.0):
        raise ValueError(f"rate: must be a finite number >= 0, got {rate!r}")
    if not (is_real(until_pressure) and until_pressure > 1.0):
        raise ValueError(f"until_pressure: must be a number > 1 (the ideal gas has Z = 1), got {until_pressure!r}")
    try:
        shape = np.shape(positions)
    except ValueError:  # numpy refuses ragged nesting
        shape = None
    if shape is None or len(shape) != 2 or shape[0] < 2:
        raise ValueError(f"positions: expected shape (N, 2) with N >= 2, got {shape or 'a ragged sequence'}")
    n = shape[0]
    budget = DEFAULT_EVENTS_PER_DISK * n if max_events is None else positive_integer(max_events, "max_events")
    if masses is None:
        masses = np.ones(n)
    if velocities is None:
        velocities = _maxwell(masses, seed, n)
    pos, vel, mass, r = checked_balls(
        scene, Labels(1, single=True), np.arange(1), n, [positions], [velocities], masses, radii
    )
    kinetic = 0.5 * float(np.sum(mass[0] * np.sum(vel[0] ** 2, axis=1)))
    if not kinetic > 0.0:
        raise ValueError("velocities: the disks must move (the kinetic energy is 0, so no temperature to hold)")
    return _Compression(scene, pos[0], vel[0], mass[0], r[0], rate, kinetic).run(until_pressure, budget, progress)


def _maxwell(masses: ArrayLike, seed: int | np.random.Generator | None, n: int) -> np.ndarray:
    """Maxwell–Boltzmann velocities at ``kT = 1`` with the centre of mass at rest (for masses of
    shape ``(N,)``, positive and finite; the validation refuses the others, whatever the
    velocities)."""
    rng = np.random.default_rng(seed)
    try:
        masses = np.asarray(masses, dtype=np.float64)
    except (TypeError, ValueError):
        return np.zeros((n, 2))
    if masses.shape != (n,) or not (np.isfinite(masses) & (masses > 0)).all():
        return np.zeros((n, 2))
    vel = rng.normal(size=(n, 2)) / np.sqrt(masses)[:, None]
    vel -= np.sum(masses[:, None] * vel, axis=0) / np.sum(masses)
    return vel


class _Compression:
    """One compression's state: the event loop's arrays, the grid, and the pressure's window."""

    def __init__(self, scene: Scene, pos, vel, mass, r, rate: float, kinetic: float) -> None:
        assert scene.bounds is not None
        self.scene = scene
        self.bounds: tuple[float, float, float, float] = scene.bounds
        self.n = len(r)
        self.kinetic = kinetic  # the kinetic energy held
        x0, y0, x1, y1 = scene.bounds
        self.area = (x1 - x0) * (y1 - y0)
        if scene.periodic:
            pos, _ = wrap_positions(pos, scene.bounds, 2)
        speed = math.sqrt(kinetic / self.n / float(np.mean(mass)))  # sqrt(kT / m), kT = K / N in 2D
        gamma = rate * speed / (2.0 * float(np.mean(r)))
        self.disks = growth.Disks(
            np.ascontiguousarray(pos),
            np.ascontiguousarray(vel),
            np.zeros(self.n),
            r.copy(),
            gamma * r,
            mass.copy(),
            np.zeros(self.n, dtype=np.int64),
        )
        self.events = growth.make_events(self.n)
        self.tally = np.zeros(growth.TALLY_SIZE)
        self.largest = int(np.argmax(r))
        # when the largest disk's diameter reaches half the periodic cell (the minimum image)
        self.t_half = math.inf
        if scene.periodic and gamma > 0.0:
            self.t_half = (0.5 * HALF_CELL * min(x1 - x0, y1 - y0) / r[self.largest] - 1.0) / gamma
        self.box, self.t_grid = self._grid(0.0)
        self.cells = growth.make_cells(self.n, self.box)

    def _grid(self, t: float) -> tuple[growth.Box, float]:
        """The broad phase's grid (``broadphase.grid_geometry``) for the disks at ``GRID_HEADROOM``
        times their radii at ``t``, and the time until which it serves: when the largest disk fills
        a cell (with the margin), or, in a periodic cell, half the cell (the minimum image)."""
        scene = self.scene
        x0, y0, x1, y1 = self.bounds
        radii = (self.disks.r0 + self.disks.r_dot * t) * GRID_HEADROOM
        period = (x1 - x0, y1 - y0) if scene.periodic else None
        geometry, counts = grid_geometry(
            self.bounds,
            self.disks.pos[None],
            radii[None],
            np.ones(1, bool),
            cells_per_ball=EXACT_CELLS_PER_BALL,
            period=period,
        )
        (_, _, hx, hy), (nx, ny) = geometry[0], counts[0]
        box = growth.Box(x0, y0, x1 - x0, y1 - y0, scene.periodic, float(hx), float(hy), int(nx), int(ny))
        diameters = [h / CELL_MARGIN for h, c in ((hx, nx), (hy, ny)) if c > 1]
        r_dot = self.disks.r_dot[self.largest]
        if not diameters or r_dot == 0.0:
            return box, self.t_half
        return box, min(float((0.5 * min(diameters) - self.disks.r0[self.largest]) / r_dot), self.t_half)

    def run(self, until_pressure: float, budget: int, progress: bool) -> Packing:
        """Grow the disks window by window (of ``WINDOW_PER_DISK * N`` collisions, or up to the time
        the grid serves), rescaling the velocities after each, until the pressure over a whole
        window reaches ``until_pressure``, the budget is spent, or the largest disk fills half the
        periodic cell."""
        disks, events, tally = self.disks, self.events, self.tally
        growth.reschedule(disks, events, self.cells, self.box, 0.0)
        started = last_shown = time.perf_counter()
        window = _Window(0.0, tally, self.kinetic)
        pressure = math.nan
        t = 0.0
        while True:
            room = min(WINDOW_PER_DISK * self.n, budget - int(tally[growth.TALLY_COLLISIONS]))
            status = growth.run(disks, events, self.cells, self.box, tally, room, self.t_grid, IDLE_PER_DISK * self.n)
            t = self.t_grid if status == growth.RAN_UNTIL else float(tally[growth.TALLY_CLOCK])
            growth.synchronise(disks, t)
            window.add(t, self._kinetic_energy())
            disks.vel[:] *= math.sqrt(self.kinetic / self._kinetic_energy())  # hold the temperature
            if window.collisions(tally) >= WINDOW_PER_DISK * self.n:
                pressure = window.pressure(tally)
                window = _Window(t, tally, self.kinetic)
            done = int(tally[growth.TALLY_COLLISIONS])
            if pressure >= until_pressure or done >= budget or t >= self.t_half or status == growth.RAN_IDLE:
                break
            if status == growth.RAN_UNTIL:
                self.box, self.t_grid = self._grid(t)
                self.cells = growth.make_cells(self.n, self.box)
                assert self.t_grid > t, "a new grid serves longer"
            if self.scene.periodic:
                disks.pos[:] = wrap_positions(disks.pos, self.bounds, 2)[0]
            growth.reschedule(disks, events, self.cells, self.box, t)
            now = time.perf_counter()
            if progress and now - last_shown >= PROGRESS_SECONDS:
                last_shown = now
                self._show(t, pressure, done, now - started)
        if math.isnan(pressure) and window.collisions(tally) > 0:  # (a run shorter than a window)
            pressure = window.pressure(tally)
        return self._packing(t, pressure, until_pressure, budget)

    def _kinetic_energy(self) -> float:
        return 0.5 * float(np.sum(self.disks.mass * np.sum(self.disks.vel**2, axis=1)))

    def _packing_fraction(self, t: float) -> float:
        r = self.disks.r0 + self.disks.r_dot * t
        return float(np.pi * np.sum(r**2) / self.area)

    def _show(self, t: float, pressure: float, done: int, seconds: float) -> None:
        print(
            f"compress: phi {self._packing_fraction(t):.6f}, Z {pressure:.4g}, {done:.4g} collisions "
            f"({done / seconds:.3g}/s)",
            file=sys.stderr,
            flush=True,
        )

    def _packing(self, t: float, pressure: float, until_pressure: float, budget: int) -> Packing:
        disks = self.disks
        events = int(self.tally[growth.TALLY_COLLISIONS])
        jammed = pressure >= until_pressure
        if not jammed:
            if events >= budget:
                why = f"its budget of {budget} collisions was spent (max_events)"
            elif t >= self.t_half:
                why = "the largest disk reached half the periodic cell"
            else:
                why = f"the disks stopped meeting ({IDLE_PER_DISK} events per disk without a collision)"
            warnings.warn(
                f"compress: stopped at Z = {pressure:.4g} < until_pressure = {until_pressure:g}: {why}",
                CompressionWarning,
                stacklevel=3,
            )
        pos = disks.pos.copy()
        if self.scene.periodic:
            pos, _ = wrap_positions(pos, self.bounds, 2)
        radii = disks.r0 + disks.r_dot * t
        return Packing(
            self.scene,
            pos,
            disks.vel.copy(),
            disks.mass.copy(),
            radii,
            self._packing_fraction(t),
            pressure,
            events,
            t,
            jammed,
        )


class _Window:
    """The collision virial and the kinetic energy's time integral since a window began."""

    def __init__(self, t: float, tally: np.ndarray, kinetic: float) -> None:
        self.t = t
        self.virial0 = tally[growth.TALLY_PAIR_VIRIAL] + tally[growth.TALLY_WALL_VIRIAL]
        self.collisions0 = tally[growth.TALLY_COLLISIONS]
        self.kinetic = kinetic  # at the window's (or the last rescale's) start
        self.kinetic_time = 0.0  # integral of K dt (trapezoids between rescales)

    def add(self, t: float, kinetic_end: float) -> None:
        self.kinetic_time += 0.5 * (self.kinetic + kinetic_end) * (t - self.t)
        self.t = t

    def collisions(self, tally: np.ndarray) -> float:
        return float(tally[growth.TALLY_COLLISIONS] - self.collisions0)

    def pressure(self, tally: np.ndarray) -> float:
        virial = tally[growth.TALLY_PAIR_VIRIAL] + tally[growth.TALLY_WALL_VIRIAL] - self.virial0
        if not self.kinetic_time > 0.0:
            return math.inf if virial > 0.0 else 1.0
        return float(1.0 + virial / (2.0 * self.kinetic_time))
