"""The benchmark's metric code on small hand-made cases (the study runs themselves are not tests)."""

import math

import numpy as np
import pytest

from collision_env.bench import metrics as M
from collision_env.engine import IMPACT_DTYPE, Scene, Simulator


def _imp(rows):
    return M.as_impacts(rows)


# ------------------------------------------------------------------ impact matching
def test_match_pairs_missed_and_spurious():
    ref = _imp(
        [
            (1.00, 0, 1, None, 0.0, 0.0),  # matched (run reports the pair the other way round)
            (2.00, 0, None, "left", -2.0, 0.1),  # matched
            (3.00, 1, 2, None, 0.5, 0.5),  # missed: the run never sees pair (1, 2): tunnelled
            (4.00, 0, None, "top", 0.3, 1.0),  # missed: the run's top impact is too late
        ]
    )
    run = _imp(
        [
            (1.01, 1, 0, None, 0.0, 0.02),
            (2.02, 0, None, "left", -2.0, 0.1),
            (2.50, 0, 2, None, 1.0, 1.0),  # spurious: the reference has no (0, 2) impact
            (4.50, 0, None, "top", 0.3, 1.0),  # spurious: outside the window of the reference's
        ]
    )
    m = M.match_impacts(run, ref, window=0.1)
    assert sorted(zip(m.run_index.tolist(), m.ref_index.tolist(), strict=False)) == [(0, 0), (1, 1)]
    assert m.missed.tolist() == [2, 3]
    assert m.spurious.tolist() == [2, 3]
    assert m.tunnelled == [(1, 2)]
    np.testing.assert_allclose(sorted(m.time_error), [0.01, 0.02], atol=1e-12)
    np.testing.assert_allclose(sorted(m.point_error), [0.0, 0.02], atol=1e-12)
    s = m.summary()
    assert (s["matched"], s["missed"], s["spurious"], s["tunnelled_pairs"]) == (2, 2, 2, 1)
    assert s["t_err_max"] == pytest.approx(0.02)


def test_match_is_one_to_one_and_nearest_first():
    # two reference impacts of one pair, three run impacts near them: the nearest pair first,
    # and no impact is used twice
    ref = _imp([(1.0, 0, 1, None), (1.2, 0, 1, None)])
    run = _imp([(1.05, 0, 1, None), (1.16, 0, 1, None), (1.19, 0, 1, None)])
    m = M.match_impacts(run, ref, window=0.5)
    pairs = dict(zip(m.ref_index.tolist(), m.run_index.tolist(), strict=False))
    assert pairs == {1: 2, 0: 0}  # 1.19 <-> 1.2 (0.01) first; then 1.05 <-> 1.0 (0.05) beats 1.16 <-> 1.0
    assert m.spurious.tolist() == [1]
    assert len(m.missed) == 0
    assert m.tunnelled == []


def test_match_many_impacts_of_one_pair_at_one_instant():
    # a contact group resolved at one instant reports the same pair several times at the same time,
    # and in a different order in another run: all must pair up
    ref = _imp([(0.5, 0, 1, None)] * 6 + [(0.5, 1, 2, None)] * 6 + [(0.7, 0, 1, None)])
    run = _imp([(0.5, 1, 2, None)] * 6 + [(0.5, 1, 0, None)] * 6 + [(0.7, 0, 1, None)])
    m = M.match_impacts(run, ref, window=1.0, neighbours=2)
    assert m.matched == 13 and len(m.missed) == len(m.spurious) == 0
    # times that differ by round-off, interleaved: still one to one, nothing left over
    ref = _imp([(t, 44, 45, None) for t in (0.513477, 0.513477, 0.513993, 0.514317, 0.514885, 1.78)])
    run = _imp([(t, 44, 45, None) for t in (0.513186, 0.513186, 0.513697, 0.514014, 0.514576, 1.78)])
    m = M.match_impacts(run, ref, window=0.2)
    assert m.matched == 6 and m.time_error.max() < 2e-3


def test_match_keys_walls_apart():
    # the same ball at the same time on two different walls (a corner) are two impacts
    ref = _imp([(1.0, 0, None, "right"), (1.0, 0, None, "top")])
    run = _imp([(1.0, 0, None, "top")])
    m = M.match_impacts(run, ref, window=1e-9)
    assert m.ref_index.tolist() == [1]
    assert m.missed.tolist() == [0]
    assert m.tunnelled == []  # walls are not ball pairs


def test_match_empty_and_identical():
    empty = M.as_impacts([])
    ref = _imp([(0.5, 0, 1, None, 1.0, 2.0)])
    m = M.match_impacts(empty, ref, window=1.0)
    assert (m.matched, len(m.missed), len(m.spurious), m.tunnelled) == (0, 1, 0, [(0, 1)])
    m = M.match_impacts(ref, ref, window=0.0)
    assert m.matched == 1 and m.time_error.tolist() == [0.0]
    assert math.isnan(M.match_impacts(empty, empty, 1.0).summary()["t_err_median"])


def test_as_impacts_accepts_engine_outputs():
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5])
    batch = sim.copy().batch.step(2.0).array
    assert batch.dtype == IMPACT_DTYPE
    objects = sim.step(2.0).to_list()
    a, b = M.as_impacts(batch), M.as_impacts(objects)
    assert len(a) == len(b) == 1
    assert a[0]["time"] == pytest.approx(1.088256, abs=1e-6)
    assert a.tolist() == b.tolist()
    assert M.impact_keys(a) == [(0, 1, -1)]


# ------------------------------------------------------------------ conservation and validity
def test_drift_scalar_and_vector():
    assert M.drift([2.0, 2.0, 2.1, 1.8]) == pytest.approx(0.1)  # |1.8 - 2| / 2
    assert M.drift([1.0, 1.0], reference=[1.5, 0.5], scale=1.0) == pytest.approx(0.5)
    p = np.array([[3.0, 4.0], [3.0, 4.0], [3.0, 4.5]])  # |p0| = 5
    assert M.drift(p) == pytest.approx(0.1)
    assert M.drift([0.0, 0.0, 1e-3]) == pytest.approx(1e-3)  # zero scale: absolute


def test_energy_momentum_helpers():
    vel = np.array([[1.0, 0.0], [0.0, -2.0]])
    m = np.array([2.0, 0.5])
    assert M.kinetic_energy(vel, m) == pytest.approx(0.5 * 2 * 1 + 0.5 * 0.5 * 4)
    np.testing.assert_allclose(M.momentum(vel, m), [2.0, -1.0])
    series = np.stack([vel, vel * 1.01])  # (T, N, 2)
    ke = M.kinetic_energy(series, m)
    assert M.drift(ke) == pytest.approx(1.01**2 - 1)


def test_final_state_error():
    dx, dv = M.final_state_error(
        [[0, 0], [1, 1]], [[1, 0], [0, 0]], [[0, 0.1], [1, 1]], [[1, 0], [0, 0.5]], radii=[0.2, 0.1], speed_scale=2.0
    )
    assert dx == pytest.approx(0.5)
    assert dv == pytest.approx(0.25)


def test_escapes_penetration_overlap():
    bounds = (-1.0, -1.0, 1.0, 1.0)
    pos = np.array(
        [[[0.0, 0.0], [0.95, 0.0], [0.0, 0.5]], [[0.0, 0.0], [1.05, 0.0], [0.0, 0.5]]]
    )  # ball 1 crosses the right wall at t=1
    r = np.array([0.1, 0.1, 0.3])
    assert M.escapes(pos, bounds).tolist() == [False, True, False]
    assert M.escapes(pos[0], bounds).tolist() == [False, False, False]
    assert not M.escapes(pos, None).any()
    assert M.wall_penetration(pos[0], r, bounds) == pytest.approx(0.5)  # 0.05 into the wall, r = 0.1
    assert M.wall_penetration(pos[:, :1], r[:1], bounds) == 0.0
    # balls 0 and 2: centres 0.5 apart, radii sum 0.4: no overlap; move ball 2 to 0.3
    assert M.max_overlap(pos, r) == 0.0
    pos[1, 2] = [0.0, 0.3]
    assert M.max_overlap(pos, r) == pytest.approx(0.25)  # (0.4 - 0.3) / 0.4
    assert M.max_overlap(pos[:, :1], r[:1]) == 0.0


def test_collisions_per_ball_and_short_horizon():
    imp = _imp([(0.1, 0, None, "left"), (0.2, 0, 1, None), (0.3, 1, None, "top"), (0.4, 0, 1, None)])
    np.testing.assert_array_equal(M.collisions_per_ball(imp, 3), [3, 3, 0])
    # per-ball running mean over 2 balls: 0.5, 1.5, 2.0, 3.0 -> 1.5 first reached at the 2nd impact
    assert M.short_horizon(imp, 2, per_ball=1.5) == pytest.approx(0.25)
    assert M.short_horizon(imp, 2, per_ball=10, default=-1.0) == -1.0


# ------------------------------------------------------------------ statistics
def test_ks_rayleigh_accepts_rayleigh_and_rejects_equal_speeds():
    rng = np.random.default_rng(0)
    n = 4000
    kT, m = 0.7, 2.0
    v = np.hypot(*rng.normal(0.0, math.sqrt(kT / m), (2, n)))
    assert M.ks_rayleigh(v, m) < M.ks_critical(n)
    assert M.ks_rayleigh(v, m, kT=kT) < M.ks_critical(n)
    assert M.ks_rayleigh(np.ones(n)) > 0.3  # a delta at the mean energy is far from Rayleigh
    # several masses, each with its own Rayleigh scale
    masses = rng.choice([0.5, 3.0], n)
    v = np.hypot(*rng.normal(0.0, 1.0, (2, n))) * np.sqrt(kT / masses)
    assert M.ks_rayleigh(v, masses) < M.ks_critical(n)
    assert M.ks_rayleigh(v) > M.ks_critical(n)  # ignoring the masses is wrong
    assert M.ks_critical(100) == pytest.approx(0.1358, abs=1e-4)
