"""Train cheap, evaluate exact: what the engine's fidelity mode costs and buys a PPO agent.

    python -m agents.study --jobs 2                      # both parts, 3 seeds each (many hours on 2 cores)
    python -m agents.study --part modes --envs CollisionEnv/Line1D-v0 --modes naive:1 exact:1 --seeds 0
    python -m agents.study --part presets --presets CollisionEnv/Billiards-v0 --add

Part **modes**: each preset of ``--envs`` (default: every preset) is trained with the shipped
hyperparameters under each engine mode of ``--modes`` (``mode:substeps``, default naive k=1,
posteriori k=1, posteriori k=4 and exact), over several seeds; every policy is then evaluated
deterministically in **exact** mode (and in its own training mode) on the same 100 episodes. The
tables give success per seed, its mean and spread, the training time (wall-clock, and the training
process's CPU time, which a shared machine's load does not stretch) and the engine's share of it,
so the trade is read off directly: is a policy trained on a cheaper, less exact engine as good
when the impacts are exact, and how much training time did the cheaper engine save? The trade
table sums it up per preset, the Pareto figure (``pareto.png``) sets training time against
exact-evaluated success, and the rule says, from the same figures, where training cheap pays and
where it costs points (``Pegs`` and ``Fence``, the presets built for it: small, fast balls, narrow
targets, long control steps; in ``Fence`` the one shot commits the outcome before any impact is seen).

Part **presets**: every registered preset is trained in exact mode over the same seeds and set
beside the random and the scripted (exact-aim) baselines on the same evaluation episodes; a preset
whose shipped entry trains on the predicted observation is trained on the plain one too, and one
whose entry uses velocity control is trained with nudges too (``--variants``).

Every run records where its training time went (``agents.timing``); the time-split table shows it,
and the closing rule says when a cheaper engine mode can pay. ``--add`` adds runs to an earlier
study's ``study.json`` (a cell run again replaces its figures), so a study can be run in parts.

Writes ``study.json`` (every figure), ``modes.md``, ``presets.md``, ``time_split.md``, ``modes.png`` and
``pareto.png`` into
``--docs`` (default ``docs/agents``: the site's agents pages), and with ``--readme`` the tables into a
page's ``agents:study`` block too. Training runs go to ``--output`` (default ``runs/study``). With
``--jobs 2`` two runs train at once (one core each), as every figure on those pages was measured.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from agents.config import UsageError, as_int, check_env_id, hyperparams_for, read_run, run_cli
from agents.evaluate import pct
from collision_env.bench.machine import cpus, machine, timestamp, versions
from collision_env.bench.readme import write_outputs
from collision_env.engine import MODES

DEFAULT_MODES = ("naive:1", "posteriori:1", "posteriori:4", "exact:1")
DEFAULT_SEEDS = (0, 1, 2)
README_BLOCK = "agents:study"


def parse_mode(spec: str) -> tuple[str, int]:
    mode, _, k = spec.partition(":")
    if mode not in MODES:
        raise UsageError(f"--modes: expected mode:substeps with mode {'|'.join(MODES)}, got {spec!r}")
    try:
        substeps = int(k or 1)
    except ValueError:
        raise UsageError(f"--modes: bad substeps in {spec!r}") from None
    if substeps < 1 or (mode == "exact" and substeps != 1):
        raise UsageError(f"--modes: substeps must be >= 1 (and 1 for exact), got {spec!r}")
    return mode, substeps


def _label(mode: str, substeps: int) -> str:
    return mode if mode == "exact" else f"{mode} k={substeps}"


# ------------------------------------------------------------------------------------ the work
def train_and_evaluate(task: dict) -> dict:
    """One study cell: train (no eval or checkpoint callbacks, so the time is training only), then
    evaluate in exact mode and, if different, in the training mode. Runs in a worker process."""
    import torch

    from agents.config import run_label
    from agents.evaluate import evaluate
    from agents.train_ppo import train

    torch.set_num_threads(1)
    env_kwargs = task.get("env_kwargs") or {}
    name = run_label(task["env_id"], task["mode"], task["substeps"], task["seed"])
    name += "".join(f"-{value}" for value in env_kwargs.values())
    run_dir = train(
        task["env_id"],
        timesteps=task["timesteps"],
        seed=task["seed"],
        mode=task["mode"],
        substeps=task["substeps"],
        env_kwargs=env_kwargs,
        output=task["output"],
        run_name=name,
        eval_freq=0,
        save_freq=0,
        overwrite=True,
        log=lambda *a: None,
    )
    run = read_run(run_dir)
    out = {
        **task,
        "run": str(run_dir),
        "train_seconds": run["train_seconds"],
        "train_cpu_seconds": run["train_cpu_seconds"],
        "timesteps_done": run["timesteps_done"],
        "time_split": run["time_split"],
        "observe": _observation(run["env_kwargs"]),
        "control": _control(task["env_id"], run["env_kwargs"]),
    }
    exact = evaluate(run_dir, episodes=task["episodes"], mode="exact", baselines=())
    out["exact"] = exact["policies"]["ppo"]
    if task["mode"] != "exact":
        own = evaluate(run_dir, episodes=task["episodes"], mode=task["mode"], substeps=task["substeps"], baselines=())
        out["own"] = own["policies"]["ppo"]
    else:
        out["own"] = out["exact"]
    return out


def baselines(task: dict) -> dict:
    """Random and scripted baselines of one preset in exact mode, on the study's evaluation episodes."""
    from agents.evaluate import EVAL_SEED, make_env, play, random_policy, scripted_baseline

    env = make_env(task["env_id"], {})  # as agents.evaluate builds the env PPO is evaluated on
    out = {"env_id": task["env_id"], "random": play(env, random_policy(EVAL_SEED), task["episodes"], EVAL_SEED)}
    scripted = scripted_baseline(env)
    out["scripted"] = None if scripted is None else play(env, scripted, task["episodes"], EVAL_SEED)
    env.close()
    return out


def _run_all(fn, tasks: list, jobs: int, log) -> list:
    results = []
    if jobs <= 1:
        for i, task in enumerate(tasks):
            results.append(fn(task))
            log(f"  [{i + 1}/{len(tasks)}] {_describe(task)} done")
        return results
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for i, result in enumerate(pool.map(fn, tasks)):
            results.append(result)
            log(f"  [{i + 1}/{len(tasks)}] {_describe(tasks[i])} done")
    return results


def _describe(task: dict) -> str:
    what = task["env_id"]
    if "mode" in task:
        what += f" {_label(task['mode'], task['substeps'])} seed {task['seed']}"
    return what


# ------------------------------------------------------------------------------------- tables
def _spread(values: list) -> str:
    mean = statistics.fmean(values)
    if len(values) < 2:
        return pct(mean)
    return f"{pct(mean)} ± {100 * statistics.stdev(values):.0f}"


def _seconds(rows: list) -> float:
    """Median training wall-clock over seeds (a shared machine's noise hits single runs)."""
    return statistics.median(r["train_seconds"] for r in rows)


_CLOCK_NAME = {"cpu": "CPU time", "wall": "wall-clock (some runs predate the CPU time's record)"}


def _clock(groups: dict) -> str:
    """The training time a preset's modes are compared by: ``"cpu"`` when every run of every mode
    recorded its CPU time (wall-clock on a shared machine varies with the other jobs, CPU time with the
    work), else ``"wall"``."""
    rows = [r for rs in groups.values() for r in rs]
    return "cpu" if all(r.get("train_cpu_seconds") is not None for r in rows) else "wall"


def _time(rows: list, clock: str) -> float:
    """Median training time over seeds on ``clock`` (see :func:`_clock`)."""
    return statistics.median(r["train_cpu_seconds" if clock == "cpu" else "train_seconds"] for r in rows)


def _cpu(rows: list) -> str:
    """Median training CPU time over seeds, in seconds ("n/a" for runs recorded before it was measured)."""
    times = [r["train_cpu_seconds"] for r in rows if r.get("train_cpu_seconds") is not None]
    return f"{statistics.median(times):.0f}" if len(times) == len(rows) else "n/a"


def _engine_share(rows: list) -> float | None:
    """Median over seeds of the engine's share of the training time (None where it was not timed)."""
    shares = [r["time_split"]["engine"] / r["train_seconds"] for r in rows if r["time_split"]["engine"] is not None]
    return statistics.median(shares) if shares else None


def _share(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:.0f} %"


def _by_env_and_mode(rows: list) -> dict:
    """{env_id: {(mode, substeps): [rows sorted by seed]}} for the modes part, in run order."""
    out: dict = {}
    for r in rows:
        if r["part"] == "modes":
            out.setdefault(r["env_id"], {}).setdefault((r["mode"], r["substeps"]), []).append(r)
    for groups in out.values():
        for rs in groups.values():
            rs.sort(key=lambda r: r["seed"])
    return out


def modes_table(rows: list) -> str:
    tables = []
    for env_id, groups in _by_env_and_mode(rows).items():
        first, clock = next(iter(groups.values()))[0], _clock(groups)
        lines = [
            f"**`{env_id}`**: PPO with the shipped hyperparameters ({first['timesteps_done']:,} steps), "
            f"trained under each engine mode, evaluated deterministically on the same {first['episodes']} "
            "episodes. Success: mean ± standard deviation over seeds, then each seed's figure; training "
            f"time: median over seeds; ÷ exact's: of the {_CLOCK_NAME[clock]}.",
            "",
            "| trained in | success, evaluated exact | per seed | success in its own mode | "
            "training time (s) | CPU time (s) | ÷ exact's | engine's share of it |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
        ]
        exact_rows = groups.get(("exact", 1))
        exact_time = _time(exact_rows, clock) if exact_rows else None
        for (mode, k), rs in groups.items():
            exact = [r["exact"]["success_rate"] for r in rs]
            own = [r["own"]["success_rate"] for r in rs]
            secs = _seconds(rs)
            ratio = f"{_time(rs, clock) / exact_time:.2f}" if exact_time else "n/a"
            lines.append(
                f"| {_label(mode, k)} | {_spread(exact)} | {' / '.join(pct(x) for x in exact)} | "
                f"{_spread(own)} | {secs:.0f} | {_cpu(rs)} | {ratio} | {_share(_engine_share(rs))} |"
            )
        tables.append("\n".join(lines))
    return "\n\n".join(tables)


def _mean_exact(rows: list) -> float:
    return statistics.fmean(r["exact"]["success_rate"] for r in rows)


#: The speed-up over exact training from which a cheap mode "pays": runs of the same work differ by
#: a few per cent in CPU time (OneBallTarget's 12 runs: 55-62 s), so a smaller one is not told apart.
PAYS_AT = 1.05


def comparisons(rows: list) -> list[dict]:
    """Per preset of the modes part that has exact-trained runs and cheaper ones: the exact-trained
    mean exact-evaluated success ``ref``, the largest standard deviation over seeds of any of its
    modes ``spread``, the engine's share of exact training ``f``, and per cheaper mode (``cheap``,
    in run order) its exact-evaluated success, its loss against ``ref``, how many times as fast it
    trained (on the preset's ``clock``, :func:`_clock`), and the verdict: ``"costs"`` (a loss beyond
    the spread), ``"pays"`` (at least :data:`PAYS_AT` times as fast, no such loss) or ``"no gain"``."""
    out = []
    for env_id, groups in _by_env_and_mode(rows).items():
        exact_rows = groups.get(("exact", 1))
        cheap = {key: rs for key, rs in groups.items() if key != ("exact", 1)}
        if not exact_rows or not cheap:
            continue
        ref, clock = _mean_exact(exact_rows), _clock(groups)
        spread = max(
            statistics.stdev([r["exact"]["success_rate"] for r in rs]) if len(rs) > 1 else 0.0 for rs in groups.values()
        )
        modes = []
        for (mode, k), rs in cheap.items():
            success = _mean_exact(rs)
            loss, speed = ref - success, _time(exact_rows, clock) / _time(rs, clock)
            verdict = "costs" if loss > spread and loss >= 0.01 else "pays" if speed >= PAYS_AT else "no gain"
            modes.append(
                {"mode": mode, "substeps": k, "success": success, "loss": loss, "speed": speed, "verdict": verdict}
            )
        out.append(
            {
                "env_id": env_id,
                "ref": ref,
                "spread": spread,
                "f": _engine_share(exact_rows),
                "clock": clock,
                "cheap": modes,
            }
        )
    return out


def modes_reading(rows: list) -> str:
    """What the modes tables say, in words generated from the same figures."""
    out = []
    for c in comparisons(rows):
        ref, spread = c["ref"], c["spread"]
        diffs = [-m["loss"] for m in c["cheap"]]
        ratios = [1 / m["speed"] for m in c["cheap"]]
        worst = min(diffs)
        verdict = (
            "within the seed-to-seed spread"
            if max(abs(d) for d in diffs) <= spread
            else f"at worst {100 * -worst:.0f} points below"
            if worst < 0
            else "no worse"
        )
        out.append(
            f"- `{c['env_id']}`: policies trained in the cheaper modes succeed in exact mode "
            f"{pct(ref + min(diffs))}–{pct(ref + max(diffs))} against exact-trained {pct(ref)}, "
            f"{verdict} (largest standard deviation over seeds {100 * spread:.0f} points), after "
            f"{min(ratios):.2f}–{max(ratios):.2f}× exact mode's training {_CLOCK_NAME[c['clock']].split(' (')[0]}."
        )
    return "\n".join(out)


def trade_table(rows: list) -> str:
    """One row per preset of the modes part, one column per training mode: the trade at a glance."""
    envs = _by_env_and_mode(rows)
    if not envs:
        return ""
    keys = {key for groups in envs.values() for key in groups}
    modes = sorted(keys, key=lambda key: (key == ("exact", 1), key))  # cheaper modes by name, exact last
    lines = [
        "The trade, per preset: success of the policies trained in each mode, evaluated exact (mean over seeds; "
        "in brackets: evaluated in the mode they trained in), and their median training time: CPU seconds, or "
        'wall-clock seconds ("wall") where some run of the preset predates the CPU time\'s record; the '
        "engine's share is that of exact training.",
        "",
        "| env | engine's share | " + " | ".join(_label(m, k) for m, k in modes) + " |",
        "|---|---:|" + "---:|" * len(modes),
    ]
    for env_id, groups in envs.items():
        cells, clock = [], _clock(groups)
        unit = "s CPU" if clock == "cpu" else "s wall"
        for key in modes:
            rs = groups.get(key)
            if not rs:
                cells.append("")
                continue
            own = statistics.fmean(r["own"]["success_rate"] for r in rs)
            cells.append(f"{pct(_mean_exact(rs))} ({pct(own)}), {_time(rs, clock):.0f} {unit}")
        exact_rows = groups.get(("exact", 1))
        share = _share(_engine_share(exact_rows)) if exact_rows else "n/a"
        lines.append(f"| `{env_id}` | {share} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


@functools.cache
def _entry_setting(env_id: str) -> str | None:
    """The observation and control of the env's hyperparameter entry (None: no entry)."""
    try:
        entry = hyperparams_for(env_id).get("env_kwargs") or {}
    except UsageError:
        return None
    return _setting({**entry, "observe": _observation(entry), "control": _control(env_id, entry)})


def _control(env_id: str, env_kwargs: dict) -> str:
    """The control a run of ``env_id`` trains with: its ``control`` keyword, else its preset's."""
    from collision_env.envs import REGISTERED, make_config

    if "control" in env_kwargs:
        return env_kwargs["control"]
    reg = REGISTERED.get(env_id)
    return make_config(reg.single.preset).control if reg is not None else "nudge"


def _shipped(row: dict) -> bool:
    """Whether a row trained the env's hyperparameter entry with its current observation and control,
    and no env keywords of its own (its length is the table's steps column)."""
    return not row.get("env_kwargs") and _setting(row) == _entry_setting(row["env_id"])


def _place(row: dict) -> tuple:
    """Where a row goes in a table: presets in registration order, each preset's shipped setting first,
    then the other settings by name."""
    from collision_env.envs import PRESET_IDS

    order = list(PRESET_IDS.values())
    at = order.index(row["env_id"]) if row["env_id"] in order else len(order)
    return (at, not _shipped(row), _setting(row))


def _by_preset(rows: list, base: list) -> dict:
    """{(env_id, setting): [presets-part rows sorted by seed]}, presets in registration order, each
    preset's shipped setting first."""
    groups: dict = {}
    for r in sorted(rows, key=_place):
        if r["part"] == "presets":
            groups.setdefault((r["env_id"], _setting(r)), []).append(r)
    for rs in groups.values():
        rs.sort(key=lambda r: r["seed"])
    return groups


def presets_table(rows: list, base: list) -> str:
    groups = _by_preset(rows, base)
    if not groups:
        return ""
    by_env = {b["env_id"]: b for b in base}
    episodes = next(iter(groups.values()))[0]["episodes"]
    lines = [
        f"Every preset, PPO in exact mode, beside the baselines on the same "
        f"{episodes} evaluation episodes (success rate; mean return in brackets). PPO: mean ± standard "
        "deviation over seeds, then each seed; training time: median over seeds, wall-clock and the training "
        "process's CPU time (n/a: not measured then), with the engine's share of the wall-clock. "
        "Setting: the observation and the control of the shipped hyperparameter entry (marked *shipped*), and "
        "beside it the plain observation where the entry changes it (`predicted`: the env's "
        '`observe="predicted"`, each ball\'s next wall impact as the engine predicts it; `predicted (scoring)`: '
        'with `predicted_impact="scoring"`, a scoring ball\'s first predicted impact that lands on a pending '
        "target within the look-ahead, however many bounces ahead, else its next) and nudges where the "
        "entry uses velocity control (`nudge`: the action is each step's velocity change; `velocity`: the env's "
        '`control="velocity"`, the velocity to steer to and an engage flag; `shot`: the env\'s `control="shot"`, '
        "one velocity, set in the first step, for the whole episode). The other rows keep the rest of "
        "the entry as it stood when they were trained (such as an aiming term taken from the prediction; the "
        "steps column gives their length). The random and scripted baselines play the env's defaults (plain "
        "observation, nudges; in the presets trained with velocity control the scripted policy plays alike "
        "under either control).",
        "",
        "| env | setting | steps | PPO success | per seed | PPO return | random | scripted (exact aim) | "
        "training time (s) | CPU time (s) | engine's share |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    fmt = lambda p: "n/a" if p is None else f"{pct(p['success_rate'])} ({p['mean_return']:.2f})"  # noqa: E731
    for (env_id, setting), rs in groups.items():
        succ = [r["exact"]["success_rate"] for r in rs]
        ret = statistics.fmean(r["exact"]["mean_return"] for r in rs)
        b = by_env.get(env_id, {})
        label = f"{setting} (*shipped*)" if _shipped(rs[0]) else setting
        lines.append(
            f"| `{env_id}` | {label} | {rs[0]['timesteps_done']:,} | {_spread(succ)} | "
            f"{' / '.join(pct(x) for x in succ)} | {ret:.2f} | {fmt(b.get('random'))} | "
            f"{fmt(b.get('scripted'))} | {_seconds(rs):.0f} | {_cpu(rs)} | {_share(_engine_share(rs))} |"
        )
    return "\n".join(lines)


def split_table(rows: list) -> str:
    """Where the training time went, per preset, setting and mode (median shares over seeds)."""
    from agents.timing import PARTS

    groups: dict = {}
    for r in sorted(rows, key=_place):
        key = (r["env_id"], _setting(r), r["mode"], r["substeps"])
        runs = groups.setdefault(key, {})
        runs[r["run"]] = r  # a run counted in both parts is one run
    if not groups:
        return ""
    lines = [
        "Where the training time goes (`agents.timing`: timers around the engine's step, the env's step, the "
        "policy's forward passes and PPO's update, in every training run above; median share over seeds):",
        "",
        "| env | setting | trained in | training time (s) | CPU time (s) | " + " | ".join(PARTS) + " |",
        "|---|---|---|---:|---:|" + "---:|" * len(PARTS),
    ]
    for (env_id, setting, mode, k), runs in groups.items():
        rs = list(runs.values())
        cells = []
        for part in PARTS:
            shares = [r["time_split"][part] / r["train_seconds"] for r in rs if r["time_split"][part] is not None]
            cells.append(_share(statistics.median(shares) if shares else None))
        lines.append(
            f"| `{env_id}` | {setting} | {_label(mode, k)} | {_seconds(rs):.0f} | {_cpu(rs)} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines)


def rule(rows: list, base: list) -> str:
    """The rule for choosing a training mode, stated with this study's figures: where training cheap
    paid (faster, no exact-evaluated loss beyond the seed spread) and where it cost points."""
    measured = {env: _engine_share(rs) for (env, setting), rs in _by_preset(rows, base).items() if _shipped(rs[0])}
    shares = {env: f for env, f in measured.items() if f is not None}
    found = comparisons(rows)
    lines = []
    for c in found:
        for m in c["cheap"]:
            points = round(100 * m["loss"])
            change = f"loses {points}" if points > 0 else f"gains {-points}" if points < 0 else "loses no"
            lines.append(
                f"`{c['env_id']}` ({_share(c['f'])} of exact training in the engine): "
                f"{_label(m['mode'], m['substeps'])} trains {m['speed']:.2f}× as fast and {change} points of "
                "exact-evaluated success"
            )
    if not shares and not lines:
        return ""
    text = (
        "**Rule**: a cheaper engine mode can only save the engine's share of a training run. With the engine at "
        "a fraction f of the training time, no mode trains more than 1 / (1 − f) times faster (Amdahl's law), "
        "and a policy trained cheap must still be evaluated exact. So train cheap only where f is large and "
        "a cheap mode's policies keep their exact-evaluated success over seeds; train exact elsewhere. A short "
        "exact run tells f: every run's `config.yml` records its time split (`time_split`)."
    )
    if shares:
        text += (
            " Measured here, in exact mode: "
            + "; ".join(f"`{env}` f = {_share(f)} (at most {1 / max(1 - f, 1e-9):.1f}×)" for env, f in shares.items())
            + "."
        )
    verdicts = _verdict_text(found)
    if verdicts:
        text += "\n\n" + verdicts
    if lines:
        text += "\n\n" + "\n".join(f"- {line}." for line in lines)
    return text


def _verdict_text(found: list) -> str:
    """Where training cheap paid and where it cost points, in one sentence each, from :func:`comparisons`."""

    def where(verdict: str) -> str:
        return "; ".join(
            f"`{c['env_id']}` ("
            + ", ".join(
                f"{_label(m['mode'], m['substeps'])} {-round(100 * m['loss']):+d} points at {m['speed']:.2f}×"
                for m in c["cheap"]
                if m["verdict"] == verdict
            )
            + ")"
            for c in found
            if any(m["verdict"] == verdict for m in c["cheap"])
        )

    pays, costs, idle = where("pays"), where("costs"), where("no gain")
    out = []
    if pays:
        out.append(
            f"Training cheap **paid** (at least {PAYS_AT:g}× as fast, exact-evaluated success within the seed "
            f"spread) on {pays}."
        )
    if idle:
        out.append(
            f"It **did not pay** (less than {PAYS_AT:g}× as fast as exact) on {idle}: where few events happen per "
            "step, exact mode "
            "jumps from one to the next while a cheap mode works through every sub-step (and every sub-step of "
            "the look-ahead of a predicted observation)."
        )
    if costs:
        out.append(
            f"It **cost** exact-evaluated success beyond the seed spread on {costs}: there the cheap mode's "
            "errors (tunnelling, late or misplaced impacts) change outcomes, so train exact or with more sub-steps."
        )
    elif found:
        out.append("No preset here lost exact-evaluated success beyond the seed spread by training cheap.")
    return " ".join(out)


def pareto_plot(rows: list, path: Path) -> Path | None:
    """Training time (median over seeds; CPU time, or wall-clock for a preset with runs that predate its
    record) against exact-evaluated success (mean, with the seeds' standard
    deviation), one point per preset and training mode, each preset's modes joined in order of time and
    its Pareto front (no other mode of the preset both faster and better) drawn solid."""
    envs = _by_env_and_mode(rows)
    if not envs:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    markers = dict(zip(("naive", "posteriori", "substep", "cells", "exact"), "v^sDo", strict=False))
    fig, ax = plt.subplots(figsize=(8, 5))
    for i, (env_id, groups) in enumerate(envs.items()):
        color, clock = f"C{i % 10}", _clock(groups)
        points = []
        for (mode, k), rs in groups.items():
            exact = [100 * r["exact"]["success_rate"] for r in rs]
            sd = statistics.stdev(exact) if len(exact) > 1 else 0.0
            points.append((_time(rs, clock), statistics.fmean(exact), sd, mode, k))
        points.sort()
        front, best = [], -1.0
        for t, y, *_ in points:
            if y > best:
                front.append((t, y))
                best = y
        ax.plot([p[0] for p in points], [p[1] for p in points], color=color, alpha=0.3, lw=1)
        label = env_id.split("/")[-1] + ("" if clock == "cpu" else " (wall-clock)")
        ax.plot(*zip(*front, strict=True), color=color, lw=1.5, label=label)
        for t, y, sd, mode, k in points:
            ax.errorbar(t, y, yerr=sd, color=color, marker=markers.get(mode, "o"), ms=7, capsize=2)
            ax.annotate(_label(mode, k), (t, y), textcoords="offset points", xytext=(5, 4), fontsize=7, color=color)
    ax.set_xscale("log")
    seconds = FuncFormatter(lambda x, _: f"{x:g}")  # 50, 100, 200 rather than 5 x 10^1
    ax.xaxis.set_major_formatter(seconds)
    ax.xaxis.set_minor_formatter(seconds)
    ax.set_xlabel("training CPU time per seed (s, median; log scale)")
    ax.set_ylabel("success evaluated exact (%, mean ± sd over seeds)")
    ax.set_ylim(-3, 105)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right", title="preset (solid: its Pareto front)", title_fontsize=8)
    ax.set_title("Train cheap, evaluate exact: training time against exact-evaluated success", fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot(rows: list, path: Path) -> Path | None:
    """Per env: success evaluated exact and in its own mode (bars: means, dots: seeds), and training time
    (bars: medians)."""
    envs = _by_env_and_mode(rows)
    if not envs:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(envs), 2, figsize=(10, 3.4 * len(envs)), squeeze=False)
    for (env_id, groups), (ax1, ax2) in zip(envs.items(), axes, strict=True):
        labels = [_label(m, k) for m, k in groups]
        for i, rs in enumerate(groups.values()):
            exact = [100 * r["exact"]["success_rate"] for r in rs]
            own = [100 * r["own"]["success_rate"] for r in rs]
            ax1.bar(
                i - 0.2, statistics.fmean(exact), 0.4, color="tab:blue", label="evaluated exact" if i == 0 else None
            )
            ax1.bar(
                i + 0.2,
                statistics.fmean(own),
                0.4,
                color="tab:gray",
                label="evaluated in its own mode" if i == 0 else None,
            )
            ax1.plot([i - 0.2] * len(exact), exact, "k.", ms=6)
            ax1.plot([i + 0.2] * len(own), own, "k.", ms=6)
            ax2.bar(i, _seconds(rs), 0.6, color="tab:orange")
            ax2.plot([i] * len(rs), [r["train_seconds"] for r in rs], "k.", ms=6)
        for ax in (ax1, ax2):
            ax.set_xticks(range(len(labels)), labels, rotation=15)
        ax1.set_ylabel("success rate (%)")
        ax1.set_ylim(0, 105)
        ax1.legend(loc="lower right", fontsize=8)
        ax1.set_title(f"{env_id}: success (dots: seeds)", fontsize=9)
        ax2.set_ylabel("training wall-clock (s)")
        steps = next(iter(groups.values()))[0]["timesteps_done"]
        ax2.set_title(f"{env_id}: training time for {steps:,} steps (bar: median)", fontsize=9)
    axes[-1, 0].set_xlabel("trained in")
    axes[-1, 1].set_xlabel("trained in")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def render(data: dict, docs: Path, readme: Path | None) -> None:
    """Write the tables (and plot) from the study's JSON, and the README block."""
    docs.mkdir(parents=True, exist_ok=True)
    meta = data["meta"]
    stamp = (
        f"Generated by `python -m agents.study` ({meta['date']}, {meta['machine']}, {meta['cpus']} CPUs, "
        f"{meta['jobs']} run(s) at a time, {meta['minutes']:.0f} min); do not edit by hand."
    )
    modes = modes_table(data["rows"])
    presets = presets_table(data["rows"], data["baselines"])
    split = split_table(data["rows"])
    advice = rule(data["rows"], data["baselines"])
    trade = trade_table(data["rows"])
    png = plot(data["rows"], docs / "modes.png")
    pareto = pareto_plot(data["rows"], docs / "pareto.png")
    if modes:
        reading = modes_reading(data["rows"])
        figure = "\n\n![training time against exact-evaluated success](pareto.png)" if pareto else ""
        (docs / "modes.md").write_text(
            f"# Train cheap, evaluate exact\n\n{stamp}\n\n{trade}{figure}\n\n{modes}\n\n{reading}\n\n{advice}\n"
        )
    if presets:
        (docs / "presets.md").write_text(f"# Every preset against the baselines\n\n{stamp}\n\n{presets}\n")
    if split:
        (docs / "time_split.md").write_text(f"# Where the training time goes\n\n{stamp}\n\n{split}\n")
    if readme is not None:
        parts = [stamp]
        if trade:
            parts.append(trade)
        if pareto is not None:
            parts.append(f"![training time against exact-evaluated success]({os.path.relpath(pareto, readme.parent)})")
        if modes:
            parts.append(modes)
            reading = modes_reading(data["rows"])
            if reading:
                parts.append("Read from these figures:\n\n" + reading)
        if png is not None:
            parts.append(f"![success and training time per training mode]({os.path.relpath(png, readme.parent)})")
        if presets:
            parts.append(presets)
        if split:
            parts.append(split)
        if advice:
            parts.append(advice)
        write_outputs("\n\n".join(parts), markdown=readme, block=README_BLOCK, echo=False)


# --------------------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m agents.study",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--part", choices=("modes", "presets", "both"), default="both")
    p.add_argument("--envs", nargs="+", help="presets of the modes part (default: every preset)")
    p.add_argument("--modes", nargs="+", default=list(DEFAULT_MODES), metavar="MODE:K")
    p.add_argument("--presets", nargs="+", help="ids of the presets part (default: every preset)")
    p.add_argument("--seeds", nargs="+", type=int, default=list(DEFAULT_SEEDS))
    p.add_argument(
        "--variants",
        choices=("both", "shipped", "alternatives"),
        default="both",
        help="presets part: the shipped entry, the alternatives beside it (the plain observation beside a predicted "
        "one, nudges beside velocity control), or both",
    )
    p.add_argument("--timesteps", type=float, help="override every entry's n_timesteps (quick looks)")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--jobs", type=int, default=1, help="runs trained at once (one core each)")
    p.add_argument("--output", default="runs/study")
    p.add_argument("--docs", default="docs/agents")
    p.add_argument("--readme", help="write the tables into this README's agents:study block")
    p.add_argument("--render", action="store_true", help="only rewrite tables and plot from <docs>/study.json")
    p.add_argument(
        "--add", action="store_true", help="add these runs to <docs>/study.json (a cell run again replaces its figures)"
    )
    return p


def main(argv: list[str] | None = None) -> dict:
    args = build_parser().parse_args(argv)
    docs = Path(args.docs)
    readme = Path(args.readme) if args.readme else None
    if readme is not None:  # a README without the block's markers would only be found after the study
        from collision_env.bench.readme import markers

        begin, end = markers(README_BLOCK)
        text = readme.read_text() if readme.is_file() else ""
        if begin not in text or end not in text:
            raise UsageError(f"--readme: {readme} has no {begin} ... {end} block to write into")
    if args.render:
        path = docs / "study.json"
        if not path.is_file():
            raise UsageError(f"{path} not found: run the study first")
        try:
            data = json.loads(path.read_text())
            render(data, docs, readme)
        except (ValueError, KeyError, TypeError) as err:
            raise UsageError(f"{path} is not a study result ({type(err).__name__}: {err})") from None
        return data

    from collision_env.envs import PRESET_IDS

    unique = lambda items: list(dict.fromkeys(items))  # noqa: E731  (a repeated cell would train twice)
    modes = unique(parse_mode(m) for m in args.modes)
    presets = unique(check_env_id(e) for e in (args.presets or PRESET_IDS.values()))
    envs = unique(check_env_id(e) for e in (args.envs or PRESET_IDS.values()))
    seeds = unique(as_int("seeds", s, low=0) for s in args.seeds)
    as_int("jobs", args.jobs)
    if args.timesteps is not None:
        as_int("timesteps", args.timesteps)

    def steps(env_id):
        return args.timesteps if args.timesteps is not None else hyperparams_for(env_id)["n_timesteps"]

    common = {"episodes": as_int("episodes", args.episodes), "output": args.output}
    tasks = []
    if args.part in ("modes", "both"):
        tasks += [
            {"part": "modes", "env_id": e, "mode": m, "substeps": k, "seed": s, "timesteps": steps(e), **common}
            for e in envs
            for m, k in modes
            for s in seeds
        ]
    if args.part in ("presets", "both"):
        for env_id in presets:  # the modes part's exact runs of a preset (same seeds) count here too
            tasks += [
                {
                    "part": "presets",
                    "env_id": env_id,
                    "mode": "exact",
                    "substeps": 1,
                    "seed": s,
                    "timesteps": steps(env_id),
                    "env_kwargs": kwargs,
                    **common,
                }
                for kwargs in variants(env_id, args.variants)
                for s in seeds
                if kwargs or not (args.part == "both" and env_id in envs and ("exact", 1) in modes)
            ]
    # compile (or load) the kernels once here: a worker that compiled them would count the compiler's
    # minutes in its training time
    from collision_env.precompile import precompile

    print(f"kernels ready in {precompile():.1f} s (not counted in any training time)")
    start = time.perf_counter()
    print(f"{len(tasks)} training runs, {args.jobs} at a time ...")
    rows = _run_all(train_and_evaluate, tasks, args.jobs, print)
    if args.part == "both":  # the shared runs count for the presets table too
        rows += [
            {**r, "part": "presets"}
            for r in rows
            if r["part"] == "modes" and r["mode"] == "exact" and r["env_id"] in presets
        ]
    base = []
    if args.part in ("presets", "both"):
        print("baselines ...")
        base = _run_all(baselines, [{"env_id": e, "episodes": args.episodes} for e in presets], args.jobs, print)
    minutes = (time.perf_counter() - start) / 60
    if args.add:
        rows, base, minutes = _added(docs / "study.json", rows, base, minutes)
    data = {
        "meta": {
            "date": timestamp(),
            "machine": machine(),
            "cpus": cpus(),
            "jobs": args.jobs,
            "minutes": minutes,
            "versions": versions(["gymnasium", "stable_baselines3", "torch"]),
        },
        "rows": rows,
        "baselines": base,
    }
    docs.mkdir(parents=True, exist_ok=True)
    write_outputs("", data, json_path=docs / "study.json", echo=False)
    render(data, docs, readme)
    print(modes_table(rows))
    print()
    print(presets_table(rows, base))
    print()
    print(split_table(rows))
    return data


def variants(env_id: str, which: str = "both") -> list:
    """The env keywords the presets part trains ``env_id`` with: the shipped entry (``{}``) and its
    alternatives, each changing one setting back to the env's default (so both are reported): the
    plain observation when the entry trains on the predicted one, nudges when it uses velocity
    control. ``which`` picks ``"shipped"``, ``"alternatives"`` or ``"both"``."""
    entry = hyperparams_for(env_id).get("env_kwargs") or {}
    out: list[dict] = [{}] if which in ("both", "shipped") else []
    if which in ("both", "alternatives"):
        if entry.get("observe", "plain") != "plain":
            out.append({"observe": "plain"})
        if entry.get("control", "nudge") != "nudge":
            out.append({"control": "nudge"})
    return out


def _observation(env_kwargs: dict) -> str:
    """A run's observation by name: ``plain``, ``predicted`` (each ball's next wall impact), or
    ``predicted (scoring)`` (a scoring ball's first predicted impact on a pending target)."""
    observe = env_kwargs.get("observe", "plain")
    if observe == "predicted" and env_kwargs.get("predicted_impact", "next") == "scoring":
        return "predicted (scoring)"
    return observe


def _setting(row: dict) -> str:
    """What a presets row trained on: its observation and its control."""
    return f"{row['observe']}, {row.get('control', 'nudge')}"


def _cell(row: dict) -> tuple:
    return (row["part"], row["env_id"], row["mode"], row["substeps"], row["seed"], _setting(row))


def _added(path: Path, rows: list, base: list, minutes: float) -> tuple:
    """These runs and baselines added to an earlier study's (``--add``): a cell or preset measured again
    replaces its earlier figures; the minutes add up."""
    if not path.is_file():
        raise UsageError(f"--add: {path} not found: run the study first")
    try:
        old = json.loads(path.read_text())
        new_cells = {_cell(r) for r in rows}
        new_envs = {b["env_id"] for b in base}
        rows = [r for r in old["rows"] if _cell(r) not in new_cells] + rows
        base = [b for b in old["baselines"] if b["env_id"] not in new_envs] + base
        return rows, base, old["meta"]["minutes"] + minutes
    except (ValueError, KeyError, TypeError) as err:
        raise UsageError(f"--add: {path} is not a study result ({type(err).__name__}: {err})") from None


if __name__ == "__main__":
    run_cli(main, prog="agents.study", extras=("train", "plot"))
