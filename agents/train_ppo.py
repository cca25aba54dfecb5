"""Train PPO (stable-baselines3) on a collision_env id and write one run folder.

    python -m agents.train_ppo --env CollisionEnv/OneBallTarget-v0
    python -m agents.train_ppo --env CollisionEnv/Billiards-v0 --timesteps 5e5 --mode posteriori --substeps 4
    python -m agents.train_ppo --env CollisionEnv/Line1D-v0 --env-kwargs dt=0.1 window=3.0 --vec-env subproc

Hyperparameters come from an RL-Zoo style YAML keyed by env id (``--hyperparams``, default
``agents/hyperparams/ppo.yml``); command-line options override its ``n_envs`` and ``n_timesteps``.
By default the agent trains on the native batched vector env through the SB3 adapter
(``collision_env.envs.sb3``); ``--vec-env dummy`` or ``subproc`` use SB3's own vector envs over
``gym.make`` instead (same episodes for the same seed, slower).

The run folder (``--output``/``--run-name``) holds:

| file | what |
|---|---|
| ``config.yml`` | the resolved settings (env, hyperparameters, seed), versions, wall and CPU training time, its split |
| ``model.zip`` | the final policy (``PPO.load``) |
| ``vecnormalize.pkl`` | VecNormalize statistics (when the entry normalises) |
| ``best_model.zip``, ``eval/evaluations.npz`` | EvalCallback's best policy and its evaluation log |
| ``checkpoints/`` | CheckpointCallback's periodic saves (with the VecNormalize statistics) |
| ``tb/`` | TensorBoard logs (``tensorboard --logdir <run>/tb``) |
| ``monitor.csv`` | per-episode return, length and success (``<i>.monitor.csv`` per sub-env with dummy/subproc) |
| ``train.log`` | progress lines (every 10 % of the run) when no progress bar is shown |
| ``learning_curve.png`` | success and return against env steps (``agents.curve``; needs matplotlib) |

Evaluation and checkpoint frequencies count env steps (all sub-envs together), not callback calls.
Every evaluation replays the same episodes (the evaluation env is reseeded first), so the best
model is picked on one fixed set, and ``best_vecnormalize.pkl`` keeps the statistics it was
evaluated with. ``--hyperparams <run>/config.yml`` repeats a run: its env id, seed, vector env and
callback settings are the defaults then (options given on the command line still win).
"""

from __future__ import annotations

import argparse
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from agents.config import (
    CONFIG_FILE,
    HYPERPARAMS,
    MODEL_FILE,
    VECNORMALIZE_FILE,
    UsageError,
    add_progress_flags,
    as_int,
    check_env_id,
    engine_mode,
    episode_steps,
    hyperparams_for,
    is_run_config,
    load_yaml,
    log_tee,
    make_run_dir,
    merge_env_kwargs,
    normalize_settings,
    parse_env_kwargs,
    ppo_kwargs,
    run_cli,
    wants_progress,
    write_yaml,
)
from agents.curve import CURVE_FILE, plot_learning_curve
from collision_env.bench.machine import versions
from collision_env.engine import MODES
from collision_env.extras import MissingExtra

if TYPE_CHECKING:
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecEnv

DEFAULT_ENV = "CollisionEnv/OneBallTarget-v0"
VEC_ENVS = ("native", "dummy", "subproc")
EVAL_SEED_OFFSET = 100_000  # evaluation episodes never share seeds with training episodes
BEST_VECNORMALIZE_FILE = "best_vecnormalize.pkl"
LOG_FILE = "train.log"
#: train()'s callback settings, recorded in config.yml and reused by --hyperparams <run>/config.yml
CALLBACK_DEFAULTS = {"eval_freq": 50_000, "eval_episodes": 20, "save_freq": 250_000}


def make_vec_env(
    env_id: str, n_envs: int, seed: int, env_kwargs: dict, vec_env: str = "native", monitor_dir: Path | None = None
) -> VecEnv:
    """An SB3 ``VecEnv`` of ``n_envs`` sub-envs (sub-env i seeded ``seed + i``), monitored.

    ``native``: the batched env through :func:`collision_env.envs.sb3.make_sb3_vec_env` (one
    ``VecMonitor``); ``dummy`` / ``subproc``: SB3's ``make_vec_env`` over ``gym.make`` (one
    ``Monitor`` per sub-env). Episodes last the env's own number of control steps whatever ``dt``
    is (``max_episode_steps`` follows the task config).
    """
    kwargs = {**env_kwargs, "max_episode_steps": episode_steps(env_id, env_kwargs)}
    if vec_env == "native":
        from collision_env.envs.sb3 import make_sb3_vec_env

        return make_sb3_vec_env(
            env_id,
            n_envs,
            seed=seed,
            monitor_file=None if monitor_dir is None else str(monitor_dir / "monitor.csv"),
            **kwargs,
        )
    from stable_baselines3.common.env_util import make_vec_env as sb3_make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    start_method = subproc_start_method()
    if vec_env == "subproc" and start_method == "fork":
        _load_kernels(env_id, kwargs)  # forked workers inherit them instead of each loading the cache

    # "module:id" makes gym.make import collision_env first, in a subprocess too
    return sb3_make_vec_env(
        f"collision_env:{env_id}",
        n_envs=n_envs,
        seed=seed,
        env_kwargs=kwargs,
        vec_env_cls=DummyVecEnv if vec_env == "dummy" else SubprocVecEnv,
        vec_env_kwargs={} if vec_env == "dummy" else {"start_method": start_method},
        monitor_dir=None if monitor_dir is None else str(monitor_dir),
        monitor_kwargs={"info_keywords": ("is_success",)},
    )


def _load_kernels(env_id: str, kwargs: dict) -> None:
    """One step of the env in this process: its compiled kernels are then loaded (or compiled)."""
    import gymnasium as gym

    env = gym.make(env_id, **kwargs)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.close()


def subproc_start_method() -> str:
    """``fork`` on Linux (workers start in well under a second: nothing is re-imported), else SB3's
    default ``forkserver`` / ``spawn``, which re-import torch and the package in every worker.

    Forking is safe here: the vector env is made before the policy, so no torch thread is running
    yet, and the workers only step the env.
    """
    import multiprocessing as mp
    import sys

    methods = mp.get_all_start_methods()
    if sys.platform.startswith("linux") and "fork" in methods:
        return "fork"
    return "forkserver" if "forkserver" in methods else "spawn"


def _wrap_normalize(venv, settings: dict | None, gamma: float, training: bool):
    if settings is None:
        return venv
    from stable_baselines3.common.vec_env import VecNormalize

    if training:
        return VecNormalize(venv, gamma=gamma, **settings)
    return VecNormalize(venv, training=False, gamma=gamma, **{**settings, "norm_reward": False})


def _callbacks(
    run_dir: Path,
    eval_env,
    eval_seed: int,
    n_envs: int,
    eval_freq: int,
    eval_episodes: int,
    save_freq: int,
    normalized: bool,
) -> list:
    from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

    class SeededEvalCallback(EvalCallback):
        """EvalCallback that replays the same episodes at every evaluation (reseeds the eval env)."""

        def _on_step(self) -> bool:
            if self.eval_freq > 0 and self.n_calls % self.eval_freq == 0:
                self.eval_env.seed(eval_seed)
            return super()._on_step()

    class SaveBestStatistics(BaseCallback):
        """Keep the VecNormalize statistics that the best model was evaluated with."""

        def _on_step(self) -> bool:
            vec_normalize = self.model.get_vec_normalize_env()
            assert vec_normalize is not None  # (given to normalised runs only)
            vec_normalize.save(str(run_dir / BEST_VECNORMALIZE_FILE))
            return True

    out: list[BaseCallback] = []
    if eval_freq:
        out.append(
            SeededEvalCallback(
                eval_env,
                n_eval_episodes=eval_episodes,
                eval_freq=max(eval_freq // n_envs, 1),
                best_model_save_path=str(run_dir),
                log_path=str(run_dir / "eval"),
                deterministic=True,
                verbose=0,
                callback_on_new_best=SaveBestStatistics() if normalized else None,
            )
        )
    if save_freq:
        out.append(
            CheckpointCallback(
                save_freq=max(save_freq // n_envs, 1),
                save_path=str(run_dir / "checkpoints"),
                name_prefix="model",
                save_vecnormalize=normalized,
            )
        )
    return out


def _print(line: str) -> None:
    print(line, flush=True)  # flushed: a log file or pipe shows each line as it comes


def _progress_log(total: int, log, every: float = 0.1):
    """SB3 callback: one log line each ``every`` of the run (steps, success and return of recent
    episodes, steps/s), for when no progress bar is shown (stdout is not a terminal)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class ProgressLog(BaseCallback):
        def _on_training_start(self) -> None:
            self.start = time.perf_counter()
            self.next = every * total

        def _on_step(self) -> bool:
            done = self.model.num_timesteps
            if done >= self.next:
                self.next += every * total
                episodes = list(self.model.ep_info_buffer or ())
                success = list(getattr(self.model, "ep_success_buffer", []))
                line = f"{done:,} / {total:,} steps ({100 * done / total:.0f} %)"
                if success:
                    line += f", success {100 * sum(success) / len(success):.0f} %"
                if episodes:
                    line += f", episode return {sum(e['r'] for e in episodes) / len(episodes):.2f}"
                seconds = time.perf_counter() - self.start
                log(f"{line}, {seconds:.0f} s ({done / max(seconds, 1e-9):,.0f} steps/s)")
            return True

    return ProgressLog()


class Tuned(NamedTuple):
    """What :func:`tuned_ppo` returns: the model, and the steps its entry trains for."""

    model: PPO
    """stable-baselines3's ``PPO`` on the env's vector env (``model.get_env()``), ready to ``learn``."""
    timesteps: int
    """The entry's ``n_timesteps`` (or the ``timesteps`` asked for), rounded up to whole rollouts:
    PPO updates after every ``n_envs * n_steps`` env steps, so ``model.learn(timesteps)`` stops
    exactly there."""


class _Settings(NamedTuple):
    """A hyperparameter entry resolved and checked (see :func:`_settings`)."""

    entry: dict  # the file's entry, as read
    env_kwargs: dict
    episode_steps: int
    n_envs: int
    asked: int  # the timesteps asked for
    timesteps: int  # rounded up to whole rollouts
    rollout: int  # env steps per PPO update (n_envs * n_steps)
    normalize: dict | None
    policy: str
    ppo: dict  # PPO's keywords


def _settings(
    env_id: str,
    hyperparams: str | Path,
    n_envs: int | None,
    timesteps: float | None,
    env_kwargs: dict,
    mode: str | None = None,
    substeps: int | None = None,
) -> _Settings:
    """The entry of ``env_id`` in ``hyperparams``, with the given overrides, every value checked
    (a UsageError names the first bad one) before anything is built."""
    check_env_id(env_id)
    hp = hyperparams_for(env_id, hyperparams)
    n_envs = as_int("n_envs", n_envs if n_envs is not None else hp.get("n_envs", 8))
    asked = as_int("timesteps", timesteps if timesteps is not None else hp.get("n_timesteps", 1e6))
    kwargs = merge_env_kwargs(hp.get("env_kwargs"), env_kwargs, mode, substeps)
    steps = episode_steps(env_id, kwargs)  # validates every env kwarg
    algo_kwargs = ppo_kwargs(hp)  # validates every PPO keyword
    rollout = n_envs * as_int("n_steps", algo_kwargs.get("n_steps", 2048))
    return _Settings(
        entry=hp,
        env_kwargs=kwargs,
        episode_steps=steps,
        n_envs=n_envs,
        asked=asked,
        timesteps=-(-asked // rollout) * rollout,
        rollout=rollout,
        normalize=normalize_settings(hp.get("normalize")),
        policy=hp.get("policy", "MlpPolicy"),
        ppo=algo_kwargs,
    )


def _build(
    env_id: str,
    settings: _Settings,
    seed: int,
    vec_env: str,
    threads: int,
    monitor_dir: Path | None = None,
    tensorboard_log: str | None = None,
    verbose: int = 0,
) -> PPO:
    """PPO on the env's vector env (VecNormalize'd as the entry says), as :func:`tuned_ppo` builds it."""
    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(threads)

    gamma = float(settings.ppo.get("gamma", 0.99))
    venv = _wrap_normalize(
        make_vec_env(env_id, settings.n_envs, seed, settings.env_kwargs, vec_env, monitor_dir=monitor_dir),
        settings.normalize,
        gamma,
        training=True,
    )
    try:
        return PPO(
            settings.policy,
            venv,
            seed=seed,
            device="cpu",
            tensorboard_log=tensorboard_log,
            verbose=verbose,
            **settings.ppo,
        )
    except (TypeError, ValueError, AssertionError) as err:  # a bad value in the hyperparameter file
        venv.close()
        raise UsageError(f"PPO rejected the hyperparameters for {env_id}: {err}") from None


def tuned_ppo(
    env_id: str = DEFAULT_ENV,
    *,
    seed: int = 0,
    n_envs: int | None = None,
    timesteps: float | None = None,
    env_kwargs: dict | None = None,
    hyperparams: str | Path = HYPERPARAMS,
    vec_env: str = "native",
    threads: int = 1,
    tensorboard_log: str | None = None,
    verbose: int = 0,
) -> Tuned:
    """stable-baselines3's PPO with the shipped hyperparameters of ``env_id``, in one call: what
    ``python -m agents.train_ppo`` trains, without its run folder, callbacks and logs.

    The entry of ``env_id`` in ``hyperparams`` (``agents/hyperparams/ppo.yml``; see
    :func:`agents.config.hyperparams_for` for the fallbacks) gives the number of sub-envs, the env
    keywords (``env_kwargs`` override them), the VecNormalize settings, the policy and every PPO
    keyword; the envs are the native vector env through the SB3 adapter (``vec_env="dummy"`` or
    ``"subproc"``: SB3's own, over ``gym.make``), sub-env i seeded ``seed + i``, on the CPU, with
    ``threads`` torch threads for the process (``torch.set_num_threads``; 1, as the command: the
    small networks gain nothing from more, and on a busy machine more threads wait on each other).
    Returns the model and the steps to train it for:

    >>> model, timesteps = tuned_ppo("CollisionEnv/Billiards-v0", seed=0)  # doctest: +SKIP
    >>> model.learn(timesteps)  # doctest: +SKIP

    A bad entry or keyword is a :class:`~agents.config.UsageError` naming it. A model trained with
    normalised observations needs its ``model.get_vec_normalize_env()`` statistics to act later.
    """
    if vec_env not in VEC_ENVS:
        raise UsageError(f"vec_env: expected one of {VEC_ENVS}, got {vec_env!r}")
    settings = _settings(env_id, hyperparams, n_envs, timesteps, env_kwargs or {})
    seed = as_int("seed", seed, low=0)
    threads = as_int("threads", threads)
    model = _build(env_id, settings, seed, vec_env, threads, tensorboard_log=tensorboard_log, verbose=verbose)
    return Tuned(model, settings.timesteps)


def train(
    env_id: str = DEFAULT_ENV,
    *,
    timesteps: float | None = None,
    n_envs: int | None = None,
    seed: int = 0,
    mode: str | None = None,
    substeps: int | None = None,
    env_kwargs: dict | None = None,
    output: str | Path = "runs",
    run_name: str | None = None,
    hyperparams: str | Path = HYPERPARAMS,
    vec_env: str = "native",
    eval_freq: int = CALLBACK_DEFAULTS["eval_freq"],
    eval_episodes: int = CALLBACK_DEFAULTS["eval_episodes"],
    save_freq: int = CALLBACK_DEFAULTS["save_freq"],
    progress: bool = False,
    threads: int = 1,
    overwrite: bool = False,
    verbose: int = 0,
    log: Callable[[str], None] | None = None,
) -> Path:
    """Train PPO on ``env_id`` and write the run folder; returns its path.

    ``mode``/``substeps`` set the engine's fidelity (they override ``env_kwargs``, which override
    the hyperparameter entry's ``env_kwargs``). ``eval_freq`` / ``save_freq`` are in env steps;
    0 turns the EvalCallback / CheckpointCallback off. Everything is validated before the run
    folder is made, so a mistake costs no half-written folder. PPO updates after whole rollouts
    (``n_envs * n_steps`` env steps), so ``timesteps`` is rounded up to a whole number of them,
    and the log says so.
    """
    log = log or _print
    if vec_env not in VEC_ENVS:
        raise UsageError(f"--vec-env: expected one of {VEC_ENVS}, got {vec_env!r}")
    settings = _settings(env_id, hyperparams, n_envs, timesteps, env_kwargs or {}, mode, substeps)
    seed = as_int("seed", seed, low=0)
    eval_freq = as_int("eval_freq", eval_freq, low=0)
    save_freq = as_int("save_freq", save_freq, low=0)
    eval_episodes = as_int("eval_episodes", eval_episodes)
    threads = as_int("threads", threads)
    kwargs, n_envs, timesteps, norm = settings.env_kwargs, settings.n_envs, settings.timesteps, settings.normalize
    mode, substeps = engine_mode(kwargs)

    run_dir = make_run_dir(output, run_name, env_id, kwargs, seed, overwrite)

    callbacks_cfg = {"eval_freq": eval_freq, "eval_episodes": eval_episodes, "save_freq": save_freq}
    config = {
        "env_id": env_id,
        "env_kwargs": kwargs,
        "episode_steps": settings.episode_steps,
        "seed": seed,
        "n_envs": n_envs,
        "n_timesteps": timesteps,
        "vec_env": vec_env,
        "callbacks": callbacks_cfg,
        "threads": threads,
        "hyperparams": {**settings.entry, "n_envs": n_envs, "n_timesteps": timesteps, "env_kwargs": dict(kwargs)},
        "hyperparams_file": str(hyperparams),
        "versions": versions(["gymnasium", "stable_baselines3", "torch"]),
    }
    write_yaml(run_dir / CONFIG_FILE, config)
    log(
        f"training PPO on {env_id} (mode={mode}, substeps={substeps}) for {timesteps:,} steps, "
        f"{n_envs} envs ({vec_env}), seed {seed} -> {run_dir}"
    )
    if timesteps != settings.asked:
        log(
            f"(PPO updates after whole rollouts of {n_envs} envs x {settings.rollout // n_envs} steps = "
            f"{settings.rollout:,} env steps: {settings.asked:,} steps asked, rounded up to {timesteps:,})"
        )

    try:
        model = _build(env_id, settings, seed, vec_env, threads, run_dir, str(run_dir / "tb"), verbose)
    except UsageError:
        shutil.rmtree(run_dir)
        raise
    venv = model.get_env()
    assert venv is not None  # (given to the model above)
    eval_env = None
    if eval_freq:
        eval_seed = seed + EVAL_SEED_OFFSET
        gamma = float(settings.ppo.get("gamma", 0.99))
        eval_env = _wrap_normalize(
            make_vec_env(env_id, min(eval_episodes, 4), eval_seed, kwargs, vec_env), norm, gamma, training=False
        )
    callbacks = _callbacks(
        run_dir, eval_env, seed + EVAL_SEED_OFFSET, n_envs, eval_freq, eval_episodes, save_freq, norm is not None
    )
    from agents.timing import cpu_seconds, time_split

    timer = time_split(venv)
    callbacks.append(timer)
    cpu = cpu_seconds()
    start = time.perf_counter()
    with log_tee(log, None if progress else run_dir / LOG_FILE) as log_line:
        if not progress:  # no bar: progress lines in the log instead (and in train.log)
            callbacks.append(_progress_log(timesteps, log_line))
        model.learn(total_timesteps=timesteps, callback=callbacks, progress_bar=progress, tb_log_name="ppo")
    seconds = time.perf_counter() - start
    cpu = cpu_seconds() - cpu  # before saving: the training's own CPU time (subprocess workers: below)
    model.save(run_dir / MODEL_FILE)
    if norm is not None:
        venv.save(str(run_dir / VECNORMALIZE_FILE))  # type: ignore[attr-defined]
    children = cpu_seconds()
    venv.close()
    if eval_env is not None:
        eval_env.close()
    cpu += cpu_seconds() - children  # subprocess workers count once closed (0 for the native env)
    config["train_seconds"] = round(seconds, 2)
    config["train_cpu_seconds"] = round(cpu, 2)
    config["time_split"] = {k: None if v is None else round(v, 4) for k, v in timer.split(seconds).items()}
    config["timesteps_done"] = int(model.num_timesteps)
    write_yaml(run_dir / CONFIG_FILE, config)
    log(
        f"trained {model.num_timesteps:,} steps in {seconds:.0f} s wall-clock, {cpu:.0f} CPU s "
        f"({model.num_timesteps / seconds:,.0f} steps/s)"
    )
    try:
        plot_learning_curve(run_dir, title=f"PPO on {env_id} ({mode}, substeps {substeps}), seed {seed}")
    except MissingExtra as err:  # the run is complete without its picture: say so and go on
        log(str(err))
    return run_dir


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m agents.train_ppo",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--env", help=f"registered env id (default: {DEFAULT_ENV}, or the run's with a run config)")
    p.add_argument("--timesteps", type=float, help="total env steps (default: the entry's n_timesteps)")
    p.add_argument("--n-envs", type=int, help="parallel sub-envs (default: the entry's n_envs)")
    p.add_argument("--seed", type=int, help="default 0 (or the run's)")
    p.add_argument("--mode", choices=MODES, help="engine fidelity mode (default: exact)")
    p.add_argument("--substeps", type=int, help="sub-steps per control step for naive/posteriori")
    p.add_argument("--env-kwargs", nargs="*", metavar="KEY=VALUE", help="more env keywords, e.g. dt=0.1")
    p.add_argument("--output", default="runs", help="folder for run folders (default: %(default)s)")
    p.add_argument(
        "--run-name", help="run folder name (default: <env>-<mode><k>-s<seed>-<time>, k the sub-steps if not 1)"
    )
    p.add_argument("--overwrite", action="store_true", help="replace an existing run folder")
    p.add_argument(
        "--hyperparams",
        default=str(HYPERPARAMS),
        help="hyperparameter YAML, or a run's config.yml to repeat it (default: the shipped file)",
    )
    p.add_argument(
        "--vec-env", choices=VEC_ENVS, help="native batched env (default), or SB3's dummy/subproc over gym.make"
    )
    p.add_argument(
        "--eval-freq",
        type=int,
        help=f"env steps between evaluations, 0: none (default {CALLBACK_DEFAULTS['eval_freq']})",
    )
    p.add_argument("--eval-episodes", type=int, help=f"default {CALLBACK_DEFAULTS['eval_episodes']}")
    p.add_argument(
        "--save-freq",
        type=int,
        help=f"env steps between checkpoints, 0: none (default {CALLBACK_DEFAULTS['save_freq']})",
    )
    p.add_argument("--threads", type=int, default=1, help="torch threads (default: %(default)s)")
    add_progress_flags(p)
    p.add_argument("-v", "--verbose", type=int, default=0, help="SB3 verbosity (1: print training statistics)")
    return p


def main(argv: list[str] | None = None) -> Path:
    args = build_parser().parse_args(argv)
    # a run's config.yml supplies the defaults of the run it describes
    data = load_yaml(args.hyperparams)
    run = data if is_run_config(data) else {}

    def pick(given: Any, key: str, default: Any) -> Any:
        return given if given is not None else run.get(key, default)

    callbacks = {**CALLBACK_DEFAULTS, **run.get("callbacks", {})}
    run_dir = train(
        pick(args.env, "env_id", DEFAULT_ENV),
        timesteps=args.timesteps,
        n_envs=args.n_envs,
        seed=pick(args.seed, "seed", 0),
        mode=args.mode,
        substeps=args.substeps,
        env_kwargs=parse_env_kwargs(args.env_kwargs),
        output=args.output,
        run_name=args.run_name,
        hyperparams=args.hyperparams,
        vec_env=pick(args.vec_env, "vec_env", "native"),
        eval_freq=callbacks["eval_freq"] if args.eval_freq is None else args.eval_freq,
        eval_episodes=callbacks["eval_episodes"] if args.eval_episodes is None else args.eval_episodes,
        save_freq=callbacks["save_freq"] if args.save_freq is None else args.save_freq,
        progress=wants_progress(args.progress),
        threads=args.threads,
        overwrite=args.overwrite,
        verbose=args.verbose,
    )
    print(f"model:       {run_dir / MODEL_FILE}")
    print(f"config:      {run_dir / CONFIG_FILE}")
    if (run_dir / CURVE_FILE).is_file():
        print(f"curve:       {run_dir / CURVE_FILE}")
    print(f"tensorboard: tensorboard --logdir {run_dir / 'tb'}")
    print(f"evaluate:    python -m agents.evaluate {run_dir}")
    return run_dir


if __name__ == "__main__":
    run_cli(main, prog="agents.train_ppo", extras=("train",))
