"""PhET Inelastic (e = 0, stick): ram the resting ball, then steer the stuck cluster onto the target."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class InelasticClusterEnv(CollisionTargetEnv):
    """
    ## Description

    Two balls (0.5-1.5 kg, PhET's density radii) in the 4 m x 2 m area with perfectly inelastic
    **stick** collisions (e = 0): balls that touch become one rigid cluster that spins about its
    centre of mass, and a ball or cluster touching a wall stops dead there (and comes apart), as
    in PhET's Inelastic screen. The agent nudges ball 0 (an impulse on the whole cluster once
    stuck). Only a wall impact of a ball **that is part of a cluster** scores: the agent must first
    ram ball 1, then steer the cluster onto the target. `CollisionEnv/InelasticCluster-v0`; the
    generic env with `preset="inelastic_cluster"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: ball 0's velocity change (ax, ay) * 0.15 m/s per 0.05 s step
    (applied as the impulse m0 * dv, so a cluster responds linearly and angularly). Out-of-range
    values are clipped; NaN raises `ValueError`. A nudge cannot push ball 0 above 1.5 m/s (or above
    its current speed, if that is higher).

    ## Observation Space

    `Box(-1, 1, (24,), float32)`:

    | Index      | Observation                                                          |
    |------------|----------------------------------------------------------------------|
    | 6i + 0, 1  | ball i position x / 2 m, y / 1 m                                     |
    | 6i + 2, 3  | ball i velocity / 3 m/s                                              |
    | 6i + 4     | ball i mass / 3 kg                                                   |
    | 6i + 5     | 1 if ball i is stuck in a cluster (its wall impacts score), else 0   |
    | 12, 13     | target centre point x / 2 m, y / 1 m                                 |
    | 14         | target half width / half length of its wall                          |
    | 15-18      | target wall one-hot (left, right, bottom, top)                       |
    | 19         | target status: 1 pending, 0 hit                                      |
    | 20, 21     | -1, 1 (no time window)                                               |
    | 22         | fraction of the 200 control steps left                               |
    | 23         | fraction of the target not yet hit (1 or 0)                          |

    ## Rewards

    +1 for the hit (a cluster's wall impact whose exact contact point is on the 0.8 m target) and
    +1 success bonus, -0.02 per m/s of requested nudge. No shaping.

    ## Starting State

    Ball 0 at a random place moving at 0-0.3 m/s in a random direction, ball 1 at rest elsewhere;
    one target on a random wall.

    ## Episode End

    Terminates with `info["is_success"] = True` on the hit; truncates after 200 steps (10 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `n_balls=3`, `mode="posteriori", substeps=2`);
    `render_mode`; `trails`.
    """

    task = Task(
        env_id="CollisionEnv/InelasticCluster-v0",
        preset="inelastic_cluster",
        config=dict(
            dimension=2,
            elasticity=0.0,
            inelastic="stick",
            n_balls=2,
            mass_range=(0.5, 1.5),
            radius="mass",
            speed_range=(0.0, 0.3),
            others_speed_range=(0.0, 0.0),
            controlled=(0,),
            n_targets=1,
            sequential=True,
            target_width=0.8,
            scorers="cluster",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.0,
            action_cost=0.02,
            shaping=0.0,
            max_dv=0.15,
            max_speed=1.5,
        ),
        bench_scene="inelastic (stick)",
        hyperparams_like="CollisionEnv/Line1D-v0",
    )


InelasticClusterVectorEnv = register_task(InelasticClusterEnv)
