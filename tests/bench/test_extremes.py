"""The extremes report's cells of refusals and round trips: exact mode passes them all,
and a cell fails when what it checks is missing."""

import pytest

from collision_env.bench.extremes import cells, run_cell

GROUPS = ("set_state", "round trip", "env state", "env config", "impacts", "compress", "observables")
ISSUE_39 = [c for c in cells() if c.group in GROUPS]


def test_the_grid_has_a_cell_for_each_way_in():
    names = {c.name for c in ISSUE_39}
    for name in (
        "set_state stick cluster 1 m apart",
        "set_state unknown key 'image'",
        "set_state 1.6e-15 m past the cell",
        "env set_state current target -5",
        "env set_state unknown key",
        "env get_state/set_state",
        "env max_dv=1e+300",
        "impacts[None]",
        "impacts[True]",
        "compress a box to Z = 1e9",
        "compress without a collision",
        "g(r) of a clump",
        "henderson_g(2)",
        "MSD lag 1.5",
    ):
        assert name in names


@pytest.mark.parametrize("cell", ISSUE_39, ids=lambda c: c.name)
def test_exact_mode_passes_the_cells_of_refusals_and_round_trips(cell):
    row = run_cell(cell, "exact", 1, budget=60.0)
    assert row["status"] == "pass", row["detail"]


def test_a_cell_fails_when_its_refusal_is_missing(monkeypatch):
    import collision_env.envs._core as core

    monkeypatch.setattr(core, "checked_task_state", lambda state, current, *_: {k: state[k] for k in current})
    (cell,) = [c for c in cells() if c.name == "env set_state current target -5"]
    row = run_cell(cell, "exact", 1, budget=60.0)
    assert row["status"] == "wrong" and "accepted an input that should be refused" in row["detail"]
