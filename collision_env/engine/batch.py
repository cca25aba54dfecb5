"""Many independent scenes at once: :class:`BatchSimulator`, the engine's batched public face.

It checks what users hand it (:mod:`~collision_env.engine.validation`) and steps a
:class:`~collision_env.engine.stepper.Stepper`, which runs the mode's compiled kernel. A
:class:`~collision_env.engine.Simulator` is a stepper of one scene with a face of its own, so the
single env and the vector env run one copy of the physics.
"""

from __future__ import annotations

import copy
import inspect
import numbers
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike

from .impacts import Impacts
from .keywords import check_keywords
from .modes import MODES as MODE_REGISTRY
from .physics.motion import apply_impulses
from .scene import Scene
from .snapshot import SimulatorState
from .stepper import FrameArrays, LiveArrays, Stepper, default_event_cap
from .validation import (
    Labels,
    check_seconds,
    checked_balls,
    checked_nudge,
    checked_settings,
    checked_state,
    periodic_slack,
    real_number,
    state_record,
)


class Frames(NamedTuple):
    """A trajectory sampled after each of several equal steps (:meth:`BatchSimulator.frames`,
    :meth:`Simulator.frames <collision_env.engine.Simulator.frames>`, which drops the batch axis)."""

    time: np.ndarray  #: (F, B) each scene's clock after each step (s)
    positions: np.ndarray  #: (F, B, N, 2) centres after each step (m)
    velocities: np.ndarray  #: (F, B, N, 2) velocities after each step (m/s)
    impacts: Impacts  #: the steps' impacts, step after step, each step's as ``step`` returns them
    #: (F, B, N, 2) int64 periodic cell lengths each ball has crossed, after each step (zeros unless
    #: the scene is periodic): ``positions + images * Scene.period`` is the unwrapped trajectory
    images: np.ndarray


def new_stepper(
    scene: Any,
    positions: Any,
    velocities: Any,
    masses: Any,
    radii: Any,
    single: bool,
    *,
    mode: Any,
    substeps: Any,
    max_events: Any,
    collapse_ratio: Any,
    collapse_floor: Any,
    contact_duration: Any = 0.0,
) -> Stepper:
    """A :class:`Stepper` of ``(B, N, 2)`` positions and velocities (``single``: a batch of one that
    its simulator shows without the batch axis), every argument checked (ValueError naming it)."""
    if not isinstance(scene, Scene):
        raise ValueError(f"scene: expected a collision_env.engine.Scene, got {type(scene).__name__}")
    settings = checked_settings(
        mode, substeps, max_events, collapse_ratio, collapse_floor, MODE_REGISTRY, contact_duration, scene.sticky
    )
    try:
        shape = np.shape(cast(ArrayLike, positions))  # (numpy's ArrayLike leaves out lists of arrays)
    except ValueError:  # numpy refuses ragged nesting
        shape = None
    if shape is None or len(shape) != 3 or shape[-1] != 2:
        got = "a ragged sequence" if shape is None else shape
        raise ValueError(f"positions: expected shape (B, N, 2), got {got}")
    n_scenes, n = shape[0], shape[1]
    label = Labels(n_scenes, single)
    if n_scenes < 1 or n < 1:
        raise ValueError(f"positions: need at least one scene and one ball, got shape {label.shape(shape)}")
    if settings.max_events is None:
        settings = settings._replace(max_events=default_event_cap(n))
    scenes = np.arange(n_scenes)
    pos, vel, mass, radius = checked_balls(
        scene, label, scenes, n, positions, velocities, masses, radii, keep=periodic_slack(scene)
    )
    stepper = Stepper(scene, settings, n_scenes, n, label)
    stepper.put(scenes, pos, vel, mass, radius, time=0.0)
    return stepper


def frames_of(stepper: Stepper, dt: Any, n: Any, out: Any, stacklevel: int) -> Frames:
    """``n`` steps of ``dt`` by ``stepper``, recorded with the batch axis (:meth:`BatchSimulator.frames`),
    into ``out``'s arrays if given (viewed with the batch axis: a single simulator's are checked
    against its own shapes); ``stacklevel`` as ``Stepper.frames`` takes it."""
    dt = real_number(dt, "dt")
    check_seconds(dt, "dt")
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral) or n < 0:
        raise ValueError(f"n: must be a whole number of steps (0 or more), got {n!r}")
    n = int(n)
    b, balls = stepper.n_scenes, stepper.n
    batched = ((n, b), (n, b, balls, 2), (n, b, balls, 2))
    if out is None:
        times, positions, velocities = (np.empty(shape) for shape in batched)
        images = None
    else:  # (a single simulator's arrays gain the batch axis as a view)
        given = batched if not stepper.label.single else ((n,), (n, balls, 2), (n, balls, 2))
        arrays = zip(_output_arrays(out, given), batched, strict=True)
        times, positions, velocities = (a.reshape(shape) for a, shape in arrays)
        images = getattr(out, "images", None)
    if images is None or not stepper.scene.periodic or images.size != positions.size:
        images = np.zeros(positions.shape, dtype=np.int64)
    else:
        images = images.reshape(positions.shape)
    record = FrameArrays(times, positions, velocities, images)
    impacts = stepper.frames(dt, record, stacklevel)
    return Frames(times, positions, velocities, Impacts(impacts), images)


def _output_arrays(out: Any, shapes: tuple) -> tuple[np.ndarray, ...]:
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


def snapshot(array: np.ndarray) -> np.ndarray:
    """A read-only copy of ``array``: a write to it raises instead of silently changing nothing."""
    out = array.copy()
    out.flags.writeable = False
    return out


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
        Cap on events per scene per step in exact mode: collisions, a contact group's sweeps,
        iterations and impulses (at e < 1), and a periodic cell's cell crossings all count. A scene
        that reaches it stops at its last event, in a valid state; :attr:`cap_reached` flags it and
        an :class:`EventCapWarning` is issued. The default, ``None``, is :func:`default_event_cap`
        of the ball count: a budget per ball, far above what a gas spends in a frame, so that only
        a cascade reaches it.
    collapse_ratio, collapse_floor:
        The inelastic-collapse regulariser: a collision whose normal closing speed is at most
        ``u_min = max(collapse_ratio * s, collapse_floor)`` leaves the pair separating at ``u_min``,
        ``s`` being the fastest speed among the balls of the impact (exact mode; the cheap modes use
        the scene's slowest moving ball), see :mod:`collision_env.engine.physics.response`. The default
        floor, 0, keeps energy from growing beyond round-off at e < 1.
    contact_duration:
        The TC model (Luding & McNamara 1998), off at 0 (the default): a collision is elastic when
        either ball's previous collision was less than ``contact_duration`` seconds before it, which
        bounds the collisions of dense inelastic flows (exact mode, slip scenes; forward steps only).
        See :mod:`collision_env.engine.physics.response`.

    Inputs are real numbers (numpy scalar types included; booleans, strings and complex numbers
    are refused) with finite, representable values: positions and speeds up to 1e150, masses
    whose inverse is finite, radii that span 2^16 units in the last place of the scene's
    coordinates, and balls that have room to move in the box. Anything else raises a ``ValueError``
    naming the field and the ball, and changes nothing.
    """

    _stepper: Stepper

    def __new__(cls, *args: Any, **kwargs: Any) -> BatchSimulator:
        check_keywords(kwargs, _KEYWORDS)  # before __init__, whose TypeError names no close match
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
        contact_duration: float = 0.0,
    ) -> None:
        self._stepper = new_stepper(
            scene,
            positions,
            velocities,
            masses,
            radii,
            single=False,
            mode=mode,
            substeps=substeps,
            max_events=max_events,
            collapse_ratio=collapse_ratio,
            collapse_floor=collapse_floor,
            contact_duration=contact_duration,
        )

    @classmethod
    def _of(cls, stepper: Stepper) -> BatchSimulator:
        """A batch face of ``stepper`` (a :class:`Simulator`'s, which names balls as it does)."""
        new = object.__new__(cls)
        new._stepper = stepper
        return new

    # ------------------------------------------------------------------ stepping
    def step(self, dt: float) -> Impacts:
        """Advance every scene by ``dt`` seconds (``dt < 0`` runs time backwards).

        Returns the impacts inside the step as :class:`Impacts`, ordered by scene and then by the
        order in which they happened (``.array``: the records, of :data:`IMPACT_DTYPE`, whose
        ``scene`` field says whose; ``.for_scene(i)``: scene ``i``'s).

        ``dt`` is a real number (numpy scalars included) of at most 1e150 s; without a border, the
        step must also keep every ball within 1e150 m. The clocks are compensated sums: after any
        number of steps ``time`` is within an ulp of the exact sum of the ``dt`` taken (forward and
        back again returns it to exactly where it was). Backwards, a bounce at elasticity e < 1
        multiplies a speed by 1/e, and the bounces come ever faster: a past that reaches infinite
        speed within the step raises a ``ValueError`` naming the ball, and changes nothing.
        """
        # (a float, real_number's common case, is taken without its call)
        return self._stepper.step(dt if isinstance(dt, float) else real_number(dt, "dt"))

    def frames(self, dt: float, n: int, out: Frames | None = None) -> Frames:
        """Take ``n`` steps of ``dt`` seconds, recording every scene after each one.

        The same as ``n`` calls of :meth:`step` (the same kernel: the same impacts, states and
        clocks, bit for bit), but forward steps with a border run as one compiled loop, which
        saves the cost of a call from Python per step: about a microsecond, as much as an event
        of a sparse gas. Returns :class:`Frames` of ``n`` rows; its ``impacts`` are every step's
        impacts in step order, each step's as :meth:`step` returns them (by scene, then time), and
        its ``images`` each ball's periodic image counts after each step. ``out``: the arrays to
        record into (a :class:`Frames` of ``n`` rows from an earlier call, say; its ``impacts`` are
        not used), instead of new ones: writing a trajectory into new memory costs the operating
        system's first touch of every page, which is more than the steps of a sparse gas. A step
        that raises stops the run there, as it would stop a loop (after the steps before it).

        >>> scene = Scene(bounds=(-1.0, -1.0, 1.0, 1.0))
        >>> sim = BatchSimulator(scene, [[[0.0, 0.0]], [[0.5, 0.0]]], [[[1.0, 0.0]], [[0.0, 0.0]]], [1.0], [0.25])
        >>> rec = sim.frames(0.5, 4)
        >>> rec.positions.shape, rec.time[:, 0].tolist(), rec.positions[:, 0, 0, 0].tolist()
        ((4, 2, 1, 2), [0.5, 1.0, 1.5, 2.0], [0.5, 0.5, 0.0, -0.5])
        >>> rec.impacts.array[["scene", "time", "wall"]].tolist()
        [(0, 0.75, 1)]
        """
        return frames_of(self._stepper, dt, n, out, stacklevel=5)

    # ------------------------------------------------------------------ state access
    @property
    def scene(self) -> Scene:
        """The :class:`Scene` every batch member shares."""
        return self._stepper.scene

    @property
    def num_scenes(self) -> int:
        """``B``, the number of scenes."""
        return self._stepper.n_scenes

    @property
    def num_balls(self) -> int:
        """``N``, the number of balls in each scene."""
        return self._stepper.n

    # The state properties are read-only snapshots: a write to one raises ("assignment destination
    # is read-only") rather than being dropped; set_scenes, nudge and set_state change the state.
    @property
    def positions(self) -> np.ndarray:
        """``(B, N, 2)`` centres, m (a read-only snapshot)."""
        return snapshot(self._stepper.pos)

    @property
    def velocities(self) -> np.ndarray:
        """``(B, N, 2)`` velocities, m/s (a read-only snapshot)."""
        return snapshot(self._stepper.vel)

    @property
    def masses(self) -> np.ndarray:
        """``(B, N)`` masses, kg (a read-only snapshot)."""
        return snapshot(self._stepper.mass)

    @property
    def radii(self) -> np.ndarray:
        """``(B, N)`` radii, m (a read-only snapshot)."""
        return snapshot(self._stepper.radius)

    @property
    def time(self) -> np.ndarray:
        """``(B,)`` each scene's clock, s (a read-only snapshot)."""
        return snapshot(self._stepper.time)

    @property
    def images(self) -> np.ndarray:
        """``(B, N, 2)`` int64: how many periodic cell lengths each ball has crossed along x and y
        (zeros unless the scene is periodic); see :attr:`unwrapped_positions`."""
        return snapshot(self._stepper.images)

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """``(B, N, 2)`` centres as if the periodic cell did not wrap them, m: ``positions + images *
        (lx, ly)`` (``Scene.period``), which moves continuously (for mean squared displacements and
        diffusion). The positions themselves outside a periodic scene."""
        s = self._stepper
        return s.pos + s.images * np.array(s.scene.period)

    @property
    def clusters(self) -> np.ndarray:
        """``(B, N)``: the index of the ball rooting each ball's rigid cluster (itself if free)."""
        return snapshot(self._stepper.body)

    @property
    def cap_reached(self) -> np.ndarray:
        """``(B,)`` bool: the event cap stopped that scene's last step early."""
        return snapshot(self._stepper.capped)

    # the settings are fixed at construction: the kernels are bound to them (make a new simulator
    # to change one; get_state/set_state carry a state across)
    @property
    def mode(self) -> str:
        """``"naive"``, ``"posteriori"`` or ``"exact"``."""
        return self._stepper.settings.mode

    @property
    def substeps(self) -> int:
        """Sub-steps per step (naive and posteriori)."""
        return self._stepper.settings.substeps

    @property
    def max_events(self) -> int:
        """Event cap per step and scene (exact)."""
        return cast(int, self._stepper.settings.max_events)

    @property
    def collapse_ratio(self) -> float:
        """Collapse regulariser: u_min / fastest speed."""
        return self._stepper.settings.collapse_ratio

    @property
    def contact_duration(self) -> float:
        """The TC model's contact duration (s; 0: off), as given to the constructor."""
        return self._stepper.settings.contact_duration

    @property
    def collapse_floor(self) -> float:
        """Collapse regulariser: smallest u_min, m/s."""
        return self._stepper.settings.collapse_floor

    def live_arrays(self) -> LiveArrays:
        """The engine's own state arrays, not copies, for compiled kernels that read them every
        step (the envs' kernels). Every step updates them in place. Treat them as read-only, except
        through the engine's own kernels (``motion.apply_impulses`` is how the envs nudge).
        From then on every step compares each ball with the state the last step left it in."""
        return self._stepper.live_arrays()

    @property
    def models(self) -> dict[str, Any]:
        """What the engine computes for this scene, and nothing else: the mode and its sub-steps,
        the dimension, walls, a periodic cell, ball pairs, stick clusters, and the backend."""
        return self._stepper.models()

    @property
    def stats(self) -> dict[str, int]:
        """Work done so far: pair and wall predictions (or overlap tests), events, rotating-cluster
        predictions, grid-cell crossings and stale calendar entries re-predicted (exact mode)."""
        return self._stepper.stats()

    def kinetic_energy(self) -> np.ndarray:
        """``(B,)`` total kinetic energy, J."""
        s = self._stepper
        return 0.5 * (s.mass * (s.vel**2).sum(-1)).sum(-1)

    def momentum(self) -> np.ndarray:
        """``(B, 2)`` total momentum, kg m/s."""
        s = self._stepper
        return (s.mass[..., None] * s.vel).sum(1)

    # ------------------------------------------------------------------ changing the state
    def nudge(self, dv: ArrayLike | Sequence[ArrayLike], check: bool = True) -> None:
        """Change every ball's velocity by ``dv`` (``(B, N, 2)``), as an impulse ``m dv``.

        A member of a stuck cluster passes the impulse to the whole cluster (linear and angular).
        ``check=False`` skips validation, for callers that build ``dv`` as a float64 array of the
        right shape with finite values (and zero y in 1D) themselves, where the checks would cost
        more than the nudge. (The envs nudge from their own kernel, through ``motion.apply_impulses``,
        the function this calls.)
        """
        s = self._stepper
        if check:
            dv = checked_nudge(dv, s.scene, s.vel, s.mass, s.label)
        s.changed()
        apply_impulses(s.balls, s.body, dv, s.scene.sticky)

    def set_scenes(
        self,
        index: ArrayLike,
        positions: ArrayLike | Sequence[ArrayLike],
        velocities: ArrayLike | Sequence[ArrayLike],
        masses: ArrayLike | None = None,
        radii: ArrayLike | str | None = None,
        time: ArrayLike = 0.0,
        check: bool = True,
    ) -> None:
        """Start the scenes picked by ``index`` (indices or a ``(B,)`` bool mask) afresh.

        ``positions``/``velocities`` are ``(K, N, 2)`` for the K scenes picked; ``masses`` and
        ``radii`` default to those the scenes had. Validated like the constructor; on error
        nothing changes. ``check=False`` skips validation, for callers that pass an int64 array of
        scene indices, float64 arrays of the right shapes (masses and radii included) and a float
        time, holding balls they built valid themselves, where the checks would cost more than the
        reset (the envs' episodes, which their builder places apart from each other and the walls);
        only the shapes are checked then (a ``ValueError``, nothing changed).
        """
        s = self._stepper
        if not check:
            idx = np.asarray(index)
            pos, vel, m, r = (np.asarray(a, dtype=np.float64) for a in (positions, velocities, masses, radii))
            # (the shapes still, before anything is written: a refused call changes nothing)
            k = (len(idx), s.n)
            if idx.ndim != 1 or pos.shape != (*k, 2) or vel.shape != (*k, 2) or m.shape != k or r.shape != k:
                raise ValueError(
                    f"set_scenes: with check=False, index (K,) and positions, velocities (K, {s.n}, 2), "
                    f"masses and radii (K, {s.n}) float64 arrays are expected, got index {idx.shape}, "
                    f"positions {pos.shape}, velocities {vel.shape}, masses {m.shape}, radii {r.shape}"
                )
            s.put(idx, pos, vel, m, r, time=real_number(time, "time"))
            return
        idx = self._scene_index(index)
        time = real_number(time, "time")
        check_seconds(time, "time")
        if masses is None:
            masses = s.mass[idx]
        if radii is None:
            radii = s.radius[idx]
        pos, vel, m, r = checked_balls(
            s.scene, s.label, idx, s.n, positions, velocities, masses, radii, keep=periodic_slack(s.scene)
        )
        s.put(idx, pos, vel, m, r, time=time)

    def _scene_index(self, index: ArrayLike) -> np.ndarray:
        """``index`` (scene indices or a ``(B,)`` bool mask) as an array of scene indices."""
        n_scenes = self._stepper.n_scenes
        try:  # (indices or a mask: numpy's indexing decides)
            idx = np.atleast_1d(np.arange(n_scenes)[cast(Any, index)])
        except IndexError:
            idx = None
        if idx is None or idx.ndim != 1:
            raise ValueError(
                f"index: expected scene indices within the batch of {n_scenes} (negative ones count "
                f"from its end) or a ({n_scenes},) bool mask, got {index!r}"
            )
        return idx

    def get_state(self) -> SimulatorState:
        """The whole state, as copies of the arrays (each with the batch axis), that :meth:`set_state`
        restores exactly."""
        return self._stepper.state()

    def set_state(self, state: SimulatorState) -> None:
        """Restore a state from :meth:`get_state` (a dict of its fields is still taken, with a
        ``DeprecationWarning``).

        Checked as the constructor checks its balls (shapes, number types, finite and representable
        values, balls inside the border and apart, none spanning the box), and beyond that: the
        keys are those :meth:`get_state` gives (``images`` may be left out: zeros), the clusters
        are ball indices whose roots are their own roots (every ball its own cluster unless the
        scene sticks), a stick cluster's balls move as one rigid body and touch one another in a
        network, spins are within 1e150 rad/s, the clocks are times the constructor would accept,
        each with a compensation below an ulp of it. In naive and posteriori modes, whose steps may
        end with balls overlapping, overlaps (and touching balls from wall to wall, which these
        modes step like any others) are accepted, and so are stick clusters whose balls are up to
        their radii sum apart (posteriori's reconstruction leaves gaps of up to ~0.3 of it). Bad
        input raises a ``ValueError`` naming the scene, ball and field, and changes nothing. In a
        periodic scene, positions outside the cell are wrapped into it, their images counted
        (those a step leaves a round-off outside stay as they are, so that a state goes back bit
        for bit).
        """
        self._restore(state_record(state, stacklevel=2))

    def _restore(self, state: Mapping[str, Any]) -> None:
        """:meth:`set_state` of a :class:`SimulatorState`, or of a mapping of its fields."""
        s = self._stepper
        checked = checked_state(state, s.scene, s.label, (s.n_scenes, s.n), s.spec.leaves_overlaps)
        s.put(
            np.arange(s.n_scenes),
            checked.pos,
            checked.vel,
            checked.mass,
            checked.radius,
            time=checked.time,
            compensation=checked.compensation,
            images=checked.images,
            clusters=checked.clusters,
            omega=checked.omega,
            last_impact=checked.last_impact,
        )

    def copy(self) -> BatchSimulator:
        """An independent copy (for planning: step it ahead without touching this one)."""
        return copy.deepcopy(self)

    __copy__ = copy  # (a shallow copy would share the state arrays but not the bookkeeping around them)

    def load(self, other: BatchSimulator) -> None:
        """Take ``other``'s whole state in place: balls, clusters, clocks and, in exact mode, its
        event calendar, so that stepping this simulator on does exactly what stepping ``other``
        would, with nothing predicted afresh. For a planning simulator that copies a running one at
        every step (:meth:`set_state` checks its input and re-predicts every scene). ``other`` has
        the same scene, shape and mode; its other settings (sub-steps, the event cap) may differ
        and are this simulator's own."""
        if not isinstance(other, BatchSimulator):
            raise TypeError(f"other: expected a BatchSimulator, got {type(other).__name__}")
        mine, theirs = self._stepper, other._stepper
        if (theirs.scene, other.mode, theirs.balls.shape) != (mine.scene, self.mode, mine.balls.shape):
            raise ValueError(
                f"other: a simulator of the same scene, mode and shape, got mode {other.mode!r} and shape "
                f"{theirs.balls.shape[:2]} (this one: {self.mode!r}, {mine.balls.shape[:2]})"
            )
        mine.load(theirs)


#: The keyword arguments BatchSimulator takes (a misspelled one is named with the closest of them).
_KEYWORDS = tuple(inspect.signature(BatchSimulator.__init__).parameters)[1:]
