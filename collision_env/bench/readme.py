"""Generated blocks in the README and the docs pages: every figure there is written by a script,
between markers.

A block named ``name`` sits between ``<!-- name:start -->`` and ``<!-- name:end -->``; the
benchmark and study scripts rewrite only what lies between their own markers. Every report
script ends in :func:`write_outputs`: the table printed, the raw figures as JSON, the table as a
page or a page's block.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


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


def write_page_block(path: str | Path, name: str, text: str, title: str) -> None:
    """Put ``text`` between block ``name``'s markers in the docs page ``path``: replaced where they
    are, added at the end where they are not, the page made (headed ``title``) where it is missing."""
    p = Path(path)
    if p.exists() and replace_block(p, name, text):
        return
    start, end = markers(name)
    head = p.read_text().rstrip("\n") + "\n\n" if p.exists() else title + "\n\n"
    p.write_text(f"{head}{start}\n{text.rstrip()}\n{end}\n")


def write_outputs(
    text: str,
    results: Any = None,
    *,
    json_path: str | Path | None = None,
    markdown: str | Path | None = None,
    title: str | None = None,
    block: str | None = None,
    indent: int = 1,
    echo: bool = True,
) -> None:
    """The output tail of every report script (``--json``, ``--markdown``, ``--readme``).

    Prints ``text`` (unless not ``echo``); writes ``results`` as JSON to ``json_path`` (when both are given); and writes
    ``text`` to the page ``markdown``: without ``block`` as the whole page, under the heading
    ``title`` when given; with ``block`` between that block's markers, where a page missing them
    is left unchanged (saying so) unless ``title`` is given, which adds the block (and makes the
    page under ``title`` if there is none: :func:`write_page_block`).
    """
    if echo:
        print(text)
    if json_path and results is not None:
        Path(json_path).write_text(json.dumps(results, indent=indent) + "\n")
    if not markdown:
        return
    if block is None:
        Path(markdown).write_text((f"{title}\n\n" if title else "") + text.rstrip("\n") + "\n")
    elif title is None:
        write_block(markdown, block, text)
    else:
        write_page_block(markdown, block, text, title)
