"""What a measurement ran on: the machine, the CPUs it may use, the versions of what it measured.

Every benchmark and study stamps its output with these, so that a figure can be traced to its run.
"""

from __future__ import annotations

import importlib
import os
import platform
import time
from collections.abc import Iterable


def cpus() -> int:
    """CPUs this process may run on (its affinity mask where the OS has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - macOS and Windows have no affinity mask
        return os.cpu_count() or 1


def machine() -> str:
    """``"x86_64 Linux"``: the processor architecture and the OS."""
    return f"{platform.machine()} {platform.system()}"


def timestamp() -> str:
    """Local date and time to the minute, as the generated tables print it."""
    return time.strftime("%Y-%m-%d %H:%M")


def module_version(name: str) -> str | None:
    """The version of module ``name`` as a plain string, or None if it is not installed."""
    try:
        module = importlib.import_module(name)
    except ImportError:
        return None
    return str(getattr(module, "__version__", getattr(module, "version", "?")))


def versions(modules: Iterable[str] = ()) -> dict[str, str | None]:
    """Python, numpy, this package, the engine's backend, and each of ``modules`` (None: not installed).

    >>> v = versions(["no_such_module"])
    >>> v["no_such_module"] is None and v["backend"] in ("numba", "python")
    True
    """
    import collision_env
    from collision_env.engine import BACKEND

    out: dict[str, str | None] = {
        "python": platform.python_version(),
        "numpy": module_version("numpy"),
        "collision_env": collision_env.__version__,
        "backend": BACKEND,
    }
    out.update((name, module_version(name)) for name in modules)
    return out
