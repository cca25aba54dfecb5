"""Hyperparameter files, run folders and the command-line plumbing shared by the agent scripts.

A hyperparameter file is RL-Zoo style YAML keyed by env id (``agents/hyperparams/ppo.yml``); an
entry's keys are ``n_envs``, ``n_timesteps``, ``policy``, ``normalize`` (VecNormalize settings),
``env_kwargs``, ``policy_kwargs`` and any ``PPO`` keyword, with ``lin_<x>`` for a linear schedule.
A run folder holds ``config.yml``: the fully resolved settings of the run, enough to rebuild its
envs and to retrain it (``train_ppo --hyperparams runs/<run>/config.yml`` reads it back).
"""

from __future__ import annotations

import argparse
import ast
import difflib
import math
import os
import shutil
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar, cast

from collision_env.extras import run_entry_point

HYPERPARAMS = Path(__file__).with_name("hyperparams") / "ppo.yml"
CONFIG_FILE = "config.yml"
MODEL_FILE = "model.zip"
VECNORMALIZE_FILE = "vecnormalize.pkl"
EVAL_SEED = 1_000_000  # evaluation episodes start far from the training and EvalCallback seeds

#: Keys of a hyperparameter entry that are not PPO keywords.
RUN_KEYS = ("n_envs", "n_timesteps", "policy", "normalize", "env_kwargs")


class UsageError(Exception):
    """A mistake in what the user asked for: reported as one line, without a traceback."""


def run_cli(
    main: Callable[[list[str] | None], Any],
    argv: list[str] | None = None,
    prog: str = "agents",
    extras: tuple[str, ...] = (),
) -> Any:
    """Run ``main(argv)``; a :class:`UsageError` becomes one line on stderr and exit status 2.

    The optional ``extras`` the command needs are checked first; a missing one (then, or a module of
    an extra that the run reaches for later) is one line naming the extra, and exit status 1.
    """

    def call():
        try:
            return main(argv)
        except UsageError as err:
            print(f"{prog}: error: {err}", file=sys.stderr)
            raise SystemExit(2) from None

    return run_entry_point(call, prog, extras, checkout=True)


# --------------------------------------------------------------------------------------- env ids
def check_env_id(env_id: str) -> str:
    """``env_id`` if it is one of collision_env's registered ids, else a UsageError."""
    import collision_env

    if env_id in collision_env.ENV_IDS:
        return env_id
    close = difflib.get_close_matches(str(env_id), collision_env.ENV_IDS, n=1, cutoff=0.4)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise UsageError(f"unknown env id {env_id!r}{hint} (registered: {', '.join(collision_env.ENV_IDS)})")


#: gym.make keywords the agent scripts set themselves (not task fields).
RESERVED_ENV_KWARGS = ("render_mode", "max_episode_steps", "disable_env_checker")


def check_env_kwargs(env_kwargs: dict) -> dict:
    if not isinstance(env_kwargs, dict):
        raise UsageError(f"env kwargs: expected a mapping of env keywords, got {env_kwargs!r}")
    clash = sorted(set(env_kwargs) & set(RESERVED_ENV_KWARGS))
    if clash:
        raise UsageError(f"env kwargs: {', '.join(clash)} cannot be set here (the agent scripts set them)")
    return env_kwargs


def parse_env_kwargs(pairs: list[str] | None) -> dict:
    """``["mode=naive", "dt=0.1"]`` -> ``{"mode": "naive", "dt": 0.1}`` (values read as YAML scalars)."""
    import yaml

    out = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise UsageError(f"--env-kwargs: expected key=value, got {pair!r}")
        try:
            out[key.strip()] = yaml.safe_load(value)
        except yaml.YAMLError:
            raise UsageError(f"--env-kwargs: cannot read the value of {pair!r}") from None
    return check_env_kwargs(out)


def merge_env_kwargs(
    entry_kwargs: dict | None, env_kwargs: dict | None, mode: str | None = None, substeps: int | None = None
) -> dict:
    """A run's env keywords: the hyperparameter entry's ``env_kwargs``, overridden by the caller's,
    overridden by ``mode`` and ``substeps`` when given (each mapping checked first)."""
    kwargs = {**check_env_kwargs(entry_kwargs or {}), **check_env_kwargs(env_kwargs or {})}
    if mode is not None:
        kwargs["mode"] = mode
    if substeps is not None:
        kwargs["substeps"] = substeps
    return kwargs


def episode_steps(env_id: str, env_kwargs: dict) -> int:
    """Control steps per episode of ``env_id`` under ``env_kwargs`` (validates the kwargs)."""
    import gymnasium as gym

    from collision_env.envs import CollisionTargetEnv  # (importing the envs registers the ids)

    check_env_kwargs(env_kwargs)
    try:
        env = gym.make(env_id, **env_kwargs)
    except (TypeError, ValueError) as err:
        raise UsageError(f"{env_id}: {err}") from None
    try:
        return int(cast(CollisionTargetEnv, env.unwrapped).config.n_steps)
    finally:
        env.close()


# ------------------------------------------------------------------------------ hyperparameters
def load_yaml(path: str | Path) -> dict:
    import yaml

    path = Path(path)
    if not path.is_file():
        raise UsageError(f"no such file: {path}")
    try:
        with path.open() as fh:
            data = yaml.safe_load(fh)
    except yaml.YAMLError as err:
        where = getattr(err, "problem_mark", None)
        raise UsageError(f"{path}: not valid YAML{f' (line {where.line + 1})' if where else ''}") from None
    if not isinstance(data, dict):
        raise UsageError(f"{path}: expected a mapping of env ids to hyperparameters")
    return data


def is_run_config(data: dict) -> bool:
    """Is this mapping a run folder's resolved ``config.yml`` (rather than a hyperparameter file)?"""
    return isinstance(data.get("hyperparams"), dict) and "env_id" in data


def hyperparams_for(env_id: str, path: str | Path = HYPERPARAMS) -> dict:
    """The entry of ``env_id`` in the file at ``path``, as a fresh dict.

    Without one, the entry the task registry names for it (its ``hyperparams_like`` id), else
    ``default``. A run folder's ``config.yml`` is accepted too, for its own env id only.
    """
    from collision_env.envs.registry import DEFAULT_HYPERPARAMS, hyperparams_fallback

    data = load_yaml(path)
    if is_run_config(data):
        if data["env_id"] != env_id:
            raise UsageError(f"{path} is the config of a {data['env_id']} run, not of {env_id}")
        return _entry(path, env_id, data["hyperparams"])
    for key in (env_id, hyperparams_fallback(env_id), DEFAULT_HYPERPARAMS):
        if key in data:
            return _entry(path, env_id, data[key])
    raise UsageError(f"{path}: no entry for {env_id!r} and no {DEFAULT_HYPERPARAMS!r} entry")


def _entry(path: str | Path, env_id: str, entry: Any) -> dict:
    if not isinstance(entry, dict):
        raise UsageError(f"{path}: the entry for {env_id!r} is not a mapping")
    return dict(entry)


def linear_schedule(start: float) -> Callable[[float], float]:
    """SB3 schedule from ``start`` (progress_remaining = 1) down to 0 (at the end of training)."""

    def schedule(progress_remaining: float) -> float:
        return progress_remaining * start

    return schedule


def _schedule_or_number(key: str, value: Any):
    if isinstance(value, str) and value.startswith("lin_"):
        try:
            return linear_schedule(float(value[4:]))
        except ValueError:
            raise UsageError(f"{key}: bad schedule {value!r} (expected lin_<number>)") from None
    if isinstance(value, str):
        try:  # YAML 1.1 reads 3e-4 (no dot) as a string
            return float(value)
        except ValueError:
            pass
    return value


def _policy_kwargs(value: Any) -> dict:
    """A mapping, or RL Zoo's ``"dict(net_arch=[64, 64], activation_fn=nn.Tanh)"`` string."""
    import torch.nn as nn

    if value is None:
        return {}
    if isinstance(value, str):
        try:
            value = eval(value, {"__builtins__": {}}, {"dict": dict, "nn": nn})  # RL Zoo's format
        except Exception as err:  # any failure is the user's string
            raise UsageError(f"policy_kwargs: cannot read {value!r}: {err}") from None
    if not isinstance(value, dict):
        raise UsageError(f"policy_kwargs: expected a mapping, got {value!r}")
    out = dict(value)
    act = out.get("activation_fn")
    if isinstance(act, str):  # "tanh", "relu", "nn.ReLU", ...
        name = act.removeprefix("nn.")
        lookup = {cls.lower(): cls for cls in ("Tanh", "ReLU", "ELU", "LeakyReLU", "GELU", "SiLU")}
        if name.lower() not in lookup:
            raise UsageError(f"policy_kwargs.activation_fn: unknown activation {act!r}")
        out["activation_fn"] = getattr(nn, lookup[name.lower()])
    return out


def normalize_settings(value: Any) -> dict | None:
    """VecNormalize keywords from ``normalize`` (bool, mapping or RL Zoo's string), or None for none."""
    if isinstance(value, str):
        try:
            value = ast.literal_eval(value)
        except (ValueError, SyntaxError):
            raise UsageError(f"normalize: cannot read {value!r}") from None
    if value is None or value is False:
        return None
    if value is True:
        return {"norm_obs": True, "norm_reward": True}
    if not isinstance(value, dict):
        raise UsageError(f"normalize: expected true/false or a mapping, got {value!r}")
    allowed = ("norm_obs", "norm_reward", "clip_obs", "clip_reward", "epsilon")
    unknown = sorted(set(value) - set(allowed))
    if unknown:
        raise UsageError(f"normalize: unknown key(s) {unknown}; VecNormalize takes {list(allowed)}")
    return dict(value)


def ppo_kwargs(hp: dict) -> dict:
    """PPO's keyword arguments from a hyperparameter entry (schedules and policy_kwargs resolved).

    Unknown keys are a UsageError, so a typo in the file fails before any training starts.
    """
    import inspect

    from stable_baselines3 import PPO

    known = set(inspect.signature(PPO.__init__).parameters) - {
        "self",
        "policy",
        "env",
        "seed",
        "device",
        "tensorboard_log",
        "verbose",
        "_init_setup_model",
    }
    unknown = sorted(set(hp) - known - set(RUN_KEYS))
    if unknown:
        raise UsageError(
            f"hyperparameters: unknown key(s) {unknown}; PPO takes {sorted(known)} and the file also {list(RUN_KEYS)}"
        )
    policy = hp.get("policy", "MlpPolicy")
    if policy not in PPO.policy_aliases:
        raise UsageError(f"policy: expected one of {sorted(PPO.policy_aliases)}, got {policy!r}")
    out = {}
    for key, value in hp.items():
        if key in RUN_KEYS:
            continue
        if key == "policy_kwargs":
            out[key] = _policy_kwargs(value)
            continue
        value = _schedule_or_number(key, value)
        optional = value is None and key in ("clip_range_vf", "target_kl")
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if key in _NUMBERS and not (callable(value) or number or optional):
            raise UsageError(f"{key}: expected a number{' or lin_<x>' if key in _SCHEDULES else ''}, got {value!r}")
        out[key] = value
    return out


#: PPO keywords that take a number (the first three also a schedule, lin_<x>).
_SCHEDULES = ("learning_rate", "clip_range", "clip_range_vf")
_NUMBERS = _SCHEDULES + (
    "n_steps",
    "batch_size",
    "n_epochs",
    "gamma",
    "gae_lambda",
    "ent_coef",
    "vf_coef",
    "max_grad_norm",
    "target_kl",
    "sde_sample_freq",
)


def as_int(name: str, value: Any, low: int = 1) -> int:
    """``value`` as an int >= ``low`` (floats such as 1e6 allowed when whole), else a UsageError."""
    what = "a positive integer" if low == 1 else f"an integer >= {low}"
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{name}: expected {what}, got {value!r}") from None
    if not math.isfinite(number) or number < low or number != int(number):
        raise UsageError(f"{name}: expected {what}, got {value!r}")
    return int(number)


def add_progress_flags(parser: argparse.ArgumentParser) -> None:
    """``--progress`` / ``--no-progress`` (default: a progress bar when stdout is a terminal)."""
    bar = parser.add_mutually_exclusive_group()
    bar.add_argument(
        "--progress",
        dest="progress",
        action="store_true",
        default=None,
        help="show progress bars (default: when stdout is a terminal outside CI; else a line each 10 %%)",
    )
    bar.add_argument("--no-progress", dest="progress", action="store_false")


def wants_progress(flag: bool | None) -> bool:
    """A progress bar? ``flag`` if given, else when stdout is a terminal outside CI (no ``CI`` variable)."""
    return sys.stdout.isatty() and not os.environ.get("CI") if flag is None else flag


T = TypeVar("T")


def track(items: Iterable[T], total: int, desc: str, bar: bool | None = None, unit: str = "episode") -> Iterator[T]:
    """Yield ``items`` while showing progress: a tqdm bar when :func:`wants_progress` (``bar``), else
    (a log file, CI) one line each 10 % of ``total``, flushed: ``desc: 30/100 episodes (30 %), 4 s``."""
    if wants_progress(bar):
        try:
            from tqdm import tqdm
        except ImportError:  # (the Ray venv's agents.evaluate may run without the train extra)
            pass
        else:
            yield from tqdm(items, total=total, desc=desc, unit=unit, leave=True)
            return
    start, marks = time.perf_counter(), {math.ceil(total * k / 10) for k in range(1, 11)}
    for done, item in enumerate(items, 1):
        yield item
        if done in marks:
            seconds = time.perf_counter() - start
            print(f"{desc}: {done}/{total} {unit}s ({100 * done / total:.0f} %), {seconds:.0f} s", flush=True)


# ----------------------------------------------------------------------------------- run folders
def run_label(env_id: str, mode: str, substeps: int, seed: int) -> str:
    """``oneballtarget-posteriori4-s0``: what a run folder's name starts with."""
    name = env_id.split("/")[-1].rsplit("-v", 1)[0].lower()
    knob = f"{mode}{substeps}" if substeps != 1 else mode
    return f"{name}-{knob}-s{seed}"


def engine_mode(env_kwargs: dict) -> tuple[str, int]:
    """The engine mode and sub-steps a run's merged env keywords give (the env's defaults where
    they give none: exact, 1)."""
    return env_kwargs.get("mode", "exact"), int(env_kwargs.get("substeps", 1))


def default_run_name(env_id: str, mode: str, substeps: int, seed: int) -> str:
    """:func:`run_label` and the time: ``oneballtarget-exact-s0-20260101-120000``."""
    return f"{run_label(env_id, mode, substeps, seed)}-{time.strftime('%Y%m%d-%H%M%S')}"


def make_run_dir(
    output: str | Path, run_name: str | None, env_id: str, env_kwargs: dict, seed: int, overwrite: bool
) -> Path:
    """The run folder ``output/run_name`` (default :func:`default_run_name` of the run's mode and
    substeps in ``env_kwargs``), made empty: an existing non-empty one is a UsageError unless
    ``overwrite``, and then nothing of the earlier run survives into this one."""
    mode, substeps = engine_mode(env_kwargs)
    run_dir = Path(output) / (run_name or default_run_name(env_id, mode, substeps, seed))
    if run_dir.exists() and any(run_dir.iterdir()):
        if not overwrite:
            raise UsageError(f"run folder {run_dir} exists and is not empty (pass --overwrite to replace it)")
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    return run_dir


@contextmanager
def log_tee(log: Callable[[str], None], path: Path | None) -> Iterator[Callable[[str], None]]:
    """A logger that calls ``log`` and also appends each line to the file ``path`` (flushed); the file
    is closed when the block ends, on an error too. ``path`` None: ``log`` itself."""
    if path is None:
        yield log
        return
    with path.open("a") as fh:

        def say(line: str) -> None:
            log(line)
            fh.write(line + "\n")
            fh.flush()

        yield say


def read_run(run_dir: str | Path) -> dict:
    """The resolved config of a run folder (UsageError if it is not one)."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise UsageError(f"run folder not found: {run_dir}")
    if not (run_dir / CONFIG_FILE).is_file() or not (run_dir / MODEL_FILE).is_file():
        raise UsageError(f"{run_dir} is not a training run folder (it needs {CONFIG_FILE} and {MODEL_FILE})")
    data = load_yaml(run_dir / CONFIG_FILE)
    if not is_run_config(data):
        raise UsageError(f"{run_dir / CONFIG_FILE} is not a run config (no env_id or hyperparams)")
    return data


def write_yaml(path: Path, data: dict) -> None:
    import yaml

    with path.open("w") as fh:
        yaml.safe_dump(data, fh, sort_keys=False)
