"""Stability at the extremes: every mode over a stress grid, pass or the reason it fails.

Run it as ``python -m collision_env.bench.extremes [--quick] [--out docs/bench]``.

The grid (:func:`cells`) spans speeds 1e-6 to 1e4 m/s, radii 1e-4 to 0.5 m, mass ratios up to
1e12 (1e18 for a light ball squeezed against a wall), restitution 0 (slip and stick), 0.05, 0.5 and
1, control steps 1e-6 to 1 s, episodes up to 1e5 s of simulated time and 1e6 steps, balls touching
at the start (each other and the walls), exact corner hits and grazing contacts, scenes 1e6 m from
the origin, slow pairs beside a fast ball, inputs at the edge of float64 (and just beyond it, which
must be refused) and balls as tall as the box (refused), rows and lattices of touching balls that
span the box along x or y (2 to 4,096 balls, e = 1, 0.5 and 0; refused, and run with room to
move), ``set_state`` with each kind of bad field (refused, the state untouched) and 1e9 sub-steps
(refused), and every other way in: a stick cluster glued 1 m across and a misspelt key
(refused in every mode), a position a round-off outside a periodic cell (back bit for bit), an
env's task state with an index out of its array, a NaN or a misspelt key (refused, the env
untouched) and its round trip, env configs beyond what is counted (refused), impacts indexed by
None or True (a TypeError), a box compressed to Z = 1e9 (a state the engine takes), compression without a
collision (Z = 1) and of an inelastic or stick scene (refused), g(r) of a clump (within 50 MB), and the observables'
meaningless inputs (refused). Each cell is one scene, one control step and one duration; every mode runs it, stepping
the public :class:`~collision_env.engine.Simulator` and checking after every step:

- **NaN**: a position or velocity is not finite;
- **escape**: a ball sticks out of the reflecting border by more than ``1e-9 (r + |x|)``;
- **overlap**: two balls overlap by more than ``1e-9 (r_i + r_j) + 1e-12 |x|``;
- **energy growth**: the kinetic energy rises above its start value, or above its value at the
  previous step, by more than a relative 1e-9;
- **event cap**: the step stopped at the event cap (``cap_reached``);
- **time limit**: the mode's steps took longer in all than the budget (``--budget``, per cell and mode;
  the checks between steps are not counted);
- **wrong**: the cell has an analytic answer (pi-billiard collision count, corner reversal,
  Newton's cradle, a lone ball's position after up to 1e5 s within 1e-12 of its path length and
  its impact times within 1e-13 of the elapsed time with points exactly on the walls, a graze or
  a miss) and the mode got it wrong.

The event cap is set per cell above the physical number of events in one step (estimated from
speeds, sizes and the box), so that reaching it flags a runaway (Zeno) step rather than a busy but
finite one: a ball at 1e4 m/s in a 4 m box hits ~1e4 walls per second, which a 1 s step must
resolve. Cheaper modes failing cells is the documented trade; exact mode must pass every cell.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from collision_env.engine import PLAY_AREA_1D, PLAY_AREA_2D, EventCapWarning, Scene, Simulator

from .scenes import Case, _case, gas, inelastic_pileup, pi_billiard, pi_collisions

MODES = (("naive", 1), ("posteriori", 1), ("exact", 1))
REASONS = ("NaN", "escape", "overlap", "energy growth", "event cap", "time limit", "wrong")
TOL = 1e-9


@dataclass
class Cell:
    """One scene, control step and duration of the stress grid."""

    name: str
    group: str
    build: Callable[[], Case]
    dt: float
    duration: float
    events_per_s: float = 0.0  # rough physical event rate (sets the cap)
    check: Callable | None = None  # (sim, n_impacts, impacts or None) -> None or a message
    quick: bool = False
    params: dict = field(default_factory=dict)
    cap: int | None = None  # event cap per step, when the physics bounds it better than the rate

    @property
    def steps(self) -> int:
        return max(1, int(round(self.duration / self.dt)))

    @property
    def max_events(self) -> int:
        if self.cap is not None:
            return self.cap
        return int(max(10_000, 20 * self.events_per_s * self.dt + 1000))


# --------------------------------------------------------------------------- scene helpers
def _box_rate(n, speed, bounds, radius):
    """Rough events per second: each ball meets a wall or another ball every ~free length."""
    if bounds is None:
        return n * speed
    free = max(min(bounds[2] - bounds[0], bounds[3] - bounds[1]) - 2 * radius, radius)
    return 2 * n * speed / free + n * speed / max(radius, 1e-12) * 0.05


def _two_ball_graze(delta):
    """Two balls r = 0.1 passing with impact parameter sigma (1 - delta); no border."""
    sigma = 0.2
    b = sigma * (1.0 - delta)
    return _case(Scene(bounds=None), [[-1.0, 0.0], [1.0, b]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 1.0], [0.1, 0.1])


def _corner(e, r=0.5):
    """A ball from the centre aimed exactly at the top-right corner: both wall times are 0.5 s."""
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=e), [[0.0, 0.0]], [[3.0, 1.0]], [1.0], [r])


def _cradle(n, e, r=0.1):
    """``n - 1`` touching balls at rest, a hitter at 1 m/s 0.2 m away; 1D."""
    x0 = -(n - 2) * r
    pos = [[x0 - 2 * r - 0.2, 0.0]] + [[x0 + 2 * r * k, 0.0] for k in range(n - 1)]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * (n - 1)
    return _case(Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1), pos, vel, np.ones(n), np.full(n, r))


def _train_on_wall(n, e, r=0.1, inelastic="slip"):
    """``n`` balls touching each other and the left wall, all moving left at 1 m/s; 1D."""
    pos = [[-2.0 + r + 2 * r * k, 0.0] for k in range(n)]
    vel = [[-1.0, 0.0]] * n
    return _case(
        Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1, inelastic=inelastic), pos, vel, np.ones(n), np.full(n, r)
    )


def _wall_touch(e):
    """A ball touching the right wall and moving into it, another touching it from the left, 2D."""
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=e),
        [[1.9, 0.0], [1.7, 0.0]],
        [[1.0, 0.3], [0.5, 0.0]],
        [1.0, 1.0],
        [0.1, 0.1],
    )


def _wedged(e, gap):
    """A ball ``gap`` m shorter than the box is tall (r = 1 - gap/2), moving diagonally."""
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=e), [[0.0, 0.0]], [[1.0, 0.5]], [1.0], [1.0 - gap / 2])


def _slide(e):
    """A ball touching the bottom wall and sliding along it into the corner (grazing a wall)."""
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=e), [[0.0, -0.9]], [[1.0, 0.0]], [1.0], [0.1])


def _simultaneous(e):
    """Ball 0 catches up with ball 1 just as ball 1 hits the right wall, at t = 0.5 s."""
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=e),
        [[1.1, 0.0], [1.4, 0.0]],
        [[1.2, 0.0], [1.0, 0.0]],
        [1.0, 1.0],
        [0.1, 0.1],
    )


def _mass_gas(ratio, e):
    """A heavy ball (``ratio`` kg) at rest among three 1 kg balls at 1 m/s, r = 0.2, 2D."""
    rng = np.random.default_rng(5)
    pos = [[0.0, 0.0], [-1.2, 0.5], [1.2, -0.5], [0.8, 0.6]]
    ang = rng.uniform(0, 2 * math.pi, 3)
    vel = [[0.0, 0.0]] + [[math.cos(a), math.sin(a)] for a in ang]
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=e), pos, vel, [ratio, 1.0, 1.0, 1.0], [0.2] * 4)


def _hex_pack(e, inelastic="slip"):
    """19 touching balls (r = 0.1) in a hexagon at rest in the middle, a 5 m/s ball coming in; 2D."""
    r = 0.1
    pos = []
    for row in range(-2, 3):
        count = 5 - abs(row)
        for k in range(count):
            pos.append([(k - (count - 1) / 2) * 2 * r, row * math.sqrt(3) * r])
    pos.append([-1.5, 0.013])
    vel = [[0.0, 0.0]] * 19 + [[5.0, 0.0]]
    return _case(Scene(bounds=PLAY_AREA_2D, elasticity=e, inelastic=inelastic), pos, vel, np.ones(20), np.full(20, r))


def _heavy_cradle(ratio):
    """A touching row of alternating 1 kg and ``ratio`` kg balls, hit by a 1 kg ball; 1D, e = 1."""
    r = 0.1
    n = 6
    pos = [[-1.0, 0.0]] + [[-0.5 + 2 * r * k, 0.0] for k in range(n - 1)]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * (n - 1)
    m = [1.0] + [ratio if k % 2 == 0 else 1.0 for k in range(n - 1)]
    return _case(Scene(bounds=PLAY_AREA_1D, elasticity=1.0, dimension=1), pos, vel, m, np.full(n, r))


def _inelastic_pi(ratio, e):
    """Galperin's geometry at restitution ``e``: wall, light ball at rest, heavy ball coming in."""
    c = pi_billiard(2, 1)
    return _case(
        Scene(bounds=c.scene.bounds, elasticity=e, dimension=1), c.positions, c.velocities, [1.0, ratio], c.radii
    )


def _stuck_pair_corner():
    """Two balls that stick on contact, heading together for the top-right corner; 2D, stick."""
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=0.0, inelastic="stick"),
        [[0.5, 0.2], [1.0, 0.5]],
        [[1.5, 0.9], [0.5, 0.3]],
        [1.0, 2.0],
        [0.15, 0.2],
    )


def _stuck_gas(n):
    c = gas(n, radius=0.1, packing=0.1, speed=1.0, seed=3)
    return Case(Scene(bounds=c.scene.bounds, elasticity=0.0, inelastic="stick"), *c[1:])


# --------------------------------------------------------------------------- analytic checks
def _check_pi(digits):
    def check(sim, count, impacts):
        want = pi_collisions(digits)
        return None if count == want else f"{count} collisions, expected {want}"

    return check


def _check_corner(e):
    def check(sim, count, impacts):
        v = sim.velocities[0]
        want = np.array([-3.0 * e, -1.0 * e])
        if np.allclose(v, want, rtol=1e-12, atol=1e-15):
            return None
        return f"velocity after the corner {v.tolist()}, expected {want.tolist()}"

    return check


def _check_cradle(n):
    """After the chain (and before the far ball reaches the wall) only the far ball moves, at 1 m/s."""

    def check(sim, count, impacts):
        v = sim.velocities[:, 0]
        want = np.zeros(n)
        want[-1] = 1.0
        if np.allclose(v, want, rtol=0, atol=1e-12):
            return None
        return f"velocities after the chain {np.round(v, 12).tolist()}, expected {want.tolist()}"

    return check


def _lone_position(x0, v, lo, hi, t):
    """Position at time t of a point bouncing elastically in [lo, hi] (centre range)."""
    span = hi - lo
    u = (x0 - lo + v * t) % (2 * span)
    return lo + (u if u <= span else 2 * span - u)


def _check_lone(case, t_end):
    """Final position, and (when kept) every impact's time and point, against the analytic bounce."""

    def check(sim, count, impacts):
        (x0, y0), (vx, vy), r = case.positions[0], case.velocities[0], case.radii[0]
        b = case.scene.bounds
        want = np.array(
            [_lone_position(x0, vx, b[0] + r, b[2] - r, t_end), _lone_position(y0, vy, b[1] + r, b[3] - r, t_end)]
        )
        err = float(np.hypot(*(sim.positions[0] - want)))
        # round-off in the event times moves the ball along the wall a little at every bounce: allow
        # 1e-12 of the path length (about 5000 ulps), or 1e-6 of a radius
        tol = max(1e-6 * r, 1e-12 * float(np.hypot(vx, vy)) * t_end)
        if err > tol:
            return f"position off the analytic one by {err:.3g} m after {t_end:g} s (tol {tol:.2g})"
        if impacts is None:
            return None
        # absolute impact times late in a long run: within 1e-13 of the elapsed time (~500 ulps)
        t_tol = 1e-13 * max(t_end, 1.0)
        for axis, walls, x_start, v in ((0, (0, 1), x0, vx), (1, (2, 3), y0, vy)):
            sel = np.isin(impacts["wall"], walls)
            lo, hi = b[axis] + r, b[axis + 2] - r
            span = hi - lo
            u = (x_start - lo + v * impacts["time"][sel]) / span
            t_err = float(np.max(np.abs(u - np.round(u)) * span / abs(v), initial=0.0))
            if t_err > t_tol:
                return f"impact times off the analytic ones by up to {t_err:.3g} s (tol {t_tol:.2g})"
            coord = impacts["x" if axis == 0 else "y"][sel]
            if not np.all((coord == b[axis]) | (coord == b[axis + 2])):
                return "an impact point is not exactly on its wall"
        return None

    return check


def _check_graze(hit):
    def check(sim, count, impacts):
        v = sim.velocities
        if not hit:
            ok = count == 0 and np.array_equal(v, [[1.0, 0.0], [-1.0, 0.0]])
            return None if ok else f"{count} impacts for a miss / exact graze, velocities {v.tolist()}"
        return None if count == 1 else f"{count} impacts for a (near-grazing) hit, expected 1"

    return check


# --------------------------------------------------------------------------- the grid
def cells(quick: bool = False) -> list[Cell]:
    """The stress grid (``quick``: a subset marked ``quick``)."""
    out: list[Cell] = []

    def add(name, group, build, dt, duration, rate=0.0, check=None, q=False, cap=None, **params):
        out.append(Cell(name, group, build, dt, duration, rate, check, q, params, cap))

    # speed x control step: an 8-ball gas, r = 0.1, PhET box, e = 1
    for v in (1e-6, 1e-3, 1.0, 1e2, 1e4):
        for dt in (1e-6, 1e-3, 1.0):
            rate = _box_rate(8, v, PLAY_AREA_2D, 0.1)
            steps = int(min(200, max(2, 2e5 / max(rate * dt, 1e-300))))
            q = (v, dt) in ((1e-6, 1.0), (1.0, 1e-3), (1e4, 1e-6), (1e4, 1.0), (1e2, 1e-3))

            def build(v=v):
                c = gas(8, radius=0.1, packing=8 * math.pi * 0.01 / 8.0, speed=v, seed=4)
                return c

            add(f"gas8 v={v:g} dt={dt:g}", "speed x dt", build, dt, steps * dt, rate, q=q, speed=v)
    # radius: a gas of 4 (3 at r = 0.5), speed 1
    for r in (1e-4, 1e-3, 1e-2, 0.1, 0.5):
        n = 3 if r >= 0.5 else 4
        for dt in (1e-3, 0.1):

            def build_sized(r=r, n=n):
                c = gas(n, radius=r, packing=n * math.pi * r * r / 8.0, speed=1.0, seed=6)
                return c

            add(
                f"gas{n} r={r:g} dt={dt:g}",
                "radius",
                build_sized,
                dt,
                5.0,
                _box_rate(n, 1.0, PLAY_AREA_2D, r),
                q=(dt == 0.1 and r in (1e-4, 0.5)),
                radius=r,
            )
    # mass ratio: Galperin's billiard (count must be exact) and a heavy ball in a gas
    for digits in (1, 2, 3, 4, 5, 6):
        for dt in (1e-3, 1.0):
            if digits == 6 and dt < 1:
                continue  # the 3.1 million collisions happen within microseconds: one step size is enough
            add(
                f"pi billiard 1e{2 * digits} dt={dt:g}",
                "mass ratio",
                lambda d=digits: pi_billiard(2, d),
                dt,
                12.0 if digits < 4 else 8.0,
                0.0,
                _check_pi(digits),
                q=(digits in (2, 6) and dt == 1.0) or (digits == 3 and dt == 1e-3),
                cap=pi_collisions(digits) + 10_000,
                ratio=100.0**digits,
            )
    for ratio in (1e3, 1e6, 1e9, 1e12):
        for e in (1.0, 0.5):
            add(
                f"heavy in gas 1e{round(math.log10(ratio))} e={e:g}",
                "mass ratio",
                lambda ratio=ratio, e=e: _mass_gas(ratio, e),
                0.01,
                20.0,
                _box_rate(4, 1.0, PLAY_AREA_2D, 0.2),
                q=(ratio == 1e12),
                ratio=ratio,
                e=e,
            )
    # restitution: pile-up into a wall, a 2D gas cooling, stick clusters
    for e in (0.0, 0.05, 0.5, 1.0):
        for dt in (0.01, 1.0):
            add(
                f"pile-up 8 e={e:g} dt={dt:g}",
                "restitution",
                lambda e=e: inelastic_pileup(8, e),
                dt,
                4.0,
                _box_rate(8, 1.5, PLAY_AREA_1D, 0.1) * 10,
                q=(dt == 0.01 and e in (0.0, 0.05)),
                e=e,
            )
        add(
            f"gas16 cooling e={e:g}",
            "restitution",
            lambda e=e: gas(16, radius=0.1, packing=0.4, speed=1.0, seed=7, elasticity=e),
            0.05,
            20.0,
            _box_rate(16, 1.0, (-1, -0.5, 1, 0.5), 0.1) * 10,
            q=(e == 0.05),
            e=e,
        )
    add("gas16 stick e=0", "restitution", lambda: _stuck_gas(16), 0.05, 20.0, 2e3, q=True, e=0.0)
    add("stuck pair into corner", "restitution", _stuck_pair_corner, 0.01, 5.0, 100.0, e=0.0)
    for ratio in (1e6, 1e12):
        add(
            f"pi geometry 1e{round(math.log10(ratio))} e=0.05",
            "mass ratio",
            lambda ratio=ratio: _inelastic_pi(ratio, 0.05),
            0.01,
            8.0,
            1e3,
            q=ratio == 1e6,
            ratio=ratio,
            e=0.05,
        )
    # a touching row of alternating light and heavy balls: each light ball then rattles between two
    # heavy ones, ~pi sqrt(ratio) collisions per squeeze (1e9 already gives 4e7 events in 3 s, so the
    # grid stops at 1e6 here; the pi billiard covers 1e12)
    add("touching cradle 1:1e6", "mass ratio", lambda: _heavy_cradle(1e6), 0.01, 3.0, 0.0, cap=100_000, ratio=1e6)
    # control step on PhET's Explore 2D scene
    from .scenes import explore_2d

    for dt in (1e-6, 1e-4, 1e-2, 1.0):
        add(f"explore_2d 4 dt={dt:g}", "dt", lambda: explore_2d(4), dt, min(2000 * dt, 50.0), 20.0, q=dt in (1e-6, 1.0))
    # long episodes: a lone ball (analytic position), PhET's four balls, an inelastic gas
    lone = _case(Scene(bounds=PLAY_AREA_2D), [[0.3, -0.2]], [[0.7, 0.45]], [1.0], [0.15])
    for t_end, dt in ((1e4, 1.0), (1e5, 1.0), (1e5, 100.0)):
        add(
            f"lone ball T={t_end:g} dt={dt:g}",
            "long",
            lambda: lone,
            dt,
            t_end,
            2.0,
            _check_lone(lone, t_end),
            q=(t_end, dt) == (1e4, 1.0),
            T=t_end,
        )
    tiny = _case(Scene(bounds=PLAY_AREA_2D), [[0.3, -0.2]], [[7000.0, 4500.0]], [1.0], [1e-4])
    add("lone tiny ball v=8e3 r=1e-4 T=100", "long", lambda: tiny, 1.0, 100.0, 1e4, _check_lone(tiny, 100.0), T=100.0)
    add("explore_2d 4 T=1e5 dt=100", "long", lambda: explore_2d(4), 100.0, 1e5, 20.0, q=False, T=1e5)
    add(
        "gas16 e=0.5 T=1e5 dt=100",
        "long",
        lambda: gas(16, radius=0.1, packing=0.4, speed=1.0, seed=7, elasticity=0.5),
        100.0,
        1e5,
        2e3,
        T=1e5,
    )
    # touching at the start
    for e in (1.0, 0.5, 0.05, 0.0):
        chk = _check_cradle(5) if e == 1.0 else None
        add(
            f"cradle 5 touching e={e:g}",
            "touching",
            lambda e=e: _cradle(5, e),
            0.01,
            1.0,
            100.0,
            chk,
            q=e in (1.0, 0.05),
            e=e,
        )
        add(
            f"train on wall 5 e={e:g}",
            "touching",
            lambda e=e: _train_on_wall(5, e),
            0.01,
            2.0,
            1e3,
            q=e in (0.0, 0.05),
            e=e,
        )
        add(f"wall touch pair e={e:g}", "touching", lambda e=e: _wall_touch(e), 0.01, 3.0, 100.0, q=e == 1.0, e=e)
        add(f"wedged 2r=H-2e-6 e={e:g}", "touching", lambda e=e: _wedged(e, 2e-6), 0.01, 2.0, 3e5, q=e == 1.0, e=e)
    for e in (1.0, 0.05, 0.0):
        add(f"hex pack 19 touching e={e:g}", "touching", lambda e=e: _hex_pack(e), 0.01, 3.0, 1e4, q=e == 0.05, e=e)
    add("hex pack 19 touching stick", "touching", lambda: _hex_pack(0.0, "stick"), 0.01, 3.0, 1e4, e=0.0)
    add(
        "train on wall 5 stick",
        "touching",
        lambda: _train_on_wall(5, 0.0, inelastic="stick"),
        0.01,
        2.0,
        1e3,
        q=True,
        e=0.0,
    )
    # exact corner hits, simultaneous wall + ball, sliding along a wall
    for e in (1.0, 0.5, 0.05, 0.0):
        add(
            f"corner hit e={e:g}",
            "corner",
            lambda e=e: _corner(e),
            0.6,
            0.6,
            10.0,
            _check_corner(e),
            q=e in (1.0, 0.0),
            e=e,
        )
        add(
            f"ball+wall same instant e={e:g}", "corner", lambda e=e: _simultaneous(e), 0.01, 3.0, 100.0, q=e == 1.0, e=e
        )
        add(f"slide along wall e={e:g}", "grazing", lambda e=e: _slide(e), 0.01, 3.0, 10.0, q=e == 1.0, e=e)
    # grazing ball-ball contacts (free space)
    for delta, hit in ((1e-3, True), (1e-8, True), (1e-12, True), (0.0, False), (-1e-12, False)):
        add(
            f"graze 1-{delta:g}",
            "grazing",
            lambda d=delta: _two_ball_graze(d),
            0.013,
            2.0,
            10.0,
            _check_graze(hit),
            q=delta in (1e-12, 0.0),
            delta=delta,
        )
    _add_robustness_cells(add)
    _add_spanning_cells(add)
    _add_state_cells(add)
    _add_input_cells(add)
    return [c for c in out if c.quick] if quick else out


# --------------------------------------------------------------------------- robustness cells
# Squeezed mass ratios, a scene far from the origin, a million-step clock, slow pairs beside a fast
# ball, inputs at the edge of float64 and boxes with no room: each cell is a scene the engine must
# run, and where an input must be refused instead, its check makes sure that it is, with a message
# naming the ball and the field.
def _squeeze(ratio, e):
    """A ball ``ratio`` times heavier presses a light ball at rest against the left wall; 1D."""
    return _case(
        Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1),
        [[-1.9, 0.0], [-1.5, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        [1.0, ratio],
        [0.1, 0.1],
    )


def _check_squeeze(t_end):
    """The clock reached the end, and the heavy ball stopped against the light one (the cascade's limit)."""

    def check(sim, count, impacts):
        if abs(sim.time - t_end) > 1e-12 * t_end:
            return f"clock at {sim.time!r} s, expected {t_end:g} s"
        v = float(np.abs(sim.velocities[1]).max())
        return None if v <= 1e-6 else f"heavy ball still at {v:.3g} m/s against the wall"

    return check


def _shifted(case, offset):
    """``case`` translated by ``offset`` m along x (and y in 2D), border included."""
    b = case.scene.bounds
    dy = offset if case.scene.dimension == 2 else 0.0
    scene = Scene(
        bounds=(b[0] + offset, b[1] + dy, b[2] + offset, b[3] + dy),
        elasticity=case.scene.elasticity,
        dimension=case.scene.dimension,
    )
    return Case(scene, case.positions + np.array([offset, dy]), *case[2:])


def _near_wall(e):
    """Ball 0 rests 0.5 mm from the left wall; ball 1 hits it, and only then does it reach the wall; 1D."""
    return _case(
        Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1),
        [[-1.8995, 0.0], [-1.0, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        [1.0, 1.0],
        [0.1, 0.1],
    )


def _three_balls(e: float) -> Case:
    return _case(
        Scene(bounds=PLAY_AREA_2D, elasticity=e),
        [[-1.2, -0.4], [0.0, 0.3], [1.1, -0.2]],
        [[0.9, 0.4], [-0.3, -0.8], [-0.7, 0.5]],
        [1.0, 2.0, 0.5],
        [0.2, 0.25, 0.15],
    )


def _run_exact(case: Case, dt: float, duration: float) -> tuple[np.ndarray, Simulator]:
    """The impacts of ``case`` in exact mode over ``duration`` (steps of ``dt``) and the final simulator."""
    sim = Simulator(*case, mode="exact")
    rows = [sim.batch.step(dt).array for _ in range(max(1, int(round(duration / dt))))]
    return np.concatenate(rows), sim


def _check_translation(case, dt, duration):
    """The same impacts (who and when, within the coordinates' round-off) as the scene at the origin."""

    def check(sim, count, impacts):
        want, _ = _run_exact(case, dt, duration)
        if impacts is None or len(impacts) != len(want):
            return f"{count} impacts, {len(want)} at the origin"
        if not all(np.array_equal(impacts[k], want[k]) for k in ("ball", "other", "wall")):
            return "another impact sequence than at the origin"
        worst = float(np.max(np.abs(impacts["time"] - want["time"]), initial=0.0))
        return None if worst <= 1e-8 else f"impact times off those at the origin by up to {worst:.3g} s"

    return check


def _check_clock(case, dt, steps):
    """The clock is the correctly rounded sum of the steps (within 2 ulps) and the impacts are on time."""
    lone = _check_lone(case, dt * steps)

    def check(sim, count, impacts):
        exact = math.fsum([dt] * steps)
        if abs(sim.time - exact) > 2 * math.ulp(exact):
            return f"clock {sim.time!r} s off the exact sum {exact!r} s by {sim.time - exact:.3g} s"
        return lone(sim, count, impacts)

    return check


def _slow_pair(e, fast):
    """A pair closing at 2e-9 m/s in the middle of the box, and ball 2 far off at ``fast`` m/s."""
    r = 0.1
    return _case(
        Scene(bounds=None, elasticity=e),
        [[-r - 1e-9, 0.0], [r + 1e-9, 0.0], [5.0, 5.0]],
        [[1e-9, 0.0], [-1e-9, 0.0], [fast, fast]],
        [1.0, 1.0, 1.0],
        [r, r, r],
    )


def _check_slow_pair(e, dt, duration):
    """The pair ends as it would alone: separating at ``e`` times its closing speed, no energy gained."""

    def check(sim, count, impacts):
        _, alone = _run_exact(_slow_pair(e, 0.0), dt, duration)
        if not np.array_equal(sim.velocities[:2], alone.velocities[:2]):
            return f"the pair's velocities {sim.velocities[:2, 0].tolist()} depend on the far ball"
        v = sim.velocities[:2, 0]
        want = np.array([-e * 1e-9, e * 1e-9])
        ok = np.allclose(v, want, rtol=1e-6, atol=1e-9 * 1e-9)
        return None if ok else f"the pair separates at {v.tolist()} m/s, expected {want.tolist()}"

    return check


def _refuses(build, match, error: type[Exception] = ValueError):
    """A check that the input ``build()`` makes is refused with an ``error`` saying ``match``."""

    def check(sim, count, impacts):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DeprecationWarning)  # (a dict state: still taken, with one)
                build()
        except error as err:
            return None if match in str(err) else f"refused with another message: {err}"
        return f"accepted an input that should be refused ({match})"

    return check


def _refused_untouched(make, match):
    """A check that ``target.set_state(bad)``, ``(target, bad) = make(mode)`` for the mode of the
    cell's run, is refused saying ``match``, and leaves ``target``'s state exactly as it was."""

    def check(sim, count, impacts):
        from gymnasium.utils.env_checker import data_equivalence

        target, bad = make(sim.mode)
        before = target.get_state()
        message = _refuses(lambda: target.set_state(bad), match)(sim, count, impacts)
        same = data_equivalence(dict(before), dict(target.get_state()), exact=True)
        return message or (None if same else "a refused set_state changed the state")

    return check


def _light_ball(mass):
    return _case(
        Scene(bounds=PLAY_AREA_2D), [[-1.0, 0.1], [1.0, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [mass, 1.0], [0.1, 0.1]
    )


def _fast_pair(speed):
    return _case(Scene(bounds=None), [[-1.0, 0.05], [1.0, 0.0]], [[speed, 0.0], [-speed, 0.0]], [1.0, 1.0], [0.1, 0.1])


def _tiny_radius(radius):
    """A ball of ``radius`` in PhET's box, bouncing; another ball crossing its path."""
    return _case(
        Scene(bounds=PLAY_AREA_2D), [[0.0, 0.0], [1.0, 0.5]], [[1.0, 0.5], [-0.5, -0.25]], [1.0, 1.0], [radius, 0.1]
    )


def _add_robustness_cells(add):
    for exponent in (12, 13, 15, 18):
        for e in (0.0, 0.5):
            add(
                f"squeeze 1e{exponent} e={e:g}",
                "mass ratio",
                lambda r=10.0**exponent, e=e: _squeeze(r, e),
                0.5,
                1.5,
                0.0,
                _check_squeeze(1.5),
                q=exponent == 15 and e == 0.0,
                cap=2000,
                ratio=10.0**exponent,
                e=e,
            )
    for e in (0.5, 0.0):
        near = _near_wall(e)
        add(
            f"near wall 0.5 mm offset 1e6 e={e:g}",
            "offset",
            lambda c=near: _shifted(c, 1e6),
            0.1,
            1.2,
            10.0,
            _check_translation(near, 0.1, 1.2),
            q=e == 0.5,
            e=e,
            offset=1e6,
        )
    for e in (1.0, 0.5):
        three = _three_balls(e)
        add(
            f"3 balls offset 1e6 e={e:g}",
            "offset",
            lambda c=three: _shifted(c, 1e6),
            0.1,
            2.0,
            10.0,
            _check_translation(three, 0.1, 2.0),
            e=e,
            offset=1e6,
        )
    lone = _case(Scene(bounds=PLAY_AREA_2D), [[0.3, -0.2]], [[0.7, 0.45]], [1.0], [0.15])
    add(
        "lone ball 1e6 steps dt=1/60",
        "long",
        lambda: lone,
        1 / 60,
        1e6 / 60,
        2.0,
        _check_clock(lone, 1 / 60, 10**6),
        T=1e6 / 60,
    )
    for e in (0.5, 0.0):
        add(
            f"slow pair beside 1e3 m/s e={e:g}",
            "restitution",
            lambda e=e: _slow_pair(e, 1e3),
            0.5,
            1.0,
            10.0,
            _check_slow_pair(e, 0.5, 1.0),
            q=e == 0.5,
            e=e,
        )
    add(
        "mass 1e-300 kg",
        "overflow",
        lambda: _light_ball(1e-300),
        0.01,
        2.0,
        10.0,
        _refuses(lambda: Simulator(*_light_ball(1e-310)), "ball 0: mass must be positive and finite, with a finite"),
        q=True,
        ratio=1e300,
    )
    add(
        "speed 1e100 m/s",
        "overflow",
        lambda: _fast_pair(1e100),
        2e-101,
        2e-100,
        10.0,
        _refuses(lambda: Simulator(*_fast_pair(1e200)), "ball 0: velocity must be finite, speed within"),
        speed=1e100,
    )
    add(
        "no border dt=1e140",
        "overflow",
        lambda: _fast_pair(1.0),
        1e140,
        1e140,
        1.0,
        _refuses(lambda: Simulator(*_fast_pair(1e10)).step(1e145), "dt: a step of 1e+145 s would take ball"),
        q=True,
        cap=100,
    )
    add(
        "radius 1e-10 m",
        "overflow",
        lambda: _tiny_radius(1e-10),
        0.01,
        2.0,
        10.0,
        _refuses(lambda: Simulator(*_tiny_radius(1e-12)), "ball 0: radius 1e-12 m is too small"),
        radius=1e-10,
    )
    for e in (1.0, 0.5, 0.0):
        add(
            f"no room 2r=H vy>0 e={e:g}",
            "touching",
            lambda e=e: _wedged(e, 1e-3),
            0.01,
            2.0,
            2e3,
            _refuses(lambda e=e: Simulator(*_wedged(e, 0.0)), "ball 0: radius 1 m leaves no room to move"),
            q=e == 1.0,
            e=e,
        )


# --------------------------------------------------------------------------- spanning the box
# Touching balls that reach from a wall to the opposite one are jammed between them (a row or a
# square lattice cannot move along that axis at all), so every state with them is refused (where a
# state enters: the constructor, set_state, set_balls, env resets). Each cell runs the same row or
# lattice with room to move (gaps between the balls and at the walls), which the clock must get
# through, and checks that the touching one is refused.
_SPAN_BOX = {0: (-1.0, -2.0, 1.0, 2.0), 1: (-2.0, -1.0, 2.0, 1.0)}  # 2 m along the spanning axis


def _spanning(shape, axis, e, gap):
    """``shape = (along, across)`` balls in a square lattice (a row: across = 1) whose ``along``
    balls fill the 2 m of ``axis`` but for ``gap``, centred, their radii ``gap / 2`` short of
    touching (gap 0: touching each other and the walls), moving as one block (lattice) or each its
    own way (row); equal radii, masses 1 to 3 kg."""
    along, across = shape
    r = (2.0 - gap) / (2 * along)
    k_along, k_across = np.meshgrid(np.arange(along), np.arange(across), indexing="ij")
    u = (2 * k_along.ravel() + 1 - along) * r  # touching along the axis, centred
    w = (2 * k_across.ravel() + 1 - across) * r
    pos = np.stack([u, w], 1) if axis == 0 else np.stack([w, u], 1)
    n = len(pos)
    rng = np.random.default_rng(7)
    vel = np.tile([0.3, 0.2], (n, 1)) if across > 1 else rng.uniform(-1.0, 1.0, (n, 2))
    masses = 1.0 + 2.0 * rng.random(n)
    return _case(Scene(bounds=_SPAN_BOX[axis], elasticity=e), pos, vel, masses, np.full(n, r * (1.0 - gap / 2)))


def _check_clock_reaches(t_end):
    def check(sim, count, impacts):
        return None if abs(sim.time - t_end) <= 1e-12 * t_end else f"clock at {sim.time!r} s, expected {t_end:g} s"

    return check


def _check_all(*checks):
    def check(sim, count, impacts):
        return next((m for m in (c(sim, count, impacts) for c in checks) if m), None)

    return check


def _add_spanning_cells(add):
    for axis in (0, 1):
        for shape in ((2, 1), (3, 1), (3, 3), (8, 8), (64, 64)):
            kind = f"row of {shape[0]}" if shape[1] == 1 else f"{shape[0]}x{shape[1]} lattice"
            for e in (1.0, 0.5, 0.0):
                add(
                    f"{kind} spans {'xy'[axis]} e={e:g}",
                    "spanning",
                    lambda shape=shape, axis=axis, e=e: _spanning(shape, axis, e, 0.1),
                    0.05,
                    0.5,
                    2e3 * shape[0] * shape[1],
                    _check_all(
                        _check_clock_reaches(0.5),
                        _refuses(
                            lambda shape=shape, axis=axis, e=e: Simulator(*_spanning(shape, axis, e, 0.0)),
                            f"leaves no room to move along {'xy'[axis]}",
                        ),
                    ),
                    q=shape == (3, 1) and e == 0.0,
                    e=e,
                    balls=shape[0] * shape[1],
                )


def _bad_state(field):
    """A three-ball simulator and its state with ``field`` made bad (as the constructor would refuse
    it; "spanning": three touching balls from the left wall to the right one)."""
    sim = Simulator(*_three_balls(1.0))
    state = sim.get_state()
    bads: dict[str, dict[str, Any]] = {
        "masses": dict(masses=[-1.0, 2.0, 0.5]),
        "radii": dict(radii=[0.0, 0.25, 0.15]),
        "overlap": dict(positions=[[-1.2, -0.4], [-1.1, -0.4], [1.1, -0.2]]),
        "outside": dict(positions=[[-2.5, -0.4], [0.0, 0.3], [1.1, -0.2]]),
        "velocity 1e200": dict(velocities=[[1e200, 0.0], [0.0, 0.0], [0.0, 0.0]]),
        "clusters": dict(clusters=[0, 1, 3]),
        "time 1e300": dict(time=1e300),
        "time compensation": dict(time_compensation=1.0),
        "spanning": dict(positions=[[-4 / 3, 0.0], [0.0, 0.0], [4 / 3, 0.0]], radii=[2 / 3] * 3),
    }
    return sim, state.replace(**{key: np.asarray(value) for key, value in bads[field].items()})


def _add_state_cells(add):
    messages = {
        "masses": "ball 0: mass must be positive",
        "radii": "ball 0: radius must be positive",
        "overlap": "ball 0: position overlaps ball 1",
        "outside": "ball 0: position must keep the ball inside",
        "velocity 1e200": "ball 0: velocity must be finite, speed within",
        "clusters": "state clusters: ball 2",
        "time 1e300": "state time: must be finite and at most",
        "time compensation": "state time_compensation: must be within an ulp",
        "spanning": "ball 0: position leaves no room to move along x",
    }

    for name, match in messages.items():
        add(
            f"set_state {name}",
            "set_state",
            lambda: _three_balls(1.0),
            0.1,
            0.2,
            10.0,
            _refused_untouched(lambda mode, name=name: _bad_state(name), match),
            q=name == "velocity 1e200",
        )
    for mode in ("naive", "posteriori"):
        add(
            f"{mode} substeps=1e9",
            "overflow",
            lambda: _three_balls(1.0),
            0.01,
            0.02,
            10.0,
            _refuses(
                lambda mode=mode: Simulator(*_three_balls(1.0), mode=mode, substeps=10**9), "substeps: must be at most"
            ),
            q=mode == "naive",
        )


# --------------------------------------------------------------------------- refusals and round trips
# Every way in besides the constructor: engine and env states (a refusal names the field
# and changes nothing; a state goes back bit for bit), env configs, impacts' indices, compression
# and the observables. Each cell steps the three balls once in the mode, then makes its check there.
def _stick_cluster_apart(mode):
    """A stick simulator in ``mode`` and its state with ball 2, 1 m from a touching pair, glued to it."""
    scene = Scene(bounds=PLAY_AREA_2D, elasticity=0.0, inelastic="stick")
    pos = [[-0.25, 0.0], [0.25, 0.0], [1.65, 0.0]]
    sim = Simulator(scene, pos, [[0.0, 0.0]] * 3, [1.0, 1.0, 1.0], [0.25, 0.25, 0.15], mode=mode)
    glued = dict(clusters=np.zeros(3, dtype=np.int64), velocities=np.tile([0.3, 0.0], (3, 1)), omega=np.zeros(3))
    return sim, sim.get_state().replace(**glued)


def _unknown_key(mode):
    """A periodic simulator whose balls crossed the cell, and its state with ``images`` misspelt."""
    sim = Simulator(Scene(periodic=True), [[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0]], [1.0, 1.0], mode=mode)
    sim.step(3.0)
    state = dict(sim.get_state())
    state["image"] = state.pop("images")
    return sim, state


def _round_trip_past_the_edge(past):
    """A check that a position ``past`` m outside a periodic cell goes back bit for bit."""

    def check(sim, count, impacts):
        scene = Scene(periodic=True)
        assert scene.bounds is not None  # (a periodic cell has bounds: PhET's box by default)
        edge = scene.bounds[2] if past > 0 else scene.bounds[0]
        twin = Simulator(scene, [[0.0, 0.0], [1.0, 0.3]], [[0.7, 0.2], [-0.3, 0.1]], [1.0, 2.0], mode=sim.mode)
        positions = np.array(twin.positions)
        positions[0] = (edge + past, 0.0)
        state = twin.get_state().replace(positions=positions)
        twin.set_state(state)
        return None if twin.get_state() == state else "the state did not go back bit for bit"

    return check


def _env(mode, steps=3, **config):
    """A stepped generic env in ``mode`` whose task reads every field of its state."""
    import gymnasium as gym

    env = gym.make("CollisionEnv/Target-v0", mode=mode, n_balls=3, shaping=1.0, window=5.0, **config).unwrapped
    env.reset(seed=7)
    env.action_space.seed(7)
    for _ in range(steps):
        env.step(env.action_space.sample())
    return env


def _bad_env_state(field, column, value):
    """``make(mode)``: a stepped env and its state with one task value changed (target or scene 0)."""
    from collision_env.envs.task import layout

    def make(mode):
        env = _env(mode)
        state = env.get_state()
        core = state["core"]
        if field == "target_geo":
            core[field][0, 0, getattr(layout.TARGET_GEOMETRY, column)] = value
        else:
            core[field][0, getattr(layout.SCENE_FLOATS if field == "scene_f" else layout.SCENE_INTS, column)] = value
        return env, state

    return make


def _check_env_round_trip(sim, count, impacts):
    """An env's state goes back bit for bit: the same 30 steps after set_state(get_state())."""
    from gymnasium.utils.env_checker import data_equivalence

    env = _env(sim.mode)
    state = env.get_state()
    actions = [env.action_space.sample() for _ in range(30)]
    first = [env.step(a) for a in actions]
    env.set_state(state)
    second = [env.step(a) for a in actions]
    return None if data_equivalence(first, second, exact=True) else "the steps after set_state differ"


def _box_packing(sim, count, impacts):
    """A box compressed to Z = 1e9 (its touching disks spanned the box) is a state the engine takes."""
    from collision_env.engine import compress, disk_gas

    gas = disk_gas(30, 0.3, arrangement="random", diameters=(1.0, 1.4), seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        packing = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_pressure=1e9, seed=0, progress=False)
    if not math.isfinite(packing.reduced_pressure):
        return f"reduced pressure {packing.reduced_pressure}"
    packing.gas().simulator(mode=sim.mode)  # (raises if the engine refuses it)
    return None


def _no_collision(sim, count, impacts):
    """Two disks side by side in a periodic cell, never growing, never meet: Z = 1 (it was NaN)."""
    from collision_env.engine import compress

    scene = Scene(bounds=(0.0, 0.0, 10.0, 10.0), periodic=True)
    pos, vel = [[2.0, 2.0], [2.0, 6.0]], [[1.0, 0.0], [1.0, 0.0]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        packing = compress(scene, pos, [0.5, 0.5], velocities=vel, rate=0.0, progress=False)
    return None if packing.reduced_pressure == 1.0 else f"Z = {packing.reduced_pressure} without a collision"


def clumped_rdf_peak_bytes() -> int:
    """Peak memory (bytes, tracemalloc) of ``radial_distribution`` over 2,600 points, 600 of them in
    one 0.5 m patch of a 100 m box (it took 1.8 GB on d8ab1a0: cells x the fullest cell's count^2).
    The extremes cell below and ``tests/observables/test_structure.py`` both measure it."""
    import tracemalloc

    from collision_env.observables import radial_distribution

    rng = np.random.default_rng(0)
    p = rng.uniform(0.0, 100.0, size=(2600, 2))
    p[:600] = rng.uniform(50.0, 50.5, size=(600, 2))
    tracemalloc.start()
    try:
        radial_distribution(p, (0.0, 0.0, 100.0, 100.0), 2.0, bins=40)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _clumped_rdf(sim, count, impacts):
    """g(r) of a clump within 50 MB (:func:`clumped_rdf_peak_bytes`)."""
    peak = clumped_rdf_peak_bytes()
    return None if peak < 50e6 else f"peak memory {peak / 1e6:.0f} MB"


def _add_input_cells(add):
    from collision_env import observables
    from collision_env.engine import compress, disk_gas
    from collision_env.envs import make_config

    def cell(name, group, check, q=False):
        add(name, group, lambda: _three_balls(1.0), 0.1, 0.1, 10.0, check, q=q)

    cell(
        "set_state stick cluster 1 m apart",
        "set_state",
        _refused_untouched(_stick_cluster_apart, "ball 2: does not touch the rest of its stick cluster"),
        q=True,
    )
    cell(
        "set_state unknown key 'image'",
        "set_state",
        _refused_untouched(_unknown_key, "unknown key(s) 'image' (did you mean 'images'"),
    )
    for past in (1.6e-15, -1.6e-15):
        cell(f"set_state {past:g} m past the cell", "round trip", _round_trip_past_the_edge(past))
    env_cases = {
        "current target -5": ("scene_i", "current", -5, "scene_i current: must be a target index"),
        "NaN phi": ("scene_f", "phi", math.nan, "scene_f phi: must be from -1 to 0"),
        "NaN target centre": ("target_geo", "centre", math.nan, "target_geo centre: target 0: must be finite"),
    }
    for name, (array, column, value, match) in env_cases.items():
        cell(f"env set_state {name}", "env state", _refused_untouched(_bad_env_state(array, column, value), match))

    def misspelt(mode):
        env = _env(mode)
        state = env.get_state()
        state["core"]["target_geometry"] = state["core"].pop("target_geo")
        return env, state

    cell(
        "env set_state unknown key",
        "env state",
        _refused_untouched(misspelt, "unknown key(s) 'target_geometry' (did you mean 'target_geo'?)"),
    )
    cell("env get_state/set_state", "round trip", _check_env_round_trip, q=True)
    for name, value, match in (
        ("max_dv", 1e300, "max_dv: must be <= 1e+150"),
        ("dt", 1e-300, "time_limit: 10 s in control steps of dt = 1e-300 s"),
        ("max_events", 10**20, "max_events: must be <="),
    ):
        cell(f"env {name}={value:g}", "env config", _refuses(lambda n=name, v=value: make_config(**{n: v}), match))

    def impacts_of_a_step():
        return Simulator(*_three_balls(1.0)).step(2.0)

    for key in (None, True):
        cell(
            f"impacts[{key}]",
            "impacts",
            _refuses(lambda k=key: impacts_of_a_step()[k], "impacts: index with an integer", TypeError),
        )
    cell("compress a box to Z = 1e9", "compress", _box_packing)
    cell("compress without a collision", "compress", _no_collision)
    gas = disk_gas(12, 0.3, arrangement="random", seed=0)
    for name, scene, match in (
        ("e = 0.5", Scene(bounds=gas.scene.bounds, elasticity=0.5), "compress bounces the disks elastically"),
        ("stick", Scene(bounds=gas.scene.bounds, elasticity=0.0, inelastic="stick"), "use Scene(elasticity=1.0)"),
    ):
        compressed = lambda sc=scene: compress(sc, gas.positions, gas.radii, progress=False)  # noqa: E731
        cell(f"compress {name}", "compress", _refuses(compressed, match))
    cell("g(r) of a clump", "observables", _clumped_rdf)
    for name, call, match in (
        ("henderson_g(1)", lambda: observables.henderson_g(1.0), "packing: an area fraction"),
        ("henderson_g(2)", lambda: observables.henderson_g(2.0), "packing: an area fraction"),
        ("MSD lag 1.5", lambda: observables.mean_squared_displacement(np.zeros((5, 3, 2)), lags=[1.5]), "lags:"),
        (
            "NaN radius",
            lambda: observables.reduced_pressure(impacts_of_a_step(), [0.2, np.nan, 0.15], 2.0, 1.0, scene=Scene()),
            "radii: ball 1's radius must be finite and > 0",
        ),
    ):
        cell(name, "observables", _refuses(call, match))


# --------------------------------------------------------------------------- running a cell
def _escape_depth(pos, radii, bounds, dim):
    if bounds is None:
        return 0.0
    xmin, ymin, xmax, ymax = bounds
    depth = np.maximum(xmin + radii - pos[:, 0], pos[:, 0] - (xmax - radii))
    if dim == 2:
        depth = np.maximum(depth, np.maximum(ymin + radii - pos[:, 1], pos[:, 1] - (ymax - radii)))
    scale = TOL * (radii + np.abs(pos).max(1))
    return float(np.max(depth - scale))


def _overlap_depth(pos, radii):
    n = len(radii)
    if n < 2:
        return -math.inf
    d = np.sqrt(((pos[:, None, :] - pos[None, :, :]) ** 2).sum(-1))
    sigma = radii[:, None] + radii[None, :]
    excess = sigma - d - (TOL * sigma + 1e-12 * np.abs(pos).max())
    iu = np.triu_indices(n, 1)
    return float(excess[iu].max())


def run_cell(cell: Cell, mode: str, substeps: int, budget: float) -> dict:
    """Run one cell in one mode; returns the row (status "pass" or the failure reasons)."""
    case = cell.build()
    reasons: list[str] = []
    details: list[str] = []
    sim = Simulator(
        case.scene,
        case.positions,
        case.velocities,
        case.masses,
        case.radii,
        mode=mode,
        substeps=substeps,
        max_events=cell.max_events,
    )
    radii = case.radii
    scene = case.scene
    check_pairs = scene.ball_collisions and len(radii) > 1 and len(radii) <= 64
    ke0 = sim.kinetic_energy()
    ke_prev = ke0
    count = 0
    keep: list[np.ndarray] | None = []
    kept = 0
    worst_step = 0.0
    engine_time = 0.0
    t0 = time.perf_counter()
    steps = cell.steps
    done = 0
    for k in range(steps):
        dt = cell.dt if k < steps - 1 else cell.duration - cell.dt * (steps - 1)
        s0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", EventCapWarning)
            rows = sim.batch.step(dt).array
        spent = time.perf_counter() - s0
        engine_time += spent
        worst_step = max(worst_step, spent)
        done += 1
        count += len(rows)
        if keep is not None:
            keep.append(rows)
            kept += len(rows)
            if kept > 100_000:
                keep = None
        pos, vel = sim.positions, sim.velocities
        if not (np.isfinite(pos).all() and np.isfinite(vel).all()):
            reasons.append("NaN")
            details.append(f"non-finite state at step {k}")
            break
        if "escape" not in reasons:
            depth = _escape_depth(pos, radii, scene.bounds, scene.dimension)
            if depth > 0:
                reasons.append("escape")
                details.append(f"escape by {depth:.3g} m at step {k}")
        if check_pairs and "overlap" not in reasons:
            depth = _overlap_depth(pos, radii)
            if depth > 0:
                reasons.append("overlap")
                details.append(f"overlap by {depth:.3g} m at step {k}")
        ke = sim.kinetic_energy()
        if "energy growth" not in reasons and (ke > ke0 * (1 + TOL) or ke > ke_prev * (1 + TOL)):
            reasons.append("energy growth")
            details.append(f"kinetic energy {ke / ke0 - 1:+.3g} relative at step {k}")
        ke_prev = ke
        if sim.cap_reached and "event cap" not in reasons:
            reasons.append("event cap")
            details.append(f"cap {cell.max_events} reached at step {k}")
        if engine_time > budget:
            if k < steps - 1:
                reasons.append("time limit")
                details.append(f"{done}/{steps} steps in {engine_time:.3g} s of stepping")
            break
    wall = time.perf_counter() - t0
    if cell.check is not None and not reasons:
        impacts = np.concatenate(keep) if keep else None
        msg = cell.check(sim, count, impacts)
        if msg:
            reasons.append("wrong")
            details.append(msg)
    ke = sim.kinetic_energy()
    return {
        "cell": cell.name,
        "group": cell.group,
        "mode": mode if substeps == 1 else f"{mode} k={substeps}",
        "status": "pass" if not reasons else ", ".join(reasons),
        "detail": "; ".join(details),
        "dt": cell.dt,
        "duration": cell.duration,
        "steps": done,
        "impacts": count,
        "max_events": cell.max_events,
        "wall_s": wall,
        "engine_s": engine_time,
        "worst_step_s": worst_step,
        "energy_change": (ke / ke0 - 1) if ke0 > 0 else 0.0,
    }


def repro(cell: Cell) -> str:
    """A minimal, self-contained Python snippet that replays ``cell`` in exact mode."""
    c = cell.build()
    steps = cell.steps
    return "\n".join(
        [
            "import numpy as np",
            "from collision_env.engine import Scene, Simulator",
            f"scene = {c.scene!r}",
            f"pos = np.array({c.positions.tolist()!r})",
            f"vel = np.array({c.velocities.tolist()!r})",
            f"mass = np.array({c.masses.tolist()!r})",
            f"radii = np.array({c.radii.tolist()!r})",
            f"sim = Simulator(scene, pos, vel, mass, radii, mode='exact', max_events={cell.max_events})",
            f"for k in range({steps}):",
            f"    sim.step({cell.dt!r})",
            "print(sim.positions, sim.velocities, sim.cap_reached, sim.kinetic_energy())",
        ]
    )


def run_extremes(
    quick: bool,
    budget: float | None = None,
    modes: Sequence[tuple[str, int]] = MODES,
    log: Callable[[str], None] = print,
) -> list[dict]:
    budget = budget if budget is not None else (5.0 if quick else 30.0)
    rows = []
    grid = cells(quick)
    for cell in grid:
        t0 = time.perf_counter()
        for mode, k in modes:
            rows.append(run_cell(cell, mode, k, budget))
        status = {r["mode"]: r["status"] for r in rows[-len(modes) :]}
        log(
            f"  {cell.name:34s} {time.perf_counter() - t0:6.2f} s  " + "  ".join(f"{m}: {s}" for m, s in status.items())
        )
    return rows


EXTREME_FIELDS = (
    "cell",
    "group",
    "mode",
    "status",
    "detail",
    "dt",
    "duration",
    "steps",
    "impacts",
    "max_events",
    "wall_s",
    "engine_s",
    "worst_step_s",
    "energy_change",
)


def extremes_markdown(rows: list[dict], quick: bool, budget: float) -> str:
    modes = list(dict.fromkeys(r["mode"] for r in rows))
    by_cell: dict = {}
    for r in rows:
        by_cell.setdefault((r["group"], r["cell"]), {})[r["mode"]] = r
    lines = [
        "## Extremes: stability over the stress grid",
        "",
        f"Generated by `python -m collision_env.bench.extremes{' --quick' if quick else ''}`: {len(by_cell)} cells, "
        f"each run in every mode with a wall-time budget of {budget:g} s per cell and mode. A cell passes when, after "
        "every step, no position or velocity is NaN, no ball sticks out of the border or into another ball "
        "(beyond 1e-9 relative), the kinetic energy never grows (beyond 1e-9 relative), the event cap is not "
        "reached and the budget is not exceeded, and (where the cell has one) the analytic answer is right.",
        "",
        "| mode | cells passed | failures by reason |",
        "|---|---:|---|",
    ]
    for m in modes:
        rs = [r for r in rows if r["mode"] == m]
        passed = sum(r["status"] == "pass" for r in rs)
        counts = {reason: sum(reason in r["status"].split(", ") for r in rs) for reason in REASONS}
        fails = ", ".join(f"{k}: {v}" for k, v in counts.items() if v) or "none"
        lines.append(f"| {m} | {passed} / {len(rs)} | {fails} |")
    lines += [
        "",
        "| group | cell | dt (s) | duration (s) | " + " | ".join(modes) + " |",
        "|---|---|---:|---:|" + "---|" * len(modes),
    ]
    for (group, name), per in by_cell.items():
        any_row = next(iter(per.values()))
        cells_ = []
        for m in modes:
            r = per.get(m)
            if r is None:
                cells_.append("")
            elif r["status"] == "pass":
                cells_.append("pass")
            else:
                cells_.append(f"**{r['status']}**")
        lines.append(f"| {group} | {name} | {any_row['dt']:g} | {any_row['duration']:g} | " + " | ".join(cells_) + " |")
    exact_fail = [r for r in rows if r["mode"] == "exact" and r["status"] != "pass"]
    lines += [""]
    if exact_fail:
        lines += ["**Exact mode fails cells** (an engine problem to fix, not a trade):", ""]
        lines += [
            f"- {r['cell']}: {r['status']} ({r['detail']}); replay it with "
            f"`python -m collision_env.bench.extremes --repro '{r['cell']}'`"
            for r in exact_fail
        ]
    else:
        lines.append("Exact mode passes every cell.")
    lines.append("")
    return "\n".join(lines)


def write_csv(path: str | Path, rows: list[dict], fields: Sequence[str]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in fields})


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.extremes", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a subset of the grid (about 15 s)")
    parser.add_argument("--out", default="docs/bench", help="output folder (default docs/bench)")
    parser.add_argument("--budget", type=float, default=None, help="wall-time budget per cell and mode (s)")
    parser.add_argument("--repro", metavar="CELL", help="print a repro snippet for the named cell and exit")
    args = parser.parse_args(argv)
    if args.repro:
        for c in cells(False):
            if c.name == args.repro:
                print(repro(c))
                return 0
        print(f"no cell named {args.repro!r}", file=sys.stderr)
        return 2
    from .sweep import warm_up

    warm_up()
    budget = args.budget if args.budget is not None else (5.0 if args.quick else 30.0)
    rows = run_extremes(args.quick, budget, log=lambda m: print(m, file=sys.stderr, flush=True))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "extremes.csv", rows, EXTREME_FIELDS)
    text = extremes_markdown(rows, args.quick, budget)
    (out / "extremes.md").write_text(text)
    print(text)
    return 1 if any(r["mode"] == "exact" and r["status"] != "pass" for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
