"""One ball in 2D, one target at a time: the simplest task (the sample agent's default)."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class OneBallTargetEnv(CollisionTargetEnv):
    """
    ## Description

    One 1 kg ball (radius 0.1897 m, PhET's density rule) bounces elastically (e = 1) in PhET's
    4 m x 2 m play area. Three targets, 0.6 m wall segments on random walls, are shown one at a time;
    the agent steers the ball by nudging its velocity so that its next wall impact lands on the
    current target. `CollisionEnv/OneBallTarget-v0`; the generic env with `preset="one_ball"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: the velocity change (ax, ay) * 0.15 m/s for this 0.05 s step.
    Out-of-range values are clipped; NaN raises `ValueError`. A nudge cannot push the ball above
    2 m/s (or above its current speed, if that is higher).

    ## Observation Space

    `Box(-1, 1, (18,), float32)`:

    | Index | Observation                                                        |
    |-------|--------------------------------------------------------------------|
    | 0, 1  | ball position x / 2 m, y / 1 m                                    |
    | 2, 3  | ball velocity vx / 4, vy / 4 (m/s)                                 |
    | 4     | ball mass / 3 kg (1/3)                                             |
    | 5     | 1 (the ball's impacts score)                                       |
    | 6, 7  | current target's centre point, x / 2 m, y / 1 m                    |
    | 8     | target half width / half length of its wall                        |
    | 9-12  | target wall one-hot (left, right, bottom, top)                     |
    | 13    | target status: 1 pending, 0 hit                                    |
    | 14,15 | -1, 1 (no time window)                                             |
    | 16    | fraction of the 200 control steps left                             |
    | 17    | fraction of the 3 targets not yet hit                              |

    ## Rewards

    +1 per target hit (an impact whose exact contact point lies on the current target), +1 more
    when the third is hit, -0.05 per wall impact off target, -0.02 per m/s of requested nudge, and
    the aiming shaping term `1.0 * (phi(s') - phi(s))` on steps without a hit, where `-phi` is the
    distance from the point where the ball would touch the border flying straight on to the current
    target, over the play-area diagonal (potential-based; see `CollisionTargetEnv`).

    ## Starting State

    The ball anywhere in the area, speed uniform in [0.3, 0.8] m/s in a random direction; three
    targets on random walls with centres uniform along the wall (the segment inside the wall).

    ## Episode End

    Terminates with `info["is_success"] = True` when all three targets are hit; truncates after
    200 steps (10 s of simulated time).

    ## Arguments

    Any `TaskConfig` field as a keyword, e.g. `mode="posteriori", substeps=4, dt=0.1`; `render_mode`
    "rgb_array" or "human"; `trails=True`.
    """

    task = Task(
        env_id="CollisionEnv/OneBallTarget-v0",
        preset="one_ball",
        config=dict(
            dimension=2,
            elasticity=1.0,
            n_balls=1,
            mass_range=(1.0, 1.0),
            radius="mass",
            speed_range=(0.3, 0.8),
            controlled=(0,),
            n_targets=3,
            sequential=True,
            target_width=0.6,
            scorers="any",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.05,
            action_cost=0.02,
            shaping=1.0,
            max_dv=0.15,
            max_speed=2.0,
        ),
        bench_scene="explore_2d n=1 / dilute_gas n=1",
    )


OneBallTargetVectorEnv = register_task(OneBallTargetEnv)
