"""Every ```python block of README.md and docs/**/*.md runs as written: each one as a script of its
own, in a fresh process, from an empty folder (so it needs nothing a block above it defined).

A block that needs a module not every set-up has (Ray, from the ``distributed`` extra) says so on
the line just before its fence, ``<!-- requires: ray -->``; it runs where those modules are installed
and is skipped elsewhere, naming them. Rendering runs on SDL's dummy video driver (no display).
"""

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^(?P<indent>[ \t]*)```python[ \t]*\n(?P<code>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)
REQUIRES = re.compile(r"^\s*<!--\s*requires:\s*(?P<modules>[\w., ]+?)\s*-->\s*$")


def markdown_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def code_blocks(path: Path) -> list:
    """``(path:line, code, required modules)`` of each python block of ``path``."""
    text = path.read_text()
    blocks = []
    for match in FENCE.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        indent = len(match["indent"])
        code = "".join(row[indent:] for row in match["code"].splitlines(keepends=True))
        before = text[: match.start()].rstrip("\n").rpartition("\n")[2]
        marker = REQUIRES.match(before)
        modules = tuple(m.strip() for m in marker["modules"].split(",")) if marker else ()
        blocks.append(pytest.param(code, modules, id=f"{path.relative_to(ROOT)}:{line}"))
    return blocks


BLOCKS = [block for path in markdown_files() for block in code_blocks(path)]


def test_the_readme_and_the_docs_have_code_blocks():
    assert len(BLOCKS) >= 3
    assert any(block.values[1] == ("ray",) for block in BLOCKS)  # the marker is in use, as documented


@pytest.mark.parametrize("code, modules", BLOCKS)
def test_code_block_runs_as_written(tmp_path, code, modules):
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    script = tmp_path / "block.py"
    script.write_text(code)
    env = {
        **os.environ,
        "PYTHONPATH": str(ROOT),
        "SDL_VIDEODRIVER": "dummy",
        "SDL_AUDIODRIVER": "dummy",
        "MPLBACKEND": "Agg",
    }
    run = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600
    )
    assert run.returncode == 0, f"{code}\n--- stderr ---\n{run.stderr[-4000:]}"
