"""The engine's fidelity modes, in one registry: a mode's name mapped to what a simulator needs of it.

A :class:`Mode` says how to build the mode's stepping kernel for a scene, which arrays the kernel
takes besides the shared ``state.State`` (and so how a simulator packs them), how its grid is laid
out, how many impact rows one call may write, and whether its impact times need sorting. The
simulator looks its mode up here once, when it is built, and never tests a mode's name again; a new
mode is one entry of :data:`MODES` (and its kernel). The same object is ``collision_env.engine.MODES``,
where code above the engine takes the names from (``mode in MODES``, ``for name in MODES``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from .broadphase import CHEAP_CELLS_PER_BALL, EXACT_BALLS_PER_CELL, EXACT_CELLS_PER_BALL
from .exact import scheduler
from .scene import Scene
from .state import EXACT_FRAMES_SLOT, SUBSTEP_FRAMES_SLOT, SubstepScratch
from .stepped import cells, substep


class Mode(NamedTuple):
    """What a simulator needs of a mode: an entry of :data:`MODES`."""

    name: str
    """The mode's name, its key in :data:`MODES` (``mode=`` of a simulator or an env)."""
    summary: str
    """One line: how the mode finds collisions."""
    substeps: bool
    """Whether it takes sub-steps (``substeps=k``, its speed knob); exact mode takes only 1."""
    kernel: Callable
    """``kernel(scene, n)``: the compiled stepping kernel for scenes of n balls."""
    arrays: Callable
    """``arrays(scene, n_scenes, n)``: the bundles the kernel takes after the state."""
    persistent: bool
    """Whether the first of those bundles persists from step to step (exact mode's calendar)."""
    frames_slot: int
    """Where a pack holds a frames run's bundle (``state.FramesOut``)."""
    grid: dict
    """How ``broadphase.grid_geometry`` lays out the mode's grid."""
    impact_rows: Callable
    """``impact_rows(scene, n, uses_grid)``: rows of the impact buffer."""
    sorted_impacts: bool
    """Whether its impacts come in time order within each scene."""
    leaves_overlaps: bool
    """Whether its steps may end with balls overlapping (which its ``set_state`` accepts)."""
    kernels: Callable
    """``kernels()``: every kernel it can build (for scenes of any kind but periodic)."""


def _exact_kind(scene: Scene, n: int) -> scheduler.Kind:
    return scheduler.scene_kind(scene.sticky, scene.elasticity, scene.periodic)


def _exact_arrays(scene: Scene, n_scenes: int, n: int) -> tuple:
    return scheduler.calendar_arrays(_exact_kind(scene, n), n_scenes, n), scheduler.exact_scratch(n)


def _exact_rows(scene: Scene, n: int, uses_grid: bool) -> int:
    return max(4096, 2 * scheduler.impacts_per_event(n, _exact_kind(scene, n).cascades))


def _substep_arrays(scene: Scene, n_scenes: int, n: int) -> tuple:
    return (SubstepScratch(np.empty(cells.scratch_size(n), dtype=np.int64)),)


def _substep_rows(scene: Scene, n: int, uses_grid: bool) -> int:
    # with a grid, a sub-step's bound is counted from its cells; the buffer grows if needed
    worst = 32 * n if uses_grid else n * (n - 1) // 2 + 4 * n
    return max(4096, 2 * worst)


def _cheap(name: str, summary: str) -> Mode:
    return Mode(
        name=name,
        summary=summary,
        substeps=True,
        kernel=lambda scene, n: substep.step_kernel(name, scene.periodic),
        arrays=_substep_arrays,
        persistent=False,
        frames_slot=SUBSTEP_FRAMES_SLOT,
        grid=dict(reach=2.0, balls_per_cell=0.0, cells_per_ball=CHEAP_CELLS_PER_BALL),
        impact_rows=_substep_rows,
        sorted_impacts=False,
        leaves_overlaps=True,
        kernels=lambda: [substep.step_kernel(name)],
    )


_MODES: dict[str, Mode] = {
    "naive": _cheap("naive", "move, then reflect the overlaps found (no time of impact)"),
    "posteriori": _cheap("posteriori", "move, then reconstruct when each overlap began (PhET's first engine)"),
    "exact": Mode(
        name="exact",
        summary="event-driven: every impact at its exact time, at any step",
        substeps=False,
        kernel=lambda scene, n: scheduler.step_kernel(_exact_kind(scene, n)),
        arrays=_exact_arrays,
        persistent=True,
        frames_slot=EXACT_FRAMES_SLOT,
        grid=dict(balls_per_cell=EXACT_BALLS_PER_CELL, cells_per_ball=EXACT_CELLS_PER_BALL),
        impact_rows=_exact_rows,
        sorted_impacts=True,
        leaves_overlaps=False,
        kernels=lambda: [scheduler.step_kernel(kind) for kind in scheduler.KINDS],
    ),
}

MODES: Mapping[str, Mode] = MappingProxyType(_MODES)
"""The engine's fidelity modes by name, cheapest first: ``"naive"``, ``"posteriori"``, ``"exact"``.

A read-only mapping: iterating it gives the names (``mode in MODES``, ``for mode in MODES``), and
``MODES[name].summary`` says in one line how that mode finds collisions."""
