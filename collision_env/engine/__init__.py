"""A time-of-impact-correct 2D/1D ball collision engine modelled on PhET's Collision Lab.

>>> from collision_env.engine import Scene, Simulator
>>> sim = Simulator(Scene(bounds=None), [[-1, 0], [1, 0]], [[1, 0], [-0.5, 0]], [0.5, 1.5])
>>> [round(i.time, 6) for i in sim.step(2.0)]
[1.088256]

See :class:`Simulator` (one scene) and :class:`BatchSimulator` (many scenes at once, one engine).
"""

from ._jit import BACKEND
from .batch import BatchSimulator, Frames
from .chains import EventChains, EventChainWarning, event_chain
from .compression import CompressionWarning, Packing, compress
from .gas import Gas, disk_gas
from .impacts import Impact, Impacts
from .keywords import UnknownKeywordError
from .layout import IMPACT_DTYPE
from .modes import MODES as _MODE_REGISTRY
from .scene import (
    BALL_DENSITY,
    CONSTANT_RADIUS,
    PLAY_AREA_1D,
    PLAY_AREA_2D,
    WALL_BOTTOM,
    WALL_LEFT,
    WALL_NAMES,
    WALL_RIGHT,
    WALL_TOP,
    Scene,
    radius_from_mass,
)
from .simulator import Simulator, warm_up
from .snapshot import SimulatorState
from .stepper import EventCapWarning
from .validation import MAX_SUBSTEPS

#: The engine's mode names, cheapest first.
MODES = tuple(_MODE_REGISTRY)

__all__ = [
    "BACKEND",
    "BALL_DENSITY",
    "CONSTANT_RADIUS",
    "IMPACT_DTYPE",
    "MAX_SUBSTEPS",
    "MODES",
    "PLAY_AREA_1D",
    "PLAY_AREA_2D",
    "WALL_BOTTOM",
    "WALL_LEFT",
    "WALL_NAMES",
    "WALL_RIGHT",
    "WALL_TOP",
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
    "warm_up",
]
