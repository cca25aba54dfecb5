"""The first run: kernels cached by a hash of their sources (never stale), one compiled version per
kernel, and one line on stderr while compiling."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from collision_env.engine import _jit

needs_numba = pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="numba is not installed (or is disabled)")


def _package(root: Path) -> Path:
    (root / "engine").mkdir(parents=True)
    (root / "envs").mkdir()
    (root / "engine" / "toi.py").write_text("LIMIT = 1.0\n")
    (root / "envs" / "_kernels.py").write_text("from engine._jit import njit\n@njit\ndef k(x):\n    return x\n")
    (root / "envs" / "rendering.py").write_text("COLOUR = 'red'\n")
    return root


def test_the_hash_follows_every_kernel_source_and_nothing_else(tmp_path):
    pkg = _package(tmp_path / "pkg")
    first = _jit.source_hash(pkg)
    assert _jit.source_hash(pkg) == first
    (pkg / "envs" / "rendering.py").write_text("COLOUR = 'blue'\n")  # no kernel in it
    assert _jit.source_hash(pkg) == first
    (pkg / "engine" / "toi.py").write_text("LIMIT = 2.0\n")  # a constant a kernel may freeze
    second = _jit.source_hash(pkg)
    assert second != first
    (pkg / "envs" / "_kernels.py").write_text("from engine._jit import njit\n@njit\ndef k(x):\n    return 2 * x\n")
    assert _jit.source_hash(pkg) not in (first, second)
    (pkg / "engine" / "calendar.py").write_text("")  # a new engine module counts too
    assert len({_jit.source_hash(pkg), first, second}) == 3


def test_the_package_kernels_are_all_in_the_hash():
    names = {p.relative_to(_jit.PACKAGE_DIR).as_posix() for p in _jit.kernel_sources()}
    assert {"engine/exact/scheduler.py", "engine/physics/toi.py", "engine/_jit.py", "envs/task/finish.py"} <= names
    assert "envs/rendering.py" not in names


def test_stale_cache_folders_are_removed_but_not_the_current_one(tmp_path):
    keep = tmp_path / f"{_jit.CACHE_PREFIX}new"
    old = tmp_path / f"{_jit.CACHE_PREFIX}old"
    other = tmp_path / "something-else"
    for folder in (keep, old, other):
        folder.mkdir()
    _jit.remove_stale_caches(tmp_path, keep)
    assert keep.is_dir() and other.is_dir() and not old.exists()


@needs_numba
def test_the_cache_folder_is_named_by_the_source_hash():
    assert _jit.cache_dir().name == f"{_jit.CACHE_PREFIX}{_jit.SOURCE_HASH}"


def _add(i, j):
    return i + j


def _callers(callee):
    import numba

    @numba.njit
    def with_literal(i):
        return callee(i, -1)

    @numba.njit
    def with_variable(i, j):
        return callee(i, j)

    return with_literal, with_variable


@needs_numba
def test_a_kernel_called_with_a_literal_is_compiled_once_for_the_plain_type():
    """numba compiles a called kernel once per literal argument value; ours once per plain type."""
    import numba
    from numba.core import types

    plain = numba.njit(_add)
    ours = _jit._KernelDispatcher(py_func=_add, locals={}, targetoptions={"nopython": True, "boundscheck": None})
    for callee in (plain, ours):
        with_literal, with_variable = _callers(callee)
        assert with_literal(3) == 2 and with_variable(3, 4) == 7
    assert len(plain.signatures) == 2  # numba's own: (int64, Literal[int](-1)) and (int64, int64)
    assert ours.signatures == [(types.int64, types.int64)]


@needs_numba
def test_compiling_says_so_once_on_stderr_and_a_cached_run_says_nothing(tmp_path):
    code = (
        "from collision_env.engine.physics.tolerance import contact_tolerance\n"
        "print(contact_tolerance(1.0, 2.0, 1e-9))\n"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    runs = [
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
        for _ in range(2)
    ]
    for run in runs:
        assert run.returncode == 0, run.stderr
    assert runs[0].stderr.count(_jit.COMPILE_NOTICE) == 1
    assert _jit.COMPILE_NOTICE not in runs[1].stderr
    assert runs[0].stdout == runs[1].stdout
    assert list((tmp_path / "collision_env").glob(f"{_jit.CACHE_PREFIX}*/*.nbi"))


@needs_numba
def test_a_kernel_outside_the_package_is_cached_by_its_contents(tmp_path):
    """A test's kernel is cached with the package's; editing its file (even to the same size, with
    the same modification time) recompiles it, and a kernel with no file is compiled uncached."""
    script = tmp_path / "outside.py"
    source = "from collision_env.engine._jit import njit\n@njit\ndef k(x):\n    return x + {}\nprint(k(1))\n"
    root = str(Path(__file__).resolve().parents[2])  # this checkout's package, whatever is installed
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": root}

    def run(*args):
        done = subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        return done.stdout.strip(), _jit.COMPILE_NOTICE in done.stderr

    script.write_text(source.format(1))
    stamp = script.stat().st_mtime_ns
    assert run(str(script)) == ("2", True)
    assert run(str(script)) == ("2", False)  # from the cache
    script.write_text(source.format(2))
    os.utime(script, ns=(stamp, stamp))
    assert run(str(script)) == ("3", True)
    assert list((tmp_path / "cache" / "collision_env").glob(f"{_jit.CACHE_PREFIX}*/outside*.nbi"))
    assert run("-c", source.format(4))[0] == "5"
