"""What the agent scripts leave and say: progress without a terminal, no silent overwrite, the
subprocess start method, and a clear message when an optional extra is missing."""

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

from agents import curve, evaluate, train_ppo, train_rllib
from agents.config import UsageError
from collision_env.extras import MissingExtra

ROOT = Path(__file__).resolve().parents[2]
TINY = ["--timesteps", "2048", "--n-envs", "4", "--eval-freq", "0", "--save-freq", "0"]


def test_training_through_a_pipe_prints_progress_lines_and_keeps_them_in_the_run(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "agents.train_ppo", *TINY, "--output", str(tmp_path), "--run-name", "piped"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    progress = [line for line in run.stdout.splitlines() if " steps (" in line]
    assert len(progress) >= 2 and progress[-1].startswith("2,048 / 2,048 steps (100 %)")
    assert (tmp_path / "piped" / train_ppo.LOG_FILE).read_text().splitlines() == progress


def test_evaluate_never_replaces_an_earlier_evaluation(tmp_path):
    run_dir = train_ppo.main(TINY + ["--no-progress", "--output", str(tmp_path), "--run-name", "r"])
    first = evaluate.main([str(run_dir), "--episodes", "2", "--no-baselines"])
    second = evaluate.main([str(run_dir), "--episodes", "3", "--no-baselines"])
    assert json.loads((run_dir / "eval-exact.json").read_text())["episodes"] == first["episodes"] == 2
    assert json.loads((run_dir / "eval-exact-2.json").read_text())["episodes"] == second["episodes"] == 3
    mine = tmp_path / "mine.json"
    mine.write_text("{}")
    with pytest.raises(UsageError, match="--overwrite"):
        evaluate.main([str(run_dir), "--episodes", "2", "--no-baselines", "--json", str(mine)])
    assert mine.read_text() == "{}"  # refused before evaluating: untouched
    evaluate.main([str(run_dir), "--episodes", "2", "--no-baselines", "--json", str(mine), "--overwrite"])
    assert json.loads(mine.read_text())["episodes"] == 2


def test_the_learning_curve_reads_every_monitor_file_in_the_order_episodes_ended(tmp_path):
    (tmp_path / "0.monitor.csv").write_text(
        '#{"t_start": 100.0}\nr,l,t,is_success\n1.0,10,5.0,True\n3.0,30,9.0,False\n'
    )
    (tmp_path / "1.monitor.csv").write_text('#{"t_start": 103.0}\nr,l,t,is_success\n2.0,20,4.0,True\n')
    episodes = curve.training_episodes(tmp_path)  # ended at 105, 107, 109
    assert episodes["steps"].tolist() == [10, 30, 60]
    assert episodes["return"].tolist() == [1.0, 2.0, 3.0] and episodes["success"].tolist() == [1, 1, 0]
    assert curve.running_mean(np.array([1.0, 2.0, 3.0, 4.0]), 2).tolist() == [1.0, 1.5, 2.5, 3.5]
    assert curve.plot_learning_curve(tmp_path).is_file()
    assert curve.plot_learning_curve(tmp_path / "empty") is None  # no episode ended: no picture


def test_training_without_matplotlib_says_so_in_one_line_and_finishes(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if it were not installed
    lines = []
    run_dir = train_ppo.train(timesteps=2048, n_envs=4, eval_freq=0, save_freq=0, output=tmp_path, log=lines.append)
    assert (run_dir / "model.zip").is_file() and not (run_dir / curve.CURVE_FILE).exists()
    assert lines[-1] == (
        "the learning curve needs the 'plot' extra (matplotlib is missing): pip install -e \".[plot]\""
    )


def test_subproc_workers_fork_on_linux():
    expected = "fork" if sys.platform.startswith("linux") else ("forkserver", "spawn")
    assert train_ppo.subproc_start_method() in expected


@pytest.mark.skipif(importlib.util.find_spec("ray") is not None, reason="ray is installed here")
def test_train_rllib_without_ray_says_how_to_install_it(tmp_path):
    with pytest.raises(MissingExtra, match=r'pip install -e "\.\[distributed\]"'):
        train_rllib.train(output=tmp_path)
    assert not any(tmp_path.iterdir())  # nothing written


def test_train_rllib_rejects_bad_settings_before_starting_anything(tmp_path):
    with pytest.raises(UsageError, match="unknown env id"):
        train_rllib.train("CollisionEnv/Nope-v0", output=tmp_path)
    with pytest.raises(UsageError, match="iterations"):
        train_rllib.train(iterations=0, output=tmp_path)
    with pytest.raises(UsageError, match="target_success"):
        train_rllib.train(target_success=1.5, output=tmp_path)
    assert not any(tmp_path.iterdir())


def test_the_rllib_hyperparameter_file_has_an_entry_for_the_default_env():
    from agents.config import load_yaml

    raw = load_yaml(train_rllib.HYPERPARAMS)
    entry = raw[train_rllib.DEFAULT_ENV]
    assert entry["vectorize"] == "native" and 0 < entry["target_success"] <= 1
    assert entry["train_batch_size_per_learner"] >= entry["minibatch_size"]


def test_run_preparation_is_shared_kwargs_merge_folder_name_and_overwrite_rule(tmp_path):
    from agents.config import make_run_dir, merge_env_kwargs, run_label

    entry, given = {"mode": "posteriori", "dt": 0.1}, {"dt": 0.2, "substeps": 2}
    assert merge_env_kwargs(entry, given) == {"mode": "posteriori", "dt": 0.2, "substeps": 2}
    assert merge_env_kwargs(entry, given, mode="naive", substeps=4) == {"mode": "naive", "dt": 0.2, "substeps": 4}
    with pytest.raises(UsageError, match="render_mode"):
        merge_env_kwargs({}, {"render_mode": "rgb_array"})
    kwargs = merge_env_kwargs({}, {}, mode="posteriori", substeps=4)
    run_dir = make_run_dir(tmp_path, None, "CollisionEnv/Billiards-v0", kwargs, 3, overwrite=False)
    assert run_dir.name.startswith("billiards-posteriori4-s3-")
    assert run_label("CollisionEnv/Billiards-v0", "posteriori", 4, 3) == "billiards-posteriori4-s3"
    (run_dir / "old.txt").write_text("an earlier run")
    with pytest.raises(UsageError, match="--overwrite"):
        make_run_dir(tmp_path, run_dir.name, "CollisionEnv/Billiards-v0", kwargs, 3, overwrite=False)
    assert (run_dir / "old.txt").is_file()  # refused: untouched
    assert not any(make_run_dir(tmp_path, run_dir.name, "x/y-v0", kwargs, 3, overwrite=True).iterdir())


def test_the_log_tee_writes_every_line_and_closes_its_file_on_an_error(tmp_path, monkeypatch):
    from agents.config import log_tee

    opened, real_open = [], Path.open

    def recording_open(self, *args, **kwargs):
        opened.append(real_open(self, *args, **kwargs))
        return opened[-1]

    monkeypatch.setattr(Path, "open", recording_open)
    seen, path = [], tmp_path / "train.log"
    with pytest.raises(RuntimeError), log_tee(seen.append, path) as say:
        say("one")
        say("two")
        raise RuntimeError("training failed")
    assert seen == ["one", "two"] and path.read_text() == "one\ntwo\n"
    assert len(opened) >= 1 and all(fh.closed for fh in opened)
    with log_tee(seen.append, None) as say:
        assert say == seen.append  # no file: the logger itself


def test_rllib_run_folders_are_named_as_ppos(tmp_path, monkeypatch):
    pytest.importorskip("ray")
    made = {}

    def stop(output, run_name, env_id, kwargs, seed, overwrite):
        made.update(kwargs=kwargs, seed=seed)
        raise UsageError("stop here")

    monkeypatch.setattr(train_rllib, "make_run_dir", stop)
    with pytest.raises(UsageError, match="stop here"):
        train_rllib.train(output=tmp_path, mode="posteriori", substeps=4, seed=2)
    assert made == {"kwargs": {"mode": "posteriori", "substeps": 4}, "seed": 2}
