"""The standard error of a mean over a correlated series, by blocking (Flyvbjerg & Petersen, *J. Chem.
Phys.* 91, 461 (1989)).

Consecutive values of a Monte Carlo or molecular-dynamics series are correlated, so the naive
standard error ``s / sqrt(n)`` is too small. The blocking transformation averages neighbouring pairs
of values into a series half as long, again and again; once the blocks are longer than the
correlation, their means are independent, and the naive error of the block means is the mean's
standard error. This module keeps every level at once and online, in O(log n) memory: a value
enters level 0, and every second value of a level, averaged with the one before it, enters the
next level (:func:`push`). Each level keeps its count, mean and sum of squared deviations
(Welford's update, which stays accurate when the spread is small beside the mean).

The level read (:func:`standard_error`) is the first on the plateau: the errors grow with the
block length until the blocks outlast the correlation, then stay level within their own uncertainty,
``SE_k / sqrt(2 (n_k - 1))`` for ``n_k`` blocks (Flyvbjerg & Petersen 1989). A level is taken
when no later level of at least :data:`MIN_BLOCKS` blocks exceeds it by more than
:data:`PLATEAU_SIGMAS` of those; when only the last level would do, there is no plateau to see, and
the error is ``inf``: the series is too short to tell.

>>> import numpy as np
>>> blocks = new_blocks()
>>> push_all(blocks, np.random.default_rng(1).normal(size=4096))
>>> round(standard_error(blocks), 4)  # independent values: about 1 / sqrt(4096) = 0.0156
0.0157
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import njit

#: The most levels kept: 2**64 values fill them.
LEVELS = 64
#: Columns of a level: its count, mean, sum of squared deviations, and the value waiting for a
#: partner (``B_HELD``, valid when ``B_HOLDS`` is 1).
B_COUNT, B_MEAN, B_SQUARES, B_HELD, B_HOLDS = range(5)
#: A level is read only with at least this many blocks (its error is then known to ~20 %).
MIN_BLOCKS = 16
#: A level is on the plateau when no later level's error exceeds it by more than this many of that
#: level's own uncertainties.
PLATEAU_SIGMAS = 2.0


def new_blocks() -> np.ndarray:
    """An empty accumulator: ``(LEVELS, 5)`` float64, the columns ``B_*``."""
    return np.zeros((LEVELS, 5))


@njit(forceinline=True)
def push(blocks, value):
    """Add ``value`` to level 0, and the pair means it completes to the levels above."""
    for level in range(blocks.shape[0]):
        row = blocks[level]
        row[B_COUNT] += 1.0
        delta = value - row[B_MEAN]
        row[B_MEAN] += delta / row[B_COUNT]
        row[B_SQUARES] += delta * (value - row[B_MEAN])
        if row[B_HOLDS] == 0.0:
            row[B_HELD] = value
            row[B_HOLDS] = 1.0
            return
        value = 0.5 * (row[B_HELD] + value)
        row[B_HOLDS] = 0.0


@njit
def push_all(blocks, values):
    """:func:`push` each of ``values`` in turn."""
    for k in range(values.shape[0]):
        push(blocks, values[k])


def level_errors(blocks: np.ndarray) -> np.ndarray:
    """Per level ``k`` (blocks of ``2^k`` values), the naive standard error of its block means (inf for
    a level of fewer than two blocks)."""
    count = blocks[:, B_COUNT]
    with np.errstate(divide="ignore", invalid="ignore"):
        var = np.where(count > 1, blocks[:, B_SQUARES] / np.maximum(count - 1, 1), np.inf)
        return np.sqrt(np.maximum(var, 0.0) / np.maximum(count, 1))


def plateau(blocks: np.ndarray) -> int:
    """The first level on the plateau of the levels' errors (see the module docstring), or -1 where
    the levels of at least :data:`MIN_BLOCKS` blocks show none (a series too short beside its
    correlation time)."""
    errors = level_errors(blocks)
    counts = blocks[:, B_COUNT]
    levels = np.flatnonzero(counts >= MIN_BLOCKS)
    # each level's error is known to about 1 / sqrt(2 (blocks - 1)) of itself
    spread = PLATEAU_SIGMAS * errors / np.sqrt(2.0 * np.maximum(counts - 1, 1))
    for k, level in enumerate(levels[:-1]):
        later = levels[k + 1 :]
        if (errors[later] < errors[level] + spread[later]).all():
            return int(level)
    return -1


def standard_error(blocks: np.ndarray) -> float:
    """The standard error of the mean of the values pushed into ``blocks``, at the :func:`plateau`
    of the levels' errors; ``inf`` where there is none, 0 for values that never vary."""
    if blocks[0, B_COUNT] >= 2 and blocks[0, B_SQUARES] == 0.0:
        return 0.0
    level = plateau(blocks)
    return float(level_errors(blocks)[level]) if level >= 0 else math.inf
