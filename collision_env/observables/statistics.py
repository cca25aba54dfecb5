"""Means of correlated samples with their standard errors: block averaging.

Successive frames of a run are correlated, so the standard deviation of their values over the square
root of their number underestimates the error of their mean. Flyvbjerg & Petersen's blocking
transformation (H. Flyvbjerg and H. G. Petersen, *J. Chem. Phys.* 91, 461 (1989)) averages
neighbouring samples in pairs, again and again: level ``k`` holds the means of blocks of ``2^k``
samples, and once the blocks are longer than the correlation time, their means are independent and
the naive estimate from them, ``s_k / sqrt(n_k)`` (``s_k`` the blocks' standard deviation, ``n_k``
their number), is the mean's standard error. The error is read where Flyvbjerg & Petersen read it,
on the plateau of these estimates: the first level (of at least 16 blocks) that no later level
exceeds by more than twice the later level's own uncertainty, ``SE_k / sqrt(2 (n_k - 1))``. Where
no level settles, the run is too short beside its correlation time: the last level's estimate is
given, marked unreliable. (Rules that pick the level from the estimate at the level itself, such as
Wolff's or Lee et al.'s, read correlations slower than the blocks they try as noise; on event-chain
runs of hard disks they gave errors two to three times smaller than the scatter of independent runs.)

:class:`Blocking` takes the samples as they come (one, or an array at a time) and keeps a few
numbers per level, so a run of any length needs ``O(log n)`` memory; :func:`block_average` is the
same for an array at hand. Both are the engine's own accumulator
(:mod:`collision_env.engine.blocking`, which event-chain Monte Carlo fills inside its kernel).

>>> rng = np.random.default_rng(0)
>>> result = block_average(rng.normal(size=4096))  # independent samples: SE = 1 / 64
>>> round(result.mean, 3), round(result.error, 4), result.reliable
(-0.016, 0.0156, True)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.blocking import B_COUNT, B_MEAN, level_errors, new_blocks, plateau, push_all

__all__ = ["BlockAverage", "Blocking", "block_average"]


class BlockAverage(NamedTuple):
    """The mean of a run's samples and its standard error (:func:`block_average`, :class:`Blocking`)."""

    mean: float  #: the mean of every sample
    error: float  #: the standard error of the mean, from the chosen level's blocks
    error_of_error: float  #: the error's own standard error, ``error / sqrt(2 (blocks - 1))``
    block_size: int  #: samples per block at the chosen level, ``2^k``
    blocks: int  #: blocks at the chosen level
    reliable: bool  #: the chosen level is on the plateau (False: the run is too short to tell)
    errors: np.ndarray  #: the standard error estimated at each level, ``k = 0, 1, ...`` (the blocking curve)

    def __str__(self) -> str:
        return f"{self.mean:.6g} ± {self.error:.2g}"


class Blocking:
    """Flyvbjerg & Petersen's blocking transformation, fed sample after sample (see the module).

    >>> blocking = Blocking()
    >>> for chunk in np.array_split(np.arange(1000.0) % 7, 3):
    ...     blocking.add(chunk)
    >>> blocking.count, round(blocking.result().mean, 6)
    (1000, 2.997)
    """

    def __init__(self) -> None:
        self._blocks = new_blocks()

    @property
    def count(self) -> int:
        """The samples taken so far."""
        return int(self._blocks[0, B_COUNT])

    def add(self, values: ArrayLike) -> None:
        """Take a sample, or an array of samples in order (finite numbers; a refused call takes none)."""
        x = np.asarray(values, dtype=np.float64).reshape(-1)
        if not np.isfinite(x).all():
            raise ValueError("values: samples must be finite numbers")
        push_all(self._blocks, np.ascontiguousarray(x))

    def result(self) -> BlockAverage:
        """The mean and its standard error at the plateau (see the module). With fewer than two
        samples the error is ``nan``; samples that never vary have error 0; where no level settles,
        the last level of two blocks or more gives the error, with ``reliable`` False."""
        n = self.count
        if n == 0:
            raise ValueError("Blocking: no samples yet")
        counts = self._blocks[:, B_COUNT]
        errors = level_errors(self._blocks)[counts >= 2]
        mean = float(self._blocks[0, B_MEAN])
        if not len(errors):
            return BlockAverage(mean, math.nan, math.nan, 1, n, False, errors)
        level, reliable = plateau(self._blocks), True
        if errors[0] == 0.0:
            level = 0
        elif level < 0:
            level, reliable = len(errors) - 1, False
        blocks = int(counts[level])
        error = float(errors[level])
        return BlockAverage(mean, error, error / math.sqrt(2.0 * (blocks - 1)), 2**level, blocks, reliable, errors)


def block_average(samples: ArrayLike) -> BlockAverage:
    """The mean of a run's ``samples`` (in the order they were taken) and its standard error from
    blocking (see the module; :class:`Blocking` takes them as they come)."""
    x = np.asarray(samples, dtype=np.float64)
    if x.ndim != 1 or len(x) == 0:
        raise ValueError(f"samples: expected a non-empty 1-D sequence, got shape {x.shape}")
    blocking = Blocking()
    blocking.add(x)
    return blocking.result()
