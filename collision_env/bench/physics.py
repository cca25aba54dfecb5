"""The engine as a hard-disk research tool, checked against the literature.

Run it as::

    python -m collision_env.bench.physics                 # N = 4096, jamming at N = 1024 and 4096
    python -m collision_env.bench.physics --quick         # N = 1024, fewer jamming runs
    python -m collision_env.bench.physics --markdown docs/bench/physics.md --plot docs/img
    python -m collision_env.bench.physics --section literature --jobs 2 --markdown docs/bench/physics.md --plot docs/img

**Against Li et al. (2022)** (``--section literature``, :mod:`~collision_env.bench.literature`): small
periodic systems (N = 72, 224, 870) in the literature's cells, by exact-mode MD and by event chains,
against published event-chain pressures; its state points run serially, in local processes, or on Ray.

**Equation of state.** A periodic monodisperse fluid of ``N`` disks (diameter ``sigma = 1``, mass 1,
``kT = 1``), started on a triangular lattice (:func:`~collision_env.engine.disk_gas`) at each area
fraction ``eta``, melted over a number of collisions per disk, then measured in blocks: the
compressibility factor ``Z = P A / (N kT)`` from the collision virial
(:func:`~collision_env.observables.reduced_pressure`) against Kolafa & Rottner's fit (Mol. Phys. 104,
3435 (2006)), with Henderson's (Mol. Phys. 30, 971 (1975)) alongside; and the collision rate per
disk against Enskog's ``omega = 2 sqrt(pi) rho sigma g(sigma+) sqrt(kT / m)``, the contact value
taken from the reference ``Z`` through the contact theorem ``Z = 1 + 2 eta g(sigma+)``, which makes
it exact in equilibrium. The error is the standard error of the block means.

**Jamming.** A 50:50 bidisperse mixture, diameters 1 and 1.4 (O'Hern, Silbert, Liu & Nagel, Phys. Rev.
E 68, 011306 (2003)), placed at random at ``eta = 0.3`` in a periodic cell and compressed by
:func:`~collision_env.engine.compress` (Lubachevsky–Stillinger) until ``Z`` reaches ``10^6``, at several
growth rates and seeds: the jamming density ``phi_J`` against O'Hern et al.'s ``0.842``, and its rate
dependence (slower compressions jam denser: Skoge, Donev, Stillinger & Torquato, Phys. Rev. E 74,
041127 (2006)).

**Speed.** Events (collisions) per second of wall time through the public API (``Simulator.step``
in steps of five mean free times, the impacts returned as arrays) at ``eta = 0.3, 0.5, 0.7``, and
collisions per second of each compression.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np

from collision_env.bench.readme import write_outputs
from collision_env.engine import Simulator, compress, disk_gas
from collision_env.engine.compression import DEFAULT_RATE, DEFAULT_UNTIL_PRESSURE
from collision_env.observables import collision_rate, henderson_z, kolafa_rottner_z, reduced_pressure
from collision_env.precompile import precompile

from . import literature
from .machine import cpus, machine, timestamp, versions

PACKINGS = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.65, 0.68)
SIZE, QUICK_SIZE = 4096, 1024
#: Collisions per disk to melt the lattice, then per block of the measurement, and the blocks.
MELT_COLLISIONS = 2000.0
BLOCK_COLLISIONS = 300.0
BLOCKS = 10
SPEED_PACKINGS = (0.3, 0.5, 0.7)
#: The jamming runs: (N, growth rate, seeds), and the quick subset.
JAMMING_RUNS = (
    (1024, 1e-1, 3),
    (1024, 1e-2, 3),
    (1024, 1e-3, 3),
    (1024, 1e-4, 1),
    (4096, 1e-1, 2),
    (4096, 1e-2, 2),
    (4096, 1e-3, 2),
)
QUICK_JAMMING_RUNS = ((1024, 1e-1, 2), (1024, 1e-2, 2), (1024, 1e-3, 1))
#: The bidisperse mixture (diameters), its starting area fraction, and O'Hern et al.'s phi_J.
JAMMING_DIAMETERS = (1.0, 1.4)
JAMMING_START = 0.3
PHI_J_OHERN = 0.842
#: Collisions per disk a jamming run may spend (the slowest rates need more than compress's default).
JAMMING_EVENTS_PER_DISK = 1_000_000
#: The speed rows' timed stretch, collisions per disk.
SPEED_COLLISIONS = 50.0


def enskog_from_z(z: float) -> float:
    """Enskog's collisions per disk per unit time (``sigma = m = kT = 1``) for a fluid of compressibility
    factor ``z``: ``omega = (4 / sqrt(pi)) (Z - 1)``."""
    return 4.0 / math.sqrt(math.pi) * (z - 1.0)


def run_to_collisions(sim: Simulator, per_disk: float, omega: float) -> tuple[np.ndarray, float]:
    """Step ``sim`` for ``per_disk`` collisions per disk at the expected rate ``omega``, in steps of about
    five mean free times (``5 / omega``). Returns the impacts (one structured array) and the time run."""
    duration = per_disk / omega
    steps = max(1, int(math.ceil(duration * omega / 5.0)))
    dt = duration / steps
    arrays = [sim.step(dt).array for _ in range(steps)]
    return np.concatenate(arrays), duration


def equation_of_state(
    n: int, packings: Sequence[float] = PACKINGS, seed: int = 1, log: Callable[[str], None] = print
) -> list[dict]:
    rows = []
    for eta in packings:
        gas = disk_gas(n, eta, periodic=True, seed=seed)
        sim = gas.simulator()
        z_ref = kolafa_rottner_z(eta)
        omega_ref = enskog_from_z(z_ref)
        run_to_collisions(sim, MELT_COLLISIONS, omega_ref)
        zs, omegas = [], []
        started = time.perf_counter()
        events = 0
        for _ in range(BLOCKS):
            impacts, duration = run_to_collisions(sim, BLOCK_COLLISIONS, omega_ref)
            zs.append(reduced_pressure(impacts, gas.radii, duration, sim.kinetic_energy(), scene=gas.scene))
            omegas.append(collision_rate(impacts, n, duration))
            events += len(impacts)
        wall = time.perf_counter() - started
        z, z_err = float(np.mean(zs)), float(np.std(zs, ddof=1) / math.sqrt(BLOCKS))
        omega, omega_err = float(np.mean(omegas)), float(np.std(omegas, ddof=1) / math.sqrt(BLOCKS))
        row = {
            "packing": eta,
            "z": z,
            "z_err": z_err,
            "z_kolafa_rottner": z_ref,
            "z_henderson": henderson_z(eta),
            "deviation": z / z_ref - 1.0,
            "omega": omega,
            "omega_err": omega_err,
            "omega_enskog": omega_ref,
            "collisions": events,
            "events_per_s": events / wall,
        }
        log(
            f"  eta {eta:.2f}: Z {z:.4f} +- {z_err:.4f} (Kolafa-Rottner {z_ref:.4f}, {100 * row['deviation']:+.2f} %), "
            f"omega / Enskog {omega / omega_ref:.4f}, {events:,} collisions"
        )
        rows.append(row)
    return rows


def speed(
    n: int, packings: Sequence[float] = SPEED_PACKINGS, seed: int = 2, log: Callable[[str], None] = print
) -> list[dict]:
    rows = []
    for eta in packings:
        gas = disk_gas(n, eta, periodic=True, seed=seed)
        sim = gas.simulator()
        omega = enskog_from_z(kolafa_rottner_z(min(eta, 0.70)))
        run_to_collisions(sim, 10.0, omega)  # melt a little, and warm the caches
        started = time.perf_counter()
        impacts, _ = run_to_collisions(sim, SPEED_COLLISIONS, omega)
        wall = time.perf_counter() - started
        rows.append({"packing": eta, "events": len(impacts), "events_per_s": len(impacts) / wall})
        log(f"  eta {eta:.2f}: {len(impacts) / wall:.3g} events/s")
    return rows


def jamming(runs: Sequence[tuple[int, float, int]] = JAMMING_RUNS, log: Callable[[str], None] = print) -> list[dict]:
    """Compress the bidisperse mixture from ``JAMMING_START`` to ``Z = 10^6`` for each ``(N, rate,
    seeds)``; one row per run."""
    rows = []
    for n, rate, seeds in runs:
        for seed in range(seeds):
            gas = disk_gas(
                n, JAMMING_START, arrangement="random", periodic=True, diameters=JAMMING_DIAMETERS, seed=seed
            )
            started = time.perf_counter()
            packing = compress(
                gas.scene,
                gas.positions,
                gas.radii,
                rate=rate,
                until_pressure=DEFAULT_UNTIL_PRESSURE,
                max_events=JAMMING_EVENTS_PER_DISK * n,
                seed=seed,
                progress=False,
            )
            wall = time.perf_counter() - started
            rows.append(
                {
                    "n": n,
                    "rate": rate,
                    "seed": seed,
                    "phi_j": packing.packing_fraction,
                    "z": packing.reduced_pressure,
                    "jammed": packing.jammed,
                    "collisions": packing.events,
                    "seconds": wall,
                    "collisions_per_s": packing.events / wall,
                }
            )
            log(
                f"  N {n}, rate {rate:g}, seed {seed}: phi_J {packing.packing_fraction:.4f} at "
                f"Z {packing.reduced_pressure:.3g}, {packing.events:,} collisions in {wall:.0f} s "
                f"({packing.events / wall:.3g}/s)"
            )
    return rows


def jamming_summary(rows: Sequence[dict]) -> list[dict]:
    """Per ``(N, rate)``: the mean ``phi_J``, its spread over seeds (sample standard deviation, 0 for
    one seed), the mean seconds and collisions per second."""
    out = []
    for key in dict.fromkeys((r["n"], r["rate"]) for r in rows):
        group = [r for r in rows if (r["n"], r["rate"]) == key]
        phi = np.array([r["phi_j"] for r in group])
        out.append(
            {
                "n": key[0],
                "rate": key[1],
                "seeds": len(group),
                "phi_j": float(phi.mean()),
                "phi_j_sd": float(phi.std(ddof=1)) if len(group) > 1 else 0.0,
                "seconds": float(np.mean([r["seconds"] for r in group])),
                "collisions_per_disk": float(np.mean([r["collisions"] for r in group])) / key[0],
                "collisions_per_s": float(np.mean([r["collisions_per_s"] for r in group])),
                "all_jammed": all(r["jammed"] for r in group),
            }
        )
    return out


def run(quick: bool, log: Callable[[str], None] = print) -> dict:
    n = QUICK_SIZE if quick else SIZE
    started = time.perf_counter()
    precompile(envs=False)
    log(f"equation of state, N = {n}:")
    eos = equation_of_state(n, log=log)
    log(f"speed, N = {n}:")
    fast = speed(n, log=log)
    log("jamming:")
    jams = jamming(QUICK_JAMMING_RUNS if quick else JAMMING_RUNS, log=log)
    return {
        "machine": machine(),
        "cpus": cpus(),
        "versions": versions(["numpy", "numba"]),
        "timestamp": timestamp(),
        "seconds": time.perf_counter() - started,
        "n": n,
        "equation_of_state": eos,
        "speed": fast,
        "jamming": jams,
    }


def render_markdown(results: dict) -> str:
    v = results["versions"]
    lines = [
        f"`python -m collision_env.bench.physics` on {results['machine']}, {results['cpus']} CPUs, numpy "
        f"{v.get('numpy')}, numba {v.get('numba')}; {results['timestamp']}, {results['seconds']:.0f} s. "
        f"A periodic fluid of {results['n']:,} equal disks (sigma = m = kT = 1) melted from a triangular "
        f"lattice over {MELT_COLLISIONS:g} collisions per disk, then {BLOCKS} blocks of {BLOCK_COLLISIONS:g}: "
        "Z from the collision virial (± the standard error of the block means) against Kolafa & Rottner "
        "(2006), Henderson (1975) alongside; the collision rate against Enskog's with the reference contact value.",
        "",
        "| η | Z (this engine) | Z (Kolafa–Rottner) | deviation | Z (Henderson) | ω / ω_Enskog | collisions |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results["equation_of_state"]:
        lines.append(
            f"| {r['packing']:.2f} | {r['z']:.4f} ± {r['z_err']:.4f} | {r['z_kolafa_rottner']:.4f} | "
            f"{100 * r['deviation']:+.2f} % | {r['z_henderson']:.4f} | "
            f"{r['omega'] / r['omega_enskog']:.4f} ± {r['omega_err'] / r['omega_enskog']:.4f} | {r['collisions']:,} |"
        )
    lines += ["", "| η | events/s (public API) |", "|---:|---:|"]
    for r in results["speed"]:
        lines.append(f"| {r['packing']:.2f} | {r['events_per_s']:.3g} |")
    lines += [
        "",
        f"Jamming: a 50:50 mixture of diameters {JAMMING_DIAMETERS[0]:g} and {JAMMING_DIAMETERS[1]:g} placed at random "
        f"at φ = {JAMMING_START:g} in a periodic cell, compressed by `compress` (Lubachevsky–Stillinger; the default "
        f"rate is {DEFAULT_RATE:g}) until Z = {DEFAULT_UNTIL_PRESSURE:.0e}; φ_J is the mean over seeds (± their "
        f"standard deviation), against O'Hern et al. (2003), {PHI_J_OHERN}.",
        "",
        "| N | rate | seeds | φ_J | collisions per disk | seconds per run | collisions/s |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in jamming_summary(results["jamming"]):
        spread = f" ± {r['phi_j_sd']:.4f}" if r["seeds"] > 1 else ""
        flag = "" if r["all_jammed"] else " (not all reached Z)"
        lines.append(
            f"| {r['n']:,} | {r['rate']:g} | {r['seeds']} | {r['phi_j']:.4f}{spread}{flag} | "
            f"{r['collisions_per_disk']:,.0f} | {r['seconds']:.1f} | {r['collisions_per_s']:.3g} |"
        )
    return "\n".join(lines)


def plot(results: dict, folder: str) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    eos = results["equation_of_state"]
    eta = np.array([r["packing"] for r in eos])
    fine = np.linspace(0.0, 0.70, 200)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot(fine, [kolafa_rottner_z(x) for x in fine], "k-", label="Kolafa & Rottner (2006)")
    left.plot(fine, [henderson_z(x) for x in fine], "k--", lw=0.8, label="Henderson (1975)")
    left.errorbar(eta, [r["z"] for r in eos], [r["z_err"] for r in eos], fmt="o", color="C0", label="this engine")
    left.set(xlabel="area fraction η", ylabel="Z = PA / NkT", title=f"Equation of state, N = {results['n']:,}")
    left.legend()
    right.axhline(1.0, color="k", lw=0.8)
    right.errorbar(
        eta,
        [r["omega"] / r["omega_enskog"] for r in eos],
        [r["omega_err"] / r["omega_enskog"] for r in eos],
        fmt="o",
        color="C1",
    )
    right.set(xlabel="area fraction η", ylabel="ω / ω_Enskog", title="Collision rate against Enskog")
    fig.tight_layout()
    path = f"{folder}/physics_eos.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_jamming(results: dict, folder: str) -> str:
    """φ_J against the growth rate, each run a point, per N, with O'Hern et al.'s value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.axhline(PHI_J_OHERN, color="k", lw=0.8, ls="--", label=f"O'Hern et al. (2003), {PHI_J_OHERN}")
    for k, n in enumerate(sorted({r["n"] for r in results["jamming"]})):
        rows = [r for r in results["jamming"] if r["n"] == n]
        shift = 1.0 + 0.08 * k  # (side by side)
        ax.plot(
            [r["rate"] * shift for r in rows],
            [r["phi_j"] for r in rows],
            "o",
            color=f"C{k}",
            alpha=0.7,
            label=f"N = {n:,}",
        )
    ax.set(
        xscale="log",
        xlabel="growth rate (diameters per thermal time)",
        ylabel="φ_J at Z = 10⁶",
        title="Jamming of a 50:50 bidisperse mixture",
    )
    ax.legend()
    fig.tight_layout()
    path = f"{folder}/physics_jamming.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.physics", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--section",
        choices=("fluid", "literature"),
        default="fluid",
        help="fluid: the equation of state, speed and jamming (the default); literature: against Li et al. (2022)",
    )
    parser.add_argument(
        "--quick", action="store_true", help=f"N = {QUICK_SIZE} rather than {SIZE} (literature: a few short points)"
    )
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument(
        "--markdown", help="write the tables into this page's bench:physics (or bench:literature) block"
    )
    parser.add_argument(
        "--plot", help="write physics_eos.png and physics_jamming.png (literature: physics_li2022.png) into this folder"
    )
    literature.add_arguments(parser)
    args = parser.parse_args(argv)
    if args.section == "literature":
        return literature.main(args)
    results = run(args.quick)
    text = render_markdown(results)
    # (its block of the page: the literature section writes another)
    page = {"markdown": args.markdown, "block": "bench:physics", "title": literature.PAGE_TITLE}
    write_outputs(text, results, json_path=args.json, **page)
    if args.plot:
        print(plot(results, args.plot))
        print(plot_jamming(results, args.plot))
    return 0


if __name__ == "__main__":
    sys.exit(main())
