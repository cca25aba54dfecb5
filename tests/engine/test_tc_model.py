"""The TC model (Luding & McNamara 1998), exact mode's opt-in bound on inelastic collapse: a collision
is elastic when either ball's previous collision happened less than ``contact_duration`` before it."""

import io
import math

import numpy as np
import pytest

from collision_env.engine import BatchSimulator, Scene, Simulator

#: A box whose right wall is at x = 1, at e = 0.5: ball 1 (r = 0.1) at x = 0.6 moving +1 m/s meets
#: the wall at t = 0.3 (and leaves at -0.5 m/s), then ball 0, at rest at x = 0, at t = 1.7: 1.4 s
#: after its own previous collision, ball 0's first.
BOX = Scene(bounds=(-5.0, -1.0, 1.0, 1.0), elasticity=0.5)
TWO = ([[0.0, 0.0], [0.6, 0.0]], [[0.0, 0.0], [1.0, 0.0]], [1.0, 1.0], [0.1, 0.1])


def two_collisions(contact_duration):
    sim = Simulator(BOX, *TWO, contact_duration=contact_duration)
    hits = sim.step(2.0)
    assert [(h.ball, h.other, h.wall) for h in hits] == [(1, None, "right"), (0, 1, None)]
    np.testing.assert_allclose(hits["time"], [0.3, 1.7], rtol=1e-12)
    return sim


@pytest.mark.parametrize("contact_duration", [0.0, 0.1, 1.0, 1.39])
def test_second_collision_beyond_contact_duration_is_inelastic(contact_duration):
    # 1.4 s after ball 1's wall collision: e = 0.5, from -0.5 against 0 -> -0.375 and -0.125
    sim = two_collisions(contact_duration)
    np.testing.assert_allclose(sim.velocities, [[-0.375, 0.0], [-0.125, 0.0]], atol=1e-15)


@pytest.mark.parametrize("contact_duration", [1.41, 2.0, 1e6])
def test_second_collision_within_contact_duration_is_elastic(contact_duration):
    # the wall collision itself is ball 1's first: e = 0.5; the pair's, within t_c of it: e = 1 (the balls swap)
    sim = two_collisions(contact_duration)
    np.testing.assert_allclose(sim.velocities, [[-0.5, 0.0], [0.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(sim.get_state().last_impact, [1.7, 1.7], rtol=1e-12)


def test_wall_collision_within_contact_duration_is_elastic():
    # a ball bouncing between walls 0.2 m apart (r = 0.1, 1 m/s): the first bounce at e = 0.5, every
    # later one within t_c of the one before, elastic
    scene = Scene(bounds=(-0.2, -1.0, 0.2, 1.0), elasticity=0.5)
    sim = Simulator(scene, [[0.0, 0.0]], [[1.0, 0.0]], [1.0], [0.1], contact_duration=1.0)
    hits = sim.step(1.0)
    np.testing.assert_allclose(hits["speed"], [1.0] + [0.5] * (len(hits) - 1), rtol=1e-12)
    assert len(hits) == 3  # (t = 0.1, 0.5, 0.9)


def row(e, contact_duration, n=6):
    """``n`` touching balls along x struck at one end: one contact group, every ball's first collision."""
    r = 0.1
    pos = [[-0.5, 0.0]] + [[2 * r * k * (1 + 1e-12), 0.0] for k in range(n)]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * n
    scene = Scene(bounds=(-2.0, -1.0, 4.0, 1.0), elasticity=e)
    sim = Simulator(scene, pos, vel, np.ones(n + 1), np.full(n + 1, r), contact_duration=contact_duration)
    return sim, sim.step(0.5)


@pytest.mark.parametrize("e", [0.0, 0.5])
def test_a_cascade_does_not_make_its_own_impulses_elastic(e):
    # every contact of the group has its balls' collisions *before* the group's instant: none here,
    # so the group resolves as without the model, however long t_c
    plain, plain_hits = row(e, 0.0)
    tc, tc_hits = row(e, 10.0)
    np.testing.assert_array_equal(tc.velocities, plain.velocities)
    np.testing.assert_array_equal(tc_hits["impulse"], plain_hits["impulse"])
    assert tc.kinetic_energy() < 0.5  # (inelastic: the strike's 0.5 J is not all kept)
    instant = plain_hits["time"][1]
    np.testing.assert_array_equal(tc.get_state().last_impact, np.full(7, instant))


def test_momentum_exact_and_energy_never_gained():
    # a seeded dense gas at e = 0.2 in a periodic cell (no walls: momentum is conserved), t_c about a
    # tenth of the initial time between a ball's collisions
    rng = np.random.default_rng(7)
    side, r = 8, 0.045
    grid = (np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) + 0.5) / side
    pos = grid + rng.uniform(-0.01, 0.01, grid.shape)
    vel = rng.normal(size=grid.shape)
    n = len(pos)
    mass = rng.uniform(0.5, 2.0, n)
    scene = Scene(bounds=(0.0, 0.0, 1.0, 1.0), elasticity=0.2, periodic=True)
    sim = Simulator(scene, pos, vel, mass, np.full(n, r), contact_duration=2e-3)
    plain = Simulator(scene, pos, vel, mass, np.full(n, r))
    p0 = sim.momentum()
    scale = float(np.sqrt((mass[:, None] * vel**2).sum() * mass.sum()))
    energy = sim.kinetic_energy()
    hits = 0
    for _ in range(60):
        hits += len(sim.step(1.0 / 60.0))
        assert not sim.cap_reached
        np.testing.assert_allclose(sim.momentum(), p0, rtol=0, atol=1e-12 * scale)
        assert sim.kinetic_energy() <= energy * (1 + 1e-12)
        energy = sim.kinetic_energy()
        plain.step(1.0 / 60.0)
    assert hits > 300 and energy < 0.5 * 0.5 * float((mass[:, None] * vel**2).sum())
    assert not np.array_equal(sim.velocities, plain.velocities)  # (the model made some collisions elastic)


def test_state_round_trip_bit_for_bit():
    sim, _ = row(0.5, 10.0)
    sim.step(0.25)
    state = sim.get_state()
    ahead = sim.copy()
    ahead.step(1.0)
    balls = (state[k] for k in ("positions", "velocities", "masses", "radii"))
    other = Simulator(sim.scene, *balls, contact_duration=10.0)
    other.set_state(state)
    assert other.get_state() == state
    other.step(1.0)
    assert other.get_state() == ahead.get_state()


def test_model_off_keeps_states_as_they_were():
    sim, _ = row(0.5, 0.0)
    state = sim.get_state()
    # (a field the simulator does not keep is left out of the mapping, so np.savez stays plain)
    assert state.last_impact is None and "last_impact" not in dict(state) and len(state) == len(dict(state))
    buffer = io.BytesIO()
    np.savez(buffer, **state)
    buffer.seek(0)
    sim.set_state(dict(np.load(buffer)))
    assert sim.get_state() == state
    batch = BatchSimulator(BOX, [TWO[0]] * 2, [TWO[1]] * 2, TWO[2], TWO[3])
    assert batch.get_state().last_impact is None and batch.contact_duration == 0.0


def test_loading_a_simulator_without_the_model_brings_no_history():
    # backward steps of a simulator without the model take its clock back past the instants it
    # kept: a simulator with the model that loads it starts with none, and takes its own state back
    plain, _ = row(0.5, 0.0)
    plain.step(1.0)
    plain.step(-1.3)  # (back to 0.2 s on the clock: its row's instants are at 0.3 s)
    assert plain.time < plain._stepper.mode_arrays[0].last_impact.max()
    tc, _ = row(0.5, 1.0)
    tc.batch.load(plain.batch)
    state = tc.get_state()
    assert np.all(state.last_impact == -np.inf)
    tc.set_state(state)


@pytest.mark.parametrize("bad", [-1e-3, math.nan, math.inf, "1", True, 1e300, 10**400])
def test_bad_contact_duration_is_named(bad):
    with pytest.raises(ValueError, match="contact_duration"):
        Simulator(BOX, *TWO, contact_duration=bad)


@pytest.mark.parametrize("mode", ["naive", "posteriori"])
def test_cheap_modes_refuse_the_model(mode):
    with pytest.raises(ValueError, match="contact_duration: the TC model is exact mode's"):
        Simulator(BOX, *TWO, mode=mode, contact_duration=1e-3)
    Simulator(BOX, *TWO, mode=mode, contact_duration=0.0)


def test_stick_scenes_refuse_the_model():
    with pytest.raises(ValueError, match="contact_duration: a stick scene"):
        Simulator(Scene(elasticity=0.0, inelastic="stick"), *TWO, contact_duration=1e-3)


def test_backward_step_refused_and_state_untouched():
    sim = two_collisions(2.0)
    before = sim.get_state()
    with pytest.raises(ValueError, match="dt: cannot step backwards under the TC model"):
        sim.step(-0.5)
    assert sim.get_state() == before


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ([math.nan, 0.0], "finite or -inf"),
        ([math.inf, 0.0], "finite or -inf"),
        ([0.0, 3.0], "ball 1: a last collision instant after the clock"),
    ],
)
def test_bad_last_impact_is_named_and_state_untouched(value, message):
    sim = two_collisions(2.0)
    before = sim.get_state()
    with pytest.raises(ValueError, match=f"state last_impact: .*{message}" if message[0] == "b" else message):
        sim.set_state(before.replace(last_impact=value))
    assert sim.get_state() == before


def test_set_balls_starts_the_memory_afresh():
    sim = two_collisions(2.0)
    sim.set_balls(velocities=[[1.0, 0.0], [0.0, 0.0]])
    np.testing.assert_array_equal(sim.get_state().last_impact, [-math.inf, -math.inf])


def test_batch_scenes_keep_their_own_collision_instants():
    # scene 0 as above; in scene 1 ball 1 starts 0.1 m further from the wall, so every instant is 0.1 s later
    pos = [TWO[0], [[0.0, 0.0], [0.5, 0.0]]]
    batch = BatchSimulator(BOX, pos, [TWO[1]] * 2, TWO[2], TWO[3], contact_duration=2.0)
    batch.step(2.0)
    np.testing.assert_allclose(batch.get_state().last_impact, [[1.7, 1.7], [1.8, 1.8]], rtol=1e-12)
    np.testing.assert_allclose(batch.velocities[:, :, 0], [[-0.5, 0.0], [-0.5, 0.0]], atol=1e-15)
    other = BatchSimulator(BOX, pos, [TWO[1]] * 2, TWO[2], TWO[3], contact_duration=2.0)
    other.load(batch)
    assert other.get_state() == batch.get_state() and batch.contact_duration == 2.0
