"""The temperature, the pressure and the collision rate of a hard-disk gas, from the engine's impacts.

Units are SI, ``kT`` in J (the engine has no Boltzmann constant: ``kT`` is an energy), ``N`` is the
number of disks, ``d`` the scene's dimension, ``A`` the area of the box or periodic cell. Impacts are
:class:`~collision_env.engine.Impacts` or their structured arrays
(:data:`~collision_env.engine.IMPACT_DTYPE`), of one scene, over a run of ``duration`` seconds.

**The temperature a scene has.** A walled box exchanges momentum with its walls, so its ``d N``
velocity components are free: ``kT = 2 K / (d N)``. A periodic cell (or a scene without a border)
conserves the total momentum ``P``: the velocities lie on a sphere of ``d (N - 1)`` dimensions about
the centre of mass, ``kT = 2 K' / (d (N - 1))`` with ``K' = K - |P|^2 / (2 M)`` the kinetic energy
about it. At N = 72 the two differ by 1.4 %: :func:`temperature` takes the scene to know which holds.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.impacts import Impacts
from collision_env.engine.scene import Scene

from . import _checks
from .statistics import BlockAverage, Blocking

__all__ = [
    "PressureAccumulator",
    "collision_rate",
    "collision_virial",
    "mean_free_time",
    "reduced_pressure",
    "temperature",
    "wall_pressure",
]


def _conserves_momentum(scene: Scene) -> bool:
    """A periodic cell or a scene without a border: no wall takes momentum."""
    return scene.periodic or scene.bounds is None


def _kt(internal_energy: np.ndarray | float, n: int, scene: Scene) -> np.ndarray | float:
    """``kT`` from the kinetic energy about the centre of mass (``K`` itself in a walled box): the
    one place the degrees of freedom are counted."""
    free = scene.dimension * (n - 1 if _conserves_momentum(scene) else n)
    return 2.0 * internal_energy / free


def _disks(n: int, scene: Scene) -> None:
    if _conserves_momentum(scene) and n < 2:
        raise ValueError(f"N: a scene that conserves momentum needs at least 2 disks for a temperature, got {n}")


def temperature(velocities: ArrayLike, masses: ArrayLike, scene: Scene) -> float | np.ndarray:
    """``kT`` (J) of the disks' ``velocities``, by equipartition over the degrees of freedom ``scene``
    leaves free (see the module):

        kT = 2 K / (d N)                 a walled box
        kT = 2 K' / (d (N - 1))          a periodic cell, or no border: K' = K - |P|^2 / (2 M)

    ``K = sum m v^2 / 2``, ``P = sum m v``, ``M = sum m``. ``velocities`` is ``(N, 2)`` (a float is
    returned) or ``(..., N, 2)``, frames of a run say (an array of the leading shape is returned);
    ``masses`` is ``(N,)``.

    >>> from collision_env.engine import Scene
    >>> v = [[1.0, 0.0], [-1.0, 0.0]]
    >>> box, cell = Scene(bounds=(0, 0, 4, 4)), Scene(bounds=(0, 0, 4, 4), periodic=True)
    >>> temperature(v, [1.0, 1.0], box), temperature(v, [1.0, 1.0], cell)
    (0.5, 1.0)
    """
    s = _checks.scene(scene)
    v = _checks.finite(velocities, "velocities", 2)
    n = v.shape[-2]
    m = _checks.masses(masses, n)
    _disks(n, s)
    if _conserves_momentum(s):  # (about the centre of mass: K - |P|^2 / 2M without its cancellation)
        v = v - np.einsum("...ij,i->...j", v, m)[..., None, :] / np.sum(m)
    kt = _kt(0.5 * np.einsum("...ij,i->...", v * v, m), n, s)
    return float(kt) if np.ndim(kt) == 0 else np.asarray(kt)


def collision_virial(impacts: Impacts | np.ndarray, radii: ArrayLike) -> float:
    """``W = sum over ball-ball impacts of sigma_ij J_ij`` (J s): the collision
    virial, with ``sigma_ij = r_i + r_j`` the contact distance and ``J_ij`` the normal impulse (the
    record's ``impulse``). At contact ``r_ij . Δp_i = sigma_ij J_ij`` (the impulse lies along the line
    of centres), so ``W`` is the collisions' share of the virial ``sum r . F`` integrated over time
    (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed. 2017, §3.7). ``radii`` are every
    ball's, ``(N,)``, finite and positive."""
    rows = _checks.records(impacts)
    r = _checks.radii(radii)
    pairs = rows[rows["other"] >= 0]
    if len(pairs) and max(int(pairs["ball"].max()), int(pairs["other"].max())) >= len(r):
        raise ValueError(f"radii: the impacts name balls beyond the {len(r)} radii given")
    return float(np.sum((r[pairs["ball"]] + r[pairs["other"]]) * pairs["impulse"]))


def reduced_pressure(
    impacts: Impacts | np.ndarray, radii: ArrayLike, duration: float, kinetic_energy: float, *, scene: Scene
) -> float:
    """The compressibility factor ``Z = P A / (N kT)`` from the collision virial of a run of
    ``duration`` seconds (Alder & Wainwright, *J. Chem. Phys.* 33, 1439 (1960)):

        Z = 1 + W / (d N kT t)

    with ``W`` the :func:`collision_virial`, ``t`` the ``duration`` and ``kT`` the scene's
    :func:`temperature`: in 2D, ``Z = 1 + W / (2 K t)`` in a walled box and
    ``Z = 1 + (N - 1) / N * W / (2 K t)`` in a periodic cell.

    **Derivation.** The virial theorem (Clausius) gives the canonical pressure as
    ``P A = N kT + <sum_pairs r_ij . F_ij> / d``; for hard disks the forces are impulses at contact,
    ``r_ij . Δp_i = sigma_ij J_ij``, so the time average of the second term is ``W / (d t)``. That
    average is configurational: a collision's virial is ``sigma_ij J_ij`` with ``J_ij = 2 mu_ij
    |u_n|`` (``u_n`` the normal closing speed, ``mu_ij`` the reduced mass), and collisions arrive at
    a rate proportional to ``|u_n|`` times the density of pairs at contact, so ``W / t`` is the
    contact density times ``sigma_ij mu_ij <u_n^2>``; this is the contact theorem
    (Hansen & McDonald, *Theory of Simple Liquids*, 4th ed. 2013, §2.5),
    ``Z = 1 + (pi / 2) rho sigma^2 g(sigma+)`` for equal disks. Hard disks have no potential
    energy, so a run samples positions uniformly over the non-overlapping configurations (the
    canonical ensemble's configurations) and velocities uniformly on the sphere of its kinetic
    energy, independently: ``mu_ij <u_n^2>`` is the ``kT`` of :func:`temperature`. In a walled box
    the ``d N`` velocity components are uncorrelated and ``mu_ij <u_n^2> = 2 K / (d N)``; in a
    periodic cell ``sum m v = 0`` correlates them, ``<v_i . v_j> = -d kT / M`` for ``i != j``,
    which gives ``mu_ij <u_n^2> = 2 K / (d (N - 1))``. With ``kT = 2 K / (d N)`` a periodic cell's
    ``Z - 1`` is ``N / (N - 1)`` times too large, 1.4 % at N = 72: a hundred times the error bar of
    published event-chain Monte Carlo pressures (Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth,
    *J. Chem. Phys.* 157, 234111 (2022)).

    ``kinetic_energy``: ``K`` over the run (for elastic disks it is constant; pass its mean
    otherwise), in a momentum-conserving scene about the centre of mass (``Simulator.kinetic_energy()``
    when the total momentum is zero, as :func:`~collision_env.engine.disk_gas` starts it).
    :class:`PressureAccumulator` takes frames instead and measures the temperature itself.
    Ball-ball impacts only: the walls' share is the :func:`wall_pressure`.
    """
    s = _checks.scene(scene)
    r = _checks.radii(radii)
    t = _checks.positive(duration, "duration")
    k = _checks.positive(kinetic_energy, "kinetic_energy")
    _disks(len(r), s)
    kt = float(_kt(k, len(r), s))
    return 1.0 + collision_virial(impacts, r) / (s.dimension * len(r) * kt * t)


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
    rows = _checks.records(impacts)
    t = _checks.positive(duration, "duration")
    r = _checks.positive(radius, "radius")
    xmin, ymin, xmax, ymax = (float(b) for b in bounds)
    length = _checks.positive(
        2.0 * ((xmax - xmin - 2.0 * r) + (ymax - ymin - 2.0 * r)), "bounds (the length the centres reach)"
    )
    return float(np.sum(rows["impulse"][rows["wall"] >= 0])) / (t * length)


def collision_rate(impacts: Impacts | np.ndarray, n: int, duration: float) -> float:
    """Collisions per disk per second, ``omega = 2 N_coll / (N t)``: each ball-ball impact
    involves two disks (wall impacts are not counted). Its inverse is :func:`mean_free_time`."""
    rows = _checks.records(impacts)
    t = _checks.positive(duration, "duration")
    return 2.0 * float(np.count_nonzero(rows["other"] >= 0)) / (_checks.whole(n, "n", 1) * t)


def mean_free_time(impacts: Impacts | np.ndarray, n: int, duration: float) -> float:
    """The mean time between a disk's collisions, ``tau = 1 / omega`` (:func:`collision_rate`), s;
    infinite if no disk collided."""
    omega = collision_rate(impacts, n, duration)
    return 1.0 / omega if omega > 0.0 else math.inf


class PressureAccumulator:
    """The pressure and the collision rate of a run, with their standard errors, frame after frame.

    Hand it each :meth:`~collision_env.engine.Simulator.frames` call's :class:`~collision_env.engine.Frames`
    in turn (:meth:`add`); it keeps per frame only a few numbers of the blocking transformation
    (:class:`~collision_env.observables.statistics.Blocking`), so a long run needs no list of impacts
    in memory. Each frame gives a sample of

        Z_f = 1 + W_f / (d N kT_f t_f),   omega_f = 2 C_f / (N t_f)

    with ``W_f`` the :func:`collision_virial` of the impacts in the frame's step, ``C_f`` their number,
    ``t_f`` its length and ``kT_f`` the :func:`temperature` of the velocities it ends with (the same
    for every frame of elastic disks): :meth:`pressure` and :meth:`collision_rate` are their means
    with the standard errors from block averaging (Flyvbjerg & Petersen 1989). Frames of equal length
    (one ``dt``) weigh alike, as they should.

    Parameters
    ----------
    scene, radii, masses:
        The simulator's scene, ``(N,)`` radii and masses.
    time:
        The clock when the first frame's step starts (``Simulator.time`` before the first ``frames`` call).

    >>> from collision_env.engine import disk_gas
    >>> gas = disk_gas(64, 0.3, periodic=True, seed=1)
    >>> sim = gas.simulator()
    >>> acc = PressureAccumulator(gas.scene, gas.radii, gas.masses, time=sim.time)
    >>> for _ in range(4):
    ...     acc.add(sim.frames(0.05, 50))
    >>> acc.frames, 1.5 < acc.pressure().mean < 2.5
    (200, True)
    """

    def __init__(self, scene: Scene, radii: ArrayLike, masses: ArrayLike, *, time: float) -> None:
        self._scene = _checks.scene(scene)
        self._radii = _checks.radii(radii)
        self._masses = _checks.masses(masses, len(self._radii))
        _disks(len(self._radii), self._scene)
        if isinstance(time, (bool, np.bool_)) or not isinstance(time, (int, float, np.integer, np.floating)):
            raise ValueError(f"time: expected a finite number of seconds, got {time!r}")
        if not math.isfinite(float(time)):
            raise ValueError(f"time: expected a finite number of seconds, got {time!r}")
        self._time = float(time)
        self._z = Blocking()
        self._omega = Blocking()
        self._virial = 0.0
        self._collisions = 0
        self._start = self._time

    @property
    def frames(self) -> int:
        """The frames taken so far."""
        return self._z.count

    @property
    def duration(self) -> float:
        """The time the frames taken so far span, s."""
        return self._time - self._start

    @property
    def collisions(self) -> int:
        """The ball-ball impacts counted so far."""
        return self._collisions

    def add(self, frames: Any) -> None:
        """Take the frames of one ``Simulator.frames`` call (``time (F,)``, ``velocities (F, N, 2)``
        and ``impacts``), which must follow the frames taken before. A refused call takes none."""
        times = np.asarray(frames.time, dtype=np.float64)
        n = len(self._radii)
        if times.ndim != 1:
            raise ValueError(f"frames: expected a Simulator's frames (time of shape (F,)), got shape {times.shape}")
        velocities = np.asarray(frames.velocities, dtype=np.float64)
        if velocities.shape != (len(times), n, 2):
            raise ValueError(f"frames: expected velocities of shape ({len(times)}, {n}, 2), got {velocities.shape}")
        if not len(times):
            return
        lengths = np.diff(np.concatenate(([self._time], times)))
        if not (np.isfinite(lengths).all() and (lengths > 0.0).all()):
            raise ValueError(
                f"frames: their times must follow one another, from the last one taken ({self._time!r} s) on"
            )
        rows = _checks.records(frames.impacts)
        pairs = rows[rows["other"] >= 0]
        # each impact to the frame whose step holds it (its time, up to the clock's round-off)
        frame = np.minimum(np.searchsorted(times, pairs["time"], side="left"), len(times) - 1)
        sigma = self._radii[pairs["ball"]] + self._radii[pairs["other"]]
        virial = np.bincount(frame, weights=sigma * pairs["impulse"], minlength=len(times))
        count = np.bincount(frame, minlength=len(times))
        kt = np.atleast_1d(temperature(velocities, self._masses, self._scene))
        if not (kt > 0.0).all():
            raise ValueError("frames: a frame's disks are at rest (kT = 0): no pressure")
        z = 1.0 + virial / (self._scene.dimension * n * kt * lengths)
        omega = 2.0 * count / (n * lengths)
        if not (np.isfinite(z).all() and np.isfinite(omega).all()):
            raise ValueError("frames: a frame's pressure is not finite (its steps too short for its impulses)")
        self._z.add(z)
        self._omega.add(omega)
        self._virial += float(np.sum(virial))
        self._collisions += len(pairs)
        self._time = float(times[-1])

    def pressure(self) -> BlockAverage:
        """``Z = P A / (N kT)``: the frames' mean and its standard error (see the class)."""
        return self._z.result()

    def collision_rate(self) -> BlockAverage:
        """Collisions per disk per second: the frames' mean and its standard error."""
        return self._omega.result()
