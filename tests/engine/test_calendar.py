"""Exact mode's persistent calendar and the grid broad phase.

Every invalidation path is checked against a simulator built afresh from the same state (which
predicts everything from scratch): a nudge between steps, ``set_state``, a reversal of time (in
small scenes, and in one large enough for the event queue's time buckets), a ball crossing many
grid cells in one step, and a batch of 1024 scenes. The grid is checked
against all pairs, in exact mode and in the cheap modes.
"""

from __future__ import annotations

import numpy as np
import pytest

import collision_env.engine.stepper as stepper_module
from collision_env.engine import BatchSimulator, Scene, Simulator
from collision_env.engine.broadphase import GRID_MIN_BALLS
from collision_env.engine.exact import calendar
from collision_env.engine.exact.calendar import QUEUE_MIN_BALLS
from collision_env.engine.layout import W_GRID_NX, W_QUEUE_FAR, W_QUEUE_HEAP, W_QUEUE_RING


def gas(n, phi=0.3, r=0.01, seed=0, speed=1.0):
    """``n`` disks of radius ``r`` on a square lattice in a box at area fraction ``phi``."""
    side = np.sqrt(n * np.pi * r * r / phi)
    m = int(np.ceil(np.sqrt(n)))
    g = (np.arange(m) + 0.5) * side / m - side / 2
    xx, yy = np.meshgrid(g, g)
    pos = np.stack([xx.ravel(), yy.ravel()], 1)[:n]
    vel = np.random.default_rng(seed).normal(size=(n, 2)) * speed / np.sqrt(2)
    return Scene(bounds=(-side / 2, -side / 2, side / 2, side / 2)), pos, vel, np.full(n, r)


#: A scene large enough for the event queue's time buckets (and a grid).
LARGE = QUEUE_MIN_BALLS + 500


def fresh_copy(sim):
    """A simulator that has never predicted anything, in ``sim``'s state."""
    new = Simulator(
        sim.scene,
        sim.positions,
        sim.velocities,
        sim.masses,
        radii=sim.radii,
        mode=sim.mode,
        max_events=sim.batch.max_events,
    )
    new.set_state(sim.get_state())
    return new


def rows(impacts):
    return [(i.ball, i.other, i.wall) for i in impacts], np.array([i.time for i in impacts])


def assert_same_impacts(a, b):
    keys_a, times_a = rows(a)
    keys_b, times_b = rows(b)
    assert keys_a == keys_b
    np.testing.assert_allclose(times_a, times_b, rtol=0, atol=1e-12)


def step_both(sim, other, dt, steps):
    for _ in range(steps):
        assert_same_impacts(sim.step(dt), other.step(dt))
    np.testing.assert_allclose(sim.positions, other.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sim.velocities, other.velocities, rtol=0, atol=1e-12)


@pytest.mark.parametrize("n", [6, 120, LARGE])
def test_nudge_between_steps_matches_a_fresh_simulator(n):
    scene, pos, vel, radii = gas(n)
    sim = Simulator(scene, pos, vel, np.ones(n), radii=radii)
    for _ in range(10):
        sim.step(1 / 60)
    dv = np.zeros((n, 2))
    dv[n // 2] = (0.7, -0.3)
    sim.nudge(dv)
    step_both(sim, fresh_copy(sim), 1 / 60, 20)


@pytest.mark.parametrize("n", [6, 120, LARGE])
def test_set_state_matches_a_fresh_simulator(n):
    scene, pos, vel, radii = gas(n)
    sim = Simulator(scene, pos, vel, np.ones(n), radii=radii)
    saved = sim.get_state()
    for _ in range(15):
        sim.step(1 / 60)
    sim.set_state(saved)  # back to the start: every prediction made since is void
    reference = Simulator(scene, pos, vel, np.ones(n), radii=radii)
    step_both(sim, reference, 1 / 60, 20)


@pytest.mark.parametrize("n", [6, 120, LARGE])
def test_reversal_of_time_matches_a_fresh_simulator(n):
    scene, pos, vel, radii = gas(n)
    sim = Simulator(scene, pos, vel, np.ones(n), radii=radii)
    for _ in range(10):
        sim.step(1 / 60)
    step_both(sim, fresh_copy(sim), -1 / 60, 5)
    step_both(sim, fresh_copy(sim), 1 / 60, 5)


def test_a_large_scene_queues_most_events_in_time_buckets():
    scene, pos, vel, radii = gas(LARGE)
    sim = Simulator(scene, pos, vel, np.ones(LARGE), radii=radii)
    for _ in range(3):
        sim.step(1 / 60)
    queue = sim._stepper.work_i[0]
    assert queue[W_QUEUE_HEAP] + queue[W_QUEUE_RING] + queue[W_QUEUE_FAR] == LARGE
    assert queue[W_QUEUE_HEAP] < LARGE / 20 < queue[W_QUEUE_RING]
    assert sim._stepper.mode_arrays[0].buckets.shape == (1, LARGE // 2 + 1)


def test_a_large_scene_steps_bit_for_bit_as_with_a_heap_of_every_ball(monkeypatch):
    """The time buckets change where events wait, never the order they come in."""
    scene, pos, vel, radii = gas(LARGE)
    sim = Simulator(scene, pos, vel, np.ones(LARGE), radii=radii)
    monkeypatch.setattr(calendar, "bucket_count", lambda n: 0)
    heap = Simulator(scene, pos, vel, np.ones(LARGE), radii=radii)
    assert heap._stepper.mode_arrays[0].buckets.shape == (1, 1) and sim._stepper.mode_arrays[0].buckets.shape[1] > 1
    dv = np.zeros((LARGE, 2))
    dv[:: LARGE // 7] = (0.4, -0.9)
    for frame in range(12):
        if frame == 5:
            sim.nudge(dv)
            heap.nudge(dv)
        assert sim.step(1 / 60) == heap.step(1 / 60)
    np.testing.assert_array_equal(sim.positions, heap.positions)
    np.testing.assert_array_equal(sim.velocities, heap.velocities)


def test_forward_then_back_returns_to_the_start_with_the_calendar_kept():
    scene, pos, vel, radii = gas(150, phi=0.1)
    sim = Simulator(scene, pos, vel, np.ones(150), radii=radii)
    for _ in range(12):
        sim.step(1 / 120)
    for _ in range(12):
        sim.step(-1 / 120)
    np.testing.assert_allclose(sim.positions, pos, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sim.velocities, vel, rtol=0, atol=1e-9)


def without_grid(monkeypatch):
    monkeypatch.setattr(stepper_module, "GRID_MIN_BALLS", 10**9)


def test_a_ball_crossing_many_cells_in_one_step(monkeypatch):
    scene, pos, vel, radii = gas(200, phi=0.05)
    vel[:] = 0.0
    vel[0] = (37.0, 11.0)  # a bullet: ~20 cells per step
    sim = Simulator(scene, pos, vel, np.ones(200), radii=radii)
    assert sim._stepper.work_i[0, W_GRID_NX] > 10
    without_grid(monkeypatch)
    reference = Simulator(scene, pos, vel, np.ones(200), radii=radii)
    assert reference._stepper.work_i[0, W_GRID_NX] == 1
    step_both(sim, reference, 1 / 30, 10)
    assert sim.stats["cell_crossings"] > 100
    assert sim.stats["events"] > 20


@pytest.mark.parametrize("mode", ["naive", "posteriori", "exact"])
def test_grid_agrees_with_all_pairs(mode, monkeypatch):
    scene, pos, vel, radii = gas(150)
    sim = Simulator(scene, pos, vel, np.ones(150), radii=radii, mode=mode)
    without_grid(monkeypatch)
    reference = Simulator(scene, pos, vel, np.ones(150), radii=radii, mode=mode)
    step_both(sim, reference, 1 / 120, 30)
    assert sim.stats["pair_tests"] < reference.stats["pair_tests"] / 3


def test_batch_of_1024_scenes_matches_fresh_simulators():
    rng = np.random.default_rng(3)
    b, n = 1024, 4
    scene = Scene()
    x = np.linspace(-1.5, 1.5, n)
    pos = np.stack([np.broadcast_to(x, (b, n)), rng.uniform(-0.7, 0.7, (b, n))], -1)
    vel = rng.normal(size=(b, n, 2))
    masses = np.ones(n)
    batch = BatchSimulator(scene, pos, vel, masses, radii=np.full(n, 0.1))
    for step in range(30):
        if step % 7 == 3:  # nudge a third of the scenes, as a vector env's actions do
            dv = np.zeros((b, n, 2))
            dv[::3, 0] = rng.normal(size=(len(dv[::3]), 2))
            batch.nudge(dv)
        state = batch.get_state()
        reference = BatchSimulator(scene, state["positions"], state["velocities"], masses, radii=np.full(n, 0.1))
        reference.set_state(state)
        got, want = batch.step(1 / 60), reference.step(1 / 60)
        np.testing.assert_array_equal(got[["scene", "ball", "other", "wall"]], want[["scene", "ball", "other", "wall"]])
        np.testing.assert_allclose(got["time"], want["time"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.positions, reference.positions, rtol=0, atol=1e-12)


def test_predictions_survive_from_step_to_step():
    """Steps without events cost no prediction: the calendar is kept."""
    sim = Simulator(Scene(), [[-1.0, 0.0], [1.0, 0.5]], [[0.01, 0.0], [0.0, 0.01]], [1.0, 1.0])
    sim.step(1 / 60)
    before = sim.stats
    for _ in range(100):
        sim.step(1 / 60)
    after = sim.stats
    assert after["events"] == before["events"]
    assert after["pair_tests"] == before["pair_tests"]
    assert after["wall_tests"] == before["wall_tests"]


def test_memory_and_construction_are_linear_in_the_balls():
    n = 20_000
    scene, pos, vel, radii = gas(n)
    sim = Simulator(scene, pos, vel, np.ones(n), radii=radii)
    arrays = [v for v in vars(sim._stepper).values() if isinstance(v, np.ndarray)]
    arrays += [a for bundle in sim._stepper.mode_arrays for a in bundle]  # (the calendar and work space)
    per_ball = sum({id(a): a.nbytes for a in arrays}.values()) / n
    assert per_ball < 2048
    assert GRID_MIN_BALLS < n


def test_overlap_found_by_the_grid_names_both_balls():
    scene, pos, vel, radii = gas(300)
    pos[250] = pos[7] + (0.015, 0.0)
    with pytest.raises(ValueError, match=r"ball 7: position overlaps ball 250"):
        Simulator(scene, pos, vel, np.ones(300), radii=radii)


@pytest.mark.parametrize("elasticity", [1.0, 0.5])
def test_a_step_that_stalls_on_a_full_impact_buffer_is_bit_for_bit_the_same(elasticity):
    """A scene that finds the impact buffer full stops and is resumed where it stopped by the
    next call: its arithmetic, and so every bit of its result, does not depend on the buffer's
    size or on the other scenes of the batch."""
    scene, pos, vel, radii = gas(150, speed=3.0)
    scene = Scene(bounds=scene.bounds, elasticity=elasticity)
    starts = [(pos, vel * s) for s in (1.0, 0.5, 2.0)]
    masses = np.ones(150)
    batch = BatchSimulator(scene, [p for p, _ in starts], [v for _, v in starts], masses, radii=radii)
    singles = [Simulator(scene, p, v, masses, radii=radii) for p, v in starts]
    batch._stepper._alloc_work(300)  # a few dozen events per call
    for _ in range(3):
        got = batch.step(0.2)
        for k, sim in enumerate(singles):
            want = sim.batch.step(0.2)
            mine = got[got["scene"] == k]
            assert len(mine) > 100
            np.testing.assert_array_equal(
                mine[["time", "ball", "other", "wall", "x", "y"]], want[["time", "ball", "other", "wall", "x", "y"]]
            )
            np.testing.assert_array_equal(batch.positions[k], sim.positions)
            np.testing.assert_array_equal(batch.velocities[k], sim.velocities)
            np.testing.assert_array_equal(batch.time[k], sim.time)


@pytest.mark.parametrize("mode", ["exact", "naive"])
def test_a_simulator_loaded_from_another_steps_exactly_as_the_other_would(mode):
    """``load`` copies a running simulator's whole state, its calendar included: the copy then
    does bit for bit what the original does, with nothing predicted afresh."""
    scene, pos, vel, radii = gas(120)
    starts = np.stack([pos, pos[::-1]]), np.stack([vel, -vel])
    running = BatchSimulator(scene, *starts, np.ones(120), radii=radii, mode=mode)
    planner = BatchSimulator(scene, *starts, np.ones(120), radii=radii, mode=mode, max_events=50_000)
    for _ in range(5):
        running.step(1 / 60)
    planner.load(running)
    if mode == "exact":  # the calendar was taken over, not rebuilt: a step without events predicts nothing
        tests = planner.stats["pair_tests"]
        planner.step(1e-12)
        running.step(1e-12)
        assert planner.stats["pair_tests"] == tests
    ahead = planner.step(0.5)
    np.testing.assert_array_equal(ahead, running.step(0.5))
    np.testing.assert_array_equal(planner.positions, running.positions)
    np.testing.assert_array_equal(planner.time, running.time)


def test_load_refuses_a_simulator_of_another_shape_or_mode():
    scene, pos, vel, radii = gas(20)
    exact = BatchSimulator(scene, pos[None], vel[None], np.ones(20), radii=radii)
    with pytest.raises(ValueError, match="same scene, mode and shape"):
        exact.load(BatchSimulator(scene, pos[None], vel[None], np.ones(20), radii=radii, mode="naive"))
    with pytest.raises(ValueError, match="same scene, mode and shape"):
        exact.load(BatchSimulator(scene, np.stack([pos, pos]), np.stack([vel, vel]), np.ones(20), radii=radii))
    with pytest.raises(TypeError, match="expected a BatchSimulator"):
        exact.load(Simulator(scene, pos, vel, np.ones(20), radii=radii))
