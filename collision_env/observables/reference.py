"""What the hard-disk fluid is known to do: its equation of state, its contact value and Enskog's
collision rate, to compare a run with.

- :func:`kolafa_rottner_z`: the compressibility factor ``Z = P A / (N kT)`` at area fraction ``eta``,
  Kolafa & Rottner's fit (2006), within a few 1e-4 of event-chain Monte Carlo up to ``eta = 0.70``;
- :func:`henderson_z` and its contact value :func:`henderson_g`: Henderson's closed form (1975),
  within 0.5 % up to ``eta = 0.5``;
- :func:`enskog_rate`: the collision frequency per disk;
- :func:`li_2022_pressures`: event-chain Monte Carlo pressures of small periodic systems (N = 72,
  224 and 870, in the cells of :data:`LI_2022_CELLS`), Li et al. (2022), to about ``1e-5``.

Area fractions are ``eta = N pi sigma^2 / (4 A)`` for ``N`` disks of diameter ``sigma`` in an area ``A``.

>>> round(kolafa_rottner_z(0.5), 4), round(henderson_z(0.5), 4)
(4.1064, 4.125)
"""

from __future__ import annotations

import math
import numbers
from typing import NamedTuple

import numpy as np

from collision_env.engine.gas import CLOSE_PACKED

from . import _checks

__all__ = [
    "KOLAFA_ROTTNER",
    "KOLAFA_ROTTNER_MAX",
    "LI_2022",
    "LI_2022_CELLS",
    "CellPressures",
    "enskog_rate",
    "henderson_g",
    "henderson_z",
    "kolafa_rottner_z",
    "li_2022_pressures",
]

#: Kolafa & Rottner's fit of the hard-disk compressibility factor, ``Z = sum_i C_i x^i`` with
#: ``x = eta / (1 - eta)`` (their fit to densities up to ``rho sigma^2 = 0.90``, ``eta <= 0.707``):
#: J. Kolafa and M. Rottner, *Mol. Phys.* 104, 3435 (2006). Expanded in ``eta`` it reproduces the
#: exact virial coefficients of hard disks (Clisby & McCoy, *J. Stat. Phys.* 122, 15 (2006)).
KOLAFA_ROTTNER = {
    0: 1.0,
    1: 2.0,
    2: 1.12801775,
    3: 0.00181895291,
    4: -0.0526134737,
    5: 0.0504960168,
    6: -0.0325537792,
    7: 0.0134578632,
    8: 0.00140888182,
    9: -0.00834273601,
    10: 0.00694127367,
    11: -0.00262254723,
    12: 0.000355746352,
    22: -5.24672938e-9,
    57: 5.88054639e-23,
}
#: The fit holds up to here (the liquid-hexatic coexistence starts at about 0.700: Bernard & Krauth,
#: *Phys. Rev. Lett.* 107, 155704 (2011)); above it its high powers run away.
KOLAFA_ROTTNER_MAX = 0.70


def _fraction(packing: float, top: float, name: str = "packing") -> float:
    """An area fraction in ``[0, top)`` (``top`` itself excluded)."""
    if isinstance(packing, (bool, np.bool_)) or not isinstance(packing, numbers.Real) or not 0.0 <= packing < top:
        raise ValueError(f"{name}: an area fraction from 0 to below {top:.6g}, got {packing!r}")
    return float(packing)


def kolafa_rottner_z(packing: float) -> float:
    """The hard-disk fluid's ``Z = P A / (N kT)`` at area fraction ``packing`` (Kolafa & Rottner 2006,
    :data:`KOLAFA_ROTTNER`); a ``ValueError`` above :data:`KOLAFA_ROTTNER_MAX`, where the fit runs away."""
    eta = _fraction(packing, math.nextafter(KOLAFA_ROTTNER_MAX, 1.0), "packing (where the fit holds)")
    x = eta / (1.0 - eta)
    return math.fsum(c * x**i for i, c in KOLAFA_ROTTNER.items())


def henderson_z(packing: float) -> float:
    """Henderson's hard-disk ``Z = (1 + eta^2 / 8) / (1 - eta)^2``: D. Henderson, *Mol. Phys.* 30, 971
    (1975). Within 0.5 % of :func:`kolafa_rottner_z` up to ``eta = 0.5``, above it too high. For
    area fractions below close packing, ``pi / (2 sqrt 3)``."""
    eta = _fraction(packing, CLOSE_PACKED)
    return (1.0 + eta * eta / 8.0) / (1.0 - eta) ** 2


def henderson_g(packing: float) -> float:
    """Henderson's contact value of the hard-disk pair correlation, ``g(sigma+) = (1 - 7 eta / 16)
    / (1 - eta)^2`` at area fraction ``eta``: the contact theorem ``Z = 1 + 2 eta g(sigma+)``
    applied to :func:`henderson_z` (D. Henderson, *Mol. Phys.* 30, 971 (1975)). For area fractions
    below close packing, ``pi / (2 sqrt 3)``."""
    eta = _fraction(packing, CLOSE_PACKED)
    return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2


def enskog_rate(density: float, diameter: float, packing: float, kT: float, mass: float) -> float:
    """Enskog's collision frequency per disk in 2D, ``omega = 2 sqrt(pi) n sigma g(sigma+)
    sqrt(kT / m)`` (= ``2 n sigma g sqrt(pi kT / m)``): the flux of partners through a
    cross-section ``2 sigma`` at the mean relative speed ``sqrt(pi kT / m)`` of two Maxwellian disks,
    times the contact density ``g(sigma+)`` (:func:`henderson_g`) (Chapman & Cowling, *The
    Mathematical Theory of Non-uniform Gases*, 3rd ed. 1970, §16.8, in two dimensions). Exact at
    equilibrium for uncorrelated velocities; at n → 0 it is the Boltzmann rate. ``density`` is
    ``N / A``; ``kT`` the gas's :func:`~collision_env.observables.temperature`."""
    n = _checks.positive(density, "density")
    sigma = _checks.positive(diameter, "diameter")
    kt = _checks.positive(kT, "kT")
    m = _checks.positive(mass, "mass")
    return 2.0 * n * sigma * henderson_g(packing) * math.sqrt(math.pi * kt / m)


_ROW = math.sqrt(3.0) / 2.0
#: The periodic cells of Li et al. (2022), by name: their sides ``(width, height)`` in proportion.
#: ``"1:1"`` is a square; ``"1:sqrt3/2"`` the rectangle of a triangular lattice's rows; the other two
#: hold a perfect triangular crystal of their ``N`` (9 disks a row in 8 rows, 29 in 30), as
#: ``disk_gas(n, phi, arrangement="crystal", periodic=True, aspect=sides)`` makes it.
LI_2022_CELLS = {
    "1:1": (1.0, 1.0),
    "1:sqrt3/2": (1.0, _ROW),
    "9:8sqrt3/2": (9.0, 8.0 * _ROW),
    "29:30sqrt3/2": (29.0, 30.0 * _ROW),
}

#: Hard-disk pressures by event-chain Monte Carlo, ``(phi, beta P sigma^2, its standard error)``
#: rows for each ``(N, cell)`` (:data:`LI_2022_CELLS`), ``sigma`` the diameter, in periodic cells:
#: B. Li, Y. Nishikawa, P. Höllmer, L. Carillo, A. C. Maggs and W. Krauth, "Hard-disk pressure
#: computations — a historic perspective", *J. Chem. Phys.* 157, 234111 (2022),
#: doi:10.1063/5.0126437. The values are the authors' own runs ("this work", straight event chains,
#: the pressure by their rift formula), as published with the paper in its data set
#: (``DigitizedData/ThisWork.csv`` of the authors' HistoricDisks repository, whose software is under
#: the GNU GPL v3); the paper's ``beta P (2 sigma)^2`` is ours ``beta P sigma^2`` (their ``sigma`` is
#: the radius). Only the rows the benchmark compares with are kept: the fluid, ``phi <= 0.68``,
#: and for ``N = 224`` the Mayer–Wood loop of the liquid–hexatic coexistence up to ``phi = 0.71``.
LI_2022: dict[tuple[int, str], tuple[tuple[float, float, float], ...]] = {
    (72, "9:8sqrt3/2"): (
        (0.650, 6.895819, 0.000044),
        (0.652, 6.989873, 0.000059),
        (0.654, 7.084569, 0.000096),
        (0.656, 7.179567, 0.000062),
        (0.658, 7.27471, 0.00011),
        (0.660, 7.369629, 0.000089),
        (0.662, 7.464230, 0.000094),
        (0.664, 7.557429, 0.000085),
        (0.666, 7.648847, 0.000097),
        (0.668, 7.73781, 0.00014),
        (0.670, 7.82314, 0.00025),
        (0.672, 7.90406, 0.00022),
        (0.674, 7.97907, 0.00017),
        (0.676, 8.04520, 0.00030),
        (0.678, 8.10372, 0.00022),
        (0.680, 8.15043, 0.00028),
    ),
    (72, "1:sqrt3/2"): (
        (0.650, 6.945931, 0.000066),
        (0.652, 7.045158, 0.000050),
        (0.654, 7.145655, 0.000050),
        (0.656, 7.247326, 0.000051),
        (0.658, 7.350149, 0.000072),
        (0.660, 7.454226, 0.000069),
        (0.662, 7.559278, 0.000091),
        (0.664, 7.664998, 0.000064),
        (0.666, 7.77153, 0.00010),
        (0.668, 7.878610, 0.000081),
        (0.670, 7.98553, 0.00013),
        (0.672, 8.09301, 0.00015),
        (0.674, 8.19990, 0.00011),
        (0.676, 8.30646, 0.00011),
        (0.678, 8.41170, 0.00010),
        (0.680, 8.51637, 0.00016),
    ),
    (72, "1:1"): (
        (0.650, 6.901074, 0.000071),
        (0.652, 6.996291, 0.000089),
        (0.654, 7.092198, 0.000070),
        (0.656, 7.189031, 0.000060),
        (0.658, 7.28628, 0.00011),
        (0.660, 7.383221, 0.000087),
        (0.662, 7.48034, 0.00011),
        (0.664, 7.57651, 0.00011),
        (0.666, 7.67201, 0.00016),
        (0.668, 7.76553, 0.00010),
        (0.670, 7.85637, 0.00011),
        (0.672, 7.94389, 0.00019),
        (0.674, 8.02684, 0.00025),
        (0.676, 8.10361, 0.00017),
        (0.678, 8.17390, 0.00012),
        (0.680, 8.23631, 0.00034),
    ),
    (224, "1:1"): (
        (0.670, 7.979479, 0.000058),
        (0.672, 8.08531, 0.00011),
        (0.674, 8.18999, 0.00013),
        (0.676, 8.29315, 0.00016),
        (0.678, 8.39390, 0.00021),
        (0.680, 8.49105, 0.00019),
        (0.682, 8.58244, 0.00015),
        (0.684, 8.66582, 0.00024),
        (0.686, 8.73803, 0.00044),
        (0.688, 8.79579, 0.00026),
        (0.690, 8.83348, 0.00046),
        (0.692, 8.84651, 0.00055),
        (0.694, 8.83344, 0.00079),
        (0.696, 8.7966, 0.0011),
        (0.698, 8.74504, 0.00097),
        (0.700, 8.6876, 0.0012),
        (0.702, 8.6436, 0.0020),
        (0.704, 8.6262, 0.0021),
        (0.706, 8.6175, 0.0029),
        (0.708, 8.6305, 0.0044),
        (0.710, 8.6721, 0.0043),
    ),
    (870, "29:30sqrt3/2"): (
        (0.670, 7.986735, 0.000026),
        (0.672, 8.093337, 0.000035),
        (0.674, 8.199758, 0.000024),
        (0.676, 8.305473, 0.000034),
        (0.678, 8.410175, 0.000035),
        (0.680, 8.513233, 0.000037),
    ),
    (870, "1:1"): (
        (0.670, 7.986779, 0.000025),
        (0.672, 8.093305, 0.000035),
        (0.674, 8.199729, 0.000025),
        (0.676, 8.305464, 0.000046),
        (0.678, 8.410215, 0.000027),
        (0.680, 8.513249, 0.000037),
    ),
}


class CellPressures(NamedTuple):
    """One ``(N, cell)`` series of :data:`LI_2022`, as arrays over the area fraction."""

    n: int  #: disks
    cell: str  #: a key of :data:`LI_2022_CELLS`
    sides: tuple[float, float]  #: the cell's ``(width, height)`` in proportion
    packing: np.ndarray  #: area fractions ``phi``
    pressure: np.ndarray  #: ``beta P sigma^2``, ``sigma`` the diameter
    error: np.ndarray  #: its standard error

    @property
    def z(self) -> np.ndarray:
        """The compressibility factor ``Z = beta P A / N = beta P sigma^2 pi / (4 phi)`` (``A = N pi
        sigma^2 / (4 phi)``): what :func:`~collision_env.observables.reduced_pressure` and
        :func:`~collision_env.engine.event_chain` give."""
        return self.pressure * math.pi / (4.0 * self.packing)

    @property
    def z_error(self) -> np.ndarray:
        """The standard error of :attr:`z`."""
        return self.error * math.pi / (4.0 * self.packing)

    def at(self, packing: float) -> tuple[float, float]:
        """``(Z, its standard error)`` at one of the series' area fractions (to ``1e-9``); a
        ``ValueError`` naming the ones it has, for any other."""
        match = np.flatnonzero(np.abs(self.packing - packing) < 1e-9)
        if not len(match):
            have = ", ".join(f"{p:.3f}" for p in self.packing)
            raise ValueError(
                f"packing: Li et al. (2022) give N = {self.n}, cell {self.cell} at {have}; got {packing!r}"
            )
        k = int(match[0])
        return float(self.z[k]), float(self.z_error[k])


def li_2022_pressures(n: int, cell: str = "1:1") -> CellPressures:
    """Li et al.'s event-chain pressures (:data:`LI_2022`) for ``n`` disks in ``cell`` (a key of
    :data:`LI_2022_CELLS`); a ``ValueError`` naming the series there are, for any other.

    >>> ref = li_2022_pressures(72, "1:1")
    >>> z, err = ref.at(0.65)
    >>> round(z, 5), round(err, 6)
    (8.3386, 8.6e-05)
    """
    rows = LI_2022.get((n, cell))
    if rows is None:
        have = ", ".join(f"N = {k[0]} in {k[1]}" for k in LI_2022)
        raise ValueError(f"(n, cell): Li et al. (2022) series are {have}; got N = {n!r} in {cell!r}")
    phi, pressure, error = (np.array(col) for col in zip(*rows, strict=True))
    return CellPressures(n, cell, LI_2022_CELLS[cell], phi, pressure, error)
