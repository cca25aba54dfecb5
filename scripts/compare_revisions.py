"""Run-time of two revisions of the engine, measured alternately on this machine: the ratios.

    python scripts/compare_revisions.py BASE [HEAD] [--rounds 3] [--parts engine envs scale]

Checks out ``BASE`` (and ``HEAD``, default: the working tree) into temporary git worktrees, compiles
each one's kernels, then runs the same probe on each in turn, ``--rounds`` times, each in a fresh
process: the public API's cost on the engine benchmark's scenes (``Simulator.step`` per mode and
ball count, a batch of 1024 scenes, a 50-disk gas in frames), the environments (``gym.make`` and the
native vector env of every id, exact mode) and the scale benchmark's gases (10^2 to 10^5 disks).
Alternating spreads the machine's load over both alike; each figure is the median over the rounds,
and the report gives head / base for each (below 1: head is faster). It only uses what both
revisions offer (the public API and the benchmark functions), so it can compare any two commits.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

PROBE = r"""
import json, sys, time, warnings
import numpy as np
parts = sys.argv[1].split(",")
out = {}

def best(fn, repeats, per):
    times = []
    for _ in range(repeats):
        start = time.perf_counter(); fn(); times.append(time.perf_counter() - start)
    return min(times) / per

if "engine" in parts:
    from collision_env.bench.engine import bench_batch, bench_per_step
    for row in bench_per_step(quick=False)["rows"]:
        for mode, s in row["modes"].items():
            if mode != "pymunk":
                out[f"engine: step, {row['balls']} balls, {mode} (us)"] = s["best"]
    for row in bench_batch(quick=False)["rows"]:
        out[f"engine: batch of 1024, {row['mode']} (us per scene-step)"] = 1e6 / row["batch_scene_steps_per_s"]
    from collision_env.engine import Scene, Simulator
    rng = np.random.default_rng(3)
    n = 50
    side = np.linspace(-0.9, 0.9, 8)
    pos = np.stack(np.meshgrid(side, side), -1).reshape(-1, 2)[:n]
    vel = rng.normal(size=(n, 2))
    sim = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), pos, vel, np.ones(n), np.full(n, 0.02))
    start = sim.get_state()
    sim.frames(1 / 60, 60)
    def frames():
        sim.set_state(start); sim.frames(1 / 60, 600)
    def steps():
        sim.set_state(start)
        for _ in range(600):
            sim.step(1 / 60)
    out["engine: 50-disk gas, 600 frames in one call (ms)"] = 1e3 * best(frames, 7, 1)
    out["engine: 50-disk gas, 600 steps from Python (ms)"] = 1e3 * best(steps, 7, 1)

if "envs" in parts:
    import gymnasium as gym
    import collision_env
    from collision_env.bench.envs import single_env_us, vector_env_steps_per_s
    for env_id in collision_env.ENV_IDS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            env = gym.make(env_id)
            out[f"envs: {env_id} gym.make step (us)"] = single_env_us(env, 1.0)
            venv = gym.make_vec(env_id, num_envs=256, vectorization_mode="vector_entry_point")
            out[f"envs: {env_id} vector env, 256 (us per env-step)"] = 1e6 / vector_env_steps_per_s(venv, 1.0)

if "scale" in parts:
    from collision_env.bench.scale import bench_sizes
    for row in bench_sizes([100, 1000, 10_000, 100_000], log=lambda *a: None):
        out[f"scale: {row['n']} disks (us per event)"] = 1e6 / row["events_per_s"]

print(json.dumps(out))
"""


def _worktree(rev: str, where: Path) -> Path:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(where), rev], check=True,
                   capture_output=True)  # fmt: skip
    return where


def _run(tree: Path, parts: list[str]) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    done = subprocess.run(
        [sys.executable, "-c", PROBE, ",".join(parts)], cwd=tree, env=env, capture_output=True, text=True, check=False
    )
    if done.returncode:
        raise SystemExit(f"probe failed in {tree}:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python scripts/compare_revisions.py", description=__doc__.split("\n")[0])
    parser.add_argument("base", help="the revision to compare against (a commit, branch or tag)")
    parser.add_argument("head", nargs="?", help="the revision measured (default: the working tree)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--parts", nargs="+", default=["engine", "envs", "scale"], choices=["engine", "envs", "scale"])
    parser.add_argument("--json", help="write every round's figures here")
    args = parser.parse_args(argv)
    scratch = Path(tempfile.mkdtemp(prefix="compare-"))
    trees = {"base": _worktree(args.base, scratch / "base")}
    trees["head"] = _worktree(args.head, scratch / "head") if args.head else ROOT
    try:
        for tree in trees.values():  # compile each revision's kernels before anything is timed
            subprocess.run([sys.executable, "-m", "collision_env.precompile"], cwd=tree, check=True,
                           env={**os.environ, "PYTHONPATH": str(tree)}, capture_output=True)  # fmt: skip
        rounds: dict[str, list[dict]] = {name: [] for name in trees}
        for r in range(args.rounds):
            for name, tree in trees.items():
                rounds[name].append(_run(tree, args.parts))
                print(f"round {r + 1}/{args.rounds}: {name} done", file=sys.stderr, flush=True)
    finally:
        for tree in trees.values():
            if tree != ROOT:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)
        shutil.rmtree(scratch, ignore_errors=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rounds, indent=1))
    print(f"| figure | base ({args.base}) | head ({args.head or 'working tree'}) | head / base |")
    print("|---|---:|---:|---:|")
    for key in rounds["base"][0]:
        base = statistics.median(r[key] for r in rounds["base"])
        head = statistics.median(r[key] for r in rounds["head"])
        print(f"| {key} | {base:.4g} | {head:.4g} | {head / base:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
