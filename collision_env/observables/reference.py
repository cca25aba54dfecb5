"""What the hard-disk fluid is known to do: its equation of state, its contact value and Enskog's
collision rate, to compare a run with.

- :func:`kolafa_rottner_z`: the compressibility factor ``Z = P A / (N kT)`` at area fraction ``eta``,
  Kolafa & Rottner's fit (2006), within a few 1e-4 of event-chain Monte Carlo up to ``eta = 0.70``;
- :func:`henderson_z` and its contact value :func:`henderson_g`: Henderson's closed form (1975),
  within 0.5 % up to ``eta = 0.5``;
- :func:`enskog_rate`: the collision frequency per disk.

Area fractions are ``eta = N pi sigma^2 / (4 A)`` for ``N`` disks of diameter ``sigma`` in an area ``A``.

>>> round(kolafa_rottner_z(0.5), 4), round(henderson_z(0.5), 4)
(4.1064, 4.125)
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from collision_env.engine.gas import CLOSE_PACKED

from . import _checks

__all__ = [
    "KOLAFA_ROTTNER",
    "KOLAFA_ROTTNER_MAX",
    "enskog_rate",
    "henderson_g",
    "henderson_z",
    "kolafa_rottner_z",
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
