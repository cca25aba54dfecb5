"""Compensated simulation clocks: after any number of steps, a scene's time is within an ulp of
the exact sum of the steps taken, and forward then back returns it to exactly where it was.

Each scene keeps ``clock[sc] = (start, compensation)``: the time at the start of its current step
as the clock set it, and the rounding error accumulated so far. The exact time is their sum;
``time[sc]`` (which the stepping kernels read, and overwrite during a step) is its correctly
rounded value. Knuth's TwoSum gives the rounding error of each addition exactly, and a
renormalisation folds it back in (Knuth, *The Art of Computer Programming* 2, 4.2.2; Ogita,
Rump & Oishi 2005).
"""

from __future__ import annotations

from ._jit import njit


@njit(inline="always")
def finish_step(sc, completed, step, time, clock):
    """Scene ``sc``'s clock at the end of its step of ``step`` seconds (signed).

    A scene that ``completed`` its step advances its exact time by ``step``; one that stopped
    short (the event cap) keeps the time of its last event, which the kernel wrote into ``time``.
    """
    start = clock[sc, 0]
    if completed:
        hi = start + step
        b = hi - start
        lo = clock[sc, 1] + ((start - (hi - b)) + (step - b))
        time[sc] = hi + lo
        clock[sc, 1] = lo - (time[sc] - hi)
    clock[sc, 0] = time[sc]
