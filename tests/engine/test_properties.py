"""Property tests at the extremes: invariants after every step, in every mode.

Speeds 1e-6 to 1e4 m/s, mass ratios up to 1e9, e in {0, 0.05, 0.5, 1}, dt 1e-4 to 0.5 s, 1D and
2D, border on and off, slip and stick. After every step: no NaN, nobody outside a reflecting
border, no overlap beyond round-off (exact mode: the cheap modes' overlaps are their documented
trade), energy never grows, momentum conserved when only ball-ball collisions act, and the step
returns in bounded time (the event cap bounds exact mode; reaching it is allowed and reported),
and its state is one that ``set_state`` accepts.
"""

import time
import warnings

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collision_env.engine import EventCapWarning, Scene, Simulator

ROUNDOFF = 1e-9  # relative: positions carry ~1e-16 relative error per event, over many events


@st.composite
def scenes(draw):
    mode = draw(st.sampled_from(["exact", "exact", "posteriori", "naive"]))
    dim = draw(st.sampled_from([1, 2]))
    border = draw(st.booleans()) or draw(st.booleans())  # mostly on
    e = draw(st.sampled_from([0.0, 0.05, 0.5, 1.0]))
    stick = e == 0.0 and draw(st.booleans())
    n = draw(st.integers(1, 6))
    speed = 10.0 ** draw(st.floats(-6, 4))
    log_ratio = draw(st.floats(0, 9))
    dt = 10.0 ** draw(st.floats(-4, np.log10(0.5)))
    seed = draw(st.integers(0, 2**32 - 1))
    substeps = draw(st.sampled_from([1, 1, 2, 8])) if mode != "exact" else 1
    rng = np.random.default_rng(seed)
    # non-overlapping start: one ball per cell of a 6 x 3 grid (6 x 1 in 1D), jittered
    cells = rng.choice(18 if dim == 2 else 6, size=n, replace=False)
    radius = rng.uniform(0.02, 0.25, n)
    cx = -2 + (cells % 6 + 0.5) * (4 / 6)
    cy = -1 + (cells // 6 + 0.5) * (2 / 3) if dim == 2 else np.zeros(n)
    slack = 4 / 12 - radius
    pos = np.column_stack(
        [
            cx + rng.uniform(-1, 1, n) * slack,
            cy + (rng.uniform(-1, 1, n) * np.minimum(slack, 1 / 3 - radius) if dim == 2 else 0),
        ]
    )
    vel = rng.normal(size=(n, 2)) * speed
    if dim == 1:
        vel[:, 1] = 0.0
    masses = 10.0 ** (rng.uniform(0, 1, n) * log_ratio - log_ratio / 2)
    bounds = ((-2.0, -1.0, 2.0, 1.0) if dim == 2 else (-2.0, -0.55, 2.0, 0.55)) if border else None
    scene = Scene(bounds=bounds, elasticity=e, dimension=dim, inelastic="stick" if stick else "slip")
    sim = Simulator(scene, pos, vel, masses, radii=radius, mode=mode, substeps=substeps)
    return sim, dt


def check_invariants(sim, energy_before, momentum_before):
    p, v, r = sim.positions, sim.velocities, sim.radii
    assert np.isfinite(p).all() and np.isfinite(v).all(), "NaN or inf in the state"
    scale = 1.0 + np.abs(p).max()
    b = sim.scene.bounds
    if b is not None:
        tol = ROUNDOFF * scale
        assert np.all(p[:, 0] - r >= b[0] - tol) and np.all(p[:, 0] + r <= b[2] + tol), "escaped in x"
        if sim.scene.dimension == 2:
            assert np.all(p[:, 1] - r >= b[1] - tol) and np.all(p[:, 1] + r <= b[3] + tol), "escaped in y"
    if sim.scene.dimension == 1:
        assert np.all(p[:, 1] == 0) and np.all(v[:, 1] == 0)
    if sim.mode == "exact" and len(r) > 1:
        d = np.linalg.norm(p[:, None] - p[None], axis=-1)
        sigma = r[:, None] + r[None]
        off = ~np.eye(len(r), dtype=bool)
        assert np.all(d[off] >= sigma[off] - ROUNDOFF * scale), "overlap beyond round-off"
    energy = sim.kinetic_energy()
    assert energy <= energy_before * (1 + 1e-12) + 1e-300, f"energy grew: {energy_before} -> {energy}"
    if b is None:
        m = sim.momentum()
        tol = 1e-12 * max(np.abs(momentum_before).max(), (sim.masses * np.linalg.norm(v, axis=1)).sum())
        assert np.all(np.abs(m - momentum_before) <= tol), "momentum not conserved"
    return energy


@settings(max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenes())
def test_invariants_at_the_extremes(case):
    sim, dt = case
    energy = sim.kinetic_energy()
    momentum = sim.momentum()
    for _ in range(10):
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", EventCapWarning)  # allowed: reported, state stays valid
            sim.step(dt)
        assert time.perf_counter() - start < 5.0, "a step took too long"
        energy = check_invariants(sim, energy, momentum)
        sim.copy().set_state(sim.get_state())  # every state a step leaves is one set_state takes


@settings(max_examples=60, deadline=None)
@given(scenes())
def test_batch_of_scenes_equals_scenes_one_by_one(case):
    """One engine: a batch steps exactly like its scenes stepped alone."""
    from collision_env.engine import BatchSimulator

    sim, dt = case
    other = sim.copy()
    other.nudge(np.where(sim.scene.dimension == 1, [1.0, 0.0], [1.0, -0.5]) * 0.1 * np.ones((sim.batch.num_balls, 2)))
    batch = BatchSimulator(
        sim.scene,
        [sim.positions, other.positions],
        [sim.velocities, other.velocities],
        [sim.masses, other.masses],
        [sim.radii, other.radii],
        mode=sim.mode,
        substeps=sim.batch.substeps,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", EventCapWarning)
        for _ in range(4):
            rows = batch.step(dt)
            singles = [sim.step(dt), other.step(dt)]
            for k, impacts in enumerate(singles):
                mine = rows[rows["scene"] == k]
                assert len(mine) == len(impacts)
                assert [(h.ball, h.time) for h in impacts] == list(
                    zip(mine["ball"].tolist(), mine["time"].tolist(), strict=True)
                )
    np.testing.assert_array_equal(batch.positions, [sim.positions, other.positions])
    np.testing.assert_array_equal(batch.velocities, [sim.velocities, other.velocities])
