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
from collections.abc import Callable
from typing import Any

import numpy as np

from .broadphase import first_overlap, first_overlap_periodic, spans_walls, wall_to_wall
from .physics.periodic import MAX_IMAGES, periods, wrap_positions
from .physics.tolerance import CONTACT_RTOL, EPS, roundoff
from .scene import CONSTANT_RADIUS, MAX_MAGNITUDE, Scene, radius_from_mass

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
#: The largest finite float64: a Python int beyond it has no float64 value (``float`` raises).
_LARGEST_FLOAT = int(np.finfo(np.float64).max)


def is_real(x: object) -> bool:
    """A real number that is not a boolean (Python or numpy scalar types alike)."""
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


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


def _per_scene(values: np.ndarray, k: int) -> np.ndarray:
    """``(N,)`` or ``(K, N)`` values, a fresh copy from ``real_array``, as ``(K, N)``."""
    return values if values.ndim == 2 else np.tile(values, (k, 1))


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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Validate and return float64 copies ``(pos, vel, mass, radius)`` of the balls of ``scenes``
    (indices into the batch), ``n`` balls each (raises ValueError). ``overlaps``: accept balls that
    overlap, or touch from wall to wall (a state of a mode whose steps may leave them so)."""
    k = len(scenes)

    def where(index):
        return label(scenes[index[0]], index[1]) if len(index) > 1 else label(scenes[0], index[0])

    pos = real_array(positions, [(k, n, 2)], "positions", where, label)
    vel = real_array(velocities, [(k, n, 2)], "velocities", where, label)
    if masses is None:
        raise ValueError(f"masses: expected shape ({n},) or ({k}, {n}), got None")
    m = _per_scene(real_array(masses, [(n,), (k, n)], "masses", where, label), k)
    if radii is None:
        r = radius_from_mass(m)
    elif isinstance(radii, str):
        if radii != "constant":
            raise ValueError(f"radii: expected None, 'constant' or an array, got {radii!r}")
        r = np.full((k, n), CONSTANT_RADIUS)
    else:
        r = _per_scene(real_array(radii, [(n,), (k, n)], "radii", where, label), k)

    def fail(mask, message):
        if not mask.any():  # (the common case: several times cheaper than argwhere)
            return
        s, i = np.argwhere(mask)[0]
        raise ValueError(label(scenes[s], i) + message(s, i))

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
    given = pos
    if scene.periodic and scene.bounds is not None:  # (checked where they will be: wrapped into the cell)
        for axis, length in enumerate(periods(scene.bounds, scene.dimension)):
            if length > 0.0:
                fail(
                    ~(np.abs(pos[..., axis] - scene.bounds[axis]) <= MAX_IMAGES * length),
                    lambda s, i, axis=axis, length=length: (
                        f"position {'xy'[axis]} = {pos[s, i, axis]:g} lies more than 2**53 periods "
                        f"({MAX_IMAGES * length:.6g} m) from the periodic cell, where its image count is not exact"
                    ),
                )
        pos, _ = wrap_positions(pos, scene.bounds, scene.dimension)
    # the coordinates' magnitude in each scene: the border, or the balls' own extent
    coordinate = np.abs(pos).max(-1)
    extent = (coordinate + r).max(-1)
    if scene.bounds is not None:
        extent = np.maximum(extent, max(abs(v) for v in scene.bounds))
    smallest = MIN_RADIUS_ULPS * EPS * extent
    fail(
        r < smallest[:, None],
        lambda s, i: (
            f"radius {r[s, i]:.6g} m is too small for float64 to resolve its "
            f"contacts at coordinates of {extent[s]:.6g} m "
            f"(at least {smallest[s]:.3g} m)"
        ),
    )
    if scene.dimension == 1:
        fail(pos[..., 1] != 0.0, lambda s, i: f"position y must be 0 in a 1D scene, got {pos[s, i, 1]}")
        fail(vel[..., 1] != 0.0, lambda s, i: f"velocity y must be 0 in a 1D scene, got {vel[s, i, 1]}")
    if scene.periodic:
        # minimum image: a ball touches at most one image of another (Allen & Tildesley 1.6.4)
        for length, name in zip(scene.period, ("width", "height"), strict=True):
            if length > 0.0:
                fail(
                    ~(4.0 * r < length),
                    lambda s, i, length=length, name=name: (
                        f"radius {r[s, i]:.6g} m is too large for the periodic cell: its diameter must be "
                        f"less than half the cell {name} {length:.6g} m (minimum image)"
                    ),
                )
    elif scene.bounds is not None:
        xmin, ymin, xmax, ymax = scene.bounds
        # a ball needs room to move across the box: more than the contact tolerance of the walls
        for lo, hi, name in ((xmin, xmax, "width"), (ymin, ymax, "height"))[: scene.dimension]:
            room = (hi - lo) - 2.0 * r
            fail(
                room <= CONTACT_RTOL * 2.0 * r + roundoff(extent[:, None]),
                lambda s, i, size=hi - lo, name=name: (
                    f"radius {r[s, i]:.6g} m leaves no room to move: its "
                    f"diameter is the box {name} {size:.6g} m or more"
                ),
            )
        tol = START_CONTACT_RTOL * r + roundoff(coordinate)
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
    if scene.ball_collisions and n > 1 and not overlaps:
        for s_ in range(k):
            if scene.periodic and scene.bounds is not None:
                lx, ly = periods(scene.bounds, scene.dimension)
                x0, y0 = scene.bounds[:2]
                i, j = first_overlap_periodic(pos[s_], r[s_], START_CONTACT_RTOL, x0, y0, lx, ly)
            else:
                i, j = first_overlap(pos[s_], r[s_], START_CONTACT_RTOL)
            if i >= 0:
                d = pos[s_, i] - pos[s_, j]
                across = ""
                if scene.periodic:
                    near = d.copy()
                    for axis, length in enumerate((lx, ly)):
                        if length > 0.0:
                            near[axis] -= length * np.floor(d[axis] / length + 0.5)
                    across = " across the periodic boundary" if not np.array_equal(near, d) else ""
                    d = near
                dist = float(np.hypot(*d))
                raise ValueError(
                    f"{label(scenes[s_], i)}position overlaps ball {j}{across} "
                    f"(centres {dist:.6g} m apart, radii sum to {r[s_, i] + r[s_, j]:.6g} m)"
                )
    if scene.bounds is not None and not scene.periodic and not overlaps:
        bounds = np.array(scene.bounds)
        # only a scene with balls at two opposite walls can have a network between them
        for sc in np.flatnonzero(spans_walls(pos, r, extent, bounds, scene.dimension)):
            i, axis, size = wall_to_wall(pos[sc], r[sc], bounds, scene.dimension, scene.ball_collisions)
            if i >= 0:
                walls = ("left and right walls", "bottom and top walls")[axis]
                raise ValueError(
                    f"{label(scenes[sc], i)}position leaves no room to move along {'xy'[axis]}: the ball is one "
                    f"of {size} touching balls that reach from wall to wall ({walls}), jammed between them"
                )
    return given, vel, m, r


def check_reach(pos: np.ndarray, vel: np.ndarray, dt: float, label: Labels) -> None:
    """Without a border, a step of ``dt`` must keep every ball within the representable range."""
    reach = np.abs(pos).max(-1) + np.hypot(vel[..., 0], vel[..., 1]) * abs(dt)
    if not (reach <= MAX_MAGNITUDE).all():
        s, i = np.argwhere(~(reach <= MAX_MAGNITUDE))[0]
        raise ValueError(
            f"dt: a step of {dt:g} s would take {label(s, i).rstrip(': ')} beyond "
            f"{MAX_MAGNITUDE:g} m (no border), where positions are no longer representable"
        )


#: Most times a step may take a ball round a periodic cell: exact mode wraps a ball at each crossing
#: of the cell (an event), so a step that laps the cell without bound would never end.
MAX_LAPS = 2.0**20


def check_laps(scene: Scene, mass: np.ndarray, vel: np.ndarray, dt: float, label: Labels) -> None:
    """In a periodic cell, a step of ``dt`` must not take any ball round the cell more than
    :data:`MAX_LAPS` times, at the fastest speed the energy of its scene allows any of its balls
    (collisions never add energy)."""
    with np.errstate(over="ignore", invalid="ignore"):
        energy = (mass * (vel**2).sum(-1)).sum(-1)
        fastest = np.sqrt(energy / mass.min(-1))
        laps = fastest * abs(dt) / min(length for length in scene.period if length > 0.0)
    if not (laps <= MAX_LAPS).all():
        s = int(np.flatnonzero(~(laps <= MAX_LAPS))[0])
        where = label(s).rstrip(": ")
        raise ValueError(
            f"dt: a step of {dt:g} s could take a ball{' of ' + where if where else ''} round the periodic "
            f"cell {laps[s]:.3g} times (at most {MAX_LAPS:g}: each crossing is an event); take shorter steps"
        )


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
    touching: bool = True,
) -> None:
    """Each cluster of ``(K, N)`` ``clusters`` (indices of their root balls, checked) of more than
    one ball is one body: its balls move rigidly, with the angular velocity ``omega`` of the root,
    and (if ``touching``) touch one another in a network, within the engine's contact tolerance
    (they were stuck on contact). Raises a ValueError naming the first ball that does not. Every
    cluster of every scene at once: ``key`` numbers them ``scene * N + root``."""
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
    off = error > RIGID_RTOL * scale[key]
    if off.any():
        b = int(np.flatnonzero(off)[0])
        raise ValueError(
            f"state velocities: {label(b // n, b % n)}moves apart from its stick cluster (root ball "
            f"{clusters.flat[b]}): a cluster moves as one rigid body, v = v_cm + omega x (p - p_cm), and this "
            f"ball's velocity {tuple(v[b].tolist())} is {error[b]:.3g} m/s off"
        )
    if not touching:
        return
    # a network of touching balls: each ball takes the lowest index it reaches through touching
    # balls of its cluster, until nothing changes; every ball of a cluster then has its root's
    sigma = radius[:, :, None] + radius[:, None, :]
    gap = np.hypot(*np.moveaxis(pos[:, :, None, :] - pos[:, None, :, :], -1, 0)) - sigma
    coordinate = np.abs(pos).max(-1)
    tolerance = np.maximum(CONTACT_RTOL * sigma, roundoff(np.maximum(coordinate[:, :, None], coordinate[:, None, :])))
    linked = (gap <= tolerance) & (clusters[:, :, None] == clusters[:, None, :])
    reached = np.broadcast_to(np.arange(n), (k, n))
    while True:
        lowest = np.where(linked, reached[:, None, :], n).min(-1)
        if (lowest == reached).all():
            break
        reached = lowest
    apart = reached != np.take_along_axis(reached, clusters, axis=1)
    if apart.any():
        sc, i = np.argwhere(apart)[0]
        raise ValueError(
            f"state clusters: {label(sc, i)}does not touch the rest of its stick cluster (root ball "
            f"{clusters[sc, i]}) through a network of touching balls: clusters form on contact"
        )


def checked_nudge(dv: Any, scene: Scene, vel: np.ndarray, mass: np.ndarray, label: Labels) -> np.ndarray:
    """``dv`` as a float64 ``(B, N, 2)`` velocity change: finite, 0 along y in 1D, and giving speeds
    that stay representable (bounded through the clusters' spin by the largest change of any of
    their members: a rigid impulse moves no point faster than that)."""
    n_scenes, n = mass.shape
    dv = real_array(dv, [(n_scenes, n, 2)], "nudge", lambda index: label(*index[:2]), label)
    # one cheap test on the common path; find the culprit only when there is one
    if not (np.abs(dv) <= MAX_MAGNITUDE).all():
        s, i = np.argwhere(~(np.abs(dv) <= MAX_MAGNITUDE).all(-1))[0]
        raise ValueError(
            f"{label(s, i)}nudge must be finite, within {MAX_MAGNITUDE:g} m/s, got {tuple(dv[s, i].tolist())}"
        )
    if scene.dimension == 1 and dv[..., 1].any():
        s, i = np.argwhere(dv[..., 1] != 0.0)[0]
        raise ValueError(f"{label(s, i)}nudge y must be 0 in a 1D scene, got {dv[s, i, 1]}")
    if scene.sticky:
        most = np.abs(dv).max(axis=(1, 2), keepdims=True)[..., 0]
        limit = np.abs(vel).max(-1) + np.broadcast_to(most, mass.shape) * n
    else:
        limit = np.abs(vel + dv).max(-1)
    with np.errstate(over="ignore"):
        bad = ~(limit <= MAX_MAGNITUDE / 2) | ~np.isfinite(mass * limit * limit)
    if bad.any():
        s, i = np.argwhere(bad)[0]
        raise ValueError(
            f"{label(s, i)}nudge {tuple(dv[s, i].tolist())} would give a speed beyond the representable "
            f"range (speeds up to {MAX_MAGNITUDE:g} m/s, finite kinetic energy)"
        )
    return dv
