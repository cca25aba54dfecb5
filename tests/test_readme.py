"""The README is the front door: short, in the order a newcomer needs, its first example runs on the
install it names, its links lead somewhere, and nothing it says is said again in the docs or
ARCHITECTURE.md (the docs show its shared blocks through ``<!-- readme-block NAME -->``)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from collision_env.extras import EXTRAS

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
FENCE = re.compile(r"^```python\n(?P<code>.*?)^```$", re.M | re.S)
#: The hand-written pages (the generated ones, docs/bench/ and docs/agents/, share run stamps).
PAGES = [
    ROOT / "README.md",
    ROOT / "ARCHITECTURE.md",
    *sorted((ROOT / "docs").glob("*.md")),
    ROOT / "docs/envs/index.md",
]


def test_the_readme_is_at_most_250_lines_in_the_order_a_newcomer_needs():
    assert len(README.splitlines()) <= 250
    headings = re.findall(r"^## (.+)$", README, re.M)
    assert headings == [
        "Installation",
        "A first example",
        "The environments",
        "The engine in ten lines",
        "Fidelity modes",
        "Speed and accuracy",
        "Documentation",
        "Citing",
    ]
    assert README.count("<img ") >= 1  # the picture
    assert "make main" in README and "make test" in README and 'pip install -e ".[' in README


def test_the_readme_links_into_every_part_of_the_docs_and_every_link_resolves():
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README) + re.findall(r'src="([^"]+)"', README)
    local = [link for link in links if not link.startswith("http")]
    assert all((ROOT / link).exists() for link in local), [link for link in local if not (ROOT / link).exists()]
    for page in ("getting-started", "envs/index", "engine", "hard-disks", "agents", "benchmarks"):
        assert f"docs/{page}.md" in local, page


def test_the_first_example_runs_on_the_core_install(tmp_path):
    """The README's first python block, in a process where no extra's module can be imported."""
    first = FENCE.search(README)["code"]
    blocked = sorted({module for modules in EXTRAS.values() for module in modules})
    script = tmp_path / "first.py"
    script.write_text(f"import sys\nfor m in {blocked!r}:\n    sys.modules[m] = None\n" + first)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "wall at" in done.stdout


def test_the_env_table_is_the_one_the_script_writes():
    sys.path.insert(0, str(ROOT / "scripts"))
    pytest.importorskip("mkdocs")
    from docs_hooks import readme_env_table

    block = re.search(r"<!-- envs:table:start -->\n(.*?)<!-- envs:table:end -->", README, re.S)[1]
    assert block.strip() == readme_env_table(), "rerun python scripts/render_presets.py --readme README.md"


def test_every_block_the_docs_show_is_in_the_readme():
    used = {m for page in PAGES for m in re.findall(r"<!-- readme-block ([\w:-]+) -->", page.read_text())}
    assert {"intro", "install", "first-example", "keywords", "modes", "docs-map"} <= used
    for name in used:
        assert f"<!-- {name}:start -->" in README and f"<!-- {name}:end -->" in README, name


def _words(text: str) -> list[str]:
    text = re.sub(r"```.*?```|<!--.*?-->", "", text, flags=re.S)
    return re.findall(r"\w+", re.sub(r"^\|.*$", "", text, flags=re.M).lower())  # (tables: generated or shared)


def test_nothing_is_said_twice_across_the_readme_the_docs_and_the_architecture_note():
    """No run of 12 words of prose appears on two pages."""
    where: dict[str, set[str]] = {}
    for page in PAGES:
        words = _words(page.read_text())
        for i in range(len(words) - 11):
            where.setdefault(" ".join(words[i : i + 12]), set()).add(page.name)
    twice = {run: pages for run, pages in where.items() if len(pages) > 1}
    assert twice == {}
