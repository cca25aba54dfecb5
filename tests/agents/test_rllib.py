"""RLlib smoke test: a local Ray instance, 2 env runners, 2 iterations, a checkpoint written and
reloaded by agents.evaluate (skipped where ray is not installed: pip install -e ".[distributed]")."""

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("ray.rllib")
pytest.importorskip("yaml")

from agents import evaluate, train_rllib
from agents.config import load_yaml

ROOT = Path(__file__).resolve().parents[2]
ENV_ID = "CollisionEnv/OneBallTarget-v0"

SMALL = """
default:
  iterations: 2
  env_runners: 2
  envs_per_runner: 4
  vectorize: native
  target_success: 1.0
  eval_episodes: 10
  eval_every: 1
  fcnet_hiddens: [16, 16]
  train_batch_size_per_learner: 512
  minibatch_size: 128
  num_epochs: 1
"""


def test_the_creator_imports_the_package_itself_in_a_fresh_process():
    code = f"""
import sys
from agents.rllib_env import make_env
assert "collision_env" not in sys.modules
vec = make_env({{"env_id": {ENV_ID!r}, "num_envs": 3}})
single = make_env({{"env_id": {ENV_ID!r}, "dt": 0.1}})
obs, info = vec.reset(seed=0)
obs, reward, term, trunc, info = vec.step(vec.action_space.sample())
assert "impacts" not in info and info["is_success"].shape == (3,)
print(type(vec.unwrapped).__name__, vec.num_envs, type(single.unwrapped).__name__, single.unwrapped.config.dt)
"""
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["OneBallTargetVectorEnv", "3", "OneBallTargetEnv", "0.1"]


def test_two_runners_on_a_local_cluster_write_a_checkpoint_that_evaluate_reloads(tmp_path):
    hp = tmp_path / "small.yml"
    hp.write_text(SMALL)
    lines = []
    run_dir = train_rllib.train(ENV_ID, hyperparams=hp, output=tmp_path, run_name="smoke", log=lines.append)

    run = load_yaml(run_dir / "config.yml")
    assert run["algorithm"] == train_rllib.ALGORITHM and run["iterations_done"] == 2
    assert run["env_steps_done"] >= 2 * 512 and run["train_seconds"] > 0
    assert len(run["runner_placement"]) == 2
    assert len({spot["pid"] for spot in run["runner_placement"]}) == 2  # two runner processes
    assert all(spot["node_address"] == "127.0.0.1" for spot in run["runner_placement"])  # loopback only
    assert [e["iteration"] for e in run["evaluations"]] == [1, 2]
    assert (run_dir / train_rllib.CHECKPOINT_DIR).is_dir()
    log = (run_dir / train_rllib.LOG_FILE).read_text()
    assert "iteration 1:" in log and "iteration 2:" in log and log.splitlines() == lines

    # the reloaded policy plays the same evaluation episodes exactly as the trained one did
    results = evaluate.evaluate(run_dir, episodes=10)
    assert results["trainer"] == "rllib"
    assert results["policies"]["ppo"]["success_rate"] == pytest.approx(run["evaluations"][-1]["success"])
    assert results["policies"]["random"] is not None and results["policies"]["scripted"] is not None
    assert "RLlib PPO" in evaluate.markdown(results)


def test_a_run_from_the_command_line_logs_none_of_rays_routine_notes(tmp_path):
    hp = tmp_path / "small.yml"
    hp.write_text(SMALL.replace("env_runners: 2", "env_runners: 1"))
    command = ["--hyperparams", str(hp), "--output", str(tmp_path), "--run-name", "quiet"]
    run = subprocess.run(
        [sys.executable, "-m", "agents.train_rllib", *command], capture_output=True, text=True, cwd=ROOT, timeout=600
    )
    assert run.returncode == 0, run.stderr
    assert "iteration 2:" in run.stdout
    # Ray's Python log lines read "<time>\t<LEVEL> <file>:<line> -- <message>"; warnings and errors would stay
    notes = [line for line in run.stderr.splitlines() if "\tINFO " in line or "\tWARNING " in line]
    assert notes == []
