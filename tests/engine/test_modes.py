"""Each cheap mode's known weakness, pinned, next to exact mode getting the same case right."""

import numpy as np
import pytest

from collision_env.engine import Scene, Simulator


def test_posteriori_corner_error():
    # A ball that crosses both walls of a corner within one step: PhET's |ds|^2 / (v.ds) returns
    # a projection-weighted mix of the two crossing times, not the first one.
    r = 0.1
    scene = Scene()
    start, v, dt = [[1.75, 0.85]], [[3.0, 1.0]], 0.1
    exact = Simulator(scene, start, v, [1.0], radii=[r]).step(dt)
    post = Simulator(scene, start, v, [1.0], radii=[r], mode="posteriori").step(dt)
    # exact: top wall at (0.9 - 0.85)/1 = 0.05 s, right wall at (1.9 - 1.75)/3 = 0.05 s ... offset them:
    assert [h.wall for h in exact] == ["right", "top"]
    t_right = (1.9 - 1.75) / 3.0
    assert exact[0].time == pytest.approx(t_right, rel=1e-14)
    # posteriori: overshoot at t = 0.1 is dx = 0.15, dy = 0.05; |ds|^2/(v.ds) = 0.025/0.5 = 0.05 s ago
    assert {h.wall for h in post} == {"right", "top"}
    assert all(h.time == pytest.approx(0.1 - 0.025 / 0.5, rel=1e-12) for h in post)


def test_posteriori_corner_error_when_crossing_times_differ():
    # Overshoot (dx, dy) = (0.1, 0.01) past the corner at the end of a 0.2 s step with v = (1, 1):
    # the true crossings are at 0.1 s (right) and 0.19 s (top); posteriori reports both at the mix
    # 0.2 - (dx^2 + dy^2) / (dx + dy).
    r = 0.1
    start, v, dt = [[1.8, 0.71]], [[1.0, 1.0]], 0.2
    exact = Simulator(Scene(), start, v, [1.0], radii=[r]).step(dt)
    post = Simulator(Scene(), start, v, [1.0], radii=[r], mode="posteriori").step(dt)
    assert [(h.wall, round(h.time, 12)) for h in exact] == [("right", 0.1), ("top", 0.19)]
    mixed = 0.2 - (0.1**2 + 0.01**2) / (0.1 + 0.01)
    assert sorted(h.wall for h in post) == ["right", "top"]
    assert all(h.time == pytest.approx(mixed, rel=1e-9) for h in post)
    assert abs(mixed - 0.1) > 5e-3 and abs(mixed - 0.19) > 5e-2  # neither true crossing time


def test_naive_reports_wrong_impact_point_and_time():
    # A ball moving diagonally into the right wall: naive reports where it was put back at the end
    # of the step, not where it touched.
    r = 0.1
    start, v, dt = [[1.7, 0.0]], [[1.0, 1.0]], 0.25
    exact = Simulator(Scene(), start, v, [1.0], radii=[r]).step(dt)
    naive = Simulator(Scene(), start, v, [1.0], radii=[r], mode="naive").step(dt)
    assert exact[0].point == pytest.approx((2.0, 0.2), rel=1e-14) and exact[0].time == pytest.approx(0.2)
    assert naive[0].wall == "right" and naive[0].time == pytest.approx(0.25)
    assert naive[0].point[1] == pytest.approx(0.25)  # 0.05 m off along the wall
    # posteriori reconstructs the single-wall contact exactly
    post = Simulator(Scene(), start, v, [1.0], radii=[r], mode="posteriori").step(dt)
    assert post[0].point == pytest.approx((2.0, 0.2), rel=1e-12) and post[0].time == pytest.approx(0.2)


@pytest.mark.parametrize("mode, substeps", [("naive", 1), ("posteriori", 1), ("posteriori", 8)])
def test_tunnelling_at_large_dt(mode, substeps):
    # Two small fast balls head-on: at dt = 0.5 s the cheap modes never see them overlap.
    args = ([[-1.0, 0.0], [1.0, 0.0]], [[3.0, 0.0], [-3.0, 0.0]], [1.0, 1.0])
    kw = dict(radii=[0.02, 0.02])
    cheap = Simulator(Scene(), *args, mode=mode, substeps=substeps, **kw)
    exact = Simulator(Scene(), *args, **kw)
    exact_pairs = [h for h in exact.step(0.5) if h.other is not None]
    cheap_pairs = [h for h in cheap.step(0.5) if h.other is not None]
    assert len(exact_pairs) == 1 and exact_pairs[0].time == pytest.approx((2.0 - 0.04) / 6.0, rel=1e-14)
    assert cheap_pairs == []  # tunnelled: the balls passed through each other
    assert cheap.positions[0, 0] > cheap.positions[1, 0]


def test_substeps_trade_cost_for_accuracy():
    # Three isolated collisions in 0.4 s: posteriori reconstructs each exactly at any substep
    # count; naive's error shrinks roughly in proportion to the sub-step.
    rng = np.random.default_rng(1)
    pos = np.array([[-1.5, 0.5], [-0.5, -0.4], [0.4, 0.3], [1.4, -0.5]])
    vel = rng.normal(size=(4, 2)) * 3
    masses = [1, 2, 3, 1]
    ref = Simulator(Scene(), pos, vel, masses)
    assert sum(len(ref.step(0.1)) for _ in range(4)) == 3

    def error(mode, k):
        sim = Simulator(Scene(), pos, vel, masses, mode=mode, substeps=k)
        for _ in range(4):
            sim.step(0.1)
        return np.abs(sim.positions - ref.positions).max()

    assert error("posteriori", 1) < 1e-12
    naive = [error("naive", k) for k in (1, 4, 16, 64)]
    assert naive[0] > 0.1 and naive[-1] < 0.01
    assert all(a > b for a, b in zip(naive[1:], naive[2:], strict=False))


@pytest.mark.parametrize("mode", ["naive", "posteriori"])
def test_cheap_modes_keep_balls_inside_the_border(mode):
    sim = Simulator(Scene(), [[1.5, 0.5]], [[400.0, 300.0]], [1.0], mode=mode)
    for _ in range(20):
        sim.step(0.1)
        x, y = sim.positions[0]
        r = sim.radii[0]
        assert -2 + r <= x <= 2 - r and -1 + r <= y <= 1 - r


@pytest.mark.parametrize("mode, substeps", [("naive", 1), ("posteriori", 1), ("posteriori", 3), ("exact", 1)])
def test_batched_impacts_come_by_scene_then_in_the_order_they_happened(mode, substeps):
    from collision_env.engine import BatchSimulator

    rng = np.random.default_rng(3)
    b, n = 3, 6
    pos = np.stack([np.column_stack([np.linspace(-1.6, 1.6, n), rng.uniform(-0.6, 0.6, n)]) for _ in range(b)])
    vel = rng.normal(size=(b, n, 2)) * 3.0
    sim = BatchSimulator(
        Scene(elasticity=0.9), pos, vel, np.ones((b, n)), radii=np.full((b, n), 0.12), mode=mode, substeps=substeps
    )
    seen = 0
    for dt in [0.2] * 10 + [-0.2] * 5:
        rows = sim.step(dt)
        seen += len(rows)
        assert np.all(np.diff(rows["scene"]) >= 0)
        for s in range(b):
            t = rows["time"][rows["scene"] == s]
            assert np.all(np.diff(np.sign(dt) * t) >= 0)
    assert seen > 30


@pytest.mark.parametrize("mode, substeps", [("naive", 200), ("posteriori", 200), ("exact", 1)])
def test_a_step_too_big_for_the_impact_buffer_resumes_and_matches_single_scenes(mode, substeps):
    # 60 dense scenes over 4 s record more impacts than the buffer holds: the kernel stalls, the
    # buffer is emptied, the step resumes, and the chunks are merged in order.
    from collision_env.engine import BatchSimulator

    rng = np.random.default_rng(11)
    b, n, r = 60, 8, 0.12
    grid = np.array([[x, y] for x in np.linspace(-1.6, 1.6, 4) for y in (-0.5, 0.5)])
    pos = np.stack([grid + rng.uniform(-0.05, 0.05, grid.shape) for _ in range(b)])
    vel = rng.normal(size=(b, n, 2)) * 2.0
    batch = BatchSimulator(Scene(), pos, vel, np.ones((b, n)), radii=np.full((b, n), r), mode=mode, substeps=substeps)
    buffer = len(batch._stepper._imp)  # (it grows after the step, to hold the next one)
    rows = batch.step(4.0)
    assert len(rows) > buffer  # the step really stalled at least once
    assert np.all(np.diff(rows["scene"]) >= 0)
    for s in range(b):
        single = Simulator(Scene(), pos[s], vel[s], np.ones(n), radii=np.full(n, r), mode=mode, substeps=substeps)
        hits = single.step(4.0)
        mine = rows[rows["scene"] == s]
        assert [(h.ball, h.other if h.other is not None else -1) for h in hits] == list(
            zip(mine["ball"].tolist(), mine["other"].tolist(), strict=True)
        )
        if mode != "exact":  # the fixed-step modes are bit for bit the same
            assert [h.time for h in hits] == mine["time"].tolist()
            np.testing.assert_array_equal(single.positions, batch.positions[s])
        else:  # exact mode resumes from fresh predictions: round-off, amplified by a few collisions
            np.testing.assert_allclose([h.time for h in hits], mine["time"], rtol=0, atol=1e-6)
