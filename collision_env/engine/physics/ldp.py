"""Least-distance programming: the closest point of a polyhedral cone, for unending contact cascades.

Exact mode resolves a group of touching balls by sequential pairwise impulses (see
``exact.contacts.cascade``). Where that cascade converges only geometrically at a rate set
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

from .._jit import njit

#: Relative tolerance of the NNLS optimality test and of the feasibility test.
_TOL = 1e-12
#: Factor by which the scale grows when the residual is lost in round-off, and how many times.
_RESCALE = 1e8
_MAX_RESCALES = 40


@njit(inline="always")
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
    # The first scale s: the largest distance any one constraint alone asks for (the feasibility test
    # is scale-free: |E u - f|^2 = 1 / (1 + |x / s|^2) when feasible).
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
    # Lawson & Hanson's x = -s E_top u / r is exact in exact arithmetic, but where the masses of a
    # group differ by M/m its constraints are nearly dependent (condition ~sqrt(M/m)) and that
    # formula loses everything at M/m ~ 1e12. The NNLS still finds which constraints hold with
    # equality (u > 0), and the least-norm x meeting those with equality, by Householder QR of
    # G_A^T (backward stable whatever the conditioning), is the solution when it meets the others.
    # Infeasibility does not depend on s, while the accuracy of the NNLS does (|E u - f|^2 =
    # 1 / (1 + |x / s|^2)): when the check fails, grow s and solve again; infeasible only when no
    # scale up to 1e320 times the first gives an x that meets every constraint.
    e_mat = np.zeros((d + 1, m))
    f = np.zeros(d + 1)
    f[d] = 1.0
    cols = np.empty(m, dtype=np.int64)
    work = np.empty((d, m))
    hh = np.empty(2 * m)
    free = np.ones(d, dtype=np.bool_)
    for c in range(m):
        for k in range(d):
            if g_mat[c, k] != 0.0:
                free[k] = False
    for _ in range(_MAX_RESCALES):
        u = _ldp_dual(g_mat, h, s, e_mat, f)
        n_cols = 0
        for c in range(m):
            if u[c] > 0.0:
                cols[n_cols] = c
                n_cols += 1
        _least_norm(g_mat, h, cols, n_cols, x, work, hh)
        for k in range(d):  # no constraint involves it: exactly 0 (not the round-off of the others)
            if free[k]:
                x[k] = 0.0
        if _meets(g_mat, h, x):
            return x, True
        if s > 1e300 / _RESCALE:
            break
        s *= _RESCALE
    for k in range(d):
        x[k] = 0.0
    return x, False


@njit(inline="always")
def _ldp_dual(g_mat, h, s, e_mat, f):
    """Lawson & Hanson's NNLS dual of the LDP ``G x >= h`` at scale ``s``: returns ``u >= 0``
    (``u > 0`` on the constraints that hold with equality at the solution)."""
    m, d = g_mat.shape
    # E = [G^T; (h/s)^T], f = (0, ..., 0, 1); each column scaled to unit norm (u >= 0 is scale-free)
    for c in range(m):
        hc = h[c] / s
        norm = hc * hc
        for k in range(d):
            norm += g_mat[c, k] * g_mat[c, k]
        norm = math.sqrt(norm)
        for k in range(d + 1):
            e_mat[k, c] = 0.0
        if norm == 0.0:
            continue
        for k in range(d):
            e_mat[k, c] = g_mat[c, k] / norm
        e_mat[d, c] = hc / norm
    return nnls(e_mat, f)


@njit(inline="always")
def _least_norm(g_mat, h, cols, n_cols, x, work, hh):
    """``x`` = the least-norm solution of ``G[cols] x = h[cols]``, by Householder QR of
    ``G[cols]^T = Q R``: ``x = Q R^-T h[cols]``. A row that depends on earlier ones (a pivot at
    round-off level) is skipped. ``work`` is (d, >= n_cols), ``hh`` has >= 2 n_cols entries."""
    d = g_mat.shape[1]
    for q in range(n_cols):
        for k in range(d):
            work[k, q] = g_mat[cols[q], k]
    n_house = min(n_cols, d)
    big = 0.0
    for q in range(n_house):
        norm = 0.0
        for k in range(q, d):
            norm += work[k, q] * work[k, q]
        norm = math.sqrt(norm)
        alpha = -norm if work[q, q] >= 0.0 else norm
        work[q, q] -= alpha  # Householder vector v = work[q:, q]; H = I - 2 v v^T / |v|^2
        vnorm2 = 0.0
        for k in range(q, d):
            vnorm2 += work[k, q] * work[k, q]
        hh[q] = vnorm2
        hh[n_cols + q] = alpha  # R[q, q]
        big = max(big, norm)
        if vnorm2 == 0.0:
            continue
        for c in range(q + 1, n_cols):
            dot = 0.0
            for k in range(q, d):
                dot += work[k, q] * work[k, c]
            t = 2.0 * dot / vnorm2
            for k in range(q, d):
                work[k, c] -= t * work[k, q]
    # R^T z = h[cols] by forward substitution (R[q, c] = work[q, c] for c > q); z goes into x[:n_house]
    for k in range(d):
        x[k] = 0.0
    for q in range(n_house):
        acc = h[cols[q]]
        for p in range(q):
            acc -= work[p, q] * x[p]
        r = hh[n_cols + q]
        x[q] = acc / r if abs(r) > 1e-14 * big else 0.0
    # x = Q z = H_0 H_1 ... H_{n-1} z
    for q in range(n_house - 1, -1, -1):
        vnorm2 = hh[q]
        if vnorm2 == 0.0:
            continue
        dot = 0.0
        for k in range(q, d):
            dot += work[k, q] * x[k]
        t = 2.0 * dot / vnorm2
        for k in range(q, d):
            x[k] -= t * work[k, q]


@njit(inline="always")
def _meets(g_mat, h, x):
    """``G x >= h`` up to the round-off of a backward-stable solve (relative to the largest ``|h|``
    and the largest ``|G| |x|``: a solve is accurate norm-wise, not row by row)."""
    m, d = g_mat.shape
    size = 0.0
    for c in range(m):
        row = 0.0
        for k in range(d):
            row += abs(g_mat[c, k] * x[k])
        size = max(size, max(row, abs(h[c])))
    slack = 64.0 * 2.0**-52 * size
    for c in range(m):
        acc = 0.0
        for k in range(d):
            acc += g_mat[c, k] * x[k]
        if acc < h[c] - slack:
            return False
    return True
