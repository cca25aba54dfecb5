"""The batched task core shared by the single env (a batch of one) and the native vector env.

:class:`TaskCore` owns one :class:`collision_env.engine.BatchSimulator` and the per-scene task state
(targets, scoring flags, step counters). Episodes are drawn by :class:`EpisodeSampler` from one
``np.random.Generator`` per scene, so a scene of the vector env and a single env seeded alike draw the
same numbers in the same order. All physics happens in the engine; the core only turns actions into
nudges and the engine's impact records into hits, reward and observations (the kernels of
:mod:`collision_env.envs.task`).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import DTypeLike

from collision_env.engine import MAX_SUBSTEPS
from collision_env.engine.compiled import compile_for
from collision_env.engine.impacts import copy_records
from collision_env.engine.keywords import close_matches
from collision_env.engine.modes import MODES
from collision_env.engine.scene import WALL_NAMES
from collision_env.envs._config import AIMS, CONTROLS, TaskConfig
from collision_env.envs.task.arrays import Engine, TaskParams, TaskState, pack
from collision_env.envs.task.checks import check_cluster_mirror, checked_task_state
from collision_env.envs.task.episodes import block_size, build_episodes
from collision_env.envs.task.finish import task_kernel
from collision_env.envs.task.images import observe_images
from collision_env.envs.task.layout import (
    EPISODE_FLOATS,
    EPISODE_INTS,
    PARAMS,
    SCENE_FLOATS,
    SCENE_INTS,
    SWITCHES,
    TARGET_GEOMETRY,
    TARGET_INTS,
    TARGET_PENDING,
)
from collision_env.envs.task.nudge import nudge_kernel
from collision_env.envs.task.predict import predict_kernel

if TYPE_CHECKING:
    from collision_env.engine import BatchSimulator


# --------------------------------------------------------------------------------------------- #
# episode sampling


class Episodes:
    """Start states for k scenes: balls (k, N, ...) and targets (k, K, ...)."""

    __slots__ = ("positions", "velocities", "masses", "radii", "t_wall", "t_geo")

    def __init__(
        self,
        positions: np.ndarray,
        velocities: np.ndarray,
        masses: np.ndarray,
        radii: np.ndarray,
        t_wall: np.ndarray,
        t_geo: np.ndarray,
    ) -> None:
        self.positions = positions
        self.velocities = velocities
        self.masses = masses
        self.radii = radii
        self.t_wall = t_wall
        self.t_geo = t_geo


def packed(columns: Any, dtype: DTypeLike, **values: float) -> np.ndarray:
    """A vector laid out as ``columns`` (a ``task.layout`` layout) with every field given by name."""
    missing = sorted(set(columns._fields) - set(values))
    unknown = sorted(set(values) - set(columns._fields))
    if missing or unknown:
        raise ValueError(f"{type(columns).__name__}: missing {missing}, unknown {unknown}")
    out = np.zeros(len(columns), dtype=dtype)
    for name, value in values.items():
        out[getattr(columns, name)] = value
    return out


#: Mass scale of the observation, kg (it reads mass / 3 kg).
MASS_SCALE = 3.0
#: placement tries per ball inside one block of random numbers
PLACEMENT_TRIES = 16
#: blocks drawn for one episode before giving up (only very crowded configs come near this)
MAX_ATTEMPTS = 1000


class EpisodeSampler:
    """Draws start states: one block of uniforms per episode from that episode's generator.

    Each episode consumes ``rng.random(M)`` (M fixed by the config), repeated while the balls
    do not fit, and the block is turned into the start state by a batched kernel. A sub-env of
    the vector env and a single env seeded alike therefore draw the same episodes.
    """

    def __init__(self, cfg: TaskConfig) -> None:
        self.cfg = cfg
        """The task whose start states it draws."""
        n, k = cfg.n_balls, cfg.n_targets
        self.block = block_size(n, k, PLACEMENT_TRIES)
        """Uniforms per episode (the length of each episode's block)."""
        self.ctrl_mask = np.zeros(n, dtype=bool)
        """``(n_balls,)`` bool: the controlled balls."""
        self.ctrl_mask[list(cfg.controlled)] = True
        assert cfg.others_mass_range is not None  # (None only as an argument of TaskConfig)
        self.mass_low = np.where(self.ctrl_mask, cfg.mass_range[0], cfg.others_mass_range[0])
        """``(n_balls,)``: each ball's lightest mass."""
        self.mass_high = np.where(self.ctrl_mask, cfg.mass_range[1], cfg.others_mass_range[1])
        """``(n_balls,)``: each ball's heaviest mass."""
        assert cfg.bounds is not None and cfg.target_walls is not None  # (None only as arguments of TaskConfig)
        self.walls = np.array([WALL_NAMES.index(w) for w in cfg.target_walls], dtype=np.int64)
        """The wall codes targets may sit on."""
        xmin, ymin, xmax, ymax = cfg.bounds
        (speed_low, speed_high), (others_low, others_high) = cfg.speed_range, cfg.others_speed_range
        self.episode_f = packed(
            EPISODE_FLOATS,
            np.float64,
            xmin=xmin,
            ymin=ymin,
            xmax=xmax,
            ymax=ymax,
            speed_low=speed_low,
            speed_high=speed_high,
            others_low=others_low,
            others_high=others_high,
            half_width=0.5 * cfg.target_width,
            window=-1.0 if cfg.window is None else cfg.window,
            time_limit=cfg.time_limit,
        )
        """The episode builder's float parameters (columns named by ``EPISODE_FLOATS``)."""
        self.episode_i = packed(
            EPISODE_INTS,
            np.int64,
            dimension=cfg.dimension,
            n_balls=n,
            n_targets=k,
            rack=int(cfg.layout in ("rack", "fence")),
            fence=int(cfg.layout == "fence"),
            tries=PLACEMENT_TRIES,
        )
        """The episode builder's integer parameters (columns named by ``EPISODE_INTS``)."""

    def _build(self, uniforms: np.ndarray) -> tuple[Episodes, np.ndarray]:
        cfg = self.cfg
        r, n, k = uniforms.shape[0], cfg.n_balls, cfg.n_targets
        lo, hi = self.mass_low, self.mass_high
        masses = lo + (hi - lo) * uniforms[:, :n]
        radii = cfg.radius_of(masses)
        pos = np.zeros((r, n, 2))
        vel = np.zeros((r, n, 2))
        t_wall = np.zeros((r, k), dtype=np.int64)
        t_geo = np.zeros((r, k, len(TARGET_GEOMETRY)))
        ok = np.zeros(r, dtype=bool)
        build_episodes(
            uniforms,
            self.ctrl_mask,
            self.walls,
            self.episode_f,
            self.episode_i,
            pos,
            vel,
            masses,
            radii,
            t_wall,
            t_geo,
            ok,
        )
        return Episodes(pos, vel, masses, radii, t_wall, t_geo), ok

    def sample(self, rngs: list) -> Episodes:
        """One episode's start state per generator of ``rngs`` (each draws its own blocks)."""
        uniforms = np.empty((len(rngs), self.block))
        for i, rng in enumerate(rngs):
            rng.random(out=uniforms[i])
        eps, ok = self._build(uniforms)
        if ok.all():  # (the common case, in one test)
            return eps
        for row in np.flatnonzero(~ok):  # rare: draw fresh blocks for the rows that did not fit
            for _ in range(MAX_ATTEMPTS):
                one, good = self._build(rngs[row].random(self.block)[None])
                if good[0]:
                    for name in Episodes.__slots__:
                        getattr(eps, name)[row] = getattr(one, name)[0]
                    break
            else:
                raise RuntimeError(
                    f"could not place {self.cfg.n_balls} balls without overlap in {self.cfg.bounds} "
                    f"after {MAX_ATTEMPTS} attempts; use fewer or smaller balls"
                )
        return eps


def sample_episode(cfg: TaskConfig, rng: np.random.Generator) -> Episodes:
    """One start state drawn from ``rng`` (arrays with a leading axis of length 1)."""
    return EpisodeSampler(cfg).sample([rng])


# --------------------------------------------------------------------------------------------- #


def check_state_keys(state: Any, keys: tuple, source: str) -> None:
    """Raise unless ``state`` is a dict holding ``keys`` (the state ``source`` gives) and nothing
    else: a ``TypeError`` for anything but a mapping, a ``ValueError`` naming the unknown keys (each
    with the closest of ``keys``: a misspelt key would otherwise be ignored) or the missing ones."""
    if not isinstance(state, dict):
        raise TypeError(f"set_state: expected a dict with the keys {list(keys)} ({source}), got {type(state).__name__}")
    unknown = [key for key in state if key not in keys]
    if unknown:
        raise ValueError(
            f"set_state: unknown key(s) {close_matches(unknown, keys)}; expected a dict with the keys "
            f"{list(keys)} ({source})"
        )
    missing = [key for key in keys if key not in state]
    if missing:
        raise ValueError(f"set_state: missing {missing}; expected a dict with the keys {list(keys)} ({source})")


class TaskCore:
    """A batch of B task instances on one BatchSimulator.

    The task state is in a few packed arrays, named in :class:`~collision_env.envs.task.arrays.TaskState`
    (``scene_f`` per-scene floats, ``scene_i`` per-scene counters and flags, ``targets`` each target's
    wall and status, ``target_geo`` its segment and window, ``body`` the cluster mirror), handed to
    the compiled kernels once, in one pack with the engine's arrays and the task's parameters,
    because each array a kernel call takes costs time on every step. The balls' state is the
    engine's own. The named properties below are views.
    """

    def __init__(self, cfg: TaskConfig, num_scenes: int) -> None:
        from collision_env.engine import IMPACT_DTYPE, BatchSimulator, Scene

        self.cfg = cfg
        B, N, Kt = int(num_scenes), cfg.n_balls, cfg.n_targets
        self.num_scenes = B
        self.scene = Scene(
            bounds=cfg.bounds,
            elasticity=cfg.elasticity,
            dimension=cfg.dimension,
            inelastic=cfg.inelastic,
            ball_collisions=cfg.ball_collisions,
        )
        assert cfg.bounds is not None  # (None only as an argument of TaskConfig)
        xmin, ymin, xmax, ymax = cfg.bounds
        params = packed(
            PARAMS,
            np.float64,
            xmin=xmin,
            ymin=ymin,
            xmax=xmax,
            ymax=ymax,
            hit_reward=cfg.hit_reward,
            miss_penalty=cfg.miss_penalty,
            success_bonus=cfg.success_bonus,
            shaping=cfg.shaping,
            vscale=2.0 * cfg.max_speed,
            mscale=MASS_SCALE,
            time_limit=cfg.time_limit,
            max_dv=cfg.max_dv,
            max_speed=cfg.max_speed,
            action_cost=cfg.action_cost,
        )
        switches = packed(
            SWITCHES,
            np.int64,
            sequential=int(cfg.sequential),
            cluster=int(cfg.scorers == "cluster"),
            dimension=cfg.dimension,
            n_steps=cfg.n_steps,
            sticky=int(self.scene.sticky),
            observe_predicted=int(cfg.observe == "predicted"),
            aim_predicted=AIMS.index(cfg.aim) if cfg.aim != "straight" and cfg.shaping != 0.0 else 0,
            control=CONTROLS.index(cfg.control),
            predict_scoring=int(cfg.predicted_impact == "scoring"),
        )
        controlled = np.array(cfg.controlled, dtype=np.int64)
        self.params = TaskParams(params, switches, controlled, cfg.scoring_mask, cfg.shown_mask)
        self.obs_dim = cfg.obs_dim
        self.action_dim = cfg.action_dim
        self.state = TaskState(
            np.zeros((B, len(SCENE_FLOATS))),
            np.zeros((B, len(SCENE_INTS)), dtype=np.int64),
            np.zeros((B, Kt, len(TARGET_INTS)), dtype=np.int64),
            np.zeros((B, Kt, len(TARGET_GEOMETRY))),
            np.tile(np.arange(N, dtype=np.int64), (B, 1)),
            np.zeros((B, N, 2)),
            np.zeros((B, N), dtype=np.int64),
        )

        # A placeholder layout drawn from a fixed seed builds the engine now, so that bad engine
        # arguments fail at construction; reset() overwrites every scene.
        self.sampler = EpisodeSampler(cfg)
        ep = self.sampler.sample([np.random.default_rng(0)])
        rep = lambda a: np.repeat(a, B, 0)  # noqa: E731

        def engine(substeps):
            return BatchSimulator(
                self.scene,
                rep(ep.positions),
                rep(ep.velocities),
                rep(ep.masses),
                radii=rep(ep.radii),
                mode=cfg.mode,
                substeps=substeps,
                max_events=cfg.max_events,
            )

        self.batch = engine(cfg.substeps)
        self._write_episode(np.arange(B), Episodes(*(rep(getattr(ep, f)) for f in Episodes.__slots__)))
        self.impact_dtype = IMPACT_DTYPE
        # observe="predicted": a second engine of the same mode, loaded with the scenes' state and run
        # ahead at every observation (scratch: it holds no state of the task between calls). The cheap
        # modes keep their sub-step length: the look-ahead takes as many sub-steps as the control steps
        # it spans would, up to the engine's MAX_SUBSTEPS.
        self.ahead: BatchSimulator | None = None
        if cfg.observe == "predicted" or switches[SWITCHES.aim_predicted]:
            ahead_substeps = cfg.substeps * max(1, round(cfg.lookahead / cfg.dt)) if MODES[cfg.mode].substeps else 1
            ahead_substeps = min(ahead_substeps, MAX_SUBSTEPS)
            self.ahead = engine(ahead_substeps)
        self._bind()

    def _bind(self) -> None:
        """The kernels' pack of the engine's arrays, the task state and its parameters, and the
        kernels' compiled versions for the arguments :meth:`advance`, :meth:`finish` and
        :meth:`_predict` hand them (``compile_for``), which they call without numba's dispatch (its
        type checks cost more than a small scene's task): always this pack, ``(B, A)`` float64
        actions, ``(B,)`` bool and int8 rows, the engine's impact records and ``(B, obs_dim)``
        float32 observations, all C-contiguous."""
        live = self.batch.live_arrays()
        self._pack = pack(Engine(live.balls, live.time, live.clusters), self.state, self.params)
        b = self.num_scenes
        rows = np.zeros(b, dtype=np.int8)
        imp = self.empty_impacts()
        obs = np.zeros((b, self.obs_dim), dtype=np.float32)
        self._nudge = compile_for(nudge_kernel, self._pack, np.zeros((b, self.action_dim)), np.ones(b, dtype=bool))
        self._task = compile_for(task_kernel, self._pack, rows, imp, obs)
        self._look = None if self.ahead is None else compile_for(predict_kernel, self._pack, rows, imp, obs)

    #: What a copy or a pickle makes again rather than carries: addresses, and compiled code.
    _BOUND = ("_pack", "_nudge", "_task", "_look")

    def __getstate__(self):
        return {key: value for key, value in self.__dict__.items() if key not in self._BOUND}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._bind()

    @property
    def engines(self) -> tuple:
        """The engine, and its look-ahead copy when there is one (``observe="predicted"``)."""
        return (self.batch,) if self.ahead is None else (self.batch, self.ahead)

    # views into the packed state (writable: they share memory with it)
    scene_f = property(lambda self: self.state.scene_f, doc="(B, len(SCENE_FLOATS)) per-scene floats.")
    scene_i = property(lambda self: self.state.scene_i, doc="(B, len(SCENE_INTS)) per-scene counters and flags.")
    target_geo = property(lambda self: self.state.target_geo, doc="(B, K, len(TARGET_GEOMETRY)) target segments.")
    t_wall = property(lambda self: self.state.targets[..., TARGET_INTS.wall], doc="(B, K) target walls (wall codes).")
    t_status = property(
        lambda self: self.state.targets[..., TARGET_INTS.status],
        doc="(B, K) 0 pending, 1 hit, 2 failed (``task.layout.TARGET_PENDING`` ...).",
    )
    body = property(lambda self: self.state.body, doc="(B, N) the task's mirror of the engine's cluster roots.")
    scoring = property(lambda self: self.params.scoring, doc="(N,) bool: the balls whose wall impacts score.")
    cur = property(lambda self: self.state.scene_i[:, SCENE_INTS.current], doc="(B,) current (sequential) target.")
    steps = property(lambda self: self.state.scene_i[:, SCENE_INTS.steps], doc="(B,) control steps this episode.")

    # the engine's state: live views, to read (the renderer and the scripted policies do, per sub-env)
    pos = property(lambda self: self.batch.live_arrays().positions, doc="(B, N, 2) ball centres, m.")
    vel = property(lambda self: self.batch.live_arrays().velocities, doc="(B, N, 2) ball velocities, m/s.")
    time = property(lambda self: self.batch.live_arrays().time, doc="(B,) simulated time, s.")
    masses = property(lambda self: self.batch.live_arrays().masses, doc="(B, N) ball masses, kg.")
    radii = property(lambda self: self.batch.live_arrays().radii, doc="(B, N) ball radii, m.")

    # ------------------------------------------------------------------------------------- #
    def _write_episode(self, idx: np.ndarray, eps: Episodes) -> None:
        state = self.state
        state.targets[idx, :, TARGET_INTS.wall] = eps.t_wall
        state.targets[idx, :, TARGET_INTS.status] = TARGET_PENDING
        state.target_geo[idx] = eps.t_geo
        state.scene_i[idx, SCENE_INTS.current] = 0
        state.scene_i[idx, SCENE_INTS.steps] = 0
        state.body[idx] = np.arange(self.cfg.n_balls)

    def reset_scenes(self, idx: np.ndarray, rngs: list) -> None:
        """Draw a new episode for scenes ``idx`` (one generator each) and load it into the engine."""
        eps = self.sampler.sample(rngs)
        # (unchecked: the episode builder places the balls apart from each other and the walls, and the
        # constructor checked the config's balls, so the checks would cost more than the reset)
        self.batch.set_scenes(
            idx, eps.positions, eps.velocities, masses=eps.masses, radii=eps.radii, time=0.0, check=False
        )
        self._write_episode(idx, eps)

    @staticmethod
    def check_actions(actions: Any, field: str = "action") -> None:
        """Raise ValueError unless ``actions`` holds real numbers: a complex, string or boolean action
        would otherwise be cast to float64 silently (its imaginary part dropped, ``"0.5"`` parsed,
        ``True`` read as 1). The envs call this on the action as given, before they convert it."""
        if isinstance(actions, np.ndarray) and actions.dtype.kind in "iuf":
            return  # the common path: one test
        try:
            values = np.asarray(actions, dtype=object).ravel()
        except ValueError:
            raise ValueError(f"{field}: expected real numbers, got a ragged sequence") from None
        for x in values:
            if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
                raise ValueError(f"{field}: expected real numbers, got {x!r} ({type(x).__name__}) in {actions!r}")

    def advance(self, actions: np.ndarray, active: np.ndarray, dt: float) -> np.ndarray:
        """Nudge (actions (B, A) float64, C-contiguous; inactive rows get none) and step the engine by dt.

        Returns the engine's impact records (read-only); the nudge's size per scene is in
        ``scene_f`` (``nudge``, m/s). An action with NaN raises ValueError and changes nothing. The
        arrays' kinds are not checked (the compiled kernel is called directly, see :meth:`_bind`):
        the envs' ``step`` checks and converts what a user hands over.
        """
        bad = self._nudge(self._pack, actions, active)
        if bad >= 0:
            where = f"sub-env {bad}: " if self.num_scenes > 1 else ""
            raise ValueError(f"{where}action contains NaN: {actions[bad].tolist()}")
        imp = self.batch.step(dt).array
        if not len(imp):  # (most steps: the engine's one shared, read-only empty array)
            return imp
        # (a copy: the engine's records are a view of its impact buffer, which an info kept for long,
        # an episode's last say, would keep alive whole)
        imp = copy_records(imp)
        imp.flags.writeable = False  # (the kernels take the records read-only: one compiled version)
        return imp

    def finish(self, flags: np.ndarray, imp: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """Run the task kernel on the engine's state after a step; returns ``obs`` (written in place).

        ``flags``: one ``task.layout.ROW_*`` code per scene. Reward, energy, targets hit and the end
        flags are then in ``scene_f`` and ``scene_i`` (see :meth:`outputs`).

        Like :meth:`advance`, it calls its compiled kernel directly, without checking the arrays it
        is handed: ``(B,)`` int8 flags, the engine's impact records and ``(B, obs_dim)`` float32
        observations, C-contiguous, as the envs build them (see :meth:`_bind`); the envs' own
        ``step`` and ``reset`` are the checked way in.
        """
        self._task(self._pack, flags, imp, obs)
        if self.cfg.bank_images:
            observe_images(self, flags, obs, self.cfg.images_at)
        if self.ahead is not None:
            self._predict(self.ahead, flags, obs)
        return obs

    def _predict(self, ahead: BatchSimulator, flags: np.ndarray, obs: np.ndarray) -> None:
        """Run a copy of the engine ``lookahead`` s ahead of every scene (no nudge): each ball's
        predicted next wall impact goes into the observation and/or the aiming potential
        (``task.predict.predict_kernel``)."""
        from collision_env.engine import EventCapWarning

        ahead.load(self.batch)  # (its calendar too: nothing is predicted afresh)
        with warnings.catch_warnings():  # a capped look-ahead only predicts less far
            warnings.simplefilter("ignore", EventCapWarning)
            imp = ahead.step(self.cfg.lookahead).array
        imp.flags.writeable = False
        look = self._look
        assert look is not None  # (bound whenever there is a look-ahead engine)
        look(self._pack, flags, imp, obs)

    def outputs(self) -> tuple:
        """Fresh ``(reward, terminated, truncated, success, targets_hit, energy, nudge)`` arrays (B,)."""
        scene_f, scene_i, sf, si = self.state.scene_f, self.state.scene_i, SCENE_FLOATS, SCENE_INTS
        return (
            scene_f[:, sf.reward].copy(),
            scene_i[:, si.terminated].astype(bool),
            scene_i[:, si.truncated].astype(bool),
            scene_i[:, si.success].astype(bool),
            scene_i[:, si.targets_hit].copy(),
            scene_f[:, sf.energy].copy(),
            scene_f[:, sf.nudge].copy(),
        )

    def empty_impacts(self) -> np.ndarray:
        """A fresh zero-length impact record array (the engine's dtype; read-only, as the kernels take it)."""
        out = np.empty(0, dtype=self.impact_dtype)
        out.flags.writeable = False
        return out

    # ------------------------------------------------------------------------------------- #
    #: The task state's fields that :meth:`get_state` carries (the rest is scratch).
    _TASK_FIELDS = ("scene_f", "scene_i", "targets", "target_geo", "body")

    def get_state(self) -> dict:
        state = {name: getattr(self.state, name).copy() for name in self._TASK_FIELDS}
        state["engine"] = self.batch.get_state()
        return state

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`: its keys, the task's values
        (:func:`~collision_env.envs.task.checks.checked_task_state`), the task's cluster mirror
        against the engine's clusters (:func:`~collision_env.envs.task.checks.check_cluster_mirror`)
        and the engine's state are all checked before anything changes (raises ValueError or
        TypeError naming the field)."""
        check_state_keys(state, (*self._TASK_FIELDS, "engine"), "as get_state gives")
        current = {name: getattr(self.state, name) for name in self._TASK_FIELDS}
        arrays = checked_task_state(state, current, self.cfg.n_targets, tuple(self.sampler.walls.tolist()))
        check_cluster_mirror(arrays["body"], state["engine"])
        self.batch.set_state(state["engine"])
        for name, arr in arrays.items():
            np.copyto(current[name], arr)
