"""Just-in-time compilation of the engine kernels.

The kernels are plain Python loops over numpy arrays. numba (a dependency of the package, on every
platform it publishes wheels for) compiles them once and caches them on disk; without it they run
as ordinary Python, with the same results and a cost per event some :data:`PYTHON_SLOWDOWN` times
higher, and importing the engine issues one :class:`SlowBackendWarning` that says so.
``NUMBA_DISABLE_JIT=1`` forces the Python path without the warning, which is how the tests check
that both paths agree.

Every kernel of the package goes through :func:`njit`, which differs from ``numba.njit`` in three
ways:

* **The cache can never run stale code.** numba keys its on-disk cache on the kernel's own file,
  so a cached caller keeps the old machine code of a callee inlined from another file after that
  file is edited. Here every kernel is cached in one folder named by a hash of all the kernel
  sources (:data:`SOURCE_HASH`: every module of ``collision_env.engine`` and every other module that
  defines a kernel): an edit to any of them recompiles everything once.
  The folder is ``collision_env/__pycache__/kernels-<hash>`` when the package folder is writable,
  else ``~/.cache/collision_env/kernels-<hash>`` (``$XDG_CACHE_HOME``), or under numba's own
  ``NUMBA_CACHE_DIR`` when that is set. Folders of earlier sources are removed when a new one is
  made. A kernel outside the package (a test's, which inlines the package's kernels) is cached in
  the same folder, keyed on its own file's contents as well (one that has no file is not cached).
* **One compiled version per kernel.** numba compiles a separate version of a called kernel for
  every distinct literal argument (``f(i, -1)`` and ``f(i, j)`` are two compilations) and integer
  type (an int32 read from an array, an int64 loop counter); here a kernel called from another
  kernel is compiled for the arguments' plain types, every integer as int64.
* **Kernels built for a kind of scene are cached too.** A stepping kernel is made by a factory for
  one kind of scene (a closure over a few constants, see :mod:`collision_env.engine.modes`), so
  that a scene never compiles the paths it cannot take. numba keys a closure's cache entry on its
  cells' pickled values; a cell that holds another kernel would pickle differently in every
  process, so here such a cell is keyed on the kernel's name and its own cells instead.
* **It says what it compiles, and how long it will take.** The first compilation in a process (a
  fresh install, or edited sources) prints :data:`COMPILE_NOTICE` on stderr; a kernel given a
  ``label`` (each mode's stepping kernel for a kind of scene, each env kernel: words a user knows,
  such as "exact mode for elastic scenes") then prints one line: its label, the seconds it is
  expected to take (:data:`EXPECTED_SECONDS`), and when done the seconds it took. Inside
  :func:`compile_plan` (``python -m collision_env.precompile``), the line also counts the kernels of
  the plan and estimates the time left: ``compiling exact mode for elastic scenes (3 of 9 kernels,
  ~40 s left) ... 14.1 s``.

Compile time: numba compiles every kernel once (then cached) and LLVM inlines the small ones where
they are called. ``inline="always"`` (numba's inlining of its own IR into every call site) is kept
for a few helpers that must be inlined (those that build arrays from a pack, or are called once in
a kernel's hot loop): each copy is typed and lowered again, which costs compile time that grows
faster than the number of call sites.

:func:`prefetch` asks the processor for an array element's cache line ahead of its use (an LLVM
intrinsic under numba, nothing in the Python path): the kernels use it where they know an address
well before they read it.

``@njit(refcount=False)`` compiles a kernel without numba's reference counting of arrays (its
private ``_nrt`` target option). Numba increments and decrements an array's count whenever a
kernel binds it to a new name, and an inlined helper with a branch binds every array it takes:
about 10 ns per array per call, which costs more than the arithmetic of a small scene. A kernel
compiled so must only borrow the arrays it is passed (slices of them included) and allocate none;
the kernels it calls that do allocate (a contact group's least-distance solve) keep their own
counting, since every other kernel is compiled with it explicitly.

The kernels keep the GIL while they run (numba's ``nogil`` off): releasing and taking it back costs
some 35 ns a call, a tenth of a small scene's step from Python, and the package runs work in
parallel in processes (:mod:`collision_env.bench.parallel`, vector envs' subprocesses), never in
threads.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import pickle
import shutil
import sys
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

#: How many times slower a collision costs in plain Python than compiled: a 1000-disk gas in frames
#: of 1/60 s, as ``python -m collision_env.bench.backend`` measures it (``docs/bench/backend.md``).
PYTHON_SLOWDOWN = 500


class SlowBackendWarning(RuntimeWarning):
    """numba is missing, so the engine runs as plain Python (issued once, when the engine is imported)."""


def slow_backend_message() -> str:
    """What :class:`SlowBackendWarning` says: how much slower, and what to install."""
    return (
        "collision_env: numba is not installed, so the engine's kernels run as plain Python: the same "
        f"results, about {PYTHON_SLOWDOWN} times slower per collision (a 1000-disk gas). "
        "Install numba to compile them: pip install numba"
    )


try:  # a dependency of the package, where numba has wheels; without it the kernels run as Python
    import numba as _numba
except ImportError:
    _numba = None
    # (line 0: the message alone, without a line of this file's source under it)
    warnings.warn_explicit(slow_backend_message(), SlowBackendWarning, __file__, 0, module=__name__)

HAVE_NUMBA = _numba is not None and not _numba.config.DISABLE_JIT
BACKEND = "numba" if HAVE_NUMBA else "python"
"""``"numba"`` when the kernels are compiled, ``"python"`` when they run as plain Python (numba
missing, or ``NUMBA_DISABLE_JIT=1``)."""

PACKAGE_DIR = Path(__file__).resolve().parent.parent
CACHE_PREFIX = "kernels-"
COMPILE_NOTICE = (
    "collision_env: numba compiles the engine's kernels once per install or source edit "
    "(python -m collision_env.precompile compiles them all ahead)"
)
#: Where :data:`EXPECTED_SECONDS` is read from: written by ``python -m collision_env.bench.compile
#: --estimates`` from a run of ``python -m collision_env.precompile`` with empty caches.
ESTIMATES_FILE = Path(__file__).with_name("compile_seconds.json")


def _expected_seconds() -> dict[str, float]:
    try:
        return {str(k): float(v) for k, v in json.loads(ESTIMATES_FILE.read_text())["seconds"].items()}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


#: Label of a kernel -> the CPU seconds its compilation took in the run that measured them (a guide
#: to the wait, scaled by this machine's speed once a kernel is compiled here; see :class:`_CompileNotice`).
EXPECTED_SECONDS = _expected_seconds()


def kernel_sources(package_dir: Path = PACKAGE_DIR) -> list[Path]:
    """The files the compiled kernels are made of: every module of the engine subpackage (kernels
    and the constants they freeze) and every other module of the package that defines a kernel."""
    engine = package_dir / "engine"
    return sorted(
        path
        for path in package_dir.rglob("*.py")
        if path.is_relative_to(engine) or "njit" in path.read_text(encoding="utf-8")
    )


def source_hash(package_dir: Path = PACKAGE_DIR) -> str:
    """A hash of the kernel sources (:func:`kernel_sources`: paths and contents), in a fixed order."""
    digest = hashlib.sha256()
    for path in kernel_sources(package_dir):
        digest.update(path.relative_to(package_dir).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()[:16]


SOURCE_HASH = source_hash()


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".probe-{os.getpid()}"
        probe.touch()
        probe.unlink()
        return True
    except OSError:
        return False


def cache_root() -> Path:
    """The folder holding the ``kernels-<hash>`` cache folders (see the module docstring)."""
    if HAVE_NUMBA and _numba.config.CACHE_DIR:
        return Path(_numba.config.CACHE_DIR) / "collision_env"
    in_tree = PACKAGE_DIR / "__pycache__"
    if _writable(in_tree):
        return in_tree
    user = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return user / "collision_env"


def cache_dir() -> Path:
    """Where this version of the sources keeps its compiled kernels."""
    return cache_root() / f"{CACHE_PREFIX}{SOURCE_HASH}"


def remove_stale_caches(root: Path, keep: Path) -> None:
    """Delete the cache folders of other source versions under ``root`` (never ``keep``)."""
    for old in root.glob(f"{CACHE_PREFIX}*"):
        if old.is_dir() and old != keep:
            shutil.rmtree(old, ignore_errors=True)


class _CompileNotice:
    """What the compiler is doing, on stderr: :data:`COMPILE_NOTICE` once, at the first kernel that
    misses the cache; then one line per labelled kernel compiled: its label and the expected wait,
    completed by the seconds it took. Within a :func:`compile_plan`, the line counts the plan's
    kernels and estimates the time left from :data:`EXPECTED_SECONDS`, scaled by how this machine
    compared with them on the kernels compiled so far."""

    shown = False
    labels: list = []  # (label, wall and CPU clocks at its start) of the kernels being compiled, innermost last
    plan: tuple[str, ...] = ()  # the labels compile_plan expects, in order
    phase: str | None = None  # what compile_phase calls the kernels compiled without a label of their own
    seconds: dict[str, float] = {}  # label -> wall seconds it took to compile in this process
    cpu_seconds: dict[str, float] = {}  # label -> CPU seconds of the same

    @classmethod
    def speed(cls) -> float:
        """The wall seconds compiling took here over the expected (CPU) seconds, for the kernels
        compiled so far (1: none yet)."""
        done = [(s, EXPECTED_SECONDS[k]) for k, s in cls.seconds.items() if EXPECTED_SECONDS.get(k)]
        return sum(s for s, _ in done) / sum(e for _, e in done) if done else 1.0

    @classmethod
    def describe(cls, label: str) -> str:
        """``exact mode for elastic scenes (3 of 9 kernels, ~40 s left)`` (the time left of the kernels
        with an estimate), or outside a plan ``exact mode for elastic scenes (about 14 s)``;
        without an estimate, the label alone."""
        if label in cls.plan:
            index = cls.plan.index(label)
            known = [EXPECTED_SECONDS[k] for k in cls.plan[index:] if k in EXPECTED_SECONDS]
            estimate = f", ~{cls.speed() * sum(known):.0f} s left" if known else ""
            return f"{label} ({index + 1} of {len(cls.plan)} kernels{estimate})"
        if label in EXPECTED_SECONDS:
            return f"{label} (about {cls.speed() * EXPECTED_SECONDS[label]:.0f} s)"
        return label

    @classmethod
    def miss(cls, label: str | None) -> None:
        """A kernel (with ``label``, or None) is compiled now. An unlabelled kernel compiled within a
        :func:`compile_phase`, outside any labelled one, announces the phase (once)."""
        if not cls.shown:
            cls.shown = True
            print(COMPILE_NOTICE, file=sys.stderr, flush=True)
        phase = cls.phase
        if phase is not None and label is not None and cls.labels and cls.labels[-1][0] == phase:
            cls.done(phase)  # (a labelled kernel inside the phase gets a line of its own)
        if phase is not None and label is None and not cls.labels and phase not in cls.seconds:
            label = phase
        if label is not None:
            print(f"collision_env: compiling {cls.describe(label)} ...", end="", file=sys.stderr, flush=True)
            cls.labels.append((label, time.perf_counter(), time.process_time()))

    @classmethod
    def done(cls, label: str) -> None:
        """The labelled kernel whose compilation :meth:`miss` announced is compiled."""
        if cls.labels and cls.labels[-1][0] == label:
            _, wall, cpu = cls.labels.pop()
            seconds = time.perf_counter() - wall
            cls.seconds[label] = seconds
            cls.cpu_seconds[label] = time.process_time() - cpu
            print(f" {seconds:.1f} s", file=sys.stderr, flush=True)


@contextlib.contextmanager
def compile_plan(labels: Sequence[str]) -> Iterator[None]:
    """Within the block, the kernels of ``labels`` (in the order they will be compiled) are counted
    in the compile notice, with an estimate of the time left."""
    before = _CompileNotice.plan
    _CompileNotice.plan = tuple(labels)
    try:
        yield
    finally:
        _CompileNotice.plan = before


@contextlib.contextmanager
def compile_phase(label: str) -> Iterator[None]:
    """Within the block, kernels compiled without a label of their own (helpers that Python calls
    directly) are announced together as ``label``, on one line with their time."""
    _CompileNotice.phase = label
    try:
        yield
    finally:
        _CompileNotice.phase = None
        _CompileNotice.done(label)


def compile_seconds() -> dict[str, float]:
    """Label -> CPU seconds of every labelled kernel compiled (not loaded from the cache) in this
    process: what :data:`EXPECTED_SECONDS` is made of (CPU seconds, not wall: a busy machine's wait
    would mislead another's estimate)."""
    return dict(_CompileNotice.cpu_seconds)


if HAVE_NUMBA:
    from numba.core import types as _types
    from numba.core.caching import CompileResultCacheImpl, FunctionCache, _CacheLocator
    from numba.core.registry import CPUDispatcher
    from numba.core.types.containers import BaseTuple as _BaseTuple  # (not in numba's stubs of types)
    from numba.core.types.misc import unliteral as _unliteral

    class _SourceHashLocator(_CacheLocator):
        """Numba cache locator: one folder for the whole package, named by its source hash."""

        _prepared: set = set()

        def __init__(self, py_func, py_file):
            self._py_file = py_file  # numba names it in its warning about an uncachable kernel
            self._own_file = None if _in_package(py_func) else py_file
            self._path = cache_dir()
            self._name = f"{py_func.__module__}-{py_func.__code__.co_firstlineno}"

        def ensure_cache_path(self):
            path = self._path
            if path not in self._prepared:
                if not path.is_dir():
                    remove_stale_caches(path.parent, keep=path)
                path.mkdir(parents=True, exist_ok=True)
                self._prepared.add(path)

        def get_cache_path(self):
            return str(self._path)

        def get_source_stamp(self):
            if self._own_file is None:
                return SOURCE_HASH  # the folder is already keyed on every source file
            return SOURCE_HASH, hashlib.sha256(Path(self._own_file).read_bytes()).hexdigest()

        def get_disambiguator(self):
            return self._name

        @classmethod
        def from_function(cls, py_func, py_file):
            return cls(py_func, py_file)

    class _SourceHashCacheImpl(CompileResultCacheImpl):
        _locator_classes = [_SourceHashLocator]

    def _plain(t):
        """The type a kernel called from another is compiled for: literals as their plain type, and
        every integer as int64 (an index read from an int32 array and one counted in a loop then
        share one compiled version)."""
        t = _unliteral(t)
        return _types.int64 if isinstance(t, _types.Integer) else t

    def _closure_key(func) -> bytes:
        """What identifies a closure's constants across processes: each cell's pickled value, or for
        a cell holding a kernel, that kernel's name and the key of its own cells (its code is
        covered by :data:`SOURCE_HASH`)."""
        parts: list[object] = []
        for cell in func.__closure__ or ():
            value = cell.cell_contents
            if isinstance(value, CPUDispatcher):
                inner = value.py_func
                parts.append((inner.__module__, inner.__qualname__, _closure_key(inner)))
            else:
                parts.append(pickle.dumps(value))
        return pickle.dumps(parts)

    class _KernelCache(FunctionCache):
        _impl_class = _SourceHashCacheImpl

        def __init__(self, py_func, label):
            super().__init__(py_func)
            self._label = label

        def load_overload(self, sig, target_context):
            loaded = super().load_overload(sig, target_context)
            if loaded is None:  # a miss: numba compiles this signature now
                _CompileNotice.miss(self._label)
            return loaded

        def _index_key(self, sig, codegen):
            key = super()._index_key(sig, codegen)
            if self._py_func.__closure__ is None:
                return key
            code_hash, _ = key[2]
            return key[0], key[1], (code_hash, hashlib.sha256(_closure_key(self._py_func)).hexdigest())

    class _KernelDispatcher(CPUDispatcher):
        """A CPU dispatcher compiled for plain (non-literal) argument types, cached by source hash."""

        label: str | None = None  #: what :class:`_CompileNotice` calls it (None: not announced)

        def get_call_template(self, args, kws):
            args = tuple(_plain(a) for a in args)
            kws = {k: _plain(v) for k, v in kws.items()}
            return super().get_call_template(args, kws)

        def compile(self, sig):
            try:
                return super().compile(sig)
            finally:
                if self.label is not None:
                    _CompileNotice.done(self.label)

        def enable_caching(self):
            self._cache = _KernelCache(self.py_func, self.label)

    class _InnerKernel(_KernelDispatcher):
        """A kernel only other kernels call (``njit(python=False)``): compiled without the wrappers
        that let Python call it, which for a kernel taking bundles of arrays cost more to compile
        than the kernel itself. A call from Python is refused (it would find no wrapper to enter)."""

        def __call__(self, *args, **kwargs):
            raise TypeError(
                f"{self.py_func.__module__}.{self.py_func.__qualname__} is compiled to be called from other kernels "
                "only (njit(python=False)); in Python, call its .py_func"
            )


def _in_package(func: Callable[..., Any]) -> bool:
    try:
        return Path(func.__code__.co_filename).resolve().is_relative_to(PACKAGE_DIR)
    except (OSError, ValueError):
        return False


def compile_for(kernel: Any, *example_args: Any) -> Callable[..., Any]:
    """Compile ``kernel`` now for the types of ``example_args`` (or load it from the cache), rather
    than at its first call. Returns that compiled version as a function that Python calls directly
    (``kernel`` itself without numba).

    A call of the kernel itself pays numba's dispatch: the type of every argument is worked out
    and matched against the compiled versions, about 30 ns an array and 0.2 us a structured array,
    as much as a small scene's whole step. The direct function skips it: it must be called with
    arguments of exactly the example's types (dtype, dimensions, C-contiguous layout; scalars of
    the same kind), which it does not check, so only code that owns the arrays it passes (a
    simulator's pack, an env's own buffers) may call it."""
    if not HAVE_NUMBA:
        return kernel
    return kernel.compile(tuple(_numba.typeof(a) for a in example_args))


def njit(
    func: Callable[..., Any] | None = None,
    *,
    refcount: bool = True,
    label: str | None = None,
    python: bool | None = None,
    **options: Any,
) -> Any:
    """Compile ``func`` with numba in nopython mode (cached), or return it unchanged.

    Use bare (``@njit``) or with extra numba options (``@njit(inline="always")``);
    ``refcount=False`` and ``label`` (what the compile notice calls the kernel): see the module
    docstring. ``python=False``: only other kernels call it (no wrappers for calls from Python,
    which are refused); the default for ``forceinline=True`` kernels, True otherwise.
    """
    if func is None:
        return lambda f: njit(f, refcount=refcount, label=label, python=python, **options)
    if not HAVE_NUMBA:
        return func
    # set explicitly, so that a kernel called from a ``refcount=False`` (or ``forceinline``) one does
    # not inherit it
    options["_nrt"] = bool(refcount)
    options.setdefault("forceinline", False)
    if not (_in_package(func) or Path(func.__code__.co_filename).is_file()):
        return _numba.njit(**options)(func)  # (no file to key a cache on: ``python -c``)
    if python is None:
        python = not options["forceinline"]
    if not python:
        options.update(no_cpython_wrapper=True, no_cfunc_wrapper=True)
    dispatcher = (_KernelDispatcher if python else _InnerKernel)(
        py_func=func,
        locals=options.pop("locals", {}),
        targetoptions={"nopython": True, "boundscheck": None, **options},
    )
    dispatcher.label = label
    dispatcher.enable_caching()
    return dispatcher


if HAVE_NUMBA:
    from llvmlite import ir as _ir
    from numba.core import cgutils as _cgutils
    from numba.extending import intrinsic as _intrinsic

    @_intrinsic
    def prefetch(typingctx, array, index):
        """Ask for the cache line of ``array[index]`` (``index``: an integer, or a tuple of one per
        axis) to be brought in for reading. A hint: it changes no value and cannot fault."""
        indices = tuple(index) if isinstance(index, _BaseTuple) else (index,)
        if not (isinstance(array, _types.Array) and len(indices) == array.ndim):
            return None
        if not all(isinstance(i, _types.Integer) for i in indices):
            return None

        def codegen(context, builder, signature, args):
            array_type, index_type = signature.args
            view = context.make_array(array_type)(context, builder, args[0])
            if isinstance(index_type, _BaseTuple):
                values, types = _cgutils.unpack_tuple(builder, args[1]), tuple(index_type)
            else:
                values, types = [args[1]], (index_type,)
            index_values = [context.cast(builder, v, t, _types.intp) for v, t in zip(values, types, strict=True)]
            ptr = _cgutils.get_item_pointer(context, builder, array_type, view, index_values, wraparound=False)
            i8_ptr = _ir.IntType(8).as_pointer()
            i32 = _ir.IntType(32)
            # (llvm.prefetch(address, read = 0, locality = 3: keep in every level, data cache = 1), by
            # the name of its opaque-pointer form, which LLVM 14's typed pointers (numba 0.60) accept too)
            intrinsic = _cgutils.get_or_insert_function(
                builder.module, _ir.FunctionType(_ir.VoidType(), [i8_ptr, i32, i32, i32]), "llvm.prefetch.p0"
            )
            address = builder.bitcast(ptr, i8_ptr)
            builder.call(intrinsic, [address, _ir.Constant(i32, 0), _ir.Constant(i32, 3), _ir.Constant(i32, 1)])
            return context.get_dummy_value()

        return _types.void(array, index), codegen

else:

    def prefetch(array: np.ndarray, index: int | tuple[int, ...]) -> None:
        """Ask for the cache line of ``array[index]`` ahead of its use: nothing to do in Python."""
