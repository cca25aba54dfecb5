"""Independent tasks of a benchmark (state points, seeds) run serially, in local processes, or on Ray.

:func:`run_tasks` maps a function over tasks and returns the results in the tasks' order, however
they ran:

- ``jobs=1`` (the default): one after another, in this process;
- ``jobs > 1``: a pool of that many local processes (``concurrent.futures``, started by ``spawn``,
  so each imports the package afresh and loads its compiled kernels from the cache);
- ``ray=True``: as Ray tasks, one CPU each, on a private local Ray instance of ``jobs`` CPUs, or on
  the cluster at ``address`` (``ray start --head`` on one machine, ``ray start --address=...`` on the
  others, each with this package installed). Ray is optional (the ``distributed`` extra, in a venv
  of its own: ``make .venv-ray/.installed``, since Ray pins its own gymnasium); asked for without
  it installed, it is a ``ValueError`` that says so.

A task's result must depend on the task alone (its seeds included), never on which process ran it
or in what order: then every way of running gives the same numbers, bit for bit. Timings measured
inside a task (CPU seconds, events per second) are the exception, and the only one.

>>> run_tasks(pow, [(2, 3), (3, 2)], star=True)
[8, 9]
"""

from __future__ import annotations

import logging
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

#: Ray binds a local instance to the machine's network address unless this is "0" (then it stays
#: on loopback, as a private single-machine instance should). Ray reads it when it starts.
RAY_LOOPBACK_ENV = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"


def run_tasks(
    function: Callable[..., Any],
    tasks: Sequence[Any],
    *,
    jobs: int = 1,
    ray: bool = False,
    address: str | None = None,
    star: bool = False,
    done: Callable[[int, Any], None] | None = None,
) -> list[Any]:
    """``[function(task) for task in tasks]`` (``function(*task)`` with ``star``), run serially, in
    ``jobs`` local processes, or on Ray (see the module). ``function`` and the tasks must be
    picklable (a module-level function, plain data) unless they run serially.

    ``done(index, result)`` is called in this process as each task finishes (in the order they
    finish, which may not be the tasks'), to log progress. ``address`` (a Ray cluster's
    ``host:port``, or ``"auto"``) implies ``ray``.
    """
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs: a whole number of processes, at least 1, got {jobs!r}")
    call = _Star(function) if star else function
    tasks = list(tasks)
    if ray or address:
        return _on_ray(call, tasks, jobs, address, done)
    if jobs == 1 or len(tasks) <= 1:
        results = []
        for k, task in enumerate(tasks):
            results.append(call(task))
            if done:
                done(k, results[-1])
        return results
    return _in_processes(call, tasks, jobs, done)


class _Star:
    """``function(*task)``, picklable when ``function`` is."""

    def __init__(self, function: Callable[..., Any]) -> None:
        self.function = function

    def __call__(self, task: Sequence[Any]) -> Any:
        return self.function(*task)


def _in_processes(call, tasks, jobs, done) -> list[Any]:
    results: list[Any] = [None] * len(tasks)
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)), mp_context=context) as pool:
        futures = {pool.submit(call, task): k for k, task in enumerate(tasks)}
        for future in as_completed(futures):
            k = futures[future]
            results[k] = future.result()
            if done:
                done(k, results[k])
    return results


def _on_ray(call, tasks, jobs, address, done) -> list[Any]:
    if not address:
        os.environ[RAY_LOOPBACK_ENV] = "0"  # (read by Ray at import, and by the processes it starts)
    try:
        import ray
    except ImportError:
        raise ValueError(
            "ray: not installed in this environment; install the 'distributed' extra in a venv of its own "
            "(make .venv-ray/.installed), or run without --ray (serially, or --jobs N local processes)"
        ) from None
    started = not ray.is_initialized()
    if started:
        quiet = {"log_to_driver": False, "logging_level": logging.WARNING}
        if address:
            ray.init(address=address, **quiet)
        else:
            from ray._private import ray_constants

            ray_constants.ENABLE_RAY_CLUSTER = False  # (in case ray was imported before the variable was set)
            ray.init(num_cpus=jobs, include_dashboard=False, _node_ip_address="127.0.0.1", **quiet)
    try:
        remote = ray.remote(num_cpus=1)(call)
        refs = [remote.remote(task) for task in tasks]
        index = {ref: k for k, ref in enumerate(refs)}
        results: list[Any] = [None] * len(tasks)
        pending = list(refs)
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                k = index[ref]
                results[k] = ray.get(ref)
                if done:
                    done(k, results[k])
        return results
    finally:
        if started:
            ray.shutdown()
