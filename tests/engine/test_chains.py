"""Event-chain Monte Carlo: no overlap at any point, the chains' displacement in the image counts, the
pressure against a published reference and the dilute limit, determinism, and bad input."""

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine import EventChainWarning, Scene, disk_gas, event_chain
from collision_env.engine.blocking import new_blocks, push_all, standard_error

from .test_compression import gaps


def square_cell(n, packing, columns, rows):
    """``n`` disks of diameter 1 on a ``columns`` x ``rows`` square lattice in a square periodic cell at
    area fraction ``packing``."""
    side = math.sqrt(n * math.pi / 4 / packing)
    ix, iy = np.divmod(np.arange(n), rows)
    positions = np.stack([(ix + 0.5) * side / columns, (iy + 0.5) * side / rows], axis=1)
    return Scene(bounds=(0.0, 0.0, side, side), periodic=True), positions, np.full(n, 0.5)


def quiet_chains(*args, **kwargs):
    return event_chain(*args, progress=False, **kwargs)


def test_the_pressure_of_72_disks_is_li_et_al_s():
    # Li et al., J. Chem. Phys. 157, 234111 (2022), ThisWork.csv: N = 72, square cell, phi = 0.65,
    # beta P (2 sigma)^2 = 6.901074 +- 7.1e-5 (diameter 2 sigma = 1)
    scene, positions, radii = square_cell(72, 0.65, 9, 8)
    melted = quiet_chains(scene, positions, radii, events=200_000, seed=1)
    run = quiet_chains(scene, melted.positions, radii, events=2_000_000, seed=2)
    to_reference = 4 * 0.65 / math.pi  # beta P sigma^2 = Z N / A
    assert run.events == 2_000_000 and run.chains > 20_000
    assert 0.0 < run.pressure_error < 2e-3 * run.reduced_pressure
    assert abs(run.reduced_pressure * to_reference - 6.901074) < 4 * run.pressure_error * to_reference


def test_a_dilute_gas_follows_the_virial_series():
    # Z = 1 + 2 phi (N - 1) / N + 3.128 phi^2 + O(phi^3): N disks in a cell meet N - 1 partners, not N
    n, phi = 64, 0.05
    gas = disk_gas(n, phi, periodic=True, seed=3)
    run = quiet_chains(gas.scene, gas.positions, gas.radii, events=300_000, seed=4)
    expected = 1 + 2 * phi * (n - 1) / n + 3.12802 * phi**2
    assert abs(run.reduced_pressure - expected) < 4 * run.pressure_error + 4.3 * phi**3
    assert run.pressure_error < 2e-3


@given(
    n=st.integers(2, 40),
    fraction=st.floats(0.05, 0.45),
    dense=st.floats(0.0, 0.45),
    log_length=st.floats(-3.0, 1.5),
    events=st.integers(1, 3000),
    seed=st.integers(0, 2**31),
)
@settings(max_examples=100, deadline=None)
def test_chains_never_overlap_and_the_images_count_their_displacement(n, fraction, dense, log_length, events, seed):
    try:
        if dense:  # a lattice of equal disks, up to near close packing (0.9069)
            gas = disk_gas(n, fraction + dense, periodic=True, seed=seed)
        else:  # the bidisperse mixture at random
            gas = disk_gas(n, fraction, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=seed)
    except ValueError:  # (too few disks for a periodic cell this dense)
        return
    scene = gas.scene
    if not 4 * gas.radii.max() < min(scene.period):  # (the minimum image)
        return
    length = 10.0**log_length * max(scene.period)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", EventChainWarning)  # (a cell too dilute for the disks to meet)
        run = quiet_chains(scene, gas.positions, gas.radii, events=events, chain_length=length, seed=seed)
    assert run.events <= events
    assert gaps(run.positions, run.radii, scene).min() > -1e-12
    lo, hi = np.array(scene.bounds[:2]), np.array(scene.bounds[2:])
    assert ((run.positions >= lo) & (run.positions < hi)).all()
    # disks move only along +x and +y, each chain by its length in all (the last one maybe part way)
    moved = run.unwrapped_positions - gas.positions
    tolerance = 1e-9 * (length * (run.chains + 1) + max(scene.period))
    assert moved.min() > -tolerance
    along_x, along_y = moved.sum(axis=0)
    assert along_x > length * math.ceil(run.chains / 2) - tolerance
    assert along_y > length * (run.chains // 2) - tolerance
    assert length * run.chains - tolerance < along_x + along_y < length * (run.chains + 1) + tolerance


def test_the_same_seed_gives_the_same_run_whether_progress_is_shown_or_not(capsys):
    gas = disk_gas(100, 0.6, periodic=True, seed=5)
    a = quiet_chains(gas.scene, gas.positions, gas.radii, events=50_001, seed=6)
    b = event_chain(gas.scene, gas.positions, gas.radii, events=50_001, seed=6, progress=True)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.images, b.images)
    assert (a.reduced_pressure, a.pressure_error, a.chains) == (b.reduced_pressure, b.pressure_error, b.chains)
    c = quiet_chains(gas.scene, gas.positions, gas.radii, events=50_001, seed=7)
    assert not np.array_equal(a.positions, c.positions)
    # not a terminal: a line per tenth of the run
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 10 and lines[-1].startswith("event_chain: 100 % (50,001 events")


def test_the_input_is_left_as_it_was():
    gas = disk_gas(30, 0.4, periodic=True, seed=8)
    positions, radii = gas.positions.copy(), gas.radii.copy()
    quiet_chains(gas.scene, gas.positions, gas.radii, events=1000, seed=1)
    np.testing.assert_array_equal(gas.positions, positions)
    np.testing.assert_array_equal(gas.radii, radii)


def test_positions_outside_the_cell_are_wrapped_and_their_images_counted():
    # (a few events: the chains, like the dynamics, amplify round-off, here the wrapping's, at each
    # grazing contact; and at random, not on a lattice, where two disks hit at once tie by an ulp)
    gas = disk_gas(30, 0.3, arrangement="random", periodic=True, seed=9)
    period = np.array(gas.scene.period)
    shifted = gas.positions + period * [2, -1]
    run = quiet_chains(gas.scene, shifted, gas.radii, events=30, chain_length=1.0, seed=1)
    same = quiet_chains(gas.scene, gas.positions, gas.radii, events=30, chain_length=1.0, seed=1)
    assert run.chains > 2
    np.testing.assert_allclose(run.unwrapped_positions, same.unwrapped_positions + period * [2, -1], atol=1e-9)


def test_disks_that_never_meet_end_the_run_after_as_many_chains_as_events():
    # each chain moves a disk by exactly a hundred periods: nothing ever changes, and no disk meets
    # another (the chains cost a lap each, not a hundred)
    scene = Scene(bounds=(0.0, 0.0, 10.0, 10.0), periodic=True)
    with pytest.warns(EventChainWarning, match="shorter than the distance between liftings"):
        run = quiet_chains(scene, [[1.0, 1.0], [5.0, 5.0]], [0.5, 0.5], events=1000, chain_length=1000.0, seed=1)
    assert (run.events, run.chains) == (0, 1000)
    assert run.reduced_pressure == 1.0 and run.pressure_error == 0.0
    np.testing.assert_allclose(run.positions, [[1.0, 1.0], [5.0, 5.0]], atol=1e-9)
    assert run.images.sum() == 100 * 1000


def test_chains_shorter_than_the_free_path_end_the_run_too():
    gas = disk_gas(30, 0.3, periodic=True, seed=9)
    with pytest.warns(EventChainWarning):
        run = quiet_chains(gas.scene, gas.positions, gas.radii, events=1000, chain_length=1e-9, seed=1)
    assert run.chains == 1000 and run.events < 10


def test_a_jammed_row_gives_an_infinite_pressure_not_a_hang():
    # a row of touching disks around the cell: a chain along it hands on without moving
    scene = Scene(bounds=(0.0, 0.0, 8.0, 8.0), periodic=True)
    positions = np.stack([np.arange(8) + 0.5, np.full(8, 4.0)], axis=1)
    run = quiet_chains(scene, positions, np.full(8, 0.5), events=1000, chain_length=1.0, seed=1)
    assert run.events == 1000
    assert run.reduced_pressure > 1.0 and not math.isnan(run.reduced_pressure)
    assert gaps(run.positions, run.radii, scene).min() > -1e-12


@pytest.mark.parametrize("packing", [0.2, 0.6])
def test_the_default_chain_holds_about_four_root_n_liftings(packing):
    gas = disk_gas(400, packing, periodic=True, seed=10)
    run = quiet_chains(gas.scene, gas.positions, gas.radii, events=100_000, seed=1)
    assert 2 * math.sqrt(400) < run.events / run.chains < 8 * math.sqrt(400)


def test_blocking_finds_the_error_of_a_correlated_series():
    # an AR(1) series x_k = a x_(k-1) + noise: the mean's error is sqrt((1 + a) / (1 - a)) times the
    # naive one
    rng = np.random.default_rng(1)
    a, n = 0.9, 2**18
    noise = rng.normal(size=n)
    x = np.empty(n)
    x[0] = noise[0]
    for k in range(1, n):
        x[k] = a * x[k - 1] + noise[k]
    blocks = new_blocks()
    push_all(blocks, x)
    naive = x.std() / math.sqrt(n)
    assert standard_error(blocks) == pytest.approx(naive * math.sqrt((1 + a) / (1 - a)), rel=0.25)
    assert blocks[0, 1] == pytest.approx(x.mean(), abs=1e-12)
    short = new_blocks()
    push_all(short, x[:20])
    assert standard_error(short) == math.inf  # too few values to tell


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda g: event_chain("cell", g.positions, g.radii, events=1), TypeError, "scene: expected a Scene"),
        (lambda g: event_chain(Scene(bounds=(0, 0, 9, 9)), g.positions, g.radii, events=1), ValueError, "periodic"),
        (
            lambda g: event_chain(Scene(bounds=None, periodic=False), g.positions, g.radii, events=1),
            ValueError,
            "periodic",
        ),
        (
            lambda g: event_chain(dataclasses.replace(g.scene, elasticity=0.5), g.positions, g.radii, events=1),
            ValueError,
            "elastic",
        ),
        (
            lambda g: event_chain(dataclasses.replace(g.scene, ball_collisions=False), g.positions, g.radii, events=1),
            ValueError,
            "ball collisions",
        ),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=0), ValueError, "events"),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=1.5), ValueError, "events"),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=True), ValueError, "events"),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=2**60), ValueError, "events"),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=1, chain_length=0.0), ValueError, "chain_length"),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=1, chain_length=-1), ValueError, "chain_length"),
        (
            lambda g: event_chain(g.scene, g.positions, g.radii, events=1, chain_length=math.nan),
            ValueError,
            "chain_length",
        ),
        (
            lambda g: event_chain(g.scene, g.positions, g.radii, events=1, chain_length=1e300),
            ValueError,
            "chain_length",
        ),
        (lambda g: event_chain(g.scene, g.positions, g.radii, events=1, chain_length="1"), ValueError, "chain_length"),
        (lambda g: event_chain(g.scene, g.positions[:1], g.radii[:1], events=1), ValueError, "positions: expected"),
        (lambda g: event_chain(g.scene, g.positions, g.radii[:3], events=1), ValueError, "radii: expected shape"),
        (lambda g: event_chain(g.scene, g.positions, None, events=1), ValueError, "radii: expected 20 radii"),
        (lambda g: event_chain(g.scene, g.positions, -g.radii, events=1), ValueError, "ball 0: radius"),
        (lambda g: event_chain(g.scene, g.positions, g.radii * 1e3, events=1), ValueError, "ball 0: radius"),
        (
            lambda g: event_chain(
                g.scene, np.where(np.arange(20)[:, None] == 3, np.nan, g.positions), g.radii, events=1
            ),
            ValueError,
            "ball 3: position",
        ),
        (
            lambda g: event_chain(
                g.scene, np.vstack([g.positions[:1], g.positions[:1], g.positions[2:]]), g.radii, events=1
            ),
            ValueError,
            "ball 0: position overlaps ball 1",
        ),
    ],
)
def test_bad_input_is_refused(call, error, message):
    gas = disk_gas(20, 0.3, periodic=True, seed=2)
    with pytest.raises(error, match=message):
        call(gas)
