"""A crowd: steer one heavy ball onto wall targets through a gas of 200 light ones."""

from __future__ import annotations

from collision_env.envs.registry import Task, register_task
from collision_env.envs.target_env import CollisionTargetEnv


class CrowdEnv(CollisionTargetEnv):
    """
    ## Description

    One controlled ball (ball 0, 1 kg) among 200 light balls (0.1 kg), all of radius 0.04 m, in
    PhET's 4 m x 2 m play area, elastic (e = 1) with every ball-ball collision modelled: a gas at an
    area fraction of 13 % whose balls fly at 1-3 m/s. Three targets, 0.6 m wall segments on random
    walls, are shown one at a time, as in `OneBallTarget`; only the controlled ball's wall impacts
    score, and the gas knocks it off course every few tenths of a metre (its mean free path is about
    0.25 m), so the agent keeps steering. Here the engine does most of a step's work: the task with
    the most events per step, where the engine's fidelity mode changes the cost of training.
    `CollisionEnv/Crowd-v0`; the generic env with `preset="crowd"`.

    ## Action Space

    `Box(-1, 1, (2,), float32)`: ball 0's velocity change (ax, ay) * 0.15 m/s for this 0.05 s step.
    Out-of-range values are clipped; NaN raises `ValueError`. A nudge cannot push the ball above
    2 m/s (or above its current speed, if that is higher).

    ## Observation Space

    `Box(-1, 1, (18,), float32)`: the controlled ball, its target and the time (the gas is not
    observed, `observed_balls="controlled"`; `observed_balls="all"` adds a block per gas ball):

    | Index  | Observation                                                        |
    |--------|--------------------------------------------------------------------|
    | 0, 1   | ball 0 position x / 2 m, y / 1 m                                   |
    | 2, 3   | ball 0 velocity vx / 4, vy / 4 (m/s)                               |
    | 4      | ball 0 mass / 3 kg (1/3)                                           |
    | 5      | 1 (its impacts score)                                              |
    | 6, 7   | current target's centre point, x / 2 m, y / 1 m                    |
    | 8      | target half width / half length of its wall                        |
    | 9-12   | target wall one-hot (left, right, bottom, top)                     |
    | 13     | target status: 1 pending, 0 hit                                    |
    | 14, 15 | -1, 1 (no time window)                                             |
    | 16     | fraction of the 200 control steps left                             |
    | 17     | fraction of the 3 targets not yet hit                              |

    With `observe="predicted"`, 4 entries follow: ball 0's next wall impact as the engine predicts
    it through the gas (see `CollisionTargetEnv`).

    ## Rewards

    +1 per target hit by ball 0 (an impact whose exact contact point lies on the current target),
    +1 more when the third is hit, -0.05 per wall impact of ball 0 off target, -0.02 per m/s of
    requested nudge, and the aiming shaping term `1.0 * (phi(s') - phi(s))` on steps without a hit
    (the straight-line heuristic of `CollisionTargetEnv`, which ignores the gas).

    ## Starting State

    Every ball at a random place without overlap; ball 0 moving at 0.3-0.8 m/s, the gas at 1-3 m/s,
    in random directions; three targets on random walls with centres uniform along the wall.

    ## Episode End

    Terminates with `info["is_success"] = True` when all three targets are hit; truncates after
    200 steps (10 s).

    ## Arguments

    Any `TaskConfig` field as a keyword (e.g. `n_balls=51` for a thinner gas, `mode="naive"`);
    `render_mode`; `trails`.
    """

    task = Task(
        env_id="CollisionEnv/Crowd-v0",
        preset="crowd",
        config=dict(
            dimension=2,
            elasticity=1.0,
            n_balls=201,
            mass_range=(1.0, 1.0),
            others_mass_range=(0.1, 0.1),
            observed_balls="controlled",
            radius=0.04,
            speed_range=(0.3, 0.8),
            others_speed_range=(1.0, 3.0),
            controlled=(0,),
            n_targets=3,
            sequential=True,
            target_width=0.6,
            scorers="controlled",
            hit_reward=1.0,
            success_bonus=1.0,
            miss_penalty=0.05,
            action_cost=0.02,
            shaping=1.0,
            max_dv=0.15,
            max_speed=2.0,
        ),
        bench_scene="dilute_gas n=256",
        hyperparams_like="CollisionEnv/OneBallTarget-v0",
    )


CrowdVectorEnv = register_task(CrowdEnv)
