"""pymunk (Chipmunk2D, C): an impulse solver with positional correction and no time of impact.

Set up at its own knobs: solver ``iterations`` and ``substeps`` per step. Balls are circles
without friction; the border is four static segments of radius ``wall_radius`` whose inner surface
is the border; a shape's elasticity is ``sqrt(e)`` because Chipmunk multiplies the two shapes'
values; the collision slop (Chipmunk's default 0.1 is meant for pixels) is scaled to the smallest
ball. It reports an impact when two shapes *begin* to touch, stamped with the end of that
(sub)step (the only time it knows), with Chipmunk's first contact point.

What it cannot do: sticking (rigid merging of balls on contact).
"""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine import WALL_NAMES

from ..metrics import IMPACTS
from ..scenes import Case
from .base import Runner


class PymunkRunner(Runner):
    """pymunk at its own knobs (``iterations``, ``substeps``); see the module doc."""

    engine = "pymunk"

    def __init__(
        self, iterations: int = 10, substeps: int = 1, wall_radius: float = 0.05, slop_ratio: float = 0.01
    ) -> None:
        import pymunk

        self._pymunk = pymunk
        self.iterations = iterations
        self.substeps = substeps
        self.wall_radius = wall_radius
        self.slop_ratio = slop_ratio

    @property
    def family(self) -> str:
        return f"pymunk it={self.iterations}" + (f" k={self.substeps}" if self.substeps > 1 else "")

    def unsupported(self, case: Case) -> str | None:
        if case.scene.sticky:
            return "pymunk: no sticking (rigid merging of balls on contact) in its contact model"
        return None

    def _border(self, space, bounds, elasticity):
        xmin, ymin, xmax, ymax = bounds
        w = self.wall_radius
        segments = {  # segments of radius w whose inner surface is the border
            "left": ((xmin - w, ymin - 2 * w), (xmin - w, ymax + 2 * w)),
            "right": ((xmax + w, ymin - 2 * w), (xmax + w, ymax + 2 * w)),
            "bottom": ((xmin - 2 * w, ymin - w), (xmax + 2 * w, ymin - w)),
            "top": ((xmin - 2 * w, ymax + w), (xmax + 2 * w, ymax + w)),
        }
        for name, (a, b) in segments.items():
            seg = self._pymunk.Segment(space.static_body, a, b, w)
            seg.elasticity = elasticity
            seg.friction = 0.0
            space.add(seg)
            self._who[seg] = ("wall", WALL_NAMES.index(name))

    def start(self, case: Case) -> None:
        pm = self._pymunk
        space = pm.Space()
        space.gravity = (0.0, 0.0)
        space.iterations = self.iterations
        space.collision_slop = self.slop_ratio * float(case.radii.min())
        e_shape = math.sqrt(case.scene.elasticity)
        self._who = {}
        if case.scene.bounds is not None:
            self._border(space, case.scene.bounds, e_shape)
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
        self._log: list[tuple] = []
        self._count = 0
        self._recording = False
        space.on_collision(begin=self._begin)

    def _begin(self, arbiter, space, data):
        self._count += 1
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

    def step(self, dt: float, record: bool = True) -> np.ndarray | None:
        if not record and self.substeps == 1:  # the timed path: pymunk's own step and the clock, no bookkeeping
            self._recording = False
            self._space.step(dt)
            self._time += dt
            return None
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

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        pos = np.array([tuple(b.position) for b in self._bodies], dtype=np.float64)
        vel = np.array([tuple(b.velocity) for b in self._bodies], dtype=np.float64)
        return pos, vel

    @property
    def impact_count(self) -> int:
        return self._count
