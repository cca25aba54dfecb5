"""Keyword checks that name the closest known keyword, as a mistyped env id's error does."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class UnknownKeywordError(TypeError, ValueError):
    """A keyword that the call does not take. A ``TypeError``, as for any call, and a ``ValueError``,
    as every other bad argument of the engine and of ``gym.make`` is."""


def _closest(name: str, known: list[str]) -> list[str]:
    """Up to three of the ``known`` names closest to ``name`` (``difflib.get_close_matches``)."""
    return difflib.get_close_matches(str(name), known, n=3)


def close_matches(given: Iterable[str], known: Iterable[str]) -> str:
    """``given`` names, each quoted with up to three of the ``known`` names closest to it:
    ``"'substep' (did you mean 'substeps'?)"``."""
    known = sorted(known)
    named = []
    for name in given:
        close = _closest(name, known)
        hint = f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""
        named.append(f"{name!r}{hint}")
    return ", ".join(named)


def check_keywords(given: Iterable[str], known: Iterable[str]) -> None:
    """Raise :class:`UnknownKeywordError` for any name of ``given`` not in ``known``, suggesting up
    to three of the closest known names (:func:`close_matches`).

    >>> check_keywords(["substep"], ["mode", "substeps", "max_events"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    collision_env...UnknownKeywordError: unexpected keyword argument(s) 'substep' (did you mean 'substeps'?)
    """
    known = sorted(known)
    unknown = sorted(set(given) - set(known))
    if not unknown:
        return
    message = f"unexpected keyword argument(s) {close_matches(unknown, known)}"
    if not any(_closest(name, known) for name in unknown):
        message += f"; none of the {len(known)} keywords the call takes is close"
    raise UnknownKeywordError(message)
