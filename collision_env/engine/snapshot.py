"""A simulator's whole state as one typed record: :class:`SimulatorState`, what ``get_state`` gives and
``set_state`` takes."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np


@dataclasses.dataclass(frozen=True, eq=False)
class SimulatorState(Mapping[str, Any]):
    """Everything a simulator's future depends on, as copies of its arrays:
    :meth:`Simulator.get_state <collision_env.engine.Simulator.get_state>` gives one (arrays without
    the batch axis) and :meth:`BatchSimulator.get_state <collision_env.engine.BatchSimulator.get_state>`
    one with it (a leading axis of ``B`` scenes); ``set_state`` restores it exactly.

    Its fields are attributes (``state.positions``), and it reads as a mapping too
    (``state["positions"]``, ``dict(state)``); :meth:`replace` gives a copy with some fields changed.

    >>> from collision_env.engine import Scene, Simulator
    >>> sim = Simulator(Scene(), [[0.0, 0.0]], [[1.0, 0.0]], [1.0])
    >>> state = sim.get_state()
    >>> _ = sim.step(0.5)
    >>> sim.set_state(state.replace(velocities=[[0.0, 2.0]]))
    >>> sim.velocities.tolist(), sim.time
    ([[0.0, 2.0]], 0.0)
    """

    positions: Any  #: ``(N, 2)`` centres, m
    velocities: Any  #: ``(N, 2)`` velocities, m/s
    masses: Any  #: ``(N,)`` masses, kg
    radii: Any  #: ``(N,)`` radii, m
    clusters: Any  #: ``(N,)`` int: the ball rooting each ball's stick cluster (itself if free)
    omega: Any  #: ``(N,)`` angular velocity of the cluster each ball roots, rad/s (0 unless it roots one)
    time: Any  #: the clock, s
    time_compensation: Any  #: the clock's compensation (its round-off so far, below an ulp of ``time``)
    images: Any  #: ``(N, 2)`` int: periodic cell lengths each ball has crossed (zeros unless periodic)
    #: ``(N,)`` each ball's last collision instant on the clock, s (``-inf``: none yet), which the TC
    #: model reads (``contact_duration > 0``); None in the states of simulators without it
    last_impact: Any = None

    def __getitem__(self, key: str) -> Any:
        if key not in FIELDS:
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self) -> Iterator[str]:
        # (a field a simulator does not keep, None, is left out: ``np.savez(**state)`` stays plain)
        return (key for key in FIELDS if getattr(self, key) is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __eq__(self, other: object) -> bool:
        """Equal when every field holds the same values (``np.array_equal``)."""
        if not isinstance(other, SimulatorState):
            return NotImplemented
        return all(_same(getattr(self, key), getattr(other, key)) for key in FIELDS)

    __hash__ = None  # type: ignore[assignment]  # (its arrays are mutable: not hashable, as a dict)

    def replace(self, **changes: Any) -> SimulatorState:
        """A copy with the fields given by keyword changed (the others shared, not copied)."""
        return dataclasses.replace(self, **changes)

    def single(self) -> SimulatorState:
        """The first scene of a batch's state, without the batch axis."""
        return SimulatorState(
            **{key: None if getattr(self, key) is None else np.asarray(getattr(self, key))[0] for key in FIELDS}
        )

    def __repr__(self) -> str:
        shape = np.shape(self.positions)
        return f"SimulatorState({shape[-2] if len(shape) >= 2 else '?'} balls, time={self.time!r})"


def _same(a: Any, b: Any) -> bool:
    """Two fields hold the same values (both None, or ``np.array_equal``)."""
    if a is None or b is None:
        return a is None and b is None
    return bool(np.array_equal(a, b))


#: The fields of a :class:`SimulatorState`, in order.
FIELDS = tuple(field.name for field in dataclasses.fields(SimulatorState))
