"""Checks of a task state handed to ``set_state``, before anything changes.

The task kernels index arrays with the task state's integers (the current target, the cluster
roots) and fold its floats into rewards and observations, without checks of their own (a compiled
kernel does not check its indices). So the envs' ``set_state`` checks every value first, as the
engine checks its balls: each field's kind (integers or real numbers), then each column's range.
A bad value raises a ``ValueError`` naming the field, its column, the scene (in a batch of more
than one), the target or ball, and what the value must be.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from collision_env.engine.scene import MAX_MAGNITUDE, WALL_NAMES
from collision_env.engine.validation import refuse_first
from collision_env.envs._config import MAX_EPISODE_STEPS

from .layout import SCENE_FLOATS, SCENE_INTS, TARGET_GEOMETRY, TARGET_INTS

#: The task state's fields holding integers (the others hold real numbers).
INTEGER_FIELDS = ("scene_i", "targets", "body")

# A rule: (field, column name or None for a whole field, test of (values, the field's array) ->
# bool mask of good values, what a value must be). Columns of a layout are read by name.
_Rule = tuple[str, str | None, Callable[[np.ndarray, np.ndarray], np.ndarray], str]


def _between(low: float, high: float) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    return lambda v, _: (low <= v) & (v <= high)


def _rules(n_targets: int, n_balls: int, walls: tuple[int, ...]) -> list[_Rule]:
    """The rules of a task of ``n_targets`` targets on ``walls`` (codes) and ``n_balls`` balls."""
    big = MAX_MAGNITUDE
    geo = TARGET_GEOMETRY
    flag = "must be 0 or 1 (a flag)"
    return [
        ("scene_f", "phi", _between(-1.0, 0.0), "must be from -1 to 0 (minus a distance over the diagonal)"),
        ("scene_f", "nudge", lambda v, _: np.isfinite(v) & (v >= 0.0), "must be finite and >= 0 (m/s)"),
        ("scene_f", "reward", lambda v, _: np.isfinite(v), "must be finite"),
        ("scene_f", "energy", lambda v, _: np.isfinite(v) & (v >= 0.0), "must be finite and >= 0 (J)"),
        ("scene_i", "current", _between(0, n_targets), f"must be a target index from 0 to {n_targets} (all hit)"),
        ("scene_i", "steps", _between(0, MAX_EPISODE_STEPS), "must be from 0 to 2**53"),
        ("scene_i", "targets_hit", _between(0, n_targets), f"must be from 0 to {n_targets}"),
        ("scene_i", "terminated", _between(0, 1), flag),
        ("scene_i", "truncated", _between(0, 1), flag),
        ("scene_i", "success", _between(0, 1), flag),
        ("scene_i", "hits", _between(0, MAX_EPISODE_STEPS), "must be from 0 to 2**53"),
        ("scene_i", "misses", _between(0, MAX_EPISODE_STEPS), "must be from 0 to 2**53"),
        (
            "targets",
            "wall",
            lambda v, _: np.isin(v, walls),
            f"must be the code of one of the walls targets sit on, {[f'{c} ({WALL_NAMES[c]})' for c in walls]}",
        ),
        ("targets", "status", _between(0, 2), "must be 0, 1 or 2 (pending, hit, failed)"),
        ("target_geo", "centre", _between(-big, big), f"must be finite, within {big:g} m"),
        ("target_geo", "half_width", lambda v, _: (0.0 < v) & (v <= big), f"must be finite and > 0, at most {big:g} m"),
        ("target_geo", "opens", lambda v, _: ~np.isnan(v), "must be a time (s)"),
        ("target_geo", "closes", lambda v, a: v >= a[..., geo.opens], "must be a time (s), at least opens"),
        ("body", None, _between(0, n_balls - 1), f"must be a ball index from 0 to {n_balls - 1}"),
        (
            "body",
            None,
            lambda v, _: np.take_along_axis(v, v, axis=1) == v,
            "must be a ball index whose cluster root is its own",
        ),
    ]


_LAYOUTS = {"scene_f": SCENE_FLOATS, "scene_i": SCENE_INTS, "targets": TARGET_INTS, "target_geo": TARGET_GEOMETRY}


def _where(scene: int, item: int | None, field: str, batch: int) -> str:
    """``"scene b, target k: "`` of an element of a field's values (its column taken off; ``item``
    None where a value is the scene's own)."""
    parts = [f"scene {scene}"] if batch > 1 else []
    if item is not None:
        parts.append(f"{'ball' if field == 'body' else 'target'} {item}")
    return ", ".join(parts) + ": " if parts else ""


def _refuse_first(bad: np.ndarray, values: np.ndarray, name: str, column: str | None, must: str) -> None:
    """The engine's ``refuse_first`` over a rule's ``bad`` mask of ``values`` (per scene, or per
    scene and target or ball), the field named as ``name`` and ``column``."""
    batch = values.shape[0]
    flat = values.reshape(batch, -1)  # (scenes x their targets or balls: refuse_first's grid)

    def where(s: int, k: int) -> str:
        return _where(s, k if values.ndim > 1 else None, name, batch)

    def message(s: int, k: int) -> str:
        return f"{must}, got {flat[s, k].item()!r}"

    field = f"set_state: {name if column is None else f'{name} {column}'}"
    refuse_first(bad.reshape(batch, -1), where, message, field=field)


def checked_task_state(
    state: Mapping[str, Any], current: Mapping[str, np.ndarray], n_targets: int, walls: tuple[int, ...]
) -> dict[str, np.ndarray]:
    """The task arrays of ``state`` (``current``'s fields: a task state as ``TaskCore.get_state``
    gives it), checked against ``current``'s shapes and the rules of a task of ``n_targets``
    targets on ``walls`` (wall codes): fresh arrays of ``current``'s dtypes (raises ValueError)."""
    arrays = {}
    for name, now in current.items():
        given = np.asarray(state[name])
        if given.shape != now.shape:
            raise ValueError(f"set_state: field {name!r} has shape {given.shape}, expected {now.shape}")
        whole = name in INTEGER_FIELDS
        if given.dtype.kind not in ("iu" if whole else "iuf"):
            raise ValueError(
                f"set_state: {name}: expected {'integers' if whole else 'real numbers'}, got dtype {given.dtype}"
            )
        arrays[name] = given
    batch, n_balls = current["body"].shape
    for name, column, good, must in _rules(n_targets, n_balls, walls):
        values = arrays[name] if column is None else arrays[name][..., getattr(_LAYOUTS[name], column)]
        with np.errstate(invalid="ignore"):
            bad = ~good(values, arrays[name])
        _refuse_first(bad, values, name, column, must)
    return {name: arr.astype(current[name].dtype) for name, arr in arrays.items()}


def check_cluster_mirror(body: np.ndarray, engine: Any) -> None:
    """The task's cluster mirror ``body`` (checked by :func:`checked_task_state`) against the
    clusters of the engine state ``engine`` handed over with it: at the end of every step the two
    are equal (the task replays the step's merges and splits onto its mirror, in every mode), so a
    state pieced together from two snapshots is refused, naming the ball (raises ValueError). An
    engine state without clusters of the mirror's shape and kind is left to the engine's checks."""
    try:
        clusters = np.asarray(engine["clusters"])
    except (KeyError, TypeError, IndexError):
        return
    if clusters.shape != body.shape or clusters.dtype.kind not in "iu":
        return
    _refuse_first(clusters != body, body, "body", None, "must be the ball's cluster root in the engine's state")
