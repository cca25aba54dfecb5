"""Smoke tests of the study machinery on tiny cases (seconds, not the study itself)."""

import math

import numpy as np
import pytest

from collision_env.bench import report
from collision_env.bench.engines import EngineRunner
from collision_env.bench.extremes import Cell, _check_corner, _check_graze, _corner, _two_ball_graze, run_cell
from collision_env.bench.peers import BilliardsRunner, PymunkRunner, collect
from collision_env.bench.scenes import SCENES, pi_billiard, pi_collisions
from collision_env.bench.sweep import schedule, sweep_case


def test_schedule_lands_on_the_horizon():
    assert schedule(1.0, 0.3) == pytest.approx([0.3, 0.3, 0.3, 0.1])
    assert sum(schedule(2.0, 0.1)) == pytest.approx(2.0)
    assert len(schedule(2.0, 0.1)) == 20
    assert schedule(0.05, 0.1) == [0.05]


@pytest.mark.parametrize("name", list(SCENES))
def test_every_scene_builds_valid_cases(name):
    from collision_env.engine import Simulator

    spec = SCENES[name]
    for n in spec.counts:
        case = spec.case(n)
        assert case.positions.shape == (n, 2) and case.radii.shape == (n,)
        Simulator(case.scene, case.positions, case.velocities, case.masses, case.radii)  # validates


def test_sweep_case_exact_is_its_own_reference_and_naive_is_not():
    rows = sweep_case(
        SCENES["explore_2d"],
        2,
        [EngineRunner("naive"), EngineRunner("exact")],
        (0.01,),
        min_time=0.0,
        max_repeats=1,
        log=lambda *_: None,
    )
    by = {r["family"]: r for r in rows}
    exact, naive = by["exact"], by["naive"]
    assert exact["status"] == naive["status"] == "ok"
    assert exact["pos_err"] < 1e-9 and exact["missed"] == exact["spurious"] == 0
    assert exact["matched"] == exact["ref_impacts"] > 0
    assert exact["t_err_max"] < 1e-9
    assert naive["pos_err"] > 1e-4  # naive reports impacts at the end of the step
    assert 0 < naive["t_err_max"] < 0.05  # up to a step late, plus the drift of the wrong bounces
    assert exact["wall_per_sim_s"] > 0 and exact["us_per_step"] > 0
    assert set(report.FIELDS) <= set(exact) | {"note"}


def test_runners_agree_on_the_intro_collision():
    case = SCENES["intro"].case(2)
    runners = [EngineRunner("exact")]
    for cls in (PymunkRunner, BilliardsRunner):
        try:
            runners.append(cls())
        except ImportError:
            pass
    for runner in runners:
        assert runner.unsupported(case) is None
        runner.start(case)
        imp = collect([runner.step(0.01) for _ in range(200)])
        assert len(imp) == 1, runner.family
        assert imp["time"][0] == pytest.approx(1.088256, abs=0.011), runner.family
        pos, vel = runner.state()
        np.testing.assert_allclose(vel[:, 0], [-1.25, 0.25], atol=0.02, err_msg=runner.family)


def test_billiards_runner_refuses_restitution():
    try:
        runner = BilliardsRunner()
    except ImportError:
        pytest.skip("billiards not installed")
    assert "elastic" in runner.unsupported(SCENES["inelastic_pileup"].case(4))


def test_pi_billiard_count_in_exact_mode():
    case = pi_billiard(2, 2)
    runner = EngineRunner("exact")
    runner.start(case)
    imp = collect([runner.step(1.0) for _ in range(8)])
    assert len(imp) == pi_collisions(2) == 314


def test_extremes_cells_pass_and_fail_as_they_should():
    corner = Cell("corner", "corner", lambda: _corner(0.5), 0.6, 0.6, 10.0, _check_corner(0.5))
    assert run_cell(corner, "exact", 1, budget=10.0)["status"] == "pass"
    graze = Cell("graze", "grazing", lambda: _two_ball_graze(1e-8), 0.013, 2.0, 10.0, _check_graze(True))
    assert run_cell(graze, "exact", 1, budget=10.0)["status"] == "pass"
    row = run_cell(graze, "naive", 1, budget=10.0)  # a 1e-8 graze overlaps for ~3e-5 s: naive never sees it
    assert row["status"] == "wrong" and "impacts" in row["detail"]


def test_summary_thresholds_on_synthetic_rows():
    def row(fam, s, err, missed=0, e=1.0):
        return {
            "status": "ok",
            "family": fam,
            "speed_dt_over_r": s,
            "pos_err": err,
            "missed": missed,
            "spurious": 0,
            "elasticity": e,
            "scene": "gas" if e == 1.0 else "pile",
            "n": 4,
        }

    rows = [
        row("posteriori k=1", 0.01, 1e-12),
        row("posteriori k=1", 0.1, 1e-4),
        row("posteriori k=1", 1.0, 0.5, 3),
        row("posteriori k=1", 0.05, 1e-2, e=0.5),
    ]
    elastic = report.ELASTIC[1]
    assert report.thresholds(rows, "posteriori k=1", 1e-6, where=elastic) == (0.1, 1, 3)
    assert report.thresholds(rows, "posteriori k=1", 1e-3, where=elastic) == (1.0, 2, 3)
    assert report.thresholds(rows, "posteriori k=1", 1.0, where=elastic)[0] == math.inf
    assert report.miss_threshold(rows, "posteriori k=1", where=elastic) == (1.0, 3)
    assert report.thresholds(rows, "posteriori k=1", 1e-3)[0] == 0.05  # the inelastic run counts without a filter
    # an error within exact's own spread on that scene (the floor) is a tie, not a violation
    assert report.thresholds(rows, "posteriori k=1", 1e-6, where=elastic, floor={("gas", 4): 1e-3})[0] == 1.0
    floor = report.floors(rows + [{**row("exact", 0.1, 3e-7), "scene": "gas"}])
    assert floor == {("gas", 4): 3e-7, ("pile", 4): report.ROUND_OFF}


def test_csv_round_trip(tmp_path):
    rows = [
        {
            "scene": "intro",
            "n": np.int64(2),
            "dt": np.float64(0.01),
            "cap_reached": np.bool_(False),
            "note": "",
            "pos_err": float("nan"),
        }
    ]
    path = tmp_path / "x.csv"
    report.write_csv(path, rows, ("scene", "n", "dt", "cap_reached", "note", "pos_err"))
    back = report.read_csv(path)[0]
    assert back["n"] == 2 and back["dt"] == 0.01 and back["cap_reached"] is False and back["scene"] == "intro"
    assert math.isnan(back["pos_err"])
