"""Block averaging: the online blocking transformation is the batch one, and the standard error it
chooses is the true one for independent and for correlated samples."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.observables import Blocking, block_average


def _batch_errors(x):
    """Flyvbjerg & Petersen's transformation as a loop over whole arrays: each level's naive error."""
    errors = []
    while len(x) >= 2:
        errors.append(np.std(x, ddof=1) / math.sqrt(len(x)))
        x = 0.5 * (x[: len(x) // 2 * 2 : 2] + x[1 : len(x) // 2 * 2 : 2])
    return np.array(errors)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 3000), cuts=st.lists(st.integers(0, 3000), max_size=6), seed=st.integers(0, 2**16))
def test_fed_in_pieces_it_is_the_batch_transformation(n, cuts, seed):
    x = np.random.default_rng(seed).normal(3.0, 2.0, n)
    blocking = Blocking()
    for piece in np.split(x, sorted(c % (n + 1) for c in cuts)):
        blocking.add(piece)
    result = blocking.result()
    assert blocking.count == n and result.mean == pytest.approx(np.mean(x), rel=1e-12)
    np.testing.assert_allclose(result.errors, _batch_errors(x), rtol=1e-9)


def test_independent_samples_give_the_textbook_error():
    rng = np.random.default_rng(1)
    errors = [block_average(rng.normal(size=2**14)).error for _ in range(40)]
    # sigma / sqrt(n) = 1 / 128; the chosen level has 2^14 / B blocks, B ~ (2n)^(1/3): a few % each
    assert np.mean(errors) == pytest.approx(1 / 128, rel=0.05)


def test_correlated_samples_give_the_error_of_their_correlation_time():
    # an AR(1) process x_t = a x_(t-1) + noise: the mean's variance is var / n (1 + a) / (1 - a)
    rng = np.random.default_rng(2)
    a, n = 0.9, 2**16
    estimates, means = [], []
    for _ in range(30):
        noise = rng.normal(size=n)
        x = np.empty(n)
        x[0] = noise[0] / math.sqrt(1 - a * a)
        for t in range(1, n):
            x[t] = a * x[t - 1] + noise[t]
        result = block_average(x)
        assert result.reliable
        estimates.append(result.error)
        means.append(result.mean)
    truth = math.sqrt(1 / (1 - a * a) / n * (1 + a) / (1 - a))
    assert np.mean(estimates) == pytest.approx(truth, rel=0.1)
    assert np.std(means) == pytest.approx(truth, rel=0.3)  # (30 runs: the spread itself to ~13 %)
    naive = math.sqrt(1 / (1 - a * a) / n)
    assert np.mean(estimates) > 3 * naive  # what ignoring the correlation would claim


def test_edge_cases_and_bad_input():
    assert block_average([2.0, 2.0, 2.0, 2.0]).error == 0.0
    one = block_average([5.0])
    assert one.mean == 5.0 and math.isnan(one.error) and not one.reliable
    short = block_average(np.sin(np.arange(8.0) / 10))  # one slow swing: no level settles
    assert not short.reliable
    assert str(block_average([1.0, 2.0, 3.0, 4.0])).startswith("2.5 ± ")
    blocking = Blocking()
    with pytest.raises(ValueError, match="no samples"):
        blocking.result()
    blocking.add([1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        blocking.add([3.0, np.nan])
    assert blocking.count == 2  # the refused call took none
    with pytest.raises(ValueError, match="samples"):
        block_average(np.ones((2, 2)))
