"""The speed/accuracy sweep: mode x control step dt x number of balls x scene, peers in the same run.

For every scene and ball count:

1. **Reference.** Exact mode runs the scene's horizon (in 400 steps, with a high event cap). For a
   chaotic scene the horizon is then cut where the balls have had 5 collisions each on average
   (between two impacts), so that a final-state comparison still measures the mode and not the
   chaos (a hard-disk gas is chaotic, Dellago, Hoover & Posch, Phys. Rev. E 65, 056216, 2002: round-off
   grows by orders of magnitude per collision per ball); exact mode is rerun over that horizon and its impacts, final
   state and peak speed are the reference.
2. **Runs.** Every runner (this engine's modes, the installed peers) at every control step
   ``dt <= horizon``: one recorded run (impacts and the state after every step) for the accuracy
   metrics, and timed runs of the same schedule without recording (the best is kept; numba is
   warmed up first, construction is outside the timing) for the cost.

Each run gives one CSV row (:data:`FIELDS`): the cost (wall time per simulated second, and per
step), the impact matching against the reference (matched, missed, spurious, tunnelled pairs,
impact time and point errors), escapes and wall/ball overlaps at step ends, energy and momentum
(drift, and error against the reference at the horizon), the final-state error in radii and in
speed, and the tunnelling scale ``v_peak * (dt / substeps) / r_min`` (``v_peak`` is the reference's
largest ball speed).
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from . import metrics as M
from .engines import EngineRunner, engine_runners, peer_runners
from .peers import Runner, collect
from .scenes import SCENES, Case, SceneSpec, pi_collisions

DT_QUICK = (0.001, 0.01, 0.1)
DT_FULL = (0.001, 0.003, 0.01, 0.03, 0.1)
REFERENCE_STEPS = 400
COLLISIONS_PER_BALL = 5.0

FIELDS = (
    "scene",
    "n",
    "elasticity",
    "engine",
    "family",
    "mode",
    "substeps",
    "iterations",
    "dt",
    "h",
    "horizon",
    "steps",
    "status",
    "wall_s",
    "wall_per_sim_s",
    "us_per_step",
    "ref_impacts",
    "impacts",
    "matched",
    "missed",
    "spurious",
    "tunnelled_pairs",
    "t_err_median",
    "t_err_max",
    "p_err_median",
    "p_err_max",
    "escapes",
    "wall_penetration",
    "ball_overlap",
    "energy_drift",
    "energy_err",
    "momentum_drift",
    "momentum_err",
    "pos_err",
    "vel_err",
    "v_peak",
    "r_min",
    "tunnel_scale",
    "speed_dt_over_r",
    "cap_reached",
    "note",
)


def schedule(horizon: float, dt: float) -> list[float]:
    """Steps of ``dt`` covering ``horizon``, the last one shortened to land on it exactly."""
    k = int(math.floor(horizon / dt * (1 + 1e-12)))
    steps = [dt] * k
    rest = horizon - k * dt
    if rest > 1e-9 * horizon:
        steps.append(rest)
    return steps or [horizon]


@dataclass
class Record:
    """A recorded run: impacts, and the state before the first step and after every step."""

    impacts: np.ndarray
    times: np.ndarray  # (S+1,)
    positions: np.ndarray  # (S+1, N, 2)
    velocities: np.ndarray  # (S+1, N, 2)
    flags: dict


def record_run(runner: Runner, case: Case, steps: Sequence[float]) -> Record:
    runner.start(case)
    n = len(case.masses)
    s = len(steps)
    pos = np.empty((s + 1, n, 2))
    vel = np.empty((s + 1, n, 2))
    times = np.empty(s + 1)
    pos[0], vel[0] = runner.state()
    times[0] = 0.0
    chunks = []
    t = 0.0
    for k, dt in enumerate(steps, 1):
        chunks.append(runner.step(dt, True))
        t += dt
        times[k] = t
        pos[k], vel[k] = runner.state()
    return Record(collect(chunks), times, pos, vel, runner.flags())


def timed_run(runner: Runner, case: Case, steps: Sequence[float], min_time: float, max_repeats: int) -> float:
    """Best wall time (s) of the stepping loop over ``steps`` (construction excluded)."""
    best = math.inf
    total = 0.0
    repeats = 0
    while repeats < max_repeats and (repeats == 0 or total < min_time):
        runner.start(case)
        t0 = time.perf_counter()
        for dt in steps:
            runner.step(dt, False)
        w = time.perf_counter() - t0
        best = min(best, w)
        total += w
        repeats += 1
    return best


@dataclass
class Reference:
    case: Case
    horizon: float
    record: Record
    v_peak: float
    window_slack: float  # 5 % of a ball's mean time between impacts


def reference(spec: SceneSpec, n: int) -> Reference:
    case = spec.case(n)
    exact = EngineRunner("exact", max_events=10_000_000)
    horizon = spec.horizon
    if spec.chaotic:
        first = record_run(exact, case, [horizon / REFERENCE_STEPS] * REFERENCE_STEPS)
        short = M.short_horizon(first.impacts, n, COLLISIONS_PER_BALL, default=horizon)
        horizon = horizon if short is None else short
    rec = record_run(exact, case, [horizon / REFERENCE_STEPS] * REFERENCE_STEPS)
    v_peak = float(np.sqrt((rec.velocities**2).sum(-1)).max())
    per_ball = M.collisions_per_ball(rec.impacts, n).mean() if len(rec.impacts) else 0.0
    slack = 0.05 * horizon / max(per_ball, 1.0)
    return Reference(case, horizon, rec, v_peak, slack)


def evaluate(ref: Reference, rec: Record, dt: float, substeps: int) -> dict:
    """Accuracy metrics of a recorded run against the reference (one CSV row's worth)."""
    case = ref.case
    h = dt / substeps
    window = 2.0 * h + ref.window_slack
    match = M.match_impacts(rec.impacts, ref.record.impacts, window)
    out = match.summary()
    scene = case.scene
    masses = case.masses
    ke = M.kinetic_energy(rec.velocities, masses)
    p = M.momentum(rec.velocities, masses)
    ke0 = float(ke[0])
    p_scale = float((masses * np.hypot(*case.velocities.T)).sum())
    ref_ke = float(M.kinetic_energy(ref.record.velocities[-1], masses))
    ref_p = M.momentum(ref.record.velocities[-1], masses)
    v_scale = float(np.hypot(*case.velocities.T).max())
    pos_err, vel_err = M.final_state_error(
        rec.positions[-1], rec.velocities[-1], ref.record.positions[-1], ref.record.velocities[-1], case.radii, v_scale
    )
    finite = bool(np.isfinite(rec.positions).all() and np.isfinite(rec.velocities).all())
    out.update(
        escapes=int(M.escapes(rec.positions, scene.bounds, scene.dimension).sum()),
        wall_penetration=M.wall_penetration(rec.positions, case.radii, scene.bounds, scene.dimension),
        ball_overlap=M.max_overlap(rec.positions, case.radii) if scene.ball_collisions else 0.0,
        energy_drift=M.drift(ke) if scene.elasticity == 1.0 else math.nan,
        energy_err=abs(float(ke[-1]) - ref_ke) / ke0 if ke0 > 0 else math.nan,
        momentum_drift=M.drift(p, scale=p_scale) if scene.bounds is None else math.nan,
        momentum_err=float(np.hypot(*(p[-1] - ref_p))) / p_scale if p_scale > 0 else math.nan,
        pos_err=pos_err if finite else math.inf,
        vel_err=vel_err if finite else math.inf,
        impacts=len(rec.impacts),
        ref_impacts=len(ref.record.impacts),
        cap_reached=bool(rec.flags.get("cap_reached", False)),
    )
    return out


def _note(spec: SceneSpec, rec: Record) -> str:
    if spec.name == "pi_billiard":
        return f"{len(rec.impacts)} collisions (exact count {pi_collisions(spec.kwargs['digits'])})"
    return ""


def sweep_case(
    spec: SceneSpec,
    n: int,
    runners: list[Runner],
    dts: Iterable[float],
    *,
    min_time: float,
    max_repeats: int,
    log: Callable[[str], None] = print,
) -> list[dict]:
    """All runners at all control steps on one scene and ball count; one row per run."""
    ref = reference(spec, n)
    case = ref.case
    r_min = float(case.radii.min())
    rows = []
    for dt in dts:
        if dt > ref.horizon:
            continue
        steps = schedule(ref.horizon, dt)
        for runner in runners:
            base = {
                "scene": spec.name,
                "n": n,
                "elasticity": case.scene.elasticity,
                "engine": runner.engine,
                "family": runner.family,
                "mode": getattr(runner, "mode", None) or "",
                "substeps": runner.substeps,
                "iterations": runner.iterations if runner.iterations is not None else "",
                "dt": dt,
                "h": dt / runner.substeps,
                "horizon": ref.horizon,
                "steps": len(steps),
                "v_peak": ref.v_peak,
                "r_min": r_min,
                "tunnel_scale": ref.v_peak * dt / runner.substeps / r_min,
                "speed_dt_over_r": ref.v_peak * dt / r_min,
            }
            why = runner.unsupported(case)
            if why:
                rows.append({**base, "status": "unsupported", "note": why})
                continue
            try:
                rec = record_run(runner, case, steps)
                wall = timed_run(runner, case, steps, min_time, max_repeats)
            except Exception as exc:  # a peer blowing up is a result, not a crash of the study
                rows.append({**base, "status": "error", "note": f"{type(exc).__name__}: {exc}"})
                log(traceback.format_exc())
                continue
            row = {
                **base,
                "status": "ok",
                "wall_s": wall,
                "wall_per_sim_s": wall / ref.horizon,
                "us_per_step": wall / len(steps) * 1e6,
                "note": _note(spec, rec),
            }
            row.update(evaluate(ref, rec, dt, runner.substeps))
            rows.append(row)
    return rows


#: The cost-only runs at large ball counts: one control step, a short horizon, and the peers
#: whose cost per event grows with N (billiards predicts all pairs) left out past this size.
COST_DT = 0.01
COST_HORIZON = 0.5
ALL_PAIRS_PEER_MAX_BALLS = 256


def cost_case(spec: SceneSpec, n: int, runners: list[Runner], *, min_time: float, max_repeats: int) -> list[dict]:
    """Every runner's cost per step on one scene at a large ball count (status "timed": no accuracy)."""
    case = spec.case(n)
    steps = schedule(COST_HORIZON, COST_DT)
    rows = []
    for runner in runners:
        base = {
            "scene": spec.name,
            "n": n,
            "elasticity": case.scene.elasticity,
            "engine": runner.engine,
            "family": runner.family,
            "mode": getattr(runner, "mode", None) or "",
            "substeps": runner.substeps,
            "iterations": runner.iterations if runner.iterations is not None else "",
            "dt": COST_DT,
            "h": COST_DT / runner.substeps,
            "horizon": COST_HORIZON,
            "steps": len(steps),
        }
        why = runner.unsupported(case)
        if why is None and runner.engine == "billiards" and n > ALL_PAIRS_PEER_MAX_BALLS:
            why = f"predicts all pairs at every event: minutes per run past {ALL_PAIRS_PEER_MAX_BALLS} balls"
        if why:
            rows.append({**base, "status": "unsupported", "note": why})
            continue
        wall = timed_run(runner, case, steps, min_time, max_repeats)
        rows.append(
            {
                **base,
                "status": "timed",
                "wall_s": wall,
                "wall_per_sim_s": wall / COST_HORIZON,
                "us_per_step": wall / len(steps) * 1e6,
                "note": "cost only",
            }
        )
    return rows


def warm_up() -> None:
    """Compile or load every kernel before anything is timed."""
    for spec_name, n in (("explore_2d", 2), ("inelastic", 2), ("newtons_cradle", 4), ("inelastic_pileup", 4)):
        case = SCENES[spec_name].case(n)
        for runner in engine_runners(full=True):
            runner.start(case)
            for _ in range(3):
                runner.step(0.01)
            runner.step(1.0)


def cases(quick: bool, scenes: Iterable[str] | None = None) -> list[tuple[SceneSpec, int]]:
    """``(spec, n)`` pairs the sweep covers."""
    out = []
    for name, spec in SCENES.items():
        if scenes and name not in scenes:
            continue
        counts = spec.quick_counts or spec.counts if quick else spec.counts
        out += [(spec, n) for n in counts]
    return out


def run_sweep(
    quick: bool, scenes: Iterable[str] | None = None, peers: bool = True, log: Callable[[str], None] = print
) -> tuple[list[dict], dict]:
    """The whole sweep; returns the rows and what was left out (missing peers)."""
    warm_up()
    runners = engine_runners(full=not quick)
    missing: dict[str, str] = {}
    if peers:
        extra, missing = peer_runners(full=not quick)
        runners = runners + extra
    else:
        missing = {"pymunk": "left out (--no-peers)", "billiards": "left out (--no-peers)"}
    dts = DT_QUICK if quick else DT_FULL
    min_time, max_repeats = (0.01, 2) if quick else (0.05, 5)
    rows = []
    for spec, n in cases(quick, scenes):
        t0 = time.perf_counter()
        rows += sweep_case(spec, n, runners, dts, min_time=min_time, max_repeats=max_repeats, log=log)
        log(f"  {spec.name:17s} n={n:3d}  {time.perf_counter() - t0:6.1f} s")
    if not quick:
        for name, spec in SCENES.items():
            if scenes and name not in scenes:
                continue
            for n in spec.cost_counts:
                t0 = time.perf_counter()
                rows += cost_case(spec, n, runners, min_time=min_time, max_repeats=max_repeats)
                log(f"  {spec.name:17s} n={n:5d}  {time.perf_counter() - t0:6.1f} s (cost only)")
    return rows, missing
