"""Starting states for hard-disk studies: the asked area fraction, no overlap, the asked temperature."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine.gas import CLOSE_PACKED, RANDOM_MAX, disk_gas


def smallest_gap(gas):
    """The smallest surface-to-surface distance between two disks (all pairs)."""
    p, r = gas.positions, gas.radii
    d = np.sqrt(((p[:, None] - p[None]) ** 2).sum(-1))
    np.fill_diagonal(d, np.inf)
    return float((d - (r[:, None] + r[None])).min())


def inside(gas):
    x0, y0, x1, y1 = gas.scene.bounds
    p, r = gas.positions, gas.radii[:, None]
    return bool(((p - r >= (x0, y0)) & (p + r <= (x1, y1))).all())


@given(
    n=st.integers(2, 300),
    fraction=st.floats(0.01, 1.0),
    arrangement=st.sampled_from(["lattice", "random"]),
    diameters=st.sampled_from([(1.0,), (1.0, 1.4), (0.3, 2.0, 1.0)]),
    seed=st.integers(0, 2**32 - 1),
)
@settings(max_examples=60, deadline=None)
def test_a_gas_has_the_asked_area_fraction_and_no_overlap(n, fraction, arrangement, diameters, seed):
    limit = RANDOM_MAX if arrangement == "random" else CLOSE_PACKED
    try:
        gas = disk_gas(n, fraction * limit, arrangement=arrangement, diameters=diameters, seed=seed)
    except ValueError as error:  # a box too tight for this arrangement: refused, and said so
        assert "packing_fraction" in str(error)
        return
    assert gas.packing_fraction == pytest.approx(fraction * limit, rel=1e-12)
    assert smallest_gap(gas) >= 0.0
    assert inside(gas)
    assert np.array_equal(gas.radii, 0.5 * np.array(diameters)[np.arange(n) % len(diameters)])
    # Maxwell-Boltzmann velocities at kT = 1, the centre of mass at rest
    assert gas.kinetic_energy() == pytest.approx(n, rel=1e-12)
    assert np.abs(gas.velocities.sum(0)).max() <= 1e-12 * n


def test_the_dense_lattice_reaches_high_area_fractions_and_runs():
    gas = disk_gas(400, 0.68, seed=2)
    assert gas.packing_fraction == pytest.approx(0.68) and smallest_gap(gas) > 0.0
    sim = gas.simulator()
    sim.step(0.5)
    assert sim.time == pytest.approx(0.5)
    assert sim.kinetic_energy() == pytest.approx(gas.kinetic_energy(), rel=1e-12)


def test_velocities_follow_maxwell_boltzmann():
    gas = disk_gas(20_000, 0.2, mass=2.0, temperature=3.0, seed=5)
    vx = gas.velocities[:, 0]
    assert vx.std() == pytest.approx(math.sqrt(3.0 / 2.0), rel=0.02)
    # a Gaussian's fourth moment is three squared variances
    assert np.mean(vx**4) / np.mean(vx**2) ** 2 == pytest.approx(3.0, rel=0.05)


def test_the_same_seed_gives_the_same_gas():
    a, b = disk_gas(200, 0.4, arrangement="random", seed=7), disk_gas(200, 0.4, arrangement="random", seed=7)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(n=1, packing_fraction=0.3), "n: must be an integer of at least 2"),
        (dict(n=2.5, packing_fraction=0.3), "n: must be an integer"),
        (dict(n=10, packing_fraction=0.0), "packing_fraction: must be in"),
        (dict(n=10, packing_fraction=0.95), "packing_fraction: must be in"),
        (dict(n=10, packing_fraction=0.6, arrangement="random"), "packing_fraction: must be in"),
        (dict(n=10, packing_fraction=True), "packing_fraction: must be in"),
        (dict(n=4096, packing_fraction=0.9), "do not fit a triangular lattice"),
        (dict(n=10, packing_fraction=0.3, arrangement="hexagonal"), "arrangement: must be"),
        (dict(n=10, packing_fraction=0.3, diameters=(1.0, -1.0)), "diameters: expected positive"),
        (dict(n=10, packing_fraction=0.3, mass=0.0), "mass: must be positive"),
        (dict(n=10, packing_fraction=0.3, temperature=math.inf), "temperature: must be positive"),
        (dict(n=2, packing_fraction=0.6, aspect=3.0), "box is .* too narrow"),
        (dict(n=8, packing_fraction=0.3, periodic=True, aspect=20.0), "periodic cell is .* too narrow"),
    ],
)
def test_bad_input_is_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        disk_gas(**kwargs)


def smallest_periodic_gap(gas):
    """The smallest surface-to-surface distance between two disks, through the nearest images."""
    x0, y0, x1, y1 = gas.scene.bounds
    size = np.array([x1 - x0, y1 - y0])
    d = gas.positions[:, None] - gas.positions[None]
    d -= size * np.round(d / size)
    dist = np.sqrt((d**2).sum(-1))
    np.fill_diagonal(dist, np.inf)
    return float((dist - (gas.radii[:, None] + gas.radii[None])).min())


@given(
    n=st.integers(8, 300),
    fraction=st.floats(0.01, 1.0),
    arrangement=st.sampled_from(["lattice", "random"]),
    seed=st.integers(0, 2**32 - 1),
)
@settings(max_examples=40, deadline=None)
def test_a_periodic_gas_fills_its_cell_without_overlap_across_the_edges(n, fraction, arrangement, seed):
    limit = RANDOM_MAX if arrangement == "random" else CLOSE_PACKED
    try:
        gas = disk_gas(n, fraction * limit, arrangement=arrangement, periodic=True, seed=seed)
    except ValueError as error:
        assert "packing_fraction" in str(error)
        return
    x0, y0, x1, y1 = gas.scene.bounds
    assert gas.scene.periodic
    assert gas.packing_fraction == pytest.approx(fraction * limit, rel=1e-12)
    assert ((gas.positions >= (x0, y0)) & (gas.positions < (x1, y1))).all()
    assert smallest_periodic_gap(gas) >= 0.0


def test_a_dense_periodic_lattice_runs_and_conserves_momentum():
    gas = disk_gas(256, 0.7, periodic=True, seed=4)
    sim = gas.simulator()
    sim.step(1.0)
    assert sim.time == pytest.approx(1.0)
    assert np.abs(sim.momentum()).max() <= 1e-12 * 256
    assert sim.kinetic_energy() == pytest.approx(gas.kinetic_energy(), rel=1e-12)


@given(
    n=st.integers(2, 200),
    fraction=st.floats(0.01, 1.0),
    arrangement=st.sampled_from(["lattice", "random"]),
    periodic=st.booleans(),
    aspect=st.one_of(st.floats(0.2, 5.0), st.tuples(st.floats(0.5, 10.0), st.floats(0.5, 10.0))),
    seed=st.integers(0, 2**32 - 1),
)
@settings(max_examples=60, deadline=None)
def test_a_gas_takes_the_shape_asked_for(n, fraction, arrangement, periodic, aspect, seed):
    limit = RANDOM_MAX if arrangement == "random" else CLOSE_PACKED
    try:
        gas = disk_gas(n, fraction * limit, arrangement=arrangement, periodic=periodic, aspect=aspect, seed=seed)
    except ValueError as error:
        assert "packing_fraction" in str(error)
        return
    x0, y0, x1, y1 = gas.scene.bounds
    ratio = aspect if isinstance(aspect, float) else aspect[1] / aspect[0]
    assert (y1 - y0) / (x1 - x0) == pytest.approx(ratio, rel=1e-12)
    assert gas.packing_fraction == pytest.approx(fraction * limit, rel=1e-12)
    if periodic:
        assert ((gas.positions >= (x0, y0)) & (gas.positions < (x1, y1))).all()
        assert smallest_periodic_gap(gas) >= 0.0
    else:
        assert inside(gas) and smallest_gap(gas) >= 0.0


@pytest.mark.parametrize(
    "n, aspect, per_row, rows",
    [
        (72, (9, 8 * math.sqrt(3) / 2), 9, 8),  # Li et al.'s (9 : 8 sqrt(3)/2) cell of 72 disks
        (64, (1, math.sqrt(3) / 2), 8, 8),  # a 1 : sqrt(3)/2 cell
        (870, (29, 30 * math.sqrt(3) / 2), 29, 30),
        (72, None, 9, 8),  # the most nearly square of 72 disks' cells
    ],
)
def test_a_crystal_tiles_its_cell(n, aspect, per_row, rows):
    gas = disk_gas(n, 0.7, arrangement="crystal", periodic=True, aspect=aspect, seed=1)
    width, height = gas.scene.period
    a = width / per_row
    assert height == pytest.approx(rows * a * math.sqrt(3) / 2, rel=1e-12)
    assert gas.packing_fraction == pytest.approx(0.7, rel=1e-12)
    # every disk has six neighbours at the spacing a, through the cell's edges too
    d = gas.positions[:, None] - gas.positions[None]
    d -= np.array([width, height]) * np.round(d / (width, height))
    dist = np.sqrt((d**2).sum(-1))
    assert ((np.abs(dist - a) < 1e-9 * a).sum(1) == 6).all()
    np.fill_diagonal(dist, np.inf)
    assert dist.min() == pytest.approx(a, rel=1e-12)


def test_a_crystal_refuses_what_it_cannot_tile():
    with pytest.raises(ValueError, match="n must be even"):
        disk_gas(71, 0.7, arrangement="crystal", periodic=True)
    with pytest.raises(ValueError, match=r"72 disks tile no periodic cell .* the nearest are 9 x 8 rows"):
        disk_gas(72, 0.7, arrangement="crystal", periodic=True, aspect=(1, math.sqrt(3) / 2))
    with pytest.raises(ValueError, match="periodic=True"):
        disk_gas(72, 0.7, arrangement="crystal")
    with pytest.raises(ValueError, match="do not fit"):
        disk_gas(72, 0.9, arrangement="crystal", periodic=True, aspect=(9, 8 * math.sqrt(3) / 2), diameters=(1, 1.4))
    for aspect in (0.0, -1.0, math.nan, (1.0,) * 3, (1.0, math.inf), "wide"):
        with pytest.raises(ValueError, match="aspect"):
            disk_gas(72, 0.5, aspect=aspect)


def test_a_periodic_gas_has_the_temperature_asked_for():
    # its centre of mass at rest takes two degrees of freedom: K = (N - 1) kT
    from collision_env.observables import temperature

    for periodic, k in ((True, 99 * 1.5), (False, 100 * 1.5)):
        gas = disk_gas(100, 0.3, periodic=periodic, temperature=1.5, seed=2)
        assert temperature(gas.velocities, gas.masses, gas.scene) == pytest.approx(1.5, rel=1e-12)
        assert gas.kinetic_energy() == pytest.approx(k, rel=1e-12)
