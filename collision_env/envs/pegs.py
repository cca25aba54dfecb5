"""Pegs: shoot a small, fast ball through a field of heavy pegs onto narrow targets; fidelity matters."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class PegsEnv(CollisionTargetEnv):
    """
    ## Description

    A small, fast ball (ball 0, 1 kg, radius 0.05 m) and 16 pegs: balls of the same radius but
    50 kg, at rest in the right half of PhET's 4 m x 2 m play area, elastic (e = 1). Two narrow
    targets (0.2 m segments of the right wall) are shown one at a time; only ball 0's impacts score,
    so every shot threads the gaps between the pegs (or banks off them). The ball reaches 5 m/s and
    the control step is 0.1 s: a step moves it 0.5 m, more than twice the 0.2 m across which it
    touches a peg. This is the preset where the engine's fidelity changes outcomes: a naive or
    posteriori step that jumps a whole contact lets the ball pass through a peg (tunnelling), and a
    naive step reports a wall impact up to 0.5 m from where the ball really met the wall, more
    than the target is wide. A shot planned in a cheap mode that goes through a peg or lands on a
    target only by those errors misses when the impacts are exact (`tests/envs/test_pegs.py`); a
    policy that re-aims at every step can make up for them (`agents.study` measures what training
    cheaply costs here). `CollisionEnv/Pegs-v0`; the generic env with `preset="pegs"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: ball 0's velocity change (ax, ay) * 1 m/s for this 0.1 s step.
    Out-of-range values are clipped; NaN raises `ValueError`. A nudge cannot push the ball above
    5 m/s (or above its current speed, if that is higher).

    ## Observation Space

    `Box(-1, 1, (114,), float32)`:

    | Index          | Observation                                                     |
    |----------------|-----------------------------------------------------------------|
    | 6i + 0, 1      | ball i position x / 2 m, y / 1 m (i = 0 the ball, 1-16 the pegs) |
    | 6i + 2, 3      | ball i velocity / 10 m/s                                        |
    | 6i + 4         | ball i mass / 3 kg (clipped: 1 for a peg)                       |
    | 6i + 5         | 1 if ball i's impacts score (ball 0), else 0 (the pegs)         |
    | 102, 103       | current target's centre point, x / 2 m, y / 1 m                 |
    | 104            | target half width / half length of its wall                     |
    | 105-108        | target wall one-hot (left, right, bottom, top)                  |
    | 109            | target status: 1 pending, 0 hit                                 |
    | 110, 111       | -1, 1 (no time window)                                          |
    | 112            | fraction of the 200 control steps left                          |
    | 113            | fraction of the 2 targets not yet hit                           |

    With `observe="predicted"`, 4 entries per ball follow: its next wall impact as the engine
    predicts it through the pegs (see `CollisionTargetEnv`).

    ## Rewards

    +1 per target hit by ball 0 (an impact whose contact point lies on the current target), +1 more
    when the second is hit, -0.05 per wall impact of ball 0 off target, -0.01 per m/s of requested
    nudge, and the aiming shaping term `1.0 * (phi(s') - phi(s))` on steps without a hit (the
    straight-line heuristic of `CollisionTargetEnv`, which ignores the pegs).

    ## Starting State

    Every ball at rest: ball 0 at a random place in the left 40 % of the area, the pegs at random
    non-overlapping places in the right half; the targets on the right wall, centres uniform along it.

    ## Episode End

    Terminates with `info["is_success"] = True` when both targets are hit; truncates after 200
    steps (20 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `mode="naive"`, `substeps=4`, `dt=0.05`); `render_mode`;
    `trails`.
    """

    task = Task(
        env_id="CollisionEnv/Pegs-v0",
        preset="pegs",
        config=dict(
            dimension=2,
            elasticity=1.0,
            n_balls=17,
            mass_range=(1.0, 1.0),
            others_mass_range=(50.0, 50.0),
            radius=0.05,
            layout="rack",
            speed_range=(0.0, 0.0),
            others_speed_range=(0.0, 0.0),
            controlled=(0,),
            n_targets=2,
            sequential=True,
            target_width=0.2,
            target_walls=("right",),
            scorers="controlled",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.05,
            action_cost=0.01,
            shaping=1.0,
            max_dv=1.0,
            max_speed=5.0,
            dt=0.1,
            time_limit=20.0,
        ),
        bench_scene="17 balls, 16 at rest (rack)",
        hyperparams_like="CollisionEnv/OneBallTarget-v0",
    )


PegsVectorEnv = register_task(PegsEnv)
