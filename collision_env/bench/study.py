"""The speed/accuracy study: what each mode costs, how far it is from exact, and where it breaks.

    python -m collision_env.bench --quick               # about a minute
    python -m collision_env.bench                       # full: every mode, dt, ball count, scene
    python -m collision_env.bench --readme README.md    # also refresh the README's headline table
    python -m collision_env.bench --render              # re-make tables, plots and summary from the CSVs

Writes into ``--out`` (default ``docs/bench/``): ``sweep.csv`` and ``results.md`` (the sweep),
``pareto.png``, ``cost_vs_balls.png``, ``error_vs_tunnelling.png``, ``extremes.csv`` and
``extremes.md`` (the stress grid), ``stats.csv`` and ``stats.md`` (long-run statistics),
``envs.csv`` (env steps per second), ``summary.md`` (which mode to pick when, generated from the
figures) and ``meta.json``. Prints the summary and the small tables.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from . import report
from .envrates import ENV_FIELDS, env_rates
from .extremes import EXTREME_FIELDS, extremes_markdown, run_extremes
from .machine import cpus, machine, timestamp, versions
from .readme import write_outputs
from .stats import STAT_FIELDS, gas_statistics, stats_markdown
from .sweep import run_sweep


def _meta_text(meta):
    v = meta["versions"]
    peers = ", ".join(f"{k} {v[k]}" for k in ("pymunk", "billiards") if v.get(k))
    return (
        f"{meta['date']}, {meta['machine']}, {meta['cpus']} CPUs, Python {v['python']}, numpy {v['numpy']}, "
        f"numba {v['numba']} (backend {v['backend']}){', ' + peers if peers else ''}; "
        f"{meta['duration_s']:.0f} s"
    )


def _stderr(msg):
    print(msg, file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collision_env.bench [study]", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a subset: about a minute")
    parser.add_argument("--out", default="docs/bench", help="output folder (default docs/bench)")
    parser.add_argument("--readme", metavar="PATH", help="replace the study block between the bench:study markers")
    parser.add_argument("--no-peers", action="store_true", help="leave pymunk and billiards out")
    parser.add_argument("--skip", default="", help="comma-separated parts to skip: extremes,stats,envs")
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default: all)")
    parser.add_argument("--render", action="store_true", help="do not measure: re-make the outputs from the CSVs")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    skip = {s.strip() for s in args.skip.split(",") if s.strip()}

    if args.render:
        meta = json.loads((out / "meta.json").read_text())
        rows = report.read_csv(out / "sweep.csv")
        extreme_rows = report.read_csv(out / "extremes.csv") if (out / "extremes.csv").exists() else []
        stat_rows = report.read_csv(out / "stats.csv") if (out / "stats.csv").exists() else []
        env_rows = report.read_csv(out / "envs.csv") if (out / "envs.csv").exists() else meta.get("envs_note")
        missing = meta.get("missing", {})
        quick = meta["quick"]
    else:
        t0 = time.perf_counter()
        quick = args.quick
        _stderr(f"sweep ({'quick' if quick else 'full'}) ...")
        scenes = [s for s in args.scenes.split(",") if s] or None
        rows, missing = run_sweep(quick, scenes=scenes, peers=not args.no_peers, log=_stderr)
        report.write_csv(out / "sweep.csv", rows)
        extreme_rows, stat_rows, env_rows = [], [], None
        budget = 5.0 if quick else 30.0
        if "extremes" not in skip:
            _stderr("extremes ...")
            extreme_rows = run_extremes(quick, budget, log=_stderr)
            report.write_csv(out / "extremes.csv", extreme_rows, EXTREME_FIELDS)
        if "stats" not in skip:
            _stderr("long-run statistics ...")
            stat_rows = gas_statistics(quick, log=_stderr)
            report.write_csv(out / "stats.csv", stat_rows, STAT_FIELDS)
        envs_note = None
        if "envs" not in skip:
            _stderr("environment steps per second ...")
            env_rows = env_rates(quick, log=_stderr)
            if isinstance(env_rows, str):
                envs_note = env_rows
            else:
                report.write_csv(out / "envs.csv", env_rows, ENV_FIELDS)
        else:
            envs_note = env_rows = "left out (--skip envs)"
        meta = {
            "quick": quick,
            "date": timestamp(),
            "machine": machine(),
            "cpus": cpus(),
            "versions": versions(["numba", "pymunk", "billiards", "gymnasium", "matplotlib"]),
            "missing": missing,
            "envs_note": envs_note,
            "budget": budget,
            "duration_s": time.perf_counter() - t0,
        }
        (out / "meta.json").write_text(json.dumps(meta, indent=1))

    meta_text = _meta_text(meta)
    plots = report.plot_all(rows, out)
    (out / "results.md").write_text(report.results_markdown(rows, missing, env_rows, quick, meta_text, plots))
    summary = report.summary_markdown(rows, extreme_rows, stat_rows, quick, meta_text)
    (out / "summary.md").write_text(summary)
    if extreme_rows:
        (out / "extremes.md").write_text(extremes_markdown(extreme_rows, quick, meta.get("budget", 30.0)))
    if stat_rows:
        (out / "stats.md").write_text(stats_markdown(stat_rows))

    print(summary)
    if stat_rows:
        print(stats_markdown(stat_rows))
    if env_rows is not None:
        print(report.env_markdown(env_rows))
    print(f"Wrote {', '.join(sorted(p.name for p in out.iterdir()))} to {out}/")
    if args.readme:
        rel = os.path.relpath(out.resolve(), Path(args.readme).resolve().parent)
        block = report.readme_block(rows, rel.replace(os.sep, "/"), quick)
        write_outputs(block, markdown=args.readme, block=report.README_BLOCK, echo=False)
    exact_fail = [r for r in extreme_rows if r["mode"] == "exact" and r["status"] != "pass"]
    return 1 if exact_fail else 0


if __name__ == "__main__":
    sys.exit(main())
