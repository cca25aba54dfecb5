"""Scale benchmark: exact mode on hard-disk gases of 10^2 to 10^5 disks, stepped in 1/60 s frames.

Run it as::

    python -m collision_env.bench.scale                   # N = 1e2, 1e3, 1e4, 1e5 (about a minute)
    python -m collision_env.bench.scale --quick           # N = 1e2, 1e3, 1e4
    python -m collision_env.bench.scale --markdown docs/bench/scale.md

The gas: elastic disks of radius 0.01 m at area fraction 0.3 in a square box, started on a square
lattice with Maxwell-Boltzmann velocities (unit mean square speed). For each size it reports

- the build time of the simulator (its O(N) grid overlap check included) and the peak memory of
  the engine's arrays per disk (numpy allocations, traced with :mod:`tracemalloc`);
- events (ball-ball and ball-wall collisions) per second over frames of 1/60 s, after a warm-up
  that also lets the lattice melt: the fastest of three slices of frames, each at least 0.2 s
  long, timed in rounds that take every size in turn; and the bookkeeping per event: pair
  predictions, grid-cell crossings and stale calendar entries;
- the run's validity: no overlap (checked on a grid, not over all pairs), no ball outside the
  border, the kinetic energy conserved (relative change), and the measured ball-ball collision
  rate per disk over Enskog's prediction ``nu = 2 n sigma g(sigma) sqrt(pi kT / m)`` with
  Henderson's contact value ``g``.

It also times the 50-disk gas of the engine benchmark (r = 0.02 in [-1, 1]^2) as one long step
and in frames: frames stepped from Python cost one call each (about a microsecond of argument
passing before any physics), against one call for the long step; ``BatchSimulator.frames`` runs
the same frames in one call and records each; ``Simulator.step`` in a Python loop is the public
API's cost of the same frames.

The public API's cost per event (:func:`bench_public`): the 10^4-disk gas in frames of 1/60 s
through ``Simulator.step`` and ``Simulator.frames`` (each frame's impacts as an ``Impacts`` over a
copy of the records, no Python object per impact), against the kernel stepping the same frames
(one compiled call per frame, its impacts left in the engine's buffer), the variants taking turns
from the same start state.

Times are wall-clock times on a shared machine: compare the figures of one run with each other
(the cost per event across sizes), not across runs. Compiled kernels are warmed up first, and
their first-call cost is reported on its own.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import tracemalloc
from collections.abc import Callable, Iterable

import numpy as np

from collision_env.bench.readme import write_outputs
from collision_env.engine import BatchSimulator, Scene, Simulator
from collision_env.engine.broadphase import first_overlap
from collision_env.engine.state import RESUME, START_STEP
from collision_env.precompile import precompile

from .machine import cpus, machine, timestamp, versions
from .metrics import enskog_rate

SIZES = (100, 1_000, 10_000, 100_000)
QUICK_SIZES = (100, 1_000, 10_000)
PACKING = 0.3
RADIUS = 0.01
FRAME = 1.0 / 60.0
#: Collisions per disk before timing starts (the lattice melts), and at least this many timed.
WARM_COLLISIONS = 3.0
TIMED_COLLISIONS = 10.0
#: The timed frames come in this many slices, one per round over the sizes, and the fastest slice
#: gives the rate; a slice runs at least this long (s), so that a small gas, whose timed
#: collisions take a millisecond, is not timed on a blip of the machine's load.
SLICES = 3
MIN_SLICE_S = 0.2


def lattice_gas(
    n: int, packing: float = PACKING, radius: float = RADIUS, seed: int = 0
) -> tuple[Scene, np.ndarray, np.ndarray]:
    """``n`` disks on a square lattice in a square box at area fraction ``packing``."""
    side = math.sqrt(n * math.pi * radius**2 / packing)
    per_row = math.ceil(math.sqrt(n))
    coords = (np.arange(per_row) + 0.5) * side / per_row - side / 2
    xx, yy = np.meshgrid(coords, coords)
    positions = np.stack([xx.ravel(), yy.ravel()], axis=1)[:n]
    velocities = np.random.default_rng(seed).normal(size=(n, 2)) / math.sqrt(2.0)
    scene = Scene(bounds=(-side / 2, -side / 2, side / 2, side / 2), elasticity=1.0)
    return scene, positions, velocities


def _energy(sim) -> float:
    return float(sim.kinetic_energy()[0])


class TimedGas:
    """One gas of ``n`` disks: built and warmed up, then timed in slices of frames
    (:meth:`time_slice`, called in rounds that take every size in turn), then checked (:meth:`row`)."""

    def __init__(self, n: int, trace_memory: bool = True) -> None:
        self.n = n
        self.scene, pos, vel = lattice_gas(n)
        if trace_memory:  # (tracing slows Python code: the engine's Python path, ten times)
            tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
        t0 = time.perf_counter()
        self.sim = BatchSimulator(
            self.scene, pos[None], vel[None], np.ones(n), radii=np.full(n, RADIUS), max_events=10**9
        )
        self.build_s = time.perf_counter() - t0
        self.e0 = _energy(self.sim)
        assert self.scene.bounds is not None  # (a box: lattice_gas)
        xmin, ymin, xmax, ymax = self.scene.bounds
        self.area = (xmax - xmin) * (ymax - ymin)
        nu = enskog_rate(n / self.area, 2 * RADIUS, PACKING, self.e0 / n, 1.0)  # 2D: kT = mean kinetic energy
        for _ in range(max(1, math.ceil(WARM_COLLISIONS / nu / FRAME))):
            self.sim.step(FRAME)
        self.peak = tracemalloc.get_traced_memory()[1] - base  # (tracing stops before the timing; 0 without)
        tracemalloc.stop()
        self.slice_frames = max(10, math.ceil(TIMED_COLLISIONS / nu / FRAME / SLICES))
        self.before = self.sim.stats
        self.frames = 0
        self.pairs = 0
        self.best = math.inf  # seconds per event, the fastest slice's

    def time_slice(self, min_seconds: float = MIN_SLICE_S) -> None:
        """Step frames for at least ``min_seconds`` and the slice's share of the timed collisions,
        and keep the cost per event if it is the lowest so far."""
        sim = self.sim
        start = sim.stats["events"]
        frames = 0
        t0 = time.perf_counter()
        while frames < self.slice_frames or time.perf_counter() - t0 < min_seconds:
            self.pairs += int(np.count_nonzero(sim.step(FRAME)["other"] >= 0))
            frames += 1
        elapsed = time.perf_counter() - t0
        self.frames += frames
        self.best = min(self.best, elapsed / max(sim.stats["events"] - start, 1))

    def row(self) -> dict:
        """The figures and the validity checks of the timed frames."""
        n, sim = self.n, self.sim
        after = sim.stats
        events = after["events"] - self.before["events"]
        per_event = {
            key: (after[key] - self.before[key]) / events for key in ("pair_tests", "cell_crossings", "stale_events")
        }
        p = sim.positions[0]
        r = sim.radii[0]
        i, j = first_overlap(p, r, 1e-9)
        assert self.scene.bounds is not None  # (a box: lattice_gas)
        xmin, ymin, xmax, ymax = self.scene.bounds
        slack = 1e-12 * (xmax - xmin)
        outside = int(
            np.count_nonzero(
                (p[:, 0] - r < xmin - slack)
                | (p[:, 0] + r > xmax + slack)
                | (p[:, 1] - r < ymin - slack)
                | (p[:, 1] + r > ymax + slack)
            )
        )
        e1 = _energy(sim)
        rate = 2.0 * self.pairs / (n * self.frames * FRAME)
        nu_end = enskog_rate(n / self.area, 2 * RADIUS, PACKING, e1 / n, 1.0)
        return {
            "n": n,
            "build_s": self.build_s,
            "peak_bytes_per_disk": self.peak / n,
            "frames": self.frames,
            "events": events,
            "events_per_s": 1.0 / self.best,
            "us_per_event": 1e6 * self.best,
            **per_event,
            "overlaps": int(i >= 0),
            "outside": outside,
            "energy_rel_change": abs(e1 - self.e0) / self.e0,
            "rate_per_disk": rate,
            "rate_enskog": nu_end,
            "rate_ratio": rate / nu_end,
        }


def _log_row(row: dict, log) -> None:
    log(
        f"  N = {row['n']:>7,}: {row['events_per_s']:.3g} events/s ({row['us_per_event']:.2f} us/event), "
        f"build {row['build_s']:.3f} s, {row['peak_bytes_per_disk']:.0f} B/disk, rate/Enskog {row['rate_ratio']:.3f}"
    )


def bench_sizes(
    sizes: Iterable[int], log: Callable[[str], None] = print, min_slice_s: float = MIN_SLICE_S
) -> list[dict]:
    """Build and warm up a gas of each size, time them in :data:`SLICES` rounds that take every
    size in turn (so that the machine's load drifts over all sizes alike), and check them."""
    gases = [TimedGas(n) for n in sizes]
    for _ in range(SLICES):
        for gas in gases:
            gas.time_slice(min_slice_s)
    rows = [gas.row() for gas in gases]
    for row in rows:
        _log_row(row, log)
    return rows


def bench_size(n: int, log: Callable[[str], None] = print, min_slice_s: float = MIN_SLICE_S) -> dict:
    """Build, warm up, time and check one gas of ``n`` disks."""
    return bench_sizes([n], log, min_slice_s)[0]


def bench_frames(n: int = 50, horizon: float = 20.0, repeats: int = 5) -> dict:
    """The engine benchmark's 50-disk gas (r = 0.02 in [-1, 1]^2): one long step against frames."""
    from .engine import GAS_HALF, GAS_RADIUS, random_balls

    rng = np.random.default_rng(2024)
    bounds = (-GAS_HALF, -GAS_HALF, GAS_HALF, GAS_HALF)
    pos, vel = random_balls(rng, n, bounds, GAS_RADIUS, gap=1.0001)
    scene = Scene(bounds=bounds)
    n_frames = round(horizon / FRAME)

    def run(how: str) -> float:
        best = math.inf
        for _ in range(repeats):
            sim = BatchSimulator(
                scene, pos[None], vel[None], np.ones(n), radii=np.full(n, GAS_RADIUS), max_events=10**7
            )
            single = Simulator(scene, pos, vel, np.ones(n), radii=np.full(n, GAS_RADIUS))
            t0 = time.perf_counter()
            if how == "step loop":
                for _ in range(n_frames):
                    sim.step(FRAME)
            elif how == "Simulator.step loop":
                for _ in range(n_frames):
                    single.step(FRAME)
                sim = single.batch
            elif how == "frames call":
                sim.frames(FRAME, n_frames)
            elif how == "frames call, given arrays":
                sim.frames(FRAME, n_frames, out=reused)
            else:
                sim.step(horizon)
            best = min(best, time.perf_counter() - t0)
        return sim.stats["events"] / best

    def empty_frame() -> float:
        """The fixed cost of a frame: a step too short for any event, on the warmed-up gas."""
        sim = BatchSimulator(scene, pos[None], vel[None], np.ones(n), radii=np.full(n, GAS_RADIUS))
        sim.step(FRAME)
        best = math.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            for _ in range(n_frames):
                sim.step(1e-12)
            best = min(best, (time.perf_counter() - t0) / n_frames)
        return best

    warm = BatchSimulator(scene, pos[None], vel[None], np.ones(n), radii=np.full(n, GAS_RADIUS))
    reused = warm.frames(FRAME, n_frames)  # (the warm-up, and the arrays the last variant records into)
    one_step, in_frames, public = run("one step"), run("step loop"), run("Simulator.step loop")
    in_one_call, into_given = run("frames call"), run("frames call, given arrays")
    return {
        "n": n,
        "horizon_s": horizon,
        "frames": n_frames,
        "one_step_events_per_s": one_step,
        "frames_events_per_s": in_frames,
        "frames_over_one_step": in_frames / one_step,
        "public_frames_events_per_s": public,
        "public_frames_over_one_step": public / one_step,
        "frames_call_events_per_s": in_one_call,
        "frames_call_over_one_step": in_one_call / one_step,
        "frames_given_events_per_s": into_given,
        "frames_given_over_one_step": into_given / one_step,
        "empty_frame_us": 1e6 * empty_frame(),
    }


def bench_public(n: int = 10_000, frames: int = 60, rounds: int = 3) -> dict:
    """Events per second on the ``n``-disk gas in ``frames`` frames of 1/60 s: through
    ``Simulator.step`` (a Python loop), ``Simulator.frames`` (one call), and the kernel (one compiled
    call per frame, what ``step`` costs before its impacts are handed over), each the fastest of
    ``rounds`` rounds in which the variants take turns from the same melted start state."""
    scene, pos, vel = lattice_gas(n)
    sim = Simulator(scene, pos, vel, np.ones(n), radii=np.full(n, RADIUS))  # (the default event cap)
    nu = enskog_rate(n / _area(scene), 2 * RADIUS, PACKING, sim.kinetic_energy() / n, 1.0)
    sim.frames(FRAME, max(1, math.ceil(WARM_COLLISIONS / nu / FRAME)))
    start = sim.get_state()
    stepper = sim._stepper

    def kernel():
        for _ in range(frames):
            stepper.rewind_impacts()  # (each call's impacts are dropped)
            if stepper._kernel(stepper._pack, FRAME, START_STEP) < 0:
                while stepper._n_imp[2]:  # (a full impact buffer stopped the step: go on, as step does)
                    stepper.rewind_impacts()
                    stepper._kernel(stepper._pack, FRAME, RESUME)
        stepper.rewind_impacts()

    def step():
        for _ in range(frames):
            sim.step(FRAME)

    variants = {"kernel": kernel, "Simulator.step": step, "Simulator.frames": lambda: sim.frames(FRAME, frames)}
    best = dict.fromkeys(variants, 0.0)
    for _ in range(rounds):
        for name, fn in variants.items():
            sim.set_state(start)
            sim.step(FRAME)  # (the calendar predicted afresh after set_state: not timed)
            events = sim.stats["events"]
            t0 = time.perf_counter()
            fn()
            best[name] = max(best[name], (sim.stats["events"] - events) / (time.perf_counter() - t0))
    return {
        "n": n,
        "frames": frames,
        "kernel_events_per_s": best["kernel"],
        "step_events_per_s": best["Simulator.step"],
        "frames_events_per_s": best["Simulator.frames"],
        "step_over_kernel": best["Simulator.step"] / best["kernel"],
        "frames_over_kernel": best["Simulator.frames"] / best["kernel"],
        "capped": bool(sim.cap_reached),
    }


def _area(scene: Scene) -> float:
    assert scene.bounds is not None  # (the gas's box)
    xmin, ymin, xmax, ymax = scene.bounds
    return (xmax - xmin) * (ymax - ymin)


def run(quick: bool = False, log: Callable[[str], None] = print) -> dict:
    t0 = time.perf_counter()
    precompile(envs=False)
    first_call_s = time.perf_counter() - t0
    log(f"kernels ready in {first_call_s:.1f} s (compile or cache load, not timed below)")
    rows = bench_sizes(QUICK_SIZES if quick else SIZES, log)
    frames = bench_frames(repeats=3 if quick else 7)
    log(
        f"  50-disk gas: frames keep {100 * frames['frames_over_one_step']:.0f} % of the one-step event rate "
        f"stepped from Python, {100 * frames['public_frames_over_one_step']:.0f} % through Simulator.step, "
        f"{100 * frames['frames_call_over_one_step']:.0f} % in one frames call, "
        f"{100 * frames['frames_given_over_one_step']:.0f} % recording into given arrays"
    )
    public = bench_public()
    log(
        f"  {public['n']:,}-disk gas: Simulator.step {public['step_events_per_s']:.3g} events/s "
        f"({100 * public['step_over_kernel']:.0f} % of the kernel's {public['kernel_events_per_s']:.3g}), "
        f"Simulator.frames {public['frames_events_per_s']:.3g} ({100 * public['frames_over_kernel']:.0f} %)"
    )
    return {
        "machine": machine(),
        "cpus": cpus(),
        "timestamp": timestamp(),
        "versions": versions(["numpy", "numba"]),
        "first_call_s": first_call_s,
        "min_slice_s": MIN_SLICE_S,
        "sizes": rows,
        "frames": frames,
        "public": public,
        "seconds": time.perf_counter() - t0,
    }


def render_markdown(results: dict) -> str:
    v = results["versions"]
    rows = results["sizes"]
    lines = [
        f"`python -m collision_env.bench.scale` on {results['machine']}, {results['cpus']} CPUs, numpy {v['numpy']}, "
        f"numba {v['numba']}; {results['timestamp']}, {results['seconds']:.0f} s. Kernels warmed up first "
        f"({results['first_call_s']:.1f} s to compile or load them).",
        "",
        f"Elastic hard-disk gas, r = {RADIUS} m, area fraction {PACKING}, square box, frames of 1/60 s. Events "
        f"per second are the fastest of {SLICES} slices of frames (each at least {results['min_slice_s']:g} s and "
        f"{TIMED_COLLISIONS / SLICES:.2g} collisions per disk), timed in rounds that take every size in turn:",
        "",
        "| disks | build (s) | peak memory per disk | events/s | µs per event | ÷ smallest | pair predictions "
        "per event | cell crossings per event | stale entries per event | overlaps / outside | energy change "
        "| collision rate ÷ Enskog |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|",
    ]
    base = rows[0]["us_per_event"]
    for r in rows:
        lines.append(
            f"| {r['n']:,} | {r['build_s']:.3f} | {r['peak_bytes_per_disk']:.0f} B | {r['events_per_s']:.3g} "
            f"| {r['us_per_event']:.2f} | {r['us_per_event'] / base:.2f} | {r['pair_tests']:.1f} "
            f"| {r['cell_crossings']:.2f} | {r['stale_events']:.2f} | {r['overlaps']} / {r['outside']} "
            f"| {r['energy_rel_change']:.1e} | {r['rate_ratio']:.3f} |"
        )
    f = results["frames"]
    p = results["public"]
    lines += [
        "",
        f"The {f['n']}-disk gas of the engine benchmark over {f['horizon_s']:g} s: one step "
        f"{f['one_step_events_per_s']:.3g} events/s; {f['frames']} frames of 1/60 s stepped from Python "
        f"{f['frames_events_per_s']:.3g} events/s ({100 * f['frames_over_one_step']:.0f} % of the one-step rate), "
        f"in one `BatchSimulator.frames` call, which records every frame's positions and velocities, "
        f"{f['frames_call_events_per_s']:.3g} events/s ({100 * f['frames_call_over_one_step']:.0f} %) into new "
        f"arrays and {f['frames_given_events_per_s']:.3g} events/s ({100 * f['frames_given_over_one_step']:.0f} %) "
        f"into arrays it is given (`out=`, reused from an earlier call). A frame holds about one event "
        f"({1e6 / f['one_step_events_per_s']:.2f} µs in the long step); a frame stepped from Python costs "
        f"{f['empty_frame_us']:.2f} µs even without one (the call from Python and a pass over the balls that "
        "brings them to the frame's end); `frames` makes that call once for all its frames, and new arrays "
        "cost the operating system's first touch of each of their pages. The public API, "
        f"`Simulator.step` in a Python loop, keeps {f['public_frames_events_per_s']:.3g} events/s "
        f"({100 * f['public_frames_over_one_step']:.0f} % of the one-step rate).",
        "",
        f"The public API on the {p['n']:,}-disk gas, {p['frames']} frames of 1/60 s from the same start state "
        f"(the fastest of rounds that take turns): `Simulator.step` {p['step_events_per_s']:.3g} events/s "
        f"({100 * p['step_over_kernel']:.0f} % of the kernel's {p['kernel_events_per_s']:.3g} events/s, stepping the "
        f"same frames with its impacts left in its buffer), `Simulator.frames` {p['frames_events_per_s']:.3g} "
        f"events/s ({100 * p['frames_over_kernel']:.0f} %). Each frame's impacts come as an `Impacts` over a copy "
        "of their records: no Python object per impact.",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.scale", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="sizes up to 10^4 only")
    parser.add_argument("--json", help="write the raw figures here")
    parser.add_argument("--markdown", help="write the table here")
    args = parser.parse_args(argv)
    results = run(args.quick)
    text = render_markdown(results)
    write_outputs(text, results, json_path=args.json, markdown=args.markdown, title="# Exact mode at scale")
    return 0


if __name__ == "__main__":
    sys.exit(main())
