"""A step's impacts: :class:`Impacts`, a sequence of :class:`Impact` backed by one structured array.

The kernels write every impact as a row of :data:`~collision_env.engine.IMPACT_DTYPE`;
:meth:`Simulator.step <collision_env.engine.Simulator.step>`, :meth:`Simulator.frames
<collision_env.engine.Simulator.frames>` and the envs' ``info["impacts"]`` hand that array over
as an :class:`Impacts`, which makes an :class:`Impact` only for the rows asked for, so a step of
10^5 disks costs no Python object per impact.

**No copy.** An exact-mode step's records are handed over as they were written: a view of the
simulator's impact buffer, whose rows its kernel never writes again (once half the buffer is used,
recording goes on in a new one). So they stay as they are through every later step, for as long as
anyone holds them, who holds with them the buffer they lie in (4,096 records, 295 kB, for most
scenes; more for steps with more impacts): copy the few records of a step kept for long while
the simulator runs on (:func:`copy_records`, as the envs do for their ``info["impacts"]``). The
cheap modes' records are sorted into a copy.

**Impulse.** ``impulse`` is the normal impulse of the impact (N s): the magnitude of the momentum
change along the normal (the line of centres, or the wall's normal), of either ball of a pair (the
two are equal and opposite), or of the ball at a wall, ``m |Δv_n|``. With the balls' inverse
masses ``w`` and the separation speed ``u'`` the response left (``e u``, or the collapse
regulariser's ``u_min``, see :mod:`collision_env.engine.physics.response`):
``J = (u + u') / (w_i + w_j)`` between balls, ``J = (u + u') / w_i`` at a wall.

- In a contact group resolved at one instant (exact mode, e < 1), each contact is reported once,
  with the closing speed and the impulse of the first impulse it takes; further impulses at the
  same instant (the group's later sweeps) are not added. Where the group's cascade is replaced by
  its limit (``exact.contacts.settle``), a contact first reported there carries the two-body
  impulse ``(u + u') / (w_i + w_j)`` of its closing speed before and separation speed ``u'``
  after the limit. So the group's later impulses, the collapse regulariser's push-apart among
  them, are not in the report: a contact's impulses reported over a step are at most the momentum
  it passes in that step, and all of it outside contact groups (an isolated impact's report
  includes the push-apart: ``u' = u_min``).
- In stick scenes (``inelastic="stick"``) the impulse is the plastic one of the bodies as point
  masses, at the recorded closing speed ``u`` of the contact: ``u / (1/M_i + 1/M_j)`` for two
  bodies (clusters) of masses ``M_i``, ``M_j`` that stick, ``M u`` for a body that stops dead at a
  wall; a spinning cluster's rotation and the tangential momentum a stop removes are not counted.

The sum of ``impulse`` over a run's wall impacts, divided by the time and the wall length, is the
mechanical pressure on the walls (see :mod:`collision_env.observables`).
"""

from __future__ import annotations

import numbers
from collections.abc import Iterator, Sequence
from typing import NamedTuple, overload

import numpy as np
from numpy.typing import DTypeLike

from .physics.walls import WALL_NAMES

#: Rows converted to :class:`Impact` at a time while iterating (so a long run's iteration holds
#: no list of every impact).
_CHUNK = 4096


class Impact(NamedTuple):
    """One collision inside a step (a named tuple: cheap to make, immutable)."""

    time: float  #: absolute simulation time (s)
    ball: int  #: index of the ball
    other: int | None  #: index of the other ball, or None for a wall
    wall: str | None  #: "left" | "right" | "bottom" | "top", or None for a ball-ball impact
    point: tuple[float, float]  #: contact point (m)
    speed: float  #: normal closing speed just before the impact (m/s)
    impulse: float  #: normal impulse (N s), see :mod:`collision_env.engine.impacts`


def copy_records(rows: np.ndarray) -> np.ndarray:
    """A copy of impact records ``rows`` (C-contiguous), in memory of its own: for records kept
    long, so that they do not keep alive the impact buffer a step's records are a view of (numpy
    copies structured arrays slowly, and a structured array's buffer describes its fields in a format
    string each time: a byte copy of its bytes, 0.75 us for 50 records, is several times cheaper)."""
    return np.ndarray(len(rows), rows.dtype, bytearray(rows.view(np.uint8)))


def _impact(row: tuple) -> Impact:
    """The :class:`Impact` of one record (a row of ``IMPACT_DTYPE`` as ``tolist`` gives it)."""
    _, t, ball, other, wall, x, y, speed, impulse = row
    return Impact(t, ball, None if other < 0 else other, None if wall < 0 else WALL_NAMES[wall], (x, y), speed, impulse)


class Impacts(Sequence):
    """The impacts of a step (or of a run of frames), in order: a read-only sequence of
    :class:`Impact` over one structured array of :data:`~collision_env.engine.IMPACT_DTYPE`.

    - ``len(impacts)``, ``impacts[k]`` (an :class:`Impact`, made on demand), iteration;
    - ``impacts[a:b]``, ``impacts[mask]``, ``impacts[indices]``: an :class:`Impacts` of those rows;
    - ``impacts["time"]`` (any field of the dtype): that column as an array, as is
      ``impacts.point`` (``(n, 2)``), and ``impacts.wall_names`` the wall names (None for a
      ball-ball impact);
    - ``impacts.array``: the structured array itself (``scene``, ``time``, ``ball``, ``other``
      (-1 for a wall), ``wall`` (index into ``WALL_NAMES``, -1 for a ball), ``x``, ``y``,
      ``speed``, ``impulse``), which is also what numpy makes of it (``np.asarray(impacts)``,
      ``np.concatenate``); ``impacts.to_list()``: every :class:`Impact` in a list;
    - ``impacts.for_scene(i)``: the impacts of scene ``i`` of a batch (the sub-env of a vector env).

    Equality: with another :class:`Impacts`, the records compare (so env infos compare with
    Gymnasium's ``data_equivalence``); with a list or tuple, the :class:`Impact` tuples do
    (``sim.step(dt) == []`` is a step without impacts).

    >>> from collision_env.engine import Scene, Simulator
    >>> sim = Simulator(Scene(bounds=(-1.0, -1.0, 1.0, 1.0)), [[0.0, 0.0]], [[1.0, 0.0]], [2.0], [0.25])
    >>> imp = sim.step(1.0)
    >>> len(imp), imp[0].wall, imp[0].time, imp[0].impulse, imp["impulse"].tolist()
    (1, 'right', 0.75, 4.0, [4.0])
    """

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray) -> None:
        self.array = array
        """The records, a structured array of ``IMPACT_DTYPE`` (a view: no copy is made)."""

    def __len__(self) -> int:
        return len(self.array)

    def __array__(self, dtype: DTypeLike | None = None, copy: bool | None = None) -> np.ndarray:
        """The records (``np.asarray(impacts)`` is ``impacts.array``; numpy's functions take an
        :class:`Impacts` as the structured array it holds)."""
        if copy:
            return np.array(self.array, dtype=dtype, copy=True)
        return self.array if dtype is None else self.array.astype(dtype, copy=False)

    @overload
    def __getitem__(self, key: int) -> Impact: ...
    @overload
    def __getitem__(self, key: str) -> np.ndarray: ...
    @overload
    def __getitem__(self, key: slice | np.ndarray | Sequence[int]) -> Impacts: ...
    def __getitem__(self, key):
        if isinstance(key, str):
            return self.array[key]
        if isinstance(key, numbers.Integral) and not isinstance(key, (bool, np.bool_)):
            return _impact(self.array[key].tolist())
        rows = self.array[key]
        if rows.ndim != 1:  # (None, a boolean scalar or a 2-D index would make a 2-D array of records)
            raise TypeError(
                "impacts: index with an integer, a slice, a field name, a bool mask of the impacts or "
                f"a 1-D array of indices, got {key!r}"
            )
        return Impacts(rows)

    def __iter__(self) -> Iterator[Impact]:
        a = self.array
        for start in range(0, len(a), _CHUNK):
            yield from map(_impact, a[start : start + _CHUNK].tolist())

    def to_list(self) -> list[Impact]:
        """Every impact as an :class:`Impact`, in order."""
        return list(map(_impact, self.array.tolist()))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Impacts):
            a, b = self.array, other.array
            return a.dtype == b.dtype and a.shape == b.shape and bool(np.all(a == b))
        if isinstance(other, (list, tuple)):
            return len(self) == len(other) and self.to_list() == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # (mutable contents: not hashable, as a list)

    @property
    def point(self) -> np.ndarray:
        """``(n, 2)`` contact points (m)."""
        return np.stack([self.array["x"], self.array["y"]], axis=-1)

    @property
    def wall_names(self) -> list[str | None]:
        """The wall of each impact by name, None for a ball-ball impact."""
        return [WALL_NAMES[w] if w >= 0 else None for w in self.array["wall"].tolist()]

    def for_scene(self, scene: int) -> Impacts:
        """The impacts of scene ``scene`` of a batch."""
        return Impacts(self.array[self.array["scene"] == scene])

    def __repr__(self) -> str:
        return f"Impacts({len(self.array)} impacts)"


class BufferRows(Impacts):
    """:class:`Impacts` of rows ``first`` to ``end`` of an impact buffer (a simulator's step, see
    ``Stepper.step``), whose view of them, its :attr:`array`, is made at the first look: a loop of
    steps that never looks at their impacts (a loop of frames from Python) does not pay for the
    view. The rows are the buffer's for good (its kernel never writes them again), so a late look
    sees what an early one would have. A copy or a pickle is an :class:`Impacts` of the rows alone,
    without the buffer."""

    __slots__ = ("_buffer", "_first", "_end", "_rows")

    def __init__(self, buffer: np.ndarray, first: int, end: int) -> None:
        self._buffer: np.ndarray | None = buffer
        self._first = first
        self._end = end

    @property
    def array(self) -> np.ndarray:
        """The records, a structured array of ``IMPACT_DTYPE`` (a view of the buffer's rows)."""
        buffer = self._buffer
        if buffer is not None:  # (the first look: the view, which holds the buffer from then on)
            self._rows = buffer[self._first : self._end]
            self._buffer = None
        return self._rows

    @array.setter
    def array(self, rows: np.ndarray) -> None:
        self._rows = rows
        self._buffer = None

    def __reduce__(self) -> tuple:
        return Impacts, (self.array,)
