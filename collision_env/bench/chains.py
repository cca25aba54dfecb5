"""Event-chain Monte Carlo against exact-mode molecular dynamics, on one dense state point.

Run it as::

    python -m collision_env.bench.chains                  # long runs, and the chain-length scan
    python -m collision_env.bench.chains --quick          # a tenth of the runs, no scan
    python -m collision_env.bench.chains --markdown docs/bench/chains.md --json docs/bench/chains.json

**The state point.** ``N = 224`` equal disks (diameter 1) at area fraction ``phi = 0.68`` in a periodic
cell of sides ``1 : sqrt(3) / 2`` (one of the cells of Li et al., *J. Chem. Phys.* 157, 234111 (2022)),
started on a 16 x 14 grid and melted by :func:`~collision_env.engine.event_chain`.

**Event chains.** :func:`~collision_env.engine.event_chain` from the melted state: ``Z = beta P A / N``
with its standard error by blocking.

**Molecular dynamics.** The same melted state with Maxwell–Boltzmann velocities (``kT = 1``, the centre
of mass at rest) in the exact engine, stepped in frames of one time unit (``sigma sqrt(m / kT)``,
about 20 collisions per disk): ``Z`` per frame from the collision virial
(``observables.reduced_pressure``: ``Z = 1 + W / (d N kT t)`` with ``d (N - 1) kT = 2 K``, since a
periodic cell conserves momentum),
its standard error by blocking over the frames.

**Time to an error bar.** A mean's standard error falls as ``1 / sqrt(events)``, so each method needs
``events (err / (10^-4 Z))^2`` events for a relative error of ``10^-4``; divided by its events per
CPU second (the two measured in alternating rounds, so that both see the same machine), that is its
CPU time to ``10^-4``.

**Chain length.** Event chains at several chain lengths (multiples of the default, about ``4 sqrt(N)``
liftings): the events to ``10^-4`` at each, to check the default.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable

import numpy as np

from collision_env.bench.readme import write_outputs
from collision_env.engine import Scene, Simulator, event_chain
from collision_env.engine.blocking import new_blocks, push_all, standard_error
from collision_env.observables import reduced_pressure

from .machine import cpus, machine, timestamp, versions

N, PACKING, COLUMNS, ROWS = 224, 0.68, 16, 14
#: The cell's height over its width.
ASPECT = math.sqrt(3.0) / 2.0
#: Liftings to melt the grid (about 10^5 per disk), and the relative error the times are given for.
MELT_EVENTS = 20_000_000
TARGET = 1e-4
#: The statistics runs: liftings of event chains, frames of MD (each about 4,400 collisions), and the
#: quick runs' share of them.
CHAIN_EVENTS = 400_000_000
MD_FRAMES = 15_000
QUICK_SHARE = 0.1
#: MD: frames of this many time units, and how many the velocities get to settle first.
FRAME = 1.0
SETTLE_FRAMES = 50
#: The rates: rounds of each method in turn, each this many liftings or frames.
RATE_ROUNDS = 5
RATE_EVENTS = 10_000_000
RATE_FRAMES = 500
#: Chain lengths tried, as multiples of the default, each for this many liftings.
SCAN = (0.25, 0.5, 1.0, 2.0, 4.0, 16.0)
SCAN_EVENTS = 100_000_000


def state_point(seed: int = 1) -> tuple[Scene, np.ndarray, np.ndarray]:
    """The cell, the melted positions and the radii."""
    area = N * math.pi / 4.0 / PACKING
    width = math.sqrt(area / ASPECT)
    height = width * ASPECT
    ix, iy = np.divmod(np.arange(N), ROWS)
    grid = np.stack([(ix + 0.5) * width / COLUMNS, (iy + 0.5) * height / ROWS], axis=1)
    scene = Scene(bounds=(0.0, 0.0, width, height), periodic=True)
    radii = np.full(N, 0.5)
    melted = event_chain(scene, grid, radii, events=MELT_EVENTS, seed=seed, progress=False)
    return scene, melted.positions, radii


def chain_statistics(
    scene: Scene,
    positions: np.ndarray,
    radii: np.ndarray,
    events: int,
    chain_length: float | None = None,
    seed: int = 2,
) -> dict:
    """``Z`` and its error from ``events`` liftings, and the liftings a relative error of ``TARGET``
    would take."""
    run = event_chain(scene, positions, radii, events=events, chain_length=chain_length, seed=seed, progress=False)
    z, err = run.reduced_pressure, run.pressure_error
    return {
        "chain_length": run.chain_length,
        "events": run.events,
        "chains": run.chains,
        "liftings_per_chain": run.events / max(run.chains, 1),
        "z": z,
        "z_err": err,
        "events_to_target": run.events * (err / (TARGET * z)) ** 2,
    }


def md_simulator(scene: Scene, positions: np.ndarray, radii: np.ndarray, seed: int = 3) -> Simulator:
    """The exact engine at the state point, Maxwell velocities at ``kT = 1`` (``K = N kT``), settled."""
    rng = np.random.default_rng(seed)
    velocities = rng.normal(size=(N, 2))
    velocities -= velocities.mean(axis=0)
    velocities *= math.sqrt(N / (0.5 * np.sum(velocities**2)))
    sim = Simulator(scene, positions, velocities, np.ones(N), radii)
    for _ in range(SETTLE_FRAMES):
        sim.step(FRAME)
    return sim


def md_frames(sim: Simulator, radii: np.ndarray, frames: int) -> tuple[np.ndarray, int]:
    """``Z`` of each of ``frames`` frames, and the collisions."""
    kinetic = sim.kinetic_energy()
    zs = np.empty(frames)
    collisions = 0
    for k in range(frames):
        impacts = sim.step(FRAME)
        collisions += len(impacts)
        zs[k] = reduced_pressure(impacts, radii, FRAME, kinetic, scene=sim.scene)
    return zs, collisions


def md_statistics(scene: Scene, positions: np.ndarray, radii: np.ndarray, frames: int) -> dict:
    """``Z`` and its error over ``frames`` frames, and the collisions a relative error of ``TARGET``
    would take."""
    zs, collisions = md_frames(md_simulator(scene, positions, radii), radii, frames)
    blocks = new_blocks()
    push_all(blocks, zs)
    z, err = float(zs.mean()), standard_error(blocks)
    return {
        "frames": frames,
        "collisions": collisions,
        "z": z,
        "z_err": err,
        "collisions_to_target": collisions * (err / (TARGET * z)) ** 2,
    }


def rates(scene: Scene, positions: np.ndarray, radii: np.ndarray, rounds: int = RATE_ROUNDS) -> dict:
    """Liftings and collisions per CPU second, in alternating rounds (the median of each)."""
    sim = md_simulator(scene, positions, radii)
    chains, md = [], []
    for k in range(rounds):
        started = time.process_time()
        run = event_chain(scene, positions, radii, events=RATE_EVENTS, seed=10 + k, progress=False)
        chains.append(run.events / (time.process_time() - started))
        positions = run.positions
        started = time.process_time()
        _, collisions = md_frames(sim, radii, RATE_FRAMES)
        md.append(collisions / (time.process_time() - started))
    return {"liftings_per_s": float(np.median(chains)), "collisions_per_s": float(np.median(md))}


def run(quick: bool, log: Callable[[str], None] = print) -> dict:
    started = time.perf_counter()
    share = QUICK_SHARE if quick else 1.0
    event_chain(*_tiny(), events=1000, progress=False)  # (compile before any timing)
    log(f"melting N = {N} at phi = {PACKING} ({MELT_EVENTS:,} liftings) ...")
    scene, positions, radii = state_point()
    log("rates, alternating ...")
    speed = rates(scene, positions, radii)
    log(f"  {speed['liftings_per_s']:.3g} liftings/s, {speed['collisions_per_s']:.3g} collisions/s (CPU)")
    log("event chains ...")
    chains = chain_statistics(scene, positions, radii, int(share * CHAIN_EVENTS))
    chains["cpu_seconds_to_target"] = chains["events_to_target"] / speed["liftings_per_s"]
    log(f"  Z {chains['z']:.5f} +- {chains['z_err']:.5f}, {chains['cpu_seconds_to_target']:.0f} s to 1e-4")
    log("molecular dynamics ...")
    md = md_statistics(scene, positions, radii, int(share * MD_FRAMES))
    md["cpu_seconds_to_target"] = md["collisions_to_target"] / speed["collisions_per_s"]
    log(f"  Z {md['z']:.5f} +- {md['z_err']:.5f}, {md['cpu_seconds_to_target']:.0f} s to 1e-4")
    scan = []
    if not quick:
        for factor in SCAN:
            row = chain_statistics(scene, positions, radii, SCAN_EVENTS, chain_length=factor * chains["chain_length"])
            row["factor"] = factor
            scan.append(row)
            log(
                f"  chain length x{factor:g}: {row['liftings_per_chain']:.1f} liftings per chain, "
                f"{row['events_to_target']:.3g} liftings to 1e-4"
            )
    return {
        "machine": machine(),
        "cpus": cpus(),
        "versions": versions(["numpy", "numba"]),
        "timestamp": timestamp(),
        "seconds": time.perf_counter() - started,
        "rates": speed,
        "chains": chains,
        "md": md,
        "scan": scan,
    }


def _tiny() -> tuple[Scene, np.ndarray, np.ndarray]:
    scene = Scene(bounds=(0.0, 0.0, 10.0, 10.0), periodic=True)
    return scene, np.array([[1.0, 1.0], [5.0, 1.2], [3.0, 6.0]]), np.full(3, 0.5)


def render_markdown(results: dict) -> str:
    v = results["versions"]
    c, m, speed = results["chains"], results["md"], results["rates"]
    sigma = math.hypot(c["z_err"], m["z_err"])
    lines = [
        f"`python -m collision_env.bench.chains` on {results['machine']}, {results['cpus']} CPUs, numpy "
        f"{v.get('numpy')}, numba {v.get('numba')}; {results['timestamp']}, {results['seconds']:.0f} s. "
        f"N = {N} disks at φ = {PACKING} in a periodic cell 1 : √3/2, melted by event chains; each method then "
        "ran from the same configuration (MD with Maxwell velocities, frames of one time unit). Z = βPA/N with "
        "its standard error by blocking; the events to a relative error of 10⁻⁴ are extrapolated from each run "
        "as events (err / 10⁻⁴ Z)², and divided by the events per CPU second (alternating rounds, median).",
        "",
        "| method | events | Z | events/s (CPU) | events to 10⁻⁴ | CPU time to 10⁻⁴ |",
        "|---|---:|---:|---:|---:|---:|",
        f"| event chains ({c['liftings_per_chain']:.0f} liftings per chain) | {c['events']:.3g} liftings | "
        f"{c['z']:.5f} ± {c['z_err']:.5f} | {speed['liftings_per_s']:.3g} | {c['events_to_target']:.3g} | "
        f"{_duration(c['cpu_seconds_to_target'])} |",
        f"| exact-mode MD | {m['collisions']:.3g} collisions | {m['z']:.5f} ± {m['z_err']:.5f} | "
        f"{speed['collisions_per_s']:.3g} | {m['collisions_to_target']:.3g} | "
        f"{_duration(m['cpu_seconds_to_target'])} |",
        "",
        f"The two pressures differ by {(c['z'] - m['z']) / sigma:+.1f} combined standard errors; event chains reach "
        f"10⁻⁴ in {c['cpu_seconds_to_target'] / m['cpu_seconds_to_target']:.2g} of MD's CPU time.",
    ]
    if results["scan"]:
        lines += [
            "",
            "Chain length (multiples of the default):",
            "",
            "| chain length / default | liftings per chain | Z | liftings to 10⁻⁴ |",
            "|---:|---:|---:|---:|",
        ]
        for r in results["scan"]:
            lines.append(
                f"| {r['factor']:g} | {r['liftings_per_chain']:.1f} | {r['z']:.5f} ± {r['z_err']:.5f} | "
                f"{r['events_to_target']:.3g} |"
            )
    return "\n".join(lines)


def _duration(seconds: float) -> str:
    return f"{seconds / 3600:.1f} h" if seconds >= 3600 else f"{seconds / 60:.1f} min"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.chains", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a tenth of the statistics runs, no chain-length scan")
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument("--markdown", help="write the table here")
    args = parser.parse_args(argv)
    results = run(args.quick)
    text = render_markdown(results)
    title = "# Event chains against molecular dynamics"
    write_outputs(text, results, json_path=args.json, markdown=args.markdown, title=title)
    return 0


if __name__ == "__main__":
    sys.exit(main())
