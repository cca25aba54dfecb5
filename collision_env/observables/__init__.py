"""Observables of a hard-disk gas, from the engine's impacts, positions and velocities.

Each function states its formula and its source. Units are SI, ``kT`` in J (the engine has no
Boltzmann constant: ``kT`` is an energy), ``N`` is the number of disks, ``A`` the box's area.

- :mod:`~collision_env.observables.pressure`: the :func:`temperature` a scene has (a periodic
  cell's conserved momentum counted), the pressure from the collision virial
  (:func:`collision_virial`, :func:`reduced_pressure`) and on the walls (:func:`wall_pressure`),
  the :func:`collision_rate` and :func:`mean_free_time`, and :class:`PressureAccumulator`, which
  takes a run frame after frame and gives the pressure with its standard error;
- :mod:`~collision_env.observables.statistics`: means of correlated samples with their standard
  errors, by block averaging (:func:`block_average`, :class:`Blocking`);
- :mod:`~collision_env.observables.structure`: g(r) (:func:`radial_distribution`, O(N) memory
  through a cell list, in a box or a periodic cell) and the mean squared displacement
  (:func:`mean_squared_displacement`, :func:`unwrapped_positions`);
- :mod:`~collision_env.observables.order`: the hexatic order (:func:`hexatic_order`,
  :func:`global_hexatic_order`) and its correlation (:func:`hexatic_correlation`), through freud
  (the ``analysis`` extra);
- :mod:`~collision_env.observables.reference`: what the hard-disk fluid is known to do, to compare
  with: the equation of state (:func:`kolafa_rottner_z`, :func:`henderson_z`), the contact value
  :func:`henderson_g`, Enskog's collision rate :func:`enskog_rate`, and event-chain pressures of
  small periodic cells (:func:`li_2022_pressures`).

Every name is importable from ``collision_env.observables`` itself. Impacts are
:class:`~collision_env.engine.Impacts` or their structured arrays
(:data:`~collision_env.engine.IMPACT_DTYPE`), of one scene, over a run of ``duration`` seconds
(``Simulator.frames(dt, n).impacts`` of a run of ``n * dt`` seconds, say).

>>> import numpy as np
>>> from collision_env.engine import Scene, Simulator
>>> from collision_env.observables import collision_rate, reduced_pressure
>>> sim = Simulator(Scene(bounds=None), [[-1.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [-1.0, 0.0]], [1.0, 1.0], [0.5, 0.5])
>>> imp = sim.step(2.0)  # one head-on collision: impulse 2 N s at contact distance 1 m
>>> reduced_pressure(imp, sim.radii, 2.0, sim.kinetic_energy(), scene=sim.scene), collision_rate(imp, 2, 2.0)
(1.25, 0.5)
"""

from .order import SHORTEST_EDGE, global_hexatic_order, hexatic_correlation, hexatic_order
from .pressure import (
    PressureAccumulator,
    collision_rate,
    collision_virial,
    mean_free_time,
    reduced_pressure,
    temperature,
    wall_pressure,
)
from .reference import (
    KOLAFA_ROTTNER,
    KOLAFA_ROTTNER_MAX,
    LI_2022,
    LI_2022_CELLS,
    CellPressures,
    enskog_rate,
    henderson_g,
    henderson_z,
    kolafa_rottner_z,
    li_2022_pressures,
)
from .statistics import BlockAverage, Blocking, block_average
from .structure import PAIR_CHUNK, mean_squared_displacement, radial_distribution, unwrapped_positions

__all__ = [
    "KOLAFA_ROTTNER",
    "KOLAFA_ROTTNER_MAX",
    "LI_2022",
    "LI_2022_CELLS",
    "PAIR_CHUNK",
    "SHORTEST_EDGE",
    "BlockAverage",
    "Blocking",
    "CellPressures",
    "PressureAccumulator",
    "block_average",
    "collision_rate",
    "collision_virial",
    "enskog_rate",
    "global_hexatic_order",
    "henderson_g",
    "henderson_z",
    "hexatic_correlation",
    "hexatic_order",
    "kolafa_rottner_z",
    "li_2022_pressures",
    "mean_free_time",
    "mean_squared_displacement",
    "radial_distribution",
    "reduced_pressure",
    "temperature",
    "unwrapped_positions",
    "wall_pressure",
]
