"""Means of correlated samples with their standard errors: block averaging.

Successive frames of a run are correlated, so the standard deviation of their values over the square
root of their number underestimates the error of their mean. Flyvbjerg & Petersen's blocking
transformation (H. Flyvbjerg and H. G. Petersen, *J. Chem. Phys.* 91, 461 (1989)) averages
neighbouring samples in pairs, again and again: level ``k`` holds the means of blocks of ``2^k``
samples, and once the blocks are longer than the correlation time, their means are independent and
the naive estimate from them, ``s_k / sqrt(n_k)`` (``s_k`` the blocks' standard deviation, ``n_k``
their number), is the mean's standard error. The level is chosen as Wolff (U. Wolff, *Comput. Phys.
Commun.* 156, 143 (2004), eq. 47) and Lee et al. (R. M. Lee, G. J. Conduit, N. Nemec, P. López Ríos
and N. D. Drummond, *Phys. Rev. E* 83, 066706 (2011), eq. 14) choose it: the smallest block size
``B = 2^k`` with

    B^3 > 2 n (SE_k / SE_0)^4

``n`` the number of samples: ``(SE_k / SE_0)^2`` estimates the correlation time in samples, and
this ``B`` balances the bias of blocks too short against the noise of blocks too few. The criterion
reads the correlation at the block size it tries, so correlations slower than that (which raise
the estimates only at longer blocks) are missed: :attr:`BlockAverage.errors` is the whole blocking
curve, whose plateau is the error (Flyvbjerg & Petersen's reading), to check it by.

:class:`Blocking` takes the samples as they come (one, or an array at a time) and keeps only a few
numbers per level, so a run of any length needs ``O(log n)`` memory; :func:`block_average` is the
same for an array at hand.

>>> rng = np.random.default_rng(0)
>>> result = block_average(rng.normal(size=4096))  # independent samples: SE = 1 / 64
>>> round(result.mean, 3), round(result.error, 4), result.reliable
(-0.016, 0.0166, True)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["BlockAverage", "Blocking", "block_average"]


class BlockAverage(NamedTuple):
    """The mean of a run's samples and its standard error (:func:`block_average`, :class:`Blocking`)."""

    mean: float  #: the mean of every sample
    error: float  #: the standard error of the mean, from the chosen level's blocks
    error_of_error: float  #: the error's own standard error, ``error / sqrt(2 (blocks - 1))``
    block_size: int  #: samples per block at the chosen level, ``2^k``
    blocks: int  #: blocks at the chosen level
    reliable: bool  #: the chosen level meets the criterion (False: the run is too short to tell)
    errors: np.ndarray  #: the standard error estimated at each level, ``k = 0, 1, ...`` (the blocking curve)

    def __str__(self) -> str:
        return f"{self.mean:.6g} ± {self.error:.2g}"


class _Level:
    """One level of the blocking: the count, mean and sum of squared deviations of its block means
    (Chan, Golub & LeVeque's pairwise update), and a block mean waiting for its pair."""

    __slots__ = ("count", "m2", "mean", "pending")

    def __init__(self) -> None:
        self.count, self.mean, self.m2 = 0, 0.0, 0.0
        self.pending: float | None = None

    def add(self, values: np.ndarray) -> np.ndarray:
        """Take ``values`` in; return the means of the pairs they complete (the next level's values)."""
        n = len(values)
        if n:
            mean = float(np.mean(values))
            m2 = float(np.sum((values - mean) ** 2))
            total = self.count + n
            delta = mean - self.mean
            self.mean += delta * n / total
            self.m2 += m2 + delta * delta * self.count * n / total
            self.count = total
        if self.pending is not None:
            values = np.concatenate(([self.pending], values))
        if len(values) % 2:
            self.pending, values = float(values[-1]), values[:-1]
        else:
            self.pending = None
        return 0.5 * (values[0::2] + values[1::2])

    def error(self) -> float:
        """The naive standard error of the mean from this level's block means (``nan`` below two)."""
        if self.count < 2:
            return math.nan
        return math.sqrt(self.m2 / (self.count - 1) / self.count)


class Blocking:
    """Flyvbjerg & Petersen's blocking transformation, fed sample after sample (see the module).

    >>> blocking = Blocking()
    >>> for chunk in np.array_split(np.arange(1000.0) % 7, 3):
    ...     blocking.add(chunk)
    >>> blocking.count, round(blocking.result().mean, 6)
    (1000, 2.997)
    """

    def __init__(self) -> None:
        self._levels: list[_Level] = [_Level()]

    @property
    def count(self) -> int:
        """The samples taken so far."""
        return self._levels[0].count

    def add(self, values: ArrayLike) -> None:
        """Take a sample, or an array of samples in order (finite numbers; a refused call takes none)."""
        x = np.asarray(values, dtype=np.float64).reshape(-1)
        if not np.isfinite(x).all():
            raise ValueError("values: samples must be finite numbers")
        level = 0
        while len(x):
            if level == len(self._levels):
                self._levels.append(_Level())
            x = self._levels[level].add(x)
            level += 1

    def result(self) -> BlockAverage:
        """The mean and its standard error at the level the criterion chooses (see the module). With
        fewer than two samples the error is ``nan``; if no level with two blocks or more meets the
        criterion, the last such level's estimate is given, with ``reliable`` False."""
        n = self.count
        if n == 0:
            raise ValueError("Blocking: no samples yet")
        levels = [level for level in self._levels if level.count >= 2]
        errors = np.array([level.error() for level in levels])
        mean = self._levels[0].mean
        if not levels:
            return BlockAverage(mean, math.nan, math.nan, 1, n, False, errors)
        first = errors[0]
        chosen, reliable = len(levels) - 1, False
        for k, error in enumerate(errors):
            if first == 0.0 or 2.0 ** (3 * k) > 2.0 * n * (error / first) ** 4:
                chosen, reliable = k, True
                break
        blocks = levels[chosen].count
        error = float(errors[chosen])
        return BlockAverage(mean, error, error / math.sqrt(2.0 * (blocks - 1)), 2**chosen, blocks, reliable, errors)


def block_average(samples: ArrayLike) -> BlockAverage:
    """The mean of a run's ``samples`` (in the order they were taken) and its standard error from
    blocking (see the module; :class:`Blocking` takes them as they come)."""
    x = np.asarray(samples, dtype=np.float64)
    if x.ndim != 1 or len(x) == 0:
        raise ValueError(f"samples: expected a non-empty 1-D sequence, got shape {x.shape}")
    blocking = Blocking()
    blocking.add(x)
    return blocking.result()
