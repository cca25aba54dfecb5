"""The public engine: :class:`BatchSimulator` steps many independent scenes at once; a
:class:`Simulator` is a batch of one with per-ball conveniences.

Both call the same compiled kernels (one per mode and kind of scene, see
:mod:`~collision_env.engine.modes`), so there is one copy of the physics for the single env and the
vector env alike. Input is checked by :mod:`~collision_env.engine.validation` before anything
changes.
"""

from __future__ import annotations

import copy
import inspect
import numbers
import warnings
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike

from ._jit import BACKEND, compile_for
from .argpack import pack_arrays
from .broadphase import GRID_MIN_BALLS, grid_geometry
from .frames import copy_impacts, record_frame
from .impacts import Impacts
from .keywords import check_keywords
from .layout import (
    B_INV_MASS,
    B_MASS,
    B_OMEGA,
    B_RADIUS,
    B_VX,
    B_X,
    BALL,
    COUNTERS,
    FRAME_FIELDS,
    FRAME_FIRST,
    FRAME_LAST,
    FRAME_ROWS,
    FRAME_STEPPED,
    FRAME_STOPPED_AT,
    IMPACT_DTYPE,
    S_ELASTICITY,
    S_PAIRS,
    S_SIGN,
    SCENE_F,
    SCENE_I,
    W_CALENDAR_VALID,
    W_GRID_NX,
    W_GRID_X0,
    WORK_F,
    WORK_I,
)
from .modes import MODES as MODE_REGISTRY
from .physics.motion import apply_impulses
from .physics.periodic import MAX_IMAGES, wrap_positions
from .scene import Scene
from .state import (
    RESUME,
    RUN_FRAMES,
    START_NEXT,
    START_STEP,
    FramesOut,
    State,
    aligned_copy,
    aligned_zeros,
    pack,
    with_frames,
)
from .validation import (
    MAX_MAGNITUDE,
    MAX_SUBSTEPS,
    Labels,
    check_laps,
    check_reach,
    check_seconds,
    check_stick_clusters,
    checked_balls,
    checked_nudge,
    is_real,
    positive_integer,
    real_number,
)

#: The engine's mode names, cheapest first.
MODES = tuple(MODE_REGISTRY)

#: The default event cap's budget per ball and step, and its floor (see :func:`default_event_cap`).
EVENTS_PER_BALL = 1_000
MIN_EVENT_CAP = 10_000


def default_event_cap(n: int) -> int:
    """The default cap on events per scene and step for scenes of ``n`` balls:
    ``max(MIN_EVENT_CAP, EVENTS_PER_BALL * n)`` (10^4, or 1,000 events per ball).

    An ordinary scene never reaches it: a hard-disk gas's collision rate per disk is
    ``omega = 2 sqrt(pi) rho sigma g(sigma) sqrt(kT/m)`` (Enskog; see :mod:`collision_env.observables`),
    so the events per ball of a step of ``dt`` are ``omega dt / 2`` plus its wall impacts: about 6 in a
    1/60 s frame of disks of diameter 0.02 m at unit mean square speed and area fraction 0.7 (a dense
    fluid, Z = 10.3), 160 times below the budget, whatever the number of disks. What reaches it
    is a cascade whose event count does not scale with the step: an inelastic collapse, a light
    ball squeezed by a far heavier one (about ``pi sqrt(M/m)`` collisions, Galperin 2003), a jammed
    network. Such a scene stops after at most ``EVENTS_PER_BALL`` events per ball (a millisecond or
    so of work per ball, some hundred frames' worth of the dense gas) with an
    :class:`EventCapWarning`, in a valid state. A scene whose steps really need more (long steps of
    a dense gas, say) sets ``max_events``."""
    return max(MIN_EVENT_CAP, EVENTS_PER_BALL * int(n))


#: What a step without impacts returns: one shared array of no rows (read-only, as nothing can be
#: written to it; a fresh empty structured array costs more than a small scene's step).
_NO_IMPACTS = np.empty(0, dtype=IMPACT_DTYPE)
_NO_IMPACTS.flags.writeable = False
_NO_IMPACTS_SEQ = Impacts(_NO_IMPACTS)  # (Simulator.step's, as shared)

#: The impact buffer grows to hold a step's impacts up to this many rows (72 MB): a step that fills
#: it is run in calls that each fill it, whose impacts are then joined (a cost per row far below an
#: event's).
MAX_IMPACT_ROWS = 1 << 20


class LiveArrays(NamedTuple):
    """The engine's own state arrays (not copies): see :meth:`BatchSimulator.live_arrays`."""

    balls: np.ndarray  #: (B, N, 8) per-ball state, laid out as ``layout.BALL``
    positions: np.ndarray  #: (B, N, 2) view of ``balls``
    velocities: np.ndarray  #: (B, N, 2) view of ``balls``
    masses: np.ndarray  #: (B, N) view of ``balls``
    radii: np.ndarray  #: (B, N) view of ``balls``
    time: np.ndarray  #: (B,) clocks
    clusters: np.ndarray  #: (B, N) root ball of each ball's cluster
    capped: np.ndarray  #: (B,) the last step stopped at the event cap


class EventCapWarning(RuntimeWarning):
    """A scene reached the cap on events per step and stopped early (in a valid state)."""


class Frames(NamedTuple):
    """A trajectory sampled after each of several equal steps (:meth:`BatchSimulator.frames`,
    :meth:`Simulator.frames`, which drops the batch axis)."""

    time: np.ndarray  #: (F, B) each scene's clock after each step (s)
    positions: np.ndarray  #: (F, B, N, 2) centres after each step (m)
    velocities: np.ndarray  #: (F, B, N, 2) velocities after each step (m/s)
    impacts: Any  #: the steps' impacts, step after step, each step's as ``step`` returns them


def _batch_shapes(sim, n):
    """The shapes of ``n`` frames of a batch: clocks, positions, velocities."""
    return (n, sim._n_scenes), (n, sim._n_scenes, sim._n, 2), (n, sim._n_scenes, sim._n, 2)


def _output_arrays(out, shapes):
    """The first three arrays of ``out`` (:class:`Frames` fields ``time``, ``positions``,
    ``velocities``), checked to be distinct, writable, aligned, C-contiguous float64 arrays of
    ``shapes``."""
    arrays = tuple(out)[:3] if isinstance(out, (tuple, list)) else ()
    if len(arrays) != 3:
        raise ValueError(f"out: expected a Frames or a tuple (time, positions, velocities), got {type(out).__name__}")
    for name, array, shape in zip(Frames._fields[:3], arrays, shapes, strict=True):
        ok = isinstance(array, np.ndarray) and array.dtype == np.float64 and array.shape == shape
        if not (ok and array.flags.c_contiguous and array.flags.aligned and array.flags.writeable):
            got = f"{array.dtype} {array.shape}" if isinstance(array, np.ndarray) else type(array).__name__
            raise ValueError(
                f"out: {name} must be a writable, aligned, C-contiguous float64 array of shape {shape}, got {got}"
            )
    for a in range(3):
        for b in range(a + 1, 3):
            if np.may_share_memory(arrays[a], arrays[b]):
                raise ValueError(f"out: {Frames._fields[a]} and {Frames._fields[b]} must not share memory")
    return arrays


class BatchSimulator:
    """Step ``B`` independent scenes of ``N`` balls each, sharing one :class:`Scene`.

    Parameters
    ----------
    scene:
        The :class:`Scene` every batch member shares.
    positions, velocities:
        ``(B, N, 2)`` arrays in m and m/s.
    masses:
        ``(B, N)`` or ``(N,)`` (the same for every scene), kg.
    radii:
        ``None`` for PhET's mass-to-radius rule, ``"constant"`` for PhET's constant size
        (0.15 m), or explicit radii, ``(B, N)`` or ``(N,)``.
    mode:
        ``"exact"`` (event-driven, machine precision at any dt), ``"posteriori"`` (PhET Collision
        Lab's first engine's overlap-time reconstruction) or ``"naive"`` (move, then reflect overlaps);
        see :data:`~collision_env.engine.modes.MODES`.
    substeps:
        Equal sub-steps per step for naive and posteriori (their speed/accuracy knob), at most
        :data:`MAX_SUBSTEPS` (1e5: a compiled step cannot be interrupted, so this bounds a step's
        work). Exact mode is exact at any step, so it takes only 1.
    max_events:
        Cap on events per scene per step in exact mode. A scene that reaches it stops at its last
        event, in a valid state; :attr:`cap_reached` flags it and an :class:`EventCapWarning` is
        issued. The default, ``None``, is :func:`default_event_cap` of the ball count: a budget per
        ball, far above what a gas spends in a frame, so that only a cascade reaches it.
    collapse_ratio, collapse_floor:
        The inelastic-collapse regulariser: a collision whose normal closing speed is at most
        ``u_min = max(collapse_ratio * s, collapse_floor)`` leaves the pair separating at ``u_min``,
        ``s`` being the fastest speed among the balls of the impact (exact mode; the cheap modes use
        the scene's slowest moving ball), see :mod:`collision_env.engine.physics.response`. The default
        floor, 0, keeps energy from growing beyond round-off at e < 1.

    Inputs are real numbers (numpy scalar types included; booleans, strings and complex numbers
    are refused) with finite, representable values: positions and speeds up to 1e150, masses
    whose inverse is finite, radii that span 2^16 units in the last place of the scene's
    coordinates, and balls that have room to move in the box. Anything else raises a ``ValueError``
    naming the field and the ball, and changes nothing.
    """

    #: Whether shapes in error messages leave out the batch axis (a :class:`Simulator`'s batch of one).
    _single = False

    def __new__(cls, *args: Any, **kwargs: Any) -> BatchSimulator:
        check_keywords(kwargs, _BATCH_KEYWORDS)  # before __init__, whose TypeError names no close match
        return super().__new__(cls)

    def __init__(
        self,
        scene: Scene,
        positions: ArrayLike | Sequence[ArrayLike],
        velocities: ArrayLike | Sequence[ArrayLike],
        masses: ArrayLike,
        radii: ArrayLike | str | None = None,
        *,
        mode: str = "exact",
        substeps: int = 1,
        max_events: int | None = None,
        collapse_ratio: float = 1e-9,
        collapse_floor: float = 0.0,
    ) -> None:
        if not isinstance(scene, Scene):
            raise ValueError(f"scene: expected a collision_env.engine.Scene, got {type(scene).__name__}")
        if not (isinstance(mode, str) and mode in MODE_REGISTRY):
            raise ValueError(f"mode: must be one of {MODES}, got {mode!r}")
        spec = MODE_REGISTRY[mode]
        substeps = positive_integer(substeps, "substeps", MAX_SUBSTEPS)
        if not spec.substeps and substeps != 1:
            raise ValueError(f"substeps: {mode} mode resolves every event at its exact time; substeps must be 1")
        if max_events is not None:
            max_events = positive_integer(max_events, "max_events")
        if not (is_real(collapse_ratio) and 0.0 <= float(collapse_ratio) < 1.0):
            raise ValueError(f"collapse_ratio: must be a number in [0, 1), got {collapse_ratio!r}")
        if not (is_real(collapse_floor) and 0.0 <= float(collapse_floor) < MAX_MAGNITUDE):
            raise ValueError(f"collapse_floor: must be a finite speed >= 0 (m/s), got {collapse_floor!r}")
        self.scene = scene
        self._mode = mode
        self._spec = spec
        self._substeps = substeps
        self._max_events = max_events
        self._collapse_ratio = float(collapse_ratio)
        self._collapse_floor = float(collapse_floor)

        try:
            shape = np.shape(cast(ArrayLike, positions))  # (numpy's ArrayLike leaves out lists of arrays)
        except ValueError:  # numpy refuses ragged nesting
            shape = None
        if shape is None or len(shape) != 3 or shape[-1] != 2:
            got = "a ragged sequence" if shape is None else shape
            raise ValueError(f"positions: expected shape (B, N, 2), got {got}")
        n_scenes, n = shape[0], shape[1]
        if n_scenes < 1 or n < 1:
            raise ValueError(f"positions: need at least one scene and one ball, got shape {shape}")
        self._n_scenes = n_scenes
        self._n = n
        if max_events is None:
            self._max_events = default_event_cap(n)
        self._label = Labels(n_scenes, self._single)
        pos, vel, mass, radius = checked_balls(
            scene, self._label, np.arange(n_scenes), n, positions, velocities, masses, radii
        )
        pos, images = self._wrapped(pos)
        # Every per-ball float lives in one (B, N, 8) array, _pos, _vel, ... are views into it: each
        # array handed to a kernel costs ~0.1 us per call, which is most of a small scene's step.
        self._balls = aligned_zeros((n_scenes, n, len(BALL)), np.float64)
        self._bind_views()
        self._pos[...] = pos
        self._vel[...] = vel
        self._mass[...] = mass
        self._inv_mass[...] = 1.0 / mass
        self._radius[...] = radius
        self._body = np.tile(np.arange(n, dtype=np.int64), (n_scenes, 1))
        self._images = images  # (a periodic cell's lengths crossed by each ball; zeros otherwise)
        self._time = np.zeros(n_scenes)
        self._clock = np.zeros((n_scenes, 2))  # per scene: _time as the clock set it, its compensation
        self._capped = np.zeros(n_scenes, dtype=np.bool_)
        self._counters = np.zeros(len(COUNTERS), dtype=np.int64)

        bounds = scene.bounds if scene.bounds is not None else (0.0, 0.0, 0.0, 0.0)
        scene_f = dict(
            zip(("xmin", "ymin", "xmax", "ymax"), bounds, strict=True),
            elasticity=scene.elasticity,
            collapse_ratio=self.collapse_ratio,
            sign=1.0,
            collapse_floor=self.collapse_floor,
        )
        scene_i = dict(
            has_walls=scene.bounds is not None and not scene.periodic,
            pairs=scene.ball_collisions and n > 1,
            dim=scene.dimension,
            sticky=scene.sticky,
            max_events=self.max_events,
            substeps=self.substeps,
        )
        self._fparams = np.array([scene_f[name] for name in SCENE_F])
        self._iparams = np.array([scene_i[name] for name in SCENE_I], dtype=np.int64)
        self._work_f = np.zeros((n_scenes, len(WORK_F)))
        self._work_i = np.zeros((n_scenes, len(WORK_I)), dtype=np.int64)
        # the mode's own arrays (exact mode's event calendar and grid, kept from step to step, and work
        # space), and its kernel for this kind of scene
        self._mode_arrays = spec.arrays(scene, n_scenes, n)
        self._kernel = spec.kernel(scene, n)
        self._after_step = START_NEXT  # (see _step)
        self._invalidate(np.arange(n_scenes))
        self._alloc_work()

    # ------------------------------------------------------------------ stepping
    def _bind_views(self):
        b = self._balls
        self._pos = b[..., B_X : B_X + 2]
        self._vel = b[..., B_VX : B_VX + 2]
        self._mass = b[..., B_MASS]
        self._inv_mass = b[..., B_INV_MASS]
        self._radius = b[..., B_RADIUS]
        self._omega = b[..., B_OMEGA]

    def _wrapped(self, pos):
        """Positions ``(K, N, 2)`` wrapped into a periodic scene's cell, and the periods each was
        moved by (zeros, and ``pos`` itself, in other scenes)."""
        if not self.scene.periodic or self.scene.bounds is None:
            return pos, np.zeros(pos.shape, dtype=np.int64)
        return wrap_positions(pos, self.scene.bounds, self.scene.dimension)

    def _invalidate(self, scenes):
        """Drop the calendar's predictions for ``scenes`` (they are made afresh at the next step)
        and lay out their grid for the balls they now hold."""
        period = self.scene.period if self.scene.periodic else None
        origin_and_cells, counts = grid_geometry(
            self.scene.bounds,
            self._pos[scenes],
            self._radius[scenes],
            self._uses_grid(),
            **self._spec.grid,
            period=period,
        )
        self._work_f[scenes, W_GRID_X0 : W_GRID_X0 + 4] = origin_and_cells
        self._work_i[scenes, W_GRID_NX : W_GRID_NX + 2] = counts
        self._work_i[scenes, W_CALENDAR_VALID] = 0
        self._start = START_STEP

    def _uses_grid(self):
        """The broad phase pays only in large scenes with ball pairs (and no stick clusters)."""
        return self.scene.ball_collisions and self._n >= GRID_MIN_BALLS and not self.scene.sticky

    def _alloc_work(self, rows=None):
        if rows is None:
            rows = self._spec.impact_rows(self.scene, self._n, self._uses_grid())
        self._imp = np.empty(rows, dtype=IMPACT_DTYPE)
        self._imp_bytes = self._imp.view(np.uint8).data
        counts = getattr(self, "_n_imp", None)  # (kept when the buffer grows in the middle of a step)
        self._n_imp = np.zeros(3, dtype=np.int64)  # rows filled, scenes that reached the cap, stalled
        if counts is not None:
            self._n_imp[:] = counts
        # the kernel's arguments, packed once (the arrays are only ever updated in place)
        self._state = State(
            self._balls,
            self._body,
            self._time,
            self._capped,
            self._fparams,
            self._iparams,
            self._imp,
            self._n_imp,
            self._counters,
            self._work_f,
            self._work_i,
            self._clock,
            self._images,
        )
        self._pack = pack(self._state, *self._mode_arrays, frames=True)
        self._sign = float(self._fparams[S_SIGN])  # the direction _fparams are set for (see step)
        # step's fast path applies (not to periodic scenes: each step's laps are checked)
        self._forward = self._sign > 0.0 and self.scene.bounds is not None and not self.scene.periodic
        self._live = LiveArrays(
            self._balls, self._pos, self._vel, self._mass, self._radius, self._time, self._body, self._capped
        )

    def step(self, dt: float) -> np.ndarray:
        """Advance every scene by ``dt`` seconds (``dt < 0`` runs time backwards).

        Returns the impacts inside the step as an array of :data:`IMPACT_DTYPE`, ordered by scene
        and then by the order in which they happened.

        ``dt`` is a real number (numpy scalars included) of at most 1e150 s; without a border, the
        step must also keep every ball within 1e150 m. The clocks are compensated sums: after any
        number of steps ``time`` is within an ulp of the exact sum of the ``dt`` taken (forward and
        back again returns it to exactly where it was). Backwards, a bounce at elasticity e < 1
        multiplies a speed by 1/e, and the bounces come ever faster: a past that reaches infinite
        speed within the step raises a ``ValueError`` naming the ball, and changes nothing.
        """
        return self._step(dt)

    def _step(self, dt, stacklevel=4):
        """:meth:`step`, with the ``stacklevel`` of its warning (see :meth:`_finish`).

        A step that follows a completed forward step, with nothing changed in between, starts with
        ``START_NEXT``: the kernel then need not compare every ball with its calendar record, which
        is most of a small scene's fixed cost. ``_start`` says which: every other way of changing the
        state (a nudge, ``set_scenes``, ``set_state``, ``load``, a step of another kind, ``frames``)
        sets it back to ``START_STEP``, and once :meth:`live_arrays` has handed the arrays out, where
        anyone may write them, it stays there."""
        dt = real_number(dt, "dt")
        if self._forward and 0.0 < dt <= MAX_MAGNITUDE:  # the common case, checked in one test
            rows = self._kernel(self._pack, dt, self._start)
            if rows >= 0:  # no scene stalled or reached the event cap
                self._start = self._after_step
                return self._take_impacts(rows) if rows else _NO_IMPACTS
            self._start = START_STEP
            return self._finish(self._run(dt, first_done=True), 1.0, stacklevel)
        self._start = START_STEP
        check_seconds(dt, "dt")
        if self.scene.bounds is None:
            check_reach(self._pos, self._vel, dt, self._label)
        if self.scene.periodic:
            check_laps(self.scene, self._mass, self._vel, dt, self._label)
        e = self.scene.elasticity
        if dt < 0.0 and e == 0.0:
            raise ValueError(
                "dt: cannot step backwards with elasticity 0 (a perfectly inelastic collision has no inverse)"
            )
        if dt == 0.0:
            self._capped[:] = False
            return _NO_IMPACTS
        sign = 1.0 if dt > 0.0 else -1.0
        if sign != self._sign:  # reverse steps use 1/e
            fp = self._fparams
            fp[S_ELASTICITY] = e if sign > 0 else 1.0 / e
            fp[S_SIGN] = sign
            self._sign = sign
            self._forward = sign > 0.0 and self.scene.bounds is not None and not self.scene.periodic
        # reversed, a bounce at e < 1 multiplies the speed by 1/e, and the bounces come ever faster:
        # a past may diverge within finite time. Such a step is refused, from a copy kept here.
        before = self._saved() if sign < 0 and e < 1.0 else None
        if sign < 0:
            np.negative(self._vel, out=self._vel)
            np.negative(self._omega, out=self._omega)
        try:
            chunks = self._run(abs(dt))
        finally:
            if sign < 0:
                np.negative(self._vel, out=self._vel)
                np.negative(self._omega, out=self._omega)
        if before is not None:
            self._refuse_divergent_past(before, dt)
        return self._finish(chunks, sign, stacklevel)

    def _refuse_divergent_past(self, before: list[np.ndarray], dt: float) -> None:
        """After a backward step at e < 1: if a ball's speed or position overflowed, restore
        ``before`` (:meth:`_saved` before the step) and raise a ValueError naming the ball."""
        motion = self._balls[..., B_X : B_VX + 2]  # (positions and velocities)
        if not np.isfinite(motion).all():
            s, i = np.argwhere(~np.isfinite(motion).all(-1))[0]
            for mine, saved in zip(self._stepped_arrays(), before, strict=True):
                np.copyto(mine, saved)
            e = self.scene.elasticity
            raise ValueError(
                f"dt: the past of {self._label(s, i).rstrip(': ')} diverges within this step of {dt:g} s: "
                f"reversed, each bounce at elasticity {e:g} multiplies its speed by {1.0 / e:.6g}, and the "
                "bounces come ever faster, until the speed overflows (the state is unchanged)"
            )

    def frames(self, dt: float, n: int, out: Frames | None = None) -> Frames:
        """Take ``n`` steps of ``dt`` seconds, recording every scene after each one.

        The same as ``n`` calls of :meth:`step` (the same kernel: the same impacts, states and
        clocks, bit for bit), but forward steps with a border run as one compiled loop, which
        saves the cost of a call from Python per step: about a microsecond, as much as an event
        of a sparse gas. Returns :class:`Frames` of ``n`` rows; its ``impacts`` are every step's
        impacts in step order, each step's as :meth:`step` returns them (by scene, then time).
        ``out``: the arrays to record into (a :class:`Frames` of ``n`` rows from an earlier call,
        say; its ``impacts`` are not used), instead of new ones: writing a trajectory into new
        memory costs the operating system's first touch of every page, which is more than the
        steps of a sparse gas. A step that raises stops the run there, as it would stop a loop
        (after the steps before it).

        >>> scene = Scene(bounds=(-1.0, -1.0, 1.0, 1.0))
        >>> sim = BatchSimulator(scene, [[[0.0, 0.0]], [[0.5, 0.0]]], [[[1.0, 0.0]], [[0.0, 0.0]]], [1.0], [0.25])
        >>> rec = sim.frames(0.5, 4)
        >>> rec.positions.shape, rec.time[:, 0].tolist(), rec.positions[:, 0, 0, 0].tolist()
        ((4, 2, 1, 2), [0.5, 1.0, 1.5, 2.0], [0.5, 0.5, 0.0, -0.5])
        >>> rec.impacts[["scene", "time", "wall"]].tolist()
        [(0, 0.75, 1)]
        """
        return self._frames(dt, n, out, _batch_shapes)

    def _frames(self, dt, n, out, shapes_of):
        """:meth:`frames`, with ``out`` checked against ``shapes_of(self, n)`` (the shapes the
        caller documents; its arrays are then viewed with the batch axis). Called straight from
        each public ``frames``, so that a warning names their caller."""
        dt = real_number(dt, "dt")
        check_seconds(dt, "dt")
        self._start = START_STEP
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral) or n < 0:
            raise ValueError(f"n: must be a whole number of steps (0 or more), got {n!r}")
        n = int(n)
        if out is None:
            times, positions, velocities = (np.empty(shape) for shape in _batch_shapes(self, n))
        else:  # (a single simulator's arrays gain the batch axis as a view)
            arrays = zip(_output_arrays(out, shapes_of(self, n)), _batch_shapes(self, n), strict=True)
            times, positions, velocities = (a.reshape(shape) for a, shape in arrays)
        pieces = []
        f = 0
        buffer = None  # the compiled loop's copy of the impacts
        size = len(self._imp)
        if self.scene.periodic:  # (the run's laps, checked once: a periodic step has no fast path)
            check_laps(self.scene, self._mass, self._vel, dt * n, self._label)
        while f < n:
            forward = self._forward or (self.scene.periodic and self._sign > 0.0)
            if not (forward and 0.0 < dt <= MAX_MAGNITUDE):
                # backwards or without a border: a step as step takes it (which may make the next
                # ones forward steps with a border)
                pieces.append(self._step(dt, stacklevel=5))
                record_frame(f, self._balls, self._time, times, *self._frame_rows(positions, velocities))
                f += 1
                continue
            if buffer is None:
                buffer = np.empty(size, dtype=IMPACT_DTYPE)
            f, stepped, rows = self._run_frames(dt, f, n, times, positions, velocities, buffer)
            if rows:  # (kept, if at least half full: the next run gets a buffer of its own)
                pieces.append(buffer[:rows] if 2 * rows >= len(buffer) else buffer[:rows].copy())
            buffer = None
            if f == n:
                break
            # frame f's impacts did not fit (the next frames get a buffer twice the size), or
            # its step needs completing, as step completes it
            if stepped:
                pieces.append(self._take_impacts(self._n_imp[0]))
                size *= 2
            else:
                pieces.append(self._finish(self._run(dt, first_done=True), 1.0, stacklevel=4))
            record_frame(f, self._balls, self._time, times, *self._frame_rows(positions, velocities))
            f += 1
        if len(pieces) == 1:
            impacts = pieces[0]
        else:
            impacts = np.concatenate(pieces) if pieces else _NO_IMPACTS.copy()
        return Frames(times, positions, velocities, impacts)

    @staticmethod
    def _frame_rows(positions: np.ndarray, velocities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(F, B, N, 2) frames as the kernels record them: (F, B * N, 2) views."""
        f, b, n, _ = positions.shape
        return positions.reshape(f, b * n, 2), velocities.reshape(f, b * n, 2)

    def _run_frames(self, dt, first, n, times, positions, velocities, buffer):
        """Frames ``first`` to ``n - 1`` in one call of the kernel (see ``frames.frames_kernel``),
        the impacts into ``buffer``. Returns ``(f, stepped, rows)``: every frame was recorded if
        ``f == n``; else frame ``f`` was not, and ``stepped`` says whether its step was taken (its
        impacts did not fit ``buffer``) or needs completing; ``rows`` of ``buffer`` were written."""
        request = np.zeros(len(FRAME_FIELDS), dtype=np.int64)
        request[FRAME_FIRST] = first
        request[FRAME_LAST] = n
        out = FramesOut(request, times, *self._frame_rows(positions, velocities), buffer)
        self._kernel(with_frames(self._pack, self._spec.frames_slot, out), dt, RUN_FRAMES)
        return int(request[FRAME_STOPPED_AT]), bool(request[FRAME_STEPPED]), int(request[FRAME_ROWS])

    def _finish(self, chunks, sign, stacklevel):
        """Warn about scenes that reached the event cap; the step's impacts as one array.
        ``stacklevel`` names the caller of ``step`` or ``frames`` (4 from step: _finish, _step,
        step; 5 from a step of frames: _finish, _step, _frames, frames)."""
        if self._n_imp[1]:
            warnings.warn(
                f"event cap of {self.max_events} per step reached in scene(s) {np.flatnonzero(self._capped).tolist()}; "
                "they stopped early at their last event (see cap_reached and time)",
                EventCapWarning,
                stacklevel=stacklevel,
            )
        if not chunks:
            return _NO_IMPACTS
        if len(chunks) == 1:
            return chunks[0]
        out = np.concatenate(chunks)  # a stalled step: a scene's impacts may span chunks
        if self._n_scenes == 1:  # (one scene's chunks come in its order: each resumes where the last stopped)
            return out
        return out[np.lexsort((sign * out["time"], out["scene"]))]

    def _run(self, dt_abs, first_done=False):
        """Run the mode's kernel until every scene has stepped ``dt_abs``; the impacts in chunks,
        one per call (a call stops the scenes that find the impact buffer full, which the next
        call resumes). ``first_done``: the step's first call was made already."""
        chunks = []
        kernel, n_imp = self._kernel, self._n_imp
        if not first_done:
            kernel(self._pack, dt_abs, START_STEP)
        while True:  # each call resets n_imp[0] and fills the impact buffer from row 0
            rows = n_imp[0]
            if rows:
                chunks.append(self._take_impacts(rows))
            if not n_imp[2]:  # no scene stalled
                if len(chunks) > 1:  # the next steps like this one fit the buffer, up to MAX_IMPACT_ROWS
                    total = sum(len(chunk) for chunk in chunks)
                    self._alloc_work(max(len(self._imp), min(MAX_IMPACT_ROWS, 1 << (total - 1).bit_length())))
                return chunks
            if not rows:  # not even one sub-step's worst case fits: a bigger buffer
                self._alloc_work(2 * len(self._imp))
                n_imp = self._n_imp
            kernel(self._pack, dt_abs, RESUME)

    def _take_impacts(self, rows):
        """A copy of the first ``rows`` impact records. Exact mode records each scene's impacts in
        the order they happen, scenes in order; the cheap modes' reconstructed times need sorting
        within each scene."""
        if self._spec.sorted_impacts:
            # (numpy copies structured arrays slowly: a byte copy is several times cheaper)
            return np.ndarray(rows, IMPACT_DTYPE, bytearray(self._imp_bytes[: rows * IMPACT_DTYPE.itemsize]))
        out = np.empty(rows, dtype=IMPACT_DTYPE)
        copy_impacts(self._imp, out, self._sign)
        return out

    # ------------------------------------------------------------------ state access
    @property
    def num_scenes(self) -> int:
        return self._n_scenes

    @property
    def num_balls(self) -> int:
        return self._n

    # The state properties are read-only snapshots: a write to one raises ("assignment destination
    # is read-only") rather than being dropped; set_scenes, nudge and set_state change the state.
    @property
    def positions(self) -> np.ndarray:
        """``(B, N, 2)`` centres, m (a read-only snapshot)."""
        return _snapshot(self._pos)

    @property
    def velocities(self) -> np.ndarray:
        """``(B, N, 2)`` velocities, m/s (a read-only snapshot)."""
        return _snapshot(self._vel)

    @property
    def masses(self) -> np.ndarray:
        """``(B, N)`` masses, kg (a read-only snapshot)."""
        return _snapshot(self._mass)

    @property
    def radii(self) -> np.ndarray:
        """``(B, N)`` radii, m (a read-only snapshot)."""
        return _snapshot(self._radius)

    @property
    def time(self) -> np.ndarray:
        """``(B,)`` each scene's clock, s (a read-only snapshot)."""
        return _snapshot(self._time)

    @property
    def images(self) -> np.ndarray:
        """``(B, N, 2)`` int64: how many periodic cell lengths each ball has crossed along x and y
        (zeros unless the scene is periodic); see :attr:`unwrapped_positions`."""
        return self._images.copy()

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(B, N, 2)`` centres as if the periodic cell did not wrap them, m: ``positions + images *
        (lx, ly)`` (``Scene.period``), which moves continuously (for mean squared displacements and
        diffusion). The positions themselves outside a periodic scene."""
        return self._pos + self._images * np.array(self.scene.period)

    @property
    def clusters(self) -> np.ndarray:
        """``(B, N)``: the index of the ball rooting each ball's rigid cluster (itself if free)."""
        return _snapshot(self._body)

    @property
    def cap_reached(self) -> np.ndarray:
        """``(B,)`` bool: the event cap stopped that scene's last step early."""
        return _snapshot(self._capped)

    # the settings are fixed at construction: the kernels are bound to them (make a new simulator
    # to change one; get_state/set_state carry a state across)
    mode = property(lambda self: self._mode, doc='"naive", "posteriori" or "exact".')
    substeps = property(lambda self: self._substeps, doc="Sub-steps per step (naive and posteriori).")
    max_events = property(lambda self: self._max_events, doc="Event cap per step and scene (exact).")
    collapse_ratio = property(lambda self: self._collapse_ratio, doc="Collapse regulariser: u_min / fastest speed.")
    collapse_floor = property(lambda self: self._collapse_floor, doc="Collapse regulariser: smallest u_min, m/s.")

    def live_arrays(self) -> LiveArrays:
        """The engine's own state arrays, not copies, for compiled kernels that read them every
        step (the envs' kernels). Every step updates them in place. Treat them as read-only, except
        through the engine's own kernels (``motion.apply_impulses`` is how the envs nudge).
        From then on every step compares each ball with the state the last step left it in."""
        self._start = self._after_step = START_STEP
        return self._live

    @property
    def models(self) -> dict[str, Any]:
        """What the engine computes for this scene, and nothing else."""
        return {
            "mode": self.mode,
            "substeps": self.substeps,
            "dimension": self.scene.dimension,
            "walls": self.scene.bounds is not None and not self.scene.periodic,
            "periodic": self.scene.periodic,
            "ball_pairs": bool(self._iparams[S_PAIRS]),
            "clusters": self.scene.sticky,
            "backend": BACKEND,
        }

    @property
    def stats(self) -> dict[str, int]:
        """Work done so far: pair and wall predictions (or overlap tests), events, rotating-cluster
        predictions, grid-cell crossings and stale calendar entries re-predicted (exact mode)."""
        return {name: int(count) for name, count in zip(COUNTERS, self._counters, strict=True)}

    def kinetic_energy(self) -> np.ndarray:
        """``(B,)`` total kinetic energy, J."""
        return 0.5 * (self._mass * (self._vel**2).sum(-1)).sum(-1)

    def momentum(self) -> np.ndarray:
        """``(B, 2)`` total momentum, kg m/s."""
        return (self._mass[..., None] * self._vel).sum(1)

    # ------------------------------------------------------------------ changing the state
    def nudge(self, dv: ArrayLike | Sequence[ArrayLike], check: bool = True) -> None:
        """Change every ball's velocity by ``dv`` (``(B, N, 2)``), as an impulse ``m dv``.

        A member of a stuck cluster passes the impulse to the whole cluster (linear and angular).
        ``check=False`` skips validation, for callers that build ``dv`` as a float64 array of the
        right shape with finite values (and zero y in 1D) themselves, where the checks would cost
        more than the nudge. (The envs nudge from their own kernel, through ``motion.apply_impulses``,
        the function this calls.)
        """
        if check:
            dv = checked_nudge(dv, self.scene, self._vel, self._mass, self._label)
        self._start = START_STEP
        apply_impulses(self._balls, self._body, dv, self.scene.sticky)

    def set_scenes(
        self,
        index: ArrayLike,
        positions: ArrayLike | Sequence[ArrayLike],
        velocities: ArrayLike | Sequence[ArrayLike],
        masses: ArrayLike | None = None,
        radii: ArrayLike | str | None = None,
        time: ArrayLike = 0.0,
    ) -> None:
        """Start the scenes picked by ``index`` (indices or a ``(B,)`` bool mask) afresh.

        ``positions``/``velocities`` are ``(K, N, 2)`` for the K scenes picked; ``masses`` and
        ``radii`` default to those the scenes had. Validated like the constructor; on error
        nothing changes.
        """
        time = real_number(time, "time")
        check_seconds(time, "time")
        try:  # (indices or a mask: numpy's indexing decides)
            idx = np.atleast_1d(np.arange(self._n_scenes)[cast(Any, index)])
        except IndexError:
            idx = None
        if idx is None or idx.ndim != 1:
            raise ValueError(
                f"index: expected scene indices within the batch of {self._n_scenes} (negative ones count "
                f"from its end) or a ({self._n_scenes},) bool mask, got {index!r}"
            )
        if masses is None:
            masses = self._mass[idx]
        if radii is None:
            radii = self._radius[idx]
        pos, vel, m, r = checked_balls(self.scene, self._label, idx, self._n, positions, velocities, masses, radii)
        pos, images = self._wrapped(pos)
        self._pos[idx] = pos
        self._images[idx] = images
        self._vel[idx] = vel
        self._mass[idx] = m
        self._inv_mass[idx] = 1.0 / m
        self._radius[idx] = r
        self._body[idx] = np.arange(self._n)
        self._omega[idx] = 0.0
        self._time[idx] = time
        self._invalidate(idx)
        self._clock[idx] = (time, 0.0)

    def get_state(self) -> dict[str, np.ndarray]:
        """A dict of array copies that :meth:`set_state` restores exactly."""
        return {
            "positions": self._pos.copy(),
            "velocities": self._vel.copy(),
            "masses": self._mass.copy(),
            "radii": self._radius.copy(),
            "clusters": self._body.copy(),
            "omega": self._omega.copy(),
            "time": self._time.copy(),
            "time_compensation": self._clock[:, 1].copy(),
            "images": self._images.copy(),
        }

    def set_state(self, state: Mapping[str, ArrayLike]) -> None:
        """Restore a state from :meth:`get_state`.

        Checked as the constructor checks its balls (shapes, number types, finite and representable
        values, balls inside the border and apart, none spanning the box), and beyond that: the
        clusters are ball indices whose roots are their own roots (every ball its own cluster unless
        the scene sticks), a stick cluster's balls move as one rigid body and touch one another in a
        network, spins are within 1e150 rad/s, the clocks are times the constructor would accept,
        each with a compensation below an ulp of it. In naive and posteriori modes, whose steps may
        end with balls overlapping, overlaps (and touching balls from wall to wall, which these
        modes step like any others) are accepted, and so are stick clusters whose balls do not
        quite touch. Bad input raises a ``ValueError`` naming the scene, ball and field, and
        changes nothing. ``images`` may be left out (zeros); in a
        periodic scene, positions outside the cell are wrapped into it, their images counted.
        """
        shapes = {
            "positions": self._pos.shape,
            "velocities": self._vel.shape,
            "masses": self._mass.shape,
            "radii": self._radius.shape,
            "clusters": self._body.shape,
            "omega": self._omega.shape,
            "time": self._time.shape,
            "time_compensation": self._time.shape,
        }
        if not isinstance(state, Mapping):
            raise TypeError(f"state: expected a dict with the keys {list(shapes)}, got {type(state).__name__}")
        missing = [key for key in shapes if key not in state]
        if missing:
            raise ValueError(f"state: missing {missing} (a state has the keys {list(shapes)}, as get_state gives)")
        arrays = {}
        if "images" in state:
            shapes["images"] = self._images.shape
        for key, shape in shapes.items():
            a = np.asarray(state[key])
            if a.shape != shape:
                raise ValueError(
                    f"state {key}: expected shape {self._label.shape(shape)}, got {self._label.shape(a.shape)}"
                )
            whole = key in ("clusters", "images")
            kinds = "iu" if whole else "iuf"
            if a.dtype.kind not in kinds:
                raise ValueError(
                    f"state {key}: expected {'integers' if whole else 'real numbers'}, got dtype {a.dtype}"
                )
            if a.dtype.kind == "f" and not np.isfinite(a).all():  # (integers always are)
                raise ValueError(f"state {key}: values must be finite")
            arrays[key] = a
        scenes = np.arange(self._n_scenes)
        pos, vel, mass, radius = checked_balls(
            self.scene,
            self._label,
            scenes,
            self._n,
            arrays["positions"],
            arrays["velocities"],
            arrays["masses"],
            arrays["radii"],
            overlaps=self._spec.leaves_overlaps,
        )
        self._check_clusters(arrays["clusters"], arrays["omega"])
        if self.scene.sticky:
            touching = not self._spec.leaves_overlaps  # (the cheap modes stick balls a sub-step apart)
            check_stick_clusters(pos, vel, mass, radius, arrays["clusters"], arrays["omega"], self._label, touching)
        for sc in scenes:
            time, compensation = float(arrays["time"][sc]), float(arrays["time_compensation"][sc])
            check_seconds(time, f"state time: {self._label(sc)}".rstrip(": "))
            if not abs(compensation) <= np.spacing(abs(time)):
                raise ValueError(
                    f"state time_compensation: {self._label(sc)}must be within an ulp of the time "
                    f"({np.spacing(abs(time)):.3g} s at {time:g} s), got {compensation:g}"
                )
        pos, images = self._wrapped(pos)
        if "images" in arrays:
            images = images + self._checked_images(arrays["images"], images)
        np.copyto(self._pos, pos)
        np.copyto(self._images, images)
        np.copyto(self._vel, vel)
        np.copyto(self._mass, mass)
        np.copyto(self._inv_mass, 1.0 / mass)
        np.copyto(self._radius, radius)
        np.copyto(self._body, arrays["clusters"])
        np.copyto(self._omega, arrays["omega"])
        np.copyto(self._time, arrays["time"])
        self._clock[:, 0] = arrays["time"]
        self._clock[:, 1] = arrays["time_compensation"]
        self._invalidate(scenes)

    def _checked_images(self, given: np.ndarray, wrapped: np.ndarray) -> np.ndarray:
        """``set_state``'s images (integers), as int64: each, and its sum with the periods
        ``wrapped`` that wrapping the positions added, within ``MAX_IMAGES`` (raises ValueError)."""
        if -MAX_IMAGES <= given.min() and given.max() <= MAX_IMAGES:  # (then their sum cannot overflow)
            images = given.astype(np.int64)
            if not wrapped.any():
                return images
            far = np.abs(images + wrapped) > MAX_IMAGES
            if not far.any():
                return images
        else:  # (compared as integers: beyond 2**53, a float64 could round a count into range)
            far = (given < -MAX_IMAGES) | (given > MAX_IMAGES)
        s, i, axis = np.argwhere(far)[0]
        raise ValueError(
            f"state images: {self._label(s, i)}expected at most 2**53 periods from the cell, "
            f"got {given[s, i, axis]} along {'xy'[axis]}"
        )

    def _check_clusters(self, clusters, omega):
        """``set_state``'s clusters and spins: each ball's root is a ball index and its own root (every
        ball its own without stick clusters), and spins are representable (raises ValueError)."""
        n = self._n
        if not self.scene.sticky:  # (every ball its own cluster: its own root too)
            bad = clusters != np.arange(n)
        else:
            bad = (clusters < 0) | (clusters >= n)
            if not bad.any():
                bad = np.take_along_axis(clusters, clusters, axis=1) != clusters
        if bad.any():
            s, i = np.argwhere(bad)[0]
            expected = "a ball index whose cluster is its own" if self.scene.sticky else f"{i} (no stick clusters)"
            raise ValueError(f"state clusters: {self._label(s, i)}expected {expected}, got {clusters[s, i]}")
        spin = ~(np.abs(omega) <= MAX_MAGNITUDE)
        if spin.any():
            s, i = np.argwhere(spin)[0]
            raise ValueError(
                f"state omega: {self._label(s, i)}expected within {MAX_MAGNITUDE:g} rad/s, got {omega[s, i]}"
            )

    def copy(self) -> BatchSimulator:
        """An independent copy (for planning: step it ahead without touching this one)."""
        return copy.deepcopy(self)

    def load(self, other: BatchSimulator) -> None:
        """Take ``other``'s whole state in place: balls, clusters, clocks and, in exact mode, its
        event calendar, so that stepping this simulator on does exactly what stepping ``other``
        would, with nothing predicted afresh. For a planning simulator that copies a running one at
        every step (:meth:`set_state` checks its input and re-predicts every scene). ``other`` has
        the same scene, shape and mode; its other settings (sub-steps, the event cap) may differ
        and are this simulator's own."""
        if not isinstance(other, BatchSimulator):
            raise TypeError(f"other: expected a BatchSimulator, got {type(other).__name__}")
        if (other.scene, other.mode, other._balls.shape) != (self.scene, self.mode, self._balls.shape):
            raise ValueError(
                f"other: a simulator of the same scene, mode and shape, got mode {other.mode!r} and shape "
                f"{other._balls.shape[:2]} (this one: {self.mode!r}, {self._balls.shape[:2]})"
            )
        for mine, theirs in zip(self._stepped_arrays(), other._stepped_arrays(), strict=True):
            np.copyto(mine, theirs)
        for field in (S_ELASTICITY, S_SIGN):  # (the direction of time the state is kept for)
            self._fparams[field] = other._fparams[field]
        self._sign = other._sign
        self._forward = other._forward
        self._start = START_STEP

    def _stepped_arrays(self) -> list[np.ndarray]:
        """The arrays a step changes: balls, clusters, clocks and, in exact mode, the event
        calendar (what :meth:`load` takes from another simulator)."""
        arrays = [
            self._balls,
            self._body,
            self._time,
            self._clock,
            self._capped,
            self._work_f,
            self._work_i,
            self._images,
        ]
        return arrays + list(self._mode_arrays[0]) if self._spec.persistent else arrays

    def _saved(self) -> list[np.ndarray]:
        """Copies of :meth:`_stepped_arrays`, to restore a step's start from."""
        return [a.copy() for a in self._stepped_arrays()]

    #: What a copy or a pickle rebuilds rather than carries: work space, and what is bound to it.
    _REBUILT = (
        "_imp", "_imp_bytes", "_n_imp", "_kernel", "_state", "_pack", "_sign", "_forward", "_live", "_pos", "_vel",
        "_mass", "_inv_mass", "_radius", "_omega", "_label", "_spec", "_start", "_after_step",
    )  # fmt: skip

    def __getstate__(self):
        state = {key: value for key, value in self.__dict__.items() if key not in self._REBUILT}
        if self._spec.persistent:  # (exact mode's calendar persists; its work space is made anew)
            state["_mode_arrays"] = self._mode_arrays[:1]
        else:
            state["_mode_arrays"] = ()
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._spec = MODE_REGISTRY[self._mode]
        # a copy or an unpickled array has numpy's alignment
        self._balls = aligned_copy(self._balls)
        fresh = self._spec.arrays(self.scene, self._n_scenes, self._n)
        kept = tuple(type(b)(*(aligned_copy(a) for a in b)) for b in self._mode_arrays)
        self._mode_arrays = kept + fresh[len(kept) :]
        self._kernel = self._spec.kernel(self.scene, self._n)
        self._label = Labels(self._n_scenes, self._single)
        self._start = START_STEP
        self._after_step = START_NEXT
        self._bind_views()
        self._alloc_work()

    def __deepcopy__(self, memo):
        new = object.__new__(type(self))
        new.__setstate__(copy.deepcopy(self.__getstate__(), memo))
        return new

    def __copy__(self):  # a shallow copy would share the state arrays but not the bookkeeping around them
        return self.copy()


#: The keyword arguments BatchSimulator takes (a misspelled one is named with the closest of them).
_BATCH_KEYWORDS = tuple(inspect.signature(BatchSimulator.__init__).parameters)[1:]


class Simulator:
    """One scene: the engine's public surface for a single simulation.

    ``Simulator(scene, positions (N,2), velocities (N,2), masses (N,), radii=None, mode="exact",
    substeps=1)``; :meth:`step` returns the step's :class:`Impacts` in time order. Everything is a
    batch of one over :class:`BatchSimulator`; keyword arguments pass through to it.
    """

    def __init__(
        self,
        scene: Scene,
        positions: ArrayLike,
        velocities: ArrayLike,
        masses: ArrayLike,
        radii: ArrayLike | str | None = None,
        mode: str = "exact",
        substeps: int = 1,
        **options: Any,
    ) -> None:
        try:
            shape = np.shape(positions)
        except ValueError:  # numpy refuses ragged nesting
            shape = None
        if shape is None or len(shape) != 2:
            got = "a ragged sequence" if shape is None else shape
            raise ValueError(f"positions: expected shape (N, 2), got {got}")
        check_keywords(options, _BATCH_KEYWORDS)
        # a batch of one whose errors give shapes as this simulator takes them
        self._batch = object.__new__(BatchSimulator)
        self._batch._single = True
        BatchSimulator.__init__(
            self._batch, scene, [positions], [velocities], masses, radii, mode=mode, substeps=substeps, **options
        )

    @property
    def batch(self) -> BatchSimulator:
        """The underlying batch of one."""
        return self._batch

    @property
    def scene(self) -> Scene:
        return self._batch.scene

    @property
    def mode(self) -> str:
        return self._batch.mode

    def step(self, dt: float) -> Impacts:
        """Advance by ``dt`` seconds (negative: backwards). Returns the step's impacts in time order,
        as :class:`Impacts` (a sequence of :class:`Impact` over their records)."""
        rows = self._batch._step(dt)
        return _NO_IMPACTS_SEQ if rows is _NO_IMPACTS else Impacts(rows)

    def frames(self, dt: float, n: int, out: Frames | None = None) -> Frames:
        """``n`` steps of ``dt`` seconds in one call, recording the state after each:
        :meth:`BatchSimulator.frames` without the batch axis (``out`` too), the impacts as
        :meth:`step` gives them.

        >>> sim = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), [[0.0, 0.0]], [[1.0, 0.0]], [1.0], [0.25])
        >>> rec = sim.frames(1 / 60, 120)
        >>> rec.positions.shape, float(rec.time[-1].round(12)), [(i.wall, round(i.time, 12)) for i in rec.impacts]
        ((120, 1, 2), 2.0, [('right', 0.75)])
        """
        rec = self._batch._frames(dt, n, out, _single_shapes)
        return Frames(rec.time[:, 0], rec.positions[:, 0], rec.velocities[:, 0], Impacts(rec.impacts))

    # read-only snapshots, as BatchSimulator's: set_balls, nudge and set_state change the state
    positions = property(lambda self: _snapshot(self._batch._pos[0]), doc="(N, 2) centres, m (read-only).")
    velocities = property(lambda self: _snapshot(self._batch._vel[0]), doc="(N, 2) velocities, m/s (read-only).")
    masses = property(lambda self: _snapshot(self._batch._mass[0]), doc="(N,) masses, kg (read-only).")
    radii = property(lambda self: _snapshot(self._batch._radius[0]), doc="(N,) radii, m (read-only).")
    images = property(
        lambda self: _snapshot(self._batch._images[0]),
        doc="(N, 2) periodic cell lengths each ball has crossed (zeros unless the scene is periodic).",
    )
    unwrapped_positions = property(
        lambda self: self._batch.unwrapped_positions[0],
        doc="(N, 2) centres as if the periodic cell did not wrap them, m (``positions + images * Scene.period``).",
    )
    time = property(lambda self: float(self._batch._time[0]), doc="Simulation time, s.")
    clusters = property(lambda self: _snapshot(self._batch._body[0]), doc="(N,) root ball of each ball's cluster.")
    cap_reached = property(lambda self: bool(self._batch._capped[0]), doc="The last step stopped at the event cap.")
    models = property(lambda self: self._batch.models)
    stats = property(lambda self: self._batch.stats)

    def kinetic_energy(self) -> float:
        return float(self._batch.kinetic_energy()[0])

    def momentum(self) -> np.ndarray:
        return self._batch.momentum()[0]

    def nudge(self, dv: ArrayLike) -> None:
        """Change each ball's velocity by ``dv`` (``(N, 2)``), as an impulse (clusters included)."""
        self._batch.nudge([dv])

    def set_balls(self, positions: ArrayLike | None = None, velocities: ArrayLike | None = None) -> None:
        """Replace positions and/or velocities (validated; on error nothing changes). Time is kept."""
        b = self._batch
        clock = b._clock[0].copy()
        images = b._images[0].copy()
        b.set_scenes(
            [0],
            b._pos if positions is None else [positions],
            b._vel if velocities is None else [velocities],
            time=b._time[0],
        )
        b._clock[0] = clock
        if positions is None:  # (the balls stay where they are, images included)
            b._images[0] = images

    def get_state(self) -> dict[str, np.ndarray]:
        """A dict of array copies (no batch axis) that :meth:`set_state` restores exactly."""
        return {key: value[0] for key, value in self._batch.get_state().items()}

    def set_state(self, state: Mapping[str, ArrayLike]) -> None:
        """Restore a state from :meth:`get_state`, checked as :meth:`BatchSimulator.set_state` checks it."""
        if not isinstance(state, Mapping):
            raise TypeError(f"state: expected a dict, as get_state gives, got {type(state).__name__}")
        self._batch.set_state({key: np.asarray(value)[None] for key, value in state.items()})

    def copy(self) -> Simulator:
        """An independent copy (``copy.copy`` and ``copy.deepcopy`` give one too)."""
        new = object.__new__(Simulator)
        new._batch = self._batch.copy()
        return new

    __copy__ = copy


def _snapshot(array: np.ndarray) -> np.ndarray:
    """A read-only copy of ``array``: a write to it raises instead of silently changing nothing."""
    out = array.copy()
    out.flags.writeable = False
    return out


def _single_shapes(sim, n):
    """The shapes of ``n`` frames of a single simulator (a batch of one without its axis)."""
    return (n,), (n, sim._n, 2), (n, sim._n, 2)


def warm_up() -> None:
    """Compile (or load from numba's on-disk cache) every engine kernel, so later steps are timed fairly.

    Numba compiles a kernel at its first call; call this before timing anything. The stepping kernel
    of every mode and kind of scene is compiled by its signature (none is run); one tiny scene then
    reaches the kernels that Python calls itself (the start-state checks, nudges, frames). Without
    numba it only runs that scene.
    """
    for spec in MODE_REGISTRY.values():
        for kernel in spec.kernels():
            compile_for(kernel, pack_arrays([np.zeros(1)]), 1.0, START_STEP)
    sim = Simulator(Scene(), [[-0.5, 0.0], [0.5, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 2.0])
    sim.nudge([[0.1, 0.0], [0.0, 0.0]])
    sim.frames(0.3, 2)
    sim.step(-0.3)
