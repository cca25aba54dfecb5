"""Named layouts of the engine's packed arrays: every field of every packed array, in one place.

The kernels take a handful of packed arrays instead of dozens of small ones, because every array
handed to a compiled function costs about 0.1 us per call (a one-ball step is a few us). Each
packed array's last axis is laid out by one of the field tuples below, and the kernels read it
through the index constants defined next to it, never by bare numbers. A test checks that each
tuple and its constants agree.

Per ball, ``(B, N, len(fields))``:

- :data:`BALL` (float64): the physical state, see :mod:`collision_env.engine.physics.motion`.
- :data:`CAL_RECORD` (a structured dtype, ``(B, N)``) and :data:`CAL_I` (int32): exact mode's
  persistent event calendar and cell grid, see :mod:`collision_env.engine.exact.calendar` and
  :mod:`collision_env.engine.exact.grid`; :data:`HEAP` (float64): the heap of the calendar's event
  queue (its time buckets are an int32 array of list heads, ``(B, buckets + 1)``).

Per scene:

- :data:`SCENE_F` / :data:`SCENE_I`: the parameters every scene of a batch shares (one vector
  each, set from the :class:`~collision_env.engine.Scene` and the simulator's options).
- :data:`WORK_F` / :data:`WORK_I` (``(B, len(fields))``): per-scene bookkeeping of a step and the
  grid's geometry.
"""

from __future__ import annotations

import numpy as np

#: Per-ball physical state: centre (m), velocity (m/s), mass (kg), its inverse, radius (m), and
#: the angular velocity (rad/s) of the rigid cluster the ball roots (0 unless it roots one).
BALL = ("x", "y", "vx", "vy", "mass", "inv_mass", "radius", "omega")
B_X, B_Y, B_VX, B_VY, B_MASS, B_INV_MASS, B_RADIUS, B_OMEGA = range(8)

#: Exact mode's calendar record of a ball: one 64-byte row, one cache line, holding everything a
#: prediction reads of a neighbour, so that looking at a neighbour costs one memory access (the
#: event loop's cost at 10^4 balls and more is memory traffic, not arithmetic). The ball's
#: straight-line trajectory as the calendar knows it: its centre (m) at ``ref_time``, its velocity
#: (m/s) and radius (m); the time of its next event; the next ball in its grid cell's list; and its
#: change counter (a pair event predicted with a ball is stale once the ball's counter has moved).
#: Times are relative to the start of the current step. Between steps the record holds the state
#: the last step ended in, which is how a change made in between (a nudge, an env's action) is
#: found. A structured dtype: kernels read a field by its name, ``cal[i]["x"]``.
CAL_RECORD = np.dtype(
    [
        ("x", np.float64),
        ("y", np.float64),
        ("vx", np.float64),
        ("vy", np.float64),
        ("radius", np.float64),
        ("ref_time", np.float64),
        ("event_time", np.float64),
        ("cell_next", np.int32),
        ("changes", np.int32),
    ],
    align=True,
)

#: Per-ball calendar ints (int32), read only for the ball's own event, when it moves between
#: cells, or when a neighbour in its queue list moves: what the next event is (a partner ball >= 0,
#: or a ``calendar.EV_*`` code); the partner's change counter when it was predicted; where the
#: event is queued (a heap slot >= 0; ``-1 - p`` in bucket p of the ring, p = R in the far list)
#: and, in a list, the next and previous ball of that list; its grid cell and the previous ball in
#: that cell's list. (The first ball of each cell is in a (B, cells) int32 array of its own, so
#: that the heads of neighbouring cells share cache lines.)
CAL_I = ("event_other", "event_stamp", "queue_slot", "queue_next", "queue_prev", "cell", "cell_prev")
C_EVENT_OTHER, C_EVENT_STAMP, C_QUEUE_SLOT, C_QUEUE_NEXT, C_QUEUE_PREV, C_CELL, C_CELL_PREV = range(7)

#: The event queue's heap, one row per slot (float64): the event time held there and the ball
#: (an integer stored as a float, so that a node and its children share cache lines).
HEAP = ("time", "ball")
H_TIME, H_BALL = range(2)

#: Scene floats: the border (m; zeros when there is none), the restitution used this step (1/e
#: when running backwards), the collapse regulariser's ratio and floor (m/s), the direction
#: of time (+1 or -1), and the TC model's contact duration (s; 0: off, see
#: :mod:`collision_env.engine.physics.response`).
SCENE_F = ("xmin", "ymin", "xmax", "ymax", "elasticity", "collapse_ratio", "sign", "collapse_floor", "contact_duration")
(
    S_XMIN, S_YMIN, S_XMAX, S_YMAX, S_ELASTICITY, S_COLLAPSE_RATIO, S_SIGN, S_COLLAPSE_FLOOR, S_CONTACT_DURATION,
) = range(9)  # fmt: skip

#: Scene ints: a border exists; ball pairs are modelled; the dimension (1 or 2); stick clusters
#: are formed; the cap on events per step (exact mode); sub-steps per step (the cheap modes).
SCENE_I = ("has_walls", "pairs", "dim", "sticky", "max_events", "substeps")
S_HAS_WALLS, S_PAIRS, S_DIM, S_STICKY, S_MAX_EVENTS, S_SUBSTEPS = range(6)

#: Per-scene work floats: the length of the current step, and the time left of it once it ends
#: (more than 0 only at the event cap); how far into the step a scene that found the impact buffer
#: full got (exact mode: the next call resumes it there, so a step's arithmetic does not depend on
#: the buffer's size or the batch); start time of the current sub-step (cheap modes); the grid's
#: origin and cell sizes (exact mode); the event queue's time buckets: the step time where bucket 0
#: starts, and their width (s).
WORK_F = (
    "remaining", "stalled_at", "substep_start", "grid_x0", "grid_y0", "grid_hx", "grid_hy", "queue_base",
    "queue_width",
)  # fmt: skip
(
    W_REMAINING, W_STALLED_AT, W_SUBSTEP_START, W_GRID_X0, W_GRID_Y0, W_GRID_HX, W_GRID_HY, W_QUEUE_BASE,
    W_QUEUE_WIDTH,
) = range(9)  # fmt: skip

#: Per-scene work ints: events in the current step; the scene still has work in this step; it
#: stopped because the impact buffer was full; sub-steps done (cheap modes); the calendar holds
#: valid predictions (0 after anything that changes a scene wholesale: a reset, ``set_state``);
#: the grid's cells along x and y; the event queue: the bucket last moved into its heap, the bucket
#: at which its far list is next sorted into buckets, how many events its heap, its buckets
#: and its far list hold, and the place in the ring of the bucket after the last one moved.
WORK_I = (
    "events", "active", "stalled", "substeps_done", "calendar_valid", "grid_nx", "grid_ny", "queue_bucket",
    "queue_release", "queue_heap", "queue_ring", "queue_far", "queue_next",
)  # fmt: skip
(
    W_EVENTS, W_ACTIVE, W_STALLED, W_SUBSTEPS_DONE, W_CALENDAR_VALID, W_GRID_NX, W_GRID_NY, W_QUEUE_BUCKET,
    W_QUEUE_RELEASE, W_QUEUE_HEAP, W_QUEUE_RING, W_QUEUE_FAR, W_QUEUE_NEXT,
) = range(13)  # fmt: skip

#: One row per impact, as ``BatchSimulator.step`` returns them (the kernels write them).
IMPACT_DTYPE = np.dtype(
    [
        ("scene", np.int64),
        ("time", np.float64),
        ("ball", np.int64),
        ("other", np.int64),  # -1: a wall
        ("wall", np.int64),  # index into WALL_NAMES, -1: another ball
        ("x", np.float64),
        ("y", np.float64),
        ("speed", np.float64),  # normal closing speed just before the impact
        ("impulse", np.float64),  # normal impulse (N s): see collision_env.engine.impacts
    ]
)

#: A ball's rigid-body kinematics (``motion.body_kinematics``), as exact mode's conservative
#: advancement of rotating clusters takes it (float64): the centre of mass of the ball's cluster (m)
#: and its velocity (m/s), the ball's offset from it (m), and the cluster's angular velocity (rad/s).
KINEMATICS = ("cx", "cy", "vx", "vy", "dx", "dy", "omega")
K_CX, K_CY, K_VX, K_VY, K_DX, K_DY, K_OMEGA = range(7)

#: Work counters (``BatchSimulator.stats``), int64: pair predictions (or overlap tests), wall
#: predictions, events, rotating-cluster predictions, grid-cell crossings, stale calendar entries
#: re-predicted.
COUNTERS = ("pair_tests", "wall_tests", "events", "cluster_tests", "cell_crossings", "stale_events")
PAIR_TESTS, WALL_TESTS, EVENTS, CLUSTER_TESTS, CELL_CROSSINGS, STALE_EVENTS = range(6)

#: A frames run's request and result (int64): the frames to record (``first`` up to ``last``), the
#: impact rows written so far, and, when the run returns, the frame it stopped at and whether that
#: frame's step was taken (its impacts did not fit) or needs the caller to complete it.
FRAME_FIELDS = ("first", "last", "rows", "stopped_at", "stepped")
FRAME_FIRST, FRAME_LAST, FRAME_ROWS, FRAME_STOPPED_AT, FRAME_STEPPED = range(5)

#: Every packed layout indexed by column constants, by name (for documentation and the layout test);
#: the calendar record, :data:`CAL_RECORD`, names its fields in its dtype.
LAYOUTS = {
    "BALL": BALL,
    "CAL_I": CAL_I,
    "HEAP": HEAP,
    "SCENE_F": SCENE_F,
    "SCENE_I": SCENE_I,
    "WORK_F": WORK_F,
    "WORK_I": WORK_I,
    "KINEMATICS": KINEMATICS,
    "COUNTERS": COUNTERS,
    "FRAME_FIELDS": FRAME_FIELDS,
}
