"""Impact records: how every mode reports a collision (one row of ``layout.IMPACT_DTYPE``)."""

from __future__ import annotations

from .._jit import njit


@njit(refcount=False, forceinline=True)
def record(imp, n_imp, scene, time, ball, other, wall, x, y, speed, impulse):
    """Append an impact to the record buffer ``imp``; ``n_imp[0]`` counts the rows filled.
    ``other`` is -1 for a wall impact, ``wall`` -1 for a ball-ball one."""
    k = n_imp[0]
    r = imp[k]  # a view of row k (in numba and in numpy alike)
    r["scene"] = scene
    r["time"] = time
    r["ball"] = ball
    r["other"] = other
    r["wall"] = wall
    r["x"] = x
    r["y"] = y
    r["speed"] = speed
    r["impulse"] = impulse
    n_imp[0] = k + 1
