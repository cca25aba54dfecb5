"""Trajectories out and in: GSD files that freud and gsd.hoomd read, round trips bit for bit, a
state the engine takes back, streaming by appends, extended XYZ to 17 digits."""

import math
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from collision_env.engine import Scene, Simulator, disk_gas
from collision_env.extras import MissingExtra
from collision_env.io import read_gsd, write_gsd, write_xyz

gsd_hoomd = pytest.importorskip("gsd.hoomd")


def _recorded(sim, dt, n):
    """A Simulator's frames with their image counts, recorded step by step (a stand-in for
    ``Simulator.frames`` with ``Frames.images``)."""
    time, positions, velocities, images = [], [], [], []
    for _ in range(n):
        sim.step(dt)
        time.append(sim.time)
        positions.append(sim.positions)
        velocities.append(sim.velocities)
        images.append(sim.images)
    return SimpleNamespace(
        time=np.array(time), positions=np.array(positions), velocities=np.array(velocities), images=np.array(images)
    )


@pytest.fixture(scope="module")
def run():
    """A bidisperse gas in a rectangular periodic cell, 12 frames, its disks crossing the edges."""
    gas = disk_gas(40, 0.4, arrangement="random", periodic=True, aspect=0.7, diameters=(1.0, 1.4), seed=3)
    masses = np.where(gas.radii > 0.6, 2.0, 1.0)
    sim = Simulator(gas.scene, gas.positions, gas.velocities * 3, masses, gas.radii)
    return sim, _recorded(sim, 0.5, 12)


def test_a_round_trip_is_bit_for_bit_and_the_engine_takes_it_back(tmp_path, run):
    sim, frames = run
    path = tmp_path / "run.gsd"
    write_gsd(path, frames, sim.scene, sim.radii, masses=sim.masses)
    back = read_gsd(path)
    assert back.scene == sim.scene
    for name in ("time", "positions", "velocities", "images"):
        got, want = getattr(back, name), getattr(frames, name)
        assert got.dtype == want.dtype and np.array_equal(got, want), name
    assert np.array_equal(back.radii, sim.radii) and np.array_equal(back.masses, sim.masses)
    assert np.abs(back.images).max() > 0
    again = back.simulator()
    state = sim.get_state()
    for key in ("positions", "velocities", "masses", "radii", "images", "time"):
        assert np.array_equal(again.get_state()[key], state[key]), key
    assert read_gsd(path, frames=3).positions.shape == (1, 40, 2)
    assert np.array_equal(read_gsd(path, frames=slice(2, 5)).time, frames.time[2:5])
    assert np.array_equal(read_gsd(path, frames=-1).time, frames.time[-1:])


def test_gsd_hoomd_and_freud_read_what_we_write(tmp_path, run):
    freud = pytest.importorskip("freud")
    sim, frames = run
    path = tmp_path / "run.gsd"
    write_gsd(path, frames, sim.scene, sim.radii, masses=sim.masses)
    x0, y0, x1, y1 = sim.scene.bounds
    with gsd_hoomd.open(path, "r") as traj:
        assert len(traj) == 12
        frame = traj[5]
        assert frame.configuration.dimensions == 2 and frame.configuration.step == 5
        np.testing.assert_allclose(frame.configuration.box[:3], [x1 - x0, y1 - y0, 0.0], rtol=1e-7)
        assert frame.particles.N == 40 and sorted(frame.particles.types) == ["d1", "d1.4"]
        np.testing.assert_array_equal(frame.particles.diameter, np.float32(2 * sim.radii))
        np.testing.assert_array_equal(frame.particles.mass, np.float32(sim.masses))
        centre = np.array([x0 + x1, y0 + y1]) / 2
        np.testing.assert_allclose(frame.particles.position[:, :2], frames.positions[5] - centre, atol=1e-5)
        assert (frame.particles.position[:, 2] == 0).all()
        np.testing.assert_allclose(frame.particles.velocity[:, :2], frames.velocities[5], rtol=1e-6)
        np.testing.assert_array_equal(frame.particles.image[:, :2], frames.images[5])
        # freud: its box from the file's, and the unwrapped positions from the images
        box = freud.box.Box.from_box(frame.configuration.box, dimensions=frame.configuration.dimensions)
        assert box.is2D and box.Lx == pytest.approx(x1 - x0)
        unwrapped = box.unwrap(frame.particles.position, frame.particles.image)
        np.testing.assert_allclose(
            unwrapped[:, :2] + centre, frames.positions[5] + frames.images[5] * sim.scene.period, atol=1e-4
        )
        rdf = freud.density.RDF(bins=20, r_max=2.0)
        rdf.compute(system=frame)  # (a gsd.hoomd frame is a system freud takes)
        assert rdf.rdf.shape == (20,) and np.isfinite(rdf.rdf).all()


def test_a_long_run_streams_to_disk(tmp_path, run):
    sim, frames = run
    path = tmp_path / "stream.gsd"
    for start in range(0, 12, 4):
        piece = SimpleNamespace(**{k: getattr(frames, k)[start : start + 4] for k in vars(frames)})
        write_gsd(path, piece, sim.scene, sim.radii, masses=sim.masses, append=True)
    back = read_gsd(path)
    assert np.array_equal(back.positions, frames.positions) and np.array_equal(back.time, frames.time)
    with gsd_hoomd.open(path, "r") as traj:
        assert [f.configuration.step for f in traj] == list(range(12))
    # frames of another run are refused, and the file is left as it was
    other = Scene(bounds=sim.scene.bounds, periodic=True, elasticity=0.5)
    with pytest.raises(ValueError, match="scene"):
        write_gsd(path, frames, other, sim.radii, masses=sim.masses, append=True)
    with pytest.raises(ValueError, match="masses"):
        write_gsd(path, frames, sim.scene, sim.radii, append=True)
    assert len(read_gsd(path).time) == 12


def test_a_walled_box_and_unit_masses(tmp_path):
    gas = disk_gas(30, 0.3, aspect=(2, 1), seed=1)
    sim = gas.simulator()
    frames = _recorded(sim, 0.2, 3)
    path = tmp_path / "box.gsd"
    write_gsd(path, frames, gas.scene, gas.radii)
    back = read_gsd(path)
    assert back.scene == gas.scene and not back.scene.periodic
    assert (back.masses == 1.0).all() and (back.images == 0).all()
    assert np.array_equal(back.positions, frames.positions)


def test_bad_input_is_refused_before_the_file_is_touched(tmp_path, run):
    sim, frames = run
    gsd_path, xyz_path = tmp_path / "run.gsd", tmp_path / "run.xyz"
    write_gsd(gsd_path, frames, sim.scene, sim.radii, masses=sim.masses)
    write_xyz(xyz_path, frames, sim.scene, sim.radii)
    before = gsd_path.read_bytes(), xyz_path.read_bytes()

    def changed(**fields):
        return SimpleNamespace(**{**vars(frames), **fields})

    bad = [
        (frames, sim.scene, sim.radii[:5], "shape"),
        (frames, sim.scene, np.full(40, np.nan), "radii"),
        (frames, Scene(bounds=None), sim.radii, "bounds"),
        (changed(images=frames.images * 0.5), sim.scene, sim.radii, "images"),
        (changed(velocities=frames.velocities * np.nan), sim.scene, sim.radii, "velocities"),
        (changed(time=frames.time[:3]), sim.scene, sim.radii, "shape"),
    ]
    for bad_frames, scene, radii, message in bad:
        with pytest.raises(ValueError, match=message):
            write_gsd(gsd_path, bad_frames, scene, radii, append=True)
        with pytest.raises(ValueError, match=message):
            write_xyz(xyz_path, bad_frames, scene, radii, append=True)
    with pytest.raises(ValueError, match="int32"):  # (HOOMD's schema stores images as int32)
        write_gsd(gsd_path, changed(images=frames.images + 2**40), sim.scene, sim.radii, masses=sim.masses)
    assert (gsd_path.read_bytes(), xyz_path.read_bytes()) == before
    for selection in (12, slice(20, 30), 1.5):
        with pytest.raises(ValueError, match="frames"):
            read_gsd(gsd_path, frames=selection)


def _parse_xyz(path):
    """Extended XYZ frames: (comment fields, rows of strings)."""
    lines = path.read_text().splitlines()
    frames = []
    while lines:
        n = int(lines[0])
        frames.append((lines[1], [row.split() for row in lines[2 : 2 + n]]))
        lines = lines[2 + n :]
    return frames


def test_extended_xyz_holds_every_digit(tmp_path, run):
    sim, frames = run
    path = tmp_path / "run.xyz"
    write_xyz(path, SimpleNamespace(**{k: v[:2] for k, v in vars(frames).items()}), sim.scene, sim.radii)
    write_xyz(path, SimpleNamespace(**{k: v[2:3] for k, v in vars(frames).items()}), sim.scene, sim.radii, append=True)
    parsed = _parse_xyz(path)
    assert len(parsed) == 3
    x0, y0, x1, y1 = sim.scene.bounds
    for f, (comment, rows) in enumerate(parsed):
        assert f'Lattice="{x1 - x0!r} 0.0 0.0 0.0 {y1 - y0!r} 0.0 0.0 0.0 0.0"' in comment
        assert 'pbc="T T F"' in comment and f"Time={float(frames.time[f])!r}" in comment
        assert "Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1" in comment
        values = np.array([[float(v) for v in row[1:]] for row in rows])
        assert np.array_equal(values[:, :2], frames.positions[f])  # (17 digits: float64 exactly)
        assert np.array_equal(values[:, 3:5], frames.velocities[f]) and np.array_equal(values[:, 6], sim.radii)
        assert {row[0] for row in rows} == {"d1", "d1.4"}
    assert math.isfinite(float(parsed[0][1][0][1]))


def test_without_gsd_the_error_names_the_extra(monkeypatch, tmp_path, run):
    sim, frames = run
    monkeypatch.setitem(sys.modules, "gsd", None)
    with pytest.raises(MissingExtra, match=r"'analysis' extra \(gsd is missing\)"):
        write_gsd(tmp_path / "x.gsd", frames, sim.scene, sim.radii)
