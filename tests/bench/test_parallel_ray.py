"""A sweep of the literature benchmark on Ray (a private local instance of two CPUs) gives the serial
run's numbers bit for bit (skipped where ray is not installed: its venv is `make .venv-ray/.installed`,
and `make test-compat` runs this file there)."""

import pytest

pytest.importorskip("ray")

from collision_env.bench import literature as L


def test_a_ray_sweep_equals_the_serial_one():
    tasks = [
        L.Point(72, "1:1", 0.65, "ecmc", "fluid", 72 * 100, 200_000, 3),
        L.Point(72, "1:1", 0.65, "md", "fluid", 72 * 10, 20_000, 3),
        L.Point(72, "9:8sqrt3/2", 0.68, "ecmc", "fluid", 72 * 100, 200_000, 3),
    ]
    quiet = {"log": lambda *a: None}
    serial = L.run(tasks=tasks, **quiet)
    on_ray = L.run(tasks=tasks, ray=True, jobs=2, **quiet)
    assert serial["runner"] == "serial" and on_ray["runner"] == "ray"
    assert [L.physics_of(r) for r in on_ray["rows"]] == [L.physics_of(r) for r in serial["rows"]]
    assert [r["method"] for r in on_ray["rows"]] == ["ecmc", "md", "ecmc"]
