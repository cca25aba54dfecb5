"""Timers shared by every benchmark: repeated runs summarised by their best and median.

The machines these run on are shared and noisy, so a figure is the best of several repeats (the
least disturbed one), with the median beside it, and what matters is the ratio against a peer
measured in the same run.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, MutableMapping


def repeat(fn: Callable[[], object], repeats: int, reset: Callable[[], object] | None = None) -> list[float]:
    """Run ``fn()`` ``repeats`` times, each after an untimed ``reset()``; return the durations (s)."""
    out = []
    for _ in range(repeats):
        if reset is not None:
            reset()
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def alternating(
    runs: dict[str, Callable[[], object]], repeats: int, resets: dict[str, Callable[[], object]] | None = None
) -> dict[str, list[float]]:
    """Run each of ``runs`` in turn, ``repeats`` rounds, each run after its untimed reset (if
    ``resets`` has one); return every run's durations (s). Alternating, the runs share whatever
    the machine does meanwhile, so their ratios hold on a busy machine.

    >>> out = alternating({"a": lambda: None, "b": lambda: None}, 3)
    >>> sorted(out), [len(v) for v in out.values()]
    (['a', 'b'], [3, 3])
    """
    out: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, fn in runs.items():
            out[name] += repeat(fn, 1, (resets or {}).get(name))
    return out


def summary(durations: list[float], per: float = 1.0) -> dict:
    """Best and median of ``durations`` divided by ``per`` (e.g. seconds per step).

    >>> summary([3.0, 1.0, 2.0], per=2.0)
    {'best': 0.5, 'median': 1.0, 'repeats': 3}
    """
    return {"best": min(durations) / per, "median": statistics.median(durations) / per, "repeats": len(durations)}


def best_rate(chunk: Callable[[], int], seconds: float, slices: int) -> float:
    """Units per second of ``chunk()`` (which returns how many units it did), best of ``slices`` slices.

    Each slice repeats ``chunk`` until ``seconds / slices`` have passed.
    """
    best = 0.0
    for _ in range(slices):
        done, t0 = 0, time.perf_counter()
        while True:
            done += chunk()
            elapsed = time.perf_counter() - t0
            if elapsed >= seconds / slices:
                break
        best = max(best, done / elapsed)
    return best


def best_rates(chunks: list[Callable[[], int]], seconds: float, slices: int) -> list[float]:
    """:func:`best_rate` of each of ``chunks``, their slices interleaved (one slice of each in turn,
    ``slices`` rounds): a busy machine slows them alike, so their ratios hold.

    >>> rates = best_rates([lambda: 1, lambda: 2], 0.002, 2)
    >>> len(rates), rates[1] > 0.0
    (2, True)
    """
    best = [0.0] * len(chunks)
    for _ in range(slices):
        for k, chunk in enumerate(chunks):
            best[k] = max(best[k], best_rate(chunk, seconds / slices, 1))
    return best


def add_timer(obj: object, name: str, totals: MutableMapping[str, float], key: str) -> None:
    """Time every call of ``obj.name``: each adds its duration (s) to ``totals[key]``.

    The timer is an instance attribute that shadows the class's method; ``delattr(obj, name)``
    removes it. It costs a ``perf_counter`` pair per call.

    >>> class Clock:
    ...     def tick(self):
    ...         return 1
    >>> c, totals = Clock(), {"tick": 0.0}
    >>> add_timer(c, "tick", totals, "tick")
    >>> c.tick(), totals["tick"] > 0.0
    (1, True)
    >>> delattr(c, "tick"); "tick" in vars(c)
    False
    """
    inner = getattr(obj, name)

    def timed(*args, **kwargs):
        start = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            totals[key] += time.perf_counter() - start

    setattr(obj, name, timed)
