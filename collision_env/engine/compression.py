"""Compression of hard disks to jamming, or to an area fraction, by the Lubachevsky–Stillinger algorithm.

The disks' radii grow in proportion while they move and collide (Lubachevsky & Stillinger, *J.
Stat. Phys.* 60, 561 (1990); Donev, Torquato & Stillinger, *J. Comput. Phys.* 202, 737 (2005)): the
time of impact of growing disks is still a quadratic, and a colliding pair bounces about the growth
speed, so that it separates (:mod:`~collision_env.engine.physics.growth`; the event loop is
:mod:`~collision_env.engine.exact.growth`, on the exact engine's calendar and grid). Collisions feed
energy in; after every ``4 N`` collisions the velocities are rescaled to the starting kinetic
energy. As the packing approaches jamming, the collision rate and the pressure diverge; the
compression stops when the reduced pressure ``Z = P A / (N kT)`` passes ``until_pressure``,
measured from the collision virial (walls included, see :func:`compress`) over the last ``4 N``
collisions or more (:data:`WINDOW_PER_DISK`), or when the area fraction reaches ``until_phi``.

>>> from collision_env.engine import compress, disk_gas
>>> gas = disk_gas(64, 0.3, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=2)
>>> packing = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_pressure=100.0, seed=3)
>>> bool(0.7 < packing.packing_fraction < 0.85), packing.reduced_pressure >= 100.0
(True, True)
>>> sim = packing.gas().simulator()  # the packing, at its final radii, in the exact engine
>>> dense = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_phi=0.6, seed=3)
>>> round(dense.packing_fraction, 12), dense.jammed
(0.6, False)
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .broadphase import CELL_MARGIN, EXACT_CELLS_PER_BALL, grid_geometry, wall_to_wall
from .chains import disk_count
from .exact import growth
from .exact.grid import GridGeometry
from .gas import Gas
from .physics.periodic import wrap_positions
from .physics.tolerance import CONTACT_RTOL, EPS, ROUNDOFF_ULPS
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
#: In a box, a packing whose touching disks reach from wall to wall (which the engine refuses as
#: jammed) has its radii shrunk by this many times the engine's contact tolerance, relative to
#: themselves: its contacts then open beyond it.
UNJAM_TOLERANCES = 4.0


class CompressionWarning(RuntimeWarning):
    """A compression stopped before the pressure reached ``until_pressure``."""


class Packing(NamedTuple):
    """The result of :func:`compress`: the disks at their final radii, and how the run ended."""

    scene: Scene  #: the box or periodic cell (as given)
    positions: np.ndarray  #: (N, 2) centres (wrapped into a periodic cell)
    velocities: np.ndarray  #: (N, 2) velocities, at the starting kinetic energy
    masses: np.ndarray  #: (N,)
    radii: np.ndarray  #: (N,) the final radii
    packing_fraction: float  #: ``sum(pi r_i^2) / A``
    reduced_pressure: float  #: ``Z = P A / (N kT)`` over the last ``4 N`` collisions or more (1: none)
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
    until_phi: float | None = None,
    max_events: int | None = None,
    seed: int | np.random.Generator | None = None,
    progress: bool = True,
) -> Packing:
    """Grow the disks in proportion until the reduced pressure passes ``until_pressure``, or the area
    fraction reaches ``until_phi``.

    Parameters
    ----------
    scene:
        A 2D box (walls) or periodic cell (``Scene(periodic=True)``) with ball collisions, elastic
        (the compression bounces the disks elastically about their growth whatever the scene says,
        so a scene that says otherwise, inelastic or sticking, is refused).
    positions, radii:
        ``(N, 2)`` centres and ``(N,)`` starting radii, none overlapping (as ``Simulator`` takes
        them). Their ratios are kept: disk ``i`` grows as ``r_i(t) = r_i (1 + gamma t)``.
    velocities, masses:
        ``(N, 2)`` and ``(N,)``; by default unit masses and velocities drawn from the
        Maxwell–Boltzmann distribution at ``kT = 1`` (the centre of mass at rest). The kinetic
        energy ``K`` they start with is held.
    rate:
        How fast the diameters grow, in mean diameters ``s`` per thermal time ``s / v``, with ``v =
        sqrt(K / (N m))`` for the mean mass ``m``: ``gamma = rate v / s``. In the reduced units of
        :func:`~collision_env.engine.disk_gas` (``s = m = kT = 1``) it is the diameters' growth speed.
        Slower compressions jam denser (the rate dependence is measured by ``python -m
        collision_env.bench.physics``); 0 runs the gas without growth.
    until_pressure:
        Stop once ``Z = 1 + W / (d N kT t)`` reaches it, over a window of at least ``4 N``
        collisions: ``W`` sums ``sigma_ij J_ij`` over the collisions and, in a box, ``r_i J_i`` over
        the wall impacts (the virial theorem then gives the walls' pressure on the box area), ``J``
        the normal impulses (see :func:`~collision_env.observables.reduced_pressure`), and ``kT``
        is the temperature, ``2 K / (d N)`` in a box and ``2 K' / (d (N - 1))`` in a periodic cell,
        whose momentum is conserved (``K'`` the kinetic energy about the centre of mass: ``K`` for
        the default velocities). A run without a collision reports ``Z = 1`` (its virial is 0).
    until_phi:
        Stop when the area fraction ``sum(pi r_i^2) / A`` reaches it (it grows as ``(1 + gamma
        t)^2``, so the stop is at that time exactly), unless ``until_pressure`` comes first (the
        packing jams below it: a :class:`CompressionWarning` says so). Above the start's area
        fraction, below 1, with ``rate > 0``.
    max_events:
        The budget of collisions (default ``DEFAULT_EVENTS_PER_DISK * N``): the run stops there
        with a :class:`CompressionWarning`.
    seed:
        For the default velocities.
    progress:
        Show the packing fraction, pressure and event rate on standard error every
        :data:`PROGRESS_SECONDS` of a long run.

    Returns a :class:`Packing` that the engine takes as it is: in a box, a packing whose touching
    disks would reach from wall to wall (near ``Z ~ 10^9``, where the gaps come within the engine's
    contact tolerance, and which the engine refuses as jammed) has its radii shrunk by a few
    ``1e-9`` of themselves (:data:`UNJAM_TOLERANCES`), the least that opens those contacts. Raises
    ``ValueError`` (naming the ball and the field) for a state ``Simulator`` would refuse, a scene
    that is not an elastic 2D box or cell with ball collisions, or bad settings.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene, got {type(scene).__name__}")
    if scene.bounds is None or scene.dimension != 2 or not scene.ball_collisions:
        raise ValueError("scene: compress needs a 2D scene with bounds (a box or a periodic cell) and ball collisions")
    if scene.elasticity != 1.0:
        raise ValueError(
            f"scene: compress bounces the disks elastically; got elasticity {scene.elasticity:g} "
            f"(inelastic {scene.inelastic!r}): use Scene(elasticity=1.0)"
        )
    if not (is_real(rate) and math.isfinite(rate) and rate >= 0.0):
        raise ValueError(f"rate: must be a finite number >= 0, got {rate!r}")
    if not (is_real(until_pressure) and until_pressure > 1.0):
        raise ValueError(f"until_pressure: must be a number > 1 (the ideal gas has Z = 1), got {until_pressure!r}")
    if until_phi is not None and not (is_real(until_phi) and 0.0 < until_phi < 1.0):
        raise ValueError(f"until_phi: must be an area fraction between 0 and 1, got {until_phi!r}")
    n = disk_count(positions)
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
    compression = _Compression(scene, pos[0], vel[0], mass[0], r[0], rate, kinetic)
    if until_phi is not None:
        start = compression.packing_fraction(0.0)
        if not until_phi > start:
            raise ValueError(f"until_phi: must be above the starting area fraction {start:.6g}, got {until_phi!r}")
        if rate == 0.0:
            raise ValueError("until_phi: the disks do not grow at rate 0")
    return compression.run(until_pressure, until_phi, budget, progress)


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
    """One compression's state: the event loop's calendar and grid, and the pressure's window."""

    def __init__(self, scene: Scene, pos, vel, mass, r, rate: float, kinetic: float) -> None:
        assert scene.bounds is not None
        self.scene = scene
        self.bounds: tuple[float, float, float, float] = scene.bounds
        self.n = len(r)
        self.kinetic = kinetic  # the kinetic energy held
        self.mass = mass.copy()
        self.r0 = r.copy()
        x0, y0, x1, y1 = scene.bounds
        self.area = (x1 - x0) * (y1 - y0)
        if scene.periodic:
            pos, _ = wrap_positions(pos, scene.bounds, 2)
        speed = math.sqrt(kinetic / self.n / float(np.mean(mass)))  # sqrt(kT / m), kT = K / N in 2D
        gamma = rate * speed / (2.0 * float(np.mean(r)))
        self.growth = growth.Growth(gamma, scene.periodic, self.bounds)
        self.images = np.zeros((self.n, 2), dtype=np.int64)
        self.largest = int(np.argmax(r))
        # when the largest disk's diameter reaches half the periodic cell (the minimum image)
        self.t_half = math.inf
        if scene.periodic and gamma > 0.0:
            self.t_half = (0.5 * HALF_CELL * min(x1 - x0, y1 - y0) / r[self.largest] - 1.0) / gamma
        self.geo, self.t_grid = self._grid(0.0)
        self.cl = growth.make_calendar(self.n, self.geo.nx * self.geo.ny, 1.0 / self.mass)
        rec = self.cl.rec
        rec["x"], rec["y"] = pos[:, 0], pos[:, 1]
        rec["vx"], rec["vy"] = vel[:, 0], vel[:, 1]
        rec["radius"] = r
        self.tally = np.zeros(growth.TALLY_SIZE)

    def radii(self, t: float) -> np.ndarray:
        return self.r0 * (1.0 + self.growth.gamma * t)

    def packing_fraction(self, t: float) -> float:
        return float(np.pi * np.sum(self.radii(t) ** 2) / self.area)

    def _grid(self, t: float) -> tuple[GridGeometry, float]:
        """The broad phase's grid (``broadphase.grid_geometry``) for the disks at ``GRID_HEADROOM``
        times their radii at ``t``, and the time until which it serves: when the largest disk fills
        a cell (with the margin), or, in a periodic cell, half the cell (the minimum image)."""
        scene = self.scene
        x0, y0, x1, y1 = self.bounds
        radii = self.radii(t) * GRID_HEADROOM
        period = (x1 - x0, y1 - y0) if scene.periodic else None
        geometry, counts = grid_geometry(
            self.bounds,
            np.zeros((1, self.n, 2)),  # (the positions matter only without bounds)
            radii[None],
            np.ones(1, bool),
            cells_per_ball=EXACT_CELLS_PER_BALL,
            period=period,
        )
        (_, _, hx, hy), (nx, ny) = geometry[0], counts[0]
        geo = GridGeometry(x0, y0, float(hx), float(hy), int(nx), int(ny))
        diameters = [h / CELL_MARGIN for h, c in ((hx, nx), (hy, ny)) if c > 1]
        r_dot = self.r0[self.largest] * self.growth.gamma
        if not diameters or r_dot == 0.0:
            return geo, self.t_half
        return geo, min(float((0.5 * min(diameters) - self.r0[self.largest]) / r_dot), self.t_half)

    def run(self, until_pressure: float, until_phi: float | None, budget: int, progress: bool) -> Packing:
        """Grow the disks window by window (of ``WINDOW_PER_DISK * N`` collisions, or up to the time
        the grid serves, or ``until_phi``'s), rescaling the velocities after each, until the pressure
        over a whole window reaches ``until_pressure``, the area fraction ``until_phi``, the budget
        is spent, or the largest disk fills half the periodic cell."""
        cl, g, tally = self.cl, self.growth, self.tally
        t_phi = math.inf
        if until_phi is not None:
            t_phi = (math.sqrt(until_phi / self.packing_fraction(0.0)) - 1.0) / g.gamma
        growth.reschedule(cl, self.geo, g, 0.0)
        started = last_shown = time.perf_counter()
        window = _Window(0.0, tally, self._temperature())
        pressure = math.nan
        t = 0.0
        while True:
            room = min(WINDOW_PER_DISK * self.n, budget - int(tally[growth.TALLY_COLLISIONS]))
            until = min(self.t_grid, t_phi)
            status = growth.run(cl, self.geo, g, self.images, tally, room, until, IDLE_PER_DISK * self.n)
            t = until if status == growth.RAN_UNTIL else float(tally[growth.TALLY_CLOCK])
            growth.synchronise(cl, t)
            temperature = self._temperature()
            scale = math.sqrt(self.kinetic / self._kinetic_energy())  # hold the kinetic energy
            cl.rec["vx"] *= scale
            cl.rec["vy"] *= scale
            window.add(t, temperature, self._temperature())
            if window.collisions(tally) >= WINDOW_PER_DISK * self.n:
                pressure = window.pressure(tally, self.n)
                window = _Window(t, tally, self._temperature())
            done = int(tally[growth.TALLY_COLLISIONS])
            if pressure >= until_pressure or t >= t_phi or done >= budget or t >= self.t_half:
                break
            if status == growth.RAN_IDLE:
                break
            if status == growth.RAN_UNTIL:
                self.geo, self.t_grid = self._grid(t)
                self.cl = cl = cl._replace(heads=np.full(self.geo.nx * self.geo.ny, -1, dtype=np.int32))
                assert self.t_grid > t, "a new grid serves longer"
            growth.reschedule(cl, self.geo, g, t)
            now = time.perf_counter()
            if progress and now - last_shown >= PROGRESS_SECONDS:
                last_shown = now
                self._show(t, pressure, done, now - started)
        if math.isnan(pressure):  # (a run shorter than a window)
            pressure = window.pressure(tally, self.n)
        return self._packing(t, pressure, until_pressure, until_phi, t_phi, budget)

    def _velocities(self) -> np.ndarray:
        return np.stack([self.cl.rec["vx"], self.cl.rec["vy"]], axis=1)

    def _kinetic_energy(self) -> float:
        return 0.5 * float(np.sum(self.mass * np.sum(self._velocities() ** 2, axis=1)))

    def _temperature(self) -> float:
        from collision_env.observables.pressure import temperature  # (the observables import the engine)

        return float(temperature(self._velocities(), self.mass, self.scene))

    def _show(self, t: float, pressure: float, done: int, seconds: float) -> None:
        print(
            f"compress: phi {self.packing_fraction(t):.6f}, Z {pressure:.4g}, {done:.4g} collisions "
            f"({done / seconds:.3g}/s)",
            file=sys.stderr,
            flush=True,
        )

    def _packing(
        self, t: float, pressure: float, until_pressure: float, until_phi: float | None, t_phi: float, budget: int
    ) -> Packing:
        events = int(self.tally[growth.TALLY_COLLISIONS])
        jammed = pressure >= until_pressure
        if not (jammed or t >= t_phi):
            if events >= budget:
                why = f"its budget of {budget} collisions was spent (max_events)"
            elif t >= self.t_half:
                why = "the largest disk reached half the periodic cell"
            else:
                why = f"the disks stopped meeting ({IDLE_PER_DISK} events per disk without a collision)"
            target = f"Z = {pressure:.4g} < until_pressure = {until_pressure:g}"
            if until_phi is not None:
                target += f" and phi = {self.packing_fraction(t):.6g} < until_phi = {until_phi:g}"
            warnings.warn(f"compress: stopped at {target}: {why}", CompressionWarning, stacklevel=3)
        elif jammed and until_phi is not None and t < t_phi:
            warnings.warn(
                f"compress: jammed at phi = {self.packing_fraction(t):.6g} < until_phi = {until_phi:g} "
                f"(Z = {pressure:.4g} >= until_pressure = {until_pressure:g})",
                CompressionWarning,
                stacklevel=3,
            )
        rec = self.cl.rec
        pos = np.stack([rec["x"], rec["y"]], axis=1)
        radii = self.radii(t)
        if self.scene.periodic:
            pos, _ = wrap_positions(pos, self.bounds, 2)
        else:
            radii = _unjammed(pos, radii, self.bounds)
        return Packing(
            self.scene,
            pos,
            self._velocities(),
            self.mass.copy(),
            radii,
            float(np.pi * np.sum(radii**2) / self.area),
            pressure,
            events,
            t,
            jammed,
        )


def _unjammed(pos: np.ndarray, radii: np.ndarray, bounds: tuple[float, float, float, float]) -> np.ndarray:
    """``radii`` of disks in a box, shrunk, if their touching disks reach from wall to wall (within
    the engine's contact tolerance: ``CONTACT_RTOL`` of the radii, or the round-off of the
    coordinates), by :data:`UNJAM_TOLERANCES` times that tolerance, relative to the smallest radius
    (doubled until no such network is left)."""
    coordinate = max(float(np.abs(pos).max()), max(abs(b) for b in bounds))
    shrink = UNJAM_TOLERANCES * max(CONTACT_RTOL, ROUNDOFF_ULPS * EPS * coordinate / float(radii.min()))
    box = np.array(bounds)
    while wall_to_wall(pos, radii, box, 2, True)[0] >= 0:
        radii = radii * (1.0 - shrink)
        shrink *= 2.0
    return radii


class _Window:
    """The collision virial and the temperature's time integral since a window began."""

    def __init__(self, t: float, tally: np.ndarray, temperature: float) -> None:
        self.t = t
        self.virial0 = tally[growth.TALLY_PAIR_VIRIAL] + tally[growth.TALLY_WALL_VIRIAL]
        self.collisions0 = tally[growth.TALLY_COLLISIONS]
        self.temperature = temperature  # at the window's (or the last rescale's) start
        self.temperature_time = 0.0  # integral of kT dt (trapezoids between rescales)

    def add(self, t: float, temperature_end: float, temperature_next: float) -> None:
        """The disks ran to ``t``, where their temperature was ``temperature_end``, then rescaled to
        ``temperature_next``."""
        self.temperature_time += 0.5 * (self.temperature + temperature_end) * (t - self.t)
        self.t = t
        self.temperature = temperature_next

    def collisions(self, tally: np.ndarray) -> float:
        return float(tally[growth.TALLY_COLLISIONS] - self.collisions0)

    def pressure(self, tally: np.ndarray, n: int) -> float:
        """``Z = 1 + W / (d N integral of kT dt)`` over the window (1 with no collision: ``W = 0``;
        inf for collisions in no time)."""
        virial = tally[growth.TALLY_PAIR_VIRIAL] + tally[growth.TALLY_WALL_VIRIAL] - self.virial0
        if not virial > 0.0:
            return 1.0
        if not self.temperature_time > 0.0:
            return math.inf
        return float(1.0 + virial / (2.0 * n * self.temperature_time))
