"""Engine benchmark: what each mode costs, against peers measured in the same run.

Run it as::

    python -m collision_env.bench.engine            # full run, a few minutes
    python -m collision_env.bench.engine --quick    # about 10 s (plus ~30 s of numba compile when cold)
    python -m collision_env.bench.engine --json bench.json --markdown bench.md
    python -m collision_env.bench.engine --render bench.json --markdown bench.md   # tables only

It is not a test: it measures and prints. Four parts, each printed as a Markdown table:

1. **Gas**: exact mode's events per second against the ``billiards`` package (PyPI 0.5.0, pure
   Python, event-driven) on a 50-disk elastic gas (r = 0.02 in [-1, 1]^2, T = 20 s; the full run
   adds a 200-disk gas over 5 s), both from the same initial state,
   once as a single long step and once in frames of 1/60 s (ours alternating, with the frames'
   share of the long step's event rate: what the calls from Python cost). The same section checks the
   trajectories: over a short horizon (about 3 collisions per ball, before chaos amplifies
   round-off) the collision sequences must be the same, and it reports the largest position
   difference; at the full horizon (tens of collisions per ball) it only reports how far the two
   chaotic runs drifted apart.
2. **Per step**: microseconds per ``Simulator.step(1/60)`` for each mode (naive, posteriori with
   1 and 4 substeps, exact) at 1, 2, 4, 16 and 64 balls in the default play area, with pymunk
   (a C engine, impulse solver, no time of impact) stepping the same balls as a peer.
3. **Calls**: nanoseconds per ``Simulator.step`` and ``BatchSimulator.step`` with nothing to do
   (one ball at rest in a box), against an empty compiled kernel called through numba's dispatch
   with a stepping kernel's arguments and an empty Python function, alternating.
4. **Batch**: scene-steps per second of one :class:`BatchSimulator` of 1024 scenes of 4 balls
   against a Python loop over 1024 single :class:`Simulator` objects holding the same scenes
   (and a check that both end in the same state).

The peers are the benchmark package's adapters (:mod:`collision_env.bench.peers`), the same
set-ups the study measures.

The machine is shared and noisy, so every figure is the best (and the median) of several
repeats, and the figures that matter are the ratios, measured in the same run. Numba compile
time is excluded: every kernel is warmed up before it is timed. ``--json`` writes the raw
figures; ``--markdown`` writes the tables (from this run, or from ``--render``'s JSON file).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from collision_env.bench.readme import write_outputs
from collision_env.engine import BACKEND, PLAY_AREA_2D, BatchSimulator, Scene, Simulator
from collision_env.precompile import precompile

from .machine import cpus, machine, timestamp, versions
from .metrics import as_impacts
from .peers import make_peer
from .scenes import Case
from .timing import alternating, repeat, summary

GAS_CASES = ((50, 20.0),)  # (disks, horizon in s); the full run adds GAS_CASES_FULL
GAS_CASES_FULL = ((200, 5.0),)  # billiards manages about 1 k events/s here: seconds per run
GAS_RADIUS = 0.02
GAS_HALF = 1.0
GAS_CHECK_COLLISIONS_PER_BALL = 3
FRAME = 1.0 / 60.0
STEP_BALLS = (1, 2, 4, 16, 64)
STEP_RADIUS = 0.05  # 64 balls of r = 0.05 fill 6 % of the 4 m x 2 m play area
MODE_CONFIGS = (("naive", 1), ("posteriori", 1), ("posteriori", 4), ("exact", 1))
BATCH_SCENES = 1024
PARTS = ("gas", "per_step", "calls", "batch")  #: the benchmark's parts, in the order it runs them
BATCH_BALLS = 4


# ---------------------------------------------------------------------------------------- helpers
def random_balls(
    rng: np.random.Generator,
    n: int,
    bounds: tuple[float, float, float, float],
    radius: float,
    speed: float = 1.0,
    gap: float = 1.05,
) -> tuple[np.ndarray, np.ndarray]:
    """``n`` non-overlapping balls of ``radius`` inside ``bounds``, random directions at ``speed``.

    Returns ``(positions (n, 2), velocities (n, 2))``; centres are at least ``gap * 2 radius`` apart.
    """
    xmin, ymin, xmax, ymax = bounds
    pos = np.empty((n, 2))
    for i in range(n):
        for _ in range(100_000):
            p = rng.uniform((xmin + radius, ymin + radius), (xmax - radius, ymax - radius))
            if i == 0 or np.min(np.hypot(*(pos[:i] - p).T)) > 2.0 * radius * gap:
                pos[i] = p
                break
        else:  # pragma: no cover - only for absurd densities
            raise RuntimeError(f"could not place {n} balls of radius {radius} in {bounds}")
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    vel = speed * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    return pos, vel


# ---------------------------------------------------------------------------------------- 1. gas
def _pairs(impacts) -> list[tuple[int, int]]:
    """Impacts as comparable keys: ``(i, j)`` (i < j) for a ball pair, ``(i, -1)`` for a wall."""
    rows = as_impacts(impacts)
    return [
        (int(b), -1) if o < 0 else (int(min(b, o)), int(max(b, o)))
        for b, o in zip(rows["ball"], rows["other"], strict=True)
    ]


def bench_gas(quick: bool, n: int = 50, horizon: float = 20.0) -> dict:
    """Exact mode against billiards on an ``n``-disk gas over ``horizon`` s; see the module doc."""
    peer = make_peer("billiards")
    if isinstance(peer, str):
        return {"skipped": f"billiards is {peer}: pip install 'collision_env[peers]'"}
    rng = np.random.default_rng(2024)
    pos, vel = random_balls(rng, n, (-GAS_HALF, -GAS_HALF, GAS_HALF, GAS_HALF), GAS_RADIUS, gap=1.0001)
    masses = np.ones(n)
    radii = np.full(n, GAS_RADIUS)
    scene = Scene(bounds=(-GAS_HALF, -GAS_HALF, GAS_HALF, GAS_HALF), elasticity=1.0)
    case = Case(scene, pos, vel, masses, radii)
    n_frames = round(horizon / FRAME)
    peer_repeats, our_repeats = (3, 10) if quick else (7, 50)
    if n > 100:  # billiards takes seconds per run here
        peer_repeats = 3

    # the peer's set-up (its O(N^2) first prediction) is outside the timing, as ours is
    def peer_one_step():
        peer.step(horizon, record=False)

    def peer_frames():
        for _ in range(n_frames):
            peer.step(FRAME, record=False)

    ours: dict[str, Any] = {}

    def new_sim(max_events=10_000):
        ours["sim"] = Simulator(scene, pos, vel, masses, radii=radii, mode="exact", max_events=max_events)

    def our_one_step():
        ours["impacts"] = ours["sim"].step(horizon)

    def our_frames():
        for _ in range(n_frames):
            ours["sim"].step(FRAME)

    new_sim(10**7)
    our_one_step()  # warm-up
    peer_t = repeat(peer_one_step, peer_repeats, lambda: peer.start(case))
    peer_events = peer.impact_count
    peer_frame_t = repeat(peer_frames, max(1, peer_repeats - 1), lambda: peer.start(case))
    peer_frame_events = peer.impact_count
    # (ours alternating, so that the frames' share of the long step's rate holds on a busy machine)
    runs = {"long": our_one_step, "frames": our_frames}
    timed = alternating(runs, our_repeats, {"long": lambda: new_sim(10**7), "frames": new_sim})
    our_t, our_frame_t = timed["long"], timed["frames"]
    our_frame_events = ours["sim"].stats["events"]  # (the frames ran last)
    new_sim(10**7)
    our_one_step()
    our_events = ours["sim"].stats["events"]
    long_ours = _pairs(ours["impacts"])
    long_our_positions = ours["sim"].positions

    # the peer's impacts over the full horizon, recorded (untimed)
    peer.start(case)
    events = peer.step(horizon)
    assert events is not None  # (recorded)
    long_peer = _pairs(events)
    long_peer_positions = peer.state()[0]

    # trajectory check over a short horizon (before chaos): same sequence, position difference
    involved = np.cumsum([1 if pair[1] < 0 else 2 for pair in long_peer])
    k = int(np.searchsorted(involved, GAS_CHECK_COLLISIONS_PER_BALL * n))
    t_check = 0.5 * (events["time"][k] + events["time"][k + 1])
    peer.start(case)
    peer_short = peer.step(t_check)
    assert peer_short is not None  # (recorded)
    sim = Simulator(scene, pos, vel, masses, radii=radii, mode="exact")
    our_short = sim.step(t_check)
    same_sequence = _pairs(our_short) == _pairs(peer_short)
    time_diff = (
        max(abs(a.time - b) for a, b in zip(our_short, peer_short["time"], strict=True)) if same_sequence else None
    )
    peer_pos, peer_vel = peer.state()
    check = {
        "horizon_s": t_check,
        "collisions_per_ball": float(involved[k - 1] / n) if k > 0 else 0.0,
        "events": len(peer_short),
        "same_sequence": same_sequence,
        "max_time_diff_s": time_diff,
        "max_position_diff_m": float(np.abs(sim.positions - peer_pos).max()),
        "max_velocity_diff_m_s": float(np.abs(sim.velocities - peer_vel).max()),
    }
    # at the full horizon the runs are chaotic: report the drift, and how long the sequences agree
    agree = (i for i, (a, b) in enumerate(zip(long_ours, long_peer, strict=False)) if a != b)
    prefix = next(agree, min(len(long_ours), len(long_peer)))
    full = {
        "horizon_s": horizon,
        "collisions_per_ball": float(involved[-1] / n),
        "events_ours": our_events,
        "events_billiards": peer_events,
        "sequences_agree_for_events": prefix,
        "max_position_diff_m": float(np.abs(long_our_positions - long_peer_positions).max()),
    }
    rows = []
    for label, ours_t, ours_n, peer_t_, peer_n in (
        (f"one step of {horizon:g} s", our_t, our_events, peer_t, peer_events),
        (f"{n_frames} frames of 1/60 s", our_frame_t, our_frame_events, peer_frame_t, peer_frame_events),
    ):
        o = summary(ours_t)
        p = summary(peer_t_)
        rows.append(
            {
                "how": label,
                "ours_events": int(ours_n),
                "ours_s": o,
                "ours_events_per_s": ours_n / o["best"],
                "billiards_events": int(peer_n),
                "billiards_s": p,
                "billiards_events_per_s": peer_n / p["best"],
                "speedup_best": (ours_n / o["best"]) / (peer_n / p["best"]),
                "speedup_median": (ours_n / o["median"]) / (peer_n / p["median"]),
            }
        )
    long_rate, frames_rate = (summary(t) for t in (our_t, our_frame_t))
    return {
        "n": n,
        "radius": GAS_RADIUS,
        "box": [-GAS_HALF, GAS_HALF],
        "rows": rows,
        # the frames' event rate over the long step's: what the calls from Python cost
        "frames_share_best": (our_frame_events / frames_rate["best"]) / (our_events / long_rate["best"]),
        "frames_share_median": (our_frame_events / frames_rate["median"]) / (our_events / long_rate["median"]),
        "check": check,
        "full_horizon": full,
    }


# ---------------------------------------------------------------------------------------- 2. per step
def bench_per_step(quick: bool) -> dict:
    """Microseconds per ``step(1/60)`` of each mode at each ball count (and pymunk's)."""
    pymunk = make_peer("pymunk")
    steps, repeats = (200, 5) if quick else (1000, 25)
    rng = np.random.default_rng(7)
    rows = []
    for n in STEP_BALLS:
        pos, vel = random_balls(rng, n, PLAY_AREA_2D, STEP_RADIUS)
        masses = rng.uniform(0.5, 2.0, n)
        radii = np.full(n, STEP_RADIUS)
        row: dict[str, Any] = {"balls": n, "steps": steps, "modes": {}}
        for mode, k in MODE_CONFIGS:
            sim = Simulator(Scene(), pos, vel, masses, radii=radii, mode=mode, substeps=k)
            start = sim.get_state()
            for _ in range(3):
                sim.step(FRAME)
            impacts = [0]

            def reset(sim=sim, start=start, impacts=impacts):
                sim.set_state(start)
                impacts[0] = 0

            def run(sim=sim, impacts=impacts):
                for _ in range(steps):
                    impacts[0] += len(sim.step(FRAME))

            before = sim.stats["events"]
            s = summary(repeat(run, repeats, reset), per=steps / 1e6)
            s["impacts_per_step"] = impacts[0] / steps
            s["events_per_step"] = (sim.stats["events"] - before) / (steps * repeats)
            row["modes"][f"{mode}/{k}"] = s
        if not isinstance(pymunk, str):
            pymunk.start(Case(Scene(), pos, vel, masses, radii))
            for _ in range(3):
                pymunk.step(FRAME, record=False)

            def run_pymunk():
                for _ in range(steps):
                    pymunk.step(FRAME, record=False)

            row["modes"]["pymunk"] = summary(repeat(run_pymunk, repeats), per=steps / 1e6)
        rows.append(row)
    return {"dt": FRAME, "radius": STEP_RADIUS, "bounds": list(PLAY_AREA_2D), "rows": rows}


# ---------------------------------------------------------------------------------------- 3. batch
def bench_batch(quick: bool) -> dict:
    """Scene-steps per second: one BatchSimulator of 1024 scenes against a loop of Simulators."""
    steps, repeats = (10, 3) if quick else (30, 15)
    rng = np.random.default_rng(11)
    b, n = BATCH_SCENES, BATCH_BALLS
    pos = np.empty((b, n, 2))
    vel = np.empty((b, n, 2))
    for s in range(b):
        pos[s], vel[s] = random_balls(rng, n, PLAY_AREA_2D, STEP_RADIUS)
    masses = rng.uniform(0.5, 2.0, (b, n))
    radii = np.full((b, n), STEP_RADIUS)
    rows = []
    for mode, k in MODE_CONFIGS:
        batch = BatchSimulator(Scene(), pos, vel, masses, radii, mode=mode, substeps=k)
        singles = [
            Simulator(Scene(), pos[s], vel[s], masses[s], radii=radii[s], mode=mode, substeps=k) for s in range(b)
        ]
        batch_start = batch.get_state()
        single_starts = [sim.get_state() for sim in singles]

        def reset_batch(batch=batch, batch_start=batch_start):
            batch.set_state(batch_start)

        def reset_loop(singles=singles, single_starts=single_starts):
            for sim, st in zip(singles, single_starts, strict=True):
                sim.set_state(st)

        def run_batch(batch=batch):
            for _ in range(steps):
                batch.step(FRAME)

        def run_loop(singles=singles):
            for _ in range(steps):
                for sim in singles:
                    sim.step(FRAME)

        run_batch()  # warm-up
        run_loop()
        tb = summary(repeat(run_batch, repeats, reset_batch), per=steps * b)
        tl = summary(repeat(run_loop, repeats, reset_loop), per=steps * b)
        diff = max(float(np.abs(batch.positions[s] - singles[s].positions).max()) for s in range(b))
        rows.append(
            {
                "mode": f"{mode}/{k}",
                "batch_scene_steps_per_s": 1.0 / tb["best"],
                "loop_scene_steps_per_s": 1.0 / tl["best"],
                "speedup_best": tl["best"] / tb["best"],
                "speedup_median": tl["median"] / tb["median"],
                "batch_s_per_scene_step": tb,
                "loop_s_per_scene_step": tl,
                "max_position_diff_m": diff,
            }
        )
    return {"scenes": b, "balls": n, "steps": steps, "dt": FRAME, "rows": rows}


# ---------------------------------------------------------------------------------------- 4. calls
def _nothing(h, dt, start):
    """What the empty kernel of :func:`bench_calls` does (nothing), with a stepping kernel's arguments."""
    return 0


def _call_loop(fn: Callable, args: tuple, calls: int) -> Callable[[], None]:
    """``calls`` calls of ``fn(*args)`` (of one or three arguments), unpacked outside the loop."""
    if len(args) == 1:
        (a,) = args

        def loop() -> None:
            for _ in range(calls):
                fn(a)

    else:
        a, b, c = args

        def loop() -> None:
            for _ in range(calls):
                fn(a, b, c)

    return loop


def bench_calls(quick: bool) -> dict:
    """Nanoseconds per call from Python with nothing to do: ``Simulator.step(1/60)`` and
    ``BatchSimulator.step(1/60)`` of one ball at rest in a box, beside an empty compiled kernel
    called through numba's dispatch with the arguments a stepping kernel takes (an int64 array, a
    float, an int) and an empty Python function of the same arguments. They alternate in every
    repeat, so that a busy machine slows them alike."""
    calls, repeats = (20_000, 5) if quick else (100_000, 15)
    sim = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), [[0.0, 0.0]], [[0.0, 0.0]], [1.0], [0.1])
    pack = np.zeros(4, dtype=np.int64)
    subjects: dict[str, tuple[Callable, tuple]] = {
        "Simulator.step": (sim.step, (FRAME,)),
        "BatchSimulator.step": (sim.batch.step, (FRAME,)),
    }
    if BACKEND == "numba":
        import numba

        subjects["empty kernel, numba's dispatch"] = (numba.jit(nopython=True)(_nothing), (pack, FRAME, 1))
    subjects["empty Python function"] = (_nothing, (pack, FRAME, 1))
    for fn, args in subjects.values():  # warm-up (the empty kernel compiles)
        _call_loop(fn, args, 100)()
    timed = alternating({name: _call_loop(fn, args, calls) for name, (fn, args) in subjects.items()}, repeats)
    rows = {name: summary(t, per=calls / 1e9) for name, t in timed.items()}
    return {"calls": calls, "dt": FRAME, "rows": rows}


# ---------------------------------------------------------------------------------------- tables
def _fmt(x, digits=3):
    if x is None:
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "**no**"
    if isinstance(x, (int, np.integer)):
        return f"{x:,}"
    if x == 0:
        return "0"
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return f"{x:.2e}"
    return f"{x:,.{digits}g}" if abs(x) < 1000 else f"{x:,.0f}"


def render_markdown(results: dict) -> str:
    """The benchmark's figures as Markdown (a string), from :func:`run`'s dict or its JSON."""
    meta = results["meta"]
    v = meta["versions"]
    lines = [
        "## Engine benchmark",
        "",
        f"`python -m collision_env.bench.engine{' --quick' if meta['quick'] else ''}` on {meta['machine']}, "
        f"{meta['cpus']} CPUs, Python {v['python']}, numpy {v['numpy']}, numba {v['numba']}, "
        f"billiards {v['billiards']}, pymunk {v['pymunk']}; engine backend `{v['backend']}`; "
        f"{meta['date']}, {meta['duration_s']:.0f} s. Times are the best of several repeats (median in "
        "brackets); compare the ratios, which are measured in the same run.",
        "",
    ]
    for gas in results.get("gas", []):
        if "skipped" in gas:
            lines += ["### Exact mode against billiards", "", f"Skipped: {gas['skipped']}", ""]
            continue
        lines += [
            f"### Exact mode against billiards: {gas['n']}-disk elastic gas (r = {gas['radius']}, "
            f"box [-1, 1]², T = {gas['full_horizon']['horizon_s']:g} s)",
            "",
            "| run | our events | our time (s) | our events/s | billiards events | billiards time (s) "
            "| billiards events/s | speed-up |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for r in gas["rows"]:
            lines.append(
                f"| {r['how']} | {_fmt(r['ours_events'])} "
                f"| {_fmt(r['ours_s']['best'])} ({_fmt(r['ours_s']['median'])}) "
                f"| {_fmt(r['ours_events_per_s'])} | {_fmt(r['billiards_events'])} "
                f"| {_fmt(r['billiards_s']['best'])} ({_fmt(r['billiards_s']['median'])}) "
                f"| {_fmt(r['billiards_events_per_s'])} "
                f"| **{r['speedup_best']:.0f}×** ({r['speedup_median']:.0f}×) |"
            )
        c = gas["check"]
        f = gas["full_horizon"]
        if "frames_share_best" in gas:
            lines += [
                "",
                f"In frames of 1/60 s, one `Simulator.step` call from Python each, exact mode keeps "
                f"**{gas['frames_share_best']:.2f}** ({gas['frames_share_median']:.2f}) of its event rate in one long "
                "step (the two runs alternate).",
            ]
        lines += [
            "",
            f"Same trajectories: over the first {c['horizon_s']:.3g} s ({c['collisions_per_ball']:.1f} "
            f"collisions per ball, {c['events']} events) the collision sequences are identical: "
            f"{_fmt(c['same_sequence'])}; largest difference in impact time {_fmt(c['max_time_diff_s'])} s, "
            f"in position {_fmt(c['max_position_diff_m'])} m, in velocity {_fmt(c['max_velocity_diff_m_s'])} m/s. "
            f"Over the full {f['horizon_s']:g} s ({f['collisions_per_ball']:.0f} collisions per ball) the gas is "
            f"chaotic: the sequences agree for the first {f['sequences_agree_for_events']} of {f['events_ours']} "
            f"(ours) / {f['events_billiards']} (billiards) events and the positions end up to "
            f"{_fmt(f['max_position_diff_m'])} m apart.",
            "",
        ]
    ps = results.get("per_step")
    if ps:
        names = list(ps["rows"][0]["modes"])
        lines += [
            f"### Cost per step (µs per `Simulator.step(1/60)`), play area {tuple(ps['bounds'])}, r = {ps['radius']}, "
            "~1 m/s",
            "",
            "| balls | " + " | ".join(names) + " | exact ÷ naive | exact ÷ pymunk | impacts per step (exact) |",
            "|---:|" + "---:|" * (len(names) + 3),
        ]
        for r in ps["rows"]:
            m = r["modes"]
            cells = [f"{m[k]['best']:.2f} ({m[k]['median']:.2f})" for k in names]
            ratio = m["exact/1"]["best"] / m["naive/1"]["best"]
            peer = f"{m['exact/1']['best'] / m['pymunk']['best']:.1f}" if "pymunk" in m else "n/a"
            lines.append(
                f"| {r['balls']} | " + " | ".join(cells) + f" | {ratio:.2f} | {peer} | "
                f"{m['exact/1']['impacts_per_step']:.3f} |"
            )
        lines += [
            "",
            "Mode names are `mode/substeps`; pymunk is the C peer (impulse solver, no time of impact) "
            "stepping the same balls, set up as the study's `pymunk it=10`.",
            "",
        ]
    calls = results.get("calls")
    if calls:
        anchor = calls["rows"].get("empty kernel, numba's dispatch")
        lines += [
            "### The cost of a call: nothing to do (one ball at rest in a box, dt = 1/60 s)",
            "",
            "| call | ns per call | × an empty kernel's call |",
            "|---|---:|---:|",
        ]
        for name, r in calls["rows"].items():
            ratio = f"{r['best'] / anchor['best']:.2f}" if anchor else "n/a"
            lines.append(f"| `{name}` | {r['best']:.0f} ({r['median']:.0f}) | {ratio} |")
        lines += [
            "",
            "The empty kernel takes a stepping kernel's arguments (an int64 array, a float, an int) through "
            "numba's dispatch, which types each of them at every call; the simulators call their kernel's "
            "compiled version directly. Each figure is the best of alternating repeats of "
            f"{_fmt(calls['calls'])} calls.",
            "",
        ]
    bt = results.get("batch")
    if bt:
        lines += [
            f"### Batched stepping: {bt['scenes']} scenes of {bt['balls']} balls, dt = 1/60 s",
            "",
            "| mode | batch scene-steps/s | loop of Simulators, scene-steps/s | speed-up "
            "| same end state (max Δx, m) |",
            "|---|---:|---:|---:|---:|",
        ]
        for r in bt["rows"]:
            lines.append(
                f"| {r['mode']} | {_fmt(r['batch_scene_steps_per_s'])} | {_fmt(r['loop_scene_steps_per_s'])} "
                f"| **{r['speedup_best']:.0f}×** ({r['speedup_median']:.0f}×) | {_fmt(r['max_position_diff_m'])} |"
            )
        lines.append("")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------- main
def run(
    quick: bool = False,
    parts: Iterable[str] = PARTS,
    log: Callable[[str], None] = print,
) -> dict:
    """Run the benchmark; returns the raw figures as a JSON-ready dict."""
    t0 = time.perf_counter()
    log("warming up the kernels (numba compile or cache load) ...")
    precompile(envs=False)
    results: dict[str, Any] = {}
    if "gas" in parts:
        results["gas"] = []
        for n, horizon in GAS_CASES + (() if quick else GAS_CASES_FULL):
            log(f"gas of {n} disks: exact mode against billiards ...")
            results["gas"].append(bench_gas(quick, n, horizon))
    if "per_step" in parts:
        log("per-step cost of each mode ...")
        results["per_step"] = bench_per_step(quick)
    if "calls" in parts:
        log("the cost of a call with nothing to do ...")
        results["calls"] = bench_calls(quick)
    if "batch" in parts:
        log("batch of 1024 against a loop ...")
        results["batch"] = bench_batch(quick)
    results["meta"] = {
        "quick": quick,
        "versions": versions(["numba", "billiards", "pymunk"]),
        "machine": machine(),
        "cpus": cpus(),
        "date": timestamp(),
        "duration_s": time.perf_counter() - t0,
    }
    return results


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating,)):
        return float(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.engine", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats: about 30 s instead of a few minutes")
    parser.add_argument("--json", metavar="PATH", help="write the raw figures to PATH")
    parser.add_argument("--markdown", metavar="PATH", help="write the tables to PATH")
    parser.add_argument("--render", metavar="JSON", help="do not measure: render the tables of a --json file")
    parser.add_argument("--only", choices=PARTS, action="append", help="run only this part (repeatable)")
    args = parser.parse_args(argv)

    if args.render:
        with open(args.render) as fh:
            results = json.load(fh)
    else:
        results = _jsonable(
            run(
                quick=args.quick,
                parts=tuple(args.only or PARTS),
                log=lambda msg: print(msg, file=sys.stderr, flush=True),
            )
        )
    measured = None if args.render else results  # (a rendered file is not written again)
    write_outputs(render_markdown(results), measured, json_path=args.json, markdown=args.markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
