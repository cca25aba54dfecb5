"""The sample agents: hyperparameter file, train -> save -> reload -> evaluate, the main job, the study, bad input."""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

import collision_env
from agents import config, evaluate, study, timing, train_ppo
from agents import main as main_job

ROOT = Path(__file__).resolve().parents[2]
TINY = ["--timesteps", "2048", "--n-envs", "4", "--no-progress"]


def _finite(results):
    for name, r in results["policies"].items():
        if r is None:
            continue
        for key in ("success_rate", "mean_return", "mean_nudge", "mean_nudge_cost", "mean_targets_hit", "mean_length"):
            assert math.isfinite(r[key]), (name, key)
        assert 0.0 <= r["success_rate"] <= 1.0 and r["mean_nudge"] >= 0.0
        lo, hi = r["success_ci95"]
        assert 0.0 <= lo <= r["success_rate"] <= hi <= 1.0


# --------------------------------------------------------------------------------- hyperparameters
@pytest.mark.parametrize("env_id", collision_env.ENV_IDS)
def test_hyperparams_have_a_tuned_entry_that_builds_ppo_for_every_id(env_id):
    from stable_baselines3 import PPO

    raw = config.load_yaml(config.HYPERPARAMS)
    assert env_id in raw  # an entry of its own, not just the default
    hp = config.hyperparams_for(env_id)
    assert hp["n_timesteps"] >= 1e5 and hp["n_envs"] >= 1
    kwargs = config.ppo_kwargs(hp)
    assert set(kwargs).isdisjoint(config.RUN_KEYS)
    venv = train_ppo.make_vec_env(env_id, hp["n_envs"], 0, hp.get("env_kwargs") or {})
    model = PPO(hp["policy"], venv, device="cpu", **kwargs)
    assert model.n_steps == hp["n_steps"] and model.batch_size == hp["batch_size"]
    assert config.normalize_settings(hp["normalize"]) is not None
    venv.close()


def test_rl_zoo_style_values_are_understood():
    import torch.nn as nn

    sched = config.ppo_kwargs({"learning_rate": "lin_0.001", "clip_range": 0.2})
    assert sched["learning_rate"](1.0) == pytest.approx(1e-3) and sched["learning_rate"](0.25) == pytest.approx(2.5e-4)
    pk = config.ppo_kwargs({"policy_kwargs": "dict(net_arch=[32], activation_fn=nn.ReLU)"})["policy_kwargs"]
    assert pk == {"net_arch": [32], "activation_fn": nn.ReLU}
    assert config.ppo_kwargs({"policy_kwargs": {"activation_fn": "tanh"}})["policy_kwargs"]["activation_fn"] is nn.Tanh
    assert config.normalize_settings("{'norm_obs': True, 'norm_reward': False}") == {
        "norm_obs": True,
        "norm_reward": False,
    }
    assert config.normalize_settings(False) is None
    assert config.parse_env_kwargs(["mode=naive", "dt=0.1", "substeps=4"]) == {
        "mode": "naive",
        "dt": 0.1,
        "substeps": 4,
    }
    for bad in ({"learning_rate": "lin_x"}, {"policy_kwargs": "open('x')"}, {"policy_kwargs": {"activation_fn": "no"}}):
        with pytest.raises(config.UsageError):
            config.ppo_kwargs(bad)


def test_native_and_sb3_vector_envs_play_the_same_episodes_through_their_ends():
    # dt = 0.025 makes an episode 400 control steps, past the registered max_episode_steps of 200
    kwargs = {"mode": "posteriori", "substeps": 2, "dt": 0.025}
    native = train_ppo.make_vec_env("CollisionEnv/Billiards-v0", 3, 5, kwargs, "native")
    dummy = train_ppo.make_vec_env("CollisionEnv/Billiards-v0", 3, 5, kwargs, "dummy")
    assert np.array_equal(native.reset(), dummy.reset())
    rng = np.random.default_rng(0)
    ends = []
    for t in range(1, 421):
        actions = rng.uniform(-1, 1, (3, 2)).astype(np.float32)
        (o1, r1, d1, i1), (o2, r2, d2, i2) = native.step(actions), dummy.step(actions)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)
        for a, b in zip(i1, i2, strict=True):
            assert a["is_success"] == b["is_success"] and a["TimeLimit.truncated"] == b["TimeLimit.truncated"]
            assert ("terminal_observation" in a) == ("terminal_observation" in b)
            if "terminal_observation" in a:
                assert np.array_equal(a["terminal_observation"], b["terminal_observation"])
                assert a["episode"]["r"] == pytest.approx(b["episode"]["r"], rel=1e-5)
                ends.append((t, a["TimeLimit.truncated"]))
    assert ends and all(t == 400 for t, truncated in ends if truncated)  # the task's own length, not 200


# --------------------------------------------------------------------------- train, save, evaluate
def test_train_save_reload_evaluate_and_record(tmp_path):
    run = train_ppo.main(
        TINY
        + [
            "--output",
            str(tmp_path),
            "--run-name",
            "smoke",
            "--eval-freq",
            "1024",
            "--save-freq",
            "1024",
            "--eval-episodes",
            "2",
            "--env-kwargs",
            "time_limit=2.0",
        ]
    )
    files = ("config.yml", "model.zip", "vecnormalize.pkl", "best_model.zip", "monitor.csv", "eval/evaluations.npz")
    files += ("learning_curve.png",)
    for name in files:
        assert (run / name).is_file(), name
    assert list((run / "checkpoints").glob("model_*_steps.zip")) and list((run / "tb").rglob("events.out.tfevents.*"))
    cfg = config.read_run(run)
    assert cfg["env_id"] == "CollisionEnv/OneBallTarget-v0" and cfg["timesteps_done"] >= 2048
    assert cfg["env_kwargs"] == {"time_limit": 2.0} and cfg["episode_steps"] == 40 and cfg["train_seconds"] > 0
    split = cfg["time_split"]  # where the time went: every part measured, none negative, adding up
    assert list(split) == list(timing.PARTS) and all(v >= 0 for v in split.values())
    assert split["engine"] > 0 and split["policy forward, acting"] > 0 and split["backward and optimiser"] > 0
    assert sum(split.values()) == pytest.approx(cfg["train_seconds"], abs=0.05)
    assert cfg["train_cpu_seconds"] > 0  # the process's CPU time, beside the wall-clock

    log = np.load(run / "eval" / "evaluations.npz")
    assert log["timesteps"].tolist() == [1024, 2048] and log["results"].shape == (2, 2)
    assert list((run / "checkpoints").glob("model_vecnormalize_*_steps.pkl"))

    results = evaluate.main([str(run), "--episodes", "3", "--gif"])
    _finite(results)
    assert set(results["policies"]) == {"ppo", "random", "scripted"}
    assert results["mode"] == "exact" and results["policies"]["ppo"]["mean_length"] <= 40
    assert json.loads((run / "eval-exact.json").read_text())["episodes"] == 3
    assert (run / "episodes.gif").stat().st_size > 1000

    # the same policy under another engine mode (train in one, evaluate in another)
    other = evaluate.evaluate(run, episodes=2, mode="posteriori", substeps=4, baselines=())
    assert (other["mode"], other["substeps"], other["train_mode"]) == ("posteriori", 4, "exact")
    _finite(other)
    sim = evaluate.make_env(cfg["env_id"], evaluate.eval_kwargs(cfg, "posteriori", 4)).unwrapped.simulator
    assert (sim.mode, sim.substeps) == ("posteriori", 4)  # the engine really runs in the other mode
    # deterministic: the same episodes give the same figures
    again = evaluate.evaluate(run, episodes=3, baselines=())
    assert again["policies"]["ppo"]["mean_return"] == results["policies"]["ppo"]["mean_return"]


def test_observation_normalisation_uses_the_statistics_saved_with_each_model(tmp_path):
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    hp = dict(
        config.hyperparams_for("CollisionEnv/OneBallTarget-v0"), normalize={"norm_obs": True, "norm_reward": True}
    )
    hp_file = tmp_path / "hp.yml"
    config.write_yaml(hp_file, {"CollisionEnv/OneBallTarget-v0": hp})
    args = TINY + [
        "--hyperparams",
        str(hp_file),
        "--output",
        str(tmp_path),
        "--run-name",
        "n",
        "--eval-freq",
        "1024",
        "--eval-episodes",
        "2",
        "--save-freq",
        "0",
    ]
    run = train_ppo.main(args)
    assert (run / "vecnormalize.pkl").is_file() and (run / "best_vecnormalize.pkl").is_file()
    env = evaluate.make_env("CollisionEnv/OneBallTarget-v0", {})
    obs, _ = env.reset(seed=3)
    for which, model_file, stats_file in (
        ("final", "model.zip", "vecnormalize.pkl"),
        ("best", "best_model.zip", "best_vecnormalize.pkl"),
    ):
        act = evaluate.trained_policy(run, which)(env.unwrapped, 0)
        venv = train_ppo.make_vec_env("CollisionEnv/OneBallTarget-v0", 1, 0, {})
        stats = VecNormalize.load(str(run / stats_file), venv)
        expect = PPO.load(run / model_file, device="cpu").predict(stats.normalize_obs(obs), deterministic=True)[0]
        assert np.allclose(act(obs), expect, atol=1e-6)
    # --overwrite replaces the whole folder: no statistics of the earlier run survive
    train_ppo.main(
        TINY + ["--output", str(tmp_path), "--run-name", "n", "--overwrite", "--eval-freq", "0", "--save-freq", "0"]
    )
    assert not (run / "best_vecnormalize.pkl").exists() and not (run / "best_model.zip").exists()
    _finite(evaluate.evaluate(run, episodes=2, baselines=()))


def test_a_run_config_repeats_its_run(tmp_path):
    first = train_ppo.main(
        [
            "--env",
            "CollisionEnv/Line1D-v0",
            "--seed",
            "3",
            "--vec-env",
            "dummy",
            "--eval-freq",
            "0",
            "--save-freq",
            "0",
            "--output",
            str(tmp_path),
            "--run-name",
            "a",
            *TINY,
        ]
    )
    again = train_ppo.main(
        ["--hyperparams", str(first / "config.yml"), "--output", str(tmp_path), "--run-name", "b", "--no-progress"]
    )
    a, b = config.read_run(first), config.read_run(again)
    for key in ("env_id", "seed", "vec_env", "n_envs", "n_timesteps", "env_kwargs", "callbacks", "episode_steps"):
        assert a[key] == b[key], key
    assert (b["env_id"], b["seed"], b["vec_env"]) == ("CollisionEnv/Line1D-v0", 3, "dummy")
    from stable_baselines3 import PPO

    pa = PPO.load(first / "model.zip", device="cpu").policy.state_dict()
    pb = PPO.load(again / "model.zip", device="cpu").policy.state_dict()
    assert all(np.array_equal(pa[k].numpy(), pb[k].numpy()) for k in pa)  # the same training, bit for bit
    with pytest.raises(config.UsageError, match="config of a CollisionEnv/Line1D-v0 run"):
        train_ppo.train("CollisionEnv/OneBallTarget-v0", hyperparams=first / "config.yml", output=tmp_path)


def test_record_mp4(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    run = train_ppo.main(
        TINY
        + [
            "--output",
            str(tmp_path),
            "--run-name",
            "r",
            "--eval-freq",
            "0",
            "--save-freq",
            "0",
            "--env-kwargs",
            "time_limit=1.0",
        ]
    )
    path = evaluate.record(run, tmp_path / "ep.mp4", episodes=2)
    assert path.stat().st_size > 1000


def test_cpu_seconds_counts_this_process_and_its_ended_children():
    before = timing.cpu_seconds()
    code = "import time; sum(i * i for i in range(2_000_000)); print(time.process_time())"
    child = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)
    assert child > 0 and timing.cpu_seconds() - before >= child  # the child's CPU time, counted once it ended


def test_training_on_sb3_dummy_vec_env_and_other_mode(tmp_path):
    run = train_ppo.train(
        "CollisionEnv/Line1D-v0",
        timesteps=1024,
        n_envs=4,
        mode="naive",
        substeps=2,
        output=tmp_path,
        run_name="d",
        vec_env="dummy",
        eval_freq=0,
        save_freq=0,
        log=lambda *a: None,
    )
    cfg = config.read_run(run)
    assert cfg["env_kwargs"] == {"mode": "naive", "substeps": 2} and cfg["vec_env"] == "dummy"
    assert cfg["time_split"]["engine"] is None  # SB3's own vector envs hide the engine
    _finite(evaluate.evaluate(run, episodes=2, mode="exact"))


def test_main_job_trains_evaluates_and_records(tmp_path, capsys):
    run = main_job.main(["--timesteps", "2048", "--episodes", "2", "--output", str(tmp_path), "--no-progress"])
    out = capsys.readouterr().out
    for path in (run / "model.zip", run / "episodes.gif", run / "eval-exact.json", run / "learning_curve.png"):
        assert path.is_file() and str(path) in out
    assert "| random |" in out and f"| {evaluate.SCRIPTED_LABEL} |" in out and "tensorboard --logdir" in out


def test_study_writes_tables_plot_and_readme_block(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text("x\n<!-- agents:study:start -->\nold\n<!-- agents:study:end -->\ny\n")
    docs = tmp_path / "docs"
    data = study.main(
        [
            "--envs",
            "CollisionEnv/OneBallTarget-v0",
            "--modes",
            "naive:1",
            "exact:1",
            "--seeds",
            "0",
            "1",
            "--presets",
            "CollisionEnv/Line1D-v0",
            "CollisionEnv/OneBallTarget-v0",
            "--timesteps",
            "1024",
            "--episodes",
            "2",
            "--output",
            str(tmp_path / "runs"),
            "--docs",
            str(docs),
            "--readme",
            str(readme),
        ]
    )
    modes = [r for r in data["rows"] if r["part"] == "modes"]
    assert {(r["mode"], r["seed"]) for r in modes} == {("naive", 0), ("naive", 1), ("exact", 0), ("exact", 1)}
    presets = [r["env_id"] for r in data["rows"] if r["part"] == "presets"]
    assert sorted(presets) == ["CollisionEnv/Line1D-v0"] * 2 + ["CollisionEnv/OneBallTarget-v0"] * 2
    assert len(list((tmp_path / "runs").iterdir())) == 6  # the exact OneBallTarget runs are shared, not retrained
    for name in ("study.json", "modes.md", "presets.md", "modes.png"):
        assert (docs / name).is_file(), name
    text = readme.read_text()
    assert "old" not in text and "| naive k=1 |" in text and "`CollisionEnv/Line1D-v0`" in text
    assert text.startswith("x\n") and text.endswith("y\n")
    assert "| engine's share of it |" in text and "Where the training time goes" in text and "**Rule**" in text
    assert (docs / "time_split.md").is_file()
    # --render rebuilds the same tables from the JSON alone
    before = (docs / "modes.md").read_text()
    (docs / "modes.md").unlink()
    study.main(["--render", "--docs", str(docs)])
    assert (docs / "modes.md").read_text() == before
    # --add measures more cells into the same study: one more seed of one cell, a preset trained afresh
    more = study.main(
        [
            "--part",
            "presets",
            "--presets",
            "CollisionEnv/Line1D-v0",
            "--seeds",
            "1",
            "--timesteps",
            "1024",
            "--episodes",
            "2",
            "--output",
            str(tmp_path / "runs"),
            "--docs",
            str(docs),
            "--add",
        ]
    )
    assert len(more["rows"]) == len(data["rows"]) and more["meta"]["minutes"] > data["meta"]["minutes"]
    assert {r["run"] for r in more["rows"]} == {r["run"] for r in data["rows"]}  # the same cell, replaced


def test_study_by_default_trains_every_mode_of_the_trade_and_draws_its_pareto_figure(tmp_path):
    # the smallest configuration of the full study's code path: one preset, one seed, the default modes
    docs = tmp_path / "docs"
    data = study.main(
        ["--part", "modes", "--envs", "CollisionEnv/Pegs-v0", "--seeds", "0", "--timesteps", "512", "--episodes", "2"]
        + ["--output", str(tmp_path / "runs"), "--docs", str(docs)]
    )
    cells = [(r["mode"], r["substeps"]) for r in data["rows"]]
    assert (
        cells
        == [("naive", 1), ("posteriori", 1), ("posteriori", 4), ("exact", 1)]
        == [study.parse_mode(m) for m in study.DEFAULT_MODES]
    )
    for r in data["rows"]:  # every policy evaluated exact, and in its own mode
        assert 0.0 <= r["exact"]["success_rate"] <= 1.0 and 0.0 <= r["own"]["success_rate"] <= 1.0
        assert r["train_seconds"] > 0 and r["train_cpu_seconds"] > 0 and r["time_split"]["engine"] is not None
    assert (docs / "pareto.png").stat().st_size > 0
    page = (docs / "modes.md").read_text()
    assert "| `CollisionEnv/Pegs-v0` |" in page and "| posteriori k=4 |" in page and "pareto.png" in page
    assert "**Rule**" in page


def _mode_row(env_id, mode, k, seed, success, seconds, cpu_seconds=None):
    return {
        "part": "modes",
        "env_id": env_id,
        "mode": mode,
        "substeps": k,
        "seed": seed,
        "episodes": 100,
        "run": f"runs/{env_id}-{mode}{k}-{seed}",
        "train_seconds": seconds,
        "train_cpu_seconds": cpu_seconds,
        "timesteps_done": 1000,
        "time_split": {part: (0.5 * seconds if part == "engine" else 0.0) for part in timing.PARTS},
        "observe": "plain",
        "exact": {"success_rate": success, "mean_return": 1.0},
        "own": {"success_rate": 1.0, "mean_return": 1.0},
    }


def test_study_rule_names_where_training_cheap_pays_and_where_it_costs(tmp_path):
    rows = []
    for seed, jitter in enumerate((0.0, 0.02, -0.02)):
        rows += [
            _mode_row("CollisionEnv/Crowd-v0", "naive", 1, seed, 0.95 + jitter, 60.0),
            _mode_row("CollisionEnv/Crowd-v0", "exact", 1, seed, 0.96 - jitter, 90.0),
            _mode_row("CollisionEnv/Pegs-v0", "naive", 1, seed, 0.10 + jitter, 50.0),
            _mode_row("CollisionEnv/Pegs-v0", "posteriori", 4, seed, 0.80 + jitter, 80.0),
            _mode_row("CollisionEnv/Pegs-v0", "exact", 1, seed, 0.82 - jitter, 100.0),
        ]
    found = {c["env_id"]: c for c in study.comparisons(rows)}
    crowd, pegs = found["CollisionEnv/Crowd-v0"], found["CollisionEnv/Pegs-v0"]
    assert [m["verdict"] for m in crowd["cheap"]] == ["pays"] and crowd["cheap"][0]["speed"] == pytest.approx(1.5)
    assert [m["verdict"] for m in pegs["cheap"]] == ["costs", "pays"]
    assert pegs["cheap"][0]["loss"] == pytest.approx(0.72) and pegs["spread"] == pytest.approx(0.02)
    text = study.rule(rows, [])
    paid, cost = text.split("**paid**")[1].split("**cost**")
    assert "`CollisionEnv/Crowd-v0` (naive k=1 -1 points at 1.50×)" in paid
    assert "`CollisionEnv/Pegs-v0` (posteriori k=4 -2 points at 1.25×)" in paid
    assert "`CollisionEnv/Pegs-v0` (naive k=1 -72 points at 2.00×)" in cost
    table = study.trade_table(rows)
    cells = ["10 % (100 %), 50 s wall", "80 % (100 %), 80 s wall", "82 % (100 %), 100 s wall"]
    assert "| `CollisionEnv/Pegs-v0` | 50 % | " + " | ".join(cells) + " |" in table
    assert "| `CollisionEnv/Crowd-v0` | 50 % | 95 % (100 %), 60 s wall |  | 96 % (100 %), 90 s wall |" in table
    assert study.pareto_plot(rows, tmp_path / "pareto.png").stat().st_size > 0
    # no cheap mode beyond the spread: the rule says so rather than naming one
    slow = rows + [_mode_row("CollisionEnv/Pegs-v0", "posteriori", 1, seed, 0.82, 400.0) for seed in range(3)]
    idle = "**did not pay** (less than 1.05× as fast as exact) on `CollisionEnv/Pegs-v0` (posteriori k=1 +0 points"
    assert idle + " at 0.25×)" in study.rule(slow, [])
    # a speed-up within CPU time's run-to-run spread is no gain
    close = [{**r, "train_seconds": 88.0} if r["mode"] == "naive" else r for r in rows if "Crowd" in r["env_id"]]
    assert [m["verdict"] for m in study.comparisons(close)[0]["cheap"]] == ["no gain"]
    calm = [r for r in rows if r["env_id"] == "CollisionEnv/Crowd-v0"]
    assert "**cost**" not in study.rule(calm, []) and "No preset here lost" in study.rule(calm, [])


def test_study_variants_change_one_setting_of_the_entry_back_to_the_default():
    # Billiards' entry trains on the predicted observation with velocity control
    assert study.variants("CollisionEnv/Billiards-v0") == [{}, {"observe": "plain"}, {"control": "nudge"}]
    assert study.variants("CollisionEnv/Billiards-v0", "alternatives") == [{"observe": "plain"}, {"control": "nudge"}]
    assert study.variants("CollisionEnv/InelasticCluster-v0", "both") == [{}, {"observe": "plain"}]
    assert study.variants("CollisionEnv/OneBallTarget-v0", "both") == [{}]
    assert study.variants("CollisionEnv/OneBallTarget-v0", "alternatives") == []


def test_study_marks_the_entry_as_it_stands_shipped_and_lists_it_first():
    # four settings of Billiards, in the order a study file could hold them: a row trained when the
    # entry used nudges (no "control" field yet), a plain alternative, one trained when the entry
    # predicted next impacts, and the entry as it stands
    def row(seed, observe, control, env_kwargs, success):
        out = {
            "part": "presets",
            "env_id": "CollisionEnv/Billiards-v0",
            "mode": "exact",
            "substeps": 1,
            "seed": seed,
            "episodes": 100,
            "run": f"runs/{observe}-{control}-{seed}",
            "train_seconds": 10.0,
            "timesteps_done": 1000,
            "time_split": {part: 1.0 for part in timing.PARTS},
            "observe": observe,
            "env_kwargs": env_kwargs,
            "exact": {"success_rate": success, "mean_return": 1.0},
        }
        if control is not None:
            out["control"] = control
        return out

    rows = [row(0, "predicted", None, {}, 0.4), row(0, "plain", "velocity", {"observe": "plain"}, 0.3)]
    rows += [row(0, "predicted", "velocity", {}, 0.45)]
    rows += [row(0, "predicted (scoring)", "velocity", {}, 0.5), row(1, "predicted (scoring)", "velocity", {}, 0.7)]
    table = study.presets_table(rows, [])
    settings = [line.split(" | ")[1] for line in table.splitlines() if line.startswith("| `")]
    assert settings == [
        "predicted (scoring), velocity (*shipped*)",
        "plain, velocity",
        "predicted, nudge",
        "predicted, velocity",
    ]
    assert "| 60 % ± 14 | 50 % / 70 % |" in table
    shipped = study._by_preset(rows, [])[("CollisionEnv/Billiards-v0", "predicted (scoring), velocity")]
    assert [r["seed"] for r in shipped] == [0, 1]


def test_study_names_the_observation_a_run_trained_on():
    assert study._observation({}) == "plain"
    assert study._observation({"observe": "predicted"}) == "predicted"
    assert study._observation({"observe": "predicted", "predicted_impact": "next"}) == "predicted"
    assert study._observation({"observe": "predicted", "predicted_impact": "scoring"}) == "predicted (scoring)"
    assert study._observation({"predicted_impact": "scoring"}) == "plain"  # (nothing predicted is observed)


# --------------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "module, args, message",
    [
        ("agents.train_ppo", ["--env", "CollisionEnv/OneBalTarget-v0"], "unknown env id"),
        ("agents.train_ppo", ["--env-kwargs", "elasticity=2"], "elasticity"),
        ("agents.evaluate", ["/no/such/run"], "run folder not found"),
        ("agents.main", ["--env", "Nope-v0"], "unknown env id"),
    ],
)
def test_bad_input_is_a_one_line_error_without_traceback(module, args, message):
    proc = subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    "command, args, message",
    [
        ("train", ["--hyperparams", "{bad_yaml}"], "not valid YAML"),
        ("train", ["--hyperparams", "{typo_yaml}"], "unknown key(s) ['n_step']"),
        ("train", ["--hyperparams", "{gamma_yaml}"], "gamma: expected a number"),
        ("train", ["--hyperparams", "{kwargs_yaml}"], "expected a mapping of env keywords"),
        ("train", ["--env-kwargs", "mass_range=[1"], "cannot read the value"),
        ("train", ["--env-kwargs", "render_mode=human"], "render_mode cannot be set"),
        ("train", ["--seed", "-1"], "seed: expected an integer >= 0"),
        ("train", ["--threads", "0"], "threads: expected a positive integer"),
        ("train", ["--eval-freq", "-5"], "eval_freq"),
        ("train", ["--env", "CartPole-v1"], "unknown env id"),
        ("evaluate", ["{run}", "--gif", "--record-episodes", "0"], "record episodes"),
        ("evaluate", ["{run}", "--video", "x.avi"], "expected a .gif or .mp4"),
        ("evaluate", ["{run}", "--episodes", "-3"], "episodes"),
        ("study", ["--timesteps", "0"], "timesteps"),
        ("study", ["--modes", "exact:2"], "substeps must be"),
        ("study", ["--render", "--docs", "{corrupt_docs}"], "is not a study result"),
        ("study", ["--readme", "{corrupt_docs}/none.md"], "block to write into"),
    ],
)
def test_bad_input_in_process_is_one_line_and_exit_2(tmp_path, capsys, command, args, message):
    (tmp_path / "bad.yml").write_text("a: [1\n")
    config.write_yaml(tmp_path / "typo.yml", {"CollisionEnv/OneBallTarget-v0": {"n_step": 256}})
    config.write_yaml(tmp_path / "gamma.yml", {"CollisionEnv/OneBallTarget-v0": {"gamma": "abc"}})
    config.write_yaml(tmp_path / "kwargs.yml", {"CollisionEnv/OneBallTarget-v0": {"env_kwargs": [1, 2]}})
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "study.json").write_text("{not json")
    run = tmp_path / "run"
    if command == "evaluate":
        run = train_ppo.main(
            TINY + ["--output", str(tmp_path), "--run-name", "run", "--eval-freq", "0", "--save-freq", "0"]
        )
        capsys.readouterr()
    fill = {
        "bad_yaml": tmp_path / "bad.yml",
        "typo_yaml": tmp_path / "typo.yml",
        "gamma_yaml": tmp_path / "gamma.yml",
        "kwargs_yaml": tmp_path / "kwargs.yml",
        "run": run,
        "corrupt_docs": tmp_path / "docs",
    }
    argv = [a.format(**fill) for a in args] + (["--output", str(tmp_path / "out")] if command == "train" else [])
    main = {"train": train_ppo.main, "evaluate": evaluate.main, "study": study.main}[command]
    with pytest.raises(SystemExit) as exit_info:
        config.run_cli(main, argv, prog=command)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())  # no half-made run folder


def test_a_folder_that_is_not_a_run_is_rejected(tmp_path):
    with pytest.raises(config.UsageError, match="not a training run folder"):
        evaluate.evaluate(tmp_path)
    with pytest.raises(config.UsageError, match="exists and is not empty"):
        (tmp_path / "x").mkdir()
        (tmp_path / "x" / "f").write_text("")
        train_ppo.train("CollisionEnv/OneBallTarget-v0", timesteps=10, output=tmp_path, run_name="x")


def test_study_compares_modes_by_cpu_time_where_every_run_recorded_it():
    # Wall-clock says naive trained 1.5x as fast; the CPU time says it did the same work: no gain.
    rows = []
    for seed in range(3):
        rows += [
            _mode_row("CollisionEnv/Crowd-v0", "naive", 1, seed, 0.95, 60.0, cpu_seconds=57.0),
            _mode_row("CollisionEnv/Crowd-v0", "exact", 1, seed, 0.95, 90.0, cpu_seconds=57.0),
        ]
    (crowd,) = study.comparisons(rows)
    assert crowd["clock"] == "cpu" and crowd["cheap"][0]["speed"] == pytest.approx(1.0)
    assert crowd["cheap"][0]["verdict"] == "no gain"
    assert "95 % (100 %), 57 s CPU" in study.trade_table(rows)
    assert "| 60 | 57 | 1.00 |" in study.modes_table(rows)
    # one run without its CPU time: the preset falls back to wall-clock throughout
    rows[0] = {**rows[0], "train_cpu_seconds": None}
    (crowd,) = study.comparisons(rows)
    assert crowd["clock"] == "wall" and crowd["cheap"][0]["speed"] == pytest.approx(1.5)
