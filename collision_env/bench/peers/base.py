"""The interface every engine is measured through: set up, step, report impacts, say what it cannot do.

A :class:`Runner` is built for one configuration (engine, mode, knobs), started on a
:class:`~collision_env.bench.scenes.Case`, stepped by ``dt`` and asked for its state. Impacts come
back as :data:`~collision_env.bench.metrics.IMPACTS` rows (or the engine's own ``IMPACT_DTYPE``
chunks, which :func:`collect` converts).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..metrics import IMPACTS, as_impacts
from ..scenes import Case

_EMPTY = np.zeros(0, dtype=IMPACTS)


class Runner:
    """Common interface: ``start(case)``, ``step(dt, record)`` -> impacts or None, ``state()``."""

    engine = "?"
    mode: str | None = None
    substeps = 1
    iterations: int | None = None

    @property
    def family(self) -> str:
        """What a curve in the plots is: "naive", "posteriori k=4", "exact", "pymunk", "billiards"."""
        return "?"

    @property
    def label(self) -> str:
        return self.family

    def unsupported(self, case: Case) -> str | None:
        """Why this runner cannot run ``case`` (None if it can)."""
        return None

    def start(self, case: Case) -> None:
        """Set the runner up on ``case`` (this is never timed)."""
        raise NotImplementedError

    def step(self, dt: float, record: bool = True) -> np.ndarray | None:
        """Advance by ``dt``; the impacts of the step if ``record`` (None if none or not recording)."""
        raise NotImplementedError

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities, ``(N, 2)`` each (copies)."""
        raise NotImplementedError

    @property
    def impact_count(self) -> int:
        """Impacts (events) processed since :meth:`start`, recorded or not."""
        raise NotImplementedError

    def flags(self) -> dict:
        """Engine-specific flags after a run (e.g. the event cap)."""
        return {}


def collect(chunks: Iterable[np.ndarray | None]) -> np.ndarray:
    """Impacts returned by a runner's steps, as one :data:`~collision_env.bench.metrics.IMPACTS` array."""
    kept = [c for c in chunks if c is not None and len(c)]
    return as_impacts(np.concatenate(kept)) if kept else _EMPTY.copy()
