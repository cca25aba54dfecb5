"""The temperature, the pressure and the collision rate: analytic values, exact identities, the
finite-N temperature of a periodic cell against published event-chain Monte Carlo pressures, and
statistical agreement with the fluid's known equation of state and collision rate (loose
tolerances, each explained)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.bench.scale import lattice_gas
from collision_env.engine import Scene, Simulator, disk_gas
from collision_env.observables import (
    PressureAccumulator,
    collision_rate,
    collision_virial,
    enskog_rate,
    henderson_g,
    mean_free_time,
    reduced_pressure,
    temperature,
    wall_pressure,
)

N, RADIUS, PACKING = 200, 0.01, 0.05
BOX = Scene(bounds=(0.0, 0.0, 4.0, 4.0))
CELL = Scene(bounds=(0.0, 0.0, 4.0, 4.0), periodic=True)


@pytest.fixture(scope="module")
def dilute_gas():
    """200 elastic disks at area fraction 0.05 in a square box, melted from a lattice, then run for
    30 s (about 2.5e5 collisions) in 1/60 s frames, with sum r.p before and after."""
    scene, pos, vel = lattice_gas(N, PACKING, RADIUS, seed=1)
    sim = Simulator(scene, pos, vel, np.ones(N), np.full(N, RADIUS))
    sim.frames(1 / 60, 120)

    def r_dot_p():
        return float(np.sum(sim.positions * sim.velocities))  # (unit masses)

    before = r_dot_p()
    duration = 30.0
    imp = sim.frames(1 / 60, round(duration * 60)).impacts
    return sim, imp, duration, r_dot_p() - before


def test_one_head_on_collision_has_the_analytic_virial():
    # equal masses closing at 2 m/s: J = 2 mu u = 2 N s at contact distance 0.5 + 0.25 m; in a box,
    # kT = 2K / (2N) = 0.5 J for K = 1 J, so Z = 1 + W / (2 N kT t) = 1 + 1.5 / 4
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-1, 0]], [1.0, 1.0], [0.5, 0.25])
    imp = sim.step(2.0)
    assert collision_virial(imp, sim.radii) == pytest.approx(0.75 * 2.0, rel=1e-14)
    box = Scene(bounds=(-10.0, -10.0, 10.0, 10.0))
    assert reduced_pressure(imp.array, sim.radii, 2.0, 1.0, scene=box) == pytest.approx(1.0 + 1.5 / 4.0, rel=1e-14)
    # a periodic cell (or no border: momentum is conserved) counts N - 1 = 1 disk's degrees of freedom
    assert reduced_pressure(imp, sim.radii, 2.0, 1.0, scene=sim.scene) == pytest.approx(1.0 + 1.5 / 8.0, rel=1e-14)
    assert collision_rate(imp, 2, 2.0) == 0.5 and mean_free_time(imp, 2, 2.0) == 2.0
    assert mean_free_time(sim.step(1e-9), 2, 1e-9) == math.inf


def test_temperature_counts_the_degrees_of_freedom_the_scene_leaves():
    v = np.array([[3.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    m = np.array([1.0, 2.0, 0.5])
    k = 0.5 * float(np.sum(m * np.sum(v * v, axis=1)))
    p = m @ v
    assert temperature(v, m, BOX) == pytest.approx(2 * k / (2 * 3), rel=1e-15)
    about_centre = k - 0.5 * float(p @ p) / m.sum()
    assert temperature(v, m, CELL) == pytest.approx(2 * about_centre / (2 * 2), rel=1e-14)
    assert temperature(v, m, Scene(bounds=None)) == temperature(v, m, CELL)
    # a 1D scene has one degree of freedom per disk
    line = Scene(bounds=(-2.0, -0.5, 2.0, 0.5), dimension=1)
    assert temperature(v * [1, 0], m, line) == pytest.approx(2 * 0.5 * float(np.sum(m * v[:, 0] ** 2)) / 3)
    # frames: one temperature per frame
    frames = np.stack([v, 2 * v])
    np.testing.assert_allclose(temperature(frames, m, BOX), [temperature(v, m, BOX), 4 * temperature(v, m, BOX)])


@settings(max_examples=50, deadline=None)
@given(
    n=st.integers(2, 40),
    drift=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
    seed=st.integers(0, 2**16),
)
def test_a_periodic_cells_temperature_is_the_mean_over_pairs_of_their_relative_motion(n, drift, seed):
    # equal masses: sum_{i<j} |v_i - v_j|^2 = N sum |v|^2 - |sum v|^2, so the mean over the pairs of
    # mu |u|^2 / d is 2 K' / (d (N - 1)) exactly: the kT of a pair's collisions, whatever the drift
    v = np.random.default_rng(seed).normal(size=(n, 2)) + drift
    m = np.full(n, 1.5)
    i, j = np.triu_indices(n, 1)
    pairs = 0.5 * 0.75 * np.mean(np.sum((v[i] - v[j]) ** 2, axis=1))  # mu = m / 2, d = 2
    assert temperature(v, m, CELL) == pytest.approx(pairs, rel=1e-9)
    assert temperature(v + 7.0, m, CELL) == pytest.approx(temperature(v, m, CELL), rel=1e-6)


def test_temperature_and_pressure_refuse_bad_input():
    v, m = np.ones((3, 2)), np.ones(3)
    with pytest.raises(TypeError, match="scene"):
        temperature(v, m, (0, 0, 1, 1))
    with pytest.raises(ValueError, match="velocities"):
        temperature([[np.nan, 0.0], [0.0, 0.0]], [1.0, 1.0], BOX)
    with pytest.raises(ValueError, match="masses"):
        temperature(v, [1.0, 1.0], BOX)
    with pytest.raises(ValueError, match="masses: ball 1"):
        temperature(v, [1.0, -1.0, 1.0], BOX)
    with pytest.raises(ValueError, match="at least 2 disks"):
        temperature([[1.0, 0.0]], [1.0], CELL)
    imp = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-1, 0]], [1.0, 1.0], [0.5, 0.5]).step(2.0)
    with pytest.raises(TypeError):
        reduced_pressure(imp, [0.5, 0.5], 2.0, 1.0)  # the scene is required
    with pytest.raises(ValueError, match="radii: ball 1"):
        reduced_pressure(imp, [0.5, np.nan], 2.0, 1.0, scene=BOX)
    with pytest.raises(ValueError, match="radii"):
        collision_virial(imp, [0.5])  # fewer radii than the impacts' balls
    with pytest.raises(ValueError, match="duration"):
        reduced_pressure(imp, [0.5, 0.5], 0.0, 1.0, scene=BOX)
    with pytest.raises(ValueError, match="kinetic_energy"):
        reduced_pressure(imp, [0.5, 0.5], 1.0, math.inf, scene=BOX)
    with pytest.raises(ValueError, match="n"):
        collision_rate(imp, 2.5, 1.0)
    with pytest.raises(ValueError, match="radius"):
        wall_pressure(imp, 1.0, BOX.bounds, np.nan)


def test_virial_identity_holds_exactly_over_a_run(dilute_gas):
    # d/dt sum r.p = 2K + sum r.F, integrated: Δ(sum r.p) = 2 K t + W - sum_wall J h, with h the
    # distance from the box's centre (the origin) to the line the centre touches the wall on
    sim, imp, t, delta = dilute_gas
    k = sim.kinetic_energy()
    xmin, ymin, xmax, ymax = sim.scene.bounds
    reach = {"left": -xmin - RADIUS, "right": xmax - RADIUS, "bottom": -ymin - RADIUS, "top": ymax - RADIUS}
    walls = imp[imp["wall"] >= 0]
    wall_virial = sum(j * reach[w] for j, w in zip(walls["impulse"].tolist(), walls.wall_names, strict=True))
    w = collision_virial(imp, sim.radii)
    assert delta == pytest.approx(2 * k * t + w - wall_virial, rel=1e-9, abs=1e-9 * wall_virial)


def test_dilute_gas_pressure_is_one_plus_the_second_virial_term(dilute_gas):
    # Z - 1 = 2 eta g(sigma+) (the contact theorem; Henderson's g): 0.108 at eta = 0.05. 15 %: the
    # walls' layering and the density of the centres' reach (N / A' against N / A, 6 %) at N = 200
    sim, imp, t, _ = dilute_gas
    z = reduced_pressure(imp, sim.radii, t, sim.kinetic_energy(), scene=sim.scene)
    assert z - 1 == pytest.approx(2 * PACKING * henderson_g(PACKING), rel=0.15)


def test_virial_and_wall_pressure_agree(dilute_gas):
    # P_w A' = K + W / (2t) up to the change of sum r.p over the run (|Δ| / (2Kt) ~ L / (4 v t),
    # 0.3 % here) and the corners' share of the walls: 2 % on Z
    sim, imp, t, delta = dilute_gas
    k = sim.kinetic_energy()
    xmin, ymin, xmax, ymax = sim.scene.bounds
    a_reach = (xmax - xmin - 2 * RADIUS) * (ymax - ymin - 2 * RADIUS)
    z_wall = wall_pressure(imp, t, sim.scene.bounds, RADIUS) * a_reach / k
    z_virial = reduced_pressure(imp, sim.radii, t, k, scene=sim.scene)
    assert abs(delta) / (2 * k * t) < 0.01
    assert z_wall == pytest.approx(z_virial, rel=0.02)


def test_collision_rate_is_enskogs_at_low_density(dilute_gas):
    # omega = 2 sqrt(pi) rho sigma g sqrt(kT/m): 10 %, for the density that the walls lower (N / A
    # against the centres' N / A') and the finite N
    sim, imp, t, _ = dilute_gas
    xmin, ymin, xmax, ymax = sim.scene.bounds
    kt = temperature(sim.velocities, sim.masses, sim.scene)
    assert kt == pytest.approx(sim.kinetic_energy() / N, rel=1e-14)  # a box: kT = K / N in 2D
    predicted = enskog_rate(N / ((xmax - xmin) * (ymax - ymin)), 2 * RADIUS, PACKING, kt, 1.0)
    assert collision_rate(imp, N, t) == pytest.approx(predicted, rel=0.10)
    assert mean_free_time(imp, N, t) == pytest.approx(1 / collision_rate(imp, N, t))


def test_a_small_periodic_cell_meets_event_chain_monte_carlo():
    # Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, J. Chem. Phys. 157, 234111 (2022), data in
    # jellyfysh/HistoricDisks (DigitizedData/ThisWork.csv): N = 72, a square periodic cell,
    # phi = 0.65, beta P sigma^2 = 6.901074 +- 7.1e-5. About 1.9e6 collisions give Z to 0.1 %; with
    # the walls' kT = K / N instead, Z - 1 is N / (N - 1) times larger, 1.26 % on Z (about 15 errors)
    gas = disk_gas(72, 0.65, periodic=True, aspect=1.0, seed=3)
    sim = gas.simulator()
    sim.frames(0.05, 400)  # melt: about 330 collisions per disk
    acc = PressureAccumulator(gas.scene, gas.radii, gas.masses, time=sim.time)
    for _ in range(16):
        acc.add(sim.frames(0.05, 4000))
    z = acc.pressure()
    reference = 6.901074 * math.pi / (4 * 0.65)  # Z = beta P sigma^2 pi / (4 phi)
    assert z.reliable and z.error < 2e-3 * reference
    assert abs(z.mean - reference) < 4 * z.error
    walls_kt = 1 + (z.mean - 1) * 72 / 71
    assert abs(walls_kt - reference) > 8 * z.error


def test_the_accumulator_is_the_run_as_one_window():
    # elastic disks: kT is the same every frame, so the frames' mean Z is the whole run's Z, and the
    # collision rate the run's, to round-off, however the run is cut into frames calls
    gas = disk_gas(40, 0.4, periodic=True, seed=2)
    sim = gas.simulator()
    sim.frames(0.1, 20)
    acc = PressureAccumulator(gas.scene, gas.radii, gas.masses, time=sim.time)
    start = sim.time
    impacts = []
    for n in (7, 1, 30, 2):
        rec = sim.frames(0.1, n)
        acc.add(rec)
        impacts.append(rec.impacts.array)
    run = np.concatenate(impacts)
    t = sim.time - start
    assert (
        acc.frames == 40 and acc.duration == pytest.approx(t) and acc.collisions == np.count_nonzero(run["other"] >= 0)
    )
    z = reduced_pressure(run, gas.radii, t, sim.kinetic_energy(), scene=gas.scene)
    assert acc.pressure().mean == pytest.approx(z, rel=1e-9)
    assert acc.collision_rate().mean == pytest.approx(collision_rate(run, 40, t), rel=1e-9)


def test_the_accumulator_refuses_frames_out_of_order_and_takes_none():
    gas = disk_gas(20, 0.3, periodic=True, seed=1)
    sim = gas.simulator()
    rec = sim.frames(0.1, 5)
    acc = PressureAccumulator(gas.scene, gas.radii, gas.masses, time=0.0)
    acc.add(rec)
    with pytest.raises(ValueError, match="follow"):
        acc.add(rec)  # the same frames again
    assert acc.frames == 5
    with pytest.raises(ValueError, match="velocities"):
        acc.add(SimpleNamespace(time=rec.time, velocities=rec.velocities[:, :3], impacts=rec.impacts))
    with pytest.raises(ValueError, match="time"):
        PressureAccumulator(gas.scene, gas.radii, gas.masses, time=math.nan)
    with pytest.raises(ValueError, match="masses"):
        PressureAccumulator(gas.scene, gas.radii, gas.masses[:3], time=0.0)
    assert acc.frames == 5 and acc.pressure().mean > 1.0
