"""Every public function and method (constructors included) of the package and the sample agents is
fully annotated (its parameters and its return), so that mypy checks its callers. Compiled kernels
(``@njit``) and numba intrinsics are left out: numba types them itself."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
KERNEL_DECORATORS = {"njit", "intrinsic", "_intrinsic"}


def _decorator_name(node: ast.expr) -> str:
    node = node.func if isinstance(node, ast.Call) else node
    return node.id if isinstance(node, ast.Name) else getattr(node, "attr", "")


def _public_functions(body: list[ast.stmt], in_class: bool = False):
    """The module's (or class's) functions, with the methods of its public classes; definitions made
    under ``if``/``try`` (the numba and the plain Python variants) count too."""
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            if not node.name.startswith("_") or node.name == "__init__":
                yield node, in_class
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            yield from _public_functions(node.body, in_class=True)
        elif isinstance(node, ast.If | ast.Try):
            handlers = [stmt for handler in getattr(node, "handlers", ()) for stmt in handler.body]
            yield from _public_functions(node.body + node.orelse + handlers, in_class)


def _unannotated(fn: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> list[str]:
    args = fn.args
    params = args.posonlyargs + args.args + args.kwonlyargs
    static = any(_decorator_name(d) == "staticmethod" for d in fn.decorator_list)
    if method and not static and params and params[0].arg in ("self", "cls"):
        params = params[1:]
    params += [p for p in (args.vararg, args.kwarg) if p is not None]
    missing = [p.arg for p in params if p.annotation is None]
    return missing + (["return"] if fn.returns is None else [])


@pytest.mark.parametrize("package", ["collision_env", "agents"])
def test_public_functions_are_annotated(package):
    gaps = []
    for path in sorted((ROOT / package).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for fn, method in _public_functions(tree.body):
            if any(_decorator_name(d) in KERNEL_DECORATORS for d in fn.decorator_list):
                continue
            missing = _unannotated(fn, method)
            if missing:
                gaps.append(f"{path.relative_to(ROOT)}:{fn.lineno} {fn.name}: {', '.join(missing)}")
    assert not gaps, "not annotated:\n" + "\n".join(gaps)
