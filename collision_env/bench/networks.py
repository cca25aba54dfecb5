"""Contact networks at e < 1 in exact mode: the cost of a step, its memory, and whether the clock gets through.

Run it as::

    python -m collision_env.bench.networks            # every row (some seconds once compiled)
    python -m collision_env.bench.networks --quick    # smaller scenes, fewer steps

Each row builds a scene through the public API (:class:`~collision_env.engine.Simulator`), steps it
in frames of 1/60 s and reports the slowest step and the median one (wall-clock milliseconds, the
kernels compiled beforehand by a small run of the same kind of scene), the growth of the process's
peak resident memory over the row's steps (MB; 0 when it stays below an earlier peak, so rows run
in order of size), and whether the clock reached the end of every step (no step stopped at the
event cap). The rows:

- ``row``: a row of touching balls (10^4) struck at one end by one more, at e = 0 and 0.5, in a box
  and in a periodic cell; the strike lands in the first step. Target: every step within 50 ms.
- ``pile``: 400 balls stacked in columns of touching balls (a square lattice, rows of 20) on the
  floor of a box, each step's velocities nudged down first by g times the time the clock advanced
  in the step before (gravity: g dt, or less after a step the event cap stopped, so that the
  nudges add up to g times the simulated time, give or take the last step, and a capped step
  pumps no energy in).
  Target: every step within 20 ms, memory within 50 MB. Frictionless balls stacked in columns
  stand in an unstable equilibrium: a sideways offset grows about as ``exp(t sqrt(g / r))`` (31 per
  second here), so round-off of 1e-16 m tips the columns over within ten frames or so, and the
  pile collapses into a heap over the next half second (some tens of millions of contact impulses
  a frame, at the event cap) before it comes to rest. ``heap``: the same 400 balls in hexagonal
  rows (each in the dips of the row below), a frictionless heap that spreads while it settles, so
  that its contact network changes and collides at every step.
- ``cluster``: 144 balls on a square lattice, a tenth of a diameter apart, all moving towards the
  centre, at e = 0.3 and 0, in a box and in a periodic cell; it collapses into one contact network.
- ``cooling``: a periodic gas of 200 disks at area fraction 0.5 and e = 0 (inelastic cooling), 600
  steps, and the same gas in a box.

Where the event cap stops a step of these rows, the work is the contact groups' sequential
impulses, whose result is the one the engine's docs state, not a slow limit. Measured without a
cap: the heap at e = 0 takes 18-38 million units a frame over frames 2-6 (45-95 times its default
cap of 400,000), in 8,000-22,000 contact groups a frame of about 1,800 units each, less than 1 % of
the units in the groups' limits; the cooling gas in a box needs more than its cap (200,000) in 112
of its 600 steps (1.56 million at most), about 99 % of the units in sweeps; the cluster at e = 0.3 takes
385,000 units over its first four frames against a cap of 144,000 a step. The hexagonal heap is
not at rest either: the limit of one step's nudge on it, even in a box it fits, keeps about 0.45 J
of the nudge's 5.35 J (balls at up to 0.12 m/s), so every step is a dense inelastic flow, whose
collisions exact hard-disk dynamics resolves one by one (inelastic collapse: McNamara & Young,
*Phys. Rev. E* 50, R28, 1994). The rows marked ``TC`` run the pile, heap, cluster and cooling scenes
again under the TC model of Luding & McNamara (*Granular Matter* 1, 113, 1998; the simulators'
``contact_duration``, :data:`TC_PILE` and :data:`TC_GAS`), which bounds those collisions at a cost
in exactness: a collision within ``t_c`` of either ball's previous one is elastic. Every row also
gives the most kinetic energy a step's collisions added, as a fraction of the step's starting
energy (the nudge comes before the step: round-off at most, since e < 1).

A second table puts a granular gas beside the same gas elastic: 10^3 and 10^4 disks at area
fraction 0.3 (``disk_gas``), in a box and in a periodic cell, at e = 0.9 and at e = 1, stepped in
frames of 1/60 s (the engine's own time unit: disks of unit diameter and temperature), CPU
microseconds per event. An inelastic gas resolves its events where contact groups can see them
(:mod:`collision_env.engine.exact.contacts`); what that costs over the elastic path is the ratio.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import resource
import time

import numpy as np

from ..engine import Scene, Simulator, disk_gas
from .machine import machine, timestamp
from .readme import write_outputs

FRAME = 1.0 / 60.0
GRAVITY = 9.81
#: Targets of the rows (ms per step; MB).
ROW_MS, PILE_MS, PILE_MB = 50.0, 20.0, 50.0
#: The TC model's contact duration (s) in the rows that use it: for the balls of 1 cm (pile, heap,
#: cluster), 1e-4 s, about 1/300 of their time scale under gravity ``sqrt(r / g)`` (32 ms) and 1/20
#: of the time the cluster's first gaps take to close (2 ms); for the cooling gas, 1e-3 s, about a
#: tenth of a disk's initial mean time between collisions (Enskog's rate at area fraction 0.5 and
#: unit mean square speed: about 88 per second): much shorter than the time between a ball's
#: collisions where the flow is not collapsing, so that the model changes only where it is.
TC_PILE, TC_GAS = 1e-4, 1e-3


def row(n: int, e: float, periodic: bool) -> tuple[Scene, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` touching balls of radius 5 mm in a row along x, and one more 1 m/s towards its low end,
    arriving after half a frame; a box (or cell) four times as long as the row."""
    r = 0.005
    x = np.arange(n) * 2.0 * r
    pos = np.vstack([[-r - FRAME / 2 - r, 0.0], np.stack([x, np.zeros(n)], 1)])
    vel = np.zeros((n + 1, 2))
    vel[0, 0] = 1.0
    length = 4.0 * (x[-1] + 2 * r) + 1.0
    scene = Scene(bounds=(-0.5, -0.25, length - 0.5, 0.25), elasticity=e, periodic=periodic)
    return scene, pos, vel, np.ones(n + 1), np.full(n + 1, r)


def pile(n: int, e: float, hexagonal: bool = False) -> tuple[Scene, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` balls of radius 1 cm at rest in rows of 20 on the floor of a box twice as wide, each
    touching its neighbours (within round-off): stacked in columns (a square lattice), or with
    ``hexagonal`` in the dips of the row below (rows of 20 and 19, a frictionless heap that spreads)."""
    r = 0.01
    d = 2.0 * r * (1.0 + 1e-12)  # (a hair apart: touching within the contact tolerance, no overlap)
    rise = d * math.sqrt(3.0) / 2.0 if hexagonal else d
    places: list[tuple[float, float]] = []
    k = 0
    while len(places) < n:
        odd = hexagonal and k % 2 == 1
        places.extend(((j + (0.5 if odd else 0.0)) * d, r + k * rise) for j in range(19 if odd else 20))
        k += 1
    pos = np.array(places[:n], dtype=np.float64)
    scene = Scene(bounds=(-0.2, 0.0, 0.6, 1.0), elasticity=e)
    return scene, pos, np.zeros((n, 2)), np.ones(n), np.full(n, r)


def cluster(side: int, e: float, periodic: bool) -> tuple[Scene, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``side`` x ``side`` balls of radius 1 cm on a square lattice 2.2 cm apart, each moving at
    1 m/s towards the centre, in a box (or cell) of 1 m."""
    r = 0.01
    k = (np.arange(side) - (side - 1) / 2.0) * 2.2 * r
    pos = np.stack(np.meshgrid(k, k), -1).reshape(-1, 2)
    dist = np.hypot(pos[:, 0], pos[:, 1])
    vel = -pos / np.where(dist > 0.0, dist, 1.0)[:, None]
    n = len(pos)
    scene = Scene(bounds=(-0.5, -0.5, 0.5, 0.5), elasticity=e, periodic=periodic)
    return scene, pos, vel, np.ones(n), np.full(n, r)


def cooling(
    n: int, phi: float, periodic: bool, seed: int = 0
) -> tuple[Scene, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` disks at area fraction ``phi`` in a unit cell (or box), on a jittered square lattice,
    random velocities of unit mean square speed, e = 0."""
    rng = np.random.default_rng(seed)
    r = math.sqrt(phi / (n * math.pi))
    side = math.ceil(math.sqrt(n))
    h = 1.0 / side
    cells = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)[:n]
    pos = h * (cells + 0.5) + rng.uniform(-1, 1, (n, 2)) * max(0.0, 0.5 * h - r) * 0.9
    vel = rng.normal(size=(n, 2)) / math.sqrt(2.0)
    scene = Scene(bounds=(0.0, 0.0, 1.0, 1.0), elasticity=0.0, periodic=periodic)
    return scene, pos, vel, np.ones(n), np.full(n, r)


def granular(n: int, e: float, periodic: bool, frames: int) -> dict:
    """CPU microseconds per event of ``disk_gas(n, 0.3)`` at elasticity ``e`` over ``frames`` frames
    of 1/60 s (after one frame to warm up)."""
    gas = disk_gas(n, 0.3, periodic=periodic, seed=1)
    scene = dataclasses.replace(gas.scene, elasticity=e)
    sim = Simulator(scene, gas.positions, gas.velocities, gas.masses, gas.radii)
    sim.step(FRAME)
    events = sim.stats["events"]
    start = time.process_time()
    for _ in range(frames):
        sim.step(FRAME)
    events = sim.stats["events"] - events
    return {"events": events, "us_per_event": 1e6 * (time.process_time() - start) / max(events, 1)}


def granular_rows(quick: bool = False) -> dict:
    """The granular gas beside the elastic one, alternating, for each size and wall kind."""
    frames = 60 if quick else 300
    rows = {}
    for n in (1000,) if quick else (1000, 10_000):
        for periodic in (False, True):
            inelastic = granular(n, 0.9, periodic, frames)
            elastic = granular(n, 1.0, periodic, frames)
            rows[f"{n} disks {'cell' if periodic else 'box'}"] = {
                "disks": n,
                "events_inelastic": inelastic["events"],
                "us_per_event_inelastic": inelastic["us_per_event"],
                "us_per_event_elastic": elastic["us_per_event"],
                "ratio": inelastic["us_per_event"] / elastic["us_per_event"],
            }
    return rows


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def measure(build: tuple, steps: int, nudge: float = 0.0, contact_duration: float = 0.0) -> dict:
    """Step a scene ``steps`` frames (each velocity nudged first along y by ``-nudge`` times the
    fraction of a frame the clock advanced in the step before, the whole of it at the start), under
    the TC model if ``contact_duration`` > 0: the slowest and median step (ms), the peak memory's
    growth (MB), steps that reached their end, the clock, and the most kinetic energy a step gained
    (its collisions, after the nudge), as a fraction of the energy it started with."""
    scene, pos, vel, mass, radius = build
    sim = Simulator(scene, pos, vel, mass, radius, contact_duration=contact_duration)
    dv = np.zeros((len(pos), 2))
    dv[:, 1] = -nudge
    times = []
    reached = 0
    gained = 0.0
    before = _peak_mb()
    advanced = FRAME
    for _ in range(steps):
        if nudge:
            sim.nudge(dv * (advanced / FRAME))
        t_start = sim.time
        energy = sim.kinetic_energy()
        start = time.perf_counter()
        sim.step(FRAME)
        times.append(1e3 * (time.perf_counter() - start))
        gained = max(gained, (sim.kinetic_energy() - energy) / energy if energy > 0.0 else 0.0)
        advanced = sim.time - t_start
        reached += bool(math.isclose(sim.time - t_start, FRAME, rel_tol=1e-9)) and not sim.cap_reached
    return {
        "balls": len(pos),
        "steps": steps,
        "max_ms": max(times),
        "median_ms": float(np.median(times)),
        "peak_mb_growth": _peak_mb() - before,
        "steps_reaching_their_end": reached,
        "clock_s": sim.time,
        "contact_duration_s": contact_duration,
        "energy_gain": gained,
    }


def _warm_up() -> None:
    """Compile the kernels the rows use (small scenes of the same kinds)."""
    for e in (0.0, 0.5):
        for periodic in (False, True):
            measure(row(40, e, periodic), 2)
    measure(pile(60, 0.0), 2, GRAVITY * FRAME)
    for e in (0.9, 1.0):
        for periodic in (False, True):
            granular(50, e, periodic, 2)


def run(quick: bool = False) -> dict:
    """Every row (smaller scenes with ``quick``)."""
    _warm_up()
    n_row, n_pile, side, n_gas, gas_steps = (1000, 100, 6, 50, 60) if quick else (10_000, 400, 12, 200, 600)
    rows = {}
    # every dense flow twice: as the engine's docs state it, then under the TC model
    # (contact_duration, see TC_PILE and TC_GAS); the struck rows once, as stated
    for tag, tc_pile, tc_gas in (("", 0.0, 0.0), (" TC", TC_PILE, TC_GAS)):
        rows[f"pile e=0{tag}"] = measure(pile(n_pile, 0.0), 60, GRAVITY * FRAME, tc_pile)
        rows[f"pile e=0.5{tag}"] = measure(pile(n_pile, 0.5), 60, GRAVITY * FRAME, tc_pile)
        for e in (0.0, 0.5):
            rows[f"heap e={e:g}{tag}"] = measure(pile(n_pile, e, hexagonal=True), 60, GRAVITY * FRAME, tc_pile)
        for periodic in (False, True):
            where = "cell" if periodic else "box"
            if not tag:
                for e in (0.0, 0.5):
                    rows[f"row e={e:g} {where}"] = measure(row(n_row, e, periodic), 10)
            for e in (0.3, 0.0):
                rows[f"cluster e={e:g} {where}{tag}"] = measure(cluster(side, e, periodic), 60, 0.0, tc_pile)
            rows[f"cooling e=0 {where}{tag}"] = measure(cooling(n_gas, 0.5, periodic), gas_steps, 0.0, tc_gas)
    return rows


def render_granular(rows: dict) -> str:
    """A markdown table of the granular gas beside the elastic one."""
    lines = [
        "| gas | events (e = 0.9) | us per event, e = 0.9 | us per event, e = 1 | ratio |",
        "|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        lines.append(
            f"| {name} | {r['events_inelastic']} | {r['us_per_event_inelastic']:.2f} | "
            f"{r['us_per_event_elastic']:.2f} | {r['ratio']:.2f} |"
        )
    return "\n".join(lines)


def render(rows: dict) -> str:
    """A markdown table of the rows, with the targets."""
    lines = [
        "| scene | balls | t_c (s) | steps | slowest step (ms) | median step (ms) | peak memory growth (MB) "
        "| steps reaching their end | most energy a step gained |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        tc = f"{r['contact_duration_s']:g}" if r["contact_duration_s"] else "-"
        lines.append(
            f"| {name} | {r['balls']} | {tc} | {r['steps']} | {r['max_ms']:.1f} | {r['median_ms']:.2f} | "
            f"{r['peak_mb_growth']:.1f} | {r['steps_reaching_their_end']} of {r['steps']} | {r['energy_gain']:.1e} |"
        )
    lines.append("")
    lines.append(
        f"Targets: a row step within {ROW_MS:g} ms; a pile step within {PILE_MS:g} ms and {PILE_MB:g} MB; "
        "every step reaching its end. The square piles are frictionless columns, an unstable equilibrium "
        "that round-off tips over within ten frames or so: they collapse into heaps, whose landings reach "
        "the event cap (see this module's docstring). Rows marked TC run under the TC model (Luding & McNamara "
        "1998: a collision within t_c of either ball's previous one is elastic; `contact_duration`); the "
        "energy column is the most kinetic energy a step's collisions added, as a fraction of what it started with."
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.networks", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="smaller scenes, fewer steps")
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument("--markdown", help="write the table as a page here (docs/bench/networks.md)")
    args = parser.parse_args(argv)
    started = time.perf_counter()
    rows = run(args.quick)
    gases = granular_rows(args.quick)
    how = (
        f"`python -m collision_env.bench.networks{' --quick' if args.quick else ''}` on {machine()}, "
        f"{timestamp()}, {time.perf_counter() - started:.0f} s; wall-clock milliseconds per 1/60 s step "
        "through `Simulator.step`, the kernels compiled beforehand."
    )
    granular_how = (
        "A granular gas (e = 0.9) beside the same gas elastic, alternating in the same run: "
        "`disk_gas(n, 0.3)` stepped in 1/60 s frames through `Simulator.step`, CPU microseconds per event."
    )
    write_outputs(
        how + "\n\n" + render(rows) + "\n\n" + granular_how + "\n\n" + render_granular(gases),
        {"networks": rows, "granular": gases},
        json_path=args.json,
        markdown=args.markdown,
        title="# Contact networks at e < 1",
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
