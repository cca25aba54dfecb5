"""The named layouts: the kernel writes each observation entry where its layout says, and every env's
docstring table agrees with the layout the kernel uses."""

import re

import gymnasium as gym
import numpy as np
import pytest

import collision_env
from collision_env.engine import WALL_NAMES
from collision_env.envs import REGISTERED, CollisionTargetEnv
from collision_env.envs.task.layout import (
    BALL_OBS,
    GLOBAL_OBS,
    PREDICTED_OBS,
    SCENE_INTS,
    TARGET_OBS,
    observation_table,
    rows_of,
)

SINGLE_CLASSES = sorted({reg.single for reg in REGISTERED.values()}, key=lambda cls: cls.__name__)


def test_generic_docstring_shows_the_generated_observation_table():
    doc = "\n".join(line.strip() for line in CollisionTargetEnv.__doc__.splitlines())
    assert observation_table() in doc


def test_wall_one_hot_follows_the_engine_wall_codes():
    from collision_env.engine import scene

    for name in WALL_NAMES:
        code = getattr(scene, f"WALL_{name.upper()}")
        assert getattr(TARGET_OBS, f"wall_{name}") == TARGET_OBS.wall_left + code


# ----------------------------------------------------------------------------------- docstrings
def _index_sets(cell: str, n_balls: int, n_slots: int, dim: int) -> list:
    """The index sets a docstring table's index cell names, one per ball i / target slot s."""
    cell = cell.replace(" ", "")
    *bases, tail = cell.split("+")
    if tail.startswith("D-"):
        return [{dim - int(tail[2:])}]
    if ".." in tail or re.fullmatch(r"\d+-\d+", tail):
        lo, hi = (int(v) for v in re.split(r"\.\.|-", tail))
        offsets = set(range(lo, hi + 1))
    else:
        offsets = {int(v) for v in tail.split(",")}
    instances = [0]
    for term in bases:
        factor, var = re.fullmatch(r"(\d*)([a-zA-Z]?)", term).groups()
        factor = int(factor or 1)
        if var == "i":
            instances = [b + factor * i for b in instances for i in range(n_balls)]
        elif var == "s":
            instances = [b + factor * s for b in instances for s in range(n_slots)]
        elif var == "N":
            instances = [b + factor * n_balls for b in instances]
        elif var == "S":
            instances = [b + factor * n_slots for b in instances]
        else:
            instances = [b + factor for b in instances]
    return [{b + o for o in offsets} for b in instances]


def _field_groups(n_balls: int, n_slots: int, predicted: bool = False) -> list:
    """For every observation index: (section, instance, row of its layout)."""
    out = []
    sections = [("ball", n_balls, BALL_OBS), ("target", n_slots, TARGET_OBS), ("global", 1, GLOBAL_OBS)]
    for section, count, columns in sections + ([("predicted", n_balls, PREDICTED_OBS)] if predicted else []):
        rows = rows_of(columns)
        for instance in range(count):
            for col in range(len(columns)):
                out.append((section, instance, next(r for r, (a, b, _) in enumerate(rows) if a <= col <= b)))
    return out


def _table_cells(doc: str) -> list:
    section = doc.split("## Observation Space", 1)[1].split("##", 1)[0]
    cells = [line.strip().split("|")[1].strip() for line in section.splitlines() if line.strip().startswith("|")]
    return [c for c in cells[2:] if c]  # skip the header and the rule; empty cells continue a row


def _check_table(doc: str, cfg) -> None:
    n, slots, dim = cfg.n_observed, cfg.target_slots, cfg.obs_dim
    groups = _field_groups(n, slots, cfg.observe == "predicted")
    seen = []
    for cell in _table_cells(doc):
        indices_of_cell = _index_sets(cell, n, slots, dim)
        if cfg.observe == "plain" and any(i >= dim for indices in indices_of_cell for i in indices):
            continue  # a row of the predicted block, which this config does not observe
        for indices in indices_of_cell:
            seen += indices
            fields = {groups[i] for i in indices}
            # one row documents part of one layout row, or whole layout rows, of one ball / slot / globals
            assert len({(s, k) for s, k, _ in fields}) == 1, (cell, indices)
            if len(fields) > 1:
                whole = {i for i, g in enumerate(groups) if g in fields}
                assert whole == indices, (cell, indices)
    assert sorted(seen) == list(range(dim)), "the rows must name every entry exactly once"


@pytest.mark.parametrize("cls", SINGLE_CLASSES, ids=lambda cls: cls.__name__)
def test_docstring_observation_table_agrees_with_the_layout(cls):
    env_id = next(i for i, r in REGISTERED.items() if r.single is cls)
    _check_table(cls.__doc__, gym.make(env_id).unwrapped.config)


@pytest.mark.parametrize("preset", sorted(collision_env.envs.PRESETS))
@pytest.mark.parametrize("observe", ["plain", "predicted"])
def test_generic_table_agrees_with_the_layout_of_every_preset(preset, observe):
    from collision_env.envs import make_config

    _check_table(CollisionTargetEnv.__doc__, make_config(preset, observe=observe))


@pytest.mark.parametrize(
    "edits",
    [
        ("| 9-12  |", "| 9-11  |"),  # an entry left out
        ("| 4     | ball mass", "| 4, 5  | ball mass"),  # an entry named twice
        ("| 8     |", "| 8, 9  |", "| 9-12  |", "| 10-12 |"),  # a row across layout rows, not whole ones
    ],
)
def test_a_table_that_disagrees_with_the_layout_is_caught(edits):
    from collision_env.envs import OneBallTargetEnv, make_config

    doc = OneBallTargetEnv.__doc__
    for old, new in zip(edits[::2], edits[1::2], strict=True):
        assert old in doc
        doc = doc.replace(old, new)
    with pytest.raises(AssertionError):
        _check_table(doc, make_config("one_ball"))


# ----------------------------------------------------------------------------------- the kernel
@pytest.mark.parametrize("env_id", collision_env.ENV_IDS)
def test_observation_entries_sit_where_the_layout_says(env_id):
    env = gym.make(env_id).unwrapped
    obs, _ = env.reset(seed=4)
    for _ in range(7):
        obs, *_ = env.step(env.action_space.sample())
    core, cfg = env.core, env.config
    xmin, ymin, xmax, ymax = cfg.bounds
    xc, yc, xh, yh = (xmin + xmax) / 2, (ymin + ymax) / 2, (xmax - xmin) / 2, (ymax - ymin) / 2
    nb, nt = len(BALL_OBS), len(TARGET_OBS)
    for j, i in enumerate(np.flatnonzero(cfg.shown_mask)):
        block = obs[nb * j : nb * (j + 1)]
        assert block[BALL_OBS.x] == pytest.approx(np.clip((core.pos[0, i, 0] - xc) / xh, -1, 1), abs=1e-6)
        assert block[BALL_OBS.y] == pytest.approx(np.clip((core.pos[0, i, 1] - yc) / yh, -1, 1), abs=1e-6)
        assert block[BALL_OBS.vy] == pytest.approx(np.clip(core.vel[0, i, 1] / (2 * cfg.max_speed), -1, 1), abs=1e-6)
        assert block[BALL_OBS.mass] == pytest.approx(min(core.masses[0, i] / 3.0, 1.0), abs=1e-6)  # (Pegs: 50 kg)
    for s in range(cfg.target_slots):
        block = obs[nb * cfg.n_observed + nt * s : nb * cfg.n_observed + nt * (s + 1)]
        k = min(int(core.cur[0]), cfg.n_targets - 1) if cfg.sequential else s
        wall = WALL_NAMES[int(core.t_wall[0, k])]
        assert block[getattr(TARGET_OBS, f"wall_{wall}")] == 1.0 and block[TARGET_OBS.wall_left :][:4].sum() == 1.0
    tail = obs[-len(GLOBAL_OBS) :]
    assert tail[GLOBAL_OBS.steps_left] == pytest.approx(1 - int(core.steps[0]) / cfg.n_steps, abs=1e-6)
    hit = int(core.scene_i[0, SCENE_INTS.targets_hit])
    assert tail[GLOBAL_OBS.targets_left] == pytest.approx(1 - hit / cfg.n_targets, abs=1e-6)


def test_architecture_notes_name_every_layout():
    from pathlib import Path

    from collision_env.envs.task import layout as _layout

    text = (Path(__file__).parents[2] / "ARCHITECTURE.md").read_text()
    names = [n for n, v in vars(_layout).items() if isinstance(v, tuple) and hasattr(type(v), "layout_rows")]
    assert len(names) >= 10 and all(f"`{n}`" in text for n in names), names
