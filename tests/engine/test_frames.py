"""``frames``: many steps in one call are a loop of ``step`` calls, bit for bit, on every path
(the compiled loop, the frames it hands back to Python, and the step-by-step fallback)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from collision_env.engine import BatchSimulator, EventCapWarning, Scene, Simulator
from collision_env.engine.stepper import Stepper
from tests.engine.test_calendar import gas

FIELDS = ["scene", "time", "ball", "other", "wall", "x", "y", "speed", "impulse"]


@pytest.fixture
def loop_exits(monkeypatch):
    """Where each call of the compiled loop stopped: ``(frame, stepped)`` (see ``frames.frames_kernel``)."""
    exits = []
    compiled = Stepper._run_frames

    def spy(self, *args):
        result = compiled(self, *args)
        exits.append((result[0], result[1]))
        return result

    monkeypatch.setattr(Stepper, "_run_frames", spy)
    return exits


def twin_batches(scene, starts, radii, **options):
    """Two identical batches of the scenes ``starts`` ((positions, velocities) pairs)."""
    masses = np.ones(len(radii))
    return [
        BatchSimulator(scene, [p for p, _ in starts], [v for _, v in starts], masses, radii=radii, **options)
        for _ in range(2)
    ]


def assert_frames_are_a_step_loop(sim, loop, dt, n):
    """``sim.frames(dt, n)`` against ``n`` calls of ``loop.step(dt)`` on a twin: every bit the same."""
    rec = sim.frames(dt, n)
    steps = []
    for f in range(n):
        steps.append(loop.step(dt))
        np.testing.assert_array_equal(rec.time[f], loop.time)
        np.testing.assert_array_equal(rec.positions[f], loop.positions)
        np.testing.assert_array_equal(rec.velocities[f], loop.velocities)
    np.testing.assert_array_equal(rec.impacts[FIELDS], np.concatenate(steps)[FIELDS])
    np.testing.assert_array_equal(sim.positions, loop.positions)
    np.testing.assert_array_equal(sim.time, loop.time)
    np.testing.assert_array_equal(sim.cap_reached, loop.cap_reached)
    assert sim.stats == loop.stats
    for name in ("body", "clock"):  # the clusters and clocks too
        np.testing.assert_array_equal(getattr(sim._stepper, name), getattr(loop._stepper, name))
    if sim._stepper.spec.persistent:  # and exact mode's calendar
        for mine, theirs in zip(sim._stepper.mode_arrays[0], loop._stepper.mode_arrays[0], strict=True):
            np.testing.assert_array_equal(mine, theirs)
    return rec


@pytest.mark.parametrize("mode", ["exact", "naive", "posteriori"])
def test_frames_are_a_loop_of_steps(mode, loop_exits):
    scene, pos, vel, radii = gas(60, speed=2.0)
    starts = [(pos, vel), (pos, 0.5 * vel), (pos, -vel)]
    sim, loop = twin_batches(scene, starts, radii, mode=mode, substeps=1 if mode == "exact" else 2)
    rec = assert_frames_are_a_step_loop(sim, loop, 1 / 60, 40)
    assert len(rec.impacts) > 100
    assert set(rec.impacts["scene"]) == {0, 1, 2}
    # the compiled loop ran every frame (handing one back only when its copy of the impacts was full)
    assert loop_exits[-1] == (40, True) and all(stepped for _, stepped in loop_exits)


@pytest.mark.parametrize(
    "scene",
    [
        Scene(bounds=(-0.5, -0.5, 0.5, 0.5), elasticity=0.3),  # contact groups and collapse cascades
        Scene(bounds=(-0.5, -0.5, 0.5, 0.5), elasticity=0.0, inelastic="stick"),  # rotating clusters
    ],
    ids=["cascades", "stick"],
)
def test_frames_of_inelastic_scenes_are_a_loop_of_steps(scene, loop_exits):
    _, pos, vel, radii = gas(12, phi=0.4, r=0.05, speed=2.0)
    sim, loop = twin_batches(scene, [(pos, vel), (pos, 0.5 * vel)], radii)
    assert_frames_are_a_step_loop(sim, loop, 1 / 60, 9)
    if scene.sticky:  # clusters formed (and rotate: their scenes are predicted afresh every step)
        assert (sim.clusters != np.arange(12)).any()
    assert_frames_are_a_step_loop(sim, loop, 1 / 60, 80)
    assert loop_exits[-1] == (80, True) and all(stepped for _, stepped in loop_exits)


def test_frames_after_a_backward_step_go_back_to_the_compiled_loop(loop_exits):
    scene, pos, vel, radii = gas(30, speed=2.0)
    sim, loop = twin_batches(scene, [(pos, vel)], radii)
    for b in (sim, loop):
        b.step(0.3)
        b.nudge(np.full((1, 30, 2), 0.1))
    assert_frames_are_a_step_loop(sim, loop, -1 / 60, 5)  # backwards: step by step
    assert loop_exits == []
    assert_frames_are_a_step_loop(sim, loop, 1 / 60, 20)  # the first step turns time forward again
    assert loop_exits == [(20, True)]


@pytest.mark.parametrize(
    "dt, n, max_events, capped_steps",
    [
        (0.0005, 60, 10_000, 0),  # a few dozen impacts a frame: the frames' own copy fills up, and grows
        (0.05, 12, 10_000, 0),  # hundreds a frame: the kernel's buffer fills in every frame
        (0.05, 12, 40, 12),  # and the event cap stops every frame's step early
    ],
)
def test_frames_past_full_impact_buffers_and_the_event_cap(dt, n, max_events, capped_steps, loop_exits):
    """A small impact buffer (300 rows) makes the kernel stall mid-step, or the frames' copy of
    the impacts fill up; an event cap stops scenes early. Python completes those frames as step
    completes a step."""
    scene, pos, vel, radii = gas(150, speed=3.0)
    starts = [(pos, vel * s) for s in (1.0, 0.5, 2.0)]
    sim, loop = twin_batches(scene, starts, radii, max_events=max_events)
    for b in (sim, loop):
        b._stepper._alloc_work(300)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = assert_frames_are_a_step_loop(sim, loop, dt, n)
    assert len(rec.impacts) > 3 * 300
    capped = [w for w in caught if issubclass(w.category, EventCapWarning)]
    assert len(capped) == 2 * capped_steps  # a warning per step, from either
    assert all(w.filename == __file__ for w in capped)  # (each names the caller)
    if dt < 0.01:  # the loop's own copy fills up after a few frames: it hands over a stepped frame
        assert any(stepped for f, stepped in loop_exits if f < n) and loop_exits[-1] == (n, True)
    elif capped_steps:  # every frame's step is capped: Python completes each
        assert loop_exits == [(f, False) for f in range(n)]
    else:  # the kernel's buffer fills up (Python completes the frame), then grows to hold a step's impacts
        assert loop_exits[0] == (0, False)
        assert sum(not stepped for _, stepped in loop_exits) < n // 2


@pytest.mark.parametrize("dt", [0.05, -0.05], ids=["compiled loop", "step by step"])
def test_a_single_simulators_event_cap_warning_names_the_caller(dt):
    scene, pos, vel, radii = gas(60, speed=3.0)
    sim = Simulator(scene, pos, vel, np.ones(60), radii=radii, max_events=5)
    with pytest.warns(EventCapWarning) as caught:
        sim.frames(dt, 2)
    assert len(caught) == 2 and all(w.filename == __file__ for w in caught)


@pytest.mark.parametrize("case", ["backwards", "no border"])
def test_frames_that_step_one_by_one(case):
    scene, pos, vel, radii = gas(30)
    dt = -1 / 60 if case == "backwards" else 1 / 60
    if case == "no border":
        scene = Scene(bounds=None)
    sim, loop = twin_batches(scene, [(pos, vel)], radii)
    assert_frames_are_a_step_loop(sim, loop, dt, 30)


def test_single_simulator_frames_drop_the_batch_axis():
    scene, pos, vel, radii = gas(20, speed=3.0)
    sim = Simulator(scene, pos, vel, np.ones(20), radii=radii)
    loop = Simulator(scene, pos, vel, np.ones(20), radii=radii)
    rec = sim.frames(0.1, 5)
    assert rec.time.shape == (5,) and rec.positions.shape == rec.velocities.shape == (5, 20, 2)
    want = [impact for _ in range(5) for impact in loop.step(0.1)]
    assert rec.impacts == want and len(want) > 5
    np.testing.assert_array_equal(rec.positions[-1], loop.positions)


def test_no_frames_and_bad_arguments_leave_the_state_alone():
    scene, pos, vel, radii = gas(10)
    sim = Simulator(scene, pos, vel, np.ones(10), radii=radii)
    before = sim.get_state()
    rec = sim.frames(0.1, 0)
    assert rec.positions.shape == (0, 10, 2) and rec.impacts == []
    for dt, n, match in (
        (0.1, -1, "n: must be a whole number"),
        (0.1, 2.0, "n: must be a whole number"),
        (0.1, True, "n: must be a whole number"),
        (float("nan"), 3, "dt: "),
        ("0.1", 3, "dt: "),
    ):
        with pytest.raises(ValueError, match=match):
            sim.frames(dt, n)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


def test_frames_record_into_the_arrays_they_are_given():
    scene, pos, vel, radii = gas(40, speed=2.0)
    sim, loop = twin_batches(scene, [(pos, vel), (pos, -vel)], radii)
    first = sim.frames(0.02, 30)
    again = sim.frames(0.02, 30, out=first)
    assert np.shares_memory(again.positions, first.positions) and np.shares_memory(again.time, first.time)
    loop.frames(0.02, 30)
    want = loop.frames(0.02, 30)
    for got, expected in zip(again[:3], want[:3], strict=True):
        np.testing.assert_array_equal(got, expected)
    single = Simulator(scene, pos, vel, np.ones(40), radii=radii)
    rec = single.frames(0.02, 30)
    assert np.shares_memory(single.frames(0.02, 30, out=rec).positions, rec.positions)
    np.testing.assert_array_equal(rec.positions, want.positions[:, 0])


def test_frames_refuse_arrays_they_cannot_record_into():
    scene, pos, vel, radii = gas(10)
    sim = BatchSimulator(scene, [pos], [vel], np.ones(10), radii=radii)
    good = (np.zeros((5, 1)), np.zeros((5, 1, 10, 2)), np.zeros((5, 1, 10, 2)))
    before = sim.get_state()
    for out, match in (
        ({"time": good[0]}, "out: expected a Frames or a tuple"),
        (good[:2], "out: expected a Frames or a tuple"),
        ((np.empty((4, 1)), good[1], good[2]), r"out: time must be .* shape \(5, 1\)"),
        ((good[0], good[1].astype(np.float32), good[2]), "out: positions must be .* float64"),
        ((good[0], good[1], np.empty((5, 1, 10, 4))[..., :2]), "out: velocities must be .* C-contiguous"),
        ((good[0], good[1], good[1]), "out: positions and velocities must not share memory"),
    ):
        with pytest.raises(ValueError, match=match):
            sim.frames(0.1, 5, out=out)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])
    single = Simulator(scene, pos, vel, np.ones(10), radii=radii)
    with pytest.raises(ValueError, match=r"out: time must be .* of shape \(5,\), got float64 \(5, 1\)"):
        single.frames(0.1, 5, out=good)  # (a batch's arrays, not a single simulator's)


@pytest.mark.parametrize("change", ["nudge", "set_balls", "set_state", "live arrays"])
def test_a_step_sees_a_change_made_since_the_last_step(change):
    # a step right after a step does not compare every ball with the calendar; every way of
    # changing the state in between must bring that comparison back
    scene, pos, vel, radii = gas(60, seed=4)
    sim = Simulator(scene, pos, vel, np.ones(60), radii)
    for _ in range(5):
        sim.step(1 / 60)
    dv = np.zeros((60, 2))
    dv[:, 0] = 0.5
    if change == "nudge":
        sim.nudge(dv)
    elif change == "set_balls":
        sim.set_balls(velocities=sim.velocities + dv)
    elif change == "set_state":
        state = sim.get_state()
        sim.set_state(state.replace(velocities=state.velocities + dv))
    else:
        sim.batch.live_arrays().velocities[0] += dv
    fresh = Simulator(scene, sim.positions, sim.velocities, np.ones(60), radii)
    for _ in range(5):
        a, b = sim.step(1 / 60), fresh.step(1 / 60)
        assert [(i.ball, i.other, i.wall) for i in a] == [(i.ball, i.other, i.wall) for i in b] and len(a) > 0
    np.testing.assert_allclose(sim.positions, fresh.positions, rtol=0, atol=1e-12)


@pytest.mark.parametrize("single", [True, False], ids=["Simulator", "BatchSimulator"])
def test_frames_record_the_periodic_image_counts(single):
    """Each frame's images are the simulator's after that step, so that ``positions + images *
    period`` is the unwrapped trajectory (zeros in a walled box)."""
    scene = Scene(bounds=(-1.0, -1.0, 1.0, 1.0), periodic=True)
    pos, vel = [[0.0, 0.0], [0.5, 0.5]], [[7.0, -3.0], [-2.0, 5.0]]
    if single:
        sim, loop = (Simulator(scene, pos, vel, [1.0, 1.0], [0.1, 0.1]) for _ in range(2))
    else:
        sim, loop = (BatchSimulator(scene, [pos, pos], [vel, vel], [1.0, 1.0], [0.1, 0.1]) for _ in range(2))
    rec = sim.frames(0.1, 30)
    for f in range(30):
        loop.step(0.1)
        np.testing.assert_array_equal(rec.images[f], loop.images)
        np.testing.assert_array_equal(rec.positions[f], loop.positions)
    assert np.abs(rec.images).max() >= 3
    unwrapped = rec.positions + rec.images * np.array(scene.period)
    np.testing.assert_allclose(unwrapped[-1], loop.unwrapped_positions)
    box = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), pos, vel, [1.0, 1.0], [0.1, 0.1])
    walled = box.frames(0.1, 5)
    assert walled.images.shape == (5, 2, 2) and not walled.images.any()
