"""Robustness of exact mode against adversarial input, one class of input per section.

1. one physical collision is one reported impact (the regulariser's correction is not an impact);
2. a cascade squeezed by any mass ratio against a wall ends, and time advances;
3. tolerances follow the local geometry: a scene far from the origin behaves as at the origin;
4. the clock is a compensated sum of the steps;
5. the collapse regulariser depends only on the balls of the impact and adds no energy at e < 1;
6. finite input that the engine cannot represent is rejected, naming the ball and the field;
7. a ball with no room to move in the box is rejected;
8. every field is type-checked (numpy scalar types accepted, booleans only where meant).
"""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine import PLAY_AREA_1D, PLAY_AREA_2D, BatchSimulator, EventCapWarning, Scene, Simulator

SLOW = settings(max_examples=40, deadline=None)


def _step_all(sim, dt, steps):
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventCapWarning)  # a capped step fails the test
        for _ in range(steps):
            out += sim.step(dt)
    return out


# --------------------------------------------------------------------------- 1. one report per collision
@SLOW
@given(
    b=st.floats(-0.199, 0.199),
    v=st.floats(0.01, 100.0),
    log_mass=st.floats(-6.0, 6.0),
    e=st.sampled_from([0.0, 0.05, 0.5, 0.999]),
)
def test_an_oblique_collision_is_reported_once(b, v, log_mass, e):
    sim = Simulator(
        Scene(bounds=None, elasticity=e),
        [[-0.5, 0.0], [0.5, b]],
        [[v, 0.0], [-0.5 * v, 0.0]],
        [1.0, 10.0**log_mass],
        [0.1, 0.1],
    )
    hits = _step_all(sim, 2.0 / v, 1)
    assert len(hits) == 1, [(h.time, h.speed) for h in hits]
    assert hits[0].speed == pytest.approx(1.5 * v * math.sqrt(1 - (b / 0.2) ** 2), rel=1e-9)


@SLOW
@given(e=st.sampled_from([0.0, 0.3]), y=st.floats(-0.6, 0.6), vy=st.floats(-1.0, 1.0))
def test_a_cascade_reports_each_contact_once(e, y, vy):
    # a ball hits a touching pair that rests on the left wall: every contact at most once per instant
    r = 0.1
    pos = [[-2 + r, y], [-2 + 3 * r, y], [0.0, y + 0.05]]
    sim = Simulator(Scene(elasticity=e), pos, [[0.0, 0.0], [0.0, 0.0], [-2.0, vy]], [1.0, 1.0, 1.0], [r, r, r])
    hits = _step_all(sim, 0.05, 40)
    keys = [(h.time, h.ball, h.other, h.wall) for h in hits]
    assert len(keys) == len(set(keys))
    assert all(h.speed > 1e-12 for h in hits)  # no round-off "impacts"


# --------------------------------------------------------------------------- 2. squeezed mass ratios
def _squeeze(ratio, e, dim):
    """A ball ``ratio`` times heavier presses a light ball at rest against the left wall."""
    r = 0.1
    if dim == 1:
        return Simulator(
            Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1),
            [[-2 + r, 0.0], [-1.5, 0.0]],
            [[0.0, 0.0], [-1.0, 0.0]],
            [1.0, ratio],
            [r, r],
            max_events=2000,
        )
    return Simulator(
        Scene(bounds=PLAY_AREA_2D, elasticity=e),
        [[-2 + r, 0.1], [-1.5, 0.2]],
        [[0.0, 0.0], [-1.0, 0.2]],
        [1.0, ratio],
        [r, r],
        max_events=2000,
    )


@SLOW
@given(log_ratio=st.floats(0.0, 18.0), e=st.floats(0.0, 0.99), dim=st.sampled_from([1, 2]))
def test_a_squeezed_cascade_ends_whatever_the_mass_ratio(log_ratio, e, dim):
    sim = _squeeze(10.0**log_ratio, e, dim)
    energy = sim.kinetic_energy()
    _step_all(sim, 0.5, 3)  # every step reaches its end: no event cap, the clock moves on
    assert sim.time == 1.5 and not sim.cap_reached
    assert np.isfinite(sim.velocities).all()
    assert sim.kinetic_energy() <= energy * (1 + 1e-12)


@pytest.mark.parametrize("log_ratio", [13, 15, 18])
def test_the_squeezed_heavy_ball_stops_against_the_wall(log_ratio):
    sim = _squeeze(10.0**log_ratio, 0.0, 1)
    hits = _step_all(sim, 0.5, 1)
    assert [(h.ball, h.other, h.wall) for h in hits] == [(0, 1, None), (0, None, "left")]
    # the limit: both balls at rest, up to the regulariser's separation speed (1e-9 of 1 m/s)
    assert np.all(np.abs(sim.velocities) <= 1e-8)


# --------------------------------------------------------------------------- 3. far from the origin
def _shifted(case, offset):
    scene, pos, vel, mass, radii = case
    b = scene.bounds
    bounds = None if b is None else (b[0] + offset, b[1] + offset, b[2] + offset, b[3] + offset)
    shift = np.array([offset, offset if scene.dimension == 2 else 0.0])
    if scene.dimension == 1 and b is not None:
        bounds = (b[0] + offset, b[1], b[2] + offset, b[3])
    shifted = Scene(bounds=bounds, elasticity=scene.elasticity, dimension=scene.dimension)
    return Simulator(shifted, np.asarray(pos) + shift, vel, mass, radii)


def _sequence(sim, dt, steps):
    hits = _step_all(sim, dt, steps)
    return [(h.ball, h.other, h.wall) for h in hits], np.array([h.time for h in hits])


@SLOW
@given(gap=st.floats(1e-7, 2e-3), e=st.sampled_from([0.0, 0.5]), offset=st.sampled_from([1e3, 1e6, -1e6]))
def test_a_near_contact_far_from_the_origin_is_not_a_contact(gap, e, offset):
    # ball 0 rests ``gap`` from the left wall; ball 1 hits it. Only then does ball 0 reach the wall.
    r = 0.1
    case = (
        Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1),
        [[-2 + r + gap, 0.0], [-1.0, 0.0]],
        [[0.0, 0.0], [-1.0, 0.0]],
        [1.0, 1.0],
        [r, r],
    )
    near, far = _shifted(case, 0.0), _shifted(case, offset)
    seq0, t0 = _sequence(near, 0.1, 12)
    seq1, t1 = _sequence(far, 0.1, 12)
    assert seq1 == seq0
    np.testing.assert_allclose(t1, t0, rtol=0, atol=1e-8)  # the coordinates' round-off at 1e6 m is ~1e-10 m
    np.testing.assert_allclose(far.velocities, near.velocities, rtol=0, atol=1e-6)


@SLOW
@given(seed=st.integers(0, 10_000), e=st.sampled_from([1.0, 0.5, 0.0]), offset=st.sampled_from([1e4, 1e6]))
def test_a_scene_translated_far_away_has_the_same_impacts(seed, e, offset):
    rng = np.random.default_rng(seed)
    pos = np.array([[-1.2, -0.4], [0.0, 0.3], [1.1, -0.2]]) + rng.uniform(-0.1, 0.1, (3, 2))
    vel = rng.uniform(-1.0, 1.0, (3, 2))
    case = (Scene(bounds=PLAY_AREA_2D, elasticity=e), pos, vel, [1.0, 2.0, 0.5], [0.2, 0.25, 0.15])
    seq0, t0 = _sequence(_shifted(case, 0.0), 0.1, 20)  # a few bounces: chaos has no time to amplify
    seq1, t1 = _sequence(_shifted(case, offset), 0.1, 20)
    assert seq1 == seq0
    np.testing.assert_allclose(t1, t0, rtol=0, atol=1e-8)


@SLOW
@given(
    offset=st.sampled_from([1e3, 1e5, 1e6, -1e7]),
    e=st.sampled_from([0.0, 0.5]),
    speed=st.floats(0.1, 10.0),
    dt=st.floats(0.01, 1.0),
)
def test_a_state_the_engine_leaves_far_from_the_origin_is_accepted_again(offset, e, speed, dt):
    # the balls end steps touching, a few ulps of the coordinates apart either way: at 1e7 m an ulp
    # is 2e-9 m, ten times what a tolerance of 1e-9 of the radii sum alone would allow
    case = (
        Scene(bounds=PLAY_AREA_1D, elasticity=e, dimension=1),
        [[-1.5, 0.0], [-0.8, 0.0]],
        [[-speed, 0.0], [-speed, 0.0]],
        [1.0, 1.0],
        [0.1, 0.1],
    )
    sim = _shifted(case, offset)
    twin = sim.copy()
    for _ in range(10):
        sim.step(dt)
        twin.step(dt)
        twin.set_state(twin.get_state())
    assert sim.time == twin.time
    np.testing.assert_array_equal(twin.positions, sim.positions)
    np.testing.assert_array_equal(twin.velocities, sim.velocities)


# --------------------------------------------------------------------------- 4. the clock
def test_the_clock_is_the_correctly_rounded_sum_after_a_million_steps():
    dt = 1 / 60
    sim = Simulator(Scene(), [[0.3, -0.2]], [[0.7, 0.45]], [1.0], [0.15])
    n = 1_000_000
    last = None
    for _ in range(n):
        hits = sim.step(dt)
        if hits:
            last = hits[-1]
    exact = math.fsum([dt] * n)
    assert abs(sim.time - exact) <= 2 * math.ulp(exact)
    # the last impact's time, against the analytic bounce: the ball reaches a wall when its unfolded
    # coordinate is a whole number of spans past its start
    axis = 0 if last.wall in ("left", "right") else 1
    lo, hi = (-2.0 + 0.15, 2.0 - 0.15) if axis == 0 else (-1.0 + 0.15, 1.0 - 0.15)
    x0, v = (0.3, 0.7) if axis == 0 else (-0.2, 0.45)
    u = (x0 - lo + v * last.time) / (hi - lo)
    assert abs(u - round(u)) * (hi - lo) / v <= 1e-9  # the uncompensated clock was 1.6e-7 s off here


@SLOW
@given(dt=st.floats(1e-4, 1.0), steps=st.integers(1, 3000))
def test_forward_then_back_ends_at_time_zero(dt, steps):
    sim = Simulator(Scene(elasticity=0.5), [[-1.0, 0.0], [1.0, 0.1]], [[1.0, 0.3], [-1.0, 0.2]], [1.0, 2.0])
    for _ in range(steps):
        sim.step(dt)
    assert abs(sim.time - math.fsum([dt] * steps)) <= 2 * math.ulp(dt * steps)
    for _ in range(steps):
        sim.step(-dt)
    assert sim.time == 0.0


def test_the_clock_compensation_is_part_of_the_state():
    sim = Simulator(Scene(), [[0.0, 0.0]], [[1.0, 0.5]], [1.0])
    for _ in range(1000):
        sim.step(0.1)
    state, twin = sim.get_state(), sim.copy()
    other = Simulator(Scene(), [[0.0, 0.0]], [[1.0, 0.5]], [1.0])
    other.set_state(state)
    for s in (sim, twin, other):
        for _ in range(1000):
            s.step(0.1)
    assert sim.time == twin.time == other.time == math.fsum([0.1] * 2000)


# --------------------------------------------------------------------------- 5. the regulariser is local
def _slow_pair(e, slow, fast):
    """A slow head-on pair (closing at ``2 slow``) in the middle; ball 2 far away, at ``fast``."""
    r = 0.1
    return Simulator(
        Scene(bounds=None, elasticity=e),
        [[-r - slow, 0.0], [r + slow, 0.0], [50.0, 50.0]],
        [[slow, 0.0], [-slow, 0.0], [fast, fast]],
        [1.0, 1.0, 1.0],
        [r, r, r],
    )


@SLOW
@given(e=st.floats(0.0, 0.99), log_slow=st.floats(-12.0, -3.0), log_fast=st.floats(0.0, 4.0))
def test_a_slow_pair_ignores_a_fast_ball_and_gains_no_energy(e, log_slow, log_fast):
    slow = 10.0**log_slow
    alone = _slow_pair(e, slow, 0.0)
    beside = _slow_pair(e, slow, 10.0**log_fast)
    pair_energy = alone.kinetic_energy()
    _step_all(alone, 1.5, 1)
    _step_all(beside, 1.5, 1)
    np.testing.assert_array_equal(beside.velocities[:2], alone.velocities[:2])
    assert alone.kinetic_energy() <= pair_energy * (1 + 1e-15)
    assert abs(alone.velocities[0, 0]) == pytest.approx(e * slow, rel=1e-6, abs=1e-9 * slow)


@SLOW
@given(seed=st.integers(0, 10_000), e=st.floats(0.0, 0.95))
def test_energy_never_grows_below_unit_restitution(seed, e):
    rng = np.random.default_rng(seed)
    pos = np.array([[-1.5, -0.5], [-0.5, 0.5], [0.5, -0.5], [1.5, 0.5]]) + rng.uniform(-0.2, 0.2, (4, 2))
    speeds = 10.0 ** rng.uniform(-6, 3, 4)
    vel = rng.normal(size=(4, 2)) * speeds[:, None]
    sim = Simulator(Scene(elasticity=e), pos, vel, 10.0 ** rng.uniform(-2, 2, 4), [0.2] * 4, max_events=100_000)
    energy = sim.kinetic_energy()
    for _ in range(20):
        _step_all(sim, 0.05, 1)
        assert sim.kinetic_energy() <= energy * (1 + 1e-14)
        energy = sim.kinetic_energy()


# --------------------------------------------------------------------------- 6. representable input
GOOD = dict(positions=[[-1.0, 0.0], [1.0, 0.0]], velocities=[[1.0, 0.0], [-1.0, 0.0]], masses=[1.0, 2.0])


def _make(**changes):
    kw = {**GOOD, **changes}
    scene = kw.pop("scene", Scene())
    return Simulator(scene, kw.pop("positions"), kw.pop("velocities"), kw.pop("masses"), **kw)


@given(exponent=st.integers(-323, -309))
def test_a_mass_whose_inverse_overflows_is_rejected(exponent):
    with pytest.raises(ValueError, match="ball 1: mass must be positive and finite, with a finite inverse"):
        _make(masses=[1.0, 10.0**exponent], radii=[0.1, 0.1])


@given(speed=st.floats(1e151, 1e308))
def test_a_speed_whose_square_overflows_is_rejected(speed):
    with pytest.raises(ValueError, match="ball 0: velocity must be finite, speed within"):
        _make(velocities=[[speed, 0.0], [0.0, 0.0]])


@given(speed=st.floats(1e100, 1e150), log_mass=st.floats(110.0, 300.0))
def test_a_kinetic_energy_beyond_float64_is_rejected(speed, log_mass):
    with pytest.raises(ValueError, match="ball 0: velocity .* kinetic energy beyond float64"):
        _make(velocities=[[speed, 0.0], [0.0, 0.0]], masses=[10.0**log_mass, 1.0], radii=[0.1, 0.1])


@given(dt=st.floats(1.1e150, 1e308), speed=st.floats(1.0, 1e3))
def test_a_step_that_overflows_the_position_is_rejected(dt, speed):
    sim = _make(scene=Scene(bounds=None), velocities=[[0.0, 0.0], [speed, 0.0]])
    before = sim.get_state()
    with pytest.raises(ValueError, match="dt: "):
        sim.step(dt)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


@SLOW
@given(e=st.floats(0.05, 0.8), dt=st.floats(20.0, 1e3), n_scenes=st.integers(1, 3))
def test_a_backward_step_into_a_divergent_past_is_rejected(e, dt, n_scenes):
    # reversed, a ball bouncing between walls at e < 1 gains 1/e of its speed per bounce, and the
    # bounces come ever faster: its past reaches infinite speed within a finite time (along y,
    # 1.8 m / 0.8 m/s * e / (1 - e) after the first bounce: under 11 s for e <= 0.8)
    pos = [[[0.0, 0.0]]] * n_scenes
    vel = [[[0.0, 0.0]]] * (n_scenes - 1) + [[[0.6, 0.8]]]  # (only the last scene's ball moves)
    sim = BatchSimulator(Scene(elasticity=e), pos, vel, [1.0], [0.1])
    twin = sim.copy()
    sim.step(0.25)
    twin.step(0.25)
    before = sim.get_state()
    ball = "ball 0" if n_scenes == 1 else f"scene {n_scenes - 1}, ball 0"
    with pytest.raises(ValueError, match=f"dt: the past of {ball} diverges within this step"):
        sim.step(-dt)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])
    for s in (sim, twin):  # and what follows is as if the step was never asked for
        s.step(-0.5)
        s.step(1.0)
    np.testing.assert_array_equal(sim.positions, twin.positions)
    np.testing.assert_array_equal(sim.velocities, twin.velocities)
    assert np.isfinite(sim.velocities).all()


def test_a_long_step_without_a_border_that_stays_representable_is_taken():
    sim = _make(scene=Scene(bounds=None), velocities=[[-1.0, 0.0], [1.0, 0.0]])
    sim.step(1e140)
    assert np.isfinite(sim.positions).all() and sim.time == 1e140


@given(radius=st.floats(1e-300, 1e-11))
def test_a_radius_too_small_to_resolve_is_rejected(radius):
    with pytest.raises(ValueError, match="ball 0: radius .* too small for float64 to resolve"):
        _make(radii=[radius, 0.1])


def test_a_radius_too_small_far_from_the_origin_is_rejected():
    # 1e9 m from the origin a coordinate's last place is 1.2e-7 m: a 1 mm ball is below resolution
    with pytest.raises(ValueError, match="ball 1: radius 0.001 m is too small"):
        _make(scene=Scene(bounds=None), positions=[[1e9, 0.0], [1e9 + 1.0, 0.0]], radii=[0.5, 1e-3])


def test_a_nudge_that_overflows_the_speed_is_rejected():
    sim = _make()
    before = sim.get_state()
    with pytest.raises(ValueError, match="ball 1: nudge"):
        sim.nudge([[0.0, 0.0], [1e200, 0.0]])
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


# --------------------------------------------------------------------------- 7. room to move
@pytest.mark.parametrize("e", [1.0, 0.5, 0.0])
@pytest.mark.parametrize("short", [0.0, 1e-13, -1e-13])
def test_a_ball_as_tall_as_the_box_is_rejected(e, short):
    r = 1.0 - short / 2  # the box is 2 m tall
    with pytest.raises(ValueError, match="ball 0: radius .* leaves no room to move: its diameter is the box height"):
        Simulator(Scene(elasticity=e), [[0.0, 0.0]], [[1.0, 0.5]], [1.0], [r])


def test_a_ball_as_wide_as_a_1d_box_is_rejected():
    with pytest.raises(ValueError, match="ball 0: radius .* box width"):
        Simulator(Scene(bounds=(-1.0, -0.5, 1.0, 0.5), dimension=1), [[0.0, 0.0]], [[1.0, 0.0]], [1.0], [1.0])


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_a_ball_with_a_little_room_moves_on(e):
    sim = Simulator(Scene(elasticity=e), [[0.0, 0.0]], [[1.0, 0.5]], [1.0], [1.0 - 1e-6], max_events=10**6)
    _step_all(sim, 0.01, 10)
    assert sim.time == pytest.approx(0.1, abs=1e-15) and not sim.cap_reached


# --------------------------------------------------------------------------- 8. types
@pytest.mark.parametrize("field", ["positions", "velocities"])
@pytest.mark.parametrize("bad", ["1.0", 1 + 2j, True, np.complex128(1.0), np.bool_(False), None])
def test_a_non_real_position_or_velocity_names_the_field_and_ball(field, bad):
    value = [[0.0, 0.0], [0.5, bad]] if field == "positions" else [[0.0, 0.0], [bad, 0.0]]
    with pytest.raises(ValueError, match=f"ball 1: {field} must be real numbers"):
        _make(**{field: value})


@pytest.mark.parametrize("field", ["masses", "radii"])
@pytest.mark.parametrize("bad", ["1.0", 1 + 0j, True, np.bool_(True)])
def test_a_non_real_mass_or_radius_names_the_field_and_ball(field, bad):
    with pytest.raises(ValueError, match=f"ball 1: {field} must be real numbers"):
        _make(**{field: [0.2, bad]})


@pytest.mark.parametrize("field", ["positions", "velocities", "masses", "radii"])
def test_complex_and_boolean_arrays_are_refused(field):
    shape = (2, 2) if field in ("positions", "velocities") else (2,)
    for arr in (np.full(shape, 0.1 + 0j), np.zeros(shape, dtype=bool)):
        with pytest.raises(ValueError, match=f"ball 0: {field} must be real numbers"):
            _make(**{field: arr})


@pytest.mark.parametrize("field", ["positions", "velocities"])
def test_a_ragged_list_names_the_field(field):
    with pytest.raises(ValueError, match=f"{field}: expected"):
        _make(**{field: [[0.0, 0.0], [1.0]]})


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(ball_collisions="no"), "ball_collisions: expected True or False"),
        (dict(ball_collisions=1), "ball_collisions: expected True or False"),
        (dict(dimension=True), "dimension: must be 1 or 2"),
        (dict(dimension=2.0), "dimension: must be 1 or 2"),
        (dict(elasticity="0.5"), "elasticity: expected a number"),
        (dict(elasticity=True), "elasticity: expected a number"),
        (dict(elasticity=0.5 + 0j), "elasticity: expected a number"),
        (dict(bounds=(-2, -1, "2", 1)), "bounds: expected real numbers"),
        (dict(bounds=(-2, -1, True, 1)), "bounds: expected real numbers"),
        (dict(inelastic=1), "inelastic: must be"),
    ],
)
def test_scene_fields_are_type_checked(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Scene(**kwargs)


@pytest.mark.parametrize("dt", ["0.1", True, 0.1 + 0j, None])
def test_dt_must_be_a_real_number(dt):
    sim = _make()
    with pytest.raises(ValueError, match="dt: expected a number"):
        sim.step(dt)
    assert sim.time == 0.0


@pytest.mark.parametrize(
    "kwargs", [dict(collapse_ratio=True), dict(collapse_floor="0"), dict(max_events=True), dict(mode=1)]
)
def test_settings_are_type_checked(kwargs):
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        _make(**kwargs)


@pytest.mark.parametrize("real", [np.float32, np.float64, np.int64, np.int32, np.float16])
def test_numpy_scalar_types_are_accepted_wherever_numbers_are(real):
    scene = Scene(bounds=tuple(real(v) for v in (-2, -1, 2, 1)), elasticity=real(1), dimension=np.int64(2))
    pos = [[real(-1), real(0)], [real(1), real(0)]]
    sim = Simulator(
        scene,
        pos,
        [[real(1), real(0)], [real(-1), real(0)]],
        [real(1), real(2)],
        [real(1) / 4, real(1) / 4],
        max_events=np.int64(100),
        collapse_ratio=np.float32(1e-9),
        collapse_floor=real(0),
    )
    sim.step(real(1))
    sim.batch.set_scenes([0], [pos], [[[real(0), real(0)], [real(0), real(0)]]], time=real(2))
    sim.nudge([[real(1), real(0)], [real(0), real(0)]])
    assert sim.time == 2.0


def test_set_state_type_checks_its_fields():
    sim = _make()
    state = sim.get_state()
    before = sim.get_state()
    for key, bad in (
        ("positions", state["positions"].astype(complex)),
        ("time", np.array("0.0")),
        ("masses", np.array([1.0, math.nan])),
    ):
        with pytest.raises(ValueError, match=f"state {key}"):
            sim.set_state(state.replace(**{key: bad}))
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


def test_a_batch_names_the_scene_and_ball():
    pos = np.zeros((3, 1, 2))
    vel = np.zeros((3, 1, 2)).tolist()
    vel[2][0][1] = "fast"
    with pytest.raises(ValueError, match="scene 2, ball 0: velocities must be real numbers"):
        BatchSimulator(Scene(), pos, vel, [1.0])
