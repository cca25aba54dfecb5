"""Impacts as a sequence over their records, the normal impulse of every impact, and the default
event cap (a gas runs its frames to the end; a cascade stops with the warning, in bounded time)."""

import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.bench.scale import lattice_gas
from collision_env.engine import (
    IMPACT_DTYPE,
    MODES,
    PLAY_AREA_1D,
    BatchSimulator,
    EventCapWarning,
    Impact,
    Impacts,
    Scene,
    Simulator,
)
from collision_env.engine.stepper import EVENTS_PER_BALL, MIN_EVENT_CAP, default_event_cap


def _box_gas(n=12, seed=0, masses=None, e=1.0):
    rng = np.random.default_rng(seed)
    side = np.linspace(-1.6, 1.6, 4)
    pos = np.stack(np.meshgrid(side, [-0.6, 0.0, 0.6]), -1).reshape(-1, 2)[:n]
    m = np.ones(n) if masses is None else masses
    return Simulator(Scene(elasticity=e), pos, rng.normal(size=(n, 2)), m, np.full(n, 0.1))


# --------------------------------------------------------------------------- the sequence
def test_impacts_is_a_sequence_of_impact_tuples_over_the_records():
    sim = _box_gas()
    imp = sim.step(1.0)
    assert isinstance(imp, Impacts) and imp.array.dtype == IMPACT_DTYPE and len(imp) == len(imp.array) > 5
    tuples = imp.to_list()
    assert all(type(i) is Impact for i in tuples) and list(imp) == tuples and imp == tuples
    first, last = imp[0], imp[-1]
    assert first == tuples[0] and last == tuples[-1]
    row = imp.array[0]
    fields = ("time", "ball", "speed", "impulse")
    assert tuple(getattr(first, f) for f in fields) == tuple(row[f] for f in fields)
    assert first.point == (row["x"], row["y"])
    assert imp[1:3] == tuples[1:3] and isinstance(imp[1:3], Impacts)
    walls = imp[imp["wall"] >= 0]
    assert all(i.wall is not None and i.other is None for i in walls)
    assert imp.wall_names == [i.wall for i in tuples]
    np.testing.assert_array_equal(imp.point, [i.point for i in tuples])
    np.testing.assert_array_equal(imp["time"], [i.time for i in tuples])
    assert imp.for_scene(0) == imp and len(imp.for_scene(1)) == 0
    with pytest.raises(IndexError):
        imp[len(imp)]
    assert sim.step(1e-12) == [] and not sim.step(1e-12)
    assert imp != imp[1:] and imp != tuples[1:] and (imp == "impacts") is False


@pytest.mark.parametrize("key", [None, True, False, np.True_, (None,), [[0, 1]], np.zeros((2, 2), dtype=int)])
def test_impacts_refuse_an_index_that_is_not_one_of_rows(key):
    # (on d8ab1a0 impacts[None] and impacts[True] gave 2-D arrays of records)
    imp = _box_gas().step(1.0)
    with pytest.raises(TypeError, match="impacts: index with an integer, a slice, a field name, a bool mask"):
        imp[key]
    assert len(imp[np.arange(len(imp)) % 2 == 0]) == (len(imp) + 1) // 2 and len(imp[[0, 2]]) == 2


@pytest.mark.parametrize("mode", MODES)
def test_a_steps_impacts_stay_as_they_were_through_later_steps(mode):
    # exact mode hands its records over without a copy (views of a buffer its kernel moves on
    # from), the cheap modes sort theirs into a copy: either way, the impacts a step returned,
    # its columns and rows taken from them, never change, whichever steps, frames or new impact
    # buffers follow (the buffer holds 4,096 rows: over 10,000 impacts go by)
    gas = _box_gas(seed=5)
    sim, twin = (
        Simulator(gas.scene, gas.positions, 40 * gas.velocities, gas.masses, gas.radii, mode=mode) for _ in range(2)
    )
    kept = [sim.step(0.5)]
    times, row = kept[0]["time"], kept[0][1:2]
    copies = [kept[0].array.copy()]
    seen = 0
    for k in range(300):
        imp = sim.step(0.6) if k % 3 else sim.frames(0.2, 3).impacts
        seen += len(imp)
        if k % 50 == 0:
            kept.append(imp)
            copies.append(imp.array.copy())
    assert min(len(c) for c in copies) > 5 and seen > 10_000
    for imp, copy in zip(kept, copies, strict=True):
        np.testing.assert_array_equal(imp.array, copy)
    np.testing.assert_array_equal(times, copies[0]["time"])
    np.testing.assert_array_equal(row.array, copies[0][1:2])
    # (and the state is a simulator's that kept nothing)
    twin.step(0.5)
    for k in range(300):
        twin.step(0.6) if k % 3 else twin.frames(0.2, 3)
    np.testing.assert_array_equal(twin.positions, sim.positions)


def test_frames_give_the_impacts_the_steps_give():
    a, b = _box_gas(seed=3), _box_gas(seed=3)
    rec = a.frames(0.05, 40)
    steps = [i for _ in range(40) for i in b.step(0.05)]
    assert isinstance(rec.impacts, Impacts) and rec.impacts == steps and len(steps) > 10


# --------------------------------------------------------------------------- the impulse
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("e", [1.0, 0.5])
def test_head_on_impulse_is_one_plus_e_times_reduced_mass_times_closing_speed(mode, e):
    # PhET Intro: m = 0.5 and 1.5 kg closing at 1.5 m/s; then ball 0 reaches the left wall
    sim = Simulator(Scene(elasticity=e), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5], mode=mode)
    v0 = sim.velocities
    (pair,) = sim.step(1.2)
    mu = 0.5 * 1.5 / 2.0
    assert pair.impulse == pytest.approx((1 + e) * mu * 1.5, rel=1e-12)
    assert pair.impulse == pytest.approx(0.5 * abs(sim.velocities[0, 0] - v0[0, 0]), rel=1e-12)  # m |Δv_n|
    v = abs(sim.velocities[0, 0])
    hits = [i for _ in range(40) for i in sim.step(0.1) if i.wall == "left"]
    assert hits[0].impulse == pytest.approx(0.5 * (1 + e) * v, rel=1e-12)


@pytest.mark.parametrize("mode", MODES)
def test_stick_impulse_is_the_plastic_impulse_of_the_bodies(mode):
    scene = Scene(elasticity=0.0, inelastic="stick")
    sim = Simulator(scene, [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5], mode=mode)
    (pair,) = sim.step(1.2)
    assert pair.impulse == pytest.approx(0.5 * 1.5 / 2.0 * 1.5, rel=1e-12)  # mu u: the pair moves as one
    speed = abs(sim.velocities[0, 0])
    hits = [i for _ in range(200) for i in sim.step(0.1) if i.wall is not None]
    assert hits[0].impulse == pytest.approx(2.0 * speed, rel=1e-12)  # the cluster (2 kg) stops dead


@pytest.mark.parametrize("mode", MODES)
def test_the_collapse_regularisers_push_apart_is_in_the_reported_impulse(mode):
    # e = 0, touching balls closing at 1e-10 m/s, below u_min (1e-9 of their speed, ~1.4e-9 m/s):
    # the response sets them apart at u_min, and the impulse reported is the one applied
    scene = Scene(elasticity=0.0)
    sim = Simulator(
        scene, [[0.0, 0.0], [0.4, 0.0]], [[1.0, 1.0], [1.0 - 1e-10, 1.0]], [1.0, 3.0], [0.2, 0.2], mode=mode
    )
    v0 = sim.velocities
    (pair,) = sim.step(0.1)
    applied = 3.0 * abs(sim.velocities[1, 0] - v0[1, 0])
    assert pair.impulse == pytest.approx(applied, rel=1e-6)
    assert sim.velocities[1, 0] - sim.velocities[0, 0] > 0.0  # (apart, not merely stopped)
    assert pair.impulse > 0.75 * pair.speed * 1.5  # (more than the plastic mu u: the push-apart is in it)


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_a_contacts_reported_impulses_are_at_most_the_momentum_it_passes(e):
    # a 1D row of 4 touching balls against the right wall, hit by a fifth: the momentum contact k
    # passes rightwards in the step (ball k to k + 1, the last to the wall) is J_k = -sum_{i <= k} dp_i.
    # A contact group reports each contact's first impulse only (impacts.py): at most J_k, and
    # all of it outside groups (e = 1)
    n, r = 5, 0.1
    pos = [[0.0, 0.0]] + [[2.0 - r - 2 * r * k, 0.0] for k in range(n - 1)][::-1]
    vel = [[1.0, 0.0]] + [[0.0, 0.0]] * (n - 1)
    sim = Simulator(Scene(bounds=PLAY_AREA_1D, dimension=1, elasticity=e), pos, vel, np.ones(n), np.full(n, r))
    v0 = sim.velocities
    imp = sim.step(1.5)
    passed = -np.cumsum(sim.velocities[:, 0] - v0[:, 0])
    reported = np.zeros(n)
    for i in imp:
        assert i.other is None or abs(i.other - i.ball) == 1
        reported[i.ball if i.other is None else min(i.ball, i.other)] += i.impulse
    assert (reported > 0.0).all() and (reported <= passed * (1 + 1e-9)).all()
    if e == 1.0:
        np.testing.assert_allclose(reported, passed, rtol=1e-12)


@settings(max_examples=40, deadline=None)
@given(log_ratio=st.floats(-6.0, 6.0), seed=st.integers(0, 2**16))
def test_wall_impulses_account_for_the_momentum_a_gas_gains(log_ratio, seed):
    # elastic balls only push each other (equal and opposite): the box's total momentum changes by
    # the wall impulses along the walls' inward normals, whatever the masses
    masses = np.where(np.arange(12) % 2 == 0, 1.0, 10.0**log_ratio)
    sim = _box_gas(seed=seed, masses=masses)
    p0 = sim.momentum()
    imp = sim.frames(0.1, 10).impacts
    inward = {"left": (1, 0), "right": (-1, 0), "bottom": (0, 1), "top": (0, -1)}
    walls = [i for i in imp if i.wall is not None]
    gained = sum((i.impulse * np.array(inward[i.wall]) for i in walls), np.zeros(2))
    scale = sum(i.impulse for i in imp)
    np.testing.assert_allclose(sim.momentum() - p0, gained, atol=1e-11 * scale)
    assert all(i.impulse > 0 for i in imp)


# --------------------------------------------------------------------------- the default event cap
def test_default_cap_is_a_budget_per_ball():
    assert default_event_cap(2) == MIN_EVENT_CAP
    assert default_event_cap(10**6) == EVENTS_PER_BALL * 10**6
    assert _box_gas(n=5).batch.max_events == MIN_EVENT_CAP and _box_gas(n=12).batch.max_events == 12_000
    assert Simulator(Scene(), [[0, 0]], [[1, 0]], [1.0], max_events=7).batch.max_events == 7


@pytest.mark.parametrize("n, packing, frames", [(40_000, 0.3, 6), (2_500, 0.7, 6)])
def test_a_large_gas_runs_its_frames_to_the_end_with_the_default_cap(n, packing, frames):
    scene, pos, vel = lattice_gas(n, packing)
    sim = BatchSimulator(scene, pos[None], vel[None], np.ones(n), np.full(n, 0.01))
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventCapWarning)
        rec = sim.frames(1 / 60, frames)
    assert not sim.cap_reached.any() and sim.time[0] == pytest.approx(frames / 60, rel=1e-12)
    per_frame = np.histogram(rec.impacts["time"], bins=frames, range=(0.0, frames / 60))[0]
    if n > MIN_EVENT_CAP:  # (the former fixed default, 10^4 per step, would have cut its frames short)
        assert per_frame.max() > MIN_EVENT_CAP


def _elastic_squeeze():
    """A light ball at the wall, a 1e15 times heavier one pressing it: about pi sqrt(1e15) collisions."""
    scene = Scene(bounds=PLAY_AREA_1D, dimension=1)
    return Simulator(scene, [[-1.9, 0], [-1.5, 0]], [[0, 0], [-1, 0]], [1.0, 1e15], [0.1, 0.1])


def _inelastic_collapse():
    """e = 0.999: the gap between a wall and a 1e15 times heavier ball collapses on a light ball."""
    scene = Scene(bounds=PLAY_AREA_1D, dimension=1, elasticity=0.999)
    return Simulator(scene, [[-1.5, 0], [-1.0, 0]], [[0, 0], [-1, 0]], [1.0, 1e15], [0.1, 0.1])


def _jammed_network():
    """A square lattice of touching disks that fills its box exactly, every disk moving."""
    r, m = 0.1, 10
    side = (np.arange(m) + 0.5) * 2 * r - m * r
    pos = np.stack(np.meshgrid(side, side), -1).reshape(-1, 2)
    vel = np.random.default_rng(0).normal(size=pos.shape)
    return Simulator(Scene(bounds=(-m * r, -m * r, m * r, m * r)), pos, vel, np.ones(m * m), np.full(m * m, r))


def test_a_jammed_network_never_enters():
    # (its cascade would never advance the clock: it is refused where a state enters)
    with pytest.raises(ValueError, match="reach from wall to wall"):
        _jammed_network()


@pytest.mark.parametrize("make", [_elastic_squeeze, _inelastic_collapse])
def test_a_cascade_stops_at_the_default_cap_with_the_warning(make):
    sim = make()
    start = time.perf_counter()
    with pytest.warns(EventCapWarning, match=f"event cap of {default_event_cap(len(sim.radii))}"):
        hits = sim.step(1.0)
    elapsed = time.perf_counter() - start
    assert sim.cap_reached and len(hits) <= default_event_cap(len(sim.radii)) and sim.time < 1.0
    assert elapsed < 10.0  # bounded: at most EVENTS_PER_BALL events per ball (a generous bound on a shared machine)
    p, r = sim.positions, sim.radii
    d = np.linalg.norm(p[:, None] - p[None], axis=-1) + np.eye(len(r)) * 1e9
    assert np.all(d >= (r[:, None] + r[None]) * (1 - 1e-9)) and math.isfinite(sim.kinetic_energy())


def test_a_steps_impacts_looked_at_late_are_those_an_early_look_saw():
    # exact mode's step records are viewed at the first look, which may come after the kernel has
    # moved on to new buffers (4,096 rows each): what it sees is what a look at once saw, and a
    # pickle or copy is a plain Impacts of the rows
    import copy
    import pickle

    gas = _box_gas(seed=7)
    sim, twin = (Simulator(gas.scene, gas.positions, 40 * gas.velocities, gas.masses, gas.radii) for _ in range(2))
    late, early = [], []
    for _ in range(200):
        late.append(sim.step(0.6))
        early.append(twin.step(0.6).array.copy())
    assert sum(len(c) for c in early) > 10_000
    for imp, rows in zip(late, early, strict=True):
        np.testing.assert_array_equal(imp.array, rows)
    for clone in (pickle.loads(pickle.dumps(late[-1])), copy.copy(late[-1]), copy.deepcopy(late[-2])):
        assert type(clone) is Impacts
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(late[-1])).array, early[-1])
    np.testing.assert_array_equal(copy.deepcopy(late[-2]).array, early[-2])
