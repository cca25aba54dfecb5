"""Task configuration shared by every environment of the suite.

One :class:`TaskConfig` describes a whole task: the scene the engine simulates, how balls and targets
are placed at reset, which balls the agent nudges and whose impacts count, the rewards, the control
step, and the engine's fidelity knobs. Each preset (``PRESETS``, filled from the task registry) is just
a ``TaskConfig``; the generic env takes a preset name plus any field as a keyword override.
Construction validates every field and raises ``ValueError`` naming it, so bad keyword arguments
fail at ``gym.make`` time.
"""

from __future__ import annotations

import dataclasses
import difflib
import inspect
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from collision_env.engine import MAX_SUBSTEPS, MODES
from collision_env.engine.keywords import check_keywords
from collision_env.engine.scene import MAX_MAGNITUDE, PLAY_AREA_1D, PLAY_AREA_2D, WALL_NAMES, radius_from_mass
from collision_env.engine.validation import MAX_EVENT_CAP
from collision_env.envs.task.episodes import FENCE_SPACING
from collision_env.envs.task.images import IMAGE_FEATURES
from collision_env.envs.task.layout import BALL_OBS, GLOBAL_OBS, PREDICTED_OBS, TARGET_OBS

OBSERVATIONS = ("plain", "predicted")
OBSERVED_BALLS = ("all", "controlled")
AIMS = ("straight", "predicted", "landing")  # (an index is the aim_predicted switch: task.layout.AIM_LANDING)
#: Which predicted wall impact of a scoring ball the prediction reports (see TaskConfig).
PREDICTED_IMPACTS = ("next", "scoring")
#: What an action component means: a velocity change, or a velocity the ball is steered to (see TaskConfig).
CONTROLS = ("nudge", "velocity", "shot")  # (in the order of task.layout's CONTROL_* codes)
SCORERS = ("any", "controlled", "others", "cluster")
LAYOUTS = ("random", "rack", "fence")
RADIUS_RULES = ("mass", "constant")
#: The most reflections each way ``bank_images`` takes.
MAX_BANK_IMAGES = 8

#: Number of observation entries per ball, per target slot and global (the layouts in ``task.layout``).
BALL_FEATURES = len(BALL_OBS)
TARGET_FEATURES = len(TARGET_OBS)
GLOBAL_FEATURES = len(GLOBAL_OBS)
PREDICTED_FEATURES = len(PREDICTED_OBS)


def _pair(name, value, *, low=None, allow_equal=True):
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a (low, high) pair of numbers, got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"{name}: must be finite, got {value!r}")
    if lo > hi or (not allow_equal and lo == hi):
        raise ValueError(f"{name}: need low <= high, got {value!r}")
    if low is not None and lo < low:
        raise ValueError(f"{name}: values must be >= {low}, got {value!r}")
    return (lo, hi)


#: The most control steps an episode may have: its step counter is exact in float64 and int64 alike.
MAX_EPISODE_STEPS = 2**53


def _number(name, value, *, low=None, high=None, strict_low=False, integer=False):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}: expected a number, got {value!r}")
    if integer:
        if not math.isfinite(value):
            raise ValueError(f"{name}: must be finite, got {value!r}")
        if int(value) != value:
            raise ValueError(f"{name}: expected an integer, got {value!r}")
        value = int(value)
    else:
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"{name}: must be finite, got {value!r}")
    if low is not None and (value < low or (strict_low and value == low)):
        op = ">" if strict_low else ">="
        raise ValueError(f"{name}: must be {op} {low}, got {value!r}")
    if high is not None and value > high:
        raise ValueError(f"{name}: must be <= {high}, got {value!r}")
    return value


@dataclass(frozen=True)
class TaskConfig:
    """Everything that defines a task. Every field below can be given to ``gym.make`` as a keyword.

    The fields come in groups: the scene (passed to :class:`collision_env.engine.Scene`), the
    balls, the control, the targets, the reward, the observation, the episode and the engine.
    Construction checks every field and raises a ``ValueError`` naming it. Speeds (``max_dv``,
    ``max_speed``) and reward weights are at most 1e150 in size (the engine's ``MAX_MAGNITUDE``),
    so that a nudge's size, a ball's speed and a reward stay finite.
    """

    # ---- scene
    dimension: int = 2
    """1 or 2: a 1D scene moves along x only (y and vy stay 0)."""
    bounds: tuple | None = None
    """The play area ``(xmin, ymin, xmax, ymax)`` in m; ``None``: PhET's play area for the dimension."""
    elasticity: float = 1.0
    """Coefficient of restitution, 0 to 1, of ball-ball and ball-wall collisions."""
    inelastic: str = "slip"
    """How balls collide at elasticity 0: ``"slip"``, or ``"stick"`` into one rigid, spinning cluster."""
    ball_collisions: bool = True
    """Whether balls collide with each other (``False``: they pass through each other)."""
    # ---- balls
    n_balls: int = 1
    """Number of balls."""
    mass_range: tuple = (1.0, 1.0)
    """Each ball's mass is drawn uniformly from this ``(low, high)`` range, kg."""
    others_mass_range: tuple | None = None
    """The mass range of the balls that are not controlled; ``None``: ``mass_range``."""
    radius: str | float = "mass"
    """Radii: ``"mass"`` (PhET's rule, a sphere of density 35 kg/m³), ``"constant"`` (PhET's 0.15 m),
    or a number in m."""
    layout: str = "random"
    """Where balls start: ``"random"`` (anywhere without overlap; left to right by index in 1D) or
    ``"rack"`` (controlled balls in the left 40 % of the area, the others in the right half) or
    ``"fence"`` (2D: controlled balls as in ``"rack"``; the others fixed, in a column across the
    area's vertical centre line downward from the top wall, centres ``FENCE_SPACING`` radii of the
    largest of them apart and the first half a spacing from the wall, so that an opening is left
    above the bottom wall)."""
    speed_range: tuple = (0.3, 0.8)
    """Initial speed of each controlled ball, drawn from this ``(low, high)`` range (m/s), in a random direction."""
    others_speed_range: tuple = (0.0, 0.0)
    """Initial speed range of the other balls (m/s), in a random direction."""
    # ---- control
    controlled: tuple = (0,)
    """Indices of the balls the agent nudges."""
    control: str = "nudge"
    """What an action means: ``"nudge"``, velocity changes, or ``"velocity"``, velocities to steer to.
    ``"nudge"``: per controlled ball, one component per axis, each a velocity change of up to
    ``max_dv``. ``"velocity"``: per controlled ball, the velocity to steer it to (each component over
    ``max_speed``), then an engage flag: while the flag is > 0 the env nudges the ball
    towards that velocity, by at most ``max_dv`` per axis and step along the straight line to it; while
    it is <= 0 the ball coasts. A named velocity longer than ``max_speed`` is scaled back to it; the
    change charged (``action_cost``) is the change made. ``"shot"``: per controlled ball, one
    component per axis, the velocity (each component over ``max_speed``, scaled back to it if
    longer) the ball is given at once in the episode's first step; the actions of later steps are
    ignored (no change, no cost), and a target fails when a scoring ball strikes its wall off it
    (the episode then ends, as at a window's close)."""
    dt: float = 0.05
    """The control step: seconds of simulated time per ``env.step``."""
    max_dv: float = 0.15
    """The velocity change a full nudge component asks for, and the most a velocity step changes an axis (m/s)."""
    max_speed: float = 2.0
    """Speed cap of a nudge: it never pushes a ball above max(``max_speed``, its current speed) (m/s)."""
    # ---- targets
    n_targets: int = 3
    """Number of targets per episode."""
    sequential: bool = True
    """Show and score one target at a time (else all at once)."""
    target_width: float = 0.6
    """Width of a target along its wall (m)."""
    target_walls: tuple | None = None
    """The walls targets may sit on (names of ``collision_env.engine.WALL_NAMES``); ``None``: every
    wall of the dimension."""
    window: float | None = None
    """``None``, or the length (s) of each target's time window: an impact scores only inside it."""
    scorers: str = "any"
    """Whose wall impacts count: ``"any"`` ball, the ``"controlled"`` ones, the ``"others"``, or
    ``"cluster"`` (balls that have stuck to another ball)."""
    # ---- reward
    hit_reward: float = 1.0
    """Reward per target hit."""
    success_bonus: float = 1.0
    """Reward when every target is hit."""
    miss_penalty: float = 0.05
    """Penalty per wall impact of a scoring ball that hits no target."""
    action_cost: float = 0.02
    """Penalty per m/s of requested velocity change."""
    shaping: float = 0.0
    """Weight of the potential-based aiming term (0: off): the reward for bringing a scoring ball's
    next wall contact nearer the nearest pending target (the env's docstring, "Rewards", gives it)."""
    aim: str = "straight"
    """Where the aiming term takes each scoring ball's next wall contact from: ``"straight"`` (flying
    straight on, a heuristic that ignores other balls), ``"predicted"`` (the engine's prediction,
    as for ``observe``) or ``"landing"`` (the engine's prediction of each scoring ball's first impact
    on the wall of a visible pending target, the impact that decides a shot, past any bounces off
    the other walls and balls)."""
    # ---- observation
    observed_balls: str = "all"
    """``"all"``: a block per ball in the observation; ``"controlled"``: the controlled balls' blocks
    only, for scenes of many balls the agent does not steer."""
    observe: str = "plain"
    """What the observation holds: ``"plain"``, the balls, targets and globals; ``"predicted"``, also,
    per observed ball, its next wall impact as the engine predicts it with no further nudge (contact
    point, time, and whether it hits a target), found by running a copy of the engine ``lookahead`` s
    ahead at every step."""
    bank_images: int = 0
    """With ``n > 0``, the observation ends (before the predicted blocks) with the current target's
    bank-shot aims from the first controlled ball: for the target and its ``2 n`` mirror images in
    the two walls along its wall (``n`` reflections each way), the unit direction from the ball to
    the image and whether that straight unfolded path passes every other ball (``task.images``).
    2D, one target at a time."""
    lookahead: float = 5.0
    """How far ahead (s) the prediction of ``observe="predicted"`` and ``aim="predicted"`` or ``"landing"`` runs."""
    predicted_impact: str = "next"
    """Which impact of a scoring ball the prediction reports: ``"next"``, its next wall impact;
    ``"scoring"``, the first of its wall impacts within the look-ahead that lands on a visible pending
    target, or its next one when none does (``aim="predicted"`` then also takes the nearest of all its
    impacts within the look-ahead)."""
    # ---- episode
    time_limit: float = 10.0
    """Episode length in s of simulated time: the env truncates after round(``time_limit`` / ``dt``) steps."""
    # ---- engine
    mode: str = "exact"
    """The engine's fidelity mode, one of ``collision_env.engine.MODES``."""
    substeps: int = 1
    """Sub-steps per control step of the cheap modes, 1 to ``collision_env.engine.MAX_SUBSTEPS``."""
    max_events: int = 10_000
    """The engine's cap on events per step and scene."""
    # derived (not arguments)
    n_steps: int = field(init=False, default=0)
    """Control steps per episode, derived: round(``time_limit`` / ``dt``), at least 1."""

    def __new__(cls, *args, **kwargs):
        check_keywords(kwargs, field_names())  # before the generated __init__, which names no close match
        return super().__new__(cls)

    def __post_init__(self):  # one check per field, in order
        s = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if self.dimension not in (1, 2) or isinstance(self.dimension, bool):
            raise ValueError(f"dimension: must be 1 or 2, got {self.dimension!r}")
        s("dimension", int(self.dimension))
        bounds = self.bounds
        if bounds is None:
            bounds = PLAY_AREA_1D if self.dimension == 1 else PLAY_AREA_2D
            s("bounds", bounds)
        try:
            b = tuple(float(v) for v in bounds)
        except (TypeError, ValueError):
            raise ValueError(f"bounds: expected (xmin, ymin, xmax, ymax), got {self.bounds!r}") from None
        if len(b) != 4 or not all(math.isfinite(v) for v in b) or not (b[0] < b[2] and b[1] < b[3]):
            raise ValueError(f"bounds: expected finite (xmin, ymin, xmax, ymax) with min < max, got {self.bounds!r}")
        if self.dimension == 1 and not (b[1] < 0.0 < b[3]):
            raise ValueError(f"bounds: a 1D scene needs ymin < 0 < ymax, got {b}")
        s("bounds", b)
        s("elasticity", _number("elasticity", self.elasticity, low=0.0, high=1.0))
        if self.inelastic not in ("slip", "stick"):
            raise ValueError(f"inelastic: must be 'slip' or 'stick', got {self.inelastic!r}")
        if not isinstance(self.ball_collisions, (bool, np.bool_)):
            raise ValueError(f"ball_collisions: expected a bool, got {self.ball_collisions!r}")
        s("ball_collisions", bool(self.ball_collisions))
        s("n_balls", _number("n_balls", self.n_balls, low=1, integer=True))
        s("mass_range", _pair("mass_range", self.mass_range))
        if self.mass_range[0] <= 0:
            raise ValueError(f"mass_range: masses must be > 0, got {self.mass_range!r}")
        others = _pair(
            "others_mass_range", self.mass_range if self.others_mass_range is None else self.others_mass_range
        )
        s("others_mass_range", others)
        if others[0] <= 0:
            raise ValueError(f"others_mass_range: masses must be > 0, got {self.others_mass_range!r}")
        if isinstance(self.radius, str):
            if self.radius not in RADIUS_RULES:
                raise ValueError(f"radius: expected 'mass', 'constant' or a positive number, got {self.radius!r}")
        else:
            s("radius", _number("radius", self.radius, low=0.0, strict_low=True))
        if self.layout not in LAYOUTS:
            raise ValueError(f"layout: expected one of {LAYOUTS}, got {self.layout!r}")
        if self.layout == "fence" and self.dimension != 2:
            raise ValueError(f"layout: 'fence' needs dimension=2, got dimension={self.dimension}")
        s("speed_range", _pair("speed_range", self.speed_range, low=0.0))
        s("others_speed_range", _pair("others_speed_range", self.others_speed_range, low=0.0))
        try:
            ctrl = tuple(int(i) for i in np.atleast_1d(np.asarray(self.controlled)))
        except (TypeError, ValueError):
            raise ValueError(f"controlled: expected ball indices, got {self.controlled!r}") from None
        if not ctrl or len(set(ctrl)) != len(ctrl) or not all(0 <= i < self.n_balls for i in ctrl):
            raise ValueError(f"controlled: need distinct ball indices in [0, {self.n_balls}), got {self.controlled!r}")
        s("controlled", ctrl)
        if self.control not in CONTROLS:
            raise ValueError(f"control: expected one of {CONTROLS}, got {self.control!r}")
        s("dt", _number("dt", self.dt, low=0.0, strict_low=True))
        s("max_dv", _number("max_dv", self.max_dv, low=0.0, high=MAX_MAGNITUDE))
        s("max_speed", _number("max_speed", self.max_speed, low=0.0, strict_low=True, high=MAX_MAGNITUDE))
        s("n_targets", _number("n_targets", self.n_targets, low=1, integer=True))
        s("sequential", bool(self.sequential))
        allowed = WALL_NAMES[:2] if self.dimension == 1 else WALL_NAMES
        walls = allowed if self.target_walls is None else self.target_walls
        if isinstance(walls, str):
            walls = (walls,)
        walls = tuple(walls)
        if not walls or not all(w in allowed for w in walls):
            raise ValueError(f"target_walls: expected a non-empty subset of {allowed}, got {self.target_walls!r}")
        s("target_walls", walls)
        s("target_width", _number("target_width", self.target_width, low=0.0, strict_low=True))
        shortest = min((b[3] - b[1]) if w in ("left", "right") else (b[2] - b[0]) for w in walls)
        if self.dimension == 2 and self.target_width > shortest:
            raise ValueError(
                f"target_width: {self.target_width} m is longer than the shortest target wall ({shortest} m)"
            )
        if self.scorers not in SCORERS:
            raise ValueError(f"scorers: expected one of {SCORERS}, got {self.scorers!r}")
        if self.scorers == "others" and len(ctrl) == self.n_balls:
            raise ValueError("scorers: 'others' needs at least one ball that is not controlled")
        sticky = self.inelastic == "stick" and self.elasticity == 0.0 and self.ball_collisions
        if self.scorers == "cluster" and not sticky:
            raise ValueError(
                "scorers: 'cluster' needs a stick scene (inelastic='stick', elasticity=0, ball_collisions=True)"
            )
        if self.scorers == "cluster" and self.n_balls < 2:
            raise ValueError("scorers: 'cluster' needs at least 2 balls")
        for name in ("hit_reward", "success_bonus", "miss_penalty", "action_cost", "shaping"):
            s(name, _number(name, getattr(self, name), low=-MAX_MAGNITUDE, high=MAX_MAGNITUDE))
        if self.observed_balls not in OBSERVED_BALLS:
            raise ValueError(f"observed_balls: expected one of {OBSERVED_BALLS}, got {self.observed_balls!r}")
        if self.aim not in AIMS:
            raise ValueError(f"aim: expected one of {AIMS}, got {self.aim!r}")
        if self.observe not in OBSERVATIONS:
            raise ValueError(f"observe: expected one of {OBSERVATIONS}, got {self.observe!r}")
        s("bank_images", _number("bank_images", self.bank_images, low=0, high=MAX_BANK_IMAGES, integer=True))
        if self.bank_images and (self.dimension != 2 or (self.n_targets > 1 and not self.sequential)):
            raise ValueError(
                f"bank_images: needs dimension=2 and one target at a time, got dimension={self.dimension}, "
                f"n_targets={self.n_targets}, sequential={self.sequential}"
            )
        s("lookahead", _number("lookahead", self.lookahead, low=0.0, strict_low=True))
        if self.predicted_impact not in PREDICTED_IMPACTS:
            raise ValueError(f"predicted_impact: expected one of {PREDICTED_IMPACTS}, got {self.predicted_impact!r}")
        s("time_limit", _number("time_limit", self.time_limit, low=0.0, strict_low=True))
        if self.time_limit < self.dt:
            raise ValueError(f"time_limit: must be at least one control step dt={self.dt}, got {self.time_limit}")
        if self.window is not None:
            s("window", _number("window", self.window, low=0.0, strict_low=True))
            if self.window > self.time_limit:
                raise ValueError(f"window: {self.window} s is longer than time_limit {self.time_limit} s")
        if self.mode not in MODES:
            raise ValueError(f"mode: expected one of {tuple(MODES)}, got {self.mode!r}")
        s("substeps", _number("substeps", self.substeps, low=1, high=MAX_SUBSTEPS, integer=True))
        s("max_events", _number("max_events", self.max_events, low=1, high=MAX_EVENT_CAP, integer=True))
        steps = self.time_limit / self.dt
        if not steps <= MAX_EPISODE_STEPS:
            raise ValueError(
                f"time_limit: {self.time_limit:g} s in control steps of dt = {self.dt:g} s is {steps:.3g} steps, "
                f"more than an episode counts exactly (2**53); take a shorter time_limit or a longer dt"
            )
        s("n_steps", max(1, int(round(steps))))
        # geometric feasibility: every ball must fit, and the balls must be placeable
        extremes = np.array([*self.mass_range, *others])
        r_big = float(self.radius_of(extremes).max())
        if 2 * r_big >= min(b[2] - b[0], b[3] - b[1]):
            raise ValueError(f"radius: a ball of radius {r_big:.4g} m does not fit in bounds {b}")
        if self.layout == "fence":
            r_peg = float(self.radius_of(np.array(others)).max())
            n_pegs = self.n_balls - len(ctrl)
            if FENCE_SPACING * r_peg * (n_pegs + 1) > b[3] - b[1]:
                raise ValueError(
                    f"n_balls: a fence of {n_pegs} balls of radius {r_peg:.4g} m, {FENCE_SPACING} radii apart, "
                    f"leaves no opening in bounds {b}"
                )
        if self.dimension == 1:
            if 2 * r_big * self.n_balls > 0.8 * (b[2] - b[0]):
                raise ValueError(f"n_balls: {self.n_balls} balls of radius up to {r_big:.4g} m do not fit on the line")
        else:
            room = 0.3 * (b[2] - b[0]) * (b[3] - b[1]) * (1.0 if self.layout == "random" else 0.5)
            if self.n_balls * math.pi * r_big**2 > room:
                raise ValueError(
                    f"n_balls: {self.n_balls} balls of radius up to {r_big:.4g} m are too many for bounds {b}"
                )

    # ----------------------------------------------------------------------------------------- #
    def radius_of(self, masses: np.ndarray) -> np.ndarray:
        """Radii (m) of balls with these masses under this config's radius rule."""
        if self.radius == "mass":
            return radius_from_mass(masses)
        value = 0.15 if self.radius == "constant" else float(self.radius)
        return np.full(np.shape(masses), value, dtype=np.float64)

    @property
    def action_dim(self) -> int:
        """Length of the action vector: :attr:`per_ball_action` per controlled ball."""
        return len(self.controlled) * self.per_ball_action

    @property
    def per_ball_action(self) -> int:
        """Action components per controlled ball: one per axis, and the engage flag with ``control="velocity"``."""
        return self.dimension + (self.control == "velocity")

    @property
    def target_slots(self) -> int:
        """Target blocks in the observation: one with ``sequential`` targets, else one per target."""
        return 1 if self.sequential else self.n_targets

    @property
    def obs_dim(self) -> int:
        """Length of the observation vector (the layout is tabled in each env's docstring)."""
        shown = self.n_observed
        images = (2 * self.bank_images + 1) * IMAGE_FEATURES if self.bank_images else 0
        return self.images_at + images + (shown * PREDICTED_FEATURES if self.observe == "predicted" else 0)

    @property
    def images_at(self) -> int:
        """Where the bank-shot aims (``bank_images``) start in the observation: after the globals."""
        return self.n_observed * BALL_FEATURES + self.target_slots * TARGET_FEATURES + GLOBAL_FEATURES

    @property
    def shown_mask(self) -> np.ndarray:
        """(n_balls,) bool: the balls that have a block in the observation (``observed_balls``)."""
        if self.observed_balls == "all":
            return np.ones(self.n_balls, dtype=bool)
        mask = np.zeros(self.n_balls, dtype=bool)
        mask[list(self.controlled)] = True
        return mask

    @property
    def n_observed(self) -> int:
        """Number of ball blocks in the observation."""
        return self.n_balls if self.observed_balls == "all" else len(self.controlled)

    @property
    def scoring_mask(self) -> np.ndarray:
        """(n_balls,) bool: balls whose wall impacts may score (before the cluster condition)."""
        mask = np.zeros(self.n_balls, dtype=bool)
        ctrl = list(self.controlled)
        if self.scorers == "controlled":
            mask[ctrl] = True
        elif self.scorers == "others":
            mask[:] = True
            mask[ctrl] = False
        else:
            mask[:] = True
        return mask

    def replace(self, **changes: Any) -> TaskConfig:
        """A copy with ``changes`` (field names as keywords), checked as a new config is."""
        return dataclasses.replace(self, **changes)


# --------------------------------------------------------------------------------------------- #
#: Preset name -> its ``TaskConfig`` fields. Each task's env file declares its preset, and
#: ``collision_env.envs.registry.register_task`` enters it here (and registers its id).
PRESETS: dict[str, dict] = {}


def field_names() -> tuple[str, ...]:
    """The :class:`TaskConfig` fields a caller may set (every keyword ``gym.make`` passes on to the task)."""
    return tuple(f.name for f in dataclasses.fields(TaskConfig) if f.init)


def keywords_of(*functions: Callable[..., Any]) -> tuple[str, ...]:
    """The named parameters of ``functions`` (an env's ``__init__``, ``gym.make``): what ``also`` offers."""
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return tuple(
        name
        for f in functions
        for name, p in inspect.signature(f).parameters.items()
        if p.kind in kinds and name not in ("self", "id")
    )


def make_config(preset: str | None = "one_ball", *, also: Iterable[str] = (), **overrides: Any) -> TaskConfig:
    """The preset's :class:`TaskConfig` with ``overrides`` applied (``preset=None``: the defaults).

    An unknown preset is a ``ValueError``; an unknown keyword an
    :class:`~collision_env.engine.keywords.UnknownKeywordError` (a ``TypeError`` and a
    ``ValueError``) that suggests the closest names among the fields and ``also``, the keywords the
    caller takes itself (an env's ``render_mode``, say).
    """
    if preset is None:
        base = {}
    elif preset in PRESETS:
        base = dict(PRESETS[preset])
    else:
        close = difflib.get_close_matches(str(preset), sorted(PRESETS), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"preset: expected one of {sorted(PRESETS)} or None, got {preset!r}{hint}")
    check_keywords(overrides, (*field_names(), *also))
    base.update(overrides)
    return TaskConfig(**base)
