"""MkDocs hooks of the documentation site (mkdocs.yml ``hooks:``), so that no page copies by hand
what the code or the README already says:

* one page per registered env id, ``envs/<name>.md``, from the env class's docstring, its task
  entry and its GIF in ``docs/img/`` (added to the nav under "Environments"), and the table of ids
  that ``<!-- env-table -->`` stands for;
* ``<!-- extras-table -->`` stands for the table of the optional extras, from pyproject.toml;
* ``<!-- readme-block NAME -->`` stands for the README's block ``NAME`` (between
  ``<!-- NAME:start -->`` and ``<!-- NAME:end -->``: the introduction, the install commands, the first
  example, the modes table), its ``docs/`` links made relative to the page, so that a page shows
  what the README says without a second copy;
* Sphinx roles in docstrings (``:class:`~a.b.C` ``) are shown as plain code (``C``);
* an entry of the API reference without a description (an object with no docstring) is a warning,
  which fails ``mkdocs build --strict``;
* the API pages rank first in the site search for API names (a search boost), the generated
  benchmark tables last.
"""

from __future__ import annotations

import inspect
import logging
import os
import re
import sys
import tomllib
from html.parser import HTMLParser
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the checkout's collision_env, whatever is installed

import collision_env  # noqa: E402
from collision_env.envs import REGISTERED  # noqa: E402

ENV_SECTION = "Environments"
ENV_TABLE = "<!-- env-table -->"
EXTRAS_TABLE = "<!-- extras-table -->"
README_BLOCK = re.compile(r"^<!-- readme-block (?P<name>[\w:-]+) -->$", re.M)
#: Search boost by page: an API name finds its reference entry before the pages that mention it.
SEARCH_BOOST = {"api/": 4.0, "bench/": 0.5, "agents/": 0.5}
LOG = logging.getLogger("mkdocs.plugins.collision_env")
ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|attr|data|obj|exc):<code>(?P<tilde>~?)(?P<target>[^<]*)</code>")


def env_slug(env_id: str) -> str:
    """``CollisionEnv/OneBallTarget-v0`` -> ``oneballtarget`` (also the name of its GIF)."""
    return env_id.split("/")[-1].rsplit("-v", 1)[0].lower()


def summary(env_id: str) -> str:
    """The first line of the docstring of the module that defines the id's env class."""
    module = sys.modules[REGISTERED[env_id].single.__module__]
    return inspect.cleandoc(module.__doc__ or "").split("\n")[0]


def gif(env_id: str) -> str | None:
    path = Path("img") / f"{env_slug(env_id)}.gif"
    return path.as_posix() if (ROOT / "docs" / path).is_file() else None


def env_page(env_id: str) -> str:
    reg = REGISTERED[env_id]
    single, vector = reg.single.__name__, reg.vector.__name__
    lines = [f"# `{env_id}`", "", summary(env_id), ""]
    if picture := gif(env_id):
        lines += [f'![{env_id}]({relative(picture, "envs/page.md")}){{ width="480" }}', ""]
    lines += [
        f'`gym.make("{env_id}")` makes the single env (`collision_env.envs.{single}`), '
        f'`gym.make_vec("{env_id}", n)` the native vector env on the batched engine (`{vector}`); '
        "both take any `TaskConfig` field as a keyword, the engine's `mode` and `substeps` among them.",
        "",
    ]
    if reg.task is not None:
        lines += [
            f'The preset `{reg.task.preset}` (`gym.make("CollisionEnv/Target-v0", preset="{reg.task.preset}")`) '
            "sets these `TaskConfig` fields; the others keep their defaults:",
            "",
            "| field | value |",
            "|---|---|",
            *(f"| `{k}` | `{v!r}` |" for k, v in reg.task.config.items()),
            "",
        ]
    return "\n".join(lines) + "\n" + inspect.cleandoc(reg.single.__doc__ or "") + "\n"


def relative(path: str, page_path: str) -> str:
    """``path`` (relative to docs/) as a link from the page ``page_path`` (also relative to docs/)."""
    return Path(os.path.relpath(Path("docs", path), Path("docs", page_path).parent)).as_posix()


def readme_env_table() -> str:
    """The README's table of ids (its ``envs:table`` block, written by ``scripts/render_presets.py
    --readme``): each id's task and its GIF."""
    rows = ["| id | the task | |", "|---|---|---|"]
    for env_id in collision_env.ENV_IDS:
        path = gif(env_id)
        picture = f'<img src="docs/{path}" width="200">' if path else ""
        rows.append(f"| `{env_id}` | {summary(env_id)} | {picture} |")
    return "\n".join(rows)


def env_table(page_path: str) -> str:
    rows = ["| id | the task | |", "|---|---|---|"]
    for env_id in collision_env.ENV_IDS:
        path = gif(env_id)
        picture = f'![]({relative(path, page_path)}){{ width="200" }}' if path else ""
        link = relative(f"envs/{env_slug(env_id)}.md", page_path)
        rows.append(f"| [`{env_id}`]({link}) | {summary(env_id)} | {picture} |")
    return "\n".join(rows)


def extras_table() -> str:
    """The optional extras: what each is for (the comment above it in pyproject.toml) and installs."""
    text = (ROOT / "pyproject.toml").read_text()
    extras = tomllib.loads(text)["project"]["optional-dependencies"]
    lines = text.splitlines()
    rows = ["| extra | what for | installs |", "|---|---|---|"]
    for name, requirements in extras.items():
        at = next(i for i, line in enumerate(lines) if line.startswith(f"{name} = ["))
        comment: list[str] = []
        while at > 0 and lines[at - 1].startswith("#"):
            at -= 1
            comment.insert(0, lines[at].lstrip("# "))
        rows.append(f"| `{name}` | {' '.join(comment)} | {', '.join(f'`{r}`' for r in requirements)} |")
    return "\n".join(rows)


def readme_block(name: str, page_path: str) -> str:
    text = (ROOT / "README.md").read_text()
    match = re.search(rf"<!-- {re.escape(name)}:start -->\n(.*?)<!-- {re.escape(name)}:end -->", text, re.S)
    if match is None:
        raise ValueError(f"README.md has no block {name!r}")
    return re.sub(r"\]\(docs/([^)]*)\)", lambda m: f"]({relative(m[1], page_path)})", match.group(1))


class _Entries(HTMLParser):
    """The API reference's entries (mkdocstrings' ``div.doc-object``): each one's id and the text of
    its own description (its ``div.doc-contents``, without the entries nested in it)."""

    def __init__(self) -> None:
        super().__init__()
        self.entries: list[dict] = []
        self._stack: list[tuple[str, dict | None]] = []

    def handle_starttag(self, tag: str, attrs: list) -> None:
        attributes = dict(attrs)
        classes = (attributes.get("class") or "").split()
        if tag == "div":
            if "doc-object" in classes:
                entry = {"id": None, "text": ""}
                self.entries.append(entry)
                self._stack.append(("object", entry))
            elif "doc-contents" in classes:
                owner = next((e for kind, e in reversed(self._stack) if kind == "object"), None)
                self._stack.append(("contents", owner))
            else:
                self._stack.append(("other", None))
        elif re.fullmatch(r"h[1-6]", tag) and attributes.get("id"):
            owner = next((e for kind, e in reversed(self._stack) if kind == "object"), None)
            if owner is not None and owner["id"] is None:
                owner["id"] = attributes["id"]

    def handle_endtag(self, tag: str) -> None:
        if tag == "div" and self._stack:
            self._stack.pop()

    def handle_data(self, data: str) -> None:
        for kind, entry in reversed(self._stack):
            if kind == "contents" and entry is not None:
                entry["text"] += data
            if kind in ("contents", "object"):
                return


def empty_entries(html: str) -> list[str]:
    """The ids of the API reference entries in ``html`` that have no description."""
    parser = _Entries()
    parser.feed(html)
    return [str(e["id"]) for e in parser.entries if not e["text"].strip()]


# ------------------------------------------------------------------------------------------ hooks
def on_config(config):
    pages = [{env_id: f"envs/{env_slug(env_id)}.md"} for env_id in collision_env.ENV_IDS]
    for item in config["nav"]:
        if isinstance(item, dict) and ENV_SECTION in item:
            item[ENV_SECTION] = [*item[ENV_SECTION], *pages]
            return config
    raise ValueError(f"mkdocs.yml: the nav has no {ENV_SECTION!r} section for the env pages")


def on_files(files, config):
    for env_id in collision_env.ENV_IDS:
        files.append(File.generated(config, f"envs/{env_slug(env_id)}.md", content=env_page(env_id)))
    return files


def on_page_markdown(markdown, page, config, files):
    for prefix, boost in SEARCH_BOOST.items():
        if page.file.src_uri.startswith(prefix):
            page.meta.setdefault("search", {}).setdefault("boost", boost)
    markdown = markdown.replace(ENV_TABLE, env_table(page.file.src_uri)).replace(EXTRAS_TABLE, extras_table())
    return README_BLOCK.sub(lambda m: readme_block(m["name"], page.file.src_uri), markdown)


def on_page_content(html, page, config, files):
    if page.file.src_uri.startswith("api/") and (empty := empty_entries(html)):
        LOG.warning(f"{page.file.src_uri}: {len(empty)} API entries without a description: {', '.join(empty)}")
    return ROLE.sub(lambda m: f"<code>{m['target'].rsplit('.', 1)[-1] if m['tilde'] else m['target']}</code>", html)
