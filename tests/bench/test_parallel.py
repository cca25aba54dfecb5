"""Independent tasks run serially or in local processes, results in the tasks' order; Ray asked for
where it is not installed is a clear error (Ray's own run: tests/bench/test_parallel_ray.py)."""

import importlib.util
import operator

import pytest

from collision_env.bench.parallel import run_tasks


def test_serially_in_order_with_progress():
    seen = []
    assert run_tasks(operator.neg, [1, 2, 3], done=lambda k, r: seen.append((k, r))) == [-1, -2, -3]
    assert seen == [(0, -1), (1, -2), (2, -3)]
    assert run_tasks(pow, [(2, 3), (3, 2)], star=True) == [8, 9]
    assert run_tasks(operator.neg, []) == []


def test_processes_return_the_tasks_in_order():
    seen = []
    assert run_tasks(pow, [(2, k) for k in range(5)], star=True, jobs=2, done=lambda k, r: seen.append(k)) == [
        1,
        2,
        4,
        8,
        16,
    ]
    assert sorted(seen) == list(range(5))


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2"])
def test_jobs_must_be_a_positive_whole_number(jobs):
    with pytest.raises(ValueError, match="jobs"):
        run_tasks(operator.neg, [1], jobs=jobs)


@pytest.mark.skipif(importlib.util.find_spec("ray") is not None, reason="ray is installed here")
def test_ray_without_ray_says_how_to_get_it():
    with pytest.raises(ValueError, match="distributed"):
        run_tasks(operator.neg, [1], ray=True)
    with pytest.raises(ValueError, match="not installed"):
        run_tasks(operator.neg, [1], address="127.0.0.1:6379")
