"""The scale benchmark's measurements and checks, on a small gas (the full sizes run from the script)."""

from __future__ import annotations

import pytest

from collision_env.bench import scale
from collision_env.precompile import precompile


@pytest.fixture(scope="module", autouse=True)
def compiled():
    precompile(envs=False)  # numba's compile must not count as the engine's memory


def test_a_gas_on_the_grid_stays_valid_and_collides_at_enskogs_rate():
    row = scale.bench_size(400, log=lambda *_: None, min_slice_s=0.0)
    assert row["overlaps"] == 0 and row["outside"] == 0
    assert row["energy_rel_change"] < 1e-9
    assert 0.7 < row["rate_ratio"] < 1.3  # a small box: walls and finite size shift it a little
    assert row["cell_crossings"] > 0  # the grid is in use
    assert row["pair_tests"] < 60  # neighbours only, not all 399 others
    assert row["peak_bytes_per_disk"] < 2048


def test_the_report_renders_every_size():
    results = {
        "machine": "m",
        "cpus": 2,
        "timestamp": "t",
        "versions": {"numpy": "1", "numba": "2"},
        "first_call_s": 1.0,
        "min_slice_s": 0.0,
        "seconds": 3.0,
        "sizes": scale.bench_sizes((100, 200), log=lambda *_: None, min_slice_s=0.0),
        "frames": scale.bench_frames(n=20, horizon=1.0, repeats=1),
        "public": scale.bench_public(n=200, frames=5, rounds=1),
    }
    text = scale.render_markdown(results)
    assert "| 100 |" in text and "| 200 |" in text
    assert all(row["frames"] >= scale.SLICES * 10 for row in results["sizes"])  # every size timed in every round
    assert "% of the one-step rate" in text and "into arrays it is given" in text
    assert "`Simulator.step`" in text and results["public"]["step_over_kernel"] > 0
    frames = results["frames"]
    ratios = ("frames_over_one_step", "frames_call_over_one_step", "frames_given_over_one_step")
    assert all(frames[key] > 0 for key in ratios)


def test_a_small_gas_is_timed_for_the_slices_least_time():
    """A 100-disk gas's share of the timed collisions takes about a millisecond: a slice runs on
    until its least time has passed."""
    row = scale.bench_size(100, log=lambda *_: None, min_slice_s=0.05)
    assert row["frames"] > 3 * scale.SLICES * 10
