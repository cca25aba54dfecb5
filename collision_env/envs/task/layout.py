"""Named columns of the task's packed arrays, each layout generated from one table.

The task state lives in a few packed arrays (every array handed to a compiled kernel costs time to
pass, on every step), so a column is known by its index. :func:`layout` turns one table of rows,
``(field names, meaning)``, into a namedtuple *instance* mapping each field name to its column:
``SCENE_FLOATS.reward`` is 2. Kernels read it as a global, which numba freezes into compile-time
constants (``S[b, SCENE_FLOATS.reward]`` compiles to the same code as ``S[b, 2]``), and ``len()`` of
it is the number of columns. The meanings stay attached to the layout's class
(``layout_rows``), so documentation tables are generated from the same table the kernels index by.
"""

from __future__ import annotations

from collections import namedtuple
from typing import Any, cast

from collision_env.engine.scene import WALL_NAMES


def layout(name: str, rows: tuple) -> Any:
    """A namedtuple instance: field name -> column index, columns numbered in the order of ``rows``.

    ``rows`` is a tuple of ``(names, meaning)``: ``names`` is one field name or several separated by
    spaces (fields documented together, such as ``"x y"``), ``meaning`` what the columns hold.
    (Typed ``Any``: its fields are made from the table.)
    """
    fields = [field for names, _ in rows for field in names.split()]
    cls = cast(Any, namedtuple(name, fields))
    cls.layout_rows = tuple((tuple(names.split()), meaning) for names, meaning in rows)
    return cls(*range(len(fields)))


def rows_of(columns: Any) -> tuple:
    """``((first column, last column, meaning), ...)`` of a layout, one entry per row of its table."""
    out = []
    for names, meaning in type(columns).layout_rows:
        out.append((getattr(columns, names[0]), getattr(columns, names[-1]), meaning))
    return tuple(out)


# --------------------------------------------------------------------------------------------- #
# The task's packed arrays (one row per scene; the shapes are in ``TaskCore``).

#: Float task parameters ``P`` (one vector, shared by every scene), read by both step kernels.
PARAMS = layout(
    "Params",
    (
        ("xmin ymin xmax ymax", "play area bounds, m"),
        ("hit_reward miss_penalty success_bonus shaping", "reward terms (see TaskConfig)"),
        ("vscale", "velocity scale of the observation (2 max_speed), m/s"),
        ("mscale", "mass scale of the observation, kg"),
        ("time_limit", "episode length, s (window observation scale)"),
        ("max_dv", "velocity change of a full nudge component, the most a velocity step changes an axis; m/s"),
        ("max_speed", "speed a nudge never pushes a ball above, m/s"),
        ("action_cost", "reward cost per m/s of requested nudge"),
    ),
)

#: Integer task parameters ``Q`` (one vector, shared by every scene).
SWITCHES = layout(
    "Switches",
    (
        ("sequential", "1: one target at a time"),
        ("cluster", "1: only balls stuck in a cluster score"),
        ("dimension", "1 or 2"),
        ("n_steps", "control steps per episode"),
        ("sticky", "1: the engine merges colliding balls (the nudge moves whole clusters)"),
        ("observe_predicted", "1: the observation ends with the engine's predicted impacts"),
        ("aim_predicted", "phi from the engine's predicted impacts: 0 no, 1 the nearest, 2 the landing (AIM_LANDING)"),
        ("control", "what an action means: the index of TaskConfig.control in CONTROLS (0 nudge, 1 velocity, 2 shot)"),
        ("predict_scoring", "1: the prediction looks past a scoring ball's next wall impact for one on a target"),
    ),
)

#: Per-scene floats ``S`` (B, len).
SCENE_FLOATS = layout(
    "SceneFloats",
    (
        ("phi", "aiming potential at the last observation"),
        ("nudge", "requested velocity change of the step, m/s"),
        ("reward", "reward of the step"),
        ("energy", "kinetic energy, J"),
    ),
)

#: Per-scene integers ``C`` (B, len); ``hits`` and ``misses`` are the task kernel's scratch.
SCENE_INTS = layout(
    "SceneInts",
    (
        ("current", "index of the current target (sequential targets)"),
        ("steps", "control steps taken this episode"),
        ("targets_hit", "targets hit so far"),
        ("terminated truncated success", "end flags of the step"),
        ("hits misses", "target hits and off-target wall impacts of the step"),
    ),
)

#: Per-target integers ``T`` (B, K, len).
TARGET_INTS = layout(
    "TargetInts",
    (
        ("wall", "wall code (an index into collision_env.engine.WALL_NAMES)"),
        ("status", "TARGET_PENDING, TARGET_HIT or TARGET_FAILED"),
    ),
)

#: Per-target geometry ``t_geo`` (B, K, len).
TARGET_GEOMETRY = layout(
    "TargetGeometry",
    (
        ("centre", "centre of the segment along its wall, m"),
        ("half_width", "half width of the segment, m"),
        ("opens closes", "time window, s (-1e300, 1e300 without one)"),
    ),
)

#: Float parameters of the episode builder.
EPISODE_FLOATS = layout(
    "EpisodeFloats",
    (
        ("xmin ymin xmax ymax", "play area bounds, m"),
        ("speed_low speed_high", "initial speed range of the controlled balls, m/s"),
        ("others_low others_high", "initial speed range of the other balls, m/s"),
        ("half_width", "half width of a target, m"),
        ("window", "length of a target's time window, s (< 0: no windows)"),
        ("time_limit", "episode length, s"),
    ),
)

#: Integer parameters of the episode builder.
EPISODE_INTS = layout(
    "EpisodeInts",
    (
        ("dimension n_balls n_targets", "the task's sizes"),
        ("rack", "1: controlled balls in the left 40 % (the others in the right half, unless fence)"),
        ("fence", "1: the balls not controlled in a column with an opening (TaskConfig.layout)"),
        ("tries", "placement tries per ball in one block of random numbers"),
    ),
)

#: ``SWITCHES.control`` codes: the index of ``TaskConfig.control`` in ``CONTROLS``.
CONTROL_NUDGE, CONTROL_VELOCITY, CONTROL_SHOT = 0, 1, 2

#: The ``SWITCHES.aim_predicted`` code of ``aim="landing"``: the index of ``TaskConfig.aim`` in
#: ``AIMS``, as for "predicted" (1; 0: straight flight, or no aiming term when ``shaping`` is 0).
AIM_LANDING = 2

#: Target status codes (``TARGET_INTS.status``).
TARGET_PENDING, TARGET_HIT, TARGET_FAILED = 0, 1, 2

#: Row flags of the task kernel: what to do with each scene.
ROW_RESET = 0  # a scene just reset: start its episode and observe it
ROW_STEPPED = 1  # a stepped scene: score it and observe it
ROW_SKIP = 2  # leave it alone
ROW_OBSERVE = 3  # observe it without changing anything

# --------------------------------------------------------------------------------------------- #
# The observation: N ball blocks, S target slots (1 with sequential targets, else K), the globals.
# Centre and half-size of the play area are (xc, yc), (xh, yh); vs = 2 max_speed.

#: One ball's block of the observation.
BALL_OBS = layout(
    "BallObs",
    (
        ("x y", "ball i position: (x - xc) / xh, (y - yc) / yh"),
        ("vx vy", "ball i velocity: vx / vs, vy / vs (0 for y in 1D)"),
        ("mass", "ball i mass / 3 kg"),
        ("scoring", "1 if ball i's wall impacts currently score, else 0"),
    ),
)

#: One target slot's block of the observation (the one-hot follows the engine's wall codes).
TARGET_OBS = layout(
    "TargetObs",
    (
        ("x y", "target s centre point, normalised like positions"),
        ("half_width", "target s half width / half length of its wall"),
        (" ".join(f"wall_{w}" for w in WALL_NAMES), f"target s wall one-hot ({', '.join(WALL_NAMES)})"),
        ("status", "target s status: 1 pending, 0 hit, -1 failed (window closed)"),
        ("opens closes", "(window open - t) / time_limit, (window close - t) / time_limit"),
    ),
)

#: The observation's last entries.
GLOBAL_OBS = layout(
    "GlobalObs",
    (
        ("steps_left", "fraction of the episode's control steps left"),
        ("targets_left", "fraction of targets not yet hit"),
    ),
)


#: One ball's block of the engine's prediction (``TaskConfig.observe = "predicted"``), after the globals:
#: the scene is run ahead ``lookahead`` seconds on a copy of the engine with no further nudge.
PREDICTED_OBS = layout(
    "PredictedObs",
    (
        ("x y", "ball i's predicted wall impact (no more nudges), normalised like positions"),
        ("time", "time until it / time_limit (1, and point 0, 0: none within the lookahead)"),
        ("hits", "1 if it lands on a visible pending target inside its window, else 0"),
    ),
)


def _index_label(base: str, first: int, last: int) -> str:
    if first == last:
        return f"{base}{first}"
    return f"{base}{first}, {last}" if last == first + 1 else f"{base}{first}..{last}"


def observation_table() -> str:
    """The generic env's observation table (Markdown), generated from the observation layouts.

    N balls, S target slots; ``observe="predicted"`` appends one ``PREDICTED_OBS`` block per ball
    after the globals.
    """
    nb, nt, ng = len(BALL_OBS), len(TARGET_OBS), len(GLOBAL_OBS)
    rows = [(_index_label(f"{nb}i + ", a, b), m) for a, b, m in rows_of(BALL_OBS)]
    rows += [(_index_label(f"{nb}N + {nt}s + ", a, b), m) for a, b, m in rows_of(TARGET_OBS)]
    rows += [(_index_label(f"{nb}N + {nt}S + ", a, b), m) for a, b, m in rows_of(GLOBAL_OBS)]
    npred = len(PREDICTED_OBS)
    rows += [(_index_label(f"{nb}N + {nt}S + {ng} + {npred}i + ", a, b), m) for a, b, m in rows_of(PREDICTED_OBS)]
    wide = max(len("Index"), *(len(i) for i, _ in rows))
    text = max(len("Observation"), *(len(m) for _, m in rows))
    lines = [f"| {'Index':<{wide}} | {'Observation':<{text}} |", f"|{'-' * (wide + 2)}|{'-' * (text + 2)}|"]
    lines += [f"| {i:<{wide}} | {m:<{text}} |" for i, m in rows]
    return "\n".join(lines)
