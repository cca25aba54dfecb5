"""What code outside the engine needs to compile its own kernels over the engine's arrays.

The environments' task kernels read the balls a :class:`~collision_env.engine.BatchSimulator` holds
(:meth:`~collision_env.engine.BatchSimulator.live_arrays`) and nudge them. They compile the way the
engine's own kernels do, through this module, and never through the engine's private modules:

- :func:`njit`: numba's nopython compilation, cached by source hash (see
  ``collision_env.engine._jit``), or the plain Python function without numba;
- :func:`pack` and :func:`view`: persistent arrays handed over as one int64 pack, unpacked in the
  kernel (see ``collision_env.engine.argpack``);
- :func:`ball_views`: the per-ball state array's fields (``layout.BALL``) as views;
- :func:`apply_impulses`: the engine's own nudge, which moves stuck clusters as rigid bodies.
"""

from __future__ import annotations

from ._jit import HAVE_NUMBA, compile_for, njit
from .argpack import pack_arrays
from .physics.motion import apply_impulses, ball_views

if HAVE_NUMBA:
    from .argpack import view

__all__ = ["HAVE_NUMBA", "apply_impulses", "ball_views", "compile_for", "njit", "pack_arrays", "view"]
