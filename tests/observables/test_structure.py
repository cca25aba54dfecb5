"""g(r) and the mean squared displacement: the cell list against all pairs, O(N) memory for points
in a clump, the MSD of frames unwrapped by their image counts."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.bench.extremes import clumped_rdf_peak_bytes
from collision_env.engine import Scene, Simulator
from collision_env.observables import mean_squared_displacement, radial_distribution, unwrapped_positions


def _all_pairs_g(p, bounds, r_max, bins, periodic):
    size = np.array([bounds[2] - bounds[0], bounds[3] - bounds[1]])
    i, j = np.triu_indices(len(p), 1)
    d = p[j] - p[i]
    if periodic:
        d -= size * np.round(d / size)
    counts = np.histogram(np.linalg.norm(d, axis=-1), bins=bins, range=(0.0, r_max))[0]
    edges = np.linspace(0.0, r_max, bins + 1)
    return 2 * counts * size.prod() / (len(p) * (len(p) - 1) * math.pi * np.diff(edges**2))


@settings(max_examples=80, deadline=None)
@given(
    n=st.integers(2, 300),
    width=st.floats(0.5, 40.0),
    r_frac=st.floats(0.01, 0.5),
    periodic=st.booleans(),
    edge=st.booleans(),
    clump=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_g_of_r_through_the_grid_is_the_all_pairs_histogram(n, width, r_frac, periodic, edge, clump, seed):
    rng = np.random.default_rng(seed)
    bounds = (-width / 2, -1.0, width / 2, 1.0)
    p = rng.uniform((bounds[0], bounds[1]), (bounds[2], bounds[3]), size=(n, 2))
    if edge:  # disks on the border (the last cell holds them) and at its corners
        p[: n // 2, 0] = bounds[2]
        p[0] = bounds[:2]
    if clump:  # most points in one small patch
        p[: 3 * n // 4] = rng.uniform(0.0, 0.05, size=(3 * n // 4, 2))
    r_max = r_frac * min(width, 2.0) * (1.0 if periodic else 1.9)
    r, g = radial_distribution(p, bounds, r_max, bins=17, periodic=periodic)
    np.testing.assert_allclose(g, _all_pairs_g(p, bounds, r_max, 17, periodic), rtol=1e-12)
    np.testing.assert_allclose(r, (np.arange(17) + 0.5) * r_max / 17)


def test_g_of_r_in_pieces_is_g_of_r_whole(monkeypatch):
    # pairs measured a chunk at a time, down to one point's candidates per chunk
    from collision_env.observables import structure

    rng = np.random.default_rng(3)
    p = rng.uniform(0.0, 10.0, size=(400, 2))
    whole = radial_distribution(p, (0.0, 0.0, 10.0, 10.0), 2.0, bins=20, periodic=True)[1]
    monkeypatch.setattr(structure, "PAIR_CHUNK", 7)
    pieces = radial_distribution(p, (0.0, 0.0, 10.0, 10.0), 2.0, bins=20, periodic=True)[1]
    np.testing.assert_array_equal(whole, pieces)


def test_g_of_r_of_points_in_a_clump_needs_memory_of_order_n():
    # (on d8ab1a0 2,600 points, 600 in one patch, took 1.8 GB: cells x the fullest cell's count^2)
    peak = clumped_rdf_peak_bytes()
    assert peak < 50e6  # (about 180,000 pairs in the clump's cell: a few MB)


def test_g_of_r_averages_samples_and_is_one_for_an_ideal_gas():
    rng = np.random.default_rng(0)
    p = rng.uniform(0.0, 10.0, size=(40, 500, 2))
    _, g = radial_distribution(p, (0.0, 0.0, 10.0, 10.0), 1.0, bins=10, periodic=True)
    assert np.all(np.abs(g - 1) < 0.08)  # (about 5e3 pairs per shell: a few % of noise)
    both = radial_distribution(p[:2], (0.0, 0.0, 10.0, 10.0), 1.0, bins=10)[1]
    each = [radial_distribution(s, (0.0, 0.0, 10.0, 10.0), 1.0, bins=10)[1] for s in p[:2]]
    np.testing.assert_allclose(both, np.mean(each, axis=0), rtol=1e-12)


def test_g_of_r_rejects_bad_input():
    box = (0.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="r_max"):
        radial_distribution(np.zeros((3, 2)), box, 0.6, periodic=True)
    with pytest.raises(ValueError, match="positions"):
        radial_distribution(np.zeros((1, 2)), box, 0.1)
    with pytest.raises(ValueError, match="positions"):
        radial_distribution([[0.0, np.nan], [0.5, 0.5]], box, 0.1)
    with pytest.raises(ValueError, match="bins"):
        radial_distribution(np.zeros((3, 2)), box, 0.1, bins=2.5)
    with pytest.raises(ValueError, match="bounds"):
        radial_distribution(np.zeros((3, 2)), (0.0, 0.0, np.inf, 1.0), 0.1)
    with pytest.raises(ValueError, match="r_max"):
        radial_distribution(np.zeros((3, 2)), box, np.nan)


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
    lags, whole_floats = mean_squared_displacement(rec.positions, lags=np.array([3.0, 7.0]))
    np.testing.assert_array_equal(whole_floats, part)
    for bad in ([50], [1.5], [-1], [[1]], [True]):  # a lag of 1.5 was truncated to 1 on d8ab1a0
        with pytest.raises(ValueError, match="lags"):
            mean_squared_displacement(rec.positions, lags=bad)


def _recorded(sim, dt, n):
    """A Simulator's frames with their image counts, recorded step by step (a stand-in for
    ``Simulator.frames`` with ``Frames.images``)."""
    time, positions, velocities, images = [], [], [], []
    for _ in range(n):
        sim.step(dt)
        time.append(sim.time)
        positions.append(sim.positions)
        velocities.append(sim.velocities)
        images.append(sim.images)
    return SimpleNamespace(
        time=np.array(time), positions=np.array(positions), velocities=np.array(velocities), images=np.array(images)
    )


def test_msd_of_frames_undoes_the_periodic_cells_wrapping():
    # free flight through a small periodic cell, many laps: the unwrapped MSD is ballistic
    cell = Scene(bounds=(0.0, 0.0, 1.0, 2.0), periodic=True, ball_collisions=False)
    rng = np.random.default_rng(1)
    vel = rng.normal(0.0, 3.0, size=(10, 2))
    sim = Simulator(cell, rng.uniform(0.0, 1.0, size=(10, 2)), vel, np.ones(10), np.full(10, 0.05))
    frames = _recorded(sim, 0.1, 60)
    assert np.abs(frames.images).max() > 3
    np.testing.assert_allclose(unwrapped_positions(frames, cell)[-1], sim.unwrapped_positions, rtol=1e-15)
    lags, msd = mean_squared_displacement(frames, scene=cell)
    np.testing.assert_allclose(msd, np.mean(np.sum(vel**2, axis=1)) * (lags * 0.1) ** 2, rtol=1e-9, atol=1e-20)
    # a batch's frames (F, B, N, 2): one MSD per scene
    batch = SimpleNamespace(positions=np.stack([frames.positions] * 3, 1), images=np.stack([frames.images] * 3, 1))
    lags, per_scene = mean_squared_displacement(batch, scene=cell)
    assert per_scene.shape == (60, 3)
    np.testing.assert_allclose(per_scene, np.repeat(msd[:, None], 3, 1), rtol=1e-14)
    with pytest.raises(ValueError, match="scene"):
        mean_squared_displacement(frames)
    with pytest.raises(ValueError, match="scene"):
        mean_squared_displacement(frames.positions, scene=cell)
    with pytest.raises(ValueError, match="images"):
        unwrapped_positions(SimpleNamespace(positions=frames.positions, images=frames.images[:, :3]), cell)
