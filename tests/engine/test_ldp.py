"""The least-distance solver behind exact mode's contact-cascade limit: NNLS and LDP optimality."""

import numpy as np
import pytest

from collision_env.engine.physics.ldp import least_distance, nnls


def test_nnls_matches_the_unconstrained_solution_when_it_is_positive():
    e = np.array([[2.0, 0.0], [0.0, 4.0], [0.0, 0.0]])
    f = np.array([2.0, 2.0, 1.0])
    assert np.allclose(nnls(e, f), [1.0, 0.5])


def test_nnls_clamps_a_negative_coefficient_to_zero():
    e = np.eye(2)
    f = np.array([3.0, -1.0])
    assert np.allclose(nnls(e, f), [3.0, 0.0])


@pytest.mark.parametrize("seed", range(40))
def test_nnls_satisfies_the_kkt_conditions(seed):
    rng = np.random.default_rng(seed)
    rows, m = rng.integers(1, 9, 2)
    e = rng.normal(size=(rows, m))
    f = rng.normal(size=rows)
    u = nnls(e, f)
    grad = e.T @ (e @ u - f)  # gradient of |E u - f|^2 / 2
    assert np.all(u >= 0)
    assert np.all(grad >= -1e-9)  # no descent direction into u >= 0
    assert np.allclose(u * grad, 0, atol=1e-9)  # complementarity


def test_ldp_single_constraint_is_the_projection_onto_its_half_space():
    g = np.array([[3.0, 4.0]])
    x, ok = least_distance(g, np.array([10.0]))
    assert ok and np.allclose(x, [1.2, 1.6])


def test_ldp_returns_zero_when_zero_is_feasible():
    x, ok = least_distance(np.array([[1.0, 0.0], [0.0, 1.0]]), np.array([-1.0, 0.0]))
    assert ok and np.all(x == 0)


def test_ldp_reports_infeasible_constraints():
    # x >= 1 and -x >= 0 (a ball that should leave two opposite walls at once)
    x, ok = least_distance(np.array([[1.0], [-1.0]]), np.array([1.0, 0.0]))
    assert not ok and np.all(x == 0)


@pytest.mark.parametrize("seed", range(25))
def test_ldp_is_feasible_and_optimal(seed):
    rng = np.random.default_rng(seed)
    m, d = rng.integers(1, 9, 2)
    g = rng.normal(size=(m, d)) * 10.0 ** rng.uniform(-6, 0, size=(m, 1))  # rows of very different scale
    x0 = rng.normal(size=d) * 10.0 ** rng.uniform(-3, 3)
    h = g @ x0 - rng.exponential(size=m) * rng.integers(0, 2, size=m) * np.abs(g @ x0).mean()  # x0 is feasible
    x, ok = least_distance(g, h)
    assert ok
    assert x @ x <= x0 @ x0 * (1 + 1e-9)  # no longer than the feasible point we know
    scale = np.abs(h).max() + 1e-300
    assert np.all(g @ x >= h - 1e-9 * scale)
    # optimality, against an independent method: Dykstra's alternating projections onto the
    # half-spaces converge to the projection of 0 onto their intersection
    y = np.zeros(d)
    corr = np.zeros((m, d))
    for _ in range(2_000):
        for c in range(m):
            z = y + corr[c]
            gap = h[c] - g[c] @ z
            y_new = z + max(gap, 0.0) * g[c] / (g[c] @ g[c])
            corr[c] = z - y_new
            y = y_new
    assert np.linalg.norm(x) <= np.linalg.norm(y) * (1 + 1e-6) + 1e-12 * scale
    assert np.allclose(x, y, rtol=1e-4, atol=1e-4 * np.abs(y).max() + 1e-12 * scale)
