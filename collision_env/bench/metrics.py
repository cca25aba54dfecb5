"""Accuracy metrics: how far a run is from the exact reference, and whether a long run is physical.

Impacts are handled as :data:`IMPACTS` structured arrays (``time, ball, other, wall, x, y``;
``other = -1`` for a wall, ``wall = -1`` for a ball, wall codes index ``WALL_NAMES``).
:func:`as_impacts` converts the engine's ``Impact`` lists and ``IMPACT_DTYPE`` arrays, and plain
tuples, into that form.

- :func:`match_impacts` pairs a run's impacts one to one with the reference's: same key (the
  unordered ball pair, or the ball and the wall), nearest time first, within a time window.
  Unmatched reference impacts are *missed*, unmatched run impacts are *spurious*; a ball pair
  the reference sees collide but the run never reports at all is *tunnelled*.
- :func:`drift`, :func:`final_state_error`, :func:`escapes`, :func:`wall_penetration`,
  :func:`max_overlap`: conservation and validity of states.
- :func:`ks_rayleigh`, and :func:`~collision_env.observables.henderson_g` and
  :func:`~collision_env.observables.enskog_rate` (from :mod:`collision_env.observables`):
  statistical checks for long runs of an elastic gas (2D Maxwell-Boltzmann speeds, collision
  frequency).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike

from collision_env.engine import WALL_NAMES
from collision_env.observables import enskog_rate, henderson_g  # noqa: F401  (the bench's statistical checks)

IMPACTS = np.dtype(
    [
        ("time", np.float64),
        ("ball", np.int64),
        ("other", np.int64),
        ("wall", np.int64),
        ("x", np.float64),
        ("y", np.float64),
    ]
)


def as_impacts(impacts: Any) -> np.ndarray:
    """Impacts as an :data:`IMPACTS` array.

    Accepts an :data:`IMPACTS` or engine ``IMPACT_DTYPE`` array, a list of engine ``Impact``
    objects, or a list of tuples ``(time, ball, other, wall[, x, y])`` where ``other`` is a ball
    index or None and ``wall`` a wall name, a wall index or None; missing points are NaN.
    """
    if isinstance(impacts, np.ndarray) and impacts.dtype.names is not None:
        out = np.empty(len(impacts), dtype=IMPACTS)
        for name in IMPACTS.names or ():
            out[name] = impacts[name]
        return out
    rows = []
    for item in impacts:
        if hasattr(item, "ball"):  # engine Impact
            t, b, o, w = item.time, item.ball, item.other, item.wall
            x, y = item.point
        else:
            t, b, o, w, *point = item
            x, y = point if point else (math.nan, math.nan)
        if isinstance(w, str):
            w = WALL_NAMES.index(w)
        rows.append((t, b, -1 if o is None else o, -1 if w is None else w, x, y))
    return np.array(rows, dtype=IMPACTS) if rows else np.zeros(0, dtype=IMPACTS)


def impact_keys(imp: np.ndarray) -> list[tuple[int, int, int]]:
    """One hashable key per impact: ``(lower ball, higher ball, -1)`` or ``(ball, -1, wall)``."""
    keys = []
    for b, o, w in zip(imp["ball"].tolist(), imp["other"].tolist(), imp["wall"].tolist(), strict=True):
        keys.append((min(b, o), max(b, o), -1) if o >= 0 else (b, -1, w))
    return keys


@dataclass
class Match:
    """The result of :func:`match_impacts` (indices into the run's and the reference's arrays)."""

    run_index: np.ndarray  # matched run impacts
    ref_index: np.ndarray  # their reference partners
    missed: np.ndarray  # reference impacts with no partner
    spurious: np.ndarray  # run impacts with no partner
    time_error: np.ndarray  # |t_run - t_ref| per matched pair (s)
    point_error: np.ndarray  # |p_run - p_ref| per matched pair (m; NaN where a point is unknown)
    tunnelled: list  # ball pairs the reference sees collide and the run never reports

    @property
    def matched(self) -> int:
        return len(self.run_index)

    def summary(self) -> dict:
        """Counts and error statistics as a flat dict (NaN where there is nothing to measure)."""

        def stat(a, f):
            a = a[np.isfinite(a)]
            return float(f(a)) if len(a) else math.nan

        return {
            "matched": self.matched,
            "missed": len(self.missed),
            "spurious": len(self.spurious),
            "tunnelled_pairs": len(self.tunnelled),
            "t_err_median": stat(self.time_error, np.median),
            "t_err_max": stat(self.time_error, np.max),
            "p_err_median": stat(self.point_error, np.median),
            "p_err_max": stat(self.point_error, np.max),
        }


def match_impacts(run: np.ndarray, ref: np.ndarray, window: float, neighbours: int = 4) -> Match:
    """Pair ``run`` impacts with ``ref`` impacts one to one.

    Two impacts can pair only if they have the same key (:func:`impact_keys`) and their times
    differ by at most ``window``. Among the allowed pairs, the closest in time is taken first
    (ties: lower reference index, then lower run index), then the next closest among the
    impacts still free, and so on (greedy nearest-time matching). For a key with very many
    impacts in both runs (more than 200 000 candidate pairs: the pi billiard), only the
    ``neighbours`` nearest reference impacts on each side of a run impact's time are considered
    (widened to all impacts as close as the farthest of them), which keeps the cost near linear.
    """
    run = as_impacts(run)
    ref = as_impacts(ref)
    if not window >= 0.0:
        raise ValueError(f"window: must be >= 0, got {window}")
    run_keys = impact_keys(run)
    ref_keys = impact_keys(ref)
    by_key_ref: dict = {}
    for k, key in enumerate(ref_keys):
        by_key_ref.setdefault(key, []).append(k)
    by_key_run: dict = {}
    for k, key in enumerate(run_keys):
        by_key_run.setdefault(key, []).append(k)

    d_all, j_all, i_all = [], [], []  # candidate pairs: |dt|, reference index, run index
    for key, run_idx in by_key_run.items():
        ref_idx = by_key_ref.get(key)
        if not ref_idx:
            continue
        ref_idx = np.array(ref_idx)
        ref_idx = ref_idx[np.argsort(ref["time"][ref_idx], kind="stable")]
        ref_t = ref["time"][ref_idx]
        run_idx = np.array(run_idx)
        t = run["time"][run_idx]
        if len(run_idx) * len(ref_idx) <= 200_000:  # every reference impact of the key within the window
            reach = np.full(len(t), window)
        else:  # the nearest few, widened to all as close as the farthest of them (ties at one instant)
            pos = np.searchsorted(ref_t, t)
            lo = np.maximum(pos - neighbours, 0)
            hi = np.minimum(pos + neighbours, len(ref_t)) - 1
            reach = np.minimum(window, np.maximum(np.abs(ref_t[lo] - t), np.abs(ref_t[hi] - t)))
        lo = np.searchsorted(ref_t, t - reach, side="left")
        hi = np.searchsorted(ref_t, t + reach, side="right")
        count = hi - lo
        if not count.sum():
            continue
        which = np.repeat(np.arange(len(t)), count)
        offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        q = lo[which] + offset
        d = np.abs(ref_t[q] - t[which])
        keep = d <= window
        d_all.append(d[keep])
        j_all.append(ref_idx[q[keep]])
        i_all.append(run_idx[which[keep]])
    matched_run: list[int] = []
    matched_ref: list[int] = []
    if d_all:
        d = np.concatenate(d_all)
        j = np.concatenate(j_all)
        i = np.concatenate(i_all)
        order = np.lexsort((i, j, d))
        run_used = np.zeros(len(run), dtype=bool)
        ref_used = np.zeros(len(ref), dtype=bool)
        most = min(len(run), len(ref))
        for jj, ii in zip(j[order].tolist(), i[order].tolist(), strict=True):
            if run_used[ii] or ref_used[jj]:
                continue
            run_used[ii] = ref_used[jj] = True
            matched_run.append(ii)
            matched_ref.append(jj)
            if len(matched_run) == most:
                break
    else:
        run_used = np.zeros(len(run), dtype=bool)
        ref_used = np.zeros(len(ref), dtype=bool)
    pr = np.array(matched_run, dtype=np.int64)
    pf = np.array(matched_ref, dtype=np.int64)
    time_error = np.abs(run["time"][pr] - ref["time"][pf])
    point_error = np.hypot(run["x"][pr] - ref["x"][pf], run["y"][pr] - ref["y"][pf])
    run_pairs = {k for k in run_keys if k[2] < 0}
    tunnelled = sorted({k for k in ref_keys if k[2] < 0} - run_pairs)
    return Match(
        pr,
        pf,
        np.flatnonzero(~ref_used),
        np.flatnonzero(~run_used),
        time_error,
        point_error,
        [(a, b) for a, b, _ in tunnelled],
    )


# --------------------------------------------------------------------------- conservation, validity
def drift(series: ArrayLike, reference: float | None = None, scale: float | None = None) -> float:
    """Largest relative deviation of ``series`` from ``reference``.

    ``series`` is ``(T,)`` or ``(T, d)`` (a vector per time: its deviation is the Euclidean norm).
    ``reference`` defaults to the first entry (so this is the drift of a conserved quantity), and
    may be one value or a series of the same shape. ``scale`` defaults to the norm of the first
    entry; a zero scale gives the absolute deviation.
    """
    s = np.asarray(series, dtype=np.float64)
    ref = s[0] if reference is None else np.asarray(reference, dtype=np.float64)
    dev = s - ref
    dev = np.abs(dev) if dev.ndim == 1 else np.sqrt((dev**2).sum(-1))
    if scale is None:
        scale = float(np.sqrt(np.sum(np.asarray(s[0]) ** 2)))
    if not len(dev):
        return 0.0
    worst = float(np.max(dev))
    return worst / scale if scale > 0 else worst


def kinetic_energy(vel: ArrayLike, masses: ArrayLike) -> np.ndarray:
    """Total kinetic energy of ``vel`` ``(..., N, 2)``, J."""
    return 0.5 * (np.asarray(masses) * (np.asarray(vel) ** 2).sum(-1)).sum(-1)


def momentum(vel: ArrayLike, masses: ArrayLike) -> np.ndarray:
    """Total momentum of ``vel`` ``(..., N, 2)``, kg m/s."""
    return (np.asarray(masses)[:, None] * np.asarray(vel)).sum(-2)


def final_state_error(
    pos: np.ndarray,
    vel: np.ndarray,
    ref_pos: np.ndarray,
    ref_vel: np.ndarray,
    radii: np.ndarray,
    speed_scale: float,
) -> tuple[float, float]:
    """``(max_i |x_i - x_ref,i| / r_i, max_i |v_i - v_ref,i| / speed_scale)``."""
    dx = np.hypot(*(np.asarray(pos) - np.asarray(ref_pos)).T) / np.asarray(radii)
    dv = np.hypot(*(np.asarray(vel) - np.asarray(ref_vel)).T) / speed_scale
    return float(dx.max()), float(dv.max())


def escapes(positions: ArrayLike, bounds: tuple[float, float, float, float] | None, dimension: int = 2) -> np.ndarray:
    """``(N,)`` bool: balls whose centre is outside the border in any of ``positions`` ``([T,] N, 2)``.

    A ball that merely overlaps a wall has not escaped (see :func:`wall_penetration`); one whose
    centre crossed the wall line has. Without a border nothing escapes.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    if bounds is None:
        return np.zeros(p.shape[1], dtype=bool)
    xmin, ymin, xmax, ymax = bounds
    out = (p[..., 0] < xmin) | (p[..., 0] > xmax)
    if dimension == 2:
        out |= (p[..., 1] < ymin) | (p[..., 1] > ymax)
    out |= ~np.isfinite(p).all(-1)
    return cast(np.ndarray, out.any(0))  # (p has three axes)


def wall_penetration(
    positions: ArrayLike, radii: ArrayLike, bounds: tuple[float, float, float, float] | None, dimension: int = 2
) -> float:
    """Deepest overlap of a ball with a wall over ``positions`` ``([T,] N, 2)``, in radii (0: none)."""
    if bounds is None:
        return 0.0
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    r = np.asarray(radii, dtype=np.float64)
    xmin, ymin, xmax, ymax = bounds
    depth = np.maximum(xmin + r - p[..., 0], p[..., 0] - (xmax - r))
    if dimension == 2:
        depth = np.maximum(depth, np.maximum(ymin + r - p[..., 1], p[..., 1] - (ymax - r)))
    return float(max(0.0, np.nanmax(depth / r)))


def max_overlap(positions: ArrayLike, radii: ArrayLike, chunk: int = 256) -> float:
    """Deepest ball-ball overlap over ``positions`` ``([T,] N, 2)``, relative to the radii sum (0: none)."""
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    n = p.shape[1]
    if n < 2:
        return 0.0
    r = np.asarray(radii, dtype=np.float64)
    sigma = r[:, None] + r[None, :]
    iu = np.triu_indices(n, 1)
    worst = 0.0
    for start in range(0, p.shape[0], chunk):
        q = p[start : start + chunk]
        d = np.sqrt(((q[:, :, None, :] - q[:, None, :, :]) ** 2).sum(-1))
        rel = (sigma - d) / sigma
        worst = max(worst, float(np.max(rel[:, iu[0], iu[1]])))
    return max(0.0, worst)


def collisions_per_ball(impacts: np.ndarray, n: int) -> np.ndarray:
    """``(n,)`` number of impacts each ball took part in (a ball-ball impact counts for both)."""
    imp = as_impacts(impacts)
    count = np.bincount(imp["ball"], minlength=n).astype(np.float64)
    pairs = imp["other"] >= 0
    count += np.bincount(imp["other"][pairs], minlength=n)
    return count


def short_horizon(impacts: np.ndarray, n: int, per_ball: float = 5.0, default: float | None = None) -> float | None:
    """A time between two impacts at which the balls have had ``per_ball`` impacts on average.

    ``impacts`` must be in time order (a reference run). Returns ``default`` if the run never
    gets there.
    """
    imp = as_impacts(impacts)
    inc = np.where(imp["other"] >= 0, 2.0, 1.0)
    cum = np.cumsum(inc) / n
    k = int(np.searchsorted(cum, per_ball))
    if k + 1 >= len(imp):
        return default
    return 0.5 * (imp["time"][k] + imp["time"][k + 1])


# --------------------------------------------------------------------------- statistics
def ks_rayleigh(speeds: ArrayLike, masses: ArrayLike | None = None, kT: float | None = None) -> float:
    """Kolmogorov-Smirnov distance between sampled speeds and the 2D Maxwell-Boltzmann (Rayleigh) law.

    ``F(v) = 1 - exp(-m v^2 / (2 kT))``. With several masses, each speed is scaled by
    ``sqrt(m / kT)`` first. ``kT`` defaults to the sample's mean kinetic energy per ball
    (equipartition in 2D: ``<m v^2 / 2> = kT``).
    """
    v = np.asarray(speeds, dtype=np.float64).ravel()
    m = np.ones_like(v) if masses is None else np.broadcast_to(np.asarray(masses, dtype=np.float64).ravel(), v.shape)
    if kT is None:
        kT = float(np.mean(0.5 * m * v**2))
    u = np.sort(v * np.sqrt(m / kT))
    cdf = 1.0 - np.exp(-0.5 * u**2)
    k = np.arange(1, len(u) + 1)
    return float(max(np.max(k / len(u) - cdf), np.max(cdf - (k - 1) / len(u))))


def ks_critical(n_samples: int, alpha: float = 0.05) -> float:
    """Asymptotic critical KS distance for ``n_samples`` independent samples at level ``alpha``."""
    return math.sqrt(-0.5 * math.log(alpha / 2.0)) / math.sqrt(n_samples)
