"""Hard disks with collision_env: a periodic fluid at a given area fraction, its pressure against the
published equation of state, its radial distribution function g(r) and its mean squared displacement.

    python examples/hard_disks.py                      # 1024 disks at area fraction 0.5
    python examples/hard_disks.py --n 4096 --packing 0.65 --plot hard_disks.png

Units are the reduced ones of hard-disk studies: diameter 1, mass 1, kT = 1.
"""

from __future__ import annotations

import argparse

import numpy as np

from collision_env.bench.metrics import henderson_z, kolafa_rottner_z
from collision_env.engine import disk_gas
from collision_env.observables import (
    collision_rate,
    mean_free_time,
    mean_squared_displacement,
    radial_distribution,
    reduced_pressure,
)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=1024, help="disks")
    parser.add_argument("--packing", type=float, default=0.5, help="area fraction, up to 0.70")
    parser.add_argument("--plot", help="save g(r) and the MSD here (a .png)")
    args = parser.parse_args(argv)

    # 1. a gas: a triangular lattice in a periodic cell, Maxwell-Boltzmann velocities at kT = 1
    gas = disk_gas(args.n, args.packing, periodic=True, seed=1)
    sim = gas.simulator()
    print(f"{args.n} disks at area fraction {gas.packing_fraction:.3f} in a {gas.scene.bounds[2]:.2f} cell")

    # 2. melt the lattice: a few hundred collisions per disk
    expected_rate = 4 / np.sqrt(np.pi) * (kolafa_rottner_z(args.packing) - 1)  # Enskog's, per disk
    for _ in range(20):
        sim.step(20.0 / expected_rate)

    # 3. measure: the impacts (with their impulses) of a run, and the positions along it
    frames, dt = 100, 2.0 / expected_rate
    impacts, wrapped, unwrapped = [], [], []
    for _ in range(frames):
        impacts.append(sim.step(dt).array)
        wrapped.append(sim.positions)
        unwrapped.append(sim.unwrapped_positions)
    impacts = np.concatenate(impacts)
    duration = frames * dt
    z = reduced_pressure(impacts, gas.radii, duration, sim.kinetic_energy())
    print(
        f"Z = PA/NkT = {z:.4f}: Kolafa & Rottner (2006) {kolafa_rottner_z(args.packing):.4f}, "
        f"Henderson (1975) {henderson_z(args.packing):.4f}"
    )
    print(
        f"collision rate {collision_rate(impacts, args.n, duration):.3f} per disk, Enskog {expected_rate:.3f}; "
        f"mean free time {mean_free_time(impacts, args.n, duration):.4f}"
    )
    r, g = radial_distribution(np.array(wrapped[::10]), gas.scene.bounds, r_max=4.0, bins=160, periodic=True)
    print(
        f"g(r) peaks at r = {r[np.argmax(g)]:.3f}, at {g.max():.2f} "
        f"(the contact value from Z: {(z - 1) / (2 * args.packing):.2f})"
    )
    lags, msd = mean_squared_displacement(np.array(unwrapped))
    print(
        f"MSD after {lags[-1] * dt:.2f} time units: {msd[-1]:.3f} "
        f"(at one frame {msd[1]:.2e}, ballistic 2 t^2 = {2 * dt**2:.2e})"
    )

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
        left.plot(r, g)
        left.axhline(1.0, color="k", lw=0.8)
        left.set(xlabel="r / sigma", ylabel="g(r)", title=f"Radial distribution, eta = {args.packing}")
        right.loglog(lags[1:] * dt, msd[1:], label="measured")
        right.loglog(lags[1:] * dt, 2 * (lags[1:] * dt) ** 2, "k--", lw=0.8, label="ballistic 2 (kT/m) t^2")
        right.set(xlabel="t", ylabel="MSD", title="Mean squared displacement")
        right.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
