"""The agent modules import one another without a cycle (function-level imports included)."""

import ast
from pathlib import Path

AGENTS = Path(__file__).resolve().parents[2] / "agents"


def _imported_agents(path: Path) -> set[str]:
    """The ``agents.<name>`` modules that ``path`` imports anywhere in its body."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
        out |= {name.split(".")[1] for name in names if name.startswith("agents.")}
    return out


def test_agent_modules_import_no_cycle():
    graph = {path.stem: _imported_agents(path) for path in AGENTS.glob("*.py")}
    done: set[str] = set()

    def visit(module: str, chain: list[str]) -> None:
        assert module not in chain, "import cycle: " + " -> ".join([*chain[chain.index(module) :], module])
        if module in done:
            return
        for imported in sorted(graph.get(module, ())):
            visit(imported, [*chain, module])
        done.add(module)

    for module in sorted(graph):
        visit(module, [])
