"""One int64 array in place of many: how a step is handed from Python to its compiled kernel.

Numba type-checks and unboxes every argument of every call made from Python: about 30 ns for an
array and several times that for a structured array. A stepping kernel takes some twenty arrays,
so that alone costs more than a small scene's physics. But a simulator's arrays are allocated once
and only ever updated in place, so it packs their addresses and shapes once into an int64 array
(:func:`pack`), and a compiled entry point rebuilds the arrays from it (``numba.carray``) before
calling the kernel: one array to check per call instead of twenty.

The entry points are in the modules of the kernels they call (``exact.step_exact_packed``,
``substep.step_substeps_packed``); they read slot ``k`` of a pack with :func:`view1`,
:func:`view2` or :func:`view3`, in the order :func:`pack` was given the arrays. A pack refers to
its arrays by address: its owner keeps them alive, never replaces one without packing again, and
hands the pack only to the entry point it was made for. Without numba the kernels are called with
the arrays themselves and no pack is made.
"""

from __future__ import annotations

import numpy as np

from ._jit import HAVE_NUMBA, njit

#: Entries per array in a pack: its address, then up to three dimensions.
SLOT = 4


def pack(arrays) -> np.ndarray:
    """The addresses and shapes of ``arrays`` (C-contiguous, at most three dimensions) as one
    int64 array, slot ``k`` (entries ``4k .. 4k + 3``) for ``arrays[k]``."""
    out = np.zeros(SLOT * len(arrays), dtype=np.int64)
    for k, a in enumerate(arrays):
        if not (isinstance(a, np.ndarray) and a.flags.c_contiguous and 1 <= a.ndim < SLOT):
            raise ValueError(f"pack: array {k} must be a C-contiguous array of 1 to {SLOT - 1} dimensions")
        out[SLOT * k] = a.ctypes.data
        out[SLOT * k + 1 : SLOT * k + 1 + a.ndim] = a.shape
    return out


if HAVE_NUMBA:
    from numba import carray
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    @intrinsic
    def _pointer(typingctx, address):
        """The address (an int64) as a ``void*``, for ``numba.carray``."""

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], cgutils.voidptr_t)

        return types.voidptr(types.int64), codegen

    @njit(inline="always")
    def view1(h, k, dtype):
        """Slot ``k`` of pack ``h`` as a 1-D array of ``dtype``."""
        o = SLOT * k
        return carray(_pointer(h[o]), (h[o + 1],), dtype)

    @njit(inline="always")
    def view2(h, k, dtype):
        """Slot ``k`` of pack ``h`` as a 2-D array of ``dtype``."""
        o = SLOT * k
        return carray(_pointer(h[o]), (h[o + 1], h[o + 2]), dtype)

    @njit(inline="always")
    def view3(h, k, dtype):
        """Slot ``k`` of pack ``h`` as a 3-D array of ``dtype``."""
        o = SLOT * k
        return carray(_pointer(h[o]), (h[o + 1], h[o + 2], h[o + 3]), dtype)
