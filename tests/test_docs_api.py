"""The API reference is complete: every public object has a docstring (as the reference's griffe
loader reads them, ``#:`` comments and inherited docstrings included), the build fails on an entry
without a description, and the site needs nothing from outside (no web fonts)."""

import sys
from pathlib import Path

import pytest

griffe = pytest.importorskip("griffe")
pytest.importorskip("mkdocs")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

import docs_hooks  # noqa: E402
from docs_griffe import ProseDocstrings, doc_comment  # noqa: E402

#: Every module the API reference renders (docs/api/*.md), with its members.
REFERENCE = [
    line.removeprefix(":::").strip()
    for page in sorted((ROOT / "docs" / "api").glob("*.md"))
    for line in page.read_text().splitlines()
    if line.startswith(":::")
]


def public_members(obj):
    """What mkdocstrings renders of a module (its ``__all__``, else its own public names) or a class
    (its public members)."""
    if obj.is_module and obj.exports is not None:
        return [obj.members[name if isinstance(name, str) else name.name] for name in obj.exports]
    return [m for name, m in obj.members.items() if not name.startswith("_") and not (obj.is_module and m.is_alias)]


def undocumented() -> list[str]:
    loader = griffe.GriffeLoader(
        docstring_parser=griffe.Parser.numpy, extensions=griffe.load_extensions(ProseDocstrings()), search_paths=[ROOT]
    )
    package = loader.load("collision_env")
    loader.resolve_aliases(external=False, implicit=False)
    missing, seen = [], set()

    def visit(obj, path):
        target = obj.final_target if obj.is_alias else obj
        if target.path in seen:
            return
        seen.add(target.path)
        if target.docstring is None or not target.docstring.value.strip():
            missing.append(f"{path} ({target.kind.value})")
        if target.is_class:
            for member in public_members(target):
                visit(member, f"{path}.{member.name}")

    for module_path in REFERENCE:
        module = package if module_path == "collision_env" else package[module_path.removeprefix("collision_env.")]
        if module_path != "collision_env.engine.impacts":  # (rendered without members: they are the engine's)
            for member in public_members(module):
                visit(member, f"{module_path}.{member.name}")
    return missing


def test_the_reference_renders_the_public_modules():
    assert {"collision_env.engine", "collision_env.envs", "collision_env.precompile", "collision_env.io"} <= set(
        REFERENCE
    )


def test_every_public_object_has_a_docstring():
    assert undocumented() == []


def test_doc_comments_above_or_after_an_attribute_are_its_docstring():
    lines = ["#: first line", "#: second line", "X = 1", "Y = 2  #: why Y", "Z = 3"]
    assert doc_comment(lines, 3) == "first line\nsecond line"
    assert doc_comment(lines, 4) == "why Y"
    assert doc_comment(lines, 5) is None


def test_an_entry_without_a_description_is_found_in_the_built_page():
    page = (
        '<div class="doc doc-object doc-class"><h2 id="m.A">A</h2>'
        '<div class="doc doc-contents"><p>An A.</p><div class="doc doc-children">'
        '<div class="doc doc-object doc-attribute"><h3 id="m.A.x">x</h3><div class="doc doc-contents"> </div></div>'
        '<div class="doc doc-object doc-function"><h3 id="m.A.f">f</h3>'
        '<div class="doc-signature highlight"><pre>f(a)</pre></div>'
        '<div class="doc doc-contents"><p>Does f.</p></div></div>'
        "</div></div></div>"
        '<div class="doc doc-object doc-class"><h2 id="m.B">B</h2><div class="doc doc-contents">'
        '<div class="doc doc-children"><div class="doc doc-object doc-attribute"><h3 id="m.B.y">y</h3>'
        '<div class="doc doc-contents"><p>A y.</p></div></div></div></div></div>'
    )
    assert docs_hooks.empty_entries(page) == ["m.A.x", "m.B"]  # (B's member's text is not B's)


def test_the_site_loads_no_web_fonts_and_boosts_the_api_pages_in_its_search():
    config = (ROOT / "mkdocs.yml").read_text()
    assert "\n  font: false\n" in config
    assert docs_hooks.SEARCH_BOOST["api/"] > 1 > docs_hooks.SEARCH_BOOST["bench/"]
