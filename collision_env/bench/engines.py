"""One stepping interface over this engine's modes and the peer engines.

A :class:`Runner` is built for one configuration (engine, mode, knobs), started on a
:class:`~collision_env.bench.scenes.Case`, stepped by ``dt`` and asked for its state. Peers are
optional imports: :func:`peer_runners` returns only those installed, and every runner says
(:meth:`Runner.unsupported`) when it cannot do a scene and why.

- :class:`EngineRunner`: ``collision_env.engine`` in naive, posteriori (k substeps) or exact mode.
  Steps the batch-of-one underneath ``Simulator`` (what the vector envs use) and keeps its
  impacts as arrays.
- :class:`PymunkRunner`: pymunk (Chipmunk2D, C, impulse solver with positional correction, no time
  of impact) at its own knobs: solver ``iterations`` and ``substeps`` per step. Balls are circles
  without friction; the border is four static segments; a shape's elasticity is ``sqrt(e)`` because
  Chipmunk multiplies the two shapes' values. It reports an impact when two shapes *begin* to touch,
  stamped with the end of that (sub)step (the only time it knows).
- :class:`BilliardsRunner`: the ``billiards`` package (PyPI 0.5.0; pure Python, event-driven,
  exact times) with the border as four ``InfiniteWall`` obstacles. Elastic only. Its events carry
  no contact point (NaN).
"""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine import WALL_NAMES, BatchSimulator

from .metrics import IMPACTS
from .scenes import Case

_EMPTY = np.zeros(0, dtype=IMPACTS)


class Runner:
    """Common interface: ``start(case)``, ``step(dt, record)`` -> impacts or None, ``state()``."""

    engine = "?"
    family = "?"  # what a curve in the plots is: "naive", "posteriori k=4", "exact", "pymunk", "billiards"

    @property
    def label(self) -> str:
        return self.family

    def unsupported(self, case: Case) -> str | None:
        """Why this runner cannot run ``case`` (None if it can)."""
        return None

    def start(self, case: Case) -> None:
        raise NotImplementedError

    def step(self, dt: float, record: bool = True):
        raise NotImplementedError

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def flags(self) -> dict:
        """Engine-specific flags after a run (e.g. the event cap)."""
        return {}


class EngineRunner(Runner):
    """This engine, one mode."""

    engine = "collision_env"

    def __init__(self, mode: str, substeps: int = 1, max_events: int = 10_000):
        self.mode = mode
        self.substeps = substeps
        self.max_events = max_events
        self.iterations = None
        self._sim = None
        self._capped = False

    @property
    def family(self):
        if self.mode == "posteriori" or (self.mode == "naive" and self.substeps > 1):
            return f"{self.mode} k={self.substeps}"
        return self.mode

    def start(self, case):
        self._sim = BatchSimulator(case.scene, case.positions[None], case.velocities[None], case.masses,
                                   case.radii, mode=self.mode, substeps=self.substeps, max_events=self.max_events)
        self._capped = False

    def step(self, dt, record=True):
        rows = self._sim.step(dt)
        if self._sim._capped[0]:
            self._capped = True
        return rows

    def state(self):
        return self._sim._pos[0].copy(), self._sim._vel[0].copy()

    def flags(self):
        return {"cap_reached": self._capped}


def _impacts_from_engine(chunks) -> np.ndarray:
    """Concatenate the engine's ``IMPACT_DTYPE`` chunks into one :data:`IMPACTS` array."""
    chunks = [c for c in chunks if c is not None and len(c)]
    if not chunks:
        return _EMPTY.copy()
    rows = np.concatenate(chunks)
    out = np.empty(len(rows), dtype=IMPACTS)
    for name in IMPACTS.names:
        out[name] = rows[name]
    return out


def collect(chunks) -> np.ndarray:
    """Impacts returned by a runner's steps, as one :data:`IMPACTS` array."""
    chunks = [c for c in chunks if c is not None and len(c)]
    if not chunks:
        return _EMPTY.copy()
    if chunks[0].dtype != IMPACTS:
        return _impacts_from_engine(chunks)
    return np.concatenate(chunks)


class PymunkRunner(Runner):
    """pymunk at its own knobs (``iterations``, ``substeps``); see the module doc."""

    engine = "pymunk"

    def __init__(self, iterations: int = 10, substeps: int = 1, wall_radius: float = 0.05, slop_ratio: float = 0.01):
        import pymunk

        self._pymunk = pymunk
        self.iterations = iterations
        self.substeps = substeps
        self.mode = None
        self.wall_radius = wall_radius
        self.slop_ratio = slop_ratio

    @property
    def family(self):
        return f"pymunk it={self.iterations}" + (f" k={self.substeps}" if self.substeps > 1 else "")

    def unsupported(self, case):
        if case.scene.sticky:
            return "pymunk: no sticking (rigid merging of balls on contact) in its contact model"
        return None

    def start(self, case):
        pm = self._pymunk
        space = pm.Space()
        space.gravity = (0.0, 0.0)
        space.iterations = self.iterations
        # Chipmunk's default slop (0.1) is in "pixels"; in metres with 5 cm balls it would let balls
        # sink deep into each other, so it is scaled to the smallest ball
        space.collision_slop = self.slop_ratio * float(case.radii.min())
        e_shape = math.sqrt(case.scene.elasticity)
        self._who = {}
        if case.scene.bounds is not None:
            xmin, ymin, xmax, ymax = case.scene.bounds
            w = self.wall_radius
            # segments of radius w whose inner surface is the border
            walls = {
                "left": ((xmin - w, ymin - 2 * w), (xmin - w, ymax + 2 * w)),
                "right": ((xmax + w, ymin - 2 * w), (xmax + w, ymax + 2 * w)),
                "bottom": ((xmin - 2 * w, ymin - w), (xmax + 2 * w, ymin - w)),
                "top": ((xmin - 2 * w, ymax + w), (xmax + 2 * w, ymax + w)),
            }
            for name, (a, b) in walls.items():
                seg = pm.Segment(space.static_body, a, b, w)
                seg.elasticity = e_shape
                seg.friction = 0.0
                space.add(seg)
                self._who[seg] = ("wall", WALL_NAMES.index(name))
        self._bodies = []
        for i in range(len(case.masses)):
            m = float(case.masses[i])
            r = float(case.radii[i])
            body = pm.Body(m, pm.moment_for_circle(m, 0.0, r))
            body.position = (float(case.positions[i, 0]), float(case.positions[i, 1]))
            body.velocity = (float(case.velocities[i, 0]), float(case.velocities[i, 1]))
            shape = pm.Circle(body, r)
            shape.elasticity = e_shape
            shape.friction = 0.0
            space.add(body, shape)
            self._bodies.append(body)
            self._who[shape] = ("ball", i)
        self._space = space
        self._time = 0.0
        self._now = 0.0
        self._log = []
        self._recording = False
        space.on_collision(begin=self._begin)

    def _begin(self, arbiter, space, data):
        if not self._recording:
            return
        a, b = arbiter.shapes
        ka, kb = self._who.get(a), self._who.get(b)
        if ka is None or kb is None:
            return
        pts = arbiter.contact_point_set.points
        x, y = (pts[0].point_a.x, pts[0].point_a.y) if pts else (math.nan, math.nan)
        if ka[0] == "wall":
            ka, kb = kb, ka
        if kb[0] == "wall":
            self._log.append((self._now, ka[1], -1, kb[1], x, y))
        else:
            self._log.append((self._now, ka[1], kb[1], -1, x, y))

    def step(self, dt, record=True):
        self._recording = record
        self._log = []
        h = dt / self.substeps
        for k in range(self.substeps):
            self._now = self._time + (dt if k == self.substeps - 1 else h * (k + 1))
            self._space.step(h)
        self._time += dt
        if not record:
            return None
        return np.array(self._log, dtype=IMPACTS) if self._log else None

    def state(self):
        pos = np.array([tuple(b.position) for b in self._bodies], dtype=np.float64)
        vel = np.array([tuple(b.velocity) for b in self._bodies], dtype=np.float64)
        return pos, vel


class BilliardsRunner(Runner):
    """The ``billiards`` package (event-driven, elastic only); see the module doc."""

    engine = "billiards"
    family = "billiards"

    def __init__(self):
        import billiards

        self._b = billiards
        self.mode = None
        self.substeps = 1
        self.iterations = None

    def unsupported(self, case):
        if case.scene.elasticity != 1.0:
            return f"billiards: elastic collisions only (no restitution; scene has e = {case.scene.elasticity:g})"
        return None

    def start(self, case):
        bl = self._b
        walls = []
        self._wall_index = {}
        if case.scene.bounds is not None:
            xmin, ymin, xmax, ymax = case.scene.bounds
            # inside on the left of each wall (counter-clockwise)
            for name, a, b in (("bottom", (xmin, ymin), (xmax, ymin)), ("right", (xmax, ymin), (xmax, ymax)),
                               ("top", (xmax, ymax), (xmin, ymax)), ("left", (xmin, ymax), (xmin, ymin))):
                w = bl.InfiniteWall(a, b)
                walls.append(w)
                self._wall_index[id(w)] = WALL_NAMES.index(name)
        table = bl.Billiard(walls)
        for i in range(len(case.masses)):
            table.add_ball(case.positions[i].copy(), case.velocities[i].copy(), float(case.radii[i]),
                           float(case.masses[i]))
        self._table = table
        self._time = 0.0

    def step(self, dt, record=True):
        self._time += dt
        events = self._table.evolve(self._time)
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

    def state(self):
        return np.array(self._table.balls_position, dtype=np.float64), np.array(self._table.balls_velocity,
                                                                                 dtype=np.float64)


def engine_runners(full: bool) -> list[Runner]:
    """This engine's configurations: naive, posteriori with 1/2/4/8 substeps (quick: 1 and 8), exact."""
    ks = (1, 2, 4, 8) if full else (1, 8)
    return [EngineRunner("naive")] + [EngineRunner("posteriori", k) for k in ks] + [EngineRunner("exact")]


def peer_runners(full: bool) -> tuple[list[Runner], dict[str, str]]:
    """Installed peers at their knobs, and the reasons for the ones missing."""
    runners, missing = [], {}
    try:
        PymunkRunner()
    except ImportError as exc:
        missing["pymunk"] = f"not installed ({exc})"
    else:
        knobs = ((10, 1), (10, 8), (30, 1)) if full else ((10, 1), (10, 8))
        runners += [PymunkRunner(iterations=it, substeps=k) for it, k in knobs]
    try:
        BilliardsRunner()
    except ImportError as exc:
        missing["billiards"] = f"not installed ({exc})"
    else:
        runners.append(BilliardsRunner())
    return runners, missing
