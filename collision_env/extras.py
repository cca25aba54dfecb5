"""The optional extras (``pip install "collision_env[render]"``) and the modules each one brings.

The core package needs numpy, gymnasium and numba (which compiles the engine's kernels). A part
that needs more checks for its extra with :func:`require`, which raises :class:`MissingExtra`: a
``ModuleNotFoundError`` whose message names the extra and the command that installs it, in one
line. The command-line entry points print that line alone (no traceback) and exit with status 1.

>>> EXTRAS["render"]
('pygame',)
>>> extra_of("yaml")
'train'
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from typing import Any

#: Extra -> the top-level modules it installs (the import names of its requirements in pyproject.toml).
EXTRAS: dict[str, tuple[str, ...]] = {
    "train": ("stable_baselines3", "torch", "tqdm", "rich", "tensorboard", "yaml", "imageio"),
    "video": ("imageio_ffmpeg",),
    "render": ("pygame",),
    "plot": ("matplotlib",),
    "analysis": ("freud", "gsd"),
    "peers": ("billiards", "pymunk"),
    "test": ("pytest", "xdist", "hypothesis"),
    "dev": ("ruff", "mypy", "yaml-stubs", "build", "twine", "cffconvert"),  # (yaml-stubs: types-PyYAML)
    "docs": ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers"),
    "distributed": ("ray", "torch", "yaml"),
}

#: Extras that pull torch: on a machine without a GPU, torch's CPU build goes in first.
TORCH_EXTRAS = ("train", "distributed")


class MissingExtra(ModuleNotFoundError):
    """A module of an optional extra is not installed; the message says which extra installs it."""

    def __init__(self, extra: str, module: str, who: str, checkout: bool = False) -> None:
        target = f'-e ".[{extra}]"' if checkout else f'"collision_env[{extra}]"'
        torch = " (torch's CPU build first on a machine without a GPU: see the README)" if extra in TORCH_EXTRAS else ""
        super().__init__(f"{who} needs the '{extra}' extra ({module} is missing): pip install {target}{torch}")
        self.name = module
        """The missing module (as ``ModuleNotFoundError.name``)."""
        self.extra = extra
        """The extra that installs it."""


def _missing(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is None
    except ValueError:  # a module in sys.modules without a spec: it is there
        return False


def require(extra: str, who: str, checkout: bool = False, modules: tuple[str, ...] | None = None) -> None:
    """Raise :class:`MissingExtra` if a module of ``extra`` (or of those ``modules`` of it) is not installed.

    ``who`` names what needs it (``"rendering"``, ``"agents.train_ppo"``); ``checkout``: the install
    command is the checkout's editable one (``pip install -e ".[train]"``), for the parts that run
    from a clone of the repository only.
    """
    if extra not in EXTRAS:
        raise ValueError(f"extra: expected one of {sorted(EXTRAS)}, got {extra!r}")
    if modules is not None and not set(modules) <= set(EXTRAS[extra]):
        raise ValueError(f"modules: {modules!r} are not all modules of the {extra!r} extra {EXTRAS[extra]}")
    for module in EXTRAS[extra] if modules is None else modules:
        if _missing(module):
            raise MissingExtra(extra, module, who, checkout)


def extra_of(module: str, prefer: tuple[str, ...] = ()) -> str | None:
    """The extra that installs the top-level module of ``module``: the first of ``prefer`` that does,
    else the first in the order of :data:`EXTRAS` (``None``: no extra does)."""
    top = module.partition(".")[0]
    return next((extra for extra in (*prefer, *EXTRAS) if top in EXTRAS.get(extra, ())), None)


def run_entry_point(
    main: Callable[[], Any], who: str, extras: tuple[str, ...] = (), checkout: bool = False, status: int = 1
) -> Any:
    """Run a command-line entry point: check its ``extras`` first, and report a missing extra, then or
    during the run, as one line on stderr (exit ``status``) instead of a traceback.

    A ``ModuleNotFoundError`` of a module that no extra installs is a bug, not a missing extra: it
    propagates.
    """
    try:
        for extra in extras:
            require(extra, who, checkout)
        return main()
    except MissingExtra as err:
        print(err, file=sys.stderr)
    except ModuleNotFoundError as err:
        module = err.name or ""
        missing = extra_of(module, prefer=extras)
        if missing is None:
            raise
        print(MissingExtra(missing, module, who, checkout), file=sys.stderr)
    raise SystemExit(status)
