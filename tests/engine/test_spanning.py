"""Touching balls that reach from a wall to the opposite one: refused wherever a state enters.

Such a network is jammed between the walls (a straight row or a square lattice has no velocity along
that axis that closes none of its contacts), and exact mode, resolving its impacts one pair after
another, would make no progress; so the constructor, ``set_scenes``, ``set_balls`` and ``set_state`` refuse it with a
``ValueError`` naming a ball of it and the axis, and leave the state as it was. The same balls with
room to move (a gap above the contact tolerance) are accepted, and the clock gets through.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collision_env.engine import BatchSimulator, Scene, Simulator
from collision_env.engine.broadphase import GRID_MIN_BALLS
from collision_env.engine.physics.tolerance import CONTACT_RTOL

MODES = ("exact", "posteriori", "naive")


def spanning(along, across, axis, gap, size=1.0, offset=0.0, e=1.0, seed=0):
    """``along`` x ``across`` balls of equal radius in a square lattice (a row when ``across`` is 1)
    that fill ``2 size`` m along ``axis`` but for ``gap`` (relative to the box), their radii
    ``gap / 2`` short of touching (gap 0: touching each other and the walls), centred in a box twice
    as long across, ``offset`` m from the origin; masses 1 to 3 kg."""
    r = size * (2.0 - gap) / (2 * along)
    k_along, k_across = np.meshgrid(np.arange(along), np.arange(across), indexing="ij")
    u = (2 * k_along.ravel() + 1 - along) * r
    w = (2 * k_across.ravel() + 1 - across) * r
    pos = (np.stack([u, w], 1) if axis == 0 else np.stack([w, u], 1)) + offset
    half = np.array([size, 2.0 * max(size, across * r)])[[axis, 1 - axis]]
    bounds = (offset - half[0], offset - half[1], offset + half[0], offset + half[1])
    rng = np.random.default_rng(seed)
    n = len(pos)
    return (
        Scene(bounds=bounds, elasticity=e),
        pos,
        rng.uniform(-1.0, 1.0, (n, 2)),
        1.0 + 2.0 * rng.random(n),
        np.full(n, r * (1.0 - gap / 2)),
    )


def test_the_two_balls_of_the_report_are_refused():
    with pytest.raises(ValueError, match="ball 0: position leaves no room to move along x: the ball is one of 2"):
        Simulator(Scene(bounds=(-1, -2, 1, 2)), [[-0.5, 0], [0.5, 0]], [[0.3, 0.7], [-0.1, 0.2]], [1, 2], [0.5, 0.5])


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    along=st.integers(2, 9),
    across=st.integers(1, 4),
    axis=st.sampled_from([0, 1]),
    e=st.sampled_from([0.0, 0.5, 1.0]),
    size=st.sampled_from([1e-3, 1.0, 1e3]),
    shift=st.sampled_from([0.0, -3.0, 10.0]),
    within=st.floats(0.0, 0.5),
)
def test_touching_balls_from_wall_to_wall_are_refused_at_every_entry(along, across, axis, e, size, shift, within):
    """Gaps inside the contact tolerance (a fraction ``within`` of it, relative to the radii) count
    as touching, at any scale and away from the origin (``shift`` box sizes); every entry refuses
    the state and leaves the simulator as it was."""
    offset = shift * size
    scene, pos, vel, mass, radii = spanning(along, across, axis, 0.0, size, offset, e)
    radii = radii * (1.0 - within * CONTACT_RTOL)  # gaps of up to half the contact tolerance
    message = f"ball 0: position leaves no room to move along {'xy'[axis]}: the ball is one of {along * across} "
    with pytest.raises(ValueError, match=message):
        Simulator(scene, pos, vel, mass, radii)
    good = spanning(along, across, axis, 0.01, size, offset, e)
    sim = Simulator(*good)
    before = sim.get_state()
    bad = before.replace(positions=pos, radii=radii)
    with pytest.raises(ValueError, match=f"along {'xy'[axis]}"):
        sim.set_state(bad)
    with pytest.raises(ValueError, match=f"along {'xy'[axis]}"):
        sim.batch.set_scenes([0], [pos], [vel], masses=mass, radii=radii)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("e", [1.0, 0.5, 0.0])
@pytest.mark.parametrize("shape", [(2, 1), (3, 1), (3, 3), (8, 8)])
@pytest.mark.parametrize("axis", [0, 1])
def test_the_same_balls_with_room_to_move_get_through_the_step(mode, e, shape, axis):
    """A gap of 1e-3 of the box: accepted, and every mode's clock reaches the end of the steps. (The
    cap counts contact groups' sweeps and impulses too: the 8 x 8 lattice's first step at e = 0 takes
    about 10^5 of them.)"""
    sim = Simulator(*spanning(*shape, axis, 1e-3, e=e), mode=mode, max_events=10**6)
    for _ in range(4):
        sim.step(0.05)
        assert not sim.cap_reached
    assert sim.time == pytest.approx(0.2, rel=1e-12)
    assert np.isfinite(sim.positions).all()


def test_set_balls_refuses_a_row_from_wall_to_wall():
    scene, pos, vel, mass, radii = spanning(3, 1, 1, 0.0)
    sim = Simulator(scene, pos + [[0.0, 0.0], [0.0, 0.0], [0.7, 0.0]], vel, mass, radii)
    before = sim.get_state()
    with pytest.raises(ValueError, match="ball 0: position leaves no room to move along y"):
        sim.set_balls(positions=pos)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


@pytest.mark.parametrize("k", [GRID_MIN_BALLS // 8, 64])
def test_a_large_lattice_is_refused_on_the_grid_path(k):
    """8 x 8 (the grid's smallest scene) and 64 x 64 touching lattices filling a square box."""
    r = 1.0 / k
    u = (2 * np.arange(k) + 1 - k) * r
    pos = np.stack(np.meshgrid(u, u), -1).reshape(-1, 2)
    n = len(pos)
    assert n >= GRID_MIN_BALLS
    with pytest.raises(ValueError, match="leaves no room to move along x: the ball is one of"):
        BatchSimulator(Scene(bounds=(-1, -1, 1, 1)), [pos], np.ones((1, n, 2)), np.ones(n), np.full(n, r))


def test_a_network_touching_one_wall_or_two_adjacent_ones_is_accepted():
    """Left and bottom walls (a corner), or one wall: room along both axes."""
    scene, pos, vel, mass, radii = spanning(3, 1, 0, 1e-3)
    corner = pos - pos[0] + [scene.bounds[0] + radii[0], scene.bounds[1] + radii[0]]
    Simulator(scene, corner, vel, mass, radii).step(0.1)


def test_stepped_modes_accept_their_own_states_and_step_a_spanning_one():
    """naive and posteriori may end steps with balls overlapping or pressed from wall to wall;
    their set_state takes such states, and their steps get through them."""
    scene, pos, vel, mass, radii = spanning(4, 4, 0, 0.01)
    for mode in ("naive", "posteriori"):
        sim = Simulator(scene, pos, vel, mass, radii, mode=mode)
        state = sim.get_state()
        tight = spanning(4, 4, 0, 0.0)
        sim.set_state(state.replace(positions=tight[1], radii=tight[4]))
        sim.step(0.1)
        assert sim.time == pytest.approx(0.1)
