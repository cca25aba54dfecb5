"""What the engine knows ahead (``observe="predicted"``, ``aim="predicted"`` or ``"landing"``): each
ball's next wall impact if the agent stops nudging, from a copy of the engine run ``lookahead``
seconds ahead."""

from __future__ import annotations

import math

import numpy as np

from collision_env.engine.compiled import njit

from .arrays import unpack
from .layout import (
    AIM_LANDING,
    PARAMS,
    PREDICTED_OBS,
    ROW_RESET,
    ROW_SKIP,
    ROW_STEPPED,
    SCENE_FLOATS,
    SCENE_INTS,
    SWITCHES,
)
from .nudge import clip1
from .observe import centre_and_half_size
from .scoring import aim_squared, landing_squared, next_wall_impact, play_area, target_hit


@njit(label="the environments' predicted observation")
def predict_kernel(h, flags, imp, obs):  # pragma: no cover - numba
    """Each ball's predicted wall impact: written into the observation's last entries, one
    ``PREDICTED_OBS`` block per shown ball (``observe_predicted``), and made the aiming potential
    (``aim_predicted``), for the rows whose flag is not ``ROW_SKIP``.

    ``imp`` are the impacts of a copy of the engine run ahead from the scenes' current state with no
    nudge (sorted by scene then time); ``h`` the task's pack (:mod:`~.arrays`), whose engine is at
    the scenes' current state and whose cluster mirror of the look-ahead (``TaskState.ahead_body``)
    replays the clusters through it as the task kernel does. A ball's entry is its first wall
    impact: the contact point, the time until it over ``time_limit``, and whether it would score on
    a visible pending target (target status as the task kernel left it, so a target hit this step no
    longer counts); with ``predict_scoring``, a scoring ball's entry is its first impact that scores
    so, if one does. With ``aim_predicted``, phi is minus the distance, over the play-area diagonal,
    from the nearest of the scoring balls' predicted impact points (their first ones; all of them
    with ``predict_scoring``) to a visible pending target (-1 when none is predicted): the task
    kernel's shaping term, computed here with the engine's prediction instead of straight flight,
    added to the reward of stepped scenes without a hit. With ``aim_predicted`` 2 (``aim="landing"``)
    the distance is instead from each scoring ball's first predicted impact on the wall of a visible
    pending target to that target (:func:`landing_squared`): the impact that decides a shot.
    """
    engine, state, params = unpack(h)
    p, switches, shown, body = params.params, params.switches, params.shown, state.ahead_body
    xc, yc, xh, yh = centre_and_half_size(p)
    box = play_area(p)
    diag = 2.0 * math.sqrt(xh * xh + yh * yh)
    tlimit = p[PARAMS.time_limit]
    seq = switches[SWITCHES.sequential] != 0
    observe = switches[SWITCHES.observe_predicted] != 0
    aim = switches[SWITCHES.aim_predicted] != 0
    landing = switches[SWITCHES.aim_predicted] == AIM_LANDING
    scan = switches[SWITCHES.predict_scoring] != 0
    n = body.shape[1]
    block = np.full(n, -1)  # the observation entry where each shown ball's block starts
    n_shown = 0
    for i in range(n):
        if shown[i]:
            n_shown += 1
    o = obs.shape[1] - n_shown * len(PREDICTED_OBS)
    for i in range(n):
        if shown[i]:
            block[i] = o
            o += len(PREDICTED_OBS)
    seen = np.zeros(body.shape, dtype=np.bool_)
    found = np.zeros(body.shape, dtype=np.bool_)  # (a scoring impact is in the ball's block)
    landed = np.zeros(body.shape, dtype=np.bool_)  # (the ball's landing is in best)
    best = np.full(body.shape[0], np.inf)  # (each scene's least squared aim distance)
    for b in range(flags.shape[0]):
        if flags[b] == ROW_SKIP:
            continue
        for i in range(n):
            body[b, i] = engine.clusters[b, i]
            if observe and shown[i]:
                o = block[i]
                obs[b, o + PREDICTED_OBS.x] = 0.0
                obs[b, o + PREDICTED_OBS.y] = 0.0
                obs[b, o + PREDICTED_OBS.time] = 1.0
                obs[b, o + PREDICTED_OBS.hits] = 0.0
    cluster = switches[SWITCHES.cluster] != 0
    j, scores = next_wall_impact(0, imp, flags, False, body, params.scoring, cluster)
    while j < imp.shape[0]:
        b = imp[j]["scene"]
        i = imp[j]["ball"]
        if landing and scores and not landed[b, i]:
            d2 = landing_squared(j, imp, state, seq)
            if d2 < math.inf:
                landed[b, i] = True
                best[b] = min(best[b], d2)
        first = not seen[b, i]
        if first or (scan and scores and not found[b, i]):
            seen[b, i] = True
            x = imp[j]["x"]
            y = imp[j]["y"]
            if aim and scores and not landing:
                best[b] = min(best[b], aim_squared(x, y, b, state, seq, box))
            if observe and shown[i]:
                hits = scores and target_hit(j, imp, state, seq) >= 0
                if first or hits:
                    found[b, i] = hits
                    o = block[i]
                    obs[b, o + PREDICTED_OBS.x] = clip1((x - xc) / xh)
                    obs[b, o + PREDICTED_OBS.y] = clip1((y - yc) / yh)
                    obs[b, o + PREDICTED_OBS.time] = clip1((imp[j]["time"] - engine.time[b]) / tlimit)
                    obs[b, o + PREDICTED_OBS.hits] = 1.0 if hits else 0.0
        j, scores = next_wall_impact(j + 1, imp, flags, False, body, params.scoring, cluster)
    if aim:
        for b in range(flags.shape[0]):
            f = flags[b]
            phi = -min(1.0, math.sqrt(best[b]) / diag)
            if f == ROW_STEPPED and state.scene_i[b, SCENE_INTS.hits] == 0:
                state.scene_f[b, SCENE_FLOATS.reward] += p[PARAMS.shaping] * (phi - state.scene_f[b, SCENE_FLOATS.phi])
            if f == ROW_STEPPED or f == ROW_RESET:
                state.scene_f[b, SCENE_FLOATS.phi] = phi
