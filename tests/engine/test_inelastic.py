"""Inelastic physics: stick clusters, the collapse regulariser, the event cap, reverse with 1/e."""

import math
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine import PLAY_AREA_1D, EventCapWarning, Scene, Simulator

STICK = Scene(elasticity=0.0, inelastic="stick")


def angular_momentum(sim):
    m, p, v = sim.masses, sim.positions, sim.velocities
    com = (m[:, None] * p).sum(0) / m.sum()
    d = p - com
    return float((m * (d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0])).sum())


def test_stick_criss_cross_moves_as_one():
    sim = Simulator(STICK, [[-0.5, 0], [0.5, 0]], [[1, 0.5], [-1, 0.5]], [0.5, 0.5])
    hits = sim.step(0.5)
    assert len(hits) == 1 and hits[0].other == 1
    assert list(sim.clusters) == [0, 0]
    np.testing.assert_allclose(sim.velocities, [[0, 0.5], [0, 0.5]], atol=1e-15)


def test_stick_glancing_cluster_rotates_rigidly_then_stops_at_wall():
    # PhET's GLANCING preset: the light ball clips the heavy one off-centre.
    sim = Simulator(STICK, [[-0.65, 0], [0.6, 0.12]], [[0, 0], [-1, 0]], [1.8, 0.3])
    p0, e0 = sim.momentum(), sim.kinetic_energy()
    hits = sim.step(1.0)
    assert [h.other for h in hits] == [1]
    assert list(sim.clusters) == [0, 0]
    np.testing.assert_allclose(sim.momentum(), p0, atol=1e-14)
    assert sim.kinetic_energy() < e0
    sigma = sim.radii.sum()
    # angular momentum about the centre of mass is that of the incoming ball, and stays constant
    m = sim.masses
    com0 = (m[:, None] * np.array([[-0.65, 0], [0.6, 0.12]])).sum(0) / m.sum()
    d1 = np.array([0.6, 0.12]) - com0
    L0 = 0.3 * (d1[0] * 0.0 - d1[1] * -1.0) - 1.8 * 0.0  # about the moving COM: r x m(v - v_cm)
    vcm = p0 / m.sum()
    L0 = sum(
        mi * ((pi - com0)[0] * (vi - vcm)[1] - (pi - com0)[1] * (vi - vcm)[0])
        for mi, pi, vi in zip(
            m, [np.array([-0.65, 0]), np.array([0.6, 0.12])], [np.zeros(2), np.array([-1.0, 0])], strict=True
        )
    )
    assert angular_momentum(sim) == pytest.approx(L0, rel=1e-12)
    assert abs(L0) > 1e-3
    stopped = False
    for _ in range(400):
        for h in sim.step(0.05):
            if h.wall is not None:
                stopped = True
                x, y = h.point
                assert x in (-2.0, 2.0) or y in (-1.0, 1.0)
        d = np.linalg.norm(sim.positions[0] - sim.positions[1])
        if not stopped:
            assert d == pytest.approx(sigma, rel=1e-12)  # rigid
            assert angular_momentum(sim) == pytest.approx(L0, rel=1e-9)
        p, r = sim.positions, sim.radii
        assert np.all(np.abs(p[:, 0]) + r <= 2 + 1e-12) and np.all(np.abs(p[:, 1]) + r <= 1 + 1e-12)
    assert stopped
    np.testing.assert_array_equal(sim.velocities, 0.0)


def test_stuck_cluster_follows_rigid_motion_between_events():
    sim = Simulator(STICK, [[-0.65, 0], [0.6, 0.12]], [[0, 0], [-1, 0]], [1.8, 0.3])
    (hit,) = sim.step(1.0)
    m, p, v = sim.masses, sim.positions, sim.velocities
    com, vcm = (m[:, None] * p).sum(0) / m.sum(), (m[:, None] * v).sum(0) / m.sum()
    d = p - com
    w = (m * (d[:, 0] * (v - vcm)[:, 1] - d[:, 1] * (v - vcm)[:, 0])).sum() / (m * (d**2).sum(1)).sum()
    tau = 0.3
    sim.step(tau)
    c, s = math.cos(w * tau), math.sin(w * tau)
    expect = com + vcm * tau + d @ np.array([[c, s], [-s, c]])
    np.testing.assert_allclose(sim.positions, expect, atol=1e-13)


def test_stick_ball_stops_dead_at_a_wall():
    sim = Simulator(STICK, [[1.0, 0.0]], [[2.0, 1.0]], [1.0])
    hits = sim.step(1.0)
    assert [h.wall for h in hits] == ["right"]
    np.testing.assert_array_equal(sim.velocities, 0.0)


def test_nudge_on_a_cluster_is_an_impulse():
    sim = Simulator(STICK, [[-0.65, 0], [0.6, 0.12]], [[0, 0], [-1, 0]], [1.8, 0.3])
    sim.step(1.0)
    p0 = sim.momentum()
    sim.nudge([[0.0, 0.0], [0.0, 0.5]])
    np.testing.assert_allclose(sim.momentum() - p0, [0.0, 0.3 * 0.5], atol=1e-14)
    d = np.linalg.norm(sim.positions[0] - sim.positions[1])
    sim.step(0.2)
    assert np.linalg.norm(sim.positions[0] - sim.positions[1]) == pytest.approx(d, rel=1e-12)


def _valid(sim, tol=1e-9):
    p, r = sim.positions, sim.radii
    assert np.isfinite(p).all() and np.isfinite(sim.velocities).all()
    b = sim.scene.bounds
    assert np.all(p[:, 0] - r >= b[0] - tol) and np.all(p[:, 0] + r <= b[2] + tol)
    if sim.scene.dimension == 2:
        assert np.all(p[:, 1] - r >= b[1] - tol) and np.all(p[:, 1] + r <= b[3] + tol)
    d = np.linalg.norm(p[:, None] - p[None], axis=-1) + np.eye(len(r)) * 1e9
    assert np.all(d >= (r[:, None] + r[None]) * (1 - 1e-9))


@pytest.mark.parametrize("e", [0.0, 0.05])
def test_collapse_train_against_a_wall_1d(e):
    r = 0.1
    xs = [-2 + r + 2 * r * k for k in range(5)] + [0.5]  # five touching at the left wall, a sixth coming
    scene = Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1)
    sim = Simulator(scene, [[x, 0] for x in xs], [[0, 0]] * 5 + [[-3.0, 0]], [1.0] * 6, radii=[r] * 6)
    energy = sim.kinetic_energy()
    start = time.perf_counter()
    for _ in range(120):
        hits = sim.step(1 / 60)
        assert len(hits) < 2000 and not sim.cap_reached
        _valid(sim)
        assert sim.kinetic_energy() <= energy * (1 + 1e-12)
        energy = sim.kinetic_energy()
    assert time.perf_counter() - start < 5.0
    if e == 0.0:  # perfectly inelastic: everything ends at rest against the wall
        assert sim.kinetic_energy() < 1e-12


@pytest.mark.parametrize("e", [0.0, 0.05])
def test_collapse_crowd_against_a_wall_2d(e):
    rng = np.random.default_rng(7)
    r = 0.1
    pos = np.array([[-1.9 + 0.2 * (k % 3) + 0.001 * k, -0.8 + 0.21 * (k // 3)] for k in range(15)])
    vel = np.column_stack([-2 - rng.random(15), rng.normal(size=15) * 0.3])
    sim = Simulator(Scene(elasticity=e), pos, vel, rng.uniform(0.1, 3, 15), radii=[r] * 15)
    energy = sim.kinetic_energy()
    p0 = None
    for _ in range(180):
        hits = sim.step(1 / 60)
        assert not sim.cap_reached and len(hits) < 5000
        _valid(sim)
        assert sim.kinetic_energy() <= energy * (1 + 1e-12)
        energy = sim.kinetic_energy()
        p0 = hits
    assert p0 is not None


def test_three_ball_collapse_with_wall_is_bounded():
    # Zhou & Kadanoff: three particles in 1D collapse for e < 7 - 4 sqrt(3) ~ 0.072.
    r = 0.05
    scene = Scene(bounds=(-1.0, -0.5, 100.0, 0.5), elasticity=0.05, dimension=1)
    sim = Simulator(scene, [[-1 + r, 0], [-0.5, 0], [0.0, 0]], [[0, 0], [0, 0], [-1.0, 0]], [1, 1, 1], radii=[r] * 3)
    total = sum(len(sim.step(0.5)) for _ in range(10))
    assert 3 < total < 500 and not sim.cap_reached
    _valid(sim)


@pytest.mark.parametrize("ratio", [1e8, 1e12])
def test_light_ball_pressed_by_a_far_heavier_one_settles_at_once(ratio):
    # A light ball between a wall and a ball M/m times heavier: sequential impulses would need
    # about M/m sweeps at one instant; the cascade is replaced by its limit (the heavy ball stops).
    scene = Scene(bounds=(-2.0, -0.55, 1e4, 0.55), elasticity=0.05, dimension=1)
    sim = Simulator(
        scene, [[-1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [-1.0, 0.0]], [1.0, ratio], radii=[0.1, 0.1], max_events=10_000
    )
    energy = sim.kinetic_energy()
    start = time.perf_counter()
    for _ in range(200):
        sim.step(0.01)
        assert not sim.cap_reached
        _valid(sim)
        assert sim.kinetic_energy() <= energy * (1 + 1e-12)
    assert time.perf_counter() - start < 5.0
    assert np.allclose(sim.positions[:, 0], [-1.9, -1.7])  # pressed against the wall, touching
    assert np.all(np.abs(sim.velocities) < 1e-6)  # at rest: the wall took the heavy ball's momentum


def test_corner_pile_with_a_heavy_ball_settles_at_once_2d():
    # Two light balls in a corner, a 1e10 times heavier ball driven diagonally into them.
    r = 0.1
    pos = [[-2 + r, -1 + r], [-2 + r, -1 + 3 * r], [-1.0, -0.5]]
    sim = Simulator(
        Scene(elasticity=0.05), pos, [[0, 0], [0, 0], [-1.2, -0.6]], [1.0, 2.0, 1e10], radii=[r] * 3, max_events=10_000
    )
    energy = sim.kinetic_energy()
    start = time.perf_counter()
    for _ in range(120):
        sim.step(1 / 60)
        assert not sim.cap_reached
        _valid(sim)
        assert sim.kinetic_energy() <= energy * (1 + 1e-12)
        energy = sim.kinetic_energy()
    assert time.perf_counter() - start < 5.0


def test_event_cap_is_reported_and_leaves_a_valid_state():
    scene = Scene(bounds=(0.0, -1.0, 1e9, 1.0), dimension=1)
    sim = Simulator(
        scene, [[1.0, 0.0], [2.0, 0.0]], [[0.0, 0.0], [-1.0, 0.0]], [1.0, 1e6], radii=[0.1, 0.1], max_events=100
    )
    with pytest.warns(EventCapWarning, match="event cap of 100"):
        hits = sim.step(10.0)
    assert len(hits) == 100 and sim.cap_reached
    assert 0 < sim.time < 10.0 and sim.time == hits[-1].time  # stopped at its last event
    _valid(sim)
    total = len(hits)
    with pytest.warns(EventCapWarning):
        while sim.cap_reached or total == 100:
            total += len(sim.step(10.0))
            if not sim.cap_reached:
                break
    for _ in range(20):
        total += len(sim.step(10.0))
    assert total == 3141  # nothing lost across capped steps


@pytest.mark.parametrize("e", [0.5, 0.9])
def test_reverse_with_partial_elasticity_uses_inverse_restitution(e):
    sim = Simulator(Scene(elasticity=e), [[-1, 0.05], [1, 0]], [[1.5, 0], [-1, 0.2]], [1.0, 2.0])
    start = sim.get_state()
    n = sum(len(sim.step(0.1)) for _ in range(30))
    assert n >= 4  # a ball-ball impact and wall impacts, each undone with 1/e
    for _ in range(30):
        sim.step(-0.1)
    np.testing.assert_allclose(sim.positions, start["positions"], atol=1e-12)
    np.testing.assert_allclose(sim.velocities, start["velocities"], atol=1e-12)


def test_copies_and_pickles_keep_the_time_direction_right():
    import copy
    import pickle

    def fresh():
        sim = Simulator(Scene(elasticity=0.5), [[-1, 0.05], [1, 0]], [[1.5, 0], [-1, 0.2]], [1.0, 2.0])
        sim.step(0.7)
        sim.step(-0.3)  # the last step ran backwards (restitution 1/e)
        return sim

    ref = fresh()
    expect = [(h.time, h.ball) for h in ref.step(-0.3)] + [(h.time, h.ball) for h in ref.step(0.5)]
    for clone in (lambda s: copy.copy(s), lambda s: s.copy(), lambda s: pickle.loads(pickle.dumps(s))):
        sim = fresh()
        other = clone(sim)
        for s in (sim, other):
            got = [(h.time, h.ball) for h in s.step(-0.3)] + [(h.time, h.ball) for h in s.step(0.5)]
            assert got == expect
            np.testing.assert_array_equal(s.positions, ref.positions)


def _slip_scene(seed, n, e):
    """``n`` balls of random sizes and masses at random places and velocities in PhET's box."""
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.1, 0.3, n)
    pos = []
    while len(pos) < n:
        p = rng.uniform([-1.7, -0.7], [1.7, 0.7])
        if all(np.hypot(*(p - q)) > radii[len(pos)] + radii[k] + 1e-3 for k, q in enumerate(pos)):
            pos.append(p)
    return Scene(elasticity=e), np.array(pos), rng.normal(size=(n, 2)), rng.uniform(0.5, 3.0, n), radii


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    n=st.integers(3, 8),
    split=st.floats(0.05, 0.95),
    ratio=st.sampled_from([1e-12, 1e-9, 1e-6]),
)
def test_at_e0_where_a_step_is_split_moves_balls_by_at_most_the_regulariser(seed, n, split, ratio):
    """Slip at e = 0: a plastic impact leaves a pair at rest or, where round-off leaves it closing,
    separating at ``u_min`` (the regulariser, ``response``), so where steps end can change a
    ball's velocity by about ``u_min`` and its position by ``u_min`` times the time left. The bound
    that holds: velocities within ``collapse_ratio * v`` and positions within
    ``collapse_ratio * (v T + r)``, ``v`` the fastest any ball can move (all the kinetic energy in
    the lightest ball), ``r`` the largest radius."""
    scene, pos, vel, mass, radii = _slip_scene(seed, n, 0.0)
    whole = Simulator(scene, pos, vel, mass, radii, collapse_ratio=ratio)
    parts = Simulator(scene, pos, vel, mass, radii, collapse_ratio=ratio)
    total = 0.6
    whole.step(total)
    parts.step(split * total)
    parts.step(total - split * total)
    v = math.sqrt((mass * (vel**2).sum(1)).sum() / mass.min())
    assert np.abs(whole.velocities - parts.velocities).max() <= ratio * v
    assert np.abs(whole.positions - parts.positions).max() <= ratio * (v * total + radii.max())


@pytest.mark.parametrize("e", [0.3, 0.7, 1.0])
def test_above_e0_where_a_step_is_split_changes_nothing_beyond_round_off(e):
    for seed in range(10):
        scene, pos, vel, mass, radii = _slip_scene(seed, 6, e)
        whole = Simulator(scene, pos, vel, mass, radii)
        parts = Simulator(scene, pos, vel, mass, radii)
        whole.step(0.6)
        parts.step(0.3)
        parts.step(0.3)
        np.testing.assert_allclose(parts.positions, whole.positions, rtol=0, atol=1e-13)
