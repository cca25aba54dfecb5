"""The checks the observables make of what they are handed (a ``ValueError`` or ``TypeError`` naming
the argument)."""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.scene import Scene


def records(impacts: Any) -> np.ndarray:
    """The structured array of ``impacts`` (an ``Impacts`` or an ``IMPACT_DTYPE`` array)."""
    array = getattr(impacts, "array", impacts)
    if not (isinstance(array, np.ndarray) and array.dtype.names and "impulse" in array.dtype.names):
        raise TypeError(f"impacts: expected Impacts or an IMPACT_DTYPE array, got {type(impacts).__name__}")
    return array


def positive(value: Any, name: str) -> float:
    """``value`` as a finite float > 0."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}: must be a finite number > 0, got {value!r}")
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name}: must be a finite number > 0, got {value!r}")
    return value


def whole(value: Any, name: str, least: int) -> int:
    """``value`` as an int of at least ``least`` (an integer, not a boolean or a float)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) or value < least:
        raise ValueError(f"{name}: must be a whole number of at least {least}, got {value!r}")
    return int(value)


def radii(values: ArrayLike, name: str = "radii") -> np.ndarray:
    """``(N,)`` radii: finite and positive."""
    r = np.asarray(values, dtype=np.float64)
    if r.ndim != 1 or len(r) == 0:
        raise ValueError(f"{name}: expected a non-empty 1-D array, got shape {r.shape}")
    bad = np.flatnonzero(~(np.isfinite(r) & (r > 0.0)))
    if len(bad):
        raise ValueError(f"{name}: ball {bad[0]}'s radius must be finite and > 0, got {r[bad[0]]!r}")
    return r


def masses(values: ArrayLike, n: int) -> np.ndarray:
    """``(n,)`` masses: finite and positive."""
    m = np.asarray(values, dtype=np.float64)
    if m.shape != (n,):
        raise ValueError(f"masses: expected shape ({n},), got {m.shape}")
    bad = np.flatnonzero(~(np.isfinite(m) & (m > 0.0)))
    if len(bad):
        raise ValueError(f"masses: ball {bad[0]}'s mass must be finite and > 0, got {m[bad[0]]!r}")
    return m


def scene(value: Any) -> Scene:
    """A :class:`~collision_env.engine.Scene`."""
    if not isinstance(value, Scene):
        raise TypeError(f"scene: expected a collision_env.engine.Scene, got {type(value).__name__}")
    return value


def bounded_scene(value: Any) -> Scene:
    """A scene with bounds: a walled box or a periodic cell."""
    s = scene(value)
    if s.bounds is None:
        raise ValueError("scene: needs bounds (a walled box or a periodic cell), got bounds=None")
    return s


def finite(values: ArrayLike, name: str, last: int) -> np.ndarray:
    """A finite float64 array of at least two axes whose last axis has ``last`` entries."""
    a = np.asarray(values, dtype=np.float64)
    if a.ndim < 2 or a.shape[-1] != last:
        raise ValueError(f"{name}: expected shape (..., N, {last}), got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: values must be finite")
    return a
