"""The configurations the study measures: this engine's modes, and the peers at their knobs.

Every configuration is a :class:`~collision_env.bench.peers.base.Runner` (one stepping interface);
the peers' runners live in :mod:`collision_env.bench.peers`, one class per peer. Peers are
optional imports: :func:`peer_runners` returns only those installed, with the reasons for the rest.

- :class:`EngineRunner`: ``collision_env.engine`` in naive, posteriori (k substeps) or exact mode.
  Steps the batch-of-one underneath ``Simulator`` (what the vector envs use) and keeps its
  impacts as arrays.
- the peers: :class:`~collision_env.bench.peers.pymunk.PymunkRunner` and
  :class:`~collision_env.bench.peers.billiards.BilliardsRunner`.
"""

from __future__ import annotations

import numpy as np

from collision_env.engine import BatchSimulator

from .peers import PEERS, Runner, make_peer
from .scenes import Case


class EngineRunner(Runner):
    """This engine, one mode."""

    engine = "collision_env"
    mode: str
    _sim: BatchSimulator  # (made by start)

    def __init__(self, mode: str, substeps: int = 1, max_events: int = 10_000) -> None:
        self.mode = mode
        self.substeps = substeps
        self.max_events = max_events
        self.iterations = None
        self._capped = False

    @property
    def family(self) -> str:
        if self.mode == "posteriori" or (self.mode == "naive" and self.substeps > 1):
            return f"{self.mode} k={self.substeps}"
        return self.mode

    def start(self, case: Case) -> None:
        self._sim = BatchSimulator(
            case.scene,
            case.positions[None],
            case.velocities[None],
            case.masses,
            case.radii,
            mode=self.mode,
            substeps=self.substeps,
            max_events=self.max_events,
        )
        self._capped = False

    def step(self, dt: float, record: bool = True) -> np.ndarray:
        rows = self._sim.step(dt).array
        if self._sim._stepper.capped[0]:  # (the array itself: cap_reached copies it)
            self._capped = True
        return rows

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        return self._sim.positions[0], self._sim.velocities[0]

    @property
    def impact_count(self) -> int:
        return self._sim.stats["events"]

    def flags(self) -> dict:
        return {"cap_reached": self._capped}


def engine_runners(full: bool) -> list[Runner]:
    """This engine's configurations: naive, posteriori with 1/2/4/8 substeps (quick: 1 and 8), exact."""
    ks = (1, 2, 4, 8) if full else (1, 8)
    return [EngineRunner("naive"), *(EngineRunner("posteriori", k) for k in ks), EngineRunner("exact")]


#: the knobs each peer is measured at, ``(full run, quick run)``
PEER_KNOBS: dict[str, tuple[list[dict[str, int]], list[dict[str, int]]]] = {
    "pymunk": (
        [{"iterations": 10}, {"iterations": 10, "substeps": 8}, {"iterations": 30}],
        [{"iterations": 10}, {"iterations": 10, "substeps": 8}],
    ),
    "billiards": ([{}], [{}]),
}


def peer_runners(full: bool) -> tuple[list[Runner], dict[str, str]]:
    """Installed peers at their knobs, and the reasons for the ones missing."""
    runners: list[Runner] = []
    missing: dict[str, str] = {}
    for name in PEERS:
        first = make_peer(name)
        if isinstance(first, str):
            missing[name] = first
            continue
        full_knobs, quick_knobs = PEER_KNOBS[name]
        runners += [PEERS[name](**knobs) for knobs in (full_knobs if full else quick_knobs)]  # (installed)
    return runners, missing
