"""Many steps in one compiled call, recording the state after each: a trajectory sampled in frames.

A loop of ``step(dt)`` calls from Python pays, per frame, for the call into compiled code, the
step's set-up and the Python around it: about a microsecond, as much as an event of a sparse gas.
Every mode's stepping kernel is made by :func:`frames_kernel`, which runs either one step (the
``start`` codes of :mod:`~collision_env.engine.state`) or, with ``RUN_FRAMES``, the same steps
(so the same impacts, state and clocks, bit for bit) in a compiled loop that copies each frame's
ball positions, velocities, clocks, periodic image counts and impacts into the caller's arrays
(``state.FramesOut``). It stops early at a frame that needs Python: one whose step reached the
event cap or found the kernel's impact buffer full (which the simulator completes as it completes
any step), or one whose impacts do not fit the caller's buffer. One kernel for both means a mode's
step is compiled once, not again inside a loop of its own.
"""

from __future__ import annotations

from typing import Any

from ._jit import njit
from .layout import B_VX, B_X, FRAME_FIRST, FRAME_LAST, FRAME_ROWS, FRAME_STEPPED, FRAME_STOPPED_AT
from .state import RUN_FRAMES, START_NEXT, START_STEP, unpack_frames, unpack_state


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
def record_frame(f, balls, time, images, times, positions, velocities, frame_images):
    """Frame ``f`` of the caller's arrays: every scene's clock, positions and velocities now
    (``positions`` and ``velocities`` are ``(F, B * N, 2)``: each frame's scenes one after another),
    and the balls' periodic ``images`` into ``frame_images`` unless it has no rows (``(F, 0, 2)``:
    a scene that is not periodic, whose images stay 0)."""
    n_scenes, n = balls.shape[0], balls.shape[1]
    take_images = frame_images.shape[1] > 0
    for sc in range(n_scenes):
        times[f, sc] = time[sc]
        for i in range(n):
            row = sc * n + i
            positions[f, row, 0] = balls[sc, i, B_X]
            positions[f, row, 1] = balls[sc, i, B_X + 1]
            velocities[f, row, 0] = balls[sc, i, B_VX]
            velocities[f, row, 1] = balls[sc, i, B_VX + 1]
            if take_images:
                frame_images[f, row, 0] = images[sc, i, 0]
                frame_images[f, row, 1] = images[sc, i, 1]


@njit(refcount=False, python=False)
def _take_frame(f, base, end, state, out):
    """After frame ``f``'s step, which recorded its impacts from row ``base`` of the kernel's
    buffer and returned ``end``: record the frame and its impacts, then rewind the buffer's cursor
    to ``base`` (True), or note where the run stops (False): a step the caller must complete
    (``end < 0``), or impacts that do not fit ``out``."""
    request = out.request
    n_out = request[FRAME_ROWS]
    rows = end - base
    if end < 0 or n_out + rows > out.out.shape[0]:
        request[FRAME_STOPPED_AT] = f
        request[FRAME_STEPPED] = end >= 0
        return False
    copy_impacts(state.imp[base:end], out.out[n_out : n_out + rows], 1.0)
    state.n_imp[0] = base
    request[FRAME_ROWS] = n_out + rows
    record_frame(f, state.balls, state.time, state.images, out.times, out.positions, out.velocities, out.images)
    return True


def frames_kernel(step: Any, label: str, frames_slot: int) -> Any:
    """A mode's stepping kernel, ``kernel(h, dt, start)``, from its step (an inlined function of
    the same arguments, see :mod:`~collision_env.engine.state` for ``start``): one step, whose
    return value (the impact buffer's cursor after it, or -1) it returns, or with ``start =
    RUN_FRAMES`` forward steps of ``dt`` for the frames requested in the ``state.FramesOut`` at
    ``frames_slot`` of the pack (``layout.FRAME_FIELDS``: from ``first`` up to ``last``; its
    ``stopped_at`` and ``stepped`` say where the run stopped, ``stopped_at = last`` when every frame
    was recorded). ``label``: what the compile notice calls it."""

    @njit(refcount=False, label=label)
    def kernel(h, dt, start):
        frames = start == RUN_FRAMES
        first, last = 0, 1
        if frames:
            request = unpack_frames(h, frames_slot).request
            first, last = request[FRAME_FIRST], request[FRAME_LAST]
        state = unpack_state(h)
        base = state.n_imp[0]  # (each frame's impacts are copied out, and their rows used again)
        go = START_STEP if frames else start  # (the caller may have changed the balls since the last step)
        for f in range(first, last):
            end = step(h, dt, go)
            if not frames:
                return end
            go = START_NEXT
            if not _take_frame(f, base, end, state, unpack_frames(h, frames_slot)):
                return 0
        if frames:
            request = unpack_frames(h, frames_slot).request
            request[FRAME_STOPPED_AT] = last
            request[FRAME_STEPPED] = True
        return 0

    return kernel
