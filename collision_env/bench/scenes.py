"""Benchmark scenes: each builder returns a :class:`Case` ``(scene, positions, velocities, masses, radii)``.

The builders are deterministic (seeded) and take the number of balls where that makes sense;
:data:`SCENES` lists them with the ball counts the sweep uses, a default horizon and whether the
scene is chaotic (then the sweep cuts the horizon at about 5 collisions per ball, before chaos
amplifies round-off, so that a final-state comparison against the exact reference still means something).

| scene | what it is | balls |
|---|---|---|
| ``intro`` | PhET Intro: 1D, border off, 0.5 kg at x=-1 (1 m/s) and 1.5 kg at x=1 (-0.5 m/s), e=1 | 2 |
| ``explore_1d`` | PhET Explore 1D defaults (first n of its five balls), e=1 | 1, 2, 4 |
| ``explore_2d`` | PhET Explore 2D defaults (first n of its four balls), e=1 | 1, 2, 4 |
| ``inelastic`` | PhET Inelastic: e=0, stick, the two default Explore 2D balls | 2 |
| ``dilute_gas`` | r=0.05 m disks at packing fraction 0.05, speed 1 m/s, box scaled with n (2:1) | 1..64 |
| ``dense_gas`` | packing fraction 0.5 (lattice start), speed 0.2 m/s | 16, 64 |
| ``corner_shot`` | a 10 m/s ball of radius 0.1 m near the top-right corner, plus slow background balls | 1, 4, 16 |
| ``newtons_cradle`` | n-1 touching equal balls at rest, one hitter at 1 m/s, 1D | 2, 4, 16, 64 |
| ``pi_billiard`` | Galperin: wall, light ball at rest, heavy ball (100^digits) coming in, 1D | 2 |
| ``inelastic_pileup`` | n balls in a row driven into the left wall at e=0.05, 1D (inelastic collapse) | 2, 4, 16, 64 |

All scenes use SI units and PhET's frame (origin at the centre of the play area).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from collision_env.engine import PLAY_AREA_1D, PLAY_AREA_2D, Scene, radius_from_mass


class Case(NamedTuple):
    """A ready-to-run scene: unpacks as ``scene, positions, velocities, masses, radii``."""

    scene: Scene
    positions: np.ndarray  # (N, 2) m
    velocities: np.ndarray  # (N, 2) m/s
    masses: np.ndarray  # (N,) kg
    radii: np.ndarray  # (N,) m


def _case(scene, pos, vel, mass, radii) -> Case:
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
    vel = np.asarray(vel, dtype=np.float64).reshape(-1, 2)
    mass = np.asarray(mass, dtype=np.float64).reshape(-1)
    radii = np.asarray(radii, dtype=np.float64).reshape(-1)
    return Case(scene, pos, vel, mass, radii)


def _check_n(name, n, allowed):
    if n not in allowed:
        raise ValueError(f"{name}: number of balls must be one of {allowed}, got {n}")


# --------------------------------------------------------------------------- PhET presets
_EXPLORE_1D = (  # x, vx, m (PhET Explore 1D's five default balls)
    (-1.8, 1.0, 0.5),
    (-0.1, -0.5, 1.5),
    (0.8, -0.5, 1.0),
    (1.3, 1.10, 1.0),
    (1.8, -1.10, 1.0),
)
_EXPLORE_2D = (  # (x, y), (vx, vy), m (PhET Explore 2D's four default balls)
    ((-1.0, 0.0), (1.0, 0.3), 0.5),
    ((0.0, 0.5), (-0.5, -0.5), 1.5),
    ((-1.0, -0.5), (-0.25, -0.5), 1.0),
    ((0.2, -0.65), (1.1, 0.2), 1.0),
)


def intro(n: int = 2) -> Case:
    """PhET Intro: two balls head-on on a line, reflecting border off, e = 1."""
    _check_n("intro", n, (2,))
    m = np.array([0.5, 1.5])
    return _case(
        Scene(bounds=None, elasticity=1.0, dimension=1),
        [[-1.0, 0.0], [1.0, 0.0]],
        [[1.0, 0.0], [-0.5, 0.0]],
        m,
        radius_from_mass(m),
    )


def explore_1d(n: int = 2) -> Case:
    """PhET Explore 1D: the first ``n`` of its five default balls, e = 1, border on."""
    _check_n("explore_1d", n, (1, 2, 3, 4, 5))
    rows = _EXPLORE_1D[:n]
    m = np.array([r[2] for r in rows])
    return _case(
        Scene(bounds=PLAY_AREA_1D, elasticity=1.0, dimension=1),
        [[r[0], 0.0] for r in rows],
        [[r[1], 0.0] for r in rows],
        m,
        radius_from_mass(m),
    )


def explore_2d(n: int = 2) -> Case:
    """PhET Explore 2D: the first ``n`` of its four default balls, e = 1, border on."""
    _check_n("explore_2d", n, (1, 2, 3, 4))
    rows = _EXPLORE_2D[:n]
    m = np.array([r[2] for r in rows])
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=1.0), [r[0] for r in rows], [r[1] for r in rows], m, radius_from_mass(m)
    )


def inelastic(n: int = 2, flavour: str = "stick") -> Case:
    """PhET Inelastic: e = 0 (stick by default), the two default Explore 2D balls."""
    _check_n("inelastic", n, (2,))
    rows = _EXPLORE_2D[:2]
    m = np.array([r[2] for r in rows])
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=0.0, inelastic=flavour),
        [r[0] for r in rows],
        [r[1] for r in rows],
        m,
        radius_from_mass(m),
    )


# --------------------------------------------------------------------------- gases
def gas_box(n: int, radius: float, packing: float, aspect: float = 2.0) -> tuple[float, float, float, float]:
    """Bounds of a box of aspect ``aspect`` (width/height) holding ``n`` disks at packing fraction ``packing``."""
    area = n * math.pi * radius**2 / packing
    h = math.sqrt(area / aspect)
    w = aspect * h
    return (-w / 2, -h / 2, w / 2, h / 2)


def _lattice(n, bounds, radius, rng, jitter):
    """``n`` centres on a rectangular lattice filling ``bounds``, each jittered by up to ``jitter``."""
    xmin, ymin, xmax, ymax = bounds
    w, h = xmax - xmin, ymax - ymin
    best: tuple[float, int, int] | None = None
    for nx in range(1, n + 1):
        ny = math.ceil(n / nx)
        s = min(w / nx, h / ny)
        if best is None or s > best[0]:
            best = (s, nx, ny)
    assert best is not None  # (n >= 1)
    _, nx, ny = best
    sx, sy = w / nx, h / ny
    if min(sx, sy) < 2 * radius * (1 + 1e-9):
        raise ValueError(f"{n} disks of radius {radius} do not fit on a lattice in {bounds}")
    slots = [(xmin + (i + 0.5) * sx, ymin + (j + 0.5) * sy) for j in range(ny) for i in range(nx)]
    pick = rng.permutation(len(slots))[:n]
    pos = np.array([slots[k] for k in sorted(pick)])
    room = max(0.0, min(jitter, 0.5 * (min(sx, sy) - 2 * radius) * (1 - 1e-6)))
    pos += rng.uniform(-room, room, pos.shape)
    lo = np.array([xmin, ymin]) + radius
    hi = np.array([xmax, ymax]) - radius
    return np.clip(pos, lo, hi)


def _directions(n, speed, rng):
    angle = rng.uniform(0.0, 2.0 * math.pi, n)
    return speed * np.stack([np.cos(angle), np.sin(angle)], axis=1)


def gas(
    n: int, radius: float = 0.05, packing: float = 0.05, speed: float = 1.0, seed: int = 0, elasticity: float = 1.0
) -> Case:
    """``n`` equal 1 kg disks at ``packing`` fraction in a 2:1 box scaled with ``n``, equal speeds, any direction."""
    rng = np.random.default_rng(seed)
    bounds = gas_box(n, radius, packing)
    pos = _lattice(n, bounds, radius, rng, jitter=radius)
    return _case(
        Scene(bounds=bounds, elasticity=elasticity), pos, _directions(n, speed, rng), np.ones(n), np.full(n, radius)
    )


def dilute_gas(n: int = 16) -> Case:
    """Packing fraction 0.05: mostly wall collisions at small n, a dilute gas at 64."""
    return gas(n, radius=0.05, packing=0.05)


def dense_gas(n: int = 64) -> Case:
    """Packing fraction 0.5, speed 0.2 m/s: a dense hard-disk liquid (about 10 collisions per ball per second)."""
    _check_n("dense_gas", n, (16, 64, 256))
    return gas(n, radius=0.05, packing=0.5, speed=0.2)


# --------------------------------------------------------------------------- special scenes
def corner_shot(n: int = 1, speed: float = 10.0) -> Case:
    """A fast ball (``speed`` m/s, r = 0.1 m) aimed near the top-right corner of PhET's 2D play area.

    It hits the top wall 1 mm short of touching the right wall at the same time (a near-corner
    hit: the two crossing times differ by 1e-4 s), then the right wall. The other ``n - 1`` balls
    drift slowly (0.2 m/s) in the left half.
    """
    _check_n("corner_shot", n, (1, 2, 4, 16))
    rng = np.random.default_rng(1)
    r = 0.1
    # start so that the top-wall time is 0.1 s and the right-wall time is 0.1001 s
    vx, vy = speed / math.sqrt(2), speed / math.sqrt(2)
    t_top, t_right = 0.1, 0.1001
    x0 = 2.0 - r - vx * t_right
    y0 = 1.0 - r - vy * t_top
    pos = [[x0, y0]]
    vel = [[vx, vy]]
    if n > 1:
        others = _lattice(n - 1, (-2.0, -1.0, 0.0, 1.0), r, rng, jitter=0.05)
        pos += others.tolist()
        vel += _directions(n - 1, 0.2, rng).tolist()
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=1.0), pos, vel, np.ones(n), np.full(n, r))


def newtons_cradle(n: int = 4) -> Case:
    """``n - 1`` equal balls touching in a row at rest, a hitter at 1 m/s 0.3 m to their left; 1D, e = 1."""
    _check_n("newtons_cradle", n, (2, 3, 4, 5, 8, 16, 32, 64))
    r = min(0.15, 1.0 / n)
    x_first = -(n - 2) * r  # the resting row is centred on x = 0
    pos = [[x_first - 2 * r - 0.3, 0.0]] + [[x_first + 2 * r * k, 0.0] for k in range(n - 1)]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * (n - 1)
    return _case(Scene(bounds=PLAY_AREA_1D, elasticity=1.0, dimension=1), pos, vel, np.ones(n), np.full(n, r))


def pi_billiard(n: int = 2, digits: int = 2) -> Case:
    """Galperin's billiard: a wall at x = -2, a 1 kg ball at rest at x = -1, a ``100**digits`` kg ball at 1 m/s.

    Exactly ``floor(pi * 10**digits)`` collisions in all (ball-ball plus wall). The right wall is
    put far away (x = 1e4 m) so that the heavy ball never comes back within the horizon.
    """
    _check_n("pi_billiard", n, (2,))
    m = np.array([1.0, 100.0**digits])
    r = np.array([0.1, 0.1])
    return _case(
        Scene(bounds=(-2.0, -0.55, 1.0e4, 0.55), elasticity=1.0, dimension=1),
        [[-1.0, 0.0], [0.0, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        m,
        r,
    )


def pi_collisions(digits: int) -> int:
    """The exact collision count of :func:`pi_billiard`: ``floor(pi * 10**digits)``."""
    return int(math.floor(math.pi * 10**digits))


def inelastic_pileup(n: int = 4, elasticity: float = 0.05) -> Case:
    """``n`` equal balls in a row with gaps of half a radius, all driven left at 0.5..1.5 m/s; e = 0.05, 1D.

    They pile up against the left wall: a chain of ever weaker collisions (inelastic collapse),
    which exact mode ends with its regulariser.
    """
    _check_n("inelastic_pileup", n, (1, 2, 3, 4, 8, 16, 32, 64))
    rng = np.random.default_rng(2)
    r = min(0.1, 1.2 / n)
    x0 = -2.0 + r + 0.5
    pos = [[x0 + 2.5 * r * k, 0.0] for k in range(n)]
    vel = [[-rng.uniform(0.5, 1.5), 0.0] for _ in range(n)]
    return _case(Scene(bounds=PLAY_AREA_1D, elasticity=elasticity, dimension=1), pos, vel, np.ones(n), np.full(n, r))


# --------------------------------------------------------------------------- registry
@dataclass(frozen=True)
class SceneSpec:
    """A benchmark scene: its builder, the ball counts to sweep, a horizon and its nature."""

    name: str
    build: Callable[..., Case]
    counts: tuple[int, ...]
    horizon: float  # s of simulated time (cut at ~5 collisions per ball if chaotic)
    chaotic: bool
    description: str
    quick_counts: tuple[int, ...] | None = None
    kwargs: dict = field(default_factory=dict)
    #: Larger ball counts the full study times only (the cost per step, no accuracy: an exact
    #: reference and per-step records of 10^4 balls would dwarf the runs themselves).
    cost_counts: tuple[int, ...] = ()

    def case(self, n: int) -> Case:
        return self.build(n, **self.kwargs)


SCENES: dict[str, SceneSpec] = {
    s.name: s
    for s in (
        SceneSpec("intro", intro, (2,), 3.0, False, "PhET Intro (1D, border off)"),
        SceneSpec("explore_1d", explore_1d, (1, 2, 4), 6.0, False, "PhET Explore 1D defaults", (2, 4)),
        SceneSpec("explore_2d", explore_2d, (1, 2, 4), 6.0, True, "PhET Explore 2D defaults", (2, 4)),
        SceneSpec("inelastic", inelastic, (2,), 4.0, False, "PhET Inelastic (e = 0, stick)"),
        SceneSpec(
            "dilute_gas",
            dilute_gas,
            (1, 2, 4, 16, 64),
            6.0,
            True,
            "gas, packing 0.05",
            (1, 4, 16, 64),
            cost_counts=(256, 1024, 4096, 10_000),
        ),
        SceneSpec("dense_gas", dense_gas, (16, 64), 2.0, True, "gas, packing 0.5", (16,)),
        SceneSpec("corner_shot", corner_shot, (1, 4, 16), 1.0, True, "10 m/s ball near a corner", (1, 4)),
        SceneSpec(
            "newtons_cradle", newtons_cradle, (2, 4, 16, 64), 2.0, False, "Newton's cradle (touching row)", (4, 16)
        ),
        SceneSpec(
            "pi_billiard", pi_billiard, (2,), 8.0, False, "Galperin pi billiard, mass ratio 1e4", kwargs={"digits": 2}
        ),
        SceneSpec(
            "inelastic_pileup",
            inelastic_pileup,
            (2, 4, 16, 64),
            3.0,
            False,
            "1D pile-up into a wall at e = 0.05",
            (4, 16),
        ),
    )
}
