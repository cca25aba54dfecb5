"""Packed kernel arguments: one int64 array carrying the addresses and shapes of a kernel's arrays."""

from __future__ import annotations

import numpy as np
import pytest

from collision_env.engine import Scene, Simulator
from collision_env.engine._jit import HAVE_NUMBA
from collision_env.engine.argpack import SLOT, pack_arrays
from collision_env.engine.state import STATE_SLOT, State


def test_a_pack_holds_each_array_address_and_shape():
    a = np.zeros((2, 3, 4))
    b = np.zeros(5, dtype=np.int32)
    h = pack_arrays((a, b))
    assert h.dtype == np.int64 and len(h) == 2 * SLOT
    assert list(h[:SLOT]) == [a.ctypes.data, 2, 3, 4]
    assert list(h[SLOT:]) == [b.ctypes.data, 5, 0, 0]


@pytest.mark.parametrize(
    "array", [np.zeros((3, 4), order="F"), np.zeros((2, 2, 2, 2)), np.zeros(6)[::2], np.float64(1.0)]
)
def test_only_c_contiguous_arrays_of_one_to_three_dimensions_are_packed(array):
    with pytest.raises(ValueError, match="array 0 must be a C-contiguous array"):
        pack_arrays((array,))


@pytest.mark.skipif(not HAVE_NUMBA, reason="the packed call is numba's")
def test_a_pack_follows_its_arrays_when_the_impact_buffer_grows():
    """The impact buffer is the one array a simulator replaces (when a step's impacts do not fit):
    the pack is made again, and the step goes on where it stopped."""
    n = 120
    rng = np.random.default_rng(1)
    x, y = np.meshgrid(np.linspace(-1.8, 1.8, 12), np.linspace(-0.9, 0.9, 10))
    pos = np.stack([x.ravel(), y.ravel()], 1)
    sim = Simulator(Scene(), pos, rng.normal(size=(n, 2)) * 3, np.ones(n), np.full(n, 0.05), mode="naive")
    reference = Simulator(Scene(), pos, sim.velocities, np.ones(n), np.full(n, 0.05), mode="naive")
    small = sim._stepper
    small._alloc_work(64)  # far fewer rows than a step records
    slot = (STATE_SLOT + State._fields.index("imp")) * SLOT  # (the impact buffer's slot)
    address = small._pack[slot]
    got, want = sim.batch.step(0.5), reference.batch.step(0.5)
    assert small._pack[slot] == small._imp.ctypes.data != address
    assert len(got) == len(want) > 64
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(sim.positions, reference.positions)
