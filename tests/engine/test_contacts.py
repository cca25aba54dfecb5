"""Contact groups at e < 1 (``engine.exact.contacts``): found through minimum images in periodic
cells as in boxes, resolved in bounded work that counts toward ``max_events``, and physical:
momentum kept, no energy gained, no overlap, and the clock reaches the end of every step."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collision_env.engine import EventCapWarning, Scene, Simulator

FRAME = 1.0 / 60.0


def struck_row(n, e, periodic=False, r=0.01, speed=1.0, max_events=None):
    """``n`` touching balls in a row along x, and one more moving at ``speed`` towards its low end,
    arriving after half a frame; the box (or cell) four times as long as the row."""
    x = np.arange(n) * 2.0 * r
    pos = np.vstack([[-2.0 * r - speed * FRAME / 2, 0.0], np.stack([x, np.zeros(n)], 1)])
    vel = np.zeros((n + 1, 2))
    vel[0, 0] = speed
    length = 4.0 * (x[-1] + 2.0 * r) + 1.0
    scene = Scene(bounds=(-0.5, -0.25, length - 0.5, 0.25), elasticity=e, periodic=periodic)
    options = {} if max_events is None else {"max_events": max_events}
    return Simulator(scene, pos, vel, np.ones(n + 1), np.full(n + 1, r), **options)


def assert_no_overlap(sim, rtol=1e-9):
    pos, radii = sim.positions, sim.radii
    d = pos[:, None, :] - pos[None, :, :]
    if sim.scene.periodic:
        lengths = np.array([sim.scene.bounds[2] - sim.scene.bounds[0], sim.scene.bounds[3] - sim.scene.bounds[1]])
        d -= lengths * np.round(d / lengths)
    dist = np.hypot(d[..., 0], d[..., 1])
    sigma = radii[:, None] + radii[None, :]
    np.fill_diagonal(dist, np.inf)
    assert (dist >= sigma * (1.0 - rtol)).all()


@pytest.mark.parametrize(("n", "e"), [(8, 0.0), (20, 0.5), (60, 0.0)])
def test_a_struck_row_in_a_periodic_cell_keeps_its_clock(n, e):
    """The report's frozen clock: at e < 1 a periodic row solved pair by pair stopped at the event
    cap every step (after 30 steps the clock read 0.001 s for 8 balls at e = 0)."""
    sim = struck_row(n, e, periodic=True)
    for _ in range(30):
        sim.step(FRAME)
        assert not sim.cap_reached
    assert sim.time == pytest.approx(0.5, rel=1e-12)
    assert sim.velocities[-1, 0] > 0.0  # (the far end of the row moves)
    assert_no_overlap(sim)


@pytest.mark.parametrize("periodic", [False, True])
def test_a_plastic_row_moves_as_one(periodic):
    """41 equal balls at e = 0 after the strike: one block at 1/41 of the striker's speed (up to the
    regulariser's separation speeds, 1e-9 of it per contact)."""
    sim = struck_row(40, 0.0, periodic=periodic)
    sim.step(FRAME)
    np.testing.assert_allclose(sim.velocities[:, 0], 1.0 / 41.0, atol=1e-7)
    np.testing.assert_array_equal(sim.velocities[:, 1], 0.0)


def test_a_row_a_round_off_off_its_axis_is_solved_as_a_row():
    """Balls stacked in a row drift apart across it by round-off (a ball moved in one long stretch
    and one moved in many short ones round differently): such a row still goes to its limit in one
    pass, with the work of a straight one (it took the general limit, 46 times the work, when its
    contacts had to lie exactly along the axis), and the same velocities up to that round-off."""
    straight = struck_row(40, 0.0)
    bent = struck_row(40, 0.0)
    state = bent.get_state()
    pos = np.array(state.positions)
    pos[1:, 1] = 1e-16 * np.resize([1.0, -1.0, 0.0], 40)  # (a few ulps of the x coordinates)
    bent.set_state(state.replace(positions=pos))
    for sim in (straight, bent):
        sim.step(FRAME)
        assert not sim.cap_reached
    assert bent.stats["events"] == straight.stats["events"] < 400
    np.testing.assert_allclose(bent.velocities[:, 0], straight.velocities[:, 0], rtol=0, atol=1e-14)
    assert np.abs(bent.velocities[:, 1]).max() < 1e-13
    assert_no_overlap(bent)


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_the_event_cap_bounds_a_contact_groups_work(e):
    """A hexagonal patch of 100 touching balls struck at a corner with ``max_events=50``: the group's
    sweeps, iterations and impulses count, so the step stops at the cap, says so, and leaves a valid
    state (it used to run the whole cascade and its dense limit, uncounted, with ``cap_reached``
    False)."""
    pos = _patch("hex", 100)
    pos = np.vstack([[-0.02 - FRAME / 2, 0.0], pos])
    vel = np.zeros((101, 2))
    vel[0, 0] = 1.0
    sim = Simulator(
        Scene(bounds=(-1, -1, 1, 1), elasticity=e), pos, vel, np.ones(101), np.full(101, 0.01), max_events=50
    )
    momentum = sim.momentum()
    with pytest.warns(EventCapWarning, match="event cap"):
        sim.step(FRAME)
    assert sim.cap_reached
    assert FRAME / 2 - 1e-9 <= sim.time < FRAME
    assert np.isfinite(sim.velocities).all() and np.isfinite(sim.positions).all()
    np.testing.assert_allclose(sim.momentum(), momentum, atol=1e-12)
    assert_no_overlap(sim)


def _patch(shape, n):
    """``n`` touching balls of radius 0.01 m: a row, a square patch or a hexagonal one."""
    d = 0.02 * (1.0 + 1e-12)
    if shape == "row":
        return np.stack([np.arange(n) * d, np.zeros(n)], 1)
    side = int(np.ceil(np.sqrt(n)))
    k = np.arange(side * side)
    i, j = k % side, k // side
    if shape == "square":
        pos = np.stack([i * d, j * d], 1)
    else:
        pos = np.stack([(i + 0.5 * (j % 2)) * d, j * d * np.sqrt(3.0) / 2.0], 1)
    return pos[:n]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    shape=st.sampled_from(["row", "square", "hex"]),
    n=st.integers(2, 80),
    e=st.floats(0.0, 0.99),
    where=st.sampled_from(["free", "periodic"]),
    log_mass=st.floats(0.0, 3.0),
    seed=st.integers(0, 2**31),
)
def test_random_touching_groups_keep_momentum_and_gain_no_energy(shape, n, e, where, log_mass, seed):
    rng = np.random.default_rng(seed)
    pos = _patch(shape, n)
    vel = rng.normal(size=(n, 2))
    mass = 10.0 ** rng.uniform(0.0, log_mass, n)
    bounds = (-1.0, -1.0, 2.0, 2.0) if where == "periodic" else None
    sim = Simulator(Scene(bounds=bounds, elasticity=e, periodic=where == "periodic"), pos, vel, mass, np.full(n, 0.01))
    momentum, energy = sim.momentum(), sim.kinetic_energy()
    for _ in range(3):
        sim.step(FRAME / 4)
        assert not sim.cap_reached
    assert sim.time == pytest.approx(0.75 * FRAME, rel=1e-12)
    scale = np.sqrt(2.0 * energy * mass.sum())  # (a momentum the group could have)
    np.testing.assert_allclose(sim.momentum(), momentum, atol=1e-12 * scale)
    assert sim.kinetic_energy() <= energy * (1.0 + 1e-12)
    assert_no_overlap(sim)
