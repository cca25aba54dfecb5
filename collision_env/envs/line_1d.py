"""PhET Explore 1D: three balls on a line; nudge the leftmost; end-wall impacts inside time windows."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class Line1DEnv(CollisionTargetEnv):
    """
    ## Description

    Three balls of random mass (0.5-2 kg, radii by PhET's density rule) on PhET's 1D track (x in
    [-2, 2] m, y = 0), elastic (e = 1). The agent nudges only ball 0, the leftmost. Two targets
    are impacts on an end wall (left or right, at random) by any ball, each inside its own 2 s time
    window; the right wall can only be reached by passing momentum down the line.
    `CollisionEnv/Line1D-v0`; the generic env with `preset="line_1d"`.

    ## Action Space

    `Box(-1, 1, (1,), float32)`: the velocity change ax * 0.1 m/s of ball 0 for this 0.05 s step.
    Out-of-range values are clipped; NaN raises `ValueError`. A nudge cannot push ball 0 above
    1.5 m/s (or above its current speed, if that is higher).

    ## Observation Space

    `Box(-1, 1, (40,), float32)`; for ball i = 0, 1, 2 (left to right at the start):

    | Index        | Observation                                                         |
    |--------------|---------------------------------------------------------------------|
    | 6i + 0       | position x / 2 m                                                    |
    | 6i + 1       | 0 (y)                                                               |
    | 6i + 2       | velocity vx / 3 m/s                                                 |
    | 6i + 3       | 0 (vy)                                                              |
    | 6i + 4       | mass / 3 kg                                                         |
    | 6i + 5       | 1 (every ball's impacts score)                                      |
    | 18 + 10s + 0, 1 | target s = 0, 1: wall point (-1 or 1, 0)                            |
    | 18 + 10s + 2    | 1 (the whole end wall)                                              |
    | 18 + 10s + 3..6 | wall one-hot (left, right, bottom, top)                             |
    | 18 + 10s + 7    | status: 1 pending, 0 hit, -1 failed (its window closed)             |
    | 18 + 10s + 8, 9 | (window open - t) / 10 s, (window close - t) / 10 s                 |
    | 38           | fraction of the 200 control steps left                              |
    | 39           | fraction of the 2 targets not yet hit                               |

    ## Rewards

    +1 per target hit (a wall impact on the target's wall with its exact time inside the
    target's window), +1 more when both are hit, -0.02 per m/s of requested nudge. No shaping.

    ## Starting State

    Balls in index order from left to right at random non-overlapping places, each moving at a
    random speed in [0, 0.5] m/s either way; targets on random end walls with 2 s windows opening at
    sorted random times in [1, 8] s.

    ## Episode End

    Terminates with `info["is_success"] = True` when both targets are hit, or with
    `is_success = False` as soon as a window closes before its target was hit; truncates after
    200 steps (10 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `n_balls=5`, `mode="naive"`); `render_mode`; `trails`.
    """

    task = Task(
        env_id="CollisionEnv/Line1D-v0",
        preset="line_1d",
        config=dict(
            dimension=1,
            elasticity=1.0,
            n_balls=3,
            mass_range=(0.5, 2.0),
            radius="mass",
            speed_range=(0.0, 0.5),
            others_speed_range=(0.0, 0.5),
            controlled=(0,),
            n_targets=2,
            sequential=False,
            window=2.0,
            scorers="any",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.0,
            action_cost=0.02,
            shaping=0.0,
            max_dv=0.1,
            max_speed=1.5,
        ),
        bench_scene="explore_1d (3 balls)",
    )


Line1DVectorEnv = register_task(Line1DEnv)
