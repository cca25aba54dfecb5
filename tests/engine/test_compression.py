"""Compression of hard disks (Lubachevsky–Stillinger): the growing disks' time of impact and bounce
against closed forms, the event loop against the exact engine, no overlap at any point, jamming."""

import math
import warnings

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from collision_env.engine import CompressionWarning, Scene, compress, disk_gas
from collision_env.engine import compression as compression_module
from collision_env.engine.physics.periodic import wrap_positions


def gaps(positions, radii, scene):
    """Every pair's surface-to-surface distance relative to its contact distance (all pairs, nearest
    image in a periodic cell)."""
    d = positions[None] - positions[:, None]
    if scene.periodic:
        x0, y0, x1, y1 = scene.bounds
        period = np.array([x1 - x0, y1 - y0])
        d -= period * np.floor(d / period + 0.5)
    sigma = radii[:, None] + radii[None]
    rel = np.sqrt((d**2).sum(-1)) / sigma - 1.0
    np.fill_diagonal(rel, np.inf)
    return rel


def quiet_compress(*args, **kwargs):
    """``compress`` that may stop on its budget (the warning is expected)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CompressionWarning)
        return compress(*args, progress=False, **kwargs)


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("speed", [0.0, 0.5, -0.005])
def test_growing_disks_meet_when_the_closed_form_says(speed, periodic):
    # two equal disks on the x axis, d apart, approaching at u each: d - 2 u t = sigma (1 + gamma t),
    # t = (d - sigma) / (2 u + sigma gamma); at u = 0 the growth alone closes the gap, and disks that
    # move apart (u < 0) slower than their contact distance grows still meet
    distance, radius, rate, drift = 3.0, 0.5, 0.2, 0.1
    scene = Scene(bounds=(-1000.0, -1000.0, 1000.0, 1000.0), periodic=periodic)
    pos = [[-distance / 2, 0.0], [distance / 2, 0.0]]
    vel = [[speed, drift], [-speed, drift]]  # (the common drift along y keeps K > 0, closing nothing)
    kinetic = speed**2 + drift**2
    gamma = rate * math.sqrt(kinetic / 2) / (2 * radius)  # the thermal speed sqrt(K / (N m)) per mean diameter
    sigma = 2 * radius
    expected = (distance - sigma) / (2 * speed + sigma * gamma)
    packing = quiet_compress(scene, pos, [radius, radius], velocities=vel, masses=[1.0, 1.0], rate=rate, max_events=1)
    assert packing.events == 1
    assert packing.time == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(packing.radii, radius * (1 + gamma * expected), rtol=1e-12)
    dx = packing.positions[1, 0] - packing.positions[0, 0]
    assert dx == pytest.approx(packing.radii.sum(), rel=1e-12)
    # they bounce about the growth speed, u' = 2 sigma_dot - u: apart faster than sigma grows (the
    # velocities then rescaled to the starting kinetic energy)
    u_after = 2 * sigma * gamma + 2 * speed
    scale = math.sqrt(kinetic / ((u_after / 2) ** 2 + drift**2))
    assert packing.velocities[1, 0] - packing.velocities[0, 0] == pytest.approx(u_after * scale, rel=1e-12)
    np.testing.assert_allclose(packing.velocities[:, 1], drift * scale, rtol=1e-12)


def test_a_growing_disk_meets_a_wall_when_the_closed_form_says():
    # x + v t + r (1 + gamma t) = x1
    scene = Scene(bounds=(0.0, 0.0, 10.0, 10.0))
    pos = [[5.0, 5.0], [2.0, 2.0]]
    vel = [[1.0, 0.0], [0.0, 0.0]]
    packing = quiet_compress(scene, pos, [0.5, 0.5], velocities=vel, masses=[1.0, 1.0], rate=0.01, max_events=1)
    gamma = 0.01 * math.sqrt(0.5 / 2) / 1.0
    expected = (10.0 - 5.0 - 0.5) / (1.0 + 0.5 * gamma)
    assert packing.time == pytest.approx(expected, rel=1e-12)
    assert packing.positions[0, 0] + packing.radii[0] == pytest.approx(10.0, rel=1e-14)
    assert packing.velocities[0, 0] < 0.0


@pytest.mark.parametrize("periodic", [False, True])
def test_without_growth_the_event_loop_follows_the_exact_engine(periodic):
    # the same collisions at the same times, the same state after them, and the same pressure
    gas = disk_gas(40, 0.35, arrangement="random", periodic=periodic, diameters=(1.0, 1.4), seed=5)
    events = 150  # (under a window of 4 N: the pressure is that of every collision)
    packing = quiet_compress(
        gas.scene, gas.positions, gas.radii, velocities=gas.velocities, masses=gas.masses, rate=0.0, max_events=events
    )
    assert packing.events == events and not packing.jammed
    np.testing.assert_array_equal(packing.radii, gas.radii)
    sim = gas.simulator()
    records = sim.step(packing.time).array
    if len(records) == events - 1:  # (the last is at the step's end, which round-off may put just after it)
        records = np.concatenate([records, sim.step(1e-9).array])
    assert len(records) == events
    expected = sim.positions
    if periodic:
        expected = wrap_positions(expected, gas.scene.bounds, 2)[0]
        got = packing.positions.copy()
        period = np.array(gas.scene.bounds[2:])
        diff = got - expected
        diff -= period * np.round(diff / period)  # (a coordinate on the cell edge may be wrapped either way)
    else:
        diff = packing.positions - expected
    # (as far apart as round-off, amplified by the gas's chaos over 5 collisions per disk, and the
    # extra nanosecond, make them)
    assert np.abs(diff).max() < 1e-8
    assert np.abs(packing.velocities - sim.velocities).max() < 1e-8
    # Z = 1 + W / (d N kT t): W sums sigma_ij J_ij over the pairs and r_i J_i over the walls, and kT =
    # 2 K / (d (N - 1)) in a periodic cell (the gas's momentum is 0), 2 K / (d N) in a box
    pairs = records[records["other"] >= 0]
    walls = records[records["other"] < 0]
    virial = np.sum((gas.radii[pairs["ball"]] + gas.radii[pairs["other"]]) * pairs["impulse"])
    virial += np.sum(gas.radii[walls["ball"]] * walls["impulse"])
    n = len(gas.radii)
    kT = gas.kinetic_energy() / (n - 1 if periodic else n)
    assert packing.reduced_pressure == pytest.approx(1 + virial / (2 * n * kT * packing.time), rel=1e-8)
    assert len(walls) == 0 if periodic else len(walls) > 0


@given(
    n=st.integers(2, 40),
    fraction=st.floats(0.05, 0.45),
    periodic=st.booleans(),
    log_rate=st.floats(-4.0, 2.0),
    log_mass_ratio=st.floats(-6.0, 6.0),
    events=st.integers(1, 3000),
    seed=st.integers(0, 2**31),
)
@settings(max_examples=100, deadline=None)
def test_compression_never_overlaps_and_holds_the_temperature(
    n, fraction, periodic, log_rate, log_mass_ratio, events, seed
):
    try:
        gas = disk_gas(n, fraction, arrangement="random", periodic=periodic, diameters=(1.0, 1.4), seed=seed)
    except ValueError:  # (too few disks for a periodic cell this dense: its own test's business)
        return
    assume(not periodic or 4 * gas.radii.max() < min(gas.scene.bounds[2:]))  # (the minimum image)
    masses = np.where(np.arange(n) % 2, 10.0**log_mass_ratio, 1.0)  # (the large and the small disks)
    packing = quiet_compress(
        gas.scene,
        gas.positions,
        gas.radii,
        masses=masses,
        rate=10.0**log_rate,
        max_events=events,
        until_pressure=1e9,
        seed=seed,
    )
    # (a disk of a few in a small periodic cell may reach half the cell before any collision)
    assert packing.time > 0.0 and 0 <= packing.events <= events
    # the radii grew in proportion, and the packing fraction is theirs
    ratio = packing.radii / gas.radii
    assert ratio.min() > 1.0 and np.ptp(ratio) <= 1e-12 * ratio.max()
    area = np.prod(np.subtract(gas.scene.bounds[2:], gas.scene.bounds[:2]))
    assert packing.packing_fraction == pytest.approx(np.pi * np.sum(packing.radii**2) / area, rel=1e-12)
    # no overlap, beyond round-off; inside the box, or wrapped into the cell
    assert gaps(packing.positions, packing.radii, gas.scene).min() > -1e-12
    x0, y0, x1, y1 = gas.scene.bounds
    lo, hi = np.array([x0, y0]), np.array([x1, y1])
    if periodic:
        assert ((packing.positions >= lo) & (packing.positions < hi)).all()
    else:
        r = packing.radii[:, None]
        assert ((packing.positions - r >= lo - 1e-12) & (packing.positions + r <= hi + 1e-12)).all()
    kinetic = 0.5 * np.sum(packing.masses * np.sum(packing.velocities**2, axis=1))
    start = 0.5 * np.sum(masses * np.sum(compression_module._maxwell(masses, seed, n) ** 2, axis=1))
    assert kinetic == pytest.approx(start, rel=1e-12)
    # the exact engine takes the packing as it is
    packing.gas().simulator()


@pytest.mark.parametrize("periodic", [False, True])
def test_a_bidisperse_packing_jams_near_the_random_close_packing(periodic):
    gas = disk_gas(128, 0.3, arrangement="random", periodic=periodic, diameters=(1.0, 1.4), seed=11)
    packing = compress(gas.scene, gas.positions, gas.radii, rate=0.05, until_pressure=1e4, seed=1, progress=False)
    assert packing.jammed and packing.reduced_pressure >= 1e4
    # O'Hern et al. (2003): phi_J ~ 0.84 in a periodic cell; the walls of a small box pack less densely
    assert (0.80 if periodic else 0.74) < packing.packing_fraction < 0.87
    assert gaps(packing.positions, packing.radii, gas.scene).min() > -1e-12
    # jammed: the gaps of its network are of order 1 / Z of a diameter
    assert np.sort(gaps(packing.positions, packing.radii, gas.scene).min(axis=1))[len(gas.radii) // 2] < 1e-2


def test_the_same_inputs_give_the_same_packing():
    gas = disk_gas(50, 0.3, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=3)
    a, b = (
        compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_pressure=100.0, seed=4, progress=False)
        for _ in range(2)
    )
    np.testing.assert_array_equal(a.positions, b.positions)
    assert (a.events, a.time, a.reduced_pressure) == (b.events, b.time, b.reduced_pressure)


def test_a_spent_budget_warns_and_says_so():
    gas = disk_gas(30, 0.3, periodic=True, seed=1)
    with pytest.warns(CompressionWarning, match="max_events"):
        packing = compress(gas.scene, gas.positions, gas.radii, max_events=50, seed=1, progress=False)
    assert packing.events == 50 and not packing.jammed


def test_a_small_cell_stops_the_largest_disk_at_half_its_width():
    scene = Scene(bounds=(0.0, 0.0, 4.0, 4.0), periodic=True)
    with pytest.warns(CompressionWarning, match="half the periodic cell"):
        packing = compress(scene, [[1.0, 1.0], [3.0, 3.0]], [0.2, 0.2], rate=1.0, seed=1, progress=False)
    assert 2 * packing.radii.max() == pytest.approx(2.0, rel=1e-8) and 4 * packing.radii.max() < 4.0
    packing.gas().simulator()


def test_progress_is_shown_on_long_runs(monkeypatch, capsys):
    monkeypatch.setattr(compression_module, "PROGRESS_SECONDS", 0.0)
    gas = disk_gas(30, 0.3, periodic=True, seed=1)
    compress(gas.scene, gas.positions, gas.radii, rate=0.5, until_pressure=50.0, seed=1)
    err = capsys.readouterr().err
    assert "compress: phi 0." in err and "collisions" in err


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda g: compress(Scene(bounds=None), g.positions, g.radii), ValueError, "scene: compress needs"),
        (lambda g: compress(Scene(dimension=1), [[0, 0], [2, 0]], [0.5, 0.5]), ValueError, "2D scene"),
        (lambda g: compress("box", g.positions, g.radii), TypeError, "scene: expected a Scene"),
        (lambda g: compress(g.scene, g.positions, g.radii, rate=-1.0), ValueError, "rate"),
        (lambda g: compress(g.scene, g.positions, g.radii, rate=math.nan), ValueError, "rate"),
        (lambda g: compress(g.scene, g.positions, g.radii, until_pressure=1.0), ValueError, "until_pressure"),
        (lambda g: compress(g.scene, g.positions, g.radii, max_events=0), ValueError, "max_events"),
        (lambda g: compress(g.scene, g.positions[:1], g.radii[:1]), ValueError, "positions: expected shape"),
        (lambda g: compress(g.scene, g.positions, g.radii[:3]), ValueError, "radii: expected shape"),
        (lambda g: compress(g.scene, g.positions, g.radii, masses=-g.masses), ValueError, "ball 0: mass"),
        (lambda g: compress(g.scene, g.positions, g.radii, velocities=0 * g.velocities), ValueError, "velocities"),
        (
            lambda g: compress(g.scene, np.vstack([g.positions[:1], g.positions[:1], g.positions[2:]]), g.radii),
            ValueError,
            "ball 0: position overlaps ball 1",
        ),
        (lambda g: compress(g.scene, g.positions, g.radii * 1e6), ValueError, "ball 0: radius"),
        (
            lambda g: compress(Scene(bounds=(0, 0, 30, 30), elasticity=0.5), g.positions, g.radii),
            ValueError,
            "scene: compress bounces the disks elastically; got elasticity 0.5",
        ),
        (
            lambda g: compress(Scene(bounds=(0, 0, 30, 30), elasticity=0.0, inelastic="stick"), g.positions, g.radii),
            ValueError,
            "inelastic 'stick'",
        ),
        (lambda g: compress(g.scene, g.positions, g.radii, until_phi=1.0), ValueError, "until_phi"),
        (lambda g: compress(g.scene, g.positions, g.radii, until_phi=math.nan), ValueError, "until_phi"),
        (lambda g: compress(g.scene, g.positions, g.radii, until_phi="0.5"), ValueError, "until_phi"),
        (lambda g: compress(g.scene, g.positions, g.radii, until_phi=0.2), ValueError, "above the starting"),
        (lambda g: compress(g.scene, g.positions, g.radii, until_phi=0.5, rate=0.0), ValueError, "rate 0"),
    ],
)
def test_bad_input_is_refused(call, error, message):
    gas = disk_gas(20, 0.3, periodic=True, seed=2)
    with pytest.raises(error, match=message):
        call(gas)


def test_disks_that_no_longer_meet_end_the_run():
    # without growth, two disks moving side by side in a periodic cell never meet
    scene = Scene(bounds=(0.0, 0.0, 10.0, 10.0), periodic=True)
    with pytest.warns(CompressionWarning, match="stopped meeting"):
        packing = compress(
            scene, [[2.0, 2.0], [2.0, 6.0]], [0.5, 0.5], velocities=[[1.0, 0.0], [1.0, 0.0]], rate=0.0, progress=False
        )
    assert packing.events == 0 and packing.time > 0.0
    assert packing.reduced_pressure == 1.0  # (no collision: the virial is 0)


@pytest.mark.parametrize("periodic", [False, True])
def test_compression_stops_at_the_area_fraction_asked_for(periodic):
    gas = disk_gas(100, 0.3, arrangement="random", periodic=periodic, diameters=(1.0, 1.4), seed=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CompressionWarning)  # (reached: no warning)
        packing = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_phi=0.7, seed=1, progress=False)
    assert packing.packing_fraction == pytest.approx(0.7, rel=1e-12) and not packing.jammed
    ratio = packing.radii / gas.radii
    assert np.ptp(ratio) <= 1e-12 * ratio.max()
    assert gaps(packing.positions, packing.radii, gas.scene).min() > -1e-12
    assert 5 < packing.reduced_pressure < 30  # (a dense fluid, not a jam)
    packing.gas().simulator()


def test_an_area_fraction_beyond_jamming_stops_at_the_jam_and_says_so():
    gas = disk_gas(60, 0.3, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=4)
    with pytest.warns(CompressionWarning, match="jammed at phi = 0.8"):
        packing = compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_phi=0.95, seed=1, progress=False)
    assert packing.jammed and packing.packing_fraction < 0.9


@pytest.mark.parametrize("seed", range(6))
def test_a_box_compressed_beyond_the_contact_tolerance_is_one_the_engine_takes(seed):
    # at Z ~ 1e10 the gaps are ~1e-10 of a diameter, within the engine's contact tolerance (1e-9):
    # the touching disks reach from wall to wall, which the engine refuses as jammed; the radii are
    # shrunk a few 1e-9 instead
    gas = disk_gas(30, 0.3, arrangement="random", diameters=(1.0, 1.4), seed=seed)
    packing = quiet_compress(gas.scene, gas.positions, gas.radii, rate=0.1, until_pressure=1e10, seed=seed)
    assert packing.jammed
    ratio = packing.radii / gas.radii
    assert np.ptp(ratio) <= 1e-12 * ratio.max()  # (still in proportion)
    nearest = gaps(packing.positions, packing.radii, gas.scene).min(axis=1)
    assert nearest.min() > 1e-9 and np.median(nearest) < 1e-7  # (open, by no more than a few 1e-9)
    packing.gas().simulator()
