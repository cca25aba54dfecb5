"""The engine benchmark's call section: what it measures and how it renders (no timing is asserted)."""

from collision_env.bench.engine import bench_calls, render_markdown
from collision_env.engine import BACKEND

META = {
    "quick": True,
    "machine": "m",
    "cpus": 1,
    "date": "d",
    "duration_s": 1.0,
    "versions": {"python": "3", "numpy": "2", "numba": None, "billiards": None, "pymunk": None, "backend": "numba"},
}


def test_the_calls_section_times_the_simulators_beside_the_empty_calls():
    calls = bench_calls(quick=True)
    names = ["Simulator.step", "BatchSimulator.step", "empty Python function"]
    if BACKEND == "numba":
        names.insert(2, "empty kernel, numba's dispatch")
    assert list(calls["rows"]) == names
    for row in calls["rows"].values():
        assert 0.0 < row["best"] <= row["median"] and row["repeats"] == 5


def test_the_calls_section_gives_each_call_as_a_multiple_of_the_empty_kernels():
    rows = {
        "Simulator.step": {"best": 300.0, "median": 310.0, "repeats": 3},
        "empty kernel, numba's dispatch": {"best": 400.0, "median": 420.0, "repeats": 3},
    }
    text = render_markdown({"meta": META, "calls": {"calls": 1000, "dt": 1 / 60, "rows": rows}})
    assert "| `Simulator.step` | 300 (310) | 0.75 |" in text
    assert "| `empty kernel, numba's dispatch` | 400 (420) | 1.00 |" in text
