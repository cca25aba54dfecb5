"""The optional extras: the module table agrees with pyproject.toml, and every entry point without
its extra says which one to install, in one line."""

import importlib.metadata
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from collision_env.extras import EXTRAS, MissingExtra, extra_of, require

ROOT = Path(__file__).resolve().parents[1]


def _normal(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _requirement_names(extra: str) -> set:
    specs = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"][extra]
    return {_normal(re.match(r"[A-Za-z0-9_.-]+", spec).group()) for spec in specs}


@pytest.mark.parametrize("extra", sorted(EXTRAS))
def test_the_module_table_names_the_requirements_of_each_extra(extra):
    wanted = _requirement_names(extra)
    providers = importlib.metadata.packages_distributions()
    installed = {_normal(d.metadata["Name"]) for d in importlib.metadata.distributions()}
    for module in EXTRAS[extra]:
        if module in providers:  # an installed module comes from a requirement of its extra
            assert {_normal(d) for d in providers[module]} & wanted, (extra, module)
    provided = {_normal(d) for module in EXTRAS[extra] for d in providers.get(module, [])}
    assert wanted & installed <= provided, (extra, wanted & installed - provided)


def test_all_installs_every_extra_but_the_distributed_one():
    (spec,) = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["all"]
    listed = set(re.search(r"\[(.*)\]", spec).group(1).split(","))
    assert listed == set(EXTRAS) - {"distributed"}  # Ray pins its own gymnasium: a venv of its own


def test_require_names_the_extra_and_the_command(monkeypatch):
    monkeypatch.setitem(sys.modules, "pygame", None)  # as if it were not installed
    with pytest.raises(MissingExtra, match=r"""^rendering needs the 'render' extra \(pygame is missing\): """):
        require("render", "rendering")
    with pytest.raises(ModuleNotFoundError, match=r'pip install -e "\.\[render\]"$'):
        require("render", "agents.x", checkout=True)
    with pytest.raises(ValueError, match="extra: expected one of"):
        require("rendering", "x")
    with pytest.raises(ValueError, match="modules"):
        require("render", "x", modules=("yaml",))
    assert extra_of("yaml") == "train" and extra_of("yaml", prefer=("distributed",)) == "distributed"
    assert extra_of("matplotlib.pyplot") == "plot" and extra_of("numpy") is None


def test_rendering_without_pygame_says_which_extra(monkeypatch):
    import gymnasium as gym

    import collision_env  # noqa: F401

    monkeypatch.setitem(sys.modules, "pygame", None)
    env = gym.make("CollisionEnv/OneBallTarget-v0", render_mode="rgb_array")
    with pytest.raises(MissingExtra, match=r"""'render' extra .*pip install "collision_env\[render\]"$"""):
        env.reset(seed=0)


def _run_without(module: str, command: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``python -m command...`` in a fresh process in which ``module`` cannot be imported."""
    code = (
        "import runpy, sys\n"
        f"sys.modules[{module!r}] = None\n"
        f"sys.argv = {command!r}\n"
        f"runpy.run_module({command[0]!r}, run_name='__main__', alter_sys=True)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SDL_VIDEODRIVER": "dummy"}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


@pytest.mark.parametrize(
    "command, module, extra",
    [
        (["agents.main"], "yaml", "train"),
        (["agents.train_ppo"], "yaml", "train"),
        (["agents.train_ppo"], "torch", "train"),
        (["agents.evaluate", "{run}"], "yaml", "train"),
        (["agents.evaluate", "{run}", "--gif"], "pygame", "render"),
        (["agents.evaluate", "{run}", "--video", "x.mp4"], "imageio_ffmpeg", "video"),
        (["agents.train_rllib"], "ray", "distributed"),
        (["agents.rllib_report"], "ray", "distributed"),
        (["agents.study"], "matplotlib", "plot"),
        (["agents.study"], "stable_baselines3", "train"),
        (["collision_env.play"], "pygame", "render"),
    ],
)
def test_an_entry_point_without_its_extra_says_which_in_one_line(tmp_path, command, module, extra):
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.yml").write_text("env_id: CollisionEnv/OneBallTarget-v0\nhyperparams: {}\n")
    proc = _run_without(module, [c.format(run=run) for c in command], tmp_path)
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    # the agents run from a checkout (an editable install there), the package from an index or a wheel
    target = f'-e ".[{extra}]"' if command[0].startswith("agents.") else f'"collision_env[{extra}]"'
    assert f"needs the '{extra}' extra ({module} is missing): pip install {target}" in lines[0]
    assert lines[0].startswith(("agents.", "collision_env.", "recording", "writing", "evaluating"))
