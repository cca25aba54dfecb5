"""Train PPO on Ray RLlib (new API stack) on a collision_env id, on one machine or a Ray cluster.

    python -m agents.train_rllib --env CollisionEnv/OneBallTarget-v0
    python -m agents.train_rllib --env CollisionEnv/Line1D-v0 --iterations 50 --env-runners 4 --envs-per-runner 64
    python -m agents.train_rllib --address 127.0.0.1:6379     # join a running cluster (`ray start --head`)

Needs the ``distributed`` extra (``pip install -e ".[distributed]"``: Ray with RLlib, torch).
Without ``--address`` a local Ray instance starts on 127.0.0.1 and stops at the end; with it the
script joins that cluster and its env runners are placed on any of its nodes.

Each env runner builds the project's native vector env (``--vectorize native``, the default: one
batched engine steps all ``--envs-per-runner`` sub-envs) through a creator that imports
``collision_env`` itself, so the runners need nothing but the installed package. ``--vectorize
sync`` uses RLlib's default instead (one ``gym.make`` per sub-env).

Training stops after ``--iterations`` iterations or as soon as the deterministic policy succeeds on
``target_success`` of the evaluation episodes (the same episodes ``agents.evaluate`` plays).
Hyperparameters come from ``agents/hyperparams/rllib_ppo.yml`` (``--hyperparams``). The run folder
holds ``checkpoint/`` (RLlib's Algorithm checkpoint), ``config.yml`` (every resolved setting, the
versions, where each env runner ran, the training time and the evaluation history) and
``train.log`` (one line per iteration, also printed). ``python -m agents.evaluate <run>``
evaluates it beside the random and scripted baselines.
"""

from __future__ import annotations

import argparse
import logging
import os
import platform
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from agents.config import (
    CONFIG_FILE,
    EVAL_SEED,
    UsageError,
    as_int,
    check_env_id,
    engine_mode,
    episode_steps,
    hyperparams_for,
    log_tee,
    make_run_dir,
    merge_env_kwargs,
    parse_env_kwargs,
    run_cli,
    write_yaml,
)
from collision_env.engine import MODES
from collision_env.extras import require

DEFAULT_ENV = "CollisionEnv/OneBallTarget-v0"
HYPERPARAMS = Path(__file__).with_name("hyperparams") / "rllib_ppo.yml"
CHECKPOINT_DIR = "checkpoint"
LOG_FILE = "train.log"
ALGORITHM = "rllib-ppo"
#: Keys of an rllib_ppo.yml entry that are not PPOConfig.training() keywords.
RUN_KEYS = (
    "iterations",
    "env_runners",
    "envs_per_runner",
    "vectorize",
    "target_success",
    "eval_episodes",
    "eval_every",
    "fcnet_hiddens",
    "fcnet_activation",
    "env_kwargs",
)


def training_kwargs(hp: dict) -> dict:
    """PPOConfig.training() keywords of a hyperparameter entry; unknown keys are a UsageError."""
    import inspect

    from ray.rllib.algorithms.ppo import PPOConfig

    known = set(inspect.signature(PPOConfig.training).parameters) - {"self"}
    from ray.rllib.algorithms.algorithm_config import AlgorithmConfig

    known |= set(inspect.signature(AlgorithmConfig.training).parameters) - {"self"}
    unknown = sorted(set(hp) - known - set(RUN_KEYS))
    if unknown:
        raise UsageError(
            f"hyperparameters: unknown key(s) {unknown}; PPOConfig.training takes {sorted(known)} "
            f"and the file also {list(RUN_KEYS)}"
        )
    return {k: v for k, v in hp.items() if k not in RUN_KEYS}


def build_config(
    env_id: str, env_kwargs: dict, hp: dict, *, env_runners: int, envs_per_runner: int, vectorize: str, seed: int
) -> Any:
    """The PPOConfig of a run (new API stack, torch, the learner in the driver process)."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

    from agents.rllib_env import VECTORIZE_MODES, rllib_env_name

    if vectorize not in VECTORIZE_MODES:
        raise UsageError(f"vectorize: expected one of {tuple(VECTORIZE_MODES)}, got {vectorize!r}")
    return (
        PPOConfig()
        .environment(env=rllib_env_name(env_id), env_config={"env_id": env_id, **env_kwargs})
        .framework("torch")
        .env_runners(
            num_env_runners=env_runners,
            num_envs_per_env_runner=envs_per_runner,
            gym_env_vectorize_mode=VECTORIZE_MODES[vectorize],
            num_cpus_per_env_runner=1,
        )
        .learners(num_learners=0)
        .rl_module(
            model_config=DefaultModelConfig(
                fcnet_hiddens=list(hp.get("fcnet_hiddens", [64, 64])),
                fcnet_activation=hp.get("fcnet_activation", "tanh"),
            )
        )
        .training(**training_kwargs(hp))
        # no CPU/GPU usage metrics (which no report here reads, and which want gputil installed)
        .debugging(seed=seed, log_level="ERROR", log_sys_usage=False)
    )


def success_rate(module: Any, env_id: str, env_kwargs: dict, episodes: int, seed: int) -> float:
    """Share of ``episodes`` evaluation episodes (episode i from seed + i) the deterministic module wins.

    Plays them all at once on the native vector env, whose sub-env i is seeded ``seed + i`` exactly
    as ``agents.evaluate`` seeds its episode i, so both count the same episodes.
    """
    import gymnasium as gym

    import collision_env  # noqa: F401
    from agents.rllib_policy import deterministic_actions

    venv = gym.make_vec(
        env_id,
        num_envs=episodes,
        vectorization_mode="vector_entry_point",
        max_episode_steps=episode_steps(env_id, env_kwargs),
        **env_kwargs,
    )
    obs, _ = venv.reset(seed=seed)
    success = np.zeros(episodes, dtype=bool)
    done = np.zeros(episodes, dtype=bool)
    while not done.all():
        obs, _, term, trunc, info = venv.step(deterministic_actions(module, obs))
        ended = (term | trunc) & ~done
        success[ended] = info["is_success"][ended]
        done |= ended
    venv.close()
    return float(success.mean())


def warm_up(env_id: str, env_kwargs: dict) -> None:
    """One reset and step of ``env_id``: compiles the engine's kernels (or loads them from the cache)."""
    import gymnasium as gym

    import collision_env  # noqa: F401

    env = gym.make(env_id, **env_kwargs)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.close()


def runner_placement(algo: Any) -> list[dict]:
    """Which Ray node each remote env runner runs on (node id, address, whether it is the head)."""
    import ray

    def where(runner):
        ctx = ray.get_runtime_context()
        return {"node_id": ctx.get_node_id(), "pid": os.getpid()}

    head = ray.get_runtime_context().get_node_id()  # the driver runs on the node it joined
    nodes = {n["NodeID"]: n for n in ray.nodes()}
    out = []
    for i, spot in enumerate(algo.env_runner_group.foreach_env_runner(where, local_env_runner=False), start=1):
        node = nodes.get(spot["node_id"], {})
        out.append(
            {
                "runner": i,
                "node_id": spot["node_id"],
                "node_address": node.get("NodeManagerAddress"),
                "driver_node": spot["node_id"] == head,
                "pid": spot["pid"],
            }
        )
    return out


def _versions() -> dict:
    import gymnasium
    import ray
    import torch

    import collision_env
    from collision_env.engine import BACKEND

    versions = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "gymnasium": gymnasium.__version__,
        "ray": ray.__version__,
        "torch": torch.__version__,
        "collision_env": collision_env.__version__,
        "engine_backend": BACKEND,
    }
    return {name: str(v) for name, v in versions.items()}


#: Ray resolves 127.0.0.1 to the machine's network address unless this is "0" (then it stays on
#: loopback, as a single-machine instance should). Ray reads it when it is imported.
LOOPBACK_ENV = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"


def keep_ray_on_loopback() -> None:
    """Make a local Ray instance of this process (and its children) bind to 127.0.0.1 only."""
    os.environ[LOOPBACK_ENV] = "0"  # for the processes Ray starts
    from ray._private import ray_constants

    ray_constants.ENABLE_RAY_CLUSTER = False  # for this process, if ray was imported before


#: Lines Ray logs on every run that say nothing about this one (Ray 2.60), by the logger that writes
#: them: that a new local instance uses token authentication (Ray's default, which this trainer keeps),
#: RLlib's note that PPO runs on its new API stack (which this trainer uses on purpose), and the
#: deprecation warning that RLlib's own RLModule constructor sets off for every module it builds.
RAY_NOISE = {
    "ray._private.authentication.authentication_token_setup": "Token authentication is enabled for this Ray",
    "ray.rllib.algorithms.algorithm_config": "on the new API stack! This is the new default",
    "ray._common.deprecation": "RLModule(config=[RLModuleConfig",
}


class _DropLines(logging.Filter):
    """Drops the log records whose message contains ``text``."""

    def __init__(self, text: str):
        super().__init__()
        self.text = text

    def filter(self, record: logging.LogRecord) -> bool:
        return self.text not in record.getMessage()


def quiet_ray_logs() -> None:
    """Leave the lines of :data:`RAY_NOISE` out of this process's log; everything else Ray logs stays."""
    for name, text in RAY_NOISE.items():
        logger = logging.getLogger(name)
        if not any(isinstance(f, _DropLines) and f.text == text for f in logger.filters):
            logger.addFilter(_DropLines(text))


def start_ray(address: str | None, num_cpus: int, node_ip_address: str | None = None) -> None:
    """Join the cluster at ``address`` (this machine's address in it: ``node_ip_address``, else
    Ray's guess), or start a private local instance on 127.0.0.1.

    The workers' output stays in Ray's log files (``log_to_driver=False``); the driver logs Ray's
    warnings and errors only (not its progress notes), and none of :data:`RAY_NOISE`.
    """
    import ray

    quiet_ray_logs()
    quiet = {"log_to_driver": False, "logging_level": logging.WARNING}
    if address:
        ray.init(address=address, _node_ip_address=node_ip_address, **quiet)
    else:
        keep_ray_on_loopback()
        ray.init(num_cpus=num_cpus, include_dashboard=False, _node_ip_address="127.0.0.1", **quiet)


def train(
    env_id: str = DEFAULT_ENV,
    *,
    iterations: int | None = None,
    env_runners: int | None = None,
    envs_per_runner: int | None = None,
    vectorize: str | None = None,
    address: str | None = None,
    node_ip_address: str | None = None,
    seed: int = 0,
    mode: str | None = None,
    substeps: int | None = None,
    env_kwargs: dict | None = None,
    output: str | Path = "runs",
    run_name: str | None = None,
    hyperparams: str | Path = HYPERPARAMS,
    target_success: float | None = None,
    overwrite: bool = False,
    threads: int = 1,
    log: Callable[[str], None] | None = None,
) -> Path:
    """Train RLlib PPO on ``env_id`` and write the run folder; returns its path.

    Arguments left as None come from the hyperparameter entry. Everything is validated before Ray
    starts or the run folder is made.
    """
    log = log or (lambda line: print(line, flush=True))
    check_env_id(env_id)
    hp = hyperparams_for(env_id, hyperparams)

    def pick(value: Any, key: str, default: Any) -> Any:
        return hp.get(key, default) if value is None else value

    iterations = as_int("iterations", pick(iterations, "iterations", 100))
    env_runners = as_int("env_runners", pick(env_runners, "env_runners", 2), low=0)
    envs_per_runner = as_int("envs_per_runner", pick(envs_per_runner, "envs_per_runner", 16))
    vectorize = pick(vectorize, "vectorize", "native")
    seed = as_int("seed", seed, low=0)
    eval_episodes = as_int("eval_episodes", hp.get("eval_episodes", 100))
    eval_every = as_int("eval_every", hp.get("eval_every", 2))
    target = float(pick(target_success, "target_success", 0.9))
    if not 0.0 < target <= 1.0:
        raise UsageError(f"target_success: expected a share in (0, 1], got {target!r}")
    kwargs = merge_env_kwargs(hp.get("env_kwargs"), env_kwargs, mode, substeps)
    steps = episode_steps(env_id, kwargs)  # validates every env kwarg
    mode, _ = engine_mode(kwargs)
    kwargs_env = {**kwargs, "max_episode_steps": steps}
    require("distributed", "agents.train_rllib", checkout=True)
    config = build_config(
        env_id, kwargs_env, hp, env_runners=env_runners, envs_per_runner=envs_per_runner, vectorize=vectorize, seed=seed
    )  # validates the PPO keywords

    run_dir = make_run_dir(output, run_name, env_id, kwargs, seed, overwrite)
    with log_tee(log, run_dir / LOG_FILE) as say:  # (closed on an error too)
        import ray
        import torch

        torch.set_num_threads(threads)
        record = {
            "algorithm": ALGORITHM,
            "env_id": env_id,
            "env_kwargs": kwargs,
            "episode_steps": steps,
            "seed": seed,
            "iterations": iterations,
            "env_runners": env_runners,
            "envs_per_runner": envs_per_runner,
            "vectorize": vectorize,
            "target_success": target,
            "eval_episodes": eval_episodes,
            "eval_seed": EVAL_SEED,
            "address": address,
            "node_ip_address": node_ip_address,
            "hyperparams": {**hp, "env_kwargs": dict(kwargs)},
            "hyperparams_file": str(hyperparams),
            "versions": _versions(),
        }
        write_yaml(run_dir / CONFIG_FILE, record)
        setup_start = time.perf_counter()
        warm_up(env_id, kwargs)  # compile (or load) the kernels once here, not in every runner at once
        start_ray(address, max(env_runners, 1), node_ip_address)
        try:
            say(
                f"training RLlib PPO on {env_id} (mode={mode}) for up to {iterations} iterations, {env_runners} env "
                f"runners x {envs_per_runner} envs ({vectorize}), seed {seed} -> {run_dir}"
            )
            algo = config.build_algo()
            placement = runner_placement(algo)
            for spot in placement:
                say(
                    f"env runner {spot['runner']}: node {spot['node_id'][:12]} ({spot['node_address']}"
                    f"{', the driver node' if spot['driver_node'] else ''}), pid {spot['pid']}"
                )
            history = []
            start = time.perf_counter()
            setup_seconds = start - setup_start
            env_steps = 0
            for it in range(1, iterations + 1):
                result = algo.train()
                env_steps = int(result.get("num_env_steps_sampled_lifetime", env_steps))
                ret = result.get("env_runners", {}).get("episode_return_mean", float("nan"))
                line = (
                    f"iteration {it}: {env_steps:,} env steps, episode return {ret:.2f}, "
                    f"{time.perf_counter() - start:.0f} s"
                )
                if it % eval_every == 0 or it == iterations:
                    success = success_rate(algo.get_module(), env_id, kwargs, eval_episodes, EVAL_SEED)
                    history.append(
                        {
                            "iteration": it,
                            "env_steps": env_steps,
                            "success": success,
                            "seconds": round(time.perf_counter() - start, 2),
                        }
                    )
                    line += f", evaluation success {100 * success:.0f} %"
                    if success >= target:
                        say(line + f" (target {100 * target:.0f} % reached)")
                        break
                say(line)
            seconds = time.perf_counter() - start
            algo.save_to_path(str((run_dir / CHECKPOINT_DIR).resolve()))
            algo.stop()
        finally:
            ray.shutdown()  # stops the local instance; with --address it only disconnects from the cluster
        record.update(
            {
                "setup_seconds": round(setup_seconds, 2),
                "train_seconds": round(seconds, 2),
                "iterations_done": it,
                "env_steps_done": env_steps,
                "evaluations": history,
                "final_success": history[-1]["success"] if history else None,
                "runner_placement": placement,
            }
        )
        write_yaml(run_dir / CONFIG_FILE, record)
        say(
            f"trained {env_steps:,} env steps in {seconds:.0f} s ({env_steps / seconds:,.0f} steps/s); "
            f"checkpoint {run_dir / CHECKPOINT_DIR}"
        )
    return run_dir


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m agents.train_rllib",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__,
    )
    p.add_argument("--env", default=DEFAULT_ENV, help="registered env id (default: %(default)s)")
    p.add_argument("--iterations", type=int, help="most training iterations (default: the entry's)")
    p.add_argument("--env-runners", type=int, help="remote env runners (default: the entry's)")
    p.add_argument("--envs-per-runner", type=int, help="sub-envs per env runner (default: the entry's)")
    p.add_argument(
        "--vectorize",
        choices=("native", "sync"),
        help="native batched vector env per runner (default), or RLlib's sync vectorisation",
    )
    p.add_argument("--address", help="join this Ray cluster (host:port of `ray start --head`); default: local Ray")
    p.add_argument(
        "--node-ip-address", help="with --address: this machine's address in the cluster (default: Ray's guess)"
    )
    p.add_argument("--target-success", type=float, help="stop at this evaluation success share (default: 0.9)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--mode", choices=MODES, help="engine fidelity mode (default: exact)")
    p.add_argument("--substeps", type=int, help="sub-steps per control step for naive/posteriori")
    p.add_argument("--env-kwargs", nargs="*", metavar="KEY=VALUE", help="more env keywords, e.g. dt=0.1")
    p.add_argument("--output", default="runs", help="folder for run folders (default: %(default)s)")
    p.add_argument(
        "--run-name",
        help="run folder name (default: <env>-<mode><k>-s<seed>-<time>, k the sub-steps if not 1, as PPO's)",
    )
    p.add_argument("--overwrite", action="store_true", help="replace an existing run folder")
    p.add_argument("--hyperparams", default=str(HYPERPARAMS), help="hyperparameter YAML (default: the shipped file)")
    p.add_argument("--threads", type=int, default=1, help="torch threads of the learner (default: %(default)s)")
    return p


def main(argv: list[str] | None = None) -> Path:
    args = build_parser().parse_args(argv)
    run_dir = train(
        args.env,
        iterations=args.iterations,
        env_runners=args.env_runners,
        envs_per_runner=args.envs_per_runner,
        vectorize=args.vectorize,
        address=args.address,
        node_ip_address=args.node_ip_address,
        seed=args.seed,
        mode=args.mode,
        substeps=args.substeps,
        env_kwargs=parse_env_kwargs(args.env_kwargs),
        output=args.output,
        run_name=args.run_name,
        hyperparams=args.hyperparams,
        target_success=args.target_success,
        overwrite=args.overwrite,
        threads=args.threads,
        log=lambda line: print(line, flush=True),
    )
    print(f"checkpoint: {run_dir / CHECKPOINT_DIR}")
    print(f"config:     {run_dir / CONFIG_FILE}")
    print(f"evaluate:   python -m agents.evaluate {run_dir}")
    return run_dir


if __name__ == "__main__":
    run_cli(main, prog="agents.train_rllib", extras=("distributed",))
