"""Keyword checks that name the closest known keyword, as a mistyped env id's error does."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class UnknownKeywordError(TypeError, ValueError):
    """A keyword that the call does not take. A ``TypeError``, as for any call, and a ``ValueError``,
    as every other bad argument of the engine and of ``gym.make`` is."""


def check_keywords(given: Iterable[str], known: Iterable[str]) -> None:
    """Raise :class:`UnknownKeywordError` for any name of ``given`` not in ``known``, suggesting the
    closest known names (``difflib.get_close_matches``).

    >>> check_keywords(["substep"], ["mode", "substeps", "max_events"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    collision_env...UnknownKeywordError: ... 'substep' (did you mean 'substeps'?); known: [...]
    """
    known = sorted(known)
    unknown = sorted(set(given) - set(known))
    if not unknown:
        return
    named = []
    for name in unknown:
        close = difflib.get_close_matches(str(name), known, n=2)
        hint = f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""
        named.append(f"{name!r}{hint}")
    raise UnknownKeywordError(f"unexpected keyword argument(s) {', '.join(named)}; known: {known}")
