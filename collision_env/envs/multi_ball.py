"""Three balls, all nudged, passing through each other; three targets at once."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class MultiBallEnv(CollisionTargetEnv):
    """
    ## Description

    Three balls (0.5-1.5 kg, explicit radius 0.12 m) in the 4 m x 2 m area with ball-ball
    collisions **off** (they pass through each other; the engine does no pair work at all) and
    walls of restitution e = 0.8. The agent nudges all three at once; three 0.6 m targets are shown
    together and any ball's wall impact may take any of them. `CollisionEnv/MultiBall-v0`; the
    generic env with `preset="multi_ball"`.

    ## Action Space

    `Box(-1, 1, (6,), float32)`: (ax, ay) for balls 0, 1, 2 in order, each scaled to a velocity
    change of up to 0.15 m/s per component for this 0.05 s step. Out-of-range values are clipped;
    NaN raises `ValueError`. A nudge cannot push a ball above 2 m/s (or above its current speed,
    if that is higher). With `control="velocity"` (the shipped PPO agent's setting):
    `Box(-1, 1, (9,), float32)`, per ball its wanted velocity (ux, uy) * 2 m/s (at most 2 m/s long)
    and an engage flag; while a ball's flag is > 0 it is nudged towards that velocity by at most
    0.15 m/s per axis and step, else it coasts.

    ## Observation Space

    `Box(-1, 1, (50,), float32)`:

    | Index           | Observation                                                       |
    |-----------------|-------------------------------------------------------------------|
    | 6i + 0, 1       | ball i position x / 2 m, y / 1 m (i = 0, 1, 2)                    |
    | 6i + 2, 3       | ball i velocity / 4 m/s                                           |
    | 6i + 4          | ball i mass / 3 kg                                                |
    | 6i + 5          | 1 (every ball's impacts score)                                    |
    | 18 + 10s + 0, 1 | target s = 0, 1, 2: centre point x / 2 m, y / 1 m                 |
    | 18 + 10s + 2    | half width / half length of its wall                              |
    | 18 + 10s + 3..6 | wall one-hot (left, right, bottom, top)                           |
    | 18 + 10s + 7    | status: 1 pending, 0 hit                                          |
    | 18 + 10s + 8, 9 | -1, 1 (no time window)                                            |
    | 48              | fraction of the 200 control steps left                            |
    | 49              | fraction of the 3 targets not yet hit                             |

    The shipped PPO agent also observes the engine's prediction (`observe="predicted"`,
    `predicted_impact="scoring"`; 4 entries per ball: for a ball, its first predicted impact
    that lands on a pending target, else its next impact; see `CollisionTargetEnv`).

    ## Rewards

    +1 per target hit (exact contact point on a pending target), +1 more when all three are hit,
    -0.02 per wall impact off target, -0.01 per m/s of requested nudge, and the aiming shaping term
    `0.5 * (phi(s') - phi(s))` (see `CollisionTargetEnv`) on steps without a hit.

    ## Starting State

    Balls at random non-overlapping places, speeds uniform in [0.2, 0.6] m/s in random directions;
    three targets on random walls.

    ## Episode End

    Terminates with `info["is_success"] = True` when all three targets are hit; truncates after
    200 steps (10 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `n_balls=5, controlled=(0, 1, 2, 3, 4)`);
    `render_mode`; `trails`.
    """

    task = Task(
        env_id="CollisionEnv/MultiBall-v0",
        preset="multi_ball",
        config=dict(
            dimension=2,
            elasticity=0.8,
            ball_collisions=False,
            n_balls=3,
            mass_range=(0.5, 1.5),
            radius=0.12,
            speed_range=(0.2, 0.6),
            controlled=(0, 1, 2),
            n_targets=3,
            sequential=False,
            target_width=0.6,
            scorers="any",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.02,
            action_cost=0.01,
            shaping=0.5,
            max_dv=0.15,
            max_speed=2.0,
        ),
        bench_scene="3 balls, no ball-ball collisions, e = 0.8",
        hyperparams_like="CollisionEnv/Line1D-v0",
    )


MultiBallVectorEnv = register_task(MultiBallEnv)
