"""Render a PNG frame and a short GIF of every preset into docs/img/ (for the README's env table).

    python scripts/render_presets.py [--out docs/img] [--seed 0] [--ppm 100] [--fps 10] [--ids ID ...]
    python scripts/render_presets.py --readme README.md     # also rewrite the README's env table

The README's table (its ``envs:table`` block) gives each id's task, the first line of its env
module's docstring, beside its GIF (``docs_hooks.readme_env_table``).

Each preset runs one episode under its scripted policy (``collision_env.envs.scripted``, which aims
with the engine's exact prediction), with trails on. The PNG is the frame just after the first
target hit (the flash marks the exact contact point); the GIF is the whole episode, every other
control step.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import cast

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import gymnasium as gym
import imageio.v3 as iio
import numpy as np

import collision_env  # noqa: F401
from collision_env.bench.readme import write_block
from collision_env.envs import PRESET_IDS, CollisionTargetEnv
from collision_env.envs.rendering import Renderer
from collision_env.envs.scripted import scripted_policy


def render_episode(env_id: str, seed: int, ppm: float, every: int):
    env = cast(CollisionTargetEnv, gym.make(env_id).unwrapped)
    env.reset(seed=seed)
    core = env.core
    renderer = Renderer(env.config, trails=True, ppm=ppm)
    policy = scripted_policy(env)
    assert policy is not None  # (every preset has one)
    frames = [renderer.draw(core, 0)]
    still, hit_at = None, None
    for t in range(env.config.n_steps):
        _, _, term, trunc, info = env.step(policy())
        renderer.record(core, 0, info["impacts"].array)
        frame = renderer.draw(core, 0)
        if hit_at is None and info["targets_hit"] > 0:
            hit_at = t
        if hit_at is not None and still is None and t >= hit_at + 2:
            still = frame
        if t % every == 0 or term or trunc:
            frames.append(frame)
        if term or trunc:
            frames += [frame] * 10  # hold the last frame
            break
    if still is None:  # the episode ended at its first hit: its last frame shows the flash
        still = frame if hit_at is not None else frames[min(len(frames) - 1, 20)]
    return still, frames, info


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="docs/img")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--ppm", type=float, default=100.0, help="pixels per metre")
    parser.add_argument("--fps", type=int, default=10, help="GIF frame rate (the episode runs at 20 steps/s)")
    parser.add_argument("--ids", nargs="+", default=list(PRESET_IDS.values()), help="presets (default: all)")
    parser.add_argument("--readme", metavar="PATH", help="rewrite the env table between PATH's envs:table markers")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    every = max(1, round(20 / args.fps))
    for env_id in args.ids:
        still, frames, info = render_episode(env_id, args.seed, args.ppm, every)
        name = env_id.split("/")[1].removesuffix("-v0").lower()
        iio.imwrite(out / f"{name}.png", still)
        iio.imwrite(out / f"{name}.gif", np.stack(frames), duration=int(1000 / args.fps), loop=0)
        print(
            f"{env_id:36s} {len(frames):4d} frames, targets hit {info['targets_hit']}, "
            f"success {info['is_success']} -> {out / name}.png/.gif"
        )
    if args.readme:
        from docs_hooks import readme_env_table  # (scripts/ is this script's folder)

        write_block(args.readme, "envs:table", readme_env_table())


if __name__ == "__main__":
    main()
