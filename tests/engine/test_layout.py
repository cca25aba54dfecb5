"""Every packed array's field tuple and its index constants agree (one place names each field)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from collision_env.engine import layout


@pytest.mark.parametrize("name", sorted(layout.LAYOUTS))
def test_each_field_has_the_constant_of_its_position(name):
    fields = layout.LAYOUTS[name]
    prefix = {
        "BALL": "B_",
        "CAL_I": "C_",
        "HEAP": "H_",
        "SCENE_F": "S_",
        "SCENE_I": "S_",
        "WORK_F": "W_",
        "WORK_I": "W_",
        "KINEMATICS": "K_",
        "COUNTERS": "",
        "FRAME_FIELDS": "FRAME_",
    }[name]
    assert len(set(fields)) == len(fields)
    for position, field in enumerate(fields):
        constant = prefix + re.sub(r"\W", "_", field).upper()
        assert getattr(layout, constant) == position, (name, field)


def test_engine_arrays_are_as_wide_as_their_layouts():
    from collision_env.engine import Scene, Simulator

    sim = Simulator(Scene(), [[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0]], [1.0, 1.0])
    b = sim._stepper
    assert b.balls.shape[-1] == len(layout.BALL)
    calendar = b.mode_arrays[0]
    assert calendar.rec.dtype == layout.CAL_RECORD
    assert calendar.ci.shape[-1] == len(layout.CAL_I)
    assert calendar.heap.shape[-1] == len(layout.HEAP)
    assert b.fparams.shape == (len(layout.SCENE_F),)
    assert b.iparams.shape == (len(layout.SCENE_I),)
    assert b.work_f.shape[-1] == len(layout.WORK_F)
    assert b.work_i.shape[-1] == len(layout.WORK_I)
    assert b.fparams[layout.S_XMAX] == 2.0 and b.iparams[layout.S_DIM] == 2


def test_a_calendar_record_is_one_cache_line():
    """Everything a prediction reads of a neighbour is in one 64-byte row, aligned to one."""
    from collision_env.engine import Scene, Simulator

    assert layout.CAL_RECORD.itemsize == 64
    n = 100
    sim = Simulator(
        Scene(), np.stack([np.linspace(-1.8, 1.8, n), np.zeros(n)], 1), np.zeros((n, 2)), np.ones(n), np.full(n, 0.01)
    )
    for cal in (sim._stepper.mode_arrays[0].rec, sim.copy()._stepper.mode_arrays[0].rec):
        assert cal.ctypes.data % 64 == 0
