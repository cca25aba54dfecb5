"""How a simulator steps: the engine's state arrays, the mode's kernel with its packed arguments,
and the impact buffer, owned by one :class:`Stepper`.

:class:`~collision_env.engine.BatchSimulator` and :class:`~collision_env.engine.Simulator` are the
public faces of a stepper: they check what users hand them (:mod:`~collision_env.engine.validation`)
and shape what they return; the stepper only runs the kernels on input that is already checked. It
packs the kernel's arguments once (``state.pack``) and updates its arrays in place ever after, so
that a step from Python costs one call of a compiled kernel with nothing to convert.
"""

from __future__ import annotations

import copy
import warnings
from typing import Any, NamedTuple

import numpy as np

from ._jit import BACKEND, compile_for
from .broadphase import GRID_MIN_BALLS, PERIODIC_GRID_MIN_BALLS, grid_geometry
from .frames import copy_impacts, record_frame
from .impacts import BufferRows, Impacts
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
from .modes import MODES, Mode
from .physics.periodic import wrap_positions
from .scene import Scene
from .snapshot import SimulatorState
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
    with_impacts,
)
from .validation import (
    MAX_MAGNITUDE,
    Labels,
    Settings,
    check_laps,
    check_reach,
    check_seconds,
    periodic_slack,
)

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
#: written to it; a fresh empty structured array costs more than a small scene's step), and its
#: :class:`Impacts`.
NO_RECORDS = np.empty(0, dtype=IMPACT_DTYPE)
NO_RECORDS.flags.writeable = False
NO_IMPACTS = Impacts(NO_RECORDS)


def as_impacts(rows: np.ndarray) -> Impacts:
    """``rows`` (impact records a step returned) as :class:`Impacts`."""
    return NO_IMPACTS if rows is NO_RECORDS else Impacts(rows)


#: The impact buffer grows to hold a step's impacts up to this many rows (72 MB): a step that fills
#: it is run in calls that each fill it, whose impacts are then joined (a cost per row far below an
#: event's).
MAX_IMPACT_ROWS = 1 << 20


#: A new object of a type, its ``__init__`` not called.
_new = object.__new__

#: Each stepping kernel called so far -> its compiled version, which steppers call directly (see
#: ``Stepper._first_call``).
_DIRECT: dict[Any, Any] = {}


class EventCapWarning(RuntimeWarning):
    """A scene reached the cap on events per step and stopped early (in a valid state)."""


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


class FrameArrays(NamedTuple):
    """Where a run of frames is recorded, with the batch axis: clocks ``(F, B)``, positions and
    velocities ``(F, B, N, 2)``, image counts ``(F, B, N, 2)`` (int64; recorded in periodic scenes
    only, zeros elsewhere)."""

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    images: np.ndarray

    def rows(self, periodic: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities and images as the kernels record them: ``(F, B * N, 2)`` views
        (images ``(F, 0, 2)`` outside a ``periodic`` scene, where they stay 0 and are not recorded)."""
        f, b, n, _ = self.positions.shape
        images = self.images.reshape(f, b * n, 2) if periodic else np.empty((f, 0, 2), np.int64)
        return self.positions.reshape(f, b * n, 2), self.velocities.reshape(f, b * n, 2), images


class Stepper:
    """``B`` scenes of ``N`` balls sharing one :class:`Scene`, stepped by the kernel of a mode:
    the state arrays, the kernel's packed arguments and the impact buffer.

    Built empty: :meth:`put` writes each scene's balls (checked by the caller). ``label`` names
    balls and shapes in the messages it raises and warns with.
    """

    def __init__(self, scene: Scene, settings: Settings, n_scenes: int, n: int, label: Labels) -> None:
        spec = MODES[settings.mode]
        self.scene = scene
        self.spec: Mode = spec
        self.settings = settings
        self.label = label
        self.n_scenes = n_scenes
        self.n = n
        # Every per-ball float lives in one (B, N, 8) array, pos, vel, ... are views into it: each
        # array handed to a kernel costs ~0.1 us per call, which is most of a small scene's step.
        self.balls = aligned_zeros((n_scenes, n, len(BALL)), np.float64)
        self._bind_views()
        self.body = np.tile(np.arange(n, dtype=np.int64), (n_scenes, 1))
        self.images = np.zeros((n_scenes, n, 2), dtype=np.int64)  # (a periodic cell's lengths crossed)
        self.time = np.zeros(n_scenes)
        self.clock = np.zeros((n_scenes, 2))  # per scene: time as the clock set it, its compensation
        self.capped = np.zeros(n_scenes, dtype=np.bool_)
        self.counters = np.zeros(len(COUNTERS), dtype=np.int64)

        bounds = scene.bounds if scene.bounds is not None else (0.0, 0.0, 0.0, 0.0)
        scene_f = dict(
            zip(("xmin", "ymin", "xmax", "ymax"), bounds, strict=True),
            elasticity=scene.elasticity,
            collapse_ratio=settings.collapse_ratio,
            sign=1.0,
            collapse_floor=settings.collapse_floor,
            contact_duration=settings.contact_duration,
        )
        scene_i = dict(
            has_walls=scene.bounds is not None and not scene.periodic,
            pairs=scene.ball_collisions and n > 1,
            dim=scene.dimension,
            sticky=scene.sticky,
            max_events=settings.max_events,
            substeps=settings.substeps,
        )
        self.fparams = np.array([scene_f[name] for name in SCENE_F])
        self.iparams = np.array([scene_i[name] for name in SCENE_I], dtype=np.int64)
        self.work_f = np.zeros((n_scenes, len(WORK_F)))
        self.work_i = np.zeros((n_scenes, len(WORK_I)), dtype=np.int64)
        # the mode's own arrays (exact mode's event calendar and grid, kept from step to step, and work
        # space), and its kernel for this kind of scene
        self.mode_arrays = spec.arrays(scene, n_scenes, n)
        self._kernel = spec.kernel(scene, n)
        self._call = _DIRECT.get(self._kernel, self._first_call)
        self.start = START_STEP  # how the next kernel call starts (see step)
        self._after_step = START_NEXT
        self._alloc_work()

    def _bind_views(self) -> None:
        b = self.balls
        self.pos = b[..., B_X : B_X + 2]
        self.vel = b[..., B_VX : B_VX + 2]
        self.mass = b[..., B_MASS]
        self.inv_mass = b[..., B_INV_MASS]
        self.radius = b[..., B_RADIUS]
        self.omega = b[..., B_OMEGA]

    # ------------------------------------------------------------------ writing scenes
    def wrapped(self, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions ``(K, N, 2)`` wrapped into a periodic scene's cell (but for those a step's
        round-off may leave outside it, ``validation.periodic_slack``), and the periods each was
        moved by (zeros, and ``pos`` itself, in other scenes)."""
        if not self.scene.periodic or self.scene.bounds is None:
            return pos, np.zeros(pos.shape, dtype=np.int64)
        return wrap_positions(pos, self.scene.bounds, self.scene.dimension, periodic_slack(self.scene))

    def put(
        self,
        scenes: np.ndarray,
        pos: np.ndarray,
        vel: np.ndarray,
        mass: np.ndarray,
        radius: np.ndarray,
        *,
        time: np.ndarray | float,
        compensation: np.ndarray | float = 0.0,
        images: np.ndarray | None = None,
        clusters: np.ndarray | None = None,
        omega: np.ndarray | float = 0.0,
        last_impact: np.ndarray | None = None,
    ) -> None:
        """Start ``scenes`` (indices) afresh from checked ``(K, N, ...)`` balls, at ``time`` (with
        its clock's ``compensation``). Periodic positions are wrapped into the cell, the periods
        counted in their ``images`` (zeros if None); ``clusters`` default to every ball its own."""
        pos, wrapped = self.wrapped(pos)
        self.pos[scenes] = pos
        self.images[scenes] = wrapped if images is None else wrapped + images
        self.vel[scenes] = vel
        self.mass[scenes] = mass
        self.inv_mass[scenes] = 1.0 / mass
        self.radius[scenes] = radius
        self.body[scenes] = np.arange(self.n) if clusters is None else clusters
        self.omega[scenes] = omega
        self.time[scenes] = time
        self.clock[scenes, 0] = time
        self.clock[scenes, 1] = compensation
        if self.spec.persistent:  # (the TC model's memory: no collision yet, unless a state says)
            self.mode_arrays[0].last_impact[scenes] = -np.inf if last_impact is None else last_impact
        self.invalidate(scenes)

    def changed(self) -> None:
        """The balls were changed outside a step (a nudge): the next step compares every ball with
        the state the last step left it in, and checks what a step needs checked afresh."""
        self.start = START_STEP
        self._reset_fast_path()

    def _reset_fast_path(self) -> None:
        """Set the longest step that takes :meth:`step`'s fast path, ``_fast_dt``, for the state as it
        is now: any forward step with a border; none in a periodic cell of the cheap modes, until a
        checked step has bounded its laps (:meth:`_checked_step`); none without a border or
        backwards."""
        forward = self._sign > 0.0 and self.scene.bounds is not None
        self._fast_dt = MAX_MAGNITUDE if forward and not self._bounds_laps else 0.0

    @property
    def _bounds_laps(self) -> bool:
        """Steps are refused for their laps round a periodic cell (``validation.check_laps``): in the
        cheap modes. Exact mode counts each crossing of a cell toward the event cap instead, so a
        step of any length is taken, and one that laps the cell without bound stops at the cap."""
        return self.scene.periodic and not self.spec.persistent

    def invalidate(self, scenes: np.ndarray) -> None:
        """Drop the calendar's predictions for ``scenes`` (they are made afresh at the next step)
        and lay out their grid for the balls they now hold."""
        period = self.scene.period if self.scene.periodic else None
        origin_and_cells, counts = grid_geometry(
            self.scene.bounds,
            self.pos[scenes],
            self.radius[scenes],
            self.uses_grid(),
            **self.spec.grid,
            period=period,
        )
        self.work_f[scenes, W_GRID_X0 : W_GRID_X0 + 4] = origin_and_cells
        self.work_i[scenes, W_GRID_NX : W_GRID_NX + 2] = counts
        self.work_i[scenes, W_CALENDAR_VALID] = 0
        self.changed()

    def uses_grid(self) -> bool:
        """The broad phase pays only in large scenes with ball pairs (and no stick clusters)."""
        least = PERIODIC_GRID_MIN_BALLS if self.scene.periodic else GRID_MIN_BALLS
        return self.scene.ball_collisions and self.n >= least and not self.scene.sticky

    def _alloc_work(self, rows: int | None = None) -> None:
        if rows is None:
            rows = self.spec.impact_rows(self.scene, self.n, self.uses_grid())
        self._imp = np.empty(rows, dtype=IMPACT_DTYPE)
        self._views = self.spec.sorted_impacts  # (the impacts are handed over as views: see _take_impacts)
        self._cursor = 0  # (the impact buffer's first free row)
        self._refill_at = rows // 2
        # the impact buffer's cursor (mirrored in _cursor), the scenes that reached the cap, stalled
        self._n_imp = np.zeros(3, dtype=np.int64)
        # the kernel's arguments, packed once (the arrays are only ever updated in place)
        state = State(
            self.balls,
            self.body,
            self.time,
            self.capped,
            self.fparams,
            self.iparams,
            self._imp,
            self._n_imp,
            self.counters,
            self.work_f,
            self.work_i,
            self.clock,
            self.images,
        )
        self._pack = pack(state, *self.mode_arrays, frames=True)
        self._sign = float(self.fparams[S_SIGN])  # the direction fparams are set for (see step)
        self._shared = getattr(self, "_shared", False)  # (live_arrays handed out: see live_arrays)
        self._reset_fast_path()
        self.live = LiveArrays(
            self.balls, self.pos, self.vel, self.mass, self.radius, self.time, self.body, self.capped
        )

    # ------------------------------------------------------------------ stepping
    def step(self, dt: float, stacklevel: int = 4) -> Impacts:
        """Advance every scene by ``dt`` (a float: the caller made it one); the impacts, ordered by
        scene and time; ``stacklevel`` names the caller's caller in an
        :class:`EventCapWarning` (4: this, the public ``step`` and its caller, plus the warning's
        own frame).

        A step that follows a completed forward step, with nothing changed in between, starts with
        ``START_NEXT``: the kernel then need not compare every ball with its calendar record, which
        is most of a small scene's fixed cost. ``start`` says which: every other way of changing the
        state (a nudge, :meth:`put`, :meth:`load`, a step of another kind, frames) sets it back to
        ``START_STEP``, and once :meth:`live_arrays` has handed the arrays out, where anyone may
        write them, it stays there.

        The fast path takes forward steps up to ``_fast_dt``: with a border, steps that need no
        check but ``dt``'s own; in a periodic cell in exact mode, any (the event cap bounds the laps);
        in a periodic cell in a cheap mode, those whose laps round the cell a checked step bounded
        (see :meth:`_checked_step`)."""
        if 0.0 < dt <= self._fast_dt:  # the common case, checked in one test
            end = self._call(self._pack, dt, self.start)
            if end >= 0:  # no scene stalled or reached the event cap
                self.start = self._after_step
                first = self._cursor
                if end == first:
                    return NO_IMPACTS
                if self._views:  # (_take_impacts, inlined for the common case, its view made late)
                    impacts = _new(BufferRows)  # (BufferRows(...) without the call of its __init__)
                    impacts._buffer = self._imp
                    impacts._first = first
                    impacts._end = self._cursor = end
                    if end > self._refill_at:
                        self._fresh_buffer(len(self._imp))
                    return impacts
                return Impacts(self._take_impacts(first, end))
            self.start = START_STEP
            return as_impacts(self._finish(self._run(dt, first_done=True), 1.0, stacklevel))
        self.start = START_STEP
        return as_impacts(self._checked_step(dt, stacklevel + 1))

    def _checked_step(self, dt: float, stacklevel: int) -> np.ndarray:
        """:meth:`step` off its fast path: backwards, without a border, in a periodic cell in a
        cheap mode, or of a step checked for the first time."""
        label = self.label
        check_seconds(dt, "dt")
        if self.scene.bounds is None:
            check_reach(self.pos, self.vel, dt, label)
        longest = check_laps(self.scene, self.mass, self.vel, dt, label) if self._bounds_laps else 0.0
        e = self.scene.elasticity
        if dt < 0.0 and self.settings.contact_duration > 0.0:
            raise ValueError(
                "dt: cannot step backwards under the TC model (contact_duration > 0): which collisions "
                "it makes elastic depends on the collisions before them"
            )
        if dt < 0.0 and e == 0.0:
            raise ValueError(
                "dt: cannot step backwards with elasticity 0 (a perfectly inelastic collision has no inverse)"
            )
        if dt == 0.0:
            self.capped[:] = False
            return NO_RECORDS
        sign = 1.0 if dt > 0.0 else -1.0
        if sign != self._sign:  # reverse steps use 1/e
            self.fparams[S_ELASTICITY] = e if sign > 0 else 1.0 / e
            self.fparams[S_SIGN] = sign
            self._sign = sign
        self._reset_fast_path()
        # reversed, a bounce at e < 1 multiplies the speed by 1/e, and the bounces come ever faster:
        # a past may diverge within finite time. Such a step is refused, from a copy kept here.
        before = self.saved() if sign < 0 and e < 1.0 else None
        if sign < 0:
            np.negative(self.vel, out=self.vel)
            np.negative(self.omega, out=self.omega)
        try:
            chunks = self._run(abs(dt))
        finally:
            if sign < 0:
                np.negative(self.vel, out=self.vel)
                np.negative(self.omega, out=self.omega)
        if before is not None:
            self._refuse_divergent_past(before, dt)
        if sign > 0.0 and not self._shared and self.settings.collapse_floor == 0.0:
            # Forward, collisions never add energy (but for the collapse regulariser's floor), so no
            # ball can ever go faster than check_laps allowed for: until the balls are changed from
            # outside a step, steps up to its longest step need no check of their laps.
            self._fast_dt = max(self._fast_dt, min(longest, MAX_MAGNITUDE))
        return self._finish(chunks, sign, stacklevel)

    def _refuse_divergent_past(self, before: list[np.ndarray], dt: float) -> None:
        """After a backward step at e < 1: if a ball's speed or position overflowed, restore
        ``before`` (:meth:`saved` before the step) and raise a ValueError naming the ball."""
        motion = self.balls[..., B_X : B_VX + 2]  # (positions and velocities)
        if not np.isfinite(motion).all():
            s, i = np.argwhere(~np.isfinite(motion).all(-1))[0]
            self.restore(before)
            e = self.scene.elasticity
            raise ValueError(
                f"dt: the past of {self.label(s, i).rstrip(': ')} diverges within this step of {dt:g} s: "
                f"reversed, each bounce at elasticity {e:g} multiplies its speed by {1.0 / e:.6g}, and the "
                "bounces come ever faster, until the speed overflows (the state is unchanged)"
            )

    def frames(self, dt: float, out: FrameArrays, stacklevel: int) -> np.ndarray:
        """Take ``len(out.times)`` steps of ``dt`` (checked), recording every scene after each into
        ``out``; returns every step's impacts in step order. Forward steps run in one compiled loop
        (the same kernel as :meth:`step`, so the same steps bit for bit); the others, and a step
        the loop cannot complete, as :meth:`step` takes them."""
        n = len(out.times)
        self.start = START_STEP
        pieces = []
        f = 0
        buffer = None  # the compiled loop's copy of the impacts
        size = len(self._imp)
        if self._bounds_laps:  # (the run's laps, checked once: a cheap periodic step has no fast path)
            check_laps(self.scene, self.mass, self.vel, dt * n, self.label)
        while f < n:
            forward = self._sign > 0.0 and self.scene.bounds is not None
            if not (forward and 0.0 < dt <= MAX_MAGNITUDE):
                # backwards or without a border: a step as step takes it (which may make the next
                # ones forward steps with a border)
                pieces.append(self.step(dt, stacklevel + 1).array)
                self._record(f, out)
                f += 1
                continue
            if buffer is None:
                buffer = np.empty(size, dtype=IMPACT_DTYPE)
            f, stepped, rows = self._run_frames(dt, f, out, buffer)
            if rows:  # (kept, if at least half full: the next run gets a buffer of its own)
                pieces.append(buffer[:rows] if 2 * rows >= len(buffer) else buffer[:rows].copy())
            buffer = None
            if f == n:
                break
            # frame f's impacts did not fit (the next frames get a buffer twice the size), or
            # its step needs completing, as step completes it
            if stepped:
                pieces.append(self._take_impacts(self._cursor, int(self._n_imp[0])))
                size *= 2
            else:
                pieces.append(self._finish(self._run(dt, first_done=True), 1.0, stacklevel))
            self._record(f, out)
            f += 1
        if len(pieces) == 1:
            return pieces[0]
        return np.concatenate(pieces) if pieces else NO_RECORDS.copy()

    def _record(self, f: int, out: FrameArrays) -> None:
        """Frame ``f`` of ``out``: the state now."""
        record_frame(f, self.balls, self.time, self.images, out.times, *out.rows(self.scene.periodic))

    def _run_frames(self, dt: float, first: int, out: FrameArrays, buffer: np.ndarray) -> tuple[int, bool, int]:
        """Frames ``first`` to the last of ``out`` in one call of the kernel (see
        ``frames.frames_kernel``), the impacts into ``buffer``. Returns ``(f, stepped, rows)``: every
        frame was recorded if ``f`` is their number; else frame ``f`` was not, and ``stepped`` says
        whether its step was taken (its impacts did not fit ``buffer``) or needs completing; ``rows``
        of ``buffer`` were written."""
        request = np.zeros(len(FRAME_FIELDS), dtype=np.int64)
        request[FRAME_FIRST] = first
        request[FRAME_LAST] = len(out.times)
        bundle = FramesOut(request, out.times, *out.rows(self.scene.periodic), buffer)
        self._call(with_frames(self._pack, self.spec.frames_slot, bundle), dt, RUN_FRAMES)
        return int(request[FRAME_STOPPED_AT]), bool(request[FRAME_STEPPED]), int(request[FRAME_ROWS])

    def _finish(self, chunks: list[np.ndarray], sign: float, stacklevel: int) -> np.ndarray:
        """Warn about scenes that reached the event cap; the step's impacts as one array."""
        if self._n_imp[1]:
            warnings.warn(
                f"event cap of {self.settings.max_events} per step reached in scene(s) "
                f"{np.flatnonzero(self.capped).tolist()}; they stopped early at their last event "
                "(see cap_reached and time)",
                EventCapWarning,
                stacklevel=stacklevel,
            )
        if not chunks:
            return NO_RECORDS
        if len(chunks) == 1:
            return chunks[0]
        out = np.concatenate(chunks)  # a stalled step: a scene's impacts may span chunks
        if self.n_scenes == 1:  # (one scene's chunks come in its order: each resumes where the last stopped)
            return out
        return out[np.lexsort((sign * out["time"], out["scene"]))]

    def _run(self, dt_abs: float, first_done: bool = False) -> list[np.ndarray]:
        """Run the mode's kernel until every scene has stepped ``dt_abs``; the impacts in chunks,
        one per call (a call stops the scenes that find the impact buffer full, which the next
        call resumes in a buffer with room). ``first_done``: the step's first call was made already."""
        chunks = []
        n_imp = self._n_imp
        if not first_done:
            self._call(self._pack, dt_abs, START_STEP)
        while True:  # each call records from the cursor on
            first, end = self._cursor, int(n_imp[0])
            if end > first:
                chunks.append(self._take_impacts(first, end))
            if not n_imp[2]:  # no scene stalled
                if len(chunks) > 1:  # the next steps like this one fit the buffer, up to MAX_IMPACT_ROWS
                    total = sum(len(chunk) for chunk in chunks)
                    # (twice the step's rows: a step starts anywhere up to half way along)
                    size = min(MAX_IMPACT_ROWS, 1 << (2 * total - 1).bit_length())
                    if size > len(self._imp):
                        self._fresh_buffer(size)
                return chunks
            if end == first == 0:  # not even one sub-step's worst case fits an empty buffer: a bigger one
                self._fresh_buffer(2 * len(self._imp))
            elif self._cursor:  # (rows of this buffer were handed out; the cheap modes' were copied)
                self._fresh_buffer(len(self._imp))
            self._call(self._pack, dt_abs, RESUME)  # (direct from the second call on: see _first_call)

    def _first_call(self, pack: np.ndarray | tuple, dt: float, start: int) -> int:
        """The kernel's first call in this process, through numba's dispatcher (which compiles it,
        or loads it from the cache); ``_call`` is then the compiled version itself
        (``_jit.compile_for``, kept in :data:`_DIRECT` for every later stepper of the kernel), which
        a call enters without the dispatch's checks: a stepper always hands its kernel a pack, a
        float and an int."""
        rows = self._kernel(pack, dt, start)
        if self._kernel not in _DIRECT:
            _DIRECT[self._kernel] = compile_for(self._kernel, pack, dt, start)
        self._call = _DIRECT[self._kernel]
        return rows

    def _take_impacts(self, first: int, end: int) -> np.ndarray:
        """Rows ``first`` to ``end`` of the impact buffer, handed over to the caller.

        Exact mode records each scene's impacts in the order they happen, scenes in order: its rows
        are handed over as they are, a view of the buffer, which the kernel never writes again: the
        cursor moves past them, and once it is half way along, recording goes on from the first row
        of a new buffer (:meth:`_fresh_buffer`). So a step's impacts cost no copy, and stay as they
        are for as long as anyone holds them, who holds the buffer they lie in with them. The cheap
        modes' reconstructed times need sorting within each scene: their rows are sorted into a
        copy, and used again."""
        if not self._views:
            out = np.empty(end - first, dtype=IMPACT_DTYPE)
            copy_impacts(self._imp[first:end], out, self._sign)
            self._n_imp[0] = first
            return out
        rows = self._imp[first:end]
        self._cursor = end
        if end > self._refill_at:
            self._fresh_buffer(len(self._imp))
        return rows

    def rewind_impacts(self) -> None:
        """Drop the impacts recorded since the last hand-over, for a caller that calls the kernel
        itself and keeps none (a benchmark): the next call records from the first row of the buffer,
        or of a new one if rows of this one were handed out (they stay as they are)."""
        if self._cursor:
            self._fresh_buffer(len(self._imp))
        else:
            self._n_imp[0] = 0

    def _fresh_buffer(self, rows: int) -> None:
        """Record impacts from the first row of a new buffer of ``rows`` rows (what was handed out of
        the old one stays with whoever holds it; the old buffer is freed with the last of it)."""
        self._imp = np.empty(rows, dtype=IMPACT_DTYPE)
        self._refill_at = rows // 2
        self._pack = with_impacts(self._pack, self._imp)
        self._n_imp[0] = self._cursor = 0

    # ------------------------------------------------------------------ what it holds
    def live_arrays(self) -> LiveArrays:
        """The state arrays themselves; from now on every step compares each ball with the state
        the last step left it in, and checks a periodic cell's laps (whoever holds them may write
        them)."""
        if not self._shared:  # (the envs ask at every step: once is enough)
            self._shared = True
            self.start = self._after_step = START_STEP
            self._reset_fast_path()
        return self.live

    def models(self) -> dict[str, Any]:
        """What the engine computes for this scene, and nothing else."""
        return {
            "mode": self.settings.mode,
            "substeps": self.settings.substeps,
            "dimension": self.scene.dimension,
            "walls": self.scene.bounds is not None and not self.scene.periodic,
            "periodic": self.scene.periodic,
            "ball_pairs": bool(self.iparams[S_PAIRS]),
            "clusters": self.scene.sticky,
            "backend": BACKEND,
        }

    def stats(self) -> dict[str, int]:
        """The work counters, by name."""
        return {name: int(count) for name, count in zip(COUNTERS, self.counters, strict=True)}

    def state(self) -> SimulatorState:
        """Copies of every array a state is made of (see ``BatchSimulator.get_state``)."""
        return SimulatorState(
            positions=self.pos.copy(),
            velocities=self.vel.copy(),
            masses=self.mass.copy(),
            radii=self.radius.copy(),
            clusters=self.body.copy(),
            omega=self.omega.copy(),
            time=self.time.copy(),
            time_compensation=self.clock[:, 1].copy(),
            images=self.images.copy(),
            # (the TC model's memory, only where a simulator has the model: every other state stays as it was)
            last_impact=self.mode_arrays[0].last_impact.copy() if self.settings.contact_duration > 0.0 else None,
        )

    # ------------------------------------------------------------------ copies
    def load(self, other: Stepper) -> None:
        """Take ``other``'s whole state in place (the caller checked that it fits)."""
        for mine, theirs in zip(self.stepped_arrays(), other.stepped_arrays(), strict=True):
            np.copyto(mine, theirs)
        if self.spec.persistent and other.settings.contact_duration == 0.0:
            # (instants a simulator without the TC model kept are no history for one with it: its
            # backward steps may have taken the clock back past them)
            self.mode_arrays[0].last_impact[:] = -np.inf
        for field in (S_ELASTICITY, S_SIGN):  # (the direction of time the state is kept for)
            self.fparams[field] = other.fparams[field]
        self._sign = other._sign
        self.changed()

    def stepped_arrays(self) -> list[np.ndarray]:
        """The arrays a step changes: balls, clusters, clocks and, in exact mode, the event
        calendar (what :meth:`load` takes from another stepper)."""
        arrays = [self.balls, self.body, self.time, self.clock, self.capped, self.work_f, self.work_i, self.images]
        return arrays + list(self.mode_arrays[0]) if self.spec.persistent else arrays

    def saved(self) -> list[np.ndarray]:
        """Copies of :meth:`stepped_arrays`, to :meth:`restore` a step's start from."""
        return [a.copy() for a in self.stepped_arrays()]

    def restore(self, saved: list[np.ndarray]) -> None:
        """Put back the arrays :meth:`saved` copied."""
        for mine, kept in zip(self.stepped_arrays(), saved, strict=True):
            np.copyto(mine, kept)
        self.changed()

    #: What a copy or a pickle rebuilds rather than carries: work space, and what is bound to it.
    _REBUILT = (
        "_imp", "_views", "_cursor", "_refill_at", "_n_imp", "_kernel", "_call", "_pack", "_sign", "_fast_dt",
        "_shared", "live", "pos", "vel", "mass", "inv_mass", "radius", "omega", "spec", "start", "_after_step",
    )  # fmt: skip

    def __getstate__(self) -> dict[str, Any]:
        state = {key: value for key, value in self.__dict__.items() if key not in self._REBUILT}
        # (exact mode's calendar persists; its work space, and the cheap modes' scratch, are made anew)
        state["mode_arrays"] = self.mode_arrays[:1] if self.spec.persistent else ()
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self.spec = MODES[self.settings.mode]
        # a copy or an unpickled array has numpy's alignment
        self.balls = aligned_copy(self.balls)
        fresh = self.spec.arrays(self.scene, self.n_scenes, self.n)
        kept = tuple(type(b)(*(aligned_copy(a) for a in b)) for b in self.mode_arrays)
        self.mode_arrays = kept + fresh[len(kept) :]
        self._kernel = self.spec.kernel(self.scene, self.n)
        self._call = _DIRECT.get(self._kernel, self._first_call)
        self.start = START_STEP
        self._after_step = START_NEXT
        self._bind_views()
        self._alloc_work()

    def __deepcopy__(self, memo: dict[int, Any]) -> Stepper:
        new = object.__new__(type(self))
        new.__setstate__(copy.deepcopy(self.__getstate__(), memo))
        return new
