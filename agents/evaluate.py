"""Evaluate a trained run beside a random and a scripted baseline, all measured in the same run.

    python -m agents.evaluate runs/<run>                      # 100 deterministic episodes, trained mode
    python -m agents.evaluate runs/<run> --mode exact         # evaluate under another engine mode
    python -m agents.evaluate runs/<run> --gif                # also record runs/<run>/episodes.gif
    python -m agents.evaluate runs/<run> --video out.mp4 --record-episodes 3

Every policy plays the same episodes (episode i starts from ``reset(seed=seed + i)``); the trained
policy acts deterministically. The baselines are a **random** policy (uniform actions, seeded per
episode) and a **scripted** policy that aims with the engine's exact prediction
(``collision_env.envs.scripted``; not every task has one). Reported per policy: success rate (with a
95 % Wilson interval), mean return, mean nudge (the requested velocity change summed over the
episode, m/s) and its cost in reward units, mean targets hit and mean episode length. The table is
printed and written as JSON to ``<run>/eval-<mode>[<substeps>].json`` (or ``--json``); an earlier
evaluation's file is never replaced: the default name gets a number (``eval-exact-2.json``), and
an existing ``--json`` path needs ``--overwrite``.

The run folder may come from ``agents.train_ppo`` (stable-baselines3) or ``agents.train_rllib``
(RLlib; its policy is the checkpoint's RLModule, acting deterministically; needs ray).

The scripted baseline predicts with the engine it plays in: under ``--mode naive`` it aims with
naive mode's (wrong) impacts, which is part of what such an evaluation measures.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, cast

import gymnasium as gym
import numpy as np

from agents.config import (
    CONFIG_FILE,
    EVAL_SEED,
    MODEL_FILE,
    VECNORMALIZE_FILE,
    UsageError,
    add_progress_flags,
    as_int,
    check_env_id,
    episode_steps,
    is_run_config,
    load_yaml,
    normalize_settings,
    read_run,
    run_cli,
    track,
)
from agents.train_rllib import ALGORITHM, CHECKPOINT_DIR, quiet_ray_logs
from collision_env.bench.readme import write_outputs
from collision_env.engine import MODES
from collision_env.extras import require

if TYPE_CHECKING:
    from collision_env.envs import CollisionTargetEnv

BASELINES = ("random", "scripted")
SCRIPTED_LABEL = "scripted (aims with the engine's prediction)"

#: A policy factory: called after each reset with (unwrapped env, episode index); returns obs -> action.
PolicyFactory = Callable[[gym.Env, int], Callable[[np.ndarray], np.ndarray]]


def wilson_interval(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a success rate (well behaved at 0 and 1)."""
    if n == 0:
        return (0.0, 1.0)
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return (max(0.0, centre - half), min(1.0, centre + half))


# ------------------------------------------------------------------------------------- policies
def trained_policy(run_dir: str | Path, which: str = "final") -> PolicyFactory:
    """The run's PPO policy (``final`` = model.zip, ``best`` = EvalCallback's best_model.zip), deterministic.

    When the run normalised observations, they pass through the VecNormalize statistics saved with
    that model (``vecnormalize.pkl``, or ``best_vecnormalize.pkl`` for the best model).
    """
    from stable_baselines3 import PPO

    from agents.train_ppo import BEST_VECNORMALIZE_FILE

    run_dir = Path(run_dir)
    run = read_run(run_dir)
    model_path = run_dir / (MODEL_FILE if which == "final" else "best_model.zip")
    if not model_path.is_file():
        raise UsageError(f"{model_path} not found")
    model = PPO.load(model_path, device="cpu")
    obs_rms, clip, eps = None, 0.0, 0.0  # (clip and eps are read only with obs_rms)
    norm = normalize_settings(run["hyperparams"].get("normalize"))
    if norm is not None and norm.get("norm_obs", True):
        stats = run_dir / (VECNORMALIZE_FILE if which == "final" else BEST_VECNORMALIZE_FILE)
        if not stats.is_file():
            raise UsageError(f"{stats} not found: the run normalised observations and needs its statistics")
        import pickle

        with stats.open("rb") as fh:
            vecnorm = pickle.load(fh)  # VecNormalize.save pickles the wrapper without its venv
        obs_rms, clip, eps = vecnorm.obs_rms, vecnorm.clip_obs, vecnorm.epsilon

    def factory(env, episode):
        def act(obs):
            if obs_rms is not None:
                obs = np.clip((obs - obs_rms.mean) / np.sqrt(obs_rms.var + eps), -clip, clip).astype(np.float32)
            return model.predict(obs, deterministic=True)[0]

        return act

    return factory


def rllib_policy(run_dir: str | Path) -> PolicyFactory:
    """The RLlib run's policy (the RLModule in ``<run>/checkpoint``), deterministic."""
    require("distributed", "evaluating an RLlib run", checkout=True)
    from agents.rllib_policy import load_module, module_policy

    quiet_ray_logs()
    return module_policy(load_module(Path(run_dir) / CHECKPOINT_DIR))


def is_rllib_run(run: dict) -> bool:
    return run.get("algorithm") == ALGORITHM


def read_any_run(run_dir: str | Path) -> dict:
    """The resolved config of a train_ppo or train_rllib run folder (UsageError if it is neither)."""
    run_dir = Path(run_dir)
    config = run_dir / CONFIG_FILE
    if config.is_file():
        data = load_yaml(config)
        if is_run_config(data) and is_rllib_run(data):
            if not (run_dir / CHECKPOINT_DIR).is_dir():
                raise UsageError(f"{run_dir} is an RLlib run without its {CHECKPOINT_DIR}/ folder")
            return data
    return read_run(run_dir)


def run_policy(run_dir: str | Path, run: dict, which: str = "final") -> PolicyFactory:
    """The trained policy of a run folder of either trainer (RLlib runs keep only their final policy)."""
    if is_rllib_run(run):
        if which != "final":
            raise UsageError("an RLlib run keeps only its final policy (--model final)")
        return rllib_policy(run_dir)
    require("train", "evaluating a stable-baselines3 run", checkout=True)
    return trained_policy(run_dir, which)


def random_policy(seed: int = 0) -> PolicyFactory:
    """Uniform actions in the action box, from a generator seeded with ``seed + episode``."""

    def factory(env, episode):
        rng = np.random.default_rng(seed + episode)
        space = env.action_space
        return lambda obs: rng.uniform(space.low, space.high).astype(np.float32)

    return factory


def scripted_baseline(env: gym.Env) -> PolicyFactory | None:
    """The task's scripted aiming policy (``collision_env.envs.scripted.scripted_policy``), or None
    if the task of ``env`` has none."""
    from collision_env.envs.scripted import ScriptedPolicy, scripted_policy

    if scripted_policy(env.unwrapped) is None:
        return None

    def factory(env: gym.Env, episode: int) -> ScriptedPolicy:
        policy = scripted_policy(env)
        assert policy is not None  # (the task has one)
        return policy

    return factory


# ---------------------------------------------------------------------------------------- play
def play(
    env: gym.Env,
    factory: PolicyFactory,
    episodes: int,
    seed: int,
    frames: list | None = None,
    desc: str = "episodes",
    progress: bool | None = None,
) -> dict:
    """Play ``episodes`` episodes (episode i from ``reset(seed=seed + i)``); return the summary.

    With ``frames`` (a list) the env must render ``rgb_array``; every frame is appended to it.
    Progress is shown as :func:`agents.config.track` shows it, headed ``desc``.
    """
    cost_per = cast("CollisionTargetEnv", env.unwrapped).config.action_cost
    rows = []
    start = time.perf_counter()
    for i in track(range(episodes), episodes, desc, progress):
        obs, info = env.reset(seed=seed + i)
        act = factory(env.unwrapped, i)
        if frames is not None:
            frames.append(env.render())
        ret, nudge, steps, done = 0.0, 0.0, 0, False
        while not done:
            obs, reward, term, trunc, info = env.step(act(obs))
            ret += float(reward)
            nudge += info["nudge"]
            steps += 1
            done = term or trunc
            if frames is not None:
                frames.append(env.render())
        rows.append((bool(info["is_success"]), ret, nudge, int(info["targets_hit"]), steps))
    success = [r[0] for r in rows]
    lo, hi = wilson_interval(sum(success), len(success))
    mean = lambda k: float(np.mean([r[k] for r in rows]))  # noqa: E731
    return {
        "episodes": episodes,
        "success_rate": float(np.mean(success)),
        "success_ci95": [lo, hi],
        "mean_return": mean(1),
        "mean_nudge": mean(2),
        "mean_nudge_cost": cost_per * mean(2),
        "mean_targets_hit": mean(3),
        "mean_length": mean(4),
        "seconds": round(time.perf_counter() - start, 2),
    }


def make_env(env_id: str, env_kwargs: dict, render_mode: str | None = None) -> gym.Env:
    import collision_env  # noqa: F401

    return gym.make(env_id, max_episode_steps=episode_steps(env_id, env_kwargs), render_mode=render_mode, **env_kwargs)


def eval_kwargs(run: dict, mode: str | None, substeps: int | None) -> dict:
    """The run's env kwargs with the engine mode replaced (another mode starts from substeps = 1)."""
    kwargs = dict(run.get("env_kwargs") or {})
    if mode is not None and mode != kwargs.get("mode", "exact"):
        kwargs["mode"] = mode
        kwargs["substeps"] = 1
    if substeps is not None:
        kwargs["substeps"] = substeps
    return kwargs


def evaluate(
    run_dir: str | Path,
    *,
    episodes: int = 100,
    mode: str | None = None,
    substeps: int | None = None,
    seed: int = EVAL_SEED,
    baselines: tuple = BASELINES,
    model: str = "final",
    progress: bool | None = None,
) -> dict:
    """Evaluate the run (and the baselines) on the same episodes; returns the results dict.

    Each policy shows its progress (a bar in a terminal, else a line each 10 %; ``progress``
    forces the bar on or off)."""
    run = read_any_run(run_dir)
    env_id = check_env_id(run["env_id"])
    episodes = as_int("episodes", episodes)
    seed = as_int("seed", seed, low=0)
    kwargs = eval_kwargs(run, mode, substeps)
    env = make_env(env_id, kwargs)
    policies: dict[str, PolicyFactory | None] = {"ppo": run_policy(run_dir, run, model)}
    if "random" in baselines:
        policies["random"] = random_policy(seed)
    if "scripted" in baselines:
        policies["scripted"] = scripted_baseline(env)
    trained = run.get("env_kwargs") or {}
    results = {
        "env_id": env_id,
        "run": str(run_dir),
        "trainer": "rllib" if is_rllib_run(run) else "sb3",
        "model": model,
        "train_mode": trained.get("mode", "exact"),
        "train_substeps": int(trained.get("substeps", 1)),
        "mode": kwargs.get("mode", "exact"),
        "substeps": int(kwargs.get("substeps", 1)),
        "episodes": episodes,
        "seed": seed,
        "policies": {},
    }
    labels = {"ppo": "PPO", "random": "random", "scripted": "scripted"}
    for name, factory in policies.items():
        if factory is not None:
            desc = f"evaluating {labels.get(name, name)}"
            results["policies"][name] = play(env, factory, episodes, seed, desc=desc, progress=progress)
        else:
            results["policies"][name] = None
    env.close()
    return results


def check_video_path(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise UsageError(f"video: expected a .gif or .mp4 path, got {path}")
    require("render", "recording a video", checkout=True)
    if path.suffix.lower() == ".mp4":
        require("video", "writing MP4 (a .gif needs nothing more)", checkout=True)
    return path


def record(
    run_dir: str | Path,
    path: str | Path,
    *,
    episodes: int = 1,
    mode: str | None = None,
    substeps: int | None = None,
    seed: int = EVAL_SEED,
    model: str = "final",
    progress: bool | None = None,
) -> Path:
    """Record the trained policy's first ``episodes`` evaluation episodes as a GIF or MP4 (by suffix)."""
    import imageio.v2 as imageio

    run = read_any_run(run_dir)
    path = check_video_path(path)
    episodes = as_int("record episodes", episodes)
    env = make_env(check_env_id(run["env_id"]), eval_kwargs(run, mode, substeps), render_mode="rgb_array")
    frames: list = []
    play(env, run_policy(run_dir, run, model), episodes, seed, frames=frames, desc="recording", progress=progress)
    fps = env.unwrapped.metadata["render_fps"]
    env.close()
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".gif":
        imageio.mimsave(path, frames, duration=1000.0 / fps, loop=0)
    else:
        imageio.mimsave(path, frames, fps=fps, macro_block_size=1)
    return path


# ----------------------------------------------------------------------------------------- report
def pct(x: float) -> str:
    return f"{100 * x:.0f} %"


def markdown(results: dict) -> str:
    """The results as a Markdown table, one row per policy."""
    mode = results["mode"] + (f" k={results['substeps']}" if results["substeps"] != 1 else "")
    train = results["train_mode"] + (f" k={results['train_substeps']}" if results["train_substeps"] != 1 else "")
    lines = [
        f"{results['env_id']}: {results['episodes']} episodes (seeds {results['seed']}...), "
        f"evaluated in {mode} mode, trained in {train} mode",
        "",
        "| policy | success (95 % CI) | mean return | mean nudge (m/s) | nudge cost | targets hit | steps |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    trained = "RLlib PPO" if results.get("trainer") == "rllib" else "PPO"
    names = {"ppo": f"{trained} (this run, deterministic)", "random": "random", "scripted": SCRIPTED_LABEL}
    for key, r in results["policies"].items():
        if r is None:
            lines.append(f"| {names.get(key, key)} | n/a | | | | | |")
            continue
        lo, hi = r["success_ci95"]
        lines.append(
            f"| {names.get(key, key)} | {pct(r['success_rate'])} ({pct(lo)}–{pct(hi)}) | "
            f"{r['mean_return']:.3f} | {r['mean_nudge']:.2f} | {r['mean_nudge_cost']:.3f} | "
            f"{r['mean_targets_hit']:.2f} | {r['mean_length']:.0f} |"
        )
    return "\n".join(lines)


def results_path(
    run_dir: str | Path,
    run: dict,
    json_path: str | None,
    mode: str | None,
    substeps: int | None,
    overwrite: bool = False,
) -> Path:
    """Where to write the results, decided before evaluating: never an earlier evaluation's file.

    ``--json PATH`` is used as given (an existing file needs ``overwrite``); the default
    ``<run>/eval-<mode>[<substeps>].json`` becomes ``eval-<mode>-2.json``, ``-3``... when taken.
    """
    if json_path:
        path = Path(json_path)
        if path.exists() and not overwrite:
            raise UsageError(f"{path} exists (pass --overwrite to replace it, or another --json path)")
        return path
    kwargs = eval_kwargs(run, mode, substeps)
    substeps = int(kwargs.get("substeps", 1))
    stem = f"eval-{kwargs.get('mode', 'exact')}{substeps if substeps != 1 else ''}"
    path, n = Path(run_dir) / f"{stem}.json", 1
    while path.exists():
        n += 1
        path = Path(run_dir) / f"{stem}-{n}.json"
    return path


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m agents.evaluate",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("run", help="a run folder written by agents.train_ppo or agents.train_rllib")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--mode", choices=MODES, help="engine mode (default: the run's)")
    p.add_argument("--substeps", type=int, help="sub-steps for naive/posteriori (default 1 with --mode)")
    p.add_argument("--seed", type=int, default=EVAL_SEED, help="episode i starts from seed + i")
    p.add_argument("--model", choices=("final", "best"), default="final")
    p.add_argument("--no-baselines", action="store_true", help="evaluate the trained policy only")
    p.add_argument("--json", help="write the results here (default: <run>/eval-<mode>.json, numbered if taken)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --json file")
    p.add_argument("--gif", nargs="?", const="", metavar="PATH", help="record a GIF (default: <run>/episodes.gif)")
    p.add_argument("--video", metavar="PATH.mp4|PATH.gif", help="record a video (MP4 needs imageio-ffmpeg)")
    p.add_argument("--record-episodes", type=int, default=1, help="episodes to record (default 1)")
    add_progress_flags(p)
    return p


def main(argv: list[str] | None = None) -> dict:
    args = build_parser().parse_args(argv)
    videos = ([args.video] if args.video else []) + (
        [args.gif or Path(args.run) / "episodes.gif"] if args.gif is not None else []
    )
    for video in videos:  # fail on a bad path before the evaluation, not after it
        check_video_path(video)
    as_int("record episodes", args.record_episodes)
    run = read_any_run(args.run)
    out = results_path(args.run, run, args.json, args.mode, args.substeps, args.overwrite)
    results = evaluate(
        args.run,
        episodes=args.episodes,
        mode=args.mode,
        substeps=args.substeps,
        seed=args.seed,
        baselines=() if args.no_baselines else BASELINES,
        model=args.model,
        progress=args.progress,
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    write_outputs(markdown(results), results, json_path=out)
    print(f"results: {out}")
    for video in videos:
        path = record(
            args.run,
            video,
            episodes=args.record_episodes,
            mode=args.mode,
            substeps=args.substeps,
            seed=args.seed,
            model=args.model,
            progress=args.progress,
        )
        print(f"video:   {path}")
    return results


if __name__ == "__main__":
    run_cli(main, prog="agents.evaluate")
