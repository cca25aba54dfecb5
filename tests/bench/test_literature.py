"""The benchmark against Li et al. (2022): its start states, one short point by each method, the
table and the plot, the page block, and its tasks run serially or in processes to the same numbers.
(The full benchmark runs from the script; Ray's run is tests/bench/test_parallel_ray.py.)"""

import json
import math

import numpy as np
import pytest

from collision_env.bench import literature as L
from collision_env.bench import physics
from collision_env.bench.parallel import run_tasks
from collision_env.bench.readme import write_page_block
from collision_env.observables import LI_2022_CELLS


def tiny(method: str, packing: float = 0.65, cell: str = "1:1", seed: int = 1) -> L.Point:
    """A point of N = 72 run for a few thousand events."""
    if method == "ecmc":
        return L.Point(72, cell, packing, method, "fluid", 72 * 200, 400_000, seed)
    return L.Point(72, cell, packing, method, "fluid", 72 * 20, 40_000, seed)


@pytest.mark.parametrize("cell", list(LI_2022_CELLS)[:3])
def test_the_start_is_a_compressed_fluid_of_unit_disks_in_the_cell(cell):
    point = tiny("md", 0.68, cell)
    scene, positions, velocities, radii = L.start_state(point)
    width, height = scene.period
    sides = LI_2022_CELLS[cell]
    assert height / width == pytest.approx(sides[1] / sides[0], rel=1e-12)
    assert radii == pytest.approx(np.full(72, 0.5), rel=1e-12)
    assert 72 * math.pi * 0.25 / (width * height) == pytest.approx(0.68, rel=1e-12)
    # no two disks overlap (minimum image), and the centre of mass is at rest
    d = positions[:, None] - positions[None]
    d -= np.round(d / (width, height)) * (width, height)
    gaps = np.hypot(d[..., 0], d[..., 1]) + 2 * np.eye(72)
    assert gaps.min() >= 1.0 - 1e-9
    assert np.abs(velocities.sum(axis=0)).max() < 1e-9
    # both methods start from it, and a seed makes it again bit for bit
    again = L.start_state(tiny("ecmc", 0.68, cell))
    assert all(np.array_equal(a, b) for a, b in zip((positions, velocities, radii), again[1:], strict=True))


def test_points_cover_the_fluid_and_the_loop_by_both_methods():
    tasks = L.points()
    fluid = {(p.n, p.cell) for p in tasks if p.region == "fluid"}
    assert fluid == {(n, cell) for n, cell, _ in L.FLUID} and len(fluid) == 6
    assert all(p.packing <= L.FLUID_MAX for p in tasks if p.region == "fluid")
    loop = sorted({p.packing for p in tasks if p.region == "loop"})
    assert loop[0] == 0.686 and loop[-1] == 0.710 and {p.n for p in tasks if p.region == "loop"} == {224}
    assert sum(p.method == "ecmc" for p in tasks) == sum(p.method == "md" for p in tasks) == len(tasks) // 2
    quick = L.points(quick=True)
    assert len(quick) < len(tasks) and max(p.measurement for p in quick) < max(p.measurement for p in tasks)


@pytest.fixture(scope="module")
def short_rows():
    """One short point by each method, as a sweep runs them: serially, then in two processes."""
    tasks = [tiny("ecmc"), tiny("md")]
    serial = run_tasks(L.run_point, tasks)
    pooled = run_tasks(L.run_point, tasks, jobs=2)
    return serial, pooled


def test_processes_give_the_serial_numbers_bit_for_bit(short_rows):
    serial, pooled = short_rows
    assert [L.physics_of(r) for r in serial] == [L.physics_of(r) for r in pooled]
    assert set(serial[0]) - set(L.physics_of(serial[0])) == set(L.TIMINGS)


def test_a_short_point_by_each_method_is_near_li_et_al(short_rows):
    serial, _ = short_rows
    for row in serial:
        # 72 disks at phi = 0.65 in the square: Z = 8.3386 (Li et al.); a short run, a loose bound
        assert row["z_ref"] == pytest.approx(6.901074 * math.pi / (4 * 0.65))
        assert abs(row["z"] / row["z_ref"] - 1.0) < 0.01
        assert len(row["segments"]) == L.SEGMENTS and row["events"] >= row["measurement"] - L.SEGMENTS
        assert row["z"] == pytest.approx(np.mean([s[0] for s in row["segments"]]), rel=1e-12)
        assert row["events_per_s"] > 0 and row["cpu_s"] > 0


def test_the_summary_counts_deviations_in_combined_errors():
    segments = [(10.0, 0.02, True), (10.02, 0.02, True), (10.04, 0.02, True), (10.06, 0.02, True)]
    s = L._summary(segments, 10.0, 0.01)
    assert s["z"] == pytest.approx(10.03) and s["z_err"] == pytest.approx(0.01)
    assert s["deviation_sigma"] == pytest.approx(0.03 / math.hypot(0.01, 0.01))
    # halves 10.01 and 10.05, each +- 0.02 / sqrt(2)
    assert s["drift_sigma"] == pytest.approx(0.04 / 0.02)
    assert L.within({**s, "reliable": True}) == (abs(s["deviation_sigma"]) <= 3)
    blind = L._summary([(10.0, math.inf, False)] * 4, 10.0, 0.01)
    assert not L.within(blind) and math.isnan(blind["drift_sigma"])


def results_of(rows):
    return {
        "machine": "m",
        "cpus": 2,
        "versions": {"numpy": "x", "numba": "y"},
        "timestamp": "t",
        "seconds": 60.0,
        "driver_cpu_s": 1.0,
        "quick": True,
        "runner": "serial",
        "jobs": 1,
        "segments": L.SEGMENTS,
        "fluid_runs": vars(L.FLUID_RUNS),
        "loop_runs": vars(L.LOOP_RUNS),
        "rows": rows,
    }


def test_the_table_the_page_block_and_the_plot(short_rows, tmp_path):
    serial, _ = short_rows
    loop = [{**r, "region": "loop", "n": 224, "packing": 0.69} for r in serial]
    results = results_of([*serial, *loop])
    text = L.render_markdown(results)
    assert "| 72 | 1:1 | 0.650 | 8.33860 ± 0.00009 |" in text
    assert "fluid points within 3 σ" in text and "Mayer–Wood loop" in text and "| 0.690 |" in text
    assert "| event chains | 72 |" in text and "| exact-mode MD | 224 |" in text
    page = tmp_path / "physics.md"
    write_page_block(page, "bench:literature", text, L.PAGE_TITLE)  # a new page
    write_page_block(page, "bench:physics", "fluid", L.PAGE_TITLE)  # a block the page lacks: added
    write_page_block(page, "bench:literature", "again", L.PAGE_TITLE)  # a block it has: replaced
    body = page.read_text()
    assert body.startswith(L.PAGE_TITLE) and "again" in body and text not in body and "fluid" in body
    assert L.plot(results, tmp_path).endswith("physics_li2022.png") and (tmp_path / "physics_li2022.png").stat().st_size
    # the script renders a saved run without running it
    saved = tmp_path / "run.json"
    saved.write_text(json.dumps(results))
    argv = ["--section", "literature", "--render", str(saved), "--markdown", str(page), "--plot", str(tmp_path)]
    assert physics.main(argv) == 0
    assert "| 72 | 1:1 | 0.650 |" in page.read_text()
