"""A short tour of the engine: ``python examples/engine_tour.py``.

Runs PhET's Intro head-on collision, Galperin's pi billiard, a small gas in each fidelity mode
and a hard-disk gas sampled in frames, and prints what the engine reports (impact times, points,
counts, energy drift, cost, the gas's pressure on the walls).
"""

from __future__ import annotations

import time

import numpy as np

from collision_env.engine import BACKEND, PLAY_AREA_1D, Scene, Simulator
from collision_env.observables import reduced_pressure, wall_pressure


def head_on():
    sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5])
    (hit,) = sim.step(2.0)
    print(
        f"PhET Intro head-on: contact at t = {hit.time:.6f} s at x = {hit.point[0]:.6f} m; "
        f"velocities after: {sim.velocities[:, 0].round(6).tolist()} m/s"
    )


def pi_billiard(digits=5):
    scene = Scene(bounds=(0.0, -1.0, 1e9, 1.0), dimension=1)
    sim = Simulator(
        scene,
        [[1.0, 0.0], [2.0, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        [1.0, 100.0 ** (digits - 1)],
        radii=[0.1, 0.1],
        max_events=10**7,
    )
    start = time.perf_counter()
    count = sum(len(sim.step(100.0)) for _ in range(20))
    seconds = time.perf_counter() - start
    energy_error = sim.kinetic_energy() / (0.5 * 100.0 ** (digits - 1)) - 1
    print(
        f"Galperin's pi billiard, mass ratio 100^{digits - 1}: {count} collisions "
        f"({count / seconds:,.0f} events/s), energy error {energy_error:+.1e}"
    )


def modes():
    rng = np.random.default_rng(0)
    n = 16
    cells = rng.choice(32, n, replace=False)
    pos = np.column_stack([-2 + (cells % 8 + 0.5) * 0.5, -1 + (cells // 8 + 0.5) * 0.5])
    vel = rng.normal(size=(n, 2))
    masses = rng.uniform(0.1, 3.0, n)
    radii = np.full(n, 0.1)
    reference = None
    print(f"\n16-ball gas, 5 s at dt = 1/60 s (kernels: {BACKEND})")
    print(f"{'mode':<16}{'impacts':>9}{'energy drift':>14}{'us/step':>10}{'max |dx| vs exact':>20}")
    for mode, substeps in [("exact", 1), ("posteriori", 1), ("posteriori", 8), ("naive", 1), ("naive", 8)]:
        sim = Simulator(Scene(), pos, vel, masses, radii=radii, mode=mode, substeps=substeps)
        sim.copy().step(1 / 60)  # load the compiled kernels before timing
        e0 = sim.kinetic_energy()
        start = time.perf_counter()
        count = sum(len(sim.step(1 / 60)) for _ in range(300))
        us = (time.perf_counter() - start) / 300 * 1e6
        if reference is None:
            reference = sim.positions
        err = np.abs(sim.positions - reference).max()
        label = mode if mode == "exact" else f"{mode} x{substeps}"
        print(f"{label:<16}{count:>9}{sim.kinetic_energy() / e0 - 1:>+14.1e}{us:>10.1f}{err:>20.3g}")
    print("(the gas is chaotic: after many collisions per ball, cheap-mode errors saturate at the box size)")


def explore_1d():
    xs, vs, ms = [-1.8, -0.1, 0.8, 1.3, 1.8], [1, -0.5, -0.5, 1.1, -1.1], [0.5, 1.5, 1.0, 1.0, 1.0]
    sim = Simulator(Scene(bounds=PLAY_AREA_1D, dimension=1), [[x, 0] for x in xs], [[v, 0] for v in vs], ms)
    hits = [h for _ in range(60) for h in sim.step(1 / 60)]
    print("\nPhET Explore 1D, first second:")
    for h in hits:
        what = f"ball {h.other}" if h.other is not None else f"{h.wall} wall"
        print(f"  t = {h.time:.6f} s  ball {h.ball} hits {what} at x = {h.point[0]:+.6f} m")


def gas_pressure(n=400, radius=0.01, packing=0.3, seed=0):
    """A hard-disk gas sampled in frames: its pressure from the collision virial and on the walls
    (the impulses of the wall impacts over the length the centres reach and the time, times the
    area they reach, over the kinetic energy), see ``collision_env.observables``, against
    Henderson's equation of state, P A / (N kT) = (1 + eta^2 / 8) / (1 - eta)^2 (Henderson 1975,
    Mol. Phys. 30:971). The walls of a box of a few hundred disks shift it by a few per cent; the
    difference shrinks as the perimeter over the area, as 1 / sqrt(N) (try ``gas_pressure(n=10_000)``)."""
    side = np.sqrt(n * np.pi * radius**2 / packing)
    per_row = int(np.ceil(np.sqrt(n)))
    grid = (np.arange(per_row) + 0.5) * side / per_row - side / 2
    pos = np.stack(np.meshgrid(grid, grid), -1).reshape(-1, 2)[:n]
    vel = np.random.default_rng(seed).normal(size=(n, 2)) / np.sqrt(2.0)
    box = Scene(bounds=(-side / 2, -side / 2, side / 2, side / 2))
    sim = Simulator(box, pos, vel, np.ones(n), radii=np.full(n, radius))
    sim.frames(1 / 60, 120)  # two seconds for the lattice to melt
    start = time.perf_counter()
    rec = sim.frames(1 / 60, 600)  # ten seconds, sampled at 60 Hz
    seconds = time.perf_counter() - start
    duration, energy = 600 / 60, sim.kinetic_energy()
    z_virial = reduced_pressure(rec.impacts, sim.radii, duration, energy, scene=box)
    z_walls = wall_pressure(rec.impacts, duration, box.bounds, radius) * (side - 2 * radius) ** 2 / energy
    henderson = (1 + packing**2 / 8) / (1 - packing) ** 2
    print(
        f"\n{n}-disk gas at area fraction {packing}, 600 frames of 1/60 s in one call ({len(rec.impacts)} "
        f"impacts, {seconds * 1e3:.0f} ms): P A / (N kT) = {z_virial:.3f} from the collision virial, "
        f"{z_walls:.3f} from the walls, {henderson:.3f} by Henderson's equation of state"
    )


def main():
    head_on()
    pi_billiard()
    explore_1d()
    modes()
    gas_pressure()


if __name__ == "__main__":
    main()
