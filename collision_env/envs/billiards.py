"""Billiards: nudge only the cue ball; the object balls must hit the targets."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class BilliardsEnv(CollisionTargetEnv):
    """
    ## Description

    A cue ball (ball 0) and three object balls, all 1 kg with PhET's constant radius 0.15 m, on
    the 4 m x 2 m table with restitution e = 0.95 (ball-ball and cushions). The agent nudges only
    the cue ball; only **object-ball** wall impacts score, so the skill is transferring momentum
    through ball-ball collisions. Two targets (0.6 m segments) are shown at once, like pockets.
    `CollisionEnv/Billiards-v0`; the generic env with `preset="billiards"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: the cue ball's velocity change (ax, ay) * 0.2 m/s per 0.05 s step.
    Out-of-range values are clipped; NaN raises `ValueError`. A nudge cannot push the cue ball
    above 2 m/s (or above its current speed, if that is higher). With `control="velocity"` (the
    shipped PPO agent's setting): `Box(-1, 1, (3,), float32)`, the cue ball's wanted velocity
    (ux, uy) * 2 m/s (at most 2 m/s long) and an engage flag; while the flag is > 0 the cue ball is
    nudged towards that velocity by at most 0.2 m/s per axis and step, else it coasts.

    ## Observation Space

    `Box(-1, 1, (46,), float32)`:

    | Index           | Observation                                                      |
    |-----------------|------------------------------------------------------------------|
    | 6i + 0, 1       | ball i position x / 2 m, y / 1 m (i = 0 cue, 1-3 object balls)   |
    | 6i + 2, 3       | ball i velocity / 4 m/s                                          |
    | 6i + 4          | ball i mass / 3 kg                                               |
    | 6i + 5          | 1 if ball i's impacts score (object balls), else 0 (cue ball)    |
    | 24 + 10s + 0..9 | target s = 0, 1: centre point, half width, wall one-hot, status, -1, 1 |
    | 44              | fraction of the 200 control steps left                           |
    |                 | (target status: 1 pending, 0 hit; -1, 1: no time window)         |
    | 45              | fraction of the 2 targets not yet hit                            |

    The shipped PPO agent also observes the engine's prediction (`observe="predicted"`,
    `predicted_impact="scoring"`; 4 entries per ball: for an object ball, its first predicted impact
    that lands on a pending target, else its next impact (the cue ball's: its next impact); see
    `CollisionTargetEnv`).

    ## Rewards

    +1 per target hit by an object ball's wall impact (exact contact point on the segment), +1
    more when both are hit, -0.02 per m/s of requested nudge. Cue-ball impacts and object-ball
    impacts elsewhere cost nothing. No shaping.

    ## Starting State

    All balls at rest: the cue ball at a random place in the left 40 % of the table, the object
    balls at random non-overlapping places in the right half; two targets on random walls.

    ## Episode End

    Terminates with `info["is_success"] = True` when both targets are hit; truncates after 200
    steps (10 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `n_balls=6`, `elasticity=1.0`); `render_mode`; `trails`.
    """

    task = Task(
        env_id="CollisionEnv/Billiards-v0",
        preset="billiards",
        config=dict(
            dimension=2,
            elasticity=0.95,
            n_balls=4,
            mass_range=(1.0, 1.0),
            radius="constant",
            layout="rack",
            speed_range=(0.0, 0.0),
            others_speed_range=(0.0, 0.0),
            controlled=(0,),
            n_targets=2,
            sequential=False,
            target_width=0.6,
            scorers="others",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.0,
            action_cost=0.02,
            shaping=0.0,
            max_dv=0.2,
            max_speed=2.0,
        ),
        bench_scene="4 balls, e = 0.95 (rack)",
        hyperparams_like="CollisionEnv/Line1D-v0",
    )


BilliardsVectorEnv = register_task(BilliardsEnv)
