"""The ``billiards`` package (PyPI 0.5.0): pure Python, event-driven, exact times of impact.

The border is four ``InfiniteWall`` obstacles (the inside on the left of each, counter-clockwise);
the set-up (its O(N^2) first prediction) happens in :meth:`BilliardsRunner.start`, outside any
timing, as the engine's own construction does.

What it cannot do: restitution (it is elastic only); its events carry no contact point (NaN).
"""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine import WALL_NAMES

from ..metrics import IMPACTS
from ..scenes import Case
from .base import Runner


class BilliardsRunner(Runner):
    """The ``billiards`` package (event-driven, elastic only); see the module doc."""

    engine = "billiards"
    family = "billiards"

    def __init__(self) -> None:
        import billiards

        self._b = billiards

    def unsupported(self, case: Case) -> str | None:
        if case.scene.elasticity != 1.0:
            return f"billiards: elastic collisions only (no restitution; scene has e = {case.scene.elasticity:g})"
        return None

    def start(self, case: Case) -> None:
        bl = self._b
        walls = []
        self._wall_index = {}
        if case.scene.bounds is not None:
            xmin, ymin, xmax, ymax = case.scene.bounds
            for name, a, b in (
                ("bottom", (xmin, ymin), (xmax, ymin)),
                ("right", (xmax, ymin), (xmax, ymax)),
                ("top", (xmax, ymax), (xmin, ymax)),
                ("left", (xmin, ymax), (xmin, ymin)),
            ):
                w = bl.InfiniteWall(a, b)
                walls.append(w)
                self._wall_index[id(w)] = WALL_NAMES.index(name)
        table = bl.Billiard(walls)
        for i in range(len(case.masses)):
            table.add_ball(
                case.positions[i].copy(), case.velocities[i].copy(), float(case.radii[i]), float(case.masses[i])
            )
        self._table = table
        self._time = 0.0
        self._count = 0

    def step(self, dt: float, record: bool = True) -> np.ndarray | None:
        self._time += dt
        events = self._table.evolve(self._time)
        self._count += len(events)
        if not record or not events:
            return None
        rows = []
        obstacle = self._b.obstacles.Obstacle
        for t, i, other in events:
            if isinstance(other, obstacle):
                rows.append((t, int(i), -1, self._wall_index[id(other)], math.nan, math.nan))
            else:
                rows.append((t, int(i), int(other), -1, math.nan, math.nan))
        return np.array(rows, dtype=IMPACTS)

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        return (
            np.array(self._table.balls_position, dtype=np.float64),
            np.array(self._table.balls_velocity, dtype=np.float64),
        )

    @property
    def impact_count(self) -> int:
        return self._count
