"""The learning curve of a ``train_ppo`` run: success rate and return against env steps, as a PNG.

Drawn from what the run folder already holds: the training episodes of its monitor files
(``monitor.csv``, or ``<i>.monitor.csv`` per sub-env) and, when the run evaluated, the
EvalCallback's log (``eval/evaluations.npz``: deterministic episodes, the same ones each time).
A training episode is placed at the env steps of all the episodes that had ended by then (its
own included), a little behind the run's step count, which also counts the steps of episodes still
running; its curve is a running mean over ``window`` episodes. Needs matplotlib (the ``plot`` extra).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from collision_env.extras import require

CURVE_FILE = "learning_curve.png"
EVAL_LOG = Path("eval") / "evaluations.npz"


def training_episodes(run_dir: str | Path) -> dict:
    """The run's training episodes in the order they ended, from every monitor file of the folder:
    ``steps`` (env steps of the episodes ended so far), ``success`` (0/1) and ``return``.

    A monitor file (stable-baselines3's ``Monitor``/``VecMonitor``) is a JSON line with the start
    time, then CSV rows ``r, l, t[, is_success]``, ``t`` counted from that start.
    """
    rows = []
    for path in sorted(Path(run_dir).glob("*monitor.csv")):
        with path.open() as fh:
            start = json.loads(fh.readline().removeprefix("#"))["t_start"]
            for row in csv.DictReader(fh):
                success = {"True": 1.0, "False": 0.0}.get(row.get("is_success") or "", np.nan)
                rows.append((start + float(row["t"]), int(row["l"]), success, float(row["r"])))
    rows.sort()
    table = np.array(rows, dtype=float).reshape(-1, 4)
    return {"steps": np.cumsum(table[:, 1]), "success": table[:, 2], "return": table[:, 3]}


def running_mean(x: np.ndarray, window: int) -> np.ndarray:
    """Mean of the last ``window`` values at each point (of fewer at the start)."""
    sums = np.cumsum(np.insert(np.asarray(x, dtype=float), 0, 0.0))
    idx = np.arange(1, len(x) + 1)
    lo = np.maximum(idx - window, 0)
    return (sums[idx] - sums[lo]) / (idx - lo)


def plot_learning_curve(run_dir: str | Path, title: str = "", window: int = 100) -> Path | None:
    """Write ``<run>/learning_curve.png``; returns its path, or None when the run has no episode yet.

    Raises :class:`collision_env.extras.MissingExtra` without matplotlib.
    """
    require("plot", "the learning curve", checkout=True)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import EngFormatter

    run_dir = Path(run_dir)
    train = training_episodes(run_dir)
    evals = np.load(run_dir / EVAL_LOG) if (run_dir / EVAL_LOG).is_file() else None
    if not len(train["steps"]) and evals is None:
        return None
    fig, (ax_success, ax_return) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    if len(train["steps"]):
        label = f"training episodes (mean of the last {window})"
        ax_success.plot(train["steps"], 100 * running_mean(train["success"], window), color="tab:blue", label=label)
        ax_return.plot(train["steps"], running_mean(train["return"], window), color="tab:blue", label=label)
    if evals is not None:
        label = f"evaluation ({evals['results'].shape[1]} deterministic episodes)"
        if "successes" in evals:
            ax_success.plot(evals["timesteps"], 100 * evals["successes"].mean(axis=1), "o-", color="tab:orange")
        ax_return.plot(evals["timesteps"], evals["results"].mean(axis=1), "o-", color="tab:orange", label=label)
        ax_success.plot([], [], "o-", color="tab:orange", label=label)
    ax_success.set(xlabel="env steps", ylabel="success rate (%)", ylim=(-2, 102))
    ax_return.set(xlabel="env steps", ylabel="episode return")
    for ax in (ax_success, ax_return):
        ax.grid(alpha=0.3)
        ax.xaxis.set_major_formatter(EngFormatter(sep=""))  # 200k, 1M
    ax_success.legend(loc="lower right", fontsize="small")
    fig.suptitle(title or run_dir.name)
    path = run_dir / CURVE_FILE
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
