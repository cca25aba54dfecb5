"""The peer engines measured beside this one: one class per peer, one file per class.

Each is a :class:`~collision_env.bench.peers.base.Runner`: it sets itself up on a benchmark case,
steps, reports impacts and says (:meth:`~collision_env.bench.peers.base.Runner.unsupported`) what
it cannot do. Every benchmark builds its peers from :data:`PEERS`, so a figure called "pymunk" is
always the same pymunk set-up. A peer's package is imported when the class is instantiated: an
``ImportError`` then means it is not installed (``pip install 'collision_env[peers]'``).

To add a peer: a module here with one ``Runner`` subclass, and an entry in :data:`PEERS`.
"""

from __future__ import annotations

from typing import Any

from .base import Runner, collect
from .billiards import BilliardsRunner
from .pymunk import PymunkRunner

#: peer name -> its runner class
PEERS: dict[str, type[Runner]] = {"pymunk": PymunkRunner, "billiards": BilliardsRunner}


def make_peer(name: str, **knobs: Any) -> Runner | str:
    """Peer ``name`` at ``knobs``, or a string saying why it is not available."""
    try:
        return PEERS[name](**knobs)
    except ImportError as exc:
        return f"not installed ({exc})"


__all__ = ["PEERS", "BilliardsRunner", "PymunkRunner", "Runner", "collect", "make_peer"]
