"""The agents' surface: the shipped PPO settings in one call, training that stops where it was asked
to (or says why not), and evaluation that shows its progress."""

import pytest

pytest.importorskip("stable_baselines3")

from agents import config, evaluate, train_ppo


def test_tuned_ppo_builds_what_the_cli_trains(tmp_path):
    """The Billiards entry (64 sub-envs of 128 steps, a decaying learning rate, the predicted
    observation and velocity control, reward normalisation), on the native vector env."""
    from stable_baselines3.common.vec_env import VecNormalize

    from collision_env.envs.sb3 import CollisionSB3VecEnv

    env_id = "CollisionEnv/Billiards-v0"
    hp = config.hyperparams_for(env_id)
    import torch

    torch.set_num_threads(2)
    model, timesteps = train_ppo.tuned_ppo(env_id, seed=3)
    assert torch.get_num_threads() == 1  # as the command trains
    venv = model.get_env()
    assert isinstance(venv, VecNormalize) and venv.num_envs == hp["n_envs"]
    assert isinstance(venv.venv.unwrapped, CollisionSB3VecEnv)
    assert venv.norm_reward and not venv.norm_obs
    assert model.n_steps == hp["n_steps"] and model.batch_size == hp["batch_size"] and model.seed == 3
    assert model.learning_rate(1.0) == pytest.approx(float(hp["learning_rate"].removeprefix("lin_")))
    cfg = venv.venv.unwrapped.venv.unwrapped.config  # the native vector env's task config
    assert (cfg.observe, cfg.control) == (hp["env_kwargs"]["observe"], hp["env_kwargs"]["control"])
    assert timesteps >= hp["n_timesteps"] and timesteps % (hp["n_envs"] * hp["n_steps"]) == 0
    venv.close()


def test_tuned_ppo_takes_overrides_and_learns_the_steps_it_returns():
    model, timesteps = train_ppo.tuned_ppo(
        "CollisionEnv/OneBallTarget-v0", n_envs=4, timesteps=2000, env_kwargs={"mode": "naive"}
    )
    assert timesteps == 2048  # 4 envs x 256 steps per update: 2000 rounded up to whole rollouts
    model.learn(timesteps)
    assert model.num_timesteps == timesteps
    assert model.get_env().venv.unwrapped.venv.unwrapped.config.mode == "naive"
    model.get_env().close()
    with pytest.raises(config.UsageError, match="dt"):
        train_ppo.tuned_ppo("CollisionEnv/OneBallTarget-v0", env_kwargs={"dt": -1.0})


def test_training_stops_at_the_steps_asked_or_says_why_it_rounded_up(tmp_path):
    lines = []
    run = train_ppo.train(
        timesteps=1024, n_envs=4, eval_freq=0, save_freq=0, output=tmp_path, run_name="whole", log=lines.append
    )
    assert config.read_run(run)["timesteps_done"] == 1024  # one whole rollout: exactly as asked
    assert not any("rounded up" in line for line in lines)
    lines.clear()
    run = train_ppo.train(
        timesteps=1500, n_envs=4, eval_freq=0, save_freq=0, output=tmp_path, run_name="rounded", log=lines.append
    )
    assert config.read_run(run)["timesteps_done"] == 2048
    (why,) = [line for line in lines if "rounded up" in line]
    assert "4 envs x 256 steps = 1,024 env steps" in why and "1,500 steps asked, rounded up to 2,048" in why
    assert any(line.startswith("2,048 / 2,048 steps (100 %)") for line in lines)


def test_evaluation_shows_each_policys_progress_one_line_per_10_percent(tmp_path, capsys):
    run = train_ppo.train(
        timesteps=1024, n_envs=4, eval_freq=0, save_freq=0, output=tmp_path, run_name="r", log=lambda *_: None
    )
    capsys.readouterr()
    evaluate.evaluate(run, episodes=20, progress=False)
    out = capsys.readouterr().out.splitlines()
    for name in ("PPO", "random", "scripted"):
        mine = [line for line in out if line.startswith(f"evaluating {name}: ")]
        assert [line.split(": ")[1].split(" ")[0] for line in mine] == [f"{2 * k}/20" for k in range(1, 11)]
        assert mine[-1].startswith(f"evaluating {name}: 20/20 episodes (100 %), ")


def test_a_terminal_gets_a_bar_and_ci_gets_lines(monkeypatch):
    monkeypatch.setattr("sys.stdout.isatty", lambda: True)
    monkeypatch.delenv("CI", raising=False)
    assert config.wants_progress(None)
    monkeypatch.setenv("CI", "true")
    assert not config.wants_progress(None) and config.wants_progress(True)
