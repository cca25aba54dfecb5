"""Observables: analytic values, exact identities, and statistical agreement with the hard-disk
fluid's known equation of state and collision rate (loose tolerances, each explained)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.bench.scale import lattice_gas
from collision_env.engine import Scene, Simulator
from collision_env.observables import (
    collision_rate,
    collision_virial,
    enskog_rate,
    henderson_g,
    mean_free_time,
    mean_squared_displacement,
    radial_distribution,
    reduced_pressure,
    wall_pressure,
)

N, RADIUS, PACKING = 200, 0.01, 0.05


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
    # equal masses closing at 2 m/s: J = 2 mu u = 2 N s at contact distance 0.5 + 0.25 m
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-1, 0]], [1.0, 1.0], [0.5, 0.25])
    imp = sim.step(2.0)
    assert collision_virial(imp, sim.radii) == pytest.approx(0.75 * 2.0, rel=1e-14)
    assert reduced_pressure(imp.array, sim.radii, 2.0, 1.0) == pytest.approx(1.0 + 1.5 / 4.0, rel=1e-14)
    assert collision_rate(imp, 2, 2.0) == 0.5 and mean_free_time(imp, 2, 2.0) == 2.0
    assert mean_free_time(sim.step(1e-9), 2, 1e-9) == math.inf


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
    z = reduced_pressure(imp, sim.radii, t, sim.kinetic_energy())
    assert z - 1 == pytest.approx(2 * PACKING * henderson_g(PACKING), rel=0.15)


def test_virial_and_wall_pressure_agree(dilute_gas):
    # P_w A' = K + W / (2t) up to the change of sum r.p over the run (|Δ| / (2Kt) ~ L / (4 v t),
    # 0.3 % here) and the corners' share of the walls: 2 % on Z
    sim, imp, t, delta = dilute_gas
    k = sim.kinetic_energy()
    xmin, ymin, xmax, ymax = sim.scene.bounds
    a_reach = (xmax - xmin - 2 * RADIUS) * (ymax - ymin - 2 * RADIUS)
    z_wall = wall_pressure(imp, t, sim.scene.bounds, RADIUS) * a_reach / k
    z_virial = reduced_pressure(imp, sim.radii, t, k)
    assert abs(delta) / (2 * k * t) < 0.01
    assert z_wall == pytest.approx(z_virial, rel=0.02)


def test_collision_rate_is_enskogs_at_low_density(dilute_gas):
    # omega = 2 sqrt(pi) rho sigma g sqrt(kT/m) with kT = K / N (2D): 10 %, for the density that
    # the walls lower (N / A against the centres' N / A') and the finite N
    sim, imp, t, _ = dilute_gas
    xmin, ymin, xmax, ymax = sim.scene.bounds
    predicted = enskog_rate(N / ((xmax - xmin) * (ymax - ymin)), 2 * RADIUS, PACKING, sim.kinetic_energy() / N, 1.0)
    assert collision_rate(imp, N, t) == pytest.approx(predicted, rel=0.10)
    assert mean_free_time(imp, N, t) == pytest.approx(1 / collision_rate(imp, N, t))


def _all_pairs_g(p, bounds, r_max, bins, periodic):
    size = np.array([bounds[2] - bounds[0], bounds[3] - bounds[1]])
    i, j = np.triu_indices(len(p), 1)
    d = p[j] - p[i]
    if periodic:
        d -= size * np.round(d / size)
    counts = np.histogram(np.linalg.norm(d, axis=-1), bins=bins, range=(0.0, r_max))[0]
    edges = np.linspace(0.0, r_max, bins + 1)
    return 2 * counts * size.prod() / (len(p) * (len(p) - 1) * math.pi * np.diff(edges**2))


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(2, 300),
    width=st.floats(0.5, 40.0),
    r_frac=st.floats(0.01, 0.5),
    periodic=st.booleans(),
    edge=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_g_of_r_through_the_grid_is_the_all_pairs_histogram(n, width, r_frac, periodic, edge, seed):
    rng = np.random.default_rng(seed)
    bounds = (-width / 2, -1.0, width / 2, 1.0)
    p = rng.uniform((bounds[0], bounds[1]), (bounds[2], bounds[3]), size=(n, 2))
    if edge:  # disks on the border (the last cell holds them) and at its corners
        p[: n // 2, 0] = bounds[2]
        p[0] = bounds[:2]
    r_max = r_frac * min(width, 2.0) * (1.0 if periodic else 1.9)
    r, g = radial_distribution(p, bounds, r_max, bins=17, periodic=periodic)
    np.testing.assert_allclose(g, _all_pairs_g(p, bounds, r_max, 17, periodic), rtol=1e-12)
    np.testing.assert_allclose(r, (np.arange(17) + 0.5) * r_max / 17)


def test_g_of_r_averages_samples_and_is_one_for_an_ideal_gas():
    rng = np.random.default_rng(0)
    p = rng.uniform(0.0, 10.0, size=(40, 500, 2))
    _, g = radial_distribution(p, (0.0, 0.0, 10.0, 10.0), 1.0, bins=10, periodic=True)
    assert np.all(np.abs(g - 1) < 0.08)  # (about 5e3 pairs per shell: a few % of noise)
    both = radial_distribution(p[:2], (0.0, 0.0, 10.0, 10.0), 1.0, bins=10)[1]
    each = [radial_distribution(s, (0.0, 0.0, 10.0, 10.0), 1.0, bins=10)[1] for s in p[:2]]
    np.testing.assert_allclose(both, np.mean(each, axis=0), rtol=1e-12)


def test_g_of_r_rejects_bad_input():
    with pytest.raises(ValueError, match="r_max"):
        radial_distribution(np.zeros((3, 2)), (0.0, 0.0, 1.0, 1.0), 0.6, periodic=True)
    with pytest.raises(ValueError, match="positions"):
        radial_distribution(np.zeros((1, 2)), (0.0, 0.0, 1.0, 1.0), 0.1)
    with pytest.raises(ValueError, match="positions"):
        radial_distribution([[0.0, np.nan], [0.5, 0.5]], (0.0, 0.0, 1.0, 1.0), 0.1)


def test_msd_of_ballistic_motion_is_v_squared_t_squared():
    rng = np.random.default_rng(5)
    vel = rng.normal(size=(30, 2))
    sim = Simulator(Scene(bounds=None, ball_collisions=False), rng.normal(size=(30, 2)), vel, np.ones(30))
    dt = 0.1
    rec = sim.frames(dt, 50)
    lags, msd = mean_squared_displacement(rec.positions)
    np.testing.assert_array_equal(lags, np.arange(50))
    np.testing.assert_allclose(msd, np.mean(np.sum(vel**2, axis=1)) * (lags * dt) ** 2, rtol=1e-12, atol=1e-24)
    lags, part = mean_squared_displacement(rec.positions, lags=[3, 7])
    np.testing.assert_allclose(part, msd[[3, 7]], rtol=1e-15)
    with pytest.raises(ValueError, match="lags"):
        mean_squared_displacement(rec.positions, lags=[50])
