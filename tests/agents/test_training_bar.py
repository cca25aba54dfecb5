"""The sample agent's bar, as a long study (``pytest -m study``; not in the default run).

PPO with the shipped hyperparameters must reach at least 95 % success over 100 deterministic
evaluation episodes of the default preset within 10 minutes of training on a 2-core CPU.
"""

import pytest

pytest.importorskip("stable_baselines3")

from agents import config, evaluate, train_ppo


@pytest.mark.study
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ppo_reaches_95_percent_on_the_default_preset_within_10_minutes(tmp_path, seed):
    run = train_ppo.train(
        "CollisionEnv/OneBallTarget-v0",
        seed=seed,
        output=tmp_path,
        run_name="bar",
        eval_freq=0,
        save_freq=0,
        log=lambda *a: None,
    )
    assert config.read_run(run)["train_seconds"] < 600
    results = evaluate.evaluate(run, episodes=100, mode="exact", baselines=("random",))
    assert results["policies"]["ppo"]["success_rate"] >= 0.95
    assert results["policies"]["random"]["success_rate"] < 0.2
