"""Uniform motion between collisions, including rigid clusters of stuck balls.

State of one scene (arrays, no batch axis; the mode kernels loop over the batch):

- ``pos``, ``vel``: (N, 2) float64, centre and velocity of every ball;
- ``mass``: (N,) float64;
- ``body``: (N,) int64, the index of the ball that roots its rigid cluster (``body[i] == i`` for a
  free ball; only stick scenes ever merge balls);
- ``omega``: (N,) float64, the angular velocity of the cluster rooted at that index (0 for free
  balls and for clusters that only translate).

A cluster's members keep their velocities consistent with the rigid motion
``v_i = v_cm + omega x (p_i - p_cm)``, so code that only reads ``vel`` sees the right velocities.
"""

from __future__ import annotations

import math

from .._jit import njit
from ..layout import B_INV_MASS, B_MASS, B_OMEGA, B_RADIUS, B_VX, B_X


@njit(inline="always")
def ball_views(balls):
    """The per-ball state as views: pos, vel (B, N, 2), mass, inv_mass, radius, omega (B, N)."""
    return (
        balls[:, :, B_X : B_X + 2],
        balls[:, :, B_VX : B_VX + 2],
        balls[:, :, B_MASS],
        balls[:, :, B_INV_MASS],
        balls[:, :, B_RADIUS],
        balls[:, :, B_OMEGA],
    )


@njit(refcount=False, python=False)
def body_kinematics(i, pos, vel, mass, body, omega):
    """Centre of mass, its velocity, ball ``i``'s offset from it and the angular velocity.

    For a ball that does not rotate, the "body" is the ball itself: offset 0, omega 0, so
    :func:`position_at` reduces to straight-line motion.
    """
    root = body[i]
    w = omega[root]
    if w == 0.0:
        return pos[i, 0], pos[i, 1], vel[i, 0], vel[i, 1], 0.0, 0.0, 0.0
    m_tot = 0.0
    cx = 0.0
    cy = 0.0
    vx = 0.0
    vy = 0.0
    for k in range(pos.shape[0]):
        if body[k] == root:
            m = mass[k]
            m_tot += m
            cx += m * pos[k, 0]
            cy += m * pos[k, 1]
            vx += m * vel[k, 0]
            vy += m * vel[k, 1]
    cx /= m_tot
    cy /= m_tot
    return cx, cy, vx / m_tot, vy / m_tot, pos[i, 0] - cx, pos[i, 1] - cy, w


@njit(refcount=False, python=False)
def position_at(tau, cx, cy, vcx, vcy, dx, dy, w):
    """Position and velocity, ``tau`` seconds on, of a point of a body in rigid motion."""
    if w == 0.0:
        return cx + dx + vcx * tau, cy + dy + vcy * tau, vcx, vcy
    c = math.cos(w * tau)
    s = math.sin(w * tau)
    rx = dx * c - dy * s
    ry = dx * s + dy * c
    return cx + vcx * tau + rx, cy + vcy * tau + ry, vcx - w * ry, vcy + w * rx


@njit(refcount=False, python=False)
def advance_body(root, dt, pos, vel, mass, body, omega):
    """Move the members of the rotating cluster rooted at ``root`` on by ``dt``."""
    cx, cy, vcx, vcy, _, _, w = body_kinematics(root, pos, vel, mass, body, omega)
    c = math.cos(w * dt)
    s = math.sin(w * dt)
    for k in range(pos.shape[0]):
        if body[k] == root:
            dx = pos[k, 0] - cx
            dy = pos[k, 1] - cy
            rx = dx * c - dy * s
            ry = dx * s + dy * c
            pos[k, 0] = cx + vcx * dt + rx
            pos[k, 1] = cy + vcy * dt + ry
            vel[k, 0] = vcx - w * ry
            vel[k, 1] = vcy + w * rx


@njit(refcount=False, forceinline=True)
def advance_all(dt, pos, vel, mass, body, omega, any_rotating):
    """Move every ball on by ``dt``: straight lines, and rigid rotation for spinning clusters."""
    n = pos.shape[0]
    for i in range(n):
        if not any_rotating or omega[body[i]] == 0.0:
            pos[i, 0] += vel[i, 0] * dt
            pos[i, 1] += vel[i, 1] * dt
    if any_rotating:
        for r in range(n):
            if body[r] == r and omega[r] != 0.0:
                advance_body(r, dt, pos, vel, mass, body, omega)


@njit(refcount=False, forceinline=True)
def has_rotation(body, omega):
    for r in range(body.shape[0]):
        if body[r] == r and omega[r] != 0.0:
            return True
    return False


@njit(refcount=False)
def apply_impulses(balls, body, dv, sticky):
    """Add ``dv`` to every ball's velocity as an impulse ``m dv`` at its centre.

    A free ball's velocity just changes by ``dv``; an impulse on a member of a stuck cluster
    changes the cluster's linear and angular velocity, and so every member's velocity (only
    ``sticky`` scenes have clusters).
    """
    pos, vel, mass, _, _, omega = ball_views(balls)
    n_scenes, n = pos.shape[0], pos.shape[1]
    if not sticky:
        for sc in range(n_scenes):
            for i in range(n):
                vel[sc, i, 0] += dv[sc, i, 0]
                vel[sc, i, 1] += dv[sc, i, 1]
        return
    for sc in range(n_scenes):
        for i in range(n):
            if dv[sc, i, 0] == 0.0 and dv[sc, i, 1] == 0.0:
                continue
            root = body[sc, i]
            if body[sc, i] == i and omega[sc, i] == 0.0:
                alone = True
                for k in range(n):
                    if k != i and body[sc, k] == i:
                        alone = False
                        break
                if alone:
                    vel[sc, i, 0] += dv[sc, i, 0]
                    vel[sc, i, 1] += dv[sc, i, 1]
                    continue
            m_tot = 0.0
            cx = 0.0
            cy = 0.0
            vx = 0.0
            vy = 0.0
            for k in range(n):
                if body[sc, k] == root:
                    m = mass[sc, k]
                    m_tot += m
                    cx += m * pos[sc, k, 0]
                    cy += m * pos[sc, k, 1]
                    vx += m * vel[sc, k, 0]
                    vy += m * vel[sc, k, 1]
            cx /= m_tot
            cy /= m_tot
            jx = mass[sc, i] * dv[sc, i, 0]
            jy = mass[sc, i] * dv[sc, i, 1]
            vx = (vx + jx) / m_tot
            vy = (vy + jy) / m_tot
            inertia = 0.0
            for k in range(n):
                if body[sc, k] == root:
                    inertia += mass[sc, k] * ((pos[sc, k, 0] - cx) ** 2 + (pos[sc, k, 1] - cy) ** 2)
            w = omega[sc, root]
            if inertia > 0.0:
                w += ((pos[sc, i, 0] - cx) * jy - (pos[sc, i, 1] - cy) * jx) / inertia
            omega[sc, root] = w
            for k in range(n):
                if body[sc, k] == root:
                    vel[sc, k, 0] = vx - w * (pos[sc, k, 1] - cy)
                    vel[sc, k, 1] = vy + w * (pos[sc, k, 0] - cx)
