"""Analytic expected values for exact mode: closed-form collision times, velocities and counts."""

import math

import numpy as np
import pytest

from collision_env.engine import PLAY_AREA_1D, Scene, Simulator, radius_from_mass


def test_radius_rule_matches_phet():
    np.testing.assert_allclose(
        radius_from_mass([0.1, 0.5, 1.0, 1.5, 3.0]), [0.08803, 0.150524, 0.18965, 0.217093, 0.27352], atol=5e-6
    )


def test_phet_intro_head_on():
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5])
    np.testing.assert_allclose(sim.radii, [0.150524, 0.217093], atol=1e-6)
    impacts = sim.step(2.0)
    assert len(impacts) == 1
    hit = impacts[0]
    # contact when the gap 2 - (r1 + r2) closes at 1.5 m/s
    assert hit.time == pytest.approx((2.0 - sum(sim.radii)) / 1.5, rel=1e-14)
    assert hit.time == pytest.approx(1.088256, abs=1e-6)
    assert (hit.ball, hit.other, hit.wall) == (0, 1, None)
    np.testing.assert_allclose(sim.velocities, [[-1.25, 0], [0.25, 0]], atol=1e-14)


def test_equal_masses_head_on_swap_velocities():
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[2, 0], [-0.5, 0]], [1, 1])
    sim.step(3.0)
    np.testing.assert_allclose(sim.velocities, [[-0.5, 0], [2, 0]], atol=1e-14)


def test_oblique_keeps_tangential_parts():
    r = 0.1
    b = 0.6 * 2 * r  # impact parameter: sin(theta) = 0.6
    sim = Simulator(Scene(bounds=None), [[-1, 0], [0, b]], [[1, 0], [0, 0]], [1, 1], radii=[r, r])
    (hit,) = sim.step(2.0)
    v = sim.velocities
    n = np.array([math.sqrt(1 - 0.36), 0.6])  # line of centres at contact
    t = np.array([-n[1], n[0]])
    assert v[0] @ t == pytest.approx(np.array([1, 0]) @ t, abs=1e-14)
    assert v[1] @ t == pytest.approx(0.0, abs=1e-14)
    # equal masses, elastic, one at rest: outgoing directions are perpendicular
    assert v[0] @ v[1] == pytest.approx(0.0, abs=1e-14)
    assert np.linalg.norm(v[1]) == pytest.approx(math.sqrt(1 - 0.36), rel=1e-13)
    # the contact point lies on both circles
    p = sim.positions - sim.velocities * (sim.time - hit.time)
    assert np.linalg.norm(np.array(hit.point) - p[0]) == pytest.approx(r, rel=1e-12)
    assert np.linalg.norm(np.array(hit.point) - p[1]) == pytest.approx(r, rel=1e-12)


@pytest.mark.parametrize("e", [0.0, 0.05, 0.5, 0.9, 1.0])
@pytest.mark.parametrize("masses", [(0.5, 1.5), (1.0, 1e6), (3.0, 0.1)])
def test_energy_loss_and_momentum_per_collision(e, masses):
    m1, m2 = masses
    v1, v2 = np.array([1.2, 0.4]), np.array([-0.7, 0.1])
    sim = Simulator(Scene(bounds=None, elasticity=e), [[-1, -0.05], [1, 0.05]], [v1, v2], masses, radii=[0.2, 0.2])
    p0, e0 = sim.momentum(), sim.kinetic_energy()
    (hit,) = sim.step(3.0)
    p = sim.positions - sim.velocities * (sim.time - hit.time)
    n = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
    u = (v2 - v1) @ n
    mu = m1 * m2 / (m1 + m2)
    assert hit.speed == pytest.approx(-u, rel=1e-12)
    assert sim.kinetic_energy() - e0 == pytest.approx(-0.5 * (1 - e * e) * mu * u * u, rel=1e-9, abs=1e-15 * e0)
    np.testing.assert_allclose(sim.momentum(), p0, rtol=1e-12, atol=1e-12 * np.abs(p0).max())
    w = sim.velocities
    assert (w[1] - w[0]) @ n == pytest.approx(-e * u, abs=1e-12 * abs(u) * max(masses) / min(masses))


def _galperin(k, max_events):
    """A wall at x = 0 (left border), a light ball at rest, a heavy one coming in: floor(pi 10^k)."""
    scene = Scene(bounds=(0.0, -1.0, 1e9, 1.0), dimension=1)
    sim = Simulator(
        scene,
        [[1.0, 0.0], [2.0, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        [1.0, 100.0**k],
        radii=[0.1, 0.1],
        max_events=max_events,
    )
    count = 0
    for _ in range(100):
        count += len(sim.step(10.0))
    return count, sim


@pytest.mark.parametrize("k, expected", [(1, 31), (2, 314), (3, 3141), (4, 31415)])
def test_galperin_pi_billiard(k, expected):
    count, sim = _galperin(k, max_events=100_000)
    assert count == expected
    # all elastic: energy kept to round-off
    assert sim.kinetic_energy() == pytest.approx(0.5 * 100.0**k, rel=1e-11)
    assert not sim.cap_reached


def test_newtons_cradle_touching_train():
    r = 0.1
    xs = [-1.0] + [0.0 + 2 * r * k for k in range(5)]  # a hitter, then five touching balls
    pos = [[x, 0.0] for x in xs]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * 5
    sim = Simulator(Scene(bounds=None, dimension=1), pos, vel, [1.0] * 6, radii=[r] * 6)
    impacts = sim.step(1.0)
    assert [(i.ball, i.other) for i in impacts] == [(k, k + 1) for k in range(5)]
    np.testing.assert_allclose(sim.velocities[:, 0], [0, 0, 0, 0, 0, 1.0], atol=1e-15)
    assert sim.kinetic_energy() == pytest.approx(0.5, rel=1e-15)


def test_one_ball_in_box_returns_after_period():
    # free lengths 4 - 2r and 2 - 2r with r = 0.25: 3.5 and 1.5; vx, vy chosen so both periods are 7 s
    r = 0.25
    vx, vy = 2 * 3.5 / 7.0, 2 * 1.5 / 3.5
    sim = Simulator(Scene(), [[0.3, -0.2]], [[vx, vy]], [1.0], radii=[r])
    walls = []
    for _ in range(70):
        for hit in sim.step(0.1):
            walls.append(hit)
            x, y = hit.point
            assert {"left": x == -2.0, "right": x == 2.0, "bottom": y == -1.0, "top": y == 1.0}[hit.wall]
    np.testing.assert_allclose(sim.positions, [[0.3, -0.2]], atol=1e-13)
    np.testing.assert_allclose(sim.velocities, [[vx, vy]], atol=0)
    assert sorted(h.wall for h in walls) == ["bottom"] * 2 + ["left"] + ["right"] + ["top"] * 2


@pytest.mark.parametrize("e", [1.0, 0.7])
def test_time_reversal_returns_to_start(e):
    rng = np.random.default_rng(3)
    pos = np.array([[-1.5, -0.5], [-0.5, 0.4], [0.6, -0.3], [1.4, 0.5]])
    vel = rng.normal(size=(4, 2))
    sim = Simulator(Scene(elasticity=e), pos, vel, [0.5, 1.5, 1.0, 2.0])
    n_forward = sum(len(sim.step(0.05)) for _ in range(40))
    assert 4 <= n_forward <= 20  # a few collisions per ball: inside the chaos horizon
    for _ in range(40):
        sim.step(-0.05)
    np.testing.assert_allclose(sim.positions, pos, atol=1e-10)
    np.testing.assert_allclose(sim.velocities, vel, atol=1e-10)
    assert sim.time == pytest.approx(0.0, abs=1e-14)


def test_exact_corner_hit_reverses_both_components():
    r = 0.2
    start = np.array([1.0, 0.0])
    v = np.array([(2 - r - 1.0), (1 - r)]) / 0.8  # reaches (2 - r, 1 - r) at t = 0.8
    sim = Simulator(Scene(), [start], [v], [1.0], radii=[r])
    impacts = sim.step(1.0)
    assert [i.wall for i in impacts] == ["right", "top"]
    assert impacts[0].time == impacts[1].time == pytest.approx(0.8, rel=1e-14)
    np.testing.assert_allclose(sim.velocities[0], -v, atol=0)
    np.testing.assert_allclose(sim.positions[0], [2 - r, 1 - r] - 0.2 * v, atol=1e-14)


def test_border_off_balls_fly_on():
    sim = Simulator(Scene(bounds=None), [[1.9, 0.0]], [[1.0, 0.0]], [1.0])
    assert sim.step(1.0) == []
    assert sim.positions[0, 0] == pytest.approx(2.9)
    assert sim.stats["wall_tests"] == 0


def test_one_ball_scene_does_no_pair_work():
    sim = Simulator(Scene(), [[0.0, 0.0]], [[3.0, 1.0]], [1.0])
    for _ in range(50):
        sim.step(0.1)
    assert sim.models["ball_pairs"] is False
    assert sim.stats["pair_tests"] == 0 and sim.stats["wall_tests"] > 0


def test_ball_collisions_off_lets_balls_pass():
    sim = Simulator(Scene(bounds=None, ball_collisions=False), [[-1, 0], [1, 0]], [[1, 0], [-1, 0]], [1, 1])
    assert sim.step(2.0) == []
    np.testing.assert_allclose(sim.positions, [[1, 0], [-1, 0]])
    assert sim.stats["pair_tests"] == 0


def test_phet_explore_1d_defaults_conserve_momentum():
    xs = [-1.8, -0.1, 0.8, 1.3, 1.8]
    vs = [1, -0.5, -0.5, 1.1, -1.1]
    ms = [0.5, 1.5, 1.0, 1.0, 1.0]
    sim = Simulator(Scene(bounds=PLAY_AREA_1D, dimension=1), [[x, 0] for x in xs], [[v, 0] for v in vs], ms)
    e0 = sim.kinetic_energy()
    for _ in range(600):
        for hit in sim.step(1 / 60):
            if hit.wall is not None:
                assert hit.wall in ("left", "right")
    assert sim.kinetic_energy() == pytest.approx(e0, rel=1e-12)
    assert np.all(sim.positions[:, 1] == 0) and np.all(sim.velocities[:, 1] == 0)
    x, r = sim.positions[:, 0], sim.radii
    assert np.all(np.diff(x) >= (r[:-1] + r[1:]) * (1 - 1e-12))  # order kept, no overlap
