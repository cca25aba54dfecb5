"""The exact engine against the fastest public event-driven code, per collision, up to a million disks.

Run it as::

    python -m collision_env.bench.peer                     # N = 1e3 .. 1e6, phi = 0.3 and 0.7
    python -m collision_env.bench.peer --sizes 1000 10000 --rounds 1
    python -m collision_env.bench.peer --json docs/bench/peer.json --markdown docs/bench/peer.md

The peer is a 2D port of Smallenburg's event-driven MD code (EDMD, the fastest of the public codes
compared in Smallenburg, *Eur. Phys. J. E* 45, 22 (2022): neighbour lists, a Paul calendar queue, one
event per particle), built here from its C source with ``make`` when the source is there
(``--peer-source``, by default ``../shared/peers/edmd2d`` beside the checkout; it is not part of
this package). Without it the table has this engine's rows alone.

Both sides simulate the same gas: ``N`` equal disks of diameter 1, mass 1 and ``kT = 1`` in a
square periodic cell at area fraction ``phi``, started on a lattice and melted for ``WARM_TIME``
time units. Then each runs three slices of the same simulated time (chosen for about
:data:`SLICE_COLLISIONS` collisions), timed in CPU seconds of its own thread, and the best slice
gives its CPU time per ball-ball collision (cell crossings and neighbour-list rebuilds are work
each side does for its collisions, so they are in the time, not in the count). This engine runs
through its public API: ``disk_gas(n, phi, periodic=True).simulator()``, stepped in frames of
``1/60`` time units by ``Simulator.step`` (each frame's impacts handed back as ``Impacts``).

Memory is each process's resident set: the peer's peak over its disks, and this engine's peak
while it runs, over the resident set of the same process warmed up before the gas was built
(Python, numpy and the compiled kernels), per disk; the build's own peak (the start state's checks)
is reported apart.

Each configuration runs in a fresh process, the two engines in turn, ``--rounds`` times: the
machine's load falls on both alike, and each figure is the best of its rounds. The ratio is the
peer's time per collision over this engine's (above 1: this engine is faster).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from collision_env.bench.readme import write_outputs

from .machine import machine, timestamp, versions

SIZES = (1_000, 10_000, 100_000, 1_000_000)
PHIS = (0.3, 0.7)
#: Simulated time (units of sigma sqrt(m / kT)) of the melt before timing, and of a frame.
WARM_TIME = 2.0
FRAME = 1.0 / 60.0
#: Collisions per timed slice (three slices per run).
SLICE_COLLISIONS = 900_000
#: The peer's neighbour-list shell and its calendar's time multiplier, as in Smallenburg's runs.
PEER_SHELL = 2.5
PEER_LIST_MULTIPLIER = 16
DEFAULT_PEER_SOURCE = Path(__file__).resolve().parents[3] / "shared" / "peers" / "edmd2d"


def collision_rate(phi: float) -> float:
    """Collisions per disk per unit time of the hard-disk fluid at area fraction ``phi`` (Enskog, with
    Henderson's contact value: ``2 sqrt(pi) n sigma g(sigma)`` at ``kT = m = sigma = 1``), to size
    the slices."""
    density = 4.0 * phi / math.pi
    contact = (1.0 - 7.0 * phi / 16.0) / (1.0 - phi) ** 2
    return 2.0 * math.sqrt(math.pi) * density * contact


def slice_time(n: int, phi: float) -> float:
    """Simulated time of a slice of about :data:`SLICE_COLLISIONS` collisions of ``n`` disks."""
    return SLICE_COLLISIONS / (0.5 * n * collision_rate(phi))


def build_peer(source: Path, into: Path) -> Path | None:
    """The peer's binary, built with ``make`` in a copy of ``source`` under ``into`` (None if
    ``source`` is not there)."""
    if not (source / "Makefile").is_file():
        return None
    work = into / "edmd2d"
    shutil.copytree(source, work)
    subprocess.run(["make", "-s"], cwd=work, check=True, capture_output=True)
    return work / "md2d"


def run_peer(binary: Path, n: int, phi: float) -> dict:
    """One run of the peer: its best slice's CPU microseconds per collision, its collision rate and
    its peak resident set per disk."""
    args = [str(binary), str(n), str(phi), repr(slice_time(n, phi)), str(WARM_TIME), "1e9"]
    args += [str(PEER_SHELL), str(PEER_LIST_MULTIPLIER)]
    with tempfile.TemporaryDirectory() as cwd:  # (it writes snapshots where it runs)
        out = subprocess.run(args, cwd=cwd, check=True, capture_output=True, text=True).stdout
    line = next(line for line in out.splitlines() if line.startswith("RESULT"))
    fields = dict(re.findall(r"(\w+)=([^\s]+)", line))
    return {
        "us_per_collision": float(fields["best_slice_cpu_us_per_coll"]),
        "collision_rate": float(fields["coll_per_particle_per_time"]),
        "bytes_per_disk": float(fields["rss_bytes_per_particle"]),
    }


#: This engine's side of a run, in a fresh process (argv: n, phi, slice time, warm time, frame).
PROBE = r"""
import json, math, sys, time
import numpy as np
from collision_env.engine import Scene, Simulator, disk_gas

def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith(key + ":"))

def reset_peak():
    with open("/proc/self/clear_refs", "w") as f:  # (VmHWM back to the current resident set)
        f.write("5")

n, phi, slice_t, warm_t, frame = int(sys.argv[1]), float(sys.argv[2]), *map(float, sys.argv[3:6])
tiny = disk_gas(64, phi, periodic=True, seed=1).simulator()
tiny.step(1.0)  # (the periodic kernel compiled or loaded: part of the warmed-up baseline)
del tiny
reset_peak()
base = status("VmRSS")
sim = disk_gas(n, phi, periodic=True, seed=1).simulator(max_events=2**62)
built = status("VmHWM")
steps = max(1, round(warm_t / frame))
for _ in range(steps):
    sim.step(frame)
reset_peak()
per_slice = max(1, round(slice_t / frame))
best = math.inf
collisions = 0
for _ in range(3):
    events = sim.stats["events"]
    start = time.thread_time()
    for _ in range(per_slice):
        sim.step(frame)
    cpu = time.thread_time() - start
    done = sim.stats["events"] - events
    collisions += done
    best = min(best, cpu / done)
print(json.dumps({
    "us_per_collision": 1e6 * best,
    "collision_rate": 2.0 * collisions / n / (3 * per_slice * frame),
    "bytes_per_disk": (status("VmHWM") - base) / n,
    "build_bytes_per_disk": (built - base) / n,
}))
"""


def run_ours(n: int, phi: float, root: Path) -> dict:
    """One run of this engine (:data:`PROBE`, in a fresh process started in ``root``)."""
    args = [sys.executable, "-c", PROBE, str(n), str(phi), repr(slice_time(n, phi)), str(WARM_TIME), repr(FRAME)]
    out = subprocess.run(args, cwd=root, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def measure(sizes: tuple[int, ...], phis: tuple[float, ...], rounds: int, peer_source: Path) -> dict:
    """Every (N, phi) configuration, the peer and this engine in turn, ``rounds`` times; per
    configuration the best time per collision of each side over its rounds, its memory and rate."""
    root = Path(__file__).resolve().parents[2]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        peer = build_peer(peer_source, Path(tmp))
        runs: dict[tuple[int, float], dict[str, list[dict]]] = {}
        for _ in range(rounds):
            for n in sizes:
                for phi in phis:
                    got = runs.setdefault((n, phi), {"peer": [], "ours": []})
                    if peer is not None:
                        got["peer"].append(run_peer(peer, n, phi))
                    got["ours"].append(run_ours(n, phi, root))
                    print(f"N = {n:.0e}, phi = {phi}: {_summary(got)}", file=sys.stderr, flush=True)
    for (n, phi), got in runs.items():
        row: dict = {"n": n, "phi": phi}
        for side, results in got.items():
            if results:
                row[side] = {
                    "us_per_collision": min(r["us_per_collision"] for r in results),
                    "rounds": [r["us_per_collision"] for r in results],
                    "collision_rate": results[-1]["collision_rate"],
                    "bytes_per_disk": max(r["bytes_per_disk"] for r in results),
                    **(
                        {"build_bytes_per_disk": max(r["build_bytes_per_disk"] for r in results)}
                        if side == "ours"
                        else {}
                    ),
                }
        if "peer" in row:
            row["speedup"] = row["peer"]["us_per_collision"] / row["ours"]["us_per_collision"]
        rows.append(row)
    return {
        "rows": rows,
        "peer": "EDMD 2D port (Smallenburg 2022)" if rows and "peer" in rows[0] else None,
        "rounds": rounds,
        "frame": FRAME,
        "warm_time": WARM_TIME,
        "machine": machine(),
        "versions": versions(),
        "timestamp": timestamp(),
    }


def _summary(got: dict) -> str:
    parts = [f"{side} {results[-1]['us_per_collision']:.3f} us" for side, results in got.items() if results]
    return ", ".join(parts)


def render_markdown(result: dict) -> str:
    """The comparison table (and how it was measured)."""
    with_peer = result["peer"] is not None
    lines = [
        "| disks | phi | "
        + ("peer, us per collision | " if with_peer else "")
        + "ours, us per collision | "
        + ("ours vs the peer | " if with_peer else "")
        + ("peer, B per disk | " if with_peer else "")
        + "ours, B per disk (run) | ours, B per disk (build) |",
        "|---:|---:|" + ("---:|" * (6 if with_peer else 3)),
    ]
    for row in result["rows"]:
        ours = row["ours"]
        cells = [f"{row['n']:,}", f"{row['phi']:g}"]
        if with_peer:
            cells.append(f"{row['peer']['us_per_collision']:.3f}")
        cells.append(f"{ours['us_per_collision']:.3f}")
        if with_peer:
            cells.append(f"**{row['speedup']:.2f}x**")
            cells.append(f"{row['peer']['bytes_per_disk']:.0f}")
        cells += [f"{ours['bytes_per_disk']:.0f}", f"{ours['build_bytes_per_disk']:.0f}"]
        lines.append("| " + " | ".join(cells) + " |")
    peer = result["peer"] or "no peer (its source was not found)"
    lines += [
        "",
        f"CPU microseconds per ball-ball collision, the best of 3 slices of about {SLICE_COLLISIONS:,} collisions, "
        f"best of {result['rounds']} alternating fresh-process rounds; peer: {peer}; ours: "
        f"`disk_gas(n, phi, periodic=True).simulator()` stepped in frames of 1/60 by `Simulator.step`. "
        "Memory: resident set per disk (the peer's peak; ours while running, over a warmed-up process, and "
        "while building the start state). Measured by `python -m collision_env.bench.peer` on "
        f"{result['machine']}, {result['timestamp']}.",
    ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--phis", type=float, nargs="+", default=list(PHIS))
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--peer-source", type=Path, default=DEFAULT_PEER_SOURCE)
    parser.add_argument("--json", type=Path, help="write the results as JSON")
    parser.add_argument("--markdown", type=Path, help="write the table as Markdown")
    args = parser.parse_args(argv)
    os.environ.setdefault("PYTHONHASHSEED", "0")
    result = measure(tuple(args.sizes), tuple(args.phis), args.rounds, args.peer_source)
    table = render_markdown(result)
    title = "# The exact engine against EDMD"
    write_outputs(table, result, json_path=args.json, markdown=args.markdown, title=title, indent=2)


if __name__ == "__main__":
    main()
