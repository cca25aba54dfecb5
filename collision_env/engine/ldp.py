"""Least-distance programming: the closest point of a polyhedral cone, for unending contact cascades.

Exact mode resolves a group of touching balls by sequential pairwise impulses (see
``exact._resolve_contact_group``). Where that cascade converges only geometrically at a rate set
by a mass ratio (a light ball pressed between a wall and a ball 1e12 times heavier needs about
1e12 sweeps), the engine jumps to its limit instead: the velocities closest to the current ones,
in the kinetic-energy metric, at which every contact of the group separates. That is a
least-distance problem

    minimise |x|  subject to  G x >= h,

which Lawson & Hanson (*Solving Least Squares Problems*, 1974, ch. 23) reduce to one
non-negative least-squares problem solved by their active-set algorithm (finite, and stable with
Householder QR). Both are small dense routines, written here so that they compile with numba
and need no SciPy.
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import njit

#: Relative tolerance of the NNLS optimality test and of the feasibility test.
_TOL = 1e-12


@njit
def _least_squares(e_mat, f, cols, n_cols, z, work):
    """Solve ``min |E[:, cols] z - f|`` by Householder QR; ``z[cols[k]]`` gets the solution."""
    rows = e_mat.shape[0]
    for k in range(n_cols):
        for r in range(rows):
            work[r, k] = e_mat[r, cols[k]]
    for r in range(rows):
        work[r, n_cols] = f[r]
    for k in range(n_cols):
        norm = 0.0
        for r in range(k, rows):
            norm += work[r, k] * work[r, k]
        norm = math.sqrt(norm)
        if norm == 0.0:
            continue
        alpha = -norm if work[k, k] >= 0.0 else norm
        v0 = work[k, k] - alpha
        # Householder vector v = (v0, work[k+1:, k]); H = I - 2 v v^T / |v|^2
        vnorm2 = v0 * v0
        for r in range(k + 1, rows):
            vnorm2 += work[r, k] * work[r, k]
        if vnorm2 == 0.0:
            continue
        for c in range(k + 1, n_cols + 1):
            dot = v0 * work[k, c]
            for r in range(k + 1, rows):
                dot += work[r, k] * work[r, c]
            s = 2.0 * dot / vnorm2
            work[k, c] -= s * v0
            for r in range(k + 1, rows):
                work[r, c] -= s * work[r, k]
        work[k, k] = alpha
    for k in range(n_cols - 1, -1, -1):
        acc = work[k, n_cols]
        for c in range(k + 1, n_cols):
            acc -= work[k, c] * z[cols[c]]
        z[cols[k]] = acc / work[k, k] if work[k, k] != 0.0 else 0.0


@njit
def nnls(e_mat, f):
    """Non-negative least squares ``min |E u - f|, u >= 0`` (Lawson & Hanson's algorithm).

    Returns ``u``. The columns of ``E`` should be scaled to comparable norms (the tolerance of
    the optimality test is relative to them and to ``|f|``).
    """
    rows, m = e_mat.shape
    u = np.zeros(m)
    z = np.zeros(m)
    in_p = np.zeros(m, dtype=np.bool_)
    cols = np.empty(m, dtype=np.int64)
    work = np.empty((rows, m + 1))
    resid = f.copy()
    scale = 0.0
    for r in range(rows):
        scale = max(scale, abs(f[r]))
    for c in range(m):
        for r in range(rows):
            scale = max(scale, abs(e_mat[r, c]))
    tol = _TOL * scale * scale * (rows + m)
    for _ in range(3 * m + 3):  # each outer pass adds a column; Lawson & Hanson's bound is finite
        best = tol
        t = -1
        for c in range(m):
            if in_p[c]:
                continue
            w = 0.0
            for r in range(rows):
                w += e_mat[r, c] * resid[r]
            if w > best:
                best = w
                t = c
        if t < 0:
            break
        in_p[t] = True
        for _inner in range(m + 1):
            n_cols = 0
            for c in range(m):
                if in_p[c]:
                    cols[n_cols] = c
                    n_cols += 1
            _least_squares(e_mat, f, cols, n_cols, z, work)
            alpha = 2.0
            for k in range(n_cols):
                c = cols[k]
                if z[c] <= 0.0:
                    step = u[c] / (u[c] - z[c]) if u[c] - z[c] != 0.0 else 0.0
                    alpha = min(alpha, step)
            if alpha >= 2.0:  # every coefficient positive: accept
                for k in range(n_cols):
                    u[cols[k]] = z[cols[k]]
                break
            for k in range(n_cols):
                c = cols[k]
                u[c] += alpha * (z[c] - u[c])
                if u[c] <= 0.0 or (z[c] <= 0.0 and u[c] <= tol):
                    u[c] = 0.0
                    in_p[c] = False
        for r in range(rows):
            acc = f[r]
            for c in range(m):
                acc -= e_mat[r, c] * u[c]
            resid[r] = acc
    return u


@njit
def least_distance(g_mat, h):
    """``argmin |x| subject to G x >= h`` (Lawson & Hanson's LDP via NNLS).

    Returns ``(x, feasible)``; when the constraints cannot all hold, ``feasible`` is False and
    ``x`` is zeros. Rows of ``G`` may be redundant or dependent.
    """
    m, d = g_mat.shape
    x = np.zeros(d)
    # Scale x by the largest distance any one constraint alone asks for, so that |x| is O(1) and
    # the feasibility test below is scale-free (|E u - f|^2 = 1 / (1 + |x|^2) when feasible).
    s = 0.0
    for c in range(m):
        norm = 0.0
        for k in range(d):
            norm += g_mat[c, k] * g_mat[c, k]
        if h[c] > 0.0:
            if norm == 0.0:
                return x, False
            s = max(s, h[c] / math.sqrt(norm))
    if s == 0.0:  # x = 0 already satisfies every constraint
        return x, True
    # E = [G^T; (h/s)^T], f = (0, ..., 0, 1); each column scaled to unit norm (u >= 0 is scale-free)
    e_mat = np.zeros((d + 1, m))
    for c in range(m):
        hc = h[c] / s
        norm = hc * hc
        for k in range(d):
            norm += g_mat[c, k] * g_mat[c, k]
        norm = math.sqrt(norm)
        if norm == 0.0:
            continue
        for k in range(d):
            e_mat[k, c] = g_mat[c, k] / norm
        e_mat[d, c] = hc / norm
    f = np.zeros(d + 1)
    f[d] = 1.0
    u = nnls(e_mat, f)
    r_last = -1.0
    for c in range(m):
        r_last += e_mat[d, c] * u[c]
    if not -r_last > _TOL:  # |E u - f| = 0: no x satisfies every constraint
        return x, False
    for k in range(d):
        acc = 0.0
        for c in range(m):
            acc += e_mat[k, c] * u[c]
        x[k] = -s * acc / r_last
    return x, True
