"""One int64 array in place of many: how a step is handed from Python to its compiled kernel.

Numba type-checks and unboxes every argument of every call made from Python: about 30 ns for an
array and several times that for a structured array. A stepping kernel takes some twenty arrays,
so that alone costs more than a small scene's physics. But a simulator's arrays are allocated once
and only ever updated in place, so it packs their addresses and shapes once into an int64 array
(:func:`pack_arrays`), and the compiled kernel rebuilds the arrays from it (``numba.carray``): one
array to check per call instead of twenty.

A kernel reads slot ``k`` of a pack with :func:`view`, in the order :func:`pack_arrays` was given
the arrays (:mod:`~collision_env.engine.state` names the
slots). A pack refers to its arrays by address: its owner keeps them alive, never replaces one
without packing it again (:func:`set_slots`), and hands the pack only to the kernel it was made
for. Without numba the kernels are called with the arrays themselves and no pack is made.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from ._jit import HAVE_NUMBA

#: Entries per array in a pack: its address, then up to three dimensions.
SLOT = 4


def pack_arrays(arrays: Sequence[np.ndarray], extra_slots: int = 0) -> np.ndarray:
    """The addresses and shapes of ``arrays`` (C-contiguous, at most three dimensions) as one
    int64 array, slot ``k`` (entries ``4k .. 4k + 3``) for ``arrays[k]``, followed by
    ``extra_slots`` empty slots (for :func:`set_slots`)."""
    out = np.zeros(SLOT * (len(arrays) + extra_slots), dtype=np.int64)
    set_slots(out, 0, arrays)
    return out


def set_slots(h: np.ndarray, first: int, arrays: Iterable[np.ndarray]) -> None:
    """Point slots ``first, first + 1, ...`` of pack ``h`` at ``arrays``."""
    for k, a in enumerate(arrays, start=first):
        if not (isinstance(a, np.ndarray) and a.flags.c_contiguous and 1 <= a.ndim < SLOT):
            raise ValueError(f"pack: array {k} must be a C-contiguous array of 1 to {SLOT - 1} dimensions")
        h[SLOT * k] = a.ctypes.data
        h[SLOT * k + 1 : SLOT * (k + 1)] = 0
        h[SLOT * k + 1 : SLOT * k + 1 + a.ndim] = a.shape


if HAVE_NUMBA:
    from numba.core import cgutils, types
    from numba.extending import intrinsic
    from numba.np.arrayobj import make_array, populate_array

    def _element_type(dtype):
        """The element type a ``view`` is asked for: a numpy scalar type or a dtype (a global)."""
        if isinstance(dtype, types.NumberClass):
            return dtype.instance_type
        if isinstance(dtype, types.DType):
            return dtype.dtype
        return None

    @intrinsic
    def view(typingctx, h, k, dtype, ndim):
        """Slot ``k`` of pack ``h`` as a C-contiguous array of ``dtype`` with ``ndim`` dimensions (a
        constant): a borrowed view, with no reference counting. An intrinsic rather than a kernel,
        so that unpacking a pack inlines nothing into the kernel that does it (each numba inlining
        copies its caller's code, which costs compile time in a large kernel)."""
        element = _element_type(dtype)
        if element is None or not isinstance(ndim, types.IntegerLiteral) or not isinstance(k, types.Integer):
            return None
        rank = ndim.literal_value
        array_type = types.Array(element, rank, "C")

        def codegen(context, builder, signature, args):
            pack, slot = args[0], context.cast(builder, args[1], signature.args[1], types.intp)
            pack_view = context.make_array(signature.args[0])(context, builder, pack)
            base = builder.mul(slot, cgutils.intp_t(SLOT))

            def entry(offset):
                return builder.load(builder.gep(pack_view.data, [builder.add(base, cgutils.intp_t(offset))]))

            shapes = [entry(1 + axis) for axis in range(rank)]
            itemsize = cgutils.intp_t(context.get_abi_sizeof(context.get_data_type(element)))
            strides = []
            stride = itemsize
            for extent in reversed(shapes):
                strides.append(stride)
                stride = builder.mul(stride, extent)
            strides.reverse()
            data = builder.inttoptr(entry(0), context.get_data_type(element).as_pointer())
            out = make_array(array_type)(context, builder)
            populate_array(out, data=data, shape=shapes, strides=strides, itemsize=itemsize, meminfo=None)
            return out._getvalue()

        return array_type(h, k, dtype, ndim), codegen
