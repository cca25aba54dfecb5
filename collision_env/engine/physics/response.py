"""Collision responses: what velocities become at an impact.

Ball-ball (smooth disks, impulse along the line of centres ``n``, tangential parts unchanged),
with inverse masses ``w = 1/m`` so that mass ratios up to 1e12 and beyond stay well conditioned:

    u = (v_j - v_i) . n   (< 0 when closing),   J = (1 + e) u / (w_i + w_j)
    v_i += J w_i n,   v_j -= J w_j n    =>  (v_j' - v_i') . n = -e u,  dKE = -1/2 (1 - e^2) mu u^2

Ball-wall: ``v_n' = -e v_n``.

**Collapse regulariser.** With e < 1, hard disks can collide infinitely often in finite time
(inelastic collapse; McNamara & Young 1992), and a touching train pressed against a wall at e = 0
is resolved by an infinite cascade of ever smaller impulses at one instant. Every impact gets a
tiny speed from the balls it involves, and from nothing else:

    u_min = max(collapse_ratio * s, collapse_floor)

where ``s`` is the fastest of the two balls just before the impact (the ball alone for a wall
impact) or, inside a contact group resolved at one instant, the group's kinetic-energy speed
``sqrt(sum m v^2 / max m)`` when the group is formed (see :func:`group_threshold` and
``exact.contacts.cascade``). Defaults: ``collapse_ratio`` = 1e-9,
``collapse_floor`` = 0 m/s. ``u_min`` is far below anything measurable and, at 1e-9 of the speeds
involved, far above their round-off (2.2e-16 of them), so a pair set apart at ``u_min`` really
separates. The rule

- makes a collision whose normal closing speed is at most ``u_min`` leave the pair (or the ball
  and the wall) separating at ``u_min``: elastic, or a hair more (as DynamO's ``ElasticV`` and
  Box2D's restitution threshold make slow collisions elastic). This ends every cascade after a
  bounded number of impulses (about log(1/ratio)/log(1/e) per contact chain), and a pair that
  round-off left closing after a plastic impact is set apart at once instead of being resolved
  again and again at the same instant.

A cascade that the rule does not end quickly because it converges at a rate set by a mass ratio
(a light ball pressed between a wall and a far heavier ball) is replaced by its limit after a
fixed number of sweeps, whatever the ratio: see ``exact.contacts.settle``.

Energy: the rule can add at most ``1/2 mu u_min^2`` to a collision whose closing speed was below
``u_min``. With ``u_min = collapse_ratio * s`` that is at most ``collapse_ratio^2`` (1e-18) of the
kinetic energy of the balls involved (the pair's reduced mass ``mu`` is at most either mass, and at
most the group's heaviest), below the round-off of the energy itself, so at e < 1 the energy never
grows beyond round-off, and balls that take no part in the impact have no say in it.
A positive ``collapse_floor`` (an absolute minimum separation speed, m/s) trades that bound for
``1/2 mu collapse_floor^2`` per collision. Elastic scenes are otherwise unaffected.

**The TC model** (opt-in: ``contact_duration`` > 0 s, a Simulator/BatchSimulator setting beside
the regulariser's; 0, the default, leaves every result as it was). The regulariser keeps
collapse from stopping the clock, but a dense inelastic flow (a heap settling under gravity, a
cluster collapsing, a cooling gas's clusters) still collides as often as exact hard-disk dynamics
says, far more often than any step budget allows. Luding & McNamara (*Granular Matter* 1, 113,
1998) bound that with a contact duration ``t_c``: a collision is elastic (e = 1) when either ball's
previous collision happened less than ``t_c`` before it (a ball-wall collision: the ball's), and
has the scene's ``e`` otherwise (:func:`restitution`). Dissipation then stops where collisions come
faster than one per ``t_c`` per ball, as it does in a soft-sphere contact lasting ``t_c``, so dense
regions stay a dense elastic gas instead of collapsing; a dilute gas, whose balls collide far less
often, is not changed so long as ``t_c`` is much shorter than the time between a ball's
collisions there: choose ``t_c`` so (the grains' contact duration, where it is known, is the
model's own reading of it).

Each ball's last collision instant (s on the clock; ``-inf``: none yet) is kept in exact mode's
calendar, carried by ``copy``/``load`` and, under the model, by ``get_state``/``set_state``
(``SimulatorState.last_impact``; None in other simulators' states, whose states stay as they
were); a ball placed afresh (``set_balls``, ``set_scenes``, a reset) has none. Inside a contact
group resolved at one instant (``exact.contacts``), every contact's restitution comes from its
balls' collision instants *before* the group's, which is recorded once the group is resolved (for
the impact's balls and those of every contact that took an impulse), so the impulses of one
cascade do not make each other elastic; the sweeps apply each contact's own restitution, and a
cascade that the sweeps do not end goes to its limit, which is the plastic one (separation at
``u_min``) whatever the contacts' restitutions: energy never grows either way. Exact mode only
(the cheap modes resolve each pair once per sub-step, with no collision instants: they refuse
``contact_duration`` > 0), slip scenes only (a stick scene merges colliding balls: refused), and
forward steps only (which collisions it makes elastic depends on those before: a backward step is
refused).

The cheap modes (naive, posteriori) resolve each pair once per sub-step, so no cascade runs at one
instant there; they keep one threshold per scene and sub-step, :func:`elastic_threshold`, relative
to the scene's slowest moving ball, which bounds the energy it adds the same way.

Stick scenes (e = 0, ``inelastic="stick"``): colliding bodies merge into one rigid cluster that
keeps the total momentum and the total angular momentum about the new centre of mass
(``omega = L / I`` with ``I = sum m_i |r_i - r_cm|^2``, PhET's point-mass inertia); a ball or
cluster that touches a wall stops dead and the cluster comes apart (PhET's Inelastic screen).
"""

from __future__ import annotations

import math

from .._jit import njit
from .walls import heads_into, wall_axis

#: Closing speeds up to this many ulps of a group's fastest speed are round-off, not collisions.
_ROUNDOFF_SPEED = 8.0 * 2.0**-52


@njit(inline="always")
def elastic_threshold(vel, collapse_ratio, collapse_floor):
    """``u_min`` for one scene of the cheap modes: ``collapse_ratio`` times the speed of the scene's
    slowest moving ball (a pair that collides has at least one ball that fast, so the rule adds at
    most ``collapse_ratio^2`` of that pair's own energy), or ``collapse_floor``."""
    slowest = math.inf
    for i in range(vel.shape[0]):
        speed2 = vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]
        if speed2 > 0.0:
            slowest = min(slowest, speed2)
    return max(collapse_ratio * math.sqrt(slowest), collapse_floor) if slowest < math.inf else collapse_floor


@njit(refcount=False, forceinline=True)
def impact_threshold(i, j, vel, collapse_ratio, collapse_floor):
    """``u_min`` of an impact of ball ``i`` with ball ``j`` (``j < 0``: a wall), from their speeds."""
    fastest = vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]
    if j >= 0:
        fastest = max(fastest, vel[j, 0] * vel[j, 0] + vel[j, 1] * vel[j, 1])
    return max(collapse_ratio * math.sqrt(fastest), collapse_floor)


@njit(refcount=False, forceinline=True)
def group_threshold(group, size, vel, inv_mass, collapse_ratio, collapse_floor):
    """``u_min`` of a contact group (its balls are ``group[:size]``): ``collapse_ratio`` times the
    group's kinetic-energy speed ``sqrt(sum m v^2 / max m)``, or a few ulps of its fastest ball's
    speed (so that round-off never passes for a collision), or ``collapse_floor``.

    Weighting by the heaviest mass bounds what the rule can add to any contact of the group, of
    reduced mass ``mu <= max m``, by ``collapse_ratio^2`` of the group's energy, however the
    masses differ (a fast light ball does not set the threshold of a slow heavy pair)."""
    energy2 = 0.0
    heaviest_inv = math.inf
    fastest = 0.0
    for q in range(size):
        i = group[q]
        speed2 = vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]
        energy2 += speed2 / inv_mass[i]
        heaviest_inv = min(heaviest_inv, inv_mass[i])
        fastest = max(fastest, speed2)
    return max(collapse_ratio * math.sqrt(energy2 * heaviest_inv), _ROUNDOFF_SPEED * math.sqrt(fastest), collapse_floor)


@njit(inline="always")
def restitution(e, contact_duration, t_abs, last, i, j):
    """The TC model's restitution of a collision at instant ``t_abs`` of ball ``i`` with ball ``j``
    (``j < 0``: a wall): 1 if either ball's last collision instant (``last``) was less than
    ``contact_duration`` before, else the scene's ``e`` (always, with ``contact_duration`` 0)."""
    if contact_duration > 0.0:
        if t_abs - last[i] < contact_duration or (j >= 0 and t_abs - last[j] < contact_duration):
            return 1.0
    return e


@njit(inline="always")
def separation_speed(closing_speed, e, u_min):
    """Normal speed at which a collision leaves the pair separating (see the regulariser)."""
    return e * closing_speed if closing_speed > u_min else u_min


@njit(refcount=False, forceinline=True)
def normal_impulse(closing_speed, e, u_min, inv_mass_sum):
    """The normal impulse (N s) of an impact whose response :func:`ball_ball` or :func:`ball_wall`
    gave: the momentum change along the normal of either ball of a pair, ``(u + u') / (w_i + w_j)``
    with ``u'`` the separation speed, or of the ball at a wall, ``m (u + u')`` (``inv_mass_sum``
    is ``w_i + w_j``, or ``w_i`` for a wall). A plastic impact (e = 0, ``u_min`` = 0) gives
    ``u / (w_i + w_j)`` (``m u`` at a wall)."""
    return (closing_speed + separation_speed(closing_speed, e, u_min)) / inv_mass_sum


@njit(refcount=False, forceinline=True)
def body_inverse_mass(i, mass, body, sticky):
    """1 / the mass of ball ``i``'s cluster (of the ball alone unless the scene is a stick one)."""
    if not sticky:
        return 1.0 / mass[i]
    root = body[i]
    m_tot = 0.0
    for k in range(mass.shape[0]):
        if body[k] == root:
            m_tot += mass[k]
    return 1.0 / m_tot


@njit(refcount=False, forceinline=True)
def ball_ball(i, j, pos, vel, inv_mass, e, u_min):
    """Apply the impulse between balls ``i`` and ``j``. Returns the closing speed (0: no impulse)."""
    return ball_ball_along(i, j, pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1], vel, inv_mass, e, u_min)


@njit(refcount=False, forceinline=True)
def ball_ball_along(i, j, dx, dy, vel, inv_mass, e, u_min):
    """:func:`ball_ball` for balls ``i`` and ``j`` whose centres are ``(dx, dy)`` apart (``j``'s from
    ``i``'s: in a periodic cell, through the nearest image)."""
    d = math.sqrt(dx * dx + dy * dy)
    # "approaching" is decided by the same expression as in toi.toi_pair, so that the predictor
    # and the response can never disagree about it through round-off
    b = dx * (vel[j, 0] - vel[i, 0]) + dy * (vel[j, 1] - vel[i, 1])
    if not (b < 0.0 and d > 0.0):
        return 0.0
    nx = dx / d
    ny = dy / d
    u = b / d
    wi = inv_mass[i]
    wj = inv_mass[j]
    jn = (u - separation_speed(-u, e, u_min)) / (wi + wj)
    vel[i, 0] += jn * wi * nx
    vel[i, 1] += jn * wi * ny
    vel[j, 0] -= jn * wj * nx
    vel[j, 1] -= jn * wj * ny
    return -u


@njit(refcount=False, forceinline=True)
def ball_wall(i, wall, vel, e, u_min):
    """Reflect the normal component of ball ``i``'s velocity off ``wall``. Returns the closing speed."""
    axis = wall_axis(wall)
    vn = vel[i, axis]
    if not heads_into(wall, vn):
        return 0.0
    out = separation_speed(abs(vn), e, u_min)
    vel[i, axis] = out if vn < 0.0 else -out
    return abs(vn)


@njit(refcount=False, python=False)
def merge_bodies(i, j, pos, vel, mass, body, omega):
    """Stick balls ``i`` and ``j`` (and their clusters) into one rigid body. Returns the root."""
    bi = body[i]
    bj = body[j]
    root = min(bi, bj)
    gone = max(bi, bj)
    n = pos.shape[0]
    m_tot = 0.0
    cx = 0.0
    cy = 0.0
    px = 0.0
    py = 0.0
    for k in range(n):
        if body[k] == gone:
            body[k] = root
        if body[k] == root:
            m = mass[k]
            m_tot += m
            cx += m * pos[k, 0]
            cy += m * pos[k, 1]
            px += m * vel[k, 0]
            py += m * vel[k, 1]
    cx /= m_tot
    cy /= m_tot
    vcx = px / m_tot
    vcy = py / m_tot
    ang = 0.0
    inertia = 0.0
    for k in range(n):
        if body[k] == root:
            m = mass[k]
            dx = pos[k, 0] - cx
            dy = pos[k, 1] - cy
            ang += m * (dx * (vel[k, 1] - vcy) - dy * (vel[k, 0] - vcx))
            inertia += m * (dx * dx + dy * dy)
    w = ang / inertia if inertia > 0.0 else 0.0
    for k in range(n):
        if body[k] == root:
            dx = pos[k, 0] - cx
            dy = pos[k, 1] - cy
            vel[k, 0] = vcx - w * dy
            vel[k, 1] = vcy + w * dx
    omega[gone] = 0.0
    omega[root] = w
    return root


@njit(refcount=False, python=False)
def stop_body(i, vel, body, omega):
    """A stuck ball or cluster touching a wall stops dead and comes apart (PhET)."""
    root = body[i]
    for k in range(vel.shape[0]):
        if body[k] == root:
            vel[k, 0] = 0.0
            vel[k, 1] = 0.0
            body[k] = k
    omega[root] = 0.0
