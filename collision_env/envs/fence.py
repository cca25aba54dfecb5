"""Fence: one shot of a small, fast ball through the opening in a fence of heavy pegs; cheap modes let it through."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class FenceEnv(CollisionTargetEnv):
    """
    ## Description

    A small, fast ball (ball 0, 1 kg, radius 0.05 m) and a fence of 9 pegs: balls of the same
    radius but 50 kg, at rest in a column down the middle of PhET's 4 m x 2 m play area (x = 0) from
    the top wall, 0.16 m apart (a 0.06 m gap, which the ball does not pass), leaving an opening of
    0.59 m above the bottom wall (the lowest peg's centre at y = -0.36 m); elastic (e = 1). The
    agent has one shot: its first action sets the ball's velocity, up to 5 m/s; the target is a
    0.3 m segment of the right wall, and the shot scores if the ball's first impact on the right
    wall lands on it. The straight line from the ball to the target mostly crosses the fence; a
    shot off the bottom wall through the opening reaches the target from most starts.

    Committing the whole outcome to one action makes this the preset where training in a cheap
    engine mode costs: at 5 m/s a 0.1 s control step moves the ball 0.5 m, more than the 0.12 to 0.2 m
    across which it overlaps a peg as it crosses the fence, so naive and posteriori steps with one
    sub-step, which look for contacts only at a step's end, mostly let it through the fence
    (tunnelling), and a naive step reports each wall impact where the step ends (it bounces the ball
    late). A policy trained there can shoot straight at the target through the pegs, and loses those
    shots when the impacts are exact (`tests/envs/test_fence.py`; `agents.study` measures what
    training cheaply costs). `CollisionEnv/Fence-v0`; the generic env with `preset="fence"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: the shot, ball 0's velocity (ux, uy) * 5 m/s (scaled back to 5 m/s
    if longer), given at once in the episode's first step. The actions of later steps are ignored
    (the ball flies on). Out-of-range values are clipped; NaN raises `ValueError`.

    ## Observation Space

    `Box(-1, 1, (18,), float32)` (only the ball is shown: the fence's place is fixed):

    | Index  | Observation                                                |
    |--------|------------------------------------------------------------|
    | 0, 1   | ball position x / 2 m, y / 1 m                             |
    | 2, 3   | ball velocity / 10 m/s                                     |
    | 4      | ball mass / 3 kg                                           |
    | 5      | 1 (the ball's impacts score)                               |
    | 6, 7   | target's centre point, x / 2 m, y / 1 m                    |
    | 8      | target half width / half length of its wall                |
    | 9-12   | target wall one-hot (left, right, bottom, top)             |
    | 13     | target status: 1 pending, 0 hit, -1 failed                 |
    | 14, 15 | -1, 1 (no time window)                                     |
    | 16     | fraction of the 15 control steps left                      |
    | 17     | 1 until the target is hit, then 0                          |

    ## Rewards

    +1 when the target is hit; nothing else (impacts off the target, and the shot's speed, cost
    nothing).

    ## Starting State

    The ball at rest at a random place in the left 40 % of the area (x < -0.4 m), the fence fixed;
    the target on the right wall, its centre uniform along it.

    ## Episode End

    Terminates at the ball's first impact on the right wall: on the target with
    `info["is_success"] = True`, elsewhere with the target failed (`is_success = False`). Impacts
    on the other walls and on the pegs are bounces. Truncates after 15 steps (1.5 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `mode="naive"`, `substeps=4`, `dt=0.05`); `render_mode`;
    `trails`.
    """

    task = Task(
        env_id="CollisionEnv/Fence-v0",
        preset="fence",
        config=dict(
            dimension=2,
            elasticity=1.0,
            n_balls=10,
            mass_range=(1.0, 1.0),
            others_mass_range=(50.0, 50.0),
            radius=0.05,
            layout="fence",
            speed_range=(0.0, 0.0),
            others_speed_range=(0.0, 0.0),
            controlled=(0,),
            control="shot",
            n_targets=1,
            target_width=0.3,
            target_walls=("right",),
            scorers="controlled",
            hit_reward=1.0,
            success_bonus=0.0,
            miss_penalty=0.0,
            action_cost=0.0,
            max_speed=5.0,
            dt=0.1,
            time_limit=1.5,
            observed_balls="controlled",
        ),
        bench_scene="10 balls, 9 at rest (fence)",
    )


FenceVectorEnv = register_task(FenceEnv)
