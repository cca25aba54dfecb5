"""Checks of everything a user hands the engine, before anything changes.

Every public entry point of :class:`~collision_env.engine.BatchSimulator` runs its input through
these functions first, so that bad input raises a ``ValueError`` naming the ball and the field and
leaves the state as it was. Values are type-checked (numpy scalar types are numbers; booleans,
strings and complex numbers are refused), and values the engine cannot represent are refused too
(positions and speeds beyond :data:`MAX_MAGNITUDE`, masses whose inverse overflows, radii below
float64's resolution at the scene's coordinates, a ball with no room to move in the box, a step
that would fly a ball out of range).
"""

from __future__ import annotations

import numbers
import warnings
from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

import numpy as np

from .broadphase import first_overlap, first_overlap_periodic, spans_walls, wall_to_wall
from .keywords import close_matches
from .physics.periodic import MAX_IMAGES, periods, wrap_positions
from .physics.tolerance import CONTACT_RTOL, EPS, roundoff
from .scene import CONSTANT_RADIUS, MAX_MAGNITUDE, Scene, is_real, radius_from_mass
from .snapshot import FIELDS as STATE_FIELDS
from .snapshot import SimulatorState

#: Relative tolerance for "touching" in the start-state checks: the engine's own contact tolerance,
#: within which its steps leave touching balls and walls (exact mode's impacts leave pairs a few
#: 1e-12 of their radii sum apart either way, the cheap modes' walls a ball a few 1e-12 of its
#: radius past them).
START_CONTACT_RTOL = CONTACT_RTOL
#: A radius must span this many units in the last place of the scene's coordinates: contact is then
#: resolved to better than 1e-4 of the radius (``tolerance.contact_tolerance``) anywhere in the scene.
MIN_RADIUS_ULPS = 2.0**16
#: Most sub-steps per step (naive and posteriori modes): a compiled step cannot be interrupted, so
#: this bounds its work, to 1e5 sub-steps of ~20-50 ns per ball each (the broad phase keeps a
#: sub-step's work linear in the balls).
MAX_SUBSTEPS = 100_000
#: Largest event cap (``max_events``): the kernels count events in int64.
MAX_EVENT_CAP = 2**63 - 1
#: How far apart the cheap modes may leave two balls they stuck together, relative to their radii
#: sum: posteriori reconstructs each contact of a sub-step on its own, and the re-advance of the
#: bodies it stuck leaves gaps (measured on 6,600 random stick scenes, up to 16 sub-steps, speeds
#: 0.5-50 m/s, steps up to 1 s: at most 0.29 of the radii sum; naive leaves none). A cluster glued
#: across more than its balls' size is refused.
CHEAP_STICK_GAP_RTOL = 1.0
#: The largest finite float64: a Python int beyond it has no float64 value (``float`` raises).
_LARGEST_FLOAT = int(np.finfo(np.float64).max)


def _magnitude(x: int) -> str:
    """A huge integer in short: its sign and order of magnitude."""
    return f"an integer of about {'-' if x < 0 else ''}1e{len(str(abs(x))) - 1}"


def real_number(value: Any, field: str) -> float:
    """``value`` as a float: a real number (numpy scalar types included), not a boolean or a string."""
    if isinstance(value, float):  # the common case (np.float64 too), at the cost of one test
        return value
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if not is_real(value):
        raise ValueError(
            f"{field}: expected a number (real, not a boolean or a string), got {value!r} ({type(value).__name__})"
        )
    try:
        return float(value)
    except OverflowError:  # an int beyond float64's range
        raise ValueError(f"{field}: must be within float64's range, got {_magnitude(value)}") from None


def positive_integer(value: Any, field: str, most: int | None = None) -> int:
    """``value`` as an int: a whole number of at least 1 (not a boolean), and at most ``most``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) or int(value) < 1:
        raise ValueError(f"{field}: must be a positive integer, got {value!r}")
    if most is not None and int(value) > most:
        raise ValueError(f"{field}: must be at most {most:,}, got {value:,}")
    return int(value)


def check_seconds(value: float, field: str) -> None:
    """A time or a step (s), already a float: finite and at most :data:`MAX_MAGNITUDE`."""
    if not abs(value) <= MAX_MAGNITUDE:
        raise ValueError(f"{field}: must be finite and at most {MAX_MAGNITUDE:g} s, got {value}")


def real_array(value: Any, shapes: list, field: str, where: Callable, label: Labels | None = None) -> np.ndarray:
    """A float64 copy of ``value``: real numbers (no booleans, strings or complex numbers) in one of
    ``shapes``, the last of them the batched one. ``where(index)`` names the ball of an element, and
    ``label`` shows shapes (for the error message). A field with the batched shape alone is one that
    a single simulator wraps in a batch axis of its own: its shape is shown without it."""
    rank = len(shapes[-1])

    def expected():
        shown = (label.shape(s, len(s) == rank) if label else str(s) for s in shapes)
        return " or ".join(dict.fromkeys(shown))

    if isinstance(value, np.ndarray) and value.dtype.kind in "iuf":
        arr = value.astype(np.float64)
    else:
        try:
            obj = np.array(value, dtype=object)
        except ValueError:
            raise ValueError(f"{field}: expected real numbers of shape {expected()}, got a ragged sequence") from None
        if obj.shape in shapes:
            for index, x in np.ndenumerate(obj):
                if not is_real(x):
                    raise ValueError(
                        f"{where(index)}{field} must be real numbers (not booleans, strings or complex), "
                        f"got {x!r} ({type(x).__name__})"
                    )
                if isinstance(x, numbers.Integral) and not abs(int(x)) <= _LARGEST_FLOAT:
                    raise ValueError(f"{where(index)}{field} must be within float64's range, got {_magnitude(int(x))}")
        arr = obj.astype(np.float64) if obj.shape in shapes else obj
    if arr.shape not in shapes:
        got = label.shape(arr.shape, arr.ndim == rank or len(shapes) == 1) if label else str(arr.shape)
        raise ValueError(f"{field}: expected shape {expected()}, got {got}")
    return arr


class Labels:
    """How errors name a ball (``"scene s, ball i: "`` in a batch, ``"ball i: "`` in a batch of one)
    and shapes (without the batch axis for a ``single`` simulator, which has none)."""

    def __init__(self, n_scenes: int, single: bool = False) -> None:
        self.n_scenes = n_scenes
        self.single = single

    def shape(self, shape: tuple[int, ...], batched: bool = True) -> str:
        """``shape`` as the caller passed it: a batched shape loses its leading axis if single."""
        return str(shape[1:] if self.single and batched and len(shape) > 0 else shape)

    def __call__(self, sc, ball=None) -> str:
        where = f"scene {sc}, " if self.n_scenes > 1 else ""
        return f"{where}ball {ball}: " if ball is not None else (f"scene {sc}: " if self.n_scenes > 1 else "")


def refuse_first(
    mask: np.ndarray,
    label: Callable[[int, int], str],
    message: Callable[[int, int], str],
    scenes: np.ndarray | None = None,
    field: str = "",
) -> None:
    """Raise a ValueError for the first ``True`` of a ``(K, N)`` ``mask`` of scenes and balls (or
    other items of a scene), if any: ``"{field}: {label(s, i)}{message(s, i)}"`` (``label``: a
    :class:`Labels`, or any namer of a scene's item), ``s`` and ``i`` the row and column of the mask
    (``scenes[s]`` the scene the label names, if the rows are a pick of the batch's scenes)."""
    if not mask.any():  # (the common case: several times cheaper than argwhere)
        return
    s, i = (int(x) for x in np.argwhere(mask)[0])
    where = label(s if scenes is None else int(scenes[s]), i)
    raise ValueError(f"{field + ': ' if field else ''}{where}{message(s, i)}")


class Balls(NamedTuple):
    """The balls of ``K`` scenes as :func:`checked_balls` checks them: float64 ``(K, N, 2)``
    positions (wrapped into a periodic cell) and velocities, ``(K, N)`` masses and radii, and each
    ball's largest coordinate and each scene's extent (the border, or the balls' own; m)."""

    pos: np.ndarray
    vel: np.ndarray
    mass: np.ndarray
    radius: np.ndarray
    coordinate: np.ndarray
    extent: np.ndarray


def _per_scene(values: np.ndarray, k: int) -> np.ndarray:
    """``(N,)`` or ``(K, N)`` values, a fresh copy from ``real_array``, as ``(K, N)``."""
    return values if values.ndim == 2 else np.tile(values, (k, 1))


def _radii(radii: Any, masses: np.ndarray, k: int, n: int, where: Callable, label: Labels) -> np.ndarray:
    """``(K, N)`` radii: PhET's rule from the masses (``None``), its constant size (``"constant"``),
    or the given ones."""
    if radii is None:
        return radius_from_mass(masses)
    if isinstance(radii, str):
        if radii != "constant":
            raise ValueError(f"radii: expected None, 'constant' or an array, got {radii!r}")
        return np.full((k, n), CONSTANT_RADIUS)
    return _per_scene(real_array(radii, [(n,), (k, n)], "radii", where, label), k)


def _representable(fail: Callable, pos: np.ndarray, vel: np.ndarray, m: np.ndarray, r: np.ndarray) -> None:
    """Positions, speeds, masses (and their inverses), kinetic energies and radii the engine can
    compute with: finite, within :data:`MAX_MAGNITUDE`, masses and radii positive."""
    big = MAX_MAGNITUDE
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        speed = np.hypot(vel[..., 0], vel[..., 1])
        fail(
            ~(np.abs(pos) <= big).all(-1),
            lambda s, i: f"position must be finite, within {big:g} m, got {tuple(pos[s, i].tolist())}",
        )
        fail(  # (a speed within range bounds both components: hypot is at least either)
            ~(speed <= big),
            lambda s, i: f"velocity must be finite, speed within {big:g} m/s, got {tuple(vel[s, i].tolist())}",
        )
        fail(
            ~(np.isfinite(m) & (m > 0) & np.isfinite(1.0 / m)),
            lambda s, i: f"mass must be positive and finite, with a finite inverse, got {m[s, i]}",
        )
        fail(
            ~np.isfinite(0.5 * m * speed * speed),
            lambda s, i: f"velocity {tuple(vel[s, i].tolist())} gives mass {m[s, i]} a kinetic energy beyond float64",
        )
    fail(~(np.isfinite(r) & (r > 0) & (r <= big)), lambda s, i: f"radius must be positive and finite, got {r[s, i]}")


def _wrapped_into_cell(fail: Callable, scene: Scene, pos: np.ndarray, keep: float) -> np.ndarray:
    """A periodic scene's positions wrapped into its cell (where the other checks look at them),
    each within 2**53 periods of it (image counts are exact there); the positions themselves in
    other scenes. ``keep``: positions up to this far outside the cell stay as they are (a step's
    round-off leaves balls there)."""
    if not (scene.periodic and scene.bounds is not None):
        return pos
    for axis, length in enumerate(periods(scene.bounds, scene.dimension)):
        if length > 0.0:
            fail(
                ~(np.abs(pos[..., axis] - scene.bounds[axis]) <= MAX_IMAGES * length),
                lambda s, i, axis=axis, length=length: (
                    f"position {'xy'[axis]} = {pos[s, i, axis]:g} lies more than 2**53 periods "
                    f"({MAX_IMAGES * length:.6g} m) from the periodic cell, where its image count is not exact"
                ),
            )
    return wrap_positions(pos, scene.bounds, scene.dimension, keep)[0]


def _resolvable(fail: Callable, scene: Scene, balls: Balls) -> None:
    """Radii that span :data:`MIN_RADIUS_ULPS` units in the last place of the scene's coordinates."""
    r, extent = balls.radius, balls.extent
    smallest = MIN_RADIUS_ULPS * EPS * extent
    fail(
        r < smallest[:, None],
        lambda s, i: (
            f"radius {r[s, i]:.6g} m is too small for float64 to resolve its "
            f"contacts at coordinates of {extent[s]:.6g} m "
            f"(at least {smallest[s]:.3g} m)"
        ),
    )


def _on_the_line(fail: Callable, scene: Scene, balls: Balls) -> None:
    """In 1D, balls on y = 0, moving along x."""
    if scene.dimension == 1:
        pos, vel = balls.pos, balls.vel
        fail(pos[..., 1] != 0.0, lambda s, i: f"position y must be 0 in a 1D scene, got {pos[s, i, 1]}")
        fail(vel[..., 1] != 0.0, lambda s, i: f"velocity y must be 0 in a 1D scene, got {vel[s, i, 1]}")


def _minimum_image(fail: Callable, scene: Scene, balls: Balls) -> None:
    """In a periodic cell, diameters below half the cell: a ball touches at most one image of
    another (the minimum-image convention, Allen & Tildesley 1.6.4)."""
    if not scene.periodic:
        return
    r = balls.radius
    for length, name in zip(scene.period, ("width", "height"), strict=True):
        if length > 0.0:
            fail(
                ~(4.0 * r < length),
                lambda s, i, length=length, name=name: (
                    f"radius {r[s, i]:.6g} m is too large for the periodic cell: its diameter must be "
                    f"less than half the cell {name} {length:.6g} m (minimum image)"
                ),
            )


def _inside_border(fail: Callable, scene: Scene, balls: Balls) -> None:
    """In a box, room for each ball to move across it (more than the walls' contact tolerance),
    and each ball inside the border (within the start-state contact tolerance)."""
    if scene.periodic or scene.bounds is None:
        return
    pos, r = balls.pos, balls.radius
    xmin, ymin, xmax, ymax = scene.bounds
    for lo, hi, name in ((xmin, xmax, "width"), (ymin, ymax, "height"))[: scene.dimension]:
        room = (hi - lo) - 2.0 * r
        fail(
            room <= CONTACT_RTOL * 2.0 * r + roundoff(balls.extent[:, None]),
            lambda s, i, size=hi - lo, name=name: (
                f"radius {r[s, i]:.6g} m leaves no room to move: its diameter is the box {name} {size:.6g} m or more"
            ),
        )
    tol = START_CONTACT_RTOL * r + roundoff(balls.coordinate)
    out = (pos[..., 0] - r < xmin - tol) | (pos[..., 0] + r > xmax + tol)
    if scene.dimension == 2:
        out |= (pos[..., 1] - r < ymin - tol) | (pos[..., 1] + r > ymax + tol)
    fail(
        out,
        lambda s, i: (
            f"position must keep the ball inside the reflecting border {scene.bounds}, "
            f"got {tuple(pos[s, i].tolist())} with radius {r[s, i]:.6g}"
        ),
    )


def _apart(scene: Scene, balls: Balls, label: Labels, scenes: np.ndarray) -> None:
    """No two balls overlap (beyond the start-state contact tolerance), through the nearest images
    in a periodic cell."""
    if not scene.ball_collisions or balls.pos.shape[1] < 2:
        return
    pos, r = balls.pos, balls.radius
    bounds = scene.bounds if scene.periodic else None
    for s in range(len(pos)):
        if bounds is not None:
            lx, ly = periods(bounds, scene.dimension)
            x0, y0 = bounds[:2]
            i, j = first_overlap_periodic(pos[s], r[s], START_CONTACT_RTOL, x0, y0, lx, ly)
        else:
            i, j = first_overlap(pos[s], r[s], START_CONTACT_RTOL)
        if i < 0:
            continue
        d = pos[s, i] - pos[s, j]
        across = ""
        if bounds is not None:
            near = d.copy()
            for axis, length in enumerate((lx, ly)):
                if length > 0.0:
                    near[axis] -= length * np.floor(d[axis] / length + 0.5)
            across = " across the periodic boundary" if not np.array_equal(near, d) else ""
            d = near
        raise ValueError(
            f"{label(scenes[s], i)}position overlaps ball {j}{across} "
            f"(centres {float(np.hypot(*d)):.6g} m apart, radii sum to {r[s, i] + r[s, j]:.6g} m)"
        )


def _not_jammed(scene: Scene, balls: Balls, label: Labels, scenes: np.ndarray) -> None:
    """In a box, no network of touching balls reaches from wall to wall (it could not move)."""
    if scene.bounds is None or scene.periodic:
        return
    pos, r = balls.pos, balls.radius
    bounds = np.array(scene.bounds)
    # only a scene with balls at two opposite walls can have a network between them
    for s in np.flatnonzero(spans_walls(pos, r, balls.extent, bounds, scene.dimension)):
        i, axis, size = wall_to_wall(pos[s], r[s], bounds, scene.dimension, scene.ball_collisions)
        if i >= 0:
            walls = ("left and right walls", "bottom and top walls")[axis]
            raise ValueError(
                f"{label(scenes[s], i)}position leaves no room to move along {'xy'[axis]}: the ball is one "
                f"of {size} touching balls that reach from wall to wall ({walls}), jammed between them"
            )


def checked_balls(
    scene: Scene,
    label: Labels,
    scenes: np.ndarray,
    n: int,
    positions: Any,
    velocities: Any,
    masses: Any,
    radii: Any,
    overlaps: bool = False,
    keep: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Validate and return float64 copies ``(pos, vel, mass, radius)`` of the balls of ``scenes``
    (indices into the batch), ``n`` balls each (raises ValueError). ``overlaps``: accept balls that
    overlap, or touch from wall to wall (a state of a mode whose steps may leave them so). ``keep``:
    how far outside a periodic cell a position may lie and be checked where it is rather than
    wrapped (the positions returned are those given, either way).

    The checks, in order: types and shapes; representable values (:func:`_representable`);
    positions near a periodic cell; radii float64 resolves there; 1D balls on their line; the
    minimum-image rule; room to move and inside the border; apart; no jammed network."""
    k = len(scenes)

    def where(index):
        return label(scenes[index[0]], index[1]) if len(index) > 1 else label(scenes[0], index[0])

    pos = real_array(positions, [(k, n, 2)], "positions", where, label)
    vel = real_array(velocities, [(k, n, 2)], "velocities", where, label)
    if masses is None:
        raise ValueError(f"masses: expected shape ({n},) or ({k}, {n}), got None")
    m = _per_scene(real_array(masses, [(n,), (k, n)], "masses", where, label), k)
    r = _radii(radii, m, k, n, where, label)

    def fail(mask, message):
        refuse_first(mask, label, message, scenes)

    _representable(fail, pos, vel, m, r)
    inside = _wrapped_into_cell(fail, scene, pos, keep)
    coordinate = np.abs(inside).max(-1)
    extent = (coordinate + r).max(-1)
    if scene.bounds is not None:
        extent = np.maximum(extent, max(abs(v) for v in scene.bounds))
    balls = Balls(inside, vel, m, r, coordinate, extent)
    for check in (_resolvable, _on_the_line, _minimum_image, _inside_border):
        check(fail, scene, balls)
    if not overlaps:
        _apart(scene, balls, label, scenes)
        _not_jammed(scene, balls, label, scenes)
    return pos, vel, m, r


def check_reach(pos: np.ndarray, vel: np.ndarray, dt: float, label: Labels) -> None:
    """Without a border, a step of ``dt`` must keep every ball within the representable range."""
    reach = np.abs(pos).max(-1) + np.hypot(vel[..., 0], vel[..., 1]) * abs(dt)
    if not (reach <= MAX_MAGNITUDE).all():
        s, i = np.argwhere(~(reach <= MAX_MAGNITUDE))[0]
        raise ValueError(
            f"dt: a step of {dt:g} s would take {label(s, i).rstrip(': ')} beyond "
            f"{MAX_MAGNITUDE:g} m (no border), where positions are no longer representable"
        )


#: Most times a step of the cheap modes may take a ball round a periodic cell (their sub-steps wrap
#: positions by floor division, which loses a ball's place beyond that; exact mode counts each
#: crossing toward the event cap instead).
MAX_LAPS = 2.0**20


def check_laps(scene: Scene, mass: np.ndarray, vel: np.ndarray, dt: float, label: Labels) -> float:
    """In a periodic cell of the cheap modes, a step of ``dt`` must not take any ball round the cell more than
    :data:`MAX_LAPS` times, at the fastest speed the energy of its scene allows any of its balls
    (collisions never add energy). Returns the longest step that would pass (s; inf if no ball moves)."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        energy = (mass * (vel**2).sum(-1)).sum(-1)
        fastest = np.sqrt(energy / mass.min(-1))
        length = min(length for length in scene.period if length > 0.0)
        laps = fastest * abs(dt) / length
        longest = float(MAX_LAPS * length / fastest.max())
    if not (laps <= MAX_LAPS).all():
        s = int(np.flatnonzero(~(laps <= MAX_LAPS))[0])
        where = label(s).rstrip(": ")
        raise ValueError(
            f"dt: a step of {dt:g} s could take a ball{' of ' + where if where else ''} round the periodic "
            f"cell {laps[s]:.3g} times (at most {MAX_LAPS:g} in this mode; exact mode takes it); take shorter steps"
        )
    return longest


#: A stick cluster's members move as one rigid body: a member's velocity may differ from the rigid
#: motion ``v_cm + omega x (p - p_cm)`` by this much of the cluster's fastest speed (the engine's
#: rigid-body updates leave ~1e-10 of round-off; a state put together by hand is off by far more).
RIGID_RTOL = 1e-6


def check_stick_clusters(
    pos: np.ndarray,
    vel: np.ndarray,
    mass: np.ndarray,
    radius: np.ndarray,
    clusters: np.ndarray,
    omega: np.ndarray,
    label: Labels,
    gap_rtol: float = CONTACT_RTOL,
) -> None:
    """Each cluster of ``(K, N)`` ``clusters`` (indices of their root balls, checked) of more than
    one ball is one body: its balls move rigidly, with the angular velocity ``omega`` of the root,
    and touch one another in a network (they were stuck on contact): gaps within ``gap_rtol`` of
    the radii sum, or the coordinates' round-off (exact mode's contact tolerance by default; the
    cheap modes stick balls up to a sub-step's reconstruction error apart). Raises a ValueError
    naming the first ball that does not. Every cluster of every scene at once: ``key`` numbers
    them ``scene * N + root``."""
    k, n = clusters.shape
    if (clusters == np.arange(n)).all():  # (no cluster of more than one ball)
        return
    key = (clusters + n * np.arange(k)[:, None]).ravel()
    m = mass.ravel()
    total = np.bincount(key, weights=m, minlength=k * n)[key]

    def centre(values):  # each ball's cluster's mass-weighted mean of (K, N, 2) values
        x, y = (np.bincount(key, weights=m * values[..., axis].ravel(), minlength=k * n)[key] for axis in (0, 1))
        return np.stack([x, y], axis=-1) / total[:, None]

    p, v = pos.reshape(-1, 2), vel.reshape(-1, 2)
    offset = p - centre(pos)
    w = omega.ravel()[key]
    rigid = centre(vel) + w[:, None] * np.stack([-offset[:, 1], offset[:, 0]], axis=-1)
    scale = np.zeros(k * n)  # each cluster's fastest speed, of a ball or of a point spun by omega
    np.maximum.at(scale, key, np.abs(v).max(-1) + np.abs(w) * np.abs(offset).max(-1))
    error = np.abs(v - rigid).max(-1)
    off = (error > RIGID_RTOL * scale[key]).reshape(k, n)
    refuse_first(
        off,
        label,
        lambda s, i: (
            f"moves apart from its stick cluster (root ball {clusters[s, i]}): a cluster moves as one rigid "
            f"body, v = v_cm + omega x (p - p_cm), and this ball's velocity {tuple(vel[s, i].tolist())} is "
            f"{error[s * n + i]:.3g} m/s off"
        ),
        field="state velocities",
    )
    # a network of touching balls: each ball takes the lowest index it reaches through touching
    # balls of its cluster, until nothing changes; every ball of a cluster then has its root's
    sigma = radius[:, :, None] + radius[:, None, :]
    gap = np.hypot(*np.moveaxis(pos[:, :, None, :] - pos[:, None, :, :], -1, 0)) - sigma
    coordinate = np.abs(pos).max(-1)
    tolerance = np.maximum(gap_rtol * sigma, roundoff(np.maximum(coordinate[:, :, None], coordinate[:, None, :])))
    linked = (gap <= tolerance) & (clusters[:, :, None] == clusters[:, None, :])
    reached = np.broadcast_to(np.arange(n), (k, n))
    while True:
        lowest = np.where(linked, reached[:, None, :], n).min(-1)
        if (lowest == reached).all():
            break
        reached = lowest
    refuse_first(
        reached != np.take_along_axis(reached, clusters, axis=1),
        label,
        lambda s, i: (
            f"does not touch the rest of its stick cluster (root ball {clusters[s, i]}) through a network of "
            f"touching balls (gaps up to {gap_rtol:g} of their radii sums): clusters form on contact"
        ),
        field="state clusters",
    )


def checked_nudge(dv: Any, scene: Scene, vel: np.ndarray, mass: np.ndarray, label: Labels) -> np.ndarray:
    """``dv`` as a float64 ``(B, N, 2)`` velocity change: finite, 0 along y in 1D, and giving speeds
    that stay representable (bounded through the clusters' spin by the largest change of any of
    their members: a rigid impulse moves no point faster than that)."""
    n_scenes, n = mass.shape
    dv = real_array(dv, [(n_scenes, n, 2)], "nudge", lambda index: label(*index[:2]), label)
    refuse_first(
        ~(np.abs(dv) <= MAX_MAGNITUDE).all(-1),
        label,
        lambda s, i: f"nudge must be finite, within {MAX_MAGNITUDE:g} m/s, got {tuple(dv[s, i].tolist())}",
    )
    if scene.dimension == 1:
        refuse_first(dv[..., 1] != 0.0, label, lambda s, i: f"nudge y must be 0 in a 1D scene, got {dv[s, i, 1]}")
    if scene.sticky:
        most = np.abs(dv).max(axis=(1, 2), keepdims=True)[..., 0]
        limit = np.abs(vel).max(-1) + np.broadcast_to(most, mass.shape) * n
    else:
        limit = np.abs(vel + dv).max(-1)
    with np.errstate(over="ignore"):
        bad = ~(limit <= MAX_MAGNITUDE / 2) | ~np.isfinite(mass * limit * limit)
    refuse_first(
        bad,
        label,
        lambda s, i: (
            f"nudge {tuple(dv[s, i].tolist())} would give a speed beyond the representable "
            f"range (speeds up to {MAX_MAGNITUDE:g} m/s, finite kinetic energy)"
        ),
    )
    return dv


class Settings(NamedTuple):
    """A simulator's settings, fixed at construction (its kernels are bound to them)."""

    mode: str  #: ``"naive"``, ``"posteriori"`` or ``"exact"``
    substeps: int  #: sub-steps per step (naive and posteriori)
    max_events: int | None  #: cap on events per scene and step (exact); None: the default for N balls
    collapse_ratio: float  #: collapse regulariser: u_min / fastest speed
    collapse_floor: float  #: collapse regulariser: smallest u_min, m/s
    contact_duration: float = 0.0  #: the TC model's t_c, s (0: off)


def checked_settings(
    mode: Any,
    substeps: Any,
    max_events: Any,
    collapse_ratio: Any,
    collapse_floor: Any,
    modes: Mapping[str, Any],
    contact_duration: Any = 0.0,
    sticky: bool = False,
) -> Settings:
    """A simulator's settings, each checked (raises ValueError naming it); ``modes``: the mode
    registry (``modes.MODES``), whose entry says whether the mode takes sub-steps; ``sticky``: the
    scene forms stick clusters (which the TC model does not apply to)."""
    if not (isinstance(mode, str) and mode in modes):
        raise ValueError(f"mode: must be one of {tuple(modes)}, got {mode!r}")
    substeps = positive_integer(substeps, "substeps", MAX_SUBSTEPS)
    if not modes[mode].substeps and substeps != 1:
        raise ValueError(f"substeps: {mode} mode resolves every event at its exact time; substeps must be 1")
    if max_events is not None:
        max_events = positive_integer(max_events, "max_events", MAX_EVENT_CAP)
    # (compared as given: a huge int has no float, and float() of it would raise OverflowError)
    if not (is_real(collapse_ratio) and 0.0 <= collapse_ratio < 1.0):
        raise ValueError(f"collapse_ratio: must be a number in [0, 1), got {collapse_ratio!r}")
    if not (is_real(collapse_floor) and 0.0 <= collapse_floor < MAX_MAGNITUDE):
        raise ValueError(f"collapse_floor: must be a finite speed >= 0 (m/s), got {collapse_floor!r}")
    if not (is_real(contact_duration) and 0.0 <= contact_duration < MAX_MAGNITUDE):
        raise ValueError(f"contact_duration: must be a finite time >= 0 (s), got {contact_duration!r}")
    if float(contact_duration) > 0.0 and mode != "exact":
        raise ValueError(
            f"contact_duration: the TC model is exact mode's (a {mode} step resolves each pair once per "
            "sub-step, with no collision instants to compare); it must be 0 here"
        )
    if float(contact_duration) > 0.0 and sticky:
        raise ValueError(
            "contact_duration: a stick scene merges colliding balls (no restitution for the TC model to "
            "set); it must be 0 here"
        )
    return Settings(mode, substeps, max_events, float(collapse_ratio), float(collapse_floor), float(contact_duration))


#: The state fields a dict given to ``set_state`` may go without (a :class:`SimulatorState` has all).
OPTIONAL_STATE_KEYS = ("images", "last_impact")


def state_record(state: Any, stacklevel: int) -> SimulatorState | dict:
    """``set_state``'s argument: a :class:`SimulatorState` as it is; a mapping (the dict earlier
    versions gave) with a ``DeprecationWarning`` (``stacklevel`` names the caller), as a dict of its
    keys, checked by :func:`checked_state`."""
    if isinstance(state, SimulatorState):
        return state
    if not isinstance(state, Mapping):
        raise TypeError(f"state: expected a SimulatorState, as get_state gives, got {type(state).__name__}")
    warnings.warn(
        "set_state: a dict of the state's arrays is deprecated; pass the SimulatorState that get_state "
        "gives (its replace() changes fields)",
        DeprecationWarning,
        stacklevel=stacklevel + 1,
    )
    return dict(state)


def left_out(value: Any) -> bool:
    """An optional state field given as None (or a copy of it, ``np.array(None)``): left out."""
    if value is None:
        return True
    a = np.asarray(value)
    return a.shape == () and a.dtype == object and a.item() is None


class CheckedState(NamedTuple):
    """A state as :func:`checked_state` returns it, ready for the stepper's ``put``."""

    pos: np.ndarray
    vel: np.ndarray
    mass: np.ndarray
    radius: np.ndarray
    clusters: np.ndarray
    omega: np.ndarray
    time: np.ndarray
    compensation: np.ndarray
    images: np.ndarray | None
    last_impact: np.ndarray | None


def checked_state(
    state: Any, scene: Scene, label: Labels, shape: tuple[int, int], leaves_overlaps: bool
) -> CheckedState:
    """A ``set_state`` state of ``shape = (B, N)`` balls, checked: its keys (:data:`STATE_FIELDS`,
    ``images`` optional, nothing else), shapes and number types, the balls as the constructor
    checks them (with ``leaves_overlaps``, a state of a cheap mode: overlaps and jammed networks
    accepted, stick clusters with gaps of a sub-step's error), clusters and spins
    (:func:`check_clusters`), stick clusters (:func:`check_stick_clusters`), clocks and images."""
    n_scenes, n = shape
    shapes = {
        "positions": (n_scenes, n, 2),
        "velocities": (n_scenes, n, 2),
        "masses": (n_scenes, n),
        "radii": (n_scenes, n),
        "clusters": (n_scenes, n),
        "omega": (n_scenes, n),
        "time": (n_scenes,),
        "time_compensation": (n_scenes,),
        "images": (n_scenes, n, 2),
        "last_impact": (n_scenes, n),
    }
    required = [key for key in STATE_FIELDS if key not in OPTIONAL_STATE_KEYS]
    if not isinstance(state, Mapping):
        raise TypeError(f"state: expected a SimulatorState, as get_state gives, got {type(state).__name__}")
    unknown = [key for key in state if key not in shapes]
    if unknown:
        raise ValueError(
            f"state: unknown key(s) {close_matches(unknown, STATE_FIELDS)} (a state has the keys {list(STATE_FIELDS)})"
        )
    missing = [key for key in required if key not in state]
    if missing:
        raise ValueError(f"state: missing {missing} (a state has the keys {required}, as get_state gives)")
    arrays = {}
    for key in state:
        if key in OPTIONAL_STATE_KEYS and left_out(state[key]):
            continue
        a = np.asarray(state[key])
        if a.shape != shapes[key]:
            raise ValueError(f"state {key}: expected shape {label.shape(shapes[key])}, got {label.shape(a.shape)}")
        whole = key in ("clusters", "images")
        if a.dtype.kind not in ("iu" if whole else "iuf"):
            raise ValueError(f"state {key}: expected {'integers' if whole else 'real numbers'}, got dtype {a.dtype}")
        # (integers always are finite; a ball with no collision yet has its last one at -inf)
        if a.dtype.kind == "f" and not (np.isfinite(a) | (a == -np.inf if key == "last_impact" else False)).all():
            raise ValueError(f"state {key}: values must be finite{' or -inf' if key == 'last_impact' else ''}")
        arrays[key] = a
    scenes = np.arange(n_scenes)
    # (positions a step left a round-off outside a periodic cell are taken as they are)
    pos, vel, mass, radius = checked_balls(
        scene,
        label,
        scenes,
        n,
        arrays["positions"],
        arrays["velocities"],
        arrays["masses"],
        arrays["radii"],
        overlaps=leaves_overlaps,
        keep=periodic_slack(scene),
    )
    check_clusters(arrays["clusters"], arrays["omega"], scene.sticky, label)
    if scene.sticky:
        gap_rtol = CHEAP_STICK_GAP_RTOL if leaves_overlaps else CONTACT_RTOL
        check_stick_clusters(pos, vel, mass, radius, arrays["clusters"], arrays["omega"], label, gap_rtol)
    for sc in scenes:
        time, compensation = float(arrays["time"][sc]), float(arrays["time_compensation"][sc])
        check_seconds(time, f"state time: {label(sc)}".rstrip(": "))
        if not abs(compensation) <= np.spacing(abs(time)):
            raise ValueError(
                f"state time_compensation: {label(sc)}must be within an ulp of the time "
                f"({np.spacing(abs(time)):.3g} s at {time:g} s), got {compensation:g}"
            )
    last_impact = arrays.get("last_impact")
    if last_impact is not None:
        clocks = arrays["time"]
        refuse_first(
            # (an instant at a step's very end may round an ulp above the compensated clock)
            last_impact > np.nextafter(clocks, np.inf)[:, None],
            label,
            lambda s, i: f"a last collision instant after the clock ({clocks[s]:g} s), got {last_impact[s, i]:g}",
            field="state last_impact",
        )
    images = None
    if "images" in arrays:
        wrapped: np.ndarray | int = 0
        if scene.periodic and scene.bounds is not None:  # (the periods wrapping the positions adds)
            wrapped = wrap_positions(pos, scene.bounds, scene.dimension, periodic_slack(scene))[1]
        images = checked_images(arrays["images"], wrapped, label)
    return CheckedState(
        pos,
        vel,
        mass,
        radius,
        arrays["clusters"],
        arrays["omega"],
        arrays["time"],
        arrays["time_compensation"],
        images,
        None if last_impact is None else last_impact.astype(np.float64),
    )


def periodic_slack(scene: Scene) -> float:
    """How far outside a periodic scene's cell a step may leave a ball (m): the round-off of its
    coordinates, which are at most the cell's bounds (0 outside periodic scenes)."""
    if not scene.periodic or scene.bounds is None:
        return 0.0
    return roundoff(max(abs(v) for v in scene.bounds))


def checked_images(given: np.ndarray, wrapped: np.ndarray | int, label: Labels) -> np.ndarray:
    """``set_state``'s images (integers), as int64: each, and its sum with the periods
    ``wrapped`` that wrapping the positions added, within ``MAX_IMAGES`` (raises ValueError)."""
    if -MAX_IMAGES <= given.min() and given.max() <= MAX_IMAGES:  # (then their sum cannot overflow)
        images = given.astype(np.int64)
        far = np.abs(images + wrapped) > MAX_IMAGES
    else:  # (compared as integers: beyond 2**53, a float64 could round a count into range)
        images = given
        far = (given < -MAX_IMAGES) | (given > MAX_IMAGES)
    axis_of = far.argmax(-1)
    refuse_first(
        np.asarray(far.any(-1)),
        label,
        lambda s, i: (
            f"expected at most 2**53 periods from the cell, got {given[s, i, axis_of[s, i]]} "
            f"along {'xy'[axis_of[s, i]]}"
        ),
        field="state images",
    )
    return images


def check_clusters(clusters: np.ndarray, omega: np.ndarray, sticky: bool, label: Labels) -> None:
    """``set_state``'s clusters and spins: each ball's root is a ball index and its own root (every
    ball its own without stick clusters), and spins are representable (raises ValueError)."""
    n = clusters.shape[1]
    if not sticky:  # (every ball its own cluster: its own root too)
        bad = clusters != np.arange(n)
    else:
        bad = (clusters < 0) | (clusters >= n)
        if not bad.any():
            bad = np.take_along_axis(clusters, clusters, axis=1) != clusters
    refuse_first(
        bad,
        label,
        lambda s, i: (
            f"expected {'a ball index whose cluster is its own' if sticky else f'{i} (no stick clusters)'}, "
            f"got {clusters[s, i]}"
        ),
        field="state clusters",
    )
    refuse_first(
        ~(np.abs(omega) <= MAX_MAGNITUDE),
        label,
        lambda s, i: f"expected within {MAX_MAGNITUDE:g} rad/s, got {omega[s, i]}",
        field="state omega",
    )
