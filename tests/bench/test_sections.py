"""Every benchmark section runs through the package's dispatcher as on its own."""

import importlib
import json

import pytest

from collision_env.bench import SECTIONS
from collision_env.bench.__main__ import main


def test_list_names_every_section(capsys):
    assert main(["--list"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in SECTIONS)


@pytest.mark.parametrize("name", list(SECTIONS))
def test_each_section_has_a_main_with_help(name, capsys):
    module = importlib.import_module(SECTIONS[name][0])
    with pytest.raises(SystemExit) as done:
        main([name, "--help"])
    assert done.value.code == 0
    assert "usage: python -m collision_env.bench" in capsys.readouterr().out
    assert callable(module.main)


def test_no_section_name_runs_the_study(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "study" in capsys.readouterr().out


def test_dispatch_passes_the_arguments_on(tmp_path, capsys):
    """``python -m collision_env.bench engine --render`` renders a saved run, as the section does."""
    results = {
        "meta": {
            "quick": True,
            "machine": "m",
            "cpus": 1,
            "date": "d",
            "duration_s": 1.0,
            "versions": {
                "python": "3",
                "numpy": "2",
                "numba": None,
                "billiards": None,
                "pymunk": None,
                "backend": "python",
            },
        },
        "batch": {
            "scenes": 2,
            "balls": 4,
            "steps": 1,
            "dt": 1 / 60,
            "rows": [
                {
                    "mode": "exact/1",
                    "batch_scene_steps_per_s": 10.0,
                    "loop_scene_steps_per_s": 5.0,
                    "speedup_best": 2.0,
                    "speedup_median": 2.0,
                    "max_position_diff_m": 0.0,
                }
            ],
        },
    }
    saved = tmp_path / "engine.json"
    saved.write_text(json.dumps(results))
    md = tmp_path / "engine.md"
    assert main(["engine", "--render", str(saved), "--markdown", str(md)]) == 0
    assert "| exact/1 | 10 | 5 | **2×** (2×) | 0 |" in md.read_text()
