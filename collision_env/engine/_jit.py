"""Optional just-in-time compilation of the engine kernels.

The kernels are plain Python loops over numpy arrays. With numba installed (the ``fast`` extra)
they are compiled once and cached on disk; without it they run as ordinary Python, with the same
results and a much higher cost per event. ``NUMBA_DISABLE_JIT=1`` forces the Python path, which is
how the tests check that both paths agree.
"""

from __future__ import annotations

try:  # numba is an optional accelerator, not a requirement of the core install
    import numba as _numba
except ImportError:  # pragma: no cover - numba is installed wherever the suite runs
    _numba = None

HAVE_NUMBA = _numba is not None and not _numba.config.DISABLE_JIT


def njit(func=None, **options):
    """Compile ``func`` with numba in nopython mode (cached), or return it unchanged.

    Use bare (``@njit``) or with extra numba options (``@njit(inline="always")``).
    """
    if func is None:
        return lambda f: njit(f, **options)
    if _numba is None:
        return func
    return _numba.njit(cache=True, nogil=True, **options)(func)


BACKEND = "numba" if HAVE_NUMBA else "python"
