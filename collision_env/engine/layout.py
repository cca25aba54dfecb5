"""Named layouts of the engine's packed arrays: every field of every packed array, in one place.

The kernels take a handful of packed arrays instead of dozens of small ones, because every array
handed to a compiled function costs about 0.1 us per call (a one-ball step is a few us). Each
packed array's last axis is laid out by one of the field tuples below, and the kernels read it
through the index constants defined next to it, never by bare numbers. A test checks that each
tuple and its constants agree.

Per ball, ``(B, N, len(fields))``:

- :data:`BALL` (float64): the physical state, see :mod:`collision_env.engine.motion`.
- :data:`CAL_F` / :data:`CAL_I` (float64 / int64): exact mode's persistent event calendar and
  cell grid, see :mod:`collision_env.engine.calendar` and :mod:`collision_env.engine.grid`;
  :data:`HEAP` (float64): the calendar's event queue.

Per scene:

- :data:`SCENE_F` / :data:`SCENE_I`: the parameters every scene of a batch shares (one vector
  each, set from the :class:`~collision_env.engine.Scene` and the simulator's options).
- :data:`WORK_F` / :data:`WORK_I` (``(B, len(fields))``): per-scene bookkeeping of a step and the
  grid's geometry.
"""

from __future__ import annotations

#: Per-ball physical state: centre (m), velocity (m/s), mass (kg), its inverse, radius (m), and
#: the angular velocity (rad/s) of the rigid cluster the ball roots (0 unless it roots one).
BALL = ("x", "y", "vx", "vy", "mass", "inv_mass", "radius", "omega")
B_X, B_Y, B_VX, B_VY, B_MASS, B_INV_MASS, B_RADIUS, B_OMEGA = range(8)

#: Per-ball calendar floats: the time of the ball's next event (relative to the step's start);
#: the time its stored position refers to (balls are moved lazily, when an event touches them);
#: the position and velocity it had when the last step ended (a change made between steps, by a
#: nudge or an env, is found by comparing against them).
CAL_F = ("event_time", "ref_time", "seen_x", "seen_y", "seen_vx", "seen_vy")
C_EVENT_TIME, C_REF_TIME, C_SEEN_X, C_SEEN_Y, C_SEEN_VX, C_SEEN_VY = range(6)

#: Per-ball calendar ints: what the next event is (a partner ball >= 0, or an ``calendar.EV_*``
#: code); the partner's change counter when the event was predicted (a mismatch makes the event
#: stale); the ball's own change counter; its slot in the event queue's heap; the ball's grid
#: cell, the next and previous ball in that cell's list; and, in the first ``n_cells`` rows, the
#: first ball of each cell (row c holds cell c's head).
CAL_I = ("event_other", "event_stamp", "changes", "heap_slot", "cell", "cell_next", "cell_prev", "cell_head")
C_EVENT_OTHER, C_EVENT_STAMP, C_CHANGES, C_HEAP_SLOT, C_CELL, C_CELL_NEXT, C_CELL_PREV, C_CELL_HEAD = range(8)

#: The event queue's heap, one row per slot (float64): the event time held there and the ball
#: (an integer stored as a float, so that a node and its children share cache lines).
HEAP = ("time", "ball")
H_TIME, H_BALL = range(2)

#: Scene floats: the border (m; zeros when there is none), the restitution used this step (1/e
#: when running backwards), the collapse regulariser's ratio and floor (m/s), and the direction
#: of time (+1 or -1).
SCENE_F = ("xmin", "ymin", "xmax", "ymax", "elasticity", "collapse_ratio", "sign", "collapse_floor")
S_XMIN, S_YMIN, S_XMAX, S_YMAX, S_ELASTICITY, S_COLLAPSE_RATIO, S_SIGN, S_COLLAPSE_FLOOR = range(8)

#: Scene ints: a border exists; ball pairs are modelled; the dimension (1 or 2); stick clusters
#: are formed; the cap on events per step.
SCENE_I = ("has_walls", "pairs", "dim", "sticky", "max_events")
S_HAS_WALLS, S_PAIRS, S_DIM, S_STICKY, S_MAX_EVENTS = range(5)

#: Per-scene work floats: time left in the current step; start time of the current sub-step
#: (cheap modes); the grid's origin and cell sizes (exact mode).
WORK_F = ("remaining", "substep_start", "grid_x0", "grid_y0", "grid_hx", "grid_hy")
W_REMAINING, W_SUBSTEP_START, W_GRID_X0, W_GRID_Y0, W_GRID_HX, W_GRID_HY = range(6)

#: Per-scene work ints: events in the current step; the scene still has work in this step; it
#: stopped because the impact buffer was full; sub-steps done (cheap modes); the calendar holds
#: valid predictions (0 after anything that changes a scene wholesale: a reset, ``set_state``);
#: the grid's cells along x and y.
WORK_I = ("events", "active", "stalled", "substeps_done", "calendar_valid", "grid_nx", "grid_ny")
W_EVENTS, W_ACTIVE, W_STALLED, W_SUBSTEPS_DONE, W_CALENDAR_VALID, W_GRID_NX, W_GRID_NY = range(7)

#: Every packed layout, by name (for documentation and the layout test).
LAYOUTS = {
    "BALL": BALL,
    "CAL_F": CAL_F,
    "CAL_I": CAL_I,
    "HEAP": HEAP,
    "SCENE_F": SCENE_F,
    "SCENE_I": SCENE_I,
    "WORK_F": WORK_F,
    "WORK_I": WORK_I,
}
