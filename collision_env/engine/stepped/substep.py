"""The fixed-step driver shared by naive and posteriori modes: k equal sub-steps per step.

Each sub-step moves every ball by ``h = dt / k`` and then lets the mode's resolver find and
resolve what overlaps (:mod:`~.naive`, :mod:`~.posteriori`). The resolver is chosen where the
kernel is built (:func:`step_kernel`), so each mode compiles only its own.

``open_step`` and the helpers called once per scene and sub-step (``elastic_threshold``, the cell
lists' ``worst_case_impacts`` and ``later_neighbours``, ``naive.contain``) are copied into the kernel
by numba (``inline="always"``) rather than inlined by LLVM (``forceinline``): each has one call site
per kernel, and with LLVM's inlining the posteriori step of a batch of 1024 four-ball scenes ran
about 5 % slower (the same work, compiled to worse machine code: measured, not derived). The
resolvers stay LLVM's: copying posteriori's in too ran a little faster still but compiled its
kernel about 4 s longer.
"""

from __future__ import annotations

from typing import Any

from .._jit import njit
from ..clock import finish_step
from ..exact.grid import scene_geometry
from ..frames import frames_kernel
from ..layout import S_SUBSTEPS, W_ACTIVE, W_STALLED, W_SUBSTEP_START, W_SUBSTEPS_DONE
from ..physics.motion import advance_all, ball_views, has_rotation
from ..physics.response import elastic_threshold
from ..state import (
    RESUME,
    SUBSTEP_FRAMES_SLOT,
    physics,
    scene_balls,
    unpack_state,
    unpack_substep_scratch,
)
from . import naive, posteriori
from . import periodic as cyclic
from .cells import cell_lists, worst_case_impacts

#: The resolver of each cheap mode.
RESOLVERS = {"naive": naive.resolve, "posteriori": posteriori.resolve}


@njit(inline="always")
def open_step(state, start):
    """Start a step for every scene (``start``: not ``RESUME``), or resume the stalled ones
    (impacts are recorded from row ``n_imp[0]`` on, as in exact mode)."""
    if start != RESUME:
        for sc in range(state.time.shape[0]):
            state.work_i[sc, W_ACTIVE] = True
            state.work_f[sc, W_SUBSTEP_START] = state.time[sc]
            state.work_i[sc, W_SUBSTEPS_DONE] = 0
        state.n_imp[1] = 0
    state.n_imp[2] = 0


def _step(resolve, periodic=False):
    """The sub-steps of every active scene of a batch, resolved by ``resolve`` (a mode's, with
    the signature of ``naive.resolve``; ``periodic``: in a periodic cell, :mod:`~.periodic`): a
    function ``step(h, dt_abs, start)`` of a pack of a
    ``State`` and a ``SubstepScratch``, inlined into its kernel (:func:`step_kernel`). ``start``
    and the return value are as for exact mode's step (the cheap modes have no event cap, so
    ``capped`` stays False); a scene stops between sub-steps when the impact buffer could not
    hold another sub-step's worst case, and is flagged stalled."""

    @njit(inline="always")
    def step(pk, dt_abs, start):
        state = unpack_state(pk)
        scratch = unpack_substep_scratch(pk).cells
        ph = physics(state.fparams, state.iparams)
        k_total = state.iparams[S_SUBSTEPS]
        h = dt_abs / k_total
        open_step(state, start)
        views = ball_views(state.balls)
        n = state.balls.shape[1]
        for sc in range(state.time.shape[0]):
            if not state.work_i[sc, W_ACTIVE]:
                continue
            state.work_i[sc, W_STALLED] = False
            b = scene_balls(views, state.body, sc)
            geo = scene_geometry(state.work_f, state.work_i, sc)
            u_min = elastic_threshold(b.vel, ph.ratio, ph.floor)
            while state.work_i[sc, W_SUBSTEPS_DONE] < k_total:
                if periodic:
                    cells = cyclic.cell_lists(n, b.pos, b.vel, h, scratch, geo, ph.bounds, ph.dim)
                else:
                    cells = cell_lists(n, b.pos, b.vel, h, scratch, geo)
                room = state.imp.shape[0] - state.n_imp[0]
                if periodic:
                    worst = cyclic.worst_case_impacts(n, cells, room)
                else:
                    worst = worst_case_impacts(n, cells, room)
                if room < worst:
                    state.work_i[sc, W_STALLED] = True
                    break
                k = state.work_i[sc, W_SUBSTEPS_DONE] + 1
                t_end = state.work_f[sc, W_SUBSTEP_START] + ph.sign * (dt_abs if k == k_total else h * k)
                rot = ph.sticky and has_rotation(b.body, b.omega)
                advance_all(h, b.pos, b.vel, b.mass, b.body, b.omega, rot)
                resolve(sc, t_end, h, u_min, b, ph, state, cells)
                state.work_i[sc, W_SUBSTEPS_DONE] = k
                state.time[sc] = t_end
            stalled = state.work_i[sc, W_STALLED]
            state.n_imp[2] += stalled
            state.work_i[sc, W_ACTIVE] = stalled
            if not stalled:
                finish_step(sc, True, ph.sign * dt_abs, state.time, state.clock)
        return state.n_imp[0] if state.n_imp[2] == 0 else -1

    return step


_KERNELS: dict = {}


def step_kernel(mode: str, periodic: bool = False) -> Any:
    """The compiled stepping kernel of cheap ``mode`` ("naive" or "posteriori", built on first
    use): ``kernel(h, dt_abs, start)`` on a pack of a ``State``, a ``SubstepScratch`` and room for
    frames (see :func:`~collision_env.engine.frames.frames_kernel`). ``periodic``: the kernel for
    periodic scenes (compiled only when one is first stepped)."""
    key = (mode, periodic)
    if key not in _KERNELS:
        if periodic:
            step = _step(cyclic.RESOLVERS[mode], True)
            _KERNELS[key] = frames_kernel(step, f"{mode} mode for periodic scenes", SUBSTEP_FRAMES_SLOT)
        else:
            _KERNELS[key] = frames_kernel(_step(RESOLVERS[mode]), f"{mode} mode", SUBSTEP_FRAMES_SLOT)
    return _KERNELS[key]
