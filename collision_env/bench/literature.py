"""Hard-disk pressures of small periodic systems against Li et al. (2022), by exact-mode MD and by
event chains: the ``literature`` section of ``python -m collision_env.bench.physics``.

Run it as::

    python -m collision_env.bench.physics --section literature                 # every point, serially
    python -m collision_env.bench.physics --section literature --jobs 2        # two local processes
    python -m collision_env.bench.physics --section literature --ray --jobs 2  # a private Ray instance
    python -m collision_env.bench.physics --section literature --address HOST:PORT   # a Ray cluster
    python -m collision_env.bench.physics --section literature --quick         # a few points, a tenth as long

**The reference.** Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, *J. Chem. Phys.* 157, 234111
(2022) give ``beta P sigma^2`` of ``N = 72``, 224 and 870 disks in periodic cells to about ``1e-5``
(:func:`~collision_env.observables.li_2022_pressures`): ``N = 72`` in three cells (square, ``1 :
sqrt3/2``, and ``9 : 8 sqrt3/2``, which a crystal of 9 disks by 8 rows tiles), ``N = 224`` in a square,
``N = 870`` in a square and in ``29 : 30 sqrt3/2``. Both methods are compared in ``Z = beta P A / N
= beta P sigma^2 pi / (4 phi)`` at every fluid point of :data:`FLUID` (``phi <= 0.68``), and at
``N = 224`` over the Mayer–Wood loop of the liquid–hexatic coexistence (:data:`LOOP`).

**The start.** Each state point starts from a fluid: ``N`` disks placed at random at ``phi = 0.45``
(:func:`~collision_env.engine.disk_gas`, in the cell's shape), then compressed
(:func:`~collision_env.engine.compress`, ``until_phi``) to the point's area fraction, where the
diameter is 1. A compressed fluid reaches every point of the fluid branch without crossing the
liquid–hexatic coexistence (``phi ~ 0.70``), where a melting crystal (in a commensurate cell
especially) would linger; the compression's own disorder is removed by the equilibration, whose
length :data:`FLUID_RUNS` and :data:`LOOP_RUNS` give per disk, before any measurement.

**The runs.** Event chains (:func:`~collision_env.engine.event_chain`) and exact-mode MD
(``Simulator.frames`` into :class:`~collision_env.observables.PressureAccumulator`, frames of one
time unit ``sigma sqrt(m / kT)``, the temperature counting the ``2 (N - 1)`` degrees of freedom of a
periodic cell) each equilibrate and measure on their own from the same start. The measurement runs
in :data:`SEGMENTS` equal segments; ``Z`` is their mean, its error the segments' blocking errors
combined. The drift, the second half's mean less the first's in their combined errors, tells an
equilibration that was too short.

**Parallel.** The state points and methods are independent tasks (:func:`points`), each seeded by
its own ``(seed, N, cell, phi, method)``: run serially, in local processes or on Ray
(:mod:`~collision_env.bench.parallel`), they give the same numbers bit for bit (only the CPU
seconds differ).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from collision_env.engine import Scene, Simulator, compress, disk_gas, event_chain
from collision_env.observables import LI_2022_CELLS, PressureAccumulator, li_2022_pressures

from .machine import cpus, machine, timestamp, versions
from .parallel import run_tasks
from .readme import write_outputs

#: The fluid's state points: ``(N, cell, area fractions)``, the cells keys of ``LI_2022_CELLS``.
FLUID = (
    (72, "9:8sqrt3/2", (0.650, 0.670, 0.680)),
    (72, "1:sqrt3/2", (0.650, 0.670, 0.680)),
    (72, "1:1", (0.650, 0.670, 0.680)),
    (224, "1:1", (0.670, 0.676, 0.680)),
    (870, "29:30sqrt3/2", (0.670, 0.680)),
    (870, "1:1", (0.670, 0.680)),
)
#: The Mayer–Wood loop of ``N = 224`` in the square cell: up to its maximum (0.692) and down to its
#: minimum (0.706).
LOOP = ((224, "1:1", (0.686, 0.692, 0.698, 0.704, 0.710)),)
#: ``--quick``: a few of the points, runs :data:`QUICK_SHARE` as long.
QUICK_FLUID = ((72, "1:1", (0.650, 0.680)), (224, "1:1", (0.680,)))
QUICK_LOOP = ((224, "1:1", (0.690, 0.700)),)
QUICK_SHARE = 0.1
#: The fluid's last area fraction, where each method must be within 3 combined standard errors.
FLUID_MAX = 0.68
WITHIN_SIGMA = 3.0
METHODS = ("ecmc", "md")
#: Where the compression starts, and its rate (diameters per thermal time).
START_PACKING = 0.45
COMPRESSION_RATE = 0.01
#: MD frames, in time units ``sigma sqrt(m / kT)``, and how many one ``frames`` call runs.
FRAME = 1.0
FRAMES_PER_CALL = 20
#: The measurement's segments (an even number: the drift compares the halves).
SEGMENTS = 4
#: The numbers of a point that are timings (they differ from run to run; nothing else may).
TIMINGS = ("start_cpu_s", "equilibration_cpu_s", "cpu_s", "events_per_s")


@dataclass(frozen=True)
class Runs:
    """How long each method equilibrates (events per disk) and measures (events in all): liftings
    for event chains, collisions for MD."""

    ecmc_equilibration: float
    ecmc_measurement: int
    md_equilibration: float
    md_measurement: int

    def scaled(self, share: float) -> Runs:
        return Runs(
            self.ecmc_equilibration * share,
            int(self.ecmc_measurement * share),
            self.md_equilibration * share,
            int(self.md_measurement * share),
        )


FLUID_RUNS = Runs(ecmc_equilibration=1e5, ecmc_measurement=150_000_000, md_equilibration=5e3, md_measurement=15_000_000)
#: The loop's runs are longer: the liquid–hexatic coexistence equilibrates slowly.
LOOP_RUNS = Runs(ecmc_equilibration=5e5, ecmc_measurement=400_000_000, md_equilibration=2e4, md_measurement=30_000_000)


@dataclass(frozen=True)
class Point:
    """One task: a state point, a method and its run lengths (events), a seed."""

    n: int
    cell: str
    packing: float
    method: str  #: "ecmc" or "md"
    region: str  #: "fluid" or "loop"
    equilibration: int  #: liftings or collisions
    measurement: int  #: liftings or collisions
    seed: int


def points(quick: bool = False, seed: int = 1) -> list[Point]:
    """Every task of the section: each state point of :data:`FLUID` and :data:`LOOP` (or the quick
    ones) by each method."""
    share = QUICK_SHARE if quick else 1.0
    out = []
    for region, series, runs in (
        ("fluid", QUICK_FLUID if quick else FLUID, FLUID_RUNS.scaled(share)),
        ("loop", QUICK_LOOP if quick else LOOP, LOOP_RUNS.scaled(share)),
    ):
        for n, cell, packings in series:
            for phi in packings:
                for method in METHODS:
                    eq, measure = (
                        (runs.ecmc_equilibration, runs.ecmc_measurement)
                        if method == "ecmc"
                        else (runs.md_equilibration, runs.md_measurement)
                    )
                    out.append(Point(n, cell, phi, method, region, int(eq * n), int(measure), seed))
    return out


def _seeds(point: Point, *tail: int) -> np.random.SeedSequence:
    """The point's own seed sequence: ``(seed, N, cell, phi)`` and ``tail``."""
    cell = list(LI_2022_CELLS).index(point.cell)
    return np.random.SeedSequence([point.seed, point.n, cell, round(point.packing * 1e6), *tail])


def start_state(point: Point) -> tuple[Scene, np.ndarray, np.ndarray, np.ndarray]:
    """The cell, positions, velocities (``kT = 1``) and radii (1/2) of the point's start: placed at
    random at :data:`START_PACKING` in the cell's shape, compressed to the point's area fraction.
    The same for both methods."""
    place, grow = (np.random.default_rng(s) for s in _seeds(point).spawn(2))
    sides = LI_2022_CELLS[point.cell]
    diameter = math.sqrt(START_PACKING / point.packing)  # (grown to 1 at the point)
    gas = disk_gas(
        point.n,
        START_PACKING,
        arrangement="random",
        periodic=True,
        aspect=sides,
        diameters=(diameter,),
        seed=place,
    )
    packing = compress(
        gas.scene,
        gas.positions,
        gas.radii,
        velocities=gas.velocities,
        masses=gas.masses,
        rate=COMPRESSION_RATE,
        until_phi=point.packing,
        seed=grow,
        progress=False,
    )
    return packing.scene, packing.positions, packing.velocities, packing.radii


def run_point(point: Point) -> dict:
    """One task: the start, the method's equilibration and measurement, ``Z`` against Li et al.'s."""
    started = time.process_time()
    scene, positions, velocities, radii = start_state(point)
    start_cpu = time.process_time() - started
    method = {"ecmc": _chains, "md": _dynamics}[point.method]
    segments, events, equilibration_cpu, cpu = method(point, scene, positions, velocities, radii)
    z_ref, z_ref_err = li_2022_pressures(point.n, point.cell).at(point.packing)
    return {**asdict(point), **_summary(segments, z_ref, z_ref_err), "events": events} | {
        "start_cpu_s": start_cpu,
        "equilibration_cpu_s": equilibration_cpu,
        "cpu_s": cpu,
        "events_per_s": events / cpu if cpu > 0 else math.inf,
    }


def _chains(point, scene, positions, velocities, radii):
    """Event chains: equilibrate, then :data:`SEGMENTS` segments; ``(Z, error, reliable)`` of each."""
    rng = np.random.default_rng(_seeds(point, 1))
    started = time.process_time()
    pos = event_chain(scene, positions, radii, events=point.equilibration, seed=rng, progress=False).positions
    equilibration_cpu = time.process_time() - started
    started = time.process_time()
    segments, events = [], 0
    for _ in range(SEGMENTS):
        run = event_chain(scene, pos, radii, events=point.measurement // SEGMENTS, seed=rng, progress=False)
        segments.append((float(run.reduced_pressure), float(run.pressure_error), math.isfinite(run.pressure_error)))
        events += run.events
        pos = run.positions
    return segments, events, equilibration_cpu, time.process_time() - started


def _dynamics(point, scene, positions, velocities, radii):
    """Exact-mode MD: equilibrate, then :data:`SEGMENTS` segments, each a
    :class:`~collision_env.observables.PressureAccumulator`; ``(Z, error, reliable)`` of each."""
    masses = np.ones(point.n)
    sim = Simulator(scene, positions, velocities, masses, radii)
    started = time.process_time()
    done = 0
    while done < point.equilibration:
        done += len(sim.frames(FRAME, FRAMES_PER_CALL).impacts)
    equilibration_cpu = time.process_time() - started
    started = time.process_time()
    segments, events = [], 0
    for _ in range(SEGMENTS):
        acc = PressureAccumulator(scene, radii, masses, time=sim.time)
        while acc.collisions < point.measurement // SEGMENTS:
            acc.add(sim.frames(FRAME, FRAMES_PER_CALL))
        z = acc.pressure()
        segments.append((float(z.mean), float(z.error), bool(z.reliable)))
        events += acc.collisions
    return segments, events, equilibration_cpu, time.process_time() - started


def _summary(segments: Sequence[tuple[float, float, bool]], z_ref: float, z_ref_err: float) -> dict:
    """``Z`` (the segments' mean) and its error, the drift between the halves, the deviation from
    the reference in combined standard errors."""
    z = np.array([s[0] for s in segments])
    err = np.array([s[1] for s in segments])
    half = len(segments) // 2
    mean, error = float(z.mean()), float(math.sqrt(np.sum(err**2)) / len(z))
    first, second = z[:half].mean(), z[half:].mean()
    spread = math.sqrt(np.sum(err[:half] ** 2)) / half, math.sqrt(np.sum(err[half:] ** 2)) / (len(z) - half)
    combined = math.hypot(error, z_ref_err)
    return {
        "z": mean,
        "z_err": error,
        "reliable": all(s[2] for s in segments),
        "segments": [[float(a), float(b)] for a, b, _ in segments],
        "drift_sigma": float((second - first) / math.hypot(*spread)) if math.isfinite(sum(spread)) else math.nan,
        "z_ref": z_ref,
        "z_ref_err": z_ref_err,
        "deviation": mean / z_ref - 1.0,
        "deviation_sigma": (mean - z_ref) / combined if math.isfinite(combined) else math.nan,
    }


def physics_of(row: dict) -> dict:
    """A result row without its timings (:data:`TIMINGS`): what must not depend on how it ran."""
    return {k: v for k, v in row.items() if k not in TIMINGS}


def within(row: dict) -> bool:
    """A measured ``Z`` within :data:`WITHIN_SIGMA` combined standard errors of the reference (a
    run whose error is not finite is not)."""
    return row["reliable"] and math.isfinite(row["deviation_sigma"]) and abs(row["deviation_sigma"]) <= WITHIN_SIGMA


def run(
    quick: bool = False,
    *,
    jobs: int = 1,
    ray: bool = False,
    address: str | None = None,
    seed: int = 1,
    tasks: Sequence[Point] | None = None,
    log: Callable[[str], None] = print,
) -> dict:
    """Every task (:func:`points`, or ``tasks``), run as :func:`~collision_env.bench.parallel.run_tasks`
    runs them, with the machine and the totals."""
    todo = list(points(quick, seed) if tasks is None else tasks)
    started, cpu = time.perf_counter(), time.process_time()

    def done(k: int, row: dict) -> None:
        log(
            f"  N {row['n']} {row['cell']} phi {row['packing']:.3f} {row['method']}: Z {row['z']:.5f} +- "
            f"{row['z_err']:.5f} (Li et al. {row['z_ref']:.5f}, {row['deviation_sigma']:+.1f} sigma, drift "
            f"{row['drift_sigma']:+.1f}), {row['events']:.3g} events, {row['cpu_s']:.0f} s CPU"
        )

    log(f"literature: {len(todo)} tasks, {'Ray' if ray or address else f'{jobs} process(es)'}")
    rows = run_tasks(run_point, todo, jobs=jobs, ray=ray, address=address, done=done)
    return {
        "machine": machine(),
        "cpus": cpus(),
        "versions": versions(["numpy", "numba"]),
        "timestamp": timestamp(),
        "seconds": time.perf_counter() - started,
        "driver_cpu_s": time.process_time() - cpu,
        "quick": quick,
        "runner": "ray" if ray or address else ("processes" if jobs > 1 else "serial"),
        "jobs": jobs,
        "segments": SEGMENTS,
        "fluid_runs": asdict(FLUID_RUNS.scaled(QUICK_SHARE if quick else 1.0)),
        "loop_runs": asdict(LOOP_RUNS.scaled(QUICK_SHARE if quick else 1.0)),
        "rows": rows,
    }


_NAMES = {"ecmc": "event chains", "md": "exact-mode MD"}
_UNITS = {"ecmc": "liftings", "md": "collisions"}


def _pair(rows: Sequence[dict], region: str) -> list[tuple[dict, dict]]:
    """The rows of ``region`` by state point: ``(event chains, MD)`` pairs, in order."""
    by = {(r["n"], r["cell"], r["packing"], r["method"]): r for r in rows if r["region"] == region}
    keys = dict.fromkeys((r["n"], r["cell"], r["packing"]) for r in rows if r["region"] == region)
    return [(by[(*k, "ecmc")], by[(*k, "md")]) for k in keys if (*k, "ecmc") in by and (*k, "md") in by]


def _z(row: dict) -> str:
    flag = "" if row["reliable"] else " (unreliable)"
    return f"{row['z']:.5f} ± {row['z_err']:.5f}{flag}"


def _bp(row: dict, z: float, err: float) -> str:
    """``Z`` as ``beta P sigma^2 = Z 4 phi / pi``."""
    f = 4.0 * row["packing"] / math.pi
    return f"{z * f:.4f} ± {err * f:.4f}"


def render_markdown(results: dict) -> str:
    v, rows = results["versions"], results["rows"]
    fluid, loop = _pair(rows, "fluid"), _pair(rows, "loop")
    fr, lr = results["fluid_runs"], results["loop_runs"]
    lines = [
        f"`python -m collision_env.bench.physics --section literature{' --quick' if results['quick'] else ''}` on "
        f"{results['machine']}, {results['cpus']} CPUs, numpy {v.get('numpy')}, numba {v.get('numba')}; "
        f"{results['timestamp']}, {results['seconds'] / 60:.0f} min wall time ({results['runner']}, {results['jobs']} "
        f"job(s)), {sum(r['start_cpu_s'] + r['equilibration_cpu_s'] + r['cpu_s'] for r in rows) / 3600:.2f} CPU hours "
        "in the tasks. Each state point: disks placed at random at φ = 0.45 in Li et al.'s cell, compressed to φ "
        f"(rate {COMPRESSION_RATE:g}); then each method on its own equilibrated "
        f"({fr['ecmc_equilibration']:.3g} liftings or {fr['md_equilibration']:.3g} collisions per disk; in the loop "
        f"{lr['ecmc_equilibration']:.3g} and {lr['md_equilibration']:.3g}) and measured "
        f"({fr['ecmc_measurement']:.3g} liftings or {fr['md_measurement']:.3g} collisions; in the loop "
        f"{lr['ecmc_measurement']:.3g} and {lr['md_measurement']:.3g}) in {results['segments']} segments. "
        "Z = βPA/N ± its standard error (blocking); σ: the deviation from Li et al. (2022) in combined standard "
        "errors; drift: the second half's mean less the first's, in their combined errors.",
        "",
        "| N | cell | φ | Z (Li et al.) | Z (event chains) | σ | drift | Z (exact-mode MD) | σ | drift |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for c, m in fluid:
        lines.append(
            f"| {c['n']} | {c['cell']} | {c['packing']:.3f} | {c['z_ref']:.5f} ± {c['z_ref_err']:.5f} | {_z(c)} | "
            f"{c['deviation_sigma']:+.1f} | {c['drift_sigma']:+.1f} | {_z(m)} | {m['deviation_sigma']:+.1f} | "
            f"{m['drift_sigma']:+.1f} |"
        )
    checked = [r for pair in fluid for r in pair if r["packing"] <= FLUID_MAX + 1e-9]
    if checked:
        lines += ["", _verdict(checked)]
    if loop:
        lines += [
            "",
            "The Mayer–Wood loop, N = 224 in the square cell, in βPσ² = Z 4φ/π as Li et al. plot it:",
            "",
            "| φ | βPσ² (Li et al.) | event chains | σ | drift | exact-mode MD | σ | drift |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for c, m in loop:
            lines.append(
                f"| {c['packing']:.3f} | {_bp(c, c['z_ref'], c['z_ref_err'])} | {_bp(c, c['z'], c['z_err'])} | "
                f"{c['deviation_sigma']:+.1f} | {c['drift_sigma']:+.1f} | {_bp(m, m['z'], m['z_err'])} | "
                f"{m['deviation_sigma']:+.1f} | {m['drift_sigma']:+.1f} |"
            )
        lines += ["", _loop_note([r for pair in loop for r in pair])]
    lines += [
        "",
        "| method | N | points | events per point | events/s (CPU, median) | CPU per point |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for method in METHODS:
        for n in sorted({r["n"] for r in rows}):
            group = [r for r in rows if r["method"] == method and r["n"] == n]
            if not group:
                continue
            events = np.median([r["equilibration"] + r["events"] for r in group])
            rate = np.median([r["events_per_s"] for r in group])
            cpu = np.median([r["start_cpu_s"] + r["equilibration_cpu_s"] + r["cpu_s"] for r in group])
            lines.append(
                f"| {_NAMES[method]} | {n} | {len(group)} | {events:.3g} {_UNITS[method]} | {rate:.3g} | {cpu:.0f} s |"
            )
    return "\n".join(lines)


def _loop_note(rows: Sequence[dict]) -> str:
    """The loop's points that a method did not equilibrate at this run length: beyond
    :data:`WITHIN_SIGMA` of the reference, or drifting by as much."""
    off = [
        r
        for r in rows
        if not within(r) or not (math.isfinite(r["drift_sigma"]) and abs(r["drift_sigma"]) <= WITHIN_SIGMA)
    ]
    if not off:
        return f"Every loop point within {WITHIN_SIGMA:g} σ of Li et al., none drifting by as much."
    where = "; ".join(
        f"φ = {r['packing']:.3f} by {_NAMES[r['method']]} ({r['deviation_sigma']:+.1f} σ, "
        f"drift {r['drift_sigma']:+.1f}{'' if r['reliable'] else ', a segment too short for its error'})"
        for r in sorted(off, key=lambda r: (r["packing"], r["method"]))
    )
    return (
        f"Beyond {WITHIN_SIGMA:g} σ of Li et al., or drifting by as much: {where}. At this run length such a point "
        "is not equilibrated; the coexistence relaxes slowly."
    )


def _verdict(rows: Sequence[dict]) -> str:
    parts = []
    for method in METHODS:
        group = [r for r in rows if r["method"] == method]
        if not group:
            continue
        ok = sum(within(r) for r in group)
        worst = max(abs(r["deviation_sigma"]) for r in group)
        rms = math.sqrt(np.mean([r["deviation_sigma"] ** 2 for r in group]))
        parts.append(
            f"{_NAMES[method]}: {ok} of {len(group)} fluid points within {WITHIN_SIGMA:g} σ "
            f"(largest |deviation| {worst:.1f} σ, root mean square {rms:.2f} σ)"
        )
    return "; ".join(parts) + "."


def plot(results: dict, folder: str | Path) -> str:
    """The N = 224 loop against Li et al.'s (left), and every fluid point's deviation (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = results["rows"]
    ref = li_2022_pressures(224, "1:1")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.errorbar(
        ref.packing, ref.pressure, ref.error, fmt="-", color="k", lw=1, label="Li et al. (2022), event chains"
    )
    for k, method in enumerate(METHODS):
        mine = sorted(
            (r for r in rows if r["n"] == 224 and r["cell"] == "1:1" and r["method"] == method),
            key=lambda r: r["packing"],
        )
        if not mine:
            continue
        f = np.array([4.0 * r["packing"] / math.pi for r in mine])
        left.errorbar(
            np.array([r["packing"] for r in mine]) + (k - 0.5) * 4e-4,
            np.array([r["z"] for r in mine]) * f,
            np.array([r["z_err"] for r in mine]) * f,
            fmt="o",
            ms=4,
            color=f"C{k}",
            label=f"this engine, {_NAMES[method]}",
        )
    left.set(xlabel="area fraction φ", ylabel="βPσ²", title="N = 224, square periodic cell: the Mayer–Wood loop")
    left.legend(fontsize=8)
    fluid = [r for r in rows if r["region"] == "fluid"]
    labels = list(dict.fromkeys((r["n"], r["cell"]) for r in fluid))
    for k, method in enumerate(METHODS):
        mine = [r for r in fluid if r["method"] == method]
        x = [labels.index((r["n"], r["cell"])) + (k - 0.5) * 0.25 for r in mine]
        right.plot(x, [r["deviation_sigma"] for r in mine], "o", ms=4, color=f"C{k}", label=_NAMES[method])
    for y in (-WITHIN_SIGMA, WITHIN_SIGMA):
        right.axhline(y, color="k", lw=0.8, ls="--")
    right.axhline(0.0, color="k", lw=0.5)
    right.set_xticks(range(len(labels)), [f"N = {n}\n{cell}" for n, cell in labels], fontsize=8)
    right.set(ylabel="(Z − Z_Li) / combined σ", title=f"Fluid points, φ ≤ {FLUID_MAX}")
    right.legend(fontsize=8)
    fig.tight_layout()
    path = f"{folder}/physics_li2022.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


PAGE_TITLE = "# Hard disks against the literature"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The section's options (``python -m collision_env.bench.physics --section literature``)."""
    parser.add_argument(
        "--jobs", type=int, default=1, help="local processes (or, with --ray, the private Ray instance's CPUs)"
    )
    parser.add_argument(
        "--ray", action="store_true", help="run the state points as Ray tasks (the 'distributed' extra)"
    )
    parser.add_argument("--address", help="the Ray cluster to join (host:port, or auto); implies --ray")
    parser.add_argument("--seed", type=int, default=1, help="the seed every state point's seeds derive from")
    parser.add_argument("--render", metavar="JSON", help="run nothing: write the table and plot of a saved run")


def main(args: argparse.Namespace) -> int:
    """Run the section as ``args`` ask, print the table, write the json, the page block and the plot."""
    if args.render:
        with open(args.render) as fh:
            results = json.load(fh)
    else:
        results = run(args.quick, jobs=args.jobs, ray=args.ray, address=args.address, seed=args.seed)
    text = render_markdown(results)
    measured = None if args.render else results  # (a rendered file is not written again)
    write_outputs(
        text, measured, json_path=args.json, markdown=args.markdown, block="bench:literature", title=PAGE_TITLE
    )
    if args.plot:
        print(plot(results, args.plot))
    return 0
