"""Cache misses per event in exact mode, by array: where a large gas's cost per event comes from.

Run it as::

    python -m collision_env.bench.misses                       # N = 1e3 and 1e5 (about 3 minutes)
    python -m collision_env.bench.misses --sizes 400 --cache-kib 2048
    python -m collision_env.bench.misses --sizes 100000 --sites 20     # and the 20 costliest lines

Timings on a shared machine cannot say which of the engine's arrays an event waits for, and numba's
machine code carries no symbols a cache profiler could attribute to. This tool counts instead. It
runs the scale benchmark's gas (:class:`~collision_env.bench.scale.TimedGas`, built and warmed up
as that benchmark does) through the engine's Python path (``NUMBA_DISABLE_JIT=1``: the same kernel
source, interpreted). It hands the kernel views of the simulator's arrays that note the 64-byte
line of every element the kernel reads or writes. Those lines go through a model of one cache:
fully associative, least recently used first out, ``--cache-kib`` in all. The default, 2 MiB, is
the private L2 cache of one core of a current server.

Every line of every array is fetched once (the largest array first), a short step then fills the
model with what events use, and one frame of 1/60 s is counted. The report gives, per event (ball-
ball and ball-wall collisions) and per array the kernel takes (named as the fields of its bundles,
:class:`~collision_env.engine.state.State`, :class:`~collision_env.engine.state.Calendar` and
:class:`~collision_env.engine.state.ExactScratch`), the lines that missed; with ``--sites``, also
per line of the kernel source that indexed the array (``scheduler._partner_event:255``).
What the counts leave out:

- the frame's passes over every ball (the step's start and end) are counted with the events, as
  the scale benchmark times them; they stream through the arrays in order, which hardware
  prefetchers hide;
- the Python side's work between kernel calls (copying impacts out of the buffer) is not counted;
- reads and writes count alike;
- the kernels' software prefetches (``_jit.prefetch``, a hint, not an access) are not counted: a
  miss they hide still counts where the data is used;
- associativity, prefetchers and the other levels are not modelled, and where numpy places an
  array that is not aligned to a line moves its counts a little from run to run.

So the counts rank the arrays; they are not a time.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections import OrderedDict

import numpy as np

from collision_env.bench.readme import write_outputs

SIZES = (1_000, 100_000)
CACHE_KIB = 2048
LINE = 64
#: The step that fills the cache model before the counted frame (s): at 10^5 disks, several
#: thousand events, each touching dozens of lines.
WARM_S = 0.002
FRAME = 1.0 / 60.0


class LineCache:
    """A fully associative, least-recently-used cache of ``lines`` lines that counts, per tag, the
    lines it had to fetch while ``counting`` is on; and per ``(tag, site)`` too, in ``sites``, once
    that is set to a dict (the traced arrays then name the source line of each access)."""

    def __init__(self, lines: int) -> None:
        self.lines = lines
        self.held: OrderedDict[int, None] = OrderedDict()
        self.counting = False
        self.misses: dict[str, int] = {}
        self.sites: dict[tuple[str, str], int] | None = None

    def touch_all(self, array: np.ndarray, tag: str) -> None:
        """Fetch every line of ``array``, in order."""
        start = array.__array_interface__["data"][0]
        for line in range(start // LINE, (start + array.nbytes + LINE - 1) // LINE):
            self.touch(line, tag)

    def touch(self, line: int, tag: str, site: str = "") -> None:
        if line in self.held:
            self.held.move_to_end(line)
            return
        if self.counting:
            self.misses[tag] = self.misses.get(tag, 0) + 1
            if self.sites is not None:
                self.sites[tag, site] = self.sites.get((tag, site), 0) + 1
        self.held[line] = None
        if len(self.held) > self.lines:
            self.held.popitem(last=False)


class TracedArray(np.ndarray):
    """A view that reports to its :class:`LineCache` the lines of every element the kernel indexes
    with integers (all the lines a structured record spans; the first line of a row indexed by
    fewer integers than the array has axes). Views of it report theirs too; the fields a kernel
    reads from a record it took out (``r = rec[k]; r["x"]``) are the record's."""

    def __array_finalize__(self, obj):
        self.tag = getattr(obj, "tag", "?")
        self.cache = getattr(obj, "cache", None)
        self.address = self.__array_interface__["data"][0]

    def _touch(self, key) -> None:
        if self.cache is None:
            return
        key = key if isinstance(key, tuple) else (key,)
        address = self.address
        for index, stride, size in zip(key, self.strides, self.shape, strict=False):
            if not isinstance(index, int | np.integer):
                return  # (a slice makes a view: its elements report when they are indexed)
            address += (int(index) % size) * stride  # (a negative index counts from the end)
        # an element reports every line it spans (a structured record may span two); a row, its first
        end = address + (self.itemsize if len(key) == self.ndim else 1)
        site = _site(sys._getframe(2)) if self.cache.sites is not None else ""  # (who indexed: 2 calls up)
        for line in range(address // LINE, (end - 1) // LINE + 1):
            self.cache.touch(line, self.tag, site)

    def __getitem__(self, key):
        self._touch(key)
        return super().__getitem__(key)

    def __setitem__(self, key, value):
        self._touch(key)
        super().__setitem__(key, value)


def _site(frame) -> str:
    """A source line, as ``module.function:line``."""
    module = os.path.splitext(os.path.basename(frame.f_code.co_filename))[0]
    return f"{module}.{frame.f_code.co_name}:{frame.f_lineno}"


def measure(n: int, cache_kib: int = CACHE_KIB, sites: int = 0) -> dict:
    """Misses per event, by array, of one frame of the ``n``-disk gas (the Python path only); with
    ``sites``, also the that many source lines that missed most, under ``"sites"``."""
    from collision_env.engine._jit import HAVE_NUMBA

    from .scale import TimedGas

    if HAVE_NUMBA:
        raise RuntimeError("measure() traces the Python path: run it with NUMBA_DISABLE_JIT=1 (main() does)")
    # (built, and warmed up as the scale benchmark does; its stepper, whose pack the tracing replaces)
    stepper = TimedGas(n, trace_memory=False).sim._stepper
    cache = LineCache(cache_kib * 1024 // LINE)
    if sites:
        cache.sites = {}
    traced = []
    bundles = []
    for bundle in stepper._pack:  # (the Python path's pack: the kernel's bundles of arrays)
        views = [array.view(TracedArray) for array in bundle]
        for name, view in zip(bundle._fields, views, strict=True):
            view.tag, view.cache = name, cache
        traced += views
        bundles.append(type(bundle)(*views))
    stepper._pack = tuple(bundles)
    for view in sorted(traced, key=lambda view: -view.nbytes):  # (largest first: what fits stays)
        cache.touch_all(view, view.tag)
    stepper.step(WARM_S)
    cache.counting = True
    before = stepper.stats()
    stepper.step(FRAME)
    after = stepper.stats()
    events = after["events"] - before["events"]
    per_event = {tag: count / events for tag, count in sorted(cache.misses.items(), key=lambda kv: -kv[1])}
    costliest = sorted((cache.sites or {}).items(), key=lambda kv: -kv[1])[:sites]
    return {
        "n": n,
        "cache_kib": cache_kib,
        "events": events,
        "pair_tests": (after["pair_tests"] - before["pair_tests"]) / events,  # (pair predictions)
        "cell_crossings": (after["cell_crossings"] - before["cell_crossings"]) / events,
        "misses_per_event": per_event,
        **(
            {"sites": [{"array": tag, "site": site, "per_event": count / events} for (tag, site), count in costliest]}
            if sites
            else {}
        ),
    }


def render_markdown(rows: list[dict]) -> str:
    largest = max(rows, key=lambda row: row["n"])["misses_per_event"]
    arrays = sorted({tag for row in rows for tag in row["misses_per_event"]}, key=lambda tag: -largest.get(tag, 0.0))
    arrays = [tag for tag in arrays if max(row["misses_per_event"].get(tag, 0.0) for row in rows) >= 0.01]
    lines = [
        f"Lines missed per event in a {rows[0]['cache_kib']} KiB least-recently-used cache, one frame of 1/60 s "
        "of the scale benchmark's gas (`python -m collision_env.bench.misses`):",
        "",
        "| disks | events | pair predictions per event | crossings per event | all |"
        + "".join(f" {tag} |" for tag in arrays),
        "|---:|---:|---:|---:|---:|" + "---:|" * len(arrays),
    ]
    for row in rows:
        m = row["misses_per_event"]
        lines.append(
            f"| {row['n']:,} | {row['events']:,} | {row['pair_tests']:.1f} | {row['cell_crossings']:.2f} "
            f"| {sum(m.values()):.1f} |" + "".join(f" {m.get(tag, 0.0):.2f} |" for tag in arrays)
        )
    for row in rows:
        if row.get("sites"):
            lines += ["", f"Where {row['n']:,} disks miss most (source line of the access):", ""]
            lines += ["| line | array | per event |", "|---|---|---:|"]
            lines += [f"| `{s['site']}` | {s['array']} | {s['per_event']:.2f} |" for s in row["sites"]]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench.misses", description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES), help="gases of these many disks")
    parser.add_argument("--cache-kib", type=int, default=CACHE_KIB, help="the modelled cache's size (KiB)")
    parser.add_argument("--sites", type=int, default=0, help="also list this many source lines that miss most")
    parser.add_argument("--json", help="write the raw figures here")
    args = parser.parse_args(argv)
    if os.environ.get("NUMBA_DISABLE_JIT") != "1":  # (numba decides at import: trace in a fresh process)
        env = dict(os.environ, NUMBA_DISABLE_JIT="1")
        command = [sys.executable, "-m", "collision_env.bench.misses", *(argv if argv is not None else sys.argv[1:])]
        return subprocess.run(command, env=env, check=False).returncode
    rows = []
    for n in args.sizes:
        rows.append(measure(n, args.cache_kib, args.sites))
        print(f"  N = {n:,}: {sum(rows[-1]['misses_per_event'].values()):.1f} misses per event", flush=True)
    write_outputs(render_markdown(rows), rows, json_path=args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
