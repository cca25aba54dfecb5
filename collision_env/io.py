"""Trajectories out and in: GSD files (HOOMD-blue's schema) and extended XYZ.

- :func:`write_gsd` writes a run's frames to a GSD file through the ``gsd`` package (the
  ``analysis`` extra), in the ``hoomd`` schema that HOOMD-blue, freud, OVITO and MDAnalysis read: a
  2D box (``Lz = 0``, ``dimensions = 2``) centred on the origin as the schema wants it, and per
  frame the positions, velocities, image counts, diameters, masses and type ids (one type per
  diameter). The schema holds single precision, so each frame also logs the engine's own float64
  positions and velocities, int64 images and clock, and the first frame the scene, radii and masses
  (``log/collision_env/...`` chunks, which other readers skip): :func:`read_gsd` gives back what was
  written, bit for bit, and a state that ``Simulator.set_state`` takes. With ``append=True`` each
  call adds its frames to the file, so a long run streams to disk one ``frames`` call at a time and
  never holds every frame in memory.
- :func:`write_xyz` writes extended XYZ (the format of ASE and OVITO): per frame a count line, a
  comment line with the cell (``Lattice``), its origin, the periodic axes, the time and the columns
  (``Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1``), then a line per disk, every number to
  17 significant digits.

Frames are a ``Simulator``'s :class:`~collision_env.engine.Frames`: ``time (F,)``, ``positions`` and
``velocities (F, N, 2)`` and ``images (F, N, 2)``, the image counts as
:attr:`Simulator.images <collision_env.engine.Simulator.images>` gives them.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine.scene import Scene
from collision_env.engine.simulator import Simulator
from collision_env.engine.snapshot import SimulatorState
from collision_env.extras import require
from collision_env.observables import _checks

__all__ = ["Trajectory", "read_gsd", "write_gsd", "write_xyz"]

#: The prefix of the log chunks that hold what the schema cannot (float64, int64, the scene).
LOG = "collision_env/"
_INT32 = np.iinfo(np.int32)


class Trajectory(NamedTuple):
    """A GSD file's frames as :func:`read_gsd` gives them back."""

    scene: Scene  #: the box or periodic cell
    radii: np.ndarray  #: (N,) radii
    masses: np.ndarray  #: (N,) masses
    time: np.ndarray  #: (F,) each frame's clock
    positions: np.ndarray  #: (F, N, 2) centres, in the scene's coordinates (wrapped into a periodic cell)
    velocities: np.ndarray  #: (F, N, 2) velocities
    images: np.ndarray  #: (F, N, 2) int64 periodic cell lengths crossed

    def state(self, frame: int = -1) -> SimulatorState:
        """Frame ``frame`` as a state :meth:`Simulator.set_state <collision_env.engine.Simulator.set_state>`
        takes (every disk its own cluster, no spin, the clock without compensation)."""
        n = len(self.radii)
        return SimulatorState(
            positions=self.positions[frame].copy(),
            velocities=self.velocities[frame].copy(),
            masses=self.masses.copy(),
            radii=self.radii.copy(),
            clusters=np.arange(n),
            omega=np.zeros(n),
            time=np.array(self.time[frame]),
            time_compensation=np.array(0.0),
            images=self.images[frame].copy(),
        )

    def simulator(self, frame: int = -1, **options: Any) -> Simulator:
        """A :class:`~collision_env.engine.Simulator` in frame ``frame``'s state (``options``: mode, ...)."""
        sim = Simulator(self.scene, self.positions[frame], self.velocities[frame], self.masses, self.radii, **options)
        sim.set_state(self.state(frame))
        return sim


def _gsd(who: str) -> Any:
    require("analysis", who, modules=("gsd",))
    import gsd.hoomd

    return gsd.hoomd


class _Run(NamedTuple):
    """Checked frames, ready to write."""

    scene: Scene
    radii: np.ndarray
    masses: np.ndarray
    time: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    images: np.ndarray


def _checked(frames, scene, radii, masses) -> _Run:
    """The frames of a ``Simulator`` and what goes with them, checked (a ``ValueError`` naming the field)."""
    s = _checks.bounded_scene(scene)
    r = _checks.radii(radii)
    n = len(r)
    m = np.ones(n) if masses is None else _checks.masses(masses, n)
    time = np.asarray(frames.time, dtype=np.float64)
    if time.ndim != 1:
        raise ValueError(f"frames: expected a Simulator's frames (time of shape (F,)), got time of shape {time.shape}")
    shape = (len(time), n, 2)
    arrays = []
    for field in ("positions", "velocities"):
        a = np.asarray(getattr(frames, field), dtype=np.float64)
        if a.shape != shape:
            raise ValueError(f"frames: expected {field} of shape {shape}, got {a.shape}")
        if not np.isfinite(a).all():
            raise ValueError(f"frames: {field} must be finite")
        arrays.append(a)
    images = np.asarray(frames.images)
    if images.shape != shape or images.dtype.kind not in "iu":
        raise ValueError(f"frames: expected integer images of shape {shape}, got {images.dtype} {images.shape}")
    if not np.isfinite(time).all():
        raise ValueError("frames: times must be finite")
    return _Run(s, r, m, time, arrays[0], arrays[1], images.astype(np.int64))


def _scene_record(scene: Scene) -> np.ndarray:
    """The scene as JSON bytes (``uint8``), for a log chunk."""
    return np.frombuffer(json.dumps(asdict(scene)).encode(), dtype=np.uint8)


def _scene_from(record: np.ndarray) -> Scene:
    fields = json.loads(bytes(np.asarray(record, dtype=np.uint8)).decode())
    fields["bounds"] = tuple(fields["bounds"])
    return Scene(**fields)


def _types(radii: np.ndarray) -> tuple[list[str], np.ndarray]:
    """One type per diameter, named by it (``"d1"``, ``"d1.4"``), and each disk's type id."""
    diameters, typeid = np.unique(2.0 * radii, return_inverse=True)
    return [f"d{d:.6g}" for d in diameters], typeid.astype(np.uint32)


def _same_run(path, reader, run: _Run) -> None:
    """Refuse to append frames of another run (scene, radii or masses) to ``path``."""
    if len(reader) == 0:
        return
    first = reader[0]
    found = {key: first.log.get(LOG + key) for key in ("scene", "radii", "masses")}
    if any(v is None for v in found.values()):
        raise ValueError(f"path: {os.fspath(path)} was not written by write_gsd (no {LOG} chunks): cannot append")
    if _scene_from(found["scene"]) != run.scene:
        raise ValueError(f"scene: {os.fspath(path)} holds frames of another scene, {_scene_from(found['scene'])}")
    for key, mine in (("radii", run.radii), ("masses", run.masses)):
        if not np.array_equal(found[key], mine):
            raise ValueError(f"{key}: {os.fspath(path)} holds frames of disks with other {key}")


def write_gsd(
    path: str | os.PathLike,
    frames: Any,
    scene: Scene,
    radii: ArrayLike,
    *,
    masses: ArrayLike | None = None,
    append: bool = False,
) -> None:
    """Write a ``Simulator``'s ``frames`` to the GSD file ``path`` (see the module): HOOMD's schema,
    readable by freud, OVITO, MDAnalysis and HOOMD-blue, with the engine's own state in log chunks.

    ``scene``: the simulator's box or periodic cell; ``radii``, ``masses``: its ``(N,)`` radii and
    masses (``None``: unit masses). ``append``: add the frames to the file's (which must hold the
    same scene, radii and masses), to stream a long run to disk call by call; otherwise the file is
    written anew. Frame steps (``configuration.step``) count the file's frames. Bad input raises a
    ``ValueError`` before the file is touched. Needs ``gsd`` (the ``analysis`` extra).
    """
    hoomd = _gsd("io.write_gsd")
    run = _checked(frames, scene, radii, masses)
    if (run.images < _INT32.min).any() or (run.images > _INT32.max).any():
        raise ValueError("frames: images beyond int32, which HOOMD's schema stores, are not written")
    if not isinstance(append, (bool, np.bool_)):
        raise ValueError(f"append: expected True or False, got {append!r}")
    mode = "a" if append and os.path.exists(path) else "w"
    if mode == "a":
        with hoomd.open(path, "r") as reader:
            _same_run(path, reader, run)
            first_step = len(reader)
    else:
        first_step = 0
    assert run.scene.bounds is not None
    xmin, ymin, xmax, ymax = run.scene.bounds
    size = np.array([xmax - xmin, ymax - ymin])
    centre = np.array([xmin, ymin]) + 0.5 * size
    types, typeid = _types(run.radii)
    n = len(run.radii)
    with hoomd.open(path, mode) as out:
        for f in range(len(run.time)):
            frame = hoomd.Frame()
            frame.configuration.step = first_step + f
            frame.configuration.dimensions = 2
            frame.configuration.box = [size[0], size[1], 0.0, 0.0, 0.0, 0.0]
            frame.particles.N = n
            frame.particles.types = types
            frame.particles.typeid = typeid
            frame.particles.diameter = 2.0 * run.radii
            frame.particles.mass = run.masses
            frame.particles.position = np.column_stack([run.positions[f] - centre, np.zeros(n)])
            frame.particles.velocity = np.column_stack([run.velocities[f], np.zeros(n)])
            frame.particles.image = np.column_stack([run.images[f], np.zeros(n, dtype=np.int64)])
            if first_step + f == 0:
                frame.log[LOG + "scene"] = _scene_record(run.scene)
                frame.log[LOG + "radii"] = run.radii
                frame.log[LOG + "masses"] = run.masses
            frame.log[LOG + "time"] = run.time[f : f + 1]
            frame.log[LOG + "position"] = run.positions[f]
            frame.log[LOG + "velocity"] = run.velocities[f]
            frame.log[LOG + "image"] = run.images[f]
            out.append(frame)


def read_gsd(path: str | os.PathLike, frames: int | slice | None = None) -> Trajectory:
    """The frames of a GSD file as a :class:`Trajectory` (all of them, or those ``frames`` selects:
    an index or a slice). A file :func:`write_gsd` wrote comes back bit for bit, with its scene;
    another writer's file (HOOMD's schema, 2D) is read from its single-precision fields, as a
    periodic cell of its box centred on the origin, each frame's time its step. Needs
    ``gsd`` (the ``analysis`` extra)."""
    hoomd = _gsd("io.read_gsd")
    with hoomd.open(path, "r") as reader:
        count = len(reader)
        if frames is None:
            chosen = range(count)
        elif isinstance(frames, slice):
            chosen = range(count)[frames]
        elif isinstance(frames, (int, np.integer)) and not isinstance(frames, (bool, np.bool_)):
            if not -count <= frames < count:
                raise ValueError(f"frames: index {frames} outside the file's {count} frames")
            index = range(count)[frames]
            chosen = range(index, index + 1)
        else:
            raise ValueError(f"frames: expected None, an index or a slice, got {frames!r}")
        if len(chosen) == 0:
            raise ValueError(f"frames: {frames!r} selects none of the file's {count} frames")
        first = reader[0]
        if first.configuration.dimensions != 2:
            raise ValueError(f"path: {os.fspath(path)} holds a {first.configuration.dimensions}D system, not disks")
        ours = first.log.get(LOG + "scene") is not None
        if ours:
            scene = _scene_from(first.log[LOG + "scene"])
            radii = np.array(first.log[LOG + "radii"], dtype=np.float64)
            masses = np.array(first.log[LOG + "masses"], dtype=np.float64)
        else:
            lx, ly = (float(v) for v in first.configuration.box[:2])
            scene = Scene(bounds=(-lx / 2, -ly / 2, lx / 2, ly / 2), periodic=True)
            radii = 0.5 * np.asarray(first.particles.diameter, dtype=np.float64)
            masses = np.asarray(first.particles.mass, dtype=np.float64)
        time, positions, velocities, images = [], [], [], []
        for f in chosen:
            frame = reader[f]
            if ours:
                time.append(float(frame.log[LOG + "time"][0]))
                positions.append(np.asarray(frame.log[LOG + "position"], dtype=np.float64))
                velocities.append(np.asarray(frame.log[LOG + "velocity"], dtype=np.float64))
                images.append(np.asarray(frame.log[LOG + "image"], dtype=np.int64))
            else:
                time.append(float(frame.configuration.step))
                positions.append(np.asarray(frame.particles.position[:, :2], dtype=np.float64))
                velocities.append(np.asarray(frame.particles.velocity[:, :2], dtype=np.float64))
                images.append(np.asarray(frame.particles.image[:, :2], dtype=np.int64))
    return Trajectory(scene, radii, masses, np.array(time), np.array(positions), np.array(velocities), np.array(images))


def write_xyz(path: str | os.PathLike, frames: Any, scene: Scene, radii: ArrayLike, *, append: bool = False) -> None:
    """Write a ``Simulator``'s ``frames`` to the extended XYZ file ``path`` (see the module), in the
    scene's own coordinates: ``Lattice`` holds the cell's sides (``Lz = 0``), ``Origin`` its
    corner, ``pbc`` its periodic axes, ``Time`` the frame's clock; each disk's line its species
    (one per diameter, as in :func:`write_gsd`), position (z = 0), velocity and radius.
    ``append``: add the frames to the file. Bad input raises a ``ValueError`` before the file is
    touched."""
    run = _checked(frames, scene, radii, None)
    if not isinstance(append, (bool, np.bool_)):
        raise ValueError(f"append: expected True or False, got {append!r}")
    assert run.scene.bounds is not None
    xmin, ymin, xmax, ymax = run.scene.bounds
    pbc = "T T F" if run.scene.periodic else "F F F"
    types, typeid = _types(run.radii)
    species = np.array(types)[typeid]
    n = len(run.radii)
    with open(path, "a" if append else "w", encoding="utf-8") as out:
        for f in range(len(run.time)):
            out.write(f"{n}\n")
            out.write(
                f'Lattice="{xmax - xmin!r} 0.0 0.0 0.0 {ymax - ymin!r} 0.0 0.0 0.0 0.0" '
                f'Origin="{xmin!r} {ymin!r} 0.0" pbc="{pbc}" Time={float(run.time[f])!r} '
                "Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1\n"
            )
            rows = zip(
                species.tolist(), run.positions[f].tolist(), run.velocities[f].tolist(), run.radii.tolist(), strict=True
            )
            out.writelines(f"{s} {p[0]!r} {p[1]!r} 0.0 {v[0]!r} {v[1]!r} 0.0 {r!r}\n" for s, p, v, r in rows)
