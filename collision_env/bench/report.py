"""Outputs of the study: CSV, Markdown tables, the three plots, the generated summary, the README block.

Everything here is computed from the sweep's rows (and the extremes and statistics rows), so the
summary's statements are regenerated with the figures and never typed by hand.
"""

from __future__ import annotations

import csv
import math
import re
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import numpy as np

from .sweep import FIELDS

#: Final-state errors (in radii) at or below this are round-off: such runs "match exact".
ROUND_OFF = 1e-9
#: Error levels (in radii) the summary's rules are stated for.
LEVELS = (1e-6, 1e-3, 1e-1)
PLOT_FLOOR = 1e-16
#: the README block this study rewrites (see :mod:`collision_env.bench.readme`)
README_BLOCK = "bench:study"


# --------------------------------------------------------------------------- CSV
def write_csv(path: str | Path, rows: list[dict], fields: Sequence[str] = FIELDS) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: _csv_value(r.get(k, "")) for k in fields})


def _csv_value(v):
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return v


def read_csv(path: str | Path) -> list[dict]:
    """Rows back from :func:`write_csv`, numbers as numbers."""
    out = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            out.append({k: _parse(v) for k, v in row.items()})
    return out


def _parse(v):
    if v in ("True", "False"):
        return v == "True"
    try:
        f = float(v)
    except (TypeError, ValueError):
        return v
    if re.fullmatch(r"-?\d+", v):
        return int(v)
    return f


# --------------------------------------------------------------------------- helpers
def ok_rows(rows: list[dict]) -> list[dict]:
    return [r for r in rows if r.get("status") == "ok"]


def family_order(rows: list[dict]) -> list[str]:
    """Families in a stable, meaningful order: ours (naive, posteriori by k, exact), then peers."""
    fams = list(dict.fromkeys(r["family"] for r in rows))

    def key(f):
        if f == "naive":
            return (0, 0, f)
        if f.startswith("naive k="):
            return (0, int(f.split("=")[1]), f)
        if f.startswith("posteriori"):
            return (1, int(f.split("=")[1]), f)
        if f == "exact":
            return (2, 0, f)
        if f.startswith("pymunk"):
            return (3, 0, f)
        return (4, 0, f)

    return sorted(fams, key=key)


def _fmt(x, digits=2):
    if x is None or x == "" or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return f"{x:,}"
    if x == 0:
        return "0"
    if math.isinf(x):
        return "inf"
    if abs(x) >= 1e4 or abs(x) < 1e-2:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}" if abs(x) < 100 else f"{x:,.0f}"


def _median(values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    return float(np.median(values)) if values else math.nan


def _err(r):
    e = r.get("pos_err")
    return math.inf if e is None or e == "" or (isinstance(e, float) and math.isnan(e)) else float(e)


# --------------------------------------------------------------------------- tables
def results_markdown(
    rows: list[dict],
    missing: dict,
    env_rows: list[dict] | str | None,
    quick: bool,
    meta: str,
    plots: Sequence[str] = (),
) -> str:
    """The sweep's page: its tables, with ``plots`` (file names beside the page) after the intro."""
    ok = ok_rows(rows)
    fams = family_order(ok)
    mid_dt = 0.01 if any(r["dt"] == 0.01 for r in ok) else sorted({r["dt"] for r in ok})[0]
    lines = [
        "## Speed/accuracy sweep",
        "",
        f"`python -m collision_env.bench{' --quick' if quick else ''}` — {meta}. Every run is compared with "
        "exact mode's reference over a short horizon (≤ 5 collisions per ball for chaotic scenes). Cost is the best "
        "of the timed repeats; compare ratios within one run. Error = final-state position error in radii.",
        "",
        *(f"![{p}]({p})" for p in plots),
        *([""] if plots else []),
        f"### At control step dt = {mid_dt:g} s",
        "",
        "| scene | n | engine / mode | µs/step | wall s per sim s | error (radii) | impact time err max (s) "
        "| matched / missed / spurious | tunnelled pairs | escapes | energy drift |",
        "|---|---:|---|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    for r in sorted(
        (r for r in ok if r["dt"] == mid_dt),
        key=lambda r: (
            list(dict.fromkeys(x["scene"] for x in rows)).index(r["scene"]),
            r["n"],
            fams.index(r["family"]),
        ),
    ):
        lines.append(
            f"| {r['scene']} | {r['n']} | {r['family']} | {_fmt(r['us_per_step'], 3)} | {_fmt(r['wall_per_sim_s'])} "
            f"| {_fmt(r['pos_err'])} | {_fmt(r['t_err_max'])} | {r['matched']} / {r['missed']} / {r['spurious']} "
            f"| {r['tunnelled_pairs']} | {r['escapes']} | {_fmt(r['energy_drift'])} |"
        )
    # error by dt, for each scene at its largest ball count
    dts = sorted({r["dt"] for r in ok})
    lines += [
        "",
        "### Final-state error (radii) against the control step, at each scene's largest ball count",
        "",
        "| scene | n | engine / mode | " + " | ".join(f"dt={d:g}" for d in dts) + " |",
        "|---|---:|---|" + "---:|" * len(dts),
    ]
    largest: dict[str, int] = {}
    for r in ok:
        largest[r["scene"]] = max(largest.get(r["scene"], 0), r["n"])
    for scene, n in largest.items():
        for f in fams:
            cells = []
            have = False
            for d in dts:
                rr = [r for r in ok if r["scene"] == scene and r["n"] == n and r["family"] == f and r["dt"] == d]
                cells.append(_fmt(rr[0]["pos_err"]) if rr else "")
                have |= bool(rr)
            if have:
                lines.append(f"| {scene} | {n} | {f} | " + " | ".join(cells) + " |")
    # what could not run
    notes = sorted(
        {(r["family"], r["scene"], r.get("note", "")) for r in rows if r.get("status") not in ("ok", "timed")}
    )
    if notes or missing:
        lines += ["", "### What could not run", ""]
        for name, why in missing.items():
            lines.append(f"- {name}: {why}")
        grouped = defaultdict(list)
        for fam, scene, note in notes:
            grouped[(fam, note)].append(scene)
        for (fam, note), scenes in grouped.items():
            lines.append(f"- {fam} on {', '.join(sorted(set(scenes)))}: {note}")
    if env_rows is not None:
        lines += ["", env_markdown(env_rows)]
    lines.append("")
    return "\n".join(lines)


def env_markdown(env_rows: list[dict] | str) -> str:
    if isinstance(env_rows, str):
        return f"### Environment steps per second\n\n{env_rows}\n"
    lines = [
        "### Environment steps per second (random actions, same run)",
        "",
        "| env id | matching scene | mode | single env steps/s | vector env (64) steps/s |",
        "|---|---|---|---:|---:|",
    ]
    for r in env_rows:
        lines.append(
            f"| {r['env']} | {r['scene']} | {r['mode']} | {_fmt(r['single_steps_per_s'])} "
            f"| {_fmt(r['vector_steps_per_s'])} |"
        )
    lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------- plots
def _style(fams):
    import matplotlib

    cmap = matplotlib.colormaps["tab10"]
    style = {}
    for i, f in enumerate(fams):
        marker = "o" if f.startswith(("naive", "posteriori", "exact")) else ("s" if f.startswith("pymunk") else "D")
        style[f] = dict(color=cmap(i % 10), marker=marker)
    return style


def plot_all(rows: list[dict], out: Path) -> list[str]:
    """The three plots as PNG files in ``out``; returns their file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = ok_rows(rows)
    fams = family_order(ok)
    style = _style(fams)
    names = []

    # 1. Pareto front: error vs cost, one panel per scene at its largest ball count
    largest: dict[str, int] = {}
    for r in ok:
        largest[r["scene"]] = max(largest.get(r["scene"], 0), r["n"])
    scenes = list(largest)
    cols = 5 if len(scenes) > 4 else len(scenes)
    nrows = math.ceil(len(scenes) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.0 * cols, 3.4 * nrows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes, strict=False):
        n = largest[scene]
        pts = [r for r in ok if r["scene"] == scene and r["n"] == n]
        for f in fams:
            fr = sorted((r for r in pts if r["family"] == f), key=lambda r: r["wall_per_sim_s"])
            if not fr:
                continue
            x = [r["wall_per_sim_s"] for r in fr]
            y = [max(_err(r), PLOT_FLOOR) for r in fr]
            ax.plot(x, y, label=f, lw=1, ms=4, **style[f])
        front = _pareto([(r["wall_per_sim_s"], max(_err(r), PLOT_FLOOR)) for r in pts])
        if front:
            fx, fy = zip(*front, strict=False)
            ax.step(fx, fy, where="post", color="k", lw=2, alpha=0.25, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{scene}, n={n}", fontsize=9)
        ax.set_xlabel("wall s per simulated s", fontsize=8)
        ax.set_ylabel("final-state error (radii)", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[len(scenes) :]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=8)
    fig.suptitle("Error against cost (each point one control step dt; lower left is better)", fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    names.append("pareto.png")
    fig.savefig(out / names[-1], dpi=110)
    plt.close(fig)

    # 2. cost vs number of balls (the dilute gas, at the middle dt; past 64 balls timed only)
    gas = [r for r in rows if r["scene"] == "dilute_gas" and r.get("status") in ("ok", "timed")]
    dts = sorted({r["dt"] for r in gas})
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    if gas:
        dt = 0.01 if 0.01 in dts else dts[len(dts) // 2]
        for f in fams:
            fr = sorted((r for r in gas if r["family"] == f and r["dt"] == dt), key=lambda r: r["n"])
            if fr:
                axes[0].plot([r["n"] for r in fr], [r["wall_per_sim_s"] for r in fr], label=f, **style[f])
                axes[1].plot([r["n"] for r in fr], [r["us_per_step"] for r in fr], label=f, **style[f])
        for ax, lab in zip(axes, ("wall s per simulated s", "µs per control step"), strict=True):
            ax.set_xscale("log", base=2)
            ax.set_yscale("log")
            ax.set_xlabel("number of balls")
            ax.set_ylabel(lab)
            ax.grid(alpha=0.3, which="both")
        axes[0].set_title(f"dilute gas (packing 0.05, box grows with n), dt = {dt:g} s", fontsize=10)
        axes[1].set_title("the same per step", fontsize=10)
        axes[1].legend(fontsize=8)
    fig.tight_layout()
    names.append("cost_vs_balls.png")
    fig.savefig(out / names[-1], dpi=110)
    plt.close(fig)

    # 3. error vs tunnelling scale v h / r
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for f in fams:
        fr = [r for r in ok if r["family"] == f]
        if not fr:
            continue
        x = [r["tunnel_scale"] for r in fr]
        axes[0].scatter(
            x,
            [max(_err(r), PLOT_FLOOR) for r in fr],
            s=12,
            label=f,
            color=style[f]["color"],
            marker=style[f]["marker"],
            alpha=0.7,
        )
        axes[1].scatter(
            x,
            [r["missed"] / max(r["ref_impacts"], 1) for r in fr],
            s=12,
            label=f,
            color=style[f]["color"],
            marker=style[f]["marker"],
            alpha=0.7,
        )
    axes[0].set_yscale("log")
    axes[0].set_ylabel("final-state error (radii)")
    axes[1].set_ylabel("fraction of reference impacts missed")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel("tunnelling scale  v_peak · (dt / substeps) / r_min")
        ax.axvline(1.0, color="k", lw=0.8, ls=":")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("Error against the tunnelling scale (all scenes, ball counts and steps)", fontsize=10)
    fig.tight_layout()
    names.append("error_vs_tunnelling.png")
    fig.savefig(out / names[-1], dpi=110)
    plt.close(fig)
    return names


def _pareto(points):
    """The lower-left staircase of (cost, error) points."""
    front = []
    best = math.inf
    for x, y in sorted(points):
        if y < best:
            front.append((x, y))
            best = y
    return front


# --------------------------------------------------------------------------- the generated summary
ELASTIC = ("elastic scenes (e = 1)", lambda r: r["elasticity"] == 1.0)
INELASTIC = ("inelastic scenes (e < 1)", lambda r: r["elasticity"] < 1.0)


def floors(rows: list[dict]) -> dict:
    """Per ``(scene, n)``: the spread of exact mode's own runs around the reference (its round-off,
    amplified by chaos over the horizon), at least :data:`ROUND_OFF`. Errors below it are ties."""
    out: dict = {}
    for r in ok_rows(rows):
        key = (r["scene"], r["n"])
        out.setdefault(key, ROUND_OFF)
        if r["family"] == "exact":
            out[key] = max(out[key], _err(r))
    return out


def thresholds(
    rows: list[dict],
    family: str,
    level: float,
    key: str = "speed_dt_over_r",
    where: Callable[[dict], bool] = lambda r: True,
    floor: dict | None = None,
) -> tuple[float, int, int]:
    """``(Y, runs below Y, all runs)``: every run of ``family`` with ``key < Y`` has error <= ``level``.

    Y is the smallest ``key`` at which the family's error exceeded ``level`` (inf if it never did).
    ``where`` restricts the runs considered (e.g. to elastic scenes); with ``floor`` (see
    :func:`floors`) an error up to the case's floor counts as within any level.
    """
    fr = [r for r in ok_rows(rows) if r["family"] == family and where(r)]
    floor = floor or {}
    bad = [r[key] for r in fr if _err(r) > max(level, floor.get((r["scene"], r["n"]), 0.0))]
    y = min(bad) if bad else math.inf
    below = sum(r[key] < y for r in fr)
    return y, below, len(fr)


def miss_threshold(
    rows: list[dict], family: str, key: str = "speed_dt_over_r", where: Callable[[dict], bool] = lambda r: True
) -> tuple[float, int]:
    fr = [r for r in ok_rows(rows) if r["family"] == family and where(r)]
    bad = [r[key] for r in fr if r["missed"] > 0 or r["spurious"] > 0]
    return (min(bad) if bad else math.inf), len(fr)


def pareto_check(rows: list[dict]) -> tuple[list[tuple], list[tuple]]:
    """Per (scene, n): runs faster than exact's fastest run that are more accurate than it beyond the
    case's floor (dominated), and those within the floor (ties). Returns (dominated, ties)."""
    ok = ok_rows(rows)
    floor = floors(ok)
    dominated, ties = [], []
    keys = sorted({(r["scene"], r["n"]) for r in ok}, key=lambda k: (k[0], k[1]))
    for scene, n in keys:
        pts = [r for r in ok if r["scene"] == scene and r["n"] == n]
        exact = [r for r in pts if r["family"] == "exact"]
        if not exact:
            continue
        fastest = min(exact, key=lambda r: r["wall_per_sim_s"])
        e_err = _err(fastest)
        f = floor[(scene, n)]
        for r in pts:
            if r["family"] == "exact" or r["wall_per_sim_s"] >= fastest["wall_per_sim_s"]:
                continue
            if _err(r) <= f:
                ties.append((scene, n, r["family"], r["dt"], r["wall_per_sim_s"] / fastest["wall_per_sim_s"]))
            elif _err(r) < e_err - f:
                dominated.append((scene, n, r["family"], r["dt"]))
    return dominated, ties


def cost_ratios(
    rows: list[dict], num: str = "exact", den: str = "naive", counts: Iterable[int] = (1, 2, 4)
) -> tuple[float, float, int]:
    """Per-step cost ratio ``num / den`` at the same scene, n and dt, for n in ``counts``: (median, max, k)."""
    ok = ok_rows(rows)
    index = {(r["scene"], r["n"], r["dt"], r["family"]): r for r in ok}
    ratios = []
    for (scene, n, dt, fam), r in index.items():
        if fam != num or n not in counts:
            continue
        d = index.get((scene, n, dt, den))
        if d and d["us_per_step"] > 0:
            ratios.append(r["us_per_step"] / d["us_per_step"])
    if not ratios:
        return math.nan, math.nan, 0
    return float(np.median(ratios)), float(np.max(ratios)), len(ratios)


def _unmatched_cells(exact) -> tuple[list, bool]:
    """Exact-mode runs whose impacts did not pair one to one with the reference's, and whether all
    of them are inelastic (where the collapse bookkeeping explains them)."""
    cells = [r for r in exact if r["missed"] + r["spurious"]]
    return cells, bool(cells) and all(r["elasticity"] < 1.0 for r in cells)


def _exact_unmatched(exact) -> str:
    """Where exact mode's impacts did not pair one to one with its reference's, and why that can be."""
    cells, collapse = _unmatched_cells(exact)
    where = "; ".join(
        f"{r['scene']} n={r['n']} dt={r['dt']:g}: {r['missed']} missed, {r['spurious']} spurious, "
        f"final-state error {_fmt(_err(r))} radii"
        for r in cells
    )
    text = f", all in these runs ({where})"
    if collapse:
        text += (
            ". In an inelastic collapse, balls pressed together sit at the contact tolerance of a contact group "
            "(1e-9 of the length scale): round-off decides whether a barely touching ball joins a group, which "
            "can split one cascade's resolution over two instants and move its impacts' bookkeeping to a later "
            "cascade, while the motion agrees to the final-state error given"
        )
    return text + "."


def summary_markdown(rows: list[dict], extreme_rows: list[dict], stat_rows: list[dict], quick: bool, meta: str) -> str:
    ok = ok_rows(rows)
    fams = family_order(ok)
    floor = floors(ok)
    lines = [
        "# Which mode to pick when",
        "",
        f"Generated by `python -m collision_env.bench{' --quick' if quick else ''}` from the figures of that run "
        f"({meta}); do not edit by hand. Error = final-state position error against exact mode, in ball radii, "
        "over ≤ 5 collisions per ball; s = v_peak·dt/r_min with dt the control step (v_peak the fastest ball "
        "speed in the reference run, r_min the smallest radius). An error within exact mode's own spread on "
        "that scene (its round-off amplified by chaos, at least 1e-9 radii) counts as a tie with exact.",
        "",
    ]
    exact = [r for r in ok if r["family"] == "exact"]
    if exact:
        worst = max(exact, key=_err)
        t_worst = max(
            (r["t_err_max"] for r in exact if isinstance(r["t_err_max"], float) and not math.isnan(r["t_err_max"])),
            default=math.nan,
        )
        missed = sum(r["missed"] + r["spurious"] for r in exact)
        lines += [
            f"- **exact** matches its reference to round-off (amplified by the gas's chaos over ≤ 5 collisions per "
            f"ball) at every control step: worst final-state error "
            f"{_fmt(_err(worst))} radii ({worst['scene']}, n={worst['n']}, dt={worst['dt']:g}), worst impact-time "
            f"error {_fmt(t_worst)} s, {missed} missed or spurious impacts over {len(exact)} runs"
            + ("." if not missed else _exact_unmatched(exact)),
        ]
    # cheap modes: the rule from the measured error, for elastic and inelastic scenes apart
    for title, where in (ELASTIC, INELASTIC):
        fr_all = [r for r in ok if where(r)]
        if not fr_all:
            continue
        lines += ["", f"Cheaper modes and peers on {title}: each bound holds in every measured run below s = Y", ""]
        for f in fams:
            if f == "exact" or not any(r["family"] == f for r in fr_all):
                continue
            parts = []
            for level in LEVELS:
                y, below, total = thresholds(ok, f, level, where=where, floor=floor)
                if below == 0:
                    parts.append(f"never within {level:g} (even at the smallest s measured)")
                elif math.isinf(y):
                    parts.append(f"within {level:g} in all {total} runs")
                else:
                    parts.append(f"within {level:g} when s < {y:.2g} ({below}/{total} runs)")
            y_miss, total = miss_threshold(ok, f, where=where)
            miss = (
                "never misses or invents an impact"
                if math.isinf(y_miss)
                else f"first misses or invents an impact at s = {y_miss:.2g}"
            )
            lines.append(f"- **{f}**: " + "; ".join(parts) + f"; {miss}.")
    # typical errors by tunnelling scale
    edges = (0.0, 0.01, 0.1, 1.0, math.inf)
    names = ("s < 0.01", "0.01–0.1", "0.1–1", "s ≥ 1")
    for title, where in (ELASTIC, INELASTIC):
        fr_all = [r for r in ok if where(r)]
        if not fr_all:
            continue
        lines += [
            "",
            f"Median (worst) final-state error in radii on {title}, by s:",
            "",
            "| engine / mode | " + " | ".join(names) + " |",
            "|---|" + "---:|" * len(names),
        ]
        for f in fams:
            cells = []
            for lo, hi in zip(edges[:-1], edges[1:], strict=True):
                errs = [_err(r) for r in fr_all if r["family"] == f and lo <= r["speed_dt_over_r"] < hi]
                cells.append(f"{_fmt(_median(errs))} ({_fmt(max(errs))})" if errs else "")
            if any(cells):
                lines.append(f"| {f} | " + " | ".join(cells) + " |")
    # cost
    med, mx, k = cost_ratios(ok, "exact", "naive")
    lines += ["", "Cost, measured in the same run (per control step, same scene, ball count and dt):", ""]
    if k:
        lines.append(f"- exact ÷ naive at 1–4 balls: median {med:.2f}×, worst {mx:.2f}× over {k} runs.")
    for num, den, counts in (
        ("exact", "posteriori k=1", (1, 2, 4)),
        ("exact", "naive", (16, 64)),
        ("exact", "posteriori k=8", (1, 2, 4, 16, 64)),
        ("exact", "pymunk it=10", (1, 2, 4, 16, 64)),
        ("exact", "billiards", (1, 2, 4, 16, 64)),
    ):
        med, mx, k = cost_ratios(ok, num, den, counts)
        if k:
            lines.append(
                f"- {num} ÷ {den} at {counts[0]}–{counts[-1]} balls: median {med:.2f}×, worst {mx:.2f}× over {k} runs."
            )
    dominated, ties = pareto_check(ok)
    lines += [
        "",
        "Pareto front: is any run both faster than exact's fastest run and more accurate than it, "
        "beyond exact's own spread on that scene?",
        "",
    ]
    if dominated:
        lines += [f"- **exact is dominated** on {s}, n={n} by {f} at dt={d:g}" for s, n, f, d in dominated]
    else:
        cases = len({(r["scene"], r["n"]) for r in exact})
        lines.append(f"- exact is on the Pareto front for every scene and ball count ({cases} cases).")
    if ties:
        by = defaultdict(list)
        for s, n, f, d, ratio in ties:
            by[(s, n)].append(f"{f} dt={d:g} ({ratio:.2f}× the cost)")
        lines.append(
            "- runs that tie with exact (error within its spread) at lower cost: "
            + "; ".join(f"{s} n={n}: " + ", ".join(v) for (s, n), v in by.items())
            + "."
        )
    # peers
    peer_lines = []
    for f in fams:
        if not f.startswith(("pymunk", "billiards")):
            continue
        fr = [r for r in ok if r["family"] == f]
        esc = sum(r["escapes"] > 0 for r in fr)
        unsup = sorted({r["scene"] for r in rows if r["family"] == f and r.get("status") == "unsupported"})
        drifts = [
            r["energy_drift"] for r in fr if isinstance(r["energy_drift"], float) and not math.isnan(r["energy_drift"])
        ]
        txt = (
            f"- {f}: median error {_fmt(_median([_err(r) for r in fr]))} radii, energy drift on elastic scenes "
            f"median {_fmt(_median(drifts))} / worst {_fmt(max(drifts, default=math.nan))}, balls escaped the "
            f"border in {esc} of {len(fr)} runs"
        )
        if unsup:
            txt += f"; cannot run {', '.join(unsup)}"
        peer_lines.append(txt + ".")
    if peer_lines:
        lines += ["", "Peers:", ""] + peer_lines
    # extremes and statistics
    if extreme_rows:
        lines += ["", "Extremes grid (pass / cells):", ""]
        for mode in dict.fromkeys(r["mode"] for r in extreme_rows):
            rs = [r for r in extreme_rows if r["mode"] == mode]
            fails = [r for r in rs if r["status"] != "pass"]
            reasons: defaultdict[str, int] = defaultdict(int)
            for r in fails:
                for reason in str(r["status"]).split(", "):
                    reasons[reason] += 1
            txt = ", ".join(f"{k} {v}" for k, v in reasons.items()) or "no failures"
            lines.append(f"- {mode}: {len(rs) - len(fails)} / {len(rs)} ({txt})")
        bad = [r for r in extreme_rows if r["mode"] == "exact" and r["status"] != "pass"]
        if bad:
            lines.append(
                "- **exact fails**: "
                + "; ".join(f"{r['cell']} ({r['status']})" for r in bad)
                + " — an engine problem, see extremes.md"
            )
    if stat_rows:
        good = [r for r in stat_rows if r.get("ks") not in (None, "")]
        lines += ["", "Long runs (64-ball gases; Maxwell-Boltzmann KS test and Enskog rate ratio):", ""]
        for f in dict.fromkeys(r["family"] for r in good):
            fr = [r for r in good if r["family"] == f]
            txt = ", ".join(
                f"{r['gas'].split('_')[0]} dt={r['dt']:g}: KS {'pass' if r['ks_pass'] else 'fail'}, "
                f"rate ×{r['rate_ratio']:.2f}"
                for r in fr
            )
            lines.append(f"- {f}: {txt}")
    # the rule of thumb, assembled from the numbers above
    lines += ["", "## Rule of thumb (from the numbers above)", ""]
    rule = []
    post = [f for f in fams if f.startswith("posteriori")]
    if exact:
        worst = max(_err(r) for r in exact)
        cells, collapse = _unmatched_cells(exact)
        impacts = (
            "no impact missed; "
            if not cells
            else "no impact missed outside the bookkeeping of inelastic collapse cascades (above); "
            if collapse
            else "impacts unmatched in some runs (above); "
        )
        rule.append(
            f"- **exact**: error ≤ {_fmt(worst)} radii at every dt, speed and scene measured, {impacts}"
            + "the mode to use whenever impact times and points matter or no error bound below holds."
        )
    for f in post + [f for f in fams if f.startswith("naive")]:
        for title, where in (ELASTIC, INELASTIC):
            y, below, total = thresholds(ok, f, 1e-3, where=where, floor=floor)
            y_miss, _ = miss_threshold(ok, f, where=where)
            if not total:
                continue
            if below == 0:
                rule.append(f"- {f} on {title}: never within 1e-3 radii of exact at the steps measured.")
            elif math.isinf(y):
                rule.append(f"- {f} on {title}: within 1e-3 radii of exact in every run measured.")
            else:
                txt = f"- {f} on {title}: within 1e-3 radii of exact when speed·dt/radius < {y:.2g}"
                if not math.isinf(y_miss):
                    txt += f"; it first misses or invents an impact at speed·dt/radius = {y_miss:.2g}"
                rule.append(txt + ".")
    med, mx, k = cost_ratios(ok, "exact", "naive")
    if k:
        verdict = "within" if mx <= 2.0 else "above"
        rule.append(
            f"- Cost: at 1–4 balls exact costs {med:.2f}× naive per step (median; worst {mx:.2f}×, "
            f"{verdict} the 2× bar)."
        )
        med2, mx2, k2 = cost_ratios(ok, "exact", "naive", (16, 64))
        if k2:
            rule.append(
                f"  At 16–64 balls it costs {med2:.2f}× naive (worst {mx2:.2f}×): the regime where a cheap "
                "mode saves time, if its error above is acceptable."
            )
    lines += rule + [""]
    return "\n".join(lines)


def readme_block(rows: list[dict], out_rel: str, quick: bool) -> str:
    """The README's headline table: each engine and mode's cost and error (the plots are on the results page)."""
    ok = ok_rows(rows)
    fams = family_order(ok)
    dt = 0.01
    lines = [
        f"Measured by `python -m collision_env.bench{' --quick' if quick else ''} --readme README.md` "
        f"(every figure and the plots: [{out_rel}/results.md]({out_rel}/results.md); which mode when: "
        f"[{out_rel}/summary.md]({out_rel}/summary.md)).",
        "",
        f"| engine / mode | µs per step, 4 balls | µs per step, 64 balls | median error (radii), dt = {dt:g} s "
        "| worst error (radii), dt = 0.01 s | runs missing impacts |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for f in fams:
        gas4 = [r for r in ok if r["family"] == f and r["scene"] == "dilute_gas" and r["n"] == 4 and r["dt"] == dt]
        gas64 = [r for r in ok if r["family"] == f and r["scene"] == "dilute_gas" and r["n"] == 64 and r["dt"] == dt]
        at = [r for r in ok if r["family"] == f and r["dt"] == dt]
        allr = [r for r in ok if r["family"] == f]
        lines.append(
            f"| {f} | {_fmt(gas4[0]['us_per_step'], 3) if gas4 else '–'} "
            f"| {_fmt(gas64[0]['us_per_step'], 3) if gas64 else '–'} | {_fmt(_median([_err(r) for r in at]))} "
            f"| {_fmt(max((_err(r) for r in at), default=math.nan))} "
            f"| {sum(r['missed'] > 0 for r in allr)} / {len(allr)} |"
        )
    return "\n".join(lines)
