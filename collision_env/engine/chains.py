"""Event-chain Monte Carlo for hard disks in a periodic cell: equilibrium samples and the pressure,
without the dynamics.

Straight event chains (Bernard, Krauth & Wilson, *Phys. Rev. E* 80, 056704 (2009)) move one disk at
a time along +x, or along +y, for a fixed total displacement ``l`` (the chain length): the disk flies
until it touches another, which then flies on in its place (a *lifting*), until the chain has moved
``l``. Chains go alternately along x and y, each from a disk drawn at random. The method is
rejection-free and satisfies global balance (not detailed balance): the uniform distribution of
non-overlapping configurations is stationary. Near the liquid–hexatic transition it samples many
times faster than local Monte Carlo (Bernard & Krauth, *Phys. Rev. Lett.* 107, 155704 (2011); Engel
et al., *Phys. Rev. E* 87, 042134 (2013)).

The pressure comes from the chains themselves (Michel, Kapfer & Krauth, *J. Chem. Phys.* 140, 054116
(2014); the estimator Li et al., *J. Chem. Phys.* 157, 234111 (2022) use for their reference data):

    beta P A / N = 1 + (sum over liftings of dx_ij) / (total displacement),

``dx_ij`` the distance of the two centres along the chain's axis at the lifting. Derivation, from the
contact theorem: in 2D, ``beta P / rho = 1 + (pi / 2) rho sigma^2 g(sigma)`` for disks of diameter
``sigma`` (contact value ``g``). A disk moving ``ds`` along +x sweeps the partners whose contact
point lies at angle ``theta`` (``|theta| < pi / 2``) from +x within ``ds cos theta``: it meets
``rho g sigma cos theta dtheta ds`` of them, each at ``dx = sigma cos theta``. The sum of ``dx``
per unit displacement is then ``rho g sigma^2 (integral of cos^2 over (-pi/2, pi/2)) = (pi / 2) rho
sigma^2 g = beta P / rho - 1``. In equilibrium the moving disk's surroundings are those of any
disk (global balance), so the ratio over a run measures ``Z - 1``. With several sizes, ``sigma_ij
= r_i + r_j`` and the same sum of ``dx_ij`` hold term by term.

The kernel is :mod:`~collision_env.engine.exact.chains` (compiled at the first call);
the error bar comes from :mod:`~collision_env.engine.blocking`.

>>> from collision_env.engine import disk_gas, event_chain
>>> gas = disk_gas(64, 0.5, periodic=True, seed=1)
>>> run = event_chain(gas.scene, gas.positions, gas.radii, events=200_000, seed=2, progress=False)
>>> run.events, run.chains > 1000, bool(abs(run.reduced_pressure - 4.08) < 3 * run.pressure_error)
(200000, True, True)
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .blocking import new_blocks, standard_error
from .broadphase import grid_geometry
from .exact import chains as kernel
from .physics.periodic import wrap_positions
from .scene import Scene
from .validation import Labels, checked_balls, positive_integer, real_number

#: Most events a run may be asked for (the tallies count them exactly in float64).
MAX_EVENTS = 2**53
#: The longest chain, in periods of the cell's longer side.
MAX_CHAIN_PERIODS = 2**20
#: The default chain holds about this many times ``sqrt(N)`` liftings (see :func:`event_chain`): at
#: ``N = 224``, ``phi = 0.68`` the liftings to an error bar were fewest, and the same within their
#: uncertainty, from 1 to 8 times ``sqrt(N)`` liftings per chain, and grew beyond
#: (``python -m collision_env.bench.chains``).
LIFTINGS_PER_ROOT_N = 4.0
#: Starting disks are drawn this many at a time.
STARTS_BATCH = 4096
#: On a terminal, progress is updated every this many seconds; elsewhere, a line per tenth of the run.
PROGRESS_SECONDS = 0.5
PROGRESS_LINES = 10


class EventChainWarning(RuntimeWarning):
    """An event-chain run ran as many chains as it was asked for events, with fewer liftings: its
    chains are shorter than the distance between liftings."""


class EventChains(NamedTuple):
    """The result of :func:`event_chain`: the disks where the chains left them, and the pressure."""

    scene: Scene  #: the periodic cell (as given)
    positions: np.ndarray  #: (N, 2) centres, wrapped into the cell
    images: np.ndarray  #: (N, 2) int64: periods each disk crossed (the wrapping of the input counted)
    radii: np.ndarray  #: (N,)
    reduced_pressure: float  #: ``Z = beta P A / N`` over the run (inf if no disk could move)
    pressure_error: float  #: its standard error by blocking (inf for a run too short to tell)
    events: int  #: liftings (as asked for, unless an :class:`EventChainWarning` said otherwise)
    chains: int  #: chains completed (the last one may be left part done)
    chain_length: float  #: each chain's total displacement (m)

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``positions + images * (lx, ly)``: where the disks would be without wrapping."""
        return self.positions + self.images * np.array(self.scene.period)


def event_chain(
    scene: Scene,
    positions: ArrayLike,
    radii: ArrayLike,
    *,
    events: int,
    chain_length: float | None = None,
    seed: int | np.random.Generator | None = None,
    progress: bool = True,
) -> EventChains:
    """Sample hard disks in a periodic cell by straight event chains, and measure their pressure.

    See the module docstring for the method and the pressure formula,
    ``Z = beta P A / N = 1 + sum(dx_ij) / (total displacement)``. The pressure is that of the
    canonical ensemble of ``N`` disks (``Z`` for ``N`` disks; an MD run's temperature in a periodic
    cell must count ``d (N - 1)`` degrees of freedom to match it). For monodisperse disks of
    diameter ``sigma`` at area fraction ``phi``, ``beta P sigma^2 = Z 4 phi / pi``.

    Parameters
    ----------
    scene:
        A 2D periodic cell (``Scene(periodic=True)``) with ball collisions, elastic: the ensemble
        sampled is that of elastic hard disks. A box with walls is refused (a chain has
        no partner to hand on to at a wall).
    positions, radii:
        ``(N, 2)`` centres and ``(N,)`` radii, none overlapping, as ``Simulator`` takes them
        (positions outside the cell are wrapped into it, their images counted).
    events:
        How many liftings to run. The chain in progress at the last one is left part done: its
        displacement counts in the pressure, but not in the error's blocks. A run also ends after
        ``events`` chains (with an :class:`EventChainWarning` if it has fewer liftings: chains
        shorter than the distance between liftings, or disks that never meet), so that its work is
        bounded by ``events`` whatever the chain length.
    chain_length:
        Each chain's total displacement (m). By default about ``4 sqrt(N)`` liftings' worth
        (:data:`LIFTINGS_PER_ROOT_N`), the distance between liftings estimated from Henderson's
        equation of state (*Mol. Phys.* 30, 971 (1975)) at the disks' area fraction and mean
        diameter; Li et al. (2022) use chains of the same order, ``sqrt(N)`` times a few mean free
        paths. At most :data:`MAX_CHAIN_PERIODS` periods of the cell's longer side.
    seed:
        For the chains' starting disks (numpy's ``default_rng``). The same seed and input give the
        same run, whether or not progress is shown.
    progress:
        Show the run's progress on standard error: updated in place on a terminal, else one line
        per tenth of the run.

    Returns
    -------
    EventChains
        ``positions`` and ``images`` where the chains left the disks, ``reduced_pressure`` and its
        ``pressure_error``: the standard error of the chains' estimates by blocking
        (Flyvbjerg & Petersen 1989, :mod:`~collision_env.engine.blocking`), ``inf`` until the run
        holds a few dozen of their correlation times.

    Raises ``ValueError`` (naming the ball and the field) for a state ``Simulator`` would refuse, a
    scene that is not an elastic 2D periodic cell with ball collisions, or bad ``events`` or
    ``chain_length``; ``TypeError`` for a scene that is not a :class:`Scene`.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a Scene, got {type(scene).__name__}")
    if not (scene.periodic and scene.dimension == 2 and scene.ball_collisions):
        raise ValueError("scene: event_chain needs a 2D periodic cell (Scene(periodic=True)) with ball collisions")
    if scene.elasticity != 1.0:  # (a periodic scene never sticks)
        raise ValueError(f"scene: event_chain samples elastic hard disks; got elasticity {scene.elasticity:g}")
    events = positive_integer(events, "events", MAX_EVENTS)
    n = disk_count(positions)
    if radii is None or isinstance(radii, str):
        raise ValueError(f"radii: expected {n} radii, got {radii!r}")
    pos, _, _, r = checked_balls(
        scene, Labels(1, single=True), np.arange(1), n, [positions], np.zeros((1, n, 2)), np.ones(n), radii
    )
    assert scene.bounds is not None
    pos, images = wrap_positions(pos[0], scene.bounds, 2)
    radii_ = r[0]
    lx, ly = scene.period
    length = _chain_length(chain_length, radii_, lx * ly, max(lx, ly))
    return _Run(scene, np.ascontiguousarray(pos), images, radii_, length, seed).go(events, progress)


def disk_count(positions: ArrayLike) -> int:
    """The number of disks ``N`` of ``(N, 2)`` positions, at least 2 (else a ValueError)."""
    try:
        shape = np.shape(positions)
    except ValueError:  # numpy refuses ragged nesting
        shape = None
    if shape is None or len(shape) != 2 or shape[0] < 2:
        raise ValueError(f"positions: expected shape (N, 2) with N >= 2, got {shape or 'a ragged sequence'}")
    return int(shape[0])


def _chain_length(given: float | None, radii: np.ndarray, area: float, side: float) -> float:
    """``chain_length`` checked, or the default: ``LIFTINGS_PER_ROOT_N sqrt(N)`` times the mean
    displacement between liftings, ``lambda = (pi sigma / 4) / (Z - 1)`` (from the sum of ``dx`` per
    unit displacement, ``Z - 1``, and its mean ``dx``, ``pi sigma / 4``, over the contact angles),
    with Henderson's ``Z = (1 + phi^2 / 8) / (1 - phi)^2``."""
    most = MAX_CHAIN_PERIODS * side
    if given is None:
        phi = min(float(np.pi * np.sum(radii**2) / area), 0.9)
        z = (1.0 + phi * phi / 8.0) / (1.0 - phi) ** 2
        spacing = 0.25 * np.pi * 2.0 * float(np.mean(radii)) / (z - 1.0)
        return min(LIFTINGS_PER_ROOT_N * math.sqrt(len(radii)) * spacing, most)
    value = real_number(given, "chain_length")
    if not 0.0 < value <= most:
        raise ValueError(
            f"chain_length: must be positive and at most {MAX_CHAIN_PERIODS} periods ({most:.6g} m), got {value!r}"
        )
    return value


class _Run:
    """One run's arrays: the disks, their grid, the chain in progress, the tallies and the blocks."""

    def __init__(self, scene: Scene, pos, images, radii, length: float, seed) -> None:
        assert scene.bounds is not None
        self.scene = scene
        self.pos = pos
        self.images = images
        self.radii = radii
        self.length = length
        self.rng = np.random.default_rng(seed)
        x0, y0 = scene.bounds[:2]
        lx, ly = scene.period
        (_, _, hx, hy), (nx, ny) = (
            a[0] for a in grid_geometry(scene.bounds, pos[None], radii[None], np.ones(1, bool), period=(lx, ly))
        )
        self.grid = kernel.ChainGrid(x0, y0, lx, ly, float(hx), float(hy), int(nx), int(ny))
        self.cells = kernel.make_cells(len(radii), self.grid)
        kernel.fill_cells(pos, self.cells, self.grid)
        self.tally = np.zeros(kernel.TALLY_SIZE)
        self.state = np.zeros(kernel.STATE_SIZE)
        self.blocks = new_blocks()
        self.starts = np.empty(0, dtype=np.int64)
        self.used = 0

    def go(self, events: int, progress: bool) -> EventChains:
        """Run to ``events`` liftings, in stretches between progress reports."""
        show = _Progress(events) if progress else None
        goals = show.goals() if show else [events]
        for goal in goals:
            while self.tally[kernel.TALLY_EVENTS] < goal and self.tally[kernel.TALLY_CHAINS] < events:
                if self.used == len(self.starts):
                    self.starts = self.rng.integers(0, len(self.radii), STARTS_BATCH)
                    self.used = 0
                self.used = kernel.run(
                    self.pos,
                    self.images,
                    self.radii,
                    self.cells,
                    self.grid,
                    self.starts,
                    self.used,
                    self.length,
                    float(goal),
                    float(events),
                    self.tally,
                    self.state,
                    self.blocks,
                )
            if show:
                show.report(self.tally, self._pressure())
            if self.tally[kernel.TALLY_CHAINS] >= events:
                break
        done = int(self.tally[kernel.TALLY_EVENTS])
        if done < events:
            warnings.warn(
                f"event_chain: stopped after {events:,} chains with only {done:,} liftings: the chains "
                f"({self.length:.6g} m) are shorter than the distance between liftings, or the disks never meet",
                EventChainWarning,
                stacklevel=3,
            )
        return EventChains(
            self.scene,
            self.pos,
            self.images,
            self.radii,
            self._pressure(),
            standard_error(self.blocks),
            done,
            int(self.tally[kernel.TALLY_CHAINS]),
            self.length,
        )

    def _pressure(self) -> float:
        moved = self.tally[kernel.TALLY_DISPLACEMENT]
        if not moved > 0.0:
            return math.inf
        return float(1.0 + self.tally[kernel.TALLY_LIFTED] / moved)


class _Progress:
    """Progress on standard error: in place on a terminal (every :data:`PROGRESS_SECONDS`), else a
    line per tenth of the run."""

    def __init__(self, events: int) -> None:
        self.events = events
        self.terminal = sys.stderr.isatty()
        self.started = self.shown = time.perf_counter()

    def goals(self) -> list[int]:
        """The event counts to report at: every 1 % on a terminal, every 10 % elsewhere."""
        parts = 100 if self.terminal else PROGRESS_LINES
        return sorted({max(1, self.events * k // parts) for k in range(1, parts + 1)})

    def report(self, tally: np.ndarray, pressure: float) -> None:
        now = time.perf_counter()
        done = int(tally[kernel.TALLY_EVENTS])
        last = done >= self.events
        if self.terminal and not last and now - self.shown < PROGRESS_SECONDS:
            return
        self.shown = now
        rate = done / max(now - self.started, 1e-9)
        line = f"event_chain: {100 * done / self.events:3.0f} % ({done:,} events, {rate:.3g}/s), Z {pressure:.6g}"
        if self.terminal:
            print("\r" + line, end="\n" if last else "", file=sys.stderr, flush=True)
        else:
            print(line, file=sys.stderr, flush=True)
