"""What a scene contains: the play area, the restitution, the dimension and the collision model.

A :class:`Scene` is shared by every ball and, in a batch, by every scene of the batch. Ball
properties (positions, velocities, masses, radii) belong to the simulator.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .keywords import check_keywords
from .physics.walls import WALL_BOTTOM, WALL_LEFT, WALL_NAMES, WALL_RIGHT, WALL_TOP

#: PhET Collision Lab's 2D play area, (xmin, ymin, xmax, ymax) in metres.
PLAY_AREA_2D = (-2.0, -1.0, 2.0, 1.0)
#: PhET's 1D play area: 4 m by 1.1 m; balls stay on y = 0.
PLAY_AREA_1D = (-2.0, -0.55, 2.0, 0.55)
#: Largest coordinate of a border or a ball (m), speed (m/s) and |dt| (s) accepted: squares and sums
#: of these stay finite in float64 (the time-of-impact kernels square separations and relative
#: velocities).
MAX_MAGNITUDE = 1e150
#: Density of PhET's balls (kg/m^3): the radius of a ball is that of a sphere of this density.
BALL_DENSITY = 35.0
#: PhET's radius with "Constant Size" checked (m).
CONSTANT_RADIUS = 0.15

__all__ = [
    "BALL_DENSITY",
    "CONSTANT_RADIUS",
    "PLAY_AREA_1D",
    "PLAY_AREA_2D",
    "WALL_BOTTOM",
    "WALL_LEFT",
    "WALL_NAMES",
    "WALL_RIGHT",
    "WALL_TOP",
    "Scene",
    "radius_from_mass",
]


def is_real(x: object) -> bool:
    """A real number that is not a boolean (Python or numpy scalar types alike)."""
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


def _real_tuple(values, field, expected):
    """``values`` as a tuple of floats, each a real number (not a boolean or a string)."""
    try:
        items = tuple(values)
    except TypeError:
        raise ValueError(f"{field}: expected {expected}, got {values!r}") from None
    for v in items:
        if not is_real(v):
            raise ValueError(f"{field}: expected real numbers {expected}, got {v!r} ({type(v).__name__}) in {values!r}")
    try:
        return tuple(float(v) for v in items)
    except OverflowError:  # an int beyond float64's range
        raise ValueError(f"{field}: expected numbers within float64's range {expected}") from None


def radius_from_mass(mass: ArrayLike) -> np.ndarray:
    """PhET's mass-to-radius rule, ``r = (3 m / (4 pi rho))^(1/3)`` with rho = 35 kg/m^3."""
    return np.cbrt(3.0 * np.asarray(mass, dtype=np.float64) / (4.0 * math.pi * BALL_DENSITY))


@dataclass(frozen=True)
class Scene:
    """The static description of a scene: its border, restitution, dimension and collision model,
    shared by every ball (and, in a batch, by every scene). Each field is a keyword argument."""

    bounds: tuple[float, float, float, float] | None = PLAY_AREA_2D
    """``(xmin, ymin, xmax, ymax)`` of the reflecting border in metres (of the periodic cell with
    ``periodic=True``), or ``None`` for no border (balls leave the area and fly on)."""
    elasticity: float = 1.0
    """Coefficient of restitution ``e`` in [0, 1], for ball-ball and ball-wall collisions alike."""
    dimension: int = 2
    """2, or 1 for motion along x only (y and vy stay 0)."""
    inelastic: str = "slip"
    """``"slip"`` or ``"stick"``. Only meaningful at elasticity 0: with ``"stick"``, colliding balls
    join a rigid cluster that rotates about its centre of mass, and a ball or cluster that touches a
    wall stops dead (PhET's Inelastic screen)."""
    ball_collisions: bool = True
    """``False`` lets balls pass through each other (no pair work at all)."""
    periodic: bool = False
    """``True`` makes ``bounds`` a periodic cell in both axes (x only in 1D) instead of a reflecting
    border: there are no walls and no wall impacts; a ball that leaves the cell through one side
    comes back through the opposite one, and two balls meet through the boundary by the
    minimum-image convention (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed., 2017,
    section 1.6.4): a pair interacts through its nearest periodic images. Positions are reported
    wrapped into the cell, ``[xmin, xmax) x [ymin, ymax)`` up to round-off; each ball's count of
    cell lengths crossed is kept (``images``), so that ``positions + images * (xmax - xmin, ymax -
    ymin)`` are the unwrapped positions (``Simulator.unwrapped_positions``), for diffusion. Every
    ball's diameter must be less than half the cell's width (and height, in 2D), so that a ball
    never touches two images of another at once; positions outside the cell are wrapped into it
    (their images counted). Stick clusters (``inelastic="stick"`` at elasticity 0) are not
    supported in a periodic cell, and at elasticity below 1 the balls of a touching group collide
    pairwise, one event after another, rather than as one contact group. Works in every mode."""

    def __new__(cls, *args: Any, **kwargs: Any) -> Scene:
        # before the generated __init__, whose TypeError names no close match
        check_keywords(kwargs, (f.name for f in fields(cls)))
        return super().__new__(cls)

    def __post_init__(self) -> None:
        if (
            isinstance(self.dimension, (bool, np.bool_))
            or not isinstance(self.dimension, numbers.Integral)
            or self.dimension not in (1, 2)
        ):
            raise ValueError(f"scene dimension: must be 1 or 2 (an integer, not a boolean), got {self.dimension!r}")
        object.__setattr__(self, "dimension", int(self.dimension))
        if self.bounds is not None:
            b = _real_tuple(self.bounds, "scene bounds", "(xmin, ymin, xmax, ymax)")
            if len(b) != 4 or not all(abs(v) <= MAX_MAGNITUDE for v in b):
                raise ValueError(
                    f"scene bounds: expected four finite numbers within {MAX_MAGNITUDE:g} m, got {self.bounds!r}"
                )
            if not (b[0] < b[2] and b[1] < b[3]):
                raise ValueError(f"scene bounds: need xmin < xmax and ymin < ymax, got {b}")
            if self.dimension == 1 and not (b[1] < 0.0 < b[3]):
                raise ValueError(f"scene bounds: a 1D scene needs ymin < 0 < ymax (balls move on y = 0), got {b}")
            object.__setattr__(self, "bounds", b)
        if not is_real(self.elasticity):
            raise ValueError(f"scene elasticity: expected a number in [0, 1], got {self.elasticity!r}")
        if not (0 <= self.elasticity <= 1):  # (compared as given: a huge int has no float)
            raise ValueError(f"scene elasticity: must lie in [0, 1], got {self.elasticity!r}")
        object.__setattr__(self, "elasticity", float(self.elasticity))
        if not (isinstance(self.inelastic, str) and self.inelastic in ("slip", "stick")):
            raise ValueError(f"scene inelastic: must be 'slip' or 'stick', got {self.inelastic!r}")
        if not isinstance(self.ball_collisions, (bool, np.bool_)):
            raise ValueError(f"scene ball_collisions: expected True or False, got {self.ball_collisions!r}")
        object.__setattr__(self, "ball_collisions", bool(self.ball_collisions))
        if not isinstance(self.periodic, (bool, np.bool_)):
            raise ValueError(f"scene periodic: expected True or False, got {self.periodic!r}")
        object.__setattr__(self, "periodic", bool(self.periodic))
        if self.periodic and self.bounds is None:
            raise ValueError("scene periodic: a periodic scene needs bounds (the periodic cell), got bounds=None")
        if self.periodic and self.sticky:
            raise ValueError(
                "scene periodic: stick clusters (inelastic='stick' at elasticity 0) are not supported in a "
                "periodic cell; use inelastic='slip' or periodic=False"
            )

    @property
    def sticky(self) -> bool:
        """True when colliding balls form rigid clusters (stick flavour at elasticity 0)."""
        return self.inelastic == "stick" and self.elasticity == 0.0 and self.ball_collisions

    @property
    def period(self) -> tuple[float, float]:
        """The periodic cell's lengths along x and y (m); 0 along an axis that is not periodic
        (both without ``periodic``, y in 1D)."""
        if not self.periodic or self.bounds is None:  # (a periodic scene always has bounds)
            return (0.0, 0.0)
        xmin, ymin, xmax, ymax = self.bounds
        return (xmax - xmin, ymax - ymin if self.dimension == 2 else 0.0)
