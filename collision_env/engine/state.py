"""The engine's arrays as named bundles, and how a compiled kernel gets them from Python.

Every stepping kernel takes the simulator's :class:`State` (the balls, clocks, scene parameters,
impact buffer and bookkeeping), then what its mode adds: exact mode its :class:`Calendar` and
:class:`ExactScratch`, the cheap modes a :class:`SubstepScratch`; a frames run also hands over its
:class:`FramesOut`. Each bundle is a named tuple of arrays, so a kernel reads ``state.balls``,
never the k-th of twenty positional arguments.

Inside a kernel a scene's balls and the scene parameters are bundles too (:class:`SceneBalls`,
:class:`Physics`), which every mode's phases take.

A call from Python pays numba's check of every argument (about 30 ns an array). A simulator's
arrays are allocated once and updated in place, so with numba they are packed once into one int64
array (:func:`pack`: addresses and shapes, in the order of the bundles' fields) and a kernel
rebuilds its bundles from it (:func:`unpack_state` and its siblings, which name each field's
slot). Without numba the "pack" is the tuple of bundles itself and the same functions return its
parts, so the kernels run unchanged as plain Python.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import DTypeLike

from ._jit import HAVE_NUMBA, njit
from .argpack import pack_arrays, set_slots
from .layout import (
    IMPACT_DTYPE,
    S_COLLAPSE_FLOOR,
    S_COLLAPSE_RATIO,
    S_CONTACT_DURATION,
    S_DIM,
    S_ELASTICITY,
    S_HAS_WALLS,
    S_PAIRS,
    S_SIGN,
    S_STICKY,
    S_XMIN,
    S_YMAX,
)

#: How a call of a stepping kernel starts: it resumes the scenes a full impact buffer stopped,
#: starts a step (exact mode re-predicts the balls that changed since the last step), starts the
#: next step of a run of steps made in one compiled loop, where nothing can have changed in between
#: (the cheap modes treat both starts alike), or runs frames (:mod:`~collision_env.engine.frames`).
RESUME, START_STEP, START_NEXT, RUN_FRAMES = range(4)


class State(NamedTuple):
    """What every mode's kernel reads and writes (``layout`` names the packed ones' fields)."""

    balls: np.ndarray  #: (B, N, len(BALL)) float64, ``layout.BALL``
    body: np.ndarray  #: (B, N) int64, the ball rooting each ball's cluster
    time: np.ndarray  #: (B,) float64 clocks, s
    capped: np.ndarray  #: (B,) bool, the step stopped at the event cap
    fparams: np.ndarray  #: ``layout.SCENE_F`` float64
    iparams: np.ndarray  #: ``layout.SCENE_I`` int64
    imp: np.ndarray  #: impact records, ``layout.IMPACT_DTYPE``
    n_imp: np.ndarray  #: (3,) int64: rows filled, scenes capped, scenes stalled
    counters: np.ndarray  #: ``layout.COUNTERS`` int64
    work_f: np.ndarray  #: (B, len(WORK_F)) float64
    work_i: np.ndarray  #: (B, len(WORK_I)) int64
    clock: np.ndarray  #: (B, 2) float64 compensated clocks (:mod:`~collision_env.engine.clock`)
    images: np.ndarray  #: (B, N, 2) int64: periodic cell lengths each ball has crossed (0 unless periodic)


class Calendar(NamedTuple):
    """Exact mode's persistent event calendar and cell grid (one row per scene)."""

    rec: np.ndarray  #: (B, N) ``layout.CAL_RECORD``
    ci: np.ndarray  #: (B, N, len(CAL_I)) int32
    heads: np.ndarray  #: (B, cells) int32, the first ball of each grid cell
    heap: np.ndarray  #: (B, rows, len(HEAP)) float64, the event queue's heap
    buckets: np.ndarray  #: (B, R + 1) int32, the event queue's bucket lists and far list
    inv_mass: np.ndarray  #: (B, N) float64, the inverse masses the calendar took
    last_impact: np.ndarray  #: (B, N) float64, each ball's last collision instant (s; -inf: none), the TC model's


class ExactScratch(NamedTuple):
    """Exact mode's work space (O(N), allocated once; see ``exact.scheduler.exact_scratch``)."""

    pending: np.ndarray  #: (N,) int64: balls to predict, or whose motion an event changed
    in_group: np.ndarray  #: (N,) bool: a contact group's membership
    c_a: np.ndarray  #: (C,) int64: a contact group's contacts, the lower ball
    c_b: np.ndarray  #: (C,) int64: ... the other ball (>= 0) or the wall (-1 - wall)
    c_hit: np.ndarray  #: (C,) bool: ... already reported
    kinematics: np.ndarray  #: (2, len(KINEMATICS)) float64: two cluster members' rigid kinematics
    event: np.ndarray  #: (1, 2, len(BALL)) float64: the two balls of an event, laid out as ``BALL``
    event_body: np.ndarray  #: (2,) int64: their cluster roots (the rows' own indices)
    slot: np.ndarray  #: (N,) int64: a ball's place in the contact group being resolved (-1: none)
    near: np.ndarray  #: (N,) int64: the balls touching one ball of a contact group (or its new order)
    g_i: np.ndarray  #: (N, 2) int64: per group place, its neighbours along a row, pooled blocks or degree
    g_f: np.ndarray  #: (N, 4) float64: per group place, pooled blocks or velocities (``contacts``)
    c_f: np.ndarray  #: (C, 9) float64: per contact, its geometry and impulses (``contacts.F_*``)


class SubstepScratch(NamedTuple):
    """The cheap modes' work space: a sub-step's cell lists (see ``stepped.cells``)."""

    cells: np.ndarray  #: (len,) int64


class FramesOut(NamedTuple):
    """Where a frames run records (``frames.FRAME_*`` name ``request``'s entries)."""

    request: np.ndarray  #: (len(FRAME_FIELDS),) int64: frame range, rows written, where it stopped
    times: np.ndarray  #: (F, B) float64
    positions: np.ndarray  #: (F, B * N, 2) float64
    velocities: np.ndarray  #: (F, B * N, 2) float64
    images: np.ndarray  #: (F, B * N, 2) int64 periodic image counts, or (F, 0, 2): not recorded
    out: np.ndarray  #: impact records, ``layout.IMPACT_DTYPE``


class SceneBalls(NamedTuple):
    """One scene's ball state: views of the batch's ``layout.BALL`` array and cluster roots (or two
    scratch rows laid out alike, for an event's balls)."""

    pos: np.ndarray  #: (N, 2) centres, m
    vel: np.ndarray  #: (N, 2) velocities, m/s
    mass: np.ndarray  #: (N,) kg
    inv_mass: np.ndarray  #: (N,) 1 / kg
    radius: np.ndarray  #: (N,) m
    body: np.ndarray  #: (N,) the ball rooting each ball's cluster
    omega: np.ndarray  #: (N,) angular velocity of the cluster each ball roots, rad/s


class Physics(NamedTuple):
    """What a step's physics depends on, shared by the scenes of a batch (``layout.SCENE_F`` and
    ``layout.SCENE_I``)."""

    bounds: np.ndarray  #: (xmin, ymin, xmax, ymax), m
    e: float  #: restitution used this step
    ratio: float  #: collapse regulariser: u_min / fastest speed
    floor: float  #: collapse regulariser: smallest u_min, m/s
    sign: float  #: direction of time, +1 or -1
    has_walls: bool
    pairs: bool  #: ball pairs are modelled
    dim: int
    sticky: bool  #: stick clusters are formed
    cascades: bool  #: forward inelastic: touching groups are resolved at one instant
    contact_duration: float  #: the TC model's t_c, s (0: off)


@njit(inline="always")
def scene_balls(views, body, sc):
    """Scene ``sc``'s :class:`SceneBalls`, from the batch's ``ball_views`` and cluster roots (made once
    per call of a kernel, not per scene: a view of the (B, N, 8) state costs as much as a small
    scene's arithmetic)."""
    pos, vel, mass, inv_mass, radius, omega = views
    return SceneBalls(pos[sc], vel[sc], mass[sc], inv_mass[sc], radius[sc], body[sc], omega[sc])


@njit(inline="always")
def physics(fparams, iparams):
    """The :class:`Physics` of the scene parameters."""
    e = fparams[S_ELASTICITY]
    return Physics(
        fparams[S_XMIN : S_YMAX + 1],
        e,
        fparams[S_COLLAPSE_RATIO],
        fparams[S_COLLAPSE_FLOOR],
        fparams[S_SIGN],
        iparams[S_HAS_WALLS] != 0,
        iparams[S_PAIRS] != 0,
        iparams[S_DIM],
        iparams[S_STICKY] != 0,
        e < 1.0,
        fparams[S_CONTACT_DURATION],
    )


def aligned_zeros(shape: int | tuple[int, ...], dtype: DTypeLike, align: int = 64) -> np.ndarray:
    """Zeros whose rows start on ``align``-byte boundaries: a 64-byte calendar record or ball state
    row is then one cache line (numpy itself aligns to 16 bytes)."""
    dtype = np.dtype(dtype)
    size = int(np.prod(shape)) * dtype.itemsize
    buffer = np.zeros(size + align, dtype=np.uint8)
    start = -buffer.ctypes.data % align
    return buffer[start : start + size].view(dtype).reshape(shape)


def aligned_copy(array: np.ndarray, align: int = 64) -> np.ndarray:
    """A copy of ``array`` in :func:`aligned_zeros` memory."""
    out = aligned_zeros(array.shape, array.dtype, align)
    out[...] = array
    return out


def pack(*bundles: NamedTuple, frames: bool = False) -> np.ndarray | tuple:
    """The bundles as a kernel takes them: one int64 array of their arrays' addresses and shapes
    (with numba), or the tuple of bundles (without). ``frames``: room for a :class:`FramesOut`
    after them (:func:`with_frames`). The owner keeps the arrays alive and never replaces one
    without packing again."""
    if not HAVE_NUMBA:
        return bundles
    return pack_arrays([a for bundle in bundles for a in bundle], len(FramesOut._fields) if frames else 0)


def with_frames(h: np.ndarray | tuple, slot: int, frames: FramesOut) -> np.ndarray | tuple:
    """Pack ``h`` (made with room for frames) with ``frames`` at ``slot``; without numba, the
    tuple of bundles with ``frames`` last."""
    if isinstance(h, tuple):  # (without numba)
        return (*h, frames)
    set_slots(h, slot, frames)
    return h


#: Slots of each bundle's first field in a pack: a state first, then the mode's bundles.
STATE_SLOT = 0
#: The slot of the state's impact buffer (the one array a simulator replaces: see ``with_impacts``).
IMPACTS_SLOT = STATE_SLOT + State._fields.index("imp")
CALENDAR_SLOT = len(State._fields)
EXACT_SCRATCH_SLOT = CALENDAR_SLOT + len(Calendar._fields)
SUBSTEP_SCRATCH_SLOT = len(State._fields)
#: A frames run's bundle follows the mode's own.
EXACT_FRAMES_SLOT = EXACT_SCRATCH_SLOT + len(ExactScratch._fields)
SUBSTEP_FRAMES_SLOT = SUBSTEP_SCRATCH_SLOT + len(SubstepScratch._fields)


def with_impacts(h: np.ndarray | tuple, imp: np.ndarray) -> np.ndarray | tuple:
    """Pack ``h`` with ``imp`` as its state's impact buffer (in place with numba, where it costs a
    microsecond against a hundred for packing every array again; a new tuple of bundles without)."""
    if isinstance(h, tuple):  # (without numba)
        return (h[0]._replace(imp=imp), *h[1:])
    set_slots(h, IMPACTS_SLOT, [imp])
    return h


if HAVE_NUMBA:
    from .argpack import view
    from .layout import CAL_RECORD

    @njit(inline="always")
    def unpack_state(h):
        """The :class:`State` of pack ``h``."""
        s = STATE_SLOT
        return State(
            view(h, s, np.float64, 3),
            view(h, s + 1, np.int64, 2),
            view(h, s + 2, np.float64, 1),
            view(h, s + 3, np.bool_, 1),
            view(h, s + 4, np.float64, 1),
            view(h, s + 5, np.int64, 1),
            view(h, s + 6, IMPACT_DTYPE, 1),
            view(h, s + 7, np.int64, 1),
            view(h, s + 8, np.int64, 1),
            view(h, s + 9, np.float64, 2),
            view(h, s + 10, np.int64, 2),
            view(h, s + 11, np.float64, 2),
            view(h, s + 12, np.int64, 3),
        )

    @njit(inline="always")
    def unpack_calendar(h):
        """The :class:`Calendar` of an exact-mode pack ``h``."""
        s = CALENDAR_SLOT
        return Calendar(
            view(h, s, CAL_RECORD, 2),
            view(h, s + 1, np.int32, 3),
            view(h, s + 2, np.int32, 2),
            view(h, s + 3, np.float64, 3),
            view(h, s + 4, np.int32, 2),
            view(h, s + 5, np.float64, 2),
            view(h, s + 6, np.float64, 2),
        )

    @njit(inline="always")
    def unpack_exact_scratch(h):
        """The :class:`ExactScratch` of an exact-mode pack ``h``."""
        s = EXACT_SCRATCH_SLOT
        return ExactScratch(
            view(h, s, np.int64, 1),
            view(h, s + 1, np.bool_, 1),
            view(h, s + 2, np.int64, 1),
            view(h, s + 3, np.int64, 1),
            view(h, s + 4, np.bool_, 1),
            view(h, s + 5, np.float64, 2),
            view(h, s + 6, np.float64, 3),
            view(h, s + 7, np.int64, 1),
            view(h, s + 8, np.int64, 1),
            view(h, s + 9, np.int64, 1),
            view(h, s + 10, np.int64, 2),
            view(h, s + 11, np.float64, 2),
            view(h, s + 12, np.float64, 2),
        )

    @njit(inline="always")
    def unpack_substep_scratch(h):
        """The :class:`SubstepScratch` of a cheap-mode pack ``h``."""
        return SubstepScratch(view(h, SUBSTEP_SCRATCH_SLOT, np.int64, 1))

    @njit(inline="always")
    def unpack_frames(h, s):
        """The :class:`FramesOut` at slot ``s`` of pack ``h``."""
        return FramesOut(
            view(h, s, np.int64, 1),
            view(h, s + 1, np.float64, 2),
            view(h, s + 2, np.float64, 3),
            view(h, s + 3, np.float64, 3),
            view(h, s + 4, np.int64, 3),
            view(h, s + 5, IMPACT_DTYPE, 1),
        )

else:

    def unpack_state(h: tuple) -> State:
        """The :class:`State` of ``h`` (the tuple of bundles)."""
        return h[0]

    def unpack_calendar(h: tuple) -> Calendar:
        """The :class:`Calendar` of an exact-mode ``h``."""
        return h[1]

    def unpack_exact_scratch(h: tuple) -> ExactScratch:
        """The :class:`ExactScratch` of an exact-mode ``h``."""
        return h[2]

    def unpack_substep_scratch(h: tuple) -> SubstepScratch:
        """The :class:`SubstepScratch` of a cheap-mode ``h``."""
        return h[1]

    def unpack_frames(h: tuple, s: int) -> FramesOut:
        """The :class:`FramesOut` of ``h`` (its last bundle)."""
        return h[-1]
