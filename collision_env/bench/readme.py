"""Generated blocks in the README and the docs pages: every figure there is written by a script,
between markers.

A block named ``name`` sits between ``<!-- name:start -->`` and ``<!-- name:end -->``; the
benchmark and study scripts rewrite only what lies between their own markers.
"""

from __future__ import annotations

from pathlib import Path


def markers(name: str) -> tuple[str, str]:
    return f"<!-- {name}:start -->", f"<!-- {name}:end -->"


def replace_block(path: str | Path, name: str, block: str) -> bool:
    """Replace the text between block ``name``'s markers in ``path``; False if they are missing."""
    start_mark, end_mark = markers(name)
    p = Path(path)
    text = p.read_text()
    start = text.find(start_mark)
    end = text.find(end_mark)
    if start < 0 or end < 0 or end < start:
        return False
    p.write_text(text[: start + len(start_mark)] + "\n" + block.rstrip("\n") + "\n" + text[end:])
    return True


def write_block(path: str | Path, name: str, block: str) -> None:
    """:func:`replace_block`, saying on stdout what happened."""
    if replace_block(path, name, block):
        print(f"{path}: {name} block updated")
    else:
        start_mark, end_mark = markers(name)
        print(f"{path} has no {start_mark} ... {end_mark} markers: left unchanged")
