"""Statistical checks over long runs of an elastic gas, for every mode and peer.

A gas started from equal speeds on a lattice relaxes to the 2D Maxwell-Boltzmann distribution
(speeds follow Rayleigh's law with ``kT = <m v^2 / 2>``), and its balls collide at Enskog's rate
``nu = 2 n sigma g(sigma) sqrt(pi kT / m)`` with Henderson's contact value ``g``. Long runs are
chaotic, so they are checked against these laws, not against a trajectory.

Per gas (the sweep's dilute and dense scenes at 64 balls), runner and control step: run through
an equilibration of 5 collisions per ball, then for a measurement window; pool the speeds of
snapshots three mean collision times apart (so ``N x snapshots`` roughly independent samples) and
compute the KS distance to Rayleigh's law against the 5 % critical distance; count the ball-ball
impacts in the window for the measured rate. Walls and finite size bias the rate a little (the
centres cannot reach the walls, which raises the density the balls see): compare the modes with
each other, and exact mode with the law.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from . import metrics as M
from .engines import EngineRunner
from .peers import make_peer
from .scenes import SCENES
from .sweep import record_run

SNAPSHOT_COLLISIONS = 3.0  # mean collision times between speed snapshots (decorrelation)
STAT_FIELDS = (
    "gas",
    "n",
    "packing",
    "family",
    "dt",
    "tunnel_scale",
    "horizon",
    "snapshots",
    "samples",
    "ks",
    "ks_critical",
    "ks_pass",
    "rate",
    "rate_enskog",
    "rate_ratio",
    "energy_drift",
    "wall_s",
    "note",
)


def _runners():
    out = [EngineRunner("naive"), EngineRunner("posteriori", 1), EngineRunner("posteriori", 8), EngineRunner("exact")]
    peers = (make_peer("pymunk", iterations=10), make_peer("billiards"))
    return out + [peer for peer in peers if not isinstance(peer, str)]


def gas_statistics(quick: bool, log: Callable[[str], None] = print) -> list[dict]:
    rows = []
    per_ball = 30.0 if quick else 100.0
    dts = (0.01, 0.1)
    for name, packing in (("dilute_gas", 0.05), ("dense_gas", 0.5)):
        spec = SCENES[name]
        n = 64
        case = spec.case(n)
        b = case.scene.bounds
        assert b is not None  # (a bounded scene)
        area = (b[2] - b[0]) * (b[3] - b[1])
        r = float(case.radii[0])
        m = float(case.masses[0])
        speed = float(np.hypot(*case.velocities[0]))
        kT0 = 0.5 * m * speed**2
        nu0 = M.enskog_rate(n / area, 2 * r, packing, kT0, m)
        t_eq = 5.0 / nu0
        t_meas = per_ball / nu0
        horizon = t_eq + t_meas
        for dt in dts:
            steps = [dt] * int(math.ceil(horizon / dt))
            total = len(steps) * dt
            every = max(1, int(round(SNAPSHOT_COLLISIONS / nu0 / dt)))
            for runner in _runners():
                base = {
                    "gas": name,
                    "n": n,
                    "packing": packing,
                    "family": runner.family,
                    "dt": dt,
                    "tunnel_scale": speed * dt / runner.substeps / r,
                    "horizon": total,
                }
                t0 = time.perf_counter()
                try:
                    rec = record_run(runner, case, steps)
                except Exception as exc:  # a peer failing is a result
                    rows.append({**base, "note": f"{type(exc).__name__}: {exc}"})
                    continue
                wall = time.perf_counter() - t0
                k_eq = int(math.ceil(t_eq / dt))
                snaps = np.arange(k_eq, len(steps) + 1, every)
                speeds = np.hypot(rec.velocities[snaps, :, 0], rec.velocities[snaps, :, 1])
                ks = M.ks_rayleigh(speeds, case.masses[None, :].repeat(len(snaps), 0))
                crit = M.ks_critical(speeds.size)
                imp = rec.impacts
                window = imp["time"] > rec.times[k_eq]
                pairs = int(np.sum(window & (imp["other"] >= 0)))
                t_window = rec.times[-1] - rec.times[k_eq]
                rate = 2.0 * pairs / (n * t_window)
                ke = M.kinetic_energy(rec.velocities[k_eq:], case.masses)
                kT = float(np.mean(ke)) / n
                predicted = M.enskog_rate(n / area, 2 * r, packing, kT, m)
                rows.append(
                    {
                        **base,
                        "snapshots": len(snaps),
                        "samples": int(speeds.size),
                        "ks": ks,
                        "ks_critical": crit,
                        "ks_pass": bool(ks < crit),
                        "rate": rate,
                        "rate_enskog": predicted,
                        "rate_ratio": rate / predicted,
                        "energy_drift": M.drift(M.kinetic_energy(rec.velocities, case.masses)),
                        "wall_s": wall,
                        "note": "impacts are begin-contact events" if runner.engine == "pymunk" else "",
                    }
                )
            log(f"  statistics {name} dt={dt:g}: {time.perf_counter() - t0:5.1f} s (last runner)")
    return rows


def stats_markdown(rows: list[dict]) -> str:
    lines = [
        "## Long runs: Maxwell-Boltzmann speeds and Enskog collision rate",
        "",
        "64-ball gases from equal speeds on a lattice; after 5 collisions per ball, speeds pooled from snapshots "
        "three mean collision times apart. KS: distance to Rayleigh's law (pass: below the 5 % critical distance for "
        "that many samples). Rate: ball-ball collisions per ball per second over the Enskog prediction with "
        "Henderson's g(σ) at the measured temperature.",
        "",
        "| gas | packing | dt (s) | engine / mode | v·h/r | samples | KS (crit.) | MB | rate (1/s) | Enskog (1/s) "
        "| ratio | energy drift |",
        "|---|---:|---:|---|---:|---:|---:|---|---:|---:|---:|---:|",
    ]
    for r in rows:
        if "ks" not in r or r.get("ks") in (None, ""):
            lines.append(
                f"| {r['gas']} | {r['packing']} | {r['dt']:g} | {r['family']} | | | | | | | | {r.get('note', '')} |"
            )
            continue
        lines.append(
            f"| {r['gas']} | {r['packing']:g} | {r['dt']:g} | {r['family']} | {r['tunnel_scale']:.2g} | {r['samples']} "
            f"| {r['ks']:.3f} ({r['ks_critical']:.3f}) | {'pass' if r['ks_pass'] else '**fail**'} | {r['rate']:.3g} "
            f"| {r['rate_enskog']:.3g} | {r['rate_ratio']:.2f} | {r['energy_drift']:.1e} |"
        )
    lines.append("")
    return "\n".join(lines)
