"""The fixed-step driver shared by naive and posteriori modes: k equal sub-steps per step."""

from __future__ import annotations

from ._jit import njit
from .exact import scene_params
from .motion import advance_all, ball_views, has_rotation
from .naive import resolve_naive
from .posteriori import resolve_posteriori
from .response import elastic_threshold

NAIVE, POSTERIORI = 0, 1


def worst_case_impacts(n):
    """Most impacts one sub-step can record for one scene (pairs, border, containment)."""
    return n * (n - 1) // 2 + 4 * n


@njit
def step_substeps(mode, k_total, balls, body, time, capped, fparams, iparams, imp, n_imp, counters, work_f, work_i,
                  dt_abs, fresh):
    """Run the remaining sub-steps of every active scene (``done[sc]`` of ``k_total`` are done).

    Parameters as :func:`exact.step_exact` (``fresh`` starts a step for every scene; ``capped``
    is not used: the cheap modes have no event cap); a scene stops between sub-steps when the
    impact buffer could not hold another sub-step's worst case, and is flagged stalled. Returns
    the number of stalled scenes.
    """
    pos, vel, mass, inv_mass, radius, omega = ball_views(balls)
    t_start = work_f[:, 1]
    active = work_i[:, 1]
    stalled = work_i[:, 2]
    done = work_i[:, 3]
    n_imp[0] = 0
    n = pos.shape[1]
    worst = n * (n - 1) // 2 + 4 * n
    bounds, e, ratio, floor, sign, has_walls, pairs, dim, sticky, _ = scene_params(fparams, iparams)
    h = dt_abs / k_total
    if fresh:
        for sc in range(pos.shape[0]):
            active[sc] = True
            t_start[sc] = time[sc]
            done[sc] = 0
        n_imp[1] = 0
    n_stalled = 0
    for sc in range(pos.shape[0]):
        if not active[sc]:
            continue
        stalled[sc] = False
        p = pos[sc]
        v = vel[sc]
        m = mass[sc]
        b = body[sc]
        w = omega[sc]
        u_min = elastic_threshold(v, ratio, floor)
        while done[sc] < k_total:
            if imp.shape[0] - n_imp[0] < worst:
                stalled[sc] = True
                break
            k = done[sc] + 1
            t_end = t_start[sc] + sign * (dt_abs if k == k_total else h * k)
            advance_all(h, p, v, m, b, w, sticky and has_rotation(b, w))
            if mode == NAIVE:
                resolve_naive(sc, t_end, p, v, m, inv_mass[sc], radius[sc], b, w, bounds, dim, e, u_min,
                              has_walls, pairs, sticky, imp, n_imp, counters)
            else:
                resolve_posteriori(sc, t_end, sign, h, p, v, m, inv_mass[sc], radius[sc], b, w, bounds, dim, e, u_min,
                                   has_walls, pairs, sticky, imp, n_imp, counters)
            done[sc] = k
            time[sc] = t_end
        n_stalled += stalled[sc]
        active[sc] = stalled[sc]
    return n_stalled
