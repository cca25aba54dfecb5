"""The public surface: one name per concept, each name exported once, one way to compile ahead, and
compile notices a user can read."""

import importlib

import pytest

from collision_env import engine, envs
from collision_env.engine import _jit
from collision_env.engine import modes as mode_registry

#: The public modules, as the API reference lists them.
PUBLIC = (
    "collision_env",
    "collision_env.engine",
    "collision_env.envs",
    "collision_env.observables",
    "collision_env.io",
)


def test_modes_is_one_object_whose_keys_are_the_names():
    assert engine.MODES is mode_registry.MODES
    assert list(engine.MODES) == ["naive", "posteriori", "exact"]
    assert "exact" in engine.MODES and engine.MODES["exact"].summary
    with pytest.raises(TypeError):
        engine.MODES["fast"] = engine.MODES["exact"]  # read-only


def test_walls_are_names_in_records_and_constants_alike():
    """``Impact.wall`` is a name; the integer codes are not public (the envs' kernels read them from
    ``collision_env.engine.scene``), and ``WALL_NAMES`` decodes a raw record's code."""
    assert not any(name.startswith("WALL_") and name != "WALL_NAMES" for name in engine.__all__)
    sim = engine.Simulator(engine.Scene(), [[0.0, 0.0]], [[1.0, 0.0]], [1.0])
    (impact,) = sim.step(2.0)
    assert impact.wall == "right" and impact.wall in engine.WALL_NAMES
    assert engine.WALL_NAMES[sim.step(4.0).array["wall"][0]] == "left"


def test_every_public_name_is_exported_by_one_module_only():
    owners: dict[int, list[str]] = {}
    for module_name in PUBLIC:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            value = getattr(module, name)
            if isinstance(value, type) or callable(value):
                owners.setdefault(id(value), []).append(f"{module_name}.{name}")
    assert [names for names in owners.values() if len(names) > 1] == []


def test_one_documented_way_to_compile_ahead():
    from collision_env.precompile import plan, precompile

    assert not hasattr(engine, "warm_up") and "compile_for" not in engine.__all__
    assert callable(precompile)
    labels = plan()
    assert (
        labels[:5]
        == [
            "naive mode",
            "posteriori mode",
            "exact mode for elastic scenes",
            "exact mode for inelastic scenes",
            "exact mode for stick scenes",
        ]
        or not _jit.HAVE_NUMBA
    )
    assert all("kernel" not in label and "_" not in label for label in labels)  # words a user knows


def test_the_dead_helpers_are_gone():
    from collision_env.bench import scenes
    from collision_env.envs import target_env

    assert not hasattr(target_env, "preset_names") and not hasattr(scenes, "scene_names")
    assert "UnknownKeywordError" in engine.__all__ and "UnknownKeywordError" not in envs.__all__


def test_the_compile_notice_counts_the_plan_and_estimates_the_time_left(monkeypatch):
    notice = _jit._CompileNotice
    monkeypatch.setattr(_jit, "EXPECTED_SECONDS", {"a mode": 10.0, "b mode": 20.0, "c mode": 30.0})
    monkeypatch.setattr(notice, "seconds", {})
    assert notice.describe("b mode") == "b mode (about 20 s)"
    assert notice.describe("z mode") == "z mode"  # no estimate for it
    with _jit.compile_plan(["a mode", "b mode", "c mode"]):
        assert notice.describe("a mode") == "a mode (1 of 3 kernels, ~60 s left)"
        monkeypatch.setattr(notice, "seconds", {"a mode": 20.0})  # this machine took twice as long
        assert notice.describe("b mode") == "b mode (2 of 3 kernels, ~100 s left)"
    assert notice.plan == ()


def test_the_shipped_estimates_cover_the_precompile_plan():
    if not _jit.HAVE_NUMBA:
        pytest.skip("without numba nothing is compiled")
    from collision_env.precompile import plan

    assert set(plan()) <= set(_jit.EXPECTED_SECONDS), "rerun python -m collision_env.bench.compile --estimates"
    assert all(0 < seconds < 120 for seconds in _jit.EXPECTED_SECONDS.values())


def test_kernels_without_a_label_are_announced_once_as_their_phase(monkeypatch, capsys):
    notice = _jit._CompileNotice
    monkeypatch.setattr(notice, "shown", True)
    monkeypatch.setattr(notice, "seconds", {})
    monkeypatch.setattr(notice, "cpu_seconds", {})
    monkeypatch.setattr(notice, "labels", [])
    monkeypatch.setattr(_jit, "EXPECTED_SECONDS", {"the helpers": 4.0, "b mode": 6.0})
    with _jit.compile_plan(["the helpers", "b mode"]):
        with _jit.compile_phase("the helpers"):
            notice.miss(None)
            notice.miss(None)  # (the same phase: no second line)
            notice.miss("b mode")  # a labelled kernel inside the phase closes the phase's line first
            notice.done("b mode")
    lines = capsys.readouterr().err.splitlines()
    assert [line.split(" ...")[0] for line in lines] == [
        "collision_env: compiling the helpers (1 of 2 kernels, ~10 s left)",
        "collision_env: compiling b mode (2 of 2 kernels, ~0 s left)",  # (the helpers took no time here)
    ]
    assert set(_jit.compile_seconds()) == {"the helpers", "b mode"} and notice.phase is None


def test_a_misspelt_keyword_names_at_most_three_fields_in_one_short_line():
    import gymnasium as gym

    for typo in ("n_target", "zzz"):
        with pytest.raises(ValueError) as err:
            gym.make("CollisionEnv/OneBallTarget-v0", **{typo: 2})
        message = str(err.value)
        assert "\n" not in message and len(message) < 300
        assert message.count("'") <= 2 * 4 + 2  # the typo and at most three suggestions (and gym's kwargs)
