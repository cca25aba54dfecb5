"""Many steps in one compiled call, recording the state after each: a trajectory sampled in frames.

A loop of ``step(dt)`` calls from Python pays, per frame, for the call into compiled code, the
step's set-up and the Python around it: about a microsecond, as much as an event of a sparse gas.
:func:`step_frames` runs the same steps (the same kernel, so the same impacts, state and clocks
bit for bit) in a compiled loop and copies each frame's ball positions, velocities, clocks and
impacts into the caller's arrays. It stops early at a frame that needs Python: one whose step
reached the event cap or found the kernel's impact buffer full (which the simulator completes
as it completes any step), or one whose impacts do not fit the caller's buffer.
"""

from __future__ import annotations

from ._jit import HAVE_NUMBA, njit
from .layout import B_VX, B_X

#: The mode code of exact mode for :func:`step_frames` (the cheap modes use their own,
#: ``substep.NAIVE`` and ``substep.POSTERIORI``, which are not negative).
EXACT = -1


@njit(refcount=False)
def copy_impacts(buf, out, sign):
    """Copy the first ``len(out)`` impact records of ``buf`` into ``out``, each scene's records
    ordered by ``sign * time`` (stable, so simultaneous impacts keep their order). The rows of one
    scene are contiguous and scenes come in order, so an insertion sort is linear here (the cheap
    modes reconstruct impact times out of order within a sub-step; exact mode's are in order)."""
    n = out.shape[0]
    for k in range(n):
        out[k] = buf[k]
    for k in range(1, n):
        j = k
        while j > 0 and out[j - 1]["scene"] == out[j]["scene"] and sign * out[j - 1]["time"] > sign * out[j]["time"]:
            buf[0] = out[j]  # swap through row 0 of the buffer, which is copied out already
            out[j] = out[j - 1]
            out[j - 1] = buf[0]
            j -= 1


@njit(refcount=False)
def record_frame(f, balls, time, times, positions, velocities):
    """Frame ``f`` of the caller's arrays: every scene's clock, positions and velocities now."""
    n_scenes, n = balls.shape[0], balls.shape[1]
    for sc in range(n_scenes):
        times[f, sc] = time[sc]
        for i in range(n):
            positions[f, sc, i, 0] = balls[sc, i, B_X]
            positions[f, sc, i, 1] = balls[sc, i, B_X + 1]
            velocities[f, sc, i, 0] = balls[sc, i, B_VX]
            velocities[f, sc, i, 1] = balls[sc, i, B_VX + 1]


if HAVE_NUMBA:
    import numpy as np

    from .argpack import view1, view3
    from .exact.scheduler import START_NEXT, START_STEP, step_exact_packed
    from .layout import IMPACT_DTYPE
    from .stepped.substep import step_substeps_packed

    @njit
    def step_frames(mode, k_total, h, dt, first, n_frames, times, positions, velocities, out, n_out):
        """Frames ``first`` to ``n_frames - 1``: a forward step of ``dt`` each by the kernel of
        ``mode`` (:data:`EXACT`, or the cheap modes' code and ``k_total`` sub-steps) on the pack
        ``h``, recording each into row ``f`` of ``times`` (F, B), ``positions`` and
        ``velocities`` (F, B, N, 2), and its impacts into ``out`` from row ``n_out`` on.

        Returns ``(f, stepped, n_out)``: ``f == n_frames`` when every frame was recorded; else
        frame ``f`` is not, and ``stepped`` says whether its step ended (its impacts did not fit
        ``out`` and are still in the kernel's buffer) or needs the caller to complete it (the
        kernel returned -1: the event cap, or a full kernel buffer).
        """
        balls = view3(h, 0, np.float64)
        time = view1(h, 2, np.float64)
        imp = view1(h, 6, IMPACT_DTYPE)
        start = START_STEP  # (the caller may have changed the balls since the last step)
        for f in range(first, n_frames):
            if mode == EXACT:
                rows = step_exact_packed(h, dt, start)
            else:
                rows = step_substeps_packed(mode, k_total, h, dt, start)
            start = START_NEXT
            if rows < 0:
                return f, False, n_out
            if n_out + rows > out.shape[0]:
                return f, True, n_out
            copy_impacts(imp, out[n_out : n_out + rows], 1.0)
            n_out += rows
            record_frame(f, balls, time, times, positions, velocities)
        return n_frames, True, n_out
