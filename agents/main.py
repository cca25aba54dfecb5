"""The README's main job: train PPO on the default env, evaluate it, record a GIF.

    python -m agents.main                       # CollisionEnv/OneBallTarget-v0, shipped hyperparameters
    python -m agents.main --env CollisionEnv/Billiards-v0 --seed 1

Trains with ``agents.train_ppo`` (native batched env, exact engine mode), evaluates the policy over
100 deterministic episodes in exact mode beside the random and scripted baselines
(``agents.evaluate``), records one evaluation episode as a GIF, plots the learning curve (success
rate and return against env steps, ``agents.curve``) and prints where everything went.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from agents.config import CONFIG_FILE, MODEL_FILE, add_progress_flags, as_int, run_cli, wants_progress
from agents.curve import CURVE_FILE
from agents.evaluate import evaluate, markdown, record
from agents.train_ppo import train


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m agents.main", description=__doc__.split("\n\n")[0])
    p.add_argument("--env", default="CollisionEnv/OneBallTarget-v0")
    p.add_argument("--timesteps", type=float, help="default: the hyperparameter entry's n_timesteps")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--episodes", type=int, default=100, help="evaluation episodes (default %(default)s)")
    p.add_argument("--output", default="runs")
    add_progress_flags(p)
    return p


def main(argv: list[str] | None = None) -> Path:
    args = build_parser().parse_args(argv)
    episodes = as_int("episodes", args.episodes)  # checked before training, not after it
    run_dir = train(
        args.env, timesteps=args.timesteps, seed=args.seed, output=args.output, progress=wants_progress(args.progress)
    )
    print(f"evaluating over {episodes} episodes in exact mode, beside the random and scripted baselines ...")
    results = evaluate(run_dir, episodes=episodes, mode="exact", progress=args.progress)
    (run_dir / "eval-exact.json").write_text(json.dumps(results, indent=1))
    print()
    print(markdown(results))
    print()
    gif = record(run_dir, run_dir / "episodes.gif", episodes=1, mode="exact", progress=args.progress)
    print(f"model:       {run_dir / MODEL_FILE}")
    print(f"config:      {run_dir / CONFIG_FILE}")
    print(f"evaluation:  {run_dir / 'eval-exact.json'}")
    print(f"GIF:         {gif}")
    if (run_dir / CURVE_FILE).is_file():
        print(f"curve:       {run_dir / CURVE_FILE}")
    print(f"TensorBoard: tensorboard --logdir {run_dir / 'tb'}")
    return run_dir


if __name__ == "__main__":
    run_cli(main, prog="agents.main", extras=("train", "render"))
