"""The peer adapters: one class each, one interface, and the engine benchmark built on them."""

import numpy as np
import pytest

from collision_env.bench import engine
from collision_env.bench.engines import EngineRunner, peer_runners
from collision_env.bench.peers import PEERS, Runner, collect, make_peer
from collision_env.bench.scenes import SCENES


def installed_peers():
    peers = {name: make_peer(name) for name in PEERS}
    return {name: peer for name, peer in peers.items() if not isinstance(peer, str)}


@pytest.mark.parametrize("name", list(PEERS))
def test_each_peer_is_one_runner_class(name):
    assert issubclass(PEERS[name], Runner)
    peer = make_peer(name)
    assert isinstance(peer, str) and "not installed" in peer or peer.engine == name


def test_impact_count_counts_recorded_and_unrecorded_steps():
    case = SCENES["explore_2d"].case(4)
    for runner in [EngineRunner("exact"), *installed_peers().values()]:
        runner.start(case)
        recorded = collect([runner.step(0.05) for _ in range(20)])
        assert runner.impact_count == len(recorded) > 0, runner.family
        for _ in range(40):
            runner.step(0.05, record=False)
        assert runner.impact_count > len(recorded), runner.family


def test_the_study_and_the_engine_benchmark_share_the_peer_set_up():
    runners, missing = peer_runners(full=True)
    assert set(missing) | {r.engine for r in runners} == set(PEERS)
    for runner in runners:
        assert type(runner) is PEERS[runner.engine]


def test_engine_benchmark_gas_agrees_with_billiards_over_a_short_horizon():
    if "billiards" not in installed_peers():
        pytest.skip("billiards not installed")
    gas = engine.bench_gas(quick=True, n=12, horizon=6.0)
    check = gas["check"]
    assert check["same_sequence"] and check["events"] > 0
    assert check["max_position_diff_m"] < 1e-9 and check["max_time_diff_s"] < 1e-9
    assert [r["ours_events"] > 0 and r["billiards_events"] > 0 for r in gas["rows"]] == [True, True]


def test_engine_benchmark_per_step_times_pymunk_on_the_same_balls():
    results = engine.bench_per_step(quick=True)
    for row in results["rows"]:
        modes = row["modes"]
        assert {"naive/1", "exact/1"} <= set(modes)
        assert ("pymunk" in modes) == ("pymunk" in installed_peers())
        assert all(np.isfinite(m["best"]) and 0 < m["best"] <= m["median"] for m in modes.values())
    assert "exact ÷ pymunk" in engine.render_markdown(
        {
            "meta": {
                "quick": True,
                "machine": "m",
                "cpus": 1,
                "date": "d",
                "duration_s": 1.0,
                "versions": engine.versions(["numba", "billiards", "pymunk"]),
            },
            "per_step": results,
        }
    )
