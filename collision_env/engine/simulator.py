"""One scene: :class:`Simulator`, the engine's public face for a single simulation.

A simulator steps a :class:`~collision_env.engine.stepper.Stepper` of one scene, the same one a
:class:`~collision_env.engine.BatchSimulator` steps many scenes with: one copy of the physics for
both. It takes and returns arrays without the batch axis, and its errors never show one.
"""

from __future__ import annotations

import copy
import inspect
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .batch import BatchSimulator, Frames, frames_of, new_stepper, snapshot
from .impacts import Impacts
from .keywords import check_keywords
from .scene import Scene
from .snapshot import SimulatorState
from .stepper import Stepper
from .validation import checked_balls, left_out, periodic_slack, real_number, state_record


class Simulator:
    """One scene of ``N`` balls.

    ``Simulator(scene, positions (N, 2), velocities (N, 2), masses (N,), radii=None, mode="exact",
    substeps=1)``; :meth:`step` returns the step's :class:`Impacts` in time order. The other keyword
    arguments (``max_events``, ``collapse_ratio``, ``collapse_floor``, ``contact_duration``) and every
    check are those of :class:`BatchSimulator`, whose parameters they are; shapes in errors are this
    simulator's own.
    """

    _stepper: Stepper

    def __new__(cls, *args: Any, **kwargs: Any) -> Simulator:
        check_keywords(kwargs, _KEYWORDS)  # before __init__, whose TypeError names no close match
        return super().__new__(cls)

    def __init__(
        self,
        scene: Scene,
        positions: ArrayLike,
        velocities: ArrayLike,
        masses: ArrayLike,
        radii: ArrayLike | str | None = None,
        mode: str = "exact",
        substeps: int = 1,
        *,
        max_events: int | None = None,
        collapse_ratio: float = 1e-9,
        collapse_floor: float = 0.0,
        contact_duration: float = 0.0,
    ) -> None:
        try:
            shape = np.shape(positions)
        except ValueError:  # numpy refuses ragged nesting
            shape = None
        if shape is None or len(shape) != 2:
            got = "a ragged sequence" if shape is None else shape
            raise ValueError(f"positions: expected shape (N, 2), got {got}")
        self._stepper = new_stepper(
            scene,
            [positions],
            [velocities],
            masses,
            radii,
            single=True,
            mode=mode,
            substeps=substeps,
            max_events=max_events,
            collapse_ratio=collapse_ratio,
            collapse_floor=collapse_floor,
            contact_duration=contact_duration,
        )

    @property
    def batch(self) -> BatchSimulator:
        """This simulator as a batch of one (the same state: a change through either shows in both)."""
        return BatchSimulator._of(self._stepper)

    @property
    def scene(self) -> Scene:
        """The :class:`Scene`."""
        return self._stepper.scene

    @property
    def mode(self) -> str:
        """``"naive"``, ``"posteriori"`` or ``"exact"``."""
        return self._stepper.settings.mode

    def step(self, dt: float) -> Impacts:
        """Advance by ``dt`` seconds (negative: backwards). Returns the step's impacts in time order,
        as :class:`Impacts` (a sequence of :class:`Impact` over their records); see
        :meth:`BatchSimulator.step` for what ``dt`` may be."""
        # (a float, real_number's common case, is taken without its call)
        return self._stepper.step(dt if isinstance(dt, float) else real_number(dt, "dt"))

    def frames(self, dt: float, n: int, out: Frames | None = None) -> Frames:
        """``n`` steps of ``dt`` seconds in one call, recording the state after each:
        :meth:`BatchSimulator.frames` without the batch axis (``out`` too), the impacts as
        :meth:`step` gives them.

        >>> sim = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), [[0.0, 0.0]], [[1.0, 0.0]], [1.0], [0.25])
        >>> rec = sim.frames(1 / 60, 120)
        >>> rec.positions.shape, float(rec.time[-1].round(12)), [(i.wall, round(i.time, 12)) for i in rec.impacts]
        ((120, 1, 2), 2.0, [('right', 0.75)])
        """
        rec = frames_of(self._stepper, dt, n, out, stacklevel=5)
        return Frames(rec.time[:, 0], rec.positions[:, 0], rec.velocities[:, 0], rec.impacts, rec.images[:, 0])

    # read-only snapshots, as BatchSimulator's: set_balls, nudge and set_state change the state
    @property
    def positions(self) -> np.ndarray:
        """``(N, 2)`` centres, m (a read-only snapshot)."""
        return snapshot(self._stepper.pos[0])

    @property
    def velocities(self) -> np.ndarray:
        """``(N, 2)`` velocities, m/s (a read-only snapshot)."""
        return snapshot(self._stepper.vel[0])

    @property
    def masses(self) -> np.ndarray:
        """``(N,)`` masses, kg (a read-only snapshot)."""
        return snapshot(self._stepper.mass[0])

    @property
    def radii(self) -> np.ndarray:
        """``(N,)`` radii, m (a read-only snapshot)."""
        return snapshot(self._stepper.radius[0])

    @property
    def images(self) -> np.ndarray:
        """``(N, 2)`` int64: periodic cell lengths each ball has crossed along x and y (zeros unless
        the scene is periodic); see :attr:`unwrapped_positions`."""
        return snapshot(self._stepper.images[0])

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(N, 2)`` centres as if the periodic cell did not wrap them, m: ``positions + images *
        Scene.period``."""
        return self.batch.unwrapped_positions[0]

    @property
    def time(self) -> float:
        """Simulation time, s."""
        return float(self._stepper.time[0])

    @property
    def clusters(self) -> np.ndarray:
        """``(N,)``: the index of the ball rooting each ball's rigid cluster (itself if free)."""
        return snapshot(self._stepper.body[0])

    @property
    def cap_reached(self) -> bool:
        """The last step stopped at the event cap."""
        return bool(self._stepper.capped[0])

    @property
    def models(self) -> dict[str, Any]:
        """What the engine computes for this scene (see :attr:`BatchSimulator.models`)."""
        return self._stepper.models()

    @property
    def stats(self) -> dict[str, int]:
        """Work done so far (see :attr:`BatchSimulator.stats`)."""
        return self._stepper.stats()

    def kinetic_energy(self) -> float:
        """Total kinetic energy, J."""
        return float(self.batch.kinetic_energy()[0])

    def momentum(self) -> np.ndarray:
        """``(2,)`` total momentum, kg m/s."""
        return self.batch.momentum()[0]

    def nudge(self, dv: ArrayLike) -> None:
        """Change each ball's velocity by ``dv`` (``(N, 2)``), as an impulse (clusters included)."""
        self.batch.nudge([dv])

    def set_balls(self, positions: ArrayLike | None = None, velocities: ArrayLike | None = None) -> None:
        """Replace positions and/or velocities (validated; on error nothing changes). Time is kept."""
        s = self._stepper
        scene = np.zeros(1, dtype=np.int64)
        pos, vel, mass, radius = checked_balls(
            s.scene,
            s.label,
            scene,
            s.n,
            s.pos if positions is None else [positions],
            s.vel if velocities is None else [velocities],
            s.mass,
            s.radius,
            keep=periodic_slack(s.scene),
        )
        # (balls placed afresh are wrapped into a periodic cell, their images counted from there)
        images = s.images[scene] if positions is None else None
        s.put(scene, pos, vel, mass, radius, time=s.time[scene], compensation=s.clock[scene, 1], images=images)

    def get_state(self) -> SimulatorState:
        """The whole state, as copies of the arrays (no batch axis), that :meth:`set_state` restores
        exactly."""
        return self._stepper.state().single()

    def set_state(self, state: SimulatorState) -> None:
        """Restore a state from :meth:`get_state`, checked as :meth:`BatchSimulator.set_state` checks it
        (a dict of its fields is still taken, with a ``DeprecationWarning``)."""
        record = state_record(state, stacklevel=2)
        self.batch._restore({key: np.asarray(value)[None] for key, value in record.items() if not left_out(value)})

    def copy(self) -> Simulator:
        """An independent copy (``copy.copy`` and ``copy.deepcopy`` give one too)."""
        return copy.deepcopy(self)

    __copy__ = copy


#: The keyword arguments Simulator takes (a misspelled one is named with the closest of them).
_KEYWORDS = tuple(inspect.signature(Simulator.__init__).parameters)[1:]
