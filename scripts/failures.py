"""Where trained policies fail beside the scripted policy, episode by episode (the study's 100 episodes).

    python scripts/failures.py CollisionEnv/Billiards-v0 runs/study/billiards-exact-s0 runs/study/billiards-exact-s1

For each run: its success, the evaluation episodes it fails where the scripted policy succeeds (and
the reverse), how its failures end (targets hit; a time window closed, or the time ran out), the
median control step of its first hit and the gap to its second, and its mean nudge per episode
beside the scripted policy's.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from agents.config import read_run
from agents.evaluate import EVAL_SEED, make_env, scripted_baseline, trained_policy


def episodes(env, factory, n: int) -> list:
    out = []
    for i in range(n):
        obs, _ = env.reset(seed=EVAL_SEED + i)
        act = factory(env.unwrapped, i)
        hits: list[int] = []
        t, nudge, done = 0, 0.0, False
        while not done:
            obs, _, term, trunc, info = env.step(act(obs))
            t += 1
            nudge += info["nudge"]
            if info["targets_hit"] > len(hits):
                hits.append(t)
            done = term or trunc
        out.append({"success": bool(info["is_success"]), "hits": hits, "nudge": nudge, "terminated": bool(term)})
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("env_id")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--episodes", type=int, default=100)
    args = parser.parse_args(argv)
    env = make_env(args.env_id, {})
    scripted = episodes(env, scripted_baseline(env), args.episodes)
    s_ok = np.array([e["success"] for e in scripted])
    print(f"{args.env_id}: scripted {s_ok.mean():.0%}, mean nudge {np.mean([e['nudge'] for e in scripted]):.1f} m/s")
    for run in args.runs:
        ppo = episodes(make_env(args.env_id, read_run(run)["env_kwargs"]), trained_policy(run), args.episodes)
        p_ok = np.array([e["success"] for e in ppo])
        ends = Counter(
            f"{len(e['hits'])} hit(s), {'window closed' if e['terminated'] else 'time ran out'}"
            for e in ppo
            if not e["success"]
        )
        first = [e["hits"][0] for e in ppo if e["hits"]]
        gap = [e["hits"][1] - e["hits"][0] for e in ppo if len(e["hits"]) > 1]
        print(
            f"{run}: {p_ok.mean():.0%}; fails where scripted succeeds {int((~p_ok & s_ok).sum())}, "
            f"succeeds where scripted fails {int((p_ok & ~s_ok).sum())}, both fail {int((~p_ok & ~s_ok).sum())}; "
            f"failures: {dict(ends)}; first hit at step {np.median(first) if first else 'n/a'}, second "
            f"{np.median(gap) if gap else 'n/a'} steps later (medians); mean nudge "
            f"{np.mean([e['nudge'] for e in ppo]):.1f} m/s"
        )


if __name__ == "__main__":
    main()
