"""A time-of-impact-correct 2D/1D ball collision engine modelled on PhET's Collision Lab.

>>> from collision_env.engine import Scene, Simulator
>>> sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5])
>>> [round(i.time, 6) for i in sim.step(2.0)]
[1.088256]

See :class:`Simulator` (one scene) and :class:`BatchSimulator` (many scenes at once, one engine).
numba compiles the kernels at their first call and caches them on disk; ``python -m
collision_env.precompile`` compiles them all ahead (:func:`collision_env.precompile.precompile`).
"""

from ._jit import BACKEND
from .batch import BatchSimulator, Frames
from .chains import EventChains, EventChainWarning, event_chain
from .compression import CompressionWarning, Packing, compress
from .gas import Gas, disk_gas
from .impacts import Impact, Impacts
from .keywords import UnknownKeywordError
from .layout import IMPACT_DTYPE
from .modes import MODES
from .scene import BALL_DENSITY, CONSTANT_RADIUS, PLAY_AREA_1D, PLAY_AREA_2D, WALL_NAMES, Scene, radius_from_mass
from .simulator import Simulator
from .snapshot import SimulatorState
from .stepper import EventCapWarning
from .validation import MAX_SUBSTEPS

__all__ = [
    "BACKEND",
    "BALL_DENSITY",
    "CONSTANT_RADIUS",
    "IMPACT_DTYPE",
    "MAX_SUBSTEPS",
    "MODES",
    "PLAY_AREA_1D",
    "PLAY_AREA_2D",
    "WALL_NAMES",
    "BatchSimulator",
    "CompressionWarning",
    "EventCapWarning",
    "EventChainWarning",
    "EventChains",
    "Frames",
    "Gas",
    "Impact",
    "Impacts",
    "Packing",
    "Scene",
    "Simulator",
    "SimulatorState",
    "UnknownKeywordError",
    "compress",
    "disk_gas",
    "event_chain",
    "radius_from_mass",
]
