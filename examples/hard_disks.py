"""Hard disks with collision_env: a periodic fluid at a given area fraction in a cell of a given shape,
its pressure with an error bar against the published equation of state, its radial distribution
function g(r), mean squared displacement and hexatic order, its trajectory saved for freud or OVITO;
then a bidisperse mixture compressed to jamming.

    python examples/hard_disks.py                      # 1024 disks at area fraction 0.5
    python examples/hard_disks.py --n 4096 --packing 0.65 --aspect 0.866 --gsd run.gsd --plot hard_disks.png

Units are the reduced ones of hard-disk studies: diameter 1, mass 1, kT = 1. The hexatic order and the
GSD file need the ``analysis`` extra (freud, gsd).
"""

from __future__ import annotations

import argparse
import importlib.util

import numpy as np

from collision_env.engine import compress, disk_gas
from collision_env.engine.compression import DEFAULT_RATE
from collision_env.observables import (
    PressureAccumulator,
    henderson_z,
    kolafa_rottner_z,
    mean_squared_displacement,
    radial_distribution,
    unwrapped_positions,
)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=1024, help="disks")
    parser.add_argument("--packing", type=float, default=0.5, help="area fraction, up to 0.70")
    parser.add_argument("--aspect", type=float, default=None, help="the cell's height over its width")
    parser.add_argument("--blocks", type=int, default=10, help="frames calls of the measurement")
    parser.add_argument("--jam-n", type=int, default=1024, help="disks of the packing compressed to jamming")
    parser.add_argument("--rate", type=float, default=DEFAULT_RATE, help="the compression's growth rate")
    parser.add_argument("--gsd", help="save the measured trajectory here (a .gsd file, for freud, OVITO, ...)")
    parser.add_argument("--plot", help="save g(r), the MSD and the jammed packing here (a .png)")
    args = parser.parse_args(argv)
    analysis = all(importlib.util.find_spec(m) is not None for m in ("freud", "gsd"))

    # 1. a gas: a triangular lattice in a periodic cell, Maxwell-Boltzmann velocities at kT = 1
    gas = disk_gas(args.n, args.packing, periodic=True, aspect=args.aspect, seed=1)
    sim = gas.simulator()
    width, height = gas.scene.period
    print(f"{args.n} disks at area fraction {gas.packing_fraction:.3f} in a {width:.2f} x {height:.2f} cell")

    # 2. melt the lattice: a few hundred collisions per disk
    expected_rate = 4 / np.sqrt(np.pi) * (kolafa_rottner_z(args.packing) - 1)  # Enskog's, per disk
    dt = 2.0 / expected_rate  # frames two mean free times apart
    sim.frames(dt, 200)

    # 3. measure, frames call after frames call: the pressure and collision rate (with their errors),
    # every frame's positions and image counts for g(r) and the MSD, the trajectory on disk
    pressure = PressureAccumulator(gas.scene, gas.radii, gas.masses, time=sim.time)
    wrapped, unwrapped = [], []
    for block in range(args.blocks):
        rec = sim.frames(dt, 20)
        pressure.add(rec)
        wrapped.append(rec.positions[::10])
        unwrapped.append(unwrapped_positions(rec, gas.scene))
        if args.gsd and analysis:
            from collision_env.io import write_gsd

            write_gsd(args.gsd, rec, gas.scene, gas.radii, masses=gas.masses, append=block > 0)
    z, omega = pressure.pressure(), pressure.collision_rate()
    print(
        f"Z = PA/NkT = {z.mean:.4f} ± {z.error:.4f}: Kolafa & Rottner (2006) {kolafa_rottner_z(args.packing):.4f}, "
        f"Henderson (1975) {henderson_z(args.packing):.4f}"
    )
    print(f"collision rate {omega.mean:.3f} ± {omega.error:.3f} per disk, Enskog {expected_rate:.3f}")
    r, g = radial_distribution(np.concatenate(wrapped), gas.scene.bounds, r_max=4.0, bins=160, periodic=True)
    print(
        f"g(r) peaks at r = {r[np.argmax(g)]:.3f}, at {g.max():.2f} "
        f"(the contact value from Z: {(z.mean - 1) / (2 * args.packing):.2f})"
    )
    lags, msd = mean_squared_displacement(np.concatenate(unwrapped))
    print(
        f"MSD after {lags[-1] * dt:.2f} time units: {msd[-1]:.3f} "
        f"(at one frame {msd[1]:.2e}, ballistic 2 t^2 = {2 * dt**2:.2e})"
    )
    if analysis:
        from collision_env.observables import global_hexatic_order

        psi = abs(global_hexatic_order(sim.positions, gas.scene))
        print(f"hexatic order |Psi6| = {psi:.3f} (an uncorrelated fluid: about 1/sqrt(N) = {args.n**-0.5:.3f})")
        if args.gsd:
            print(f"trajectory: {args.gsd} ({pressure.frames} frames)")

    # 4. jamming: a 50:50 mixture of diameters 1 and 1.4 (O'Hern et al. 2003), placed at random at
    # area fraction 0.3, its disks grown (Lubachevsky-Stillinger) until the pressure diverges
    mixture = disk_gas(args.jam_n, 0.3, arrangement="random", periodic=True, diameters=(1.0, 1.4), seed=2)
    packing = compress(mixture.scene, mixture.positions, mixture.radii, rate=args.rate, seed=3)
    print(
        f"jammed at area fraction {packing.packing_fraction:.4f} (O'Hern et al.: 0.842) after "
        f"{packing.events:,} collisions, Z = {packing.reduced_pressure:.3g}"
    )

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.collections import EllipseCollection

        fig, (left, right, packed) = plt.subplots(1, 3, figsize=(15, 4))
        left.plot(r, g)
        left.axhline(1.0, color="k", lw=0.8)
        left.set(xlabel="r / sigma", ylabel="g(r)", title=f"Radial distribution, eta = {args.packing}")
        right.loglog(lags[1:] * dt, msd[1:], label="measured")
        right.loglog(lags[1:] * dt, 2 * (lags[1:] * dt) ** 2, "k--", lw=0.8, label="ballistic 2 (kT/m) t^2")
        right.set(xlabel="t", ylabel="MSD", title="Mean squared displacement")
        right.legend()
        size = 2 * packing.radii
        packed.add_collection(
            EllipseCollection(
                size,
                size,
                0.0,
                units="xy",
                offsets=packing.positions,
                offset_transform=packed.transData,
                array=packing.radii,
                cmap="coolwarm",
            )
        )
        x0, y0, x1, y1 = packing.scene.bounds
        packed.set(xlim=(x0, x1), ylim=(y0, y1), aspect="equal", title=f"Jammed, phi = {packing.packing_fraction:.3f}")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
