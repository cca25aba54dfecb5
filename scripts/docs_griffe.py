"""A griffe extension for the API reference (mkdocs.yml, mkdocstrings ``extensions:``): the
docstrings are prose, with doctest examples and, in two engine classes, a numpydoc ``Parameters``
section followed by prose; constants and fields are often documented by Sphinx's ``#:`` comments.

* An attribute without a docstring takes its ``#:`` doc comment: the ``#:`` lines just above it, or
  the ``#:`` comment at the end of its line (as Sphinx's autodoc reads them).
* A class member without a docstring takes the one of the same member of a base class in the
  package (an env's ``task``, a subclass's ``reset``), as Python's ``inspect.getdoc`` does; a
  preset's ``FooVectorEnv = register_task(FooEnv)`` is described as what it is.

* A run of doctest lines (``>>>`` and its output, up to a blank line) becomes a ``pycon`` code
  block, so that Markdown reads neither ``[1.5]`` as a link nor ``**`` as emphasis.
* Prose after a ``Parameters`` section, set off by a blank line and not indented, is not a
  parameter: it goes under a ``Notes`` heading (numpydoc ends a section only at the next heading).
"""

from __future__ import annotations

import re
from pathlib import Path

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


def doc_comment(lines: list[str], lineno: int) -> str | None:
    """The ``#:`` doc comment of the statement on line ``lineno`` (1-based) of ``lines``, or None."""
    own = lines[lineno - 1]
    if "#:" in own:
        return own.split("#:", 1)[1].strip() or None
    above: list[str] = []
    for line in reversed(lines[: lineno - 1]):
        if not line.strip().startswith("#:"):
            break
        above.insert(0, line.strip()[2:].strip())
    return "\n".join(above) or None


REGISTERED_VECTOR_ENV = re.compile(r"^register_task\((?P<env>\w+)\)$")


def attribute_doc(obj: griffe.Object) -> str | None:
    """What an attribute without a docstring says: its ``#:`` comment, or for a preset's vector env
    class (``FooVectorEnv = register_task(FooEnv)``) what that is."""
    collection = obj.lines_collection
    if isinstance(obj.filepath, Path) and obj.filepath in collection and obj.lineno is not None:
        text = doc_comment(collection[obj.filepath], obj.lineno)
        if text:
            return text
    match = REGISTERED_VECTOR_ENV.match(str(getattr(obj, "value", "")))
    if match:
        return (
            f"The native vector env of `{match['env']}` (what `gym.make_vec` makes for its id): "
            "a `CollisionTargetVectorEnv` with the same task, made by `register_task`."
        )
    return None


def _set_docstring(obj: griffe.Object, text: str) -> None:
    obj.docstring = griffe.Docstring(text, lineno=obj.lineno, parent=obj, parser=griffe.Parser.numpy)


def inherit_docstrings(module: griffe.Module) -> None:
    """Give every class member of ``module`` (and its submodules) without a docstring the one of
    the same member of its nearest base class in the package that has one."""
    for member in module.members.values():
        if isinstance(member, griffe.Module):
            inherit_docstrings(member)
        elif isinstance(member, griffe.Class):
            try:
                bases = member.mro()
            except (griffe.AliasResolutionError, ValueError):  # (a base outside the package)
                bases = []
            for name, own in member.members.items():
                if not isinstance(own, griffe.Object) or own.docstring is not None:
                    continue
                for base in bases:
                    found = base.members.get(name)
                    if isinstance(found, griffe.Object) and found.docstring is not None:
                        _set_docstring(own, found.docstring.value)
                        break


class ProseDocstrings(griffe.Extension):
    """Gives attributes their ``#:`` doc comments (:func:`attribute_doc`) and class members their
    bases' docstrings (:func:`inherit_docstrings`), then applies :func:`fence_doctests` and
    :func:`end_parameter_sections` to every docstring."""

    def on_package(self, *, pkg: griffe.Module, **kwargs) -> None:
        inherit_docstrings(pkg)

    def on_object(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.is_attribute and obj.docstring is None and (text := attribute_doc(obj)):
            _set_docstring(obj, text)
        if obj.docstring is not None:
            lines = obj.docstring.value.split("\n")
            obj.docstring.value = "\n".join(end_parameter_sections(fence_doctests(lines)))
