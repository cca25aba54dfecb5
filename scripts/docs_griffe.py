"""A griffe extension for the API reference (mkdocs.yml, mkdocstrings ``extensions:``): the
docstrings are prose, with doctest examples and, in two engine classes, a numpydoc ``Parameters``
section followed by prose.

* A run of doctest lines (``>>>`` and its output, up to a blank line) becomes a ``pycon`` code
  block, so that Markdown reads neither ``[1.5]`` as a link nor ``**`` as emphasis.
* Prose after a ``Parameters`` section, set off by a blank line and not indented, is not a
  parameter: it goes under a ``Notes`` heading (numpydoc ends a section only at the next heading).
"""

from __future__ import annotations

import re

import griffe

PARAMETER = re.compile(r"^[\w*]+(, *[\w*]+)*\s*(:.*)?$")  # "name:", "a, b:", "name : type"
HEADING = re.compile(r"^-{3,}$")


def fence_doctests(lines: list[str]) -> list[str]:
    out, i = [], 0
    while i < len(lines):
        if not lines[i].lstrip().startswith(">>>"):
            out.append(lines[i])
            i += 1
            continue
        indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
        out.append(f"{indent}```pycon")
        while i < len(lines) and lines[i].strip():
            out.append(lines[i])
            i += 1
        out.append(f"{indent}```")
    return out


def end_parameter_sections(lines: list[str]) -> list[str]:
    out, in_parameters = [], False
    for i, line in enumerate(lines):
        is_heading = i + 1 < len(lines) and HEADING.match(lines[i + 1].strip()) and line.strip()
        if is_heading:
            in_parameters = line.strip() == "Parameters"
        elif (
            in_parameters
            and line.strip()
            and not line.startswith((" ", "\t"))
            and not HEADING.match(line.strip())
            and i > 0
            and not lines[i - 1].strip()
            and not PARAMETER.match(line)
        ):
            out += ["Notes", "-----"]
            in_parameters = False
        out.append(line)
    return out


class ProseDocstrings(griffe.Extension):
    """Applies :func:`fence_doctests` and :func:`end_parameter_sections` to every docstring."""

    def on_object(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.docstring is not None:
            lines = obj.docstring.value.split("\n")
            obj.docstring.value = "\n".join(end_parameter_sections(fence_doctests(lines)))
